/*
 * sweep.c — the speeds of a solve in ascending order with continuation
 * (equilibrium.c); at each equilibrium the case is finished (sweep_case.c:
 * linearisation with P frozen, eigen-analysis, mode shapes in the hub frame;
 * DESIGN.md 1.3-1.4) here or, with sm_options.threads > 1, on a worker
 * (sweep_pool.c) while the continuation goes on.  sm_solve (post/solve.c)
 * adds labels, tracking, critical and divergence speeds on top; nothing here
 * calls post/.
 */
#include "sweep_pool.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double sweep_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e3 * (double)t.tv_sec + 1e-6 * (double)t.tv_nsec;
}

void sm_result_free(sm_result *r)
{
    if (!r)
        return;
    for (int i = 0; i < r->n_cases; i++) {
        sm_case *c = &r->cases[i];
        free(c->nodes);
        free(c->axial_force);
        free(c->frequency);
        free(c->eig_re);
        free(c->eig_im);
        free(c->mac_to_previous);
        free(c->previous_index);
        free(c->shape_re);
        free(c->shape_im);
        free(c->error_estimate);
        free(c->error_order);
        free(c->energy);
        free(c->label_kind);
        free(c->label_ordinal);
        free(c->label_confidence);
        free(c->support_share);
        free(c->tracked_index);
        free(c->track_flag);
        free(c->track_partner);
    }
    free(r->cases);
    free(r->critical);
    free(r->divergence);
    free(r);
}


typedef struct sweep_key {
    double omega;
    int index;
} sweep_key;

static int sweep_key_cmp(const void *a, const void *b)
{
    const sweep_key *x = a, *y = b;
    if (x->omega != y->omega)
        return x->omega < y->omega ? -1 : 1;
    return x->index - y->index;
}

/* The speeds of omegas in ascending order (ties in input order) into ord (n case indices). */
int sweep_order(const double *omegas, int n, int *ord)
{
    sweep_key *key = malloc((size_t)(n ? n : 1) * sizeof *key);
    if (!key)
        return SM_NOMEM;
    for (int i = 0; i < n; i++) {
        key[i].omega = omegas[i];
        key[i].index = i;
    }
    qsort(key, (size_t)n, sizeof *key, sweep_key_cmp);
    for (int i = 0; i < n; i++)
        ord[i] = key[i].index;
    free(key);
    return SM_OK;
}

/* Every speed of omegas: equilibrium, modes and nodal shapes (kept), after on each case with
 * modes, no tracking. */
