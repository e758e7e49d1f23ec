/*
 * test_mac.c — MAC between two sets of mode shapes that need not share a mesh (sm_mac,
 * core/post/mac.c, DESIGN.md 9.2).
 *
 * The shapes are the clamped-free Euler-Bernoulli beam modes, in closed form
 * (phi_k = cosh bx - cos bx - s_k (sinh bx - sin bx), s_k = (cosh b + cos b)/(sinh b + sin b),
 * b = beta_k L = 1.8751, 4.6941, 7.8548, 10.9955: Blevins, Formulas for Natural Frequency and
 * Mode Shape, table 8-1), sampled at 61 even points (a fine mesh) and at BModes' Test01
 * stations (13 uneven points), two components per point (mode k in the first, a tenth of it
 * in the second).
 *  1. A set against itself: diagonal 1 to 1e-12, symmetric, by index.
 *  2. Fine against coarse: the fine set is interpolated (how = SM_MAC_INTERPOLATED_A) and
 *     the table agrees with the exact MAC of the shapes at the coarse points to 1e-3; the
 *     diagonal >= 0.999.  The reverse order gives the transpose (SM_MAC_INTERPOLATED_B).
 *  3. A complex multiple of a shape (any phase) has MAC 1 with it.
 *  4. Refusals with a reason: different components, different member counts, different
 *     point counts without span positions, a point outside the other's span, no modes,
 *     span fractions that do not ascend.
 */
#include "testutil.h"

static const double mac_beta[4] = {1.875104068711961, 4.694091132974175, 7.854757438237613,
                                   10.99554073487547};

/* Clamped-free mode k at x in [0, 1]. */
static double mac_phi(int k, double x)
{
    double b = mac_beta[k], s = (cosh(b) + cos(b)) / (sinh(b) + sin(b));
    return cosh(b * x) - cos(b * x) - s * (sinh(b * x) - sin(b * x));
}

/* 4 modes at the n points s into re (4 * n * 2 values). */
static void mac_sample(int n, const double *s, double *re)
{
    for (int k = 0; k < 4; k++)
        for (int p = 0; p < n; p++) {
            re[(k * n + p) * 2] = mac_phi(k, s[p]);
            re[(k * n + p) * 2 + 1] = 0.1 * mac_phi(k, s[p]);
        }
}

static const double mac_bm_s[13] = {0,    0.08, 0.16, 0.24, 0.32, 0.40, 0.48,
                                    0.56, 0.64, 0.72, 0.80, 0.90, 1.0};

static void self_and_meshes(void)
{
    double fs[61], fre[4 * 61 * 2], cre[4 * 13 * 2], mac[16], exact[16], macT[16];
    int how = -1, i, j;
    char why[200];
    for (i = 0; i < 61; i++)
        fs[i] = i / 60.0;
    mac_sample(61, fs, fre);
    mac_sample(13, mac_bm_s, cre);
    sm_mac_shapes f = {4, 61, 2, 1, NULL, fs, fre, NULL},
                  c = {4, 13, 2, 1, NULL, mac_bm_s, cre, NULL};

    TU_CHECK(sm_mac(&f, &f, mac, &how, why, sizeof why) == SM_OK && how == SM_MAC_BY_INDEX,
             "self: by index (%s)", why);
    for (i = 0; i < 4; i++)
        for (j = 0; j < 4; j++) {
            if (i == j)
                TU_NEAR(mac[i * 4 + j], 1.0, 1e-12, "self MAC(%d,%d)", i + 1, j + 1);
            TU_CHECK(fabs(mac[i * 4 + j] - mac[j * 4 + i]) < 1e-14, "self: symmetric");
        }
    TU_CHECK(sm_mac(&c, &c, exact, &how, why, sizeof why) == SM_OK, "coarse self");
    TU_CHECK(sm_mac(&f, &c, mac, &how, why, sizeof why) == SM_OK && how == SM_MAC_INTERPOLATED_A,
             "fine vs coarse: the fine set interpolated (how %d, %s)", how, why);
    for (i = 0; i < 4; i++) {
        TU_CHECK(mac[i * 4 + i] >= 0.999, "fine vs coarse: diagonal %d = %.6f", i + 1, mac[i * 5]);
        for (j = 0; j < 4; j++)
            TU_CHECK(fabs(mac[i * 4 + j] - exact[i * 4 + j]) < 1e-3,
                     "fine vs coarse (%d,%d): %.6f, exact at the coarse points %.6f", i + 1, j + 1,
                     mac[i * 4 + j], exact[i * 4 + j]);
    }
    printf("fine vs coarse diagonal: %.6f %.6f %.6f %.6f\n", mac[0], mac[5], mac[10], mac[15]);
    TU_CHECK(sm_mac(&c, &f, macT, &how, why, sizeof why) == SM_OK && how == SM_MAC_INTERPOLATED_B,
             "coarse vs fine: B interpolated");
    for (i = 0; i < 4; i++)
        for (j = 0; j < 4; j++)
            TU_CHECK(fabs(macT[j * 4 + i] - mac[i * 4 + j]) < 1e-14, "reversed: the transpose");
}

