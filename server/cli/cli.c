/*
 * cli.c — the one-shot `spinmodal` command line tool.
 *
 * How it fits: reads one request (DESIGN.md section 3) from a file or stdin,
 * validates it with the codec, runs it through the codec's pipeline
 * (codec_run: model, solve, documents; the daemon's workers call the same)
 * and prints the result document (section 4) or the CSV frequency table on
 * stdout.  Errors in the request are reported as an RFC 9457 problem
 * document on stderr, exactly as the daemon would send them.
 *
 * Exit codes: 0 every speed has its modes (solved or unstable),
 * 2 invalid input (problem JSON on stderr, nothing on stdout), 3 some speed
 * has no modes: no equilibrium, or its eigen-analysis failed (the result is
 * still printed), 1 any other error (I/O, out of memory, LAPACK), 64 usage
 * error.
 */
#include <errno.h>
#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli_import.h"
#include "codec.h"
#include "elastodyn.h"
#include "mac.h"
#include "spinmodal.h"

/* OpenBLAS: the program chooses its BLAS threads (weak: a reference BLAS links too). */
extern void openblas_set_num_threads(int n) __attribute__((weak));

/*
 * OpenBLAS starts its thread pool (a thread per core) in its own constructor, before main, unless
 * the environment names a count: 4-5 ms of a 15-19 ms small solve on 2 cores (issue 27).
 * With OpenBLAS linked from its archive (meson.build) this constructor runs first (a prioritised
 * one) and, when the user set none of the variables OpenBLAS reads, asks it for one thread;
 * cli_threads then sets the count it always set (1, or the cores for a large dense model:
 * OpenBLAS adds the threads then).  Linked as a shared library, OpenBLAS has started already and
 * this changes nothing.
 */
static int cli_blas_env_ours;
__attribute__((constructor(101))) static void cli_blas_env(void)
{
    if (!getenv("OPENBLAS_NUM_THREADS") && !getenv("GOTO_NUM_THREADS") &&
        !getenv("OMP_NUM_THREADS")) {
        setenv("OPENBLAS_NUM_THREADS", "1", 1);
        cli_blas_env_ours = 1;
    }
}

/* Dense models at least this large (coordinates) keep OpenBLAS's default threads. */
#define CLI_BLAS_THREADED_FROM 1000
/* The most threads a sweep takes by default (--threads: any number from 1 to CLI_THREADS_MAX). */
#define CLI_THREADS_DEFAULT_MAX 16
#define CLI_THREADS_MAX 1024

enum {
    CLI_OK = 0,
    CLI_FAILED = 1,
    CLI_INVALID = 2,
    CLI_NO_EQUILIBRIUM = 3,
    CLI_USAGE = 64
};

/* Command-line settings of `solve` and `validate`. */
typedef struct cli_args {
    const char *command; /* "solve" or "validate" */
    const char *path;    /* request file, "-" = stdin */
    int csv;             /* --csv: frequency table instead of JSON */
    int table;           /* --table: aligned frequency table for a terminal */
    int critical_csv;    /* --critical-csv: the critical speeds as CSV (DESIGN.md 9.1) */
    int pretty;          /* --pretty: indented JSON */
    int threads;         /* --threads N; 0: chosen by cli_threads */
} cli_args;

static const char cli_usage_text[] =
    "usage: spinmodal solve [--csv | --table | --critical-csv] [--pretty] [--threads N] FILE|-\n"
    "       spinmodal validate [--pretty] FILE|-\n"
    "       spinmodal import bmodes|elastodyn|csv FILE [--tip-radius R] [--hub-radius H]\n"
    "                        [--rpm SPEEDS] [--bmodes-mesh K] [--allow-outside] [--pretty] [--full]\n"
    "       spinmodal export spanwise|bmodes RESULT|-\n"
    "       spinmodal export elastodyn RESULT|- [--case K] [--patch DECK]\n"
    "       spinmodal compare A B [--case K] [--case-b K] [--format json|csv] [--pretty]\n"
    "       spinmodal --help | --version\n";

