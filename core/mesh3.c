/*
 * mesh3.c — the spatial part of the mesh phase (DESIGN.md 7.1-7.2): checks of
 * the spatial input, the principal axes and section data of every element,
 * the lumped rotary inertia of the nodes and the orientation of every frame.
 * mesh.c does the topology (walk, numbering, substructures) for both kinds.
 */
#include "spatial.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* A member is taken as lying along the spin axis when the in-plane part of its direction is
 * below this (unit direction). */
#define MESH3_ALONG_Z 1e-9
/* A flap direction whose part normal to the member is below this fraction of its length is
 * unusable. */
#define MESH3_PARALLEL 1e-6

static int mesh3_fail(sm_diag *d, sm_item item, int index, const char *field, const char *msg)
{
    if (d) {
        d->status = SM_INVALID_INPUT;
        d->item = item;
        d->item_index = index;
        snprintf(d->field, sizeof d->field, "%s", field);
        snprintf(d->message, sizeof d->message, "%s", msg);
    }
    return SM_INVALID_INPUT;
}

static int mesh3_positive(double v)
{
    return isfinite(v) && v > 0.0;
}

static int mesh3_nonneg(double v)
{
    return isfinite(v) && v >= 0.0;
}

/* Spatial section s: stiffnesses and mass positive, inertias non-negative. */
static int mesh3_section(const sm_section *c, int s, sm_diag *d)
{
    static const char *pos[] = {"EA", "EI_flap", "EI_edge", "GJ", "mass_per_length"};
    static const char *units[] = {"N", "N m^2", "N m^2", "N m^2", "kg/m"};
    double pv[] = {c->EA, c->EI_flap, c->EI_edge, c->GJ, c->mu};
    char msg[128];
    for (int i = 0; i < 5; i++)
        if (!mesh3_positive(pv[i])) {
            snprintf(msg, sizeof msg, "%s must be a positive number (%s)", pos[i], units[i]);
            return mesh3_fail(d, SM_ITEM_SECTION, s, pos[i], msg);
        }
    if (!mesh3_nonneg(c->i_flap))
        return mesh3_fail(d, SM_ITEM_SECTION, s, "flap_inertia",
                          "flap_inertia must be a non-negative number (kg m)");
    if (!mesh3_nonneg(c->i_edge))
        return mesh3_fail(d, SM_ITEM_SECTION, s, "edge_inertia",
                          "edge_inertia must be a non-negative number (kg m)");
    if (!mesh3_nonneg(c->ip_over_a))
        return mesh3_fail(d, SM_ITEM_SECTION, s, "ip_over_a",
                          "the polar radius of gyration squared I_p/A must be a non-negative number (m^2)");
    return SM_OK;
}

int mesh3_check(const sm_structure *st, const sm_options *o, sm_diag *d)
{
    for (int j = 0; st->joint_z && j < st->n_joints; j++)
        if (!isfinite(st->joint_z[j]))
            return mesh3_fail(d, SM_ITEM_JOINT, j, "z", "joint coordinates must be finite numbers");
    for (int s = 0; s < st->n_sections; s++) {
        int rc = mesh3_section(&st->sections[s], s, d);
        if (rc < 0)
            return rc;
    }
    for (int i = 0; i < st->n_members; i++) {
        const sm_member *b = &st->members[i];
        if (!isfinite(b->twist))
            return mesh3_fail(d, SM_ITEM_MEMBER, i, "twist_deg", "twist_deg must be a finite number (deg)");
        if (!isfinite(b->e3[0]) || !isfinite(b->e3[1]) || !isfinite(b->e3[2]))
            return mesh3_fail(d, SM_ITEM_MEMBER, i, "flap_direction",
                              "flap_direction must be three finite numbers");
    }
    for (int i = 0; i < st->n_point_masses; i++)
        for (int c = 0; c < 3; c++)
            if (!mesh3_nonneg(st->point_masses[i].inertia[c]))
                return mesh3_fail(d, SM_ITEM_POINT_MASS, i, "inertia",
                                  "inertia must be three non-negative numbers (kg m^2)");
    if (o->basis == SM_BASIS_PAPER)
        return mesh3_fail(d, SM_ITEM_OPTIONS, -1, "substructure_modes",
                          "the paper basis is planar-only (it exists to reproduce Table 2): use "
                          "\"augmented\" for a spatial structure");
    return SM_OK;
}

