/*
 * http_analyses.c — the /v1/analyses routes of spinmodald and the end of a
 * POST (DAEMON.md): status, result, request, listing, cancel, validate and
 * submit,
 * with ?wait=S.
 *
 * How it fits: reads go through the job pool while it runs (live progress)
 * and to the store once the daemon stops; every document comes from the
 * codec (codec_job_status, codec_job_list, codec_validate_doc).  A POST body
 * is validated once by the codec; the model is built by the worker that
 * runs the job, never here.
 */
#include "elastodyn.h"
#include "http_internal.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* -------------------------------------------------------- status document */

/* Describe a stored job for the codec's documents; with_result links its result text. */
static codec_job_view http_view(const store_job *jb, int with_result)
{
    codec_job_view v;

    memset(&v, 0, sizeof(v));
    v.id = jb->id;
    v.state = store_state_name(jb->state);
    v.done = jb->state == STORE_DONE ? jb->speeds_total : jb->speeds_done;
    v.total = jb->speeds_total;
    v.created_at = jb->created_at;
    v.started_at = jb->started_at;
    v.finished_at = jb->finished_at;
    v.attempts = jb->attempts;
    v.cancel_requested = jb->cancel_requested;
    v.error = jb->error;
    v.name = jb->name;
    if (with_result && jb->result) {
        v.result = jb->result;
        v.result_len = jb->result_len;
    }
    return v;
}

/*
 * Read a job: through the pool (live progress) while it runs, from the
 * store once stopping.  Returns JOBS_OK, JOBS_NOT_FOUND or another jobs_rc.
 */
static int http_job_read(http *h, const char *id, unsigned flags, store_job *out)
{
    int rc;

    memset(out, 0, sizeof(*out));
    if (http_enter(h) == 0) {
        rc = jobs_get(h->j, id, flags, out);
        http_leave(h);
        return rc;
    }
    rc = store_get(h->st, id, flags, out);
    if (rc == STORE_OK)
        return JOBS_OK;
    return rc == STORE_NOT_FOUND ? JOBS_NOT_FOUND : rc == STORE_NOMEM ? JOBS_NOMEM : JOBS_STORE_ERROR;
}

static int http_unfinished(const store_job *jb)
{
    return jb->state == STORE_QUEUED || jb->state == STORE_RUNNING;
}

/*
 * The slices of a long poll w: wait in jobs_wait until the job in *out
 * (unfinished, read without texts) finishes, end (monotonic s) passes, the
 * daemon stops or w is released; *out is re-read after each slice.
 * JOBS_OK or the failure of a read.
 */
static int http_job_wait_slices(http *h, const char *id, double end, http_waiter *w,
                                store_job *out)
{
    double left;
    int rc, wrc;

    while (http_unfinished(out) && (left = end - http_mono()) > 0.0 &&
           !http_waiter_released(h, w)) {
        if (http_enter(h))
            break;
        wrc = jobs_wait(h->j, id, left < HTTP_WAIT_SLICE ? left : HTTP_WAIT_SLICE);
        http_leave(h);
        store_job_clear(out);
        rc = http_job_read(h, id, 0, out);
        if (rc != JOBS_OK)
            return rc;
        if (wrc != JOBS_OK) /* stopping, or the store failed: answer what we have */
            break;
    }
    return JOBS_OK;
}

/*
 * Read a job after waiting up to wait seconds for it to finish (in slices,
 * so a stop is never held up); flags as for jobs_get.  The wait is a long
 * poll of the --max-waiters budget: it ends early, with the job as it is,
 * when a newer long poll releases it (http_waiter_join).
 */
static int http_job_wait(http *h, const char *id, double wait, unsigned flags, store_job *out)
{
    double end = http_mono() + wait;
    int rc = http_job_read(h, id, wait > 0.0 ? 0u : flags, out);
    http_waiter w;

    if (rc != JOBS_OK || wait <= 0.0)
        return rc;
    if (http_unfinished(out) && http_waiter_join(h, &w) == 0) {
        rc = http_job_wait_slices(h, id, end, &w, out);
        http_waiter_leave(h, &w);
        if (rc != JOBS_OK)
            return rc;
    }
    if (flags && out->has_result) {
        store_job_clear(out);
        rc = http_job_read(h, id, flags, out);
    }
    return rc;
}

