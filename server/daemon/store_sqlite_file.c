/*
 * store_sqlite_file.c — care of an open SQLite store: the readiness probe,
 * health (the file still there, still writable), size, and retention
 * (store.h: store_check_writable, store_health, store_size, store_prune).
 *
 * Health.  SQLite (in WAL mode) keeps writing to a database file that was
 * deleted or replaced under it, and every commit then goes to an inode
 * nobody will open again: jobs answered 202 vanish at the next start.
 * Every write transaction therefore refuses with STORE_GONE when the path
 * no longer names the file opened (store_sqlite_writer_begin), and
 * store_health compares the lock file likewise, then commits one real write —
 * user_version rewritten unchanged, one WAL frame, no fsync — so read-only
 * remounts, revoked permissions and a full device show as their kinds.  A
 * write that succeeded is not repeated for PROBE_EVERY seconds (callers in
 * between get STORE_OK; the two file checks run every time, and after a
 * failure every call probes again, so a recovery shows at once): /readyz is
 * open to anyone, and a client polling it 18 800 times a second made as many
 * write transactions, which grew the WAL to 4 MB and kept it there — on a
 * nearly full disk the probes ate the space a result needed.
 *
 * Retention.  Finished jobs are deleted oldest end first, in transactions
 * of at most PRUNE_BATCH rows so submissions wait at most one batch.  The
 * age bound is one statement per batch; the size bound deletes one row at
 * a time and re-reads the page counts after each (deleting a row moves its
 * overflow pages to the free list at once, inside the transaction), so it
 * stops at the first row that brings the live data under the bound.  A
 * database with auto_vacuum = INCREMENTAL then gets its free pages back to
 * the file system (PRAGMA incremental_vacuum, VACUUM_PAGES per
 * transaction) and a passive checkpoint lets the file itself shrink.
 * Shrinking moves the pages at the end of the file into the freed ones,
 * so it costs about the data moved: measured here (2 loaded cores), 10 000
 * of 20 000 jobs with 20 KB results deleted by age in 0.3 s without and
 * 6 s with the vacuum (200 MB freed at the start of a 412 MB file).  A
 * periodic prune that deletes a few jobs moves a few pages.
 * The budget on insert (store_settings.retain_bytes, store_sqlite_trim)
 * runs the same size bound inside the transaction of a submission or a
 * finish, before it commits, keeping the job just written: the live data
 * never exceeds the budget by more than that one job.  It leaves the freed
 * pages on the free list, where the next result reuses them (no vacuum on
 * that path: moving pages costs as much as the data moved).
 * Neither query has an index on finished_at: each batch scans the table's
 * small columns (the large texts are not read), which is fine at the
 * intended scale (a scan of 100 000 jobs is milliseconds).
 */
#include "store_sqlite.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

enum {
    PRUNE_BATCH = 256,     /* deletions per transaction */
    VACUUM_PAGES = 1024    /* pages given back per transaction (4 MiB at 4 KiB) */
};

#define PROBE_EVERY 1.0    /* s between two write probes of store_health */

/* ---- probes --------------------------------------------------------------- */

int store_sqlite_check_writable(store *s)
{
    store_conn *c = NULL;
    int status = store_sqlite_writer_begin_within(s, &c, 1, "check_writable", s->probe_ms);

    if (status != STORE_OK)
        return status;
    return store_sqlite_writer_end(s, STORE_OK, 0);
}

/* Monotonic seconds, for PROBE_EVERY. */
static double probe_clock(void)
{
    struct timespec ts;

    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int store_sqlite_health(store *s)
{
    store_sqlite *q = s->impl;
    store_conn *c = NULL;
    char sql[48];
    double now;
    int rc, status;

    status = store_sqlite_same_file(s, q->path, q->db_dev, q->db_ino, "database file", "health");
    if (status == STORE_OK)
        status = store_sqlite_same_file(s, q->lock.path, q->lock.dev, q->lock.ino, "lock file",
                                        "health");
    if (status != STORE_OK)
        return status;
    (void)pthread_mutex_lock(&q->pool_lock);
    now = probe_clock();
    if (q->probe_at > 0.0 && now - q->probe_at < PROBE_EVERY) {
        (void)pthread_mutex_unlock(&q->pool_lock);
        return STORE_OK;
    }
    (void)pthread_mutex_unlock(&q->pool_lock);
    /* a real write: the schema version, rewritten unchanged, is one page */
    status = store_sqlite_writer_begin_within(s, &c, 0, "health", s->probe_ms);
    if (status == STORE_OK) {
        snprintf(sql, sizeof sql, "PRAGMA user_version = %d", q->version);
        rc = sqlite3_exec(c->db, sql, NULL, NULL, NULL);
        status = store_sqlite_writer_end(s, rc == SQLITE_OK ? STORE_OK : store_sqlite_fail(c, rc),
                                         rc == SQLITE_OK);
    }
    (void)pthread_mutex_lock(&q->pool_lock);
    q->probe_at = status == STORE_OK ? probe_clock() : 0.0;
    (void)pthread_mutex_unlock(&q->pool_lock);
    return status;
}

/* ---- size ----------------------------------------------------------------- */

/* Live bytes ((page_count - freelist_count) * page_size) and the size the
 * file has once the WAL is checkpointed (page_count * page_size), read on
 * c (in its transaction, if any).  Returns a store_rc. */
static int conn_pages(store_conn *c, long long *live, long long *file)
{
    int rc, status = STORE_OK;
    sqlite3_stmt *st = store_sqlite_stmt(c, STMT_PAGES, &rc);

    if (st == NULL)
        return store_sqlite_fail(c, rc);
    rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        long long pages = sqlite3_column_int64(st, 0), free_pages = sqlite3_column_int64(st, 1);
        long long size = sqlite3_column_int64(st, 2);
        *live = (pages - free_pages) * size;
        if (file)
            *file = pages * size;
    } else {
        status = store_sqlite_fail(c, rc == SQLITE_DONE ? SQLITE_ERROR : rc);
    }
    store_sqlite_stmt_done(st);
    return status;
}

