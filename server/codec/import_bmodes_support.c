/*
 * import_bmodes_support.c — a BModes tower's support (DESIGN.md 8.6): the lines after el_loc
 * (tow_support 0; 1 guy wires: n_attachments, n_wires, node_attach, wire_stfness, th_wire; 2 a
 * platform or monopile: draft, cm_pform, mass_pform, the inertia, ref_msl, hydro_M, hydro_K,
 * mooring_K, the distributed added mass and stiffness BModes v3.00 reads and does not use), read
 * as BModes.f90 reads them, and their parts of the tower form ("wires", "platform").
 *
 * How it fits: import_bmodes.c reads the .bmi up to el_loc and calls bm_support, then builds the
 * tower's request and calls bm_tower_wires and bm_tower_platform (import_bmodes.h).
 */
#include "import_bmodes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/*
 * Tension wires (tow_support 1, BModes.f90:573-611): a comment line, n_attachments, then one line
 * each of n_wires, node_attach, wire_stfness, th_wire with n_attachments numbers, checked as
 * BModes checks them (n_wires >= 3, 1 < node_attach <= nselt + 1, th_wire 0..90 deg).
 */
static int bm_wires(bm_in *b, bm_main *m)
{
    static const char *const name[4] = {"n_wires", "node_attach", "wire_stfness", "th_wire"};
    imp_tok t[IMP_MAX_TOKENS];
    int st, k, i, n;
    double x;

    if ((st = bm_com(b, "tension-wires data")) ||
        (st = bm_int(b, "n_attachments", 0, BM_MAX_WIRES, &m->n_att)))
        return st;
    for (k = 0; k < 4; k++) {
        if (!imp_next_nonblank(&b->r))
            return bm_ends(b, name[k]);
        n = imp_split(b->r.s, b->r.n, ",", t, IMP_MAX_TOKENS);
        if (n < m->n_att)
            return imp_fail(b->d, b->file, b->r.line, name[k],
                            "%ld numbers expected "
                            "(n_attachments), got %d",
                            m->n_att, n);
        for (i = 0; i < m->n_att; i++) {
            if ((st = imp_value(b->d, b->file, b->r.line, name[k], &t[i], IMP_NONNEG, &x)))
                return st;
            if ((k == 0 && (x != floor(x) || x < 3)) ||
                (k == 1 && (x != floor(x) || x <= 1 || x > (double)m->nselt + 1)) ||
                (k == 3 && x > 90))
                return imp_fail(b->d, b->file, b->r.line, name[k], "%.15g: %s", x,
                                k == 0   ? "must be an integer, 3 or more (BModes.f90:598)"
                                : k == 1 ? "must be an integer node number above 1 and at most "
                                           "nselt + 1 (BModes.f90:599-600)"
                                         : "must be 0 to 90 degrees (BModes.f90:601)");
            m->wire[k][i] = x;
        }
    }
    return SM_OK;
}

/* n numbers of the next non-blank line (ReadAry) into x[0], x[step] ...; SM_OK or the error. */
static int bm_row(bm_in *b, const char *field, int n, int step, double *x)
{
    imp_tok t[IMP_MAX_TOKENS];
    int i, st, got;

    if (!imp_next_nonblank(&b->r))
        return bm_ends(b, field);
    got = imp_split(b->r.s, b->r.n, ",", t, IMP_MAX_TOKENS);
    if (got < n)
        return imp_fail(b->d, b->file, b->r.line, field, "%d numbers expected, got %d", n, got);
    for (i = 0; i < n; i++)
        if ((st = imp_value(b->d, b->file, b->r.line, field, &t[i], IMP_ANY, &x[i * step])))
            return st;
    return SM_OK;
}

/* Six rows of a 6x6 (after its comment line) into a, row-major. */
static int bm_six(bm_in *b, const char *field, double *a)
{
    int st = bm_com(b, field), i;

    for (i = 0; !st && i < 6; i++)
        st = bm_row(b, field, 6, 1, a + 6 * i);
    return st;
}

/*
 * The platform (tow_support 2, BModes.f90:510-571): draft, cm_pform, mass_pform, the 3x3
 * inertia about the c.m., ref_msl, hydro_M, hydro_K, mooring_K (6x6 over surge, sway, heave,
 * roll, pitch, yaw = the tower axes fa, ss, up), then the distributed added mass and stiffness
 * (read: BModes v3.00 reads them and never uses them).  radius becomes the length from the
 * tower's base, radius + draft, as BModes makes it (BModes.f90:616).
 */
