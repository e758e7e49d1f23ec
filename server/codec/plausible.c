/*
 * plausible.c — unit slips found by dimensionless groups, whatever the kind of structure.
 *
 * How it fits: warn_collect (warn.c) calls plaus_check after its field
 * checks, on a valid request whose core arrays request.c has built.  The
 * groups are read from those arrays (sm_structure: joints, sections,
 * members, stations; the speeds in rad/s), so a planar or spatial
 * structure, a blade, sections in any form and imported files are checked
 * alike; the canonical request only names the field a warning points at.
 * Per member, from the span means of its stations (else its section):
 *   - the axial wave speed c = sqrt(EA / mu) (any structural material:
 *     300 to 20 000 m/s);
 *   - the radius of gyration sqrt(EI / EA) against the member's length L,
 *     each bending direction (1e-4 L to 0.5 L);
 * then for the structure the tip speed Omega R_max (below the speed of
 * sound) and per member the centrifugal strain mu Omega^2 R^2 / EA.  A
 * unit slip scales a whole column of a table, so span means catch it while
 * the tip of a tapered blade (where an importer's stand-in EA meets the
 * smallest mass) does not raise a false alarm.  Each warning points at the
 * field most likely wrong and names the slip: the power of 1e3 that brings
 * the group back into its range nearest its typical value (warn_rules),
 * rpm given as omega, or lengths in mm.  The thresholds are warn.c's.
 */
#include "codec_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* rev/min per rad/s: 60 / 2 pi */
#define PLAUS_RPM_PER_RAD_S (60.0 / CODEC_TWO_PI)

/* The span-mean quantities of a member, indices of plaus_member.q. */
enum { PQ_MU, PQ_EA, PQ_EI_FLAP, PQ_EI_EDGE, PQ_N };

/* A member as the checks see it. */
typedef struct plaus_member {
    size_t i;                /* index in /structure/members */
    double len;              /* length, m */
    double beam;             /* length of the unbranched chain of members it lies in, m */
    double rout;             /* larger distance of its two ends from the spin axis, m */
    double q[PQ_N];          /* span means: mu (kg/m), EA (N), EI_flap, EI_edge (N m^2);
                                EI_edge NAN for a planar member */
    const char *field[PQ_N]; /* the request field behind each ("E" for EA of a material
                                section, "I" ...), or NULL: none, no check */
    unsigned at_station;     /* bit q: field[q] is the stations' (else the section's) */
    const char *sname;       /* the member's section */
    int ea_stand_in;         /* EA is the section's, marked in its "stand_ins" (section.c) */
} plaus_member;

/* The whole request as the checks see it. */
typedef struct plaus_ctx {
    warn_list *w;
    const codec_request *r;
    const sm_structure *st;
    double rmax;             /* largest distance of a joint from the spin axis, m */
    int far_joint;           /* that joint */
    double omax;             /* largest speed, rad/s */
    int kmax;                /* its index in the request's speeds */
    int tip_warned;          /* the tip speed warned */
    double *beam;            /* per member: plaus_member.beam (plaus_beams) */
} plaus_ctx;

/* Unit hints of a slip of k powers of ten in a field (prefix match on field). */
static const struct {
    const char *field;
    int k;
    const char *hint;
} plaus_hints[] = {
    {"E", -3, "kPa for Pa"},           {"E", -6, "MPa or N/mm^2 for Pa"},
    {"E", -9, "GPa for Pa"},           {"EA", -3, "kN for N"},
    {"EA", -6, "MN for N"},            {"EI", 6, "N mm^2 for N m^2"},
    {"EI", -3, "kN m^2 for N m^2"},    {"EI", -6, "MN m^2 for N m^2"},
    {"I", 12, "mm^4 for m^4"},         {"mass_per_length", 3, "g/m for kg/m: g for kg"},
    {"mass_per_length", -3, "t/m for kg/m"}, {"length", 3, "mm for m"},
};

/* 1 when x lies in rule r's range (a NAN bound is open). */
static int plaus_in(double x, const warn_rule *r)
{
    return !(x < r->lo) && !(x > r->hi);
}

