/*
 * test_ptap.c — dm_ptap_ordered (core/base/dense.c) gives the bits of the plain loops it replaced
 * in the planar kind's reduced stiffness (modes_planar.c: K N, then N' (K N), each entry a sum in
 * index order from 0): memcmp against those loops on random and on graded, sign-mixed matrices
 * (so that a changed order of a sum would show in the last bits), sizes 1 x 1 to 173 x 61, and
 * N' K N against BLAS within rounding (the values are right, not only the bits equal).
 */
#include "dense.h"
#include "testutil.h"

#include <cblas.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static double rnd(unsigned *s)
{
    *s = *s * 1103515245u + 12345u;
    return (double)((*s >> 8) & 0xffff) / 65536.0 - 0.5;
}

static void check(int n, int m, unsigned seed)
{
    double *K = dm_vec((size_t)n * n), *N = dm_vec((size_t)n * m);
    double *KN = dm_vec((size_t)n * m), *C = dm_vec((size_t)m * m);
    double *KN0 = dm_vec((size_t)n * m), *C0 = dm_vec((size_t)m * m), *C1 = dm_vec((size_t)m * m);
    unsigned s = seed;
    for (int j = 0; j < n; j++) /* symmetric, graded over 12 decades, signs mixed */
        for (int i = 0; i <= j; i++)
            K[(size_t)j * n + i] = K[(size_t)i * n + j] =
                rnd(&s) * pow(10.0, 12.0 * (i + j) / (2.0 * n) - 6);
    for (size_t i = 0; i < (size_t)n * m; i++)
        N[i] = rnd(&s) * (i % 7 == 3 ? 1e-9 : 1.0);
    for (int i = 0; i < n; i++) /* the loops modes_planar.c had */
        for (int j = 0; j < m; j++) {
            double t = 0;
            for (int p = 0; p < n; p++)
                t += K[(size_t)p * n + i] * N[(size_t)j * n + p];
            KN0[(size_t)j * n + i] = t;
        }
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            double t = 0;
            for (int p = 0; p < n; p++)
                t += N[(size_t)i * n + p] * KN0[(size_t)j * n + p];
            C0[(size_t)j * m + i] = t;
        }
    TU_CHECK(dm_ptap_ordered(n, m, K, N, KN, C) == SM_OK, "%d x %d: runs", n, m);
    TU_CHECK(memcmp(KN, KN0, (size_t)n * m * sizeof(double)) == 0, "%d x %d: K N, the loops' bits",
             n, m);
    TU_CHECK(memcmp(C, C0, (size_t)m * m * sizeof(double)) == 0, "%d x %d: N' K N, the loops' bits",
             n, m);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, n, m, n, 1.0, K, n, N, n, 0.0, KN0, n);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, m, m, n, 1.0, N, n, KN0, n, 0.0, C1, m);
    double err = 0, ref = 0;
    for (size_t i = 0; i < (size_t)m * m; i++) {
        err = fmax(err, fabs(C[i] - C1[i]));
        ref = fmax(ref, fabs(C1[i]));
    }
    TU_CHECK(err <= 1e-12 * ref * n, "%d x %d: against BLAS %.2e of %.2e", n, m, err, ref);
    free(K);
    free(N);
    free(KN);
    free(C);
    free(KN0);
    free(C0);
    free(C1);
}

int main(void)
{
    check(1, 1, 1);
    check(3, 1, 2);
    check(2, 5, 3);
    check(18, 7, 4);
    check(75, 75, 5);
    check(173, 61, 6);
    return tu_finish("ptap");
}
