/*
 * import_bmodes.c — BModes v3 input (NREL): the .bmi main file and the
 * section-properties file it names, into the blade form (spec 12 section 6) or, for a tower
 * (beam_type 2, tow_support 0), the tower form (DESIGN.md 8.5).
 *
 * The .bmi is read by position, line after line, in the order of BModes.f90
 * (its main program: ReadCom skips a line, ReadVar takes the first token of
 * the next line with a value); the names in diagnostics are BModes' own
 * (rot_rpm, hub_rad, ...), whatever the comment on the line says (Test02
 * writes "romg").  The section file: a title, n_secs, a blank line, column
 * titles and units, then n_secs rows of 13 numbers.
 *
 * Mapping: radius - hub_rad -> length, hub_rad -> hub_radius, precone ->
 * precone_deg, bl_thp -> pitch_deg, rot_rpm x rpm_mult -> analysis.rpm,
 * modepr -> analysis.modes (capped), tip mass: cm_loc -> offset [0, cm_loc,
 * 0], izz/iyy/ixx_tip -> inertia [I11 torsion, I22 flap, I33 lag],
 * iyz/ixy/izx_tip -> products [I12, I23, I31] (x = lag axis 3, y = flap
 * axis 2, z = span axis 1); every station property times its multiplier.
 * nselt and el_loc are kept in "source" only: the blade gets
 * IMPORT_ELEMENTS equal elements.  hub_conn other than 1 is refused (a tower's 2 goes with its
 * platform).
 *
 * Towers (bm_tower, bm_tower_doc): radius -> height, hub_rad -> base_height,
 * the sections as BModes reads a tower's (symmetric: edge = flap, twists and
 * offsets 0), the top mass in tower axes (fa, ss, up) = BModes' tower-top
 * (x, y, z): offset [cm_loc, 0, cm_axial], inertia [ixx, iyy, izz],
 * products [ixy, iyz, izx]; speed 0.  tow_support 1: guy wires; 2 with hub_conn 2 or 3: a
 * platform or monopile (the tower form's "wires" and "platform", DESIGN.md 8.6): those lines and
 * their request parts are import_bmodes_support.c's (import_bmodes.h).
 */
#include "import_bmodes.h"
#include "codec.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


static void bm_init(bm_in *b, const import_file *f, import_diag *d)
{
    imp_reader_init(&b->r, f);
    b->file = f->name;
    b->d = d;
}

int bm_ends(bm_in *b, const char *field)
{
    return imp_fail(b->d, b->file, b->r.line + 1, field,
                    "the file ends here (truncated?): this line is missing");
}

/* ReadCom: skip one line, whatever it holds. */
int bm_com(bm_in *b, const char *what)
{
    return imp_next(&b->r) ? SM_OK : bm_ends(b, what);
}

/* ReadVar: the first token of the next line that is not blank. */
int bm_tok(bm_in *b, const char *field, imp_tok *t)
{
    if (!imp_next_nonblank(&b->r))
        return bm_ends(b, field);
    t->s = b->r.s;
    t->n = 0; /* a line of separators only: "missing value" */
    imp_split(b->r.s, b->r.n, ",", t, 1);
    return SM_OK;
}

int bm_num(bm_in *b, const char *field, int kind, double *v)
{
    imp_tok t;
    int st = bm_tok(b, field, &t);

    return st ? st : imp_value(b->d, b->file, b->r.line, field, &t, kind, v);
}

int bm_int(bm_in *b, const char *field, long lo, long hi, long *v)
{
    double x;
    int st = bm_num(b, field, IMP_ANY, &x);

    if (st)
        return st;
    if (x != floor(x) || x < (double)lo || x > (double)hi)
        return imp_fail(b->d, b->file, b->r.line, field, "must be an integer in [%ld, %ld] (%.15g)",
                        lo, hi, x);
    *v = (long)x;
    return SM_OK;
}


static const char *const bm_mult_names[10] = {
    "sec_mass_mult", "flp_iner_mult", "lag_iner_mult", "flp_stff_mult", "edge_stff_mult",
    "tor_stff_mult", "axial_stff_mult", "cg_offst_mult", "sc_offst_mult", "tc_offst_mult"};
static const int bm_mult_kinds[10] = {IMP_POSITIVE, IMP_NONNEG,   IMP_NONNEG,   IMP_POSITIVE,
                                      IMP_POSITIVE, IMP_POSITIVE, IMP_POSITIVE, IMP_ANY,
                                      IMP_ANY,      IMP_ANY};

