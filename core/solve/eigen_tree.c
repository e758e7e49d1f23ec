/*
 * eigen_tree.c — the lowest modes of a large model in the tree-structured
 * form (tree.c): shift-invert Arnoldi at zero on the companion form with
 * O(n) operator applications, then the small projected quadratic problem
 * (DESIGN.md 1.4, "Large models").  The dense eigen-analysis is eigen.c;
 * eig_solve_tree falls back to it when K* is indefinite or Arnoldi stalls.  In a spatial sweep a
 * speed after the first of its chunk starts from the previous speed's modes (smi_lin_warm,
 * sweep_pool.h; DESIGN.md 2.1, solver 0.8.3).
 */
#include "internal.h"

#include <cblas.h>
#include <complex.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------ tree form: shift-invert Arnoldi (tree.c) */

/* Relative residual that accepts the modes; or, at the round-off floor of large models (the
 * solves with K* carry ~cond(K*) eps: residuals stall near 1e-10 at 768 elements), a residual
 * below EIG_TREE_FLOOR with frequencies that moved by less than EIG_TREE_STALL (relative) since
 * the previous, smaller basis (Ritz values of a Rayleigh-Ritz step only improve).  The largest
 * Krylov basis, and the basis sizes at which the projection is tried first and then every
 * EIG_TREE_STEP vectors. */
#define EIG_TREE_TOL 1e-11
#define EIG_TREE_FLOOR 1e-9
#define EIG_TREE_STALL 1e-10
/* Past EIG_TREE_LATE vectors (the strict tests met nothing: 3072 elements, where K* x itself
 * carries ~cond(K*) eps and the frequencies wander by ~2e-9 between bases), the noise-limited
 * acceptance: residual below 1e-7 and frequencies steady to 1e-8. */
#define EIG_TREE_LATE 48
/* Past EIG_TREE_LATE vectors, also (spatial models, solver 0.8.7): frequencies steady to
 * EIG_TREE_STALL with a residual below EIG_TREE_LATE_STEADY.  Many modes of a stiff blade reach
 * that and then lose it as the basis grows: 40 modes of a 250-element precone blade (EA 8.4e8) at
 * 20 rad/s had a residual of 2.0e-7 with frequencies steady to 6e-12 at 138 vectors, and from
 * there frequencies that flickered by 2.2e-7 between bases and residuals of 2e-4 up to the largest
 * basis (eigen_failed in 0.8.6; 1500 coordinates, beyond the dense path).  Where a basis met this
 * before one of the tests above, the modes are now that basis's (another basis than 0.8.6's). */
#define EIG_TREE_LATE_STEADY 1e-6
/* From ~40 modes on, the Ritz vectors of the highest modes stall at relative residuals of 1e-7 to
 * 3e-5 (their error lies along stiff directions that shift-invert at zero resolves last, and the
 * residual weighs it by K) while every frequency is steady to 1e-11: 48, 64 and 100 modes of a
 * 150-element spatial blade agree with the dense path within 2e-10 (test_tree3_solve; issue 23:
 * they fell back to the dense path: 7 s a speed there, 4 min at 666 elements).  When the largest
 * basis meets none of the tests above, its modes are accepted below EIG_TREE_SHAPE_FLOOR if the
 * frequencies are steady to EIG_TREE_STALL between the last two bases, instead of the dense path
 * (only there: what the other tests accept stays bit for bit as it was). */