/*
 * The signed power of ten k (a multiple of 3, 0 < |k| <= 12) of a slip in
 * a quantity that enters the group g as quantity^p: g / 10^(k p) lies in
 * rule r's range, nearest r->typical (in log).  0 when no k does.
 */
static int plaus_slip(double g, const warn_rule *r, double p)
{
    double best = INFINITY;
    int k, out = 0;

    for (k = -12; k <= 12; k += 3) {
        double x = g * pow(10.0, -k * p), d = fabs(log10(x / r->typical));
        if (k != 0 && plaus_in(x, r) && d < best) {
            best = d;
            out = k;
        }
    }
    return out;
}

/* "EI_flap x1e6 (N mm^2 for N m^2)" (k > 0: given 10^k too large) into buf. */
static const char *plaus_slip_text(char *buf, size_t n, const char *field, int k)
{
    const char *hint = NULL;
    size_t j;

    if (k == 0) {
        snprintf(buf, n, "none by a power of 1e3: check %s and its unit", field);
        return buf;
    }
    for (j = 0; j < sizeof(plaus_hints) / sizeof(plaus_hints[0]); j++)
        if (plaus_hints[j].k == k && !strncmp(field, plaus_hints[j].field,
                                              strlen(plaus_hints[j].field)) &&
            (strcmp(plaus_hints[j].field, "E") || !strcmp(field, "E") || !strcmp(field, "G")))
            hint = plaus_hints[j].hint;
    snprintf(buf, n, "%s %s1e%d%s%s%s", field, k > 0 ? "x" : "/", abs(k), hint ? " (" : "",
             hint ? hint : "", hint ? ")" : "");
    return buf;
}

/* The mean over the span of station quantity q of member m (linear between stations). */
static double plaus_station_mean(const sm_member *m, int q)
{
    double sum = 0;
    int j;

    for (j = 0; j + 1 < m->n_stations; j++) {
        const sm_station *a = &m->stations[j], *b = &m->stations[j + 1];
        double va = q == PQ_MU ? a->mu : q == PQ_EA ? a->EA : q == PQ_EI_FLAP ? a->EI_flap
                                                                               : a->EI_edge;
        double vb = q == PQ_MU ? b->mu : q == PQ_EA ? b->EA : q == PQ_EI_FLAP ? b->EI_flap
                                                                               : b->EI_edge;
        sum += (b->s - a->s) * 0.5 * (va + vb); /* trapezoid: exact for linear */
    }
    return sum;
}

/* Distance of joint j from the spin axis (the hub's z axis), m. */
static double plaus_radius(const sm_structure *st, int j)
{
    return hypot(st->joint_xy[2 * j], st->joint_xy[2 * j + 1]);
}

/* Position of joint j. */
static void plaus_joint(const sm_structure *st, int j, double p[3])
{
    p[0] = st->joint_xy[2 * j];
    p[1] = st->joint_xy[2 * j + 1];
    p[2] = st->joint_z ? st->joint_z[j] : 0;
}

/* The request field behind span-mean quantity q of a section of form f (NULL: none). */
static const char *plaus_section_field(sec_form f, int q)
{
    static const char *const planar[PQ_N] = {"mass_per_length", "E", "I", NULL};
    static const char *const material[PQ_N] = {"mass_per_length", "E", "I_flap", "I_edge"};
    static const char *const stiffness[PQ_N] = {"mass_per_length", "EA", "EI_flap", "EI_edge"};

    return (f == SEC_PLANAR ? planar : f == SEC_MATERIAL ? material : stiffness)[q];
}

/* The station keys of the span-mean quantities. */
static const char *const plaus_station_key[PQ_N] = {"mass_per_length", "EA", "EI_flap", "EI_edge"};

/* The pointer of the field behind quantity q of member pm (pm->field[q] not NULL), malloc'd;
 * NULL on NOMEM (w->nomem set).  Written only for a warning (issue 27: writing four for every
 * member, twice, was a tenth of a blade request's parse). */
static char *plaus_ptr(plaus_ctx *c, const plaus_member *pm, int q)
{
    char *p, *base;

    if (pm->at_station & (1u << q)) {
        p = err_fmt("/structure/members/%zu/stations/0/%s", pm->i, plaus_station_key[q]);
    } else {
        base = err_ptr_key("/structure/sections", pm->sname);
        p = base ? err_ptr_key(base, pm->field[q]) : NULL;
        free(base);
    }
    if (!p)
        c->w->nomem = 1;
    return p;
}

