/*
 * result.c — an sm_result as the result document of DESIGN.md section 4.
 *
 * How it fits: after sm_solve, the CLI and the daemon's workers call
 * codec_result_encode; the document is what the daemon stores and serves
 * byte for byte, so its layout is a contract (schemas/result.schema.json).
 * The request supplies the SHA-256 and the joint names (in the sorted order
 * of request.c), the model the joint -> node map and the sizes.  Numbers
 * that are not finite become null (JSON has no NaN or infinity).  csv.c
 * writes the same frequencies as a table.
 *
 * Planar or spatial (DESIGN.md 7.3): every node, joint and shape row has
 * the case's node_dof numbers, [x, y, phi] planar and [x, y, z, rx, ry, rz]
 * spatial; a spatial model adds "spatial": true and "dof_per_node": 6 to
 * "model".  A planar result has no new key, so its bytes are those of
 * before the spatial model existed.
 *
 * Blades (DESIGN.md 8): each mode ends with "per_rev" (frequency / omega,
 * null at omega = 0), each case with "rpm", and the document with
 * "input_warnings" when the request has any (warn.c).  These are appended
 * after the keys of before, so a result of before reads the same with
 * them removed.
 *
 * Error estimate (DESIGN.md 9, analysis.error_estimate): each mode ends
 * with "error_estimate" (rad/s, null where no mode of the refined levels
 * matched); without the option the key is absent and the bytes unchanged.
 * Trust (DESIGN.md 9.1): each mode then ends with "label", "label_confidence",
 * "energy", "tracked_index", "tracking_flag", "tracking_partner", and the
 * document with "critical_speeds" when the request gives engine_orders;
 * appended likewise (frequencies and shapes are unchanged).
 *
 * Large results (issue 23 item 9): the daemon stores the text of the
 * document, so codec_result_text writes it one case at a time instead of
 * building the whole tree and dumping it: the text is the only whole copy
 * held, with the same bytes as json_dumps(codec_result_encode's document,
 * CODEC_RESULT_DUMP).  A case is described once (res_case and the functions
 * it calls) to a res_out, which builds its tree for codec_result_encode or
 * writes its text straight away for codec_result_text (issue 27: no tree of
 * a case at all).
 */
#include "codec_internal.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

const char *codec_case_status_name(sm_case_status s)
{
    switch (s) {
    case SM_CASE_SOLVED: return "solved";
    case SM_CASE_UNSTABLE: return "unstable";
    case SM_CASE_NO_EQUILIBRIUM: return "no_equilibrium";
    case SM_CASE_EIGEN_FAILED: return "eigen_failed";
    }
    return "unknown";
}

/* A real, or null when not finite (JSON has no NaN or infinity). */
static json_t *res_real(double x)
{
    return isfinite(x) ? json_real(x) : json_null();
}

/* Values per node of case c: node_dof (3 planar, 6 spatial). */
static int res_node_dof(const sm_case *c)
{
    return c->node_dof == 6 ? 6 : 3; /* only 3 and 6 exist: never read past the arrays */
}

/* case.equilibrium */
static void res_equilibrium(const codec_request *r, const sm_model *m, const sm_case *c, res_out *o)
{
    int j, nj = codec_request_structure(r)->n_joints, dof = res_node_dof(c);

    ro_open(o, "equilibrium", 1);
    ro_bool(o, "converged", c->converged);
    ro_int(o, "iterations", c->iterations);
    ro_real(o, "residual", c->residual);
    if (c->nodes && c->n_nodes > 0) {
        ro_open(o, "joints", 1);
        for (j = 0; j < nj; j++) {
            int node = sm_model_joint_node(m, j);
            if (node >= 0 && node < c->n_nodes)
                ro_reals(o, codec_request_joint_name(r, j), c->nodes + (size_t)dof * (size_t)node,
                         dof);
        }
        ro_close(o);
        ro_rows(o, "nodes", c->nodes, c->n_nodes, dof);
    }
    if (c->axial_force && c->n_elements > 0)
        ro_reals(o, "axial_force", c->axial_force, c->n_elements);
    if (c->nodes && c->n_nodes > 0)
        ro_real(o, "max_frame_rotation", c->max_frame_rotation);
    ro_close(o);
}

