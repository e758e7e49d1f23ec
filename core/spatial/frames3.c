/*
 * frames3.c — kinematics of a spatial model along its frame tree (DESIGN.md
 * 7.2-7.3): frame poses, point positions and small rotations, the Jacobians
 * J (translation) and W (hub-frame rotation) of every point, the centrifugal
 * force g = dT0~/dq and its Jacobian H.
 *
 * Poses are computed in complex arithmetic, every quantity analytic in q
 * (rot3.c): H = dg/dq was a complex step of this recursion up to solver
 * 0.8.1 (hessian3.c now differentiates it in closed form; the tests keep the
 * complex steps as their reference).  g comes from the O(n) reverse recursion:
 *   virtual work  dT0~ = sum_p F_p . dr_p + M_p . dtheta_p,
 *   F_p = m_p P r_p,  M_p = (X_p e_z) x e_z,  X_p = A_p I_p A_p',
 * accumulated leaves first as the wrench (F, M about R_s) of each subtree.
 * J and W come from the forward recursion
 *   dR_c = dR_s + dtheta_s x (A_s w_e) + A_s N^u_e dq_s,
 *   dtheta_c = dtheta_s + A_s T(psi_e) N^psi_e dq_s.
 */
#include "spatial.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void sp_kin_free(sp_kin *k)
{
    free(k->R);
    free(k->A);
    free(k->r);
    free(k->psi);
    free(k->AT);
    free(k->dh);
    dm_free(&k->JRT);
    dm_free(&k->JW);
    free(k->cq);
    free(k->cR);
    free(k->cA);
    free(k->cF);
    free(k->cg);
    free(k->lw);
    free(k->lpsi);
    free(k->lL);
    free(k->lT);
    free(k->bR);
    free(k->bA);
    free(k->mark);
    free(k->bF);
    free(k->bq);
    free(k->Psi);
    free(k->pb);
    free(k->Gown);
    free(k->v);
    free(k->pt_ptr);
    free(k->pt_idx);
    free(k->ch_ptr);
    free(k->ch_idx);
    memset(k, 0, sizeof *k);
}

/* Points and children of every substructure, as CSR lists. */
static int sp_lists(const sm_model *m, sp_kin *k)
{
    int S = m->n_subs, P = m->n_pt;
    k->pt_ptr = calloc((size_t)S + 1, sizeof(int));
    k->ch_ptr = calloc((size_t)S + 1, sizeof(int));
    k->pt_idx = malloc((size_t)(P ? P : 1) * sizeof(int));
    k->ch_idx = malloc((size_t)(S ? S : 1) * sizeof(int));
    if (!k->pt_ptr || !k->ch_ptr || !k->pt_idx || !k->ch_idx)
        return SM_NOMEM;
    for (int p = 0; p < P; p++)
        if (m->pt[p].sub >= 0)
            k->pt_ptr[m->pt[p].sub + 1]++;
    for (int s = 0; s < S; s++)
        if (m->subs[s].parent >= 0)
            k->ch_ptr[m->subs[s].parent + 1]++;
    for (int s = 0; s < S; s++) {
        k->pt_ptr[s + 1] += k->pt_ptr[s];
        k->ch_ptr[s + 1] += k->ch_ptr[s];
    }
    int *fp = calloc((size_t)S + 1, sizeof(int)), *fc = calloc((size_t)S + 1, sizeof(int));
    if (!fp || !fc) {
        free(fp);
        free(fc);
        return SM_NOMEM;
    }
    for (int p = 0; p < P; p++) {
        int s = m->pt[p].sub;
        if (s >= 0)
            k->pt_idx[k->pt_ptr[s] + fp[s]++] = p;
    }
    for (int s = 0; s < S; s++) {
        int a = m->subs[s].parent;
        if (a >= 0)
            k->ch_idx[k->ch_ptr[a] + fc[a]++] = s;
    }
    free(fp);
    free(fc);
    return SM_OK;
}

