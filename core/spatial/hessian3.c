/*
 * hessian3.c — the spatial kind's centrifugal Jacobian H = dg/dq in closed form (DESIGN.md 7.3):
 * a coordinate of frame s moves the points of s in their frame (sp_own_column: the rows of s);
 * below s the subtrees move rigidly (their 6-column responses Gown, Psi computed once per
 * Jacobian, leaves first: sp_rigid); the rows above s are H's symmetry (sp_fill_up).  Also the
 * pieces of the tree path's block Hessian (sp_hessian_base, _own, _end: tree3.c).  Each
 * derivative is frames3.c's wrench recursion (sp_point_wrench, sp_apply) differentiated by hand
 * at the base state; they were complex steps through it up to solver 0.8.1, which
 * tests/core/test_spatial_hessian.c still takes as its reference.
 *
 * How it fits: frames3.c evaluates poses, points and the wrench recursion at q (sp_base keeps
 * that state); this file differentiates it one coordinate at a time.
 */
#include "spatial.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The rigid transport of a pose change v = (dR, dtheta) of frame p to its child frame c:
 * dR_c = dR + dtheta x (R_c - R_p), dtheta_c = dtheta (base poses). */
static void sp_transport(const sp_kin *k, int p, int c, const double v[6], double vc[6])
{
    double a[3];
    for (int i = 0; i < 3; i++)
        a[i] = creal(k->bR[3 * c + i]) - creal(k->bR[3 * p + i]);
    vc[0] = v[0] + v[4] * a[2] - v[5] * a[1];
    vc[1] = v[1] + v[5] * a[0] - v[3] * a[2];
    vc[2] = v[2] + v[3] * a[1] - v[4] * a[0];
    vc[3] = v[3], vc[4] = v[4], vc[5] = v[5];
}

/* rows (m_s) += N' (f, mo): a force f and moment mo (frame axes) at point p into the rows of its
 * frame b, as sp_apply adds them (the same sum per row). */
static void sp_rows_add(const sm_sub *b, const sp_point *p, const double f[3], const double mo[3],
                        double *rows)
{
    for (int j = 0; j < b->m; j++) {
        const double *Nc = p->N + (size_t)p->ldn * j;
        rows[j] += Nc[0] * f[0] + Nc[1] * f[1] + Nc[2] * f[2] + Nc[3] * mo[0] + Nc[4] * mo[1] +
                   Nc[5] * mo[2];
    }
}

/* A point's share of a rigid motion's response, one direction: the point's force F and moment
 * Mo (hub frame) change by dF, dMo while its frame turns by dth and T (NULL: no moment) maps
 * it into its coordinates.  With the frame's A and the point's offset aw = A w (both at rest in
 * the motion), sp_apply's terms change by
 *   d(A' F) = A' (dF - dth x F),  d(T' A' Mo) = T' A' (dMo - dth x Mo),
 *   d wrench = (dF, dMo + (dth x aw) x F + aw x dF),
 * and the rows of the frame by N' (d(A' F), d(T' A' Mo)). */
static void sp_rigid_apply(const sm_sub *b, const sp_point *p, const double A[9], const double *T,
                           const double aw[3], const double F[3], const double Mo[3],
                           const double dF[3], const double dMo[3], const double dth[3],
                           double *gcol, double dW[6])
{
    double t[3], u[3], f[3], mo[3] = {0, 0, 0}, c[3], e[3];
    rot3_cross_r(dth, F, t);
    for (int i = 0; i < 3; i++)
        u[i] = dF[i] - t[i];
    rot3_tmv_r(A, u, f);
    if (T) {
        rot3_cross_r(dth, Mo, t);
        for (int i = 0; i < 3; i++)
            u[i] = dMo[i] - t[i];
        rot3_tmv_r(A, u, t);
        rot3_tmv_r(T, t, mo);
    }
    sp_rows_add(b, p, f, mo, gcol);
    rot3_cross_r(dth, aw, t);
    rot3_cross_r(t, F, c);
    rot3_cross_r(aw, dF, e);
    for (int i = 0; i < 3; i++) {
        dW[i] += dF[i];
        dW[3 + i] += dMo[i] + c[i] + e[i];
    }
}

