/*
 * import_test.c — the importers of server/codec/import.h against the real
 * files (BModes certification tests, the NREL 5-MW ElastoDyn blade file)
 * and against each kind of bad file, with the exact message expected.
 *
 * Usage: import_test REFERENCE_DIR   (tests/reference/blades)
 * Bad files are made from the good ones in memory: a line cut, a field
 * replaced (edit()), so each case shows the one thing that is wrong.
 */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "import.h"

static int failures;
static const char *ref_dir;

static void fail(const char *fmt, ...)
{
    va_list ap;

    va_start(ap, fmt);
    fputs("FAIL: ", stdout);
    vprintf(fmt, ap);
    fputc('\n', stdout);
    va_end(ap);
    failures++;
}

/* Read ref_dir/rel whole (NUL-terminated); exits on failure. */
static char *slurp(const char *rel)
{
    char path[1024];
    FILE *f;
    char *b;
    long n;

    snprintf(path, sizeof(path), "%s/%s", ref_dir, rel);
    f = fopen(path, "rb");
    if (!f || fseek(f, 0, SEEK_END) || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET)) {
        fprintf(stderr, "cannot read %s\n", path);
        exit(1);
    }
    b = malloc((size_t)n + 1);
    if (!b || fread(b, 1, (size_t)n, f) != (size_t)n) {
        fprintf(stderr, "cannot read %s\n", path);
        exit(1);
    }
    b[n] = '\0';
    fclose(f);
    return b;
}

/* Copy of text with the first `from` on line `line` (1-based) replaced by `to`. */
static char *edit(const char *text, int line, const char *from, const char *to)
{
    const char *p = text, *hit;
    char *out;
    int i;

    for (i = 1; i < line && p; i++) {
        p = strchr(p, '\n');
        if (p)
            p++;
    }
    hit = p ? strstr(p, from) : NULL;
    if (!hit || (strchr(p, '\n') && hit > strchr(p, '\n'))) {
        fprintf(stderr, "edit: '%s' not on line %d\n", from, line);
        exit(1);
    }
    out = malloc(strlen(text) - strlen(from) + strlen(to) + 1);
    memcpy(out, text, (size_t)(hit - text));
    strcpy(out + (hit - text), to);
    strcat(out, hit + strlen(from));
    return out;
}

/* Copy of the first `lines` lines of text. */
static char *cut(const char *text, int lines)
{
    const char *p = text;
    char *out;
    int i;

    for (i = 0; i < lines && p; i++) {
        p = strchr(p, '\n');
        if (p)
            p++;
    }
    out = strdup(text);
    if (p)
        out[p - text] = '\0';
    return out;
}

/* ---------------------------------------------------------------- BModes */

static int load_sec(void *ctx, const char *name, import_file *out, char *why, size_t cap)
{
    (void)name;
    if (!ctx) {
        snprintf(why, cap, "No such file or directory");
        return SM_INVALID_INPUT;
    }
    out->name = NULL;
    out->text = ctx;
    out->len = strlen(ctx);
    return SM_OK;
}

static int bmodes(json_t **doc, const char *name, const char *bmi, const char *sec,
                  import_diag *d)
{
    import_file f = {name, bmi, strlen(bmi)};
    import_options o;

    import_default_options(&o);
    return import_bmodes(doc, &f, load_sec, (void *)sec, &o, d);
}

static double num(const json_t *doc, const char *path)
{
    /* path: keys and indexes separated by '/', e.g. "request/blade/stations/2/EA" */
    char buf[256], *tok, *save = NULL;
    const json_t *cur = doc;
    double x = NAN;

    snprintf(buf, sizeof(buf), "%s", path);
    for (tok = strtok_r(buf, "/", &save); tok && cur; tok = strtok_r(NULL, "/", &save))
        cur = json_is_array(cur) ? json_array_get(cur, (size_t)atoi(tok))
                                 : json_object_get(cur, tok);
    if (cur && json_is_number(cur))
        x = json_number_value(cur);
    return x;
}

static void expect_num(const json_t *doc, const char *path, double want, const char *what)
{
    double got = num(doc, path);

    if (!(fabs(got - want) <= 1e-12 * fabs(want)))
        fail("%s: %s = %.17g, expected %.17g", what, path, got, want);
}

static void expect_error(const char *what, int st, const import_diag *d, const char *want);

