/*
 * test_blades.c — blades along the span (DESIGN.md 8) against BModes' certification tests
 * (reference/blades/bmodes_certtest): the section file is read here the way BModes reads it,
 * every column a station quantity; the tip mass of Test02 with its offset and inertia.
 * Options that match BModes' model: Coriolis off, lumped mass with rotary inertia, stiffening
 * on, per-element frames, complete component-mode bases.
 *  1. Test01, Test02 at 60 rpm: modes 1-6 within 1 %, 7-10 within 2 % of BModes v3.00;
 *  2. what BModes cannot give: the same blades with Coriolis on (printed, and checked to move
 *     the lead-lag mode and leave the flap mode within 0.5 %);
 *  3. station means: a tapered blade given as stations and as stepped uniform members converge
 *     to one answer as both are refined.
 */
#include "testutil.h"

#define PI 3.14159265358979323846
#define NSEC_MAX 64

typedef struct blade {
    int n;
    sm_station st[NSEC_MAX];
} blade;

/* BModes section file: 21 rows of 13 numbers after 5 header lines (BModes.f90 reads it so). */
static int blade_read(const char *dir, blade *b)
{
    char path[1024], line[512];
    snprintf(path, sizeof path, "%s/blades/bmodes_certtest/blade_sec_props.dat", dir);
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    int n = 0, ln = 0;
    while (fgets(line, sizeof line, f)) {
        if (++ln == 2)
            n = atoi(line);
        if (ln < 6 || b->n >= n)
            continue;
        double v[13];
        if (sscanf(line, "%lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf", &v[0], &v[1], &v[2], &v[3], &v[4],
                   &v[5], &v[6], &v[7], &v[8], &v[9], &v[10], &v[11], &v[12]) != 13)
            continue;
        sm_station *t = &b->st[b->n++];
        memset(t, 0, sizeof *t);
        t->s = v[0];
        t->twist = v[1] * PI / 180;
        t->inertia_twist = v[2] * PI / 180;
        t->mu = v[3];
        t->i_flap = v[4];
        t->i_edge = v[5];
        t->EI_flap = v[6];
        t->EI_edge = v[7];
        t->GJ = v[8];
        t->EA = v[9];
        t->cg[0] = v[10];
        t->sc[0] = v[11];
        t->tc[0] = v[12];
        /* BModes' mass moments are about the reference axis (its torsional inertia is
         * flp_iner + edge_iner with no m cg^2 term, Struct.f90:1302); spinmodal's are about the
         * centre of mass: a chordwise cg offset takes m cg^2 from the edgewise moment */
        t->i_edge -= t->mu * t->cg[0] * t->cg[0];
    }
    fclose(f);
    return b->n == n && n >= 2 ? 0 : -1;
}

/* BModes' published frequencies (Hz) of test `name`, modes 1..n. */
static int blade_reference(const char *dir, const char *name, double *hz, int n)
{
    char path[1024], line[256];
    snprintf(path, sizeof path, "%s/blades/bmodes_certtest/certtest_frequencies.csv", dir);
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    int got = 0;
    while (fgets(line, sizeof line, f)) {
        char t[64];
        int mode;
        double v;
        if (sscanf(line, "%63[^,],%d,%lf", t, &mode, &v) == 3 && !strcmp(t, name) && mode >= 1 && mode <= n) {
            hz[mode - 1] = v;
            got++;
        }
    }
    fclose(f);
    return got == n ? 0 : -1;
}

/* Our BModes runs (bmodes_refined.csv): frequencies (Hz) of test/variant, modes 1..n. */
static int blade_refined(const char *dir, const char *name, const char *variant, double *hz, int n)
{
    char path[1024], line[256];
    snprintf(path, sizeof path, "%s/blades/bmodes_refined.csv", dir);
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    int got = 0;
    while (fgets(line, sizeof line, f)) {
        char t[64], v[64];
        int mode;
        double x;
        if (line[0] != '#' && sscanf(line, "%63[^,],%63[^,],%d,%lf", t, v, &mode, &x) == 4 && !strcmp(t, name) &&
            !strcmp(v, variant) && mode >= 1 && mode <= n) {
            hz[mode - 1] = x;
            got++;
        }
    }
    fclose(f);
    return got == n ? 0 : -1;
}

/* Print hz against ref and check modes 1-6 within tol6, 7-10 within tol10 (only the modes whose
 * bit is set in which). */
