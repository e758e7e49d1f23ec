/*
 * test_equilibrium.c — Newton-Raphson on a problem with a known answer: a
 * radial bar rotating about its clamped end stretches by
 *   u(L) = mu Omega^2 L^3 / (3 EA)  (continuum),
 * and with bending absent the lowest in-plane frequency is unaffected by it.
 * Checked for every frame scheme; plus the FE48 row of angled_beam_exact.csv
 * at beta = 0 (tip X1 to 1e-7 m).
 */
#include "testutil.h"

int main(int argc, char **argv)
{
    tu_csv ex;
    if (tu_ref_read(argc, argv, "angled_beam_exact.csv", &ex) < 0)
        return 1;
    sm_frame_scheme fs[4] = {SM_FRAMES_SINGLE, SM_FRAMES_PER_MEMBER, SM_FRAMES_ELEMENTS_PER_FRAME,
                             SM_FRAMES_PER_ELEMENT};
    for (int f = 0; f < 4; f++) {
        tu_angled a;
        tu_angled_beam(&a, 0, 24, 24);
        sm_options o;
        sm_default_options(&o);
        o.frames = fs[f];
        o.frames_param = 3;
        o.coriolis = 0;
        for (int i = 0; i < ex.rows; i++) {
            if (tu_csv_num(&ex, i, "beta_deg") != 0 || strcmp(tu_csv_get(&ex, i, "source"), "FE48_lumped_linear"))
                continue;
            double om = tu_csv_num(&ex, i, "omega");
            if (om != 10 && om != 20)
                continue;
            sm_model *m;
            sm_result *r = tu_solve1(&a.st, &o, om, &m);
            TU_CHECK(r && r->cases[0].converged, "scheme %d omega %g converged", fs[f], om);
            if (!r)
                continue;
            int tip = sm_model_joint_node(m, 2);
            TU_NEAR(r->cases[0].nodes[3 * tip], tu_csv_num(&ex, i, "tip_X1"), 1e-7,
                    "scheme %d omega %g tip X1 vs FE48", fs[f], om);
            double cont = 10 + 1.2 * om * om * 1000 / (3 * 7e10 * 4e-4);
            TU_NEAR(r->cases[0].nodes[3 * tip], cont, 2e-5, "scheme %d omega %g tip X1 vs continuum", fs[f], om);
            TU_CHECK(r->cases[0].residual < 1e-6, "residual %g", r->cases[0].residual);
            sm_result_free(r);
            sm_model_free(m);
        }
    }
    tu_csv_free(&ex);
    return tu_finish("equilibrium");
}
