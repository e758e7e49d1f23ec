/*
 * store_pg.c — the PostgreSQL backend of the store (store.h, DESIGN.md §6):
 * statements, the pool of libpq connections and its reconnection, error
 * kinds, and the job operations.  Opening (migrations under an advisory
 * lock), the probes and retention are in store_pg_open.c.
 *
 * Several replicas.  Any number of stores, in any processes, share the
 * database; the database is the only shared state.  A claim is one UPDATE
 * of the row that `SELECT … FOR UPDATE SKIP LOCKED LIMIT 1` picked, so two
 * claimers never wait for each other and never get the same job; it
 * stamps the job with the store's owner id and lease_until = now + lease.
 * The owner renews the lease (store_renew_lease) while the job runs; any
 * replica puts back jobs whose lease ran out (store_requeue_expired), and
 * fails them after max attempts.  Finish and requeue are the owner's only
 * (`AND owner = $me`), so a worker that lost its lease cannot overwrite
 * the replica that took the job over.  Times are the callers' clocks
 * (unix seconds, as on SQLite): replicas need clocks in step to well
 * within a lease (NTP).
 *
 * Idempotent submission.  In one transaction: read the row FOR UPDATE;
 * none → `INSERT … ON CONFLICT (id) DO NOTHING` (a replica inserting the
 * same id at the same moment makes ours a no-op: outcome 0), then read it.
 * The read comes first so that the common case — the job exists — does
 * not draw a number from the seq sequence (an INSERT that conflicts
 * does): seq stays dense, as on SQLite.  A failed/canceled job is
 * resubmitted with a new seq (nextval), so it queues last.
 *
 * Connections.  STORE_PG_CONNS sessions at most (and one more of the
 * probes' own: readiness, counts, size), opened on demand, each
 * used by one thread at a time and with its prepared statements (prepared
 * on first use).  Before a pooled session is reused, input the server
 * sent while it was idle is read: a session the server closed (restart,
 * pg_terminate_backend) is noticed then and replaced by a new one before
 * any statement is sent — a statement is never sent twice, since a lost
 * answer cannot tell whether it committed.  A session that fails during a
 * statement is closed and the call returns STORE_UNAVAILABLE.  When a
 * connect fails, the next one is tried at most STORE_PG_RETRY_MS later;
 * until then every call fails at once with STORE_UNAVAILABLE and libpq's
 * words of that failure, so callers never queue up behind connect
 * timeouts of an unreachable server.
 *
 * Texts.  The large texts are sent in binary format with their length
 * (text's binary form is its bytes), so no copy and no NUL is needed, and
 * read back in text format.  Doubles travel as "%.17g" and are printed by
 * the server in shortest exact form, so times round-trip exactly.
 */
#include "store_pg.h"

#include <errno.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Columns every job read selects, in the order pg_job_from_row expects
 * (0 … 13); the three large texts follow as columns 14, 15, 16. */
#define PG_JOB_COLS                                                                          \
    "seq, id, state, speeds_total, speeds_done, attempts, cancel_requested::int, created_at," \
    " started_at, finished_at, (result IS NOT NULL)::int, error, owner, lease_until"
#define PG_GET_SQL(req, res, csv) \
    "SELECT " PG_JOB_COLS ", " req ", " res ", " csv " FROM jobs WHERE id = $1::text"
#define PG_FINISHED "state IN ('done', 'failed', 'canceled')"
/* the bytes a row holds (stored, possibly compressed sizes; no detoasting) */
#define PG_ROW_BYTES                                                                   \
    "(120 + coalesce(pg_column_size(request), 0) + coalesce(pg_column_size(result), 0)" \
    " + coalesce(pg_column_size(result_csv), 0) + coalesce(pg_column_size(error), 0))"

