/*
 * equilibrium.c — the dynamic equilibrium (steady deflected state) in the
 * hub frame, DESIGN.md 1.3:
 *
 *   F(q) = K q + f_g(q) - Omega^2 g(q) = 0,     g = sum m_k J_k' r_k
 *
 * solved by Newton-Raphson with the exact tangent
 *   Kt = K + d f_g/dq - Omega^2 (M* + H)        (the kind's, through linsys.h)
 * along a continuation in s = Omega^2: tangent predictor, damped Newton
 * corrector, step halving when Newton fails or the corrector lands far from
 * the predictor (a jump to another branch), step growth when it converges
 * fast.  Running out of step size is the reported "no equilibrium" outcome.
 */
#include "linsys.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EQ_MAX_INCREMENTS 400
#define EQ_MAX_TOTAL_ITER 4000
/* Validity limit of the model: elastic axial strain.  Inside a frame the
 * kinematics are linear, so a large rotation shows up as a spurious strain;
 * beyond 1 % (ten times the yield strain of structural metals) the "steady
 * state" is an artefact of too few frames (the single frame at beta = 90 deg
 * runs away), not an equilibrium of the structure. */
#define EQ_MAX_STRAIN 0.01
/* A kind with stiffened_start (kind.h; the 3D kind, DESIGN.md 7.3), from rest: the first
 * increment is this fraction of the largest,
 * and its predictor is stiffened (the tangent at the linear predictor, where the axial forces of
 * the centrifugal load give their geometric stiffness).  The flap of a preconed blade is governed
 * by that stiffness: with the tangent at rest the predictor overshoots it many times over, and the
 * first increments were rejected (140 Newton iterations on the 48-element R3 blade at 10 rad/s,
 * 36 with both; Kim & Yoo's planar kind keeps its continuation, and its answers, unchanged). */
#define EQ_STIFFENED_FIRST 4
/* A change of sign of det(Kt) is accepted as a crossed bifurcation only on a step no larger
 * than this fraction of the target s (the step is halved down to it first). */
#define EQ_CROSS_STEP 1e-4
/* Newton iterations of the one-step trial from Omega = 0 (eq_solve) before the increments from
 * rest take over: a trial that diverges or leaves the branch stops earlier (eq_newton); 8 cut
 * off a converging one (chord steps contracting 11-fold each, 9 iterations in all) on the
 * out-of-plane case R2F at 20 rad/s. */
#define EQ_TRIAL_ITERATIONS 12
/* A trial is tried only where the step from rest is weakly nonlinear: the residual at its
 * stiffened predictor at most this fraction of the load s |g| there (eq_newton).  A one-step
 * trial can converge to an equilibrium the continuation from rest never reaches: a random frame
 * with a pendulous member and a tip mass (rho 0.23) swung out to the other side of the one a
 * fine sweep from rest follows (its first frequency 2.55 instead of 3.05 rad/s), and a frame with
 * an inward member (rho 0.59) landed on an unstable equilibrium with two negative eigenvalues
 * (which the determinant's sign cannot see) where the increments find none.  Of 907 trials
 * (the 144 requests of tests/bench/compare_starts.py and 800 random frames), 369 of the 451
 * that converged were below 0.05; every trial that gave a different answer was above 0.2. */
#define EQ_TRIAL_RHO 0.05

typedef struct eq_ws {
    smi_lin *L;              /* kinematics and the tangent: dense or tree (linsys.h) */
    double *F, *g, *dq, *qt, *q0, *qp;
    double *d0;              /* a trial's predictor direction Kt^-1 g at (q, s_from) */
    double *P;               /* n_elems axial forces */
    int iterations;          /* total Newton iterations */
    double residual;
} eq_ws;

struct eq_carry {
    eq_ws w;
    int valid; /* w->L holds the factors of a Newton tangent at s (kinds without fixed_bits) */
    int sign;  /* the continuation's sign of det Kt there */
    double s;
};

static void eq_ws_free(eq_ws *w)
{
    smi_lin_free(w->L);
    free(w->F);
    free(w->g);
    free(w->dq);
    free(w->qt);
    free(w->q0);
    free(w->qp);
    free(w->d0);
    free(w->P);
}

