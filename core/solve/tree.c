/*
 * tree.c — the linearised equations in block form along the frame tree, so
 * that time and memory grow linearly with the number of frames (issue 14).
 *
 * Why.  In the modal coordinates q every Jacobian J_k = dr_k/dq is dense
 * (a node depends on all the frames above it), so M*, C*, K* and the Newton
 * tangent are dense n x n, and the dense path costs O(n^3) time and O(n^2)
 * memory (768 elements: 12.8 s, 563 MB).  Profile of that path: the dense LU
 * of the Newton tangent, its assembly (dsyrk for M*, the Jtha Jth' dgemm of
 * frames_hessian: both O(n^2 n_mp)), the condensation and the Hermitian
 * eigen-solve, and the n x 3 n_nodes Jacobians of frames_eval.
 *
 * How.  Let y_s = (R_s, theta_s) be the pose of frame s.  The chain of
 * eq. 36 is linear in its increments:
 *     dy_c = T_c dy_p + D_c dq_p,   T_c = [I2, A'(th_p) w_e; 0, 1],
 *     D_c = [A(th_p) N_e; Nphi_e]                    (c child of p at node e)
 * and a mass point p of s moves by dr_p = [I2, A' w_p] dy_s + A N_p dq_s.
 * So every matrix of the linearisation is a sum over substructures of a small
 * local block on (dy_s, dq_s), of size 3 + m_s:
 *     M* = sum_s Y_s' Ml_s Y_s,  Ml_s = sum_p m_p Jl_p' Jl_p,  Jl_p = [G_p, A N_p]
 *     C* = 2 Omega sum_s Y_s' Cl_s Y_s,  Cl_s = sum_p m_p Jl_p' S Jl_p
 *     K* (or the Newton tangent) = sum_s Y_s' Kl_s Y_s,
 *         Kl_s = -Omega^2 (Ml_s + Hl_s) + [0 0; 0 K_s + Kg_s]
 * with Y_s = [dy_s/dq; E_s] and Hl_s the second-derivative term of
 * frames_hessian (a_s on theta-theta, g_s on theta-q_s).  Writing u = dy/dq x
 * (a forward recursion root to leaves) and w for the multipliers of the chain
 * equations, K x = b is the sparse system
 *     [ Kqq   Kqy   -D' ] [x]   [b]
 *     [ Kyq   Kyy  Lam' ] [u] = [0],   Lam = I - T (unit block lower triangular)
 *     [ -D    Lam    0  ] [w]   [0]
 * whose graph is the frame tree.  It is eliminated leaves first, one front
 * of size m_s + 6 per frame (x_s, u_s, w_s), no fill: the Schur complement
 * of a child touches only its parent's front, through the 3 rows of w_c.
 * Symmetric K*: Bunch-Kaufman fronts (dsytrf), and Sylvester's law gives the
 * inertia of K* = inertia of the system minus (3S, 3S) (the (u, w) part is a
 * nonsingular saddle point).  Newton tangent (not symmetric): LU fronts, and
 * sign det K = (-1)^(3S) prod sign det(front).  Products with M*, C*, K* are
 * a forward recursion, local blocks and the adjoint recursion: O(n).
 *
 * Eigen-analysis (tree_eig).  Shift-invert at 0 of the gyroscopic problem:
 * with z = [x; lambda x], mu = 1/lambda is an eigenvalue of
 *     A = [ -K^-1 C   -K^-1 M ]
 *         [    I          0   ]
 * (the massless directions give mu = 0: harmless).  Arnoldi with full
 * reorthogonalisation builds a Krylov basis; the x-parts span a subspace V
 * onto which the quadratic problem is projected (V'MV, V'CV, V'KV keep the
 * structure: symmetric, skew, symmetric), and the small projected problem is
 * solved by the dense eig_solve of eigen.c (null-space condensation, the
 * Hermitian form).  For K* positive definite this is a Rayleigh-Ritz step of
 * a Hermitian-definite pencil: the Ritz frequencies approach the lowest ones
 * from above.  The basis grows until every requested mode has a residual
 * ||(lambda^2 M + lambda C + K) x|| below TREE_EIG_TOL relative to its terms.
 * When K* is not positive definite (an unstable steady state: the dense path
 * reports Re(lambda) over all roots) or the iteration does not converge, the
 * caller falls back to the dense path.
 *
 * Cost per frame: O((m_s + 6)^3) for a factorisation, O((m_s + 6)^2) per
 * product or solve; memory O(sum (m_s + 6)^2).  For a single frame this is
 * the dense cost again: the automatic choice (tree_use) keeps the dense path
 * for small models and large frames.
 */
