/*
 * mesh.c — from the user's structure (joints, members, sections) to the FE
 * mesh and the substructures (DESIGN.md 1.1-1.2).
 *
 * The members must form a tree rooted at the clamp joint.  A breadth-first
 * walk from the clamp orients every member away from it; nodes and elements
 * are numbered in that order, so every non-clamp node is the far node (n2) of
 * exactly one element.  The frame scheme then cuts the elements into runs
 * (substructures); a substructure's root is the near node of its first
 * element and its parent is the substructure holding that node.
 */
#include "kind.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MESH_MAX_ITEMS 1000000
/* z of joint j (0 for a planar structure or without joint_z). */
/* a joint's z (0 without joint_z; a planar structure's are zero: its kind's check refused others) */
#define MESH_Z(st, j) ((st)->joint_z ? (st)->joint_z[j] : 0.0)

/* The one place that picks the structure kind (kind.h): spatial sections make a spatial model. */
const smi_kind *smi_kind_of(const sm_structure *st)
{
    return st->spatial ? &smi_kind_spatial : &smi_kind_planar;
}

/*
 * The smallest member or element length the numerics carry (issue 23 item 7: a 1e-15 m member
 * at 0.5 m from the hub solved at 2.9e18 rad/s; a 1e-300 m one was told its flap_direction was
 * along the member).  A joint coordinate of magnitude S is held to eps S (eps = 2.2e-16), so a
 * length l taken as the difference of two joints is known to eps S / l, its direction alike,
 * and the element stiffness EI/l^3 to 3 eps S / l.  With l >= MESH_MIN_RELATIVE S that is
 * 2.2e-10 for length and direction (7e-10 for EI/l^3): far inside the 1e-6 with which the axes
 * are checked (MESH3_PARALLEL) and the results are reported, so round-off of the geometry never
 * decides an answer.  (Conditioning between long and short elements is stricter: the codec
 * refuses element lengths below 1e-4 of the longest.)  S is the structure's size: its largest
 * joint coordinate (hub frame, m), which bounds every joint's distance from the hub centre and
 * from the clamp to within a factor 2 sqrt 3 and cannot overflow.  The absolute floor
 * MESH_MIN_ABSOLUTE is where the steps the solver takes in metres stop being small: the complex
 * step of the spatial Hessian (1e-20 m, frames3.c) is exact to (h/l)^2, below round-off only for
 * l >> 1e-12 m; 1e-9 m keeps that at 1e-22 (and lengths squared, cubed and to the fourth far
 * from underflow), and no beam is shorter than a nanometre.
 */
#define MESH_MIN_RELATIVE 1e-6 /* of the largest joint coordinate */
#define MESH_MIN_ABSOLUTE 1e-9 /* m */

/* The structure's size: its largest joint coordinate (m); coordinates are finite. */
static double mesh_size(const sm_structure *st)
{
    double s = 0.0;
    for (int j = 0; j < st->n_joints; j++) {
        s = fmax(s, fmax(fabs(st->joint_xy[2 * j]), fabs(st->joint_xy[2 * j + 1])));
        s = fmax(s, fabs(MESH_Z(st, j)));
    }
    return s;
}

/*
 * Member i of length l (m) against the smallest length the numerics carry (size: mesh_size):
 * the member (field "", as for a zero-length member: no one joint is at fault, and the
 * codec's blade form has no "from"/"to" to point at) and then its elements ("elements"; then
 * l >= lmin > l / elements, so l / lmin < elements fits an int).
 */
