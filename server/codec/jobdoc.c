/*
 * jobdoc.c — the daemon's documents about jobs (status, listing, validate
 * answer, a failed job's error object) and the text buffer they are written
 * into.  See jobdoc.h.
 *
 * How it fits: the daemon reads a job from its store, describes it with a
 * codec_job_view and sends what this file writes; the stored result text is
 * spliced in verbatim, never re-parsed.  Helpers of this file are jdoc_*.
 */
#include "codec.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ----------------------------------------------------------- text buffer */

char *codec_text_room(codec_text *t, size_t n)
{
    if (t->nomem)
        return NULL;
    if (t->len + n + 1 > t->cap) {
        size_t ncap = t->cap ? t->cap : 1024;
        char *np;
        while (ncap < t->len + n + 1)
            ncap *= 2;
        np = realloc(t->p, ncap);
        if (!np) {
            t->nomem = 1;
            return NULL;
        }
        t->p = np;
        t->cap = ncap;
    }
    return t->p + t->len;
}

void codec_text_put(codec_text *t, const char *s, size_t n)
{
    char *q = codec_text_room(t, n);

    if (!q)
        return;
    memcpy(q, s, n);
    t->len += n;
    t->p[t->len] = '\0';
}

void codec_text_reserve(codec_text *t, size_t n)
{
    char *np;

    if (t->nomem || t->len + n + 1 <= t->cap)
        return;
    np = realloc(t->p, t->len + n + 1);
    if (!np) {
        t->nomem = 1;
        return;
    }
    t->p = np;
    t->cap = t->len + n + 1;
}

void codec_text_puts(codec_text *t, const char *s)
{
    codec_text_put(t, s, strlen(s));
}

void codec_text_printf(codec_text *t, const char *fmt, ...)
{
    char tmp[256];
    va_list ap;
    int n;

    va_start(ap, fmt);
    n = vsnprintf(tmp, sizeof(tmp), fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= sizeof(tmp)) { /* callers format short fields only */
        t->nomem = 1;
        return;
    }
    codec_text_put(t, tmp, (size_t)n);
}

void codec_text_free(codec_text *t)
{
    if (!t)
        return;
    free(t->p);
    memset(t, 0, sizeof(*t));
}

void codec_time_rfc3339(double t, char buf[32])
{
    time_t s = (time_t)t;
    int ms = (int)((t - (double)s) * 1000.0);
    struct tm tm;
    char ymdhms[24];
    size_t n;

    if (ms < 0)
        ms = 0;
    if (ms > 999)
        ms = 999;
    gmtime_r(&s, &tm);
    n = strftime(ymdhms, sizeof(ymdhms), "%Y-%m-%dT%H:%M:%S", &tm);
    ymdhms[n] = '\0';
    snprintf(buf, 32, "%.20s.%03dZ", ymdhms, ms % 1000);
}

/* ------------------------------------------------------------- documents */

/* A timestamp member value: the quoted RFC 3339 text, or null when t is 0. */
static void jdoc_time(codec_text *t, double when)
{
    char ts[32];

    if (when <= 0.0) {
        codec_text_puts(t, "null");
        return;
    }
    codec_time_rfc3339(when, ts);
    codec_text_printf(t, "\"%s\"", ts);
}

/* key, then s as a JSON string (escaped by jansson). */
static void jdoc_string(codec_text *t, const char *key, const char *s)
{
    json_t *j = json_string(s);
    char *q = j ? json_dumps(j, JSON_ENCODE_ANY) : NULL;

    if (!q)
        t->nomem = 1;
    else {
        codec_text_puts(t, key);
        codec_text_puts(t, q);
    }
    free(q);
    json_decref(j);
}

