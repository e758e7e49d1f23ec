/*
 * size.c — how big a request's result will be, known before it is accepted.
 *
 * How it fits: validate.c calls size_check once the analysis and the
 * structure are checked.  From the request's counts alone (speeds, modes,
 * FE nodes, joints, members, engine orders, Coriolis, mode_shapes) it
 * estimates the result document of DESIGN.md section 4 as result.c writes
 * it (compact, reals with 17 significant digits) and the mode-shape numbers
 * the solver holds for it, and refuses a request over max_result_bytes or
 * max_shape_values with a 422 that names the part to reduce and says how
 * (fewer speeds with shapes, shapes off, fewer modes, fewer speeds or
 * elements), with the estimate and the limit.
 *
 * The estimate is meant to be at least the document's size: every real
 * counts the most "%.17g" prints, and every sentence the most the core
 * writes.  Measured on a spatial 2,000-element blade, 27 speeds x 6 modes
 * with shapes: 93.7 MB written, 99.4 MB estimated.  Parts the counts do not
 * bound exactly are counted at a generous rate: critical speeds (one
 * crossing of each tracked mode with each engine order line, counted twice),
 * input warnings (a few sentences per section, member, point mass and
 * station).  Helpers of this file are size_*.
 */
#include "codec_internal.h"

#include <stdio.h>
#include <string.h>

/* Bytes of the parts of a result document (result.c, compact). */
#define SIZE_NUMBER 25.0      /* a real as "%.17g": at most 24 characters
                                 (-1.2345678901234567e-308), and its comma */
#define SIZE_ROW 3.0          /* "[", "]" and "," around the numbers of one node */
#define SIZE_MODE 800.0       /* a mode without its shape: frequencies, eigenvalue, MAC,
                                 per_rev, label, energy, tracking, error_estimate (about 16
                                 numbers, their keys and a label) */
#define SIZE_SHAPE_KEYS 40.0  /* "shape":{"re":[],"im":[]} of one mode */
#define SIZE_CASE 1400.0      /* a speed without its modes and equilibrium arrays: omega,
                                 status, stability, rpm, and a warning and a diagnostics
                                 sentence (at most 256 bytes each in the core) */
#define SIZE_EQUILIBRIUM 200.0 /* the equilibrium's keys and scalars */
#define SIZE_CRITICAL 500.0   /* one critical speed (13 members) */
#define SIZE_DIVERGENCE 400.0 /* one divergence speed (at most one between two speeds) */
#define SIZE_LAYOUT 600.0     /* one member's layout without its node arrays */
#define SIZE_WARNING 1536.0   /* input warnings per section, member, point mass, station */
#define SIZE_DOCUMENT 4096.0  /* solver, model sizes, timing */

/* The estimate of one request's result. */
typedef struct size_est {
    double speeds, modes, nodes, elements; /* counts of the request */
    int dof;                  /* numbers per node: 3 planar, 6 spatial */
    int parts;                /* shapes per mode: 2 with Coriolis (re, im), else 1 */
    int shapes;               /* analysis.mode_shapes */
    double shape_values;      /* numbers of the mode shapes (0 without them) */
    double shape_bytes;       /* bytes of the mode shapes */
    double equilibrium_bytes; /* bytes of the equilibria (every node at every speed) */
    double mode_bytes;        /* bytes of the modes without their shapes */
    double total;             /* bytes of the whole document */
} size_est;

/* bytes as "12.3 MB" (kB, GB; decimal) or "512 bytes" into buf. */
static const char *size_text(double bytes, char buf[32])
{
    if (bytes >= 1e9)
        snprintf(buf, 32, "%.1f GB", bytes / 1e9);
    else if (bytes >= 1e6)
        snprintf(buf, 32, "%.1f MB", bytes / 1e6);
    else if (bytes >= 1e3)
        snprintf(buf, 32, "%.1f kB", bytes / 1e3);
    else
        snprintf(buf, 32, "%.0f bytes", bytes);
    return buf;
}

/* Bytes of s as a JSON string with its quotes (control characters at their longest, \u00XX). */
static double size_string(const char *s)
{
    double n = 2;

    for (; s && *s; s++) {
        unsigned char c = (unsigned char)*s;
        n += c == '"' || c == '\\' ? 2 : c < 0x20 ? 6 : 1;
    }
    return n;
}

/* Bytes of one case's "joints": {"name": [numbers], ...} of the canonical structure st. */
static double size_joints(const json_t *st, double node_bytes)
{
    const json_t *joints = json_object_get(st, "joints"), *xy;
    const char *name;
    double n = 2;

    json_object_foreach((json_t *)joints, name, xy) {
        (void)xy;
        n += size_string(name) + 1 + node_bytes;
    }
    return n;
}

/*
 * Bytes outside the cases' arrays: the document's fixed members, the member layouts
 * (spatial, with shapes), critical and divergence speeds, input warnings.
 */
