/*
 * jobs.c — submission, bounded queue and worker pool of spinmodald.
 *
 * The store is the durable queue: a submission is committed there before
 * the caller answers, and workers claim the oldest queued job from it
 * (store_claim_next), so a restart or a second process sees the same
 * queue.  This module keeps the in-memory half:
 *   - `queued`, the number of queued jobs, for the 429 bound and the
 *     queue-depth gauge only (initialised from the store, +1 per accepted
 *     submission or requeue, -1 per claim or cancel; resynchronised with the
 *     store when a claim finds nothing, unless a change raced the count);
 *   - `posted`, bumped after every commit that makes a job queued: an idle
 *     worker sleeps only while it is unchanged since before its last empty
 *     claim (and at most JOBS_IDLE_POLL s, for jobs of another process), and
 *     after a successful claim it claims again at once.  Whether a worker
 *     sleeps never depends on `queued`: an approximate count must not be
 *     able to strand committed jobs;
 *   - one slot per worker with the running job's id, live progress and its
 *     cancel flag, read by the core's progress callback after every Newton
 *     iteration and every speed (cancel, time limit, shutdown);
 *   - a generation counter bumped whenever a job leaves queued/running, on
 *     which jobs_wait sleeps (?wait=S).
 * Locks: `lock` guards everything in struct jobs; `claim_lock` makes
 * "claim a job in the store + publish it in a slot" atomic with respect to
 * jobs_cancel, so a DELETE arriving between the two is never lost.  No store
 * call is made while holding `lock`.
 */
#include "jobs_internal.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "log.h"

/* OpenBLAS: pin BLAS to one thread per worker (parallelism is across jobs).
 * Weak, so a reference BLAS without the symbol links too. */
extern void openblas_set_num_threads(int n) __attribute__((weak));

/* ---------------------------------------------------------------- helpers */

/* Absolute CLOCK_REALTIME deadline seconds from now, for timed waits. */
struct timespec jobs_deadline(double seconds)
{
    struct timespec ts;
    double frac;

    clock_gettime(CLOCK_REALTIME, &ts);
    if (seconds < 0)
        seconds = 0;
    if (seconds > 1e6)
        seconds = 1e6;
    frac = seconds - floor(seconds);
    ts.tv_sec += (time_t)floor(seconds);
    ts.tv_nsec += (long)(frac * 1e9);
    if (ts.tv_nsec >= 1000000000L) {
        ts.tv_sec++;
        ts.tv_nsec -= 1000000000L;
    }
    return ts;
}

