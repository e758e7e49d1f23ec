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
 *
 * The main ElastoDyn file (its first line names neither BLADE nor TOWER) gives the tower form
 * (DESIGN.md 8.5): TowerHt -> height, TowerBsHt (+ TwrRBHt of older files) -> base_height,
 * the tower file it names (TwrFile, read through the loader relative to the main file, with
 * the loader's path rules) -> stations (HtFract -> s, TMassDen x AdjTwMa, TwFAStif x AdjFASt
 * -> EI_flap = fore-aft, TwSSStif x AdjSSSt -> EI_edge = side-side), and the tower-top mass
 * as ElastoDyn's TwrTpMass = YawBrMass + NacMass + HubMass + NumBl x (blade mass + TipMass):
 * the blade's mass from BldFile(1) (BMassDen x AdjBlMs over TipRad - HubRad), every part a
 * rigid body placed as ElastoDyn places it (ed_top_*).  Helpers are ed_*.
 */
#include "import_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#define ED_MAX_COLUMNS 32
#define ED_PI 3.14159265358979323846

/* A column of the table: its key (imp_key, -1 = known and not used), its adjustment factor
 * (0 none, else the kind's adj[]) and whether it is required. */
typedef struct ed_col {
    const char *name;
    int key, adj, need;
} ed_col;

static const ed_col ed_blade_cols[] = {
    {"BlFract", IK_S, 0, 1},      {"PitchAxis", -1, 0, 0},       {"StrcTwst", IK_TWIST, 0, 1},
    {"BMassDen", IK_MU, 1, 1},    {"FlpStff", IK_EI_FLAP, 2, 1}, {"EdgStff", IK_EI_EDGE, 3, 1},
    {"GJStff", IK_GJ, 0, 0},      {"EAStff", IK_EA, 0, 0},       {"FlpIner", IK_I_FLAP, 0, 0},
    {"EdgIner", IK_I_EDGE, 0, 0},
};

/* The tower's: fore-aft is the tower form's flap, side-side its edge (DESIGN.md 8.5). */
static const ed_col ed_tower_cols[] = {
    {"HtFract", IK_S, 0, 1},        {"TMassDen", IK_MU, 1, 1}, {"TwFAStif", IK_EI_FLAP, 2, 1},
    {"TwSSStif", IK_EI_EDGE, 3, 1}, {"TwGJStif", IK_GJ, 0, 0}, {"TwEAStif", IK_EA, 0, 0},
};

/* What differs between a blade file and a tower file. */
typedef struct ed_kind {
    const char *header; /* a word of the first line */
    const char *table;  /* the table's section line */
    const char *nst;    /* the station count */
    const char *adj[4]; /* [1..3] adjustment factors */
    const ed_col *cols;
    int ncols;
    const char *pointer; /* where unused columns are reported */
} ed_kind;

static const ed_kind ed_blade = {
    "BLADE",          "DISTRIBUTED BLADE PROPERTIES",
    "NBlInpSt",       {NULL, "AdjBlMs", "AdjFlSt", "AdjEdSt"},
    ed_blade_cols,    (int)(sizeof(ed_blade_cols) / sizeof(ed_blade_cols[0])),
    "/blade/stations"};
static const ed_kind ed_tower = {
    "TOWER",          "DISTRIBUTED TOWER PROPERTIES",
    "NTwInpSt",       {NULL, "AdjTwMa", "AdjFASt", "AdjSSSt"},
    ed_tower_cols,    (int)(sizeof(ed_tower_cols) / sizeof(ed_tower_cols[0])),
    "/tower/stations"};

