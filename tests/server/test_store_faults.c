/*
 * test_store_faults.c — what an operator must be able to tell apart, on
 * real files in a mkdtemp directory (server/daemon/store.h):
 * - error kinds: names and sentences, the SQLite code → kind table (and
 *   PostgreSQL's SQLSTATE → kind table), a real
 *   BUSY (another connection's write lock) and a real FULL (a file size
 *   limit in a child process) with SQLite's text in store_last_error and
 *   the on_error callback;
 * - the exclusive database: a second store in this process and in a child
 *   process is refused with the path and pid; a holder killed with -9
 *   frees the file and its running job is requeued only then;
 * - corruption: a garbage page, a truncated file and a garbage header are
 *   refused at open (STORE_CORRUPT) and left untouched;
 * - health: the database or lock file deleted or replaced under the open
 *   store (STORE_GONE), a write lock held elsewhere (STORE_BUSY);
 * - retention: which jobs store_prune keeps, by age and by size, and that
 *   the file shrinks.
 */
#include "store.h"
#include "store_pg.h"       /* store_pg_kind, for the SQLSTATE table */
#include "store_sqlite.h"   /* store_sqlite_kind, for the code table */

#include <errno.h>
#include <signal.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static int failures = 0;
static int checks = 0;

#define CHECK(cond, ...)                                      \
    do {                                                      \
        checks++;                                             \
        if (!(cond)) {                                        \
            failures++;                                       \
            printf("FAIL %s:%d: ", __FILE__, __LINE__);       \
            printf(__VA_ARGS__);                              \
            printf("\n");                                     \
        }                                                     \
    } while (0)

static void make_id(unsigned n, char id[65])
{
    snprintf(id, 65, "%064x", n);
}

static int submit(store *s, unsigned n, double now)
{
    char id[65], req[64];
    int len, outcome = -1;

    make_id(n, id);
    len = snprintf(req, sizeof req, "{\"job\":%u}", n);
    return store_submit(s, id, req, (size_t)len, 11, now, &outcome, NULL);
}

/* First column of the first row of sql as text into buf (own connection). */
static int raw_text(const char *path, const char *sql, char *buf, size_t len)
{
    sqlite3 *db = NULL;
    sqlite3_stmt *st = NULL;
    int rc = sqlite3_open_v2(path, &db, SQLITE_OPEN_READWRITE, NULL);

    buf[0] = '\0';
    if (rc == SQLITE_OK)
        rc = sqlite3_prepare_v2(db, sql, -1, &st, NULL);
    if (rc == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW && sqlite3_column_text(st, 0))
        snprintf(buf, len, "%s", (const char *)sqlite3_column_text(st, 0));
    sqlite3_finalize(st);
    sqlite3_close(db);
    return rc;
}

static void remove_db(const char *path)
{
    static const char *const ext[] = {"", "-wal", "-shm", ".lock"};
    char p[700];

    for (int i = 0; i < 4; i++) {
        snprintf(p, sizeof p, "%s%s", path, ext[i]);
        unlink(p);
    }
}

static long long file_size(const char *path)
{
    struct stat st;

    return stat(path, &st) == 0 ? (long long)st.st_size : -1;
}

/* What the on_error callback saw. */
typedef struct seen {
    int calls;
    store_error last;
} seen;

static void on_error(void *ctx, const store_error *e)
{
    seen *w = ctx;

    w->calls++;
    w->last = *e;
}

static int open_with(store **s, const char *path, int busy_ms, seen *w, char *err, size_t n)
{
    store_settings set;

    store_default_settings(&set);
    set.path = path;
    if (busy_ms > 0)
        set.busy_timeout_ms = busy_ms;
    set.on_error = w ? on_error : NULL;
    set.on_error_ctx = w;
    return store_open_with(s, &set, NULL, err, n);
}

/* ---- kinds -------------------------------------------------------------- */

