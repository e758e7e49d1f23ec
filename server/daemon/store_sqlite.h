/*
 * store_sqlite.h — private to the SQLite backend (store_sqlite.c,
 * store_sqlite_conn.c, store_sqlite_open.c, store_sqlite_file.c) and the
 * store test: the backend's state, its connections and the helpers its
 * files share.
 */
#ifndef SPINMODAL_STORE_SQLITE_H
#define SPINMODAL_STORE_SQLITE_H

#include "store_backend.h"

#include <pthread.h>
#include <sqlite3.h>
#include <sys/types.h>

enum {
    STORE_SQLITE_READERS = 7,         /* reader connections; + 1 writer = a pool of 8 */
    STORE_SQLITE_APP_ID = 0x534d4f44  /* PRAGMA application_id: "SMOD" */
};

/* Cached statements, one set per connection (store_sqlite_sql).  STMT_GET
 * + flags (0 … 7) selects the large texts asked for by STORE_WITH_*. */
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
    STMT_PAGES,          /* page_count, freelist_count, page_size */
    STMT_PRUNE_AGE,
    STMT_PRUNE_OLDEST,
    STMT_PRUNE_ONE,
    STMT_CANCEL_FLAG,
    STMT_N
};

/* One connection and its statement cache.  Used by one thread at a time
 * (the writer under write_lock, a reader taken from the pool), so op may
 * name the operation it serves for the error record. */
typedef struct store_conn {
    sqlite3 *db;
    sqlite3_stmt *stmt[STMT_N];   /* prepared on first use, NULL before */
    struct store_conn *next;      /* free list of readers */
    store *owner;                 /* for store_note_error */
    const char *op;               /* "submit", "get", …: the operation using it now */
} store_conn;

/* The exclusive lock on `<db>.lock` (store_sqlite_open.c). */
typedef struct store_file_lock {
    int fd;          /* -1 when not held */
    char *path;      /* "<db>.lock", malloc'd */
    dev_t dev;       /* the locked file, to notice it being deleted or replaced */
    ino_t ino;
    int dbfd;        /* the database file itself, OFD-locked at DB_LOCK_BYTE; -1 when not */
} store_file_lock;

/* The backend's state: s->impl of a SQLite store. */
typedef struct store_sqlite {
    store_conn writer;                   /* every write transaction, under write_lock */
    pthread_mutex_t write_lock;
    store_conn readers[STORE_SQLITE_READERS];
    store_conn *free_readers;            /* readers not in use, under pool_lock */
    pthread_mutex_t pool_lock;
    pthread_cond_t pool_cond;            /* signalled when a reader is returned */
    int locks_ready;                     /* 1 once the mutexes and condvar exist */
    int version;                         /* user_version after the migrations */
    int writer_relaxed;                  /* 1 while the writer runs synchronous=NORMAL */
    int busy_ms;                         /* busy timeout of every connection */
    char *path;                          /* the database file, malloc'd */
    dev_t db_dev;                        /* the file opened, to notice it being */
    ino_t db_ino;                        /* deleted or replaced (store_health) */
    double probe_at;                     /* monotonic s of store_health's last write that
                                            succeeded, 0 after a failure (pool_lock) */
    store_file_lock lock;
} store_sqlite;

/* The SQL text of each cached statement. */
extern const char *const store_sqlite_sql[STMT_N];

/* A SQLite result code (extended or primary) and the errno of the failing
 * system call (sqlite3_system_errno, 0 when unknown) → store_rc kind. */
int store_sqlite_kind(int rc, int sys_errno);

/* Record the failure rc of connection c (kind, code, errno, sqlite3_errmsg,
 * c->op) and return its kind.  Call before anything else runs on c (a
 * ROLLBACK replaces the message). */
int store_sqlite_fail(store_conn *c, int rc);

/* Does path still name the file (dev, ino) the store opened?  STORE_OK,
 * or the recorded failure of op: STORE_GONE when deleted or replaced, the
 * errno's kind when stat fails otherwise.  what: "database file", … */
int store_sqlite_same_file(store *s, const char *path, dev_t dev, ino_t ino, const char *what,
                           const char *op);

/* The cached statement k of c, prepared on first use; NULL on failure
 * (*rc receives the SQLite code). */
sqlite3_stmt *store_sqlite_stmt(store_conn *c, int k, int *rc);

/* Make a statement ready for its next use: end its read, drop bindings
 * (they may point into the caller's buffers).  The connection keeps the
 * error message of a failed step. */
void store_sqlite_stmt_done(sqlite3_stmt *st);

/* Run a cached statement that returns no rows; SQLITE_DONE → SQLITE_OK. */
int store_sqlite_exec(store_conn *c, int k);

/* Roll back the open transaction of c, if SQLite has not already done so. */
void store_sqlite_rollback(store_conn *c);

/* Finalize the statements of c and close it. */
void store_sqlite_conn_close(store_conn *c);

/* Take the writer for operation op and open a write transaction;
 * durable = 0 commits it with synchronous=NORMAL.  On STORE_OK the caller
 * must call store_sqlite_writer_end.  Returns a store_rc. */
int store_sqlite_writer_begin(store *s, store_conn **out, int durable, const char *op);

/* store_sqlite_writer_begin with a deadline of ms (the probes' budget)
 * instead of the store's timeout_ms: the writer's mutex and another
 * process's lock are both waited for within it (then STORE_BUSY). */
int store_sqlite_writer_begin_within(store *s, store_conn **out, int durable, const char *op,
                                     int ms);

/* Take a reader connection for op, waiting at most ms while all are in
 * use (then STORE_BUSY, recorded).  Give it back with
 * store_sqlite_reader_release. */
int store_sqlite_reader_acquire(store *s, const char *op, int ms, store_conn **out);
void store_sqlite_reader_release(store *s, store_conn *c);

/* The budget on insert (store_settings.retain_bytes), inside the writer's
 * open transaction c: while the live data exceeds it, delete the oldest
 * finished job other than keep_id (one batch at most); *removed counts the
 * deletions (they commit with the transaction).  Nothing without a
 * budget.  Returns a store_rc (recorded). */
int store_sqlite_trim(store *s, store_conn *c, const char *keep_id, long long *removed);

/* End the write transaction: commit when commit is 1, else roll back;
 * give the writer back.  Returns status, or the kind of a failed commit. */
int store_sqlite_writer_end(store *s, int status, int commit);

/* The backend operations outside store_sqlite.c (store_backend for
 * their meaning): store_sqlite_open.c … */
int store_sqlite_open(store *s, const store_settings *set, int *requeued, char *err,
                      size_t errlen);
void store_sqlite_close(store *s);
int store_sqlite_schema_version(store *s);
/* … and store_sqlite_file.c. */
int store_sqlite_check_writable(store *s);
int store_sqlite_health(store *s);
int store_sqlite_prune(store *s, int by_age, double cutoff, long long max_bytes,
                       long long *removed);
int store_sqlite_size(store *s, long long *live_bytes, long long *file_bytes);

#endif /* SPINMODAL_STORE_SQLITE_H */
