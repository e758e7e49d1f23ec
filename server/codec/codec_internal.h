/*
 * codec_internal.h — what the files of server/codec share and nobody else sees.
 *
 * The codec is one library split by meaning (codec.h lists the public part):
 *
 *   limits.c    the default request limits                           (no helpers)
 *   errors.c    the error list and RFC 6901 pointer building         err_
 *   field.c     reading one request field: check, report, canonical  field_
 *   section.c   a section in its planar or spatial forms             sec_
 *   station.c   section properties along a member (stations)         stn_
 *   blade.c     the "blade" form expanded to a structure             blade_
 *   tower.c     the "tower" form expanded to a structure; which form a
 *               request has and its pointers                          tower_
 *   speeds.c    analysis.omega / analysis.rpm: numbers, lists, ranges spd_
 *   warn.c      unit-slip warnings of a valid request: the thresholds,
 *               the list, single-field checks                        warn_
 *   plausible.c the dimensionless groups of those warnings (wave speed,
 *               radius of gyration, tip speed, centrifugal strain)   plaus_
 *   validate.c  the request document walked field by field           val_
 *   size.c      the size of a request's result, before it is accepted size_
 *   request.c   canonical text, SHA-256, the core's arrays           req_
 *   diag.c      core diagnostics -> pointers, codec_model_new        diag_
 *   result.c    the result document (DESIGN.md section 4)            res_
 *   resout.c    result.c's writer: a tree or straight into text      ro_
 *   csv.c       the result's frequency table as CSV                  csv_
 *   problem.c   RFC 9457 problem documents                           (no helpers)
 *   jsonread.c  a request's text as jansson's tree, read faster      jr_
 *   jobdoc.c    the daemon's job documents, the text buffer (jobdoc.h)  jdoc_
 *   run.c       the pipeline request -> model -> solve -> documents
 *               (run.h; the CLI and the job workers call it)         run_
 *
 * Data flows one way: request.c calls val_request (validate.c, built on
 * field.c, errors.c) and turns the canonical copy into core arrays; diag.c
 * reads a request back through its accessors; result.c, csv.c and problem.c
 * only encode.  This header is not installed and not included outside
 * server/codec.
 */
#ifndef SPINMODAL_CODEC_INTERNAL_H
#define SPINMODAL_CODEC_INTERNAL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

#include <jansson.h>

#include "codec.h"

/* 2*pi, for hertz (M_PI is not C11); result.c and csv.c. */
#define CODEC_TWO_PI 6.283185307179586476925

/* pi/180: twist_deg (request, degrees) -> sm_member.twist (rad); request.c. */
#define CODEC_RAD_PER_DEG 0.017453292519943295769

/* GCC/Clang printf format check of argument `fmt` (1-based) and `args`. */
#if defined(__GNUC__)
#define CODEC_PRINTF(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define CODEC_PRINTF(fmt, args)
#endif

/* ======================================================== errors.c: err_ */

/** malloc'd vprintf; the caller frees it.  NULL when out of memory. */
char *err_vfmt(const char *fmt, va_list ap);

/** malloc'd printf; the caller frees it.  NULL when out of memory. */
char *err_fmt(const char *fmt, ...) CODEC_PRINTF(1, 2);

/**
 * Append an error with a vprintf message; pointer is copied.  Returns SM_OK
 * (also when the error is only counted past CODEC_MAX_ERRORS) or SM_NOMEM.
 */
int err_vadd(codec_errors *e, const char *pointer, const char *fmt, va_list ap);

/** Mark e as describing text that is not JSON (HTTP 400). */
void err_mark_malformed(codec_errors *e);

/** Mark e as describing text over max_request_bytes (HTTP 413). */
void err_mark_too_large(codec_errors *e);

/** Mark e as having lost an error for lack of memory. */
void err_mark_nomem(codec_errors *e);

/**
 * base + "/" + key with RFC 6901 escaping (~ -> ~0, / -> ~1); malloc'd,
 * the caller frees it.  NULL when out of memory.
 */
char *err_ptr_key(const char *base, const char *key);

/** base + "/" + index; malloc'd, the caller frees it.  NULL when out of memory. */
char *err_ptr_idx(const char *base, size_t i);

/* ======================================================== field.c: field_ */

