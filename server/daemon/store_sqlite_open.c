/*
 * store_sqlite_open.c — opening and closing a SQLite store: the exclusive
 * lock file, the checks before anything is written, WAL, the schema and
 * its migrations, crash recovery (store.h: store_open_with).
 *
 * Order at open, each step refusing with a sentence in err:
 *   1. lock `<db>.lock` exclusively (one store per database file), and the
 *      database file itself (one store per inode, whatever its path);
 *   2. open the writer and look at the file: SQLite at all, ours, not newer;
 *   3. PRAGMA quick_check (optional, on by default): damaged pages refuse
 *      the open with SQLite's first findings instead of failing later, in
 *      the middle of some job;
 *   4. WAL; 5. migrations; 6. `running` → `queued`; 7. the readers.
 * Nothing is written before step 4, so a refused file is left as it was.
 *
 * The lock.  Two daemons on one file would each requeue the other's running
 * jobs at start and run them twice.  The lock is an open-file-description
 * lock (F_OFD_SETLK, Linux ≥ 3.15; POSIX F_SETLK elsewhere) on the whole of
 * a separate file `<db>.lock`, never on the database itself: SQLite's own
 * POSIX locks on the database would be dropped by any close(2) of another
 * descriptor of it in this process, and OFD locks conflict with them.  The
 * kernel releases the lock when the last descriptor of the description is
 * closed — at store_close, or when the process dies in any way (kill -9
 * included) — so a crash never blocks a restart and no stale-lock clean-up
 * exists.  Being an OFD lock, it also refuses a second store on the same
 * file within this process.  The file holds the owner's pid (text) for the
 * refusal message; it is never deleted (deleting it would let a newcomer
 * lock a new file while the old owner runs; store_health reports it gone).
 * The lock file is named after the path, so a second daemon given another
 * path to the same database — a symlink, a hard link — would lock another
 * file and run beside the first (a hard link even with its own WAL, which
 * corrupts the database).  So the database file itself is locked too: an
 * OFD write lock on one byte at DB_LOCK_BYTE (2^62), far from the bytes
 * SQLite's own POSIX locks use (2^30 … 2^30 + 511), so the two never meet;
 * being an OFD lock it stays held when SQLite closes a descriptor of the
 * file.  It follows the inode, whatever the path.  A file that cannot be
 * opened for writing is left to the checks of step 2 (they refuse it).
 *
 * Schema.  PRAGMA user_version is the schema version; store_migrations[k]
 * takes a database from version k to k + 1, each in its own transaction.
 * A newer database than this code knows, a file that is not SQLite, or a
 * SQLite file of another application is refused.  Large texts (request,
 * result, CSV) are the last columns of a row, so reading the small columns
 * of a job never walks their overflow pages.  A database created by this
 * code uses auto_vacuum = INCREMENTAL (set before the first table exists;
 * store_prune gives freed pages back to the file system); older files keep
 * auto_vacuum = NONE until an offline VACUUM.
 */
#define _GNU_SOURCE   /* F_OFD_SETLK; the rest of the file is POSIX */

#include "store_sqlite.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The migrations: store_migrations[k] brings user_version k to k + 1. */
static const char *const store_migrations[] = {
    /* 1: the jobs table.  state is the store_state_name text (readable
     * from the sqlite3 shell); times are unix seconds, NULL until they
     * happen; the large texts come last in the row. */
    "CREATE TABLE jobs ("
    " seq INTEGER PRIMARY KEY,"
    " id TEXT NOT NULL UNIQUE CHECK (length(id) = 64),"
    " state TEXT NOT NULL CHECK (state IN ('queued','running','done','failed','canceled')),"
    " speeds_total INTEGER NOT NULL,"
    " speeds_done INTEGER NOT NULL DEFAULT 0,"
    " attempts INTEGER NOT NULL DEFAULT 0,"
    " cancel_requested INTEGER NOT NULL DEFAULT 0,"
    " created_at REAL NOT NULL,"
    " started_at REAL,"
    " finished_at REAL,"
    " error TEXT,"
    " request TEXT NOT NULL,"
    " result TEXT,"
    " result_csv TEXT);"
    "CREATE INDEX jobs_state_seq ON jobs (state, seq);"
    "PRAGMA application_id = 1397575492;",   /* STORE_SQLITE_APP_ID */
};
#define STORE_SCHEMA_VERSION ((int)(sizeof store_migrations / sizeof store_migrations[0]))

