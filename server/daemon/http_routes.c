/*
 * http_routes.c — the routes of the HTTP front (see http_internal.h and
 * server/DAEMON.md): the table http_routes[], the one lookup, the answers
 * the table gives by itself (404, 405 + Allow, the CORS preflight, 401 for
 * a read under --auth-reads) and the operational routes (/livez, /readyz,
 * /metrics, the embedded files).
 *
 * How it fits: routes are data, as Redis's command table is
 * (commands.def: name, handler, arity, flags; lookupCommand finds one).
 * Each entry of http_routes[] holds a path template, the methods it
 * allows and a handler per method: GET/HEAD (get), DELETE (del), and the
 * two phases of a POST that reads a body (begin on the headers, end on the
 * whole body; http.c calls them).  http_route_find runs once per request,
 * when its headers arrive (http.c's http_req_new): the first entry whose
 * template matches the path wins, then the embedded files (schemas,
 * OpenAPI, the web page; embedded.c).  No route: 404.  A method the route
 * does not allow: 405 with its Allow header (http_reply.c's http_allow).
 *
 * A new route is one line of http_routes[] and its handler (in the file of
 * its resource: http_analyses.c, http_import.c, or here for an
 * operational one); schemas/openapi.json documents it, and the routes test
 * (tests/server/test_routes.c) checks that the two agree.
 */
#include "http_internal.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "http_mac.h"
#include "import.h"

/* ------------------------------------------------------ operational routes */

/*
 * GET /readyz: ready when the database takes a real write (store_health: the
 * file is still the one opened, a WAL frame can be written), the last write
 * of a job did not fail, every worker runs and the daemon is not stopping.
 * checks.database is "ok" or the kind of the failure (store_rc_name:
 * "full", "readonly", "gone", "corrupt", "busy", "db_timeout" ...;
 * "write_failed" when the probe passes but a job's result could not be
 * stored).  The probe has its own budget (store_settings.probe_timeout_ms,
 * 0.5 s): a stalled database answers 503 "db_timeout", never a hang.
 */
static enum MHD_Result http_readyz(struct MHD_Connection *c, http_req *r)
{
    http_hdr retry = {MHD_HTTP_HEADER_RETRY_AFTER, HTTP_RETRY_FAULT};
    jobs_stats s;
    int db_rc = store_health(r->h->st), stopping = 1, writes_fail = 0;
    const char *db = db_rc == STORE_OK ? "ok" : store_rc_name(db_rc);
    char workers[48], detail[300];
    codec_text b = {0};

    memset(&s, 0, sizeof(s));
    if (http_enter(r->h) == 0) {
        jobs_get_stats(r->h->j, &s);
        stopping = jobs_stopping(r->h->j);
        http_leave(r->h);
        writes_fail = s.store_failing || s.unrecorded > 0;
    }
    if (db_rc == STORE_OK && writes_fail)
        db = "write_failed";
    snprintf(workers, sizeof(workers), "%d/%d", s.workers_alive, s.workers);
    if (strcmp(db, "ok") == 0 && !stopping && s.workers_alive == s.workers && s.workers > 0) {
        codec_text_printf(&b, "{\"status\":\"ready\",\"checks\":{\"database\":\"ok\","
                              "\"workers\":\"%s\"}}", workers);
        return http_respond_buf(c, r, MHD_HTTP_OK, "application/json", &b, NULL, 0);
    }
    if (stopping)
        snprintf(detail, sizeof(detail), "The daemon is stopping.");
    else if (db_rc == STORE_TIMEOUT)   /* the probe's own budget passed (DESIGN §F) */
        snprintf(detail, sizeof(detail), "The database did not answer the readiness probe "
                                         "in time: %s.", store_strerror(db_rc));
    else if (db_rc != STORE_OK)
        snprintf(detail, sizeof(detail), "The database is not writable: %s.",
                 store_strerror(db_rc));
    else if (writes_fail)
        snprintf(detail, sizeof(detail), "The database refused the last write of a job "
                                         "(full disk or read-only); results are not stored.");
    else
        snprintf(detail, sizeof(detail), "A worker thread is gone.");
    codec_text_printf(&b, "{\"type\":\"" HTTP_PROBLEMS "not-ready\",\"title\":\"Service "
                          "Unavailable\",\"status\":503,\"detail\":\"%s\",", detail);
    codec_text_printf(&b, "\"checks\":{\"database\":\"%s\",\"workers\":\"%s\"}}", db,
                      workers);
    if (stopping)
        retry.value = HTTP_RETRY_BUSY;
    return http_respond_buf(c, r, MHD_HTTP_SERVICE_UNAVAILABLE, "application/problem+json", &b,
                            &retry, 1);
}

