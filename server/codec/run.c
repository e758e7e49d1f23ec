/*
 * run.c — the one place where a request becomes a result: model, solve,
 * documents (see run.h).
 *
 * How it fits: the CLI and the daemon's workers validate a request with the
 * codec, then call codec_run; it builds the core model, calls sm_solve with
 * the caller's progress/cancel callback (counting finished speeds on the
 * way), encodes the result JSON and/or CSV and, when something went wrong,
 * the error object a job stores (DAEMON.md: type, title, detail, errors,
 * diagnostics).  Helpers of this file are run_*.
 */
#include "codec.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Monotonic seconds. */
static double run_clock(void)
{
    struct timespec ts;

    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The caller's callback, and the number of speeds finished so far. */
typedef struct run_progress {
    sm_progress_fn cb;
    void *user;
    int done;
    int total;     /* speeds requested */
    int solves;    /* 1 + the refined levels of an error estimate: the speeds reported are
                      done/solves, so progress stays within the speeds and keeps rising */
} run_progress;

static int run_progress_cb(void *user, int done, int total)
{
    run_progress *p = user;

    p->done = p->solves > 1 ? done / p->solves : done;
    return p->cb ? p->cb(p->user, p->done, total) : 0;
}

/* The refined solves of an error estimate: speeds solved after the request's own. */
static int run_estimate_cb(void *user, int done, int total)
{
    run_progress *p = user;

    (void)total;
    return run_progress_cb(user, p->total + done, p->total);
}

/* While the model is built: no speed is done yet; the caller may stop it. */
static int run_build_cb(void *user, int built, int frames)
{
    run_progress *p = user;

    (void)built;
    (void)frames;
    return p->cb ? p->cb(p->user, 0, p->total) : 0;
}

/* Diagnostics object of a case without modes. */
static json_t *run_case_diag(const sm_case *c)
{
    return json_pack("{s:f, s:f, s:i, s:f, s:s}", "omega", c->omega, "last_omega",
                     c->last_omega, "iterations", c->iterations, "residual",
                     isfinite(c->residual) ? c->residual : -1.0, "message", c->message);
}

/* Set out->error (and message) for a failure; errors is stolen, may be NULL. */
static void run_fail(codec_run_out *out, codec_run_outcome outcome, const char *type,
                     const char *title, const char *detail, json_t *errors)
{
    out->outcome = outcome;
    snprintf(out->message, sizeof(out->message), "%s", detail);
    out->error = codec_job_error_text(type, title, detail, errors, NULL);
}

/* The errors of errs as JSON, or NULL when it holds none. */
static json_t *run_errors(const codec_errors *errs)
{
    return codec_errors_count(errs) > 0 ? codec_errors_to_json(errs) : NULL;
}

/*
 * A solved result: DONE, or PARTIAL with the error of the first speed
 * without modes (no equilibrium, or an eigen-analysis that failed after a
 * converged equilibrium).  Returns SM_OK or SM_NOMEM.
 */
static int run_outcome_of(const sm_result *res, codec_run_out *out)
{
    const sm_case *bad = NULL;
    int i, n_bad = 0, eigen;

    for (i = 0; i < res->n_cases; i++)
        if (res->cases[i].status == SM_CASE_NO_EQUILIBRIUM ||
            res->cases[i].status == SM_CASE_EIGEN_FAILED) {
            if (!bad)
                bad = &res->cases[i];
            n_bad++;
        }
    out->outcome = CODEC_RUN_DONE;
    if (!bad)
        return SM_OK;
    out->outcome = CODEC_RUN_PARTIAL;
    eigen = bad->status == SM_CASE_EIGEN_FAILED;
    snprintf(out->message, sizeof(out->message),
             "%s at %d of %d speeds, first at omega = %.6g rad/s "
             "(last speed reached %.6g rad/s): %s; the other speeds are in the result",
             eigen ? "no modes (the eigen-analysis failed at a converged equilibrium)"
                   : "no dynamic equilibrium",
             n_bad, res->n_cases, bad->omega, bad->last_omega, bad->message);
    out->error = codec_job_error_text(eigen ? "eigen_failed" : "no_equilibrium",
                                      eigen ? "Eigen-analysis failed" : "No dynamic equilibrium",
                                      out->message, NULL, run_case_diag(bad));
    return out->error ? SM_OK : SM_NOMEM;
}

/*
 * The documents of want for a solved result; SM_OK or SM_NOMEM.  The CSV (small) first, so
 * the text of a large result is the last thing allocated while the solver's numbers are held.
 */
static int run_encode(const codec_request *req, const sm_model *m, const sm_result *res,
                      unsigned want, codec_run_out *out)
{
    if ((want & CODEC_RUN_CSV) && codec_result_csv(&out->csv, &out->csv_len, req, res) != SM_OK)
        return SM_NOMEM;
    if ((want & CODEC_RUN_JSON) && codec_result_encode(&out->result, req, m, res) != SM_OK)
        return SM_NOMEM;
    if ((want & CODEC_RUN_TEXT) &&
        codec_result_text(&out->result_text, &out->result_len, req, m, res) != SM_OK)
        return SM_NOMEM;
    return run_outcome_of(res, out);
}

/*
 * analysis.error_estimate (DESIGN.md 9): sm_estimate on the refined levels the request was
 * validated for; fills res's error_estimate.  SM_OK, SM_NOMEM, or the outcome set in out
 * (canceled, failed) and its status.
 */
static int run_estimate(const codec_request *req, const sm_model *m, sm_result *res,
                        run_progress *prog, codec_run_out *out)
{
    sm_estimate_options eo;
    const double *speeds;
    char detail[400];
    sm_diag d;
    int n, st;

    sm_estimate_default_options(&eo);
    eo.levels = prog->solves - 1;
    speeds = codec_request_speeds(req, &n);
    memset(&d, 0, sizeof(d));
    st = sm_estimate(m, codec_request_structure(req), codec_request_options(req), speeds, n, &eo,
                     run_estimate_cb, prog, res, &d);
    out->status = st;
    if (st == SM_OK || st == SM_NOMEM)
        return st;
    out->speeds_done = prog->done;
    if (st == SM_CANCELED) {
        out->outcome = CODEC_RUN_CANCELED;
        return st;
    }
    snprintf(detail, sizeof(detail), "the error estimate failed: %s%s%s", sm_strerror(st),
             d.message[0] ? ": " : "", d.message);
    run_fail(out, CODEC_RUN_FAILED, "solver_error", "Error estimate failed", detail, NULL);
    return st;
}

codec_run_outcome codec_run(const codec_request *req, unsigned want, sm_progress_fn cb,
                            void *user, codec_errors *errs, codec_run_out *out)
{
    run_progress prog = {cb, user, 0, 0, 1};
    sm_model *m = NULL;
    sm_result *res = NULL;
    const double *speeds;
    char detail[400];
    double t0 = run_clock();
    sm_diag d;
    int n, st;

    memset(out, 0, sizeof(*out));
    out->seconds = -1;
    speeds = codec_request_speeds(req, &n);
    out->speeds_total = prog.total = n;
    prog.solves = 1 + codec_request_error_estimate(req);
    memset(&d, 0, sizeof(d));
    st = codec_model_build(&m, req, run_build_cb, &prog, errs, &d);
    out->seconds = run_clock() - t0;
    out->status = st;
    if (st == SM_NOMEM)
        goto nomem;
    if (st == SM_CANCELED) {
        out->outcome = CODEC_RUN_CANCELED;
        goto done;
    }
    if (st != SM_OK) {
        snprintf(detail, sizeof(detail), "the model could not be built: %s%s%s", sm_strerror(st),
                 d.message[0] ? ": " : "", d.message);
        run_fail(out, st == SM_INVALID_INPUT ? CODEC_RUN_INVALID : CODEC_RUN_FAILED,
                 st == SM_INVALID_INPUT ? "invalid" : "solver_error", "Model construction failed",
                 detail, run_errors(errs));
        goto done;
    }
    memset(&d, 0, sizeof(d));
    st = sm_solve(m, speeds, n, run_progress_cb, &prog, &res, &d);
    out->seconds = run_clock() - t0;
    out->status = st;
    out->speeds_done = st == SM_OK ? n : prog.done;
    if (st == SM_CANCELED) {
        out->outcome = CODEC_RUN_CANCELED;
        goto done;
    }
    if (st == SM_NOMEM)
        goto nomem;
    if (st != SM_OK) {
        snprintf(detail, sizeof(detail), "%s%s%s", sm_strerror(st), d.message[0] ? ": " : "",
                 d.message);
        if (st == SM_INVALID_INPUT && codec_diag_error(req, &d, errs) == SM_NOMEM)
            goto nomem;
        run_fail(out, st == SM_INVALID_INPUT ? CODEC_RUN_INVALID : CODEC_RUN_FAILED,
                 st == SM_INVALID_INPUT ? "invalid" : "solver_error", "Solver error", detail,
                 run_errors(errs));
        goto done;
    }
    if (prog.solves > 1) {
        st = run_estimate(req, m, res, &prog, out);
        out->seconds = run_clock() - t0;
        if (st == SM_NOMEM)
            goto nomem;
        if (st == SM_CANCELED) { /* every speed is solved: keep them, without the estimate */
            res->refine_stopped = 1;
            out->outcome = CODEC_RUN_DONE;
            out->status = SM_OK;
            out->speeds_done = n;
            st = SM_OK;
        }
        if (st != SM_OK)
            goto done;
    }
    if (run_encode(req, m, res, want, out) != SM_OK)
        goto nomem;
    goto done;
nomem:
    json_decref(out->result);
    free(out->result_text);
    free(out->csv);
    free(out->error);
    out->result = NULL;
    out->result_text = NULL;
    out->result_len = 0;
    out->csv = NULL;
    out->csv_len = 0;
    out->status = SM_NOMEM;
    run_fail(out, CODEC_RUN_NOMEM, "solver_error", "Out of memory",
             "the daemon ran out of memory running this job", NULL);
done:
    sm_result_free(res);
    sm_model_free(m);
    return out->outcome;
}

void codec_run_clear(codec_run_out *out)
{
    if (!out)
        return;
    json_decref(out->result);
    free(out->result_text);
    free(out->csv);
    free(out->error);
    memset(out, 0, sizeof(*out));
    out->seconds = -1;
}