static void test_names(void)
{
    static const struct {
        int rc;
        const char *token;
        int db;
    } t[] = {{STORE_OK, "ok", 0},          {STORE_NOT_FOUND, "not_found", 0},
             {STORE_CONFLICT, "conflict", 0}, {STORE_NOMEM, "nomem", 0},
             {STORE_ERROR, "error", 1},    {STORE_FULL, "full", 1},
             {STORE_BUSY, "busy", 1},      {STORE_CORRUPT, "corrupt", 1},
             {STORE_READONLY, "readonly", 1}, {STORE_IOERR, "ioerr", 1},
             {STORE_IN_USE, "in_use", 1},  {STORE_GONE, "gone", 1},
             {STORE_INVALID, "invalid", 0}, {STORE_UNAVAILABLE, "unavailable", 1},
             {STORE_TIMEOUT, "db_timeout", 1}};

    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
        CHECK(!strcmp(store_rc_name(t[i].rc), t[i].token), "token of %d: %s", t[i].rc,
              store_rc_name(t[i].rc));
        CHECK(store_is_db_error(t[i].rc) == t[i].db, "is_db_error(%s)", t[i].token);
        CHECK(store_strerror(t[i].rc)[0] != '\0', "sentence of %s", t[i].token);
    }
    CHECK(STORE_RC_MIN == STORE_TIMEOUT, "STORE_RC_MIN is the lowest code");
    CHECK(!strcmp(store_rc_name(1), "unknown") && !strcmp(store_rc_name(-99), "unknown"),
          "unknown token");
    CHECK(!strcmp(store_strerror(-99), "unknown store error"), "unknown sentence");
    CHECK(strstr(store_strerror(STORE_FULL), "full") != NULL, "FULL sentence");
}

/* PostgreSQL: SQLSTATE and a lost session → kind (store_pg_kind). */
static void test_pg_kind_table(void)
{
    static const struct {
        const char *state;
        int bad, kind;
    } t[] = {
        {"57P01", 0, STORE_UNAVAILABLE}, {"08006", 0, STORE_UNAVAILABLE},
        {"53300", 0, STORE_UNAVAILABLE}, {NULL, 1, STORE_UNAVAILABLE},
        {"42P01", 1, STORE_UNAVAILABLE}, {"53100", 0, STORE_FULL},
        {"25006", 0, STORE_READONLY},    {"42501", 0, STORE_READONLY},
        {"55P03", 0, STORE_BUSY},        {"57014", 0, STORE_BUSY},
        {"40P01", 0, STORE_BUSY},        {"XX001", 0, STORE_CORRUPT},
        {"58030", 0, STORE_IOERR},       {"23505", 0, STORE_ERROR},
        {"", 0, STORE_ERROR},            {NULL, 0, STORE_ERROR},
    };

    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
        CHECK(store_pg_kind(t[i].state, t[i].bad) == t[i].kind, "SQLSTATE %s bad %d → %s, got %s",
              t[i].state ? t[i].state : "(none)", t[i].bad, store_rc_name(t[i].kind),
              store_rc_name(store_pg_kind(t[i].state, t[i].bad)));
}