#define EIG_TREE_SHAPE_FLOOR 1e-4
/* The residuals need not fall as the basis grows (spatial models, solver 0.8.7): 40 modes of a
 * 400-element precone blade at 20 rad/s (2400 coordinates) reached 2.0e-7 at 130 vectors, where
 * the frequencies had moved by 7e-10, and then rose to 2e-4 for two modes by the largest basis
 * (the Ritz vectors' error along the stiff directions grows with the basis), which failed the case
 * (eigen_failed; the dense path is limited to 1000 coordinates).  So from EIG_TREE_LATE vectors on,
 * the basis with the smallest residual is kept; when the largest basis meets no test above, its
 * modes are accepted if that residual is below EIG_TREE_BEST_FLOOR and their frequencies agree
 * with the largest basis's to EIG_TREE_BEST_AGREE (relative): two bases vouch for the frequencies,
 * the better one gives the shapes.  The floor is above EIG_TREE_SHAPE_FLOOR because the worst
 * residuals are the torsion modes' (a translation error of 1e-8 weighs with the mass, ~3000 times
 * the polar inertia of their own inertia force: 1.2e-4 at best on the 400-element blade at
 * 30 rad/s).  The agreement checks that both bases hold the same modes (a mode missing from one
 * shifts the list by a whole gap); it is not the accuracy: the largest basis drifts, and its
 * highest mode asked was 1.1e-8 to 1.5e-7 from the kept basis's (600 elements at 30 rad/s; a
 * sweep at 250 elements with 10 EA and warm starts), while the kept bases' frequencies were within
 * 1e-10 of the dense path's over that sweep (17 to 22 rad/s).  Against the dense path on such cases
 * (1500 to 2400 coordinates): frequencies within 1.3e-8, shapes within 1.4e-5 (both the highest
 * mode asked).  Only where the other tests fail: what they accept stays as it was. */
#define EIG_TREE_BEST_AGREE 1e-6
#define EIG_TREE_BEST_FLOOR 1e-3
#define EIG_TREE_MAX_BASIS 240
#define EIG_TREE_STEP 8

/* A spatial model's solves stop being refined once a refinement has corrected the solution by
 * less than this (relative): 2e-15 typically, at most 9e-14 up to 800 elements (4800
 * coordinates), where a step costs one more solve and K product: 12 % of a sweep (issue 27). */
#define EIG_TREE_REFINE_SKIP 1e-13

/* A warm start (spatial models, smi_lin_warm): the Arnoldi start vector is the sum of the
 * previous speed's modes, each normalised, plus this fraction of the generic start, which keeps
 * every direction in the Krylov space (a mode that was not among the previous speed's lowest
 * costs a few more vectors: its start component is 1e-3 instead of O(1)).  On the 288-coordinate
 * blade, with the projections of a cold start, every warm speed was accepted at 24 vectors where
 * cold starts needed 32 at 10 of 21 speeds: -9 % instructions for 21 speeds, -11 % for 101
 * (issue 27, DESIGN.md 2.1). */
#define EIG_TREE_WARM_COLD 1e-3

/* ||x|| (n): a spatial model's plain sum of squares (no division per entry: dm_norm's scaling
 * was 4 % of a spatial sweep's eigen-analysis, issue 27), dm_norm where that sum leaves the
 * safe range or for a planar model, whose bits are fixed. */
static double eig_norm(int fixed_bits, const double *x, int n)
{
    if (fixed_bits)
        return dm_norm(x, n);
    double s = 0;
    for (int i = 0; i < n; i++)
        s += x[i] * x[i];
    return s > 1e-280 && s < 1e280 ? sqrt(s) : dm_norm(x, n);
}

/* w (n) = -K^-1 b for b = w on entry, with one step of iterative refinement: the block solve is
 * backward stable, but K* is graded (cond ~1e7 at 1536 elements) and the refined solution keeps
 * the Ritz frequencies steady to ~1e-12 instead of ~1e-9.  tmp: 2n scratch.  *refine: 1 while
 * the solves are refined (cleared here for a spatial model, see EIG_TREE_REFINE_SKIP). */
static int eig_tree_solve(const sm_model *m, tree_ws *t, double *w, double *tmp, int *refine)
{
    int n = m->n;
    double *b = tmp + n;
    memcpy(b, w, (size_t)n * sizeof(double));
    int rc = tree_solve(m, t, w);
    if (rc < 0 || !*refine)
        return rc;
    tree_apply(m, t, TREE_K, w, tmp);
    for (int i = 0; i < n; i++)
        tmp[i] = b[i] - tmp[i];
    if ((rc = tree_solve(m, t, tmp)) < 0)
        return rc;
    if (!t->fixed_bits && eig_norm(0, tmp, n) <= EIG_TREE_REFINE_SKIP * eig_norm(0, w, n))
        *refine = 0; /* planar models keep every refinement: their bytes are fixed (issue 27) */
    for (int i = 0; i < n; i++)
        w[i] += tmp[i];
    return SM_OK;
}