/*
 * Map a jobs_rc failure to a response: 404 for an unknown id, the
 * out-of-memory 503 for JOBS_NOMEM, 503 "database unavailable" for the
 * store, 503 "stopping" once the daemon stops.
 */
static enum MHD_Result http_jobs_failed(struct MHD_Connection *c, http_req *r, int rc)
{
    if (rc == JOBS_NOT_FOUND)
        return http_not_found(c, r, 1);
    if (rc == JOBS_NOMEM)
        return http_send_oom(c, r);
    if (rc == JOBS_STOPPING)
        return http_unavailable(c, r, "stopping");
    return http_unavailable(c, r, "unavailable");
}

/* ------------------------------------------------------ analyses routes */

/* Answer a status document of jb; status 202 adds Location. */
static enum MHD_Result http_send_status(struct MHD_Connection *c, http_req *r, int status,
                                        const store_job *jb)
{
    codec_text b = {0};
    char location[96];
    http_hdr loc = {MHD_HTTP_HEADER_LOCATION, location};

    codec_job_view v = http_view(jb, 1);

    snprintf(location, sizeof(location), "/v1/analyses/%s", jb->id);
    codec_job_status(&b, &v);
    return http_respond_buf(c, r, status, "application/json", &b, &loc,
                            status == MHD_HTTP_ACCEPTED ? 1 : 0);
}

/* ?wait=S into *wait (0 when absent); 0, or -1 after queueing a 400. */
int http_query_wait(struct MHD_Connection *c, http_req *r, double *wait,
                           enum MHD_Result *q)
{
    const char *v = NULL;

    *wait = 0.0;
    if (MHD_lookup_connection_value_n(c, MHD_GET_ARGUMENT_KIND, "wait", 4, &v, NULL) != MHD_YES)
        return 0;
    if (http_parse_seconds(v, HTTP_WAIT_MAX, wait) == 0)
        return 0;
    *q = http_bad_query(c, r, "wait", "must be a decimal number of seconds from 0 to 60");
    return -1;
}

/* GET /v1/analyses/{id}[?wait=S] */
enum MHD_Result http_get_analysis(struct MHD_Connection *c, http_req *r)
{
    enum MHD_Result q;
    store_job jb;
    double wait;
    int rc;

    if (!r->id_ok)
        return http_not_found(c, r, 1);
    if (http_query_wait(c, r, &wait, &q))
        return q;
    rc = http_job_wait(r->h, r->id, wait, STORE_WITH_RESULT, &jb);
    if (rc != JOBS_OK)
        q = http_jobs_failed(c, r, rc);
    else
        q = http_send_status(c, r, MHD_HTTP_OK, &jb);
    store_job_clear(&jb);
    return q;
}

/*
 * The stored result document text[len] as span-wise shapes (codec_result_spanwise: bmodes 0
 * CSV, 1 the BModes-style table; 409 for a result without them: planar, or without mode
 * shapes) or, bmodes 2, its critical speeds (codec_critical_speeds_csv: the header alone
 * without engine_orders), or, bmodes 3, the ElastoDyn blade coefficients
 * (codec_result_elastodyn, text; 409 no-elastodyn-shapes without a blade's shapes and
 * energies); takes text.
 */
static enum MHD_Result http_spanwise(struct MHD_Connection *c, http_req *r, char *text,
                                     size_t len, int bmodes)
{
    json_t *doc = json_loadb(text, len, 0, NULL);
    char *out = NULL, why[256];
    size_t n = 0;
    int st = !doc          ? SM_NOMEM
             : bmodes == 2 ? codec_critical_speeds_csv(&out, &n, doc)
             : bmodes == 3 ? codec_result_elastodyn(&out, &n, doc, why, sizeof why)
                           : codec_result_spanwise(&out, &n, doc, bmodes, why, sizeof why);

    json_decref(doc);
    free(text);
    if (st == SM_INVALID_INPUT && bmodes == 3)
        return http_problem(c, r, MHD_HTTP_CONFLICT, "no-elastodyn-shapes", "No ElastoDyn Shapes",
                            why, NULL, 0);
    if (st == SM_INVALID_INPUT)
        return http_problem(c, r, MHD_HTTP_CONFLICT, "no-spanwise-shapes",
                            "No Span-wise Shapes", why, NULL, 0);
    if (st)
        return http_problem(c, r, MHD_HTTP_SERVICE_UNAVAILABLE, "out-of-memory",
                            "Out Of Memory", "The shapes could not be written.", NULL, 0);
    return http_respond(c, r, MHD_HTTP_OK,
                        bmodes == 1 || bmodes == 3 ? "text/plain; charset=utf-8"
                                                   : "text/csv; charset=utf-8",
                        out, n, 1, NULL, 0);
}

