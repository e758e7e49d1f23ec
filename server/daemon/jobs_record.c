/*
 * jobs_record.c — how a worker records the end of a job in the store.
 *
 * How it fits: jobs.c's workers run a job and hand its outcome here.  The
 * finish is retried while the store is briefly unavailable, busy or slow
 * (jobs_finish_retrying); a job whose end no write could record (full disk,
 * read-only store) is kept by id and retried before each later claim
 * (jobs_retry_unrecorded), so the store never shows a finished job as
 * running for longer than the outage.  /readyz follows the writes' health
 * (jobs_store_health).
 */
#include "jobs_internal.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"

/* A write to the store succeeded (rc == STORE_OK) or failed: /readyz follows it. */
void jobs_store_health(jobs *j, int rc)
{
    if (rc == STORE_NOT_FOUND || rc == STORE_CONFLICT)
        return; /* the store answered */
    pthread_mutex_lock(&j->lock);
    j->store_failed_at = rc == STORE_OK ? 0.0 : log_now();
    pthread_mutex_unlock(&j->lock);
}

/* Remember id as a job whose end is not recorded yet (see jobs_retry_unrecorded). */
static void jobs_add_unrecorded(jobs *j, const char *id)
{
    int i;

    pthread_mutex_lock(&j->lock);
    for (i = 0; i < j->n_unrecorded; i++)
        if (strcmp(j->unrecorded[i], id) == 0)
            goto done;
    if (j->n_unrecorded == j->cap_unrecorded) {
        int ncap = j->cap_unrecorded ? 2 * j->cap_unrecorded : 8;
        char(*nu)[65] = realloc(j->unrecorded, (size_t)ncap * sizeof(*nu));
        if (!nu) /* a restart re-queues it (it is `running` in the store) */
            goto done;
        j->unrecorded = nu;
        j->cap_unrecorded = ncap;
    }
    memcpy(j->unrecorded[j->n_unrecorded++], id, 65);
done:
    pthread_mutex_unlock(&j->lock);
}

/*
 * The end of a job could not be written as computed (its result is too big
 * for a full disk, or the store refused the write): store it as failed with
 * the reason and no result; if even that fails, put it back to the queue;
 * if that fails too, keep it in memory and retry (jobs_retry_unrecorded).
 * Never leaves a job `running` without a worker.  Returns the state stored,
 * or STORE_RUNNING when nothing could be stored.
 */
static store_state jobs_record_fallback(jobs *j, const char *id, int why)
{
    char detail[256], *err;
    int rc;

    snprintf(detail, sizeof(detail),
             "the analysis ended but its result could not be stored (%s); it is not kept: "
             "submit the request again once the database accepts writes",
             store_strerror(why));
    err = codec_job_error_text("store_error", "Result not stored", detail, NULL, NULL);
    rc = err ? store_finish(j->st, id, STORE_FAILED, log_now(), 0, err, NULL, 0, NULL, 0)
             : STORE_NOMEM;
    free(err);
    /* these small writes may well succeed on a full disk: only their failures
     * count, so /readyz keeps saying that a result could not be stored */
    if (rc != STORE_OK)
        jobs_store_health(j, rc);
    if (rc == STORE_OK || rc == STORE_CONFLICT || rc == STORE_NOT_FOUND)
        return STORE_FAILED;
    rc = store_requeue(j->st, id);
    if (rc != STORE_OK)
        jobs_store_health(j, rc);
    if (rc == STORE_OK) {
        pthread_mutex_lock(&j->lock);
        jobs_posted_locked(j);
        pthread_mutex_unlock(&j->lock);
        return STORE_QUEUED;
    }
    jobs_add_unrecorded(j, id);
    return STORE_RUNNING;
}

/* Try again to record the jobs whose end no write could store yet. */
void jobs_retry_unrecorded(jobs *j)
{
    char id[65];
    store_state st;

    for (;;) {
        pthread_mutex_lock(&j->lock);
        if (j->n_unrecorded == 0) {
            pthread_mutex_unlock(&j->lock);
            return;
        }
        memcpy(id, j->unrecorded[--j->n_unrecorded], sizeof(id));
        pthread_mutex_unlock(&j->lock);
        st = jobs_record_fallback(j, id, STORE_ERROR);
        log_event(st == STORE_RUNNING ? "error" : "warn", "job_recorded_late", "job", id,
                  "state", st == STORE_RUNNING ? "still unrecorded" : store_state_name(st),
                  (char *)NULL);
        if (st == STORE_RUNNING)
            return; /* the store still refuses: the next loop tries again */
        jobs_bump(j);
    }
}

