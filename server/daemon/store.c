/*
 * store.c — the durable record of every analysis job: the public face of
 * the store (store.h), whatever the backend.
 *
 * How it fits: jobs.c records submissions, claims queued jobs for its
 * workers and records their ends here; http.c reads jobs for GETs, lists,
 * /readyz and /metrics; main.c opens and closes the store and runs its
 * retention.  This file checks arguments, zeroes out-parameters, names
 * states and return codes, keeps the error record, and hands every call to
 * the backend table (store_backend.h).  The SQLite backend lives in
 * store_sqlite.c (the job operations), store_sqlite_conn.c (statements,
 * connections, the waits within a deadline), store_sqlite_file.c (health,
 * retention) and store_sqlite_open.c (the lock file, checks, schema and
 * migrations at open); the PostgreSQL backend (DESIGN.md §6) in
 * store_pg.c (pool, reconnection, job operations) and store_pg_open.c
 * (migrations under an advisory lock, probes, retention).
 * store_open_with chooses by the form of the path: a "postgresql://" or
 * "postgres://" URI is PostgreSQL, anything else a SQLite file.
 *
 * Errors.  A backend turns each failure into a store_rc kind and reports
 * it with store_note_error: the record (kind, backend code, errno, text,
 * operation) is kept under err_lock for store_last_error and passed to the
 * settings' on_error callback, so the daemon logs SQLite's own words
 * without the store depending on the daemon's log module.
 *
 * No process-global mutable state: everything lives in the store object.
 */
#include "store_backend.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* ---- return codes --------------------------------------------------------- */

/* Index of rc in the tables below: 0 … -STORE_RC_MIN, or -1. */
static int rc_index(int rc)
{
    return rc <= 0 && rc >= STORE_RC_MIN ? -rc : -1;
}

#define STORE_RC_TOKEN(name, value, token, text) [-(value)] = token,
#define STORE_RC_TEXT(name, value, token, text) [-(value)] = text,
static const char *const store_rc_tokens[1 - STORE_RC_MIN] = {STORE_RC_MAP(STORE_RC_TOKEN)};
static const char *const store_rc_texts[1 - STORE_RC_MIN] = {STORE_RC_MAP(STORE_RC_TEXT)};
#undef STORE_RC_TOKEN
#undef STORE_RC_TEXT

const char *store_strerror(int rc)
{
    int i = rc_index(rc);

    return i >= 0 && store_rc_texts[i] ? store_rc_texts[i] : "unknown store error";
}

const char *store_rc_name(int rc)
{
    int i = rc_index(rc);

    return i >= 0 && store_rc_tokens[i] ? store_rc_tokens[i] : "unknown";
}

int store_is_db_error(int rc)
{
    switch (rc) {
    case STORE_ERROR:
    case STORE_FULL:
    case STORE_BUSY:
    case STORE_CORRUPT:
    case STORE_READONLY:
    case STORE_IOERR:
    case STORE_IN_USE:
    case STORE_GONE:
    case STORE_UNAVAILABLE:
    case STORE_TIMEOUT:
        return 1;
    default:
        return 0;
    }
}

int store_errno_kind(int e)
{
    switch (e) {
    case 0:
        return STORE_OK;
    case EACCES:
    case EPERM:
    case EROFS:
        return STORE_READONLY;
    case ENOSPC:
#ifdef EDQUOT
    case EDQUOT:
#endif
    case EFBIG:   /* a file size limit (RLIMIT_FSIZE, file system maximum) */
        return STORE_FULL;
    case ENOMEM:
        return STORE_NOMEM;
    case EIO:
        return STORE_IOERR;
    default:
        return STORE_ERROR;
    }
}

/* Record e (kind, codes and texts filled) and call the callback. */
static int note(store *s, store_error *e, const char *op, const char *text)
{
    snprintf(e->op, sizeof e->op, "%s", op ? op : "");
    snprintf(e->text, sizeof e->text, "%s", text ? text : store_strerror(e->rc));
    if (pthread_mutex_lock(&s->err_lock) == 0) {
        e->seq = s->last.seq + 1;
        s->last = *e;
        (void)pthread_mutex_unlock(&s->err_lock);
    }
    if (s->on_error)
        s->on_error(s->on_error_ctx, e);
    return e->rc;
}