static void test_bmodes_good(void)
{
    char *bmi1 = slurp("bmodes_certtest/Test01_nonunif_blade.bmi");
    char *bmi2 = slurp("bmodes_certtest/Test02_blade_with_tip_mass.bmi");
    char *sec = slurp("bmodes_certtest/blade_sec_props.dat");
    json_t *doc = NULL;
    import_diag d;
    const json_t *b;
    int i;

    /* Test01: no tip mass */
    if (bmodes(&doc, "Test01_nonunif_blade.bmi", bmi1, sec, &d) != SM_OK) {
        fail("Test01: %s", d.text);
    } else {
        b = json_object_get(json_object_get(doc, "request"), "blade");
        expect_num(doc, "request/blade/length", 33.25, "Test01");
        expect_num(doc, "request/blade/hub_radius", 1.75, "Test01");
        expect_num(doc, "request/blade/precone_deg", 0, "Test01");
        expect_num(doc, "request/blade/elements", 48, "Test01");
        expect_num(doc, "request/analysis/rpm/0", 60, "Test01");
        expect_num(doc, "request/analysis/modes", 20, "Test01");
        if (json_array_size(json_object_get(b, "stations")) != 21)
            fail("Test01: %zu stations", json_array_size(json_object_get(b, "stations")));
        if (json_object_get(b, "tip_mass"))
            fail("Test01: a tip mass where the file has none");
        if (!json_is_false(json_object_get(json_object_get(json_object_get(doc, "request"),
                                                            "analysis"), "coriolis")))
            fail("Test01: coriolis is not false");
        expect_num(doc, "request/blade/stations/2/mass_per_length", 181.672, "Test01");
        expect_num(doc, "request/blade/stations/2/EA", 2611.3e6, "Test01");
        expect_num(doc, "request/blade/stations/2/cg_offset/0", 0.032, "Test01");
        expect_num(doc, "request/blade/stations/2/shear_center_offset/0", -0.005, "Test01");
        expect_num(doc, "request/blade/stations/6/twist_deg", 9.5, "Test01");
        expect_num(doc, "request/blade/stations/20/s", 1, "Test01");
        expect_num(doc, "source/el_loc/11", 0.9, "Test01");
        expect_num(doc, "source/nselt", 12, "Test01");
        for (i = 0; i < 21; i++) /* every station carries all 12 keys + s */
            if (json_object_size(json_array_get(json_object_get(b, "stations"), (size_t)i)) != 13)
                fail("Test01: station %d has %zu keys", i,
                     json_object_size(json_array_get(json_object_get(b, "stations"), (size_t)i)));
    }
    json_decref(doc);

    /* Test02: tip mass 40 kg, offset along the edgewise axis, inertias reordered */
    if (bmodes(&doc, "Test02_blade_with_tip_mass.bmi", bmi2, sec, &d) != SM_OK) {
        fail("Test02: %s", d.text);
    } else {
        expect_num(doc, "request/blade/length", 33.25, "Test02");
        expect_num(doc, "request/analysis/rpm/0", 60, "Test02");
        expect_num(doc, "request/blade/stations/2/mass_per_length", 181.672, "Test02");
        expect_num(doc, "request/blade/tip_mass/mass", 40, "Test02");
        expect_num(doc, "request/blade/tip_mass/offset/0", 0, "Test02");
        expect_num(doc, "request/blade/tip_mass/offset/1", 0.05, "Test02");
        expect_num(doc, "request/blade/tip_mass/offset/2", 0, "Test02");
        expect_num(doc, "request/blade/tip_mass/inertia/0", 2.5, "Test02");
        expect_num(doc, "request/blade/tip_mass/inertia/1", 1.75, "Test02");
        expect_num(doc, "request/blade/tip_mass/inertia/2", 10, "Test02");
    }
    json_decref(doc);

    /* multipliers, rpm_mult, precone and pitch */
    {
        char *a = edit(bmi1, 8, "1.0 ", "1.5 ");                 /* rpm_mult */
        char *b2 = edit(a, 11, "0. ", "2.5 ");                   /* precone */
        char *c = edit(b2, 12, "0. ", "-3 ");                    /* bl_thp */
        char *e = edit(c, 34, "1.0 ", "1.2 ");                   /* sec_mass_mult */
        char *g = edit(e, 37, "1.0 ", "0.5 ");                   /* flp_stff_mult */
        char *h = edit(g, 41, "1.0 ", "-1 ");                    /* cg_offst_mult */
        if (bmodes(&doc, "m.bmi", h, sec, &d) != SM_OK) {
            fail("multipliers: %s", d.text);
        } else {
            expect_num(doc, "request/analysis/rpm/0", 90, "multipliers");
            expect_num(doc, "request/blade/precone_deg", 2.5, "multipliers");
            expect_num(doc, "request/blade/pitch_deg", -3, "multipliers");
            expect_num(doc, "request/blade/stations/2/mass_per_length", 218.0064, "multipliers");
            /* edge_iner about the reference axis -> about the centre of mass: - mass cg^2 */
            expect_num(doc, "request/blade/stations/2/edge_inertia", 80.113 - 218.0064 * 0.032 * 0.032,
                       "multipliers");
            expect_num(doc, "request/blade/stations/2/flap_inertia", 68.241, "multipliers");
            expect_num(doc, "request/blade/stations/2/EI_flap", 510.31e6, "multipliers");
            expect_num(doc, "request/blade/stations/2/EI_edge", 1092.28e6, "multipliers");
            expect_num(doc, "request/blade/stations/2/cg_offset/0", -0.032, "multipliers");
            expect_num(doc, "source/multipliers/sec_mass_mult", 1.2, "multipliers");
        }
        json_decref(doc);
        /* twice the mass puts mass x cg^2 above edge_iner at the tip: BModes itself fails there
         * (its section mass matrix is not positive definite); the importer names the line */
        char *k = edit(bmi1, 34, "1.0 ", "2.0 ");
        int st = bmodes(&doc, "k.bmi", k, sec, &d);
        expect_error("mass multiplier 2", st, &d,
                     "blade_sec_props.dat:26: edge_iner: 0.747 kg m is below mass_den x cg_offst^2 = 1.09897 kg m: "
                     "the section's mass moment about its reference axis cannot be smaller than that of its mass at "
                     "the centre of mass");
        json_decref(doc);
        free(a), free(b2), free(c), free(e), free(g), free(h), free(k);
    }
    free(bmi1), free(bmi2), free(sec);
}

/* One bad case: the import must fail with exactly `want`. */
static void expect_error(const char *what, int st, const import_diag *d, const char *want)
{
    if (st != SM_INVALID_INPUT)
        fail("%s: status %d, expected SM_INVALID_INPUT (%s)", what, st, want);
    else if (strcmp(d->text, want))
        fail("%s:\n   got  %s\n   want %s", what, d->text, want);
}

static void bad_bmodes_sec(const char *what, char *sec, const char *want)
{
    char *bmi = slurp("bmodes_certtest/Test01_nonunif_blade.bmi");
    json_t *doc = NULL;
    import_diag d;
    int st = bmodes(&doc, "T.bmi", bmi, sec, &d);

    expect_error(what, st, &d, want);
    if (doc)
        json_decref(doc);
    free(bmi);
    free(sec);
}

static void bad_bmodes_main(const char *what, char *bmi, const char *want)
{
    char *sec = slurp("bmodes_certtest/blade_sec_props.dat");
    json_t *doc = NULL;
    import_diag d;
    int st = bmodes(&doc, "T.bmi", bmi, sec, &d);

    expect_error(what, st, &d, want);
    if (doc)
        json_decref(doc);
    free(bmi);
    free(sec);
}