int mesh3_check_planar(const sm_structure *st, sm_diag *d)
{
    for (int j = 0; st->joint_z && j < st->n_joints; j++)
        if (st->joint_z[j] != 0.0)
            return mesh3_fail(d, SM_ITEM_JOINT, j, "z",
                              "a joint out of the x-y plane needs spatial sections (EA, EI_flap, "
                              "EI_edge, GJ, mass_per_length)");
    for (int i = 0; i < st->n_members; i++) {
        const sm_member *b = &st->members[i];
        if (b->twist != 0.0)
            return mesh3_fail(d, SM_ITEM_MEMBER, i, "twist_deg", "twist_deg needs spatial sections");
        if (b->e3[0] != 0.0 || b->e3[1] != 0.0 || b->e3[2] != 0.0)
            return mesh3_fail(d, SM_ITEM_MEMBER, i, "flap_direction", "flap_direction needs spatial sections");
    }
    for (int i = 0; i < st->n_point_masses; i++) {
        const double *I = st->point_masses[i].inertia;
        if (I[0] != 0.0 || I[1] != 0.0 || I[2] != 0.0)
            return mesh3_fail(d, SM_ITEM_POINT_MASS, i, "inertia", "a rotary inertia needs spatial sections");
    }
    return SM_OK;
}

static double mesh3_norm(const double v[3])
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/*
 * Principal axes of member i (DESIGN.md 7.1) into ax (columns e1 from -> to, p2, p3).
 * e3: the part of flap_direction (or of z; for a member along z, of the radial direction of its
 * midpoint) normal to e1; e2 = e3 x e1; the twist turns (e2, e3) about e1.
 */
static int mesh3_axes(const sm_structure *st, int i, double ax[9], sm_diag *d)
{
    const sm_member *b = &st->members[i];
    const double *P = st->joint_xy, *Z = st->joint_z;
    double e1[3] = {P[2 * b->to] - P[2 * b->from], P[2 * b->to + 1] - P[2 * b->from + 1],
                    Z ? Z[b->to] - Z[b->from] : 0.0};
    double l = mesh3_norm(e1), f[3], e2[3], e3[3];
    for (int c = 0; c < 3; c++)
        e1[c] /= l;
    if (b->e3[0] != 0.0 || b->e3[1] != 0.0 || b->e3[2] != 0.0) {
        memcpy(f, b->e3, sizeof f);
    } else if (hypot(e1[0], e1[1]) > MESH3_ALONG_Z) {
        f[0] = 0, f[1] = 0, f[2] = 1; /* the hub axis */
    } else {
        /* along the spin axis: the radial direction of the midpoint */
        f[0] = 0.5 * (P[2 * b->to] + P[2 * b->from]);
        f[1] = 0.5 * (P[2 * b->to + 1] + P[2 * b->from + 1]);
        f[2] = 0;
        if (!(hypot(f[0], f[1]) > 1e-12 * l))
            return mesh3_fail(d, SM_ITEM_MEMBER, i, "flap_direction",
                              "the member lies on the spin axis, where the flapwise direction has no "
                              "default: give flap_direction [x, y, z], a direction not along the member");
    }
    double fn = mesh3_norm(f), fe = f[0] * e1[0] + f[1] * e1[1] + f[2] * e1[2];
    for (int c = 0; c < 3; c++)
        e3[c] = f[c] - fe * e1[c];
    double n3 = mesh3_norm(e3);
    if (!(n3 > MESH3_PARALLEL * fn))
        return mesh3_fail(d, SM_ITEM_MEMBER, i, "flap_direction",
                          "flap_direction is along the member: give a direction normal to it");
    for (int c = 0; c < 3; c++)
        e3[c] /= n3;
    e2[0] = e3[1] * e1[2] - e3[2] * e1[1]; /* e2 = e3 x e1 */
    e2[1] = e3[2] * e1[0] - e3[0] * e1[2];
    e2[2] = e3[0] * e1[1] - e3[1] * e1[0];
    double ct = cos(b->twist), sn = sin(b->twist);
    for (int c = 0; c < 3; c++) {
        ax[c] = e1[c];
        ax[3 + c] = ct * e2[c] + sn * e3[c];  /* p2 */
        ax[6 + c] = -sn * e2[c] + ct * e3[c]; /* p3 */
    }
    return SM_OK;
}