int store_note_error_state(store *s, int kind, const char *sqlstate, const char *op,
                           const char *text)
{
    store_error e;

    if (s == NULL)
        return kind;
    memset(&e, 0, sizeof e);
    e.rc = kind;
    if (sqlstate)
        snprintf(e.sqlstate, sizeof e.sqlstate, "%s", sqlstate);
    return note(s, &e, op, text);
}

int store_note_error(store *s, int kind, int backend_rc, int sys_errno, const char *op,
                     const char *text)
{
    store_error e;

    if (s == NULL)
        return kind;
    memset(&e, 0, sizeof e);
    e.rc = kind;
    e.backend_rc = backend_rc;
    e.sys_errno = sys_errno;
    return note(s, &e, op, text);
}

int store_last_error(store *s, store_error *out)
{
    memset(out, 0, sizeof *out);
    if (s == NULL || pthread_mutex_lock(&s->err_lock) != 0)
        return STORE_OK;
    *out = s->last;
    (void)pthread_mutex_unlock(&s->err_lock);
    return out->rc;
}

/* ---- states and jobs ------------------------------------------------------ */

static const char *const store_state_names[STORE_N_STATES] = {
    "queued", "running", "done", "failed", "canceled"};

const char *store_state_name(store_state s)
{
    if ((int)s < 0 || s >= STORE_N_STATES)
        return "unknown";
    return store_state_names[s];
}

int store_state_parse(const char *name, store_state *out)
{
    if (name == NULL)
        return STORE_NOT_FOUND;
    for (int i = 0; i < STORE_N_STATES; i++) {
        if (strcmp(name, store_state_names[i]) == 0) {
            if (out)
                *out = (store_state)i;
            return STORE_OK;
        }
    }
    return STORE_NOT_FOUND;
}

void store_job_clear(store_job *j)
{
    if (j == NULL)
        return;
    free(j->request);
    free(j->error);
    free(j->result);
    free(j->result_csv);
    free(j->name);
    memset(j, 0, sizeof *j);
}

/* ---- open and close ------------------------------------------------------- */

void store_default_settings(store_settings *set)
{
    memset(set, 0, sizeof *set);
    set->busy_timeout_ms = 5000;
    set->timeout_ms = 5000;
    set->probe_timeout_ms = 500;
    set->quick_check = 1;
    set->lease_s = 30;
}

/* Is path a PostgreSQL URI (libpq's two prefixes)? */
static int is_pg_uri(const char *path)
{
    return strncmp(path, "postgresql://", 13) == 0 || strncmp(path, "postgres://", 11) == 0;
}

/* The owner id: the settings' (at most 63 bytes), or "<host>:<pid>:<8 hex>"
 * with 32 random bits (or the clock's, without /dev/urandom) so two opens
 * in one process, or a restarted process with a reused pid, differ. */
static int make_owner(store *s, const char *given)
{
    char host[40] = "";
    unsigned r = 0;
    struct timespec ts;
    int fd;

    if (given != NULL) {
        if (given[0] == '\0' || strlen(given) >= sizeof s->owner)
            return -1;
        snprintf(s->owner, sizeof s->owner, "%s", given);
        return 0;
    }
    if (gethostname(host, sizeof host - 1) != 0 || host[0] == '\0')
        snprintf(host, sizeof host, "localhost");
    host[sizeof host - 1] = '\0';
    fd = open("/dev/urandom", O_RDONLY | O_CLOEXEC);
    if (fd < 0 || read(fd, &r, sizeof r) != (ssize_t)sizeof r) {
        (void)clock_gettime(CLOCK_REALTIME, &ts);
        r = (unsigned)ts.tv_nsec ^ (unsigned)ts.tv_sec ^ (unsigned)(size_t)s;
    }
    if (fd >= 0)
        (void)close(fd);
    snprintf(s->owner, sizeof s->owner, "%s:%ld:%08x", host, (long)getpid(), r);
    return 0;
}