static void test_bmodes_bad(void)
{
    char *sec = slurp("bmodes_certtest/blade_sec_props.dat");
    char *bmi = slurp("bmodes_certtest/Test01_nonunif_blade.bmi");
    json_t *doc = NULL;
    import_diag d;

    bad_bmodes_sec("sec truncated", cut(sec, 25),
                   "blade_sec_props.dat:26: sec_loc: the file ends before station 21 of 21 "
                   "(truncated?)");
    bad_bmodes_sec("sec column count", edit(sec, 8, "    0.0\n", "\n"),
                   "blade_sec_props.dat:8: tc_offst: missing: the row has 12 columns, expected 13");
    bad_bmodes_sec("sec extra column", edit(sec, 8, "    0.0\n", "    0.0  7\n"),
                   "blade_sec_props.dat:8: row: 14 columns, expected 13 (sec_loc ... tc_offst)");
    bad_bmodes_sec("sec not a number", edit(sec, 8, "2611.3E+06", "abc"),
                   "blade_sec_props.dat:8: axial_stff: not a number (\"abc\")");
    bad_bmodes_sec("sec negative stiffness", edit(sec, 9, " 771.88E+06", "-771.88E+06"),
                   "blade_sec_props.dat:9: flp_stff: must be > 0 (-771880000)");
    bad_bmodes_sec("sec zero mass", edit(sec, 10, "186.138", "0.0"),
                   "blade_sec_props.dat:10: mass_den: must be > 0 (0)");
    bad_bmodes_sec("sec negative inertia", edit(sec, 10, "27.444", "-1"),
                   "blade_sec_props.dat:10: flp_iner: must be >= 0 (-1)");
    bad_bmodes_sec("sec out of order", edit(sec, 9, "0.10526", "0.01"),
                   "blade_sec_props.dat:9: sec_loc: stations out of order: 0.01 after 0.05263 "
                   "(must increase)");
    bad_bmodes_sec("sec last not 1", edit(sec, 26, "1.00000", "0.99"),
                   "blade_sec_props.dat:26: sec_loc: the last station must be at the tip, 1 "
                   "(got 0.99)");
    bad_bmodes_sec("sec n_secs", edit(sec, 2, "21 ", "x1 "),
                   "blade_sec_props.dat:2: n_secs: not a number (\"x1\")");
    bad_bmodes_sec("sec empty", strdup(""),
                   "blade_sec_props.dat:1: header: the file ends here (truncated?): this line "
                   "is missing");

    bad_bmodes_main("main truncated", cut(bmi, 20),
                    "T.bmi:21: cm_axial: the file ends here (truncated?): this line is missing");
    /* a blade's file given as a tower's (DESIGN.md 8.5): no support lines after el_loc */
    bad_bmodes_main("blade as tower", edit(bmi, 6, "1 ", "2 "),
                    "T.bmi:51: tow_support: missing: beam_type (line 6) is 2 (tower), and a "
                    "tower's file goes on after el_loc with its support lines (tow_support, "
                    "BModes.f90:503), a number here; a blade's file has none: give beam_type 1 "
                    "to import it as a blade");
    bad_bmodes_main("hub_conn", edit(bmi, 13, "1 ", "2 "),
                    "T.bmi:13: hub_conn: only 1 (cantilevered) is supported (2)");
    bad_bmodes_main("rot_rpm", edit(bmi, 7, "60.0", "sixty"),
                    "T.bmi:7: rot_rpm: not a number (\"sixty\")");
    bad_bmodes_main("hub_rad", edit(bmi, 10, "1.75", "40"),
                    "T.bmi:10: hub_rad: must be less than radius 35 (40)");
    bad_bmodes_main("zero mass multiplier", edit(bmi, 34, "1.0 ", "0 "),
                    "T.bmi:34: sec_mass_mult: must be > 0 (0)");
    bad_bmodes_main("el_loc", edit(bmi, 48, "0.90", "0.9x"),
                    "T.bmi:48: el_loc: not a number (\"0.9x\")");
    bad_bmodes_main("nselt", edit(bmi, 46, "12 ", "1.5 "),
                    "T.bmi:46: nselt: must be an integer in [1, 10000] (1.5)");

    /* the section file cannot be loaded */
    expect_error("no sec file", bmodes(&doc, "T.bmi", bmi, NULL, &d), &d,
                 "T.bmi:31: sec_props_file: cannot read \"blade_sec_props.dat\": No such file "
                 "or directory");
    json_decref(doc);
    /* towers (DESIGN.md 8.5): the real Test03 is the tower form; its frequencies are
     * tests/cli/tower_test.py's */
    {
        char *t3 = slurp("bmodes_certtest/Test03_tower.bmi");
        char *ts = slurp("bmodes_certtest/tower_sec_props.dat");
        if (bmodes(&doc, "Test03_tower.bmi", t3, ts, &d) != SM_OK ||
            !json_object_get(json_object_get(doc, "request"), "tower"))
            fail("Test03: expected the tower form (%s)", d.text);
        json_decref(doc);
        doc = NULL;
        free(t3), free(ts);
    }
    free(sec);
    free(bmi);
}

/* ------------------------------------------------------------- ElastoDyn */

static int elastodyn(json_t **doc, const char *text, double tip, double hub, import_diag *d)
{
    import_file f = {"blade.dat", text, strlen(text)};
    import_options o;

    import_default_options(&o);
    o.tip_radius = tip;
    o.hub_radius = hub;
    return import_elastodyn(doc, &f, &o, d);
}

