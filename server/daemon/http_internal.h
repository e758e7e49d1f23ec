/*
 * http_internal.h — what the files of the HTTP front share (private to
 * server/daemon/http*.c; the public interface is http.h).
 *
 * The HTTP front is one module in five files:
 *   http.c           libmicrohttpd set-up and stop, the three-phase handler,
 *                    the job-pool guard;
 *   http_routes.c    the route table http_routes[] {template, methods,
 *                    handlers} (Redis's command table), the one lookup and
 *                    the answers it gives (404, 405 + Allow, preflight), the
 *                    operational routes (/livez, /readyz, /metrics,
 *                    embedded files);
 *   http_analyses.c  the /v1/analyses routes and the end of a POST (validate,
 *                    submit, wait, answer);
 *   http_body.c      receiving a POST body: token, content type, size caps,
 *                    the early 413;
 *   http_reply.c     building responses: headers, problem documents, the
 *                    last-resort 503, small parsers of the request line;
 *   http_guard.c     the budgets of connection slots: the deadline for a
 *                    request's head and body (slow clients cannot hold
 *                    slots), the slots kept free, the cap on long polls;
 *   http_import.c    POST /v1/import/{format}: blade files into requests.
 */
#ifndef SPINMODAL_HTTP_INTERNAL_H
#define SPINMODAL_HTTP_INTERNAL_H

#include <stddef.h>

#include <pthread.h>

#include <microhttpd.h>

#include "codec.h"
#include "embedded.h"
#include "http.h"
#include "jobs.h"
#include "metrics.h"
#include "store.h"

#define HTTP_WAIT_MAX 60.0         /* s, largest ?wait= */
#define HTTP_WAIT_SLICE 0.25       /* s, longest single jobs_wait (bounds http_begin_stop) */
#define HTTP_LIST_DEFAULT 20       /* ?limit= default */
#define HTTP_LIST_MAX 100          /* ?limit= maximum */
#define HTTP_BODY_CHUNK 65536      /* first body allocation when Content-Length is unknown */
#define HTTP_RETRY_BUSY "5"        /* Retry-After of 429 and of 503 while stopping */
#define HTTP_RETRY_FAULT "1"       /* Retry-After of 503 for store/memory failures */
#define HTTP_PROBLEMS "https://spinmodal.dev/problems/"

/* Methods as bits, for the Allow header and route checks. */
enum {
    M_GET = 1,
    M_HEAD = 2,
    M_POST = 4,
    M_DELETE = 8,
    M_OPTIONS = 16,
    M_OTHER = 32
};

/* A tracked connection (http_guard.c). */
typedef struct http_conn http_conn;

/* A waiting long poll (?wait=S), on the stack of its request thread (http_guard.c). */
typedef struct http_waiter {
    int released;                     /* 1: answer now, a newer long poll took the slot */
    struct http_waiter *prev, *next;  /* in http->waiters, oldest first */
} http_waiter;

/* Routes of DAEMON.md. */
typedef enum http_route {
    R_OTHER = 0,     /* no route: 404 */
    R_ANALYSES,      /* /v1/analyses */
    R_VALIDATE,      /* /v1/validate */
    R_ANALYSIS,      /* /v1/analyses/{id} */
    R_RESULT,        /* /v1/analyses/{id}/result */
    R_REQUEST,       /* /v1/analyses/{id}/request */
    R_LIVEZ,
    R_READYZ,
    R_METRICS,
    R_FILE,          /* an embedded file (schemas, OpenAPI, /) */
    R_IMPORT         /* /v1/import/{bmodes|elastodyn|csv} (http_import.c) */
} http_route;

/* Flags of a route (http_route_def.flags). */
enum {
    HTTP_ROUTE_READ_TOKEN = 1  /* GET and HEAD need the token under --auth-reads */
};

typedef struct http_req http_req;

/* A handler: answer the request (queue a response). */
typedef enum MHD_Result (*http_route_fn)(struct MHD_Connection *c, http_req *r);

/* Phase 1 of a POST: 1 to read the body, or 0 with the answer queued in *q. */
typedef int (*http_begin_fn)(struct MHD_Connection *c, http_req *r, enum MHD_Result *q);

/*
 * One route of http_routes[] (http_routes.c): its path template, the
 * methods it allows and who answers each.  A template is literal but for
 * at most one {param} segment: {id} takes any one segment (a job id:
 * http_req.id_ok says whether it is one), {format} a name of the codec's
 * import_formats[].  OPTIONS is answered for every route (the preflight
 * under --cors-origin, 405 otherwise).
 */
