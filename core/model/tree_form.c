/*
 * tree_form.c — the tree form of a model's linearised equations (solve/tree.c's header gives
 * the equations): which models take it (tree_choose, tree_use), its workspace (tree_alloc,
 * tree_free), and the recursions along the frame tree that map modal increments to frame pose
 * increments and back (tree_forward, tree_adjoint).
 *
 * How it fits: model layer.  The kinds' tree blocks (planar/tree_planar.c, spatial/tree3.c)
 * and the block factorisation of solve/tree.c both use these; the path choice is reported by
 * sm_structure_check (model.c) before any basis exists.
 */
#include "kind.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Automatic choice: tree path from this many coordinates on (below, the dense path is as
 * fast: 192 elements take ~30 ms either way), for frames of at most TREE_MAX_FRAME_M coordinates. */
#define TREE_AUTO_MIN_N 200
#define TREE_MAX_FRAME_M 40

int tree_choose(int solver, int n, int max_m, int modes)
{
    if (solver == SM_SOLVER_DENSE)
        return 0;
    if (solver == SM_SOLVER_TREE)
        return 1;
    return n >= TREE_AUTO_MIN_N && max_m <= TREE_MAX_FRAME_M && 8 * modes <= n &&
           modes <= SM_TREE_MAX_MODES;
}

int tree_use(const sm_model *m)
{
    int mx = 0;
    if (m->has_supports || m->gravity) /* K_sup and M_sup couple every frame they reach
                                          (supports.c); the weight has no tree form yet */
        return 0;
    for (int s = 0; s < m->n_subs; s++)
        mx = m->subs[s].m > mx ? m->subs[s].m : mx;
    return tree_choose(m->opt.solver, m->n, mx, m->opt.modes);
}

void tree_free(tree_ws *t)
{
    free(t->mp_ptr);
    free(t->mp_idx);
    free(t->loc_off);
    free(t->fr_off);
    free(t->v_off);
    free(t->Kl);
    free(t->Ml);
    free(t->Cl);
    free(t->F);
    free(t->Finv);
    free(t->X);
    free(t->ipiv);
    free(t->lk);
    free(t->D);
    free(t->d_off);
    free(t->Cc);
    free(t->c_off);
    free(t->z);
    free(t->u);
    free(t->v);
    free(t->work);
    free(t->warm);
    memset(t, 0, sizeof *t);
}

