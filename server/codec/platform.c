/*
 * platform.c — the clamp of a request (DESIGN.md 8.6): a joint's name (rigid), an elastic clamp
 * {joint, stiffness, mass} or a floating platform ("clamp": null with "platform"), checked into
 * the canonical copy and turned into the core's free base (sm_structure.base_free) and its point
 * support at the clamp joint.
 *
 * How it fits: validate.c calls plat_clamp after the springs; request.c takes the clamp joint
 * from plat_clamp_name and base_free from plat_base_free; supports.c's sup_build appends the
 * base's support (plat_fill) after the springs and foundations, and sup_pointer sends its index
 * to plat_pointer; diag.c points SM_ITEM_CLAMP at plat_clamp_pointer.  The 6x6 matrices are
 * read and checked by supports.c (sup_matrix6); what the core refuses about a free base (a
 * direction without stiffness, speeds other than 0) comes back as its diagnostic.
 *
 * A platform's matrices are about points: hydrostatic, mooring and added_mass about
 * "reference" ([x, y, z], hub frame, default the joint), mass about "mass_reference" (default
 * "reference").  Each is carried rigidly to the clamp joint: a point at r from the joint moves
 * by u + theta x r, so with T = [[I, -[r]x], [0, I]] the matrix about the joint is T^T K T
 * (BModes' T_pform, BModes.f90:745-782, is this T for a point on the tower's axis).
 */
#include "codec_internal.h"

#include <stdlib.h>
#include <string.h>

/* Units of a stiffness and a mass 6x6 in messages. */
#define PLAT_K_UNIT " (N/m, N/rad, N m/rad)"
#define PLAT_M_UNIT " (kg, kg m, kg m^2)"

/* The elastic clamp object cl at /structure/clamp into canonical c. */
static void plat_elastic(val_ctx *v, const json_t *cl, const json_t *joints, json_t *c)
{
    static const char *const keys[] = {"joint", "stiffness", "mass", NULL};
    static const char *p = "/structure/clamp";
    double a[36];

    field_check_keys(v, cl, p, keys, "elastic clamp");
    field_ref(v, cl, "joint", p, c, joints, "joint");
    if (!json_object_get(cl, "stiffness"))
        field_error_key(v, p, "stiffness",
                        "required field 'stiffness' is missing: an elastic clamp is a 6x6 "
                        "stiffness (and mass) at the clamp joint");
    else
        sup_matrix6(v, cl, p, "stiffness", PLAT_K_UNIT, 0, c, a);
    if (json_object_get(cl, "mass"))
        sup_matrix6(v, cl, p, "mass", PLAT_M_UNIT, 0, c, a);
}

/* Direction names of a base, hub axes (bit i of sm_structure.base_held) and the tower form's
 * (tower axes fa, ss, up = hub z, x, y: tower name k is hub direction plat_tower_dir[k]). */
static const char *const plat_dirs[6] = {"x", "y", "z", "rx", "ry", "rz"};
static const char *const plat_tower_dirs[6] = {"fa", "ss", "up", "r_fa", "r_ss", "r_up"};
static const int plat_tower_dir[6] = {2, 0, 1, 5, 3, 4};

/* "held" of pf at p: the directions (names, one each, not all six) the base is held in, as a
 * mask of bits over names[]; -1 when invalid (reported). */
static int plat_held(val_ctx *v, const json_t *pf, const char *p, const char *const names[6])
{
    const json_t *h = json_object_get(pf, "held"), *x;
    char ptr[64];
    size_t i;
    int mask = 0, k;

    if (!h)
        return 0;
    snprintf(ptr, sizeof ptr, "%s/held", p);
    if (!json_is_array(h) || json_array_size(h) < 1 || json_array_size(h) > 5) {
        field_error(v, ptr,
                    "must be an array of 1 to 5 direction names among %s, %s, %s, %s, %s, %s "
                    "(held in all six is a rigid clamp)",
                    names[0], names[1], names[2], names[3], names[4], names[5]);
        return -1;
    }
    json_array_foreach(h, i, x) {
        for (k = 0; k < 6; k++)
            if (json_is_string(x) && !strcmp(json_string_value(x), names[k]))
                break;
        if (k == 6 || (mask & (1 << k))) {
            char q[128];
            snprintf(q, sizeof q, "%s/%zu", ptr, i);
            field_error(v, q, "%s: each direction once, among %s, %s, %s, %s, %s, %s",
                        k == 6 ? "unknown direction" : "given twice", names[0], names[1], names[2],
                        names[3], names[4], names[5]);
            return -1;
        }
        mask |= 1 << k;
    }
    return mask;
}

