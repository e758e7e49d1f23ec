/*
 * elastodyn_text.c — ElastoDyn blade mode-shape coefficients from a result document
 * (DESIGN.md 9.3): GET .../result?format=elastodyn and `spinmodal export elastodyn`.
 *
 * How it fits: a spatial result with mode shapes carries under "model.members" each
 * member's FE nodes (root first), span fractions, twist and axes without twist (result.c),
 * and each mode its shape and energy split (labels).  This file gathers the blade member's
 * node rows of every mode, lets the core project them on the principal axes
 * (sm_elastodyn_project) and select and fit (sm_elastodyn_fit_modes, want {2, 1}: the
 * numerics are the core's, DESIGN §B), then writes the ElastoDyn lines.  A tower form's
 * member ("tower") gives TwFAM1Sh, TwFAM2Sh, TwSSM1Sh, TwSSM2Sh the same way (flap = fore-aft,
 * edge = side-side, DESIGN.md 8.5; want {2, 2}), after the root's rigid motion is taken out
 * and a degenerate fore-aft/side-side pair is turned to pure directions (the core's
 * sm_elastodyn_degenerate).  It reads nothing but
 * the document, so the daemon (from the stored result) and the CLI give the same bytes, and
 * elastodyn_patch.c writes the same values into a deck.  Helpers are edt_*.
 */
#include "codec_internal.h"
#include "elastodyn.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *const codec_ed_blade_names[CODEC_ED_BLADE_VALUES] = {
    "BldFl1Sh(2)", "BldFl1Sh(3)", "BldFl1Sh(4)", "BldFl1Sh(5)", "BldFl1Sh(6)",
    "BldFl2Sh(2)", "BldFl2Sh(3)", "BldFl2Sh(4)", "BldFl2Sh(5)", "BldFl2Sh(6)",
    "BldEdgSh(2)", "BldEdgSh(3)", "BldEdgSh(4)", "BldEdgSh(5)", "BldEdgSh(6)",
};

const char *const codec_ed_tower_names[CODEC_ED_TOWER_VALUES] = {
    "TwFAM1Sh(2)", "TwFAM1Sh(3)", "TwFAM1Sh(4)", "TwFAM1Sh(5)", "TwFAM1Sh(6)",
    "TwFAM2Sh(2)", "TwFAM2Sh(3)", "TwFAM2Sh(4)", "TwFAM2Sh(5)", "TwFAM2Sh(6)",
    "TwSSM1Sh(2)", "TwSSM1Sh(3)", "TwSSM1Sh(4)", "TwSSM1Sh(5)", "TwSSM1Sh(6)",
    "TwSSM2Sh(2)", "TwSSM2Sh(3)", "TwSSM2Sh(4)", "TwSSM2Sh(5)", "TwSSM2Sh(6)",
};

/* The deck name, the NREL description and the direction word of each fit. */
typedef struct edt_name {
    const char *name, *what, *dir;
} edt_name;

static const edt_name edt_blade[SM_ED_BLADE_FITS] = {
    {"BldFl1Sh", "Flap mode 1", "flap"},
    {"BldFl2Sh", "Flap mode 2", "flap"},
    {"BldEdgSh", "Edge mode 1", "edge"},
};

/* The tower's, in the tower file's order (fore-aft = the form's flap, DESIGN.md 8.5). */
static const edt_name edt_tower[CODEC_ED_TOWER_FITS] = {
    {"TwFAM1Sh", "Mode 1", "fore-aft"},
    {"TwFAM2Sh", "Mode 2", "fore-aft"},
    {"TwSSM1Sh", "Mode 1", "side-side"},
    {"TwSSM2Sh", "Mode 2", "side-side"},
};

/* What codec_elastodyn_case reads out of a document (borrowed pointers, owned arrays). */
typedef struct edt_input {
    const json_t *layout; /* the blade (or tower) member's layout */
    int n;                /* its nodes */
    int tower;            /* 1: the tower form's member (fore-aft, side-side; want {2, 2}) */
    double ax[9], length;
    double *x, *twist; /* n each */
    json_t *own;       /* a wired tower's members joined into one layout (layout), or NULL */
} edt_input;

static void edt_input_clear(edt_input *in)
{
    free(in->x);
    free(in->twist);
    json_decref(in->own);
    memset(in, 0, sizeof *in);
}

