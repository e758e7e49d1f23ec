/*
 * request.c — a validated request: canonical text, SHA-256 and the core's arrays.
 *
 * How it fits: codec_request_parse reads the text (size limit, JSON syntax),
 * val_request (validate.c) checks it and returns the canonical copy with
 * every default written out, and only when no error was found this file
 * dumps that copy as the canonical text (keys sorted, compact, 17 digits),
 * hashes it, and turns it into the sm_structure, sm_options and speeds that
 * sm_model_new and sm_solve take.  Joints and sections are indexed in sorted
 * name order, so the canonical text fully determines the model and two
 * requests with the same SHA-256 give the same result.  The request is
 * immutable afterwards; diag.c and result.c read it through the accessors.
 */
#include "codec_internal.h"

#include <stdarg.h>
#include <stdlib.h>
#include <math.h>
#include <stdio.h>
#include <limits.h>
#include <string.h>

/* Flags for dumping canonical text. */

struct codec_request {
    json_t *canon;              /* canonical request, defaults applied */
    json_t *structure;          /* canonical structure of the model: canon's, or the one its
                                   "blade" stands for (blade.c) */
    int blade;                  /* CODEC_FORM_*: the blade (1) and tower (2) forms move
                                   pointers into /blade, /tower (tower_form_pointer) */
    json_t *warnings;           /* input_warnings (warn.c), an array, maybe empty */
    char *canon_text;           /* its sorted compact dump */
    char *name;                 /* the request's "name" (not in canon), or NULL */
    char *stored_text;          /* canon with "name", dumped as canon_text; NULL without one */
    char sha[65];               /* SHA-256 of canon_text, hex */
    const char **joint_names;   /* n_joints, sorted, borrowed from canon */
    const char **section_names; /* n_sections, sorted, borrowed from canon */
    double *joint_xy;           /* 2*n_joints */
    double *joint_z;            /* n_joints (spatial requests), else NULL */
    sm_section *sections;       /* n_sections */
    sm_member *members;         /* n_members */
    sm_point_mass *point_masses;/* n_point_masses (NULL if 0) */
    sm_support *supports;       /* n_supports (NULL if 0): springs, then foundations */
    sm_station *stations;       /* every member's stations, member after member (or NULL) */
    double *speeds;             /* n_speeds, request order, rad/s */
    double *rpm;                /* n_speeds, the same in rev/min */
    int n_speeds;
    sm_structure st;            /* points into the arrays above */
    sm_options opt;             /* from the analysis and frames fields */
    sm_model_info info;         /* sizes of its model (sm_structure_check) */
    int estimate_levels;        /* analysis.error_estimate: refined levels that fit the
                                   limits (sm_estimate_plan: 2, or 1), 0 when not asked */
};