/* The names of mask's bits over names[] (new). */
static json_t *plat_held_names(int mask, const char *const names[6])
{
    json_t *a = json_array();
    for (int k = 0; a && k < 6; k++)
        if ((mask & (1 << k)) && json_array_append_new(a, json_string(names[k]))) {
            json_decref(a);
            return NULL;
        }
    return a;
}

/* The platform object pf at /structure/platform into canonical c. */
static void plat_floating(val_ctx *v, const json_t *pf, const json_t *joints, json_t *c)
{
    static const char *const keys[] = {"joint",          "mass",    "added_mass",
                                       "hydrostatic",    "mooring", "reference",
                                       "mass_reference", "held",    NULL};
    static const char *const mats[] = {"mass", "added_mass", "hydrostatic", "mooring"};
    static const char *const pt[] = {"reference", "mass_reference"};
    static const char *p = "/structure/platform";
    double a[36], r[3];
    int k;

    field_check_keys(v, pf, p, keys, "platform");
    field_ref(v, pf, "joint", p, c, joints, "joint");
    for (k = 0; k < 4; k++)
        if (json_object_get(pf, mats[k]))
            sup_matrix6(v, pf, p, mats[k], k < 2 ? PLAT_M_UNIT : PLAT_K_UNIT, k == 2, c, a);
    for (k = 0; k < 2; k++)
        if (json_object_get(pf, pt[k]) &&
            field_vector(v, pf, pt[k], p, 3, FIELD_FINITE, "[x, y, z]", " (m)", r))
            field_set(v, c, pt[k], field_reals(r, 3));
    if ((k = plat_held(v, pf, p, plat_dirs)) > 0)
        field_set(v, c, "held", plat_held_names(k, plat_dirs));
}

void plat_clamp(val_ctx *v, const json_t *st, const json_t *joints, json_t *cst)
{
    const json_t *cl = json_object_get(st, "clamp"), *pf = json_object_get(st, "platform");
    json_t *c;

    if (pf && !json_is_null(cl) && cl)
        field_error(v, "/structure/platform",
                    "a platform carries the clamp joint: give \"clamp\": null with it (a "
                    "floating base), or leave the platform out");
    if (!json_is_object(cl) && !json_is_null(cl)) {
        field_ref(v, st, "clamp", "/structure", cst, joints, "joint");
        return;
    }
    if (v->spatial == 0)
        field_error(v, "/structure/clamp",
                    "an elastic clamp or a floating platform needs a spatial structure (its "
                    "base moves in six directions); give the rigid clamp's joint name");
    if (json_is_null(cl) && !json_is_object(pf)) {
        field_error(v, pf ? "/structure/platform" : "/structure/clamp",
                    pf ? "must be an object {joint, mass, added_mass, hydrostatic, mooring [, "
                         "reference, mass_reference]}"
                       : "null means a floating base: it needs a \"platform\" {joint, mass, "
                         "added_mass, hydrostatic, mooring}; give the joint's name for a rigid "
                         "clamp");
        return;
    }
    if (!(c = json_object())) {
        v->nomem = 1;
        return;
    }
    if (json_is_object(cl)) {
        plat_elastic(v, cl, joints, c);
        field_set(v, cst, "clamp", c);
        return;
    }
    plat_floating(v, pf, joints, c);
    field_set(v, cst, "clamp", json_null());
    field_set(v, cst, "platform", c);
}

const char *plat_clamp_name(const json_t *st)
{
    const json_t *cl = json_object_get(st, "clamp");

    if (json_is_string(cl))
        return json_string_value(cl);
    if (json_is_object(cl))
        return json_string_value(json_object_get(cl, "joint"));
    return json_string_value(json_object_get(json_object_get(st, "platform"), "joint"));
}

