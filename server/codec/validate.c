/*
 * validate.c — the request document of DESIGN.md sections 3 and 7.3, walked field by field.
 *
 * How it fits: request.c hands the parsed JSON to val_request, which checks
 * it against the request's shape and builds the canonical copy with every
 * default written out; request.c turns that copy into the core's arrays
 * only when no error was found.  The walk follows the document (structure:
 * joints, sections, members, point masses, clamp; then frames; then
 * analysis) and never stops at the first error: each field is checked
 * (type, range, references, unknown keys) with the readers of field.c, and
 * each error carries the JSON pointer of its field.  The limits of
 * codec_limits are checked before anything is built from a count; the
 * size of the result last, from all the counts (size.c).
 *
 * Planar or spatial (DESIGN.md 7.3): the sections decide (section.c tells
 * the form of each).  They must all be of one kind; the spatial fields of
 * the other items ([x, y, z] joints, a member's twist_deg and
 * flap_direction, a point mass's inertia) and the "paper" basis are checked
 * against that kind, each mismatch a 422 that says what to add.  A planar
 * request keeps exactly its canonical form of before the spatial fields
 * existed; a spatial one writes its defaults out (z = 0, twist_deg 0,
 * inertia [0, 0, 0], the section inertias).
 *
 * Topology (cycles, disconnected members) is the core's job: sm_model_new
 * reports it and diag.c maps it back to a pointer.  Here only the cheap
 * local cases are pre-checked (zero-length member, a joint or clamp that
 * is no member's end) so those appear with the other errors.
 */
#include "codec_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Position of joint `name` in the input joints object (z = 0 for [x, y]), if valid. */
static int val_joint_pos(const json_t *joints, const char *name, double p[3])
{
    const json_t *j = joints ? json_object_get(joints, name) : NULL;
    size_t n = json_array_size(j), k;

    if (!json_is_array(j) || n < 2 || n > 3)
        return 0;
    p[2] = 0;
    for (k = 0; k < n; k++)
        if (!field_number(json_array_get(j, k), &p[k]) || !isfinite(p[k]))
            return 0;
    return 1;
}

/*
 * A count n of items at base against its limit: when none is set, n must
 * also be > 0 (none is the message).  1 when fine, else 0 after reporting.
 */
static int val_count(val_ctx *v, const char *base, size_t n, int limit, const char *what,
                     const char *none)
{
    if (n == 0 && none) {
        field_error(v, base, "%s", none);
        return 0;
    }
    if (n > (size_t)limit) {
        field_error(v, base, "too many %s (%zu): the limit is %d", what, n, limit);
        return 0;
    }
    return 1;
}

/* ---------------------------------------------------------- structure */

/*
 * structure.joints: {"name": [x, y] or [x, y, z], ...}; returns the input
 * object if usable.  *first_z receives the name (borrowed) of the first
 * joint given with z, or NULL: whether z is allowed depends on the
 * sections (val_spatial_joints).
 */
static const json_t *val_joints(val_ctx *v, const json_t *st, json_t *cst, const char **first_z)
{
    static const char *base = "/structure/joints";
    const json_t *joints = field_object(v, st, "joints", "/structure");
    json_t *cj, *xy;
    const char *name;

    *first_z = NULL;
    if (!joints)
        return NULL;
    if (!val_count(v, base, json_object_size(joints), v->lim->max_joints, "joints",
                   "must name at least one joint"))
        return NULL;
    cj = json_object();
    if (!cj)
        v->nomem = 1;
    json_object_foreach((json_t *)joints, name, xy) {
        char *p = err_ptr_key(base, name);
        double c[3];
        size_t k, n = json_array_size(xy);
        int ok = 1;
        json_t *arr;
        if (!p) {
            v->nomem = 1;
            break;
        }
        if (name[0] == '\0')
            field_error(v, p, "a joint name must not be empty");
        if (!json_is_array(xy) || n < 2 || n > 3) {
            if (json_is_array(xy))
                field_error(v, p, "must be [x, y] or [x, y, z] (2 or 3 numbers), got %zu value%s",
                            n, n == 1 ? "" : "s");
            else
                field_error(v, p, "must be [x, y] or [x, y, z] (2 or 3 numbers), not %s",
                            field_type_name(xy));
            free(p);
            continue;
        }
        if (n == 3 && !*first_z)
            *first_z = name;
        for (k = 0; k < n; k++) {
            char *pk = err_ptr_idx(p, k);
            if (!field_check_real(v, json_array_get(xy, k), pk ? pk : p, FIELD_FINITE, " (m)",
                                  &c[k]))
                ok = 0;
            free(pk);
        }
        free(p);
        if (!ok)
            continue;
        arr = n == 3 ? json_pack("[f, f, f]", c[0], c[1], c[2]) : json_pack("[f, f]", c[0], c[1]);
        if (cj && (!arr || json_object_set_new(cj, name, arr)))
            v->nomem = 1;
        else if (!cj)
            json_decref(arr);
    }
    field_set(v, cst, "joints", cj);
    return joints;
}

