/*
 * store_pg_open.c — opening and closing a PostgreSQL store, its schema
 * and migrations, the probes and retention (store.h: store_open_with,
 * store_check_writable, store_health, store_size, store_prune).
 *
 * Order at open, each step refusing with a sentence in err:
 *   1. parse the URI (libpq's syntax; a typo is STORE_INVALID, not a hang);
 *   2. connect one session of the pool (the others open on demand);
 *   3. pg_advisory_lock(STORE_PG_LOCK_KEY): replicas starting together
 *      wait here for the first one's migrations and then find nothing to
 *      do; the lock is the session's, so a replica killed while migrating
 *      lets go of it with its connection;
 *   4. look at the database: spinmodal_schema holds the schema version
 *      (one row); a newer version than this code knows, or a `jobs` table
 *      without spinmodal_schema (another application's), is refused;
 *   5. migrations, one transaction each (PostgreSQL's DDL is transactional:
 *      a failed step leaves the previous version);
 *   6. unlock; put back to `queued` the running jobs whose lease ended
 *      before this host's clock (their replica is gone).
 * Messages never show the URI itself (it may hold a password): only host,
 * port and database name.
 *
 * Schema.  id (the content address) is the primary key; seq, from a
 * sequence, is the queue order and list cursor as on SQLite; owner and
 * lease_until say who runs a job and until when.  A partial index on the
 * queued jobs' seq keeps a claim one index probe however many finished
 * jobs the table holds; one on the running jobs' lease_until serves
 * store_requeue_expired.  Large texts (text, TOASTed and compressed by
 * the server) are the last columns.
 *
 * Retention.  Rows are deleted in batches of PRUNE_BATCH, each its own
 * transaction (store_prune; and store_pg_trim, the budget on insert, after
 * a submission or a finish when this store's estimate of the live data
 * passes the budget or a second after its last measure); the server's autovacuum makes their space reusable (the
 * files do not shrink without VACUUM FULL, which locks the table: an
 * operator's decision, not the daemon's).  Live data is measured from the
 * stored sizes of the texts (pg_column_size, no detoasting): a scan of the
 * table's small columns, milliseconds for 100 000 jobs.
 */
#include "store_pg.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { PRUNE_BATCH = 256 };
#define STORE_PG_OPEN_TEXT "60000"   /* STORE_PG_OPEN_MS, for SQL */

/* The migrations: store_pg_migrations[k] brings schema version k to k + 1. */
static const char *const store_pg_migrations[] = {
    /* 1: the jobs table.  state is the store_state_name text; times are
     * unix seconds, NULL until they happen; large texts come last. */
    "CREATE SEQUENCE jobs_seq;"
    "CREATE TABLE jobs ("
    " id text PRIMARY KEY CHECK (length(id) = 64),"
    " seq bigint NOT NULL UNIQUE DEFAULT nextval('jobs_seq'),"
    " state text NOT NULL CHECK (state IN ('queued','running','done','failed','canceled')),"
    " speeds_total integer NOT NULL,"
    " speeds_done integer NOT NULL DEFAULT 0,"
    " attempts integer NOT NULL DEFAULT 0,"
    " cancel_requested boolean NOT NULL DEFAULT false,"
    " created_at double precision NOT NULL,"
    " started_at double precision,"
    " finished_at double precision,"
    " owner text,"
    " lease_until double precision,"
    " error text,"
    " request text NOT NULL,"
    " result text,"
    " result_csv text);"
    "ALTER SEQUENCE jobs_seq OWNED BY jobs.seq;"
    "CREATE INDEX jobs_queued ON jobs (seq) WHERE state = 'queued';"
    "CREATE INDEX jobs_running_lease ON jobs (lease_until) WHERE state = 'running';"
    "CREATE INDEX jobs_state_seq ON jobs (state, seq);",
};
#define STORE_PG_SCHEMA_VERSION ((int)(sizeof store_pg_migrations / sizeof store_pg_migrations[0]))