static int edt_err(char *err, size_t errcap, const char *msg)
{
    if (err && errcap)
        snprintf(err, errcap, "%s", msg);
    return SM_INVALID_INPUT;
}

/* A wired tower's members (tower_1 ... tower_k in the request, each "tower" in the result's
 * model; base to top, cut at the wires: DESIGN.md 8.6)
 * as one layout "tower" (new): their nodes in order (each shared joint once), s over the whole
 * flexible length, the axes of the first (they are collinear, flap_direction fa); NULL when
 * mems are not such members. */
static json_t *edt_join_tower(const json_t *mems)
{
    const json_t *lay;
    json_t *nodes = json_array(), *s = json_array(), *tw = json_array(), *out = NULL;
    double total = 0, acc = 0;
    size_t i, j;

    json_array_foreach(mems, i, lay) { /* each "tower" (result.c), joined end to start */
        const char *id = json_string_value(json_object_get(lay, "id"));
        const json_t *nd = json_object_get(lay, "nodes");
        const json_t *prev = i ? json_object_get(json_array_get(mems, i - 1), "nodes") : NULL;
        if (!id || strcmp(id, "tower") ||
            (prev &&
             !json_equal(json_array_get(prev, json_array_size(prev) - 1), json_array_get(nd, 0))))
            goto done;
        total += json_number_value(json_object_get(lay, "length"));
    }
    if (!nodes || !s || !tw || json_array_size(mems) < 2 || !(total > 0))
        goto done;
    json_array_foreach(mems, i, lay) {
        const json_t *nd = json_object_get(lay, "nodes"), *ss = json_object_get(lay, "s");
        double L = json_number_value(json_object_get(lay, "length"));
        for (j = i ? 1 : 0; j < json_array_size(nd); j++)
            if (json_array_append(nodes, json_array_get(nd, j)) ||
                json_array_append_new(
                    s, json_real((acc + json_number_value(json_array_get(ss, j)) * L) / total)) ||
                json_array_append_new(tw, json_real(0.0)))
                goto done;
        acc += L;
    }
    out = json_pack("{s:s, s:O, s:O, s:O, s:O, s:f}", "id", "tower", "nodes", nodes, "s", s,
                    "twist_deg", tw, "axes", json_object_get(json_array_get(mems, 0), "axes"),
                    "length", total);
done:
    json_decref(nodes);
    json_decref(s);
    json_decref(tw);
    return out;
}

/* The blade member's layout: id "blade", else the only member (*tower = 1 when its id is
 * "tower": the tower form's member, which takes TwFAM1Sh..., not the blade's names), else a
 * wired tower's members joined (*own, new: edt_join_tower). */
static const json_t *edt_member(const json_t *result, int *tower, json_t **own)
{
    const json_t *mems = json_object_get(json_object_get(result, "model"), "members"), *lay;
    const char *id;
    size_t i;

    json_array_foreach(mems, i, lay) {
        id = json_string_value(json_object_get(lay, "id"));
        if (id && !strcmp(id, "blade"))
            return lay;
    }
    lay = json_array_get(mems, 0);
    id = json_string_value(json_object_get(lay, "id"));
    *tower = id && !strcmp(id, "tower");
    if (json_array_size(mems) > 1 && (*own = edt_join_tower(mems)))
        *tower = 1;
    return json_array_size(mems) == 1 ? lay : *own;
}

/* The member's nodes, span fractions, twists (rad), axes and length into *in. */
static int edt_layout(const json_t *result, edt_input *in, char *err, size_t errcap)
{
    const json_t *lay;
    int j;

    memset(in, 0, sizeof *in);
    if (!json_is_true(json_object_get(json_object_get(result, "model"), "spatial")))
        return edt_err(err, errcap,
                       "ElastoDyn coefficients need a spatial result with mode "
                       "shapes (\"mode_shapes\": true)");
    lay = edt_member(result, &in->tower, &in->own);
    if (!lay)
        return edt_err(err, errcap,
                       "ElastoDyn coefficients need a blade or a tower: the blade or tower "
                       "form or a structure of one member, with mode shapes");
    in->layout = lay;
    in->n = (int)json_array_size(json_object_get(lay, "nodes"));
    if (in->n < 4 || (int)json_array_size(json_object_get(lay, "s")) != in->n)
        return edt_err(err, errcap, "the member has fewer than 4 nodes: no polynomial fit");
    in->x = malloc((size_t)in->n * sizeof *in->x);
    in->twist = malloc((size_t)in->n * sizeof *in->twist);
    if (!in->x || !in->twist)
        return SM_NOMEM;
    for (j = 0; j < in->n; j++) {
        in->x[j] = json_number_value(json_array_get(json_object_get(lay, "s"), (size_t)j));
        in->twist[j] = /* a tower's shapes are fore-aft and side-side, whatever its twist */
            in->tower ? 0.0
                      : CODEC_RAD_PER_DEG * json_number_value(json_array_get(
                                                json_object_get(lay, "twist_deg"), (size_t)j));
    }
    in->x[in->n - 1] = 1.0;
    for (j = 0; j < 9; j++)
        in->ax[j] = json_number_value(json_array_get(json_object_get(lay, "axes"), (size_t)j));
    in->length = json_number_value(json_object_get(lay, "length"));
    return SM_OK;
}