static int bm_platform(bm_in *b, bm_main *m)
{
    static const char *const mats[3] = {"hydro_M", "hydro_K", "mooring_K"};
    double dummy[1];
    int st, k, i;

    m->platform = 1;
    if ((st = bm_num(b, "draft", IMP_ANY, &m->draft)) ||
        (st = bm_num(b, "cm_pform", IMP_ANY, &m->cm_pform)) ||
        (st = bm_num(b, "mass_pform", IMP_NONNEG, &m->pf[0][0])) ||
        (st = bm_com(b, "platform inertia matrix")))
        return st;
    m->pf[0][7] = m->pf[0][14] = m->pf[0][0];
    for (i = 0; i < 3; i++)
        if ((st = bm_row(b, "i_matrix_pform", 3, 1, &m->pf[0][6 * (3 + i) + 3])))
            return st;
    if ((st = bm_num(b, "ref_msl", IMP_ANY, &m->ref_msl)))
        return st;
    for (k = 0; k < 3; k++)
        if ((st = bm_six(b, mats[k], m->pf[k + 1])))
            return st;
    for (k = 0; k < 2; k++) {
        if ((st = bm_com(b, "blank line")) || (st = bm_com(b, "distributed data")) ||
            (st = bm_int(b, k ? "n_secs_k_distr" : "n_secs_m_distr", 0, 100000, &m->n_distr[k])))
            return st;
        for (i = 0; i < 2; i++)
            if ((st = bm_row(b, k ? "distr_k" : "distr_m", 0, 1, dummy)))
                return st;
    }
    for (k = 0; k < 4; k++) /* symmetric: (a + a^T) / 2, the asymmetry kept for a warning */
        for (i = 0; i < 36; i++) {
            double *x = &m->pf[k][i], *y = &m->pf[k][6 * (i % 6) + i / 6];
            m->asym[k] = fmax(m->asym[k], fabs(*x - *y));
            *x = *y = 0.5 * (*x + *y);
        }
    m->radius += m->draft;
    return SM_OK;
}

/*
 * A tower's support (BModes.f90:503-612, read after el_loc): tow_support 0 (none), 1 (tension
 * guy wires, bm_wires) and 2 (a platform or a monopile's 6x6 at the base, bm_platform).  A
 * blade has no such lines.
 */
int bm_support(bm_in *b, bm_main *m)
{
    imp_tok t[2];
    double x;
    long ts;

    if (!m->tower) { /* a tower's file given as a blade: its support lines follow el_loc */
        while (imp_next(&b->r))
            if (imp_split(b->r.s, b->r.n, ",", t, 2) >= 2 && t[1].n >= 11 &&
                !strncmp(t[1].s, "tow_support", 11))
                return imp_fail(b->d, b->file, b->r.line, "tow_support",
                                "a tower's support "
                                "line, but beam_type (line %d) is 1 (blade): this is a tower "
                                "file; give beam_type 2 to import it as a tower",
                                m->beam_line);
        return SM_OK;
    }
    t[0].n = 0; /* ReadCom, ReadCom, ReadVar: the first token of the next line */
    if (imp_next(&b->r) && imp_next(&b->r) && imp_next_nonblank(&b->r))
        imp_split(b->r.s, b->r.n, ",", t, 1);
    else
        b->r.line++;
    if (t[0].n == 0 || imp_number(&t[0], &x))
        return imp_fail(b->d, b->file, b->r.line, "tow_support",
                        "missing: beam_type (line %d) "
                        "is 2 (tower), and a tower's file goes on after el_loc with its support "
                        "lines (tow_support, BModes.f90:503), a number here; a blade's file has "
                        "none: give beam_type 1 to import it as a blade",
                        m->beam_line);
    if (x != floor(x) || x < 0.0 || x > 2.0)
        return imp_fail(b->d, b->file, b->r.line, "tow_support",
                        "must be an integer in [0, 2] (%.15g)", x);
    ts = (long)x;
    if (ts == 1)
        return bm_wires(b, m);
    if (ts == 2 && (m->hub_conn == 2 || m->hub_conn == 3))
        return bm_platform(b, m); /* 3: held in heave and yaw (bm_tower_platform) */
    if (m->hub_conn == 1 && ts < 2)
        return SM_OK;
    return imp_fail(b->d, b->file, m->hub_conn_line, "hub_conn",
                    m->hub_conn == 2   ? "2 (free root) needs tow_support 2 (a platform): "
                                         "without one the tower has no support"
                    : m->hub_conn == 3 ? "3 (base held in heave and torsion, free laterally on "
                                         "the platform's matrices) needs tow_support 2 (the "
                                         "platform or monopile matrices)"
                                       : "1 (cantilevered) with tow_support 2: BModes adds the "
                                         "platform's matrices to the clamped root, where they "
                                         "do nothing; give hub_conn 2 (free root) or "
                                         "tow_support 0");
}

/* The rows of the row-major 6x6 a as a JSON array. */
static json_t *bm_rows(const double *a)
{
    json_t *rows = json_array();
    int i;

    for (i = 0; rows && i < 6; i++)
        if (json_array_append_new(rows, bm_vec(a + 6 * i, 6))) {
            json_decref(rows);
            return NULL;
        }
    return rows;
}

/*
 * tow_support 2 into doc's tower: "platform" {mass (mass_pform and the inertia, about the
 * c.m.), added_mass hydro_M, hydrostatic hydro_K, mooring mooring_K, reference_height
 * draft - ref_msl, mass_height draft - cm_pform} — heights above the tower's base, where the
 * tower form's height and base_height now start (radius + draft, hub_rad: BModes.f90:616);
 * BModes' platform axes (surge, sway, heave) are the tower axes (fa, ss, up): its T_pform
 * (BModes.f90:749-782) carries surge to the fore-aft displacement v.  Warnings for what
 * BModes reads and does not use.  0 or -1 (memory).
 */
