/*
 * store_sqlite.c — the SQLite backend's job operations (store.h): the SQL
 * of every cached statement, reading a job row, submit, claim, finish,
 * requeue, cancel, the reads, the calls of several replicas, and the
 * backend table.  Connections, statements, errors and the waits within a
 * call's deadline are in store_sqlite_conn.c; opening, the lock file,
 * checks and migrations in store_sqlite_open.c; the probes and retention
 * in store_sqlite_file.c.
 *
 * Durability.  A submission and a cancel are committed with synchronous=FULL
 * (WAL: the commit is on disk) before store_submit / store_cancel return,
 * so a 202 is never sent for a job a power cut or kill -9 could lose.
 * Claims, finishes, requeues, pruning and the health probe commit with
 * synchronous=NORMAL (no fsync): they survive a kill -9 of the process, and
 * a power cut can at worst roll them back, which puts the job back to
 * `queued` and runs it again (one fsync less per commit: ~1.4 ms each here).
 *
 * Queue order.  seq (INTEGER PRIMARY KEY, the rowid) is both the submission
 * order and the list cursor.  A resubmitted failed/canceled job gets a new
 * seq (max + 1), so it queues last and lists as the newest; a job put back
 * by store_requeue keeps its seq and runs first again.  Claiming is "lowest
 * seq among queued" on the index jobs(state, seq).
 *
 * The budget on insert.  A submission that writes a job and every finish
 * keep store_settings.retain_bytes inside their own transaction
 * (store_sqlite_trim, store_sqlite_file.c) before committing, keeping the
 * job just written.
 */
#include "store_sqlite.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Columns every job read selects, in the order job_from_row expects
 * (0 … 11); the three large texts follow as columns 12, 13, 14.
 * typeof() tells whether a result is stored without loading its text. */
#define JOB_COLS                                                                        \
    "seq, id, state, speeds_total, speeds_done, attempts, cancel_requested, created_at," \
    " started_at, finished_at, typeof(result) <> 'null', error"
/* A listing's column 12: the request's "name" (codec_request_stored_text), NULL without one. */
#define JOB_NAME "json_extract(request, '$.name')"
#define JOB_GET(req, res, csv) "SELECT " JOB_COLS ", " req ", " res ", " csv " FROM jobs WHERE id = ?1"
#define JOB_FINISHED "state IN ('done', 'failed', 'canceled')"

const char *const store_sqlite_sql[STMT_N] = {
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
    "SELECT " JOB_COLS ", " JOB_NAME " FROM jobs WHERE seq < ?1 ORDER BY seq DESC LIMIT ?2",
    /* STMT_LIST_STATE */
    "SELECT " JOB_COLS ", " JOB_NAME " FROM jobs WHERE state = ?3 AND seq < ?1"
    " ORDER BY seq DESC LIMIT ?2",
    /* STMT_COUNT */ "SELECT state, count(*) FROM jobs GROUP BY state",
    /* STMT_PAGES */
    "SELECT p.page_count, f.freelist_count, s.page_size"
    " FROM pragma_page_count AS p, pragma_freelist_count AS f, pragma_page_size AS s",
    /* STMT_PRUNE_AGE: one batch of the jobs that ended before ?1 */
    "DELETE FROM jobs WHERE seq IN (SELECT seq FROM jobs WHERE " JOB_FINISHED
    " AND finished_at < ?1 ORDER BY finished_at, seq LIMIT ?2)",
    /* STMT_PRUNE_OLDEST: the next batch of candidates for the size bound,
     * other than job ?2 (NULL: none kept) */
    "SELECT seq FROM jobs WHERE " JOB_FINISHED " AND id IS NOT ?2 ORDER BY finished_at, seq"
    " LIMIT ?1",
    /* STMT_PRUNE_ONE: the state test again, in case the job was resubmitted */
    "DELETE FROM jobs WHERE seq = ?1 AND " JOB_FINISHED,
    /* STMT_CANCEL_FLAG */ "SELECT cancel_requested FROM jobs WHERE id = ?1",
};

