/*
 * tower.c — the "tower" form of a request, expanded to a spatial structure (DESIGN.md 8.5).
 *
 * How it fits: a request gives exactly one of "structure", "blade" and
 * "tower".  For a tower, validate.c calls tower_validate: the tower's own
 * fields (height, base_height, elements, top_mass, gravity) are checked
 * here, then the tower is expanded into the structure it stands for and
 * that structure goes through the ordinary checks of validate.c (section,
 * stations, point mass), with every error pointer moved back into /tower
 * (tower_pointer).  The canonical request keeps the tower as given (its
 * defaults written out); the expanded structure is what request.c turns
 * into the core's arrays.  A tower does not spin: tower_check_speeds
 * refuses a speed other than 0 (validate.c calls it after the analysis).
 *
 * Tower axes (fa, ss, up), right-handed like BModes' tower (x, y, z) and
 * ElastoDyn's (xt, yt, zt): fa fore-aft, downwind along the rotor's spin
 * axis; ss side-side, horizontal, to the left looking downwind; up along
 * the tower.  In the hub frame (spin axis z, which a later rotor-on-tower
 * model keeps): fa = z, ss = x, up = y.  Joints base = base_height up and
 * top = height up; one member "tower" with flap_direction fa, so the
 * core's flap (e3) is fore-aft and its edge (e2 = e3 x e1 = -ss) side-side:
 * the energy labels "flap"/"edge" of a tower mode are fore-aft/side-side
 * motion.  The clamp at base; the top mass at top, its offset and inertia
 * tensor given in tower axes and turned into hub axes (I_hub = T I T^T,
 * T = [fa ss up] in hub components).
 *
 * "wires" and "foundation" are elastic supports (DESIGN.md 8.6); "platform" (a floating or
 * elastic base: 6x6 matrices in tower axes) is platform.c's plat_tower, which writes the
 * structure's "clamp": null and "platform" in hub axes.  "gravity": true is the structure's
 * "gravity" [0, -9.80665, 0] (DESIGN.md 8.8).
 */
#include "codec_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Where the expanded structure's pointers go in the tower (longest prefix first). */
static const struct {
    const char *from, *to;
} tower_map[] = {
    {"/structure/springs", "/tower/wires"},
    {"/structure/members/0/foundation", "/tower/foundation"},
    {"/structure/members/0/stations", "/tower/stations"},
    {"/structure/members/0/elements", "/tower/elements"},
    {"/structure/members/0", "/tower"},
    {"/structure/sections/tower", "/tower/section"},
    {"/structure/sections", "/tower/section"},
    {"/structure/point_masses/0", "/tower/top_mass"},
    {"/structure/gravity", "/tower/gravity"},
    {"/structure/joints", "/tower/height"},
    {"/structure/platform", "/tower/platform"},
    {"/structure/clamp", "/tower/platform"},
    {"/structure/members", "/tower"}, /* a piece between wires (tower_split) */
    {"/structure", "/tower"},
};

char *tower_pointer(const char *p)
{
    size_t k, n;

    for (k = 0; k < sizeof(tower_map) / sizeof(tower_map[0]); k++) {
        n = strlen(tower_map[k].from);
        if (!strncmp(p, tower_map[k].from, n) && (p[n] == '\0' || p[n] == '/'))
            return err_fmt("%s%s", tower_map[k].to, p + n);
    }
    return strdup(p);
}

int tower_form(const json_t *canon)
{
    if (json_object_get(canon, "tower"))
        return CODEC_FORM_TOWER;
    return json_object_get(canon, "blade") ? CODEC_FORM_BLADE : CODEC_FORM_STRUCTURE;
}

char *tower_form_pointer(int form, const char *p)
{
    if (form == CODEC_FORM_TOWER)
        return tower_pointer(p);
    return form == CODEC_FORM_BLADE ? blade_pointer(p) : strdup(p);
}

