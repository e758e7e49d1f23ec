/*
 * codec.c — JSON request validation, canonical form, result encoding.
 *
 * How it fits: the CLI (cli.c) and the daemon read a request with
 * codec_request_parse, build the core model with codec_model_new, call
 * sm_solve and write codec_result_encode (or codec_result_csv).  Every
 * failure on the way becomes a codec_errors list that codec_problem_* turns
 * into an RFC 9457 document.
 *
 * Validation walks the request once, in document order, and never stops at
 * the first error: each field is checked (type, range, references, unknown
 * keys), errors are appended with the JSON pointer of the field, and a
 * canonical copy of the request is built along the way with every default
 * written out.  Only when no error was found is the canonical copy turned
 * into the core's arrays.  Joints and sections are indexed in sorted name
 * order, so the canonical text (keys sorted) fully determines the model and
 * two requests with the same SHA-256 give the same result.
 *
 * Topology (cycles, disconnected members) is the core's job: sm_model_new
 * reports it in an sm_diag, which codec_diag_error maps back to a pointer.
 * The codec pre-checks only the cheap local cases (zero-length member, a
 * clamp that is no member's end) so those appear with the other errors.
 */
#include "codec_internal.h"

#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <openssl/evp.h>

/* Flags for dumping canonical text and results. */
#define CODEC_DUMP_CANON (JSON_SORT_KEYS | JSON_COMPACT | JSON_REAL_PRECISION(17))

/* ================================================================= field */

/* A user-supplied name shortened for messages (cut on a UTF-8 boundary). */
field_short field_short_name(const char *name)
{
    field_short out;
    size_t n = strlen(name), cut = 60;

    if (n <= cut) {
        memcpy(out.s, name, n + 1);
        return out;
    }
    while (cut > 0 && ((unsigned char)name[cut] & 0xC0) == 0x80)
        cut--;
    memcpy(out.s, name, cut);
    memcpy(out.s + cut, "...", 4);
    return out;
}

/* "an object", "a string", ... for "must be X, not Y" messages. */
const char *field_type_name(const json_t *x)
{
    switch (json_typeof(x)) {
    case JSON_OBJECT: return "an object";
    case JSON_ARRAY: return "an array";
    case JSON_STRING: return "a string";
    case JSON_INTEGER:
    case JSON_REAL: return "a number";
    case JSON_TRUE:
    case JSON_FALSE: return "a boolean";
    case JSON_NULL: return "null";
    }
    return "an unknown value";
}

/* Levenshtein distance, capped: returns > 2 for anything far or long. */
static int field_edit_distance(const char *a, const char *b)
{
    size_t na = strlen(a), nb = strlen(b), i, j;
    int row[65];

    if (na > 64 || nb > 64)
        return 99;
    for (j = 0; j <= nb; j++)
        row[j] = (int)j;
    for (i = 1; i <= na; i++) {
        int diag = row[0];
        row[0] = (int)i;
        for (j = 1; j <= nb; j++) {
            int up = row[j];
            int best = diag + (a[i - 1] != b[j - 1]);
            if (row[j - 1] + 1 < best)
                best = row[j - 1] + 1;
            if (up + 1 < best)
                best = up + 1;
            row[j] = best;
            diag = up;
        }
    }
    return row[nb];
}

void field_error(val_ctx *v, const char *ptr, const char *fmt, ...)
{
    va_list ap;

    if (!ptr) {
        v->nomem = 1;
        return;
    }
    va_start(ap, fmt);
    if (err_vadd(v->errs, ptr, fmt, ap))
        v->nomem = 1;
    va_end(ap);
}

/* Error at base/key. */
void field_error_key(val_ctx *v, const char *base, const char *key, const char *fmt, ...)
{
    va_list ap;
    char *p = err_ptr_key(base, key);

    if (!p) {
        v->nomem = 1;
        return;
    }
    va_start(ap, fmt);
    if (err_vadd(v->errs, p, fmt, ap))
        v->nomem = 1;
    va_end(ap);
    free(p);
}

/* Set canon[key] = value (stolen); records NOMEM. */
void field_set(val_ctx *v, json_t *canon, const char *key, json_t *value)
{
    if (!canon) {
        json_decref(value);
        return;
    }
    if (json_object_set_new(canon, key, value))
        v->nomem = 1;
}

/* Every key of obj must be one of allowed (NULL-terminated). */
void field_check_keys(val_ctx *v, const json_t *obj, const char *base,
                      const char *const *allowed, const char *what)
{
    const char *key;
    json_t *val;

    json_object_foreach((json_t *)obj, key, val) {
        const char *best = NULL;
        int i, found = 0, bestd = strlen(key) >= 5 ? 4 : 3; /* suggest below this distance */
        (void)val;
        for (i = 0; allowed[i]; i++) {
            int d;
            if (!strcmp(key, allowed[i])) {
                found = 1;
                break;
            }
            d = field_edit_distance(key, allowed[i]);
            if (d < bestd) {
                bestd = d;
                best = allowed[i];
            }
        }
        if (found)
            continue;
        if (best)
            field_error_key(v, base, key, "unknown %s key '%s' (did you mean '%s'?)", what,
                            field_short_name(key).s, best);
        else
            field_error_key(v, base, key, "unknown %s key '%s'", what,
                            field_short_name(key).s);
    }
}

/* Numeric value of an integer or real; 0 if x is not a number. */
int field_number(const json_t *x, double *d)
{
    if (json_is_integer(x)) {
        *d = (double)json_integer_value(x);
        return 1;
    }
    if (json_is_real(x)) {
        *d = json_real_value(x);
        return 1;
    }
    return 0;
}

/* Integer value of an integer or an integral real in [lo, hi]; 0 otherwise. */
static int field_integer(const json_t *x, long lo, long hi, long *out)
{
    double d;

    if (json_is_integer(x)) {
        json_int_t i = json_integer_value(x);
        if (i < lo || i > hi)
            return 0;
        *out = (long)i;
        return 1;
    }
    if (!json_is_real(x))
        return 0;
    d = json_real_value(x);
    if (!isfinite(d) || d != floor(d) || d < (double)lo || d > (double)hi ||
        d >= -(double)LONG_MIN) /* (long)d overflows from 2^63 on */
        return 0;
    *out = (long)d;
    return 1;
}

/* Check a real value x at ptr; 1 and *out when valid. */
int field_check_real(val_ctx *v, const json_t *x, const char *ptr,
                     enum field_real_kind kind, const char *unit, double *out)
{
    double d;

    if (!field_number(x, &d)) {
        field_error(v, ptr, "must be a number%s, not %s", unit, field_type_name(x));
        return 0;
    }
    if (!isfinite(d)) {
        field_error(v, ptr, "must be a finite number");
        return 0;
    }
    if (kind == FIELD_POSITIVE && !(d > 0)) {
        field_error(v, ptr, "must be a positive number%s, got %g", unit, d);
        return 0;
    }
    if (kind == FIELD_NONNEG && !(d >= 0)) {
        field_error(v, ptr, "must be a number >= 0%s, got %g", unit, d);
        return 0;
    }
    if (d == 0)
        d = 0.0; /* -0 and 0 are the same request */
    *out = d;
    return 1;
}