int sp_kin_alloc(const sm_model *m, sp_kin *k, int jac)
{
    int n = m->n, S = m->n_subs, P = m->n_pt;
    memset(k, 0, sizeof *k);
    k->n = n;
    k->S = S;
    k->P = P;
    k->jac = jac;
    k->R = dm_vec(3 * (size_t)S);
    k->A = dm_vec(9 * (size_t)S);
    k->r = dm_vec(3 * (size_t)P);
    k->psi = dm_vec(3 * (size_t)P);
    k->AT = dm_vec(9 * (size_t)P);
    k->dh = dm_vec(3 * (size_t)P);
    k->cq = calloc((size_t)n, sizeof(sp_cx));
    k->cR = calloc(3 * (size_t)S, sizeof(sp_cx));
    k->cA = calloc(9 * (size_t)S, sizeof(sp_cx));
    k->cF = calloc(6 * (size_t)S, sizeof(sp_cx));
    k->cg = calloc((size_t)n, sizeof(sp_cx));
    k->lw = calloc(3 * (size_t)P + 1, sizeof(sp_cx));
    k->lpsi = calloc(3 * (size_t)P + 1, sizeof(sp_cx));
    k->lL = calloc(9 * (size_t)P + 1, sizeof(sp_cx));
    k->lT = calloc(9 * (size_t)P + 1, sizeof(sp_cx));
    k->bR = calloc(3 * (size_t)S + 1, sizeof(sp_cx));
    k->bA = calloc(9 * (size_t)S + 1, sizeof(sp_cx));
    k->mark = calloc((size_t)S + 1, sizeof(int));
    k->bF = calloc(6 * (size_t)S + 1, sizeof(sp_cx));
    k->bq = dm_vec((size_t)n + 1);
    k->Psi = dm_vec(36 * (size_t)S + 1);
    k->pb = dm_vec(12 * (size_t)P + 1);
    k->Gown = dm_vec(6 * (size_t)n + 1);
    k->v = dm_vec(6 * (size_t)S + 1);
    if (!k->R || !k->A || !k->r || !k->psi || !k->AT || !k->dh || !k->cq || !k->cR || !k->cA ||
        !k->cF || !k->cg || !k->lw || !k->lpsi || !k->lL || !k->lT || !k->bR || !k->bA ||
        !k->mark || !k->bF || !k->bq || !k->Psi || !k->pb || !k->Gown || !k->v || sp_lists(m, k) ||
        (jac && (dm_alloc(&k->JRT, n, 6 * S) || dm_alloc(&k->JW, n, 6 * P)))) {
        sp_kin_free(k);
        return SM_NOMEM;
    }
    return SM_OK;
}

/* Local deformed position w = ub + N^u q_s and small rotation psi = N^psi q_s of point p. */
static void sp_local(const sm_model *m, const sp_point *p, const sp_cx *q, sp_cx w[3], sp_cx psi[3])
{
    const sm_sub *b = &m->subs[p->sub];
    const sp_cx *qs = q + b->q0;
    for (int i = 0; i < 3; i++) {
        w[i] = p->ub[i];
        psi[i] = 0;
    }
    for (int c = 0; c < b->m; c++) {
        const double *Nc = p->N + (size_t)p->ldn * c;
        for (int i = 0; i < 3; i++) {
            w[i] += Nc[i] * qs[c];
            psi[i] += Nc[3 + i] * qs[c];
        }
    }
}

/*
 * Local state of point pi at the complex q: w = ub + N^u q_s, psi = N^psi q_s, L = Lambda(psi),
 * T = its tangent.  While k->lw.. hold the local state at the base of a Jacobian (k->cached,
 * sp_base), they are copied: the closed-form derivatives (hessian3.c) ask for the base state only.
 */
