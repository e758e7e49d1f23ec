/*
 * mac.c — the modal assurance criterion between the modes of two results that
 * need not share a model: two designs, two meshes of one structure, or
 * spinmodal against another program's shape table (DESIGN.md 9.2).
 *
 * How it fits: track.c's track_mac compares two cases of one model node by
 * node.  Here the two sides are plain sm_mac_shapes (points along segments,
 * their span fractions, the compared components), filled by the codec from a
 * result document (server/codec/mac.c) or a BModes .out table
 * (import_bmodes_out.c), so the core never sees JSON.  Matching: by index
 * when the layouts agree; else the side with more points is interpolated
 * linearly in the span fraction at the other side's points, segment by
 * segment (a fine mesh read at a coarse one's nodes: the coarse side's own
 * values are never interpolated).  Anything else is refused with a reason:
 * a MAC between shapes sampled at unrelated points means nothing.
 * Helpers are mac_*.
 */
#include "spinmodal.h"

#include <complex.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Span fractions closer than this are the same point. */
#define MAC_S_TOL 1e-9

/* Writes the reason of a refusal into why (may be NULL) and returns SM_INVALID_INPUT. */
static int mac_refuse(char *why, size_t cap, const char *fmt, ...)
{
    va_list ap;
    if (why && cap) {
        va_start(ap, fmt);
        vsnprintf(why, cap, fmt, ap);
        va_end(ap);
    }
    return SM_INVALID_INPUT;
}

/* Number of segments of x, or -1 when its offsets are not 0 = first <= ... <= last = n_points. */
static int mac_segments(const sm_mac_shapes *x)
{
    int k, n = x->seg_start ? x->n_segments : 1;
    if (!x->seg_start)
        return 1;
    if (n < 1 || x->seg_start[0] != 0 || x->seg_start[n] != x->n_points)
        return -1;
    for (k = 0; k < n; k++)
        if (x->seg_start[k + 1] < x->seg_start[k])
            return -1;
    return n;
}

/* First point of segment k of x. */
static int mac_seg(const sm_mac_shapes *x, int k)
{
    return x->seg_start ? x->seg_start[k] : (k ? x->n_points : 0);
}

/* 1 when a and b have the same segments and points (and span fractions where both give them). */
static int mac_same_layout(const sm_mac_shapes *a, const sm_mac_shapes *b, int nseg)
{
    int k;
    if (a->n_points != b->n_points || mac_segments(b) != nseg)
        return 0;
    for (k = 0; k <= nseg; k++)
        if (mac_seg(a, k) != mac_seg(b, k))
            return 0;
    if (a->s && b->s)
        for (k = 0; k < a->n_points; k++)
            if (fabs(a->s[k] - b->s[k]) > MAC_S_TOL)
                return 0;
    return 1;
}

/* 0 when the span fractions of every segment of x ascend, else a refusal naming the segment. */
static int mac_check_s(const sm_mac_shapes *x, int nseg, const char *side, char *why, size_t cap)
{
    int k, p;
    for (k = 0; k < nseg; k++) {
        if (mac_seg(x, k + 1) - mac_seg(x, k) < 1)
            return mac_refuse(why, cap, "%s: member %d has no points", side, k);
        for (p = mac_seg(x, k); p < mac_seg(x, k + 1); p++)
            if (!isfinite(x->s[p]) || (p > mac_seg(x, k) && x->s[p] < x->s[p - 1]))
                return mac_refuse(why, cap, "%s: the span fractions of member %d do not ascend",
                                  side, k);
    }
    return 0;
}

/*
 * src's shapes read at dst's points, linearly in s per segment, into re / im (src->n_modes *
 * dst->n_points * n_comp each; im only when src has one).  SM_INVALID_INPUT when a point of dst
 * lies outside src's span of its segment.
 */
static int mac_interp(const sm_mac_shapes *src, const sm_mac_shapes *dst, int nseg, double *re,
                      double *im, const char *names[2], char *why, size_t cap)
{
    int nc = src->n_comp, k, p, m, c;
    for (k = 0; k < nseg; k++) {
        int lo = mac_seg(src, k), hi = mac_seg(src, k + 1) - 1, q = lo;
        for (p = mac_seg(dst, k); p < mac_seg(dst, k + 1); p++) {
            double s = dst->s[p], t = 0;
            if (s < src->s[lo] - MAC_S_TOL || s > src->s[hi] + MAC_S_TOL)
                return mac_refuse(why, cap,
                                  "member %d: span fraction %.6g of %s lies outside %s's "
                                  "[%.6g, %.6g]; the shapes cannot be interpolated there",
                                  k, s, names[1], names[0], src->s[lo], src->s[hi]);
            while (q < hi - 1 && src->s[q + 1] < s)
                q++;
            int q1 = q < hi ? q + 1 : q;
            double ds = src->s[q1] - src->s[q];
            if (ds > 0)
                t = fmin(1.0, fmax(0.0, (s - src->s[q]) / ds));
            for (m = 0; m < src->n_modes; m++) {
                size_t o0 = ((size_t)m * src->n_points + q) * nc;
                size_t o1 = ((size_t)m * src->n_points + q1) * nc;
                size_t od = ((size_t)m * dst->n_points + p) * nc;
                for (c = 0; c < nc; c++) {
                    re[od + c] = (1 - t) * src->re[o0 + c] + t * src->re[o1 + c];
                    if (im)
                        im[od + c] = (1 - t) * src->im[o0 + c] + t * src->im[o1 + c];
                }
            }
        }
    }
    return SM_OK;
}

