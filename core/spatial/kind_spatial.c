/*
 * kind_spatial.c — the spatial structure kind (kind.h, DESIGN.md 7): 6 DOF per node,
 * frames with full orientations, rotary inertia.
 *
 * How it fits: the table smi_kind_spatial routes the shared code (mesh.c, modes.c,
 * equilibrium.c, linsys.c, sweep.c) to the spatial modules of spatial.h — mesh3.c
 * (checks, axes, orientations), modes3.c (bases, points), frames3.c (poses, g),
 * hessian3.c (H in closed form), lin3.c (f_g, tangent, M*, C*, nodal outputs), tree3.c (the block form).
 * Each entry makes the calls the spatial path made before the table, in the same order.
 */
#include "element.h"
#include "kind.h"
#include "spatial.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double spatial_length(double dx, double dy, double dz)
{
    return sqrt(dx * dx + dy * dy + dz * dz);
}

static void *spatial_kin_new(const sm_model *m, int use)
{
    sp_kin *k = calloc(1, sizeof *k);

    if (!k)
        return NULL;
    if (sp_kin_alloc(m, k, use == SMI_USE_MODES) != SM_OK) {
        free(k);
        return NULL;
    }
    return k;
}

static void spatial_kin_free(void *k)
{
    if (k)
        sp_kin_free(k);
    free(k);
}

static void spatial_kin_eval(const sm_model *m, const double *q, void *k)
{
    sp_eval(m, q, k);
}

/* The FE nodes are the first n_nodes points of JW (n x 6 n_pt); a point with a mass offset
 * moves the offset mass, r_p = r_node + dh: the node's translation is J_p - dtheta x dh. */
static void spatial_node_jacobian(const sm_model *m, const void *kin, int nd, double *J)
{
    const sp_kin *k = kin;
    size_t n = (size_t)m->n;

    memcpy(J, &DM(&k->JW, 0, 6 * nd), 6 * n * sizeof(double));
    if (!m->pt[nd].has_c)
        return;
    const double *dh = k->dh + 3 * nd, *W = J + 3 * n;
    for (size_t x = 0; x < n; x++) {
        J[x] -= W[n + x] * dh[2] - W[2 * n + x] * dh[1];
        J[n + x] -= W[2 * n + x] * dh[0] - W[x] * dh[2];
        J[2 * n + x] -= W[x] * dh[1] - W[n + x] * dh[0];
    }
}

static void spatial_centrifugal(const sm_model *m, const double *q, void *k, tree_ws *t, double *g)
{
    (void)t;
    sp_centrifugal(m, q, k, g);
}

/* Newton: K (the tangent) and H; modes: M, C, K, H and W (n x 6 P). */
static int spatial_dense_alloc(const sm_model *m, int use, smi_dense *D)
{
    int n = m->n;

    memset(D, 0, sizeof *D);
    if (dm_alloc(&D->K, n, n) || dm_alloc(&D->H, n, n))
        return SM_NOMEM;
    if (use == SMI_USE_MODES &&
        (dm_alloc(&D->M, n, n) || dm_alloc(&D->C, n, n) || dm_alloc(&D->W, n, 6 * m->n_pt)))
        return SM_NOMEM;
    return SM_OK;
}

static void spatial_dense_tangent(const sm_model *m, const double *q, void *k, double s,
                                  smi_dense *D, double *work)
{
    lin3_tangent(m, q, k, s, 0, &D->K, &D->H, work);
}

/* K*, P frozen; M*; C* (DESIGN.md 7.3). */
static void spatial_dense_linearize(const sm_model *m, const double *q, void *k, double omega,
                                    int gyro, smi_dense *D, double *work)
{
    sp_eval(m, q, k);
    lin3_tangent(m, q, k, smi_load(m, omega), 1, &D->K, &D->H, work);
    lin3_mass(m, k, &D->M, &D->W);
    if (gyro)
        lin3_gyro(m, k, omega, &D->C, &D->W);
}

static int spatial_tree_assemble(const sm_model *m, const double *q, void *k, double s, int lin,
                                 int gyro, tree_ws *t)
{
    return tree3_assemble(m, q, k, s, lin, lin, lin && gyro, t);
}

static void spatial_nodal(const sm_model *m, void *k, tree_ws *t, const double *xr,
                          const double *xi, double *yr, double *yi)
{
    if (t) {
        tree3_nodal(m, k, t, xr, yr);
        tree3_nodal(m, k, t, xi, yi);
    } else {
        lin3_nodal(m, k, xr, yr);
        lin3_nodal(m, k, xi, yi);
    }
}

/* |psi|: the rotation relative to the own frame. */
static double spatial_nodes(const sm_model *m, void *k, double *nodes, int *at)
{
    return lin3_nodes(m, k, nodes, at);
}

/* v rotated by the rotation vector psi (Rodrigues): v cos + (k x v) sin + k (k.v)(1 - cos). */
static void spatial_rotate(const double psi[3], double v[3])
{
    double th = sqrt(smi_dot3(psi, psi));
    if (!(th > 0))
        return;
    double k[3] = {psi[0] / th, psi[1] / th, psi[2] / th}, kv = smi_dot3(k, v), cs = cos(th),
           sn = sin(th);
    double x[3] = {k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]};
    for (int i = 0; i < 3; i++)
        v[i] = v[i] * cs + x[i] * sn + k[i] * kv * (1 - cs);
}

