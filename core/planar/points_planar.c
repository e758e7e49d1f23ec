/*
 * points_planar.c — the planar kind's mass points (DESIGN.md 1.2): the lumped FE nodes, or four
 * Gauss points per element with their shape-function rows for consistent mass, plus the point
 * masses.  The kinematics (frames.c) move them and the mass matrices sum over them.
 *
 * How it fits: the planar kind's `points` entry (kind_planar.c), called by model/modes.c after
 * every frame's basis (modes_planar.c).
 */
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Mass points: lumped nodes, or 4 Gauss points per element + point masses. */
int modes_planar_points(sm_model *m)
{
    static const double gx[4] = {-0.86113631159405258, -0.33998104358485626, 0.33998104358485626,
                                 0.86113631159405258};
    static const double gw[4] = {0.34785484513745386, 0.65214515486254614, 0.65214515486254614,
                                 0.34785484513745386};
    int consistent = m->opt.mass == SM_MASS_CONSISTENT, np = 0;
    for (int k = 0; k < m->n_nodes; k++)
        if (m->nodes[k].sub >= 0 && (consistent ? m->nodes[k].point_mass : m->nodes[k].mass) > 0)
            np++;
    if (consistent)
        np += 4 * m->n_elems;
    m->mp = calloc((size_t)(np ? np : 1), sizeof(sm_mpoint));
    if (!m->mp)
        return SM_NOMEM;
    m->n_mp = 0;
    for (int k = 0; k < m->n_nodes; k++) {
        const sm_node *nd = &m->nodes[k];
        double mass = consistent ? nd->point_mass : nd->mass;
        if (nd->sub < 0 || !(mass > 0))
            continue;
        sm_sub *b = &m->subs[nd->sub];
        sm_mpoint *p = &m->mp[m->n_mp++];
        p->sub = nd->sub;
        p->node = k;
        p->ub[0] = b->ubar[2 * nd->local];
        p->ub[1] = b->ubar[2 * nd->local + 1];
        p->mass = mass;
        p->N = b->N.a + 3 * nd->local;
        p->ldn = b->N.rows;
    }
    if (!consistent)
        return SM_OK;
    for (int s = 0; s < m->n_subs; s++) {
        sm_sub *b = &m->subs[s];
        int mm = b->m;
        b->qpN = dm_vec((size_t)b->nel * 4 * 2 * mm);
        if (!b->qpN)
            return SM_NOMEM;
        for (int j = 0; j < b->nel; j++) {
            const sm_elem *e = &m->elems[b->elems[j]];
            double alpha = e->angle - b->theta0, co = cos(alpha), si = sin(alpha);
            double u1[2] = {0, 0}, u2[2];
            if (e->n1 != b->root) {
                u1[0] = b->ubar[2 * m->nodes[e->n1].local];
                u1[1] = b->ubar[2 * m->nodes[e->n1].local + 1];
            }
            u2[0] = b->ubar[2 * m->nodes[e->n2].local];
            u2[1] = b->ubar[2 * m->nodes[e->n2].local + 1];
            for (int g = 0; g < 4; g++) {
                double xi = 0.5 * (1.0 + gx[g]), S[12];
                double *Nq = b->qpN + (size_t)(4 * j + g) * 2 * mm;
                fe_shape(xi, e->l, S);
                for (int c = 0; c < mm; c++) {
                    double ua = 0, ut = 0; /* element-local axial, transverse */
                    for (int r = 0; r < 6; r++) {
                        ua += S[0 + 2 * r] * DM(&b->T, 6 * j + r, c);
                        ut += S[1 + 2 * r] * DM(&b->T, 6 * j + r, c);
                    }
                    Nq[2 * c] = co * ua - si * ut; /* R(alpha) u_loc */
                    Nq[2 * c + 1] = si * ua + co * ut;
                }
                sm_mpoint *p = &m->mp[m->n_mp++];
                p->sub = s;
                p->node = -1;
                p->ub[0] = u1[0] + xi * (u2[0] - u1[0]);
                p->ub[1] = u1[1] + xi * (u2[1] - u1[1]);
                p->mass = e->mu * e->l * 0.5 * gw[g];
                p->N = Nq;
                p->ldn = 2;
            }
        }
    }
    return SM_OK;
}
