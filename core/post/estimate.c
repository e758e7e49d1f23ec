/*
 * estimate.c — an error bar on every frequency (DESIGN.md 9): the same request solved on
 * refined discretisations, modes matched level to level by MAC, Richardson extrapolation.
 *
 * How it fits: after sm_solve, a caller that wants error bars calls sm_estimate with the
 * model, its structure and options and the result.  Level L has every member's elements
 * x 2^L (element length h/2^L) and, where frames are not tied to the elements, frames x 2^L
 * (est_refine), so every level is the same beam model and the levels differ only in h.
 * The refined results are read one level at a time: each case keeps the frequencies of the
 * matched modes and their shapes on the nodes of the base model (est_chain), so the memory
 * held beside the caller's result is one refined sm_result plus those compact shapes.
 * Matching is a greedy assignment by MAC (largest first), chained 0 -> 1 -> 2, on the base
 * model's nodes (found in each refined mesh by position).  Helpers are est_*.
 */
#include "spinmodal.h"

#include <complex.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EST_MAX_LEVELS 2      /* refined levels: h/2, h/4 */
#define EST_RATIO_MAX 0.70710678118654752 /* 2^-1/2: observed orders below 0.5 are not trusted */

void sm_estimate_default_options(sm_estimate_options *o)
{
    memset(o, 0, sizeof *o);
    o->levels = EST_MAX_LEVELS;
    o->min_mac = 0.5;
}

int sm_estimate_refine(const sm_structure *st, const sm_options *opt, int level,
                       sm_member *members, sm_structure *st_out, sm_options *opt_out)
{
    int f = 1 << (level > 0 ? level : 0);

    if (level < 0 || level > EST_MAX_LEVELS)
        return SM_INVALID_INPUT;
    for (int i = 0; i < st->n_members; i++) {
        members[i] = st->members[i];
        if (members[i].elements > INT_MAX / 4)
            return SM_LIMIT;
        members[i].elements *= f; /* h -> h / 2^level */
    }
    *st_out = *st;
    st_out->members = members;
    *opt_out = *opt;
    if (opt->frames == SM_FRAMES_PER_MEMBER) {
        if (opt->frames_param > INT_MAX / 4)
            return SM_LIMIT;
        opt_out->frames_param = opt->frames_param * f; /* frames x 2^level */
    }
    return SM_OK;
}

/* Fill d with status rc and a printf-style message; returns rc. */
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static int est_fail(sm_diag *d, int rc, const char *fmt, ...)
{
    va_list ap;

    if (d) {
        memset(d, 0, sizeof *d);
        d->status = rc;
        d->item_index = -1;
        va_start(ap, fmt);
        vsnprintf(d->message, sizeof d->message, fmt, ap);
        va_end(ap);
    }
    return rc;
}

/* Options of the solves of level L: refined, with shapes and room for reordered modes. */
static void est_level_options(sm_options *o, int level)
{
    o->mode_shapes = 1;
    if (level > 0)
        o->modes += 2 + o->modes / 2; /* a mode may move down the list at a finer level */
}

/* Sizes of level L into *info; SM_OK, or the first cap of est it passes (SM_LIMIT, message). */
static int est_check_level(const sm_structure *st, const sm_options *opt,
                           const sm_estimate_options *est, int level, sm_model_info *info,
                           sm_diag *d)
{
    sm_member *mem = malloc((size_t)st->n_members * sizeof *mem);
    sm_structure rs;
    sm_options ro;
    int rc, dofs;

    if (!mem)
        return SM_NOMEM;
    rc = sm_estimate_refine(st, opt, level, mem, &rs, &ro);
    if (rc == SM_LIMIT)
        est_fail(d, rc, "the model refined for the error estimate would have more than %d "
                 "elements in one member", INT_MAX / 4);
    est_level_options(&ro, level);
    if (rc == SM_OK)
        rc = sm_structure_check(&rs, &ro, info, d);
    free(mem);
    if (rc != SM_OK)
        return rc;
    dofs = info->node_dof * info->max_frame_nodes;
    if (est->max_elements > 0 && info->elements > est->max_elements)
        return est_fail(d, SM_LIMIT, "the model refined for the error estimate (%s) would have "
                        "%d FE elements, more than the limit of %d", level > 1 ? "h/4" : "h/2",
                        info->elements, est->max_elements);
    if (est->max_frame_dofs > 0 && dofs > est->max_frame_dofs)
        return est_fail(d, SM_LIMIT, "the model refined for the error estimate (%s) would have "
                        "%d degrees of freedom in one reference frame, more than the limit of "
                        "%d", level > 1 ? "h/4" : "h/2", dofs, est->max_frame_dofs);
    if (est->max_coordinates > 0 && !info->structured && info->coordinates > est->max_coordinates)
        return est_fail(d, SM_LIMIT, "the model refined for the error estimate (%s) would have "
                        "%d modal coordinates on the dense solvers, more than the limit of %d",
                        level > 1 ? "h/4" : "h/2", info->coordinates, est->max_coordinates);
    return SM_OK;
}