/*
 * Joints and the kind of the sections: with planar sections a joint must
 * not have z (one error, at the first joint given with z); with spatial
 * sections every canonical joint is [x, y, z] (z = 0 written out).
 */
static void val_spatial_joints(val_ctx *v, json_t *cst, const char *first_z)
{
    json_t *cj = json_object_get(cst, "joints"), *xy;
    const char *name;

    if (v->spatial == 0 && first_z) {
        field_error_key(v, "/structure/joints", first_z,
                        "a joint with z needs spatial sections: " VAL_SPATIAL_SECTIONS
                        ", or give the joint as [x, y]");
        return;
    }
    if (v->spatial != 1 || !cj)
        return;
    json_object_foreach(cj, name, xy)
        if (json_array_size(xy) == 2 && json_array_append_new(xy, json_real(0.0)))
            v->nomem = 1;
}

/*
 * The kind of one section (form f, named name) against the first section
 * with a form (*first, *first_form): planar and spatial do not mix.
 */
static void val_section_kind(val_ctx *v, const char *ptr, const char *name, sec_form f,
                             const char **first, sec_form *first_form)
{
    int spatial = f >= SEC_STIFFNESS;

    if (!*first) {
        *first = name;
        *first_form = f;
        v->spatial = spatial;
        return;
    }
    if (spatial == v->spatial)
        return;
    field_error(v, ptr,
                "section '%s' is %s but the first section, '%s', is %s: planar and spatial "
                "sections do not mix; %s",
                field_short_name(name).s, sec_form_name(f), field_short_name(*first).s,
                sec_form_name(*first_form),
                spatial ? "give every section in spatial form (EA, EI_flap, EI_edge, GJ and "
                          "mass_per_length, or E, G, A, I_flap, I_edge, J and "
                          "mass_per_length), or this one in planar form (E, A, I, "
                          "mass_per_length)"
                        : "give this section in spatial form: EA, EI_flap, EI_edge, GJ and "
                          "mass_per_length (or E, G, A, I_flap, I_edge, J and mass_per_length)");
}

/* structure.sections: {"name": {planar or spatial section}, ...} (section.c). */
static const json_t *val_sections(val_ctx *v, const json_t *st, json_t *cst)
{
    static const char *base = "/structure/sections";
    const json_t *secs = field_object(v, st, "sections", "/structure");
    json_t *cs, *sec;
    const char *name, *first = NULL;
    sec_form first_form = SEC_NONE;

    if (!secs)
        return NULL;
    if (!val_count(v, base, json_object_size(secs), v->lim->max_sections, "sections",
                   "must define at least one section"))
        return NULL;
    cs = json_object();
    if (!cs)
        v->nomem = 1;
    json_object_foreach((json_t *)secs, name, sec) {
        char *p = err_ptr_key(base, name);
        sec_form f = sec_classify(sec);
        unsigned cover;
        json_t *c;
        if (!p) {
            v->nomem = 1;
            break;
        }
        if (name[0] == '\0')
            field_error(v, p, "a section name must not be empty");
        if (f == SEC_NONE) {
            field_error(v, p, "must be an object {E, A, I, mass_per_length} (planar) or {EA, "
                        "EI_flap, EI_edge, GJ, mass_per_length} (spatial), not %s",
                        field_type_name(sec));
            free(p);
            continue;
        }
        cover = (unsigned)json_integer_value(json_object_get(v->cover, name));
        if (cover || v->blade) /* a section the stations complete is spatial */
            f = sec_classify_as(sec, 1);
        val_section_kind(v, p, name, f, &first, &first_form);
        c = sec_validate(v, sec, p, f, cover);
        free(p);
        if (cs && c && json_object_set_new(cs, name, c))
            v->nomem = 1;
        else if (!cs)
            json_decref(c);
    }
    field_set(v, cst, "sections", cs);
    v->in_sections = secs;
    v->canon_sections = cs;
    return secs;
}

