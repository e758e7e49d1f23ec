/*
 * test_base.c — a free base (sm_structure.base_free: an elastic clamp, a floating platform;
 * DESIGN.md 8.6) against independent computations, at rest:
 *  1. rigid body on a platform: a nearly rigid, light mast on a base with a 6x6 stiffness and
 *     mass; its six lowest frequencies are those of the 6x6 rigid-body problem K v = w^2 M v,
 *     M = the platform's mass + the mast's lumped masses carried rigidly, solved here with LAPACK
 *     (dsygv) from the same numbers: 1e-5; and held in y and ry (heave and yaw of a tower along
 *     y, BModes' hub_conn 3): the 4x4 problem of the free directions;
 *  2. an elastic clamp: a cantilever on a rotational spring k (translations held stiff) against
 *     the spring-hinged cantilever's frequency equation (the 4x4 boundary determinant of
 *     Euler-Bernoulli modes; k -> infinity gives the clamped roots 1.875, 4.694): 0.1 %;
 *  3. free-free: a uniform beam on a base with neither stiffness nor mass: six rigid-body modes at
 *     0 rad/s (labelled rigid-body) and the free-free roots 4.7300, 7.8532, 10.9956: 0.1 %;
 *  4. refusals: a speed other than 0, no support at the clamp joint.
 * Lumped mass, per-element frames, augmented basis, Coriolis on (no effect at rest).
 */
#include "testutil.h"

#include <lapacke.h>

#define PI 3.14159265358979323846

typedef struct base_mast {
    double xy[4], z[2];
    sm_section sec;
    sm_member mem;
    sm_support sup;
    sm_structure st;
} base_mast;

/* A mast of height H along y from the clamp (the base) at the origin: flap (p3) = z. */
static void base_init(base_mast *b, double H, int elements, double EI, double mu)
{
    memset(b, 0, sizeof *b);
    b->xy[3] = H;
    b->sec.EA = 1e4 * EI;
    b->sec.EI_flap = EI;
    b->sec.EI_edge = 2 * EI;
    b->sec.GJ = EI;
    b->sec.mu = mu;
    b->sec.i_flap = b->sec.i_edge = 1e-12;
    b->sec.ip_over_a = 2e-12 / mu;
    b->mem.to = 1;
    b->mem.elements = elements;
    tu_one_member3(&b->st, b->xy, b->z, &b->sec, &b->mem);
    b->sup.joint = 0;
    b->sup.member = -1;
    b->st.n_supports = 1;
    b->st.supports = &b->sup;
    b->st.base_free = 1;
}

static sm_result *base_solve(const sm_structure *st, int modes, double omega, sm_diag *d)
{
    sm_options o;
    sm_model *m = NULL;
    sm_result *r = NULL;
    sm_default_options(&o);
    o.modes = modes;
    if (sm_model_new(&m, st, &o, d) != SM_OK || sm_solve(m, &omega, 1, NULL, NULL, &r, d) != SM_OK)
        r = NULL;
    sm_model_free(m);
    return r;
}

/* 1. the rigid-body frequencies of a stiff, light mast on a platform free in the directions not
 * in held (bits x, y, z, rx, ry, rz). */