/* Real parts of n complex values. */
static void sp_re(const sp_cx *z, int n, double *x)
{
    for (int i = 0; i < n; i++)
        x[i] = creal(z[i]);
}

/* A point's force and moment change under the rigid motion (dR, dth) of its frame, from its
 * state at rest in the motion (sp_point_wrench's terms differentiated):
 *   F = m P (R + aw + dh): dF = m P (dR + dth x (aw + dh)), dh = A Lambda c its offset mass;
 *   Mo = dh x F: dMo = (dth x dh) x F + dh x dF (the weight: dF = 0);
 *   rotary: Mo += y x e, y = X e, X = A Lambda Ic Lambda' A': dy = dth x y - X (dth x e). */
static void sp_rigid_point(const sp_point *p, const double A[9], const double L[9],
                           const double aw[3], const double dh[3], const double F[3],
                           const double y[3], int grav, const double dR[3], const double dth[3],
                           double dF[3], double dMo[3])
{
    static const double ez[3] = {0, 0, 1};
    double t[3], a[3], c[3];
    for (int i = 0; i < 3; i++)
        dF[i] = dMo[i] = 0;
    if (p->mass != 0) {
        if (!grav) {
            for (int i = 0; i < 3; i++)
                a[i] = aw[i] + dh[i];
            rot3_cross_r(dth, a, t);
            dF[0] = p->mass * (dR[0] + t[0]);
            dF[1] = p->mass * (dR[1] + t[1]);
        }
        if (p->has_c) {
            rot3_cross_r(dth, dh, t);
            rot3_cross_r(t, F, dMo);
            rot3_cross_r(dh, dF, c);
            for (int i = 0; i < 3; i++)
                dMo[i] += c[i];
        }
    }
    if (p->has_Ic && !grav) {
        double u[3], v[3], dy[3];
        rot3_cross_r(dth, ez, t); /* X t = A L Ic L' A' t */
        rot3_tmv_r(A, t, u);
        rot3_tmv_r(L, u, v);
        rot3_mv_r(p->Ic, v, u);
        rot3_mv_r(L, u, v);
        rot3_mv_r(A, v, u);
        rot3_cross_r(dth, y, dy);
        for (int i = 0; i < 3; i++)
            dy[i] -= u[i];
        rot3_cross_r(dy, ez, t);
        for (int i = 0; i < 3; i++)
            dMo[i] += t[i];
    }
}

/*
 * Rigid-motion response of frame c and its subtree (leaves first, the children's Psi known): for
 * each of the 6 unit pose changes v = (dR, dth) of c, the change of g_c (Gown, rows of c) and of
 * the subtree wrench of c (Psi_c, 6 x 6): d g_c = Gown_c v, d wrench_c = Psi_c v.  A moving subtree
 * is rigid below its root frame, so these are all the Jacobian needs below a stepped coordinate.
 * In closed form (sp_rigid_point, sp_rigid_apply) from the base state at rest in the motion: the
 * points keep their local state, only A, R and the children's wrenches move.  It was 6 complex
 * steps of the frame's wrench recursion (issue 27: 9 % of a 12-element blade's instructions);
 * the two agree to round-off (1e-16 relative).
 */
