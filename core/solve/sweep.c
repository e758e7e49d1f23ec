/*
 * sweep.c — the speeds of a solve in ascending order with continuation
 * (equilibrium.c), linearisation at each equilibrium (M*, C*, K* with P
 * frozen), the eigen-analysis (eigen.c), mode shapes in the hub frame
 * (DESIGN.md 1.3-1.4).  sm_solve (post/solve.c) adds labels, tracking,
 * critical and divergence speeds on top; nothing here calls post/.
 */
#include "linsys.h"

#include <complex.h>
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

/* 1 when component c of a nodal vector with dof values per node is a translation. */
static int sweep_translation(int c, int dof)
{
    return dof == 6 ? c % 6 < 3 : c % 3 != 2;
}

/* Nodal shapes (the kind's node_dof values per node, hub frame) of the modes in e at the
 * linearisation in L; largest translation = 1. */
static void sweep_shapes(const sm_model *m, smi_lin *L, const sm_eig_out *e, double *sr, double *si)
{
    int n = m->n, nn = m->n_nodes, dof = m->kind->node_dof;
    for (int j = 0; j < e->n_modes; j++) {
        const double *xr = e->xre + (size_t)j * n, *xi = e->xim + (size_t)j * n;
        double *yr = sr + (size_t)j * dof * nn, *yi = si + (size_t)j * dof * nn;
        smi_lin_nodal(m, L, xr, xi, yr, yi);
        double best = -1;
        double complex piv = 1;
        for (int c = 0; c < dof * nn; c++)
            if (sweep_translation(c, dof) && hypot(yr[c], yi[c]) > best) {
                best = hypot(yr[c], yi[c]);
                piv = yr[c] + _Complex_I * yi[c];
            }
        if (!(best > 0))
            continue;
        for (int c = 0; c < dof * nn; c++) {
            double complex v = (yr[c] + _Complex_I * yi[c]) / piv;
            yr[c] = creal(v);
            yi[c] = cimag(v);
        }
    }
}

/* Fill equilibrium outputs of case c at q (kinematics of q in L). */
static int sweep_equilibrium_out(const sm_model *m, const double *q, smi_lin *L, sm_case *c)
{
    c->n_nodes = m->n_nodes;
    c->node_dof = m->kind->node_dof;
    c->n_elements = m->n_elems;
    c->nodes = dm_vec((size_t)c->node_dof * m->n_nodes);
    c->axial_force = dm_vec((size_t)m->n_elems);
    if (!c->nodes || !c->axial_force)
        return SM_NOMEM;
    lin_axial_forces(m, q, c->axial_force);
    int at = -1;
    double rot = smi_lin_nodes(m, L, c->nodes, &at); /* rotation relative to the own frame */
    c->max_frame_rotation = rot;
    c->warning[0] = '\0';
    if (c->converged && rot > SM_FRAME_ROTATION_LIMIT)
        snprintf(c->warning, sizeof c->warning,
                 "FE node %d turns %.2f rad relative to its frame (limit %.1f rad for the linear kinematics "
                 "inside a frame): the steady state and frequencies are those of the model, not of the "
                 "structure; use more frames",
                 at, rot, SM_FRAME_ROTATION_LIMIT);
    return SM_OK;
}

/*
 * The eigen-analysis failed (status rc) at the converged equilibrium of case
 * c: the case keeps its equilibrium fields and reports the cause.  finite: 0
 * when the linearised matrices had non-finite entries.  Returns SM_OK, or rc
 * when the failure is fatal to the whole solve (SM_NOMEM) or a stop (SM_CANCELED).
 */
static int sweep_eigen_failed(sm_case *c, int rc, int finite)
{
    if (rc == SM_NOMEM || rc == SM_CANCELED) /* a stop asked during the Arnoldi iteration */
        return rc;
    c->status = SM_CASE_EIGEN_FAILED;
    if (rc == SM_LIMIT) /* sweep_eigen wrote the reason */
        return SM_OK;
    snprintf(c->message, sizeof c->message, "eigen-analysis failed at the converged equilibrium: %s%s",
             sm_strerror(rc),
             finite ? "" : " (K*, M* or C* has non-finite entries: the numbers overflow double precision)");
    return SM_OK;
}