/* The status document of v, with the result when with_result and v has one. */
static void jdoc_status(codec_text *t, const codec_job_view *v, int with_result)
{
    codec_text_printf(t, "{\"id\":\"%s\",\"state\":\"%s\",\"progress\":{\"done\":%d,\"total\":%d}",
                      v->id, v->state, v->done, v->total);
    codec_text_puts(t, ",\"created_at\":");
    jdoc_time(t, v->created_at);
    codec_text_puts(t, ",\"started_at\":");
    jdoc_time(t, v->started_at);
    codec_text_puts(t, ",\"finished_at\":");
    jdoc_time(t, v->finished_at);
    codec_text_printf(t, ",\"attempts\":%d,\"cancel_requested\":%s,\"error\":", v->attempts,
                      v->cancel_requested ? "true" : "false");
    codec_text_puts(t, v->error && v->error[0] ? v->error : "null");
    if (v->name)
        jdoc_string(t, ",\"name\":", v->name);
    codec_text_printf(t, ",\"links\":{\"self\":\"/v1/analyses/%s\",", v->id);
    codec_text_printf(t, "\"result\":\"/v1/analyses/%s/result\"}", v->id);
    if (with_result && v->result) {
        codec_text_puts(t, ",\"result\":");
        codec_text_put(t, v->result, v->result_len);
    }
    codec_text_puts(t, "}");
}

void codec_job_status(codec_text *t, const codec_job_view *v)
{
    codec_text_reserve(t, 1024 + (v->result ? v->result_len : 0) +
                              (v->error ? strlen(v->error) : 0));
    jdoc_status(t, v, 1);
}

void codec_job_list(codec_text *t, const codec_job_view *items, int n, const char *next)
{
    int i;

    codec_text_puts(t, "{\"items\":[");
    for (i = 0; i < n; i++) {
        if (i)
            codec_text_puts(t, ",");
        jdoc_status(t, &items[i], 0);
    }
    codec_text_puts(t, "],\"next\":");
    if (next) {
        codec_text_puts(t, "\"");
        codec_text_puts(t, next);
        codec_text_puts(t, "\"}");
    } else {
        codec_text_puts(t, "null}");
    }
}

int codec_job_id(const codec_request *req, char id[65])
{
    char buf[64 + 1 + 64];
    int n = snprintf(buf, sizeof(buf), "%s:%s", codec_request_sha256(req), sm_version());

    if (n < 0 || (size_t)n >= sizeof(buf))
        return SM_NOMEM;
    return codec_sha256_hex(buf, (size_t)n, id);
}

void codec_validate_doc(codec_text *t, const char *id, const codec_request *req)
{
    codec_text_printf(t, "{\"valid\":true,\"id\":\"%s\",\"request_sha256\":\"%s\",\"canonical\":",
                      id, codec_request_sha256(req));
    codec_text_puts(t, codec_request_canonical_text(req));
    if (json_array_size(codec_request_input_warnings(req))) { /* DESIGN.md 8: unit slips */
        char *w = json_dumps(codec_request_input_warnings(req), JSON_COMPACT);
        if (!w)
            t->nomem = 1;
        codec_text_puts(t, ",\"input_warnings\":");
        codec_text_puts(t, w ? w : "[]");
        free(w);
    }
    codec_text_puts(t, "}");
}

char *codec_job_error_text(const char *type, const char *title, const char *detail,
                           json_t *errors, json_t *diagnostics)
{
    json_t *e = json_object();
    char *text = NULL;

    if (!e)
        goto done;
    if (json_object_set_new(e, "type", json_string(type)) ||
        json_object_set_new(e, "title", json_string(title)) ||
        json_object_set_new(e, "detail", json_string(detail ? detail : "")))
        goto done;
    if (errors && json_object_set_new(e, "errors", json_incref(errors)))
        goto done;
    if (diagnostics && json_object_set_new(e, "diagnostics", json_incref(diagnostics)))
        goto done;
    text = json_dumps(e, JSON_COMPACT | JSON_REAL_PRECISION(17));
done:
    json_decref(errors);
    json_decref(diagnostics);
    json_decref(e);
    return text;
}