static void cli_help(void)
{
    printf("spinmodal %s: modal analysis of spinning beam structures (planar and spatial)\n"
           "A request is a planar structure (in the rotation plane), a spatial one (flap,\n"
           "lead-lag, torsion, axial) or a blade given by stations (README, DESIGN.md).\n\n%s\n"
           "commands:\n"
           "  solve FILE|-     solve the JSON request in FILE (- = stdin) and print the\n"
           "                   result JSON on stdout\n"
           "  validate FILE|-  check a request; print its canonical form and SHA-256\n"
           "  import FORMAT FILE  turn a BModes .bmi (+ its section file), an ElastoDyn\n"
           "                   blade file or a CSV of stations into a request (stdout);\n"
           "                   ElastoDyn and CSV with s need --tip-radius; --rpm takes a\n"
           "                   speed, a list or START:STOP:COUNT; import --help lists all\n"
           "  export spanwise|bmodes RESULT|-  span-wise mode shapes of a spatial result:\n"
           "                   CSV (s, span_m along the member, flap, edge, twist ...)\n"
           "                   or BModes' table\n"
           "  export elastodyn RESULT|- [--case K] [--patch DECK]  ElastoDyn blade\n"
           "                   mode-shape coefficients (BldFl1Sh, BldFl2Sh, BldEdgSh) with\n"
           "                   the fit report; --patch: DECK with them replaced (case K,\n"
           "                   default 1), every other byte as it was\n"
           "  compare A B      MAC table between the modes of case K (default 1; B's:\n"
           "                   --case-b) of two results, or of a result and a BModes\n"
           "                   .out (its flap and lag columns); same nodes: by index,\n"
           "                   other meshes: by span fraction along each member\n\n"
           "options:\n"
           "  --csv            print the frequency table as CSV instead of JSON\n"
           "  --table          print an aligned table: speed (rad/s, rpm), mode,\n"
           "                   frequency in rad/s, Hz and per revolution, status, label\n"
           "  --critical-csv   print the critical speeds (analysis.engine_orders) as CSV\n"
           "  --pretty         indent the JSON output\n"
           "  --threads N      threads a sweep may use (default: the online cores, at most\n"
           "                   16; 1 when OpenBLAS runs threaded); the result is the same\n"
           "  -h, --help       show this help\n"
           "  -V, --version    show the version\n\n"
           "exit status: 0 solved, 2 invalid request (problem JSON on stderr),\n"
           "3 some speed has no modes (no equilibrium, or its eigen-analysis failed),\n"
           "1 other error, 64 usage error\n",
           SM_VERSION, cli_usage_text);
}

static int cli_usage(const char *why)
{
    fprintf(stderr, "spinmodal: %s\n%s", why, cli_usage_text);
    return CLI_USAGE;
}

/*
 * Read all of path ("-" = stdin), at most max + 1 bytes (so the codec can
 * report "too large").  *buf is malloc'd and NUL-terminated.  Returns 0 or
 * an errno value.
 */
static int cli_read(const char *path, size_t max, char **buf, size_t *len)
{
    FILE *f = strcmp(path, "-") ? fopen(path, "rb") : stdin;
    size_t cap = 65536, n = 0;
    char *b = NULL;
    int err = 0;

    *buf = NULL;
    *len = 0;
    if (!f)
        return errno ? errno : EIO;
    b = malloc(cap + 1);
    if (!b) {
        err = ENOMEM;
        goto done;
    }
    for (;;) {
        size_t want, got;
        if (n == cap) {
            size_t ncap = cap * 2 > max + 1 ? max + 1 : cap * 2;
            char *nb;
            if (ncap <= cap)
                break; /* read max + 1 bytes: enough to know it is too large */
            nb = realloc(b, ncap + 1);
            if (!nb) {
                err = ENOMEM;
                goto done;
            }
            b = nb;
            cap = ncap;
        }
        want = cap - n;
        got = fread(b + n, 1, want, f);
        n += got;
        if (got < want) {
            if (ferror(f))
                err = EIO;
            break;
        }
    }
done:
    if (f != stdin)
        fclose(f);
    if (err) {
        free(b);
        return err;
    }
    b[n] = '\0';
    *buf = b;
    *len = n;
    return 0;
}

/* Print a JSON document and a newline; 0 or -1 on a write error. */
static int cli_print_json(FILE *f, const json_t *doc, int pretty)
{
    size_t flags = JSON_REAL_PRECISION(17) | (pretty ? JSON_INDENT(2) : JSON_COMPACT);

    if ((pretty ? json_dumpf(doc, f, flags) : codec_json_dumpf(doc, f)) || fputc('\n', f) == EOF ||
        fflush(f))
        return -1;
    return 0;
}