/*
 * A spatial-only field obj[key] at base/key: with planar sections its
 * presence is an error saying what to add (returns 0); with spatial
 * sections it is checked by the caller (returns 1); when the kind is not
 * known (no usable section: already an error) it is left alone (0).
 */
static int val_spatial_field(val_ctx *v, const json_t *obj, const char *key, const char *base)
{
    if (v->spatial == 1)
        return 1;
    if (v->spatial == 0 && json_object_get(obj, key))
        field_error_key(v, base, key, "'%s' needs spatial sections: " VAL_SPATIAL_SECTIONS
                        ", or drop '%s'", key, key);
    return 0;
}

/*
 * A vector field obj[key] of 3 numbers of kind at base/key, copied to
 * canon; nonzero (a direction: flap_direction): it must not be [0, 0, 0].
 * shape ("[x, y, z]") and unit (" (m)" or "") go into messages.  Returns 1
 * when valid.
 */
static int val_vector3(val_ctx *v, const json_t *obj, const char *key, const char *base,
                       json_t *canon, enum field_real_kind kind, int nonzero, const char *shape,
                       const char *unit)
{
    double c[3];

    if (!field_vector(v, obj, key, base, 3, kind, shape, unit, c))
        return 0;
    if (nonzero && c[0] == 0 && c[1] == 0 && c[2] == 0) {
        field_error_key(v, base, key, "[0, 0, 0] is no direction: give a non-zero [x, y, z] "
                        "(hub frame) for the member's e3 (flapwise) axis, or drop '%s' for the "
                        "default", key);
        return 0;
    }
    field_set(v, canon, key, field_reals(c, 3));
    return 1;
}

/*
 * The spatial fields of member p (DESIGN.md 7.1, 7.3): twist_deg (degrees,
 * default 0 written out), flap_direction ([x, y, z], hub frame, any
 * length; no default in the canonical form: the core finds e3) and
 * stations (DESIGN.md 8, station.c).
 */
static void val_member_spatial(val_ctx *v, const json_t *mem, const char *p, json_t *c)
{
    if (val_spatial_field(v, mem, "twist_deg", p)) {
        if (json_object_get(mem, "twist_deg"))
            field_real(v, mem, "twist_deg", p, c, FIELD_FINITE, " (degrees)", NULL);
        else
            field_set(v, c, "twist_deg", json_real(0.0));
    }
    if (val_spatial_field(v, mem, "flap_direction", p) && json_object_get(mem, "flap_direction"))
        val_vector3(v, mem, "flap_direction", p, c, FIELD_FINITE, 1, "[x, y, z]", "");
    if (val_spatial_field(v, mem, "stations", p) && json_object_get(mem, "stations"))
        stn_validate(v, mem, p, c);
}

/* Member i: {id, from, to, section, elements [, twist_deg, flap_direction]}; adds its
 * elements to *total. */
