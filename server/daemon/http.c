/*
 * http.c — the HTTP front of spinmodald (see http.h and server/DAEMON.md).
 *
 * How it fits: libmicrohttpd runs one thread per connection and calls
 * http_handler in three phases (libmicrohttpd's simplepost.c shape):
 *   1. headers received: *req_cls is NULL; allocate the request context
 *      and route it.  Only refusals of a body are answered here (401, 400
 *      ?wait, 415, 413 by Content-Length, or any answer to a non-POST that
 *      carries a body): libmicrohttpd then closes the connection without
 *      reading the body.  Everything else waits for phase 3 so the
 *      connection stays alive;
 *   2. body data of POST /v1/analyses and /v1/validate: appended to the
 *      context's buffer, capped at --max-body (over it: 413 at once, see
 *      http_early_too_large);
 *   3. request complete (*upload_data_size == 0): answer GET/HEAD/DELETE/
 *      OPTIONS, or validate the POST body with the codec, submit it to the
 *      job pool, optionally wait, answer.
 * http_completed (MHD_OPTION_NOTIFY_COMPLETED) counts the response in the
 * metrics, logs the `request` line and frees the context.
 *
 * Status documents are written by hand (every field is a number, a fixed
 * word, a hex id or a timestamp) and the stored error and result texts are
 * spliced in verbatim, so a GET of a finished job costs one store read and
 * one copy.  Bodies are handed to libmicrohttpd with a free callback (no
 * second copy).  Any allocation or store failure answers 503 +
 * Retry-After; if even that cannot be built, a static 503 is sent.
 *
 * Stop: http_begin_stop sets `stopping` and waits until no thread is
 * inside a jobs_* call (calls are bracketed by http_enter/http_leave and
 * waits are sliced), so the pool can then be freed by jobs_stop while the
 * server still answers status reads from the store.
 */
#include "http.h"

#include <errno.h>
#include <limits.h>
#include <netdb.h>
#include <poll.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <time.h>

#include <microhttpd.h>

#include "embedded.h"
#include "log.h"

#define HTTP_WAIT_MAX 60.0         /* s, largest ?wait= */
#define HTTP_WAIT_SLICE 0.25       /* s, longest single jobs_wait (bounds http_begin_stop) */
#define HTTP_LIST_DEFAULT 20       /* ?limit= default */
#define HTTP_LIST_MAX 100          /* ?limit= maximum */
#define HTTP_BODY_CHUNK 65536      /* first body allocation when Content-Length is unknown */
#define HTTP_RETRY_BUSY "5"        /* Retry-After of 429 and of 503 while stopping */
#define HTTP_RETRY_FAULT "1"       /* Retry-After of 503 for store/memory failures */
#define HTTP_PROBLEMS "https://spinmodal.dev/problems/"

/* Methods as bits, for the Allow header and route checks. */
enum {
    M_GET = 1,
    M_HEAD = 2,
    M_POST = 4,
    M_DELETE = 8,
    M_OPTIONS = 16,
    M_OTHER = 32
};

/* Routes of DAEMON.md. */
typedef enum http_route {
    R_OTHER = 0,     /* no route: 404 */
    R_ANALYSES,      /* /v1/analyses */
    R_VALIDATE,      /* /v1/validate */
    R_ANALYSIS,      /* /v1/analyses/{id} */
    R_RESULT,        /* /v1/analyses/{id}/result */
    R_LIVEZ,
    R_READYZ,
    R_METRICS,
    R_FILE           /* an embedded file (schemas, OpenAPI, /) */
} http_route;

/* State of the body of a POST. */
enum { BODY_OK = 0, BODY_TOO_LARGE = 1, BODY_NOMEM = 2 };

struct http {
    struct MHD_Daemon *d;
    jobs *j;                 /* borrowed; not touched after http_begin_stop */
    store *st;               /* borrowed */
    metrics *mx;             /* borrowed */
    size_t max_body;         /* bytes */
    codec_limits limits;     /* request validation */
    char *cors_origin;       /* NULL = no CORS */
    char token_hash[65];     /* SHA-256 hex of the bearer token, "" = no auth */
    int port;                /* bound port */
    pthread_mutex_t lock;    /* guards stopping and active */
    pthread_cond_t idle;     /* signaled when active drops to 0 while stopping */
    int stopping;            /* http_begin_stop has begun */
    int active;              /* request threads inside a jobs_* call */
};

/* Per-request context (*req_cls), from the first call to http_completed. */
typedef struct http_req {
    http *h;
    double t0;               /* monotonic s when the headers were received */
    http_route route;
    const char *tmpl;        /* route template for the metrics (static or embedded path) */
    const embedded_file *file; /* R_FILE */
    unsigned method;         /* M_* */
    char method_name[16];    /* for the log, sanitized */
    char path[200];          /* for the log, sanitized, truncated */
    char id[65];             /* job id of the path or of a submission, "" = none */
    int id_ok;               /* the {id} of the path is 64 lowercase hex digits */
    int status;              /* status queued, 0 = none yet */
    size_t bytes;            /* response body bytes sent (0 for HEAD) */
    double wait;             /* ?wait= of a POST, s */
    char *body;              /* POST body received so far (malloc'd) */
    size_t len, cap;         /* bytes in body, bytes allocated */
    size_t announced;        /* Content-Length of a POST, 0 = none */
    int body_state;          /* BODY_* */
    int collect;             /* a POST whose body is read (phase 2) */
    int raw_answer;          /* answered on the socket by http_early_too_large */
} http_req;

/* A response header. */
typedef struct http_hdr {
    const char *name;
    const char *value;
} http_hdr;

static const char http_oom_body[] =
    "{\"type\":\"" HTTP_PROBLEMS "unavailable\",\"title\":\"Service Unavailable\","
    "\"status\":503,\"detail\":\"The server is out of memory; retry later.\"}";

/* ------------------------------------------------------------ utilities */

