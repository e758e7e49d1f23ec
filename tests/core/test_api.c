/*
 * test_api.c — public API behaviour: status texts, free(NULL), topology and
 * property errors naming the offending item and field, model sizes for every
 * frame scheme and basis (n = 2 free nodes + attachment nodes), branched
 * trees and a clamp in the middle of a structure; sm_model_build stopped by
 * its callback.
 */
#include "testutil.h"

static int build(int nj, const double *xy, int nm, const sm_member *mem, int clamp, sm_options *o, sm_diag *d,
                 sm_model_info *info)
{
    sm_section sec = {7e10, 4e-4, 2e-7, 1.2};
    sm_structure st = {nj, xy, 1, &sec, nm, mem, 0, NULL, clamp};
    sm_model *m;
    int rc = sm_model_new(&m, &st, o, d);
    if (rc == SM_OK) {
        if (info)
            sm_model_get_info(m, info);
        sm_model_free(m);
    }
    return rc;
}

/* Cancel callback: stop once `after` substructures are built; counts calls. */
typedef struct cancel_ctx {
    int after, calls, last_done, last_total;
} cancel_ctx;

static int cancel_cb(void *user, int done, int total)
{
    cancel_ctx *c = user;
    c->calls++;
    c->last_done = done;
    c->last_total = total;
    return done >= c->after;
}

/* sm_model_build: the callback sees every substructure and can stop the build. */
static void build_cancel(void)
{
    double xy[4] = {0, 0, 5, 0};
    sm_member mem = {0, 1, 0, 24};
    sm_section sec = {7e10, 4e-4, 2e-7, 1.2};
    sm_structure st = {2, xy, 1, &sec, 1, &mem, 0, NULL, 0};
    sm_options o;
    sm_default_options(&o);
    o.frames = SM_FRAMES_ELEMENTS_PER_FRAME;
    o.frames_param = 4; /* 6 substructures */
    sm_model *m = (sm_model *)1;
    sm_diag d;
    cancel_ctx c = {2, 0, 0, 0};
    int rc = sm_model_build(&m, &st, &o, cancel_cb, &c, &d);
    TU_CHECK(rc == SM_CANCELED && m == NULL && d.status == SM_CANCELED,
             "a callback returning nonzero stops the build: rc %d", rc);
    TU_CHECK(c.calls == 2 && c.last_done == 2 && c.last_total == 6,
             "asked between substructures: %d calls, last %d/%d", c.calls, c.last_done, c.last_total);
    c = (cancel_ctx){100, 0, 0, 0};
    rc = sm_model_build(&m, &st, &o, cancel_cb, &c, &d);
    TU_CHECK(rc == SM_OK && m && c.calls == 5, "never stopping: the model is built (%d calls)", c.calls);
    sm_model_free(m);
}

