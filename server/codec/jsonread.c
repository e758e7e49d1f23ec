/*
 * jsonread.c — a request's text as a jansson tree: the tree json_loadb gives, built faster
 * (issue 27, DESIGN.md 2.1).
 *
 * How it fits: req_parse (request.c), the one parse of every request the CLI and the daemon
 * take, spent 40 % of its time in jansson's lexer (a function call and a buffer append a
 * byte, a copy of every token).  Here plain JSON — ASCII strings with the short escapes,
 * numbers, literals, nesting up to JSON_FAST_DEPTH — is read straight from the buffer into the
 * same jansson values: integers by strtoll and reals by strtod on the token jansson would hand
 * them (jansson's own calls, so the same values and the same overflow rules) or, a real whose
 * digits make an integer w <= 2^53 with a decimal exponent within +-22, by one multiplication
 * or division of exact doubles (codec_json_real_fast: strtod's bits in a tenth of its time),
 * object members in text order (jansson keeps insertion order), a repeated key refused as
 * JSON_REJECT_DUPLICATES does.  Whatever is not plain — a byte outside printable ASCII in a
 * string, a \u escape, any syntax error, a number out of range, a decimal point that is not
 * '.' in the current locale, a flag other than JSON_REJECT_DUPLICATES, running out of memory —
 * makes the fast reader give up and jansson read the whole text itself, so every error, its
 * message and position, UTF-8 checks and Unicode escapes stay jansson's.  test_jsonread and
 * the fuzz target compare both trees value by value, reals by their bits.
 */
#include "codec_internal.h"

#include <errno.h>
#include <float.h>
#include <langinfo.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Nesting the fast reader takes (jansson's limit, JSON_PARSER_MAX_DEPTH, is 2048; deeper
 * text goes to jansson, which reads or refuses it). */
#define JSON_FAST_DEPTH 256
/* The longest number token read here (longer ones go to jansson). */
#define JSON_FAST_NUMBER 128

typedef struct jr {
    const char *p, *end;
    int reject_dup;
    int depth;
    char *buf; /* a string with escapes, unescaped */
    size_t cap;
} jr;

static void jr_ws(jr *r)
{
    while (r->p < r->end && (*r->p == ' ' || *r->p == '\n' || *r->p == '\r' || *r->p == '\t'))
        r->p++;
}

/* The string whose opening quote r->p is past: its bytes in *s (the text itself, or r->buf
 * when it has escapes) and *n.  Returns 0, or -1 to give up (not plain, or out of memory). */
static int jr_string(jr *r, const char **s, size_t *n)
{
    const char *q = r->p;
    while (q < r->end && *q != '"' && *q != '\\' && (unsigned char)*q >= 0x20 &&
           (unsigned char)*q < 0x7f)
        q++;
    if (q < r->end && *q == '"') {
        *s = r->p;
        *n = (size_t)(q - r->p);
        r->p = q + 1;
        return 0;
    }
    if (q >= r->end || *q != '\\')
        return -1; /* a control byte, DEL, a byte >= 0x80, or no closing quote: jansson's */
    size_t k = 0;
    for (q = r->p; q < r->end && *q != '"'; q++) {
        char c = *q;
        if ((unsigned char)c < 0x20 || (unsigned char)c >= 0x7f)
            return -1;
        if (c == '\\') {
            if (++q >= r->end)
                return -1;
            switch (*q) {
            case '"':
                c = '"';
                break;
            case '\\':
                c = '\\';
                break;
            case '/':
                c = '/';
                break;
            case 'b':
                c = '\b';
                break;
            case 'f':
                c = '\f';
                break;
            case 'n':
                c = '\n';
                break;
            case 'r':
                c = '\r';
                break;
            case 't':
                c = '\t';
                break;
            default:
                return -1; /* \u (jansson's UTF-8) or an invalid escape */
            }
        }
        if (k == r->cap) {
            size_t cap = r->cap ? 2 * r->cap : 256;
            char *b = realloc(r->buf, cap);
            if (!b)
                return -1;
            r->buf = b;
            r->cap = cap;
        }
        r->buf[k++] = c;
    }
    if (q >= r->end)
        return -1;
    *s = r->buf ? r->buf : "";
    *n = k;
    r->p = q + 1;
    return 0;
}

