/*
 * import_internal.h — what the importers share (private to
 * server/codec/import*.c; the public interface is import.h).
 *
 *   import.c            lines, tokens, numbers, diagnostics, the station
 *                       table and the request document in the blade form;
 *   import_formats.c    the table of formats (name, file roles, parser)
 *                       that the CLI and the HTTP route look up;
 *   import_bmodes.c     BModes .bmi + section-properties file;
 *   import_elastodyn.c  OpenFAST ElastoDyn blade file;
 *   import_csv.c        CSV with a header of station keys.
 */
#ifndef SPINMODAL_IMPORT_INTERNAL_H
#define SPINMODAL_IMPORT_INTERNAL_H

#include "import.h"

/* ------------------------------------------------------------ lines */

/** Reads a file line by line (LF, CRLF or CR ends a line). */
typedef struct imp_reader {
    const import_file *f;
    size_t pos;    /* byte offset of the next line */
    int line;      /* number of the line last returned, 0 before the first */
    const char *s; /* the line last returned, without its end */
    size_t n;      /* its length */
} imp_reader;

/** Start reading f. */
void imp_reader_init(imp_reader *r, const import_file *f);

/** Next line into r->s, r->n: 1, or 0 at the end of the file. */
int imp_next(imp_reader *r);

/** Next line that is not blank (spaces, tabs only): 1, or 0 at the end. */
int imp_next_nonblank(imp_reader *r);

/** 1 when s[0..n) holds only spaces and tabs. */
int imp_blank(const char *s, size_t n);

/* ----------------------------------------------------------- tokens */

#define IMP_MAX_TOKENS 64

/** A token: s[0..n), quotes removed. */
typedef struct imp_tok {
    const char *s;
    size_t n;
} imp_tok;

/**
 * Split s[0..n) at whitespace and at any character of seps (may be ""),
 * Fortran list-directed style: runs of separators are one, a token may be
 * quoted with ' or ".  Stores at most max tokens in t; returns how many
 * there are (more than max when cut).
 */
int imp_split(const char *s, size_t n, const char *seps, imp_tok *t, int max);

/** Copy a token into dst[cap] (truncated, ASCII: control and other bytes as '?'). */
void imp_tok_copy(char *dst, size_t cap, const imp_tok *t);

#define IMP_EXCERPT 40                 /* characters of file text an error may quote */
#define IMP_EXCERPT_SIZE (IMP_EXCERPT + 4) /* a buffer for imp_excerpt: "..." and the NUL */

/**
 * A short, escaped excerpt of t for a message into dst[cap] (cap >= IMP_EXCERPT_SIZE): at most
 * IMP_EXCERPT characters, bytes outside printable ASCII as \xNN, '"' and '\\' escaped, "..."
 * when cut.  Errors quote file text only through this (a file may hold anything: a section
 * file named by a .bmi may be any file the CLI can read).
 */
void imp_excerpt(char *dst, size_t cap, const imp_tok *t);

/** A JSON string of s made ASCII as imp_tok_copy does (at most 255 bytes); NULL = NOMEM. */
json_t *imp_string(const char *s);

/* ---------------------------------------------------------- numbers */

/** A number (Fortran D exponents accepted), finite: 0, or -1 when t is not one. */
int imp_number(const imp_tok *t, double *v);

/** v rounded to 15 significant digits (what import_dumps prints, exactly). */
double imp_round(double v);

/** The largest magnitude a request carries: larger ones round to infinity at 15 digits. */
#define IMP_MAX_ABS_TEXT "1.79769313486231e+308"

/** 1 when v is finite and stays finite rounded to 15 significant digits (imp_round). */
int imp_finite(double v);

/* ------------------------------------------------------- diagnostics */

