/*
 * station.c — section properties along a member: the "stations" table (DESIGN.md 8).
 *
 * How it fits: a spatial member may carry "stations", a table of span
 * fractions s (0 at its `from` joint, 1 at `to`) with any of the spatial
 * section quantities in stiffness form (stn_keys below).  validate.c calls
 * stn_validate for each member: every station an object, s from exactly 0
 * to exactly 1 and strictly increasing, every value in range, and a key
 * given at one station given at all of them (the core interpolates each
 * quantity linearly between stations).  A quantity no station gives comes
 * from the member's section, so a section used only by members whose
 * stations give a stiffness may leave that stiffness out (stn_cover tells
 * section.c which).  The canonical stations are written with the per-station
 * default mass moments of DESIGN.md 7.3 (mass_per_length*EI/EA, each factor
 * from the station or the section) when the stations change one of those
 * factors and neither they nor the section give the moment, so omitting
 * them and giving their values are the same question.  request.c turns the
 * canonical table into the core's sm_station array with stn_fill.
 */
#include "codec_internal.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

/* One station quantity: request key, core mask bit, range, values (1 or 2), where in
 * sm_station, unit for messages. */
typedef struct stn_key {
    const char *name;
    unsigned bit;
    enum field_real_kind kind;
    int n;
    size_t off;
    const char *unit;
} stn_key;

#define STN_AT(f) offsetof(sm_station, f)

static const stn_key stn_keys[] = {
    {"mass_per_length", SM_ST_MU, FIELD_POSITIVE, 1, STN_AT(mu), " (kg/m)"},
    {"EA", SM_ST_EA, FIELD_POSITIVE, 1, STN_AT(EA), " (N)"},
    {"EI_flap", SM_ST_EI_FLAP, FIELD_POSITIVE, 1, STN_AT(EI_flap), " (N m^2)"},
    {"EI_edge", SM_ST_EI_EDGE, FIELD_POSITIVE, 1, STN_AT(EI_edge), " (N m^2)"},
    {"GJ", SM_ST_GJ, FIELD_POSITIVE, 1, STN_AT(GJ), " (N m^2)"},
    {"flap_inertia", SM_ST_I_FLAP, FIELD_NONNEG, 1, STN_AT(i_flap), " (kg m)"},
    {"edge_inertia", SM_ST_I_EDGE, FIELD_NONNEG, 1, STN_AT(i_edge), " (kg m)"},
    {"twist_deg", SM_ST_TWIST, FIELD_FINITE, 1, STN_AT(twist), " (degrees)"},
    {"inertia_twist_deg", SM_ST_INERTIA_TWIST, FIELD_FINITE, 1, STN_AT(inertia_twist),
     " (degrees)"},
    {"cg_offset", SM_ST_CG, FIELD_FINITE, 2, STN_AT(cg), " (m)"},
    {"shear_center_offset", SM_ST_SC, FIELD_FINITE, 2, STN_AT(sc), " (m)"},
    {"tension_center_offset", SM_ST_TC, FIELD_FINITE, 2, STN_AT(tc), " (m)"},
    {"ip_over_a", SM_ST_IP_OVER_A, FIELD_NONNEG, 1, STN_AT(ip_over_a), " (m^2)"},
};
#define STN_NKEYS (sizeof(stn_keys) / sizeof(stn_keys[0]))

/* Every key a station may have, for the unknown-key check. */
static const char *const stn_allowed[] = {
    "s", "mass_per_length", "EA", "EI_flap", "EI_edge", "GJ", "flap_inertia", "edge_inertia",
    "twist_deg", "inertia_twist_deg", "cg_offset", "shear_center_offset",
    "tension_center_offset", "ip_over_a", NULL};

/* Material-form keys: stations take the stiffness form only. */
static const char *const stn_material[] = {"E", "G", "A", "I", "I_flap", "I_edge", "J", NULL};

/* Index in stn_keys of the key, STN_S for "s", STN_OTHER for any other key. */
enum { STN_S = -1, STN_OTHER = -2 };
static int stn_index(const char *key)
{
    size_t k;

    if (key[0] == 's' && !key[1])
        return STN_S;
    for (k = 0; k < STN_NKEYS; k++)
        if (stn_keys[k].name[0] == key[0] && !strcmp(stn_keys[k].name, key))
            return (int)k;
    return STN_OTHER;
}

/* A station's values by key, from one walk over its members: no hash lookups (issue 27: a
 * blade's request asked each station's table for each key some ten times over). */
typedef struct stn_view {
    const json_t *s;            /* "s", or NULL */
    const json_t *v[STN_NKEYS]; /* stn_keys[k]'s value, or NULL */
    unsigned mask;              /* bits of the keys present */
    int other;                  /* some key is neither "s" nor a station key */
} stn_view;

static void stn_view_of(const json_t *st, stn_view *w)
{
    const char *key;
    json_t *val;

    memset(w, 0, sizeof(*w));
    json_object_foreach((json_t *)st, key, val) {
        int k = stn_index(key);
        if (k == STN_S) {
            w->s = val;
        } else if (k == STN_OTHER) {
            w->other = 1;
        } else {
            w->v[k] = val;
            w->mask |= stn_keys[k].bit;
        }
    }
}