/** Validation state of one request, passed down the walk of validate.c. */
typedef struct val_ctx {
    codec_errors *errs;         /* where errors go (borrowed) */
    const codec_limits *lim;    /* limits (borrowed) */
    long total_elements;        /* FE elements over all valid members */
    int spatial;                /* kind of the sections: 1 spatial, 0 planar, -1 not known
                                   (no usable section); DESIGN.md 7.3 */
    int nomem;                  /* an allocation failed */
    /* stations (station.c, DESIGN.md 8): */
    const json_t *cover;        /* section name -> mask (SM_ST_*) of the quantities that the
                                   stations of every member using it give, or NULL */
    const json_t *in_sections;  /* the request's sections object (borrowed), or NULL */
    json_t *canon_sections;     /* their canonical copies (borrowed), or NULL */
    int blade;                  /* 1 while the structure expanded from "blade" is checked:
                                   a section without E, A, I is spatial (blade.c) */
} val_ctx;

/** A user-supplied name shortened for messages (at most 60 bytes + "..."). */
typedef struct field_short {
    char s[72];
} field_short;

/** name cut to fit field_short on a UTF-8 boundary. */
field_short field_short_name(const char *name);

/** "an object", "a string", ... for "must be X, not Y" messages. */
const char *field_type_name(const json_t *x);

/** Error at ptr (borrowed; NULL records NOMEM), message printf-style. */
void field_error(val_ctx *v, const char *ptr, const char *fmt, ...) CODEC_PRINTF(3, 4);

/** Error at base/key (key escaped), message printf-style. */
void field_error_key(val_ctx *v, const char *base, const char *key, const char *fmt, ...)
    CODEC_PRINTF(4, 5);

/** Set canon[key] = value (stolen; canon NULL drops it); records NOMEM. */
void field_set(val_ctx *v, json_t *canon, const char *key, json_t *value);

/**
 * Every key of obj must be one of allowed (NULL-terminated); an unknown key
 * is an error at base/key, with "did you mean" for a near miss.  what names
 * the object in the message ("member", "analysis", ...).
 */
void field_check_keys(val_ctx *v, const json_t *obj, const char *base,
                      const char *const *allowed, const char *what);
/** field_check_keys, the keys of skip (NULL-terminated) neither allowed nor reported: their
 *  caller has its own message for them (a station's material keys). */
void field_check_keys_but(val_ctx *v, const json_t *obj, const char *base,
                          const char *const *allowed, const char *const *skip, const char *what);

/** Numeric value of an integer or real into *d: 1, or 0 if x is not a number. */
int field_number(const json_t *x, double *d);

/** Range classes for real fields. */
enum field_real_kind { FIELD_FINITE, FIELD_NONNEG, FIELD_POSITIVE };

/**
 * Check a real value x at ptr (borrowed) against kind; unit (" (m)" or "")
 * goes into messages.  Returns 1 and *out (-0 as 0) when valid, else 0
 * after reporting.
 */
int field_check_real(val_ctx *v, const json_t *x, const char *ptr, enum field_real_kind kind,
                     const char *unit, double *out);

/**
 * Required real field obj[key] at base/key: checked, written to canon as a
 * real, and to *out (out may be NULL).  Returns 1 when valid.
 */
int field_real(val_ctx *v, const json_t *obj, const char *key, const char *base,
               json_t *canon, enum field_real_kind kind, const char *unit, double *out);
/** field_real of the value x (NULL: missing) that obj[key] holds. */
int field_real_at(val_ctx *v, const json_t *x, const char *key, const char *base, json_t *canon,
                  enum field_real_kind kind, const char *unit, double *out);

/**
 * Integer field obj[key] in [lo, hi]; when limit_name is set, a value over
 * hi is reported as over that limit.  Absent: an error when required, else
 * canon gets def.  Returns 1 and *out (out may be NULL) when valid.
 */
int field_int(val_ctx *v, const json_t *obj, const char *key, const char *base,
              json_t *canon, int required, long def, long lo, long hi,
              const char *limit_name, long *out);

/**
 * Vector field obj[key]: an array of n (1..3) numbers of kind, checked at
 * base/key/k into out[0..n-1]; shape ("[x, y, z]") and unit go into
 * messages.  Nothing is written to a canonical copy.  Returns 1 when valid.
 */
