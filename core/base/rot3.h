/*
 * rot3.h — 3x3 rotations, real and complex (not installed; base layer: no model).  The complex
 * ones are analytic in their arguments, so the spatial kind differentiates its kinematics by
 * complex steps through them (DESIGN.md 7.2).  3x3 matrices column-major (a[i + 3 j]).
 */
#ifndef SM_ROT3_H
#define SM_ROT3_H

#include <complex.h>
/* complex.h's I would clash with the field I of sm_section and sp_point: the imaginary unit is
 * written _Complex_I in the spatial files. */
#undef I

typedef double complex sp_cx;

/* ------------------------------------------------------------- rot3.c */
/** L = Lambda(psi) = exp(skew psi) and T = its left tangent (d Lambda = skew(T d psi) Lambda);
 *  T may be NULL.  Analytic in psi (series near zero), so complex steps go through. */
void rot3_exp(const sp_cx psi[3], sp_cx L[9], sp_cx T[9]);
/** c = a b (3x3). */
void rot3_mul(const sp_cx a[9], const sp_cx b[9], sp_cx c[9]);
/** c = a' b (3x3). */
void rot3_tmul(const sp_cx a[9], const sp_cx b[9], sp_cx c[9]);
/** y = a x (3x3 times 3). */
void rot3_mv(const sp_cx a[9], const sp_cx x[3], sp_cx y[3]);
/** y = a' x. */
void rot3_tmv(const sp_cx a[9], const sp_cx x[3], sp_cx y[3]);
/** c = a x b. */
void rot3_cross(const sp_cx a[3], const sp_cx b[3], sp_cx c[3]);
/** Rotation vector (rad) of the real rotation matrix R (log map), |v| <= pi. */
void rot3_log(const double R[9], double v[3]);
/** Real 3x3 helpers: c = a b, c = a' b. */
void rot3_mul_r(const double a[9], const double b[9], double c[9]);
void rot3_tmul_r(const double a[9], const double b[9], double c[9]);

#endif
