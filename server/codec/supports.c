/*
 * supports.c — elastic supports of a request (DESIGN.md 8.6): the structure's "springs" and a
 * member's "foundation" checked into the canonical copy, turned into the core's sm_support
 * array, and a core diagnostic about a support pointed back at its field.
 *
 * How it fits: validate.c calls sup_springs (after the members) and sup_foundation (per
 * member); request.c calls sup_build with the joint table it built; diag.c calls sup_pointer
 * for SM_ITEM_SUPPORT.  The core's support index runs over the springs in request order, then
 * over the members' foundations member by member (a foundation object is one stretch, an array
 * one per entry), then the free base's support at the clamp joint when there is one (platform.c).  The codec checks what it can name precisely (numbers, signs, symmetry, the
 * stretch inside the member); positive semi-definiteness of a 6x6 is the core's check
 * (core/model/supports.c), reported at the matrix.
 *
 * A spring's 6x6 is over (x, y, z, rx, ry, rz), given as rows (symmetric, so rows and columns
 * read alike) or as {translational, rotational} diagonals.  "axes": "member:ID" gives it in
 * the member's axes without twist (e1 from -> to, e2 edgewise, e3 flapwise: flap_direction
 * made normal to e1, or the default of DESIGN.md 7.1, the radial direction of the midpoint);
 * sup_build turns it into hub axes, K_hub = R K R^T with R = diag(A, A), A = [e1 e2 e3].
 */
#include "codec_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The matrices a spring carries: request key, unit for messages, sm_support field. */
static const char *const sup_mat_key[2] = {"stiffness", "added_mass"};
static const char *const sup_mat_unit[2] = {" (N/m, N/rad, N m/rad)", " (kg, kg m, kg m^2)"};

/* A 6x6 given as six rows of six numbers at p into a (column-major); 1 when valid. */
static int sup_rows(val_ctx *v, const json_t *x, const char *p, const char *unit, double a[36])
{
    int i, j, ok = 1;

    if (!json_is_array(x) || json_array_size(x) != 6) {
        field_error(v, p,
                    "must be a 6x6 matrix (six rows of six numbers over x, y, z, rx, ry, "
                    "rz) or {\"translational\": [kx, ky, kz], \"rotational\": [rx, ry, rz]}");
        return 0;
    }
    for (i = 0; i < 6; i++) {
        const json_t *row = json_array_get(x, (size_t)i);
        char *pr = err_ptr_idx(p, (size_t)i);
        if (!pr) {
            v->nomem = 1;
            return 0;
        }
        if (!json_is_array(row) || json_array_size(row) != 6) {
            field_error(v, pr, "must be a row of six numbers, not %s", field_type_name(row));
            ok = 0;
        } else {
            for (j = 0; j < 6; j++) {
                char *pe = err_ptr_idx(pr, (size_t)j);
                if (!pe || !field_check_real(v, json_array_get(row, (size_t)j), pe, FIELD_FINITE,
                                             unit, &a[i + 6 * j]))
                    ok = 0;
                v->nomem |= !pe;
                free(pe);
            }
        }
        free(pr);
    }
    return ok;
}

/* a symmetric (1e-9 of its largest entry, as the core) with a diagonal >= 0 unless any_sign;
 * errors at p/i/j. */
static int sup_check_sym(val_ctx *v, const char *p, const char *unit, int any_sign,
                         const double a[36])
{
    double mx = 0;
    int i, j;

    for (i = 0; i < 36; i++)
        mx = fmax(mx, fabs(a[i]));
    for (i = 0; i < 6 && !any_sign; i++)
        if (a[i + 6 * i] < 0) {
            char *pe = err_fmt("%s/%d/%d", p, i, i);
            field_error(v, pe, "a negative diagonal entry (%g%s): a stiffness or mass is >= 0",
                        a[i + 6 * i], unit);
            free(pe);
            return 0;
        }
    for (j = 0; j < 6; j++)
        for (i = 0; i < j; i++)
            if (fabs(a[i + 6 * j] - a[j + 6 * i]) > 1e-9 * mx) {
                char *pe = err_fmt("%s/%d/%d", p, i, j);
                field_error(v, pe,
                            "the matrix is not symmetric: row %d column %d is %g, row %d column "
                            "%d is %g (they must agree within 1e-9 of the largest entry)",
                            i, j, a[i + 6 * j], j, i, a[j + 6 * i]);
                free(pe);
                return 0;
            }
    return 1;
}

