/*
 * test_elastodyn.c — ElastoDyn mode-shape coefficients (core/post/elastodyn.c, DESIGN §B).
 *
 *  1. analytic: a shape that IS sum C_k x^k with C2 + ... + C6 = 1 (times any tip value, on
 *     uneven nodes) gives back its coefficients (1e-12), C's sum to 1, phi(0) = phi'(0) = 0,
 *     phi(1) = 1, zero residuals and tip-slope error; bad input is refused.
 *  2. a uniform blade (EI_edge = 4 EI_flap, twisted 30 degrees: the principal axes are not the
 *     member's e2, e3) at rest: flap 1, flap 2, edge 1 are modes 1, 3, 2 by energy; each fit
 *     reproduces the FE shape within 1 % of the tip and matches the Euler-Bernoulli cantilever
 *     mode; the projection on the principal axes leaves no edge motion in a flap mode.
 *  3. the same blade spinning (complex Coriolis shapes): the same selection, clean fits.
 *  4. selection by energy on a hand-made energy table: torsion and axial modes are never
 *     picked, a mode below 90 % gets the warning, a missing mode is -1.
 */
#include "testutil.h"

#define PI 3.14159265358979323846

typedef struct blade {
    double xy[4], z[2];
    sm_section sec;
    sm_member mem;
    sm_structure st;
} blade;

static void blade_init(blade *b, int elements, double twist_deg)
{
    memset(b, 0, sizeof *b);
    b->xy[0] = 2.0; /* a hub radius: x runs from the root joint */
    b->xy[2] = 2.0 + 31.623;
    b->sec.EA = 1e12;
    b->sec.EI_flap = 1e8;
    b->sec.EI_edge = 4e8;
    b->sec.GJ = 1e9;
    b->sec.mu = 100;
    b->mem = (sm_member){0, 1, 0, elements};
    b->mem.twist = twist_deg * PI / 180;
    tu_one_member3(&b->st, b->xy, b->z, &b->sec, &b->mem);
}

/* 1. A polynomial of ElastoDyn's form is fitted exactly. */
static void analytic(void)
{
    const double C[5] = {0.3, -1.2, 2.5, -0.7, 1 - (0.3 - 1.2 + 2.5 - 0.7)};
    double x[23], y[23], slope, sum = 0, d0;
    sm_ed_fit fit;
    int j, k, n = 23;

    for (j = 0; j < n; j++) {
        x[j] = pow((double)j / (n - 1), 1.3); /* uneven, 0 and 1 included */
        y[j] = -2.5 * sm_elastodyn_eval(C, x[j], NULL);
    }
    sm_elastodyn_eval(C, 1.0, &slope);
    TU_CHECK(sm_elastodyn_fit(n, x, y, -2.5 * slope, &fit) == SM_OK, "fit");
    for (k = 0; k < 5; k++) {
        TU_NEAR(fit.coef[k], C[k], 1e-12, "analytic C%d", k + 2);
        sum += fit.coef[k];
    }
    TU_NEAR(sum, 1.0, 1e-15, "C2 + ... + C6");
    TU_NEAR(sm_elastodyn_eval(fit.coef, 0, &d0), 0, 0, "phi(0)");
    TU_NEAR(d0, 0, 0, "phi'(0)");
    TU_NEAR(sm_elastodyn_eval(fit.coef, 1, NULL), 1, 1e-15, "phi(1)");
    TU_NEAR(fit.tip, -2.5, 0, "signed tip");
    TU_NEAR(fit.rms, 0, 1e-13, "rms residual");
    TU_NEAR(fit.max_residual, 0, 1e-13, "largest residual");
    TU_NEAR(fit.tip_slope_error, 0, 1e-12, "tip-slope error");
    TU_CHECK(fit.mode == -1 && isnan(fit.share), "mode and share left to the caller");

    /* refusals */
    TU_CHECK(sm_elastodyn_fit(3, x, y, NAN, &fit) == SM_INVALID_INPUT, "n < 4");
    y[n - 1] = 0;
    TU_CHECK(sm_elastodyn_fit(n, x, y, NAN, &fit) == SM_INVALID_INPUT, "zero tip");
    y[n - 1] = 1;
    x[n - 1] = 0.9;
    TU_CHECK(sm_elastodyn_fit(n, x, y, NAN, &fit) == SM_INVALID_INPUT, "last x not 1");
}

