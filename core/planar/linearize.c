/*
 * linearize.c — the terms of the equilibrium residual and of the linearised
 * equations (DESIGN.md 1.3-1.4, Kim & Yoo eqs. 11, 22-26, 42-44):
 *
 *   elastic      f_e = K q,            K = blockdiag(N_s' Kbar_s N_s)
 *   geometric    f_g = sum_e P_e T_e' G_e T_e q_s,   P_e = d_e . q_s   (eqs. 22, 24, 26)
 *   mass         M*  = sum_p m_p J_p' J_p                                (eq. 42)
 *   gyroscopic   C*  = 2 Omega sum_p m_p J_p' S J_p,  S = [[0,-1],[1,0]]  (eq. 43)
 *
 * The geometric tangent has two forms: with P frozen at P(q*) (the paper's
 * K*, symmetric) and the full derivative that Newton-Raphson needs.
 */
#include "internal.h"

#include <cblas.h>
#include <math.h>
#include <string.h>

/* Bending rows (v1, phi1, v2, phi2) of T_e q_s, and P_e = d_e . q_s. */
static double lin_element_state(const sm_sub *b, int j, const double *qs, double tb[4])
{
    static const int rows[4] = {1, 2, 4, 5};
    const double *d = b->d + (size_t)j * b->m;
    double P = 0;
    for (int r = 0; r < 4; r++)
        tb[r] = 0;
    for (int c = 0; c < b->m; c++) {
        P += d[c] * qs[c];
        for (int r = 0; r < 4; r++)
            tb[r] += DM(&b->T, 6 * j + rows[r], c) * qs[c];
    }
    return P;
}

/** f += f_g(q) = sum_e P_e T_e' G_e T_e q_s (eqs. 22, 26). */
void lin_geometric_force(const sm_model *m, const double *q, double *f)
{
    static const int rows[4] = {1, 2, 4, 5};
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        const double *qs = q + b->q0;
        for (int j = 0; j < b->nel; j++) {
            double tb[4], gt[4];
            double P = lin_element_state(b, j, qs, tb);
            const double *g = b->gq + 16 * j;
            for (int r = 0; r < 4; r++)
                gt[r] = P * (g[r] * tb[0] + g[r + 4] * tb[1] + g[r + 8] * tb[2] + g[r + 12] * tb[3]);
            for (int c = 0; c < b->m; c++) {
                double t = 0;
                for (int r = 0; r < 4; r++)
                    t += DM(&b->T, 6 * j + rows[r], c) * gt[r];
                f[b->q0 + c] += t;
            }
        }
    }
}

/**
 * A += d f_g,s / dq_s for substructure s alone (m_s x m_s, leading dimension
 * lda).  frozen != 0: P_e held at P_e(q) (K*, symmetric); otherwise the full
 * derivative, adding (T' G T q) d_e'.  work: >= 5*max m.
 *
 * Each element adds P_e Tb' G Tb (+ Tb' G tb d_e'), Tb the element's four bending rows of T_s.
 * Those rows are copied into work first, one contiguous row each (T_s is column-major with
 * 6 nel rows: a row of it is strided), and V = G Tb is formed a column at a time inside the
 * column loop, so the inner loop over the rows of A reads and writes contiguous memory (issue
 * 27: 52 % of a 500-coordinate one-frame planar model's time, strided).  Every entry of A
 * receives the same operations in the same order as in solver 0.8.8 (t summed over r = 0..3
 * from 0, then P t added, then the d_e' term; elements in order), so the bits are the same
 * (test_geometric_tangent compares with that form).
 */
void lin_geometric_tangent_sub(const sm_model *m, int s, const double *q, int frozen, double *A, int lda,
                               double *work)
{
    static const int rows[4] = {1, 2, 4, 5};
    const sm_sub *b = &m->subs[s];
    const double *qs = q + b->q0;
    int mm = b->m;
    double *Tr = work, *u = work + 4 * (size_t)mm; /* Tr: 4 x mm, rows of Tb; u = Tb' G tb */
    for (int j = 0; j < b->nel; j++) {
        double tb[4];
        double P = lin_element_state(b, j, qs, tb);
        const double *g = b->gq + 16 * j, *d = b->d + (size_t)j * mm;
        const double *T0 = Tr, *T1 = Tr + mm, *T2 = Tr + 2 * (size_t)mm, *T3 = Tr + 3 * (size_t)mm;
        for (int c = 0; c < mm; c++)
            for (int r = 0; r < 4; r++)
                Tr[(size_t)r * mm + c] = DM(&b->T, 6 * j + rows[r], c);
        if (!frozen) {
            double gt[4];
            for (int r = 0; r < 4; r++)
                gt[r] = g[r] * tb[0] + g[r + 4] * tb[1] + g[r + 8] * tb[2] + g[r + 12] * tb[3];
            for (int ic = 0; ic < mm; ic++) {
                double t = 0;
                t += T0[ic] * gt[0];
                t += T1[ic] * gt[1];
                t += T2[ic] * gt[2];
                t += T3[ic] * gt[3];
                u[ic] = t;
            }
        }
        for (int jc = 0; jc < mm; jc++) {
            double v[4]; /* column jc of V = G Tb */
            for (int r = 0; r < 4; r++) {
                double t = 0;
                t += g[r] * T0[jc];
                t += g[r + 4] * T1[jc];
                t += g[r + 8] * T2[jc];
                t += g[r + 12] * T3[jc];
                v[r] = t;
            }
            double *a = A + (size_t)jc * lda;
            /* two loops, not one with u d_e' scaled by !frozen: adding 0 would turn a -0 entry
             * into +0, and the branch stays out of the inner loop */
            if (frozen) {
                for (int ic = 0; ic < mm; ic++) {
                    double t = 0;
                    t += T0[ic] * v[0];
                    t += T1[ic] * v[1];
                    t += T2[ic] * v[2];
                    t += T3[ic] * v[3];
                    a[ic] += P * t;
                }
            } else {
                double dj = d[jc];
                for (int ic = 0; ic < mm; ic++) {
                    double t = 0;
                    t += T0[ic] * v[0];
                    t += T1[ic] * v[1];
                    t += T2[ic] * v[2];
                    t += T3[ic] * v[3];
                    a[ic] += P * t;
                    a[ic] += u[ic] * dj;
                }
            }
        }
    }
}

