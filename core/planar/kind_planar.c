/*
 * kind_planar.c — the planar structure kind (kind.h): Kim & Yoo's formulation, 3 DOF per
 * node, frames that turn about the spin axis.
 *
 * How it fits: the table smi_kind_planar routes the shared code (mesh.c, modes.c,
 * equilibrium.c, linsys.c, sweep.c) to the planar modules — frames.c (kinematics, g, H),
 * linearize.c (f_g, tangent, M*, C*), tree.c (the block form), modes.c (bases) — and holds
 * the planar parts that had no module of their own: the input checks, the undeformed local
 * positions and the nodal outputs.  Every call makes exactly the floating-point operations
 * the planar path made before the table existed, in the same order (planar answers are
 * byte-identical).
 */
#include "element.h"
#include "kind.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int planar_positive(double v)
{
    return isfinite(v) && v > 0.0;
}

/* The spatial-only fields must be absent (zero); then the planar sections. */
static int planar_check_spatial_fields(const sm_structure *st, sm_diag *d)
{
    for (int j = 0; st->joint_z && j < st->n_joints; j++)
        if (st->joint_z[j] != 0.0)
            return smi_input_fail(
                d, SM_ITEM_JOINT, j, "z",
                "a joint out of the x-y plane needs spatial sections (EA, EI_flap, "
                "EI_edge, GJ, mass_per_length)");
    for (int i = 0; i < st->n_members; i++) {
        const sm_member *b = &st->members[i];
        if (b->twist != 0.0)
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "twist_deg",
                                  "twist_deg needs spatial sections");
        if (b->e3[0] != 0.0 || b->e3[1] != 0.0 || b->e3[2] != 0.0)
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "flap_direction",
                                  "flap_direction needs spatial sections");
    }
    for (int i = 0; i < st->n_point_masses; i++) {
        const sm_point_mass *pm = &st->point_masses[i];
        const double *I = pm->inertia;
        if (I[0] != 0.0 || I[1] != 0.0 || I[2] != 0.0)
            return smi_input_fail(d, SM_ITEM_POINT_MASS, i, "inertia",
                                  "a rotary inertia needs spatial sections");
        if (pm->products[0] != 0.0 || pm->products[1] != 0.0 || pm->products[2] != 0.0)
            return smi_input_fail(d, SM_ITEM_POINT_MASS, i, "products",
                                  "products of inertia need spatial sections");
        if (pm->offset[0] != 0.0 || pm->offset[1] != 0.0 || pm->offset[2] != 0.0)
            return smi_input_fail(d, SM_ITEM_POINT_MASS, i, "offset",
                                  "a point-mass offset needs spatial sections");
    }
    for (int i = 0; i < st->n_members; i++)
        if (st->members[i].n_stations || st->members[i].station_mask)
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "stations",
                                  "stations need spatial sections");
    for (int s = 0; s < st->n_sections; s++) {
        const sm_section *c = &st->sections[s];
        if (c->cg[0] != 0.0 || c->cg[1] != 0.0 || c->sc[0] != 0.0 || c->sc[1] != 0.0 ||
            c->tc[0] != 0.0 || c->tc[1] != 0.0)
            return smi_input_fail(d, SM_ITEM_SECTION, s, "cg_offset",
                                  "section offsets need spatial sections");
    }
    return SM_OK;
}

static int planar_check(const sm_structure *st, const sm_options *o, sm_diag *d)
{
    int rc = planar_check_spatial_fields(st, d);

    (void)o;
    if (rc < 0)
        return rc;
    for (int s = 0; s < st->n_sections; s++) {
        const sm_section *c = &st->sections[s];
        if (!planar_positive(c->E))
            return smi_input_fail(d, SM_ITEM_SECTION, s, "E", "E must be a positive number (Pa)");
        if (!planar_positive(c->A))
            return smi_input_fail(d, SM_ITEM_SECTION, s, "A", "A must be a positive number (m^2)");
        if (!planar_positive(c->I))
            return smi_input_fail(d, SM_ITEM_SECTION, s, "I", "I must be a positive number (m^4)");
        if (!planar_positive(c->mu))
            return smi_input_fail(d, SM_ITEM_SECTION, s, "mass_per_length",
                                  "mass_per_length must be a positive number (kg/m)");
    }
    return SM_OK;
}

