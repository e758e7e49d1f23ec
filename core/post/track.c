/*
 * track.c — Campbell lines: modes followed across the speeds of a sweep by
 * MAC with an optimal (Hungarian) assignment, and the crossings and veerings
 * of tracked modes (DESIGN.md 9, 9.1).
 *
 * How it fits: sm_solve (sweep.c) calls track_sweep once every speed is
 * solved, while the nodal shapes still exist, with the cases in ascending
 * speed.  Between consecutive speeds with modes the assignment maximises the
 * sum of the MACs (track_assign, O(n^3) Hungarian with potentials; a greedy
 * choice of the largest MAC first can give a worse total, see
 * tests/core/test_track.c).  mac_to_previous and previous_index keep their
 * meaning of before (DESIGN.md 1.4: to the previous speed, none after a speed
 * without modes); tracked_index bridges such gaps and starts a new line when
 * the assigned MAC is below TRACK_NEW_LINE (a mode entered the window of the
 * lowest modes).  Helpers are track_*.
 */
#include "internal.h"

#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Below this MAC an assigned mode starts a new tracked line. */
#define TRACK_NEW_LINE 0.3
/* A swap of order keeping both shapes (MAC >= this) is a crossing, else a veering; across a
 * closest approach a line whose shape changes below it has veered. */
#define TRACK_SAME_SHAPE 0.9
/* A closest approach is a veering candidate when the gap is below this share of the mean
 * frequency of the pair. */
#define TRACK_CLOSE 0.1

/* 1 when component c of a nodal vector with dof values per node is a translation. */
static int track_translation(int c, int dof)
{
    return dof == 6 ? c % 6 < 3 : c % 3 != 2;
}

double track_mac(const sm_case *A, int a, const sm_case *B, int b)
{
    int nn = A->n_nodes, dof = A->node_dof;
    const double *ar = A->shape_re + (size_t)a * dof * nn, *ai = A->shape_im + (size_t)a * dof * nn;
    const double *br = B->shape_re + (size_t)b * dof * nn, *bi = B->shape_im + (size_t)b * dof * nn;
    double complex dot = 0;
    double na = 0, nb = 0;
    for (int c = 0; c < dof * nn; c++) {
        if (!track_translation(c, dof))
            continue;
        double complex u = ar[c] + _Complex_I * ai[c], v = br[c] + _Complex_I * bi[c];
        dot += conj(u) * v; /* MAC = |u^H v|^2 / (u^H u v^H v) */
        na += creal(conj(u) * u);
        nb += creal(conj(v) * v);
    }
    return na > 0 && nb > 0 ? creal(dot * conj(dot)) / (na * nb) : 0.0;
}

/* Hungarian method with potentials on the N x N cost c (row-major): p[j] = row of column j,
 * 1-based, p[0] scratch; work: u, v, minv (N+1 doubles each), way (N+1 ints), used (N+1). */
static void track_hungarian(int N, const double *c, int *p, int *way, char *used, double *u, double *v,
                            double *minv)
{
    for (int j = 0; j <= N; j++)
        u[j] = v[j] = 0, p[j] = 0, way[j] = 0;
    for (int i = 1; i <= N; i++) {
        int j0 = 0;
        p[0] = i;
        for (int j = 0; j <= N; j++)
            minv[j] = INFINITY, used[j] = 0;
        do { /* grow an alternating tree from row i until a free column is reached */
            int i0 = p[j0], j1 = 0;
            double delta = INFINITY;
            used[j0] = 1;
            for (int j = 1; j <= N; j++) {
                if (used[j])
                    continue;
                double cur = c[(size_t)(i0 - 1) * N + (j - 1)] - u[i0] - v[j]; /* reduced cost */
                if (cur < minv[j])
                    minv[j] = cur, way[j] = j0;
                if (minv[j] < delta)
                    delta = minv[j], j1 = j;
            }
            for (int j = 0; j <= N; j++) /* dual update keeps the reduced costs >= 0 */
                if (used[j])
                    u[p[j]] += delta, v[j] -= delta;
                else
                    minv[j] -= delta;
            j0 = j1;
        } while (p[j0] != 0);
        do { /* augment along the path */
            int j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
        } while (j0);
    }
}

