/*
 * fe.c — planar Euler-Bernoulli frame element matrices (2 nodes, DOF order
 * u1 v1 phi1 u2 v2 phi2 in element coordinates), the shape functions of
 * Kim & Yoo (2006) eq. 16 and the geometric stiffness integrand of eq. 23.
 * All 6x6 arrays are column-major: a[i + 6*j].
 */
#include "internal.h"

#include <math.h>
#include <string.h>

/** Standard consistent mass (linear axial, Hermite cubic transverse), mu*l/420 [...]. */
void fe_mass_consistent_local(double mu, double l, double m[36])
{
    double f = mu * l / 420.0;
    double v[36] = {
        140, 0, 0, 70, 0, 0,
        0, 156, 22 * l, 0, 54, -13 * l,
        0, 22 * l, 4 * l * l, 0, 13 * l, -3 * l * l,
        70, 0, 0, 140, 0, 0,
        0, 54, 13 * l, 0, 156, -22 * l,
        0, -13 * l, -3 * l * l, 0, -22 * l, 4 * l * l,
    };
    for (int i = 0; i < 36; i++)
        m[i] = f * v[i];
}

/** C(alpha) of eq. 19: element DOFs = C * frame DOFs. */
void fe_rotation(double alpha, double c[36])
{
    double co = cos(alpha), si = sin(alpha);
    memset(c, 0, 36 * sizeof(double));
    for (int b = 0; b < 2; b++) {
        int o = 3 * b;
        c[(o + 0) + 6 * (o + 0)] = co;
        c[(o + 0) + 6 * (o + 1)] = si;
        c[(o + 1) + 6 * (o + 0)] = -si;
        c[(o + 1) + 6 * (o + 1)] = co;
        c[(o + 2) + 6 * (o + 2)] = 1.0;
    }
}

/** kfr = C' kloc C: an element matrix rotated into frame coordinates. */
void fe_to_frame(const double kloc[36], double alpha, double kfr[36])
{
    double c[36], t[36];
    fe_rotation(alpha, c);
    /* t = kloc C */
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++) {
            double s = 0;
            for (int p = 0; p < 6; p++)
                s += kloc[i + 6 * p] * c[p + 6 * j];
            t[i + 6 * j] = s;
        }
    /* kfr = C' t */
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++) {
            double s = 0;
            for (int p = 0; p < 6; p++)
                s += c[p + 6 * i] * t[p + 6 * j];
            kfr[i + 6 * j] = s;
        }
}