/* In the plane (z is zero). */
static double planar_length(double dx, double dy, double dz)
{
    (void)dz;
    return hypot(dx, dy);
}

/* ubar of every free node: A(theta0)' (X - X_root), 2 per node. */
static void planar_subs(sm_model *m)
{
    for (int k = 0; k < m->n_subs; k++) {
        sm_sub *b = &m->subs[k];
        const sm_node *r = &m->nodes[b->root];
        double c = cos(b->theta0), si = sin(b->theta0);
        for (int i = 0; i < b->nfree; i++) {
            const sm_node *nd = &m->nodes[b->free_nodes[i]];
            double dx = nd->x - r->x, dy = nd->y - r->y;
            b->ubar[2 * i] = c * dx + si * dy;
            b->ubar[2 * i + 1] = -si * dx + c * dy;
        }
    }
}

static void *planar_kin_new(const sm_model *m, int use)
{
    sm_kin *k = calloc(1, sizeof *k);

    if (!k)
        return NULL;
    if ((use == SMI_USE_TREE ? frames_kin_alloc_light(m, k) : frames_kin_alloc(m, k)) != SM_OK) {
        free(k);
        return NULL;
    }
    return k;
}

static void planar_kin_free(void *k)
{
    if (k)
        frames_kin_free(k);
    free(k);
}

static void planar_kin_eval(const sm_model *m, const double *q, void *k)
{
    frames_eval(m, q, k);
}

static void planar_node_jacobian(const sm_model *m, const void *k, int nd, double *J)
{
    memcpy(J, &DM(&((const sm_kin *)k)->Jn, 0, 3 * nd), 3 * (size_t)m->n * sizeof(double));
}

static void planar_centrifugal(const sm_model *m, const double *q, void *k, tree_ws *t, double *g)
{
    frames_eval(m, q, k);
    if (t)
        tree_centrifugal(m, k, t, g);
    else
        frames_centrifugal(m, k, g);
}

/* Newton: K (the tangent), M, H, W (n x 2 n_mp); modes: also C and X (n x n). */
static int planar_dense_alloc(const sm_model *m, int use, smi_dense *D)
{
    int n = m->n;

    memset(D, 0, sizeof *D);
    if (dm_alloc(&D->K, n, n) || dm_alloc(&D->M, n, n) || dm_alloc(&D->H, n, n) ||
        dm_alloc(&D->W, n, 2 * m->n_mp))
        return SM_NOMEM;
    if (use == SMI_USE_MODES && (dm_alloc(&D->C, n, n) || dm_alloc(&D->X, n, n)))
        return SM_NOMEM;
    return SM_OK;
}

static void planar_dense_tangent(const sm_model *m, const double *q, void *k, double s,
                                 smi_dense *D, double *work)
{
    lin_tangent(m, q, k, s, 0, &D->K, &D->M, &D->H, &D->W, work);
}

static void planar_dense_linearize(const sm_model *m, const double *q, void *k, double omega,
                                   int gyro, smi_dense *D, double *work)
{
    frames_eval(m, q, k);
    lin_tangent(m, q, k, omega * omega, 1, &D->K, &D->M, &D->H, &D->W, work); /* K*, P frozen; M* */
    if (gyro)
        lin_gyro(m, k, omega, &D->C, &D->W, &D->X);
}

static int planar_tree_assemble(const sm_model *m, const double *q, void *k, double s, int lin,
                                int gyro, tree_ws *t)
{
    if (lin) { /* K*, P frozen; M*; C* */
        frames_eval(m, q, k);
        return tree_assemble(m, q, k, s, 1, gyro, t);
    }
    return tree_assemble(m, q, k, s, 0, 0, t);
}