static void test_elastodyn(void)
{
    char *ed = slurp("elastodyn/NRELOffshrBsline5MW_Blade.dat");
    json_t *doc = NULL;
    import_diag d;

    if (elastodyn(&doc, ed, 63, 1.5, &d) != SM_OK) {
        fail("ElastoDyn 5MW: %s", d.text);
    } else {
        const json_t *b = json_object_get(json_object_get(doc, "request"), "blade");
        expect_num(doc, "request/blade/length", 61.5, "5MW");
        expect_num(doc, "request/blade/hub_radius", 1.5, "5MW");
        if (json_array_size(json_object_get(b, "stations")) != 49)
            fail("5MW: %zu stations", json_array_size(json_object_get(b, "stations")));
        /* BMassDen x AdjBlMs, rounded to 15 digits */
        expect_num(doc, "request/blade/stations/0/mass_per_length", 709.7314916, "5MW");
        expect_num(doc, "request/blade/stations/0/EI_flap", 1.811e10, "5MW");
        expect_num(doc, "request/blade/stations/48/EI_edge", 5.01e6, "5MW");
        expect_num(doc, "request/blade/stations/12/twist_deg", 13.181, "5MW");
        expect_num(doc, "request/blade/stations/48/s", 1, "5MW");
        if (!json_is_number(json_object_get(json_object_get(b, "section"), "EA")) ||
            !json_is_number(json_object_get(json_object_get(b, "section"), "GJ")))
            fail("5MW: no assumed EA/GJ in blade.section");
        if (json_array_size(json_object_get(doc, "warnings")) != 3) /* EA, GJ, rpm */
            fail("5MW: %zu warnings", json_array_size(json_object_get(doc, "warnings")));
        expect_num(doc, "source/AdjBlMs", 1.04536, "5MW");
    }
    json_decref(doc);
    doc = NULL;

    expect_error("ED no tip radius", elastodyn(&doc, ed, NAN, NAN, &d), &d,
                 "blade.dat: tip_radius: the file does not give the blade length: give the tip "
                 "radius (CLI --tip-radius, HTTP ?tip_radius=; TipRad in an ElastoDyn main file) "
                 "and the hub radius (--hub-radius, ?hub_radius=; HubRad)");
    {
        struct {
            const char *what;
            char *text;
            const char *want;
        } cases[] = {
            {"ED truncated", cut(ed, 40),
             "blade.dat:41: BlFract: the file ends before station 25 of 49 (NBlInpSt; "
             "truncated?)"},
            {"ED column count", edit(ed, 20, "  1.949780000000000E+10", ""),
             "blade.dat:20: EdgStff: missing: the row has 4 columns, expected 5"},
            {"ED not a number", edit(ed, 20, "7.405500000000000E+02", "7.4O55E+02"),
             "blade.dat:20: BMassDen: not a number (\"7.4O55E+02\")"},
            {"ED negative stiffness", edit(ed, 21, " 1.528740000000000E+10", "-1.528740000000000E+10"),
             "blade.dat:21: FlpStff: must be > 0 (-15287400000)"},
            {"ED zero mass", edit(ed, 21, "7.400420000000000E+02", "0.0"),
             "blade.dat:21: BMassDen: must be > 0 (0)"},
            {"ED out of order", edit(ed, 21, "5.203000000000000E-02", "3.0E-02"),
             "blade.dat:21: BlFract: stations out of order: 0.03 after 0.03577 (must increase)"},
            {"ED AdjBlMs", edit(ed, 11, "1.04536", "0"),
             "blade.dat:11: AdjBlMs: must be > 0 (0)"},
            {"ED no table", cut(ed, 13),
             "blade.dat:14: DISTRIBUTED BLADE PROPERTIES: the file ends before this section "
             "(truncated?)"},
            {"ED missing column", edit(ed, 15, "FlpStff", "FlpStiff"),
             "blade.dat:15: FlpStff: column missing from the table's title line"},
            {"ED not ElastoDyn", strdup("s,mass_per_length\n"),
             "blade.dat:1: header: not an ElastoDyn blade file (expected a first line like "
             "\"--- ELASTODYN ... INDIVIDUAL BLADE INPUT FILE ---\")"},
        };
        size_t i;
        for (i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
            doc = NULL;
            expect_error(cases[i].what, elastodyn(&doc, cases[i].text, 63, 1.5, &d), &d,
                         cases[i].want);
            json_decref(doc);
            free(cases[i].text);
        }
    }
    free(ed);
}

/* ------------------------------------------------------------------- CSV */

static int csv(json_t **doc, const char *text, double tip, import_diag *d)
{
    import_file f = {"st.csv", text, strlen(text)};
    import_options o;

    import_default_options(&o);
    o.tip_radius = tip;
    o.rpm = 12;
    return import_csv(doc, &f, &o, d);
}

static const char csv_good[] =
    "# a tapered blade\n"
    "s, mass_per_length [kg/m], EI_flap [N m^2], EI_edge [N*m^2], GJ [Nm^2], EA [N], "
    "twist_deg [deg], cg_offset_edge [m]\n"
    "0,   100, 4e8, 8e8, 1e8, 3e9, 10, 0.1   # root\n"
    "\n"
    "0.5,  60, 1e8, 3e8, 4e7, 2e9, 5, 0.05\n"
    "1,    20, 1e7, 5e7, 5e6, 1e9, 0, 0\n";

