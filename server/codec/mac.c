/*
 * mac.c — MAC tables between two results (or a result and a BModes .out):
 * reading a result case's shapes into sm_mac_shapes, the JSON table and its
 * CSV (DESIGN.md 9.2; declarations and the overview in mac.h).
 *
 * How it fits: the numbers come from core's sm_mac; this file only reads the
 * result document (model.members: each member's nodes from its `from`
 * joint, their span fractions and the member's untwisted axes, as
 * spanwise.c reads them) and writes the answer.  A spatial result is read
 * member by member (so that two meshes of one structure can be matched by
 * span fraction), a planar one node by node (no span positions: only the
 * same mesh can be compared).  Helpers are mac_*.
 */
#include "mac.h"

#include "codec_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void codec_mac_set_free(codec_mac_set *x)
{
    free(x->s);
    free(x->re);
    free(x->im);
    free(x->freq_hz);
    free(x->seg);
    json_decref(x->labels);
    memset(x, 0, sizeof(*x));
}

/* Value c of row `node` of a shape part ([[dx, dy, ...], ...]), 0 when absent. */
static double mac_val(const json_t *part, size_t node, int c)
{
    return json_number_value(json_array_get(json_array_get(part, node), (size_t)c));
}

/* The compared components of one node of one shape part: hub translations or flap, lag. */
static void mac_point(const json_t *part, size_t node, const double *ax, int comp, int nc,
                      double *out)
{
    double d[3] = {mac_val(part, node, 0), mac_val(part, node, 1), mac_val(part, node, 2)};
    if (comp == CODEC_MAC_FLAP_LAG) { /* ax = [e1 | e2 | e3]: flap d.e3, lag -d.e2 */
        out[0] = d[0] * ax[6] + d[1] * ax[7] + d[2] * ax[8];
        out[1] = -(d[0] * ax[3] + d[1] * ax[4] + d[2] * ax[5]);
        return;
    }
    memcpy(out, d, sizeof(double) * (size_t)nc);
}

/* Allocates x's arrays for n_modes modes of np points, nc components, nseg segments. */
static int mac_alloc(codec_mac_set *x, int n_modes, int np, int nc, int nseg, int with_im)
{
    size_t n = (size_t)n_modes * np * nc;
    x->re = calloc(n ? n : 1, sizeof(double));
    x->im = with_im ? calloc(n ? n : 1, sizeof(double)) : NULL;
    x->s = calloc((size_t)np + 1, sizeof(double));
    x->seg = calloc((size_t)nseg + 1, sizeof(int));
    x->freq_hz = calloc((size_t)n_modes + 1, sizeof(double));
    x->labels = json_array();
    if (!x->re || (with_im && !x->im) || !x->s || !x->seg || !x->freq_hz || !x->labels)
        return SM_NOMEM;
    x->sh = (sm_mac_shapes){n_modes, np, nc, nseg, x->seg, x->s, x->re, x->im};
    return SM_OK;
}

/* The modes of case cs that carry shapes (count, and whether any is complex). */
static int mac_count(const json_t *cs, int *with_im)
{
    const json_t *m;
    size_t i;
    int n = 0;
    *with_im = 0;
    json_array_foreach(json_object_get(cs, "modes"), i, m) {
        const json_t *sh = json_object_get(m, "shape");
        if (json_array_size(json_object_get(sh, "re"))) {
            n++;
            *with_im |= json_is_array(json_object_get(sh, "im"));
        }
    }
    return n;
}

/* Fills the shapes of x (already allocated) from case cs, members `mems` (NULL: by node; chain:
 * the node a member shares with the one before is taken once). */
static void mac_fill(codec_mac_set *x, const json_t *cs, const json_t *mems, int chain, int comp)
{
    const json_t *m, *lay;
    size_t i, k, j;
    int mi = 0, nc = x->sh.n_comp;
    json_array_foreach(json_object_get(cs, "modes"), i, m) {
        const json_t *sh = json_object_get(m, "shape"), *re = json_object_get(sh, "re");
        const json_t *im = json_object_get(sh, "im");
        double *o = x->re + (size_t)mi * x->sh.n_points * nc, ax[9] = {0};
        double *oi = x->im ? x->im + (size_t)mi * x->sh.n_points * nc : NULL;
        if (!json_array_size(re))
            continue;
        x->freq_hz[mi] = json_number_value(json_object_get(m, "frequency_hz"));
        json_array_append(x->labels,
                          json_object_get(m, "label") ? json_object_get(m, "label") : json_null());
        if (!mems)
            for (k = 0; k < (size_t)x->sh.n_points; k++) {
                mac_point(re, k, ax, comp, nc, o + k * nc);
                if (oi && im)
                    mac_point(im, k, ax, comp, nc, oi + k * nc);
            }
        size_t p = 0;
        json_array_foreach(mems, k, lay) {
            const json_t *nodes = json_object_get(lay, "nodes");
            for (j = 0; j < 9; j++)
                ax[j] = json_number_value(json_array_get(json_object_get(lay, "axes"), j));
            for (j = chain && k > 0; j < json_array_size(nodes); j++, p++) {
                size_t node = (size_t)json_integer_value(json_array_get(nodes, j));
                mac_point(re, node, ax, comp, nc, o + p * nc);
                if (oi && im)
                    mac_point(im, node, ax, comp, nc, oi + p * nc);
            }
        }
        mi++;
    }
}

