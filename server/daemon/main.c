/*
 * main.c — spinmodald, the analysis daemon (server/DAEMON.md).
 *
 * How it fits: startup and shutdown.  It reads the settings (config.c:
 * the flags, each with a SPINMODAL_* environment variable, the flag wins;
 * --help; the checks) and the token file once, turns SIGTERM and SIGINT
 * into a byte on a self-pipe (blocked in the threads it starts, main reads
 * the pipe after the start) and ignores SIGPIPE, then starts the modules
 * in order store_open -> jobs_start -> http_start and logs `listening`
 * with the bound address.  On SIGTERM/SIGINT: `stopping`, http_begin_stop
 * (POST answers 503), jobs_stop (grace period), http_stop, store_close,
 * `stopped`, exit 0.
 *
 * Exit status: 0 after a clean stop, 64 on a bad flag, 1 when it cannot
 * start (token file, database, port).
 */
#include <errno.h>
#include <fcntl.h>
#include <malloc.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "codec.h"
#include "config.h"
#include "http.h"
#include "jobs.h"
#include "log.h"
#include "metrics.h"
#include "spinmodal.h"
#include "store.h"

enum { EXIT_START = CONFIG_EXIT_START };

#define MAIN_PRUNE_EVERY_MS (10 * 60 * 1000) /* retention runs at start and then this often */

/* The running daemon, for the stop. */
typedef struct main_daemon {
    store *st;
    metrics *mx;
    jobs *j;
    http *h;
} main_daemon;

/* ------------------------------------------------------------ running */

/* "HOST:PORT" or "[HOST]:PORT" of the bound address into buf. */
static void main_addr(const config_opts *o, int port, char *buf, size_t cap)
{
    if (o->ipv6 || strchr(o->host, ':'))
        snprintf(buf, cap, "[%s]:%d", o->host, port);
    else
        snprintf(buf, cap, "%s:%d", o->host, port);
}

static void main_fail(const char *what, const char *detail)
{
    log_event("error", "start_failed", "error", what, "detail", detail, (const char *)NULL);
}

/*
 * The store's error callback (on the failing thread, at the failure): log
 * the kind and SQLite's own text, count it by kind.  Never calls the store.
 */
static void main_store_error(void *ctx, const store_error *e)
{
    char code[16];

    snprintf(code, sizeof(code), "%d", e->backend_rc);
    log_event("error", "store_error", "op", e->op, "kind", store_rc_name(e->rc), "code", code,
              "sqlstate", e->sqlstate[0] ? e->sqlstate : NULL, "detail", e->text,
              (const char *)NULL);
    metrics_store_error(ctx, e->rc);
}

/* The store's prune-on-insert callback: count what --retain-bytes removed. */
static void main_store_pruned(void *ctx, long long n)
{
    metrics_store_pruned(ctx, n);
}

/* Open the store and the metrics; 0 or EXIT_START. */
static int main_open(const config_opts *o, main_daemon *d)
{
    store_settings set;
    char err[512], n[32];
    int requeued = 0, rc;

    d->mx = metrics_new();
    if (!d->mx) {
        main_fail("out of memory", NULL);
        return EXIT_START;
    }
    err[0] = '\0';
    store_default_settings(&set);
    set.path = o->db;
    set.owner = o->replica_id;
    set.lease_s = o->lease;
    set.on_error = main_store_error;
    set.on_error_ctx = d->mx;
    set.timeout_ms = (int)(o->db_timeout * 1000.0);
    set.retain_bytes = o->retain_bytes;   /* pruned on insert too, not only periodically */
    set.on_pruned = main_store_pruned;
    set.on_pruned_ctx = d->mx;
    rc = store_open_with(&d->st, &set, &requeued, err, sizeof(err));
    if (rc != STORE_OK) {
        /* err names the file, or host:port/database of a URI (never its password) */
        log_event("error", "store_open_failed", "kind", store_rc_name(rc), "detail",
                  err[0] ? err : store_strerror(rc), (const char *)NULL);
        main_fail("cannot open the database", err[0] ? err : store_strerror(rc));
        return EXIT_START;
    }
    snprintf(n, sizeof(n), "%d", requeued);
    log_event("info", "recovered", "jobs", n, "backend", store_backend_name(d->st), "owner",
              store_owner(d->st), "db", store_caps(d->st) & STORE_CAP_SECRET_PATH ? NULL : o->db,
              (const char *)NULL);
    return 0;
}

