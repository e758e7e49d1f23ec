/*
 * http_import.c — POST /v1/import/{bmodes|elastodyn|csv}: a blade file in,
 * the import document {"request", "warnings", "source"} out (200), or a 422
 * problem document naming the file, line and field that is wrong.
 *
 * How it fits: the format of the path is looked up in the codec's table
 * import_formats[] (its parser, its default file name, whether it reads a
 * second file: no format is named here).  Routed by http.c like /v1/validate
 * (a POST whose body is collected by http_take_body under --max-body, the
 * same guards and deadlines), but answered here: no request is validated, no
 * model built, nothing stored or queued.  The importers
 * (server/codec/import.h) only read the text once, linearly, so the cost is
 * bounded by --max-body.
 *
 * Bodies: BModes needs two files, so it takes JSON {"main": ".bmi text",
 * "sec_props": "section file text", "name": "optional .bmi name"};
 * elastodyn and csv take the same JSON (without sec_props) or the raw text
 * (text/plain, text/csv or application/octet-stream).  Query parameters:
 * tip_radius, hub_radius (numbers), rpm (a number, a list 0,5,10 or a range
 * START:STOP:COUNT: import_rpm_option, as the CLI's --rpm) and name (the
 * file name used in messages).  The token is needed only under
 * --auth-reads (as for /v1/validate: nothing is written).
 */
#include "http_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "import.h"

/* Which body a file came from, for the pointer of a 422. */
typedef struct http_import_in {
    const import_format *format; /* from the path: an entry of import_formats[] */
    int json;              /* the body is JSON */
    import_file main;      /* the .bmi / blade file / CSV */
    import_file sec;       /* BModes section file (JSON "sec_props") */
    const json_t *files;   /* IMPORT_NAMED_FILES: JSON "files" {NAME: text} (borrowed), or NULL */
    import_options opt;
    json_t *rpm_speeds;    /* ?rpm= as a list or range (opt.rpm_speeds), NULL for one speed */
} http_import_in;

/* The format of the path /v1/import/{format}, in the codec's table (routed only when known:
 * import_format_known; NULL otherwise). */
static const import_format *http_import_format(const http_req *r)
{
    return import_format_find(r->path + strlen("/v1/import/"));
}

/* 1 when the media type of ct (parameters ignored) is mt. */
static int http_import_ctype(const char *ct, const char *mt)
{
    size_t n = strlen(mt);

    if (!ct)
        return 0;
    while (*ct == ' ' || *ct == '\t')
        ct++;
    return strncasecmp(ct, mt, n) == 0 &&
           (ct[n] == '\0' || ct[n] == ';' || ct[n] == ' ' || ct[n] == '\t');
}

int http_import_begin(struct MHD_Connection *c, http_req *r, enum MHD_Result *q)
{
    const char *ct = MHD_lookup_connection_value(c, MHD_HEADER_KIND,
                                                 MHD_HTTP_HEADER_CONTENT_TYPE);
    const char *cl = MHD_lookup_connection_value(c, MHD_HEADER_KIND,
                                                 MHD_HTTP_HEADER_CONTENT_LENGTH);
    int json = http_import_ctype(ct, "application/json");
    int text = http_import_ctype(ct, "text/plain") || http_import_ctype(ct, "text/csv") ||
               http_import_ctype(ct, "application/octet-stream");
    const import_format *fmt = http_import_format(r);
    int two_files = fmt && (fmt->flags & IMPORT_SEC_FILE);
    char detail[200];
    long long n = 0;

    if (!fmt) {
        *q = http_not_found(c, r, 0);
        return 0;
    }
    if (r->h->auth_reads && !http_authorized(r->h, c)) {
        *q = http_unauthorized(c, r);
        return 0;
    }
    if (!json && (!text || two_files)) {
        snprintf(detail, sizeof(detail), "A %s import is JSON {\"main\": \"...\", "
                 "\"sec_props\": \"...\"} (Content-Type: application/json).", fmt->label);
        *q = http_problem(c, r, MHD_HTTP_UNSUPPORTED_MEDIA_TYPE, NULL, "Unsupported Media Type",
                          two_files ? detail
                                    : "The body is the file (Content-Type: text/plain, text/csv "
                                      "or application/octet-stream) or JSON {\"main\": "
                                      "\"...\"} (application/json).",
                          NULL, 0);
        return 0;
    }
    if (cl && (http_parse_int(cl, 0, (long long)r->h->max_body, &n) ||
               (size_t)n > r->h->max_body)) {
        *q = http_too_large(c, r);
        return 0;
    }
    r->announced = cl ? (size_t)n : 0;
    return 1;
}

/* 400 with a detail. */
static enum MHD_Result http_import_bad(struct MHD_Connection *c, http_req *r,
                                       const char *pointer, const char *message)
{
    codec_errors *errs = codec_errors_new();
    json_t *p = NULL;

    if (errs && codec_errors_add(errs, pointer, "%s", message) == SM_OK)
        p = codec_problem_new(MHD_HTTP_BAD_REQUEST, NULL, "Bad Request",
                              "The import body is not usable.", errs);
    codec_errors_free(errs);
    return http_respond_problem(c, r, MHD_HTTP_BAD_REQUEST, p, NULL, 0);
}

