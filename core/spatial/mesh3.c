/*
 * mesh3.c — the spatial part of the mesh phase (DESIGN.md 7.1-7.2): checks of
 * the spatial input, the principal axes and section data of every element,
 * the lumped rotary inertia of the nodes and the orientation of every frame.
 * mesh.c does the topology (walk, numbering, substructures) for both kinds.
 */
#include "spatial.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

/* A member is taken as lying along the spin axis when the in-plane part of its direction is
 * below this (unit direction). */
#define MESH3_ALONG_Z 1e-9
/* A flap direction whose part normal to the member is below this fraction of its length is
 * unusable. */
#define MESH3_PARALLEL 1e-6

static int mesh3_positive(double v)
{
    return isfinite(v) && v > 0.0;
}

static int mesh3_nonneg(double v)
{
    return isfinite(v) && v >= 0.0;
}

static int mesh3_finite2(const double v[2])
{
    return isfinite(v[0]) && isfinite(v[1]);
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
            return smi_input_fail(d, SM_ITEM_SECTION, s, pos[i], msg);
        }
    if (!mesh3_nonneg(c->i_flap))
        return smi_input_fail(d, SM_ITEM_SECTION, s, "flap_inertia",
                              "flap_inertia must be a non-negative number (kg m)");
    if (!mesh3_nonneg(c->i_edge))
        return smi_input_fail(d, SM_ITEM_SECTION, s, "edge_inertia",
                              "edge_inertia must be a non-negative number (kg m)");
    if (!mesh3_nonneg(c->ip_over_a))
        return smi_input_fail(
            d, SM_ITEM_SECTION, s, "ip_over_a",
            "the polar radius of gyration squared I_p/A must be a non-negative number (m^2)");
    if (!mesh3_finite2(c->cg))
        return smi_input_fail(d, SM_ITEM_SECTION, s, "cg_offset",
                              "cg_offset must be two finite numbers (m)");
    if (!mesh3_finite2(c->sc))
        return smi_input_fail(d, SM_ITEM_SECTION, s, "shear_center_offset",
                              "shear_center_offset must be two finite numbers (m)");
    if (!mesh3_finite2(c->tc))
        return smi_input_fail(d, SM_ITEM_SECTION, s, "tension_center_offset",
                              "tension_center_offset must be two finite numbers (m)");
    return SM_OK;
}

/* The quantities a station may give: mask bit, offset in sm_station, name, kind (1 positive,
 * 0 non-negative, -1 any finite) and unit. */
typedef struct mesh3_stq {
    unsigned bit;
    size_t off;
    int count;
    const char *name;
    int kind;
    const char *unit;
} mesh3_stq;

static const mesh3_stq mesh3_stqs[] = {
    {SM_ST_MU, offsetof(sm_station, mu), 1, "mass_per_length", 1, "kg/m"},
    {SM_ST_EA, offsetof(sm_station, EA), 1, "EA", 1, "N"},
    {SM_ST_EI_FLAP, offsetof(sm_station, EI_flap), 1, "EI_flap", 1, "N m^2"},
    {SM_ST_EI_EDGE, offsetof(sm_station, EI_edge), 1, "EI_edge", 1, "N m^2"},
    {SM_ST_GJ, offsetof(sm_station, GJ), 1, "GJ", 1, "N m^2"},
    {SM_ST_I_FLAP, offsetof(sm_station, i_flap), 1, "flap_inertia", 0, "kg m"},
    {SM_ST_I_EDGE, offsetof(sm_station, i_edge), 1, "edge_inertia", 0, "kg m"},
    {SM_ST_IP_OVER_A, offsetof(sm_station, ip_over_a), 1, "ip_over_a", 0, "m^2"},
    {SM_ST_TWIST, offsetof(sm_station, twist), 1, "twist_deg", -1, "deg"},
    {SM_ST_INERTIA_TWIST, offsetof(sm_station, inertia_twist), 1, "inertia_twist_deg", -1, "deg"},
    {SM_ST_CG, offsetof(sm_station, cg), 2, "cg_offset", -1, "m"},
    {SM_ST_SC, offsetof(sm_station, sc), 2, "shear_center_offset", -1, "m"},
    {SM_ST_TC, offsetof(sm_station, tc), 2, "tension_center_offset", -1, "m"},
};
#define MESH3_NSTQ ((int)(sizeof mesh3_stqs / sizeof mesh3_stqs[0]))