int main(void)
{
    build_cancel();
    TU_CHECK(!strcmp(sm_strerror(SM_NOT_CONVERGED), "Newton-Raphson did not converge"), "strerror");
    TU_CHECK(!strcmp(sm_strerror(12345), "unknown status"), "strerror unknown");
    sm_model_free(NULL);
    sm_result_free(NULL);
    sm_options o;
    sm_default_options(&o);
    sm_diag d;
    double xy[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    /* cycle: triangle 0-1-2-0 */
    sm_member tri[3] = {{0, 1, 0, 2}, {1, 2, 0, 2}, {2, 0, 0, 2}};
    TU_CHECK(build(3, xy, 3, tri, 0, &o, &d, NULL) == SM_INVALID_INPUT && d.item == SM_ITEM_MEMBER &&
                 d.item_index == 1,
             "cycle names the member that closes it, 1 (got item %d index %d: %s)", d.item, d.item_index, d.message);
    /* disconnected member 2-3 */
    sm_member dis[2] = {{0, 1, 0, 2}, {2, 3, 0, 2}};
    TU_CHECK(build(4, xy, 2, dis, 0, &o, &d, NULL) == SM_INVALID_INPUT && d.item == SM_ITEM_MEMBER &&
                 d.item_index == 1,
             "disconnected member (got item %d index %d: %s)", d.item, d.item_index, d.message);
    /* zero-length member */
    double xz[4] = {0, 0, 0, 0};
    sm_member zl = {0, 1, 0, 2};
    TU_CHECK(build(2, xz, 1, &zl, 0, &o, &d, NULL) == SM_INVALID_INPUT && d.item == SM_ITEM_MEMBER,
             "zero-length member: %s", d.message);
    /* clamp not on a member */
    sm_member one = {0, 1, 0, 2};
    TU_CHECK(build(3, xy, 1, &one, 2, &o, &d, NULL) == SM_INVALID_INPUT && d.item == SM_ITEM_CLAMP,
             "clamp not on a member: %s", d.message);
    /* bad elements count and bad section property */
    sm_member z0 = {0, 1, 0, 0};
    TU_CHECK(build(2, xy, 1, &z0, 0, &o, &d, NULL) == SM_INVALID_INPUT && !strcmp(d.field, "elements"),
             "elements 0 rejected");
    sm_section bad = {7e10, -1, 2e-7, 1.2};
    sm_structure st = {2, xy, 1, &bad, 1, &one, 0, NULL, 0};
    sm_model *m = NULL;
    TU_CHECK(sm_model_new(&m, &st, &o, &d) == SM_INVALID_INPUT && d.item == SM_ITEM_SECTION && !strcmp(d.field, "A"),
             "negative A names the field");
    /* sizes: angled beam 24+24 */
    tu_angled a;
    tu_angled_beam(&a, 90, 24, 24);
    struct {
        sm_frame_scheme f;
        int p;
        sm_basis b;
        int frames, coords;
    } cases[] = {
        {SM_FRAMES_SINGLE, 1, SM_BASIS_AUGMENTED, 1, 96},     {SM_FRAMES_PER_MEMBER, 8, SM_BASIS_PAPER, 16, 96},
        {SM_FRAMES_PER_MEMBER, 8, SM_BASIS_AUGMENTED, 16, 111}, {SM_FRAMES_PER_ELEMENT, 1, SM_BASIS_AUGMENTED, 48, 143},
        {SM_FRAMES_ELEMENTS_PER_FRAME, 5, SM_BASIS_AUGMENTED, 10, 105},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        sm_model_info in;
        o.frames = cases[i].f;
        o.frames_param = cases[i].p;
        o.basis = cases[i].b;
        TU_CHECK(sm_model_new(&m, &a.st, &o, &d) == SM_OK, "model %zu", i);
        sm_model_get_info(m, &in);
        TU_CHECK(in.nodes == 49 && in.elements == 48 && in.frames == cases[i].frames &&
                     in.coordinates == cases[i].coords,
                 "case %zu: nodes %d elements %d frames %d coords %d (want %d, %d)", i, in.nodes, in.elements,
                 in.frames, in.coordinates, cases[i].frames, cases[i].coords);
        sm_model_free(m);
    }
    /* modes_per_frame truncation keeps attachment columns */
    o.frames = SM_FRAMES_PER_MEMBER;
    o.frames_param = 2;
    o.modes_per_frame = 6;
    TU_CHECK(sm_model_new(&m, &a.st, &o, &d) == SM_OK, "truncated model");
    sm_model_info in;
    sm_model_get_info(m, &in);
    TU_CHECK(in.coordinates == 4 * 6 + 3, "truncated coordinates %d (want 27)", in.coordinates);
    sm_model_free(m);
    /* a branched frame, clamp in the middle: T shape, members given in any direction */
    double tx[8] = {0, 0, 2, 0, -2, 0, 0, 2};
    sm_member tm[3] = {{1, 0, 0, 4}, {0, 2, 0, 4}, {3, 0, 0, 4}};
    sm_default_options(&o);
    sm_model_info ti;
    TU_CHECK(build(4, tx, 3, tm, 0, &o, &d, &ti) == SM_OK, "branched structure: %s", d.message);
    TU_CHECK(ti.nodes == 13 && ti.frames == 12, "branched sizes: nodes %d frames %d", ti.nodes, ti.frames);
    return tu_finish("api");
}
