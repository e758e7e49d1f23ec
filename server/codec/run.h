/*
 * run.h — the one request pipeline: validated request -> core model ->
 * sm_solve -> result documents (DESIGN.md §2).
 *
 * The CLI (`spinmodal solve`) and the daemon's job workers both call
 * codec_run; nothing else in server/ calls sm_model_new or sm_solve.  The
 * outcome tells the caller what to do (print, store, exit code, job state);
 * the documents it returns are the exact bytes the user gets.
 */
#ifndef SPINMODAL_CODEC_RUN_H
#define SPINMODAL_CODEC_RUN_H

#include <stddef.h>

#include <jansson.h>

#include "spinmodal.h"

#ifdef __cplusplus
extern "C" {
#endif

struct codec_request;
struct codec_errors;

/** What became of a run. */
typedef enum codec_run_outcome {
    CODEC_RUN_DONE = 0,   /* every speed solved (stable or unstable): documents set */
    CODEC_RUN_PARTIAL,    /* documents set, but some speed has no modes (no equilibrium, or the
                             eigen-analysis failed): error describes the first such speed */
    CODEC_RUN_INVALID,    /* the core refused the request: errs holds the pointer, error set */
    CODEC_RUN_FAILED,     /* the core failed (singular matrix, LAPACK): error and message set */
    CODEC_RUN_CANCELED,   /* the progress callback asked to stop: nothing else set */
    CODEC_RUN_NOMEM       /* out of memory: error set when it could still be written */
} codec_run_outcome;

/** Documents codec_run writes (bits of want). */
enum {
    CODEC_RUN_JSON = 1,   /* the result document (DESIGN.md §4) */
    CODEC_RUN_CSV = 2,    /* the frequency table */
    CODEC_RUN_TEXT = 4    /* the result document as text (codec_result_text: one case at a
                             time, no tree of the whole document) */
};

/** Output of codec_run; release with codec_run_clear. */
typedef struct codec_run_out {
    codec_run_outcome outcome;
    int status;           /* sm_status of the core step that ended the run (SM_OK: DONE, PARTIAL) */
    json_t *result;       /* result document (CODEC_RUN_JSON; DONE, PARTIAL), owned */
    char *result_text;    /* result document as text, malloc'd (CODEC_RUN_TEXT; DONE,
                             PARTIAL); a caller may take it (and set it NULL) */
    size_t result_len;    /* bytes of result_text */
    char *csv;            /* frequency table, malloc'd (CODEC_RUN_CSV; DONE, PARTIAL) */
    size_t csv_len;       /* bytes of csv */
    char *error;          /* the job's error object as JSON text (PARTIAL, INVALID, FAILED,
                             NOMEM), malloc'd, or NULL */
    char message[512];    /* one line for a log or stderr; "" when DONE */
    int speeds_total;     /* speeds requested */
    int speeds_done;      /* speeds finished (all of them unless CANCELED) */
    double seconds;       /* model construction + solve, s; < 0 when no model was built */
} codec_run_out;

/**
 * Run a validated request (borrowed): build its model, solve every speed
 * with continuation, and write the documents of want.  cb (may be NULL) is
 * the core's progress/cancel callback, called with user between the
 * substructures of the model build (done = 0), after every Newton iteration
 * and after every speed; a nonzero return stops the run (CANCELED).
 * errs (borrowed, not NULL) receives the pointer of a core refusal
 * (INVALID).  *out is always initialised; release it with codec_run_clear.
 * Returns out->outcome.
 */
codec_run_outcome codec_run(const struct codec_request *req, unsigned want, sm_progress_fn cb,
                            void *user, struct codec_errors *errs, codec_run_out *out);

/** Free what *out holds and zero it; NULL is a no-op. */
void codec_run_clear(codec_run_out *out);

#ifdef __cplusplus
}
#endif

#endif /* SPINMODAL_CODEC_RUN_H */