static void test_code_table(void)
{
    static const struct {
        int sqlite_rc, sys_errno, kind;
    } t[] = {
        {SQLITE_NOMEM, 0, STORE_NOMEM},          {SQLITE_IOERR_NOMEM, 0, STORE_NOMEM},
        {SQLITE_FULL, ENOSPC, STORE_FULL},       {SQLITE_IOERR_WRITE, ENOSPC, STORE_FULL},
        {SQLITE_IOERR_FSYNC, EDQUOT, STORE_FULL}, {SQLITE_IOERR_WRITE, EIO, STORE_IOERR},
        {SQLITE_IOERR_READ, 0, STORE_IOERR},     {SQLITE_IOERR_WRITE, EROFS, STORE_READONLY},
        {SQLITE_BUSY, 0, STORE_BUSY},            {SQLITE_BUSY_SNAPSHOT, 0, STORE_BUSY},
        {SQLITE_LOCKED, 0, STORE_BUSY},          {SQLITE_CORRUPT, 0, STORE_CORRUPT},
        {SQLITE_CORRUPT_INDEX, 0, STORE_CORRUPT}, {SQLITE_NOTADB, 0, STORE_CORRUPT},
        {SQLITE_READONLY, 0, STORE_READONLY},    {SQLITE_READONLY_DBMOVED, 0, STORE_GONE},
        {SQLITE_PERM, 0, STORE_READONLY},        {SQLITE_CANTOPEN, EACCES, STORE_READONLY},
        {SQLITE_CANTOPEN, EROFS, STORE_READONLY}, {SQLITE_CANTOPEN, ENOSPC, STORE_FULL},
        {SQLITE_CANTOPEN, ENOENT, STORE_ERROR},  {SQLITE_CANTOPEN, 0, STORE_ERROR},
        {SQLITE_ERROR, 0, STORE_ERROR},          {SQLITE_CONSTRAINT, 0, STORE_ERROR},
        {SQLITE_OK, 0, STORE_OK},                {SQLITE_DONE, 0, STORE_OK}};

    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
        int k = store_sqlite_kind(t[i].sqlite_rc, t[i].sys_errno);
        CHECK(k == t[i].kind, "SQLite %d (%s) errno %d -> %s, want %s", t[i].sqlite_rc,
              sqlite3_errstr(t[i].sqlite_rc), t[i].sys_errno, store_rc_name(k),
              store_rc_name(t[i].kind));
    }
}

static void test_invalid(const char *dir)
{
    store_settings set;
    store *s = NULL;
    store_job page[1];
    char path[600], err[256];
    int n, more;

    store_default_settings(&set);
    CHECK(set.busy_timeout_ms == 5000 && set.quick_check == 1 && set.on_error == NULL,
          "default settings");
    CHECK(store_open_with(&s, &set, NULL, err, sizeof err) == STORE_INVALID && s == NULL &&
              strstr(err, "no database path") != NULL, "no path: '%s'", err);
    CHECK(store_open_with(&s, NULL, NULL, NULL, 0) == STORE_INVALID, "no settings");
    snprintf(path, sizeof path, "%s/inv.db", dir);
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_OK, "open: %s", err);
    if (s == NULL)
        return;
    CHECK(store_submit(s, "abc", "{}", 2, 1, 1, NULL, NULL) == STORE_INVALID, "short id");
    CHECK(store_list(s, 0, STORE_N_STATES, 1, page, &n, &more) == STORE_INVALID, "bad filter");
    {
        store_error e;
        CHECK(store_last_error(s, &e) == STORE_OK && e.seq == 0, "INVALID is not recorded");
    }
    store_close(s);
    remove_db(path);
}

/* Another connection holds the write lock: STORE_BUSY after the timeout,
 * with SQLite's text, recorded and passed to the callback. */
static void test_busy(const char *dir)
{
    store *s = NULL;
    sqlite3 *other = NULL;
    store_error e;
    seen w;
    char path[600], err[256];

    memset(&w, 0, sizeof w);
    snprintf(path, sizeof path, "%s/busy.db", dir);
    CHECK(open_with(&s, path, 100, &w, err, sizeof err) == STORE_OK, "open: %s", err);
    if (s == NULL)
        return;
    CHECK(submit(s, 1, 10) == STORE_OK, "submit before");
    CHECK(sqlite3_open(path, &other) == SQLITE_OK &&
              sqlite3_exec(other, "BEGIN IMMEDIATE", NULL, NULL, NULL) == SQLITE_OK,
          "another connection takes the write lock");
    CHECK(submit(s, 2, 11) == STORE_BUSY, "submit while locked: STORE_BUSY");
    CHECK(w.calls == 1 && w.last.rc == STORE_BUSY && !strcmp(w.last.op, "submit") &&
              (w.last.backend_rc & 0xff) == SQLITE_BUSY && strstr(w.last.text, "locked") != NULL &&
              w.last.seq == 1,
          "callback: calls %d rc %s op '%s' text '%s'", w.calls, store_rc_name(w.last.rc),
          w.last.op, w.last.text);
    CHECK(store_last_error(s, &e) == STORE_BUSY && e.seq == 1 && !strcmp(e.text, w.last.text),
          "store_last_error: '%s'", e.text);
    CHECK(store_check_writable(s) == STORE_BUSY, "check_writable: STORE_BUSY");
    CHECK(store_health(s) == STORE_BUSY, "health: STORE_BUSY");
    CHECK(store_last_error(s, &e) == STORE_BUSY && e.seq == 3 && !strcmp(e.op, "health"),
          "seq counts failures: %llu op '%s'", e.seq, e.op);
    sqlite3_exec(other, "ROLLBACK", NULL, NULL, NULL);
    sqlite3_close(other);
    CHECK(submit(s, 2, 12) == STORE_OK && store_health(s) == STORE_OK, "after the lock is gone");
    CHECK(w.calls == 3, "no callback for successes (%d)", w.calls);
    store_close(s);
    remove_db(path);
}