int field_vector(val_ctx *v, const json_t *obj, const char *key, const char *base, int n,
                 enum field_real_kind kind, const char *shape, const char *unit, double *out);
/** field_vector of the value x (NULL: missing) that obj[key] holds. */
int field_vector_at(val_ctx *v, const json_t *x, const char *key, const char *base, int n,
                    enum field_real_kind kind, const char *shape, const char *unit, double *out);

/** A new JSON array of the n reals x, or NULL when out of memory. */
json_t *field_reals(const double *x, int n);

/** Boolean field obj[key], default def when absent. */
void field_bool(val_ctx *v, const json_t *obj, const char *key, const char *base,
                json_t *canon, int def);

/** String field obj[key], one of choices (NULL-terminated, >= 2), default def. */
void field_enum(val_ctx *v, const json_t *obj, const char *key, const char *base,
                json_t *canon, const char *const *choices, const char *def);

/**
 * Required object field obj[key] (borrowed from obj); NULL, after
 * reporting, when absent or not an object.
 */
const json_t *field_object(val_ctx *v, const json_t *obj, const char *key, const char *base);

/**
 * Required reference obj[key]: a string naming a key of names (a joint,
 * section ...; what says which in messages).  names NULL (its object was
 * invalid) checks only the type.  Returns the name (borrowed) when it was
 * checked against names, else NULL.
 */
const char *field_ref(val_ctx *v, const json_t *obj, const char *key, const char *base,
                      json_t *canon, const json_t *names, const char *what);

/* ====================================================== section.c: sec_ */

/** The form of a section object (DESIGN.md 7.3); spatial iff >= SEC_STIFFNESS. */
typedef enum sec_form {
    SEC_NONE = 0,   /* not an object */
    SEC_PLANAR,     /* E, A, I, mass_per_length */
    SEC_STIFFNESS,  /* EA, EI_flap, EI_edge, GJ, mass_per_length [, flap/edge_inertia] */
    SEC_MATERIAL    /* E, G, A, I_flap, I_edge, J, mass_per_length [, flap/edge_inertia] */
} sec_form;

/**
 * The form of sec (borrowed) from the keys present: any of EA, EI_flap,
 * EI_edge, GJ is the stiffness form; else any of G, I_flap, I_edge, J the
 * material form; else planar (whatever else is missing or wrong).
 */
sec_form sec_classify(const json_t *sec);

/**
 * sec_classify, except that with spatial set a section without E, A and I
 * (a partial section whose stiffnesses the stations give, DESIGN.md 8) is
 * SEC_STIFFNESS.
 */
sec_form sec_classify_as(const json_t *sec, int spatial);

/** "planar (E, A, I, mass_per_length)", ... for messages; never NULL. */
const char *sec_form_name(sec_form f);

/**
 * Check the section object sec (borrowed) at ptr in its form f (from
 * sec_classify, not SEC_NONE): unknown keys, fields of another form, the
 * required fields (> 0) and, spatial, the inertias (given > 0, or their
 * defaults written out), the offsets (written only when not zero).  A
 * stiffness-form field whose SM_ST_* bit is in cover may be absent (the
 * stations of every member using the section give it).  Returns its
 * canonical copy (new reference), or
 * NULL after reporting a field of another form or running out of memory
 * (v->nomem).  The copy is complete only when no error was added.
 */
json_t *sec_validate(val_ctx *v, const json_t *sec, const char *ptr, sec_form f,
                     unsigned cover);

/**
 * The core's section from a validated canonical section (borrowed): planar
 * E, A, I, mu; spatial mu and the spatial block (material form: EA = E*A,
 * EI_flap = E*I_flap, EI_edge = E*I_edge, GJ = G*J, I_p/A = (I_flap +
 * I_edge)/A; stiffness form: I_p/A = (flap_inertia + edge_inertia)/mu).
 * and the offsets; spatial: the request is spatial (sec_classify_as).
 * Every other field of *out is zero.
 */
void sec_fill(const json_t *canon, int spatial, sm_section *out);

/**
 * The request field of the canonical section canon (borrowed) behind a core
 * field name ("EA", "mu", "ip_over_a" ...): the same name when the section
 * has it, "E" for EA in the material form (I_flap for EI_flap, I_edge for
 * EI_edge, J for GJ), or NULL when no one field stands for it (the error
 * then points at the section).  *relation receives NULL or a static text
 * such as "EA = E*A" that the message should carry.
 */
