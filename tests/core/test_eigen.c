/*
 * test_eigen.c — the eigen-solver on gyroscopic systems with closed-form
 * answers: M = I, K = diag(k1, k2), C = [[0,-g],[g,0]] gives
 *   w^4 - (k1 + k2 + g^2) w^2 + k1 k2 = 0,
 * first as is (Hermitian route), then with an extra massless coordinate
 * (exact null-space condensation), then with k1 < 0 (general route: a
 * divergent root with Re > 0 and a negative eigenvalue of K reported).
 * Last, many such blocks hidden by an orthogonal change of coordinates, with
 * a repeated pair, a nearly repeated pair and a 1e4 spread of frequencies:
 * the real skew route (S'S, then Rayleigh-Ritz) must keep every frequency
 * (to 1e-9 absolute: the rounding of the input allows ~1e-8) and return
 * independent vectors with small residuals.  All of it with fixed_bits 1 and 0 (the symmetric
 * eigenproblems by dsyevr, and by dm_syev_range's route without bisection).
 */
#include "internal.h"

#include <complex.h>
#include "testutil.h"

/* eig_solve's fixed_bits: 1 LAPACK's dsyevr (the planar kind), 0 dm_syev_range's route without
 * bisection (the spatial kind, solver 0.8.8); main runs every check on both. */
static int route;

static void roots(double k1, double k2, double g, double *w1, double *w2)
{
    double b = k1 + k2 + g * g, disc = sqrt(b * b - 4 * k1 * k2);
    *w1 = sqrt(0.5 * (b - disc));
    *w2 = sqrt(0.5 * (b + disc));
}

/* nb 2x2 blocks (k1, k2, g) in the coordinates x = Q y, Q a Householder
 * reflection: M = I, K = Q Kd Q', C = Q Cd Q'. */
