/*
 * store.c — the durable record of every analysis job, in SQLite (store.h).
 *
 * How it fits: jobs.c records submissions, claims queued jobs for its
 * workers and records their ends here; http.c reads jobs for GETs and lists.
 * A submission is committed (WAL, synchronous=FULL: the commit is on disk)
 * before store_submit returns, so a 202 is never sent for a job a power cut
 * or kill -9 could lose.  Claims, finishes and requeues commit with
 * synchronous=NORMAL (no fsync): they survive a kill -9 of the process, and
 * a power cut can at worst roll them back, which puts the job back to
 * `queued` and runs it again (one fsync less per commit: ~1.4 ms each here).
 *
 * Connections.  One writer connection, guarded by a mutex, runs every write
 * transaction (BEGIN IMMEDIATE … COMMIT); SQLite allows one writer at a time
 * anyway, and serialising writers in-process hands the lock over on a mutex
 * instead of sleeping in SQLite's busy handler.  The busy timeout (5 s) is
 * still there for writers of other processes (a sqlite3 shell, a backup).
 * STORE_READERS reader connections, handed out under a mutex + condition
 * variable, serve reads; in WAL mode they never wait for the writer.  Every
 * connection is opened SQLITE_OPEN_NOMUTEX: it is only ever used by the one
 * thread that holds it.  Each connection caches its prepared statements
 * (prepared on first use), so a GET is one bind + step on a warm statement.
 *
 * Queue order.  seq (INTEGER PRIMARY KEY, the rowid) is both the submission
 * order and the list cursor.  A resubmitted failed/canceled job gets a new
 * seq (max + 1), so it queues last and lists as the newest; a job put back
 * by store_requeue keeps its seq and runs first again.  No second ordering
 * column is needed: claiming is "lowest seq among queued" on the index
 * jobs(state, seq).
 *
 * Schema.  PRAGMA user_version is the schema version; store_migrations[k]
 * takes a database from version k to k + 1, each in its own transaction.
 * A newer database than this code knows, a file that is not SQLite, or a
 * SQLite file of another application is refused with a sentence in err.
 * Large texts (request, result, CSV) are the last columns of a row, so
 * reading the small columns of a job never walks their overflow pages.
 *
 * No process-global state: everything lives in the store object.
 */
#include "store.h"

#include <limits.h>
#include <pthread.h>
#include <sqlite3.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum {
    STORE_READERS = 7,          /* reader connections; + 1 writer = a pool of 8 */
    STORE_BUSY_MS = 5000,       /* wait this long for another process's lock */
    STORE_APP_ID = 0x534d4f44   /* PRAGMA application_id: "SMOD" */
};

/* The migrations: store_migrations[k] brings user_version k to k + 1. */
static const char *const store_migrations[] = {
    /* 1: the jobs table.  state is the store_state_name text (readable
     * from the sqlite3 shell); times are unix seconds, NULL until they
     * happen; the large texts come last in the row. */
    "CREATE TABLE jobs ("
    " seq INTEGER PRIMARY KEY,"
    " id TEXT NOT NULL UNIQUE CHECK (length(id) = 64),"
    " state TEXT NOT NULL CHECK (state IN ('queued','running','done','failed','canceled')),"
    " speeds_total INTEGER NOT NULL,"
    " speeds_done INTEGER NOT NULL DEFAULT 0,"
    " attempts INTEGER NOT NULL DEFAULT 0,"
    " cancel_requested INTEGER NOT NULL DEFAULT 0,"
    " created_at REAL NOT NULL,"
    " started_at REAL,"
    " finished_at REAL,"
    " error TEXT,"
    " request TEXT NOT NULL,"
    " result TEXT,"
    " result_csv TEXT);"
    "CREATE INDEX jobs_state_seq ON jobs (state, seq);"
    "PRAGMA application_id = 1397575492;",   /* STORE_APP_ID */
};
#define STORE_SCHEMA_VERSION ((int)(sizeof store_migrations / sizeof store_migrations[0]))

/* Columns every job read selects, in the order job_from_row expects
 * (0 … 11); the three large texts follow as columns 12, 13, 14.
 * typeof() tells whether a result is stored without loading its text. */
#define JOB_COLS                                                                        \
    "seq, id, state, speeds_total, speeds_done, attempts, cancel_requested, created_at," \
    " started_at, finished_at, typeof(result) <> 'null', error"
#define JOB_GET(req, res, csv) "SELECT " JOB_COLS ", " req ", " res ", " csv " FROM jobs WHERE id = ?1"

/* Cached statements, one set per connection.  STMT_GET + flags (0 … 7)
 * selects the large texts asked for by STORE_WITH_*. */
enum {
    STMT_GET = 0,
    STMT_BEGIN = 8,
    STMT_COMMIT,
    STMT_ROLLBACK,
    STMT_INSERT,
    STMT_RESUBMIT,
    STMT_CLAIM,
    STMT_FINISH,
    STMT_REQUEUE,
    STMT_STATE,
    STMT_CANCEL_QUEUED,
    STMT_CANCEL_RUNNING,
    STMT_LIST_ALL,
    STMT_LIST_STATE,
    STMT_COUNT,
    STMT_N
};