/* Problem document for errs on stderr; returns CLI_INVALID. */
static int cli_problem(const codec_errors *errs)
{
    json_t *p = codec_problem_from_errors(errs);

    if (!p) {
        fprintf(stderr, "spinmodal: out of memory\n");
        return CLI_FAILED;
    }
    cli_print_json(stderr, p, 1);
    json_decref(p);
    return CLI_INVALID;
}

static int cli_fail(const char *what, int status)
{
    fprintf(stderr, "spinmodal: %s: %s\n", what, sm_strerror(status));
    return CLI_FAILED;
}

/* Columns of --table: header, decimals (-1: an integer or text). */
#define CLI_TABLE_COLS 8
static const struct {
    const char *head;
    int decimals;
} cli_table_cols[CLI_TABLE_COLS] = {
    {"omega_rad_s", 4}, {"rpm", 2}, {"mode", -1}, {"freq_rad_s", 6}, {"freq_hz", 6},
    {"per_rev", 4}, {"status", -1}, {"label", -1},
};

/* Cell text of a number with d decimals, "-" for null or absent. */
static void cli_cell_num(char *cell, size_t n, const json_t *x, int d)
{
    if (json_is_number(x))
        snprintf(cell, n, "%.*f", d, json_number_value(x));
    else
        snprintf(cell, n, "-");
}

/* analysis.error_estimate (DESIGN.md 9): " +/- e" (e in %.1e, so the column stays aligned) after the
 * frequency in rad/s when the mode has a number there. */
static void cli_cell_estimate(char *cell, size_t n, const json_t *x)
{
    size_t len = strlen(cell);

    if (json_is_number(x) && len < n)
        snprintf(cell + len, n - len, " +/- %.1e", json_number_value(x));
}

/* The cells of one table row of case c and mode m (NULL: a case without modes). */
static void cli_table_row(char cells[CLI_TABLE_COLS][40], const json_t *c, const json_t *m, int k)
{
    cli_cell_num(cells[0], 40, json_object_get(c, "omega"), cli_table_cols[0].decimals);
    cli_cell_num(cells[1], 40, json_object_get(c, "rpm"), cli_table_cols[1].decimals);
    if (m)
        snprintf(cells[2], 40, "%d", k + 1);
    else
        snprintf(cells[2], 40, "-");
    cli_cell_num(cells[3], 40, json_object_get(m, "frequency_rad_s"), cli_table_cols[3].decimals);
    cli_cell_estimate(cells[3], 40, json_object_get(m, "error_estimate"));
    cli_cell_num(cells[4], 40, json_object_get(m, "frequency_hz"), cli_table_cols[4].decimals);
    cli_cell_num(cells[5], 40, json_object_get(m, "per_rev"), cli_table_cols[5].decimals);
    snprintf(cells[6], 40, "%.39s", json_string_value(json_object_get(c, "status")));
    snprintf(cells[7], 40, "%.39s", json_is_string(json_object_get(m, "label"))
                                        ? json_string_value(json_object_get(m, "label")) : "-");
}

/* Print or measure (print 0: widen w) every row of the result's cases. */
static void cli_table_rows(FILE *f, const json_t *cases, int w[CLI_TABLE_COLS], int print)
{
    char cells[CLI_TABLE_COLS][40];
    const json_t *c, *m;
    size_t i, k;
    int j;

    json_array_foreach(cases, i, c) {
        const json_t *modes = json_object_get(c, "modes");
        for (k = 0; k < (json_array_size(modes) ? json_array_size(modes) : 1); k++) {
            m = json_array_get(modes, k);
            cli_table_row(cells, c, m, (int)k);
            for (j = 0; j < CLI_TABLE_COLS; j++) {
                int len = (int)strlen(cells[j]);
                if (!print && len > w[j])
                    w[j] = len;
                if (print)
                    fprintf(f, j < CLI_TABLE_COLS - 1 ? "%*s  " : "%-*s\n", w[j], cells[j]);
            }
        }
    }
}

/*
 * --table: one row per speed and mode, every number of a column with the
 * same decimals, right-aligned (DESIGN.md 8: rad/s, Hz and per revolution
 * side by side).  0 or -1 on a write error.
 */
