/*
 * validate_analysis.c — the request's "frames" and "analysis" objects, walked field by field
 * (DESIGN.md 3): the frame scheme; the speeds (omega or rpm: speeds.c), modes and every option
 * with its default written into the canonical copy; the error estimate, engine orders and rotary
 * inertia options.
 *
 * How it fits: val_document (validate.c) calls val_frames and val_analysis after the structure,
 * with the same val_ctx, so their errors join the structure's with their JSON pointers.  Moved
 * out of validate.c (906 lines) as it was.
 */
#include "codec_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* frames: "single", "per_element", {"per_member": k} or {"elements_per_frame": n}. */
void val_frames(val_ctx *v, const json_t *root, json_t *canon)
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
            field_error(v, "/frames",
                        "unknown frame scheme '%s'; expected \"single\", "
                        "\"per_element\", {\"per_member\": k} or {\"elements_per_frame\": n}",
                        field_short_name(s).s);
        return;
    }
    if (!json_is_object(f)) {
        field_error(v, "/frames",
                    "must be \"single\", \"per_element\", {\"per_member\": k} or "
                    "{\"elements_per_frame\": n}, not %s",
                    field_type_name(f));
        return;
    }
    field_check_keys(v, f, "/frames", keys, "frames");
    nk = (json_object_get(f, "per_member") != NULL) +
         (json_object_get(f, "elements_per_frame") != NULL);
    if (nk != 1) {
        field_error(v, "/frames", "must have exactly one of 'per_member' and 'elements_per_frame'");
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

/*
 * analysis.error_estimate (DESIGN.md 9): a boolean, default false.  Only true goes into the
 * canonical request, so a request without it keeps its canonical text and job id.  The
 * paper basis has no error estimate (it does not converge to the beam model as frames are
 * added); the refined models are checked against the limits in request.c.
 */
static void val_error_estimate(val_ctx *v, const json_t *an, json_t *can)
{
    const json_t *x = json_object_get(an, "error_estimate");
    const char *basis = json_string_value(json_object_get(can, "substructure_modes"));

    if (!x || json_is_false(x))
        return;
    if (!json_is_true(x)) {
        field_error(v, "/analysis/error_estimate", "must be true or false, not %s",
                    field_type_name(x));
        return;
    }
    if (basis && !strcmp(basis, "paper")) {
        field_error(v, "/analysis/error_estimate",
                    "no error estimate with the \"paper\" basis: it does not converge to the "
                    "beam model as frames are added (DESIGN.md 1.2); use \"augmented\"");
        return;
    }
    field_set(v, can, "error_estimate", json_true());
}

/*
 * analysis.engine_orders (DESIGN.md 9.1): 1..SM_MAX_ENGINE_ORDERS distinct positive numbers
 * (n of w = n Omega, at most 1000), each checked at /analysis/engine_orders/<i>.  Written to
 * the canonical request only when given, so a request without it keeps its job id.
 */
static void val_engine_orders(val_ctx *v, const json_t *an, json_t *can)
{
    const json_t *eo = json_object_get(an, "engine_orders"), *x;
    char ptr[64];
    double d[SM_MAX_ENGINE_ORDERS];
    size_t i, j;
    json_t *c;

    if (!eo)
        return;
    if (!json_is_array(eo) || json_array_size(eo) == 0 ||
        json_array_size(eo) > SM_MAX_ENGINE_ORDERS) {
        field_error(v, "/analysis/engine_orders",
                    "must be a list of 1 to %d engine orders (n of w = n Omega, e.g. [1, 2, 3, 4])",
                    SM_MAX_ENGINE_ORDERS);
        return;
    }
    c = json_array();
    if (!c) {
        v->nomem = 1;
        return;
    }
    json_array_foreach(eo, i, x) {
        snprintf(ptr, sizeof(ptr), "/analysis/engine_orders/%zu", i);
        if (!field_check_real(v, x, ptr, FIELD_POSITIVE, "", &d[i]))
            continue;
        if (d[i] > 1000) {
            field_error(v, ptr, "an engine order above 1000 (%g) is not a rotor harmonic", d[i]);
            continue;
        }
        for (j = 0; j < i; j++)
            if (d[j] == d[i])
                field_error(v, ptr, "engine order %g is given twice", d[i]);
        if (json_array_append_new(c, json_real(d[i])))
            v->nomem = 1;
    }
    field_set(v, can, "engine_orders", c);
}

/*
 * analysis.rotary_inertia (DESIGN.md 8.5): "full" (default) or "torsion" (a spatial section's
 * mass moments act in torsion only, BModes' model).  Only "torsion" goes into the canonical
 * request, so a request without it (or with "full") keeps its canonical text and job id.
 */
static void val_rotary_inertia(val_ctx *v, const json_t *an, json_t *can)
{
    const json_t *x = json_object_get(an, "rotary_inertia");
    const char *s = json_string_value(x);

    if (!x || (s && !strcmp(s, "full")))
        return;
    if (!s || strcmp(s, "torsion")) {
        field_error(v, "/analysis/rotary_inertia", "must be \"full\" or \"torsion\"");
        return;
    }
    if (v->spatial == 0) {
        field_error(v, "/analysis/rotary_inertia",
                    "\"torsion\" needs spatial sections (planar sections have no rotary "
                    "inertia): " VAL_SPATIAL_SECTIONS);
        return;
    }
    field_set(v, can, "rotary_inertia", json_string("torsion"));
}

/* The analysis object: omega or rpm (speeds.c), modes and the options, with their defaults. */
void val_analysis(val_ctx *v, const json_t *root, json_t *canon)
{
    static const char *const keys[] = {"omega",
                                       "rpm",
                                       "modes",
                                       "geometric_stiffening",
                                       "coriolis",
                                       "mass",
                                       "substructure_modes",
                                       "modes_per_frame",
                                       "mode_shapes",
                                       "error_estimate",
                                       "engine_orders",
                                       "rotary_inertia",
                                       NULL};
    static const char *const mass[] = {"lumped", "consistent", NULL};
    static const char *const basis[] = {"augmented", "paper", NULL};
    static const char *base = "/analysis";
    const json_t *an = field_object(v, root, "analysis", "");
    const json_t *mpf;
    const char *basis_name;
    json_t *can;

    if (!an)
        return;
    field_check_keys(v, an, base, keys, "analysis");
    can = json_object();
    if (!can)
        v->nomem = 1;
    spd_validate(v, an, can);
    field_int(v, an, "modes", base, can, 0, 3, 1, v->lim->max_modes, "the number of modes", NULL);
    field_bool(v, an, "geometric_stiffening", base, can, 1);
    field_bool(v, an, "coriolis", base, can, 1);
    field_enum(v, an, "mass", base, can, mass, "lumped");
    field_enum(v, an, "substructure_modes", base, can, basis, "augmented");
    basis_name = json_string_value(json_object_get(can, "substructure_modes"));
    if (v->spatial == 1 && basis_name && !strcmp(basis_name, "paper"))
        field_error(v, "/analysis/substructure_modes",
                    "the \"paper\" basis is planar-only (Kim & Yoo's condensed in-plane "
                    "component modes, kept to reproduce their Table 2): use \"augmented\" (the "
                    "default) with spatial sections");
    mpf = json_object_get(an, "modes_per_frame");
    if (!mpf || (json_is_string(mpf) && !strcmp(json_string_value(mpf), "all")))
        field_set(v, can, "modes_per_frame", json_string("all"));
    else if (json_is_number(mpf))
        field_int(v, an, "modes_per_frame", base, can, 1, 0, 1, 100000, NULL, NULL);
    else
        field_error(v, "/analysis/modes_per_frame", "must be \"all\" or a positive integer, not %s",
                    json_is_string(mpf) ? "another string" : field_type_name(mpf));
    field_bool(v, an, "mode_shapes", base, can, 1);
    val_error_estimate(v, an, can);
    val_engine_orders(v, an, can);
    val_rotary_inertia(v, an, can);
    field_set(v, canon, "analysis", can);
}
