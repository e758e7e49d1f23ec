/*
 * spanwise.c — span-wise mode shapes from a result document: CSV and a
 * BModes-style text table (DESIGN.md 8.3).
 *
 * How it fits: a spatial result with mode shapes carries, under
 * "model.members", each member's FE nodes from its `from` joint (s = 0) to
 * its `to` joint (s = 1), their span fractions, the member's length and its
 * axes without twist [e1, e2, e3] (result.c): e3 is the flap direction, e2
 * edgewise (for a blade, out of and in the rotor plane, as BModes' flap and
 * lag; the structural twist turns the principal axes away from them, so
 * these are the directions whose slopes are the derivatives of the
 * displacements).  This file projects each mode's nodal motion (hub frame):
 *   flap  = d . e3      flap_slope = -(r . e2) L   (d flap / d s)
 *   edge  = d . e2      edge_slope =  (r . e3) L   (d edge / d s)
 *   twist = r . e1      axial      =  d . e1
 * with d the displacement and r the small rotation of the node.  The CSV's
 * columns: omega (rad/s), rpm, mode (1-based), frequency_hz, per_rev,
 * member (0-based index), member_id, s (span fraction, 0 at the member's
 * `from` joint, 1 at its `to` joint), span_m = s x the member's length (m
 * from the `from` joint: for a blade from its root, not from the spin axis,
 * whose distance is blade.hub_radius + span_m on a blade without precone;
 * before 0.8 this column was named r_m), then the six motions above.  It reads
 * nothing but the result document, so the CLI (`spinmodal export`) and the
 * daemon (GET .../result?format=spanwise|bmodes, from the stored result)
 * give the same bytes.
 *
 * Each mode is shown in one phase and one scale, as shape tables are: a
 * complex (Coriolis) mode is turned so that its largest flap or edge
 * displacement is real and positive, and every mode is scaled so that this
 * displacement is 1 m (for a mode without bending motion, its largest twist
 * 1 rad).  The real parts are written: the CSV in m and rad for that scale
 * (slopes in m per unit span fraction).  The BModes-style table uses BModes'
 * columns and signs (BldVib.f90:860-905; checked against its CertTest):
 * displacements over the member length (BModes divides by the rotor
 * radius), slopes dw/dx, lag = -edge (positive against the rotation),
 * twist = -(rotation about e1).  The scale and phase are presentation only:
 * the result document keeps the solver's shapes.
 */
#include "codec_internal.h"

#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* One node's projected motion: flap, flap slope, edge, edge slope, twist, axial. */
enum { SW_FLAP, SW_FLAP_SLOPE, SW_EDGE, SW_EDGE_SLOPE, SW_TWIST, SW_AXIAL, SW_N };

static double sw_dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Row k (6 numbers) of a shape part ([[dx, dy, dz, rx, ry, rz], ...]), 0 when absent. */
static void sw_row(const json_t *part, json_int_t node, double v[6])
{
    const json_t *row = json_array_get(part, (size_t)node);
    int k;

    for (k = 0; k < 6; k++)
        v[k] = json_number_value(json_array_get(row, (size_t)k));
}

/* The projected motion of one member layout's node k for a mode shape (re, im: may be NULL). */
static void sw_project(const json_t *layout, size_t k, const json_t *re, const json_t *im,
                       double complex out[SW_N])
{
    const json_t *ax = json_object_get(layout, "axes");
    json_int_t node = json_integer_value(json_array_get(json_object_get(layout, "nodes"), k));
    double L = json_number_value(json_object_get(layout, "length"));
    double a[9], vr[6], vi[6];
    int c;

    for (c = 0; c < 9; c++)
        a[c] = json_number_value(json_array_get(ax, (size_t)c));
    sw_row(re, node, vr);
    if (im)
        sw_row(im, node, vi);
    else
        memset(vi, 0, sizeof vi);
    /* a = [e1 | e2 | e3] */
    out[SW_FLAP] = sw_dot(vr, a + 6) + I * sw_dot(vi, a + 6);
    out[SW_EDGE] = sw_dot(vr, a + 3) + I * sw_dot(vi, a + 3);
    out[SW_AXIAL] = sw_dot(vr, a) + I * sw_dot(vi, a);
    out[SW_TWIST] = sw_dot(vr + 3, a) + I * sw_dot(vi + 3, a);
    out[SW_FLAP_SLOPE] = -L * (sw_dot(vr + 3, a + 3) + I * sw_dot(vi + 3, a + 3));
    out[SW_EDGE_SLOPE] = L * (sw_dot(vr + 3, a + 6) + I * sw_dot(vi + 3, a + 6));
}

