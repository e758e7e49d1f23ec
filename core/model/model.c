/*
 * model.c — the sm_model lifecycle: defaults, construction (mesh.c then
 * modes.c), queries and destruction, and sm_structure_check, which runs the
 * same mesh phase (model_mesh) without the component-mode bases and predicts
 * the sizes with modes_count.
 */
#include "kind.h"

#include <stdlib.h>
#include <string.h>

void sm_default_options(sm_options *o)
{
    memset(o, 0, sizeof *o);
    o->frames = SM_FRAMES_PER_ELEMENT;
    o->frames_param = 1;
    o->mass = SM_MASS_LUMPED;
    o->basis = SM_BASIS_AUGMENTED;
    o->modes_per_frame = 0;
    o->modes = 3;
    o->geometric_stiffening = 1;
    o->coriolis = 1;
    o->mode_shapes = 1;
    o->min_increments = 5;
    o->max_iterations = 40;
    o->tolerance = 1e-10;
}

void sm_model_free(sm_model *m)
{
    if (!m)
        return;
    for (int s = 0; m->subs && s < m->n_subs; s++) {
        sm_sub *b = &m->subs[s];
        free(b->free_nodes);
        free(b->ubar);
        free(b->elems);
        free(b->attach);
        dm_free(&b->N);
        dm_free(&b->K);
        dm_free(&b->T);
        free(b->d);
        free(b->gq);
        free(b->qpN);
    }
    free(m->subs);
    free(m->nodes);
    free(m->elems);
    free(m->joint_node);
    free(m->mp);
    free(m->pt);
    supports_free(m);
    free(m);
}

/*
 * The phase sm_model_new and sm_structure_check share: reset diag, allocate
 * a model with the options it will use (opt or the defaults, solver
 * settings made valid) and run mesh_build (numbers, indices, topology, nodes,
 * elements, substructures).  *out receives the model, or NULL on failure.
 * Returns SM_OK, SM_INVALID_INPUT or SM_NOMEM, with d filled.
 */
static int model_mesh(sm_model **out, const sm_structure *st, const sm_options *opt, sm_diag *d)
{
    memset(d, 0, sizeof *d);
    d->item_index = -1;
    *out = NULL;
    sm_model *m = calloc(1, sizeof *m);
    if (!m) {
        d->status = SM_NOMEM;
        return SM_NOMEM;
    }
    if (opt)
        m->opt = *opt;
    else
        sm_default_options(&m->opt);
    if (m->opt.min_increments < 1)
        m->opt.min_increments = 1;
    if (m->opt.max_iterations < 1)
        m->opt.max_iterations = 40;
    if (!(m->opt.tolerance > 0))
        m->opt.tolerance = 1e-10;
    int rc = mesh_build(m, st, d);
    if (rc == SM_OK) {
        m->base = 0;
        for (int i = 0; st->base_free && i < 6; i++)
            if (!(st->base_held & (1u << i)))
                m->base_dir[m->base++] = i;
        m->gravity = st->gravity[0] != 0 || st->gravity[1] != 0 || st->gravity[2] != 0;
        memcpy(m->grav, st->gravity, sizeof m->grav);
        rc = supports_lump(m, st);
    }
    if (rc < 0) {
        sm_model_free(m);
        return rc;
    }
    *out = m;
    return SM_OK;
}

/* Sizes that do not need the bases: nodes, elements, frames, max_frame_nodes. */
static void model_mesh_info(const sm_model *m, sm_model_info *info)
{
    memset(info, 0, sizeof *info);
    info->nodes = m->n_nodes;
    info->elements = m->n_elems;
    info->frames = m->n_subs;
    info->spatial = m->kind->spatial;
    info->node_dof = m->kind->node_dof;
    for (int s = 0; s < m->n_subs; s++)
        if (m->subs[s].nfree > info->max_frame_nodes)
            info->max_frame_nodes = m->subs[s].nfree;
}

/* Status of a failed construction into d (a message for SM_NOMEM). */
static int model_fail(sm_diag *d, int rc)
{
    if (rc == SM_NOMEM && !d->message[0])
        strcpy(d->message, "out of memory while building the model");
    d->status = rc;
    return rc;
}

int sm_model_new(sm_model **out, const sm_structure *st, const sm_options *opt, sm_diag *diag)
{
    return sm_model_build(out, st, opt, NULL, NULL, diag);
}

int sm_model_build(sm_model **out, const sm_structure *st, const sm_options *opt,
                   sm_progress_fn cb, void *user, sm_diag *diag)
{
    sm_diag scratch;
    sm_diag *d = diag ? diag : &scratch;
    sm_model *m = NULL;
    int rc = model_mesh(&m, st, opt, d);
    *out = NULL;
    if (rc < 0)
        return model_fail(d, rc);
    if ((rc = modes_build(m, cb, user, d)) < 0 || (rc = supports_build(m)) < 0) {
        sm_model_free(m);
        return model_fail(d, rc);
    }
    *out = m;
    return SM_OK;
}