/*
 * Retention: remove the oldest finished jobs beyond --retain-age and
 * --retain-bytes (queued and running jobs are never removed); count and log.
 * The store also keeps --retain-bytes on every insert (set.retain_bytes):
 * this periodic pass catches up the age bound and what other replicas wrote.
 */
static void main_prune(const config_opts *o, main_daemon *d)
{
    long long removed = 0;
    char n[32];
    int rc;

    if (o->retain_age <= 0.0 && o->retain_bytes <= 0)
        return;
    rc = store_prune(d->st, log_now(), o->retain_age, o->retain_bytes, &removed);
    metrics_store_pruned(d->mx, removed);
    if (removed > 0 || rc != STORE_OK) {
        snprintf(n, sizeof(n), "%lld", removed);
        log_event(rc == STORE_OK ? "info" : "error", "store_pruned", "jobs", n, "store",
                  rc == STORE_OK ? NULL : store_rc_name(rc), (const char *)NULL);
    }
}

/* Start the pool and the HTTP server; 0 or EXIT_START. */
static int main_serve(const config_opts *o, const char *token, main_daemon *d)
{
    jobs_config jc;
    http_config hc;
    char addr[300], workers[16];
    int rc;

    http_default_config(&hc);
    hc.host = o->host;
    hc.port = o->port;
    hc.max_body = (size_t)o->max_body;
    hc.limits.max_request_bytes = (size_t)o->max_body;
    hc.limits.max_elements = (int)o->max_elements;
    hc.limits.max_speeds = (int)o->max_speeds;
    hc.limits.max_coordinates = (int)o->max_coordinates;
    hc.limits.max_frame_dofs = (int)o->max_frame_dofs;
    hc.limits.max_solve_seconds = o->job_timeout;
    hc.limits.max_result_bytes = (size_t)o->max_result_bytes;
    hc.token = token;
    hc.auth_reads = o->auth_reads;
    hc.cors_origin = o->cors_origin;
    hc.per_client_limit = (unsigned)o->per_client;
    hc.connection_limit = (unsigned)o->max_connections;
    hc.max_waiters = (unsigned)o->max_waiters;
    hc.request_deadline = o->request_deadline;
    jc.workers = (int)o->workers;
    jc.solve_threads = (int)o->solve_threads;
    jc.queue_max = (int)o->queue_max;
    jc.job_timeout = o->job_timeout;
    jc.shared = (store_caps(d->st) & STORE_CAP_SHARED) != 0;
    jc.lease = o->lease;
    jc.limits = hc.limits;
    rc = jobs_start(&d->j, d->st, d->mx, &jc);
    if (rc != JOBS_OK) {
        main_fail("cannot start the workers",
                  rc == JOBS_NOMEM ? "out of memory" : "the database failed");
        return EXIT_START;
    }
    main_addr(o, o->port, addr, sizeof(addr));
    rc = http_start(&d->h, &hc, d->j, d->st, d->mx);
    if (rc != HTTP_OK) {
        main_fail(rc == HTTP_ADDRESS ? "cannot resolve the listen address"
                  : rc == HTTP_NOMEM ? "out of memory"
                                     : "cannot listen (address in use or not permitted)",
                  addr);
        return EXIT_START;
    }
    main_addr(o, http_port(d->h), addr, sizeof(addr));
    snprintf(workers, sizeof(workers), "%ld", o->workers);
    log_event("info", "listening", "addr", addr, "workers", workers, "version", SM_VERSION,
              (const char *)NULL);
    return 0;
}

/* Stop in DAEMON.md order; safe on a partly started daemon. */
static void main_stop(main_daemon *d, double grace)
{
    http_begin_stop(d->h);
    jobs_stop(d->j, grace);
    d->j = NULL;
    http_stop(d->h);
    d->h = NULL;
    store_close(d->st);
    d->st = NULL;
    metrics_free(d->mx);
    d->mx = NULL;
}

/*
 * Write end of the self-pipe.  The one global of the daemon: a signal
 * handler gets no argument.  Set before the handlers are installed.
 */
static volatile sig_atomic_t main_signal_fd = -1;

/* SIGTERM/SIGINT: one byte (the signal number) into the self-pipe. */
static void main_on_signal(int sig)
{
    int saved = errno;
    unsigned char b = (unsigned char)sig;
    ssize_t n;

    if (main_signal_fd >= 0) {
        n = write(main_signal_fd, &b, 1);
        (void)n; /* a full pipe already holds a stop request */
    }
    errno = saved;
}

