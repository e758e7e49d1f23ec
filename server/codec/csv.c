/*
 * csv.c — the frequency table of an sm_result as CSV.
 *
 * How it fits: `spinmodal solve --csv` and GET /v1/analyses/{id}/result
 * ?format=csv serve this instead of the result document of result.c: one
 * row per speed and mode (Campbell-diagram data for a spreadsheet), one row
 * with empty mode fields for a speed without modes.  Numbers are written at
 * full precision (%.17g); a value that is not finite is an empty field.
 * The columns per_rev (frequency / omega, empty at rest) and rpm (the
 * case's speed in rev/min, DESIGN.md 8) come last, after the columns of
 * before, so a reader that takes columns by position still works; the
 * columns label, label_confidence, tracked_index, tracking_flag (DESIGN.md
 * 9.1) follow them for the same reason.  codec_critical_speeds_csv writes
 * the critical speeds of a result document as a second table, and after
 * them its divergence speeds as rows of engine order 0 (a static
 * instability: the frequency passes through zero; tracked_index and
 * label_confidence empty, frequency 0).  With an
 * error estimate (DESIGN.md 9) a last column error_estimate_rad_s follows;
 * without one the table is as before.
 */
#include "codec_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

int codec_memstream_done(FILE *f, char **buf, size_t *n, char **out, size_t *len)
{
    int bad = ferror(f);

    if (fclose(f) || bad) { /* fclose also writes *buf and *n */
        free(*buf);
        *buf = NULL;
        return SM_NOMEM;
    }
    *out = *buf;
    if (len)
        *len = *n;
    return SM_OK;
}

/* A CSV number: full precision, empty when not finite. */
static void csv_num(FILE *f, double x)
{
    char text[CODEC_NUMTEXT_MAX];

    if (isfinite(x))
        fwrite(text, 1, (size_t)codec_numtext(text, x, 0), f);
}

/* The columns after status: per_rev (frequency / omega, empty at rest) and rpm. */
static void csv_tail(FILE *f, double freq, double omega, double rpm)
{
    fputc(',', f);
    if (omega > 0)
        csv_num(f, freq / omega);
    fputc(',', f);
    csv_num(f, rpm);
}

/* The columns after rpm (DESIGN.md 9.1): label, label_confidence, tracked_index (0-based, as
 * in the JSON), tracking_flag; empty where the case has none (k < 0: a row without a mode). */
static void csv_trust(FILE *f, const codec_request *r, const sm_case *c, int k)
{
    char lab[32];
    int flag = k >= 0 && c->track_flag ? c->track_flag[k] : 0;

    if (k >= 0 && c->label_kind) {
        fprintf(f, ",%s,",
                codec_mode_label(r, c->label_kind[k], c->label_ordinal[k], lab, sizeof(lab)));
        csv_num(f, c->label_confidence[k]);
    } else {
        fputs(",,", f);
    }
    fputc(',', f);
    if (k >= 0 && c->tracked_index)
        fprintf(f, "%d", c->tracked_index[k]);
    fprintf(f, ",%s", flag == SM_TRACK_CROSSING ? "crossing" : flag == SM_TRACK_VEERING ? "veering" : "");
}

/* The end of a row: the error estimate when the table has that column (est), the newline. */
static void csv_est(FILE *f, int est, double err)
{
    if (est) {
        fputc(',', f);
        csv_num(f, err);
    }
    fputc('\n', f);
}

/* 1 when a case of res carries error estimates (sm_estimate ran). */
static int csv_has_estimate(const sm_result *res)
{
    for (int i = 0; i < res->n_cases; i++)
        if (res->cases[i].error_estimate)
            return 1;
    return 0;
}