/* The query parameters into in->opt and in->main.name; 0, or -1 after a 400. */
static int http_import_query(struct MHD_Connection *c, http_req *r, http_import_in *in,
                             enum MHD_Result *q)
{
    static const char *const names[2] = {"tip_radius", "hub_radius"};
    double *dst[2] = {&in->opt.tip_radius, &in->opt.hub_radius};
    const char *v;
    char *end, why[200];
    int k;

    for (k = 0; k < 2; k++) {
        v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, names[k]);
        if (!v)
            continue;
        *dst[k] = strtod(v, &end);
        if (end == v || *end != '\0' || !isfinite(*dst[k]) || *dst[k] < 0.0) {
            *q = http_bad_query(c, r, names[k], "expected a number >= 0");
            return -1;
        }
    }
    v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "rpm");
    k = v ? import_rpm_option(v, &in->opt, &in->rpm_speeds, why, sizeof(why)) : SM_OK;
    if (k) {
        *q = k == SM_NOMEM ? http_send_oom(c, r) : http_bad_query(c, r, "rpm", why);
        return -1;
    }
    v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "bmodes_mesh");
    if (v) { /* BModes' own model, this many FE elements per BModes element (import.h) */
        long per = strtol(v, &end, 10);
        if (end == v || *end != '\0' || per < 1 || per > 1000) {
            *q = http_bad_query(c, r, "bmodes_mesh", "expected a whole number 1 to 1000");
            return -1;
        }
        in->opt.bmodes_mesh = (int)per;
    }
    v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "name");
    if (v && *v)
        in->main.name = v;
    return 0;
}

/* A JSON body: main, sec_props, name; 0, or -1 after a 400/422 (*q). doc keeps the texts. */
static int http_import_json(struct MHD_Connection *c, http_req *r, http_import_in *in,
                            json_t **doc, enum MHD_Result *q)
{
    int two = (in->format->flags & IMPORT_SEC_FILE) != 0; /* main and sec_props */
    int named = (in->format->flags & IMPORT_NAMED_FILES) != 0; /* main and files */
    const char *key;
    json_error_t jerr;
    json_t *v;

    *doc = json_loadb(r->body ? r->body : "", r->len, JSON_REJECT_DUPLICATES, &jerr);
    if (!*doc || !json_is_object(*doc)) {
        *q = http_import_bad(c, r, "", *doc ? "the body must be a JSON object" : jerr.text);
        return -1;
    }
    json_object_foreach(*doc, key, v) {
        if (strcmp(key, "main") && strcmp(key, "name") && (!two || strcmp(key, "sec_props")) &&
            (!named || strcmp(key, "files"))) {
            char pointer[80];
            snprintf(pointer, sizeof(pointer), "/%.60s", key);
            *q = http_import_bad(c, r, pointer,
                                 two     ? "unknown key; expected main, sec_props and name"
                                 : named ? "unknown key; expected main, files and name"
                                         : "unknown key; expected main and name");
            return -1;
        }
        if (named && !strcmp(key, "files")) { /* {NAME: text}: the files the main file names */
            const char *fk;
            json_t *fv;
            int ok = json_is_object(v);
            json_object_foreach(v, fk, fv)
                ok &= json_is_string(fv);
            if (!ok) {
                *q = http_import_bad(c, r, "/files",
                                     "must be an object of the named files' texts {\"NAME\": "
                                     "\"text\"}, NAME as the main file writes it");
                return -1;
            }
            in->files = v;
            continue;
        }
        if (!json_is_string(v)) {
            char pointer[80];
            snprintf(pointer, sizeof(pointer), "/%s", key);
            *q = http_import_bad(c, r, pointer, "must be a string (the file's text)");
            return -1;
        }
    }
    if (!json_object_get(*doc, "main") || (two && !json_object_get(*doc, "sec_props"))) {
        const char *miss = json_object_get(*doc, "main") ? "/sec_props" : "/main";
        *q = http_import_bad(c, r, miss, two ? "required: the .bmi text (main) and the "
                             "section-properties file's text (sec_props)"
                             : "required: the file's text");
        return -1;
    }
    v = json_object_get(*doc, "main");
    in->main.text = json_string_value(v);
    in->main.len = json_string_length(v);
    if ((v = json_object_get(*doc, "name")) && json_string_length(v) > 0)
        in->main.name = json_string_value(v);
    if ((v = json_object_get(*doc, "sec_props"))) {
        in->sec.text = json_string_value(v);
        in->sec.len = json_string_length(v);
    }
    return 0;
}

/* import_loader: the JSON's sec_props, under the name the .bmi gives it; with "files", the
 * text given under the name the main file writes (or its last path component). */
