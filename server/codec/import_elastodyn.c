/*
 * import_elastodyn.c — an OpenFAST ElastoDyn blade file (the
 * "ELASTODYN ... INDIVIDUAL BLADE INPUT FILE", e.g. r-test's
 * NRELOffshrBsline5MW_Blade.dat) into the blade form (spec 12 section 6).
 *
 * The file: a header line, a title, then "value Name - description" lines
 * in sections opened by "-----" lines: NBlInpSt, damping, then AdjBlMs,
 * AdjFlSt, AdjEdSt; the section "DISTRIBUTED BLADE PROPERTIES" holds a
 * line of column names, a line of units and NBlInpSt rows; mode-shape
 * coefficients follow (not used).  Parameters are found by name, not by
 * position, so the older files (with CalcBMode) read too; columns are found
 * by name in the title line: OpenFAST 3 dropped PitchAxis (5 columns), older
 * files have 6 (FAST 7's extra columns GJStff, EAStff, FlpIner, EdgIner are
 * used when present, others are reported as ignored).
 *
 * Mapping: BlFract -> s, StrcTwst -> twist_deg, BMassDen x AdjBlMs ->
 * mass_per_length, FlpStff x AdjFlSt -> EI_flap, EdgStff x AdjEdSt ->
 * EI_edge.  The file has no blade length, hub radius or speed: options
 * (tip_radius required, hub_radius and rpm with a warning when absent).
 * EA and GJ are not in the file (ElastoDyn's blade is rigid in extension
 * and torsion): the blade section gets stiff assumed values, with
 * warnings (imp_assumed_section).
 */
#include "import_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#define ED_MAX_COLUMNS 32

/* Columns of the table that are used; anything else is ignored. */
static const struct {
    const char *name;
    int key;  /* imp_key, -1 = known and not used */
    int adj;  /* 0 none, 1 AdjBlMs, 2 AdjFlSt, 3 AdjEdSt */
    int need; /* required */
} ed_cols[] = {
    {"BlFract", IK_S, 0, 1},         {"PitchAxis", -1, 0, 0},       {"StrcTwst", IK_TWIST, 0, 1},
    {"BMassDen", IK_MU, 1, 1},       {"FlpStff", IK_EI_FLAP, 2, 1}, {"EdgStff", IK_EI_EDGE, 3, 1},
    {"GJStff", IK_GJ, 0, 0},         {"EAStff", IK_EA, 0, 0},       {"FlpIner", IK_I_FLAP, 0, 0},
    {"EdgIner", IK_I_EDGE, 0, 0},
};
#define ED_NCOLS ((int)(sizeof(ed_cols) / sizeof(ed_cols[0])))

/* What the parameter lines say. */
typedef struct ed_params {
    char title[200];
    long nst;      /* NBlInpSt, 0 = not seen */
    double adj[4]; /* [1..3]: AdjBlMs, AdjFlSt, AdjEdSt */
    int adj_line[4]; /* line of each, 0 = not seen */
} ed_params;

static int ed_tok_is(const imp_tok *t, const char *name)
{
    return t->n == strlen(name) && strncasecmp(t->s, name, t->n) == 0;
}

/* 1 when s[0..n) contains word, any case. */
static int ed_contains(const char *s, size_t n, const char *word)
{
    size_t k, w = strlen(word);

    for (k = 0; k + w <= n; k++)
        if (strncasecmp(s + k, word, w) == 0)
            return 1;
    return 0;
}

/* 1 when the line is a "-----" section line, *dist = 1 for DISTRIBUTED BLADE PROPERTIES. */
static int ed_section(const char *s, size_t n, int *dist)
{
    size_t i = 0;

    while (i < n && (s[i] == ' ' || s[i] == '\t'))
        i++;
    if (n - i < 3 || strncmp(s + i, "---", 3) != 0)
        return 0;
    *dist = ed_contains(s, n, "DISTRIBUTED BLADE PROPERTIES");
    return 1;
}

