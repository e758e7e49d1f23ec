/*
 * csv.c — the frequency table of an sm_result as CSV.
 *
 * How it fits: `spinmodal solve --csv` and GET /v1/analyses/{id}/result
 * ?format=csv serve this instead of the result document of result.c: one
 * row per speed and mode (Campbell-diagram data for a spreadsheet), one row
 * with empty mode fields for a speed without modes.  Numbers are written at
 * full precision (%.17g); a value that is not finite is an empty field.
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

int codec_result_csv(char **out, size_t *len, const sm_result *res)
{
    char *buf = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&buf, &n);
    int i, k;

    *out = NULL;
    if (!f)
        return SM_NOMEM;
    fputs("omega,mode,frequency_rad_s,frequency_hz,eig_re,eig_im,mac_to_previous,status\n", f);
    for (i = 0; i < res->n_cases; i++) {
        const sm_case *c = &res->cases[i];
        const char *st = codec_case_status_name(c->status);
        if (c->n_modes == 0) {
            csv_num(f, c->omega);
            fprintf(f, ",,,,,,,%s\n", st);
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
            fprintf(f, ",%s\n", st);
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
