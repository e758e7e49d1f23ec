/*
 * numtext_test.c — codec_numtext (server/codec/numtext.c) gives the bytes of glibc's "%.17g"
 * (json 0) and of jansson's own dump of a real at JSON_REAL_PRECISION(17) (json 1), for:
 *  1. random bit patterns (every finite double: subnormals, huge, tiny);
 *  2. random doubles spread evenly in log10 over 1e-45..1e75, either sign (the fast path's range
 *     and beyond it);
 *  3. values near ties and edges: m 2^k for small odd m and k = -200..200 (finite binary
 *     fractions: their exact decimals end in 5), 10^k and its neighbours, integers around
 *     10^16 and 10^17, numbers whose 17-digit rounding carries into a new decade
 *     (9.99999999999999999e k), 0, -0, the largest and smallest doubles;
 *  4. the numbers of a solved result: frequencies, shape components, eigenvalues.
 * Prints how many values took the fast path.
 */
#include <float.h>
#include <jansson.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "codec_internal.h"

static long checked, failures;

static uint64_t rng = 0x9E3779B97F4A7C15ULL;

static uint64_t next_u64(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
}

/* x against snprintf, and against jansson's dump when with_jansson. */
static void check(double x, int with_jansson)
{
    char want[64], got[CODEC_NUMTEXT_MAX];
    if (!isfinite(x))
        return;
    checked++;
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
    for (int k = -44; k <= 74; k++) {
        double p = pow(10.0, k);
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
        check(9.99999999999999999 * p, 1);
        check(9.9999999999999995 * p, 1);
        check(1.00000000000000005 * p, 1);
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
    printf("numtext: %ld values, %ld failures\n", checked, failures);
    return failures ? 1 : 0;
}