const char *const store_pg_sql[PG_N] = {
    PG_GET_SQL("NULL", "NULL", "NULL"),
    PG_GET_SQL("request", "NULL", "NULL"),
    PG_GET_SQL("NULL", "result", "NULL"),
    PG_GET_SQL("request", "result", "NULL"),
    PG_GET_SQL("NULL", "NULL", "result_csv"),
    PG_GET_SQL("request", "NULL", "result_csv"),
    PG_GET_SQL("NULL", "result", "result_csv"),
    PG_GET_SQL("request", "result", "result_csv"),
    /* PG_STATE */ "SELECT state FROM jobs WHERE id = $1::text",
    /* PG_STATE_LOCK */ "SELECT state FROM jobs WHERE id = $1::text FOR UPDATE",
    /* PG_INSERT */
    "INSERT INTO jobs (id, state, speeds_total, created_at, request)"
    " VALUES ($1::text, 'queued', $2::int, $3::float8, $4::text) ON CONFLICT (id) DO NOTHING",
    /* PG_RESUBMIT: a new seq so the job queues last */
    "UPDATE jobs SET seq = nextval('jobs_seq'), state = 'queued', speeds_total = $2::int,"
    " speeds_done = 0, attempts = 0, cancel_requested = false, started_at = NULL,"
    " finished_at = NULL, error = NULL, request = $3::text, result = NULL, result_csv = NULL,"
    " owner = NULL, lease_until = NULL WHERE id = $1::text AND state IN ('failed', 'canceled')",
    /* PG_CLAIM (DESIGN.md §6) */
    "UPDATE jobs SET state = 'running', started_at = $1::float8, attempts = attempts + 1,"
    " owner = $2::text, lease_until = $1::float8 + $3::float8"
    " WHERE id = (SELECT id FROM jobs WHERE state = 'queued' ORDER BY seq"
    " FOR UPDATE SKIP LOCKED LIMIT 1)"
    " RETURNING " PG_JOB_COLS ", request, NULL, NULL",
    /* PG_FINISH: the owner's only */
    "UPDATE jobs SET state = $2::text, finished_at = $3::float8, speeds_done = $4::int,"
    " error = $5::text, result = $6::text, result_csv = $7::text, lease_until = NULL"
    " WHERE id = $1::text AND state = 'running' AND owner = $8::text",
    /* PG_REQUEUE: the interruption was not the job's fault; a cancel
     * request is kept, so the next worker stops the job at once */
    "UPDATE jobs SET state = 'queued', started_at = NULL, speeds_done = 0,"
    " attempts = greatest(attempts - 1, 0), owner = NULL, lease_until = NULL"
    " WHERE id = $1::text AND state = 'running' AND owner = $2::text",
    /* PG_CANCEL_QUEUED */
    "UPDATE jobs SET state = 'canceled', finished_at = $2::float8"
    " WHERE id = $1::text AND state = 'queued'",
    /* PG_CANCEL_RUNNING */
    "UPDATE jobs SET cancel_requested = true WHERE id = $1::text AND state = 'running'",
    /* PG_LIST_ALL (column 14: the request's "name", codec_request_stored_text) */
    "SELECT " PG_JOB_COLS ", request::json ->> 'name' FROM jobs WHERE seq < $1::int8"
    " ORDER BY seq DESC LIMIT $2::int8",
    /* PG_LIST_STATE */
    "SELECT " PG_JOB_COLS ", request::json ->> 'name' FROM jobs WHERE state = $3::text"
    " AND seq < $1::int8"
    " ORDER BY seq DESC LIMIT $2::int8",
    /* PG_COUNT */ "SELECT state, count(*) FROM jobs GROUP BY state",
    /* PG_RENEW */
    "UPDATE jobs SET lease_until = $3::float8 + $4::float8"
    " WHERE id = $1::text AND state = 'running' AND owner = $2::text",
    /* PG_CANCEL_FLAG */ "SELECT cancel_requested::int FROM jobs WHERE id = $1::text",
    /* PG_EXPIRE: $1 now, $2 max attempts; a waiting renewal that committed
     * first makes the row fail the lease test when re-checked */
    "UPDATE jobs SET"
    " state = CASE WHEN attempts >= $2::int THEN 'failed' ELSE 'queued' END,"
    " finished_at = CASE WHEN attempts >= $2::int THEN $1::float8 END,"
    " error = CASE WHEN attempts >= $2::int THEN"
    " '{\"type\":\"interrupted\",\"title\":\"Job interrupted repeatedly\",\"detail\":\"the job"
    " was claimed ' || attempts || ' times and each time its worker stopped renewing its lease"
    " (its replica stopped or lost the database); it is not retried again — resubmit it to"
    " try once more\"}' ELSE error END,"
    " started_at = CASE WHEN attempts >= $2::int THEN started_at END,"
    " speeds_done = CASE WHEN attempts >= $2::int THEN speeds_done ELSE 0 END,"
    " owner = CASE WHEN attempts >= $2::int THEN owner END, lease_until = NULL"
    " WHERE state = 'running' AND (lease_until IS NULL OR lease_until < $1::float8)"
    " RETURNING state",
    /* PG_RECOVER: at open, as SQLite's crash recovery, for dead replicas only */
    "UPDATE jobs SET state = 'queued', started_at = NULL, speeds_done = 0, owner = NULL,"
    " lease_until = NULL WHERE state = 'running'"
    " AND (lease_until IS NULL OR lease_until < $1::float8)",
    /* PG_HEALTH: a real write, nothing changed */
    "UPDATE spinmodal_schema SET version = version",
    /* PG_WRITABLE */ "SELECT current_setting('transaction_read_only')",
    /* PG_SIZE */
    "SELECT coalesce(sum(" PG_ROW_BYTES "), 0)::int8, pg_total_relation_size('jobs') FROM jobs",
    /* PG_PRUNE_AGE: one batch of the jobs that ended before $1 */
    "DELETE FROM jobs WHERE " PG_FINISHED " AND seq IN (SELECT seq FROM jobs WHERE "
    PG_FINISHED " AND finished_at < $1::float8 ORDER BY finished_at, seq LIMIT $2::int)",
    /* PG_PRUNE_SIZE: the oldest finished jobs (other than job $3; NULL: any)
     * that free $1 bytes, one batch */
    "DELETE FROM jobs WHERE " PG_FINISHED " AND seq IN (SELECT seq FROM (SELECT seq,"
    " finished_at, sum(" PG_ROW_BYTES ") OVER (ORDER BY finished_at, seq) - " PG_ROW_BYTES
    " AS before FROM jobs WHERE " PG_FINISHED " AND id IS DISTINCT FROM $3::text) b"
    " WHERE before < $1::int8 ORDER BY finished_at, seq LIMIT $2::int)",
};