int codec_result_csv(char **out, size_t *len, const codec_request *r, const sm_result *res)
{
    char *buf = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&buf, &n);
    const double *rpm = NULL;
    int i, k, n_rpm = 0, est = csv_has_estimate(res);

    *out = NULL;
    if (!f)
        return SM_NOMEM;
    if (r)
        rpm = codec_request_rpm(r, &n_rpm);
    fputs("omega,mode,frequency_rad_s,frequency_hz,eig_re,eig_im,mac_to_previous,status,"
          "per_rev,rpm,label,label_confidence,tracked_index,tracking_flag", f);
    fputs(est ? ",error_estimate_rad_s\n" : "\n", f);
    for (i = 0; i < res->n_cases; i++) {
        const sm_case *c = &res->cases[i];
        const char *st = codec_case_status_name(c->status);
        double case_rpm = i < n_rpm ? rpm[i] : c->omega * 60 / CODEC_TWO_PI;
        if (c->n_modes == 0) {
            csv_num(f, c->omega);
            fprintf(f, ",,,,,,,%s", st);
            csv_tail(f, NAN, 0, case_rpm);
            csv_trust(f, r, c, -1);
            csv_est(f, est, NAN);
        }
        for (k = 0; k < c->n_modes; k++) {
            double mac = c->mac_to_previous ? c->mac_to_previous[k] : -1;
            csv_num(f, c->omega);
            fprintf(f, ",%d,", k + 1);
            csv_num(f, c->frequency[k]);
            fputc(',', f);
            csv_num(f, c->frequency[k] / CODEC_TWO_PI);
            fputc(',', f);
            csv_num(f, c->eig_re[k]);
            fputc(',', f);
            csv_num(f, c->eig_im[k]);
            fputc(',', f);
            if (mac >= 0)
                csv_num(f, mac);
            fprintf(f, ",%s", st);
            csv_tail(f, c->frequency[k], c->omega, case_rpm);
            csv_trust(f, r, c, k);
            csv_est(f, est, c->error_estimate ? c->error_estimate[k] : NAN);
        }
    }
    return codec_memstream_done(f, &buf, &n, out, len);
}

/* A number of a JSON object o[key] for the CSV, empty when absent or null. */
static void csv_json_num(FILE *f, const json_t *o, const char *key)
{
    const json_t *x = json_object_get(o, key);
    if (json_is_number(x))
        csv_num(f, json_number_value(x));
}

int codec_critical_speeds_csv(char **out, size_t *len, const json_t *result)
{
    char *buf = NULL;
    size_t n = 0, i;
    FILE *f = open_memstream(&buf, &n);
    const json_t *cs = json_object_get(result, "critical_speeds"), *c;

    *out = NULL;
    if (!f)
        return SM_NOMEM;
    fputs("order,tracked_index,label,label_confidence,omega,rpm,frequency_rad_s,frequency_hz,"
          "refined,omega_interpolated\n", f);
    json_array_foreach(cs, i, c) {
        const char *lab = json_string_value(json_object_get(c, "label"));
        csv_json_num(f, c, "order");
        fputc(',', f);
        csv_json_num(f, c, "tracked_index");
        fprintf(f, ",%s,", lab ? lab : "");
        csv_json_num(f, c, "label_confidence");
        fputc(',', f);
        csv_json_num(f, c, "omega");
        fputc(',', f);
        csv_json_num(f, c, "rpm");
        fputc(',', f);
        csv_json_num(f, c, "frequency_rad_s");
        fputc(',', f);
        csv_json_num(f, c, "frequency_hz");
        fprintf(f, ",%s,", json_is_true(json_object_get(c, "refined")) ? "true" : "false");
        csv_json_num(f, c, "omega_interpolated");
        fputc('\n', f);
    }
    cs = json_object_get(result, "divergence_speeds");
    json_array_foreach(cs, i, c) { /* engine order 0: the frequency passes through zero */
        const char *lab = json_string_value(json_object_get(c, "mode"));
        fprintf(f, "0,,%s,,", lab ? lab : "");
        csv_json_num(f, c, "omega_rad_s");
        fputc(',', f);
        csv_json_num(f, c, "rpm");
        fprintf(f, ",0,0,%s,", json_is_true(json_object_get(c, "refined")) ? "true" : "false");
        csv_json_num(f, c, "omega_interpolated");
        fputc('\n', f);
    }
    return codec_memstream_done(f, &buf, &n, out, len);
}