const char *sec_request_field(const json_t *canon, const char *core_field,
                              const char **relation);

/* ====================================================== station.c: stn_ */

/* Most stations on one member (DESIGN.md 8). */
#define CODEC_MAX_STATIONS 1000

/** Mask (SM_ST_*) of the quantities any station of the array stations (borrowed) gives. */
unsigned stn_keys_mask(const json_t *stations);

/** The SM_ST_* bit of a station key ("EA", "mass_per_length" ...), 0 for another name. */
unsigned stn_section_bit(const char *key);

/**
 * For the input members array (borrowed, unchecked): a new object mapping
 * each section name to the mask of the quantities that the stations of
 * every member using it give (0 when one member has none).  NULL when out
 * of memory.
 */
json_t *stn_cover(const json_t *members);

/**
 * Check mem's "stations" (present) at p (the member's pointer) and write
 * their canonical copy, with the per-station default mass moments, into c
 * (the member's canonical copy).  Reads v->in_sections, v->canon_sections.
 */
void stn_validate(val_ctx *v, const json_t *mem, const char *p, json_t *c);

/**
 * The core's stations from a canonical stations array (borrowed): out gets
 * json_array_size(stations) entries (angles in rad).  Returns the mask.
 */
unsigned stn_fill(const json_t *stations, sm_station *out);

/* ===================================================== validate.c: val_ */

/**
 * Validate root (borrowed) against DESIGN.md section 3, appending every
 * error to errs.  Returns the canonical request (new reference; defaults
 * applied), or NULL when root is not an object or memory ran out, and in
 * *structure the canonical structure to build the model from (new
 * reference or NULL: the request's, or its blade's expansion).  The
 * request is valid only if no error was added.  *nomem is set to 1 when an
 * allocation failed (the errors may then be incomplete), else 0.
 */
json_t *val_request(const json_t *root, const codec_limits *lim, codec_errors *errs,
                    int *nomem, json_t **structure);

/**
 * The "structure" of root (borrowed) checked into canon["structure"] (the
 * walk of validate.c; blade.c checks its expanded structure with it).
 */
void val_structure(val_ctx *v, const json_t *root, json_t *canon);

/* What to add for spatial sections, in messages (validate.c, validate_analysis.c). */
#define VAL_SPATIAL_SECTIONS                                                                \
    "give every section EA, EI_flap, EI_edge, GJ and mass_per_length (or E, G, A, I_flap, " \
    "I_edge, J and mass_per_length)"

/** root's "frames" (the scheme, default "per_element") into canon (validate_analysis.c). */
void val_frames(val_ctx *v, const json_t *root, json_t *canon);

/** root's "analysis" (speeds, modes, options and their defaults) into canon (validate_analysis.c). */
void val_analysis(val_ctx *v, const json_t *root, json_t *canon);

/* ===================================================== supports.c: sup_ */

/**
 * structure.springs (optional) of the input structure st (borrowed) checked into cst["springs"]:
 * joint (one of joints), stiffness and added_mass (6x6 rows or {translational, rotational}),
 * axes ("hub" or "member:ID").  Call after the members (v->spatial known).
 */
void sup_springs(val_ctx *v, const json_t *st, const json_t *joints, json_t *cst);

/**
 * mem's "foundation" (present) at p/foundation: one stretch object or an array of them, checked
 * into c["foundation"]; len the member's length (0 when its joints are not known).
 */
void sup_foundation(val_ctx *v, const json_t *mem, const char *p, json_t *c, double len);

/** The joint table sup_build reads (request.c's sorted names and coordinates, borrowed). */
typedef struct sup_joints {
    const char **names; /* n, sorted */
    int n;
    const double *xy; /* 2n, hub frame, m */
    const double *z;  /* n or NULL */
} sup_joints;

/**
 * The core's supports of a valid canonical structure st (borrowed): the springs in order, then
 * each member's foundation stretches; *out malloc'd (NULL when none), *n its length.  SM_OK or
 * SM_NOMEM.
 */
int sup_build(const json_t *st, const sup_joints *J, sm_support **out, int *n);

/**
 * The pointer of core support index (sup_build's order) and core field ("K", "k_per_length"
 * ...) in the structure st (borrowed); malloc'd, NULL when out of memory.
 */