/* The kind of SQLite failure rc on c (its errno included). */
static int conn_kind(store_conn *c, int rc)
{
    return store_sqlite_kind(rc, c->db ? sqlite3_system_errno(c->db) : 0);
}

/* ---- the lock file -------------------------------------------------------- */

/* Lock the whole file fd for writing without waiting: 0 or -1 (errno). */
static int lock_fd(int fd)
{
    struct flock fl;
    int r;

    memset(&fl, 0, sizeof fl);
    fl.l_type = F_WRLCK;
    fl.l_whence = SEEK_SET;   /* l_start = l_len = 0: the whole file; l_pid = 0 for OFD */
#ifdef F_OFD_SETLK
    r = fcntl(fd, F_OFD_SETLK, &fl);
    if (r == 0 || errno != EINVAL)
        return r;
    /* a kernel without OFD locks: the process-wide POSIX lock still keeps
     * other processes out (the only descriptor of this file is fd) */
#endif
    return fcntl(fd, F_SETLK, &fl);
}

/* The pid written in the lock file by its holder, 0 when unknown. */
static long lock_holder(int fd)
{
    char buf[32];
    ssize_t n = pread(fd, buf, sizeof buf - 1, 0);

    if (n <= 0)
        return 0;
    buf[n] = '\0';
    return strtol(buf, NULL, 10);
}

/* Take the exclusive lock on `<db>.lock` for this store.  Returns a
 * store_rc with err set on refusal (STORE_IN_USE when held elsewhere). */
static int lock_take(store_file_lock *l, const char *db, char *err, size_t errlen)
{
    size_t n = strlen(db) + sizeof ".lock";
    struct stat st;
    char pid[32];
    int e, len;

    l->fd = -1;
    l->path = malloc(n);
    if (l->path == NULL) {
        store_seterr(err, errlen, "out of memory opening the database");
        return STORE_NOMEM;
    }
    snprintf(l->path, n, "%s.lock", db);
    l->fd = open(l->path, O_RDWR | O_CREAT | O_CLOEXEC | O_NOCTTY, 0644);
    if (l->fd < 0) {
        e = errno;
        store_seterr(err, errlen, "cannot open database '%s': cannot create its lock file '%s': %s", db,
               l->path, strerror(e));
        return store_errno_kind(e);
    }
    if (lock_fd(l->fd) != 0) {
        e = errno;
        if (e == EAGAIN || e == EACCES) {
            long holder = lock_holder(l->fd);
            if (holder > 0)
                store_seterr(err, errlen, "database '%s' is in use by another process (pid %ld holds "
                       "'%s'); stop it, or give this daemon another database", db, holder,
                       l->path);
            else
                store_seterr(err, errlen, "database '%s' is in use by another process (it holds "
                       "'%s'); stop it, or give this daemon another database", db, l->path);
            return STORE_IN_USE;
        }
        store_seterr(err, errlen, "cannot lock '%s' for database '%s': %s", l->path, db, strerror(e));
        return store_errno_kind(e);
    }
    if (fstat(l->fd, &st) != 0) {
        e = errno;
        store_seterr(err, errlen, "cannot read lock file '%s': %s", l->path, strerror(e));
        return store_errno_kind(e);
    }
    l->dev = st.st_dev;
    l->ino = st.st_ino;
    /* the holder's pid, for the message of a refused newcomer; best effort */
    len = snprintf(pid, sizeof pid, "%ld\n", (long)getpid());
    if (ftruncate(l->fd, 0) != 0 || pwrite(l->fd, pid, (size_t)len, 0) != len) {
        /* a full disk shows at the first write to the database */
    }
    return STORE_OK;
}

#define DB_LOCK_BYTE ((off_t)1 << 62)

/* The OFD lock on the database file itself (the inode, whatever path names
 * it).  Returns a store_rc with err set on refusal; STORE_OK also when the
 * file cannot be opened for writing or the kernel has no OFD locks (the
 * checks of step 2, and the lock file, then stand alone). */