/* What the parameter lines say. */
typedef struct ed_params {
    char title[200];
    const ed_kind *k;
    long nst;        /* NBlInpSt (NTwInpSt), 0 = not seen */
    double adj[4];   /* [1..3]: AdjBlMs, AdjFlSt, AdjEdSt (AdjTwMa, AdjFASt, AdjSSSt) */
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

/* 1 when the line is a "-----" section line, *dist = 1 for the table's (title: its name). */
static int ed_section(const char *s, size_t n, const char *title, int *dist)
{
    size_t i = 0;

    while (i < n && (s[i] == ' ' || s[i] == '\t'))
        i++;
    if (n - i < 3 || strncmp(s + i, "---", 3) != 0)
        return 0;
    *dist = ed_contains(s, n, title);
    return 1;
}

/* One "value Name - ..." line: the station count and the adjustment factors are kept. */
static int ed_param(imp_reader *r, import_diag *d, ed_params *p)
{
    const char *const *adj = p->k->adj, *nst = p->k->nst;
    const char *file = r->f->name;
    imp_tok t[2];
    double v;
    int i, st;

    if (imp_split(r->s, r->n, "", t, 2) < 2)
        return SM_OK; /* not a parameter line: ignored, as ElastoDyn reads by position */
    if (ed_tok_is(&t[1], nst)) {
        if ((st = imp_value(d, file, r->line, nst, &t[0], IMP_ANY, &v)))
            return st;
        if (v != floor(v) || v < 2 || v > IMPORT_MAX_STATIONS)
            return imp_fail(d, file, r->line, nst, "must be an integer in [2, %d] (%.15g)",
                            IMPORT_MAX_STATIONS, v);
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
    const ed_kind *k = p->k;
    const char *file = r->f->name;
    imp_tok t;
    int dist = 0, i, st;

    if (!imp_next(r) || !ed_contains(r->s, r->n, k->header))
        return imp_fail(d, file, 1, "header",
                        "not an ElastoDyn %s file (expected a first line like \"--- "
                        "ELASTODYN ... %s INPUT FILE ---\")",
                        k == &ed_tower ? "tower" : "blade",
                        k == &ed_tower ? "TOWER" : "INDIVIDUAL BLADE");
    if (!imp_next(r))
        return imp_fail(d, file, 2, "title", "the file ends here (truncated?)");
    t.s = r->s;
    t.n = r->n;
    imp_tok_copy(p->title, sizeof(p->title), &t);
    while (imp_next(r)) {
        if (ed_section(r->s, r->n, k->table, &dist)) {
            if (dist)
                break;
            continue;
        }
        if ((st = ed_param(r, d, p)))
            return st;
    }
    if (!dist)
        return imp_fail(d, file, r->line + 1, k->table,
                        "the file ends before this section (truncated?)");
    if (!p->nst)
        return imp_fail(d, file, r->line, k->nst, "not found before the table");
    for (i = 1; i <= 3; i++)
        if (!p->adj_line[i])
            return imp_fail(d, file, r->line, k->adj[i], "not found before the table");
    return SM_OK;
}

/* The line of column names: col[c] = index into ed_cols or -1 (ignored). */
static int ed_columns(imp_reader *r, import_diag *d, const ed_kind *kd, int *col, int *ncol,
                      json_t *warn)
{
    const char *file = r->f->name;
    imp_tok t[ED_MAX_COLUMNS + 1];
    const ed_col *ed_cols = kd->cols;
    int seen[ED_MAX_COLUMNS] = {0};
    int n, c, k;

    if (!imp_next(r))
        return imp_fail(d, file, r->line + 1, kd->cols[0].name,
                        "the file ends before the column names of the table (truncated?)");
    n = imp_split(r->s, r->n, ",", t, ED_MAX_COLUMNS + 1);
    if (n > ED_MAX_COLUMNS)
        return imp_fail(d, file, r->line, "columns", "more than %d columns", ED_MAX_COLUMNS);
    for (c = 0; c < n; c++) {
        char name[40];
        col[c] = -1;
        for (k = 0; k < kd->ncols; k++)
            if (ed_tok_is(&t[c], ed_cols[k].name))
                col[c] = k;
        imp_tok_copy(name, sizeof(name), &t[c]);
        if (col[c] >= 0 && seen[col[c]]++)
            return imp_fail(d, file, r->line, name, "column given twice");
        if (col[c] < 0 &&
            imp_warn(warn, kd->pointer, "column %s of the ElastoDyn table is not used", name))
            return SM_NOMEM;
    }
    for (k = 0; k < kd->ncols; k++)
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
    const ed_col *ed_cols = p->k->cols;
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
                            "the file ends before station %ld of %ld (%s; truncated?)", i + 1,
                            p->nst, p->k->nst);
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
    return imp_table_order(d, file, t, ed_cols[0].name);
}

static json_t *ed_source(const ed_params *p, const char *file)
{
    json_t *src = json_object();
    int bad = !src;

    if (!bad) {
        bad |= json_object_set_new(src, "format", json_string("elastodyn"));
        bad |= json_object_set_new(src, "file", imp_string(file));
        bad |= json_object_set_new(src, "title", json_string(p->title));
        bad |= json_object_set_new(src, p->k->adj[1], json_real(imp_round(p->adj[1])));
        bad |= json_object_set_new(src, p->k->adj[2], json_real(imp_round(p->adj[2])));
        bad |= json_object_set_new(src, p->k->adj[3], json_real(imp_round(p->adj[3])));
    }
    if (bad) {
        json_decref(src);
        return NULL;
    }
    return src;
}

static const char *const ed_ei_names[2] = {"FlpStff", "EdgStff"};
static const char *const ed_tw_ei_names[2] = {"TwFAStif", "TwSSStif"};

/* Read one blade or tower file (already in UTF-8 form) into *t and *p. */
static int ed_file(const import_file *f, const ed_kind *k, import_diag *d, ed_params *p,
                   imp_table *t, json_t *warn)
{
    int col[ED_MAX_COLUMNS], ncol = 0, st;
    imp_reader r;

    memset(p, 0, sizeof(*p));
    p->k = k;
    imp_reader_init(&r, f);
    if ((st = ed_head(&r, d, p)) || (st = ed_columns(&r, d, k, col, &ncol, warn)))
        return st;
    return ed_rows(&r, d, p, col, ncol, t);
}

/* The main file's parameters the tower form takes (ElastoDyn's names). */
enum {
    EM_TOWERHT,
    EM_TOWERBSHT,
    EM_TWRRBHT,
    EM_NUMBL,
    EM_TIPRAD,
    EM_HUBRAD,
    EM_PRECONE,
    EM_HUBCM,
    EM_OVERHANG,
    EM_SHFTTILT,
    EM_NACCMXN,
    EM_NACCMYN,
    EM_NACCMZN,
    EM_TWR2SHFT,
    EM_TIPMASS,
    EM_HUBMASS,
    EM_HUBINER,
    EM_NACMASS,
    EM_NACYINER,
    EM_YAWBRMASS,
    EM_ROTSPEED,
    EM_N
};
static const char *const em_names[EM_N] = {
    "TowerHt",    "TowerBsHt", "TwrRBHt",  "NumBl",   "TipRad",   "HubRad",    "PreCone(1)",
    "HubCM",      "OverHang",  "ShftTilt", "NacCMxn", "NacCMyn",  "NacCMzn",   "Twr2Shft",
    "TipMass(1)", "HubMass",   "HubIner",  "NacMass", "NacYIner", "YawBrMass", "RotSpeed"};
/* optional ones (0 when absent): TowerBsHt and TwrRBHt (one or the other), HubCM, TipMass,
 * RotSpeed */
#define EM_OPTIONAL                                                                      \
    ((1u << EM_TOWERBSHT) | (1u << EM_TWRRBHT) | (1u << EM_HUBCM) | (1u << EM_TIPMASS) | \
     (1u << EM_ROTSPEED))

typedef struct ed_main {
    double v[EM_N];
    int line[EM_N];
    char twr[256], bld[256]; /* TwrFile, BldFile(1) as written */
    int twr_line, bld_line;
} ed_main;

/* The main file's lines "value Name - ...". */
static int ed_main_read(const import_file *f, import_diag *d, ed_main *m)
{
    imp_reader r;
    imp_tok t[2];
    int k, st;

    memset(m, 0, sizeof(*m));
    imp_reader_init(&r, f);
    while (imp_next(&r)) {
        if (imp_split(r.s, r.n, "", t, 2) < 2)
            continue;
        if (ed_tok_is(&t[1], "TwrFile") && !m->twr_line) {
            imp_tok_copy(m->twr, sizeof(m->twr), &t[0]);
            m->twr_line = r.line;
        }
        if (ed_tok_is(&t[1], "BldFile(1)") && !m->bld_line) {
            imp_tok_copy(m->bld, sizeof(m->bld), &t[0]);
            m->bld_line = r.line;
        }
        for (k = 0; k < EM_N; k++)
            if (!m->line[k] && ed_tok_is(&t[1], em_names[k])) {
                if ((st = imp_value(d, f->name, r.line, em_names[k], &t[0], IMP_ANY, &m->v[k])))
                    return st;
                m->line[k] = r.line;
            }
    }
    for (k = 0; k < EM_N; k++)
        if (!m->line[k] && !(EM_OPTIONAL & (1u << k)))
            return imp_fail(d, f->name, r.line, em_names[k], "not found in the main file");
    if (!m->twr_line || !m->bld_line)
        return imp_fail(d, f->name, r.line, m->twr_line ? "BldFile(1)" : "TwrFile",
                        "not found in the main file");
    if (m->v[EM_NUMBL] != floor(m->v[EM_NUMBL]) || m->v[EM_NUMBL] < 1 || m->v[EM_NUMBL] > 3)
        return imp_fail(d, f->name, m->line[EM_NUMBL], "NumBl", "must be 1, 2 or 3 (%g)",
                        m->v[EM_NUMBL]);
    for (k = EM_TIPMASS; k < EM_N; k++)
        if (m->v[k] < 0)
            return imp_fail(d, f->name, m->line[k], em_names[k], "must be >= 0 (%g)", m->v[k]);
    return SM_OK;
}

/* Load the file the main file names at line (field), through the loader, into *out. */
static int ed_load(import_loader load, void *ctx, const char *main, const char *name, int line,
                   const char *field, import_file *out, import_diag *d)
{
    char why[160] = "";
    int st;

    if (!load)
        return imp_fail(d, main, line, field,
                        "the main ElastoDyn file names other files: "
                        "import it where they can be read (the CLI)");
    st = load(ctx, name, out, why, sizeof(why));
    if (st == SM_INVALID_INPUT) {
        imp_tok nt = {name, strlen(name)};
        char shown[IMP_EXCERPT_SIZE];
        imp_excerpt(shown, sizeof(shown), &nt);
        return imp_fail(d, main, line, field, "cannot read \"%s\": %s", shown, why);
    }
    if (!st && (!out->text || !out->len))
        return imp_fail(d, main, line, field,
                        "the file it names was not given (over HTTP: JSON {\"main\", "
                        "\"files\": {NAME: text}} with each file the main file names)");
    if (!st && !out->name)
        out->name = name;
    return st ? st : imp_encoding(d, out, out);
}

/* The tower-top rigid body being summed: mass, first moment, inertia about the tower top. */
typedef struct ed_top {
    double m, s[3], i[9];
} ed_top;

/* Add a body of mass m at p (tower axes fa, ss, up from the tower top) with the tensor j
 * about its own c.m. (NULL: a point). */
static void ed_top_add(ed_top *t, double m, const double p[3], const double *j)
{
    double pp = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    int a, b;

    t->m += m;
    for (a = 0; a < 3; a++) {
        t->s[a] += m * p[a];
        for (b = 0; b < 3; b++) /* parallel axes: m (|p|^2 I - p p') */
            t->i[3 * a + b] += (j ? j[3 * a + b] : 0) + m * ((a == b) * pp - p[a] * p[b]);
    }
}

/* The blade's mass, and its first and second moments of mass about the rotor apex (radius
 * HubRad + x (TipRad - HubRad)), trapezoidal over the stations. */
static void ed_blade_moments(const imp_table *t, double hub, double len, double mom[3])
{
    int j, k;

    mom[0] = mom[1] = mom[2] = 0;
    for (j = 0; j + 1 < t->n; j++) {
        double dx = (t->st[j + 1].v[IK_S] - t->st[j].v[IK_S]) * len;
        for (k = j; k <= j + 1; k++) {
            double r = hub + t->st[k].v[IK_S] * len, mu = t->st[k].v[IK_MU];
            mom[0] += 0.5 * dx * mu;
            mom[1] += 0.5 * dx * mu * r;
            mom[2] += 0.5 * dx * mu * r * r;
        }
    }
}

/* ElastoDyn's tower-top mass (TwrTpMass = YawBrMass + NacMass + HubMass + NumBl x (blade +
 * tip mass)) as one rigid body: the yaw bearing at the tower top; the nacelle at (NacCMxn,
 * NacCMyn, NacCMzn) with NacYIner about the yaw axis; the rotor apex at Twr2Shft up and
 * OverHang along the shaft c1 = (cos ShftTilt, 0, sin ShftTilt) (ElastoDyn's shaft: a negative
 * tilt lifts the upwind rotor, 87.6 + 1.96256 + 5.0191 sin 5 deg = 90 m hub height for the
 * NREL 5-MW), the hub HubCM downwind of it with HubIner about the shaft, the blades coned by
 * PreCone about the shaft (an axisymmetric rotor: half the polar inertia about each axis
 * normal to the shaft). */
static void ed_top_mass(const ed_main *m, const double bmom[3], int rigid_rotor, ed_top *top)
{
    const double *v = m->v;
    double T = v[EM_SHFTTILT] * ED_PI / 180, be = v[EM_PRECONE] * ED_PI / 180;
    double c1[3] = {cos(T), 0, sin(T)}, apex[3], p[3], j[9];
    double nb = v[EM_NUMBL], tip = v[EM_TIPMASS], R = v[EM_TIPRAD], mb = bmom[0] + tip;
    double jn = v[EM_NACYINER] -
                v[EM_NACMASS] * (v[EM_NACCMXN] * v[EM_NACCMXN] + v[EM_NACCMYN] * v[EM_NACCMYN]);
    double jr = nb * cos(be) * cos(be) * (bmom[2] + tip * R * R), zero[3] = {0, 0, 0};
    int a, b;

    memset(top, 0, sizeof(*top));
    ed_top_add(top, v[EM_YAWBRMASS], zero, NULL);
    memset(j, 0, sizeof(j));
    j[8] = jn > 0 ? jn : 0;
    p[0] = v[EM_NACCMXN], p[1] = v[EM_NACCMYN], p[2] = v[EM_NACCMZN];
    ed_top_add(top, v[EM_NACMASS], p, j);
    for (a = 0; a < 3; a++)
        apex[a] = v[EM_OVERHANG] * c1[a] + (a == 2) * v[EM_TWR2SHFT];
    for (a = 0; a < 3; a++)
        for (b = 0; b < 3; b++)
            j[3 * a + b] = v[EM_HUBINER] * c1[a] * c1[b];
    for (a = 0; a < 3; a++)
        p[a] = apex[a] + v[EM_HUBCM] * c1[a];
    ed_top_add(top, v[EM_HUBMASS], p, j);
    for (a = 0; a < 3; a++) {
        p[a] = apex[a] + c1[a] * sin(be) * (bmom[1] + tip * R) / (mb > 0 ? mb : 1);
        for (b = 0; b < 3; b++)
            j[3 * a + b] = jr * c1[a] * c1[b] + 0.5 * jr * ((a == b) - c1[a] * c1[b]);
    }
    ed_top_add(top, nb * mb, p, rigid_rotor ? j : NULL);
}

/* The top mass as the tower form takes it: offset = c.m., inertia and products about it. */
static json_t *ed_top_json(const ed_top *t)
{
    double c[3], ic[9], vv;
    int a, b;

    for (a = 0; a < 3; a++)
        c[a] = t->s[a] / t->m;
    for (a = 0; a < 3; a++) /* back from the tower top to the c.m. */
        for (b = 0; b < 3; b++) {
            vv = t->i[3 * a + b] -
                 t->m * ((a == b) * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) - c[a] * c[b]);
            ic[3 * a + b] = fabs(vv) < 1e-9 * (fabs(t->i[0]) + fabs(t->i[4]) + fabs(t->i[8]))
                                ? 0.0
                                : imp_round(vv);
        }
    return json_pack("{s:f, s:[f,f,f], s:[f,f,f], s:[f,f,f]}", "mass", imp_round(t->m), "offset",
                     imp_round(c[0]), imp_round(c[1]), imp_round(c[2]), "inertia", ic[0], ic[4],
                     ic[8], "products", ic[1], ic[5], ic[6]);
}