/* 10^0 .. 10^22: every one exact in a double (5^22 < 2^53). */
static const double jr_pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                    1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                    1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

int codec_json_real_fast(const char *s, size_t n, double *out)
{
#if FLT_EVAL_METHOD == 0
    const char *e = s + n;
    uint64_t w = 0;
    int neg = 0, digits = 0, frac = 0, ex = 0, exneg = 0;
    if (s < e && *s == '-') {
        neg = 1;
        s++;
    }
    for (; s < e && *s >= '0' && *s <= '9'; s++)
        if (w || *s != '0') { /* leading zeros are no significant digits */
            if (++digits > 19)
                return 0;
            w = 10 * w + (uint64_t)(*s - '0');
        }
    if (s < e && *s == '.')
        for (s++; s < e && *s >= '0' && *s <= '9'; s++) {
            frac++;
            if (w || *s != '0') {
                if (++digits > 19)
                    return 0;
                w = 10 * w + (uint64_t)(*s - '0');
            }
        }
    if (s < e && (*s == 'e' || *s == 'E')) {
        s++;
        if (s < e && (*s == '+' || *s == '-'))
            exneg = *s++ == '-';
        for (; s < e && *s >= '0' && *s <= '9'; s++)
            if ((ex = 10 * ex + (*s - '0')) > 9999)
                return 0;
    }
    if (s != e || w > (1ULL << 53))
        return 0;
    int p = (exneg ? -ex : ex) - frac;
    double d = (double)w; /* exact */
    if (w && (p < -22 || p > 22))
        return 0;
    if (w)
        d = p >= 0 ? d * jr_pow10[p] : d / jr_pow10[-p]; /* one rounding of exact operands */
    *out = neg ? -d : d;
    return 1;
#else /* x87 arithmetic would round twice */
    (void)s;
    (void)n;
    (void)out;
    return 0;
#endif
}

/* A number at r->p, by jansson's grammar (lex_scan_number) and conversions; NULL to give up. */
static json_t *jr_number(jr *r)
{
    const char *q = r->p, *e = r->end;
    int real = 0;
    if (q < e && *q == '-')
        q++;
    if (q >= e || *q < '0' || *q > '9')
        return NULL;
    if (*q == '0') {
        q++;
        if (q < e && *q >= '0' && *q <= '9')
            return NULL; /* a leading zero: jansson's error */
    } else {
        while (q < e && *q >= '0' && *q <= '9')
            q++;
    }
    if (q < e && *q == '.') {
        real = 1;
        q++;
        if (q >= e || *q < '0' || *q > '9')
            return NULL;
        while (q < e && *q >= '0' && *q <= '9')
            q++;
    }
    if (q < e && (*q == 'e' || *q == 'E')) {
        real = 1;
        q++;
        if (q < e && (*q == '+' || *q == '-'))
            q++;
        if (q >= e || *q < '0' || *q > '9')
            return NULL;
        while (q < e && *q >= '0' && *q <= '9')
            q++;
    }
    size_t n = (size_t)(q - r->p);
    char tok[JSON_FAST_NUMBER + 1], *end = NULL;
    double d;
    if (real && codec_json_real_fast(r->p, n, &d)) {
        json_t *v = json_real(d);
        if (v)
            r->p = q;
        return v;
    }
    if (n > JSON_FAST_NUMBER)
        return NULL;
    memcpy(tok, r->p, n);
    tok[n] = '\0';
    errno = 0;
    json_t *v;
    if (real) {
        d = strtod(tok, &end);
        if ((d == HUGE_VAL || d == -HUGE_VAL) && errno == ERANGE)
            return NULL; /* jansson: "real number overflow" */
        v = json_real(d);
    } else {
        long long i = strtoll(tok, &end, 10);
        if (errno == ERANGE)
            return NULL; /* jansson: "too big integer" */
        v = json_integer((json_int_t)i);
    }
    if (end != tok + n) { /* cannot happen for the grammar above; jansson decides */
        json_decref(v);
        return NULL;
    }
    r->p = q;
    return v;
}

static json_t *jr_value(jr *r);

