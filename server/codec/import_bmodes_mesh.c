/*
 * import_bmodes_mesh.c — BModes' own model of an imported blade or tower (import option
 * bmodes_mesh, CLI --bmodes-mesh): the request's stations sampled at the midpoints of BModes'
 * el_loc elements as BModes does, k FE elements each, written as a structure; the warnings'
 * pointers follow the form it replaced.
 *
 * How it fits: import_bmodes.c (the .bmi and section-file reader) calls bm_own_mesh and
 * bm_mesh_warnings after it has built the blade or tower form (import_internal.h).
 */
#include "import_internal.h"
#include "codec.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/*
 * A sampled number as a JSON real: rounded as printed; one that is not a number the request
 * carries sets *big and is written as 0 (the caller refuses the file: json_real(inf) would be
 * NULL, read as out of memory).
 */
static json_t *bm_real(double v, int *big)
{
    if (!imp_finite(v)) {
        *big = 1;
        v = 0.0;
    }
    return json_real(imp_round(v));
}

/* Value x of station key k at fraction f between stations a and b (arrays element by element). */
static json_t *bm_lerp(const json_t *a, const json_t *b, double f, int *big)
{
    double va, vb, v;

    if (json_is_array(a)) {
        json_t *o = json_array();
        size_t i;
        for (i = 0; o && i < json_array_size(a); i++)
            if (json_array_append_new(
                    o, bm_lerp(json_array_get(a, i), json_array_get(b, i), f, big))) {
                json_decref(o);
                return NULL;
            }
        return o;
    }
    va = json_number_value(a);
    vb = json_number_value(b);
    v = va + f * (vb - va);
    if (!isfinite(vb - va)) /* opposite signs near the largest double: (1 - f) a + f b */
        v = (1.0 - f) * va + f * vb;
    return bm_real(v, big);
}

/* sts[j] key's number (0 when absent). */
static double bm_st(const json_t *st, const char *key)
{
    return json_number_value(json_object_get(st, key));
}

/*
 * The expanded blade's stations sts at span fraction x as BModes samples them for an element
 * (BModes.f90:1110-1140): every value linear between the stations around x, the mass moments
 * through their ratio to the mass (BModes.f90:702-704) and, BModes' moments being about the
 * reference axis, the edge moment moved there for that and back to the centre of mass
 * (the importer's edge_inertia = edge_iner - mass cg^2).  A new station object without "s".
 */
static json_t *bm_sample(const json_t *sts, double x, int *big)
{
    size_t j = 0, n = json_array_size(sts);
    const json_t *a, *b, *v;
    const char *key;
    json_t *o = json_object();
    double f, mu, cg, ra, rb;

    while (j + 2 < n && x > bm_st(json_array_get(sts, j + 1), "s"))
        j++;
    a = json_array_get(sts, j);
    b = json_array_get(sts, j + 1);
    f = (x - bm_st(a, "s")) / (bm_st(b, "s") - bm_st(a, "s"));
    json_object_foreach((json_t *)a, key, v)
        if (strcmp(key, "s") &&
            json_object_set_new(o, key, bm_lerp(v, json_object_get(b, key), f, big)))
            goto fail;
    mu = bm_st(o, "mass_per_length");
    ra = bm_st(a, "flap_inertia") / bm_st(a, "mass_per_length");
    rb = bm_st(b, "flap_inertia") / bm_st(b, "mass_per_length");
    if (json_object_set_new(o, "flap_inertia", bm_real(mu * (ra + f * (rb - ra)), big)))
        goto fail;
#define BM_CG(st) json_number_value(json_array_get(json_object_get(st, "cg_offset"), 0))
    ra = bm_st(a, "edge_inertia") / bm_st(a, "mass_per_length") + BM_CG(a) * BM_CG(a);
    rb = bm_st(b, "edge_inertia") / bm_st(b, "mass_per_length") + BM_CG(b) * BM_CG(b);
    cg = BM_CG(o);
#undef BM_CG
    if (json_object_set_new(o, "edge_inertia",
                            bm_real(mu * (ra + f * (rb - ra)) - mu * cg * cg, big)))
        goto fail;
    return o;
fail:
    json_decref(o);
    return NULL;
}

