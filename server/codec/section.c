/*
 * section.c — a section in its three forms: planar, spatial stiffness, spatial material.
 *
 * How it fits: validate.c hands every section object of a request here.  A
 * section is planar {E, A, I, mass_per_length} (DESIGN.md 1.1) or spatial
 * (DESIGN.md 7.3): in stiffness form {EA, EI_flap, EI_edge, GJ,
 * mass_per_length} or in material form {E, G, A, I_flap, I_edge, J,
 * mass_per_length}, both with the optional mass moments per length
 * flap_inertia and edge_inertia.  sec_classify tells the form from the keys
 * present (any of EA, EI_flap, EI_edge, GJ: stiffness; else any of G,
 * I_flap, I_edge, J: material; else planar), sec_validate checks the fields
 * of that form, reports a field of another form, and writes the canonical
 * copy with the defaulted inertias written out, so that a request that
 * omits them and one that gives their default values are the same question.
 * request.c turns the canonical copy into the core's sm_section with
 * sec_fill (EA = E*A, ... for the material form, and I_p/A), and diag.c and
 * request.c name the request field behind a core field with
 * sec_request_field.  This file is the one place that knows the forms.
 */
#include "codec_internal.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* Keys of each form, with units for messages (NULL-terminated). */
static const char *const sec_planar_keys[] = {"E", "A", "I", "mass_per_length", NULL};
static const char *const sec_planar_units[] = {" (Pa)", " (m^2)", " (m^4)", " (kg/m)"};
static const char *const sec_stiff_keys[] = {"EA", "EI_flap", "EI_edge", "GJ",
                                             "mass_per_length", NULL};
static const char *const sec_stiff_units[] = {" (N)", " (N m^2)", " (N m^2)", " (N m^2)",
                                              " (kg/m)"};
static const char *const sec_mat_keys[] = {"E", "G", "A", "I_flap", "I_edge", "J",
                                           "mass_per_length", NULL};
static const char *const sec_mat_units[] = {" (Pa)", " (Pa)", " (m^2)", " (m^4)", " (m^4)",
                                            " (m^4)", " (kg/m)"};
static const char *const sec_inertia_keys[] = {"flap_inertia", "edge_inertia", NULL};
/* Every key a section may have, for the unknown-key check and its suggestions. */
static const char *const sec_all_keys[] = {"E",
                                           "A",
                                           "I",
                                           "mass_per_length",
                                           "EA",
                                           "EI_flap",
                                           "EI_edge",
                                           "GJ",
                                           "G",
                                           "I_flap",
                                           "I_edge",
                                           "J",
                                           "flap_inertia",
                                           "edge_inertia",
                                           "cg_offset",
                                           "shear_center_offset",
                                           "tension_center_offset",
                                           "ip_over_a",
                                           "stand_ins",
                                           NULL};
/* The fields a section may mark as stand-ins (DESIGN.md 8.4, 8.5), in canonical order. */
static const char *const sec_stand_in_keys[] = {"EA", "GJ", NULL};
/* Offsets from the member axis (DESIGN.md 8), [edgewise, flapwise] in m, spatial only. */
static const char *const sec_offset_keys[] = {"cg_offset", "shear_center_offset",
                                              "tension_center_offset", NULL};
/* Keys that only the material form has (the stiffness form has none of them). */
static const char *const sec_mat_only_keys[] = {"G", "I_flap", "I_edge", "J", NULL};

#define SEC_SPATIAL_HINT                                                                       \
    "EA, EI_flap, EI_edge, GJ and mass_per_length (or E, G, A, I_flap, I_edge, J and "         \
    "mass_per_length)"

/* 1 when obj has one of the keys. */
static int sec_has_any(const json_t *obj, const char *const *keys)
{
    int i;

    for (i = 0; keys[i]; i++)
        if (json_object_get(obj, keys[i]))
            return 1;
    return 0;
}

/* 1 when name is one of keys. */
static int sec_has_key(const char *const *keys, const char *name)
{
    int i;

    for (i = 0; keys[i]; i++)
        if (!strcmp(keys[i], name))
            return 1;
    return 0;
}

sec_form sec_classify_as(const json_t *sec, int spatial)
{
    static const char *const planar_only[] = {"E", "A", "I", NULL};
    sec_form f = sec_classify(sec);

    if (f == SEC_PLANAR && spatial && !sec_has_any(sec, planar_only))
        return SEC_STIFFNESS;
    return f;
}