static double http_mono(void)
{
    struct timespec ts;

    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Copy s into dst (cap bytes), keeping printable ASCII, '?' for the rest. */
static void http_sanitize(char *dst, size_t cap, const char *s)
{
    size_t i;

    for (i = 0; s && s[i] && i + 1 < cap; i++)
        dst[i] = (s[i] > 0x20 && s[i] < 0x7f) ? s[i] : '?';
    dst[i] = '\0';
}

/* 1 when s is exactly 64 lowercase hex digits. */
static int http_is_id(const char *s, size_t len)
{
    size_t i;

    if (len != 64)
        return 0;
    for (i = 0; i < len; i++)
        if (!((s[i] >= '0' && s[i] <= '9') || (s[i] >= 'a' && s[i] <= 'f')))
            return 0;
    return 1;
}

/* Decimal integer in [lo, hi] (digits only); 0 or -1. */
static int http_parse_int(const char *s, long long lo, long long hi, long long *out)
{
    long long v = 0;
    size_t i;

    if (!s || !*s || strlen(s) > 18)
        return -1;
    for (i = 0; s[i]; i++) {
        if (s[i] < '0' || s[i] > '9')
            return -1;
        v = v * 10 + (s[i] - '0');
    }
    if (v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

/* Decimal number (digits with at most one '.') in [0, hi]; 0 or -1. */
static int http_parse_seconds(const char *s, double hi, double *out)
{
    size_t i, digits = 0, dots = 0;
    double v;

    if (!s || !*s || strlen(s) > 24)
        return -1;
    for (i = 0; s[i]; i++) {
        if (s[i] >= '0' && s[i] <= '9')
            digits++;
        else if (s[i] == '.' && dots++ == 0)
            continue;
        else
            return -1;
    }
    if (!digits)
        return -1;
    v = strtod(s, NULL);
    if (!(v >= 0.0 && v <= hi))
        return -1;
    *out = v;
    return 0;
}

/* Constant-time comparison of n bytes; 1 when equal. */
static int http_ct_equal(const char *a, const char *b, size_t n)
{
    volatile unsigned char d = 0;
    size_t i;

    for (i = 0; i < n; i++)
        d |= (unsigned char)(a[i] ^ b[i]);
    return d == 0;
}

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
    if (with_result && jb->result) {
        v.result = jb->result;
        v.result_len = jb->result_len;
    }
    return v;
}

/* ------------------------------------------------------------ responses */

/* Queue the static out-of-memory 503; the last resort. */
static enum MHD_Result http_send_oom(struct MHD_Connection *c, http_req *r)
{
    struct MHD_Response *resp;
    enum MHD_Result q;

    resp = MHD_create_response_from_buffer(sizeof(http_oom_body) - 1, (void *)http_oom_body,
                                           MHD_RESPMEM_PERSISTENT);
    if (!resp)
        return MHD_NO;
    if (MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE,
                                "application/problem+json") != MHD_YES ||
        MHD_add_response_header(resp, MHD_HTTP_HEADER_RETRY_AFTER, HTTP_RETRY_FAULT) !=
            MHD_YES) {
        MHD_destroy_response(resp);
        return MHD_NO;
    }
    q = MHD_queue_response(c, MHD_HTTP_SERVICE_UNAVAILABLE, resp);
    MHD_destroy_response(resp);
    if (r && q == MHD_YES) {
        r->status = MHD_HTTP_SERVICE_UNAVAILABLE;
        r->bytes = r->method == M_HEAD ? 0 : sizeof(http_oom_body) - 1;
    }
    return q;
}

/* Add ctype, the CORS headers and hdrs[0..n) to resp; 0 or -1. */
static int http_add_headers(http_req *r, struct MHD_Response *resp, const char *ctype,
                            const http_hdr *hdrs, int n)
{
    int i;

    if (ctype && MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, ctype) != MHD_YES)
        return -1;
    if (r->h->cors_origin &&
        (MHD_add_response_header(resp, MHD_HTTP_HEADER_ACCESS_CONTROL_ALLOW_ORIGIN,
                                 r->h->cors_origin) != MHD_YES ||
         MHD_add_response_header(resp, "Access-Control-Expose-Headers",
                                 "Location, Retry-After, WWW-Authenticate") != MHD_YES))
        return -1;
    for (i = 0; i < n; i++)
        if (MHD_add_response_header(resp, hdrs[i].name, hdrs[i].value) != MHD_YES)
            return -1;
    return 0;
}

/*
 * Queue a response.  body (len bytes) is freed with free() after sending
 * when own is 1, or is static when own is 0; body NULL means no body.
 * On any failure body is freed (if owned) and the static 503 is sent.
 */
static enum MHD_Result http_respond(struct MHD_Connection *c, http_req *r, int status,
                                    const char *ctype, char *body, size_t len, int own,
                                    const http_hdr *hdrs, int n)
{
    struct MHD_Response *resp;
    enum MHD_Result q;

    if (!body)
        resp = MHD_create_response_from_buffer(0, (void *)"", MHD_RESPMEM_PERSISTENT);
    else if (own)
        resp = MHD_create_response_from_buffer_with_free_callback(len, body, &free);
    else
        resp = MHD_create_response_from_buffer(len, body, MHD_RESPMEM_PERSISTENT);
    if (!resp) {
        if (own)
            free(body);
        return http_send_oom(c, r);
    }
    if (http_add_headers(r, resp, ctype, hdrs, n)) {
        MHD_destroy_response(resp); /* frees an owned body through the callback */
        return http_send_oom(c, r);
    }
    q = MHD_queue_response(c, (unsigned)status, resp);
    MHD_destroy_response(resp);
    if (q == MHD_YES) {
        r->status = status;
        r->bytes = (body && r->method != M_HEAD) ? len : 0;
    }
    return q;
}

/* Queue a JSON document held in b (taken); 503 when b ran out of memory. */
static enum MHD_Result http_respond_buf(struct MHD_Connection *c, http_req *r, int status,
                                        const char *ctype, codec_text *b, const http_hdr *hdrs,
                                        int n)
{
    if (b->nomem || !b->p) {
        free(b->p);
        return http_send_oom(c, r);
    }
    return http_respond(c, r, status, ctype, b->p, b->len, 1, hdrs, n);
}