/*
 * The factor that shows a mode in its table phase and scale: 1 / (its largest flap or edge
 * displacement over all members), or of its largest twist when it has no bending motion
 * (below 1e-9 of the twist, in m per rad); 0 for a zero shape.
 */
static double complex sw_scale(const json_t *members, const json_t *re, const json_t *im)
{
    double complex best = 0, best_tw = 0, v[SW_N];
    const json_t *lay;
    size_t i, k;

    json_array_foreach(members, i, lay) {
        size_t n = json_array_size(json_object_get(lay, "nodes"));
        for (k = 0; k < n; k++) {
            sw_project(lay, k, re, im, v);
            if (cabs(v[SW_FLAP]) > cabs(best))
                best = v[SW_FLAP];
            if (cabs(v[SW_EDGE]) > cabs(best))
                best = v[SW_EDGE];
            if (cabs(v[SW_TWIST]) > cabs(best_tw))
                best_tw = v[SW_TWIST];
        }
    }
    if (cabs(best) <= 1e-9 * cabs(best_tw))
        best = best_tw;
    return cabs(best) > 0 ? 1.0 / best : 0;
}

/* A CSV number: full precision, empty when not finite. */
static void sw_num(FILE *f, double x)
{
    if (isfinite(x))
        fprintf(f, "%.17g", x + 0.0); /* + 0.0: no "-0" */
}

/* The member's id as CSV text (ids are names: quoted when they hold a comma or quote). */
static void sw_id(FILE *f, const json_t *id)
{
    const char *s = json_string_value(id), *p;

    if (!s)
        return;
    if (!strpbrk(s, ",\"\n\r")) {
        fputs(s, f);
        return;
    }
    fputc('"', f);
    for (p = s; *p; p++) {
        if (*p == '"')
            fputc('"', f);
        fputc(*p, f);
    }
    fputc('"', f);
}

/* rpm of a case: its "rpm", else omega * 60 / 2 pi. */
static double sw_rpm(const json_t *cs)
{
    const json_t *rpm = json_object_get(cs, "rpm");

    return json_is_number(rpm) ? json_number_value(rpm)
                               : json_number_value(json_object_get(cs, "omega")) * 60 /
                                     CODEC_TWO_PI;
}

static void sw_csv_mode(FILE *f, const json_t *members, const json_t *cs, size_t mi,
                        const json_t *mode)
{
    const json_t *shape = json_object_get(mode, "shape"), *lay;
    const json_t *re = json_object_get(shape, "re"), *im = json_object_get(shape, "im");
    double complex sc = sw_scale(members, re, im), v[SW_N];
    double hz = json_number_value(json_object_get(mode, "frequency_hz"));
    const json_t *pr = json_object_get(mode, "per_rev");
    size_t i, k;
    int c;

    json_array_foreach(members, i, lay) {
        size_t n = json_array_size(json_object_get(lay, "nodes"));
        double L = json_number_value(json_object_get(lay, "length"));
        for (k = 0; k < n; k++) {
            double s = json_number_value(json_array_get(json_object_get(lay, "s"), k));
            sw_project(lay, k, re, im, v);
            sw_num(f, json_number_value(json_object_get(cs, "omega")));
            fputc(',', f);
            sw_num(f, sw_rpm(cs));
            fprintf(f, ",%zu,", mi + 1);
            sw_num(f, hz);
            fputc(',', f);
            if (json_is_number(pr))
                sw_num(f, json_number_value(pr));
            fprintf(f, ",%" JSON_INTEGER_FORMAT ",",
                    json_integer_value(json_object_get(lay, "member")));
            sw_id(f, json_object_get(lay, "id"));
            fputc(',', f);
            sw_num(f, s);
            fputc(',', f);
            sw_num(f, s * L);
            for (c = 0; c < SW_N; c++) {
                fputc(',', f);
                sw_num(f, creal(v[c] * sc));
            }
            fputc('\n', f);
        }
    }
}

