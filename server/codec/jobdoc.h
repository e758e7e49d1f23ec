/*
 * jobdoc.h — the daemon's JSON documents about jobs, written by the codec.
 *
 * A job's status document, the job listing, the answer of POST /v1/validate
 * and the error object of a failed job (server/DAEMON.md).  The status and
 * listing splice a stored result text in verbatim (results are stored as the
 * exact JSON served, and may be tens of MB), so they are written as text into
 * a growing buffer, not built as jansson trees.  Nothing here knows HTTP or
 * SQLite: the daemon describes a job with a codec_job_view.
 *
 * Ownership: a codec_text owns its buffer (codec_text_free); views and
 * requests are borrowed.
 */
#ifndef SPINMODAL_CODEC_JOBDOC_H
#define SPINMODAL_CODEC_JOBDOC_H

#include <stddef.h>

#include <jansson.h>

#ifdef __cplusplus
extern "C" {
#endif

struct codec_request;

/* ----------------------------------------------------------- text buffer */

/** A growing NUL-terminated text; zero-initialise it.  nomem is sticky. */
typedef struct codec_text {
    char *p;       /* text, NUL-terminated once anything was appended; malloc'd */
    size_t len;    /* bytes of text, without the NUL */
    size_t cap;    /* bytes allocated */
    int nomem;     /* 1 once an allocation failed: the text is incomplete */
} codec_text;

/** Append n bytes of s. */
void codec_text_put(codec_text *t, const char *s, size_t n);

/** Room for n more bytes and the NUL, grown as codec_text_put grows it (doubling): where to
 *  write them (then add what was written to len and put the NUL), or NULL out of memory. */
char *codec_text_room(codec_text *t, size_t n);

/** Append the NUL-terminated s. */
void codec_text_puts(codec_text *t, const char *s);

/** Append printf-style; for short fields (at most 255 bytes, else nomem is set). */
void codec_text_printf(codec_text *t, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/** Make room for n more bytes at once (before splicing a large text). */
void codec_text_reserve(codec_text *t, size_t n);

/** Free the buffer and zero *t; NULL is a no-op. */
void codec_text_free(codec_text *t);

/** t (Unix seconds, UTC) as RFC 3339 with milliseconds: "2026-11-23T10:00:00.123Z". */
void codec_time_rfc3339(double t, char buf[32]);

/* ------------------------------------------------------------- documents */

/** What the status document says about a job; every pointer is borrowed. */
typedef struct codec_job_view {
    const char *id;              /* 64 lowercase hex digits */
    const char *state;           /* "queued", "running", "done", "failed", "canceled" */
    int done, total;             /* progress: speeds finished / requested */
    double created_at;           /* Unix s; 0 = null */
    double started_at;           /* Unix s; 0 = null */
    double finished_at;          /* Unix s; 0 = null */
    int attempts;                /* claims so far */
    int cancel_requested;        /* 1 once a DELETE asked a running job to stop */
    const char *error;           /* the error object as JSON text, NULL or "" = null */
    const char *name;            /* the request's "name" (plain text), NULL = no member */
    const char *result;          /* result JSON text spliced in verbatim, or NULL = no member */
    size_t result_len;           /* bytes of result */
} codec_job_view;

/**
 * Append the status document of v: {id, state, progress, created_at,
 * started_at, finished_at, attempts, cancel_requested, error[, name],
 * links[, result]}.  Out of memory shows as t->nomem.
 */
void codec_job_status(codec_text *t, const codec_job_view *v);

/**
 * Append a listing {"items":[status...], "next": next-or-null}; the items
 * carry no result.  next is the link to the following page or NULL.
 */
void codec_job_list(codec_text *t, const codec_job_view *items, int n, const char *next);

/**
 * The job id of a request: SHA-256 hex of "<request_sha256>:<solver
 * version>", so a new solver never serves an old cached result.  Returns
 * SM_OK or SM_NOMEM.
 */
int codec_job_id(const struct codec_request *req, char id[65]);

/**
 * Append the answer of a valid POST /v1/validate:
 * {"valid":true,"id","request_sha256","canonical"[,"input_warnings"]}; id
 * from codec_job_id; input_warnings only when the request has any.
 */
void codec_validate_doc(codec_text *t, const char *id, const struct codec_request *req);

/**
 * The error object of a failed job as compact JSON text:
 * {"type","title","detail"[,"errors"][,"diagnostics"]}.  errors and
 * diagnostics are stolen (either may be NULL); detail NULL is "".  Returns a
 * malloc'd string (free) or NULL when out of memory.
 */
char *codec_job_error_text(const char *type, const char *title, const char *detail,
                           json_t *errors, json_t *diagnostics);

#ifdef __cplusplus
}
#endif

#endif /* SPINMODAL_CODEC_JOBDOC_H */
