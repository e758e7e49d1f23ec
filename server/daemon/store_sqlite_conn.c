/*
 * store_sqlite_conn.c — the SQLite backend's connections: error kinds from
 * SQLite's codes, the statement cache, the reader pool and the writer, and
 * the waits for them within a call's deadline (store_sqlite.h).  The job
 * operations on top of it are store_sqlite.c; opening and migrations
 * store_sqlite_open.c; the probes and retention store_sqlite_file.c.
 *
 * Connections.  One writer connection, guarded by a mutex, runs every write
 * transaction (BEGIN IMMEDIATE … COMMIT); SQLite allows one writer at a time
 * anyway, and serialising writers in-process hands the lock over on a mutex
 * instead of sleeping in SQLite's busy handler.  The busy timeout (5 s by
 * default) is still there for writers of other processes (a sqlite3 shell,
 * a backup).  STORE_SQLITE_READERS reader connections, handed out under a
 * mutex + condition variable, serve reads; in WAL mode they never wait for
 * the writer.  Every connection is opened SQLITE_OPEN_NOMUTEX: it is only
 * ever used by the one thread that holds it.  Each connection caches its
 * prepared statements (prepared on first use), so a GET is one bind + step
 * on a warm statement.
 *
 * Deadlines (store.h, DESIGN.md §F).  A call waits for what it needs within
 * its deadline (store_settings.timeout_ms; a probe's probe_timeout_ms),
 * then fails with STORE_BUSY, recorded: a reader while all are in use
 * (a timed wait on the pool's condition variable), the writer's mutex
 * while this process's other writes hold it (a timed lock), and another
 * process's write lock (SQLite's busy timeout, set before each BEGIN to what
 * is left of the deadline, at most busy_ms).  Before, 12 submissions behind
 * another process's write lock waited the whole busy timeout each in turn.
 *
 * Every write transaction first checks that the path still names the file
 * opened (store_sqlite_same_file): SQLite in WAL mode goes on committing to
 * a deleted or replaced file, and those commits would be lost.
 *
 * Errors.  Every failing SQLite call goes through store_sqlite_fail while
 * the connection is still held and before a ROLLBACK can replace its
 * message: SQLite's extended code, errno and sqlite3_errmsg text are
 * recorded (store_note_error) with the operation's name, and the code is
 * mapped to a kind (store_sqlite_kind).
 */
#include "store_sqlite.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

/* ---- errors --------------------------------------------------------------- */

int store_sqlite_kind(int rc, int sys_errno)
{
    int errno_kind = store_errno_kind(sys_errno);

    switch (rc & 0xff) {
    case SQLITE_OK:
    case SQLITE_ROW:
    case SQLITE_DONE:
        return STORE_OK;
    case SQLITE_NOMEM:
        return STORE_NOMEM;
    case SQLITE_FULL:
        return STORE_FULL;
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
        return STORE_BUSY;
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB:
        return STORE_CORRUPT;
    case SQLITE_READONLY:
        /* DBMOVED: the file was unlinked or replaced under the connection */
        return rc == SQLITE_READONLY_DBMOVED ? STORE_GONE : STORE_READONLY;
    case SQLITE_PERM:
        return STORE_READONLY;
    case SQLITE_CANTOPEN:
        /* the file or a -wal/-shm/temp file beside it: the errno says why */
        return errno_kind == STORE_OK ? STORE_ERROR : errno_kind;
    case SQLITE_IOERR:
        if (rc == SQLITE_IOERR_NOMEM)
            return STORE_NOMEM;
        return errno_kind == STORE_FULL || errno_kind == STORE_READONLY ? errno_kind : STORE_IOERR;
    default:
        return STORE_ERROR;
    }
}

int store_sqlite_fail(store_conn *c, int rc)
{
    int e = c->db ? sqlite3_system_errno(c->db) : 0;
    int kind = store_sqlite_kind(rc, e);
    const char *text = c->db ? sqlite3_errmsg(c->db) : sqlite3_errstr(rc);

    if (kind == STORE_OK)
        kind = STORE_ERROR;   /* a caller's "failure" SQLite did not see */
    return store_note_error(c->owner, kind, rc, e, c->op, text);
}