/* (dx, dy, dphi) = J_k x per node, hub frame, for both parts of x in one pass over J_k. */
static void planar_nodal(const sm_model *m, void *kin, tree_ws *t, const double *xr,
                         const double *xi, double *yr, double *yi)
{
    const sm_kin *k = kin;
    int n = m->n;

    if (t) {
        tree_nodal(m, k, t, xr, yr);
        tree_nodal(m, k, t, xi, yi);
        return;
    }
    for (int c = 0; c < 3 * m->n_nodes; c++) {
        const double *jc = &DM(&k->Jn, 0, c);
        double a = 0, b = 0;
        for (int i = 0; i < n; i++) {
            a += jc[i] * xr[i];
            b += jc[i] * xi[i];
        }
        yr[c] = a;
        yi[c] = b;
    }
}

/* x, y, phi of every node; the largest rotation relative to the frame is
 * phi_k - (theta_s - theta0_s). */
static double planar_nodes(const sm_model *m, void *kin, double *nodes, int *at)
{
    const sm_kin *k = kin;
    double rot = 0;

    *at = -1;
    memcpy(nodes, k->rn, 3 * (size_t)m->n_nodes * sizeof(double));
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        for (int i = 0; i < b->nfree; i++) {
            double p = k->rn[3 * b->free_nodes[i] + 2] - (k->theta[s] - b->theta0);
            if (fabs(p) > rot) {
                rot = fabs(p);
                *at = b->free_nodes[i];
            }
        }
    }
    return rot;
}

/* t along the deformed chord n1 -> n2, p2 the in-plane normal, p3 = z. */
static void planar_label_axes(const sm_model *m, const sm_case *c, const sm_elem *e, double t[3],
                              double p2[3], double p3[3])
{
    const double *a = c->nodes + (size_t)3 * e->n1, *b = c->nodes + (size_t)3 * e->n2;
    double n;

    (void)m;
    t[0] = b[0] - a[0], t[1] = b[1] - a[1], t[2] = 0;
    n = sqrt(smi_dot3(t, t));
    for (int k = 0; k < 3; k++)
        t[k] /= n;
    p2[0] = -t[1], p2[1] = t[0], p2[2] = 0;
    p3[0] = 0, p3[1] = 0, p3[2] = 1;
}

/* (dx, dy, dphi) -> (dx, dy, 0), (0, 0, dphi). */
static void planar_label_node(const double *s, int k, double d[3], double r[3])
{
    d[0] = s[3 * (size_t)k], d[1] = s[3 * (size_t)k + 1], d[2] = 0;
    r[0] = 0, r[1] = 0, r[2] = s[3 * (size_t)k + 2];
}

/* In-plane bending (EI) in the edge slot; no torsion. */
static void planar_label_strain(const sm_elem *E, const double v[2], const double w[2],
                                const double tx[2], const double r2[2], const double r3[2],
                                double e[SM_ENERGY_PARTS])
{
    (void)w, (void)tx, (void)r2;
    e[5] += smi_elem_bending_energy(E->EI, E->l, v[0], r3[0], v[1], r3[1]);
}

const smi_kind smi_kind_planar = {
    .name = "planar",
    .spatial = 0,
    .axes = 0,
    .node_dof = 3,
    .pose_dof = 3,
    .ubar_dim = 2,
    .stiffened_start = 0,
    .fixed_bits = 1,
    .length = planar_length,
    .check = planar_check,
    .elements = NULL,
    .subs = planar_subs,
    .count = modes_count,
    .basis = modes_planar_sub,
    .points = modes_planar_points,
    .kin_new = planar_kin_new,
    .kin_free = planar_kin_free,
    .kin_eval = planar_kin_eval,
    .node_jacobian = planar_node_jacobian,
    .centrifugal = planar_centrifugal,
    .geometric_force = lin_geometric_force,
    .dense_alloc = planar_dense_alloc,
    .dense_tangent = planar_dense_tangent,
    .dense_linearize = planar_dense_linearize,
    .tree_assemble = planar_tree_assemble,
    .nodal = planar_nodal,
    .nodes = planar_nodes,
    .label_bending = 1,
    .label_axes = planar_label_axes,
    .label_node = planar_label_node,
    .label_rotary = NULL,
    .label_strain = planar_label_strain,
    .label_point = NULL,
};