static void blade_compare(const char *what, const double *hz, const double *ref, double tol6, double tol10,
                          unsigned which)
{
    printf("%s\n", what);
    for (int i = 0; i < 10; i++) {
        double e = hz[i] / ref[i] - 1;
        printf("  mode %2d  %9.4f Hz  reference %9.4f  %+6.2f %%%s\n", i + 1, hz[i], ref[i], 100 * e,
               which & (1u << i) ? "" : "  (not checked)");
        if (which & (1u << i))
            TU_CHECK(fabs(e) <= (i < 6 ? tol6 : tol10), "mode %d within %.0f %%", i + 1, 100 * (i < 6 ? tol6 : tol10));
    }
}

typedef struct blade_case {
    double hub, len, tip_mass, tip_off, tip_I[3]; /* tip inertia: torsion, flap, lag */
    unsigned mask;
    int elements;
    int coriolis;
    int wagner;      /* 1: the tension-torsion (Wagner) term with I_p/A from the mass moments;
                        0: without it, as BModes (its files carry no such data) */
} blade_case;

/* BModes' 12 elements (el_loc of Test01/Test02) */
static const double bm_el[13] = {0, 0.08, 0.16, 0.24, 0.32, 0.40, 0.48, 0.56, 0.64, 0.72, 0.80, 0.90, 1.0};

/* The station values at s (linear; the mass moments through their ratio to the mass, as BModes
 * interpolates them, BModes.f90:1126). */
static sm_station blade_at(const blade *b, double s)
{
    int j = 0;
    while (j + 2 < b->n && s > b->st[j + 1].s)
        j++;
    const sm_station *a = &b->st[j], *c = &b->st[j + 1];
    double t = (s - a->s) / (c->s - a->s);
    sm_station r = *a;
#define LIN(f) r.f = a->f + t * (c->f - a->f)
    LIN(mu), LIN(EA), LIN(EI_flap), LIN(EI_edge), LIN(GJ), LIN(twist), LIN(inertia_twist), LIN(cg[0]), LIN(sc[0]),
        LIN(tc[0]);
#undef LIN
    /* back to BModes' moments (about the reference axis) for the ratio, then to the cg again */
    double fa = a->i_flap / a->mu, fc = c->i_flap / c->mu;
    double ea = (a->i_edge + a->mu * a->cg[0] * a->cg[0]) / a->mu, ec = (c->i_edge + c->mu * c->cg[0] * c->cg[0]) / c->mu;
    r.i_flap = r.mu * (fa + t * (fc - fa));
    r.i_edge = r.mu * (ea + t * (ec - ea)) - r.mu * r.cg[0] * r.cg[0];
    r.s = s;
    return r;
}

/* Solve the blade at omega; frequencies (Hz) of the lowest nm modes into hz.  c->elements > 0:
 * one member with the stations; < 0: BModes' 12 elements as 12 uniform members with the
 * midpoint values (BModes' own model, BModes.f90:1110), -c->elements FE elements each. */