/* The blade-form document made a tower form: request.tower {height, base_height, elements,
 * section, stations, top_mass}, speed 0, warnings' pointers /blade -> /tower. */
static int ed_tower_doc(json_t *doc, const ed_main *m, json_t *top)
{
    json_t *req = json_object_get(doc, "request"), *bl = json_object_get(req, "blade");
    json_t *an = json_object_get(req, "analysis"), *tw = json_object(), *w;
    const char *const keep[] = {"elements", "section", "stations"};
    const char *const lists[] = {"warnings", "input_warnings"};
    size_t i;
    int bad = !tw || !bl || !an || !top, k;

    bad = bad || json_object_set_new(tw, "height", json_real(imp_round(m->v[EM_TOWERHT]))) ||
          json_object_set_new(tw, "base_height",
                              json_real(imp_round(m->v[EM_TOWERBSHT] + m->v[EM_TWRRBHT])));
    for (k = 0; !bad && k < 3; k++)
        if (json_object_get(bl, keep[k]))
            bad |= json_object_set(tw, keep[k], json_object_get(bl, keep[k]));
    bad = bad || json_object_set_new(tw, "top_mass", top);
    top = NULL;
    if (bad || json_object_set_new(req, "tower", tw) || json_object_del(req, "blade") ||
        json_object_del(an, "rpm") || json_object_set_new(an, "omega", json_pack("[f]", 0.0))) {
        json_decref(top);
        return -1;
    }
    for (k = 0; k < 2; k++)
        json_array_foreach(json_object_get(doc, lists[k]), i, w) {
            const char *p = json_string_value(json_object_get(w, "pointer"));
            char buf[256];
            if (p && !strncmp(p, "/blade", 6)) {
                snprintf(buf, sizeof(buf), "/tower%s", p + 6);
                if (json_object_set_new(w, "pointer", json_string(buf)))
                    return -1;
            }
        }
    return 0;
}

