/*
 * codec_test.c — data-driven tests of the JSON codec (server/codec/).
 *
 * Usage: codec_test CASES_DIR
 *
 * Every folder of CASES_DIR is one case:
 *   request.json + expected-error.json  an invalid request.  The request goes
 *       through codec_request_parse and, when the codec accepts it,
 *       codec_model_new (topology errors come from the core).  Every entry
 *       of "errors" ({"pointer" or "pointer_prefix", "contains"}) must match
 *       one reported error; optional "status" is the HTTP status (400, 413,
 *       422), "limits" overrides codec_limits fields and "error_count" is how many
 *       errors the request has in all (none beyond those listed, e.g. a key that has its own
 *       message not also reported as unknown).
 *   request.json + checks.json  a valid request; checks: canonical_contains,
 *       canonical_text and sha256 (exact: pins of the canonical form),
 *       same_sha_as / different_sha_from (other files of the folder),
 *       joint_names, speeds, options, structure (with the spatial arrays:
 *       spatial, joint_z, joint_xy, member_spatial, point_mass_inertia,
 *       point_mass_products, point_mass_offset, member_stations, gravity), sections
 *       (sm_section values, offsets), model (sizes from sm_model_get_info),
 *       rpm (codec_request_rpm) and input_warnings (exactly these); name (the
 *       request's "name", null for none), canonical_lacks, stored_contains (the
 *       text a job stores: re-parsed, it has the same SHA-256 and name) and
 *       listing_contains (a job listing of the request, codec_job_list).
 *
 * Spatial requests (DESIGN.md 7.3): a valid case with "spatial": true in
 * checks.json is read twice: by the codec alone (req_parse_codec_only, no
 * structure check of the core), for the codec checks, so that they say
 * what the codec makes of the request whatever the core does; then by the
 * whole codec_request_parse, which must give the same canonical text and
 * SHA-256, for the "model" checks.
 * Before the folders a few unit checks run (SHA-256 vector, error list cap,
 * problem document, CSV encoder, diag pointers; spatial_units.c: spatial
 * diag pointers and result rows; blade_units.c: a solved blade's Hz,
 * per-rev and rpm; size_units.c: the result's text and size estimate).
 * One line per case; exit status 1 when anything failed.
 */
#include <dirent.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codec_test.h"

#define TEST_PATH_MAX 4096

void fail(test_case *tc, const char *fmt, ...)
{
    va_list ap;

    if (tc->failures++ == 0)
        printf("FAIL %s\n", tc->name);
    printf("     ");
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    printf("\n");
}

/* Whole file as a malloc'd NUL-terminated string, or NULL. */
static char *read_text(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    long n;

    if (!f)
        return NULL;
    if (fseek(f, 0, SEEK_END) || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET))
        goto done;
    buf = malloc((size_t)n + 1);
    if (!buf)
        goto done;
    if (fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
        goto done;
    }
    buf[n] = '\0';
    if (len)
        *len = (size_t)n;
done:
    fclose(f);
    return buf;
}

/* path = dir/file; 0, or -1 when it does not fit. */
static int path_join(char path[TEST_PATH_MAX], const char *dir, const char *file)
{
    int n = snprintf(path, TEST_PATH_MAX, "%s/%s", dir, file);

    return n < 0 || n >= TEST_PATH_MAX ? -1 : 0;
}

static int file_exists(const char *path)
{
    FILE *f = fopen(path, "rb");

    if (!f)
        return 0;
    fclose(f);
    return 1;
}

/* Limits with the overrides of spec (an object or NULL). */
static void apply_limits(codec_limits *lim, const json_t *spec)
{
    const json_t *x;

    codec_default_limits(lim);
    if ((x = json_object_get(spec, "max_request_bytes")))
        lim->max_request_bytes = (size_t)json_integer_value(x);
    if ((x = json_object_get(spec, "max_shape_values")))
        lim->max_shape_values = (long)json_integer_value(x);
    if ((x = json_object_get(spec, "max_result_bytes")))
        lim->max_result_bytes = (size_t)json_integer_value(x);
#define LIMIT(f) if ((x = json_object_get(spec, #f))) lim->f = (int)json_integer_value(x);
    LIMIT(max_joints) LIMIT(max_sections) LIMIT(max_members) LIMIT(max_point_masses)
    LIMIT(max_elements) LIMIT(max_speeds) LIMIT(max_modes) LIMIT(max_coordinates)
    LIMIT(max_frame_dofs)
#undef LIMIT
}

/*
 * Parse dir/file into a request; NULL (and a failure) when it does not
 * validate.  codec_only: without the core's structure check.
 */
static codec_request *load_request(test_case *tc, const char *dir, const char *file,
                                   const codec_limits *lim, int codec_only)
{
    char path[TEST_PATH_MAX];
    codec_errors *errs = codec_errors_new();
    codec_request *req = NULL;
    size_t len = 0;
    char *text;
    int st, i;

    text = path_join(path, dir, file) ? NULL : read_text(path, &len);
    if (!text || !errs) {
        fail(tc, "cannot read %s", path);
        goto done;
    }
    st = codec_only ? req_parse_codec_only(&req, text, len, lim, errs)
                    : codec_request_parse(&req, text, len, lim, errs);
    if (st != SM_OK) {
        fail(tc, "%s rejected (%s):", file, sm_strerror(st));
        for (i = 0; i < codec_errors_count(errs); i++)
            fail(tc, "  '%s': %s", codec_errors_pointer(errs, i), codec_errors_message(errs, i));
    }
done:
    free(text);
    codec_errors_free(errs);
    return req;
}