int track_assign(int nr, int nc, const double *mac, int *match)
{
    int N = nr > nc ? nr : nc, rc = SM_NOMEM;
    double *c = malloc((size_t)N * N * sizeof(double)), *w = malloc(3 * (size_t)(N + 1) * sizeof(double));
    int *p = malloc(2 * (size_t)(N + 1) * sizeof(int));
    char *used = malloc((size_t)N + 1);

    for (int r = 0; r < nr; r++)
        match[r] = -1;
    if (N == 0) {
        rc = SM_OK;
        goto done;
    }
    if (!c || !w || !p || !used)
        goto done;
    for (int r = 0; r < N; r++) /* cost 1 - MAC; padding rows/columns cost 1 (MAC 0) */
        for (int k = 0; k < N; k++)
            c[(size_t)r * N + k] = r < nr && k < nc ? 1.0 - mac[(size_t)r * nc + k] : 1.0;
    track_hungarian(N, c, p, p + N + 1, used, w, w + N + 1, w + 2 * (N + 1));
    for (int j = 1; j <= N; j++)
        if (p[j] >= 1 && p[j] <= nr && j <= nc)
            match[p[j] - 1] = j - 1;
    rc = SM_OK;
done:
    free(c);
    free(w);
    free(p);
    free(used);
    return rc;
}

/* Mode of case c on tracked line id, or -1. */
static int track_mode_of(const sm_case *c, int id)
{
    for (int j = 0; j < c->n_modes; j++)
        if (c->tracked_index[j] == id)
            return j;
    return -1;
}

/* Relative gap of lines i, j at case c (both present): |w_i - w_j| / mean, or -1. */
static double track_gap(const sm_case *c, int i, int j)
{
    int a = track_mode_of(c, i), b = track_mode_of(c, j);
    if (a < 0 || b < 0)
        return -1;
    double mean = 0.5 * (c->frequency[a] + c->frequency[b]);
    return mean > 0 ? fabs(c->frequency[a] - c->frequency[b]) / mean : 0.0;
}

/* Mark the pair (p, q) of case c with flag, when gap is smaller than a mark it already has. */
static void track_mark(sm_case *c, int p, int q, int flag, double gap, double *mgap)
{
    int m[2] = {p, q};
    for (int h = 0; h < 2; h++)
        if (!c->track_flag[m[h]] || gap < mgap[m[h]]) {
            c->track_flag[m[h]] = flag;
            c->track_partner[m[h]] = c->tracked_index[m[1 - h]];
            mgap[m[h]] = gap;
        }
}

/* Lines i and j swapped order between the cases a and b (both present in both). */
static int track_swapped(const sm_case *a, const sm_case *b, int i, int j)
{
    int ai = track_mode_of(a, i), aj = track_mode_of(a, j), bi = track_mode_of(b, i), bj = track_mode_of(b, j);
    if (ai < 0 || aj < 0 || bi < 0 || bj < 0)
        return 0;
    return (a->frequency[ai] - a->frequency[aj]) * (b->frequency[bi] - b->frequency[bj]) < 0;
}

/*
 * Closest approach of lines i, j at position t of the cases with modes cw[0..n): a strict
 * local minimum of the gap below TRACK_CLOSE, no swap on either side, and a shape change of
 * either line (MAC < TRACK_SAME_SHAPE) between the speeds on both sides where the gap is twice
 * the minimum again (or the ends of the sweep).  Returns 1 for a veering.
 */
static int track_veered(sm_case *const *cw, int n, int t, int i, int j)
{
    double g = track_gap(cw[t], i, j), gl, gr;
    int lo = t, hi = t;
    if (t == 0 || t == n - 1 || g < 0 || !(g < TRACK_CLOSE))
        return 0;
    gl = track_gap(cw[t - 1], i, j);
    gr = track_gap(cw[t + 1], i, j);
    if (gl < 0 || gr < 0 || !(g < gl) || !(g < gr) || track_swapped(cw[t - 1], cw[t], i, j) ||
        track_swapped(cw[t], cw[t + 1], i, j))
        return 0;
    while (lo > 0 && track_gap(cw[lo - 1], i, j) >= 0 && track_gap(cw[lo], i, j) < 2 * g)
        lo--;
    while (hi < n - 1 && track_gap(cw[hi + 1], i, j) >= 0 && track_gap(cw[hi], i, j) < 2 * g)
        hi++;
    int li = track_mode_of(cw[lo], i), hi_i = track_mode_of(cw[hi], i);
    int lj = track_mode_of(cw[lo], j), hj = track_mode_of(cw[hi], j);
    return track_mac(cw[lo], li, cw[hi], hi_i) < TRACK_SAME_SHAPE ||
           track_mac(cw[lo], lj, cw[hi], hj) < TRACK_SAME_SHAPE;
}

/* Flags of case cw[t] (its previous case with modes cw[t-1]); amac: MACs of its assignment;
 * mgap: n_modes scratch. */