static int http_import_load(void *ctx, const char *name, import_file *out, char *why,
                            size_t cap)
{
    const http_import_in *in = ctx;
    const json_t *t;
    const char *base = strrchr(name, '/');

    *out = in->sec;
    out->name = NULL;
    if (!(in->format->flags & IMPORT_NAMED_FILES))
        return SM_OK;
    t = json_object_get(in->files, name);
    if (!t && base)
        t = json_object_get(in->files, base + 1);
    if (!t) {
        snprintf(why, cap, "not in the request's \"files\": give its text as files[\"%s\"]",
                 base ? base + 1 : name);
        return SM_INVALID_INPUT;
    }
    out->text = json_string_value(t);
    out->len = json_string_length(t);
    return SM_OK;
}

/* 422 for a refused file: errors[0] points at the body member (or query) that held it. */
static enum MHD_Result http_import_refused(struct MHD_Connection *c, http_req *r,
                                           const http_import_in *in, const import_diag *d)
{
    codec_errors *errs = codec_errors_new();
    char pointer[80] = "";
    json_t *p = NULL;

    if (d->line == 0 && (!strcmp(d->field, "tip_radius") || !strcmp(d->field, "hub_radius") ||
                         !strcmp(d->field, "rpm")))
        snprintf(pointer, sizeof(pointer), "/query/%s", d->field);
    else if (in->json && in->main.name && !strcmp(d->file, in->main.name))
        snprintf(pointer, sizeof(pointer), "/main");
    else if (in->json && in->files) { /* a named file: /files/NAME (as a JSON pointer) */
        const char *base = strrchr(d->file, '/'), *key = d->file;
        if (!json_object_get(in->files, key) && base)
            key = base + 1;
        size_t n = strlen("/files/");
        memcpy(pointer, "/files/", n + 1);
        for (; *key && n + 3 < sizeof(pointer); key++) { /* RFC 6901: ~ -> ~0, / -> ~1 */
            if (*key == '~' || *key == '/') {
                pointer[n++] = '~';
                pointer[n++] = *key == '~' ? '0' : '1';
            } else {
                pointer[n++] = *key;
            }
        }
        pointer[n] = '\0';
    } else if (in->json)
        snprintf(pointer, sizeof(pointer), "/sec_props");
    if (errs && codec_errors_add(errs, pointer, "%s", d->text) == SM_OK)
        p = codec_problem_new(MHD_HTTP_UNPROCESSABLE_CONTENT, HTTP_PROBLEMS "import-invalid",
                              "Unprocessable Content", d->text, errs);
    codec_errors_free(errs);
    if (p && (json_object_set_new(p, "file", json_string(d->file)) ||
              json_object_set_new(p, "line", json_integer(d->line)) ||
              json_object_set_new(p, "field", json_string(d->field)))) {
        json_decref(p);
        p = NULL;
    }
    return http_respond_problem(c, r, MHD_HTTP_UNPROCESSABLE_CONTENT, p, NULL, 0);
}

/* Run the importer and answer. */
static enum MHD_Result http_import_run(struct MHD_Connection *c, http_req *r, http_import_in *in)
{
    import_diag d;
    json_t *doc = NULL;
    char *text;
    int st;

    in->opt.max_modes = r->h->limits.max_modes;
    st = in->format->parse(&doc, &in->main, http_import_load, in, &in->opt, &d);
    if (st == SM_INVALID_INPUT)
        return http_import_refused(c, r, in, &d);
    if (st != SM_OK)
        return http_send_oom(c, r);
    text = import_dumps(doc, 0);
    json_decref(doc);
    if (!text)
        return http_send_oom(c, r);
    return http_respond(c, r, MHD_HTTP_OK, "application/json", text, strlen(text), 1, NULL, 0);
}

enum MHD_Result http_import_end(struct MHD_Connection *c, http_req *r)
{
    const char *ct = MHD_lookup_connection_value(c, MHD_HEADER_KIND,
                                                 MHD_HTTP_HEADER_CONTENT_TYPE);
    http_import_in in;
    enum MHD_Result q;
    json_t *doc = NULL;
    char names[100], why[140];

    if (r->body_state == BODY_TOO_LARGE)
        return http_too_large(c, r);
    if (r->body_state == BODY_NOMEM)
        return http_send_oom(c, r);
    memset(&in, 0, sizeof(in));
    if (!(in.format = http_import_format(r)))
        return http_not_found(c, r, 0);
    import_default_options(&in.opt);
    in.main.name = in.format->main_name;
    in.json = http_import_ctype(ct, "application/json");
    if (http_import_query(c, r, &in, &q)) {
        json_decref(in.rpm_speeds);
        return q;
    }
    if (in.opt.bmodes_mesh && !(in.format->flags & IMPORT_OWN_MESH)) {
        json_decref(in.rpm_speeds);
        snprintf(why, sizeof(why), "applies to %s only",
                 import_format_list(names, sizeof(names), IMPORT_OWN_MESH));
        return http_bad_query(c, r, "bmodes_mesh", why);
    }
    if (in.json && http_import_json(c, r, &in, &doc, &q)) {
        json_decref(in.rpm_speeds);
        json_decref(doc);
        return q;
    }
    if (!in.json) {
        in.main.text = r->body ? r->body : "";
        in.main.len = r->len;
    }
    q = http_import_run(c, r, &in);
    json_decref(in.rpm_speeds);
    json_decref(doc);
    return q;
}