/* Stand-ins for what ElastoDyn's blades and tower lack (DESIGN.md 8.5, 9.3): EA = 1e7 EI/L^2,
 * GJ = 1e5 EI (ElastoDyn's are rigid in extension and torsion; a tower's top mass, with its
 * c.m. offset and product of inertia, couples them to bending, so the 1e4 and 10 of the CSV
 * import moved the NREL tower's bending frequencies by 3e-3 under 10x changes and the blade's
 * by 1e-3; these move them by <= 2e-7 when changed 10x), and rotary inertias mu (1e-5 L)^2
 * (ElastoDyn has none; the default mu EI/EA would tie the frequencies to the EA stand-in).
 * Only what the file does not give; each with a warning replacing imp_assumed_section's. */
#define ED_TW_EA 1e7
#define ED_TW_GJ 1e5
#define ED_TW_RG 1e-5

static int ed_standins(json_t *doc, const imp_table *t, double length, const char *form)
{
    json_t *tw = json_object_get(json_object_get(doc, "request"), form);
    json_t *sec = json_object_get(tw, "section"), *ws = json_object_get(doc, "input_warnings"), *st;
    double ei = imp_table_max(t, IK_EI_FLAP), ea, gj, rg = ED_TW_RG * length;
    json_t *marks = json_array();
    char ptr[3][40];
    size_t i;
    int bad = !marks, inert;

    snprintf(ptr[0], sizeof(ptr[0]), "/%s/section/EA", form);
    snprintf(ptr[1], sizeof(ptr[1]), "/%s/section/GJ", form);
    snprintf(ptr[2], sizeof(ptr[2]), "/%s/stations", form);
    if (imp_table_max(t, IK_EI_EDGE) > ei)
        ei = imp_table_max(t, IK_EI_EDGE);
    ea = imp_round(ED_TW_EA * ei / (length * length));
    gj = imp_round(ED_TW_GJ * ei);
    for (i = json_array_size(ws); i-- > 0;) { /* imp_assumed_section's warnings go */
        const char *p = json_string_value(json_object_get(json_array_get(ws, i), "pointer"));
        if (p && (!strcmp(p, ptr[0]) || !strcmp(p, ptr[1])))
            bad |= json_array_remove(ws, i);
    }
    inert = !(t->mask & (1u << IK_I_FLAP)) && !(t->mask & (1u << IK_I_EDGE));
    if (inert)
        json_array_foreach(json_object_get(tw, "stations"), i, st) {
            double mu = json_number_value(json_object_get(st, "mass_per_length"));
            bad |= json_object_set_new(st, "flap_inertia", json_real(imp_round(mu * rg * rg)));
            bad |= json_object_set_new(st, "edge_inertia", json_real(imp_round(mu * rg * rg)));
        }
    if (json_object_get(sec, "EA")) {
        bad |= json_object_set_new(sec, "EA", json_real(ea)) ||
               json_array_append_new(marks, json_string("EA"));
        bad |= imp_warn(ws, ptr[0],
                        "EA is not in the ElastoDyn %s file (rigid in extension): "
                        "%s.section.EA = %.6g N assumed (1e7 x the largest EI / length^2)%s",
                        form, form, ea,
                        inert ? "; and as ElastoDyn has no rotary inertia, flap_inertia = "
                                "edge_inertia = mass_per_length x (1e-5 x length)^2 at each "
                                "station (negligible, and independent of EA)"
                              : "");
    } else if (inert) {
        bad |= imp_warn(ws, ptr[2],
                        "ElastoDyn's %s has no rotary inertia: flap_inertia = edge_inertia = "
                        "mass_per_length x (1e-5 x length)^2 (negligible)",
                        form);
    }
    if (json_object_get(sec, "GJ")) {
        bad |= json_object_set_new(sec, "GJ", json_real(gj)) ||
               json_array_append_new(marks, json_string("GJ"));
        bad |= imp_warn(ws, ptr[1],
                        "GJ is not in the ElastoDyn %s file (rigid in torsion): "
                        "%s.section.GJ = %.6g N m^2 assumed (1e5 x the largest EI)",
                        form, form, gj);
    }
    /* marked, so that the plausibility check reads EA through EI (DESIGN.md 8.4) */
    if (json_array_size(marks))
        bad |= json_object_set(sec, "stand_ins", marks);
    json_decref(marks);
    return bad || imp_legacy_warnings(doc) ? -1 : 0;
}

