/*
 * warn.c — unit-slip warnings: values a request almost surely gives in the wrong unit.
 *
 * How it fits: after a request validated, request.c calls warn_collect on
 * its canonical structure; the result and the answer of /v1/validate carry
 * the list as "input_warnings" [{pointer, message}] (DESIGN.md 8).  A
 * warning never rejects a request: the value may be what the user meant.
 * The rules, each naming the field and the likely slip:
 *   - E or G below 1e6 Pa (MPa, N/mm^2) or above 1e13 Pa;
 *   - mass_per_length / A outside 100..25000 kg/m^3 when the section gives
 *     A (a density, or A in mm^2), or mass_per_length above 5000 kg/m
 *     without A (a density given as mass per length; also at stations);
 *   - a second moment (I, I_flap, I_edge, J) above 100 A^2 (mm^4, cm^4): the
 *     thinnest practical tubes stay near 10 A^2, while the specification's
 *     "above A^2" flags the Kim & Yoo beam itself (I = 1.25 A^2);
 *   - a bending or torsional stiffness below 1 N m^2 on a member longer
 *     than 1 m (kN m^2 or MN m^2; also at stations).
 */
#include "codec_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The list being built, and whether its pointers move into /blade. */
typedef struct warn_list {
    json_t *arr;
    int blade;
    int nomem;
} warn_list;

/* Append a warning at base/key (key may be NULL: at base). */
static void warn_add(warn_list *w, const char *base, const char *key, const char *fmt, ...)
    CODEC_PRINTF(4, 5);

static void warn_add(warn_list *w, const char *base, const char *key, const char *fmt, ...)
{
    char *p = key ? err_ptr_key(base, key) : strdup(base), *q = NULL, *msg;
    va_list ap;

    va_start(ap, fmt);
    msg = err_vfmt(fmt, ap);
    va_end(ap);
    q = p && w->blade ? blade_pointer(p) : NULL;
    if (!p || !msg || (w->blade && !q) ||
        json_array_append_new(w->arr, json_pack("{s:s, s:s}", "pointer", q ? q : p, "message",
                                                msg)))
        w->nomem = 1;
    free(p);
    free(q);
    free(msg);
}

/* A number of a canonical object, or NAN when absent. */
static double warn_num(const json_t *obj, const char *key)
{
    double d = NAN;

    field_number(json_object_get(obj, key), &d);
    return d;
}

/* Length of member m (canonical joints js). */
static double warn_member_length(const json_t *js, const json_t *m)
{
    const json_t *a = json_object_get(js, json_string_value(json_object_get(m, "from")));
    const json_t *b = json_object_get(js, json_string_value(json_object_get(m, "to")));
    double d2 = 0;
    size_t k;

    for (k = 0; k < json_array_size(a); k++) {
        double d = json_number_value(json_array_get(b, k)) - json_number_value(json_array_get(a, k));
        d2 += d * d;
    }
    return sqrt(d2);
}

/* E or G of a section at base. */
static void warn_modulus(warn_list *w, const json_t *sec, const char *base, const char *key)
{
    double x = warn_num(sec, key);

    if (x < 1e6)
        warn_add(w, base, key, "%s = %g Pa is below 1e6 Pa: was it given in MPa or N/mm^2? "
                 "(SI: Pa)", key, x);
    else if (x > 1e13)
        warn_add(w, base, key, "%s = %g Pa is above 1e13 Pa, stiffer than any material: was "
                 "it given in another unit? (SI: Pa)", key, x);
}

/* mass_per_length of an object (section or station) at base; A NAN when not given. */
static void warn_mass(warn_list *w, const json_t *obj, const char *base, double A)
{
    double mu = warn_num(obj, "mass_per_length");

    if (isnan(mu))
        return;
    if (!isnan(A) && (mu / A < 100 || mu / A > 25000))
        warn_add(w, base, "mass_per_length", "mass_per_length / A = %g kg/m^3 is no "
                 "structural material's density (100 to 25000 kg/m^3): was mass_per_length "
                 "given as a density, or A in mm^2 or cm^2? (SI: kg/m, m^2)", mu / A);
    else if (isnan(A) && mu > 5000)
        warn_add(w, base, "mass_per_length", "mass_per_length = %g kg/m looks like a density "
                 "(kg/m^3): it is the mass per metre of span, density x area (SI: kg/m)", mu);
}

