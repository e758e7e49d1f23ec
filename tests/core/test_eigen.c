/*
 * test_eigen.c — the eigen-solver on gyroscopic systems with closed-form
 * answers: M = I, K = diag(k1, k2), C = [[0,-g],[g,0]] gives
 *   w^4 - (k1 + k2 + g^2) w^2 + k1 k2 = 0,
 * first as is (Hermitian route), then with an extra massless coordinate
 * (exact null-space condensation), then with k1 < 0 (general route: a
 * divergent root with Re > 0 and a negative eigenvalue of K reported).
 */
#include "internal.h"
#include "testutil.h"

static void roots(double k1, double k2, double g, double *w1, double *w2)
{
    double b = k1 + k2 + g * g, disc = sqrt(b * b - 4 * k1 * k2);
    *w1 = sqrt(0.5 * (b - disc));
    *w2 = sqrt(0.5 * (b + disc));
}

int main(void)
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
    TU_CHECK(eig_solve(2, &M, &C, &K, 1, 2, &e) == SM_OK, "eig_solve 2x2");
    TU_NEAR(e.wim[0], w1, 1e-12, "gyroscopic w1");
    TU_NEAR(e.wim[1], w2, 1e-12, "gyroscopic w2");
    TU_CHECK(e.negative == 0 && e.max_re == 0, "stable system flagged");
    eig_out_free(&e);
    TU_CHECK(eig_solve(2, &M, &C, &K, 0, 2, &e) == SM_OK, "eig_solve undamped");
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
    TU_CHECK(eig_solve(3, &M, &C, &K, 1, 2, &e) == SM_OK, "eig_solve with a massless coordinate");
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
    TU_CHECK(eig_solve(3, &M, &C, &K, 1, 2, &e) == SM_OK, "eig_solve unstable");
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
    return tu_finish("eigen");
}
