/*
 * import.c — what the importers share: reading lines and tokens, numbers,
 * the "FILE:LINE: FIELD: what is wrong" diagnostics, the table of stations
 * and the request document in the blade form (spec 12 sections 1, 2, 6).
 *
 * How it fits: import_bmodes.c, import_elastodyn.c and import_csv.c each
 * read their format into an imp_table (one imp_station per row, values
 * checked as they are read, with the file's own column names in messages)
 * and an imp_blade (length, hub radius, tip mass, speed), then call
 * imp_document.  Nothing here touches the file system or builds a model:
 * the cost is linear in the text, which the caller has already bounded.
 *
 * Numbers are rounded to 15 significant digits when they enter the
 * document and printed with the same precision (import_dumps), so the text
 * holds exactly the values the checks saw: "181.672", not
 * "181.67200000000001".
 */
#include "import_internal.h"

#include <ctype.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codec.h"

#define IMP_DUMP_PRECISION 15

/* ------------------------------------------------------------ options */

void import_default_options(import_options *o)
{
    codec_limits lim;

    codec_default_limits(&lim);
    o->tip_radius = NAN;
    o->hub_radius = NAN;
    o->rpm = NAN;
    o->rpm_speeds = NULL;
    o->max_modes = lim.max_modes;
    o->bmodes_mesh = 0;
    o->ed_blade = 0;
}

/*
 * One speed of an --rpm option, text[0..n): 0, or -1 when not a number >= 0 that a request
 * carries (imp_finite; a lone speed is checked by imp_option instead, as the file's).
 */
static int imp_rpm_number(const char *text, size_t n, double *v)
{
    char buf[64], *end;

    if (n == 0 || n >= sizeof(buf))
        return -1;
    memcpy(buf, text, n);
    buf[n] = '\0';
    *v = strtod(buf, &end);
    return end == buf || *end != '\0' || !(*v >= 0.0) || !imp_finite(*v) ? -1 : 0;
}

/* "START:STOP:COUNT" (colon at c1 and c2) into o and *speeds; see import_rpm_option. */
static int imp_rpm_range(const char *text, const char *c1, const char *c2, import_options *o,
                         json_t **speeds, char *why, size_t cap)
{
    double from, to, count;

    if (imp_rpm_number(text, (size_t)(c1 - text), &from) ||
        imp_rpm_number(c1 + 1, (size_t)(c2 - c1 - 1), &to) ||
        imp_rpm_number(c2 + 1, strlen(c2 + 1), &count) || count != floor(count) ||
        count < 1 || count > 1e9) {
        snprintf(why, cap, "expected START:STOP:COUNT with speeds >= 0 and a whole COUNT >= 1 "
                 "(\"%.40s\")", text);
        return SM_INVALID_INPUT;
    }
    if (to < from) {
        snprintf(why, cap, "the range runs from %g to %g rpm: STOP must not be below START",
                 from, to);
        return SM_INVALID_INPUT;
    }
    if (count == 1 && to != from) {
        snprintf(why, cap, "%g:%g:1 would be %g rpm alone: COUNT is the number of speeds, both "
                 "ends included (%g:%g:%.0f is every 1 rpm)", from, to, from, from, to,
                 to - from == floor(to - from) && to - from < 1e6 ? to - from + 1 : 2.0);
        return SM_INVALID_INPUT;
    }
    o->rpm = from;
    *speeds = count == 1 ? json_pack("[f]", from)
                         : json_pack("{s:f, s:f, s:I}", "from", from, "to", to, "steps",
                                     (json_int_t)(count - 1));
    return *speeds ? SM_OK : SM_NOMEM;
}

