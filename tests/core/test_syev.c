/*
 * test_syev.c — dm_syev_range (core/base/dense.c): a subset of a symmetric matrix's eigenpairs
 * by LAPACK's dsyevr (dsyevr_bits = 1, the planar kind's bits) and by the route without bisection
 * (0: dsytrd, dsterf block by block, dstein, dormtr; the spatial kind's since solver 0.8.8, issue
 * 27).  On each matrix and subset, for both routes: the vectors satisfy A z = w z to 1e-13 |A|,
 * are orthonormal to 1e-12, and come in ascending order; the two routes' eigenvalues agree to
 * 1e-13 |A|.  The matrices are those the solver meets and the ones the route must not get wrong:
 *  - a graded SPD matrix (spectrum over 12 decades, as 1/w^2 of a blade), lowest, highest,
 *    middle, single and all subsets;
 *  - a block-diagonal matrix whose blocks have the same spectrum: its tridiagonal form splits
 *    (dstebz's test), each eigenvalue is repeated once per block, and each vector must lie in
 *    one block, as dsyevr's do (decoupled motions stay apart; without the split, dstein mixes
 *    the blocks' equal eigenvalues);
 *  - S'S of a real skew S (the gyroscopic squared problem of eigen_skew.c): every eigenvalue
 *    exactly twice;
 *  - 1 x 1, and NaN in A (refused with a negative info, as dsyevr's LAPACKE check refuses it).
 */
#include "dense.h"
#include "testutil.h"

#include <cblas.h>

#define NMAX 90

static double lcg(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (double)(*s >> 8) / 16777216.0 - 0.5;
}

/* A = Q diag(lam) Q' with Q a product of two Householder reflections of random vectors. */
static void sy_from_spectrum(int n, const double *lam, unsigned seed, double *A)
{
    double *Q = calloc((size_t)n * n, sizeof *Q), *v = malloc((size_t)n * sizeof *v);
    for (int i = 0; i < n; i++)
        Q[(size_t)i * n + i] = 1;
    for (int h = 0; h < 2; h++) {
        double vv = 0;
        for (int i = 0; i < n; i++) {
            v[i] = lcg(&seed);
            vv += v[i] * v[i];
        }
        for (int j = 0; j < n; j++) { /* column j of Q = (I - 2 v v'/v'v) Q */
            double d = 0;
            for (int i = 0; i < n; i++)
                d += v[i] * Q[(size_t)j * n + i];
            for (int i = 0; i < n; i++)
                Q[(size_t)j * n + i] -= 2 * d / vv * v[i];
        }
    }
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double s = 0;
            for (int k = 0; k < n; k++)
                s += Q[(size_t)k * n + i] * lam[k] * Q[(size_t)k * n + j];
            A[(size_t)j * n + i] = s;
        }
    free(Q);
    free(v);
}

/* Both routes on A (n x n, full storage, not changed) for eigenvalues il..iu; nb > 0: A is
 * block diagonal with nb equal blocks, and each vector must lie in one block. */