static int lock_inode(store_file_lock *l, const char *db, char *err, size_t errlen)
{
#ifdef F_OFD_SETLK
    struct flock fl;
    struct stat st;
    int fd = open(db, O_RDWR | O_CREAT | O_CLOEXEC | O_NOCTTY | O_NONBLOCK, 0644);

    if (fd < 0)
        return STORE_OK;
    memset(&fl, 0, sizeof fl);
    fl.l_type = F_WRLCK;
    fl.l_whence = SEEK_SET;
    fl.l_start = DB_LOCK_BYTE;
    fl.l_len = 1;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        (void)close(fd);
        return STORE_OK;
    }
    if (fcntl(fd, F_OFD_SETLK, &fl) != 0) {
        int e = errno;
        (void)close(fd);
        if (e == EAGAIN || e == EACCES) {
            store_seterr(err, errlen, "database '%s' is in use by another process (another "
                         "spinmodald has the same file open, through this path or another one: "
                         "a symlink or a hard link); stop it, or give this daemon another "
                         "database", db);
            return STORE_IN_USE;
        }
        return STORE_OK;   /* EINVAL: no OFD locks on this file system */
    }
    l->dbfd = fd;
#else
    (void)l;
    (void)db;
    (void)err;
    (void)errlen;
#endif
    return STORE_OK;
}

/* Drop the locks (closing their only descriptors) and free the path. */
static void lock_drop(store_file_lock *l)
{
    if (l->dbfd >= 0)
        (void)close(l->dbfd);
    l->dbfd = -1;
    if (l->fd >= 0)
        (void)close(l->fd);
    l->fd = -1;
    free(l->path);
    l->path = NULL;
}

/* ---- connections ---------------------------------------------------------- */

/* Run one pragma (or any SQL) and read the first column of its first row
 * as an integer (*val may be NULL) or as text into buf (may be NULL). */
static int conn_pragma(store_conn *c, const char *sql, int *val, char *buf, size_t buflen)
{
    sqlite3_stmt *st = NULL;
    int rc = sqlite3_prepare_v2(c->db, sql, -1, &st, NULL);

    if (rc != SQLITE_OK)
        goto done;
    rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        if (val)
            *val = sqlite3_column_int(st, 0);
        if (buf && buflen > 0) {
            const unsigned char *t = sqlite3_column_text(st, 0);
            snprintf(buf, buflen, "%s", t ? (const char *)t : "");
        }
        rc = SQLITE_OK;
    } else if (rc == SQLITE_DONE) {
        rc = SQLITE_OK;
    }
done:
    (void)sqlite3_finalize(st);
    return rc;
}

/* Open one connection of store s with its settings: extended result codes,
 * busy timeout, FULL sync (a commit is on disk before it returns), a
 * bounded WAL file.  A file this process may only read is refused. */
static int conn_open(store *s, store_conn *c, char *err, size_t errlen)
{
    store_sqlite *q = s->impl;
    int rc, kind;

    memset(c, 0, sizeof *c);
    c->owner = s;
    c->op = "open";
    rc = sqlite3_open_v2(q->path, &c->db,
                         SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, NULL);
    if (rc != SQLITE_OK) {
        kind = conn_kind(c, rc);
        store_seterr(err, errlen, "cannot open database '%s': %s", q->path,
               c->db ? sqlite3_errmsg(c->db) : sqlite3_errstr(rc));
        goto fail;
    }
    (void)sqlite3_extended_result_codes(c->db, 1);
    if (sqlite3_db_readonly(c->db, "main") == 1) {
        /* SQLite falls back to read-only when the file cannot be written */
        rc = SQLITE_READONLY;
        kind = STORE_READONLY;
        store_seterr(err, errlen, "cannot open database '%s' for writing (permissions or a read-only "
               "mount)", q->path);
        goto fail;
    }
    rc = sqlite3_busy_timeout(c->db, q->busy_ms);
    if (rc == SQLITE_OK)
        rc = sqlite3_exec(c->db, "PRAGMA synchronous = FULL; PRAGMA journal_size_limit = 67108864",
                          NULL, NULL, NULL);
    if (rc != SQLITE_OK) {
        kind = conn_kind(c, rc);
        if ((rc & 0xff) == SQLITE_NOTADB)
            store_seterr(err, errlen, "'%s' is not a SQLite database", q->path);
        else if (kind == STORE_CORRUPT)
            store_seterr(err, errlen, "database '%s' is corrupt: %s", q->path, sqlite3_errmsg(c->db));
        else
            store_seterr(err, errlen, "cannot configure database '%s': %s", q->path,
                   sqlite3_errmsg(c->db));
        goto fail;
    }
    return STORE_OK;
fail:
    store_sqlite_conn_close(c);
    return kind == STORE_OK ? STORE_ERROR : kind;
}

/* ---- checks before writing ------------------------------------------------ */

/* Remember which file the path names now (the writer just opened it), for
 * store_health.  Returns a store_rc with err set. */
