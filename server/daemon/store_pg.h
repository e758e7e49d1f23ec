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
    STORE_PG_RETRY_MS = 1000,         /* after a failed connect, fail at once this long */
    STORE_PG_WAIT_MS = 10000,         /* longest wait for a free connection (then BUSY) */
    STORE_PG_STATEMENT_MS = 60000     /* statement_timeout of every session */
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
 * pool), so op may name the operation it serves for the error record. */
typedef struct pg_conn {
    PGconn *conn;                 /* NULL when not connected */
    unsigned long long prepared;  /* bit k: statement k prepared on conn */
    struct pg_conn *next;         /* free list */
    store *owner;                 /* for store_note_error_state */
    const char *op;               /* "submit", "get", …: the operation using it now */
} pg_conn;

/* The backend's state: s->impl of a PostgreSQL store. */
typedef struct store_pg {
    char *dsn;                        /* the URI given, malloc'd */
    pg_conn conns[STORE_PG_CONNS];
    pg_conn *free_conns;              /* not in use, under pool_lock */
    pthread_mutex_t pool_lock;
    pthread_cond_t pool_cond;         /* signalled when a connection is returned */
    int locks_ready;                  /* 1 once the mutex and condvar exist */
    int down;                         /* 1 after a failed connect, until one succeeds */
    int connecting;                   /* 1 while a thread connects with down set */
    double retry_at;                  /* monotonic s: no connect before (when down) */
    char down_text[256];              /* libpq's words of the failed connect */
    int lock_timeout_ms;              /* settings' busy_timeout_ms */
    int version;                      /* schema version after the migrations */
} store_pg;

/* The SQL text of each prepared statement. */
extern const char *const store_pg_sql[PG_N];

/* SQLSTATE (may be NULL) and the connection's status → store_rc kind. */
int store_pg_kind(const char *sqlstate, int connection_bad);

/* Open a new session on c (libpq connect with the store's DSN, a short
 * connect_timeout unless the DSN sets one, lock and statement timeouts).
 * Returns STORE_OK, or the kind with libpq's text in err (also when err
 * is NULL, the caller records it). */
int store_pg_connect(store *s, pg_conn *c, char *err, size_t errlen);

/* Close the session of c (statements forgotten). */
void store_pg_disconnect(pg_conn *c);

/* Take a connection for operation op: a live one from the pool, or a new
 * session.  *out NULL on failure.  Returns STORE_OK, STORE_UNAVAILABLE
 * (recorded; at once while the server was unreachable less than
 * STORE_PG_RETRY_MS ago), STORE_BUSY (no connection free in time). */
int store_pg_acquire(store *s, const char *op, pg_conn **out);

/* Give c back; a broken session, or one left inside a transaction, is
 * closed first (reconnected at its next use). */
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

/* Roll back the session's open transaction (after a failed statement); best effort. */
void store_pg_rollback(pg_conn *c);

/* Record a failure of c that libpq did not see (a malformed row, memory). */
int store_pg_fail_kind(pg_conn *c, int kind, const char *text);

/* The number of rows an UPDATE/DELETE of res changed. */
long long store_pg_changed(PGresult *res);

/* Monotonic clock, seconds. */
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