/* The database at its size limit: SQLite's own SQLITE_FULL ("database or
 * disk is full") as STORE_FULL.  White box: the limit is set on the store's
 * writer connection (PRAGMA max_page_count), as a full disk would be. */
static void test_full(const char *dir)
{
    store *s = NULL;
    store_error e;
    seen w;
    char path[600], err[256], id[65], *big = malloc(1u << 20);
    int rc;

    memset(&w, 0, sizeof w);
    snprintf(path, sizeof path, "%s/full.db", dir);
    CHECK(big != NULL && open_with(&s, path, 0, &w, err, sizeof err) == STORE_OK, "open: %s", err);
    if (s == NULL || big == NULL) {
        free(big);
        store_close(s);
        return;
    }
    memset(big, 'x', 1u << 20);
    CHECK(submit(s, 1, 1) == STORE_OK, "a small job fits");
    {
        store_sqlite *q = s->impl;
        CHECK(sqlite3_exec(q->writer.db, "PRAGMA max_page_count = 64", NULL, NULL, NULL) ==
                  SQLITE_OK, "limit the database to 64 pages");
    }
    make_id(2, id);
    rc = store_submit(s, id, big, 1u << 20, 1, 2, NULL, NULL);
    CHECK(rc == STORE_FULL, "a 1 MB request: %s", store_rc_name(rc));
    CHECK(store_last_error(s, &e) == STORE_FULL && (e.backend_rc & 0xff) == SQLITE_FULL &&
              strstr(e.text, "full") != NULL && !strcmp(e.op, "submit") && w.calls == 1,
          "recorded: '%s' (%s), %d callback", e.text, e.op, w.calls);
    CHECK(submit(s, 3, 3) == STORE_OK, "a small job still fits after the rollback");
    store_close(s);
    free(big);
    remove_db(path);
}

/* A file size limit (RLIMIT_FSIZE, in a child so the limit stays there):
 * write(2) fails with EFBIG, SQLite says "disk I/O error": STORE_IOERR. */
static void test_ioerr(const char *dir)
{
    char path[600];
    pid_t pid;
    int status = -1;

    snprintf(path, sizeof path, "%s/ioerr.db", dir);
    fflush(stdout);
    pid = fork();
    if (pid == 0) {
        store *s = NULL;
        store_error e;
        struct rlimit rl = {256 * 1024, 256 * 1024};
        size_t n = 1u << 20;
        char *big = malloc(n + 1), id[65], err[256];
        int rc;

        signal(SIGXFSZ, SIG_IGN);
        if (big == NULL || store_open(&s, path, NULL, err, sizeof err) != STORE_OK)
            _exit(2);
        memset(big, 'x', n);
        big[n] = '\0';
        make_id(7, id);
        if (setrlimit(RLIMIT_FSIZE, &rl) != 0)
            _exit(3);
        rc = store_submit(s, id, big, n, 1, 1, NULL, NULL);
        store_last_error(s, &e);
        printf("file size limit: %s / %s: %s (SQLite %d, errno %d)\n", store_rc_name(rc), e.op,
               e.text, e.backend_rc, e.sys_errno);
        fflush(stdout);
        _exit(rc == STORE_IOERR && e.rc == STORE_IOERR && strstr(e.text, "I/O") ? 0 : 4);
    }
    CHECK(pid > 0 && waitpid(pid, &status, 0) == pid && WIFEXITED(status) &&
              WEXITSTATUS(status) == 0,
          "a write past the file size limit is STORE_IOERR (child status %d)", status);
    remove_db(path);
}

