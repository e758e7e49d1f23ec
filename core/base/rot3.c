/*
 * rot3.c — 3x3 rotations (rot3.h), real and complex: the exponential
 * map Lambda(psi) = exp(skew psi) of DESIGN.md 7.2 and its left tangent T
 * (d Lambda = skew(T d psi) Lambda), written so that every function is
 * analytic in psi (powers of psi.psi, no conjugates, series near zero), so
 * that complex steps go through them (the tests' reference for the closed-form
 * Jacobian of hessian3.c); and the derivative of T along a direction, real
 * (rot3_dtangent), for that Jacobian.
 */
#include "rot3.h"

#include <math.h>
#include <string.h>

/* Series switch: below it sin(t)/t, (1 - cos t)/t^2 and (t - sin t)/t^3 come from their Taylor
 * series in t2 = t^2 (terms through t^10: truncation below 1e-22 relative). */
#define ROT3_SERIES 1e-2

/* c1 = sin t / t, c2 = (1 - cos t)/t^2, c3 = (t - sin t)/t^3 as functions of t2 = t^2: one body for
 * the complex t2 of complex steps (rot3_coeffs) and the real one of real states (rot3_coeffs_real,
 * the same operations on the real parts: a complex step's imaginary parts are zeros there, which
 * add nothing to a real part that is not zero). */
#define ROT3_COEFFS(NAME, T, ABS, SQRT, SIN, COS)                                 \
    static void NAME(T t2, T *c1, T *c2, T *c3)                                   \
    {                                                                             \
        if (ABS(t2) < ROT3_SERIES) {                                              \
            /* alternating series: sum (-t2)^k / (2k+1)!, / (2k+2)!, / (2k+3)! */ \
            T p = 1, a = 0, b = 0, c = 0;                                         \
            double f1 = 1, f2 = 2, f3 = 6; /* (2k+1)!, (2k+2)!, (2k+3)! */        \
            for (int k = 0; k < 6; k++) {                                         \
                a += p / f1;                                                      \
                b += p / f2;                                                      \
                c += p / f3;                                                      \
                p *= -t2;                                                         \
                f1 *= (2 * k + 2) * (2 * k + 3);                                  \
                f2 *= (2 * k + 3) * (2 * k + 4);                                  \
                f3 *= (2 * k + 4) * (2 * k + 5);                                  \
            }                                                                     \
            *c1 = a;                                                              \
            *c2 = b;                                                              \
            *c3 = c;                                                              \
            return;                                                               \
        }                                                                         \
        T t = SQRT(t2), s = SIN(t), co = COS(t);                                  \
        *c1 = s / t;                                                              \
        *c2 = (1 - co) / t2;                                                      \
        *c3 = (t - s) / (t2 * t);                                                 \
    }
ROT3_COEFFS(rot3_coeffs, sp_cx, cabs, csqrt, csin, ccos)
ROT3_COEFFS(rot3_coeffs_real, double, fabs, sqrt, sin, cos)

/* K = skew(p) and K2 = skew(p)^2 (column-major). */
static void rot3_skew2(const sp_cx p[3], sp_cx K[9], sp_cx K2[9])
{
    K[0] = 0, K[1] = p[2], K[2] = -p[1];
    K[3] = -p[2], K[4] = 0, K[5] = p[0];
    K[6] = p[1], K[7] = -p[0], K[8] = 0;
    /* skew(p)^2 = p p' - (p.p) I */
    sp_cx pp = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            K2[i + 3 * j] = p[i] * p[j] - (i == j ? pp : 0);
}

/* rot3_exp at a real psi (every evaluation outside the complex-step tests): the complex code's
 * operations on the real parts only, a quarter of its work (issue 27: rot3_exp was 4.7 % of a
 * spatial sweep).  The imaginary parts are +0. */
static void rot3_exp_real(const sp_cx psi[3], sp_cx L[9], sp_cx T[9])
{
    double p[3] = {creal(psi[0]), creal(psi[1]), creal(psi[2])}, c1, c2, c3;
    double t2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    rot3_coeffs_real(t2, &c1, &c2, &c3);
    double K[9] = {0, p[2], -p[1], -p[2], 0, p[0], p[1], -p[0], 0}, K2[9];
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            K2[i + 3 * j] = p[i] * p[j] - (i == j ? t2 : 0);
    for (int i = 0; i < 9; i++) {
        double id = i % 4 == 0 ? 1 : 0;
        L[i] = rot3_cx(id + c1 * K[i] + c2 * K2[i], 0);
        if (T)
            T[i] = rot3_cx(id + c2 * K[i] + c3 * K2[i], 0);
    }
}