/* Monotonic seconds, for elapsed times. */
static double jobs_clock(void)
{
    struct timespec ts;

    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static jobs_slot *jobs_find_slot(jobs *j, const char *id)
{
    int i;

    for (i = 0; i < j->cfg.workers; i++)
        if (strcmp(j->slots[i].id, id) == 0)
            return &j->slots[i];
    return NULL;
}

/* Signal waiters that some job left queued/running. */
void jobs_bump(jobs *j)
{
    pthread_mutex_lock(&j->lock);
    j->gen++;
    pthread_cond_broadcast(&j->done_cv);
    pthread_mutex_unlock(&j->lock);
}

/* A job became queued in the store (committed): count it, wake an idle worker.  Lock held. */
void jobs_posted_locked(jobs *j)
{
    j->queued++;
    j->qver++;
    j->posted++;
    pthread_cond_signal(&j->work_cv);
}

static int jobs_map_store(int rc)
{
    switch (rc) {
    case STORE_OK: return JOBS_OK;
    case STORE_NOT_FOUND: return JOBS_NOT_FOUND;
    case STORE_CONFLICT: return JOBS_CONFLICT;
    case STORE_NOMEM: return JOBS_NOMEM;
    default: return JOBS_STORE_ERROR;
    }
}

/* ---------------------------------------------------------------- a job */

/* Progress/cancel callback of sm_solve: user is the worker's slot index. */
typedef struct jobs_cb_ctx {
    jobs *pool;
    jobs_slot *slot;
    double t0;               /* jobs_clock() at the start of the job */
} jobs_cb_ctx;

static int jobs_progress_cb(void *user, int done, int total)
{
    jobs_cb_ctx *c = user;
    int stop;

    pthread_mutex_lock(&c->pool->lock);
    c->slot->done = done;
    c->slot->total = total;
    if (jobs_clock() - c->t0 > c->pool->cfg.job_timeout)
        c->slot->timed_out = 1;
    stop = c->slot->cancel || c->slot->timed_out || c->slot->lost || c->pool->stop_now;
    pthread_mutex_unlock(&c->pool->lock);
    return stop;
}

/* A failure outside the pipeline (timeout, too many attempts): fills rec->state/error. */
static void jobs_fail(jobs_outcome_rec *rec, const char *type, const char *title,
                      const char *detail)
{
    rec->state = STORE_FAILED;
    rec->error = codec_job_error_text(type, title, detail, NULL, NULL);
}

/* The state a stopped run leaves its job in: timed out, canceled or back to the queue. */
static void jobs_stopped(jobs *j, jobs_slot *slot, int total, jobs_outcome_rec *rec)
{
    char detail[256];
    int timed_out;

    pthread_mutex_lock(&j->lock);
    timed_out = slot->timed_out && !slot->lost;
    rec->state = slot->lost ? STORE_RUNNING : slot->cancel ? STORE_CANCELED : STORE_QUEUED;
    pthread_mutex_unlock(&j->lock);
    if (!timed_out)
        return;
    snprintf(detail, sizeof(detail),
             "the job ran longer than the limit of %g s (--job-timeout) and was "
             "stopped after %d of %d speeds",
             j->cfg.job_timeout, rec->speeds_done, total);
    jobs_fail(rec, "timeout", "Job time limit exceeded", detail);
}

/*
 * A result over --max-result-bytes although its request passed the estimate
 * (codec size.c, an upper bound but for what the counts cannot bound:
 * critical speeds beyond two per mode and engine order): the job fails with
 * the reason instead of storing it.  Returns 1 then (rec filled), else 0.
 */
static int jobs_too_large(jobs *j, const codec_run_out *out, jobs_outcome_rec *rec)
{
    size_t lim = j->cfg.limits.max_result_bytes;
    char detail[256];

    if (lim == 0 || out->result_len <= lim)
        return 0;
    snprintf(detail, sizeof(detail),
             "the result is %zu bytes, more than the limit of %zu (--max-result-bytes); ask "
             "for fewer speeds, modes or engine orders, or leave mode_shapes out",
             out->result_len, lim);
    jobs_fail(rec, "result_too_large", "Result too large", detail);
    return 1;
}

/*
 * Run the claimed job through the codec's pipeline (parse the stored
 * canonical request, then codec_run); fills rec.
 */
static void jobs_run(jobs *j, jobs_slot *slot, const store_job *job, jobs_outcome_rec *rec)
{
    codec_errors *errs = codec_errors_new();
    codec_request *req = NULL;
    jobs_cb_ctx ctx = {j, slot, jobs_clock()};
    codec_run_out out;
    int st;

    memset(&out, 0, sizeof(out));
    rec->solve_seconds = -1;
    rec->state = STORE_FAILED;
    if (!errs)
        goto nomem;
    st = codec_request_parse(&req, job->request ? job->request : "", job->request_len,
                             &j->cfg.limits, errs);
    if (st == SM_NOMEM)
        goto nomem;
    if (st != SM_OK) {
        rec->error = codec_job_error_text(
            "invalid", "Stored request is no longer valid",
            "the request was accepted earlier but this spinmodald rejects it",
            codec_errors_to_json(errs), NULL);
        goto done;
    }
    codec_request_set_threads(req, j->cfg.solve_threads);
    codec_run(req, CODEC_RUN_TEXT | CODEC_RUN_CSV, jobs_progress_cb, &ctx, errs, &out);
    rec->solve_seconds = out.seconds;
    rec->speeds_done = out.speeds_done;
    switch (out.outcome) {
    case CODEC_RUN_CANCELED:
        jobs_stopped(j, slot, out.speeds_total, rec);
        goto done;
    case CODEC_RUN_DONE:
    case CODEC_RUN_PARTIAL:
        if (jobs_too_large(j, &out, rec))
            goto done;
        rec->result = out.result_text; /* taken over: the one copy, handed to the store */
        rec->result_len = out.result_len;
        rec->csv = out.csv;
        rec->csv_len = out.csv_len;
        out.result_text = out.csv = NULL;
        rec->state = out.outcome == CODEC_RUN_DONE ? STORE_DONE : STORE_FAILED;
        break;
    default: /* INVALID, FAILED, NOMEM: the pipeline wrote the error object */
        break;
    }
    rec->error = out.error; /* NULL when done; a partial result keeps its error */
    out.error = NULL;
    goto done;
nomem:
    free(rec->result);
    free(rec->csv);
    free(rec->error);
    rec->result = rec->csv = NULL;
    rec->csv_len = 0;
    rec->state = STORE_FAILED;
    rec->error = codec_job_error_text("solver_error", "Out of memory",
                                      "the daemon ran out of memory running this job", NULL, NULL);
done:
    codec_run_clear(&out);
    codec_request_free(req);
    codec_errors_free(errs);
}

/* --------------------------------------------------------------- workers */

/* Claim the next job into slot; 1 when one was claimed. */
static int jobs_claim(jobs *j, jobs_slot *slot, store_job *job)
{
    int rc;

    pthread_mutex_lock(&j->claim_lock);
    rc = store_claim_next(j->st, log_now(), job);
    if (rc == STORE_OK) {
        pthread_mutex_lock(&j->lock);
        memcpy(slot->id, job->id, sizeof(slot->id));
        slot->done = 0;
        slot->total = job->speeds_total;
        slot->cancel = job->cancel_requested;
        slot->timed_out = 0;
        slot->lost = 0;
        slot->started = log_now();
        if (j->queued > 0)
            j->queued--;
        j->qver++;
        j->busy++;
        pthread_mutex_unlock(&j->lock);
    }
    pthread_mutex_unlock(&j->claim_lock);
    if (rc != STORE_OK && rc != STORE_NOT_FOUND) {
        log_event("error", "store_error", "op", "claim", (char *)NULL);
        jobs_store_health(j, rc);
        return -1;
    }
    return rc == STORE_OK;
}

/* Run (or refuse, after too many attempts) one claimed job. */
static void jobs_handle(jobs *j, jobs_slot *slot, store_job *job)
{
    jobs_outcome_rec rec;
    char attempts[16];

    memset(&rec, 0, sizeof(rec));
    snprintf(attempts, sizeof(attempts), "%d", job->attempts);
    log_event("info", "job_started", "job", job->id, "attempts", attempts, (char *)NULL);
    if (job->attempts > JOBS_MAX_ATTEMPTS) {
        rec.solve_seconds = -1;
        jobs_fail(&rec, "interrupted", "Job interrupted repeatedly",
                  "the job was interrupted (crash or kill) every time it ran; it is not retried "
                  "again — resubmit it to try once more");
    } else {
        jobs_run(j, slot, job, &rec);
    }
    jobs_record(j, job, &rec);
    free(rec.error);
    free(rec.result);
    free(rec.csv);
}

/*
 * A claim found nothing: set `queued` to the store's count (another process
 * may have changed the queue).  The count is taken outside the lock, so it is
 * only applied when no submission was between its reservation and its commit
 * and no change of `queued` (reservation, commit, claim, cancel, requeue)
 * happened meanwhile: otherwise it would erase a reservation whose commit it
 * did not see, or count a claim twice; the next empty claim tries again.
 */
static void jobs_resync(jobs *j)
{
    long long counts[STORE_N_STATES];
    unsigned long long ver;
    int busy, ok;

    pthread_mutex_lock(&j->lock);
    ver = j->qver;
    busy = j->reserving > 0;
    pthread_mutex_unlock(&j->lock);
    if (busy)
        return;
    ok = store_count(j->st, counts) == STORE_OK;
    pthread_mutex_lock(&j->lock);
    if (ok && j->qver == ver && j->reserving == 0)
        j->queued = (int)(counts[STORE_QUEUED] > 1000000000LL ? 1000000000LL
                                                               : counts[STORE_QUEUED]);
    pthread_mutex_unlock(&j->lock);
}

static void *jobs_worker_main(void *arg)
{
    jobs_worker *w = arg;
    jobs *j = w->pool;
    jobs_slot *slot = &j->slots[w->index];
    store_job job;
    struct timespec until;
    unsigned long long seen;
    int got;

    memset(&job, 0, sizeof(job));
    for (;;) {
        /* `seen` is read before the claim: a job committed after the claim's
         * read of the store bumps `posted` after this, so the wait below
         * returns at once instead of sleeping on a job it did not see */
        pthread_mutex_lock(&j->lock);
        if (j->stopping) {
            pthread_mutex_unlock(&j->lock);
            break;
        }
        seen = j->posted;
        pthread_mutex_unlock(&j->lock);
        jobs_retry_unrecorded(j);
        got = jobs_claim(j, slot, &job);
        if (got < 0) {
            until = jobs_deadline(1.0);
            pthread_mutex_lock(&j->lock);
            if (!j->stopping)
                pthread_cond_timedwait(&j->work_cv, &j->lock, &until);
            pthread_mutex_unlock(&j->lock);
            continue;
        }
        if (got == 0) {
            jobs_resync(j);
            /* a shared store gets jobs from other replicas, which no signal announces */
            until = jobs_deadline(j->cfg.shared ? JOBS_SHARED_POLL : JOBS_IDLE_POLL);
            pthread_mutex_lock(&j->lock);
            while (j->posted == seen && !j->stopping) {
                if (pthread_cond_timedwait(&j->work_cv, &j->lock, &until) == ETIMEDOUT)
                    break;
            }
            pthread_mutex_unlock(&j->lock);
            continue;
        }
        jobs_handle(j, slot, &job);
        store_job_clear(&job);
        pthread_mutex_lock(&j->lock);
        slot->id[0] = '\0';
        j->busy--;
        j->gen++;
        pthread_cond_broadcast(&j->done_cv);
        pthread_mutex_unlock(&j->lock);
    }
    pthread_mutex_lock(&j->lock);
    j->alive--;
    pthread_cond_broadcast(&j->done_cv);
    pthread_mutex_unlock(&j->lock);
    return NULL;
}

/* ------------------------------------------------------------ lifecycle */

static void jobs_free(jobs *j)
{
    if (!j)
        return;
    pthread_cond_destroy(&j->heart_cv);
    pthread_cond_destroy(&j->work_cv);
    pthread_cond_destroy(&j->done_cv);
    pthread_mutex_destroy(&j->claim_lock);
    pthread_mutex_destroy(&j->lock);
    free(j->slots);
    free(j->workers);
    free(j->unrecorded);
    free(j);
}

int jobs_start(jobs **out, store *st, metrics *mx, const jobs_config *cfg)
{
    long long counts[STORE_N_STATES];
    jobs *j;
    int i;

    *out = NULL;
    if (store_count(st, counts) != STORE_OK)
        return JOBS_STORE_ERROR;
    j = calloc(1, sizeof(*j));
    if (!j)
        return JOBS_NOMEM;
    j->st = st;
    j->mx = mx;
    j->cfg = *cfg;
    if (j->cfg.workers < 1)
        j->cfg.workers = 1;
    if (j->cfg.queue_max < 1)
        j->cfg.queue_max = 1;
    if (!(j->cfg.job_timeout > 0))
        j->cfg.job_timeout = 30;
    /* A stored request was accepted once: its body limit does not apply to
     * the canonical text (longer: defaults added, reals at 17 digits). */
    j->cfg.limits.max_request_bytes = (size_t)-1;
    j->queued = (int)(counts[STORE_QUEUED] > 1000000000LL ? 1000000000LL : counts[STORE_QUEUED]);
    j->slots = calloc((size_t)j->cfg.workers, sizeof(*j->slots));
    j->workers = calloc((size_t)j->cfg.workers, sizeof(*j->workers));
    if (!j->slots || !j->workers || pthread_mutex_init(&j->lock, NULL) ||
        pthread_mutex_init(&j->claim_lock, NULL) || pthread_cond_init(&j->work_cv, NULL) ||
        pthread_cond_init(&j->done_cv, NULL) || pthread_cond_init(&j->heart_cv, NULL)) {
        free(j->slots);
        free(j->workers);
        free(j);
        return JOBS_NOMEM;
    }
    if (openblas_set_num_threads)
        openblas_set_num_threads(1);
    for (i = 0; i < j->cfg.workers; i++) {
        j->workers[i].pool = j;
        j->workers[i].index = i;
        pthread_mutex_lock(&j->lock);
        j->alive++;
        pthread_mutex_unlock(&j->lock);
        if (pthread_create(&j->workers[i].thread, NULL, jobs_worker_main, &j->workers[i])) {
            pthread_mutex_lock(&j->lock);
            j->alive--;
            pthread_mutex_unlock(&j->lock);
            jobs_stop(j, 0);
            return JOBS_NOMEM;
        }
        j->workers[i].started = 1;
    }
    if (j->cfg.shared) {
        if (!(j->cfg.lease >= 3.0))
            j->cfg.lease = 30.0;
        if (pthread_create(&j->heart, NULL, jobs_heart_main, j)) {
            jobs_stop(j, 0);
            return JOBS_NOMEM;
        }
        j->heart_started = 1;
    }
    *out = j;
    return JOBS_OK;
}

void jobs_stop(jobs *j, double grace)
{
    struct timespec until = jobs_deadline(grace);
    int i;

    if (!j)
        return;
    pthread_mutex_lock(&j->lock);
    j->stopping = 1;
    pthread_cond_broadcast(&j->work_cv);
    pthread_cond_broadcast(&j->done_cv);
    while (j->busy > 0) {
        if (pthread_cond_timedwait(&j->done_cv, &j->lock, &until) == ETIMEDOUT)
            break;
    }
    j->stop_now = 1;   /* jobs still running go back to the queue */
    pthread_mutex_unlock(&j->lock);
    for (i = 0; i < j->cfg.workers; i++)
        if (j->workers[i].started)
            pthread_join(j->workers[i].thread, NULL);
    if (j->heart_started) {
        pthread_mutex_lock(&j->lock);
        j->heart_stop = 1;
        pthread_cond_broadcast(&j->heart_cv);
        pthread_mutex_unlock(&j->lock);
        pthread_join(j->heart, NULL);
    }
    jobs_free(j);
}

int jobs_stopping(jobs *j)
{
    int s;

    pthread_mutex_lock(&j->lock);
    s = j->stopping;
    pthread_mutex_unlock(&j->lock);
    return s;
}

/* ------------------------------------------------------------ requests */

/*
 * Queued jobs of the whole shared store (all replicas) for the 429 bound: a
 * store count at most JOBS_SHARED_COUNT_AGE s old (a count scans the table:
 * not once per POST) plus this replica's submissions since; 0 on a store of
 * this process alone (j->queued is exact there).
 */
static long long jobs_shared_queued(jobs *j)
{
    long long counts[STORE_N_STATES], q;
    double now = log_now();

    if (!j->cfg.shared)
        return 0;
    pthread_mutex_lock(&j->lock);
    q = now - j->shared_at < JOBS_SHARED_COUNT_AGE ? j->shared_queued + j->shared_since : -1;
    pthread_mutex_unlock(&j->lock);
    if (q >= 0)
        return q;
    if (store_count(j->st, counts) != STORE_OK)
        return 0; /* the submission's own write will report the store */
    pthread_mutex_lock(&j->lock);
    j->shared_queued = q = counts[STORE_QUEUED];
    j->shared_since = 0;
    j->shared_at = now;
    pthread_mutex_unlock(&j->lock);
    return q;
}

int jobs_submit(jobs *j, const codec_request *req, jobs_outcome *outcome, store_job *job)
{
    char id[65];
    int speeds, created = 0, rc;
    long long shared_queued;
    store_job tmp;
    store_job *jb = job ? job : &tmp;

    memset(&tmp, 0, sizeof(tmp));
    *outcome = JOBS_EXISTING;
    if (jobs_stopping(j))
        return JOBS_STOPPING;
    if (codec_job_id(req, id) != SM_OK)
        return JOBS_NOMEM;
    /* cache hit: a read, no write transaction */
    rc = store_get(j->st, id, 0, jb);
    if (rc == STORE_OK && jb->state != STORE_FAILED && jb->state != STORE_CANCELED) {
        metrics_cache(j->mx, 1);
        store_job_clear(&tmp);
        return JOBS_OK;
    }
    store_job_clear(jb);
    if (rc != STORE_OK && rc != STORE_NOT_FOUND)
        return jobs_map_store(rc);
    shared_queued = jobs_shared_queued(j);
    pthread_mutex_lock(&j->lock);
    /* a shared store: other replicas claim what this one queued, so only the
     * store's count means anything (up to JOBS_SHARED_COUNT_AGE s old) */
    if (j->cfg.shared ? shared_queued >= j->cfg.queue_max : j->queued >= j->cfg.queue_max) {
        pthread_mutex_unlock(&j->lock);
        return JOBS_FULL;
    }
    j->queued++;   /* reserve the place before the write */
    j->shared_since++; /* counted with the shared queue until the next store count */
    j->qver++;
    j->reserving++;
    pthread_mutex_unlock(&j->lock);
    codec_request_speeds(req, &speeds);
    /* the canonical text, with the request's "name" when it has one (not in the id) */
    rc = store_submit(j->st, id, codec_request_stored_text(req),
                      strlen(codec_request_stored_text(req)), speeds, log_now(), &created, jb);
    pthread_mutex_lock(&j->lock);
    j->reserving--;
    j->qver++;
    if (rc != STORE_OK || created == 0) {
        j->queued--;   /* nothing new queued: give the place back */
    } else {
        j->posted++;   /* committed: the reserved place is the job's */
        pthread_cond_signal(&j->work_cv);
    }
    pthread_mutex_unlock(&j->lock);
    store_job_clear(&tmp);
    if (rc != STORE_OK)
        return jobs_map_store(rc);
    *outcome = created == 1 ? JOBS_CREATED : created == 2 ? JOBS_RESUBMITTED : JOBS_EXISTING;
    metrics_cache(j->mx, created == 0);
    if (created)
        log_event("info", "job_queued", "job", id, "resubmitted", created == 2 ? "true" : NULL,
                  (char *)NULL);
    return JOBS_OK;
}

int jobs_cancel(jobs *j, const char *id, store_job *job)
{
    store_state state = STORE_QUEUED;
    jobs_slot *slot;
    int rc;

    pthread_mutex_lock(&j->claim_lock);
    rc = store_cancel(j->st, id, log_now(), &state);
    if (rc == STORE_OK) {
        pthread_mutex_lock(&j->lock);
        if (state == STORE_CANCELED) {          /* was queued */
            if (j->queued > 0)
                j->queued--;
            j->qver++;
        } else if ((slot = jobs_find_slot(j, id)) != NULL) {
            slot->cancel = 1;                    /* the callback stops it */
        }
        pthread_mutex_unlock(&j->lock);
    }
    pthread_mutex_unlock(&j->claim_lock);
    if (rc == STORE_OK && state == STORE_CANCELED) {
        metrics_job_finished(j->mx, STORE_CANCELED);
        log_event("info", "job_canceled", "job", id, "state", "queued", (char *)NULL);
        jobs_bump(j);
    }
    if (job && (rc == STORE_OK || rc == STORE_CONFLICT)) {
        int rc2 = jobs_get(j, id, 0, job);
        if (rc2 != JOBS_OK)
            return rc2;
    }
    return jobs_map_store(rc);
}

int jobs_get(jobs *j, const char *id, unsigned flags, store_job *out)
{
    jobs_slot *slot;
    int rc = store_get(j->st, id, flags, out);

    if (rc != STORE_OK)
        return jobs_map_store(rc);
    if (out->state == STORE_RUNNING) {
        pthread_mutex_lock(&j->lock);
        slot = jobs_find_slot(j, id);
        if (slot) {
            out->speeds_done = slot->done;
            if (slot->cancel)
                out->cancel_requested = 1;
        }
        pthread_mutex_unlock(&j->lock);
    }
    return JOBS_OK;
}

int jobs_wait(jobs *j, const char *id, double timeout)
{
    double end = jobs_clock() + (timeout > 0 ? timeout : 0);
    unsigned long long gen;
    struct timespec until;
    store_job job;
    store_state state;
    int rc, stopping;

    memset(&job, 0, sizeof(job));
    for (;;) {
        pthread_mutex_lock(&j->lock);
        gen = j->gen;
        stopping = j->stopping;
        pthread_mutex_unlock(&j->lock);
        if (stopping)
            return JOBS_STOPPING;
        rc = store_get(j->st, id, 0, &job);
        state = job.state;
        store_job_clear(&job);
        if (rc != STORE_OK)
            return jobs_map_store(rc);
        if (state != STORE_QUEUED && state != STORE_RUNNING)
            return JOBS_OK;
        if (jobs_clock() >= end)
            return JOBS_OK;
        /* sleep until some job finishes, at most 1 s (another process may finish it) */
        until = jobs_deadline(fmin(1.0, end - jobs_clock()));
        pthread_mutex_lock(&j->lock);
        while (j->gen == gen && !j->stopping) {
            if (pthread_cond_timedwait(&j->done_cv, &j->lock, &until) == ETIMEDOUT)
                break;
        }
        pthread_mutex_unlock(&j->lock);
    }
}

void jobs_get_stats(jobs *j, jobs_stats *s)
{
    pthread_mutex_lock(&j->lock);
    s->queued = j->queued;
    s->workers = j->cfg.workers;
    s->workers_alive = j->alive;
    s->workers_busy = j->busy;
    s->store_failing = j->store_failed_at > 0.0 &&
                       log_now() - j->store_failed_at < JOBS_STORE_FAIL_MEMORY;
    s->unrecorded = j->n_unrecorded;
    pthread_mutex_unlock(&j->lock);
}