/* The MAC of na x nb modes of length len (values), im arrays may be NULL. */
static void mac_table(size_t len, int na, const double *ar, const double *ai, int nb,
                      const double *br, const double *bi, double *mac)
{
    int i, j;
    for (i = 0; i < na; i++)
        for (j = 0; j < nb; j++) {
            const double *ur = ar + (size_t)i * len, *vr = br + (size_t)j * len;
            const double *ui = ai ? ai + (size_t)i * len : NULL;
            const double *vi = bi ? bi + (size_t)j * len : NULL;
            double complex dot = 0;
            double nu = 0, nv = 0;
            for (size_t c = 0; c < len; c++) {
                double complex u = ur[c] + (ui ? _Complex_I * ui[c] : 0);
                double complex v = vr[c] + (vi ? _Complex_I * vi[c] : 0);
                dot += conj(u) * v;
                nu += creal(conj(u) * u);
                nv += creal(conj(v) * v);
            }
            mac[(size_t)i * nb + j] = nu > 0 && nv > 0 ? creal(dot * conj(dot)) / (nu * nv) : 0.0;
        }
}

/* The checks that need no layout: shapes present, same components, valid segments. */
static int mac_check(const sm_mac_shapes *a, const sm_mac_shapes *b, char *why, size_t cap)
{
    const sm_mac_shapes *x[2] = {a, b};
    for (int k = 0; k < 2; k++)
        if (!x[k] || x[k]->n_modes < 1 || x[k]->n_points < 1 || x[k]->n_comp < 1 || !x[k]->re)
            return mac_refuse(why, cap, "%s has no mode shapes", k ? "B" : "A");
    if (a->n_comp != b->n_comp)
        return mac_refuse(why, cap,
                          "different shape components: %d values per point against %d "
                          "(a planar and a spatial structure?)",
                          a->n_comp, b->n_comp);
    if (mac_segments(a) < 0 || mac_segments(b) < 0)
        return mac_refuse(why, cap, "%s: bad member offsets", mac_segments(a) < 0 ? "A" : "B");
    return SM_OK;
}

int sm_mac(const sm_mac_shapes *a, const sm_mac_shapes *b, double *mac, int *how, char *why,
           size_t why_size)
{
    const char *names[2];
    const sm_mac_shapes *src, *dst;
    double *re = NULL, *im = NULL;
    int st = mac_check(a, b, why, why_size), nseg;
    size_t len;

    if (st)
        return st;
    nseg = mac_segments(a);
    if (why && why_size)
        why[0] = '\0';
    if (mac_same_layout(a, b, nseg)) {
        if (how)
            *how = SM_MAC_BY_INDEX;
        mac_table((size_t)a->n_points * a->n_comp, a->n_modes, a->re, a->im, b->n_modes, b->re,
                  b->im, mac);
        return SM_OK;
    }
    if (!a->s || !b->s)
        return mac_refuse(why, why_size,
                          "the two have different nodes (%d and %d points) and no span "
                          "positions to match them by",
                          a->n_points, b->n_points);
    if (mac_segments(b) != nseg)
        return mac_refuse(why, why_size, "different structures: %d members against %d", nseg,
                          mac_segments(b));
    if ((st = mac_check_s(a, nseg, "A", why, why_size)) ||
        (st = mac_check_s(b, nseg, "B", why, why_size)))
        return st;
    /* the side with more points is read at the other's points */
    src = a->n_points > b->n_points ? a : b;
    dst = src == a ? b : a;
    names[0] = src == a ? "A" : "B";
    names[1] = src == a ? "B" : "A";
    len = (size_t)dst->n_points * dst->n_comp;
    re = malloc(sizeof(double) * len * (size_t)src->n_modes);
    im = src->im ? malloc(sizeof(double) * len * (size_t)src->n_modes) : NULL;
    if (!re || (src->im && !im)) {
        st = SM_NOMEM;
        goto fail;
    }
    st = mac_interp(src, dst, nseg, re, im, names, why, why_size);
    if (st)
        goto fail;
    if (how)
        *how = src == a ? SM_MAC_INTERPOLATED_A : SM_MAC_INTERPOLATED_B;
    if (src == a)
        mac_table(len, a->n_modes, re, im, b->n_modes, b->re, b->im, mac);
    else
        mac_table(len, a->n_modes, a->re, a->im, b->n_modes, re, im, mac);
fail:
    free(re);
    free(im);
    return st;
}
