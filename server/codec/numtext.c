/*
 * numtext.c — a double as the text of printf's "%.17g", and as jansson writes a real at
 * JSON_REAL_PRECISION(17), without glibc's multi-precision formatting (issue 27, DESIGN.md 2.1).
 *
 * How it fits: result documents and CSV tables are mostly numbers at full precision; glibc's
 * printf spends ~4 000 instructions on each (15 % of a 101-speed sweep's whole process).  Here
 * the 17 significant digits come from one or two roundings in x87 extended precision (64-bit
 * significand): N = x 10^p with 10^16 <= N < 10^17 and the powers of ten up to 10^27 exact, so
 * N is within 2 ulp (2^-6 at most, the ulp being <= 2^-7 there) of x 10^p.  Only the distance
 * of N's fraction to one half decides the rounding: when it is within the error bound, and for
 * everything outside 1e-38..1e70, subnormals and non-finite values, the text
 * is glibc's own (snprintf).  The bytes are therefore those of "%.17g" (numtext_units checks
 * millions of values against snprintf).  Without a 64-bit long double every value takes the
 * snprintf path.
 */
#include "codec_internal.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#if LDBL_MANT_DIG == 64
/* 10^k, k = 0..27: exact in a 64-bit significand (5^27 < 2^64). */
static const long double numtext_pow10[28] = {
    1e0L,  1e1L,  1e2L,  1e3L,  1e4L,  1e5L,  1e6L,  1e7L,  1e8L,  1e9L,
    1e10L, 1e11L, 1e12L, 1e13L, 1e14L, 1e15L, 1e16L, 1e17L, 1e18L, 1e19L,
    1e20L, 1e21L, 1e22L, 1e23L, 1e24L, 1e25L, 1e26L, 1e27L,
};

/* N = x 10^p and its error bound in ulps of N, or 0 when p is out of reach. */
static int numtext_scale(double x, int p, long double *N)
{
    long double v = (long double)x;
    if (p >= 0 && p <= 27) {
        *N = v * numtext_pow10[p];
        return 1;
    }
    if (p < 0 && p >= -27) {
        *N = v / numtext_pow10[-p];
        return 1;
    }
    if (p > 27 && p <= 54) {
        *N = (v * numtext_pow10[27]) * numtext_pow10[p - 27];
        return 2;
    }
    if (p < -27 && p >= -54) {
        *N = (v / numtext_pow10[27]) / numtext_pow10[-p - 27];
        return 2;
    }
    return 0;
}

/* "00" to "99": two digits a step (numtext_digits). */
static const char numtext_pairs[201] = "00010203040506070809101112131415161718192021222324"
                                       "25262728293031323334353637383940414243444546474849"
                                       "50515253545556575859606162636465666768697071727374"
                                       "75767778798081828384858687888990919293949596979899";

/* The 17 significant digits of x > 0 (normal) into dig and its decimal exponent into *X
 * (x ~ d.dddd 10^X after rounding); 0 when the rounding is not sure (the caller asks glibc).
 * The exponents come from the bits and the floor of N from its integer part instead of frexp,
 * frexpl, ldexpl and floorl (the same values), and the digits two at a time (issue 27). */
static int numtext_digits(double x, char dig[17], int *X)
{
    int X0, ulps = 0, found = 0;
    long double N = 0;
    uint64_t bits;
    memcpy(&bits, &x, sizeof bits);
    int e2 = (int)((bits >> 52) & 0x7ff) - 1022; /* frexp's: 2^(e2-1) <= x < 2^e2 (normal x) */
    /* floor((e2 - 1) log10 2), the first guess of the decimal exponent (the search below
     * settles it): ((e2 - 1) 78913) >> 18 is floor((e2 - 1) 0.30102999566398120) for every
     * double's exponent (checked for |e2| <= 1100) */
    X0 = (int)(((int64_t)(e2 - 1) * 78913) >> 18);
    for (int X1 = X0 + 1; X1 >= X0 - 1 && !found; X1--) { /* the largest X with N >= 1e16 */
        if (!(ulps = numtext_scale(x, 16 - X1, &N)))
            return 0;
        if (N >= 1e16L) {
            *X = X1;
            found = 1;
        }
    }
    /* near either end of [1e16, 1e17) the exponent itself is not sure */
    if (!found || !(N >= 1e16L + 4 && N < 1e17L - 4))
        return 0;
    /* an ulp of N: 2^(e-64) for 2^(e-1) <= N < 2^e, e = 54..57 in [1e16, 1e17) */
    long double ulp = N < 0x1p54L   ? 0x1p-10L
                      : N < 0x1p55L ? 0x1p-9L
                      : N < 0x1p56L ? 0x1p-8L
                                    : 0x1p-7L;
    long double err = (long double)ulps * ulp;
    uint64_t fl = (uint64_t)N;              /* floor: 0 < N < 2^57 */
    long double frac = N - (long double)fl; /* exact */
    if (fabsl(frac - 0.5L) <= err)
        return 0; /* too close to a tie to round here */
    uint64_t D = fl + (frac > 0.5L);
    if (D >= 100000000000000000ULL) /* cannot happen below 1e17 - 4, kept for safety */
        return 0;
    /* 9 + 8 digits: the halves in 32 bits (a 64-bit division by a constant costs twice) */
    uint32_t h = (uint32_t)(D / 100000000u), l = (uint32_t)(D % 100000000u);
    for (int i = 15; i > 8; i -= 2, l /= 100) {
        dig[i] = numtext_pairs[2 * (l % 100)];
        dig[i + 1] = numtext_pairs[2 * (l % 100) + 1];
    }
    for (int i = 7; i > 0; i -= 2, h /= 100) {
        dig[i] = numtext_pairs[2 * (h % 100)];
        dig[i + 1] = numtext_pairs[2 * (h % 100) + 1];
    }
    dig[0] = (char)('0' + h);
    return 1;
}

