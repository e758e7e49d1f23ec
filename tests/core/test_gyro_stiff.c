/*
 * test_gyro_stiff.c — the gyroscopic eigen-solve (eigen.c, Hermitian route) on problems whose
 * stiffness spans many decades, where the lowest frequencies must stay accurate relative to
 * themselves (DESIGN.md 9.4, "Found on the way"):
 *   1. a rotating spring-mass chain, stiff along x (kx = 1e12) and soft along y (ky = 4000),
 *      each mass coupled x-y by Coriolis (g = 2 Omega m).  M, K and C commute with the chain
 *      matrix T (fixed-free, eigenvalues t_j = 4 sin^2((2j - 1) pi / (2 (2N + 1)))), so each
 *      chain mode is a 2x2 block (k1, k2, g) = (kx t_j, ky t_j, g) with the closed-form roots
 *      w^4 - (k1 + k2 + g^2) w^2 + k1 k2 = 0: w_max^2 / w_1^2 ~ 1e13.  Tolerance 1e-10
 *      relative on the 8 lowest (the solve from the squared form S'S lost ~1e-3); with
 *      g = 0, Coriolis on equals Coriolis off to 1e-12;
 *   2. the spatial Wright blade of test_estimate (EA = 1e14, no flapwise rotary inertia; and a
 *      realistic EA = 1e10), 48 and 64 elements: at rest (C* = 0) Coriolis on must equal
 *      Coriolis off to 1e-9 relative (was 8.7e-4 and 6e-3 at EA = 1e14); at lambda = Omega =
 *      12 the four lowest modes are flap modes, on which Coriolis does not act, and must equal
 *      Coriolis off to 1e-9 too (was up to 1.6e-5; 5.7e-5 at EA = 1e10).
 */
#include "internal.h"

#include "testutil.h"

#define PI 3.14159265358979323846L

/* The two roots w of the block (k1, k2, g), without cancellation. */
static void gs_roots(long double k1, long double k2, long double g, long double w[2])
{
    long double b = k1 + k2 + g * g, disc = sqrtl((k1 - k2) * (k1 - k2) + g * g * (2 * k1 + 2 * k2 + g * g));
    long double hi = 0.5L * (b + disc);
    w[0] = sqrtl(k1 * k2 / hi);
    w[1] = sqrtl(hi);
}

static int gs_cmp(const void *a, const void *b)
{
    long double x = *(const long double *)a, y = *(const long double *)b;
    return (x > y) - (x < y);
}

/* Chain of nn masses (m = 1), coordinates (x_i, y_i); the lowest `modes` against closed form. */
static void gs_chain(int nn, double kx, double ky, double g, int modes, double tol)
{
    int n = 2 * nn;
    dmat M = {0}, C = {0}, K = {0};
    long double *want = calloc(2 * (size_t)nn, sizeof(long double));
    sm_eig_out on = {0}, off = {0};
    if (dm_alloc(&M, n, n) || dm_alloc(&C, n, n) || dm_alloc(&K, n, n) || !want) {
        TU_CHECK(0, "allocation");
        goto done;
    }
    for (int i = 0; i < nn; i++) {
        int x = 2 * i, y = 2 * i + 1;
        DM(&M, x, x) = DM(&M, y, y) = 1.0;
        DM(&C, x, y) = -g;
        DM(&C, y, x) = g;
        double d = i + 1 < nn ? 2.0 : 1.0; /* fixed at 0, free at nn - 1 */
        DM(&K, x, x) = d * kx;
        DM(&K, y, y) = d * ky;
        if (i + 1 < nn) {
            DM(&K, x, x + 2) = DM(&K, x + 2, x) = -kx;
            DM(&K, y, y + 2) = DM(&K, y + 2, y) = -ky;
        }
    }
    for (int j = 1; j <= nn; j++) {
        long double s = sinl((2 * j - 1) * PI / (2 * (2 * nn + 1))), t = 4 * s * s;
        gs_roots(kx * t, ky * t, g, want + 2 * (j - 1));
    }
    qsort(want, 2 * (size_t)nn, sizeof *want, gs_cmp);
    int rc = eig_solve(n, &M, &C, &K, 1, modes, 0, &on);
    TU_CHECK(rc == SM_OK && on.n_modes == modes, "chain %d, g %g: eig_solve %d", nn, g, rc);
    if (rc != SM_OK)
        goto done;
    double worst = 0;
    for (int k = 0; k < modes; k++) {
        double e = fabs(on.wim[k] - (double)want[k]) / (double)want[k];
        worst = fmax(worst, e);
        TU_CHECK(e <= tol && on.wre[k] == 0, "chain %d, g %g, mode %d: w %.15g want %.15Lg (rel %.2e)", nn, g,
                 k + 1, on.wim[k], want[k], e);
    }
    printf("chain %d masses, kx %g, ky %g, g %g: w1 %.12f (want %.12Lf), worst relative error of %d "
           "modes %.2e (tol %.0e)\n",
           nn, kx, ky, g, on.wim[0], want[0], modes, worst, tol);
    if (g == 0) { /* C = 0: the gyroscopic route must give the undamped one */
        rc = eig_solve(n, &M, &C, &K, 0, modes, 0, &off);
        TU_CHECK(rc == SM_OK, "chain undamped: %d", rc);
        for (int k = 0; rc == SM_OK && k < modes; k++)
            TU_NEAR(on.wim[k], off.wim[k], 1e-12 * off.wim[k], "chain %d, C = 0, mode %d on vs off", nn, k + 1);
    }
done:
    eig_out_free(&on);
    eig_out_free(&off);
    dm_free(&M);
    dm_free(&C);
    dm_free(&K);
    free(want);
}