static void sp_rigid(const sm_model *m, sp_kin *k, int c)
{
    const sm_sub *b = &m->subs[c];
    int grav = m->gravity, n = m->n;
    double A[9], R[3], Psi[36] = {0};
    sp_re(k->bA + 9 * c, 9, A);
    sp_re(k->bR + 3 * c, 3, R);
    for (int kk = 0; kk < 6; kk++)
        for (int i = 0; i < b->m; i++)
            k->Gown[b->q0 + i + (size_t)n * kk] = 0;
    for (int t = k->pt_ptr[c]; t < k->pt_ptr[c + 1]; t++) {
        int pi = k->pt_idx[t];
        const sp_point *p = &m->pt[pi];
        int rot = p->has_Ic || p->has_c;
        sp_cx w[3], psi[3], aw[3], F[3] = {0, 0, 0}, Mo[3] = {0, 0, 0}, L[9], T[9];
        sp_point_state(m, k, pi, k->cq, rot, w, psi, L, T);
        rot3_mv(k->bA + 9 * c, w, aw);
        sp_point_wrench(p, k->bR + 3 * c, k->bA + 9 * c, aw, L, grav ? m->grav : NULL, F, Mo);
        double awr[3], Fr[3], Mr[3], Lr[9] = {0}, Tr[9] = {0}, dh[3] = {0, 0, 0}, y[3] = {0, 0, 0};
        sp_re(aw, 3, awr);
        sp_re(F, 3, Fr);
        sp_re(Mo, 3, Mr);
        if (rot) {
            sp_re(L, 9, Lr);
            sp_re(T, 9, Tr);
        }
        if (p->has_c) { /* dh = A Lambda c */
            double u[3];
            rot3_mv_r(Lr, p->c, u);
            rot3_mv_r(A, u, dh);
        }
        if (p->has_Ic && !grav) { /* y = X e_z */
            double u[3], v[3];
            u[0] = A[2], u[1] = A[5], u[2] = A[8]; /* A' e_z */
            rot3_tmv_r(Lr, u, v);
            rot3_mv_r(p->Ic, v, u);
            rot3_mv_r(Lr, u, v);
            rot3_mv_r(A, v, y);
        }
        double *pb = k->pb + 12 * (size_t)pi; /* for the own columns (sp_own_column) */
        memcpy(pb, Fr, sizeof Fr);
        memcpy(pb + 3, Mr, sizeof Mr);
        memcpy(pb + 6, dh, sizeof dh);
        memcpy(pb + 9, y, sizeof y);
        for (int kk = 0; kk < 6; kk++) {
            double v[6] = {0, 0, 0, 0, 0, 0}, dF[3], dMo[3];
            v[kk] = 1;
            sp_rigid_point(p, A, Lr, awr, dh, Fr, y, grav, v, v + 3, dF, dMo);
            sp_rigid_apply(b, p, A, rot ? Tr : NULL, awr, Fr, Mr, dF, dMo, v + 3,
                           k->Gown + b->q0 + (size_t)n * kk, Psi + 6 * kk);
        }
    }
    for (int t = k->ch_ptr[c]; t < k->ch_ptr[c + 1]; t++) { /* the children's wrenches */
        int ch = k->ch_idx[t], pi = m->subs[ch].root;
        const sp_point *p = &m->pt[pi];
        sp_cx w[3], psi[3], aw[3], L[9], T[9];
        sp_point_state(m, k, pi, k->cq, 1, w, psi, L, T);
        rot3_mv(k->bA + 9 * c, w, aw);
        double awr[3], Tr[9], Fc[6];
        sp_re(aw, 3, awr);
        sp_re(T, 9, Tr);
        sp_re(k->bF + 6 * ch, 6, Fc);
        const double *Pc = k->Psi + 36 * ch;
        for (int kk = 0; kk < 6; kk++) {
            double v[6] = {0, 0, 0, 0, 0, 0}, vc[6], dW[6];
            v[kk] = 1;
            sp_transport(k, c, ch, v, vc);
            for (int r = 0; r < 6; r++) {
                double sum = 0;
                for (int j = 0; j < 6; j++)
                    sum += Pc[r + 6 * j] * vc[j];
                dW[r] = sum;
            }
            sp_rigid_apply(b, p, A, Tr, awr, Fc, Fc + 3, dW, dW + 3, v + 3,
                           k->Gown + b->q0 + (size_t)n * kk, Psi + 6 * kk);
        }
    }
    memcpy(k->Psi + 36 * c, Psi, sizeof Psi);
}