/* The energy split of a mode ({"kinetic": {...}, "strain": {...}}) into e[SM_ENERGY_PARTS];
 * 0 when it has none. */
static int edt_energy(const json_t *mode, double *e)
{
    static const char *const parts[4] = {"axial", "edge", "flap", "torsion"};
    const json_t *en = json_object_get(mode, "energy");
    const json_t *kin = json_object_get(en, "kinetic"), *str = json_object_get(en, "strain");
    int p;

    if (!json_is_object(kin) || !json_is_object(str))
        return 0;
    for (p = 0; p < 4; p++) {
        e[p] = json_number_value(json_object_get(kin, parts[p]));
        e[4 + p] = json_number_value(json_object_get(str, parts[p]));
    }
    return 1;
}

/* A tower's shape less the root's rigid motion (DESIGN §B: y - y0 - y0' x, per direction;
 * y0' = -L e2.r for fore-aft, L e3.r for side-side, the projection's slopes at the root, the
 * tower untwisted).  Zero on a clamped base; it matters on elastic supports. */
static void edt_root_rigid(const edt_input *in, const double *rows, double *out, double slope[2])
{
    const double *r = rows + 3;
    double s0[2], y0;
    int d, j;

    s0[0] = -in->length * (in->ax[3] * r[0] + in->ax[4] * r[1] + in->ax[5] * r[2]);
    s0[1] = in->length * (in->ax[6] * r[0] + in->ax[7] * r[1] + in->ax[8] * r[2]);
    for (d = 0; d < 2; d++) {
        y0 = out[d * in->n];
        for (j = 0; j < in->n; j++)
            out[d * in->n + j] -= y0 + s0[d] * in->x[j];
        slope[d] -= s0[d];
    }
}

/* One shape part ([[dx..rz] per model node]) on the member's nodes, projected (core). */
static void edt_project(const edt_input *in, const json_t *part, double *rows, double *out,
                        double slope[2])
{
    const json_t *nodes = json_object_get(in->layout, "nodes");
    int j, c;

    for (j = 0; j < in->n; j++) {
        const json_t *row =
            json_array_get(part, (size_t)json_integer_value(json_array_get(nodes, (size_t)j)));
        for (c = 0; c < 6; c++)
            rows[6 * j + c] = json_number_value(json_array_get(row, (size_t)c));
    }
    sm_elastodyn_project(in->n, in->ax, in->twist, in->length, rows, out, slope);
    if (in->tower)
        edt_root_rigid(in, rows, out, slope);
}

/* Buffers of one case's sm_ed_shapes (owned). */
typedef struct edt_bufs {
    double *rows, *re, *im, *sr, *si, *energy, *freq;
} edt_bufs;

static void edt_bufs_free(edt_bufs *b)
{
    free(b->rows), free(b->re), free(b->im), free(b->sr), free(b->si), free(b->energy);
    free(b->freq);
}

/* Fill the shapes of case cs's modes into b and s; SM_INVALID_INPUT when a mode lacks its
 * shape or energy. */