static int sq_identify(store_sqlite *q, char *err, size_t errlen)
{
    struct stat st;

    if (stat(q->path, &st) != 0) {
        int e = errno;
        store_seterr(err, errlen, "cannot open database '%s': %s", q->path, strerror(e));
        return store_errno_kind(e) == STORE_OK ? STORE_ERROR : store_errno_kind(e);
    }
    q->db_dev = st.st_dev;
    q->db_ino = st.st_ino;
    return STORE_OK;
}

/* Is the file a SQLite database, ours, and not newer than this code?
 * *fresh = 1 for an empty database (no schema yet).  Returns a store_rc
 * with err set on refusal. */
static int sq_inspect(store_conn *c, const char *path, int *fresh, char *err, size_t errlen)
{
    int app = 0, version = 0, objects = 0;
    int rc = conn_pragma(c, "PRAGMA application_id", &app, NULL, 0);

    *fresh = 0;
    if (rc == SQLITE_OK)
        rc = conn_pragma(c, "PRAGMA user_version", &version, NULL, 0);
    if (rc == SQLITE_OK)
        rc = conn_pragma(c, "SELECT count(*) FROM sqlite_schema", &objects, NULL, 0);
    if ((rc & 0xff) == SQLITE_NOTADB) {
        store_seterr(err, errlen, "'%s' is not a SQLite database", path);
        return STORE_CORRUPT;
    }
    if (rc != SQLITE_OK) {
        store_seterr(err, errlen, "cannot read database '%s': %s", path, sqlite3_errmsg(c->db));
        return conn_kind(c, rc);
    }
    if (app != 0 && app != STORE_SQLITE_APP_ID) {
        store_seterr(err, errlen, "'%s' is a SQLite database of another application "
               "(application_id %d)", path, app);
        return STORE_ERROR;
    }
    if (version > STORE_SCHEMA_VERSION) {
        store_seterr(err, errlen, "database schema version %d is newer than this spinmodald (%d)",
               version, STORE_SCHEMA_VERSION);
        return STORE_ERROR;
    }
    if (app == 0 && version == 0 && objects > 0) {
        store_seterr(err, errlen, "'%s' is a SQLite database but not a spinmodal one", path);
        return STORE_ERROR;
    }
    *fresh = app == 0 && version == 0 && objects == 0;
    return STORE_OK;
}

/* PRAGMA quick_check: every page of the file is read once and the b-trees,
 * free list and page links are checked (not the indexes' agreement with
 * the table: that is integrity_check, O(N log N)).  The cost is one
 * sequential read of the file (~0.3 s per GB from the page cache here).
 * Returns STORE_OK, or STORE_CORRUPT with SQLite's first findings in err. */
static int sq_quick_check(store_conn *c, const char *path, char *err, size_t errlen)
{
    sqlite3_stmt *st = NULL;
    char found[384] = "";
    size_t used = 0;
    int rc = sqlite3_prepare_v2(c->db, "PRAGMA quick_check(4)", -1, &st, NULL), ok = 0, rows = 0;
    int kind = STORE_OK;

    while (rc == SQLITE_OK || rc == SQLITE_ROW) {
        if ((rc = sqlite3_step(st)) != SQLITE_ROW)
            break;
        const char *t = (const char *)sqlite3_column_text(st, 0);
        if (rows++ == 0 && t != NULL && strcmp(t, "ok") == 0) {
            ok = 1;
            continue;
        }
        if (used < sizeof found - 1) {
            int w = snprintf(found + used, sizeof found - used, "%s%s", used ? "; " : "",
                             t ? t : "?");
            used = w > 0 ? used + (size_t)w : used;
        }
    }
    for (char *p = found; *p; p++)   /* one line for the log */
        if (*p == '\n')
            *p = ' ';
    if (rc != SQLITE_DONE && rc != SQLITE_OK) {
        kind = conn_kind(c, rc);
        if (kind == STORE_CORRUPT)
            store_seterr(err, errlen, "database '%s' is corrupt: %s", path, sqlite3_errmsg(c->db));
        else
            store_seterr(err, errlen, "cannot check database '%s': %s", path, sqlite3_errmsg(c->db));
    } else if (!ok) {
        kind = STORE_CORRUPT;
        store_seterr(err, errlen, "database '%s' is corrupt (PRAGMA quick_check: %s); restore it from "
               "a backup or move it away", path, found[0] ? found : "no answer");
    }
    (void)sqlite3_finalize(st);
    return kind;
}

/* Switch to WAL (persistent in the file); a fresh file first gets
 * auto_vacuum = INCREMENTAL, which only an empty database accepts. */
