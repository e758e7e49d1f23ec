/*
 * elastodyn.c — ElastoDyn mode-shape coefficients (DESIGN §B "ElastoDyn polynomial fit",
 * DESIGN.md 9.3): which mode is flap 1, flap 2, edge 1 (or a tower's fore-aft and
 * side-side modes), and the sixth-order polynomial ElastoDyn reads for each.
 *
 * How it fits: three layers, each a caller of the one below.
 *   sm_elastodyn_fit        one shape y(x) -> C2..C6, residuals, tip-slope error.
 *   sm_elastodyn_fit_modes  a case's modes projected on two bending directions (a, b) and
 *                           their energy split (labels.c) -> the lowest modes dominated by
 *                           a and by b, each fitted.  Knows nothing of blades or towers:
 *                           the blade below and a tower caller fill sm_ed_shapes.
 *   sm_elastodyn_blade      a model member and a solved case -> sm_ed_shapes in the
 *                           member's principal axes (flap p3, edge p2) -> want {2, 1}.
 * The codec (server/codec/elastodyn_text.c) fills sm_ed_shapes from a stored result
 * document the same way, so the daemon and the CLI give the core's numbers.
 *
 * The fit (DESIGN §B): x = distance from the flexible root / flexible length, y divided by
 * its signed tip value, unweighted least squares
 *   min || A c - b ||,  A[j][k] = x_j^(k+2) - x_j^6 (k = 0..3),  b_j = y_j/y_tip - x_j^6,
 * then C6 = 1 - (C2 + ... + C5), so phi(0) = phi'(0) = 0 and phi(1) = 1 hold by
 * construction.  A is at most a few hundred rows by 4: LAPACK's dgels (QR), never the normal
 * equations (cond(A'A) ~ 1e8 on this basis).  Helpers are ed_*.
 */
#include "spinmodal.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ED_TERMS 4    /* unknowns C2..C5 */
#define ED_MAX_WANT 8 /* modes per direction a caller may ask for */

double sm_elastodyn_eval(const double coef[5], double x, double *slope)
{
    double phi = 0, d = 0, p = x; /* p = x^(k-1) */
    int k;

    for (k = 2; k <= 6; k++) {
        d += k * coef[k - 2] * p; /* phi' = sum k C_k x^(k-1) */
        p *= x;
        phi += coef[k - 2] * p; /* phi = sum C_k x^k */
    }
    if (slope)
        *slope = d;
    return phi;
}

/* Checks of sm_elastodyn_fit's input: n >= 4, x in [0, 1] and finite, the last x 1, the tip
 * value finite and nonzero. */
static int ed_fit_check(int n, const double *x, const double *y)
{
    int j;

    if (n < ED_TERMS || !x || !y || x[n - 1] != 1.0 || !isfinite(y[n - 1]) || y[n - 1] == 0)
        return SM_INVALID_INPUT;
    for (j = 0; j < n; j++)
        if (!(x[j] >= 0 && x[j] <= 1) || !isfinite(y[j]))
            return SM_INVALID_INPUT;
    return SM_OK;
}

/* Residuals and tip slopes of a solved fit (coef filled). */
static void ed_fit_quality(int n, const double *x, const double *y, double tip_slope,
                           sm_ed_fit *fit)
{
    double ss = 0, r;
    int j;

    fit->max_residual = 0;
    for (j = 0; j < n; j++) {
        r = sm_elastodyn_eval(fit->coef, x[j], NULL) - y[j] / fit->tip;
        ss += r * r;
        if (fabs(r) > fit->max_residual)
            fit->max_residual = fabs(r);
    }
    fit->rms = sqrt(ss / n);
    sm_elastodyn_eval(fit->coef, 1.0, &fit->tip_slope_fit);
    fit->tip_slope_fe = isfinite(tip_slope) ? tip_slope / fit->tip : NAN;
    fit->tip_slope_error = isfinite(fit->tip_slope_fe) && fit->tip_slope_fe != 0
                               ? (fit->tip_slope_fit - fit->tip_slope_fe) / fabs(fit->tip_slope_fe)
                               : NAN;
}

