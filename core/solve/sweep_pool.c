/*
 * sweep_pool.c — worker threads that finish a sweep's cases at their equilibria (sweep_pool.h).
 *
 * sweep_run (sweep.c) queues each speed's case once its equilibrium is found; threads - 1
 * workers, each with its own smi_lin, take the chunks of sweep_chunk cases in queue order
 * and finish a chunk's cases one after the other as they are queued (warm starts), and the
 * calling thread takes its share once the continuation is done.  A case is written by one
 * thread only after it is queued, under the pool's lock, so the hand-over orders the calling
 * thread's writes (speed, equilibrium status) before the worker's.  The model is read only.  Stopping: an atomic flag
 * the workers' progress callback returns (the tree path's Krylov iteration asks it), checked
 * again before each case.
 */
#include "sweep_pool.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct pool_job {
    sm_case *c;
    double *q; /* the equilibrium (n), owned */
} pool_job;

struct sweep_pool {
    const sm_model *m;
    sweep_case_fn after;
    int n_workers, started;
    pthread_t *th;
    pthread_mutex_t mu;
    pthread_cond_t more;  /* a case was queued, or the pool closes */
    pthread_cond_t ended; /* a case was finished */
    pool_job *jobs;       /* queue: jobs[0 .. tail) queued; chunks from head on not taken */
    int head, tail, n_cases;
    int chunk; /* sweep_chunk */
    int running, finished, closing;
    int rc; /* first SM_NOMEM / SM_CANCELED of a thread */
    atomic_int stop;
};

/* The workers' progress callback: only the stop flag. */
static int pool_stop_cb(void *user, int done, int total)
{
    (void)done;
    (void)total;
    return atomic_load(&((sweep_pool *)user)->stop);
}

/* Take the next chunk whose first case is queued (lock held): *start its first case; 0 when
 * none. */
static int pool_take(sweep_pool *p, int *start)
{
    if (p->head >= p->tail)
        return 0;
    *start = p->head;
    p->head += p->chunk;
    p->running++;
    return 1;
}

/* The calling thread's progress callback with the cases finished (lock held; released while
 * the callback runs: it may take its time); a stop asked before the last case stops the pool. */
static void pool_ask(sweep_pool *p, sm_progress *pr)
{
    int done = p->finished, total = pr->total;
    if (!pr->cb || atomic_load(&p->stop))
        return;
    pthread_mutex_unlock(&p->mu);
    pr->done = done;
    int stop = pr->cb(pr->user, done, total) && done < total;
    pthread_mutex_lock(&p->mu);
    if (stop && p->rc == SM_OK) {
        p->rc = SM_CANCELED;
        atomic_store(&p->stop, 1);
    }
}

/* Finish the chunk from case start on L, each case once it is queued (takes the lock to wait
 * and to record each end; not held on entry).  caller: the calling thread, whose callback
 * (pool_ask) is asked after each case; a worker's pr is the stop flag's. */
static void pool_run(sweep_pool *p, int start, smi_lin *L, sm_progress *pr, int caller)
{
    int end = start + p->chunk < p->n_cases ? start + p->chunk : p->n_cases;
    pthread_mutex_lock(&p->mu);
    for (int j = start; j < end; j++) {
        while (j >= p->tail && !p->closing)
            pthread_cond_wait(&p->more, &p->mu);
        if (j >= p->tail)
            break; /* closing: the sweep stopped before queueing it */
        pool_job job = p->jobs[j];
        p->jobs[j].q = NULL;
        pthread_mutex_unlock(&p->mu);
        smi_lin_warm(L, j > start);
        int rc = atomic_load(&p->stop) ? SM_CANCELED
                                       : sweep_case_finish(p->m, job.q, L, pr, p->after, job.c);
        free(job.q);
        pthread_mutex_lock(&p->mu);
        p->finished++;
        if (rc < 0 && p->rc == SM_OK) {
            p->rc = rc;
            atomic_store(&p->stop, 1);
        }
        pthread_cond_broadcast(&p->ended);
        if (caller && j + 1 < end)
            pool_ask(p, pr);
    }
    p->running--;
    pthread_cond_broadcast(&p->ended);
    pthread_mutex_unlock(&p->mu);
}

static void *pool_worker(void *arg)
{
    sweep_pool *p = arg;
    smi_lin *L = NULL;
    sm_progress pr = {pool_stop_cb, p, 0, 0};
    int rc = smi_lin_new(p->m, SMI_USE_MODES, tree_use(p->m), &L), start;
    pthread_mutex_lock(&p->mu);
    if (rc < 0) { /* the other threads finish the cases */
        pthread_mutex_unlock(&p->mu);
        return NULL;
    }
    for (;;) {
        while (p->head >= p->tail && !p->closing)
            pthread_cond_wait(&p->more, &p->mu);
        if (!pool_take(p, &start))
            break; /* closing, nothing left */
        pthread_mutex_unlock(&p->mu);
        pool_run(p, start, L, &pr, 0);
        pthread_mutex_lock(&p->mu);
    }
    pthread_mutex_unlock(&p->mu);
    smi_lin_free(L);
    return NULL;
}

