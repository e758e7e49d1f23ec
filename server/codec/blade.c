/*
 * blade.c — the "blade" form of a request, expanded to a spatial structure (DESIGN.md 8).
 *
 * How it fits: a request gives either "structure" or "blade".  For a blade,
 * validate.c calls blade_validate: the blade's own fields (length,
 * hub_radius, precone_deg, pitch_deg, elements, tip_mass) are checked here,
 * then the blade is expanded into the structure it stands for and that
 * structure goes through the ordinary checks of validate.c (section,
 * stations, point mass), with every error pointer moved back into /blade
 * (blade_pointer).  The canonical request keeps the blade as given (its
 * defaults written out); the expanded structure, with the pitch added to
 * the stations' twists, is what request.c turns into the core's arrays.
 *
 * Blade axes at the root (p = precone): b1 = (cos p, 0, sin p) along the
 * span, b2 = (0, 1, 0) edgewise (in the plane of rotation), b3 = (-sin p,
 * 0, cos p) flapwise.  Joints root = hub_radius b1 and tip = (hub_radius +
 * length) b1; one member "blade" with flap_direction b3 and twist pitch; the
 * clamp at root; the tip mass at tip, its offset and inertia tensor given
 * in blade axes and rotated to hub axes (I_hub = B I_blade B^T, B = [b1 b2
 * b3]).
 */
#include "codec_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Where the expanded structure's pointers go in the blade (longest prefix first). */
static const struct {
    const char *from, *to;
} blade_map[] = {
    {"/structure/members/0/stations", "/blade/stations"},
    {"/structure/members/0/elements", "/blade/elements"},
    {"/structure/members/0/twist_deg", "/blade/pitch_deg"},
    {"/structure/members/0", "/blade"},
    {"/structure/sections/blade", "/blade/section"},
    {"/structure/sections", "/blade/section"},
    {"/structure/point_masses/0", "/blade/tip_mass"},
    {"/structure/joints", "/blade/length"},
    {"/structure", "/blade"},
};

char *blade_pointer(const char *p)
{
    size_t k, n;

    for (k = 0; k < sizeof(blade_map) / sizeof(blade_map[0]); k++) {
        n = strlen(blade_map[k].from);
        if (!strncmp(p, blade_map[k].from, n) && (p[n] == '\0' || p[n] == '/'))
            return err_fmt("%s%s", blade_map[k].to, p + n);
    }
    return strdup(p);
}

/* The blade axes b1, b2, b3 as the columns of B (row-major B[i][j]: component i of b_j). */
static void blade_axes(double precone_deg, double B[3][3])
{
    double p = precone_deg * CODEC_RAD_PER_DEG, c = cos(p), s = sin(p);

    B[0][0] = c;  B[0][1] = 0; B[0][2] = -s;
    B[1][0] = 0;  B[1][1] = 1; B[1][2] = 0;
    B[2][0] = s;  B[2][1] = 0; B[2][2] = c;
}

/* out = R x: a vector in a form's axes to hub axes (R row-major 3x3; blade.c and tower.c). */
void blade_rotate(const double *R, const double x[3], double out[3])
{
    int i;

    for (i = 0; i < 3; i++)
        out[i] = R[3 * i] * x[0] + R[3 * i + 1] * x[1] + R[3 * i + 2] * x[2];
}

/*
 * A point mass's tensor from a form's axes (diag = [I11, I22, I33], prod = [I12, I23, I31]) to
 * hub axes: I_hub = R I R^T (R row-major 3x3), returned as diag [Ixx, Iyy, Izz] and prod [Ixy,
 * Iyz, Izx].  blade.c and tower.c.
 */
void blade_tensor(const double *R, const double diag[3], const double prod[3], double hd[3],
                  double hp[3])
{
    double T[3][3] = {{diag[0], prod[0], prod[2]},
                      {prod[0], diag[1], prod[1]},
                      {prod[2], prod[1], diag[2]}};
    double H[3][3];
    int i, j, a, b;

    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) {
            H[i][j] = 0;
            for (a = 0; a < 3; a++)
                for (b = 0; b < 3; b++)
                    H[i][j] += R[3 * i + a] * T[a][b] * R[3 * j + b];
        }
    for (i = 0; i < 3; i++)
        hd[i] = H[i][i];
    hp[0] = H[0][1];
    hp[1] = H[1][2];
    hp[2] = H[2][0];
}

/* The tip mass's vectors in blade axes, as the messages name their components. */
static const char *const blade_tip_shapes[3] = {"[span, edgewise, flapwise]", "[I11, I22, I33]",
                                                "[I12, I23, I31]"};