/* ---- rows ----------------------------------------------------------------- */

static long long col_ll(PGresult *r, int row, int col)
{
    return PQgetisnull(r, row, col) ? 0 : strtoll(PQgetvalue(r, row, col), NULL, 10);
}

static double col_d(PGresult *r, int row, int col)
{
    return PQgetisnull(r, row, col) ? 0.0 : strtod(PQgetvalue(r, row, col), NULL);
}

/* Copy text column col into a malloc'd string (NULL for SQL NULL).
 * Returns 0, or -1 when out of memory. */
static int col_dup(PGresult *r, int row, int col, char **out, size_t *len)
{
    int n;

    *out = NULL;
    if (len)
        *len = 0;
    if (PQgetisnull(r, row, col))
        return 0;
    n = PQgetlength(r, row, col);
    *out = malloc((size_t)n + 1);
    if (*out == NULL)
        return -1;
    memcpy(*out, PQgetvalue(r, row, col), (size_t)n);
    (*out)[n] = '\0';
    if (len)
        *len = (size_t)n;
    return 0;
}

/* The state text of a column: STORE_OK, or STORE_CORRUPT (recorded) for a
 * state the schema's CHECK forbids. */
static int col_state(pg_conn *c, PGresult *r, int row, int col, store_state *out)
{
    if (!PQgetisnull(r, row, col) && store_state_parse(PQgetvalue(r, row, col), out) == STORE_OK)
        return STORE_OK;
    return store_pg_fail_kind(c, STORE_CORRUPT, "a job row holds an unknown state");
}

/* Fill *j (overwritten, not freed) from row of r, laid out as PG_JOB_COLS;
 * with_large: columns 14 … 16 hold request, result, CSV (or NULL).  On
 * failure *j holds no allocation.  Returns a store_rc. */
