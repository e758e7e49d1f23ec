/*
 * http.c — the HTTP front of spinmodald (see http.h and server/DAEMON.md):
 * set-up, the handler and stop.  The routes are a table (http_routes.c);
 * the other files of the front are listed in http_internal.h.
 *
 * How it fits: libmicrohttpd runs one thread per connection and calls
 * http_handler in three phases (libmicrohttpd's simplepost.c shape):
 *   1. headers received: *req_cls is NULL; allocate the request context
 *      and route it (http_route_find: the table of http_routes.c).  Only refusals of a body are answered here (401, 400
 *      ?wait, 415, 413 by Content-Length, or any answer to a non-POST that
 *      carries a body): libmicrohttpd then closes the connection without
 *      reading the body.  Everything else waits for phase 3 so the
 *      connection stays alive;
 *   2. body data of a POST to a route that reads one (its begin said
 *      so: /v1/analyses, /v1/validate, /v1/import/{format}): appended to the
 *      context's buffer, capped at --max-body (over it: 413 at once, see
 *      http_early_too_large);
 *   3. request complete (*upload_data_size == 0): answer GET/HEAD/DELETE/
 *      OPTIONS (http_answer), or hand the POST body to the route's end
 *      (validate it with the codec, submit it to the job pool, optionally
 *      wait, answer).
 * http_completed (MHD_OPTION_NOTIFY_COMPLETED) counts the response in the
 * metrics, logs the `request` line and frees the context.
 *
 * Status documents are written by the codec (codec_job_status: the stored
 * error and result texts are spliced in verbatim), so a GET of a finished
 * job costs one store read and one copy.  Bodies are handed to libmicrohttpd with a free callback (no
 * second copy).  Any allocation or store failure answers 503 +
 * Retry-After; if even that cannot be built, a static 503 is sent.
 *
 * Stop: http_begin_stop sets `stopping` and waits until no thread is
 * inside a jobs_* call (calls are bracketed by http_enter/http_leave and
 * waits are sliced), so the pool can then be freed by jobs_stop while the
 * server still answers status reads from the store.
 */
#include "http_internal.h"

#include <errno.h>
#include <netdb.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>

#include "log.h"

/* ------------------------------------------------------------ the handler */

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

    if (r->method == M_POST && r->def && r->def->begin) {
        r->collect = 1;
        if (!r->def->begin(c, r, &q))
            return q;
        return MHD_YES;
    }
    if (http_has_body(c))
        return http_answer(c, r);
    /* complete: not a connection to shed; one shed already is not served (http_guard.c) */
    return http_guard_answering(r->h, c) ? MHD_NO : MHD_YES;
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
    http_route_find(r, url);
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
    if (http_guard_answering(h, c))
        return MHD_NO;
    return r->collect ? r->def->end(c, r) : http_answer(c, r);
}

static void http_completed(void *cls, struct MHD_Connection *c, void **req_cls,
                           enum MHD_RequestTerminationCode toe)
{
    static const char *const toe_names[] = {NULL,           "error",      "timeout",
                                            "shutdown",     "read_error", "client_abort"};
    http_req *r = *req_cls;
    char status[16], ms[32], bytes[32];

    http_guard_answered(cls, c);
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

/* ------------------------------------------------- the job pool, guarded */

/* Enter a jobs_* call: 0, or -1 once http_begin_stop has begun. */
int http_enter(http *h)
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

void http_leave(http *h)
{
    pthread_mutex_lock(&h->lock);
    if (--h->active == 0 && h->stopping)
        pthread_cond_broadcast(&h->idle);
    pthread_mutex_unlock(&h->lock);
}

int http_is_stopping(http *h)
{
    int s;

    pthread_mutex_lock(&h->lock);
    s = h->stopping;
    pthread_mutex_unlock(&h->lock);
    return s;
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
    /* our own MHD_NO (a connection the guard shed, a raw 413) is not an error; those are
       counted and logged where they happen */
    if (strncmp(msg, "Application reported internal error", 35) == 0)
        return;
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
    cfg->per_client_limit = 64;
    cfg->max_waiters = 128;
    cfg->connection_timeout = 60;
    cfg->request_deadline = 30.0;
}

/* Copy the settings of cfg into h; 0 or HTTP_NOMEM. */
static int http_configure(http *h, const http_config *cfg)
{
    h->max_body = cfg->max_body;
    h->auth_reads = cfg->auth_reads && cfg->token;
    h->request_deadline = cfg->request_deadline > 0.0 ? cfg->request_deadline : 30.0;
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

/* The value of hex digit ch, or -1. */
static int http_hex(char ch)
{
    if (ch >= '0' && ch <= '9')
        return ch - '0';
    if (ch >= 'a' && ch <= 'f')
        return ch - 'a' + 10;
    if (ch >= 'A' && ch <= 'F')
        return ch - 'A' + 10;
    return -1;
}

/*
 * MHD_OPTION_UNESCAPE_CALLBACK: percent-decode s in place (the path, and
 * each query key and value) and return its new length; "%00" is kept as
 * the three characters.  libmicrohttpd's own decoder turns it into a NUL
 * that silently cuts the string short: "/livez%00.html" was served as
 * /livez, "?format=csv%00json" as csv, "/v1/analyses/{id}%00x" as the job.
 */
static size_t http_unescape(void *cls, struct MHD_Connection *c, char *s)
{
    size_t r = 0, w = 0;
    int hi, lo;

    (void)cls;
    (void)c;
    while (s[r]) {
        if (s[r] == '%' && (hi = http_hex(s[r + 1])) >= 0 && (lo = http_hex(s[r + 2])) >= 0 &&
            (hi | lo) != 0) {
            s[w++] = (char)(hi * 16 + lo);
            r += 3;
        } else {
            s[w++] = s[r++];
        }
    }
    s[w] = '\0';
    return w;
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
                            MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)cfg->per_client_limit,
                            MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)cfg->connection_timeout,
                            MHD_OPTION_NOTIFY_COMPLETED, &http_completed, h,
                            MHD_OPTION_NOTIFY_CONNECTION, &http_guard_notify, h,
                            MHD_OPTION_UNESCAPE_CALLBACK, &http_unescape, h,
                            MHD_OPTION_STRICT_FOR_CLIENT, 1,
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
    pthread_cond_destroy(&h->guard_cv);
    pthread_mutex_destroy(&h->guard_lock);
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
    if (pthread_mutex_init(&h->guard_lock, NULL)) {
        pthread_cond_destroy(&h->idle);
        pthread_mutex_destroy(&h->lock);
        free(h);
        return HTTP_NOMEM;
    }
    if (pthread_cond_init(&h->guard_cv, NULL)) {
        pthread_mutex_destroy(&h->guard_lock);
        pthread_cond_destroy(&h->idle);
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
    http_guard_set_caps(h, (int)cfg->connection_limit, (int)cfg->max_waiters);
    rc = http_guard_start(h);
    if (rc == HTTP_OK)
        rc = http_listen(h, cfg, ai);
    freeaddrinfo(ai);
    if (rc) {
        http_guard_stop(h);
        goto fail;
    }
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
    http_guard_stop(h);
    MHD_stop_daemon(h->d);
    http_free(h);
}