int store_open_with(store **out, const store_settings *set, int *requeued, char *err,
                    size_t errlen)
{
    store *s;
    int rc;

    *out = NULL;
    if (requeued)
        *requeued = 0;
    if (err && errlen > 0)
        err[0] = '\0';
    if (set == NULL || set->path == NULL || set->path[0] == '\0') {
        if (err && errlen > 0)
            snprintf(err, errlen, "no database path given");
        return STORE_INVALID;
    }
    s = calloc(1, sizeof *s);
    if (s == NULL) {
        if (err && errlen > 0)
            snprintf(err, errlen, "out of memory opening the database");
        return STORE_NOMEM;
    }
    if (pthread_mutex_init(&s->err_lock, NULL) != 0) {
        free(s);
        if (err && errlen > 0)
            snprintf(err, errlen, "cannot create the store's error lock");
        return STORE_ERROR;
    }
    s->be = is_pg_uri(set->path) ? &store_pg_backend : &store_sqlite_backend;
    s->lease_s = set->lease_s > 0 ? set->lease_s : 30;
    s->timeout_ms = set->timeout_ms > 0 ? set->timeout_ms : 5000;
    s->probe_ms = set->probe_timeout_ms > 0 ? set->probe_timeout_ms : 500;
    s->retain_bytes = set->retain_bytes > 0 ? set->retain_bytes : 0;
    rc = make_owner(s, set->owner) == 0 ? STORE_OK : STORE_INVALID;
    if (rc != STORE_OK) {
        if (err && errlen > 0)
            snprintf(err, errlen, "the owner id must be 1 to %zu bytes", sizeof s->owner - 1);
    } else {
        rc = s->be->open(s, set, requeued, err, errlen);
    }
    if (rc != STORE_OK) {
        if (requeued)
            *requeued = 0;
        (void)pthread_mutex_destroy(&s->err_lock);
        free(s);
        return rc;
    }
    /* the callback sees failures from here on; open failures are in err */
    s->on_error = set->on_error;
    s->on_error_ctx = set->on_error_ctx;
    s->on_pruned = set->on_pruned;
    s->on_pruned_ctx = set->on_pruned_ctx;
    *out = s;
    return STORE_OK;
}

int store_open(store **out, const char *path, int *requeued, char *err, size_t errlen)
{
    store_settings set;

    store_default_settings(&set);
    set.path = path;
    return store_open_with(out, &set, requeued, err, errlen);
}

void store_close(store *s)
{
    if (s == NULL)
        return;
    s->be->close(s);
    (void)pthread_mutex_destroy(&s->err_lock);
    free(s);
}

int store_schema_version(store *s)
{
    return s->be->schema_version(s);
}

const char *store_backend_name(store *s)
{
    return s->be->name;
}

unsigned store_caps(store *s)
{
    return s->be->caps;
}

const char *store_owner(store *s)
{
    return s->owner;
}

/* ---- jobs ----------------------------------------------------------------- */

/* A job id as the store keeps it: 64 characters (jobs.c makes them hex). */
static int valid_id(const char *id)
{
    return id != NULL && strlen(id) == 64;
}

int store_submit(store *s, const char *id, const char *request, size_t request_len,
                 int speeds_total, double now, int *outcome, store_job *job)
{
    if (outcome)
        *outcome = 0;
    if (job)
        memset(job, 0, sizeof *job);
    if (!valid_id(id) || request == NULL)
        return STORE_INVALID;   /* a caller's mistake: ids are 64 hex digits */
    return s->be->submit(s, id, request, request_len, speeds_total, now, outcome, job);
}

int store_get(store *s, const char *id, unsigned flags, store_job *out)
{
    memset(out, 0, sizeof *out);
    if (id == NULL)
        return STORE_NOT_FOUND;
    return s->be->get(s, id, flags & 7u, out);
}

int store_claim_next(store *s, double now, store_job *out)
{
    memset(out, 0, sizeof *out);
    return s->be->claim_next(s, now, out);
}