static double mesh3_stv(const sm_station *t, size_t off, int c)
{
    return ((const double *)(const void *)((const char *)t + off))[c];
}

/* The stations of member i: at least two, s from exactly 0 to exactly 1 strictly increasing,
 * every quantity of the mask valid at every station. */
static int mesh3_stations(const sm_member *b, int i, sm_diag *d)
{
    char msg[200];
    if (b->n_stations == 0)
        return b->station_mask ? smi_input_fail(d, SM_ITEM_MEMBER, i, "stations",
                                                "station_mask without stations")
                               : SM_OK;
    if (b->n_stations < 2 || !b->stations)
        return smi_input_fail(d, SM_ITEM_MEMBER, i, "stations",
                              "stations need at least two entries, at s = 0 and s = 1");
    if (b->station_mask >= (SM_ST_TC << 1))
        return smi_input_fail(d, SM_ITEM_MEMBER, i, "stations", "unknown bits in station_mask");
    for (int j = 0; j < b->n_stations; j++) {
        const sm_station *t = &b->stations[j];
        double prev = j ? b->stations[j - 1].s : -1.0;
        if (!isfinite(t->s) || t->s < 0.0 || t->s > 1.0) {
            snprintf(msg, sizeof msg, "station %d: s = %g is outside 0..1 (span fraction)", j, t->s);
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "stations", msg);
        }
        if ((j == 0 && t->s != 0.0) || (j == b->n_stations - 1 && t->s != 1.0)) {
            snprintf(msg, sizeof msg, "station %d: the first station must be at s = 0 and the last at s = 1", j);
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "stations", msg);
        }
        if (!(t->s > prev)) {
            snprintf(msg, sizeof msg, "station %d: s = %g does not increase (previous %g)", j, t->s, prev);
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "stations", msg);
        }
        for (int q = 0; q < MESH3_NSTQ; q++) {
            const mesh3_stq *f = &mesh3_stqs[q];
            if (!(b->station_mask & f->bit))
                continue;
            for (int c = 0; c < f->count; c++) {
                double v = mesh3_stv(t, f->off, c);
                int ok = f->kind > 0 ? mesh3_positive(v) : f->kind == 0 ? mesh3_nonneg(v) : isfinite(v);
                if (!ok) {
                    snprintf(msg, sizeof msg, "station %d: %s must be a %s number (%s)", j, f->name,
                             f->kind > 0 ? "positive" : f->kind == 0 ? "non-negative" : "finite", f->unit);
                    return smi_input_fail(d, SM_ITEM_MEMBER, i, "stations", msg);
                }
            }
        }
    }
    return SM_OK;
}

/* Mean over [a, b] (span fractions) of the linear interpolant of the stations' value at off
 * (component c); a == b gives the interpolated value. */
static double mesh3_mean(const sm_member *m, size_t off, int c, double a, double b)
{
    const sm_station *t = m->stations;
    int n = m->n_stations;
    if (b <= a) {
        for (int j = 0; j + 1 < n; j++)
            if (a <= t[j + 1].s || j + 2 == n) {
                double v0 = mesh3_stv(&t[j], off, c), v1 = mesh3_stv(&t[j + 1], off, c);
                return v0 + (v1 - v0) * (a - t[j].s) / (t[j + 1].s - t[j].s);
            }
        return mesh3_stv(&t[0], off, c);
    }
    double sum = 0.0;
    for (int j = 0; j + 1 < n; j++) {
        double lo = fmax(a, t[j].s), hi = fmin(b, t[j + 1].s);
        if (hi <= lo)
            continue;
        double v0 = mesh3_stv(&t[j], off, c), v1 = mesh3_stv(&t[j + 1], off, c), h = t[j + 1].s - t[j].s;
        double vl = v0 + (v1 - v0) * (lo - t[j].s) / h, vh = v0 + (v1 - v0) * (hi - t[j].s) / h;
        sum += 0.5 * (hi - lo) * (vl + vh);
    }
    return sum / (b - a);
}