sec_form sec_classify(const json_t *sec)
{
    static const char *const stiff_only[] = {"EA", "EI_flap", "EI_edge", "GJ", NULL};

    if (!json_is_object(sec))
        return SEC_NONE;
    if (sec_has_any(sec, stiff_only))
        return SEC_STIFFNESS;
    if (sec_has_any(sec, sec_mat_only_keys))
        return SEC_MATERIAL;
    return SEC_PLANAR;
}

const char *sec_form_name(sec_form f)
{
    switch (f) {
    case SEC_PLANAR: return "planar (E, A, I, mass_per_length)";
    case SEC_STIFFNESS: return "spatial (EA, EI_flap, EI_edge, GJ, mass_per_length)";
    case SEC_MATERIAL: return "spatial (E, G, A, I_flap, I_edge, J, mass_per_length)";
    case SEC_NONE: break;
    }
    return "not a section";
}

/*
 * Fields of another form in a section of form f: one error each, at the
 * field, saying which form it belongs to and what to do.  Returns the
 * number found (the section is then not checked further).
 */
static int sec_foreign(val_ctx *v, const json_t *sec, const char *ptr, sec_form f)
{
    static const char *const not_stiff[] = {"E", "A", "G", "I_flap", "I_edge", "J", NULL};
    static const char *const inertias[] = {"flap_inertia", "edge_inertia", "cg_offset",
                                           "shear_center_offset", "tension_center_offset",
                                           "ip_over_a", NULL};
    int i, n = 0;

    if (f == SEC_STIFFNESS) {
        for (i = 0; not_stiff[i]; i++) {
            if (!json_object_get(sec, not_stiff[i]))
                continue;
            field_error_key(v, ptr, not_stiff[i],
                            "'%s' belongs to the material form (E, G, A, I_flap, I_edge, J) "
                            "but this section gives its stiffness as EA, EI_flap, EI_edge, GJ: "
                            "the two forms do not mix; drop '%s' or give the section in one form",
                            not_stiff[i], not_stiff[i]);
            n++;
        }
    }
    if (f != SEC_PLANAR && json_object_get(sec, "I")) {
        field_error_key(v, ptr, "I",
                        "'I' is the in-plane second moment of a planar section (E, A, I); this "
                        "section is spatial, with %s: drop 'I'",
                        f == SEC_STIFFNESS ? "EI_flap and EI_edge" : "I_flap and I_edge");
        n++;
    }
    if (f == SEC_PLANAR) {
        for (i = 0; inertias[i]; i++) {
            if (!json_object_get(sec, inertias[i]))
                continue;
            field_error_key(v, ptr, inertias[i],
                            "'%s' is spatial section data, and a planar section (E, A, I, "
                            "mass_per_length) has none: give the section in spatial form ("
                            SEC_SPATIAL_HINT "), or drop '%s'",
                            inertias[i], inertias[i]);
            n++;
        }
    }
    return n;
}

/*
 * The required fields of form f: checked, copied to c; 1 when all are valid.
 * A stiffness-form field whose bit (SM_ST_*) is in cover may be absent (the
 * stations of every member using the section give it); its val stays NaN.
 */
static int sec_required(val_ctx *v, const json_t *sec, const char *ptr, sec_form f, json_t *c,
                        double *val, unsigned cover)
{
    const char *const *keys = f == SEC_PLANAR ? sec_planar_keys
                              : f == SEC_STIFFNESS ? sec_stiff_keys : sec_mat_keys;
    const char *const *units = f == SEC_PLANAR ? sec_planar_units
                               : f == SEC_STIFFNESS ? sec_stiff_units : sec_mat_units;
    int k, ok = 1;

    for (k = 0; keys[k]; k++) {
        val[k] = NAN;
        if (f == SEC_STIFFNESS && !json_object_get(sec, keys[k]) &&
            (cover & stn_section_bit(keys[k])))
            continue;
        if (f != SEC_PLANAR && !json_object_get(sec, keys[k])) {
            field_error_key(v, ptr, keys[k],
                            "required field '%s' is missing: a spatial section in %s form gives "
                            "%s",
                            keys[k], f == SEC_STIFFNESS ? "stiffness" : "material",
                            f == SEC_STIFFNESS
                                ? "EA, EI_flap, EI_edge, GJ and mass_per_length"
                                : "E, G, A, I_flap, I_edge, J and mass_per_length");
            ok = 0;
            continue;
        }
        if (!field_real(v, sec, keys[k], ptr, c, FIELD_POSITIVE, units[k], &val[k]))
            ok = 0;
    }
    return ok;
}

