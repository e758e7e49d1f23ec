/*
 * resout.c — where result.c writes a case and the document's head: a jansson tree or straight
 * into text (issue 27).
 *
 * How it fits: result.c describes each part of the result document once, as calls to ro_open,
 * ro_real, ro_rows ... on a res_out (codec_internal.h).  With t NULL they build the tree that
 * codec_result_encode returns (the daemon's documents, --pretty, the tables); with t set they
 * append the compact text that codec_json_dump would write of that tree (CODEC_RESULT_DUMP:
 * insertion order, reals by codec_numtext, strings with jansson's escapes, null for a real that
 * is not finite), without a tree: building, walking and freeing ~50 blocks a mode was half of a
 * 12-element blade's result text.  Rows of reals, most of a result, are written in place with
 * their room made once.  size_units.c compares the two for every part of a document.  Helpers of
 * this file are ro_*.
 */
#include "codec_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Text: the separator and key of the next member of the innermost container. */
static void ro_key(res_out *o, const char *key)
{
    if (o->depth > 0 && o->count[o->depth - 1]++)
        codec_text_put(o->t, ",", 1);
    if (key) {
        if (codec_text_json_string(o->t, key, strlen(key)))
            o->nomem = 1;
        codec_text_put(o->t, ":", 1);
    }
}

/* Tree: v (stolen; NULL: out of memory) as member key of the innermost container. */
static void ro_tree(res_out *o, const char *key, json_t *v)
{
    json_t *in = o->depth > 0 ? o->c[o->depth - 1] : NULL;

    if (!v || !in || (key ? json_object_set_new(in, key, v) : json_array_append_new(in, v)))
        o->nomem = 1;
}

/* Open an object (object 1) or array as member key (NULL in an array). */
void ro_open(res_out *o, const char *key, int object)
{
    if (o->depth >= RES_DEPTH) { /* cannot happen: a case is 5 deep */
        o->nomem = 1;
        return;
    }
    if (o->t) {
        ro_key(o, key);
        codec_text_put(o->t, object ? "{" : "[", 1);
        o->close[o->depth] = object ? '}' : ']';
        o->count[o->depth++] = 0;
        return;
    }
    json_t *x = object ? json_object() : json_array();
    if (o->depth > 0)
        ro_tree(o, key, json_incref(x));
    o->c[o->depth++] = x;
    if (!x)
        o->nomem = 1;
}

/* Close the innermost container (a tree's root stays in c[0]). */
void ro_close(res_out *o)
{
    if (o->depth <= 0)
        return;
    o->depth--;
    if (o->t)
        codec_text_put(o->t, &o->close[o->depth], 1);
    else if (o->depth > 0)
        json_decref(o->c[o->depth]); /* its parent holds it */
}

/* A real (null when not finite, as res_real). */
void ro_real(res_out *o, const char *key, double x)
{
    if (o->t) {
        ro_key(o, key);
        codec_text_json_real(o->t, x);
    } else {
        ro_tree(o, key, isfinite(x) ? json_real(x) : json_null());
    }
}

void ro_int(res_out *o, const char *key, long long v)
{
    if (o->t) {
        char num[24];
        ro_key(o, key);
        codec_text_put(o->t, num,
                       (size_t)snprintf(num, sizeof num, "%" JSON_INTEGER_FORMAT, (json_int_t)v));
    } else {
        ro_tree(o, key, json_integer((json_int_t)v));
    }
}

/* null, true or false (lit 0, 1, 2). */
static void ro_lit(res_out *o, const char *key, int lit)
{
    static const char *const text[] = {"null", "true", "false"};

    if (o->t) {
        ro_key(o, key);
        codec_text_puts(o->t, text[lit]);
    } else {
        ro_tree(o, key, lit == 0 ? json_null() : json_boolean(lit == 1));
    }
}

void ro_null(res_out *o, const char *key)
{
    ro_lit(o, key, 0);
}

void ro_bool(res_out *o, const char *key, int b)
{
    ro_lit(o, key, b ? 1 : 2);
}

void ro_string(res_out *o, const char *key, const char *s)
{
    if (o->t) {
        ro_key(o, key);
        if (codec_text_json_string(o->t, s, strlen(s)))
            o->nomem = 1;
    } else {
        ro_tree(o, key, json_string(s));
    }
}

/* Text: [v0,v1,...] from n reals at q (room made: n (CODEC_NUMTEXT_MAX + 1) + 2); the end. */
static char *ro_text_reals(char *q, const double *v, int n)
{
    *q++ = '[';
    for (int k = 0; k < n; k++) {
        if (k > 0)
            *q++ = ',';
        if (isfinite(v[k])) {
            q += codec_numtext(q, v[k], 1);
        } else {
            memcpy(q, "null", 4);
            q += 4;
        }
    }
    *q++ = ']';
    return q;
}

/* Text: [[x, y, phi], ...] from rows of dof reals each (rows < 0: the one row [v0, ...] of dof
 * reals), written in place with its room made once (the numbers are most of a result). */
static void ro_text_block(res_out *o, const char *key, const double *v, int rows, int dof)
{
    size_t n = rows < 0 ? 1 : (size_t)rows;
    char *q, *start;

    ro_key(o, key);
    if (!(q = start = codec_text_room(o->t, 2 + n * ((size_t)dof * (CODEC_NUMTEXT_MAX + 1) + 3))))
        return;
    if (rows < 0) {
        q = ro_text_reals(q, v, dof);
    } else {
        *q++ = '[';
        for (int k = 0; k < rows; k++) {
            if (k > 0)
                *q++ = ',';
            q = ro_text_reals(q, v + (size_t)dof * (size_t)k, dof);
        }
        *q++ = ']';
    }
    o->t->len += (size_t)(q - start);
    o->t->p[o->t->len] = '\0';
}

void ro_reals(res_out *o, const char *key, const double *v, int n)
{
    if (o->t) {
        ro_text_block(o, key, v, -1, n);
        return;
    }
    ro_open(o, key, 0);
    for (int k = 0; k < n; k++)
        ro_real(o, NULL, v[k]);
    ro_close(o);
}

void ro_rows(res_out *o, const char *key, const double *v, int n, int dof)
{
    if (o->t) {
        ro_text_block(o, key, v, n, dof);
        return;
    }
    ro_open(o, key, 0);
    for (int k = 0; k < n; k++)
        ro_reals(o, NULL, v + (size_t)dof * (size_t)k, dof);
    ro_close(o);
}