/* {"axial", "edge", "flap", "torsion"} (planar: {"axial", "bending"}) from 4 fractions. */
static void res_parts(res_out *o, const char *key, const double *f, int spatial)
{
    ro_open(o, key, 1);
    ro_real(o, "axial", f[0]);
    if (!spatial) {
        ro_real(o, "bending", f[1]);
    } else {
        ro_real(o, "edge", f[1]);
        ro_real(o, "flap", f[2]);
        ro_real(o, "torsion", f[3]);
    }
    ro_close(o);
}

char *codec_mode_label(const codec_request *r, int kind, int ordinal, char *buf, size_t size)
{
    char tmp[32];
    const char *name = kind == SM_MODE_FLAP   ? "fore-aft"
                       : kind == SM_MODE_EDGE ? "side-side"
                                              : NULL;

    sm_mode_label(kind, ordinal, buf, size);
    if (!name || !r || !json_object_get(codec_request_canonical(r), "tower"))
        return buf;
    /* a tower's flap (e3) is fore-aft and its edge (e2) side-side (tower.c, DESIGN.md 8.5):
     * name the mode by the direction it moves */
    snprintf(tmp, sizeof tmp, "%s", buf);
    char *sp = strrchr(tmp, ' ');
    if (sp)
        sp[1] = '\0';
    else
        tmp[0] = '\0';
    snprintf(buf, size, "%s%s", tmp, name);
    return buf;
}

/*
 * DESIGN.md 9.1, appended to mode k: "label", "label_confidence", "energy" {"kinetic",
 * "strain", and "support" for a model with supports (DESIGN.md 8.7)}, "tracked_index", "tracking_flag" ("crossing", "veering" or null) and
 * "tracking_partner" (the other tracked index of the flagged pair, or null).  Nothing for a
 * case the core gave no labels (hand-built results).
 */
static void res_trust(const codec_request *r, res_out *o, const sm_case *c, int k)
{
    char lab[32];
    int spatial = res_node_dof(c) == 6, flag;
    const double *f;

    if (c->label_kind && c->energy) {
        f = c->energy + (size_t)k * SM_ENERGY_PARTS;
        codec_mode_label(r, c->label_kind[k], c->label_ordinal[k], lab, sizeof(lab));
        ro_string(o, "label", lab);
        ro_real(o, "label_confidence", c->label_confidence[k]);
        ro_open(o, "energy", 1);
        res_parts(o, "kinetic", f, spatial);
        res_parts(o, "strain", f + 4, spatial);
        if (c->support_share) /* DESIGN.md 8.7: only models with supports */
            ro_real(o, "support", c->support_share[k]);
        ro_close(o);
    }
    if (c->tracked_index) {
        flag = c->track_flag[k];
        ro_int(o, "tracked_index", c->tracked_index[k]);
        if (flag == SM_TRACK_CROSSING || flag == SM_TRACK_VEERING)
            ro_string(o, "tracking_flag", flag == SM_TRACK_CROSSING ? "crossing" : "veering");
        else
            ro_null(o, "tracking_flag");
        if (flag)
            ro_int(o, "tracking_partner", c->track_partner[k]);
        else
            ro_null(o, "tracking_partner");
    }
}

/* One mode of a case. */
static void res_mode(const codec_request *r, const sm_case *c, int k, int shapes, res_out *o)
{
    int dof = res_node_dof(c);
    size_t stride = (size_t)dof * (size_t)c->n_nodes;
    double mac = c->mac_to_previous ? c->mac_to_previous[k] : -1;
    int prev = c->previous_index ? c->previous_index[k] : -1;

    ro_open(o, NULL, 1);
    ro_real(o, "frequency_rad_s", c->frequency[k]);
    ro_real(o, "frequency_hz", c->frequency[k] / CODEC_TWO_PI);
    ro_open(o, "eigenvalue", 0);
    ro_real(o, NULL, c->eig_re[k]);
    ro_real(o, NULL, c->eig_im[k]);
    ro_close(o);
    if (mac < 0)
        ro_null(o, "mac_to_previous");
    else
        ro_real(o, "mac_to_previous", mac);
    if (prev < 0)
        ro_null(o, "previous_index");
    else
        ro_int(o, "previous_index", prev);
    if (shapes && c->shape_re) {
        ro_open(o, "shape", 1);
        ro_rows(o, "re", c->shape_re + k * stride, c->n_nodes, dof);
        if (c->shape_im)
            ro_rows(o, "im", c->shape_im + k * stride, c->n_nodes, dof);
        ro_close(o);
    }
    if (c->omega > 0) /* per_rev: frequency / omega, null at rest */
        ro_real(o, "per_rev", c->frequency[k] / c->omega);
    else
        ro_null(o, "per_rev");
    res_trust(r, o, c, k);
    if (c->error_estimate)
        ro_real(o, "error_estimate", c->error_estimate[k]);
    ro_close(o);
}

