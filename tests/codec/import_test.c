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
    bad_bmodes_main("tower", edit(bmi, 6, "1 ", "2 "),
                    "T.bmi:6: beam_type: towers are not supported yet (beam_type 2); only "
                    "blades (1)");
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
    /* towers: the real Test03 */
    {
        char *t3 = slurp("bmodes_certtest/Test03_tower.bmi");
        char *ts = slurp("bmodes_certtest/tower_sec_props.dat");
        expect_error("Test03", bmodes(&doc, "Test03_tower.bmi", t3, ts, &d), &d,
                     "Test03_tower.bmi:6: beam_type: towers are not supported yet (beam_type "
                     "2); only blades (1)");
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
    test_prefixes();
    if (failures) {
        printf("%d failures\n", failures);
        return 1;
    }
    printf("import: all checks passed\n");
    return 0;
}
