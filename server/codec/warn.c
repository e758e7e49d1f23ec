/*
 * warn.c — unit-slip warnings: values a request almost surely gives in the wrong unit.
 *
 * How it fits: after a request validated, request.c calls warn_collect on
 * it; the result and the answer of /v1/validate carry the list as
 * "input_warnings" [{pointer, message}] (DESIGN.md 8.1, 8.4).  A warning
 * never rejects a request: the value may be what the user meant.  Every
 * threshold is a row of warn_rules below (and of the table in DESIGN.md
 * 8.4); nothing else in the codec holds one.  This file checks single
 * fields of the canonical structure, naming the field and the likely slip:
 *   - E or G outside the moduli of materials (MPa, N/mm^2);
 *   - mass_per_length / A outside the densities of materials when the
 *     section gives A (a density, g/m, A in mm^2), or mass_per_length above
 *     a density's magnitude without A (also at stations);
 *   - a second moment (I, I_flap, I_edge, J) above 100 A^2 (mm^4, cm^4): the
 *     thinnest practical tubes stay near 10 A^2, while the specification's
 *     "above A^2" flags the Kim & Yoo beam itself (I = 1.25 A^2);
 *   - a bending or torsional stiffness below 1 N m^2 on a member longer
 *     than 1 m (kN m^2 or MN m^2; also at stations).
 * plausible.c checks the dimensionless groups that do not depend on the
 * kind of structure (wave speed, radius of gyration, tip speed, centrifugal
 * strain).  The field checks run first; a pointer gets one warning, the
 * first, so a slip one field check names is not named again by a group.
 */
#include "codec_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/*
 * The thresholds: one row per check (DESIGN.md 8.4 is this table).  typical
 * is where a group usually lies: of the powers of 1e3 that bring a value
 * back into range, the slip named is the one that brings it nearest.
 */
const warn_rule warn_rules[WARN_N_RULES] = {
    /*                    name                        lo      hi       typical  unit     */
    [WARN_MODULUS]     = {"E or G",                    1e6,    1e13,    7e10,    "Pa"},
    [WARN_DENSITY]     = {"mass_per_length / A",       50,     25000,   3000,    "kg/m^3"},
    [WARN_LINE_MASS]   = {"mass_per_length without A", NAN,    5000,    100,     "kg/m"},
    [WARN_SECOND]      = {"second moment / A^2",       NAN,    100,     1,       ""},
    [WARN_STIFF_FLOOR] = {"EI or GJ (members > 1 m)",  1,      NAN,     1e6,     "N m^2"},
    [WARN_WAVE_SPEED]  = {"sqrt(EA / mass_per_length)", 300,   20000,   5000,    "m/s"},
    [WARN_GYRATION]    = {"sqrt(EI / EA) / length",    1e-4,   0.5,     0.01,    ""},
    [WARN_TIP_SPEED]   = {"Omega R_max",               NAN,    340,     100,     "m/s"},
    [WARN_STRAIN]      = {"mass_per_length Omega^2 R^2 / EA", NAN, 1e-2, 1e-4,   ""},
    [WARN_RADIUS]      = {"R_max",                     NAN,    1000,    30,      "m"},
    [WARN_ROUND]       = {"omega resolution",          0.1,    NAN,     NAN,     "rad/s"},
};

const char *warn_g(char buf[32], double x)
{
    double e = nearbyint(log10(fabs(x)));

    if (x > 0 && (e >= 4 || e <= -3) && x == pow(10.0, e))
        snprintf(buf, 32, "1e%d", (int)e);
    else
        snprintf(buf, 32, "%g", x);
    return buf;
}

/* 1 when pointer p (final form) already has a warning, else marks it. */
static int warn_seen(warn_list *w, const char *p)
{
    if (json_object_get(w->seen, p))
        return 1;
    if (json_object_set_new(w->seen, p, json_true()))
        w->nomem = 1;
    return 0;
}

void warn_vadd(warn_list *w, const char *ptr, const char *fmt, va_list ap)
{
    char *q = ptr && w->blade ? tower_form_pointer(w->blade, ptr) : NULL, *msg;
    const char *p = w->blade ? q : ptr;

    if (!p) {
        w->nomem = 1;
        return;
    }
    if (warn_seen(w, p)) {
        free(q);
        return;
    }
    msg = err_vfmt(fmt, ap);
    if (!msg || json_array_append_new(w->arr, json_pack("{s:s, s:s}", "pointer", p, "message",
                                                        msg)))
        w->nomem = 1;
    free(q);
    free(msg);
}