/* One case (speed), rpm its speed in rev/min, into o. */
static void res_case(const codec_request *r, const sm_model *m, const sm_case *c, double rpm,
                     res_out *o)
{
    int k, shapes = codec_request_options(r)->mode_shapes;

    ro_open(o, NULL, 1);
    ro_real(o, "omega", c->omega);
    ro_string(o, "status", codec_case_status_name(c->status));
    res_equilibrium(r, m, c, o);
    if (c->status != SM_CASE_NO_EQUILIBRIUM && c->status != SM_CASE_EIGEN_FAILED) {
        ro_open(o, "stability", 1);
        ro_bool(o, "stable", c->stable);
        ro_int(o, "negative_eigenvalues", c->negative_eigenvalues);
        ro_close(o);
    }
    ro_open(o, "modes", 0);
    for (k = 0; k < c->n_modes; k++)
        res_mode(r, c, k, shapes, o);
    ro_close(o);
    if (c->warning[0]) {
        ro_open(o, "warnings", 0);
        ro_string(o, NULL, c->warning);
        ro_close(o);
    }
    if (c->status != SM_CASE_SOLVED) {
        ro_open(o, "diagnostics", 1);
        ro_int(o, "iterations", c->iterations);
        ro_real(o, "residual", c->residual);
        ro_real(o, "last_omega", c->last_omega);
        ro_string(o, "message", c->message[0] ? c->message : codec_case_status_name(c->status));
        ro_close(o);
    }
    ro_real(o, "rpm", rpm);
    ro_close(o);
}

/* The id of member i in the canonical request: "blade" for the blade form, else its "id" (a
 * string) or null. */
static void res_member_id(const codec_request *r, int i, res_out *o)
{
    const json_t *canon = codec_request_canonical(r);
    const json_t *mems = json_object_get(json_object_get(canon, "structure"), "members");
    const char *id = json_string_value(json_object_get(json_array_get(mems, (size_t)i), "id"));

    if (json_object_get(canon, "blade"))
        ro_string(o, "id", "blade");
    else if (json_object_get(canon, "tower"))
        ro_string(o, "id", "tower");
    else if (id)
        ro_string(o, "id", id);
    else
        ro_null(o, "id");
}

/*
 * One member's layout for span-wise shapes (spatial, mode shapes on; DESIGN.md 8.3):
 * {"member", "id", "length", "axes", "nodes", "s", "twist_deg"}: the member's axes without
 * twist ([e1, e2, e3], 9 numbers, hub frame), its FE nodes from `from` (s = 0) to `to` (s = 1),
 * their span fractions and the structural twist there (degrees, about e1 from e2, e3).
 */
