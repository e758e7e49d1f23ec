/*
 * jobs_internal.h — what jobs.c (the pool), jobs_record.c (a job's end in
 * the store) and jobs_lease.c (replicas on a shared store) share; private to
 * server/daemon/jobs*.c.
 */
#ifndef SPINMODAL_JOBS_INTERNAL_H
#define SPINMODAL_JOBS_INTERNAL_H

#include <pthread.h>
#include <time.h>

#include "jobs.h"

#define JOBS_MAX_ATTEMPTS 3   /* claims before a job that keeps dying is failed */
#define JOBS_IDLE_POLL 5.0    /* s between store polls of an idle worker */
#define JOBS_SHARED_POLL 0.5  /* the same on a store shared by replicas (PostgreSQL) */
#define JOBS_SHARED_COUNT_AGE 1.0 /* s a shared queue count is reused for the 429 bound */
#define JOBS_FINISH_RETRY 60.0 /* s a result is offered again to an unreachable store */
#define JOBS_STORE_FAIL_MEMORY 30.0 /* s a failed write keeps /readyz false without a newer one */

typedef struct jobs_slot {
    char id[65];          /* running job, "" when idle */
    int done, total;      /* speeds finished / requested */
    int cancel;           /* 1: DELETE asked to stop */
    int timed_out;        /* 1: the callback stopped it for the time limit */
    int lost;             /* 1: another replica took the job (our lease expired): stop, record
                             nothing; cleared by the next claim (the loss is the job's) */
    double started;       /* log_now() at claim */
} jobs_slot;

typedef struct jobs_worker {
    jobs *pool;
    int index;
    pthread_t thread;
    int started;          /* 1 when pthread_create succeeded */
} jobs_worker;

struct jobs {
    store *st;                 /* borrowed */
    metrics *mx;               /* borrowed */
    jobs_config cfg;
    pthread_mutex_t lock;
    pthread_mutex_t claim_lock;
    pthread_cond_t work_cv;    /* workers: a job was queued, or stopping */
    pthread_cond_t done_cv;    /* waiters: a job finished (gen changed), or stopping */
    int queued;
    unsigned long long posted; /* bumped after each commit that makes a job queued */
    unsigned long long qver;   /* bumped on each change of `queued` (see jobs_resync) */
    int reserving;             /* submissions between their reservation and their commit */
    int stopping;              /* no new submissions, workers leave their loop */
    int stop_now;              /* running jobs stop and go back to the queue */
    int alive, busy;
    unsigned long long gen;
    jobs_slot *slots;          /* cfg.workers */
    jobs_worker *workers;      /* cfg.workers */
    /* jobs that ended while the store refused every write (full disk, read-only):
     * they are `running` in the store with no worker; retried until recorded */
    char (*unrecorded)[65];    /* ids, n_unrecorded of cap_unrecorded */
    int n_unrecorded, cap_unrecorded;
    double store_failed_at;    /* log_now() of the last failed write, 0 after a successful one */
    /* shared store (PostgreSQL, cfg.shared): the heartbeat thread renews the leases of the
     * running jobs, brings their cancels from other replicas, re-queues expired leases */
    pthread_t heart;
    int heart_started;
    int heart_stop;            /* 1: the heartbeat thread leaves */
    long long shared_queued;   /* queued jobs of all replicas at shared_at (store_count) */
    double shared_at;          /* log_now() of that count, 0 = never */
    long long shared_since;    /* submissions of this replica since that count */
    pthread_cond_t heart_cv;   /* wakes the heartbeat to stop */
};


/* What a worker produced for one job, handed to store_finish. */
typedef struct jobs_outcome_rec {
    store_state state;       /* DONE, FAILED, CANCELED; QUEUED = requeue */
    char *error;             /* JSON text or NULL */
    char *result;            /* JSON text or NULL */
    size_t result_len;       /* bytes of result */
    char *csv;               /* CSV text or NULL */
    size_t csv_len;
    int speeds_done;
    double solve_seconds;    /* < 0 when no solve ran */
} jobs_outcome_rec;

/** A job became queued in the store (committed): count it, wake an idle worker.  Lock held. */
void jobs_posted_locked(jobs *j);

/** A write to the store succeeded (rc == STORE_OK) or failed: /readyz follows it (jobs_record.c). */
void jobs_store_health(jobs *j, int rc);

/** Record the end of a claimed job, retrying a store that is briefly away; a job no write
 * could record is kept for jobs_retry_unrecorded (jobs_record.c). */
void jobs_record(jobs *j, const store_job *job, const jobs_outcome_rec *rec);

/** Retry the ends that could not be recorded (called before each claim; jobs_record.c). */
void jobs_retry_unrecorded(jobs *j);

/** Absolute CLOCK_REALTIME deadline seconds from now, for timed waits. */
struct timespec jobs_deadline(double seconds);

/** Signal waiters that some job left queued/running (gen++). */
void jobs_bump(jobs *j);

/**
 * The heartbeat thread of a replica on a shared store (jobs_lease.c): every
 * lease/3 it renews the leases of the running jobs, brings cancels asked
 * through other replicas, and re-queues the jobs of dead replicas, until
 * j->heart_stop.  arg is the pool.
 */
void *jobs_heart_main(void *arg);

#endif /* SPINMODAL_JOBS_INTERNAL_H */
