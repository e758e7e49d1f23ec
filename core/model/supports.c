/*
 * supports.c — elastic supports (sm_support, DESIGN.md 8.6): their checks, their lumping onto
 * FE nodes, and their stiffness and added mass in modal coordinates.
 *
 * How it fits: model layer.  mesh_check calls supports_check (with the other input checks);
 * model.c calls supports_lump after the mesh (node positions, element axes) and
 * supports_build after the component-mode bases.  A support is a spring and an added mass on
 * the motion of nodes from rest, 6x6 per node in hub axes over (x, y, z, rx, ry, rz); in modal
 * coordinates it is K_sup = sum_k J0_k' K_k J0_k and M_sup = sum_k J0_k' M_k J0_k with J0_k the
 * node's motion per modal coordinate at q = 0, read from the kind (node_jacobian of kind.h).
 * Both are dense n x n: a model with supports takes the dense path (tree_use).  The elastic
 * terms (elastic.c) add K_sup to K everywhere K is used (F, the Newton tangent, K*), and the
 * linear system adds M_sup to M* (linsys.c).
 */
#include "kind.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The planar kind's node motion (dx, dy, dphi) is (x, y, rz) of the 6x6. */
static const int sup_planar_dof[3] = {0, 1, 5};

/* 1 when the 6x6 a is finite and symmetric within 1e-9 of its largest entry. */
static int sup_symmetric(const double a[36])
{
    double mx = 0;

    for (int i = 0; i < 36; i++) {
        if (!isfinite(a[i]))
            return 0;
        mx = fmax(mx, fabs(a[i]));
    }
    for (int j = 0; j < 6; j++)
        for (int i = 0; i < j; i++)
            if (fabs(a[i + 6 * j] - a[j + 6 * i]) > 1e-9 * mx)
                return 0;
    return 1;
}

/* The smallest eigenvalue of the symmetric 6x6 a relative to its largest |eigenvalue| (0 for a
 * zero matrix); NAN when LAPACK fails. */
static double sup_lowest(const double a[36])
{
    double c[36], w[6];

    memcpy(c, a, sizeof c);
    if (LAPACKE_dsyev(LAPACK_COL_MAJOR, 'N', 'L', 6, c, 6, w) != 0)
        return NAN;
    double mx = fmax(fabs(w[0]), fabs(w[5]));
    return mx > 0 ? w[0] / mx : 0.0;
}

/* A 6x6 of a point support: symmetric and positive semi-definite. */
static int sup_check_matrix(sm_diag *d, int i, const char *field, const double a[36])
{
    if (!sup_symmetric(a))
        return smi_input_fail(d, SM_ITEM_SUPPORT, i, field,
                              "the 6x6 matrix must be finite and symmetric (within 1e-9 of its "
                              "largest entry)");
    double low = sup_lowest(a);
    if (!(low >= -1e-9))
        return smi_input_fail(d, SM_ITEM_SUPPORT, i, field,
                              "the 6x6 matrix must be positive semi-definite (it has a negative "
                              "eigenvalue)");
    return SM_OK;
}

/* A foundation's stretch and per-length values; L: the member's length. */
static int sup_check_foundation(const sm_support *s, int i, double L, sm_diag *d)
{
    for (int k = 0; k < 4; k++)
        if (!isfinite(s->k_per_length[k]) || s->k_per_length[k] < 0)
            return smi_input_fail(d, SM_ITEM_SUPPORT, i, "k_per_length",
                                  "stiffness per length must be non-negative numbers (N/m per m, "
                                  "N m/rad per m)");
    if (!isfinite(s->added_mass_per_length) || s->added_mass_per_length < 0)
        return smi_input_fail(d, SM_ITEM_SUPPORT, i, "added_mass_per_length",
                              "added mass per length must be a non-negative number (kg/m)");
    if (!isfinite(s->from_s) || s->from_s < 0 || s->from_s >= L * (1 + 1e-12))
        return smi_input_fail(d, SM_ITEM_SUPPORT, i, "from_s",
                              "the stretch must start on the member (0 <= from_s < its length, m)");
    if (!isfinite(s->to_s) || s->to_s <= s->from_s || s->to_s > L * (1 + 1e-9))
        return smi_input_fail(d, SM_ITEM_SUPPORT, i, "to_s",
                              "the stretch must end on the member, after it starts (from_s < to_s "
                              "<= its length, m)");
    return SM_OK;
}