static void res_member_layout(const codec_request *r, const sm_model *m, int i, res_out *o)
{
    int n = sm_model_member_nodes(m, i, 0, NULL, NULL, NULL), k;
    int *nodes = NULL;
    double *s = NULL, *tw = NULL, ax[9], a[3], b[3];

    if (n < 2) {
        ro_null(o, NULL);
        return;
    }
    nodes = malloc((size_t)n * sizeof *nodes);
    s = malloc((size_t)n * sizeof *s);
    tw = malloc((size_t)n * sizeof *tw);
    if (!nodes || !s || !tw || sm_model_member_nodes(m, i, n, nodes, s, tw) != n ||
        sm_model_member_axes(m, i, ax) != SM_OK) {
        o->nomem = 1;
        goto done;
    }
    sm_model_node_position3(m, nodes[0], a);
    sm_model_node_position3(m, nodes[n - 1], b);
    ro_open(o, NULL, 1);
    ro_int(o, "member", i);
    res_member_id(r, i, o);
    ro_real(o, "length",
            sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
                 (b[2] - a[2]) * (b[2] - a[2])));
    ro_reals(o, "axes", ax, 9);
    ro_open(o, "nodes", 0);
    for (k = 0; k < n; k++)
        ro_int(o, NULL, nodes[k]);
    ro_close(o);
    ro_reals(o, "s", s, n);
    for (k = 0; k < n; k++)
        tw[k] /= CODEC_RAD_PER_DEG;
    ro_reals(o, "twist_deg", tw, n);
    ro_close(o);
done:
    free(nodes);
    free(s);
    free(tw);
}

/* The "model" object: sizes, and for a spatial model "spatial" and "dof_per_node", and with
 * mode shapes "members" (res_member_layout). */
static void res_model(const codec_request *r, const sm_model *m, const sm_model_info *info,
                      res_out *o)
{
    const sm_structure *st = codec_request_structure(r);
    int i;

    ro_open(o, "model", 1);
    ro_int(o, "nodes", info->nodes);
    ro_int(o, "elements", info->elements);
    ro_int(o, "frames", info->frames);
    ro_int(o, "coordinates", info->coordinates);
    if (st->spatial) {
        ro_bool(o, "spatial", 1);
        ro_int(o, "dof_per_node", 6);
    }
    if (st->spatial && codec_request_options(r)->mode_shapes) {
        ro_open(o, "members", 0);
        for (i = 0; i < st->n_members; i++)
            res_member_layout(r, m, i, o);
        ro_close(o);
    }
    ro_close(o);
}

/* One critical speed (DESIGN.md 9.1). */
static json_t *res_critical(const sm_critical *c)
{
    char lab[32];

    sm_mode_label(c->label_kind, c->label_ordinal, lab, sizeof(lab));
    return json_pack("{s:o, s:i, s:s, s:o, s:o, s:o, s:o, s:o, s:b, s:i, s:o, s:o, s:[o, o]}",
                     "order", res_real(c->order), "tracked_index", c->tracked_index, "label", lab,
                     "label_confidence", res_real(c->label_confidence), "omega",
                     res_real(c->omega), "rpm", res_real(c->omega * 60 / CODEC_TWO_PI),
                     "frequency_rad_s", res_real(c->frequency), "frequency_hz",
                     res_real(c->frequency / CODEC_TWO_PI), "refined", c->refined,
                     "refine_solves", c->iterations, "residual", res_real(c->residual),
                     "omega_interpolated", res_real(c->omega_interpolated), "bracket",
                     res_real(c->omega_below), res_real(c->omega_above));
}

/* The document's "critical_speeds" (only when the request gives engine_orders). */
static int res_critical_speeds(json_t *doc, const codec_request *r, const sm_result *res)
{
    json_t *a;
    int i;

    if (codec_request_options(r)->n_engine_orders <= 0)
        return 0;
    a = json_array();
    if (json_object_set_new(doc, "critical_speeds", a))
        return -1;
    for (i = 0; i < res->n_critical; i++)
        if (json_array_append_new(a, res_critical(&res->critical[i])))
            return -1;
    return 0;
}

/* One divergence speed (shared DESIGN A). */
static json_t *res_divergence(const sm_divergence *d)
{
    char lab[32];

    sm_mode_label(d->label_kind, d->label_ordinal, lab, sizeof(lab));
    return json_pack("{s:o, s:o, s:s, s:s, s:[o, o], s:[i, i], s:b, s:i, s:o}", "omega_rad_s",
                     res_real(d->omega), "rpm", res_real(d->omega * 60 / CODEC_TWO_PI), "mode", lab,
                     "kind", d->onset ? "onset" : "recovery", "bracket", res_real(d->omega_below),
                     res_real(d->omega_above), "negative_eigenvalues", d->negative_below,
                     d->negative_above, "refined", d->refined, "refine_solves", d->iterations,
                     "omega_interpolated", res_real(d->omega_interpolated));
}

