/*
 * metrics.c — counters and the solve-time histogram of spinmodald, rendered
 * as Prometheus text (exposition format 0.0.4).  See metrics.h.
 *
 * The HTTP counters are a small fixed table of (route, method, code) series
 * searched linearly: there are a dozen routes, a few methods and codes, so
 * the table stays tiny and a lookup costs less than the request itself.
 *
 * Store gauges.  The caller reads the job counts and sizes from the store
 * within the probes' budget (DESIGN.md §F: /metrics never waits on the
 * database); when that read fails (a stalled or locked database), the last
 * values read are served again and spinmodal_store_stats_stale says so,
 * with spinmodal_store_stats_age_seconds their age.
 */
#include "metrics.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define METRICS_MAX_SERIES 256
#define METRICS_LABEL 64

/* Upper bounds of the solve-time histogram, s (le="+Inf" is implicit). */
static const double metrics_buckets[] = {0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5,
                                         1.0,   2.5,  5.0,   10.0, 30.0, 60.0};
#define METRICS_N_BUCKETS (sizeof(metrics_buckets) / sizeof(metrics_buckets[0]))

typedef struct metrics_series {
    char route[METRICS_LABEL];   /* route template */
    char method[16];
    int code;
    unsigned long long count;
} metrics_series;

struct metrics {
    pthread_mutex_t lock;
    metrics_series http[METRICS_MAX_SERIES];  /* n_http used */
    int n_http;
    unsigned long long bucket[METRICS_N_BUCKETS + 1]; /* non-cumulative; last = +Inf */
    double solve_sum;                         /* s */
    unsigned long long solve_count;
    unsigned long long cache_hits, cache_misses;
    unsigned long long deadline_closed; /* connections closed by the request deadline */
    unsigned long long shed;            /* incomplete requests closed to free a slot */
    unsigned long long store_errors[-STORE_RC_MIN + 1]; /* failures by -store_rc */
    unsigned long long store_pruned;    /* finished jobs removed by retention */
    unsigned long long lease_requeued, lease_failed; /* jobs of dead replicas */
    unsigned long long finished[STORE_N_STATES];
    long long last_jobs[STORE_N_STATES]; /* the last job counts read; -1 before */
    long long last_live, last_file;     /* the last sizes read; -1 before */
    double jobs_at, size_at;            /* monotonic s of those reads, 0 = never */
};

metrics *metrics_new(void)
{
    metrics *m = calloc(1, sizeof(*m));

    if (!m)
        return NULL;
    if (pthread_mutex_init(&m->lock, NULL)) {
        free(m);
        return NULL;
    }
    for (int i = 0; i < STORE_N_STATES; i++)
        m->last_jobs[i] = -1;
    m->last_live = m->last_file = -1;
    return m;
}

void metrics_free(metrics *m)
{
    if (!m)
        return;
    pthread_mutex_destroy(&m->lock);
    free(m);
}

/* Copy s into dst (cap bytes) keeping only characters safe in a label value. */
static void metrics_label(char *dst, size_t cap, const char *s)
{
    size_t i = 0;

    for (; s && *s && i + 1 < cap; s++)
        if (*s != '"' && *s != '\\' && *s != '\n')
            dst[i++] = *s;
    dst[i] = '\0';
}

void metrics_http(metrics *m, const char *route, const char *method, int code)
{
    char r[METRICS_LABEL], me[16];
    int i;

    metrics_label(r, sizeof(r), route ? route : "other");
    metrics_label(me, sizeof(me), method ? method : "OTHER");
    pthread_mutex_lock(&m->lock);
    for (i = 0; i < m->n_http; i++) {
        metrics_series *s = &m->http[i];
        if (s->code == code && strcmp(s->route, r) == 0 && strcmp(s->method, me) == 0)
            break;
    }
    if (i == m->n_http) {
        if (m->n_http == METRICS_MAX_SERIES) {
            /* table full: count under route="other" if that series exists */
            for (i = 0; i < m->n_http; i++)
                if (strcmp(m->http[i].route, "other") == 0)
                    break;
            if (i == m->n_http)
                i = METRICS_MAX_SERIES - 1;
        } else {
            metrics_series *s = &m->http[m->n_http++];
            memcpy(s->route, r, sizeof(r));
            memcpy(s->method, me, sizeof(me));
            s->code = code;
        }
    }
    m->http[i].count++;
    pthread_mutex_unlock(&m->lock);
}

