/*
 * test_rotary_option.c — sm_options.rotary_inertia (DESIGN.md 8.5, issue 25): a uniform spatial
 * cantilever (L = 5 m along x, 40 elements, radii of gyration 0.2 and 0.245 m) at rest.
 *  1. SM_ROTARY_TORSION, lumped mass: every flap and edge frequency equals the plain FE (lumped
 *     translational mass, no rotary inertia: the planar kind, DESIGN.md 1.1, with EI = EI_flap
 *     and EI_edge) to 1e-9, and the Euler-Bernoulli cantilever (beta_n L = 1.87510, 4.69409,
 *     7.85476; Blevins, Formulas for natural frequency and mode shape, table 8-1) within 0.3 %;
 *  2. SM_ROTARY_FULL (the default) keeps the sections' bending rotary inertia: its third flap
 *     mode is more than 1 % below the Euler-Bernoulli value (Rayleigh beam), so 1. fails on the
 *     behaviour before the option;
 *  3. torsion is the same with either option (to 1e-12) and within 0.2 % of
 *     pi/(2L) sqrt(GJ/(i_flap + i_edge));
 *  4. consistent mass has no bending rotary inertia in M* already: the option changes nothing
 *     there (bit for bit); an unknown value is an input error naming rotary_inertia;
 *  5. spinning, torsion keeps the propeller moment with either option (analytic, 0.2 %).
 */
#include "testutil.h"

#define PI 3.14159265358979323846
#define L_BEAM 5.0
#define N_EL 40
#define MU 100.0
#define EI_F 2e6
#define EI_E 5e6
#define GJ_T 1e6
#define I_F 4.0 /* MU 0.2^2 */
#define I_E 6.0
#define N_MODES 12

/* The cantilever (clamp at joint 0, x = 0): spatial sections, or planar with EI = ei. */
typedef struct rot_beam {
    double xy[4], z[2];
    sm_section sec;
    sm_member mem;
    sm_structure st;
} rot_beam;

static void rot_beam_init(rot_beam *b, int spatial, double ei)
{
    memset(b, 0, sizeof *b);
    b->xy[2] = L_BEAM;
    b->sec.mu = MU;
    if (spatial) {
        b->sec.EA = 1e10, b->sec.EI_flap = EI_F, b->sec.EI_edge = EI_E, b->sec.GJ = GJ_T;
        b->sec.i_flap = I_F, b->sec.i_edge = I_E;
        b->sec.ip_over_a = (I_F + I_E) / MU;
    } else {
        b->sec.E = 1.0, b->sec.A = 1e10, b->sec.I = ei;
    }
    b->mem.from = 0, b->mem.to = 1, b->mem.elements = N_EL;
    b->st.n_joints = 2;
    b->st.joint_xy = b->xy;
    b->st.joint_z = spatial ? b->z : NULL;
    b->st.n_sections = 1;
    b->st.sections = &b->sec;
    b->st.n_members = 1;
    b->st.members = &b->mem;
    b->st.spatial = spatial;
}

/* Solve at rest; *r owns the result (NULL on failure, reported). */
static void rot_solve(const rot_beam *b, sm_mass_model mass, int rotary, sm_result **r)
{
    sm_options o;
    sm_model *m = NULL;
    sm_diag d;
    double w = 0.0;

    sm_default_options(&o);
    o.modes = N_MODES;
    o.coriolis = 0;
    o.mass = mass;
    o.rotary_inertia = rotary;
    *r = NULL;
    TU_CHECK(sm_model_new(&m, &b->st, &o, &d) == SM_OK, "model: %s", d.message);
    if (m)
        TU_CHECK(sm_solve(m, &w, 1, NULL, NULL, r, &d) == SM_OK, "solve: %s", d.message);
    sm_model_free(m);
}

/* Frequency (rad/s) of the n-th mode of the kind in case 0, NAN if absent. */
static double rot_freq(const sm_result *r, int kind, int n)
{
    const sm_case *c = r ? &r->cases[0] : NULL;
    for (int j = 0; c && j < c->n_modes; j++)
        if (c->label_kind[j] == kind && c->label_ordinal[j] == n)
            return c->frequency[j];
    return NAN;
}

/* Euler-Bernoulli cantilever, mode n (1..3), rad/s. */
static double rot_eb(double ei, int n)
{
    static const double bl[3] = {1.87510407, 4.69409113, 7.85475744};
    return bl[n - 1] * bl[n - 1] * sqrt(ei / (MU * pow(L_BEAM, 4)));
}

