/*
 * numtext.c — a double as the text of printf's "%.17g", and as jansson writes a real at
 * JSON_REAL_PRECISION(17), without glibc's multi-precision formatting (issue 27, DESIGN.md 2.1).
 *
 * How it fits: result documents and CSV tables are mostly numbers at full precision; glibc's
 * printf spends ~4 000 instructions on each (15 % of a 101-speed sweep's whole process).  Here
 * the 17 significant digits come from N = x 10^p (10^16 <= N < 10^17) in 192-bit integer
 * arithmetic: x's 53-bit significand times a 128-bit power of ten from a table written at build
 * time (numtext_pow10.py): N to within 2^-69.  Only when N's fraction lies that close
 * to one half (a tie, or near one), and for subnormals and non-finite values, is the text glibc's
 * own (snprintf).  The bytes are therefore those of "%.17g" (numtext_test checks millions of
 * values against snprintf).  Without a 128-bit integer type every value takes the snprintf
 * path.  (0.8.6 to 0.8.8 scaled in x87 extended precision, 1e-38..1e70 only: 45.7 ns a number
 * of a blade's result in a loop on the development machine, 36.8 ns now; DESIGN.md 2.1.)
 */
#include "codec_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#if defined(__SIZEOF_INT128__)
#include "numtext_pow10.h"

__extension__ typedef unsigned __int128 numtext_u128; /* GCC, Clang: -Wpedantic accepts it so */

/* "00" to "99": two digits a step (numtext_digits). */
static const char numtext_pairs[201] = "00010203040506070809101112131415161718192021222324"
                                       "25262728293031323334353637383940414243444546474849"
                                       "50515253545556575859606162636465666768697071727374"
                                       "75767778798081828384858687888990919293949596979899";

/* N = m 2^q 10^p with the table's c 2^b for 10^p (numtext_pow10.h): the product P = m c is
 * exact in 192 bits and N = P / 2^s, s = -(q + b).  *N receives floor(P / 2^s), *R the bits of P
 * below (the fraction, out of 2^s), *s s.  0 when p is outside the table or s - 64 is outside
 * 54..63 (then floor(N) would not fit 64 bits, or the fraction 127: N is far from 10^16..10^17,
 * not the scale wanted). */
static int numtext_scale(uint64_t m, int q, int p, uint64_t *N, numtext_u128 *R, int *s)
{
    if (p < NUMTEXT_P_MIN || p > NUMTEXT_P_MAX)
        return 0;
    const struct numtext_pow10 *t = &numtext_pow10[p - NUMTEXT_P_MIN];
    numtext_u128 lo = (numtext_u128)m * t->lo;
    numtext_u128 top = (numtext_u128)m * t->hi + (uint64_t)(lo >> 64); /* P >> 64, < 2^117 */
    int r = -(q + t->b) - 64; /* the bits of top below N's integer part */
    if (r < 54 || r > 63)
        return 0;
    *N = (uint64_t)(top >> r);
    *R = ((top & (((numtext_u128)1 << r) - 1)) << 64) | (uint64_t)lo;
    *s = r + 64;
    return 1;
}

/* The 17 significant digits of x > 0 (normal) into dig and its decimal exponent into *X
 * (x ~ d.dddd 10^X after rounding); 0 when the rounding is not sure (the caller asks glibc).
 * x = m 2^q exactly; N = x 10^p, 10^16 <= N < 10^17, p = 16 - X, from the table's 128 bits of
 * 10^p: c 2^b <= 10^p < (c + 1) 2^b, so the exact N lies in [P, P + m) / 2^s.  N rounds down
 * when the fraction's bits R satisfy R + m <= 2^(s-1), up when R > 2^(s-1); in between (a tie or
 * within m 2^-s < 2^-69 of one: ~0.07 % of random bit patterns, all of them binary fractions
 * whose decimals end in 5) snprintf decides.  The first guess of X comes from the binary
 * exponent; one more power of ten settles it. */
static int numtext_digits(double x, char dig[17], int *X)
{
    uint64_t bits, N;
    numtext_u128 R;
    int s;
    memcpy(&bits, &x, sizeof bits);
    int E = (int)((bits >> 52) & 0x7ff), q = E - 1075;
    uint64_t m = (bits & ((1ULL << 52) - 1)) | (1ULL << 52);
    /* floor((e2 - 1) log10 2), e2 = E - 1022 frexp's exponent (2^(e2-1) <= x < 2^e2):
     * ((e2 - 1) 78913) >> 18 for every double's exponent (checked for |e2| <= 1100); X is
     * this or one more */
    int X0 = (int)(((int64_t)(E - 1023) * 78913) >> 18);
    if (!numtext_scale(m, q, 16 - X0, &N, &R, &s))
        return 0;
    if (N >= 100000000000000000ULL && !numtext_scale(m, q, 16 - ++X0, &N, &R, &s))
        return 0;
    if (N < 10000000000000000ULL || N >= 100000000000000000ULL)
        return 0; /* within 2^-69 below a power of ten: snprintf */
    numtext_u128 half = (numtext_u128)1 << (s - 1);
    if (R <= half && R + m > half)
        return 0; /* too close to a tie to round here */
    uint64_t D = N + (R > half);
    if (D == 100000000000000000ULL) { /* 9.99...95 and up: 1.0000000000000000 10^(X+1) */
        D = 10000000000000000ULL;
        X0++;
    }
    *X = X0;
    /* 1 + 16 digits: D = h 10^16 + a 10^8 + b, each 8-digit part as 4 + 4 and each 4 as 2 + 2
     * (independent divisions by constants, not one chain), two digits a store */
    uint64_t r16 = D % 10000000000000000ULL;
    uint32_t h = (uint32_t)(D / 10000000000000000ULL), a = (uint32_t)(r16 / 100000000u),
             b = (uint32_t)(r16 % 100000000u);
    uint32_t q4[4] = {a / 10000u, a % 10000u, b / 10000u, b % 10000u};
    for (int k = 0; k < 4; k++) {
        memcpy(dig + 1 + 4 * k, numtext_pairs + 2 * (q4[k] / 100u), 2);
        memcpy(dig + 3 + 4 * k, numtext_pairs + 2 * (q4[k] % 100u), 2);
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
#if defined(__SIZEOF_INT128__)
    char dig[17];
    int X;
    if (isnormal(x) && numtext_digits(fabs(x), dig, &X))
        return numtext_layout(buf, x < 0, dig, X, json);
#endif
    return numtext_printf(buf, x, json);
}

int codec_numtext_direct(double x)
{
#if defined(__SIZEOF_INT128__)
    char dig[17];
    int X;
    return x == 0 || (isnormal(x) && numtext_digits(fabs(x), dig, &X));
#else
    return x == 0;
#endif
}
