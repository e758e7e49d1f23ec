/*
 * linsys.c — the linearised system at a state, dense or tree (linsys.h).
 *
 * How it fits: equilibrium.c (Newton tangent, solves, determinant sign) and sweep.c (K*, M*,
 * C*, eigen-analysis, shapes) call these functions; each one does the path's part here
 * (LAPACK factorisation, the tree factorisation of tree.c, eig_solve or eig_solve_tree) and
 * the kind's part through m->kind (kind.h).  The only branch on the path is L->tree.
 */
#include "linsys.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

struct smi_lin {
    const smi_kind *kind;
    int use;   /* SMI_USE_NEWTON | SMI_USE_MODES */
    int tree;  /* 1: tree form (t, light kinematics); 0: dense matrices */
    void *kin; /* the kind's kinematics workspace */
    tree_ws t;
    smi_dense D;
    int *ipiv;    /* LU pivots of the dense Newton tangent */
    double *work; /* 12 max m_s + n doubles */
};

void smi_dense_free(smi_dense *D)
{
    dm_free(&D->K);
    dm_free(&D->M);
    dm_free(&D->C);
    dm_free(&D->H);
    dm_free(&D->W);
    dm_free(&D->X);
}

void smi_lin_free(smi_lin *L)
{
    if (!L)
        return;
    L->kind->kin_free(L->kin);
    tree_free(&L->t);
    smi_dense_free(&L->D);
    free(L->ipiv);
    free(L->work);
    free(L);
}

int smi_lin_new(const sm_model *m, int use, int tree, smi_lin **out)
{
    smi_lin *L = calloc(1, sizeof *L);
    int mx = 1;

    *out = NULL;
    if (!L)
        return SM_NOMEM;
    L->kind = m->kind;
    L->use = use;
    L->tree = tree;
    for (int s = 0; s < m->n_subs; s++)
        mx = m->subs[s].m > mx ? m->subs[s].m : mx;
    L->work = dm_vec((size_t)(12 * mx + m->n));
    L->kin = m->kind->kin_new(m, tree ? SMI_USE_TREE : use);
    if (!L->work || !L->kin)
        goto fail;
    if (tree) {
        if (tree_alloc(m, &L->t) != SM_OK)
            goto fail;
    } else {
        if (m->kind->dense_alloc(m, use, &L->D) != SM_OK)
            goto fail;
        if (use == SMI_USE_NEWTON && !(L->ipiv = malloc((size_t)(m->n ? m->n : 1) * sizeof(int))))
            goto fail;
    }
    *out = L;
    return SM_OK;
fail:
    smi_lin_free(L);
    return SM_NOMEM;
}

int smi_lin_is_tree(const smi_lin *L)
{
    return L->tree;
}

void smi_lin_centrifugal(const sm_model *m, const double *q, smi_lin *L, double *g)
{
    L->kind->centrifugal(m, q, L->kin, L->tree ? &L->t : NULL, g);
}

int smi_lin_tangent(const sm_model *m, const double *q, double s, smi_lin *L)
{
    int n = m->n;

    if (L->tree) {
        L->kind->tree_assemble(m, q, L->kin, s, 0, 0, &L->t);
        return tree_factor(m, &L->t, 0);
    }
    L->kind->dense_tangent(m, q, L->kin, s, &L->D, L->work);
    return dm_lapack_status(LAPACKE_dgetrf_work(LAPACK_COL_MAJOR, n, n, L->D.K.a, n, L->ipiv),
                            SM_SINGULAR);
}

int smi_lin_solve(const sm_model *m, smi_lin *L, double *x)
{
    int n = m->n;

    if (L->tree)
        return tree_solve(m, &L->t, x);
    return dm_lapack_status(
        LAPACKE_dgetrs_work(LAPACK_COL_MAJOR, 'N', n, 1, L->D.K.a, n, L->ipiv, x, n),
        SM_LAPACK_FAILED);
}

int smi_lin_det_sign(const sm_model *m, const smi_lin *L)
{
    int n = m->n, sign = 1;

    if (L->tree)
        return L->t.det_sign;
    for (int i = 0; i < n; i++) {
        if (L->D.K.a[(size_t)i * n + i] < 0)
            sign = -sign;
        if (L->ipiv[i] != i + 1)
            sign = -sign;
    }
    return sign;
}

void smi_lin_eval(const sm_model *m, const double *q, smi_lin *L)
{
    L->kind->kin_eval(m, q, L->kin);
}

double smi_lin_nodes(const sm_model *m, smi_lin *L, double *nodes, int *at)
{
    return L->kind->nodes(m, L->kin, nodes, at);
}

