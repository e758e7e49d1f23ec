/*
 * http_body.c — receiving the body of a POST (phases 1 and 2 of the
 * handler, see http.c): bearer token, content type, ?wait, the
 * --max-body cap (by Content-Length at once, or while a chunked body
 * arrives: then a 413 is written straight to the socket and the connection
 * closed, so a client cannot make the daemon read an endless body).
 */
#include "http_internal.h"

#include <errno.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>

/* ------------------------------------------------------------------ POST */

/* 1 when the bearer token of the request is the configured one (or none is). */
int http_authorized(const http *h, struct MHD_Connection *c)
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

enum MHD_Result http_unauthorized(struct MHD_Connection *c, http_req *r)
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
enum MHD_Result http_too_large(struct MHD_Connection *c, http_req *r)
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
enum MHD_Result http_early_too_large(struct MHD_Connection *c, http_req *r)
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
 * Header checks of POST /v1/analyses and /v1/validate (validate needs the
 * token only under --auth-reads, takes no wait and is served while
 * stopping).  Returns 1 when the body should be read, 0 after
 * queueing an answer (*q).
 */
int http_post_begin(struct MHD_Connection *c, http_req *r, enum MHD_Result *q)
{
    int submit = r->route == R_ANALYSES;
    const char *cl;
    long long n = 0;

    if ((submit || r->h->auth_reads) && !http_authorized(r->h, c)) {
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
void http_take_body(http_req *r, const char *data, size_t n)
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
