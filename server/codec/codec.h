/*
 * codec.h — JSON <-> core translation for the spinmodal CLI and daemon.
 *
 * The codec reads the request of DESIGN.md section 3 (planar) and 7.3
 * (spatial), validates every field
 * (collecting all errors, each with the RFC 6901 JSON pointer of the field),
 * applies the defaults and keeps a canonical copy whose SHA-256 identifies
 * the question.  It builds the core's sm_structure/sm_options/speeds from
 * that canonical copy, maps the core's sm_diag back to JSON pointers, encodes
 * an sm_result as the result document of DESIGN.md section 4 and builds the
 * RFC 9457 problem documents used for errors.
 *
 * Ownership: functions named *_new return objects owned by the caller and
 * released by the matching *_free (NULL is a no-op).  json_t results are new
 * references (json_decref).  Status codes are the core's sm_status values.
 *
 * The sections below name the file that implements them; codec_internal.h
 * (private to server/codec) describes how those files fit together.
 */
#ifndef SPINMODAL_CODEC_H
#define SPINMODAL_CODEC_H

#include <stddef.h>
#include <stdio.h>

#include <jansson.h>

#include "spinmodal.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ----------------------------------------------------- limits (limits.c) */

/** Size limits applied while validating a request (the daemon configures them). */
typedef struct codec_limits {
    size_t max_request_bytes; /* request text, default 16 MiB */
    int max_joints;           /* default 1000 */
    int max_sections;         /* default 1000 */
    int max_members;          /* default 1000 */
    int max_point_masses;     /* default 1000 */
    int max_elements;         /* FE elements summed over all members, default 2000 */
    int max_speeds;           /* entries of analysis.omega, default 1001 */
    int max_modes;            /* analysis.modes, default 200 */
    long max_shape_values;    /* numbers in the mode shapes the solver holds for a result
                                 (speeds x modes x nodes x 3, 6 for a spatial request, x 2
                                 with Coriolis; 8 bytes each), default 4e6 (32 MB) */
    size_t max_result_bytes;  /* bytes of the result document (JSON), estimated from the
                                 request's counts before it is accepted (size.c: mode
                                 shapes, equilibria, modes, critical speeds), default
                                 50 000 000; 0 = no limit */
    int max_coordinates;      /* modal coordinates of a model solved by the dense path (cost
                                 ~ n^3: ~5.6 s and ~200 MB a speed with Coriolis at 1000;
                                 models the tree-structured path takes are bounded by
                                 max_elements only), default SM_DENSE_MAX_DEFAULT (1000) */
    double max_solve_seconds; /* the dense path's estimated time (sm_dense_seconds x speeds)
                                 above which a request is refused: the daemon's --job-timeout;
                                 0 = no limit (the CLI's default) */
    int max_frame_dofs;       /* degrees of freedom of one substructure's component-mode
                                 problem (3 x its free nodes, 6 x for a spatial request; cost
                                 ~ dofs^3 each), default 1200 (~3 s on one core) */
} codec_limits;

/** Fill *lim with the default limits listed in codec_limits. */
void codec_default_limits(codec_limits *lim);

/* ----------------------------------------------------- errors (errors.c) */

/** Most errors kept in one list; later ones are counted, not stored. */
#define CODEC_MAX_ERRORS 100

/**
 * A list of validation errors, each a JSON pointer (RFC 6901, "" for the
 * whole document) and a sentence for a user.  Opaque.
 */
typedef struct codec_errors codec_errors;

/** New empty list, or NULL when out of memory.  Free with codec_errors_free. */
codec_errors *codec_errors_new(void);

/** Free a list; NULL is a no-op. */
void codec_errors_free(codec_errors *e);

/** Remove every error and reset the malformed flag. */
void codec_errors_clear(codec_errors *e);

/**
 * Append an error: pointer is copied, the message is formatted printf-style.
 * Returns SM_OK or SM_NOMEM (the list then remembers it was truncated).
 */
