/*
 * store.h — the durable record of every analysis job (SQLite, WAL).
 *
 * One row per job, keyed by its content-addressed id (server/DAEMON.md).
 * The store is the queue's durable half: workers claim the oldest queued
 * job with store_claim_next, and at start store_open puts jobs left
 * `running` by a crash back to `queued`.  Results are stored as the exact
 * bytes served.  DESIGN.md §6: this small interface is what a PostgreSQL
 * backend will implement later (claim = SELECT … FOR UPDATE SKIP LOCKED).
 *
 * Thread safety: every function may be called from any thread at once; the
 * store keeps a small pool of connections (WAL: readers never block the
 * writer).  Return values are store_rc codes (0 = STORE_OK).
 */
#ifndef SPINMODAL_STORE_H
#define SPINMODAL_STORE_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Return codes of the store. */
typedef enum store_rc {
    STORE_OK = 0,
    STORE_NOT_FOUND = -1,   /* no such job, or no queued job to claim */
    STORE_CONFLICT = -2,    /* the job is not in a state that allows the change */
    STORE_NOMEM = -3,
    STORE_ERROR = -4        /* SQLite failed (disk full, locked past the timeout, corrupt …) */
} store_rc;

/** Job states, in this order (used as array indices). */
typedef enum store_state {
    STORE_QUEUED = 0,
    STORE_RUNNING,
    STORE_DONE,
    STORE_FAILED,
    STORE_CANCELED,
    STORE_N_STATES
} store_state;

/** "queued", "running", "done", "failed", "canceled"; "unknown" out of range. */
const char *store_state_name(store_state s);

/** Parse a state name; returns STORE_OK or STORE_NOT_FOUND. */
int store_state_parse(const char *name, store_state *out);

/** Flags for store_get / store_claim_next: which large texts to load. */
enum {
    STORE_WITH_REQUEST = 1,  /* canonical request text */
    STORE_WITH_RESULT = 2,   /* result JSON text */
    STORE_WITH_CSV = 4       /* result CSV text */
};

/**
 * One job as read from the store.  Strings are malloc'd and owned by the
 * struct (store_job_clear frees them); NULL when absent or not asked for.
 */
typedef struct store_job {
    char id[65];             /* 64 hex digits + NUL */
    long long seq;           /* submission order, > 0, unique; pagination cursor */
    store_state state;
    int speeds_total;        /* speeds in the request */
    int speeds_done;         /* speeds finished (== total when done) */
    int attempts;            /* times a worker claimed it since (re)submission */
    int cancel_requested;    /* 1 after a DELETE of a running job */
    double created_at;       /* unix time, s; 0 = never */
    double started_at;       /* 0 until claimed */
    double finished_at;      /* 0 until done/failed/canceled */
    char *request;           /* canonical request JSON (STORE_WITH_REQUEST) */
    size_t request_len;
    char *error;             /* error object JSON text, or NULL */
    char *result;            /* result JSON text (STORE_WITH_RESULT), or NULL */
    size_t result_len;
    char *result_csv;        /* result CSV text (STORE_WITH_CSV), or NULL */
    size_t csv_len;
    int has_result;          /* 1 when a result is stored, whatever the flags */
} store_job;

/** Free the strings of j and zero it; NULL is a no-op. */
void store_job_clear(store_job *j);

typedef struct store store;  /* opaque */

/**
 * Open (creating if needed) the database at path, switch it to WAL, apply
 * the migrations up to the current schema version, and put every `running`
 * job back to `queued` (a crash or kill -9 left them so).  *requeued
 * receives how many (may be NULL).  On failure *out is NULL and err
 * (errlen bytes, may be NULL) holds a sentence naming the cause.
 * Returns STORE_OK, STORE_NOMEM or STORE_ERROR.
 */
int store_open(store **out, const char *path, int *requeued, char *err, size_t errlen);