/* ---- rows ----------------------------------------------------------------- */

/* A failure that is not SQLite's (a malformed row, an allocation). */
static int conn_fail_kind(store_conn *c, int kind, const char *text)
{
    return store_note_error(c->owner, kind, 0, 0, c->op, text);
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

/* Read the state text of column i: STORE_OK, or STORE_CORRUPT (recorded)
 * for a state the schema's CHECK forbids. */
static int column_state(store_conn *c, sqlite3_stmt *st, int i, store_state *out)
{
    const char *t = (const char *)sqlite3_column_text(st, i);

    if (store_state_parse(t, out) == STORE_OK)
        return STORE_OK;
    return conn_fail_kind(c, STORE_CORRUPT, "a job row holds an unknown state");
}

/* Fill *j (overwritten, not freed) from the current row of st, laid out as
 * JOB_COLS; with_large: columns 12 … 14 hold request, result, CSV (or NULL).
 * On failure *j holds no allocation.  Returns a store_rc. */
static int job_from_row(store_conn *c, sqlite3_stmt *st, int with_large, store_job *j)
{
    const unsigned char *id;
    int rc;

    memset(j, 0, sizeof *j);
    id = sqlite3_column_text(st, 1);
    if (id == NULL || sqlite3_column_bytes(st, 1) != 64)   /* the schema's CHECK forbids it */
        return conn_fail_kind(c, STORE_CORRUPT, "a job row holds an id that is not 64 characters");
    memcpy(j->id, id, 64);
    j->id[64] = '\0';
    j->seq = sqlite3_column_int64(st, 0);
    if (column_state(c, st, 2, &j->state) != STORE_OK)
        return STORE_CORRUPT;
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
        return conn_fail_kind(c, STORE_NOMEM, "out of memory copying a job's texts");
    }
    return STORE_OK;
}

/* ---- writes --------------------------------------------------------------- */

/* Read job id on connection c (inside the caller's transaction or not)
 * with the large texts of flags.  Returns a store_rc. */
static int conn_get(store_conn *c, const char *id, unsigned flags, store_job *out)
{
    int rc, status;
    sqlite3_stmt *st = store_sqlite_stmt(c, STMT_GET + (int)(flags & 7u), &rc);

    memset(out, 0, sizeof *out);
    if (st == NULL)
        return store_sqlite_fail(c, rc);
    rc = bind_text(st, 1, id, strlen(id));
    if (rc == SQLITE_OK)
        rc = sqlite3_step(st);
    if (rc == SQLITE_ROW)
        status = job_from_row(c, st, 1, out);
    else if (rc == SQLITE_DONE)
        status = STORE_NOT_FOUND;
    else
        status = store_sqlite_fail(c, rc);
    store_sqlite_stmt_done(st);
    return status;
}

/* The state of job id on c: STORE_OK, STORE_NOT_FOUND or a failure kind. */
static int conn_state(store_conn *c, const char *id, store_state *out)
{
    int rc, status;
    sqlite3_stmt *st = store_sqlite_stmt(c, STMT_STATE, &rc);

    if (st == NULL)
        return store_sqlite_fail(c, rc);
    rc = bind_text(st, 1, id, strlen(id));
    if (rc == SQLITE_OK)
        rc = sqlite3_step(st);
    if (rc == SQLITE_ROW)
        status = column_state(c, st, 0, out);
    else if (rc == SQLITE_DONE)
        status = STORE_NOT_FOUND;
    else
        status = store_sqlite_fail(c, rc);
    store_sqlite_stmt_done(st);
    return status;
}

/* Step the bound update statement st of c once, reset it; *changes
 * receives the rows it changed.  Returns a store_rc. */
