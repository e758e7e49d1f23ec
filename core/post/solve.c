/*
 * solve.c — sm_solve: the sweep of solve/sweep.c, then what makes its answer trustworthy
 * (DESIGN.md 9.1): mode labels, tracking by MAC, critical and divergence speeds, and the
 * shapes dropped that the request did not ask for.
 *
 * How it fits: the top of the core's layers (post -> solve -> model -> base): it calls the
 * solve layer's sweep_run and the post modules (labels, track, critical, diverge); nothing
 * in solve/ calls back up here.
 */
#include "internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* DESIGN.md 9.1 on a solved sweep whose cases have their labels (sweep_run called lab_case on
 * each, on the thread that finished it): tracking, critical speeds (shapes still present). */
static int sweep_trust(const sm_model *m, sm_result *r, const double *omegas, int n,
                       sm_progress_fn cb, void *user)
{
    int *ord = malloc((size_t)(n ? n : 1) * sizeof(int)), rc = SM_NOMEM;
    if (!ord || sweep_order(omegas, n, ord) < 0)
        goto done;
    if ((rc = track_sweep(r, ord, n)) < 0)
        goto done;
    /* the refinements are extra solves: a stop (cancel, time limit, shutdown) ends them and keeps
     * what the sweep found */
    if ((rc = crit_find(m, r, ord, n, cb, user)) == SM_OK)
        rc = div_find(m, r, ord, n, cb, user);
    if (rc == SM_CANCELED) {
        r->refine_stopped = 1;
        rc = SM_OK;
    }
done:
    free(ord);
    return rc;
}

int sm_solve(const sm_model *m, const double *omegas, int n_omegas, sm_progress_fn cb, void *user,
             sm_result **out, sm_diag *diag)
{
    sm_result *r = NULL;
    int rc = sweep_run(m, omegas, n_omegas, cb, user, lab_case, &r, diag);
    if (rc < 0)
        return rc;
    if ((rc = sweep_trust(m, r, omegas, n_omegas, cb, user)) < 0) {
        sm_result_free(r);
        if (diag) {
            memset(diag, 0, sizeof *diag);
            diag->item_index = -1;
            diag->status = rc;
            snprintf(diag->message, sizeof diag->message, "%s", sm_strerror(rc));
        }
        return rc;
    }
    if (!m->opt.mode_shapes || !m->opt.coriolis)
        for (int i = 0; i < n_omegas; i++) {
            sm_case *c = &r->cases[i];
            if (!m->opt.mode_shapes) {
                free(c->shape_re);
                c->shape_re = NULL;
            }
            free(c->shape_im);
            c->shape_im = NULL;
        }
    *out = r;
    return SM_OK;
}
