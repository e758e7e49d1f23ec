/*
 * pg_cluster.c — a throwaway PostgreSQL cluster for the store tests
 * (pg_cluster.h), in the manner of libuv's test runner starting helper
 * processes beside the test.
 *
 * initdb -D <dir>/data -A trust -U postgres, then
 * pg_ctl -D <dir>/data -l <dir>/log -o "-p PORT -k <dir> -c listen_addresses=127.0.0.1" start,
 * on a port found free by binding port 0.  fsync is off: the tests check
 * behaviour, not durability of the server.  The binaries run as `nobody`
 * when the test runs as root (CI on Debian 12): the child drops its
 * groups, gid and uid before exec, and the directory is chowned to it.
 *
 * Clean-up when the test dies.  Before the cluster exists a guard process
 * is forked; it blocks reading a pipe whose write end only the test holds
 * (close-on-exec, so the server never inherits it).  When the test exits
 * in any way — return, abort, a sanitizer report, kill -9 — the pipe
 * closes and the guard stops the server (-m immediate) and removes the
 * directory.  pg_cluster_destroy just closes the pipe and waits for it.
 */
#define _GNU_SOURCE   /* setgroups, nftw, pipe2 */

#include "pg_cluster.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <grp.h>
#include <libpq-fe.h>
#include <netinet/in.h>
#include <pwd.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

/* Is bindir/initdb and bindir/pg_ctl there and executable? */
static int has_server(const char *bindir)
{
    char p[600];

    snprintf(p, sizeof p, "%s/initdb", bindir);
    if (access(p, X_OK) != 0)
        return 0;
    snprintf(p, sizeof p, "%s/pg_ctl", bindir);
    return access(p, X_OK) == 0;
}

/* The directory of the server binaries into out; 0, or -1 when none. */
static int find_bindir(char *out, size_t len)
{
    const char *env = getenv("PG_BINDIR");
    char line[512] = "";
    FILE *f;
    DIR *d;
    struct dirent *e;
    int best = -1;

    if (env && *env) {   /* when set, the only place looked at (CI can force a skip) */
        snprintf(out, len, "%s", env);
        return has_server(env) ? 0 : -1;
    }
    f = popen("pg_config --bindir 2>/dev/null", "r");
    if (f != NULL) {
        if (fgets(line, sizeof line, f) != NULL)
            line[strcspn(line, "\n")] = '\0';
        (void)pclose(f);
        if (line[0] && has_server(line)) {
            snprintf(out, len, "%s", line);
            return 0;
        }
    }
    d = opendir("/usr/lib/postgresql");   /* Debian: one directory per major version */
    while (d != NULL && (e = readdir(d)) != NULL) {
        int v = atoi(e->d_name);
        char p[512];
        snprintf(p, sizeof p, "/usr/lib/postgresql/%s/bin", e->d_name);
        if (v > best && has_server(p)) {
            best = v;
            snprintf(out, len, "%s", p);
        }
    }
    if (d != NULL)
        closedir(d);
    return best >= 0 ? 0 : -1;
}

int pg_free_port(void)
{
    struct sockaddr_in a;
    socklen_t n = sizeof a;
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0), port = 0;

    if (fd < 0)
        return 0;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (bind(fd, (struct sockaddr *)&a, sizeof a) == 0 &&
        getsockname(fd, (struct sockaddr *)&a, &n) == 0)
        port = ntohs(a.sin_port);
    close(fd);
    return port;
}

/* Run argv (argv[0] a path) as the cluster's user, output appended to
 * <dir>/log; the exit status, or -1. */