/* 1 when x is a finite normal positive double (a value the numerics carry). */
static int sec_usable(double x)
{
    return isfinite(x) && x >= DBL_MIN;
}

/*
 * Material form: the stiffnesses the core gets are products (EA = E*A, ...)
 * and must not overflow or vanish.  val holds E, G, A, I_flap, I_edge, J, mu.
 */
static void sec_products(val_ctx *v, const char *ptr, const double *val)
{
    static const struct {
        const char *name, *field, *formula;
        int a, b;
    } prod[] = {
        {"EA", "E", "E*A", 0, 2},
        {"EI_flap", "I_flap", "E*I_flap", 0, 3},
        {"EI_edge", "I_edge", "E*I_edge", 0, 4},
        {"GJ", "J", "G*J", 1, 5},
    };
    size_t k;

    for (k = 0; k < sizeof(prod) / sizeof(prod[0]); k++) {
        double p = val[prod[k].a] * val[prod[k].b];
        if (!sec_usable(p))
            field_error_key(v, ptr, prod[k].field,
                            "%s = %s = %g is not a number the numerics can carry: check the "
                            "units (SI: Pa, m^2, m^4)",
                            prod[k].name, prod[k].formula, p);
    }
    if (!sec_usable((val[3] + val[4]) / val[2]))
        field_error_key(v, ptr, "A",
                        "I_p/A = (I_flap + I_edge)/A = %g (the torsional geometric stiffness) "
                        "is not a number the numerics can carry: check the units (SI: m^2, m^4)",
                        (val[3] + val[4]) / val[2]);
}

/*
 * The optional inertias of a spatial section: given (>= 0: zero is a massless rotation, which
 * the eigen-analysis condenses exactly, DESIGN.md 7.4), or the defaults
 * mu*EI/EA (stiffness form: val = EA, EI_flap, EI_edge, GJ, mu) or mu*I/A
 * (material form: val = E, G, A, I_flap, I_edge, J, mu) written out.
 * base_ok says whether val holds valid numbers for the defaults.
 */
static void sec_inertias(val_ctx *v, const json_t *sec, const char *ptr, sec_form f, json_t *c,
                         const double *val, int base_ok)
{
    double mu = f == SEC_STIFFNESS ? val[4] : val[6];
    double given[2] = {0, 0};
    int k, have[2] = {0, 0};

    for (k = 0; k < 2; k++) {
        double def;
        const char *key = sec_inertia_keys[k];
        if (json_object_get(sec, key)) {
            have[k] = field_real(v, sec, key, ptr, c, FIELD_NONNEG, " (kg m)", &given[k]);
            continue;
        }
        if (!base_ok)
            continue;
        /* DESIGN.md 7.3: flap_inertia = mu*EI_flap/EA (= mu*I_flap/A), edge likewise */
        def = f == SEC_STIFFNESS ? mu * val[1 + k] / val[0] : mu * val[3 + k] / val[2];
        if (isnan(def)) /* a factor only the stations give: the stations default it */
            continue;
        if (!sec_usable(def)) {
            field_error_key(v, ptr, key,
                            "the default %s = mass_per_length*%s = %g is not a number the "
                            "numerics can carry: give %s (kg m)",
                            key, f == SEC_STIFFNESS ? (k ? "EI_edge/EA" : "EI_flap/EA")
                                                    : (k ? "I_edge/A" : "I_flap/A"),
                            def, key);
            continue;
        }
        given[k] = def;
        have[k] = 1;
        field_set(v, c, key, json_real(def));
    }
    /* stiffness form: I_p/A = (flap_inertia + edge_inertia)/mass_per_length */
    if (f == SEC_STIFFNESS && have[0] && have[1] && base_ok && !isnan(mu) &&
        given[0] + given[1] != 0 && !sec_usable((given[0] + given[1]) / mu))
        field_error(v, ptr,
                    "I_p/A = (flap_inertia + edge_inertia)/mass_per_length = %g (the torsional "
                    "geometric stiffness) is not a number the numerics can carry: check the "
                    "units (SI: kg m, kg/m)",
                    (given[0] + given[1]) / mu);
}