/* ---- the exclusive database ---------------------------------------------- */

static void test_exclusive(const char *dir)
{
    store *a = NULL, *b = NULL;
    char path[600], err[512], want[64], buf[64];
    int fds[2], status = -1, requeued = -1;
    pid_t pid;

    snprintf(path, sizeof path, "%s/excl.db", dir);
    CHECK(store_open(&a, path, NULL, err, sizeof err) == STORE_OK, "first open: %s", err);
    if (a == NULL)
        return;
    /* a second store in this process */
    CHECK(store_open(&b, path, NULL, err, sizeof err) == STORE_IN_USE && b == NULL,
          "second store in this process refused");
    snprintf(want, sizeof want, "pid %ld", (long)getpid());
    CHECK(strstr(err, path) != NULL && strstr(err, want) != NULL && strstr(err, "in use"),
          "refusal names the file and the holder: '%s'", err);
    /* a second process */
    fflush(stdout);
    pid = fork();
    if (pid == 0) {
        store *c = NULL;
        char e2[512];
        int rc = store_open(&c, path, NULL, e2, sizeof e2);
        _exit(rc == STORE_IN_USE && c == NULL && strstr(e2, path) && strstr(e2, want) ? 0 : 1);
    }
    CHECK(pid > 0 && waitpid(pid, &status, 0) == pid && WIFEXITED(status) &&
              WEXITSTATUS(status) == 0, "a second process is refused (status %d)", status);
    CHECK(submit(a, 1, 1) == STORE_OK, "the first store still works");
    store_close(a);
    a = NULL;

    /* a holder killed with -9 while it runs a job */
    CHECK(pipe(fds) == 0, "pipe");
    fflush(stdout);
    pid = fork();
    if (pid == 0) {
        store *c = NULL;
        store_job j;
        char e2[256];
        close(fds[0]);
        if (store_open(&c, path, NULL, e2, sizeof e2) != STORE_OK ||
            store_claim_next(c, 5, &j) != STORE_OK)
            _exit(1);
        if (write(fds[1], "r", 1) != 1)
            _exit(2);
        for (;;)
            pause();
    }
    close(fds[1]);
    CHECK(pid > 0 && read(fds[0], buf, 1) == 1, "child holds the store with a running job");
    close(fds[0]);
    snprintf(want, sizeof want, "pid %ld", (long)pid);
    CHECK(store_open(&b, path, &requeued, err, sizeof err) == STORE_IN_USE && b == NULL &&
              requeued == 0 && strstr(err, want) != NULL,
          "refused while the child runs: '%s'", err);
    CHECK(raw_text(path, "SELECT state FROM jobs", buf, sizeof buf) == SQLITE_OK &&
              !strcmp(buf, "running"), "the refused open left the child's job running (%s)", buf);
    kill(pid, SIGKILL);
    CHECK(waitpid(pid, &status, 0) == pid && WIFSIGNALED(status), "child killed");
    CHECK(store_open(&b, path, &requeued, err, sizeof err) == STORE_OK && requeued == 1,
          "after kill -9 the file opens and the job is requeued (%d): %s", requeued, err);
    CHECK(raw_text(path, "PRAGMA journal_mode", buf, sizeof buf) == SQLITE_OK &&
              !strcmp(buf, "wal"), "still WAL (%s)", buf);
    store_close(b);
    remove_db(path);
}

/* ---- corruption ----------------------------------------------------------- */