static void test_csv(void)
{
    json_t *doc = NULL;
    import_diag d;

    if (csv(&doc, csv_good, 20, &d) != SM_OK) {
        fail("CSV: %s", d.text);
    } else {
        const json_t *b = json_object_get(json_object_get(doc, "request"), "blade");
        expect_num(doc, "request/blade/length", 20, "CSV");
        expect_num(doc, "request/analysis/rpm/0", 12, "CSV");
        expect_num(doc, "request/blade/stations/1/s", 0.5, "CSV");
        expect_num(doc, "request/blade/stations/1/EI_edge", 3e8, "CSV");
        expect_num(doc, "request/blade/stations/0/cg_offset/0", 0.1, "CSV");
        expect_num(doc, "request/blade/stations/0/cg_offset/1", 0, "CSV");
        if (json_object_get(b, "section"))
            fail("CSV: a section although EA and GJ are given");
        if (json_array_size(json_object_get(b, "stations")) != 3)
            fail("CSV: %zu stations", json_array_size(json_object_get(b, "stations")));
        if (json_array_size(json_object_get(doc, "warnings")) != 1) /* hub radius */
            fail("CSV: %zu warnings", json_array_size(json_object_get(doc, "warnings")));
    }
    json_decref(doc);
    doc = NULL;
    /* r in m: hub radius and length from the column */
    if (csv(&doc, "r [m],mass_per_length,EI_flap,EI_edge\n2,10,1e6,2e6\n4,8,5e5,1e6\n12,5,1e5,2e5\n",
            NAN, &d) != SM_OK) {
        fail("CSV r: %s", d.text);
    } else {
        expect_num(doc, "request/blade/hub_radius", 2, "CSV r");
        expect_num(doc, "request/blade/length", 10, "CSV r");
        expect_num(doc, "request/blade/stations/1/s", 0.2, "CSV r");
        expect_num(doc, "request/blade/stations/2/s", 1, "CSV r");
        expect_num(doc, "request/blade/section/EA", 1e4 * 2e6 / 100, "CSV r");
        expect_num(doc, "request/blade/section/GJ", 2e7, "CSV r");
    }
    json_decref(doc);
    {
        static const char hdr[] = "s,mass_per_length,EI_flap,EI_edge\n";
        struct {
            const char *what;
            const char *text;
            const char *want;
        } cases[] = {
            {"CSV empty", "# nothing\n",
             "st.csv:2: header: the file has no header row (station keys separated by commas)"},
            {"CSV no rows", "s,mass_per_length,EI_flap,EI_edge\n",
             "st.csv:2: row: the file ends before the first station (truncated?)"},
            {"CSV unknown unit", "s,mass_per_length,EI_flap [kN m^2],EI_edge\n0,1,1,1\n1,1,1,1\n",
             "st.csv:1: EI_flap: unknown unit [kN m^2]; expected [N m^2] (SI)"},
            {"CSV unknown column", "s,mass,EI_flap,EI_edge\n",
             "st.csv:1: mass: unknown column; expected s or r, then station keys "
             "(mass_per_length, EA, EI_flap, EI_edge, GJ, flap_inertia, edge_inertia, twist_deg, "
             "inertia_twist_deg, cg_offset_edge, cg_offset_flap, shear_center_offset_edge, ..., "
             "tension_center_offset_flap)"},
            {"CSV missing column", "s,mass_per_length,EI_flap\n",
             "st.csv:1: EI_edge: column missing (required)"},
            {"CSV too few", "s,mass_per_length,EI_flap,EI_edge\n0,1,1,1\n1,1,1\n",
             "st.csv:3: EI_edge: missing: the row has 3 columns, expected 4"},
            {"CSV too many", "s,mass_per_length,EI_flap,EI_edge\n0,1,1,1,1\n",
             "st.csv:2: row: 5 columns, expected 4 (as the header)"},
            {"CSV empty field", "s,mass_per_length,EI_flap,EI_edge\n0,1,,1\n",
             "st.csv:2: EI_flap: missing value"},
            {"CSV not a number", "s,mass_per_length,EI_flap,EI_edge\n0,1,1e,1\n",
             "st.csv:2: EI_flap: not a number (\"1e\")"},
            {"CSV negative", "s,mass_per_length,EI_flap,EI_edge\n0,1,1,-5\n",
             "st.csv:2: EI_edge: must be > 0 (-5)"},
            {"CSV zero mass", "s,mass_per_length,EI_flap,EI_edge\n0,0,1,1\n",
             "st.csv:2: mass_per_length: must be > 0 (0)"},
            {"CSV nan", "s,mass_per_length,EI_flap,EI_edge\n0,nan,1,1\n",
             "st.csv:2: mass_per_length: not a number (\"nan\")"},
            {"CSV out of order", "s,mass_per_length,EI_flap,EI_edge\n0,1,1,1\n0.6,1,1,1\n0.4,1,1,1\n1,1,1,1\n",
             "st.csv:4: s: stations out of order: 0.4 after 0.6 (must increase)"},
            {"CSV first not 0", "s,mass_per_length,EI_flap,EI_edge\n0.1,1,1,1\n1,1,1,1\n",
             "st.csv:2: s: the first station must be at the root, 0 (got 0.1)"},
            {"CSV r out of order", "r,mass_per_length,EI_flap,EI_edge\n2,1,1,1\n2,1,1,1\n",
             "st.csv:3: r: stations out of order: 2 after 2 (must increase)"},
            {"CSV s and r", "s,r,mass_per_length,EI_flap,EI_edge\n",
             "st.csv:1: s: give exactly one of the columns s (span fraction) and r (m from the "
             "spin axis)"},
        };
        size_t i;
        (void)hdr;
        for (i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
            doc = NULL;
            expect_error(cases[i].what, csv(&doc, cases[i].text, 20, &d), &d, cases[i].want);
            json_decref(doc);
        }
    }
}

/* ------------------------------------------------------ issue 23, items 4 to 6 */

static const char dbl_max[] = "1.7976931348623157e308"; /* rounds to inf at 15 digits */

static int bmodes_rpm(json_t **doc, const char *bmi, const char *sec, double rpm,
                      import_diag *d)
{
    import_file f = {"T.bmi", bmi, strlen(bmi)};
    import_options o;

    import_default_options(&o);
    o.rpm = rpm;
    return import_bmodes(doc, &f, load_sec, (void *)sec, &o, d);
}

static int csv_opt(json_t **doc, const char *text, size_t len, double tip, double rpm,
                   import_diag *d)
{
    import_file f = {"st.csv", text, len == SIZE_MAX ? strlen(text) : len};
    import_options o;

    import_default_options(&o);
    o.tip_radius = tip;
    o.rpm = rpm;
    return import_csv(doc, &f, &o, d);
}

/*
 * Issue 23 item 4: numbers that are merely extreme were "out of memory" (json_real of an
 * infinity: a value past 1.79769313486231e308 rounds to inf at 15 digits; an assumed EA or
 * rot_rpm x rpm_mult overflows): each is now SM_INVALID_INPUT with the file, line and field.
 */