/* The general parameters (lines 1-16 of a .bmi). */
static int bm_general(bm_in *b, bm_main *m)
{
    imp_tok t;
    size_t i = 0;
    int st;

    if ((st = bm_com(b, "header")) || (st = bm_com(b, "title")))
        return st;
    while (i < b->r.n && (b->r.s[i] == ' ' || b->r.s[i] == '\t'))
        i++;
    t.s = b->r.s + i;
    t.n = b->r.n - i;
    imp_tok_copy(m->title, sizeof(m->title), &t);
    if ((st = bm_com(b, "blank line")) || (st = bm_com(b, "general parameters")) ||
        (st = bm_tok(b, "Echo", &t)) || (st = bm_int(b, "beam_type", 1, 9, &m->beam_type)))
        return st;
    m->tower = m->beam_type == 2;
    m->beam_line = b->r.line;
    if (m->beam_type != 1 && m->beam_type != 2)
        return imp_fail(b->d, b->file, b->r.line, "beam_type",
                        "must be 1 (blade) or 2 (tower) (%ld)", m->beam_type);
    if ((st = bm_num(b, "rot_rpm", IMP_NONNEG, &m->rot_rpm)))
        return st;
    m->speed_line = b->r.line;
    if ((st = bm_num(b, "rpm_mult", IMP_NONNEG, &m->rpm_mult)))
        return st;
    m->rpm = m->rot_rpm * m->rpm_mult; /* BModes.f90: romg = rot_rpm * rpm_mult */
    if (!imp_finite(m->rpm))
        return imp_fail(b->d, b->file, b->r.line, "rpm_mult", "rot_rpm x rpm_mult = %.15g x "
                        "%.15g overflows: beyond the largest number a request carries (%s)",
                        m->rot_rpm, m->rpm_mult, IMP_MAX_ABS_TEXT);
    if ((st = bm_num(b, "radius", IMP_POSITIVE, &m->radius)) ||
        (st = bm_num(b, "hub_rad", IMP_NONNEG, &m->hub_rad)))
        return st;
    if (!(m->hub_rad < m->radius))
        return imp_fail(b->d, b->file, b->r.line, "hub_rad",
                        "must be less than radius %.15g (%.15g)", m->radius, m->hub_rad);
    m->length_line = b->r.line;
    if ((st = imp_length(b->d, b->file, b->r.line, "hub_rad", m->hub_rad,
                         m->radius - m->hub_rad)))
        return st;
    if ((st = bm_num(b, "precone", IMP_ANY, &m->precone)) ||
        (st = bm_num(b, "bl_thp", IMP_ANY, &m->bl_thp)) ||
        (st = bm_int(b, "hub_conn", 1, 3, &m->hub_conn)))
        return st;
    m->hub_conn_line = b->r.line;
    if (m->hub_conn != 1 && !m->tower) /* a tower's free root goes with its platform */
        return imp_fail(b->d, b->file, b->r.line, "hub_conn",
                        "only 1 (cantilevered) is supported (%ld)", m->hub_conn);
    if ((st = bm_int(b, "modepr", 1, 100000, &m->modepr)) ||
        (st = bm_tok(b, "TabDelim", &t)) || (st = bm_tok(b, "mid_node_tw", &t)))
        return st;
    return SM_OK;
}

