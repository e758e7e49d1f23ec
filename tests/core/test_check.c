/*
 * test_check.c — sm_structure_check against sm_model_new.
 *
 * For the example structures (the JSON files in examples/: angled beam 24+24, straight
 * blade with a tip mass), a branched tree with a member pointing towards the
 * clamp and a clamp in the middle of a structure, under every frame scheme
 * (several parameters, including more runs than elements), both bases, both
 * mass models and several modes_per_frame: the predicted sizes equal
 * sm_model_get_info of the built model, field by field.  For invalid inputs
 * (cycle, disconnected member, zero-length member, bad section values,
 * unknown joints and sections, bad options, no structure) both return the
 * same status and an identical diag.  Last, a chain of 200000 one-element
 * members is checked (the walk must be linear: a scan of every member per
 * joint would take minutes).
 */
#include "testutil.h"

#include <time.h>

typedef struct shape {
    const char *name;
    int nj;
    const double *xy;
    int ns;
    const sm_section *sec;
    int nm;
    const sm_member *mem;
    int npm;
    const sm_point_mass *pm;
    int clamp;
} shape;

static sm_structure shape_structure(const shape *s)
{
    sm_structure st = {s->nj, s->xy, s->ns, s->sec, s->nm, s->mem, s->npm, s->pm, s->clamp};
    return st;
}

static int info_equal(const sm_model_info *a, const sm_model_info *b)
{
    return a->nodes == b->nodes && a->elements == b->elements && a->frames == b->frames &&
           a->coordinates == b->coordinates && a->max_frame_coordinates == b->max_frame_coordinates &&
           a->max_frame_nodes == b->max_frame_nodes;
}

/* sm_structure_check sizes == sm_model_get_info of the built model. */
static void same_sizes(const shape *s, const sm_options *o, const char *what)
{
    sm_structure st = shape_structure(s);
    sm_model_info ci, mi;
    sm_diag cd, md;
    sm_model *m = NULL;
    memset(&ci, 0xff, sizeof ci);
    memset(&mi, 0xff, sizeof mi);
    int crc = sm_structure_check(&st, o, &ci, &cd);
    int mrc = sm_model_new(&m, &st, o, &md);
    TU_CHECK(crc == SM_OK && mrc == SM_OK, "%s %s: check %d, model %d (%s)", s->name, what, crc, mrc, md.message);
    if (mrc == SM_OK) {
        sm_model_get_info(m, &mi);
        TU_CHECK(info_equal(&ci, &mi),
                 "%s %s: check nodes %d elements %d frames %d n %d max m %d max nodes %d; model %d %d %d %d %d %d",
                 s->name, what, ci.nodes, ci.elements, ci.frames, ci.coordinates, ci.max_frame_coordinates,
                 ci.max_frame_nodes, mi.nodes, mi.elements, mi.frames, mi.coordinates, mi.max_frame_coordinates,
                 mi.max_frame_nodes);
    }
    sm_model_free(m);
}

static void sizes(const shape *s)
{
    static const struct {
        sm_frame_scheme f;
        int p;
    } schemes[] = {
        {SM_FRAMES_SINGLE, 0},          {SM_FRAMES_PER_MEMBER, 1},         {SM_FRAMES_PER_MEMBER, 3},
        {SM_FRAMES_PER_MEMBER, 8},      {SM_FRAMES_PER_MEMBER, 1000},      {SM_FRAMES_ELEMENTS_PER_FRAME, 1},
        {SM_FRAMES_ELEMENTS_PER_FRAME, 5}, {SM_FRAMES_ELEMENTS_PER_FRAME, 7}, {SM_FRAMES_PER_ELEMENT, 0},
    };
    static const int mpf[] = {0, 1, 3, 1000};
    int before = tu_failures;
    for (size_t f = 0; f < sizeof schemes / sizeof schemes[0]; f++)
        for (int basis = 0; basis < 2; basis++)
            for (int mass = 0; mass < 2; mass++)
                for (size_t k = 0; k < sizeof mpf / sizeof mpf[0]; k++) {
                    sm_options o;
                    char what[128];
                    sm_default_options(&o);
                    o.frames = schemes[f].f;
                    o.frames_param = schemes[f].p;
                    o.basis = basis ? SM_BASIS_PAPER : SM_BASIS_AUGMENTED;
                    o.mass = mass ? SM_MASS_CONSISTENT : SM_MASS_LUMPED;
                    o.modes_per_frame = mpf[k];
                    snprintf(what, sizeof what, "frames %d/%d %s %s modes_per_frame %d", (int)o.frames,
                             o.frames_param, basis ? "paper" : "augmented", mass ? "consistent" : "lumped",
                             o.modes_per_frame);
                    same_sizes(s, &o, what);
                }
    same_sizes(s, NULL, "default options (NULL)");
    printf("%s: sizes %s\n", s->name, tu_failures == before ? "agree" : "DIFFER");
}