/* T: the tower axes fa, ss, up as the columns, in hub components (row i = hub axis i). */
/* The top mass's vectors in tower axes, as the messages name their components. */
static const char *const tower_top_shapes[3] = {
    "[fore-aft, side-side, axial]", "[I_fa, I_ss, I_axial]", "[I_fa_ss, I_ss_axial, I_axial_fa]"};

static const double tower_T[3][3] = {{0, 1, 0},  /* hub x: ss */
                                     {0, 0, 1},  /* hub y: up */
                                     {1, 0, 0}}; /* hub z: fa */

/* Standard gravity, m/s^2 (CGPM 1901): a tower's "gravity": true is this along -up. */
#define TOWER_G 9.80665

/* "gravity": false (default) or true: the weight of the tower and its top mass as a steady load
 * (DESIGN.md 8.8), the expanded structure's "gravity" [0, -g, 0] (up = hub y). */
static void tower_gravity(val_ctx *v, const json_t *tw, json_t *ct)
{
    field_bool(v, tw, "gravity", "/tower", ct, 0);
}

/* Most wires and foundation stretches of a tower. */
#define TOWER_MAX_SUP 64

/* A tower's wires and foundation stretches as checked (tower_supports), for tower_split. */
typedef struct tower_sup {
    int nw;                   /* wires */
    double wh[TOWER_MAX_SUP]; /* attachment height above ground, m */
    double wk[TOWER_MAX_SUP]; /* lateral spring in each of fa, ss: count k cos^2, N/m */
    int nf;                   /* foundation stretches */
    double f0[TOWER_MAX_SUP], f1[TOWER_MAX_SUP]; /* from_height, to_height, m above ground */
    double fk[TOWER_MAX_SUP][4]; /* axial, fore-aft, side-side, torsion per length */
    double fm[TOWER_MAX_SUP];    /* added mass per length, kg/m */
} tower_sup;

/*
 * Wire w at p: {height (m above ground, base_height < height <= the tower's), count (>= 1),
 * stiffness (N/m, one wire), angle_deg (between wire and tower, 0..90)} into canonical c and
 * s: BModes' lateral spring count stiffness cos^2(angle) in each of fore-aft and side-side
 * (BModes.f90:607-611, BldVib.f90:667-674).  1 when valid.
 */
static int tower_wire(val_ctx *v, const json_t *w, const char *p, const double g[3], json_t *c,
                      tower_sup *s)
{
    static const char *const keys[] = {"height", "count", "stiffness", "angle_deg", NULL};
    double h = 0, k = 0, a = 0, cs;
    long n = 0;
    int ok;

    if (!json_is_object(w)) {
        field_error(v, p, "must be an object {height, count, stiffness, angle_deg}, not %s",
                    field_type_name(w));
        return 0;
    }
    field_check_keys(v, w, p, keys, "wire");
    ok = field_real(v, w, "height", p, c, FIELD_POSITIVE, " (m)", &h);
    ok &= field_int(v, w, "count", p, c, 1, 0, 1, 1000, NULL, &n);
    ok &= field_real(v, w, "stiffness", p, c, FIELD_NONNEG, " (N/m)", &k);
    ok &= field_real(v, w, "angle_deg", p, c, FIELD_NONNEG, " (deg)", &a);
    if (ok && a > 90) {
        field_error_key(v, p, "angle_deg", "must be 0 to 90 degrees from the tower, got %g", a);
        ok = 0;
    }
    if (ok && !(h > g[1] && h <= g[0])) {
        field_error_key(v, p, "height",
                        "the wires attach at %g m, outside the flexible tower (above "
                        "base_height %g m, up to height %g m)",
                        h, g[1], g[0]);
        ok = 0;
    }
    if (!ok)
        return 0;
    cs = cos(a * CODEC_RAD_PER_DEG);
    s->wh[s->nw] = h;
    s->wk[s->nw++] = (double)n * k * cs * cs;
    return 1;
}