static void test_overflow_is_invalid(void)
{
    char *bmi = slurp("bmodes_certtest/Test01_nonunif_blade.bmi");
    char *sec = slurp("bmodes_certtest/blade_sec_props.dat");
    char *ed = slurp("elastodyn/NRELOffshrBsline5MW_Blade.dat");
    double big = strtod(dbl_max, NULL);
    json_t *doc = NULL;
    import_diag d;
    static const char ok[] = "s,mass_per_length,EI_flap,EI_edge\n0,1,1,1\n1,1,1,1\n";

    expect_error("4: CSV EI_flap 1e305, EA assumed",
                 csv_opt(&doc, "s,mass_per_length,EI_flap,EI_edge\n0,1,1e305,1\n1,1,1,1\n",
                         SIZE_MAX, 20, 12, &d), &d,
                 "st.csv:2: EI_flap: 1e+305 N m^2 makes the assumed EA = 1e4 x EI / length^2 "
                 "overflow (length 20 m): give EA");
    json_decref(doc), doc = NULL;
    expect_error("4: CSV EI_edge 1e308, GJ assumed",
                 csv_opt(&doc, "s,mass_per_length,EI_flap,EI_edge,EA\n0,1,1,1,1\n1,1,1,1e308,1\n",
                         SIZE_MAX, 20, 12, &d), &d,
                 "st.csv:3: EI_edge: 1e+308 N m^2 makes the assumed GJ = 10 x EI overflow "
                 "(length 20 m): give GJ");
    json_decref(doc), doc = NULL;
    expect_error("4: ?tip_radius=DBL_MAX", csv_opt(&doc, ok, SIZE_MAX, big, 12, &d), &d,
                 "st.csv: tip_radius: out of range: 1.7976931348623157e+308 is beyond the largest "
                 "number a request carries (1.79769313486231e+308 in magnitude)");
    json_decref(doc), doc = NULL;
    expect_error("4: ?rpm=DBL_MAX", csv_opt(&doc, ok, SIZE_MAX, 20, big, &d), &d,
                 "st.csv: rpm: out of range: 1.7976931348623157e+308 is beyond the largest number "
                 "a request carries (1.79769313486231e+308 in magnitude)");
    json_decref(doc), doc = NULL;
    expect_error("4: BModes ?rpm=DBL_MAX", bmodes_rpm(&doc, bmi, sec, big, &d), &d,
                 "T.bmi: rpm: out of range: 1.7976931348623157e+308 is beyond the largest number "
                 "a request carries (1.79769313486231e+308 in magnitude)");
    json_decref(doc), doc = NULL;
    {
        char *a = edit(bmi, 7, "60.0", "1e200"), *b = edit(a, 8, "1.0 ", "1e200 ");
        bad_bmodes_main("4: rot_rpm 1e200 x rpm_mult 1e200", b,
                        "T.bmi:8: rpm_mult: rot_rpm x rpm_mult = 1e+200 x 1e+200 overflows: "
                        "beyond the largest number a request carries (1.79769313486231e+308)");
        free(a);
    }
    bad_bmodes_main("4: radius DBL_MAX", edit(bmi, 9, "35.0", dbl_max),
                    "T.bmi:9: radius: out of range: 1.7976931348623157e+308 is beyond the largest "
                    "number a request carries (1.79769313486231e+308 in magnitude)");
    bad_bmodes_main("4: el_loc DBL_MAX", edit(bmi, 48, "0.90", dbl_max),
                    "T.bmi:48: el_loc: out of range: 1.7976931348623157e+308 is beyond the "
                    "largest number a request carries (1.79769313486231e+308 in magnitude)");
    bad_bmodes_sec("4: axial_stff DBL_MAX", edit(sec, 8, "2611.3E+06", dbl_max),
                   "blade_sec_props.dat:8: axial_stff: out of range: 1.7976931348623157e+308 is "
                   "beyond the largest number a request carries (1.79769313486231e+308 in "
                   "magnitude)");
    /* bmodes_mesh samples the properties at element midpoints: a flap inertia / mass past the
     * largest double there, or offsets of opposite signs near it (their difference overflows) */
    {
        import_file f = {"T.bmi", bmi, strlen(bmi)};
        import_options o;
        char *s1 = edit(sec, 9, " 183.905   47.842 ", " 0.5 1e308 ");
        char *a = edit(sec, 9, "-0.014", "1.7e308"), *s2 = edit(a, 10, "-0.023", "-1.7e308");
        import_default_options(&o);
        o.bmodes_mesh = 2;
        expect_error("4: bmodes_mesh, flp_iner / mass_den overflows at a midpoint",
                     import_bmodes(&doc, &f, load_sec, s1, &o, &d), &d,
                     "T.bmi: bmodes_mesh: element e2 (el_loc 0.08 to 0.16): a property sampled "
                     "at its midpoint is beyond the largest number a request carries "
                     "(1.79769313486231e+308)");
        json_decref(doc), doc = NULL;
        if (import_bmodes(&doc, &f, load_sec, s2, &o, &d) != SM_OK)
            fail("4: bmodes_mesh, sc_offst +-1.7e308 around a midpoint: %s", d.text);
        json_decref(doc), doc = NULL;
        free(s1), free(a), free(s2);
    }
    expect_error("4: ElastoDyn tip_radius DBL_MAX", elastodyn(&doc, ed, big, 1.5, &d), &d,
                 "blade.dat: tip_radius: out of range: 1.7976931348623157e+308 is beyond the "
                 "largest number a request carries (1.79769313486231e+308 in magnitude)");
    json_decref(doc), doc = NULL;
    free(bmi), free(sec), free(ed);
}