static int blade_solve(const blade *b, const blade_case *c, double omega, int nm, double *hz)
{
    enum { NB = 12 };
    int nmem = c->elements > 0 ? 1 : NB;
    double xy[2 * (NB + 1)], z[NB + 1];
    sm_section sec[NB];
    sm_member mem[NB];
    memset(sec, 0, sizeof sec);
    memset(mem, 0, sizeof mem);
    for (int j = 0; j <= nmem; j++) {
        xy[2 * j] = c->hub + c->len * (nmem == 1 ? j : bm_el[j]), xy[2 * j + 1] = 0, z[j] = 0;
    }
    for (int i = 0; i < nmem; i++) {
        mem[i].from = i, mem[i].to = i + 1, mem[i].section = i;
        if (nmem == 1) {
            sec[0].EA = 1, sec[0].EI_flap = 1, sec[0].EI_edge = 1, sec[0].GJ = 1, sec[0].mu = 1; /* all from stations */
            mem[0].elements = c->elements;
            mem[0].n_stations = b->n;
            mem[0].stations = b->st;
            mem[0].station_mask = c->mask | (c->wagner ? 0u : SM_ST_IP_OVER_A); /* ip_over_a 0 at every station */
            continue;
        }
        sm_station t = blade_at(b, 0.5 * (bm_el[i] + bm_el[i + 1]));
        sm_section *q = &sec[i];
        q->mu = t.mu, q->EA = t.EA, q->EI_flap = t.EI_flap, q->EI_edge = t.EI_edge, q->GJ = t.GJ;
        q->i_flap = t.i_flap, q->i_edge = t.i_edge, q->ip_over_a = c->wagner ? (t.i_flap + t.i_edge) / t.mu : 0.0;
        q->cg[0] = t.cg[0], q->sc[0] = t.sc[0], q->tc[0] = t.tc[0];
        mem[i].twist = t.twist;
        mem[i].elements = -c->elements;
    }
    sm_point_mass pm;
    memset(&pm, 0, sizeof pm);
    pm.joint = nmem;
    pm.mass = c->tip_mass;
    pm.offset[1] = c->tip_off;      /* along the tip section's chord (twist 0 there): hub y */
    pm.inertia[0] = c->tip_I[0];   /* torsion: about the span, hub x */
    pm.inertia[1] = c->tip_I[1];   /* flap rotation: about the chord, hub y */
    pm.inertia[2] = c->tip_I[2];   /* lag rotation: about the flap normal, hub z */
    sm_structure st = {.n_joints = nmem + 1, .joint_xy = xy, .n_sections = nmem, .sections = sec, .n_members = nmem,
                       .members = mem, .n_point_masses = c->tip_mass > 0 ? 1 : 0, .point_masses = &pm,
                       .clamp = 0, .spatial = 1, .joint_z = z};
    sm_options o;
    sm_default_options(&o);
    o.modes = nm;
    o.coriolis = c->coriolis;
    o.mode_shapes = 0;
    sm_result *r = tu_solve1(&st, &o, omega, NULL);
    if (!r)
        return -1;
    int ok = r->cases[0].status == SM_CASE_SOLVED && r->cases[0].n_modes >= nm;
    for (int i = 0; ok && i < nm; i++)
        hz[i] = r->cases[0].frequency[i] / (2 * PI);
    sm_result_free(r);
    return ok ? 0 : -1;
}

/* A tapered blade (hub 1 m, length 10 m, 600 rpm-class speed) given either as stations on one
 * member of ne elements, or (k > 0) as k uniform members of ne/k elements each, every member
 * taking the stations' value at its midpoint, as a user typing a stepped blade would. */
static int taper_solve(const blade *b, int ne, int k, double omega, int nm, double *f)
{
    enum { KMAX = 64 };
    double xy[2 * (KMAX + 1)], z[KMAX + 1];
    sm_section sec[KMAX];
    sm_member mem[KMAX];
    int nmem = k > 0 ? k : 1;
    if (nmem > KMAX)
        return -1;
    memset(sec, 0, sizeof sec);
    memset(mem, 0, sizeof mem);
    for (int j = 0; j <= nmem; j++) {
        xy[2 * j] = 1.0 + 10.0 * j / nmem, xy[2 * j + 1] = 0, z[j] = 0;
    }
    for (int i = 0; i < nmem; i++) {
        double sm = (i + 0.5) / nmem, v[6] = {0};
        for (int j = 0; j + 1 < b->n; j++) /* linear interpolation at sm */
            if (sm <= b->st[j + 1].s) {
                const sm_station *a = &b->st[j], *c = &b->st[j + 1];
                double t = (sm - a->s) / (c->s - a->s);
                double va[6] = {a->mu, a->EA, a->EI_flap, a->EI_edge, a->GJ, a->i_edge};
                double vc[6] = {c->mu, c->EA, c->EI_flap, c->EI_edge, c->GJ, c->i_edge};
                for (int q = 0; q < 6; q++)
                    v[q] = va[q] + t * (vc[q] - va[q]);
                break;
            }
        sec[i].mu = v[0], sec[i].EA = v[1], sec[i].EI_flap = v[2], sec[i].EI_edge = v[3], sec[i].GJ = v[4];
        sec[i].i_edge = v[5], sec[i].i_flap = 0.1 * v[5], sec[i].ip_over_a = 1.1 * v[5] / v[0];
        mem[i].from = i, mem[i].to = i + 1, mem[i].section = i, mem[i].elements = k > 0 ? ne / k : ne;
    }
    if (k == 0) {
        mem[0].n_stations = b->n, mem[0].stations = b->st;
        mem[0].station_mask = SM_ST_MU | SM_ST_EA | SM_ST_EI_FLAP | SM_ST_EI_EDGE | SM_ST_GJ | SM_ST_I_EDGE | SM_ST_I_FLAP;
    }
    sm_structure st = {.n_joints = nmem + 1, .joint_xy = xy, .n_sections = nmem, .sections = sec,
                       .n_members = nmem, .members = mem, .clamp = 0, .spatial = 1, .joint_z = z};
    sm_options o;
    sm_default_options(&o);
    o.modes = nm;
    o.mode_shapes = 0;
    sm_result *r = tu_solve1(&st, &o, omega, NULL);
    if (!r)
        return -1;
    int ok = r->cases[0].status == SM_CASE_SOLVED && r->cases[0].n_modes >= nm;
    for (int i = 0; ok && i < nm; i++)
        f[i] = r->cases[0].frequency[i];
    sm_result_free(r);
    return ok ? 0 : -1;
}