/* An RFC 6901 pointer: "" or "/..." with ~ only as ~0 or ~1. */
static int pointer_ok(const char *p)
{
    if (p[0] != '\0' && p[0] != '/')
        return 0;
    for (; *p; p++)
        if (*p == '~' && p[1] != '0' && p[1] != '1')
            return 0;
    return 1;
}

/* Does some error match the expectation e? */
static int error_matches(const codec_errors *errs, const json_t *e)
{
    const char *ptr = json_string_value(json_object_get(e, "pointer"));
    const char *prefix = json_string_value(json_object_get(e, "pointer_prefix"));
    const char *contains = json_string_value(json_object_get(e, "contains"));
    int i;

    for (i = 0; i < codec_errors_count(errs); i++) {
        const char *p = codec_errors_pointer(errs, i);
        const char *m = codec_errors_message(errs, i);
        if (ptr && strcmp(p, ptr))
            continue;
        if (prefix && strncmp(p, prefix, strlen(prefix)))
            continue;
        if (contains && !strstr(m, contains))
            continue;
        return 1;
    }
    return 0;
}

/* An invalid request: every expected error must be reported. */
static void run_invalid(test_case *tc, const char *dir, const json_t *exp)
{
    char path[TEST_PATH_MAX];
    codec_limits lim;
    codec_errors *errs = codec_errors_new();
    codec_request *req = NULL;
    sm_model *m = NULL;
    const json_t *e, *status = json_object_get(exp, "status");
    json_t *problem = NULL;
    size_t len = 0, k;
    char *text;
    int st, i;

    apply_limits(&lim, json_object_get(exp, "limits"));
    text = path_join(path, dir, "request.json") ? NULL : read_text(path, &len);
    if (!text || !errs) {
        fail(tc, "cannot read %s", path);
        goto done;
    }
    st = codec_request_parse(&req, text, len, &lim, errs);
    if (st == SM_OK)
        st = codec_model_new(&m, req, errs, NULL);
    if (st == SM_OK) {
        fail(tc, "the request was accepted");
        goto done;
    }
    if (st == SM_NOMEM)
        fail(tc, "out of memory");
    json_array_foreach(json_object_get(exp, "errors"), k, e) {
        if (!error_matches(errs, e)) {
            char *want = json_dumps(e, JSON_COMPACT);
            fail(tc, "expected error %s not reported", want ? want : "?");
            free(want);
        }
    }
    const json_t *count = json_object_get(exp, "error_count");
    if (count && codec_errors_count(errs) != (int)json_integer_value(count))
        fail(tc, "%d errors reported, expected %d", codec_errors_count(errs),
             (int)json_integer_value(count));
    for (i = 0; i < codec_errors_count(errs); i++)
        if (!pointer_ok(codec_errors_pointer(errs, i)))
            fail(tc, "malformed pointer '%s'", codec_errors_pointer(errs, i));
    if (status && codec_errors_http_status(errs) != (int)json_integer_value(status))
        fail(tc, "HTTP status %d, expected %d", codec_errors_http_status(errs),
             (int)json_integer_value(status));
    problem = codec_problem_from_errors(errs);
    if (!problem || !json_is_array(json_object_get(problem, "errors")))
        fail(tc, "no problem document with errors");
    if (tc->failures) {
        fail(tc, "reported errors:");
        for (i = 0; i < codec_errors_count(errs); i++)
            fail(tc, "  '%s': %s", codec_errors_pointer(errs, i), codec_errors_message(errs, i));
    }
done:
    json_decref(problem);
    sm_model_free(m);
    codec_request_free(req);
    codec_errors_free(errs);
    free(text);
}

/* checks.options: selected sm_options fields. */
static void check_options(test_case *tc, const sm_options *o, const json_t *want)
{
    const char *key;
    const json_t *v;

    json_object_foreach((json_t *)want, key, v) {
        long got, w = (long)json_integer_value(v);
        if (!strcmp(key, "frames")) got = (long)o->frames;
        else if (!strcmp(key, "frames_param")) got = o->frames_param;
        else if (!strcmp(key, "mass")) got = (long)o->mass;
        else if (!strcmp(key, "basis")) got = (long)o->basis;
        else if (!strcmp(key, "modes")) got = o->modes;
        else if (!strcmp(key, "modes_per_frame")) got = o->modes_per_frame;
        else if (!strcmp(key, "geometric_stiffening")) got = o->geometric_stiffening;
        else if (!strcmp(key, "coriolis")) got = o->coriolis;
        else if (!strcmp(key, "mode_shapes")) got = o->mode_shapes;
        else if (!strcmp(key, "rotary_inertia"))
            got = (long)o->rotary_inertia;
        else {
            fail(tc, "unknown option check '%s'", key);
            continue;
        }
        if (got != w)
            fail(tc, "option %s is %ld, expected %ld", key, got, w);
    }
}

