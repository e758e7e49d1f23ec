/*
 * test_gravity.c — gravity as a steady load at rest (sm_structure.gravity, DESIGN.md 8.8)
 * against closed forms of beams under axial load (Euler-Bernoulli; Timoshenko & Gere, Theory of
 * Elastic Stability, 1961, 1.11 and 2.7):
 *  1. a heavy tip mass M hanging from a light, clamped beam (tension T = M g): the tip stiffness
 *     of a beam under tension, k = T / (L - tanh(aL)/a), a = sqrt(T/EI), gives w^2 = k/M; from the
 *     bending beam (aL = 0.5) to the pendulum limit (aL = 20: w -> sqrt(g/L));
 *  2. the same mass standing on the beam (compression P = M g): k = P / (tan(bL)/b - L),
 *     b = sqrt(P/EI), up to bL = 1.4 (pi/2 buckles);
 *  3. buckling: a light column under a top mass is stable below P = pi^2 EI / (4 L^2) and
 *     unstable above (1 % either side); a uniform column under its own weight (Greenhill 1881:
 *     (mu g L^3 / EI)_cr = 7.837) likewise;
 *  4. refusals: a speed other than 0, a planar structure.
 * Lumped mass, per-element frames, augmented basis, geometric stiffening on, 60 elements.
 */
#include "testutil.h"

#define PI 3.14159265358979323846
#define GR_L 10.0
#define GR_EI 1.0e4

typedef struct gr_beam {
    double xy[4], z[2];
    sm_section sec;
    sm_member mem;
    sm_point_mass pm;
    sm_structure st;
} gr_beam;

/* A beam from the clamp at the origin to (0, L, 0) with a tip mass M, gravity g along hub y
 * (g > 0: hanging, the weight pulls away from the clamp; g < 0: standing). */
static void gr_init(gr_beam *b, double mu, double M, double g)
{
    memset(b, 0, sizeof *b);
    b->xy[3] = GR_L;
    b->sec.EA = 1e6 * GR_EI;
    b->sec.EI_flap = GR_EI;
    b->sec.EI_edge = 3 * GR_EI;
    b->sec.GJ = GR_EI;
    b->sec.mu = mu;
    b->sec.i_flap = b->sec.i_edge = 1e-9 * mu;
    b->sec.ip_over_a = 2e-9;
    b->mem.to = 1;
    b->mem.elements = 60;
    b->pm.joint = 1;
    b->pm.mass = M;
    tu_one_member3(&b->st, b->xy, b->z, &b->sec, &b->mem);
    b->st.n_point_masses = M > 0;
    b->st.point_masses = &b->pm;
    b->st.gravity[1] = g;
}

static sm_result *gr_solve(const sm_structure *st, double omega, sm_diag *d)
{
    sm_options o;
    sm_model *m = NULL;
    sm_result *r = NULL;
    sm_default_options(&o);
    o.modes = 4;
    if (sm_model_new(&m, st, &o, d) != SM_OK || sm_solve(m, &omega, 1, NULL, NULL, &r, d) != SM_OK)
        r = NULL;
    sm_model_free(m);
    return r;
}

/* The lowest flapwise (hub z) mode's frequency, rad/s, or -1. */
static double gr_flap1(const sm_case *c)
{
    for (int j = 0; j < c->n_modes; j++) {
        const double *s = c->shape_re + (size_t)j * 6 * c->n_nodes;
        double z = 0, all = 0;
        for (int k = 0; k < c->n_nodes; k++)
            for (int i = 0; i < 3; i++) {
                all += s[6 * k + i] * s[6 * k + i];
                z += i == 2 ? s[6 * k + i] * s[6 * k + i] : 0;
            }
        if (z > 0.5 * all)
            return c->frequency[j];
    }
    return -1;
}

