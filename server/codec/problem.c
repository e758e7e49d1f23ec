/*
 * problem.c — RFC 9457 problem documents for the codec's errors.
 *
 * How it fits: when codec_request_parse or codec_model_new fails, the CLI
 * prints and the daemon sends codec_problem_from_errors: the HTTP status
 * follows from the error list (400 not JSON, 413 too large, 422 invalid
 * model, DESIGN.md section 5) and the list itself (errors.c) becomes the
 * "errors" member.  The daemon also builds its other problems (404, 429,
 * 503...) with codec_problem_new.
 */
#include "codec_internal.h"

#include <stdio.h>

json_t *codec_problem_new(int http_status, const char *type, const char *title,
                          const char *detail, const codec_errors *errs)
{
    json_t *p = json_pack("{s:s, s:s, s:i}", "type", type ? type : "about:blank", "title",
                          title ? title : "Error", "status", http_status);

    if (!p)
        return NULL;
    if (detail && json_object_set_new(p, "detail", json_string(detail)))
        goto fail;
    if (errs && codec_errors_count(errs) > 0 &&
        json_object_set_new(p, "errors", codec_errors_to_json(errs)))
        goto fail;
    return p;
fail:
    json_decref(p);
    return NULL;
}

int codec_errors_http_status(const codec_errors *e)
{
    if (codec_errors_too_large(e))
        return 413;
    if (codec_errors_malformed(e))
        return 400;
    return 422;
}

json_t *codec_problem_from_errors(const codec_errors *errs)
{
    int status = codec_errors_http_status(errs), n = codec_errors_count(errs);
    char detail[96];

    switch (status) {
    case 413:
        return codec_problem_new(413, NULL, "Content Too Large",
                                 "The request is larger than the configured limit.", errs);
    case 400:
        return codec_problem_new(400, NULL, "Bad Request", "The request is not valid JSON.",
                                 errs);
    default:
        snprintf(detail, sizeof(detail), "The request has %d error%s; see 'errors'.", n,
                 n == 1 ? "" : "s");
        return codec_problem_new(422, NULL, "Unprocessable Content", detail, errs);
    }
}
