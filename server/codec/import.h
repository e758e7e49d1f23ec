/*
 * import.h — importers: turn the files engineers already have into a
 * spinmodal request in the blade form (DESIGN.md section 8, spec 12
 * section 6).
 *
 * Three formats: BModes (a .bmi main file and the section-properties file it
 * names), an OpenFAST ElastoDyn blade file, and CSV with a header row of
 * station keys, listed once in the table import_formats[] (name, file roles,
 * parser) that the CLI and the HTTP route look up.  Each importer reads text
 * already in memory (no file system access: the caller loads files, so the
 * CLI and the daemon share the code) and returns an import document
 *
 *     {"request": {"blade": {...}, "frames": "per_element", "analysis": {...}},
 *      "warnings": ["values assumed, ..."],
 *      "input_warnings": [{"pointer": "/blade/section/EA", "message": "values assumed, ..."}],
 *      "source": {"format": "bmodes", "file": "...", ...}}
 *
 * whose "request" is what `spinmodal solve` takes.  "input_warnings" has the
 * shape of a result's input_warnings: the pointer names the field of the
 * request the warning is about (a value assumed, an option that replaced the
 * file's, a column left out: /blade/stations); "warnings" holds the same
 * messages as plain strings, the shape before 0.8, kept for older clients.  A bad file is refused
 * with one diagnostic naming the file, the line and the field:
 * "blade_sec_props.dat:7: axial_stff: not a number (\"abc\")".
 * Numbers too large for the request (past 1.79769313486231e+308, which
 * prints as infinity at 15 digits), derived values that overflow (rot_rpm x
 * rpm_mult, an assumed EA or GJ) and blades shorter than IMPORT_MIN_LENGTH
 * are refused the same way; a message quotes at most a short, escaped
 * excerpt of the file (40 characters).  Text: UTF-8 (a byte-order mark is
 * skipped) or ASCII; UTF-16 is refused.
 *
 * Ownership: the json_t *out is a new reference (json_decref).  Status
 * codes: SM_OK, SM_INVALID_INPUT (diag filled), SM_NOMEM.
 */
#ifndef SPINMODAL_IMPORT_H
#define SPINMODAL_IMPORT_H

#include <stddef.h>

#include <jansson.h>

#include "spinmodal.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IMPORT_MAX_STATIONS 10000  /* rows of a station table */
#define IMPORT_MAX_BYTES ((size_t)16 << 20) /* one input file */
#define IMPORT_ELEMENTS 48         /* elements of the imported blade */
#define IMPORT_DEFAULT_MODES 10    /* analysis.modes when the file gives none */
#define IMPORT_MIN_LENGTH 1e-6       /* m: the shortest blade (tip radius - hub radius) */
#define IMPORT_MIN_LENGTH_RATIO 1e-6 /* and at least this fraction of the tip radius: the
                                        stations' radii hub + s length stay distinct */

/** One input file: its name for messages and its text (need not be NUL-terminated). */
typedef struct import_file {
    const char *name; /* shown in diagnostics, e.g. "blade_sec_props.dat" */
    const char *text; /* contents, len bytes */
    size_t len;
} import_file;

/** What a file may not say, given by the user (CLI options, HTTP query). */
typedef struct import_options {
    double tip_radius; /* m, from the spin axis along the blade; NAN = not given */
    double hub_radius; /* m, >= 0; NAN = not given */
    double rpm;        /* rev/min, >= 0; NAN = not given (overrides the file's) */
    const json_t *rpm_speeds; /* NULL, or several speeds (rev/min) for analysis.rpm instead of
                                 [rpm]: an array of numbers or a range {"from", "to", "steps"}
                                 as a request takes them (CLI --rpm 0:15:16 or 0,5,10); borrowed,
                                 checked by the caller (finite, >= 0); rpm is then its first
                                 speed */
    int max_modes;     /* cap of analysis.modes (the codec's limit) */
    int ed_blade;      /* ElastoDyn main file only: 1 = its blade (BldFile(1) with TipRad,
                          HubRad, PreCone(1), RotSpeed), 0 = its tower (CLI --part blade) */
    int bmodes_mesh;   /* BModes only: > 0 = BModes' own model (its nselt elements as uniform
                          members with its midpoint properties, BModes.f90:1110), this many FE
                          elements each, in the structure form; 0 = the blade form */
} import_options;

/** Every option "not given", max_modes the codec's default limit. */
void import_default_options(import_options *o);

/** Why a file was refused: "FILE:LINE: FIELD: what is wrong" and its parts. */
typedef struct import_diag {
    char file[128];   /* file name as given (truncated) */
    int line;         /* 1-based, 0 = the file as a whole / an option */
    char field[64];   /* the field or column of the format, or the option */
    char message[400];/* what is wrong */
    char text[640];   /* the whole sentence */
} import_diag;

/**
 * Loads a file named by another one (BModes: the section-properties file
 * named in the .bmi, relative to it).  Fills *out (memory owned by ctx,
 * valid until import_bmodes returns; out->name NULL = the name as written).
 * Returns SM_OK; SM_INVALID_INPUT with why[cap] saying why it cannot be
 * read ("No such file or directory"; the importer names the file and the
 * line that names it); or SM_NOMEM.
 */
