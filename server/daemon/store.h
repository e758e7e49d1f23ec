/*
 * store.h — the durable record of every analysis job: SQLite (WAL, one
 * process) or PostgreSQL (several replicas), chosen by the path given.
 *
 * One row per job, keyed by its content-addressed id (server/DAEMON.md).
 * The store is the queue's durable half: workers claim the oldest queued
 * job with store_claim_next, and at start store_open puts jobs left
 * `running` by a crash back to `queued`.  Results are stored as the exact
 * bytes served.
 *
 * Backends (DESIGN.md §6).  A path "postgresql://…" or "postgres://…" opens
 * the PostgreSQL backend (libpq): any number of stores, in any number of
 * processes ("replicas"), share one database; a claim is an UPDATE of the
 * row chosen by SELECT … FOR UPDATE SKIP LOCKED, and stamps the job with
 * the store's owner id and a lease (lease_until) its worker renews
 * (store_renew_lease); jobs whose lease ran out are put back by any replica
 * (store_requeue_expired).  Anything else is a SQLite file, owned by one
 * process at a time (a lock file, store_open_with); there owners and
 * leases are not stored and the multi-replica calls are cheap checks or
 * no-ops (each says which).
 *
 * Thread safety: every function may be called from any thread at once; the
 * store keeps a small pool of connections (SQLite in WAL: readers never
 * block the writer).  Return values are store_rc codes (0 = STORE_OK,
 * failures < 0); a failure of the database also leaves the backend's own
 * words (SQLite's message, libpq's text and SQLSTATE) in store_last_error
 * and the settings' on_error callback.
 *
 * Deadlines (DESIGN.md §F: every database round trip has one).  No call
 * waits longer than settings' timeout_ms for anything (probe_timeout_ms
 * for the probes: store_check_writable, store_health, store_count,
 * store_size), whatever the database does: a PostgreSQL server that is
 * stopped (SIGSTOP), or a network that swallows packets, still accepts
 * bytes into the kernel's buffers and never answers, and neither TCP nor
 * statement_timeout ends that.  The PostgreSQL backend therefore drives
 * libpq asynchronously (connect, send, read) with poll() on the session's
 * socket and closes a session whose deadline passed (its statement may
 * still run when the server wakes: the caller hears STORE_TIMEOUT, as for
 * a lost connection it cannot tell whether it committed).  A call that
 * timed out at its full deadline marks the server stalled: for the next
 * second every call fails at once with STORE_TIMEOUT, then one call tries
 * again (as for an unreachable server).  SQLite waits for its own writer
 * and for another process's lock (busy timeout) within the same deadline
 * and then fails with STORE_BUSY.
 */
#ifndef SPINMODAL_STORE_H
#define SPINMODAL_STORE_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Return codes of the store: one X-macro table generates the enum,
 * store_strerror and store_rc_name.  0 is success; every failure is
 * negative.  The database kinds (ERROR … GONE) keep apart problems an
 * operator solves differently: free disk space (FULL), find the other
 * writer (BUSY), restore a backup (CORRUPT), fix permissions or the mount
 * (READONLY), look at the disk (IOERR), stop the other daemon (IN_USE),
 * find who deleted the file (GONE), bring the database server or the
 * network back (UNAVAILABLE: PostgreSQL only, the store reconnects by
 * itself), find what stalls the server (TIMEOUT: a call's deadline,
 * store_settings.timeout_ms, passed without an answer).  STORE_NOMEM
 * stays apart from them.
 * X(name, value, token for logs and metric labels, sentence)
 */
#define STORE_RC_MAP(X)                                                                        \
    X(OK, 0, "ok", "success")                                                                  \
    X(NOT_FOUND, -1, "not_found", "no such job, or no queued job to claim")                    \
    X(CONFLICT, -2, "conflict", "the job is not in a state that allows the change")            \
    X(NOMEM, -3, "nomem", "out of memory")                                                     \
    X(ERROR, -4, "error", "database error")                                                    \
    X(FULL, -5, "full", "the database or its disk is full")                                    \
    X(BUSY, -6, "busy", "the database stayed locked by another connection past the timeout")   \
    X(CORRUPT, -7, "corrupt", "the database file is corrupt or not a database")                \
    X(READONLY, -8, "readonly",                                                                \
      "the database cannot be written (read-only file, directory, mount or permissions)")      \
    X(IOERR, -9, "ioerr", "input/output error on the database file")                           \
    X(IN_USE, -10, "in_use", "the database is in use by another process")                      \
    X(GONE, -11, "gone", "the database file was deleted or replaced while the store had it open") \
    X(INVALID, -12, "invalid", "invalid argument (a caller's mistake)")                      \
    X(UNAVAILABLE, -13, "unavailable",                                                         \
      "the database server cannot be reached (down, restarting, or the network); retried")    \
    X(TIMEOUT, -14, "db_timeout",                                                             \
      "the database did not answer within its deadline (stalled server or network); retried")