/* w (2n) = A v for A = [-K^-1 C, -K^-1 M; I, 0] (tree.c header); tmp: 2n scratch. */
static int eig_tree_op(const sm_model *m, tree_ws *t, int coriolis, const double *v, double *w,
                       double *tmp, int *refine)
{
    int n = m->n;
    tree_apply(m, t, TREE_M, v + n, w); /* w = M y */
    if (coriolis) {
        tree_apply(m, t, TREE_C, v, tmp);
        for (int i = 0; i < n; i++)
            w[i] += tmp[i];
    }
    for (int i = 0; i < n; i++)
        w[i] = -w[i];
    memcpy(w + n, v, (size_t)n * sizeof(double));
    return eig_tree_solve(m, t, w, tmp, refine);
}

/* w (2n) = A v as eig_tree_op, for a spatial model whose basis V (n x nv, orthonormal) holds the
 * x-part of v and, within 1e-10 of it (eig_tree_extend skips a dependent x-part), its y-part,
 * which is a combination of earlier x-parts: M y + C x from the products MV, CV with the
 * coordinates of y and x in V (cf: 2 nv), four products of n x nv instead of two operator
 * applications (a forward recursion, the local blocks and the adjoint each: 7 % of a spatial
 * sweep, issue 27). */
static int eig_tree_op_basis(const sm_model *m, tree_ws *t, int coriolis, int nv, const double *V,
                             const double *MV, const double *CV, const double *v, double *w,
                             double *tmp, double *cf, int *refine)
{
    int n = m->n;
    cblas_dgemv(CblasColMajor, CblasTrans, n, nv, 1.0, V, n, v + n, 1, 0.0, cf, 1);
    cblas_dgemv(CblasColMajor, CblasNoTrans, n, nv, -1.0, MV, n, cf, 1, 0.0, w, 1);
    if (coriolis) {
        cblas_dgemv(CblasColMajor, CblasTrans, n, nv, 1.0, V, n, v, 1, 0.0, cf + nv, 1);
        cblas_dgemv(CblasColMajor, CblasNoTrans, n, nv, -1.0, CV, n, cf + nv, 1, 1.0, w, 1);
    }
    memcpy(w + n, v, (size_t)n * sizeof(double));
    return eig_tree_solve(m, t, w, tmp, refine);
}

/* Orthogonalise w (len) against the nq columns of Q (ld len) twice (CGS2); returns ||w|| after. */
static double eig_cgs2(int fixed_bits, int len, int nq, const double *Q, double *w, double *h)
{
    for (int pass = 0; pass < 2 && nq > 0; pass++) {
        cblas_dgemv(CblasColMajor, CblasTrans, len, nq, 1.0, Q, len, w, 1, 0.0, h, 1);
        cblas_dgemv(CblasColMajor, CblasNoTrans, len, nq, -1.0, Q, len, h, 1, 1.0, w, 1);
    }
    return eig_norm(fixed_bits, w, len);
}

/* Relative residual of mode lambda = lr + i li from the products of its vector x with M, C, K
 * (s: Mr, Mi, Cr, Ci, Kr, Ki, n each; C zero without Coriolis). */
static double eig_residual_terms(int n, double lr, double li, const double *s)
{
    const double *Mr = s, *Mi = s + n, *Cr = s + 2 * n, *Ci = s + 3 * n, *Kr = s + 4 * n,
                 *Ki = s + 5 * n;
    double l2r = lr * lr - li * li, l2i = 2 * lr * li, rr = 0, nm = 0, nc = 0, nk = 0;
    for (int i = 0; i < n; i++) {
        double re = l2r * Mr[i] - l2i * Mi[i] + lr * Cr[i] - li * Ci[i] + Kr[i];
        double im = l2r * Mi[i] + l2i * Mr[i] + lr * Ci[i] + li * Cr[i] + Ki[i];
        rr += re * re + im * im;
        nm += Mr[i] * Mr[i] + Mi[i] * Mi[i];
        nc += Cr[i] * Cr[i] + Ci[i] * Ci[i];
        nk += Kr[i] * Kr[i] + Ki[i] * Ki[i];
    }
    double al = hypot(lr, li), den = al * al * sqrt(nm) + al * sqrt(nc) + sqrt(nk);
    return den > 0 ? sqrt(rr) / den : INFINITY;
}