static int eq_ws_alloc(const sm_model *m, eq_ws *w)
{
    int n = m->n;
    memset(w, 0, sizeof *w);
    w->F = dm_vec((size_t)n);
    w->g = dm_vec((size_t)n);
    w->dq = dm_vec((size_t)n);
    w->qt = dm_vec((size_t)n);
    w->q0 = dm_vec((size_t)n);
    w->qp = dm_vec((size_t)n);
    w->d0 = dm_vec((size_t)n);
    w->P = dm_vec((size_t)m->n_elems);
    if (!w->P || !w->F || !w->g || !w->dq || !w->qt || !w->q0 || !w->qp || !w->d0 ||
        smi_lin_new(m, SMI_USE_NEWTON, tree_use(m), &w->L) != SM_OK) {
        eq_ws_free(w);
        return SM_NOMEM;
    }
    return SM_OK;
}

/* F(q) at s = Omega^2; leaves the kinematics of q in w->L.  Returns ||F||. */
static double eq_residual(const sm_model *m, const double *q, double s, eq_ws *w)
{
    int n = m->n;
    smi_lin_centrifugal(m, q, w->L, w->g);
    memset(w->F, 0, (size_t)n * sizeof(double));
    lin_elastic_force(m, q, w->F);
    if (m->opt.geometric_stiffening)
        m->kind->geometric_force(m, q, w->F);
    for (int i = 0; i < n; i++)
        w->F[i] -= s * w->g[i];
    return dm_norm(w->F, n);
}

/* Largest elastic axial strain |P_e| / EA over all elements at q; P: n_elems scratch. */
static double eq_max_strain(const sm_model *m, const double *q, double *P)
{
    double mx = 0;
    lin_axial_forces(m, q, P);
    for (int e = 0; e < m->n_elems; e++)
        mx = fmax(mx, fabs(P[e]) / m->elems[e].EA);
    return mx;
}

static int eq_progress(sm_progress *pr)
{
    return pr && pr->cb && pr->cb(pr->user, pr->done, pr->total);
}

/* The branch check of a continuation step: whether the corrector q has moved from the predictor
 * w->qp by more than half the predicted step w->qp - w->q0 (and more than 1e-6 max(1, |q|)). */
static int eq_off_branch(const double *q, const eq_ws *w, int n)
{
    double step = 0, corr = 0;
    for (int i = 0; i < n; i++) {
        step += (w->qp[i] - w->q0[i]) * (w->qp[i] - w->q0[i]);
        corr += (q[i] - w->qp[i]) * (q[i] - w->qp[i]);
    }
    step = sqrt(step);
    corr = sqrt(corr);
    return corr > fmax(0.5 * step, 1e-6 * fmax(1.0, dm_norm(q, n)));
}

/*
 * Newton-Raphson at fixed s from q (in/out).  Returns 1 converged, 0 not
 * (including an exactly singular tangent), SM_CANCELED, or SM_LAPACK_FAILED
 * when a factorisation or solve reports an error.  On return w->L holds
 * the kinematics of q and the factors of a tangent at an iterate of this
 * call.
 *
 * The first iteration factors the tangent at the starting point (so the LU
 * always belongs to the new s: the determinant-sign check and the next
 * predictor rely on it).  Later iterations first try a chord step with the
 * LU already in hand (one residual evaluation instead of a tangent assembly
 * and LU, about 1/15 of the cost); the step is kept when it converges, or
 * when it cuts the residual at least tenfold, and is otherwise redone as a
 * full, damped Newton step with a fresh tangent.
 *
 * A trial (the one step from Omega = 0, eq_solve) gives up early, returning 0, when it cannot
 * pass or should not: before its first tangent when the residual at the predictor exceeds
 * EQ_TRIAL_RHO times the load s |g| there (a strongly nonlinear step, where one step may reach
 * another equilibrium), at a damped step (a good trial converges in full steps) and, from its
 * second iteration on, once the iterate is off the predicted branch (eq_off_branch, the check a
 * converged step must pass).  A failed trial took its EQ_TRIAL_ITERATIONS in full in solver
 * 0.8.4, and solver 0.8.4 tried every step from Omega = 0 (a sweep's speed after 0).
 */