static int pg_job_from_row(pg_conn *c, PGresult *r, int row, int with_large, store_job *j)
{
    int bad = 0;

    memset(j, 0, sizeof *j);
    if (PQgetlength(r, row, 1) != 64)   /* the schema's CHECK forbids it */
        return store_pg_fail_kind(c, STORE_CORRUPT, "a job row holds an id that is not 64 "
                                  "characters");
    memcpy(j->id, PQgetvalue(r, row, 1), 64);
    j->id[64] = '\0';
    j->seq = col_ll(r, row, 0);
    if (col_state(c, r, row, 2, &j->state) != STORE_OK)
        return STORE_CORRUPT;
    j->speeds_total = (int)col_ll(r, row, 3);
    j->speeds_done = (int)col_ll(r, row, 4);
    j->attempts = (int)col_ll(r, row, 5);
    j->cancel_requested = col_ll(r, row, 6) != 0;
    j->created_at = col_d(r, row, 7);
    j->started_at = col_d(r, row, 8);
    j->finished_at = col_d(r, row, 9);
    j->has_result = col_ll(r, row, 10) != 0;
    if (!PQgetisnull(r, row, 12))
        snprintf(j->owner, sizeof j->owner, "%s", PQgetvalue(r, row, 12));
    j->lease_until = col_d(r, row, 13);
    bad = col_dup(r, row, 11, &j->error, NULL);
    if (!bad && with_large)
        bad = col_dup(r, row, 14, &j->request, &j->request_len) ||
              col_dup(r, row, 15, &j->result, &j->result_len) ||
              col_dup(r, row, 16, &j->result_csv, &j->csv_len);
    if (bad) {
        store_job_clear(j);
        return store_pg_fail_kind(c, STORE_NOMEM, "out of memory copying a job's texts");
    }
    return STORE_OK;
}

/* ---- operations on one session -------------------------------------------- */

/* Read job id on c (in the caller's transaction or not). */
static int conn_get(pg_conn *c, const char *id, unsigned flags, store_job *out)
{
    const char *v[1] = {id};
    PGresult *r;
    int status = store_pg_run(c, PG_GET + (int)(flags & 7u), 1, v, NULL, NULL, &r);

    if (status != STORE_OK)
        return status;
    status = PQntuples(r) == 0 ? STORE_NOT_FOUND : pg_job_from_row(c, r, 0, 1, out);
    PQclear(r);
    return status;
}

/* The state of job id on c (k: PG_STATE, or PG_STATE_LOCK inside a
 * transaction): STORE_OK, STORE_NOT_FOUND or a failure kind. */
static int conn_state(pg_conn *c, int k, const char *id, store_state *out)
{
    const char *v[1] = {id};
    PGresult *r;
    int status = store_pg_run(c, k, 1, v, NULL, NULL, &r);

    if (status != STORE_OK)
        return status;
    status = PQntuples(r) == 0 ? STORE_NOT_FOUND : col_state(c, r, 0, 0, out);
    PQclear(r);
    return status;
}

/* Run update k with its parameters; *changed receives the rows changed. */
static int conn_update(pg_conn *c, int k, int n, const char *const *v, const int *lens,
                       const int *fmts, long long *changed)
{
    PGresult *r;
    int status = store_pg_run(c, k, n, v, lens, fmts, &r);

    if (status == STORE_OK) {
        *changed = store_pg_changed(r);
        PQclear(r);
    }
    return status;
}

/* After an update of job id changed no row: STORE_NOT_FOUND (no such job)
 * or STORE_CONFLICT (it exists in another state, or another owner's). */
static int no_change_status(pg_conn *c, const char *id)
{
    store_state st = STORE_QUEUED;
    int status = conn_state(c, PG_STATE, id, &st);

    return status == STORE_OK ? STORE_CONFLICT : status;
}

/* End c's transaction: COMMIT when status is STORE_OK, else ROLLBACK.
 * Returns status, or the kind of a failed commit. */
static int conn_end(pg_conn *c, int status)
{
    if (status == STORE_OK)
        return store_pg_exec(c, "COMMIT");
    store_pg_rollback(c);
    return status;
}