/* A database of 40 done jobs with 8 KB results, closed. */
static int make_db(const char *path, int jobs)
{
    store *s = NULL;
    store_job j;
    char id[65], err[256], *res = malloc(8001);
    int ok = res != NULL && store_open(&s, path, NULL, err, sizeof err) == STORE_OK;

    if (res)
        memset(res, 'r', 8000);
    for (int i = 1; ok && i <= jobs; i++) {
        make_id((unsigned)i, id);
        ok = submit(s, (unsigned)i, i) == STORE_OK && store_claim_next(s, i, &j) == STORE_OK &&
             store_finish(s, id, STORE_DONE, 100 + i, 11, NULL, res, 8000, NULL, 0) == STORE_OK;
        store_job_clear(&j);
    }
    store_close(s);
    free(res);
    return ok;
}

/* Overwrite n bytes at off with a pattern. */
static int scribble(const char *path, long off, size_t n)
{
    FILE *f = fopen(path, "r+b");
    int ok = f != NULL && fseek(f, off, SEEK_SET) == 0;

    for (size_t i = 0; ok && i < n; i++)
        ok = fputc(0xa5 ^ (int)(i & 0x3f), f) != EOF;
    if (f)
        ok = fclose(f) == 0 && ok;
    return ok;
}

static void test_corrupt(const char *dir)
{
    store *s = NULL;
    char path[600], err[512];
    long long size;

    snprintf(path, sizeof path, "%s/corrupt.db", dir);
    /* a garbage page in the middle */
    CHECK(make_db(path, 40), "make db");
    size = file_size(path);
    CHECK(size > 40 * 8000, "db of %lld bytes", size);
    CHECK(scribble(path, (long)(size / 4096 / 2) * 4096, 4096), "scribble a page");
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_CORRUPT && s == NULL,
          "garbage page refused");
    CHECK(strstr(err, path) != NULL && strstr(err, "corrupt") != NULL, "sentence: '%s'", err);
    printf("corrupt page: %s\n", err);
    CHECK(file_size(path) == size, "the refused file is left as it was");
    remove_db(path);

    /* truncated to half */
    CHECK(make_db(path, 40), "make db");
    size = file_size(path);
    CHECK(truncate(path, (off_t)(size / 2 / 4096 * 4096)) == 0, "truncate");
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_CORRUPT && s == NULL,
          "truncated file refused: '%s'", err);
    printf("truncated: %s\n", err);
    remove_db(path);

    /* garbage header */
    CHECK(make_db(path, 3), "make db");
    CHECK(scribble(path, 0, 100), "scribble the header");
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_CORRUPT && s == NULL &&
              strstr(err, "is not a SQLite database") != NULL, "garbage header: '%s'", err);
    remove_db(path);

    /* a sound database passes the check */
    CHECK(make_db(path, 5), "make db");
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_OK, "sound db opens: %s", err);
    store_close(s);
    remove_db(path);
}

/* ---- health --------------------------------------------------------------- */

