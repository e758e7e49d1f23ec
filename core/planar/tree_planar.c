/*
 * tree_planar.c — the planar kind's part of the tree path (solve/tree.c): the links of its
 * frame chain (eq. 36), the local blocks of the Newton tangent and of K*, M*, C* per frame,
 * the centrifugal force g and the nodal shapes, on the light kinematics of frames.c.
 *
 * How it fits: kind_planar.c's tree entries call these; the block factorisation, solves and
 * products along the tree that both kinds share are solve/tree.c (whose header gives the
 * equations); the spatial kind's counterpart is spatial/tree3.c.
 */
#include "kind.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Link data of every frame with a parent p: lk = (cos th_p, sin th_p, a0, a1),
 * a = A'(th_p) w_e for the attachment node e (T_c of the header). */
static void tree_links(const sm_model *m, const sm_kin *k, tree_ws *t)
{
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        double *lk = t->lk + 4 * s;
        if (b->parent < 0) {
            lk[0] = 1;
            lk[1] = lk[2] = lk[3] = 0;
            continue;
        }
        double th = k->theta[b->parent], c = cos(th), si = sin(th);
        const double *w = k->wn + 2 * b->root;
        lk[0] = c;
        lk[1] = si;
        lk[2] = -si * w[0] - c * w[1];
        lk[3] = c * w[0] - si * w[1];
    }
}

/* Jl = [G, A N] (2 x (3+m), column-major ld 2) of a point at local position w with rows N. */
static void tree_point_jac(double c, double si, const double *w, const double *N, int ldn, int mm,
                           double *Jl)
{
    Jl[0] = 1;
    Jl[1] = 0;
    Jl[2] = 0;
    Jl[3] = 1;
    Jl[4] = -si * w[0] - c * w[1]; /* A' w */
    Jl[5] = c * w[0] - si * w[1];
    for (int j = 0; j < mm; j++) {
        double n0 = N[(size_t)ldn * j], n1 = N[(size_t)ldn * j + 1];
        Jl[6 + 2 * j] = c * n0 - si * n1;
        Jl[7 + 2 * j] = si * n0 + c * n1;
    }
}

void tree_centrifugal(const sm_model *m, const sm_kin *k, tree_ws *t, double *g)
{
    tree_links(m, k, t);
    memset(g, 0, (size_t)m->n * sizeof(double));
    double *Jl = t->work;
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        double c = cos(k->theta[s]), si = sin(k->theta[s]), *vs = t->v + 3 * s;
        int l = 3 + b->m;
        vs[0] = vs[1] = vs[2] = 0;
        for (int i = t->mp_ptr[s]; i < t->mp_ptr[s + 1]; i++) {
            int p = t->mp_idx[i];
            const sm_mpoint *mp = &m->mp[p];
            double f0 = mp->mass * k->rp[2 * p], f1 = mp->mass * k->rp[2 * p + 1];
            tree_point_jac(c, si, k->wp + 2 * p, mp->N, mp->ldn, b->m, Jl);
            /* [v_s; g_s] += Jl' f */
            for (int j = 0; j < l; j++) {
                double t0 = Jl[2 * j] * f0 + Jl[2 * j + 1] * f1;
                if (j < 3)
                    vs[j] += t0;
                else
                    g[b->q0 + j - 3] += t0;
            }
        }
    }
    tree_adjoint(m, t, t->v, g);
}

/* a_s and g_s of frames_hessian for substructure s (subtree forces in k->fext, which this
 * updates for the parent): Hl_s = a_s on theta-theta, g_s on theta-q_s. */
static double tree_hessian_sub(const sm_model *m, const sm_kin *k, const tree_ws *t, int s,
                               double *gs)
{
    const sm_sub *b = &m->subs[s];
    double th = k->theta[s], c = cos(th), si = sin(th), a = 0, Ft[2] = {0, 0}, *F = k->fext;
    memset(gs, 0, (size_t)b->m * sizeof(double));
    for (int i = t->mp_ptr[s]; i <= t->mp_ptr[s + 1] - 1 + b->n_attach; i++) {
        const double *f, *w, *N;
        double fm[2];
        int ldn;
        if (i < t->mp_ptr[s + 1]) { /* a mass point: f = m r */
            int p = t->mp_idx[i];
            const sm_mpoint *mp = &m->mp[p];
            fm[0] = mp->mass * k->rp[2 * p];
            fm[1] = mp->mass * k->rp[2 * p + 1];
            f = fm;
            w = k->wp + 2 * p;
            N = mp->N;
            ldn = mp->ldn;
        } else { /* an attachment node: the total force of the subtrees hanging there */
            int al = b->attach[i - t->mp_ptr[s + 1]], nd = b->free_nodes[al];
            f = F + 2 * nd;
            w = k->wn + 2 * nd;
            N = b->N.a + 3 * al;
            ldn = b->N.rows;
        }
        /* a -= f . (A w);  g_s += N' A'' f (frames_hess_point) */
        a -= f[0] * (c * w[0] - si * w[1]) + f[1] * (si * w[0] + c * w[1]);
        double t0 = -si * f[0] + c * f[1], t1 = -c * f[0] - si * f[1];
        for (int j = 0; j < b->m; j++)
            gs[j] += N[(size_t)ldn * j] * t0 + N[(size_t)ldn * j + 1] * t1;
        Ft[0] += f[0];
        Ft[1] += f[1];
    }
    if (b->parent >= 0) {
        F[2 * b->root] += Ft[0];
        F[2 * b->root + 1] += Ft[1];
    }
    return a;
}