static void val_member(val_ctx *v, const json_t *mem, size_t i, const json_t *joints,
                       const json_t *secs, json_t *cm, json_t *ids, json_t *ends,
                       int *ends_ok, long *total)
{
    static const char *const keys[] = {
        "id",        "from",           "to",       "section",    "elements",
        "twist_deg", "flap_direction", "stations", "foundation", NULL};
    char *p = err_ptr_idx("/structure/members", i);
    const json_t *id;
    const char *from, *to;
    double a[3], b[3];
    long el;
    json_t *c = NULL;

    if (!p) {
        v->nomem = 1;
        return;
    }
    if (!json_is_object(mem)) {
        field_error(v, p, "must be an object {id, from, to, section, elements}, not %s",
                    field_type_name(mem));
        *ends_ok = 0;
        goto done;
    }
    field_check_keys(v, mem, p, keys, "member");
    c = json_object();
    if (!c)
        v->nomem = 1;
    id = json_object_get(mem, "id");
    if (id && (!json_is_string(id) || json_string_length(id) == 0)) {
        field_error_key(v, p, "id", "must be a non-empty string, not %s",
                        json_is_string(id) ? "an empty string" : field_type_name(id));
    } else if (id) {
        const char *s = json_string_value(id);
        const json_t *seen = json_object_get(ids, s);
        if (seen)
            field_error_key(v, p, "id", "duplicate member id '%s' (also /structure/members/%"
                            JSON_INTEGER_FORMAT ")", field_short_name(s).s,
                            json_integer_value(seen));
        else if (json_object_set_new(ids, s, json_integer((json_int_t)i)))
            v->nomem = 1;
        field_set(v, c, "id", json_string(s));
    }
    from = field_ref(v, mem, "from", p, c, joints, "joint");
    to = field_ref(v, mem, "to", p, c, joints, "joint");
    field_ref(v, mem, "section", p, c, secs, "section");
    if (field_int(v, mem, "elements", p, c, 1, 0, 1, v->lim->max_elements,
                  "the number of elements", &el))
        *total += el;
    val_member_spatial(v, mem, p, c);
    if (!from || !to) {
        *ends_ok = 0;
    } else {
        if (json_object_set_new(ends, from, json_true()) ||
            json_object_set_new(ends, to, json_true()))
            v->nomem = 1;
        if (!strcmp(from, to))
            field_error_key(v, p, "to", "zero-length member: it starts and ends at joint '%s'",
                            field_short_name(to).s);
        else if (val_joint_pos(joints, from, a) && val_joint_pos(joints, to, b) &&
                 a[0] == b[0] && a[1] == b[1] && a[2] == b[2])
            field_error(v, p, "zero-length member: joints '%s' and '%s' are at the same position",
                        field_short_name(from).s, field_short_name(to).s);
    }
    if (json_object_get(mem, "foundation")) /* supports.c; its length when its joints are known */
        sup_foundation(v, mem, p, c,
                       from && to && val_joint_pos(joints, from, a) && val_joint_pos(joints, to, b)
                           ? sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
                                  (b[2] - a[2]) * (b[2] - a[2]))
                           : 0.0);
done:
    free(p);
    if (c && cm && json_array_append_new(cm, c))
        v->nomem = 1;
    else if (c && !cm)
        json_decref(c);
}

/* structure.members: non-empty array; returns the set of joints that are member ends. */
static void val_members(val_ctx *v, const json_t *st, const json_t *joints, const json_t *secs,
                        json_t *cst, json_t *ends, int *ends_ok)
{
    static const char *base = "/structure/members";
    const json_t *mems = json_object_get(st, "members");
    json_t *cm, *ids, *mem;
    size_t i;
    long total = 0;

    *ends_ok = 0;
    if (!mems) {
        field_error(v, base, "required field 'members' is missing");
        return;
    }
    if (!json_is_array(mems)) {
        field_error(v, base, "must be an array of members, not %s", field_type_name(mems));
        return;
    }
    if (!val_count(v, base, json_array_size(mems), v->lim->max_members, "members",
                   "must list at least one member"))
        return;
    *ends_ok = joints != NULL;
    cm = json_array();
    ids = json_object();
    if (!cm || !ids)
        v->nomem = 1;
    else
        json_array_foreach(mems, i, mem)
            val_member(v, mem, i, joints, secs, cm, ids, ends, ends_ok, &total);
    json_decref(ids);
    v->total_elements = total;
    if (total > v->lim->max_elements)
        field_error(v, base, "the members have %ld elements in total: the limit is %d", total,
                    v->lim->max_elements);
    field_set(v, cst, "members", cm);
}