static const char *const store_sql[STMT_N] = {
    JOB_GET("NULL", "NULL", "NULL"),
    JOB_GET("request", "NULL", "NULL"),
    JOB_GET("NULL", "result", "NULL"),
    JOB_GET("request", "result", "NULL"),
    JOB_GET("NULL", "NULL", "result_csv"),
    JOB_GET("request", "NULL", "result_csv"),
    JOB_GET("NULL", "result", "result_csv"),
    JOB_GET("request", "result", "result_csv"),
    /* STMT_BEGIN */ "BEGIN IMMEDIATE",
    /* STMT_COMMIT */ "COMMIT",
    /* STMT_ROLLBACK */ "ROLLBACK",
    /* STMT_INSERT */
    "INSERT INTO jobs (id, state, speeds_total, created_at, request)"
    " VALUES (?1, 'queued', ?2, ?3, ?4)",
    /* STMT_RESUBMIT: a new seq (max + 1) so the job queues last */
    "UPDATE jobs SET seq = (SELECT max(seq) FROM jobs) + 1, state = 'queued', speeds_total = ?2,"
    " speeds_done = 0, attempts = 0, cancel_requested = 0, started_at = NULL,"
    " finished_at = NULL, error = NULL, request = ?3, result = NULL, result_csv = NULL"
    " WHERE id = ?1 AND state IN ('failed', 'canceled')",
    /* STMT_CLAIM */
    "UPDATE jobs SET state = 'running', started_at = ?1, attempts = attempts + 1"
    " WHERE seq = (SELECT seq FROM jobs WHERE state = 'queued' ORDER BY seq LIMIT 1)"
    " RETURNING " JOB_COLS ", request, NULL, NULL",
    /* STMT_FINISH */
    "UPDATE jobs SET state = ?2, finished_at = ?3, speeds_done = ?4, error = ?5, result = ?6,"
    " result_csv = ?7 WHERE id = ?1 AND state = 'running'",
    /* STMT_REQUEUE: the interruption was not the job's fault; a cancel
     * request is kept, so the next worker stops the job at once */
    "UPDATE jobs SET state = 'queued', started_at = NULL, speeds_done = 0,"
    " attempts = max(attempts - 1, 0) WHERE id = ?1 AND state = 'running'",
    /* STMT_STATE */ "SELECT state FROM jobs WHERE id = ?1",
    /* STMT_CANCEL_QUEUED */
    "UPDATE jobs SET state = 'canceled', finished_at = ?2 WHERE id = ?1 AND state = 'queued'",
    /* STMT_CANCEL_RUNNING */
    "UPDATE jobs SET cancel_requested = 1 WHERE id = ?1 AND state = 'running'",
    /* STMT_LIST_ALL */
    "SELECT " JOB_COLS " FROM jobs WHERE seq < ?1 ORDER BY seq DESC LIMIT ?2",
    /* STMT_LIST_STATE */
    "SELECT " JOB_COLS " FROM jobs WHERE state = ?3 AND seq < ?1 ORDER BY seq DESC LIMIT ?2",
    /* STMT_COUNT */ "SELECT state, count(*) FROM jobs GROUP BY state",
};

/* One connection and its statement cache. */
typedef struct store_conn {
    sqlite3 *db;
    sqlite3_stmt *stmt[STMT_N];   /* prepared on first use, NULL before */
    struct store_conn *next;      /* free list of readers */
} store_conn;

struct store {
    store_conn writer;                   /* every write transaction, under write_lock */
    pthread_mutex_t write_lock;
    store_conn readers[STORE_READERS];
    store_conn *free_readers;            /* readers not in use, under pool_lock */
    pthread_mutex_t pool_lock;
    pthread_cond_t pool_cond;            /* signalled when a reader is returned */
    int locks_ready;                     /* 1 once the mutexes and condvar exist */
    int version;                         /* user_version after the migrations */
    int writer_relaxed;                  /* 1 while the writer runs synchronous=NORMAL */
};

static const char *const store_state_names[STORE_N_STATES] = {
    "queued", "running", "done", "failed", "canceled"};

const char *store_state_name(store_state s)
{
    if ((int)s < 0 || s >= STORE_N_STATES)
        return "unknown";
    return store_state_names[s];
}

int store_state_parse(const char *name, store_state *out)
{
    if (name == NULL)
        return STORE_NOT_FOUND;
    for (int i = 0; i < STORE_N_STATES; i++) {
        if (strcmp(name, store_state_names[i]) == 0) {
            if (out)
                *out = (store_state)i;
            return STORE_OK;
        }
    }
    return STORE_NOT_FOUND;
}

void store_job_clear(store_job *j)
{
    if (j == NULL)
        return;
    free(j->request);
    free(j->error);
    free(j->result);
    free(j->result_csv);
    memset(j, 0, sizeof *j);
}

/* ---- small helpers ------------------------------------------------------ */

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static void store_seterr(char *err, size_t errlen, const char *fmt, ...)
{
    va_list ap;

    if (err == NULL || errlen == 0)
        return;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}

/* SQLite result code → store_rc. */
static int store_rc_of(int rc)
{
    return (rc & 0xff) == SQLITE_NOMEM ? STORE_NOMEM : STORE_ERROR;
}

/* The cached statement k of c, prepared on first use; NULL on failure
 * (*rc receives the SQLite code). */
static sqlite3_stmt *conn_stmt(store_conn *c, int k, int *rc)
{
    if (c->stmt[k] == NULL) {
        *rc = sqlite3_prepare_v3(c->db, store_sql[k], -1, SQLITE_PREPARE_PERSISTENT, &c->stmt[k],
                                 NULL);
        if (*rc != SQLITE_OK) {
            c->stmt[k] = NULL;
            return NULL;
        }
    }
    *rc = SQLITE_OK;
    return c->stmt[k];
}