/** Return codes of the store (STORE_RC_MAP). */
typedef enum store_rc {
#define STORE_RC_ENUM(name, value, token, text) STORE_##name = value,
    STORE_RC_MAP(STORE_RC_ENUM)
#undef STORE_RC_ENUM
    STORE_RC_MIN = -14      /* the lowest code, for tables indexed by -rc */
} store_rc;

/** A sentence for rc ("the database or its disk is full"); never NULL. */
const char *store_strerror(int rc);

/**
 * A short token for rc, for log fields and metric labels: "ok",
 * "not_found", "conflict", "nomem", "error", "full", "busy", "corrupt",
 * "readonly", "ioerr", "in_use", "gone", "invalid", "unavailable",
 * "db_timeout"; "unknown" otherwise.
 */
const char *store_rc_name(int rc);

/**
 * 1 when rc is a database failure (STORE_ERROR, FULL, BUSY, CORRUPT,
 * READONLY, IOERR, IN_USE, GONE, UNAVAILABLE, TIMEOUT): the kinds a caller that only needs
 * "the database failed" (a 503, readiness) treats alike.  0 for
 * STORE_OK, NOT_FOUND, CONFLICT, NOMEM and INVALID.
 */
int store_is_db_error(int rc);

/**
 * One failure, as recorded by the store: the kind, the backend's own code
 * and text (for SQLite: the extended result code and sqlite3_errmsg; for
 * PostgreSQL: the SQLSTATE and libpq's message), the errno of the failing
 * system call when the backend knows it, and which store operation
 * failed.  Plain data, no pointers.
 */
typedef struct store_error {
    int rc;                    /* store_rc kind; STORE_OK when nothing failed yet */
    int backend_rc;            /* SQLite extended result code, 0 when not SQLite's */
    char sqlstate[6];          /* PostgreSQL SQLSTATE ("57P01"), "" when none (a lost
                                * connection, SQLite) */
    int sys_errno;             /* errno of the failing system call, 0 when unknown */
    unsigned long long seq;    /* failures recorded by this store so far, this one included */
    char op[24];               /* "submit", "claim", "finish", "health", "prune", … */
    char text[256];            /* the backend's message ("database or disk is full") */
} store_error;

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
    char *name;              /* the stored request's "name" (store_list only), or NULL */
    char owner[64];          /* PostgreSQL: the owner id of the store that claimed it
                              * last ("" before; kept after it ends); SQLite: "" */
    double lease_until;      /* PostgreSQL, while running: the claim holds until this
                              * unix time (store_renew_lease); 0 otherwise and on SQLite */
} store_job;

/** Free the strings of j and zero it; NULL is a no-op. */
void store_job_clear(store_job *j);

typedef struct store store;  /* opaque */

/**
 * Called by the store on every failure of a database operation after
 * store_open returned (not for STORE_NOT_FOUND, CONFLICT or INVALID: those
 * are answers, not failures).  Runs on the thread that saw the failure,
 * possibly while the store holds its write lock: it must be quick and
 * must not call the store.  e is valid only during the call.
 */
typedef void (*store_error_cb)(void *ctx, const store_error *e);

/**
 * Called by the store after it deleted n finished jobs on its own (the
 * byte budget on insert, store_settings.retain_bytes), on the thread that
 * inserted; quick, must not call the store.  Not called by store_prune
 * (its caller has the count).
 */
typedef void (*store_pruned_cb)(void *ctx, long long n);