/* ---- the job operations --------------------------------------------------- */

static int pg_submit_tx(pg_conn *c, const char *id, const char *request, size_t request_len,
                        int speeds_total, double now, int *result, store_job *job)
{
    char total[16], created[32];
    const char *v[4] = {id, total, created, request};
    const int lens[4] = {0, 0, 0, (int)request_len}, fmts[4] = {0, 0, 0, 1};
    store_state state = STORE_QUEUED;
    long long changed = 0;
    int status;

    snprintf(total, sizeof total, "%d", speeds_total);
    snprintf(created, sizeof created, "%.17g", now);
    status = store_pg_exec(c, "BEGIN");
    if (status != STORE_OK)
        return status;
    status = conn_state(c, PG_STATE_LOCK, id, &state);
    if (status == STORE_NOT_FOUND) {
        status = conn_update(c, PG_INSERT, 4, v, lens, fmts, &changed);
        *result = changed == 1;   /* 0: a replica inserted it at the same moment */
    } else if (status == STORE_OK && (state == STORE_FAILED || state == STORE_CANCELED)) {
        const char *rv[3] = {id, total, request};
        const int rl[3] = {0, 0, (int)request_len}, rf[3] = {0, 0, 1};
        status = conn_update(c, PG_RESUBMIT, 3, rv, rl, rf, &changed);
        *result = 2;
    }
    if (status == STORE_OK && job)
        status = conn_get(c, id, 0, job);
    status = conn_end(c, status);
    if (status != STORE_OK)
        store_job_clear(job);
    return status;
}

static int pg_submit(store *s, const char *id, const char *request, size_t request_len,
                     int speeds_total, double now, int *outcome, store_job *job)
{
    pg_conn *c;
    int status, result = 0;

    if (request_len > 0x7fffffff)
        return STORE_INVALID;
    status = store_pg_acquire(s, "submit", &c);
    if (status != STORE_OK)
        return status;
    status = pg_submit_tx(c, id, request, request_len, speeds_total, now, &result, job);
    if (status == STORE_OK && result != 0)
        (void)store_pg_trim(s, c, (long long)request_len + 120, id);   /* recorded */
    store_pg_release(s, c);
    if (status == STORE_OK && outcome)
        *outcome = result;
    return status;
}

static int pg_get(store *s, const char *id, unsigned flags, store_job *out)
{
    pg_conn *c;
    int status = store_pg_acquire(s, "get", &c);

    if (status != STORE_OK)
        return status;
    status = conn_get(c, id, flags, out);
    store_pg_release(s, c);
    return status;
}

static int pg_claim_next(store *s, double now, store_job *out)
{
    char t[32], lease[32];
    const char *v[3] = {t, s->owner, lease};
    PGresult *r;
    pg_conn *c;
    int status = store_pg_acquire(s, "claim", &c);

    if (status != STORE_OK)
        return status;
    snprintf(t, sizeof t, "%.17g", now);
    snprintf(lease, sizeof lease, "%.17g", s->lease_s);
    status = store_pg_run(c, PG_CLAIM, 3, v, NULL, NULL, &r);
    if (status == STORE_OK) {
        status = PQntuples(r) == 0 ? STORE_NOT_FOUND : pg_job_from_row(c, r, 0, 1, out);
        PQclear(r);
    }
    store_pg_release(s, c);
    return status;
}

static int pg_finish(store *s, const char *id, store_state state, double now, int speeds_done,
                     const char *error, const char *result, size_t result_len, const char *csv,
                     size_t csv_len)
{
    char t[32], done[16];
    const char *v[8] = {id, store_state_name(state), t, done, error, result, csv, s->owner};
    const int lens[8] = {0, 0, 0, 0, 0, (int)result_len, (int)csv_len, 0};
    const int fmts[8] = {0, 0, 0, 0, 0, 1, 1, 0};
    long long changed = 0;
    pg_conn *c;
    int status;

    if (result_len > 0x7fffffff || csv_len > 0x7fffffff)
        return STORE_INVALID;
    status = store_pg_acquire(s, "finish", &c);
    if (status != STORE_OK)
        return status;
    snprintf(t, sizeof t, "%.17g", now);
    snprintf(done, sizeof done, "%d", speeds_done);
    status = conn_update(c, PG_FINISH, 8, v, lens, fmts, &changed);
    if (status == STORE_OK && changed == 0)
        status = no_change_status(c, id);
    if (status == STORE_OK)   /* the budget on insert; a failure is recorded, the end kept */
        (void)store_pg_trim(s, c, (long long)(result_len + csv_len + (error ? strlen(error) : 0)),
                            id);
    store_pg_release(s, c);
    return status;
}