char *sup_pointer(const json_t *st, int index, const char *field);

/**
 * The 6x6 matrix obj[key] (rows or {translational, rotational}) at p/key checked into a
 * (column-major) and c[key] (canonical): symmetric, its diagonal >= 0 unless any_sign (a
 * hydrostatic stiffness); unit goes into messages.  1 when valid.
 */
int sup_matrix6(val_ctx *v, const json_t *obj, const char *p, const char *key, const char *unit,
                int any_sign, json_t *c, double a[36]);

/** Index of name among the n sorted joint names, -1 when absent. */
int sup_joint(const char **names, int n, const char *name);

/** A canonical 6x6 (rows or diagonal form; absent: zero) into a, column-major. */
void sup_read(const json_t *x, double a[36]);

/** The position of joint j of J (hub frame, m). */
void sup_pos(const sup_joints *J, int j, double p[3]);

/* ===================================================== platform.c: plat_ */

/**
 * The clamp of the input structure st (borrowed) checked into cst["clamp"] (and
 * cst["platform"]): a joint's name (rigid), {joint, stiffness, mass} (an elastic clamp) or null
 * with a "platform" {joint, mass, added_mass, hydrostatic, mooring, reference, mass_reference}
 * (floating).  joints the input joints (NULL when invalid).
 */
void plat_clamp(val_ctx *v, const json_t *st, const json_t *joints, json_t *cst);

/** The clamp joint's name of a canonical structure st: the clamp's, or its platform's. */
const char *plat_clamp_name(const json_t *st);

/** 1 when the canonical structure st has a free base (elastic clamp or platform), else 0. */
int plat_base_free(const json_t *st);
/** sm_structure.base_held of the canonical st: its platform's "held" directions (bits x, y, z,
 *  rx, ry, rz), 0 without a floating platform. */
unsigned plat_base_held(const json_t *st);

/**
 * The free base's point support of the canonical st (plat_base_free 1) into s: at the clamp
 * joint, K = stiffness (hydrostatic + mooring), M = mass (mass + added_mass), each carried
 * rigidly from its reference point to the joint (K' = T^T K T).
 */
void plat_fill(const json_t *st, const sup_joints *J, sm_support *s);

/** The pointer of the free base's support field ("K", "M", other) in st; malloc'd. */
char *plat_pointer(const json_t *st, const char *field);

/** The pointer of a core SM_ITEM_CLAMP diagnostic in st (the clamp or the platform); malloc'd. */
char *plat_clamp_pointer(const json_t *st);

/**
 * The tower form's "platform" of tw (borrowed; optional): {mass, added_mass, hydrostatic,
 * mooring (6x6 in tower axes fa, ss, up), reference_height, mass_height (m, like height; default
 * base_height)} checked at /tower/platform into ct, and written into the expanded structure st
 * as "clamp": null and a "platform" at joint "base" in hub axes (T: tower -> hub, row i = hub axis i).
 */
void plat_tower(val_ctx *v, const json_t *tw, json_t *ct, json_t *st, const double T[3][3],
                double base_height);

/* ========================================================= size.c: size_ */

/**
 * The size of the result of a request checked so far (canon: its canonical request,
 * structure: the canonical structure it is built from; both borrowed): the estimated bytes
 * of the result document against max_result_bytes (0: no limit) and the mode-shape numbers
 * against max_shape_values, each over its limit one error naming what to reduce.
 */
void size_check(val_ctx *v, const json_t *canon, const json_t *structure);

/* ======================================================== blade.c: blade_ */

/**
 * Check root's "blade" (DESIGN.md 8), write its canonical copy (defaults
 * written out) into canon["blade"] and return the canonical structure it
 * stands for (new reference; the pitch added to the stations' twists), or
 * NULL.  Errors point into /blade.
 */
json_t *blade_validate(val_ctx *v, const json_t *root, json_t *canon);
/**
 * A point mass {mass [, offset, inertia, products]} of a form at ptr (the blade's tip mass, the
 * tower's top mass; what names it in messages, shapes[3] the vectors' component names) checked
 * and written as parent[key]; t = mass, offset, inertia, products in the form's axes.  1 when
 * valid.
 */