/* The diagonal form {translational, rotational} at p into a (>= 0 unless any_sign); 1 when
 * valid. */
static int sup_diag(val_ctx *v, const json_t *x, const char *p, int any_sign, double a[36])
{
    static const char *const keys[] = {"translational", "rotational", NULL};
    double d[6] = {0, 0, 0, 0, 0, 0};
    int ok = 1, k;

    field_check_keys(v, x, p, keys, "diagonal 6x6");
    for (k = 0; k < 2; k++)
        if (json_object_get(x, keys[k]) &&
            !field_vector(v, x, keys[k], p, 3, any_sign ? FIELD_FINITE : FIELD_NONNEG,
                          k ? "[rx, ry, rz]" : "[x, y, z]", "", d + 3 * k))
            ok = 0;
    memset(a, 0, 36 * sizeof(double));
    for (k = 0; k < 6; k++)
        a[k + 6 * k] = d[k];
    return ok;
}

/* The canonical form of a (reals): {translational, rotational} when diag, else six rows. */
static json_t *sup_canon(const double a[36], int diag)
{
    double d[6];
    json_t *rows;
    int i, j;

    if (diag) {
        for (i = 0; i < 6; i++)
            d[i] = a[i + 6 * i];
        return json_pack("{s:o, s:o}", "translational", field_reals(d, 3), "rotational",
                         field_reals(d + 3, 3));
    }
    rows = json_array();
    for (i = 0; rows && i < 6; i++) {
        for (j = 0; j < 6; j++)
            d[j] = a[i + 6 * j];
        if (json_array_append_new(rows, field_reals(d, 6))) {
            json_decref(rows);
            return NULL;
        }
    }
    return rows;
}

int sup_matrix6(val_ctx *v, const json_t *obj, const char *p, const char *key, const char *unit,
                int any_sign, json_t *c, double a[36])
{
    const json_t *x = json_object_get(obj, key);
    char *pm = err_ptr_key(p, key);
    int ok;

    if (!pm) {
        v->nomem = 1;
        return 0;
    }
    if (json_is_object(x))
        ok = sup_diag(v, x, pm, any_sign, a);
    else
        ok = sup_rows(v, x, pm, unit, a) && sup_check_sym(v, pm, unit, any_sign, a);
    free(pm);
    if (ok)
        field_set(v, c, key, sup_canon(a, json_is_object(x)));
    return ok;
}

/* Spring matrix m (0 stiffness, 1 added mass) of sp at p into a and canonical c; 1 when valid. */
static int sup_matrix(val_ctx *v, const json_t *sp, const char *p, int m, json_t *c, double a[36])
{
    return sup_matrix6(v, sp, p, sup_mat_key[m], sup_mat_unit[m], 0, c, a);
}

/* "axes": "hub" (default) or "member:ID" with ID a member id of the input members. */
static void sup_axes(val_ctx *v, const json_t *sp, const char *p, const json_t *mems, json_t *c)
{
    const json_t *x = json_object_get(sp, "axes"), *mem;
    const char *s;
    size_t i;

    if (!x) {
        field_set(v, c, "axes", json_string("hub"));
        return;
    }
    s = json_string_value(x);
    if (s && !strcmp(s, "hub")) {
        field_set(v, c, "axes", json_string(s));
        return;
    }
    if (s && !strncmp(s, "member:", 7)) {
        if (v->spatial == 0) {
            field_error_key(v, p, "axes",
                            "\"member:ID\" needs a spatial structure (a planar "
                            "member has no flapwise axis): give \"hub\"");
            return;
        }
        json_array_foreach(mems, i, mem)
            if (json_is_string(json_object_get(mem, "id")) &&
                !strcmp(json_string_value(json_object_get(mem, "id")), s + 7)) {
                field_set(v, c, "axes", json_string(s));
                return;
            }
        field_error_key(v, p, "axes", "unknown member '%s' (\"member:ID\" names a member's id)",
                        field_short_name(s + 7).s);
        return;
    }
    field_error_key(v, p, "axes", "must be \"hub\" or \"member:ID\" (a member's id), not %s",
                    s ? field_short_name(s).s : field_type_name(x));
}