/** How to open a store; fill with store_default_settings, then change fields. */
typedef struct store_settings {
    const char *path;          /* required: a SQLite database file (not ":memory:"), or a
                                * PostgreSQL URI "postgresql://…" / "postgres://…" (libpq
                                * syntax; its parameters, e.g. connect_timeout, apply) */
    int busy_timeout_ms;       /* SQLite: wait this long for another process's lock;
                                * PostgreSQL: lock_timeout of a row lock; 5000.  Never
                                * more than timeout_ms */
    int timeout_ms;            /* deadline of one call, everything it waits for included:
                                * a free connection, a lock (this process's or another's),
                                * each round trip to the server (PostgreSQL: plus 1 s per
                                * 4 MiB a statement sends; the sessions' statement_timeout
                                * unless the URI's options set one).  Past it the call
                                * fails with STORE_TIMEOUT (BUSY for a SQLite lock); 5000 */
    int probe_timeout_ms;      /* the same for store_check_writable, store_health,
                                * store_count and store_size (readiness, metrics); 500 */
    long long retain_bytes;    /* > 0: prune on insert.  After a submission or a finish
                                * stores its texts, while the live data (store_prune)
                                * exceeds this, the oldest finished jobs other than the
                                * one just written are deleted, so the store stays within
                                * it plus about one job.  0: only store_prune deletes */
    store_pruned_cb on_pruned; /* may be NULL */
    void *on_pruned_ctx;       /* passed to on_pruned */
    int quick_check;           /* SQLite: 1: PRAGMA quick_check at open, refuse a corrupt
                                * file (reads the whole file once: ~0.3 s per GB cached);
                                * 0: skip.  PostgreSQL: unused */
    store_error_cb on_error;   /* may be NULL */
    void *on_error_ctx;        /* passed to on_error */
    const char *owner;         /* the id claims are stamped with (PostgreSQL), copied, at
                                * most 63 bytes; NULL: "<hostname>:<pid>:<8 hex>", unique
                                * per open.  Must differ between live replicas */
    double lease_s;            /* PostgreSQL: a claim holds for this long unless renewed
                                * (store_renew_lease); 30.  SQLite: unused */
} store_settings;

/** Defaults: no path, busy_timeout_ms 5000, timeout_ms 5000, probe_timeout_ms 500,
 *  retain_bytes 0, quick_check 1, no callbacks, owner NULL (generated), lease_s 30. */
void store_default_settings(store_settings *set);

/**
 * Open the store named by set->path: PostgreSQL when it begins with
 * "postgresql://" or "postgres://" (see PostgreSQL below), else SQLite:
 *
 * SQLite.  Open (creating if needed) the database at set->path for this process
 * alone, check it, switch it to WAL, apply the migrations up to the
 * current schema version, and put every `running` job back to `queued` (a
 * crash or kill -9 left them so).  *requeued receives how many (may be
 * NULL).  On failure *out is NULL and err (errlen bytes, may be NULL)
 * holds a sentence naming the file and the cause.
 *
 * Exclusive: the store holds an exclusive lock on `<path>.lock` (created
 * next to the database, holding the owner's pid; never deleted) for its
 * whole life.  The kernel drops the lock when the process ends in any way
 * (kill -9 included), so a crashed daemon never blocks its restart.  A
 * second store on the same file, in this process or another, fails with
 * STORE_IN_USE and a sentence naming the file and the holder's pid.
 *
 * Returns STORE_OK; STORE_IN_USE (another store holds the file);
 * STORE_CORRUPT (not a SQLite database, or PRAGMA quick_check found
 * damage: err carries SQLite's first finding); STORE_READONLY (the file,
 * its directory or the lock file cannot be written); STORE_FULL,
 * STORE_IOERR, STORE_BUSY (another process kept a write lock past the
 * timeout); STORE_NOMEM; STORE_INVALID (set or its path NULL or empty);
 * STORE_ERROR (a newer schema, a database of another application, a
 * missing directory, ":memory:" or a file system without WAL, anything
 * else).
 *
 * PostgreSQL.  Connect (one connection now, up to 8 on demand later),
 * take pg_advisory_lock so that N replicas starting together migrate once,
 * refuse a database with a newer schema (STORE_ERROR) or with a `jobs`
 * table that is not spinmodal's (STORE_ERROR), apply the migrations, let
 * go of the lock, then put back to `queued` the `running` jobs whose lease
 * ended before this host's clock (their replica died; attempts and cancel
 * requests kept, as for SQLite; jobs of live replicas are left alone).
 * Not exclusive: any number of stores may share the database.  Returns
 * STORE_OK; STORE_INVALID (a DSN libpq cannot parse); STORE_UNAVAILABLE
 * (the server cannot be reached, or refuses the login: err has libpq's
 * text); STORE_READONLY (a read-only server or no privilege to create
 * the tables); STORE_ERROR; STORE_NOMEM.  Later, while the server cannot
 * be reached, every call fails with STORE_UNAVAILABLE at once (after at
 * most one connect_timeout, 2 s by default, per second) and the store
 * reconnects by itself when it can: the handle stays usable; while it
 * does not answer, likewise with STORE_TIMEOUT.  Session defaults, each
 * unless the URI sets it: connect_timeout 2, keepalives_idle 10,
 * keepalives_interval 5, keepalives_count 3, tcp_user_timeout 15000,
 * application_name spinmodald; statement_timeout = timeout_ms and
 * lock_timeout = busy_timeout_ms unless the URI's options (or PGOPTIONS)
 * name them.
 */