int sm_structure_check(const sm_structure *st, const sm_options *opt, sm_model_info *info, sm_diag *diag)
{
    sm_diag scratch;
    sm_diag *d = diag ? diag : &scratch;
    sm_model *m = NULL;
    int rc = model_mesh(&m, st, opt, d);
    if (rc < 0)
        return model_fail(d, rc);
    if (info) {
        model_mesh_info(m, info);
        info->coordinates = m->base;
        for (int s = 0; s < m->n_subs; s++) {
            int nm, na, k = m->kind->count(&m->opt, &m->subs[s], &nm, &na);
            info->coordinates += k;
            if (k > info->max_frame_coordinates)
                info->max_frame_coordinates = k;
        }
        info->structured = !m->has_supports && !m->gravity &&
                           tree_choose(m->opt.solver, info->coordinates,
                                       info->max_frame_coordinates, m->opt.modes);
    }
    sm_model_free(m);
    return SM_OK;
}

void sm_model_get_info(const sm_model *m, sm_model_info *info)
{
    model_mesh_info(m, info);
    info->coordinates = m->n;
    for (int s = 0; s < m->n_subs; s++)
        if (m->subs[s].m > info->max_frame_coordinates)
            info->max_frame_coordinates = m->subs[s].m;
    info->structured = tree_use(m);
}

int sm_model_joint_node(const sm_model *m, int joint)
{
    return joint >= 0 && joint < m->n_joints ? m->joint_node[joint] : -1;
}

int sm_model_element_member(const sm_model *m, int element)
{
    return element >= 0 && element < m->n_elems ? m->elems[element].member : -1;
}

int sm_model_node_position3(const sm_model *m, int node, double xyz[3])
{
    if (node < 0 || node >= m->n_nodes)
        return SM_INVALID_INPUT;
    xyz[0] = m->nodes[node].x;
    xyz[1] = m->nodes[node].y;
    xyz[2] = m->nodes[node].z;
    return SM_OK;
}

int sm_model_node_position(const sm_model *m, int node, double xy[2])
{
    if (node < 0 || node >= m->n_nodes)
        return SM_INVALID_INPUT;
    xy[0] = m->nodes[node].x;
    xy[1] = m->nodes[node].y;
    return SM_OK;
}

int sm_model_member_nodes(const sm_model *m, int member, int cap, int *nodes, double *s,
                          double *twist)
{
    int ne = 0, n = 0;

    if (!m->kind->axes || member < 0)
        return SM_INVALID_INPUT;
    for (int e = 0; e < m->n_elems; e++)
        ne += m->elems[e].member == member;
    if (ne == 0)
        return SM_INVALID_INPUT;
    if (cap < ne + 1)
        return ne + 1;
    for (int e = 0; e < m->n_elems; e++) {
        const sm_elem *el = &m->elems[e];
        if (el->member != member)
            continue;
        for (int h = 0; h < 2; h++) {
            int node = h ? el->n2 : el->n1, k, seen = 0;
            double sh = el->end_s[h];
            for (k = 0; k < n; k++)
                seen |= nodes[k] == node;
            if (seen || n > ne)
                continue;
            for (k = n; k > 0 && s[k - 1] > sh; k--) { /* insertion by span fraction */
                nodes[k] = nodes[k - 1];
                s[k] = s[k - 1];
                twist[k] = twist[k - 1];
            }
            nodes[k] = node;
            s[k] = sh;
            twist[k] = el->end_tw[h];
            n++;
        }
    }
    return n;
}

int sm_model_member_axes(const sm_model *m, int member, double axes[9])
{
    if (!m->kind->axes || member < 0)
        return SM_INVALID_INPUT;
    for (int e = 0; e < m->n_elems; e++)
        if (m->elems[e].member == member) {
            memcpy(axes, m->elems[e].base_ax, 9 * sizeof(double));
            return SM_OK;
        }
    return SM_INVALID_INPUT;
}

int sm_model_node_axes(const sm_model *m, int node, double axes[9], int *member, double *s)
{
    if (!m->kind->axes || node < 0 || node >= m->n_nodes || m->nodes[node].member < 0)
        return SM_INVALID_INPUT;
    const sm_node *nd = &m->nodes[node];
    memcpy(axes, nd->ax, sizeof nd->ax);
    if (member)
        *member = nd->member;
    if (s)
        *s = nd->span;
    return SM_OK;
}