/* Relative residual of mode (lambda, x = xr + i xi) of the quadratic problem; s: 6n scratch. */
static double eig_tree_residual(const sm_model *m, tree_ws *t, int coriolis, double lr, double li,
                                const double *xr, const double *xi, double *s)
{
    int n = m->n;
    double *Mr = s, *Mi = s + n, *Cr = s + 2 * n, *Ci = s + 3 * n, *Kr = s + 4 * n, *Ki = s + 5 * n;
    const int ops[3] = {TREE_M, TREE_K, TREE_C};
    double *const yr[3] = {Mr, Kr, Cr}, *const yi[3] = {Mi, Ki, Ci};
    tree_apply_n(m, t, coriolis ? 3 : 2, ops, xr, yr); /* one forward recursion a vector */
    tree_apply_n(m, t, coriolis ? 3 : 2, ops, xi, yi);
    if (!coriolis)
        memset(Cr, 0, 2 * (size_t)n * sizeof(double));
    return eig_residual_terms(n, lr, li, s);
}

/* The same for x = V (ar + i ai) from the basis products MV, CV, KV (n x nv): six products of
 * n x nv instead of six operator applications (spatial models, issue 27). */
static double eig_basis_residual(int n, int nv, int coriolis, const double *MV, const double *CV,
                                 const double *KV, double lr, double li, const double *ar,
                                 const double *ai, double *s)
{
    const double *P[3] = {MV, CV, KV};
    for (int k = 0; k < 3; k++) {
        if (k == 1 && !coriolis) {
            memset(s + 2 * (size_t)n, 0, 2 * (size_t)n * sizeof(double));
            continue;
        }
        cblas_dgemv(CblasColMajor, CblasNoTrans, n, nv, 1.0, P[k], n, ar, 1, 0.0,
                    s + 2 * (size_t)k * n, 1);
        cblas_dgemv(CblasColMajor, CblasNoTrans, n, nv, 1.0, P[k], n, ai, 1, 0.0,
                    s + (2 * (size_t)k + 1) * n, 1);
    }
    return eig_residual_terms(n, lr, li, s);
}

/*
 * The k lowest modes of the small gyroscopic problem (l^2 M + l C + K) a = 0 (nv x nv, K positive
 * definite) in the inverse companion form mu [a; l a] = [-K^-1 C, -K^-1 M; I, 0] [a; l a],
 * mu = 1/l, by dgeev: the wanted roots are the largest |mu|, resolved relative to themselves
 * (eig_solve resolved them relative to the highest frequency of the projected problem when this
 * was written; it has its own inverse form since, which spatial projections take: 4x cheaper.
 * Planar ones keep this one and their bytes, issue 27).
 * w: k frequencies (lambda = i w); a: nv x k complex vectors as ar, ai.  Returns SM_OK,
 * SM_NOMEM, SM_SINGULAR (K not positive definite, or fewer than k roots) or SM_LAPACK_FAILED.
 */
