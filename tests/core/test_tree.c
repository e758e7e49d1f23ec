/*
 * test_tree.c — the tree-structured linear algebra (core/tree.c) against the
 * dense matrices it replaces, at an arbitrary (non-equilibrium) state q and
 * speed, for several frame schemes, bases and mass models:
 *   tree_apply(K/M/C) x  ==  (K*|tangent, M*, C*) x   (dense, linearize.c)
 *   tree_solve           ==  dense LU solve
 *   tree_centrifugal     ==  frames_centrifugal
 *   tree_nodal           ==  Jn' x
 *   inertia / determinant sign of the tree factorisation == dense.
 * All to 1e-10 relative.
 */
#include "internal.h"

#include "testutil.h"

#include <lapacke.h>

static double rel(const double *a, const double *b, int n)
{
    double d = 0, s = 0;
    for (int i = 0; i < n; i++) {
        d = fmax(d, fabs(a[i] - b[i]));
        s = fmax(s, fabs(b[i]));
    }
    return d / fmax(s, 1e-300);
}

static void dense_mv(const dmat *A, const double *x, double *y)
{
    for (int i = 0; i < A->rows; i++) {
        double t = 0;
        for (int j = 0; j < A->cols; j++)
            t += DM(A, i, j) * x[j];
        y[i] = t;
    }
}