/*
 * Column j (a coordinate of frame s) of H in the rows of s, in closed form, into col (m_s), and
 * the pose change v_c of each child c of s (k->v), from the base (sp_base: k->pb, lw.., bA, bF,
 * Psi).  A step dq_j moves the points of s in their frame: dw = N^u_j, dpsi = N^psi_j, so
 * dLambda = skew(om) Lambda with om = T dpsi, and with A and R of s fixed:
 *   d dh = A (om x Lambda c),  dF = m P (A dw + d dh) (the weight: 0),
 *   dMo = d dh x F + dh x dF,  rotary: dy = A (om x z - Lambda Ic Lambda' (om x A' e_z)),
 *   z = A' y, dMo += dy x e_z;
 * sp_apply's rows change by N' (A' dF, dT' A' Mo + T' A' dMo), dT = rot3_dtangent(psi, dpsi).
 * A child c at node e of s moves rigidly by v_c = (A dw_e, A T_e dpsi_e): its wrench by Psi_c v_c.
 * It was a complex step of the frame's wrench recursion, child poses included (issue 27).
 */
static void sp_own_column(const sm_model *m, sp_kin *k, int s, int j, double *col)
{
    static const double ez[3] = {0, 0, 1};
    const sm_sub *b = &m->subs[s];
    int jj = j - b->q0, grav = m->gravity;
    double A[9];
    sp_re(k->bA + 9 * s, 9, A);
    for (int i = 0; i < b->m; i++)
        col[i] = 0;
    for (int t = k->pt_ptr[s]; t < k->pt_ptr[s + 1]; t++) {
        int pi = k->pt_idx[t];
        const sp_point *p = &m->pt[pi];
        const double *Nj = p->N + (size_t)p->ldn * jj, *pb = k->pb + 12 * (size_t)pi;
        int rot = p->has_Ic || p->has_c;
        double dF[3] = {0, 0, 0}, dMo[3] = {0, 0, 0}, u[3], v[3], f[3], mo[3] = {0, 0, 0};
        if (!rot) {
            if (p->mass != 0 && !grav) {
                rot3_mv_r(A, Nj, u);
                dF[0] = p->mass * u[0];
                dF[1] = p->mass * u[1];
            }
        } else {
            double psi[3], T[9], L[9], om[3], ddh[3] = {0, 0, 0}, a[3], c[3];
            sp_re(k->lpsi + 3 * pi, 3, psi);
            sp_re(k->lT + 9 * pi, 9, T);
            sp_re(k->lL + 9 * pi, 9, L);
            rot3_mv_r(T, Nj + 3, om);
            if (p->has_c) { /* d dh = A (om x Lambda c), Lambda c = A' dh */
                rot3_tmv_r(A, pb + 6, a);
                rot3_cross_r(om, a, c);
                rot3_mv_r(A, c, ddh);
            }
            if (p->mass != 0) {
                if (!grav) {
                    rot3_mv_r(A, Nj, u);
                    dF[0] = p->mass * (u[0] + ddh[0]);
                    dF[1] = p->mass * (u[1] + ddh[1]);
                }
                if (p->has_c) {
                    rot3_cross_r(ddh, pb, dMo);
                    rot3_cross_r(pb + 6, dF, c);
                    for (int i = 0; i < 3; i++)
                        dMo[i] += c[i];
                }
            }
            if (p->has_Ic && !grav) { /* dy = A (om x z - L Ic L' (om x A' e)) */
                double z[3], ae[3] = {A[2], A[5], A[8]}, w1[3], w2[3], dy[3];
                rot3_tmv_r(A, pb + 9, z);
                rot3_cross_r(om, ae, w1);
                rot3_tmv_r(L, w1, w2);
                rot3_mv_r(p->Ic, w2, w1);
                rot3_mv_r(L, w1, w2);
                rot3_cross_r(om, z, w1);
                for (int i = 0; i < 3; i++)
                    w1[i] -= w2[i];
                rot3_mv_r(A, w1, dy);
                rot3_cross_r(dy, ez, c);
                for (int i = 0; i < 3; i++)
                    dMo[i] += c[i];
            }
            double dT[9], am[3];
            rot3_dtangent(psi, Nj + 3, dT);
            rot3_tmv_r(A, pb + 3, am); /* dmo = dT' A' Mo + T' A' dMo */
            rot3_tmv_r(dT, am, mo);
            rot3_tmv_r(A, dMo, u);
            rot3_tmv_r(T, u, v);
            for (int i = 0; i < 3; i++)
                mo[i] += v[i];
        }
        rot3_tmv_r(A, dF, f);
        sp_rows_add(b, p, f, mo, col);
    }
    for (int t = k->ch_ptr[s]; t < k->ch_ptr[s + 1]; t++) { /* the children move rigidly */
        int ch = k->ch_idx[t], pi = m->subs[ch].root;
        const sp_point *p = &m->pt[pi];
        const double *Nj = p->N + (size_t)p->ldn * jj, *Pc = k->Psi + 36 * ch;
        double psi[3], T[9], dT[9], om[3], dW[6], Fc[6], f[3], mo[3], u[3], w[3];
        double *vc = k->v + 6 * ch;
        sp_re(k->lpsi + 3 * pi, 3, psi);
        sp_re(k->lT + 9 * pi, 9, T);
        sp_re(k->bF + 6 * ch, 6, Fc);
        rot3_mv_r(A, Nj, vc); /* dR_c = A dw_e, dth_c = A T_e dpsi_e */
        rot3_mv_r(T, Nj + 3, om);
        rot3_mv_r(A, om, vc + 3);
        for (int r = 0; r < 6; r++) {
            double sum = 0;
            for (int i = 0; i < 6; i++)
                sum += Pc[r + 6 * i] * vc[i];
            dW[r] = sum;
        }
        rot3_tmv_r(A, dW, f);
        rot3_dtangent(psi, Nj + 3, dT);
        rot3_tmv_r(A, Fc + 3, u);
        rot3_tmv_r(dT, u, mo);
        rot3_tmv_r(A, dW + 3, u);
        rot3_tmv_r(T, u, w);
        for (int i = 0; i < 3; i++)
            mo[i] += w[i];
        sp_rows_add(b, p, f, mo, col);
    }
}