void sp_point_state(const sm_model *m, sp_kin *k, int pi, const sp_cx *q, int want_L, sp_cx w[3],
                    sp_cx psi[3], sp_cx L[9], sp_cx T[9])
{
    const sp_point *p = &m->pt[pi];
    if (k->cached && p->sub >= 0) {
        memcpy(w, k->lw + 3 * pi, 3 * sizeof(sp_cx));
        memcpy(psi, k->lpsi + 3 * pi, 3 * sizeof(sp_cx));
        if (want_L) {
            memcpy(L, k->lL + 9 * pi, 9 * sizeof(sp_cx));
            memcpy(T, k->lT + 9 * pi, 9 * sizeof(sp_cx));
        }
        return;
    }
    sp_local(m, p, q, w, psi);
    if (want_L)
        rot3_exp(psi, L, T);
}

/* Pose of frame s (not a root frame) at the complex q from its parent's pose in k->cR, k->cA. */
void sp_pose(const sm_model *m, sp_kin *k, int s, const sp_cx *q)
{
    const sm_sub *b = &m->subs[s];
    sp_cx *R = k->cR + 3 * s, *A = k->cA + 9 * s;
    const sp_cx *Rp = k->cR + 3 * b->parent, *Ap = k->cA + 9 * b->parent;
    sp_cx w[3], psi[3], aw[3], L[9], T[9], AL[9], Ar[9];
    sp_point_state(m, k, b->root, q, 1, w, psi, L, T);
    rot3_mv(Ap, w, aw);
    for (int i = 0; i < 3; i++)
        R[i] = Rp[i] + aw[i]; /* R_c = R_s + A_s w_e */
    rot3_mul(Ap, L, AL);
    for (int i = 0; i < 9; i++)
        Ar[i] = b->Arel[i];
    rot3_mul(AL, Ar, A); /* A_c = A_s Lambda(psi_e) Arel_c */
}

/* Frame poses at the complex q into k->cR, k->cA (parents first). */
static void sp_poses(const sm_model *m, const sp_cx *q, sp_kin *k)
{
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        if (b->parent >= 0) {
            sp_pose(m, k, s, q);
            continue;
        }
        const sm_node *r = &m->nodes[b->root];
        sp_cx *R = k->cR + 3 * s, *A = k->cA + 9 * s;
        R[0] = r->x, R[1] = r->y, R[2] = r->z;
        for (int i = 0; i < 9; i++)
            A[i] = b->Arel[i];
    }
}

/*
 * A force F and moment Mo (hub frame) acting at point p of frame s, at aw = A_s w_p from R_s:
 * gs (m_s) += N^u' (A' F) + N^psi' (T' A' Mo), and the wrench of s about R_s += (F, Mo + aw x F).
 * T = T(psi_p); NULL when Mo is zero (a point without rotary inertia).
 */
void sp_apply(const sm_sub *b, const sp_point *p, const sp_cx A[9], const sp_cx T[9], const sp_cx aw[3],
              const sp_cx F[3], const sp_cx Mo[3], sp_cx *gs, sp_cx *Fs, sp_cx *Ms)
{
    sp_cx f[3], mo[3] = {0, 0, 0}, t[3], c[3];
    rot3_tmv(A, F, f);
    if (T) {
        rot3_tmv(A, Mo, t);
        rot3_tmv(T, t, mo);
    }
    for (int j = 0; j < b->m; j++) {
        const double *Nc = p->N + (size_t)p->ldn * j;
        gs[j] += Nc[0] * f[0] + Nc[1] * f[1] + Nc[2] * f[2] + Nc[3] * mo[0] + Nc[4] * mo[1] + Nc[5] * mo[2];
    }
    rot3_cross(aw, F, c);
    for (int i = 0; i < 3; i++) {
        Fs[i] += F[i];
        Ms[i] += Mo[i] + c[i];
    }
}

