/*
 * sweep_case.c — one speed's case finished at its equilibrium: steady-state outputs, the
 * linearisation and eigen-analysis (dense, or the tree path with its dense fallback), the modes'
 * nodal shapes in the hub frame, the stability verdict (DESIGN.md 1.3-1.4).  sweep.c calls it
 * after each equilibrium of the continuation, or hands the case to a worker of sweep_pool.c
 * that calls it; it depends on the equilibrium and the model alone.
 */
#include "sweep_pool.h"

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
        snprintf(
            c->warning, sizeof c->warning,
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
    snprintf(c->message, sizeof c->message,
             "eigen-analysis failed at the converged equilibrium: %s%s", sm_strerror(rc),
             finite
                 ? ""
                 : " (K*, M* or C* has non-finite entries: the numbers overflow double precision)");
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
        int dmax =
            m->opt.max_dense_coordinates > 0 ? m->opt.max_dense_coordinates : SM_DENSE_MAX_DEFAULT;
        if (m->n > dmax) { /* the dense path would take minutes and gigabytes */
            if (smi_lin_negative(L) > 0)
                snprintf(c->message, sizeof c->message,
                         "the steady state is unstable: K* has %d negative eigenvalues (structured "
                         "factorisation); the modes of an unstable state are found by the dense "
                         "eigen-analysis, which is limited to %d coordinates (this model has %d)",
                         smi_lin_negative(L), dmax, m->n);
            else
                snprintf(
                    c->message, sizeof c->message,
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
static int sweep_modes(const sm_model *m, const double *q, smi_lin *L, const sm_progress *pr,
                       sm_case *c)
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
        snprintf(
            c->message, sizeof c->message,
            "equilibrium found, unstable: K* has %d negative eigenvalue%s (a static divergence: "
            "the steady state exists but a disturbance grows away from it)",
            e.negative, e.negative == 1 ? "" : "s");
    else if (!c->stable)
        snprintf(c->message, sizeof c->message,
                 "equilibrium found, unstable: a root has a positive real part %.3g (a dynamic "
                 "instability)",
                 e.max_re);
    eig_out_free(&e);
    smi_lin_free(D);
    return SM_OK;
}

int sweep_case_finish(const sm_model *m, const double *q, smi_lin *L, const sm_progress *pr,
                      sweep_case_fn after, sm_case *c)
{
    smi_lin_eval(m, q, L);
    int rc = sweep_equilibrium_out(m, q, L, c);
    if (rc < 0 || !c->converged)
        return rc;
    if ((rc = sweep_modes(m, q, L, pr, c)) < 0 || !after || c->n_modes <= 0)
        return rc;
    return after(m, c); /* on this thread: the labels of a sweep on threads are parallel too */
}