/* t along the deformed chord n1 -> n2, p2 the rest p2 turned by the mean rotation of the two
 * nodes and made normal to t, p3 = t x p2. */
static void spatial_label_axes(const sm_model *m, const sm_case *c, const sm_elem *e, double t[3],
                               double p2[3], double p3[3])
{
    const double *a = c->nodes + (size_t)6 * e->n1, *b = c->nodes + (size_t)6 * e->n2;
    double psi[3], n, d;

    (void)m;
    t[0] = b[0] - a[0], t[1] = b[1] - a[1], t[2] = b[2] - a[2];
    n = sqrt(smi_dot3(t, t));
    for (int k = 0; k < 3; k++)
        t[k] /= n;
    for (int k = 0; k < 3; k++) {
        p2[k] = e->ax[3 + k];
        psi[k] = 0.5 * (a[3 + k] + b[3 + k]);
    }
    spatial_rotate(psi, p2);
    d = smi_dot3(p2, t);
    for (int k = 0; k < 3; k++)
        p2[k] -= d * t[k];
    n = sqrt(smi_dot3(p2, p2));
    for (int k = 0; k < 3; k++)
        p2[k] /= n;
    p3[0] = t[1] * p2[2] - t[2] * p2[1];
    p3[1] = t[2] * p2[0] - t[0] * p2[2];
    p3[2] = t[0] * p2[1] - t[1] * p2[0];
}

static void spatial_label_node(const double *s, int k, double d[3], double r[3])
{
    memcpy(d, s + 6 * (size_t)k, 3 * sizeof(double));
    memcpy(r, s + 6 * (size_t)k + 3, 3 * sizeof(double));
}

/* Half the section's rotary inertia at each end: i_flap + i_edge on tx, i_flap on p2.r,
 * i_edge on p3.r. */
static void spatial_label_rotary(const sm_elem *E, double tx, double r2, double r3,
                                 double e[SM_ENERGY_PARTS])
{
    e[3] += 0.5 * E->l * (E->i_flap + E->i_edge) * tx * tx;
    e[2] += 0.5 * E->l * E->i_flap * r2 * r2;
    e[1] += 0.5 * E->l * E->i_edge * r3 * r3;
}

/* Edge (v' = p3.r), flap (w' = -p2.r) and torsion. */
static void spatial_label_strain(const sm_elem *E, const double v[2], const double w[2],
                                 const double tx[2], const double r2[2], const double r3[2],
                                 double e[SM_ENERGY_PARTS])
{
    e[5] += smi_elem_bending_energy(E->EI_edge, E->l, v[0], r3[0], v[1], r3[1]);
    e[6] += smi_elem_bending_energy(E->EI_flap, E->l, w[0], -r2[0], w[1], -r2[1]);
    e[7] += smi_elem_bar_energy(E->GJ, E->l, tx[0], tx[1]);
}

/* Point-mass rotary inertia of the far node of element el in its axes axes = (t, p2, p3): its
 * diagonal. */
static void spatial_label_point(const sm_model *m, int el, const double axes[9], const double *s,
                                double e[SM_ENERGY_PARTS])
{
    const sm_elem *E = &m->elems[el];
    const double *P = m->nodes[E->n2].point_rot, *ax[3] = {axes, axes + 3, axes + 6};
    double d[3], r[3];
    int slot[3] = {3, 2, 1}; /* about t: torsion; about p2: flap; about p3: edge */

    spatial_label_node(s, E->n2, d, r);
    for (int a = 0; a < 3; a++) {
        double Pa[3], ra = smi_dot3(ax[a], r);
        for (int i = 0; i < 3; i++)
            Pa[i] = P[i] * ax[a][0] + P[i + 3] * ax[a][1] + P[i + 6] * ax[a][2];
        e[slot[a]] += smi_dot3(ax[a], Pa) * ra * ra; /* (a' P a) (a.r)^2 */
    }
}

const smi_kind smi_kind_spatial = {
    .name = "spatial",
    .spatial = 1,
    .axes = 1,
    .node_dof = 6,
    .pose_dof = 6,
    .ubar_dim = 3,
    .stiffened_start = 1,
    .fixed_bits = 0,
    .length = spatial_length,
    .check = mesh3_check,
    .elements = mesh3_elements,
    .subs = mesh3_subs,
    .count = modes3_count,
    .basis = modes3_sub,
    .points = modes3_points,
    .kin_new = spatial_kin_new,
    .kin_free = spatial_kin_free,
    .kin_eval = spatial_kin_eval,
    .node_jacobian = spatial_node_jacobian,
    .centrifugal = spatial_centrifugal,
    .geometric_force = lin3_geometric_force,
    .dense_alloc = spatial_dense_alloc,
    .dense_tangent = spatial_dense_tangent,
    .dense_linearize = spatial_dense_linearize,
    .tree_assemble = spatial_tree_assemble,
    .nodal = spatial_nodal,
    .nodes = spatial_nodes,
    .label_bending = 0,
    .label_axes = spatial_label_axes,
    .label_node = spatial_label_node,
    .label_rotary = spatial_label_rotary,
    .label_strain = spatial_label_strain,
    .label_point = spatial_label_point,
};