/*
 * Append the long-poll budget (http_guard.c) to the metrics text *text
 * (*len bytes, malloc'd): 0, or -1 when out of memory (*text then freed).
 */
static int http_metrics_waiters(http *h, char **text, size_t *len)
{
    static const char fmt[] =
        "# HELP spinmodal_http_waiters Long polls (?wait) waiting now.\n"
        "# TYPE spinmodal_http_waiters gauge\n"
        "spinmodal_http_waiters %d\n"
        "# HELP spinmodal_http_waiters_limit Most long polls waiting at once (--max-waiters).\n"
        "# TYPE spinmodal_http_waiters_limit gauge\n"
        "spinmodal_http_waiters_limit %d\n"
        "# HELP spinmodal_http_waiters_released_total Long polls answered early with the "
        "job's current state because a newer one came over --max-waiters.\n"
        "# TYPE spinmodal_http_waiters_released_total counter\n"
        "spinmodal_http_waiters_released_total %llu\n";
    unsigned long long released;
    int waiting, cap, n;
    char *grown;

    http_waiter_counts(h, &waiting, &cap, &released);
    n = snprintf(NULL, 0, fmt, waiting, cap, released);
    grown = n < 0 ? NULL : realloc(*text, *len + (size_t)n + 1);
    if (!grown) {
        free(*text);
        *text = NULL;
        return -1;
    }
    snprintf(grown + *len, (size_t)n + 1, fmt, waiting, cap, released);
    *text = grown;
    *len += (size_t)n;
    return 0;
}

/* GET /metrics */
static enum MHD_Result http_metrics(struct MHD_Connection *c, http_req *r)
{
    metrics_gauges g;
    jobs_stats s = {0};
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
    if (store_size(r->h->st, &g.store_live_bytes, &g.store_file_bytes) != STORE_OK)
        g.store_live_bytes = g.store_file_bytes = -1;
    g.queue_depth = counted ? (int)(counts[STORE_QUEUED] > INT_MAX ? INT_MAX : counts[STORE_QUEUED]) : s.queued;
    g.workers = s.workers;
    g.workers_busy = s.workers_busy;
    if (metrics_render(r->h->mx, &g, &text, &len) || http_metrics_waiters(r->h, &text, &len))
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

/* GET /livez: the process answers. */
static enum MHD_Result http_livez(struct MHD_Connection *c, http_req *r)
{
    static const char livez[] = "{\"status\":\"ok\"}";