void warn_add(warn_list *w, const char *ptr, const char *fmt, ...)
{
    va_list ap;

    va_start(ap, fmt);
    warn_vadd(w, ptr, fmt, ap);
    va_end(ap);
}

/* warn_add at base/key. */
static void warn_add_key(warn_list *w, const char *base, const char *key, const char *fmt, ...)
    CODEC_PRINTF(4, 5);

static void warn_add_key(warn_list *w, const char *base, const char *key, const char *fmt, ...)
{
    char *p = err_ptr_key(base, key);
    va_list ap;

    if (!p) {
        w->nomem = 1;
        return;
    }
    va_start(ap, fmt);
    warn_vadd(w, p, fmt, ap);
    va_end(ap);
    free(p);
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
    const warn_rule *r = &warn_rules[WARN_MODULUS];
    double x = warn_num(sec, key);
    char b[32];

    if (x < r->lo)
        warn_add_key(w, base, key, "%s = %g Pa is below %s Pa: was it given in MPa or N/mm^2? "
                     "(SI: Pa)", key, x, warn_g(b, r->lo));
    else if (x > r->hi)
        warn_add_key(w, base, key, "%s = %g Pa is above %s Pa, stiffer than any material: was "
                     "it given in another unit? (SI: Pa)", key, x, warn_g(b, r->hi));
}

/* mass_per_length of an object (section or station) at base; A NAN when not given. */
static void warn_mass(warn_list *w, const json_t *obj, const char *base, double A)
{
    const warn_rule *d = &warn_rules[WARN_DENSITY], *m = &warn_rules[WARN_LINE_MASS];
    double mu = warn_num(obj, "mass_per_length");

    if (isnan(mu))
        return;
    if (!isnan(A) && mu / A > d->hi)
        warn_add_key(w, base, "mass_per_length", "mass_per_length / A = %g kg/m^3 is no "
                     "structural material's density (%g to %g kg/m^3): was mass_per_length "
                     "given as a density, or in g/m (g for kg, x1e3)? (SI: kg/m, m^2)", mu / A, d->lo,
                     d->hi);
    else if (!isnan(A) && mu / A < d->lo)
        warn_add_key(w, base, "A", "mass_per_length / A = %g kg/m^3 is no structural "
                     "material's density (%g to %g kg/m^3): was A given in mm^2 (x1e6) or cm^2? "
                     "(SI: kg/m, m^2)", mu / A, d->lo, d->hi);
    else if (isnan(A) && mu > m->hi)
        warn_add_key(w, base, "mass_per_length", "mass_per_length = %g kg/m looks like a "
                     "density (kg/m^3) or a mass in g/m (g for kg, x1e3): it is the mass per "
                     "metre of span, density x area (SI: kg/m)", mu);
}

/* Stiffnesses (keys, NULL-terminated) of obj at base on a member of length len. */
static void warn_stiffness(warn_list *w, const json_t *obj, const char *base, double len,
                           const char *const *keys)
{
    const warn_rule *r = &warn_rules[WARN_STIFF_FLOOR];
    int k;

    for (k = 0; keys[k] && len > 1; k++) {
        double x = warn_num(obj, keys[k]);
        if (x < r->lo)
            warn_add_key(w, base, keys[k], "%s = %g N m^2 on a member %g m long is below %g "
                         "N m^2: was it given in kN m^2 or MN m^2? (SI: N m^2)", keys[k], x,
                         len, r->lo);
    }
}

/* The second moments of section sec at base against A^2 (A given, not NAN). */
static void warn_seconds(warn_list *w, const json_t *sec, const char *base, double A)
{
    static const char *const seconds[] = {"I", "I_flap", "I_edge", "J", NULL};
    const warn_rule *r = &warn_rules[WARN_SECOND];
    int k;

    for (k = 0; seconds[k]; k++) {
        double I = warn_num(sec, seconds[k]);
        if (I > r->hi * A * A)
            warn_add_key(w, base, seconds[k], "%s = %g m^4 is more than %g A^2 = %g m^4, no "
                         "practical section: was it given in mm^4 or cm^4? (SI: m^4)",
                         seconds[k], I, r->hi, r->hi * A * A);
    }
}