/* Tip mass, distributed-property identifiers and multipliers. */
static int bm_props(bm_in *b, bm_main *m)
{
    static const char *const tip_names[9] = {"tip_mass", "cm_loc",  "cm_axial",
                                              "ixx_tip",  "iyy_tip", "izz_tip",
                                              "ixy_tip",  "izx_tip", "iyz_tip"};
    static const int tip_kinds[9] = {IMP_NONNEG, IMP_ANY,    IMP_ANY, IMP_NONNEG, IMP_NONNEG,
                                     IMP_NONNEG, IMP_ANY,    IMP_ANY, IMP_ANY};
    imp_tok t;
    long id_mat;
    int i, st;

    if ((st = bm_com(b, "blank line")) || (st = bm_com(b, "tip mass properties")))
        return st;
    for (i = 0; i < 9; i++)
        if ((st = bm_num(b, tip_names[i], tip_kinds[i], &m->tip[i])))
            return st;
    if ((st = bm_com(b, "blank line")) || (st = bm_com(b, "distributed-property identifiers")) ||
        (st = bm_int(b, "id_mat", 1, 9, &id_mat)))
        return st;
    if (id_mat != 1)
        return imp_fail(b->d, b->file, b->r.line, "id_mat",
                        "must be 1 (isotropic; BModes has no other) (%ld)", id_mat);
    if ((st = bm_tok(b, "sec_props_file", &t)))
        return st;
    if (t.n == 0 || t.n >= sizeof(m->sec_file))
        return imp_fail(b->d, b->file, b->r.line, "sec_props_file",
                        "expected a file name of 1 to %zu characters", sizeof(m->sec_file) - 1);
    imp_tok_copy(m->sec_file, sizeof(m->sec_file), &t);
    m->sec_line = b->r.line;
    memcpy(m->sec_raw, t.s, t.n);
    m->sec_raw[t.n] = '\0';
    if ((st = bm_com(b, "blank line")) || (st = bm_com(b, "property scaling factors")))
        return st;
    for (i = 0; i < 10; i++)
        if ((st = bm_num(b, bm_mult_names[i], bm_mult_kinds[i], &m->mult[i])))
            return st;
    return SM_OK;
}

/*
 * Element boundary k of n (el_loc, rounded as printed): fractions of the blade length from the
 * root, the first exactly 0, the last exactly 1, increasing (BModes' elements run root to tip
 * and bmodes_mesh makes them members: a boundary out of order folds the blade back on itself).
 */
static int bm_el_loc(bm_in *b, long k, long n, double x, double *prev)
{
    if (x < 0.0 || x > 1.0)
        return imp_fail(b->d, b->file, b->r.line, "el_loc", "boundary %ld of %ld is %.15g: "
                        "must be in [0, 1] (a fraction of the blade length from the root)",
                        k + 1, n, x);
    if (k == 0 && x != 0.0)
        return imp_fail(b->d, b->file, b->r.line, "el_loc", "the first boundary must be at "
                        "the root, 0 (got %.15g)", x);
    if (k > 0 && !(x > *prev))
        return imp_fail(b->d, b->file, b->r.line, "el_loc", "boundaries out of order: %.15g "
                        "after %.15g (must increase)", x, *prev);
    if (k == n - 1 && x != 1.0)
        return imp_fail(b->d, b->file, b->r.line, "el_loc", "the last boundary must be at the "
                        "tip, 1 (got %.15g)", x);
    *prev = x;
    return SM_OK;
}

/* nselt and el_loc (nselt + 1 numbers, over as many lines as they take). */
static int bm_mesh(bm_in *b, bm_main *m, json_t *el_loc)
{
    imp_tok t[IMP_MAX_TOKENS];
    double prev = 0.0;
    long got = 0;
    int st, i, n;

    if ((st = bm_com(b, "blank line")) || (st = bm_com(b, "finite element discretization")) ||
        (st = bm_int(b, "nselt", 1, BM_MAX_ELEMENTS, &m->nselt)) ||
        (st = bm_com(b, "el_loc comment")))
        return st;
    while (got < m->nselt + 1) {
        if (!imp_next_nonblank(&b->r))
            return bm_ends(b, "el_loc");
        n = imp_split(b->r.s, b->r.n, ",", t, IMP_MAX_TOKENS);
        if (n > IMP_MAX_TOKENS)
            n = IMP_MAX_TOKENS;
        for (i = 0; i < n && got < m->nselt + 1; i++, got++) {
            double v;
            if ((st = imp_value(b->d, b->file, b->r.line, "el_loc", &t[i], IMP_ANY, &v)) ||
                (st = bm_el_loc(b, got, m->nselt + 1, imp_round(v), &prev)))
                return st;
            if (json_array_append_new(el_loc, json_real(imp_round(v))))
                return SM_NOMEM;
        }
    }
    return SM_OK;
}

/*
 * A tower's row as BModes reads it (BModes.f90:667-677): twists and offsets zero, the s-s
 * (edge) inertia and stiffness the f-a (flap) ones, before the multipliers (so edge_stff_mult
 * and lag_iner_mult still apply).  m->tw_zeroed records the columns this changed.
 */