/* f's stiffness_per_length at p: four numbers >= 0 into k and canonical c; 1 when valid. */
static int tower_k4(val_ctx *v, const json_t *f, const char *p, json_t *c, double k[4])
{
    const json_t *x = json_object_get(f, "stiffness_per_length");
    int i, ok = 1;

    if (!json_is_array(x) || json_array_size(x) != 4) {
        field_error_key(v, p, "stiffness_per_length",
                        "must be [k_axial, k_fore_aft, k_side_side, "
                        "k_torsion] (N/m per m, N m/rad per m), not %s",
                        field_type_name(x));
        return 0;
    }
    for (i = 0; i < 4; i++) {
        char *pk = err_fmt("%s/stiffness_per_length/%d", p, i);
        ok &= pk && field_check_real(v, json_array_get(x, (size_t)i), pk, FIELD_NONNEG,
                                     i == 3 ? " (N m/rad per m)" : " (N/m per m)", &k[i]);
        v->nomem |= !pk;
        free(pk);
    }
    if (ok)
        field_set(v, c, "stiffness_per_length", field_reals(k, 4));
    return ok;
}

/* Foundation stretch f at p: {from_height, to_height, stiffness_per_length [axial, fore-aft,
 * side-side, torsion], added_mass_per_length} into canonical c and s; 1 when valid. */
static int tower_stretch(val_ctx *v, const json_t *f, const char *p, const double g[3], json_t *c,
                         tower_sup *s)
{
    static const char *const keys[] = {"from_height", "to_height", "stiffness_per_length",
                                       "added_mass_per_length", NULL};
    double h0 = g[1], h1 = g[0], k[4] = {0, 0, 0, 0}, m = 0;
    int ok = 1;

    if (!json_is_object(f)) {
        field_error(v, p,
                    "must be an object {stiffness_per_length [, added_mass_per_length, "
                    "from_height, to_height]}, not %s",
                    field_type_name(f));
        return 0;
    }
    field_check_keys(v, f, p, keys, "tower foundation");
    if (json_object_get(f, "from_height"))
        ok &= field_real(v, f, "from_height", p, c, FIELD_NONNEG, " (m)", &h0);
    else
        field_set(v, c, "from_height", json_real(h0));
    if (json_object_get(f, "to_height"))
        ok &= field_real(v, f, "to_height", p, c, FIELD_NONNEG, " (m)", &h1);
    else
        field_set(v, c, "to_height", json_real(h1));
    if (!json_object_get(f, "stiffness_per_length"))
        field_set(v, c, "stiffness_per_length", field_reals(k, 4));
    else
        ok &= tower_k4(v, f, p, c, k);
    if (json_object_get(f, "added_mass_per_length"))
        ok &= field_real(v, f, "added_mass_per_length", p, c, FIELD_NONNEG, " (kg/m)", &m);
    else
        field_set(v, c, "added_mass_per_length", json_real(0.0));
    if (ok && !(g[1] <= h0 && h0 < h1 && h1 <= g[0])) {
        field_error(v, p,
                    "the stretch %g to %g m must lie on the flexible tower (base_height %g "
                    "m to height %g m) and start below its end",
                    h0, h1, g[1], g[0]);
        ok = 0;
    }
    if (!ok)
        return 0;
    s->f0[s->nf] = h0;
    s->f1[s->nf] = h1;
    memcpy(s->fk[s->nf], k, sizeof k);
    s->fm[s->nf++] = m;
    return 1;
}

