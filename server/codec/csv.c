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
 * before, so a reader that takes columns by position still works.
 * With an error estimate (DESIGN.md 9) a last column error_estimate_rad_s
 * follows; without one the table is as before.
 */
#include "codec_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* A CSV number: full precision, empty when not finite. */
static void csv_num(FILE *f, double x)
{
    if (isfinite(x))
        fprintf(f, "%.17g", x);
}

/* The columns after status: per_rev (frequency / omega, empty at rest) and rpm; the line
 * ends unless est (a table with error estimates), which adds the last column. */
static void csv_tail(FILE *f, double freq, double omega, double rpm, int est, double err)
{
    fputc(',', f);
    if (omega > 0)
        csv_num(f, freq / omega);
    fputc(',', f);
    csv_num(f, rpm);
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
          "per_rev,rpm", f);
    fputs(est ? ",error_estimate_rad_s\n" : "\n", f);
    for (i = 0; i < res->n_cases; i++) {
        const sm_case *c = &res->cases[i];
        const char *st = codec_case_status_name(c->status);
        double case_rpm = i < n_rpm ? rpm[i] : c->omega * 60 / CODEC_TWO_PI;
        if (c->n_modes == 0) {
            csv_num(f, c->omega);
            fprintf(f, ",,,,,,,%s", st);
            csv_tail(f, NAN, 0, case_rpm, est, NAN);
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
            csv_tail(f, c->frequency[k], c->omega, case_rpm, est,
                     c->error_estimate ? c->error_estimate[k] : NAN);
        }
    }
    if (ferror(f)) {
        fclose(f);
        free(buf);
        return SM_NOMEM;
    }
    if (fclose(f)) {
        free(buf);
        return SM_NOMEM;
    }
    *out = buf;
    if (len)
        *len = n;
    return SM_OK;
}