int supports_check(const sm_structure *st, const sm_options *o, sm_diag *d)
{
    for (int i = 0; i < st->n_supports; i++) {
        const sm_support *s = &st->supports[i];
        int rc;
        if ((s->joint >= 0) == (s->member >= 0))
            return smi_input_fail(d, SM_ITEM_SUPPORT, i, "",
                                  "a support is at a joint or along a member: exactly one of them");
        if (s->joint >= 0) {
            if (s->joint >= st->n_joints)
                return smi_input_fail(d, SM_ITEM_SUPPORT, i, "joint", "unknown joint");
            if ((rc = sup_check_matrix(d, i, "K", s->K)) < 0 ||
                (rc = sup_check_matrix(d, i, "M", s->M)) < 0)
                return rc;
            if (!st->spatial && (s->K[35] != 0 || s->M[35] != 0 || s->K[5] != 0 || s->K[11] != 0 ||
                                 s->M[5] != 0 || s->M[11] != 0))
                return smi_input_fail(d, SM_ITEM_SUPPORT, i,
                                      s->K[35] != 0 || s->K[5] != 0 || s->K[11] != 0 ? "K" : "M",
                                      "a rotational support needs spatial sections: the planar "
                                      "basis condenses the rotations of its nodes (DESIGN.md 1.2)");
            continue;
        }
        if (s->member >= st->n_members)
            return smi_input_fail(d, SM_ITEM_SUPPORT, i, "member", "unknown member");
        const sm_member *b = &st->members[s->member];
        double dx = st->joint_xy[2 * b->to] - st->joint_xy[2 * b->from];
        double dy = st->joint_xy[2 * b->to + 1] - st->joint_xy[2 * b->from + 1];
        double dz = st->joint_z ? st->joint_z[b->to] - st->joint_z[b->from] : 0.0;
        if ((rc = sup_check_foundation(s, i, sqrt(dx * dx + dy * dy + dz * dz), d)) < 0)
            return rc;
    }
    if (st->base_free) {
        int held = 0;
        if (!st->spatial)
            return smi_input_fail(d, SM_ITEM_CLAMP, -1, "",
                                  "a free base (elastic clamp, floating platform) needs spatial "
                                  "sections");
        for (int i = 0; i < st->n_supports; i++)
            held |= st->supports[i].joint == st->clamp;
        if (st->base_held & ~0x3fu)
            return smi_input_fail(
                d, SM_ITEM_CLAMP, -1, "",
                "the held directions of a base are bits 0..5 (x, y, z, rx, ry, rz)");
        if ((st->base_held & 0x3fu) == 0x3fu)
            return smi_input_fail(d, SM_ITEM_CLAMP, -1, "",
                                  "a base held in all six directions is a clamp: give the clamp "
                                  "joint without base_free");
        if (!held)
            return smi_input_fail(d, SM_ITEM_CLAMP, -1, "",
                                  "a free base needs a point support at the clamp joint (its "
                                  "mass, and stiffness where it is held: none for a free-floating "
                                  "structure)");
        for (int i = 0; i < st->n_point_masses; i++) {
            const sm_point_mass *p = &st->point_masses[i];
            if (p->joint == st->clamp &&
                (p->offset[0] != 0 || p->offset[1] != 0 || p->offset[2] != 0))
                return smi_input_fail(d, SM_ITEM_POINT_MASS, i, "offset",
                                      "a point mass at a free base's clamp joint cannot be offset: "
                                      "give the platform's mass as the support's 6x6 mass");
        }
    }
    int grav = st->gravity[0] != 0 || st->gravity[1] != 0 || st->gravity[2] != 0;
    for (int i = 0; i < 3; i++)
        if (!isfinite(st->gravity[i]))
            return smi_input_fail(d, SM_ITEM_OPTIONS, -1, "gravity",
                                  "gravity must be three finite numbers (m/s^2)");
    if (grav && !st->spatial)
        return smi_input_fail(d, SM_ITEM_OPTIONS, -1, "gravity", "gravity needs spatial sections");
    if (grav && st->base_free)
        return smi_input_fail(d, SM_ITEM_OPTIONS, -1, "gravity",
                              "gravity on a free base (a platform's weight against its buoyancy) "
                              "is not supported yet");
    if (grav && o->solver == SM_SOLVER_TREE)
        return smi_input_fail(d, SM_ITEM_OPTIONS, -1, "solver",
                              "gravity needs the dense solver (solver auto or dense)");
    if (st->n_supports > 0 && o->solver == SM_SOLVER_TREE)
        return smi_input_fail(d, SM_ITEM_OPTIONS, -1, "solver",
                              "elastic supports couple the frames: they need the dense solver "
                              "(solver auto or dense)");
    return SM_OK;
}