/*
 * Linearisation and eigen-analysis at q into e, with the path of L; the tree path
 * falls back to the dense one (allocated here into *D, *use pointing at it) when
 * the tree eigen-analysis asks for it.  *finite: 0 when the matrices have non-finite entries.
 * Returns the status of the eigen-analysis (SM_NOMEM also for the fallback's allocation).
 */
static int sweep_eigen(const sm_model *m, const double *q, smi_lin *L, smi_lin **D, smi_lin **use,
                       const sm_progress *pr, sm_case *c, sm_eig_out *e, int *finite)
{
    int rc, fallback = 1;
    double t0 = sweep_ms(), t1;
    *use = L;
    *finite = 1;
    memset(e, 0, sizeof *e);
    if (smi_lin_is_tree(L)) {
        int fin = smi_lin_linearize(m, q, c->omega, L);
        t1 = sweep_ms();
        c->t_linearize = t1 - t0;
        if (fin && (rc = smi_lin_eigen(m, L, pr, e, &fallback)) < 0)
            return rc;
        c->t_eigen = sweep_ms() - t1;
        if (!fallback)
            return SM_OK;
        int dmax = m->opt.max_dense_coordinates > 0 ? m->opt.max_dense_coordinates : SM_DENSE_MAX_DEFAULT;
        if (m->n > dmax) { /* the dense path would take minutes and gigabytes */
            if (smi_lin_negative(L) > 0)
                snprintf(c->message, sizeof c->message,
                         "the steady state is unstable: K* has %d negative eigenvalues (structured "
                         "factorisation); the modes of an unstable state are found by the dense "
                         "eigen-analysis, which is limited to %d coordinates (this model has %d)",
                         smi_lin_negative(L), dmax, m->n);
            else
                snprintf(c->message, sizeof c->message,
                         "the structured eigen-analysis cannot give these modes (K* singular, too few "
                         "coordinates for the modes asked, or no convergence: many equal frequencies), "
                         "and the dense one is "
                         "limited to %d coordinates (this model has %d)",
                         dmax, m->n);
            return SM_LIMIT;
        }
        if ((rc = smi_lin_new(m, SMI_USE_MODES, 0, D)) < 0) /* the dense path decides */
            return rc;
        *use = *D;
        c->dense_fallback = 1;
        t0 = sweep_ms();
    }
    smi_lin_linearize(m, q, c->omega, *use);
    t1 = sweep_ms();
    rc = smi_lin_eigen(m, *use, pr, e, &fallback);
    c->t_linearize += t1 - t0;
    c->t_eigen += sweep_ms() - t1;
    if (rc < 0)
        *finite = smi_lin_finite(*use);
    return rc;
}

/* Modes of case c at the equilibrium q; pr: the stop callback the tree path asks every few
 * Krylov vectors.  An eigen-analysis failure is reported on the case (sweep_eigen_failed); returns
 * SM_OK, SM_NOMEM or SM_CANCELED. */
