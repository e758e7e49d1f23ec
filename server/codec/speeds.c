/*
 * speeds.c — the speeds of a request: analysis.omega (rad/s) or analysis.rpm (rev/min).
 *
 * How it fits: validate.c hands the analysis object here.  Exactly one of
 * omega and rpm gives the speeds, as a number, a non-empty array of
 * numbers, or a range {"from", "to", "steps"} (steps intervals, so steps + 1
 * speeds, from <= to; DESIGN.md 8).  All are finite and >= 0 and at most
 * max_speeds.  The canonical copy keeps the form given (a range stays a
 * range), so a request that does not use rpm or ranges keeps its canonical
 * text.  request.c asks spd_count and spd_fill for the core's speeds
 * (always rad/s, omega = rpm 2 pi / 60) and the rpm the result reports per
 * case (the requested value when rpm was given, else omega 60 / 2 pi).
 */
#include "codec_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* rad/s per rev/min: 2 pi / 60 */
#define SPD_RAD_S_PER_RPM (CODEC_TWO_PI / 60.0)

/* A range object {from, to, steps} at base of unit into its canonical copy; 1 when valid. */
static int spd_range(val_ctx *v, const json_t *r, const char *base, const char *unit,
                     json_t *can, const char *key)
{
    static const char *const keys[] = {"from", "to", "steps", NULL};
    json_t *c = json_object();
    double from = 0, to = 0;
    long steps = 0;
    int ok;

    if (!c) {
        v->nomem = 1;
        return 0;
    }
    field_check_keys(v, r, base, keys, "range");
    ok = field_real(v, r, "from", base, c, FIELD_NONNEG, unit, &from);
    ok &= field_real(v, r, "to", base, c, FIELD_NONNEG, unit, &to);
    ok &= field_int(v, r, "steps", base, c, 1, 0, 0, v->lim->max_speeds - 1,
                    "the number of speeds (steps + 1)", &steps);
    if (ok && to < from) {
        field_error_key(v, base, "to", "the range runs from %g to %g: 'to' must not be below "
                        "'from'", from, to);
        ok = 0;
    }
    if (ok && steps == 0 && to != from) {
        field_error_key(v, base, "steps", "steps is the number of intervals from 'from' to "
                        "'to' (steps + 1 speeds): at least 1 unless from == to");
        ok = 0;
    }
    field_set(v, can, key, c);
    return ok;
}

/* One speed field (omega or rpm) of an at /analysis/key into can. */
static void spd_field(val_ctx *v, const json_t *an, json_t *can, const char *key,
                      const char *unit)
{
    const json_t *om = json_object_get(an, key), *x;
    char *base = err_ptr_key("/analysis", key);
    json_t *arr;
    size_t i;
    double d;

    if (!base) {
        v->nomem = 1;
        return;
    }
    if (json_is_number(om)) {
        if (field_check_real(v, om, base, FIELD_NONNEG, unit, &d))
            field_set(v, can, key, json_real(d));
    } else if (json_is_object(om)) {
        spd_range(v, om, base, unit, can, key);
    } else if (!json_is_array(om)) {
        field_error(v, base, "must be a number%s, an array of numbers or a range {\"from\", "
                    "\"to\", \"steps\"}, not %s", unit, field_type_name(om));
    } else if (json_array_size(om) == 0) {
        field_error(v, base, "must list at least one speed");
    } else if (json_array_size(om) > (size_t)v->lim->max_speeds) {
        field_error(v, base, "too many speeds (%zu): the limit is %d", json_array_size(om),
                    v->lim->max_speeds);
    } else if (!(arr = json_array())) {
        v->nomem = 1;
    } else {
        json_array_foreach(om, i, x) {
            char *p = err_ptr_idx(base, i);
            if (!p) {
                v->nomem = 1;
                break;
            }
            if (field_check_real(v, x, p, FIELD_NONNEG, unit, &d) &&
                json_array_append_new(arr, json_real(d)))
                v->nomem = 1;
            free(p);
        }
        field_set(v, can, key, arr);
    }
    free(base);
}

void spd_validate(val_ctx *v, const json_t *an, json_t *can)
{
    int has_omega = json_object_get(an, "omega") != NULL;
    int has_rpm = json_object_get(an, "rpm") != NULL;

    if (has_omega && has_rpm) {
        field_error(v, "/analysis/rpm", "give the speeds once: 'omega' (rad/s) or 'rpm' "
                    "(rev/min), not both");
        return;
    }
    if (!has_omega && !has_rpm) {
        field_error(v, "/analysis/omega", "required field 'omega' (the speed in rad/s, an "
                    "array of speeds or a range {\"from\", \"to\", \"steps\"}; or 'rpm' in "
                    "rev/min) is missing");
        return;
    }
    if (has_omega)
        spd_field(v, an, can, "omega", " (rad/s)");
    else
        spd_field(v, an, can, "rpm", " (rev/min)");
}

/* The speed field of a canonical analysis and whether it is in rpm. */
static const json_t *spd_of(const json_t *an, int *rpm)
{
    const json_t *x = json_object_get(an, "rpm");

    *rpm = x != NULL;
    return x ? x : json_object_get(an, "omega");
}

size_t spd_count(const json_t *an)
{
    int rpm;
    const json_t *x = spd_of(an, &rpm);

    if (json_is_array(x))
        return json_array_size(x);
    if (json_is_object(x))
        return (size_t)json_integer_value(json_object_get(x, "steps")) + 1;
    return 1;
}

/* Speed k (in the request's unit) of the canonical speed field x. */
static double spd_value(const json_t *x, size_t k)
{
    double from, to;
    json_int_t steps;

    if (json_is_array(x))
        return json_number_value(json_array_get(x, k));
    if (!json_is_object(x))
        return json_number_value(x);
    from = json_number_value(json_object_get(x, "from"));
    to = json_number_value(json_object_get(x, "to"));
    steps = json_integer_value(json_object_get(x, "steps"));
    if ((json_int_t)k >= steps) /* the last speed is exactly 'to' */
        return to;
    return from + (to - from) * (double)k / (double)steps;
}

void spd_fill(const json_t *an, double *omega, double *rpm)
{
    int in_rpm;
    const json_t *x = spd_of(an, &in_rpm);
    size_t k, n = spd_count(an);

    for (k = 0; k < n; k++) {
        double s = spd_value(x, k);
        omega[k] = in_rpm ? s * SPD_RAD_S_PER_RPM : s;
        rpm[k] = in_rpm ? s : s / SPD_RAD_S_PER_RPM;
    }
}
