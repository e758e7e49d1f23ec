/*
 * test_supports.c — elastic supports (sm_support, DESIGN.md 8.6) against closed forms and
 * against the core's own independent parts, at rest:
 *  1. a uniform lateral foundation k over a whole lumped-mass cantilever shifts every bending
 *     omega^2 in its direction by exactly k/mu (springs and masses are lumped alike) and leaves
 *     the other direction alone; an axial foundation shifts the axial omega^2 by k/mu, a torsional
 *     one the torsion omega^2 by k_t/i_p;
 *  2. a flapwise spring at the tip of a cantilever: the Euler-Bernoulli frequency equation
 *     1 + cos L cosh L + (kL^3/EI)/L^3 (sin L cosh L - cos L sinh L) = 0 (L = beta L; it gives
 *     the clamped-free roots at k = 0 and the clamped-pinned ones as k grows): 0.1 %;
 *  3. a flapwise added mass at the tip gives the flap frequencies of the same point mass (an
 *     sm_point_mass moves with every direction; flap modes of a straight beam feel only its
 *     flapwise part): 1e-9;
 *  4. a planar cantilever with a lateral tip spring equals the spatial one's edge modes: 1e-9
 *     (a rotational support is refused in a planar model: its basis condenses the rotations);
 *  5. bad input: non-symmetric, indefinite, a stretch off the member, a support at a joint and
 *     a member, the tree solver — SM_INVALID_INPUT naming the support and the field.
 * Mass model lumped, per-element frames, augmented basis, Coriolis on (Omega = 0: no effect).
 */
#include "testutil.h"

#define PI 3.14159265358979323846
#define SUP_L 10.0
#define SUP_MU 10.0
#define SUP_EIF 1.0e4
#define SUP_EIE 4.0e4
#define SUP_EL 24

typedef struct sup_beam {
    double xy[4], z[2];
    sm_section sec;
    sm_member mem;
    sm_point_mass pm;
    sm_support sup[2];
    sm_structure st;
} sup_beam;

/* A cantilever along x from the clamp at the origin; spatial: flap = z (p3), edge = y (p2). */
static void sup_init(sup_beam *b, int spatial)
{
    memset(b, 0, sizeof *b);
    b->xy[2] = SUP_L;
    b->sec.mu = SUP_MU;
    if (spatial) {
        b->sec.EA = 1e8;
        b->sec.EI_flap = SUP_EIF;
        b->sec.EI_edge = SUP_EIE;
        b->sec.GJ = 2e4;
        b->sec.i_flap = b->sec.i_edge = 0.05;
        b->sec.ip_over_a = 0.1 / SUP_MU;
    } else {
        b->sec.E = 1e8;
        b->sec.A = 1.0;
        b->sec.I = SUP_EIE / 1e8;
    }
    b->mem.from = 0;
    b->mem.to = 1;
    b->mem.elements = SUP_EL;
    b->st.n_joints = 2;
    b->st.joint_xy = b->xy;
    b->st.joint_z = spatial ? b->z : NULL;
    b->st.n_sections = 1;
    b->st.sections = &b->sec;
    b->st.n_members = 1;
    b->st.members = &b->mem;
    b->st.spatial = spatial;
    for (int i = 0; i < 2; i++)
        b->sup[i].joint = b->sup[i].member = -1;
}

static sm_result *sup_solve(const sm_structure *st, int modes)
{
    sm_options o;
    sm_model *m = NULL;
    sm_result *r = NULL;
    sm_diag d;
    double w = 0;

    sm_default_options(&o);
    o.modes = modes;
    if (sm_model_new(&m, st, &o, &d) != SM_OK || sm_solve(m, &w, 1, NULL, NULL, &r, &d) != SM_OK) {
        printf("solve failed: %s\n", d.message);
        r = NULL;
    }
    sm_model_free(m);
    if (r && r->cases[0].status != SM_CASE_SOLVED) {
        printf("not solved: %s\n", r->cases[0].message);
        sm_result_free(r);
        r = NULL;
    }
    return r;
}

