/*
 * test_tree3_solve.c — spatial models through the dense path and the tree path (tree3.c,
 * sm_options.solver forced) on the same requests: frequencies, eigenvalues, stability,
 * equilibrium (node positions and rotations, axial forces) and mode shapes (dx..rz) must agree to
 * 1e-9 relative (shapes: 1e-7).  Covers the precone blade (per-element, per-member and
 * elements-per-frame schemes, lumped and consistent mass, Coriolis on and off, a sweep with
 * continuation), a branched frame (a joint with two children), offsets of the centre of mass and
 * point masses with rotary inertia and an offset, and the automatic choice.
 */
#include "internal.h"

#include "testutil.h"

#define PI 3.14159265358979323846

static double max_freq = 0, max_eq = 0, max_shape = 0;

static double reldiff(const double *a, const double *b, int n)
{
    double d = 0, s = 0;
    for (int i = 0; i < n; i++) {
        d = fmax(d, fabs(a[i] - b[i]));
        s = fmax(s, fabs(b[i]));
    }
    return s > 0 ? d / s : d;
}

/* || a - c b || / || a || with the complex c that fits b to a best (shapes are defined up to a factor). */
static double shapediff(const double *ar, const double *ai, const double *br, const double *bi, int n)
{
    double bb = 0, cr = 0, ci = 0, aa = 0, d = 0;
    for (int i = 0; i < n; i++) {
        double xr = ar[i], xi = ai ? ai[i] : 0, yr = br[i], yi = bi ? bi[i] : 0;
        bb += yr * yr + yi * yi;
        cr += yr * xr + yi * xi;
        ci += yr * xi - yi * xr;
        aa += xr * xr + xi * xi;
    }
    if (!(bb > 0) || !(aa > 0))
        return aa == bb ? 0 : 1;
    cr /= bb;
    ci /= bb;
    for (int i = 0; i < n; i++) {
        double xr = ar[i], xi = ai ? ai[i] : 0, yr = br[i], yi = bi ? bi[i] : 0;
        double er = xr - (cr * yr - ci * yi), ei = xi - (cr * yi + ci * yr);
        d += er * er + ei * ei;
    }
    return sqrt(d / aa);
}

static void compare(const char *name, const sm_structure *st, sm_options *o, const double *om, int nom)
{
    sm_result *r[2] = {NULL, NULL};
    sm_model *m[2] = {NULL, NULL};
    sm_diag d;
    for (int v = 0; v < 2; v++) {
        o->solver = v ? SM_SOLVER_TREE : SM_SOLVER_DENSE;
        if (sm_model_new(&m[v], st, o, &d) != SM_OK || sm_solve(m[v], om, nom, NULL, NULL, &r[v], &d) != SM_OK) {
            TU_CHECK(0, "%s: solve %d: %s", name, v, d.message);
            goto done;
        }
    }
    TU_CHECK(tree_use(m[0]) == 0 && tree_use(m[1]) == 1, "%s: forced paths", name);
    for (int i = 0; i < nom; i++) {
        const sm_case *a = &r[0]->cases[i], *b = &r[1]->cases[i];
        int nd = a->node_dof * a->n_nodes;
        TU_CHECK(a->node_dof == 6 && b->node_dof == 6, "%s: spatial layout", name);
        TU_CHECK(a->status == b->status && a->converged == b->converged, "%s W=%g: status %d/%d", name, om[i],
                 a->status, b->status);
        TU_CHECK(a->negative_eigenvalues == b->negative_eigenvalues && a->stable == b->stable,
                 "%s W=%g: stability %d/%d", name, om[i], a->negative_eigenvalues, b->negative_eigenvalues);
        if (!a->converged)
            continue;
        double de = fmax(reldiff(a->nodes, b->nodes, nd), reldiff(a->axial_force, b->axial_force, a->n_elements));
        max_eq = fmax(max_eq, de);
        TU_CHECK(de <= 1e-9, "%s W=%g: equilibrium differs by %.2e", name, om[i], de);
        TU_CHECK(a->n_modes == b->n_modes, "%s W=%g: modes %d/%d", name, om[i], a->n_modes, b->n_modes);
        int k = a->n_modes < b->n_modes ? a->n_modes : b->n_modes;
        double df = 0, ds = 0;
        for (int j = 0; j < k; j++) {
            double sc = hypot(a->eig_re[j], a->eig_im[j]);
            df = fmax(df, fabs(a->frequency[j] - b->frequency[j]) / a->frequency[j]);
            df = fmax(df, hypot(a->eig_re[j] - b->eig_re[j], a->eig_im[j] - b->eig_im[j]) / sc);
            ds = fmax(ds, shapediff(a->shape_re + (size_t)j * nd, a->shape_im ? a->shape_im + (size_t)j * nd : NULL,
                                    b->shape_re + (size_t)j * nd, b->shape_im ? b->shape_im + (size_t)j * nd : NULL,
                                    nd));
        }
        max_freq = fmax(max_freq, df);
        max_shape = fmax(max_shape, ds);
        printf("%s W=%g: status %d, w1 %.10g, max rel diff: freq %.2e equilibrium %.2e shapes %.2e; iterations "
               "%d/%d\n",
               name, om[i], a->status, k ? a->frequency[0] : 0.0, df, de, ds, a->iterations, b->iterations);
        TU_CHECK(df <= 1e-9, "%s W=%g: frequencies differ by %.2e", name, om[i], df);
        TU_CHECK(ds <= 1e-7, "%s W=%g: shapes differ by %.2e", name, om[i], ds);
    }
done:
    for (int v = 0; v < 2; v++) {
        sm_result_free(r[v]);
        sm_model_free(m[v]);
    }
    o->solver = SM_SOLVER_AUTO;
}