int sm_elastodyn_fit(int n, const double *x, const double *y, double tip_slope, sm_ed_fit *fit)
{
    double *A = NULL, *b = NULL, x6;
    int j, k, rc, info;

    memset(fit, 0, sizeof *fit);
    fit->mode = -1;
    fit->share = NAN;
    rc = ed_fit_check(n, x, y);
    if (rc)
        return rc;
    fit->tip = y[n - 1];
    A = malloc((size_t)n * ED_TERMS * sizeof *A);
    b = malloc((size_t)n * sizeof *b);
    if (!A || !b) {
        rc = SM_NOMEM;
        goto done;
    }
    for (j = 0; j < n; j++) {
        x6 = pow(x[j], 6);
        for (k = 0; k < ED_TERMS; k++) /* A[j][k] = x^(k+2) - x^6, column-major */
            A[(size_t)k * n + j] = pow(x[j], k + 2) - x6;
        b[j] = y[j] / fit->tip - x6; /* b = y/y_tip - x^6 */
    }
    /* c = argmin || A c - b || (QR); the solution is b[0..3] */
    info = LAPACKE_dgels(LAPACK_COL_MAJOR, 'N', n, ED_TERMS, 1, A, n, b, n);
    if (info != 0) {
        rc = info > 0 ? SM_SINGULAR : SM_LAPACK_FAILED;
        goto done;
    }
    fit->coef[4] = 1.0;
    for (k = 0; k < ED_TERMS; k++) {
        fit->coef[k] = b[k];
        fit->coef[4] -= b[k]; /* C6 = 1 - (C2 + ... + C5) */
    }
    ed_fit_quality(n, x, y, tip_slope, fit);
done:
    free(A);
    free(b);
    return rc;
}

/* 1 when mode k is a candidate for direction d (0: a, 1: b): its kinetic energy in d above
 * the other direction's, and its kinetic bending above its axial plus torsion. */
static int ed_dominated(const sm_ed_shapes *s, int k, int d)
{
    const double *e = s->energy + (size_t)k * SM_ENERGY_PARTS;
    double a = e[s->part[d]], b = e[s->part[1 - d]];
    double other = e[SM_MODE_AXIAL] + e[SM_MODE_TORSION];

    return a > b && a + b > other;
}

/* Mode k, direction d as a real shape into y[n_nodes] (turned so that the tip value is real:
 * y = Re(z conj(z_tip)) / |z_tip|), and its tip slope the same way (NaN when none). */
static void ed_real_shape(const sm_ed_shapes *s, int k, int d, double *y, double *slope)
{
    size_t o = (size_t)(2 * k + d) * (size_t)s->n_nodes, t = o + (size_t)s->n_nodes - 1;
    double tr = s->re[t], ti = s->im ? s->im[t] : 0, m = hypot(tr, ti), cr, ci;
    int j;

    cr = m > 0 ? tr / m : 1; /* conj(z_tip)/|z_tip| = cr - i ci */
    ci = m > 0 ? ti / m : 0;
    for (j = 0; j < s->n_nodes; j++)
        y[j] = s->re[o + j] * cr + (s->im ? s->im[o + j] * ci : 0);
    *slope = NAN;
    if (s->slope_re)
        *slope = s->slope_re[2 * k + d] * cr + (s->slope_im ? s->slope_im[2 * k + d] * ci : 0);
}

/* Fit mode k in direction d into *fit, with its strain-energy share. */
static int ed_fit_mode(const sm_ed_shapes *s, int k, int d, double *y, sm_ed_fit *fit)
{
    const double *e = s->energy + (size_t)k * SM_ENERGY_PARTS + SM_ENERGY_PARTS / 2;
    double slope, bend = e[s->part[0]] + e[s->part[1]];
    int rc;

    ed_real_shape(s, k, d, y, &slope);
    rc = sm_elastodyn_fit(s->n_nodes, s->x, y, slope, fit);
    if (rc)
        return rc;
    fit->mode = k;
    fit->direction = d;
    fit->share = bend > 0 ? e[s->part[d]] / bend : NAN;
    fit->warning = !(fit->share >= SM_ED_CLEAN);
    return SM_OK;
}