static int run(const pg_cluster *c, char *const argv[])
{
    char log[300];
    pid_t pid;
    int st;

    snprintf(log, sizeof log, "%s/log", c->dir);
    pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        int in, out;
        /* the user first: the log must be the server's to write (pg_ctl -l) */
        if (c->drop && (setgroups(0, NULL) != 0 || setgid(c->gid) != 0 || setuid(c->uid) != 0))
            _exit(126);
        in = open("/dev/null", O_RDONLY);
        out = open(log, O_WRONLY | O_CREAT | O_APPEND, 0644);
        if (in >= 0)
            dup2(in, 0);
        if (out >= 0) {
            dup2(out, 1);
            dup2(out, 2);
        }
        execv(argv[0], argv);
        _exit(127);
    }
    while (waitpid(pid, &st, 0) < 0)
        if (errno != EINTR)
            return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* pg_ctl <action> with the cluster's options. */
static int pg_ctl(const pg_cluster *c, const char *action, const char *mode)
{
    char ctl[600], data[300], log[300], opts[600];
    char *argv[16];
    int n = 0;

    snprintf(ctl, sizeof ctl, "%s/pg_ctl", c->bindir);
    snprintf(data, sizeof data, "%s/data", c->dir);
    snprintf(log, sizeof log, "%s/log", c->dir);
    snprintf(opts, sizeof opts, "-p %d -k %s -c listen_addresses=127.0.0.1 -c fsync=off "
             "-c full_page_writes=off -c max_connections=60", c->port, c->dir);
    argv[n++] = ctl;
    argv[n++] = "-D";
    argv[n++] = data;
    argv[n++] = "-w";
    argv[n++] = "-t";
    argv[n++] = "60";
    if (strcmp(action, "stop") != 0) {
        argv[n++] = "-l";
        argv[n++] = log;
        argv[n++] = "-o";
        argv[n++] = opts;
    }
    if (mode != NULL) {
        argv[n++] = "-m";
        argv[n++] = (char *)mode;
    }
    argv[n++] = (char *)action;
    argv[n] = NULL;
    return run(c, argv) == 0 ? 0 : -1;
}

static int rm_one(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st;
    (void)flag;
    (void)ftw;
    (void)remove(path);
    return 0;
}

/* The guard: wait for the test's end of the pipe to close, then stop the
 * server and remove the directory. */
static void guard_main(pg_cluster *c, int fd)
{
    char b;

    while (read(fd, &b, 1) < 0 && errno == EINTR) {
    }
    (void)pg_ctl(c, "stop", "immediate");
    (void)nftw(c->dir, rm_one, 16, FTW_DEPTH | FTW_PHYS);
    _exit(0);
}

/* Print the last lines of the server's log (a failed start). */
static void log_tail(const pg_cluster *c)
{
    char p[300], line[512];
    FILE *f;

    snprintf(p, sizeof p, "%s/log", c->dir);
    f = fopen(p, "r");
    if (f == NULL)
        return;
    printf("--- %s\n", p);
    while (fgets(line, sizeof line, f) != NULL)
        fputs(line, stdout);
    fclose(f);
}

