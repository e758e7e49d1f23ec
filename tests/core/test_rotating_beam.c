/*
 * test_rotating_beam.c — straight beam rotating about its clamped end (hub
 * radius 0), very large EA, Coriolis off: the in-plane (chordwise) bending
 * frequencies obey w_inplane^2 = w_flap^2 - lambda^2 with the flapwise table
 * of Wright et al. (1982) in cantilever.csv (dimensionless, lambda =
 * Omega sqrt(mu L^4/EI)).  48 lumped elements, per-element frames: 0.3 %.
 */
#include "testutil.h"

int main(int argc, char **argv)
{
    tu_csv c;
    if (tu_ref_read(argc, argv, "cantilever.csv", &c) < 0)
        return 1;
    double L = 10, EI = 7e10 * 2e-7, mu = 1.2, t = sqrt(mu * L * L * L * L / EI);
    double xy[4] = {0, 0, L, 0};
    sm_section sec = {7e10, 4e-4 * 1e4, 2e-7, mu}; /* EA x 1e4: axially rigid */
    sm_member mem = {0, 1, 0, 48};
    sm_structure st = {2, xy, 1, &sec, 1, &mem, 0, NULL, 0};
    sm_options o;
    sm_default_options(&o);
    o.coriolis = 0;
    for (int i = 0; i < c.rows; i++) {
        if (strcmp(tu_csv_get(&c, i, "kind"), "flap"))
            continue;
        double lam = tu_csv_num(&c, i, "lambda");
        sm_result *r = tu_solve1(&st, &o, lam / t, NULL);
        TU_CHECK(r && r->cases[0].status == SM_CASE_SOLVED, "lambda %g solved", lam);
        if (!r)
            continue;
        for (int j = 0; j < 3; j++) {
            char col[4];
            snprintf(col, sizeof col, "w%d", j + 1);
            double wf = tu_csv_num(&c, i, col), want = sqrt(wf * wf - lam * lam);
            TU_NEAR(r->cases[0].frequency[j] * t, want, 3e-3 * want, "lambda %2g in-plane w%d", lam, j + 1);
        }
        sm_result_free(r);
    }
    tu_csv_free(&c);
    return tu_finish("rotating_beam");
}
