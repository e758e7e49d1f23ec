/*
 * elastodyn_patch.c — "patch this deck": a copy of an ElastoDyn blade (or tower) file with
 * the mode-shape coefficients replaced and every other byte as it was (DESIGN.md 9.3).
 *
 * How it fits: `spinmodal export elastodyn RESULT --patch DECK` gets the values from
 * codec_elastodyn_case (elastodyn_text.c) and the names from codec_ed_blade_names; a tower
 * caller passes TwFAM1Sh(2)... the same way.  ElastoDyn reads a parameter line as "value
 * name - description", so the value is the line's first token and the name its second
 * (import_elastodyn.c reads them so too).  Only that first token is rewritten: its leading
 * blanks, the rest of the line and the line end (CRLF kept) are copied.  Helpers are edp_*.
 */
#include "elastodyn.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* A token of a line: bytes [s, s + n). */
typedef struct edp_tok {
    const char *s;
    size_t n;
} edp_tok;

static int edp_blank(char c)
{
    return c == ' ' || c == '\t';
}

/* The first two tokens of the line [p, end) (end excludes the line end). */
static void edp_tokens(const char *p, const char *end, edp_tok *value, edp_tok *name)
{
    const char *q;

    while (p < end && edp_blank(*p))
        p++;
    for (q = p; q < end && !edp_blank(*q) && *q != '\r'; q++)
        ;
    *value = (edp_tok){p, (size_t)(q - p)};
    for (p = q; p < end && edp_blank(*p); p++)
        ;
    for (q = p; q < end && !edp_blank(*q) && *q != '\r'; q++)
        ;
    *name = (edp_tok){p, (size_t)(q - p)};
}

/* Index of the name tok among names[0..n), or -1. */
static int edp_find(const edp_tok *tok, const char *const *names, int n)
{
    int i;

    for (i = 0; i < n; i++)
        if (tok->n == strlen(names[i]) && !strncasecmp(tok->s, names[i], tok->n))
            return i;
    return -1;
}

/* Line number (1-based) of position p in text. */
static int edp_line(const char *text, const char *p)
{
    int line = 1;

    for (; text < p; text++)
        line += *text == '\n';
    return line;
}

/* Find each name's value token; *where[i] is its token (s NULL when not seen). */
static int edp_locate(const char *text, size_t len, const char *const *names, int n, edp_tok *where,
                      char *err, size_t errcap)
{
    const char *p = text, *end = text + len, *eol;
    edp_tok value, name;
    int i;

    for (i = 0; i < n; i++)
        where[i] = (edp_tok){NULL, 0};
    for (; p < end; p = eol + 1) {
        eol = memchr(p, '\n', (size_t)(end - p));
        if (!eol)
            eol = end;
        edp_tokens(p, eol, &value, &name);
        i = edp_find(&name, names, n);
        if (i < 0 || !value.n)
            continue;
        if (where[i].s) {
            snprintf(err, errcap, "line %d: %s given a second time (first on line %d)",
                     edp_line(text, p), names[i], edp_line(text, where[i].s));
            return SM_INVALID_INPUT;
        }
        where[i] = value;
        if (eol == end)
            break;
    }
    for (i = 0; i < n; i++)
        if (!where[i].s) {
            snprintf(err, errcap, "no line \"value %s - ...\" in the deck", names[i]);
            return SM_INVALID_INPUT;
        }
    return SM_OK;
}

/* Write text with each located token replaced by its value. */
static int edp_write(FILE *f, const char *text, size_t len, const edp_tok *where,
                     const char *const *values, int n)
{
    const char *p = text, *end = text + len, *next;
    int i, best;

    for (;;) {
        best = -1; /* the next token to replace after p */
        for (i = 0; i < n; i++)
            if (where[i].s >= p && (best < 0 || where[i].s < where[best].s))
                best = i;
        next = best < 0 ? end : where[best].s;
        if (fwrite(p, 1, (size_t)(next - p), f) != (size_t)(next - p))
            return SM_NOMEM;
        if (best < 0)
            return SM_OK;
        fputs(values[best], f);
        p = next + where[best].n;
    }
}

int codec_elastodyn_patch(char **out, size_t *len, const char *text, size_t text_len,
                          const char *const *names, const char *const *values, int n, char *err,
                          size_t errcap)
{
    edp_tok *where = NULL;
    char *buf = NULL, dummy[8];
    size_t size = 0;
    FILE *f;
    int i, rc;

    *out = NULL;
    if (!err || !errcap) {
        err = dummy;
        errcap = sizeof dummy;
    }
    err[0] = '\0';
    for (i = 0; i < n; i++)
        if (!values[i][0] || strpbrk(values[i], " \t\r\n")) {
            snprintf(err, errcap, "%s: the value \"%s\" is not one token", names[i], values[i]);
            return SM_INVALID_INPUT;
        }
    where = malloc((size_t)(n > 0 ? n : 1) * sizeof *where);
    if (!where)
        return SM_NOMEM;
    rc = edp_locate(text, text_len, names, n, where, err, errcap);
    if (rc)
        goto done;
    f = open_memstream(&buf, &size);
    if (!f) {
        rc = SM_NOMEM;
        goto done;
    }
    rc = edp_write(f, text, text_len, where, values, n);
    if (fclose(f) || rc) {
        free(buf);
        rc = SM_NOMEM;
        goto done;
    }
    *out = buf;
    if (len)
        *len = size;
done:
    free(where);
    return rc;
}