/* a and b agree to 2 ulp-ish (1e-15 relative), or are both zero. */
static int near(double a, double b)
{
    return a == b || fabs(a - b) <= 1e-15 * fmax(fabs(a), fabs(b));
}

/* n numbers at got against the JSON array want; 1 when they agree (near). */
static int numbers_match(const double *got, int n, const json_t *want)
{
    int k;

    if (!json_is_array(want) || json_array_size(want) != (size_t)n)
        return 0;
    for (k = 0; k < n; k++)
        if (!near(got[k], json_number_value(json_array_get(want, (size_t)k))))
            return 0;
    return 1;
}

/*
 * checks.structure.member_stations: per member {"mask": SM_ST_* bits, "stations": [[s, mu, EA,
 * EI_flap, EI_edge, GJ, i_flap, i_edge, twist, inertia_twist, cg0, cg1, sc0, sc1, tc0, tc1
 * [, ip_over_a]], ...]} (angles in rad), or null for a member without stations.
 */
static void check_stations(test_case *tc, const sm_structure *st, const json_t *want)
{
    const json_t *row, *srow;
    size_t i, j;

    json_array_foreach(want, i, row) {
        const sm_member *m = (int)i < st->n_members ? &st->members[i] : NULL;
        const json_t *rows = json_object_get(row, "stations");
        if (!m) {
            fail(tc, "member %zu missing", i);
            continue;
        }
        if (json_is_null(row)) {
            if (m->n_stations)
                fail(tc, "member %zu has %d stations, expected none", i, m->n_stations);
            continue;
        }
        if (m->station_mask != (unsigned)json_integer_value(json_object_get(row, "mask")))
            fail(tc, "member %zu: station_mask %#x, expected %#x", i, m->station_mask,
                 (unsigned)json_integer_value(json_object_get(row, "mask")));
        if ((size_t)m->n_stations != json_array_size(rows)) {
            fail(tc, "member %zu: %d stations, expected %zu", i, m->n_stations, json_array_size(rows));
            continue;
        }
        json_array_foreach(rows, j, srow) {
            const sm_station *q = &m->stations[j];
            double got[17] = {q->s, q->mu, q->EA, q->EI_flap, q->EI_edge, q->GJ, q->i_flap,
                              q->i_edge, q->twist, q->inertia_twist, q->cg[0], q->cg[1],
                              q->sc[0], q->sc[1], q->tc[0], q->tc[1], q->ip_over_a};
            /* a 17th number, when given, is ip_over_a */
            if (!numbers_match(got, json_array_size(srow) == 17 ? 17 : 16, srow)) {
                char *w = json_dumps(srow, JSON_COMPACT | JSON_REAL_PRECISION(17));
                fail(tc, "member %zu station %zu: got [%.17g, %.17g, %.17g, %.17g, %.17g, %.17g, "
                     "%.17g, %.17g, %.17g, %.17g, %g, %g, %g, %g, %g, %g], want %s", i, j,
                     got[0], got[1], got[2], got[3], got[4], got[5], got[6], got[7], got[8],
                     got[9], got[10], got[11], got[12], got[13], got[14], got[15], w ? w : "?");
                free(w);
            }
        }
    }
}

/*
 * checks.structure, spatial part: spatial (0/1), joint_z (n_joints numbers,
 * or null for NULL), member_spatial [[twist (rad), e3x, e3y, e3z], ...],
 * point_mass_inertia [[Ixx, Iyy, Izz], ...].
 */
static void check_structure_spatial(test_case *tc, const sm_structure *st, const json_t *want)
{
    const json_t *x, *row;
    size_t i;

    if ((x = json_object_get(want, "spatial")) && st->spatial != (int)json_integer_value(x))
        fail(tc, "spatial is %d, expected %d", st->spatial, (int)json_integer_value(x));
    if ((x = json_object_get(want, "joint_z"))) {
        if (json_is_null(x) ? st->joint_z != NULL
                            : !st->joint_z || !numbers_match(st->joint_z, st->n_joints, x))
            fail(tc, "joint_z differs");
    }
    json_array_foreach(json_object_get(want, "member_spatial"), i, row) {
        const sm_member *m = (int)i < st->n_members ? &st->members[i] : NULL;
        double got[4];
        if (m) {
            got[0] = m->twist;
            memcpy(got + 1, m->e3, sizeof(m->e3));
        }
        if (!m || !numbers_match(got, 4, row))
            fail(tc, "member %zu: twist %g, e3 [%g, %g, %g] differ", i, m ? m->twist : 0,
                 m ? m->e3[0] : 0, m ? m->e3[1] : 0, m ? m->e3[2] : 0);
    }
    json_array_foreach(json_object_get(want, "point_mass_inertia"), i, row) {
        const sm_point_mass *p = (int)i < st->n_point_masses ? &st->point_masses[i] : NULL;
        if (!p || !numbers_match(p->inertia, 3, row))
            fail(tc, "point mass %zu: inertia [%.17g, %.17g, %.17g] differs", i, p ? p->inertia[0] : 0,
                 p ? p->inertia[1] : 0, p ? p->inertia[2] : 0);
    }
    json_array_foreach(json_object_get(want, "point_mass_products"), i, row) {
        const sm_point_mass *p = (int)i < st->n_point_masses ? &st->point_masses[i] : NULL;
        if (!p || !numbers_match(p->products, 3, row))
            fail(tc, "point mass %zu: products [%.17g, %.17g, %.17g] differ", i,
                 p ? p->products[0] : 0, p ? p->products[1] : 0, p ? p->products[2] : 0);
    }
    json_array_foreach(json_object_get(want, "point_mass_offset"), i, row) {
        const sm_point_mass *p = (int)i < st->n_point_masses ? &st->point_masses[i] : NULL;
        if (!p || !numbers_match(p->offset, 3, row))
            fail(tc, "point mass %zu: offset [%.17g, %.17g, %.17g] differs", i,
                 p ? p->offset[0] : 0, p ? p->offset[1] : 0, p ? p->offset[2] : 0);
    }
    if ((x = json_object_get(want, "joint_xy")) && !numbers_match(st->joint_xy, 2 * st->n_joints, x))
        fail(tc, "joint_xy differs");
    if ((x = json_object_get(want, "gravity")) && !numbers_match(st->gravity, 3, x))
        fail(tc, "gravity [%.17g, %.17g, %.17g] differs", st->gravity[0], st->gravity[1],
             st->gravity[2]);
    check_stations(tc, st, json_object_get(want, "member_stations"));
}