int sm_elastodyn_fit_modes(const sm_ed_shapes *s, const int want[2], sm_ed_fit *fits)
{
    int d, k, got, slot = 0, rc = SM_OK;
    double *y;

    for (d = 0; d < 2; d++)
        if (want[d] < 0 || want[d] > ED_MAX_WANT || s->part[d] < SM_MODE_EDGE ||
            s->part[d] > SM_MODE_FLAP)
            return SM_INVALID_INPUT;
    if (s->part[0] == s->part[1] || !s->x || !s->re || !s->energy || s->n_nodes < ED_TERMS ||
        s->n_modes < 0)
        return SM_INVALID_INPUT;
    y = malloc((size_t)s->n_nodes * sizeof *y);
    if (!y)
        return SM_NOMEM;
    for (d = 0; d < 2 && rc == SM_OK; d++) {
        for (got = 0, k = 0; k < s->n_modes && got < want[d] && rc == SM_OK; k++)
            if (ed_dominated(s, k, d))
                rc = ed_fit_mode(s, k, d, y, &fits[slot + got++]);
        for (; got < want[d]; got++) { /* no qualifying mode left */
            memset(&fits[slot + got], 0, sizeof fits[0]);
            fits[slot + got].mode = -1;
            fits[slot + got].direction = d;
        }
        slot += want[d];
    }
    free(y);
    return rc;
}

/* Combination y = ca x mode k + cb x mode k1 of one array of the shapes (stride per mode
 * `per`, offset o within a mode) into out[len]. */
static void ed_combine(const double *v, size_t per, int k, int k1, double ca, double cb, size_t len,
                       double *out)
{
    size_t j;

    for (j = 0; j < len; j++)
        out[j] = ca * v[(size_t)k * per + j] + cb * v[(size_t)k1 * per + j];
}

/* Mode k's shape (both directions), slopes and energy from its displacements, scaled. */
static void ed_degenerate_store(sm_ed_shapes *s, int k, const double *y, const double *yi,
                                const double *sl, const double *sli, double ax_to)
{
    size_t n2 = 2 * (size_t)s->n_nodes, j;
    double big = 0, sa = 0, sb = 0, *e = (double *)s->energy + (size_t)k * SM_ENERGY_PARTS;
    int h;

    for (j = 0; j < n2; j++)
        big = fmax(big, fabs(y[j]));
    big = big > 0 ? big : 1;
    for (j = 0; j < n2; j++) {
        ((double *)s->re)[(size_t)k * n2 + j] = y[j] / big;
        if (s->im)
            ((double *)s->im)[(size_t)k * n2 + j] = yi[j] / big;
        if (j < (size_t)s->n_nodes)
            sa += y[j] * y[j];
        else
            sb += y[j] * y[j];
    }
    for (h = 0; h < 2; h++) {
        if (s->slope_re)
            ((double *)s->slope_re)[2 * k + h] = sl[h] / big;
        if (s->slope_im)
            ((double *)s->slope_im)[2 * k + h] = sli[h] / big;
    }
    for (h = 0; h < SM_ENERGY_PARTS; h += SM_ENERGY_PARTS / 2) { /* kinetic, then strain */
        double rest = 1 - ax_to;
        e[h + SM_MODE_AXIAL] = e[h + SM_MODE_TORSION] = ax_to / 2;
        e[h + s->part[0]] = sa + sb > 0 ? rest * sa / (sa + sb) : 0;
        e[h + s->part[1]] = sa + sb > 0 ? rest * sb / (sa + sb) : 0;
    }
}