static int cli_print_table(FILE *f, const json_t *result)
{
    const json_t *cases = json_object_get(result, "cases"), *w = json_object_get(result,
                                                                                 "input_warnings"),
                 *d;
    int width[CLI_TABLE_COLS], j;
    size_t i;

    for (j = 0; j < CLI_TABLE_COLS; j++)
        width[j] = (int)strlen(cli_table_cols[j].head);
    cli_table_rows(f, cases, width, 0);
    for (j = 0; j < CLI_TABLE_COLS; j++)
        fprintf(f, j < CLI_TABLE_COLS - 1 ? "%*s  " : "%-*s\n", width[j], cli_table_cols[j].head);
    cli_table_rows(f, cases, width, 1);
    json_array_foreach(json_object_get(result, "divergence_speeds"), i, d) {
        const json_t *br = json_object_get(d, "bracket");
        int onset = !strcmp(json_string_value(json_object_get(d, "kind")), "onset");
        fprintf(f, "divergence: %s at %.6g rad/s (%.6g rpm), %s mode %s, between %.6g and %.6g rad/s%s\n",
                onset ? "static stability lost" : "static stability regained",
                json_number_value(json_object_get(d, "omega_rad_s")),
                json_number_value(json_object_get(d, "rpm")),
                json_string_value(json_object_get(d, "mode")), onset ? "softens to zero" : "stiffens from zero",
                json_number_value(json_array_get(br, 0)), json_number_value(json_array_get(br, 1)),
                json_is_true(json_object_get(d, "refined")) ? "" : " (not refined)");
    }
    for (i = 0; i < json_array_size(w); i++)
        fprintf(f, "warning: %s: %s\n",
                json_string_value(json_object_get(json_array_get(w, i), "pointer")),
                json_string_value(json_object_get(json_array_get(w, i), "message")));
    return ferror(f) || fflush(f) ? -1 : 0;
}

/* Print the documents of a run (JSON, CSV or the table); returns an exit code. */
static int cli_output(const cli_args *a, const codec_run_out *out)
{
    int rc = CLI_OK;

    if (a->csv) {
        if (fwrite(out->csv, 1, out->csv_len, stdout) != out->csv_len || fflush(stdout))
            rc = CLI_FAILED;
    } else if (a->table) {
        if (cli_print_table(stdout, out->result))
            rc = CLI_FAILED;
    } else if (a->critical_csv) {
        char *csv = NULL;
        size_t n = 0;
        if (codec_critical_speeds_csv(&csv, &n, out->result) != SM_OK ||
            fwrite(csv, 1, n, stdout) != n || fflush(stdout))
            rc = CLI_FAILED;
        free(csv);
    } else if (out->result_text) { /* compact: the daemon's bytes, written case by case */
        if (fwrite(out->result_text, 1, out->result_len, stdout) != out->result_len ||
            fputc('\n', stdout) == EOF || fflush(stdout))
            rc = CLI_FAILED;
    } else if (cli_print_json(stdout, out->result, a->pretty)) {
        rc = CLI_FAILED;
    }
    if (rc == CLI_FAILED) {
        fprintf(stderr, "spinmodal: cannot write the result: %s\n", strerror(errno));
        return rc;
    }
    return out->outcome == CODEC_RUN_PARTIAL ? CLI_NO_EQUILIBRIUM : CLI_OK;
}

/*
 * BLAS threads for this solve, chosen by the program (issue: threads
 * fighting over small matrices made a 48-element solve 6x slower on a busy
 * machine): one thread unless the model takes the dense path with at least
 * CLI_BLAS_THREADED_FROM coordinates, where threaded factorisations pay.  An
 * explicit OPENBLAS_NUM_THREADS in the environment is left alone.  Then the
 * sweep's threads (issue 27): --threads, else the online cores (at most
 * CLI_THREADS_DEFAULT_MAX) unless BLAS runs threaded.
 */
static void cli_threads(const cli_args *a, codec_request *req)
{
    const sm_model_info *info = codec_request_model_info(req);
    int blas_threaded = 1, threads = a->threads;

    const char *env = cli_blas_env_ours ? NULL : getenv("OPENBLAS_NUM_THREADS");
    long cores = sysconf(_SC_NPROCESSORS_ONLN);

    if (openblas_set_num_threads && !env &&
        (info->structured || info->coordinates < CLI_BLAS_THREADED_FROM)) {
        openblas_set_num_threads(1);
        blas_threaded = 0;
    } else if (env) {
        blas_threaded = atoi(env) != 1;
    } else if (openblas_set_num_threads && cli_blas_env_ours && cores > 1) {
        openblas_set_num_threads((int)cores); /* OpenBLAS's own default: a thread per core */
    }
    if (threads == 0) {
        threads = blas_threaded || cores < 1        ? 1
                  : cores > CLI_THREADS_DEFAULT_MAX ? CLI_THREADS_DEFAULT_MAX
                                                    : (int)cores;
    }
    codec_request_set_threads(req, threads);
}