/* "member 3 ('arm')" or "the blade", for messages, into name (96 chars). */
static const char *plaus_name(const plaus_ctx *c, const plaus_member *pm, char name[96])
{
    const json_t *id;

    if (c->w->blade) {
        snprintf(name, 96, "the %s", c->w->blade == CODEC_FORM_TOWER ? "tower" : "blade");
        return name;
    }
    id = json_object_get(json_array_get(json_object_get(req_structure(c->r), "members"), pm->i),
                         "id");
    snprintf(name, 96, "member %zu%s%.60s%s", pm->i, id ? " ('" : "",
             id ? json_string_value(id) : "", id ? "')" : "");
    return name;
}

/* The span means of member i and the fields behind them into *pm. */
static void plaus_member_fill(plaus_ctx *c, size_t i, plaus_member *pm)
{
    static const unsigned bit[PQ_N] = {SM_ST_MU, SM_ST_EA, SM_ST_EI_FLAP, SM_ST_EI_EDGE};
    const sm_member *m = &c->st->members[i];
    const sm_section *s = &c->st->sections[m->section];
    const char *sname = req_section_name(c->r, m->section);
    const json_t *sec = json_object_get(json_object_get(req_structure(c->r), "sections"), sname);
    sec_form f = sec_classify_as(sec, c->st->spatial);
    const json_t *x;
    double a[3], b[3];
    size_t k;
    int q;

    memset(pm, 0, sizeof(*pm));
    pm->i = i;
    plaus_joint(c->st, m->from, a);
    plaus_joint(c->st, m->to, b);
    pm->len = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
                   (b[2] - a[2]) * (b[2] - a[2]));
    pm->beam = c->beam[i];
    pm->rout = fmax(plaus_radius(c->st, m->from), plaus_radius(c->st, m->to));
    pm->q[PQ_MU] = s->mu;
    pm->q[PQ_EA] = c->st->spatial ? s->EA : s->E * s->A;
    pm->q[PQ_EI_FLAP] = c->st->spatial ? s->EI_flap : s->E * s->I;
    pm->q[PQ_EI_EDGE] = c->st->spatial ? s->EI_edge : NAN;
    pm->sname = sname;
    for (q = 0; q < PQ_N; q++) {
        if (m->n_stations && (m->station_mask & bit[q])) {
            pm->q[q] = plaus_station_mean(m, q);
            pm->field[q] = plaus_station_key[q];
            pm->at_station |= 1u << q;
        } else {
            pm->field[q] = plaus_section_field(f, q);
        }
    }
    if (!(m->n_stations && (m->station_mask & SM_ST_EA)))
        json_array_foreach(json_object_get(sec, "stand_ins"), k, x) {
            const char *name = json_string_value(x);
            pm->ea_stand_in |= name && !strcmp(name, "EA");
        }
}

/* The pointer of a length: the blade's length, else joint j.  malloc'd; NULL on NOMEM. */
static char *plaus_length_ptr(const plaus_ctx *c, int j)
{
    if (c->w->blade)
        return strdup(c->w->blade == CODEC_FORM_TOWER ? "/tower/height" : "/blade/length");
    return err_ptr_key("/structure/joints", codec_request_joint_name(c->r, j));
}

/*
 * The axial wave speed of member pm; returns 1 when it warned at EA (the
 * radius of gyration, which has EA too, then stays silent).  ei_hi: some
 * bending direction's radius of gyration is too large, so a low wave speed
 * is EA's, not the mass's.
 */