/* Mask of the station keys present in the object st (0 when not an object). */
static unsigned stn_mask_of(const json_t *st)
{
    stn_view w;

    stn_view_of(st, &w); /* json_object_foreach: nothing for a value that is not an object */
    return w.mask;
}

unsigned stn_keys_mask(const json_t *stations)
{
    const json_t *st;
    unsigned m = 0;
    size_t j;

    json_array_foreach(stations, j, st)
        m |= stn_mask_of(st);
    return m;
}

unsigned stn_section_bit(const char *key)
{
    size_t k;

    for (k = 0; k < STN_NKEYS; k++)
        if (!strcmp(stn_keys[k].name, key))
            return stn_keys[k].bit;
    return 0;
}

json_t *stn_cover(const json_t *members)
{
    json_t *cover = json_object(), *seen;
    const json_t *mem;
    size_t i;

    if (!cover)
        return NULL;
    json_array_foreach(members, i, mem) {
        const char *sec = json_string_value(json_object_get(mem, "section"));
        unsigned m;
        if (!sec)
            continue;
        m = stn_keys_mask(json_object_get(mem, "stations"));
        seen = json_object_get(cover, sec);
        if (seen) /* every member using the section must give it */
            m &= (unsigned)json_integer_value(seen);
        if (json_object_set_new(cover, sec, json_integer((json_int_t)m))) {
            json_decref(cover);
            return NULL;
        }
    }
    return cover;
}

/* s of station j at p (x its value, NULL when absent): a number in [0, 1], first 0, last 1,
 * above the previous *prev. */
static int stn_s(val_ctx *v, const json_t *x, const char *p, size_t j, size_t n, double *prev)
{
    double s;

    if (!x) {
        field_error_key(v, p, "s", "required field 's' (the span fraction, 0 at the member's "
                        "'from' joint, 1 at 'to') is missing");
        return 0;
    }
    if (!field_real_at(v, x, "s", p, NULL, FIELD_FINITE, "", &s))
        return 0;
    if (s < 0 || s > 1) {
        field_error_key(v, p, "s", "s = %g is outside [0, 1]: s is the span fraction (0 at "
                        "the member's 'from' joint, 1 at 'to')", s);
        return 0;
    }
    if (j == 0 && s != 0) {
        field_error_key(v, p, "s", "the first station must be at s = 0 (the member's 'from' "
                        "joint), not %g", s);
        return 0;
    }
    if (j == n - 1 && s != 1) {
        field_error_key(v, p, "s", "the last station must be at s = 1 (the member's 'to' "
                        "joint), not %g", s);
        return 0;
    }
    if (j > 0 && !(s > *prev)) {
        field_error_key(v, p, "s", "s = %g does not increase (the previous station is at %g): "
                        "list the stations from root to tip, each s once", s, *prev);
        *prev = fmax(*prev, s);
        return 0;
    }
    *prev = s;
    return 1;
}

/* Keys of station st (seen as w) at p: the material form, and the keys of union missing. */
static void stn_station_keys(val_ctx *v, const json_t *st, const stn_view *w, const char *p,
                             unsigned all)
{
    size_t k;

    for (k = 0; w->other && stn_material[k]; k++)
        if (json_object_get(st, stn_material[k]))
            field_error_key(v, p, stn_material[k],
                            "stations give the stiffness form only: use EA, EI_flap, EI_edge, "
                            "GJ (N, N m^2) instead of '%s'", stn_material[k]);
    for (k = 0; k < STN_NKEYS; k++)
        if ((all & stn_keys[k].bit) && !w->v[k])
            field_error(v, p, "missing '%s': another station of this member gives it, so "
                        "every station must (the value is interpolated between stations)",
                        stn_keys[k].name);
}

/* Station j (an object) at p: checked into its canonical copy c; 1 when valid. */
static int stn_station(val_ctx *v, const json_t *st, const char *p, size_t j, size_t n,
                       unsigned all, double *prev, json_t *c)
{
    size_t k, before = (size_t)codec_errors_count(v->errs);
    double s = 0, x[2];
    stn_view w;

    stn_view_of(st, &w);
    /* unknown keys (only where some key is not a station key); material keys get their own
     * message (stn_station_keys) */
    if (w.other)
        field_check_keys_but(v, st, p, stn_allowed, stn_material, "station");
    stn_station_keys(v, st, &w, p, all);
    if (stn_s(v, w.s, p, j, n, prev))
        s = *prev;
    field_set(v, c, "s", json_real(s));
    for (k = 0; k < STN_NKEYS; k++) {
        const stn_key *q = &stn_keys[k];
        if (!w.v[k])
            continue;
        if (q->n == 1)
            field_real_at(v, w.v[k], q->name, p, c, q->kind, q->unit, NULL);
        else if (field_vector_at(v, w.v[k], q->name, p, q->n, q->kind, "[edgewise, flapwise]",
                                 q->unit, x))
            field_set(v, c, q->name, field_reals(x, q->n));
    }
    return (size_t)codec_errors_count(v->errs) == before;
}