/* Node j of a member layout. */
static json_int_t mac_node(const json_t *lay, size_t j)
{
    return json_integer_value(json_array_get(json_object_get(lay, "nodes"), j));
}

/* Number of nodes of a member layout. */
static size_t mac_n(const json_t *lay)
{
    return json_array_size(json_object_get(lay, "nodes"));
}

/*
 * The members of a result's model with their nodes (NULL for a result without them), *np
 * their points and *chain 1 when they form one chain in order (each starts at the node where
 * the one before ends: a blade or tower cut into members, e.g. BModes' own mesh), read then as
 * one segment whose span fraction runs along the whole length.
 */
static const json_t *mac_members(const json_t *result, int *np, int *chain)
{
    const json_t *mems = json_object_get(json_object_get(result, "model"), "members"), *lay, *prev;
    size_t k;
    *np = 0;
    *chain = json_array_size(mems) > 1;
    json_array_foreach(mems, k, lay) {
        prev = k > 0 ? json_array_get(mems, k - 1) : NULL;
        if (mac_n(lay) < 2 || (prev && mac_node(lay, 0) != mac_node(prev, mac_n(prev) - 1)))
            *chain = 0;
        *np += (int)mac_n(lay);
    }
    if (*chain)
        *np -= (int)json_array_size(mems) - 1;
    return *np > 0 ? mems : NULL;
}

/* The span fractions and segments of x from the member layouts (chain: one segment, s along
 * the summed lengths). */
static void mac_layout(codec_mac_set *x, const json_t *mems, int chain)
{
    const json_t *lay;
    double total = 0, at = 0;
    size_t k, j, p = 0;
    json_array_foreach(mems, k, lay)
        total += json_number_value(json_object_get(lay, "length"));
    json_array_foreach(mems, k, lay) {
        const json_t *s = json_object_get(lay, "s");
        double len = json_number_value(json_object_get(lay, "length"));
        if (!chain)
            x->seg[k] = (int)p;
        for (j = chain && k > 0; j < mac_n(lay); j++) {
            double sj = json_number_value(json_array_get(s, j));
            x->s[p++] = chain && total > 0 ? (at + sj * len) / total : sj;
        }
        if (!chain)
            x->seg[k + 1] = (int)p;
        at += len;
    }
    if (chain)
        x->seg[0] = 0, x->seg[1] = (int)p;
}

int codec_mac_from_result(codec_mac_set *x, const json_t *result, long case_no, int comp, char *err,
                          size_t errcap)
{
    const json_t *cases = json_object_get(result, "cases"), *cs, *mems;
    int np, n_modes, with_im, nc, st, chain;

    memset(x, 0, sizeof(*x));
    if (!json_is_array(cases)) {
        snprintf(err, errcap, "not a result document (no \"cases\": a request? solve it first)");
        return SM_INVALID_INPUT;
    }
    if (case_no < 1 || (size_t)case_no > json_array_size(cases)) {
        snprintf(err, errcap, "no case %ld: the result has %zu", case_no, json_array_size(cases));
        return SM_INVALID_INPUT;
    }
    cs = json_array_get(cases, (size_t)case_no - 1);
    n_modes = mac_count(cs, &with_im);
    if (n_modes < 1) {
        snprintf(err, errcap,
                 "case %ld has no mode shapes (status %s; solve with "
                 "\"mode_shapes\": true)",
                 case_no,
                 json_string_value(json_object_get(cs, "status"))
                     ? json_string_value(json_object_get(cs, "status"))
                     : "?");
        return SM_INVALID_INPUT;
    }
    mems = mac_members(result, &np, &chain);
    if (!mems && comp == CODEC_MAC_FLAP_LAG) {
        snprintf(err, errcap,
                 "flap and lag shapes need a spatial result with mode shapes "
                 "(model.members)");
        return SM_INVALID_INPUT;
    }
    nc = comp == CODEC_MAC_FLAP_LAG                                                   ? 2
         : json_is_true(json_object_get(json_object_get(result, "model"), "spatial")) ? 3
                                                                                      : 2;
    if (!mems) /* planar: every node, by index */
        np = (int)json_array_size(json_object_get(
            json_object_get(json_array_get(json_object_get(cs, "modes"), 0), "shape"), "re"));
    st = mac_alloc(x, n_modes, np, nc, mems && !chain ? (int)json_array_size(mems) : 1, with_im);
    if (st)
        goto fail;
    if (!mems)
        x->sh.s = NULL, x->seg[1] = np;
    else
        mac_layout(x, mems, chain);
    mac_fill(x, cs, mems, chain, comp);
    x->case_no = case_no;
    x->omega = json_number_value(json_object_get(cs, "omega"));
    x->kind = "result";
    return SM_OK;
fail:
    codec_mac_set_free(x);
    return st;
}

