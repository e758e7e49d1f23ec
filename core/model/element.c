/*
 * element.c — element physics shared by the structure kinds (element.h).
 *
 * How it fits: the kinds' mode-label energies (kind_planar.c, kind_spatial.c, through
 * labels.c) take an element's strain energy from here, so the Hermite stiffness is written
 * once.
 */
#include "element.h"

double smi_dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

double smi_elem_bending_energy(double EI, double l, double v1, double s1, double v2, double s2)
{
    double a = v1 - v2;
    return EI / (l * l * l) * (12 * a * a + 12 * l * a * (s1 + s2) +
                               l * l * (4 * s1 * s1 + 4 * s2 * s2 + 4 * s1 * s2));
}

double smi_elem_bar_energy(double k, double l, double a1, double a2)
{
    double d = a2 - a1;
    return k / l * d * d;
}