static void blocks(void)
{
    enum { NB = 7, N = 2 * NB };
    const double kb[NB][3] = {
        {4.0, 9.0, 1.5},       {4.0, 9.0, 1.5},      /* repeated pair */
        {25.0, 36.0, 0.5},     {25.0, 36.0 * (1 + 1e-9), 0.5}, /* nearly repeated */
        {1.0, 1.2, 0.01},      {1e6, 3e6, 10.0},     {1e8, 1.1e8, 100.0},
    };
    double want[N], v[N], vv = 0;
    for (int b = 0; b < NB; b++)
        roots(kb[b][0], kb[b][1], kb[b][2], &want[2 * b], &want[2 * b + 1]);
    for (int i = 0; i < N; i++) { /* insertion sort */
        for (int j = i; j > 0 && want[j] < want[j - 1]; j--) {
            double t = want[j];
            want[j] = want[j - 1];
            want[j - 1] = t;
        }
        v[i] = 1.0 + 0.37 * i - 0.05 * i * i;
        vv += v[i] * v[i];
    }
    dmat M, C, K, Kd, Cd, Q;
    dm_alloc(&M, N, N);
    dm_alloc(&C, N, N);
    dm_alloc(&K, N, N);
    dm_alloc(&Kd, N, N);
    dm_alloc(&Cd, N, N);
    dm_alloc(&Q, N, N);
    for (int b = 0; b < NB; b++) {
        DM(&Kd, 2 * b, 2 * b) = kb[b][0];
        DM(&Kd, 2 * b + 1, 2 * b + 1) = kb[b][1];
        DM(&Cd, 2 * b, 2 * b + 1) = -kb[b][2];
        DM(&Cd, 2 * b + 1, 2 * b) = kb[b][2];
    }
    for (int i = 0; i < N; i++) {
        DM(&M, i, i) = 1;
        for (int j = 0; j < N; j++)
            DM(&Q, i, j) = (i == j) - 2 * v[i] * v[j] / vv;
    }
    for (int i = 0; i < N; i++) /* K = Q Kd Q', C = Q Cd Q' (Q symmetric) */
        for (int j = 0; j < N; j++)
            for (int a = 0; a < N; a++)
                for (int c = 0; c < N; c++) {
                    DM(&K, i, j) += DM(&Q, i, a) * DM(&Kd, a, c) * DM(&Q, c, j);
                    DM(&C, i, j) += DM(&Q, i, a) * DM(&Cd, a, c) * DM(&Q, c, j);
                }
    sm_eig_out e;
    int k = N - 1;
    TU_CHECK(eig_solve(N, &M, &C, &K, 1, k, route, &e) == SM_OK && e.n_modes == k,
             "eig_solve %d blocks", NB);
    for (int j = 0; j < e.n_modes; j++) {
        /* K = Q Kd Q' is rounded (entries up to 1e8): that alone moves w by up
         * to ~eps 1e8 / (2 w) ~ 1e-8; zheevr and the skew route both land within 3e-10 */
        TU_NEAR(e.wim[j], want[j], 1e-9 + 1e-12 * want[j], "blocks: w%d", j + 1);
        /* residual of (lambda^2 + lambda C + K) x, lambda = i w */
        double w = e.wim[j], res = 0, nx = 0;
        const double *xr = e.xre + (size_t)j * N, *xi = e.xim + (size_t)j * N;
        for (int i = 0; i < N; i++) {
            double rr = -w * w * xr[i], ri = -w * w * xi[i];
            for (int c = 0; c < N; c++) {
                rr += -w * DM(&C, i, c) * xi[c] + DM(&K, i, c) * xr[c];
                ri += w * DM(&C, i, c) * xr[c] + DM(&K, i, c) * xi[c];
            }
            res += rr * rr + ri * ri;
            nx += xr[i] * xr[i] + xi[i] * xi[i];
        }
        TU_CHECK(sqrt(res) <= 1e-9 * (w * w + 1e8) * sqrt(nx), "blocks: residual of mode %d: %.3e", j + 1,
                 sqrt(res / nx));
    }
    /* the repeated pair: two independent vectors */
    for (int j = 0; j + 1 < e.n_modes; j++) {
        if (fabs(e.wim[j + 1] - e.wim[j]) > 1e-6 * e.wim[j])
            continue;
        double complex d = 0;
        double na = 0, nb = 0;
        for (int i = 0; i < N; i++) {
            double complex a = e.xre[(size_t)j * N + i] + I * e.xim[(size_t)j * N + i];
            double complex b = e.xre[(size_t)(j + 1) * N + i] + I * e.xim[(size_t)(j + 1) * N + i];
            d += conj(a) * b;
            na += creal(conj(a) * a);
            nb += creal(conj(b) * b);
        }
        TU_CHECK(cabs(d) < 0.9 * sqrt(na * nb), "blocks: modes %d and %d independent (|cos| %.3f)", j + 1, j + 2,
                 cabs(d) / sqrt(na * nb));
    }
    eig_out_free(&e);
    dm_free(&M);
    dm_free(&C);
    dm_free(&K);
    dm_free(&Kd);
    dm_free(&Cd);
    dm_free(&Q);
}