static int plaus_wave_speed(plaus_ctx *c, const plaus_member *pm, int ei_hi)
{
    const warn_rule *r = &warn_rules[WARN_WAVE_SPEED];
    double cs = sqrt(pm->q[PQ_EA] / pm->q[PQ_MU]);
    char slip[160], alt[224] = "", ea[96], b1[32], b2[32], note[96] = "", name[96], *ptr;
    int on_ea, k;

    if (!(pm->q[PQ_MU] > 0 && pm->q[PQ_EA] > 0) || plaus_in(cs, r))
        return 0;
    if (pm->ea_stand_in)
        snprintf(note, sizeof(note), "; EA a stand-in, read as EI / (%g x length)^2",
                 warn_rules[WARN_GYRATION].typical);
    on_ea = cs > r->hi || ei_hi;
    k = plaus_slip(cs, r, on_ea ? 0.5 : -0.5);
    plaus_slip_text(slip, sizeof(slip), pm->field[on_ea ? PQ_EA : PQ_MU], k);
    if (k > 0 && on_ea)
        snprintf(alt, sizeof(alt), " (or every stiffness x1e%d, or mass_per_length /1e%d)", k, k);
    else if (k > 0)
        snprintf(alt, sizeof(alt), " (or every stiffness /1e%d, as %s)", k,
                 plaus_slip_text(ea, sizeof(ea), "EA", -k));
    if (!(ptr = plaus_ptr(c, pm, on_ea ? PQ_EA : PQ_MU)))
        return on_ea;
    warn_add(c->w, ptr,
             "the axial wave speed sqrt(EA / mass_per_length) of %s is %.4g m/s, outside %s to "
             "%s m/s (any structural material; span means%s): likely slip: %s%s",
             plaus_name(c, pm, name), cs, warn_g(b1, r->lo), warn_g(b2, r->hi), note, slip, alt);
    free(ptr);
    return on_ea;
}

/*
 * The radius of gyration of member pm in bending direction q (PQ_EI_FLAP or
 * PQ_EI_EDGE): at least lo times the member's length, at most hi times the
 * beam's (the chain of members it lies in: a curved beam given as short
 * straight members has members shorter than its section).
 */
static void plaus_gyration(plaus_ctx *c, const plaus_member *pm, int q)
{
    const warn_rule *r = &warn_rules[WARN_GYRATION];
    double rg = sqrt(pm->q[q] / pm->q[PQ_EA]), lo = rg / pm->len, hi = rg / pm->beam;
    double x = hi > r->hi ? hi : lo, len = hi > r->hi ? pm->beam : pm->len;
    const char *what = q == PQ_EI_FLAP ? (c->st->spatial ? "EI_flap" : "EI") : "EI_edge";
    char slip[160], b1[32], b2[32], name[96], *lp;

    if (!(pm->q[q] > 0 && pm->q[PQ_EA] > 0 && pm->len > 0) || (!(lo < r->lo) && !(hi > r->hi)))
        return;
    if (x < r->lo && c->rmax > warn_rules[WARN_RADIUS].hi && plaus_in(x * 1e3, r)) {
        lp = plaus_length_ptr(c, c->far_joint); /* all lengths: one warning, with R_max's */
        if (!lp) {
            c->w->nomem = 1;
            return;
        }
        plaus_slip_text(slip, sizeof(slip), "length", 3);
    } else {
        plaus_slip_text(slip, sizeof(slip), pm->field[q], plaus_slip(x, r, 0.5));
        if (!(lp = plaus_ptr(c, pm, q)))
            return;
    }
    warn_add(c->w, lp,
             "the radius of gyration sqrt(%s / EA) of %s is %.4g m, %.3g times %s %.6g m, "
             "outside %s to %s times (span means): likely slip: %s",
             what, plaus_name(c, pm, name), rg, x,
             len > pm->len ? "the length of the beam it lies in," : "its length", len,
             warn_g(b1, r->lo), warn_g(b2, r->hi), slip);
    free(lp);
}

/*
 * A stand-in EA (the section's "stand_ins"): set stiff on purpose, it says nothing of its own
 * units, but an importer derives it from EI, so a slip in EI or mu is what to look for.  Per
 * bending direction, the wave speed of the EA a section of that EI would have with the typical
 * radius of gyration, EA_q = EI_q / (typical L)^2: too fast blames that EI field, too slow
 * mass_per_length (once).  The radius of gyration would be typical by construction, and the
 * strain of a rigid member is nil (plaus_strain).  Returns 1 when it warned.
 */