/* node->rot += h * ax diag(d) ax' (a tensor given in the axes ax, added in hub axes). */
static void mesh3_add_tensor(double rot[9], const double ax[9], const double dg[3], double h)
{
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                rot[i + 3 * j] += h * ax[i + 3 * k] * dg[k] * ax[j + 3 * k];
}

int mesh3_elements(sm_model *m, const sm_structure *st, sm_diag *d)
{
    int done = -1;
    double ax[9];
    for (int e = 0; e < m->n_elems; e++) {
        sm_elem *el = &m->elems[e];
        const sm_member *b = &st->members[el->member];
        const sm_section *c = &st->sections[b->section];
        if (el->member != done) {
            int rc = mesh3_axes(st, el->member, ax, d);
            if (rc < 0)
                return rc;
            done = el->member;
        }
        /* the element runs from n1 (nearer the clamp) to n2: e1 and p2 turn with it */
        const sm_node *a = &m->nodes[el->n1], *z = &m->nodes[el->n2];
        double dir[3] = {z->x - a->x, z->y - a->y, z->z - a->z};
        double sg = dir[0] * ax[0] + dir[1] * ax[1] + dir[2] * ax[2] < 0 ? -1.0 : 1.0;
        for (int k = 0; k < 3; k++) {
            el->ax[k] = sg * ax[k];
            el->ax[3 + k] = sg * ax[3 + k];
            el->ax[6 + k] = ax[6 + k];
        }
        el->EA = c->EA;
        el->EI = 0.0;
        el->GJ = c->GJ;
        el->EI_edge = c->EI_edge;
        el->EI_flap = c->EI_flap;
        el->mu = c->mu;
        el->i_flap = c->i_flap;
        el->i_edge = c->i_edge;
        el->ip_over_a = c->ip_over_a;
        /* lumped rotary inertia: half the element's on each node (torsion = i_flap + i_edge) */
        double dg[3] = {c->i_flap + c->i_edge, c->i_flap, c->i_edge};
        mesh3_add_tensor(m->nodes[el->n1].rot, el->ax, dg, 0.5 * el->l);
        mesh3_add_tensor(m->nodes[el->n2].rot, el->ax, dg, 0.5 * el->l);
    }
    static const double hub[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    for (int i = 0; i < st->n_point_masses; i++) {
        sm_node *nd = &m->nodes[m->joint_node[st->point_masses[i].joint]];
        mesh3_add_tensor(nd->rot, hub, st->point_masses[i].inertia, 1.0);
        mesh3_add_tensor(nd->point_rot, hub, st->point_masses[i].inertia, 1.0);
    }
    return SM_OK;
}

void mesh3_subs(sm_model *m)
{
    for (int k = 0; k < m->n_subs; k++) {
        sm_sub *b = &m->subs[k];
        const sm_node *r = &m->nodes[b->root];
        memcpy(b->A0, m->elems[b->elems[0]].ax, sizeof b->A0);
        for (int i = 0; i < b->nfree; i++) {
            const sm_node *nd = &m->nodes[b->free_nodes[i]];
            double dx[3] = {nd->x - r->x, nd->y - r->y, nd->z - r->z};
            for (int c = 0; c < 3; c++) /* ubar = A0' (X - X_root) */
                b->ubar[3 * i + c] = b->A0[3 * c] * dx[0] + b->A0[3 * c + 1] * dx[1] + b->A0[3 * c + 2] * dx[2];
        }
        if (b->parent >= 0)
            rot3_tmul_r(m->subs[b->parent].A0, b->A0, b->Arel);
        else
            memcpy(b->Arel, b->A0, sizeof b->Arel);
    }
}
