/*
 * http_reply.c — building the responses of spinmodald: headers (CORS,
 * Location, Retry-After, Allow), RFC 9457 problem documents, the static
 * out-of-memory 503 that needs no allocation, and the small parsers of the
 * request line (ids, integers, seconds).
 */
#include "http_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char http_oom_body[] =
    "{\"type\":\"" HTTP_PROBLEMS "unavailable\",\"title\":\"Service Unavailable\","
    "\"status\":503,\"detail\":\"The server is out of memory; retry later.\"}";

/* ------------------------------------------------------------ utilities */

double http_mono(void)
{
    struct timespec ts;

    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Copy s into dst (cap bytes), keeping printable ASCII, '?' for the rest. */
void http_sanitize(char *dst, size_t cap, const char *s)
{
    size_t i;

    for (i = 0; s && s[i] && i + 1 < cap; i++)
        dst[i] = (s[i] > 0x20 && s[i] < 0x7f) ? s[i] : '?';
    dst[i] = '\0';
}

/* 1 when s is exactly 64 lowercase hex digits. */
int http_is_id(const char *s, size_t len)
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
int http_parse_int(const char *s, long long lo, long long hi, long long *out)
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
int http_parse_seconds(const char *s, double hi, double *out)
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
int http_ct_equal(const char *a, const char *b, size_t n)
{
    volatile unsigned char d = 0;
    size_t i;

    for (i = 0; i < n; i++)
        d |= (unsigned char)(a[i] ^ b[i]);
    return d == 0;
}

/* ------------------------------------------------------------ responses */

/* Queue the static out-of-memory 503; the last resort. */
enum MHD_Result http_send_oom(struct MHD_Connection *c, http_req *r)
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
enum MHD_Result http_respond(struct MHD_Connection *c, http_req *r, int status,
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
enum MHD_Result http_respond_buf(struct MHD_Connection *c, http_req *r, int status,
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
enum MHD_Result http_respond_problem(struct MHD_Connection *c, http_req *r, int status,
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
enum MHD_Result http_problem(struct MHD_Connection *c, http_req *r, int status,
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
enum MHD_Result http_unavailable(struct MHD_Connection *c, http_req *r, const char *why)
{
    int stopping = strcmp(why, "stopping") == 0;
    http_hdr retry = {MHD_HTTP_HEADER_RETRY_AFTER, stopping ? HTTP_RETRY_BUSY : HTTP_RETRY_FAULT};

    return http_problem(c, r, MHD_HTTP_SERVICE_UNAVAILABLE, why, "Service Unavailable",
                        stopping ? "The daemon is stopping; retry later."
                                 : "The database is unavailable; retry later.",
                        &retry, 1);
}

/* 400 for query parameter name, with pointer /query/<name>. */
enum MHD_Result http_bad_query(struct MHD_Connection *c, http_req *r, const char *name,
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

enum MHD_Result http_not_found(struct MHD_Connection *c, http_req *r, int is_id)
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

enum MHD_Result http_not_allowed(struct MHD_Connection *c, http_req *r, unsigned methods)
{
    http_hdr allow = {MHD_HTTP_HEADER_ALLOW, http_allow(r->h, methods)};
    char detail[80];

    snprintf(detail, sizeof(detail), "This route allows %s.", allow.value);
    return http_problem(c, r, MHD_HTTP_METHOD_NOT_ALLOWED, NULL, "Method Not Allowed", detail,
                        &allow, 1);
}