static int plaus_stand_in_wave(plaus_ctx *c, const plaus_member *pm)
{
    const warn_rule *r = &warn_rules[WARN_WAVE_SPEED];
    double rg = warn_rules[WARN_GYRATION].typical * pm->len;
    char slip[160], b1[32], b2[32], name[96], *ptr;
    int q, slow = 0, warned = 0;

    for (q = PQ_EI_FLAP; q <= PQ_EI_EDGE && rg > 0 && pm->q[PQ_MU] > 0; q++) {
        double cs = sqrt(pm->q[q] / (rg * rg) / pm->q[PQ_MU]);
        if (!(pm->q[q] > 0) || !pm->field[q] || plaus_in(cs, r))
            continue;
        if (cs < r->lo) {
            slow = q;
            continue;
        }
        plaus_slip_text(slip, sizeof(slip), pm->field[q], plaus_slip(cs, r, 0.5));
        if (!(ptr = plaus_ptr(c, pm, q)))
            return 1;
        warn_add(c->w, ptr,
                 "the axial wave speed of %s, its stand-in EA read as %s / (%g x length)^2, is "
                 "%.4g m/s, outside %s to %s m/s (any structural material; span means): likely "
                 "slip: %s",
                 plaus_name(c, pm, name), pm->field[q], warn_rules[WARN_GYRATION].typical, cs,
                 warn_g(b1, r->lo), warn_g(b2, r->hi), slip);
        free(ptr);
        warned = 1;
    }
    if (slow && !warned) {
        plaus_member eq = *pm;
        eq.q[PQ_EA] = pm->q[slow] / (rg * rg);
        plaus_wave_speed(c, &eq, 0); /* too slow: it blames mass_per_length */
        warned = 1;
    }
    return warned;
}

/* The checks of one member that need no speed; returns 1 when its wave speed warned. */
static int plaus_member_groups(plaus_ctx *c, const plaus_member *pm)
{
    const warn_rule *g = &warn_rules[WARN_GYRATION];
    int q, ei_hi = 0, on_ea;

    if (!pm->field[PQ_MU] || !pm->field[PQ_EA])
        return 0;
    if (pm->ea_stand_in)
        return plaus_stand_in_wave(c, pm);
    for (q = PQ_EI_FLAP; q <= PQ_EI_EDGE; q++)
        ei_hi |= pm->q[q] > 0 && pm->q[PQ_EA] > 0 && pm->beam > 0 &&
                 sqrt(pm->q[q] / pm->q[PQ_EA]) / pm->beam > g->hi;
    on_ea = plaus_wave_speed(c, pm, ei_hi);
    if (!on_ea)
        for (q = PQ_EI_FLAP; q <= PQ_EI_EDGE; q++)
            if (pm->field[q])
                plaus_gyration(c, pm, q);
    return on_ea || !plaus_in(sqrt(pm->q[PQ_EA] / pm->q[PQ_MU]), &warn_rules[WARN_WAVE_SPEED]);
}

/* The pointer of speed k of the request (malloc'd; NULL on NOMEM); *key "omega" or "rpm". */
static char *plaus_speed_ptr(const plaus_ctx *c, int k, const char **key)
{
    const json_t *an = json_object_get(codec_request_canonical(c->r), "analysis");
    const json_t *x;

    *key = json_object_get(an, "omega") ? "omega" : "rpm";
    x = json_object_get(an, *key);
    if (json_is_array(x))
        return err_fmt("/analysis/%s/%d", *key, k);
    if (json_is_object(x))
        return err_fmt("/analysis/%s/to", *key);
    return err_fmt("/analysis/%s", *key);
}

/* 1 when x is a multiple of the WARN_ROUND step (as an rpm number is written). */
static int plaus_round(double x)
{
    double n = x / warn_rules[WARN_ROUND].lo;

    return x > 0 && fabs(n - nearbyint(n)) <= 1e-9 * fmax(1.0, n); /* decimal to binary */
}

/*
 * The tip speed: Omega R_max against the speed of sound.  The slip named:
 * rpm given as omega when omega read as rpm gives a plausible tip speed and
 * omega * 60 / 2 pi is no round rpm (a converted rpm is in rad/s); lengths
 * in mm when R_max is beyond any rotor and / 1e3 fits; else the speed.
 */