int plat_base_free(const json_t *st)
{
    const json_t *cl = json_object_get(st, "clamp");

    return json_is_object(cl) || (json_is_null(cl) && json_object_get(st, "platform"));
}

unsigned plat_base_held(const json_t *st)
{
    const json_t *h = json_object_get(json_object_get(st, "platform"), "held"), *x;
    unsigned mask = 0;
    size_t i;

    json_array_foreach(h, i, x)
        for (int k = 0; k < 6; k++)
            if (json_is_string(x) && !strcmp(json_string_value(x), plat_dirs[k]))
                mask |= 1u << k;
    return json_is_null(json_object_get(st, "clamp")) ? mask : 0;
}

/* a (6x6, column-major) about the point r from the joint moved to the joint: T^T a T. */
static void plat_transport(const double r[3], double a[36])
{
    double T[36], t[36];
    int i, j, k;

    memset(T, 0, sizeof T);
    for (i = 0; i < 6; i++)
        T[i + 6 * i] = 1;
    /* -[r]x in rows 0-2, columns 3-5: u_r = u + theta x r = u - r x theta */
    T[0 + 6 * 4] = r[2];
    T[0 + 6 * 5] = -r[1];
    T[1 + 6 * 3] = -r[2];
    T[1 + 6 * 5] = r[0];
    T[2 + 6 * 3] = r[1];
    T[2 + 6 * 4] = -r[0];
    for (i = 0; i < 6; i++) /* t = a T */
        for (j = 0; j < 6; j++) {
            t[i + 6 * j] = 0;
            for (k = 0; k < 6; k++)
                t[i + 6 * j] += a[i + 6 * k] * T[k + 6 * j];
        }
    for (i = 0; i < 6; i++) /* a = T^T t */
        for (j = 0; j < 6; j++) {
            a[i + 6 * j] = 0;
            for (k = 0; k < 6; k++)
                a[i + 6 * j] += T[k + 6 * i] * t[k + 6 * j];
        }
}

/* out += the matrix pf[key] about the point pf[at] (absent: the joint at pj) moved to pj. */
static void plat_add(const json_t *pf, const char *key, const json_t *at, const double pj[3],
                     double out[36])
{
    double a[36], r[3] = {0, 0, 0};
    int k;

    if (!json_object_get(pf, key))
        return;
    sup_read(json_object_get(pf, key), a);
    for (k = 0; at && k < 3; k++)
        r[k] = json_number_value(json_array_get(at, (size_t)k)) - pj[k];
    plat_transport(r, a);
    for (k = 0; k < 36; k++)
        out[k] += a[k];
}

void plat_fill(const json_t *st, const sup_joints *J, sm_support *s)
{
    const json_t *cl = json_object_get(st, "clamp"), *pf = json_object_get(st, "platform");
    const json_t *ref, *mref;
    double pj[3];

    memset(s, 0, sizeof *s);
    s->member = -1;
    s->joint = sup_joint(J->names, J->n, plat_clamp_name(st));
    if (s->joint < 0)
        return;
    if (json_is_object(cl)) {
        sup_read(json_object_get(cl, "stiffness"), s->K);
        sup_read(json_object_get(cl, "mass"), s->M);
        return;
    }
    sup_pos(J, s->joint, pj);
    ref = json_object_get(pf, "reference");
    mref = json_object_get(pf, "mass_reference");
    plat_add(pf, "hydrostatic", ref, pj, s->K);
    plat_add(pf, "mooring", ref, pj, s->K);
    plat_add(pf, "added_mass", ref, pj, s->M);
    plat_add(pf, "mass", mref ? mref : ref, pj, s->M);
}

char *plat_pointer(const json_t *st, const char *field)
{
    int el = json_is_object(json_object_get(st, "clamp"));

    if (el && !strcmp(field, "K"))
        return strdup("/structure/clamp/stiffness");
    if (el && !strcmp(field, "M"))
        return strdup("/structure/clamp/mass");
    return plat_clamp_pointer(st);
}

char *plat_clamp_pointer(const json_t *st)
{
    return strdup(json_is_null(json_object_get(st, "clamp")) && json_object_get(st, "platform")
                      ? "/structure/platform"
                      : "/structure/clamp");
}