/* Euler-Bernoulli cantilever mode r (0, 1) at x, divided by its tip value. */
static double eb_mode(int r, double x)
{
    static const double beta[2] = {1.87510406871196, 4.69409113297418};
    double b = beta[r], s = (cosh(b) + cos(b)) / (sinh(b) + sin(b));
    double tip = cosh(b) - cos(b) - s * (sinh(b) - sin(b));

    return (cosh(b * x) - cos(b * x) - s * (sinh(b * x) - sin(b * x))) / tip;
}

/* Largest |phi - analytic| over x = 0, 0.01, ..., 1. */
static double eb_diff(const sm_ed_fit *f, int r)
{
    double worst = 0, d;
    int i;

    for (i = 0; i <= 100; i++) {
        d = fabs(sm_elastodyn_eval(f->coef, i / 100.0, NULL) - eb_mode(r, i / 100.0));
        worst = d > worst ? d : worst;
    }
    return worst;
}

/* Largest |edge| / |flap| of mode k projected on the principal axes of the member. */
static double edge_in_flap(const sm_model *m, const sm_case *c, int k)
{
    int n = sm_model_member_nodes(m, 0, 0, NULL, NULL, NULL), nodes[64], j;
    double s[64], tw[64], ax[9], rows[6 * 64], out[128], slope[2], fl = 0, ed = 0;

    sm_model_member_nodes(m, 0, n, nodes, s, tw);
    sm_model_member_axes(m, 0, ax);
    for (j = 0; j < n; j++)
        memcpy(rows + 6 * j, c->shape_re + (size_t)k * 6 * c->n_nodes + 6 * nodes[j],
               6 * sizeof(double));
    sm_elastodyn_project(n, ax, tw, 31.623, rows, out, slope);
    for (j = 0; j < n; j++) {
        fl = fmax(fl, fabs(out[j]));
        ed = fmax(ed, fabs(out[n + j]));
    }
    return ed / fl;
}

/* 2 and 3. The uniform twisted blade at rest and spinning. */
static void uniform_blade(double omega)
{
    static const int modes[SM_ED_BLADE_FITS] = {0, 2, 1}; /* flap 1, flap 2, edge 1 */
    sm_ed_fit fits[SM_ED_BLADE_FITS];
    sm_options o;
    sm_model *m = NULL;
    sm_result *r = NULL;
    sm_diag d;
    blade b;
    int i;

    blade_init(&b, 40, 30);
    sm_default_options(&o);
    o.modes = 6;
    if (sm_model_new(&m, &b.st, &o, &d) < 0 || sm_solve(m, &omega, 1, NULL, NULL, &r, &d) < 0) {
        TU_CHECK(0, "solve: %s", d.message);
        sm_model_free(m);
        return;
    }
    TU_CHECK(sm_elastodyn_blade(m, &r->cases[0], 0, fits) == SM_OK, "sm_elastodyn_blade");
    for (i = 0; i < SM_ED_BLADE_FITS; i++) {
        TU_CHECK(fits[i].mode == modes[i], "omega %g fit %d: mode %d, want %d", omega, i,
                 fits[i].mode, modes[i]);
        TU_CHECK(fits[i].max_residual < 0.01, "omega %g fit %d within 1 %% of tip: %.2e", omega, i,
                 fits[i].max_residual);
        /* at rest the twisted blade's principal directions are uncoupled; spinning, the
         * pitched (30 degree) blade couples flap and edge (flap 1 keeps ~95 %) */
        TU_CHECK(!fits[i].warning && fits[i].share > (omega == 0 ? 0.999 : 0.94),
                 "omega %g fit %d clean: %.6f", omega, i, fits[i].share);
        TU_CHECK(fabs(fits[i].tip_slope_error) < 0.02, "omega %g fit %d tip slope error %.2e",
                 omega, i, fits[i].tip_slope_error);
        TU_NEAR(fits[i].coef[0] + fits[i].coef[1] + fits[i].coef[2] + fits[i].coef[3] +
                    fits[i].coef[4],
                1, 1e-14, "omega %g fit %d: sum of C", omega, i);
    }
    if (omega == 0) {
        /* non-rotating: the Euler-Bernoulli modes (flap 1, flap 2, edge 1 = first shape) */
        TU_NEAR(eb_diff(&fits[0], 0), 0, 2e-3, "flap 1 vs Euler-Bernoulli mode 1");
        TU_NEAR(eb_diff(&fits[1], 1), 0, 1e-2, "flap 2 vs Euler-Bernoulli mode 2");
        TU_NEAR(eb_diff(&fits[2], 0), 0, 2e-3, "edge 1 vs Euler-Bernoulli mode 1");
        TU_NEAR(edge_in_flap(m, &r->cases[0], 0), 0, 1e-6, "principal axes: edge in flap 1");
    }
    printf("omega %g: flap 1 C = %.7g %.7g %.7g %.7g %.7g, rms %.2e\n", omega, fits[0].coef[0],
           fits[0].coef[1], fits[0].coef[2], fits[0].coef[3], fits[0].coef[4], fits[0].rms);
    sm_result_free(r);
    sm_model_free(m);
}

