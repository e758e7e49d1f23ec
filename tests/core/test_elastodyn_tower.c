/*
 * test_elastodyn_tower.c — a degenerate fore-aft/side-side pair (DESIGN §B): a symmetric
 * tower's first two modes share a frequency, and an eigensolver may return any two orthogonal
 * mixtures of them.  Made-up shapes: mode 0 = (FA y, SS y), mode 1 = (FA y, SS -y) at 45
 * degrees, both with half their energy in each direction, at the same frequency; mode 2, 3 the
 * second pair, pure.  Without sm_elastodyn_degenerate neither mixture is dominated by either
 * direction (a > b is strict), so FA 1 / SS 1 fall to the second pair; with it, mode 0 is pure
 * fore-aft and mode 1 pure side-side, each the cantilever shape y.
 */
#include "testutil.h"

#define NN 21
#define NM 4

/* The made-up case: x, shapes (mode k, direction d, node j), energies, frequencies. */
static void tw_case(double *x, double *re, double *energy, double *freq)
{
    int j, k, p;

    for (j = 0; j < NN; j++) {
        double s = (double)j / (NN - 1), y1 = s * s * (3 - s) / 2, y2 = s * s * (1 - s) + s * s * s;
        x[j] = s;
        re[(0 * 2 + 0) * NN + j] = y1; /* mode 0: FA + SS */
        re[(0 * 2 + 1) * NN + j] = y1;
        re[(1 * 2 + 0) * NN + j] = y1; /* mode 1: FA - SS */
        re[(1 * 2 + 1) * NN + j] = -y1;
        re[(2 * 2 + 0) * NN + j] = y2; /* mode 2: FA only */
        re[(2 * 2 + 1) * NN + j] = 0;
        re[(3 * 2 + 0) * NN + j] = 0; /* mode 3: SS only */
        re[(3 * 2 + 1) * NN + j] = y2;
    }
    for (k = 0; k < NM; k++)
        for (p = 0; p < SM_ENERGY_PARTS; p++) {
            int part = p % (SM_ENERGY_PARTS / 2);
            double flap = k < 2 ? 0.5 : k == 2 ? 1 : 0;
            energy[k * SM_ENERGY_PARTS + p] = part == SM_MODE_FLAP   ? flap
                                              : part == SM_MODE_EDGE ? 1 - flap
                                                                     : 0;
        }
    freq[0] = freq[1] = 0.3366; /* the pair */
    freq[2] = freq[3] = 3.07;
}

int main(void)
{
    static const int want[2] = {2, 2};
    double x[NN], re[NM * 2 * NN], energy[NM * SM_ENERGY_PARTS], freq[NM];
    sm_ed_fit fits[4];
    sm_ed_shapes s;
    int k;

    tw_case(x, re, energy, freq);
    s = (sm_ed_shapes){NM, NN, x, re, NULL, NULL, NULL, energy, {SM_MODE_FLAP, SM_MODE_EDGE}};
    /* before: the mixtures qualify for neither direction */
    TU_CHECK(sm_elastodyn_fit_modes(&s, want, fits) == SM_OK, "fit without rotation");
    TU_CHECK(fits[0].mode == 2 && fits[2].mode == 3,
             "without the rotation FA 1 / SS 1 fall to modes %d / %d (the second pair)",
             fits[0].mode, fits[2].mode);
    /* the rotation: one pair (0, 1); the second pair is not degenerate with the first */
    TU_CHECK(sm_elastodyn_degenerate(&s, freq) == 2, "two degenerate pairs rotated");
    TU_CHECK(sm_elastodyn_fit_modes(&s, want, fits) == SM_OK, "fit after rotation");
    TU_CHECK(fits[0].mode == 0 && fits[1].mode == 2 && fits[2].mode == 1 && fits[3].mode == 3,
             "FA 1, FA 2, SS 1, SS 2 = modes 0, 2, 1, 3 (got %d %d %d %d)", fits[0].mode,
             fits[1].mode, fits[2].mode, fits[3].mode);
    for (k = 0; k < 4; k++)
        TU_CHECK(fits[k].share > 0.999999 && !fits[k].warning, "fit %d pure (share %g)", k,
                 fits[k].share);
    for (k = 0; k < 5; k++) /* both first modes are y1 = (3 x^2 - x^3) / 2 */
        TU_NEAR(fits[0].coef[k], fits[2].coef[k], 1e-12, "FA 1 = SS 1, C%d", k + 2);
    TU_NEAR(fits[0].coef[0], 1.5, 1e-12, "C2 of (3 x^2 - x^3)/2");
    TU_NEAR(fits[0].coef[1], -0.5, 1e-12, "C3 of (3 x^2 - x^3)/2");
    /* a pair apart by more than SM_ED_DEGENERATE is left alone */
    tw_case(x, re, energy, freq);
    freq[1] = freq[0] * (1 + 2 * SM_ED_DEGENERATE);
    freq[2] = 3.07, freq[3] = 3.08;
    TU_CHECK(sm_elastodyn_degenerate(&s, freq) == 0, "no pair rotated at a gap of 2e-4");
    return tu_finish("elastodyn_tower");
}
