/*
 * http_mac.c — GET /v1/analyses/{id}/mac?with=ID2: the MAC table between the
 * modes of two stored results, the same document (or CSV) as `spinmodal
 * compare A B` gives for the two result files (DESIGN.md 9.2).
 *
 * How it fits: one line of http_routes[] (http_routes.c) points here; both
 * results are read from the jobs table or the store as GET .../result reads
 * them, then the codec (server/codec/mac.c) reads their shapes and calls
 * core's sm_mac.  The second id is a query parameter so the route keeps the
 * one {id} of the path templates.  Errors: 404 either id unknown, 409 a
 * result that is missing or cannot be compared (the reason in detail), 400
 * bad query.  Helpers are hm_*.
 */
#include "http_mac.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mac.h"

/* The result document of job id into *doc: JOBS_OK, a jobs_* failure, or JOBS_OK with
 * *doc NULL when the job has no result (yet). */
static int hm_read(http *h, const char *id, json_t **doc)
{
    store_job jb;
    int rc;

    memset(&jb, 0, sizeof(jb));
    *doc = NULL;
    if (http_enter(h) == 0) {
        rc = jobs_get(h->j, id, STORE_WITH_RESULT, &jb);
        http_leave(h);
    } else {
        rc = store_get(h->st, id, STORE_WITH_RESULT, &jb);
        rc = rc == STORE_OK          ? JOBS_OK
             : rc == STORE_NOT_FOUND ? JOBS_NOT_FOUND
             : rc == STORE_NOMEM     ? JOBS_NOMEM
                                     : JOBS_STORE_ERROR;
    }
    if (rc == JOBS_OK && jb.has_result && jb.result)
        *doc = json_loadb(jb.result, jb.result_len, 0, NULL);
    store_job_clear(&jb);
    return rc;
}

/* A case number of the query (name), default def; 0 when not a number from 1. */
static long hm_case(struct MHD_Connection *c, const char *name, long def)
{
    const char *v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, name);
    char *end;
    long k;
    if (!v)
        return def;
    k = strtol(v, &end, 10);
    return *v && !*end && k >= 1 ? k : 0;
}

/* The answer for two loaded results: the table, or 409 with the reason. */
static enum MHD_Result hm_answer(struct MHD_Connection *c, http_req *r, json_t *da, json_t *db,
                                 long ca, long cb, int csv)
{
    codec_mac_set x[2];
    char why[400] = "", *out = NULL;
    size_t n = 0;
    json_t *doc = NULL;
    int st;

    memset(x, 0, sizeof(x));
    st = codec_mac_from_result(&x[0], da, ca, CODEC_MAC_HUB, why, sizeof why);
    if (!st)
        st = codec_mac_from_result(&x[1], db, cb, CODEC_MAC_HUB, why, sizeof why);
    if (!st)
        st = codec_mac_doc(&doc, &x[0], &x[1], CODEC_MAC_HUB, why, sizeof why);
    if (!st)
        st = csv ? codec_mac_csv(&out, &n, doc)
             : (out = json_dumps(doc, JSON_REAL_PRECISION(17) | JSON_COMPACT)) ? SM_OK
                                                                               : SM_NOMEM;
    if (!st && !csv)
        n = strlen(out);
    json_decref(doc);
    codec_mac_set_free(&x[0]);
    codec_mac_set_free(&x[1]);
    if (st == SM_INVALID_INPUT)
        return http_problem(c, r, MHD_HTTP_CONFLICT, "not-comparable", "Not Comparable", why, NULL,
                            0);
    if (st)
        return http_send_oom(c, r);
    return http_respond(c, r, MHD_HTTP_OK, csv ? "text/csv; charset=utf-8" : "application/json",
                        out, n, 1, NULL, 0);
}

enum MHD_Result http_get_mac(struct MHD_Connection *c, http_req *r)
{
    const char *with = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "with");
    const char *format = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "format");
    long ca = hm_case(c, "case", 1), cb = hm_case(c, "case_b", ca);
    json_t *da = NULL, *db = NULL;
    enum MHD_Result q;
    int rc;

    if (!r->id_ok)
        return http_not_found(c, r, 1);
    if (!with || !http_is_id(with, strlen(with)))
        return http_bad_query(c, r, "with", "must be the id of a second analysis");
    if (format && strcmp(format, "json") && strcmp(format, "csv"))
        return http_bad_query(c, r, "format", "must be json or csv");
    if (!ca || !cb)
        return http_bad_query(c, r, ca ? "case_b" : "case", "must be a case number from 1");
    rc = hm_read(r->h, r->id, &da);
    if (rc == JOBS_OK)
        rc = hm_read(r->h, with, &db);
    if (rc != JOBS_OK)
        q = rc == JOBS_NOT_FOUND ? http_not_found(c, r, 1)
            : rc == JOBS_NOMEM   ? http_send_oom(c, r)
                                 : http_unavailable(c, r, "unavailable");
    else if (!da || !db)
        q = http_problem(c, r, MHD_HTTP_CONFLICT, "result-not-available", "Result Not Available",
                         "Both analyses need a result: one has none (yet).", NULL, 0);
    else
        q = hm_answer(c, r, da, db, ca, cb, format && !strcmp(format, "csv"));
    json_decref(da);
    json_decref(db);
    return q;
}
