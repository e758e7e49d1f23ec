/*
 * numtext_test.c — codec_numtext (server/codec/numtext.c) gives the bytes of glibc's "%.17g"
 * (json 0) and of jansson's own dump of a real at JSON_REAL_PRECISION(17) (json 1), for:
 *  1. random bit patterns (every finite double: subnormals, huge, tiny);
 *  2. random doubles spread evenly in log10 over 1e-45..1e75, either sign (the fast path's range
 *     and beyond it);
 *  3. values near ties and edges: the first, a random and the last double of every binary
 *     exponent; m 2^k for small odd m and k = -200..200 (finite binary
 *     fractions: their exact decimals end in 5), 10^k and its neighbours in every decade of the
 *     normal doubles (and random values of each, which codec_numtext must write without
 *     snprintf: every power of ten of its table in use), integers around
 *     10^16 and 10^17, numbers whose 17-digit rounding carries into a new decade
 *     (9.99999999999999999e k), 0, -0, the largest and smallest doubles;
 *  4. the numbers of a solved result: frequencies, shape components, eigenvalues (all of them
 *     written without snprintf; of all normal values checked at least 99 %);
 * and codec_json_dump / codec_json_dumps_sorted (jsontext.c) against jansson's own compact
 * dump, with and without JSON_SORT_KEYS, on 3 000 random documents (nested objects — one in 16
 * with 30 to 41 keys, past jt_sorted's stack array — and arrays,
 * keys and strings with quotes, backslashes, control characters and UTF-8, reals, integers).
 */
#include <float.h>
#include <jansson.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "codec_internal.h"
#include "xorshift.h"

static long checked, failures;
static long normals, direct; /* normal values checked, and how many codec_numtext wrote itself */

static uint64_t rng = 0x9E3779B97F4A7C15ULL;

static uint64_t next_u64(void)
{
    return xorshift64(&rng);
}

/* x against snprintf, and against jansson's dump when with_jansson. */
static void check(double x, int with_jansson)
{
    char want[64], got[CODEC_NUMTEXT_MAX];
    if (!isfinite(x))
        return;
    checked++;
    if (isnormal(x)) {
        normals++;
        direct += codec_numtext_direct(x);
    }
    snprintf(want, sizeof want, "%.17g", x);
    int n = codec_numtext(got, x, 0);
    if (n != (int)strlen(want) || strcmp(got, want)) {
        if (failures++ < 20)
            printf("FAIL %%.17g of %a: got '%s' want '%s'\n", x, got, want);
    }
    if (!with_jansson)
        return;
    json_t *r = json_real(x);
    char *j = r ? json_dumps(r, JSON_ENCODE_ANY | JSON_REAL_PRECISION(17)) : NULL;
    n = codec_numtext(got, x, 1);
    if (!j || n != (int)strlen(j) || strcmp(got, j)) {
        if (failures++ < 20)
            printf("FAIL json of %a: got '%s' want '%s'\n", x, got, j ? j : "(null)");
    }
    free(j);
    json_decref(r);
}

/* A random JSON value of depth up to d: objects with keys in random order (some not plain
 * ASCII, some needing escapes), arrays, reals, integers, strings, true, false, null. */
static json_t *random_doc(int d)
{
    static const char *strs[] = {"plain",     "1st edge", "quote\"d",    "back\\slash",
                                 "tab\there", "ctl\x01",  "caf\xc3\xa9", "\xe2\x86\x92 arrow",
                                 "",          "/slash"};
    int kind = d > 0 ? (int)(next_u64() % 9) : 2 + (int)(next_u64() % 7);
    uint64_t b;
    double x;
    switch (kind) {
    case 0: {
        json_t *o = json_object();
        /* mostly small objects; one in 16 larger than jt_sorted's stack array (32) */
        int n = next_u64() % 16 ? (int)(next_u64() % 6) : 30 + (int)(next_u64() % 12);
        for (int i = 0; i < n; i++) {
            char key[32];
            snprintf(key, sizeof key, "%s%d", strs[next_u64() % 10], (int)(next_u64() % 50));
            json_object_set_new(o, key, random_doc(d - 1));
        }
        return o;
    }
    case 1: {
        json_t *a = json_array();
        int n = (int)(next_u64() % 6);
        for (int i = 0; i < n; i++)
            json_array_append_new(a, random_doc(d - 1));
        return a;
    }
    case 2:
        b = next_u64();
        memcpy(&x, &b, sizeof x);
        return json_real(isfinite(x) ? x : 0.5);
    case 3:
        return json_real((double)(next_u64() % 1000) / 8.0);
    case 4:
        return json_integer((json_int_t)(next_u64() >> 1) * (next_u64() & 1 ? -1 : 1));
    case 5:
        return json_string(strs[next_u64() % 10]);
    case 6:
        return json_true();
    case 7:
        return json_false();
    default:
        return json_null();
    }
}

static int put_text(const char *buffer, size_t size, void *data)
{
    FILE *f = data;
    return fwrite(buffer, 1, size, f) == size ? 0 : -1;
}

/* codec_json_dump = json_dump_callback(CODEC_RESULT_DUMP) and codec_json_dumps_sorted =
 * json_dumps(JSON_SORT_KEYS | compact | precision 17) on random documents. */
