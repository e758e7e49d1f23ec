/*
 * frames3.c — kinematics of a spatial model along its frame tree (DESIGN.md
 * 7.2-7.3): frame poses, point positions and small rotations, the Jacobians
 * J (translation) and W (hub-frame rotation) of every point, the centrifugal
 * force g = dT0~/dq and its Jacobian H.
 *
 * Poses are computed in complex arithmetic: every quantity is analytic in q
 * (rot3.c), so H is obtained column by column by a complex step,
 * H e_j = Im g(q + i h e_j) / h, exact to round-off (no subtractive
 * cancellation), from the O(n) reverse recursion for g:
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

/* Complex step: small enough that h^2 terms vanish against round-off. */
#define SP_STEP 1e-20

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
    free(k->Psi);
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
    k->Psi = dm_vec(36 * (size_t)S + 1);
    k->Gown = dm_vec(6 * (size_t)n + 1);
    k->v = dm_vec(6 * (size_t)S + 1);
    k->pert = -1;
    if (!k->R || !k->A || !k->r || !k->psi || !k->AT || !k->dh || !k->cq || !k->cR || !k->cA || !k->cF || !k->cg ||
        !k->lw || !k->lpsi || !k->lL || !k->lT || !k->bR || !k->bA || !k->mark || !k->bF || !k->Psi || !k->Gown ||
        !k->v ||
        sp_lists(m, k) || (jac && (dm_alloc(&k->JRT, n, 6 * S) || dm_alloc(&k->JW, n, 6 * P)))) {
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
 * T = its tangent.  When k->lw holds the local state at the real base point of a complex-step
 * Jacobian (sp_centrifugal_jacobian), only the points of the perturbed substructure k->pert
 * are recomputed; the others are copied (the same operations on the same values: bitwise equal).
 */
static void sp_point_state(const sm_model *m, sp_kin *k, int pi, const sp_cx *q, int want_L, sp_cx w[3],
                           sp_cx psi[3], sp_cx L[9], sp_cx T[9])
{
    const sp_point *p = &m->pt[pi];
    if (k->cached && p->sub != k->pert) {
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
static void sp_pose(const sm_model *m, sp_kin *k, int s, const sp_cx *q)
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
static void sp_apply(const sm_sub *b, const sp_point *p, const sp_cx A[9], const sp_cx T[9], const sp_cx aw[3],
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
static void sp_point_wrench(const sp_point *p, const sp_cx R[3], const sp_cx A[9], const sp_cx aw[3],
                            const sp_cx L[9], sp_cx F[3], sp_cx Mo[3])
{
    static const sp_cx ez[3] = {0, 0, 1};
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
static void sp_frame_wrench(const sm_model *m, sp_kin *k, int s, const sp_cx *q)
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
        sp_point_wrench(p, k->cR + 3 * s, A, aw, L, F, Mo);
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
static void sp_centrifugal_c(const sm_model *m, sp_kin *k)
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
}

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

/* The child wrench of c stepped by its pose change vc: F_c = bF_c + i h Psi_c vc. */
static void sp_child_step(sp_kin *k, int c, const double vc[6], double h)
{
    const double *Ps = k->Psi + 36 * c;
    for (int r = 0; r < 6; r++) {
        double s = 0;
        for (int j = 0; j < 6; j++)
            s += Ps[r + 6 * j] * vc[j];
        k->cF[6 * c + r] = k->bF[6 * c + r] + _Complex_I * h * s;
    }
}

/*
 * Rigid-motion response of frame c and its subtree (leaves first, the children's Psi known):
 * for each of the 6 unit pose changes v of c (R + i h dR, A + i h skew(dtheta) A), a complex step
 * through c's own points and its children's stepped wrenches gives the imaginary part of g_c
 * (Gown, rows of c) and of the subtree wrench of c (Psi_c, 6 x 6): d g_c = Gown_c v,
 * d wrench_c = Psi_c v.  A moving subtree is rigid below its root frame, so these are all the
 * Jacobian needs below a stepped coordinate.
 */
static void sp_rigid(const sm_model *m, sp_kin *k, int c)
{
    const sm_sub *b = &m->subs[c];
    const double h = SP_STEP;
    const sp_cx *A0 = k->bA + 9 * c;
    for (int kk = 0; kk < 6; kk++) {
        double v[6] = {0, 0, 0, 0, 0, 0}, vc[6];
        v[kk] = 1;
        for (int i = 0; i < 3; i++)
            k->cR[3 * c + i] = k->bR[3 * c + i] + _Complex_I * h * v[i];
        for (int j = 0; j < 3; j++) { /* Im A = h skew(dtheta) A */
            const sp_cx *aj = A0 + 3 * j;
            double w[3] = {v[4] * creal(aj[2]) - v[5] * creal(aj[1]), v[5] * creal(aj[0]) - v[3] * creal(aj[2]),
                           v[3] * creal(aj[1]) - v[4] * creal(aj[0])};
            for (int i = 0; i < 3; i++)
                k->cA[9 * c + 3 * j + i] = aj[i] + _Complex_I * h * w[i];
        }
        for (int t = k->ch_ptr[c]; t < k->ch_ptr[c + 1]; t++) {
            int ch = k->ch_idx[t];
            sp_transport(k, c, ch, v, vc);
            sp_child_step(k, ch, vc, h);
        }
        for (int i = 0; i < b->m; i++)
            k->cg[b->q0 + i] = 0;
        sp_frame_wrench(m, k, c, k->cq);
        for (int r = 0; r < 6; r++)
            k->Psi[36 * c + r + 6 * kk] = cimag(k->cF[6 * c + r]) / h;
        for (int i = 0; i < b->m; i++)
            k->Gown[b->q0 + i + (size_t)m->n * kk] = cimag(k->cg[b->q0 + i]) / h;
    }
    memcpy(k->cR + 3 * c, k->bR + 3 * c, 3 * sizeof(sp_cx));
    memcpy(k->cA + 9 * c, k->bA + 9 * c, 9 * sizeof(sp_cx));
    memcpy(k->cF + 6 * c, k->bF + 6 * c, 6 * sizeof(sp_cx));
    for (int t = k->ch_ptr[c]; t < k->ch_ptr[c + 1]; t++)
        memcpy(k->cF + 6 * k->ch_idx[t], k->bF + 6 * k->ch_idx[t], 6 * sizeof(sp_cx));
}

/* The base of the complex steps at the real q (k->cq): local state of every point (k->lw..),
 * poses (bR, bA), subtree wrenches (bF), and the rigid-motion responses Gown, Psi. */
static void sp_base(const sm_model *m, sp_kin *k)
{
    k->cached = 0;
    k->pert = -1;
    sp_centrifugal_c(m, k);
    memcpy(k->bR, k->cR, 3 * (size_t)m->n_subs * sizeof(sp_cx));
    memcpy(k->bA, k->cA, 9 * (size_t)m->n_subs * sizeof(sp_cx));
    memcpy(k->bF, k->cF, 6 * (size_t)m->n_subs * sizeof(sp_cx));
    for (int pi = 0; pi < m->n_pt; pi++)
        if (m->pt[pi].sub >= 0)
            sp_point_state(m, k, pi, k->cq, 1, k->lw + 3 * pi, k->lpsi + 3 * pi, k->lL + 9 * pi, k->lT + 9 * pi);
    k->cached = 1;
    for (int c = m->n_subs - 1; c >= 0; c--)
        sp_rigid(m, k, c);
}

/*
 * Column j of H, a coordinate of frame s (k->cq[j] = q_j + i h), into col (n).  The points of s
 * take the complex step themselves; each child frame c of s takes the pose change v_c of the
 * step, and everything below it moves rigidly: rows of a descendant t are Gown_t v_t with v_t
 * transported down the tree, the child's wrench is bF_c + i h Psi_c v_c.  Above s only the
 * imaginary part of the wrench on the path to the root is nonzero; it is carried up through the
 * child on the path alone.  Rows of the frames off the path and outside the subtree are zero.
 */
/* The step of sp_step within frame s: its children take their pose changes (k->v), and g_s and
 * the wrench of s are recomputed at the complex q (k->cg rows of s, k->cF of s). */
static void sp_step_own(const sm_model *m, sp_kin *k, int s, double h)
{
    const sp_cx *q = k->cq;
    const sm_sub *bs = &m->subs[s];
    k->pert = s;
    for (int t = k->ch_ptr[s]; t < k->ch_ptr[s + 1]; t++) {
        int c = k->ch_idx[t];
        const sp_cx *Ac = k->cA + 9 * c;
        double *v = k->v + 6 * c;
        sp_pose(m, k, c, q);
        for (int i = 0; i < 3; i++)
            v[i] = cimag(k->cR[3 * c + i]) / h;
        /* skew(dtheta) = Im(A) Re(A)' / h: dtheta = (S21, S02, S10) */
        for (int i = 0; i < 3; i++) {
            int r = (i + 2) % 3, cc = (i + 1) % 3; /* S(r, cc) with (r, cc) = (2,1), (0,2), (1,0) */
            double sum = 0;
            for (int l = 0; l < 3; l++)
                sum += cimag(Ac[r + 3 * l]) * creal(Ac[cc + 3 * l]);
            v[3 + i] = sum / h;
        }
        sp_child_step(k, c, v, h);
        memcpy(k->cR + 3 * c, k->bR + 3 * c, 3 * sizeof(sp_cx));
        memcpy(k->cA + 9 * c, k->bA + 9 * c, 9 * sizeof(sp_cx));
    }
    memset(k->cg + bs->q0, 0, (size_t)bs->m * sizeof(sp_cx));
    sp_frame_wrench(m, k, s, q);
}

static void sp_step(const sm_model *m, sp_kin *k, int s, double h, double *col)
{
    const sm_sub *bs = &m->subs[s];
    int S = m->n_subs, n = m->n;
    memset(col, 0, (size_t)n * sizeof(double));
    sp_step_own(m, k, s, h);
    for (int i = 0; i < bs->m; i++)
        col[bs->q0 + i] = cimag(k->cg[bs->q0 + i]) / h;
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
    for (int c = s, a = bs->parent; a >= 0; c = a, a = m->subs[a].parent) {
        const sm_sub *b = &m->subs[a];
        int pi = m->subs[c].root;
        sp_cx *Fs = k->cF + 6 * a, aw[3];
        for (int i = 0; i < 6; i++)
            Fs[i] = 0;
        memset(k->cg + b->q0, 0, (size_t)b->m * sizeof(sp_cx));
        rot3_mv(k->cA + 9 * a, k->lw + 3 * pi, aw);
        sp_apply(b, &m->pt[pi], k->cA + 9 * a, k->lT + 9 * pi, aw, k->cF + 6 * c, k->cF + 6 * c + 3,
                 k->cg + b->q0, Fs, Fs + 3);
        for (int i = 0; i < b->m; i++)
            col[b->q0 + i] = cimag(k->cg[b->q0 + i]) / h;
    }
    for (int t = s; t < S; t++)
        k->mark[t] = 0;
    k->pert = -1;
}

void sp_hessian_base(const sm_model *m, const double *q, sp_kin *k)
{
    for (int i = 0; i < m->n; i++)
        k->cq[i] = q[i];
    sp_base(m, k);
}

void sp_hessian_own(const sm_model *m, sp_kin *k, int s, int j, double *col)
{
    const sm_sub *b = &m->subs[s];
    double qj = creal(k->cq[j]), h = SP_STEP * fmax(1.0, fabs(qj));
    k->cq[j] = qj + _Complex_I * h;
    sp_step_own(m, k, s, h);
    for (int i = 0; i < b->m; i++)
        col[i] = cimag(k->cg[b->q0 + i]) / h;
    k->cq[j] = qj;
    memcpy(k->cF + 6 * s, k->bF + 6 * s, 6 * sizeof(sp_cx));
    for (int t = k->ch_ptr[s]; t < k->ch_ptr[s + 1]; t++)
        memcpy(k->cF + 6 * k->ch_idx[t], k->bF + 6 * k->ch_idx[t], 6 * sizeof(sp_cx));
    k->pert = -1;
}

void sp_hessian_end(const sm_model *m, sp_kin *k)
{
    memcpy(k->cF, k->bF, 6 * (size_t)m->n_subs * sizeof(sp_cx));
    k->cached = 0;
}

void sp_centrifugal_jacobian(const sm_model *m, const double *q, sp_kin *k, dmat *H)
{
    int n = m->n;
    for (int i = 0; i < n; i++)
        k->cq[i] = q[i];
    sp_base(m, k);
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        for (int j = b->q0; j < b->q0 + b->m; j++) {
            double h = SP_STEP * fmax(1.0, fabs(q[j]));
            k->cq[j] = q[j] + _Complex_I * h;
            sp_step(m, k, s, h, &DM(H, 0, j));
            k->cq[j] = q[j];
        }
    }
    memcpy(k->cF, k->bF, 6 * (size_t)m->n_subs * sizeof(sp_cx));
    k->cached = 0;
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
        if (s < 0)
            continue;
        double *JRc = &DM(&k->JRT, 0, 6 * c);
        sp_offset(k, e, s, a);
        sp_jac_carry(m, k, s, &m->pt[e], k->AT + 9 * e, a, NULL, JRc, JRc + 3 * (size_t)m->n);
    }
    for (int pi = 0; pi < m->n_pt; pi++) {
        int s = m->pt[pi].sub;
        if (s < 0)
            continue;
        double *Jp = &DM(&k->JW, 0, 6 * pi);
        sp_offset(k, pi, s, a);
        sp_jac_carry(m, k, s, &m->pt[pi], k->AT + 9 * pi, a, m->pt[pi].has_c ? k->dh + 3 * pi : NULL, Jp,
                     Jp + 3 * (size_t)m->n);
    }
}