/* Make a statement ready for its next use: end its read, drop bindings
 * (they may point into the caller's buffers). */
static void stmt_done(sqlite3_stmt *st)
{
    if (st == NULL)
        return;
    (void)sqlite3_reset(st);
    (void)sqlite3_clear_bindings(st);
}

/* Run a cached statement that returns no rows; SQLITE_DONE → SQLITE_OK. */
static int conn_exec(store_conn *c, int k)
{
    int rc;
    sqlite3_stmt *st = conn_stmt(c, k, &rc);

    if (st == NULL)
        return rc;
    rc = sqlite3_step(st);
    stmt_done(st);
    return rc == SQLITE_DONE || rc == SQLITE_ROW ? SQLITE_OK : rc;
}

/* Roll back the open transaction of c, if SQLite has not already done so. */
static void conn_rollback(store_conn *c)
{
    if (!sqlite3_get_autocommit(c->db))
        (void)conn_exec(c, STMT_ROLLBACK);
}

/* Bind text (NULL → SQL NULL); the text must live until the step. */
static int bind_text(sqlite3_stmt *st, int i, const char *s, size_t len)
{
    if (s == NULL)
        return sqlite3_bind_null(st, i);
    return sqlite3_bind_text64(st, i, s, (sqlite3_uint64)len, SQLITE_STATIC, SQLITE_UTF8);
}

/* Copy text column i into a malloc'd NUL-terminated string (NULL when the
 * column is NULL).  Returns SQLITE_OK or SQLITE_NOMEM. */
static int column_dup(sqlite3_stmt *st, int i, char **out, size_t *len)
{
    const unsigned char *t;
    int n;

    *out = NULL;
    if (len)
        *len = 0;
    if (sqlite3_column_type(st, i) == SQLITE_NULL)
        return SQLITE_OK;
    t = sqlite3_column_text(st, i);
    n = sqlite3_column_bytes(st, i);
    if (t == NULL || n < 0)
        return SQLITE_NOMEM;   /* a non-NULL value that could not be converted */
    *out = malloc((size_t)n + 1);
    if (*out == NULL)
        return SQLITE_NOMEM;
    memcpy(*out, t, (size_t)n);
    (*out)[n] = '\0';
    if (len)
        *len = (size_t)n;
    return SQLITE_OK;
}

/* Read the state text of column i. */
static int column_state(sqlite3_stmt *st, int i, store_state *out)
{
    const char *t = (const char *)sqlite3_column_text(st, i);

    return store_state_parse(t, out) == STORE_OK ? STORE_OK : STORE_ERROR;
}

/* Fill *j (overwritten, not freed) from the current row of st, laid out as
 * JOB_COLS; with_large: columns 12 … 14 hold request, result, CSV (or NULL).
 * On failure *j holds no allocation.  Returns a store_rc. */
static int job_from_row(sqlite3_stmt *st, int with_large, store_job *j)
{
    const unsigned char *id;
    int rc;

    memset(j, 0, sizeof *j);
    id = sqlite3_column_text(st, 1);
    if (id == NULL || sqlite3_column_bytes(st, 1) != 64)
        return STORE_ERROR;   /* the schema's CHECK makes this a corrupt row */
    memcpy(j->id, id, 64);
    j->id[64] = '\0';
    j->seq = sqlite3_column_int64(st, 0);
    if (column_state(st, 2, &j->state) != STORE_OK)
        return STORE_ERROR;
    j->speeds_total = sqlite3_column_int(st, 3);
    j->speeds_done = sqlite3_column_int(st, 4);
    j->attempts = sqlite3_column_int(st, 5);
    j->cancel_requested = sqlite3_column_int(st, 6) != 0;
    j->created_at = sqlite3_column_double(st, 7);   /* NULL reads as 0.0 */
    j->started_at = sqlite3_column_double(st, 8);
    j->finished_at = sqlite3_column_double(st, 9);
    j->has_result = sqlite3_column_int(st, 10) != 0;
    rc = column_dup(st, 11, &j->error, NULL);
    if (rc == SQLITE_OK && with_large)
        rc = column_dup(st, 12, &j->request, &j->request_len);
    if (rc == SQLITE_OK && with_large)
        rc = column_dup(st, 13, &j->result, &j->result_len);
    if (rc == SQLITE_OK && with_large)
        rc = column_dup(st, 14, &j->result_csv, &j->csv_len);
    if (rc != SQLITE_OK) {
        store_job_clear(j);
        return STORE_NOMEM;
    }
    return STORE_OK;
}

/* ---- the pool ----------------------------------------------------------- */

/* Take a reader connection, waiting while all are in use. */
static store_conn *reader_acquire(store *s)
{
    store_conn *c;

    if (pthread_mutex_lock(&s->pool_lock) != 0)
        return NULL;
    while (s->free_readers == NULL) {
        if (pthread_cond_wait(&s->pool_cond, &s->pool_lock) != 0) {
            (void)pthread_mutex_unlock(&s->pool_lock);
            return NULL;
        }
    }
    c = s->free_readers;
    s->free_readers = c->next;
    (void)pthread_mutex_unlock(&s->pool_lock);
    return c;
}

static void reader_release(store *s, store_conn *c)
{
    (void)pthread_mutex_lock(&s->pool_lock);
    c->next = s->free_readers;
    s->free_readers = c;
    (void)pthread_cond_signal(&s->pool_cond);
    (void)pthread_mutex_unlock(&s->pool_lock);
}

