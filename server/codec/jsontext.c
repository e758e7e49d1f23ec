/*
 * jsontext.c — a result document as text: the bytes of jansson's json_dump_callback with
 * CODEC_RESULT_DUMP (compact, reals at 17 digits, keys in insertion order), written faster
 * (issue 27, DESIGN.md 2.1).
 *
 * How it fits: result.c's documents are mostly reals; jansson formats each through snprintf
 * (glibc's multi-precision path, ~4 000 instructions a number: 15 % of a 101-speed sweep's
 * process) and hands every piece to its callback.  Here reals take codec_numtext (the same
 * bytes), pieces gather in a buffer, and whatever is not plain — a string with a byte outside
 * printable ASCII, a quote or a backslash — is still written by jansson itself, so escapes and
 * UTF-8 checks stay jansson's.  numtext_test checks the numbers; the CLI and daemon tests
 * compare whole results.
 */
#include "codec_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct jt_out {
    char b[8192];
    size_t n;
    json_dump_callback_t cb;
    void *data;
    int err;
    int sort; /* JSON_SORT_KEYS: an object's keys in strcmp order (jansson's compare_keys) */
} jt_out;

static void jt_flush(jt_out *o)
{
    if (o->n && !o->err && o->cb(o->b, o->n, o->data))
        o->err = 1;
    o->n = 0;
}

static void jt_put(jt_out *o, const char *s, size_t n)
{
    if (n > sizeof o->b - o->n) {
        jt_flush(o);
        if (n > sizeof o->b) {
            if (!o->err && o->cb(s, n, o->data))
                o->err = 1;
            return;
        }
    }
    memcpy(o->b + o->n, s, n);
    o->n += n;
}

/* 1 when s (n bytes) is written between quotes as it is: printable ASCII, no '"' nor '\'. */
static int jt_plain(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)s[i];
        if (c < 0x20 || c > 0x7e || c == '"' || c == '\\')
            return 0;
    }
    return 1;
}

/* The string s (n bytes): plain here, else by jansson (its escapes and UTF-8 check). */
static void jt_string(jt_out *o, const char *s, size_t n)
{
    if (jt_plain(s, n)) {
        jt_put(o, "\"", 1);
        jt_put(o, s, n);
        jt_put(o, "\"", 1);
        return;
    }
    jt_flush(o);
    json_t *t = json_stringn(s, n);
    if (!t || o->err || json_dump_callback(t, o->cb, o->data, JSON_ENCODE_ANY))
        o->err = 1;
    json_decref(t);
}

static void jt_value(jt_out *o, const json_t *x);

/* The real x as jt_value writes a json_real (null when not finite: result.c's res_real), into
 * the buffer itself. */
static void jt_real(jt_out *o, double x)
{
    if (!isfinite(x)) {
        jt_put(o, "null", 4);
        return;
    }
    if (sizeof o->b - o->n < CODEC_NUMTEXT_MAX)
        jt_flush(o);
    o->n += (size_t)codec_numtext(o->b + o->n, x, 1);
}

/* A member of an object being written with its keys sorted. */
typedef struct jt_member {
    const char *key;
    const json_t *v;
} jt_member;

/* strcmp's order of two keys; most keys of an object differ in their first byte, compared here
 * without a call */
static inline int jt_keycmp(const char *a, const char *b)
{
    unsigned char x = (unsigned char)a[0], y = (unsigned char)b[0];
    return x != y ? (int)x - (int)y : x ? strcmp(a + 1, b + 1) : 0;
}

static int jt_member_cmp(const void *a, const void *b)
{
    return jt_keycmp(((const jt_member *)a)->key, ((const jt_member *)b)->key);
}

/* An object with its keys sorted by strcmp, as jansson's JSON_SORT_KEYS writes it.  Objects of
 * up to JT_SMALL members (every object of a request but the big tables) are sorted on the stack
 * by insertion (the keys are distinct: any correct sort gives the same order), their values taken
 * with their keys instead of looked up again (issue 27: the canonical text of every request). */
