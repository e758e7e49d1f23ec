/*
 * tree3.c — the local blocks of the tree form (tree.c) for a spatial model
 * (DESIGN.md 7.3, "Large models"): the frame pose of s is y_s = (R_s, theta_s),
 * increments dy_s = (dR_s, dtheta_s) in the hub frame, and the chain
 *     dy_c = T_c dy_p + D_c dq_p,  T_c = [I -skew(a_c); 0 I],  a_c = R_c - R_p,
 *     D_c = [A_p N^u_e; A_p T(psi_e) N^psi_e]               (c child of p at node e)
 * is the forward recursion of frames3.c.  Every matrix is Y' L Y with Y_s = [dy_s/dq; E_s]:
 *
 * M*, C*.  A point p of s moves by dr_p = Jl_p (dy_s, dq_s) and turns by Wl_p (dy_s, dq_s),
 *     Jl_p = [I, -skew(a_p), A_s N^u_p + offset],  Wl_p = [0, I, A_s T(psi_p) N^psi_p],
 * so Ml_s = sum_p m_p Jl' Jl + Wl' X_p Wl and Cl_s the skew part of
 * sum_p Jl' (2 m_p S) Jl + Wl' Y_p Wl (lin3_mass, lin3_gyro, point by point).
 *
 * H = dg/dq.  A coordinate j of s moves the frames below s rigidly; the rows of a
 * descendant t then change by Gown_t (the rigid-motion response of frames3.c) times the
 * pose change of t, and by symmetry of H the rows above by its transpose.  So
 *     H = Hd + G U + U' G',  Hd = blockdiag(H_ss),  G = blockdiag(Gown_s),  U = dy/dq,
 * i.e. Hl_s = [0, Gown_s'; Gown_s, H_ss] on (dy_s, dq_s): every entry of H (the dense
 * Jacobian of hessian3.c) comes out, with H_ss from the m_s closed-form columns of the points
 * of s alone (sp_hessian_own).  The Newton tangent or K* is then
 *     Kl_s = -Omega^2 Hl_s + [0 0; 0 K_s + Kg_s]
 * (the spatial g already holds the J' P J part that the planar form adds as -Omega^2 Ml).
 */
#include "spatial.h"

#include <math.h>
#include <string.h>

/* a_s = R_s - R_p and D_s of every frame with a parent, at the kinematics k (sp_eval). */
static void tree3_links(const sm_model *m, const sp_kin *k, tree_ws *t)
{
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        double *a = t->lk + 3 * s;
        if (b->parent < 0) {
            a[0] = a[1] = a[2] = 0;
            continue;
        }
        int p = b->parent, e = b->root;
        const sp_point *pe = &m->pt[e];
        const double *A = k->A + 9 * p, *AT = k->AT + 9 * e;
        double *D = t->D + t->d_off[s];
        for (int i = 0; i < 3; i++)
            a[i] = k->R[3 * s + i] - k->R[3 * p + i];
        for (int j = 0; j < m->subs[p].m; j++) {
            const double *Nc = pe->N + (size_t)pe->ldn * j;
            for (int i = 0; i < 3; i++) {
                D[6 * j + i] = A[i] * Nc[0] + A[i + 3] * Nc[1] + A[i + 6] * Nc[2];
                D[6 * j + 3 + i] = AT[i] * Nc[3] + AT[i + 3] * Nc[4] + AT[i + 6] * Nc[5];
            }
        }
    }
}