static int conn_update(store_conn *c, sqlite3_stmt *st, int *changes)
{
    int rc = sqlite3_step(st), status = STORE_OK;

    if (rc != SQLITE_DONE)
        status = store_sqlite_fail(c, rc);
    store_sqlite_stmt_done(st);
    if (status == STORE_OK)
        *changes = sqlite3_changes(c->db);
    return status;
}

/* A statement of c that failed to prepare or bind: record, reset, return the kind. */
static int stmt_fail(store_conn *c, sqlite3_stmt *st, int rc)
{
    int kind = store_sqlite_fail(c, rc);

    store_sqlite_stmt_done(st);
    return kind;
}

/* Commit the writer's open transaction after the budget on insert
 * (store_sqlite_trim, keeping job id) made room for what it wrote; tell
 * on_pruned what the committed transaction deleted.  Returns a store_rc. */
static int writer_commit_trimmed(store *s, store_conn *c, const char *id)
{
    long long removed = 0;
    int status = store_sqlite_trim(s, c, id, &removed);

    if (status != STORE_OK)
        return store_sqlite_writer_end(s, status, 0);
    status = store_sqlite_writer_end(s, STORE_OK, 1);
    if (status == STORE_OK)
        store_note_pruned(s, removed);
    return status;
}

static int sq_submit(store *s, const char *id, const char *request, size_t request_len,
                     int speeds_total, double now, int *outcome, store_job *job)
{
    store_conn *c = NULL;
    sqlite3_stmt *st;
    store_state state;
    int rc, status, changes = 0, result = 0;

    status = store_sqlite_writer_begin(s, &c, 1, "submit");
    if (status != STORE_OK)
        return status;
    status = conn_state(c, id, &state);
    if (status == STORE_NOT_FOUND) {
        st = store_sqlite_stmt(c, STMT_INSERT, &rc);
        if (st == NULL || (rc = bind_text(st, 1, id, 64)) != SQLITE_OK ||
            (rc = sqlite3_bind_int(st, 2, speeds_total)) != SQLITE_OK ||
            (rc = sqlite3_bind_double(st, 3, now)) != SQLITE_OK ||
            (rc = bind_text(st, 4, request, request_len)) != SQLITE_OK) {
            status = stmt_fail(c, st, rc);
            goto fail;
        }
        status = conn_update(c, st, &changes);
        result = 1;
    } else if (status == STORE_OK && (state == STORE_FAILED || state == STORE_CANCELED)) {
        st = store_sqlite_stmt(c, STMT_RESUBMIT, &rc);
        if (st == NULL || (rc = bind_text(st, 1, id, 64)) != SQLITE_OK ||
            (rc = sqlite3_bind_int(st, 2, speeds_total)) != SQLITE_OK ||
            (rc = bind_text(st, 3, request, request_len)) != SQLITE_OK) {
            status = stmt_fail(c, st, rc);
            goto fail;
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
    status = result ? writer_commit_trimmed(s, c, id) : store_sqlite_writer_end(s, STORE_OK, 1);
    if (status != STORE_OK) {
        store_job_clear(job);
        return status;
    }
    if (outcome)
        *outcome = result;
    return STORE_OK;
fail:
    store_job_clear(job);
    return store_sqlite_writer_end(s, status, 0);
}

static int sq_claim_next(store *s, double now, store_job *out)
{
    store_conn *c = NULL;
    sqlite3_stmt *st;
    int rc, status, got = 0;

    status = store_sqlite_writer_begin(s, &c, 0, "claim");
    if (status != STORE_OK)
        return status;
    st = store_sqlite_stmt(c, STMT_CLAIM, &rc);
    if (st == NULL || (rc = sqlite3_bind_double(st, 1, now)) != SQLITE_OK) {
        status = stmt_fail(c, st, rc);
        goto fail;
    }
    /* RETURNING: every row is computed at the first step; step to DONE
     * before committing */
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (!got) {
            status = job_from_row(c, st, 1, out);
            if (status != STORE_OK) {
                store_sqlite_stmt_done(st);
                goto fail;
            }
            got = 1;
        }
    }
    if (rc != SQLITE_DONE) {
        status = stmt_fail(c, st, rc);
        goto fail;
    }
    store_sqlite_stmt_done(st);
    if (!got)
        return store_sqlite_writer_end(s, STORE_NOT_FOUND, 0);
    status = store_sqlite_writer_end(s, STORE_OK, 1);
    if (status != STORE_OK)
        store_job_clear(out);
    return status;
fail:
    store_job_clear(out);
    return store_sqlite_writer_end(s, status, 0);
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
 * the transaction: committed when a row changed (trim: after the budget on
 * insert made room); else rolled back with STORE_NOT_FOUND or
 * STORE_CONFLICT (no_change_status). */
static int writer_update_one(store *s, store_conn *c, sqlite3_stmt *st, const char *id, int trim)
{
    int changes = 0, status = conn_update(c, st, &changes);

    if (status != STORE_OK)
        return store_sqlite_writer_end(s, status, 0);
    if (changes == 0)
        return store_sqlite_writer_end(s, no_change_status(c, id), 0);
    if (trim)
        return writer_commit_trimmed(s, c, id);
    return store_sqlite_writer_end(s, STORE_OK, 1);
}

static int sq_finish(store *s, const char *id, store_state state, double now, int speeds_done,
                     const char *error, const char *result, size_t result_len, const char *csv,
                     size_t csv_len)
{
    const char *name = store_state_name(state);
    store_conn *c = NULL;
    sqlite3_stmt *st;
    int rc, status;

    status = store_sqlite_writer_begin(s, &c, 0, "finish");
    if (status != STORE_OK)
        return status;
    st = store_sqlite_stmt(c, STMT_FINISH, &rc);
    if (st == NULL || (rc = bind_text(st, 1, id, strlen(id))) != SQLITE_OK ||
        (rc = bind_text(st, 2, name, strlen(name))) != SQLITE_OK ||
        (rc = sqlite3_bind_double(st, 3, now)) != SQLITE_OK ||
        (rc = sqlite3_bind_int(st, 4, speeds_done)) != SQLITE_OK ||
        (rc = bind_text(st, 5, error, error ? strlen(error) : 0)) != SQLITE_OK ||
        (rc = bind_text(st, 6, result, result_len)) != SQLITE_OK ||
        (rc = bind_text(st, 7, csv, csv_len)) != SQLITE_OK)
        return store_sqlite_writer_end(s, stmt_fail(c, st, rc), 0);
    return writer_update_one(s, c, st, id, 1);
}

static int sq_requeue(store *s, const char *id)
{
    store_conn *c = NULL;
    sqlite3_stmt *st;
    int rc, status;

    status = store_sqlite_writer_begin(s, &c, 0, "requeue");
    if (status != STORE_OK)
        return status;
    st = store_sqlite_stmt(c, STMT_REQUEUE, &rc);
    if (st == NULL || (rc = bind_text(st, 1, id, strlen(id))) != SQLITE_OK)
        return store_sqlite_writer_end(s, stmt_fail(c, st, rc), 0);
    return writer_update_one(s, c, st, id, 0);
}

static int sq_cancel(store *s, const char *id, double now, store_state *state)
{
    store_conn *c = NULL;
    sqlite3_stmt *st;
    store_state cur = STORE_QUEUED;
    int rc, status, changes = 0;

    status = store_sqlite_writer_begin(s, &c, 1, "cancel");
    if (status != STORE_OK)
        return status;
    status = conn_state(c, id, &cur);
    if (status != STORE_OK)
        return store_sqlite_writer_end(s, status, 0);
    if (state)
        *state = cur;
    if (cur != STORE_QUEUED && cur != STORE_RUNNING)
        return store_sqlite_writer_end(s, STORE_CONFLICT, 0);

    st = store_sqlite_stmt(c, cur == STORE_QUEUED ? STMT_CANCEL_QUEUED : STMT_CANCEL_RUNNING, &rc);
    if (st != NULL)
        rc = bind_text(st, 1, id, strlen(id));
    if (st != NULL && rc == SQLITE_OK && cur == STORE_QUEUED)
        rc = sqlite3_bind_double(st, 2, now);
    if (st == NULL || rc != SQLITE_OK)
        return store_sqlite_writer_end(s, stmt_fail(c, st, rc), 0);
    status = conn_update(c, st, &changes);
    if (status != STORE_OK)
        return store_sqlite_writer_end(s, status, 0);
    status = store_sqlite_writer_end(s, STORE_OK, 1);
    if (status == STORE_OK && state && cur == STORE_QUEUED)
        *state = STORE_CANCELED;
    return status;
}

/* ---- reads ---------------------------------------------------------------- */

/* A reader for op within the store's deadline; NULL on failure, with
 * the recorded kind in *status. */
static store_conn *reader_acquire(store *s, const char *op, int *status)
{
    store_conn *c = NULL;

    *status = store_sqlite_reader_acquire(s, op, s->timeout_ms, &c);
    return c;
}

static int sq_get(store *s, const char *id, unsigned flags, store_job *out)
{
    store_conn *c;
    int status;

    c = reader_acquire(s, "get", &status);
    if (c == NULL)
        return status;
    status = conn_get(c, id, flags, out);
    store_sqlite_reader_release(s, c);
    return status;
}

/* The rows of a list statement into out[0 … max-1]; *more when a row
 * beyond max exists. */
static int list_rows(store_conn *c, sqlite3_stmt *st, int max, store_job *out, int *n, int *more)
{
    int rc, status;

    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (*n >= max) {
            *more = 1;
            break;
        }
        status = job_from_row(c, st, 0, &out[*n]);
        if (status != STORE_OK)
            return status;
        if (column_dup(st, 12, &out[*n].name, NULL) != SQLITE_OK) {
            store_job_clear(&out[*n]);
            return conn_fail_kind(c, STORE_NOMEM, "out of memory copying a job's name");
        }
        (*n)++;
    }
    if (rc != SQLITE_ROW && rc != SQLITE_DONE)
        return store_sqlite_fail(c, rc);
    return STORE_OK;
}

static int sq_list(store *s, long long before, int filter, int max, store_job *out, int *n,
                   int *more)
{
    store_conn *c;
    sqlite3_stmt *st;
    int rc, status;

    c = reader_acquire(s, "list", &status);
    if (c == NULL)
        return status;
    st = store_sqlite_stmt(c, filter >= 0 ? STMT_LIST_STATE : STMT_LIST_ALL, &rc);
    if (st == NULL) {
        status = store_sqlite_fail(c, rc);
        goto done;
    }
    rc = sqlite3_bind_int64(st, 1, before > 0 ? (sqlite3_int64)before : INT64_MAX);
    if (rc == SQLITE_OK)
        rc = sqlite3_bind_int64(st, 2, (sqlite3_int64)max + 1);   /* one more: is there more? */
    if (rc == SQLITE_OK && filter >= 0) {
        const char *name = store_state_name((store_state)filter);
        rc = bind_text(st, 3, name, strlen(name));
    }
    if (rc != SQLITE_OK)
        status = store_sqlite_fail(c, rc);
    else
        status = list_rows(c, st, max, out, n, more);
    store_sqlite_stmt_done(st);
done:
    store_sqlite_reader_release(s, c);
    if (status != STORE_OK) {
        for (int i = 0; i < *n; i++)
            store_job_clear(&out[i]);
        *n = 0;
        *more = 0;
    }
    return status;
}

static int sq_count(store *s, long long counts[STORE_N_STATES])
{
    store_conn *c = NULL;
    sqlite3_stmt *st;
    store_state state;
    int rc, status = store_sqlite_reader_acquire(s, "count", s->probe_ms, &c);

    if (status != STORE_OK)
        return status;
    st = store_sqlite_stmt(c, STMT_COUNT, &rc);
    if (st == NULL) {
        status = store_sqlite_fail(c, rc);
        store_sqlite_reader_release(s, c);
        return status;
    }
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        status = column_state(c, st, 0, &state);
        if (status != STORE_OK)
            break;
        counts[state] = sqlite3_column_int64(st, 1);
    }
    if (status == STORE_OK && rc != SQLITE_DONE)
        status = store_sqlite_fail(c, rc);
    store_sqlite_stmt_done(st);
    store_sqlite_reader_release(s, c);
    if (status != STORE_OK) {
        for (int i = 0; i < STORE_N_STATES; i++)
            counts[i] = 0;
    }
    return status;
}