/* GET /v1/analyses/{id}/result[?format=json|csv|spanwise|bmodes|critical|elastodyn] */
enum MHD_Result http_get_result(struct MHD_Connection *c, http_req *r)
{
    const char *format = NULL;
    enum MHD_Result q;
    store_job jb;
    char *text;
    size_t len;
    int csv = 0, rc, shapes = -1; /* -1 no, 0 span-wise CSV, 1 BModes table, 2 critical,
                                     3 ElastoDyn */

    if (!r->id_ok)
        return http_not_found(c, r, 1);
    if (MHD_lookup_connection_value_n(c, MHD_GET_ARGUMENT_KIND, "format", 6, &format, NULL) ==
        MHD_YES) {
        csv = format && strcmp(format, "csv") == 0;
        if (format && !strcmp(format, "spanwise"))
            shapes = 0;
        else if (format && !strcmp(format, "bmodes"))
            shapes = 1;
        else if (format && !strcmp(format, "critical"))
            shapes = 2;
        else if (format && !strcmp(format, "elastodyn"))
            shapes = 3;
        else if (!format || (!csv && strcmp(format, "json") != 0))
            return http_bad_query(c, r, "format",
                                  "must be json, csv, spanwise, bmodes, critical or elastodyn");
    }
    rc = http_job_read(r->h, r->id, csv ? STORE_WITH_CSV : STORE_WITH_RESULT, &jb);
    if (rc != JOBS_OK) {
        store_job_clear(&jb);
        return http_jobs_failed(c, r, rc);
    }
    text = csv ? jb.result_csv : jb.result;
    len = csv ? jb.csv_len : jb.result_len;
    if (!jb.has_result || !text) {
        char detail[96];
        snprintf(detail, sizeof(detail), "The job is %s and has no result%s.",
                 store_state_name(jb.state), http_unfinished(&jb) ? " yet" : "");
        store_job_clear(&jb);
        return http_problem(c, r, MHD_HTTP_CONFLICT, "result-not-available",
                            "Result Not Available", detail, NULL, 0);
    }
    if (csv)
        jb.result_csv = NULL; /* handed to libmicrohttpd */
    else
        jb.result = NULL;
    if (shapes >= 0) {
        store_job_clear(&jb);
        return http_spanwise(c, r, text, len, shapes);
    }
    q = http_respond(c, r, MHD_HTTP_OK, csv ? "text/csv; charset=utf-8" : "application/json",
                     text, len, 1, NULL, 0);
    store_job_clear(&jb);
    return q;
}

/*
 * GET /v1/analyses/{id}/request: the canonical request the job was
 * submitted as (defaults applied, keys sorted: the text its id is the
 * SHA-256 of), verbatim from the store, in any state.  POSTing it back
 * gives the same job.  404 for an unknown id (also once retention removed
 * it); the token rules are those of GET /v1/analyses/{id}.
 */
enum MHD_Result http_get_request(struct MHD_Connection *c, http_req *r)
{
    enum MHD_Result q;
    store_job jb;
    char *text;
    size_t len;
    int rc;

    if (!r->id_ok)
        return http_not_found(c, r, 1);
    rc = http_job_read(r->h, r->id, STORE_WITH_REQUEST, &jb);
    if (rc != JOBS_OK) {
        store_job_clear(&jb);
        return http_jobs_failed(c, r, rc);
    }
    if (!jb.request) { /* a store always keeps it: treat a missing text as a store fault */
        store_job_clear(&jb);
        return http_unavailable(c, r, "unavailable");
    }
    text = jb.request;
    len = jb.request_len;
    jb.request = NULL; /* handed to libmicrohttpd */
    q = http_respond(c, r, MHD_HTTP_OK, "application/json", text, len, 1, NULL, 0);
    store_job_clear(&jb);
    return q;
}