int tree_assemble(const sm_model *m, const double *q, sm_kin *k, double s2, int frozen, int gyro,
                  tree_ws *t)
{
    tree_links(m, k, t);
    memset(k->fext, 0, 2 * (size_t)m->n_nodes * sizeof(double));
    double *Jl = t->work, *gs = t->work + 2 * (3 + t->max_m), *gw = gs + t->max_m;
    int finite = 1;
    for (int s = m->n_subs - 1; s >= 0; s--) { /* leaves first: subtree forces for the Hessian */
        const sm_sub *b = &m->subs[s];
        int l = 3 + b->m;
        double c = cos(k->theta[s]), si = sin(k->theta[s]);
        double *Ml = t->Ml + t->loc_off[s], *Cl = t->Cl + t->loc_off[s],
               *Kl = t->Kl + t->loc_off[s];
        memset(Ml, 0, (size_t)l * l * sizeof(double));
        memset(Cl, 0, (size_t)l * l * sizeof(double));
        for (int i = t->mp_ptr[s]; i < t->mp_ptr[s + 1]; i++) {
            const sm_mpoint *mp = &m->mp[t->mp_idx[i]];
            tree_point_jac(c, si, k->wp + 2 * t->mp_idx[i], mp->N, mp->ldn, b->m, Jl);
            /* Ml += m Jl' Jl;  Cl += m Jl' S Jl, S Jl = [-Jl_y; Jl_x] */
            for (int j = 0; j < l; j++)
                for (int r = 0; r < l; r++) {
                    Ml[(size_t)j * l + r] +=
                        mp->mass * (Jl[2 * r] * Jl[2 * j] + Jl[2 * r + 1] * Jl[2 * j + 1]);
                    if (gyro)
                        Cl[(size_t)j * l + r] +=
                            mp->mass * (-Jl[2 * r] * Jl[2 * j + 1] + Jl[2 * r + 1] * Jl[2 * j]);
                }
        }
        /* Kl = -s2 (Ml + Hl) + [0 0; 0 K_s + Kg_s] */
        double a = tree_hessian_sub(m, k, t, s, gs);
        for (size_t i = 0; i < (size_t)l * l; i++)
            Kl[i] = Ml[i];
        Kl[2 + 2 * l] += a;
        for (int j = 0; j < b->m; j++) {
            Kl[(size_t)(3 + j) * l + 2] += gs[j];
            Kl[2 * (size_t)l + 3 + j] += gs[j];
        }
        for (size_t i = 0; i < (size_t)l * l; i++)
            Kl[i] *= -s2;
        for (int j = 0; j < b->m; j++) /* + K_s (eq. 11) */
            for (int i = 0; i < b->m; i++)
                Kl[(size_t)(3 + j) * l + 3 + i] += DM(&b->K, i, j);
        if (m->opt.geometric_stiffening) /* + d f_g,s / dq_s (eqs. 22-26) */
            lin_geometric_tangent_sub(m, s, q, frozen, Kl + 3 * (size_t)l + 3, l, gw);
        if (frozen) /* K* is symmetric up to round-off: make it exact */
            for (int j = 0; j < l; j++)
                for (int i = 0; i < j; i++)
                    Kl[(size_t)j * l + i] = Kl[(size_t)i * l + j] =
                        0.5 * (Kl[(size_t)j * l + i] + Kl[(size_t)i * l + j]);
        for (size_t i = 0; i < (size_t)l * l; i++)
            if (!isfinite(Kl[i]) || !isfinite(Ml[i]) || !isfinite(Cl[i]))
                finite = 0;
    }
    t->omega = sqrt(s2);
    return finite;
}

void tree_nodal(const sm_model *m, const sm_kin *k, tree_ws *t, const double *x, double *d)
{
    tree_links(m, k, t);
    tree_forward(m, t, x, t->u);
    memset(d, 0, 3 * (size_t)m->n_nodes * sizeof(double));
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        const double *us = t->u + 3 * s, *xs = x + b->q0;
        double c = cos(k->theta[s]), si = sin(k->theta[s]);
        for (int i = 0; i < b->nfree; i++) {
            int nd = b->free_nodes[i];
            const double *w = k->wn + 2 * nd;
            double n0 = 0, n1 = 0, nf = 0;
            for (int j = 0; j < b->m; j++) {
                n0 += DM(&b->N, 3 * i, j) * xs[j];
                n1 += DM(&b->N, 3 * i + 1, j) * xs[j];
                nf += DM(&b->N, 3 * i + 2, j) * xs[j];
            }
            d[3 * nd] = us[0] + (-si * w[0] - c * w[1]) * us[2] + c * n0 - si * n1;
            d[3 * nd + 1] = us[1] + (c * w[0] - si * w[1]) * us[2] + si * n0 + c * n1;
            d[3 * nd + 2] = us[2] + nf;
        }
    }
}