int mesh3_check(const sm_structure *st, const sm_options *o, sm_diag *d)
{
    for (int j = 0; st->joint_z && j < st->n_joints; j++)
        if (!isfinite(st->joint_z[j]))
            return smi_input_fail(d, SM_ITEM_JOINT, j, "z",
                                  "joint coordinates must be finite numbers");
    for (int s = 0; s < st->n_sections; s++) {
        int rc = mesh3_section(&st->sections[s], s, d);
        if (rc < 0)
            return rc;
    }
    for (int i = 0; i < st->n_members; i++) {
        const sm_member *b = &st->members[i];
        if (!isfinite(b->twist))
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "twist_deg",
                                  "twist_deg must be a finite number (deg)");
        if (!isfinite(b->e3[0]) || !isfinite(b->e3[1]) || !isfinite(b->e3[2]))
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "flap_direction",
                                  "flap_direction must be three finite numbers");
        int rc = mesh3_stations(b, i, d);
        if (rc < 0)
            return rc;
    }
    for (int i = 0; i < st->n_point_masses; i++) {
        const sm_point_mass *pm = &st->point_masses[i];
        for (int c = 0; c < 3; c++)
            if (!mesh3_nonneg(pm->inertia[c]))
                return smi_input_fail(d, SM_ITEM_POINT_MASS, i, "inertia",
                                      "inertia must be three non-negative numbers (kg m^2)");
        for (int c = 0; c < 3; c++)
            if (!isfinite(pm->products[c]))
                return smi_input_fail(d, SM_ITEM_POINT_MASS, i, "products",
                                      "products must be three finite numbers (kg m^2)");
        for (int c = 0; c < 3; c++)
            if (!isfinite(pm->offset[c]))
                return smi_input_fail(d, SM_ITEM_POINT_MASS, i, "offset",
                                      "offset must be three finite numbers (m)");
        /* positive semi-definite: the diagonal is >= 0; the 2x2 minors and the determinant too
         * (round-off allowed relative to the diagonal) */
        const double *I = pm->inertia, *P = pm->products;
        double tol = 1e-12 * (I[0] + I[1] + I[2]) * (I[0] + I[1] + I[2]);
        double m01 = I[0] * I[1] - P[0] * P[0], m12 = I[1] * I[2] - P[1] * P[1], m20 = I[2] * I[0] - P[2] * P[2];
        double det = I[0] * m12 - P[0] * (P[0] * I[2] - P[1] * P[2]) + P[2] * (P[0] * P[1] - I[1] * P[2]);
        if (m01 < -tol || m12 < -tol || m20 < -tol || det < -tol * (I[0] + I[1] + I[2]))
            return smi_input_fail(
                d, SM_ITEM_POINT_MASS, i, "products",
                "inertia and products do not form a physical inertia tensor (it must be "
                "positive semi-definite)");
    }
    if (o->rotary_inertia != SM_ROTARY_FULL && o->rotary_inertia != SM_ROTARY_TORSION)
        return smi_input_fail(d, SM_ITEM_OPTIONS, -1, "rotary_inertia",
                              "unknown rotary_inertia (full or torsion)");
    if (o->basis == SM_BASIS_PAPER)
        return smi_input_fail(
            d, SM_ITEM_OPTIONS, -1, "substructure_modes",
            "the paper basis is planar-only (it exists to reproduce Table 2): use "
            "\"augmented\" for a spatial structure");
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
            return smi_input_fail(
                d, SM_ITEM_MEMBER, i, "flap_direction",
                "the member lies on the spin axis, where the flapwise direction has no "
                "default: give flap_direction [x, y, z], a direction not along the member");
    }
    double fn = mesh3_norm(f), fe = f[0] * e1[0] + f[1] * e1[1] + f[2] * e1[2];
    for (int c = 0; c < 3; c++)
        e3[c] = f[c] - fe * e1[c];
    double n3 = mesh3_norm(e3);
    if (!(n3 > MESH3_PARALLEL * fn))
        return smi_input_fail(d, SM_ITEM_MEMBER, i, "flap_direction",
                              "flap_direction is along the member: give a direction normal to it");
    for (int c = 0; c < 3; c++)
        e3[c] /= n3;
    e2[0] = e3[1] * e1[2] - e3[2] * e1[1]; /* e2 = e3 x e1 */
    e2[1] = e3[2] * e1[0] - e3[0] * e1[2];
    e2[2] = e3[0] * e1[1] - e3[1] * e1[0];
    for (int c = 0; c < 3; c++) {
        ax[c] = e1[c];
        ax[3 + c] = e2[c];
        ax[6 + c] = e3[c];
    }
    return SM_OK;
}