/* Solve a validated request through the codec's pipeline and print; returns an exit code. */
static int cli_solve(const cli_args *a, codec_request *req, codec_errors *errs)
{
    codec_run_out out;
    int rc;

    cli_threads(a, req);
    /* the compact document as text (codec_result_text: no tree of the whole document, and its
     * cases written on the sweep's threads, issue 27); the table and --pretty read the tree */
    unsigned want = a->csv                                     ? CODEC_RUN_CSV
                    : a->table || a->critical_csv || a->pretty ? CODEC_RUN_JSON
                                                               : CODEC_RUN_TEXT;
    switch (codec_run(req, want, NULL, NULL, errs, &out)) {
    case CODEC_RUN_DONE:
    case CODEC_RUN_PARTIAL:
        rc = cli_output(a, &out);
        break;
    case CODEC_RUN_INVALID:
        rc = cli_problem(errs);
        break;
    case CODEC_RUN_FAILED:
        fprintf(stderr, "spinmodal: solve: %s\n", out.message);
        rc = CLI_FAILED;
        break;
    default: /* NOMEM; CANCELED cannot happen without a callback */
        rc = cli_fail("solve", out.status);
        break;
    }
    codec_run_clear(&out);
    return rc;
}

/* `validate`: canonical request and its SHA-256. */
static int cli_validate(const cli_args *a, const codec_request *req)
{
    json_t *doc = json_pack("{s:b, s:s, s:O}", "valid", 1, "request_sha256",
                            codec_request_sha256(req), "canonical",
                            codec_request_canonical(req));
    int rc = CLI_OK;

    if (doc && json_array_size(codec_request_input_warnings(req)) &&
        json_object_set(doc, "input_warnings", (json_t *)codec_request_input_warnings(req))) {
        json_decref(doc);
        doc = NULL;
    }
    if (!doc)
        return cli_fail("validate", SM_NOMEM);
    if (cli_print_json(stdout, doc, a->pretty)) {
        fprintf(stderr, "spinmodal: cannot write the result: %s\n", strerror(errno));
        rc = CLI_FAILED;
    }
    json_decref(doc);
    return rc;
}

/* Read, validate, then solve or validate; returns an exit code. */
static int cli_run(const cli_args *a)
{
    codec_limits lim;
    codec_errors *errs = codec_errors_new();
    codec_request *req = NULL;
    char *text = NULL;
    size_t len = 0;
    int err, st, rc;

    if (!errs)
        return cli_fail("start", SM_NOMEM);
    codec_default_limits(&lim);
    err = cli_read(a->path, lim.max_request_bytes, &text, &len);
    if (err) {
        fprintf(stderr, "spinmodal: cannot read %s: %s\n",
                strcmp(a->path, "-") ? a->path : "standard input", strerror(err));
        rc = CLI_FAILED;
        goto done;
    }
    st = codec_request_parse(&req, text, len, &lim, errs);
    if (st == SM_INVALID_INPUT) {
        rc = cli_problem(errs);
        goto done;
    }
    if (st != SM_OK) {
        rc = cli_fail("request", st);
        goto done;
    }
    rc = !strcmp(a->command, "validate") ? cli_validate(a, req) : cli_solve(a, req, errs);
done:
    codec_request_free(req);
    free(text);
    codec_errors_free(errs);
    return rc;
}

/* Write out[n] to stdout and free it; CLI_OK or CLI_FAILED. */
static int cli_put(char *out, size_t n)
{
    int e = fwrite(out, 1, n, stdout) != n || fflush(stdout);

    free(out);
    return e ? CLI_FAILED : CLI_OK;
}

/* The result document at path ("-" = stdin) into *doc; CLI_OK or CLI_FAILED (said why). */
static int cli_load_result(const char *path, json_t **doc)
{
    json_error_t jerr;
    char *text = NULL;
    size_t len = 0;
    int e = cli_read(path, (size_t)1 << 31, &text, &len);

    *doc = NULL;
    if (e) {
        fprintf(stderr, "spinmodal: %s: %s\n", path, strerror(e));
        return CLI_FAILED;
    }
    *doc = json_loadb(text, len, 0, &jerr);
    free(text);
    if (!*doc) {
        fprintf(stderr, "spinmodal: %s:%d: not a result document: %s\n", path, jerr.line,
                jerr.text);
        return CLI_FAILED;
    }
    return CLI_OK;
}