static int sq_wal(store_conn *c, const char *path, int fresh, char *err, size_t errlen)
{
    char mode[16] = "";
    int rc = SQLITE_OK;

    if (fresh)
        rc = sqlite3_exec(c->db, "PRAGMA auto_vacuum = INCREMENTAL", NULL, NULL, NULL);
    if (rc == SQLITE_OK)
        rc = conn_pragma(c, "PRAGMA journal_mode = WAL", NULL, mode, sizeof mode);
    if (rc != SQLITE_OK) {
        store_seterr(err, errlen, "cannot switch database '%s' to WAL: %s", path,
               sqlite3_errmsg(c->db));
        return conn_kind(c, rc);
    }
    if (strcmp(mode, "wal") != 0) {
        store_seterr(err, errlen, "database '%s' cannot use WAL (journal mode is '%s'); "
               "it must be a file on a local file system", path, mode);
        return STORE_ERROR;
    }
    return STORE_OK;
}

/* ---- schema and recovery -------------------------------------------------- */

/* Apply the migrations one transaction each. */
static int sq_migrate(store_sqlite *q, char *err, size_t errlen)
{
    store_conn *c = &q->writer;
    char sql[64];
    int version = 0, rc = SQLITE_OK, kind;

    for (;;) {
        rc = store_sqlite_exec(c, STMT_BEGIN);
        if (rc == SQLITE_OK)
            rc = conn_pragma(c, "PRAGMA user_version", &version, NULL, 0);
        if (rc != SQLITE_OK)
            goto fail;
        if (version > STORE_SCHEMA_VERSION) {
            store_sqlite_rollback(c);
            store_seterr(err, errlen, "database schema version %d is newer than this spinmodald (%d)",
                   version, STORE_SCHEMA_VERSION);
            return STORE_ERROR;
        }
        if (version == STORE_SCHEMA_VERSION)
            break;
        snprintf(sql, sizeof sql, "PRAGMA user_version = %d", version + 1);
        rc = sqlite3_exec(c->db, store_migrations[version], NULL, NULL, NULL);
        if (rc == SQLITE_OK)
            rc = sqlite3_exec(c->db, sql, NULL, NULL, NULL);
        if (rc == SQLITE_OK)
            rc = store_sqlite_exec(c, STMT_COMMIT);
        if (rc != SQLITE_OK)
            goto fail;
    }
    rc = store_sqlite_exec(c, STMT_COMMIT);
    if (rc != SQLITE_OK)
        goto fail;
    q->version = version;
    return STORE_OK;
fail:
    kind = conn_kind(c, rc);
    store_seterr(err, errlen, "cannot migrate database '%s' to schema version %d: %s", q->path,
           version + 1, sqlite3_errmsg(c->db));
    store_sqlite_rollback(c);
    return kind;
}

/* Crash recovery, one transaction: every `running` job goes back to
 * `queued`.  attempts is kept (jobs.c fails a job interrupted too often);
 * cancel_requested is kept too, so the worker that claims the job again
 * stops it at once and the user's DELETE is not lost.  The lock file makes
 * sure no other live process is running them. */
static int sq_recover(store_sqlite *q, int *requeued, char *err, size_t errlen)
{
    store_conn *c = &q->writer;
    int rc = store_sqlite_exec(c, STMT_BEGIN), kind;

    if (rc == SQLITE_OK)
        rc = sqlite3_exec(c->db, "UPDATE jobs SET state = 'queued', started_at = NULL,"
                          " speeds_done = 0 WHERE state = 'running'", NULL, NULL, NULL);
    if (rc == SQLITE_OK && requeued)
        *requeued = sqlite3_changes(c->db);
    if (rc == SQLITE_OK)
        rc = store_sqlite_exec(c, STMT_COMMIT);
    if (rc != SQLITE_OK) {
        kind = conn_kind(c, rc);
        store_seterr(err, errlen, "cannot requeue the running jobs of '%s': %s", q->path,
               sqlite3_errmsg(c->db));
        store_sqlite_rollback(c);
        return kind;
    }
    return STORE_OK;
}

/* ---- open and close ------------------------------------------------------- */