static void bm_tower_row(bm_main *m, double raw[BM_COLUMNS], int line)
{
    static const int zero[] = {1, 2, 10, 11, 12}; /* str_tw, tw_iner, cg, sc, tc_offst */
    unsigned before = m->tw_zeroed;
    size_t k;

    for (k = 0; k < sizeof(zero) / sizeof(zero[0]); k++) {
        if (raw[zero[k]] != 0.0)
            m->tw_zeroed |= 1u << zero[k];
        raw[zero[k]] = 0.0;
    }
    if (raw[5] != raw[4]) /* edge_iner := flp_iner */
        m->tw_zeroed |= 1u << 5;
    if (raw[7] != raw[6]) /* edge_stff := flp_stff */
        m->tw_zeroed |= 1u << 7;
    raw[5] = raw[4];
    raw[7] = raw[6];
    if (!before && m->tw_zeroed)
        m->tw_zeroed_line = line;
}

/* The section-properties file into t, multipliers applied. */
static int bm_sections(bm_in *b, bm_main *m, imp_table *t)
{
    static const char *const col[BM_COLUMNS] = {
        "sec_loc",   "str_tw",    "tw_iner",  "mass_den", "flp_iner", "edge_iner", "flp_stff",
        "edge_stff", "tor_stff",  "axial_stff", "cg_offst", "sc_offst", "tc_offst"};
    static const imp_key key[BM_COLUMNS] = {IK_S,       IK_TWIST,   IK_ITWIST, IK_MU,
                                            IK_I_FLAP,  IK_I_EDGE,  IK_EI_FLAP, IK_EI_EDGE,
                                            IK_GJ,      IK_EA,      IK_CG_E,   IK_SC_E,
                                            IK_TC_E};
    /* multiplier of each column: index into m->mult, -1 = none */
    static const int mult[BM_COLUMNS] = {-1, -1, -1, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    imp_tok tok[BM_COLUMNS + 1];
    double raw[BM_COLUMNS];
    long n_secs, i;
    int st, c, n;

    if ((st = bm_com(b, "header")) ||
        (st = bm_int(b, "n_secs", 2, IMPORT_MAX_STATIONS, &n_secs)) ||
        (st = bm_com(b, "blank line")) || (st = bm_com(b, "column titles")) ||
        (st = bm_com(b, "column units")))
        return st;
    for (i = 0; i < n_secs; i++) {
        imp_station *s;
        if (!imp_next_nonblank(&b->r))
            return imp_fail(b->d, b->file, b->r.line + 1, "sec_loc",
                            "the file ends before station %ld of %ld (truncated?)", i + 1,
                            n_secs);
        n = imp_split(b->r.s, b->r.n, ",", tok, BM_COLUMNS + 1);
        if (n < BM_COLUMNS)
            return imp_fail(b->d, b->file, b->r.line, col[n],
                            "missing: the row has %d columns, expected %d", n, BM_COLUMNS);
        if (n > BM_COLUMNS)
            return imp_fail(b->d, b->file, b->r.line, "row",
                            "%d columns, expected %d (sec_loc ... tc_offst)", n, BM_COLUMNS);
        if (!(s = imp_table_add(t)))
            return SM_NOMEM;
        s->line = b->r.line;
        for (c = 0; c < BM_COLUMNS; c++)
            if ((st = imp_value(b->d, b->file, b->r.line, col[c], &tok[c], imp_key_kind(key[c]),
                                &raw[c])))
                return st;
        if (m->tower)
            bm_tower_row(m, raw, b->r.line);
        for (c = 0; c < BM_COLUMNS; c++) {
            int kind = imp_key_kind(key[c]);
            double v = raw[c];
            if (mult[c] >= 0)
                v *= m->mult[mult[c]];
            if ((st = imp_check(b->d, b->file, b->r.line, col[c], kind, v)))
                return st;
            s->v[key[c]] = v;
        }
        /* BModes' mass moments are about the reference axis (its torsional inertia is
         * flp_iner + edge_iner with no mass cg^2 term, Struct.f90:1302); spinmodal's are about
         * the centre of mass, which the chordwise cg offset moves off the axis: edge - mass cg^2
         * (DESIGN.md 8). BModes itself needs it positive (its section mass matrix). */
        double cg = s->v[IK_CG_E], ie = s->v[IK_I_EDGE] - s->v[IK_MU] * cg * cg;
        if (ie < 0.0)
            return imp_fail(b->d, b->file, b->r.line, "edge_iner",
                            "%g kg m is below mass_den x cg_offst^2 = %g kg m: the section's mass "
                            "moment about its reference axis cannot be smaller than that of its mass "
                            "at the centre of mass", s->v[IK_I_EDGE], s->v[IK_MU] * cg * cg);
        s->v[IK_I_EDGE] = imp_round(ie);
    }
    for (c = 0; c < BM_COLUMNS; c++)
        t->mask |= 1u << key[c];
    t->mask |= (1u << IK_CG_F) | (1u << IK_SC_F) | (1u << IK_TC_F); /* flap parts 0 */
    return imp_table_order(b->d, b->file, t, "sec_loc");
}

/* The blade (everything but the stations) and the warnings of the .bmi. */
static int bm_blade(const bm_main *m, const import_options *o, imp_blade *bl, json_t *warn)
{
    int bad = 0;

    bl->length = m->radius - m->hub_rad;
    bl->hub_radius = m->hub_rad;
    bl->precone_deg = m->precone;
    bl->pitch_deg = m->bl_thp;
    bl->rpm = m->rpm;
    bl->length_line = m->length_line;
    bl->length_field = "hub_rad";
    if (!isnan(o->rpm)) {
        const json_t *to = json_object_get(o->rpm_speeds, "to");
        if (o->rpm_speeds)
            bad |= imp_warn(warn, "/analysis/rpm", "rotor speeds %g %s %g rpm given (%s): the "
                            "file's %g rpm (rot_rpm x rpm_mult) is not used", o->rpm,
                            to ? "to" : "...", to ? json_number_value(to) : json_number_value(
                            json_array_get(o->rpm_speeds, json_array_size(o->rpm_speeds) - 1)),
                            to ? "a range" : "a list", bl->rpm);
        else
            bad |= imp_warn(warn, "/analysis/rpm", "rotor speed %g rpm given: the file's %g "
                            "rpm (rot_rpm x rpm_mult) is not used", o->rpm, bl->rpm);
        bl->rpm = o->rpm;
        bl->rpm_speeds = o->rpm_speeds;
    }
    bl->modes = (int)m->modepr;
    if (o->max_modes > 0 && bl->modes > o->max_modes) {
        bad |= imp_warn(warn, "/analysis/modes", "modepr %d is above the limit of %d modes: analysis.modes = %d",
                        bl->modes, o->max_modes, o->max_modes);
        bl->modes = o->max_modes;
    }
    bl->has_tip = m->tip[0] != 0.0 || m->tip[1] != 0.0 || m->tip[3] != 0.0 ||
                  m->tip[4] != 0.0 || m->tip[5] != 0.0 || m->tip[6] != 0.0 ||
                  m->tip[7] != 0.0 || m->tip[8] != 0.0;
    bl->tip_mass = m->tip[0];
    bl->tip_offset[1] = m->tip[1];     /* cm_loc, along the edgewise axis b2 */
    bl->tip_inertia[0] = m->tip[5];    /* izz: torsion, about the span axis b1 */
    bl->tip_inertia[1] = m->tip[4];    /* iyy: flap, about b2 */
    bl->tip_inertia[2] = m->tip[3];    /* ixx: lag, about b3 */
    bl->tip_products[0] = m->tip[8];   /* iyz -> I12 */
    bl->tip_products[1] = m->tip[6];   /* ixy -> I23 */
    bl->tip_products[2] = m->tip[7];   /* izx -> I31 */
    if (m->tip[2] != 0.0)
        bad |= imp_warn(warn, bl->has_tip ? "/blade/tip_mass" : "/blade",
                        "cm_axial = %g m is ignored: BModes uses it for towers only", m->tip[2]);
    return bad ? SM_NOMEM : SM_OK;
}

/*
 * A tower (beam_type 2, DESIGN.md 8.5): the length and modes into bl (the blade document is
 * built first and turned into the tower form by bm_tower_doc), and the warnings of what BModes
 * itself overwrites for a tower.  A tower does not spin: an rpm option is refused.
 */
static int bm_tower(const bm_main *m, const import_options *o, imp_blade *bl, json_t *warn,
                    import_diag *d, const char *file)
{
    static const char *const names[] = {
        "sec_loc",   "str_tw",   "tw_iner",    "mass_den", "flp_iner", "edge_iner", "flp_stff",
        "edge_stff", "tor_stff", "axial_stff", "cg_offst", "sc_offst", "tc_offst"};
    char cols[160];
    size_t len = 0;
    int bad = 0, c;

    if (!isnan(o->rpm))
        return imp_fail(d, file, 0, "rpm",
                        "a tower does not spin: the rotor speed option "
                        "does not apply to a tower (beam_type 2)");
    bl->length = m->radius - m->hub_rad;
    bl->hub_radius = m->hub_rad;
    bl->rpm = 0.0;
    bl->modes = (int)m->modepr;
    if (o->max_modes > 0 && bl->modes > o->max_modes) {
        bad |= imp_warn(warn, "/analysis/modes",
                        "modepr %d is above the limit of %d modes: "
                        "analysis.modes = %d",
                        bl->modes, o->max_modes, o->max_modes);
        bl->modes = o->max_modes;
    }
    if (m->rpm != 0.0)
        bad |= imp_warn(warn, "/analysis/omega",
                        "%s:%d: rot_rpm x rpm_mult = %g rpm is not used: "
                        "a tower does not spin (BModes sets its speed to 0, BModes.f90:436)",
                        file, m->speed_line, m->rpm);
    if (m->precone != 0.0 || m->bl_thp != 0.0)
        bad |= imp_warn(warn, "/tower",
                        "precone %g and bl_thp %g degrees are not used: BModes "
                        "sets them to zero for a tower",
                        m->precone, m->bl_thp);
    if (m->tip[1] != m->tip[2] || m->tip[2] != 0.0)
        bad |= imp_warn(warn, "/tower/top_mass/offset",
                        "top_mass.offset = [cm_loc, 0, "
                        "cm_axial] = [%g, 0, %g] m as the file's comments define them; BModes "
                        "v3.00 itself reads cm_axial into cm_loc (BModes.f90:448-449), so its "
                        "own numbers are for the offset [%g, 0, 0] (the option bmodes_mesh "
                        "uses that, to reproduce them)",
                        m->tip[1], m->tip[2], m->tip[2]);
    for (c = 0; c < BM_COLUMNS && m->tw_zeroed; c++)
        if ((m->tw_zeroed & (1u << c)) && len < sizeof(cols))
            len +=
                (size_t)snprintf(cols + len, sizeof(cols) - len, "%s%s", len ? ", " : "", names[c]);
    if (m->tw_zeroed)
        bad |= imp_warn(warn, "/tower/stations",
                        "%s:%d: %s not used: BModes reads a tower's "
                        "sections as symmetric, with twists and offsets zero and the s-s "
                        "(edge) inertia and stiffness equal to the f-a (flap) ones "
                        "(BModes.f90:667-677), and so does the import",
                        m->sec_file, m->tw_zeroed_line, cols);
    return bad ? SM_NOMEM : SM_OK;
}

/* JSON reals of the n numbers x, rounded as printed; NULL when out of memory. */
json_t *bm_vec(const double *x, int n)
{
    json_t *a = json_array();
    int i;

    for (i = 0; a && i < n; i++)
        if (json_array_append_new(a, json_real(imp_round(x[i])))) {
            json_decref(a);
            return NULL;
        }
    return a;
}

/*
 * doc's blade request made a tower (DESIGN.md 8.5): height = radius, base_height = hub_rad
 * (BModes' rigid base), the elements, section and stations as they are; the top mass in tower
 * axes (fa, ss, up) = BModes' tower-top (x, y, z): offset [cm_loc, 0, cm_axial], inertia
 * [ixx, iyy, izz], products [ixy, iyz, izx] (the tensor's off-diagonal entries: BldVib.f90:
 * 685-709 adds them to the mass matrix as such); analysis.omega [0] instead of rpm.  0 or -1
 * (memory).
 */
static int bm_tower_doc(json_t *doc, const bm_main *m)
{
    json_t *req = json_object_get(doc, "request"), *bl = json_object_get(req, "blade");
    json_t *an = json_object_get(req, "analysis"), *tw = json_object(), *top = NULL;
    const char *const keep[] = {"elements", "section", "stations"};
    double off[3] = {m->tip[1], 0.0, m->tip[2]};
    double prod[3] = {m->tip[6], m->tip[8], m->tip[7]}; /* ixy, iyz, izx */
    int bad = !tw || !bl || !an, k, i;

    bad = bad || json_object_set_new(tw, "height", json_real(imp_round(m->radius))) ||
          json_object_set_new(tw, "base_height", json_real(imp_round(m->hub_rad)));
    for (k = 0; !bad && k < 3; k++)
        if (json_object_get(bl, keep[k]))
            bad |= json_object_set(tw, keep[k], json_object_get(bl, keep[k]));
    for (i = 0; !bad && i < 9 && !top; i++)
        if (i != 2 && m->tip[i] != 0.0) { /* a top mass given (cm_axial alone offsets nothing) */
            top = json_pack("{s:f, s:o, s:o, s:o}", "mass", imp_round(m->tip[0]), "offset",
                            bm_vec(off, 3), "inertia", bm_vec(m->tip + 3, 3), "products",
                            bm_vec(prod, 3));
            bad |= !top || json_object_set_new(tw, "top_mass", top);
        }
    if (bad) {
        json_decref(tw);
        return -1;
    }
    if (json_object_set_new(req, "tower", tw) || json_object_del(req, "blade") ||
        json_object_del(an, "rpm") || json_object_set_new(an, "omega", json_pack("[f]", 0.0)))
        return -1; /* set_new took tw */
    return 0;
}

/*
 * Option bmodes_mesh on a tower: BModes' own model takes the top mass's offset as BModes reads
 * it, [cm_axial, 0, 0] (BModes.f90:448-449 reads cm_axial into cm_loc and leaves cm_axial 0).
 * 0 or -1 (memory).
 */
static int bm_tower_own_offset(json_t *doc, const bm_main *m)
{
    json_t *top =
        json_object_get(json_object_get(json_object_get(doc, "request"), "tower"), "top_mass");
    double off[3] = {m->tip[2], 0.0, 0.0};

    if (!top || (m->tip[1] == m->tip[2] && m->tip[2] == 0.0))
        return 0;
    if (json_object_set_new(top, "offset", bm_vec(off, 3)))
        return -1;
    return imp_warn(json_object_get(doc, "input_warnings"), "/tower/top_mass/offset",
                    "BModes' own model: top_mass.offset = [%g, 0, 0] m, the offset BModes v3.00 "
                    "computes with (it reads cm_axial = %g into cm_loc = %g)",
                    m->tip[2], m->tip[2], m->tip[1]);
}

/*
 * A tower's station model (no bmodes_mesh): the sections' mass moments in torsion only
 * (analysis.rotary_inertia "torsion"), as BModes has them (no bending rotary inertia,
 * Struct.f90:1222-1223 vs 1302), like bm_own_mesh's; with bending rotary inertia Test04's 3rd
 * fore-aft/side-side and 4th fore-aft were 1.5 % below BModes refined (DESIGN.md 8.5).
 * 0 or -1 (memory).
 */
static int bm_tower_rotary(json_t *doc)
{
    json_t *an = json_object_get(json_object_get(doc, "request"), "analysis");

    if (!an || json_object_set_new(an, "rotary_inertia", json_string("torsion")))
        return -1;
    return imp_warn(json_object_get(doc, "input_warnings"), "/analysis/rotary_inertia",
                    "analysis.rotary_inertia = \"torsion\": BModes has no bending rotary "
                    "inertia (the sections' mass moments enter torsion only), so the import "
                    "leaves it out to reproduce BModes; \"full\" includes it (Test04's 3rd and "
                    "4th bending modes 1.5 %% lower)");
}

/* "source": what the .bmi said that the request does not carry. */
static json_t *bm_source(const bm_main *m, const char *bmi, json_t *el_loc)
{
    json_t *src = json_object(), *mult = json_object();
    int i, bad = !src || !mult;

    for (i = 0; !bad && i < 10; i++)
        bad |= json_object_set_new(mult, bm_mult_names[i], json_real(imp_round(m->mult[i])));
    if (!bad) {
        bad |= json_object_set_new(src, "format", json_string("bmodes"));
        bad |= json_object_set_new(src, "file", imp_string(bmi));
        bad |= json_object_set_new(src, "sec_props_file", json_string(m->sec_file));
        bad |= json_object_set_new(src, "title", json_string(m->title));
        bad |= json_object_set_new(src, "rot_rpm", json_real(imp_round(m->rot_rpm)));
        bad |= json_object_set_new(src, "rpm_mult", json_real(imp_round(m->rpm_mult)));
        bad |= json_object_set_new(src, "multipliers", mult);
        mult = NULL;
        bad |= json_object_set_new(src, "nselt", json_integer(m->nselt));
        bad |= json_object_set(src, "el_loc", el_loc);
        bad |= json_object_set_new(
            src, "note",
            json_string(
                m->tower ? "BModes' element boundaries (nselt, el_loc) are not used: the tower is "
                           "meshed with tower.elements equal elements"
                         : "BModes' element boundaries (nselt, el_loc) are not used: the blade is "
                           "meshed with blade.elements equal elements"));
    }
    json_decref(mult);
    if (bad) {
        json_decref(src);
        return NULL;
    }
    return src;
}

int import_bmodes(json_t **out, const import_file *bmi, import_loader load, void *ctx,
                  const import_options *o, import_diag *d)
{
    json_t *warn = json_array(), *el_loc = json_array(), *src, *sec;
    import_file sf = {NULL, NULL, 0}, body;
    imp_table t = {NULL, 0, 0, 0};
    imp_blade bl;
    bm_main m;
    bm_in b;
    char why[160];
    int st;

    *out = NULL;
    memset(&m, 0, sizeof(m));
    imp_blade_init(&bl);
    if (!warn || !el_loc) {
        st = SM_NOMEM;
        goto done;
    }
    if ((st = imp_option(d, bmi->name, "rpm", o->rpm)) || (st = imp_encoding(d, bmi, &body)))
        goto done;
    bm_init(&b, &body, d);
    if ((st = bm_general(&b, &m)) || (st = bm_props(&b, &m)) || (st = bm_mesh(&b, &m, el_loc)) ||
        (st = bm_support(&b, &m)))
        goto done;
    why[0] = '\0';
    st = load(ctx, m.sec_raw, &sf, why, sizeof(why));
    if (st == SM_INVALID_INPUT) {
        imp_tok nt = {m.sec_raw, strlen(m.sec_raw)};
        char shown[IMP_EXCERPT_SIZE];
        imp_excerpt(shown, sizeof(shown), &nt);
        st = imp_fail(d, bmi->name, m.sec_line, "sec_props_file", "cannot read \"%s\": %s",
                      shown, why);
    }
    if (st)
        goto done;
    if (!sf.name)
        sf.name = m.sec_file;
    if ((st = imp_encoding(d, &sf, &sf)))
        goto done;
    bm_init(&b, &sf, d);
    if ((st = bm_sections(&b, &m, &t)) ||
        (st = m.tower ? bm_tower(&m, o, &bl, warn, d, bmi->name) : bm_blade(&m, o, &bl, warn)))
        goto done;
    src = bm_source(&m, bmi->name, el_loc);
    /* BModes has no tension-torsion (Wagner) term (DESIGN.md 8.2): the request switches it
     * off so that it is BModes' model, and says how to put it back */
    sec = json_pack("{s:f}", "ip_over_a", 0.0);
    if (!sec || imp_warn(warn, m.tower ? "/tower/section/ip_over_a" : "/blade/section/ip_over_a",
                         "%s.section.ip_over_a = 0: BModes has no tension-torsion "
                         "(Wagner) stiffness, so the import leaves it out to reproduce "
                         "BModes; delete ip_over_a to include it (it raises the first "
                         "torsion frequency, ~1.4 %% on BModes' Test01)",
                         m.tower ? "tower" : "blade")) {
        json_decref(sec);
        json_decref(src);
        st = SM_NOMEM;
        goto done;
    }
    *out = imp_document(&bl, &t, sec, warn, src);
    warn = NULL;
    st = *out ? SM_OK : SM_NOMEM;
    if (!st && m.tower && (bm_tower_doc(*out, &m) || bm_tower_platform(*out, &m)))
        st = SM_NOMEM;
    if (!st && m.tower && o->bmodes_mesh > 0 && bm_tower_own_offset(*out, &m))
        st = SM_NOMEM;
    if (!st && m.tower && o->bmodes_mesh <= 0 && bm_tower_rotary(*out))
        st = SM_NOMEM;
    if (!st && o->bmodes_mesh > 0) {
        st = bm_own_mesh(*out, el_loc, o->bmodes_mesh, bmi->name, d,
                         json_object_get(*out, "input_warnings"));
        if (!st && bm_mesh_warnings(*out, m.tower))
            st = SM_NOMEM;
    }
    if (!st && m.tower && bm_tower_wires(*out, &m, el_loc, o->bmodes_mesh > 0))
        st = SM_NOMEM;
    if (st && *out) {
        json_decref(*out);
        *out = NULL;
    }
done:
    json_decref(warn);
    json_decref(el_loc);
    imp_table_clear(&t);
    return st;
}
