/*
 * jsonread_test.c — codec_json_fast and codec_json_loadb (server/codec/jsonread.c) against
 * jansson's json_loadb, with and without JSON_REJECT_DUPLICATES:
 *  1. every .json file under the folders given (examples/, the codec cases, the fuzz corpus);
 *     every file of the first folder (examples/: plain ASCII requests) must take the fast path;
 *  2. hand-made edge cases: each number form and overflow jansson refuses or takes, literals
 *     run into letters, trailing commas, leading zeros, a repeated key, escapes (short ones read
 *     here, \u left to jansson), bytes >= 0x80, control bytes, a NUL inside the text, nesting
 *     past the fast reader's depth and past jansson's, text after the value, a byte order mark;
 *  3. 2 000 random documents (nested objects and arrays, integers, reals in several printf
 *     forms, strings with escapes, random whitespace), every one of which must take the fast
 *     path, and 40 000 single-byte mutations of them (replaced, deleted, inserted);
 *  4. codec_json_real_fast (reals without strtod) against strtod, bit for bit, on 500 000
 *     tokens in and around its range (2^53, 10^+-22, 19 digits, leading zeros, signs), and
 *     that it answers exactly inside that range.
 * Wherever the fast reader gives a tree, jansson must give the same one (json_same.h: reals by
 * bits, members in order); codec_json_loadb must give jansson's tree, or NULL with jansson's
 * error (text, line, column, position).
 */
#define _XOPEN_SOURCE 700 /* nftw */
#include <ftw.h>
#include <jansson.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codec_internal.h"
#include "xorshift.h"
#include "json_same.h"

static long checked, fast_taken, failures;

/* 10^k, 0 <= k <= 22, exactly */
static double jr_test_pow10(int k)
{
    double x = 1;
    while (k-- > 0)
        x *= 10;
    return x;
}

static uint64_t rng = 0x2545F4914F6CDD1DULL;

static uint64_t next_u64(void)
{
    return xorshift64(&rng);
}

static void show(const char *what, const char *text, size_t len)
{
    fprintf(stderr, "FAIL: %s: ", what);
    for (size_t i = 0; i < len && i < 160; i++)
        fputc((unsigned char)text[i] >= 0x20 && (unsigned char)text[i] < 0x7f ? text[i] : '?',
              stderr);
    fputc('\n', stderr);
    failures++;
}

/* text against jansson with flags; returns 1 when the fast reader gave the tree. */
static int check_flags(const char *text, size_t len, size_t flags)
{
    json_error_t ref_err, got_err;
    json_t *ref = json_loadb(text, len, flags, &ref_err);
    json_t *fast = codec_json_fast(text, len, flags);
    json_t *got = codec_json_loadb(text, len, flags, &got_err);
    checked++;
    if (fast && !json_same(fast, ref))
        show(ref ? "the fast tree differs from jansson's"
                 : "the fast reader took what jansson refuses",
             text, len);
    if (ref ? !json_same(got, ref)
            : got || strcmp(got_err.text, ref_err.text) || got_err.line != ref_err.line ||
                  got_err.column != ref_err.column || got_err.position != ref_err.position)
        show("codec_json_loadb differs from json_loadb", text, len);
    int took = fast != NULL;
    json_decref(ref);
    json_decref(fast);
    json_decref(got);
    return took;
}

static int check(const char *text, size_t len)
{
    int a = check_flags(text, len, 0), b = check_flags(text, len, JSON_REJECT_DUPLICATES);
    fast_taken += a;
    return a && b;
}

static int check_str(const char *text)
{
    return check(text, strlen(text));
}

/* ---- 1. files ---- */

static int files_must_be_fast, files_seen;

static int on_file(const char *path, const struct stat *sb, int type, struct FTW *ftw)
{
    (void)sb;
    (void)ftw;
    size_t n = strlen(path);
    if (type != FTW_F || n < 5 || strcmp(path + n - 5, ".json"))
        return 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    char *buf = malloc(1 << 22);
    size_t len = buf ? fread(buf, 1, 1 << 22, f) : 0;
    fclose(f);
    if (buf) {
        files_seen++;
        if (!check(buf, len) && files_must_be_fast)
            show("an examples/ file did not take the fast path", path, strlen(path));
    }
    free(buf);
    return 0;
}

/* ---- 3. random documents ---- */

typedef struct gen {
    char *b;
    size_t n, cap;
} gen;

static void put(gen *g, const char *s, size_t n)
{
    if (g->n + n + 1 > g->cap) {
        g->cap = 2 * (g->n + n + 1);
        g->b = realloc(g->b, g->cap);
        if (!g->b)
            abort();
    }
    memcpy(g->b + g->n, s, n);
    g->n += n;
    g->b[g->n] = '\0';
}

