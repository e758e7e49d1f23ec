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

/* Eigen: relative residual that accepts a mode, and the largest Krylov basis. */
#define TREE_EIG_TOL 1e-11
#define TREE_EIG_MAX_BASIS 240

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

/* Spatial C_s = [-D_s, -T_s] (6 x (m_p + 6), ld 6; the zero block of w_p is not stored). */
static void tree_coupling6(const sm_model *m, const tree_ws *t, int s, double *C)
{
    const sm_sub *b = &m->subs[s], *p = &m->subs[b->parent];
    const double *a = t->lk + 3 * s, *D = t->D + t->d_off[s];
    int mp = p->m;
    memset(C, 0, 6 * (size_t)(mp + 6) * sizeof(double));
    for (size_t i = 0; i < 6 * (size_t)mp; i++)
        C[i] = -D[i];
    double *Ct = C + 6 * (size_t)mp; /* -T = -[I -skew(a); 0 I] */
    for (int i = 0; i < 6; i++)
        Ct[6 * i + i] = -1.0;
    Ct[6 * 3 + 1] = a[2], Ct[6 * 3 + 2] = -a[1];
    Ct[6 * 4 + 0] = -a[2], Ct[6 * 4 + 2] = a[0];
    Ct[6 * 5 + 0] = a[1], Ct[6 * 5 + 1] = -a[0];
}

/* C_s = [-D_s, -T_s] (d x (m_p + d), column-major ld d) coupling child s to its parent's front
 * (its zero block on the parent's w_p is not stored: nothing reads it). */
