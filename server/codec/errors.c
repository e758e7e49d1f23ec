/*
 * errors.c — the list of validation errors and the JSON pointers they carry.
 *
 * How it fits: every failure of the codec (invalid field, malformed text,
 * core diagnostic) is appended here as {RFC 6901 pointer, message};
 * problem.c turns the list into the "errors" member of a problem document.
 * The list keeps the first CODEC_MAX_ERRORS and counts the rest, so a
 * hostile request cannot make it grow without bound.  The pointer builders
 * (err_ptr_key, err_ptr_idx) and the malloc'd printf live here too: the
 * validation walk and the diagnostic mapping build their pointers with them.
 */
#include "codec_internal.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct codec_error {
    char *pointer;   /* RFC 6901 pointer, "" = whole document */
    char *message;   /* sentence for a user */
} codec_error;

struct codec_errors {
    int n;              /* stored errors */
    int cap;            /* allocated entries of items */
    codec_error *items; /* n errors in the order found */
    int dropped;        /* errors not stored past CODEC_MAX_ERRORS */
    int malformed;      /* the text was not JSON */
    int too_large;      /* the text exceeded max_request_bytes */
    int nomem;          /* an append failed for lack of memory */
};

/* malloc'd printf; NULL when out of memory.  Formatted once into a stack buffer when it fits
 * (validation formats texts for every member and station of a request: issue 27). */
char *err_vfmt(const char *fmt, va_list ap)
{
    char buf[256];
    va_list aq;
    int n;
    char *s;

    va_copy(aq, ap);
    n = vsnprintf(buf, sizeof buf, fmt, aq);
    va_end(aq);
    if (n < 0)
        return NULL;
    s = malloc((size_t)n + 1);
    if (!s)
        return NULL;
    if ((size_t)n < sizeof buf)
        memcpy(s, buf, (size_t)n + 1);
    else
        vsnprintf(s, (size_t)n + 1, fmt, ap);
    return s;
}

char *err_fmt(const char *fmt, ...)
{
    va_list ap;
    char *s;

    va_start(ap, fmt);
    s = err_vfmt(fmt, ap);
    va_end(ap);
    return s;
}

codec_errors *codec_errors_new(void)
{
    return calloc(1, sizeof(codec_errors));
}

void codec_errors_clear(codec_errors *e)
{
    int i;

    if (!e)
        return;
    for (i = 0; i < e->n; i++) {
        free(e->items[i].pointer);
        free(e->items[i].message);
    }
    e->n = 0;
    e->dropped = 0;
    e->malformed = 0;
    e->too_large = 0;
    e->nomem = 0;
}

void codec_errors_free(codec_errors *e)
{
    if (!e)
        return;
    codec_errors_clear(e);
    free(e->items);
    free(e);
}

/* Store one error; takes ownership of message (may be NULL = NOMEM). */
static int err_push(codec_errors *e, const char *pointer, char *message)
{
    char *p = NULL;

    if (!message)
        goto fail;
    if (e->n >= CODEC_MAX_ERRORS) {
        e->dropped++;
        free(message);
        return SM_OK;
    }
    if (e->n == e->cap) {
        int cap = e->cap ? 2 * e->cap : 8;
        codec_error *items;
        if (cap > CODEC_MAX_ERRORS + 1)
            cap = CODEC_MAX_ERRORS + 1;
        items = realloc(e->items, (size_t)cap * sizeof(*items));
        if (!items)
            goto fail;
        e->items = items;
        e->cap = cap;
    }
    p = strdup(pointer ? pointer : "");
    if (!p)
        goto fail;
    e->items[e->n].pointer = p;
    e->items[e->n].message = message;
    e->n++;
    return SM_OK;
fail:
    free(message);
    e->nomem = 1;
    return SM_NOMEM;
}

int err_vadd(codec_errors *e, const char *pointer, const char *fmt, va_list ap)
{
    return err_push(e, pointer, err_vfmt(fmt, ap));
}

int codec_errors_add(codec_errors *e, const char *pointer, const char *fmt, ...)
{
    va_list ap;
    int rc;

    va_start(ap, fmt);
    rc = err_vadd(e, pointer, fmt, ap);
    va_end(ap);
    return rc;
}

int codec_errors_count(const codec_errors *e)
{
    return e ? e->n + (e->dropped > 0) : 0;
}

const char *codec_errors_pointer(const codec_errors *e, int i)
{
    if (!e || i < 0 || i >= codec_errors_count(e))
        return NULL;
    return i < e->n ? e->items[i].pointer : "";
}

const char *codec_errors_message(const codec_errors *e, int i)
{
    if (!e || i < 0 || i >= codec_errors_count(e))
        return NULL;
    return i < e->n ? e->items[i].message : "more errors were found and not listed";
}

int codec_errors_malformed(const codec_errors *e)
{
    return e ? e->malformed : 0;
}

int codec_errors_too_large(const codec_errors *e)
{
    return e ? e->too_large : 0;
}

void err_mark_malformed(codec_errors *e)
{
    e->malformed = 1;
}

void err_mark_too_large(codec_errors *e)
{
    e->too_large = 1;
}

void err_mark_nomem(codec_errors *e)
{
    e->nomem = 1;
}

json_t *codec_errors_to_json(const codec_errors *e)
{
    json_t *arr = json_array();
    int i, n = codec_errors_count(e);

    if (!arr)
        return NULL;
    for (i = 0; i < n; i++) {
        json_t *it = json_pack("{s:s, s:s}", "pointer", codec_errors_pointer(e, i),
                               "message", codec_errors_message(e, i));
        if (json_array_append_new(arr, it))
            goto fail;
    }
    return arr;
fail:
    json_decref(arr);
    return NULL;
}

/* ------------------------------------------------ RFC 6901 pointers */

/* base + "/" + key with RFC 6901 escaping (~ -> ~0, / -> ~1); NULL = NOMEM. */
char *err_ptr_key(const char *base, const char *key)
{
    size_t nb = strlen(base), nk = strlen(key), extra = 0, i, j;
    char *s;

    for (i = 0; i < nk; i++)
        extra += (key[i] == '~' || key[i] == '/');
    s = malloc(nb + 1 + nk + extra + 1);
    if (!s)
        return NULL;
    memcpy(s, base, nb);
    j = nb;
    s[j++] = '/';
    for (i = 0; i < nk; i++) {
        if (key[i] == '~' || key[i] == '/') {
            s[j++] = '~';
            s[j++] = key[i] == '~' ? '0' : '1';
        } else {
            s[j++] = key[i];
        }
    }
    s[j] = '\0';
    return s;
}

/* base + "/" + index (decimal); NULL = NOMEM.  Written here, not by printf: validation makes one
 * for every element of every array it checks. */
char *err_ptr_idx(const char *base, size_t i)
{
    char digits[24];
    int nd = 0;
    do {
        digits[nd++] = (char)('0' + i % 10);
        i /= 10;
    } while (i);
    size_t nb = strlen(base);
    char *s = malloc(nb + 1 + (size_t)nd + 1);
    if (!s)
        return NULL;
    memcpy(s, base, nb);
    s[nb] = '/';
    for (int k = 0; k < nd; k++)
        s[nb + 1 + k] = digits[nd - 1 - k];
    s[nb + 1 + nd] = '\0';
    return s;
}
