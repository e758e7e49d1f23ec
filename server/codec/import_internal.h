/*
 * import_internal.h — what the importers share (private to
 * server/codec/import*.c; the public interface is import.h).
 *
 *   import.c            lines, tokens, numbers, diagnostics, the station
 *                       table and the request document in the blade form;
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

/** A JSON string of s made ASCII as imp_tok_copy does (at most 255 bytes); NULL = NOMEM. */
json_t *imp_string(const char *s);

/* ---------------------------------------------------------- numbers */

/** A number (Fortran D exponents accepted), finite: 0, or -1 when t is not one. */
int imp_number(const imp_tok *t, double *v);

/** v rounded to 15 significant digits (what import_dumps prints, exactly). */
double imp_round(double v);

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

/** Check v (after a multiplier) against kind; SM_OK or SM_INVALID_INPUT (d). */
int imp_check(import_diag *d, const char *file, int line, const char *field, int kind,
              double v);

/** Add a sentence to the warnings array (printf style); -1 when out of memory. */
int imp_warn(json_t *warnings, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

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
    int modes;           /* analysis.modes */
} imp_blade;

/** Zero everything, modes IMPORT_DEFAULT_MODES. */
void imp_blade_init(imp_blade *b);

/**
 * When the table gives no EA or no GJ, the blade section gets assumed
 * values (stiff: the models these files come from are rigid in extension
 * and torsion) and warnings says so.  Returns the section object (new
 * reference, possibly empty) or NULL when out of memory.
 */
json_t *imp_assumed_section(const imp_table *t, double length, json_t *warnings,
                            const char *format);

/**
 * Apply the user's options common to ElastoDyn and CSV: length from
 * tip_radius - hub_radius (tip_radius required unless length_known), rpm.
 * SM_OK or SM_INVALID_INPUT (d).
 */
int imp_options_apply(import_diag *d, const char *file, const import_options *o,
                      int length_known, imp_blade *b, json_t *warnings);

/**
 * The import document {"request", "warnings", "source"}: takes section
 * (may be NULL), warnings and source (stolen, even on failure).  NULL when
 * out of memory.
 */
json_t *imp_document(const imp_blade *b, const imp_table *t, json_t *section,
                     json_t *warnings, json_t *source);

/** imp_document with the section imp_assumed_section makes for a file without EA/GJ (ElastoDyn,
 *  CSV; format names it in the warning); takes warnings and source like imp_document. */
json_t *imp_document_assumed(const imp_blade *b, const imp_table *t, const char *format,
                             json_t *warnings, json_t *source);

#endif /* SPINMODAL_IMPORT_INTERNAL_H */
