/*
 * field.c — reading one field of a request: check it, report it, copy it.
 *
 * How it fits: validate.c walks the request document and calls these
 * readers for each field.  A reader looks the field up, checks its type and
 * range, appends an error at the field's JSON pointer when it is wrong (and
 * carries on: validation never stops at the first error), and writes the
 * checked value, or the default when the field is absent, into the
 * canonical copy.  Messages name what was expected and what was found,
 * suggest a near key for a typo, and shorten user-supplied names.
 * Everything goes through a val_ctx (codec_internal.h), which also records
 * a failed allocation so the caller reports SM_NOMEM, not a bogus error.
 */
#include "codec_internal.h"

#include <float.h>

#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

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

/* Error at ptr (NULL: the pointer could not be built, NOMEM), vprintf-style. */
static void field_verror(val_ctx *v, const char *ptr, const char *fmt, va_list ap)
{
    if (!ptr || err_vadd(v->errs, ptr, fmt, ap))
        v->nomem = 1;
}

void field_error(val_ctx *v, const char *ptr, const char *fmt, ...)
{
    va_list ap;

    va_start(ap, fmt);
    field_verror(v, ptr, fmt, ap);
    va_end(ap);
}

/* Error at base/key. */
void field_error_key(val_ctx *v, const char *base, const char *key, const char *fmt, ...)
{
    va_list ap;
    char *p = err_ptr_key(base, key);

    va_start(ap, fmt);
    field_verror(v, p, fmt, ap);
    va_end(ap);
    free(p);
}

/* Set canon[key] = value (stolen); records NOMEM.  key is one of the program's names or a key
 * of the request (which its parse has checked as UTF-8), so jansson need not check it again. */
void field_set(val_ctx *v, json_t *canon, const char *key, json_t *value)
{
    if (!canon) {
        json_decref(value);
        return;
    }
    if (json_object_set_new_nocheck(canon, key, value))
        v->nomem = 1;
}

/* Every key of obj must be one of allowed (NULL-terminated). */
void field_check_keys(val_ctx *v, const json_t *obj, const char *base,
                      const char *const *allowed, const char *what)
{
    field_check_keys_but(v, obj, base, allowed, NULL, what);
}