/* Back to synchronous=FULL after a relaxed transaction (caller holds write_lock). */
static void writer_restore(store *s)
{
    if (s->writer_relaxed &&
        sqlite3_exec(s->writer.db, "PRAGMA synchronous = FULL", NULL, NULL, NULL) == SQLITE_OK)
        s->writer_relaxed = 0;
}

/* Take the writer and open a write transaction (BEGIN IMMEDIATE: the write
 * lock is taken now, so no later statement of it can fail with BUSY).
 * durable = 0 commits this transaction with synchronous=NORMAL: in WAL mode
 * it survives a crash or kill -9 of the process but may roll back on power
 * loss.  Used for claim, finish and requeue, whose loss only means the job
 * runs again (results are deterministic); a submission and a cancel are
 * always durable (synchronous=FULL: on disk before the HTTP answer).
 * On success the caller owns write_lock and must call writer_end. */
static int writer_begin_mode(store *s, store_conn **out, int durable)
{
    int rc;

    *out = NULL;
    if (pthread_mutex_lock(&s->write_lock) != 0)
        return STORE_ERROR;
    if (!durable && sqlite3_exec(s->writer.db, "PRAGMA synchronous = NORMAL", NULL, NULL,
                                 NULL) == SQLITE_OK)
        s->writer_relaxed = 1;
    rc = conn_exec(&s->writer, STMT_BEGIN);   /* waits up to STORE_BUSY_MS for other processes */
    if (rc != SQLITE_OK) {
        writer_restore(s);
        (void)pthread_mutex_unlock(&s->write_lock);
        return store_rc_of(rc);
    }
    *out = &s->writer;
    return STORE_OK;
}

static int writer_begin(store *s, store_conn **out)
{
    return writer_begin_mode(s, out, 1);
}

/* End the write transaction of writer_begin: commit when commit is 1, else
 * roll back; then give the writer back.  Returns status, or the store_rc
 * of a failed commit (the transaction is then rolled back). */
static int writer_end(store *s, int status, int commit)
{
    int rc;

    if (commit) {
        rc = conn_exec(&s->writer, STMT_COMMIT);
        if (rc != SQLITE_OK) {
            conn_rollback(&s->writer);
            status = store_rc_of(rc);
        }
    } else {
        conn_rollback(&s->writer);
    }
    writer_restore(s);
    (void)pthread_mutex_unlock(&s->write_lock);
    return status;
}

/* Finalize the statements of c and close it. */
static void conn_close(store_conn *c)
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

/* ---- open --------------------------------------------------------------- */

/* Run one pragma (or any SQL) and read the first column of its first row
 * as an integer (*val may be NULL) or as text into buf (may be NULL). */
static int conn_pragma(store_conn *c, const char *sql, int *val, char *buf, size_t buflen)
{
    sqlite3_stmt *st = NULL;
    int rc = sqlite3_prepare_v2(c->db, sql, -1, &st, NULL);

    if (rc != SQLITE_OK)
        goto done;
    rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        if (val)
            *val = sqlite3_column_int(st, 0);
        if (buf && buflen > 0) {
            const unsigned char *t = sqlite3_column_text(st, 0);
            snprintf(buf, buflen, "%s", t ? (const char *)t : "");
        }
        rc = SQLITE_OK;
    } else if (rc == SQLITE_DONE) {
        rc = SQLITE_OK;
    }
done:
    (void)sqlite3_finalize(st);
    return rc;
}

/* Open one connection with the store's settings: busy timeout, FULL sync
 * (a commit is on disk before it returns), a bounded WAL file. */
static int conn_open(store_conn *c, const char *path, char *err, size_t errlen)
{
    int rc;

    memset(c, 0, sizeof *c);
    rc = sqlite3_open_v2(path, &c->db,
                         SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, NULL);
    if (rc != SQLITE_OK) {
        store_seterr(err, errlen, "cannot open database '%s': %s", path,
                     c->db ? sqlite3_errmsg(c->db) : sqlite3_errstr(rc));
        goto fail;
    }
    rc = sqlite3_busy_timeout(c->db, STORE_BUSY_MS);
    if (rc == SQLITE_OK)
        rc = sqlite3_exec(c->db, "PRAGMA synchronous = FULL; PRAGMA journal_size_limit = 67108864",
                          NULL, NULL, NULL);
    if ((rc & 0xff) == SQLITE_NOTADB) {
        store_seterr(err, errlen, "'%s' is not a SQLite database", path);
        goto fail;
    }
    if (rc != SQLITE_OK) {
        store_seterr(err, errlen, "cannot configure database '%s': %s", path,
                     sqlite3_errmsg(c->db));
        goto fail;
    }
    return STORE_OK;
fail:
    conn_close(c);
    return store_rc_of(rc);
}

/* Before touching the file: is it a SQLite database, ours, and not newer
 * than this code?  Returns a store_rc with err set on refusal. */