#include "kind.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Automatic choice: tree path from this many coordinates on (below, the dense path is as
 * fast: 192 elements take ~30 ms either way), for frames of at most TREE_MAX_FRAME_M coordinates. */
#define TREE_AUTO_MIN_N 200
#define TREE_MAX_FRAME_M 40
/* Eigen: relative residual that accepts a mode, and the largest Krylov basis. */
#define TREE_EIG_TOL 1e-11
#define TREE_EIG_MAX_BASIS 240

int tree_choose(int solver, int n, int max_m, int modes)
{
    if (solver == SM_SOLVER_DENSE)
        return 0;
    if (solver == SM_SOLVER_TREE)
        return 1;
    return n >= TREE_AUTO_MIN_N && max_m <= TREE_MAX_FRAME_M && 8 * modes <= n && modes <= SM_TREE_MAX_MODES;
}

int tree_use(const sm_model *m)
{
    int mx = 0;
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
    free(t->X);
    free(t->ipiv);
    free(t->lk);
    free(t->D);
    free(t->d_off);
    free(t->z);
    free(t->u);
    free(t->v);
    free(t->work);
    memset(t, 0, sizeof *t);
}

int tree_alloc(const sm_model *m, tree_ws *t)
{
    int S = m->n_subs, mx = 1, d = m->kind->pose_dof;
    memset(t, 0, sizeof *t);
    t->S = S;
    t->n = m->n;
    t->d = d;
    t->mp_ptr = calloc((size_t)S + 1, sizeof(int));
    t->mp_idx = calloc((size_t)(m->n_mp ? m->n_mp : 1), sizeof(int));
    t->loc_off = calloc((size_t)S + 1, sizeof(size_t));
    t->fr_off = calloc((size_t)S + 1, sizeof(size_t));
    t->v_off = calloc((size_t)S + 1, sizeof(size_t));
    t->d_off = calloc((size_t)S + 1, sizeof(size_t));
    if (!t->mp_ptr || !t->mp_idx || !t->loc_off || !t->fr_off || !t->v_off || !t->d_off)
        goto fail;
    for (int s = 0; s < S; s++) {
        size_t l = (size_t)d + m->subs[s].m, nb = 2 * (size_t)d + m->subs[s].m;
        int p = m->subs[s].parent;
        mx = m->subs[s].m > mx ? m->subs[s].m : mx;
        t->loc_off[s + 1] = t->loc_off[s] + l * l;
        t->fr_off[s + 1] = t->fr_off[s] + nb * nb;
        t->v_off[s + 1] = t->v_off[s] + nb;
        t->d_off[s + 1] = t->d_off[s] + (d == 6 && p >= 0 ? 6 * (size_t)m->subs[p].m : 0);
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
    t->z = dm_vec(V);
    t->u = dm_vec((size_t)d * S);
    t->v = dm_vec((size_t)d * S);
    t->work = dm_vec(4 * (size_t)mx + 2 * (size_t)(mx + 2 * d) * (mx + 2 * d) + 64);
    if (!t->Kl || !t->Ml || !t->Cl || !t->F || !t->X || !t->ipiv || !t->lk || !t->D || !t->z || !t->u ||
        !t->v || !t->work)
        goto fail;
    return SM_OK;
fail:
    tree_free(t);
    return SM_NOMEM;
}

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

/* Spatial forward step: u_s = T_s u_p + D_s x_p, T_s u = (dR + dtheta x a, dtheta). */
static void tree_forward6(const sm_model *m, const tree_ws *t, int s, const double *x, double *u)
{
    const sm_sub *b = &m->subs[s], *p = &m->subs[b->parent];
    const double *up = u + 6 * b->parent, *a = t->lk + 3 * s, *D = t->D + t->d_off[s], *xp = x + p->q0;
    double *us = u + 6 * s;
    us[0] = up[0] + up[4] * a[2] - up[5] * a[1];
    us[1] = up[1] + up[5] * a[0] - up[3] * a[2];
    us[2] = up[2] + up[3] * a[1] - up[4] * a[0];
    us[3] = up[3];
    us[4] = up[4];
    us[5] = up[5];
    for (int j = 0; j < p->m; j++)
        for (int i = 0; i < 6; i++)
            us[i] += D[6 * j + i] * xp[j];
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
    for (int j = 0; j < p->m; j++) {
        double acc = 0;
        for (int i = 0; i < 6; i++)
            acc += D[6 * j + i] * vs[i];
        yp[j] += acc;
    }
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
static void tree_adjoint(const sm_model *m, const tree_ws *t, double *v, double *y)
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
            yp[j] += DM(&p->N, 3 * a, j) * f0 + DM(&p->N, 3 * a + 1, j) * f1 + DM(&p->N, 3 * a + 2, j) * vs[2];
    }
}