/*
 * checks.sections: one object per section (sorted name order) with any of
 * the sm_section fields E, A, I, mu, EA, EI_flap, EI_edge, GJ, i_flap,
 * i_edge, ip_over_a; fields not named must be zero.
 */
static void check_sections(test_case *tc, const sm_structure *st, const json_t *want)
{
    const json_t *row;
    size_t i;

    if (json_array_size(want) != (size_t)st->n_sections)
        fail(tc, "%d sections, expected %zu", st->n_sections, json_array_size(want));
    json_array_foreach(want, i, row) {
        const sm_section *c = (int)i < st->n_sections ? &st->sections[i] : NULL;
        if (!c)
            break;
#define FIELD(f) if (!near(c->f, json_number_value(json_object_get(row, #f)))) \
        fail(tc, "section %zu: " #f " is %.17g, expected %.17g", i, c->f, \
             json_number_value(json_object_get(row, #f)));
        FIELD(E) FIELD(A) FIELD(I) FIELD(mu) FIELD(EA) FIELD(EI_flap) FIELD(EI_edge) FIELD(GJ)
        FIELD(i_flap) FIELD(i_edge) FIELD(ip_over_a)
#undef FIELD
        if (json_object_get(row, "offsets")) { /* [cg0, cg1, sc0, sc1, tc0, tc1] */
            double got[6] = {c->cg[0], c->cg[1], c->sc[0], c->sc[1], c->tc[0], c->tc[1]};
            if (!numbers_match(got, 6, json_object_get(row, "offsets")))
                fail(tc, "section %zu: offsets differ", i);
        }
    }
}

/* checks.structure: counts, clamp, members [from, to, section, elements], point masses. */
static void check_structure(test_case *tc, const sm_structure *st, const json_t *want)
{
    const json_t *x, *row;
    size_t i;

#define COUNT(f) if ((x = json_object_get(want, #f)) && st->f != (int)json_integer_value(x)) \
        fail(tc, #f " is %d, expected %d", st->f, (int)json_integer_value(x));
    COUNT(n_joints) COUNT(n_sections) COUNT(n_members) COUNT(n_point_masses) COUNT(clamp)
#undef COUNT
    json_array_foreach(json_object_get(want, "members"), i, row) {
        const sm_member *m = (int)i < st->n_members ? &st->members[i] : NULL;
        if (!m || m->from != json_integer_value(json_array_get(row, 0)) ||
            m->to != json_integer_value(json_array_get(row, 1)) ||
            m->section != json_integer_value(json_array_get(row, 2)) ||
            m->elements != json_integer_value(json_array_get(row, 3)))
            fail(tc, "member %zu differs", i);
    }
    json_array_foreach(json_object_get(want, "point_masses"), i, row) {
        const sm_point_mass *p = (int)i < st->n_point_masses ? &st->point_masses[i] : NULL;
        if (!p || p->joint != json_integer_value(json_array_get(row, 0)) ||
            p->mass != json_number_value(json_array_get(row, 1)))
            fail(tc, "point mass %zu differs", i);
    }
    check_structure_spatial(tc, st, want);
}

/*
 * Same canonical text after a second pass (the canonical form is a
 * fixpoint); codec_only as for load_request.
 */
static void check_idempotent(test_case *tc, const codec_request *req, int codec_only)
{
    const char *text = codec_request_canonical_text(req);
    codec_errors *errs = codec_errors_new();
    codec_request *again = NULL;

    if (!errs || (codec_only ? req_parse_codec_only(&again, text, strlen(text), NULL, errs)
                             : codec_request_parse(&again, text, strlen(text), NULL, errs)) !=
                     SM_OK)
        fail(tc, "the canonical request does not validate");
    else if (strcmp(text, codec_request_canonical_text(again)))
        fail(tc, "canonicalizing twice changes the text");
    codec_request_free(again);
    codec_errors_free(errs);
}

/* Compare the SHA-256 of req with the requests in files. */
static void check_shas(test_case *tc, const char *dir, const codec_request *req,
                       const json_t *files, int same, int codec_only)
{
    const json_t *f;
    size_t i;

    json_array_foreach(files, i, f) {
        codec_request *other = load_request(tc, dir, json_string_value(f), NULL, codec_only);
        if (!other)
            continue;
        if (same != !strcmp(codec_request_sha256(req), codec_request_sha256(other)))
            fail(tc, "SHA-256 of %s should %s:\n       %s\n       %s", json_string_value(f),
                 same ? "be the same" : "differ", codec_request_canonical_text(req),
                 codec_request_canonical_text(other));
        codec_request_free(other);
    }
}

/* checks.model: the core model builds, with these sizes. */
static void check_model(test_case *tc, const codec_request *req, const json_t *want)
{
    codec_errors *errs = codec_errors_new();
    sm_model *m = NULL;
    sm_model_info info;
    const json_t *x;
    int st;

    if (!errs) {
        fail(tc, "out of memory");
        return;
    }
    st = codec_model_new(&m, req, errs, NULL);
    if (st != SM_OK) {
        fail(tc, "sm_model_new: %s: '%s' %s", sm_strerror(st), codec_errors_pointer(errs, 0),
             codec_errors_message(errs, 0));
        goto done;
    }
    sm_model_get_info(m, &info);
#define INFO(f) if ((x = json_object_get(want, #f)) && info.f != (int)json_integer_value(x)) \
        fail(tc, "model " #f " is %d, expected %d", info.f, (int)json_integer_value(x));
    INFO(nodes) INFO(elements) INFO(frames) INFO(coordinates)
#undef INFO
done:
    sm_model_free(m);
    codec_errors_free(errs);
}

/*
 * A spatial request through the whole codec_request_parse, the core's
 * structure check included: the same canonical text and SHA-256 as the
 * codec alone gave, then the model checks.
 */
static void check_with_core(test_case *tc, const char *dir, const codec_request *req,
                            const json_t *chk)
{
    codec_request *full = load_request(tc, dir, "request.json", NULL, 0);
    const json_t *x;

    if (!full)
        return;
    if (strcmp(codec_request_canonical_text(full), codec_request_canonical_text(req)) ||
        strcmp(codec_request_sha256(full), codec_request_sha256(req)))
        fail(tc, "the full parse gives another canonical text or SHA-256");
    if ((x = json_object_get(chk, "model")))
        check_model(tc, full, x);
    check_idempotent(tc, full, 0);
    codec_request_free(full);
}

/*
 * checks.input_warnings: exactly these warnings ([{"pointer", "contains"}], in order; [] for
 * none).
 */
static void check_warnings(test_case *tc, const json_t *got, const json_t *want)
{
    const json_t *w;
    size_t i;

    if (json_array_size(got) != json_array_size(want)) {
        char *g = json_dumps(got, JSON_COMPACT);
        fail(tc, "%zu input warnings, expected %zu: %s", json_array_size(got),
             json_array_size(want), g ? g : "?");
        free(g);
        return;
    }
    json_array_foreach(want, i, w) {
        const json_t *e = json_array_get(got, i);
        const char *p = json_string_value(json_object_get(e, "pointer"));
        const char *m = json_string_value(json_object_get(e, "message"));
        if (!p || !m || strcmp(p, json_string_value(json_object_get(w, "pointer"))) ||
            !strstr(m, json_string_value(json_object_get(w, "contains"))))
            fail(tc, "input warning %zu is '%s': %s", i, p ? p : "?", m ? m : "?");
    }
}

/* checks.speeds / checks.rpm: the n numbers at got equal want exactly. */
static void check_exact(test_case *tc, const char *what, const double *got, int n,
                        const json_t *want)
{
    int k;

    if (n != (int)json_array_size(want))
        fail(tc, "%d %s values, expected %zu", n, what, json_array_size(want));
    for (k = 0; k < n && k < (int)json_array_size(want); k++)
        if (got[k] != json_number_value(json_array_get(want, (size_t)k)))
            fail(tc, "%s %d is %.17g", what, k, got[k]);
}

/* The request's "name": kept out of the canonical text (and the id), in the stored text
 * and in a job listing (checks name, canonical_lacks, stored_contains, listing_contains). */
static void check_name(test_case *tc, const codec_request *req, const json_t *chk)
{
    const char *name = codec_request_name(req), *stored = codec_request_stored_text(req);
    const json_t *x = json_object_get(chk, "name");
    codec_errors *errs = codec_errors_new();
    codec_request *again = NULL;
    codec_job_view v;
    codec_text t = {0};
    char id[65];
    size_t i;

    if (x && (json_is_null(x) ? name != NULL : !name || strcmp(name, json_string_value(x))))
        fail(tc, "name is '%s'", name ? name : "(none)");
    json_array_foreach(json_object_get(chk, "canonical_lacks"), i, x)
        if (strstr(codec_request_canonical_text(req), json_string_value(x)))
            fail(tc, "canonical text holds %s", json_string_value(x));
    json_array_foreach(json_object_get(chk, "stored_contains"), i, x)
        if (!strstr(stored, json_string_value(x)))
            fail(tc, "stored text lacks %s:\n       %s", json_string_value(x), stored);
    if (!errs || codec_request_parse(&again, stored, strlen(stored), NULL, errs) != SM_OK)
        fail(tc, "the stored text does not validate");
    else if (strcmp(codec_request_sha256(again), codec_request_sha256(req)) ||
             (name && (!codec_request_name(again) || strcmp(codec_request_name(again), name))))
        fail(tc, "the stored text parses to another SHA-256 or name");
    memset(&v, 0, sizeof(v));
    if (codec_job_id(req, id) != SM_OK)
        fail(tc, "no job id");
    v.id = id;
    v.state = "done";
    v.name = name;
    codec_job_list(&t, &v, 1, NULL);
    json_array_foreach(json_object_get(chk, "listing_contains"), i, x)
        if (!t.p || !strstr(t.p, json_string_value(x)))
            fail(tc, "listing lacks %s:\n       %s", json_string_value(x), t.p ? t.p : "");
    codec_text_free(&t);
    codec_request_free(again);
    codec_errors_free(errs);
}

/* A valid request and its checks. */
static void run_valid(test_case *tc, const char *dir, const json_t *chk)
{
    int spatial = json_is_true(json_object_get(chk, "spatial"));
    codec_request *req = load_request(tc, dir, "request.json", NULL, spatial);
    const json_t *x;
    const double *sp;
    size_t i;
    int n;

    if (!req)
        return;
    json_array_foreach(json_object_get(chk, "canonical_contains"), i, x)
        if (!strstr(codec_request_canonical_text(req), json_string_value(x)))
            fail(tc, "canonical text lacks %s:\n       %s", json_string_value(x),
                 codec_request_canonical_text(req));
    if ((x = json_object_get(chk, "canonical_text")) &&
        strcmp(codec_request_canonical_text(req), json_string_value(x)))
        fail(tc, "canonical text differs:\n       got  %s\n       want %s",
             codec_request_canonical_text(req), json_string_value(x));
    if ((x = json_object_get(chk, "sha256")) && strcmp(codec_request_sha256(req),
                                                       json_string_value(x)))
        fail(tc, "SHA-256 is %s, expected %s", codec_request_sha256(req), json_string_value(x));
    check_shas(tc, dir, req, json_object_get(chk, "same_sha_as"), 1, spatial);
    check_shas(tc, dir, req, json_object_get(chk, "different_sha_from"), 0, spatial);
    json_array_foreach(json_object_get(chk, "joint_names"), i, x) {
        const char *got = codec_request_joint_name(req, (int)i);
        if (!got || strcmp(got, json_string_value(x)))
            fail(tc, "joint %zu is '%s', expected '%s'", i, got ? got : "(none)",
                 json_string_value(x));
    }
    if ((x = json_object_get(chk, "speeds"))) {
        sp = codec_request_speeds(req, &n);
        check_exact(tc, "speed", sp, n, x);
    }
    if ((x = json_object_get(chk, "rpm"))) {
        sp = codec_request_rpm(req, &n);
        check_exact(tc, "rpm", sp, n, x);
    }
    if ((x = json_object_get(chk, "input_warnings")))
        check_warnings(tc, codec_request_input_warnings(req), x);
    if ((x = json_object_get(chk, "options")))
        check_options(tc, codec_request_options(req), x);
    if ((x = json_object_get(chk, "structure")))
        check_structure(tc, codec_request_structure(req), x);
    if ((x = json_object_get(chk, "sections")))
        check_sections(tc, codec_request_structure(req), x);
    if (!spatial && (x = json_object_get(chk, "model")))
        check_model(tc, req, x);
    if (strlen(codec_request_sha256(req)) != 64)
        fail(tc, "SHA-256 is not 64 hex digits");
    check_idempotent(tc, req, spatial);
    check_name(tc, req, chk);
    if (spatial)
        check_with_core(tc, dir, req, chk);
    codec_request_free(req);
}

static int run_case(const char *root, const char *name)
{
    char dir[TEST_PATH_MAX], path[TEST_PATH_MAX];
    test_case tc = {name, 0};
    json_error_t jerr;
    json_t *spec;

    if (path_join(dir, root, name) || path_join(path, dir, "expected-error.json")) {
        fail(&tc, "path too long");
        return 1;
    }
    if (file_exists(path)) {
        spec = json_load_file(path, 0, &jerr);
        if (!spec)
            fail(&tc, "%s: %s", path, jerr.text);
        else
            run_invalid(&tc, dir, spec);
    } else {
        spec = path_join(path, dir, "checks.json") ? NULL : json_load_file(path, 0, &jerr);
        if (!spec)
            fail(&tc, "no expected-error.json or readable checks.json: %s", jerr.text);
        else
            run_valid(&tc, dir, spec);
    }
    json_decref(spec);
    if (!tc.failures)
        printf("ok   %s\n", name);
    return tc.failures != 0;
}

/* ------------------------------------------------------------ unit checks */

static void unit_sha(test_case *tc)
{
    char hex[65];

    static const char two[] = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
    char *million = malloc(1000000);

    codec_sha256_hex("abc", 3, hex);
    if (strcmp(hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"))
        fail(tc, "SHA-256(\"abc\") = %s", hex);
    /* FIPS 180-2 appendix B.2 (two blocks) and B.3 (a million 'a'), and the empty string
     * (NIST's example values): sha256.c's padding at 0, 56 and 64k bytes. */
    codec_sha256_hex(two, strlen(two), hex);
    if (strcmp(hex, "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1"))
        fail(tc, "SHA-256(B.2) = %s", hex);
    codec_sha256_hex("", 0, hex);
    if (strcmp(hex, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"))
        fail(tc, "SHA-256(\"\") = %s", hex);
    if (million) {
        memset(million, 'a', 1000000);
        codec_sha256_hex(million, 1000000, hex);
        if (strcmp(hex, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0"))
            fail(tc, "SHA-256(B.3) = %s", hex);
    }
    free(million);
    /* the SHA extensions' rounds (where the CPU has them) against the portable ones: every
     * length up to 300 bytes (the padding into one or two blocks, several blocks), pseudo-random
     * bytes */
    unsigned char buf[300];
    unsigned x = 12345;
    for (size_t i = 0; i < sizeof buf; i++) {
        x = x * 1103515245u + 12345u;
        buf[i] = (unsigned char)(x >> 16);
    }
    for (size_t n = 0; n <= sizeof buf; n++) {
        char fast[65], slow[65];
        codec_sha256_hex_with(buf, n, fast, 1);
        codec_sha256_hex_with(buf, n, slow, 0);
        if (strcmp(fast, slow))
            fail(tc, "SHA-256 of %zu bytes: %s with the CPU's extensions, %s without", n, fast,
                 slow);
    }
    printf("note SHA-256: the CPU's SHA extensions %s\n",
           codec_sha256_accelerated() ? "used (and checked against the portable rounds)"
                                      : "not available: the portable rounds");
}

static void unit_errors(test_case *tc)
{
    codec_errors *e = codec_errors_new();
    json_t *p = NULL;
    int i;

    for (i = 0; i < CODEC_MAX_ERRORS + 50; i++)
        codec_errors_add(e, "/x", "error %d", i);
    if (codec_errors_count(e) != CODEC_MAX_ERRORS + 1)
        fail(tc, "error list holds %d entries", codec_errors_count(e));
    if (!strstr(codec_errors_message(e, CODEC_MAX_ERRORS), "more errors"))
        fail(tc, "no 'more errors' note at the end");
    p = codec_problem_from_errors(e);
    if (!p || json_integer_value(json_object_get(p, "status")) != 422 ||
        json_array_size(json_object_get(p, "errors")) != CODEC_MAX_ERRORS + 1 ||
        strcmp(json_string_value(json_object_get(p, "type")), "about:blank"))
        fail(tc, "problem document");
    json_decref(p);
    p = codec_problem_new(503, "urn:spinmodal:shutting-down", "Service Unavailable", NULL, NULL);
    if (!p || json_object_get(p, "errors") || json_object_get(p, "detail"))
        fail(tc, "problem without errors");
    json_decref(p);
    codec_errors_free(e);
}

static void unit_csv(test_case *tc)
{
    double freq[2] = {3.5, 20}, re[2] = {0, 0}, im[2] = {3.5, 20}, mac[2] = {-1, -1};
    int prev[2] = {-1, -1};
    sm_case cases[2];
    sm_result res = {2, cases, 0, NULL, 0, NULL, 0};
    char *csv = NULL;
    size_t len = 0;
    /* per_rev is empty at rest; rpm = omega 60 / (2 pi) without a request */
    /* DESIGN.md 9.1 columns: label, confidence, tracked index, flag; empty without a mode */
    int kind[2] = {SM_MODE_FLAP, SM_MODE_EDGE}, ord[2] = {1, 2}, track[2] = {0, 3};
    int flag[2] = {0, SM_TRACK_VEERING}, partner[2] = {-1, 0};
    double conf[2] = {0.5, 0.75};
    const char *want =
        "omega,mode,frequency_rad_s,frequency_hz,eig_re,eig_im,mac_to_previous,status,per_rev,"
        "rpm,label,label_confidence,tracked_index,tracking_flag\n"
        "0,1,3.5,0.55704230082163375,0,3.5,,solved,,0,1st flap,0.5,0,\n"
        "0,2,20,3.183098861837907,0,20,,solved,,0,2nd edge,0.75,3,veering\n"
        "20,,,,,,,no_equilibrium,,190.9859317102744,,,,\n";

    memset(cases, 0, sizeof(cases));
    cases[0].status = SM_CASE_SOLVED;
    cases[0].n_modes = 2;
    cases[0].frequency = freq;
    cases[0].eig_re = re;
    cases[0].eig_im = im;
    cases[0].mac_to_previous = mac;
    cases[0].previous_index = prev;
    cases[0].label_kind = kind;
    cases[0].label_ordinal = ord;
    cases[0].label_confidence = conf;
    cases[0].tracked_index = track;
    cases[0].track_flag = flag;
    cases[0].track_partner = partner;
    cases[1].omega = 20;
    cases[1].status = SM_CASE_NO_EQUILIBRIUM;
    if (codec_result_csv(&csv, &len, NULL, &res) != SM_OK || strcmp(csv, want) || len != strlen(want))
        fail(tc, "CSV:\n%s", csv ? csv : "(none)");
    free(csv);
}

/* codec_diag_error: every kind of sm_diag item maps to the right pointer. */
static void unit_diag(test_case *tc)
{
    static const char *text =
        "{\"structure\": {\"joints\": {\"O\": [0, 0], \"a/b\": [1, 0], \"P\": [1, 1]},"
        " \"sections\": {\"al\": {\"E\": 1, \"A\": 1, \"I\": 1, \"mass_per_length\": 1}},"
        " \"members\": [{\"from\": \"O\", \"to\": \"a/b\", \"section\": \"al\", \"elements\": 1},"
        " {\"from\": \"a/b\", \"to\": \"P\", \"section\": \"al\", \"elements\": 1}],"
        " \"point_masses\": [{\"joint\": \"P\", \"mass\": 1}], \"clamp\": \"O\"},"
        " \"frames\": {\"per_member\": 1}, \"analysis\": {\"omega\": [0, 1]}}";
    static const struct {
        sm_item item;
        int index;
        const char *field;
        const char *pointer;
    } map[] = {
        {SM_ITEM_MEMBER, 1, "to", "/structure/members/1/to"},
        {SM_ITEM_MEMBER, 1, "length", "/structure/members/1"},
        {SM_ITEM_MEMBER, 0, "E", "/structure/sections/al/E"},
        {SM_ITEM_MEMBER, 7, "", "/structure/members"},
        {SM_ITEM_SECTION, 0, "mu", "/structure/sections/al/mass_per_length"},
        {SM_ITEM_JOINT, 2, "", "/structure/joints/a~1b"},
        {SM_ITEM_JOINT, 0, "y", "/structure/joints/O/1"},
        {SM_ITEM_POINT_MASS, 0, "mass", "/structure/point_masses/0/mass"},
        {SM_ITEM_CLAMP, -1, "", "/structure/clamp"},
        {SM_ITEM_OPTIONS, -1, "frames", "/frames"},
        {SM_ITEM_OPTIONS, -1, "frames_param", "/frames/per_member"},
        {SM_ITEM_OPTIONS, -1, "modes", "/analysis/modes"},
        {SM_ITEM_OPTIONS, -1, "basis", "/analysis/substructure_modes"},
        {SM_ITEM_OPTIONS, 1, "omega", "/analysis/omega/1"},
        {SM_ITEM_NONE, -1, "", "/structure"},
    };
    codec_errors *errs = codec_errors_new();
    codec_request *req = NULL;
    size_t k;

    if (codec_request_parse(&req, text, strlen(text), NULL, errs) != SM_OK) {
        fail(tc, "diag request rejected: '%s' %s", codec_errors_pointer(errs, 0),
             codec_errors_message(errs, 0));
        goto done;
    }
    for (k = 0; k < sizeof(map) / sizeof(map[0]); k++) {
        sm_diag d;
        memset(&d, 0, sizeof(d));
        d.status = SM_INVALID_INPUT;
        d.item = map[k].item;
        d.item_index = map[k].index;
        snprintf(d.field, sizeof(d.field), "%s", map[k].field);
        snprintf(d.message, sizeof(d.message), "diag %zu", k);
        codec_errors_clear(errs);
        if (codec_diag_error(req, &d, errs) != SM_OK || codec_errors_count(errs) != 1 ||
            strcmp(codec_errors_pointer(errs, 0), map[k].pointer) ||
            strcmp(codec_errors_message(errs, 0), d.message))
            fail(tc, "diag %zu -> '%s', expected '%s'", k, codec_errors_pointer(errs, 0),
                 map[k].pointer);
    }
done:
    codec_request_free(req);
    codec_errors_free(errs);
}

static int cmp_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

int main(int argc, char **argv)
{
    test_case tc = {"unit: sha256, error list, problem, csv, diag pointers, spatial diag and "
                    "result rows, blade result (Hz, per-rev, rpm), result text and size", 0};
    char **names = NULL;
    size_t n = 0, cap = 0, i;
    struct dirent *de;
    DIR *d;
    int failed = 0;

    if (argc != 2) {
        fprintf(stderr, "usage: codec_test CASES_DIR\n");
        return 2;
    }
    unit_sha(&tc);
    unit_errors(&tc);
    unit_csv(&tc);
    unit_diag(&tc);
    unit_spatial_diag(&tc);
    unit_spatial_result(&tc);
    unit_blade_result(&tc);
    unit_result_size(&tc);
    if (tc.failures)
        failed++;
    else
        printf("ok   %s\n", tc.name);
    d = opendir(argv[1]);
    if (!d) {
        perror(argv[1]);
        return 1;
    }
    while ((de = readdir(d))) {
        if (de->d_name[0] == '.')
            continue;
        if (n == cap) {
            char **nn = realloc(names, (cap = cap ? 2 * cap : 64) * sizeof(*names));
            if (!nn)
                return 1;
            names = nn;
        }
        names[n++] = strdup(de->d_name);
    }
    closedir(d);
    qsort(names, n, sizeof(*names), cmp_name);
    for (i = 0; i < n; i++) {
        failed += run_case(argv[1], names[i]);
        free(names[i]);
    }
    free(names);
    printf("%zu cases, %d failed\n", n, failed);
    return failed ? 1 : 0;
}
