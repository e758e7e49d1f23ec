/*
 * fe.c — planar Euler-Bernoulli frame element matrices (2 nodes, DOF order
 * u1 v1 phi1 u2 v2 phi2 in element coordinates), the shape functions of
 * Kim & Yoo (2006) eq. 16 and the geometric stiffness integrand of eq. 23.
 * All 6x6 arrays are column-major: a[i + 6*j].
 */
#include "internal.h"

#include <math.h>
#include <string.h>

/** Element stiffness in element coordinates: EA/l axial, 12EI/l^3... bending. */
void fe_stiffness_local(double EA, double EI, double l, double k[36])
{
    double a = EA / l, b = 12.0 * EI / (l * l * l), c = 6.0 * EI / (l * l);
    double d = 4.0 * EI / l, e = 2.0 * EI / l;
    double v[36] = {
        a, 0, 0, -a, 0, 0,
        0, b, c, 0, -b, c,
        0, c, d, 0, -c, e,
        -a, 0, 0, a, 0, 0,
        0, -b, -c, 0, b, -c,
        0, c, e, 0, -c, d,
    };
    memcpy(k, v, sizeof v);
}

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

/** Shape functions S(xi) of eq. 16, 2x6 column-major (s[r + 2*j]). */
void fe_shape(double xi, double l, double s[12])
{
    double x2 = xi * xi, x3 = x2 * xi;
    memset(s, 0, 12 * sizeof(double));
    s[0 + 2 * 0] = 1.0 - xi;
    s[0 + 2 * 3] = xi;
    s[1 + 2 * 1] = 1.0 - 3.0 * x2 + 2.0 * x3;
    s[1 + 2 * 2] = l * (xi - 2.0 * x2 + x3);
    s[1 + 2 * 4] = 3.0 * x2 - 2.0 * x3;
    s[1 + 2 * 5] = l * (x3 - x2);
}

/**
 * Bending block of G_e (eq. 23) on (v1, phi1, v2, phi2), 4x4 column-major.
 * The axial row and column of eq. 23 are zero (the printed l/15 is a typo).
 */
void fe_geometric_bending(double l, double g[16])
{
    double v[16] = {
        6.0 / 5.0, l / 10.0, -6.0 / 5.0, l / 10.0,
        l / 10.0, 2.0 * l * l / 15.0, -l / 10.0, -l * l / 30.0,
        -6.0 / 5.0, -l / 10.0, 6.0 / 5.0, -l / 10.0,
        l / 10.0, -l * l / 30.0, -l / 10.0, 2.0 * l * l / 15.0,
    };
    for (int i = 0; i < 16; i++)
        g[i] = v[i] / l;
}