/* The deck at deck_path with case ci's blade (or tower) coefficients of doc
 * (elastodyn_patch.c). */
static int cli_patch_deck(const json_t *doc, long ci, const char *deck_path, char *why,
                          size_t whycap, char **out, size_t *n)
{
    sm_ed_fit fits[CODEC_ED_TOWER_FITS];
    char v[CODEC_ED_TOWER_VALUES][CODEC_ED_TEXT];
    const char *vp[CODEC_ED_TOWER_VALUES];
    const char *const *names = NULL;
    char *deck = NULL;
    size_t dlen = 0;
    int st, e, i, nfit = 0;

    st = codec_elastodyn_fits(doc, (size_t)ci - 1, fits, &nfit, &names, why, whycap);
    for (i = 0; st == SM_OK && i < nfit; i++)
        if (fits[i].mode < 0) {
            snprintf(why, whycap, "case %ld: no mode for %.8s: ask for more modes", ci,
                     names[5 * i]);
            st = SM_INVALID_INPUT;
        }
    if (st)
        return st;
    e = cli_read(deck_path, (size_t)1 << 26, &deck, &dlen);
    if (e) {
        snprintf(why, whycap, "%s: %s", deck_path, strerror(e));
        return SM_INVALID_INPUT;
    }
    codec_elastodyn_values(fits, nfit, v);
    for (i = 0; i < 5 * nfit; i++)
        vp[i] = v[i];
    st = codec_elastodyn_patch(out, n, deck, dlen, names, vp, 5 * nfit, why, whycap);
    free(deck);
    return st;
}

/* spinmodal export elastodyn RESULT|- [--case K] [--patch DECK]: the coefficients' text
 * (codec_result_elastodyn, what ?format=elastodyn serves) or the patched DECK. */
static int cli_export_elastodyn(int argc, char **argv)
{
    const char *deck = NULL, *path = NULL;
    char *out = NULL, why[512] = "", *end;
    long ci = 1;
    size_t n = 0;
    json_t *doc;
    int i, st;

    for (i = 3; i < argc; i++) {
        if (!strcmp(argv[i], "--patch") && i + 1 < argc)
            deck = argv[++i];
        else if (!strcmp(argv[i], "--case") && i + 1 < argc) {
            ci = strtol(argv[++i], &end, 10);
            if (*end || ci < 1 || ci > 1000000)
                return cli_usage("--case takes a case number from 1");
        } else if (!path && (argv[i][0] != '-' || !strcmp(argv[i], "-")))
            path = argv[i];
        else
            return cli_usage("export elastodyn takes RESULT|- [--case K] [--patch DECK]");
    }
    if (!path)
        return cli_usage("export elastodyn takes a result file (or -)");
    if (cli_load_result(path, &doc))
        return CLI_FAILED;
    st = deck ? cli_patch_deck(doc, ci, deck, why, sizeof why, &out, &n)
              : codec_result_elastodyn(&out, &n, doc, why, sizeof why);
    json_decref(doc);
    if (st) {
        fprintf(stderr, "spinmodal: %s: %s\n", st == SM_NOMEM ? "export" : path,
                st == SM_NOMEM ? "out of memory" : why);
        return CLI_FAILED;
    }
    return cli_put(out, n);
}

/* spinmodal export spanwise|bmodes RESULT|-: codec_result_spanwise of a result document. */
static int cli_export_main(int argc, char **argv)
{
    json_error_t jerr;
    json_t *doc;
    char *text = NULL, *out = NULL, why[256];
    size_t len = 0, n = 0;
    int bmodes, st, e;

    if (argc >= 3 && !strcmp(argv[2], "elastodyn"))
        return cli_export_elastodyn(argc, argv);
    if (argc != 4)
        return cli_usage("export takes a format (spanwise or bmodes) and a result file (or -)");
    if (strcmp(argv[2], "spanwise") && strcmp(argv[2], "bmodes"))
        return cli_usage("export formats: spanwise (CSV) or bmodes (text table)");
    bmodes = !strcmp(argv[2], "bmodes");
    e = cli_read(argv[3], (size_t)1 << 31, &text, &len);
    if (e) {
        fprintf(stderr, "spinmodal: %s: %s\n", argv[3], strerror(e));
        return CLI_FAILED;
    }
    doc = json_loadb(text, len, 0, &jerr);
    free(text);
    if (!doc) {
        fprintf(stderr, "spinmodal: %s:%d: not a result document: %s\n", argv[3], jerr.line,
                jerr.text);
        return CLI_FAILED;
    }
    st = codec_result_spanwise(&out, &n, doc, bmodes, why, sizeof why);
    json_decref(doc);
    if (st == SM_INVALID_INPUT) {
        fprintf(stderr, "spinmodal: %s: %s\n", argv[3], why);
        return CLI_FAILED;
    }
    if (st) {
        fprintf(stderr, "spinmodal: out of memory\n");
        return CLI_FAILED;
    }
    e = fwrite(out, 1, n, stdout) != n || fflush(stdout);
    free(out);
    return e ? CLI_FAILED : CLI_OK;
}