int codec_errors_add(codec_errors *e, const char *pointer, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/** Number of stored errors (at most CODEC_MAX_ERRORS + 1 with the "more" note). */
int codec_errors_count(const codec_errors *e);

/** Pointer of error i (0 <= i < count), borrowed; NULL when out of range. */
const char *codec_errors_pointer(const codec_errors *e, int i);

/** Message of error i (0 <= i < count), borrowed; NULL when out of range. */
const char *codec_errors_message(const codec_errors *e, int i);

/** 1 when the list describes a request that is not JSON at all (HTTP 400). */
int codec_errors_malformed(const codec_errors *e);

/** 1 when the request was larger than max_request_bytes (HTTP 413). */
int codec_errors_too_large(const codec_errors *e);

/** The list as a JSON array [{"pointer","message"}...]; new reference or NULL (NOMEM). */
json_t *codec_errors_to_json(const codec_errors *e);

/* --------------------------------------- request (validate.c, request.c) */

/** A validated request with its defaults applied.  Opaque, immutable. */
typedef struct codec_request codec_request;

/**
 * Parse and validate request text (need not be NUL-terminated).  On SM_OK,
 * *out receives a new request (codec_request_free).  On SM_INVALID_INPUT,
 * *out is NULL and errs lists every problem found (codec_errors_malformed
 * tells a syntax error from an invalid model).  Returns SM_NOMEM when out of
 * memory.  lim may be NULL for the defaults; errs must not be NULL.
 */
int codec_request_parse(codec_request **out, const char *text, size_t len,
                        const codec_limits *lim, codec_errors *errs);

/**
 * Validate an already parsed request (borrowed, not modified).  Same
 * contract as codec_request_parse.
 */
int codec_request_from_json(codec_request **out, const json_t *root,
                            const codec_limits *lim, codec_errors *errs);

/** Free a request; NULL is a no-op. */
void codec_request_free(codec_request *r);

/** The structure for sm_model_new; borrowed from r. */
const sm_structure *codec_request_structure(const codec_request *r);

/**
 * The sizes the model of r will have (nodes, elements, frames, coordinates,
 * largest frame), from the core's structure check run at validation (no
 * model is built to know them); borrowed from r.
 */
const sm_model_info *codec_request_model_info(const codec_request *r);

/** The options for sm_model_new; borrowed from r. */
const sm_options *codec_request_options(const codec_request *r);

/** Let r's sweep use up to threads threads (sm_options.threads; < 2: the calling thread only).
 *  A setting of the program that runs it, not of the request: the canonical text, the job id
 *  and every number of the result stay the same. */
void codec_request_set_threads(codec_request *r, int threads);

/** The speeds (rad/s) in request order; borrowed from r.  *n receives their count. */
const double *codec_request_speeds(const codec_request *r, int *n);

/** The speeds in rev/min (request order, as given when the request used rpm); borrowed. */
const double *codec_request_rpm(const codec_request *r, int *n);

/**
 * The unit-slip warnings of r (DESIGN.md 8): an array [{"pointer",
 * "message"}], empty when none; borrowed from r.
 */
const json_t *codec_request_input_warnings(const codec_request *r);

/**
 * analysis.error_estimate (DESIGN.md 9): 0 when not asked, else the refined levels to solve
 * (2: h/2 and h/4, the observed order; 1: h/2 only, the refined h/4 model being over the
 * limits the request was validated with).
 */
int codec_request_error_estimate(const codec_request *r);

/** Name of joint j (the joints are indexed in sorted name order), borrowed; NULL if out of range. */
const char *codec_request_joint_name(const codec_request *r, int j);

/** The canonical request (defaults applied), borrowed from r. */
const json_t *codec_request_canonical(const codec_request *r);

/** The canonical structure the model is built from (borrowed): the canonical request's
 *  "structure", or the structure a "blade" stands for (DESIGN.md 8.1). */
const json_t *codec_request_structure_json(const codec_request *r);

/**
 * The canonical JSON text: keys sorted, compact, reals with 17 significant
 * digits.  Borrowed from r, NUL-terminated.
 */
const char *codec_request_canonical_text(const codec_request *r);

/** SHA-256 of the canonical text as 64 lowercase hex digits, borrowed from r. */
const char *codec_request_sha256(const codec_request *r);

/** Longest request "name", in bytes. */
#define CODEC_NAME_MAX 200

/**
 * The request's optional top-level "name" (a label for people, kept out of
 * the canonical text and so of the job id), borrowed from r; NULL without one.
 */
const char *codec_request_name(const codec_request *r);

/**
 * The text a job stores and GET /v1/analyses/{id}/request serves: the
 * canonical text, with the "name" among its sorted keys when the request has
 * one (its SHA-256 is then not the job's: the id is the canonical text's).
 * Borrowed from r, NUL-terminated.
 */
const char *codec_request_stored_text(const codec_request *r);

/**
 * SHA-256 of len bytes of data as lowercase hex into hex[65] (NUL-terminated).
 * Returns SM_OK (sha256.c: FIPS 180-4, no library).
 */
int codec_sha256_hex(const void *data, size_t len, char hex[65]);

/* --------------------------------------------------------- core (diag.c) */

/**
 * Turn a core diagnostic (sm_model_new, sm_solve) into one error of errs:
 * the pointer names the member, joint, section, point mass, clamp or option
 * it refers to.  Returns SM_OK or SM_NOMEM.
 */
int codec_diag_error(const codec_request *r, const sm_diag *d, codec_errors *errs);

/**
 * Build the core model of a request.  On SM_OK *out receives a new model
 * (sm_model_free).  On any other status *out is NULL and, unless the status
 * is SM_NOMEM, errs holds one error naming the offending item (topology
 * errors: cycle, disconnected member, ...).  diag may be NULL.
 */
int codec_model_new(sm_model **out, const codec_request *r, codec_errors *errs,
                    sm_diag *diag);

/**
 * codec_model_new that can be stopped: cb (may be NULL) is asked between
 * substructures (sm_model_build); nonzero stops with SM_CANCELED (errs
 * untouched).
 */
int codec_model_build(sm_model **out, const codec_request *r, sm_progress_fn cb, void *user,
                      codec_errors *errs, sm_diag *diag);

/* ---------------------------------------------- result (result.c, csv.c) */

/** Name of a case status: "solved", "unstable" or "no_equilibrium". */
const char *codec_case_status_name(sm_case_status s);

/**
 * Encode a result as the document of DESIGN.md section 4 (7.3 for a spatial
 * request: 6 numbers per node, "model" with "spatial" and "dof_per_node").
 * r, m and res are borrowed; *out receives a new reference.  Returns SM_OK
 * or SM_NOMEM.
 */
int codec_result_encode(json_t **out, const codec_request *r, const sm_model *m,
                        const sm_result *res);

/** The dump flags of a stored result document: compact, reals with 17 significant digits. */
#define CODEC_RESULT_DUMP (JSON_COMPACT | JSON_REAL_PRECISION(17))

/** json_dump_callback(x, cb, data, CODEC_RESULT_DUMP): the same bytes, written faster (reals
 *  without glibc's multi-precision printf, pieces buffered; jsontext.c).  x: an object or an
 *  array (else -1).  Returns 0, or -1 when cb failed or a string is not valid UTF-8. */
int codec_json_dump(const json_t *x, json_dump_callback_t cb, void *data);

/** codec_json_dump into the stream f (json_dumpf with CODEC_RESULT_DUMP).  0 or -1. */
int codec_json_dumpf(const json_t *x, FILE *f);

/**
 * codec_result_encode's document as text, the bytes of json_dumps(document,
 * CODEC_RESULT_DUMP), written one case at a time so that no tree of the whole
 * document is held beside the text.  *out receives a malloc'd NUL-terminated
 * string (free), *len its length (len may be NULL).  Returns SM_OK or SM_NOMEM.
 */
int codec_result_text(char **out, size_t *len, const codec_request *r, const sm_model *m,
                      const sm_result *res);

/**
 * Encode the frequency table as CSV (header omega,mode,frequency_rad_s,
 * frequency_hz,eig_re,eig_im,mac_to_previous,status,per_rev,rpm,label,
 * label_confidence,tracked_index,tracking_flag (DESIGN.md 9.1); one row
 * per speed and mode, one row with empty mode fields for a speed without
 * modes).  r (may be NULL: rpm from omega) gives the rpm of each case.
 * *out receives a malloc'd NUL-terminated string (free), *len its length
 * (len may be NULL).  Returns SM_OK or SM_NOMEM.
 */
int codec_result_csv(char **out, size_t *len, const codec_request *r, const sm_result *res);

/**
 * Span-wise mode shapes (DESIGN.md 8.3) from a result document (as
 * codec_result_encode writes it, or read back from the store): bmodes 0 the
 * CSV omega,rpm,mode,frequency_hz,per_rev,member,member_id,s,span_m,flap,
 * flap_slope,edge,edge_slope,twist,axial (one row per speed, mode, member
 * and node; span_m = s x length, m from the member's `from` joint, named
 * r_m before 0.8); 1 a BModes-style text table.  *out receives a malloc'd
 * NUL-terminated string, *len its length (len may be NULL).  Returns SM_OK,
 * SM_NOMEM, or SM_INVALID_INPUT with err saying why (a planar result, or
 * one without mode shapes).
 */
int codec_result_spanwise(char **out, size_t *len, const json_t *result, int bmodes,
                          char *err, size_t errcap);

/**
 * The critical speeds of a result document (its "critical_speeds", DESIGN.md 9.1) as CSV:
 * header order,tracked_index,label,label_confidence,omega,rpm,frequency_rad_s,frequency_hz,
 * refined,omega_interpolated; one row per critical speed, then one row of order 0 per
 * divergence speed (its "divergence_speeds": the frequency of the softening mode passes
 * through zero; tracked_index and label_confidence empty, frequency 0), just the header when
 * the document has neither.  Works on a stored document, so the daemon can serve it without solving again.
 * result is borrowed; *out receives a malloc'd NUL-terminated string (free), *len its length
 * (len may be NULL).  Returns SM_OK or SM_NOMEM.
 */
int codec_critical_speeds_csv(char **out, size_t *len, const json_t *result);

/* --------------------------------------------------- problem (problem.c) */

/**
 * An RFC 9457 problem document {type, title, status, detail, errors}.
 * type NULL means "about:blank"; detail may be NULL; errs may be NULL or
 * empty (no "errors" member then).  Returns a new reference or NULL (NOMEM).
 */
json_t *codec_problem_new(int http_status, const char *type, const char *title,
                          const char *detail, const codec_errors *errs);

/**
 * The problem document for a failed codec_request_parse/codec_model_new:
 * 400 (malformed JSON), 413 (too large) or 422 (invalid model), with errs.
 * Returns a new reference or NULL (NOMEM).
 */
json_t *codec_problem_from_errors(const codec_errors *errs);

/** HTTP status the errors of a failed request map to: 400, 413 or 422. */
int codec_errors_http_status(const codec_errors *e);

#ifdef __cplusplus
}
#endif

#include "jobdoc.h" /* documents about jobs (status, listing, validate, error object) */
#include "run.h"    /* the pipeline: request -> model -> solve -> documents */

#endif /* SPINMODAL_CODEC_H */