int store_finish(store *s, const char *id, store_state state, double now, int speeds_done,
                 const char *error, const char *result, size_t result_len,
                 const char *csv, size_t csv_len)
{
    if (id == NULL)
        return STORE_NOT_FOUND;
    if (state != STORE_DONE && state != STORE_FAILED && state != STORE_CANCELED)
        return STORE_CONFLICT;   /* no job may finish as queued or running */
    return s->be->finish(s, id, state, now, speeds_done, error, result, result_len, csv, csv_len);
}

int store_requeue(store *s, const char *id)
{
    if (id == NULL)
        return STORE_NOT_FOUND;
    return s->be->requeue(s, id);
}

int store_cancel(store *s, const char *id, double now, store_state *state)
{
    if (id == NULL)
        return STORE_NOT_FOUND;
    return s->be->cancel(s, id, now, state);
}

int store_list(store *s, long long before, int filter, int max, store_job *out, int *n,
               int *more)
{
    *n = 0;
    *more = 0;
    if (filter >= STORE_N_STATES)
        return STORE_INVALID;   /* a caller's mistake: parse states with store_state_parse */
    return s->be->list(s, before, filter < 0 ? -1 : filter, max < 0 ? 0 : max, out, n, more);
}

int store_count(store *s, long long counts[STORE_N_STATES])
{
    for (int i = 0; i < STORE_N_STATES; i++)
        counts[i] = 0;
    return s->be->count(s, counts);
}

/* ---- several replicas ----------------------------------------------------- */

int store_renew_lease(store *s, const char *id, const char *owner, double now, double lease_s)
{
    if (id == NULL)
        return STORE_NOT_FOUND;
    if (owner == NULL || !(lease_s > 0))
        return STORE_INVALID;
    return s->be->renew_lease(s, id, owner, now, lease_s);
}

int store_requeue_expired(store *s, double now, int max_attempts, int *requeued, int *failed)
{
    int dummy_r = 0, dummy_f = 0;

    if (requeued == NULL)
        requeued = &dummy_r;
    if (failed == NULL)
        failed = &dummy_f;
    *requeued = 0;
    *failed = 0;
    if (max_attempts < 1)
        return STORE_INVALID;
    return s->be->requeue_expired(s, now, max_attempts, requeued, failed);
}

int store_cancel_requested(store *s, const char *id, int *flag)
{
    *flag = 0;
    if (id == NULL)
        return STORE_NOT_FOUND;
    return s->be->cancel_requested(s, id, flag);
}

int store_state_of(store *s, const char *id, store_state *state)
{
    *state = STORE_QUEUED;
    if (id == NULL)
        return STORE_NOT_FOUND;
    return s->be->state_of(s, id, state);
}

/* ---- the database itself -------------------------------------------------- */

int store_check_writable(store *s)
{
    return s->be->check_writable(s);
}

int store_health(store *s)
{
    return s->be->health(s);
}

int store_prune(store *s, double now, double max_age_s, long long max_bytes,
                long long *removed)
{
    long long dummy = 0;

    if (removed == NULL)
        removed = &dummy;
    *removed = 0;
    return s->be->prune(s, max_age_s > 0, now - max_age_s, max_bytes > 0 ? max_bytes : 0, removed);
}

int store_size(store *s, long long *live_bytes, long long *file_bytes)
{
    *live_bytes = 0;
    *file_bytes = 0;
    return s->be->size(s, live_bytes, file_bytes);
}

double store_mono(void)
{
    struct timespec ts;

    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

struct timespec store_wall_in(int ms)
{
    struct timespec t;

    (void)clock_gettime(CLOCK_REALTIME, &t);
    t.tv_sec += ms / 1000;
    t.tv_nsec += (long)(ms % 1000) * 1000000L;
    if (t.tv_nsec >= 1000000000L) {
        t.tv_sec++;
        t.tv_nsec -= 1000000000L;
    }
    return t;
}

void store_note_pruned(store *s, long long n)
{
    if (n > 0 && s->on_pruned)
        s->on_pruned(s->on_pruned_ctx, n);
}

void store_seterr(char *err, size_t errlen, const char *fmt, ...)
{
    va_list ap;

    if (err == NULL || errlen == 0)
        return;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}