int store_open_with(store **out, const store_settings *set, int *requeued, char *err,
                    size_t errlen);

/**
 * store_open_with with the default settings and this path (no error
 * callback).  Same returns.
 */
int store_open(store **out, const char *path, int *requeued, char *err, size_t errlen);

/** Close every connection (checkpointing the WAL) and drop the lock; NULL is a no-op. */
void store_close(store *s);

/** The schema version of the open database (SQLite: PRAGMA user_version;
 *  PostgreSQL: the table spinmodal_schema), as seen at open. */
int store_schema_version(store *s);

/** "sqlite" or "postgresql": the backend store_open_with chose.  For the log
 *  only: ask what a backend can do with store_caps, never its name. */
const char *store_backend_name(store *s);

/* What a backend can do (store_caps: a capability of the store, not a name
 * to compare). */
enum {
    /* Several replicas share this store (PostgreSQL): a claim holds a lease
     * the claimer renews (store_renew_lease, store_requeue_expired), and
     * other replicas' submissions arrive without a signal to this process. */
    STORE_CAP_SHARED = 1u << 0,
    /* The path is a connection URI that may hold a password (PostgreSQL):
     * never log it. */
    STORE_CAP_SECRET_PATH = 1u << 1
};

/** The STORE_CAP_* bits of the backend store_open_with chose. */
unsigned store_caps(store *s);

/**
 * The owner id this store stamps on the jobs it claims (settings' owner,
 * or the generated one); valid until store_close, never NULL.  Pass it to
 * store_renew_lease.  On SQLite it is not stored in the jobs.
 */
const char *store_owner(store *s);

/**
 * The most recent failure recorded by s, from any thread, into *out (a
 * copy taken under a lock; out->seq tells a new failure from an old one).
 * For the text of one particular call, use the on_error callback, which
 * sees each failure on its own thread.  Returns out->rc: STORE_OK (and a
 * zeroed *out) when nothing failed since store_open.
 */
int store_last_error(store *s, store_error *out);

/**
 * Record a submission in one transaction, committed before it returns.
 * - no row with this id: insert it `queued` (created_at = now), *outcome = 1;
 * - a `failed` or `canceled` row: put it back to `queued` (attempts 0,
 *   speeds_done 0, error/result/csv/finished/started cleared, cancel flag
 *   cleared, created_at kept, seq renewed so it queues last), *outcome = 2;
 * - a `queued`, `running` or `done` row: nothing changes, *outcome = 0.
 * In every case *job (may be NULL) receives the row as it now is, without
 * the large texts.  Returns STORE_OK, STORE_INVALID (id not 64 characters,
 * request NULL), STORE_NOMEM or a database kind (store_is_db_error).
 */
int store_submit(store *s, const char *id, const char *request, size_t request_len,
                 int speeds_total, double now, int *outcome, store_job *job);

/**
 * Read one job; flags (STORE_WITH_*) choose the large texts to load.
 * Returns STORE_OK, STORE_NOT_FOUND, STORE_NOMEM or a database kind.
 */
int store_get(store *s, const char *id, unsigned flags, store_job *out);

/**
 * Claim the oldest `queued` job (lowest seq): in one transaction set it
 * `running`, started_at = now, attempts + 1.  *out receives it with its
 * request text.  PostgreSQL: the job is also stamped owner =
 * store_owner(s), lease_until = now + settings' lease_s, and concurrent
 * claims of any replicas skip each other's locked rows (FOR UPDATE SKIP
 * LOCKED): a job is handed to one claimer only.  Returns STORE_OK,
 * STORE_NOT_FOUND (queue empty), STORE_NOMEM or a database kind.
 */
int store_claim_next(store *s, double now, store_job *out);