int store_sqlite_size(store *s, long long *live_bytes, long long *file_bytes)
{
    store_conn *c = NULL;
    int status = store_sqlite_reader_acquire(s, "size", s->probe_ms, &c);

    /* on a reader (one statement, its own read transaction): the writer may
     * wait for another process's lock, and /metrics must not */
    if (status != STORE_OK)
        return status;
    status = conn_pages(c, live_bytes, file_bytes);
    store_sqlite_reader_release(s, c);
    if (status != STORE_OK) {
        *live_bytes = 0;
        *file_bytes = 0;
    }
    return status;
}

/* ---- retention ------------------------------------------------------------ */

/* Delete the finished jobs that ended before cutoff, PRUNE_BATCH per
 * transaction; *removed grows by each committed batch. */
static int prune_age(store *s, double cutoff, long long *removed)
{
    for (;;) {
        store_conn *c = NULL;
        sqlite3_stmt *st;
        int rc, changes, status = store_sqlite_writer_begin(s, &c, 0, "prune");

        if (status != STORE_OK)
            return status;
        st = store_sqlite_stmt(c, STMT_PRUNE_AGE, &rc);
        if (st != NULL && (rc = sqlite3_bind_double(st, 1, cutoff)) == SQLITE_OK &&
            (rc = sqlite3_bind_int(st, 2, PRUNE_BATCH)) == SQLITE_OK)
            rc = sqlite3_step(st);
        if (rc != SQLITE_DONE) {
            status = store_sqlite_fail(c, rc);
            store_sqlite_stmt_done(st);
            return store_sqlite_writer_end(s, status, 0);
        }
        store_sqlite_stmt_done(st);
        changes = sqlite3_changes(c->db);
        status = store_sqlite_writer_end(s, STORE_OK, 1);
        if (status != STORE_OK)
            return status;
        *removed += changes;
        if (changes < PRUNE_BATCH)
            return STORE_OK;
    }
}

/* The seq of the next (at most PRUNE_BATCH) oldest finished jobs other than
 * keep_id (NULL: any) into seqs. */
static int prune_candidates(store_conn *c, const char *keep_id, long long seqs[PRUNE_BATCH],
                            int *n)
{
    int rc;
    sqlite3_stmt *st = store_sqlite_stmt(c, STMT_PRUNE_OLDEST, &rc);

    *n = 0;
    if (st != NULL && (rc = sqlite3_bind_int(st, 1, PRUNE_BATCH)) == SQLITE_OK && keep_id)
        rc = sqlite3_bind_text(st, 2, keep_id, -1, SQLITE_STATIC);
    if (st == NULL || rc != SQLITE_OK) {
        rc = store_sqlite_fail(c, rc);
        store_sqlite_stmt_done(st);
        return rc;
    }
    while (*n < PRUNE_BATCH && (rc = sqlite3_step(st)) == SQLITE_ROW)
        seqs[(*n)++] = sqlite3_column_int64(st, 0);
    if (rc != SQLITE_ROW && rc != SQLITE_DONE) {
        rc = store_sqlite_fail(c, rc);
        store_sqlite_stmt_done(st);
        return rc;
    }
    store_sqlite_stmt_done(st);
    return STORE_OK;
}

/* In the writer's open transaction c: delete the oldest finished jobs
 * other than keep_id (NULL: any) one at a time, at most one batch, until
 * the live data is at most max_bytes.  *deleted: rows deleted; *done: 1
 * when under the bound or nothing finished is left.  Returns a store_rc. */