/* "%.17g" of x from its digits and exponent into buf; json: jansson's form (".0" after a
 * number without point or exponent, no '+' nor leading zeros in the exponent).  Returns the
 * length. */
static int numtext_layout(char *buf, int neg, const char dig[17], int X, int json)
{
    int n = 0, last = 16;
    while (last > 0 && dig[last] == '0')
        last--; /* %g drops trailing zeros */
    if (neg)
        buf[n++] = '-';
    if (X < -4 || X >= 17) {
        buf[n++] = dig[0];
        if (last > 0) {
            buf[n++] = '.';
            memcpy(buf + n, dig + 1, (size_t)last);
            n += last;
        }
        buf[n++] = 'e';
        int ax = X < 0 ? -X : X;
        if (X < 0)
            buf[n++] = '-';
        else if (!json)
            buf[n++] = '+';
        if (ax >= 100)
            buf[n++] = (char)('0' + ax / 100);
        if (ax >= 10 || !json)
            buf[n++] = (char)('0' + ax / 10 % 10);
        buf[n++] = (char)('0' + ax % 10);
    } else if (X >= 0) {
        memcpy(buf + n, dig, (size_t)X + 1);
        n += X + 1;
        if (last > X) {
            buf[n++] = '.';
            memcpy(buf + n, dig + X + 1, (size_t)(last - X));
            n += last - X;
        } else if (json) {
            buf[n++] = '.';
            buf[n++] = '0';
        }
    } else {
        buf[n++] = '0';
        buf[n++] = '.';
        for (int i = 0; i < -X - 1; i++)
            buf[n++] = '0';
        memcpy(buf + n, dig, (size_t)last + 1);
        n += last + 1;
    }
    buf[n] = '\0';
    return n;
}
#endif

/* glibc's "%.17g", and for json jansson's changes to it (jsonp_dtostr, jansson 2.14). */
static int numtext_printf(char *buf, double x, int json)
{
    int n = snprintf(buf, CODEC_NUMTEXT_MAX, "%.17g", x);
    if (!json || n < 0 || n >= CODEC_NUMTEXT_MAX - 3)
        return n;
    if (!strchr(buf, '.') && !strchr(buf, 'e')) {
        buf[n++] = '.';
        buf[n++] = '0';
        buf[n] = '\0';
    }
    char *start = strchr(buf, 'e');
    if (start) {
        start++;
        char *end = start + 1;
        if (*start == '-')
            start++;
        while (*end == '0')
            end++;
        if (end != start) {
            memmove(start, end, (size_t)(n - (end - buf)) + 1);
            n -= (int)(end - start);
        }
    }
    return n;
}

int codec_numtext(char *buf, double x, int json)
{
    if (x == 0) { /* "0" or "-0" ("0.0", "-0.0" in JSON): a tenth of a mode shape's values */
        int n = 0;
        if (signbit(x))
            buf[n++] = '-';
        buf[n++] = '0';
        if (json) {
            buf[n++] = '.';
            buf[n++] = '0';
        }
        buf[n] = '\0';
        return n;
    }
#if LDBL_MANT_DIG == 64
    char dig[17];
    int X;
    if (isnormal(x) && numtext_digits(fabs(x), dig, &X))
        return numtext_layout(buf, x < 0, dig, X, json);
#endif
    return numtext_printf(buf, x, json);
}
