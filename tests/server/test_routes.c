/*
 * test_routes.c — the route table of the HTTP front (server/daemon/
 * http_routes.c) against the documented API, schemas/openapi.json (its
 * path given as argv[1]).
 *
 * For every path of the OpenAPI document, a concrete URL ({id} = a job id,
 * {format} = each format of the codec's import_formats[]) is routed by
 * http_route_find, the lookup every request goes through: it must find a
 * route whose template is the documented path (or the embedded file of
 * that path) and whose methods are exactly the documented ones (get =
 * GET and HEAD; options is the preflight every route answers).  Every
 * entry of the table must be documented.  Then the paths that must not
 * route: an unknown import format, an extra segment, a bad id (routed, but
 * id_ok 0), a path that only starts like a route.
 */
#include "http_internal.h"
#include "import.h"

#include <jansson.h>
#include <stdio.h>
#include <string.h>

static int failures = 0;
static int checks = 0;

#define CHECK(cond, ...)                                      \
    do {                                                      \
        checks++;                                             \
        if (!(cond)) {                                        \
            failures++;                                       \
            printf("FAIL %s:%d: ", __FILE__, __LINE__);       \
            printf(__VA_ARGS__);                              \
            printf("\n");                                     \
        }                                                     \
    } while (0)

#define ID "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef"

/* The M_* bits of an OpenAPI path item's operations. */
static unsigned documented_methods(json_t *item)
{
    unsigned m = 0;

    if (json_object_get(item, "get"))
        m |= M_GET | M_HEAD;
    if (json_object_get(item, "post"))
        m |= M_POST;
    if (json_object_get(item, "delete"))
        m |= M_DELETE;
    return m;
}

/* The URL of tmpl with its {param} replaced by arg, into out[cap]. */
static void concrete(const char *tmpl, const char *arg, char *out, size_t cap)
{
    const char *open = strchr(tmpl, '{'), *close = open ? strchr(open, '}') : NULL;

    if (!open || !close)
        snprintf(out, cap, "%s", tmpl);
    else
        snprintf(out, cap, "%.*s%s%s", (int)(open - tmpl), tmpl, arg, close + 1);
}

/* Route url and check it lands on tmpl with the methods m. */
static void check_routed(const char *url, const char *tmpl, unsigned m)
{
    http_req r;

    memset(&r, 0, sizeof(r));
    http_route_find(&r, url);
    CHECK(r.def != NULL, "%s: no route", url);
    if (!r.def)
        return;
    CHECK(strcmp(r.tmpl, tmpl) == 0, "%s: template %s, documented %s", url, r.tmpl, tmpl);
    CHECK(r.def->methods == m, "%s: methods %#x, documented %#x", url, r.def->methods, m);
    CHECK(r.route == r.def->route, "%s: route id", url);
    CHECK(!(m & M_GET) || r.def->get, "%s: GET without a handler", url);
    CHECK(!(m & M_DELETE) || r.def->del, "%s: DELETE without a handler", url);
    CHECK(!(m & M_POST) || (r.def->begin && r.def->end), "%s: POST without handlers", url);
    if (strstr(tmpl, "{id}"))
        CHECK(r.id_ok && strcmp(r.id, ID) == 0, "%s: id not taken", url);
}

/* Every documented path routes to itself; returns how many were checked. */
static int check_documented(json_t *paths)
{
    const import_format *f;
    const char *tmpl;
    json_t *item;
    char url[256];
    int n = 0;

    json_object_foreach(paths, tmpl, item) {
        if (strstr(tmpl, "{format}")) {
            for (f = import_formats; f->name; f++) {
                concrete(tmpl, f->name, url, sizeof(url));
                check_routed(url, tmpl, documented_methods(item));
            }
        } else {
            concrete(tmpl, ID, url, sizeof(url));
            check_routed(url, tmpl, documented_methods(item));
        }
        n++;
    }
    return n;
}

/* url routes nowhere (404). */
static void check_unrouted(const char *url)
{
    http_req r;

    memset(&r, 0, sizeof(r));
    http_route_find(&r, url);
    CHECK(r.def == NULL && r.route == R_OTHER && strcmp(r.tmpl, "other") == 0,
          "%s: routed to %s", url, r.tmpl);
}

int main(int argc, char **argv)
{
    json_error_t err;
    json_t *doc, *paths;
    const http_route_def *table;
    size_t n, i;
    http_req r;

    if (argc < 2) {
        fprintf(stderr, "usage: test_routes openapi.json\n");
        return 2;
    }
    doc = json_load_file(argv[1], 0, &err);
    paths = doc ? json_object_get(doc, "paths") : NULL;
    if (!json_is_object(paths)) {
        fprintf(stderr, "test_routes: %s: %s\n", argv[1], doc ? "no paths" : err.text);
        return 2;
    }
    CHECK(check_documented(paths) >= 10, "too few documented paths");
    table = http_route_table(&n);
    for (i = 0; i < n; i++)
        CHECK(json_object_get(paths, table[i].tmpl) != NULL, "route %s is not documented",
              table[i].tmpl);
    check_unrouted("/v1/import/nope");
    check_unrouted("/v1/import/");
    check_unrouted("/v1/import/csv/x");
    check_unrouted("/v1/analyses/" ID "/other");
    check_unrouted("/v1/analyses/" ID "/result/x");
    check_unrouted("/v1/analyses/" ID "/");
    check_unrouted("/livez/");
    check_unrouted("/v1");
    check_unrouted("/nope");
    memset(&r, 0, sizeof(r));
    http_route_find(&r, "/v1/analyses/0123ABC/result");
    CHECK(r.route == R_RESULT && !r.id_ok && r.id[0] == '\0', "a bad id is routed, not taken");
    CHECK(http_method_of("GET") == M_GET && http_method_of("PUT") == M_OTHER &&
              strcmp(http_method_label(M_DELETE), "DELETE") == 0 &&
              strcmp(http_method_label(M_OTHER), "OTHER") == 0,
          "method names");
    json_decref(doc);
    printf("%d checks, %d failures\n", checks, failures);
    return failures ? 1 : 0;
}
