/*
 * labels.c — what kind of mode is this?  The energy split and label of every mode
 * (DESIGN.md 9, 9.1).
 *
 * How it fits: sm_solve calls lab_case on every case with modes while the nodal
 * shapes (hub frame, sweep.c) still exist, before it drops them when the request
 * asked for no shapes.  For each element, in the principal axes of its member at
 * rest (t along the element from n1 to n2, p2 edgewise, p3 = t x p2 flapwise;
 * planar: p2 in-plane normal, p3 = z), the shape's nodal translations and rotations
 * are split into
 *   axial   u = t.d                          strain  EA/l (u2 - u1)^2
 *   edge    v = p2.d, v' = p3.r              strain  Hermite EI_edge on (v1, v1', v2, v2')
 *   flap    w = p3.d, w' = -p2.r             strain  Hermite EI_flap on (w1, w1', w2, w2')
 *   torsion tx = t.r                         strain  GJ/l (tx2 - tx1)^2
 * (planar: EA, and EI for the in-plane bending in the edge slot).  Kinetic parts:
 * half the element's mass mu l at each end (and each node's point mass, in the axes
 * of the element that ends there) times the squared component, plus the rotary
 * inertia halves (i_flap + i_edge on tx, i_flap on p2.r, i_edge on p3.r).  A complex
 * shape (Coriolis) counts the real and the imaginary part: |x|^2 = re^2 + im^2.
 * Fractions only: the common factors (1/2, w^2) cancel.  The section offsets and
 * the consistent mass are left out of the split (lumped halves always) (it classifies; it does not add up
 * to the modal energy of the model to round-off).
 *
 * The label comes from the strain fractions: a member that moves rigidly along its
 * axis carries kinetic "axial" energy without stretching (the second member of the
 * angled beam in its first bending mode), so the kinetic split would call bending
 * modes coupled.  Helpers are lab_*.
 */
#include "internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Share of the strain energy above which a mode is of one kind (DESIGN.md 9). */
#define LAB_DOMINANT 0.6

static const char *const lab_names[] = {"axial", "edge", "flap", "torsion", "coupled", "bending"};

const char *sm_mode_kind_name(int kind)
{
    return kind >= 0 && kind <= SM_MODE_BENDING ? lab_names[kind] : "unknown";
}

char *sm_mode_label(int kind, int ordinal, char *buf, size_t size)
{
    const char *suf = "th";
    int r100 = ordinal % 100, r10 = ordinal % 10;

    if (!buf || size == 0)
        return buf;
    if (kind == SM_MODE_COUPLED || ordinal < 1) {
        snprintf(buf, size, "%s", sm_mode_kind_name(kind));
        return buf;
    }
    if (r100 < 11 || r100 > 13)
        suf = r10 == 1 ? "st" : r10 == 2 ? "nd" : r10 == 3 ? "rd" : "th";
    snprintf(buf, size, "%d%s %s", ordinal, suf, sm_mode_kind_name(kind));
    return buf;
}

static double lab_dot(const double *a, const double *b);

/* v rotated by the rotation vector psi (Rodrigues): v cos + (k x v) sin + k (k.v)(1 - cos). */
static void lab_rotate(const double psi[3], double v[3])
{
    double th = sqrt(lab_dot(psi, psi));
    if (!(th > 0))
        return;
    double k[3] = {psi[0] / th, psi[1] / th, psi[2] / th}, kv = lab_dot(k, v), cs = cos(th), sn = sin(th);
    double x[3] = {k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]};
    for (int i = 0; i < 3; i++)
        v[i] = v[i] * cs + x[i] * sn + k[i] * kv * (1 - cs);
}

/* Principal axes of element e at the equilibrium of case c: t along the deformed chord n1 -> n2,
 * p2 the rest p2 turned by the mean rotation of the two nodes and made normal to t, p3 = t x p2
 * (planar: p2 the in-plane normal, p3 = z), hub frame. */