/* The mutexes and condition variable of q; 0 or -1 (none left made). */
static int locks_init(store_sqlite *q)
{
    if (pthread_mutex_init(&q->write_lock, NULL) != 0)
        return -1;
    if (pthread_mutex_init(&q->pool_lock, NULL) != 0)
        goto fail_pool;
    if (pthread_cond_init(&q->pool_cond, NULL) != 0)
        goto fail_cond;
    q->locks_ready = 1;
    return 0;
fail_cond:
    (void)pthread_mutex_destroy(&q->pool_lock);
fail_pool:
    (void)pthread_mutex_destroy(&q->write_lock);
    return -1;
}

/* Steps 2 … 7 of the open, on a store whose lock is held. */
static int sq_open_db(store *s, const store_settings *set, int *requeued, char *err,
                      size_t errlen)
{
    store_sqlite *q = s->impl;
    int rc, fresh = 0;

    rc = conn_open(s, &q->writer, err, errlen);
    if (rc == STORE_OK)
        rc = sq_identify(q, err, errlen);
    if (rc == STORE_OK)
        rc = sq_inspect(&q->writer, q->path, &fresh, err, errlen);
    if (rc == STORE_OK && set->quick_check && !fresh)
        rc = sq_quick_check(&q->writer, q->path, err, errlen);
    if (rc == STORE_OK)
        rc = sq_wal(&q->writer, q->path, fresh, err, errlen);
    if (rc == STORE_OK)
        rc = sq_migrate(q, err, errlen);
    if (rc == STORE_OK)
        rc = sq_recover(q, requeued, err, errlen);
    for (int i = 0; rc == STORE_OK && i < STORE_SQLITE_READERS; i++) {
        rc = conn_open(s, &q->readers[i], err, errlen);
        if (rc == STORE_OK) {
            q->readers[i].next = q->free_readers;
            q->free_readers = &q->readers[i];
        }
    }
    return rc;
}

int store_sqlite_open(store *s, const store_settings *set, int *requeued, char *err,
                      size_t errlen)
{
    store_sqlite *q;
    int rc;

    s->impl = NULL;
    if (strcmp(set->path, ":memory:") == 0) {
        store_seterr(err, errlen, "database ':memory:' cannot use WAL (it lives in memory); it must be "
               "a file on a local file system");
        return STORE_ERROR;
    }
    if (sqlite3_threadsafe() == 0) {
        store_seterr(err, errlen, "this SQLite library was built without thread support");
        return STORE_ERROR;
    }
    q = calloc(1, sizeof *q);
    if (q == NULL || (q->path = strdup(set->path)) == NULL) {
        free(q);
        store_seterr(err, errlen, "out of memory opening the database");
        return STORE_NOMEM;
    }
    q->lock.fd = -1;
    q->lock.dbfd = -1;
    q->busy_ms = set->busy_timeout_ms > 0 ? set->busy_timeout_ms : 0;
    if (q->busy_ms > s->timeout_ms)   /* no wait outlasts a call's deadline */
        q->busy_ms = s->timeout_ms;
    s->impl = q;
    if (locks_init(q) != 0) {
        store_seterr(err, errlen, "cannot create the database locks");
        rc = STORE_ERROR;
        goto fail;
    }
    rc = lock_take(&q->lock, q->path, err, errlen);
    if (rc == STORE_OK)
        rc = lock_inode(&q->lock, q->path, err, errlen);
    if (rc == STORE_OK)
        rc = sq_open_db(s, set, requeued, err, errlen);
    if (rc == STORE_OK)
        return STORE_OK;
fail:
    if (requeued)
        *requeued = 0;
    store_sqlite_close(s);
    return rc;
}

void store_sqlite_close(store *s)
{
    store_sqlite *q = s->impl;

    if (q == NULL)
        return;
    for (int i = 0; i < STORE_SQLITE_READERS; i++)
        store_sqlite_conn_close(&q->readers[i]);
    if (q->writer.db != NULL) {
        /* the last connection would checkpoint anyway; do it explicitly and
         * truncate the WAL so the database is one file at rest */
        (void)sqlite3_wal_checkpoint_v2(q->writer.db, NULL, SQLITE_CHECKPOINT_TRUNCATE, NULL,
                                        NULL);
    }
    store_sqlite_conn_close(&q->writer);
    lock_drop(&q->lock);   /* after the last connection: no one else writes before */
    if (q->locks_ready) {
        (void)pthread_cond_destroy(&q->pool_cond);
        (void)pthread_mutex_destroy(&q->pool_lock);
        (void)pthread_mutex_destroy(&q->write_lock);
    }
    free(q->path);
    free(q);
    s->impl = NULL;
}

int store_sqlite_schema_version(store *s)
{
    store_sqlite *q = s->impl;

    return q->version;
}