static double size_rest(const size_est *e, const json_t *an, const json_t *st)
{
    const json_t *mems = json_object_get(st, "members"), *mem;
    double items = (double)json_object_size(json_object_get(st, "sections")) +
                   (double)json_array_size(json_object_get(st, "point_masses"));
    double orders = (double)json_array_size(json_object_get(an, "engine_orders"));
    double n = SIZE_DOCUMENT + e->speeds * SIZE_CASE;
    size_t i;

    json_array_foreach(mems, i, mem) {
        items += 1 + (double)json_array_size(json_object_get(mem, "stations"));
        if (e->dof == 6 && e->shapes) /* "model"."members": axes, nodes, s, twist_deg */
            n += SIZE_LAYOUT + size_string(json_string_value(json_object_get(mem, "id"))) +
                 3 * SIZE_NUMBER *
                     (1 + (double)json_integer_value(json_object_get(mem, "elements")));
    }
    n += items * SIZE_WARNING;
    n += 2 * orders * e->modes * SIZE_CRITICAL;
    n += (e->speeds > 1 ? e->speeds - 1 : 0) * SIZE_DIVERGENCE;
    return n;
}

/* The estimate of the canonical request canon with canonical structure st. */
static void size_estimate(const val_ctx *v, const json_t *canon, const json_t *st, size_est *e)
{
    const json_t *an = json_object_get(canon, "analysis");
    double node_bytes, values;

    memset(e, 0, sizeof(*e));
    e->speeds = (double)spd_count(an);
    e->modes = (double)json_integer_value(json_object_get(an, "modes"));
    e->elements = (double)v->total_elements;
    e->nodes = e->elements + 1; /* a tree of elements */
    e->dof = v->spatial == 1 ? 6 : 3;
    e->parts = json_is_true(json_object_get(an, "coriolis")) ? 2 : 1;
    e->shapes = json_is_true(json_object_get(an, "mode_shapes"));
    node_bytes = e->dof * SIZE_NUMBER + SIZE_ROW;
    values = e->speeds * e->modes * e->nodes * e->dof * e->parts;
    if (e->shapes) {
        e->shape_values = values;
        e->shape_bytes = e->speeds * e->modes *
                         (e->parts * (e->nodes * node_bytes + SIZE_ROW) + SIZE_SHAPE_KEYS);
    }
    e->equilibrium_bytes = e->speeds * (SIZE_EQUILIBRIUM + e->nodes * node_bytes +
                                        e->elements * SIZE_NUMBER + size_joints(st, node_bytes));
    e->mode_bytes = e->speeds * e->modes * SIZE_MODE;
    e->total = e->shape_bytes + e->equilibrium_bytes + e->mode_bytes + size_rest(e, an, st);
}

/*
 * The estimate over max_result_bytes: one error at the field to change, for the largest
 * part (shapes, the equilibria of every speed, or the modes).  Returns 1 when the error
 * points at /analysis/mode_shapes.
 */
static int size_too_big(val_ctx *v, const json_t *canon, const size_est *e)
{
    const json_t *an = json_object_get(canon, "analysis");
    const char *speeds = json_object_get(an, "rpm") ? "/analysis/rpm" : "/analysis/omega";
    char head[200], a[32], b[32], c[32];

    snprintf(head, sizeof(head), "the result would be about %s, more than the limit of %s "
             "(%zu bytes)", size_text(e->total, a),
             size_text((double)v->lim->max_result_bytes, b), v->lim->max_result_bytes);
    if (e->shape_bytes >= e->equilibrium_bytes && e->shape_bytes >= e->mode_bytes) {
        field_error(v, "/analysis/mode_shapes",
                    "%s: its mode shapes alone are %.0f speeds x %.0f modes x %.0f nodes x %d "
                    "numbers (%.0f numbers, about %s); ask for the shapes at fewer speeds (this "
                    "sweep with mode_shapes false, and the few speeds whose shapes you need in "
                    "a second request), set mode_shapes to false, or ask for fewer modes or "
                    "elements", head, e->speeds, e->modes, e->nodes, e->dof * e->parts,
                    e->shape_values, size_text(e->shape_bytes, c));
        return 1;
    }
    if (e->equilibrium_bytes >= e->mode_bytes)
        field_error(v, speeds,
                    "%s: the steady state of its %.0f nodes at each of %.0f speeds is about %s "
                    "of it; ask for fewer speeds or fewer elements", head, e->nodes, e->speeds,
                    size_text(e->equilibrium_bytes, c));
    else
        field_error(v, "/analysis/modes",
                    "%s: %.0f speeds x %.0f modes are about %s of it without shapes; ask for "
                    "fewer modes or fewer speeds", head, e->speeds, e->modes,
                    size_text(e->mode_bytes, c));
    return 0;
}

void size_check(val_ctx *v, const json_t *canon, const json_t *structure)
{
    size_est e;
    int at_shapes = 0;

    size_estimate(v, canon, structure, &e);
    if (v->lim->max_result_bytes > 0 && e.total > (double)v->lim->max_result_bytes)
        at_shapes = size_too_big(v, canon, &e);
    if (at_shapes || !(e.shape_values > (double)v->lim->max_shape_values))
        return;
    field_error(v, "/analysis/mode_shapes",
                "mode shapes for %.0f speeds x %.0f modes x %.0f nodes "
                "would be %.0f numbers: the limit is %ld; set mode_shapes to false or ask for "
                "fewer speeds or modes", e.speeds, e.modes, e.nodes, e.shape_values,
                v->lim->max_shape_values);
}