static int store_inspect(store_conn *c, const char *path, char *err, size_t errlen)
{
    int app = 0, version = 0, objects = 0;
    int rc = conn_pragma(c, "PRAGMA application_id", &app, NULL, 0);

    if (rc == SQLITE_OK)
        rc = conn_pragma(c, "PRAGMA user_version", &version, NULL, 0);
    if (rc == SQLITE_OK)
        rc = conn_pragma(c, "SELECT count(*) FROM sqlite_schema", &objects, NULL, 0);
    if ((rc & 0xff) == SQLITE_NOTADB) {
        store_seterr(err, errlen, "'%s' is not a SQLite database", path);
        return STORE_ERROR;
    }
    if (rc != SQLITE_OK) {
        store_seterr(err, errlen, "cannot read database '%s': %s", path, sqlite3_errmsg(c->db));
        return store_rc_of(rc);
    }
    if (app != 0 && app != STORE_APP_ID) {
        store_seterr(err, errlen, "'%s' is a SQLite database of another application "
                     "(application_id %d)", path, app);
        return STORE_ERROR;
    }
    if (version > STORE_SCHEMA_VERSION) {
        store_seterr(err, errlen, "database schema version %d is newer than this spinmodald (%d)",
                     version, STORE_SCHEMA_VERSION);
        return STORE_ERROR;
    }
    if (app == 0 && version == 0 && objects > 0) {
        store_seterr(err, errlen, "'%s' is a SQLite database but not a spinmodal one", path);
        return STORE_ERROR;
    }
    return STORE_OK;
}

/* Switch to WAL (persistent in the file). */
static int store_wal(store_conn *c, const char *path, char *err, size_t errlen)
{
    char mode[16] = "";
    int rc = conn_pragma(c, "PRAGMA journal_mode = WAL", NULL, mode, sizeof mode);

    if (rc != SQLITE_OK) {
        store_seterr(err, errlen, "cannot switch database '%s' to WAL: %s", path,
                     sqlite3_errmsg(c->db));
        return store_rc_of(rc);
    }
    if (strcmp(mode, "wal") != 0) {
        store_seterr(err, errlen, "database '%s' cannot use WAL (journal mode is '%s'); "
                     "it must be a file on a local file system", path, mode);
        return STORE_ERROR;
    }
    return STORE_OK;
}

/* Apply the migrations one transaction each.  The version is read again
 * inside each transaction, so two processes opening at once agree. */
static int store_migrate(store *s, const char *path, char *err, size_t errlen)
{
    store_conn *c = &s->writer;
    char sql[64];
    int version = 0, rc = SQLITE_OK;

    for (;;) {
        rc = conn_exec(c, STMT_BEGIN);
        if (rc == SQLITE_OK)
            rc = conn_pragma(c, "PRAGMA user_version", &version, NULL, 0);
        if (rc != SQLITE_OK)
            goto fail;
        if (version > STORE_SCHEMA_VERSION) {
            conn_rollback(c);
            store_seterr(err, errlen,
                         "database schema version %d is newer than this spinmodald (%d)", version,
                         STORE_SCHEMA_VERSION);
            return STORE_ERROR;
        }
        if (version == STORE_SCHEMA_VERSION)
            break;
        snprintf(sql, sizeof sql, "PRAGMA user_version = %d", version + 1);
        rc = sqlite3_exec(c->db, store_migrations[version], NULL, NULL, NULL);
        if (rc == SQLITE_OK)
            rc = sqlite3_exec(c->db, sql, NULL, NULL, NULL);
        if (rc == SQLITE_OK)
            rc = conn_exec(c, STMT_COMMIT);
        if (rc != SQLITE_OK)
            goto fail;
    }
    rc = conn_exec(c, STMT_COMMIT);
    if (rc != SQLITE_OK)
        goto fail;
    s->version = version;
    return STORE_OK;
fail:
    store_seterr(err, errlen, "cannot migrate database '%s' to schema version %d: %s", path,
                 version + 1, sqlite3_errmsg(c->db));
    conn_rollback(c);
    return store_rc_of(rc);
}

/* Crash recovery, one transaction: every `running` job goes back to
 * `queued`.  attempts is kept (jobs.c fails a job interrupted too often);
 * cancel_requested is kept too, so the worker that claims the job again
 * stops it at once and the user's DELETE is not lost. */
static int store_recover(store *s, const char *path, int *requeued, char *err, size_t errlen)
{
    store_conn *c = &s->writer;
    int rc = conn_exec(c, STMT_BEGIN);

    if (rc == SQLITE_OK)
        rc = sqlite3_exec(c->db, "UPDATE jobs SET state = 'queued', started_at = NULL,"
                          " speeds_done = 0 WHERE state = 'running'", NULL, NULL, NULL);
    if (rc == SQLITE_OK && requeued)
        *requeued = sqlite3_changes(c->db);
    if (rc == SQLITE_OK)
        rc = conn_exec(c, STMT_COMMIT);
    if (rc != SQLITE_OK) {
        store_seterr(err, errlen, "cannot requeue the running jobs of '%s': %s", path,
                     sqlite3_errmsg(c->db));
        conn_rollback(c);
        return store_rc_of(rc);
    }
    return STORE_OK;
}