/* The base of the Jacobian at the real q (= k->cq): local state of every point (k->lw..),
 * poses (bR, bA), subtree wrenches (bF), and the rigid-motion responses Gown, Psi.  Poses and
 * wrenches are those of g at q: a Newton tangent follows a residual at the same q, whose
 * sp_centrifugal left them in bR, bA, bF (the same operations on the same values).  The
 * derivatives read the base only (b*, lw.., pb); cR, cA, cF are scratch. */
static void sp_base(const sm_model *m, const double *q, sp_kin *k)
{
    size_t S = (size_t)m->n_subs;
    k->cached = 0;
    if (!(k->bvalid && !memcmp(k->bq, q, (size_t)m->n * sizeof(double)))) {
        sp_centrifugal_c(m, k);
        memcpy(k->bR, k->cR, 3 * S * sizeof(sp_cx));
        memcpy(k->bA, k->cA, 9 * S * sizeof(sp_cx));
        memcpy(k->bF, k->cF, 6 * S * sizeof(sp_cx));
        memcpy(k->bq, q, (size_t)m->n * sizeof(double));
        k->bvalid = 1;
    }
    for (int pi = 0; pi < m->n_pt; pi++)
        if (m->pt[pi].sub >= 0)
            sp_point_state(m, k, pi, k->cq, 1, k->lw + 3 * pi, k->lpsi + 3 * pi, k->lL + 9 * pi,
                           k->lT + 9 * pi);
    k->cached = 1;
    for (int c = m->n_subs - 1; c >= 0; c--)
        sp_rigid(m, k, c);
}