/*
 * The offsets of a spatial section (DESIGN.md 8): [edgewise, flapwise], m,
 * finite; written to c only when not [0, 0] (the default), so a request
 * without them keeps its canonical form.
 */
static void sec_offsets(val_ctx *v, const json_t *sec, const char *ptr, json_t *c)
{
    double x[2];
    int k;

    for (k = 0; sec_offset_keys[k]; k++)
        if (json_object_get(sec, sec_offset_keys[k]) &&
            field_vector(v, sec, sec_offset_keys[k], ptr, 2, FIELD_FINITE,
                         "[edgewise, flapwise]", " (m)", x) &&
            (x[0] != 0 || x[1] != 0))
            field_set(v, c, sec_offset_keys[k], field_reals(x, 2));
}

/*
 * "stand_ins": the stiffness-form fields (EA, GJ) the section gives as stand-ins for what its
 * source lacks, set stiff on purpose (an ElastoDyn file is rigid in extension and torsion): the
 * plausibility check reads such an EA through EI (plausible.c).  Each once, given by the
 * section itself; the canonical copy lists them in sec_stand_in_keys' order, none when empty.
 */
static void sec_stand_ins(val_ctx *v, const json_t *sec, const char *ptr, sec_form f, json_t *c)
{
    const json_t *a = json_object_get(sec, "stand_ins"), *x;
    unsigned seen = 0;
    json_t *out;
    size_t i;
    int k;

    if (!a)
        return;
    if (!json_is_array(a) || (f != SEC_STIFFNESS && json_array_size(a))) {
        field_error_key(v, ptr, "stand_ins",
                        "must be a list of the fields a section in stiffness form gives as "
                        "stand-ins (\"EA\", \"GJ\"), not %s",
                        json_is_array(a) ? "a list in this form" : field_type_name(a));
        return;
    }
    json_array_foreach(a, i, x) {
        const char *name = json_string_value(x);
        for (k = 0; name && sec_stand_in_keys[k] && strcmp(name, sec_stand_in_keys[k]); k++)
            ;
        if (!name || !sec_stand_in_keys[k] || (seen & (1u << k)) || !json_object_get(sec, name))
            field_error_key(v, ptr, "stand_ins",
                            "entry %zu (%s): each entry names once a field the section gives, "
                            "\"EA\" or \"GJ\"",
                            i, name ? name : field_type_name(x));
        else
            seen |= 1u << k;
    }
    if (!seen)
        return;
    if (!(out = json_array())) {
        v->nomem = 1;
        return;
    }
    for (k = 0; sec_stand_in_keys[k]; k++)
        if ((seen & (1u << k)) && json_array_append_new(out, json_string(sec_stand_in_keys[k])))
            v->nomem = 1;
    field_set(v, c, "stand_ins", out);
}

json_t *sec_validate(val_ctx *v, const json_t *sec, const char *ptr, sec_form f,
                     unsigned cover)
{
    double val[8] = {0};
    json_t *c;
    int ok;

    field_check_keys(v, sec, ptr, sec_all_keys, "section");
    if (sec_foreign(v, sec, ptr, f))
        return NULL;
    c = json_object();
    if (!c) {
        v->nomem = 1;
        return NULL;
    }
    ok = sec_required(v, sec, ptr, f, c, val, cover);
    if (f == SEC_MATERIAL && ok)
        sec_products(v, ptr, val);
    if (f != SEC_PLANAR) {
        double ip;
        sec_inertias(v, sec, ptr, f, c, val, ok);
        sec_offsets(v, sec, ptr, c);
        sec_stand_ins(v, sec, ptr, f, c);
        /* the Wagner ratio I_p/A given (DESIGN.md 8.1): it replaces the one derived from the
         * section (0 switches the tension-torsion term off, as BModes has none) */
        if (json_object_get(sec, "ip_over_a"))
            field_real(v, sec, "ip_over_a", ptr, c, FIELD_NONNEG, " (m^2)", &ip);
    }
    return c;
}