void metrics_solve_seconds(metrics *m, double seconds)
{
    size_t b = 0;

    while (b < METRICS_N_BUCKETS && seconds > metrics_buckets[b])
        b++;
    pthread_mutex_lock(&m->lock);
    m->bucket[b]++;
    m->solve_sum += seconds;
    m->solve_count++;
    pthread_mutex_unlock(&m->lock);
}

void metrics_cache(metrics *m, int hit)
{
    pthread_mutex_lock(&m->lock);
    if (hit)
        m->cache_hits++;
    else
        m->cache_misses++;
    pthread_mutex_unlock(&m->lock);
}

void metrics_deadline_closed(metrics *m, int n)
{
    pthread_mutex_lock(&m->lock);
    m->deadline_closed += (unsigned long long)(n > 0 ? n : 0);
    pthread_mutex_unlock(&m->lock);
}

void metrics_shed(metrics *m, int n)
{
    pthread_mutex_lock(&m->lock);
    m->shed += (unsigned long long)(n > 0 ? n : 0);
    pthread_mutex_unlock(&m->lock);
}

void metrics_store_error(metrics *m, int rc)
{
    if (rc > 0 || rc < STORE_RC_MIN)
        rc = STORE_ERROR;
    pthread_mutex_lock(&m->lock);
    m->store_errors[-rc]++;
    pthread_mutex_unlock(&m->lock);
}

void metrics_lease_expired(metrics *m, int requeued, int failed)
{
    pthread_mutex_lock(&m->lock);
    m->lease_requeued += (unsigned long long)(requeued > 0 ? requeued : 0);
    m->lease_failed += (unsigned long long)(failed > 0 ? failed : 0);
    pthread_mutex_unlock(&m->lock);
}

void metrics_store_pruned(metrics *m, long long n)
{
    pthread_mutex_lock(&m->lock);
    m->store_pruned += (unsigned long long)(n > 0 ? n : 0);
    pthread_mutex_unlock(&m->lock);
}

void metrics_job_finished(metrics *m, store_state s)
{
    if ((int)s < 0 || s >= STORE_N_STATES)
        return;
    pthread_mutex_lock(&m->lock);
    m->finished[s]++;
    pthread_mutex_unlock(&m->lock);
}

/* A growing text buffer; failed = 1 after an allocation failure. */
typedef struct metrics_buf {
    char *s;
    size_t len, cap;
    int failed;
} metrics_buf;

