/*
 * elastodyn_test.c — ElastoDyn coefficients of the NREL 5-MW blade, end to end through the
 * codec (DESIGN.md 9.3): import the r-test blade file (--tip-radius 63 --hub-radius 1.5,
 * 0 rpm), run the one pipeline (codec_run), fit from the result document
 * (codec_elastodyn_case, what the daemon and the CLI use), then
 *  1. the three modes are 1st flap, 2nd flap, 1st edge by energy, each clean (>= 90 %);
 *  2. each fit reproduces the computed shape within 1 % of the tip, C2..C6 sum to 1 and
 *     phi'(0) = 0;
 *  3. the fitted shapes against the coefficients printed in the NREL file: max |dphi| over
 *     x = 0..1 (measured 0.014, 0.030, 0.004 for flap 1, flap 2, edge 1; bound 0.04);
 *  4. the text (?format=elastodyn) holds the 15 coefficient lines in ElastoDyn's layout,
 *     written with seven significant digits (on the largest) and summing to 1 exactly in
 *     decimal;
 *  5. the patched deck is the file byte for byte except the 15 values (CRLF kept), its
 *     values read back, and a deck without a name or with a name twice is refused.
 * Argument: the tests/reference/blades folder.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codec.h"
#include "elastodyn.h"
#include "import.h"
#include "run.h"

static int failures;
static const char *ref_dir;

static void fail(const char *fmt, ...)
{
    va_list ap;

    va_start(ap, fmt);
    printf("FAIL ");
    vprintf(fmt, ap);
    printf("\n");
    va_end(ap);
    failures++;
}

static char *slurp(const char *rel, size_t *len)
{
    char path[1024];
    FILE *f;
    long n;
    char *b;

    snprintf(path, sizeof path, "%s/%s", ref_dir, rel);
    f = fopen(path, "rb");
    if (!f || fseek(f, 0, SEEK_END) || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET)) {
        printf("cannot read %s\n", path);
        exit(1);
    }
    b = malloc((size_t)n + 1);
    if (!b || fread(b, 1, (size_t)n, f) != (size_t)n)
        exit(1);
    b[n] = '\0';
    fclose(f);
    *len = (size_t)n;
    return b;
}

/* The NREL 5-MW deck's own coefficients (NRELOffshrBsline5MW_Blade.dat). */
static const double nrel[SM_ED_BLADE_FITS][5] = {
    {0.0622, 1.7254, -3.2452, 4.7131, -2.2555},
    {-0.5809, 1.2067, -15.5349, 29.7347, -13.8255},
    {0.3627, 2.5337, -3.5772, 2.376, -0.6952},
};

/* Import the deck, solve it at 0 rpm with 10 modes and shapes: the result document. */
static json_t *solve_5mw(const char *deck, size_t len)
{
    import_file f = {"NRELOffshrBsline5MW_Blade.dat", deck, len};
    import_options o;
    import_diag d;
    json_t *doc = NULL, *result = NULL;
    codec_request *req = NULL;
    codec_errors *errs = codec_errors_new();
    codec_limits lim;
    codec_run_out out;
    char *text = NULL;

    import_default_options(&o);
    o.tip_radius = 63;
    o.hub_radius = 1.5;
    if (import_elastodyn(&doc, &f, &o, &d) != SM_OK) {
        fail("import: %s", d.text);
        goto done;
    }
    json_object_set_new(json_object_get(json_object_get(doc, "request"), "analysis"), "rpm",
                        json_pack("[f]", 0.0));
    text = json_dumps(json_object_get(doc, "request"), JSON_COMPACT);
    codec_default_limits(&lim);
    if (!text || codec_request_parse(&req, text, strlen(text), &lim, errs) != SM_OK) {
        fail("request refused");
        goto done;
    }
    if (codec_run(req, CODEC_RUN_JSON, NULL, NULL, errs, &out) != CODEC_RUN_DONE)
        fail("run: %s", out.message);
    else
        result = json_incref(out.result);
    codec_run_clear(&out);
done:
    free(text);
    codec_request_free(req);
    codec_errors_free(errs);
    json_decref(doc);
    return result;
}