static int edt_shapes(const edt_input *in, const json_t *modes, edt_bufs *b, sm_ed_shapes *s,
                      int *has_im)
{
    size_t nm = json_array_size(modes), k, n = (size_t)in->n;
    const json_t *mode, *shape;

    b->rows = malloc(6 * n * sizeof(double));
    b->re = malloc(nm * 2 * n * sizeof(double));
    b->im = calloc(nm * 2 * n, sizeof(double));
    b->sr = malloc(nm * 2 * sizeof(double));
    b->si = calloc(nm * 2, sizeof(double));
    b->energy = malloc(nm * SM_ENERGY_PARTS * sizeof(double));
    b->freq = malloc((nm ? nm : 1) * sizeof(double));
    if (!b->rows || !b->re || !b->im || !b->sr || !b->si || !b->energy || !b->freq)
        return SM_NOMEM;
    *has_im = 0;
    json_array_foreach(modes, k, mode) {
        shape = json_object_get(mode, "shape");
        if (!json_is_array(json_object_get(shape, "re")) ||
            !edt_energy(mode, b->energy + k * SM_ENERGY_PARTS))
            return SM_INVALID_INPUT;
        b->freq[k] = json_number_value(json_object_get(mode, "frequency_hz"));
        edt_project(in, json_object_get(shape, "re"), b->rows, b->re + 2 * k * n, b->sr + 2 * k);
        if (json_is_array(json_object_get(shape, "im"))) {
            edt_project(in, json_object_get(shape, "im"), b->rows, b->im + 2 * k * n,
                        b->si + 2 * k);
            *has_im = 1;
        }
    }
    *s = (sm_ed_shapes){(int)nm,
                        in->n,
                        in->x,
                        b->re,
                        *has_im ? b->im : NULL,
                        b->sr,
                        *has_im ? b->si : NULL,
                        b->energy,
                        {SM_MODE_FLAP, SM_MODE_EDGE}};
    if (in->tower) /* a symmetric tower's fore-aft/side-side pair (core, DESIGN §B) */
        sm_elastodyn_degenerate(s, b->freq);
    return SM_OK;
}

/* Fits of case cs given the layout. */
static int edt_case_fits(const edt_input *in, const json_t *cs, sm_ed_fit *fits, char *err,
                         size_t errcap)
{
    static const int want[2][2] = {{2, 1}, {2, 2}};
    const json_t *modes = json_object_get(cs, "modes");
    edt_bufs b = {NULL, NULL, NULL, NULL, NULL, NULL, NULL};
    sm_ed_shapes s;
    int rc, has_im;

    if (!json_array_size(modes))
        return edt_err(err, errcap, "the case has no modes");
    rc = edt_shapes(in, modes, &b, &s, &has_im);
    if (rc == SM_INVALID_INPUT)
        edt_err(err, errcap,
                "a mode has no shape or energy split (\"mode_shapes\": true; a "
                "spatial result)");
    else if (rc == SM_OK) {
        rc = sm_elastodyn_fit_modes(&s, want[in->tower], fits);
        if (rc == SM_INVALID_INPUT)
            edt_err(err, errcap, "a fitted mode has a zero tip displacement");
    }
    edt_bufs_free(&b);
    return rc;
}

int codec_elastodyn_fits(const json_t *result, size_t ci, sm_ed_fit fits[CODEC_ED_TOWER_FITS],
                         int *nfit, const char *const **names, char *err, size_t errcap)
{
    const json_t *cs = json_array_get(json_object_get(result, "cases"), ci);
    edt_input in;
    int rc;

    if (err && errcap)
        err[0] = '\0';
    *nfit = 0;
    if (!cs)
        return edt_err(err, errcap, "no such case in the result");
    rc = edt_layout(result, &in, err, errcap);
    if (rc == SM_OK)
        rc = edt_case_fits(&in, cs, fits, err, errcap);
    if (rc == SM_OK) {
        *nfit = in.tower ? CODEC_ED_TOWER_FITS : SM_ED_BLADE_FITS;
        if (names)
            *names = in.tower ? codec_ed_tower_names : codec_ed_blade_names;
    }
    edt_input_clear(&in);
    return rc;
}

int codec_elastodyn_case(const json_t *result, size_t ci, sm_ed_fit fits[SM_ED_BLADE_FITS],
                         char *err, size_t errcap)
{
    sm_ed_fit all[CODEC_ED_TOWER_FITS];
    int rc, n;

    rc = codec_elastodyn_fits(result, ci, all, &n, NULL, err, errcap);
    if (rc == SM_OK && n != SM_ED_BLADE_FITS)
        return edt_err(err, errcap,
                       "the result is a tower's: its coefficients are "
                       "TwFAM1Sh... (codec_elastodyn_fits)");
    if (rc == SM_OK)
        memcpy(fits, all, SM_ED_BLADE_FITS * sizeof fits[0]);
    return rc;
}