int blade_point_mass(val_ctx *v, const json_t *tm, json_t *parent, const char *key, const char *ptr,
                     const char *what, const char *const shapes[3], double t[10]);
/** out = R x, R row-major 3x3: a vector in a form's axes to hub axes. */
void blade_rotate(const double *R, const double x[3], double out[3]);
/** A point mass's tensor (diag, prod in a form's axes) to hub axes: R I R^T as hd, hp. */
void blade_tensor(const double *R, const double diag[3], const double prod[3], double hd[3],
                  double hp[3]);

/**
 * The pointer p of the structure a blade was expanded to, moved into
 * /blade ("/structure/members/0/stations/2/EA" -> "/blade/stations/2/EA").
 * malloc'd; NULL when out of memory.
 */
char *blade_pointer(const char *p);

/* ======================================================== tower.c: tower_ */

/** The form of a request (tower_form): "structure", "blade" or "tower". */
enum { CODEC_FORM_STRUCTURE = 0, CODEC_FORM_BLADE = 1, CODEC_FORM_TOWER = 2 };

/**
 * Check root's "tower" (DESIGN.md 8.5), write its canonical copy (defaults
 * written out) into canon["tower"] and return the canonical structure it
 * stands for (new reference), or NULL.  Errors point into /tower.
 */
json_t *tower_validate(val_ctx *v, const json_t *root, json_t *canon);

/**
 * A structure analysed at rest only (a tower, gravity, a free base: validate.c): an error at
 * /analysis/omega (or rpm), "why: its speed must be 0 (speed i is x unit)tail", when a speed of
 * the canonical request canon (borrowed, analysis checked) is not 0.
 */
void tower_check_speeds(val_ctx *v, const json_t *canon, const char *why, const char *tail);

/** The pointer p of a tower's expanded structure moved into /tower; malloc'd, NULL = NOMEM. */
char *tower_pointer(const char *p);
/** sm_mode_label of a mode of r's result; a tower form's flap and edge modes are named by the
 *  direction they move: "1st fore-aft", "2nd side-side" (DESIGN.md 8.5).  Returns buf. */
char *codec_mode_label(const codec_request *r, int kind, int ordinal, char *buf, size_t size);

/** CODEC_FORM_* of a canonical (or input) request object (borrowed). */
int tower_form(const json_t *canon);

/**
 * p moved into the form's object (blade_pointer, tower_pointer) or copied for the structure
 * form; malloc'd, NULL when out of memory.
 */
char *tower_form_pointer(int form, const char *p);

/* ====================================================== speeds.c: spd_ */

/** analysis.omega or analysis.rpm (exactly one) of an (borrowed) checked into can. */
void spd_validate(val_ctx *v, const json_t *an, json_t *can);

/** Number of speeds of a validated canonical analysis object (borrowed). */
size_t spd_count(const json_t *an);

/**
 * The speeds of a validated canonical analysis (borrowed) in request order:
 * omega (rad/s) and rpm (rev/min), spd_count entries each.
 */
void spd_fill(const json_t *an, double *omega, double *rpm);

/* ======================================================== warn.c: warn_ */

/** The plausibility checks (DESIGN.md 8.4), one row of warn_rules each. */
typedef enum warn_rule_id {
    WARN_MODULUS,     /* E, G (Pa) */
    WARN_DENSITY,     /* mass_per_length / A, when A is given (kg/m^3) */
    WARN_LINE_MASS,   /* mass_per_length without A (kg/m) */
    WARN_SECOND,      /* I, I_flap, I_edge, J over A^2 */
    WARN_STIFF_FLOOR, /* EI, GJ on a member longer than 1 m (N m^2) */
    WARN_WAVE_SPEED,  /* sqrt(EA / mu) of a member, span means (m/s) */
    WARN_GYRATION,    /* sqrt(EI / EA) over the member's length, each bending direction */
    WARN_TIP_SPEED,   /* Omega R_max (m/s) */
    WARN_STRAIN,      /* mu Omega^2 R^2 / EA of a member, R its outer end's radius */
    WARN_RADIUS,      /* R_max (m): the largest distance of a joint from the spin axis */
    WARN_ROUND,       /* lo: the step (rad/s) of an omega that reads as a round rpm number */
    WARN_N_RULES
} warn_rule_id;

