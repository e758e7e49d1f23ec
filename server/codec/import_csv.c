/*
 * import_csv.c — a CSV table of stations into the blade form (spec 12
 * section 6).
 *
 * The file: '#' starts a comment (to the end of the line), blank lines are
 * skipped; the first other line is the header, comma-separated station
 * keys, each optionally followed by its unit in brackets
 * ("EI_flap [N m^2]"); every further line is one station with as many
 * fields as the header.  Keys: s (span fraction, 0 to 1) or r (m from the
 * spin axis along the blade: hub_radius = first r, length = last - first),
 * mass_per_length, EA, EI_flap, EI_edge, GJ, flap_inertia, edge_inertia,
 * twist_deg, inertia_twist_deg and the offsets as two columns each:
 * cg_offset_edge, cg_offset_flap, shear_center_offset_edge, ... .
 * mass_per_length, EI_flap and EI_edge are required; a missing EA or GJ is
 * assumed (imp_assumed_section, with a warning).  Units must be the SI ones
 * (spelled with or without spaces, '*', '.', '-', '^': "N m^2", "Nm2",
 * "N*m^2"); any other unit is an error, never a silent conversion.
 * The text is UTF-8 or ASCII: a UTF-8 byte-order mark (Excel's "CSV UTF-8")
 * is skipped, UTF-16 refused (imp_encoding).  With r, the blade must be
 * longer than IMPORT_MIN_LENGTH and IMPORT_MIN_LENGTH_RATIO x the last r
 * (imp_length).
 */
#include "import_internal.h"

#include <stdio.h>
#include <string.h>

#define CSV_MAX_COLUMNS 32
#define CSV_R (-2) /* column r (m), not a station key */

/* Columns and their SI unit, spelled normalised (csv_unit_norm) and as shown. */
static const struct {
    const char *name;
    int key;          /* imp_key, or CSV_R */
    const char *unit; /* normalised */
    const char *shown;
} csv_cols[] = {
    {"s", IK_S, "", "-"},
    {"r", CSV_R, "m", "m"},
    {"mass_per_length", IK_MU, "kg/m", "kg/m"},
    {"EA", IK_EA, "N", "N"},
    {"EI_flap", IK_EI_FLAP, "Nm2", "N m^2"},
    {"EI_edge", IK_EI_EDGE, "Nm2", "N m^2"},
    {"GJ", IK_GJ, "Nm2", "N m^2"},
    {"flap_inertia", IK_I_FLAP, "kgm", "kg m"},
    {"edge_inertia", IK_I_EDGE, "kgm", "kg m"},
    {"twist_deg", IK_TWIST, "deg", "deg"},
    {"inertia_twist_deg", IK_ITWIST, "deg", "deg"},
    {"cg_offset_edge", IK_CG_E, "m", "m"},
    {"cg_offset_flap", IK_CG_F, "m", "m"},
    {"shear_center_offset_edge", IK_SC_E, "m", "m"},
    {"shear_center_offset_flap", IK_SC_F, "m", "m"},
    {"tension_center_offset_edge", IK_TC_E, "m", "m"},
    {"tension_center_offset_flap", IK_TC_F, "m", "m"},
};
#define CSV_NCOLS ((int)(sizeof(csv_cols) / sizeof(csv_cols[0])))

/*
 * Split a CSV line at commas (only: a field may hold spaces, "EI_flap [N
 * m^2]"), each field trimmed and unquoted; at most max stored, the count
 * returned.
 */
static int csv_split(const char *s, size_t n, imp_tok *t, int max)
{
    size_t i = 0;
    int count = 0;

    for (;;) {
        size_t b = i, e;
        while (i < n && s[i] != ',')
            i++;
        e = i;
        while (b < e && (s[b] == ' ' || s[b] == '\t'))
            b++;
        while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t'))
            e--;
        if (e - b >= 2 && s[b] == '"' && s[e - 1] == '"')
            b++, e--;
        if (count < max) {
            t[count].s = s + b;
            t[count].n = e - b;
        }
        count++;
        if (i >= n)
            return count;
        i++; /* the comma */
    }
}

/* Next line with content, '#' comments cut: 1, or 0 at the end. */
static int csv_next(imp_reader *r)
{
    while (imp_next(r)) {
        const char *h = memchr(r->s, '#', r->n);
        if (h)
            r->n = (size_t)(h - r->s);
        if (!imp_blank(r->s, r->n))
            return 1;
    }
    return 0;
}

/*
 * A unit spelled the canonical way into out[cap]: spaces, '*', '.', '^',
 * '-' and the middle dot dropped, "²" as 2, degree sign as deg; a lone
 * "-" or "1" is dimensionless ("").  -1 when too long.
 */