/* Fraction of mode j's translation in direction dir (0 x, 1 y, 2 z) and of its rotation rx. */
static double sup_part(const sm_case *c, int j, int dir)
{
    const double *s = c->shape_re + (size_t)j * 6 * c->n_nodes;
    double a = 0, all = 0;
    for (int k = 0; k < c->n_nodes; k++)
        for (int i = 0; i < 4; i++) {
            double v = s[6 * k + i];
            all += v * v;
            if (i == dir)
                a += v * v;
        }
    return all > 0 ? a / all : 0;
}

/* The dominant direction of mode j: 0 axial, 1 edge (y), 2 flap (z), 3 torsion. */
static int sup_dir(const sm_case *c, int j)
{
    int best = 0;
    for (int d = 1; d < 4; d++)
        if (sup_part(c, j, d) > sup_part(c, j, best))
            best = d;
    return best;
}

/* 1. foundations over the whole beam: omega^2 shifts by k / (mass per length) per direction. */
static void test_foundation(int torsion)
{
    static const char *names[4] = {"axial", "edge", "flap", "torsion"};
    const int modes = 14;
    sup_beam b;
    sup_init(&b, 1);
    if (!torsion) { /* bending rotary inertia would take a share of omega^2 that k does not */
        b.sec.i_flap = b.sec.i_edge = 1e-9;
        b.sec.ip_over_a = 2e-9 / SUP_MU;
        b.sec.EA = 1e6; /* the first axial mode among the lowest 14 */
    }
    sm_result *r0 = sup_solve(&b.st, modes);
    /* k per direction: axial 2e5, edge 1e3, flap 3e3 N/m^2, torsion 40 N m/rad per m */
    double k[4] = {2e5, 1e3, 3e3, 40.0}, per[4] = {SUP_MU, SUP_MU, SUP_MU, 0.1};
    b.sup[0].member = 0;
    b.sup[0].to_s = SUP_L;
    memcpy(b.sup[0].k_per_length, k, sizeof k);
    if (torsion)
        b.sup[0].k_per_length[0] = b.sup[0].k_per_length[1] = b.sup[0].k_per_length[2] = 0;
    else
        b.sup[0].k_per_length[3] = 0;
    b.st.n_supports = 1;
    b.st.supports = b.sup;
    sm_result *r1 = sup_solve(&b.st, modes);
    TU_CHECK(r0 && r1, "both solve");
    if (!r0 || !r1)
        goto done;
    const sm_case *c0 = &r0->cases[0], *c1 = &r1->cases[0];
    int seen[4] = {0};
    for (int j = 0; j < modes; j++) {
        int d = sup_dir(c1, j), i0 = -1;
        for (int t = 0, n = 0; t < modes && i0 < 0; t++) /* the same direction's same ordinal */
            if (sup_dir(c0, t) == d && n++ == seen[d])
                i0 = t;
        if (i0 < 0 || (d == 3) != torsion)
            continue;
        double w0 = c0->frequency[i0], want = sqrt(w0 * w0 + k[d] / per[d]);
        TU_NEAR(c1->frequency[j], want, 1e-7 * want,
                "foundation: %s mode %d, omega (rad/s) from %.5f by sqrt(w0^2 + k/m)", names[d],
                ++seen[d], w0);
        /* the supports' share of the strain energy: k |phi|^2 over mu omega^2 |phi|^2 */
        double share = k[d] / per[d] / (c1->frequency[j] * c1->frequency[j]);
        TU_CHECK(c1->support_share && fabs(c1->support_share[j] - share) <= 1e-6,
                 "%s mode %d: support share %.9f, want (k/m)/omega^2 = %.9f", names[d], seen[d],
                 c1->support_share ? c1->support_share[j] : -1.0, share);
    }
    TU_CHECK(!c0->support_share, "no support share without supports");
    TU_CHECK(torsion ? seen[3] >= 1 : seen[1] >= 2 && seen[2] >= 2 && seen[0] >= 1,
             "modes of every direction compared (axial %d edge %d flap %d torsion %d)", seen[0],
             seen[1], seen[2], seen[3]);
done:
    sm_result_free(r0);
    sm_result_free(r1);
}

