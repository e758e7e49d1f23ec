/*
 * test_augmented.c — the augmented basis (default):
 *  - at Omega = 0, identical frequencies (1e-6 relative) for every frame
 *    scheme, equal to the plain FE (single frame, all modes);
 *  - at beta = 90, Omega = 20, per-element frames within 0.5 % of the
 *    FE48_lumped_linear row of angled_beam_exact.csv with and without Coriolis,
 *    steady free end within 1 cm;
 *  - every augmented row of multiframe_checkpoints.csv to 1e-4 relative.
 */
#include "testutil.h"

static sm_case *solve(sm_options *o, double beta, double om, sm_model **m, sm_result **r)
{
    tu_angled a;
    tu_angled_beam(&a, beta, 24, 24);
    *r = tu_solve1(&a.st, o, om, m);
    return *r ? &(*r)->cases[0] : NULL;
}

int main(int argc, char **argv)
{
    tu_csv ex, ck;
    if (tu_ref_read(argc, argv, "angled_beam_exact.csv", &ex) < 0)
        return 1;
    if (tu_ref_read(argc, argv, "multiframe_checkpoints.csv", &ck) < 0)
        return 1;
    sm_model *m;
    sm_result *r;
    sm_options o;
    /* Omega = 0: every scheme equals the plain FE */
    for (int beta = 0; beta <= 90; beta += 45) {
        sm_default_options(&o);
        o.frames = SM_FRAMES_SINGLE;
        o.modes = 5;
        sm_case *ref = solve(&o, beta, 0, &m, &r);
        double fe[5];
        for (int j = 0; j < 5; j++)
            fe[j] = ref->frequency[j];
        sm_result_free(r);
        sm_model_free(m);
        sm_frame_scheme fs[3] = {SM_FRAMES_PER_MEMBER, SM_FRAMES_ELEMENTS_PER_FRAME, SM_FRAMES_PER_ELEMENT};
        int par[3] = {4, 5, 1};
        for (int f = 0; f < 3; f++)
            for (int cor = 0; cor < 2; cor++) {
                o.frames = fs[f];
                o.frames_param = par[f];
                o.coriolis = cor;
                sm_case *c = solve(&o, beta, 0, &m, &r);
                double worst = 0;
                for (int j = 0; j < 5; j++)
                    worst = fmax(worst, fabs(c->frequency[j] / fe[j] - 1));
                TU_CHECK(worst < 1e-6, "beta %d scheme %d coriolis %d: Omega=0 differs from FE by %.2e", beta,
                         fs[f], cor, worst);
                printf("ok   beta %d scheme %d/%d coriolis %d at rest: max rel. diff to FE %.1e\n", beta, fs[f],
                       par[f], cor, worst);
                sm_result_free(r);
                sm_model_free(m);
            }
    }
    /* per-element frames vs the geometrically exact FE48 at beta 90, Omega 20 */
    int row = -1;
    for (int i = 0; i < ex.rows; i++)
        if (tu_csv_num(&ex, i, "beta_deg") == 90 && tu_csv_num(&ex, i, "omega") == 20 &&
            !strcmp(tu_csv_get(&ex, i, "source"), "FE48_lumped_linear"))
            row = i;
    TU_CHECK(row >= 0, "FE48 row present");
    for (int cor = 0; row >= 0 && cor < 2; cor++) {
        sm_default_options(&o);
        o.coriolis = cor;
        sm_case *c = solve(&o, 90, 20, &m, &r);
        int tip = sm_model_joint_node(m, 2);
        for (int j = 0; j < 3; j++) {
            char col[32];
            snprintf(col, sizeof col, "w%d_%s", j + 1, cor ? "coriolis" : "no_coriolis");
            double want = tu_csv_num(&ex, row, col);
            TU_NEAR(c->frequency[j], want, 5e-3 * want, "per-element vs FE48 %s", col);
        }
        TU_NEAR(c->nodes[3 * tip], tu_csv_num(&ex, row, "tip_X1"), 0.01, "free end X1");
        TU_NEAR(c->nodes[3 * tip + 1], tu_csv_num(&ex, row, "tip_X2"), 0.01, "free end X2");
        sm_result_free(r);
        sm_model_free(m);
    }
    /* the multi-frame checkpoints, augmented rows */
    for (int k = 0; k < ck.rows; k++) {
        if (strcmp(tu_csv_get(&ck, k, "basis"), "augmented"))
            continue;
        int rf = (int)tu_csv_num(&ck, k, "RF");
        int cor = !strcmp(tu_csv_get(&ck, k, "coriolis"), "on");
        sm_default_options(&o);
        o.frames = rf == 48 ? SM_FRAMES_PER_ELEMENT : SM_FRAMES_PER_MEMBER;
        o.frames_param = rf == 48 ? 1 : rf / 2;
        o.coriolis = cor;
        sm_case *c = solve(&o, 90, 20, &m, &r);
        int tip = sm_model_joint_node(m, 2);
        for (int j = 0; j < 3; j++) {
            char col[8];
            snprintf(col, sizeof col, "w%d", j + 1);
            double want = tu_csv_num(&ck, k, col);
            TU_NEAR(c->frequency[j], want, 1e-4 * want, "augmented RF %d coriolis %d %s", rf, cor, col);
        }
        TU_NEAR(c->nodes[3 * tip], tu_csv_num(&ck, k, "tip_x"), 1e-4, "augmented RF %d tip x", rf);
        TU_NEAR(c->nodes[3 * tip + 1], tu_csv_num(&ck, k, "tip_y"), 1e-4, "augmented RF %d tip y", rf);
        sm_result_free(r);
        sm_model_free(m);
    }
    tu_csv_free(&ex);
    tu_csv_free(&ck);
    return tu_finish("augmented");
}
