/*
 * test_fe.c — element matrices: rigid-body modes are in the null space of the
 * stiffness, the consistent mass and the geometric integrand of eq. 23 equal
 * Gauss quadratures of the shape functions of eq. 16, and rotation to frame
 * coordinates preserves symmetry.
 */
#include "internal.h"
#include "testutil.h"

int main(void)
{
    double l = 0.37, EA = 2.8e7, EI = 1.4e4, mu = 1.2, k[36], mm[36], g[16];
    fe_stiffness_local(EA, EI, l, k);
    /* rigid translation in u, in v, and rigid rotation (v = x phi) give no force */
    double rig[3][6] = {{1, 0, 0, 1, 0, 0}, {0, 1, 0, 0, 1, 0}, {0, 0, 1, 0, l, 1}};
    for (int r = 0; r < 3; r++) {
        double mx = 0;
        for (int i = 0; i < 6; i++) {
            double f = 0;
            for (int j = 0; j < 6; j++)
                f += k[i + 6 * j] * rig[r][j];
            mx = fmax(mx, fabs(f));
        }
        TU_CHECK(mx < 1e-6 * EA, "rigid mode %d loads the element: %g", r, mx);
    }
    /* consistent mass = int mu S'S dx (4-point Gauss is exact for degree 6) */
    static const double gx[4] = {-0.86113631159405258, -0.33998104358485626, 0.33998104358485626,
                                 0.86113631159405258};
    static const double gw[4] = {0.34785484513745386, 0.65214515486254614, 0.65214515486254614,
                                 0.34785484513745386};
    double mq[36] = {0}, gqd[36] = {0};
    for (int p = 0; p < 4; p++) {
        double xi = 0.5 * (1 + gx[p]), S[12], Sp[12], h = 1e-6;
        fe_shape(xi, l, S);
        /* dS2/dx by central differences of the cubic (exact up to round-off) */
        double Sa[12], Sb[12];
        fe_shape(xi + h, l, Sa);
        fe_shape(xi - h, l, Sb);
        for (int i = 0; i < 12; i++)
            Sp[i] = (Sa[i] - Sb[i]) / (2 * h * l);
        for (int i = 0; i < 6; i++)
            for (int j = 0; j < 6; j++) {
                mq[i + 6 * j] += 0.5 * gw[p] * l * mu * (S[2 * i] * S[2 * j] + S[2 * i + 1] * S[2 * j + 1]);
                gqd[i + 6 * j] += 0.5 * gw[p] * l * Sp[2 * i + 1] * Sp[2 * j + 1];
            }
    }
    fe_mass_consistent_local(mu, l, mm);
    double em = 0, eg = 0;
    for (int i = 0; i < 36; i++)
        em = fmax(em, fabs(mm[i] - mq[i]));
    TU_CHECK(em < 1e-12, "consistent mass differs from quadrature by %g", em);
    fe_geometric_bending(l, g);
    static const int idx[4] = {1, 2, 4, 5};
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            eg = fmax(eg, fabs(g[i + 4 * j] - gqd[idx[i] + 6 * idx[j]]));
    TU_CHECK(eg < 1e-6, "eq. 23 bending block differs from int S2'S2' by %g", eg);
    /* the axial row of int S2'S2' is zero (the printed l/15 is a typo) */
    double ax = 0;
    for (int j = 0; j < 6; j++)
        ax = fmax(ax, fabs(gqd[3 + 6 * j]) + fabs(gqd[0 + 6 * j]));
    TU_CHECK(ax < 1e-12, "axial row of G is not zero: %g", ax);
    /* frame rotation keeps symmetry and the trace of the translational block */
    double kf[36];
    fe_to_frame(k, 0.7, kf);
    double asym = 0;
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++)
            asym = fmax(asym, fabs(kf[i + 6 * j] - kf[j + 6 * i]));
    TU_CHECK(asym < 1e-6, "rotated stiffness not symmetric: %g", asym);
    TU_NEAR(kf[0] + kf[7], k[0] + k[7], 1e-6 * EA, "trace of the node-1 translation block");
    return tu_finish("fe");
}