/* Real field obj[key]: required, checked, written to canon as a real. */
int field_real(val_ctx *v, const json_t *obj, const char *key, const char *base,
               json_t *canon, enum field_real_kind kind, const char *unit, double *out)
{
    const json_t *x = json_object_get(obj, key);
    char *ptr;
    double d = 0;
    int ok;

    if (!x) {
        field_error_key(v, base, key, "required field '%s' is missing", key);
        return 0;
    }
    ptr = err_ptr_key(base, key);
    if (!ptr) {
        v->nomem = 1;
        return 0;
    }
    ok = field_check_real(v, x, ptr, kind, unit, &d);
    free(ptr);
    if (!ok)
        return 0;
    field_set(v, canon, key, json_real(d));
    if (out)
        *out = d;
    return 1;
}

/*
 * Integer field obj[key] in [lo, hi] (hi from a limit when limit_name is set).
 * Absent: error when required, else canon gets def.
 */
int field_int(val_ctx *v, const json_t *obj, const char *key, const char *base,
              json_t *canon, int required, long def, long lo, long hi,
              const char *limit_name, long *out)
{
    const json_t *x = json_object_get(obj, key);
    long i;

    if (!x) {
        if (required) {
            field_error_key(v, base, key, "required field '%s' is missing", key);
            return 0;
        }
        field_set(v, canon, key, json_integer(def));
        if (out)
            *out = def;
        return 1;
    }
    if (!field_integer(x, lo, LONG_MAX, &i)) {
        double d;
        if (field_number(x, &d) && d >= (double)lo && isfinite(d) && d == floor(d))
            i = LONG_MAX; /* integral but huge: report as over the limit */
        else {
            field_error_key(v, base, key, "must be an integer >= %ld", lo);
            return 0;
        }
    }
    if (i > hi) {
        if (limit_name)
            field_error_key(v, base, key, "%s is too large: the limit is %ld", limit_name, hi);
        else
            field_error_key(v, base, key, "must be an integer between %ld and %ld", lo, hi);
        return 0;
    }
    field_set(v, canon, key, json_integer(i));
    if (out)
        *out = i;
    return 1;
}

/* Boolean field with a default. */
void field_bool(val_ctx *v, const json_t *obj, const char *key, const char *base,
                json_t *canon, int def)
{
    const json_t *x = json_object_get(obj, key);

    if (!x) {
        field_set(v, canon, key, json_boolean(def));
        return;
    }
    if (!json_is_boolean(x)) {
        field_error_key(v, base, key, "must be true or false, not %s", field_type_name(x));
        return;
    }
    field_set(v, canon, key, json_boolean(json_is_true(x)));
}

/* String field with one of choices (NULL-terminated) and a default. */
void field_enum(val_ctx *v, const json_t *obj, const char *key, const char *base,
                json_t *canon, const char *const *choices, const char *def)
{
    const json_t *x = json_object_get(obj, key);
    const char *s;
    int i;

    if (!x) {
        field_set(v, canon, key, json_string(def));
        return;
    }
    if (!json_is_string(x)) {
        field_error_key(v, base, key, "must be a string, not %s", field_type_name(x));
        return;
    }
    s = json_string_value(x);
    for (i = 0; choices[i]; i++) {
        if (!strcmp(s, choices[i])) {
            field_set(v, canon, key, json_string(s));
            return;
        }
    }
    field_error_key(v, base, key, "unknown value '%s'; expected '%s' or '%s'",
                    field_short_name(s).s, choices[0], choices[1]);
}

/* Required object field; NULL (with an error) when absent or not an object. */
const json_t *field_object(val_ctx *v, const json_t *obj, const char *key, const char *base)
{
    const json_t *x = json_object_get(obj, key);

    if (!x) {
        field_error_key(v, base, key, "required field '%s' is missing", key);
        return NULL;
    }
    if (!json_is_object(x)) {
        field_error_key(v, base, key, "must be an object, not %s", field_type_name(x));
        return NULL;
    }
    return x;
}

/* Reference obj[key] (string naming a key of names, if known). */
const char *field_ref(val_ctx *v, const json_t *obj, const char *key, const char *base,
                      json_t *canon, const json_t *names, const char *what)
{
    const json_t *x = json_object_get(obj, key);
    const char *s;

    if (!x) {
        field_error_key(v, base, key, "required field '%s' is missing", key);
        return NULL;
    }
    if (!json_is_string(x)) {
        field_error_key(v, base, key, "must be the name of a %s (a string), not %s", what,
                        field_type_name(x));
        return NULL;
    }
    s = json_string_value(x);
    if (names && !json_object_get(names, s)) {
        field_error_key(v, base, key, "unknown %s '%s'", what, field_short_name(s).s);
        return NULL;
    }
    field_set(v, canon, key, json_string(s));
    return names ? s : NULL;
}

/* ============================================================== validate */

/* Coordinates of joint `name` in the input joints object, if valid. */
static int val_joint_xy(const json_t *joints, const char *name, double xy[2])
{
    const json_t *j = joints ? json_object_get(joints, name) : NULL;

    if (!json_is_array(j) || json_array_size(j) != 2)
        return 0;
    if (!field_number(json_array_get(j, 0), &xy[0]) ||
        !field_number(json_array_get(j, 1), &xy[1]))
        return 0;
    return isfinite(xy[0]) && isfinite(xy[1]);
}

/* ---------------------------------------------------------- structure */

/* structure.joints: {"name": [x, y], ...}; returns the input object if usable. */
static const json_t *val_joints(val_ctx *v, const json_t *st, json_t *cst)
{
    static const char *base = "/structure/joints";
    const json_t *joints = field_object(v, st, "joints", "/structure");
    json_t *cj, *xy;
    const char *name;

    if (!joints)
        return NULL;
    if (json_object_size(joints) == 0) {
        field_error(v, base, "must name at least one joint");
        return NULL;
    }
    if (json_object_size(joints) > (size_t)v->lim->max_joints) {
        field_error(v, base, "too many joints (%zu): the limit is %d", json_object_size(joints),
                    v->lim->max_joints);
        return NULL;
    }
    cj = json_object();
    if (!cj)
        v->nomem = 1;
    json_object_foreach((json_t *)joints, name, xy) {
        char *p = err_ptr_key(base, name);
        double c[2];
        size_t k;
        json_t *arr;
        if (!p) {
            v->nomem = 1;
            break;
        }
        if (name[0] == '\0')
            field_error(v, p, "a joint name must not be empty");
        if (!json_is_array(xy) || json_array_size(xy) != 2) {
            if (json_is_array(xy))
                field_error(v, p, "must be [x, y] (2 numbers), got %zu value%s",
                            json_array_size(xy), json_array_size(xy) == 1 ? "" : "s");
            else
                field_error(v, p, "must be [x, y] (2 numbers), not %s", field_type_name(xy));
            free(p);
            continue;
        }
        for (k = 0; k < 2; k++) {
            char *pk = err_ptr_idx(p, k);
            if (!field_check_real(v, json_array_get(xy, k), pk ? pk : p, FIELD_FINITE, " (m)",
                                  &c[k]))
                c[k] = NAN;
            free(pk);
        }
        free(p);
        if (isfinite(c[0]) && isfinite(c[1])) {
            arr = json_pack("[f, f]", c[0], c[1]);
            if (cj && (!arr || json_object_set_new(cj, name, arr)))
                v->nomem = 1;
            else if (!cj)
                json_decref(arr);
        }
    }
    field_set(v, cst, "joints", cj);
    return joints;
}