static void check(const char *name, sm_options *o, double omega)
{
    tu_angled ab;
    tu_angled_beam(&ab, 90, 8, 8);
    sm_model *m = NULL;
    sm_diag d;
    if (sm_model_new(&m, &ab.st, o, &d) != SM_OK) {
        TU_CHECK(0, "%s: model: %s", name, d.message);
        return;
    }
    int n = m->n, mx = 1;
    for (int s = 0; s < m->n_subs; s++)
        mx = m->subs[s].m > mx ? m->subs[s].m : mx;
    sm_kin kd, kl;
    tree_ws t;
    dmat K, M, C, H, W, X;
    double *q = dm_vec((size_t)n), *x = dm_vec((size_t)n), *y1 = dm_vec((size_t)n), *y2 = dm_vec((size_t)n);
    double *work = dm_vec((size_t)(4 * mx + n)), *nd = dm_vec(3 * (size_t)m->n_nodes);
    double *nd2 = dm_vec(3 * (size_t)m->n_nodes);
    int *ip = malloc((size_t)n * sizeof(int));
    TU_CHECK(frames_kin_alloc(m, &kd) == SM_OK && frames_kin_alloc_light(m, &kl) == SM_OK &&
                 tree_alloc(m, &t) == SM_OK && dm_alloc(&K, n, n) == SM_OK && dm_alloc(&M, n, n) == SM_OK &&
                 dm_alloc(&C, n, n) == SM_OK && dm_alloc(&H, n, n) == SM_OK &&
                 dm_alloc(&W, n, 2 * m->n_mp) == SM_OK && dm_alloc(&X, n, n) == SM_OK,
             "alloc");
    for (int i = 0; i < n; i++) {
        q[i] = 1e-3 * sin(1.3 * i + 0.2);
        x[i] = cos(0.7 * i) + 0.1 * i / n;
    }
    double s2 = omega * omega;
    frames_eval(m, q, &kd);
    frames_eval(m, q, &kl);
    for (int frozen = 0; frozen <= 1; frozen++) {
        lin_tangent(m, q, &kd, s2, frozen, &K, &M, &H, &W, work);
        lin_gyro(m, &kd, omega, &C, &W, &X);
        if (frozen)
            for (int j = 0; j < n; j++)
                for (int i = 0; i < j; i++)
                    DM(&K, i, j) = DM(&K, j, i) = 0.5 * (DM(&K, i, j) + DM(&K, j, i));
        TU_CHECK(tree_assemble(m, q, &kl, s2, frozen, 1, &t) == 1, "assemble finite");
        const char *lab[3] = {"K", "M", "C"};
        const dmat *D[3] = {&K, &M, &C};
        for (int w = 0; w < 3; w++) {
            tree_apply(m, &t, w, x, y1);
            dense_mv(D[w], x, y2);
            double r = rel(y1, y2, n);
            printf("%s frozen %d: %s x rel diff %.2e\n", name, frozen, lab[w], r);
            TU_CHECK(r < 1e-10, "%s frozen %d: tree %s x", name, frozen, lab[w]);
        }
        /* solve */
        TU_CHECK(tree_factor(m, &t, frozen) == SM_OK, "%s: tree factor", name);
        memcpy(y1, x, (size_t)n * sizeof(double));
        TU_CHECK(tree_solve(m, &t, y1) == SM_OK, "tree solve");
        dense_mv(&K, y1, y2);
        double r = rel(y2, x, n);
        printf("%s frozen %d: K (K^-1 x) - x rel %.2e\n", name, frozen, r);
        TU_CHECK(r < 1e-9, "%s frozen %d: tree solve residual %.2e", name, frozen, r);
        memcpy(X.a, K.a, (size_t)n * n * sizeof(double));
        if (frozen) {
            int neg = 0;
            LAPACKE_dsytrf(LAPACK_COL_MAJOR, 'L', n, X.a, n, ip);
            for (int k2 = 0; k2 < n; k2++) { /* same count as eig_inertia */
                double a = X.a[(size_t)k2 * n + k2];
                if (ip[k2] > 0 || k2 + 1 == n) {
                    neg += a < 0;
                } else {
                    double b = X.a[(size_t)k2 * n + k2 + 1], c = X.a[(size_t)(k2 + 1) * n + k2 + 1];
                    neg += a * c - b * b < 0 ? 1 : (a < 0 ? 2 : 0);
                    k2++;
                }
            }
            printf("%s: negative eigenvalues dense %d tree %d\n", name, neg, t.neg);
            TU_CHECK(neg == t.neg, "%s: inertia", name);
            /* the eigen-analysis: the same modes, or the dense path's turn when K* is indefinite */
            sm_eig_out ed, et;
            int fb = -1, modes = n >= 40 ? 4 : 1;
            TU_CHECK(eig_solve(n, &M, &C, &K, 1, modes, t.fixed_bits, &ed) == SM_OK,
                     "%s: dense eig", name);
            TU_CHECK(eig_solve_tree(m, &t, 1, modes, NULL, &et, &fb) == SM_OK, "%s: tree eig", name);
            if (neg > 0 || 4 * modes > n) {
                TU_CHECK(fb == 1 && et.n_modes == 0 && !et.wim, "%s: indefinite K* or too few coordinates: dense "
                         "fallback, nothing returned", name);
            } else {
                TU_CHECK(fb == 0 && et.n_modes == ed.n_modes, "%s: tree eig converged (%d modes)", name, et.n_modes);
                for (int j = 0; !fb && j < et.n_modes && j < ed.n_modes; j++) {
                    double dw = fabs(et.wim[j] - ed.wim[j]) / ed.wim[j];
                    printf("%s: mode %d w %.12g tree %.12g rel %.1e\n", name, j, ed.wim[j], et.wim[j], dw);
                    TU_CHECK(dw < 1e-9, "%s: mode %d frequency", name, j);
                }
            }
            eig_out_free(&ed);
            eig_out_free(&et);
        } else {
            LAPACKE_dgetrf(LAPACK_COL_MAJOR, n, n, X.a, n, ip);
            int sign = 1;
            for (int i = 0; i < n; i++) {
                if (X.a[(size_t)i * n + i] < 0)
                    sign = -sign;
                if (ip[i] != i + 1)
                    sign = -sign;
            }
            printf("%s: det sign dense %d tree %d\n", name, sign, t.det_sign);
            TU_CHECK(sign == t.det_sign, "%s: determinant sign", name);
        }
    }
    frames_centrifugal(m, &kd, y2);
    tree_centrifugal(m, &kl, &t, y1);
    TU_CHECK(rel(y1, y2, n) < 1e-12, "%s: centrifugal %.2e", name, rel(y1, y2, n));
    tree_nodal(m, &kl, &t, x, nd);
    for (int c = 0; c < 3 * m->n_nodes; c++) {
        double a = 0;
        for (int i = 0; i < n; i++)
            a += DM(&kd.Jn, i, c) * x[i];
        nd2[c] = a;
    }
    TU_CHECK(rel(nd, nd2, 3 * m->n_nodes) < 1e-12, "%s: nodal %.2e", name, rel(nd, nd2, 3 * m->n_nodes));
    frames_kin_free(&kd);
    frames_kin_free(&kl);
    tree_free(&t);
    dm_free(&K);
    dm_free(&M);
    dm_free(&C);
    dm_free(&H);
    dm_free(&W);
    dm_free(&X);
    free(q);
    free(x);
    free(y1);
    free(y2);
    free(work);
    free(nd);
    free(nd2);
    free(ip);
    sm_model_free(m);
}

int main(void)
{
    sm_options o;
    sm_default_options(&o);
    check("per_element augmented", &o, 20);
    o.frames = SM_FRAMES_PER_MEMBER;
    o.frames_param = 4;
    check("per_member 4 augmented", &o, 20);
    o.basis = SM_BASIS_PAPER;
    check("per_member 4 paper", &o, 15);
    o.frames = SM_FRAMES_SINGLE;
    check("single paper", &o, 5);
    sm_default_options(&o);
    o.mass = SM_MASS_CONSISTENT;
    o.frames = SM_FRAMES_ELEMENTS_PER_FRAME;
    o.frames_param = 3;
    check("elements_per_frame 3 consistent", &o, 20);
    o.modes_per_frame = 2;
    check("elements_per_frame 3 consistent, 2 modes per frame", &o, 20);
    return tu_finish("tree");
}