/* Rotate the pair k, k + 1 (the declaration of sm_elastodyn_degenerate); 1 when done. */
static int ed_degenerate_pair(sm_ed_shapes *s, int k, double *buf)
{
    size_t n = (size_t)s->n_nodes, n2 = 2 * n, tip = n - 1;
    const double *re = s->re;
    double a0 = re[(size_t)k * n2 + tip], b0 = re[(size_t)k * n2 + n + tip];
    double a1 = re[(size_t)(k + 1) * n2 + tip], b1 = re[(size_t)(k + 1) * n2 + n + tip];
    double det = a0 * b1 - a1 * b0, c[2][2] = {{b1, -b0}, {a1, -a0}};
    double sl[2][2] = {{0, 0}, {0, 0}}, sli[2][2] = {{0, 0}, {0, 0}};
    const double *e0 = s->energy + (size_t)k * SM_ENERGY_PARTS, *e1 = e0 + SM_ENERGY_PARTS;
    double ax_to =
        fmin(e0[SM_MODE_AXIAL] + e0[SM_MODE_TORSION], e1[SM_MODE_AXIAL] + e1[SM_MODE_TORSION]);
    double *y = buf, *yi = buf + 2 * n2;
    int r;

    if (!(fabs(det) > 1e-12 * (fabs(a0 * b1) + fabs(a1 * b0))))
        return 0;             /* both already along one direction: nothing to separate */
    for (r = 0; r < 2; r++) { /* r = 0: b-tip zero (pure a); r = 1: a-tip zero (pure b) */
        ed_combine(s->re, n2, k, k + 1, c[r][0], c[r][1], n2, y + r * n2);
        if (s->im)
            ed_combine(s->im, n2, k, k + 1, c[r][0], c[r][1], n2, yi + r * n2);
        if (s->slope_re)
            ed_combine(s->slope_re, 2, k, k + 1, c[r][0], c[r][1], 2, sl[r]);
        if (s->slope_im)
            ed_combine(s->slope_im, 2, k, k + 1, c[r][0], c[r][1], 2, sli[r]);
    }
    for (r = 0; r < 2; r++)
        ed_degenerate_store(s, k + r, y + r * n2, yi + r * n2, sl[r], sli[r], ax_to);
    return 1;
}

int sm_elastodyn_degenerate(sm_ed_shapes *s, const double *freq)
{
    double *buf;
    int k, got = 0;

    if (!s || !freq || !s->re || !s->energy || s->n_nodes < 1 || s->n_modes < 2)
        return 0;
    buf = calloc((size_t)8 * (size_t)s->n_nodes, sizeof *buf);
    if (!buf)
        return 0;
    for (k = 0; k + 1 < s->n_modes; k++)
        if (freq[k + 1] > 0 && fabs(freq[k + 1] - freq[k]) < SM_ED_DEGENERATE * freq[k + 1] &&
            ed_degenerate_pair(s, k, buf)) {
            got++;
            k++;
        }
    free(buf);
    return got;
}

/* The principal edge (p2) and flap (p3) directions at a node: the member's e2, e3 turned by
 * the twist t about e1 (p2 = cos t e2 + sin t e3, p3 = -sin t e2 + cos t e3). */
static void ed_principal(const double ax[9], double t, double p2[3], double p3[3])
{
    int i;

    for (i = 0; i < 3; i++) {
        p2[i] = cos(t) * ax[3 + i] + sin(t) * ax[6 + i];
        p3[i] = -sin(t) * ax[3 + i] + cos(t) * ax[6 + i];
    }
}

static double ed_dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void sm_elastodyn_project(int n, const double ax[9], const double *twist, double length,
                          const double *rows, double *out, double slope[2])
{
    double p2[3] = {0, 0, 0}, p3[3] = {0, 0, 0};
    const double *u;
    int j;

    slope[0] = slope[1] = 0;
    if (n < 1)
        return;
    for (j = 0; j < n; j++) {
        ed_principal(ax, twist[j], p2, p3);
        u = rows + (size_t)6 * (size_t)j;
        out[j] = ed_dot(u, p3);     /* flap w = p3.u */
        out[n + j] = ed_dot(u, p2); /* edge v = p2.u */
    }
    /* at the tip: dw/dx = -L p2.r, dv/dx = L p3.r */
    slope[0] = -length * ed_dot(rows + (size_t)6 * (size_t)(n - 1) + 3, p2);
    slope[1] = length * ed_dot(rows + (size_t)6 * (size_t)(n - 1) + 3, p3);
}