static void test_health(const char *dir)
{
    store *s = NULL;
    store_error e;
    seen w;
    char path[600], other[700], lock[700], err[256];
    int rc;

    memset(&w, 0, sizeof w);
    snprintf(path, sizeof path, "%s/health.db", dir);
    snprintf(lock, sizeof lock, "%s.lock", path);
    snprintf(other, sizeof other, "%s/other.db", dir);

    /* deleted */
    CHECK(open_with(&s, path, 0, &w, err, sizeof err) == STORE_OK, "open: %s", err);
    if (s == NULL)
        return;
    CHECK(submit(s, 1, 1) == STORE_OK && store_health(s) == STORE_OK, "healthy");
    CHECK(unlink(path) == 0, "unlink the database");
    CHECK(store_health(s) == STORE_GONE, "health after unlink: STORE_GONE");
    CHECK(store_last_error(s, &e) == STORE_GONE && strstr(e.text, "deleted") && strstr(e.text, path),
          "text: '%s'", e.text);
    rc = submit(s, 2, 2);
    CHECK(rc == STORE_GONE, "a write after unlink: %s (%s)", store_rc_name(rc), w.last.text);
    store_close(s);
    s = NULL;
    remove_db(path);

    /* replaced by another file */
    CHECK(make_db(other, 1), "another db");
    CHECK(open_with(&s, path, 0, &w, err, sizeof err) == STORE_OK, "open: %s", err);
    if (s == NULL)
        return;
    CHECK(rename(other, path) == 0, "rename another file over the database");
    CHECK(store_health(s) == STORE_GONE, "health after replace: STORE_GONE");
    CHECK(store_last_error(s, &e) == STORE_GONE && strstr(e.text, "replaced"), "text: '%s'",
          e.text);
    rc = submit(s, 3, 3);
    CHECK(rc == STORE_GONE, "a write after replace: %s (%s)", store_rc_name(rc), w.last.text);
    store_close(s);
    s = NULL;
    remove_db(path);
    remove_db(other);

    /* the lock file deleted */
    CHECK(open_with(&s, path, 0, &w, err, sizeof err) == STORE_OK, "open: %s", err);
    if (s == NULL)
        return;
    CHECK(unlink(lock) == 0 && store_health(s) == STORE_GONE, "health without the lock file");
    CHECK(store_last_error(s, &e) == STORE_GONE && strstr(e.text, "lock file"), "text: '%s'",
          e.text);
    store_close(s);
    remove_db(path);
}

/* ---- retention ------------------------------------------------------------ */

enum { P_DONE = 50, P_RUNNING = 5, P_QUEUED = 5, P_RESULT = 8000 };

/* When finished job n (1 … P_DONE) ended: a permutation of 1000 … 1049,
 * so the age order is not the submission order. */
static double ended(unsigned n)
{
    return 1000.0 + (double)((n * 37u) % P_DONE);
}

/* 1 when job n exists. */
static int present(store *s, unsigned n)
{
    store_job j;
    char id[65];
    int rc;

    make_id(n, id);
    rc = store_get(s, id, 0, &j);
    store_job_clear(&j);
    return rc == STORE_OK;
}

/* Check that exactly the finished jobs that ended at or after `from` remain, and every
 * running and queued one. */
static void check_remaining(store *s, double from, const char *what)
{
    int wrong = 0, live = 0;

    for (unsigned n = 1; n <= P_DONE; n++) {
        int want = ended(n) >= from;
        if (present(s, n) != want)
            wrong++;
    }
    for (unsigned n = P_DONE + 1; n <= P_DONE + P_RUNNING + P_QUEUED; n++)
        live += present(s, n);
    CHECK(wrong == 0 && live == P_RUNNING + P_QUEUED,
          "%s: finished jobs ended >= %.0f remain (%d wrong), queued/running all (%d)", what,
          from, wrong, live);
}