/* One spring sp at p checked into a new canonical object appended to cs. */
static void sup_spring(val_ctx *v, const json_t *sp, const char *p, const json_t *joints,
                       const json_t *mems, json_t *cs)
{
    static const char *const keys[] = {"joint", "stiffness", "added_mass", "axes", NULL};
    double a[36];
    json_t *c;

    if (!json_is_object(sp)) {
        field_error(v, p, "must be an object {joint, stiffness [, added_mass, axes]}, not %s",
                    field_type_name(sp));
        return;
    }
    field_check_keys(v, sp, p, keys, "spring");
    if (!(c = json_object())) {
        v->nomem = 1;
        return;
    }
    field_ref(v, sp, "joint", p, c, joints, "joint");
    if (!json_object_get(sp, "stiffness"))
        field_error_key(v, p, "stiffness", "required field 'stiffness' is missing");
    else
        sup_matrix(v, sp, p, 0, c, a);
    if (json_object_get(sp, "added_mass"))
        sup_matrix(v, sp, p, 1, c, a);
    sup_axes(v, sp, p, mems, c);
    if (json_array_append_new(cs, c))
        v->nomem = 1;
}

void sup_springs(val_ctx *v, const json_t *st, const json_t *joints, json_t *cst)
{
    static const char *base = "/structure/springs";
    const json_t *sps = json_object_get(st, "springs"), *sp;
    json_t *cs;
    size_t i;

    if (!sps)
        return;
    if (!json_is_array(sps)) {
        field_error(v, base, "must be an array of {joint, stiffness}, not %s",
                    field_type_name(sps));
        return;
    }
    if (json_array_size(sps) > (size_t)v->lim->max_point_masses) {
        field_error(v, base, "%zu springs: the limit is %d (max_point_masses)",
                    json_array_size(sps), v->lim->max_point_masses);
        return;
    }
    if (!(cs = json_array())) {
        v->nomem = 1;
        return;
    }
    json_array_foreach(sps, i, sp) {
        char *p = err_ptr_idx(base, i);
        if (!p) {
            v->nomem = 1;
            break;
        }
        sup_spring(v, sp, p, joints, json_object_get(st, "members"), cs);
        free(p);
    }
    field_set(v, cst, "springs", cs);
}

