/*
 * size_units.c — unit checks of the size of a result (issue 23 item 9).
 *
 *   unit_result_size  for requests that use every part of the result document
 *                     (planar and spatial, mode shapes with Coriolis, error
 *                     estimates, engine orders and critical speeds, stations,
 *                     input warnings, speeds without equilibrium and their
 *                     diagnostics): codec_result_text writes the bytes of
 *                     json_dumps(codec_result_encode's document,
 *                     CODEC_RESULT_DUMP) (the daemon stores the first), and the
 *                     estimate of size.c is at least those bytes and not
 *                     wildly more: with max_result_bytes set to the length the
 *                     request is refused (the estimate is larger), with twice
 *                     the length plus the fixed allowance it is accepted.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codec_test.h"

/* The estimate's allowances that do not grow with the result (size.c: document, warnings). */
#define SIZE_UNITS_SLACK 20000

/* A planar tree with shapes (Coriolis: re and im) at three speeds. */
static const char *size_planar =
    "{\"structure\": {\"joints\": {\"O\": [0, 0], \"C\": [5, 0], \"P\": [5, 5]},"
    " \"sections\": {\"al\": {\"E\": 7e10, \"A\": 4e-4, \"I\": 2e-7, \"mass_per_length\": 1.2}},"
    " \"members\": [{\"id\": \"beam1\", \"from\": \"O\", \"to\": \"C\", \"section\": \"al\","
    " \"elements\": 24}, {\"id\": \"beam2\", \"from\": \"C\", \"to\": \"P\", \"section\": \"al\","
    " \"elements\": 24}], \"clamp\": \"O\"},"
    " \"analysis\": {\"omega\": [0, 10, 20], \"modes\": 6, \"mode_shapes\": true}}";

/* A blade with stations, shapes, error estimates and engine orders (critical speeds). */
static const char *size_blade =
    "{\"blade\": {\"length\": 10, \"hub_radius\": 0.5, \"elements\": 16,"
    " \"section\": {\"EA\": 2.8e7, \"EI_flap\": 1.4e4, \"EI_edge\": 5.6e4, \"GJ\": 1.3e4,"
    " \"mass_per_length\": 1.2},"
    " \"stations\": [{\"s\": 0, \"mass_per_length\": 1.5}, {\"s\": 1, \"mass_per_length\": 0.9}]},"
    " \"analysis\": {\"rpm\": {\"from\": 0, \"to\": 600, \"steps\": 12}, \"modes\": 5,"
    " \"mode_shapes\": true, \"error_estimate\": true, \"engine_orders\": [1, 2, 3]}}";

/* A spatial frame without shapes whose section draws input warnings (E and G in MPa): too
 * soft to turn past the first speeds, so its other cases carry diagnostics (PARTIAL). */
static const char *size_warned =
    "{\"structure\": {\"joints\": {\"O\": [0, 0, 0], \"C\": [3, 0, 0.5], \"T\": [6, 0, 1]},"
    " \"sections\": {\"s\": {\"E\": 7e4, \"G\": 2.6e4, \"A\": 4e-4, \"I_flap\": 2e-7,"
    " \"I_edge\": 8e-7, \"J\": 5e-7, \"mass_per_length\": 1.2}},"
    " \"members\": [{\"from\": \"O\", \"to\": \"C\", \"section\": \"s\", \"elements\": 6},"
    " {\"from\": \"C\", \"to\": \"T\", \"section\": \"s\", \"elements\": 6}],"
    " \"clamp\": \"O\"}, \"analysis\": {\"omega\": [0, 1, 2, 3], \"modes\": 4, \"mode_shapes\": false}}";

/* 1 when text validates with max_result_bytes = limit; errs receives the refusal. */
static int size_accepted(const char *text, size_t limit, codec_errors *errs)
{
    codec_limits lim;
    codec_request *req = NULL;
    int st;

    codec_default_limits(&lim);
    lim.max_result_bytes = limit;
    codec_errors_clear(errs);
    st = codec_request_parse(&req, text, strlen(text), &lim, errs);
    codec_request_free(req);
    return st == SM_OK;
}

/* One request: the text against the tree's dump, then the estimate against the length. */
static void size_check_one(test_case *tc, const char *text, const char *what)
{
    codec_errors *errs = codec_errors_new();
    codec_request *req = NULL;
    codec_run_out out;
    char *dump = NULL;
    size_t n;

    memset(&out, 0, sizeof(out));
    if (!errs || codec_request_parse(&req, text, strlen(text), NULL, errs) != SM_OK) {
        fail(tc, "%s rejected: '%s' %s", what, codec_errors_pointer(errs, 0),
             codec_errors_message(errs, 0));
        goto done;
    }
    codec_run(req, CODEC_RUN_JSON | CODEC_RUN_TEXT, NULL, NULL, errs, &out);
    if (out.outcome != CODEC_RUN_DONE && out.outcome != CODEC_RUN_PARTIAL) {
        fail(tc, "%s not solved: %s", what, out.message);
        goto done;
    }
    dump = json_dumps(out.result, CODEC_RESULT_DUMP);
    n = out.result_len;
    if (!dump || !out.result_text || strlen(out.result_text) != n || strcmp(dump, out.result_text))
        fail(tc, "%s: codec_result_text (%zu bytes) differs from the dump of the document (%zu)",
             what, n, dump ? strlen(dump) : 0);
    if (size_accepted(text, n, errs))
        fail(tc, "%s: accepted with max_result_bytes = its result's %zu bytes: the estimate is "
             "below the result", what, n);
    else if (!strstr(codec_errors_message(errs, 0), "the result would be about"))
        fail(tc, "%s: refused at %zu bytes for another reason: '%s' %s", what, n,
             codec_errors_pointer(errs, 0), codec_errors_message(errs, 0));
    if (!size_accepted(text, 2 * n + SIZE_UNITS_SLACK, errs))
        fail(tc, "%s: refused with max_result_bytes = 2 x its result's %zu bytes + %d: %s", what,
             n, SIZE_UNITS_SLACK, codec_errors_message(errs, 0));
done:
    free(dump);
    codec_run_clear(&out);
    codec_request_free(req);
    codec_errors_free(errs);
}

void unit_result_size(test_case *tc)
{
    size_check_one(tc, size_planar, "planar request with shapes");
    size_check_one(tc, size_blade, "blade with error estimate and engine orders");
    size_check_one(tc, size_warned, "spatial frame with input warnings");
}
