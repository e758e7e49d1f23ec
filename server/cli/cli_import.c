/*
 * cli_import.c — `spinmodal import {bmodes|elastodyn|csv} FILE [options]`:
 * turn a blade file into a request (the importers of server/codec/import.h)
 * and print it on stdout, ready for `spinmodal solve -`.
 *
 * How it fits: cli.c's main() hands every `import` command line here.  The
 * format is looked up in the codec's table import_formats[]: its parser, its
 * usage line and which options it takes (--bmodes-mesh, --allow-outside)
 * come from its entry, so no format is named here.  This file reads the
 * files (BModes: the .bmi, then the section-properties file it names,
 * relative to the .bmi's folder and, without --allow-outside, inside it: no
 * absolute path, no '..', never '-'), calls the importer and prints the
 * request; the importer's warnings (values it had to assume) go to stderr as
 * "spinmodal: warning: POINTER: ..." lines (POINTER: the field of the
 * request, as `solve --table` prints a result's input_warnings).  --full
 * prints the whole import document {"request", "warnings", "input_warnings",
 * "source"} instead (what POST /v1/import/{format} answers).  --rpm takes
 * one speed, a list 0,5,10 or a range START:STOP:COUNT (import_rpm_option).
 *
 * Exit codes: 0 imported, 2 the file is refused (one line
 * "FILE:LINE: FIELD: what is wrong" on stderr, nothing on stdout), 1 the
 * main file cannot be read or any other error, 64 usage error.
 */
#include "cli_import.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "import.h"

enum { CLI_IMPORT_OK = 0, CLI_IMPORT_FAILED = 1, CLI_IMPORT_INVALID = 2, CLI_IMPORT_USAGE = 64 };

static const char cli_import_help_text[] =
    "\noptions:\n"
    "  --tip-radius R   m from the spin axis to the tip (ElastoDyn; CSV with s)\n"
    "  --hub-radius H   m from the spin axis to the root (default 0, with a warning)\n"
    "  --rpm SPEEDS     rotor speeds, rev/min (override the file's): one speed 12.1,\n"
    "                   a list 0,5,10 or a range START:STOP:COUNT (COUNT speeds, both\n"
    "                   ends included: 0:15:16 is 0, 1, ... 15 rpm)\n"
    "  --bmodes-mesh K  BModes: its own elements as members, K FE elements each\n"
    "  --allow-outside  BModes: let the .bmi's sec_props_file be an absolute path or\n"
    "                   go up with '..' (by default it must lie in the .bmi's folder\n"
    "                   or below; '-' is never standard input)\n"
    "  --full           print the import document {request, warnings, input_warnings,\n"
    "                   source}\n"
    "  --pretty         indent the JSON output\n"
    "  -h, --help       show this help\n\n"
    "exit status: 0 imported, 2 the file is refused (FILE:LINE: FIELD: ... on stderr),\n"
    "1 a file cannot be read or another error, 64 usage error\n";

/* Command-line settings of `import`. */
typedef struct cli_import_args {
    const import_format *format; /* an entry of import_formats[], NULL until given */
    const char *path;   /* the file, "-" = stdin */
    int pretty;         /* --pretty */
    int full;           /* --full: the import document, not only the request */
    int allow_outside;  /* --allow-outside: sec_props_file may leave the .bmi's folder */
    import_options opt; /* --tip-radius, --hub-radius, --rpm */
    json_t *rpm_speeds; /* --rpm as a list or range (opt.rpm_speeds), NULL for one speed */
} cli_import_args;

/* A file read whole; the loader's context for BModes. */
typedef struct cli_import_files {
    const char *main_path; /* the .bmi as given */
    int allow_outside;     /* --allow-outside */
    char *sec;             /* the section file's text (malloc'd) */
} cli_import_files;

/* The usage lines, one per format of import_formats[], on out. */
static void cli_import_usage_write(FILE *out)
{
    const import_format *f;

    for (f = import_formats; f->name; f++)
        fprintf(out, "%s spinmodal import %s %s [--pretty] [--full]\n",
                f == import_formats ? "usage:" : "      ", f->name, f->synopsis);
}

