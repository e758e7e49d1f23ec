/*
 * test_tree_solve.c — sm_solve through the dense path and the tree path
 * (sm_options.solver forced) on the same requests: frequencies, eigenvalues,
 * stability, equilibrium node positions and axial forces and mode shapes must
 * agree to 1e-9 relative (shapes: 1e-7 of the unit maximum).  Covers
 * per-element, per-member and elements-per-frame schemes, augmented and paper
 * bases, lumped and consistent mass, Coriolis on and off, sweeps with
 * continuation, an unstable steady state (the tree eigen-analysis hands it to
 * the dense path) and a speed without equilibrium.  Also the automatic
 * choice: dense for the 48-element beam, tree for 192+ elements.
 */
#include "pathcmp.h"

int main(void)
{
    tu_angled ab;
    sm_options o;
    double w20 = 20, sweep[5] = {0, 5, 10, 15, 20}, fast[2] = {10, 40};
    tu_angled_beam(&ab, 90, 24, 24);
    sm_default_options(&o);
    compare("(a) per-element augmented Coriolis", &ab.st, &o, &w20, 1, 1e-9);
    o.modes = 8;
    compare("per-element 8 modes", &ab.st, &o, sweep, 5, 1e-9);
    o.modes = 3;
    o.coriolis = 0;
    compare("per-element no Coriolis", &ab.st, &o, sweep, 5, 1e-9);
    sm_default_options(&o);
    o.frames = SM_FRAMES_PER_MEMBER;
    o.frames_param = 8;
    o.basis = SM_BASIS_PAPER;
    o.coriolis = 0;
    compare("(b) RF16 paper no Coriolis", &ab.st, &o, &w20, 1, 1e-9);
    o.frames_param = 1;
    o.geometric_stiffening = 0;
    compare("RF2 paper no stiffening (unstable or no equilibrium)", &ab.st, &o, sweep, 5, 1e-9);
    o.frames_param = 2;
    compare("RF4 paper no stiffening", &ab.st, &o, sweep, 5, 1e-9);
    o.frames_param = 3;
    compare("RF6 paper no stiffening", &ab.st, &o, sweep, 5, 1e-9);
    sm_default_options(&o);
    o.frames = SM_FRAMES_PER_MEMBER;
    o.frames_param = 4;
    compare("per-member 4 augmented", &ab.st, &o, sweep, 5, 1e-9);
    sm_default_options(&o);
    o.mass = SM_MASS_CONSISTENT;
    o.frames = SM_FRAMES_ELEMENTS_PER_FRAME;
    o.frames_param = 3;
    /* Consistent mass: today's dense gyroscopic solve is only accurate to ~1e-7 here (residuals
     * ||(l^2 M + l C + K) x|| / (|l|^2 ||Mx|| + |l| ||Cx|| + ||Kx||) of 3.5e-9, 2.5e-8, 2.2e-7 for
     * w1..w3 with the dense matrices), the tree path to 1e-14 (7e-15, 3e-14, 8e-13): the
     * comparison can only be as close as the dense error. */
    compare("elements-per-frame 3 consistent", &ab.st, &o, &w20, 1, 1e-5);
    sm_default_options(&o);
    o.frames = SM_FRAMES_SINGLE;
    compare("single frame beyond its equilibrium", &ab.st, &o, fast, 2, 1e-9);
    tu_angled_beam(&ab, 45, 96, 96);
    sm_default_options(&o);
    compare("beta 45, 96+96 per-element sweep", &ab.st, &o, sweep, 5, 1e-9);

    /* the tree path's fallback to the dense eigen-analysis is capped by max_dense_coordinates: on
     * the RF 2 paper basis with more modes than n / 4 (the tree path hands every speed over)
     * a cap below n ends each converged speed eigen_failed with the reason and the equilibrium
     * kept; a cap at n gives the dense answers */
    tu_angled_beam(&ab, 90, 24, 24);
    for (int cap = 1; cap <= 2; cap++) {
        sm_default_options(&o);
        o.frames = SM_FRAMES_PER_MEMBER;
        o.frames_param = 1;
        o.basis = SM_BASIS_PAPER;
        o.coriolis = 0;
        sm_result *rd = NULL, *rt = NULL;
        sm_model *md = NULL, *mt = NULL;
        TU_CHECK(sm_model_new(&md, &ab.st, &o, NULL) == SM_OK, "RF2 model");
        o.modes = md->n / 4 + 1; /* more than the tree eigen-analysis takes: it hands over */
        sm_model_free(md);
        md = NULL;
        TU_CHECK(sm_model_new(&md, &ab.st, &o, NULL) == SM_OK && sm_solve(md, sweep, 5, NULL, NULL, &rd, NULL) == SM_OK,
                 "RF2 dense");
        o.solver = SM_SOLVER_TREE;
        o.max_dense_coordinates = cap == 1 ? 1 : md->n;
        TU_CHECK(sm_model_new(&mt, &ab.st, &o, NULL) == SM_OK && sm_solve(mt, sweep, 5, NULL, NULL, &rt, NULL) == SM_OK,
                 "RF2 tree, dense fallback capped at %d", o.max_dense_coordinates);
        for (int i = 0; rd && rt && i < 5; i++) {
            const sm_case *a = &rd->cases[i], *b = &rt->cases[i];
            if (a->status != SM_CASE_SOLVED)
                continue;
            if (cap == 1) {
                printf("RF2 W=%g cap 1: %s\n", sweep[i], b->message);
                TU_CHECK(b->status == SM_CASE_EIGEN_FAILED && strstr(b->message, "limited to 1 coordinates") &&
                             b->converged && b->nodes && b->n_modes == 0,
                         "RF2 W=%g: capped: eigen_failed with the reason, the equilibrium kept", sweep[i]);
            } else {
                TU_CHECK(b->status == SM_CASE_SOLVED && fabs(b->frequency[0] - a->frequency[0]) <= 1e-9 * a->frequency[0],
                         "RF2 W=%g: cap at n: the dense answer", sweep[i]);
            }
        }
        sm_result_free(rd);
        sm_result_free(rt);
        sm_model_free(md);
        sm_model_free(mt);
    }

    /* the automatic choice */
    sm_model *m = NULL;
    tu_angled_beam(&ab, 90, 24, 24);
    sm_default_options(&o);
    TU_CHECK(sm_model_new(&m, &ab.st, &o, NULL) == SM_OK && !tree_use(m), "48 elements: dense");
    sm_model_free(m);
    tu_angled_beam(&ab, 90, 96, 96);
    TU_CHECK(sm_model_new(&m, &ab.st, &o, NULL) == SM_OK && tree_use(m), "192 elements: tree");
    sm_model_free(m);
    o.frames = SM_FRAMES_SINGLE;
    TU_CHECK(sm_model_new(&m, &ab.st, &o, NULL) == SM_OK && !tree_use(m), "192 elements, one frame: dense");
    sm_model_free(m);
    printf("largest relative differences tree vs dense: frequencies %.2e, equilibrium %.2e, shapes/MAC %.2e\n",
           tu_max_freq, tu_max_eq, tu_max_shape);
    return tu_finish("tree_solve");
}