/** Kt += d f_g / dq: the blocks of lin_geometric_tangent_sub on the diagonal. */
void lin_geometric_tangent(const sm_model *m, const double *q, int frozen, dmat *Kt, double *work)
{
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        lin_geometric_tangent_sub(m, s, q, frozen, &DM(Kt, b->q0, b->q0), Kt->rows, work);
    }
}

/* W = J_p columns scaled by sqrt(m_p), (n x 2 n_mp). */
static void lin_weighted(const sm_model *m, const sm_kin *k, dmat *W)
{
    for (int p = 0; p < m->n_mp; p++) {
        double w = sqrt(m->mp[p].mass);
        for (int h = 0; h < 2; h++) {
            const double *src = &DM(&k->Jp, 0, 2 * p + h);
            double *dst = &DM(W, 0, 2 * p + h);
            for (int i = 0; i < m->n; i++)
                dst[i] = w * src[i];
        }
    }
}

/** M = sum_p m_p J_p' J_p (eq. 42), full symmetric.  W: n x 2 n_mp scratch. */
void lin_mass(const sm_model *m, const sm_kin *k, dmat *M, dmat *W)
{
    int n = m->n;
    lin_weighted(m, k, W);
    /* M = W W' */
    cblas_dsyrk(CblasColMajor, CblasUpper, CblasNoTrans, n, W->cols, 1.0, W->a, n, 0.0, M->a, n);
    for (int j = 0; j < n; j++)
        for (int i = j + 1; i < n; i++)
            DM(M, i, j) = DM(M, j, i);
}

/**
 * C = 2 Omega sum_p m_p J_p' S J_p (eq. 43): with columns jx, jy of J_p',
 * J'SJ = jy jx' - jx jy', so C = 2 Omega (X - X'), X = Wy Wx'.
 * W: n x 2 n_mp scratch, X: n x n scratch.
 */
void lin_gyro(const sm_model *m, const sm_kin *k, double omega, dmat *C, dmat *W, dmat *X)
{
    int n = m->n, np = m->n_mp;
    lin_weighted(m, k, W);
    /* columns 2p are x, 2p+1 are y: stride 2n in the column-major W */
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, n, n, np, 1.0, W->a + n, 2 * n,
                W->a, 2 * n, 0.0, X->a, n);
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++)
            DM(C, i, j) = 2.0 * omega * (DM(X, i, j) - DM(X, j, i));
}

/**
 * Kt = K + d f_g/dq - s (M* + H) at q, s = Omega^2, with the kinematics of q
 * in k (frames_eval): the Newton tangent of F (frozen = 0, equilibrium.c) or
 * the paper's K* with P_e frozen at P_e(q) (frozen != 0, eq. 44, sweep.c).
 * Leaves M* (eq. 42) in M and the Hessian term H in H.  All matrices n x n,
 * W n x 2 n_mp scratch, work >= 5*max m_s doubles; nothing is allocated.
 */
void lin_tangent(const sm_model *m, const double *q, const sm_kin *k, double s, int frozen, dmat *Kt,
                 dmat *M, dmat *H, dmat *W, double *work)
{
    int n = m->n;
    lin_mass(m, k, M, W);
    dm_zero(H);
    frames_hessian(m, q, k, H, work);
    for (size_t i = 0; i < (size_t)n * n; i++) /* Kt = -s (M* + H) */
        Kt->a[i] = -s * (M->a[i] + H->a[i]);
    lin_elastic_add(m, Kt); /* + K (eq. 11) */
    if (m->opt.geometric_stiffening)
        lin_geometric_tangent(m, q, frozen, Kt, work); /* + d f_g/dq (eqs. 22-26) */
}