/* The document's "divergence_speeds" (only when the sweep crossed one: results without keep
 * their bytes). */
static int res_divergence_speeds(json_t *doc, const sm_result *res)
{
    json_t *a;
    int i;

    if (res->n_divergence <= 0)
        return 0;
    a = json_array();
    if (json_object_set_new(doc, "divergence_speeds", a))
        return -1;
    for (i = 0; i < res->n_divergence; i++)
        if (json_array_append_new(a, res_divergence(&res->divergence[i])))
            return -1;
    return 0;
}

/* The document's members before "cases", "solver" and "model", into the open document o. */
static void res_head(const codec_request *r, const sm_model *m, res_out *o)
{
    sm_model_info info;

    sm_model_get_info(m, &info);
    ro_open(o, "solver", 1);
    ro_string(o, "name", "spinmodal");
    ro_string(o, "version", SM_VERSION);
    ro_string(o, "request_sha256", codec_request_sha256(r));
    ro_close(o);
    res_model(r, m, &info, o);
}

/*
 * The document's members after "cases", set on doc: "timing_ms", "input_warnings",
 * "refinement_stopped", "critical_speeds", "divergence_speeds".  Returns 0, or -1 out of memory.
 */
static int res_tail(json_t *doc, const codec_request *r, const sm_result *res)
{
    const json_t *warnings = codec_request_input_warnings(r);
    double te = 0, tl = 0, tg = 0;
    int i;

    for (i = 0; i < res->n_cases; i++) {
        te += res->cases[i].t_equilibrium;
        tl += res->cases[i].t_linearize;
        tg += res->cases[i].t_eigen;
    }
    if (json_object_set_new(doc, "timing_ms",
                            json_pack("{s:o, s:o, s:o}", "equilibrium", res_real(te),
                                      "linearize", res_real(tl), "eigen", res_real(tg))))
        return -1;
    if (json_array_size(warnings) &&
        json_object_set_new(doc, "input_warnings", json_deep_copy(warnings)))
        return -1;
    if (res->refine_stopped &&
        json_object_set_new(doc, "refinement_stopped",
                            json_string("a stop (the job time limit, a cancel or a shutdown) came "
                                        "after every speed was solved: the cases are whole, but "
                                        "critical_speeds and divergence_speeds may be unrefined "
                                        "or missing, and an error estimate asked for was not "
                                        "made")))
        return -1;
    return res_critical_speeds(doc, r, res) || res_divergence_speeds(doc, res) ? -1 : 0;
}

/* Case i of res, with its rpm (as the request gave it, else from omega), into o. */
static void res_case_at(const codec_request *r, const sm_model *m, const sm_result *res, int i,
                        res_out *o)
{
    int n_rpm;
    const double *rpm = codec_request_rpm(r, &n_rpm);

    res_case(r, m, &res->cases[i], i < n_rpm ? rpm[i] : NAN, o);
}

int codec_result_encode(json_t **out, const codec_request *r, const sm_model *m,
                        const sm_result *res)
{
    json_t *doc, *cases;
    res_out head = {0};
    int i;

    *out = NULL;
    ro_open(&head, NULL, 1);
    res_head(r, m, &head);
    ro_close(&head);
    doc = head.c[0];
    if (head.nomem) {
        json_decref(doc);
        return SM_NOMEM;
    }
    cases = json_array();
    if (!doc || json_object_set_new(doc, "cases", cases))
        goto fail;
    for (i = 0; i < res->n_cases; i++) {
        res_out o = {0};
        res_case_at(r, m, res, i, &o);
        if (o.nomem) {
            json_decref(o.c[0]);
            goto fail;
        }
        if (json_array_append_new(cases, o.c[0]))
            goto fail;
    }
    if (res_tail(doc, r, res))
        goto fail;
    *out = doc;
    return SM_OK;
fail:
    json_decref(doc);
    return SM_NOMEM;
}