typedef struct http_route_def {
    const char *tmpl;        /* path template; also the route label of the metrics */
    http_route route;        /* its id, for the code a route shares (R_ANALYSES ...) */
    unsigned methods;        /* M_* bits allowed: the Allow header of a 405 */
    unsigned flags;          /* HTTP_ROUTE_* */
    http_route_fn get;       /* GET and HEAD (M_GET in methods) */
    http_route_fn del;       /* DELETE, once the token is checked (M_DELETE in methods) */
    http_begin_fn begin;     /* POST phase 1: token, query, type, size (M_POST in methods) */
    http_route_fn end;       /* POST phase 3: the body is in */
} http_route_def;

/* State of the body of a POST. */
enum { BODY_OK = 0, BODY_TOO_LARGE = 1, BODY_NOMEM = 2 };

struct http {
    struct MHD_Daemon *d;
    jobs *j;                 /* borrowed; not touched after http_begin_stop */
    store *st;               /* borrowed */
    metrics *mx;             /* borrowed */
    size_t max_body;         /* bytes */
    codec_limits limits;     /* request validation */
    char *cors_origin;       /* NULL = no CORS */
    char token_hash[65];     /* SHA-256 hex of the bearer token, "" = no auth */
    int port;                /* bound port */
    pthread_mutex_t lock;    /* guards stopping and active */
    pthread_cond_t idle;     /* signaled when active drops to 0 while stopping */
    int stopping;            /* http_begin_stop has begun */
    int active;              /* request threads inside a jobs_* call */
    int auth_reads;          /* 1: reads of jobs, /metrics and /v1/validate need the token too */
    /* slot budgets (http_guard.c) */
    double request_deadline; /* s for a request's head and body to arrive */
    pthread_mutex_t guard_lock; /* guards conns and every http_conn, the waiters,
                                   the counts below, guard_stop */
    pthread_cond_t guard_cv; /* wakes the guard thread to stop */
    http_conn *conns;        /* open connections, newest first */
    int n_held;              /* of those, not yet shut down by the guard */
    int n_dying;             /* shut down, not yet closed by libmicrohttpd */
    int held_cap;            /* most connections held before one waiting for its
                                request is closed (the rest is kept for newcomers) */
    int shed_pending;        /* connections closed at accept and not yet logged */
    unsigned shed_round;     /* counts the calls of http_guard_shed (its spared marks) */
    http_waiter *waiters, *waiters_tail; /* waiting long polls, oldest first */
    int n_waiters;           /* in the list */
    int n_releasing;         /* released from it, not yet answered */
    int max_waiters;         /* --max-waiters; 0 = ?wait never blocks */
    int released_pending;    /* long polls answered early, not yet logged */
    unsigned long long released_total; /* long polls answered early for a newer one */
    pthread_t guard_thread;
    int guard_started;       /* 1 while the guard thread runs */
    int guard_stop;          /* 1: the guard thread leaves */
};

/* Per-request context (*req_cls), from the first call to http_completed. */
struct http_req {
    http *h;
    double t0;               /* monotonic s when the headers were received */
    const http_route_def *def; /* its route (http_route_find), NULL = none: 404 */
    http_route route;        /* def->route, R_OTHER without one */
    const char *tmpl;        /* route template for the metrics (static or embedded path) */
    const embedded_file *file; /* R_FILE */
    unsigned method;         /* M_* */
    char method_name[16];    /* for the log, sanitized */
    char path[200];          /* for the log, sanitized, truncated */
    char id[65];             /* job id of the path or of a submission, "" = none */
    int id_ok;               /* the {id} of the path is 64 lowercase hex digits */
    int status;              /* status queued, 0 = none yet */
    size_t bytes;            /* response body bytes sent (0 for HEAD) */
    double wait;             /* ?wait= of a POST, s */
    char *body;              /* POST body received so far (malloc'd) */
    size_t len, cap;         /* bytes in body, bytes allocated */
    size_t announced;        /* Content-Length of a POST, 0 = none */
    int body_state;          /* BODY_* */
    int collect;             /* a POST whose body is read (phase 2) */
    int raw_answer;          /* answered on the socket by http_early_too_large */
};

/* A response header. */
typedef struct http_hdr {
    const char *name;
    const char *value;
} http_hdr;