static void cases(void)
{
    double k1 = 4.0, k2 = 9.0, g = 1.5, w1, w2;
    roots(k1, k2, g, &w1, &w2);
    dmat M, C, K;
    sm_eig_out e;
    /* 2 x 2 */
    dm_alloc(&M, 2, 2);
    dm_alloc(&C, 2, 2);
    dm_alloc(&K, 2, 2);
    DM(&M, 0, 0) = DM(&M, 1, 1) = 1;
    DM(&K, 0, 0) = k1;
    DM(&K, 1, 1) = k2;
    DM(&C, 0, 1) = -g;
    DM(&C, 1, 0) = g;
    TU_CHECK(eig_solve(2, &M, &C, &K, 1, 2, route, &e) == SM_OK, "eig_solve 2x2");
    TU_NEAR(e.wim[0], w1, 1e-12, "gyroscopic w1");
    TU_NEAR(e.wim[1], w2, 1e-12, "gyroscopic w2");
    TU_CHECK(e.negative == 0 && e.max_re == 0, "stable system flagged");
    eig_out_free(&e);
    TU_CHECK(eig_solve(2, &M, &C, &K, 0, 2, route, &e) == SM_OK, "eig_solve undamped");
    TU_NEAR(e.wim[0], 2.0, 1e-12, "undamped w1 = sqrt(k1)");
    TU_NEAR(e.wim[1], 3.0, 1e-12, "undamped w2 = sqrt(k2)");
    eig_out_free(&e);
    dm_free(&M);
    dm_free(&C);
    dm_free(&K);

    /* 3 x 3 with a massless coordinate z coupled by springs: x = (a1, a2, z).
     * K = [[k1+c, 0, -c], [0, k2, 0], [-c, 0, c + d]]: condensing z gives
     * k1' = k1 + c - c^2/(c + d). */
    double c = 3.0, dd = 2.0, k1p = k1 + c - c * c / (c + dd);
    roots(k1p, k2, g, &w1, &w2);
    dm_alloc(&M, 3, 3);
    dm_alloc(&C, 3, 3);
    dm_alloc(&K, 3, 3);
    DM(&M, 0, 0) = DM(&M, 1, 1) = 1;
    DM(&K, 0, 0) = k1 + c;
    DM(&K, 1, 1) = k2;
    DM(&K, 2, 2) = c + dd;
    DM(&K, 0, 2) = DM(&K, 2, 0) = -c;
    DM(&C, 0, 1) = -g;
    DM(&C, 1, 0) = g;
    TU_CHECK(eig_solve(3, &M, &C, &K, 1, 2, route, &e) == SM_OK,
             "eig_solve with a massless coordinate");
    TU_CHECK(e.n_modes == 2, "two finite roots, got %d", e.n_modes);
    TU_NEAR(e.wim[0], w1, 1e-10, "condensed gyroscopic w1");
    TU_NEAR(e.wim[1], w2, 1e-10, "condensed gyroscopic w2");
    /* the massless coordinate follows statically: z = c a1 / (c + d) */
    double ratio = hypot(e.xre[2], e.xim[2]) / hypot(e.xre[0], e.xim[0]);
    TU_NEAR(ratio, c / (c + dd), 1e-10, "massless coordinate recovered");
    eig_out_free(&e);

    /* unstable: k1 < 0 -> negative eigenvalue of K and a root with Re > 0
     * unless gyroscopic stabilisation; with small g it diverges */
    DM(&K, 0, 0) = -2.0 + c;
    DM(&K, 2, 2) = c + dd;
    TU_CHECK(eig_solve(3, &M, &C, &K, 1, 2, route, &e) == SM_OK, "eig_solve unstable");
    TU_CHECK(e.negative == 1, "negative eigenvalues of K: got %d want 1", e.negative);
    /* closed form: lambda^4 + (k1'+k2+g^2) lambda^2 + k1' k2 = 0 */
    double k1u = -2.0 + c - c * c / (c + dd), b = k1u + k2 + g * g;
    double l2 = 0.5 * (-b + sqrt(b * b - 4 * k1u * k2)); /* positive root in lambda^2 */
    TU_NEAR(e.max_re, sqrt(l2), 1e-9, "divergence rate");
    TU_NEAR(e.wre[0], sqrt(l2), 1e-9, "divergent root reported first");
    eig_out_free(&e);
    dm_free(&M);
    dm_free(&C);
    dm_free(&K);
    blocks();
    /* a nearly free coordinate (w1^2 / w2^2 ~ 1e-16, below the 1e-14 the S'S
     * route accepts): the zheevr fallback answers */
    dm_alloc(&M, 2, 2);
    dm_alloc(&C, 2, 2);
    dm_alloc(&K, 2, 2);
    DM(&M, 0, 0) = DM(&M, 1, 1) = 1;
    DM(&K, 0, 0) = 1e-16;
    DM(&K, 1, 1) = 1.0;
    DM(&C, 0, 1) = -0.5;
    DM(&C, 1, 0) = 0.5;
    roots(1e-16, 1.0, 0.5, &w1, &w2);
    w1 = 1e-8 / w2; /* the small root without cancellation: w1 w2 = sqrt(k1 k2) */
    TU_CHECK(eig_solve(2, &M, &C, &K, 1, 2, route, &e) == SM_OK && e.n_modes == 2,
             "eig_solve, nearly free coordinate");
    TU_NEAR(e.wim[0], w1, 1e-6 * w1, "nearly free coordinate: w1");
    TU_NEAR(e.wim[1], w2, 1e-12, "nearly free coordinate: w2");
    eig_out_free(&e);
    dm_free(&M);
    dm_free(&C);
    dm_free(&K);
}

int main(void)
{
    for (route = 1; route >= 0; route--) {
        printf("-- fixed_bits %d\n", route);
        cases();
    }
    return tu_finish("eigen");
}