static int eq_newton(const sm_model *m, double *q, double s, eq_ws *w, sm_progress *pr, int trial)
{
    int n = m->n, have_lu = 0, rc;
    int max_it = trial && m->opt.max_iterations > EQ_TRIAL_ITERATIONS ? EQ_TRIAL_ITERATIONS
                                                                      : m->opt.max_iterations;
    double tol = m->opt.tolerance;
    double r = eq_residual(m, q, s, w), prev_step = INFINITY;
    if (trial && !(r <= EQ_TRIAL_RHO * s * dm_norm(w->g, n)))
        return 0;
    for (int it = 0; it < max_it; it++) {
        if (!isfinite(r))
            return 0;
        double qn = fmax(1.0, dm_norm(q, n)), step = 0, alpha = 1.0, rt = 0;
        int fresh = 0;
        if (have_lu) { /* chord step */
            for (int i = 0; i < n; i++)
                w->dq[i] = -w->F[i];
            if ((rc = smi_lin_solve(m, w->L, w->dq)) < 0)
                return rc;
            step = dm_norm(w->dq, n);
            for (int i = 0; i < n; i++)
                w->qt[i] = q[i] + w->dq[i];
            rt = eq_residual(m, w->qt, s, w);
            if (!(isfinite(rt) && (step <= tol * qn || rt <= 0.1 * r)))
                have_lu = 0; /* poor contraction: redo from q with a fresh tangent */
            if (!have_lu)
                r = eq_residual(m, q, s, w);
        }
        if (!have_lu) { /* full Newton step, damped: halve while the residual grows */
            if ((rc = smi_lin_tangent(m, q, s, w->L)) != SM_OK)
                return rc == SM_SINGULAR ? 0 : rc;
            have_lu = fresh = 1;
            for (int i = 0; i < n; i++)
                w->dq[i] = -w->F[i];
            if ((rc = smi_lin_solve(m, w->L, w->dq)) < 0)
                return rc;
            step = dm_norm(w->dq, n);
            for (int tries = 0; tries < 8; tries++) {
                for (int i = 0; i < n; i++)
                    w->qt[i] = q[i] + alpha * w->dq[i];
                rt = eq_residual(m, w->qt, s, w);
                if (isfinite(rt) && (rt <= r || step <= 1e-6 * qn))
                    break;
                alpha *= 0.5;
            }
        }
        memcpy(q, w->qt, (size_t)n * sizeof(double));
        w->iterations++;
        w->residual = rt;
        if (eq_progress(pr))
            return SM_CANCELED;
        if (!isfinite(rt) || dm_norm(q, n) > 1e12)
            return 0;
        if (alpha == 1.0 && step <= tol * qn)
            return 1;
        /* stagnation at round-off: a full Newton step no longer shrinks */
        if (fresh && alpha == 1.0 && step <= 1e-8 * qn && step >= 0.5 * prev_step)
            return 1;
        if (fresh)
            prev_step = step;
        if (trial && (alpha < 1.0 || (it >= 1 && eq_off_branch(q, w, n))))
            return 0;
        r = rt;
    }
    return 0;
}

/* Factor the tangent at (q, s) after a residual evaluation there: *have_lu
 * receives 1 when an LU is usable (0 for an exactly singular tangent).
 * Returns SM_OK or SM_LAPACK_FAILED. */
static int eq_restart(const sm_model *m, const double *q, double s, eq_ws *w, int *have_lu)
{
    eq_residual(m, q, s, w);
    int rc = smi_lin_tangent(m, q, s, w->L);
    *have_lu = rc == SM_OK;
    return rc == SM_SINGULAR ? SM_OK : rc;
}

/*
 * Continuation from (q, s_from) to s_to in s = Omega^2.  q is the converged
 * state at s_from (zero at rest).  On success q is the equilibrium at s_to.
 * On failure q is the last converged state and out->last_s its s.
 * Returns SM_OK (whether or not it converged: see out), SM_NOMEM or
 * SM_LAPACK_FAILED (a LAPACK error, not a property of the structure).
 */