/* json_dump_callback into a codec_text (data); -1 stops the dump when out of memory. */
static int res_put(const char *buffer, size_t size, void *data)
{
    codec_text *t = data;

    codec_text_put(t, buffer, size);
    return t->nomem ? -1 : 0;
}

/* Append x (stolen; NULL is out of memory) to t as CODEC_RESULT_DUMP text; 0 or -1. */
static int res_dump(codec_text *t, json_t *x)
{
    int rc = x ? codec_json_dump(x, res_put, t) : -1;

    json_decref(x);
    return rc || t->nomem ? -1 : 0;
}

/*
 * The document as text, one case at a time: {head members, "cases": [case, case, ...], tail
 * members}.  A compact dump writes an object as "{" members joined by "," "}", so the head
 * without its "}", the cases and the tail with its "{" turned into "," are the bytes of the
 * whole document's dump.
 */
static int res_text_head(codec_text *t, const codec_request *r, const sm_model *m)
{
    res_out o = {0};

    o.t = t;
    ro_open(&o, NULL, 1);
    res_head(r, m, &o); /* the document stays open: its "}" is the tail's */
    codec_text_puts(t, ",\"cases\":[");
    return o.nomem || t->nomem ? -1 : 0;
}

/* Case i as text (res_out: no tree); 0 or -1. */
static int res_case_text(codec_text *t, const codec_request *r, const sm_model *m,
                         const sm_result *res, int i)
{
    res_out o = {0};

    o.t = t;
    res_case_at(r, m, res, i, &o);
    return o.nomem || t->nomem ? -1 : 0;
}

/* Cases [from, to) (each after the first of the document with its ","); 0 or -1. */
static int res_text_cases(codec_text *t, const codec_request *r, const sm_model *m,
                          const sm_result *res, int from, int to)
{
    for (int i = from; i < to; i++) {
        if (i > 0)
            codec_text_puts(t, ",");
        if (res_case_text(t, r, m, res, i))
            return -1;
    }
    return 0;
}

static int res_text_tail(codec_text *t, const codec_request *r, const sm_result *res)
{
    json_t *tail;
    size_t at;

    codec_text_puts(t, "]");
    tail = json_object();
    if (!tail || res_tail(tail, r, res)) {
        json_decref(tail);
        return -1;
    }
    at = t->len;
    if (res_dump(t, tail))
        return -1;
    t->p[at] = ','; /* the tail's "{" */
    return 0;
}

/*
 * The cases on several threads (the request's sweep threads; issue 27: building, dumping and
 * freeing the cases' trees was 11 % of a 101-speed spatial sweep, all of it after the sweep on
 * one thread).  The cases form blocks; the threads build the blocks' texts in any order, at
 * most RES_WINDOW blocks per thread ahead of the first one not yet appended, and the calling
 * thread appends them in order and frees each (so the text in blocks beside the document stays a
 * small part of it).  Each case's text is the same whatever thread writes it: the document's
 * bytes do not depend on the number of threads.  The request, the model and the result are
 * only read; jansson counts references atomically.
 */
#define RES_BLOCKS_PER_THREAD 4
#define RES_WINDOW 2

typedef struct res_par {
    const codec_request *r;
    const sm_model *m;
    const sm_result *res;
    int per, n_blocks, limit; /* cases a block, blocks, blocks taken ahead at most */
    codec_text *blk;
    int *state; /* 0 not written yet, 2 written, 3 out of memory */
    int next, appended, failed;
    pthread_mutex_t mu;
    pthread_cond_t cv;
} res_par;

/* The next block to write (lock held), or -1. */
static int res_par_take(res_par *p)
{
    if (p->failed || p->next >= p->n_blocks || p->next >= p->appended + p->limit)
        return -1;
    return p->next++;
}

/* Write block b (lock not held; taken), then record it (lock held on return). */
static void res_par_write(res_par *p, int b)
{
    int from = b * p->per, to = from + p->per < p->res->n_cases ? from + p->per : p->res->n_cases;
    int rc = res_text_cases(&p->blk[b], p->r, p->m, p->res, from, to);

    pthread_mutex_lock(&p->mu);
    p->state[b] = rc || p->blk[b].nomem ? 3 : 2;
    if (p->state[b] == 3)
        p->failed = 1;
    pthread_cond_broadcast(&p->cv);
}