/* An object or array of them at tw[key]: each through one (wire or stretch) into ct[key]. */
static void tower_list(val_ctx *v, const json_t *tw, const char *key, json_t *ct, const double g[3],
                       tower_sup *s,
                       int (*one)(val_ctx *, const json_t *, const char *, const double *, json_t *,
                                  tower_sup *))
{
    const json_t *x = json_object_get(tw, key), *e;
    char *base = err_ptr_key("/tower", key), *p;
    json_t *arr = json_array(), *c;
    size_t i, n = json_is_array(x) ? json_array_size(x) : 1;

    if (!base || !arr) {
        v->nomem = 1;
        goto done;
    }
    if (!json_is_array(x) || n == 0 || n > TOWER_MAX_SUP) {
        field_error(v, base, "must be an array of 1 to %d objects, not %s", TOWER_MAX_SUP,
                    json_is_array(x) ? "that many" : field_type_name(x));
        goto done;
    }
    json_array_foreach(x, i, e) {
        p = err_ptr_idx(base, i);
        c = json_object();
        if (!p || !c || json_array_append_new(arr, c)) {
            v->nomem = 1;
            free(p);
            break;
        }
        one(v, e, p, g, c, s);
        free(p);
    }
    field_set(v, ct, key, arr);
    arr = NULL;
done:
    json_decref(arr);
    free(base);
}

/* The tower's wires and foundation (optional) into ct and s. */
static void tower_supports(val_ctx *v, const json_t *tw, json_t *ct, const double g[3],
                           tower_sup *s)
{
    memset(s, 0, sizeof *s);
    if (json_object_get(tw, "wires"))
        tower_list(v, tw, "wires", ct, g, s, tower_wire);
    if (json_object_get(tw, "foundation"))
        tower_list(v, tw, "foundation", ct, g, s, tower_stretch);
}

/* The tower's scalar fields into ct; g = height, base_height, elements. */
static void tower_scalars(val_ctx *v, const json_t *tw, json_t *ct, double g[3])
{
    long el = 48;

    if (!field_real(v, tw, "height", "/tower", ct, FIELD_POSITIVE, " (m)", &g[0]))
        g[0] = 1; /* still check the section and stations */
    g[1] = 0;
    if (!json_object_get(tw, "base_height"))
        field_set(v, ct, "base_height", json_real(0.0));
    else if (!field_real(v, tw, "base_height", "/tower", ct, FIELD_NONNEG, " (m)", &g[1]))
        g[1] = 0;
    if (!(g[1] < g[0])) {
        field_error(v, "/tower/base_height",
                    "the rigid base (%g m) must be lower than the "
                    "tower's height (%g m): the flexible tower runs from base_height to height",
                    g[1], g[0]);
        g[1] = 0;
    }
    field_int(v, tw, "elements", "/tower", ct, 0, 48, 1, v->lim->max_elements,
              "the number of elements", &el);
    g[2] = (double)el;
}

/*
 * The structure a tower stands for, in request form (new): g the scalars, t
 * the top mass (mass, offset, inertia, products in tower axes) or NULL.
 */
static json_t *tower_structure(const json_t *tw, const double g[3], const double *t)
{
    static const double fa[3] = {0, 0, 1};
    const json_t *sec = json_object_get(tw, "section"), *sts = json_object_get(tw, "stations");
    double base[3] = {0, g[1], 0}, top[3] = {0, g[0], 0}, off[3], hd[3], hp[3];
    json_t *st, *mem;

    mem = json_pack("{s:s, s:s, s:s, s:s, s:I, s:f, s:o}", "id", "tower", "from", "base", "to",
                    "top", "section", "tower", "elements", (json_int_t)g[2], "twist_deg", 0.0,
                    "flap_direction", field_reals(fa, 3));
    if (mem && sts && json_object_set(mem, "stations", (json_t *)sts)) {
        json_decref(mem);
        return NULL;
    }
    st = json_pack("{s:{s:o, s:o}, s:{s:o}, s:[o], s:s, s:[]}", "joints", "base",
                   field_reals(base, 3), "top", field_reals(top, 3), "sections", "tower",
                   sec ? json_incref((json_t *)sec) : json_object(), "members", mem, "clamp",
                   "base", "point_masses");
    if (st && t) {
        blade_rotate(&tower_T[0][0], t + 1, off); /* off = T o */
        blade_tensor(&tower_T[0][0], t + 4, t + 7, hd, hp);
        if (json_array_append_new(json_object_get(st, "point_masses"),
                                  json_pack("{s:s, s:f, s:o, s:o, s:o}", "joint", "top", "mass",
                                            t[0], "offset", field_reals(off, 3), "inertia",
                                            field_reals(hd, 3), "products", field_reals(hp, 3)))) {
            json_decref(st);
            return NULL;
        }
    }
    return st;
}

