/*
 * sweep.c — sm_solve: speeds in ascending order with continuation
 * (equilibrium.c), linearisation at each equilibrium (M*, C*, K* with P
 * frozen), the eigen-analysis (eigen.c), mode shapes in the hub frame and
 * mode tracking across speeds by MAC (DESIGN.md 1.3-1.4).
 */
#include "spatial.h"

#include <complex.h>
#include <lapacke.h>
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
        free(c->tracked_index);
        free(c->track_flag);
        free(c->track_partner);
    }
    free(r->cases);
    free(r->critical);
    free(r->divergence);
    free(r);
}

/* Linearised matrices at q: M*, C* (coriolis), K* = K + Kg(P frozen) - s (M* + H): dense n x n,
 * or (tree != 0) the local blocks of tree.c with light kinematics (O(n) memory). */
typedef struct sweep_lin {
    int tree;           /* 1: tree form (t, light kin); 0: dense matrices */
    sm_kin kin;         /* planar kinematics */
    sp_kin sk;          /* spatial kinematics with J, W (m->spatial) */
    dmat M, C, K, H, W, X; /* spatial: W is n x 6P scratch, X unused */
    double *work;
    tree_ws t;
} sweep_lin;

static void sweep_lin_free(sweep_lin *L)
{
    frames_kin_free(&L->kin);
    sp_kin_free(&L->sk);
    dm_free(&L->M);
    dm_free(&L->C);
    dm_free(&L->K);
    dm_free(&L->H);
    dm_free(&L->W);
    dm_free(&L->X);
    free(L->work);
    tree_free(&L->t);
}

static int sweep_lin_alloc(const sm_model *m, sweep_lin *L, int tree)
{
    int n = m->n, mx = 1;
    memset(L, 0, sizeof *L);
    L->tree = tree;
    for (int s = 0; s < m->n_subs; s++)
        mx = m->subs[s].m > mx ? m->subs[s].m : mx;
    L->work = dm_vec((size_t)(12 * mx + n));
    if (m->spatial && tree) {
        if (!L->work || sp_kin_alloc(m, &L->sk, 0) || tree_alloc(m, &L->t)) {
            sweep_lin_free(L);
            return SM_NOMEM;
        }
        return SM_OK;
    }
    if (m->spatial) {
        if (!L->work || sp_kin_alloc(m, &L->sk, 1) || dm_alloc(&L->M, n, n) || dm_alloc(&L->C, n, n) ||
            dm_alloc(&L->K, n, n) || dm_alloc(&L->H, n, n) || dm_alloc(&L->W, n, 6 * m->n_pt)) {
            sweep_lin_free(L);
            return SM_NOMEM;
        }
        return SM_OK;
    }
    if (tree) {
        if (!L->work || frames_kin_alloc_light(m, &L->kin) || tree_alloc(m, &L->t)) {
            sweep_lin_free(L);
            return SM_NOMEM;
        }
        return SM_OK;
    }
    if (!L->work || frames_kin_alloc(m, &L->kin) || dm_alloc(&L->M, n, n) || dm_alloc(&L->C, n, n) ||
        dm_alloc(&L->K, n, n) || dm_alloc(&L->H, n, n) || dm_alloc(&L->W, n, 2 * m->n_mp) ||
        dm_alloc(&L->X, n, n)) {
        sweep_lin_free(L);
        return SM_NOMEM;
    }
    return SM_OK;
}

/* Linearise at q; returns 1 when the tree blocks are finite (always 1 for the dense form,
 * whose finiteness sweep_eigen_failed checks). */