/* One stretch f at p of a member of length len (0: not known) into canonical c. */
static void sup_stretch(val_ctx *v, const json_t *f, const char *p, double len, json_t *c)
{
    static const char *const keys[] = {"stiffness_per_length", "added_mass_per_length", "from_s",
                                       "to_s", NULL};
    double k[4] = {0, 0, 0, 0}, a = 0, s0 = 0, s1 = len;
    const json_t *kx = json_object_get(f, "stiffness_per_length");
    char *pk;
    int i, ok = 1;

    field_check_keys(v, f, p, keys, "foundation");
    if (!kx || !json_is_array(kx) || json_array_size(kx) != 4) {
        field_error_key(v, p, "stiffness_per_length",
                        "must be [k_axial, k_lateral_edgewise, "
                        "k_lateral_flapwise, k_torsion] (N/m per m, N m/rad per m), not %s",
                        kx ? field_type_name(kx) : "missing");
        ok = 0;
    }
    for (i = 0; ok && i < 4; i++) {
        pk = err_fmt("%s/stiffness_per_length/%d", p, i);
        ok = pk && field_check_real(v, json_array_get(kx, (size_t)i), pk, FIELD_NONNEG,
                                    i == 3 ? " (N m/rad per m)" : " (N/m per m)", &k[i]);
        v->nomem |= !pk;
        free(pk);
    }
    if (ok)
        field_set(v, c, "stiffness_per_length", field_reals(k, 4));
    if (json_object_get(f, "added_mass_per_length"))
        field_real(v, f, "added_mass_per_length", p, c, FIELD_NONNEG, " (kg/m)", &a);
    else
        field_set(v, c, "added_mass_per_length", json_real(0.0));
    if (json_object_get(f, "from_s") &&
        !field_real(v, f, "from_s", p, c, FIELD_NONNEG, " (m)", &s0))
        return;
    if (!json_object_get(f, "to_s") && len > 0)
        field_set(v, c, "to_s", json_real(len));
    else if (json_object_get(f, "to_s") &&
             !field_real(v, f, "to_s", p, c, FIELD_POSITIVE, " (m)", &s1))
        return;
    if (!json_object_get(f, "from_s"))
        field_set(v, c, "from_s", json_real(0.0));
    if (len > 0 && !(s1 <= len * (1 + 1e-12)))
        field_error_key(v, p, "to_s",
                        "the stretch ends at %g m, past the member's end (%g m "
                        "from its 'from' joint)",
                        s1, len);
    else if (len > 0 && !(s0 < s1))
        field_error_key(v, p, "from_s", "the stretch must start (%g m) before it ends (%g m)", s0,
                        s1);
}

void sup_foundation(val_ctx *v, const json_t *mem, const char *p, json_t *c, double len)
{
    const json_t *f = json_object_get(mem, "foundation"), *x;
    char *pf = err_ptr_key(p, "foundation");
    json_t *cf = NULL, *one;
    size_t i;

    if (!pf) {
        v->nomem = 1;
        return;
    }
    if (json_is_object(f)) {
        if ((cf = json_object()))
            sup_stretch(v, f, pf, len, cf);
    } else if (json_is_array(f) && json_array_size(f) > 0 && json_array_size(f) <= 64) {
        cf = json_array();
        json_array_foreach(f, i, x) {
            char *pi = err_ptr_idx(pf, i);
            if (!cf || !pi || !(one = json_object())) {
                v->nomem = 1;
                free(pi);
                break;
            }
            if (!json_is_object(x))
                field_error(v, pi,
                            "must be an object {stiffness_per_length [, "
                            "added_mass_per_length, from_s, to_s]}, not %s",
                            field_type_name(x));
            else
                sup_stretch(v, x, pi, len, one);
            free(pi);
            if (json_array_append_new(cf, one))
                v->nomem = 1;
        }
    } else {
        field_error(v, pf,
                    "must be an object {stiffness_per_length [, added_mass_per_length, "
                    "from_s, to_s]} or an array of 1 to 64 of them, not %s",
                    field_type_name(f));
    }
    v->nomem |= !cf && (json_is_object(f) || json_is_array(f));
    free(pf);
    if (cf)
        field_set(v, c, "foundation", cf);
}