/* The frequency equation of a cantilever with a tip spring, K = kL^3/EI, at lambda = beta L. */
static double sup_tip_spring_eq(double lam, double K)
{
    return 1 + cos(lam) * cosh(lam) +
           K / (lam * lam * lam) * (sin(lam) * cosh(lam) - cos(lam) * sinh(lam));
}

/* Its roots in (a, b) by bisection after a scan. */
static int sup_roots(double K, double *out, int want)
{
    int n = 0;
    double h = 1e-3, a = 0.5, fa = sup_tip_spring_eq(a, K);
    for (double x = a + h; x < 20 && n < want; x += h) {
        double fx = sup_tip_spring_eq(x, K);
        if ((fa < 0) != (fx < 0)) {
            double lo = x - h, hi = x;
            for (int it = 0; it < 200; it++) {
                double mid = 0.5 * (lo + hi);
                if ((sup_tip_spring_eq(lo, K) < 0) == (sup_tip_spring_eq(mid, K) < 0))
                    lo = mid;
                else
                    hi = mid;
            }
            out[n++] = 0.5 * (lo + hi);
        }
        fa = fx;
    }
    return n;
}

/* 2. a flapwise tip spring against the Euler-Bernoulli frequency equation. */
static void test_tip_spring(void)
{
    const double K = 20.0; /* kL^3/EI */
    sup_beam b;
    sup_init(&b, 1);
    b.sec.i_flap = b.sec.i_edge = 1e-6; /* Euler-Bernoulli: no rotary inertia to speak of */
    b.sec.ip_over_a = 2e-6 / SUP_MU;
    b.mem.elements = 96;
    b.sup[0].joint = 1;
    b.sup[0].K[2 + 6 * 2] = K * SUP_EIF / (SUP_L * SUP_L * SUP_L);
    b.st.n_supports = 1;
    b.st.supports = b.sup;
    sm_result *r = sup_solve(&b.st, 8);
    double lam[3];
    int nr = sup_roots(K, lam, 3);
    TU_CHECK(r && nr == 3, "solved, three roots");
    if (!r || nr != 3)
        goto done;
    const sm_case *c = &r->cases[0];
    for (int j = 0, f = 0; j < c->n_modes && f < 3; j++) {
        if (sup_dir(c, j) != 2)
            continue;
        double want = lam[f] * lam[f] / (SUP_L * SUP_L) * sqrt(SUP_EIF / SUP_MU);
        TU_NEAR(c->frequency[j], want, 1e-3 * want,
                "tip spring kL^3/EI = %g: flap mode %d (lambda %.6f), 96 lumped elements", K, f + 1,
                lam[f]);
        f++;
    }
done:
    sm_result_free(r);
}

/* 3. a flapwise added mass at the tip: the flap modes of the same point mass. */
static void test_added_mass(void)
{
    sup_beam b, p;
    sup_init(&b, 1);
    sup_init(&p, 1);
    b.sup[0].joint = 1;
    b.sup[0].M[2 + 6 * 2] = 0.4 * SUP_MU * SUP_L;
    b.st.n_supports = 1;
    b.st.supports = b.sup;
    p.pm.joint = 1;
    p.pm.mass = 0.4 * SUP_MU * SUP_L;
    p.st.n_point_masses = 1;
    p.st.point_masses = &p.pm;
    sm_result *rb = sup_solve(&b.st, 10), *rp = sup_solve(&p.st, 10);
    TU_CHECK(rb && rp, "both solve");
    if (!rb || !rp)
        goto done;
    const sm_case *cb = &rb->cases[0], *cp = &rp->cases[0];
    int i = 0, n = 0;
    for (int j = 0; j < cb->n_modes; j++) {
        if (sup_dir(cb, j) != 2)
            continue;
        while (i < cp->n_modes && sup_dir(cp, i) != 2)
            i++;
        if (i >= cp->n_modes)
            break;
        TU_NEAR(cb->frequency[j], cp->frequency[i], 1e-9 * cp->frequency[i],
                "flapwise added mass 0.4 mu L at the tip = point mass: flap mode %d", ++n);
        i++;
    }
    TU_CHECK(n >= 2, "two flap modes compared (%d)", n);
done:
    sm_result_free(rb);
    sm_result_free(rp);
}