static int sweep_linearize(const sm_model *m, const double *q, double omega, sweep_lin *L)
{
    int n = m->n;
    double s = omega * omega;
    if (m->spatial && L->tree) /* K*, P frozen; M*; C* in the local blocks of tree3.c */
        return tree3_assemble(m, q, &L->sk, s, 1, 1, m->opt.coriolis, &L->t);
    if (m->spatial) { /* K*, P frozen; M*; C* (DESIGN.md 7.3) */
        sp_eval(m, q, &L->sk);
        lin3_tangent(m, q, &L->sk, s, 1, &L->K, &L->H, L->work);
        lin3_mass(m, &L->sk, &L->M, &L->W);
        if (m->opt.coriolis)
            lin3_gyro(m, &L->sk, omega, &L->C, &L->W);
    } else {
        frames_eval(m, q, &L->kin);
    }
    if (L->tree)
        return tree_assemble(m, q, &L->kin, s, 1, m->opt.coriolis, &L->t); /* K*, P frozen; M*; C* */
    if (!m->spatial) {
        lin_tangent(m, q, &L->kin, s, 1, &L->K, &L->M, &L->H, &L->W, L->work); /* K*, P frozen; M* */
        if (m->opt.coriolis)
            lin_gyro(m, &L->kin, omega, &L->C, &L->W, &L->X);
    }
    for (int j = 0; j < n; j++) /* symmetric up to round-off: make it exact */
        for (int i = 0; i < j; i++)
            DM(&L->K, i, j) = DM(&L->K, j, i) = 0.5 * (DM(&L->K, i, j) + DM(&L->K, j, i));
    return 1;
}

/* Values per node in nodes and shapes: 3 planar (x, y, phi), 6 spatial (x, y, z, rx, ry, rz). */
static int sweep_dof(const sm_model *m)
{
    return m->spatial ? 6 : 3;
}

/* 1 when component c of a nodal vector with dof values per node is a translation. */
static int sweep_translation(int c, int dof)
{
    return dof == 6 ? c % 6 < 3 : c % 3 != 2;
}

/* Nodal shapes (dx, dy, dphi) = J_k x in the hub frame (spatial: dx..dz, rx..rz); largest
 * translation = 1. */