/*
 * The inertia tensor of point mass p (canonical c: inertia, products) must
 * be positive semi-definite (every principal minor >= 0, with a round-off
 * margin): a rotary inertia the core can carry.
 */
static void val_inertia_psd(val_ctx *v, const json_t *c, const char *p)
{
    const json_t *in = json_object_get(c, "inertia"), *pr = json_object_get(c, "products");
    double a = json_number_value(json_array_get(in, 0)), b = json_number_value(json_array_get(in, 1));
    double d = json_number_value(json_array_get(in, 2)), xy = json_number_value(json_array_get(pr, 0));
    double yz = json_number_value(json_array_get(pr, 1)), zx = json_number_value(json_array_get(pr, 2));
    double tol = 1e-12 * (a + b + d) * (a + b + d);
    /* det [[a, xy, zx], [xy, b, yz], [zx, yz, d]] */
    double det = a * (b * d - yz * yz) - xy * (xy * d - yz * zx) + zx * (xy * yz - b * zx);

    if (!pr || !in)
        return;
    if (a * b - xy * xy < -tol || b * d - yz * yz < -tol || a * d - zx * zx < -tol ||
        det < -tol * (a + b + d))
        field_error_key(v, p, "products",
                        "the inertia tensor [[%g, %g, %g], [%g, %g, %g], [%g, %g, %g]] (kg m^2) "
                        "is not positive semi-definite: no body has it (each |product| must stay "
                        "below the square root of the two moments it couples)",
                        a, xy, zx, xy, b, yz, zx, yz, d);
}

/*
 * The spatial fields of point mass pm at p (canonical c): inertia [Ixx, Iyy,
 * Izz] (default [0, 0, 0] written out), and (DESIGN.md 8) products [Ixy,
 * Iyz, Izx] and offset [x, y, z], written only when not zero.
 */
static void val_point_mass_spatial(val_ctx *v, const json_t *pm, const char *p, json_t *c)
{
    double x[3];

    if (val_spatial_field(v, pm, "inertia", p)) {
        if (json_object_get(pm, "inertia"))
            val_vector3(v, pm, "inertia", p, c, FIELD_NONNEG, 0, "[Ixx, Iyy, Izz]", " (kg m^2)");
        else
            field_set(v, c, "inertia", json_pack("[f, f, f]", 0.0, 0.0, 0.0));
    }
    if (val_spatial_field(v, pm, "products", p) && json_object_get(pm, "products") &&
        field_vector(v, pm, "products", p, 3, FIELD_FINITE, "[Ixy, Iyz, Izx]", " (kg m^2)", x) &&
        (x[0] != 0 || x[1] != 0 || x[2] != 0)) {
        field_set(v, c, "products", field_reals(x, 3));
        val_inertia_psd(v, c, p);
    }
    if (val_spatial_field(v, pm, "offset", p) && json_object_get(pm, "offset") &&
        field_vector(v, pm, "offset", p, 3, FIELD_FINITE, "[x, y, z]", " (m)", x) &&
        (x[0] != 0 || x[1] != 0 || x[2] != 0))
        field_set(v, c, "offset", field_reals(x, 3));
}

/*
 * structure.point_masses: optional array of {joint, mass [, inertia,
 * products, offset]}, the last three with spatial sections only
 * (val_point_mass_spatial).
 */