static void puts_(gen *g, const char *s)
{
    put(g, s, strlen(s));
}

static void ws(gen *g)
{
    static const char *w[] = {"", "", "", " ", "\n", "\t", "\r\n  ", "  "};
    puts_(g, w[next_u64() % 8]);
}

static void gen_string(gen *g)
{
    static const char *piece[] = {"a",   "Zq",  "blade", " ",   "\\n", "\\\"", "\\\\", "\\/", "\\t",
                                  "\\b", "\\f", "\\r",   "x_1", "{",   "]",    ":",    ","};
    int n = (int)(next_u64() % 6);
    puts_(g, "\"");
    for (int i = 0; i < n; i++)
        puts_(g, piece[next_u64() % (sizeof piece / sizeof *piece)]);
    puts_(g, "\"");
}

static void gen_number(gen *g)
{
    char t[64];
    double x = (double)(int64_t)next_u64() / (double)(1ULL << (next_u64() % 63));
    if (next_u64() % 3 == 0)
        x = x * 1e-300 * (double)(next_u64() % 1000);
    switch (next_u64() % 7) {
    case 0:
        snprintf(t, sizeof t, "%lld", (long long)(int64_t)next_u64() >> (next_u64() % 64));
        break;
    case 1:
        snprintf(t, sizeof t, "%.17g", x);
        break;
    case 2:
        snprintf(t, sizeof t, "%.3e", x);
        break;
    case 3:
        snprintf(t, sizeof t, "%.6f", x / 1e12);
        break;
    case 4:
        snprintf(t, sizeof t, "%.17G", x);
        break;
    case 5:
        snprintf(t, sizeof t, "%d", (int)(next_u64() % 3) - 1);
        break;
    default:
        snprintf(t, sizeof t, "%.1f", (double)(next_u64() % 100));
        break;
    }
    if (!strchr(t, 'n') && !strchr(t, 'N')) /* inf, nan: not JSON */
        puts_(g, t);
    else
        puts_(g, "0");
}

static void gen_value(gen *g, int depth)
{
    int k = (int)(next_u64() % (depth > 5 ? 6 : 9));
    ws(g);
    if (k < 3) {
        gen_number(g);
    } else if (k == 3) {
        gen_string(g);
    } else if (k == 4) {
        static const char *lit[] = {"true", "false", "null"};
        puts_(g, lit[next_u64() % 3]);
    } else if (k == 5) {
        gen_number(g);
    } else if (k < 8) {
        int n = (int)(next_u64() % 5);
        puts_(g, "{");
        for (int i = 0; i < n; i++) {
            char key[32];
            if (i)
                puts_(g, ",");
            ws(g);
            snprintf(key, sizeof key, "\"k%d%s\"", i, next_u64() % 4 ? "" : "\\n");
            puts_(g, key);
            ws(g);
            puts_(g, ":");
            gen_value(g, depth + 1);
        }
        ws(g);
        puts_(g, "}");
    } else {
        int n = (int)(next_u64() % 6);
        puts_(g, "[");
        for (int i = 0; i < n; i++) {
            if (i)
                puts_(g, ",");
            gen_value(g, depth + 1);
        }
        ws(g);
        puts_(g, "]");
    }
    ws(g);
}

/* ---- 4. reals without strtod ---- */

static long reals_checked, reals_taken;

/* tok through codec_json_real_fast: its bits must be strtod's wherever it answers, and it must
 * answer exactly when `expect` says (Clinger's range: the integer w of all the digits written,
 * trailing zeros too, <= 2^53 and exponent -22..22: "9007199254740992.0" is w = 2^53 * 10). */
static void check_real(const char *tok, int expect)
{
    double got = 0, ref = strtod(tok, NULL);
    int took = codec_json_real_fast(tok, strlen(tok), &got);
    reals_checked++;
    reals_taken += took;
    if (took && memcmp(&got, &ref, sizeof got))
        show("codec_json_real_fast differs from strtod", tok, strlen(tok));
    if (took != expect)
        show(took ? "codec_json_real_fast answered outside its range"
                  : "codec_json_real_fast gave up inside its range",
             tok, strlen(tok));
}

/* A token of the digits of w with the point after `point` of them (0: "0." first, with `zeros`
 * zeros after the point; ndig: no point) and exponent ex (written when write_ex), and whether
 * codec_json_real_fast must take it. */