static int pg_requeue(store *s, const char *id)
{
    const char *v[2] = {id, s->owner};
    long long changed = 0;
    pg_conn *c;
    int status = store_pg_acquire(s, "requeue", &c);

    if (status != STORE_OK)
        return status;
    status = conn_update(c, PG_REQUEUE, 2, v, NULL, NULL, &changed);
    if (status == STORE_OK && changed == 0)
        status = no_change_status(c, id);
    store_pg_release(s, c);
    return status;
}

static int pg_cancel_tx(pg_conn *c, const char *id, double now, store_state *state)
{
    char t[32];
    const char *v[2] = {id, t};
    store_state cur = STORE_QUEUED;
    long long changed = 0;
    int status = store_pg_exec(c, "BEGIN");

    if (status != STORE_OK)
        return status;
    snprintf(t, sizeof t, "%.17g", now);
    status = conn_state(c, PG_STATE_LOCK, id, &cur);
    if (status == STORE_OK && state)
        *state = cur;
    if (status == STORE_OK && cur != STORE_QUEUED && cur != STORE_RUNNING)
        status = STORE_CONFLICT;
    if (status == STORE_OK)
        status = conn_update(c, cur == STORE_QUEUED ? PG_CANCEL_QUEUED : PG_CANCEL_RUNNING,
                             cur == STORE_QUEUED ? 2 : 1, v, NULL, NULL, &changed);
    status = conn_end(c, status);
    if (status == STORE_OK && state && cur == STORE_QUEUED)
        *state = STORE_CANCELED;
    return status;
}

static int pg_cancel(store *s, const char *id, double now, store_state *state)
{
    pg_conn *c;
    int status = store_pg_acquire(s, "cancel", &c);

    if (status != STORE_OK)
        return status;
    status = pg_cancel_tx(c, id, now, state);
    store_pg_release(s, c);
    return status;
}

static int pg_list(store *s, long long before, int filter, int max, store_job *out, int *n,
                   int *more)
{
    char b[32], lim[32];
    const char *v[3] = {b, lim, filter >= 0 ? store_state_name((store_state)filter) : NULL};
    PGresult *r;
    pg_conn *c;
    int status = store_pg_acquire(s, "list", &c), rows;

    if (status != STORE_OK)
        return status;
    snprintf(b, sizeof b, "%lld", before > 0 ? before : 0x7fffffffffffffffLL);
    snprintf(lim, sizeof lim, "%lld", (long long)max + 1);   /* one more: is there more? */
    status = store_pg_run(c, filter >= 0 ? PG_LIST_STATE : PG_LIST_ALL, filter >= 0 ? 3 : 2, v,
                          NULL, NULL, &r);
    if (status == STORE_OK) {
        rows = PQntuples(r);
        for (int i = 0; i < rows && i < max && status == STORE_OK; i++) {
            status = pg_job_from_row(c, r, i, 0, &out[i]);
            if (status == STORE_OK && col_dup(r, i, 14, &out[i].name, NULL)) {
                store_job_clear(&out[i]);
                status = store_pg_fail_kind(c, STORE_NOMEM, "out of memory copying a job's name");
            }
            if (status == STORE_OK)
                (*n)++;
        }
        *more = rows > max;
        PQclear(r);
    }
    store_pg_release(s, c);
    if (status != STORE_OK) {
        for (int i = 0; i < *n; i++)
            store_job_clear(&out[i]);
        *n = 0;
        *more = 0;
    }
    return status;
}