/* "spinmodal: WHY" and the usage on stderr; the usage exit code. */
static int cli_import_usage(const char *why)
{
    fprintf(stderr, "spinmodal: %s\n", why);
    cli_import_usage_write(stderr);
    return CLI_IMPORT_USAGE;
}

/*
 * Read all of path (stdin_ok and "-": standard input) into *buf (malloc'd,
 * NUL-terminated), at most IMPORT_MAX_BYTES: 0, EFBIG when larger, or an
 * errno value.
 */
static int cli_import_read(const char *path, int stdin_ok, char **buf, size_t *len)
{
    FILE *f = stdin_ok && !strcmp(path, "-") ? stdin : fopen(path, "rb");
    size_t cap = 65536, n = 0, got;
    char *b, *nb;
    int err = 0;

    *buf = NULL;
    *len = 0;
    if (!f)
        return errno ? errno : EIO;
    b = malloc(cap + 1);
    if (!b)
        err = ENOMEM;
    while (!err) {
        if (n == cap) {
            nb = realloc(b, cap * 2 + 1);
            if (!nb) {
                err = ENOMEM;
                break;
            }
            b = nb;
            cap *= 2;
        }
        got = fread(b + n, 1, cap - n, f);
        if (got == 0) {
            err = ferror(f) ? EIO : 0;
            break;
        }
        n += got;
        if (n > IMPORT_MAX_BYTES)
            err = EFBIG;
    }
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

/*
 * Why the section file's name is refused ("" = it is not): '-' (standard input), control
 * characters, and unless --allow-outside an absolute path or a '..' component (the name is a
 * line of the .bmi: a .bmi from elsewhere must not make the CLI read, and quote in its errors,
 * any file the user can read).
 */
static const char *cli_import_sec_name_refused(const char *name, int allow_outside)
{
    const char *p;

    if (!strcmp(name, "-"))
        return "'-' is not standard input here: name the section file";
    for (p = name; *p; p++)
        if ((unsigned char)*p < 0x20 || *p == 0x7f)
            return "the name holds control characters";
    if (allow_outside)
        return "";
    if (name[0] == '/')
        return "an absolute path, outside the .bmi's folder (give --allow-outside to read it)";
    for (p = name; *p; p = strchr(p, '/') ? strchr(p, '/') + 1 : p + strlen(p))
        if (p[0] == '.' && p[1] == '.' && (p[2] == '/' || p[2] == '\0'))
            return "a '..' component leaves the .bmi's folder (give --allow-outside to read it)";
    return "";
}

/* import_loader: the section file, relative to the folder of the .bmi. */
static int cli_import_load(void *ctx, const char *name, import_file *out, char *why, size_t cap)
{
    cli_import_files *fs = ctx;
    const char *slash = strrchr(fs->main_path, '/');
    const char *refused = cli_import_sec_name_refused(name, fs->allow_outside);
    size_t dir = slash && name[0] != '/' ? (size_t)(slash - fs->main_path) + 1 : 0;
    char *path;
    size_t len;
    int err;

    if (*refused) {
        snprintf(why, cap, "%s", refused);
        return SM_INVALID_INPUT;
    }
    if (!(path = malloc(dir + strlen(name) + 1)))
        return SM_NOMEM;
    memcpy(path, fs->main_path, dir);
    strcpy(path + dir, name);
    free(fs->sec); /* a main file may name several (ElastoDyn: tower, then blade) */
    fs->sec = NULL;
    err = cli_import_read(path, 0, &fs->sec, &len);
    free(path);
    if (err == ENOMEM)
        return SM_NOMEM;
    if (err) {
        snprintf(why, cap, "%s", err == EFBIG ? "larger than 16 MiB" : strerror(err));
        return SM_INVALID_INPUT;
    }
    out->name = NULL;
    out->text = fs->sec;
    out->len = len;
    return SM_OK;
}

/* A number option's value: 0, or -1 when it is not a finite number. */
static int cli_import_number(const char *s, double *v)
{
    char *end;

    errno = 0;
    *v = strtod(s, &end);
    return end == s || *end != '\0' || errno || !isfinite(*v) ? -1 : 0;
}

/* --rpm SPEEDS (one, a list or START:STOP:COUNT: import_rpm_option); 0, or an exit code. */
static int cli_import_rpm(cli_import_args *a, const char *text)
{
    char why[200];
    int st;

    json_decref(a->rpm_speeds); /* a second --rpm replaces the first */
    a->rpm_speeds = NULL;
    if (!text)
        return cli_import_usage("--rpm needs a speed, a list or a range");
    st = import_rpm_option(text, &a->opt, &a->rpm_speeds, why, sizeof(why));
    if (st == SM_NOMEM) {
        fprintf(stderr, "spinmodal: out of memory\n");
        return CLI_IMPORT_FAILED;
    }
    if (st) {
        fprintf(stderr, "spinmodal: --rpm: %s\n", why);
        cli_import_usage_write(stderr);
        return CLI_IMPORT_USAGE;
    }
    return 0;
}

/* After the command line: a format and a file given, options that the format takes (its
 * import_formats[] flags); 0, or the usage exit code. */
static int cli_import_args_check(const cli_import_args *a)
{
    char names[200], why[300];

    if (!a->format) {
        snprintf(why, sizeof(why), "a format is required: %s",
                 import_format_list(names, sizeof(names), 0));
        return cli_import_usage(why);
    }
    if (!a->path)
        return cli_import_usage("a file (or - for standard input) is required");
    if (a->opt.bmodes_mesh && !(a->format->flags & IMPORT_OWN_MESH)) {
        snprintf(why, sizeof(why), "--bmodes-mesh applies to %s only",
                 import_format_list(names, sizeof(names), IMPORT_OWN_MESH));
        return cli_import_usage(why);
    }
    if (a->allow_outside && !(a->format->flags & IMPORT_SEC_FILE)) {
        snprintf(why, sizeof(why), "--allow-outside applies to %s only",
                 import_format_list(names, sizeof(names), IMPORT_SEC_FILE));
        return cli_import_usage(why);
    }
    return 0;
}

/* Parse argv[2..] (argv[1] is "import"); 0, or an exit code. */
static int cli_import_args_parse(int argc, char **argv, cli_import_args *a)
{
    static const char *const num_opts[2] = {"--tip-radius", "--hub-radius"};
    double *num_dst[2];
    char names[200];
    int i, k, opts_done = 0;

    import_default_options(&a->opt);
    num_dst[0] = &a->opt.tip_radius;
    num_dst[1] = &a->opt.hub_radius;
    for (i = 2; i < argc; i++) {
        const char *s = argv[i];
        if (!opts_done && !strcmp(s, "--")) {
            opts_done = 1;
            continue;
        }
        if (!opts_done && !strcmp(s, "--pretty")) {
            a->pretty = 1;
            continue;
        }
        if (!opts_done && !strcmp(s, "--full")) {
            a->full = 1;
            continue;
        }
        if (!opts_done && !strcmp(s, "--allow-outside")) {
            a->allow_outside = 1;
            continue;
        }
        if (!opts_done && (!strcmp(s, "--help") || !strcmp(s, "-h"))) {
            cli_import_usage_write(stdout);
            fputs(cli_import_help_text, stdout);
            return -1; /* done: exit 0 */
        }
        if (!opts_done && !strcmp(s, "--part")) { /* ElastoDyn main file: tower or blade */
            if (i + 1 >= argc || (strcmp(argv[i + 1], "blade") && strcmp(argv[i + 1], "tower")))
                return cli_import_usage("--part needs blade or tower (an ElastoDyn main file)");
            a->opt.ed_blade = !strcmp(argv[++i], "blade");
            continue;
        }
        if (!opts_done && !strcmp(s, "--bmodes-mesh")) {
            double per;
            if (i + 1 >= argc || cli_import_number(argv[i + 1], &per) || per < 1 ||
                per > 1000 || per != (int)per)
                return cli_import_usage("--bmodes-mesh needs a whole number of FE elements per "
                                        "BModes element (1 to 1000)");
            a->opt.bmodes_mesh = (int)per;
            i++;
            continue;
        }
        if (!opts_done && !strcmp(s, "--rpm")) {
            if ((k = cli_import_rpm(a, i + 1 < argc ? argv[i + 1] : NULL)))
                return k;
            i++;
            continue;
        }
        for (k = 0; !opts_done && k < 2; k++)
            if (!strcmp(s, num_opts[k]))
                break;
        if (!opts_done && k < 2) {
            if (i + 1 >= argc || cli_import_number(argv[i + 1], num_dst[k])) {
                fprintf(stderr, "spinmodal: %s needs a number\n", s);
                cli_import_usage_write(stderr);
                return CLI_IMPORT_USAGE;
            }
            i++;
            continue;
        }
        if (!opts_done && s[0] == '-' && s[1] != '\0') {
            fprintf(stderr, "spinmodal: unknown option '%s'\n", s);
            cli_import_usage_write(stderr);
            return CLI_IMPORT_USAGE;
        }
        if (!a->format) {
            if (!(a->format = import_format_find(s))) {
                fprintf(stderr, "spinmodal: unknown import format '%s' (%s)\n", s,
                        import_format_list(names, sizeof(names), 0));
                cli_import_usage_write(stderr);
                return CLI_IMPORT_USAGE;
            }
        } else if (!a->path) {
            a->path = s;
        } else {
            return cli_import_usage("only one file may be given");
        }
    }
    return cli_import_args_check(a);
}

/* Print the warnings, then the request (or the whole document); an exit code. */
static int cli_import_print(const cli_import_args *a, const json_t *doc)
{
    const json_t *w;
    char *text;
    size_t i;
    int ok;

    json_array_foreach(json_object_get(doc, "input_warnings"), i, w)
        fprintf(stderr, "spinmodal: warning: %s: %s\n",
                json_string_value(json_object_get(w, "pointer")),
                json_string_value(json_object_get(w, "message")));
    text = import_dumps(a->full ? doc : json_object_get(doc, "request"), a->pretty);
    if (!text) {
        fprintf(stderr, "spinmodal: out of memory\n");
        return CLI_IMPORT_FAILED;
    }
    ok = fputs(text, stdout) != EOF && fputc('\n', stdout) != EOF && fflush(stdout) == 0;
    free(text);
    if (!ok) {
        fprintf(stderr, "spinmodal: cannot write the request: %s\n", strerror(errno));
        return CLI_IMPORT_FAILED;
    }
    return CLI_IMPORT_OK;
}

int cli_import_main(int argc, char **argv)
{
    cli_import_args a;
    cli_import_files fs = {NULL, 0, NULL};
    import_file f;
    import_diag d;
    json_t *doc = NULL;
    char *text = NULL;
    size_t len = 0;
    int rc, st, err;

    memset(&a, 0, sizeof(a));
    if ((rc = cli_import_args_parse(argc, argv, &a))) {
        json_decref(a.rpm_speeds);
        return rc < 0 ? CLI_IMPORT_OK : rc;
    }
    err = cli_import_read(a.path, 1, &text, &len);
    if (err) {
        fprintf(stderr, "spinmodal: cannot read %s: %s\n",
                strcmp(a.path, "-") ? a.path : "standard input",
                err == EFBIG ? "larger than 16 MiB" : strerror(err));
        json_decref(a.rpm_speeds);
        return CLI_IMPORT_FAILED;
    }
    f.name = strcmp(a.path, "-") ? a.path : "<stdin>";
    f.text = text;
    f.len = len;
    fs.main_path = strcmp(a.path, "-") ? a.path : "";
    fs.allow_outside = a.allow_outside;
    st = a.format->parse(&doc, &f, cli_import_load, &fs, &a.opt, &d);
    if (st == SM_OK) {
        rc = cli_import_print(&a, doc);
    } else if (st == SM_INVALID_INPUT) {
        fprintf(stderr, "%s\n", d.text);
        rc = CLI_IMPORT_INVALID;
    } else {
        fprintf(stderr, "spinmodal: import: %s\n", sm_strerror(st));
        rc = CLI_IMPORT_FAILED;
    }
    json_decref(doc);
    json_decref(a.rpm_speeds);
    free(fs.sec);
    free(text);
    return rc;
}