/* import_rpm_option but for o->rpm_speeds. */
static int imp_rpm_parse(const char *text, import_options *o, json_t **speeds, char *why,
                         size_t cap)
{
    const char *c1 = strchr(text, ':'), *c2 = c1 ? strchr(c1 + 1, ':') : NULL, *p, *comma;
    double v;

    *speeds = NULL;
    if (c1 && c2 && !strchr(c2 + 1, ':'))
        return imp_rpm_range(text, c1, c2, o, speeds, why, cap);
    if (c1) {
        snprintf(why, cap, "a range is START:STOP:COUNT (\"%.40s\")", text);
        return SM_INVALID_INPUT;
    }
    if (!strchr(text, ',')) {
        char *end;
        o->rpm = strtod(text, &end);
        if (end == text || *end != '\0' || !isfinite(o->rpm) || o->rpm < 0.0)
            goto bad;
        return SM_OK; /* imp_option refuses it beyond what a request carries */
    }
    if (!(*speeds = json_array()))
        return SM_NOMEM;
    for (p = text;; p = comma + 1) {
        comma = strchr(p, ',');
        if (imp_rpm_number(p, comma ? (size_t)(comma - p) : strlen(p), &v))
            goto bad;
        if (json_array_append_new(*speeds, json_real(v))) {
            json_decref(*speeds);
            *speeds = NULL;
            return SM_NOMEM;
        }
        if (!comma)
            break;
    }
    o->rpm = json_number_value(json_array_get(*speeds, 0));
    return SM_OK;
bad:
    json_decref(*speeds);
    *speeds = NULL;
    snprintf(why, cap, "expected a speed >= 0 (rev/min), a list 0,5,10 or a range "
             "START:STOP:COUNT (\"%.40s\")", text);
    return SM_INVALID_INPUT;
}

int import_rpm_option(const char *text, import_options *o, json_t **speeds, char *why,
                      size_t cap)
{
    int st = imp_rpm_parse(text, o, speeds, why, cap);

    o->rpm_speeds = st == SM_OK ? *speeds : NULL;
    return st;
}

/* ----------------------------------------------------------- encoding */

int imp_encoding(import_diag *d, const import_file *f, import_file *body)
{
    const unsigned char *u = (const unsigned char *)f->text;
    const char *nul;
    size_t skip = 0;

    if (f->len >= 2 && ((u[0] == 0xFF && u[1] == 0xFE) || (u[0] == 0xFE && u[1] == 0xFF)))
        return imp_fail(d, f->name, 1, "encoding", "the file is UTF-16 (byte-order mark %02X "
                        "%02X): save it as UTF-8 (Excel: \"CSV UTF-8\"; Notepad: Save as, "
                        "Encoding UTF-8)", u[0], u[1]);
    if (f->len >= 3 && u[0] == 0xEF && u[1] == 0xBB && u[2] == 0xBF)
        skip = 3; /* UTF-8 byte-order mark, as Excel's "CSV UTF-8" writes */
    if ((nul = memchr(f->text, '\0', f->len))) {
        int line = 1;
        const char *p;
        for (p = f->text; p < nul; p++) /* LF, CRLF or CR ends a line (imp_next) */
            line += *p == '\n' || (*p == '\r' && p + 1 < nul && p[1] != '\n');
        return imp_fail(d, f->name, line, "encoding", "the file holds NUL bytes: it is UTF-16 "
                        "or binary, not text; save it as UTF-8 (Excel: \"CSV UTF-8\")");
    }
    *body = *f; /* body may be f */
    body->text += skip;
    body->len -= skip;
    return SM_OK;
}

/* -------------------------------------------------------------- lines */

void imp_reader_init(imp_reader *r, const import_file *f)
{
    r->f = f;
    r->pos = 0;
    r->line = 0;
    r->s = NULL;
    r->n = 0;
}

int imp_next(imp_reader *r)
{
    const char *t = r->f->text;
    size_t len = r->f->len, i = r->pos;

    if (i >= len)
        return 0;
    while (i < len && t[i] != '\n' && t[i] != '\r')
        i++;
    r->s = t + r->pos;
    r->n = i - r->pos;
    r->line++;
    if (i < len && t[i] == '\r')
        i++;
    if (i < len && t[i] == '\n' && (i == r->pos + r->n || t[i - 1] == '\r'))
        i++;
    r->pos = i;
    return 1;
}

int imp_blank(const char *s, size_t n)
{
    size_t i;

    for (i = 0; i < n; i++)
        if (s[i] != ' ' && s[i] != '\t' && s[i] != '\f' && s[i] != '\v')
            return 0;
    return 1;
}

