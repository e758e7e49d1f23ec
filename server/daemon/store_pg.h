/*
 * store_pg.h — private to the PostgreSQL backend (store_pg.c,
 * store_pg_open.c): the backend's state, its pool of libpq connections,
 * the statement table and the helpers both files use.
 */
#ifndef SPINMODAL_STORE_PG_H
#define SPINMODAL_STORE_PG_H

#include "store_backend.h"

#include <libpq-fe.h>
#include <pthread.h>

enum {
    STORE_PG_CONNS = 8,               /* the pool: connections opened on demand */
    STORE_PG_LOCK_KEY = 0x534d4f44,   /* pg_advisory_lock key of the migrations: "SMOD" */
    STORE_PG_RETRY_MS = 1000,         /* after a failed connect or a stalled call, fail at
                                       * once this long, then let one call try */
    STORE_PG_OPEN_MS = 60000,         /* deadline (and statement_timeout) of the opening
                                       * session: the migrations, the advisory lock */
    STORE_PG_SEND_RATE = 4 << 20      /* bytes a second a round trip's deadline allows
                                       * for what it sends (a large result) */
};

/* Prepared statements, one set per connection (store_pg_sql), prepared on
 * first use.  PG_GET + flags (0 … 7) selects the large texts (STORE_WITH_*). */
enum {
    PG_GET = 0,
    PG_STATE = 8,
    PG_STATE_LOCK,
    PG_INSERT,
    PG_RESUBMIT,
    PG_CLAIM,
    PG_FINISH,
    PG_REQUEUE,
    PG_CANCEL_QUEUED,
    PG_CANCEL_RUNNING,
    PG_LIST_ALL,
    PG_LIST_STATE,
    PG_COUNT,
    PG_RENEW,
    PG_CANCEL_FLAG,
    PG_EXPIRE,
    PG_RECOVER,
    PG_HEALTH,
    PG_WRITABLE,
    PG_SIZE,
    PG_PRUNE_AGE,
    PG_PRUNE_SIZE,
    PG_N
};

/* One pooled connection.  Used by one thread at a time (taken from the
 * pool), so op may name the operation it serves for the error record,
 * and deadline the end of that call. */
typedef struct pg_conn {
    PGconn *conn;                 /* NULL when not connected; nonblocking when connected */
    unsigned long long prepared;  /* bit k: statement k prepared on conn */
    struct pg_conn *next;         /* free list */
    store *owner;                 /* for store_note_error_state */
    const char *op;               /* "submit", "get", …: the operation using it now */
    double deadline;              /* monotonic s: the call fails with STORE_TIMEOUT after */
    int budget_ms;                /* the call's budget (timeout_ms or probe_ms) */
    int probe;                    /* 1: the probes' own session (store_pg_acquire_probe) */
    int answered;                 /* 1 once the server answered during this call */
    int trying;                   /* 1: the one call let through while the server is down */
} pg_conn;

/* The backend's state: s->impl of a PostgreSQL store. */
typedef struct store_pg {
    char *dsn;                        /* the URI given, malloc'd */
    pg_conn conns[STORE_PG_CONNS];
    pg_conn *free_conns;              /* not in use, under pool_lock */
    pthread_mutex_t pool_lock;
    pthread_cond_t pool_cond;         /* signalled when a connection is returned */
    pg_conn probe_conn;               /* the probes' session, under probe_lock */
    pthread_mutex_t probe_lock;
    int locks_ready;                  /* 1 once the mutexes and condvar exist */
    int down;                         /* 1 after a failed connect or a call that timed out,
                                       * until the server answers again (pool_lock) */
    int down_kind;                    /* STORE_UNAVAILABLE or STORE_TIMEOUT */
    int trying;                       /* 1 while the one call allowed while down runs */
    double retry_at;                  /* monotonic s: no call before (when down) */
    char down_text[256];              /* the words of the failure that set down */
    double probe_retry_at;            /* monotonic s: after a probe timed out, probes fail
                                       * at once until then (pool_lock) */
    int lock_timeout_ms;              /* settings' busy_timeout_ms, at most timeout_ms */
    int version;                      /* schema version after the migrations */
    long long live_est;               /* budget on insert: live bytes measured, plus what
                                       * this store wrote since (pool_lock) */
    double measured_at;               /* monotonic s of that measure, 0 = never */
} store_pg;

