/*
 * jobs.h — submission, bounded queue and worker pool of spinmodald.
 *
 * The store is the durable queue; this module adds the bounded in-memory
 * view of it (how many jobs are queued, for 429), a pool of pthread
 * workers that claim jobs from the store in submission order and run them
 * through the codec and the core (libuv's queue_work shape, but the pool is
 * an object, not process state), cancellation and the job time limit
 * through the core's progress callback, in-memory progress of running jobs,
 * and waiting for a job to finish (?wait=S).
 *
 * Every function is thread-safe.  Return values are jobs_rc codes.
 */
#ifndef SPINMODAL_JOBS_H
#define SPINMODAL_JOBS_H

#include "codec.h"
#include "metrics.h"
#include "store.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum jobs_rc {
    JOBS_OK = 0,
    JOBS_NOT_FOUND = -1,   /* unknown id */
    JOBS_CONFLICT = -2,    /* cancel of a finished job */
    JOBS_FULL = -3,        /* queue-max queued jobs already: 429 */
    JOBS_STOPPING = -4,    /* jobs_stop has begun: 503 */
    JOBS_STORE_ERROR = -5, /* the store failed: 503 */
    JOBS_NOMEM = -6        /* 503 */
} jobs_rc;

/** Outcome of a submission. */
typedef enum jobs_outcome {
    JOBS_EXISTING = 0,     /* identical job already queued, running or done: nothing new */
    JOBS_CREATED = 1,      /* new job queued */
    JOBS_RESUBMITTED = 2   /* failed/canceled job queued again */
} jobs_outcome;

typedef struct jobs_config {
    int workers;            /* worker threads, >= 1 */
    int solve_threads;      /* threads one sweep job may use (codec_request_set_threads), >= 1 */
    int queue_max;          /* most queued jobs before JOBS_FULL, >= 1 */
    double job_timeout;     /* s of solve time before a job fails with "timeout", > 0 */
    codec_limits limits;    /* limits applied when a worker re-reads a stored request */
    int shared;             /* 1: other replicas share the store (PostgreSQL): idle workers
                               poll every 0.5 s, a heartbeat thread renews leases every
                               lease/3, brings cancels from other replicas and re-queues
                               jobs whose lease expired */
    double lease;           /* s a claim holds without renewal (shared store), >= 3 */
} jobs_config;

typedef struct jobs jobs;   /* opaque */

/**
 * Start the pool: cfg->workers threads, each with BLAS pinned to one
 * thread, claiming queued jobs (those left by an earlier run first).
 * st and mx are borrowed and must outlive the pool.  Returns JOBS_OK,
 * JOBS_NOMEM or JOBS_STORE_ERROR (counting the queued jobs failed).
 */
int jobs_start(jobs **out, store *st, metrics *mx, const jobs_config *cfg);

/**
 * Stop: refuse new submissions (JOBS_STOPPING), let running jobs finish for
 * up to grace seconds, then cancel them and put them back to `queued` in
 * the store; join the workers and free the pool.  NULL is a no-op.
 */
void jobs_stop(jobs *j, double grace);

/** 1 once jobs_stop has begun. */
int jobs_stopping(jobs *j);

/**
 * Submit a validated request (borrowed).  The id is derived from the
 * request's SHA-256 and SM_VERSION (codec_job_id).  The job is committed to the
 * store before this returns.  *outcome says what happened; *job (may be
 * NULL) receives the job as stored, without large texts.  Cache hits and
 * misses are counted in the metrics.  Returns JOBS_OK, JOBS_FULL (nothing
 * stored), JOBS_STOPPING, JOBS_STORE_ERROR or JOBS_NOMEM.
 */
int jobs_submit(jobs *j, const codec_request *req, jobs_outcome *outcome, store_job *job);

/**
 * Cancel a queued job (it becomes canceled at once) or ask a running one to
 * stop (it becomes canceled at its next Newton iteration or speed).
 * *job (may be NULL) receives the job after the call, without large texts.
 * Returns JOBS_OK, JOBS_NOT_FOUND, JOBS_CONFLICT (already finished; *job
 * filled) or JOBS_STORE_ERROR.
 */
int jobs_cancel(jobs *j, const char *id, store_job *job);

/**
 * Read a job from the store (flags STORE_WITH_*), with the live progress of
 * a running job filled in (speeds_done).  Returns JOBS_OK, JOBS_NOT_FOUND,
 * JOBS_STORE_ERROR or JOBS_NOMEM.
 */
int jobs_get(jobs *j, const char *id, unsigned flags, store_job *out);

/**
 * Block until job id is no longer queued or running, timeout seconds pass,
 * or the pool stops.  Returns JOBS_OK (finished, or timed out: read the
 * job again to know), JOBS_STOPPING.
 */
int jobs_wait(jobs *j, const char *id, double timeout);

/** Snapshot for /metrics and /readyz. */
typedef struct jobs_stats {
    int queued;             /* jobs in the in-memory queue view */
    int workers;            /* configured */
    int workers_alive;      /* threads running their loop */
    int workers_busy;       /* threads running a job */
    int store_failing;      /* 1 when a write to the store failed (full disk, read-only) in the
                               last 30 s and none succeeded since */
    int unrecorded;         /* finished jobs whose end the store has not taken yet */
} jobs_stats;

/** Fill *s. */
void jobs_get_stats(jobs *j, jobs_stats *s);

#ifdef __cplusplus
}
#endif

#endif /* SPINMODAL_JOBS_H */