/* ------------------------------------------------------------ http_reply.c */

/** Monotonic seconds. */
double http_mono(void);

/** Copy s into dst[cap] with control characters replaced, truncated. */
void http_sanitize(char *dst, size_t cap, const char *s);

/** 1 when s[0..len) is a job id: 64 lowercase hex digits. */
int http_is_id(const char *s, size_t len);

/** Decimal integer in [lo, hi] into *out: 0, or -1 when s is not one. */
int http_parse_int(const char *s, long long lo, long long hi, long long *out);

/** Decimal seconds in [0, hi] into *out: 0, or -1 when s is not one. */
int http_parse_seconds(const char *s, double hi, double *out);

/** Compare n bytes in constant time; 1 when equal. */
int http_ct_equal(const char *a, const char *b, size_t n);

/** Queue the static out-of-memory 503; the last resort. */
enum MHD_Result http_send_oom(struct MHD_Connection *c, http_req *r);

/**
 * Queue a response.  body (len bytes) is freed with free() after sending
 * when own is 1, or is static when own is 0; body NULL means no body.  On
 * any failure body is freed (if owned) and the static 503 is sent.
 */
enum MHD_Result http_respond(struct MHD_Connection *c, http_req *r, int status,
                             const char *ctype, char *body, size_t len, int own,
                             const http_hdr *hdrs, int n);

/** Queue the text held in b (taken); the static 503 when b ran out of memory. */
enum MHD_Result http_respond_buf(struct MHD_Connection *c, http_req *r, int status,
                                 const char *ctype, codec_text *b, const http_hdr *hdrs, int n);

/** Queue the problem document p (taken; NULL = out of memory). */
enum MHD_Result http_respond_problem(struct MHD_Connection *c, http_req *r, int status,
                                     json_t *p, const http_hdr *hdrs, int n);

/** Queue a problem document; type_name NULL = about:blank. */
enum MHD_Result http_problem(struct MHD_Connection *c, http_req *r, int status,
                             const char *type_name, const char *title, const char *detail,
                             const http_hdr *hdrs, int n);

/** 503 + Retry-After: why is "stopping" (the daemon stops) or "unavailable" (the store). */
enum MHD_Result http_unavailable(struct MHD_Connection *c, http_req *r, const char *why);

/** 400 for query parameter name, with pointer /query/<name>. */
enum MHD_Result http_bad_query(struct MHD_Connection *c, http_req *r, const char *name,
                               const char *message);

/** 404: no such analysis (is_id) or no such route. */
enum MHD_Result http_not_found(struct MHD_Connection *c, http_req *r, int is_id);

/** 405 with the Allow header of methods (M_* bits). */
enum MHD_Result http_not_allowed(struct MHD_Connection *c, http_req *r, unsigned methods);

/* ------------------------------------------------------------- http_body.c */

/** 1 when the request carries the bearer token (or no token is configured). */
int http_authorized(const http *h, struct MHD_Connection *c);

/** 401 with WWW-Authenticate. */
enum MHD_Result http_unauthorized(struct MHD_Connection *c, http_req *r);

/** 413 for a body over --max-body, answered through libmicrohttpd. */
enum MHD_Result http_too_large(struct MHD_Connection *c, http_req *r);

/** 413 written straight to the socket while the body still arrives, then close. */
enum MHD_Result http_early_too_large(struct MHD_Connection *c, http_req *r);

/**
 * Phase 1 of a POST: refuse it early (token, ?wait, content type,
 * Content-Length) or get ready to collect its body.  0 to read the body, or
 * -1 with *q the answer already queued.
 */
int http_post_begin(struct MHD_Connection *c, http_req *r, enum MHD_Result *q);

/** Phase 2 of a POST: append n bytes of body, capped at --max-body. */
void http_take_body(http_req *r, const char *data, size_t n);

/* --------------------------------------------------------- http_analyses.c */

/** ?wait=S into *wait (0 when absent); 0, or -1 after queueing a 400. */
int http_query_wait(struct MHD_Connection *c, http_req *r, double *wait, enum MHD_Result *q);

/** GET /v1/analyses/{id}[?wait=S] */
enum MHD_Result http_get_analysis(struct MHD_Connection *c, http_req *r);

/** GET /v1/analyses/{id}/result[?format=json|csv] */
enum MHD_Result http_get_result(struct MHD_Connection *c, http_req *r);
/** GET /v1/analyses/{id}/request: the job's canonical request (http_analyses.c). */
enum MHD_Result http_get_request(struct MHD_Connection *c, http_req *r);