int sm_estimate_plan(const sm_structure *st, const sm_options *opt,
                     const sm_estimate_options *est, int *levels, sm_model_info *finest,
                     sm_diag *diag)
{
    sm_diag scratch, keep;
    sm_diag *d = diag ? diag : &scratch;
    sm_model_info info;
    int want = est->levels < 1 ? 1 : est->levels > EST_MAX_LEVELS ? EST_MAX_LEVELS : est->levels;

    *levels = 0;
    if (opt && opt->basis == SM_BASIS_PAPER) {
        est_fail(d, SM_INVALID_INPUT, "the paper basis does not converge to the beam model as "
                 "frames are added (DESIGN.md 1.2): no error estimate for it; use the augmented "
                 "basis");
        d->item = SM_ITEM_OPTIONS;
        snprintf(d->field, sizeof d->field, "substructure_modes");
        return SM_INVALID_INPUT;
    }
    for (int l = 1; l <= want; l++) {
        int rc = est_check_level(st, opt, est, l, &info, l == 1 ? d : &keep);
        if (rc == SM_LIMIT && l > 1)
            break;  /* h/2 fits: two levels and the theoretical order */
        if (rc != SM_OK)
            return rc;
        *levels = l;
        if (finest)
            *finest = info;
    }
    return SM_OK;
}

/* ---------------------------------------------------------- node map */

/* Sort order of node indices by x (est_map_nodes). */
typedef struct est_xnode {
    double x[3];
    int node;
} est_xnode;

static int est_cmp_x(const void *a, const void *b)
{
    double p = ((const est_xnode *)a)->x[0], q = ((const est_xnode *)b)->x[0];
    return (p > q) - (p < q);
}

/*
 * map[k] = the node of fine at the undeformed position of node k of base (every node of a
 * mesh is a node of its refinement).  Nodes sorted by x, then a window of width tol.
 * Returns SM_OK, SM_NOMEM, or SM_INVALID_INPUT when a node has no partner.
 */
static int est_map_nodes(const sm_model *base, const sm_model *fine, int *map)
{
    sm_model_info ib, iff;
    est_xnode *xs;
    double ext = 0, tol;
    int rc = SM_OK;

    sm_model_get_info(base, &ib);
    sm_model_get_info(fine, &iff);
    xs = malloc((size_t)iff.nodes * sizeof *xs);
    if (!xs)
        return SM_NOMEM;
    for (int k = 0; k < iff.nodes; k++) {
        sm_model_node_position3(fine, k, xs[k].x);
        xs[k].node = k;
        for (int c = 0; c < 3; c++)
            ext = fmax(ext, fabs(xs[k].x[c]));
    }
    tol = 1e-9 * ext + 1e-300;
    qsort(xs, (size_t)iff.nodes, sizeof *xs, est_cmp_x);
    for (int k = 0; k < ib.nodes && rc == SM_OK; k++) {
        double p[3];
        int lo = 0, hi = iff.nodes, best = -1;
        double bd = tol;
        sm_model_node_position3(base, k, p);
        while (lo < hi) { /* first node with x >= p.x - tol */
            int mid = lo + (hi - lo) / 2;
            if (xs[mid].x[0] < p[0] - tol)
                lo = mid + 1;
            else
                hi = mid;
        }
        for (int j = lo; j < iff.nodes && xs[j].x[0] <= p[0] + tol; j++) {
            double dd = fmax(fabs(xs[j].x[1] - p[1]), fabs(xs[j].x[2] - p[2]));
            if (dd <= bd) {
                bd = dd;
                best = xs[j].node;
            }
        }
        map[k] = best;
        if (best < 0)
            rc = SM_INVALID_INPUT;
    }
    free(xs);
    return rc;
}

/* ------------------------------------------------ shapes and matching */