/* tw = base axes (e1, e2, e3) turned by the angle t about e1: (e1, p2, p3). */
static void mesh3_twist(const double base[9], double t, double tw[9])
{
    double ct = cos(t), sn = sin(t);
    for (int c = 0; c < 3; c++) {
        tw[c] = base[c];
        tw[3 + c] = ct * base[3 + c] + sn * base[6 + c];  /* p2 */
        tw[6 + c] = -sn * base[3 + c] + ct * base[6 + c]; /* p3 */
    }
}

/* Span fraction of node k on member b (from its `from` joint). */
static double mesh3_span(const sm_structure *st, const sm_member *b, const sm_node *k)
{
    const double *P = st->joint_xy, *Z = st->joint_z;
    double a[3] = {P[2 * b->from], P[2 * b->from + 1], Z ? Z[b->from] : 0.0};
    double e[3] = {P[2 * b->to] - a[0], P[2 * b->to + 1] - a[1], (Z ? Z[b->to] : 0.0) - a[2]};
    double l2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
    double t = ((k->x - a[0]) * e[0] + (k->y - a[1]) * e[1] + (k->z - a[2]) * e[2]) / l2;
    return fmin(1.0, fmax(0.0, t));
}

/* Value of member b's quantity (station field off, component c, else the fallback) over the
 * span [a, z]: the integral mean of the stations' interpolant, or the uniform value. */
static double mesh3_q(const sm_member *b, unsigned bit, size_t off, int c, double fallback, double a, double z)
{
    return (b->station_mask & bit) ? mesh3_mean(b, off, c, a, z) : fallback;
}