int tree_alloc(const sm_model *m, tree_ws *t)
{
    int S = m->n_subs, mx = 1, d = m->kind->pose_dof;
    memset(t, 0, sizeof *t);
    t->S = S;
    t->n = m->n;
    t->d = d;
    t->fixed_bits = m->kind->fixed_bits;
    t->mp_ptr = calloc((size_t)S + 1, sizeof(int));
    t->mp_idx = calloc((size_t)(m->n_mp ? m->n_mp : 1), sizeof(int));
    t->loc_off = calloc((size_t)S + 1, sizeof(size_t));
    t->fr_off = calloc((size_t)S + 1, sizeof(size_t));
    t->v_off = calloc((size_t)S + 1, sizeof(size_t));
    t->d_off = calloc((size_t)S + 1, sizeof(size_t));
    t->c_off = calloc((size_t)S + 1, sizeof(size_t));
    if (!t->mp_ptr || !t->mp_idx || !t->loc_off || !t->fr_off || !t->v_off || !t->d_off ||
        !t->c_off)
        goto fail;
    for (int s = 0; s < S; s++) {
        size_t l = (size_t)d + m->subs[s].m, nb = 2 * (size_t)d + m->subs[s].m;
        int p = m->subs[s].parent;
        mx = m->subs[s].m > mx ? m->subs[s].m : mx;
        t->loc_off[s + 1] = t->loc_off[s] + l * l;
        t->fr_off[s + 1] = t->fr_off[s] + nb * nb;
        t->v_off[s + 1] = t->v_off[s] + nb;
        t->d_off[s + 1] = t->d_off[s] + (d == 6 && p >= 0 ? 6 * (size_t)m->subs[p].m : 0);
        t->c_off[s + 1] = t->c_off[s] + (p >= 0 ? (size_t)d * ((size_t)m->subs[p].m + d) : 0);
    }
    /* mass points of each substructure (CSR, in the order of m->mp) */
    for (int p = 0; p < m->n_mp; p++)
        t->mp_ptr[m->mp[p].sub + 1]++;
    for (int s = 0; s < S; s++)
        t->mp_ptr[s + 1] += t->mp_ptr[s];
    int *fill = calloc((size_t)S + 1, sizeof(int));
    if (!fill)
        goto fail;
    for (int p = 0; p < m->n_mp; p++) {
        int s = m->mp[p].sub;
        t->mp_idx[t->mp_ptr[s] + fill[s]++] = p;
    }
    free(fill);
    t->max_m = mx;
    size_t L = t->loc_off[S], Fz = t->fr_off[S], V = t->v_off[S];
    t->Kl = dm_vec(L);
    t->Ml = dm_vec(L);
    t->Cl = dm_vec(L);
    t->F = dm_vec(Fz);
    t->X = dm_vec((size_t)d * V);
    t->ipiv = calloc(V ? V : 1, sizeof(int));
    t->lk = dm_vec(4 * (size_t)S);
    t->D = dm_vec(t->d_off[S] + 1);
    t->Cc = dm_vec(t->c_off[S] + 1);
    t->z = dm_vec(V);
    t->u = dm_vec((size_t)d * S);
    t->v = dm_vec((size_t)d * S);
    t->work = dm_vec(4 * (size_t)mx + 2 * (size_t)(mx + 2 * d) * (mx + 2 * d) + 64);
    if (!t->Kl || !t->Ml || !t->Cl || !t->F || !t->X || !t->ipiv || !t->lk || !t->D || !t->Cc ||
        !t->z || !t->u || !t->v || !t->work)
        goto fail;
    return SM_OK;
fail:
    tree_free(t);
    return SM_NOMEM;
}

/* us (6) += D xp, D 6 x mp; and yp (mp) += D' vs.  Inlined with mp = 6 a constant where the
 * parent is a one-element frame, so that the loops unroll: the same sums in the same order
 * (issue 27: tree_forward and tree_adjoint were 8 % of a spatial sweep). */
static inline void tree_dx6(int mp, const double *restrict D, const double *restrict xp,
                            double *restrict us)
{
    for (int j = 0; j < mp; j++)
        for (int i = 0; i < 6; i++)
            us[i] += D[6 * j + i] * xp[j];
}

static inline void tree_dtv6(int mp, const double *restrict D, const double *restrict vs,
                             double *restrict yp)
{
    for (int j = 0; j < mp; j++) {
        double acc = 0;
        for (int i = 0; i < 6; i++)
            acc += D[6 * j + i] * vs[i];
        yp[j] += acc;
    }
}

/* Spatial forward step: u_s = T_s u_p + D_s x_p, T_s u = (dR + dtheta x a, dtheta). */
static void tree_forward6(const sm_model *m, const tree_ws *t, int s, const double *x, double *u)
{
    const sm_sub *b = &m->subs[s], *p = &m->subs[b->parent];
    const double *up = u + 6 * b->parent, *a = t->lk + 3 * s, *D = t->D + t->d_off[s],
                 *xp = x + p->q0;
    double *us = u + 6 * s;
    us[0] = up[0] + up[4] * a[2] - up[5] * a[1];
    us[1] = up[1] + up[5] * a[0] - up[3] * a[2];
    us[2] = up[2] + up[3] * a[1] - up[4] * a[0];
    us[3] = up[3];
    us[4] = up[4];
    us[5] = up[5];
    if (p->m == 6)
        tree_dx6(6, D, xp, us);
    else
        tree_dx6(p->m, D, xp, us);
}