/* The object or array whose opening bracket r->p is past; NULL to give up. */
static json_t *jr_container(jr *r, int object)
{
    char close = object ? '}' : ']', *own = NULL;
    json_t *c = object ? json_object() : json_array();
    if (!c || ++r->depth > JSON_FAST_DEPTH)
        goto fail;
    jr_ws(r);
    if (r->p < r->end && *r->p == close) {
        r->p++;
        r->depth--;
        return c;
    }
    for (;;) {
        const char *key = NULL;
        size_t klen = 0;
        if (object) {
            if (r->p >= r->end || *r->p != '"')
                goto fail;
            r->p++;
            if (jr_string(r, &key, &klen))
                goto fail;
            if (key == r->buf) { /* unescaped into r->buf, which the value's strings reuse */
                if (!(own = malloc(klen ? klen : 1)))
                    goto fail;
                memcpy(own, key, klen);
                key = own;
            }
            jr_ws(r);
            if (r->p >= r->end || *r->p != ':')
                goto fail;
            r->p++;
        }
        json_t *v = jr_value(r);
        if (!v)
            goto fail;
        size_t had = object ? json_object_size(c) : 0;
        if (object ? json_object_setn_new_nocheck(c, key, klen, v) : json_array_append_new(c, v))
            goto fail;
        /* a repeated key replaced the first one's value and left the size: jansson refuses it
         * (one hash of the key, not a lookup and then an insert) */
        if (object && r->reject_dup && json_object_size(c) == had)
            goto fail;
        free(own);
        own = NULL;
        jr_ws(r);
        if (r->p < r->end && *r->p == ',') {
            r->p++;
            jr_ws(r);
            continue;
        }
        if (r->p >= r->end || *r->p != close)
            goto fail;
        r->p++;
        r->depth--;
        return c;
    }
fail:
    free(own);
    json_decref(c);
    return NULL;
}

/* A value at r->p (whitespace before it skipped); NULL to give up. */
static json_t *jr_value(jr *r)
{
    jr_ws(r);
    if (r->p >= r->end)
        return NULL;
    const char *s;
    size_t n, left = (size_t)(r->end - r->p);
    switch (*r->p) {
    case '{':
        r->p++;
        return jr_container(r, 1);
    case '[':
        r->p++;
        return jr_container(r, 0);
    case '"':
        r->p++;
        return jr_string(r, &s, &n) ? NULL : json_stringn_nocheck(s, n);
    case 't':
        if (left >= 4 && !memcmp(r->p, "true", 4)) {
            r->p += 4;
            return json_true();
        }
        return NULL;
    case 'f':
        if (left >= 5 && !memcmp(r->p, "false", 5)) {
            r->p += 5;
            return json_false();
        }
        return NULL;
    case 'n':
        if (left >= 4 && !memcmp(r->p, "null", 4)) {
            r->p += 4;
            return json_null();
        }
        return NULL;
    default:
        return jr_number(r);
    }
}

json_t *codec_json_fast(const char *text, size_t len, size_t flags)
{
    /* nl_langinfo, not localeconv: glibc's localeconv writes a static struct on every call (a
     * data race between the daemon's request threads); nl_langinfo only reads the locale */
    const char *point = nl_langinfo(RADIXCHAR);
    if ((flags & ~(size_t)JSON_REJECT_DUPLICATES) || !text || !point || strcmp(point, "."))
        return NULL;
    jr r = {text, text + len, (flags & JSON_REJECT_DUPLICATES) != 0, 0, NULL, 0};
    jr_ws(&r);
    if (r.p >= r.end || (*r.p != '{' && *r.p != '['))
        return NULL; /* jansson: "'[' or '{' expected" */
    json_t *v = jr_value(&r);
    free(r.buf);
    if (!v)
        return NULL;
    jr_ws(&r);
    if (r.p != r.end) { /* jansson: "end of file expected" */
        json_decref(v);
        return NULL;
    }
    return v;
}

json_t *codec_json_loadb(const char *text, size_t len, size_t flags, json_error_t *error)
{
    json_t *v = codec_json_fast(text, len, flags);
    return v ? v : json_loadb(text, len, flags, error);
}
