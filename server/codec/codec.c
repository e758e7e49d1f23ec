/*
 * codec.c — JSON request validation, canonical form, result encoding.
 *
 * How it fits: the CLI (cli.c) and the daemon read a request with
 * codec_request_parse, build the core model with codec_model_new, call
 * sm_solve and write codec_result_encode (or codec_result_csv).  Every
 * failure on the way becomes a codec_errors list that codec_problem_* turns
 * into an RFC 9457 document.
 *
 * Validation walks the request once, in document order, and never stops at
 * the first error: each field is checked (type, range, references, unknown
 * keys), errors are appended with the JSON pointer of the field, and a
 * canonical copy of the request is built along the way with every default
 * written out.  Only when no error was found is the canonical copy turned
 * into the core's arrays.  Joints and sections are indexed in sorted name
 * order, so the canonical text (keys sorted) fully determines the model and
 * two requests with the same SHA-256 give the same result.
 *
 * Topology (cycles, disconnected members) is the core's job: sm_model_new
 * reports it in an sm_diag, which codec_diag_error maps back to a pointer.
 * The codec pre-checks only the cheap local cases (zero-length member, a
 * clamp that is no member's end) so those appear with the other errors.
 */
#include "codec_internal.h"

#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <openssl/evp.h>

/* Flags for dumping canonical text and results. */
#define CODEC_DUMP_CANON (JSON_SORT_KEYS | JSON_COMPACT | JSON_REAL_PRECISION(17))

/* =============================================================== request */

struct codec_request {
    json_t *canon;              /* canonical request, defaults applied */
    char *canon_text;           /* its sorted compact dump */
    char sha[65];               /* SHA-256 of canon_text, hex */
    const char **joint_names;   /* n_joints, sorted, borrowed from canon */
    const char **section_names; /* n_sections, sorted, borrowed from canon */
    double *joint_xy;           /* 2*n_joints */
    sm_section *sections;       /* n_sections */
    sm_member *members;         /* n_members */
    sm_point_mass *point_masses;/* n_point_masses (NULL if 0) */
    double *speeds;             /* n_speeds, request order */
    int n_speeds;
    sm_structure st;            /* points into the arrays above */
    sm_options opt;             /* from the analysis and frames fields */
};