/* The Wright blade (test_estimate.c, est_wright): L = 31.623 m, mu = 100, EI_flap = GJ = 1e8,
 * EI_edge = 1e12, i_flap = 0, i_edge = 1e-3; n elements; the four lowest frequencies at
 * omega with Coriolis on and off must agree to tol (relative). */
static void gs_wright(int n, double EA, double omega, double tol)
{
    double xy[4] = {0, 0, 31.623, 0}, z[2] = {0, 0}, w[2][4] = {{0}};
    sm_section sec;
    memset(&sec, 0, sizeof sec);
    sec.EA = EA;
    sec.EI_flap = 1e8;
    sec.EI_edge = 1e12;
    sec.GJ = 1e8;
    sec.mu = 100.0;
    sec.i_flap = 0.0;
    sec.i_edge = 1e-3;
    sec.ip_over_a = (sec.i_flap + sec.i_edge) / sec.mu;
    sm_member mem = {0, 1, 0, n};
    sm_structure st;
    memset(&st, 0, sizeof st);
    st.n_joints = 2;
    st.joint_xy = xy;
    st.joint_z = z;
    st.n_sections = 1;
    st.sections = &sec;
    st.n_members = 1;
    st.members = &mem;
    st.spatial = 1;
    for (int cor = 0; cor < 2; cor++) {
        sm_options o;
        sm_default_options(&o);
        o.modes = 4;
        o.coriolis = cor;
        sm_result *r = tu_solve1(&st, &o, omega, NULL);
        TU_CHECK(r && r->cases[0].status == SM_CASE_SOLVED && r->cases[0].n_modes == 4,
                 "Wright blade %d elements, EA %g, Omega %g, Coriolis %d solved", n, EA, omega, cor);
        if (!r || r->cases[0].n_modes < 4) {
            sm_result_free(r);
            return;
        }
        for (int k = 0; k < 4; k++)
            w[cor][k] = r->cases[0].frequency[k];
        sm_result_free(r);
    }
    double worst = 0;
    for (int k = 0; k < 4; k++) {
        double e = fabs(w[1][k] - w[0][k]) / w[0][k];
        worst = fmax(worst, e);
        TU_CHECK(e <= tol, "Wright blade %d elements, EA %g, Omega %g, mode %d: Coriolis %.12f, without %.12f "
                 "(rel %.2e)", n, EA, omega, k + 1, w[1][k], w[0][k], e);
    }
    printf("Wright blade %2d elements, EA %g, Omega %4g: w1 %.10f, Coriolis on vs off: worst relative "
           "difference of 4 modes %.2e (tol %.0e)\n",
           n, EA, omega, w[1][0], worst, tol);
}

int main(void)
{
    gs_chain(100, 1e12, 4000.0, 1.0, 8, 1e-10);
    gs_chain(100, 1e12, 4000.0, 0.0, 8, 1e-10);
    gs_chain(40, 1e6, 4000.0, 30.0, 8, 1e-10); /* Coriolis acts strongly; a mild spread */
    const int meshes[2] = {48, 64};
    for (int i = 0; i < 2; i++)
        for (int e = 0; e < 2; e++) {
            double EA = e ? 1e10 : 1e14;
            gs_wright(meshes[i], EA, 0.0, 1e-9);
            gs_wright(meshes[i], EA, 12.0, 1e-9);
        }
    return tu_finish("gyro_stiff");
}