static int eig_gyro_inverse(int nv, const dmat *Mp, const dmat *Cp, const dmat *Kp, int k, double *w, double *ar,
                            double *ai)
{
    int N2 = 2 * nv, rc = SM_NOMEM, nr = 0;
    double *L = dm_vec((size_t)nv * nv), *T = dm_vec((size_t)nv * N2), *A = dm_vec((size_t)N2 * N2);
    double *wr = dm_vec((size_t)N2), *wi = dm_vec((size_t)N2), *VR = dm_vec((size_t)N2 * N2);
    eig_root *roots = calloc((size_t)N2, sizeof(eig_root));
    if (!L || !T || !A || !wr || !wi || !VR || !roots)
        goto done;
    memcpy(L, Kp->a, (size_t)nv * nv * sizeof(double));
    if ((rc = dm_lapack_status(LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', nv, L, nv), SM_SINGULAR)) < 0)
        goto done;
    memcpy(T, Cp->a, (size_t)nv * nv * sizeof(double)); /* T = K^-1 [C M] */
    memcpy(T + (size_t)nv * nv, Mp->a, (size_t)nv * nv * sizeof(double));
    if ((rc = dm_lapack_status(LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', nv, N2, L, nv, T, nv),
                               SM_LAPACK_FAILED)) < 0)
        goto done;
    for (int j = 0; j < N2; j++)
        for (int i = 0; i < nv; i++)
            A[(size_t)j * N2 + i] = -T[(size_t)j * nv + i];
    for (int i = 0; i < nv; i++)
        A[(size_t)i * N2 + nv + i] = 1.0;
    rc = dm_lapack_status(LAPACKE_dgeev(LAPACK_COL_MAJOR, 'N', 'V', N2, A, N2, wr, wi, NULL, 1, VR, N2),
                          SM_LAPACK_FAILED);
    if (rc < 0)
        goto done;
    for (int j = 0; j + 1 < N2; j++) /* conjugate pairs (mu, conj mu), Im mu > 0 first */
        if (wi[j] > 0) {
            double m2 = wr[j] * wr[j] + wi[j] * wi[j];
            roots[nr].re = 0;
            roots[nr].im = wi[j] / m2; /* lambda = 1 / conj(mu) = (wr + i wi) / |mu|^2 */
            roots[nr].key = -sqrt(m2);
            roots[nr].col = j;
            nr++;
            j++;
        }
    rc = SM_SINGULAR;
    if (nr < k)
        goto done;
    qsort(roots, (size_t)nr, sizeof *roots, eig_root_cmp);
    for (int t = 0; t < k; t++) {
        int j = roots[t].col;
        w[t] = roots[t].im;
        for (int i = 0; i < nv; i++) { /* eigenvector of conj(mu): VR_j - i VR_j+1 */
            ar[(size_t)t * nv + i] = VR[(size_t)j * N2 + i];
            ai[(size_t)t * nv + i] = -VR[(size_t)(j + 1) * N2 + i];
        }
    }
    rc = SM_OK;
done:
    free(L);
    free(T);
    free(A);
    free(wr);
    free(wi);
    free(VR);
    free(roots);
    return rc;
}

/* Extend V (n x *nv, orthonormal) by the x-parts of the Arnoldi vectors *done_x..p of Q (ld 2n),
 * orthonormalised, with their products MV, KV, CV (CV with Coriolis); an x-part within 1e-10 of
 * the basis adds nothing.  h: scratch of the basis size. */
static void eig_tree_extend(const sm_model *m, tree_ws *t, int coriolis, int p, const double *Q,
                            double *V, double *MV, double *KV, double *CV, double *h, int *nv,
                            int *done_x)
{
    int n = m->n;
    for (; *done_x <= p; (*done_x)++) {
        double *v = V + (size_t)*nv * n;
        memcpy(v, Q + (size_t)*done_x * 2 * n, (size_t)n * sizeof(double));
        double v0 = eig_norm(t->fixed_bits, v, n), vn = eig_cgs2(t->fixed_bits, n, *nv, V, v, h);
        if (!(vn > 1e-10 * v0))
            continue;
        for (int i = 0; i < n; i++)
            v[i] /= vn;
        /* one forward recursion for the three products (issue 27: -2 of 5 a vector) */
        const int ops[3] = {TREE_M, TREE_K, TREE_C};
        double *const ys[3] = {MV + (size_t)*nv * n, KV + (size_t)*nv * n, CV + (size_t)*nv * n};
        tree_apply_n(m, t, coriolis ? 3 : 2, ops, v, ys);
        (*nv)++;
    }
}

/* The projected problem on the nv orthonormal columns of V (n x nv, with MV, CV, KV = the
 * products): dense eig_solve, then x = V a into out and the largest residual into *res. */
static int eig_tree_project(const sm_model *m, tree_ws *t, int coriolis, int modes, int nv, const double *V,
                            const double *MV, const double *CV, const double *KV, double *scratch,
                            sm_eig_out *out, double *res)
{
    int n = m->n, rc;
    dmat Mp = {0}, Cp = {0}, Kp = {0};
    sm_eig_out e;
    memset(&e, 0, sizeof e);
    *res = INFINITY;
    if ((rc = dm_alloc(&Mp, nv, nv)) < 0 || (rc = dm_alloc(&Cp, nv, nv)) < 0 || (rc = dm_alloc(&Kp, nv, nv)) < 0)
        goto done;
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, nv, nv, n, 1.0, V, n, MV, n, 0.0, Mp.a, nv);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, nv, nv, n, 1.0, V, n, KV, n, 0.0, Kp.a, nv);
    if (coriolis)
        cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, nv, nv, n, 1.0, V, n, CV, n, 0.0, Cp.a, nv);
    for (int j = 0; j < nv; j++) /* exact symmetry / skew-symmetry */
        for (int i = 0; i < j; i++) {
            DM(&Mp, i, j) = DM(&Mp, j, i) = 0.5 * (DM(&Mp, i, j) + DM(&Mp, j, i));
            DM(&Kp, i, j) = DM(&Kp, j, i) = 0.5 * (DM(&Kp, i, j) + DM(&Kp, j, i));
            double c = 0.5 * (DM(&Cp, i, j) - DM(&Cp, j, i));
            DM(&Cp, i, j) = c;
            DM(&Cp, j, i) = -c;
        }
    for (int i = 0; i < nv; i++)
        DM(&Cp, i, i) = 0;
    if (coriolis && t->fixed_bits) {
        rc = eig_alloc_out(&e, nv, modes);
        if (rc == SM_OK)
            rc = eig_gyro_inverse(nv, &Mp, &Cp, &Kp, modes, e.wim, e.xre, e.xim);
        if (rc == SM_SINGULAR) { /* not yet (fewer roots than modes): *res stays infinite */
            rc = SM_OK;
            goto done;
        }
    } else {
        rc = eig_solve(nv, &Mp, &Cp, &Kp, coriolis, modes, t->fixed_bits, &e);
    }
    if (rc < 0)
        goto done;
    if (e.n_modes < modes || e.negative > 0) {
        rc = SM_OK; /* not yet: *res stays infinite */
        goto done;
    }
    eig_out_free(out);
    if ((rc = eig_alloc_out(out, n, modes)) < 0)
        goto done;
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, n, modes, nv, 1.0, V, n, e.xre, nv, 0.0, out->xre, n);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, n, modes, nv, 1.0, V, n, e.xim, nv, 0.0, out->xim, n);
    out->max_re = e.max_re;
    double worst = 0;
    for (int j = 0; j < modes; j++) {
        out->wre[j] = e.wre[j];
        out->wim[j] = e.wim[j];
        double r =
            !t->fixed_bits
                ? eig_basis_residual(n, nv, coriolis, MV, CV, KV, e.wre[j], e.wim[j],
                                     e.xre + (size_t)j * nv, e.xim + (size_t)j * nv, scratch)
                : eig_tree_residual(m, t, coriolis, e.wre[j], e.wim[j], out->xre + (size_t)j * n,
                                    out->xim + (size_t)j * n, scratch);
        worst = fmax(worst, r);
    }
    *res = worst;
    rc = SM_OK;