int pg_cluster_start(pg_cluster *c, char *why, size_t len)
{
    char initdb[600], data[300];
    int fds[2];

    memset(c, 0, sizeof *c);
    c->guard_fd = -1;
    c->guard = -1;
    if (find_bindir(c->bindir, sizeof c->bindir) != 0) {
        snprintf(why, len, "no PostgreSQL server binaries (initdb, pg_ctl) in $PG_BINDIR, "
                 "`pg_config --bindir` or /usr/lib/postgresql/*/bin: install postgresql");
        return 77;
    }
    c->uid = getuid();
    c->gid = getgid();
    if (geteuid() == 0) {
        struct passwd *pw = getpwnam("nobody");
        if (pw == NULL) {
            snprintf(why, len, "running as root and no user 'nobody' to run PostgreSQL as");
            return -1;
        }
        c->uid = pw->pw_uid;
        c->gid = pw->pw_gid;
        c->drop = 1;
    }
    /* root: /tmp, which nobody can traverse whatever TMPDIR is */
    snprintf(c->dir, sizeof c->dir, "%s/test_store_pg.XXXXXX",
             !c->drop && getenv("TMPDIR") && *getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (mkdtemp(c->dir) == NULL || (c->drop && chown(c->dir, c->uid, c->gid) != 0)) {
        snprintf(why, len, "cannot create %s: %s", c->dir, strerror(errno));
        return -1;
    }
    if (pipe2(fds, O_CLOEXEC) != 0 || (c->guard = fork()) < 0) {
        snprintf(why, len, "cannot start the guard process: %s", strerror(errno));
        return -1;
    }
    if (c->guard == 0) {
        close(fds[1]);
        guard_main(c, fds[0]);
    }
    close(fds[0]);
    c->guard_fd = fds[1];

    snprintf(initdb, sizeof initdb, "%s/initdb", c->bindir);
    snprintf(data, sizeof data, "%s/data", c->dir);
    {
        char *argv[] = {initdb, "-D", data, "-A", "trust", "-U", "postgres", "-E", "UTF8",
                        "--locale=C", "--no-sync", NULL};
        if (run(c, argv) != 0) {
            log_tail(c);
            snprintf(why, len, "initdb %s failed (log above)", data);
            return -1;
        }
    }
    for (int attempt = 0; attempt < 3; attempt++) {
        c->port = pg_free_port();
        if (c->port > 0 && pg_ctl(c, "start", NULL) == 0) {
            c->running = 1;
            return 0;
        }
    }
    log_tail(c);
    snprintf(why, len, "pg_ctl start failed three times (log above)");
    return -1;
}

int pg_cluster_stop(pg_cluster *c)
{
    int rc = pg_ctl(c, "stop", "fast");

    if (rc == 0)
        c->running = 0;
    return rc;
}

int pg_cluster_resume(pg_cluster *c)
{
    int rc = pg_ctl(c, "start", NULL);

    if (rc == 0)
        c->running = 1;
    else
        log_tail(c);
    return rc;
}

int pg_cluster_restart(pg_cluster *c)
{
    return pg_ctl(c, "restart", "fast");
}

int pg_raw(const char *dsn, const char *sql, char *buf, size_t len)
{
    PGconn *conn = PQconnectdb(dsn);
    PGresult *r = NULL;
    int rc = -1;

    if (buf && len)
        buf[0] = '\0';
    if (PQstatus(conn) == CONNECTION_OK) {
        r = PQexec(conn, sql);
        if (PQresultStatus(r) == PGRES_TUPLES_OK || PQresultStatus(r) == PGRES_COMMAND_OK) {
            rc = 0;
            if (buf && len && PQresultStatus(r) == PGRES_TUPLES_OK && PQntuples(r) > 0)
                snprintf(buf, len, "%s", PQgetvalue(r, 0, 0));
        } else {
            printf("pg_raw: %s: %s", sql, PQresultErrorMessage(r));
        }
    } else {
        printf("pg_raw: %s", PQerrorMessage(conn));
    }
    PQclear(r);
    PQfinish(conn);
    return rc;
}

int pg_cluster_createdb(pg_cluster *c, const char *name, char *dsn, size_t len)
{
    char admin[128], sql[128];

    snprintf(admin, sizeof admin, "postgresql://postgres@127.0.0.1:%d/postgres", c->port);
    snprintf(sql, sizeof sql, "CREATE DATABASE %s", name);
    if (pg_raw(admin, sql, NULL, 0) != 0)
        return -1;
    snprintf(dsn, len, "postgresql://postgres@127.0.0.1:%d/%s", c->port, name);
    return 0;
}

void pg_cluster_destroy(pg_cluster *c)
{
    if (c == NULL)
        return;
    if (c->guard_fd >= 0)
        close(c->guard_fd);   /* the guard stops the server and removes the directory */
    c->guard_fd = -1;
    if (c->guard > 0)
        while (waitpid(c->guard, NULL, 0) < 0 && errno == EINTR) {
        }
    c->guard = -1;
    c->running = 0;
}