static void sy_check(const char *name, int n, const double *A, int il, int iu, int nb)
{
    int m = iu - il + 1;
    double *W = malloc((size_t)n * n * sizeof *W), *w[2], *Z = malloc((size_t)n * m * sizeof *Z);
    double anorm = 0;
    for (size_t i = 0; i < (size_t)n * n; i++)
        anorm = fmax(anorm, fabs(A[i]));
    anorm *= n;
    for (int route = 0; route < 2; route++) {
        w[route] = malloc((size_t)m * sizeof(double));
        memcpy(W, A, (size_t)n * n * sizeof *W);
        int info = dm_syev_range(route, n, W, il, iu, w[route], Z, n);
        TU_CHECK(info == 0, "%s [%d, %d], route %d: info %d", name, il, iu, route, info);
        if (info != 0)
            continue;
        double res = 0, orth = 0, order = 0, mixed = 0;
        for (int j = 0; j < m; j++) {
            const double *z = Z + (size_t)j * n;
            for (int i = 0; i < n; i++) { /* (A z - w z)_i */
                double s = -w[route][j] * z[i];
                for (int k = 0; k < n; k++)
                    s += A[(size_t)k * n + i] * z[k];
                res = fmax(res, fabs(s));
            }
            for (int l = 0; l <= j; l++) { /* z_l' z_j - delta */
                double d = cblas_ddot(n, Z + (size_t)l * n, 1, z, 1) - (l == j);
                orth = fmax(orth, fabs(d));
            }
            if (j > 0)
                order = fmax(order, w[route][j - 1] - w[route][j]);
            double share[NMAX], big = 0, out = 0; /* |z|^2 in each block; out of the largest */
            for (int b = 0, len = nb ? n / nb : 0; b < nb; b++) {
                share[b] = cblas_ddot(len, z + b * len, 1, z + b * len, 1);
                big = fmax(big, share[b]);
            }
            for (int b = 0; b < nb; b++)
                out += share[b] < big ? share[b] : 0;
            mixed = fmax(mixed, out);
        }
        TU_CHECK(res <= 1e-13 * anorm, "%s [%d, %d], route %d: residual %.2e of |A| %.2e", name, il,
                 iu, route, res, anorm);
        TU_CHECK(orth <= 1e-12, "%s [%d, %d], route %d: orthonormality %.2e", name, il, iu, route,
                 orth);
        TU_CHECK(order <= 0, "%s [%d, %d], route %d: not ascending (%.2e)", name, il, iu, route,
                 order);
        TU_CHECK(mixed <= 1e-20, "%s [%d, %d], route %d: a vector spread over blocks (%.2e)", name,
                 il, iu, route, mixed);
    }
    double dw = 0;
    for (int j = 0; j < m; j++)
        dw = fmax(dw, fabs(w[0][j] - w[1][j]));
    TU_CHECK(dw <= 1e-13 * anorm, "%s [%d, %d]: routes differ by %.2e", name, il, iu, dw);
    printf("%s [%d, %d] of %d: routes agree to %.1e |A|\n", name, il, iu, n, dw / anorm);
    free(w[0]);
    free(w[1]);
    free(W);
    free(Z);
}

int main(void)
{
    static double A[NMAX * NMAX], lam[NMAX];
    /* graded: 1 .. 1e12 */
    int n = 72;
    for (int i = 0; i < n; i++)
        lam[i] = pow(10.0, 12.0 * i / (n - 1)) * (1 + 0.01 * (i % 3));
    sy_from_spectrum(n, lam, 7, A);
    sy_check("graded", n, A, 1, 20, 0);
    sy_check("graded", n, A, n - 19, n, 0);
    sy_check("graded", n, A, 30, 41, 0);
    sy_check("graded", n, A, 5, 5, 0);
    sy_check("graded", n, A, 1, n, 0);

    /* three diagonal blocks with one spectrum: each eigenvalue three times, a split tridiagonal */
    int nb = 25;
    n = 3 * nb;
    double blk[25 * 25], lb[25];
    for (int i = 0; i < nb; i++)
        lb[i] = 1.0 + i * i;
    sy_from_spectrum(nb, lb, 11, blk);
    memset(A, 0, sizeof A);
    for (int b = 0; b < 3; b++)
        for (int j = 0; j < nb; j++)
            for (int i = 0; i < nb; i++)
                A[(size_t)(b * nb + j) * n + b * nb + i] = blk[j * nb + i];
    sy_check("blocks", n, A, 1, 12, 3);
    sy_check("blocks", n, A, n - 8, n, 3);
    sy_check("blocks", n, A, 20, 40, 3);

    /* S'S of a real skew S (2r = 50): every eigenvalue twice */
    int r = 25;
    n = 2 * r;
    double *S = calloc((size_t)n * n, sizeof *S);
    unsigned seed = 3;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < j; i++) {
            double x = lcg(&seed) * (1 + i);
            S[(size_t)j * n + i] = x;
            S[(size_t)i * n + j] = -x;
        }
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, n, n, n, 1.0, S, n, S, n, 0.0, A, n);
    sy_check("skew squared", n, A, 1, 16, 0);
    sy_check("skew squared", n, A, n - 15, n, 0);
    free(S);

    /* 1 x 1 */
    A[0] = 3.5;
    sy_check("one", 1, A, 1, 1, 0);

    /* NaN: refused by both routes with a negative info (LAPACKE's check) */
    double Bn[4] = {1, NAN, NAN, 2}, wn[2], Zn[4];
    for (int route = 0; route < 2; route++) {
        double Bc[4];
        memcpy(Bc, Bn, sizeof Bc);
        int info = dm_syev_range(route, 2, Bc, 1, 2, wn, Zn, 2);
        TU_CHECK(info < 0, "NaN, route %d: info %d, want negative", route, info);
    }
    return tu_finish("syev");
}