static int csv_unit_norm(const char *s, size_t n, char *out, size_t cap)
{
    size_t i, k = 0;

    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t'))
        n--;
    while (n > 0 && (*s == ' ' || *s == '\t'))
        s++, n--;
    if ((n == 1 && (s[0] == '-' || s[0] == '1')) || n == 0) {
        out[0] = '\0';
        return 0;
    }
    for (i = 0; i < n; i++) {
        unsigned char c = (unsigned char)s[i];
        const char *put = NULL;
        char one[2] = {(char)c, '\0'};
        if (c == ' ' || c == '\t' || c == '*' || c == '.' || c == '^' || c == '-')
            continue;
        if (c == 0xC2 && i + 1 < n && (unsigned char)s[i + 1] == 0xB7) { /* middle dot */
            i++;
            continue;
        }
        if (c == 0xC2 && i + 1 < n && (unsigned char)s[i + 1] == 0xB2) /* superscript 2 */
            put = "2", i++;
        else if (c == 0xC2 && i + 1 < n && (unsigned char)s[i + 1] == 0xB0) /* degree sign */
            put = "deg", i++;
        else
            put = one;
        if (k + strlen(put) >= cap)
            return -1;
        memcpy(out + k, put, strlen(put));
        k += strlen(put);
    }
    out[k] = '\0';
    if (!strcmp(out, "degree") || !strcmp(out, "degrees"))
        strcpy(out, "deg");
    return 0;
}

/* One header field "name [unit]" into *col (index into csv_cols). */
static int csv_header_field(imp_reader *r, import_diag *d, const imp_tok *f, int *col)
{
    const char *file = r->f->name, *lb = memchr(f->s, '[', f->n);
    imp_tok name = *f;
    char shown[IMP_EXCERPT_SIZE], unit[32];
    int k;

    if (lb)
        name.n = (size_t)(lb - f->s);
    while (name.n > 0 && (name.s[name.n - 1] == ' ' || name.s[name.n - 1] == '\t'))
        name.n--;
    imp_excerpt(shown, sizeof(shown), &name);
    if (name.n == 0)
        return imp_fail(d, file, r->line, "header", "a column has no name");
    for (k = 0; k < CSV_NCOLS; k++)
        if (strlen(csv_cols[k].name) == name.n && !memcmp(csv_cols[k].name, name.s, name.n))
            break;
    if (k == CSV_NCOLS)
        return imp_fail(d, file, r->line, shown,
                        "unknown column; expected s or r, then station keys (mass_per_length, "
                        "EA, EI_flap, EI_edge, GJ, flap_inertia, edge_inertia, twist_deg, "
                        "inertia_twist_deg, cg_offset_edge, cg_offset_flap, "
                        "shear_center_offset_edge, ..., tension_center_offset_flap)");
    *col = k;
    if (!lb)
        return SM_OK;
    {
        const char *rb = memchr(lb, ']', f->n - (size_t)(lb - f->s));
        imp_tok u = {lb + 1, rb ? (size_t)(rb - lb - 1) : 0};
        char ushown[IMP_EXCERPT_SIZE];
        if (!rb || !imp_blank(rb + 1, f->n - (size_t)(rb + 1 - f->s)))
            return imp_fail(d, file, r->line, shown, "the unit must be in brackets after the "
                            "name, as in \"EI_flap [N m^2]\"");
        imp_excerpt(ushown, sizeof(ushown), &u);
        if (csv_unit_norm(u.s, u.n, unit, sizeof(unit)) || strcmp(unit, csv_cols[k].unit))
            return imp_fail(d, file, r->line, shown, "unknown unit [%s]; expected [%s] (SI)",
                            ushown, csv_cols[k].shown);
    }
    return SM_OK;
}

/* The header line: col[0..*ncol) indexes csv_cols. */
static int csv_header(imp_reader *r, import_diag *d, int *col, int *ncol)
{
    const char *file = r->f->name;
    imp_tok f[CSV_MAX_COLUMNS + 1];
    int seen[CSV_NCOLS] = {0};
    int n, c, st;

    if (!csv_next(r))
        return imp_fail(d, file, r->line + 1, "header",
                        "the file has no header row (station keys separated by commas)");
    n = csv_split(r->s, r->n, f, CSV_MAX_COLUMNS + 1);
    if (n > CSV_MAX_COLUMNS)
        return imp_fail(d, file, r->line, "header", "more than %d columns", CSV_MAX_COLUMNS);
    for (c = 0; c < n; c++) {
        if ((st = csv_header_field(r, d, &f[c], &col[c])))
            return st;
        if (seen[col[c]]++)
            return imp_fail(d, file, r->line, csv_cols[col[c]].name, "column given twice");
    }
    if (seen[0] == seen[1])
        return imp_fail(d, file, r->line, "s", "give exactly one of the columns s (span "
                        "fraction) and r (m from the spin axis)");
    for (c = 2; c < 6; c++)
        if (c != 3 && !seen[c]) /* mass_per_length, EI_flap, EI_edge */
            return imp_fail(d, file, r->line, csv_cols[c].name, "column missing (required)");
    *ncol = n;
    return SM_OK;
}