/* ed_standins on a blade document made with status st; the status (SM_NOMEM on failure,
 * the document freed).  Their EA of 1e7 EI/L^2 is an axial wave speed of ~4e5 m/s: the
 * section's "stand_ins" mark lets the plausibility check (plausible.c) read it through EI
 * instead of reporting an EA slip on every ElastoDyn blade (DESIGN.md 8.4). */
static int ed_blade_standins(json_t **out, const imp_table *t, double length, int st)
{
    if (st == SM_OK && ed_standins(*out, t, length, "blade")) {
        json_decref(*out);
        *out = NULL;
        st = SM_NOMEM;
    }
    return st;
}

/* The main file's blade (CLI --part blade): BldFile(1) with TipRad, HubRad, PreCone(1),
 * TipMass(1) and RotSpeed (rpm; the option --rpm overrides it), so that no radius option is
 * needed. */
static int ed_main_blade(json_t **out, const import_file *f, const ed_main *m, import_loader load,
                         void *ctx, const import_options *o, import_diag *d)
{
    json_t *warn = json_array(), *src;
    imp_table t = {NULL, 0, 0, 0};
    import_file bf = {NULL, NULL, 0};
    imp_blade bl;
    ed_params p;
    int st;

    imp_blade_init(&bl);
    if (!warn)
        return SM_NOMEM;
    if ((st = ed_load(load, ctx, f->name, m->bld, m->bld_line, "BldFile(1)", &bf, d)) ||
        (st = ed_file(&bf, &ed_blade, d, &p, &t, warn)) ||
        (st = imp_length(d, f->name, m->line[EM_TIPRAD], "TipRad", m->v[EM_HUBRAD],
                         m->v[EM_TIPRAD] - m->v[EM_HUBRAD])))
        goto done;
    bl.hub_radius = m->v[EM_HUBRAD];
    bl.length = m->v[EM_TIPRAD] - m->v[EM_HUBRAD];
    bl.length_line = m->line[EM_TIPRAD];
    bl.length_field = "TipRad";
    bl.precone_deg = m->v[EM_PRECONE];
    bl.has_tip = m->v[EM_TIPMASS] > 0;
    bl.tip_mass = m->v[EM_TIPMASS];
    bl.rpm = isnan(o->rpm) ? m->v[EM_ROTSPEED] : o->rpm;
    bl.rpm_speeds = isnan(o->rpm) ? NULL : o->rpm_speeds;
    if (isnan(o->rpm) && !m->line[EM_ROTSPEED] &&
        imp_warn(warn, "/analysis/rpm", "no RotSpeed in the main file: analysis.rpm = [0]")) {
        st = SM_NOMEM;
        goto done;
    }
    if (!(src = ed_source(&p, bf.name)) ||
        json_object_set_new(src, "main_file", imp_string(f->name))) {
        json_decref(src);
        st = SM_NOMEM;
        goto done;
    }
    st = imp_document_assumed(out, d, bf.name, &bl, &t, "ElastoDyn blade", ed_ei_names, warn, src);
    warn = NULL;
    st = ed_blade_standins(out, &t, bl.length, st);
done:
    json_decref(warn);
    imp_table_clear(&t);
    return st;
}

