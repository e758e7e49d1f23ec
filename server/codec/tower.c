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
 * Guy wires, a foundation and a floating platform need elastic supports
 * the core does not have yet: "wires", "foundation" and "platform" are
 * reserved and refused with "not supported yet", as is "gravity": true.
 */
#include "codec_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Where the expanded structure's pointers go in the tower (longest prefix first). */
static const struct {
    const char *from, *to;
} tower_map[] = {
    {"/structure/members/0/stations", "/tower/stations"},
    {"/structure/members/0/elements", "/tower/elements"},
    {"/structure/members/0", "/tower"},
    {"/structure/sections/tower", "/tower/section"},
    {"/structure/sections", "/tower/section"},
    {"/structure/point_masses/0", "/tower/top_mass"},
    {"/structure/joints", "/tower/height"},
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

/* The reserved fields (supports the core does not have yet) and gravity. */
static void tower_reserved(val_ctx *v, const json_t *tw, json_t *ct)
{
    static const struct {
        const char *key, *what;
    } r[] = {
        {"wires", "guy wires (attachment station, number, stiffness, angle)"},
        {"foundation", "a foundation (soil springs and added mass per length)"},
        {"platform", "a floating platform (6x6 mass, added mass, hydrostatic and mooring "
                     "matrices)"},
    };
    size_t k;

    for (k = 0; k < sizeof(r) / sizeof(r[0]); k++)
        if (json_object_get(tw, r[k].key))
            field_error_key(v, "/tower", r[k].key,
                            "not supported yet: %s needs elastic "
                            "supports, which the solver does not have yet (issue 25); leave "
                            "'%s' out for a tower clamped at its base",
                            r[k].what, r[k].key);
    field_bool(v, tw, "gravity", "/tower", ct, 0);
    if (json_is_true(json_object_get(tw, "gravity")))
        field_error(v, "/tower/gravity",
                    "not supported yet: the weight of the tower and top "
                    "mass as an axial load needs the solver's support (issue 25); give false "
                    "or leave it out (BModes and ElastoDyn's modes leave gravity out too)");
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

json_t *tower_validate(val_ctx *v, const json_t *root, json_t *canon)
{
    static const char *const keys[] = {"height",     "base_height", "elements", "section",
                                       "stations",   "top_mass",    "gravity",  "wires",
                                       "foundation", "platform",    NULL};
    const json_t *tw = json_object_get(root, "tower"), *tm, *sec, *mem;
    json_t *ct, *st, *cst = NULL;
    double g[3], t[10];
    int top_ok = 0;

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
    tower_reserved(v, tw, ct);
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
    if (!st)
        v->nomem = 1;
    else
        cst = tower_check_structure(v, st);
    json_decref(st);
    mem = json_array_get(json_object_get(cst, "members"), 0);
    sec = json_object_get(json_object_get(cst, "sections"), "tower");
    if (json_object_get(tw, "section") && sec)
        field_set(v, ct, "section", json_deep_copy(sec));
    if (json_object_get(tw, "stations") && json_object_get(mem, "stations"))
        field_set(v, ct, "stations", json_deep_copy(json_object_get(mem, "stations")));
    field_set(v, canon, "tower", ct);
    return cst;
}

void tower_check_speeds(val_ctx *v, const json_t *canon)
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
            field_error(v, p,
                        "a tower does not spin: its speed must be 0 (speed %zu is %g "
                        "%s); the rotor's speed belongs to a rotor-on-tower model, which is "
                        "not supported yet",
                        i + 1, !strcmp(key, "rpm") ? rpm[i] : om[i],
                        !strcmp(key, "rpm") ? "rpm" : "rad/s");
            free(p);
            break;
        }
done:
    free(om);
    free(rpm);
}