/* The rows: values into t (r goes into IK_S, converted by csv_radii). */
static int csv_rows(imp_reader *r, import_diag *d, const int *col, int ncol, imp_table *t)
{
    const char *file = r->f->name;
    imp_tok f[CSV_MAX_COLUMNS + 1];
    int n, c, st;

    for (c = 0; c < ncol; c++)
        t->mask |= 1u << (csv_cols[col[c]].key == CSV_R ? IK_S : csv_cols[col[c]].key);
    while (csv_next(r)) {
        imp_station *s;
        n = csv_split(r->s, r->n, f, CSV_MAX_COLUMNS + 1);
        if (n < ncol)
            return imp_fail(d, file, r->line, csv_cols[col[n]].name,
                            "missing: the row has %d columns, expected %d", n, ncol);
        if (n > ncol)
            return imp_fail(d, file, r->line, "row", "%d columns, expected %d (as the header)",
                            n, ncol);
        if (t->n >= IMPORT_MAX_STATIONS)
            return imp_fail(d, file, r->line, "row", "more than %d stations",
                            IMPORT_MAX_STATIONS);
        if (!(s = imp_table_add(t)))
            return SM_NOMEM;
        s->line = r->line;
        for (c = 0; c < ncol; c++) {
            int key = csv_cols[col[c]].key;
            int kind = key == CSV_R ? IMP_NONNEG : imp_key_kind((imp_key)key);
            if ((st = imp_value(d, file, r->line, csv_cols[col[c]].name, &f[c], kind,
                                &s->v[key == CSV_R ? IK_S : key])))
                return st;
        }
    }
    if (t->n == 0)
        return imp_fail(d, file, r->line + 1, "row",
                        "the file ends before the first station (truncated?)");
    return SM_OK;
}

/* Column r: hub radius and length from the first and last, then s = (r - r0) / length. */
static int csv_radii(import_diag *d, const char *file, imp_table *t, imp_blade *bl)
{
    double r0, len;
    int i, st;

    for (i = 1; i < t->n; i++)
        if (!(t->st[i].v[IK_S] > t->st[i - 1].v[IK_S]))
            return imp_fail(d, file, t->st[i].line, "r",
                            "stations out of order: %.15g after %.15g (must increase)",
                            t->st[i].v[IK_S], t->st[i - 1].v[IK_S]);
    if (t->n < 2)
        return imp_fail(d, file, t->st[0].line, "r",
                        "at least 2 stations are needed (root and tip), 1 given");
    r0 = t->st[0].v[IK_S];
    len = t->st[t->n - 1].v[IK_S] - r0;
    bl->hub_radius = r0;
    bl->length = len;
    bl->length_line = t->st[t->n - 1].line;
    bl->length_field = "r";
    if ((st = imp_length(d, file, bl->length_line, "r", r0, len)))
        return st;
    for (i = 0; i < t->n; i++)
        t->st[i].v[IK_S] = (t->st[i].v[IK_S] - r0) / len;
    t->st[0].v[IK_S] = 0.0;
    t->st[t->n - 1].v[IK_S] = 1.0;
    return SM_OK;
}

static json_t *csv_source(const char *file, const int *col, int ncol)
{
    json_t *src = json_object(), *cols = json_array();
    int c, bad = !src || !cols;

    for (c = 0; !bad && c < ncol; c++)
        bad |= json_array_append_new(cols, json_string(csv_cols[col[c]].name));
    if (!bad) {
        bad |= json_object_set_new(src, "format", json_string("csv"));
        bad |= json_object_set_new(src, "file", imp_string(file));
        bad |= json_object_set(src, "columns", cols);
    }
    json_decref(cols);
    if (bad) {
        json_decref(src);
        return NULL;
    }
    return src;
}

static const char *const csv_ei_names[2] = {"EI_flap", "EI_edge"};

int import_csv(json_t **out, const import_file *f, const import_options *o, import_diag *d)
{
    json_t *warn = json_array();
    imp_table t = {NULL, 0, 0, 0};
    int col[CSV_MAX_COLUMNS], ncol = 0, has_r, c, st;
    imp_blade bl;
    imp_reader r;
    import_file body;

    *out = NULL;
    imp_blade_init(&bl);
    if (!warn)
        return SM_NOMEM;
    if ((st = imp_encoding(d, f, &body)))
        goto done;
    imp_reader_init(&r, &body);
    if ((st = csv_header(&r, d, col, &ncol)) || (st = csv_rows(&r, d, col, ncol, &t)))
        goto done;
    for (has_r = 0, c = 0; c < ncol; c++)
        has_r |= csv_cols[col[c]].key == CSV_R;
    if (has_r && (st = csv_radii(d, f->name, &t, &bl)))
        goto done;
    if ((st = imp_table_order(d, f->name, &t, has_r ? "r" : "s")) ||
        (st = imp_options_apply(d, f->name, o, has_r, &bl, warn)))
        goto done;
    st = imp_document_assumed(out, d, f->name, &bl, &t, "CSV", csv_ei_names, warn,
                              csv_source(f->name, col, ncol));
    warn = NULL;
done:
    json_decref(warn);
    imp_table_clear(&t);
    return st;
}