/* Element e's axes at rest in hub components: e1, p2, p3 (the planar kind: from its angle). */
static void sup_axes(const sm_model *m, const sm_elem *e, double ax[9])
{
    if (m->kind->axes) {
        memcpy(ax, e->ax, 9 * sizeof(double));
        return;
    }
    double c = cos(e->angle), s = sin(e->angle);
    const double a[9] = {c, s, 0, -s, c, 0, 0, 0, 1};
    memcpy(ax, a, sizeof a);
}

/* k6 += len times a foundation's springs (and m6 its added mass) in element e's axes. */
static void sup_lump(const sm_model *m, const sm_elem *e, const sm_support *s, double len,
                     double *k6, double *m6)
{
    double ax[9];

    sup_axes(m, e, ax);
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++) {
            double kt = 0, ma = 0;
            for (int a = 0; a < 3; a++)
                kt += s->k_per_length[a] * ax[i + 3 * a] * ax[j + 3 * a];
            for (int a = 1; a < 3; a++)
                ma += s->added_mass_per_length * ax[i + 3 * a] * ax[j + 3 * a];
            k6[i + 6 * j] += len * kt;
            k6[(i + 3) + 6 * (j + 3)] += len * s->k_per_length[3] * ax[i] * ax[j];
            m6[i + 6 * j] += len * ma;
        }
}

/* Length of [a, b] inside [lo, hi]. */
static double sup_overlap(double a, double b, double lo, double hi)
{
    return fmax(0.0, fmin(b, hi) - fmax(a, lo));
}

/* The distance of node nd from the from joint of member i, m. */
static double sup_distance(const sm_node *nd, const sm_structure *st, int i)
{
    int j = st->members[i].from;
    double dx = nd->x - st->joint_xy[2 * j], dy = nd->y - st->joint_xy[2 * j + 1];
    double dz = nd->z - (st->joint_z ? st->joint_z[j] : 0.0);
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* Every support's 6x6 matrices onto its nodes: kn, mn (36 per node, zeroed). */
static void sup_spread(const sm_model *m, const sm_structure *st, double *kn, double *mn)
{
    for (int i = 0; i < st->n_supports; i++) {
        const sm_support *s = &st->supports[i];
        if (s->joint >= 0) {
            int nd = m->joint_node[s->joint];
            for (int c = 0; c < 36; c++) {
                kn[36 * nd + c] += s->K[c];
                mn[36 * nd + c] += s->M[c];
            }
            continue;
        }
        for (int el = 0; el < m->n_elems; el++) {
            const sm_elem *e = &m->elems[el];
            if (e->member != s->member)
                continue;
            /* distances from the member's from joint (a straight member) */
            double a = sup_distance(&m->nodes[e->n1], st, s->member);
            double b = sup_distance(&m->nodes[e->n2], st, s->member), h = 0.5 * (a + b);
            double la = sup_overlap(fmin(a, h), fmax(a, h), s->from_s, s->to_s);
            double lb = sup_overlap(fmin(h, b), fmax(h, b), s->from_s, s->to_s);
            sup_lump(m, e, s, la, kn + 36 * e->n1, mn + 36 * e->n1);
            sup_lump(m, e, s, lb, kn + 36 * e->n2, mn + 36 * e->n2);
        }
    }
}

int supports_lump(sm_model *m, const sm_structure *st)
{
    int rc = SM_NOMEM, count = 0;
    double *kn = NULL, *mn = NULL;

    if (st->n_supports <= 0)
        return SM_OK;
    kn = calloc(36 * (size_t)m->n_nodes, sizeof(double));
    mn = calloc(36 * (size_t)m->n_nodes, sizeof(double));
    if (!kn || !mn)
        goto done;
    sup_spread(m, st, kn, mn);
    for (int nd = m->base ? 0 : 1; nd < m->n_nodes; nd++) /* node 0, the clamp, moves with a
                                                               free base only */
        for (int c = 0; c < 36; c++)
            if (kn[36 * nd + c] != 0.0 || mn[36 * nd + c] != 0.0) {
                count++;
                break;
            }
    m->sup_node = malloc((size_t)(count ? count : 1) * sizeof(int));
    m->sup_k = malloc(36 * (size_t)(count ? count : 1) * sizeof(double));
    m->sup_m = malloc(36 * (size_t)(count ? count : 1) * sizeof(double));
    if (!m->sup_node || !m->sup_k || !m->sup_m)
        goto done;
    m->n_sup = 0;
    for (int nd = m->base ? 0 : 1; nd < m->n_nodes; nd++)
        for (int c = 0; c < 36; c++)
            if (kn[36 * nd + c] != 0.0 || mn[36 * nd + c] != 0.0) {
                m->sup_node[m->n_sup] = nd;
                memcpy(m->sup_k + 36 * m->n_sup, kn + 36 * nd, 36 * sizeof(double));
                memcpy(m->sup_m + 36 * m->n_sup, mn + 36 * nd, 36 * sizeof(double));
                m->n_sup++;
                break;
            }
    m->has_supports = 1;
    rc = SM_OK;
done:
    free(kn);
    free(mn);
    return rc;
}

/* Out += J a J' for the node_dof columns J (ld n) and the kind's part of the 6x6 a. */
static void sup_congruence(int n, int nd, const double *J, const double a[36], double *T, dmat *Out)
{
    double s[36];

    for (int j = 0; j < nd; j++)
        for (int i = 0; i < nd; i++)
            s[i + nd * j] = nd == 6 ? a[i + 6 * j] : a[sup_planar_dof[i] + 6 * sup_planar_dof[j]];
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, n, nd, nd, 1.0, J, n, s, nd, 0.0, T, n);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, n, n, nd, 1.0, T, n, J, n, 1.0, Out->a, n);
}

