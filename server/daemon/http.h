/*
 * http.h — the HTTP front of spinmodald (libmicrohttpd).
 *
 * One libmicrohttpd daemon with a thread per connection (so `?wait=S` can
 * block in jobs_wait without holding up other clients).  It routes the
 * requests of server/DAEMON.md to the codec (validation), the job pool
 * (submit, cancel, wait, live progress), the store (results, listings,
 * readiness) and the metrics, answers errors as RFC 9457 problem
 * documents, checks the bearer token of POST/DELETE, adds CORS headers,
 * counts every response in the metrics and logs one `request` line per
 * request.
 *
 * Stopping is two-step: http_begin_stop (POST answers 503, the handlers
 * let go of the job pool so jobs_stop may free it, status reads go to the
 * store), then http_stop after jobs_stop.
 */
#ifndef SPINMODAL_HTTP_H
#define SPINMODAL_HTTP_H

#include <stddef.h>

#include "codec.h"
#include "jobs.h"
#include "metrics.h"
#include "store.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Return codes of http_start. */
typedef enum http_rc {
    HTTP_OK = 0,
    HTTP_NOMEM = -1,    /* out of memory */
    HTTP_ADDRESS = -2,  /* host is not an address (or a name that resolves) */
    HTTP_LISTEN = -3    /* cannot listen (port taken, permission); the cause is logged */
} http_rc;

/** Settings of the HTTP server. */
typedef struct http_config {
    const char *host;            /* address to bind: IPv4, IPv6 (no brackets) or a name */
    int port;                    /* 0..65535; 0 = any free port (http_port tells which) */
    size_t max_body;             /* bytes of request body, larger is 413 */
    codec_limits limits;         /* request validation limits (max_request_bytes = max_body) */
    const char *token;           /* bearer token for POST/DELETE, NULL = no auth; copied */
    const char *cors_origin;     /* Access-Control-Allow-Origin, NULL = no CORS; copied */
    int auth_reads;              /* 1: with a token, reads of jobs, /metrics and /v1/validate
                                    need it too (probes and static files never do) */
    unsigned connection_limit;   /* concurrent connections (threads), >= 1 */
    unsigned per_client_limit;   /* concurrent connections from one IP address, 0 = no limit */
    unsigned max_waiters;        /* concurrent ?wait long polls (GET and POST): a new one over
                                    it answers the oldest at once; 0 = ?wait never blocks;
                                    at most connection_limit / 2 (larger is cut to it) */
    unsigned connection_timeout; /* s of idleness before a connection is closed */
    double request_deadline;     /* s for a request's head and body to arrive, > 0 */
} http_config;

/**
 * Defaults: host 127.0.0.1, port 8080, max_body 1 MiB, the codec's default
 * limits, no token, no CORS, 512 connections of which at most 64 from one
 * address and at most 128 waiting long polls, 60 s idle timeout, 30 s
 * request deadline.
 *
 * Slots: an eighth of connection_limit (at least 16) is kept free for
 * probes and writes; over the rest a new connection closes the connection
 * that has waited longest for its request (http_guard.c).  Long polls have
 * their own budget, max_waiters, within the rest.
 */
void http_default_config(http_config *cfg);

typedef struct http http;   /* opaque */

/**
 * Start listening and serving.  j, st and mx are borrowed: st and mx must
 * outlive the server; j must stay valid until http_begin_stop returns.
 * cfg is read during the call only (strings are copied).  On failure *out
 * is NULL.  Returns HTTP_OK, HTTP_NOMEM, HTTP_ADDRESS or HTTP_LISTEN.
 */
int http_start(http **out, const http_config *cfg, jobs *j, store *st, metrics *mx);

/** The port actually bound (the chosen one when cfg->port was 0). */
int http_port(const http *h);

/**
 * Begin the stop: from now on POST and DELETE answer 503 (+ Retry-After),
 * /readyz answers 503, waits answer at once, and status reads come from
 * the store.  Blocks until no request thread is inside a jobs_* call
 * (at most a fraction of a second), so the caller may then jobs_stop the
 * pool.  The server keeps serving until http_stop.  NULL is a no-op.
 */
void http_begin_stop(http *h);

/**
 * Stop: close the listening socket and every connection, join their
 * threads, free the server.  Calls http_begin_stop first if needed.
 * NULL is a no-op.
 */
void http_stop(http *h);

#ifdef __cplusplus
}
#endif

#endif /* SPINMODAL_HTTP_H */