/* The BModes-style block of one mode (BModes' .out layout: tab-separated, six decimals). */
static void sw_bmodes_mode(FILE *f, const json_t *members, size_t mi, const json_t *mode)
{
    const json_t *shape = json_object_get(mode, "shape"), *lay;
    const json_t *re = json_object_get(shape, "re"), *im = json_object_get(shape, "im");
    double complex sc = sw_scale(members, re, im), v[SW_N];
    size_t i, k;

    fprintf(f, "\n -------- Mode No. %3zu  (freq = %.5E Hz)\n",
            mi + 1, json_number_value(json_object_get(mode, "frequency_hz")));
    json_array_foreach(members, i, lay) {
        size_t n = json_array_size(json_object_get(lay, "nodes"));
        const char *id = json_string_value(json_object_get(lay, "id"));
        if (json_array_size(members) > 1) {
            fprintf(f, "\n member %" JSON_INTEGER_FORMAT,
                    json_integer_value(json_object_get(lay, "member")));
            if (id)
                fprintf(f, " (%s)", id);
            fputc('\n', f);
        }
        fputs("\nspan_loc\tflap disp\tflap slope\tlag disp\tlag slope\ttwist\n\n", f);
        double L = json_number_value(json_object_get(lay, "length"));
        for (k = 0; k < n; k++) {
            double s = json_number_value(json_array_get(json_object_get(lay, "s"), k));
            sw_project(lay, k, re, im, v);
            /* BModes' columns: displacements / length, slopes d(w/L)/d(x/L) = dw/dx, lag
             * against the rotation (-edge), twist in BModes' sense (-rotation about e1) */
            fprintf(f, "%7.4f\t%9.6f\t%9.6f\t%9.6f\t%9.6f\t%9.6f\n", s,
                    creal(v[SW_FLAP] * sc) + 0.0, creal(v[SW_FLAP_SLOPE] * sc) + 0.0,
                    -creal(v[SW_EDGE] * sc) + 0.0, -creal(v[SW_EDGE_SLOPE] * sc) + 0.0,
                    -L * creal(v[SW_TWIST] * sc) + 0.0);
        }
    }
    fputc('\n', f);
}

int codec_result_spanwise(char **out, size_t *len, const json_t *result, int bmodes,
                          char *err, size_t errcap)
{
    const json_t *model = json_object_get(result, "model"), *cases, *cs, *modes, *mode;
    json_t *members = json_array(), *lay;
    char *buf = NULL;
    size_t n = 0, i, k;
    FILE *f;

    *out = NULL;
    if (err && errcap)
        err[0] = '\0';
    if (!members)
        return SM_NOMEM;
    json_array_foreach(json_object_get(model, "members"), i, lay)
        if (json_is_object(lay) && json_array_size(json_object_get(lay, "nodes")) >= 2)
            json_array_append(members, lay);
    if (!json_is_true(json_object_get(model, "spatial")) || !json_array_size(members)) {
        json_decref(members);
        if (err)
            snprintf(err, errcap, "span-wise shapes need a spatial result with mode shapes "
                                  "(\"mode_shapes\": true; a planar structure has no flap "
                                  "or twist)");
        return SM_INVALID_INPUT;
    }
    f = open_memstream(&buf, &n);
    if (!f) {
        json_decref(members);
        return SM_NOMEM;
    }
    cases = json_object_get(result, "cases");
    if (bmodes)
        fprintf(f, "spinmodal %s span-wise mode shapes (BModes layout)\nrequest %s\n"
                   "flap disp = displacement along e3 (out of the rotor plane), lag disp = "
                   "against e2 (in it, against the rotation), both over the member length; slopes d(disp)/d(span_loc); "
                   "twist = rotation about -e1 (rad), as BModes; each mode scaled so that "
                   "its largest flap or lag displacement is 1\n"
                   "=================================================================="
                   "===============\n",
                json_string_value(json_object_get(json_object_get(result, "solver"),
                                                  "version")),
                json_string_value(json_object_get(json_object_get(result, "solver"),
                                                  "request_sha256")));
    else
        fputs("omega,rpm,mode,frequency_hz,per_rev,member,member_id,s,span_m,flap,flap_slope,"
              "edge,edge_slope,twist,axial\n", f);
    json_array_foreach(cases, i, cs) {
        modes = json_object_get(cs, "modes");
        if (bmodes)
            fprintf(f, "\n\n            rotating blade frequencies & mode shapes at %.6g rpm "
                       "(%.6g rad/s), %s\n",
                    sw_rpm(cs), json_number_value(json_object_get(cs, "omega")),
                    json_string_value(json_object_get(cs, "status")));
        json_array_foreach(modes, k, mode) {
            if (!json_object_get(json_object_get(mode, "shape"), "re"))
                continue;
            if (bmodes)
                sw_bmodes_mode(f, members, k, mode);
            else
                sw_csv_mode(f, members, cs, k, mode);
        }
    }
    json_decref(members);
    return codec_memstream_done(f, &buf, &n, out, len);
}
