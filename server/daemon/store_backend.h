/*
 * store_backend.h — private to the store: the line where a backend plugs in.
 *
 * store.c owns what every backend shares: argument checks, the public
 * entry points, the error record and callback, state names, the owner id.
 * A backend (store_sqlite*.c; store_pg*.c, DESIGN.md §6) fills one
 * store_backend table; store.c calls it after checking arguments and
 * zeroing out-parameters, so a backend sees only valid ids, states and
 * filters.  A backend reports every failure through store_note_error.
 * Not installed, not included by the daemon: only store*.c and the store
 * test include it.
 */
#ifndef SPINMODAL_STORE_BACKEND_H
#define SPINMODAL_STORE_BACKEND_H

#include "store.h"

#include <pthread.h>
#include <time.h>

/* The operations of one backend; the meanings and return codes are those
 * of the public functions of the same name in store.h.  open sets s->impl
 * (NULL on failure, after freeing what it made); close frees it. */
typedef struct store_backend {
    const char *name; /* "sqlite", "postgresql": for the log only */
    unsigned caps;    /* STORE_CAP_* (store.h): what callers may ask instead of the name */
    int (*open)(store *s, const store_settings *set, int *requeued, char *err, size_t errlen);
    void (*close)(store *s);
    int (*schema_version)(store *s);
    int (*submit)(store *s, const char *id, const char *request, size_t request_len,
                  int speeds_total, double now, int *outcome, store_job *job);
    int (*get)(store *s, const char *id, unsigned flags, store_job *out);
    int (*claim_next)(store *s, double now, store_job *out);
    int (*finish)(store *s, const char *id, store_state state, double now, int speeds_done,
                  const char *error, const char *result, size_t result_len, const char *csv,
                  size_t csv_len);
    int (*requeue)(store *s, const char *id);
    int (*cancel)(store *s, const char *id, double now, store_state *state);
    int (*list)(store *s, long long before, int filter, int max, store_job *out, int *n,
                int *more);
    int (*count)(store *s, long long counts[STORE_N_STATES]);
    int (*check_writable)(store *s);
    int (*health)(store *s);
    /* store_prune with the age bound as a time: by_age = 1 deletes the
     * finished jobs that ended before cutoff; max_bytes <= 0: no size bound */
    int (*prune)(store *s, int by_age, double cutoff, long long max_bytes, long long *removed);
    int (*size)(store *s, long long *live_bytes, long long *file_bytes);
    /* the calls several replicas need (store.h); owner is never NULL */
    int (*renew_lease)(store *s, const char *id, const char *owner, double now,
                       double lease_s);
    int (*requeue_expired)(store *s, double now, int max_attempts, int *requeued, int *failed);
    int (*cancel_requested)(store *s, const char *id, int *flag);
    int (*state_of)(store *s, const char *id, store_state *state);
} store_backend;

/* The SQLite backend (store_sqlite.c, store_sqlite_conn.c, store_sqlite_open.c,
 * store_sqlite_file.c). */
extern const store_backend store_sqlite_backend;
/* The PostgreSQL backend (store_pg.c, store_pg_open.c). */
extern const store_backend store_pg_backend;

struct store {
    const store_backend *be;
    void *impl;                 /* the backend's state */
    store_error_cb on_error;    /* may be NULL */
    void *on_error_ctx;
    pthread_mutex_t err_lock;   /* guards last */
    store_error last;           /* the most recent failure */
    char owner[64];             /* store_owner: settings' owner or generated */
    double lease_s;             /* settings' lease_s (> 0) */
    int timeout_ms;             /* settings' timeout_ms (> 0): a call's deadline */
    int probe_ms;               /* settings' probe_timeout_ms (> 0): a probe's */
    long long retain_bytes;     /* settings' retain_bytes: prune on insert above it; 0 none */
    store_pruned_cb on_pruned;  /* may be NULL */
    void *on_pruned_ctx;
};

/* Monotonic clock, seconds: the deadlines' time base. */
double store_mono(void);

/* The wall-clock time ms milliseconds from now, for the backends' timed
 * waits (pthread_cond_timedwait, pthread_mutex_timedlock: CLOCK_REALTIME). */
struct timespec store_wall_in(int ms);

/* n > 0 finished jobs deleted by the budget on insert: tell on_pruned. */
void store_note_pruned(store *s, long long n);

/*
 * Record a failure of operation op (a static string) with the backend's
 * code, errno and message (text may be NULL), then call the on_error
 * callback outside err_lock.  Returns kind, so a backend can write
 * `return store_note_error(s, …)`.  Not for NOT_FOUND, CONFLICT, INVALID.
 */
int store_note_error(store *s, int kind, int backend_rc, int sys_errno, const char *op,
                     const char *text);

/* store_note_error with a PostgreSQL SQLSTATE (5 characters, or NULL/""). */
int store_note_error_state(store *s, int kind, const char *sqlstate, const char *op,
                           const char *text);

/* errno of a failed system call → store_rc kind (EACCES → STORE_READONLY,
 * ENOSPC → STORE_FULL, EIO → STORE_IOERR, …; STORE_ERROR otherwise). */
int store_errno_kind(int e);

/** printf into err[errlen] (an open's message for the caller); err NULL or errlen 0: nothing. */
void store_seterr(char *err, size_t errlen, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

#endif /* SPINMODAL_STORE_BACKEND_H */