static void test_prune(const char *dir)
{
    store *s = NULL;
    store_job j;
    char path[600], id[65], err[256], *res = malloc(P_RESULT);
    long long removed = -1, live0, file0, live1, file1, bound, disk0, disk1;
    int ok = 1;

    snprintf(path, sizeof path, "%s/prune.db", dir);
    CHECK(res != NULL && store_open(&s, path, NULL, err, sizeof err) == STORE_OK, "open: %s", err);
    if (s == NULL || res == NULL) {
        free(res);
        store_close(s);
        return;
    }
    memset(res, 'p', P_RESULT);
    for (unsigned n = 1; n <= P_DONE; n++) {
        make_id(n, id);
        ok = ok && submit(s, n, n) == STORE_OK && store_claim_next(s, n, &j) == STORE_OK &&
             store_finish(s, id, n % 3 ? STORE_DONE : n % 2 ? STORE_FAILED : STORE_CANCELED,
                          ended(n), 1, NULL, res, P_RESULT, NULL, 0) == STORE_OK;
        store_job_clear(&j);
    }
    for (unsigned n = P_DONE + 1; n <= P_DONE + P_RUNNING + P_QUEUED; n++)
        ok = ok && submit(s, n, n) == STORE_OK;
    for (int k = 0; k < P_RUNNING; k++) {
        ok = ok && store_claim_next(s, 2000, &j) == STORE_OK;
        store_job_clear(&j);
    }
    CHECK(ok, "50 finished, 5 running, 5 queued");

    CHECK(store_prune(s, 3000, 0, 0, &removed) == STORE_OK && removed == 0, "no bounds: none");
    /* age: ended before 3000 - 1975 = 1025 */
    CHECK(store_prune(s, 3000, 1975, 0, &removed) == STORE_OK && removed == 25,
          "age bound removes 25 (%lld)", removed);
    check_remaining(s, 1025, "after the age bound");

    /* size: about ten results over the bound */
    CHECK(store_size(s, &live0, &file0) == STORE_OK && live0 > 25 * P_RESULT,
          "size %lld live, %lld file", live0, file0);
    store_close(s);   /* checkpoint: the file on disk is the database */
    s = NULL;
    disk0 = file_size(path);
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_OK, "reopen: %s", err);
    if (s == NULL) {
        free(res);
        return;
    }
    for (int k = 0; k < P_RUNNING; k++) {   /* the reopen requeued them */
        CHECK(store_claim_next(s, 2000, &j) == STORE_OK, "claim again");
        store_job_clear(&j);
    }
    bound = live0 - 10 * P_RESULT;
    CHECK(store_prune(s, 3000, 0, bound, &removed) == STORE_OK && removed >= 10 && removed < 15,
          "size bound removes the oldest ~10 (%lld)", removed);
    CHECK(store_size(s, &live1, &file1) == STORE_OK && live1 <= bound && file1 == live1,
          "under the bound (%lld <= %lld), free pages given back (file %lld)", live1, bound, file1);
    check_remaining(s, 1025 + (double)removed, "after the size bound");
    disk1 = file_size(path);
    CHECK(disk1 < disk0, "the file shrank: %lld -> %lld bytes", disk0, disk1);
    printf("prune: live %lld -> %lld bytes (bound %lld), file %lld -> %lld bytes, %lld jobs\n",
           live0, live1, bound, disk0, disk1, removed);

    /* a bound nothing finished can meet: every finished job goes, nothing else */
    {
        long long before = removed;
        CHECK(store_prune(s, 3000, 0, 1, &removed) == STORE_OK && removed == 25 - before,
              "size bound 1 removes the other %lld (%lld)", 25 - before, removed);
    }
    check_remaining(s, 1e9, "after size bound 1");
    {
        long long counts[STORE_N_STATES];
        int rc = store_count(s, counts);
        CHECK(rc == STORE_OK && counts[STORE_RUNNING] == P_RUNNING &&
                  counts[STORE_QUEUED] == P_QUEUED && counts[STORE_DONE] == 0 &&
                  counts[STORE_FAILED] == 0 && counts[STORE_CANCELED] == 0,
              "only queued and running remain: %s %lld %lld %lld %lld %lld", store_rc_name(rc),
              counts[0], counts[1], counts[2], counts[3], counts[4]);
    }
    store_close(s);
    free(res);
    remove_db(path);
}

int main(void)
{
    char tmpl[512];
    const char *tmp = getenv("TMPDIR");

    snprintf(tmpl, sizeof tmpl, "%s/test_store_faults.XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (mkdtemp(tmpl) == NULL) {
        perror("mkdtemp");
        return 1;
    }
    test_names();
    test_code_table();
    test_pg_kind_table();
    test_invalid(tmpl);
    test_busy(tmpl);
    test_full(tmpl);
    test_ioerr(tmpl);
    test_exclusive(tmpl);
    test_corrupt(tmpl);
    test_health(tmpl);
    test_prune(tmpl);
    if (rmdir(tmpl) != 0)
        perror("rmdir");
    printf("%d checks, %d failures\n", checks, failures);
    return failures ? 1 : 0;
}
