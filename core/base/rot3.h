/*
 * rot3.h — 3x3 rotations, real and complex (not installed; base layer: no model).  The complex
 * ones are analytic in their arguments, so complex steps go through them (the tests take them as
 * the reference for the spatial kind's closed-form Jacobian, DESIGN.md 7.2-7.3).  3x3 matrices
 * column-major (a[i + 3 j]).
 */
#ifndef SM_ROT3_H
#define SM_ROT3_H

#include <complex.h>
/* complex.h's I would clash with the field I of sm_section and sp_point: the imaginary unit is
 * written _Complex_I in the spatial files. */
#undef I

typedef double complex sp_cx;

/* re + i im, exactly (both parts as given, a zero's sign included): C11's CMPLX, which glibc's
 * complex.h leaves undefined under clang. */
static inline sp_cx rot3_cx(double re, double im)
{
    union {
        sp_cx z;
        double d[2]; /* C11 6.2.5: a complex has the representation of double[2] */
    } u;
    u.d[0] = re;
    u.d[1] = im;
    return u.z;
}

/* ------------------------------------------------------------- rot3.c */
/** L = Lambda(psi) = exp(skew psi) and T = its left tangent (d Lambda = skew(T d psi) Lambda);
 *  T may be NULL.  Analytic in psi (series near zero), so complex steps go through. */
void rot3_exp(const sp_cx psi[3], sp_cx L[9], sp_cx T[9]);
/** dT (real) = the derivative of the left tangent T(psi) along d (real psi). */
void rot3_dtangent(const double psi[3], const double d[3], double dT[9]);
/** Rotation vector (rad) of the real rotation matrix R (log map), |v| <= pi. */
void rot3_log(const double R[9], double v[3]);

/* The small products are defined here so that every caller inlines them (they run millions of
 * times in a spatial solve: 9 % of a 12-element blade's instructions were their calls; issue 27).
 * Same arithmetic, same bits. */

/** c = a b (3x3). */
static inline void rot3_mul(const sp_cx a[9], const sp_cx b[9], sp_cx c[9])
{
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            c[i + 3 * j] = a[i] * b[3 * j] + a[i + 3] * b[3 * j + 1] + a[i + 6] * b[3 * j + 2];
}

/** c = a' b (3x3). */
static inline void rot3_tmul(const sp_cx a[9], const sp_cx b[9], sp_cx c[9])
{
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            c[i + 3 * j] =
                a[3 * i] * b[3 * j] + a[3 * i + 1] * b[3 * j + 1] + a[3 * i + 2] * b[3 * j + 2];
}

/** y = a x (3x3 times 3). */
static inline void rot3_mv(const sp_cx a[9], const sp_cx x[3], sp_cx y[3])
{
    for (int i = 0; i < 3; i++)
        y[i] = a[i] * x[0] + a[i + 3] * x[1] + a[i + 6] * x[2];
}

/** y = a' x. */
static inline void rot3_tmv(const sp_cx a[9], const sp_cx x[3], sp_cx y[3])
{
    for (int i = 0; i < 3; i++)
        y[i] = a[3 * i] * x[0] + a[3 * i + 1] * x[1] + a[3 * i + 2] * x[2];
}

/** c = a x b. */
static inline void rot3_cross(const sp_cx a[3], const sp_cx b[3], sp_cx c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/** Real 3x3: c = a b. */
static inline void rot3_mul_r(const double a[9], const double b[9], double c[9])
{
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            c[i + 3 * j] = a[i] * b[3 * j] + a[i + 3] * b[3 * j + 1] + a[i + 6] * b[3 * j + 2];
}

/** Real 3x3: c = a' b. */
static inline void rot3_tmul_r(const double a[9], const double b[9], double c[9])
{
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            c[i + 3 * j] =
                a[3 * i] * b[3 * j] + a[3 * i + 1] * b[3 * j + 1] + a[3 * i + 2] * b[3 * j + 2];
}

/** Real: y = a x, y = a' x (3x3 times 3), c = a x b. */
static inline void rot3_mv_r(const double a[9], const double x[3], double y[3])
{
    for (int i = 0; i < 3; i++)
        y[i] = a[i] * x[0] + a[i + 3] * x[1] + a[i + 6] * x[2];
}

static inline void rot3_tmv_r(const double a[9], const double x[3], double y[3])
{
    for (int i = 0; i < 3; i++)
        y[i] = a[3 * i] * x[0] + a[3 * i + 1] * x[1] + a[3 * i + 2] * x[2];
}

static inline void rot3_cross_r(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

#endif