/* A vector field of a point mass at ptr: checked (zeros written out when absent). */
static void blade_mass_vector(val_ctx *v, const json_t *tm, const char *key, const char *ptr,
                              json_t *c, enum field_real_kind kind, const char *shape,
                              const char *unit, double out[3])
{
    out[0] = out[1] = out[2] = 0;
    if (json_object_get(tm, key) && !field_vector(v, tm, key, ptr, 3, kind, shape, unit, out))
        return;
    field_set(v, c, key, field_reals(out, 3));
}

int blade_point_mass(val_ctx *v, const json_t *tm, json_t *parent, const char *key, const char *ptr,
                     const char *what, const char *const shapes[3], double t[10])
{
    static const char *const keys[] = {"mass", "offset", "inertia", "products", NULL};
    size_t before = (size_t)codec_errors_count(v->errs);
    json_t *c;

    if (!json_is_object(tm)) {
        field_error(v, ptr, "must be an object {mass [, offset, inertia, products]}, not %s",
                    field_type_name(tm));
        return 0;
    }
    if (!(c = json_object())) {
        v->nomem = 1;
        return 0;
    }
    field_check_keys(v, tm, ptr, keys, what);
    field_real(v, tm, "mass", ptr, c, FIELD_NONNEG, " (kg)", &t[0]);
    blade_mass_vector(v, tm, "offset", ptr, c, FIELD_FINITE, shapes[0], " (m)", t + 1);
    blade_mass_vector(v, tm, "inertia", ptr, c, FIELD_NONNEG, shapes[1], " (kg m^2)", t + 4);
    blade_mass_vector(v, tm, "products", ptr, c, FIELD_FINITE, shapes[2], " (kg m^2)", t + 7);
    field_set(v, parent, key, c);
    return (size_t)codec_errors_count(v->errs) == before;
}

/* The blade's scalar fields into cb; g = length, hub_radius, precone, pitch, elements. */
static void blade_scalars(val_ctx *v, const json_t *b, json_t *cb, double g[5])
{
    long el = 48;

    if (!field_real(v, b, "length", "/blade", cb, FIELD_POSITIVE, " (m)", &g[0]))
        g[0] = 1; /* still check the section and stations */
#define BLADE_OPT(key, kind, unit, i)                                                          \
    if (!json_object_get(b, key) || !field_real(v, b, key, "/blade", cb, kind, unit, &g[i])) { \
        g[i] = 0;                                                                              \
        if (!json_object_get(b, key))                                                          \
            field_set(v, cb, key, json_real(0.0));                                             \
    }
    BLADE_OPT("hub_radius", FIELD_NONNEG, " (m)", 1)
    BLADE_OPT("precone_deg", FIELD_FINITE, " (degrees)", 2)
    BLADE_OPT("pitch_deg", FIELD_FINITE, " (degrees)", 3)
#undef BLADE_OPT
    if (fabs(g[2]) >= 90) {
        field_error(v, "/blade/precone_deg", "the precone must be between -90 and 90 degrees "
                    "(the blade axis tilted out of the plane of rotation), got %g", g[2]);
        g[2] = 0;
    }
    field_int(v, b, "elements", "/blade", cb, 0, 48, 1, v->lim->max_elements,
              "the number of elements", &el);
    g[4] = (double)el;
}

/*
 * The structure a blade stands for, in request form (new): g the scalars, t
 * the tip mass (mass, offset, inertia, products in blade axes) or NULL.
 */
static json_t *blade_structure(const json_t *b, const double g[5], const double *t)
{
    double B[3][3], root[3], tip[3], off[3], hd[3], hp[3], b3[3];
    const json_t *sec = json_object_get(b, "section"), *sts = json_object_get(b, "stations");
    json_t *st, *mem;
    int i;

    blade_axes(g[2], B);
    for (i = 0; i < 3; i++) {
        root[i] = g[1] * B[i][0];
        tip[i] = (g[1] + g[0]) * B[i][0];
        b3[i] = B[i][2];
    }
    mem = json_pack("{s:s, s:s, s:s, s:s, s:I, s:f, s:o}", "id", "blade", "from", "root", "to",
                    "tip", "section", "blade", "elements", (json_int_t)g[4], "twist_deg", g[3],
                    "flap_direction", field_reals(b3, 3));
    if (mem && sts && json_object_set(mem, "stations", (json_t *)sts)) {
        json_decref(mem);
        return NULL;
    }
    st = json_pack("{s:{s:o, s:o}, s:{s:o}, s:[o], s:s, s:[]}", "joints", "root",
                   field_reals(root, 3), "tip", field_reals(tip, 3), "sections", "blade",
                   sec ? json_incref((json_t *)sec) : json_object(), "members", mem, "clamp",
                   "root", "point_masses");
    if (st && t) {
        blade_rotate(&B[0][0], t + 1, off);
        blade_tensor(&B[0][0], t + 4, t + 7, hd, hp);
        if (json_array_append_new(json_object_get(st, "point_masses"),
                                  json_pack("{s:s, s:f, s:o, s:o, s:o}", "joint", "tip", "mass",
                                            t[0], "offset", field_reals(off, 3), "inertia",
                                            field_reals(hd, 3), "products",
                                            field_reals(hp, 3)))) {
            json_decref(st);
            return NULL;
        }
    }
    return st;
}