static int mesh_length(sm_diag *d, int i, double l, int elements, double size)
{
    double rel = MESH_MIN_RELATIVE * size, lmin = fmax(rel, MESH_MIN_ABSOLUTE), le = l / elements;
    char why[96];
    if (l >= lmin && le >= lmin)
        return SM_OK;
    if (rel >= MESH_MIN_ABSOLUTE)
        snprintf(why, sizeof why, "%g of the structure's size %.3g m, its largest joint coordinate",
                 MESH_MIN_RELATIVE, size);
    else
        snprintf(why, sizeof why, "%g m", MESH_MIN_ABSOLUTE);
    int rc = smi_input_fail(d, SM_ITEM_MEMBER, i, l < lmin ? "" : "elements", "");
    if (d && l < lmin)
        snprintf(d->message, sizeof d->message,
                 "the member is %.3g m long: shorter than the smallest length the numerics carry "
                 "(%s): move its joints apart or merge it into its neighbour", l, why);
    else if (d)
        snprintf(d->message, sizeof d->message,
                 "%d elements of %.3g m: shorter than the smallest length the numerics carry (%s): "
                 "use at most %d elements", elements, le, why, (int)(l / lmin));
    return rc;
}

/* Check numbers, indices and options; topology is checked by mesh_walk. */
static int mesh_check(const sm_structure *st, const sm_options *o, sm_diag *d)
{
    if (!st)
        return smi_input_fail(d, SM_ITEM_NONE, -1, "", "no structure");
    if (st->n_joints < 1 || st->n_joints > MESH_MAX_ITEMS || !st->joint_xy)
        return smi_input_fail(d, SM_ITEM_NONE, -1, "", "the structure has no joints");
    if (st->n_members < 1 || st->n_members > MESH_MAX_ITEMS || !st->members)
        return smi_input_fail(d, SM_ITEM_NONE, -1, "", "the structure has no members");
    if (st->n_sections < 1 || !st->sections)
        return smi_input_fail(d, SM_ITEM_NONE, -1, "", "the structure has no sections");
    if (st->clamp < 0 || st->clamp >= st->n_joints)
        return smi_input_fail(d, SM_ITEM_CLAMP, -1, "",
                              "the clamp is not a joint of the structure");
    for (int j = 0; j < st->n_joints; j++)
        if (!isfinite(st->joint_xy[2 * j]) || !isfinite(st->joint_xy[2 * j + 1]))
            return smi_input_fail(d, SM_ITEM_JOINT, j, "",
                                  "joint coordinates must be finite numbers");
    int rc = smi_kind_of(st)->check(st, o, d);
    if (rc < 0)
        return rc;
    long total = 0;
    double size = mesh_size(st);
    for (int i = 0; i < st->n_members; i++) {
        const sm_member *b = &st->members[i];
        if (b->from < 0 || b->from >= st->n_joints)
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "from", "unknown joint");
        if (b->to < 0 || b->to >= st->n_joints)
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "to", "unknown joint");
        if (b->section < 0 || b->section >= st->n_sections)
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "section", "unknown section");
        if (b->elements < 1 || b->elements > MESH_MAX_ITEMS)
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "elements",
                                  "elements must be a positive integer");
        total += b->elements;
        if (total > MESH_MAX_ITEMS)
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "elements", "too many elements");
        double dx = st->joint_xy[2 * b->to] - st->joint_xy[2 * b->from];
        double dy = st->joint_xy[2 * b->to + 1] - st->joint_xy[2 * b->from + 1];
        double dz = MESH_Z(st, b->to) - MESH_Z(st, b->from);
        double l = hypot(hypot(dx, dy), dz);
        if (b->from == b->to || !(l > 0.0))
            return smi_input_fail(d, SM_ITEM_MEMBER, i, "",
                                  "zero-length member: its joints coincide");
        rc = mesh_length(d, i, l, b->elements, size);
        if (rc < 0)
            return rc;
    }
    for (int i = 0; i < st->n_point_masses; i++) {
        const sm_point_mass *p = &st->point_masses[i];
        if (p->joint < 0 || p->joint >= st->n_joints)
            return smi_input_fail(d, SM_ITEM_POINT_MASS, i, "joint", "unknown joint");
        if (!isfinite(p->mass) || p->mass < 0.0)
            return smi_input_fail(d, SM_ITEM_POINT_MASS, i, "mass",
                                  "mass must be a non-negative number (kg)");
    }
    if (o->modes < 1)
        return smi_input_fail(d, SM_ITEM_OPTIONS, -1, "modes", "modes must be a positive integer");
    if ((rc = supports_check(st, o, d)) < 0)
        return rc;
    if ((o->frames == SM_FRAMES_PER_MEMBER || o->frames == SM_FRAMES_ELEMENTS_PER_FRAME) &&
        o->frames_param < 1)
        return smi_input_fail(d, SM_ITEM_OPTIONS, -1, "frames",
                              "the frame count must be a positive integer");
    if (o->frames < SM_FRAMES_SINGLE || o->frames > SM_FRAMES_PER_ELEMENT)
        return smi_input_fail(d, SM_ITEM_OPTIONS, -1, "frames", "unknown frame scheme");
    if (o->modes_per_frame < 0)
        return smi_input_fail(d, SM_ITEM_OPTIONS, -1, "modes_per_frame",
                              "modes_per_frame must be positive or all");
    return SM_OK;
}