/* A number of a validated canonical section. */
static double sec_num(const json_t *canon, const char *key)
{
    double d = 0;

    field_number(json_object_get(canon, key), &d);
    return d;
}

/* The offset canon[key] into out[2] (zero when absent). */
static void sec_offset(const json_t *canon, const char *key, double out[2])
{
    const json_t *x = json_object_get(canon, key);

    out[0] = json_number_value(json_array_get(x, 0));
    out[1] = json_number_value(json_array_get(x, 1));
}

void sec_fill(const json_t *canon, int spatial, sm_section *out)
{
    sec_form f = sec_classify_as(canon, spatial);

    memset(out, 0, sizeof(*out));
    out->mu = sec_num(canon, "mass_per_length");
    if (f == SEC_PLANAR) {
        out->E = sec_num(canon, "E");
        out->A = sec_num(canon, "A");
        out->I = sec_num(canon, "I");
        return;
    }
    out->i_flap = sec_num(canon, "flap_inertia");
    out->i_edge = sec_num(canon, "edge_inertia");
    sec_offset(canon, "cg_offset", out->cg);
    sec_offset(canon, "shear_center_offset", out->sc);
    sec_offset(canon, "tension_center_offset", out->tc);
    if (f == SEC_STIFFNESS) {
        out->EA = sec_num(canon, "EA");
        out->EI_flap = sec_num(canon, "EI_flap");
        out->EI_edge = sec_num(canon, "EI_edge");
        out->GJ = sec_num(canon, "GJ");
        /* DESIGN.md 7.3: without A and I, I_p/A from the mass moments (0 while a partial
         * section waits for its stations' values, request.c) */
        out->ip_over_a = out->mu > 0 ? (out->i_flap + out->i_edge) / out->mu : 0;
    } else {
        double E = sec_num(canon, "E"), G = sec_num(canon, "G"), A = sec_num(canon, "A");
        double I_flap = sec_num(canon, "I_flap"), I_edge = sec_num(canon, "I_edge");
        out->EA = E * A;
        out->EI_flap = E * I_flap;
        out->EI_edge = E * I_edge;
        out->GJ = G * sec_num(canon, "J");
        out->ip_over_a = (I_flap + I_edge) / A; /* DESIGN.md 7.3: I_p/A = (I_flap + I_edge)/A */
    }
    if (json_object_get(canon, "ip_over_a")) /* given: it wins (DESIGN.md 8.1) */
        out->ip_over_a = sec_num(canon, "ip_over_a");
}

const char *sec_request_field(const json_t *canon, const char *core_field, const char **relation)
{
    static const struct {
        const char *core, *field, *relation;
    } material[] = {
        {"EA", "E", "EA = E*A"},
        {"EI_flap", "I_flap", "EI_flap = E*I_flap"},
        {"EI_edge", "I_edge", "EI_edge = E*I_edge"},
        {"GJ", "J", "GJ = G*J"},
        {"ip_over_a", NULL, "I_p/A = (I_flap + I_edge)/A"},
    };
    sec_form f = sec_classify(canon);
    size_t k;

    *relation = NULL;
    if (!strcmp(core_field, "mu"))
        return "mass_per_length";
    if (!strcmp(core_field, "ip_over_a") && json_object_get(canon, "ip_over_a"))
        return "ip_over_a";
    if (!strcmp(core_field, "ip_over_a") && f == SEC_STIFFNESS) {
        *relation = "I_p/A = (flap_inertia + edge_inertia)/mass_per_length";
        return NULL;
    }
    if (f == SEC_MATERIAL)
        for (k = 0; k < sizeof(material) / sizeof(material[0]); k++)
            if (!strcmp(core_field, material[k].core)) {
                *relation = material[k].relation;
                return material[k].field;
            }
    /* a field of the section's own form, or none (then the section itself) */
    if ((f == SEC_PLANAR && sec_has_key(sec_planar_keys, core_field)) ||
        (f == SEC_STIFFNESS && (sec_has_key(sec_stiff_keys, core_field) ||
                                sec_has_key(sec_inertia_keys, core_field))) ||
        (f == SEC_MATERIAL && (sec_has_key(sec_mat_keys, core_field) ||
                               sec_has_key(sec_inertia_keys, core_field))))
        return core_field;
    return NULL;
}