/* ---- the calls of several replicas ---------------------------------------- */

/* One process owns the file and nothing stores leases: a renewal only
 * tells the worker whether its job is still running (a read, no write). */
static int sq_renew_lease(store *s, const char *id, const char *owner, double now,
                          double lease_s)
{
    store_conn *c;
    store_state state = STORE_QUEUED;
    int status;

    c = reader_acquire(s, "renew_lease", &status);
    if (c == NULL)
        return status;
    status = conn_state(c, id, &state);
    store_sqlite_reader_release(s, c);
    if (status == STORE_OK && state != STORE_RUNNING)
        status = STORE_CONFLICT;
    return status;
}

/* Nothing expires: the running jobs of a dead process are requeued when
 * the next one opens the file (store_sqlite_open). */
static int sq_requeue_expired(store *s, double now, int max_attempts, int *requeued,
                              int *failed)
{
    return STORE_OK;
}

static int sq_cancel_requested(store *s, const char *id, int *flag)
{
    store_conn *c;
    sqlite3_stmt *st;
    int rc, status;

    c = reader_acquire(s, "cancel_requested", &status);
    if (c == NULL)
        return status;
    st = store_sqlite_stmt(c, STMT_CANCEL_FLAG, &rc);
    if (st == NULL) {
        status = store_sqlite_fail(c, rc);
        goto done;
    }
    rc = bind_text(st, 1, id, strlen(id));
    if (rc == SQLITE_OK)
        rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        *flag = sqlite3_column_int(st, 0) != 0;
        status = STORE_OK;
    } else {
        status = rc == SQLITE_DONE ? STORE_NOT_FOUND : store_sqlite_fail(c, rc);
    }
    store_sqlite_stmt_done(st);
done:
    store_sqlite_reader_release(s, c);
    return status;
}

static int sq_state_of(store *s, const char *id, store_state *state)
{
    store_conn *c;
    int status;

    c = reader_acquire(s, "state_of", &status);
    if (c == NULL)
        return status;
    status = conn_state(c, id, state);
    store_sqlite_reader_release(s, c);
    return status;
}

/* ---- the backend table --------------------------------------------------- */

const store_backend store_sqlite_backend = {
    .name = "sqlite",
    .caps = 0, /* one process, one file: not shared, the path is no secret */
    .open = store_sqlite_open,
    .close = store_sqlite_close,
    .schema_version = store_sqlite_schema_version,
    .submit = sq_submit,
    .get = sq_get,
    .claim_next = sq_claim_next,
    .finish = sq_finish,
    .requeue = sq_requeue,
    .cancel = sq_cancel,
    .list = sq_list,
    .count = sq_count,
    .check_writable = store_sqlite_check_writable,
    .health = store_sqlite_health,
    .prune = store_sqlite_prune,
    .size = store_sqlite_size,
    .renew_lease = sq_renew_lease,
    .requeue_expired = sq_requeue_expired,
    .cancel_requested = sq_cancel_requested,
    .state_of = sq_state_of,
};