/* The main file: the tower form (the file's head comment). */
static int ed_main_import(json_t **out, const import_file *f, import_loader load, void *ctx,
                          const import_options *o, import_diag *d)
{
    json_t *warn = json_array(), *src = NULL, *top;
    imp_table t = {NULL, 0, 0, 0}, tb = {NULL, 0, 0, 0};
    import_file tf = {NULL, NULL, 0}, bf = {NULL, NULL, 0};
    double bmom[3], base;
    ed_params p, pb;
    imp_blade bl;
    ed_top tm;
    ed_main m;
    int st;

    imp_blade_init(&bl);
    if (!warn)
        return SM_NOMEM;
    if ((!isnan(o->rpm) && !o->ed_blade) || !isnan(o->tip_radius) || !isnan(o->hub_radius)) {
        st = imp_fail(d, f->name, 0,
                      isnan(o->tip_radius) && isnan(o->hub_radius) ? "rpm" : "tip_radius",
                      "the main ElastoDyn file gives the blade's radii (TipRad, HubRad), and "
                      "its tower does not spin: the tip and hub radius options do not apply, "
                      "nor the rpm without --part blade");
        goto done;
    }
    if ((st = ed_main_read(f, d, &m)))
        goto done;
    if (o->ed_blade) {
        json_decref(warn);
        return ed_main_blade(out, f, &m, load, ctx, o, d);
    }
    if ((st = ed_load(load, ctx, f->name, m.twr, m.twr_line, "TwrFile", &tf, d)) ||
        (st = ed_file(&tf, &ed_tower, d, &p, &t, warn)))
        goto done;
    if (!(src = ed_source(&p, tf.name)) ||
        json_object_set_new(src, "main_file", imp_string(f->name))) {
        st = SM_NOMEM;
        goto done;
    }
    /* the tower file is read: the loader may reuse its buffer for the blade file */
    if ((st = ed_load(load, ctx, f->name, m.bld, m.bld_line, "BldFile(1)", &bf, d)) ||
        (st = ed_file(&bf, &ed_blade, d, &pb, &tb, warn)))
        goto done;
    base = m.v[EM_TOWERBSHT] + m.v[EM_TWRRBHT];
    bl.hub_radius = base;
    bl.length = m.v[EM_TOWERHT] - base;
    bl.rpm = 0;
    if ((st = imp_length(d, f->name, m.line[EM_TOWERHT], "TowerHt", base, bl.length)) ||
        (st = imp_length(d, f->name, m.line[EM_TIPRAD], "TipRad", m.v[EM_HUBRAD],
                         m.v[EM_TIPRAD] - m.v[EM_HUBRAD])))
        goto done;
    ed_blade_moments(&tb, m.v[EM_HUBRAD], m.v[EM_TIPRAD] - m.v[EM_HUBRAD], bmom);
    ed_top_mass(&m, bmom, 0, &tm);
    if (imp_warn(warn, "/tower/top_mass",
                 "top_mass = ElastoDyn's tower-top mass %.6g kg (YawBrMass + NacMass + HubMass + "
                 "%g blades of %.6g kg from %s) as one rigid body (DESIGN.md 8.5)",
                 tm.m, m.v[EM_NUMBL], bmom[0], bf.name)) {
        st = SM_NOMEM;
        goto done;
    }
    st = imp_document_assumed(out, d, tf.name, &bl, &t, "ElastoDyn tower", ed_tw_ei_names, warn,
                              src);
    warn = src = NULL;
    if (!st && ((top = ed_top_json(&tm)) == NULL || ed_tower_doc(*out, &m, top) ||
                ed_standins(*out, &t, bl.length, "tower"))) {
        json_decref(*out);
        *out = NULL;
        st = SM_NOMEM;
    }
done:
    json_decref(warn);
    json_decref(src);
    imp_table_clear(&t);
    imp_table_clear(&tb);
    return st;
}