int store_open(store **out, const char *path, int *requeued, char *err, size_t errlen)
{
    store *s = NULL;
    int rc = STORE_ERROR, locks = 0;

    *out = NULL;
    if (requeued)
        *requeued = 0;
    store_seterr(err, errlen, "%s", "");
    if (path == NULL || *path == '\0') {
        store_seterr(err, errlen, "no database path given");
        return STORE_ERROR;
    }
    if (sqlite3_threadsafe() == 0) {
        store_seterr(err, errlen, "this SQLite library was built without thread support");
        return STORE_ERROR;
    }
    s = calloc(1, sizeof *s);
    if (s == NULL) {
        store_seterr(err, errlen, "out of memory opening the database");
        return STORE_NOMEM;
    }
    if (pthread_mutex_init(&s->write_lock, NULL) == 0)
        locks++;
    if (locks == 1 && pthread_mutex_init(&s->pool_lock, NULL) == 0)
        locks++;
    if (locks == 2 && pthread_cond_init(&s->pool_cond, NULL) == 0)
        locks++;
    if (locks != 3) {
        store_seterr(err, errlen, "cannot create the database locks");
        goto fail_locks;
    }
    s->locks_ready = 1;

    rc = conn_open(&s->writer, path, err, errlen);
    if (rc == STORE_OK)
        rc = store_inspect(&s->writer, path, err, errlen);
    if (rc == STORE_OK)
        rc = store_wal(&s->writer, path, err, errlen);
    if (rc == STORE_OK)
        rc = store_migrate(s, path, err, errlen);
    if (rc == STORE_OK)
        rc = store_recover(s, path, requeued, err, errlen);
    for (int i = 0; rc == STORE_OK && i < STORE_READERS; i++) {
        rc = conn_open(&s->readers[i], path, err, errlen);
        if (rc == STORE_OK) {
            s->readers[i].next = s->free_readers;
            s->free_readers = &s->readers[i];
        }
    }
    if (rc != STORE_OK)
        goto fail;
    *out = s;
    return STORE_OK;

fail:
    if (requeued)
        *requeued = 0;
    store_close(s);
    return rc;
fail_locks:
    if (locks > 1)
        (void)pthread_mutex_destroy(&s->pool_lock);
    if (locks > 0)
        (void)pthread_mutex_destroy(&s->write_lock);
    free(s);
    return STORE_ERROR;
}

void store_close(store *s)
{
    if (s == NULL)
        return;
    for (int i = 0; i < STORE_READERS; i++)
        conn_close(&s->readers[i]);
    if (s->writer.db != NULL) {
        /* the last connection would checkpoint anyway; do it explicitly and
         * truncate the WAL so the database is one file at rest */
        (void)sqlite3_wal_checkpoint_v2(s->writer.db, NULL, SQLITE_CHECKPOINT_TRUNCATE, NULL, NULL);
    }
    conn_close(&s->writer);
    if (s->locks_ready) {
        (void)pthread_cond_destroy(&s->pool_cond);
        (void)pthread_mutex_destroy(&s->pool_lock);
        (void)pthread_mutex_destroy(&s->write_lock);
    }
    free(s);
}

int store_schema_version(store *s)
{
    return s->version;
}

/* ---- writes ------------------------------------------------------------- */

/* Read job id on connection c (inside the caller's transaction or not)
 * with the large texts of flags.  Returns a store_rc. */
static int conn_get(store_conn *c, const char *id, unsigned flags, store_job *out)
{
    int rc, status;
    sqlite3_stmt *st = conn_stmt(c, STMT_GET + (int)(flags & 7u), &rc);

    memset(out, 0, sizeof *out);
    if (st == NULL)
        return store_rc_of(rc);
    rc = bind_text(st, 1, id, strlen(id));
    if (rc != SQLITE_OK) {
        status = store_rc_of(rc);
        goto done;
    }
    rc = sqlite3_step(st);
    if (rc == SQLITE_ROW)
        status = job_from_row(st, 1, out);
    else if (rc == SQLITE_DONE)
        status = STORE_NOT_FOUND;
    else
        status = store_rc_of(rc);
done:
    stmt_done(st);
    return status;
}

/* The state of job id on c: STORE_OK, STORE_NOT_FOUND or an error. */
static int conn_state(store_conn *c, const char *id, store_state *out)
{
    int rc, status;
    sqlite3_stmt *st = conn_stmt(c, STMT_STATE, &rc);

    if (st == NULL)
        return store_rc_of(rc);
    rc = bind_text(st, 1, id, strlen(id));
    if (rc == SQLITE_OK)
        rc = sqlite3_step(st);
    if (rc == SQLITE_ROW)
        status = column_state(st, 0, out);
    else if (rc == SQLITE_DONE)
        status = STORE_NOT_FOUND;
    else
        status = store_rc_of(rc);
    stmt_done(st);
    return status;
}

/* Step the bound update statement st of c once, reset it; *changes
 * receives the rows it changed.  Returns a store_rc. */
static int conn_update(store_conn *c, sqlite3_stmt *st, int *changes)
{
    int rc = sqlite3_step(st);

    stmt_done(st);
    if (rc != SQLITE_DONE)
        return store_rc_of(rc);
    *changes = sqlite3_changes(c->db);
    return STORE_OK;
}