/* 1-3: bending and torsion with each option, lumped mass. */
static void rot_lumped(void)
{
    rot_beam sp, pf, pe;
    sm_result *tor = NULL, *full = NULL, *plf = NULL, *ple = NULL;
    static const int kinds[2] = {SM_MODE_FLAP, SM_MODE_EDGE};
    static const double eis[2] = {EI_F, EI_E};
    rot_beam_init(&sp, 1, 0.0);
    rot_beam_init(&pf, 0, EI_F);
    rot_beam_init(&pe, 0, EI_E);
    rot_solve(&sp, SM_MASS_LUMPED, SM_ROTARY_TORSION, &tor);
    rot_solve(&sp, SM_MASS_LUMPED, SM_ROTARY_FULL, &full);
    rot_solve(&pf, SM_MASS_LUMPED, SM_ROTARY_FULL, &plf);
    rot_solve(&pe, SM_MASS_LUMPED, SM_ROTARY_FULL, &ple);
    for (int k = 0; k < 2; k++)
        for (int n = 1; n <= 3; n++) {
            const sm_result *pl = k ? ple : plf;
            double t = rot_freq(tor, kinds[k], n), p = rot_freq(pl, SM_MODE_BENDING, n);
            double eb = rot_eb(eis[k], n);
            TU_NEAR(t / p, 1.0, 1e-9, "torsion-only %s %d / plain FE (%.6f rad/s)",
                    k ? "edge" : "flap", n, p);
            TU_NEAR(t / eb, 1.0, 3e-3, "torsion-only %s %d / Euler-Bernoulli (%.6f rad/s)",
                    k ? "edge" : "flap", n, eb);
        }
    double f3 = rot_freq(full, SM_MODE_FLAP, 3) / rot_eb(EI_F, 3);
    TU_CHECK(f3 < 0.99, "full rotary inertia: flap 3 / Euler-Bernoulli = %.5f, expected < 0.99",
             f3);
    printf("full rotary inertia: flap 3 / Euler-Bernoulli = %.5f\n", f3);
    double tt = rot_freq(tor, SM_MODE_TORSION, 1), tf = rot_freq(full, SM_MODE_TORSION, 1);
    TU_NEAR(tt / tf, 1.0, 1e-12, "torsion 1, torsion-only / full");
    TU_NEAR(tt / (PI / (2 * L_BEAM) * sqrt(GJ_T / (I_F + I_E))), 1.0, 2e-3, "torsion 1 / analytic");
    sm_result_free(tor);
    sm_result_free(full);
    sm_result_free(plf);
    sm_result_free(ple);
}

/* 5: spinning at OMEGA_P about z (clamp at x = 1 m, no Wagner term): torsion keeps the propeller
 * moment, a uniform torsional spring Omega^2 (i_edge - i_flap) cos 2theta per length (BModes
 * has it too: Struct.f90:1067, 1298, dsk = skm2 - skm1), theta = 0 here (chord p2 in the plane
 * of rotation); a uniform spring shifts w^2 of the clamped-free torsion mode by spring / i_p:
 * w_t^2 = w_t0^2 + Omega^2 (i_edge - i_flap) / (i_flap + i_edge), either option and mass model
 * (without the term: w_t0, 0.9 % lower). */
#define OMEGA_P 30.0
static void rot_propeller(void)
{
    static const sm_mass_model mass[2] = {SM_MASS_LUMPED, SM_MASS_CONSISTENT};
    rot_beam sp;
    rot_beam_init(&sp, 1, 0.0);
    sp.xy[0] = 1.0, sp.xy[2] = 1.0 + L_BEAM;
    sp.sec.ip_over_a = 0.0;
    double w0 = PI / (2 * L_BEAM) * sqrt(GJ_T / (I_F + I_E));
    double want = sqrt(w0 * w0 + OMEGA_P * OMEGA_P * (I_E - I_F) / (I_F + I_E));
    for (int k = 0; k < 2; k++)
        for (int ri = 0; ri < 2; ri++) {
            sm_options o;
            sm_model *m = NULL;
            sm_result *r = NULL;
            sm_diag d;
            double w = OMEGA_P;
            sm_default_options(&o);
            o.modes = N_MODES, o.coriolis = 0, o.mass = mass[k];
            o.rotary_inertia = ri ? SM_ROTARY_TORSION : SM_ROTARY_FULL;
            TU_CHECK(sm_model_new(&m, &sp.st, &o, &d) == SM_OK, "model: %s", d.message);
            if (m)
                TU_CHECK(sm_solve(m, &w, 1, NULL, NULL, &r, &d) == SM_OK, "solve: %s", d.message);
            TU_NEAR(rot_freq(r, SM_MODE_TORSION, 1) / want, 1.0, 2e-3,
                    "%s, %s, Omega %g: torsion 1 / analytic with the propeller moment (%.4f rad/s; "
                    "without it %.4f)",
                    k ? "consistent" : "lumped", ri ? "torsion-only" : "full", OMEGA_P, want, w0);
            sm_result_free(r);
            sm_model_free(m);
        }
}

/* 4: consistent mass unchanged; a bad value refused. */
static void rot_consistent(void)
{
    rot_beam sp;
    sm_result *a = NULL, *b = NULL;
    rot_beam_init(&sp, 1, 0.0);
    rot_solve(&sp, SM_MASS_CONSISTENT, SM_ROTARY_FULL, &a);
    rot_solve(&sp, SM_MASS_CONSISTENT, SM_ROTARY_TORSION, &b);
    int same = a && b && a->cases[0].n_modes == b->cases[0].n_modes;
    for (int j = 0; same && j < a->cases[0].n_modes; j++)
        same = a->cases[0].frequency[j] == b->cases[0].frequency[j];
    TU_CHECK(same, "consistent mass: the same frequencies with either option");
    sm_result_free(a);
    sm_result_free(b);

    sm_options o;
    sm_model *m = NULL;
    sm_diag d;
    sm_default_options(&o);
    o.rotary_inertia = (sm_rotary_inertia)7;
    TU_CHECK(sm_model_new(&m, &sp.st, &o, &d) == SM_INVALID_INPUT &&
                 !strcmp(d.field, "rotary_inertia"),
             "rotary_inertia 7: input error at rotary_inertia (%s)", d.message);
    sm_model_free(m);
}

int main(void)
{
    rot_lumped();
    rot_consistent();
    rot_propeller();
    return tu_finish("test_rotary_option");
}