static void track_flags(sm_case *const *cw, int n, int t, const double *amac, double *mgap)
{
    sm_case *b = cw[t];
    for (int p = 0; p < b->n_modes; p++)
        for (int q = p + 1; q < b->n_modes; q++) {
            int i = b->tracked_index[p], j = b->tracked_index[q];
            double gap = track_gap(b, i, j);
            if (t > 0 && track_swapped(cw[t - 1], b, i, j))
                track_mark(b, p, q, fmin(amac[p], amac[q]) >= TRACK_SAME_SHAPE ? SM_TRACK_CROSSING
                                                                                : SM_TRACK_VEERING,
                           gap, mgap);
            else if (q == p + 1 && track_veered(cw, n, t, i, j))
                track_mark(b, p, q, SM_TRACK_VEERING, gap, mgap);
        }
}

/* Tracked lines of cur from prev (NULL: all new); adjacent: no speed without modes between
 * them (then mac_to_previous, previous_index are set); amac receives the assigned MACs. */
static int track_step(sm_case *cur, const sm_case *prev, int adjacent, int *next_id, double *amac)
{
    int nc = cur->n_modes, np = prev ? prev->n_modes : 0, rc = SM_OK;
    double *mac = NULL;
    int *match = malloc((size_t)(nc ? nc : 1) * sizeof(int));

    if (!match)
        return SM_NOMEM;
    for (int j = 0; j < nc; j++)
        match[j] = -1, amac[j] = -1;
    if (np > 0) {
        mac = malloc((size_t)nc * np * sizeof(double));
        if (!mac) {
            free(match);
            return SM_NOMEM;
        }
        for (int j = 0; j < nc; j++)
            for (int i = 0; i < np; i++)
                mac[(size_t)j * np + i] = track_mac(cur, j, prev, i);
        rc = track_assign(nc, np, mac, match);
    }
    for (int j = 0; rc == SM_OK && j < nc; j++) {
        int i = match[j];
        amac[j] = i >= 0 ? mac[(size_t)j * np + i] : -1;
        cur->mac_to_previous[j] = adjacent && i >= 0 ? amac[j] : -1;
        cur->previous_index[j] = adjacent && i >= 0 ? i : -1;
        cur->tracked_index[j] = i >= 0 && amac[j] >= TRACK_NEW_LINE ? prev->tracked_index[i] : (*next_id)++;
        cur->track_flag[j] = 0;
        cur->track_partner[j] = -1;
    }
    free(mac);
    free(match);
    return rc;
}

int track_sweep(sm_result *r, const int *ord, int n)
{
    int nw = 0, next_id = 0, adjacent = 0, max_modes = 1, rc = SM_NOMEM;
    sm_case **cw = malloc((size_t)(n ? n : 1) * sizeof *cw);
    double *amac = NULL, *mgap = NULL;
    size_t *off = malloc((size_t)(n + 1) * sizeof(size_t));

    if (!cw || !off)
        goto done;
    off[0] = 0;
    for (int t = 0; t < n; t++) { /* the cases with modes (and shapes) in ascending speed */
        sm_case *c = &r->cases[ord[t]];
        if (c->n_modes <= 0 || !c->shape_re)
            continue;
        c->tracked_index = malloc((size_t)c->n_modes * sizeof(int));
        c->track_flag = malloc((size_t)c->n_modes * sizeof(int));
        c->track_partner = malloc((size_t)c->n_modes * sizeof(int));
        if (!c->tracked_index || !c->track_flag || !c->track_partner)
            goto done;
        cw[nw] = c;
        off[nw + 1] = off[nw] + (size_t)c->n_modes;
        max_modes = c->n_modes > max_modes ? c->n_modes : max_modes;
        nw++;
    }
    amac = malloc((off[nw] ? off[nw] : 1) * sizeof(double));
    mgap = malloc((size_t)max_modes * sizeof(double));
    if (!amac || !mgap)
        goto done;
    for (int t = 0, w = 0; t < n; t++) {
        sm_case *c = &r->cases[ord[t]];
        if (c->n_modes <= 0 || !c->shape_re) {
            adjacent = 0;
            continue;
        }
        if ((rc = track_step(c, w ? cw[w - 1] : NULL, adjacent, &next_id, amac + off[w])) < 0)
            goto done;
        rc = SM_NOMEM;
        adjacent = 1;
        w++;
    }
    for (int t = 0; t < nw; t++)
        track_flags(cw, nw, t, amac + off[t], mgap);
    rc = SM_OK;
done:
    free(cw);
    free(off);
    free(amac);
    free(mgap);
    return rc;
}