/*
 * Column j of H, a coordinate of frame s, into col (n): the rows of s (sp_own_column) and of its
 * subtree: each child frame c of s takes the pose change v_c of the step, and everything below
 * it moves rigidly, rows of a descendant t being Gown_t v_t with v_t transported down the tree.
 * The rows of the ancestors of s are H's symmetry (sp_fill_up); rows of the frames off the path
 * and outside the subtree are zero.
 */
static void sp_step(const sm_model *m, sp_kin *k, int s, int j, double *col)
{
    const sm_sub *bs = &m->subs[s];
    int S = m->n_subs, n = m->n;
    memset(col, 0, (size_t)n * sizeof(double));
    sp_own_column(m, k, s, j, col + bs->q0);
    k->mark[s] = 1;
    for (int t = s + 1; t < S; t++) { /* the subtree of s: parents come first */
        int p = m->subs[t].parent;
        k->mark[t] = p >= 0 && k->mark[p];
        if (!k->mark[t])
            continue;
        const sm_sub *b = &m->subs[t];
        double *v = k->v + 6 * t;
        if (p != s)
            sp_transport(k, p, t, k->v + 6 * p, v);
        for (int i = 0; i < b->m; i++) { /* rows of t = Gown_t v_t */
            double sum = 0;
            for (int kk = 0; kk < 6; kk++)
                sum += k->Gown[b->q0 + i + (size_t)n * kk] * v[kk];
            col[b->q0 + i] = sum;
        }
    }
    for (int t = s; t < S; t++)
        k->mark[t] = 0;
}

/*
 * The rows of the ancestors of frame s in column j (a coordinate of s).  H = dg/dq is the
 * Hessian of T0~, so H(i, j) = H(j, i), and the column of a coordinate i of an ancestor, done
 * before s's (parents come first), holds H(j, i) among its subtree rows (Gown_s v_s).  This
 * replaced carrying the step's wrench up the path to the root once per column (issue 27: 9 %
 * of a 12-element blade's Newton tangent); the tree path's block Hessian (tree3.c) has always
 * taken these blocks as Gown'.  The two differ by round-off (H's asymmetry, 1e-16 relative).
 */
static void sp_fill_up(const sm_model *m, int s, int j, dmat *H)
{
    for (int a = m->subs[s].parent; a >= 0; a = m->subs[a].parent) {
        const sm_sub *b = &m->subs[a];
        for (int i = b->q0; i < b->q0 + b->m; i++)
            DM(H, i, j) = DM(H, j, i);
    }
}

void sp_hessian_base(const sm_model *m, const double *q, sp_kin *k)
{
    for (int i = 0; i < m->n; i++)
        k->cq[i] = q[i];
    sp_base(m, q, k);
}

void sp_hessian_own(const sm_model *m, sp_kin *k, int s, int j, double *col)
{
    sp_own_column(m, k, s, j, col);
}

void sp_hessian_end(const sm_model *m, sp_kin *k)
{
    (void)m;
    k->cached = 0;
}

void sp_centrifugal_jacobian(const sm_model *m, const double *q, sp_kin *k, dmat *H)
{
    int n = m->n;
    for (int i = 0; i < n; i++)
        k->cq[i] = q[i];
    sp_base(m, q, k);
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        for (int j = b->q0; j < b->q0 + b->m; j++) {
            sp_step(m, k, s, j, &DM(H, 0, j));
            sp_fill_up(m, s, j, H);
        }
    }
    k->cached = 0;
}