/* a = R a R^T with R = diag(T, T) (tower axes -> hub axes). */
static void plat_rotate(const double T[3][3], double a[36])
{
    double t[36];
    int i, j, k, l;

    for (i = 0; i < 6; i++) /* t = R a */
        for (j = 0; j < 6; j++) {
            t[i + 6 * j] = 0;
            for (k = 0; k < 3; k++)
                t[i + 6 * j] += T[i % 3][k] * a[k + 3 * (i / 3) + 6 * j];
        }
    for (i = 0; i < 6; i++) /* a = t R^T */
        for (j = 0; j < 6; j++) {
            a[i + 6 * j] = 0;
            for (l = 0; l < 3; l++)
                a[i + 6 * j] += t[i + 6 * (l + 3 * (j / 3))] * T[j % 3][l];
        }
}

/* The hub-axes rows of the 6x6 a (column-major) as a JSON array. */
static json_t *plat_rows(const double a[36])
{
    json_t *rows = json_array();
    double r[6];
    int i, j;

    for (i = 0; rows && i < 6; i++) {
        for (j = 0; j < 6; j++)
            r[j] = a[i + 6 * j];
        if (json_array_append_new(rows, field_reals(r, 6))) {
            json_decref(rows);
            return NULL;
        }
    }
    return rows;
}

void plat_tower(val_ctx *v, const json_t *tw, json_t *ct, json_t *st, const double T[3][3],
                double base_height)
{
    static const char *const keys[] = {
        "mass",        "added_mass", "hydrostatic", "mooring", "reference_height",
        "mass_height", "held",       NULL};
    static const char *p = "/tower/platform";
    const json_t *pf = json_object_get(tw, "platform");
    double a[36], h[2] = {base_height, base_height}, pt[3] = {0, 0, 0};
    json_t *c, *sp;
    int k, ok = 1;

    if (!pf)
        return;
    if (!json_is_object(pf)) {
        field_error(v, p,
                    "must be an object {mass, added_mass, hydrostatic, mooring [, "
                    "reference_height, mass_height]} (6x6 in tower axes fa, ss, up), not %s",
                    field_type_name(pf));
        return;
    }
    field_check_keys(v, pf, p, keys, "platform");
    c = json_object();
    sp = json_pack("{s:s}", "joint", "base");
    if (!c || !sp) {
        v->nomem = 1;
        goto done;
    }
    if (json_object_get(pf, "reference_height"))
        ok &= field_real(v, pf, "reference_height", p, c, FIELD_FINITE, " (m)", &h[0]);
    h[1] = h[0];
    if (json_object_get(pf, "mass_height"))
        ok &= field_real(v, pf, "mass_height", p, c, FIELD_FINITE, " (m)", &h[1]);
    for (k = 0; k < 4; k++)
        if (json_object_get(pf, keys[k])) {
            if (!sup_matrix6(v, pf, p, keys[k], k < 2 ? PLAT_M_UNIT : PLAT_K_UNIT, k == 2, c, a)) {
                ok = 0;
                continue;
            }
            plat_rotate(T, a);
            field_set(v, sp, keys[k], plat_rows(a));
        }
    for (k = 0; k < 2; k++) { /* the points on the tower's axis: up = hub y */
        pt[1] = h[k];
        field_set(v, sp, k ? "mass_reference" : "reference", field_reals(pt, 3));
    }
    if ((k = plat_held(v, pf, p, plat_tower_dirs)) > 0) { /* tower names -> hub directions */
        int hub = 0;
        for (int i = 0; i < 6; i++)
            if (k & (1 << i))
                hub |= 1 << plat_tower_dir[i];
        field_set(v, c, "held", plat_held_names(k, plat_tower_dirs));
        field_set(v, sp, "held", plat_held_names(hub, plat_dirs));
    } else if (k < 0) {
        ok = 0;
    }
    if (ok) {
        field_set(v, st, "clamp", json_null());
        field_set(v, st, "platform", json_incref(sp));
    }
    field_set(v, ct, "platform", json_incref(c));
done:
    json_decref(c);
    json_decref(sp);
}
