/*
 * import_formats.c — the table of import formats: the one place that says
 * which formats exist, what each reads and which importer parses it.
 *
 * How it fits: the CLI (`spinmodal import FORMAT FILE`, server/cli/cli_import.c)
 * and the HTTP route (POST /v1/import/{format}, server/daemon/http_import.c)
 * look their format up here (import_format_find) and then do only what the
 * entry's fields and flags say: neither compares a format's name.  Their
 * messages that list formats ("bmodes, elastodyn or csv") are built from
 * the table too (import_format_list).  The model is dav1d's demuxer table
 * (tools/input/input.c: {name, probe, open, read, close} per container).
 *
 * A new format is one entry below and its parser file (import_NAME.c, with
 * the parse signature import_parse_fn, or a two-line adapter here as for
 * ElastoDyn and CSV, whose public functions take no loader).
 */
#include "import.h"

#include <stdio.h>
#include <string.h>

/* import_parse_fn for ElastoDyn: a blade file, or a main file and the files it names. */
static int imf_elastodyn(json_t **out, const import_file *f, import_loader load, void *ctx,
                         const import_options *o, import_diag *d)
{
    return import_elastodyn_files(out, f, load, ctx, o, d);
}

/* import_parse_fn for CSV: one file, no loader. */
static int imf_csv(json_t **out, const import_file *f, import_loader load, void *ctx,
                   const import_options *o, import_diag *d)
{
    (void)load;
    (void)ctx;
    return import_csv(out, f, o, d);
}

const import_format import_formats[] = {
    {"bmodes", "BModes", "main.bmi", "FILE.bmi [--rpm SPEEDS] [--bmodes-mesh K] [--allow-outside]",
     IMPORT_SEC_FILE | IMPORT_OWN_MESH, import_bmodes},
    {"elastodyn", "ElastoDyn", "blade.dat",
     "BLADE.dat --tip-radius R [--hub-radius H] [--rpm SPEEDS] | MAIN.dat [--part blade [--rpm SPEEDS]]",
     IMPORT_NAMED_FILES, imf_elastodyn},
    {"csv", "CSV", "stations.csv", "FILE [--tip-radius R] [--hub-radius H] [--rpm SPEEDS]", 0,
     imf_csv},
    {NULL, NULL, NULL, NULL, 0, NULL},
};

const import_format *import_format_find(const char *name)
{
    const import_format *f;

    for (f = import_formats; name && f->name; f++)
        if (!strcmp(f->name, name))
            return f;
    return NULL;
}

int import_format_known(const char *name)
{
    return import_format_find(name) != NULL;
}

const char *import_format_list(char *buf, size_t cap, unsigned flags)
{
    const import_format *f;
    size_t len = 0;
    int n = 0, k = 0;

    for (f = import_formats; f->name; f++)
        n += (f->flags & flags) == flags;
    if (cap)
        buf[0] = '\0';
    for (f = import_formats; f->name; f++) {
        if ((f->flags & flags) != flags)
            continue;
        k++;
        if (len < cap)
            len += (size_t)snprintf(buf + len, cap - len, "%s%s",
                                    k == 1 ? "" : k == n ? " or " : ", ", f->name);
    }
    return buf;
}