static void complex_phase(void)
{
    double s[13], re[4 * 13 * 2], ure[4 * 13 * 2], uim[4 * 13 * 2], mac[16];
    int how;
    memcpy(s, mac_bm_s, sizeof s);
    mac_sample(13, s, re);
    for (int v = 0; v < 4 * 13 * 2; v++) { /* times 2.5 e^{0.7 i} */
        ure[v] = 2.5 * cos(0.7) * re[v];
        uim[v] = 2.5 * sin(0.7) * re[v];
    }
    sm_mac_shapes a = {4, 13, 2, 1, NULL, s, re, NULL}, b = {4, 13, 2, 1, NULL, s, ure, uim};
    TU_CHECK(sm_mac(&a, &b, mac, &how, NULL, 0) == SM_OK, "complex");
    for (int i = 0; i < 4; i++)
        TU_NEAR(mac[i * 5], 1.0, 1e-12, "complex multiple, mode %d", i + 1);
}

static void refusals(void)
{
    double s[13], re[4 * 13 * 2], fs[61], fre[4 * 61 * 2], mac[16], bad_s[13];
    int seg2[3] = {0, 30, 61};
    char why[200];
    memcpy(s, mac_bm_s, sizeof s);
    for (int i = 0; i < 61; i++)
        fs[i] = i / 60.0;
    mac_sample(13, s, re);
    mac_sample(61, fs, fre);
    sm_mac_shapes a = {4, 13, 2, 1, NULL, s, re, NULL}, b;

    b = a, b.n_comp = 3;
    TU_CHECK(sm_mac(&a, &b, mac, NULL, why, sizeof why) == SM_INVALID_INPUT &&
                 strstr(why, "components"),
             "different components: %s", why);
    b = (sm_mac_shapes){4, 61, 2, 2, seg2, fs, fre, NULL};
    TU_CHECK(sm_mac(&a, &b, mac, NULL, why, sizeof why) == SM_INVALID_INPUT &&
                 strstr(why, "different structures"),
             "different members: %s", why);
    b = (sm_mac_shapes){4, 61, 2, 1, NULL, NULL, fre, NULL};
    TU_CHECK(sm_mac(&a, &b, mac, NULL, why, sizeof why) == SM_INVALID_INPUT &&
                 strstr(why, "no span positions"),
             "no s: %s", why);
    for (int i = 0; i < 61; i++)
        fs[i] = 0.5 * i / 60.0; /* the fine set covers only half the span */
    b = (sm_mac_shapes){4, 61, 2, 1, NULL, fs, fre, NULL};
    TU_CHECK(sm_mac(&a, &b, mac, NULL, why, sizeof why) == SM_INVALID_INPUT &&
                 strstr(why, "outside"),
             "outside the span: %s", why);
    b = a, b.n_modes = 0;
    TU_CHECK(sm_mac(&a, &b, mac, NULL, why, sizeof why) == SM_INVALID_INPUT &&
                 strstr(why, "no mode shapes"),
             "no modes: %s", why);
    memcpy(bad_s, s, sizeof bad_s);
    bad_s[5] = 0.9;
    b = (sm_mac_shapes){4, 61, 2, 1, NULL, fs, fre, NULL};
    for (int i = 0; i < 61; i++)
        fs[i] = i / 60.0;
    a.s = bad_s;
    TU_CHECK(sm_mac(&a, &b, mac, NULL, why, sizeof why) == SM_INVALID_INPUT &&
                 strstr(why, "ascend"),
             "s not ascending: %s", why);
}

int main(void)
{
    self_and_meshes();
    complex_phase();
    refusals();
    return tu_finish("mac");
}