static void check_real_parts(uint64_t w, int neg, int point, int zeros, int ex, int write_ex)
{
    char dig[24], tok[96];
    int nd = snprintf(dig, sizeof dig, "%llu", (unsigned long long)w), n = 0, frac = 0;
    if (neg)
        tok[n++] = '-';
    if (point <= 0) {
        n += snprintf(tok + n, sizeof tok - (size_t)n, "0.%.*s%s", zeros, "0000000000", dig);
        frac = zeros + nd;
    } else if (point >= nd) {
        n += snprintf(tok + n, sizeof tok - (size_t)n, "%s", dig);
    } else {
        n += snprintf(tok + n, sizeof tok - (size_t)n, "%.*s.%s", point, dig, dig + point);
        frac = nd - point;
    }
    if (write_ex)
        snprintf(tok + n, sizeof tok - (size_t)n, "e%+d", ex);
    int p = (write_ex ? ex : 0) - frac;
    check_real(tok, w == 0 || (w <= (1ULL << 53) && p >= -22 && p <= 22));
}

static void check_reals(void)
{
    static const char *edge[] = {
        "0.0", "-0.0", "0e999", "-0.000e-5", "1e22", "1e23", "1e-22", "1e-23", "9007199254740992.0",
        "9007199254740993.0", "9007199254740991e22", "9007199254740993e-22", "1.5E+3",
        "12345678901234567890.0", "1234567890123456789.0", "1e0005", "1e99999", "0.1",
        "0.30000000000000004", "2.2250738585072014e-308",
        /* 2^64 + 1 and 2^64 + 2^32: wrapped in 64 bits, 1 and 2^32 */
        "18446744073709551617", "0.18446744073709551617e3", "18446744078004518912e-20"};
    static const int expect[] = {1, 1, 1, 1, 1, 0, 1, 0, 0, 0, 1, 0,
                                 1, 0, 0, 1, 0, 1, 0, 0, 0, 0, 0};
    for (size_t i = 0; i < sizeof edge / sizeof *edge; i++)
        check_real(edge[i], expect[i]);
    for (int i = 0; i < 400000; i++) {
        uint64_t w;
        switch (next_u64() % 4) {
        case 0: /* around 2^53 */
            w = (1ULL << 53) - 4 + next_u64() % 9;
            break;
        case 1: /* up to 19 digits */
            w = next_u64() % 10000000000000000000ULL;
            break;
        default: /* 1 to 16 digits, as requests write them */
            w = next_u64() % (uint64_t)jr_test_pow10(1 + (int)(next_u64() % 16));
            break;
        }
        int nd = snprintf(NULL, 0, "%llu", (unsigned long long)w);
        check_real_parts(w, (int)(next_u64() % 2), (int)(next_u64() % (unsigned)(nd + 2)),
                         (int)(next_u64() % 4), (int)(next_u64() % 61) - 30,
                         (int)(next_u64() % 3 == 0));
    }
    /* requests' reals: %.15g of random doubles near 1e-6 .. 1e12 must all be taken */
    for (int i = 0; i < 100000; i++) {
        char tok[40];
        double x = (double)(next_u64() >> 11) / (double)(1ULL << 53) *
                   jr_test_pow10((int)(next_u64() % 19)) * 1e-6;
        snprintf(tok, sizeof tok, "%.15g", x);
        if (!strchr(tok, 'e'))
            check_real(tok, 1);
        else
            check_real(tok, codec_json_real_fast(tok, strlen(tok), &x));
    }
    /* and through the reader: the tree must be jansson's */
    for (int i = 0; i < 2000; i++) {
        char doc[64];
        snprintf(doc, sizeof doc, "[%.*g]", 1 + (int)(next_u64() % 17),
                 (double)(int64_t)next_u64() / jr_test_pow10((int)(next_u64() % 23)));
        check_str(doc);
    }
}

