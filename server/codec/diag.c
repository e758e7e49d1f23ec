/*
 * diag.c — the core's diagnostics as request errors, and building the model.
 *
 * How it fits: the core knows nothing of JSON.  sm_model_new and sm_solve
 * report a failure in an sm_diag that names an item by kind and index (a
 * member, joint, section, point mass, the clamp or an option) and a core
 * field name (mu, basis, omegas...).  This file maps that back to the JSON
 * pointer of the field in the request (joints and sections by name in the
 * sorted order of request.c, core field names to request field names) so a
 * topology error found by the core reads like any validation error.
 * Section fields go through section.c, which knows the section's form: a
 * core error on EA of a section given as E, G, A, I_flap, I_edge, J points
 * at its E and says EA = E*A (EI_flap: I_flap, EI_edge: I_edge, GJ: J).
 * codec_model_new is the one place the codec calls sm_model_new.
 */
#include "codec_internal.h"

#include <stdlib.h>
#include <string.h>

/* Request field name of a core field name (mu -> mass_per_length ...). */
static const char *diag_field_name(const char *f)
{
    if (!strcmp(f, "mu"))
        return "mass_per_length";
    if (!strcmp(f, "basis"))
        return "substructure_modes";
    if (!strcmp(f, "omegas"))
        return "omega";
    if (!strcmp(f, "twist"))
        return "twist_deg";
    if (!strcmp(f, "e3"))
        return "flap_direction";
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

/* 1 when f is a section property, in the core's or the request's spelling. */
static int diag_is_section_field(const char *f)
{
    static const char *const names[] = {"E", "A", "I", "mu", "mass_per_length", "EA", "EI_flap",
                                        "EI_edge", "GJ", "G", "I_flap", "I_edge", "J",
                                        "flap_inertia", "edge_inertia", "i_flap", "i_edge",
                                        "ip_over_a", NULL};

    return diag_among(f, names);
}

/*
 * Pointer of field f of section s (section.c names the request field; the
 * section itself when none stands for f).  *relation: NULL or a text for
 * the message ("EA = E*A").  malloc'd, NULL = NOMEM.
 */
static char *diag_section_pointer(const codec_request *r, int s, const char *f,
                                  const char **relation)
{
    const json_t *secs =
        json_object_get(req_structure(r), "sections");
    const char *name = req_section_name(r, s), *key;
    char *base = err_ptr_key("/structure/sections", name), *p;

    *relation = NULL;
    if (!base || f[0] == '\0')
        return base;
    if (!strcmp(f, "i_flap") || !strcmp(f, "i_edge")) /* sm_section's spelling */
        f = f[2] == 'f' ? "flap_inertia" : "edge_inertia";
    key = sec_request_field(json_object_get(secs, name), f, relation);
    if (!key)
        return base;
    p = err_ptr_key(base, key);
    free(base);
    return p;
}

/* Pointer of an option field reported by the core. */
static char *diag_options_pointer(const codec_request *r, const char *f, int index)
{
    const json_t *canon = codec_request_canonical(r);
    const json_t *fr = json_object_get(canon, "frames");
    const json_t *an = json_object_get(canon, "analysis");
    const char *unit = json_object_get(an, "rpm") ? "rpm" : "omega";
    const json_t *om = json_object_get(an, unit);

    if (!strcmp(f, "omega") || !strcmp(f, "omegas")) {
        if (json_is_array(om) && index >= 0 && (size_t)index < json_array_size(om))
            return err_fmt("/analysis/%s/%d", unit, index);
        return err_fmt("/analysis/%s", unit);
    }

    if (!strcmp(f, "frames") || !strcmp(f, "frames_param") || !strcmp(f, "per_member") ||
        !strcmp(f, "elements_per_frame")) {
        if (json_is_object(fr) && strcmp(f, "frames")) {
            const char *key = json_object_get(fr, "per_member") ? "per_member"
                                                                : "elements_per_frame";
            return err_fmt("/frames/%s", key);
        }
        return strdup("/frames");
    }
    if (!strcmp(f, "gravity")) /* DESIGN.md 8.8 */
        return strdup(json_object_get(canon, "tower") ? "/tower/gravity" : "/structure/gravity");
    if (f[0] == '\0')
        return strdup("/analysis");
    return err_ptr_key("/analysis", diag_field_name(f));
}

/* Pointer of joint j's field f ("x", "y", "z": its coordinate; else the joint). */
static char *diag_joint_pointer(const codec_request *r, int j, const char *f)
{
    const json_t *joints =
        json_object_get(req_structure(r), "joints");
    const char *name = codec_request_joint_name(r, j);
    char *base = err_ptr_key("/structure/joints", name), *p;
    int k = !strcmp(f, "x") ? 0 : !strcmp(f, "y") ? 1 : !strcmp(f, "z") ? 2 : -1;

    /* z only where the joint has one (a spatial request writes every z out) */
    if (!base || k < 0 || (size_t)k >= json_array_size(json_object_get(joints, name)))
        return base;
    p = err_fmt("%s/%d", base, k);
    free(base);
    return p;
}

/*
 * Pointer of the item a diagnostic names; malloc'd, NULL = NOMEM.
 * *relation: NULL or a text the message should carry (section fields).
 */
static char *diag_pointer(const codec_request *r, const sm_diag *d, const char **relation)
{
    const sm_structure *st = codec_request_structure(r);
    const char *f = d->field;
    int i = d->item_index;
    char *base, *p;

    static const char *const member_fields[] = {
        "id",        "from",           "to",       "section",    "elements",
        "twist_deg", "flap_direction", "stations", "foundation", NULL};
    static const char *const pm_fields[] = {"joint", "mass", "inertia", "products", "offset",
                                            NULL};
    const char *const *known;

    *relation = NULL;
    switch (d->item) {
    case SM_ITEM_MEMBER:
        if (i < 0 || i >= st->n_members)
            return strdup("/structure/members");
        if (diag_is_section_field(f) && st->members[i].section >= 0 &&
            st->members[i].section < st->n_sections)
            return diag_section_pointer(r, st->members[i].section, f, relation);
        base = err_ptr_idx("/structure/members", (size_t)i);
        known = member_fields;
        break;
    case SM_ITEM_JOINT:
        if (i < 0 || i >= st->n_joints)
            return strdup("/structure/joints");
        return diag_joint_pointer(r, i, f);
    case SM_ITEM_SECTION:
        if (i < 0 || i >= st->n_sections)
            return strdup("/structure/sections");
        return diag_section_pointer(r, i, f, relation);
    case SM_ITEM_POINT_MASS:
        if (i < 0 || i >= st->n_point_masses)
            return strdup("/structure/point_masses");
        base = err_ptr_idx("/structure/point_masses", (size_t)i);
        known = pm_fields;
        break;
    case SM_ITEM_CLAMP:
        return plat_clamp_pointer(req_structure(r));
    case SM_ITEM_SUPPORT: /* springs, then foundations (supports.c) */
        return sup_pointer(req_structure(r), i, f);
    case SM_ITEM_OPTIONS:
        return diag_options_pointer(r, f, i);
    case SM_ITEM_NONE:
    default:
        return strdup("/structure");
    }
    /* a field the request does not have: point at the item itself */
    if (!base || f[0] == '\0' || !diag_among(diag_field_name(f), known))
        return base;
    p = err_ptr_key(base, diag_field_name(f));
    free(base);
    return p;
}

int codec_diag_error(const codec_request *r, const sm_diag *d, codec_errors *errs)
{
    const char *relation;
    const char *msg = d->message[0] ? d->message : sm_strerror(d->status);
    char *p = diag_pointer(r, d, &relation);
    int rc;

    if (!p) {
        err_mark_nomem(errs);
        return SM_NOMEM;
    }
    /* req_error moves a structure pointer into /blade for the blade form */
    if (relation)
        rc = req_error(r, errs, p, "%s (%s)", msg, relation);
    else
        rc = req_error(r, errs, p, "%s", msg);
    free(p);
    return rc;
}

int codec_model_new(sm_model **out, const codec_request *r, codec_errors *errs,
                    sm_diag *diag)
{
    return codec_model_build(out, r, NULL, NULL, errs, diag);
}

int codec_model_build(sm_model **out, const codec_request *r, sm_progress_fn cb, void *user,
                      codec_errors *errs, sm_diag *diag)
{
    sm_diag local;
    sm_diag *d = diag ? diag : &local;
    int rc;

    memset(d, 0, sizeof(*d));
    d->item_index = -1;
    *out = NULL;
    rc = sm_model_build(out, codec_request_structure(r), codec_request_options(r), cb, user, d);
    if (rc == SM_OK)
        return SM_OK;
    *out = NULL;
    if (d->status == SM_OK)
        d->status = rc;
    if (rc != SM_NOMEM && rc != SM_CANCELED && codec_diag_error(r, d, errs))
        return SM_NOMEM;
    return rc;
}