/* 4. Selection by energy on made-up fractions (shapes: the first analytic mode). */
static void selection(void)
{
    /* kinetic axial, edge, flap, torsion, strain the same */
    static const double e[6][SM_ENERGY_PARTS] = {
        {0.9, 0.0, 0.1, 0.0, 0.9, 0.0, 0.1, 0.0},   /* axial: flap > edge, but no candidate */
        {0.0, 0.05, 0.95, 0.0, 0.0, 0.05, 0.95, 0}, /* flap 1, clean */
        {0.0, 0.02, 0.08, 0.9, 0.0, 0.0, 0.1, 0.9}, /* torsion: no candidate */
        {0.0, 0.85, 0.15, 0.0, 0.0, 0.85, 0.15, 0}, /* edge 1, 85 %: warning */
        {0.0, 0.2, 0.8, 0.0, 0.0, 0.2, 0.8, 0.0},   /* flap 2, 80 %: warning */
        {0.0, 0.9, 0.1, 0.0, 0.0, 0.9, 0.1, 0.0},   /* edge 2 */
    };
    enum { N = 11, M = 6 };
    double x[N], re[M * 2 * N];
    const int want[2] = {2, 2};
    sm_ed_fit f[4];
    sm_ed_shapes s;
    int j, k;

    for (j = 0; j < N; j++)
        x[j] = (double)j / (N - 1);
    for (k = 0; k < M; k++)
        for (j = 0; j < N; j++)
            re[2 * k * N + j] = re[(2 * k + 1) * N + j] = eb_mode(0, x[j]);
    s = (sm_ed_shapes){M, N, x, re, NULL, NULL, NULL, &e[0][0], {SM_MODE_FLAP, SM_MODE_EDGE}};
    TU_CHECK(sm_elastodyn_fit_modes(&s, want, f) == SM_OK, "fit_modes");
    TU_CHECK(f[0].mode == 1 && !f[0].warning, "flap 1 = mode 1 (%d)", f[0].mode);
    TU_CHECK(f[1].mode == 4 && f[1].warning, "flap 2 = mode 4 with a warning (%d)", f[1].mode);
    TU_NEAR(f[1].share, 0.8, 1e-15, "flap 2 share");
    TU_CHECK(f[2].mode == 3 && f[2].warning && f[2].direction == 1, "edge 1 = mode 3 (%d)",
             f[2].mode);
    TU_CHECK(f[3].mode == 5 && !f[3].warning, "edge 2 = mode 5 (%d)", f[3].mode);
    s.n_modes = 4; /* no second flap, no second edge */
    TU_CHECK(sm_elastodyn_fit_modes(&s, want, f) == SM_OK && f[1].mode == -1 && f[3].mode == -1,
             "missing modes are -1");
}

int main(void)
{
    analytic();
    uniform_blade(0);
    uniform_blade(3.0);
    selection();
    return tu_finish("elastodyn");
}