int supports_build(sm_model *m)
{
    int n = m->n, nd = m->kind->node_dof, rc = SM_NOMEM;
    double *q = NULL, *T = NULL, *J = NULL;
    void *k = NULL;

    if (!m->has_supports)
        return SM_OK;
    q = dm_vec((size_t)n);
    T = dm_vec((size_t)n * (size_t)nd);
    J = dm_vec((size_t)n * (size_t)nd);
    k = m->kind->kin_new(m, SMI_USE_MODES);
    if (!q || !T || !J || !k || dm_alloc(&m->sup_K, n, n) || dm_alloc(&m->sup_M, n, n))
        goto done;
    m->kind->kin_eval(m, q, k); /* rest: q = 0 */
    for (int i = 0; i < m->n_sup; i++) {
        m->kind->node_jacobian(m, k, m->sup_node[i], J);
        sup_congruence(n, nd, J, m->sup_k + 36 * i, T, &m->sup_K);
        sup_congruence(n, nd, J, m->sup_m + 36 * i, T, &m->sup_M);
    }
    for (int j = 0; j < n; j++) /* exactly symmetric */
        for (int i = 0; i < j; i++) {
            DM(&m->sup_K, i, j) = DM(&m->sup_K, j, i) =
                0.5 * (DM(&m->sup_K, i, j) + DM(&m->sup_K, j, i));
            DM(&m->sup_M, i, j) = DM(&m->sup_M, j, i) =
                0.5 * (DM(&m->sup_M, i, j) + DM(&m->sup_M, j, i));
        }
    rc = SM_OK;
done:
    if (k)
        m->kind->kin_free(k);
    free(q);
    free(T);
    free(J);
    return rc;
}

void supports_free(sm_model *m)
{
    free(m->sup_node);
    free(m->sup_k);
    free(m->sup_m);
    dm_free(&m->sup_K);
    dm_free(&m->sup_M);
}

double supports_shape_energy(const sm_model *m, const double *s)
{
    int nd = m->kind->node_dof;
    double e = 0;

    for (int i = 0; i < m->n_sup; i++) {
        const double *K = m->sup_k + 36 * i, *x = s + (size_t)nd * m->sup_node[i];
        for (int a = 0; a < nd; a++)
            for (int b = 0; b < nd; b++) {
                int ra = nd == 6 ? a : sup_planar_dof[a], rb = nd == 6 ? b : sup_planar_dof[b];
                e += x[a] * K[ra + 6 * rb] * x[b];
            }
    }
    return e;
}