/** GET /v1/analyses[?limit=N&before=SEQ&state=S] */
enum MHD_Result http_list(struct MHD_Connection *c, http_req *r);

/** DELETE /v1/analyses/{id} */
enum MHD_Result http_delete(struct MHD_Connection *c, http_req *r);

/** Phase 3 of a POST: validate the body, then submit or describe it, and answer. */
enum MHD_Result http_post_end(struct MHD_Connection *c, http_req *r);

/* ----------------------------------------------------------- http_import.c */

/** Phase 1 of POST /v1/import/{format}: as http_post_begin (1 = read the body). */
int http_import_begin(struct MHD_Connection *c, http_req *r, enum MHD_Result *q);

/** Phase 3 of POST /v1/import/{format}: import the body and answer. */
enum MHD_Result http_import_end(struct MHD_Connection *c, http_req *r);

/* ------------------------------------------------------------ http_guard.c */

/** MHD_OPTION_NOTIFY_CONNECTION (cls = the http): track a connection from accept to close. */
void http_guard_notify(void *cls, struct MHD_Connection *c, void **socket_context,
                       enum MHD_ConnectionNotificationCode code);

/**
 * The request on c is complete and being answered: no deadline until it is
 * answered.  Returns 1 when the guard has already shut the connection down
 * (shed, or past its deadline, while its request was read): close it
 * without serving it (a long poll would hold the slot for nothing).
 */
int http_guard_answering(http *h, struct MHD_Connection *c);

/** The request on c was answered: the next one must arrive within the deadline. */
void http_guard_answered(http *h, struct MHD_Connection *c);

/**
 * Keep an eighth of connection_limit (at least 16) free: past the rest, a
 * new connection closes the one waiting longest for its request.  Long
 * polls may take at most max_waiters of the rest (cut to connection_limit / 2).
 */
void http_guard_set_caps(http *h, int connection_limit, int max_waiters);

/**
 * Join the long polls with w (zeroed by the call): 0, or -1 when
 * --max-waiters is 0 (answer at once; do not call http_waiter_leave).  At
 * the cap the oldest waiter is released (answers with the job's current
 * state at its next slice).  Every 0 is paired with http_waiter_leave.
 */
int http_waiter_join(http *h, http_waiter *w);

/** 1 once w was released for a newer long poll: answer now. */
int http_waiter_released(http *h, http_waiter *w);

/** Leave the long polls (w is no longer referenced). */
void http_waiter_leave(http *h, http_waiter *w);

/** The waiting long polls, the cap and the total answered early, for /metrics. */
void http_waiter_counts(http *h, int *waiting, int *cap, unsigned long long *released);

/** Start the guard thread; HTTP_OK or HTTP_NOMEM. */
int http_guard_start(http *h);

/** Stop and join the guard thread (before MHD_stop_daemon); safe when not started. */
void http_guard_stop(http *h);

/* ---------------------------------------------------------- http_routes.c */

/**
 * Route r by url (decoded, NUL-terminated): sets def, route, tmpl (the
 * template, an embedded file's path, or "other"), file, and id/id_ok for
 * an {id} path.  The table is searched in order, then the embedded files.
 */
void http_route_find(http_req *r, const char *url);

/** The route table (n entries into *n), for the tests; embedded files are not in it. */
const http_route_def *http_route_table(size_t *n);

/** M_* bit of a method name; M_OTHER when it is none of ours. */
unsigned http_method_of(const char *name);

/** The name of an M_* bit ("GET" ...), "OTHER" for M_OTHER: the metrics label. */
const char *http_method_label(unsigned method);

/**
 * Answer a request other than a POST to a route that reads a body, once
 * it is complete: the preflight, 404, 405 + Allow, 401, or the route's
 * handler for its method.
 */
enum MHD_Result http_answer(struct MHD_Connection *c, http_req *r);

/* ------------------------------------------------------------------ http.c */

/**
 * Enter a jobs_* call: 0, or -1 once http_begin_stop has begun (the pool
 * may be gone).  Every 0 is paired with http_leave.
 */
int http_enter(http *h);

/** Leave a jobs_* call entered with http_enter. */
void http_leave(http *h);

/** 1 once http_begin_stop has begun. */
int http_is_stopping(http *h);

#endif /* SPINMODAL_HTTP_INTERNAL_H */