static void test_rigid(unsigned held)
{
    const double H = 10, mu = 2.0, K[6] = {4e5, 9e5, 6e5, 3e7, 5e7, 2e7};
    const double Mp[6] = {1000, 1200, 900, 4000, 3000, 5000};
    const int el = 20;
    base_mast b;
    base_init(&b, H, el, 1e12, mu);
    for (int i = 0; i < 6; i++) {
        b.sup.K[i + 6 * i] = K[i];
        b.sup.M[i + 6 * i] = Mp[i];
    }
    b.sup.K[0 + 6 * 5] = b.sup.K[5 + 6 * 0] = 1e6; /* surge-yaw coupling, still definite */
    b.st.base_held = held;
    int fr[6], nf = 0;
    for (int i = 0; i < 6; i++)
        if (!(held & (1u << i)))
            fr[nf++] = i;
    sm_diag d;
    sm_result *r = base_solve(&b.st, nf, 0.0, &d);
    TU_CHECK(r && r->cases[0].status == SM_CASE_SOLVED, "solved: %s",
             r ? r->cases[0].message : d.message);
    if (!r || r->cases[0].status != SM_CASE_SOLVED)
        goto done;
    /* by hand: M = Mp + sum_k m_k [I, -[r]x; [r]x, -[r]x[r]x] over the lumped nodes r_k = (0, y_k, 0) */
    double A[36], B[36], w[6];
    memcpy(A, b.sup.K, sizeof A);
    memcpy(B, b.sup.M, sizeof B);
    for (int k = 0; k <= el; k++) {
        double y = H * k / el, mk = mu * H / el * (k == 0 || k == el ? 0.5 : 1.0);
        double rx[9] = {0, 0, -y, 0, 0, 0, y, 0, 0}; /* [r]x column-major, r = (0, y, 0) */
        for (int i = 0; i < 3; i++) {
            B[i + 6 * i] += mk;
            for (int j = 0; j < 3; j++) {
                B[i + 6 * (3 + j)] -= mk * rx[i + 3 * j];
                B[(3 + i) + 6 * j] += mk * rx[i + 3 * j];
                double t = 0;
                for (int a = 0; a < 3; a++)
                    t += rx[i + 3 * a] * rx[a + 3 * j];
                B[(3 + i) + 6 * (3 + j)] -= mk * t;
            }
        }
    }
    double Af[36], Bf[36]; /* the free directions' block */
    for (int j = 0; j < nf; j++)
        for (int i = 0; i < nf; i++) {
            Af[i + nf * j] = A[fr[i] + 6 * fr[j]];
            Bf[i + nf * j] = B[fr[i] + 6 * fr[j]];
        }
    TU_CHECK(LAPACKE_dsygv(LAPACK_COL_MAJOR, 1, 'N', 'L', nf, Af, nf, Bf, nf, w) == 0, "dsygv");
    for (int j = 0; j < nf; j++)
        TU_CHECK(r->cases[0].support_share && r->cases[0].support_share[j] > 0.99999,
                 "rigid-body mode %d: the supports hold the strain energy (share %.9f)", j + 1,
                 r->cases[0].support_share ? r->cases[0].support_share[j] : -1.0);
    for (int j = 0; j < nf; j++)
        TU_NEAR(r->cases[0].frequency[j], sqrt(w[j]), 1e-5 * sqrt(w[j]),
                "rigid mast on a platform held in 0x%02x: mode %d (rad/s) against the %dx%d "
                "rigid-body problem",
                held, j + 1, nf, nf);
done:
    sm_result_free(r);
}

/* det of the spring-hinged cantilever's boundary matrix at lambda = beta L, kappa = k L / EI */
static double base_det(double l, double kap)
{
    double a[16] = {1, -l, -cos(l), sin(l),  0, -kap, -sin(l), -cos(l),
                    1, l,  cosh(l), sinh(l), 0, -kap, sinh(l), cosh(l)};
    int ipiv[4];
    if (LAPACKE_dgetrf(LAPACK_COL_MAJOR, 4, 4, a, 4, ipiv) != 0)
        return 0;
    double det = 1;
    for (int i = 0; i < 4; i++)
        det *= a[i + 4 * i] * (ipiv[i] != i + 1 ? -1 : 1);
    return det;
}

/* 2. a cantilever on a rotational spring about its flap bending axis (x). */
static void test_elastic_clamp(void)
{
    const double H = 10, EI = 1e4, mu = 10, kap = 5;
    base_mast b;
    base_init(&b, H, 96, EI, mu);
    for (int i = 0; i < 6; i++)
        b.sup.K[i + 6 * i] = 1e12;     /* held */
    b.sup.K[3 + 6 * 3] = kap * EI / H; /* rx: the flapwise (z) bending rotation */
    sm_diag d;
    sm_result *r = base_solve(&b.st, 6, 0.0, &d);
    TU_CHECK(r && r->cases[0].status == SM_CASE_SOLVED, "solved: %s",
             r ? r->cases[0].message : d.message);
    if (!r || r->cases[0].status != SM_CASE_SOLVED)
        goto done;
    double lam[3];
    int nr = 0;
    for (double x = 0.05, h = 1e-3; x < 12 && nr < 3; x += h)
        if ((base_det(x, kap) < 0) != (base_det(x + h, kap) < 0)) {
            double lo = x, hi = x + h;
            for (int it = 0; it < 100; it++) {
                double mid = 0.5 * (lo + hi);
                if ((base_det(lo, kap) < 0) == (base_det(mid, kap) < 0))
                    lo = mid;
                else
                    hi = mid;
            }
            lam[nr++] = 0.5 * (lo + hi);
        }
    TU_CHECK(nr == 3, "three roots");
    const sm_case *c = &r->cases[0];
    for (int j = 0, f = 0; j < c->n_modes && f < nr; j++) {
        const double *s = c->shape_re + (size_t)j * 6 * c->n_nodes;
        double z = 0, all = 0;
        for (int k = 0; k < c->n_nodes; k++)
            for (int i = 0; i < 3; i++) {
                all += s[6 * k + i] * s[6 * k + i];
                z += i == 2 ? s[6 * k + i] * s[6 * k + i] : 0;
            }
        if (z < 0.5 * all)
            continue;
        double want = lam[f] * lam[f] / (H * H) * sqrt(EI / mu);
        TU_NEAR(c->frequency[j], want, 1e-3 * want,
                "elastic clamp k L/EI = %g: flap mode %d (lambda %.5f), 96 lumped elements", kap,
                f + 1, lam[f]);
        f++;
    }
done:
    sm_result_free(r);
}