/* 1, 2: a tip mass on a light beam, hanging (tension) and standing (compression). */
static void test_tip_mass(void)
{
    const double M = 1000, mu = 1e-4; /* the beam weighs 1e-6 M */
    const double aL[] = {0.5, 2, 5, 20}, bL[] = {0.5, 1.0, 1.4};
    for (int t = 0; t < 4 + 3; t++) {
        int hang = t < 4;
        double x = hang ? aL[t] : bL[t - 4], P = x * x * GR_EI / (GR_L * GR_L), g = P / M, k;
        if (hang) {
            double a = x / GR_L;
            k = P / (GR_L - tanh(x) / a);
        } else {
            double b = x / GR_L;
            k = P / (tan(x) / b - GR_L);
        }
        gr_beam gb;
        gr_init(&gb, mu, M, hang ? g : -g);
        sm_diag d;
        sm_result *r = gr_solve(&gb.st, 0.0, &d);
        TU_CHECK(r && r->cases[0].status == SM_CASE_SOLVED, "solved: %s",
                 r ? r->cases[0].message : d.message);
        if (r && r->cases[0].status == SM_CASE_SOLVED) {
            double want = sqrt(k / M);
            TU_NEAR(gr_flap1(&r->cases[0]), want, 1e-5 * want,
                    "%s tip mass, %s = %g (g = %.4g m/s^2): flap 1 against k = %s",
                    hang ? "hanging" : "standing", hang ? "aL" : "bL", x, g,
                    hang ? "T/(L - tanh(aL)/a)" : "P/(tan(bL)/b - L)");
        }
        sm_result_free(r);
    }
    /* the pendulum limit of the hanging mass */
    gr_beam gb;
    gr_init(&gb, mu, M, 9.80665);
    gb.sec.EI_flap = gb.sec.EI_edge = 1e-6 * M * 9.80665 * GR_L * GR_L;
    sm_diag d;
    sm_result *r = gr_solve(&gb.st, 0.0, &d);
    if (r && r->cases[0].status == SM_CASE_SOLVED) {
        double want = sqrt(9.80665 / GR_L);
        TU_NEAR(gr_flap1(&r->cases[0]), want, 2e-3 * want,
                "a nearly limp beam (T L^2/EI = 1e6) with a hanging mass: the pendulum sqrt(g/L)");
    }
    sm_result_free(r);
}

/* 1 when the structure is stable under gravity g (tip mass M, beam mu). */
static int gr_stable(double mu, double M, double g)
{
    gr_beam gb;
    gr_init(&gb, mu, M, -g);
    sm_diag d;
    sm_result *r = gr_solve(&gb.st, 0.0, &d);
    int stable = r && r->cases[0].status == SM_CASE_SOLVED && r->cases[0].stable;
    sm_result_free(r);
    return stable;
}

/* 3. buckling under a top mass (Euler) and under the column's own weight (Greenhill). */
static void test_buckling(void)
{
    const double M = 1000, Pcr = PI * PI * GR_EI / (4 * GR_L * GR_L), gcr = Pcr / M;
    int below = gr_stable(1e-4, M, 0.99 * gcr), above = gr_stable(1e-4, M, 1.01 * gcr);
    TU_CHECK(below && !above,
             "top mass: stable at 0.99 of Euler's pi^2 EI/(4 L^2) (%d), unstable "
             "at 1.01 (%d)",
             below, above);
    printf("%s top mass on a light column: stable at 0.99 P_cr, unstable at 1.01 P_cr\n",
           below && !above ? "ok  " : "FAIL");
    const double mu = 10, qcr = 7.837 * GR_EI / (GR_L * GR_L * GR_L), g2 = qcr / mu;
    below = gr_stable(mu, 0, 0.99 * g2);
    above = gr_stable(mu, 0, 1.01 * g2);
    TU_CHECK(below && !above,
             "own weight: stable at 0.99 of Greenhill's 7.837 EI/L^3 (%d), "
             "unstable at 1.01 (%d)",
             below, above);
    printf("%s column under its own weight: stable at 0.99, unstable at 1.01 of Greenhill's load\n",
           below && !above ? "ok  " : "FAIL");
}

static void test_refusals(void)
{
    gr_beam gb;
    sm_diag d;
    gr_init(&gb, 10, 0, -9.81);
    sm_result *r = gr_solve(&gb.st, 1.0, &d);
    TU_CHECK(!r && d.status == SM_INVALID_INPUT && !strcmp(d.field, "omega"),
             "gravity at a speed refused (%s)", d.message);
    printf("ok   gravity at 1 rad/s: %s\n", d.message);
    sm_result_free(r);
}

int main(void)
{
    test_tip_mass();
    test_buckling();
    test_refusals();
    return tu_finish("gravity");
}