int main(int argc, char **argv)
{
    /* 1. files: the first folder's must all be fast */
    for (int i = 1; i < argc; i++) {
        int before = files_seen;
        files_must_be_fast = i == 1;
        nftw(argv[i], on_file, 16, FTW_PHYS);
        if (files_seen == before) {
            fprintf(stderr, "FAIL: no .json file under %s\n", argv[i]);
            failures++;
        }
    }

    /* 2. edge cases */
    static const char *edge[] = {
        "",
        " ",
        "{}",
        "[]",
        " [ ] ",
        "{ }",
        "[1,]",
        "{\"a\":1,}",
        "[01]",
        "[-0]",
        "[-0.0]",
        "[0.0]",
        "[1e400]",
        "[-1e400]",
        "[1e-400]",
        "[4.9e-324]",
        "[2.2250738585072011e-308]",
        "[-]",
        "[1.]",
        "[.5]",
        "[1e]",
        "[1e+]",
        "[1E-2]",
        "[1.5e3]",
        "[+1]",
        "[0x10]",
        "[truex]",
        "[true false]",
        "[nul]",
        "[tru]",
        "[null]",
        "{\"a\":1,\"a\":2}",
        "{\"a\":{\"b\":1,\"b\":1}}",
        "[\"\\u0041\"]",
        "[\"\\u0000\"]",
        "[\"a\\nb\"]",
        "{\"a\\nb\":\"c\\td\",\"a\\u000ab\":1}",
        "{\"a\\nb\":1,\"a\\nb\":2}",
        "[\"\\x\"]",
        "[\"\xc3\xa9\"]",
        "[\"\xff\"]",
        "\xef\xbb\xbf{}",
        "[1] x",
        "[1]\n\t ",
        "[1][2]",
        "  {\"k\": [1, 2.5, -3e-7, true, false, null, \"s\", {}, []]}  ",
        "[9223372036854775807]",
        "[9223372036854775808]",
        "[-9223372036854775808]",
        "[-9223372036854775809]",
        "\"top\"",
        "123",
        "true",
        "[\"\x01\"]",
        "[\"\x7f\"]",
        "[\"abc",
        "{\"a\" 1}",
        "{1:2}",
        "[1 2]",
        "[\"a\\\"b\"]",
        "{\"\":0}",
        "{\"\":0,\"\":1}",
        "[\"\\\\\"]",
        "{\"a\":[1,{\"b\":[]}],\"c\":\"\\/\"}",
        "[1,2",
        "{\"a\":",
        "{\"a\"",
        "{",
        "[",
        "]",
        "}",
        "[\"\t\"]",
        "[1.0e+308, 1.7976931348623157e308, 1.7976931348623159e308]",
        "[123456789012345678901234567890.5]",
        "[-0e0]",
        "[0e-0]",
        "[00.5]",
        "[-01]",
    };
    for (size_t i = 0; i < sizeof edge / sizeof *edge; i++)
        check_str(edge[i]);
    /* plain ones must be read here, not by jansson */
    static const char *plain[] = {"{}",       " [ ] ",       "[-0.0]",
                                  "[1e-400]", "[\"a\\nb\"]", "{\"a\\nb\":\"c\\td\"}",
                                  "[1]\n\t ", "{\"\":0}",    "[123456789012345678901234567890.5]"};
    for (size_t i = 0; i < sizeof plain / sizeof *plain; i++)
        if (!check_str(plain[i]))
            show("plain JSON did not take the fast path", plain[i], strlen(plain[i]));
    /* a NUL inside the text, with its length */
    check("[1,\0 2]", 7);
    check("[\"a\0b\"]", 7);
    /* nesting: past the fast reader's depth (jansson reads it), past jansson's (refused) */
    for (int depth = 250; depth <= 2100; depth += 925) {
        gen g = {NULL, 0, 0};
        for (int i = 0; i < depth; i++)
            puts_(&g, i % 2 ? "{\"k\":" : "[");
        puts_(&g, "1");
        for (int i = depth - 1; i >= 0; i--)
            puts_(&g, i % 2 ? "}" : "]");
        check(g.b, g.n);
        free(g.b);
    }

    /* 3. random documents and their mutations */
    static const char alphabet[] = "{}[]:,\"\\ \n0123456789.eE+-tfnul\x01\x80\xff";
    long random_docs = 0, random_fast = 0;
    for (int d = 0; d < 2000; d++) {
        gen g = {NULL, 0, 0};
        ws(&g);
        if (next_u64() % 2) {
            puts_(&g, "{\"a\":");
            gen_value(&g, 0);
            puts_(&g, ",\"b\":");
            gen_value(&g, 0);
            puts_(&g, "}");
        } else {
            puts_(&g, "[");
            gen_value(&g, 0);
            puts_(&g, "]");
        }
        random_docs++;
        random_fast += check(g.b, g.n);
        for (int m = 0; m < 20 && g.n > 0; m++) {
            char *t = malloc(g.n + 2);
            size_t pos = next_u64() % g.n, n = g.n;
            char c = alphabet[next_u64() % (sizeof alphabet - 1)];
            memcpy(t, g.b, g.n);
            switch (next_u64() % 3) {
            case 0:
                t[pos] = c;
                break;
            case 1:
                memmove(t + pos, t + pos + 1, n - pos - 1);
                n--;
                break;
            default:
                memmove(t + pos + 1, t + pos, n - pos);
                t[pos] = c;
                n++;
                break;
            }
            check(t, n);
            free(t);
        }
        free(g.b);
    }
    if (random_fast != random_docs) {
        fprintf(stderr, "FAIL: %ld of %ld random plain documents took the fast path\n", random_fast,
                random_docs);
        failures++;
    }
    /* 4. reals without strtod */
    check_reals();
    printf("jsonread: %ld texts checked against json_loadb (x2 flags), %ld read by the fast "
           "reader, %d files, %ld random documents; %ld reals against strtod, %ld of them "
           "without it; %ld failures\n",
           checked / 2, fast_taken, files_seen, random_docs, reals_checked, reals_taken, failures);
    return failures ? 1 : 0;
}