static void lab_axes(const sm_model *m, const sm_case *c, const sm_elem *e, double t[3], double p2[3],
                     double p3[3])
{
    int dof = m->spatial ? 6 : 3;
    const double *a = c->nodes + (size_t)dof * e->n1, *b = c->nodes + (size_t)dof * e->n2;
    t[0] = b[0] - a[0], t[1] = b[1] - a[1], t[2] = m->spatial ? b[2] - a[2] : 0;
    double n = sqrt(lab_dot(t, t));
    for (int k = 0; k < 3; k++)
        t[k] /= n;
    if (!m->spatial) {
        p2[0] = -t[1], p2[1] = t[0], p2[2] = 0;
        p3[0] = 0, p3[1] = 0, p3[2] = 1;
        return;
    }
    double psi[3];
    for (int k = 0; k < 3; k++) {
        p2[k] = e->ax[3 + k];
        psi[k] = 0.5 * (a[3 + k] + b[3 + k]);
    }
    lab_rotate(psi, p2);
    double d = lab_dot(p2, t);
    for (int k = 0; k < 3; k++)
        p2[k] -= d * t[k];
    n = sqrt(lab_dot(p2, p2));
    for (int k = 0; k < 3; k++)
        p2[k] /= n;
    p3[0] = t[1] * p2[2] - t[2] * p2[1];
    p3[1] = t[2] * p2[0] - t[0] * p2[2];
    p3[2] = t[0] * p2[1] - t[1] * p2[0];
}

static double lab_dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Node k of shape s as (d, r) in 3D: planar (dx, dy, dphi) -> (dx, dy, 0, 0, 0, dphi). */
static void lab_node(const sm_model *m, const double *s, int k, double d[3], double r[3])
{
    if (m->spatial) {
        memcpy(d, s + 6 * (size_t)k, 3 * sizeof(double));
        memcpy(r, s + 6 * (size_t)k + 3, 3 * sizeof(double));
        return;
    }
    d[0] = s[3 * (size_t)k], d[1] = s[3 * (size_t)k + 1], d[2] = 0;
    r[0] = 0, r[1] = 0, r[2] = s[3 * (size_t)k + 2];
}

/* x' K x for the Hermite bending stiffness EI/l^3 [12 6l -12 6l; . 4l^2 -6l 2l^2; ...] on
 * (v1, v1', v2, v2'). */
static double lab_bending(double EI, double l, double v1, double s1, double v2, double s2)
{
    double a = v1 - v2;
    return EI / (l * l * l) * (12 * a * a + 12 * l * a * (s1 + s2) +
                               l * l * (4 * s1 * s1 + 4 * s2 * s2 + 4 * s1 * s2));
}

/* e[0..3] += kinetic (axial, edge, flap, torsion), e[4..7] += strain of element el for one
 * real shape s (a part of a complex one). */
static void lab_element(const sm_model *m, const sm_case *c, int el, const double *s, double e[SM_ENERGY_PARTS])
{
    const sm_elem *E = &m->elems[el];
    double t[3], p2[3], p3[3], d[2][3], r[2][3], u[2], v[2], w[2], tx[2], r2[2], r3[2];
    int nd[2] = {E->n1, E->n2};

    lab_axes(m, c, E, t, p2, p3);
    for (int h = 0; h < 2; h++) {
        lab_node(m, s, nd[h], d[h], r[h]);
        u[h] = lab_dot(t, d[h]);
        v[h] = lab_dot(p2, d[h]);
        w[h] = lab_dot(p3, d[h]);
        tx[h] = lab_dot(t, r[h]);
        r2[h] = lab_dot(p2, r[h]);
        r3[h] = lab_dot(p3, r[h]);
        /* kinetic: half the element on each end; the far node's point mass (every node but the
         * clamp ends exactly one element: elements run away from the clamp) */
        double mass = 0.5 * E->mu * E->l + (h == 1 ? m->nodes[E->n2].point_mass : 0.0);
        e[0] += mass * u[h] * u[h];
        e[1] += mass * v[h] * v[h];
        e[2] += mass * w[h] * w[h];
        if (m->spatial) {
            e[3] += 0.5 * E->l * (E->i_flap + E->i_edge) * tx[h] * tx[h];
            e[2] += 0.5 * E->l * E->i_flap * r2[h] * r2[h];
            e[1] += 0.5 * E->l * E->i_edge * r3[h] * r3[h];
        }
    }
    /* strain */
    double du = u[1] - u[0];
    e[4] += E->EA / E->l * du * du;
    if (m->spatial) {
        double dt = tx[1] - tx[0];
        e[5] += lab_bending(E->EI_edge, E->l, v[0], r3[0], v[1], r3[1]);   /* v' = p3.r */
        e[6] += lab_bending(E->EI_flap, E->l, w[0], -r2[0], w[1], -r2[1]); /* w' = -p2.r */
        e[7] += E->GJ / E->l * dt * dt;
    } else {
        e[5] += lab_bending(E->EI, E->l, v[0], r3[0], v[1], r3[1]);
    }
}

