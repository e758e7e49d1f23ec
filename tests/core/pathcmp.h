/*
 * pathcmp.h — sm_solve of one request through the dense path and the tree path
 * (sm_options.solver forced), compared case by case: status, stability, equilibrium
 * (nodes and axial forces), eigenvalues and frequencies to ftol relative, mode shapes
 * (fitted by a complex factor) and MAC to 1e2 ftol.  Planar and spatial node layouts
 * alike (node_dof per case).  Shared by test_tree_solve.c and test_tree3_solve.c.
 */
#ifndef SM_PATHCMP_H
#define SM_PATHCMP_H

#include "internal.h"

#include "testutil.h"

static double tu_max_freq = 0, tu_max_eq = 0, tu_max_shape = 0;
/* 1: the tree path must find the modes itself (no case may fall back to the dense eigen-analysis) */
static int pc_tree_eigen = 0;

static double reldiff(const double *a, const double *b, int n)
{
    double d = 0, s = 0;
    for (int i = 0; i < n; i++) {
        d = fmax(d, fabs(a[i] - b[i]));
        s = fmax(s, fabs(b[i]));
    }
    return s > 0 ? d / s : d;
}

/* || a - c b || / || a || with the complex c = <b, a> / <b, b> that fits b to a best: mode shapes are
 * defined up to a factor, and the normalisation (largest translation = 1) picks between equal
 * translations (a member at 45 degrees) by round-off. */
static double shapediff(const double *ar, const double *ai, const double *br, const double *bi, int n)
{
    double bb = 0, cr = 0, ci = 0, aa = 0, d = 0;
    for (int i = 0; i < n; i++) {
        double xr = ar[i], xi = ai ? ai[i] : 0, yr = br[i], yi = bi ? bi[i] : 0;
        bb += yr * yr + yi * yi;
        cr += yr * xr + yi * xi; /* conj(b) a */
        ci += yr * xi - yi * xr;
        aa += xr * xr + xi * xi;
    }
    if (!(bb > 0) || !(aa > 0))
        return aa == bb ? 0 : 1;
    cr /= bb;
    ci /= bb;
    for (int i = 0; i < n; i++) {
        double xr = ar[i], xi = ai ? ai[i] : 0, yr = br[i], yi = bi ? bi[i] : 0;
        double er = xr - (cr * yr - ci * yi), ei = xi - (cr * yi + ci * yr);
        d += er * er + ei * ei;
    }
    return sqrt(d / aa);
}

static void compare(const char *name, const sm_structure *st, sm_options *o, const double *om, int nom, double ftol)
{
    sm_result *r[2] = {NULL, NULL};
    sm_model *m[2] = {NULL, NULL};
    sm_diag d;
    for (int v = 0; v < 2; v++) {
        o->solver = v ? SM_SOLVER_TREE : SM_SOLVER_DENSE;
        if (sm_model_new(&m[v], st, o, &d) != SM_OK || sm_solve(m[v], om, nom, NULL, NULL, &r[v], &d) != SM_OK) {
            TU_CHECK(0, "%s: solve %d: %s", name, v, d.message);
            goto done;
        }
    }
    TU_CHECK(tree_use(m[0]) == 0 && tree_use(m[1]) == 1, "%s: forced paths", name);
    for (int i = 0; i < nom; i++) {
        const sm_case *a = &r[0]->cases[i], *b = &r[1]->cases[i];
        TU_CHECK(a->status == b->status && a->converged == b->converged, "%s W=%g: status %d/%d", name, om[i],
                 a->status, b->status);
        TU_CHECK(a->negative_eigenvalues == b->negative_eigenvalues && a->stable == b->stable,
                 "%s W=%g: stability %d/%d", name, om[i], a->negative_eigenvalues, b->negative_eigenvalues);
        double de = fmax(reldiff(a->nodes, b->nodes, a->node_dof * a->n_nodes),
                         reldiff(a->axial_force, b->axial_force, a->n_elements));
        if (!a->converged) { /* where a failing continuation stops is decided by round-off */
            printf("%s W=%g: no equilibrium in both, last speed %.6g / %.6g\n", name, om[i], a->last_omega,
                   b->last_omega);
            continue;
        }
        tu_max_eq = fmax(tu_max_eq, de);
        TU_CHECK(de <= 1e-9, "%s W=%g: equilibrium differs by %.2e", name, om[i], de);
        TU_CHECK(!pc_tree_eigen || !b->dense_fallback, "%s W=%g: the tree path fell back to the dense one",
                 name, om[i]);
        TU_CHECK(a->n_modes == b->n_modes, "%s W=%g: modes %d/%d", name, om[i], a->n_modes, b->n_modes);
        int k = a->n_modes < b->n_modes ? a->n_modes : b->n_modes;
        double df = 0, ds = 0;
        for (int j = 0; j < k; j++) {
            double sc = hypot(a->eig_re[j], a->eig_im[j]);
            df = fmax(df, fabs(a->frequency[j] - b->frequency[j]) / a->frequency[j]);
            df = fmax(df, hypot(a->eig_re[j] - b->eig_re[j], a->eig_im[j] - b->eig_im[j]) / sc);
            if (a->shape_re && b->shape_re) {
                size_t nn = (size_t)a->node_dof * a->n_nodes;
                ds = fmax(ds, shapediff(a->shape_re + j * nn, a->shape_im ? a->shape_im + j * nn : NULL,
                                        b->shape_re + j * nn, b->shape_im ? b->shape_im + j * nn : NULL, (int)nn));
            }
            if (a->mac_to_previous[j] >= 0)
                ds = fmax(ds, fabs(a->mac_to_previous[j] - b->mac_to_previous[j]));
        }
        if (ftol <= 1e-9)
            tu_max_freq = fmax(tu_max_freq, df);
        if (ftol <= 1e-9)
            tu_max_shape = fmax(tu_max_shape, ds);
        printf("%s W=%g: status %d, w1 %.10g, max rel diff: freq %.2e equilibrium %.2e shapes %.2e; iterations "
               "%d/%d\n",
               name, om[i], a->status, k ? a->frequency[0] : 0.0, df, de, ds, a->iterations, b->iterations);
        TU_CHECK(df <= ftol, "%s W=%g: frequencies differ by %.2e", name, om[i], df);
        TU_CHECK(ds <= 1e2 * ftol, "%s W=%g: shapes differ by %.2e", name, om[i], ds);
    }
done:
    for (int v = 0; v < 2; v++) {
        sm_result_free(r[v]);
        sm_model_free(m[v]);
    }
    o->solver = SM_SOLVER_AUTO;
}

#endif