int import_elastodyn_files(json_t **out, const import_file *f, import_loader load, void *ctx,
                           const import_options *o, import_diag *d)
{
    json_t *warn;
    imp_table t = {NULL, 0, 0, 0};
    imp_blade bl;
    ed_params p;
    imp_reader r;
    import_file body;
    int st;

    *out = NULL;
    imp_blade_init(&bl);
    if ((st = imp_encoding(d, f, &body)))
        return st;
    imp_reader_init(&r, &body);
    if (imp_next(&r) && ed_contains(r.s, r.n, "ELASTODYN") && !ed_contains(r.s, r.n, "BLADE") &&
        !ed_contains(r.s, r.n, "TOWER"))
        return ed_main_import(out, &body, load, ctx, o, d);
    if (r.line == 1 && ed_contains(r.s, r.n, "TOWER"))
        return imp_fail(d, f->name, 1, "header",
                        "an ElastoDyn tower file has no height: import the main ElastoDyn file "
                        "that names it (TwrFile)");
    if (o->ed_blade)
        return imp_fail(d, f->name, 0, "part",
                        "--part applies to a main ElastoDyn file (this one is a blade file)");
    if (!(warn = json_array()))
        return SM_NOMEM;
    if ((st = ed_file(&body, &ed_blade, d, &p, &t, warn)) ||
        (st = imp_options_apply(d, f->name, o, 0, &bl, warn)))
        goto done;
    st = imp_document_assumed(out, d, f->name, &bl, &t, "ElastoDyn blade", ed_ei_names, warn,
                              ed_source(&p, f->name));
    warn = NULL;
    st = ed_blade_standins(out, &t, bl.length, st);
done:
    json_decref(warn);
    imp_table_clear(&t);
    return st;
}

int import_elastodyn(json_t **out, const import_file *f, const import_options *o, import_diag *d)
{
    return import_elastodyn_files(out, f, NULL, NULL, o, d);
}