/*
 * Check the expanded structure st (borrowed) with the ordinary walk, the
 * errors moved into /tower; returns its canonical copy (new) or NULL.
 */
static json_t *tower_check_structure(val_ctx *v, json_t *st)
{
    codec_errors *mine = codec_errors_new(), *saved = v->errs;
    json_t *root = json_pack("{s:O}", "structure", st), *canon = json_object(), *cst = NULL;
    int i;

    if (!mine || !root || !canon) {
        v->nomem = 1;
        goto done;
    }
    v->errs = mine;
    v->blade = 1; /* a section without E, A, I is spatial, as for a blade */
    val_structure(v, root, canon);
    v->blade = 0;
    v->errs = saved;
    for (i = 0; i < codec_errors_count(mine); i++) {
        char *p = tower_pointer(codec_errors_pointer(mine, i));
        field_error(v, p, "%s", codec_errors_message(mine, i));
        free(p);
    }
    cst = json_incref(json_object_get(canon, "structure"));
done:
    codec_errors_free(mine);
    json_decref(root);
    json_decref(canon);
    return cst;
}

static int tower_split(val_ctx *v, json_t *cst, const double g[3], const tower_sup *s);

json_t *tower_validate(val_ctx *v, const json_t *root, json_t *canon)
{
    static const char *const keys[] = {"height",     "base_height", "elements", "section",
                                       "stations",   "top_mass",    "gravity",  "wires",
                                       "foundation", "platform",    NULL};
    const json_t *tw = json_object_get(root, "tower"), *tm, *sec, *mem;
    json_t *ct, *st, *cst = NULL;
    double g[3], t[10];
    int top_ok = 0, nerr = codec_errors_count(v->errs);
    tower_sup sup;

    if (!json_is_object(tw)) {
        field_error(v, "/tower",
                    "must be an object {height, [base_height, elements,] section "
                    "and/or stations [, top_mass]}, not %s",
                    field_type_name(tw));
        return NULL;
    }
    if (!(ct = json_object())) {
        v->nomem = 1;
        return NULL;
    }
    field_check_keys(v, tw, "/tower", keys, "tower");
    tower_scalars(v, tw, ct, g);
    tower_gravity(v, tw, ct);
    tower_supports(v, tw, ct, g, &sup);
    if ((tm = json_object_get(tw, "top_mass")))
        top_ok = blade_point_mass(v, tm, ct, "top_mass", "/tower/top_mass", "top mass",
                                  tower_top_shapes, t);
    if (json_object_get(tw, "section") &&
        sec_classify_as(json_object_get(tw, "section"), 1) == SEC_PLANAR) {
        field_error(v, "/tower/section",
                    "a tower is spatial, and this section is %s: give it "
                    "as EA, EI_flap (fore-aft), EI_edge (side-side), GJ and mass_per_length (or "
                    "E, G, A, I_flap, I_edge, J and mass_per_length)",
                    sec_form_name(SEC_PLANAR));
        field_set(v, canon, "tower", ct);
        return NULL;
    }
    st = tower_structure(tw, g, top_ok ? t : NULL);
    if (st && json_is_true(json_object_get(tw, "gravity")) &&
        json_object_set_new(st, "gravity", json_pack("[f, f, f]", 0.0, -TOWER_G, 0.0)))
        v->nomem = 1;
    if (!st)
        v->nomem = 1;
    plat_tower(v, tw, ct, st, tower_T, g[1]);
    if (st)
        cst = tower_check_structure(v, st);
    json_decref(st);
    mem = json_array_get(json_object_get(cst, "members"), 0);
    sec = json_object_get(json_object_get(cst, "sections"), "tower");
    if (json_object_get(tw, "section") && sec)
        field_set(v, ct, "section", json_deep_copy(sec));
    if (json_object_get(tw, "stations") && json_object_get(mem, "stations"))
        field_set(v, ct, "stations", json_deep_copy(json_object_get(mem, "stations")));
    field_set(v, canon, "tower", ct);
    if (cst && codec_errors_count(v->errs) == nerr && tower_split(v, cst, g, &sup)) {
        json_decref(cst);
        cst = NULL;
    }
    return cst;
}