/* Force and moment (hub frame) of the centrifugal potential on point p of frame s at its local
 * state (w, L), aw = A_s w: F = m P r (r = R + A w, + A Lambda c for an offset mass), Mo = the
 * moment of F about the node at the offset plus (X e) x e, X e = A Lambda I Lambda' A' e. */
void sp_point_wrench(const sp_point *p, const sp_cx R[3], const sp_cx A[9], const sp_cx aw[3],
                     const sp_cx L[9], const double *grav, sp_cx F[3], sp_cx Mo[3])
{
    static const sp_cx ez[3] = {0, 0, 1};
    if (grav) { /* the weight m g at the centre of mass (DESIGN.md 8.8): no moment about it */
        if (p->mass == 0)
            return;
        for (int i = 0; i < 3; i++)
            F[i] = p->mass * grav[i];
        if (p->has_c) {
            sp_cx cc[3] = {p->c[0], p->c[1], p->c[2]}, lc[3], dh[3];
            rot3_mv(L, cc, lc);
            rot3_mv(A, lc, dh);
            rot3_cross(dh, F, Mo);
        }
        return;
    }
    if (p->mass != 0) {
        sp_cx dh[3] = {0, 0, 0};
        if (p->has_c) {
            sp_cx cc[3] = {p->c[0], p->c[1], p->c[2]}, lc[3];
            rot3_mv(L, cc, lc);
            rot3_mv(A, lc, dh);
        }
        F[0] = p->mass * (R[0] + aw[0] + dh[0]);
        F[1] = p->mass * (R[1] + aw[1] + dh[1]);
        if (p->has_c) /* F acts at the offset: its moment about the node, F.dr = (dh x F).dtheta */
            rot3_cross(dh, F, Mo);
    }
    if (p->has_Ic) {
        sp_cx v[3], u[3], Ic[9], y[3], z[3], mr[3];
        for (int i = 0; i < 9; i++)
            Ic[i] = p->Ic[i];
        rot3_tmv(A, ez, v);
        rot3_tmv(L, v, u);
        rot3_mv(Ic, u, y);
        rot3_mv(L, y, z);
        rot3_mv(A, z, y);
        rot3_cross(y, ez, mr);
        for (int i = 0; i < 3; i++)
            Mo[i] += mr[i];
    }
}

/* The wrench recursion step of frame s at q (its pose and its children's wrenches in k): g_s and
 * the subtree wrench (F, M about R_s) of s. */
void sp_frame_wrench(const sm_model *m, sp_kin *k, int s, const sp_cx *q)
{
    const sm_sub *b = &m->subs[s];
    const sp_cx *A = k->cA + 9 * s;
    sp_cx *Fs = k->cF + 6 * s, *Ms = Fs + 3, *gs = k->cg + b->q0;
    for (int i = 0; i < 6; i++)
        Fs[i] = 0;
    for (int t = k->pt_ptr[s]; t < k->pt_ptr[s + 1]; t++) {
        int pi = k->pt_idx[t];
        const sp_point *p = &m->pt[pi];
        int rot = p->has_Ic || p->has_c;
        sp_cx w[3], psi[3], aw[3], F[3] = {0, 0, 0}, Mo[3] = {0, 0, 0}, L[9], T[9];
        sp_point_state(m, k, pi, q, rot, w, psi, L, T);
        rot3_mv(A, w, aw);
        sp_point_wrench(p, k->cR + 3 * s, A, aw, L, m->gravity ? m->grav : NULL, F, Mo);
        sp_apply(b, p, A, rot ? T : NULL, aw, F, Mo, gs, Fs, Ms);
    }
    for (int t = k->ch_ptr[s]; t < k->ch_ptr[s + 1]; t++) { /* the subtree wrench of each child */
        int ch = k->ch_idx[t], pi = m->subs[ch].root;
        const sp_cx *Fc = k->cF + 6 * ch, *Mc = Fc + 3;
        sp_cx w[3], psi[3], aw[3], L[9], T[9];
        sp_point_state(m, k, pi, q, 1, w, psi, L, T);
        rot3_mv(A, w, aw);
        sp_apply(b, &m->pt[pi], A, T, aw, Fc, Mc, gs, Fs, Ms);
    }
}