/* The "a" / "b" object of the table: where the modes come from and their frequencies. */
static json_t *mac_side(const codec_mac_set *x)
{
    json_t *o = json_pack("{s:s, s:i, s:i}", "source", x->kind, "modes", x->sh.n_modes, "points",
                          x->sh.n_points),
           *f = json_array();
    int i;
    if (!o || !f)
        goto fail;
    if (x->case_no > 0 && (json_object_set_new(o, "case", json_integer(x->case_no)) ||
                           json_object_set_new(o, "omega", json_real(x->omega))))
        goto fail;
    for (i = 0; i < x->sh.n_modes; i++)
        if (json_array_append_new(f, json_real(x->freq_hz[i])))
            goto fail;
    if (json_object_set_new(o, "frequency_hz", f) ||
        json_object_set(o, "labels", x->labels ? x->labels : json_null()))
        goto fail_o;
    return o;
fail:
    json_decref(f);
fail_o:
    json_decref(o);
    return NULL;
}

/* The rows of the table and, per row, the best column. */
static int mac_rows(json_t *doc, const double *mac, int na, int nb)
{
    json_t *rows = json_array(), *best = json_array();
    int i, j;
    if (json_object_set_new(doc, "mac", rows) || json_object_set_new(doc, "best", best))
        return SM_NOMEM;
    for (i = 0; i < na; i++) {
        json_t *r = json_array();
        int bj = 0;
        if (json_array_append_new(rows, r))
            return SM_NOMEM;
        for (j = 0; j < nb; j++) {
            if (json_array_append_new(r, json_real(mac[(size_t)i * nb + j])))
                return SM_NOMEM;
            if (mac[(size_t)i * nb + j] > mac[(size_t)i * nb + bj])
                bj = j;
        }
        if (json_array_append_new(best, json_pack("{s:i, s:i, s:f}", "a", i + 1, "b", bj + 1, "mac",
                                                  mac[(size_t)i * nb + bj])))
            return SM_NOMEM;
    }
    return SM_OK;
}

int codec_mac_doc(json_t **doc, const codec_mac_set *a, const codec_mac_set *b, int comp, char *err,
                  size_t errcap)
{
    static const char *how_names[] = {"by_index", "interpolated_a", "interpolated_b"};
    double *mac = malloc(sizeof(double) * (size_t)(a->sh.n_modes > 0 ? a->sh.n_modes : 1) *
                         (size_t)(b->sh.n_modes > 0 ? b->sh.n_modes : 1));
    int how = 0, st;

    *doc = NULL;
    if (!mac)
        return SM_NOMEM;
    st = sm_mac(&a->sh, &b->sh, mac, &how, err, errcap);
    if (st)
        goto done;
    st = SM_NOMEM;
    *doc = json_pack("{s:o*, s:o*, s:s, s:s}", "a", mac_side(a), "b", mac_side(b), "matching",
                     how_names[how], "components",
                     comp == CODEC_MAC_FLAP_LAG ? "flap, lag (BModes' directions)"
                     : a->sh.n_comp == 3        ? "dx, dy, dz (hub frame)"
                                                : "dx, dy (hub frame)");
    if (!*doc || !json_object_get(*doc, "a") || !json_object_get(*doc, "b") ||
        mac_rows(*doc, mac, a->sh.n_modes, b->sh.n_modes))
        goto done;
    st = SM_OK;
done:
    if (st && *doc) {
        json_decref(*doc);
        *doc = NULL;
    }
    free(mac);
    return st;
}

int codec_mac_csv(char **out, size_t *len, const json_t *doc)
{
    const json_t *a = json_object_get(doc, "a"), *rows = json_object_get(doc, "mac"), *r, *v;
    char *buf = NULL;
    size_t n = 0, i, j;
    FILE *f = open_memstream(&buf, &n);

    *out = NULL;
    if (!f)
        return SM_NOMEM;
    fputs("mode_a,frequency_hz_a,label_a", f);
    for (j = 0; j < json_array_size(json_array_get(rows, 0)); j++)
        fprintf(f, ",b%zu", j + 1);
    fputc('\n', f);
    json_array_foreach(rows, i, r) {
        const char *lab = json_string_value(json_array_get(json_object_get(a, "labels"), i));
        fprintf(f, "%zu,%.17g,%s", i + 1,
                json_number_value(json_array_get(json_object_get(a, "frequency_hz"), i)),
                lab ? lab : "");
        json_array_foreach(r, j, v)
            fprintf(f, ",%.17g", json_number_value(v));
        fputc('\n', f);
    }
    return codec_memstream_done(f, &buf, &n, out, len);
}