/*
 * Signals: SIGTERM/SIGINT write to the self-pipe fds (the handler works in
 * whichever thread takes them, the BLAS library's own threads started
 * before main included), and are blocked in this thread so the threads
 * started next inherit the block (main unblocks them once it waits on the
 * pipe); SIGPIPE is ignored.  0 or -1.
 */
static int main_signals(int fds[2], sigset_t *set)
{
    struct sigaction sa;

    if (pipe(fds))
        return -1;
    if (fcntl(fds[0], F_SETFD, FD_CLOEXEC) || fcntl(fds[1], F_SETFD, FD_CLOEXEC) ||
        fcntl(fds[1], F_SETFL, O_NONBLOCK))
        return -1;
    main_signal_fd = fds[1];
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = SIG_IGN;
    sigemptyset(&sa.sa_mask);
    if (sigaction(SIGPIPE, &sa, NULL))
        return -1;
    sa.sa_handler = main_on_signal;
    sa.sa_flags = SA_RESTART;
    if (sigemptyset(set) || sigaddset(set, SIGTERM) || sigaddset(set, SIGINT) ||
        sigaddset(&sa.sa_mask, SIGTERM) || sigaddset(&sa.sa_mask, SIGINT) ||
        sigaction(SIGTERM, &sa, NULL) || sigaction(SIGINT, &sa, NULL) ||
        pthread_sigmask(SIG_BLOCK, set, NULL))
        return -1;
    return 0;
}

/* Wait for SIGTERM/SIGINT (a byte on the self-pipe); returns the signal. */
static int main_wait_signal(int fd, const sigset_t *set, const config_opts *o, main_daemon *d)
{
    struct pollfd p = {fd, POLLIN, 0};
    unsigned char b = 0;
    ssize_t n;
    int ready;

    pthread_sigmask(SIG_UNBLOCK, set, NULL);
    main_prune(o, d);
    for (;;) {
        ready = poll(&p, 1, MAIN_PRUNE_EVERY_MS);
        if (ready == 0) {
            main_prune(o, d);
            continue;
        }
        if (ready < 0 && errno == EINTR)
            continue;
        break;
    }
    do
        n = read(fd, &b, 1);
    while (n < 0 && errno == EINTR);
    return n == 1 ? (int)b : SIGTERM;
}

static void main_close_pipe(int fds[2])
{
    main_signal_fd = -1;
    if (fds[0] >= 0)
        close(fds[0]);
    if (fds[1] >= 0)
        close(fds[1]);
}

int main(int argc, char **argv)
{
    main_daemon d = {NULL, NULL, NULL, NULL};
    int rc, sig, fds[2] = {-1, -1};
    char *token = NULL;
    config_opts o;
    sigset_t set;

    /* The solver allocates and frees matrices of 0.1-4 MB at every Newton step and speed:
     * keep them in each worker's heap instead of handing them back to the kernel and faulting
     * them in again (DESIGN.md 2.1).  At most 16 MB stays unreturned above a heap's top. */
    mallopt(M_MMAP_THRESHOLD, 4 << 20);
    mallopt(M_TRIM_THRESHOLD, 16 << 20);
    rc = config_parse(argc, argv, &o);
    if (rc)
        return rc < 0 ? 0 : rc;
    log_init(o.format, 1);
    if (o.token_file && config_token(o.token_file, &token))
        return EXIT_START;
    if (main_signals(fds, &set)) {
        fprintf(stderr, "spinmodald: cannot set up the signals: %s.\n", strerror(errno));
        main_close_pipe(fds);
        free(token);
        return EXIT_START;
    }
    rc = main_open(&o, &d);
    if (!rc)
        rc = main_serve(&o, token, &d);
    free(token);
    if (rc) {
        main_stop(&d, 0.0);
        main_close_pipe(fds);
        return rc;
    }
    sig = main_wait_signal(fds[0], &set, &o, &d);
    http_begin_stop(d.h); /* refuse first, then say so: a client that reads the log sees 503 */
    log_event("info", "stopping", "signal", sig == SIGINT ? "SIGINT" : "SIGTERM",
              (const char *)NULL);
    main_stop(&d, o.shutdown_grace);
    log_event("info", "stopped", (const char *)NULL);
    main_close_pipe(fds);
    return 0;
}
