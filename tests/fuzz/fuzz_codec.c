/*
 * fuzz_codec.c — fuzz target for the request codec (server/codec/).
 *
 * How it fits: libFuzzer (clang -fsanitize=fuzzer, target fuzz_codec) or
 * main.c (the replay driver, any compiler, target fuzz_codec_replay) hands
 * arbitrary bytes to LLVMFuzzerTestOneInput, which treats them as the body of
 * POST /v1/analyses.  The limits are the defaults with small caps (see
 * fuzz_limits) so that one input costs about a millisecond.  Memory errors
 * and undefined behaviour are the sanitizers' to find; this file checks the
 * codec's contract and calls abort() on any violation:
 *
 *   rejected (SM_INVALID_INPUT): no request, 1..CODEC_MAX_ERRORS+1 errors,
 *     each with a valid RFC 6901 pointer and a message; HTTP status 413 iff
 *     the body is over the cap, else 400 iff the text is not JSON, else 422;
 *     a problem document with that status and an "errors" array;
 *   accepted (SM_OK): the SHA-256 is the hash of the canonical text; the
 *     canonical text parses again to the same text and SHA (the canonical
 *     form is a fixed point); the core arrays respect the limits and refer
 *     to existing joints and sections; codec_request_from_json on the same
 *     document agrees with codec_request_parse;
 *     (spatial requests, DESIGN.md 7.3: the spatial block of every section
 *     positive and finite, joint_z present; planar: the spatial fields
 *     zero);
 *   the codec alone (req_parse_codec_only, no core structure check) accepts
 *     whatever codec_request_parse accepts, with the same canonical text,
 *     and what it accepts passes the same array and fixed-point checks, so
 *     the codec's own handling of spatial requests is fuzzed whatever the
 *     core's structure check refuses;
 *   codec_model_new: a model and no error, or no model and at least one
 *     error that becomes a 422 problem document;
 *   tiny models (one speed, at most FUZZ_SOLVE_MAX_ELEMENTS elements) are
 *     also solved, with a budget of progress callbacks, and the result is
 *     encoded as JSON and CSV, which must succeed.
 *
 *   the fast JSON reader (codec_json_fast, server/codec/jsonread.c), with and
 *     without JSON_REJECT_DUPLICATES: a tree only where json_loadb gives one,
 *     and the same tree (../codec/json_same.h: reals by bits, members in order).
 *
 * SM_NOMEM is accepted at every step (it cannot be told from a bug here).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "codec.h"
#include "codec_internal.h" /* req_parse_codec_only, codec_json_fast */
#include "../codec/json_same.h"
#include "fuzz.h"
#include "spinmodal.h"

#define FUZZ_MAX_REQUEST_BYTES 12288 /* body cap: above it the answer is 413 */
#define FUZZ_MAX_ELEMENTS 200        /* FE elements over all members */
#define FUZZ_MAX_SPEEDS 20           /* entries of analysis.omega */
#define FUZZ_SOLVE_MAX_ELEMENTS 8    /* solve only models this small ... */
#define FUZZ_SOLVE_BUDGET 400        /* ... and cancel after this many callbacks */

/* Report a violated invariant and abort (a crash for libFuzzer). */
static void fuzz_fail(const char *cond, int line)
{
    fprintf(stderr, "fuzz_codec.c:%d: invariant violated: %s\n", line, cond);
    abort();
}