/* structure.sections: {"name": {E, A, I, mass_per_length}, ...}. */
static const json_t *val_sections(val_ctx *v, const json_t *st, json_t *cst)
{
    static const char *const keys[] = {"E", "A", "I", "mass_per_length", NULL};
    static const char *const units[] = {" (Pa)", " (m^2)", " (m^4)", " (kg/m)"};
    static const char *base = "/structure/sections";
    const json_t *secs = field_object(v, st, "sections", "/structure");
    json_t *cs, *sec;
    const char *name;

    if (!secs)
        return NULL;
    if (json_object_size(secs) == 0) {
        field_error(v, base, "must define at least one section");
        return NULL;
    }
    if (json_object_size(secs) > (size_t)v->lim->max_sections) {
        field_error(v, base, "too many sections (%zu): the limit is %d", json_object_size(secs),
                    v->lim->max_sections);
        return NULL;
    }
    cs = json_object();
    if (!cs)
        v->nomem = 1;
    json_object_foreach((json_t *)secs, name, sec) {
        char *p = err_ptr_key(base, name);
        json_t *c;
        int k;
        if (!p) {
            v->nomem = 1;
            break;
        }
        if (name[0] == '\0')
            field_error(v, p, "a section name must not be empty");
        if (!json_is_object(sec)) {
            field_error(v, p, "must be an object {E, A, I, mass_per_length}, not %s",
                        field_type_name(sec));
            free(p);
            continue;
        }
        field_check_keys(v, sec, p, keys, "section");
        c = json_object();
        if (!c)
            v->nomem = 1;
        for (k = 0; keys[k]; k++)
            field_real(v, sec, keys[k], p, c, FIELD_POSITIVE, units[k], NULL);
        free(p);
        if (cs && c && json_object_set_new(cs, name, c))
            v->nomem = 1;
        else if (!cs)
            json_decref(c);
    }
    field_set(v, cst, "sections", cs);
    return secs;
}