int imp_next_nonblank(imp_reader *r)
{
    while (imp_next(r))
        if (!imp_blank(r->s, r->n))
            return 1;
    return 0;
}

/* ------------------------------------------------------------- tokens */

static int imp_space(char c)
{
    return c == ' ' || c == '\t' || c == '\f' || c == '\v';
}

int imp_split(const char *s, size_t n, const char *seps, imp_tok *t, int max)
{
    size_t i = 0, b, e;
    int count = 0;

    for (;;) {
        while (i < n && (imp_space(s[i]) || (s[i] != '\0' && strchr(seps, s[i]))))
            i++;
        if (i >= n)
            break;
        if (s[i] == '\'' || s[i] == '"') {
            char q = s[i++];
            b = i;
            while (i < n && s[i] != q)
                i++;
            e = i;
            if (i < n)
                i++;
        } else {
            b = i;
            while (i < n && !imp_space(s[i]) && !(s[i] != '\0' && strchr(seps, s[i])))
                i++;
            e = i;
        }
        if (count < max) {
            t[count].s = s + b;
            t[count].n = e - b;
        }
        count++;
    }
    return count;
}

void imp_tok_copy(char *dst, size_t cap, const imp_tok *t)
{
    size_t i, n = t->n < cap - 1 ? t->n : cap - 1;

    for (i = 0; i < n; i++) {
        unsigned char c = (unsigned char)t->s[i];
        dst[i] = c < 0x20 || c >= 0x7f ? '?' : (char)c; /* ASCII: messages go into JSON */
    }
    dst[n] = '\0';
}

void imp_excerpt(char *dst, size_t cap, const imp_tok *t)
{
    size_t i, k = 0, room = cap - 4 < IMP_EXCERPT ? cap - 4 : IMP_EXCERPT; /* "..." + NUL */

    for (i = 0; i < t->n; i++) {
        unsigned char c = (unsigned char)t->s[i];
        char one[5];
        size_t w;
        if (c < 0x20 || c >= 0x7f)
            w = (size_t)snprintf(one, sizeof(one), "\\x%02x", c);
        else if (c == '"' || c == '\\')
            w = (size_t)snprintf(one, sizeof(one), "\\%c", c);
        else
            w = (size_t)snprintf(one, sizeof(one), "%c", c);
        if (k + w > room) {
            memcpy(dst + k, "...", 3);
            k += 3;
            break;
        }
        memcpy(dst + k, one, w);
        k += w;
    }
    dst[k] = '\0';
}

json_t *imp_string(const char *s)
{
    imp_tok t = {s ? s : "", s ? strlen(s) : 0};
    char buf[256];

    imp_tok_copy(buf, sizeof(buf), &t);
    return json_string(buf);
}

/* ------------------------------------------------------------ numbers */

int imp_number(const imp_tok *t, double *v)
{
    char buf[64], *end;
    size_t i;
    double x;

    if (t->n == 0 || t->n >= sizeof(buf))
        return -1;
    for (i = 0; i < t->n; i++) {
        char c = t->s[i];
        if (!(isdigit((unsigned char)c) || c == '+' || c == '-' || c == '.' || c == 'e' ||
              c == 'E' || c == 'd' || c == 'D'))
            return -1; /* no "nan", "inf", hex or spaces */
        buf[i] = c == 'd' || c == 'D' ? 'E' : c; /* Fortran 1.0D+03 */
    }
    buf[i] = '\0';
    x = strtod(buf, &end);
    if (end == buf || *end != '\0' || !isfinite(x))
        return -1;
    *v = x;
    return 0;
}

double imp_round(double v)
{
    char buf[40];

    if (!isfinite(v) || v == 0.0)
        return v == 0.0 ? 0.0 : v;
    snprintf(buf, sizeof(buf), "%.*g", IMP_DUMP_PRECISION, v);
    return strtod(buf, NULL);
}

int imp_finite(double v)
{
    return isfinite(v) && isfinite(imp_round(v));
}

/* -------------------------------------------------------- diagnostics */