void codec_elastodyn_format(const double coef[5], char text[5][CODEC_ED_TEXT])
{
    double big = 0, scale;
    long long n[5], sum = 0, unit, a;
    int d, k;

    for (k = 0; k < 5; k++)
        big = fmax(big, fabs(coef[k]));
    /* d decimals: 7 significant digits on the largest (|C| < 1e15: a fit gives ~1e2) */
    d = big > 0 && big < 1e15 ? 6 - (int)floor(log10(big)) : 6;
    d = d < 0 ? 0 : d > 12 ? 12 : d;
    scale = pow(10, d);
    unit = llround(scale);
    for (k = 0; k < 4; k++) {
        n[k] = llround(coef[k] * scale); /* C_k in units of 10^-d */
        sum += n[k];
    }
    n[4] = unit - sum; /* C6 = 1 - (C2 + ... + C5), exact in decimal */
    for (k = 0; k < 5; k++) {
        a = n[k] < 0 ? -n[k] : n[k];
        if (d)
            snprintf(text[k], CODEC_ED_TEXT, "%s%lld.%0*lld", n[k] < 0 ? "-" : "", a / unit, d,
                     a % unit);
        else
            snprintf(text[k], CODEC_ED_TEXT, "%lld", n[k]);
    }
}

void codec_elastodyn_blade_values(const sm_ed_fit fits[SM_ED_BLADE_FITS],
                                  char values[CODEC_ED_BLADE_VALUES][CODEC_ED_TEXT])
{
    codec_elastodyn_values(fits, SM_ED_BLADE_FITS, values);
}

void codec_elastodyn_values(const sm_ed_fit *fits, int nfit, char values[][CODEC_ED_TEXT])
{
    int f;

    for (f = 0; f < nfit; f++)
        codec_elastodyn_format(fits[f].coef, values + 5 * f);
}

/* A number for a comment line, "n/a" when not finite. */
static void edt_num(FILE *f, const char *fmt, double v)
{
    if (isfinite(v))
        fprintf(f, fmt, v + 0.0);
    else
        fputs("n/a", f);
}

/* The report line(s) and the five coefficient lines of fit i of a case's modes. */
static void edt_write_fit(FILE *f, const json_t *modes, const edt_name *nm, int tower,
                          const sm_ed_fit *fit)
{
    const json_t *md = json_array_get(modes, (size_t)(fit->mode < 0 ? 0 : fit->mode));
    char text[5][CODEC_ED_TEXT];
    int k;

    if (fit->mode < 0) {
        fprintf(f,
                "! %s: no %s-dominated mode among the %zu computed: ask for more modes "
                "(\"modes\")\n",
                nm->name, nm->dir, json_array_size(modes));
        return;
    }
    fprintf(f, "! %s: mode %d (%.6g Hz, %s): %s share of the bending strain energy ", nm->name,
            fit->mode + 1, json_number_value(json_object_get(md, "frequency_hz")),
            json_string_value(json_object_get(md, "label"))
                ? json_string_value(json_object_get(md, "label"))
                : "unlabelled",
            nm->dir);
    edt_num(f, "%.2f %%", 100 * fit->share);
    fprintf(f, "; rms residual %.3e, largest %.3e (of tip); tip slope FE ", fit->rms,
            fit->max_residual);
    edt_num(f, "%.6g", fit->tip_slope_fe);
    fprintf(f, ", fit %.6g, error ", fit->tip_slope_fit);
    edt_num(f, "%.3g %%", 100 * fit->tip_slope_error);
    fputc('\n', f);
    if (fit->warning) {
        fprintf(f, "! warning: %s: mode %d is not clean: %s carries ", nm->name, fit->mode + 1,
                nm->dir);
        edt_num(f, "%.2f %%", 100 * fit->share);
        fprintf(f, " of its bending strain energy (below %.0f %%); fitted anyway\n",
                100 * SM_ED_CLEAN);
    }
    codec_elastodyn_format(fit->coef, text);
    for (k = 0; k < 5; k++)
        if (tower) /* the tower file's layout */
            fprintf(f, "%14s   %s(%d) - %-6s, coefficient of x^%d term\n", text[k], nm->name, k + 2,
                    k ? "" : nm->what, k + 2);
        else
            fprintf(f, "%14s   %s(%d) - %-11s, coeff of x^%d\n", text[k], nm->name, k + 2,
                    k ? "" : nm->what, k + 2);
}