/* Gather the member's node rows of one shape (6 values a node) and project them. */
static void ed_project(const double *shape, int n, const int *nodes, const double *tw,
                       const double ax[9], double L, double *rows, double *out, double *slope)
{
    int j;

    for (j = 0; j < n; j++)
        memcpy(rows + (size_t)6 * (size_t)j, shape + (size_t)6 * (size_t)nodes[j],
               6 * sizeof *rows);
    sm_elastodyn_project(n, ax, tw, L, rows, out, slope);
}

/* The member's nodes, span fractions, twists, axes and length into the caller's arrays (n
 * each, allocated here).  Returns the node count or a status < 0. */
static int ed_member(const sm_model *m, int member, int **nodes, double **x, double **tw,
                     double ax[9], double *L)
{
    int n = sm_model_member_nodes(m, member, 0, NULL, NULL, NULL);
    double a[3], b[3];

    if (n < ED_TERMS)
        return n < 0 ? n : SM_INVALID_INPUT;
    *nodes = malloc((size_t)n * sizeof **nodes);
    *x = malloc((size_t)n * sizeof **x);
    *tw = malloc((size_t)n * sizeof **tw);
    if (!*nodes || !*x || !*tw)
        return SM_NOMEM;
    if (sm_model_member_nodes(m, member, n, *nodes, *x, *tw) != n ||
        sm_model_member_axes(m, member, ax) != SM_OK)
        return SM_INVALID_INPUT;
    sm_model_node_position3(m, (*nodes)[0], a);
    sm_model_node_position3(m, (*nodes)[n - 1], b);
    *L = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
              (b[2] - a[2]) * (b[2] - a[2]));
    (*x)[n - 1] = 1.0; /* the tip is x = 1 exactly */
    return n;
}

int sm_elastodyn_blade(const sm_model *m, const sm_case *c, int member,
                       sm_ed_fit fits[SM_ED_BLADE_FITS])
{
    static const int want[2] = {2, 1};
    sm_model_info info;
    sm_ed_shapes s;
    int *nodes = NULL, n, k, rc;
    double *x = NULL, *tw = NULL, *re = NULL, *im = NULL, *sr = NULL, *si = NULL, ax[9], L;
    double *rows = NULL;
    size_t stride;

    sm_model_get_info(m, &info);
    if (!info.spatial || !c->shape_re || !c->energy || c->n_modes < 1)
        return SM_INVALID_INPUT;
    rc = n = ed_member(m, member, &nodes, &x, &tw, ax, &L);
    if (n < 0)
        goto done;
    stride = (size_t)6 * (size_t)c->n_nodes;
    re = malloc((size_t)c->n_modes * 2 * (size_t)n * sizeof *re);
    im = c->shape_im ? malloc((size_t)c->n_modes * 2 * (size_t)n * sizeof *im) : NULL;
    sr = malloc((size_t)c->n_modes * 2 * sizeof *sr);
    si = malloc((size_t)c->n_modes * 2 * sizeof *si);
    rows = malloc((size_t)6 * (size_t)n * sizeof *rows);
    rc = SM_NOMEM;
    if (!re || !sr || !si || !rows || (c->shape_im && !im))
        goto done;
    for (k = 0; k < c->n_modes; k++) {
        ed_project(c->shape_re + k * stride, n, nodes, tw, ax, L, rows, re + (size_t)2 * k * n,
                   sr + 2 * k);
        if (im)
            ed_project(c->shape_im + k * stride, n, nodes, tw, ax, L, rows, im + (size_t)2 * k * n,
                       si + 2 * k);
    }
    s = (sm_ed_shapes){
        c->n_modes, n, x, re, im, sr, im ? si : NULL, c->energy, {SM_MODE_FLAP, SM_MODE_EDGE}};
    rc = sm_elastodyn_fit_modes(&s, want, fits);
done:
    free(nodes);
    free(x);
    free(tw);
    free(re);
    free(im);
    free(sr);
    free(si);
    free(rows);
    return rc < 0 ? rc : SM_OK;
}