static void val_point_masses(val_ctx *v, const json_t *st, const json_t *joints, json_t *cst)
{
    static const char *const keys[] = {"joint", "mass", "inertia", "products", "offset", NULL};
    static const char *base = "/structure/point_masses";
    const json_t *pms = json_object_get(st, "point_masses");
    json_t *cp, *pm;
    size_t i;

    if (!pms) {
        field_set(v, cst, "point_masses", json_array());
        return;
    }
    if (!json_is_array(pms)) {
        field_error(v, base, "must be an array of {joint, mass}, not %s", field_type_name(pms));
        return;
    }
    if (!val_count(v, base, json_array_size(pms), v->lim->max_point_masses, "point masses",
                   NULL))
        return;
    cp = json_array();
    if (!cp) {
        v->nomem = 1;
        return;
    }
    json_array_foreach(pms, i, pm) {
        char *p = err_ptr_idx(base, i);
        json_t *c;
        if (!p) {
            v->nomem = 1;
            break;
        }
        if (!json_is_object(pm)) {
            field_error(v, p, "must be an object {joint, mass}, not %s", field_type_name(pm));
            free(p);
            continue;
        }
        field_check_keys(v, pm, p, keys, "point mass");
        c = json_object();
        if (!c)
            v->nomem = 1;
        field_ref(v, pm, "joint", p, c, joints, "joint");
        field_real(v, pm, "mass", p, c, FIELD_NONNEG, " (kg)", NULL);
        val_point_mass_spatial(v, pm, p, c);
        free(p);
        if (c && json_array_append_new(cp, c))
            v->nomem = 1;
    }
    field_set(v, cst, "point_masses", cp);
}

/* Every joint must be an end of some member (the core rejects it too). */
static void val_unused_joints(val_ctx *v, const json_t *joints, const json_t *ends)
{
    const char *name;
    json_t *xy;

    json_object_foreach((json_t *)joints, name, xy) {
        (void)xy;
        if (!json_object_get(ends, name))
            field_error_key(v, "/structure/joints", name,
                            "joint '%s' is not an end of any member", field_short_name(name).s);
    }
}

/* "gravity": [gx, gy, gz] (m/s^2, hub axes; DESIGN.md 8.8), spatial sections only; written to
 * the canonical structure only when not zero (a request without it keeps its id). */
static void val_gravity(val_ctx *v, const json_t *st, json_t *cst)
{
    double g[3];

    if (json_object_get(st, "gravity") && val_spatial_field(v, st, "gravity", "/structure") &&
        field_vector(v, st, "gravity", "/structure", 3, FIELD_FINITE, "[gx, gy, gz]", " (m/s^2)",
                     g) &&
        (g[0] != 0 || g[1] != 0 || g[2] != 0))
        field_set(v, cst, "gravity", field_reals(g, 3));
}

/* The structure object. */
void val_structure(val_ctx *v, const json_t *root, json_t *canon)
{
    static const char *const keys[] = {"joints",       "sections", "members",
                                       "point_masses", "clamp",    "springs",
                                       "platform",     "gravity",  NULL};
    const json_t *st = field_object(v, root, "structure", "");
    const json_t *joints, *secs, *clamp;
    const char *first_z;
    json_t *cst, *ends, *cover;
    int ends_ok = 0;

    if (!st)
        return;
    field_check_keys(v, st, "/structure", keys, "structure");
    cst = json_object();
    ends = json_object();
    if (!cst || !ends)
        v->nomem = 1;
    joints = val_joints(v, st, cst, &first_z);
    cover = stn_cover(json_object_get(st, "members"));
    if (!cover)
        v->nomem = 1;
    v->cover = cover;
    secs = val_sections(v, st, cst);
    val_spatial_joints(v, cst, first_z);
    if (ends)
        val_members(v, st, joints, secs, cst, ends, &ends_ok);
    val_point_masses(v, st, joints, cst);
    val_gravity(v, st, cst);
    sup_springs(v, st, joints, cst);
    if (ends_ok)
        val_unused_joints(v, joints, ends);
    clamp = json_object_get(st, "clamp");
    if (clamp && json_is_string(clamp) && joints &&
        json_object_get(joints, json_string_value(clamp)) && ends_ok &&
        !json_object_get(ends, json_string_value(clamp)))
        field_error(v, "/structure/clamp", "joint '%s' is not an end of any member",
                    field_short_name(json_string_value(clamp)).s);
    plat_clamp(v, st, joints, cst);
    json_decref(ends);
    json_decref(cover);
    v->cover = NULL;
    field_set(v, canon, "structure", cst);
}