/**
 * Record the end of a `running` job: state is STORE_DONE, STORE_FAILED or
 * STORE_CANCELED; error (JSON text), result (JSON text) and csv may be NULL.
 * speeds_done is stored too.  PostgreSQL: only the owner's (the store that
 * claimed it) end is recorded: a worker whose lease ran out and whose job
 * another replica took gets STORE_CONFLICT.  Returns STORE_OK,
 * STORE_CONFLICT (the job is not running, or not this store's, or state is
 * not an end state), STORE_NOT_FOUND, STORE_NOMEM or a database kind.
 */
int store_finish(store *s, const char *id, store_state state, double now, int speeds_done,
                 const char *error, const char *result, size_t result_len,
                 const char *csv, size_t csv_len);

/**
 * Put a `running` job back to `queued` (graceful shutdown while it ran):
 * started_at cleared, attempts - 1 (the interruption was not its fault),
 * seq kept so it runs first again.  PostgreSQL: only this store's own job
 * (owner), and owner/lease cleared.  Returns STORE_OK, STORE_CONFLICT,
 * STORE_NOT_FOUND, STORE_NOMEM or a database kind.
 */
int store_requeue(store *s, const char *id);

/**
 * Cancel: a `queued` job becomes `canceled` (finished_at = now); a `running`
 * job gets cancel_requested = 1 and stays running (its worker stops it);
 * *state (may be NULL) receives the state after the call.  Returns
 * STORE_OK, STORE_CONFLICT (done/failed/canceled: *state says which),
 * STORE_NOT_FOUND, STORE_NOMEM or a database kind.
 */
int store_cancel(store *s, const char *id, double now, store_state *state);

/**
 * Heartbeat of a running job: lease_until = now + lease_s when the job is
 * `running` and owned by owner (store_owner(s) of the store that claimed
 * it).  Call it every lease_s / 3 while the job runs.  PostgreSQL: one
 * UPDATE by primary key.  SQLite (one process, no leases): checks that the
 * job is running, writes nothing.  Returns STORE_OK; STORE_CONFLICT when
 * the job is no longer running or no longer owner's (its lease ran out and
 * another replica requeued or took it, or it was finished elsewhere): the
 * worker must stop it without recording a result; STORE_NOT_FOUND;
 * STORE_INVALID (owner NULL, lease_s <= 0); STORE_NOMEM or a database kind.
 */
int store_renew_lease(store *s, const char *id, const char *owner, double now, double lease_s);

/**
 * Jobs of dead replicas: every `running` job whose lease_until < now goes
 * back to `queued` (started_at, speeds_done, owner and lease cleared;
 * attempts and a cancel request kept, seq kept so it runs first), unless
 * its attempts already reached max_attempts: then it becomes `failed`
 * (finished_at = now) with the error object
 * {"type":"interrupted","title":"Job interrupted repeatedly","detail":"…"}.
 * Safe to call from every replica at any rate (each expired job is moved
 * by one of them).  *requeued and *failed (each may be NULL) receive the
 * counts.  SQLite: nothing to do (running jobs of a dead process are
 * requeued at open), both counts 0, STORE_OK.  Returns STORE_OK,
 * STORE_INVALID (max_attempts < 1), STORE_NOMEM or a database kind.
 */
int store_requeue_expired(store *s, double now, int max_attempts, int *requeued, int *failed);

/**
 * Has a cancel been asked for job id (store_cancel, from any replica)?
 * *flag (required) receives 1 or 0.  For a running job's worker between
 * heartbeats (its progress callback, rate-limited by the caller).  One
 * read by primary key on both backends.  Returns STORE_OK,
 * STORE_NOT_FOUND, STORE_NOMEM or a database kind (*flag 0).
 */
int store_cancel_requested(store *s, const char *id, int *flag);

/**
 * The state of job id into *state (required): the cheap read of a
 * `?wait=` poll across replicas (one column by primary key; the daemon
 * polls it with backoff: it cannot see another replica's condition
 * variable).  Returns STORE_OK, STORE_NOT_FOUND, STORE_NOMEM or a
 * database kind.
 */
int store_state_of(store *s, const char *id, store_state *state);

/**
 * Jobs newest first (descending seq), without the large texts:
 * seq < before (before <= 0: from the newest), only state `filter` when
 * filter >= 0, at most max of them into out[] (caller's array of max
 * zeroed store_job).  *n receives the count; *more is 1 when older
 * matching jobs exist.  Returns STORE_OK, STORE_INVALID (filter >=
 * STORE_N_STATES), STORE_NOMEM or a database kind.
 */