/* "host:port/dbname" of a URI, without user or password, for messages. */
static void describe(const char *dsn, char *out, size_t len)
{
    PQconninfoOption *opts = PQconninfoParse(dsn, NULL);
    const char *host = "localhost", *port = "5432", *db = "(default)";

    if (opts != NULL) {
        for (PQconninfoOption *o = opts; o->keyword; o++) {
            if (o->val == NULL || o->val[0] == '\0')
                continue;
            if (strcmp(o->keyword, "host") == 0 || strcmp(o->keyword, "hostaddr") == 0)
                host = o->val;
            else if (strcmp(o->keyword, "port") == 0)
                port = o->val;
            else if (strcmp(o->keyword, "dbname") == 0)
                db = o->val;
        }
    }
    snprintf(out, len, "%s:%s/%s", host, port, db);
    PQconninfoFree(opts);
}

/* The text of the last failure recorded by s (for err at open). */
static const char *last_text(store *s, store_error *e)
{
    (void)store_last_error(s, e);
    return e->text;
}

/* ---- schema --------------------------------------------------------------- */

/* One-row, one-column query on c into buf; STORE_OK, or the recorded kind. */
static int query_text(pg_conn *c, const char *sql, char *buf, size_t len)
{
    PGresult *r = NULL;
    int status = store_pg_query(c, sql, &r);

    buf[0] = '\0';
    if (status != STORE_OK)
        return status;
    if (PQntuples(r) > 0 && !PQgetisnull(r, 0, 0))
        snprintf(buf, len, "%s", PQgetvalue(r, 0, 0));
    PQclear(r);
    return status;
}

/* Step 4: the schema version of the database, 0 when it has none yet.
 * Returns a store_rc with err set on refusal. */
static int pg_inspect(pg_conn *c, const char *where, int *version, char *err, size_t errlen)
{
    store_error e;
    char both[8];
    int rc;

    *version = 0;
    rc = query_text(c, "SELECT (to_regclass('spinmodal_schema') IS NOT NULL)::int::text ||"
                       " (to_regclass('jobs') IS NOT NULL)::int::text", both, sizeof both);
    if (rc == STORE_OK && strcmp(both, "01") == 0) {
        store_seterr(err, errlen, "PostgreSQL database %s has a table 'jobs' but is not a spinmodal "
               "one (no spinmodal_schema table); give spinmodald its own database or schema",
               where);
        return STORE_ERROR;
    }
    if (rc == STORE_OK && both[0] == '1') {
        char v[16];
        rc = query_text(c, "SELECT version FROM spinmodal_schema", v, sizeof v);
        *version = atoi(v);
    }
    if (rc != STORE_OK) {
        store_seterr(err, errlen, "cannot read PostgreSQL database %s: %s", where,
               last_text(c->owner, &e));
        return rc;
    }
    if (*version > STORE_PG_SCHEMA_VERSION) {
        store_seterr(err, errlen, "database schema version %d is newer than this spinmodald (%d)",
               *version, STORE_PG_SCHEMA_VERSION);
        return STORE_ERROR;
    }
    return STORE_OK;
}

/* Step 5: migration k (version k → k + 1) in one transaction. */
static int pg_migrate_one(pg_conn *c, int k)
{
    char sql[80];
    int rc = store_pg_exec(c, "BEGIN");

    if (rc == STORE_OK && k == 0)
        rc = store_pg_exec(c, "CREATE TABLE spinmodal_schema (version integer NOT NULL);"
                              "INSERT INTO spinmodal_schema VALUES (0)");
    if (rc == STORE_OK)
        rc = store_pg_exec(c, store_pg_migrations[k]);
    snprintf(sql, sizeof sql, "UPDATE spinmodal_schema SET version = %d", k + 1);
    if (rc == STORE_OK)
        rc = store_pg_exec(c, sql);
    if (rc == STORE_OK)
        rc = store_pg_exec(c, "COMMIT");
    if (rc != STORE_OK)
        store_pg_rollback(c);
    return rc;
}