/** Fill d with "file:line: field: message"; returns SM_INVALID_INPUT. */
int imp_fail(import_diag *d, const char *file, int line, const char *field, const char *fmt,
             ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/** Kinds of values, for imp_check. */
enum { IMP_ANY = 0, IMP_POSITIVE, IMP_NONNEG };

/** Read token t as a number of the given kind; SM_OK or SM_INVALID_INPUT (d). */
int imp_value(import_diag *d, const char *file, int line, const char *field, const imp_tok *t,
              int kind, double *v);

/** Check v (after a multiplier) against kind and imp_finite; SM_OK or SM_INVALID_INPUT (d). */
int imp_check(import_diag *d, const char *file, int line, const char *field, int kind,
              double v);

/**
 * Add {"pointer", "message"} to the warnings array: pointer (RFC 6901) names the field of the
 * request the warning is about, as the result's input_warnings do; the message is printf style.
 * -1 when out of memory.
 */
int imp_warn(json_t *warnings, const char *pointer, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/**
 * Set doc's "warnings" to the messages of its "input_warnings", as strings: the shape of the
 * import document before 0.8 (kept for older clients; DAEMON.md).  -1 when out of memory.
 */
int imp_legacy_warnings(json_t *doc);

/* ---------------------------------------------------- station table */

/** Station quantities, in the order of the keys of a station (spec 12 section 1). */
typedef enum imp_key {
    IK_S = 0,  /* span fraction */
    IK_MU,     /* mass_per_length, kg/m */
    IK_EA,     /* N */
    IK_EI_FLAP,/* N m^2 */
    IK_EI_EDGE,
    IK_GJ,
    IK_I_FLAP, /* flap_inertia, kg m */
    IK_I_EDGE,
    IK_TWIST,  /* twist_deg */
    IK_ITWIST, /* inertia_twist_deg */
    IK_CG_E,   /* cg_offset [edge, flap], m */
    IK_CG_F,
    IK_SC_E,   /* shear_center_offset */
    IK_SC_F,
    IK_TC_E,   /* tension_center_offset */
    IK_TC_F,
    IK_N
} imp_key;

/** The kind (IMP_*) of the values of key k. */
int imp_key_kind(imp_key k);

/** One station: values of the keys in the table's mask, and its line. */
typedef struct imp_station {
    double v[IK_N];
    int line;
} imp_station;

/** Stations in file order. */
typedef struct imp_table {
    imp_station *st; /* n stations, cap allocated */
    int n, cap;
    unsigned mask;   /* bit k: key k is given (at every station) */
} imp_table;

/** Append a zeroed station; NULL when out of memory. */
imp_station *imp_table_add(imp_table *t);

/** Free the stations. */
void imp_table_clear(imp_table *t);

/**
 * Check the span fractions: at least 2 stations, first exactly 0, last
 * exactly 1, strictly increasing (after rounding to what is printed).
 * field names the s column in messages.  SM_OK or SM_INVALID_INPUT.
 */
int imp_table_order(import_diag *d, const char *file, const imp_table *t, const char *field);

/** max over the stations of key k (0 when none). */
double imp_table_max(const imp_table *t, imp_key k);

/* ----------------------------------------------------- the document */

/** Everything of the blade form other than the stations. */
typedef struct imp_blade {
    double length;       /* m, > 0 */
    double hub_radius;   /* m, >= 0 */
    double precone_deg;
    double pitch_deg;
    int has_tip;         /* tip_mass given */
    double tip_mass;     /* kg */
    double tip_offset[3];   /* [span, edge, flap] m */
    double tip_inertia[3];  /* [I11 torsion, I22 flap, I33 edge] kg m^2 */
    double tip_products[3]; /* [I12, I23, I31] kg m^2 */
    double rpm;          /* rev/min */
    const json_t *rpm_speeds; /* NULL, or analysis.rpm instead of [rpm] (import_options) */
    int modes;           /* analysis.modes */
    int length_line;     /* the line that gives the length (0 = an option) */
    const char *length_field; /* its field ("r", "radius", "tip_radius"), for messages */
} imp_blade;

/** Zero everything, modes IMPORT_DEFAULT_MODES. */
void imp_blade_init(imp_blade *b);

/**
 * When the table gives no EA or no GJ, the blade section gets assumed
 * values (stiff: the models these files come from are rigid in extension
 * and torsion) and warnings says so.  *out: the section object (new
 * reference, possibly empty).  An assumed value that is not a number the
 * request carries (overflow, underflow) is refused naming the line of the
 * largest EI (ei_names: the file's names of EI_flap and EI_edge) or the
 * line that gives the length (b->length_line).  SM_OK, SM_INVALID_INPUT
 * (d), SM_NOMEM.
 */
int imp_assumed_section(json_t **out, import_diag *d, const char *file, const imp_table *t,
                        const imp_blade *b, json_t *warnings, const char *format,
                        const char *const *ei_names);

/**
 * The blade length made from the radii: finite, at least IMPORT_MIN_LENGTH and
 * IMPORT_MIN_LENGTH_RATIO x the tip radius (hub + length).  SM_OK or
 * SM_INVALID_INPUT (d, at line and field).
 */
int imp_length(import_diag *d, const char *file, int line, const char *field, double hub,
               double length);

/** An option (NAN = not given): >= 0 and imp_finite.  SM_OK or SM_INVALID_INPUT (d, line 0). */
int imp_option(import_diag *d, const char *file, const char *field, double v);

/**
 * Apply the user's options common to ElastoDyn and CSV: length from
 * tip_radius - hub_radius (tip_radius required unless length_known), rpm.
 * SM_OK or SM_INVALID_INPUT (d).
 */
int imp_options_apply(import_diag *d, const char *file, const import_options *o,
                      int length_known, imp_blade *b, json_t *warnings);

/**
 * The import document {"request", "warnings", "input_warnings", "source"}: takes section
 * (may be NULL), warnings and source (stolen, even on failure).  NULL when
 * out of memory.
 */
json_t *imp_document(const imp_blade *b, const imp_table *t, json_t *section,
                     json_t *warnings, json_t *source);

/**
 * imp_document with the section imp_assumed_section makes for a file without EA/GJ (ElastoDyn,
 * CSV; format names it in the warning, ei_names the file's EI columns); takes warnings and
 * source like imp_document.  *out: the document.  SM_OK, SM_INVALID_INPUT (d), SM_NOMEM.
 */
int imp_document_assumed(json_t **out, import_diag *d, const char *file, const imp_blade *b,
                         const imp_table *t, const char *format, const char *const *ei_names,
                         json_t *warnings, json_t *source);

/**
 * The text encoding of f: *body = the text to read, f without a UTF-8 byte-order mark
 * (body may be f); UTF-16 (a byte-order mark FF FE or FE FF, or any NUL byte) is refused,
 * saying to save the file as UTF-8.  SM_OK or SM_INVALID_INPUT (d).
 */
int imp_encoding(import_diag *d, const import_file *f, import_file *body);

/* ---- import_bmodes_mesh.c: BModes' own model (import option bmodes_mesh) ---- */
/**
 * Replace the blade or tower form of the import document doc by BModes' own model: the
 * stations sampled at the midpoints of el_loc's elements (BModes' mesh), k FE elements each,
 * written as a structure; file names the .bmi in refusals.  SM_OK, SM_NOMEM, SM_INVALID_INPUT
 * (d) when the result is not a valid request; a warning may be added to warn.
 */
int bm_own_mesh(json_t *doc, const json_t *el_loc, int k, const char *file, import_diag *d,
                json_t *warn);
/** The warnings' pointers of doc follow the structure that replaced its form (tower: 1 for
 *  /tower, 0 for /blade).  0, -1 (memory). */
int bm_mesh_warnings(json_t *doc, int tower);

#endif /* SPINMODAL_IMPORT_INTERNAL_H */