static int delete_oldest(store_conn *c, long long max_bytes, const char *keep_id, int *deleted,
                         int *done)
{
    long long seqs[PRUNE_BATCH], live = 0;
    sqlite3_stmt *st;
    int rc, n = 0, status = conn_pages(c, &live, NULL);

    *deleted = 0;
    *done = 1;
    if (status == STORE_OK && live > max_bytes)
        status = prune_candidates(c, keep_id, seqs, &n);
    for (int i = 0; status == STORE_OK && live > max_bytes && i < n; i++) {
        st = store_sqlite_stmt(c, STMT_PRUNE_ONE, &rc);
        if (st != NULL && (rc = sqlite3_bind_int64(st, 1, seqs[i])) == SQLITE_OK)
            rc = sqlite3_step(st);
        if (rc != SQLITE_DONE)
            status = store_sqlite_fail(c, rc);
        store_sqlite_stmt_done(st);
        if (status == STORE_OK) {
            *deleted += sqlite3_changes(c->db);
            status = conn_pages(c, &live, NULL);
        }
    }
    *done = live <= max_bytes || n < PRUNE_BATCH;
    return status;
}

int store_sqlite_trim(store *s, store_conn *c, const char *keep_id, long long *removed)
{
    int deleted = 0, done = 0, status;

    *removed = 0;
    if (s->retain_bytes <= 0)
        return STORE_OK;
    status = delete_oldest(c, s->retain_bytes, keep_id, &deleted, &done);
    if (status == STORE_OK)
        *removed = deleted;
    return status;
}

/* One transaction of the size bound (delete_oldest, no job kept).
 * *deleted: rows deleted (committed when this returns STORE_OK); *done: 1
 * when under the bound or nothing finished is left. */
static int prune_size_batch(store *s, long long max_bytes, int *deleted, int *done)
{
    store_conn *c = NULL;
    int status = store_sqlite_writer_begin(s, &c, 0, "prune");

    *deleted = 0;
    *done = 1;
    if (status != STORE_OK)
        return status;
    status = delete_oldest(c, max_bytes, NULL, deleted, done);
    if (status != STORE_OK) {
        *deleted = 0;
        return store_sqlite_writer_end(s, status, 0);
    }
    status = store_sqlite_writer_end(s, STORE_OK, *deleted > 0);
    if (status != STORE_OK)
        *deleted = 0;
    return status;
}

/* Give the free pages back to the file system when the database has
 * auto_vacuum = INCREMENTAL, then let a passive checkpoint shrink the file. */
static int prune_vacuum(store *s)
{
    store_sqlite *q = s->impl;
    int mode = 0, free_pages = 1, rc, status;

    while (free_pages > 0) {
        store_conn *c = NULL;
        sqlite3_stmt *st = NULL;
        char sql[64];

        status = store_sqlite_writer_begin(s, &c, 0, "prune");
        if (status != STORE_OK)
            return status;
        rc = sqlite3_prepare_v2(c->db, "PRAGMA auto_vacuum", -1, &st, NULL);
        if (rc == SQLITE_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
            mode = sqlite3_column_int(st, 0);
            rc = SQLITE_OK;
        }
        if (rc != SQLITE_OK)
            status = store_sqlite_fail(c, rc);
        (void)sqlite3_finalize(st);
        if (status != STORE_OK || mode != 2)   /* 2: INCREMENTAL */
            return store_sqlite_writer_end(s, status, 0);
        snprintf(sql, sizeof sql, "PRAGMA incremental_vacuum(%d)", VACUUM_PAGES);
        rc = sqlite3_exec(c->db, sql, NULL, NULL, NULL);
        if (rc != SQLITE_OK)
            return store_sqlite_writer_end(s, store_sqlite_fail(c, rc), 0);
        {
            long long live = 0, file = 0;
            status = conn_pages(c, &live, &file);
            free_pages = status == STORE_OK && file > live;
        }
        status = store_sqlite_writer_end(s, status, status == STORE_OK);
        if (status != STORE_OK)
            return status;
    }
    if (pthread_mutex_lock(&q->write_lock) == 0) {
        (void)sqlite3_wal_checkpoint_v2(q->writer.db, NULL, SQLITE_CHECKPOINT_PASSIVE, NULL, NULL);
        (void)pthread_mutex_unlock(&q->write_lock);
    }
    return STORE_OK;
}

int store_sqlite_prune(store *s, int by_age, double cutoff, long long max_bytes,
                       long long *removed)
{
    int status = STORE_OK, deleted = 0, done = 0;

    if (by_age)
        status = prune_age(s, cutoff, removed);
    while (status == STORE_OK && max_bytes > 0 && !done) {
        status = prune_size_batch(s, max_bytes, &deleted, &done);
        *removed += deleted;
    }
    if (status == STORE_OK && *removed > 0)
        status = prune_vacuum(s);
    return status;
}