/* Issue 23 item 5: el_loc (BModes' element boundaries) in [0, 1], from 0 to 1, increasing. */
static void test_el_loc_checked(void)
{
    char *bmi = slurp("bmodes_certtest/Test01_nonunif_blade.bmi");

    bad_bmodes_main("5: el_loc unsorted", edit(bmi, 48, "0.08  0.16", "0.16  0.08"),
                    "T.bmi:48: el_loc: boundaries out of order: 0.08 after 0.16 (must increase)");
    bad_bmodes_main("5: el_loc repeated", edit(bmi, 48, "0.08  0.16", "0.16  0.16"),
                    "T.bmi:48: el_loc: boundaries out of order: 0.16 after 0.16 (must increase)");
    bad_bmodes_main("5: el_loc negative", edit(bmi, 48, "0.08", "-0.08"),
                    "T.bmi:48: el_loc: boundary 2 of 13 is -0.08: must be in [0, 1] (a fraction "
                    "of the blade length from the root)");
    bad_bmodes_main("5: el_loc above 1", edit(bmi, 48, "0.90   1.0", "1.20   1.0"),
                    "T.bmi:48: el_loc: boundary 12 of 13 is 1.2: must be in [0, 1] (a fraction "
                    "of the blade length from the root)");
    bad_bmodes_main("5: el_loc first not 0", edit(bmi, 48, "0.  0.08", "0.01  0.08"),
                    "T.bmi:48: el_loc: the first boundary must be at the root, 0 (got 0.01)");
    bad_bmodes_main("5: el_loc last not 1", edit(bmi, 48, "0.90   1.0", "0.90   0.95"),
                    "T.bmi:48: el_loc: the last boundary must be at the tip, 1 (got 0.95)");
    /* over two lines: the line of the value that is wrong */
    bad_bmodes_main("5: el_loc on the next line", edit(bmi, 48, "0.48  0.56", "0.48\n0.46"),
                    "T.bmi:49: el_loc: boundaries out of order: 0.46 after 0.48 (must increase)");
    free(bmi);
}

/*
 * Issue 23 item 6: CSV with a UTF-8 byte-order mark (Excel "CSV UTF-8") imports as without;
 * UTF-16 is refused saying so; the r form's radii near 1e308 (an assumed EA of 0) and a blade
 * of 2.2e-16 m are refused with the line.
 */
static void test_csv_encoding_and_radii(void)
{
    static const char plain[] = "s,mass_per_length,EI_flap,EI_edge\n0,1,1,1\n1,1,1,1\n";
    char bom[sizeof(plain) + 3], u16[2 * sizeof(plain) + 2];
    char *a = NULL, *b = NULL;
    json_t *doc = NULL, *ref = NULL;
    import_diag d;
    size_t i, n;

    memcpy(bom, "\xEF\xBB\xBF", 3);
    memcpy(bom + 3, plain, sizeof(plain));
    if (csv_opt(&ref, plain, strlen(plain), 20, 12, &d) != SM_OK ||
        csv_opt(&doc, bom, strlen(bom), 20, 12, &d) != SM_OK)
        fail("6: CSV with a UTF-8 BOM: %s", d.text);
    else if (!(a = import_dumps(doc, 0)) || !(b = import_dumps(ref, 0)) || strcmp(a, b))
        fail("6: CSV with a UTF-8 BOM: not the document without it");
    free(a), free(b);
    json_decref(doc), json_decref(ref), doc = NULL;
    /* UTF-16 LE with its BOM, then without (NUL bytes) */
    u16[0] = (char)0xFF, u16[1] = (char)0xFE;
    for (i = 0, n = strlen(plain); i < n; i++)
        u16[2 + 2 * i] = plain[i], u16[3 + 2 * i] = '\0';
    expect_error("6: UTF-16 LE", csv_opt(&doc, u16, 2 + 2 * n, 20, 12, &d), &d,
                 "st.csv:1: encoding: the file is UTF-16 (byte-order mark FF FE): save it as "
                 "UTF-8 (Excel: \"CSV UTF-8\"; Notepad: Save as, Encoding UTF-8)");
    json_decref(doc), doc = NULL;
    u16[0] = (char)0xFE, u16[1] = (char)0xFF;
    expect_error("6: UTF-16 BE", csv_opt(&doc, u16, 2 + 2 * n, 20, 12, &d), &d,
                 "st.csv:1: encoding: the file is UTF-16 (byte-order mark FE FF): save it as "
                 "UTF-8 (Excel: \"CSV UTF-8\"; Notepad: Save as, Encoding UTF-8)");
    json_decref(doc), doc = NULL;
    expect_error("6: UTF-16 without a BOM", csv_opt(&doc, u16 + 2, 2 * n, 20, 12, &d), &d,
                 "st.csv:1: encoding: the file holds NUL bytes: it is UTF-16 or binary, not "
                 "text; save it as UTF-8 (Excel: \"CSV UTF-8\")");
    json_decref(doc), doc = NULL;
    expect_error("6: r near 1e308 (EA 0)",
                 csv_opt(&doc, "r,mass_per_length,EI_flap,EI_edge\n1e308,1,1,1\n1.7e308,1,1,1\n",
                         SIZE_MAX, NAN, 12, &d), &d,
                 "st.csv:3: r: the blade length 7e+307 m makes the assumed EA = 1e4 x EI / "
                 "length^2 underflow to 0 (largest EI 1 N m^2): give EA");
    json_decref(doc), doc = NULL;
    expect_error("6: r 1 to 1+2e-16",
                 csv_opt(&doc, "r,mass_per_length,EI_flap,EI_edge,EA,GJ\n1,1,1,1,1,1\n"
                         "1.0000000000000002,1,1,1,1,1\n", SIZE_MAX, NAN, 12, &d), &d,
                 "st.csv:3: r: the blade length 2.22044604925031e-16 m (tip radius "
                 "1.0000000000000002 m less hub radius 1 m) is below the shortest the numerics "
                 "carry: at least 1e-06 m and 1e-06 x the tip radius");
    json_decref(doc), doc = NULL;
    expect_error("6: r 1e6 to 1e6+0.5 (below 1e-6 x the tip radius)",
                 csv_opt(&doc, "r,mass_per_length,EI_flap,EI_edge\n1e6,1,1,1\n1000000.5,1,1,1\n",
                         SIZE_MAX, NAN, 12, &d), &d,
                 "st.csv:3: r: the blade length 0.5 m (tip radius 1000000.5 m less hub radius "
                 "1000000 m) is below the shortest the numerics carry: at least 1e-06 m and 1e-06 "
                 "x the tip radius");
    json_decref(doc), doc = NULL;
    expect_error("6: tip_radius 1e-7 (below 1e-6 m)", csv_opt(&doc, plain, SIZE_MAX, 1e-7, 12, &d),
                 &d, "st.csv: tip_radius: the blade length 1e-07 m (tip radius "
                 "9.9999999999999995e-08 m less hub radius 0 m) is below the shortest the numerics "
                 "carry: at least 1e-06 m and 1e-06 x the tip radius");
    json_decref(doc), doc = NULL;
    /* an excerpt of file text is short and escaped */
    expect_error("6: excerpt", csv_opt(&doc, "s,mass_per_length,EI_flap,EI_edge\n"
                                       "0,1,\x1b[31m\"red\"\\0123456789012345678901234567890,1\n",
                                       SIZE_MAX, 20, 12, &d), &d,
                 "st.csv:2: EI_flap: not a number (\"\\x1b[31m\\\"red\\\"\\\\01234567890123456789"
                 "012...\")"); /* 40 characters, escapes counted */
    json_decref(doc);
}