/* g = dT0~/dq at the complex q (k->cq) into k->cg: poses, then the wrench recursion. */
void sp_centrifugal_c(const sm_model *m, sp_kin *k)
{
    const sp_cx *q = k->cq;
    sp_poses(m, q, k);
    memset(k->cg, 0, (size_t)m->n * sizeof(sp_cx));
    for (int s = m->n_subs - 1; s >= 0; s--) /* children first */
        sp_frame_wrench(m, k, s, q);
}

void sp_centrifugal(const sm_model *m, const double *q, sp_kin *k, double *g)
{
    for (int i = 0; i < m->n; i++)
        k->cq[i] = q[i];
    sp_centrifugal_c(m, k);
    for (int i = 0; i < m->n; i++)
        g[i] = creal(k->cg[i]);
    if (!k->cached) { /* the base of a Jacobian at q, should one follow (sp_base) */
        memcpy(k->bR, k->cR, 3 * (size_t)m->n_subs * sizeof(sp_cx));
        memcpy(k->bA, k->cA, 9 * (size_t)m->n_subs * sizeof(sp_cx));
        memcpy(k->bF, k->cF, 6 * (size_t)m->n_subs * sizeof(sp_cx));
        memcpy(k->bq, q, (size_t)m->n * sizeof(double));
        k->bvalid = 1;
    }
}

/*
 * J, W (n x 3 each, ld n) of a point at offset a = x - R_s from the origin of frame s, carried
 * by s: the rigid transport of the frame's pose Jacobians (dR_s + dtheta_s x a, dtheta_s) plus
 * the point's own columns in q_s: A_s N^u (translation), AT = A_s T(psi) times N^psi (rotation).
 * Used for child frames (x = their origin) and for points alike.
 */
static void sp_jac_carry(const sm_model *m, const sp_kin *k, int s, const sp_point *p, const double *AT,
                         const double a[3], const double *dh, double *J, double *W)
{
    int n = m->n;
    const sm_sub *b = &m->subs[s];
    const double *A = k->A + 9 * s, *JRs = &DM(&k->JRT, 0, 6 * s), *JTs = JRs + 3 * (size_t)n;
    for (int x = 0; x < n; x++) {
        const double t0 = JTs[x], t1 = JTs[n + x], t2 = JTs[2 * (size_t)n + x];
        J[x] = JRs[x] + t1 * a[2] - t2 * a[1]; /* dtheta x a */
        J[n + x] = JRs[n + x] + t2 * a[0] - t0 * a[2];
        J[2 * (size_t)n + x] = JRs[2 * (size_t)n + x] + t0 * a[1] - t1 * a[0];
        W[x] = t0;
        W[n + x] = t1;
        W[2 * (size_t)n + x] = t2;
    }
    for (int j = 0; j < b->m; j++) {
        const double *Nc = p->N + (size_t)p->ldn * j;
        double wj[3];
        for (int i = 0; i < 3; i++) {
            J[(size_t)n * i + b->q0 + j] += A[i] * Nc[0] + A[i + 3] * Nc[1] + A[i + 6] * Nc[2];
            wj[i] = AT[i] * Nc[3] + AT[i + 3] * Nc[4] + AT[i + 6] * Nc[5];
            W[(size_t)n * i + b->q0 + j] += wj[i];
        }
        if (dh) { /* an offset mass: its own rotation carries the offset, dtheta x dh */
            J[b->q0 + j] += wj[1] * dh[2] - wj[2] * dh[1];
            J[(size_t)n + b->q0 + j] += wj[2] * dh[0] - wj[0] * dh[2];
            J[2 * (size_t)n + b->q0 + j] += wj[0] * dh[1] - wj[1] * dh[0];
        }
    }
}