/* 1-3. The fits. */
static void check_fits(const json_t *result, sm_ed_fit *fits)
{
    static const char *const labels[SM_ED_BLADE_FITS] = {"1st flap", "2nd flap", "1st edge"};
    static const double bound[SM_ED_BLADE_FITS] = {0.02, 0.04, 0.01};
    const json_t *modes =
        json_object_get(json_array_get(json_object_get(result, "cases"), 0), "modes");
    double sum, d0, worst, dphi;
    char why[256];
    int i, k, j;

    if (codec_elastodyn_case(result, 0, fits, why, sizeof why) != SM_OK) {
        fail("codec_elastodyn_case: %s", why);
        return;
    }
    for (i = 0; i < SM_ED_BLADE_FITS; i++) {
        const char *lab = json_string_value(
            json_object_get(json_array_get(modes, (size_t)fits[i].mode), "label"));
        if (fits[i].mode < 0 || !lab || strcmp(lab, labels[i]))
            fail("fit %d: mode %d is \"%s\", want %s", i, fits[i].mode, lab ? lab : "", labels[i]);
        if (fits[i].warning || !(fits[i].share >= 0.9))
            fail("fit %d: share %.4f", i, fits[i].share);
        if (!(fits[i].max_residual < 0.01))
            fail("fit %d: largest residual %.3e of tip (want < 1 %%)", i, fits[i].max_residual);
        for (sum = 0, k = 0; k < 5; k++)
            sum += fits[i].coef[k];
        sm_elastodyn_eval(fits[i].coef, 0, &d0);
        if (fabs(sum - 1) > 1e-14 || d0 != 0)
            fail("fit %d: sum of C - 1 = %.2e, phi'(0) = %g", i, sum - 1, d0);
        for (worst = 0, j = 0; j <= 1000; j++) {
            dphi = fabs(sm_elastodyn_eval(fits[i].coef, j / 1000.0, NULL) -
                        sm_elastodyn_eval(nrel[i], j / 1000.0, NULL));
            worst = dphi > worst ? dphi : worst;
        }
        printf("%s: mode %d, share %.4f, rms %.2e, largest residual %.2e, tip slope error "
               "%.2e; max |dphi| vs the NREL file %.4f\n",
               codec_ed_blade_names[5 * i], fits[i].mode + 1, fits[i].share, fits[i].rms,
               fits[i].max_residual, fits[i].tip_slope_error, worst);
        if (!(worst < bound[i]))
            fail("fit %d: max |dphi| %.4f vs the NREL coefficients (bound %.2f)", i, worst,
                 bound[i]);
    }
}

/* 4. The text has the 15 lines, each value the fit's to 7 digits. */
static void check_text(const json_t *result, const sm_ed_fit *fits)
{
    char v[CODEC_ED_BLADE_VALUES][CODEC_ED_TEXT], tok[64];
    char *out = NULL, why[256], name[32], *line;
    size_t n = 0;
    int seen = 0, i;

    codec_elastodyn_blade_values(fits, v);
    if (codec_result_elastodyn(&out, &n, result, why, sizeof why) != SM_OK || strlen(out) != n) {
        fail("codec_result_elastodyn: %s", why);
        free(out);
        return;
    }
    for (line = strtok(out, "\n"); line; line = strtok(NULL, "\n")) {
        if (line[0] == '!')
            continue;
        if (sscanf(line, "%63s %31s", tok, name) != 2) {
            fail("text: line \"%s\"", line);
            continue;
        }
        for (i = 0; i < CODEC_ED_BLADE_VALUES && strcmp(name, codec_ed_blade_names[i]); i++)
            ;
        if (i == CODEC_ED_BLADE_VALUES || strcmp(tok, v[i]) || i != seen++)
            fail("text: \"%s\"", line);
    }
    if (seen != CODEC_ED_BLADE_VALUES)
        fail("text: %d coefficient lines", seen);
    free(out);
}

/* The value token of name's line in text (a copy into buf), or "" when absent. */
static void value_of(const char *text, const char *name, char *buf, size_t cap)
{
    const char *p = strstr(text, name), *b;

    buf[0] = '\0';
    if (!p)
        return;
    for (b = p; b > text && b[-1] != '\n'; b--)
        ;
    sscanf(b, "%63s", buf);
    (void)cap;
}

/* 5. The patch: byte-identical outside the 15 values. */
static void check_patch(const char *deck, size_t len, const sm_ed_fit *fits)
{
    char v[CODEC_ED_BLADE_VALUES][CODEC_ED_TEXT];
    const char *vp[CODEC_ED_BLADE_VALUES];
    char *out = NULL, why[256], tok[64];
    size_t n = 0, a = 0, b = 0, changed = 0;
    int i;

    codec_elastodyn_blade_values(fits, v);
    for (i = 0; i < CODEC_ED_BLADE_VALUES; i++)
        vp[i] = v[i];
    if (codec_elastodyn_patch(&out, &n, deck, len, codec_ed_blade_names, vp, CODEC_ED_BLADE_VALUES,
                              why, sizeof why) != SM_OK) {
        fail("patch: %s", why);
        return;
    }
    /* walk both texts: equal bytes, except one number token each in 15 places */
    while (a < len && b < n) {
        if (deck[a] == out[b]) {
            a++, b++;
            continue;
        }
        while (a < len && !strchr(" \t\r\n", deck[a]))
            a++;
        while (b < n && !strchr(" \t\r\n", out[b]))
            b++;
        changed++;
    }
    if (a != len || b != n || changed > CODEC_ED_BLADE_VALUES)
        fail("patch: %zu tokens differ, ends %zu/%zu %zu/%zu", changed, a, len, b, n);
    for (i = 0; i < CODEC_ED_BLADE_VALUES; i++) {
        value_of(out, codec_ed_blade_names[i], tok, sizeof tok);
        if (strcmp(tok, v[i]))
            fail("patch: %s = %s, want %s", codec_ed_blade_names[i], tok, v[i]);
    }
    {
        size_t crlf_in = 0, crlf_out = 0, k;
        for (k = 0; k + 1 < len; k++)
            crlf_in += deck[k] == '\r' && deck[k + 1] == '\n';
        for (k = 0; k + 1 < n; k++)
            crlf_out += out[k] == '\r' && out[k + 1] == '\n';
        if (crlf_in != crlf_out || crlf_in < 80)
            fail("patch: CRLF %zu -> %zu", crlf_in, crlf_out);
    }
    printf("patch: %zu -> %zu bytes, %zu value tokens replaced, everything else identical\n", len,
           n, changed);
    free(out);
}