/*
 * store_finish of rec; a store that is only unreachable for a while
 * (PostgreSQL restarting, BUSY) is retried with backoff for up to
 * JOBS_FINISH_RETRY s, so a result computed during an outage is kept, not
 * dropped; a stop cuts the retries short.  Returns the last store_rc.
 */
static int jobs_finish_retrying(jobs *j, const char *id, const jobs_outcome_rec *rec)
{
    double wait = 0.25, spent = 0.0;
    struct timespec until;
    int rc, stop;

    for (;;) {
        rc = store_finish(j->st, id, rec->state, log_now(), rec->speeds_done, rec->error,
                          rec->result, rec->result_len, rec->csv, rec->csv_len);
        if ((rc != STORE_UNAVAILABLE && rc != STORE_BUSY && rc != STORE_TIMEOUT) ||
            spent >= JOBS_FINISH_RETRY)
            return rc;
        until = jobs_deadline(wait);
        pthread_mutex_lock(&j->lock);
        if (!j->stop_now)
            pthread_cond_timedwait(&j->work_cv, &j->lock, &until);
        stop = j->stop_now;
        pthread_mutex_unlock(&j->lock);
        if (stop)
            return rc;
        spent += wait;
        wait = wait * 2 > 5.0 ? 5.0 : wait * 2;
    }
}

/* Record rec in the store, count and log it. */
void jobs_record(jobs *j, const store_job *job, const jobs_outcome_rec *rec)
{
    char secs[32], speeds[32];
    store_state kept = rec->state;
    int rc;

    snprintf(secs, sizeof(secs), "%.3f", rec->solve_seconds < 0 ? 0.0 : rec->solve_seconds);
    snprintf(speeds, sizeof(speeds), "%d/%d", rec->speeds_done, job->speeds_total);
    if (rec->state == STORE_RUNNING) { /* lost: its lease expired and another replica runs it */
        log_event("warn", "job_lost", "job", job->id, "speeds", speeds, "reason",
                  "lease expired (another replica re-queued it); nothing recorded", (char *)NULL);
        return;
    }
    if (rec->state == STORE_QUEUED) {
        rc = store_requeue(j->st, job->id);
        jobs_store_health(j, rc);
        if (rc == STORE_OK) {
            pthread_mutex_lock(&j->lock);
            jobs_posted_locked(j);
            pthread_mutex_unlock(&j->lock);
        } else if (rc != STORE_CONFLICT && rc != STORE_NOT_FOUND) {
            jobs_add_unrecorded(j, job->id);
        }
        log_event(rc == STORE_OK ? "info" : "error", "job_requeued", "job", job->id, "speeds",
                  speeds, "reason", "shutdown", "store", rc == STORE_OK ? NULL : store_strerror(rc),
                  (char *)NULL);
        return;
    }
    rc = jobs_finish_retrying(j, job->id, rec);
    jobs_store_health(j, rc);
    if (rc != STORE_OK && rc != STORE_CONFLICT && rc != STORE_NOT_FOUND)
        kept = jobs_record_fallback(j, job->id, rc);
    if (rec->solve_seconds >= 0 && rec->state != STORE_CANCELED)
        metrics_solve_seconds(j->mx, rec->solve_seconds);
    if (kept != STORE_QUEUED && kept != STORE_RUNNING)
        metrics_job_finished(j->mx, kept);
    log_event(rc == STORE_OK ? "info" : "error",
              rec->state == STORE_DONE     ? "job_done"
              : rec->state == STORE_FAILED ? "job_failed"
                                           : "job_canceled",
              "job", job->id, "state", store_state_name(rec->state), "speeds", speeds, "seconds",
              secs, "attempts", NULL, "store",
              rc == STORE_OK ? NULL : store_strerror(rc), "stored_as",
              rc == STORE_OK ? NULL : kept == STORE_RUNNING ? "nothing yet (retried)"
                                                            : store_state_name(kept),
              (char *)NULL);
}