/* Jl, Wl (3 x (6 + m_s), column-major ld 3) of point pi of frame s at k (sp_jac_carry, local). */
static void tree3_point_jac(const sm_model *m, const sp_kin *k, int s, int pi, double *Jl, double *Wl)
{
    const sm_sub *b = &m->subs[s];
    const sp_point *p = &m->pt[pi];
    const double *A = k->A + 9 * s, *AT = k->AT + 9 * pi, *dh = k->dh + 3 * pi;
    double a[3];
    int l = 6 + b->m;
    for (int i = 0; i < 3; i++)
        a[i] = k->r[3 * pi + i] - k->R[3 * s + i];
    memset(Jl, 0, 3 * (size_t)l * sizeof(double));
    memset(Wl, 0, 3 * (size_t)l * sizeof(double));
    for (int i = 0; i < 3; i++) {
        Jl[3 * i + i] = 1.0;
        Wl[3 * (3 + i) + i] = 1.0;
    }
    /* -skew(a): dtheta x a */
    Jl[3 * 3 + 1] = -a[2], Jl[3 * 3 + 2] = a[1];
    Jl[3 * 4 + 0] = a[2], Jl[3 * 4 + 2] = -a[0];
    Jl[3 * 5 + 0] = -a[1], Jl[3 * 5 + 1] = a[0];
    for (int j = 0; j < b->m; j++) {
        const double *Nc = p->N + (size_t)p->ldn * j;
        double *J = Jl + 3 * (6 + j), *W = Wl + 3 * (6 + j);
        for (int i = 0; i < 3; i++) {
            J[i] = A[i] * Nc[0] + A[i + 3] * Nc[1] + A[i + 6] * Nc[2];
            W[i] = AT[i] * Nc[3] + AT[i + 3] * Nc[4] + AT[i + 6] * Nc[5];
        }
        if (p->has_c) { /* the offset mass turns with the node: w x dh */
            J[0] += W[1] * dh[2] - W[2] * dh[1];
            J[1] += W[2] * dh[0] - W[0] * dh[2];
            J[2] += W[0] * dh[1] - W[1] * dh[0];
        }
    }
}

/* L (l x l) += X' B X for X (3 x l, ld 3) and B (3 x 3 column-major). */
static void tree3_add_btb(int l, const double *X, const double B[9], double *L)
{
    for (int j = 0; j < l; j++) {
        const double *xj = X + 3 * j;
        double bx[3];
        for (int i = 0; i < 3; i++)
            bx[i] = B[i] * xj[0] + B[i + 3] * xj[1] + B[i + 6] * xj[2];
        for (int i = 0; i < l; i++) {
            const double *xi = X + 3 * i;
            L[(size_t)j * l + i] += xi[0] * bx[0] + xi[1] * bx[1] + xi[2] * bx[2];
        }
    }
}

/* Ml_s and (gyro) Cl_s of frame s; Jl, Wl: 6 (6 + m_s) scratch, Cr: (6 + m_s)^2 scratch. */
static void tree3_mass_sub(const sm_model *m, const sp_kin *k, tree_ws *t, int s, int gyro, double *Jl, double *Wl,
                           double *Cr)
{
    int l = 6 + m->subs[s].m;
    double *Ml = t->Ml + t->loc_off[s], *Cl = t->Cl + t->loc_off[s];
    memset(Ml, 0, (size_t)l * l * sizeof(double));
    memset(Cr, 0, (size_t)l * l * sizeof(double));
    for (int ip = k->pt_ptr[s]; ip < k->pt_ptr[s + 1]; ip++) {
        int pi = k->pt_idx[ip];
        const sp_point *p = &m->pt[pi];
        if (p->mass == 0 && !p->has_I)
            continue;
        double mI[9] = {p->mass, 0, 0, 0, p->mass, 0, 0, 0, p->mass};
        double S2[9] = {0, 2 * p->mass, 0, -2 * p->mass, 0, 0, 0, 0, 0}, X[9], Yp[9];
        tree3_point_jac(m, k, s, pi, Jl, Wl);
        tree3_add_btb(l, Jl, mI, Ml);
        if (gyro)
            tree3_add_btb(l, Jl, S2, Cr);
        if (!p->has_I)
            continue;
        lin3_hub_inertia(m, k, pi, X);
        tree3_add_btb(l, Wl, X, Ml);
        if (gyro) {
            lin3_gyro_rotary(X, Yp);
            tree3_add_btb(l, Wl, Yp, Cr);
        }
    }
    for (int j = 0; j < l; j++) /* exactly symmetric M, skew C (lin3_product); C* = 2 Omega Cl */
        for (int i = 0; i <= j; i++) {
            double a = 0.5 * (Ml[(size_t)j * l + i] + Ml[(size_t)i * l + j]);
            Ml[(size_t)j * l + i] = Ml[(size_t)i * l + j] = a;
            double c = gyro && i < j ? 0.25 * (Cr[(size_t)j * l + i] - Cr[(size_t)i * l + j]) : 0.0;
            Cl[(size_t)j * l + i] = c;
            Cl[(size_t)i * l + j] = -c;
        }
}