int imp_fail(import_diag *d, const char *file, int line, const char *field, const char *fmt,
             ...)
{
    va_list ap;

    imp_tok f = {file ? file : "", file ? strlen(file) : 0};

    imp_tok_copy(d->file, sizeof(d->file), &f);
    d->line = line;
    snprintf(d->field, sizeof(d->field), "%s", field ? field : "");
    va_start(ap, fmt);
    vsnprintf(d->message, sizeof(d->message), fmt, ap);
    va_end(ap);
    if (line > 0)
        snprintf(d->text, sizeof(d->text), "%s:%d: %s: %s", d->file, line, d->field,
                 d->message);
    else
        snprintf(d->text, sizeof(d->text), "%s: %s: %s", d->file, d->field, d->message);
    return SM_INVALID_INPUT;
}

int imp_check(import_diag *d, const char *file, int line, const char *field, int kind,
              double v)
{
    if (!isfinite(v))
        return imp_fail(d, file, line, field, "not a finite number (%g)", v);
    if (!imp_finite(v))
        return imp_fail(d, file, line, field, "out of range: %.17g is beyond the largest "
                        "number a request carries (%s in magnitude)", v, IMP_MAX_ABS_TEXT);
    if (kind == IMP_POSITIVE && !(v > 0.0))
        return imp_fail(d, file, line, field, "must be > 0 (%.15g)", v);
    if (kind == IMP_NONNEG && v < 0.0)
        return imp_fail(d, file, line, field, "must be >= 0 (%.15g)", v);
    return SM_OK;
}

int imp_value(import_diag *d, const char *file, int line, const char *field, const imp_tok *t,
              int kind, double *v)
{
    char shown[IMP_EXCERPT_SIZE];

    if (t->n == 0)
        return imp_fail(d, file, line, field, "missing value");
    if (imp_number(t, v)) {
        imp_excerpt(shown, sizeof(shown), t);
        return imp_fail(d, file, line, field, "not a number (\"%s\")", shown);
    }
    return imp_check(d, file, line, field, kind, *v);
}

int imp_warn(json_t *warnings, const char *pointer, const char *fmt, ...)
{
    char msg[512];
    va_list ap;

    va_start(ap, fmt);
    vsnprintf(msg, sizeof(msg), fmt, ap);
    va_end(ap);
    return json_array_append_new(warnings, json_pack("{s:s, s:s}", "pointer", pointer,
                                                     "message", msg));
}

int imp_legacy_warnings(json_t *doc)
{
    const json_t *w;
    json_t *strings = json_array();
    size_t i;
    int bad = !strings;

    json_array_foreach(json_object_get(doc, "input_warnings"), i, w)
        bad |= json_array_append_new(strings, json_copy(json_object_get(w, "message")));
    return bad || json_object_set_new(doc, "warnings", strings) ? -1 : 0;
}

/* ------------------------------------------------------ station table */

int imp_key_kind(imp_key k)
{
    switch (k) {
    case IK_MU:
    case IK_EA:
    case IK_EI_FLAP:
    case IK_EI_EDGE:
    case IK_GJ:
        return IMP_POSITIVE;
    case IK_I_FLAP:
    case IK_I_EDGE:
        return IMP_NONNEG;
    default:
        return IMP_ANY;
    }
}

imp_station *imp_table_add(imp_table *t)
{
    imp_station *s;

    if (t->n == t->cap) {
        int ncap = t->cap ? 2 * t->cap : 32;
        imp_station *ns = realloc(t->st, (size_t)ncap * sizeof(*ns));
        if (!ns)
            return NULL;
        t->st = ns;
        t->cap = ncap;
    }
    s = &t->st[t->n++];
    memset(s, 0, sizeof(*s));
    return s;
}

void imp_table_clear(imp_table *t)
{
    free(t->st);
    t->st = NULL;
    t->n = t->cap = 0;
    t->mask = 0;
}