/* Queue the problem document p (taken; NULL = out of memory). */
static enum MHD_Result http_respond_problem(struct MHD_Connection *c, http_req *r, int status,
                                            json_t *p, const http_hdr *hdrs, int n)
{
    char *text;

    if (!p)
        return http_send_oom(c, r);
    text = json_dumps(p, JSON_COMPACT);
    json_decref(p);
    if (!text)
        return http_send_oom(c, r);
    return http_respond(c, r, status, "application/problem+json", text, strlen(text), 1, hdrs,
                        n);
}

/* Queue a problem document; type_name NULL = about:blank. */
static enum MHD_Result http_problem(struct MHD_Connection *c, http_req *r, int status,
                                    const char *type_name, const char *title,
                                    const char *detail, const http_hdr *hdrs, int n)
{
    char type[96];

    if (type_name)
        snprintf(type, sizeof(type), HTTP_PROBLEMS "%s", type_name);
    return http_respond_problem(c, r, status,
                                codec_problem_new(status, type_name ? type : NULL, title,
                                                  detail, NULL),
                                hdrs, n);
}

/* 503 + Retry-After: why is "stopping" (the daemon stops) or "unavailable" (store, memory). */
static enum MHD_Result http_unavailable(struct MHD_Connection *c, http_req *r, const char *why)
{
    int stopping = strcmp(why, "stopping") == 0;
    http_hdr retry = {MHD_HTTP_HEADER_RETRY_AFTER, stopping ? HTTP_RETRY_BUSY : HTTP_RETRY_FAULT};

    return http_problem(c, r, MHD_HTTP_SERVICE_UNAVAILABLE, why, "Service Unavailable",
                        stopping ? "The daemon is stopping; retry later."
                                 : "The database is unavailable; retry later.",
                        &retry, 1);
}

/* 400 for query parameter name, with pointer /query/<name>. */
static enum MHD_Result http_bad_query(struct MHD_Connection *c, http_req *r, const char *name,
                                      const char *message)
{
    codec_errors *errs = codec_errors_new();
    char pointer[32], detail[80];
    json_t *p = NULL;

    snprintf(pointer, sizeof(pointer), "/query/%s", name);
    snprintf(detail, sizeof(detail), "The query parameter '%s' is not valid.", name);
    if (errs && codec_errors_add(errs, pointer, "%s", message) == SM_OK)
        p = codec_problem_new(MHD_HTTP_BAD_REQUEST, NULL, "Bad Request", detail, errs);
    codec_errors_free(errs);
    return http_respond_problem(c, r, MHD_HTTP_BAD_REQUEST, p, NULL, 0);
}

static enum MHD_Result http_not_found(struct MHD_Connection *c, http_req *r, int is_id)
{
    return http_problem(c, r, MHD_HTTP_NOT_FOUND, NULL, "Not Found",
                        is_id ? "No analysis has this id." : "No route matches this path.",
                        NULL, 0);
}

/* The value of Allow for a route's methods. */
static const char *http_allow(const http *h, unsigned methods)
{
    if ((methods & M_POST) && (methods & M_DELETE))
        return "GET, HEAD, POST, DELETE";
    if (methods == M_POST)
        return h->cors_origin ? "POST, OPTIONS" : "POST";
    if (methods & M_POST)
        return h->cors_origin ? "GET, HEAD, POST, OPTIONS" : "GET, HEAD, POST";
    if (methods & M_DELETE)
        return h->cors_origin ? "GET, HEAD, DELETE, OPTIONS" : "GET, HEAD, DELETE";
    return h->cors_origin ? "GET, HEAD, OPTIONS" : "GET, HEAD";
}

static enum MHD_Result http_not_allowed(struct MHD_Connection *c, http_req *r, unsigned methods)
{
    http_hdr allow = {MHD_HTTP_HEADER_ALLOW, http_allow(r->h, methods)};
    char detail[80];

    snprintf(detail, sizeof(detail), "This route allows %s.", allow.value);
    return http_problem(c, r, MHD_HTTP_METHOD_NOT_ALLOWED, NULL, "Method Not Allowed", detail,
                        &allow, 1);
}

/* ------------------------------------------------- the job pool, guarded */

/* Enter a jobs_* call: 0, or -1 once http_begin_stop has begun. */
static int http_enter(http *h)
{
    int rc = 0;

    pthread_mutex_lock(&h->lock);
    if (h->stopping)
        rc = -1;
    else
        h->active++;
    pthread_mutex_unlock(&h->lock);
    return rc;
}

static void http_leave(http *h)
{
    pthread_mutex_lock(&h->lock);
    if (--h->active == 0 && h->stopping)
        pthread_cond_broadcast(&h->idle);
    pthread_mutex_unlock(&h->lock);
}

static int http_is_stopping(http *h)
{
    int s;

    pthread_mutex_lock(&h->lock);
    s = h->stopping;
    pthread_mutex_unlock(&h->lock);
    return s;
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
    return rc == STORE_NOT_FOUND ? JOBS_NOT_FOUND : JOBS_STORE_ERROR;
}

static int http_unfinished(const store_job *jb)
{
    return jb->state == STORE_QUEUED || jb->state == STORE_RUNNING;
}

/*
 * Read a job after waiting up to wait seconds for it to finish (in slices,
 * so a stop is never held up); flags as for jobs_get.
 */