/** One threshold row: a check warns outside [lo, hi] (NAN: no bound). */
typedef struct warn_rule {
    const char *name;   /* the checked quantity, for DESIGN.md and tests */
    double lo, hi;      /* the plausible range, in unit */
    double typical;     /* where it usually lies: picks the slip (plaus_slip) */
    const char *unit;   /* "" for a ratio */
} warn_rule;

/** The thresholds, indexed by warn_rule_id (warn.c). */
extern const warn_rule warn_rules[WARN_N_RULES];

/** x for a message: "1e6" for a power of ten from 1e4 up or 1e-3 down, else %g; in buf. */
const char *warn_g(char buf[32], double x);

/** A list of warnings being built (warn_collect, plausible.c). */
typedef struct warn_list {
    json_t *arr;   /* [{"pointer", "message"}] */
    json_t *seen;  /* pointer -> true: one warning per pointer, the first */
    int blade;     /* CODEC_FORM_*: pointers into the expanded structure move into /blade
                      (1) or /tower (2) */
    int nomem;     /* an allocation failed */
} warn_list;

/**
 * Append a warning at ptr (borrowed; a pointer into the canonical structure
 * or into /analysis), message vprintf-style, unless ptr already has one.
 * NULL ptr or no memory sets w->nomem.
 */
void warn_vadd(warn_list *w, const char *ptr, const char *fmt, va_list ap);

/** warn_vadd, printf-style. */
void warn_add(warn_list *w, const char *ptr, const char *fmt, ...) CODEC_PRINTF(3, 4);

/**
 * Unit-slip warnings (DESIGN.md 8.1, 8.4) of a valid request r (its
 * canonical structure and the core's arrays built from it): a new array
 * [{"pointer", "message"}], empty when none; pointers into /blade for the
 * blade form.  NULL when out of memory.
 */
json_t *warn_collect(const codec_request *r);

/* ================================================= plausible.c: plaus_ */

/**
 * The dimensionless checks of r into w (DESIGN.md 8.4): per member the
 * axial wave speed and the radius of gyration in each bending direction
 * (span means of the sections and stations), then the tip speed and per
 * member the centrifugal strain.  They use the core's arrays, so they hold
 * for every kind of structure and form of section.
 */
void plaus_check(warn_list *w, const codec_request *r);

/* ====================================================== request.c: req_ */

/**
 * Name of section s (sections are indexed in sorted name order), borrowed
 * from r; NULL if out of range.
 */
const char *req_section_name(const codec_request *r, int s);

/**
 * The canonical structure the model of r is built from (borrowed): the
 * request's "structure", or the one its "blade" stands for.
 */
const json_t *req_structure(const codec_request *r);

/**
 * Append an error about r at ptr (a pointer into the structure: moved into
 * /blade for the blade form), message printf-style.  SM_OK or SM_NOMEM.
 */
int req_error(const codec_request *r, codec_errors *errs, const char *ptr, const char *fmt,
              ...) CODEC_PRINTF(4, 5);

/**
 * codec_request_parse without the core's structure check (topology, sizes)
 * and the cost bounds that need its sizes: what the codec alone makes of a
 * request, for tests of the codec that must not depend on the core (a
 * spatial request before the core can check spatial structures).  The
 * model sizes (codec_request_model_info) are then all zero.  Never used
 * to accept a request for solving.
 */
int req_parse_codec_only(codec_request **out, const char *text, size_t len,
                         const codec_limits *lim, codec_errors *errs);

/*
 * Close an open_memstream f (buffer *buf, size *n) and hand its text to *out (NUL-terminated,
 * malloc'd) and *len (may be NULL).  SM_OK, or SM_NOMEM (a write or the close failed; the
 * buffer is freed).  csv.c; used by every text writer of the codec.
 */
int codec_memstream_done(FILE *f, char **buf, size_t *n, char **out, size_t *len);

/* ------------------------------------------------------------ sha256.c */

/** codec_sha256_hex with accel 0: the portable rounds even where the CPU has the SHA
 *  extensions (the unit test compares the two). */
int codec_sha256_hex_with(const void *data, size_t len, char hex[65], int accel);
/** 1 when codec_sha256_hex uses the CPU's SHA extensions. */
int codec_sha256_accelerated(void);

/* ------------------------------------------------------------ numtext.c */