/* Steps 3 … 5 under the advisory lock. */
static int pg_migrate(store_pg *q, pg_conn *c, const char *where, char *err, size_t errlen)
{
    char sql[64], ignored[8];
    store_error e;
    int rc, version = 0;

    snprintf(sql, sizeof sql, "SELECT pg_advisory_lock(%d)::text", STORE_PG_LOCK_KEY);
    rc = query_text(c, sql, ignored, sizeof ignored);
    if (rc != STORE_OK) {
        store_seterr(err, errlen, "cannot lock PostgreSQL database %s for the migrations: %s", where,
               last_text(c->owner, &e));
        return rc;
    }
    rc = pg_inspect(c, where, &version, err, errlen);
    while (rc == STORE_OK && version < STORE_PG_SCHEMA_VERSION) {
        rc = pg_migrate_one(c, version);
        if (rc != STORE_OK)
            store_seterr(err, errlen, "cannot migrate PostgreSQL database %s to schema version %d: %s",
                   where, version + 1, last_text(c->owner, &e));
        else
            version++;
    }
    snprintf(sql, sizeof sql, "SELECT pg_advisory_unlock(%d)::text", STORE_PG_LOCK_KEY);
    if (rc == STORE_OK && (rc = query_text(c, sql, ignored, sizeof ignored)) != STORE_OK)
        store_seterr(err, errlen, "cannot unlock PostgreSQL database %s: %s", where,
               last_text(c->owner, &e));
    if (rc != STORE_OK)
        store_pg_disconnect(c);   /* ends the session, and its advisory lock */
    q->version = version;
    return rc;
}

/* Step 6: jobs of replicas that died, by this host's clock. */
static int pg_recover(store *s, pg_conn *c, const char *where, int *requeued, char *err,
                      size_t errlen)
{
    char t[32];
    const char *v[1] = {t};
    struct timespec now;
    store_error e;
    PGresult *r;
    int rc;

    (void)clock_gettime(CLOCK_REALTIME, &now);
    snprintf(t, sizeof t, "%.17g", (double)now.tv_sec + 1e-9 * (double)now.tv_nsec);
    rc = store_pg_run(c, PG_RECOVER, 1, v, NULL, NULL, &r);
    if (rc != STORE_OK) {
        store_seterr(err, errlen, "cannot requeue the expired jobs of PostgreSQL database %s: %s",
               where, last_text(s, &e));
        return rc;
    }
    if (requeued)
        *requeued = (int)store_pg_changed(r);
    PQclear(r);
    return STORE_OK;
}

/* ---- open and close ------------------------------------------------------- */

/* The pool's lock, condition variable and free list; 0 or -1. */
static int pool_init(store *s, store_pg *q)
{
    if (pthread_mutex_init(&q->pool_lock, NULL) != 0)
        return -1;
    if (pthread_mutex_init(&q->probe_lock, NULL) != 0) {
        (void)pthread_mutex_destroy(&q->pool_lock);
        return -1;
    }
    if (pthread_cond_init(&q->pool_cond, NULL) != 0) {
        (void)pthread_mutex_destroy(&q->probe_lock);
        (void)pthread_mutex_destroy(&q->pool_lock);
        return -1;
    }
    q->locks_ready = 1;
    q->probe_conn.owner = s;
    q->probe_conn.probe = 1;
    for (int i = STORE_PG_CONNS - 1; i >= 0; i--) {
        q->conns[i].owner = s;
        q->conns[i].next = q->free_conns;
        q->free_conns = &q->conns[i];
    }
    return 0;
}

/* Steps 2 … 6 on a store whose pool exists. */
static int pg_open_db(store *s, const char *where, int *requeued, char *err, size_t errlen)
{
    store_error e;
    pg_conn *c;
    int rc = store_pg_acquire(s, "open", &c);

    if (rc != STORE_OK) {
        store_seterr(err, errlen, "cannot connect to PostgreSQL database %s: %s", where,
               last_text(s, &e));
        return rc;
    }
    /* the migrations (and the wait for another replica's) get a longer
     * deadline than a call; the session is closed after, so the pool's
     * sessions all have the call's statement_timeout */
    c->deadline = store_mono() + STORE_PG_OPEN_MS / 1000.0;
    c->budget_ms = STORE_PG_OPEN_MS;
    rc = store_pg_exec(c, "SET statement_timeout = " STORE_PG_OPEN_TEXT);
    if (rc != STORE_OK)
        store_seterr(err, errlen, "cannot set up a session of PostgreSQL database %s: %s",
                     where, last_text(s, &e));
    if (rc == STORE_OK)
        rc = pg_migrate(s->impl, c, where, err, errlen);
    if (rc == STORE_OK)
        rc = pg_recover(s, c, where, requeued, err, errlen);
    store_pg_disconnect(c);
    store_pg_release(s, c);
    return rc;
}