static void *res_par_worker(void *arg)
{
    res_par *p = arg;
    int b;

    pthread_mutex_lock(&p->mu);
    while (!p->failed && p->next < p->n_blocks) {
        if ((b = res_par_take(p)) < 0) {
            pthread_cond_wait(&p->cv, &p->mu);
            continue;
        }
        pthread_mutex_unlock(&p->mu);
        res_par_write(p, b);
    }
    pthread_mutex_unlock(&p->mu);
    return NULL;
}

/* The cases of res into t on up to threads threads; 0 or -1. */
static int res_text_cases_par(codec_text *t, const codec_request *r, const sm_model *m,
                              const sm_result *res, int threads)
{
    int n = res->n_cases, want = threads * RES_BLOCKS_PER_THREAD, started = 0, rc = 0, b;
    res_par p = {.r = r,
                 .m = m,
                 .res = res,
                 .per = (n + want - 1) / want,
                 .limit = threads * RES_WINDOW,
                 .mu = PTHREAD_MUTEX_INITIALIZER,
                 .cv = PTHREAD_COND_INITIALIZER};
    pthread_t *th = calloc((size_t)threads, sizeof *th);

    p.n_blocks = (n + p.per - 1) / p.per;
    p.blk = calloc((size_t)p.n_blocks, sizeof *p.blk);
    p.state = calloc((size_t)p.n_blocks, sizeof *p.state);
    if (!th || !p.blk || !p.state) {
        free(th);
        free(p.blk);
        free(p.state);
        return res_text_cases(t, r, m, res, 0, n); /* on this thread */
    }
    while (started < threads - 1 && started < p.n_blocks - 1 &&
           pthread_create(&th[started], NULL, res_par_worker, &p) == 0)
        started++; /* fewer threads still work: this thread writes what is left */
    pthread_mutex_lock(&p.mu);
    for (int a = 0; a < p.n_blocks && !p.failed; a++) {
        while (p.state[a] < 2 && !p.failed) {
            if ((b = res_par_take(&p)) >= 0) { /* write one while block a is on its way */
                pthread_mutex_unlock(&p.mu);
                res_par_write(&p, b);
            } else {
                pthread_cond_wait(&p.cv, &p.mu);
            }
        }
        if (p.failed)
            break;
        pthread_mutex_unlock(&p.mu);
        codec_text_put(t, p.blk[a].p, p.blk[a].len);
        codec_text_free(&p.blk[a]);
        pthread_mutex_lock(&p.mu);
        p.appended++;
        if (t->nomem)
            p.failed = 1;
        pthread_cond_broadcast(&p.cv);
    }
    rc = p.failed ? -1 : 0;
    pthread_mutex_unlock(&p.mu);
    for (int i = 0; i < started; i++)
        pthread_join(th[i], NULL);
    for (int i = 0; i < p.n_blocks; i++)
        codec_text_free(&p.blk[i]);
    free(th);
    free(p.blk);
    free(p.state);
    pthread_mutex_destroy(&p.mu);
    pthread_cond_destroy(&p.cv);
    return rc;
}

static int res_text(codec_text *t, const codec_request *r, const sm_model *m, const sm_result *res)
{
    int threads = codec_request_options(r)->threads;

    if (res_text_head(t, r, m))
        return -1;
    if (threads > 1 && res->n_cases > 1 ? res_text_cases_par(t, r, m, res, threads)
                                        : res_text_cases(t, r, m, res, 0, res->n_cases))
        return -1;
    return res_text_tail(t, r, res);
}

int codec_result_text(char **out, size_t *len, const codec_request *r, const sm_model *m,
                      const sm_result *res)
{
    codec_text t = {NULL, 0, 0, 0};
    char *p;

    *out = NULL;
    if (len)
        *len = 0;
    if (res_text(&t, r, m, res) || t.nomem) {
        codec_text_free(&t);
        return SM_NOMEM;
    }
    p = realloc(t.p, t.len + 1); /* give back what the doubling left unused */
    *out = p ? p : t.p;
    if (len)
        *len = t.len;
    return SM_OK;
}