/* 3. free-free: a uniform beam whose base has neither stiffness nor mass of its own. */
static void test_free_free(void)
{
    const double H = 10, EI = 1e4, mu = 10, lam[3] = {4.730040745, 7.853204624, 10.99560784};
    base_mast b;
    base_init(&b, H, 96, EI, mu);       /* the support at the clamp joint: all zero */
    b.sec.i_flap = b.sec.i_edge = 1e-3; /* a rigid spin about the axis needs some inertia */
    b.sec.ip_over_a = 2e-3 / mu;
    sm_diag d;
    sm_result *r = base_solve(&b.st, 12, 0.0, &d);
    TU_CHECK(r && r->cases[0].status == SM_CASE_SOLVED && r->cases[0].stable,
             "free-free: solved and stable: %s", r ? r->cases[0].message : d.message);
    if (!r || r->cases[0].status != SM_CASE_SOLVED)
        goto done;
    const sm_case *c = &r->cases[0];
    int rigid = 0, f = 0;
    for (int j = 0; j < c->n_modes; j++) {
        if (c->frequency[j] == 0) {
            rigid++;
            TU_CHECK(c->label_kind && c->label_kind[j] == SM_MODE_RIGID,
                     "free-free: mode %d at 0 rad/s is labelled rigid-body", j + 1);
            continue;
        }
        const double *sh = c->shape_re + (size_t)j * 6 * c->n_nodes;
        double z = 0, all = 0;
        for (int k = 0; k < c->n_nodes; k++)
            for (int i = 0; i < 3; i++) {
                all += sh[6 * k + i] * sh[6 * k + i];
                z += i == 2 ? sh[6 * k + i] * sh[6 * k + i] : 0;
            }
        if (z < 0.5 * all || f >= 3)
            continue;
        double want = lam[f] * lam[f] / (H * H) * sqrt(EI / mu);
        TU_NEAR(c->frequency[j], want, 1e-3 * want,
                "free-free beam: flap mode %d (lambda %.6f), 96 lumped elements", f + 1, lam[f]);
        f++;
    }
    TU_CHECK(rigid == 6, "free-free: six rigid-body modes at 0 rad/s (%d)", rigid);
    TU_CHECK(f == 3, "free-free: three flap modes compared (%d)", f);
done:
    sm_result_free(r);
}

static void test_refusals(void)
{
    base_mast b;
    sm_diag d;
    base_init(&b, 10, 8, 1e4, 10);
    for (int i = 0; i < 6; i++)
        b.sup.K[i + 6 * i] = 1e6;
    sm_result *r = base_solve(&b.st, 3, 2.0, &d);
    TU_CHECK(!r && d.status == SM_INVALID_INPUT && !strcmp(d.field, "omega"),
             "a speed other than 0 refused (%s)", d.message);
    printf("ok   speed 2 rad/s: %s\n", d.message);
    sm_result_free(r);
    b.st.supports = NULL;
    b.st.n_supports = 0;
    r = base_solve(&b.st, 3, 0.0, &d);
    TU_CHECK(!r && d.status == SM_INVALID_INPUT && d.item == SM_ITEM_CLAMP,
             "no support at the clamp refused (%s)", d.message);
    printf("ok   no support: %s\n", d.message);
    sm_result_free(r);
}

int main(void)
{
    test_rigid(0);
    test_rigid(0x12); /* held in y and ry: a tower's heave and yaw (BModes hub_conn 3) */
    test_elastic_clamp();
    test_free_free();
    test_refusals();
    return tu_finish("base");
}
