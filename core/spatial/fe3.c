/*
 * fe3.c — space-frame Euler-Bernoulli element matrices (DESIGN.md 7.1, 7.3)
 * in the element's principal axes (e1 along the element, p2 edgewise, p3
 * flapwise), DOF order u1 v1 w1 tx1 ty1 tz1 u2 v2 w2 tx2 ty2 tz2, 12x12
 * column-major.  The two bending planes are the planar element of fe.c: in
 * the p2 direction on (v, tz) exactly, in the p3 direction on (w, -ty)
 * (w' = -ty), so a planar member reproduces the planar matrices entry for
 * entry.
 */
#include "spatial.h"

#include <string.h>

/* The 3D DOF of each bending plane and their planar DOF (u1 v1 phi1 u2 v2 phi2): the p2 plane
 * (edge: v, tz) and the p3 plane (flap: w, ty, with the sign of the rotation, w' = -ty). */
static const int fe3_edge[4] = {1, 5, 7, 11};
static const int fe3_flap[4] = {2, 4, 8, 10};
static const int fe3_plane[4] = {1, 2, 4, 5};
static const double fe3_flap_sign[4] = {1, -1, 1, -1};

/* a (12x12) += the bending part of the planar 6x6 p (rows/cols v, phi) in both planes: the 16
 * entries of each plane only (the two planes share no DOF; issue 27: the loop over all 144
 * entries with table lookups was 2 % of a 12-element blade's instructions). */
static void fe3_add_planes(const double pe[36], const double pf[36], double a[144])
{
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            int pij = fe3_plane[i] + 6 * fe3_plane[j];
            a[fe3_edge[i] + 12 * fe3_edge[j]] += pe[pij];
            a[fe3_flap[i] + 12 * fe3_flap[j]] += fe3_flap_sign[i] * fe3_flap_sign[j] * pf[pij];
        }
}

/* a (12x12) += c [1 -1; -1 1] on the DOF pair (i, i + 6). */
static void fe3_add_bar(double c, int i, double a[144])
{
    a[i + 12 * i] += c;
    a[(i + 6) + 12 * (i + 6)] += c;
    a[i + 12 * (i + 6)] -= c;
    a[(i + 6) + 12 * i] -= c;
}

/*
 * k = T' k T for the rigid link from the member axis to an axis at the offset (0, d2, d3)
 * (principal axes): at each end the displacement there is u + theta x d, so
 *   u_x' = u_x + d3 ty - d2 tz,  u_y' = u_y - d3 tx,  u_z' = u_z + d2 tx,  rotations unchanged.
 */
static void fe3_offset(double k[144], double d2, double d3)
{
    if (d2 == 0.0 && d3 == 0.0)
        return;
    double T[144] = {0}, t[144];
    for (int i = 0; i < 12; i++)
        T[i + 12 * i] = 1.0;
    for (int h = 0; h < 12; h += 6) {
        T[(h + 0) + 12 * (h + 4)] = d3;
        T[(h + 0) + 12 * (h + 5)] = -d2;
        T[(h + 1) + 12 * (h + 3)] = -d3;
        T[(h + 2) + 12 * (h + 3)] = d2;
    }
    for (int j = 0; j < 12; j++) /* t = k T */
        for (int i = 0; i < 12; i++) {
            double v = 0;
            for (int r = 0; r < 12; r++)
                v += k[i + 12 * r] * T[r + 12 * j];
            t[i + 12 * j] = v;
        }
    for (int j = 0; j < 12; j++) /* k = T' t */
        for (int i = 0; i < 12; i++) {
            double v = 0;
            for (int r = 0; r < 12; r++)
                v += T[r + 12 * i] * t[r + 12 * j];
            k[i + 12 * j] = v;
        }
}

void fe3_stiffness(const sm_elem *e, double k[144])
{
    double pe[36], pf[36], ka[144] = {0};
    memset(k, 0, 144 * sizeof(double));
    fe_stiffness_local(0.0, e->EI_edge, e->l, pe);
    fe_stiffness_local(0.0, e->EI_flap, e->l, pf);
    fe3_add_planes(pe, pf, k);
    fe3_add_bar(e->GJ / e->l, 3, k); /* torsion: GJ/l */
    fe3_offset(k, e->sc[0], e->sc[1]); /* bending and torsion about the shear centre (DESIGN.md 8) */
    fe3_add_bar(e->EA / e->l, 0, ka); /* axial: EA/l at the tension centre */
    fe3_offset(ka, e->tc[0], e->tc[1]);
    for (int i = 0; i < 144; i++)
        k[i] += ka[i];
}

void fe3_geometric(const sm_elem *e, double g[144])
{
    double b[16], p[36];
    memset(g, 0, 144 * sizeof(double));
    memset(p, 0, sizeof p);
    fe_geometric_bending(e->l, b); /* eq. 23 on (v1, phi1, v2, phi2) */
    static const int at[4] = {1, 2, 4, 5};
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++)
            p[at[i] + 6 * at[j]] = b[i + 4 * j];
    fe3_add_planes(p, p, g);
    fe3_add_bar(e->ip_over_a / e->l, 3, g); /* Wagner: (I_p/A) int tx'^2 */
}