static void plaus_tip_speed(plaus_ctx *c)
{
    const warn_rule *r = &warn_rules[WARN_TIP_SPEED];
    double v = c->omax * c->rmax, as_rpm = v / PLAUS_RPM_PER_RAD_S;
    const char *key;
    char *sp = plaus_speed_ptr(c, c->kmax, &key), *lp = plaus_length_ptr(c, c->far_joint);
    int omega = !strcmp(key, "omega");

    if (!sp || !lp) {
        c->w->nomem = 1;
    } else if (omega && plaus_in(as_rpm, r) && !plaus_round(c->omax * PLAUS_RPM_PER_RAD_S)) {
        warn_add(c->w, sp, "the tip speed Omega R_max = %.4g m/s (omega %g rad/s = %.4g rpm, "
                 "R_max %.4g m) is above %g m/s, the speed of sound: read as %g rpm%s the tip "
                 "would run at %.3g m/s: likely slip: rpm given as omega (rpm for rad/s): give "
                 "\"rpm\" instead", v, c->omax, c->omax * PLAUS_RPM_PER_RAD_S, c->rmax, r->hi,
                 c->omax, plaus_round(c->omax) ? " (a round rpm number)" : "", as_rpm);
        c->tip_warned = 1;
    } else if (c->rmax > warn_rules[WARN_RADIUS].hi && plaus_in(v / 1e3, r)) {
        warn_add(c->w, lp, "the tip speed Omega R_max = %.4g m/s (R_max %.6g m, beyond any "
                 "rotor's %g m) is above %g m/s, the speed of sound: likely slip: lengths in mm "
                 "for m (mm for m, x1e3)", v, c->rmax, warn_rules[WARN_RADIUS].hi, r->hi);
        c->tip_warned = 1;
    } else {
        warn_add(c->w, sp, "the tip speed Omega R_max = %.4g m/s (%s %g%s, R_max %.4g m) is "
                 "above %g m/s, the speed of sound (supersonic fan tips aside): %s", v, key,
                 omega ? c->omax : c->omax * PLAUS_RPM_PER_RAD_S,
                 omega && plaus_round(c->omax * PLAUS_RPM_PER_RAD_S) ? " rad/s, a round rpm "
                 "converted" : "", c->rmax, r->hi,
                 omega && !plaus_round(c->omax * PLAUS_RPM_PER_RAD_S)
                     ? "is the speed in rpm (rpm for rad/s), or a length in mm?"
                     : "check the speed and the lengths (a length in mm?)");
        c->tip_warned = 1;
    }
    free(sp);
    free(lp);
}

/* The centrifugal strain of member pm at the largest speed. */
static void plaus_strain(plaus_ctx *c, const plaus_member *pm)
{
    const warn_rule *r = &warn_rules[WARN_STRAIN];
    double e = pm->q[PQ_MU] * c->omax * c->omax * pm->rout * pm->rout / pm->q[PQ_EA];
    char slip[160], alt[128] = "", ea[96], b[32], name[96], *ptr;
    int k = plaus_slip(e, r, 1.0);

    if (!(pm->q[PQ_EA] > 0) || !pm->field[PQ_MU] || pm->ea_stand_in || plaus_in(e, r) ||
        !(ptr = plaus_ptr(c, pm, PQ_MU)))
        return;
    plaus_slip_text(slip, sizeof(slip), pm->field[PQ_MU], k);
    if (k > 0)
        snprintf(alt, sizeof(alt), ", or %s", plaus_slip_text(ea, sizeof(ea), "EA", -k));
    warn_add(c->w, ptr,
             "the centrifugal strain mass_per_length Omega^2 R^2 / EA of "
             "%s is %.3g at %g rad/s (R %.4g m; span means), above %s: no structure stretches "
             "so far: likely slip: %s%s",
             plaus_name(c, pm, name), e, c->omax, pm->rout, warn_g(b, r->hi), slip, alt);
    free(ptr);
}

/* Root of member i in the union-find forest up (path halving). */
static int plaus_root(int *up, int i)
{
    while (up[i] != i)
        i = up[i] = up[up[i]];
    return i;
}

/*
 * c->beam: per member the length of its beam, the chain of members joined
 * end to end at joints that no third member shares.  SM_OK or SM_NOMEM.
 */