/* Spatial adjoint step: v_p += T_s' v_s = (v_R, v_theta + a x v_R); y_p += D_s' v_s. */
static void tree_adjoint6(const sm_model *m, const tree_ws *t, int s, double *v, double *y)
{
    const sm_sub *b = &m->subs[s], *p = &m->subs[b->parent];
    const double *vs = v + 6 * s, *a = t->lk + 3 * s, *D = t->D + t->d_off[s];
    double *vp = v + 6 * b->parent, *yp = y + p->q0;
    vp[0] += vs[0];
    vp[1] += vs[1];
    vp[2] += vs[2];
    vp[3] += vs[3] + a[1] * vs[2] - a[2] * vs[1];
    vp[4] += vs[4] + a[2] * vs[0] - a[0] * vs[2];
    vp[5] += vs[5] + a[0] * vs[1] - a[1] * vs[0];
    if (p->m == 6)
        tree_dtv6(6, D, vs, yp);
    else
        tree_dtv6(p->m, D, vs, yp);
}

/* u (d S) = dy/dq x: the forward recursion dy_c = T_c dy_p + D_c x_p, dy = 0 at the hub. */
void tree_forward(const sm_model *m, const tree_ws *t, const double *x, double *u)
{
    if (t->d == 6) {
        for (int s = 0; s < m->n_subs; s++) {
            if (m->subs[s].parent < 0)
                memset(u + 6 * s, 0, 6 * sizeof(double));
            else
                tree_forward6(m, t, s, x, u);
        }
        return;
    }
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        double *us = u + 3 * s;
        if (b->parent < 0) {
            us[0] = us[1] = us[2] = 0;
            continue;
        }
        const sm_sub *p = &m->subs[b->parent];
        const double *up = u + 3 * b->parent, *lk = t->lk + 4 * s, *xp = x + p->q0;
        int a = b->attach_local;
        double n0 = 0, n1 = 0, nf = 0;
        for (int j = 0; j < p->m; j++) { /* (N_e; Nphi_e) x_p */
            n0 += DM(&p->N, 3 * a, j) * xp[j];
            n1 += DM(&p->N, 3 * a + 1, j) * xp[j];
            nf += DM(&p->N, 3 * a + 2, j) * xp[j];
        }
        us[0] = up[0] + lk[2] * up[2] + lk[0] * n0 - lk[1] * n1;
        us[1] = up[1] + lk[3] * up[2] + lk[1] * n0 + lk[0] * n1;
        us[2] = up[2] + nf;
    }
}

/* y += (dy/dq)' v for v (d S, destroyed): the adjoint recursion, leaves first. */
void tree_adjoint(const sm_model *m, const tree_ws *t, double *v, double *y)
{
    for (int s = m->n_subs - 1; s >= 0; s--) {
        const sm_sub *b = &m->subs[s];
        if (b->parent < 0)
            continue;
        if (t->d == 6) {
            tree_adjoint6(m, t, s, v, y);
            continue;
        }
        const sm_sub *p = &m->subs[b->parent];
        double *vs = v + 3 * s, *vp = v + 3 * b->parent, *yp = y + p->q0;
        const double *lk = t->lk + 4 * s;
        int a = b->attach_local;
        /* v_p += T' v_s;  y_p += D' v_s = N_e' A' (v0, v1) + Nphi_e' v2 */
        vp[0] += vs[0];
        vp[1] += vs[1];
        vp[2] += lk[2] * vs[0] + lk[3] * vs[1] + vs[2];
        double f0 = lk[0] * vs[0] + lk[1] * vs[1], f1 = -lk[1] * vs[0] + lk[0] * vs[1];
        for (int j = 0; j < p->m; j++)
            yp[j] += DM(&p->N, 3 * a, j) * f0 + DM(&p->N, 3 * a + 1, j) * f1 +
                     DM(&p->N, 3 * a + 2, j) * vs[2];
    }
}