/* The precone blade of reference/3d (R3): hub radius 1 m, 10 m at 10 degrees, ne elements. */
typedef struct blade {
    double xy[8], z[4];
    sm_section sec;
    sm_member mem[3];
    sm_point_mass pm[2];
    sm_structure st;
} blade;

static void blade_init(blade *b, int ne)
{
    double a = 10 * PI / 180;
    memset(b, 0, sizeof *b);
    b->xy[0] = 1, b->xy[2] = 1 + 10 * cos(a), b->z[1] = 10 * sin(a);
    b->sec.EA = 8.4e7, b->sec.EI_flap = 2800, b->sec.EI_edge = 25200, b->sec.GJ = 3883, b->sec.mu = 3.0;
    b->sec.i_flap = 1e-4, b->sec.i_edge = 9e-4, b->sec.ip_over_a = 1e-3 / 3.0;
    b->mem[0].to = 1, b->mem[0].elements = ne;
    b->st.n_joints = 2, b->st.joint_xy = b->xy, b->st.joint_z = b->z, b->st.n_sections = 1;
    b->st.sections = &b->sec, b->st.n_members = 1, b->st.members = b->mem, b->st.spatial = 1;
}

int main(void)
{
    blade b;
    sm_options o;
    double w10 = 10, sweep[4] = {0, 5, 10, 20};
    blade_init(&b, 48);
    sm_default_options(&o);
    o.modes = 6;
    compare("blade 48 per-element Coriolis", &b.st, &o, sweep, 4);
    o.coriolis = 0;
    compare("blade 48 per-element no Coriolis", &b.st, &o, &w10, 1);
    sm_default_options(&o);
    o.modes = 6;
    o.mass = SM_MASS_CONSISTENT;
    compare("blade 48 per-element consistent", &b.st, &o, &w10, 1);
    sm_default_options(&o);
    o.modes = 6;
    o.frames = SM_FRAMES_PER_MEMBER;
    o.frames_param = 6;
    compare("blade 48 per-member 6 frames", &b.st, &o, sweep, 4);
    sm_default_options(&o);
    o.modes = 6;
    o.frames = SM_FRAMES_ELEMENTS_PER_FRAME;
    o.frames_param = 4;
    o.modes_per_frame = 8;
    compare("blade 48 elements-per-frame 4, 8 modes per frame", &b.st, &o, &w10, 1);

    /* offsets: centre of mass, shear and tension centres; twist; a tip mass with inertia and offset */
    blade_init(&b, 24);
    b.sec.cg[0] = 0.05, b.sec.cg[1] = -0.02, b.sec.sc[0] = 0.03, b.sec.tc[1] = 0.01;
    b.mem[0].twist = 20 * PI / 180;
    b.pm[0].joint = 1, b.pm[0].mass = 4, b.pm[0].inertia[0] = 0.2, b.pm[0].inertia[1] = 0.1;
    b.pm[0].inertia[2] = 0.3, b.pm[0].products[0] = 0.01, b.pm[0].offset[0] = 0.1, b.pm[0].offset[2] = 0.05;
    b.st.n_point_masses = 1, b.st.point_masses = b.pm;
    sm_default_options(&o);
    o.modes = 6;
    compare("blade 24 offsets, twist, tip mass", &b.st, &o, sweep, 4);

    /* a branched frame: a mast from the hub and two arms from its top, one out of the plane */
    blade br;
    memset(&br, 0, sizeof br);
    double xy[8] = {0.5, 0, 3, 0, 5, 1.5, 4, -1}, z[4] = {0, 0, 0.5, -1};
    memcpy(br.xy, xy, sizeof xy);
    memcpy(br.z, z, sizeof z);
    br.sec = b.sec;
    memset(br.sec.cg, 0, sizeof br.sec.cg);
    memset(br.sec.sc, 0, sizeof br.sec.sc);
    memset(br.sec.tc, 0, sizeof br.sec.tc);
    br.mem[0].to = 1, br.mem[0].elements = 12;
    br.mem[1].from = 1, br.mem[1].to = 2, br.mem[1].elements = 10;
    br.mem[2].from = 1, br.mem[2].to = 3, br.mem[2].elements = 8;
    br.pm[0].joint = 2, br.pm[0].mass = 2, br.pm[0].inertia[2] = 0.05;
    br.st.n_joints = 4, br.st.joint_xy = br.xy, br.st.joint_z = br.z, br.st.n_sections = 1;
    br.st.sections = &br.sec, br.st.n_members = 3, br.st.members = br.mem, br.st.spatial = 1;
    br.st.n_point_masses = 1, br.st.point_masses = br.pm;
    sm_default_options(&o);
    o.modes = 8;
    compare("branched frame per-element", &br.st, &o, sweep, 4);
    o.frames = SM_FRAMES_PER_MEMBER;
    o.frames_param = 2;
    o.mass = SM_MASS_CONSISTENT;
    compare("branched frame per-member 2 consistent", &br.st, &o, &w10, 1);

    /* the automatic choice */
    sm_model *m = NULL;
    blade_init(&b, 192);
    sm_default_options(&o);
    TU_CHECK(sm_model_new(&m, &b.st, &o, NULL) == SM_OK && tree_use(m), "192 elements: tree");
    sm_model_free(m);
    printf("largest relative differences tree vs dense: frequencies %.2e, equilibrium %.2e, shapes %.2e\n",
           max_freq, max_eq, max_shape);
    return tu_finish("tree3_solve");
}