/* Jl = [G, A N] (2 x (3+m), column-major ld 2) of a point at local position w with rows N. */
static void tree_point_jac(double c, double si, const double *w, const double *N, int ldn, int mm, double *Jl)
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
static double tree_hessian_sub(const sm_model *m, const sm_kin *k, const tree_ws *t, int s, double *gs)
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

int tree_assemble(const sm_model *m, const double *q, sm_kin *k, double s2, int frozen, int gyro, tree_ws *t)
{
    tree_links(m, k, t);
    memset(k->fext, 0, 2 * (size_t)m->n_nodes * sizeof(double));
    double *Jl = t->work, *gs = t->work + 2 * (3 + t->max_m), *gw = gs + t->max_m;
    int finite = 1;
    for (int s = m->n_subs - 1; s >= 0; s--) { /* leaves first: subtree forces for the Hessian */
        const sm_sub *b = &m->subs[s];
        int l = 3 + b->m;
        double c = cos(k->theta[s]), si = sin(k->theta[s]);
        double *Ml = t->Ml + t->loc_off[s], *Cl = t->Cl + t->loc_off[s], *Kl = t->Kl + t->loc_off[s];
        memset(Ml, 0, (size_t)l * l * sizeof(double));
        memset(Cl, 0, (size_t)l * l * sizeof(double));
        for (int i = t->mp_ptr[s]; i < t->mp_ptr[s + 1]; i++) {
            const sm_mpoint *mp = &m->mp[t->mp_idx[i]];
            tree_point_jac(c, si, k->wp + 2 * t->mp_idx[i], mp->N, mp->ldn, b->m, Jl);
            /* Ml += m Jl' Jl;  Cl += m Jl' S Jl, S Jl = [-Jl_y; Jl_x] */
            for (int j = 0; j < l; j++)
                for (int r = 0; r < l; r++) {
                    Ml[(size_t)j * l + r] += mp->mass * (Jl[2 * r] * Jl[2 * j] + Jl[2 * r + 1] * Jl[2 * j + 1]);
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

/* Front of s before elimination: [Kqq Kqy 0; Kyq Kyy I; 0 I 0] on (x_s, u_s, w_s). */
static void tree_front_init(const sm_model *m, tree_ws *t, int s)
{
    int d = t->d, mm = m->subs[s].m, l = d + mm, nb = mm + 2 * d;
    double *F = t->F + t->fr_off[s];
    const double *Kl = t->Kl + t->loc_off[s];
    memset(F, 0, (size_t)nb * nb * sizeof(double));
    for (int j = 0; j < l; j++) /* local order (y, q) -> front order (x, u) */
        for (int i = 0; i < l; i++) {
            int fi = i < d ? mm + i : i - d, fj = j < d ? mm + j : j - d;
            F[(size_t)fj * nb + fi] = Kl[(size_t)j * l + i];
        }
    for (int i = 0; i < d; i++) {
        F[(size_t)(mm + d + i) * nb + mm + i] = 1.0;
        F[(size_t)(mm + i) * nb + mm + d + i] = 1.0;
    }
}

/* Spatial C_s = [-D_s, -T_s, 0] (6 x nb_p, ld 6). */
static void tree_coupling6(const sm_model *m, const tree_ws *t, int s, double *C)
{
    const sm_sub *b = &m->subs[s], *p = &m->subs[b->parent];
    const double *a = t->lk + 3 * s, *D = t->D + t->d_off[s];
    int mp = p->m;
    memset(C, 0, 6 * (size_t)(mp + 12) * sizeof(double));
    for (size_t i = 0; i < 6 * (size_t)mp; i++)
        C[i] = -D[i];
    double *Ct = C + 6 * (size_t)mp; /* -T = -[I -skew(a); 0 I] */
    for (int i = 0; i < 6; i++)
        Ct[6 * i + i] = -1.0;
    Ct[6 * 3 + 1] = a[2], Ct[6 * 3 + 2] = -a[1];
    Ct[6 * 4 + 0] = -a[2], Ct[6 * 4 + 2] = a[0];
    Ct[6 * 5 + 0] = a[1], Ct[6 * 5 + 1] = -a[0];
}

/* C_s = [-D_s, -T_s, 0] (d x nb_p, column-major ld d) coupling child s to its parent's front. */
static void tree_coupling(const sm_model *m, const tree_ws *t, int s, double *C)
{
    if (t->d == 6) {
        tree_coupling6(m, t, s, C);
        return;
    }
    const sm_sub *b = &m->subs[s], *p = &m->subs[b->parent];
    const double *lk = t->lk + 4 * s;
    int a = b->attach_local, mp = p->m;
    memset(C, 0, 3 * (size_t)(mp + 6) * sizeof(double));
    for (int j = 0; j < mp; j++) {
        double n0 = DM(&p->N, 3 * a, j), n1 = DM(&p->N, 3 * a + 1, j);
        C[3 * j] = -(lk[0] * n0 - lk[1] * n1);
        C[3 * j + 1] = -(lk[1] * n0 + lk[0] * n1);
        C[3 * j + 2] = -DM(&p->N, 3 * a + 2, j);
    }
    double T[9] = {1, 0, 0, 0, 1, 0, lk[2], lk[3], 1}; /* column-major */
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            C[3 * (mp + j) + i] = -T[3 * j + i];
}

/* Negative eigenvalues of a dsytrf-factored n x n matrix (eig_inertia's count). */
static int tree_neg(int n, const double *A, const int *ipiv)
{
    int neg = 0;
    for (int k = 0; k < n; k++) {
        double a = A[(size_t)k * n + k];
        if (ipiv[k] > 0 || k + 1 == n) {
            neg += a < 0;
        } else {
            double b = A[(size_t)k * n + k + 1], c = A[(size_t)(k + 1) * n + k + 1];
            double det = a * c - b * b;
            neg += det < 0 ? 1 : (a < 0 ? 2 : 0);
            k++;
        }
    }
    return neg;
}

/* Solve front s in place for nrhs columns (ld nb). */
static int tree_front_solve(const tree_ws *t, int s, int nb, int nrhs, double *B)
{
    const double *F = t->F + t->fr_off[s];
    const int *ip = t->ipiv + t->v_off[s];
    int info = t->sym ? LAPACKE_dsytrs_work(LAPACK_COL_MAJOR, 'L', nb, nrhs, F, nb, ip, B, nb)
                      : LAPACKE_dgetrs_work(LAPACK_COL_MAJOR, 'N', nb, nrhs, F, nb, ip, B, nb);
    return dm_lapack_status(info, SM_LAPACK_FAILED);
}

int tree_factor(const sm_model *m, tree_ws *t, int sym)
{
    int S = m->n_subs, d = t->d, neg = 0, sign = (d * S) % 2 ? -1 : 1, rc;
    double *C = t->work, *W = C + (size_t)d * (t->max_m + 2 * d);
    t->sym = sym;
    t->neg = 0;
    for (int s = 0; s < S; s++)
        tree_front_init(m, t, s);
    for (int s = S - 1; s >= 0; s--) {
        int mm = m->subs[s].m, nb = mm + 2 * d;
        double *F = t->F + t->fr_off[s], *X = t->X + (size_t)d * t->v_off[s];
        int *ip = t->ipiv + t->v_off[s];
        if (sym) {
            int lw = nb * 64;
            double *wk = malloc((size_t)lw * sizeof(double));
            if (!wk)
                return SM_NOMEM;
            int info = LAPACKE_dsytrf_work(LAPACK_COL_MAJOR, 'L', nb, F, nb, ip, wk, lw);
            free(wk);
            if ((rc = dm_lapack_status(info, SM_SINGULAR)) < 0)
                return rc;
            neg += tree_neg(nb, F, ip);
        } else {
            if ((rc = dm_lapack_status(LAPACKE_dgetrf_work(LAPACK_COL_MAJOR, nb, nb, F, nb, ip), SM_SINGULAR)) < 0)
                return rc;
            for (int i = 0; i < nb; i++) {
                if (F[(size_t)i * nb + i] < 0)
                    sign = -sign;
                if (ip[i] != i + 1)
                    sign = -sign;
            }
        }
        /* X_s = F_s^-1 E_w */
        memset(X, 0, (size_t)d * nb * sizeof(double));
        for (int i = 0; i < d; i++)
            X[(size_t)i * nb + mm + d + i] = 1.0;
        if ((rc = tree_front_solve(t, s, nb, d, X)) < 0)
            return rc;
        const sm_sub *b = &m->subs[s];
        if (b->parent < 0)
            continue;
        /* F_p -= C' Z C,  Z = (F_s^-1)_ww = rows w of X */
        int mp = m->subs[b->parent].m, nbp = mp + 2 * d, nc = mp + d;
        double *Fp = t->F + t->fr_off[b->parent];
        tree_coupling(m, t, s, C);
        for (int j = 0; j < nc; j++) /* W = Z C (d x nc) */
            for (int i = 0; i < d; i++) {
                double acc = 0;
                for (int r = 0; r < d; r++)
                    acc += X[(size_t)r * nb + mm + d + i] * C[d * j + r];
                W[d * j + i] = acc;
            }
        for (int j = 0; j < nc; j++)
            for (int i = 0; i < nc; i++) {
                double acc = C[d * i] * W[d * j];
                for (int r = 1; r < d; r++)
                    acc += C[d * i + r] * W[d * j + r];
                Fp[(size_t)j * nbp + i] -= acc;
            }
    }
    t->neg = neg - d * S;
    t->det_sign = sign;
    return SM_OK;
}

int tree_solve(const sm_model *m, tree_ws *t, double *x)
{
    int S = m->n_subs, d = t->d, rc;
    double *C = t->work;
    for (int s = 0; s < S; s++) { /* right-hand sides [b_s; 0; 0] */
        double *zs = t->z + t->v_off[s];
        int mm = m->subs[s].m;
        memcpy(zs, x + m->subs[s].q0, (size_t)mm * sizeof(double));
        memset(zs + mm, 0, 2 * (size_t)d * sizeof(double));
    }
    for (int s = S - 1; s >= 0; s--) { /* forward: y_s = F_s^-1 r_s; r_p -= C' y_s,w */
        const sm_sub *b = &m->subs[s];
        int mm = b->m, nb = mm + 2 * d;
        double *zs = t->z + t->v_off[s];
        if ((rc = tree_front_solve(t, s, nb, 1, zs)) < 0)
            return rc;
        if (b->parent < 0)
            continue;
        int nc = m->subs[b->parent].m + d;
        double *zp = t->z + t->v_off[b->parent], *yw = zs + mm + d;
        tree_coupling(m, t, s, C);
        for (int j = 0; j < nc; j++) {
            double acc = C[d * j] * yw[0];
            for (int r = 1; r < d; r++)
                acc += C[d * j + r] * yw[r];
            zp[j] -= acc;
        }
    }
    for (int s = 0; s < S; s++) { /* back: z_s = y_s - X_s (C z_p) */
        const sm_sub *b = &m->subs[s];
        int mm = b->m, nb = mm + 2 * d;
        double *zs = t->z + t->v_off[s];
        if (b->parent >= 0) {
            int nc = m->subs[b->parent].m + d;
            const double *zp = t->z + t->v_off[b->parent], *X = t->X + (size_t)d * t->v_off[s];
            double cz[6] = {0, 0, 0, 0, 0, 0};
            tree_coupling(m, t, s, C);
            for (int j = 0; j < nc; j++)
                for (int i = 0; i < d; i++)
                    cz[i] += C[d * j + i] * zp[j];
            for (int r = 0; r < nb; r++) {
                double acc = X[r] * cz[0];
                for (int i = 1; i < d; i++)
                    acc += X[(size_t)i * nb + r] * cz[i];
                zs[r] -= acc;
            }
        }
        memcpy(x + b->q0, zs, (size_t)mm * sizeof(double));
    }
    return SM_OK;
}

void tree_apply(const sm_model *m, tree_ws *t, int which, const double *x, double *y)
{
    const double *L = which == TREE_K ? t->Kl : which == TREE_M ? t->Ml : t->Cl;
    double scale = which == TREE_C ? 2.0 * t->omega : 1.0;
    int d = t->d;
    double *in = t->work, *out = t->work + d + t->max_m;
    tree_forward(m, t, x, t->u);
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        int l = d + b->m;
        const double *Ls = L + t->loc_off[s];
        memcpy(in, t->u + (size_t)d * s, (size_t)d * sizeof(double));
        memcpy(in + d, x + b->q0, (size_t)b->m * sizeof(double));
        for (int i = 0; i < l; i++)
            out[i] = 0;
        for (int j = 0; j < l; j++)
            for (int i = 0; i < l; i++)
                out[i] += Ls[(size_t)j * l + i] * in[j];
        for (int i = 0; i < d; i++)
            t->v[(size_t)d * s + i] = scale * out[i];
        for (int i = 0; i < b->m; i++)
            y[b->q0 + i] = scale * out[d + i];
    }
    tree_adjoint(m, t, t->v, y);
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