void field_check_keys_but(val_ctx *v, const json_t *obj, const char *base,
                          const char *const *allowed, const char *const *skip, const char *what)
{
    const char *key;
    json_t *val;

    json_object_foreach((json_t *)obj, key, val) {
        const char *best = NULL;
        int i, found = 0, bestd = strlen(key) >= 5 ? 4 : 3; /* suggest below this distance */
        (void)val;
        for (i = 0; allowed[i] && !found; i++)
            found = !strcmp(key, allowed[i]);
        for (i = 0; skip && skip[i] && !found; i++)
            found = !strcmp(key, skip[i]);
        if (found)
            continue;
        for (i = 0; allowed[i]; i++) { /* an unknown key: the closest allowed one, if close */
            int d = field_edit_distance(key, allowed[i]);
            if (d < bestd) {
                bestd = d;
                best = allowed[i];
            }
        }
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

/* field_check_real's check without its message: 0 when x is valid (*out its value, -0 as 0),
 * else which of the messages field_real_report writes (*out then x's number, if any). */
enum {
    FIELD_REAL_OK,
    FIELD_REAL_NOT_NUMBER,
    FIELD_REAL_INF,
    FIELD_REAL_SUBNORMAL,
    FIELD_REAL_POS,
    FIELD_REAL_NONNEG
};
static int field_real_fault(const json_t *x, enum field_real_kind kind, double *out)
{
    double d = 0;

    if (!field_number(x, &d))
        return FIELD_REAL_NOT_NUMBER;
    *out = d;
    if (!isfinite(d))
        return FIELD_REAL_INF;
    if (d != 0 && fabs(d) < DBL_MIN)
        return FIELD_REAL_SUBNORMAL;
    if (kind == FIELD_POSITIVE && !(d > 0))
        return FIELD_REAL_POS;
    if (kind == FIELD_NONNEG && !(d >= 0))
        return FIELD_REAL_NONNEG;
    if (d == 0)
        *out = 0.0; /* -0 and 0 are the same request */
    return FIELD_REAL_OK;
}

/* The message of a field_real_fault at ptr (d: the number, when there is one). */
static void field_real_report(val_ctx *v, const char *ptr, int fault, const json_t *x, double d,
                              const char *unit)
{
    switch (fault) {
    case FIELD_REAL_NOT_NUMBER:
        field_error(v, ptr, "must be a number%s, not %s", unit, field_type_name(x));
        break;
    case FIELD_REAL_INF:
        field_error(v, ptr, "must be a finite number");
        break;
    case FIELD_REAL_SUBNORMAL:
        field_error(v, ptr, "%g is below the smallest normal double (%g): not a value the "
                    "numerics can carry%s", d, DBL_MIN, unit);
        break;
    case FIELD_REAL_POS:
        field_error(v, ptr, "must be a positive number%s, got %g", unit, d);
        break;
    default:
        field_error(v, ptr, "must be a number >= 0%s, got %g", unit, d);
        break;
    }
}

/* Check a real value x at ptr; 1 and *out when valid. */
int field_check_real(val_ctx *v, const json_t *x, const char *ptr, enum field_real_kind kind,
                     const char *unit, double *out)
{
    double d = 0;
    int fault = field_real_fault(x, kind, &d);

    if (fault) {
        field_real_report(v, ptr, fault, x, d, unit);
        return 0;
    }
    *out = d;
    return 1;
}

/* Real field obj[key]: required, checked, written to canon as a real.  The field's pointer is
 * written only for a message (a blade's stations have thousands of valid reals: issue 27). */
int field_real(val_ctx *v, const json_t *obj, const char *key, const char *base,
               json_t *canon, enum field_real_kind kind, const char *unit, double *out)
{
    return field_real_at(v, json_object_get(obj, key), key, base, canon, kind, unit, out);
}

int field_real_at(val_ctx *v, const json_t *x, const char *key, const char *base, json_t *canon,
                  enum field_real_kind kind, const char *unit, double *out)
{
    double d = 0;
    int fault;

    if (!x) {
        field_error_key(v, base, key, "required field '%s' is missing", key);
        return 0;
    }
    if ((fault = field_real_fault(x, kind, &d))) {
        char *ptr = err_ptr_key(base, key);
        if (!ptr) {
            v->nomem = 1;
            return 0;
        }
        field_real_report(v, ptr, fault, x, d, unit);
        free(ptr);
        return 0;
    }
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

/* Vector field obj[key] of n (<= 3) numbers of kind; see codec_internal.h. */
int field_vector(val_ctx *v, const json_t *obj, const char *key, const char *base, int n,
                 enum field_real_kind kind, const char *shape, const char *unit, double *out)
{
    return field_vector_at(v, json_object_get(obj, key), key, base, n, kind, shape, unit, out);
}

int field_vector_at(val_ctx *v, const json_t *x, const char *key, const char *base, int n,
                    enum field_real_kind kind, const char *shape, const char *unit, double *out)
{
    char *p;
    size_t k;
    int ok = 1;

    if (json_is_array(x) && json_array_size(x) == (size_t)n) { /* valid: no pointers written */
        for (k = 0; k < (size_t)n && ok; k++)
            ok = !field_real_fault(json_array_get(x, k), kind, &out[k]);
        if (ok)
            return 1;
        ok = 1;
    }
    if (!(p = err_ptr_key(base, key))) {
        v->nomem = 1;
        return 0;
    }
    if (!json_is_array(x) || json_array_size(x) != (size_t)n) {
        if (json_is_array(x))
            field_error(v, p, "must be %s (%d numbers), got %zu value%s", shape, n,
                        json_array_size(x), json_array_size(x) == 1 ? "" : "s");
        else
            field_error(v, p, "must be %s (%d numbers), not %s", shape, n, field_type_name(x));
        free(p);
        return 0;
    }
    for (k = 0; k < (size_t)n; k++) {
        char *pk = err_ptr_idx(p, k);
        if (!field_check_real(v, json_array_get(x, k), pk ? pk : p, kind, unit, &out[k]))
            ok = 0;
        free(pk);
    }
    free(p);
    return ok;
}

/* [out[0], ..., out[n-1]] as reals; NULL when out of memory. */
json_t *field_reals(const double *x, int n)
{
    json_t *a = json_array();
    int k;

    for (k = 0; a && k < n; k++)
        if (json_array_append_new(a, json_real(x[k]))) {
            json_decref(a);
            return NULL;
        }
    return a;
}
