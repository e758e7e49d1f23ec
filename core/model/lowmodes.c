/*
 * lowmodes.c — the nm lowest component modes of a large frame by subspace
 * iteration on the sparse factor of Kbar (lowmodes.h, issue 10).
 *
 * The frame's eigenproblem is written as modes3.c writes it: Mbar x = mu Kbar x,
 * mu = 1/omega^2, with Kbar positive definite and Mbar only semi-definite (the
 * massless rotations of planar lumped mass, zero rotary inertia).  Simultaneous
 * inverse iteration (K.-J. Bathe, Finite Element Procedures, 1996, sec. 11.6)
 * keeps p = max(2 nm, nm + 8) vectors V, Kbar-orthonormal with Ritz values mu:
 *     Y = Kbar^-1 Mbar V                      (p sparse solves)
 *     Kr = Y' Mbar V (= Y' Kbar Y), Mr = Y' Mbar Y, Mr z = mu Kr z, V = Y Z
 * Mode j converges like (mu_{p+1}/mu_j)^iterations.  The test is a residual of
 * the inverse operator, |Kbar^-1 Mbar v - mu v|, built from quantities of the
 * size of mu v (no cancellation against the large entries of Kbar; see
 * LOWMODES_TOL for the bound).  A last Rayleigh-Ritz with explicit products
 * summed accurately (lowmodes_ritz, the sparse twin of modes3_ritz) gives the
 * basis.  Exactly repeated frequencies (identical branches, round sections) are
 * found as a subspace because the block is wider than nm.  An iteration that
 * does not converge, or a block that loses rank, hands the frame back to the
 * dense path (*fallback).
 *
 * Cost per iteration O(D p (b + p)) with b the entries per column of the
 * factor (~2 node blocks on a tree), 10-20 iterations, so O(D) for a fixed nm;
 * memory O(D p).  Measured (tests/bench/bench_modes, one frame, 8 modes, one
 * thread): D = 1200 builds in ~10 ms against 0.3-0.6 s dense, D = 2400 in
 * ~20 ms.  Being accurate (refined static solves, accurate K_s) it is also
 * closer to the exact eigenvectors than the dense path: tests/core/test_lowmodes.
 */
#include "lowmodes.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/*
 * Smallest frame (DOF) that leaves the dense path, and largest share of its
 * modes kept, from the model build timed both ways (one thread, one frame):
 * with 8 modes the two break even at D ~ 150-200 (planar lumped 180: 1.2 ms
 * dense, 1.5 ms sparse; 240: 2.2 against 1.7; spatial 120: 1.2 against 0.9),
 * and below that both take a millisecond or two.  The sparse cost grows with
 * the block (O(D p^2) for the projections, p = 2 nm) and breaks even with the
 * dense O(D^3) near nm = D/8 at D = 600 (planar 75 modes: 45 ms both ways;
 * spatial 100: 83 ms both) and D/6 at D = 1200 (planar 200: 0.47 s dense,
 * 0.9 s sparse; 150: 0.40 s, 0.26 s); at D = 300, nm = D/8 the sparse path is
 * 0.6-1.1 x the dense time, a few milliseconds either way.
 */
#define LOWMODES_MIN_DOFS 200
#define LOWMODES_SHARE 8
/*
 * Convergence of Ritz pair j: |y_j - mu_j v_j| <= (LOWMODES_TOL mu_j + LOWMODES_KAPPA mu_1) |v_j|
 * (y_j = Kbar^-1 Mbar v_j).  The second term is the rounding of the solves and of the projected
 * problem, which are accurate relative to the largest mu only: mode 100 of a 400-element chain
 * (mu_j ~ 1e-8 mu_1) cannot get a residual below ~1e-6 of its own mu, the 8th (~4e-5 mu_1) gets
 * ~1e-11.  LOWMODES_STALL iterations without a new low of the worst ratio (residual over that
 * bound), with the low under LOWMODES_STALL_AT, also mean the noise is reached (a slow but
 * steady convergence makes a new low every iteration).  Typical runs take 10-20 iterations.
 */
#define LOWMODES_TOL 1e-12
#define LOWMODES_KAPPA (64 * 2.2e-16)
#define LOWMODES_STALL 4
#define LOWMODES_STALL_AT 1e4
#define LOWMODES_MAX_ITER 100

int lowmodes_use(const sm_options *o, int D, int nm)
{
    return o->solver != SM_SOLVER_DENSE && D >= LOWMODES_MIN_DOFS && (long)LOWMODES_SHARE * nm <= D && nm > 0;
}