/* node->first += h v (first moment) and node->rot (about the node) += h (|v|^2 1 - v v'). */
static void mesh3_add_offset(double first[3], double rot[9], const double v[3], double h)
{
    double v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    for (int i = 0; i < 3; i++) {
        first[i] += h * v[i];
        for (int j = 0; j < 3; j++)
            rot[i + 3 * j] += h * ((i == j ? v2 : 0.0) - v[i] * v[j]);
    }
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
    double base[9];
    for (int k = 0; k < m->n_nodes; k++) { /* lumped masses again, from the element sections */
        m->nodes[k].member = -1;
        m->nodes[k].mass = 0.0;
    }
    for (int e = 0; e < m->n_elems; e++) {
        sm_elem *el = &m->elems[e];
        const sm_member *b = &st->members[el->member];
        const sm_section *c = &st->sections[b->section];
        if (el->member != done) {
            int rc = mesh3_axes(st, el->member, base, d);
            if (rc < 0)
                return rc;
            done = el->member;
        }
        sm_node *na = &m->nodes[el->n1], *nz = &m->nodes[el->n2];
        double sa = mesh3_span(st, b, na), sz = mesh3_span(st, b, nz);
        double lo = fmin(sa, sz), hi = fmax(sa, sz);
        /* the section of the element: integral means over its span (DESIGN.md 8) */
#define MESH3_Q(bit, field, fb) mesh3_q(b, bit, offsetof(sm_station, field), 0, fb, lo, hi)
        double tw = MESH3_Q(SM_ST_TWIST, twist, b->twist);
        double itw = MESH3_Q(SM_ST_INERTIA_TWIST, inertia_twist, tw);
        el->EA = MESH3_Q(SM_ST_EA, EA, c->EA);
        el->EI = 0.0;
        el->GJ = MESH3_Q(SM_ST_GJ, GJ, c->GJ);
        el->EI_edge = MESH3_Q(SM_ST_EI_EDGE, EI_edge, c->EI_edge);
        el->EI_flap = MESH3_Q(SM_ST_EI_FLAP, EI_flap, c->EI_flap);
        el->mu = MESH3_Q(SM_ST_MU, mu, c->mu);
        el->i_flap = MESH3_Q(SM_ST_I_FLAP, i_flap, c->i_flap);
        el->i_edge = MESH3_Q(SM_ST_I_EDGE, i_edge, c->i_edge);
        if (b->station_mask & SM_ST_IP_OVER_A)
            el->ip_over_a = MESH3_Q(SM_ST_IP_OVER_A, ip_over_a, 0.0);
        else if (b->station_mask & (SM_ST_MU | SM_ST_I_FLAP | SM_ST_I_EDGE))
            el->ip_over_a = (el->i_flap + el->i_edge) / el->mu; /* Wagner ratio from the mass moments */
        else
            el->ip_over_a = c->ip_over_a;
#undef MESH3_Q
        double cg[2], sc[2], tc[2];
        for (int i = 0; i < 2; i++) {
            cg[i] = mesh3_q(b, SM_ST_CG, offsetof(sm_station, cg), i, c->cg[i], lo, hi);
            sc[i] = mesh3_q(b, SM_ST_SC, offsetof(sm_station, sc), i, c->sc[i], lo, hi);
            tc[i] = mesh3_q(b, SM_ST_TC, offsetof(sm_station, tc), i, c->tc[i], lo, hi);
        }
        double ax[9], iax[9];
        mesh3_twist(base, tw, ax);
        mesh3_twist(base, itw, iax);
        /* the element runs from n1 (nearer the clamp) to n2: e1 and p2 turn with it */
        double dir[3] = {nz->x - na->x, nz->y - na->y, nz->z - na->z};
        double sg = dir[0] * ax[0] + dir[1] * ax[1] + dir[2] * ax[2] < 0 ? -1.0 : 1.0;
        for (int k = 0; k < 3; k++) {
            el->ax[k] = sg * ax[k];
            el->ax[3 + k] = sg * ax[3 + k];
            el->ax[6 + k] = ax[6 + k];
            el->cg[k] = cg[0] * ax[3 + k] + cg[1] * ax[6 + k]; /* hub axes */
        }
        el->sc[0] = sg * sc[0], el->sc[1] = sc[1];
        el->tc[0] = sg * tc[0], el->tc[1] = tc[1];
        /* lumped: half the element's mass and rotary inertia (about its centre of mass, in the
         * inertia axes; torsion = i_flap + i_edge) on each node, at the centre of mass; the
         * nodes' bending parts only with SM_ROTARY_FULL (BModes' sections have none, DESIGN.md
         * 8.5); rot_pl keeps the whole tensor (the propeller moment, modes3.c) */
        int bend = m->opt.rotary_inertia == SM_ROTARY_FULL;
        double dg[3] = {el->i_flap + el->i_edge, el->i_flap, el->i_edge};
        double dn[3] = {dg[0], bend ? dg[1] : 0.0, bend ? dg[2] : 0.0};
        double hm = 0.5 * el->mu * el->l;
        memset(el->rot_pl, 0, sizeof el->rot_pl);
        mesh3_add_tensor(el->rot_pl, iax, dg, 1.0);
        sm_node *ends[2] = {na, nz};
        for (int h = 0; h < 2; h++) {
            ends[h]->mass += hm;
            mesh3_add_tensor(ends[h]->rot, iax, dn, 0.5 * el->l);
            if (el->cg[0] != 0.0 || el->cg[1] != 0.0 || el->cg[2] != 0.0)
                mesh3_add_offset(ends[h]->first, ends[h]->rot, el->cg, hm);
        }
        /* the axes a node reports: those of the first member that reaches it, twist at the node */
        double sp[2] = {sa, sz};
        memcpy(el->base_ax, base, sizeof el->base_ax);
        for (int h = 0; h < 2; h++) {
            double t = (b->station_mask & SM_ST_TWIST)
                           ? mesh3_mean(b, offsetof(sm_station, twist), 0, sp[h], sp[h])
                           : b->twist;
            el->end_tw[h] = t;
            el->end_s[h] = sp[h];
            if (ends[h]->member < 0) {
                mesh3_twist(base, t, ends[h]->ax);
                ends[h]->member = el->member;
                ends[h]->span = sp[h];
            }
        }
    }
    for (int i = 0; i < st->n_point_masses; i++) {
        const sm_point_mass *pm = &st->point_masses[i];
        sm_node *nd = &m->nodes[m->joint_node[pm->joint]];
        nd->mass += pm->mass;
        const double *I = pm->inertia, *P = pm->products;
        double T[9] = {I[0], P[0], P[2], P[0], I[1], P[1], P[2], P[1], I[2]};
        for (int k = 0; k < 9; k++) {
            nd->rot[k] += T[k];
            nd->point_rot[k] += T[k];
        }
        if (pm->offset[0] != 0.0 || pm->offset[1] != 0.0 || pm->offset[2] != 0.0) {
            mesh3_add_offset(nd->first, nd->rot, pm->offset, pm->mass);
            mesh3_add_offset(nd->point_first, nd->point_rot, pm->offset, pm->mass);
        }
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