/* 4. planar with a lateral tip spring = the spatial beam's edge modes with the same spring. */
static void test_planar(void)
{
    sup_beam p, s;
    sup_init(&p, 0);
    sup_init(&s, 1);
    s.sec.i_flap = s.sec.i_edge = 0.0; /* the planar beam has no rotary inertia */
    s.sec.ip_over_a = 0.0;
    s.sec.EA = 1e8;
    for (int k = 0; k < 2; k++) {
        sup_beam *b = k ? &s : &p;
        b->sup[0].joint = 1;
        b->sup[0].K[1 + 6 * 1] = 3e3;
        b->st.n_supports = 1;
        b->st.supports = b->sup;
    }
    sm_result *rp = sup_solve(&p.st, 3), *rs = sup_solve(&s.st, 12);
    TU_CHECK(rp && rs, "both solve");
    if (!rp || !rs)
        goto done;
    const sm_case *cp = &rp->cases[0], *cs = &rs->cases[0];
    for (int j = 0, f = 0; j < cs->n_modes && f < 2; j++) {
        if (sup_dir(cs, j) != 1)
            continue;
        TU_NEAR(cs->frequency[j], cp->frequency[f], 1e-9 * cp->frequency[f],
                "planar tip spring (y 3e3 N/m) = spatial edge mode %d", f + 1);
        f++;
    }
done:
    sm_result_free(rp);
    sm_result_free(rs);
}

/* 5. refusals naming the support and field. */
static void sup_expect(const sm_structure *st, int solver, const char *field, const char *what)
{
    sm_options o;
    sm_model *m = NULL;
    sm_diag d;
    sm_default_options(&o);
    o.solver = solver;
    int rc = sm_model_new(&m, st, &o, &d);
    sm_model_free(m);
    TU_CHECK(rc == SM_INVALID_INPUT && !strcmp(d.field, field) &&
                 (d.item == SM_ITEM_SUPPORT || d.item == SM_ITEM_OPTIONS),
             "%s refused at field '%s' (rc %d, item %d, field '%s': %s)", what, field, rc, d.item,
             d.field, d.message);
    printf("ok   %s: %s\n", what, d.message);
}

static void test_refusals(void)
{
    sup_beam b;
    sup_init(&b, 1);
    b.st.n_supports = 1;
    b.st.supports = b.sup;
    b.sup[0].joint = 1;
    b.sup[0].K[0 + 6 * 1] = 1.0; /* K_xy without K_yx */
    sup_expect(&b.st, 0, "K", "non-symmetric stiffness");
    b.sup[0].K[1 + 6 * 0] = 1.0; /* symmetric, [0 1; 1 0]: indefinite */
    sup_expect(&b.st, 0, "K", "indefinite stiffness");
    memset(b.sup[0].K, 0, sizeof b.sup[0].K);
    b.sup[0].M[3 + 6 * 3] = -1.0;
    sup_expect(&b.st, 0, "M", "negative added mass");
    b.sup[0].M[3 + 6 * 3] = 0.0;
    b.sup[0].member = 0;
    sup_expect(&b.st, 0, "", "a joint and a member");
    b.sup[0].joint = -1;
    b.sup[0].from_s = 2;
    b.sup[0].to_s = SUP_L + 1;
    sup_expect(&b.st, 0, "to_s", "a stretch past the member's end");
    b.sup[0].to_s = 1;
    sup_expect(&b.st, 0, "to_s", "a stretch that ends before it starts");
    b.sup[0].to_s = 5;
    b.sup[0].k_per_length[1] = -3;
    sup_expect(&b.st, 0, "k_per_length", "a negative foundation stiffness");
    b.sup[0].k_per_length[1] = 3;
    sup_expect(&b.st, SM_SOLVER_TREE, "solver", "the tree solver");
    sup_init(&b, 0);
    b.st.n_supports = 1;
    b.st.supports = b.sup;
    b.sup[0].joint = 1;
    b.sup[0].K[5 + 6 * 5] = 1e4;
    sup_expect(&b.st, 0, "K", "a planar rotational spring");
}

int main(void)
{
    test_foundation(0);
    test_foundation(1);
    test_tip_spring();
    test_added_mass();
    test_planar();
    test_refusals();
    return tu_finish("supports");
}