void tower_check_speeds(val_ctx *v, const json_t *canon, const char *why, const char *tail)
{
    const json_t *an = json_object_get(canon, "analysis");
    const char *key = json_object_get(an, "rpm") ? "rpm" : "omega";
    size_t n = spd_count(an), i;
    double *om, *rpm;

    if (!json_object_get(an, key) || !n)
        return;
    om = malloc(n * sizeof(double));
    rpm = malloc(n * sizeof(double));
    if (!om || !rpm) {
        v->nomem = 1;
        goto done;
    }
    spd_fill(an, om, rpm);
    for (i = 0; i < n; i++)
        if (om[i] != 0) {
            char *p = err_ptr_key("/analysis", key);
            field_error(v, p, "%s: its speed must be 0 (speed %zu is %g %s)%s", why, i + 1,
                        !strcmp(key, "rpm") ? rpm[i] : om[i], !strcmp(key, "rpm") ? "rpm" : "rad/s",
                        tail);
            free(p);
            break;
        }
done:
    free(om);
    free(rpm);
}

/* x linear between a and b at f (numbers, or arrays of numbers element by element); new. */
static json_t *tower_lerp(const json_t *a, const json_t *b, double f)
{
    json_t *o;
    size_t i;

    if (!json_is_array(a))
        return json_real(json_number_value(a) + f * (json_number_value(b) - json_number_value(a)));
    o = json_array();
    for (i = 0; o && i < json_array_size(a); i++)
        if (json_array_append_new(o, tower_lerp(json_array_get(a, i), json_array_get(b, i), f))) {
            json_decref(o);
            return NULL;
        }
    return o;
}

/* The station of the canonical stations sts at fraction x (linear, as the core interpolates),
 * with s = sn; new. */
static json_t *tower_station_at(const json_t *sts, double x, double sn)
{
    size_t j = 0, n = json_array_size(sts);
    const json_t *a, *b, *val;
    const char *key;
    json_t *o = json_object();
    double sa, sb;

    while (j + 2 < n && x > json_number_value(json_object_get(json_array_get(sts, j + 1), "s")))
        j++;
    a = json_array_get(sts, j);
    b = json_array_get(sts, j + 1);
    sa = json_number_value(json_object_get(a, "s"));
    sb = json_number_value(json_object_get(b, "s"));
    json_object_foreach((json_t *)a, key, val)
        if (o && strcmp(key, "s") &&
            json_object_set_new(o, key,
                                tower_lerp(val, json_object_get(b, key), (x - sa) / (sb - sa)))) {
            json_decref(o);
            return NULL;
        }
    if (o && json_object_set_new(o, "s", json_real(sn))) {
        json_decref(o);
        return NULL;
    }
    return o;
}