/*
 * Check the expanded structure st (borrowed) with the ordinary walk, the
 * errors moved into /blade; returns its canonical copy (new) or NULL.
 */
static json_t *blade_check_structure(val_ctx *v, json_t *st)
{
    codec_errors *mine = codec_errors_new(), *saved = v->errs;
    json_t *root = json_pack("{s:O}", "structure", st), *canon = json_object(), *cst = NULL;
    int i;

    if (!mine || !root || !canon) {
        v->nomem = 1;
        goto done;
    }
    v->errs = mine;
    v->blade = 1;
    val_structure(v, root, canon);
    v->blade = 0;
    v->errs = saved;
    for (i = 0; i < codec_errors_count(mine); i++) {
        char *p = blade_pointer(codec_errors_pointer(mine, i));
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

/* The structural and inertia twists of the canonical stations sts plus the pitch (degrees). */
static void blade_pitch_stations(json_t *sts, double pitch)
{
    static const char *const keys[] = {"twist_deg", "inertia_twist_deg"};
    json_t *st, *x;
    size_t j;
    int k;

    json_array_foreach(sts, j, st)
        for (k = 0; k < 2; k++)
            if ((x = json_object_get(st, keys[k])))
                json_real_set(x, json_real_value(x) + pitch);
}

json_t *blade_validate(val_ctx *v, const json_t *root, json_t *canon)
{
    static const char *const keys[] = {"length", "hub_radius", "precone_deg", "pitch_deg",
                                       "elements", "section", "stations", "tip_mass", NULL};
    const json_t *b = json_object_get(root, "blade"), *tm, *sec;
    json_t *cb, *st, *cst = NULL, *mem;
    double g[5], t[10];
    int tip_ok = 0;

    if (!json_is_object(b)) {
        field_error(v, "/blade", "must be an object {length, [hub_radius, precone_deg, "
                    "pitch_deg, elements,] section and/or stations [, tip_mass]}, not %s",
                    field_type_name(b));
        return NULL;
    }
    if (!(cb = json_object())) {
        v->nomem = 1;
        return NULL;
    }
    field_check_keys(v, b, "/blade", keys, "blade");
    blade_scalars(v, b, cb, g);
    if ((tm = json_object_get(b, "tip_mass")))
        tip_ok = blade_point_mass(v, tm, cb, "tip_mass", "/blade/tip_mass", "tip mass",
                                  blade_tip_shapes, t);
    if (json_object_get(b, "section") && sec_classify_as(json_object_get(b, "section"), 1) ==
                                             SEC_PLANAR) {
        field_error(v, "/blade/section", "a blade is spatial, and this section is %s: give it "
                    "as EA, EI_flap, EI_edge, GJ and mass_per_length (or E, G, A, I_flap, I_edge, "
                    "J and mass_per_length)", sec_form_name(SEC_PLANAR));
        field_set(v, canon, "blade", cb);
        return NULL;
    }
    st = blade_structure(b, g, tip_ok ? t : NULL);
    if (!st)
        v->nomem = 1;
    else
        cst = blade_check_structure(v, st);
    json_decref(st);
    mem = json_array_get(json_object_get(cst, "members"), 0);
    sec = json_object_get(json_object_get(cst, "sections"), "blade");
    if (json_object_get(b, "section") && sec)
        field_set(v, cb, "section", json_deep_copy(sec));
    if (json_object_get(b, "stations") && json_object_get(mem, "stations")) {
        field_set(v, cb, "stations", json_deep_copy(json_object_get(mem, "stations")));
        blade_pitch_stations(json_object_get(mem, "stations"), g[3]);
    }
    field_set(v, canon, "blade", cb);
    return cst;
}
