/*
 * hessian3.c — the spatial kind's centrifugal Jacobian H = dg/dq by complex step, exact to
 * round-off (DESIGN.md 7.3): a step in a coordinate of frame s goes through the points of s
 * only; below s the subtrees move rigidly (their 6-column responses computed once per
 * Jacobian, leaves first), above s the wrench is carried up the path.  Also the pieces of the
 * tree path's block Hessian (sp_hessian_base, _own, _end: tree3.c).
 *
 * How it fits: frames3.c evaluates poses, points and the wrench recursion at complex q; this
 * file perturbs that state one coordinate at a time.
 */
#include "spatial.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Complex step: small enough that h^2 terms vanish against round-off. */
#define SP_STEP 1e-20

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
            double w[3] = {v[4] * creal(aj[2]) - v[5] * creal(aj[1]),
                           v[5] * creal(aj[0]) - v[3] * creal(aj[2]),
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

/* The base of the complex steps at the real q (= k->cq): local state of every point (k->lw..),
 * poses (bR, bA), subtree wrenches (bF), and the rigid-motion responses Gown, Psi.  Poses and
 * wrenches are those of g at q: a Newton tangent follows a residual at the same q, whose
 * sp_centrifugal left them in bR, bA, bF (the same operations on the same values). */
static void sp_base(const sm_model *m, const double *q, sp_kin *k)
{
    size_t S = (size_t)m->n_subs;
    k->cached = 0;
    k->pert = -1;
    if (k->bvalid && !memcmp(k->bq, q, (size_t)m->n * sizeof(double))) {
        memcpy(k->cR, k->bR, 3 * S * sizeof(sp_cx));
        memcpy(k->cA, k->bA, 9 * S * sizeof(sp_cx));
        memcpy(k->cF, k->bF, 6 * S * sizeof(sp_cx));
    } else {
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
 * Column j of H, a coordinate of frame s (k->cq[j] = q_j + i h), into col (n): the rows of s and
 * of its subtree.  The points of s take the complex step themselves; each child frame c of s
 * takes the pose change v_c of the step, and everything below it moves rigidly: rows of a
 * descendant t are Gown_t v_t with v_t transported down the tree, the child's wrench is
 * bF_c + i h Psi_c v_c.  The rows of the ancestors of s are H's symmetry (sp_fill_up); rows of
 * the frames off the path and outside the subtree are zero.
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
    for (int t = s; t < S; t++)
        k->mark[t] = 0;
    k->pert = -1;
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
    const sm_sub *b = &m->subs[s];
    double qj = creal(k->cq[j]), h = SP_STEP * fmax(1.0, fabs(qj));
    k->cq[j] = qj + _Complex_I * h;
    k->pert_j = j;
    k->step++;
    sp_step_own(m, k, s, h);
    for (int i = 0; i < b->m; i++)
        col[i] = cimag(k->cg[b->q0 + i]) / h;
    k->cq[j] = qj;
    k->pert_j = -1;
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
    sp_base(m, q, k);
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        for (int j = b->q0; j < b->q0 + b->m; j++) {
            double h = SP_STEP * fmax(1.0, fabs(q[j]));
            k->cq[j] = q[j] + _Complex_I * h;
            k->pert_j = j;
            k->step++;
            sp_step(m, k, s, h, &DM(H, 0, j));
            sp_fill_up(m, s, j, H);
            k->cq[j] = q[j];
            k->pert_j = -1;
        }
    }
    memcpy(k->cF, k->bF, 6 * (size_t)m->n_subs * sizeof(sp_cx));
    k->cached = 0;
}