int store_submit(store *s, const char *id, const char *request, size_t request_len,
                 int speeds_total, double now, int *outcome, store_job *job)
{
    store_conn *c = NULL;
    sqlite3_stmt *st;
    store_state state;
    int rc, status, changes = 0, result = 0;

    if (outcome)
        *outcome = 0;
    if (job)
        memset(job, 0, sizeof *job);
    if (id == NULL || request == NULL || strlen(id) != 64)
        return STORE_ERROR;   /* a caller's mistake: ids are 64 hex digits */
    status = writer_begin(s, &c);
    if (status != STORE_OK)
        return status;

    status = conn_state(c, id, &state);
    if (status == STORE_NOT_FOUND) {
        st = conn_stmt(c, STMT_INSERT, &rc);
        if (st == NULL)
            goto fail_sqlite;
        if ((rc = bind_text(st, 1, id, 64)) != SQLITE_OK ||
            (rc = sqlite3_bind_int(st, 2, speeds_total)) != SQLITE_OK ||
            (rc = sqlite3_bind_double(st, 3, now)) != SQLITE_OK ||
            (rc = bind_text(st, 4, request, request_len)) != SQLITE_OK) {
            stmt_done(st);
            goto fail_sqlite;
        }
        status = conn_update(c, st, &changes);
        result = 1;
    } else if (status == STORE_OK && (state == STORE_FAILED || state == STORE_CANCELED)) {
        st = conn_stmt(c, STMT_RESUBMIT, &rc);
        if (st == NULL)
            goto fail_sqlite;
        if ((rc = bind_text(st, 1, id, 64)) != SQLITE_OK ||
            (rc = sqlite3_bind_int(st, 2, speeds_total)) != SQLITE_OK ||
            (rc = bind_text(st, 3, request, request_len)) != SQLITE_OK) {
            stmt_done(st);
            goto fail_sqlite;
        }
        status = conn_update(c, st, &changes);
        result = 2;
    }
    if (status != STORE_OK)
        goto fail;
    if (job) {
        status = conn_get(c, id, 0, job);
        if (status != STORE_OK)
            goto fail;
    }
    status = writer_end(s, STORE_OK, 1);
    if (status != STORE_OK) {
        store_job_clear(job);
        return status;
    }
    if (outcome)
        *outcome = result;
    return STORE_OK;

fail_sqlite:
    status = store_rc_of(rc);
fail:
    store_job_clear(job);
    return writer_end(s, status, 0);
}

int store_claim_next(store *s, double now, store_job *out)
{
    store_conn *c = NULL;
    sqlite3_stmt *st;
    int rc, status, got = 0;

    memset(out, 0, sizeof *out);
    status = writer_begin_mode(s, &c, 0);
    if (status != STORE_OK)
        return status;
    st = conn_stmt(c, STMT_CLAIM, &rc);
    if (st == NULL || (rc = sqlite3_bind_double(st, 1, now)) != SQLITE_OK) {
        status = store_rc_of(rc);
        goto fail;
    }
    /* RETURNING: every row is computed at the first step; step to DONE
     * before committing */
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (!got) {
            status = job_from_row(st, 1, out);
            if (status != STORE_OK)
                goto fail;
            got = 1;
        }
    }
    if (rc != SQLITE_DONE) {
        status = store_rc_of(rc);
        goto fail;
    }
    stmt_done(st);
    if (!got)
        return writer_end(s, STORE_NOT_FOUND, 0);
    status = writer_end(s, STORE_OK, 1);
    if (status != STORE_OK)
        store_job_clear(out);
    return status;

fail:
    stmt_done(st);
    store_job_clear(out);
    return writer_end(s, status, 0);
}

/* After an update touched no row: STORE_NOT_FOUND (no such job) or
 * STORE_CONFLICT (it exists in another state). */
static int no_change_status(store_conn *c, const char *id)
{
    store_state st = STORE_QUEUED;
    int status = conn_state(c, id, &st);

    return status == STORE_OK ? STORE_CONFLICT : status;
}

/* Run the bound update st of the writer's open transaction on job id and end
 * the transaction: committed when a row changed; else rolled back with
 * STORE_NOT_FOUND or STORE_CONFLICT (no_change_status). */
static int writer_update_one(store *s, store_conn *c, sqlite3_stmt *st, const char *id)
{
    int changes = 0, status = conn_update(c, st, &changes);

    if (status != STORE_OK)
        return writer_end(s, status, 0);
    if (changes == 0)
        return writer_end(s, no_change_status(c, id), 0);
    return writer_end(s, STORE_OK, 1);
}

int store_finish(store *s, const char *id, store_state state, double now, int speeds_done,
                 const char *error, const char *result, size_t result_len,
                 const char *csv, size_t csv_len)
{
    store_conn *c = NULL;
    sqlite3_stmt *st;
    int rc, status;

    if (id == NULL)
        return STORE_NOT_FOUND;
    if (state != STORE_DONE && state != STORE_FAILED && state != STORE_CANCELED)
        return STORE_CONFLICT;   /* no job may finish as queued or running */
    status = writer_begin_mode(s, &c, 0);
    if (status != STORE_OK)
        return status;
    st = conn_stmt(c, STMT_FINISH, &rc);
    if (st == NULL)
        return writer_end(s, store_rc_of(rc), 0);
    if ((rc = bind_text(st, 1, id, strlen(id))) != SQLITE_OK ||
        (rc = bind_text(st, 2, store_state_names[state], strlen(store_state_names[state]))) !=
            SQLITE_OK ||
        (rc = sqlite3_bind_double(st, 3, now)) != SQLITE_OK ||
        (rc = sqlite3_bind_int(st, 4, speeds_done)) != SQLITE_OK ||
        (rc = bind_text(st, 5, error, error ? strlen(error) : 0)) != SQLITE_OK ||
        (rc = bind_text(st, 6, result, result_len)) != SQLITE_OK ||
        (rc = bind_text(st, 7, csv, csv_len)) != SQLITE_OK) {
        stmt_done(st);
        return writer_end(s, store_rc_of(rc), 0);
    }
    return writer_update_one(s, c, st, id);
}

int store_requeue(store *s, const char *id)
{
    store_conn *c = NULL;
    sqlite3_stmt *st;
    int rc, status;

    if (id == NULL)
        return STORE_NOT_FOUND;
    status = writer_begin_mode(s, &c, 0);
    if (status != STORE_OK)
        return status;
    st = conn_stmt(c, STMT_REQUEUE, &rc);
    if (st == NULL)
        return writer_end(s, store_rc_of(rc), 0);
    if ((rc = bind_text(st, 1, id, strlen(id))) != SQLITE_OK) {
        stmt_done(st);
        return writer_end(s, store_rc_of(rc), 0);
    }
    return writer_update_one(s, c, st, id);
}