/* Both functions fail the same way, with identical diagnostics. */
static void same_error(const sm_structure *st, const sm_options *o, const char *what)
{
    sm_diag cd, md;
    sm_model_info ci;
    sm_model *m = NULL;
    memset(&cd, 0x5a, sizeof cd);
    memset(&md, 0xa5, sizeof md);
    int crc = sm_structure_check(st, o, &ci, &cd);
    int mrc = sm_model_new(&m, st, o, &md);
    printf("%-40s check %d model %d: item %d index %d field \"%s\": %s\n", what, crc, mrc, cd.item,
           cd.item_index, cd.field, cd.message);
    TU_CHECK(crc == SM_INVALID_INPUT && mrc == SM_INVALID_INPUT && !m, "%s: both SM_INVALID_INPUT", what);
    TU_CHECK(cd.status == md.status && cd.item == md.item && cd.item_index == md.item_index &&
                 !strcmp(cd.field, md.field) && !strcmp(cd.message, md.message) &&
                 cd.iterations == md.iterations && cd.residual == md.residual && cd.last_omega == md.last_omega,
             "%s: identical diag", what);
    TU_CHECK(cd.message[0] != '\0', "%s: a message", what);
    TU_CHECK(sm_structure_check(st, o, NULL, NULL) == crc, "%s: info and diag may be NULL", what);
    sm_model_free(m);
}

static void errors(void)
{
    double xy[10] = {0, 0, 1, 0, 1, 1, 0, 1, 2, 2};
    sm_section sec = {7e10, 4e-4, 2e-7, 1.2};
    sm_member tri[3] = {{0, 1, 0, 2}, {1, 2, 0, 2}, {2, 0, 0, 2}};
    sm_structure st = {3, xy, 1, &sec, 3, tri, 0, NULL, 0};
    sm_options o;
    sm_default_options(&o);
    same_error(&st, &o, "cycle");
    sm_member dis[2] = {{0, 1, 0, 2}, {2, 3, 0, 2}};
    st = (sm_structure){4, xy, 1, &sec, 2, dis, 0, NULL, 0};
    same_error(&st, &o, "disconnected member");
    double xz[4] = {1, 1, 1, 1};
    sm_member one = {0, 1, 0, 2};
    st = (sm_structure){2, xz, 1, &sec, 1, &one, 0, NULL, 0};
    same_error(&st, &o, "zero-length member");
    sm_member self = {1, 1, 0, 2};
    st = (sm_structure){2, xy, 1, &sec, 1, &self, 0, NULL, 0};
    same_error(&st, &o, "member from a joint to itself");
    st = (sm_structure){3, xy, 1, &sec, 1, &one, 0, NULL, 0};
    same_error(&st, &o, "joint on no member");
    st = (sm_structure){3, xy, 1, &sec, 1, &one, 0, NULL, 2};
    same_error(&st, &o, "clamp on no member");
    st = (sm_structure){2, xy, 1, &sec, 1, &one, 0, NULL, 5};
    same_error(&st, &o, "clamp not a joint");
    const double bad[] = {0.0, -1.0, NAN, INFINITY};
    for (int field = 0; field < 4; field++)
        for (size_t v = 0; v < sizeof bad / sizeof bad[0]; v++) {
            sm_section b = sec;
            double *p = field == 0 ? &b.E : field == 1 ? &b.A : field == 2 ? &b.I : &b.mu;
            char what[64];
            *p = bad[v];
            snprintf(what, sizeof what, "section field %d = %g", field, bad[v]);
            st = (sm_structure){2, xy, 1, &b, 1, &one, 0, NULL, 0};
            same_error(&st, &o, what);
        }
    double xnan[4] = {0, 0, NAN, 0};
    st = (sm_structure){2, xnan, 1, &sec, 1, &one, 0, NULL, 0};
    same_error(&st, &o, "joint coordinate NaN");
    sm_member unk[4] = {{0, 7, 0, 2}, {-1, 1, 0, 2}, {0, 1, 3, 2}, {0, 1, 0, 0}};
    const char *unk_what[4] = {"unknown joint (to)", "unknown joint (from)", "unknown section", "zero elements"};
    for (int i = 0; i < 4; i++) {
        st = (sm_structure){2, xy, 1, &sec, 1, &unk[i], 0, NULL, 0};
        same_error(&st, &o, unk_what[i]);
    }
    sm_point_mass pm[2] = {{1, 0.5}, {9, 0.5}};
    st = (sm_structure){2, xy, 1, &sec, 1, &one, 2, pm, 0};
    same_error(&st, &o, "point mass on an unknown joint");
    pm[1] = (sm_point_mass){1, -2};
    same_error(&st, &o, "negative point mass");
    st = (sm_structure){0, xy, 1, &sec, 1, &one, 0, NULL, 0};
    same_error(&st, &o, "no joints");
    st = (sm_structure){2, xy, 1, &sec, 0, NULL, 0, NULL, 0};
    same_error(&st, &o, "no members");
    st = (sm_structure){2, xy, 0, NULL, 1, &one, 0, NULL, 0};
    same_error(&st, &o, "no sections");
    same_error(NULL, &o, "no structure");
    st = (sm_structure){2, xy, 1, &sec, 1, &one, 0, NULL, 0};
    sm_options ob = o;
    ob.modes = 0;
    same_error(&st, &ob, "modes 0");
    ob = o;
    ob.frames = SM_FRAMES_PER_MEMBER;
    ob.frames_param = 0;
    same_error(&st, &ob, "per_member 0");
    ob = o;
    ob.frames = (sm_frame_scheme)99;
    same_error(&st, &ob, "unknown frame scheme");
    ob = o;
    ob.modes_per_frame = -1;
    same_error(&st, &ob, "modes_per_frame -1");
}

