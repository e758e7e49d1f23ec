/*
 * critical.c — critical speeds: where a tracked mode meets an engine order,
 * w(Omega) = n Omega (DESIGN.md 9, 9.1).
 *
 * How it fits: sm_solve (sweep.c) calls crit_find after track.c has tracked
 * the sweep.  For each order n and each tracked line, on every interval
 * between consecutive speeds of the sweep (both solved, stable, without a
 * validity warning, no failed speed between them) where g = w - n Omega
 * changes sign, the crossing is interpolated linearly and then refined by
 * solving the model at single speeds (crit_single, from rest with
 * continuation) inside the bracket: regula falsi with the Illinois
 * modification, the mode at each trial speed being the one of largest MAC to
 * the line's mode at the nearer end of the bracket.  It stops when
 * |g| <= CRIT_TOL n Omega (refined), when the bracket shrinks below 1e-13
 * relative, or after CRIT_MAX_SOLVES solves (refined when |g| <= 1e-6 n Omega
 * by then); a trial speed without equilibrium or without a matching mode
 * (MAC < CRIT_MIN_MAC) ends it with the interpolated value (refined = 0).
 * Helpers are crit_*.
 */
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CRIT_TOL 1e-10        /* |w - n Omega| / (n Omega) that ends the refinement */
#define CRIT_LOOSE 1e-6       /* ... that still counts as refined after CRIT_MAX_SOLVES */
#define CRIT_MAX_SOLVES 30
#define CRIT_MIN_MAC 0.5      /* a trial speed's mode must resemble the line's this much */

/* The caller's callback for the refining solves: cancel only, progress stays at the end. */
typedef struct crit_ctx {
    const sm_model *m;
    sm_progress_fn cb;
    void *user;
    int total;                /* speeds of the sweep */
    int canceled;
} crit_ctx;

/* Solve at one speed with shapes kept and labels (no tracking); *out owned by the caller. */
static int crit_single(const sm_model *m, double omega, sm_progress_fn cb, void *user, sm_result **out)
{
    return sweep_run(m, &omega, 1, cb, user, lab_case, out, NULL);
}

static int crit_cb(void *user, int done, int total)
{
    crit_ctx *x = user;
    (void)done;
    (void)total;
    if (x->cb && x->cb(x->user, x->total, x->total))
        x->canceled = 1;
    return x->canceled;
}

/* Mode of case c on tracked line id, or -1. */
static int crit_mode_of(const sm_case *c, int id)
{
    for (int j = 0; j < c->n_modes; j++)
        if (c->tracked_index[j] == id)
            return j;
    return -1;
}

/* A case whose frequencies may bracket a critical speed. */
static int crit_usable(const sm_case *c)
{
    return c->status == SM_CASE_SOLVED && c->n_modes > 0 && c->tracked_index && c->shape_re && !c->warning[0];
}

/* Solve at x; *w the frequency of the mode most like mode rj of ref, its label into cr.
 * *ok = 0 when the speed has no modes or nothing matches.  SM_OK, SM_NOMEM or SM_CANCELED. */
static int crit_eval(crit_ctx *x, double om, const sm_case *ref, int rj, double *w, sm_critical *cr, int *ok)
{
    sm_result *r = NULL;
    int rc = crit_single(x->m, om, crit_cb, x, &r), best = -1;
    double bm = -1;

    *ok = 0;
    if (rc == SM_CANCELED || x->canceled)
        return SM_CANCELED;
    if (rc == SM_NOMEM)
        return rc;
    if (rc < 0)
        return SM_OK; /* a failed solve ends the refinement, not the analysis */
    const sm_case *c = &r->cases[0];
    for (int j = 0; c->status == SM_CASE_SOLVED && c->shape_re && j < c->n_modes; j++) {
        double mac = track_mac(ref, rj, c, j);
        if (mac > bm)
            bm = mac, best = j;
    }
    if (best >= 0 && bm >= CRIT_MIN_MAC) {
        *ok = 1;
        *w = c->frequency[best];
        cr->label_kind = c->label_kind ? c->label_kind[best] : SM_MODE_COUPLED;
        cr->label_ordinal = c->label_ordinal ? c->label_ordinal[best] : 0;
        cr->label_confidence = c->label_confidence ? c->label_confidence[best] : 0;
    }
    sm_result_free(r);
    return SM_OK;
}

/*
 * Refine the crossing of line id with order n between the cases A (mode ja, g = ga) and B
 * (mode jb, g = gb), ga and gb of opposite signs, into *cr (its interpolated fields set).
 * Regula falsi with the Illinois modification.  SM_OK, SM_NOMEM or SM_CANCELED.
 */