/* qsort/bsearch order of two (const char *) elements. */
static int req_cmp_str(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* Sorted key list of obj (borrowed keys); NULL = NOMEM. */
static const char **req_sorted_keys(const json_t *obj, int *n)
{
    size_t k = 0, cnt = json_object_size(obj);
    const char **names = calloc(cnt ? cnt : 1, sizeof(*names));
    const char *key;
    json_t *val;

    if (!names)
        return NULL;
    json_object_foreach((json_t *)obj, key, val) {
        (void)val;
        names[k++] = key;
    }
    qsort(names, cnt, sizeof(*names), req_cmp_str);
    *n = (int)cnt;
    return names;
}

/* Index of name in the n sorted names; -1 when absent. */
static int req_name_index(const char **names, int n, const char *name)
{
    const char **hit = bsearch(&name, names, (size_t)n, sizeof(*names), req_cmp_str);
    return hit ? (int)(hit - names) : -1;
}

/* A number of the canonical copy (validated: 0 is never used for a non-number). */
static double req_number(const json_t *x)
{
    double d = 0;
    field_number(x, &d);
    return d;
}

/*
 * Joints and sections arrays, sorted by name.  The request is spatial when
 * its sections are (validate.c made them all of one kind); then every
 * canonical joint is [x, y, z], which is how it is told here (a section
 * that its members' stations complete may have no field of its form).
 */
static int req_build_tables(codec_request *r)
{
    const json_t *st = r->structure;
    const json_t *joints = json_object_get(st, "joints");
    const json_t *secs = json_object_get(st, "sections");
    int i, nj = 0, ns = 0;

    r->joint_names = req_sorted_keys(joints, &nj);
    r->section_names = req_sorted_keys(secs, &ns);
    if (!r->joint_names || !r->section_names)
        return SM_NOMEM;
    r->joint_xy = malloc(2 * (size_t)nj * sizeof(double));
    r->sections = calloc((size_t)(ns ? ns : 1), sizeof(sm_section));
    if (!r->joint_xy || !r->sections)
        return SM_NOMEM;
    /* a spatial request writes every joint as [x, y, z] (validate.c), a planar one [x, y] */
    r->st.spatial = nj > 0 && json_array_size(json_object_get(joints, r->joint_names[0])) == 3;
    for (i = 0; i < ns; i++)
        sec_fill(json_object_get(secs, r->section_names[i]), r->st.spatial, &r->sections[i]);
    if (r->st.spatial && !(r->joint_z = malloc((size_t)(nj ? nj : 1) * sizeof(double))))
        return SM_NOMEM;
    for (i = 0; i < nj; i++) {
        const json_t *xy = json_object_get(joints, r->joint_names[i]);
        r->joint_xy[2 * i] = req_number(json_array_get(xy, 0));
        r->joint_xy[2 * i + 1] = req_number(json_array_get(xy, 1));
        if (r->joint_z)
            r->joint_z[i] = req_number(json_array_get(xy, 2));
    }
    r->st.n_joints = nj;
    r->st.joint_xy = r->joint_xy;
    r->st.joint_z = r->joint_z;
    r->st.n_sections = ns;
    r->st.sections = r->sections;
    return SM_OK;
}

/* The spatial fields of member b from its canonical object x (zero when absent). */
static void req_member_spatial(const json_t *x, sm_member *b)
{
    const json_t *e3 = json_object_get(x, "flap_direction");
    int k;

    b->twist = req_number(json_object_get(x, "twist_deg")) * CODEC_RAD_PER_DEG;
    for (k = 0; k < 3; k++)
        b->e3[k] = req_number(json_array_get(e3, (size_t)k));
}

/*
 * The stations of every member (DESIGN.md 8, station.c) into r->stations;
 * a section field that only the stations give (absent from a partial
 * section: zero) takes the member's first station's value, so the section
 * stays valid for the core, which reads that field from the stations.
 */
/* 1 when section k of r gives ip_over_a itself (DESIGN.md 8.1). */
static int req_ip_given(const codec_request *r, int k)
{
    const json_t *secs = json_object_get(r->structure, "sections");

    return k >= 0 && json_object_get(json_object_get(secs, r->section_names[k]), "ip_over_a");
}

static int req_build_stations(codec_request *r, const json_t *mems)
{
    const json_t *x;
    size_t i, total = 0, at = 0;

    json_array_foreach(mems, i, x)
        total += json_array_size(json_object_get(x, "stations"));
    if (!total)
        return SM_OK;
    if (!(r->stations = calloc(total, sizeof(sm_station))))
        return SM_NOMEM;
    json_array_foreach(mems, i, x) {
        const json_t *sts = json_object_get(x, "stations");
        sm_member *b = &r->members[i];
        sm_section *c = b->section >= 0 ? &r->sections[b->section] : NULL;
        size_t n = json_array_size(sts);
        if (!n)
            continue;
        b->stations = r->stations + at;
        b->n_stations = (int)n;
        b->station_mask = stn_fill(sts, r->stations + at);
#define REQ_FROM_STATION(bit, f) if (c && (b->station_mask & (bit)) && c->f == 0) c->f = b->stations[0].f;
        REQ_FROM_STATION(SM_ST_MU, mu) REQ_FROM_STATION(SM_ST_EA, EA)
        REQ_FROM_STATION(SM_ST_EI_FLAP, EI_flap) REQ_FROM_STATION(SM_ST_EI_EDGE, EI_edge)
        REQ_FROM_STATION(SM_ST_GJ, GJ) REQ_FROM_STATION(SM_ST_I_FLAP, i_flap)
        REQ_FROM_STATION(SM_ST_I_EDGE, i_edge)
#undef REQ_FROM_STATION
        if (c && c->ip_over_a == 0 && c->mu > 0 && !req_ip_given(r, b->section))
            c->ip_over_a = (c->i_flap + c->i_edge) / c->mu; /* DESIGN.md 7.3, stiffness form */
        if (c && req_ip_given(r, b->section) && !(b->station_mask & SM_ST_IP_OVER_A)) {
            size_t j; /* the section's I_p/A given: it holds along the stations too (8.1) */
            for (j = 0; j < n; j++)
                r->stations[at + j].ip_over_a = c->ip_over_a;
            b->station_mask |= SM_ST_IP_OVER_A;
        }
        at += n;
    }
    return SM_OK;
}

/* The point mass x (canonical) into p: joint, mass and the spatial inertia, products, offset. */
static void req_point_mass(codec_request *r, const json_t *x, sm_point_mass *p)
{
    const json_t *in = json_object_get(x, "inertia"), *pr = json_object_get(x, "products");
    const json_t *off = json_object_get(x, "offset");
    int k;

    p->joint = req_name_index(r->joint_names, r->st.n_joints,
                              json_string_value(json_object_get(x, "joint")));
    p->mass = req_number(json_object_get(x, "mass"));
    for (k = 0; k < 3; k++) {
        p->inertia[k] = req_number(json_array_get(in, (size_t)k));
        p->products[k] = req_number(json_array_get(pr, (size_t)k));
        p->offset[k] = req_number(json_array_get(off, (size_t)k));
    }
}

/* Members, point masses and clamp as indices. */
static int req_build_structure(codec_request *r)
{
    const json_t *st = r->structure;
    const json_t *mems = json_object_get(st, "members");
    const json_t *pms = json_object_get(st, "point_masses");
    const json_t *x;
    size_t i, nm = json_array_size(mems), np = json_array_size(pms);
    int nj = r->st.n_joints, ns = r->st.n_sections;

    r->members = calloc(nm ? nm : 1, sizeof(sm_member));
    r->point_masses = np ? calloc(np, sizeof(sm_point_mass)) : NULL;
    if (!r->members || (np && !r->point_masses))
        return SM_NOMEM;
    json_array_foreach(mems, i, x) {
        r->members[i].from = req_name_index(r->joint_names, nj,
                                            json_string_value(json_object_get(x, "from")));
        r->members[i].to = req_name_index(r->joint_names, nj,
                                          json_string_value(json_object_get(x, "to")));
        r->members[i].section = req_name_index(r->section_names, ns,
                                               json_string_value(json_object_get(x, "section")));
        r->members[i].elements = (int)json_integer_value(json_object_get(x, "elements"));
        req_member_spatial(x, &r->members[i]);
    }
    json_array_foreach(pms, i, x)
        req_point_mass(r, x, &r->point_masses[i]);
    r->st.n_members = (int)nm;
    r->st.members = r->members;
    r->st.n_point_masses = (int)np;
    r->st.point_masses = r->point_masses;
    r->st.clamp = req_name_index(r->joint_names, nj, plat_clamp_name(st));
    r->st.base_free = plat_base_free(st);
    r->st.base_held = plat_base_held(st);
    for (int k = 0; k < 3; k++) /* DESIGN.md 8.8: absent = none */
        r->st.gravity[k] = req_number(json_array_get(json_object_get(st, "gravity"), (size_t)k));
    {
        sup_joints J = {r->joint_names, nj, r->joint_xy, r->joint_z};
        if (sup_build(st, &J, &r->supports, &r->st.n_supports))
            return SM_NOMEM;
        r->st.supports = r->supports;
    }
    return req_build_stations(r, mems);
}

/* sm_options.engine_orders from the canonical analysis.engine_orders (DESIGN.md 9.1). */
static void req_engine_orders(sm_options *o, const json_t *eo)
{
    size_t i;
    const json_t *x;

    o->n_engine_orders = 0;
    json_array_foreach(eo, i, x)
        if (i < SM_MAX_ENGINE_ORDERS)
            o->engine_orders[o->n_engine_orders++] = json_number_value(x);
}

/* sm_options and speeds from frames and analysis. */
static int req_build_options(codec_request *r)
{
    const json_t *an = json_object_get(r->canon, "analysis");
    const json_t *fr = json_object_get(r->canon, "frames");
    const json_t *mpf = json_object_get(an, "modes_per_frame");
    size_t n = spd_count(an);

    sm_default_options(&r->opt);
    if (json_is_string(fr)) {
        r->opt.frames = !strcmp(json_string_value(fr), "single") ? SM_FRAMES_SINGLE
                                                                 : SM_FRAMES_PER_ELEMENT;
        r->opt.frames_param = 0;
    } else if (json_object_get(fr, "per_member")) {
        r->opt.frames = SM_FRAMES_PER_MEMBER;
        r->opt.frames_param = (int)json_integer_value(json_object_get(fr, "per_member"));
    } else {
        r->opt.frames = SM_FRAMES_ELEMENTS_PER_FRAME;
        r->opt.frames_param = (int)json_integer_value(json_object_get(fr, "elements_per_frame"));
    }
    r->opt.mass = !strcmp(json_string_value(json_object_get(an, "mass")), "consistent")
                      ? SM_MASS_CONSISTENT : SM_MASS_LUMPED;
    r->opt.basis = !strcmp(json_string_value(json_object_get(an, "substructure_modes")),
                           "paper") ? SM_BASIS_PAPER : SM_BASIS_AUGMENTED;
    r->opt.modes_per_frame = json_is_integer(mpf) ? (int)json_integer_value(mpf) : 0;
    r->opt.rotary_inertia =
        json_object_get(an, "rotary_inertia") ? SM_ROTARY_TORSION : SM_ROTARY_FULL;
    r->opt.modes = (int)json_integer_value(json_object_get(an, "modes"));
    r->opt.geometric_stiffening = json_is_true(json_object_get(an, "geometric_stiffening"));
    r->opt.coriolis = json_is_true(json_object_get(an, "coriolis"));
    r->opt.mode_shapes = json_is_true(json_object_get(an, "mode_shapes"));
    req_engine_orders(&r->opt, json_object_get(an, "engine_orders"));

    r->speeds = malloc(n * sizeof(double));
    r->rpm = malloc(n * sizeof(double));
    if (!r->speeds || !r->rpm)
        return SM_NOMEM;
    spd_fill(an, r->speeds, r->rpm); /* speeds.c: rpm or omega, numbers, lists, ranges */
    r->n_speeds = (int)n;
    return SM_OK;
}

/*
 * The dense path's bounds (issue 23): a model it takes (frames of more than 40 coordinates, a
 * small model, or more modes than the structured eigen-analysis gives) must have at most
 * max_coordinates, and its estimated time (sm_dense_seconds a speed) must stay within
 * max_solve_seconds.  Returns 0, 1 after adding the reason to errs, or SM_NOMEM.
 */
static int req_check_dense(const codec_request *r, const codec_limits *lim, codec_errors *errs)
{
    int n = r->info.coordinates, speeds = r->n_speeds, many = r->opt.modes > SM_TREE_MAX_MODES;
    double t1 = sm_dense_seconds(n, r->opt.coriolis), total = t1 * speeds;
    char why[200];

    if (r->info.structured)
        return 0;
    if (many)
        snprintf(why, sizeof(why),
                 "%d modes are more than the structured eigen-analysis gives (%d): ask for at "
                 "most %d modes, or ",
                 r->opt.modes, SM_TREE_MAX_MODES, SM_TREE_MAX_MODES);
    else
        snprintf(why, sizeof(why), "frames of more than 40 coordinates or many modes take it: ");
    if (n > lim->max_coordinates)
        return codec_errors_add(errs, many ? "/analysis/modes" : "/structure",
                                "the model would have %d modal coordinates on the dense solvers, "
                                "more than the limit of %d (cost ~n^3: at least %.3g s and about %.0f MB a "
                                "speed); %suse per-element or small frames, fewer elements, or "
                                "\"modes_per_frame\"",
                                n, lim->max_coordinates, t1,
                                (r->opt.coriolis ? 190e-6 : 100e-6) * (double)n * n, why) == SM_NOMEM
                   ? SM_NOMEM
                   : 1;
    if (lim->max_solve_seconds > 0 && total > lim->max_solve_seconds)
        return codec_errors_add(errs, "/analysis/omega",
                                "%d speeds on the dense solvers (%d modal coordinates, at least %.3g s "
                                "a speed) are estimated at %.3g s or more, past the job time limit of "
                                "%g s: ask for fewer speeds (at most %d), or %suse per-element or "
                                "small frames, or fewer elements",
                                speeds, n, t1, total, lim->max_solve_seconds,
                                (int)(lim->max_solve_seconds / (t1 > 0 ? t1 : 1)), why) == SM_NOMEM
                   ? SM_NOMEM
                   : 1;
    return 0;
}

/*
 * The checks that need the model's topology and sizes, without building it
 * (sm_structure_check is linear in the size): a tree rooted at the clamp,
 * then the cost bounds of lim (a 422 that says what to change).  A frame's
 * component-mode problem has 3 DOF per free node, 6 in a spatial model; the
 * coordinates are the core's count for either.  Returns SM_OK,
 * SM_INVALID_INPUT (errs filled) or SM_NOMEM.
 */
static int req_check_model(codec_request *r, const codec_limits *lim, codec_errors *errs)
{
    sm_diag d;
    int st = sm_structure_check(&r->st, &r->opt, &r->info, &d), dofs;
    int node_dof = r->st.spatial ? 6 : 3;

    if (st == SM_INVALID_INPUT)
        return codec_diag_error(r, &d, errs) == SM_NOMEM ? SM_NOMEM : SM_INVALID_INPUT;
    if (st != SM_OK)
        return st;
    /* the tree path's fallback to the dense eigen-analysis is bounded alike (0: no cap) */
    r->opt.max_dense_coordinates = lim->max_coordinates > 0 ? lim->max_coordinates : INT_MAX;
    dofs = node_dof * r->info.max_frame_nodes;
    if (dofs > lim->max_frame_dofs &&
        codec_errors_add(errs, "/frames",
                         "one reference frame would carry %d degrees of freedom (%d FE nodes), "
                         "more than the limit of %d: its component modes cost ~dofs^3; use more "
                         "frames (\"per_element\", or {\"elements_per_frame\": n} with n up to "
                         "%d)",
                         dofs, r->info.max_frame_nodes, lim->max_frame_dofs,
                         lim->max_frame_dofs / node_dof) == SM_NOMEM)
        return SM_NOMEM;
    if ((st = req_check_dense(r, lim, errs)) < 0)
        return st;
    return dofs > lim->max_frame_dofs || st ? SM_INVALID_INPUT : SM_OK;
}

/*
 * Conditioning (issue: a 1e-9 m member gave three identical modes at
 * 2.6e7 rad/s, marked solved): the element stiffnesses scale like
 * EI/l^3, so elements whose lengths differ by more than REQ_MIN_LENGTH_RATIO
 * leave the stiffness matrix too ill-conditioned for double precision, and
 * section values whose element stiffness or mass overflow (E = 1.8e308) or
 * vanish give numbers that mean nothing.  Both are refused with the pointer
 * of the member or section field and the ratio.  Returns SM_OK,
 * SM_INVALID_INPUT or SM_NOMEM.
 */
#define REQ_MIN_LENGTH_RATIO 1e-4   /* shortest / longest element length */
#define REQ_MAX_MAGNITUDE 1e150     /* |element stiffness or mass| in SI units */

static double req_element_length(const codec_request *r, int i)
{
    const sm_member *b = &r->members[i];
    double dx = r->joint_xy[2 * b->to] - r->joint_xy[2 * b->from];
    double dy = r->joint_xy[2 * b->to + 1] - r->joint_xy[2 * b->from + 1];

    if (r->joint_z) /* |(dx, dy, dz)| */
        return hypot(hypot(dx, dy), r->joint_z[b->to] - r->joint_z[b->from]) / b->elements;
    return hypot(dx, dy) / b->elements;
}

/*
 * Planar section c: "E" or "mass_per_length" when its element stiffness
 * (EI/l^3, EA/l) or mass (mu*l) leaves the range, with the message in msg;
 * NULL when in range.
 */
static const char *req_planar_range(const sm_section *c, double lmin, double lmax, char *msg,
                                    size_t n)
{
    double kb = c->E * c->I / (lmin * lmin * lmin), ka = c->E * c->A / lmin;
    double mass = c->mu * lmax;
    const char *field = NULL;

    if (!(kb < REQ_MAX_MAGNITUDE && ka < REQ_MAX_MAGNITUDE) ||
        !(kb > 1 / REQ_MAX_MAGNITUDE && ka > 1 / REQ_MAX_MAGNITUDE))
        field = "E";
    else if (!(mass < REQ_MAX_MAGNITUDE && mass > 1 / REQ_MAX_MAGNITUDE))
        field = "mass_per_length";
    if (field)
        snprintf(msg, n,
                 "with this value the element %s (EI/l^3 = %.3g N/m, EA/l = %.3g N/m, "
                 "mu*l = %.3g kg) leaves the range the numerics carry (%g to %g): check the "
                 "units (SI: Pa, m^2, m^4, kg/m)",
                 field[0] == 'E' ? "stiffness" : "mass", kb, ka, mass, 1 / REQ_MAX_MAGNITUDE,
                 REQ_MAX_MAGNITUDE);
    return field;
}

/*
 * Spatial section c: the core field name of the first element stiffness,
 * mass or rotary inertia out of range, with the message in msg; NULL when
 * all are in range.
 */
static const char *req_spatial_range(const sm_section *c, double lmin, double lmax, char *msg,
                                     size_t n)
{
    double l3 = lmin * lmin * lmin;
    const struct {
        const char *field, *what, *unit;
        double value;
    } q[] = {
        {"EA", "axial stiffness EA/l", "N/m", c->EA / lmin},
        {"EI_flap", "flapwise bending stiffness EI_flap/l^3", "N/m", c->EI_flap / l3},
        {"EI_edge", "edgewise bending stiffness EI_edge/l^3", "N/m", c->EI_edge / l3},
        {"GJ", "torsional stiffness GJ/l", "N m", c->GJ / lmin},
        {"mu", "mass mu*l", "kg", c->mu * lmax},
        {"flap_inertia", "rotary inertia flap_inertia*l", "kg m^2", c->i_flap * lmax},
        {"edge_inertia", "rotary inertia edge_inertia*l", "kg m^2", c->i_edge * lmax},
    };
    size_t k;

    for (k = 0; k < sizeof(q) / sizeof(q[0]); k++) {
        if (q[k].value < REQ_MAX_MAGNITUDE && q[k].value > 1 / REQ_MAX_MAGNITUDE)
            continue;
        snprintf(msg, n,
                 "with this value the element %s = %.3g %s leaves the range the numerics "
                 "carry (%g to %g): check the units (SI: N, N m^2, kg/m, kg m; or Pa, m^2, "
                 "m^4)",
                 q[k].what, q[k].value, q[k].unit, 1 / REQ_MAX_MAGNITUDE, REQ_MAX_MAGNITUDE);
        return q[k].field;
    }
    return NULL;
}

int req_error(const codec_request *r, codec_errors *errs, const char *ptr, const char *fmt,
              ...)
{
    char *moved = r->blade ? tower_form_pointer(r->blade, ptr) : NULL;
    va_list ap;
    int rc;

    if (r->blade && !moved) {
        err_mark_nomem(errs);
        return SM_NOMEM;
    }
    va_start(ap, fmt);
    rc = err_vadd(errs, moved ? moved : ptr, fmt, ap);
    va_end(ap);
    free(moved);
    return rc;
}

/*
 * One conditioning error for section i: at its field that stands for the
 * core field `field` (section.c: E for EA in the material form, with the
 * relation added to the message), or at the section.  SM_OK or SM_NOMEM.
 */
static int req_section_error(const codec_request *r, int i, const char *field, const char *msg,
                             codec_errors *errs)
{
    const json_t *secs = json_object_get(r->structure, "sections");
    const char *relation, *key;
    char *sec = err_ptr_key("/structure/sections", r->section_names[i]), *p = NULL;
    int rc = SM_NOMEM;

    if (!sec)
        return SM_NOMEM;
    key = sec_request_field(json_object_get(secs, r->section_names[i]), field, &relation);
    if (key && !(p = err_ptr_key(sec, key)))
        goto done;
    if (relation)
        rc = req_error(r, errs, p ? p : sec, "%s (%s)", msg, relation);
    else
        rc = req_error(r, errs, p ? p : sec, "%s", msg);
done:
    free(p);
    free(sec);
    return rc;
}

static int req_check_conditioning(const codec_request *r, codec_errors *errs)
{
    int i, bad = 0;
    double lmax = 0, lmin = HUGE_VAL;
    char msg[400], base[48];

    for (i = 0; i < r->st.n_members; i++) {
        double l = req_element_length(r, i);
        lmax = fmax(lmax, l);
        lmin = fmin(lmin, l);
    }
    for (i = 0; i < r->st.n_members; i++) {
        double l = req_element_length(r, i), ratio = l / lmax;
        if (!(ratio >= REQ_MIN_LENGTH_RATIO)) {
            snprintf(base, sizeof(base), "/structure/members/%d", i);
            snprintf(msg, sizeof(msg),
                     "its elements are %.3g m long, %.3g times the longest (%.3g m): below %g "
                     "the stiffness matrix (~ratio^-3) is too ill-conditioned to give "
                     "meaningful frequencies; merge this member into its neighbour or give "
                     "the long members more elements",
                     l, ratio, lmax, REQ_MIN_LENGTH_RATIO);
            if (req_error(r, errs, base, "%s", msg) == SM_NOMEM)
                return SM_NOMEM;
            bad = 1;
        }
    }
    for (i = 0; i < r->st.n_sections; i++) {
        const char *field = r->st.spatial
                                ? req_spatial_range(&r->sections[i], lmin, lmax, msg, sizeof(msg))
                                : req_planar_range(&r->sections[i], lmin, lmax, msg, sizeof(msg));
        if (!field)
            continue;
        if (req_section_error(r, i, field, msg, errs) == SM_NOMEM)
            return SM_NOMEM;
        bad = 1;
    }
    return bad ? SM_INVALID_INPUT : SM_OK;
}

/*
 * analysis.error_estimate (DESIGN.md 9): the refined models (elements x 2 and x 4) must pass
 * the same limits as a request (elements, frame DOF, dense coordinates).  h/4 over a limit:
 * two levels and the theoretical order (the result is still estimated); h/2 over a limit: a
 * 422 at /analysis/error_estimate naming the limit.  Returns SM_OK, SM_INVALID_INPUT or
 * SM_NOMEM.
 */
static int req_check_estimate(codec_request *r, const codec_limits *lim, codec_errors *errs)
{
    sm_estimate_options eo;
    sm_diag d;
    int rc;

    if (!json_is_true(json_object_get(json_object_get(r->canon, "analysis"), "error_estimate")))
        return SM_OK;
    sm_estimate_default_options(&eo);
    eo.max_elements = lim->max_elements;
    eo.max_coordinates = lim->max_coordinates;
    eo.max_frame_dofs = lim->max_frame_dofs;
    memset(&d, 0, sizeof(d));
    rc = sm_estimate_plan(&r->st, &r->opt, &eo, &r->estimate_levels, NULL, &d);
    if (rc == SM_LIMIT || rc == SM_INVALID_INPUT) {
        if (codec_errors_add(errs, "/analysis/error_estimate",
                             "%s: ask for fewer elements, or leave error_estimate out",
                             d.message) == SM_NOMEM)
            return SM_NOMEM;
        return SM_INVALID_INPUT;
    }
    return rc;
}

/*
 * Keep root's "name" (validated: a string) beside the canonical request, and
 * the stored text: canon with the name, dumped as the canonical text.
 * Returns SM_OK or SM_NOMEM.
 */
static int req_keep_name(codec_request *r, const json_t *root)
{
    const json_t *n = json_object_get(root, "name");
    json_t *copy;

    if (!json_is_string(n))
        return SM_OK;
    r->name = strdup(json_string_value(n));
    copy = json_copy(r->canon); /* shallow: shares the values */
    if (!r->name || !copy || json_object_set_new(copy, "name", json_string(r->name))) {
        json_decref(copy);
        return SM_NOMEM;
    }
    r->stored_text = codec_json_dumps_sorted(copy);
    json_decref(copy);
    return r->stored_text ? SM_OK : SM_NOMEM;
}

/*
 * codec_request_from_json; core_check 0 leaves out the core's structure
 * check and the cost bounds (req_parse_codec_only).
 */
static int req_from_json(codec_request **out, const json_t *root, const codec_limits *lim,
                         codec_errors *errs, int core_check)
{
    codec_limits deflim;
    codec_request *r = NULL;
    json_t *canon, *structure = NULL;
    int rc = SM_NOMEM, before = codec_errors_count(errs), nomem;

    *out = NULL;
    if (!lim) {
        codec_default_limits(&deflim);
        lim = &deflim;
    }
    canon = val_request(root, lim, errs, &nomem, &structure);
    if (nomem)
        goto fail;
    if (codec_errors_count(errs) > before || !canon || !structure) {
        rc = SM_INVALID_INPUT;
        goto fail;
    }
    r = calloc(1, sizeof(*r));
    if (!r)
        goto fail;
    r->canon = canon;
    r->structure = structure;
    r->blade = tower_form(r->canon);
    canon = structure = NULL;
    r->canon_text = codec_json_dumps_sorted(r->canon);
    if (!r->canon_text || req_keep_name(r, root))
        goto fail;
    if ((rc = codec_sha256_hex(r->canon_text, strlen(r->canon_text), r->sha)) ||
        (rc = req_build_tables(r)) || (rc = req_build_structure(r)) ||
        (rc = req_build_options(r)) ||
        (core_check && (rc = req_check_model(r, lim, errs))) ||
        (core_check && (rc = req_check_estimate(r, lim, errs))) ||
        (rc = req_check_conditioning(r, errs)))
        goto fail;
    rc = SM_NOMEM;
    if (!(r->warnings = warn_collect(r)))
        goto fail;
    *out = r;
    return SM_OK;
fail:
    json_decref(canon);
    json_decref(structure);
    codec_request_free(r);
    return rc;
}

int codec_request_from_json(codec_request **out, const json_t *root,
                            const codec_limits *lim, codec_errors *errs)
{
    return req_from_json(out, root, lim, errs, 1);
}

/* codec_request_parse; core_check as for req_from_json. */
static int req_parse(codec_request **out, const char *text, size_t len, const codec_limits *lim,
                     codec_errors *errs, int core_check)
{
    codec_limits deflim;
    json_error_t jerr;
    json_t *root;
    int rc;

    *out = NULL;
    if (!lim) {
        codec_default_limits(&deflim);
        lim = &deflim;
    }
    if (len > lim->max_request_bytes) {
        err_mark_too_large(errs);
        if (codec_errors_add(errs, "", "the request is %zu bytes: the limit is %zu bytes",
                             len, lim->max_request_bytes))
            return SM_NOMEM;
        return SM_INVALID_INPUT;
    }
    root = codec_json_loadb(text, len, JSON_REJECT_DUPLICATES, &jerr);
    if (!root) {
        err_mark_malformed(errs);
        for (size_t k = 0; jerr.text[k]; k++) /* jansson's "near '...'" may cut a UTF-8 char */
            if ((unsigned char)jerr.text[k] >= 0x80)
                jerr.text[k] = '?';
        if (json_error_code(&jerr) == json_error_out_of_memory)
            return SM_NOMEM;
        if (codec_errors_add(errs, "", "not valid JSON: %s (line %d, column %d)", jerr.text,
                             jerr.line, jerr.column))
            return SM_NOMEM;
        return SM_INVALID_INPUT;
    }
    rc = req_from_json(out, root, lim, errs, core_check);
    json_decref(root);
    return rc;
}

int codec_request_parse(codec_request **out, const char *text, size_t len,
                        const codec_limits *lim, codec_errors *errs)
{
    return req_parse(out, text, len, lim, errs, 1);
}

int req_parse_codec_only(codec_request **out, const char *text, size_t len,
                         const codec_limits *lim, codec_errors *errs)
{
    return req_parse(out, text, len, lim, errs, 0);
}

void codec_request_free(codec_request *r)
{
    if (!r)
        return;
    free(r->speeds);
    free(r->rpm);
    free(r->stations);
    json_decref(r->structure);
    json_decref(r->warnings);
    free(r->point_masses);
    free(r->supports);
    free(r->members);
    free(r->sections);
    free(r->joint_xy);
    free(r->joint_z);
    free(r->section_names);
    free(r->joint_names);
    free(r->canon_text);
    free(r->name);
    free(r->stored_text);
    json_decref(r->canon);
    free(r);
}

const sm_structure *codec_request_structure(const codec_request *r)
{
    return &r->st;
}

const sm_model_info *codec_request_model_info(const codec_request *r)
{
    return &r->info;
}

const sm_options *codec_request_options(const codec_request *r)
{
    return &r->opt;
}

void codec_request_set_threads(codec_request *r, int threads)
{
    r->opt.threads = threads > 1 ? threads : 1;
}

const double *codec_request_speeds(const codec_request *r, int *n)
{
    *n = r->n_speeds;
    return r->speeds;
}

const double *codec_request_rpm(const codec_request *r, int *n)
{
    *n = r->n_speeds;
    return r->rpm;
}

const json_t *codec_request_input_warnings(const codec_request *r)
{
    return r->warnings;
}

const json_t *req_structure(const codec_request *r)
{
    return r->structure;
}

const char *codec_request_joint_name(const codec_request *r, int j)
{
    if (j < 0 || j >= r->st.n_joints)
        return NULL;
    return r->joint_names[j];
}

const char *req_section_name(const codec_request *r, int s)
{
    if (s < 0 || s >= r->st.n_sections)
        return NULL;
    return r->section_names[s];
}

const json_t *codec_request_canonical(const codec_request *r)
{
    return r->canon;
}

const json_t *codec_request_structure_json(const codec_request *r)
{
    return r->structure;
}

const char *codec_request_canonical_text(const codec_request *r)
{
    return r->canon_text;
}

const char *codec_request_sha256(const codec_request *r)
{
    return r->sha;
}

const char *codec_request_name(const codec_request *r)
{
    return r->name;
}

const char *codec_request_stored_text(const codec_request *r)
{
    return r->stored_text ? r->stored_text : r->canon_text;
}

int codec_request_error_estimate(const codec_request *r)
{
    return r->estimate_levels;
}
