/*
 * diverge.c — divergence speeds: where the steady state of a sweep loses (or
 * regains) static stability, the lowest eigenvalue of K* passing through
 * zero (DESIGN.md 1.4, 7.3; shared DESIGN A).
 *
 * How it fits: sm_solve (sweep.c) calls div_find after crit_find.  Between
 * consecutive speeds of the sweep whose equilibria converged and whose
 * eigen-analyses ran (solved or unstable), a change in the count of negative
 * eigenvalues of K* brackets a divergence.  lambda(Omega), the lowest
 * eigenvalue of K* at the steady state of Omega (sweep_lowest: equilibrium
 * from rest, dense K*), is refined in s = Omega^2 (where K*'s centrifugal
 * terms are linear) by regula falsi with the Illinois modification to
 * |dOmega| <= DIV_TOL Omega.  Where the dense K* is too large
 * (more than DIV_DENSE_MAX coordinates) the speed is interpolated from the
 * sweep's own eigenvalues (Coriolis off: lambda = w^2 of the lowest root, or
 * -Re^2 of a real one) or the bracket's middle, and marked not refined.
 * Helpers are div_*.
 */
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define DIV_TOL 1e-6          /* |dOmega| / Omega that ends the refinement */
#define DIV_MAX_SOLVES 40
#define DIV_DENSE_MAX 600     /* coordinates up to which lambda comes from a dense K* (a dsyevx of
                                 ~0.1 s; each refining solve also solves the equilibrium from rest) */

typedef struct div_ctx {
    const sm_model *m;
    sm_progress_fn cb;
    void *user;
    int total;
    int canceled;
} div_ctx;

static int div_cb(void *user, int done, int total)
{
    div_ctx *x = user;
    (void)done;
    (void)total;
    if (x->cb && x->cb(x->user, x->total, x->total))
        x->canceled = 1;
    return x->canceled;
}

/* A case whose stability is known: converged equilibrium and eigen-analysis. */
static int div_usable(const sm_case *c)
{
    return c->converged && (c->status == SM_CASE_SOLVED || c->status == SM_CASE_UNSTABLE) && c->n_modes > 0;
}

/* lambda of the sweep's own roots of case c (Coriolis off: one of Re, Im is zero), NaN else. */
static double div_case_lambda(const sm_model *m, const sm_case *c)
{
    if (m->opt.coriolis || c->n_modes < 1)
        return NAN;
    double lo = INFINITY;
    for (int j = 0; j < c->n_modes; j++) {
        double l = c->eig_im[j] * c->eig_im[j] - c->eig_re[j] * c->eig_re[j];
        lo = fmin(lo, l);
    }
    return lo;
}

/* *lam = lambda(om); *ok = 0 when it could not be had.  SM_OK, SM_NOMEM or SM_CANCELED. */
static int div_eval(div_ctx *x, double om, double *lam, int *ok)
{
    int rc = sweep_lowest(x->m, om, div_cb, x, lam);
    *ok = rc == SM_OK;
    if (rc == SM_CANCELED || x->canceled)
        return SM_CANCELED;
    return rc == SM_NOMEM ? rc : SM_OK;
}

/* The label of the softening mode: the lowest root of the stable side. */
static void div_label(const sm_case *c, sm_divergence *d)
{
    int best = -1;
    double lo = INFINITY;
    for (int j = 0; j < c->n_modes; j++) {
        double a = hypot(c->eig_re[j], c->eig_im[j]);
        if (a < lo)
            lo = a, best = j;
    }
    d->label_kind = best >= 0 && c->label_kind ? c->label_kind[best] : SM_MODE_COUPLED;
    d->label_ordinal = best >= 0 && c->label_ordinal ? c->label_ordinal[best] : 0;
}

/*
 * Refine the zero of lambda between A and B (lambda la, lb of opposite signs, or unknown)
 * into d.  SM_OK, SM_NOMEM or SM_CANCELED.
 */
static int div_refine(div_ctx *x, const sm_case *A, const sm_case *B, sm_divergence *d)
{
    /* in s = Omega^2, where the centrifugal terms of K* are linear: lambda(s) is nearly so */
    double a = A->omega * A->omega, b = B->omega * B->omega, fa = NAN, fb = NAN, prev = NAN;
    int ok_a = 0, ok_b = 0, rc, side = 0;
    d->omega = d->omega_interpolated = sqrt(0.5 * (a + b));
    if (x->m->n <= DIV_DENSE_MAX) {
        if ((rc = div_eval(x, A->omega, &fa, &ok_a)) < 0 || (rc = div_eval(x, B->omega, &fb, &ok_b)) < 0)
            return rc;
        d->iterations = 2;
    } else {
        fa = div_case_lambda(x->m, A), fb = div_case_lambda(x->m, B);
        ok_a = ok_b = isfinite(fa) && isfinite(fb);
    }
    if (!ok_a || !ok_b || !(fa * fb < 0))
        return SM_OK; /* the bracket's middle, not refined */
    /* s_i = b - f(b) (b - a) / (f(b) - f(a)) */
    d->omega = d->omega_interpolated = sqrt(b - fb * (b - a) / (fb - fa));
    if (x->m->n > DIV_DENSE_MAX)
        return SM_OK;
    for (int it = 0; it < DIV_MAX_SOLVES; it++) {
        double c = b - fb * (b - a) / (fb - fa), fc;
        int ok;
        if ((rc = div_eval(x, sqrt(c), &fc, &ok)) < 0)
            return rc;
        d->iterations++;
        if (!ok)
            break;
        d->omega = sqrt(c);
        /* |d Omega| <= DIV_TOL Omega  <=>  |d s| <= 2 DIV_TOL s */
        if (fc == 0 || fabs(b - a) <= 2 * DIV_TOL * c || fabs(c - prev) <= 2 * DIV_TOL * c) {
            d->refined = 1;
            break;
        }
        if (fc * fb < 0) { /* the zero lies between c and b */
            a = b, fa = fb;
            side = 0;
        } else if (side == -1) { /* Illinois: halve the stale end's value */
            fa *= 0.5;
        } else {
            side = -1;
        }
        b = c, fb = fc;
        prev = c;
    }
    return SM_OK;
}

int div_find(const sm_model *m, sm_result *r, const int *ord, int n, sm_progress_fn cb, void *user)
{
    div_ctx x = {m, cb, user, n, 0};
    int cap = 0, rc;
    for (int t = 0; t + 1 < n; t++) {
        const sm_case *A = &r->cases[ord[t]], *B = &r->cases[ord[t + 1]];
        if (!div_usable(A) || !div_usable(B) || A->negative_eigenvalues == B->negative_eigenvalues ||
            !(B->omega > A->omega))
            continue;
        if (r->n_divergence == cap) {
            cap = cap ? 2 * cap : 4;
            sm_divergence *g = realloc(r->divergence, (size_t)cap * sizeof *g);
            if (!g)
                return SM_NOMEM;
            r->divergence = g;
        }
        sm_divergence *d = &r->divergence[r->n_divergence++];
        memset(d, 0, sizeof *d);
        d->omega_below = A->omega;
        d->omega_above = B->omega;
        d->onset = B->negative_eigenvalues > A->negative_eigenvalues;
        d->negative_below = A->negative_eigenvalues;
        d->negative_above = B->negative_eigenvalues;
        div_label(d->onset ? A : B, d);
        if ((rc = div_refine(&x, A, B, d)) < 0)
            return rc;
    }
    return SM_OK;
}