int imp_table_order(import_diag *d, const char *file, const imp_table *t, const char *field)
{
    int i;

    if (t->n < 2)
        return imp_fail(d, file, t->n ? t->st[0].line : 0, field,
                        "at least 2 stations are needed (root and tip), %d given", t->n);
    if (t->st[0].v[IK_S] != 0.0)
        return imp_fail(d, file, t->st[0].line, field,
                        "the first station must be at the root, 0 (got %.15g)", t->st[0].v[IK_S]);
    for (i = 1; i < t->n; i++) {
        double a = imp_round(t->st[i - 1].v[IK_S]), b = imp_round(t->st[i].v[IK_S]);
        if (!(b > a))
            return imp_fail(d, file, t->st[i].line, field,
                            "stations out of order: %.15g after %.15g (must increase)", b, a);
    }
    if (t->st[t->n - 1].v[IK_S] != 1.0)
        return imp_fail(d, file, t->st[t->n - 1].line, field,
                        "the last station must be at the tip, 1 (got %.15g)",
                        t->st[t->n - 1].v[IK_S]);
    return SM_OK;
}

double imp_table_max(const imp_table *t, imp_key k)
{
    double m = 0.0;
    int i;

    for (i = 0; i < t->n; i++)
        if (t->st[i].v[k] > m)
            m = t->st[i].v[k];
    return m;
}

/* ------------------------------------------------------- the document */

void imp_blade_init(imp_blade *b)
{
    memset(b, 0, sizeof(*b));
    b->modes = IMPORT_DEFAULT_MODES;
}

static json_t *imp_real(double v)
{
    return json_real(imp_round(v));
}

static json_t *imp_vec(const double *v, int n)
{
    json_t *a = json_array();
    int i;

    for (i = 0; a && i < n; i++)
        if (json_array_append_new(a, imp_real(v[i]))) {
            json_decref(a);
            return NULL;
        }
    return a;
}

/*
 * Ratios of the assumed stiffnesses to the largest bending stiffness EI of
 * the table: EA = IMP_EA_RATIO EI / length^2 and GJ = IMP_GJ_RATIO EI.  Far
 * above the bending stiffness along the whole blade, so extension and
 * torsion stay out of the low modes, as in ElastoDyn (rigid in both).
 */
#define IMP_EA_RATIO 1e4
#define IMP_GJ_RATIO 10.0

/* The station whose EI_flap or EI_edge is the largest, and that key (for the line of a message). */
static const imp_station *imp_largest_ei(const imp_table *t, imp_key *k)
{
    const imp_station *best = NULL;
    double m = -1.0;
    int i;

    *k = IK_EI_FLAP;
    for (i = 0; i < t->n; i++) {
        if (t->st[i].v[IK_EI_FLAP] > m)
            best = &t->st[i], m = t->st[i].v[IK_EI_FLAP], *k = IK_EI_FLAP;
        if (t->st[i].v[IK_EI_EDGE] > m)
            best = &t->st[i], m = t->st[i].v[IK_EI_EDGE], *k = IK_EI_EDGE;
    }
    return best;
}

/*
 * An assumed stiffness (EA or GJ) must be a number the request carries: finite when printed and
 * a normal positive double.  Overflow is the EI's fault (the line of the largest); underflow
 * too, unless a length over 1 m divides it (EA): then the line that gives the length.
 */
static int imp_assumed_check(import_diag *d, const char *file, const imp_table *t,
                             const imp_blade *b, const char *key, const char *formula,
                             double v, const char *const *ei_names)
{
    imp_key k;
    const imp_station *s = imp_largest_ei(t, &k);
    const char *ei = ei_names[k == IK_EI_EDGE];

    if (!imp_finite(v))
        return imp_fail(d, file, s ? s->line : 0, ei, "%.15g N m^2 makes the "
                        "assumed %s = %s overflow (length %.15g m): give %s", s ? s->v[k] : 0.0,
                        key, formula, b->length, key);
    if (!(imp_round(v) >= DBL_MIN) && (strcmp(key, "EA") || !(b->length > 1.0)))
        return imp_fail(d, file, s ? s->line : 0, ei, "%.15g N m^2 makes the assumed %s = %s "
                        "underflow to %g (length %.15g m): give %s", s ? s->v[k] : 0.0, key,
                        formula, v, b->length, key);
    if (!(imp_round(v) >= DBL_MIN))
        return imp_fail(d, file, b->length_line, b->length_field ? b->length_field : "length",
                        "the blade length %.15g m makes the assumed %s = %s underflow to %g "
                        "(largest EI %.15g N m^2): give %s", b->length, key, formula, v,
                        s ? s->v[k] : 0.0, key);
    return SM_OK;
}

