/*
 * element.c — element physics shared by the structure kinds (element.h).
 *
 * How it fits: the kinds' mode-label energies (kind_planar.c, kind_spatial.c, through
 * labels.c) take an element's strain energy from here, so the Hermite stiffness is written
 * once; the beam element's local stiffness, Hermite shape functions and geometric bending
 * block (used by the planar element matrices, planar/fe.c, and by the spatial ones,
 * spatial/fe3.c) live here too (declared in internal.h as fe_*).
 */
#include "element.h"
#include "internal.h"

#include <string.h>

double smi_dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

double smi_elem_bending_energy(double EI, double l, double v1, double s1, double v2, double s2)
{
    double a = v1 - v2;
    return EI / (l * l * l) *
           (12 * a * a + 12 * l * a * (s1 + s2) +
            l * l * (4 * s1 * s1 + 4 * s2 * s2 + 4 * s1 * s2));
}

double smi_elem_bar_energy(double k, double l, double a1, double a2)
{
    double d = a2 - a1;
    return k / l * d * d;
}

/** Element stiffness in element coordinates: EA/l axial, 12EI/l^3... bending. */
void fe_stiffness_local(double EA, double EI, double l, double k[36])
{
    double a = EA / l, b = 12.0 * EI / (l * l * l), c = 6.0 * EI / (l * l);
    double d = 4.0 * EI / l, e = 2.0 * EI / l;
    double v[36] = {
        a,  0, 0, -a, 0, 0, 0, b,  c,  0, -b, c,  0, c, d, 0, -c, e,
        -a, 0, 0, a,  0, 0, 0, -b, -c, 0, b,  -c, 0, c, e, 0, -c, d,
    };
    memcpy(k, v, sizeof v);
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
        6.0 / 5.0, l / 10.0,      -6.0 / 5.0, l / 10.0,           l / 10.0,  2.0 * l * l / 15.0,
        -l / 10.0, -l * l / 30.0, -6.0 / 5.0, -l / 10.0,          6.0 / 5.0, -l / 10.0,
        l / 10.0,  -l * l / 30.0, -l / 10.0,  2.0 * l * l / 15.0,
    };
    for (int i = 0; i < 16; i++)
        g[i] = v[i] / l;
}