/*
 * Breadth-first walk from the clamp: order[] receives the members in visit
 * order, near[] the joint each member is entered from.  Detects cycles,
 * members not connected to the clamp and joints on no member.  The members
 * at each joint are kept in increasing index order (adjacency lists built by
 * a counting sort), so the walk costs O(joints + members) and visits members
 * in the same order as a scan of all members per joint would.
 */
static int mesh_walk(const sm_structure *st, int *order, int *near, sm_diag *d)
{
    int nj = st->n_joints, nm = st->n_members, rc = SM_NOMEM;
    int *seen = calloc((size_t)nj, sizeof(int));
    int *used = calloc((size_t)nm, sizeof(int));
    int *queue = malloc((size_t)nj * sizeof(int));
    int *start = calloc((size_t)nj + 1, sizeof(int)); /* adj[start[j] .. start[j+1]): members at joint j */
    int *adj = malloc(2 * (size_t)nm * sizeof(int));
    if (!seen || !used || !queue || !start || !adj)
        goto done;
    for (int i = 0; i < nm; i++) { /* mesh_check: from != to, both valid joints */
        start[st->members[i].from + 1]++;
        start[st->members[i].to + 1]++;
    }
    for (int j = 0; j < nj; j++)
        start[j + 1] += start[j];
    for (int i = 0; i < nm; i++) {
        adj[start[st->members[i].from]++] = i;
        adj[start[st->members[i].to]++] = i;
    }
    for (int j = nj; j > 0; j--) /* the fill advanced start[j] to start[j+1]: shift back */
        start[j] = start[j - 1];
    start[0] = 0;
    int head = 0, tail = 0, count = 0;
    queue[tail++] = st->clamp;
    seen[st->clamp] = 1;
    while (head < tail) {
        int j = queue[head++];
        for (int p = start[j]; p < start[j + 1]; p++) {
            int i = adj[p];
            const sm_member *b = &st->members[i];
            if (used[i])
                continue;
            int other = b->from == j ? b->to : b->from;
            if (seen[other]) {
                rc = smi_input_fail(
                    d, SM_ITEM_MEMBER, i, "",
                    "this member closes a cycle: members must form a tree rooted at the clamp");
                goto done;
            }
            used[i] = 1;
            seen[other] = 1;
            order[count] = i;
            near[count] = j;
            count++;
            queue[tail++] = other;
        }
    }
    if (count == 0) {
        rc = smi_input_fail(d, SM_ITEM_CLAMP, -1, "", "the clamp joint is not on any member");
        goto done;
    }
    for (int i = 0; i < nm; i++)
        if (!used[i]) {
            rc = smi_input_fail(d, SM_ITEM_MEMBER, i, "",
                                "this member is not connected to the clamp joint");
            goto done;
        }
    for (int j = 0; j < nj; j++)
        if (!seen[j]) {
            rc = smi_input_fail(d, SM_ITEM_JOINT, j, "", "this joint is not on any member");
            goto done;
        }
    rc = SM_OK;
done:
    free(seen);
    free(used);
    free(queue);
    free(start);
    free(adj);
    return rc;
}