/* The listing's "next" link into next[cap]. */
static void http_list_next(char *next, size_t cap, long long limit, long long last_seq,
                           int filter)
{
    int n = snprintf(next, cap, "/v1/analyses?limit=%lld&before=%lld", limit, last_seq);

    if (filter >= 0 && n > 0 && (size_t)n < cap)
        snprintf(next + n, cap - (size_t)n, "&state=%s", store_state_name((store_state)filter));
}

/* Fill the live progress of the running jobs of a listing (best effort). */
static void http_list_progress(http *h, store_job *items, int n)
{
    store_job live;
    int i;

    for (i = 0; i < n; i++) {
        if (items[i].state != STORE_RUNNING || http_enter(h))
            continue;
        memset(&live, 0, sizeof(live));
        if (jobs_get(h->j, items[i].id, 0, &live) == JOBS_OK && live.state == STORE_RUNNING)
            items[i].speeds_done = live.speeds_done;
        http_leave(h);
        store_job_clear(&live);
    }
}

/* Parse the query of a listing; 0, or -1 after queueing a 400. */
static int http_list_query(struct MHD_Connection *c, http_req *r, long long *limit,
                           long long *before, int *filter, enum MHD_Result *q)
{
    const char *v = NULL;
    store_state s;

    *limit = HTTP_LIST_DEFAULT;
    *before = 0;
    *filter = -1;
    if (MHD_lookup_connection_value_n(c, MHD_GET_ARGUMENT_KIND, "limit", 5, &v, NULL) ==
            MHD_YES &&
        http_parse_int(v, 1, HTTP_LIST_MAX, limit)) {
        *q = http_bad_query(c, r, "limit", "must be an integer from 1 to 100");
        return -1;
    }
    if (MHD_lookup_connection_value_n(c, MHD_GET_ARGUMENT_KIND, "before", 6, &v, NULL) ==
            MHD_YES &&
        http_parse_int(v, 1, LLONG_MAX / 16, before)) {
        *q = http_bad_query(c, r, "before", "must be a positive integer (a job's seq)");
        return -1;
    }
    if (MHD_lookup_connection_value_n(c, MHD_GET_ARGUMENT_KIND, "state", 5, &v, NULL) ==
        MHD_YES) {
        if (!v || store_state_parse(v, &s) != STORE_OK) {
            *q = http_bad_query(c, r, "state",
                                "must be queued, running, done, failed or canceled");
            return -1;
        }
        *filter = (int)s;
    }
    return 0;
}

/* GET /v1/analyses[?limit=N&before=SEQ&state=S] */
enum MHD_Result http_list(struct MHD_Connection *c, http_req *r)
{
    long long limit, before;
    int filter, n = 0, more = 0, i, rc;
    store_job *items;
    codec_job_view *views;
    enum MHD_Result q;
    codec_text b = {0};
    char next[160];

    if (http_list_query(c, r, &limit, &before, &filter, &q))
        return q;
    items = calloc((size_t)limit, sizeof(*items));
    views = calloc((size_t)limit, sizeof(*views));
    if (!items || !views) {
        free(items);
        free(views);
        return http_send_oom(c, r);
    }
    rc = store_list(r->h->st, before, filter, (int)limit, items, &n, &more);
    if (rc != STORE_OK) {
        q = rc == STORE_NOMEM ? http_send_oom(c, r) : http_unavailable(c, r, "unavailable");
        goto done;
    }
    http_list_progress(r->h, items, n);
    for (i = 0; i < n; i++)
        views[i] = http_view(&items[i], 0);
    if (more && n > 0)
        http_list_next(next, sizeof(next), limit, items[n - 1].seq, filter);
    codec_job_list(&b, views, n, more && n > 0 ? next : NULL);
    q = http_respond_buf(c, r, MHD_HTTP_OK, "application/json", &b, NULL, 0);
done:
    for (i = 0; i < n; i++)
        store_job_clear(&items[i]);
    free(items);
    free(views);
    return q;
}

/* DELETE /v1/analyses/{id} */
enum MHD_Result http_delete(struct MHD_Connection *c, http_req *r)
{
    enum MHD_Result q;
    store_job jb;
    char detail[64];
    int rc;