int store_sqlite_same_file(store *s, const char *path, dev_t dev, ino_t ino, const char *what,
                           const char *op)
{
    struct stat st;
    char text[256];
    int e;

    if (stat(path, &st) != 0) {
        e = errno;
        if (e != ENOENT && e != ENOTDIR) {
            snprintf(text, sizeof text, "cannot look at %s '%s': %s", what, path, strerror(e));
            return store_note_error(s, store_errno_kind(e), 0, e, op, text);
        }
        snprintf(text, sizeof text, "%s '%s' was deleted while the store had it open", what, path);
        return store_note_error(s, STORE_GONE, 0, e, op, text);
    }
    if (st.st_dev != dev || st.st_ino != ino) {
        snprintf(text, sizeof text, "%s '%s' was replaced by another file while the store had "
                 "it open", what, path);
        return store_note_error(s, STORE_GONE, 0, 0, op, text);
    }
    return STORE_OK;
}

/* ---- statements ----------------------------------------------------------- */

sqlite3_stmt *store_sqlite_stmt(store_conn *c, int k, int *rc)
{
    if (c->stmt[k] == NULL) {
        *rc = sqlite3_prepare_v3(c->db, store_sqlite_sql[k], -1, SQLITE_PREPARE_PERSISTENT,
                                 &c->stmt[k], NULL);
        if (*rc != SQLITE_OK) {
            c->stmt[k] = NULL;
            return NULL;
        }
    }
    *rc = SQLITE_OK;
    return c->stmt[k];
}

void store_sqlite_stmt_done(sqlite3_stmt *st)
{
    if (st == NULL)
        return;
    (void)sqlite3_reset(st);
    (void)sqlite3_clear_bindings(st);
}

int store_sqlite_exec(store_conn *c, int k)
{
    int rc;
    sqlite3_stmt *st = store_sqlite_stmt(c, k, &rc);

    if (st == NULL)
        return rc;
    rc = sqlite3_step(st);
    store_sqlite_stmt_done(st);
    return rc == SQLITE_DONE || rc == SQLITE_ROW ? SQLITE_OK : rc;
}

void store_sqlite_rollback(store_conn *c)
{
    if (!sqlite3_get_autocommit(c->db))
        (void)store_sqlite_exec(c, STMT_ROLLBACK);
}

void store_sqlite_conn_close(store_conn *c)
{
    for (int k = 0; k < STMT_N; k++) {
        if (c->stmt[k] != NULL)
            (void)sqlite3_finalize(c->stmt[k]);
        c->stmt[k] = NULL;
    }
    if (c->db != NULL)
        (void)sqlite3_close(c->db);
    c->db = NULL;
}

/* ---- the pool ------------------------------------------------------------- */

int store_sqlite_reader_acquire(store *s, const char *op, int ms, store_conn **out)
{
    store_sqlite *q = s->impl;
    struct timespec until = store_wall_in(ms);
    char text[128];
    int e = 0;

    *out = NULL;
    if (pthread_mutex_lock(&q->pool_lock) != 0)
        return store_note_error(s, STORE_ERROR, 0, 0, op, "cannot take a reader connection");
    while (q->free_readers == NULL && e == 0)
        e = pthread_cond_timedwait(&q->pool_cond, &q->pool_lock, &until);
    if (q->free_readers == NULL) {
        (void)pthread_mutex_unlock(&q->pool_lock);
        snprintf(text, sizeof text, "every reader connection stayed in use for %d ms", ms);
        return store_note_error(s, e == ETIMEDOUT ? STORE_BUSY : STORE_ERROR, 0, 0, op, text);
    }
    *out = q->free_readers;
    q->free_readers = (*out)->next;
    (void)pthread_mutex_unlock(&q->pool_lock);
    (*out)->op = op;
    return STORE_OK;
}

void store_sqlite_reader_release(store *s, store_conn *c)
{
    store_sqlite *q = s->impl;

    (void)pthread_mutex_lock(&q->pool_lock);
    c->next = q->free_readers;
    q->free_readers = c;
    (void)pthread_cond_signal(&q->pool_cond);
    (void)pthread_mutex_unlock(&q->pool_lock);
}