/* Nodes and elements along the walk order. */
static int mesh_nodes(sm_model *m, const sm_structure *st, const int *order, const int *near)
{
    int ne = 0;
    for (int i = 0; i < st->n_members; i++)
        ne += st->members[i].elements;
    m->n_elems = ne;
    m->n_nodes = ne + 1; /* a tree */
    m->n_joints = st->n_joints;
    m->nodes = calloc((size_t)m->n_nodes, sizeof(sm_node));
    m->elems = calloc((size_t)ne, sizeof(sm_elem));
    m->joint_node = malloc((size_t)st->n_joints * sizeof(int));
    if (!m->nodes || !m->elems || !m->joint_node)
        return SM_NOMEM;
    for (int j = 0; j < st->n_joints; j++)
        m->joint_node[j] = -1;
    int nn = 0, e = 0;
    sm_node *c = &m->nodes[nn++];
    c->x = st->joint_xy[2 * st->clamp];
    c->y = st->joint_xy[2 * st->clamp + 1];
    c->z = MESH_Z(st, st->clamp);
    c->joint = st->clamp;
    c->sub = c->local = -1;
    m->joint_node[st->clamp] = 0;
    m->clamp_node = 0;
    for (int k = 0; k < st->n_members; k++) {
        const sm_member *b = &st->members[order[k]];
        const sm_section *sec = &st->sections[b->section];
        int a = near[k], z = b->from == a ? b->to : b->from;
        double x0 = st->joint_xy[2 * a], y0 = st->joint_xy[2 * a + 1];
        double dx = st->joint_xy[2 * z] - x0, dy = st->joint_xy[2 * z + 1] - y0;
        double z0 = MESH_Z(st, a), dz = MESH_Z(st, z) - z0;
        double len = m->kind->length(dx, dy, dz), ang = atan2(dy, dx);
        int prev = m->joint_node[a];
        for (int i = 1; i <= b->elements; i++) {
            sm_node *nd = &m->nodes[nn];
            double t = (double)i / b->elements;
            nd->x = x0 + t * dx;
            nd->y = y0 + t * dy;
            nd->z = z0 + t * dz;
            nd->joint = i == b->elements ? z : -1;
            nd->sub = nd->local = -1;
            if (i == b->elements) {
                nd->x = st->joint_xy[2 * z]; /* exact joint position */
                nd->y = st->joint_xy[2 * z + 1];
                nd->z = MESH_Z(st, z);
                m->joint_node[z] = nn;
            }
            sm_elem *el = &m->elems[e++];
            el->n1 = prev;
            el->n2 = nn;
            el->member = order[k];
            el->l = len / b->elements;
            el->angle = ang;
            el->EA = sec->E * sec->A;
            el->EI = sec->E * sec->I;
            el->mu = sec->mu;
            el->sub = -1;
            prev = nn++;
        }
    }
    /* lumped masses: mu*(l_left + l_right)/2 on each node, each node once */
    for (int i = 0; i < ne; i++) {
        double h = 0.5 * m->elems[i].mu * m->elems[i].l;
        m->nodes[m->elems[i].n1].mass += h;
        m->nodes[m->elems[i].n2].mass += h;
    }
    for (int i = 0; i < st->n_point_masses; i++) {
        int k = m->joint_node[st->point_masses[i].joint];
        m->nodes[k].mass += st->point_masses[i].mass;
        m->nodes[k].point_mass += st->point_masses[i].mass;
    }
    return SM_OK;
}

/* 1 when element i (0-based within its member of ne elements) starts a run under the scheme. */
static int mesh_run_start(const sm_options *o, int i, int ne)
{
    switch (o->frames) {
    case SM_FRAMES_SINGLE:
        return 0;
    case SM_FRAMES_PER_ELEMENT:
        return 1;
    case SM_FRAMES_ELEMENTS_PER_FRAME:
        return i % o->frames_param == 0;
    case SM_FRAMES_PER_MEMBER: {
        long long k = o->frames_param < ne ? o->frames_param : ne;
        /* run r covers elements [floor(r*ne/k), floor((r+1)*ne/k)); floor(r*ne/k) grows with r,
         * so i starts a run iff the smallest r with r*ne >= i*k (r = ceil(i*k/ne)) lands on i */
        long long r = ((long long)i * k + ne - 1) / ne;
        return r < k && (r * ne) / k == i;
    }
    }
    return 0;
}