/* Mode j of case c on the base nodes (map, nb of them) as one complex vector v (dof*nb). */
static void est_compact(const sm_case *c, int j, const int *map, int nb, double complex *v)
{
    int dof = c->node_dof;
    size_t stride = (size_t)dof * (size_t)c->n_nodes, at = (size_t)j * stride;

    for (int k = 0; k < nb; k++)
        for (int d = 0; d < dof; d++) {
            size_t i = at + (size_t)dof * (size_t)map[k] + (size_t)d;
            v[(size_t)dof * k + d] = c->shape_re[i] + (c->shape_im ? c->shape_im[i] : 0.0) * _Complex_I;
        }
}

/* MAC = |a^H b|^2 / (a^H a)(b^H b) of two vectors of length n; 0 for a zero vector. */
static double est_mac(const double complex *a, const double complex *b, size_t n)
{
    double complex dot = 0;
    double na = 0, nb = 0;

    for (size_t i = 0; i < n; i++) {
        dot += conj(a[i]) * b[i];
        na += creal(conj(a[i]) * a[i]);
        nb += creal(conj(b[i]) * b[i]);
    }
    return na > 0 && nb > 0 ? creal(dot * conj(dot)) / (na * nb) : 0.0;
}

/*
 * Greedy assignment by MAC, largest first: pick[k] = the mode of cur (nc modes, vectors in
 * cv) matched to prev mode k (np modes, pv; alive[k] == 0 skips it), or -1 when none with a
 * MAC >= min_mac is left.  mac: np*nc scratch.
 */
static void est_match(const double complex *pv, const int *alive, int np,
                      const double complex *cv, int nc, size_t len, double min_mac,
                      double *mac, int *pick)
{
    for (int k = 0; k < np; k++) {
        pick[k] = -1;
        for (int j = 0; j < nc; j++)
            mac[(size_t)k * nc + j] = alive[k] ? est_mac(pv + k * len, cv + j * len, len) : -1;
    }
    for (int t = 0; t < np && t < nc; t++) {
        int bk = -1, bj = -1;
        double best = min_mac;
        for (int k = 0; k < np; k++)
            for (int j = 0; j < nc; j++)
                if (mac[(size_t)k * nc + j] >= best) {
                    best = mac[(size_t)k * nc + j];
                    bk = k;
                    bj = j;
                }
        if (bk < 0)
            break;
        pick[bk] = bj;
        for (int j = 0; j < nc; j++)
            mac[(size_t)bk * nc + j] = -1;
        for (int k = 0; k < np; k++)
            mac[(size_t)k * nc + bj] = -1;
    }
}

/* ------------------------------------------------- Richardson */

/*
 * Estimate of |f[0] - f_inf| from the frequencies of nl + 1 levels (nl = 1 or 2), and the
 * order used.  Three levels: r = d2/d1 (d_l = f_{l-1} - f_l) in (0, 2^-1/2] is a regular
 * convergence of order p = -log2 r, and the geometric series gives f0 - f_inf = d1/(1 - r).
 * Otherwise (two levels; or r <= 0, r > 2^-1/2: not yet in the asymptotic range, or
 * round-off) the theoretical order p: |d|/(1 - 2^-p), d the larger difference.
 */
static double est_richardson(const double *f, int nl, double *order)
{
    double d1 = f[0] - f[1], d2 = nl > 1 ? f[1] - f[2] : 0, r;
    double theo = 1.0 / (1.0 - pow(2.0, -SM_ESTIMATE_ORDER));

    *order = SM_ESTIMATE_ORDER;
    if (nl < 2)
        return fabs(d1) * theo;
    r = d1 != 0 ? d2 / d1 : -1;
    if (r > 0 && r <= EST_RATIO_MAX) {
        *order = -log2(r);
        return fabs(d1) / (1.0 - r);
    }
    return fmax(fabs(d1), fabs(d2)) * theo;
}

/* ------------------------------------------------------------- driver */

/* The caller's callback seen over all solves of the estimate. */
typedef struct est_prog {
    sm_progress_fn cb;
    void *user;
    int base;          /* speeds finished by the solves before this one */
    int total;         /* speeds of all solves */
} est_prog;

static int est_solve_cb(void *user, int done, int total)
{
    est_prog *p = user;

    (void)total;
    return p->cb ? p->cb(p->user, p->base + done, p->total) : 0;
}

static int est_build_cb(void *user, int built, int frames)
{
    est_prog *p = user;

    (void)built;
    (void)frames;
    return p->cb ? p->cb(p->user, p->base, p->total) : 0;
}