/* Stiffnesses (keys, NULL-terminated) of obj at base on a member of length len. */
static void warn_stiffness(warn_list *w, const json_t *obj, const char *base, double len,
                           const char *const *keys)
{
    int k;

    for (k = 0; keys[k] && len > 1; k++) {
        double x = warn_num(obj, keys[k]);
        if (x < 1)
            warn_add(w, base, keys[k], "%s = %g N m^2 on a member %g m long is below 1 N m^2: "
                     "was it given in kN m^2 or MN m^2? (SI: N m^2)", keys[k], x, len);
    }
}

/* Section sec (named name) used by members up to len long. */
static void warn_section(warn_list *w, const json_t *sec, const char *name, double len)
{
    static const char *const seconds[] = {"I", "I_flap", "I_edge", "J", NULL};
    static const char *const stiff[] = {"EI_flap", "EI_edge", "GJ", NULL};
    char *base = err_ptr_key("/structure/sections", name);
    double A = warn_num(sec, "A");
    int k;

    if (!base) {
        w->nomem = 1;
        return;
    }
    if (json_object_get(sec, "E"))
        warn_modulus(w, sec, base, "E");
    if (json_object_get(sec, "G"))
        warn_modulus(w, sec, base, "G");
    warn_mass(w, sec, base, A);
    for (k = 0; seconds[k] && !isnan(A); k++) {
        double I = warn_num(sec, seconds[k]);
        if (I > 100 * A * A)
            warn_add(w, base, seconds[k], "%s = %g m^4 is more than 100 A^2 = %g m^4, no "
                     "practical section: was it given in mm^4 or cm^4? (SI: m^4)",
                     seconds[k], I, 100 * A * A);
    }
    if (json_object_get(sec, "I") && len > 1 && warn_num(sec, "E") * warn_num(sec, "I") < 1)
        warn_add(w, base, "I", "E I = %g N m^2 on a member %g m long is below 1 N m^2: check "
                 "the units of E (Pa) and I (m^4)", warn_num(sec, "E") * warn_num(sec, "I"), len);
    warn_stiffness(w, sec, base, len, stiff);
    free(base);
}

/* The stations of member i (length len). */
static void warn_stations(warn_list *w, const json_t *sts, size_t i, double len)
{
    static const char *const stiff[] = {"EI_flap", "EI_edge", "GJ", NULL};
    const json_t *st;
    size_t j;

    json_array_foreach(sts, j, st) {
        char *base = err_fmt("/structure/members/%zu/stations/%zu", i, j);
        if (!base) {
            w->nomem = 1;
            return;
        }
        warn_mass(w, st, base, NAN);
        warn_stiffness(w, st, base, len, stiff);
        free(base);
    }
}

json_t *warn_collect(const json_t *st, int blade)
{
    const json_t *js = json_object_get(st, "joints"), *mems = json_object_get(st, "members");
    const json_t *secs = json_object_get(st, "sections"), *m, *sec;
    warn_list w = {json_array(), blade, 0};
    const char *name;
    size_t i;

    if (!w.arr)
        return NULL;
    json_object_foreach((json_t *)secs, name, sec) {
        double len = 0;
        json_array_foreach(mems, i, m)
            if (!strcmp(json_string_value(json_object_get(m, "section")), name))
                len = fmax(len, warn_member_length(js, m));
        warn_section(&w, sec, name, len);
    }
    json_array_foreach(mems, i, m)
        warn_stations(&w, json_object_get(m, "stations"), i, warn_member_length(js, m));
    if (w.nomem) {
        json_decref(w.arr);
        return NULL;
    }
    return w.arr;
}