/* The canonical stations sts cut to the fractions [x0, x1], s rescaled to 0..1; new. */
static json_t *tower_cut_stations(const json_t *sts, double x0, double x1)
{
    json_t *o = json_array();
    const json_t *st;
    size_t i;

    if (!o || json_array_append_new(o, tower_station_at(sts, x0, 0.0)))
        goto fail;
    json_array_foreach(sts, i, st) {
        double s = json_number_value(json_object_get(st, "s"));
        json_t *c;
        if (!(s > x0 && s < x1))
            continue;
        c = json_deep_copy(st);
        if (!c || json_object_set_new(c, "s", json_real((s - x0) / (x1 - x0))) ||
            json_array_append_new(o, c))
            goto fail;
    }
    if (json_array_append_new(o, tower_station_at(sts, x1, 1.0)))
        goto fail;
    return o;
fail:
    json_decref(o);
    return NULL;
}

/* The cut heights y[1..K-1] between y[0] = base and y[K] = top (wire heights below the top,
 * sorted, distinct); returns K, the number of pieces. */
static int tower_cuts(const tower_sup *s, const double g[3], double *y)
{
    int K = 1, i, j;

    y[0] = g[1];
    for (i = 0; i < s->nw; i++) {
        double h = s->wh[i];
        if (h >= g[0])
            continue;
        for (j = K; j > 1 && y[j - 1] > h; j--)
            y[j] = y[j - 1];
        if (y[j - 1] == h) { /* already a cut: undo the shift */
            for (; j < K; j++)
                y[j] = y[j + 1];
            continue;
        }
        y[j] = h;
        K++;
    }
    y[K] = g[0];
    return K;
}

/* Elements of the K pieces between heights y: E shared by length, each >= 1, summing to E. */
static void tower_share(const double *y, int K, long E, long *n)
{
    long sum = 0;
    int i, big;

    for (i = 0; i < K; i++) {
        n[i] = lround((double)E * (y[i + 1] - y[i]) / (y[K] - y[0]));
        n[i] = n[i] < 1 ? 1 : n[i];
        sum += n[i];
    }
    while (sum != E) { /* the longest piece per element gives or takes one */
        big = -1;
        for (i = 0; i < K; i++)
            if ((sum < E || n[i] > 1) &&
                (big < 0 || (y[i + 1] - y[i]) / (double)n[i] * (sum < E ? 1 : -1) >
                                (y[big + 1] - y[big]) / (double)n[big] * (sum < E ? 1 : -1)))
                big = i;
        n[big] += sum < E ? 1 : -1;
        sum += sum < E ? 1 : -1;
    }
}

/* Piece i's foundation stretches (member axes: [axial, p2 = side-side, p3 = fore-aft,
 * torsion]) in m from its lower end; new array, maybe empty. */
static json_t *tower_piece_foundation(const tower_sup *s, double y0, double y1)
{
    json_t *arr = json_array();
    int j;

    for (j = 0; arr && j < s->nf; j++) {
        double a = s->f0[j] > y0 ? s->f0[j] : y0, b = s->f1[j] < y1 ? s->f1[j] : y1;
        double k[4] = {s->fk[j][0], s->fk[j][2], s->fk[j][1], s->fk[j][3]};
        if (b <= a)
            continue;
        if (json_array_append_new(arr, json_pack("{s:o, s:f, s:f, s:f}", "stiffness_per_length",
                                                 field_reals(k, 4), "added_mass_per_length",
                                                 s->fm[j], "from_s", a - y0, "to_s", b - y0))) {
            json_decref(arr);
            return NULL;
        }
    }
    return arr;
}