/*
 * Option bmodes_mesh = k: doc's request becomes BModes' own model in the structure form: the
 * blade (or tower) as the codec expands it (DESIGN.md 8.1, 8.5), cut at BModes' element boundaries el_loc into
 * nselt uniform members (two equal stations each) with the properties sampled at the element
 * midpoints, k FE elements each.  SM_OK, SM_NOMEM, SM_INVALID_INPUT (d) when the blade is not a
 * valid request.
 */
int bm_own_mesh(json_t *doc, const json_t *el_loc, int k, const char *file, import_diag *d,
                json_t *warn)
{
    json_t *req = json_object_get(doc, "request"), *st = NULL, *joints, *mems, *pms;
    codec_errors *errs = codec_errors_new();
    codec_request *r = NULL;
    codec_limits lim;
    const json_t *ex, *mem, *sts, *root, *tip;
    const char *rname, *tname, *secname;
    size_t n = json_array_size(el_loc), i, c;
    int rc = SM_NOMEM;

    codec_default_limits(&lim);
    if (!errs)
        return SM_NOMEM;
    rc = codec_request_from_json(&r, req, &lim, errs);
    if (rc == SM_INVALID_INPUT) {
        rc = imp_fail(d, file, 0, "bmodes_mesh", "the %s is not a valid request (%s: %s)",
                      json_object_get(req, "tower") ? "tower" : "blade",
                      codec_errors_pointer(errs, 0), codec_errors_message(errs, 0));
        goto done;
    }
    if (rc)
        goto done;
    rc = SM_NOMEM;
    ex = codec_request_structure_json(r);
    mem = json_array_get(json_object_get(ex, "members"), 0);
    sts = json_object_get(mem, "stations");
    rname = json_string_value(json_object_get(mem, "from")); /* blade: root, tower: base */
    tname = json_string_value(json_object_get(mem, "to"));   /* blade: tip, tower: top */
    secname = json_string_value(json_object_get(mem, "section"));
    root = json_object_get(json_object_get(ex, "joints"), rname);
    tip = json_object_get(json_object_get(ex, "joints"), tname);
    st = json_pack("{s:{}, s:O, s:[], s:s, s:O}", "joints", "sections",
                   json_object_get(ex, "sections"), "members", "clamp", rname, "point_masses",
                   json_object_get(ex, "point_masses"));
    if (!st || (json_object_get(ex, "platform") && /* a free base (tower platform) */
                (json_object_set_new(st, "clamp", json_null()) ||
                 json_object_set(st, "platform", json_object_get(ex, "platform")))))
        goto done;
    joints = json_object_get(st, "joints");
    mems = json_object_get(st, "members");
    for (i = 0; i < n; i++) {
        char name[32];
        double x = json_number_value(json_array_get(el_loc, i)), p[3];
        for (c = 0; c < 3; c++) {
            p[c] = imp_round(json_number_value(json_array_get(root, c)) +
                             x * (json_number_value(json_array_get(tip, c)) -
                                  json_number_value(json_array_get(root, c))));
            if (!imp_finite(p[c])) {
                rc = imp_fail(d, file, 0, "bmodes_mesh",
                              "the joint at el_loc %.15g is beyond "
                              "the largest number a request carries (%s)",
                              x, IMP_MAX_ABS_TEXT);
                goto done;
            }
        }
        if (i == 0 || i + 1 == n)
            snprintf(name, sizeof name, "%s", i == 0 ? rname : tname);
        else
            snprintf(name, sizeof name, "x%zu", i);
        if (json_object_set_new(joints, name, json_pack("[f, f, f]", p[0], p[1], p[2])))
            goto done;
        if (i == 0)
            continue;
        {
            double x0 = json_number_value(json_array_get(el_loc, i - 1));
            int h, big = 0;
            json_t *mid = bm_sample(sts, 0.5 * (x0 + x), &big), *m = NULL, *two[2] = {NULL, NULL};
            char from[32], id[32];
            if (big) {
                json_decref(mid);
                rc = imp_fail(d, file, 0, "bmodes_mesh",
                              "element e%zu (el_loc %.15g to %.15g): "
                              "a property sampled at its midpoint is beyond the largest number a "
                              "request carries (%s)",
                              i, x0, x, IMP_MAX_ABS_TEXT);
                goto done;
            }
            if (i == 1)
                snprintf(from, sizeof from, "%s", rname);
            else
                snprintf(from, sizeof from, "x%zu", i - 1);
            snprintf(id, sizeof id, "e%zu", i);
            for (h = 0; mid && h < 2; h++) { /* the member uniform: two equal stations */
                two[h] = json_pack("{s:f}", "s", (double)h);
                if (!two[h] || json_object_update(two[h], mid))
                    break;
            }
            if (two[0] && two[1])
                m = json_pack("{s:s, s:s, s:s, s:s, s:i, s:O, s:O, s:[O, O]}", "id", id, "from",
                              from, "to", name, "section", secname, "elements", k, "flap_direction",
                              json_object_get(mem, "flap_direction"), "twist_deg",
                              json_object_get(mem, "twist_deg"), "stations", two[0], two[1]);
            json_decref(two[0]);
            json_decref(two[1]);
            json_decref(mid);
            if (!m || json_array_append_new(mems, m))
                goto done;
        }
    }
    pms = json_object_get(st, "point_masses");
    if (!json_array_size(pms))
        json_object_del(st, "point_masses");
    if (json_object_set(req, "structure", st) ||
        json_object_del(req, json_object_get(req, "tower") ? "tower" : "blade") ||
        imp_warn(warn, "/structure",
                 "BModes' own model (bmodes_mesh %d): its %zu elements as uniform members "
                 "with the properties at their midpoints (BModes.f90:1110), %d FE elements "
                 "each, and the sections' mass moments in torsion only "
                 "(analysis.rotary_inertia \"torsion\": BModes has no bending rotary "
                 "inertia, Struct.f90:1222), which reproduces BModes' numbers; without the "
                 "option the properties are interpolated along the span as the file gives "
                 "them (the finer model: BModes itself refined to 96 elements gives 1.6-5.5 %% "
                 "higher frequencies on its CertTest blades)",
                 k, n - 1, k) ||
        json_object_set_new(json_object_get(req, "analysis"), "rotary_inertia",
                            json_string("torsion")) ||
        json_object_set_new(json_object_get(doc, "source"), "note",
                            json_string("BModes' element boundaries (nselt, el_loc) are the "
                                        "members of the structure (option bmodes_mesh)")))
        goto done;
    rc = SM_OK;
done:
    json_decref(st);
    codec_request_free(r);
    codec_errors_free(errs);
    return rc;
}

/*
 * After bm_own_mesh: the warnings' pointers into the blade (tower) form point into the
 * structure that replaced it (/blade/section/K -> /structure/sections/blade/K, any other
 * /blade... -> /structure; /tower likewise), and "warnings" gets the message of the one
 * bm_own_mesh added.  0, -1 (memory).
 */
int bm_mesh_warnings(json_t *doc, int tower)
{
    const char *form = tower ? "/tower" : "/blade", *name = form + 1;
    size_t fn = strlen(form);
    json_t *w;
    size_t i;
    char p[160];

    json_array_foreach(json_object_get(doc, "input_warnings"), i, w) {
        const char *ptr = json_string_value(json_object_get(w, "pointer"));
        if (!ptr || strncmp(ptr, form, fn) || (ptr[fn] != '/' && ptr[fn] != '\0'))
            continue;
        if (!strncmp(ptr + fn, "/section/", 9))
            snprintf(p, sizeof(p), "/structure/sections/%s/%s", name, ptr + fn + 9);
        else
            snprintf(p, sizeof(p), "/structure");
        if (json_object_set_new(w, "pointer", json_string(p)))
            return -1;
    }
    return imp_legacy_warnings(doc);
}