/* The header lines of the document. */
static void edt_header(FILE *f, const json_t *result, const edt_input *in)
{
    const json_t *solver = json_object_get(result, "solver");
    const char *id = json_string_value(json_object_get(in->layout, "id"));

    if (in->tower) {
        fprintf(f,
                "! spinmodal %s ElastoDyn tower mode-shape coefficients (DESIGN.md 9.3)\n"
                "! request %s\n"
                "! member %s (%.6g m): x = s from the top of the rigid base, fore-aft (flap) "
                "and side-side (edge) displacements less the root's rigid motion, divided by "
                "the top value; least squares on x^k - x^6 (k = 2..5), C6 = 1 - (C2 + ... + "
                "C5)\n"
                "! FA 1, FA 2 (SS 1, SS 2): the two lowest modes with more fore-aft than "
                "side-side (the reverse) kinetic energy, torsion and axial excluded by energy; "
                "a pair within %g relative in frequency turned to pure directions first\n",
                json_string_value(json_object_get(solver, "version")),
                json_string_value(json_object_get(solver, "request_sha256")), id ? id : "0",
                in->length, SM_ED_DEGENERATE);
        return;
    }
    fprintf(f,
            "! spinmodal %s ElastoDyn blade mode-shape coefficients (DESIGN.md 9.3)\n"
            "! request %s\n"
            "! member %s (%.6g m): x = s from its root joint (the flexible root), shapes in "
            "the principal axes (flap p3, edge p2, with the structural twist), divided by "
            "the tip value; least squares on x^k - x^6 (k = 2..5), C6 = 1 - (C2 + ... + "
            "C5)\n"
            "! flap 1, flap 2: the two lowest modes with more flapwise than edgewise "
            "kinetic energy; edge 1: the lowest with more edgewise\n",
            json_string_value(json_object_get(solver, "version")),
            json_string_value(json_object_get(solver, "request_sha256")), id ? id : "0",
            in->length);
}

/* rpm of a case: its "rpm", else omega x 60 / 2 pi. */
static double edt_rpm(const json_t *cs)
{
    const json_t *rpm = json_object_get(cs, "rpm");

    return json_is_number(rpm)
               ? json_number_value(rpm)
               : json_number_value(json_object_get(cs, "omega")) * 60 / CODEC_TWO_PI;
}

int codec_result_elastodyn(char **out, size_t *len, const json_t *result, char *err, size_t errcap)
{
    const json_t *cases = json_object_get(result, "cases"), *cs;
    sm_ed_fit fits[CODEC_ED_TOWER_FITS];
    char *buf = NULL;
    size_t n = 0, ci;
    edt_input in;
    FILE *f = NULL;
    int rc, i;

    *out = NULL;
    if (err && errcap)
        err[0] = '\0';
    rc = edt_layout(result, &in, err, errcap);
    if (rc == SM_OK && !json_array_size(cases))
        rc = edt_err(err, errcap, "the result has no cases");
    if (rc == SM_OK && !(f = open_memstream(&buf, &n)))
        rc = SM_NOMEM;
    if (rc)
        goto done;
    edt_header(f, result, &in);
    json_array_foreach(cases, ci, cs) {
        fprintf(f, "!\n! case %zu of %zu: %.6g rpm (%.6g rad/s), %s\n", ci + 1,
                json_array_size(cases), edt_rpm(cs),
                json_number_value(json_object_get(cs, "omega")),
                json_string_value(json_object_get(cs, "status")));
        if (!json_array_size(json_object_get(cs, "modes"))) {
            fputs("! no modes at this speed\n", f);
            continue;
        }
        rc = edt_case_fits(&in, cs, fits, err, errcap);
        if (rc)
            break;
        for (i = 0; i < (in.tower ? CODEC_ED_TOWER_FITS : SM_ED_BLADE_FITS); i++)
            edt_write_fit(f, json_object_get(cs, "modes"), in.tower ? &edt_tower[i] : &edt_blade[i],
                          in.tower, &fits[i]);
    }
    if (rc) {
        fclose(f);
        free(buf);
        goto done;
    }
    rc = codec_memstream_done(f, &buf, &n, out, len);
done:
    edt_input_clear(&in);
    return rc;
}