int store_pg_open(store *s, const store_settings *set, int *requeued, char *err, size_t errlen)
{
    PQconninfoOption *opts;
    char *perr = NULL, where[200];
    store_pg *q;
    int rc;

    s->impl = NULL;
    opts = PQconninfoParse(set->path, &perr);
    if (opts == NULL) {
        store_seterr(err, errlen, "invalid PostgreSQL URI: %s",
               perr ? perr : "out of memory parsing it");
        if (perr)
            PQfreemem(perr);
        return perr ? STORE_INVALID : STORE_NOMEM;
    }
    PQconninfoFree(opts);
    describe(set->path, where, sizeof where);
    q = calloc(1, sizeof *q);
    if (q == NULL || (q->dsn = strdup(set->path)) == NULL) {
        free(q);
        store_seterr(err, errlen, "out of memory opening the database");
        return STORE_NOMEM;
    }
    q->lock_timeout_ms = set->busy_timeout_ms > 0 ? set->busy_timeout_ms : 1;
    if (q->lock_timeout_ms > s->timeout_ms)   /* a lock wait inside a call's deadline */
        q->lock_timeout_ms = s->timeout_ms;
    s->impl = q;
    if (pool_init(s, q) != 0) {
        store_seterr(err, errlen, "cannot create the connection pool's locks");
        rc = STORE_ERROR;
    } else {
        rc = pg_open_db(s, where, requeued, err, errlen);
    }
    if (rc != STORE_OK) {
        if (requeued)
            *requeued = 0;
        store_pg_close(s);   /* store.c frees s */
    }
    return rc;
}

void store_pg_close(store *s)
{
    store_pg *q = s->impl;

    if (q == NULL)
        return;
    for (int i = 0; i < STORE_PG_CONNS; i++)
        store_pg_disconnect(&q->conns[i]);
    store_pg_disconnect(&q->probe_conn);
    if (q->locks_ready) {
        (void)pthread_cond_destroy(&q->pool_cond);
        (void)pthread_mutex_destroy(&q->probe_lock);
        (void)pthread_mutex_destroy(&q->pool_lock);
    }
    free(q->dsn);
    free(q);
    s->impl = NULL;
}

int store_pg_schema_version(store *s)
{
    store_pg *q = s->impl;

    return q->version;
}

/* ---- probes --------------------------------------------------------------- */

int store_pg_check_writable(store *s)
{
    PGresult *r;
    pg_conn *c;
    int status = store_pg_acquire_probe(s, "check_writable", &c);

    if (status != STORE_OK)
        return status;
    status = store_pg_run(c, PG_WRITABLE, 0, NULL, NULL, NULL, &r);
    if (status == STORE_OK) {
        if (PQntuples(r) != 1 || strcmp(PQgetvalue(r, 0, 0), "off") != 0)
            status = store_pg_fail_kind(c, STORE_READONLY, "the PostgreSQL session is "
                                        "read-only (a standby, or default_transaction_read_only)");
        PQclear(r);
    }
    store_pg_release(s, c);
    return status;
}

int store_pg_health(store *s)
{
    long long changed;
    PGresult *r;
    pg_conn *c;
    int status = store_pg_acquire_probe(s, "health", &c);

    if (status != STORE_OK)
        return status;
    status = store_pg_run(c, PG_HEALTH, 0, NULL, NULL, NULL, &r);
    if (status == STORE_OK) {
        changed = store_pg_changed(r);
        PQclear(r);
        if (changed != 1)
            status = store_pg_fail_kind(c, STORE_ERROR, "the table spinmodal_schema lost its row");
    }
    store_pg_release(s, c);
    return status;
}

/* ---- size and retention --------------------------------------------------- */