/* Level `level` of st/opt built and solved at the speeds: *mo and *ro (caller frees). */
static int est_solve_level(const sm_structure *st, const sm_options *opt, int level,
                           const double *omegas, int n, est_prog *prog, sm_model **mo,
                           sm_result **ro, sm_diag *d)
{
    sm_member *mem = malloc((size_t)st->n_members * sizeof *mem);
    sm_structure rs;
    sm_options o;
    int rc;

    *mo = NULL;
    *ro = NULL;
    if (!mem)
        return SM_NOMEM;
    rc = sm_estimate_refine(st, opt, level, mem, &rs, &o);
    est_level_options(&o, level);
    if (rc == SM_OK)
        rc = sm_model_build(mo, &rs, &o, est_build_cb, prog, d);
    if (rc == SM_OK)
        rc = sm_solve(*mo, omegas, n, est_solve_cb, prog, ro, d);
    free(mem);
    prog->base += n;
    return rc;
}

/* One case along the levels: the matched modes' frequencies and last shapes. */
typedef struct est_case {
    int n;                 /* modes of the base case (0: nothing to estimate) */
    double *f;             /* (EST_MAX_LEVELS + 1) * n: frequency of mode k at level l */
    int *levels;           /* n: finest level mode k was matched at (its chain's length) */
    double complex *v;     /* n * len: its shape at that level on the base nodes */
} est_case;

/* Start the chain of case e from base case c (its nodes are the base nodes: map identity). */
static int est_start(est_case *e, const sm_case *c, const int *ident, int nb, size_t len)
{
    int n = c->status == SM_CASE_NO_EQUILIBRIUM || c->status == SM_CASE_EIGEN_FAILED ||
                    !c->shape_re ? 0 : c->n_modes;

    e->n = n;
    if (!n)
        return SM_OK;
    e->f = calloc((size_t)(EST_MAX_LEVELS + 1) * n, sizeof *e->f);
    e->levels = calloc((size_t)n, sizeof *e->levels);
    e->v = malloc((size_t)n * len * sizeof *e->v);
    if (!e->f || !e->levels || !e->v)
        return SM_NOMEM;
    for (int k = 0; k < n; k++) {
        e->f[k] = c->frequency[k];
        est_compact(c, k, ident, nb, e->v + k * len);
    }
    return SM_OK;
}

/* Extend the chain of e by case c of level `level` (nodes of the base at map). */
static int est_extend(est_case *e, const sm_case *c, int level, const int *map, int nb,
                      size_t len, double min_mac)
{
    int nc = c->n_modes, rc = SM_NOMEM;
    double complex *cv;
    double *mac;
    int *pick, *alive;

    if (!e->n || !nc || !c->shape_re || c->status == SM_CASE_NO_EQUILIBRIUM ||
        c->status == SM_CASE_EIGEN_FAILED)
        return SM_OK; /* the chains of this case end at the level before */
    cv = malloc((size_t)nc * len * sizeof *cv);
    mac = malloc((size_t)e->n * nc * sizeof *mac);
    pick = malloc((size_t)e->n * sizeof *pick);
    alive = malloc((size_t)e->n * sizeof *alive);
    if (!cv || !mac || !pick || !alive)
        goto done;
    for (int j = 0; j < nc; j++)
        est_compact(c, j, map, nb, cv + j * len);
    for (int k = 0; k < e->n; k++)
        alive[k] = e->levels[k] == level - 1;
    est_match(e->v, alive, e->n, cv, nc, len, min_mac, mac, pick);
    for (int k = 0; k < e->n; k++) {
        if (pick[k] < 0)
            continue;
        e->levels[k] = level;
        e->f[(size_t)level * e->n + k] = c->frequency[pick[k]];
        memcpy(e->v + k * len, cv + pick[k] * len, len * sizeof *cv);
    }
    rc = SM_OK;
done:
    free(cv);
    free(mac);
    free(pick);
    free(alive);
    return rc;
}

/* Estimates of case e into new arrays *est, *ord (n_modes of the base case, NaN where none). */
static int est_finish(const est_case *e, int n_modes, double **est, double **ord)
{
    *est = malloc((size_t)(n_modes ? n_modes : 1) * sizeof **est);
    *ord = malloc((size_t)(n_modes ? n_modes : 1) * sizeof **ord);
    if (!*est || !*ord)
        return SM_NOMEM;
    for (int k = 0; k < n_modes; k++) {
        double f[EST_MAX_LEVELS + 1];
        (*est)[k] = (*ord)[k] = NAN;
        if (k >= e->n || e->levels[k] < 1)
            continue;
        for (int l = 0; l <= e->levels[k]; l++)
            f[l] = e->f[(size_t)l * e->n + k];
        (*est)[k] = est_richardson(f, e->levels[k], &(*ord)[k]);
    }
    return SM_OK;
}