/*
 * The optional top-level "name" (a label for people: lists, file names): a
 * string of 1 to CODEC_NAME_MAX bytes without control characters.  It is
 * not copied into the canonical request, so it never changes the job id;
 * request.c keeps it beside (codec_request_name).
 */
static void val_name(val_ctx *v, const json_t *root)
{
    const json_t *n = json_object_get(root, "name");
    const unsigned char *s;
    size_t len;

    if (!n)
        return;
    if (!json_is_string(n)) {
        field_error(v, "/name", "must be a string (a label for the design), not %s",
                    field_type_name(n));
        return;
    }
    s = (const unsigned char *)json_string_value(n);
    len = json_string_length(n);
    if (len == 0 || len > CODEC_NAME_MAX) {
        field_error(v, "/name", "must be 1 to %d bytes long, not %zu", CODEC_NAME_MAX, len);
        return;
    }
    for (size_t i = 0; i < len; i++)
        if (s[i] < 0x20 || s[i] == 0x7f) {
            field_error(v, "/name", "must not hold control characters (byte %zu)", i);
            return;
        }
}

/*
 * Validate root; returns the canonical request (new) or NULL, and in
 * *structure the canonical structure the core's arrays come from (new, or
 * NULL): the request's, or the one its "blade" stands for (blade.c).
 */
static json_t *val_document(val_ctx *v, const json_t *root, json_t **structure)
{
    static const char *const keys[] = {"structure", "blade", "tower", "frames",
                                       "analysis",  "name",  NULL};
    json_t *canon;

    if (!json_is_object(root)) {
        field_error(v, "", "the request must be a JSON object, not %s", field_type_name(root));
        return NULL;
    }
    field_check_keys(v, root, "", keys, "top-level");
    canon = json_object();
    if (!canon) {
        v->nomem = 1;
        return NULL;
    }
    if (json_object_get(root, "tower") &&
        (json_object_get(root, "blade") || json_object_get(root, "structure"))) {
        field_error(v, "/tower", "give one of 'structure', 'blade' and 'tower', not several");
    } else if (json_object_get(root, "tower")) {
        *structure = tower_validate(v, root, canon);
    } else if (json_object_get(root, "blade") && json_object_get(root, "structure")) {
        field_error(v, "/blade", "give either 'structure' or 'blade', not both");
    } else if (json_object_get(root, "blade")) {
        *structure = blade_validate(v, root, canon);
    } else {
        val_structure(v, root, canon);
        *structure = json_incref(json_object_get(canon, "structure"));
    }
    val_frames(v, root, canon);
    val_analysis(v, root, canon);
    if (json_object_get(canon, "tower")) /* a tower does not spin (tower.c) */
        tower_check_speeds(v, canon, "a tower does not spin",
                           "; the rotor's speed belongs to a rotor-on-tower model, which is not "
                           "supported yet");
    else if (json_object_get(json_object_get(canon, "structure"), "gravity"))
        tower_check_speeds(v, canon, "gravity is a steady load at rest only (DESIGN.md 8.8)", "");
    else if (plat_base_free(json_object_get(canon, "structure")))
        tower_check_speeds(v, canon,
                           "a structure on a free base (elastic clamp, floating platform) is "
                           "analysed at rest only (DESIGN.md 8.7)",
                           "");
    val_name(v, root);
    if (json_object_get(canon, "analysis") && *structure)
        size_check(v, canon, *structure); /* the result's size (size.c) */
    return canon;
}

json_t *val_request(const json_t *root, const codec_limits *lim, codec_errors *errs,
                    int *nomem, json_t **structure)
{
    val_ctx v;
    json_t *canon;

    memset(&v, 0, sizeof(v));
    v.errs = errs;
    v.lim = lim;
    v.spatial = -1;
    *structure = NULL;
    canon = val_document(&v, root, structure);
    *nomem = v.nomem;
    return canon;
}