int store_cancel(store *s, const char *id, double now, store_state *state)
{
    store_conn *c = NULL;
    sqlite3_stmt *st;
    store_state cur = STORE_QUEUED;
    int rc, status, changes = 0;

    if (id == NULL)
        return STORE_NOT_FOUND;
    status = writer_begin(s, &c);
    if (status != STORE_OK)
        return status;
    status = conn_state(c, id, &cur);
    if (status != STORE_OK)
        return writer_end(s, status, 0);
    if (state)
        *state = cur;
    if (cur != STORE_QUEUED && cur != STORE_RUNNING)
        return writer_end(s, STORE_CONFLICT, 0);

    st = conn_stmt(c, cur == STORE_QUEUED ? STMT_CANCEL_QUEUED : STMT_CANCEL_RUNNING, &rc);
    if (st == NULL)
        return writer_end(s, store_rc_of(rc), 0);
    rc = bind_text(st, 1, id, strlen(id));
    if (rc == SQLITE_OK && cur == STORE_QUEUED)
        rc = sqlite3_bind_double(st, 2, now);
    if (rc != SQLITE_OK) {
        stmt_done(st);
        return writer_end(s, store_rc_of(rc), 0);
    }
    status = conn_update(c, st, &changes);
    if (status != STORE_OK)
        return writer_end(s, status, 0);
    status = writer_end(s, STORE_OK, 1);
    if (status == STORE_OK && state && cur == STORE_QUEUED)
        *state = STORE_CANCELED;
    return status;
}

int store_check_writable(store *s)
{
    store_conn *c = NULL;
    int status = writer_begin(s, &c);

    if (status != STORE_OK)
        return STORE_ERROR;
    return writer_end(s, STORE_OK, 0) == STORE_OK ? STORE_OK : STORE_ERROR;
}

/* ---- reads -------------------------------------------------------------- */

int store_get(store *s, const char *id, unsigned flags, store_job *out)
{
    store_conn *c;
    int status;

    memset(out, 0, sizeof *out);
    if (id == NULL)
        return STORE_NOT_FOUND;
    c = reader_acquire(s);
    if (c == NULL)
        return STORE_ERROR;
    status = conn_get(c, id, flags, out);
    reader_release(s, c);
    return status;
}

/* The rows of a list statement into out[0 … max-1]; *more when a row
 * beyond max exists. */
static int list_rows(sqlite3_stmt *st, int max, store_job *out, int *n, int *more)
{
    int rc, status;

    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (*n >= max) {
            *more = 1;
            break;
        }
        status = job_from_row(st, 0, &out[*n]);
        if (status != STORE_OK)
            return status;
        (*n)++;
    }
    if (rc != SQLITE_ROW && rc != SQLITE_DONE)
        return store_rc_of(rc);
    return STORE_OK;
}

int store_list(store *s, long long before, int filter, int max, store_job *out, int *n,
               int *more)
{
    store_conn *c;
    sqlite3_stmt *st;
    int rc, status;

    *n = 0;
    *more = 0;
    if (max < 0)
        max = 0;
    if (filter >= STORE_N_STATES)
        return STORE_ERROR;   /* a caller's mistake: parse states with store_state_parse */
    c = reader_acquire(s);
    if (c == NULL)
        return STORE_ERROR;
    st = conn_stmt(c, filter >= 0 ? STMT_LIST_STATE : STMT_LIST_ALL, &rc);
    if (st == NULL) {
        status = store_rc_of(rc);
        goto done;
    }
    rc = sqlite3_bind_int64(st, 1, before > 0 ? (sqlite3_int64)before : INT64_MAX);
    if (rc == SQLITE_OK)
        rc = sqlite3_bind_int64(st, 2, (sqlite3_int64)max + 1);   /* one more: is there more? */
    if (rc == SQLITE_OK && filter >= 0)
        rc = bind_text(st, 3, store_state_names[filter], strlen(store_state_names[filter]));
    if (rc != SQLITE_OK)
        status = store_rc_of(rc);
    else
        status = list_rows(st, max, out, n, more);
    stmt_done(st);
done:
    reader_release(s, c);
    if (status != STORE_OK) {
        for (int i = 0; i < *n; i++)
            store_job_clear(&out[i]);
        *n = 0;
        *more = 0;
    }
    return status;
}

int store_count(store *s, long long counts[STORE_N_STATES])
{
    store_conn *c;
    sqlite3_stmt *st;
    store_state state;
    int rc, status = STORE_OK;

    for (int i = 0; i < STORE_N_STATES; i++)
        counts[i] = 0;
    c = reader_acquire(s);
    if (c == NULL)
        return STORE_ERROR;
    st = conn_stmt(c, STMT_COUNT, &rc);
    if (st == NULL) {
        reader_release(s, c);
        return STORE_ERROR;
    }
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (column_state(st, 0, &state) != STORE_OK) {
            status = STORE_ERROR;
            break;
        }
        counts[state] = sqlite3_column_int64(st, 1);
    }
    if (status == STORE_OK && rc != SQLITE_DONE)
        status = STORE_ERROR;
    stmt_done(st);
    reader_release(s, c);
    if (status != STORE_OK) {
        for (int i = 0; i < STORE_N_STATES; i++)
            counts[i] = 0;
    }
    return status;
}