/* One "value Name - ..." line: NBlInpSt and the adjustment factors are kept. */
static int ed_param(imp_reader *r, import_diag *d, ed_params *p)
{
    static const char *const adj[4] = {NULL, "AdjBlMs", "AdjFlSt", "AdjEdSt"};
    const char *file = r->f->name;
    imp_tok t[2];
    double v;
    int i, st;

    if (imp_split(r->s, r->n, "", t, 2) < 2)
        return SM_OK; /* not a parameter line: ignored, as ElastoDyn reads by position */
    if (ed_tok_is(&t[1], "NBlInpSt")) {
        if ((st = imp_value(d, file, r->line, "NBlInpSt", &t[0], IMP_ANY, &v)))
            return st;
        if (v != floor(v) || v < 2 || v > IMPORT_MAX_STATIONS)
            return imp_fail(d, file, r->line, "NBlInpSt",
                            "must be an integer in [2, %d] (%.15g)", IMPORT_MAX_STATIONS, v);
        p->nst = (long)v;
    }
    for (i = 1; i <= 3; i++)
        if (ed_tok_is(&t[1], adj[i])) {
            if ((st = imp_value(d, file, r->line, adj[i], &t[0], IMP_POSITIVE, &p->adj[i])))
                return st;
            p->adj_line[i] = r->line;
        }
    return SM_OK;
}

/* The header, the title and the parameters, up to the table's section line. */
static int ed_head(imp_reader *r, import_diag *d, ed_params *p)
{
    static const char *const adj[4] = {NULL, "AdjBlMs", "AdjFlSt", "AdjEdSt"};
    const char *file = r->f->name;
    imp_tok t;
    int dist = 0, i, st;

    if (!imp_next(r) || !ed_contains(r->s, r->n, "BLADE"))
        return imp_fail(d, file, 1, "header",
                        "not an ElastoDyn blade file (expected a first line like \"--- "
                        "ELASTODYN ... INDIVIDUAL BLADE INPUT FILE ---\")");
    if (!imp_next(r))
        return imp_fail(d, file, 2, "title", "the file ends here (truncated?)");
    t.s = r->s;
    t.n = r->n;
    imp_tok_copy(p->title, sizeof(p->title), &t);
    while (imp_next(r)) {
        if (ed_section(r->s, r->n, &dist)) {
            if (dist)
                break;
            continue;
        }
        if ((st = ed_param(r, d, p)))
            return st;
    }
    if (!dist)
        return imp_fail(d, file, r->line + 1, "DISTRIBUTED BLADE PROPERTIES",
                        "the file ends before this section (truncated?)");
    if (!p->nst)
        return imp_fail(d, file, r->line, "NBlInpSt", "not found before the table");
    for (i = 1; i <= 3; i++)
        if (!p->adj_line[i])
            return imp_fail(d, file, r->line, adj[i], "not found before the table");
    return SM_OK;
}

/* The line of column names: col[c] = index into ed_cols or -1 (ignored). */
static int ed_columns(imp_reader *r, import_diag *d, int *col, int *ncol, json_t *warn)
{
    const char *file = r->f->name;
    imp_tok t[ED_MAX_COLUMNS + 1];
    int seen[ED_NCOLS] = {0};
    int n, c, k;

    if (!imp_next(r))
        return imp_fail(d, file, r->line + 1, "BlFract",
                        "the file ends before the column names of the table (truncated?)");
    n = imp_split(r->s, r->n, ",", t, ED_MAX_COLUMNS + 1);
    if (n > ED_MAX_COLUMNS)
        return imp_fail(d, file, r->line, "columns", "more than %d columns", ED_MAX_COLUMNS);
    for (c = 0; c < n; c++) {
        char name[40];
        col[c] = -1;
        for (k = 0; k < ED_NCOLS; k++)
            if (ed_tok_is(&t[c], ed_cols[k].name))
                col[c] = k;
        imp_tok_copy(name, sizeof(name), &t[c]);
        if (col[c] >= 0 && seen[col[c]]++)
            return imp_fail(d, file, r->line, name, "column given twice");
        if (col[c] < 0 && imp_warn(warn, "/blade/stations", "column %s of the ElastoDyn table is not used",
                                    name))
            return SM_NOMEM;
    }
    for (k = 0; k < ED_NCOLS; k++)
        if (ed_cols[k].need && !seen[k])
            return imp_fail(d, file, r->line, ed_cols[k].name,
                            "column missing from the table's title line");
    *ncol = n;
    return imp_next(r) ? SM_OK
                       : imp_fail(d, file, r->line + 1, "units",
                                  "the file ends before the units line of the table (truncated?)");
}