int imp_assumed_section(json_t **out, import_diag *d, const char *file, const imp_table *t,
                        const imp_blade *b, json_t *warnings, const char *format,
                        const char *const *ei_names)
{
    double ei = imp_table_max(t, IK_EI_FLAP), ee = imp_table_max(t, IK_EI_EDGE);
    double length = b->length;
    json_t *sec;
    int bad = 0, st;

    *out = NULL;
    if (ee > ei)
        ei = ee;
    if (!(t->mask & (1u << IK_EA)) &&
        (st = imp_assumed_check(d, file, t, b, "EA", "1e4 x EI / length^2",
                                IMP_EA_RATIO * ei / (length * length), ei_names)))
        return st;
    if (!(t->mask & (1u << IK_GJ)) &&
        (st = imp_assumed_check(d, file, t, b, "GJ", "10 x EI", IMP_GJ_RATIO * ei, ei_names)))
        return st;
    if (!(sec = json_object()))
        return SM_NOMEM;
    if (!(t->mask & (1u << IK_EA))) {
        double ea = imp_round(IMP_EA_RATIO * ei / (length * length));
        bad |= json_object_set_new(sec, "EA", json_real(ea));
        bad |= imp_warn(warnings, "/blade/section/EA", "EA is not in the %s file: blade.section.EA = %.6g N assumed "
                        "(1e4 x the largest EI / length^2: nearly rigid in extension); the "
                        "default rotary inertias mass_per_length x EI / EA depend on it: "
                        "review", format, ea);
    }
    if (!(t->mask & (1u << IK_GJ))) {
        double gj = imp_round(IMP_GJ_RATIO * ei);
        bad |= json_object_set_new(sec, "GJ", json_real(gj));
        bad |= imp_warn(warnings, "/blade/section/GJ", "GJ is not in the %s file: blade.section.GJ = %.6g N m^2 "
                        "assumed (10 x the largest EI: nearly rigid in torsion): review",
                        format, gj);
    }
    if (bad) {
        json_decref(sec);
        return SM_NOMEM;
    }
    *out = sec;
    return SM_OK;
}

int imp_length(import_diag *d, const char *file, int line, const char *field, double hub,
               double length)
{
    double tip = hub + length;

    if (!imp_finite(length) || !imp_finite(tip))
        return imp_fail(d, file, line, field, "the blade length %.17g m is beyond the largest "
                        "number a request carries (%s in magnitude)", length, IMP_MAX_ABS_TEXT);
    if (!(length >= IMPORT_MIN_LENGTH) || !(length >= IMPORT_MIN_LENGTH_RATIO * tip))
        return imp_fail(d, file, line, field,
                        "the blade length %.15g m (tip radius %.17g m less hub radius %.17g m) "
                        "is below the shortest the numerics carry: at least %g m and %g x the "
                        "tip radius", length, tip, hub, IMPORT_MIN_LENGTH,
                        IMPORT_MIN_LENGTH_RATIO);
    return SM_OK;
}

int imp_option(import_diag *d, const char *file, const char *field, double v)
{
    if (isnan(v))
        return SM_OK;
    if (!(v >= 0.0 && isfinite(v)))
        return imp_fail(d, file, 0, field, "must be >= 0 (%g)", v);
    if (!imp_finite(v))
        return imp_fail(d, file, 0, field, "out of range: %.17g is beyond the largest number a "
                        "request carries (%s in magnitude)", v, IMP_MAX_ABS_TEXT);
    return SM_OK;
}