static void metrics_printf(metrics_buf *b, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static void metrics_printf(metrics_buf *b, const char *fmt, ...)
{
    va_list ap;
    int n;

    if (b->failed)
        return;
    for (;;) {
        va_start(ap, fmt);
        n = vsnprintf(b->s + b->len, b->cap - b->len, fmt, ap);
        va_end(ap);
        if (n < 0) {
            b->failed = 1;
            return;
        }
        if ((size_t)n < b->cap - b->len) {
            b->len += (size_t)n;
            return;
        }
        {
            size_t cap = 2 * b->cap + (size_t)n + 1;
            char *s = realloc(b->s, cap);
            if (!s) {
                b->failed = 1;
                return;
            }
            b->s = s;
            b->cap = cap;
        }
    }
}

/* The HTTP counters and the solve histogram (caller holds the lock). */
static void metrics_render_locked(const metrics *m, metrics_buf *b)
{
    unsigned long long cum = 0;
    size_t k;
    int i;

    metrics_printf(b, "# HELP spinmodal_http_requests_total HTTP requests answered, by route template, method and status code.\n"
                      "# TYPE spinmodal_http_requests_total counter\n");
    for (i = 0; i < m->n_http; i++)
        metrics_printf(b, "spinmodal_http_requests_total{route=\"%s\",method=\"%s\",code=\"%d\"} %llu\n",
                       m->http[i].route, m->http[i].method, m->http[i].code, m->http[i].count);
    metrics_printf(b, "# HELP spinmodal_solve_duration_seconds Wall time of one job's solve (all its speeds).\n"
                      "# TYPE spinmodal_solve_duration_seconds histogram\n");
    for (k = 0; k < METRICS_N_BUCKETS; k++) {
        cum += m->bucket[k];
        metrics_printf(b, "spinmodal_solve_duration_seconds_bucket{le=\"%g\"} %llu\n",
                       metrics_buckets[k], cum);
    }
    cum += m->bucket[METRICS_N_BUCKETS];
    metrics_printf(b, "spinmodal_solve_duration_seconds_bucket{le=\"+Inf\"} %llu\n", cum);
    metrics_printf(b, "spinmodal_solve_duration_seconds_sum %.9g\n", m->solve_sum);
    metrics_printf(b, "spinmodal_solve_duration_seconds_count %llu\n", m->solve_count);
    metrics_printf(b, "# HELP spinmodal_cache_hits_total Submissions answered by an existing job.\n"
                      "# TYPE spinmodal_cache_hits_total counter\n"
                      "spinmodal_cache_hits_total %llu\n"
                      "# HELP spinmodal_cache_misses_total Submissions that created or requeued a job.\n"
                      "# TYPE spinmodal_cache_misses_total counter\n"
                      "spinmodal_cache_misses_total %llu\n",
                   m->cache_hits, m->cache_misses);
    metrics_printf(b, "# HELP spinmodal_http_deadline_closed_total Connections closed because a "
                      "request's head and body did not arrive within --request-deadline.\n"
                      "# TYPE spinmodal_http_deadline_closed_total counter\n"
                      "spinmodal_http_deadline_closed_total %llu\n",
                   m->deadline_closed);
    metrics_printf(b, "# HELP spinmodal_http_shed_total Connections whose request had not "
                      "arrived in full, closed to keep slots free for complete requests.\n"
                      "# TYPE spinmodal_http_shed_total counter\n"
                      "spinmodal_http_shed_total %llu\n",
                   m->shed);
    metrics_printf(b, "# HELP spinmodal_store_errors_total Failures of the job store, by kind "
                      "(full, busy, corrupt, readonly, ioerr, gone, ...).\n"
                      "# TYPE spinmodal_store_errors_total counter\n");
    for (i = 1; i <= -STORE_RC_MIN; i++)
        if (store_is_db_error(-i) || -i == STORE_NOMEM)
            metrics_printf(b, "spinmodal_store_errors_total{kind=\"%s\"} %llu\n",
                           store_rc_name(-i), m->store_errors[i]);
    metrics_printf(b, "# HELP spinmodal_store_pruned_jobs_total Finished jobs removed by the "
                      "retention policy (--retain-age, --retain-bytes).\n"
                      "# TYPE spinmodal_store_pruned_jobs_total counter\n"
                      "spinmodal_store_pruned_jobs_total %llu\n",
                   m->store_pruned);
    metrics_printf(b, "# HELP spinmodal_lease_expiries_total Jobs of a replica that stopped "
                      "renewing its lease (PostgreSQL), by what became of them.\n"
                      "# TYPE spinmodal_lease_expiries_total counter\n"
                      "spinmodal_lease_expiries_total{outcome=\"requeued\"} %llu\n"
                      "spinmodal_lease_expiries_total{outcome=\"failed\"} %llu\n",
                   m->lease_requeued, m->lease_failed);
    metrics_printf(b, "# HELP spinmodal_jobs_finished_total Jobs that ended, by final state.\n"
                      "# TYPE spinmodal_jobs_finished_total counter\n");
    for (i = STORE_DONE; i < STORE_N_STATES; i++)
        metrics_printf(b, "spinmodal_jobs_finished_total{state=\"%s\"} %llu\n",
                       store_state_name((store_state)i), m->finished[i]);
}

/* Monotonic seconds, for the age of the store gauges. */
static double metrics_mono(void)
{
    struct timespec ts;

    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/*
 * The store gauges of in, into out: fresh ones are remembered; unknown ones
 * (-1: the store did not answer within the probes' budget) are replaced by
 * the last known.  *age: s since the oldest of the values served was read
 * (0 when all are fresh, -1 when none was ever read).  Returns 1 when a
 * value is not fresh.  Caller holds the lock.
 */
static int metrics_store_gauges(metrics *m, const metrics_gauges *in, metrics_gauges *out,
                                double *age)
{
    double now = metrics_mono(), oldest = now;
    int i, stale = 0;

    *out = *in;
    if (in->jobs[0] >= 0) {
        for (i = 0; i < STORE_N_STATES; i++)
            m->last_jobs[i] = in->jobs[i];
        m->jobs_at = now;
    } else {
        for (i = 0; i < STORE_N_STATES; i++)
            out->jobs[i] = m->last_jobs[i];
        stale = 1;
        oldest = m->jobs_at;
    }
    if (in->store_live_bytes >= 0) {
        m->last_live = in->store_live_bytes;
        m->last_file = in->store_file_bytes;
        m->size_at = now;
    } else {
        out->store_live_bytes = m->last_live;
        out->store_file_bytes = m->last_file;
        stale = 1;
        oldest = m->size_at < oldest ? m->size_at : oldest;
    }
    *age = oldest > 0.0 ? now - oldest : -1.0;
    return stale;
}

int metrics_render(metrics *m, const metrics_gauges *given, char **out, size_t *len)
{
    metrics_buf b = {NULL, 0, 0, 0};
    metrics_gauges gs, *g = &gs;
    double age = 0.0;
    int i, stale;

    *out = NULL;
    b.cap = 4096;
    b.s = malloc(b.cap);
    if (!b.s)
        return -1;
    b.s[0] = '\0';
    pthread_mutex_lock(&m->lock);
    metrics_render_locked(m, &b);
    stale = metrics_store_gauges(m, given, &gs, &age);
    pthread_mutex_unlock(&m->lock);
    metrics_printf(&b, "# HELP spinmodal_store_stats_stale 1 when the store did not answer "
                       "within the probes' budget and the store gauges below are the last "
                       "values read.\n"
                       "# TYPE spinmodal_store_stats_stale gauge\n"
                       "spinmodal_store_stats_stale %d\n"
                       "# HELP spinmodal_store_stats_age_seconds Age of the store gauges "
                       "(0 when read now; -1 when never read).\n"
                       "# TYPE spinmodal_store_stats_age_seconds gauge\n"
                       "spinmodal_store_stats_age_seconds %.3f\n",
                   stale, age);
    metrics_printf(&b, "# HELP spinmodal_jobs Jobs in the store, by state.\n"
                       "# TYPE spinmodal_jobs gauge\n");
    for (i = 0; i < STORE_N_STATES; i++)
        if (g->jobs[i] >= 0)
            metrics_printf(&b, "spinmodal_jobs{state=\"%s\"} %lld\n",
                           store_state_name((store_state)i), g->jobs[i]);
    metrics_printf(&b, "# HELP spinmodal_queue_depth Jobs waiting for a worker.\n"
                       "# TYPE spinmodal_queue_depth gauge\n"
                       "spinmodal_queue_depth %d\n"
                       "# HELP spinmodal_workers Worker threads configured.\n"
                       "# TYPE spinmodal_workers gauge\n"
                       "spinmodal_workers %d\n"
                       "# HELP spinmodal_workers_busy Worker threads running a job.\n"
                       "# TYPE spinmodal_workers_busy gauge\n"
                       "spinmodal_workers_busy %d\n",
                   g->queue_depth, g->workers, g->workers_busy);
    if (g->store_live_bytes >= 0)
        metrics_printf(&b, "# HELP spinmodal_store_live_bytes Bytes of live data in the database.\n"
                           "# TYPE spinmodal_store_live_bytes gauge\n"
                           "spinmodal_store_live_bytes %lld\n"
                           "# HELP spinmodal_store_file_bytes Bytes of the database files on disk.\n"
                           "# TYPE spinmodal_store_file_bytes gauge\n"
                           "spinmodal_store_file_bytes %lld\n",
                       g->store_live_bytes, g->store_file_bytes);
    if (b.failed) {
        free(b.s);
        return -1;
    }
    *out = b.s;
    *len = b.len;
    return 0;
}