static int pg_count(store *s, long long counts[STORE_N_STATES])
{
    PGresult *r;
    pg_conn *c;
    store_state state;
    int status = store_pg_acquire_probe(s, "count", &c);

    if (status != STORE_OK)
        return status;
    status = store_pg_run(c, PG_COUNT, 0, NULL, NULL, NULL, &r);
    if (status == STORE_OK) {
        for (int i = 0; i < PQntuples(r) && status == STORE_OK; i++) {
            status = col_state(c, r, i, 0, &state);
            if (status == STORE_OK)
                counts[state] = col_ll(r, i, 1);
        }
        PQclear(r);
    }
    store_pg_release(s, c);
    if (status != STORE_OK)
        for (int i = 0; i < STORE_N_STATES; i++)
            counts[i] = 0;
    return status;
}

/* ---- the calls of several replicas ---------------------------------------- */

static int pg_renew_lease(store *s, const char *id, const char *owner, double now,
                          double lease_s)
{
    char t[32], l[32];
    const char *v[4] = {id, owner, t, l};
    long long changed = 0;
    pg_conn *c;
    int status = store_pg_acquire(s, "renew_lease", &c);

    if (status != STORE_OK)
        return status;
    snprintf(t, sizeof t, "%.17g", now);
    snprintf(l, sizeof l, "%.17g", lease_s);
    status = conn_update(c, PG_RENEW, 4, v, NULL, NULL, &changed);
    if (status == STORE_OK && changed == 0)
        status = no_change_status(c, id);
    store_pg_release(s, c);
    return status;
}

static int pg_requeue_expired(store *s, double now, int max_attempts, int *requeued,
                              int *failed)
{
    char t[32], m[16];
    const char *v[2] = {t, m};
    PGresult *r;
    pg_conn *c;
    int status = store_pg_acquire(s, "requeue_expired", &c);

    if (status != STORE_OK)
        return status;
    snprintf(t, sizeof t, "%.17g", now);
    snprintf(m, sizeof m, "%d", max_attempts);
    status = store_pg_run(c, PG_EXPIRE, 2, v, NULL, NULL, &r);
    if (status == STORE_OK) {
        for (int i = 0; i < PQntuples(r); i++) {
            if (strcmp(PQgetvalue(r, i, 0), "failed") == 0)
                (*failed)++;
            else
                (*requeued)++;
        }
        PQclear(r);
    }
    store_pg_release(s, c);
    return status;
}

static int pg_cancel_requested(store *s, const char *id, int *flag)
{
    const char *v[1] = {id};
    PGresult *r;
    pg_conn *c;
    int status = store_pg_acquire(s, "cancel_requested", &c);

    if (status != STORE_OK)
        return status;
    status = store_pg_run(c, PG_CANCEL_FLAG, 1, v, NULL, NULL, &r);
    if (status == STORE_OK) {
        if (PQntuples(r) == 0)
            status = STORE_NOT_FOUND;
        else
            *flag = col_ll(r, 0, 0) != 0;
        PQclear(r);
    }
    store_pg_release(s, c);
    return status;
}

static int pg_state_of(store *s, const char *id, store_state *state)
{
    pg_conn *c;
    int status = store_pg_acquire(s, "state_of", &c);

    if (status != STORE_OK)
        return status;
    status = conn_state(c, PG_STATE, id, state);
    store_pg_release(s, c);
    return status;
}

/* ---- the backend table --------------------------------------------------- */

const store_backend store_pg_backend = {
    .name = "postgresql",
    .caps = STORE_CAP_SHARED | STORE_CAP_SECRET_PATH,
    .open = store_pg_open,
    .close = store_pg_close,
    .schema_version = store_pg_schema_version,
    .submit = pg_submit,
    .get = pg_get,
    .claim_next = pg_claim_next,
    .finish = pg_finish,
    .requeue = pg_requeue,
    .cancel = pg_cancel,
    .list = pg_list,
    .count = pg_count,
    .check_writable = store_pg_check_writable,
    .health = store_pg_health,
    .prune = store_pg_prune,
    .size = store_pg_size,
    .renew_lease = pg_renew_lease,
    .requeue_expired = pg_requeue_expired,
    .cancel_requested = pg_cancel_requested,
    .state_of = pg_state_of,
};