int tree3_assemble(const sm_model *m, const double *q, sp_kin *k, double s2, int frozen, int lin, int gyro,
                   tree_ws *t)
{
    int mx = t->max_m, finite = 1;
    size_t lmax = 6 + (size_t)mx;
    double *Jl = t->work; /* tree_alloc: >= 6 lmax + lmax^2 + 14 mx */
    double *Wl = Jl + 3 * lmax, *Cr = Wl + 3 * lmax, *col = Cr + lmax * lmax, *gw = col + mx;
    sp_eval(m, q, k);
    tree3_links(m, k, t);
    if (s2 != 0.0)
        sp_hessian_base(m, q, k);
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        int l = 6 + b->m, n = m->n;
        double *Kl = t->Kl + t->loc_off[s];
        memset(Kl, 0, (size_t)l * l * sizeof(double));
        if (s2 != 0.0) {
            for (int c = 0; c < b->m; c++) { /* -s2 Hl_s */
                sp_hessian_own(m, k, s, b->q0 + c, col);
                for (int i = 0; i < b->m; i++)
                    Kl[(size_t)(6 + c) * l + 6 + i] = -s2 * col[i];
                for (int i = 0; i < 6; i++) {
                    double g = -s2 * k->Gown[b->q0 + c + (size_t)n * i];
                    Kl[(size_t)(6 + c) * l + i] = g;
                    Kl[(size_t)i * l + 6 + c] = g;
                }
            }
        }
        for (int j = 0; j < b->m; j++) /* + K_s (eq. 11) */
            for (int i = 0; i < b->m; i++)
                Kl[(size_t)(6 + j) * l + 6 + i] += DM(&b->K, i, j);
        if (m->opt.geometric_stiffening)
            lin3_geometric_tangent_sub(m, s, q, frozen, Kl + 6 * (size_t)l + 6, l, gw);
        if (frozen) /* K* is symmetric up to round-off: make it exact */
            for (int j = 0; j < l; j++)
                for (int i = 0; i < j; i++)
                    Kl[(size_t)j * l + i] = Kl[(size_t)i * l + j] =
                        0.5 * (Kl[(size_t)j * l + i] + Kl[(size_t)i * l + j]);
        if (lin)
            tree3_mass_sub(m, k, t, s, gyro, Jl, Wl, Cr);
        for (size_t i = 0; i < (size_t)l * l; i++)
            if (!isfinite(Kl[i]) || (lin && (!isfinite(t->Ml[t->loc_off[s] + i]) || !isfinite(t->Cl[t->loc_off[s] + i]))))
                finite = 0;
    }
    if (s2 != 0.0)
        sp_hessian_end(m, k);
    t->omega = sqrt(s2);
    return finite;
}

void tree3_nodal(const sm_model *m, const sp_kin *k, tree_ws *t, const double *x, double *y)
{
    size_t lmax = 6 + (size_t)t->max_m;
    tree_forward(m, t, x, t->u);
    memset(y, 0, 6 * (size_t)m->n_nodes * sizeof(double));
    double *Jl = t->work, *Wl = Jl + 3 * lmax;
    for (int nd = 0; nd < m->n_nodes; nd++) {
        int s = m->pt[nd].sub;
        if (s < 0)
            continue;
        const sm_sub *b = &m->subs[s];
        const double *us = t->u + 6 * s, *xs = x + b->q0;
        double *o = y + 6 * (size_t)nd;
        tree3_point_jac(m, k, s, nd, Jl, Wl);
        for (int j = 0; j < 6 + b->m; j++) {
            double v = j < 6 ? us[j] : xs[j - 6];
            for (int i = 0; i < 3; i++) {
                o[i] += Jl[3 * j + i] * v;
                o[3 + i] += Wl[3 * j + i] * v;
            }
        }
    }
}