/* Cut the elements into substructures and fill their topology. */
static int mesh_subs(sm_model *m, const sm_structure *st)
{
    int ne = m->n_elems, ns = 0;
    int *start = calloc((size_t)ne, sizeof(int));
    if (!start)
        return SM_NOMEM;
    for (int e = 0, i = 0; e < ne; e++, i++) {
        if (e > 0 && m->elems[e].member != m->elems[e - 1].member)
            i = 0;
        int nel = st->members[m->elems[e].member].elements;
        start[e] = e == 0 || (i == 0 && m->opt.frames != SM_FRAMES_SINGLE) ||
                   mesh_run_start(&m->opt, i, nel);
        ns += start[e];
    }
    m->n_subs = ns;
    m->subs = calloc((size_t)ns, sizeof(sm_sub));
    if (!m->subs) {
        free(start);
        return SM_NOMEM;
    }
    int s = -1;
    for (int e = 0; e < ne; e++) {
        if (start[e])
            s++;
        m->elems[e].sub = s;
        m->subs[s].nel++;
    }
    free(start);
    for (int k = 0; k < ns; k++) {
        sm_sub *b = &m->subs[k];
        b->elems = malloc((size_t)b->nel * sizeof(int));
        b->free_nodes = malloc((size_t)b->nel * sizeof(int));
        b->ubar = malloc((size_t)b->nel * m->kind->ubar_dim * sizeof(double));
        b->attach = malloc((size_t)b->nel * sizeof(int));
        if (!b->elems || !b->free_nodes || !b->ubar || !b->attach)
            return SM_NOMEM;
        b->nel = 0;
    }
    for (int e = 0; e < ne; e++) {
        sm_elem *el = &m->elems[e];
        sm_sub *b = &m->subs[el->sub];
        if (b->nel == 0) {
            b->root = el->n1;
            b->theta0 = el->angle;
        }
        b->elems[b->nel++] = e;
        m->nodes[el->n2].sub = el->sub;
        m->nodes[el->n2].local = b->nfree;
        b->free_nodes[b->nfree++] = el->n2;
    }
    for (int k = 0; k < ns; k++) {
        sm_sub *b = &m->subs[k];
        const sm_node *r = &m->nodes[b->root];
        b->parent = r->sub;
        b->attach_local = r->local;
        if (b->parent >= 0) {
            sm_sub *p = &m->subs[b->parent];
            b->beta = b->theta0 - p->theta0;
            int dup = 0;
            for (int a = 0; a < p->n_attach; a++)
                dup |= p->attach[a] == r->local;
            if (!dup)
                p->attach[p->n_attach++] = r->local;
        } else {
            b->beta = b->theta0;
        }
    }
    return SM_OK;
}

int mesh_build(sm_model *m, const sm_structure *st, sm_diag *d)
{
    int rc = mesh_check(st, &m->opt, d);
    if (rc < 0)
        return rc;
    int *order = malloc((size_t)st->n_members * sizeof(int));
    int *near = malloc((size_t)st->n_members * sizeof(int));
    rc = SM_NOMEM;
    if (!order || !near)
        goto done;
    rc = mesh_walk(st, order, near, d);
    if (rc < 0)
        goto done;
    m->kind = smi_kind_of(st);
    rc = mesh_nodes(m, st, order, near);
    if (rc == SM_OK && m->kind->elements)
        rc = m->kind->elements(m, st, d);
    if (rc < 0)
        goto done;
    rc = mesh_subs(m, st);
    if (rc == SM_OK)
        m->kind->subs(m);
done:
    free(order);
    free(near);
    return rc;
}