static void check_documents(int count)
{
    for (int i = 0; i < count; i++) {
        json_t *doc = json_object();
        json_object_set_new(doc, "a", random_doc(4));
        json_object_set_new(doc, "z\xc3\xa9", random_doc(3));
        char *want = json_dumps(doc, CODEC_RESULT_DUMP), *got = NULL, *ws = NULL, *gs = NULL;
        size_t len = 0;
        FILE *f = open_memstream(&got, &len);
        int rc = codec_json_dump(doc, put_text, f);
        fclose(f);
        ws = json_dumps(doc, JSON_SORT_KEYS | JSON_COMPACT | JSON_REAL_PRECISION(17));
        gs = codec_json_dumps_sorted(doc);
        checked++;
        if (rc || !want || strcmp(want, got) || !ws || !gs || strcmp(ws, gs)) {
            if (failures++ < 20)
                printf(
                    "FAIL document %d:\n want %.300s\n got  %.300s\n sorted want %.300s\n sorted got  %.300s\n",
                    i, want, got, ws, gs ? gs : "(null)");
        }
        free(want);
        free(got);
        free(ws);
        free(gs);
        json_decref(doc);
    }
}

int main(void)
{
    /* 1. random bits */
    for (int i = 0; i < 1000000; i++) {
        uint64_t b = next_u64();
        double x;
        memcpy(&x, &b, sizeof x);
        check(x, i % 8 == 0);
    }
    /* 2. log-uniform over 1e-45..1e75, either sign */
    for (int i = 0; i < 1000000; i++) {
        double u = (double)(next_u64() >> 11) / 9007199254740992.0;
        double x = pow(10.0, -45 + 120 * u);
        check(next_u64() & 1 ? -x : x, i % 8 == 0);
    }
    /* 3. ties and edges */
    for (int k = -200; k <= 200; k++)
        for (int m = 1; m < 2000; m += 2)
            check(ldexp((double)m, k), m < 200);
    for (int k = -307; k <= 308; k++) { /* every decade of the normal doubles */
        double p = k < 0 ? 1.0 / pow(10.0, -k) : pow(10.0, k);
        double x = p;
        for (int s = 0; s < 40; s++) {
            check(x, 1);
            x = nextafter(x, INFINITY);
        }
        x = p;
        for (int s = 0; s < 40; s++) {
            check(x, 1);
            x = nextafter(x, 0);
        }
        if (k < 308) {
            check(9.99999999999999999 * p, 1);
            check(9.9999999999999995 * p, 1);
        }
        check(1.00000000000000005 * p, 1);
        /* random values of the decade: each power of ten of the table in use.  None is near a
         * tie, except in 1e14..1e16, where a double has 2 or 3 binary digits after the point
         * (so 18 significant decimals, the last one 5, for every other value of 1e15) */
        for (int r = 0; r < 4 && (k < 14 || k > 15); r++) {
            double y = p * (1 + 8.9 * (double)(next_u64() >> 11) / 9007199254740992.0);
            check(y, 0);
            if (isfinite(y) && !codec_numtext_direct(y)) {
                failures++;
                printf("FAIL %a (decade %d) went to snprintf\n", y, k);
            }
        }
    }
    /* every binary exponent: its first double, a random one and its last (the exponent and
     * the decimal exponent's first guess come from the bits, numtext_digits), either sign */
    for (int e = -1021; e <= 1024; e++) {
        double lo = ldexp(1.0, e - 1), hi = nextafter(ldexp(1.0, e), 0);
        double mid = ldexp(1.0 + (double)(next_u64() >> 12) / 4503599627370496.0, e - 1);
        check(lo, 1);
        check(-hi, 1);
        check(mid, e % 4 == 0);
        check(hi, 0);
    }
    for (double x = 1e16 - 64; x <= 1e16 + 64; x += 2) /* doubles are 2 apart there */
        check(x, 1);
    for (double x = 1e17 - 1024; x <= 1e17 + 1024; x += 16) /* 16 apart */
        check(x, 1);
    double edge[] = {0.0,
                     -0.0,
                     DBL_MAX,
                     -DBL_MAX,
                     DBL_MIN,
                     DBL_TRUE_MIN,
                     1.0,
                     -1.0,
                     0.1,
                     0.5,
                     1e-5,
                     1e-4,
                     9.9999999999999995e-5,
                     1e16,
                     1e17,
                     123456789012345678.0,
                     0.30000000000000004};
    for (size_t i = 0; i < sizeof edge / sizeof *edge; i++)
        check(edge[i], 1);
    /* 4. numbers like a result's: frequencies, shapes (with round-off noise), eigenvalues */
    for (int i = 0; i < 200000; i++) {
        double u = (double)(next_u64() >> 11) / 9007199254740992.0;
        double v = (double)(next_u64() >> 11) / 9007199254740992.0;
        check(1 + 500 * u, i % 4 == 0);                      /* rad/s */
        check((2 * v - 1) * pow(10.0, -18 * u), i % 4 == 0); /* shape components */
        check(-1e-3 * u * v, i % 4 == 0);                    /* small real parts */
    }
    /* the result-like numbers of 4. never near a tie: all written without snprintf */
    long before = direct, of = normals;
    for (int i = 0; i < 20000; i++) {
        double u = (double)(next_u64() >> 11) / 9007199254740992.0;
        double v = (double)(next_u64() >> 11) / 9007199254740992.0;
        check(1 + 500 * u, 0);
        check((2 * v - 1) * pow(10.0, -18 * u), 0);
    }
    if (direct - before != normals - of) {
        failures++;
        printf("FAIL %ld of %ld result-like values went to snprintf\n",
               (normals - of) - (direct - before), normals - of);
    }
    check_documents(3000);
    /* snprintf only near ties (binary fractions with few digits, section 3): ~0.5 % here */
    if (!(direct >= 0.99 * normals)) {
        failures++;
        printf("FAIL only %ld of %ld normal values written without snprintf\n", direct, normals);
    }
    printf("numtext: %ld values and documents, %ld failures; %ld of %ld normal values without "
           "snprintf\n",
           checked, failures, direct, normals);
    return failures ? 1 : 0;
}