#define FUZZ_CHECK(cond)                  \
    do {                                  \
        if (!(cond))                      \
            fuzz_fail(#cond, __LINE__);   \
    } while (0)

/* The limits of one run: defaults with small caps. */
static void fuzz_limits(codec_limits *lim)
{
    codec_default_limits(lim);
    lim->max_request_bytes = FUZZ_MAX_REQUEST_BYTES;
    lim->max_elements = FUZZ_MAX_ELEMENTS;
    lim->max_speeds = FUZZ_MAX_SPEEDS;
}

/* 1 when p is "" or a valid RFC 6901 pointer ("/a/b~0c~1d"). */
static int fuzz_valid_pointer(const char *p)
{
    if (p[0] == '\0')
        return 1;
    if (p[0] != '/')
        return 0;
    for (; *p; p++)
        if (*p == '~' && p[1] != '0' && p[1] != '1')
            return 0;
    return 1;
}

/* A non-empty error list: pointers, messages, its JSON form. */
static void fuzz_check_errors(const codec_errors *errs)
{
    int i, n = codec_errors_count(errs);
    json_t *arr;

    FUZZ_CHECK(n >= 1 && n <= CODEC_MAX_ERRORS + 1);
    for (i = 0; i < n; i++) {
        const char *p = codec_errors_pointer(errs, i);
        const char *m = codec_errors_message(errs, i);
        FUZZ_CHECK(p != NULL && fuzz_valid_pointer(p));
        FUZZ_CHECK(m != NULL && m[0] != '\0');
    }
    FUZZ_CHECK(codec_errors_pointer(errs, n) == NULL);
    FUZZ_CHECK(codec_errors_message(errs, -1) == NULL);
    arr = codec_errors_to_json(errs);
    FUZZ_CHECK(arr != NULL && json_array_size(arr) == (size_t)n);
    json_decref(arr);
}

/* The problem document of a failed request: status, errors, serializable. */
static void fuzz_check_problem(const codec_errors *errs, int want_status)
{
    int status = codec_errors_http_status(errs);
    json_t *p;
    char *text;

    FUZZ_CHECK(status == 400 || status == 413 || status == 422);
    FUZZ_CHECK(status == want_status);
    p = codec_problem_from_errors(errs);
    FUZZ_CHECK(p != NULL);
    FUZZ_CHECK(json_integer_value(json_object_get(p, "status")) == status);
    FUZZ_CHECK(json_is_string(json_object_get(p, "title")));
    FUZZ_CHECK(json_array_size(json_object_get(p, "errors")) ==
               (size_t)codec_errors_count(errs));
    text = json_dumps(p, JSON_COMPACT);
    FUZZ_CHECK(text != NULL);
    free(text);
    json_decref(p);
}

/* The core view of an accepted request stays within the limits. */
static void fuzz_check_arrays(const codec_request *r, const codec_limits *lim)
{
    const sm_structure *st = codec_request_structure(r);
    const sm_options *opt = codec_request_options(r);
    const double *w;
    long total = 0;
    int i, n;

    w = codec_request_speeds(r, &n);
    FUZZ_CHECK(n >= 1 && n <= lim->max_speeds && w != NULL);
    for (i = 0; i < n; i++)
        FUZZ_CHECK(isfinite(w[i]) && w[i] >= 0);
    FUZZ_CHECK(st->n_joints >= 1 && st->n_joints <= lim->max_joints);
    FUZZ_CHECK(st->n_sections >= 1 && st->n_sections <= lim->max_sections);
    FUZZ_CHECK(st->n_members >= 1 && st->n_members <= lim->max_members);
    FUZZ_CHECK(st->n_point_masses >= 0 && st->n_point_masses <= lim->max_point_masses);
    FUZZ_CHECK(st->clamp >= 0 && st->clamp < st->n_joints);
    for (i = 0; i < 2 * st->n_joints; i++)
        FUZZ_CHECK(isfinite(st->joint_xy[i]));
    for (i = 0; i < st->n_joints; i++) {
        const char *a = codec_request_joint_name(r, i);
        FUZZ_CHECK(a != NULL);
        if (i > 0)
            FUZZ_CHECK(strcmp(codec_request_joint_name(r, i - 1), a) < 0);
    }
    FUZZ_CHECK(codec_request_joint_name(r, st->n_joints) == NULL);
    FUZZ_CHECK(st->spatial == 0 || st->spatial == 1);
    FUZZ_CHECK(st->spatial ? st->joint_z != NULL : st->joint_z == NULL);
    for (i = 0; st->joint_z && i < st->n_joints; i++)
        FUZZ_CHECK(isfinite(st->joint_z[i]));
    for (i = 0; i < st->n_sections; i++) {
        const sm_section *s = &st->sections[i];
        FUZZ_CHECK(s->mu > 0 && isfinite(s->mu));
        if (!st->spatial) { /* planar: E, A, I, mu; the spatial block zero */
            FUZZ_CHECK(s->E > 0 && s->A > 0 && s->I > 0);
            FUZZ_CHECK(isfinite(s->E) && isfinite(s->A) && isfinite(s->I));
            FUZZ_CHECK(s->EA == 0 && s->EI_flap == 0 && s->EI_edge == 0 && s->GJ == 0 &&
                       s->i_flap == 0 && s->i_edge == 0 && s->ip_over_a == 0);
            continue;
        }
        /* spatial (DESIGN.md 7.3): the spatial block positive and finite, E, A, I zero */
        FUZZ_CHECK(s->EA > 0 && s->EI_flap > 0 && s->EI_edge > 0 && s->GJ > 0);
        FUZZ_CHECK(isfinite(s->EA) && isfinite(s->EI_flap) && isfinite(s->EI_edge) &&
                   isfinite(s->GJ));
        FUZZ_CHECK(s->i_flap > 0 && s->i_edge > 0 && s->ip_over_a >= 0); /* 0: given, Wagner off */
        FUZZ_CHECK(isfinite(s->i_flap) && isfinite(s->i_edge) && isfinite(s->ip_over_a));
        FUZZ_CHECK(s->E == 0 && s->A == 0 && s->I == 0);
    }
    for (i = 0; i < st->n_members; i++) {
        const sm_member *m = &st->members[i];
        FUZZ_CHECK(m->from >= 0 && m->from < st->n_joints);
        FUZZ_CHECK(m->to >= 0 && m->to < st->n_joints && m->to != m->from);
        FUZZ_CHECK(m->section >= 0 && m->section < st->n_sections);
        FUZZ_CHECK(m->elements >= 1 && m->elements <= lim->max_elements);
        FUZZ_CHECK(isfinite(m->twist) && isfinite(m->e3[0]) && isfinite(m->e3[1]) &&
                   isfinite(m->e3[2]));
        if (!st->spatial) /* planar: no twist, no e3 */
            FUZZ_CHECK(m->twist == 0 && m->e3[0] == 0 && m->e3[1] == 0 && m->e3[2] == 0);
        total += m->elements;
    }
    FUZZ_CHECK(total <= lim->max_elements);
    for (i = 0; i < st->n_point_masses; i++) {
        const sm_point_mass *pm = &st->point_masses[i];
        FUZZ_CHECK(pm->joint >= 0 && pm->joint < st->n_joints);
        FUZZ_CHECK(isfinite(pm->mass) && pm->mass >= 0);
        FUZZ_CHECK(pm->inertia[0] >= 0 && pm->inertia[1] >= 0 && pm->inertia[2] >= 0);
        FUZZ_CHECK(isfinite(pm->inertia[0]) && isfinite(pm->inertia[1]) &&
                   isfinite(pm->inertia[2]));
        if (!st->spatial)
            FUZZ_CHECK(pm->inertia[0] == 0 && pm->inertia[1] == 0 && pm->inertia[2] == 0);
    }
    FUZZ_CHECK(opt->modes >= 1 && opt->modes <= lim->max_modes);
}

/* SHA-256 of the canonical text, and the canonical form is a fixed point. */
static void fuzz_check_canonical(const codec_request *r, const codec_limits *lim)
{
    const char *text = codec_request_canonical_text(r);
    const char *sha = codec_request_sha256(r);
    codec_limits big = *lim;
    codec_request *again = NULL;
    codec_errors *errs;
    char hex[65];
    int rc;

    FUZZ_CHECK(text != NULL && sha != NULL && strlen(sha) == 64);
    FUZZ_CHECK(codec_request_canonical(r) != NULL);
    if (codec_sha256_hex(text, strlen(text), hex) != SM_OK)
        return;
    FUZZ_CHECK(strcmp(hex, sha) == 0);

    big.max_request_bytes = SIZE_MAX; /* defaults and 17 digits make it longer */
    errs = codec_errors_new();
    if (!errs)
        return;
    rc = codec_request_parse(&again, text, strlen(text), &big, errs);
    if (rc != SM_NOMEM) {
        if (rc != SM_OK && codec_errors_count(errs) > 0)
            fprintf(stderr, "canonical text rejected at '%s': %s\n%s\n",
                    codec_errors_pointer(errs, 0), codec_errors_message(errs, 0), text);
        FUZZ_CHECK(rc == SM_OK && again != NULL);
        FUZZ_CHECK(strcmp(codec_request_canonical_text(again), text) == 0);
        FUZZ_CHECK(strcmp(codec_request_sha256(again), sha) == 0);
    }
    codec_request_free(again);
    codec_errors_free(errs);
}

/* Progress callback: cancels the solve once the budget is spent. */
static int fuzz_budget(void *user, int done, int total)
{
    int *left = user;

    (void)done;
    (void)total;
    return --*left < 0;
}

/* Solve a tiny model at its one speed and encode the result. */
static void fuzz_check_solve(const codec_request *r, const sm_model *m)
{
    const sm_structure *st = codec_request_structure(r);
    const double *w;
    sm_result *res = NULL;
    sm_diag d;
    json_t *doc = NULL;
    char *text = NULL;
    size_t len = 0;
    long total = 0;
    int i, n, rc, budget = FUZZ_SOLVE_BUDGET;

    w = codec_request_speeds(r, &n);
    for (i = 0; i < st->n_members; i++)
        total += st->members[i].elements;
    if (n != 1 || total > FUZZ_SOLVE_MAX_ELEMENTS)
        return;
    memset(&d, 0, sizeof(d));
    rc = sm_solve(m, w, n, fuzz_budget, &budget, &res, &d);
    if (rc != SM_OK) {
        /* speeds the codec accepted must be accepted by the core */
        FUZZ_CHECK(rc == SM_CANCELED || rc == SM_NOMEM || rc == SM_LAPACK_FAILED);
        FUZZ_CHECK(res == NULL);
        return;
    }
    FUZZ_CHECK(res != NULL && res->n_cases == 1);
    rc = codec_result_encode(&doc, r, m, res);
    FUZZ_CHECK(rc == SM_OK && doc != NULL);
    text = json_dumps(doc, JSON_COMPACT);
    FUZZ_CHECK(text != NULL);
    free(text);
    json_decref(doc);
    rc = codec_result_csv(&text, &len, r, res);
    FUZZ_CHECK(rc == SM_OK && text != NULL && len == strlen(text));
    free(text);
    sm_result_free(res);
}

/* codec_model_new: a model, or no model and errors for a 422. */
static void fuzz_check_model(const codec_request *r)
{
    codec_errors *errs = codec_errors_new();
    sm_model *m = NULL;
    sm_diag d;
    int rc;

    if (!errs)
        return;
    rc = codec_model_new(&m, r, errs, &d);
    if (rc == SM_OK) {
        FUZZ_CHECK(m != NULL && codec_errors_count(errs) == 0);
        fuzz_check_solve(r, m);
    } else if (rc != SM_NOMEM) {
        FUZZ_CHECK(m == NULL && d.status == rc);
        fuzz_check_errors(errs);
        fuzz_check_problem(errs, 422);
    }
    sm_model_free(m);
    codec_errors_free(errs);
}

/* codec_request_from_json on the parsed document agrees with the parse. */
static void fuzz_check_from_json(const json_t *root, const codec_request *parsed, int parsed_rc,
                                 const codec_limits *lim)
{
    codec_errors *errs = codec_errors_new();
    codec_request *r = NULL;
    int rc;

    if (!errs)
        return;
    rc = codec_request_from_json(&r, root, lim, errs);
    if (rc != SM_NOMEM && parsed_rc != SM_NOMEM) {
        FUZZ_CHECK(rc == parsed_rc);
        if (rc == SM_OK)
            FUZZ_CHECK(strcmp(codec_request_sha256(r), codec_request_sha256(parsed)) == 0);
        else
            FUZZ_CHECK(r == NULL && codec_errors_count(errs) >= 1);
    }
    codec_request_free(r);
    codec_errors_free(errs);
}

/*
 * The codec alone on the same input: accepts what the full parse accepted
 * (full: its request, or NULL), with the same canonical text; what it
 * accepts has sound arrays and a canonical text that is a fixed point.
 */
static void fuzz_check_codec_only(const uint8_t *data, size_t size, const codec_limits *lim,
                                  const codec_request *full)
{
    codec_limits big = *lim;
    codec_errors *errs = codec_errors_new(), *errs2 = codec_errors_new();
    codec_request *r = NULL, *again = NULL;
    const char *text;
    int rc;

    if (!errs || !errs2)
        goto done;
    rc = req_parse_codec_only(&r, (const char *)data, size, lim, errs);
    if (rc == SM_NOMEM)
        goto done;
    if (full)
        FUZZ_CHECK(rc == SM_OK &&
                   !strcmp(codec_request_canonical_text(r), codec_request_canonical_text(full)));
    if (rc != SM_OK) {
        FUZZ_CHECK(r == NULL && codec_errors_count(errs) > 0);
        goto done;
    }
    fuzz_check_arrays(r, lim);
    text = codec_request_canonical_text(r);
    big.max_request_bytes = SIZE_MAX;
    rc = req_parse_codec_only(&again, text, strlen(text), &big, errs2);
    if (rc != SM_NOMEM) {
        FUZZ_CHECK(rc == SM_OK && again != NULL);
        FUZZ_CHECK(strcmp(codec_request_canonical_text(again), text) == 0);
    }
done:
    codec_request_free(again);
    codec_request_free(r);
    codec_errors_free(errs2);
    codec_errors_free(errs);
}

/* codec_json_fast against json_loadb (ref: its tree with JSON_REJECT_DUPLICATES, or NULL);
 * a tree only where jansson gives one, and the same tree.  have_ref: ref was read (the body is
 * within the cap). */
static void fuzz_json_fast(const uint8_t *data, size_t size, int have_ref, const json_t *ref)
{
    const char *text = (const char *)data;
    json_t *fast = codec_json_fast(text, size, JSON_REJECT_DUPLICATES);
    if (have_ref)
        FUZZ_CHECK(!fast || json_same(fast, ref));
    json_decref(fast);
    json_t *any = json_loadb(text, size, 0, NULL);
    fast = codec_json_fast(text, size, 0);
    FUZZ_CHECK(!fast || json_same(fast, any));
    json_decref(fast);
    json_decref(any);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    codec_limits lim;
    codec_errors *errs;
    codec_request *r = NULL;
    json_t *root = NULL;
    json_error_t jerr;
    int rc, want;

    fuzz_limits(&lim);
    errs = codec_errors_new();
    if (!errs)
        return 0;
    rc = codec_request_parse(&r, (const char *)data, size, &lim, errs);
    if (size <= lim.max_request_bytes)
        root = json_loadb((const char *)data, size, JSON_REJECT_DUPLICATES, &jerr);
    fuzz_json_fast(data, size, size <= lim.max_request_bytes, root);

    if (rc == SM_OK) {
        FUZZ_CHECK(r != NULL && root != NULL && codec_errors_count(errs) == 0);
        fuzz_check_arrays(r, &lim);
        fuzz_check_canonical(r, &lim);
        fuzz_check_model(r);
    } else if (rc == SM_INVALID_INPUT) {
        FUZZ_CHECK(r == NULL);
        FUZZ_CHECK(codec_errors_too_large(errs) == (size > lim.max_request_bytes));
        FUZZ_CHECK(codec_errors_malformed(errs) == (size <= lim.max_request_bytes && !root));
        want = size > lim.max_request_bytes ? 413 : root ? 422 : 400;
        fuzz_check_errors(errs);
        fuzz_check_problem(errs, want);
    } else {
        FUZZ_CHECK(rc == SM_NOMEM && r == NULL);
    }
    if (root)
        fuzz_check_from_json(root, r, rc, &lim);
    if (rc != SM_NOMEM)
        fuzz_check_codec_only(data, size, &lim, rc == SM_OK ? r : NULL);

    json_decref(root);
    codec_request_free(r);
    codec_errors_free(errs);
    return 0;
}