int sup_joint(const char **names, int n, const char *name)
{
    int lo = 0, hi = n - 1;

    while (name && lo <= hi) {
        int mid = (lo + hi) / 2, c = strcmp(names[mid], name);
        if (!c)
            return mid;
        if (c < 0)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return -1;
}

void sup_read(const json_t *x, double a[36])
{
    int i, j;

    memset(a, 0, 36 * sizeof(double));
    if (json_is_object(x)) {
        for (i = 0; i < 3; i++) {
            a[i + 6 * i] =
                json_number_value(json_array_get(json_object_get(x, "translational"), i));
            a[i + 3 + 6 * (i + 3)] =
                json_number_value(json_array_get(json_object_get(x, "rotational"), i));
        }
        return;
    }
    for (i = 0; i < 6; i++)
        for (j = 0; j < 6; j++)
            a[i + 6 * j] = json_number_value(json_array_get(json_array_get(x, i), j));
}

void sup_pos(const sup_joints *J, int j, double p[3])
{
    p[0] = J->xy[2 * j];
    p[1] = J->xy[2 * j + 1];
    p[2] = J->z ? J->z[j] : 0.0;
}

/*
 * The axes A = [e1 e2 e3] (column-major) of the canonical member mem without twist: e1 from ->
 * to, e3 its flap_direction (default: the radial direction of its midpoint) made normal to e1,
 * e2 = e3 x e1.  0, or -1 when e3 has no direction.
 */
static int sup_member_axes(const sup_joints *J, const json_t *mem, double A[9])
{
    const json_t *fd = json_object_get(mem, "flap_direction");
    int a = sup_joint(J->names, J->n, json_string_value(json_object_get(mem, "from")));
    int b = sup_joint(J->names, J->n, json_string_value(json_object_get(mem, "to")));
    double pa[3], pb[3], d[3], L = 0, dot = 0, n3 = 0;
    int k;

    if (a < 0 || b < 0)
        return -1;
    sup_pos(J, a, pa);
    sup_pos(J, b, pb);
    for (k = 0; k < 3; k++) {
        A[k] = pb[k] - pa[k];
        L += A[k] * A[k];
        d[k] = fd ? json_number_value(json_array_get(fd, (size_t)k))
                  : (k < 2 ? 0.5 * (pa[k] + pb[k]) : 0.0);
    }
    L = sqrt(L);
    for (k = 0; k < 3; k++) {
        A[k] /= L;
        dot += d[k] * A[k];
    }
    for (k = 0; k < 3; k++) { /* e3 = d - (d . e1) e1 */
        A[6 + k] = d[k] - dot * A[k];
        n3 += A[6 + k] * A[6 + k];
    }
    if (!(L > 0) || !(n3 > 1e-24 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2])) || n3 == 0)
        return -1;
    for (k = 0; k < 3; k++)
        A[6 + k] /= sqrt(n3);
    A[3] = A[7] * A[2] - A[8] * A[1]; /* e2 = e3 x e1 */
    A[4] = A[8] * A[0] - A[6] * A[2];
    A[5] = A[6] * A[1] - A[7] * A[0];
    return 0;
}

/* a = R a R^T with R = diag(A, A) (member axes -> hub axes). */
static void sup_rotate(const double A[9], double a[36])
{
    double t[36], R[36];
    int i, j, k;

    memset(R, 0, sizeof R);
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++)
            R[i + 6 * j] = R[i + 3 + 6 * (j + 3)] = A[i + 3 * j];
    for (i = 0; i < 6; i++) /* t = R a */
        for (j = 0; j < 6; j++) {
            t[i + 6 * j] = 0;
            for (k = 0; k < 6; k++)
                t[i + 6 * j] += R[i + 6 * k] * a[k + 6 * j];
        }
    for (i = 0; i < 6; i++) /* a = t R^T */
        for (j = 0; j < 6; j++) {
            a[i + 6 * j] = 0;
            for (k = 0; k < 6; k++)
                a[i + 6 * j] += t[i + 6 * k] * R[j + 6 * k];
        }
}

/* Spring sp (canonical) into s; the member axes from mems. */
static void sup_fill_spring(const sup_joints *J, const json_t *sp, const json_t *mems,
                            sm_support *s)
{
    const char *ax = json_string_value(json_object_get(sp, "axes"));
    const json_t *mem;
    double A[9];
    size_t i;

    s->joint = sup_joint(J->names, J->n, json_string_value(json_object_get(sp, "joint")));
    s->member = -1;
    sup_read(json_object_get(sp, "stiffness"), s->K);
    sup_read(json_object_get(sp, "added_mass"), s->M);
    if (!ax || strncmp(ax, "member:", 7))
        return;
    json_array_foreach(mems, i, mem) {
        const char *id = json_string_value(json_object_get(mem, "id"));
        if (id && !strcmp(id, ax + 7) && !sup_member_axes(J, mem, A)) {
            sup_rotate(A, s->K);
            sup_rotate(A, s->M);
            return;
        }
    }
}