done:
    eig_out_free(&e);
    dm_free(&Mp);
    dm_free(&Cp);
    dm_free(&Kp);
    return rc;
}

/* 1 when the kept basis (best, its residual best_res) may give the modes at the end of the
 * Krylov steps (EIG_TREE_BEST_AGREE): a residual below EIG_TREE_BEST_FLOOR and frequencies
 * within EIG_TREE_BEST_AGREE of those of the largest basis (out). */
static int eig_tree_best_agrees(int modes, const sm_eig_out *out, const sm_eig_out *best,
                                double best_res)
{
    if (!best->wim || !out->wim || !(best_res <= EIG_TREE_BEST_FLOOR))
        return 0;
    for (int j = 0; j < modes; j++)
        if (!(fabs(best->wim[j] - out->wim[j]) <= EIG_TREE_BEST_AGREE * fabs(out->wim[j])))
            return 0;
    return 1;
}

/* *dst = a copy of src's modes (dst freed first); SM_OK or SM_NOMEM. */
static int eig_out_copy(int n, const sm_eig_out *src, sm_eig_out *dst)
{
    eig_out_free(dst);
    int k = src->n_modes, rc = eig_alloc_out(dst, n, k);
    if (rc < 0) {
        eig_out_free(dst);
        return rc;
    }
    memcpy(dst->wre, src->wre, (size_t)k * sizeof(double));
    memcpy(dst->wim, src->wim, (size_t)k * sizeof(double));
    memcpy(dst->xre, src->xre, (size_t)n * k * sizeof(double));
    memcpy(dst->xim, src->xim, (size_t)n * k * sizeof(double));
    dst->negative = src->negative;
    dst->max_re = src->max_re;
    return SM_OK;
}