typedef int (*import_loader)(void *ctx, const char *name, import_file *out, char *why,
                             size_t cap);

/**
 * BModes v3: the .bmi main file (beam_type 1, blades only) and the section
 * properties file it names, loaded through load(ctx, name, ...).
 */
int import_bmodes(json_t **out, const import_file *bmi, import_loader load, void *ctx,
                  const import_options *o, import_diag *d);

/**
 * OpenFAST ElastoDyn: a blade file (o->tip_radius required: the file has no length), or the
 * main ElastoDyn file, which gives the tower form: the tower file it names (TwrFile) and the
 * blade file (BldFile(1), for the rotor's mass in the tower-top mass) are read through
 * load(ctx, ...), relative to the main file (DESIGN.md 8.5).
 */
int import_elastodyn_files(json_t **out, const import_file *f, import_loader load, void *ctx,
                           const import_options *o, import_diag *d);

/** import_elastodyn_files without a loader: a blade file (a main file is refused). */
int import_elastodyn(json_t **out, const import_file *f, const import_options *o,
                     import_diag *d);

/** CSV with a header row of station keys (units in brackets optional, '#' comments). */
int import_csv(json_t **out, const import_file *f, const import_options *o, import_diag *d);

/**
 * The rotor-speed option (CLI --rpm, HTTP ?rpm=), in rev/min: one number "12.1", a list
 * "0,5,10", or a range "START:STOP:COUNT" (COUNT speeds from START to STOP, both ends
 * included, as the Python client's and campbell.sh's ranges: "0:15:16" is 0, 1, ... 15 rpm;
 * COUNT 1 only when START = STOP, so that "0:15:1" is not silently 0 rpm alone).  Every
 * speed finite and >= 0, START <= STOP.  Sets o->rpm to the first speed and o->rpm_speeds to
 * *speeds: NULL for one number, else a new reference (an array, or the range
 * {"from", "to", "steps": COUNT - 1} of a request) that the caller keeps while it imports and
 * then json_decref's.  SM_OK; SM_INVALID_INPUT with why[cap] saying what is wrong; SM_NOMEM.
 */
int import_rpm_option(const char *text, import_options *o, json_t **speeds, char *why,
                      size_t cap);

/**
 * An importer, as the table calls it: f is the main file; load(ctx, ...) reads a file that f
 * names (used only by formats with IMPORT_SEC_FILE; others ignore load and ctx).  Ownership
 * and status codes as import_bmodes.
 */
typedef int (*import_parse_fn)(json_t **out, const import_file *f, import_loader load,
                               void *ctx, const import_options *o, import_diag *d);

#define IMPORT_SEC_FILE 1u /* the main file names a second file, read through the loader (BModes'
                              section properties): HTTP takes only JSON {main, sec_props, name};
                              the CLI's --allow-outside applies */
#define IMPORT_OWN_MESH 2u /* import_options.bmodes_mesh applies (CLI --bmodes-mesh, HTTP
                              ?bmodes_mesh=) */
#define IMPORT_NAMED_FILES \
    4u /* the main file may name other files (an ElastoDyn main file's
                                 TwrFile, BldFile): HTTP takes JSON {main, files: {NAME: text},
                                 name}, each file under the name the main file gives it */

/**
 * One import format (import_formats.c).  The CLI and the HTTP route do for a format only what
 * its entry says: a new format is one entry and its parser file.
 */
typedef struct import_format {
    const char *name;      /* "bmodes": the CLI's FORMAT, the HTTP path's {format} */
    const char *label;     /* "BModes": the format in sentences */
    const char *main_name; /* the main file's name in messages when the request names none */
    const char *synopsis;  /* CLI usage after "spinmodal import NAME " (common options left out) */
    unsigned flags;        /* IMPORT_SEC_FILE, IMPORT_OWN_MESH */
    import_parse_fn parse; /* the importer */
} import_format;

/** Every import format, in the order messages list them; ends with an entry whose name is NULL. */
extern const import_format import_formats[];

/** The format called name (NULL allowed), or NULL when there is none. */
const import_format *import_format_find(const char *name);

/** 1 when name is an import format of the table (import_format_find), else 0. */
int import_format_known(const char *name);

/**
 * The names of the formats that have every flag of flags (0: all), as a sentence lists them:
 * "bmodes, elastodyn or csv", "bmodes"; written into buf[cap] (truncated, NUL-terminated when
 * cap > 0) and returned.
 */
const char *import_format_list(char *buf, size_t cap, unsigned flags);

/**
 * The import document as text, numbers at 15 significant digits (the
 * importers round every number to that, so the text is exact); malloc'd,
 * NULL when out of memory.  pretty: indented.
 */
char *import_dumps(const json_t *doc, int pretty);

#ifdef __cplusplus
}
#endif

#endif /* SPINMODAL_IMPORT_H */
