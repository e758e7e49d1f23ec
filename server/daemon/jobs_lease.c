/*
 * jobs_lease.c — a replica's part in a store shared with other replicas
 * (PostgreSQL, DESIGN.md §6): leases and their heartbeat.
 *
 * How it fits: a job claimed from a shared store belongs to this replica
 * until its lease runs out.  The heartbeat thread (started by jobs_start when
 * cfg.shared) renews the leases of the jobs its workers run every lease/3; a
 * replica that dies stops renewing, and any other replica's heartbeat puts its
 * jobs back in the queue (store_requeue_expired; a job that keeps killing
 * replicas fails after JOBS_MAX_ATTEMPTS).  A renewal refused with CONFLICT
 * means this replica's lease already expired and another took the job: the
 * worker stops it and records nothing (jobs.c, slot->lost).  A DELETE through
 * another replica sets the job's cancel flag in the store; the heartbeat
 * brings it to the slot, and the core's callback stops the job.
 */
#include "jobs_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"

/*
 * One heartbeat of a replica on a shared store: renew the lease of every
 * running job (a CONFLICT means the lease expired and another replica took
 * it: the job is lost here, stopped and not recorded), bring a cancel asked
 * through another replica to the job's slot, and re-queue the jobs of dead
 * replicas (leases expired; failed after JOBS_MAX_ATTEMPTS).
 */
static void jobs_heartbeat(jobs *j)
{
    char (*ids)[65] = calloc((size_t)j->cfg.workers, sizeof(*ids));
    double now = log_now();
    int i, n = 0, requeued = 0, failed = 0, rc, flag;

    if (!ids)
        return;
    pthread_mutex_lock(&j->lock);
    for (i = 0; i < j->cfg.workers; i++)
        memcpy(ids[i], j->slots[i].id, 65);
    pthread_mutex_unlock(&j->lock);
    for (i = 0; i < j->cfg.workers; i++) {
        if (!ids[i][0])
            continue;
        rc = store_renew_lease(j->st, ids[i], store_owner(j->st), now, j->cfg.lease);
        flag = 0;
        if (rc == STORE_OK)
            store_cancel_requested(j->st, ids[i], &flag);
        pthread_mutex_lock(&j->lock);
        if (strcmp(j->slots[i].id, ids[i]) == 0) { /* still the same job */
            if (rc == STORE_CONFLICT || rc == STORE_NOT_FOUND)
                j->slots[i].lost = 1;
            if (flag)
                j->slots[i].cancel = 1;
        }
        pthread_mutex_unlock(&j->lock);
        n++;
    }
    free(ids);
    if (store_requeue_expired(j->st, now, JOBS_MAX_ATTEMPTS, &requeued, &failed) == STORE_OK &&
        requeued + failed > 0) {
        char a[16], b[16];
        snprintf(a, sizeof(a), "%d", requeued);
        snprintf(b, sizeof(b), "%d", failed);
        log_event("warn", "leases_expired", "requeued", a, "failed", b, (char *)NULL);
        metrics_lease_expired(j->mx, requeued, failed);
        pthread_mutex_lock(&j->lock);
        j->posted++;
        pthread_cond_broadcast(&j->work_cv);
        pthread_mutex_unlock(&j->lock);
        if (failed)
            jobs_bump(j);
    }
    (void)n;
}

void *jobs_heart_main(void *arg)
{
    jobs *j = arg;
    struct timespec until;

    pthread_mutex_lock(&j->lock);
    while (!j->heart_stop) {
        until = jobs_deadline(j->cfg.lease / 3.0);
        pthread_cond_timedwait(&j->heart_cv, &j->lock, &until);
        if (j->heart_stop)
            break;
        pthread_mutex_unlock(&j->lock);
        jobs_heartbeat(j);
        pthread_mutex_lock(&j->lock);
    }
    pthread_mutex_unlock(&j->lock);
    return NULL;
}