/* Member i: {id, from, to, section, elements}; adds its elements to *total. */
static void val_member(val_ctx *v, const json_t *mem, size_t i, const json_t *joints,
                       const json_t *secs, json_t *cm, json_t *ids, json_t *ends,
                       int *ends_ok, long *total)
{
    static const char *const keys[] = {"id", "from", "to", "section", "elements", NULL};
    char *p = err_ptr_idx("/structure/members", i);
    const json_t *id;
    const char *from, *to;
    double a[2], b[2];
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
    if (!from || !to) {
        *ends_ok = 0;
    } else {
        if (json_object_set_new(ends, from, json_true()) ||
            json_object_set_new(ends, to, json_true()))
            v->nomem = 1;
        if (!strcmp(from, to))
            field_error_key(v, p, "to", "zero-length member: it starts and ends at joint '%s'",
                            field_short_name(to).s);
        else if (val_joint_xy(joints, from, a) && val_joint_xy(joints, to, b) && a[0] == b[0] &&
                 a[1] == b[1])
            field_error(v, p, "zero-length member: joints '%s' and '%s' are at the same position",
                        field_short_name(from).s, field_short_name(to).s);
    }
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
    if (json_array_size(mems) == 0) {
        field_error(v, base, "must list at least one member");
        return;
    }
    if (json_array_size(mems) > (size_t)v->lim->max_members) {
        field_error(v, base, "too many members (%zu): the limit is %d", json_array_size(mems),
                    v->lim->max_members);
        return;
    }
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

/* structure.point_masses: optional array of {joint, mass}. */
static void val_point_masses(val_ctx *v, const json_t *st, const json_t *joints, json_t *cst)
{
    static const char *const keys[] = {"joint", "mass", NULL};
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
    if (json_array_size(pms) > (size_t)v->lim->max_point_masses) {
        field_error(v, base, "too many point masses (%zu): the limit is %d", json_array_size(pms),
                    v->lim->max_point_masses);
        return;
    }
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

/* The structure object. */
static void val_structure(val_ctx *v, const json_t *root, json_t *canon)
{
    static const char *const keys[] = {"joints", "sections", "members", "point_masses",
                                       "clamp", NULL};
    const json_t *st = field_object(v, root, "structure", "");
    const json_t *joints, *secs, *clamp;
    json_t *cst, *ends;
    int ends_ok = 0;

    if (!st)
        return;
    field_check_keys(v, st, "/structure", keys, "structure");
    cst = json_object();
    ends = json_object();
    if (!cst || !ends)
        v->nomem = 1;
    joints = val_joints(v, st, cst);
    secs = val_sections(v, st, cst);
    if (ends)
        val_members(v, st, joints, secs, cst, ends, &ends_ok);
    val_point_masses(v, st, joints, cst);
    if (ends_ok)
        val_unused_joints(v, joints, ends);
    clamp = json_object_get(st, "clamp");
    if (clamp && json_is_string(clamp) && joints &&
        json_object_get(joints, json_string_value(clamp)) && ends_ok &&
        !json_object_get(ends, json_string_value(clamp)))
        field_error(v, "/structure/clamp", "joint '%s' is not an end of any member",
                    field_short_name(json_string_value(clamp)).s);
    field_ref(v, st, "clamp", "/structure", cst, joints, "joint");
    json_decref(ends);
    field_set(v, canon, "structure", cst);
}

/* ----------------------------------------------------- frames, analysis */

static void val_frames(val_ctx *v, const json_t *root, json_t *canon)
{
    static const char *const keys[] = {"per_member", "elements_per_frame", NULL};
    const json_t *f = json_object_get(root, "frames");
    json_t *c;
    int nk;

    if (!f) {
        field_set(v, canon, "frames", json_string("per_element"));
        return;
    }
    if (json_is_string(f)) {
        const char *s = json_string_value(f);
        if (!strcmp(s, "single") || !strcmp(s, "per_element"))
            field_set(v, canon, "frames", json_string(s));
        else
            field_error(v, "/frames", "unknown frame scheme '%s'; expected \"single\", "
                        "\"per_element\", {\"per_member\": k} or {\"elements_per_frame\": n}",
                        field_short_name(s).s);
        return;
    }
    if (!json_is_object(f)) {
        field_error(v, "/frames", "must be \"single\", \"per_element\", {\"per_member\": k} or "
                    "{\"elements_per_frame\": n}, not %s", field_type_name(f));
        return;
    }
    field_check_keys(v, f, "/frames", keys, "frames");
    nk = (json_object_get(f, "per_member") != NULL) +
         (json_object_get(f, "elements_per_frame") != NULL);
    if (nk != 1) {
        field_error(v, "/frames",
                    "must have exactly one of 'per_member' and 'elements_per_frame'");
        return;
    }
    c = json_object();
    if (!c) {
        v->nomem = 1;
        return;
    }
    field_int(v, f, json_object_get(f, "per_member") ? "per_member" : "elements_per_frame",
              "/frames", c, 1, 0, 1, v->lim->max_elements, NULL, NULL);
    field_set(v, canon, "frames", c);
}

/* analysis.omega: a number or a non-empty array of numbers, finite, >= 0. */
static void val_omega(val_ctx *v, const json_t *an, json_t *can)
{
    static const char *base = "/analysis/omega";
    const json_t *om = json_object_get(an, "omega");
    json_t *arr, *x;
    size_t i;
    double d;

    if (!om) {
        field_error(v, base, "required field 'omega' (the speed in rad/s, or an array of speeds) "
                    "is missing");
        return;
    }
    if (json_is_number(om)) {
        if (field_check_real(v, om, base, FIELD_NONNEG, " (rad/s)", &d))
            field_set(v, can, "omega", json_real(d));
        return;
    }
    if (!json_is_array(om)) {
        field_error(v, base, "must be a number (rad/s) or an array of numbers, not %s",
                    field_type_name(om));
        return;
    }
    if (json_array_size(om) == 0) {
        field_error(v, base, "must list at least one speed");
        return;
    }
    if (json_array_size(om) > (size_t)v->lim->max_speeds) {
        field_error(v, base, "too many speeds (%zu): the limit is %d", json_array_size(om),
                    v->lim->max_speeds);
        return;
    }
    arr = json_array();
    if (!arr) {
        v->nomem = 1;
        return;
    }
    json_array_foreach(om, i, x) {
        char *p = err_ptr_idx(base, i);
        if (!p) {
            v->nomem = 1;
            break;
        }
        if (field_check_real(v, x, p, FIELD_NONNEG, " (rad/s)", &d) &&
            json_array_append_new(arr, json_real(d)))
            v->nomem = 1;
        free(p);
    }
    field_set(v, can, "omega", arr);
}

static void val_analysis(val_ctx *v, const json_t *root, json_t *canon)
{
    static const char *const keys[] = {"omega", "modes", "geometric_stiffening", "coriolis",
                                       "mass", "substructure_modes", "modes_per_frame",
                                       "mode_shapes", NULL};
    static const char *const mass[] = {"lumped", "consistent", NULL};
    static const char *const basis[] = {"augmented", "paper", NULL};
    static const char *base = "/analysis";
    const json_t *an = field_object(v, root, "analysis", "");
    const json_t *mpf;
    json_t *can;

    if (!an)
        return;
    field_check_keys(v, an, base, keys, "analysis");
    can = json_object();
    if (!can)
        v->nomem = 1;
    val_omega(v, an, can);
    field_int(v, an, "modes", base, can, 0, 3, 1, v->lim->max_modes, "the number of modes",
              NULL);
    field_bool(v, an, "geometric_stiffening", base, can, 1);
    field_bool(v, an, "coriolis", base, can, 1);
    field_enum(v, an, "mass", base, can, mass, "lumped");
    field_enum(v, an, "substructure_modes", base, can, basis, "augmented");
    mpf = json_object_get(an, "modes_per_frame");
    if (!mpf || (json_is_string(mpf) && !strcmp(json_string_value(mpf), "all")))
        field_set(v, can, "modes_per_frame", json_string("all"));
    else if (json_is_number(mpf))
        field_int(v, an, "modes_per_frame", base, can, 1, 0, 1, 100000, NULL, NULL);
    else
        field_error(v, "/analysis/modes_per_frame",
                    "must be \"all\" or a positive integer, not %s",
                    json_is_string(mpf) ? "another string" : field_type_name(mpf));
    field_bool(v, an, "mode_shapes", base, can, 1);
    field_set(v, canon, "analysis", can);
}

/*
 * Size of the mode shapes in the result: speeds x modes x nodes x 3
 * (x 2 with Coriolis: complex shapes) against max_shape_values.
 */
static void val_output_size(val_ctx *v, const json_t *canon)
{
    const json_t *an = json_object_get(canon, "analysis");
    const json_t *om = json_object_get(an, "omega");
    double speeds = json_is_array(om) ? (double)json_array_size(om) : 1;
    double modes = (double)json_integer_value(json_object_get(an, "modes"));
    double nodes = (double)v->total_elements + 1; /* a tree of elements */
    double values = speeds * modes * nodes * 3 *
                    (json_is_true(json_object_get(an, "coriolis")) ? 2 : 1);

    if (!json_is_true(json_object_get(an, "mode_shapes")) || !(values > v->lim->max_shape_values))
        return;
    field_error(v, "/analysis/mode_shapes",
                "mode shapes for %.0f speeds x %.0f modes x %.0f nodes "
                "would be %.0f numbers: the limit is %ld; set mode_shapes to false or ask for "
                "fewer speeds or modes", speeds, modes, nodes, values, v->lim->max_shape_values);
}

/* Validate root; returns the canonical request (new) or NULL. */
static json_t *val_document(val_ctx *v, const json_t *root)
{
    static const char *const keys[] = {"structure", "frames", "analysis", NULL};
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
    val_structure(v, root, canon);
    val_frames(v, root, canon);
    val_analysis(v, root, canon);
    if (json_object_get(canon, "analysis") && json_object_get(canon, "structure"))
        val_output_size(v, canon);
    return canon;
}

json_t *val_request(const json_t *root, const codec_limits *lim, codec_errors *errs,
                    int *nomem)
{
    val_ctx v;
    json_t *canon;

    v.errs = errs;
    v.lim = lim;
    v.total_elements = 0;
    v.nomem = 0;
    canon = val_document(&v, root);
    *nomem = v.nomem;
    return canon;
}

/* =============================================================== request */

struct codec_request {
    json_t *canon;              /* canonical request, defaults applied */
    char *canon_text;           /* its sorted compact dump */
    char sha[65];               /* SHA-256 of canon_text, hex */
    const char **joint_names;   /* n_joints, sorted, borrowed from canon */
    const char **section_names; /* n_sections, sorted, borrowed from canon */
    double *joint_xy;           /* 2*n_joints */
    sm_section *sections;       /* n_sections */
    sm_member *members;         /* n_members */
    sm_point_mass *point_masses;/* n_point_masses (NULL if 0) */
    double *speeds;             /* n_speeds, request order */
    int n_speeds;
    sm_structure st;            /* points into the arrays above */
    sm_options opt;             /* from the analysis and frames fields */
};

static int req_cmp_str(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* Sorted key list of obj (borrowed keys); NULL = NOMEM. */
static const char **req_sorted_keys(const json_t *obj, int *n)
{
    size_t k = 0, cnt = json_object_size(obj);
    const char **names = calloc(cnt ? cnt : 1, sizeof(*names));
    const char *key;
    json_t *val;

    if (!names)
        return NULL;
    json_object_foreach((json_t *)obj, key, val) {
        (void)val;
        names[k++] = key;
    }
    qsort(names, cnt, sizeof(*names), req_cmp_str);
    *n = (int)cnt;
    return names;
}

static int req_name_index(const char **names, int n, const char *name)
{
    const char **hit = bsearch(&name, names, (size_t)n, sizeof(*names), req_cmp_str);
    return hit ? (int)(hit - names) : -1;
}

static double req_number(const json_t *x)
{
    double d = 0;
    field_number(x, &d);
    return d;
}

/* Joints and sections arrays, sorted by name. */
static int req_build_tables(codec_request *r)
{
    const json_t *st = json_object_get(r->canon, "structure");
    const json_t *joints = json_object_get(st, "joints");
    const json_t *secs = json_object_get(st, "sections");
    int i, nj = 0, ns = 0;

    r->joint_names = req_sorted_keys(joints, &nj);
    r->section_names = req_sorted_keys(secs, &ns);
    if (!r->joint_names || !r->section_names)
        return SM_NOMEM;
    r->joint_xy = malloc(2 * (size_t)nj * sizeof(double));
    r->sections = malloc((size_t)(ns ? ns : 1) * sizeof(sm_section));
    if (!r->joint_xy || !r->sections)
        return SM_NOMEM;
    for (i = 0; i < nj; i++) {
        const json_t *xy = json_object_get(joints, r->joint_names[i]);
        r->joint_xy[2 * i] = req_number(json_array_get(xy, 0));
        r->joint_xy[2 * i + 1] = req_number(json_array_get(xy, 1));
    }
    for (i = 0; i < ns; i++) {
        const json_t *s = json_object_get(secs, r->section_names[i]);
        r->sections[i].E = req_number(json_object_get(s, "E"));
        r->sections[i].A = req_number(json_object_get(s, "A"));
        r->sections[i].I = req_number(json_object_get(s, "I"));
        r->sections[i].mu = req_number(json_object_get(s, "mass_per_length"));
    }
    r->st.n_joints = nj;
    r->st.joint_xy = r->joint_xy;
    r->st.n_sections = ns;
    r->st.sections = r->sections;
    return SM_OK;
}

/* Members, point masses and clamp as indices. */
static int req_build_structure(codec_request *r)
{
    const json_t *st = json_object_get(r->canon, "structure");
    const json_t *mems = json_object_get(st, "members");
    const json_t *pms = json_object_get(st, "point_masses");
    const json_t *x;
    size_t i, nm = json_array_size(mems), np = json_array_size(pms);
    int nj = r->st.n_joints, ns = r->st.n_sections;

    r->members = malloc((nm ? nm : 1) * sizeof(sm_member));
    r->point_masses = np ? malloc(np * sizeof(sm_point_mass)) : NULL;
    if (!r->members || (np && !r->point_masses))
        return SM_NOMEM;
    json_array_foreach(mems, i, x) {
        r->members[i].from = req_name_index(r->joint_names, nj,
                                            json_string_value(json_object_get(x, "from")));
        r->members[i].to = req_name_index(r->joint_names, nj,
                                          json_string_value(json_object_get(x, "to")));
        r->members[i].section = req_name_index(r->section_names, ns,
                                               json_string_value(json_object_get(x, "section")));
        r->members[i].elements = (int)json_integer_value(json_object_get(x, "elements"));
    }
    json_array_foreach(pms, i, x) {
        r->point_masses[i].joint = req_name_index(r->joint_names, nj,
                                                  json_string_value(json_object_get(x, "joint")));
        r->point_masses[i].mass = req_number(json_object_get(x, "mass"));
    }
    r->st.n_members = (int)nm;
    r->st.members = r->members;
    r->st.n_point_masses = (int)np;
    r->st.point_masses = r->point_masses;
    r->st.clamp = req_name_index(r->joint_names, nj,
                                 json_string_value(json_object_get(st, "clamp")));
    return SM_OK;
}

/* sm_options and speeds from frames and analysis. */
static int req_build_options(codec_request *r)
{
    const json_t *an = json_object_get(r->canon, "analysis");
    const json_t *fr = json_object_get(r->canon, "frames");
    const json_t *om = json_object_get(an, "omega");
    const json_t *mpf = json_object_get(an, "modes_per_frame");
    size_t i, n = json_is_array(om) ? json_array_size(om) : 1;

    sm_default_options(&r->opt);
    if (json_is_string(fr)) {
        r->opt.frames = !strcmp(json_string_value(fr), "single") ? SM_FRAMES_SINGLE
                                                                 : SM_FRAMES_PER_ELEMENT;
        r->opt.frames_param = 0;
    } else if (json_object_get(fr, "per_member")) {
        r->opt.frames = SM_FRAMES_PER_MEMBER;
        r->opt.frames_param = (int)json_integer_value(json_object_get(fr, "per_member"));
    } else {
        r->opt.frames = SM_FRAMES_ELEMENTS_PER_FRAME;
        r->opt.frames_param = (int)json_integer_value(json_object_get(fr, "elements_per_frame"));
    }
    r->opt.mass = !strcmp(json_string_value(json_object_get(an, "mass")), "consistent")
                      ? SM_MASS_CONSISTENT : SM_MASS_LUMPED;
    r->opt.basis = !strcmp(json_string_value(json_object_get(an, "substructure_modes")),
                           "paper") ? SM_BASIS_PAPER : SM_BASIS_AUGMENTED;
    r->opt.modes_per_frame = json_is_integer(mpf) ? (int)json_integer_value(mpf) : 0;
    r->opt.modes = (int)json_integer_value(json_object_get(an, "modes"));
    r->opt.geometric_stiffening = json_is_true(json_object_get(an, "geometric_stiffening"));
    r->opt.coriolis = json_is_true(json_object_get(an, "coriolis"));
    r->opt.mode_shapes = json_is_true(json_object_get(an, "mode_shapes"));

    r->speeds = malloc(n * sizeof(double));
    if (!r->speeds)
        return SM_NOMEM;
    for (i = 0; i < n; i++)
        r->speeds[i] = req_number(json_is_array(om) ? json_array_get(om, i) : om);
    r->n_speeds = (int)n;
    return SM_OK;
}

int codec_sha256_hex(const void *data, size_t len, char hex[65])
{
    static const char digits[] = "0123456789abcdef";
    unsigned char md[EVP_MAX_MD_SIZE];
    unsigned int n = 0, i;

    hex[0] = '\0';
    if (!EVP_Digest(data, len, md, &n, EVP_sha256(), NULL) || n != 32)
        return SM_NOMEM;
    for (i = 0; i < n; i++) {
        hex[2 * i] = digits[md[i] >> 4];
        hex[2 * i + 1] = digits[md[i] & 15];
    }
    hex[64] = '\0';
    return SM_OK;
}

int codec_request_from_json(codec_request **out, const json_t *root,
                            const codec_limits *lim, codec_errors *errs)
{
    codec_limits deflim;
    codec_request *r = NULL;
    json_t *canon;
    int rc = SM_NOMEM, before = codec_errors_count(errs), nomem;

    *out = NULL;
    if (!lim) {
        codec_default_limits(&deflim);
        lim = &deflim;
    }
    canon = val_request(root, lim, errs, &nomem);
    if (nomem)
        goto fail;
    if (codec_errors_count(errs) > before || !canon) {
        rc = SM_INVALID_INPUT;
        goto fail;
    }
    r = calloc(1, sizeof(*r));
    if (!r)
        goto fail;
    r->canon = canon;
    canon = NULL;
    r->canon_text = json_dumps(r->canon, CODEC_DUMP_CANON);
    if (!r->canon_text)
        goto fail;
    if ((rc = codec_sha256_hex(r->canon_text, strlen(r->canon_text), r->sha)) ||
        (rc = req_build_tables(r)) || (rc = req_build_structure(r)) ||
        (rc = req_build_options(r)))
        goto fail;
    *out = r;
    return SM_OK;
fail:
    json_decref(canon);
    codec_request_free(r);
    return rc;
}

int codec_request_parse(codec_request **out, const char *text, size_t len,
                        const codec_limits *lim, codec_errors *errs)
{
    codec_limits deflim;
    json_error_t jerr;
    json_t *root;
    int rc;

    *out = NULL;
    if (!lim) {
        codec_default_limits(&deflim);
        lim = &deflim;
    }
    if (len > lim->max_request_bytes) {
        err_mark_too_large(errs);
        if (codec_errors_add(errs, "", "the request is %zu bytes: the limit is %zu bytes",
                             len, lim->max_request_bytes))
            return SM_NOMEM;
        return SM_INVALID_INPUT;
    }
    root = json_loadb(text, len, JSON_REJECT_DUPLICATES, &jerr);
    if (!root) {
        err_mark_malformed(errs);
        for (size_t k = 0; jerr.text[k]; k++) /* jansson's "near '...'" may cut a UTF-8 char */
            if ((unsigned char)jerr.text[k] >= 0x80)
                jerr.text[k] = '?';
        if (json_error_code(&jerr) == json_error_out_of_memory)
            return SM_NOMEM;
        if (codec_errors_add(errs, "", "not valid JSON: %s (line %d, column %d)", jerr.text,
                             jerr.line, jerr.column))
            return SM_NOMEM;
        return SM_INVALID_INPUT;
    }
    rc = codec_request_from_json(out, root, lim, errs);
    json_decref(root);
    return rc;
}

void codec_request_free(codec_request *r)
{
    if (!r)
        return;
    free(r->speeds);
    free(r->point_masses);
    free(r->members);
    free(r->sections);
    free(r->joint_xy);
    free(r->section_names);
    free(r->joint_names);
    free(r->canon_text);
    json_decref(r->canon);
    free(r);
}

const sm_structure *codec_request_structure(const codec_request *r)
{
    return &r->st;
}

const sm_options *codec_request_options(const codec_request *r)
{
    return &r->opt;
}

const double *codec_request_speeds(const codec_request *r, int *n)
{
    *n = r->n_speeds;
    return r->speeds;
}

const char *codec_request_joint_name(const codec_request *r, int j)
{
    if (j < 0 || j >= r->st.n_joints)
        return NULL;
    return r->joint_names[j];
}

const char *req_section_name(const codec_request *r, int s)
{
    if (s < 0 || s >= r->st.n_sections)
        return NULL;
    return r->section_names[s];
}

const json_t *codec_request_canonical(const codec_request *r)
{
    return r->canon;
}

const char *codec_request_canonical_text(const codec_request *r)
{
    return r->canon_text;
}

const char *codec_request_sha256(const codec_request *r)
{
    return r->sha;
}

/* ================================================================== diag */

/* Request field name of a core field name (mu -> mass_per_length ...). */
static const char *diag_field_name(const char *f)
{
    if (!strcmp(f, "mu"))
        return "mass_per_length";
    if (!strcmp(f, "basis"))
        return "substructure_modes";
    if (!strcmp(f, "omegas"))
        return "omega";
    return f;
}

/* 1 when f is one of the NULL-terminated names. */
static int diag_among(const char *f, const char *const *names)
{
    int i;

    for (i = 0; names[i]; i++)
        if (!strcmp(f, names[i]))
            return 1;
    return 0;
}

static int diag_is_section_field(const char *f)
{
    return !strcmp(f, "E") || !strcmp(f, "A") || !strcmp(f, "I") || !strcmp(f, "mu") ||
           !strcmp(f, "mass_per_length");
}

/* Pointer of an option field reported by the core. */
static char *diag_options_pointer(const codec_request *r, const char *f, int index)
{
    const json_t *canon = codec_request_canonical(r);
    const json_t *fr = json_object_get(canon, "frames");
    const json_t *om = json_object_get(json_object_get(canon, "analysis"), "omega");

    if ((!strcmp(f, "omega") || !strcmp(f, "omegas")) && json_is_array(om) && index >= 0 &&
        (size_t)index < json_array_size(om))
        return err_fmt("/analysis/omega/%d", index);

    if (!strcmp(f, "frames") || !strcmp(f, "frames_param") || !strcmp(f, "per_member") ||
        !strcmp(f, "elements_per_frame")) {
        if (json_is_object(fr) && strcmp(f, "frames")) {
            const char *key = json_object_get(fr, "per_member") ? "per_member"
                                                                : "elements_per_frame";
            return err_fmt("/frames/%s", key);
        }
        return strdup("/frames");
    }
    if (f[0] == '\0')
        return strdup("/analysis");
    return err_ptr_key("/analysis", diag_field_name(f));
}

/* Pointer of the item a diagnostic names; malloc'd, NULL = NOMEM. */
static char *diag_pointer(const codec_request *r, const sm_diag *d)
{
    const sm_structure *st = codec_request_structure(r);
    const char *f = d->field;
    int i = d->item_index;
    char *base, *p;

    static const char *const member_fields[] = {"id", "from", "to", "section", "elements",
                                                NULL};
    static const char *const pm_fields[] = {"joint", "mass", NULL};
    static const char *const no_fields[] = {NULL};
    const char *const *known = no_fields;

    switch (d->item) {
    case SM_ITEM_MEMBER:
        if (i < 0 || i >= st->n_members)
            return strdup("/structure/members");
        if (diag_is_section_field(f) && st->members[i].section >= 0 &&
            st->members[i].section < st->n_sections) {
            base = err_ptr_key("/structure/sections",
                               req_section_name(r, st->members[i].section));
            known = NULL;
            break;
        }
        base = err_ptr_idx("/structure/members", (size_t)i);
        known = member_fields;
        break;
    case SM_ITEM_JOINT:
        if (i < 0 || i >= st->n_joints)
            return strdup("/structure/joints");
        base = err_ptr_key("/structure/joints", codec_request_joint_name(r, i));
        if (base && (!strcmp(f, "x") || !strcmp(f, "y"))) {
            p = err_fmt("%s/%d", base, f[0] == 'y');
            free(base);
            return p;
        }
        return base;
    case SM_ITEM_SECTION:
        if (i < 0 || i >= st->n_sections)
            return strdup("/structure/sections");
        base = err_ptr_key("/structure/sections", req_section_name(r, i));
        known = NULL;
        break;
    case SM_ITEM_POINT_MASS:
        if (i < 0 || i >= st->n_point_masses)
            return strdup("/structure/point_masses");
        base = err_ptr_idx("/structure/point_masses", (size_t)i);
        known = pm_fields;
        break;
    case SM_ITEM_CLAMP:
        return strdup("/structure/clamp");
    case SM_ITEM_OPTIONS:
        return diag_options_pointer(r, f, i);
    case SM_ITEM_NONE:
    default:
        return strdup("/structure");
    }
    /* a field the request does not have: point at the item itself */
    if (!base || f[0] == '\0' || (known ? !diag_among(f, known) : !diag_is_section_field(f)))
        return base;
    p = err_ptr_key(base, diag_field_name(f));
    free(base);
    return p;
}

int codec_diag_error(const codec_request *r, const sm_diag *d, codec_errors *errs)
{
    char *p = diag_pointer(r, d);
    int rc;

    if (!p) {
        err_mark_nomem(errs);
        return SM_NOMEM;
    }
    rc = codec_errors_add(errs, p, "%s", d->message[0] ? d->message : sm_strerror(d->status));
    free(p);
    return rc;
}

int codec_model_new(sm_model **out, const codec_request *r, codec_errors *errs,
                    sm_diag *diag)
{
    sm_diag local;
    sm_diag *d = diag ? diag : &local;
    int rc;

    memset(d, 0, sizeof(*d));
    d->item_index = -1;
    *out = NULL;
    rc = sm_model_new(out, codec_request_structure(r), codec_request_options(r), d);
    if (rc == SM_OK)
        return SM_OK;
    *out = NULL;
    if (d->status == SM_OK)
        d->status = rc;
    if (rc != SM_NOMEM && codec_diag_error(r, d, errs))
        return SM_NOMEM;
    return rc;
}

/* ================================================================ result */

const char *codec_case_status_name(sm_case_status s)
{
    switch (s) {
    case SM_CASE_SOLVED: return "solved";
    case SM_CASE_UNSTABLE: return "unstable";
    case SM_CASE_NO_EQUILIBRIUM: return "no_equilibrium";
    }
    return "unknown";
}

/* A real, or null when not finite (JSON has no NaN or infinity). */
static json_t *res_real(double x)
{
    return isfinite(x) ? json_real(x) : json_null();
}

/* [a, b, c] from three reals. */
static json_t *res_triple(const double *v)
{
    json_t *a = json_array();

    if (!a)
        return NULL;
    if (json_array_append_new(a, res_real(v[0])) || json_array_append_new(a, res_real(v[1])) ||
        json_array_append_new(a, res_real(v[2]))) {
        json_decref(a);
        return NULL;
    }
    return a;
}

/* [[x, y, z], ...] from n triples. */
static json_t *res_triples(const double *v, int n)
{
    json_t *a = json_array();
    int k;

    if (!a)
        return NULL;
    for (k = 0; k < n; k++)
        if (json_array_append_new(a, res_triple(v + 3 * (size_t)k)))
            goto fail;
    return a;
fail:
    json_decref(a);
    return NULL;
}

static json_t *res_reals(const double *v, int n)
{
    json_t *a = json_array();
    int k;

    if (!a)
        return NULL;
    for (k = 0; k < n; k++)
        if (json_array_append_new(a, res_real(v[k])))
            goto fail;
    return a;
fail:
    json_decref(a);
    return NULL;
}

/* case.equilibrium */
static json_t *res_equilibrium(const codec_request *r, const sm_model *m, const sm_case *c)
{
    json_t *e = json_object(), *joints = NULL;
    int j, nj = codec_request_structure(r)->n_joints;

    if (!e)
        return NULL;
    if (json_object_set_new(e, "converged", json_boolean(c->converged)) ||
        json_object_set_new(e, "iterations", json_integer(c->iterations)) ||
        json_object_set_new(e, "residual", res_real(c->residual)))
        goto fail;
    if (c->nodes && c->n_nodes > 0) {
        joints = json_object();
        if (!joints)
            goto fail;
        for (j = 0; j < nj; j++) {
            int node = sm_model_joint_node(m, j);
            if (node < 0 || node >= c->n_nodes)
                continue;
            if (json_object_set_new(joints, codec_request_joint_name(r, j),
                                    res_triple(c->nodes + 3 * (size_t)node)))
                goto fail;
        }
        if (json_object_set_new(e, "joints", joints))
            goto fail_set;
        joints = NULL;
        if (json_object_set_new(e, "nodes", res_triples(c->nodes, c->n_nodes)))
            goto fail;
    }
    if (c->axial_force && c->n_elements > 0 &&
        json_object_set_new(e, "axial_force", res_reals(c->axial_force, c->n_elements)))
        goto fail;
    if (c->nodes && c->n_nodes > 0 &&
        json_object_set_new(e, "max_frame_rotation", res_real(c->max_frame_rotation)))
        goto fail;
    return e;
fail:
    json_decref(joints);
fail_set:
    json_decref(e);
    return NULL;
}

/* One mode of a case. */
static json_t *res_mode(const sm_case *c, int k, int shapes)
{
    size_t stride = 3 * (size_t)c->n_nodes;
    json_t *md = json_object(), *shape;
    double mac = c->mac_to_previous ? c->mac_to_previous[k] : -1;
    int prev = c->previous_index ? c->previous_index[k] : -1;

    if (!md)
        return NULL;
    if (json_object_set_new(md, "frequency_rad_s", res_real(c->frequency[k])) ||
        json_object_set_new(md, "frequency_hz", res_real(c->frequency[k] / CODEC_TWO_PI)) ||
        json_object_set_new(md, "eigenvalue", json_pack("[o, o]", res_real(c->eig_re[k]),
                                                        res_real(c->eig_im[k]))) ||
        json_object_set_new(md, "mac_to_previous", mac < 0 ? json_null() : res_real(mac)) ||
        json_object_set_new(md, "previous_index", prev < 0 ? json_null() : json_integer(prev)))
        goto fail;
    if (shapes && c->shape_re) {
        shape = json_object();
        if (json_object_set_new(md, "shape", shape))
            goto fail;
        if (json_object_set_new(shape, "re", res_triples(c->shape_re + k * stride, c->n_nodes)))
            goto fail;
        if (c->shape_im &&
            json_object_set_new(shape, "im", res_triples(c->shape_im + k * stride, c->n_nodes)))
            goto fail;
    }
    return md;
fail:
    json_decref(md);
    return NULL;
}

/* One case (speed). */
static json_t *res_case(const codec_request *r, const sm_model *m, const sm_case *c)
{
    json_t *o = json_object(), *modes;
    int k, shapes = codec_request_options(r)->mode_shapes;

    if (!o)
        return NULL;
    if (json_object_set_new(o, "omega", res_real(c->omega)) ||
        json_object_set_new(o, "status", json_string(codec_case_status_name(c->status))) ||
        json_object_set_new(o, "equilibrium", res_equilibrium(r, m, c)))
        goto fail;
    if (c->status != SM_CASE_NO_EQUILIBRIUM &&
        json_object_set_new(o, "stability",
                            json_pack("{s:b, s:i}", "stable", c->stable,
                                      "negative_eigenvalues", c->negative_eigenvalues)))
        goto fail;
    modes = json_array();
    if (json_object_set_new(o, "modes", modes))
        goto fail;
    for (k = 0; k < c->n_modes; k++)
        if (json_array_append_new(modes, res_mode(c, k, shapes)))
            goto fail;
    if (c->warning[0] &&
        json_object_set_new(o, "warnings", json_pack("[s]", c->warning)))
        goto fail;
    if (c->status != SM_CASE_SOLVED &&
        json_object_set_new(o, "diagnostics",
                            json_pack("{s:i, s:o, s:o, s:s}", "iterations", c->iterations,
                                      "residual", res_real(c->residual), "last_omega",
                                      res_real(c->last_omega), "message",
                                      c->message[0] ? c->message
                                                    : codec_case_status_name(c->status))))
        goto fail;
    return o;
fail:
    json_decref(o);
    return NULL;
}

int codec_result_encode(json_t **out, const codec_request *r, const sm_model *m,
                        const sm_result *res)
{
    json_t *doc = NULL, *cases;
    sm_model_info info;
    double te = 0, tl = 0, tg = 0;
    int i;

    *out = NULL;
    sm_model_get_info(m, &info);
    doc = json_object();
    if (!doc)
        goto fail;
    if (json_object_set_new(doc, "solver",
                            json_pack("{s:s, s:s, s:s}", "name", "spinmodal", "version",
                                      SM_VERSION, "request_sha256", codec_request_sha256(r))) ||
        json_object_set_new(doc, "model",
                            json_pack("{s:i, s:i, s:i, s:i}", "nodes", info.nodes,
                                      "elements", info.elements, "frames", info.frames,
                                      "coordinates", info.coordinates)))
        goto fail;
    cases = json_array();
    if (json_object_set_new(doc, "cases", cases))
        goto fail;
    for (i = 0; i < res->n_cases; i++) {
        const sm_case *c = &res->cases[i];
        if (json_array_append_new(cases, res_case(r, m, c)))
            goto fail;
        te += c->t_equilibrium;
        tl += c->t_linearize;
        tg += c->t_eigen;
    }
    if (json_object_set_new(doc, "timing_ms",
                            json_pack("{s:o, s:o, s:o}", "equilibrium", res_real(te),
                                      "linearize", res_real(tl), "eigen", res_real(tg))))
        goto fail;
    *out = doc;
    return SM_OK;
fail:
    json_decref(doc);
    return SM_NOMEM;
}

/* =================================================================== csv */

/* A CSV number: full precision, empty when not finite. */
static void csv_num(FILE *f, double x)
{
    if (isfinite(x))
        fprintf(f, "%.17g", x);
}

int codec_result_csv(char **out, size_t *len, const sm_result *res)
{
    char *buf = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&buf, &n);
    int i, k;

    *out = NULL;
    if (!f)
        return SM_NOMEM;
    fputs("omega,mode,frequency_rad_s,frequency_hz,eig_re,eig_im,mac_to_previous,status\n", f);
    for (i = 0; i < res->n_cases; i++) {
        const sm_case *c = &res->cases[i];
        const char *st = codec_case_status_name(c->status);
        if (c->n_modes == 0) {
            csv_num(f, c->omega);
            fprintf(f, ",,,,,,,%s\n", st);
        }
        for (k = 0; k < c->n_modes; k++) {
            double mac = c->mac_to_previous ? c->mac_to_previous[k] : -1;
            csv_num(f, c->omega);
            fprintf(f, ",%d,", k + 1);
            csv_num(f, c->frequency[k]);
            fputc(',', f);
            csv_num(f, c->frequency[k] / CODEC_TWO_PI);
            fputc(',', f);
            csv_num(f, c->eig_re[k]);
            fputc(',', f);
            csv_num(f, c->eig_im[k]);
            fputc(',', f);
            if (mac >= 0)
                csv_num(f, mac);
            fprintf(f, ",%s\n", st);
        }
    }
    if (ferror(f)) {
        fclose(f);
        free(buf);
        return SM_NOMEM;
    }
    if (fclose(f)) {
        free(buf);
        return SM_NOMEM;
    }
    *out = buf;
    if (len)
        *len = n;
    return SM_OK;
}

/* =============================================================== problem */

json_t *codec_problem_new(int http_status, const char *type, const char *title,
                          const char *detail, const codec_errors *errs)
{
    json_t *p = json_pack("{s:s, s:s, s:i}", "type", type ? type : "about:blank", "title",
                          title ? title : "Error", "status", http_status);

    if (!p)
        return NULL;
    if (detail && json_object_set_new(p, "detail", json_string(detail)))
        goto fail;
    if (errs && codec_errors_count(errs) > 0 &&
        json_object_set_new(p, "errors", codec_errors_to_json(errs)))
        goto fail;
    return p;
fail:
    json_decref(p);
    return NULL;
}

int codec_errors_http_status(const codec_errors *e)
{
    if (codec_errors_too_large(e))
        return 413;
    if (codec_errors_malformed(e))
        return 400;
    return 422;
}

json_t *codec_problem_from_errors(const codec_errors *errs)
{
    int status = codec_errors_http_status(errs), n = codec_errors_count(errs);
    char detail[96];

    switch (status) {
    case 413:
        return codec_problem_new(413, NULL, "Content Too Large",
                                 "The request is larger than the configured limit.", errs);
    case 400:
        return codec_problem_new(400, NULL, "Bad Request", "The request is not valid JSON.",
                                 errs);
    default:
        snprintf(detail, sizeof(detail), "The request has %d error%s; see 'errors'.", n,
                 n == 1 ? "" : "s");
        return codec_problem_new(422, NULL, "Unprocessable Content", detail, errs);
    }
}