/* Section sec (named name) used by members up to len long. */
static void warn_section(warn_list *w, const json_t *sec, const char *name, double len)
{
    static const char *const stiff[] = {"EI_flap", "EI_edge", "GJ", NULL};
    char *base = err_ptr_key("/structure/sections", name);
    double A = warn_num(sec, "A"), EI = warn_num(sec, "E") * warn_num(sec, "I");

    if (!base) {
        w->nomem = 1;
        return;
    }
    if (json_object_get(sec, "E"))
        warn_modulus(w, sec, base, "E");
    if (json_object_get(sec, "G"))
        warn_modulus(w, sec, base, "G");
    warn_mass(w, sec, base, A);
    if (!isnan(A))
        warn_seconds(w, sec, base, A);
    if (json_object_get(sec, "I") && len > 1 && EI < warn_rules[WARN_STIFF_FLOOR].lo)
        warn_add_key(w, base, "I", "E I = %g N m^2 on a member %g m long is below %g N m^2: "
                     "check the units of E (Pa) and I (m^4)", EI, len,
                     warn_rules[WARN_STIFF_FLOOR].lo);
    warn_stiffness(w, sec, base, len, stiff);
    free(base);
}

/*
 * Station key `key` of member i (length len) out of range at some stations:
 * one warning, at the first, counting the others (a slip fills a column).
 */
static void warn_station_key(warn_list *w, const json_t *sts, size_t i, double len,
                             const char *key)
{
    const warn_rule *m = &warn_rules[WARN_LINE_MASS], *f = &warn_rules[WARN_STIFF_FLOOR];
    int mass = !strcmp(key, "mass_per_length");
    size_t j, n = 0, first = 0;
    char *p;

    for (j = 0; j < json_array_size(sts); j++) {
        double x = warn_num(json_array_get(sts, j), key);
        if (mass ? x > m->hi : len > 1 && x < f->lo)
            first = n++ ? first : j;
    }
    if (!n)
        return;
    p = err_fmt("/structure/members/%zu/stations/%zu/%s", i, first, key);
    if (!p) {
        w->nomem = 1;
        return;
    }
    if (mass)
        warn_add(w, p, "mass_per_length = %g kg/m looks like a density (kg/m^3) or a mass in "
                 "g/m (g for kg, x1e3): it is the mass per metre of span, density x area (SI: "
                 "kg/m); %zu of the member's %zu stations are above %g kg/m",
                 warn_num(json_array_get(sts, first), key), n, json_array_size(sts), m->hi);
    else
        warn_add(w, p, "%s = %g N m^2 on a member %g m long is below %g N m^2: was it given in "
                 "kN m^2 or MN m^2? (SI: N m^2); %zu of the member's %zu stations are below",
                 key, warn_num(json_array_get(sts, first), key), len, f->lo, n,
                 json_array_size(sts));
    free(p);
}

/* The stations of member i (length len). */
static void warn_stations(warn_list *w, const json_t *sts, size_t i, double len)
{
    static const char *const keys[] = {"mass_per_length", "EI_flap", "EI_edge", "GJ", NULL};
    int k;

    for (k = 0; keys[k] && json_array_size(sts); k++)
        warn_station_key(w, sts, i, len, keys[k]);
}

/* The single-field checks of the canonical structure st. */
static void warn_fields(warn_list *w, const json_t *st)
{
    const json_t *js = json_object_get(st, "joints"), *mems = json_object_get(st, "members");
    const json_t *secs = json_object_get(st, "sections"), *m, *sec;
    const char *name;
    size_t i;

    json_object_foreach((json_t *)secs, name, sec) {
        double len = 0;
        json_array_foreach(mems, i, m)
            if (!strcmp(json_string_value(json_object_get(m, "section")), name))
                len = fmax(len, warn_member_length(js, m));
        warn_section(w, sec, name, len);
    }
    json_array_foreach(mems, i, m)
        warn_stations(w, json_object_get(m, "stations"), i, warn_member_length(js, m));
}

json_t *warn_collect(const codec_request *r)
{
    warn_list w = {json_array(), json_object(), 0, 0};

    w.blade = tower_form(codec_request_canonical(r)); /* CODEC_FORM_*: pointers move */
    if (!w.arr || !w.seen)
        w.nomem = 1;
    else
        warn_fields(&w, req_structure(r));
    if (!w.nomem)
        plaus_check(&w, r);
    json_decref(w.seen);
    if (w.nomem) {
        json_decref(w.arr);
        return NULL;
    }
    return w.arr;
}