static int sweep_modes(const sm_model *m, const double *q, smi_lin *L, const sm_progress *pr, sm_case *c)
{
    sm_eig_out e;
    smi_lin *D = NULL, *use = L;
    int finite = 1;
    int rc = sweep_eigen(m, q, L, &D, &use, pr, c, &e, &finite);
    if (rc < 0) {
        smi_lin_free(D);
        return sweep_eigen_failed(c, rc, finite);
    }
    int k = e.n_modes, nn = m->n_nodes * m->kind->node_dof;
    c->n_modes = k;
    c->frequency = dm_vec((size_t)k);
    c->eig_re = dm_vec((size_t)k);
    c->eig_im = dm_vec((size_t)k);
    c->mac_to_previous = dm_vec((size_t)k);
    c->previous_index = calloc((size_t)(k ? k : 1), sizeof(int));
    c->shape_re = dm_vec((size_t)k * nn);
    c->shape_im = dm_vec((size_t)k * nn);
    if (!c->frequency || !c->eig_re || !c->eig_im || !c->mac_to_previous || !c->previous_index ||
        !c->shape_re || !c->shape_im) {
        eig_out_free(&e);
        smi_lin_free(D);
        return SM_NOMEM;
    }
    for (int j = 0; j < k; j++) {
        c->eig_re[j] = e.wre[j];
        c->eig_im[j] = e.wim[j];
        c->frequency[j] = fabs(e.wim[j]);
    }
    sweep_shapes(m, use, &e, c->shape_re, c->shape_im);
    c->negative_eigenvalues = e.negative;
    c->max_real_part = e.max_re;
    double scale = k ? hypot(e.wre[k - 1], e.wim[k - 1]) : 1;
    c->stable = e.negative == 0 && !(e.max_re > 1e-8 * fmax(scale, 1e-3));
    c->status = c->stable ? SM_CASE_SOLVED : SM_CASE_UNSTABLE;
    if (!c->stable && e.negative > 0)
        snprintf(c->message, sizeof c->message,
                 "equilibrium found, unstable: K* has %d negative eigenvalue%s (a static divergence: "
                 "the steady state exists but a disturbance grows away from it)",
                 e.negative, e.negative == 1 ? "" : "s");
    else if (!c->stable)
        snprintf(c->message, sizeof c->message,
                 "equilibrium found, unstable: a root has a positive real part %.3g (a dynamic "
                 "instability)", e.max_re);
    eig_out_free(&e);
    smi_lin_free(D);
    return SM_OK;
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

/* Every speed of omegas: equilibrium, modes and nodal shapes (kept), no tracking. */
int sweep_run(const sm_model *m, const double *omegas, int n_omegas, sm_progress_fn cb, void *user,
                     sm_result **out, sm_diag *diag)
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
    if (!r || !key || !q)
        goto fail;
    r->cases = calloc((size_t)n_omegas, sizeof(sm_case));
    if (!r->cases)
        goto fail;
    r->n_cases = n_omegas;
    if ((rc = smi_lin_new(m, SMI_USE_MODES, tree_use(m), &L)) < 0)
        goto fail;
    for (int i = 0; i < n_omegas; i++) {
        key[i].omega = omegas[i];
        key[i].index = i;
        r->cases[i].omega = omegas[i];
    }
    qsort(key, (size_t)n_omegas, sizeof *key, sweep_key_cmp);
    sm_progress pr = {cb, user, 0, n_omegas};
    double s_prev = 0;
    int from_rest = 1;
    for (int t = 0; t < n_omegas; t++) {
        sm_case *c = &r->cases[key[t].index];
        double s = smi_load(m, c->omega), t0 = sweep_ms();
        sm_eq_out eo;
        if (from_rest) {
            memset(q, 0, (size_t)n * sizeof(double));
            s_prev = 0;
        }
        rc = eq_solve(m, q, s_prev, s, from_rest, &pr, &eo);
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
        smi_lin_eval(m, q, L);
        if ((rc = sweep_equilibrium_out(m, q, L, c)) < 0)
            goto fail;
        if (!eo.converged) {
            c->status = SM_CASE_NO_EQUILIBRIUM;
            snprintf(c->message, sizeof c->message, "%s", eo.message);
            from_rest = 1;
        } else {
            if ((rc = sweep_modes(m, q, L, &pr, c)) < 0)
                goto fail;
            s_prev = s; /* tracking (track.c) runs once every speed is solved */
            from_rest = 0;
        }
        pr.done = t + 1;
        /* after the last speed a stop request leaves the finished cases alone */
        if (cb && cb(user, pr.done, pr.total) && pr.done < pr.total) {
            rc = SM_CANCELED;
            goto fail;
        }
    }
    smi_lin_free(L);
    free(key);
    free(q);
    *out = r;
    return SM_OK;
fail:
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
    if ((rc = eq_solve(m, q, 0, smi_load(m, omega), 1, &pr, &eo)) < 0)
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