int sweep_chunk(const sm_model *m)
{
    return tree_use(m) && !m->kind->fixed_bits ? SWEEP_WARM_CHUNK : 1;
}

int sweep_pool_new(const sm_model *m, int threads, int n_cases, sweep_case_fn after,
                   sweep_pool **out)
{
    sweep_pool *p = calloc(1, sizeof *p);
    *out = NULL;
    if (!p)
        return SM_NOMEM;
    p->m = m;
    p->after = after;
    p->n_cases = n_cases;
    p->chunk = sweep_chunk(m);
    p->n_workers = threads - 1 < n_cases ? threads - 1 : n_cases;
    p->jobs = calloc((size_t)(n_cases > 0 ? n_cases : 1), sizeof *p->jobs);
    p->th = calloc((size_t)(p->n_workers > 0 ? p->n_workers : 1), sizeof *p->th);
    atomic_init(&p->stop, 0);
    if (!p->jobs || !p->th || pthread_mutex_init(&p->mu, NULL)) {
        free(p->jobs);
        free(p->th);
        free(p);
        return SM_NOMEM;
    }
    pthread_cond_init(&p->more, NULL);
    pthread_cond_init(&p->ended, NULL);
    while (p->started < p->n_workers &&
           pthread_create(&p->th[p->started], NULL, pool_worker, p) == 0)
        p->started++; /* fewer threads than asked still work: the calling thread finishes the rest */
    *out = p;
    return SM_OK;
}

int sweep_pool_add(sweep_pool *p, sm_case *c, const double *q)
{
    size_t n = (size_t)p->m->n;
    double *copy = malloc((n ? n : 1) * sizeof(double));
    if (!copy)
        return SM_NOMEM;
    memcpy(copy, q, n * sizeof(double));
    pthread_mutex_lock(&p->mu);
    p->jobs[p->tail].c = c;
    p->jobs[p->tail].q = copy;
    p->tail++;
    pthread_cond_broadcast(&p->more); /* a chunk's owner may wait for this very case */
    pthread_mutex_unlock(&p->mu);
    return SM_OK;
}

int sweep_pool_finished(sweep_pool *p)
{
    pthread_mutex_lock(&p->mu);
    int f = p->finished;
    pthread_mutex_unlock(&p->mu);
    return f;
}

void sweep_pool_stop(sweep_pool *p)
{
    atomic_store(&p->stop, 1);
}

/* Wait up to 50 ms for a case to end (lock held). */
static void pool_wait(sweep_pool *p)
{
    struct timespec t;
    clock_gettime(CLOCK_REALTIME, &t);
    t.tv_nsec += 50000000L;
    if (t.tv_nsec >= 1000000000L) {
        t.tv_sec++;
        t.tv_nsec -= 1000000000L;
    }
    int e = pthread_cond_timedwait(&p->ended, &p->mu, &t);
    (void)e; /* ETIMEDOUT: ask the callback again */
}

int sweep_pool_finish(sweep_pool *p, smi_lin *L, sm_progress *pr)
{
    int start;
    pthread_mutex_lock(&p->mu);
    for (;;) {
        if (pool_take(p, &start)) {
            pthread_mutex_unlock(&p->mu);
            pool_run(p, start, L, pr, 1);
            pthread_mutex_lock(&p->mu);
        } else if (p->running > 0) {
            pool_wait(p);
        } else {
            break;
        }
        pool_ask(p, pr);
    }
    /* the last case may have ended while the callback above ran (the lock is released for it):
     * the callback's last call must still say every case is done */
    if (pr->done != p->finished)
        pool_ask(p, pr);
    int rc = p->rc;
    pthread_mutex_unlock(&p->mu);
    return rc;
}

void sweep_pool_free(sweep_pool *p)
{
    if (!p)
        return;
    pthread_mutex_lock(&p->mu);
    p->closing = 1;
    pthread_cond_broadcast(&p->more);
    pthread_mutex_unlock(&p->mu);
    for (int i = 0; i < p->started; i++)
        pthread_join(p->th[i], NULL);
    for (int i = 0; i < p->tail; i++) /* left by a stop (a taken case's is NULL) */
        free(p->jobs[i].q);
    pthread_cond_destroy(&p->more);
    pthread_cond_destroy(&p->ended);
    pthread_mutex_destroy(&p->mu);
    free(p->jobs);
    free(p->th);
    free(p);
}