/** Room for codec_numtext's text with its NUL. */
#define CODEC_NUMTEXT_MAX 32
/** x as printf's "%.17g" writes it (json 0), or as jansson writes a real at
 *  JSON_REAL_PRECISION(17) (json 1: ".0" after a number without point or exponent, no '+' nor
 *  leading zeros in the exponent), the same bytes, ~10 times faster.  buf: CODEC_NUMTEXT_MAX
 *  chars.  Returns the length. */
int codec_numtext(char *buf, double x, int json);
/** 1 when codec_numtext writes x itself, 0 when it asks snprintf (a near-tie, a subnormal, a
 *  value that is not finite, or no 128-bit integers): numtext_test checks how seldom. */
int codec_numtext_direct(double x);

/** The JSON string s (n bytes) appended to t as codec_json_dump writes it (jansson's escapes);
 *  0, or -1 (out of memory, s not UTF-8). */
int codec_text_json_string(codec_text *t, const char *s, size_t n);
/** The real x appended to t as codec_json_dump writes a json_real (null when not finite, as
 *  result.c writes such a number). */
void codec_text_json_real(codec_text *t, double x);

/** json_dumps(x, JSON_SORT_KEYS | JSON_COMPACT | JSON_REAL_PRECISION(17)): the same bytes,
 *  written by jsontext.c (keys sorted by strcmp as jansson does).  x: an object or an array.
 *  Returns the malloc'd text, or NULL (out of memory, a string not valid UTF-8). */
char *codec_json_dumps_sorted(const json_t *x);

/* ======================================================= resout.c: ro_ */

/** Where result.c writes (resout.c): a tree (t NULL: the containers open, c[0] the outermost,
 *  which the caller owns after its ro_close) or text t (compact, the bytes codec_json_dump gives
 *  of that tree).  Zero-initialise it; set t for text. */
#define RES_DEPTH 8
typedef struct res_out {
    codec_text *t;         /* text, or NULL: a tree */
    json_t *c[RES_DEPTH];  /* tree: the open containers */
    int count[RES_DEPTH];  /* text: members written in each open container */
    char close[RES_DEPTH]; /* text: '}' or ']' */
    int depth;
    int nomem; /* a tree's allocation failed (text: t->nomem) */
} res_out;

/** Open an object (object 1) or an array as member key of the innermost container (key NULL in
 *  an array or outermost). */
void ro_open(res_out *o, const char *key, int object);
/** Close the innermost container. */
void ro_close(res_out *o);
/** Members of the innermost container (key NULL in an array): a real (null when not finite),
 *  an integer, null, a boolean, a string; an array of n reals; an array of n rows of dof reals. */
void ro_real(res_out *o, const char *key, double x);
void ro_int(res_out *o, const char *key, long long v);
void ro_null(res_out *o, const char *key);
void ro_bool(res_out *o, const char *key, int b);
void ro_string(res_out *o, const char *key, const char *s);
void ro_reals(res_out *o, const char *key, const double *v, int n);
void ro_rows(res_out *o, const char *key, const double *v, int n, int dof);

/* ====================================================== jsonread.c: jr_ */

/** The tree json_loadb(text, len, flags, NULL) gives, read by jsonread.c's fast reader; NULL
 *  where that reader gives up (anything but plain ASCII JSON, flags other than
 *  JSON_REJECT_DUPLICATES, out of memory) or where jansson would refuse the text. */
json_t *codec_json_fast(const char *text, size_t len, size_t flags);

/** The real of the number token s (n bytes, JSON's grammar) as strtod gives it, without strtod:
 *  1 when the token has at most 19 significant digits, their integer w <= 2^53 and the decimal
 *  exponent p in -22..22 (w and 10^|p| exact doubles, so w * 10^p or w / 10^-p is rounded once,
 *  to strtod's correctly rounded value; Clinger 1990), or w = 0; else 0 (the caller asks
 *  strtod).  jsonread_test checks its bits against strtod's. */
int codec_json_real_fast(const char *s, size_t n, double *out);

/** json_loadb(text, len, flags, error): codec_json_fast's tree, or jansson's own answer (tree,
 *  or NULL with its error) where the fast reader gives up. */
json_t *codec_json_loadb(const char *text, size_t len, size_t flags, json_error_t *error);

#endif /* SPINMODAL_CODEC_INTERNAL_H */
