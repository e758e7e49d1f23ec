/*
 * kind_spatial.c — the spatial structure kind (kind.h, DESIGN.md 7): 6 DOF per node,
 * frames with full orientations, rotary inertia.
 *
 * How it fits: the table smi_kind_spatial routes the shared code (mesh.c, modes.c,
 * equilibrium.c, linsys.c, sweep.c) to the spatial modules of spatial.h — mesh3.c
 * (checks, axes, orientations), modes3.c (bases, points), frames3.c (poses, g, H by
 * complex step), lin3.c (f_g, tangent, M*, C*, nodal outputs), tree3.c (the block form).
 * Each entry makes the calls the spatial path made before the table, in the same order.
 */
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

static void spatial_dense_tangent(const sm_model *m, const double *q, void *k, double s, smi_dense *D,
                                  double *work)
{
    lin3_tangent(m, q, k, s, 0, &D->K, &D->H, work);
}

/* K*, P frozen; M*; C* (DESIGN.md 7.3). */
static void spatial_dense_linearize(const sm_model *m, const double *q, void *k, double omega, int gyro,
                                    smi_dense *D, double *work)
{
    sp_eval(m, q, k);
    lin3_tangent(m, q, k, omega * omega, 1, &D->K, &D->H, work);
    lin3_mass(m, k, &D->M, &D->W);
    if (gyro)
        lin3_gyro(m, k, omega, &D->C, &D->W);
}

static int spatial_tree_assemble(const sm_model *m, const double *q, void *k, double s, int lin, int gyro,
                                 tree_ws *t)
{
    return tree3_assemble(m, q, k, s, lin, lin, lin && gyro, t);
}

static void spatial_nodal(const sm_model *m, void *k, tree_ws *t, const double *x, double *y)
{
    if (t)
        tree3_nodal(m, k, t, x, y);
    else
        lin3_nodal(m, k, x, y);
}

/* |psi|: the rotation relative to the own frame. */
static double spatial_nodes(const sm_model *m, void *k, double *nodes, int *at)
{
    return lin3_nodes(m, k, nodes, at);
}

const smi_kind smi_kind_spatial = {
    .name = "spatial",
    .spatial = 1,
    .axes = 1,
    .node_dof = 6,
    .pose_dof = 6,
    .ubar_dim = 3,
    .stiffened_start = 1,
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
    .centrifugal = spatial_centrifugal,
    .geometric_force = lin3_geometric_force,
    .dense_alloc = spatial_dense_alloc,
    .dense_tangent = spatial_dense_tangent,
    .dense_linearize = spatial_dense_linearize,
    .tree_assemble = spatial_tree_assemble,
    .nodal = spatial_nodal,
    .nodes = spatial_nodes,
};