/* Live and file bytes on c (store_size's meaning).  Returns a store_rc. */
static int conn_size(pg_conn *c, long long *live, long long *file)
{
    PGresult *r;
    int status = store_pg_run(c, PG_SIZE, 0, NULL, NULL, NULL, &r);

    if (status != STORE_OK)
        return status;
    *live = strtoll(PQgetvalue(r, 0, 0), NULL, 10);
    if (file)
        *file = strtoll(PQgetvalue(r, 0, 1), NULL, 10);
    PQclear(r);
    return STORE_OK;
}

int store_pg_size(store *s, long long *live_bytes, long long *file_bytes)
{
    pg_conn *c;
    int status = store_pg_acquire_probe(s, "size", &c);

    if (status != STORE_OK)
        return status;
    status = conn_size(c, live_bytes, file_bytes);
    store_pg_release(s, c);
    if (status != STORE_OK) {
        *live_bytes = 0;
        *file_bytes = 0;
    }
    return status;
}

/* Delete batches of at most PRUNE_BATCH finished jobs, each its own
 * transaction: by_age, those that ended before cutoff, until a batch comes
 * back short; else the oldest other than keep_id (NULL: any), until the
 * live data fits max_bytes (or only unfinished jobs are left; *live, may
 * be NULL, receives the last measure).  Returns a store_rc; *removed
 * counts. */
static int prune_loop(pg_conn *c, int by_age, double cutoff, long long max_bytes,
                      const char *keep_id, long long *removed, long long *live_out)
{
    char bound[32], batch[16];
    const char *v[3] = {bound, batch, keep_id};
    long long changed, live = 0;
    PGresult *r;
    int status;

    snprintf(batch, sizeof batch, "%d", PRUNE_BATCH);
    if (by_age)
        snprintf(bound, sizeof bound, "%.17g", cutoff);
    for (;;) {
        if (!by_age) {
            status = conn_size(c, &live, NULL);
            if (live_out)
                *live_out = live;
            if (status != STORE_OK || live <= max_bytes)
                return status;
            snprintf(bound, sizeof bound, "%lld", live - max_bytes);
        }
        status = store_pg_run(c, by_age ? PG_PRUNE_AGE : PG_PRUNE_SIZE, by_age ? 2 : 3, v, NULL,
                              NULL, &r);
        if (status != STORE_OK)
            return status;
        changed = store_pg_changed(r);
        PQclear(r);
        *removed += changed;
        if (changed == 0 || (by_age && changed < PRUNE_BATCH))
            return STORE_OK;
    }
}

int store_pg_prune(store *s, int by_age, double cutoff, long long max_bytes, long long *removed)
{
    pg_conn *c;
    int status = store_pg_acquire(s, "prune", &c);

    if (status != STORE_OK)
        return status;
    if (by_age)
        status = prune_loop(c, 1, cutoff, 0, NULL, removed, NULL);
    if (status == STORE_OK && max_bytes > 0)
        status = prune_loop(c, 0, 0, max_bytes, NULL, removed, NULL);
    store_pg_release(s, c);
    return status;
}

int store_pg_trim(store *s, pg_conn *c, long long added, const char *keep_id)
{
    store_pg *q = s->impl;
    long long live = 0, removed = 0;
    const char *op = c->op;
    double now = store_mono();
    int need, status;

    if (s->retain_bytes <= 0)
        return STORE_OK;
    (void)pthread_mutex_lock(&q->pool_lock);
    q->live_est += added;
    /* what this store wrote is counted (uncompressed: more than it takes);
     * other replicas' writes show at the next measure, a second at most */
    need = q->live_est > s->retain_bytes || now - q->measured_at >= 1.0;
    (void)pthread_mutex_unlock(&q->pool_lock);
    if (!need)
        return STORE_OK;
    c->op = "prune";
    c->deadline = now + s->timeout_ms / 1000.0;
    status = prune_loop(c, 0, 0, s->retain_bytes, keep_id, &removed, &live);
    c->op = op;
    (void)pthread_mutex_lock(&q->pool_lock);
    q->live_est = status == STORE_OK ? live : s->retain_bytes + 1;   /* unknown: measure next */
    q->measured_at = status == STORE_OK ? now : 0.0;
    (void)pthread_mutex_unlock(&q->pool_lock);
    store_note_pruned(s, removed);
    return status;
}