void rot3_exp(const sp_cx psi[3], sp_cx L[9], sp_cx T[9])
{
    if (cimag(psi[0]) == 0 && cimag(psi[1]) == 0 && cimag(psi[2]) == 0) {
        rot3_exp_real(psi, L, T);
        return;
    }
    sp_cx K[9], K2[9], c1, c2, c3;
    sp_cx t2 = psi[0] * psi[0] + psi[1] * psi[1] + psi[2] * psi[2];
    rot3_coeffs(t2, &c1, &c2, &c3);
    rot3_skew2(psi, K, K2);
    for (int i = 0; i < 9; i++) {
        sp_cx id = i % 4 == 0 ? 1 : 0;
        /* Rodrigues: Lambda = I + sin t/t K + (1 - cos t)/t^2 K^2 */
        L[i] = id + c1 * K[i] + c2 * K2[i];
        /* left tangent: T = I + (1 - cos t)/t^2 K + (t - sin t)/t^3 K^2 */
        if (T)
            T[i] = id + c2 * K[i] + c3 * K2[i];
    }
}

/* Real c2, c3 of rot3_coeffs and their derivatives d/dt2 (the same series switch). */
static void rot3_coeffs_d(double t2, double *c2, double *c3, double *d2, double *d3)
{
    if (fabs(t2) < ROT3_SERIES) {
        /* c2 = sum x^k / (2k+2)!, c3 = sum x^k / (2k+3)!, x = -t2; d/dt2 = -sum k x^(k-1) / ... */
        double p = 1, a = 0, b = 0, da = 0, db = 0, f2 = 2, f3 = 6;
        for (int k = 0; k < 6; k++) {
            a += p / f2;
            b += p / f3;
            if (k < 5) { /* the next term's derivative: -(k+1) x^k / (2k+4)!, / (2k+5)! */
                double g2 = f2 * (2 * k + 3) * (2 * k + 4), g3 = f3 * (2 * k + 4) * (2 * k + 5);
                da -= (k + 1) * p / g2;
                db -= (k + 1) * p / g3;
            }
            p *= -t2;
            f2 *= (2 * k + 3) * (2 * k + 4);
            f3 *= (2 * k + 4) * (2 * k + 5);
        }
        *c2 = a, *c3 = b, *d2 = da, *d3 = db;
        return;
    }
    double t = sqrt(t2), sn = sin(t), co = cos(t);
    *c2 = (1 - co) / t2;
    *c3 = (t - sn) / (t2 * t);
    *d2 = (0.5 * t * sn - (1 - co)) / (t2 * t2);
    *d3 = ((1 - co) * t - 3 * (t - sn)) / (2 * t2 * t2 * t);
}

void rot3_dtangent(const double psi[3], const double d[3], double dT[9])
{
    double t2 = psi[0] * psi[0] + psi[1] * psi[1] + psi[2] * psi[2], c2, c3, d2, d3;
    rot3_coeffs_d(t2, &c2, &c3, &d2, &d3);
    double dt2 = 2 * (psi[0] * d[0] + psi[1] * d[1] + psi[2] * d[2]), pd = 0.5 * dt2;
    /* T = I + c2 K + c3 K^2, K = skew(psi), K^2 = psi psi' - t2 I; along d (D = skew(d)):
     * dT = c2' dt2 K + c2 D + c3' dt2 K^2 + c3 (D K + K D), D K + K D = psi d' + d psi' - 2 (psi.d) I */
    double K[9] = {0, psi[2], -psi[1], -psi[2], 0, psi[0], psi[1], -psi[0], 0};
    double D[9] = {0, d[2], -d[1], -d[2], 0, d[0], d[1], -d[0], 0};
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++) {
            double id = i == j ? 1.0 : 0.0;
            double K2 = psi[i] * psi[j] - t2 * id, DK = psi[i] * d[j] + d[i] * psi[j] - 2 * pd * id;
            dT[i + 3 * j] = d2 * dt2 * K[i + 3 * j] + c2 * D[i + 3 * j] + d3 * dt2 * K2 + c3 * DK;
        }
}

void rot3_log(const double R[9], double v[3])
{
    /* skew part: (R - R')/2 = sin t/t skew(v); cos t = (tr R - 1)/2 */
    double w[3] = {0.5 * (R[5] - R[7]), 0.5 * (R[6] - R[2]), 0.5 * (R[1] - R[3])};
    double s = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    double c = 0.5 * (R[0] + R[4] + R[8] - 1.0);
    double t = atan2(s, c);
    if (c > -0.9) {
        double f = s > 1e-300 ? t / s : 1.0;
        for (int i = 0; i < 3; i++)
            v[i] = f * w[i];
        return;
    }
    /* near pi: the axis from the symmetric part, (R + R')/2 = cos t I + (1 - cos t) a a' */
    int k = R[0] >= R[4] && R[0] >= R[8] ? 0 : R[4] >= R[8] ? 1 : 2;
    double a[3];
    for (int i = 0; i < 3; i++)
        a[i] = 0.5 * (R[i + 3 * k] + R[k + 3 * i]) - (i == k ? c : 0);
    double na = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (!(na > 0)) {
        memset(v, 0, 3 * sizeof(double));
        return;
    }
    double sg = a[0] * w[0] + a[1] * w[1] + a[2] * w[2] < 0 ? -1.0 : 1.0;
    for (int i = 0; i < 3; i++)
        v[i] = sg * t * a[i] / na;
}