static const unsigned ALL = SM_ST_MU | SM_ST_EA | SM_ST_EI_FLAP | SM_ST_EI_EDGE | SM_ST_GJ | SM_ST_I_FLAP |
                            SM_ST_I_EDGE | SM_ST_TWIST | SM_ST_INERTIA_TWIST | SM_ST_CG | SM_ST_SC | SM_ST_TC;

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "tests/reference";
    blade b;
    memset(&b, 0, sizeof b);
    TU_CHECK(blade_read(dir, &b) == 0, "read blade_sec_props.dat");
    double ref1[10], ref2[10], hz[10];
    TU_CHECK(blade_reference(dir, "Test01_nonunif_blade", ref1, 10) == 0, "reference Test01");
    TU_CHECK(blade_reference(dir, "Test02_blade_with_tip_mass", ref2, 10) == 0, "reference Test02");
    double hz2[10], ref[10];
    blade_case c1 = {.hub = 1.75, .len = 33.25, .mask = ALL, .elements = -8, .coriolis = 0};
    blade_case c2 = c1;
    c2.tip_mass = 40, c2.tip_off = 0.05, c2.tip_I[0] = 2.5, c2.tip_I[1] = 1.75, c2.tip_I[2] = 10;
    const double W = 2 * PI; /* 60 rpm */
    const unsigned ALL10 = 0x3ff, FLAP = 1u << 0 | 1u << 2 | 1u << 4 | 1u << 9; /* F1 F2 F3 F5 */

    /* 1a. BModes' own model: its 12 elements as uniform members with the midpoint values */
    TU_CHECK(blade_solve(&b, &c1, W, 10, hz) == 0, "solve Test01 (12 stepped members)");
    blade_compare("Test01, 60 rpm, BModes' model (its 12 elements as 12 uniform members with the midpoint "
                  "values, 8 lumped elements each), per-element frames, Coriolis off, stiffening on, no "
                  "Wagner term, against BModes' published numbers (1 %, 2 %):",
                  hz, ref1, 0.01, 0.02, ALL10);
    /* 1b. the blade as its table says (stations, integral means), refined, against BModes refined */
    c1.elements = 96;
    TU_CHECK(blade_solve(&b, &c1, W, 10, hz) == 0, "solve Test01 (stations)");
    TU_CHECK(blade_refined(dir, "Test01_nonunif_blade", "stock", ref, 10) == 0, "refined Test01");
    blade_compare("Test01, 60 rpm, stations (96 lumped elements, integral means), same options, against "
                  "BModes with 96 elements (1 %, 2 %):",
                  hz, ref, 0.01, 0.02, ALL10);
    /* 2. Test02: BModes leaves the tip mass out of the blade tension (BldVib.f90:279) and gives it
     * no stiffness at all (BldVib.f90:679-697: mass matrix only); spinmodal's tip mass carries its
     * centrifugal potential.  Flap modes against BModes patched to include the tension. */
    c2.elements = -8;
    TU_CHECK(blade_solve(&b, &c2, W, 10, hz2) == 0, "solve Test02 (12 stepped members)");
    blade_compare("Test02 (tip mass 40 kg), BModes' model as 1a, against BModes' published numbers (not "
                  "checked: BModes leaves the tip mass out of the tension):",
                  hz2, ref2, 0.01, 0.02, 0);
    TU_CHECK(blade_refined(dir, "Test02_blade_with_tip_mass", "tip_tension_12el", ref, 10) == 0, "patched Test02");
    blade_compare("Test02, the same, against BModes with the tip mass in the tension (12 elements); flap modes "
                  "checked (BModes still lacks the tip mass's in-plane centrifugal softening):",
                  hz2, ref, 0.01, 0.02, FLAP);
    c2.elements = 96;
    TU_CHECK(blade_solve(&b, &c2, W, 10, hz2) == 0, "solve Test02 (stations)");
    TU_CHECK(blade_refined(dir, "Test02_blade_with_tip_mass", "tip_tension", ref, 10) == 0, "patched Test02, 96");
    blade_compare("Test02, stations (96 elements), against BModes with the tip mass in the tension, 96 "
                  "elements; flap modes checked:",
                  hz2, ref, 0.01, 0.02, FLAP);
    /* 3. what BModes cannot give, on Test01 as 1b: Coriolis, the Wagner term */
    double hc[10], hw[10];
    blade_case cc = c1, cw = c1;
    cc.coriolis = 1;
    cw.wagner = 1;
    TU_CHECK(blade_solve(&b, &cc, W, 10, hc) == 0, "solve Test01 with Coriolis");
    TU_CHECK(blade_solve(&b, &cw, W, 10, hw) == 0, "solve Test01 with the Wagner term");
    printf("Test01 as 1b: what Coriolis and the tension-torsion (Wagner) term change:\n");
    double cmax = 0;
    for (int i = 0; i < 10; i++) {
        printf("  mode %2d  %9.4f Hz  Coriolis on %9.4f (%+6.2f %%)  Wagner on %9.4f (%+6.2f %%)\n", i + 1, hz[i],
               hc[i], 100 * (hc[i] / hz[i] - 1), hw[i], 100 * (hw[i] / hz[i] - 1));
        cmax = fmax(cmax, fabs(hc[i] / hz[i] - 1));
    }
    /* Coriolis couples the lead-lag motion with the stretch: it moves the lag modes, and with them
     * the whole spectrum by less than a per cent on this stiff blade; Wagner raises torsion */
    TU_CHECK(cmax > 1e-5 && cmax < 0.02, "Coriolis moves the frequencies, by less than 2 %% (%.2e)", cmax);
    TU_CHECK(hw[5] / hz[5] - 1 > 0.005, "the Wagner term stiffens the first torsion mode (%+.2f %%)",
             100 * (hw[5] / hz[5] - 1));

    /* 3. stations against stepped members: a blade tapering in mass and stiffness with a kink
     * at mid-span (stations at 0, 0.5, 1), Omega = 12 rad/s, lumped, Coriolis on */
    blade tp;
    memset(&tp, 0, sizeof tp);
    tp.n = 3;
    double tv[3][6] = {{30, 2e8, 4e5, 2e6, 2e5, 0.8}, {18, 1.2e8, 1.5e5, 9e5, 8e4, 0.4}, {6, 0.5e8, 2e4, 1e5, 1e4, 0.05}};
    for (int j = 0; j < 3; j++) {
        sm_station *t = &tp.st[j];
        t->s = 0.5 * j, t->mu = tv[j][0], t->EA = tv[j][1], t->EI_flap = tv[j][2], t->EI_edge = tv[j][3];
        t->GJ = tv[j][4], t->i_edge = tv[j][5], t->i_flap = 0.1 * tv[j][5];
    }
    enum { NM = 4, NR = 4 };
    double fs[NR][NM], fk[NR][NM], fine[NM], dprev = 1e300;
    int ks[NR] = {4, 8, 16, 32};
    TU_CHECK(taper_solve(&tp, 256, 0, 12.0, NM, fine) == 0, "tapered blade, 256 elements of stations");
    printf("tapered blade, Omega = 12 rad/s, lumped, Coriolis on: stations (n elements) and k stepped members "
           "(2 elements each, midpoint values) against stations with 256 elements, largest of modes 1-%d:\n", NM);
    for (int i = 0; i < NR; i++) {
        TU_CHECK(taper_solve(&tp, 2 * ks[i], 0, 12.0, NM, fs[i]) == 0, "stations %d elements", 2 * ks[i]);
        TU_CHECK(taper_solve(&tp, 2 * ks[i], ks[i], 12.0, NM, fk[i]) == 0, "%d stepped members", ks[i]);
        double es = 0, ek = 0, d = 0;
        for (int q = 0; q < NM; q++) {
            es = fmax(es, fabs(fs[i][q] / fine[q] - 1));
            ek = fmax(ek, fabs(fk[i][q] / fine[q] - 1));
            d = fmax(d, fabs(fs[i][q] / fk[i][q] - 1));
        }
        printf("  %3d elements: stations %.2e, stepped (%2d members) %.2e, between them %.2e\n", 2 * ks[i], es, ks[i],
               ek, d);
        TU_CHECK(d < dprev, "the two descriptions approach each other as the mesh is refined");
        dprev = d;
    }
    TU_CHECK(dprev < 2e-3, "stations and 32 stepped members agree within 0.2 %% (%.2e)", dprev);
    return tu_finish("blades");
}
