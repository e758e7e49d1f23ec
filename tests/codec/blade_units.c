/*
 * blade_units.c — unit checks of a solved blade-form request (DESIGN.md 8):
 * every mode's frequency_hz is frequency_rad_s / 2 pi and per_rev is
 * frequency_rad_s / omega, exactly (the same double operations), null at
 * rest; each case reports the rpm the request gave; the CSV carries the same
 * numbers in its per_rev and rpm columns.  A uniform blade (section only, no
 * stations), which the core solves without the station code.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codec_test.h"

/* One CSV row of the table: its 10 fields (pointers into row, which is cut). */
static int blade_csv_fields(char *row, char *f[10])
{
    int n = 0;
    char *p = row;

    while (n < 10) {
        f[n++] = p;
        p = strchr(p, ',');
        if (!p)
            break;
        *p++ = '\0';
    }
    return n;
}

/* The CSV rows against the JSON modes: columns 8 (per_rev) and 9 (rpm). */
static void blade_check_csv(test_case *tc, const json_t *cases, char *csv)
{
    char *line = strtok(csv, "\n"), *f[10];
    const json_t *c, *m;
    size_t i, k;

    if (!line || strcmp(line, "omega,mode,frequency_rad_s,frequency_hz,eig_re,eig_im,"
                              "mac_to_previous,status,per_rev,rpm,label,label_confidence,"
                              "tracked_index,tracking_flag"))
        fail(tc, "blade CSV header '%s'", line ? line : "(none)");
    json_array_foreach(cases, i, c) {
        json_array_foreach(json_object_get(c, "modes"), k, m) {
            const json_t *pr = json_object_get(m, "per_rev");
            line = strtok(NULL, "\n");
            if (!line || blade_csv_fields(line, f) != 10) { /* 10 or more: the first 10 */
                fail(tc, "blade CSV: row of case %zu mode %zu missing or short", i, k);
                return;
            }
            if (json_is_null(pr) ? f[8][0] != '\0' : strtod(f[8], NULL) != json_real_value(pr))
                fail(tc, "blade CSV: per_rev '%s' of case %zu mode %zu", f[8], i, k);
            if (strtod(f[9], NULL) != json_real_value(json_object_get(c, "rpm")))
                fail(tc, "blade CSV: rpm '%s' of case %zu", f[9], i);
        }
    }
}

void unit_blade_result(test_case *tc)
{
    static const char *text =
        "{\"blade\": {\"length\": 10, \"hub_radius\": 0.5, \"elements\": 12,"
        " \"section\": {\"EA\": 2.8e7, \"EI_flap\": 1.4e4, \"EI_edge\": 5.6e4, \"GJ\": 1.3e4,"
        " \"mass_per_length\": 1.2}},"
        " \"analysis\": {\"rpm\": [0, 120], \"modes\": 4, \"mode_shapes\": false}}";
    codec_errors *errs = codec_errors_new();
    codec_request *req = NULL;
    codec_run_out out;
    const json_t *cases, *c, *m;
    size_t i, k;

    memset(&out, 0, sizeof(out));
    if (codec_request_parse(&req, text, strlen(text), NULL, errs) != SM_OK) {
        fail(tc, "blade request rejected: '%s' %s", codec_errors_pointer(errs, 0),
             codec_errors_message(errs, 0));
        goto done;
    }
    if (codec_run(req, CODEC_RUN_JSON | CODEC_RUN_CSV, NULL, NULL, errs, &out) != CODEC_RUN_DONE) {
        fail(tc, "blade request not solved: %s", out.message);
        goto done;
    }
    cases = json_object_get(out.result, "cases");
    if (json_array_size(cases) != 2)
        fail(tc, "blade result has %zu cases", json_array_size(cases));
    json_array_foreach(cases, i, c) {
        double omega = json_real_value(json_object_get(c, "omega"));
        double rpm = json_real_value(json_object_get(c, "rpm"));
        if (rpm != (i ? 120.0 : 0.0) || omega != rpm * (6.283185307179586476925 / 60.0))
            fail(tc, "case %zu: omega %.17g, rpm %.17g", i, omega, rpm);
        if (json_array_size(json_object_get(c, "modes")) != 4)
            fail(tc, "case %zu: %zu modes", i, json_array_size(json_object_get(c, "modes")));
        json_array_foreach(json_object_get(c, "modes"), k, m) {
            double f = json_real_value(json_object_get(m, "frequency_rad_s"));
            const json_t *pr = json_object_get(m, "per_rev");
            if (!(f > 0) || json_real_value(json_object_get(m, "frequency_hz")) !=
                                f / 6.283185307179586476925)
                fail(tc, "case %zu mode %zu: frequency_hz is not frequency_rad_s / 2 pi", i, k);
            if (omega == 0 ? !json_is_null(pr) : json_real_value(pr) != f / omega)
                fail(tc, "case %zu mode %zu: per_rev is not frequency_rad_s / omega (or null at "
                     "rest)", i, k);
        }
    }
    if (json_array_size(json_object_get(out.result, "input_warnings")) ||
        json_object_get(out.result, "input_warnings"))
        fail(tc, "a correct blade has input_warnings");
    blade_check_csv(tc, cases, out.csv);
done:
    codec_run_clear(&out);
    codec_request_free(req);
    codec_errors_free(errs);
}
