/*
 * import_bmodes_out.c — BModes' .out mode-shape tables read as a MAC set
 * (codec_mac_from_bmodes_out, mac.h; DESIGN.md 9.2).
 *
 * How it fits: BModes (v3, BldVib.f90:860-905) prints, per mode, a line
 * " -------- Mode No.   k  (freq = 0.17517E+01 Hz)", a header
 * "span_loc  flap disp  flap slope  lag disp  lag slope  twist" (a tower:
 * "s-s disp  s-s slope  f-a disp  f-a slope  twist") and one row of six
 * numbers per span station, span_loc from 0 (the flexible root) to 1.
 * This reader keeps span_loc and the two displacement columns (1 and 3) of
 * every mode as one segment, which mac.c compares with a result's flap and
 * lag (d.e3, -d.e2: spanwise.c's bmodes columns, whose sign conventions are
 * BModes').  Slopes and twist are not compared: BModes' displacements are
 * over the rotor radius and its twist in radians, two units one MAC cannot
 * weigh.  Helpers are bo_*.
 */
#include "mac.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The most stations and modes read (BModes prints at most 20 modes). */
#define BO_MAX_ROWS 2000
#define BO_MAX_MODES 200

/* The parse state: the modes so far, the span stations of the first, the growing arrays. */
typedef struct bo_state {
    int n_modes, n_rows, rows_first; /* rows of the current mode, of the first mode */
    double s[BO_MAX_ROWS];
    double *val; /* n_modes * rows_first * 2 once the first mode is done; rows grow */
    size_t cap;
    double freq[BO_MAX_MODES];
} bo_state;

/* Appends one row (span_loc, col1, col3) of the current mode; 0, or a reason in err. */
static int bo_row(bo_state *b, const double v[6], int line, char *err, size_t errcap)
{
    size_t at = ((size_t)(b->n_modes - 1) * (b->n_modes > 1 ? b->rows_first : 0) + b->n_rows) * 2;
    if (b->n_rows >= BO_MAX_ROWS) {
        snprintf(err, errcap, "line %d: more than %d span stations", line, BO_MAX_ROWS);
        return SM_INVALID_INPUT;
    }
    if (b->n_modes == 1)
        b->s[b->n_rows] = v[0];
    else if (b->n_rows >= b->rows_first || fabs(b->s[b->n_rows] - v[0]) > 1e-9) {
        snprintf(err, errcap, "line %d: mode %d's span_loc %g differs from mode 1's stations", line,
                 b->n_modes, v[0]);
        return SM_INVALID_INPUT;
    }
    if (at + 2 > b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 256;
        double *p = realloc(b->val, sizeof(double) * cap);
        if (!p)
            return SM_NOMEM;
        b->val = p, b->cap = cap;
    }
    b->val[at] = v[1];
    b->val[at + 1] = v[3];
    b->n_rows++;
    return SM_OK;
}

/* Ends the current mode: 0, or a reason when it had no rows or a different count. */
static int bo_end_mode(bo_state *b, int line, char *err, size_t errcap)
{
    if (b->n_modes == 0)
        return SM_OK;
    if (b->n_modes == 1)
        b->rows_first = b->n_rows;
    if (b->n_rows < 2 || b->n_rows != b->rows_first) {
        snprintf(err, errcap, "line %d: mode %d has %d span stations (mode 1: %d)", line,
                 b->n_modes, b->n_rows, b->rows_first);
        return SM_INVALID_INPUT;
    }
    return SM_OK;
}

/* Reads one line: a mode heading, a row of six numbers, or anything else (skipped). */
static int bo_line(bo_state *b, const char *ln, int line, char *err, size_t errcap)
{
    const char *m = strstr(ln, "Mode No.");
    double v[6];
    char *end;
    int k, st;

    if (m) {
        const char *f = strstr(ln, "freq =");
        if ((st = bo_end_mode(b, line, err, errcap)))
            return st;
        if (b->n_modes >= BO_MAX_MODES || !f) {
            snprintf(err, errcap, "line %d: %s", line,
                     f ? "too many modes" : "a mode heading without \"freq =\"");
            return SM_INVALID_INPUT;
        }
        b->freq[b->n_modes++] = strtod(f + 6, NULL);
        b->n_rows = 0;
        return SM_OK;
    }
    for (k = 0; k < 6; k++) {
        v[k] = strtod(ln, &end);
        if (end == ln || !isfinite(v[k]))
            return SM_OK; /* not a row of numbers: a title or a header */
        ln = end;
    }
    if (b->n_modes == 0)
        return SM_OK; /* numbers before the first mode: not a shape */
    return bo_row(b, v, line, err, errcap);
}

/* Copies the parsed modes into x (one segment). */
static int bo_store(codec_mac_set *x, const bo_state *b)
{
    int i, n = b->n_modes, np = b->rows_first;
    x->re = malloc(sizeof(double) * (size_t)n * np * 2);
    x->s = malloc(sizeof(double) * (size_t)np);
    x->seg = calloc(2, sizeof(int));
    x->freq_hz = malloc(sizeof(double) * (size_t)n);
    x->labels = json_array();
    if (!x->re || !x->s || !x->seg || !x->freq_hz || !x->labels)
        return SM_NOMEM;
    memcpy(x->re, b->val, sizeof(double) * (size_t)n * np * 2);
    memcpy(x->s, b->s, sizeof(double) * (size_t)np);
    memcpy(x->freq_hz, b->freq, sizeof(double) * (size_t)n);
    x->seg[1] = np;
    for (i = 0; i < n; i++)
        if (json_array_append_new(x->labels, json_null()))
            return SM_NOMEM;
    x->sh = (sm_mac_shapes){n, np, 2, 1, x->seg, x->s, x->re, NULL};
    x->kind = "bmodes_out";
    x->omega = NAN;
    return SM_OK;
}

int codec_mac_from_bmodes_out(codec_mac_set *x, const char *text, size_t len, char *err,
                              size_t errcap)
{
    bo_state *b = calloc(1, sizeof(*b));
    char ln[512];
    size_t at = 0;
    int line = 0, st = SM_NOMEM;

    memset(x, 0, sizeof(*x));
    if (!b)
        return SM_NOMEM;
    while (at < len) {
        size_t e = at, n;
        while (e < len && text[e] != '\n')
            e++;
        n = e - at < sizeof(ln) - 1 ? e - at : sizeof(ln) - 1;
        memcpy(ln, text + at, n);
        ln[n] = '\0';
        at = e + 1;
        line++;
        if ((st = bo_line(b, ln, line, err, errcap)))
            goto done;
    }
    if ((st = bo_end_mode(b, line, err, errcap)))
        goto done;
    if (b->n_modes == 0) {
        snprintf(err, errcap, "no \"Mode No.\" tables: not a BModes .out file");
        st = SM_INVALID_INPUT;
        goto done;
    }
    st = bo_store(x, b);
done:
    if (st)
        codec_mac_set_free(x);
    free(b->val);
    free(b);
    return st;
}