static void tree_coupling(const sm_model *m, const tree_ws *t, int s, double *C)
{
    if (t->d == 6) {
        tree_coupling6(m, t, s, C);
        return;
    }
    const sm_sub *b = &m->subs[s], *p = &m->subs[b->parent];
    const double *lk = t->lk + 4 * s;
    int a = b->attach_local, mp = p->m;
    memset(C, 0, 3 * (size_t)(mp + 3) * sizeof(double));
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

/*
 * x = A^-1 b in place for the Bunch-Kaufman factors of dsytrf ('L', 1-based ipiv), one column:
 * LAPACK's dsytrs step for step, written out.  Fronts are 18 x 18 for a spatial frame of 6
 * modes, where dsytrs's 17 dger and 17 dgemv calls cost 13 400 instructions a solve, mostly
 * per-call overhead: 32 % of a 288-coordinate spatial sweep (issue 27).  The sums run in another
 * order than OpenBLAS's kernels, so the last bits differ: fixed_bits (planar) fronts keep dsytrs (their
 * results are fixed to the byte), spatial fronts take this one (tree_front_solve).
 */
static inline void tree_sytrs_ln(int n, const double *restrict A, const int *restrict ip,
                                 double *restrict b)
{
    for (int k = 0; k < n;) { /* L D y = P b, leading column first */
        const double *ak = A + (size_t)k * n;
        if (ip[k] > 0) {
            int kp = ip[k] - 1;
            double t = b[k];
            b[k] = b[kp], b[kp] = t;
            double bk = b[k];
            for (int i = k + 1; i < n; i++)
                b[i] -= ak[i] * bk;
            b[k] = bk * (1.0 / ak[k]);
            k++;
        } else {
            const double *ak1 = ak + n;
            int kp = -ip[k] - 1;
            double t = b[k + 1];
            b[k + 1] = b[kp], b[kp] = t;
            double b0 = b[k], b1 = b[k + 1];
            for (int i = k + 2; i < n; i++)
                b[i] = (b[i] - ak[i] * b0) - ak1[i] * b1;
            double akm1k = ak[k + 1], akm1 = ak[k] / akm1k, akk = ak1[k + 1] / akm1k,
                   den = akm1 * akk - 1.0;
            double bkm1 = b0 / akm1k, bkk = b1 / akm1k;
            b[k] = (akk * bkm1 - bkk) / den;
            b[k + 1] = (akm1 * bkk - bkm1) / den;
            k += 2;
        }
    }
    for (int k = n - 1; k >= 0;) { /* L' x = y, then P' x, trailing column first */
        const double *ak = A + (size_t)k * n;
        double acc = 0;
        for (int i = k + 1; i < n; i++)
            acc += ak[i] * b[i];
        b[k] -= acc;
        if (ip[k] > 0) {
            int kp = ip[k] - 1;
            double t = b[k];
            b[k] = b[kp], b[kp] = t;
            k--;
        } else {
            const double *ak1 = ak - n;
            double acc1 = 0;
            for (int i = k + 1; i < n; i++)
                acc1 += ak1[i] * b[i];
            b[k - 1] -= acc1;
            int kp = -ip[k] - 1;
            double t = b[k];
            b[k] = b[kp], b[kp] = t;
            k -= 2;
        }
    }
}

/*
 * Z = F^-1 (n x n, column-major) from the Bunch-Kaufman factors of dsytrf ('L', 1-based ipiv) in
 * A: the steps of tree_sytrs_ln on the n columns of the identity at once, rows of the row-major
 * scratch W (n x n) as the unit of work, so that each step is a vectorised row operation instead
 * of n scalar ones.  Spatial symmetric fronts (tree_factor) keep Z, and a solve with the front is
 * then the product Z b (tree_front_solve): 324 multiply-adds in vector registers for an 18 x 18
 * front instead of two triangular sweeps with pivots (issue 27).
 */
static inline void tree_sytri_ln(int n, const double *restrict A, const int *restrict ip,
                                 double *restrict W, double *restrict Z)
{
    for (int i = 0; i < n; i++)
        for (int r = 0; r < n; r++)
            W[i * n + r] = i == r;
    for (int k = 0; k < n;) { /* L D Y = P I */
        const double *ak = A + (size_t)k * n;
        double *wk = W + k * n;
        if (ip[k] > 0) {
            int kp = ip[k] - 1;
            double *wp = W + kp * n;
            for (int r = 0; r < n; r++) {
                double t = wk[r];
                wk[r] = wp[r], wp[r] = t;
            }
            for (int i = k + 1; i < n; i++) {
                double a = ak[i], *wi = W + i * n;
                for (int r = 0; r < n; r++)
                    wi[r] -= a * wk[r];
            }
            double d = 1.0 / ak[k];
            for (int r = 0; r < n; r++)
                wk[r] *= d;
            k++;
        } else {
            const double *ak1 = ak + n;
            double *wk1 = wk + n, *wp = W + (-ip[k] - 1) * n;
            for (int r = 0; r < n; r++) {
                double t = wk1[r];
                wk1[r] = wp[r], wp[r] = t;
            }
            for (int i = k + 2; i < n; i++) {
                double a0 = ak[i], a1 = ak1[i], *wi = W + i * n;
                for (int r = 0; r < n; r++)
                    wi[r] = (wi[r] - a0 * wk[r]) - a1 * wk1[r];
            }
            double akm1k = ak[k + 1], akm1 = ak[k] / akm1k, akk = ak1[k + 1] / akm1k,
                   den = akm1 * akk - 1.0;
            for (int r = 0; r < n; r++) {
                double bkm1 = wk[r] / akm1k, bkk = wk1[r] / akm1k;
                wk[r] = (akk * bkm1 - bkk) / den;
                wk1[r] = (akm1 * bkk - bkm1) / den;
            }
            k += 2;
        }
    }
    for (int k = n - 1; k >= 0;) { /* L' X = Y, then P' X */
        const double *ak = A + (size_t)k * n;
        double *wk = W + k * n;
        for (int i = k + 1; i < n; i++) {
            double a = ak[i];
            const double *wi = W + i * n;
            for (int r = 0; r < n; r++)
                wk[r] -= a * wi[r];
        }
        if (ip[k] > 0) {
            double *wp = W + (ip[k] - 1) * n;
            for (int r = 0; r < n; r++) {
                double t = wk[r];
                wk[r] = wp[r], wp[r] = t;
            }
            k--;
        } else {
            const double *ak1 = ak - n;
            double *wk1 = wk - n, *wp = W + (-ip[k] - 1) * n;
            for (int i = k + 1; i < n; i++) {
                double a = ak1[i];
                const double *wi = W + i * n;
                for (int r = 0; r < n; r++)
                    wk1[r] -= a * wi[r];
            }
            for (int r = 0; r < n; r++) {
                double t = wk[r];
                wk[r] = wp[r], wp[r] = t;
            }
            k -= 2;
        }
    }
    for (int i = 0; i < n; i++) /* W holds Z row by row */
        for (int r = 0; r < n; r++)
            Z[(size_t)r * n + i] = W[i * n + r];
}

/* tree_sytri_ln with a spatial one-element frame's size as a constant (tree_sytrs_l). */
static void tree_sytri(int n, const double *A, const int *ip, double *W, double *Z)
{
    if (n == 18)
        tree_sytri_ln(18, A, ip, W, Z);
    else
        tree_sytri_ln(n, A, ip, W, Z);
}

/* Fronts up to this size keep their inverse (spatial symmetric fronts; larger ones solve with
 * the factors). */
#define TREE_ZMAX 64

/* y = A x for A n x n (column-major), each y[i] the sum over j in order: a spatial front's
 * solve with its inverse (tree_front_solve) and tree_apply's local product. */
static inline void tree_matvec(int n, const double *restrict A, const double *restrict x,
                               double *restrict y)
{
    for (int i = 0; i < n; i++)
        y[i] = 0;
    for (int j = 0; j < n; j++) {
        const double *restrict aj = A + (size_t)j * n;
        double xj = x[j];
        for (int i = 0; i < n; i++)
            y[i] += aj[i] * xj;
    }
}

/* tree_sytrs_ln for one front; a spatial one-element frame's front (6 own + 2 x 6 pose
 * coordinates) with its size a constant, so that the compiler drops the run-time loop bounds:
 * the same operations in the same order (issue 27). */
static void tree_sytrs_l(int n, const double *A, const int *ip, double *b)
{
    if (n == 18)
        tree_sytrs_ln(18, A, ip, b);
    else
        tree_sytrs_ln(n, A, ip, b);
}

/*
 * LU with partial pivoting of A (n x n, column-major) in place, LAPACK's dgetf2 written out
 * (1-based ipiv, the first largest |pivot|): the Newton tangent's spatial fronts, where OpenBLAS's
 * dgetrf and dgetrs cost ~30 000 instructions a front, mostly per-call overhead (issue 27; planar
 * fronts keep LAPACK and their bytes).  SM_OK, or SM_SINGULAR at an exactly zero pivot.
 */
static int tree_getrf(int n, double *A, int *ip)
{
    for (int k = 0; k < n; k++) {
        double *ak = A + (size_t)k * n, big = fabs(ak[k]);
        int p = k;
        for (int i = k + 1; i < n; i++)
            if (fabs(ak[i]) > big)
                big = fabs(ak[i]), p = i;
        ip[k] = p + 1;
        if (ak[p] == 0)
            return SM_SINGULAR;
        if (p != k)
            for (int j = 0; j < n; j++) {
                double t = A[(size_t)j * n + k];
                A[(size_t)j * n + k] = A[(size_t)j * n + p], A[(size_t)j * n + p] = t;
            }
        double r = 1.0 / ak[k];
        for (int i = k + 1; i < n; i++)
            ak[i] *= r;
        for (int j = k + 1; j < n; j++) {
            double *aj = A + (size_t)j * n, a = aj[k];
            if (a != 0)
                for (int i = k + 1; i < n; i++)
                    aj[i] -= ak[i] * a;
        }
    }
    return SM_OK;
}

/* x = A^-1 b in place for the factors of tree_getrf, one column. */
static void tree_getrs(int n, const double *A, const int *ip, double *b)
{
    for (int k = 0; k < n; k++) {
        int p = ip[k] - 1;
        double t = b[k];
        b[k] = b[p], b[p] = t;
    }
    for (int k = 0; k < n; k++) { /* L y = P b, L unit lower */
        const double *ak = A + (size_t)k * n;
        double bk = b[k];
        if (bk != 0)
            for (int i = k + 1; i < n; i++)
                b[i] -= ak[i] * bk;
    }
    for (int k = n - 1; k >= 0; k--) { /* U x = y */
        const double *ak = A + (size_t)k * n;
        double bk = b[k] / ak[k];
        b[k] = bk;
        if (bk != 0)
            for (int i = 0; i < k; i++)
                b[i] -= ak[i] * bk;
    }
}

/* Solve front s in place for nrhs columns (ld nb). */
static int tree_front_solve(const tree_ws *t, int s, int nb, int nrhs, double *B)
{
    const double *F = t->F + t->fr_off[s];
    const int *ip = t->ipiv + t->v_off[s];
    if (t->sym && t->Finv && nrhs == 1 && nb <= TREE_ZMAX) { /* spatial: the inverse's product */
        double tmp[TREE_ZMAX];
        const double *Z = t->Finv + t->fr_off[s];
        if (nb == 18)
            tree_matvec(18, Z, B, tmp);
        else
            tree_matvec(nb, Z, B, tmp);
        memcpy(B, tmp, (size_t)nb * sizeof(double));
        return SM_OK;
    }
    if (!t->fixed_bits) {
        for (int j = 0; j < nrhs; j++)
            if (t->sym)
                tree_sytrs_l(nb, F, ip, B + (size_t)j * nb);
            else
                tree_getrs(nb, F, ip, B + (size_t)j * nb);
        return SM_OK;
    }
    int info = t->sym ? LAPACKE_dsytrs_work(LAPACK_COL_MAJOR, 'L', nb, nrhs, F, nb, ip, B, nb)
                      : LAPACKE_dgetrs_work(LAPACK_COL_MAJOR, 'N', nb, nrhs, F, nb, ip, B, nb);
    return dm_lapack_status(info, SM_LAPACK_FAILED);
}

/* tree_factor with the pose size d a parameter (the constant 6 for a spatial model, as
 * tree_solve_d: the Schur updates' loops of length d unroll, each sum in the same order). */
static inline int tree_factor_fronts(const sm_model *m, tree_ws *t, int sym, int d, double *Wz)
{
    int S = m->n_subs, neg = 0, sign = (d * S) % 2 ? -1 : 1, rc;
    double *W = t->work;
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
            neg += dm_sytrf_negative(nb, F, ip);
            if (Wz && nb <= TREE_ZMAX)
                tree_sytri(nb, F, ip, Wz, t->Finv + t->fr_off[s]);
        } else {
            rc = !t->fixed_bits
                     ? tree_getrf(nb, F, ip)
                     : dm_lapack_status(LAPACKE_dgetrf_work(LAPACK_COL_MAJOR, nb, nb, F, nb, ip),
                                        SM_SINGULAR);
            if (rc < 0)
                return rc;
            for (int i = 0; i < nb; i++) {
                if (F[(size_t)i * nb + i] < 0)
                    sign = -sign;
                if (ip[i] != i + 1)
                    sign = -sign;
            }
        }
        /* X_s = F_s^-1 E_w: the w columns of the inverse where it is kept, else solved */
        if (sym && Wz && nb <= TREE_ZMAX) {
            memcpy(X, t->Finv + t->fr_off[s] + (size_t)(mm + d) * nb,
                   (size_t)d * nb * sizeof(double));
        } else {
            memset(X, 0, (size_t)d * nb * sizeof(double));
            for (int i = 0; i < d; i++)
                X[(size_t)i * nb + mm + d + i] = 1.0;
            if ((rc = tree_front_solve(t, s, nb, d, X)) < 0)
                return rc;
        }
        const sm_sub *b = &m->subs[s];
        if (b->parent < 0)
            continue;
        /* F_p -= C' Z C,  Z = (F_s^-1)_ww = rows w of X */
        int mp = m->subs[b->parent].m, nbp = mp + 2 * d, nc = mp + d;
        double *Fp = t->F + t->fr_off[b->parent], *C = t->Cc + t->c_off[s];
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

/* tree_factor_fronts with Wz, the scratch of tree_sytri, when a spatial model's symmetric fronts
 * keep their inverses (t->Finv; without the memory the solves use the factors). */
static inline int tree_factor_d(const sm_model *m, tree_ws *t, int sym, int d)
{
    double *Wz = NULL;
    if (sym && !t->fixed_bits) {
        if (!t->Finv)
            t->Finv = malloc((t->fr_off[m->n_subs] ? t->fr_off[m->n_subs] : 1) * sizeof(double));
        if (t->Finv)
            Wz = malloc((size_t)TREE_ZMAX * TREE_ZMAX * sizeof(double));
    }
    if (!Wz) {
        free(t->Finv);
        t->Finv = NULL;
    }
    int rc = tree_factor_fronts(m, t, sym, d, Wz);
    free(Wz);
    return rc;
}

int tree_factor(const sm_model *m, tree_ws *t, int sym)
{
    if (t->d == 6)
        return tree_factor_d(m, t, sym, 6);
    return tree_factor_d(m, t, sym, t->d);
}

/* C_s for a solve.  Spatial: the one tree_factor built.  Planar: rebuilt from the current links,
 * as before the cache: the planar kind's residual (tree_centrifugal) updates the links between a
 * Newton tangent's factorisation and its chord solves, which therefore run with the links of the
 * latest iterate; planar results are fixed to the byte (issue 27), so that stays. */
static const double *tree_solve_coupling(const sm_model *m, tree_ws *t, int s)
{
    if (!t->fixed_bits)
        return t->Cc + t->c_off[s];
    tree_coupling(m, t, s, t->work);
    return t->work;
}

/* tree_solve's coupling steps of one frame (d pose coordinates, a parent front's nc = m_p + d
 * rows, the child's front nb): zp -= C' yw going up; zs -= X (C zp) coming down.  Inlined with
 * the sizes of a one-element spatial frame under another (6, 12, 18) as constants, so that the
 * loops unroll: the same sums in the same order (issue 27). */
static inline void tree_couple_up(int nc, int d, const double *restrict C,
                                  const double *restrict yw, double *restrict zp)
{
    for (int j = 0; j < nc; j++) {
        double acc = C[d * j] * yw[0];
        for (int r = 1; r < d; r++)
            acc += C[d * j + r] * yw[r];
        zp[j] -= acc;
    }
}

static inline void tree_couple_down(int nc, int nb, int d, const double *restrict C,
                                    const double *restrict zp, const double *restrict X,
                                    double *restrict zs)
{
    double cz[6] = {0, 0, 0, 0, 0, 0};
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

/* tree_solve with the pose size d a parameter: tree_solve passes the constant 6 for a spatial
 * model, so that the coupling products' loops of length d unroll (the same operations in the
 * same order for either kind: issue 27). */
static inline int tree_solve_d(const sm_model *m, tree_ws *t, double *x, int d)
{
    int S = m->n_subs, rc;
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
        const double *C = tree_solve_coupling(m, t, s);
        if (d == 6 && nc == 12)
            tree_couple_up(12, 6, C, yw, zp);
        else
            tree_couple_up(nc, d, C, yw, zp);
    }
    for (int s = 0; s < S; s++) { /* back: z_s = y_s - X_s (C z_p) */
        const sm_sub *b = &m->subs[s];
        int mm = b->m, nb = mm + 2 * d;
        double *zs = t->z + t->v_off[s];
        if (b->parent >= 0) {
            int nc = m->subs[b->parent].m + d;
            const double *zp = t->z + t->v_off[b->parent], *X = t->X + (size_t)d * t->v_off[s];
            const double *C = tree_solve_coupling(m, t, s);
            if (d == 6 && nc == 12 && nb == 18)
                tree_couple_down(12, 18, 6, C, zp, X, zs);
            else
                tree_couple_down(nc, nb, d, C, zp, X, zs);
        }
        memcpy(x + b->q0, zs, (size_t)mm * sizeof(double));
    }
    return SM_OK;
}

int tree_solve(const sm_model *m, tree_ws *t, double *x)
{
    if (t->d == 6)
        return tree_solve_d(m, t, x, 6);
    return tree_solve_d(m, t, x, t->d);
}

/*
 * The local product of tree_apply for a 12 x 12 block (6 pose and 6 own coordinates: a spatial
 * frame of one element, the frames of a blade's tree path): out = L (u_s; x_s), each out[i] the
 * sum over j = 0..11 in order, as the general loop forms it (the same bits); constant bounds let
 * the compiler keep out in registers instead of a loop of run-time length 12 with its vector
 * prologue and epilogue (issue 27: 6.5 instructions a multiply-add, 15 % of a spatial sweep).
 */
static void tree_local12(const double *restrict Ls, const double *restrict us,
                         const double *restrict xs, double scale, double *restrict vs,
                         double *restrict ys)
{
    double out[12];
    for (int i = 0; i < 12; i++)
        out[i] = 0;
    for (int j = 0; j < 6; j++) {
        const double *restrict Lj = Ls + 12 * j;
        double xj = us[j];
        for (int i = 0; i < 12; i++)
            out[i] += Lj[i] * xj;
    }
    for (int j = 0; j < 6; j++) {
        const double *restrict Lj = Ls + 12 * (6 + j);
        double xj = xs[j];
        for (int i = 0; i < 12; i++)
            out[i] += Lj[i] * xj;
    }
    for (int i = 0; i < 6; i++)
        vs[i] = scale * out[i];
    for (int i = 0; i < 6; i++)
        ys[i] = scale * out[6 + i];
}

/* y = A x for the operator `which` from the pose increments t->u of x (tree_forward's, read only
 * here: several operators share them, tree_apply_n). */
static void tree_apply_u(const sm_model *m, tree_ws *t, int which, const double *x, double *y)
{
    const double *L = which == TREE_K ? t->Kl : which == TREE_M ? t->Ml : t->Cl;
    double scale = which == TREE_C ? 2.0 * t->omega : 1.0;
    int d = t->d;
    /* disjoint halves of the scratch: restrict lets the compiler keep out[] in vector registers
     * (each out[i] is the same sum in the same order: the same bits) */
    double *restrict in = t->work, *restrict out = t->work + d + t->max_m;
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        int l = d + b->m;
        const double *Ls = L + t->loc_off[s];
        if (l == 12 && d == 6) { /* a spatial frame of one element: the same sums, unrolled */
            tree_local12(Ls, t->u + 6 * (size_t)s, x + b->q0, scale, t->v + 6 * (size_t)s,
                         y + b->q0);
            continue;
        }
        memcpy(in, t->u + (size_t)d * s, (size_t)d * sizeof(double));
        memcpy(in + d, x + b->q0, (size_t)b->m * sizeof(double));
        tree_matvec(l, Ls, in, out);
        for (int i = 0; i < d; i++)
            t->v[(size_t)d * s + i] = scale * out[i];
        for (int i = 0; i < b->m; i++)
            y[b->q0 + i] = scale * out[d + i];
    }
    tree_adjoint(m, t, t->v, y);
}

void tree_apply(const sm_model *m, tree_ws *t, int which, const double *x, double *y)
{
    tree_forward(m, t, x, t->u);
    tree_apply_u(m, t, which, x, y);
}

void tree_apply_n(const sm_model *m, tree_ws *t, int n_ops, const int *which, const double *x,
                  double *const *y)
{
    tree_forward(m, t, x, t->u);
    for (int i = 0; i < n_ops; i++)
        tree_apply_u(m, t, which[i], x, y[i]);
}