/* The sum of five decimal texts in units of 10^-12 (exact for |C| < 1e6). */
static long long decimal_sum(char text[5][CODEC_ED_TEXT])
{
    long long sum = 0, ip, fp, scale;
    char frac[16];
    int k, neg, j;

    for (k = 0; k < 5; k++) {
        const char *t = text[k], *dot = strchr(t, '.');
        neg = t[0] == '-';
        ip = llabs(strtoll(t, NULL, 10));
        memset(frac, '0', 12);
        frac[12] = '\0';
        if (dot)
            for (j = 0; j < 12 && dot[1 + j]; j++)
                frac[j] = dot[1 + j];
        fp = strtoll(frac, NULL, 10);
        scale = ip * 1000000000000LL + fp;
        sum += neg ? -scale : scale;
    }
    return sum;
}

/* 4b. The written coefficients: seven significant digits on the largest, the same decimals,
 * and an exact decimal sum of 1 even when the given C2..C5 do not sum with C6 to 1 (the NREL
 * file's flap 2 sums to 1.0001). */
static void check_format(const sm_ed_fit *fits)
{
    static const char *const want[2][5] = {
        {"0.062200", "1.725400", "-3.245200", "4.713100", "-2.255500"},
        {"-0.58090", "1.20670", "-15.53490", "29.73470", "-13.82560"},
    };
    char t[5][CODEC_ED_TEXT];
    int r, k;

    for (r = 0; r < 2; r++) {
        codec_elastodyn_format(nrel[r], t);
        for (k = 0; k < 5; k++)
            if (strcmp(t[k], want[r][k]))
                fail("format %d C%d: %s, want %s", r, k + 2, t[k], want[r][k]);
    }
    for (r = 0; r < SM_ED_BLADE_FITS; r++) {
        codec_elastodyn_format(fits[r].coef, t);
        if (decimal_sum(t) != 1000000000000LL)
            fail("fit %d: written sum %lld e-12", r, decimal_sum(t));
        printf("%s..(6) written: %s %s %s %s %s\n", codec_ed_blade_names[5 * r], t[0], t[1], t[2],
               t[3], t[4]);
    }
}

/* 5b. Refusals: a deck without BldEdgSh(6), and one with BldFl1Sh(2) twice. */
static void check_patch_errors(const char *deck, size_t len)
{
    const char *v[CODEC_ED_BLADE_VALUES];
    char *out = NULL, why[256], *bad = malloc(len + 64), *p;
    int i;

    for (i = 0; i < CODEC_ED_BLADE_VALUES; i++)
        v[i] = "0";

    if (!bad)
        exit(1);
    memcpy(bad, deck, len + 1);
    p = strstr(bad, "BldEdgSh(6)");
    if (p)
        p[3] = 'X'; /* BldXdgSh(6) */
    if (codec_elastodyn_patch(&out, NULL, bad, len, codec_ed_blade_names, v, CODEC_ED_BLADE_VALUES,
                              why, sizeof why) != SM_INVALID_INPUT ||
        !strstr(why, "BldEdgSh(6)"))
        fail("missing name: \"%s\"", why);
    free(out);
    memcpy(bad, deck, len + 1);
    p = strstr(bad, "BldFl2Sh(2)");
    if (p)
        memcpy(p, "BldFl1Sh(2)", 11);
    out = NULL;
    if (codec_elastodyn_patch(&out, NULL, bad, len, codec_ed_blade_names, v, CODEC_ED_BLADE_VALUES,
                              why, sizeof why) != SM_INVALID_INPUT ||
        !strstr(why, "second time"))
        fail("name twice: \"%s\"", why);
    printf("refusals: %s\n", why);
    free(out);
    free(bad);
}

int main(int argc, char **argv)
{
    sm_ed_fit fits[SM_ED_BLADE_FITS];
    json_t *result;
    size_t len;
    char *deck;

    if (argc != 2) {
        fprintf(stderr, "usage: elastodyn_test BLADES_DIR\n");
        return 2;
    }
    ref_dir = argv[1];
    deck = slurp("elastodyn/NRELOffshrBsline5MW_Blade.dat", &len);
    result = solve_5mw(deck, len);
    if (result) {
        check_fits(result, fits);
        check_text(result, fits);
        check_format(fits);
        check_patch(deck, len, fits);
    }
    check_patch_errors(deck, len);
    json_decref(result);
    free(deck);
    printf("elastodyn: %d failures\n", failures);
    return failures ? 1 : 0;
}