int lowmodes_block(int D, int nm)
{
    int p = 2 * nm > nm + 8 ? 2 * nm : nm + 8;
    return p < D ? p : D;
}

int lowmodes_reduced(int D, int k, double *X, double *Kr, double *Mr, double *w, double *Y)
{
    /* info > k: Kr is not positive definite; 0 < info <= k: no convergence */
    int info = LAPACKE_dsygvd(LAPACK_COL_MAJOR, 1, 'V', 'U', k, Mr, k, Kr, k, w);
    int rc = dm_lapack_status(info, info > k ? SM_SINGULAR : SM_LAPACK_FAILED);
    if (rc < 0)
        return rc;
    /* Y = X Z; descending mu: reverse the columns */
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, D, k, k, 1.0, X, D, Mr, k, 0.0, Y, D);
    for (int j = 0; j < k; j++)
        memcpy(X + (size_t)D * j, Y + (size_t)D * (k - 1 - j), (size_t)D * sizeof(double));
    for (int j = 0; j < k / 2; j++) {
        double t = w[j];
        w[j] = w[k - 1 - j];
        w[k - 1 - j] = t;
    }
    return SM_OK;
}

int lowmodes_ritz(const csym *K, const csym *M, int k, double *X, double *w)
{
    int D = K->n, rc = SM_NOMEM;
    double *KX = dm_vec((size_t)D * k), *Kr = dm_vec((size_t)k * k), *Mr = dm_vec((size_t)k * k);
    double *Y = dm_vec((size_t)D * k);
    if (!KX || !Kr || !Mr || !Y)
        goto done;
    csym_mul_acc(K, k, X, D, KX, D); /* Kr = X' K X */
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, k, k, D, 1.0, X, D, KX, D, 0.0, Kr, k);
    csym_mul(M, k, X, D, KX, D); /* Mr = X' M X */
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, k, k, D, 1.0, X, D, KX, D, 0.0, Mr, k);
    rc = lowmodes_reduced(D, k, X, Kr, Mr, w, Y);
done:
    free(KX);
    free(Kr);
    free(Mr);
    free(Y);
    return rc;
}

int lowmodes_project(const csym *K, const dmat *N, dmat *Ks)
{
    int D = N->rows, mm = N->cols;
    double *KN = dm_vec((size_t)D * mm);
    if (!KN || dm_alloc(Ks, mm, mm)) {
        free(KN);
        return SM_NOMEM;
    }
    csym_mul_acc(K, mm, N->a, D, KN, D); /* Ks = N' (K N) */
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, mm, mm, D, 1.0, N->a, D, KN, D, 0.0, Ks->a, mm);
    for (int i = 0; i < mm; i++) /* exact symmetry */
        for (int j = 0; j < i; j++)
            DM(Ks, i, j) = DM(Ks, j, i) = 0.5 * (DM(Ks, i, j) + DM(Ks, j, i));
    free(KN);
    return SM_OK;
}

/* V (D x p) = reproducible pseudo-random start vectors in [-1/2, 1/2) (64-bit LCG, local state). */
static void lowmodes_start(int D, int p, double *V)
{
    uint64_t s = 0x9e3779b97f4a7c15u;
    for (size_t t = 0; t < (size_t)D * p; t++) {
        s = s * 6364136223846793005u + 1442695040888963407u;
        V[t] = (double)(s >> 11) * 0x1.0p-53 - 0.5;
    }
}

/* max over j < nm of |y_j - mu_j v_j| / ((LOWMODES_TOL mu_j + LOWMODES_KAPPA mu_1) |v_j|): the
 * residuals of Kbar^-1 Mbar at the Ritz pairs over what convergence asks (1: converged). */
static double lowmodes_residual(int D, int nm, const double *Y, const double *V, const double *mu)
{
    double worst = 0;
    for (int j = 0; j < nm; j++) {
        const double *y = Y + (size_t)D * j, *v = V + (size_t)D * j;
        double r2 = 0, v2 = 0;
        for (int i = 0; i < D; i++) {
            double r = y[i] - mu[j] * v[i];
            r2 += r * r;
            v2 += v[i] * v[i];
        }
        double bound = (LOWMODES_TOL * mu[j] + LOWMODES_KAPPA * mu[0]) * sqrt(v2);
        worst = fmax(worst, mu[j] > 0 && bound > 0 ? sqrt(r2) / bound : INFINITY);
    }
    return worst;
}

/*
 * One Rayleigh-Ritz step in the span of Y (D x p): Kr = Y' MV (= Y' K Y since
 * K Y = M V), Mr = Y' M Y, columns of Y scaled to unit K-norm first (the
 * projected pencil stays well conditioned however far mu_1 and mu_p lie
 * apart), then V = Y Z.  MV is overwritten (M Y).  SM_OK, SM_SINGULAR (Y lost
 * rank), SM_LAPACK_FAILED.
 */