#define JT_SMALL 32
static void jt_sorted(jt_out *o, const json_t *x)
{
    size_t n = json_object_size(x), i = 0;
    jt_member small[JT_SMALL], *mem = n <= JT_SMALL ? small : malloc(n * sizeof *mem);
    const char *key;
    json_t *v;
    if (!mem) {
        o->err = 1;
        return;
    }
    json_object_foreach((json_t *)x, key, v) {
        jt_member t = {key, v};
        size_t j = i++;
        if (n <= JT_SMALL) /* insertion */
            for (; j > 0 && jt_keycmp(mem[j - 1].key, key) > 0; j--)
                mem[j] = mem[j - 1];
        mem[j] = t;
    }
    if (n > JT_SMALL)
        qsort(mem, n, sizeof *mem, jt_member_cmp);
    jt_put(o, "{", 1);
    for (i = 0; i < n; i++) {
        if (i > 0)
            jt_put(o, ",", 1);
        jt_string(o, mem[i].key, strlen(mem[i].key));
        jt_put(o, ":", 1);
        jt_value(o, mem[i].v);
    }
    jt_put(o, "}", 1);
    if (mem != small)
        free(mem);
}

static void jt_value(jt_out *o, const json_t *x)
{
    char num[CODEC_NUMTEXT_MAX];
    switch (json_typeof(x)) {
    case JSON_OBJECT: {
        if (o->sort) {
            jt_sorted(o, x);
            break;
        }
        const char *key;
        json_t *v;
        int first = 1;
        jt_put(o, "{", 1);
        json_object_foreach((json_t *)x, key, v) {
            if (!first)
                jt_put(o, ",", 1);
            first = 0;
            jt_string(o, key, strlen(key));
            jt_put(o, ":", 1);
            jt_value(o, v);
        }
        jt_put(o, "}", 1);
        break;
    }
    case JSON_ARRAY:
        jt_put(o, "[", 1);
        for (size_t i = 0; i < json_array_size(x); i++) {
            if (i > 0)
                jt_put(o, ",", 1);
            jt_value(o, json_array_get(x, i));
        }
        jt_put(o, "]", 1);
        break;
    case JSON_STRING:
        jt_string(o, json_string_value(x), json_string_length(x));
        break;
    case JSON_INTEGER: {
        int n = snprintf(num, sizeof num, "%" JSON_INTEGER_FORMAT, json_integer_value(x));
        jt_put(o, num, (size_t)n);
        break;
    }
    case JSON_REAL:
        jt_real(o, json_real_value(x)); /* always finite: jansson refuses the others */
        break;
    case JSON_TRUE:
        jt_put(o, "true", 4);
        break;
    case JSON_FALSE:
        jt_put(o, "false", 5);
        break;
    case JSON_NULL:
        jt_put(o, "null", 4);
        break;
    }
}

/* The dump of x (object or array) with keys sorted or not. */
static int jt_dump(const json_t *x, int sort, json_dump_callback_t cb, void *data)
{
    jt_out o;
    if (!json_is_object(x) && !json_is_array(x))
        return -1; /* as json_dump_callback without JSON_ENCODE_ANY */
    o.n = 0;
    o.cb = cb;
    o.data = data;
    o.err = 0;
    o.sort = sort;
    jt_value(&o, x);
    jt_flush(&o);
    return o.err ? -1 : 0;
}

int codec_json_dump(const json_t *x, json_dump_callback_t cb, void *data)
{
    return jt_dump(x, 0, cb, data);
}

/* json_dump_callback into a codec_text; -1 when out of memory. */
static int jt_text(const char *buffer, size_t size, void *data)
{
    codec_text *t = data;
    codec_text_put(t, buffer, size);
    return t->nomem ? -1 : 0;
}

char *codec_json_dumps_sorted(const json_t *x)
{
    codec_text t = {NULL, 0, 0, 0};
    if (jt_dump(x, 1, jt_text, &t) || t.nomem || !t.p) {
        free(t.p);
        return NULL;
    }
    return t.p;
}

int codec_text_json_string(codec_text *t, const char *s, size_t n)
{
    if (jt_plain(s, n)) {
        codec_text_put(t, "\"", 1);
        codec_text_put(t, s, n);
        codec_text_put(t, "\"", 1);
        return t->nomem ? -1 : 0;
    }
    json_t *x = json_stringn(s, n); /* jansson's escapes and UTF-8 check, as jt_string */
    int rc = !x || json_dump_callback(x, jt_text, t, JSON_ENCODE_ANY);
    json_decref(x);
    return rc || t->nomem ? -1 : 0;
}

void codec_text_json_real(codec_text *t, double x)
{
    char num[CODEC_NUMTEXT_MAX];

    if (!isfinite(x)) {
        codec_text_put(t, "null", 4);
        return;
    }
    codec_text_put(t, num, (size_t)codec_numtext(num, x, 1));
}

static int jt_file(const char *buffer, size_t size, void *data)
{
    return fwrite(buffer, 1, size, (FILE *)data) == size ? 0 : -1;
}

int codec_json_dumpf(const json_t *x, FILE *f)
{
    return codec_json_dump(x, jt_file, f);
}