    if (!r->id_ok)
        return http_not_found(c, r, 1);
    if (http_enter(r->h))
        return http_unavailable(c, r, "stopping");
    memset(&jb, 0, sizeof(jb));
    rc = jobs_cancel(r->h->j, r->id, &jb);
    http_leave(r->h);
    if (rc == JOBS_OK) {
        q = http_send_status(c, r, jb.state == STORE_CANCELED ? MHD_HTTP_OK : MHD_HTTP_ACCEPTED,
                             &jb);
    } else if (rc == JOBS_CONFLICT) {
        snprintf(detail, sizeof(detail), "The job is already %s.", store_state_name(jb.state));
        q = http_problem(c, r, MHD_HTTP_CONFLICT, "job-finished", "Job Already Finished", detail,
                         NULL, 0);
    } else {
        q = http_jobs_failed(c, r, rc);
    }
    store_job_clear(&jb);
    return q;
}

static enum MHD_Result http_submit(struct MHD_Connection *c, http_req *r,
                                   const codec_request *req)
{
    http_hdr retry = {MHD_HTTP_HEADER_RETRY_AFTER, HTTP_RETRY_BUSY};
    jobs_outcome outcome;
    enum MHD_Result q;
    store_job jb;
    int rc;

    if (http_enter(r->h))
        return http_unavailable(c, r, "stopping");
    memset(&jb, 0, sizeof(jb));
    rc = jobs_submit(r->h->j, req, &outcome, &jb);
    http_leave(r->h);
    if (rc != JOBS_OK)
        store_job_clear(&jb);
    if (rc == JOBS_FULL)
        return http_problem(c, r, MHD_HTTP_TOO_MANY_REQUESTS, "queue-full", "Too Many Requests",
                            "The queue of analyses is full; retry later.", &retry, 1);
    if (rc != JOBS_OK)
        return http_jobs_failed(c, r, rc);
    memcpy(r->id, jb.id, sizeof(r->id));
    r->id[64] = '\0';
    if (r->wait > 0.0 || !http_unfinished(&jb)) {
        store_job_clear(&jb);
        rc = http_job_wait(r->h, r->id, r->wait, STORE_WITH_RESULT, &jb);
        if (rc != JOBS_OK) {
            store_job_clear(&jb);
            return http_jobs_failed(c, r, rc);
        }
    }
    q = http_send_status(c, r, http_unfinished(&jb) ? MHD_HTTP_ACCEPTED : MHD_HTTP_OK, &jb);
    store_job_clear(&jb);
    return q;
}

/* POST /v1/validate of a valid request: its id, SHA-256 and canonical form. */
static enum MHD_Result http_validated(struct MHD_Connection *c, http_req *r,
                                      const codec_request *req)
{
    codec_text b = {0};
    char id[65];

    if (codec_job_id(req, id) != SM_OK)
        return http_send_oom(c, r);
    codec_validate_doc(&b, id, req);
    return http_respond_buf(c, r, MHD_HTTP_OK, "application/json", &b, NULL, 0);
}

/* The whole body of a POST is in: validate, then submit or describe, answer. */
enum MHD_Result http_post_end(struct MHD_Connection *c, http_req *r)
{
    codec_request *req = NULL;
    codec_errors *errs;
    enum MHD_Result q;
    int rc;

    if (r->body_state == BODY_TOO_LARGE)
        return http_too_large(c, r);
    if (r->body_state == BODY_NOMEM)
        return http_send_oom(c, r);
    errs = codec_errors_new();
    if (!errs)
        return http_send_oom(c, r);
    rc = codec_request_parse(&req, r->body ? r->body : "", r->len, &r->h->limits, errs);
    free(r->body);
    r->body = NULL;
    if (rc == SM_OK && r->route == R_VALIDATE)
        q = http_validated(c, r, req);
    else if (rc == SM_OK)
        q = http_submit(c, r, req);
    else if (rc != SM_NOMEM && codec_errors_count(errs) > 0)
        q = http_respond_problem(c, r, codec_errors_http_status(errs),
                                 codec_problem_from_errors(errs), NULL, 0);
    else
        q = http_send_oom(c, r);
    codec_request_free(req);
    codec_errors_free(errs);
    return q;
}