int smi_lin_linearize(const sm_model *m, const double *q, double omega, smi_lin *L)
{
    int n = m->n;

    if (L->tree) /* K*, P frozen; M*; C* in the local blocks */
        return L->kind->tree_assemble(m, q, L->kin, omega * omega, 1, m->opt.coriolis, &L->t);
    L->kind->dense_linearize(m, q, L->kin, omega, m->opt.coriolis, &L->D, L->work);
    for (size_t i = 0; m->has_supports && i < (size_t)n * (size_t)n; i++)
        L->D.M.a[i] += m->sup_M.a[i]; /* the supports' added mass (supports.c) */
    for (int j = 0; j < n; j++) /* symmetric up to round-off: make it exact */
        for (int i = 0; i < j; i++)
            DM(&L->D.K, i, j) = DM(&L->D.K, j, i) = 0.5 * (DM(&L->D.K, i, j) + DM(&L->D.K, j, i));
    return 1;
}

int smi_lin_finite(const smi_lin *L)
{
    return L->tree || (dm_finite(&L->D.K) && dm_finite(&L->D.M) && dm_finite(&L->D.C));
}

/*
 * A free base at rest (DESIGN.md 8.7): C* = 0, and K* may be singular — a floating structure
 * free in a direction has rigid-body modes at zero frequency.  The undamped problem is solved
 * as (K* + sigma M*) x = w_s^2 M* x (definite: a rigid-body direction's zero is exact, the
 * elastic terms have no base rows), sigma = 1e-8 s with s = tr K* over tr M*, and w^2 = w_s^2 -
 * sigma; |w^2| within 1e-6 sigma (the inverse form's round-off near sigma is ~eps sigma) is 0, a
 * rigid-body mode; below that a negative w^2 is a divergence (Re lambda = sqrt(-w^2), counted
 * negative).
 */
static int smi_lin_eigen_base(const sm_model *m, smi_lin *L, sm_eig_out *e)
{
    int n = m->n, rc;
    double tk = 0, tm = 0;

    for (int i = 0; i < n; i++) {
        tk += fabs(DM(&L->D.K, i, i));
        tm += fabs(DM(&L->D.M, i, i));
    }
    double scale = tm > 0 && tk > 0 ? tk / tm : 1.0, sigma = 1e-8 * scale;
    for (size_t i = 0; i < (size_t)n * (size_t)n; i++)
        L->D.K.a[i] += sigma * L->D.M.a[i];
    rc = eig_solve(n, &L->D.M, &L->D.C, &L->D.K, 0, m->opt.modes, m->kind->fixed_bits, e);
    if (rc < 0)
        return rc;
    e->max_re = 0;
    for (int j = 0; j < e->n_modes; j++) {
        double w2 = e->wim[j] * e->wim[j] - e->wre[j] * e->wre[j] - sigma;
        e->wre[j] = e->wim[j] = 0;
        if (w2 > 1e-6 * sigma) {
            e->wim[j] = sqrt(w2);
        } else if (w2 < -1e-6 * sigma) {
            e->wre[j] = sqrt(-w2);
            e->negative++;
        }
        e->max_re = fmax(e->max_re, e->wre[j]);
    }
    return SM_OK;
}

int smi_lin_eigen(const sm_model *m, smi_lin *L, const sm_progress *pr, sm_eig_out *e,
                  int *fallback)
{
    if (m->base && !L->tree) {
        *fallback = 0;
        return smi_lin_eigen_base(m, L, e);
    }
    if (L->tree)
        return eig_solve_tree(m, &L->t, m->opt.coriolis, m->opt.modes, pr, e, fallback);
    *fallback = 0;
    return eig_solve(m->n, &L->D.M, &L->D.C, &L->D.K, m->opt.coriolis, m->opt.modes,
                     m->kind->fixed_bits, e);
}

void smi_lin_warm(smi_lin *L, int chain)
{
    if (L->tree)
        L->t.warm_next = chain;
}

int smi_lin_negative(const smi_lin *L)
{
    return L->tree ? L->t.neg : 0;
}

void smi_lin_nodal(const sm_model *m, smi_lin *L, const double *xr, const double *xi, double *yr,
                   double *yi)
{
    L->kind->nodal(m, L->kin, L->tree ? &L->t : NULL, xr, xi, yr, yi);
}

int smi_lin_lowest(const sm_model *m, smi_lin *L, double *lambda)
{
    *lambda = NAN;
    if (L->tree)
        return SM_NOMEM;
    /* the lowest eigenvalue of the symmetric K* (its sign change is that of det K*) */
    return dm_lapack_status(dm_sy_lowest(m->n, L->D.K.a, lambda), SM_LAPACK_FAILED);
}