static int http_job_wait(http *h, const char *id, double wait, unsigned flags, store_job *out)
{
    double end = http_mono() + wait, left;
    int rc = http_job_read(h, id, wait > 0.0 ? 0u : flags, out), wrc;

    if (rc != JOBS_OK || wait <= 0.0)
        return rc;
    while (http_unfinished(out) && (left = end - http_mono()) > 0.0) {
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
    if (flags && out->has_result) {
        store_job_clear(out);
        rc = http_job_read(h, id, flags, out);
    }
    return rc;
}

/* Map a jobs_rc failure of a read to a response. */
static enum MHD_Result http_read_failed(struct MHD_Connection *c, http_req *r, int rc)
{
    if (rc == JOBS_NOT_FOUND)
        return http_not_found(c, r, 1);
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
static int http_query_wait(struct MHD_Connection *c, http_req *r, double *wait,
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
static enum MHD_Result http_get_analysis(struct MHD_Connection *c, http_req *r)
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
        q = http_read_failed(c, r, rc);
    else
        q = http_send_status(c, r, MHD_HTTP_OK, &jb);
    store_job_clear(&jb);
    return q;
}

/* GET /v1/analyses/{id}/result[?format=json|csv] */
static enum MHD_Result http_get_result(struct MHD_Connection *c, http_req *r)
{
    const char *format = NULL;
    enum MHD_Result q;
    store_job jb;
    char *text;
    size_t len;
    int csv = 0, rc;

    if (!r->id_ok)
        return http_not_found(c, r, 1);
    if (MHD_lookup_connection_value_n(c, MHD_GET_ARGUMENT_KIND, "format", 6, &format, NULL) ==
        MHD_YES) {
        csv = format && strcmp(format, "csv") == 0;
        if (!format || (!csv && strcmp(format, "json") != 0))
            return http_bad_query(c, r, "format", "must be json or csv");
    }
    rc = http_job_read(r->h, r->id, csv ? STORE_WITH_CSV : STORE_WITH_RESULT, &jb);
    if (rc != JOBS_OK) {
        store_job_clear(&jb);
        return http_read_failed(c, r, rc);
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
    q = http_respond(c, r, MHD_HTTP_OK, csv ? "text/csv; charset=utf-8" : "application/json",
                     text, len, 1, NULL, 0);
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
static enum MHD_Result http_list(struct MHD_Connection *c, http_req *r)
{
    long long limit, before;
    int filter, n = 0, more = 0, i;
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
    if (store_list(r->h->st, before, filter, (int)limit, items, &n, &more) != STORE_OK) {
        q = http_unavailable(c, r, "unavailable");
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
static enum MHD_Result http_delete(struct MHD_Connection *c, http_req *r)
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
        q = http_read_failed(c, r, rc);
    }
    store_job_clear(&jb);
    return q;
}

/* ------------------------------------------------------------------ POST */

/* 1 when the bearer token of the request is the configured one (or none is). */
static int http_authorized(const http *h, struct MHD_Connection *c)
{
    const char *v;
    char hex[65];
    size_t len;

    if (!h->token_hash[0])
        return 1;
    v = MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_AUTHORIZATION);
    if (!v || strncasecmp(v, "Bearer ", 7) != 0)
        return 0;
    for (v += 7; *v == ' '; v++)
        ;
    len = strlen(v);
    while (len > 0 && (v[len - 1] == ' ' || v[len - 1] == '\t'))
        len--;
    if (len == 0 || codec_sha256_hex(v, len, hex) != SM_OK)
        return 0;
    return http_ct_equal(hex, h->token_hash, 64);
}

static enum MHD_Result http_unauthorized(struct MHD_Connection *c, http_req *r)
{
    int given = MHD_lookup_connection_value(c, MHD_HEADER_KIND,
                                            MHD_HTTP_HEADER_AUTHORIZATION) != NULL;
    http_hdr www = {MHD_HTTP_HEADER_WWW_AUTHENTICATE,
                    given ? "Bearer realm=\"spinmodal\", error=\"invalid_token\""
                          : "Bearer realm=\"spinmodal\""};

    return http_problem(c, r, MHD_HTTP_UNAUTHORIZED, NULL, "Unauthorized",
                        "This request needs the header 'Authorization: Bearer <token>' with the "
                        "daemon's token.",
                        &www, 1);
}

/* 1 when Content-Type is application/json (charset, if any, utf-8). */
static int http_is_json(const char *ct)
{
    const char *p, *v;
    size_t n;

    if (!ct)
        return 0;
    while (*ct == ' ' || *ct == '\t')
        ct++;
    if (strncasecmp(ct, "application/json", 16) != 0)
        return 0;
    for (p = ct + 16; *p == ' ' || *p == '\t'; p++)
        ;
    while (*p == ';') {
        for (p++; *p == ' ' || *p == '\t'; p++)
            ;
        n = strcspn(p, ";");
        if (strncasecmp(p, "charset=", 8) == 0) {
            v = p + 8;
            if (strncasecmp(v, "utf-8", 5) == 0 || strncasecmp(v, "\"utf-8\"", 7) == 0)
                v += v[0] == '"' ? 7 : 5;
            else
                return 0;
            while (*v == ' ' || *v == '\t')
                v++;
            if (*v != ';' && *v != '\0')
                return 0;
        }
        p += n;
    }
    return *p == '\0';
}

/* The problem document of a body over --max-body; NULL when out of memory. */
static json_t *http_too_large_doc(const http *h)
{
    char detail[96];

    snprintf(detail, sizeof(detail), "The request body is larger than the limit of %zu bytes.",
             h->max_body);
    return codec_problem_new(MHD_HTTP_CONTENT_TOO_LARGE, NULL, "Content Too Large", detail,
                             NULL);
}

/* 413 for a body over --max-body. */
static enum MHD_Result http_too_large(struct MHD_Connection *c, http_req *r)
{
    return http_respond_problem(c, r, MHD_HTTP_CONTENT_TOO_LARGE, http_too_large_doc(r->h),
                                NULL, 0);
}

/* Send n bytes at p on fd (non-blocking), waiting up to 1 s at a time; 0 or -1. */
static int http_raw_send(int fd, const char *p, size_t n)
{
    struct pollfd pfd = {fd, POLLOUT, 0};
    ssize_t k;

    while (n > 0) {
        k = send(fd, p, n, MSG_NOSIGNAL);
        if (k > 0) {
            p += k;
            n -= (size_t)k;
        } else if (k < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) {
            if (poll(&pfd, 1, 1000) <= 0)
                return -1;
        } else {
            return -1;
        }
    }
    return 0;
}

/* Read and drop what the client still sends, until it closes, 2 s or 16 MiB. */
static void http_raw_drain(int fd)
{
    struct pollfd pfd = {fd, POLLIN, 0};
    double end = http_mono() + 2.0;
    size_t total = 0;
    char sink[16384];
    ssize_t k;

    while (total < ((size_t)16 << 20) && http_mono() < end) {
        if (poll(&pfd, 1, 100) < 0 && errno != EINTR)
            return;
        if (!(pfd.revents & (POLLIN | POLLHUP | POLLERR)))
            continue;
        k = recv(fd, sink, sizeof(sink), 0);
        if (k == 0 || (k < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR))
            return;
        if (k > 0)
            total += (size_t)k;
    }
}

/*
 * 413 for a body without Content-Length that went over --max-body while it
 * arrives.  libmicrohttpd 0.9.75 refuses MHD_queue_response while it hands
 * over body data (later versions accept it: tried first), so the answer is
 * written on the socket here, from this connection's own thread with
 * nothing else of it in flight; the sending side is then shut, the
 * client's remaining bytes drained briefly (so the close does not reset
 * the answer away), and MHD_NO has libmicrohttpd close the connection.
 */
static enum MHD_Result http_early_too_large(struct MHD_Connection *c, http_req *r)
{
    const union MHD_ConnectionInfo *ci;
    codec_text b = {0};
    char *body = NULL;
    json_t *doc;
    size_t len;

    if (http_too_large(c, r) == MHD_YES && r->status)
        return MHD_YES;
    ci = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
    doc = http_too_large_doc(r->h);
    if (doc)
        body = json_dumps(doc, JSON_COMPACT);
    json_decref(doc);
    if (!ci || !body) {
        free(body);
        return MHD_NO;
    }
    len = strlen(body);
    codec_text_printf(&b, "HTTP/1.1 413 %s\r\nConnection: close\r\nContent-Type: "
                        "application/problem+json\r\nContent-Length: %zu\r\n",
                    MHD_get_reason_phrase_for(MHD_HTTP_CONTENT_TOO_LARGE), len);
    if (r->h->cors_origin) {
        codec_text_puts(&b, "Access-Control-Allow-Origin: ");
        codec_text_puts(&b, r->h->cors_origin);
        codec_text_puts(&b, "\r\n");
    }
    codec_text_puts(&b, "\r\n");
    codec_text_put(&b, body, len);
    if (!b.nomem && http_raw_send(ci->connect_fd, b.p, b.len) == 0) {
        r->status = MHD_HTTP_CONTENT_TOO_LARGE;
        r->bytes = len;
        r->raw_answer = 1;
        shutdown(ci->connect_fd, SHUT_WR);
        http_raw_drain(ci->connect_fd);
    }
    free(b.p);
    free(body);
    return MHD_NO;
}

/*
 * Header checks of POST /v1/analyses and /v1/validate (no token, no wait,
 * served while stopping).  Returns 1 when the body should be read, 0 after
 * queueing an answer (*q).
 */
static int http_post_begin(struct MHD_Connection *c, http_req *r, enum MHD_Result *q)
{
    int submit = r->route == R_ANALYSES;
    const char *cl;
    long long n = 0;

    if (submit && !http_authorized(r->h, c)) {
        *q = http_unauthorized(c, r);
        return 0;
    }
    if (submit && http_query_wait(c, r, &r->wait, q))
        return 0;
    if (!http_is_json(MHD_lookup_connection_value(c, MHD_HEADER_KIND,
                                                  MHD_HTTP_HEADER_CONTENT_TYPE))) {
        *q = http_problem(c, r, MHD_HTTP_UNSUPPORTED_MEDIA_TYPE, NULL, "Unsupported Media Type",
                          "The request body must be JSON (Content-Type: application/json).",
                          NULL, 0);
        return 0;
    }
    cl = MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
    if (cl && (http_parse_int(cl, 0, (long long)r->h->max_body, &n) ||
               (size_t)n > r->h->max_body)) {
        *q = http_too_large(c, r);
        return 0;
    }
    if (submit && http_is_stopping(r->h)) {
        *q = http_unavailable(c, r, "stopping");
        return 0;
    }
    r->announced = cl ? (size_t)n : 0;
    return 1;
}

/* Append body data, capped at --max-body; over the cap or without memory it is dropped. */
static void http_take_body(http_req *r, const char *data, size_t n)
{
    size_t need;
    char *nb;

    if (r->body_state != BODY_OK)
        return;
    need = r->len + n;
    if (need > r->h->max_body) {
        r->body_state = BODY_TOO_LARGE;
        goto drop;
    }
    if (need > r->cap) {
        size_t ncap = r->cap * 2 > HTTP_BODY_CHUNK ? r->cap * 2 : HTTP_BODY_CHUNK;
        if (ncap < need)
            ncap = need;
        if (ncap > r->h->max_body)
            ncap = r->h->max_body;
        if (r->announced >= need && ncap > r->announced)
            ncap = r->announced; /* memory follows the bytes received, up to Content-Length */
        nb = realloc(r->body, ncap);
        if (!nb) {
            r->body_state = BODY_NOMEM;
            goto drop;
        }
        r->body = nb;
        r->cap = ncap;
    }
    memcpy(r->body + r->len, data, n);
    r->len = need;
    return;
drop:
    free(r->body);
    r->body = NULL;
    r->len = r->cap = 0;
}

/* Submit a validated request and answer (202/200/429/503). */
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
    if (rc == JOBS_STOPPING)
        return http_unavailable(c, r, "stopping");
    if (rc != JOBS_OK)
        return http_unavailable(c, r, "unavailable");
    memcpy(r->id, jb.id, sizeof(r->id));
    r->id[64] = '\0';
    if (r->wait > 0.0 || !http_unfinished(&jb)) {
        store_job_clear(&jb);
        rc = http_job_wait(r->h, r->id, r->wait, STORE_WITH_RESULT, &jb);
        if (rc != JOBS_OK) {
            store_job_clear(&jb);
            return http_unavailable(c, r, "unavailable");
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

/*
 * Topology checks of the core (cycles, disconnected members …) that the
 * codec alone does not see: build the model and drop it.  Skipped for a
 * POST of a job the store already holds (it passed them when submitted).
 * Returns an sm_status; errs is filled on failure.
 */
static int http_check_model(http_req *r, const codec_request *req, codec_errors *errs)
{
    sm_model *m = NULL;
    store_job jb;
    char id[65];
    int st, known = 0;

    memset(&jb, 0, sizeof(jb));
    if (r->route == R_ANALYSES && codec_job_id(req, id) == SM_OK &&
        http_job_read(r->h, id, 0, &jb) == JOBS_OK)
        known = jb.state != STORE_FAILED && jb.state != STORE_CANCELED;
    store_job_clear(&jb);
    if (known)
        return SM_OK;
    st = codec_model_new(&m, req, errs, NULL);
    sm_model_free(m);
    return st;
}

/* The whole body of a POST is in: validate, then submit or describe, answer. */
static enum MHD_Result http_post_end(struct MHD_Connection *c, http_req *r)
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
    if (rc == SM_OK)
        rc = http_check_model(r, req, errs);
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

/* ------------------------------------------------------ operational routes */

/* GET /readyz */
static enum MHD_Result http_readyz(struct MHD_Connection *c, http_req *r)
{
    http_hdr retry = {MHD_HTTP_HEADER_RETRY_AFTER, HTTP_RETRY_FAULT};
    jobs_stats s = {0, 0, 0, 0};
    int db_ok = store_check_writable(r->h->st) == STORE_OK, stopping = 1;
    char workers[48];
    codec_text b = {0};

    if (http_enter(r->h) == 0) {
        jobs_get_stats(r->h->j, &s);
        stopping = jobs_stopping(r->h->j);
        http_leave(r->h);
    }
    snprintf(workers, sizeof(workers), "%d/%d", s.workers_alive, s.workers);
    if (db_ok && !stopping && s.workers_alive == s.workers && s.workers > 0) {
        codec_text_printf(&b, "{\"status\":\"ready\",\"checks\":{\"database\":\"ok\","
                            "\"workers\":\"%s\"}}", workers);
        return http_respond_buf(c, r, MHD_HTTP_OK, "application/json", &b, NULL, 0);
    }
    codec_text_printf(&b, "{\"type\":\"" HTTP_PROBLEMS "not-ready\",\"title\":\"Service "
                        "Unavailable\",\"status\":503,\"detail\":\"%s\",",
                    stopping ? "The daemon is stopping."
                    : !db_ok ? "The database is not writable."
                             : "A worker thread is gone.");
    codec_text_printf(&b, "\"checks\":{\"database\":\"%s\","
                        "\"workers\":\"%s\"}}", db_ok ? "ok" : "unwritable", workers);
    if (stopping)
        retry.value = HTTP_RETRY_BUSY;
    return http_respond_buf(c, r, MHD_HTTP_SERVICE_UNAVAILABLE, "application/problem+json", &b,
                            &retry, 1);
}

/* GET /metrics */
static enum MHD_Result http_metrics(struct MHD_Connection *c, http_req *r)
{
    metrics_gauges g;
    jobs_stats s = {0, 0, 0, 0};
    long long counts[STORE_N_STATES];
    char *text = NULL;
    size_t len = 0;
    int i, counted = store_count(r->h->st, counts) == STORE_OK;

    for (i = 0; i < STORE_N_STATES; i++)
        g.jobs[i] = counted ? counts[i] : -1;
    if (http_enter(r->h) == 0) {
        jobs_get_stats(r->h->j, &s);
        http_leave(r->h);
    } else if (counted) {
        s.queued = (int)counts[STORE_QUEUED];
    }
    g.queue_depth = s.queued;
    g.workers = s.workers;
    g.workers_busy = s.workers_busy;
    if (metrics_render(r->h->mx, &g, &text, &len))
        return http_send_oom(c, r);
    return http_respond(c, r, MHD_HTTP_OK, "text/plain; version=0.0.4", text, len, 1, NULL, 0);
}

/* OPTIONS: the CORS preflight. */
static enum MHD_Result http_preflight(struct MHD_Connection *c, http_req *r)
{
    static const http_hdr hdrs[] = {
        {MHD_HTTP_HEADER_ACCESS_CONTROL_ALLOW_METHODS, "GET, HEAD, POST, DELETE, OPTIONS"},
        {"Access-Control-Allow-Headers", "Authorization, Content-Type"},
        {"Access-Control-Max-Age", "600"}};

    return http_respond(c, r, MHD_HTTP_NO_CONTENT, NULL, NULL, 0, 0, hdrs, 3);
}

/* ---------------------------------------------------------------- routing */

/* Route r by its path; sets route, tmpl, file, id. */
static void http_route_of(http_req *r, const char *url)
{
    const char *rest, *slash;

    r->tmpl = "other";
    if (strcmp(url, "/v1/analyses") == 0) {
        r->route = R_ANALYSES;
        r->tmpl = "/v1/analyses";
    } else if (strcmp(url, "/v1/validate") == 0) {
        r->route = R_VALIDATE;
        r->tmpl = "/v1/validate";
    } else if (strncmp(url, "/v1/analyses/", 13) == 0) {
        rest = url + 13;
        slash = strchr(rest, '/');
        if (slash && strcmp(slash, "/result") != 0)
            return;
        r->route = slash ? R_RESULT : R_ANALYSIS;
        r->tmpl = slash ? "/v1/analyses/{id}/result" : "/v1/analyses/{id}";
        r->id_ok = http_is_id(rest, slash ? (size_t)(slash - rest) : strlen(rest));
        if (r->id_ok) {
            memcpy(r->id, rest, 64);
            r->id[64] = '\0';
        }
    } else if (strcmp(url, "/livez") == 0) {
        r->route = R_LIVEZ;
        r->tmpl = "/livez";
    } else if (strcmp(url, "/readyz") == 0) {
        r->route = R_READYZ;
        r->tmpl = "/readyz";
    } else if (strcmp(url, "/metrics") == 0) {
        r->route = R_METRICS;
        r->tmpl = "/metrics";
    } else if ((r->file = embedded_find(url)) != NULL) {
        r->route = R_FILE;
        r->tmpl = r->file->path;
    }
}

static unsigned http_method_of(const char *m)
{
    static const struct {
        const char *name;
        unsigned bit;
    } t[] = {{"GET", M_GET}, {"HEAD", M_HEAD}, {"POST", M_POST}, {"DELETE", M_DELETE},
             {"OPTIONS", M_OPTIONS}};
    size_t i;

    for (i = 0; i < sizeof(t) / sizeof(t[0]); i++)
        if (strcmp(m, t[i].name) == 0)
            return t[i].bit;
    return M_OTHER;
}

static unsigned http_route_methods(http_route route)
{
    switch (route) {
    case R_ANALYSES:
        return M_GET | M_HEAD | M_POST;
    case R_VALIDATE:
        return M_POST;
    case R_ANALYSIS:
        return M_GET | M_HEAD | M_DELETE;
    case R_OTHER:
        return 0;
    default:
        return M_GET | M_HEAD;
    }
}

/* Answer a GET or HEAD of a known route. */
static enum MHD_Result http_get(struct MHD_Connection *c, http_req *r)
{
    static const char livez[] = "{\"status\":\"ok\"}";

    switch (r->route) {
    case R_ANALYSES:
        return http_list(c, r);
    case R_ANALYSIS:
        return http_get_analysis(c, r);
    case R_RESULT:
        return http_get_result(c, r);
    case R_LIVEZ:
        return http_respond(c, r, MHD_HTTP_OK, "application/json", (char *)livez,
                            sizeof(livez) - 1, 0, NULL, 0);
    case R_READYZ:
        return http_readyz(c, r);
    case R_METRICS:
        return http_metrics(c, r);
    case R_FILE:
        return http_respond(c, r, MHD_HTTP_OK, r->file->content_type, (char *)r->file->data,
                            r->file->len, 0, NULL, 0);
    default:
        return http_not_found(c, r, 0);
    }
}

/* Answer a request other than a POST with a body (all of it is in). */
static enum MHD_Result http_answer(struct MHD_Connection *c, http_req *r)
{
    unsigned allowed = http_route_methods(r->route);

    if (r->method == M_OPTIONS && r->h->cors_origin)
        return http_preflight(c, r);
    if (r->method == M_OPTIONS && strcmp(r->path, "*") == 0)
        return http_not_allowed(c, r, M_GET | M_HEAD | M_POST | M_DELETE);
    if (r->route == R_OTHER)
        return http_not_found(c, r, 0);
    if (!(allowed & r->method))
        return http_not_allowed(c, r, allowed);
    if (r->method == M_GET || r->method == M_HEAD)
        return http_get(c, r);
    if (!http_authorized(r->h, c))
        return http_unauthorized(c, r);
    return http_delete(c, r);
}

/* 1 when the request announces a body (Content-Length > 0 or Transfer-Encoding). */
static int http_has_body(struct MHD_Connection *c)
{
    const char *cl = MHD_lookup_connection_value(c, MHD_HEADER_KIND,
                                                 MHD_HTTP_HEADER_CONTENT_LENGTH);

    if (MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_TRANSFER_ENCODING))
        return 1;
    return cl && cl[strspn(cl, "0")] != '\0';
}

/*
 * First call (headers received).  libmicrohttpd closes the connection
 * after a response queued now, so only answers that refuse a body are
 * queued here (the body is then never read); everything else is answered
 * on the last call, keeping the connection alive.  Returns MHD_YES
 * without a response to go on.
 */
static enum MHD_Result http_first(struct MHD_Connection *c, http_req *r)
{
    enum MHD_Result q = MHD_YES;

    if (r->method == M_POST && (r->route == R_ANALYSES || r->route == R_VALIDATE)) {
        r->collect = 1;
        if (!http_post_begin(c, r, &q))
            return q;
        return MHD_YES;
    }
    if (http_has_body(c))
        return http_answer(c, r);
    return MHD_YES;
}

static http_req *http_req_new(http *h, const char *url, const char *method)
{
    http_req *r = calloc(1, sizeof(*r));

    if (!r)
        return NULL;
    r->h = h;
    r->t0 = http_mono();
    r->method = http_method_of(method);
    http_sanitize(r->method_name, sizeof(r->method_name), method);
    http_sanitize(r->path, sizeof(r->path), url);
    http_route_of(r, url);
    return r;
}

static enum MHD_Result http_handler(void *cls, struct MHD_Connection *c, const char *url,
                                    const char *method, const char *version,
                                    const char *upload, size_t *upload_size, void **req_cls)
{
    http *h = cls;
    http_req *r = *req_cls;

    (void)version;
    if (!r) {
        r = http_req_new(h, url, method);
        if (!r)
            return http_send_oom(c, NULL);
        *req_cls = r;
        return http_first(c, r);
    }
    if (*upload_size) {
        if (r->collect)
            http_take_body(r, upload, *upload_size);
        *upload_size = 0;
        if (r->body_state == BODY_TOO_LARGE)
            return http_early_too_large(c, r);
        return MHD_YES;
    }
    return r->collect ? http_post_end(c, r) : http_answer(c, r);
}

static const char *http_method_label(unsigned m)
{
    switch (m) {
    case M_GET:
        return "GET";
    case M_HEAD:
        return "HEAD";
    case M_POST:
        return "POST";
    case M_DELETE:
        return "DELETE";
    case M_OPTIONS:
        return "OPTIONS";
    default:
        return "OTHER";
    }
}

/* MHD_OPTION_NOTIFY_COMPLETED: count, log, free. */
static void http_completed(void *cls, struct MHD_Connection *c, void **req_cls,
                           enum MHD_RequestTerminationCode toe)
{
    static const char *const toe_names[] = {NULL,           "error",      "timeout",
                                            "shutdown",     "read_error", "client_abort"};
    http_req *r = *req_cls;
    char status[16], ms[32], bytes[32];

    (void)cls;
    (void)c;
    if (!r)
        return;
    if (r->status)
        metrics_http(r->h->mx, r->tmpl, http_method_label(r->method), r->status);
    snprintf(status, sizeof(status), "%d", r->status);
    snprintf(ms, sizeof(ms), "%.1f", (http_mono() - r->t0) * 1000.0);
    snprintf(bytes, sizeof(bytes), "%zu", r->bytes);
    if (r->raw_answer)
        toe = MHD_REQUEST_TERMINATED_COMPLETED_OK; /* our own close after the answer */
    log_event("info", "request", "method", r->method_name, "path", r->path, "status", status,
              "ms", ms, "bytes", bytes, "job", r->id[0] ? r->id : NULL, "error",
              (unsigned)toe < sizeof(toe_names) / sizeof(toe_names[0]) ? toe_names[toe]
                                                                       : "unknown",
              (const char *)NULL);
    free(r->body);
    free(r);
    *req_cls = NULL;
}

/* ------------------------------------------------------------ lifecycle */

#if defined(__GNUC__)
__attribute__((format(printf, 2, 0)))
#endif
static void http_mhd_log(void *cls, const char *fmt, va_list ap)
{
    char msg[512];
    size_t n;

    (void)cls;
    vsnprintf(msg, sizeof(msg), fmt, ap);
    n = strlen(msg);
    while (n > 0 && (msg[n - 1] == '\n' || msg[n - 1] == '\r'))
        msg[--n] = '\0';
    log_event("warn", "http_error", "message", msg, (const char *)NULL);
}

void http_default_config(http_config *cfg)
{
    memset(cfg, 0, sizeof(*cfg));
    cfg->host = "127.0.0.1";
    cfg->port = 8080;
    cfg->max_body = 1048576;
    codec_default_limits(&cfg->limits);
    cfg->limits.max_request_bytes = cfg->max_body;
    cfg->connection_limit = 512;
    cfg->connection_timeout = 60;
}

/* Copy the settings of cfg into h; 0 or HTTP_NOMEM. */
static int http_configure(http *h, const http_config *cfg)
{
    h->max_body = cfg->max_body;
    h->limits = cfg->limits;
    h->limits.max_request_bytes = cfg->max_body;
    if (cfg->cors_origin) {
        h->cors_origin = strdup(cfg->cors_origin);
        if (!h->cors_origin)
            return HTTP_NOMEM;
    }
    if (cfg->token && codec_sha256_hex(cfg->token, strlen(cfg->token), h->token_hash) != SM_OK)
        return HTTP_NOMEM;
    return HTTP_OK;
}

/* Start the libmicrohttpd daemon on ai; 0 or HTTP_LISTEN. */
static int http_listen(http *h, const http_config *cfg, const struct addrinfo *ai)
{
    unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_THREAD_PER_CONNECTION |
                     MHD_USE_ERROR_LOG | MHD_USE_AUTO;
    const union MHD_DaemonInfo *info;

    if (ai->ai_family == AF_INET6)
        flags |= MHD_USE_IPv6;
    h->d = MHD_start_daemon(flags, (uint16_t)cfg->port, NULL, NULL, &http_handler, h,
                            MHD_OPTION_EXTERNAL_LOGGER, &http_mhd_log, h,
                            MHD_OPTION_SOCK_ADDR, ai->ai_addr,
                            MHD_OPTION_CONNECTION_LIMIT, (unsigned)cfg->connection_limit,
                            MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)cfg->connection_timeout,
                            MHD_OPTION_NOTIFY_COMPLETED, &http_completed, h,
                            MHD_OPTION_END);
    if (!h->d)
        return HTTP_LISTEN;
    info = MHD_get_daemon_info(h->d, MHD_DAEMON_INFO_BIND_PORT);
    h->port = info ? (int)info->port : cfg->port;
    return HTTP_OK;
}

static void http_free(http *h)
{
    if (!h)
        return;
    pthread_cond_destroy(&h->idle);
    pthread_mutex_destroy(&h->lock);
    free(h->cors_origin);
    free(h);
}

int http_start(http **out, const http_config *cfg, jobs *j, store *st, metrics *mx)
{
    struct addrinfo hints, *ai = NULL;
    char port[16];
    http *h;
    int rc;

    *out = NULL;
    h = calloc(1, sizeof(*h));
    if (!h)
        return HTTP_NOMEM;
    if (pthread_mutex_init(&h->lock, NULL)) {
        free(h);
        return HTTP_NOMEM;
    }
    if (pthread_cond_init(&h->idle, NULL)) {
        pthread_mutex_destroy(&h->lock);
        free(h);
        return HTTP_NOMEM;
    }
    h->j = j;
    h->st = st;
    h->mx = mx;
    rc = http_configure(h, cfg);
    if (rc)
        goto fail;
    memset(&hints, 0, sizeof(hints));
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
    snprintf(port, sizeof(port), "%d", cfg->port);
    if (cfg->port < 0 || cfg->port > 65535 ||
        getaddrinfo(cfg->host ? cfg->host : "127.0.0.1", port, &hints, &ai) != 0 || !ai) {
        rc = HTTP_ADDRESS;
        goto fail;
    }
    rc = http_listen(h, cfg, ai);
    freeaddrinfo(ai);
    if (rc)
        goto fail;
    *out = h;
    return HTTP_OK;
fail:
    http_free(h);
    return rc;
}

int http_port(const http *h)
{
    return h ? h->port : 0;
}

void http_begin_stop(http *h)
{
    if (!h)
        return;
    pthread_mutex_lock(&h->lock);
    h->stopping = 1;
    while (h->active > 0)
        pthread_cond_wait(&h->idle, &h->lock);
    pthread_mutex_unlock(&h->lock);
}

void http_stop(http *h)
{
    if (!h)
        return;
    http_begin_stop(h);
    MHD_stop_daemon(h->d);
    http_free(h);
}