static int crit_refine(crit_ctx *x, double n, const sm_case *A, int ja, double ga, const sm_case *B, int jb,
                       double gb, sm_critical *cr)
{
    double lo = A->omega, hi = B->omega, glo = ga, ghi = gb, om = cr->omega_interpolated;
    int side = 0;

    for (int it = 0; it < CRIT_MAX_SOLVES; it++) {
        double w = 0;
        int ok, near_a = om - A->omega <= B->omega - om;
        sm_critical trial = *cr;
        int rc = crit_eval(x, om, near_a ? A : B, near_a ? ja : jb, &w, &trial, &ok);
        if (rc < 0)
            return rc;
        if (!ok)
            break;
        double g = w - n * om, res = fabs(g) / (n * om);
        cr->iterations = it + 1;
        if (!cr->refined && (it == 0 || res < cr->residual)) { /* the best trial so far */
            trial.omega = om;
            trial.frequency = w;
            trial.residual = res;
            trial.iterations = it + 1;
            *cr = trial;
        }
        if (res <= CRIT_TOL) {
            cr->refined = 1;
            break;
        }
        if ((g > 0) == (glo > 0)) { /* [om, hi] brackets: move lo; Illinois halves the stale end */
            lo = om, glo = g;
            if (side == -1)
                ghi *= 0.5;
            side = -1;
        } else {
            hi = om, ghi = g;
            if (side == 1)
                glo *= 0.5;
            side = 1;
        }
        if (hi - lo <= 1e-13 * hi)
            break;
        om = lo - glo * (hi - lo) / (ghi - glo); /* x = root of the chord */
    }
    if (!cr->refined && cr->iterations > 0 && cr->residual <= CRIT_LOOSE)
        cr->refined = 1;
    return SM_OK;
}

/* Append c to r->critical (capacity *cap). */
static int crit_push(sm_result *r, int *cap, const sm_critical *c)
{
    if (r->n_critical == *cap) {
        int nc = *cap ? 2 * *cap : 8;
        sm_critical *p = realloc(r->critical, (size_t)nc * sizeof *p);
        if (!p)
            return SM_NOMEM;
        r->critical = p;
        *cap = nc;
    }
    r->critical[r->n_critical++] = *c;
    return SM_OK;
}

/* The crossings of order n on the interval between the cases A and B (consecutive). */
static int crit_interval(crit_ctx *x, sm_result *r, int *cap, double n, const sm_case *A, const sm_case *B)
{
    for (int jb = 0; jb < B->n_modes; jb++) {
        int id = B->tracked_index[jb], ja = crit_mode_of(A, id), rc;
        if (ja < 0)
            continue;
        double ga = A->frequency[ja] - n * A->omega, gb = B->frequency[jb] - n * B->omega;
        if (!((ga > 0 && gb <= 0) || (ga < 0 && gb >= 0))) /* a zero counts at the upper end only */
            continue;
        sm_critical c;
        memset(&c, 0, sizeof c);
        c.order = n;
        c.tracked_index = id;
        c.omega_below = A->omega;
        c.omega_above = B->omega;
        c.omega_interpolated = A->omega + ga * (B->omega - A->omega) / (ga - gb); /* g linear */
        c.omega = c.omega_interpolated;
        c.frequency = n * c.omega;
        c.residual = NAN;
        const sm_case *N = c.omega - A->omega <= B->omega - c.omega ? A : B;
        int jn = N == A ? ja : jb;
        c.label_kind = N->label_kind ? N->label_kind[jn] : SM_MODE_COUPLED;
        c.label_ordinal = N->label_ordinal ? N->label_ordinal[jn] : 0;
        c.label_confidence = N->label_confidence ? N->label_confidence[jn] : 0;
        if (gb == 0) { /* exactly on a sweep speed: nothing to refine */
            c.omega = B->omega;
            c.frequency = B->frequency[jb];
            c.residual = 0;
            c.refined = 1;
        } else if ((rc = crit_refine(x, n, A, ja, ga, B, jb, gb, &c)) < 0) {
            return rc;
        }
        if ((rc = crit_push(r, cap, &c)) < 0)
            return rc;
    }
    return SM_OK;
}

int crit_find(const sm_model *m, sm_result *r, const int *ord, int n, sm_progress_fn cb, void *user)
{
    crit_ctx x = {m, cb, user, n, 0};
    int cap = 0;

    r->n_critical = 0;
    r->critical = NULL;
    for (int o = 0; o < m->opt.n_engine_orders && o < SM_MAX_ENGINE_ORDERS; o++) {
        double eo = m->opt.engine_orders[o];
        if (!(eo > 0) || !isfinite(eo))
            continue;
        for (int t = 1; t < n; t++) {
            const sm_case *A = &r->cases[ord[t - 1]], *B = &r->cases[ord[t]];
            if (!crit_usable(A) || !crit_usable(B) || !(B->omega > A->omega))
                continue;
            int rc = crit_interval(&x, r, &cap, eo, A, B);
            if (rc < 0)
                return rc;
        }
    }
    return SM_OK;
}