/* One side of compare: a result document, or a BModes .out (no '{' first); CLI_OK or not. */
static int cli_mac_side(const char *path, long case_no, int comp, codec_mac_set *x)
{
    char *text = NULL, why[400] = "";
    size_t len = 0, i = 0;
    json_t *doc = NULL;
    int e = cli_read(path, (size_t)1 << 31, &text, &len), st;

    if (e) {
        fprintf(stderr, "spinmodal: %s: %s\n", path, strerror(e));
        return CLI_FAILED;
    }
    while (i < len && (text[i] == ' ' || text[i] == '\n' || text[i] == '\r' || text[i] == '\t'))
        i++;
    if (i < len && text[i] == '{') {
        json_error_t jerr;
        doc = json_loadb(text, len, 0, &jerr);
        st = doc ? codec_mac_from_result(x, doc, case_no, comp, why, sizeof why) : SM_INVALID_INPUT;
        if (!doc)
            snprintf(why, sizeof why, "line %d: not a result document: %s", jerr.line, jerr.text);
    } else
        st = codec_mac_from_bmodes_out(x, text, len, why, sizeof why);
    free(text);
    json_decref(doc);
    if (st)
        fprintf(stderr, "spinmodal: %s: %s\n", path, st == SM_NOMEM ? "out of memory" : why);
    return st == SM_OK ? CLI_OK : st == SM_NOMEM ? CLI_FAILED : CLI_INVALID;
}

/* 1 when the file at path starts with something other than '{' (a BModes .out). */
static int cli_is_table(const char *path)
{
    FILE *f = strcmp(path, "-") ? fopen(path, "rb") : NULL;
    int c = ' ';
    while (f && (c == ' ' || c == '\n' || c == '\r' || c == '\t'))
        c = fgetc(f);
    if (f)
        fclose(f);
    return f && c != '{';
}

/* spinmodal compare A B [--case K] [--case-b K] [--format json|csv] [--pretty]: codec_mac_doc. */
static int cli_compare(int argc, char **argv)
{
    const char *path[2] = {NULL, NULL};
    long ck[2] = {1, 0};
    int csv = 0, pretty = 0, i, np = 0, rc = CLI_FAILED, comp;
    codec_mac_set x[2];
    char why[400] = "";
    json_t *doc = NULL;

    for (i = 2; i < argc; i++) {
        if ((!strcmp(argv[i], "--case") || !strcmp(argv[i], "--case-b")) && i + 1 < argc) {
            char *end;
            long *k = &ck[argv[i][6] == '-'];
            *k = strtol(argv[++i], &end, 10);
            if (*end || *k < 1)
                return cli_usage("--case and --case-b take a case number from 1");
        } else if (!strcmp(argv[i], "--format") && i + 1 < argc) {
            csv = !strcmp(argv[++i], "csv");
            if (!csv && strcmp(argv[i], "json"))
                return cli_usage("compare formats: json or csv");
        } else if (!strcmp(argv[i], "--pretty"))
            pretty = 1;
        else if (np < 2 && (argv[i][0] != '-' || !strcmp(argv[i], "-")))
            path[np++] = argv[i];
        else
            return cli_usage("compare takes A B [--case K] [--case-b K] [--format json|csv]");
    }
    if (np != 2)
        return cli_usage("compare takes two files: results (JSON) or BModes .out tables");
    if (!ck[1])
        ck[1] = ck[0];
    comp = cli_is_table(path[0]) || cli_is_table(path[1]) ? CODEC_MAC_FLAP_LAG : CODEC_MAC_HUB;
    memset(x, 0, sizeof x);
    if ((rc = cli_mac_side(path[0], ck[0], comp, &x[0])) ||
        (rc = cli_mac_side(path[1], ck[1], comp, &x[1])))
        goto done;
    i = codec_mac_doc(&doc, &x[0], &x[1], comp, why, sizeof why);
    if (i) {
        fprintf(stderr, "spinmodal: compare: %s\n", i == SM_NOMEM ? "out of memory" : why);
        rc = i == SM_NOMEM ? CLI_FAILED : CLI_INVALID;
    } else if (csv) {
        char *out = NULL;
        size_t n = 0;
        rc = codec_mac_csv(&out, &n, doc) ? CLI_FAILED : cli_put(out, n);
    } else
        rc = cli_print_json(stdout, doc, pretty);
done:
    json_decref(doc);
    codec_mac_set_free(&x[0]);
    codec_mac_set_free(&x[1]);
    return rc;
}