int imp_options_apply(import_diag *d, const char *file, const import_options *o,
                      int length_known, imp_blade *b, json_t *warnings)
{
    int bad = 0, st;

    if ((st = imp_option(d, file, "hub_radius", o->hub_radius)) ||
        (st = imp_option(d, file, "rpm", o->rpm)))
        return st;
    if (!isnan(o->rpm)) {
        b->rpm = o->rpm;
        b->rpm_speeds = o->rpm_speeds;
    } else {
        bad |= imp_warn(warnings, "/analysis/rpm", "no rotor speed in the file: analysis.rpm = "
                        "[0] (not spinning); give one with --rpm (HTTP: ?rpm=)");
    }
    if (length_known) {
        if (!isnan(o->tip_radius) || !isnan(o->hub_radius))
            bad |= imp_warn(warnings, "/blade/length", "the file gives the blade's radii: the tip and hub "
                            "radius options are ignored");
        return bad ? SM_NOMEM : SM_OK;
    }
    if (isnan(o->tip_radius))
        return imp_fail(d, file, 0, "tip_radius",
                        "the file does not give the blade length: give the tip radius "
                        "(CLI --tip-radius, HTTP ?tip_radius=; TipRad in an ElastoDyn main "
                        "file) and the hub radius (--hub-radius, ?hub_radius=; HubRad)");
    if (isnan(o->hub_radius)) {
        b->hub_radius = 0.0;
        bad |= imp_warn(warnings, "/blade/hub_radius", "no hub radius given: blade.hub_radius = 0 assumed (give "
                        "--hub-radius, HTTP ?hub_radius=)");
    } else {
        b->hub_radius = o->hub_radius;
    }
    if (!(isfinite(o->tip_radius) && o->tip_radius > b->hub_radius))
        return imp_fail(d, file, 0, "tip_radius", "must be greater than the hub radius %g (%g)",
                        b->hub_radius, o->tip_radius);
    if ((st = imp_option(d, file, "tip_radius", o->tip_radius)))
        return st;
    b->length = o->tip_radius - b->hub_radius;
    b->length_line = 0;
    b->length_field = "tip_radius";
    if ((st = imp_length(d, file, 0, "tip_radius", b->hub_radius, b->length)))
        return st;
    return bad ? SM_NOMEM : SM_OK;
}

/* Station keys in JSON order; offsets are pairs [edge, flap] starting at their _E key. */
static const struct {
    imp_key k;
    const char *name;
    int pair; /* 1: this key and the next form [edge, flap] */
} imp_json_keys[] = {
    {IK_MU, "mass_per_length", 0},   {IK_EA, "EA", 0},
    {IK_EI_FLAP, "EI_flap", 0},      {IK_EI_EDGE, "EI_edge", 0},
    {IK_GJ, "GJ", 0},                {IK_I_FLAP, "flap_inertia", 0},
    {IK_I_EDGE, "edge_inertia", 0},  {IK_TWIST, "twist_deg", 0},
    {IK_ITWIST, "inertia_twist_deg", 0},
    {IK_CG_E, "cg_offset", 1},       {IK_SC_E, "shear_center_offset", 1},
    {IK_TC_E, "tension_center_offset", 1},
};

static json_t *imp_station_json(const imp_station *s, unsigned mask)
{
    json_t *o = json_object();
    size_t i;
    int bad = 0;

    if (!o)
        return NULL;
    bad |= json_object_set_new(o, "s", imp_real(s->v[IK_S]));
    for (i = 0; i < sizeof(imp_json_keys) / sizeof(imp_json_keys[0]); i++) {
        imp_key k = imp_json_keys[i].k;
        if (imp_json_keys[i].pair) {
            if (mask & (3u << k))
                bad |= json_object_set_new(o, imp_json_keys[i].name, imp_vec(&s->v[k], 2));
        } else if (mask & (1u << k)) {
            bad |= json_object_set_new(o, imp_json_keys[i].name, imp_real(s->v[k]));
        }
    }
    if (bad) {
        json_decref(o);
        return NULL;
    }
    return o;
}