/* Stretch f (canonical) of member m into s. */
static void sup_fill_stretch(const json_t *f, int m, sm_support *s)
{
    int k;

    s->joint = -1;
    s->member = m;
    for (k = 0; k < 4; k++)
        s->k_per_length[k] =
            json_number_value(json_array_get(json_object_get(f, "stiffness_per_length"), k));
    s->added_mass_per_length = json_number_value(json_object_get(f, "added_mass_per_length"));
    s->from_s = json_number_value(json_object_get(f, "from_s"));
    s->to_s = json_number_value(json_object_get(f, "to_s"));
}

/* Number of stretches of a canonical foundation (object: 1, array: its size, absent: 0). */
static size_t sup_stretches(const json_t *f)
{
    return json_is_object(f) ? 1 : json_array_size(f);
}

int sup_build(const json_t *st, const sup_joints *J, sm_support **out, int *n)
{
    const json_t *sps = json_object_get(st, "springs"), *mems = json_object_get(st, "members");
    const json_t *x, *f;
    size_t i, j, k = json_array_size(sps), total = k;

    *out = NULL;
    *n = 0;
    json_array_foreach(mems, i, x)
        total += sup_stretches(json_object_get(x, "foundation"));
    total += (size_t)plat_base_free(st);
    if (!total)
        return SM_OK;
    if (!(*out = calloc(total, sizeof(sm_support))))
        return SM_NOMEM;
    json_array_foreach(sps, i, x)
        sup_fill_spring(J, x, mems, &(*out)[i]);
    json_array_foreach(mems, i, x) {
        f = json_object_get(x, "foundation");
        for (j = 0; j < sup_stretches(f); j++)
            sup_fill_stretch(json_is_object(f) ? f : json_array_get(f, j), (int)i, &(*out)[k++]);
    }
    if (k < total)
        plat_fill(st, J, &(*out)[k]);
    *n = (int)total;
    return SM_OK;
}

/* The request field of a core support field (K -> stiffness ...). */
static const char *sup_field(const char *f)
{
    static const char *const map[][2] = {{"K", "stiffness"},
                                         {"M", "added_mass"},
                                         {"k_per_length", "stiffness_per_length"},
                                         {"added_mass_per_length", "added_mass_per_length"},
                                         {"from_s", "from_s"},
                                         {"to_s", "to_s"},
                                         {"joint", "joint"}};
    size_t k;

    for (k = 0; k < sizeof(map) / sizeof(map[0]); k++)
        if (!strcmp(f, map[k][0]))
            return map[k][1];
    return NULL;
}

char *sup_pointer(const json_t *st, int index, const char *field)
{
    const json_t *mems = json_object_get(st, "members"), *x, *f;
    const char *rf = sup_field(field);
    size_t i, ns = json_array_size(json_object_get(st, "springs")), k;
    char *base = NULL, *p;

    if (index >= 0 && (size_t)index < ns) {
        base = err_ptr_idx("/structure/springs", (size_t)index);
    } else if (index >= 0) {
        k = (size_t)index - ns;
        json_array_foreach(mems, i, x) {
            f = json_object_get(x, "foundation");
            if (k < sup_stretches(f)) {
                base = json_is_object(f) ? err_fmt("/structure/members/%zu/foundation", i)
                                         : err_fmt("/structure/members/%zu/foundation/%zu", i, k);
                break;
            }
            k -= sup_stretches(f);
        }
    }
    if (!base && plat_base_free(st))
        return plat_pointer(st, field);
    if (!base)
        return strdup(ns ? "/structure/springs" : "/structure/members");
    if (!rf)
        return base;
    p = err_ptr_key(base, rf);
    free(base);
    return p;
}