int main(int argc, char **argv)
{
    cli_args a = {NULL, NULL, 0, 0, 0, 0, 0};
    int i, opts_done = 0;

    /* The solver allocates and frees matrices of 0.1-4 MB at every Newton step and speed:
     * glibc's defaults hand such blocks back to the kernel and fault them in again (42 000
     * page faults in a 101-speed sweep of the angled beam, 3 000 with these; DESIGN.md 2.1). */
    mallopt(M_MMAP_THRESHOLD, 4 << 20);
    mallopt(M_TRIM_THRESHOLD, 16 << 20);
    /* No fastbins: a request's JSON trees are thousands of small blocks, and with fastbins
     * every free that joins a large free block (64 kB and up) sweeps all of them again
     * (malloc_consolidate: a fifth of a 720 kB blade request's parse, issue 27); without them
     * a free joins its neighbours at once.  The thread caches (tcache) stay. */
    mallopt(M_MXFAST, 0);

    if (argc < 2)
        return cli_usage("a command is required");
    if (!strcmp(argv[1], "import"))
        return cli_import_main(argc, argv);
    if (!strcmp(argv[1], "export"))
        return cli_export_main(argc, argv);
    if (!strcmp(argv[1], "compare"))
        return cli_compare(argc, argv);
    for (i = 1; i < argc; i++) {
        const char *s = argv[i];
        if (!opts_done && (!strcmp(s, "-h") || !strcmp(s, "--help") || !strcmp(s, "help"))) {
            cli_help();
            return CLI_OK;
        }
        if (!opts_done && (!strcmp(s, "-V") || !strcmp(s, "--version"))) {
            printf("spinmodal %s\n", SM_VERSION);
            return CLI_OK;
        }
        if (!opts_done && !strcmp(s, "--")) {
            opts_done = 1;
        } else if (!opts_done && !strcmp(s, "--csv")) {
            a.csv = 1;
        } else if (!opts_done && !strcmp(s, "--table")) {
            a.table = 1;
        } else if (!opts_done && !strcmp(s, "--critical-csv")) {
            a.critical_csv = 1;
        } else if (!opts_done && !strcmp(s, "--pretty")) {
            a.pretty = 1;
        } else if (!opts_done && !strcmp(s, "--threads")) {
            char *end = NULL;
            long t = i + 1 < argc ? strtol(argv[i + 1], &end, 10) : 0;
            if (!end || *end || t < 1 || t > CLI_THREADS_MAX)
                return cli_usage("--threads takes a number of threads from 1 to 1024");
            a.threads = (int)t;
            i++;
        } else if (!opts_done && s[0] == '-' && s[1] != '\0') {
            fprintf(stderr, "spinmodal: unknown option '%s'\n%s", s, cli_usage_text);
            return CLI_USAGE;
        } else if (!a.command) {
            if (strcmp(s, "solve") && strcmp(s, "validate")) {
                fprintf(stderr, "spinmodal: unknown command '%s'\n%s", s, cli_usage_text);
                return CLI_USAGE;
            }
            a.command = s;
        } else if (!a.path) {
            a.path = s;
        } else {
            return cli_usage("only one request file may be given");
        }
    }
    if (!a.command)
        return cli_usage("a command is required");
    if (!a.path)
        return cli_usage("a request file (or - for standard input) is required");
    if ((a.csv || a.table || a.critical_csv) && strcmp(a.command, "solve"))
        return cli_usage("--csv, --table and --critical-csv apply to solve only");
    if (a.csv + a.table + a.critical_csv > 1)
        return cli_usage("give one of --csv, --table and --critical-csv");
    return cli_run(&a);
}