static json_t *imp_tip_json(const imp_blade *b)
{
    json_t *o = json_object();
    int bad = 0;

    if (!o)
        return NULL;
    bad |= json_object_set_new(o, "mass", imp_real(b->tip_mass));
    bad |= json_object_set_new(o, "offset", imp_vec(b->tip_offset, 3));
    bad |= json_object_set_new(o, "inertia", imp_vec(b->tip_inertia, 3));
    bad |= json_object_set_new(o, "products", imp_vec(b->tip_products, 3));
    if (bad) {
        json_decref(o);
        return NULL;
    }
    return o;
}

/* The "blade" object; takes section (may be NULL). */
static json_t *imp_blade_json(const imp_blade *b, const imp_table *t, json_t *section)
{
    json_t *o = json_object(), *st = json_array();
    int i, bad = !o || !st;

    for (i = 0; !bad && i < t->n; i++)
        bad |= json_array_append_new(st, imp_station_json(&t->st[i], t->mask));
    if (!bad) {
        bad |= json_object_set_new(o, "length", imp_real(b->length));
        bad |= json_object_set_new(o, "hub_radius", imp_real(b->hub_radius));
        bad |= json_object_set_new(o, "precone_deg", imp_real(b->precone_deg));
        bad |= json_object_set_new(o, "pitch_deg", imp_real(b->pitch_deg));
        bad |= json_object_set_new(o, "elements", json_integer(IMPORT_ELEMENTS));
        if (section && json_object_size(section) > 0)
            bad |= json_object_set(o, "section", section);
        bad |= json_object_set(o, "stations", st);
        if (b->has_tip)
            bad |= json_object_set_new(o, "tip_mass", imp_tip_json(b));
    }
    json_decref(section);
    json_decref(st);
    if (bad) {
        json_decref(o);
        return NULL;
    }
    return o;
}

json_t *imp_document(const imp_blade *b, const imp_table *t, json_t *section,
                     json_t *warnings, json_t *source)
{
    json_t *doc = json_object(), *req = json_object(), *an = json_object();
    json_t *rpm = b->rpm_speeds ? json_deep_copy(b->rpm_speeds) : json_array();
    int bad = !doc || !req || !an || !rpm || !warnings || !source;

    if (!bad) {
        if (!b->rpm_speeds)
            bad |= json_array_append_new(rpm, imp_real(b->rpm));
        bad |= json_object_set(an, "rpm", rpm);
        bad |= json_object_set_new(an, "modes", json_integer(b->modes));
        bad |= json_object_set_new(an, "coriolis", json_false());
        bad |= json_object_set_new(an, "mass", json_string("lumped"));
        bad |= json_object_set_new(an, "mode_shapes", json_true());
        bad |= json_object_set_new(req, "blade", imp_blade_json(b, t, section));
        section = NULL;
        bad |= json_object_set_new(req, "frames", json_string("per_element"));
        bad |= json_object_set(req, "analysis", an);
        bad |= json_object_set(doc, "request", req);
        bad |= json_object_set(doc, "warnings", warnings); /* replaced below, keeps its place */
        bad |= json_object_set(doc, "input_warnings", warnings);
        bad |= json_object_set(doc, "source", source);
        bad |= imp_legacy_warnings(doc);
    }
    json_decref(section);
    json_decref(rpm);
    json_decref(an);
    json_decref(req);
    json_decref(warnings);
    json_decref(source);
    if (bad) {
        json_decref(doc);
        return NULL;
    }
    return doc;
}

char *import_dumps(const json_t *doc, int pretty)
{
    return json_dumps(doc, JSON_REAL_PRECISION(IMP_DUMP_PRECISION) |
                               (pretty ? JSON_INDENT(2) : JSON_COMPACT));
}

int imp_document_assumed(json_t **out, import_diag *d, const char *file, const imp_blade *b,
                         const imp_table *t, const char *format, const char *const *ei_names,
                         json_t *warnings, json_t *source)
{
    json_t *sec = NULL;
    int st = warnings ? imp_assumed_section(&sec, d, file, t, b, warnings, format, ei_names)
                      : SM_NOMEM;

    *out = NULL;
    if (st) {
        json_decref(warnings);
        json_decref(source);
        return st;
    }
    *out = imp_document(b, t, sec, warnings, source);
    return *out ? SM_OK : SM_NOMEM;
}