static void sweep_shapes(const sm_model *m, sweep_lin *L, const sm_eig_out *e, double *sr, double *si)
{
    int n = m->n, nn = m->n_nodes, dof = sweep_dof(m);
    const sm_kin *k = &L->kin;
    for (int j = 0; j < e->n_modes; j++) {
        const double *xr = e->xre + (size_t)j * n, *xi = e->xim + (size_t)j * n;
        double *yr = sr + (size_t)j * dof * nn, *yi = si + (size_t)j * dof * nn;
        if (m->spatial && L->tree) {
            tree3_nodal(m, &L->sk, &L->t, xr, yr);
            tree3_nodal(m, &L->sk, &L->t, xi, yi);
        } else if (m->spatial) {
            lin3_nodal(m, &L->sk, xr, yr);
            lin3_nodal(m, &L->sk, xi, yi);
        } else if (L->tree) {
            tree_nodal(m, k, &L->t, xr, yr);
            tree_nodal(m, k, &L->t, xi, yi);
        } else {
            for (int c = 0; c < 3 * nn; c++) {
                const double *jc = &DM(&k->Jn, 0, c);
                double a = 0, b = 0;
                for (int i = 0; i < n; i++) {
                    a += jc[i] * xr[i];
                    b += jc[i] * xi[i];
                }
                yr[c] = a;
                yi[c] = b;
            }
        }
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
static int sweep_equilibrium_out(const sm_model *m, const double *q, sweep_lin *L, sm_case *c)
{
    const sm_kin *k = &L->kin;
    c->n_nodes = m->n_nodes;
    c->node_dof = sweep_dof(m);
    c->n_elements = m->n_elems;
    c->nodes = dm_vec((size_t)c->node_dof * m->n_nodes);
    c->axial_force = dm_vec((size_t)m->n_elems);
    if (!c->nodes || !c->axial_force)
        return SM_NOMEM;
    lin_axial_forces(m, q, c->axial_force);
    double rot = 0;
    int at = -1;
    if (m->spatial)
        rot = lin3_nodes(m, &L->sk, c->nodes, &at); /* |psi|: rotation relative to the own frame */
    else
        memcpy(c->nodes, k->rn, 3 * (size_t)m->n_nodes * sizeof(double));
    /* rotation of each node relative to its frame: phi_k - (theta_s - theta0_s) */
    for (int s = 0; !m->spatial && s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        for (int i = 0; i < b->nfree; i++) {
            double p = k->rn[3 * b->free_nodes[i] + 2] - (k->theta[s] - b->theta0);
            if (fabs(p) > rot) {
                rot = fabs(p);
                at = b->free_nodes[i];
            }
        }
    }
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
 * Linearisation and eigen-analysis at q into e, with the form of L; the tree form
 * falls back to the dense one (allocated here into *D, *use pointing at it) when
 * eig_solve_tree asks for it.  *finite: 0 when the matrices have non-finite entries.
 * Returns the status of the eigen-analysis (SM_NOMEM also for the fallback's allocation).
 */
static int sweep_eigen(const sm_model *m, const double *q, sweep_lin *L, sweep_lin *D, sweep_lin **use,
                       const sm_progress *pr, sm_case *c, sm_eig_out *e, int *finite)
{
    int rc, fallback = 1;
    double t0 = sweep_ms(), t1;
    *use = L;
    *finite = 1;
    memset(e, 0, sizeof *e);
    if (L->tree) {
        int fin = sweep_linearize(m, q, c->omega, L);
        t1 = sweep_ms();
        c->t_linearize = t1 - t0;
        if (fin && (rc = eig_solve_tree(m, &L->t, m->opt.coriolis, m->opt.modes, pr, e, &fallback)) < 0)
            return rc;
        c->t_eigen = sweep_ms() - t1;
        if (!fallback)
            return SM_OK;
        int dmax = m->opt.max_dense_coordinates > 0 ? m->opt.max_dense_coordinates : SM_DENSE_MAX_DEFAULT;
        if (m->n > dmax) { /* the dense path would take minutes and gigabytes */
            if (L->t.neg > 0)
                snprintf(c->message, sizeof c->message,
                         "the steady state is unstable: K* has %d negative eigenvalues (structured "
                         "factorisation); the modes of an unstable state are found by the dense "
                         "eigen-analysis, which is limited to %d coordinates (this model has %d)",
                         L->t.neg, dmax, m->n);
            else
                snprintf(c->message, sizeof c->message,
                         "the structured eigen-analysis cannot give these modes (K* singular, too few "
                         "coordinates for the modes asked, or no convergence: many equal frequencies), "
                         "and the dense one is "
                         "limited to %d coordinates (this model has %d)",
                         dmax, m->n);
            return SM_LIMIT;
        }
        if ((rc = sweep_lin_alloc(m, D, 0)) < 0) /* the dense path decides */
            return rc;
        *use = D;
        c->dense_fallback = 1;
        t0 = sweep_ms();
    }
    sweep_linearize(m, q, c->omega, *use);
    t1 = sweep_ms();
    rc = eig_solve(m->n, &(*use)->M, &(*use)->C, &(*use)->K, m->opt.coriolis, m->opt.modes, e);
    c->t_linearize += t1 - t0;
    c->t_eigen += sweep_ms() - t1;
    if (rc < 0)
        *finite = dm_finite(&(*use)->K) && dm_finite(&(*use)->M) && dm_finite(&(*use)->C);
    return rc;
}

/* Modes of case c at the equilibrium q; pr: the stop callback the tree path asks every few
 * Krylov vectors.  An eigen-analysis failure is reported on the case (sweep_eigen_failed); returns
 * SM_OK, SM_NOMEM or SM_CANCELED. */
static int sweep_modes(const sm_model *m, const double *q, sweep_lin *L, const sm_progress *pr, sm_case *c)
{
    sm_eig_out e;
    sweep_lin D, *use = L;
    int finite = 1;
    memset(&D, 0, sizeof D);
    int rc = sweep_eigen(m, q, L, &D, &use, pr, c, &e, &finite);
    if (rc < 0) {
        sweep_lin_free(&D);
        return sweep_eigen_failed(c, rc, finite);
    }
    int k = e.n_modes, nn = m->n_nodes * sweep_dof(m);
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
        sweep_lin_free(&D);
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
    sweep_lin_free(&D);
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
static int sweep_order(const double *omegas, int n, int *ord)
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
static int sweep_run(const sm_model *m, const double *omegas, int n_omegas, sm_progress_fn cb, void *user,
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
    int rc = SM_NOMEM, n = m->n;
    sm_result *r = calloc(1, sizeof *r);
    sweep_key *key = malloc((size_t)n_omegas * sizeof *key);
    double *q = dm_vec((size_t)n);
    sweep_lin L;
    int have_lin = 0;
    if (!r || !key || !q)
        goto fail;
    r->cases = calloc((size_t)n_omegas, sizeof(sm_case));
    if (!r->cases)
        goto fail;
    r->n_cases = n_omegas;
    if ((rc = sweep_lin_alloc(m, &L, tree_use(m))) < 0)
        goto fail;
    have_lin = 1;
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
        double s = c->omega * c->omega, t0 = sweep_ms();
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
        if (m->spatial)
            sp_eval(m, q, &L.sk);
        else
            frames_eval(m, q, &L.kin);
        if ((rc = sweep_equilibrium_out(m, q, &L, c)) < 0)
            goto fail;
        if (!eo.converged) {
            c->status = SM_CASE_NO_EQUILIBRIUM;
            snprintf(c->message, sizeof c->message, "%s", eo.message);
            from_rest = 1;
        } else {
            if ((rc = sweep_modes(m, q, &L, &pr, c)) < 0)
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
    sweep_lin_free(&L);
    free(key);
    free(q);
    *out = r;
    return SM_OK;
fail:
    if (have_lin)
        sweep_lin_free(&L);
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
    int n = m->n, rc, found = 0;
    double *q = dm_vec((size_t)n), *w = dm_vec((size_t)n), vl = 0, vu = 0;
    int *ifail = calloc((size_t)n, sizeof(int));
    sm_progress pr = {cb, user, 0, 1};
    sm_eq_out eo;
    sweep_lin D;
    memset(&D, 0, sizeof D);
    *lambda = NAN;
    rc = SM_NOMEM;
    if (!q || !w || !ifail)
        goto done;
    if ((rc = eq_solve(m, q, 0, omega * omega, 1, &pr, &eo)) < 0)
        goto done;
    rc = eo.canceled ? SM_CANCELED : SM_NO_EQUILIBRIUM;
    if (!eo.converged)
        goto done;
    if ((rc = sweep_lin_alloc(m, &D, 0)) < 0)
        goto done;
    sweep_linearize(m, q, omega, &D);
    /* the lowest eigenvalue of the symmetric K* (its sign change is that of det K*) */
    rc = dm_lapack_status(LAPACKE_dsyevx(LAPACK_COL_MAJOR, 'N', 'I', 'L', n, D.K.a, n, vl, vu, 1, 1,
                                         0.0, &found, w, NULL, 1, ifail),
                          SM_LAPACK_FAILED);
    if (rc == SM_OK && found == 1)
        *lambda = w[0];
    else if (rc == SM_OK)
        rc = SM_LAPACK_FAILED;
done:
    sweep_lin_free(&D);
    free(q);
    free(w);
    free(ifail);
    return rc;
}

int sweep_single(const sm_model *m, double omega, sm_progress_fn cb, void *user, sm_result **out)
{
    int rc = sweep_run(m, &omega, 1, cb, user, out, NULL);
    if (rc == SM_OK && (rc = lab_case(m, &(*out)->cases[0])) < 0) {
        sm_result_free(*out);
        *out = NULL;
    }
    return rc;
}

/* DESIGN.md 9.1 on a solved sweep: labels, tracking, critical speeds (shapes still present). */
static int sweep_trust(const sm_model *m, sm_result *r, const double *omegas, int n, sm_progress_fn cb,
                       void *user)
{
    int *ord = malloc((size_t)(n ? n : 1) * sizeof(int)), rc = SM_NOMEM;
    if (!ord || sweep_order(omegas, n, ord) < 0)
        goto done;
    for (int i = 0; i < n; i++)
        if ((rc = lab_case(m, &r->cases[i])) < 0)
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
    int rc = sweep_run(m, omegas, n_omegas, cb, user, &r, diag);
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
