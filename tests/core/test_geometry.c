/*
 * test_geometry.c — members and elements shorter than the smallest length the numerics carry
 * (issue 23 item 7, DESIGN.md 7.1): 1e-6 of the structure's size (its largest joint coordinate),
 * never below 1e-9 m.  Before, a 1e-15 m spatial member at 0.5 m from the hub solved at ~1e18
 * rad/s with no warning and a 1e-300 m one was told "flap_direction is along the member".
 *
 * Planar and spatial, through sm_structure_check and sm_model_new (which must agree): a chain
 * O-C-P whose second member C-P has length l, the whole structure at 1e-15 m and 1e-300 m, a
 * member just below and just above the bound, and a member long enough whose `elements` make
 * its elements too short.  Every refusal is SM_INVALID_INPUT at the member with the field
 * ("" for the member itself, "elements" for its elements) and the reason in the message.
 */
#include "testutil.h"

/* Two members O(0,0[,0]) - C(x0,0) - P: O-C of e1 elements, C-P of length l along dir, e2. */
typedef struct geo {
    double xy[6], z[3];
    sm_section sec;
    sm_member mem[2];
    sm_structure st;
} geo;

static void geo_make(geo *g, int spatial, double x0, double l, const double dir[3], int e1, int e2)
{
    memset(g, 0, sizeof *g);
    double xy[6] = {0, 0, x0, 0, x0 + l * dir[0], l * dir[1]}, z[3] = {0, 0, l * dir[2]};
    memcpy(g->xy, xy, sizeof xy);
    memcpy(g->z, z, sizeof z);
    if (spatial) {
        g->sec.EA = 2.8e7, g->sec.EI_flap = 1.4e4, g->sec.EI_edge = 5.6e4, g->sec.GJ = 1.3e4;
        g->sec.i_flap = 1e-4, g->sec.i_edge = 4e-4;
    } else {
        g->sec.E = 7e10, g->sec.A = 4e-4, g->sec.I = 2e-7;
    }
    g->sec.mu = 1.2;
    sm_member a = {0, 1, 0, e1}, b = {1, 2, 0, e2};
    g->mem[0] = a, g->mem[1] = b;
    sm_structure st = {3, g->xy, 1, &g->sec, 2, g->mem, 0, NULL, 0, spatial, spatial ? g->z : NULL};
    g->st = st;
}

/* Both entry points refuse st at member `member`, field `field`, with `want` in the message. */
static void refused(const sm_structure *st, int member, const char *field, const char *want,
                    const char *what)
{
    sm_options o;
    sm_default_options(&o);
    sm_model_info info;
    sm_diag cd, md;
    sm_model *m = NULL;
    int crc = sm_structure_check(st, &o, &info, &cd);
    int mrc = sm_model_new(&m, st, &o, &md);
    TU_CHECK(crc == SM_INVALID_INPUT && mrc == SM_INVALID_INPUT, "%s: check %d, model %d", what, crc, mrc);
    TU_CHECK(cd.item == SM_ITEM_MEMBER && cd.item_index == member && !strcmp(cd.field, field),
             "%s: item %d index %d field '%s' (want member %d '%s')", what, (int)cd.item, cd.item_index,
             cd.field, member, field);
    TU_CHECK(strstr(cd.message, "shorter than the smallest length the numerics carry") &&
                 strstr(cd.message, want),
             "%s: message \"%s\" (want \"%s\")", what, cd.message, want);
    TU_CHECK(!strcmp(cd.message, md.message) && cd.item_index == md.item_index &&
                 !strcmp(cd.field, md.field),
             "%s: check and model disagree: \"%s\" / \"%s\"", what, cd.message, md.message);
    printf("ok   %s: %s\n", what, cd.message);
    sm_model_free(m);
}

/* Both entry points accept st, and the model builds (axes and all). */
static void accepted(const sm_structure *st, const char *what)
{
    sm_options o;
    sm_default_options(&o);
    sm_model_info info;
    sm_diag cd, md;
    sm_model *m = NULL;
    int crc = sm_structure_check(st, &o, &info, &cd);
    int mrc = sm_model_new(&m, st, &o, &md);
    TU_CHECK(crc == SM_OK && mrc == SM_OK, "%s: check %d (%s), model %d (%s)", what, crc, cd.message, mrc,
             md.message);
    printf("%s %s accepted\n", crc == SM_OK && mrc == SM_OK ? "ok  " : "FAIL", what);
    sm_model_free(m);
}

static void kind(int spatial)
{
    static const double along_x[3] = {1, 0, 0}, skew[3] = {0, 0.6, 0.8}, along_y[3] = {0, 1, 0};
    const double *dir = spatial ? skew : along_y;
    const char *k = spatial ? "spatial" : "planar";
    char what[96];
    geo g;

    /* size 5 m (the joint C at x = 5): the bound is 5e-6 m */
    geo_make(&g, spatial, 5, 1e-15, dir, 8, 1);
    snprintf(what, sizeof what, "%s 1e-15 m member in a 5 m structure", k);
    refused(&g.st, 1, "", "1e-06 of the structure's size 5 m", what);
    geo_make(&g, spatial, 5, 4.9e-6, dir, 8, 1);
    snprintf(what, sizeof what, "%s 4.9e-6 m member in a 5 m structure", k);
    refused(&g.st, 1, "", "the member is 4.9e-06 m long", what);
    geo_make(&g, spatial, 5, 5.1e-6, dir, 8, 1);
    snprintf(what, sizeof what, "%s 5.1e-6 m member (just above 1e-6 of 5 m)", k);
    accepted(&g.st, what);

    /* the 1e-300 m member: this reason, not "flap_direction is along the member" */
    geo_make(&g, spatial, 5, 1e-300, dir, 8, 1);
    snprintf(what, sizeof what, "%s 1e-300 m member in a 5 m structure", k);
    refused(&g.st, 1, "", "the member is 1e-300 m long", what);

    /* the whole structure tiny: the absolute floor 1e-9 m */
    for (int e = 15; e <= 300; e += 285) {
        double l = e == 15 ? 1e-15 : 1e-300;
        geo_make(&g, spatial, l, l, along_x, 1, 1);
        snprintf(what, sizeof what, "%s structure of two 1e-%d m members", k, e);
        refused(&g.st, 0, "", "(1e-09 m)", what);
    }
    geo_make(&g, spatial, 2e-9, 2e-9, along_x, 2, 2);
    snprintf(what, sizeof what, "%s structure of two 2e-9 m members of two elements", k);
    accepted(&g.st, what);

    /* a member of 1.001 mm is fine (2e-4 of 5 m), 400 elements on it are not (2.5e-6 m < 5e-6 m) */
    geo_make(&g, spatial, 5, 1.001e-3, dir, 8, 400);
    snprintf(what, sizeof what, "%s 1.001 mm member of 400 elements", k);
    refused(&g.st, 1, "elements", "use at most 200 elements", what);
    geo_make(&g, spatial, 5, 1.001e-3, dir, 8, 200);
    snprintf(what, sizeof what, "%s 1.001 mm member of 200 elements", k);
    accepted(&g.st, what);
}

int main(void)
{
    kind(0);
    kind(1);
    return tu_finish("geometry");
}