static int req_cmp_str(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* Sorted key list of obj (borrowed keys); NULL = NOMEM. */
static const char **req_sorted_keys(const json_t *obj, int *n)
{
    size_t k = 0, cnt = json_object_size(obj);
    const char **names = calloc(cnt ? cnt : 1, sizeof(*names));
    const char *key;
    json_t *val;

    if (!names)
        return NULL;
    json_object_foreach((json_t *)obj, key, val) {
        (void)val;
        names[k++] = key;
    }
    qsort(names, cnt, sizeof(*names), req_cmp_str);
    *n = (int)cnt;
    return names;
}

static int req_name_index(const char **names, int n, const char *name)
{
    const char **hit = bsearch(&name, names, (size_t)n, sizeof(*names), req_cmp_str);
    return hit ? (int)(hit - names) : -1;
}

static double req_number(const json_t *x)
{
    double d = 0;
    field_number(x, &d);
    return d;
}

/* Joints and sections arrays, sorted by name. */
static int req_build_tables(codec_request *r)
{
    const json_t *st = json_object_get(r->canon, "structure");
    const json_t *joints = json_object_get(st, "joints");
    const json_t *secs = json_object_get(st, "sections");
    int i, nj = 0, ns = 0;

    r->joint_names = req_sorted_keys(joints, &nj);
    r->section_names = req_sorted_keys(secs, &ns);
    if (!r->joint_names || !r->section_names)
        return SM_NOMEM;
    r->joint_xy = malloc(2 * (size_t)nj * sizeof(double));
    r->sections = malloc((size_t)(ns ? ns : 1) * sizeof(sm_section));
    if (!r->joint_xy || !r->sections)
        return SM_NOMEM;
    for (i = 0; i < nj; i++) {
        const json_t *xy = json_object_get(joints, r->joint_names[i]);
        r->joint_xy[2 * i] = req_number(json_array_get(xy, 0));
        r->joint_xy[2 * i + 1] = req_number(json_array_get(xy, 1));
    }
    for (i = 0; i < ns; i++) {
        const json_t *s = json_object_get(secs, r->section_names[i]);
        r->sections[i].E = req_number(json_object_get(s, "E"));
        r->sections[i].A = req_number(json_object_get(s, "A"));
        r->sections[i].I = req_number(json_object_get(s, "I"));
        r->sections[i].mu = req_number(json_object_get(s, "mass_per_length"));
    }
    r->st.n_joints = nj;
    r->st.joint_xy = r->joint_xy;
    r->st.n_sections = ns;
    r->st.sections = r->sections;
    return SM_OK;
}

/* Members, point masses and clamp as indices. */
static int req_build_structure(codec_request *r)
{
    const json_t *st = json_object_get(r->canon, "structure");
    const json_t *mems = json_object_get(st, "members");
    const json_t *pms = json_object_get(st, "point_masses");
    const json_t *x;
    size_t i, nm = json_array_size(mems), np = json_array_size(pms);
    int nj = r->st.n_joints, ns = r->st.n_sections;

    r->members = malloc((nm ? nm : 1) * sizeof(sm_member));
    r->point_masses = np ? malloc(np * sizeof(sm_point_mass)) : NULL;
    if (!r->members || (np && !r->point_masses))
        return SM_NOMEM;
    json_array_foreach(mems, i, x) {
        r->members[i].from = req_name_index(r->joint_names, nj,
                                            json_string_value(json_object_get(x, "from")));
        r->members[i].to = req_name_index(r->joint_names, nj,
                                          json_string_value(json_object_get(x, "to")));
        r->members[i].section = req_name_index(r->section_names, ns,
                                               json_string_value(json_object_get(x, "section")));
        r->members[i].elements = (int)json_integer_value(json_object_get(x, "elements"));
    }
    json_array_foreach(pms, i, x) {
        r->point_masses[i].joint = req_name_index(r->joint_names, nj,
                                                  json_string_value(json_object_get(x, "joint")));
        r->point_masses[i].mass = req_number(json_object_get(x, "mass"));
    }
    r->st.n_members = (int)nm;
    r->st.members = r->members;
    r->st.n_point_masses = (int)np;
    r->st.point_masses = r->point_masses;
    r->st.clamp = req_name_index(r->joint_names, nj,
                                 json_string_value(json_object_get(st, "clamp")));
    return SM_OK;
}

/* sm_options and speeds from frames and analysis. */
static int req_build_options(codec_request *r)
{
    const json_t *an = json_object_get(r->canon, "analysis");
    const json_t *fr = json_object_get(r->canon, "frames");
    const json_t *om = json_object_get(an, "omega");
    const json_t *mpf = json_object_get(an, "modes_per_frame");
    size_t i, n = json_is_array(om) ? json_array_size(om) : 1;

    sm_default_options(&r->opt);
    if (json_is_string(fr)) {
        r->opt.frames = !strcmp(json_string_value(fr), "single") ? SM_FRAMES_SINGLE
                                                                 : SM_FRAMES_PER_ELEMENT;
        r->opt.frames_param = 0;
    } else if (json_object_get(fr, "per_member")) {
        r->opt.frames = SM_FRAMES_PER_MEMBER;
        r->opt.frames_param = (int)json_integer_value(json_object_get(fr, "per_member"));
    } else {
        r->opt.frames = SM_FRAMES_ELEMENTS_PER_FRAME;
        r->opt.frames_param = (int)json_integer_value(json_object_get(fr, "elements_per_frame"));
    }
    r->opt.mass = !strcmp(json_string_value(json_object_get(an, "mass")), "consistent")
                      ? SM_MASS_CONSISTENT : SM_MASS_LUMPED;
    r->opt.basis = !strcmp(json_string_value(json_object_get(an, "substructure_modes")),
                           "paper") ? SM_BASIS_PAPER : SM_BASIS_AUGMENTED;
    r->opt.modes_per_frame = json_is_integer(mpf) ? (int)json_integer_value(mpf) : 0;
    r->opt.modes = (int)json_integer_value(json_object_get(an, "modes"));
    r->opt.geometric_stiffening = json_is_true(json_object_get(an, "geometric_stiffening"));
    r->opt.coriolis = json_is_true(json_object_get(an, "coriolis"));
    r->opt.mode_shapes = json_is_true(json_object_get(an, "mode_shapes"));

    r->speeds = malloc(n * sizeof(double));
    if (!r->speeds)
        return SM_NOMEM;
    for (i = 0; i < n; i++)
        r->speeds[i] = req_number(json_is_array(om) ? json_array_get(om, i) : om);
    r->n_speeds = (int)n;
    return SM_OK;
}

int codec_sha256_hex(const void *data, size_t len, char hex[65])
{
    static const char digits[] = "0123456789abcdef";
    unsigned char md[EVP_MAX_MD_SIZE];
    unsigned int n = 0, i;

    hex[0] = '\0';
    if (!EVP_Digest(data, len, md, &n, EVP_sha256(), NULL) || n != 32)
        return SM_NOMEM;
    for (i = 0; i < n; i++) {
        hex[2 * i] = digits[md[i] >> 4];
        hex[2 * i + 1] = digits[md[i] & 15];
    }
    hex[64] = '\0';
    return SM_OK;
}

int codec_request_from_json(codec_request **out, const json_t *root,
                            const codec_limits *lim, codec_errors *errs)
{
    codec_limits deflim;
    codec_request *r = NULL;
    json_t *canon;
    int rc = SM_NOMEM, before = codec_errors_count(errs), nomem;

    *out = NULL;
    if (!lim) {
        codec_default_limits(&deflim);
        lim = &deflim;
    }
    canon = val_request(root, lim, errs, &nomem);
    if (nomem)
        goto fail;
    if (codec_errors_count(errs) > before || !canon) {
        rc = SM_INVALID_INPUT;
        goto fail;
    }
    r = calloc(1, sizeof(*r));
    if (!r)
        goto fail;
    r->canon = canon;
    canon = NULL;
    r->canon_text = json_dumps(r->canon, CODEC_DUMP_CANON);
    if (!r->canon_text)
        goto fail;
    if ((rc = codec_sha256_hex(r->canon_text, strlen(r->canon_text), r->sha)) ||
        (rc = req_build_tables(r)) || (rc = req_build_structure(r)) ||
        (rc = req_build_options(r)))
        goto fail;
    *out = r;
    return SM_OK;
fail:
    json_decref(canon);
    codec_request_free(r);
    return rc;
}

int codec_request_parse(codec_request **out, const char *text, size_t len,
                        const codec_limits *lim, codec_errors *errs)
{
    codec_limits deflim;
    json_error_t jerr;
    json_t *root;
    int rc;

    *out = NULL;
    if (!lim) {
        codec_default_limits(&deflim);
        lim = &deflim;
    }
    if (len > lim->max_request_bytes) {
        err_mark_too_large(errs);
        if (codec_errors_add(errs, "", "the request is %zu bytes: the limit is %zu bytes",
                             len, lim->max_request_bytes))
            return SM_NOMEM;
        return SM_INVALID_INPUT;
    }
    root = json_loadb(text, len, JSON_REJECT_DUPLICATES, &jerr);
    if (!root) {
        err_mark_malformed(errs);
        for (size_t k = 0; jerr.text[k]; k++) /* jansson's "near '...'" may cut a UTF-8 char */
            if ((unsigned char)jerr.text[k] >= 0x80)
                jerr.text[k] = '?';
        if (json_error_code(&jerr) == json_error_out_of_memory)
            return SM_NOMEM;
        if (codec_errors_add(errs, "", "not valid JSON: %s (line %d, column %d)", jerr.text,
                             jerr.line, jerr.column))
            return SM_NOMEM;
        return SM_INVALID_INPUT;
    }
    rc = codec_request_from_json(out, root, lim, errs);
    json_decref(root);
    return rc;
}

void codec_request_free(codec_request *r)
{
    if (!r)
        return;
    free(r->speeds);
    free(r->point_masses);
    free(r->members);
    free(r->sections);
    free(r->joint_xy);
    free(r->section_names);
    free(r->joint_names);
    free(r->canon_text);
    json_decref(r->canon);
    free(r);
}

const sm_structure *codec_request_structure(const codec_request *r)
{
    return &r->st;
}

const sm_options *codec_request_options(const codec_request *r)
{
    return &r->opt;
}

const double *codec_request_speeds(const codec_request *r, int *n)
{
    *n = r->n_speeds;
    return r->speeds;
}

const char *codec_request_joint_name(const codec_request *r, int j)
{
    if (j < 0 || j >= r->st.n_joints)
        return NULL;
    return r->joint_names[j];
}

const char *req_section_name(const codec_request *r, int s)
{
    if (s < 0 || s >= r->st.n_sections)
        return NULL;
    return r->section_names[s];
}

const json_t *codec_request_canonical(const codec_request *r)
{
    return r->canon;
}

const char *codec_request_canonical_text(const codec_request *r)
{
    return r->canon_text;
}

const char *codec_request_sha256(const codec_request *r)
{
    return r->sha;
}

/* ================================================================== diag */

/* Request field name of a core field name (mu -> mass_per_length ...). */
static const char *diag_field_name(const char *f)
{
    if (!strcmp(f, "mu"))
        return "mass_per_length";
    if (!strcmp(f, "basis"))
        return "substructure_modes";
    if (!strcmp(f, "omegas"))
        return "omega";
    return f;
}

/* 1 when f is one of the NULL-terminated names. */
static int diag_among(const char *f, const char *const *names)
{
    int i;

    for (i = 0; names[i]; i++)
        if (!strcmp(f, names[i]))
            return 1;
    return 0;
}

static int diag_is_section_field(const char *f)
{
    return !strcmp(f, "E") || !strcmp(f, "A") || !strcmp(f, "I") || !strcmp(f, "mu") ||
           !strcmp(f, "mass_per_length");
}

/* Pointer of an option field reported by the core. */
static char *diag_options_pointer(const codec_request *r, const char *f, int index)
{
    const json_t *canon = codec_request_canonical(r);
    const json_t *fr = json_object_get(canon, "frames");
    const json_t *om = json_object_get(json_object_get(canon, "analysis"), "omega");

    if ((!strcmp(f, "omega") || !strcmp(f, "omegas")) && json_is_array(om) && index >= 0 &&
        (size_t)index < json_array_size(om))
        return err_fmt("/analysis/omega/%d", index);

    if (!strcmp(f, "frames") || !strcmp(f, "frames_param") || !strcmp(f, "per_member") ||
        !strcmp(f, "elements_per_frame")) {
        if (json_is_object(fr) && strcmp(f, "frames")) {
            const char *key = json_object_get(fr, "per_member") ? "per_member"
                                                                : "elements_per_frame";
            return err_fmt("/frames/%s", key);
        }
        return strdup("/frames");
    }
    if (f[0] == '\0')
        return strdup("/analysis");
    return err_ptr_key("/analysis", diag_field_name(f));
}

/* Pointer of the item a diagnostic names; malloc'd, NULL = NOMEM. */
static char *diag_pointer(const codec_request *r, const sm_diag *d)
{
    const sm_structure *st = codec_request_structure(r);
    const char *f = d->field;
    int i = d->item_index;
    char *base, *p;

    static const char *const member_fields[] = {"id", "from", "to", "section", "elements",
                                                NULL};
    static const char *const pm_fields[] = {"joint", "mass", NULL};
    static const char *const no_fields[] = {NULL};
    const char *const *known = no_fields;

    switch (d->item) {
    case SM_ITEM_MEMBER:
        if (i < 0 || i >= st->n_members)
            return strdup("/structure/members");
        if (diag_is_section_field(f) && st->members[i].section >= 0 &&
            st->members[i].section < st->n_sections) {
            base = err_ptr_key("/structure/sections",
                               req_section_name(r, st->members[i].section));
            known = NULL;
            break;
        }
        base = err_ptr_idx("/structure/members", (size_t)i);
        known = member_fields;
        break;
    case SM_ITEM_JOINT:
        if (i < 0 || i >= st->n_joints)
            return strdup("/structure/joints");
        base = err_ptr_key("/structure/joints", codec_request_joint_name(r, i));
        if (base && (!strcmp(f, "x") || !strcmp(f, "y"))) {
            p = err_fmt("%s/%d", base, f[0] == 'y');
            free(base);
            return p;
        }
        return base;
    case SM_ITEM_SECTION:
        if (i < 0 || i >= st->n_sections)
            return strdup("/structure/sections");
        base = err_ptr_key("/structure/sections", req_section_name(r, i));
        known = NULL;
        break;
    case SM_ITEM_POINT_MASS:
        if (i < 0 || i >= st->n_point_masses)
            return strdup("/structure/point_masses");
        base = err_ptr_idx("/structure/point_masses", (size_t)i);
        known = pm_fields;
        break;
    case SM_ITEM_CLAMP:
        return strdup("/structure/clamp");
    case SM_ITEM_OPTIONS:
        return diag_options_pointer(r, f, i);
    case SM_ITEM_NONE:
    default:
        return strdup("/structure");
    }
    /* a field the request does not have: point at the item itself */
    if (!base || f[0] == '\0' || (known ? !diag_among(f, known) : !diag_is_section_field(f)))
        return base;
    p = err_ptr_key(base, diag_field_name(f));
    free(base);
    return p;
}

int codec_diag_error(const codec_request *r, const sm_diag *d, codec_errors *errs)
{
    char *p = diag_pointer(r, d);
    int rc;

    if (!p) {
        err_mark_nomem(errs);
        return SM_NOMEM;
    }
    rc = codec_errors_add(errs, p, "%s", d->message[0] ? d->message : sm_strerror(d->status));
    free(p);
    return rc;
}

int codec_model_new(sm_model **out, const codec_request *r, codec_errors *errs,
                    sm_diag *diag)
{
    sm_diag local;
    sm_diag *d = diag ? diag : &local;
    int rc;

    memset(d, 0, sizeof(*d));
    d->item_index = -1;
    *out = NULL;
    rc = sm_model_new(out, codec_request_structure(r), codec_request_options(r), d);
    if (rc == SM_OK)
        return SM_OK;
    *out = NULL;
    if (d->status == SM_OK)
        d->status = rc;
    if (rc != SM_NOMEM && codec_diag_error(r, d, errs))
        return SM_NOMEM;
    return rc;
}

/* ================================================================ result */

const char *codec_case_status_name(sm_case_status s)
{
    switch (s) {
    case SM_CASE_SOLVED: return "solved";
    case SM_CASE_UNSTABLE: return "unstable";
    case SM_CASE_NO_EQUILIBRIUM: return "no_equilibrium";
    }
    return "unknown";
}

/* A real, or null when not finite (JSON has no NaN or infinity). */
static json_t *res_real(double x)
{
    return isfinite(x) ? json_real(x) : json_null();
}

/* [a, b, c] from three reals. */
static json_t *res_triple(const double *v)
{
    json_t *a = json_array();

    if (!a)
        return NULL;
    if (json_array_append_new(a, res_real(v[0])) || json_array_append_new(a, res_real(v[1])) ||
        json_array_append_new(a, res_real(v[2]))) {
        json_decref(a);
        return NULL;
    }
    return a;
}

/* [[x, y, z], ...] from n triples. */
static json_t *res_triples(const double *v, int n)
{
    json_t *a = json_array();
    int k;

    if (!a)
        return NULL;
    for (k = 0; k < n; k++)
        if (json_array_append_new(a, res_triple(v + 3 * (size_t)k)))
            goto fail;
    return a;
fail:
    json_decref(a);
    return NULL;
}

static json_t *res_reals(const double *v, int n)
{
    json_t *a = json_array();
    int k;

    if (!a)
        return NULL;
    for (k = 0; k < n; k++)
        if (json_array_append_new(a, res_real(v[k])))
            goto fail;
    return a;
fail:
    json_decref(a);
    return NULL;
}

/* case.equilibrium */
static json_t *res_equilibrium(const codec_request *r, const sm_model *m, const sm_case *c)
{
    json_t *e = json_object(), *joints = NULL;
    int j, nj = codec_request_structure(r)->n_joints;

    if (!e)
        return NULL;
    if (json_object_set_new(e, "converged", json_boolean(c->converged)) ||
        json_object_set_new(e, "iterations", json_integer(c->iterations)) ||
        json_object_set_new(e, "residual", res_real(c->residual)))
        goto fail;
    if (c->nodes && c->n_nodes > 0) {
        joints = json_object();
        if (!joints)
            goto fail;
        for (j = 0; j < nj; j++) {
            int node = sm_model_joint_node(m, j);
            if (node < 0 || node >= c->n_nodes)
                continue;
            if (json_object_set_new(joints, codec_request_joint_name(r, j),
                                    res_triple(c->nodes + 3 * (size_t)node)))
                goto fail;
        }
        if (json_object_set_new(e, "joints", joints))
            goto fail_set;
        joints = NULL;
        if (json_object_set_new(e, "nodes", res_triples(c->nodes, c->n_nodes)))
            goto fail;
    }
    if (c->axial_force && c->n_elements > 0 &&
        json_object_set_new(e, "axial_force", res_reals(c->axial_force, c->n_elements)))
        goto fail;
    if (c->nodes && c->n_nodes > 0 &&
        json_object_set_new(e, "max_frame_rotation", res_real(c->max_frame_rotation)))
        goto fail;
    return e;
fail:
    json_decref(joints);
fail_set:
    json_decref(e);
    return NULL;
}

/* One mode of a case. */
static json_t *res_mode(const sm_case *c, int k, int shapes)
{
    size_t stride = 3 * (size_t)c->n_nodes;
    json_t *md = json_object(), *shape;
    double mac = c->mac_to_previous ? c->mac_to_previous[k] : -1;
    int prev = c->previous_index ? c->previous_index[k] : -1;

    if (!md)
        return NULL;
    if (json_object_set_new(md, "frequency_rad_s", res_real(c->frequency[k])) ||
        json_object_set_new(md, "frequency_hz", res_real(c->frequency[k] / CODEC_TWO_PI)) ||
        json_object_set_new(md, "eigenvalue", json_pack("[o, o]", res_real(c->eig_re[k]),
                                                        res_real(c->eig_im[k]))) ||
        json_object_set_new(md, "mac_to_previous", mac < 0 ? json_null() : res_real(mac)) ||
        json_object_set_new(md, "previous_index", prev < 0 ? json_null() : json_integer(prev)))
        goto fail;
    if (shapes && c->shape_re) {
        shape = json_object();
        if (json_object_set_new(md, "shape", shape))
            goto fail;
        if (json_object_set_new(shape, "re", res_triples(c->shape_re + k * stride, c->n_nodes)))
            goto fail;
        if (c->shape_im &&
            json_object_set_new(shape, "im", res_triples(c->shape_im + k * stride, c->n_nodes)))
            goto fail;
    }
    return md;
fail:
    json_decref(md);
    return NULL;
}

/* One case (speed). */
static json_t *res_case(const codec_request *r, const sm_model *m, const sm_case *c)
{
    json_t *o = json_object(), *modes;
    int k, shapes = codec_request_options(r)->mode_shapes;

    if (!o)
        return NULL;
    if (json_object_set_new(o, "omega", res_real(c->omega)) ||
        json_object_set_new(o, "status", json_string(codec_case_status_name(c->status))) ||
        json_object_set_new(o, "equilibrium", res_equilibrium(r, m, c)))
        goto fail;
    if (c->status != SM_CASE_NO_EQUILIBRIUM &&
        json_object_set_new(o, "stability",
                            json_pack("{s:b, s:i}", "stable", c->stable,
                                      "negative_eigenvalues", c->negative_eigenvalues)))
        goto fail;
    modes = json_array();
    if (json_object_set_new(o, "modes", modes))
        goto fail;
    for (k = 0; k < c->n_modes; k++)
        if (json_array_append_new(modes, res_mode(c, k, shapes)))
            goto fail;
    if (c->warning[0] &&
        json_object_set_new(o, "warnings", json_pack("[s]", c->warning)))
        goto fail;
    if (c->status != SM_CASE_SOLVED &&
        json_object_set_new(o, "diagnostics",
                            json_pack("{s:i, s:o, s:o, s:s}", "iterations", c->iterations,
                                      "residual", res_real(c->residual), "last_omega",
                                      res_real(c->last_omega), "message",
                                      c->message[0] ? c->message
                                                    : codec_case_status_name(c->status))))
        goto fail;
    return o;
fail:
    json_decref(o);
    return NULL;
}

int codec_result_encode(json_t **out, const codec_request *r, const sm_model *m,
                        const sm_result *res)
{
    json_t *doc = NULL, *cases;
    sm_model_info info;
    double te = 0, tl = 0, tg = 0;
    int i;

    *out = NULL;
    sm_model_get_info(m, &info);
    doc = json_object();
    if (!doc)
        goto fail;
    if (json_object_set_new(doc, "solver",
                            json_pack("{s:s, s:s, s:s}", "name", "spinmodal", "version",
                                      SM_VERSION, "request_sha256", codec_request_sha256(r))) ||
        json_object_set_new(doc, "model",
                            json_pack("{s:i, s:i, s:i, s:i}", "nodes", info.nodes,
                                      "elements", info.elements, "frames", info.frames,
                                      "coordinates", info.coordinates)))
        goto fail;
    cases = json_array();
    if (json_object_set_new(doc, "cases", cases))
        goto fail;
    for (i = 0; i < res->n_cases; i++) {
        const sm_case *c = &res->cases[i];
        if (json_array_append_new(cases, res_case(r, m, c)))
            goto fail;
        te += c->t_equilibrium;
        tl += c->t_linearize;
        tg += c->t_eigen;
    }
    if (json_object_set_new(doc, "timing_ms",
                            json_pack("{s:o, s:o, s:o}", "equilibrium", res_real(te),
                                      "linearize", res_real(tl), "eigen", res_real(tg))))
        goto fail;
    *out = doc;
    return SM_OK;
fail:
    json_decref(doc);
    return SM_NOMEM;
}

/* =================================================================== csv */

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

/* =============================================================== problem */

json_t *codec_problem_new(int http_status, const char *type, const char *title,
                          const char *detail, const codec_errors *errs)
{
    json_t *p = json_pack("{s:s, s:s, s:i}", "type", type ? type : "about:blank", "title",
                          title ? title : "Error", "status", http_status);

    if (!p)
        return NULL;
    if (detail && json_object_set_new(p, "detail", json_string(detail)))
        goto fail;
    if (errs && codec_errors_count(errs) > 0 &&
        json_object_set_new(p, "errors", codec_errors_to_json(errs)))
        goto fail;
    return p;
fail:
    json_decref(p);
    return NULL;
}

int codec_errors_http_status(const codec_errors *e)
{
    if (codec_errors_too_large(e))
        return 413;
    if (codec_errors_malformed(e))
        return 400;
    return 422;
}

json_t *codec_problem_from_errors(const codec_errors *errs)
{
    int status = codec_errors_http_status(errs), n = codec_errors_count(errs);
    char detail[96];

    switch (status) {
    case 413:
        return codec_problem_new(413, NULL, "Content Too Large",
                                 "The request is larger than the configured limit.", errs);
    case 400:
        return codec_problem_new(400, NULL, "Bad Request", "The request is not valid JSON.",
                                 errs);
    default:
        snprintf(detail, sizeof(detail), "The request has %d error%s; see 'errors'.", n,
                 n == 1 ? "" : "s");
        return codec_problem_new(422, NULL, "Unprocessable Content", detail, errs);
    }
}