/* Point-mass rotary inertia of node k (spatial) in the axes (t, p2, p3): its diagonal. */
static void lab_point_rot(const sm_model *m, const sm_case *c, int el, const double *s, double e[SM_ENERGY_PARTS])
{
    const sm_elem *E = &m->elems[el];
    const double *P = m->nodes[E->n2].point_rot;
    double t[3], p2[3], p3[3], d[3], r[3], *ax[3] = {t, p2, p3};
    int slot[3] = {3, 2, 1}; /* about t: torsion; about p2: flap; about p3: edge */

    lab_axes(m, c, E, t, p2, p3);
    lab_node(m, s, E->n2, d, r);
    for (int a = 0; a < 3; a++) {
        double Pa[3], ra = lab_dot(ax[a], r);
        for (int i = 0; i < 3; i++)
            Pa[i] = P[i] * ax[a][0] + P[i + 3] * ax[a][1] + P[i + 6] * ax[a][2];
        e[slot[a]] += lab_dot(ax[a], Pa) * ra * ra; /* (a' P a) (a.r)^2 */
    }
}

/* Energy fractions of one nodal shape (re, and im or NULL) into f[SM_ENERGY_PARTS]. */
static void lab_energy(const sm_model *m, const sm_case *c, const double *re, const double *im, double f[SM_ENERGY_PARTS])
{
    double e[SM_ENERGY_PARTS] = {0};

    for (int el = 0; el < m->n_elems; el++) {
        lab_element(m, c, el, re, e);
        if (im)
            lab_element(m, c, el, im, e);
        if (m->spatial) {
            lab_point_rot(m, c, el, re, e);
            if (im)
                lab_point_rot(m, c, el, im, e);
        }
    }
    for (int h = 0; h < 2; h++) {
        double sum = e[4 * h] + e[4 * h + 1] + e[4 * h + 2] + e[4 * h + 3];
        for (int k = 0; k < 4; k++)
            f[4 * h + k] = sum > 0 ? e[4 * h + k] / sum : 0.0;
    }
}

/* Kind and confidence of a mode from its strain fractions f[4..7]. */
static int lab_kind(const sm_model *m, const double f[SM_ENERGY_PARTS], double *conf)
{
    int best = 0;

    for (int k = 1; k < 4; k++)
        if (f[4 + k] > f[4 + best])
            best = k;
    *conf = f[4 + best];
    if (!(*conf > LAB_DOMINANT))
        return SM_MODE_COUPLED;
    if (!m->spatial && best == 1)
        return SM_MODE_BENDING;
    return best; /* SM_MODE_AXIAL .. SM_MODE_TORSION are the slots 0..3 */
}

int lab_case(const sm_model *m, sm_case *c)
{
    int k = c->n_modes, dof = m->spatial ? 6 : 3;
    size_t stride = (size_t)dof * (size_t)m->n_nodes;
    int count[SM_MODE_BENDING + 1] = {0};

    if (k <= 0 || !c->shape_re || !c->nodes)
        return SM_OK;
    c->energy = malloc((size_t)k * SM_ENERGY_PARTS * sizeof(double));
    c->label_kind = malloc((size_t)k * sizeof(int));
    c->label_ordinal = malloc((size_t)k * sizeof(int));
    c->label_confidence = malloc((size_t)k * sizeof(double));
    if (!c->energy || !c->label_kind || !c->label_ordinal || !c->label_confidence)
        return SM_NOMEM;
    for (int j = 0; j < k; j++) { /* modes are in ascending frequency: ordinals count up */
        double *f = c->energy + (size_t)j * SM_ENERGY_PARTS;
        lab_energy(m, c, c->shape_re + j * stride, c->shape_im ? c->shape_im + j * stride : NULL, f);
        c->label_kind[j] = lab_kind(m, f, &c->label_confidence[j]);
        c->label_ordinal[j] = c->label_kind[j] == SM_MODE_COUPLED ? 0 : ++count[c->label_kind[j]];
    }
    return SM_OK;
}