/* The SQL text of each prepared statement. */
extern const char *const store_pg_sql[PG_N];

/* SQLSTATE (may be NULL) and the connection's status → store_rc kind. */
int store_pg_kind(const char *sqlstate, int connection_bad);

/* Open a new session on c before c->deadline (libpq's asynchronous
 * connect; connect_timeout, 2 s unless the DSN sets it, bounds it too),
 * nonblocking, with lock and statement timeouts (statement: stmt_ms).
 * Returns STORE_OK, or the kind (STORE_UNAVAILABLE, STORE_TIMEOUT, …) with
 * libpq's text in err (the caller records it). */
int store_pg_connect(store *s, pg_conn *c, int stmt_ms, char *err, size_t errlen);

/* Close the session of c (statements forgotten). */
void store_pg_disconnect(pg_conn *c);

/* Take a connection for operation op: a live one from the pool, or a new
 * session; the call's deadline (c->deadline) starts now, timeout_ms long.
 * *out NULL on failure.  Returns STORE_OK, or (recorded) STORE_UNAVAILABLE
 * or STORE_TIMEOUT: at once while the server was unreachable or stalled
 * less than STORE_PG_RETRY_MS ago (then one call tries again), or when no
 * connection came free before the deadline. */
int store_pg_acquire(store *s, const char *op, pg_conn **out);

/* store_pg_acquire for a probe (check_writable, health, count, size):
 * the probes' own session, within probe_timeout_ms; a probe that times
 * out does not mark the server stalled. */
int store_pg_acquire_probe(store *s, const char *op, pg_conn **out);

/* Give c back; a broken session, or one left inside a transaction, is
 * closed first (reconnected at its next use).  A call the server answered
 * ends the stalled/unreachable state; the one call allowed while down
 * that got no answer sets the next try a second later. */
void store_pg_release(store *s, pg_conn *c);

/* Run statement k on c with n parameters (vals[i] NULL = SQL NULL; lens
 * and fmts may be NULL: text; fmts[i] = 1 passes vals[i] as lens[i]
 * bytes).  *res receives the result (PQclear it) on STORE_OK, NULL
 * otherwise.  A failure is recorded with libpq's text and its kind
 * returned. */
int store_pg_run(pg_conn *c, int k, int n, const char *const *vals, const int *lens,
                 const int *fmts, PGresult **res);

/* Run a command without parameters (BEGIN, COMMIT, …) on c; recorded. */
int store_pg_exec(pg_conn *c, const char *sql);

/* Run sql (no parameters; several statements allowed) on c; *res the
 * result of a command or a query (PQclear it) on STORE_OK; a failure is
 * recorded and its kind returned. */
int store_pg_query(pg_conn *c, const char *sql, PGresult **res);

/* The budget on insert (store_settings.retain_bytes) after this store
 * wrote about added bytes on c: when its estimate of the live data passes
 * the budget, or a second after it last measured, measure and delete the
 * oldest finished jobs other than keep_id until the live data fits
 * (on_pruned told).  A fresh deadline.  Returns a store_rc (recorded). */
int store_pg_trim(store *s, pg_conn *c, long long added, const char *keep_id);

/* Roll back the session's open transaction (after a failed statement); best effort. */
void store_pg_rollback(pg_conn *c);

/* Record a failure of c that libpq did not see (a malformed row, memory). */
int store_pg_fail_kind(pg_conn *c, int kind, const char *text);

/* The number of rows an UPDATE/DELETE of res changed. */
long long store_pg_changed(PGresult *res);

/* Monotonic clock, seconds (store_mono). */
double store_pg_mono(void);

/* The backend operations of store_pg_open.c (store_backend for their meaning). */
int store_pg_open(store *s, const store_settings *set, int *requeued, char *err,
                  size_t errlen);
void store_pg_close(store *s);
int store_pg_schema_version(store *s);
int store_pg_check_writable(store *s);
int store_pg_health(store *s);
int store_pg_prune(store *s, int by_age, double cutoff, long long max_bytes,
                   long long *removed);
int store_pg_size(store *s, long long *live_bytes, long long *file_bytes);

#endif /* SPINMODAL_STORE_PG_H */