    return http_respond(c, r, MHD_HTTP_OK, "application/json", (char *)livez,
                        sizeof(livez) - 1, 0, NULL, 0);
}

/* GET of an embedded file (r->file): its bytes, verbatim. */
static enum MHD_Result http_file(struct MHD_Connection *c, http_req *r)
{
    return http_respond(c, r, MHD_HTTP_OK, r->file->content_type, (char *)r->file->data,
                        r->file->len, 0, NULL, 0);
}

/* ---------------------------------------------------------------- the table */

#define HTTP_READ (M_GET | M_HEAD)

/* The routes of DAEMON.md, in lookup order. */
static const http_route_def http_routes[] = {
    {"/v1/analyses", R_ANALYSES, HTTP_READ | M_POST, HTTP_ROUTE_READ_TOKEN, http_list, NULL,
     http_post_begin, http_post_end},
    {"/v1/validate", R_VALIDATE, M_POST, 0, NULL, NULL, http_post_begin, http_post_end},
    {"/v1/analyses/{id}", R_ANALYSIS, HTTP_READ | M_DELETE, HTTP_ROUTE_READ_TOKEN,
     http_get_analysis, http_delete, NULL, NULL},
    {"/v1/analyses/{id}/result", R_RESULT, HTTP_READ, HTTP_ROUTE_READ_TOKEN, http_get_result, NULL,
     NULL, NULL},
    {"/v1/analyses/{id}/request", R_REQUEST, HTTP_READ, HTTP_ROUTE_READ_TOKEN, http_get_request,
     NULL, NULL, NULL},
    /* reads stored results as /result does: its route id (http_mac.c) */
    {"/v1/analyses/{id}/mac", R_RESULT, HTTP_READ, HTTP_ROUTE_READ_TOKEN, http_get_mac, NULL, NULL,
     NULL},
    {"/v1/import/{format}", R_IMPORT, M_POST, 0, NULL, NULL, http_import_begin, http_import_end},
    {"/livez", R_LIVEZ, HTTP_READ, 0, http_livez, NULL, NULL, NULL},
    {"/readyz", R_READYZ, HTTP_READ, 0, http_readyz, NULL, NULL, NULL},
    {"/metrics", R_METRICS, HTTP_READ, HTTP_ROUTE_READ_TOKEN, http_metrics, NULL, NULL, NULL},
};

/* An embedded file (r->file; its path is the template). */
static const http_route_def http_route_file = {NULL, R_FILE, HTTP_READ, 0, http_file,
                                              NULL, NULL, NULL};

const http_route_def *http_route_table(size_t *n)
{
    *n = sizeof(http_routes) / sizeof(http_routes[0]);
    return http_routes;
}

/* ---------------------------------------------------------------- lookup */

/* {format}: s[0..n) is a name of the codec's import_formats[]. */
static int http_route_format(const char *s, size_t n)
{
    char name[64];

    if (n >= sizeof(name))
        return 0;
    memcpy(name, s, n);
    name[n] = '\0';
    return import_format_known(name);
}

/*
 * Does url match the template of d?  Literal text must be equal; a {param}
 * takes one segment (up to the next '/' or the end, maybe empty).  For
 * {format} the segment must name an import format; for {id} any segment
 * matches and r->id/id_ok record whether it is a job id.
 */
static int http_route_match(const http_route_def *d, const char *url, http_req *r)
{
    const char *open = strchr(d->tmpl, '{'), *close, *arg;
    size_t lit, n;

    if (!open)
        return strcmp(d->tmpl, url) == 0;
    lit = (size_t)(open - d->tmpl);
    close = strchr(open, '}');
    if (strncmp(d->tmpl, url, lit) != 0 || !close)
        return 0;
    arg = url + lit;
    n = strcspn(arg, "/");
    if (strcmp(close + 1, arg + n) != 0)
        return 0;
    if (strncmp(open, "{format}", 8) == 0)
        return http_route_format(arg, n);
    r->id_ok = http_is_id(arg, n);
    if (r->id_ok) {
        memcpy(r->id, arg, 64);
        r->id[64] = '\0';
    }
    return 1;
}

void http_route_find(http_req *r, const char *url)
{
    size_t i;

    r->def = NULL;
    r->route = R_OTHER;
    r->tmpl = "other";
    for (i = 0; i < sizeof(http_routes) / sizeof(http_routes[0]); i++)
        if (http_route_match(&http_routes[i], url, r)) {
            r->def = &http_routes[i];
            r->tmpl = r->def->tmpl;
            break;
        }
    if (!r->def && (r->file = embedded_find(url)) != NULL) {
        r->def = &http_route_file;
        r->tmpl = r->file->path;
    }
    if (r->def)
        r->route = r->def->route;
}

/* Methods by name, as M_* bits. */
static const struct {
    const char *name;
    unsigned bit;
} http_methods[] = {{"GET", M_GET}, {"HEAD", M_HEAD}, {"POST", M_POST}, {"DELETE", M_DELETE},
                    {"OPTIONS", M_OPTIONS}};

unsigned http_method_of(const char *name)
{
    size_t i;

    for (i = 0; i < sizeof(http_methods) / sizeof(http_methods[0]); i++)
        if (strcmp(name, http_methods[i].name) == 0)
            return http_methods[i].bit;
    return M_OTHER;
}

const char *http_method_label(unsigned method)
{
    size_t i;

    for (i = 0; i < sizeof(http_methods) / sizeof(http_methods[0]); i++)
        if (method == http_methods[i].bit)
            return http_methods[i].name;
    return "OTHER";
}

/* ---------------------------------------------------------------- answer */

enum MHD_Result http_answer(struct MHD_Connection *c, http_req *r)
{
    const http_route_def *d = r->def;
    int read = r->method == M_GET || r->method == M_HEAD;

    if (r->method == M_OPTIONS && r->h->cors_origin && d)
        return http_preflight(c, r);
    if (r->method == M_OPTIONS && strcmp(r->path, "*") == 0)
        return http_not_allowed(c, r, M_GET | M_HEAD | M_POST | M_DELETE);
    if (!d)
        return http_not_found(c, r, 0);
    if (!(d->methods & r->method) || (read ? !d->get : !d->del))
        return http_not_allowed(c, r, d->methods);
    if (read && (d->flags & HTTP_ROUTE_READ_TOKEN) && r->h->auth_reads &&
        !http_authorized(r->h, c))
        return http_unauthorized(c, r);
    if (read)
        return d->get(c, r);
    if (!http_authorized(r->h, c))
        return http_unauthorized(c, r);
    return d->del(c, r);
}