static int plaus_beams(plaus_ctx *c)
{
    const sm_structure *st = c->st;
    int nm = st->n_members, nj = st->n_joints, i, e, rc = SM_NOMEM;
    int *deg = calloc((size_t)nj + 1, sizeof(int)), *first = malloc(((size_t)nj + 1) * sizeof(int));
    int *up = malloc(((size_t)nm + 1) * sizeof(int));
    double *sum = calloc((size_t)nm + 1, sizeof(double));

    c->beam = calloc((size_t)nm + 1, sizeof(double));
    if (!deg || !first || !up || !sum || !c->beam)
        goto fail;
    for (i = 0; i < nj; i++)
        first[i] = -1;
    for (i = 0; i < nm; i++) {
        deg[st->members[i].from]++;
        deg[st->members[i].to]++;
        up[i] = i;
    }
    for (i = 0; i < nm; i++)
        for (e = 0; e < 2; e++) {
            int j = e ? st->members[i].to : st->members[i].from;
            if (deg[j] != 2)
                continue;
            if (first[j] < 0)
                first[j] = i;
            else
                up[plaus_root(up, i)] = plaus_root(up, first[j]);
        }
    for (i = 0; i < nm; i++) {
        double a[3], b[3];
        plaus_joint(st, st->members[i].from, a);
        plaus_joint(st, st->members[i].to, b);
        c->beam[i] = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
                          (b[2] - a[2]) * (b[2] - a[2]));
        sum[plaus_root(up, i)] += c->beam[i];
    }
    for (i = 0; i < nm; i++)
        c->beam[i] = sum[plaus_root(up, i)];
    rc = SM_OK;
fail:
    free(deg);
    free(first);
    free(up);
    free(sum);
    return rc;
}

/* R_max against the largest rotors: beyond them the lengths are in mm. */
static void plaus_radius_check(plaus_ctx *c)
{
    const warn_rule *r = &warn_rules[WARN_RADIUS];
    char *lp;

    if (!(c->rmax > r->hi))
        return;
    lp = plaus_length_ptr(c, c->far_joint);
    if (!lp) {
        c->w->nomem = 1;
        return;
    }
    warn_add(c->w, lp, "R_max = %.6g m: the structure reaches farther from the spin axis than "
             "any rotor (%g m): likely slip: %s", c->rmax, r->hi,
             plaus_in(c->rmax / 1e3, r) ? "lengths in mm for m (mm for m, x1e3)"
                                        : "a length in another unit");
    free(lp);
}

/* R_max and its joint, the largest speed and its index into c. */
static void plaus_extent(plaus_ctx *c)
{
    const double *om;
    int n, k, j;

    for (j = 0; j < c->st->n_joints; j++)
        if (plaus_radius(c->st, j) > c->rmax) {
            c->rmax = plaus_radius(c->st, j);
            c->far_joint = j;
        }
    om = codec_request_speeds(c->r, &n);
    for (k = 0; k < n; k++)
        if (om[k] > c->omax) {
            c->omax = om[k];
            c->kmax = k;
        }
}

void plaus_check(warn_list *w, const codec_request *r)
{
    plaus_ctx c = {w, r, codec_request_structure(r), 0, 0, 0, 0, 0, NULL};
    plaus_member pm;
    unsigned char *quiet; /* per member: its wave speed warned (the strain then stays quiet) */
    int i;

    quiet = calloc((size_t)c.st->n_members + 1, 1);
    if (!quiet || plaus_beams(&c) != SM_OK) {
        free(quiet);
        free(c.beam);
        w->nomem = 1;
        return;
    }
    plaus_extent(&c);
    plaus_radius_check(&c);
    for (i = 0; i < c.st->n_members && !w->nomem; i++) {
        plaus_member_fill(&c, (size_t)i, &pm);
        quiet[i] = (unsigned char)plaus_member_groups(&c, &pm);
    }
    if (!w->nomem && c.omax * c.rmax > warn_rules[WARN_TIP_SPEED].hi)
        plaus_tip_speed(&c);
    for (i = 0; i < c.st->n_members && !w->nomem && !c.tip_warned && c.omax > 0; i++) {
        plaus_member_fill(&c, (size_t)i, &pm);
        if (!quiet[i])
            plaus_strain(&c, &pm);
    }
    free(quiet);
    free(c.beam);
}