/* The chains of every case through levels 1..levels; the base from res, or solved again. */
static int est_run(const sm_model *m, const sm_structure *st, const sm_options *opt,
                   const double *omegas, int n, const sm_estimate_options *est, int levels,
                   est_prog *prog, const sm_result *res, est_case *ec, sm_diag *d)
{
    sm_model_info ib;
    sm_model *lm = NULL;
    sm_result *lr = NULL, *r0 = NULL;
    int *map, rc = SM_OK, nb, need0 = 0;
    size_t len;

    sm_model_get_info(m, &ib);
    nb = ib.nodes;
    len = (size_t)ib.node_dof * (size_t)nb;
    map = malloc((size_t)nb * sizeof *map);
    if (!map)
        return SM_NOMEM;
    for (int i = 0; i < n; i++)
        need0 |= res->cases[i].n_modes > 0 && !res->cases[i].shape_re;
    if (need0 && (rc = est_solve_level(st, opt, 0, omegas, n, prog, &lm, &r0, d)) != SM_OK)
        goto done;
    for (int k = 0; k < nb; k++)
        map[k] = k;
    for (int i = 0; i < n && rc == SM_OK; i++)
        rc = est_start(&ec[i], r0 ? &r0->cases[i] : &res->cases[i], map, nb, len);
    for (int l = 1; l <= levels && rc == SM_OK; l++) {
        sm_result_free(lr);
        sm_model_free(lm);
        rc = est_solve_level(st, opt, l, omegas, n, prog, &lm, &lr, d);
        if (rc == SM_OK && (rc = est_map_nodes(m, lm, map)) == SM_INVALID_INPUT)
            est_fail(d, rc, "the refined mesh does not contain the nodes of the model");
        for (int i = 0; i < n && rc == SM_OK; i++)
            rc = est_extend(&ec[i], &lr->cases[i], l, map, nb, len, est->min_mac);
    }
done:
    sm_result_free(r0);
    sm_result_free(lr);
    sm_model_free(lm);
    free(map);
    return rc;
}

int sm_estimate(const sm_model *m, const sm_structure *st, const sm_options *opt,
                const double *omegas, int n_omegas, const sm_estimate_options *est,
                sm_progress_fn cb, void *user, sm_result *res, sm_diag *diag)
{
    sm_diag scratch;
    sm_diag *d = diag ? diag : &scratch;
    est_prog prog = {cb, user, 0, 0};
    est_case *ec = NULL;
    double **out = NULL;
    int levels = 0, rc, need0 = 0, n = n_omegas;

    if (!m || !st || !opt || !est || !res || n < 1 || res->n_cases != n)
        return est_fail(d, SM_INVALID_INPUT, "sm_estimate: the result is not of these speeds");
    if ((rc = sm_estimate_plan(st, opt, est, &levels, NULL, d)) != SM_OK)
        return rc;
    for (int i = 0; i < n; i++)
        need0 |= res->cases[i].n_modes > 0 && !res->cases[i].shape_re;
    prog.total = n * (levels + need0);
    ec = calloc((size_t)n, sizeof *ec);
    out = calloc(2 * (size_t)n, sizeof *out);
    if (!ec || !out) {
        rc = SM_NOMEM;
        goto done;
    }
    rc = est_run(m, st, opt, omegas, n, est, levels, &prog, res, ec, d);
    for (int i = 0; i < n && rc == SM_OK; i++)
        rc = est_finish(&ec[i], res->cases[i].n_modes, &out[2 * i], &out[2 * i + 1]);
    for (int i = 0; i < n && rc == SM_OK; i++) { /* attach: res changes only on success */
        sm_case *c = &res->cases[i];
        free(c->error_estimate);
        free(c->error_order);
        c->error_estimate = out[2 * i];
        c->error_order = out[2 * i + 1];
        out[2 * i] = out[2 * i + 1] = NULL;
    }
done:
    for (int i = 0; ec && i < n; i++) {
        free(ec[i].f);
        free(ec[i].levels);
        free(ec[i].v);
    }
    for (int i = 0; out && i < 2 * n; i++)
        free(out[i]);
    free(ec);
    free(out);
    if (rc != SM_OK && d->status == 0) {
        d->status = rc;
        if (!d->message[0])
            snprintf(d->message, sizeof d->message, "%s", sm_strerror(rc));
    }
    return rc;
}