/* Back to synchronous=FULL after a relaxed transaction (caller holds write_lock). */
static void writer_restore(store_sqlite *q)
{
    if (q->writer_relaxed &&
        sqlite3_exec(q->writer.db, "PRAGMA synchronous = FULL", NULL, NULL, NULL) == SQLITE_OK)
        q->writer_relaxed = 0;
}

/* BEGIN IMMEDIATE takes the write lock now, so no later statement of the
 * transaction can fail with BUSY.  durable = 0 commits with
 * synchronous=NORMAL: in WAL mode it survives a crash or kill -9 of the
 * process but may roll back on power loss.  Used for claim, finish,
 * requeue, pruning and the health probe, whose loss only means a job runs
 * again (results are deterministic) or a probe is repeated; a submission
 * and a cancel are always durable (on disk before the HTTP answer). */
int store_sqlite_writer_begin(store *s, store_conn **out, int durable, const char *op)
{
    return store_sqlite_writer_begin_within(s, out, durable, op, s->timeout_ms);
}

/* The writer's mutex within ms (this process's other writers); STORE_OK
 * or the recorded STORE_BUSY / STORE_ERROR. */
static int writer_lock(store *s, const char *op, int ms)
{
    store_sqlite *q = s->impl;
    struct timespec until = store_wall_in(ms);
    char text[160];
    int e = pthread_mutex_timedlock(&q->write_lock, &until);

    if (e == 0)
        return STORE_OK;
    if (e != ETIMEDOUT)
        return store_note_error(s, STORE_ERROR, 0, e, op, "cannot take the writer's lock");
    snprintf(text, sizeof text, "the database's writer stayed in use for %d ms (another write "
             "waits for a lock held by another process, or is slow)", ms);
    return store_note_error(s, STORE_BUSY, SQLITE_BUSY, 0, op, text);
}

int store_sqlite_writer_begin_within(store *s, store_conn **out, int durable, const char *op,
                                     int ms)
{
    store_sqlite *q = s->impl;
    double deadline = store_mono() + ms / 1000.0;
    int rc, left;

    *out = NULL;
    rc = writer_lock(s, op, ms);
    if (rc != STORE_OK)
        return rc;
    q->writer.op = op;
    /* another process's lock: SQLite's busy wait, within what is left */
    left = (int)((deadline - store_mono()) * 1000.0);
    left = left < 0 ? 0 : left > q->busy_ms ? q->busy_ms : left;
    (void)sqlite3_busy_timeout(q->writer.db, left);
    /* a commit to a deleted or replaced file would be lost at the next
     * start (SQLite in WAL mode does not notice): one stat(2), ~1 µs */
    rc = store_sqlite_same_file(s, q->path, q->db_dev, q->db_ino, "database file", op);
    if (rc != STORE_OK) {
        (void)pthread_mutex_unlock(&q->write_lock);
        return rc;
    }
    if (!durable && sqlite3_exec(q->writer.db, "PRAGMA synchronous = NORMAL", NULL, NULL,
                                 NULL) == SQLITE_OK)
        q->writer_relaxed = 1;
    rc = store_sqlite_exec(&q->writer, STMT_BEGIN);   /* waits busy_ms for other processes */
    if (rc != SQLITE_OK) {
        int kind = store_sqlite_fail(&q->writer, rc);
        writer_restore(q);
        (void)pthread_mutex_unlock(&q->write_lock);
        return kind;
    }
    *out = &q->writer;
    return STORE_OK;
}

int store_sqlite_writer_end(store *s, int status, int commit)
{
    store_sqlite *q = s->impl;
    int rc;

    if (commit) {
        rc = store_sqlite_exec(&q->writer, STMT_COMMIT);
        if (rc != SQLITE_OK) {
            status = store_sqlite_fail(&q->writer, rc);
            store_sqlite_rollback(&q->writer);
        }
    } else {
        store_sqlite_rollback(&q->writer);
    }
    writer_restore(q);
    (void)pthread_mutex_unlock(&q->write_lock);
    return status;
}