/* A chain of n one-element members, per-element frames: n nodes + clamp, 3n - 1 coordinates. */
static void long_chain(int n)
{
    double *xy = malloc(2 * (size_t)(n + 1) * sizeof(double));
    sm_member *mem = calloc((size_t)n, sizeof(sm_member));
    sm_section sec = {7e10, 4e-4, 2e-7, 1.2};
    if (!xy || !mem) {
        TU_CHECK(0, "alloc");
        free(xy);
        free(mem);
        return;
    }
    for (int j = 0; j <= n; j++) {
        xy[2 * j] = 0.01 * j;
        xy[2 * j + 1] = 0;
    }
    for (int i = 0; i < n; i++) /* listed from the tip: every member found late in a scan */
        mem[i] = (sm_member){n - i, n - i - 1, 0, 1};
    sm_structure st = {n + 1, xy, 1, &sec, n, mem, 0, NULL, 0};
    sm_options o;
    sm_default_options(&o);
    sm_model_info info;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int rc = sm_structure_check(&st, &o, &info, NULL);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double ms = 1e3 * (double)(t1.tv_sec - t0.tv_sec) + 1e-6 * (double)(t1.tv_nsec - t0.tv_nsec);
    printf("chain of %d members checked in %.1f ms\n", n, ms);
    TU_CHECK(rc == SM_OK && info.nodes == n + 1 && info.elements == n && info.frames == n &&
                 info.coordinates == 3 * n - 1 && info.max_frame_coordinates == 3 && info.max_frame_nodes == 1,
             "chain sizes: rc %d nodes %d elements %d frames %d n %d", rc, info.nodes, info.elements, info.frames,
             info.coordinates);
    free(xy);
    free(mem);
}

int main(void)
{
    const double s2 = sqrt(0.5);
    /* examples/angled-beam-90.json */
    const double ab_xy[6] = {0, 0, 5, 0, 5, 5};
    const sm_section al = {7e10, 4e-4, 2e-7, 1.2};
    const sm_member ab_mem[2] = {{0, 1, 0, 24}, {1, 2, 0, 24}};
    /* examples/straight-blade.json */
    const double bl_xy[4] = {0.5, 0, 5.5, 0};
    const sm_member bl_mem[1] = {{0, 1, 0, 24}};
    const sm_point_mass bl_pm[1] = {{1, 0.2}};
    /* a branched tree: a root member, then three branches at joint 1 (one listed towards the
     * clamp), one of them forking again; two sections, point masses on a branch and a tip */
    const double tr_xy[14] = {0, 0, 2, 0, 3, 1, 3, -1, 4, 0, 4, 2, 2 + s2, s2};
    const sm_section tr_sec[2] = {{7e10, 4e-4, 2e-7, 1.2}, {2e11, 1e-4, 1e-8, 0.8}};
    const sm_member tr_mem[6] = {{0, 1, 0, 6}, {1, 2, 1, 3}, {3, 1, 1, 4}, {1, 4, 0, 5}, {2, 5, 1, 2},
                                 {2, 6, 0, 3}};
    const sm_point_mass tr_pm[2] = {{2, 0.1}, {5, 0.3}};
    /* clamp in the middle: two arms from the clamp joint */
    const double mid_xy[6] = {-3, 0, 0, 0, 0, 4};
    const sm_member mid_mem[2] = {{0, 1, 0, 7}, {1, 2, 0, 5}};
    const shape shapes[] = {
        {"angled-beam-90", 3, ab_xy, 1, &al, 2, ab_mem, 0, NULL, 0},
        {"straight-blade", 2, bl_xy, 1, &al, 1, bl_mem, 1, bl_pm, 0},
        {"branched tree", 7, tr_xy, 2, tr_sec, 6, tr_mem, 2, tr_pm, 0},
        {"clamp in the middle", 3, mid_xy, 1, &al, 2, mid_mem, 0, NULL, 1},
    };
    for (size_t i = 0; i < sizeof shapes / sizeof shapes[0]; i++)
        sizes(&shapes[i]);
    errors();
    long_chain(200000);
    return tu_finish("check");
}