/** Close every connection (checkpointing the WAL); NULL is a no-op. */
void store_close(store *s);

/** The schema version of the open database (PRAGMA user_version). */
int store_schema_version(store *s);

/**
 * Record a submission in one transaction, committed before it returns.
 * - no row with this id: insert it `queued` (created_at = now), *outcome = 1;
 * - a `failed` or `canceled` row: put it back to `queued` (attempts 0,
 *   speeds_done 0, error/result/csv/finished/started cleared, cancel flag
 *   cleared, created_at kept, seq renewed so it queues last), *outcome = 2;
 * - a `queued`, `running` or `done` row: nothing changes, *outcome = 0.
 * In every case *job (may be NULL) receives the row as it now is, without
 * the large texts.  Returns STORE_OK, STORE_NOMEM or STORE_ERROR.
 */
int store_submit(store *s, const char *id, const char *request, size_t request_len,
                 int speeds_total, double now, int *outcome, store_job *job);

/**
 * Read one job; flags (STORE_WITH_*) choose the large texts to load.
 * Returns STORE_OK, STORE_NOT_FOUND, STORE_NOMEM or STORE_ERROR.
 */
int store_get(store *s, const char *id, unsigned flags, store_job *out);

/**
 * Claim the oldest `queued` job (lowest seq): in one transaction set it
 * `running`, started_at = now, attempts + 1.  *out receives it with its
 * request text.  Returns STORE_OK, STORE_NOT_FOUND (queue empty),
 * STORE_NOMEM or STORE_ERROR.
 */
int store_claim_next(store *s, double now, store_job *out);

/**
 * Record the end of a `running` job: state is STORE_DONE, STORE_FAILED or
 * STORE_CANCELED; error (JSON text), result (JSON text) and csv may be NULL.
 * speeds_done is stored too.  Returns STORE_OK, STORE_CONFLICT (the job is
 * not running), STORE_NOT_FOUND, STORE_NOMEM or STORE_ERROR.
 */
int store_finish(store *s, const char *id, store_state state, double now, int speeds_done,
                 const char *error, const char *result, size_t result_len,
                 const char *csv, size_t csv_len);

/**
 * Put a `running` job back to `queued` (graceful shutdown while it ran):
 * started_at cleared, attempts - 1 (the interruption was not its fault),
 * seq kept so it runs first again.  Returns STORE_OK, STORE_CONFLICT,
 * STORE_NOT_FOUND or STORE_ERROR.
 */
int store_requeue(store *s, const char *id);

/**
 * Cancel: a `queued` job becomes `canceled` (finished_at = now); a `running`
 * job gets cancel_requested = 1 and stays running (its worker stops it);
 * *state (may be NULL) receives the state after the call.  Returns
 * STORE_OK, STORE_CONFLICT (done/failed/canceled: *state says which),
 * STORE_NOT_FOUND or STORE_ERROR.
 */
int store_cancel(store *s, const char *id, double now, store_state *state);

/**
 * Jobs newest first (descending seq), without the large texts:
 * seq < before (before <= 0: from the newest), only state `filter` when
 * filter >= 0, at most max of them into out[] (caller's array of max
 * zeroed store_job).  *n receives the count; *more is 1 when older
 * matching jobs exist.  Returns STORE_OK, STORE_NOMEM or STORE_ERROR.
 */
int store_list(store *s, long long before, int filter, int max, store_job *out, int *n,
               int *more);

/** Number of jobs per state into counts[STORE_N_STATES].  STORE_OK or STORE_ERROR. */
int store_count(store *s, long long counts[STORE_N_STATES]);

/**
 * Readiness probe: 0 (STORE_OK) when the database accepts a write
 * transaction (BEGIN IMMEDIATE; ROLLBACK), STORE_ERROR otherwise.
 */
int store_check_writable(store *s);

#ifdef __cplusplus
}
#endif

#endif /* SPINMODAL_STORE_H */