/* A number of a canonical object, or def when absent. */
static double stn_num(const json_t *obj, const char *key, double def)
{
    double d = def;

    field_number(json_object_get(obj, key), &d);
    return d;
}

/*
 * The per-station default mass moments (DESIGN.md 7.3, per station): for
 * flap (k = 0) and edge (k = 1), when no station gives the moment, the
 * member's section does not give it explicitly (sec_in), and the stations
 * change mass_per_length, EA or that EI: moment = mu*EI/EA at each station,
 * each factor from the station or the canonical section sec.
 */
static void stn_default_inertias(val_ctx *v, json_t *cs, unsigned mask, const json_t *sec_in,
                                 const json_t *sec, const char *p)
{
    static const char *const moment[] = {"flap_inertia", "edge_inertia"};
    static const char *const ei[] = {"EI_flap", "EI_edge"};
    static const unsigned ei_bit[] = {SM_ST_EI_FLAP, SM_ST_EI_EDGE};
    json_t *st;
    size_t j;
    int k;

    for (k = 0; k < 2; k++) {
        if ((mask & stn_section_bit(moment[k])) || json_object_get(sec_in, moment[k]) ||
            !(mask & (SM_ST_MU | SM_ST_EA | ei_bit[k])))
            continue;
        json_array_foreach(cs, j, st) {
            double mu = stn_num(st, "mass_per_length", stn_num(sec, "mass_per_length", 0));
            double EA = stn_num(st, "EA", stn_num(sec, "EA", 0));
            double EI = stn_num(st, ei[k], stn_num(sec, ei[k], 0));
            double d = mu * EI / EA;
            if (!(isfinite(d) && d >= DBL_MIN)) {
                field_error(v, p, "the default %s = mass_per_length*%s/EA = %g at station %zu "
                            "is not a number the numerics can carry: give %s (kg m) at every "
                            "station", moment[k], ei[k], d, j, moment[k]);
                break;
            }
            field_set(v, st, moment[k], json_real(d));
        }
    }
}

void stn_validate(val_ctx *v, const json_t *mem, const char *p, json_t *c)
{
    const json_t *sts = json_object_get(mem, "stations"), *st;
    const char *sec = json_string_value(json_object_get(mem, "section"));
    char *base = err_ptr_key(p, "stations");
    size_t j, n = json_array_size(sts);
    unsigned all = stn_keys_mask(sts);
    double prev = 0;
    json_t *cs;
    int ok = 1;

    if (!base) {
        v->nomem = 1;
        return;
    }
    if (!json_is_array(sts) || n < 2 || n > CODEC_MAX_STATIONS) {
        if (!json_is_array(sts))
            field_error(v, base, "must be an array of stations {\"s\": ..., ...}, not %s",
                        field_type_name(sts));
        else if (n < 2)
            field_error(v, base, "must list at least 2 stations (s = 0 and s = 1), got %zu", n);
        else
            field_error(v, base, "too many stations (%zu): the limit is %d", n,
                        CODEC_MAX_STATIONS);
        free(base);
        return;
    }
    if (!(cs = json_array()))
        v->nomem = 1;
    json_array_foreach(sts, j, st) {
        char *pj = err_ptr_idx(base, j);
        json_t *cj = json_object();
        if (!pj || !cj) {
            v->nomem = 1;
            free(pj);
            json_decref(cj);
            break;
        }
        if (!json_is_object(st)) {
            field_error(v, pj, "must be an object {\"s\": ..., ...}, not %s", field_type_name(st));
            ok = 0;
        } else if (!stn_station(v, st, pj, j, n, all, &prev, cj)) {
            ok = 0;
        }
        free(pj);
        if (cs && json_array_append_new(cs, cj))
            v->nomem = 1;
        else if (!cs)
            json_decref(cj);
    }
    if (ok && cs && sec)
        stn_default_inertias(v, cs, all, json_object_get(v->in_sections, sec),
                             json_object_get(v->canon_sections, sec), base);
    free(base);
    field_set(v, c, "stations", cs);
}

/* Degrees to radians for the angle keys, else the value as it is. */
static double stn_value(const stn_key *q, double x)
{
    return q->bit == SM_ST_TWIST || q->bit == SM_ST_INERTIA_TWIST ? x * CODEC_RAD_PER_DEG : x;
}

unsigned stn_fill(const json_t *stations, sm_station *out)
{
    const json_t *st;
    unsigned mask = 0;
    size_t j, k;
    int i;

    json_array_foreach(stations, j, st) {
        stn_view w;
        stn_view_of(st, &w);
        mask |= w.mask;
        memset(&out[j], 0, sizeof(out[j]));
        out[j].s = json_number_value(w.s); /* canonical: reals (0 when absent) */
        for (k = 0; k < STN_NKEYS; k++) {
            const stn_key *q = &stn_keys[k];
            double *dst = (double *)((char *)&out[j] + q->off);
            for (i = 0; w.v[k] && i < q->n; i++)
                dst[i] = stn_value(
                    q, json_number_value(q->n == 1 ? w.v[k] : json_array_get(w.v[k], (size_t)i)));
        }
    }
    return mask;
}