int sweep_run(const sm_model *m, const double *omegas, int n_omegas, sm_progress_fn cb, void *user,
              sweep_case_fn after, sm_result **out, sm_diag *diag)
{
    sm_diag scratch;
    sm_diag *d = diag ? diag : &scratch;
    memset(d, 0, sizeof *d);
    d->item_index = -1;
    *out = NULL;
    if (n_omegas < 1 || !omegas) {
        d->status = SM_INVALID_INPUT;
        d->item = SM_ITEM_OPTIONS;
        snprintf(d->field, sizeof d->field, "omega");
        snprintf(d->message, sizeof d->message, "at least one speed is required");
        return SM_INVALID_INPUT;
    }
    for (int i = 0; i < n_omegas; i++)
        if (!isfinite(omegas[i]) || omegas[i] < 0) {
            d->status = SM_INVALID_INPUT;
            d->item = SM_ITEM_OPTIONS;
            d->item_index = i;
            snprintf(d->field, sizeof d->field, "omega");
            snprintf(d->message, sizeof d->message, "speeds must be finite and non-negative (rad/s)");
            return SM_INVALID_INPUT;
        }
    for (int i = 0; m->gravity && i < n_omegas; i++)
        if (omegas[i] != 0) { /* the weight turns with the hub: not steady in its frame */
            d->status = SM_INVALID_INPUT;
            d->item = SM_ITEM_OPTIONS;
            d->item_index = i;
            snprintf(d->field, sizeof d->field, "omega");
            snprintf(d->message, sizeof d->message,
                     "gravity is a steady load at rest only: speeds must be 0");
            return SM_INVALID_INPUT;
        }
    for (int i = 0; m->base && i < n_omegas; i++)
        if (omegas[i] != 0) { /* the base's kinematics are linearised at rest (DESIGN.md 8.6) */
            d->status = SM_INVALID_INPUT;
            d->item = SM_ITEM_OPTIONS;
            d->item_index = i;
            snprintf(d->field, sizeof d->field, "omega");
            snprintf(d->message, sizeof d->message,
                     "a structure on a free base (elastic clamp, floating platform) is analysed at "
                     "rest only: speeds must be 0");
            return SM_INVALID_INPUT;
        }
    int rc = SM_NOMEM, n = m->n;
    sm_result *r = calloc(1, sizeof *r);
    sweep_key *key = malloc((size_t)n_omegas * sizeof *key);
    double *q = dm_vec((size_t)n);
    smi_lin *L = NULL;
    sweep_pool *pool = NULL;
    eq_carry *carry = NULL;
    if (!r || !key || !q)
        goto fail;
    r->cases = calloc((size_t)n_omegas, sizeof(sm_case));
    if (!r->cases)
        goto fail;
    r->n_cases = n_omegas;
    /* One speed without a pool: the modes' workspace comes after the equilibrium's is freed, so
     * that it takes the same memory instead of fresh pages (a page fault costs 1-2 us where the
     * small solves were measured: 270 of the planar beam's 1 070, issue 27).  Nothing else
     * changes: both start zeroed. */
    int single = n_omegas == 1; /* a pool takes two speeds or more */
    if ((!single && (rc = smi_lin_new(m, SMI_USE_MODES, tree_use(m), &L)) < 0) ||
        (rc = eq_carry_new(m, &carry)) < 0)
        goto fail;
    for (int i = 0; i < n_omegas; i++) {
        key[i].omega = omegas[i];
        key[i].index = i;
        r->cases[i].omega = omegas[i];
    }
    qsort(key, (size_t)n_omegas, sizeof *key, sweep_key_cmp);
    if (m->opt.threads > 1 && n_omegas > 1 &&
        (rc = sweep_pool_new(m, m->opt.threads, n_omegas, after, &pool)) < 0)
        goto fail;
    sm_progress pr = {cb, user, 0, n_omegas};
    double s_prev = 0;
    int from_rest = 1, chunk = sweep_chunk(m);
    for (int t = 0; t < n_omegas; t++) {
        sm_case *c = &r->cases[key[t].index];
        double s = smi_load(m, c->omega), t0 = sweep_ms();
        sm_eq_out eo;
        if (from_rest) {
            memset(q, 0, (size_t)n * sizeof(double));
            s_prev = 0;
        }
        rc = eq_solve(m, q, s_prev, s, from_rest, carry, &pr, &eo);
        if (rc < 0) {
            snprintf(d->message, sizeof d->message, "%s", eo.message);
            goto fail;
        }
        rc = SM_CANCELED;
        if (eo.canceled)
            goto fail;
        c->t_equilibrium = sweep_ms() - t0;
        c->converged = eo.converged;
        c->iterations = eo.iterations;
        c->residual = eo.residual;
        c->last_omega = sqrt(eo.last_s);
        if (!eo.converged) {
            c->status = SM_CASE_NO_EQUILIBRIUM;
            snprintf(c->message, sizeof c->message, "%s", eo.message);
            from_rest = 1;
        } else {
            s_prev = s; /* tracking (track.c) runs once every speed is solved */
            from_rest = 0;
        }
        /* the case's steady-state outputs and modes: here, or on a worker (sweep_pool.h); a case
         * after the first of its chunk starts its eigen-analysis from the case before */
        if (single) {
            eq_carry_free(carry);
            carry = NULL;
            if ((rc = smi_lin_new(m, SMI_USE_MODES, tree_use(m), &L)) < 0)
                goto fail;
        }
        if (!pool)
            smi_lin_warm(L, t % chunk != 0);
        if (pool ? (rc = sweep_pool_add(pool, c, q)) < 0
                 : (rc = sweep_case_finish(m, q, L, &pr, after, c)) < 0)
            goto fail;
        pr.done = pool ? sweep_pool_finished(pool) : t + 1;
        /* after the last speed a stop request leaves the finished cases alone */
        if (cb && cb(user, pr.done, pr.total) && pr.done < pr.total) {
            rc = SM_CANCELED;
            goto fail;
        }
    }
    if (pool && (rc = sweep_pool_finish(pool, L, &pr)) < 0)
        goto fail;
    sweep_pool_free(pool);
    eq_carry_free(carry);
    smi_lin_free(L);
    free(key);
    free(q);
    *out = r;
    return SM_OK;
fail:
    if (pool) {
        sweep_pool_stop(pool);
        sweep_pool_free(pool); /* before the cases its workers write go */
    }
    eq_carry_free(carry);
    smi_lin_free(L);
    free(key);
    free(q);
    sm_result_free(r);
    d->status = rc;
    if (!d->message[0])
        snprintf(d->message, sizeof d->message, "%s", sm_strerror(rc));
    return rc;
}

int sweep_lowest(const sm_model *m, double omega, sm_progress_fn cb, void *user, double *lambda)
{
    int n = m->n, rc;
    double *q = dm_vec((size_t)n);
    sm_progress pr = {cb, user, 0, 1};
    sm_eq_out eo;
    smi_lin *D = NULL;
    *lambda = NAN;
    rc = SM_NOMEM;
    if (!q)
        goto done;
    if ((rc = eq_solve(m, q, 0, smi_load(m, omega), 1, NULL, &pr, &eo)) < 0)
        goto done;
    rc = eo.canceled ? SM_CANCELED : SM_NO_EQUILIBRIUM;
    if (!eo.converged)
        goto done;
    if ((rc = smi_lin_new(m, SMI_USE_MODES, 0, &D)) < 0)
        goto done;
    smi_lin_linearize(m, q, omega, D);
    rc = smi_lin_lowest(m, D, lambda);
done:
    smi_lin_free(D);
    free(q);
    return rc;
}