int eq_solve(const sm_model *m, double *q, double s_from, double s_to, int from_rest,
             eq_carry *carry, sm_progress *pr, sm_eq_out *out)
{
    eq_ws own, *w = carry ? &carry->w : &own;
    int n = m->n, rc = carry ? SM_OK : eq_ws_alloc(m, &own), incr = 0, have_lu = 0;
    memset(out, 0, sizeof *out);
    out->last_s = s_from;
    if (rc < 0)
        return rc;
    w->iterations = 0;
    w->residual = 0;
    double range = s_to - s_from;
    /* A kind with stiffened_start going on from Omega = 0 (a sweep's speed after 0, and since
     * solver 0.8.5 a start from rest) tries one step, and when that fails takes the increments of
     * a start from rest instead of halving it: halving, the 2000-element precone blade took 190
     * Newton iterations from 0 to 10 rad/s (4 s); from rest it takes 35 (0.3 s), while one step
     * is best for a small first speed (3 iterations to 1 rad/s on the 48-element blade, 20 from
     * rest; BModes' Test01 blade at 60 rpm 2, from rest 14).  A trial gives up before its first
     * tangent when the predictor leaves more than EQ_TRIAL_RHO of the load unbalanced (there
     * one step may reach an equilibrium the increments never do), else at its first damped or
     * off-branch iterate (eq_newton): 0 to 2 iterations.  Issue 27, solvers 0.8.4 and
     * 0.8.5; the planar kind keeps its continuation and its bytes. */
    int may_rest = m->kind->stiffened_start && s_from == 0.0, rest = from_rest && !may_rest;
    double incs = m->opt.min_increments > 0 ? m->opt.min_increments : 1;
    double hmax = rest ? range / incs : range;
    double h = hmax, hmin = 1e-7 * fmax(s_to, 1e-12), s = s_from;
    if (m->kind->stiffened_start && rest)
        h = hmax / EQ_STIFFENED_FIRST;
    const char *why = "";
    int d0_ok = 0; /* w->d0 stands for the solve of the next predictor (after a failed trial) */
    /* tangent at the start for the first predictor: at (q, s_from), or the one carried over */
    int sign = 1;
    if (carry && carry->valid && !from_rest && !m->kind->fixed_bits && carry->s == s_from) {
        have_lu = 1;
        sign = carry->sign;
    } else {
        if ((rc = eq_restart(m, q, s, w, &have_lu)) < 0)
            goto fail;
        sign = have_lu ? smi_lin_det_sign(m, w->L) : 1;
    }
    if (carry)
        carry->valid = 0;
    while (s < s_to) {
        if (incr++ >= EQ_MAX_INCREMENTS || w->iterations >= EQ_MAX_TOTAL_ITER) {
            why = "too many continuation steps";
            break;
        }
        double sn = s + h >= s_to - 1e-12 * s_to ? s_to : s + h;
        /* predictor: Kt dq = g ds.  w->g holds g(q) already: q comes from eq_restart, from the
         * carried continuation or from a converged Newton step, and each ends with a residual
         * evaluation at q (issue 27: one of a speed's five evaluations of g, same values) */
        memcpy(w->q0, q, (size_t)n * sizeof(double));
        memcpy(w->qp, q, (size_t)n * sizeof(double));
        /* the one step from Omega = 0 (may_rest) is a trial: a good one converges in 2 to 4 */
        int trial = may_rest && !rest && s == s_from;
        if (have_lu) {
            if (d0_ok) {
                memcpy(w->dq, w->d0, (size_t)n * sizeof(double));
                d0_ok = 0;
            } else {
                memcpy(w->dq, w->g, (size_t)n * sizeof(double));
                if ((rc = smi_lin_solve(m, w->L, w->dq)) < 0)
                    goto fail;
                if (trial)
                    memcpy(w->d0, w->dq, (size_t)n * sizeof(double));
            }
            for (int i = 0; i < n; i++)
                w->qp[i] += (sn - s) * w->dq[i];
            /* the stiffened predictor: from rest, and on a sweep's step that at least doubles s
             * (the flap stiffness grows with s: the next speed of a sweep from 0 by 1 rad/s took
             * 14 and 13 Newton iterations on the 288-coordinate precone blade, 3 with it; issue
             * 27, solver 0.8.4).  The increments of a continuation from rest keep the tangent
             * predictor after the first: there the extra tangent cost more than it saved. */
            if (m->kind->stiffened_start && (s == 0.0 || (!rest && sn >= 2 * s))) {
                int r2 = smi_lin_tangent(m, w->qp, sn, w->L);
                if (r2 < 0 && r2 != SM_SINGULAR) {
                    rc = r2;
                    goto fail;
                }
                if (r2 == SM_OK) {
                    memcpy(w->dq, w->g, (size_t)n * sizeof(double));
                    if ((rc = smi_lin_solve(m, w->L, w->dq)) < 0)
                        goto fail;
                    for (int i = 0; i < n; i++)
                        w->qp[i] = q[i] + (sn - s) * w->dq[i];
                }
            }
        }
        memcpy(q, w->qp, (size_t)n * sizeof(double));
        int it0 = w->iterations;
        int ok = eq_newton(m, q, sn, w, pr, trial);
        if (ok == SM_CANCELED) {
            memcpy(q, w->q0, (size_t)n * sizeof(double));
            out->canceled = 1;
            break;
        }
        if (ok < 0) {
            rc = ok;
            memcpy(q, w->q0, (size_t)n * sizeof(double));
            goto fail;
        }
        if (ok) {
            /* branch check: the corrector must stay within the predicted step */
            if (have_lu && eq_off_branch(q, w, n)) {
                ok = 0;
                why = "the solution jumped to another branch";
            } else if (eq_max_strain(m, q, w->P) > EQ_MAX_STRAIN) {
                ok = 0;
                /* With one frame per element the frames cannot be refined: the strain is the
                 * structure's own (the speed is beyond what its EA carries), not an artefact. */
                why = m->n_subs >= m->n_elems
                          ? "an element stretches past 1 % axial strain: the speed exceeds what the "
                            "structure's axial stiffness EA carries (frames are per element already)"
                          : "the deformation leaves the small-strain range (axial strain above 1 %): "
                            "the steady state runs away; use more frames";
            } else if (smi_lin_det_sign(m, w->L) != sign) {
                /* A critical point lies inside the step.  Shrink the step until it is small;
                 * a converged corrector that stays on the predicted branch there has crossed
                 * a bifurcation of a branch that goes on (the symmetric steady state of a
                 * structure past its divergence speed): accept it, the state is reported
                 * unstable by the eigen-analysis.  A limit point (the branch turns back) is
                 * not crossed: beyond it Newton finds nothing near the predictor. */
                if (sn - s > EQ_CROSS_STEP * s_to) {
                    ok = 0;
                    why = "the tangent stiffness becomes singular (a limit point: the branch turns back)";
                } else {
                    sign = -sign;
                    out->crossings++;
                    if (out->crossings == 1)
                        out->first_crossing_s = 0.5 * (s + sn);
                }
            }
        } else {
            why = "Newton-Raphson did not converge";
        }
        if (ok) {
            s = sn;
            out->last_s = s;
            have_lu = 1; /* the LU of the last Newton tangent, at s */
            if (w->iterations - it0 <= 4)
                h = fmin(2.0 * h, hmax);
        } else {
            memcpy(q, w->q0, (size_t)n * sizeof(double));
            if (trial && have_lu) {
                /* the tangent at s_from is not factored again: its one use, the first
                 * predictor from rest, is the trial's direction d0 (the same bits) */
                eq_residual(m, q, s, w);
                d0_ok = 1;
            } else if ((rc = eq_restart(m, q, s, w, &have_lu)) < 0) {
                goto fail;
            }
            if (trial) { /* the increments from rest (above) */
                rest = 1;
                hmax = range / incs;
                h = hmax / EQ_STIFFENED_FIRST;
            } else {
                h *= 0.5;
            }
            if (h < hmin)
                break;
        }
    }
    out->iterations = w->iterations;
    out->converged = s >= s_to && !out->canceled;
    /* converged: the last Newton step's residual is ||F|| at this q and s_to, the same value */
    out->residual = out->converged && incr > 0
                        ? w->residual
                        : eq_residual(m, q, out->converged ? s_to : out->last_s, w);
    if (!out->converged && !out->canceled)
        snprintf(out->message, sizeof out->message,
                 "no equilibrium beyond Omega = %.6g rad/s (target %.6g rad/s): %s",
                 sqrt(out->last_s), sqrt(s_to), why);
    if (carry && out->converged && have_lu) { /* the LU of the last Newton tangent, at s_to */
        carry->valid = 1;
        carry->s = s_to;
        carry->sign = sign;
    }
    if (!carry)
        eq_ws_free(w);
    return SM_OK;
fail:
    out->iterations = w->iterations;
    snprintf(out->message, sizeof out->message, "equilibrium at Omega = %.6g rad/s: %s", sqrt(s_to),
             sm_strerror(rc));
    if (!carry)
        eq_ws_free(w);
    return rc;
}

int eq_carry_new(const sm_model *m, eq_carry **out)
{
    eq_carry *c = calloc(1, sizeof *c);
    *out = NULL;
    if (!c)
        return SM_NOMEM;
    if (eq_ws_alloc(m, &c->w) < 0) {
        free(c);
        return SM_NOMEM;
    }
    *out = c;
    return SM_OK;
}

void eq_carry_free(eq_carry *c)
{
    if (!c)
        return;
    eq_ws_free(&c->w);
    free(c);
}
