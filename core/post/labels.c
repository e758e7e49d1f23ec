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
 * modes coupled.  Helpers are lab_*; what differs between the planar and the spatial kind
 * (axes, nodal values, rotary inertia, bending and torsion strain) is the kind's (kind.h).
 */
#include "element.h"
#include "kind.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Share of the strain energy above which a mode is of one kind (DESIGN.md 9). */
#define LAB_DOMINANT 0.6

static const char *const lab_names[] = {"axial",   "edge",    "flap",      "torsion",
                                        "coupled", "bending", "rigid-body"};

const char *sm_mode_kind_name(int kind)
{
    return kind >= 0 && kind <= SM_MODE_RIGID ? lab_names[kind] : "unknown";
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

/* e[0..3] += kinetic (axial, edge, flap, torsion), e[4..7] += strain of element el for one
 * real shape s (a part of a complex one); ax: the element's axes t, p2, p3 (the kind's
 * label_axes); the kind gives the nodes' motion in 3D, the rotary inertia's parts and the
 * bending and torsion strain. */
static void lab_element(const sm_model *m, int el, const double ax[9], const double *s,
                        double e[SM_ENERGY_PARTS])
{
    const smi_kind *K = m->kind;
    const sm_elem *E = &m->elems[el];
    const double *t = ax, *p2 = ax + 3, *p3 = ax + 6;
    double d[2][3], r[2][3], u[2], v[2], w[2], tx[2], r2[2], r3[2];
    int nd[2] = {E->n1, E->n2};

    for (int h = 0; h < 2; h++) {
        K->label_node(s, nd[h], d[h], r[h]);
        u[h] = smi_dot3(t, d[h]);
        v[h] = smi_dot3(p2, d[h]);
        w[h] = smi_dot3(p3, d[h]);
        tx[h] = smi_dot3(t, r[h]);
        r2[h] = smi_dot3(p2, r[h]);
        r3[h] = smi_dot3(p3, r[h]);
        /* kinetic: half the element on each end; the far node's point mass (every node but the
         * clamp ends exactly one element: elements run away from the clamp) */
        double mass = 0.5 * E->mu * E->l + (h == 1 ? m->nodes[E->n2].point_mass : 0.0);
        e[0] += mass * u[h] * u[h];
        e[1] += mass * v[h] * v[h];
        e[2] += mass * w[h] * w[h];
        if (K->label_rotary)
            K->label_rotary(E, tx[h], r2[h], r3[h], e);
    }
    /* strain */
    e[4] += smi_elem_bar_energy(E->EA, E->l, u[0], u[1]);
    K->label_strain(E, v, w, tx, r2, r3, e);
}

/* Energy fractions of one nodal shape (re, and im or NULL) into f[SM_ENERGY_PARTS]; ax: the
 * elements' axes, 9 a element (lab_case); *support (may be NULL) = the supports' share of the
 * strain energy. */
static void lab_energy(const sm_model *m, const double *ax, const double *re, const double *im,
                       double f[SM_ENERGY_PARTS], double *support)
{
    double e[SM_ENERGY_PARTS] = {0};

    for (int el = 0; el < m->n_elems; el++) {
        const double *a = ax + (size_t)9 * el;
        lab_element(m, el, a, re, e);
        if (im)
            lab_element(m, el, a, im, e);
        if (m->kind->label_point) {
            m->kind->label_point(m, el, a, re, e);
            if (im)
                m->kind->label_point(m, el, a, im, e);
        }
    }
    for (int h = 0; h < 2; h++) {
        double sum = e[4 * h] + e[4 * h + 1] + e[4 * h + 2] + e[4 * h + 3];
        for (int k = 0; k < 4; k++)
            f[4 * h + k] = sum > 0 ? e[4 * h + k] / sum : 0.0;
    }
    if (support) {
        double es = supports_shape_energy(m, re) + (im ? supports_shape_energy(m, im) : 0.0);
        double all = es + e[4] + e[5] + e[6] + e[7];
        *support = all > 0 ? es / all : 0.0;
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
    if (m->kind->label_bending && best == 1)
        return SM_MODE_BENDING;
    return best; /* SM_MODE_AXIAL .. SM_MODE_TORSION are the slots 0..3 */
}

int lab_case(const sm_model *m, sm_case *c)
{
    int k = c->n_modes, dof = m->kind->node_dof;
    size_t stride = (size_t)dof * (size_t)m->n_nodes;
    int count[SM_MODE_RIGID + 1] = {0};

    if (k <= 0 || !c->shape_re || !c->nodes)
        return SM_OK;
    c->energy = malloc((size_t)k * SM_ENERGY_PARTS * sizeof(double));
    c->label_kind = malloc((size_t)k * sizeof(int));
    c->label_ordinal = malloc((size_t)k * sizeof(int));
    c->label_confidence = malloc((size_t)k * sizeof(double));
    if (m->has_supports && !(c->support_share = malloc((size_t)k * sizeof(double))))
        return SM_NOMEM;
    /* the elements' axes at the steady state, once for every mode (issue 27) */
    double *ax = malloc((size_t)9 * (size_t)(m->n_elems > 0 ? m->n_elems : 1) * sizeof(double));
    if (!c->energy || !c->label_kind || !c->label_ordinal || !c->label_confidence || !ax) {
        free(ax);
        return SM_NOMEM;
    }
    for (int el = 0; el < m->n_elems; el++) {
        double *a = ax + (size_t)9 * el;
        m->kind->label_axes(m, c, &m->elems[el], a, a + 3, a + 6);
    }
    for (int j = 0; j < k; j++) { /* modes are in ascending frequency: ordinals count up */
        double *f = c->energy + (size_t)j * SM_ENERGY_PARTS;
        lab_energy(m, ax, c->shape_re + j * stride, c->shape_im ? c->shape_im + j * stride : NULL,
                   f, c->support_share ? c->support_share + j : NULL);
        c->label_kind[j] = lab_kind(m, f, &c->label_confidence[j]);
        if (m->base && c->frequency[j] == 0) { /* a free base's rigid-body mode (linsys.c) */
            c->label_kind[j] = SM_MODE_RIGID;
            c->label_confidence[j] = 1;
        }
        c->label_ordinal[j] = c->label_kind[j] == SM_MODE_COUPLED ? 0 : ++count[c->label_kind[j]];
    }
    free(ax);
    return SM_OK;
}