/* The offset a = r_p - R_s of point pi from the origin of its frame. */
static void sp_offset(const sp_kin *k, int pi, int s, double a[3])
{
    for (int i = 0; i < 3; i++)
        a[i] = k->r[3 * pi + i] - k->R[3 * s + i];
}

void sp_eval(const sm_model *m, const double *q, sp_kin *k)
{
    for (int i = 0; i < m->n; i++)
        k->cq[i] = q[i];
    sp_poses(m, k->cq, k);
    for (int i = 0; i < 3 * m->n_subs; i++)
        k->R[i] = creal(k->cR[i]);
    for (int i = 0; i < 9 * m->n_subs; i++)
        k->A[i] = creal(k->cA[i]);
    for (int pi = 0; pi < m->n_pt; pi++) {
        const sp_point *p = &m->pt[pi];
        double *r = k->r + 3 * pi, *ps = k->psi + 3 * pi, *AT = k->AT + 9 * pi, *dh = k->dh + 3 * pi;
        memset(dh, 0, 3 * sizeof(double));
        if (p->sub < 0) { /* the clamp */
            memcpy(r, p->ub, 3 * sizeof(double));
            memset(ps, 0, 3 * sizeof(double));
            memset(AT, 0, 9 * sizeof(double));
            continue;
        }
        sp_cx w[3], psi[3], aw[3], L[9], T[9], At[9];
        sp_local(m, p, k->cq, w, psi);
        rot3_mv(k->cA + 9 * p->sub, w, aw);
        rot3_exp(psi, L, T);
        rot3_mul(k->cA + 9 * p->sub, T, At);
        if (p->has_c) {
            sp_cx cc[3] = {p->c[0], p->c[1], p->c[2]}, lc[3], d[3];
            rot3_mv(L, cc, lc);
            rot3_mv(k->cA + 9 * p->sub, lc, d);
            for (int i = 0; i < 3; i++)
                dh[i] = creal(d[i]);
        }
        for (int i = 0; i < 3; i++) {
            r[i] = creal(k->cR[3 * p->sub + i] + aw[i]) + dh[i];
            ps[i] = creal(psi[i]);
        }
        for (int i = 0; i < 9; i++)
            AT[i] = creal(At[i]);
    }
    if (!k->jac)
        return;
    dm_zero(&k->JRT);
    dm_zero(&k->JW);
    double a[3];
    for (int c = 0; c < m->n_subs; c++) { /* child frames at node e of their parent: R_c = r_e */
        int s = m->subs[c].parent, e = m->subs[c].root;
        if (s < 0) { /* a free base moves the root frames rigidly about the clamp (at rest) */
            for (int i = 0; i < m->base; i++)
                DM(&k->JRT, i, 6 * c + m->base_dir[i]) = 1.0;
            continue;
        }
        double *JRc = &DM(&k->JRT, 0, 6 * c);
        sp_offset(k, e, s, a);
        sp_jac_carry(m, k, s, &m->pt[e], k->AT + 9 * e, a, NULL, JRc, JRc + 3 * (size_t)m->n);
    }
    for (int pi = 0; pi < m->n_pt; pi++) {
        int s = m->pt[pi].sub;
        if (s < 0) { /* the clamp point: with a free base it is the base */
            for (int i = 0; i < m->base; i++)
                DM(&k->JW, i, 6 * pi + m->base_dir[i]) = 1.0;
            continue;
        }
        double *Jp = &DM(&k->JW, 0, 6 * pi);
        sp_offset(k, pi, s, a);
        sp_jac_carry(m, k, s, &m->pt[pi], k->AT + 9 * pi, a, m->pt[pi].has_c ? k->dh + 3 * pi : NULL, Jp,
                     Jp + 3 * (size_t)m->n);
    }
}