int eig_solve_tree(const sm_model *m, tree_ws *t, int coriolis, int modes, const sm_progress *pr,
                   sm_eig_out *out, int *fallback)
{
    int n = m->n, N2 = 2 * n, rc, nv = 0, done_x = 0;
    int pmax = EIG_TREE_MAX_BASIS < N2 - 1 ? EIG_TREE_MAX_BASIS : N2 - 1;
    /* the previous modes on this workspace start the basis when the sweep chains the speeds */
    int spatial = !t->fixed_bits; /* planar models keep their bits (issue 27) */
    int warm = spatial && t->warm_next && t->warm_ok && t->warm, keep_warm = 0;
    t->warm_next = 0;
    t->warm_ok = 0; /* until this analysis gives modes */
    memset(out, 0, sizeof *out);
    *fallback = 1;
    rc = tree_factor(m, t, 1);
    if (rc == SM_SINGULAR || (rc == SM_OK && t->neg > 0) || modes < 1 || 4 * modes > n)
        return SM_OK; /* K* not positive definite (or a singular front): the dense path decides */
    if (rc < 0)
        return rc;
    rc = SM_NOMEM;
    /* The bases are written column by column before a column is read (CV only with Coriolis):
     * malloc, not dm_vec's calloc, which cleared 3.3 MB a speed at 288 coordinates (issue 27). */
    size_t cols = (size_t)pmax + 1;
    double *Q = malloc((size_t)N2 * cols * sizeof(double)),
           *V = malloc((size_t)n * cols * sizeof(double));
    double *MV = malloc((size_t)n * cols * sizeof(double)),
           *CV = malloc((size_t)n * cols * sizeof(double));
    double *KV = malloc((size_t)n * cols * sizeof(double)), *tmp = dm_vec(6 * (size_t)n),
           *h = dm_vec((size_t)pmax + 2);
    double *prev = dm_vec((size_t)modes), *cf = dm_vec(2 * cols), best_res = INFINITY;
    int have_prev = 0, prev_p = 0;
    sm_eig_out best; /* the modes of the basis with the smallest residual from EIG_TREE_LATE on */
    memset(&best, 0, sizeof best);
    if (!Q || !V || !MV || !CV || !KV || !tmp || !h || !prev || !cf)
        goto done;
    for (int i = 0; i < n; i++) /* a start vector with every component of x, and y = 0 */
        Q[i] = 1.0 + 0.5 * sin(0.37 * i + 0.1);
    double wn0 = warm ? dm_norm(t->warm, n) : 0;
    if (warm && wn0 > 0 && isfinite(wn0)) {
        double gn = dm_norm(Q, n);
        for (int i = 0; i < n; i++)
            Q[i] = EIG_TREE_WARM_COLD * (Q[i] / gn) + t->warm[i] / wn0;
    }
    memset(Q + n, 0, (size_t)n * sizeof(double));
    double nrm = dm_norm(Q, N2);
    for (int i = 0; i < N2; i++)
        Q[i] /= nrm;
    int p = 0, next = 2 * modes + 10 > 16 ? 2 * modes + 10 : 16, breakdown = 0, refine = 1;
    /* A warm start is near its modes from the first vector, but the basis they need is that of
     * a cold start less a few vectors: on the 288-coordinate blade warm speeds reached residuals
     * of 1e-11 between 18 and 24 vectors and none at 16 (1e-9 to 1e-5 there).  So its first
     * projection comes one step later and the next ones every half step: -2.5 % instructions for
     * a 101-speed sweep (issue 27; the acceptance tests are the same). */
    int step = EIG_TREE_STEP;
    if (warm) {
        next += EIG_TREE_STEP;
        step = EIG_TREE_STEP / 2;
    }
    for (;;) {
        /* a stop every EIG_TREE_STEP vectors: one operator application is two block solves of K*,
         * so building the first 2 modes + 10 vectors of a 2000-element blade takes seconds */
        if (p % EIG_TREE_STEP == 0 && pr && pr->cb && pr->cb(pr->user, pr->done, pr->total)) {
            rc = SM_CANCELED;
            goto done;
        }
        double *w = Q + (size_t)(p + 1) * N2;
        if (spatial) { /* the basis holds the vector's x-part before its product */
            eig_tree_extend(m, t, coriolis, p, Q, V, MV, KV, CV, h, &nv, &done_x);
            rc = eig_tree_op_basis(m, t, coriolis, nv, V, MV, CV, Q + (size_t)p * N2, w, tmp, cf,
                                   &refine);
        } else {
            rc = eig_tree_op(m, t, coriolis, Q + (size_t)p * N2, w, tmp, &refine);
        }
        if (rc < 0)
            goto done;
        double w0 = eig_norm(t->fixed_bits, w, N2),
               wn = eig_cgs2(t->fixed_bits, N2, p + 1, Q, w, h);
        if (!(wn > 1e-12 * w0)) {
            breakdown = 1; /* an invariant subspace: the projection is exact */
        } else {
            for (int i = 0; i < N2; i++)
                w[i] /= wn;
            p++;
        }
        if (p + 1 < next && !breakdown && p < pmax)
            continue;
        eig_tree_extend(m, t, coriolis, p, Q, V, MV, KV, CV, h, &nv, &done_x);
        double res, moved = INFINITY;
        if ((rc = eig_tree_project(m, t, coriolis, modes, nv, V, MV, CV, KV, tmp, out, &res)) < 0)
            goto done;
        if (out->wim) {
            /* "moved" is measured against a basis at least EIG_TREE_STEP vectors smaller (the
             * half steps of a warm start keep the reference of the step before) */
            int far = !have_prev || p - prev_p >= EIG_TREE_STEP || breakdown || p >= pmax;
            if (have_prev && far) {
                moved = 0;
                for (int j = 0; j < modes; j++)
                    moved = fmax(moved, fabs(out->wim[j] - prev[j]) / fabs(out->wim[j]));
            }
            if (far) {
                memcpy(prev, out->wim, (size_t)modes * sizeof(double));
                prev_p = p;
                have_prev = 1;
            }
        }
        int accept = res <= EIG_TREE_TOL || (res <= EIG_TREE_FLOOR && moved <= EIG_TREE_STALL) ||
                     (p >= EIG_TREE_LATE && res <= 1e-7 && moved <= 1e-8) ||
                     (spatial && p >= EIG_TREE_LATE && res <= EIG_TREE_LATE_STEADY &&
                      moved <= EIG_TREE_STALL);
        if (!accept && (breakdown || p >= pmax)) {
            if (res <= EIG_TREE_SHAPE_FLOOR && moved <= EIG_TREE_STALL) { /* steady frequencies */
                accept = 1;
            } else if (spatial && eig_tree_best_agrees(modes, out, &best, best_res)) {
                eig_out_free(out); /* the modes of the basis with the smallest residual */
                *out = best;
                memset(&best, 0, sizeof best);
                accept = 1;
            } else {
                eig_out_free(out); /* no convergence: the dense path */
                break;
            }
        }
        if (accept) {
            out->negative = t->neg;
            *fallback = 0;
            keep_warm = 1;
            break;
        }
        if (spatial && p >= EIG_TREE_LATE && out->wim && res < best_res) {
            if ((rc = eig_out_copy(n, out, &best)) < 0)
                goto done;
            best_res = res;
        }
        next += step;
    }
    rc = SM_OK;
    if (keep_warm && spatial) { /* the next speed's start: the modes, each normalised */
        if (!t->warm)
            t->warm = malloc((size_t)n * sizeof(double));
        if (t->warm) {
            memset(t->warm, 0, (size_t)n * sizeof(double));
            for (int j = 0; j < modes; j++) {
                const double *xr = out->xre + (size_t)j * n, *xi = out->xim + (size_t)j * n;
                double a = dm_norm(xr, n), b = dm_norm(xi, n), c = hypot(a, b);
                if (!(c > 0) || !isfinite(c))
                    continue;
                for (int i = 0; i < n; i++)
                    t->warm[i] += (xr[i] + xi[i]) / c;
            }
            t->warm_ok = 1;
        }
    }
done:
    if (rc < 0 || *fallback)
        eig_out_free(out);
    free(Q);
    free(V);
    free(MV);
    free(CV);
    free(KV);
    free(tmp);
    free(h);
    free(prev);
    free(cf);
    eig_out_free(&best);
    return rc;
}