int store_list(store *s, long long before, int filter, int max, store_job *out, int *n,
               int *more);

/**
 * Number of jobs per state into counts[STORE_N_STATES] (all 0 on failure).
 * Within probe_timeout_ms.  Returns STORE_OK, STORE_NOMEM or a database kind.
 */
int store_count(store *s, long long counts[STORE_N_STATES]);

/**
 * Light readiness probe: STORE_OK when the database grants a write
 * transaction (SQLite: BEGIN IMMEDIATE; ROLLBACK; PostgreSQL: the session
 * is not read-only, e.g. not a standby), else the kind of the failure
 * (STORE_BUSY, STORE_READONLY, STORE_GONE, STORE_UNAVAILABLE, STORE_TIMEOUT,
 * … or STORE_NOMEM).  Writes nothing; store_health is the deeper check.
 * Within probe_timeout_ms; PostgreSQL probes have a session of their own,
 * so a pool busy with jobs does not delay them.
 */
int store_check_writable(store *s);

/**
 * Health of the open database, for /readyz and a periodic check:
 * 1. the path still names the file the store opened (same device and
 *    inode) and `<path>.lock` is still the file the store locked, else
 *    STORE_GONE (deleted, renamed or replaced: every later write would go
 *    to a file nobody will open again);
 * 2. a real write commits: the schema version is rewritten unchanged in
 *    a transaction committed without fsync (one 4 KiB WAL frame), so a
 *    read-only remount, revoked permissions or a full WAL device show.
 * Returns STORE_OK, STORE_GONE, STORE_READONLY, STORE_FULL, STORE_IOERR,
 * STORE_BUSY, STORE_CORRUPT, STORE_NOMEM or STORE_ERROR.
 * PostgreSQL: a real write commits (the schema version rewritten
 * unchanged); STORE_UNAVAILABLE while the server cannot be reached,
 * STORE_TIMEOUT while it does not answer within probe_timeout_ms, and
 * STORE_OK again by itself once it can (no reopen).
 */
int store_health(store *s);

/**
 * Retention.  Delete finished jobs (done, failed, canceled; never queued
 * or running ones), oldest end first (finished_at, then seq):
 * - every one that finished before now - max_age_s (max_age_s > 0;
 *   <= 0: no age limit);
 * - then, while the live data of the database exceeds max_bytes
 *   (max_bytes > 0; <= 0: no size limit), the oldest remaining ones.
 * Live data is (page_count - freelist_count) * page_size: the pages that
 * hold rows, not the file size and not the WAL.  Space: a database created
 * by this version uses auto_vacuum = INCREMENTAL, and store_prune ends
 * with PRAGMA incremental_vacuum, giving the freed pages back to the file
 * system (the file shrinks); a database created before keeps its size and
 * reuses the freed pages for new jobs (VACUUM it offline to shrink it).
 * Shrinking moves pages, so its cost is about the data moved (the first
 * prune of a large old database can take seconds; at most 4 MiB moved
 * per transaction, so other writers wait at most that long).
 * Works in transactions of at most 256 deletions, so submissions wait at
 * most one batch.  When only queued and running jobs are left above the
 * bound it stops there (STORE_OK).  *removed (may be NULL) receives how
 * many jobs were deleted, also on failure (the batches committed before).
 * Returns STORE_OK, STORE_NOMEM or a database kind.
 * PostgreSQL: the same rules; live data is the stored size of the jobs'
 * texts plus 120 bytes per row (the space a vacuum can give back), and
 * the server's autovacuum, not store_prune, reclaims the space.
 */
int store_prune(store *s, double now, double max_age_s, long long max_bytes,
                long long *removed);

/**
 * Live data and file size in bytes (see store_prune), for a gauge.
 * PostgreSQL: live as in store_prune, file = pg_total_relation_size of
 * the jobs table (with its TOAST and indexes).  Within probe_timeout_ms
 * (SQLite reads it on a reader connection: another process's write lock
 * does not delay it).
 * Returns STORE_OK, STORE_NOMEM or a database kind (*live, *file 0).
 */
int store_size(store *s, long long *live_bytes, long long *file_bytes);

#ifdef __cplusplus
}
#endif

#endif /* SPINMODAL_STORE_H */