/* Piece i of K (heights y, n[i] elements) of the canonical member mem0; new. */
static json_t *tower_piece(const json_t *mem0, const tower_sup *s, const double *y, int i, int K,
                           long ni)
{
    const json_t *sts = json_object_get(mem0, "stations");
    json_t *m = json_deep_copy(mem0), *f;
    char id[32], from[32], to[32];
    double L = y[K] - y[0];

    snprintf(id, sizeof id, "tower_%d", i + 1);
    snprintf(from, sizeof from, i ? "wire_%d" : "base", i);
    snprintf(to, sizeof to, i + 1 < K ? "wire_%d" : "top", i + 1);
    if (!m ||
        (K > 1 && (json_object_set_new(m, "id", json_string(id)) ||
                   json_object_set_new(m, "from", json_string(from)) ||
                   json_object_set_new(m, "to", json_string(to)))) ||
        json_object_set_new(m, "elements", json_integer((json_int_t)ni)))
        goto fail;
    if (sts && K > 1 &&
        json_object_set_new(m, "stations",
                            tower_cut_stations(sts, (y[i] - y[0]) / L, (y[i + 1] - y[0]) / L)))
        goto fail;
    f = tower_piece_foundation(s, y[i], y[i + 1]);
    if (!f || (json_array_size(f) && json_object_set(m, "foundation", f))) {
        json_decref(f);
        goto fail;
    }
    json_decref(f);
    return m;
fail:
    json_decref(m);
    return NULL;
}

/* The wires as springs at their joints (hub x = ss, z = fa); 0 or -1 (memory). */
static int tower_springs(json_t *st, const tower_sup *s, const double *y, int K)
{
    json_t *arr = json_array();
    int i, j;

    if (!arr || json_object_set_new(st, "springs", arr))
        return -1;
    for (i = 0; i < s->nw; i++) {
        double k[3] = {s->wk[i], 0.0, s->wk[i]}, z[3] = {0, 0, 0};
        char name[32] = "top";
        for (j = 1; j < K; j++)
            if (y[j] == s->wh[i])
                snprintf(name, sizeof name, "wire_%d", j);
        if (json_array_append_new(arr, json_pack("{s:s, s:{s:o, s:o}, s:s}", "joint", name,
                                                 "stiffness", "translational", field_reals(k, 3),
                                                 "rotational", field_reals(z, 3), "axes", "hub")))
            return -1;
    }
    return 0;
}

/*
 * The checked single-member structure cst cut at the wires' heights into pieces base -> wire_1
 * -> ... -> top (ids tower_1 ...; stations interpolated at the cuts, so the properties along
 * the tower are unchanged; the elements shared by length, summing to `elements`), the wires as
 * springs and the foundation as stretches of the pieces.  Nothing changes without wires and
 * foundation.  0, or -1 after reporting.
 */
static int tower_split(val_ctx *v, json_t *cst, const double g[3], const tower_sup *s)
{
    json_t *mems = json_object_get(cst, "members"), *joints = json_object_get(cst, "joints");
    json_t *mem0 = json_incref(json_array_get(mems, 0)), *nm = json_array();
    double y[TOWER_MAX_SUP + 2];
    long n[TOWER_MAX_SUP + 1];
    int K, i, rc = -1;

    if (!s->nw && !s->nf) {
        rc = 0;
        goto done;
    }
    K = tower_cuts(s, g, y);
    if ((long)K > (long)g[2]) {
        field_error(v, "/tower/elements",
                    "the wires cut the tower into %d pieces: it needs "
                    "at least one element each (elements is %ld)",
                    K, (long)g[2]);
        goto done;
    }
    tower_share(y, K, (long)g[2], n);
    for (i = 1; i < K; i++) {
        char name[32];
        snprintf(name, sizeof name, "wire_%d", i);
        if (json_object_set_new(joints, name, json_pack("[f, f, f]", 0.0, y[i], 0.0)))
            goto nomem;
    }
    for (i = 0; i < K; i++)
        if (!mem0 || !nm || json_array_append_new(nm, tower_piece(mem0, s, y, i, K, n[i])))
            goto nomem;
    if (json_object_set(cst, "members", nm) || tower_springs(cst, s, y, K))
        goto nomem;
    rc = 0;
    goto done;
nomem:
    v->nomem = 1;
done:
    json_decref(mem0);
    json_decref(nm);
    return rc;
}