static int lowmodes_step(const csym *M, int p, double *Y, double *MV, double *V, double *Kr, double *Mr,
                         double *mu)
{
    int D = M->n;
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, p, p, D, 1.0, Y, D, MV, D, 0.0, Kr, p);
    csym_mul(M, p, Y, D, MV, D);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, p, p, D, 1.0, Y, D, MV, D, 0.0, Mr, p);
    for (int j = 0; j < p; j++)
        if (!(Kr[(size_t)p * j + j] > 0))
            return SM_SINGULAR;
    for (int j = 0; j < p; j++) { /* S = diag(Kr)^-1/2: Kr = S Kr S, Mr = S Mr S, Y = Y S */
        double sj = 1.0 / sqrt(Kr[(size_t)p * j + j]);
        for (int i = 0; i < p; i++) {
            Kr[(size_t)p * j + i] *= sj;
            Kr[(size_t)p * i + j] *= sj;
            Mr[(size_t)p * j + i] *= sj;
            Mr[(size_t)p * i + j] *= sj;
        }
        cblas_dscal(D, sj, Y + (size_t)D * j, 1);
    }
    int rc = lowmodes_reduced(D, p, Y, Kr, Mr, mu, V);
    if (rc == SM_OK)
        memcpy(V, Y, (size_t)D * p * sizeof(double));
    return rc;
}

int lowmodes_solve(const csym *K, const csym_ldl *F, const csym *M, int nm, double *X, double *mu,
                   int *fallback)
{
    int D = K->n, p = lowmodes_block(D, nm), rc = SM_NOMEM, conv = 0;
    double *V = dm_vec((size_t)D * p), *Y = dm_vec((size_t)D * p), *MV = dm_vec((size_t)D * p);
    double *Kr = dm_vec((size_t)p * p), *Mr = dm_vec((size_t)p * p), *work = dm_vec((size_t)D);
    *fallback = 0;
    if (!V || !Y || !MV || !Kr || !Mr || !work)
        goto done;
    lowmodes_start(D, p, V);
    double best = INFINITY;
    for (int it = 0, since = 0; !conv; it++) {
        csym_mul(M, p, V, D, MV, D); /* Y = K^-1 M V */
        memcpy(Y, MV, (size_t)D * p * sizeof(double));
        csym_solve(F, p, Y, D, work);
        if (it > 0) {
            double res = lowmodes_residual(D, nm, Y, V, mu);
            since = res < best ? 0 : since + 1;
            best = fmin(best, res);
            /* converged, or at the noise floor of the solves: no new low for a while */
            conv = res <= 1.0 || (best <= LOWMODES_STALL_AT && since >= LOWMODES_STALL);
        }
        if (!conv && it >= LOWMODES_MAX_ITER)
            break;
        if ((rc = lowmodes_step(M, p, Y, MV, V, Kr, Mr, mu)) < 0)
            break;
    }
    if (rc == SM_SINGULAR || (rc == SM_OK && !conv)) {
        *fallback = 1;
        rc = SM_OK;
        goto done;
    }
    if (rc < 0)
        goto done;
    rc = lowmodes_ritz(K, M, p, V, mu); /* the final basis from explicit products */
    if (rc == SM_SINGULAR) {
        *fallback = 1;
        rc = SM_OK;
    }
    if (rc == SM_OK && !*fallback)
        memcpy(X, V, (size_t)D * p * sizeof(double));
done:
    free(V);
    free(Y);
    free(MV);
    free(Kr);
    free(Mr);
    free(work);
    return rc;
}

int lowmodes_frame_pattern(const sm_model *m, const sm_sub *b, int bs, csym *A)
{
    int s = (int)(b - m->subs), rc;
    int *ends = malloc((size_t)(b->nel ? 2 * b->nel : 1) * sizeof(int));
    memset(A, 0, sizeof *A);
    if (!ends)
        return SM_NOMEM;
    for (int j = 0; j < b->nel; j++) {
        const sm_elem *e = &m->elems[b->elems[j]];
        for (int h = 0; h < 2; h++) { /* local free-node index, -1 for the root */
            int k = h ? e->n2 : e->n1;
            ends[2 * j + h] = k != b->root && m->nodes[k].sub == s ? m->nodes[k].local : -1;
        }
    }
    rc = csym_pattern(A, b->nfree, bs, b->nel, ends);
    free(ends);
    return rc;
}