int bm_tower_platform(json_t *doc, const bm_main *m)
{
    json_t *tw = json_object_get(json_object_get(doc, "request"), "tower"), *pf;
    json_t *warn = json_object_get(doc, "input_warnings");
    int k;

    if (!m->platform)
        return 0;
    pf = json_pack("{s:o, s:o, s:o, s:o, s:f, s:f}", "mass", bm_rows(m->pf[0]), "added_mass",
                   bm_rows(m->pf[1]), "hydrostatic", bm_rows(m->pf[2]), "mooring",
                   bm_rows(m->pf[3]), "reference_height", imp_round(m->draft - m->ref_msl),
                   "mass_height", imp_round(m->draft - m->cm_pform));
    if (!pf || json_object_set_new(tw, "platform", pf))
        return -1;
    /* hub_conn 3: BModes' iartic 10 (BModes.f90:917-919, BldVib.f90:450-454) frees the root's
     * lateral displacements and slopes and holds its axial displacement and twist */
    if (m->hub_conn == 3 && json_object_set_new(pf, "held", json_pack("[s, s]", "up", "r_up")))
        return -1;
    for (k = 0; k < 4; k++)
        if (m->asym[k] > 0 &&
            imp_warn(warn, "/tower/platform",
                     "%s is not symmetric (entries differ by up to %g from their transposes): "
                     "the import takes (K + K^T)/2, the symmetric part (the solver's matrices "
                     "are symmetric; BModes' eigensolver takes it as it is)",
                     k == 0   ? "i_matrix_pform"
                     : k == 1 ? "hydro_M"
                     : k == 2 ? "hydro_K"
                              : "mooring_K",
                     m->asym[k]))
            return -1;
    for (k = 0; k < 2; k++)
        if (m->n_distr[k] > 0 &&
            imp_warn(warn, "/tower/platform",
                     "%s = %ld is not used: BModes v3.00 reads the distributed %s and never "
                     "uses it (BModes.f90:551-571); the tower form's \"foundation\" takes it",
                     k ? "n_secs_k_distr" : "n_secs_m_distr", m->n_distr[k],
                     k ? "stiffness" : "added mass"))
            return -1;
    return imp_warn(warn, "/tower/height",
                    "tow_support 2: heights are measured from the tower's base (draft = %g m "
                    "below the MSL): height = radius + draft = %g m, the platform's reference "
                    "point at %g m and its c.m. at %g m",
                    m->draft, m->radius, m->draft - m->ref_msl, m->draft - m->cm_pform);
}

/*
 * The tension wires (tow_support 1) into doc's request: without own (bmodes_mesh 0) the tower
 * form's "wires", each at height hub_rad + el_loc[node_attach - 1] (radius - hub_rad) (BModes'
 * node_attach counts el_loc's boundaries from the base, BldVib.f90:668); with own, BModes' own
 * model's springs at its joint of that boundary, count stiffness cos^2(th_wire) in fore-aft (hub
 * z) and side-side (hub x), the spring BModes adds (BModes.f90:607-611, BldVib.f90:667-674).
 * 0 or -1 (memory).
 */
int bm_tower_wires(json_t *doc, const bm_main *m, const json_t *el_loc, int own)
{
    json_t *req = json_object_get(doc, "request"), *arr = json_array();
    long i;

    if (!arr)
        return -1;
    for (i = 0; i < m->n_att; i++) {
        size_t node = (size_t)m->wire[1][i] - 1;
        double x = json_number_value(json_array_get(el_loc, node)), c, k[3];
        char name[32];
        json_t *w;
        if (!own) {
            w = json_pack("{s:f, s:I, s:f, s:f}", "height",
                          imp_round(m->hub_rad + x * (m->radius - m->hub_rad)), "count",
                          (json_int_t)m->wire[0][i], "stiffness", m->wire[2][i], "angle_deg",
                          m->wire[3][i]);
        } else {
            c = cos(m->wire[3][i] * 0.017453292519943295769);
            k[0] = k[2] = m->wire[0][i] * m->wire[2][i] * c * c;
            k[1] = 0.0;
            if (node + 1 == json_array_size(el_loc))
                snprintf(name, sizeof name, "top");
            else
                snprintf(name, sizeof name, "x%zu", node);
            w = json_pack("{s:s, s:{s:[f, f, f]}}", "joint", name, "stiffness", "translational",
                          k[0], k[1], k[2]);
        }
        if (!w || json_array_append_new(arr, w)) {
            json_decref(arr);
            return -1;
        }
    }
    if (!m->n_att) {
        json_decref(arr);
        return 0;
    }
    return json_object_set_new(own ? json_object_get(req, "structure")
                                   : json_object_get(req, "tower"),
                               own ? "springs" : "wires", arr)
               ? -1
               : 0;
}