/* The NBlInpSt rows, adjustment factors applied. */
static int ed_rows(imp_reader *r, import_diag *d, const ed_params *p, const int *col, int ncol,
                   imp_table *t)
{
    const char *file = r->f->name;
    imp_tok tok[ED_MAX_COLUMNS + 1];
    long i;
    int c, n, st;

    for (c = 0; c < ncol; c++)
        if (col[c] >= 0 && ed_cols[col[c]].key >= 0)
            t->mask |= 1u << ed_cols[col[c]].key;
    for (i = 0; i < p->nst; i++) {
        imp_station *s;
        if (!imp_next_nonblank(r))
            return imp_fail(d, file, r->line + 1, ed_cols[col[0] >= 0 ? col[0] : 0].name,
                            "the file ends before station %ld of %ld (NBlInpSt; truncated?)",
                            i + 1, p->nst);
        n = imp_split(r->s, r->n, ",", tok, ED_MAX_COLUMNS + 1);
        if (n != ncol) {
            char name[40] = "row";
            if (n < ncol && col[n] >= 0)
                snprintf(name, sizeof(name), "%s", ed_cols[col[n]].name);
            return imp_fail(d, file, r->line, name, "%s: the row has %d columns, expected %d",
                            n < ncol ? "missing" : "too many columns", n, ncol);
        }
        if (!(s = imp_table_add(t)))
            return SM_NOMEM;
        s->line = r->line;
        for (c = 0; c < ncol; c++) {
            int k = col[c], key, kind;
            double v;
            if (k < 0 || ed_cols[k].key < 0)
                continue;
            key = ed_cols[k].key;
            kind = imp_key_kind((imp_key)key);
            if ((st = imp_value(d, file, r->line, ed_cols[k].name, &tok[c], kind, &v)))
                return st;
            if (ed_cols[k].adj)
                v *= p->adj[ed_cols[k].adj];
            if ((st = imp_check(d, file, r->line, ed_cols[k].name, kind, v)))
                return st;
            s->v[key] = v;
        }
    }
    return imp_table_order(d, file, t, "BlFract");
}

static json_t *ed_source(const ed_params *p, const char *file)
{
    json_t *src = json_object();
    int bad = !src;

    if (!bad) {
        bad |= json_object_set_new(src, "format", json_string("elastodyn"));
        bad |= json_object_set_new(src, "file", imp_string(file));
        bad |= json_object_set_new(src, "title", json_string(p->title));
        bad |= json_object_set_new(src, "AdjBlMs", json_real(imp_round(p->adj[1])));
        bad |= json_object_set_new(src, "AdjFlSt", json_real(imp_round(p->adj[2])));
        bad |= json_object_set_new(src, "AdjEdSt", json_real(imp_round(p->adj[3])));
    }
    if (bad) {
        json_decref(src);
        return NULL;
    }
    return src;
}

static const char *const ed_ei_names[2] = {"FlpStff", "EdgStff"};

int import_elastodyn(json_t **out, const import_file *f, const import_options *o,
                     import_diag *d)
{
    json_t *warn = json_array();
    imp_table t = {NULL, 0, 0, 0};
    int col[ED_MAX_COLUMNS], ncol = 0, st;
    imp_blade bl;
    ed_params p;
    imp_reader r;
    import_file body;

    *out = NULL;
    memset(&p, 0, sizeof(p));
    imp_blade_init(&bl);
    if (!warn)
        return SM_NOMEM;
    if ((st = imp_encoding(d, f, &body)))
        goto done;
    imp_reader_init(&r, &body);
    if ((st = ed_head(&r, d, &p)) || (st = ed_columns(&r, d, col, &ncol, warn)) ||
        (st = ed_rows(&r, d, &p, col, ncol, &t)) ||
        (st = imp_options_apply(d, f->name, o, 0, &bl, warn)))
        goto done;
    st = imp_document_assumed(out, d, f->name, &bl, &t, "ElastoDyn blade", ed_ei_names, warn,
                              ed_source(&p, f->name));
    warn = NULL;
done:
    json_decref(warn);
    imp_table_clear(&t);
    return st;
}
