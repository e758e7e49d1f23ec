/*
 * metrics.h — the daemon's counters and histogram, rendered in the
 * Prometheus text format (version 0.0.4) for GET /metrics.
 *
 * Names are prefixed spinmodal_ and use base units (seconds).  Every
 * function is thread-safe (one mutex; the counters are few and cheap).
 */
#ifndef SPINMODAL_METRICS_H
#define SPINMODAL_METRICS_H

#include <stddef.h>

#include "store.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct metrics metrics;  /* opaque */

/** New metrics, or NULL when out of memory.  Free with metrics_free. */
metrics *metrics_new(void);

/** Free; NULL is a no-op. */
void metrics_free(metrics *m);

/**
 * Count one HTTP request: route is the route template ("/v1/analyses/{id}",
 * "other" for unknown paths), method the HTTP method, code the status.
 * Strings are copied on first use; at most 256 distinct series are kept
 * (later ones are counted under route="other").
 */
void metrics_http(metrics *m, const char *route, const char *method, int code);

/** Observe one job's solve time in seconds (the histogram). */
void metrics_solve_seconds(metrics *m, double seconds);

/** Count a submission: hit = 1 when the job already existed. */
void metrics_cache(metrics *m, int hit);

/** Count n connections closed because their request missed --request-deadline. */
void metrics_deadline_closed(metrics *m, int n);

/** Count n connections with an incomplete request closed to free slots (http_guard.c). */
void metrics_shed(metrics *m, int n);

/** Count one failure of the store, by kind (store_rc_name: "full", "busy", "corrupt" ...). */
void metrics_store_error(metrics *m, int rc);

/** Count jobs of dead replicas: re-queued after their lease expired, or failed (attempts). */
void metrics_lease_expired(metrics *m, int requeued, int failed);

/** Count n finished jobs removed by the retention policy. */
void metrics_store_pruned(metrics *m, long long n);

/** Count a job that ended in state s (done, failed or canceled). */
void metrics_job_finished(metrics *m, store_state s);

/** Gauges read at render time by the caller. */
typedef struct metrics_gauges {
    long long jobs[STORE_N_STATES]; /* jobs per state in the store, -1 when unknown */
    int queue_depth;
    int workers;
    int workers_busy;
    long long store_live_bytes;     /* bytes of live data in the database, -1 when unknown */
    long long store_file_bytes;     /* bytes of the database files, -1 when unknown */
} metrics_gauges;

/**
 * Render everything as Prometheus text.  *out receives a malloc'd
 * NUL-terminated string (free), *len its length.  Returns 0, or -1 when
 * out of memory.
 */
int metrics_render(metrics *m, const metrics_gauges *g, char **out, size_t *len);

#ifdef __cplusplus
}
#endif

#endif /* SPINMODAL_METRICS_H */