/*
 * Every 7th/11th prefix of a good file: an error or a document, never a
 * crash (the ASan build runs this too) nor a document with an error status.
 */
static void test_prefixes(void)
{
    char *sec = slurp("bmodes_certtest/blade_sec_props.dat");
    char *bmi = slurp("bmodes_certtest/Test02_blade_with_tip_mass.bmi");
    char *ed = slurp("elastodyn/NRELOffshrBsline5MW_Blade.dat");
    size_t n, bad = 0;

    for (n = 0; n < strlen(bmi); n += 7) {
        import_file f = {"p.bmi", bmi, n};
        import_options o;
        import_diag d;
        json_t *doc = NULL;
        import_default_options(&o);
        if ((import_bmodes(&doc, &f, load_sec, sec, &o, &d) == SM_OK) != (doc != NULL))
            bad++;
        json_decref(doc);
    }
    for (n = 0; n < strlen(ed); n += 11) {
        json_t *doc = NULL;
        import_diag d;
        char *p = strndup(ed, n);
        if ((elastodyn(&doc, p, 63, 1.5, &d) == SM_OK) != (doc != NULL))
            bad++;
        json_decref(doc);
        free(p);
    }
    if (bad)
        fail("prefixes: %zu imports returned a document and a status that disagree", bad);
    free(sec), free(bmi), free(ed);
}

/* ------------------------------------------------- the table of formats */

/* The document of one import as text ("" when refused: then the diagnostic). */
static char *table_dump(int st, json_t *doc, const import_diag *d)
{
    char *t = st == SM_OK ? import_dumps(doc, 0) : strdup(d->text);

    json_decref(doc);
    return t;
}

/*
 * import_formats[] is what the CLI and the HTTP route use: every entry is found by its name
 * (and only by it), the lists in their messages come from it, and an entry's parser gives
 * the same document as the importer called directly.
 */
static void test_formats_table(void)
{
    static const char *const names[] = {"bmodes", "elastodyn", "csv"};
    char *bmi = slurp("bmodes_certtest/Test01_nonunif_blade.bmi");
    char *sec = slurp("bmodes_certtest/blade_sec_props.dat");
    char *ed = slurp("elastodyn/NRELOffshrBsline5MW_Blade.dat");
    const char *texts[] = {bmi, ed, csv_good};
    char list[64];
    size_t k, n = 0;

    while (import_formats[n].name)
        n++;
    if (n != 3)
        fail("table: %zu formats, 3 expected", n);
    for (k = 0; k < n && k < 3; k++) {
        const import_format *f = &import_formats[k];
        import_file file = {f->main_name, texts[k], strlen(texts[k])};
        import_options o;
        import_diag d1, d2;
        json_t *doc = NULL;
        char *a, *b;
        int st;
        if (strcmp(f->name, names[k]) || import_format_find(names[k]) != f ||
            !import_format_known(names[k]) || !f->label || !f->main_name || !f->synopsis ||
            !f->parse)
            fail("table: entry %zu (%s) not found by its name or incomplete", k, names[k]);
        import_default_options(&o);
        o.tip_radius = 20;
        st = f->parse(&doc, &file, load_sec, sec, &o, &d1);
        a = table_dump(st, doc, &d1);
        doc = NULL;
        st = k == 0   ? import_bmodes(&doc, &file, load_sec, sec, &o, &d2)
             : k == 1 ? import_elastodyn(&doc, &file, &o, &d2)
                      : import_csv(&doc, &file, &o, &d2);
        b = table_dump(st, doc, &d2);
        if (!a || !b || strcmp(a, b) || !strncmp(a, f->main_name, strlen(f->main_name)))
            fail("table: %s's parser differs from the importer or refuses (%.200s)", f->name,
                 a ? a : "out of memory");
        free(a), free(b);
    }
    if (import_format_find("xml") || import_format_find("BMODES") || import_format_find("") ||
        import_format_find(NULL) || import_format_known("xml"))
        fail("table: an unknown format is found");
    if (strcmp(import_format_list(list, sizeof(list), 0), "bmodes, elastodyn or csv") ||
        strcmp(import_format_list(list, sizeof(list), IMPORT_OWN_MESH), "bmodes") ||
        strcmp(import_format_list(list, sizeof(list), IMPORT_SEC_FILE), "bmodes") ||
        strcmp(import_format_list(list, 8, 0), "bmodes,"))
        fail("table: import_format_list gives \"%s\"", list);
    free(bmi), free(sec), free(ed);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: import_test REFERENCE_BLADES_DIR\n");
        return 2;
    }
    ref_dir = argv[1];
    test_bmodes_good();
    test_bmodes_bad();
    test_elastodyn();
    test_csv();
    test_overflow_is_invalid();
    test_el_loc_checked();
    test_csv_encoding_and_radii();
    test_prefixes();
    test_formats_table();
    if (failures) {
        printf("%d failures\n", failures);
        return 1;
    }
    printf("import: all checks passed\n");
    return 0;
}
