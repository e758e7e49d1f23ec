/*
 * test_geometric_tangent.c — lin_geometric_tangent_sub (core/planar/linearize.c) and
 * lin3_geometric_tangent_sub (core/spatial/lin3.c) give the bits of their solver-0.8.8 forms,
 * copied here as geo_reference and geo3_reference.  The planar one: the rows of T_s read in place
 * (strided), V = G Tb for all columns first, then A += P Tb' V over all entries, then the d_e'
 * term over all entries.  Planar results are fixed to the byte (issue 27), so the faster form must
 * give every entry the same operations in the same order.  Checked bit for bit (memcmp) on the
 * angled beam at a large deformation, frozen and full, with one frame (a 60-element frame), frames
 * per member, per element and of 4 elements, both bases, lumped and consistent mass, into a block
 * with a leading dimension larger than m_s (the tree form's layout); and against central
 * differences of f_g (test_frames does the same for the dense assembly).  The spatial one likewise
 * (twelve rows of T_s an element) on a twisted, out-of-plane member with one frame, frames per
 * element and of 3 elements, against the 0.8.8 bits and central differences of lin3's f_g.
 */
#include "spatial.h"
#include "testutil.h"

#include <math.h>
#include <string.h>

/* lin_geometric_tangent_sub as solver 0.8.8 wrote it (work: 4 m_s). */
static void geo_reference(const sm_model *m, int s, const double *q, int frozen, double *A, int lda,
                          double *work)
{
    static const int rows[4] = {1, 2, 4, 5};
    const sm_sub *b = &m->subs[s];
    const double *qs = q + b->q0;
    int mm = b->m;
    double *V = work;
    for (int j = 0; j < b->nel; j++) {
        double tb[4];
        const double *dd = b->d + (size_t)j * mm;
        double P = 0;
        for (int r = 0; r < 4; r++)
            tb[r] = 0;
        for (int c = 0; c < mm; c++) { /* lin_element_state */
            P += dd[c] * qs[c];
            for (int r = 0; r < 4; r++)
                tb[r] += DM(&b->T, 6 * j + rows[r], c) * qs[c];
        }
        const double *g = b->gq + 16 * j, *d = dd;
        for (int c = 0; c < mm; c++)
            for (int r = 0; r < 4; r++) {
                double t = 0;
                for (int p = 0; p < 4; p++)
                    t += g[r + 4 * p] * DM(&b->T, 6 * j + rows[p], c);
                V[r + 4 * c] = t;
            }
        for (int jc = 0; jc < mm; jc++)
            for (int ic = 0; ic < mm; ic++) {
                double t = 0;
                for (int r = 0; r < 4; r++)
                    t += DM(&b->T, 6 * j + rows[r], ic) * V[r + 4 * jc];
                A[(size_t)jc * lda + ic] += P * t;
            }
        if (!frozen) {
            double gt[4];
            for (int r = 0; r < 4; r++)
                gt[r] = g[r] * tb[0] + g[r + 4] * tb[1] + g[r + 8] * tb[2] + g[r + 12] * tb[3];
            for (int ic = 0; ic < mm; ic++) {
                double t = 0;
                for (int r = 0; r < 4; r++)
                    t += DM(&b->T, 6 * j + rows[r], ic) * gt[r];
                for (int jc = 0; jc < mm; jc++)
                    A[(size_t)jc * lda + ic] += t * d[jc];
            }
        }
    }
}

/* lin3_geometric_tangent_sub as solver 0.8.8 wrote it (work: 12 m_s), with lin3.c's T_e q_s and
 * P_e. */
static void geo3_reference(const sm_model *m, int s, const double *q, int frozen, double *Kt,
                           int ld, double *work)
{
    double G[144], tq[12], gt[12];
    const sm_sub *b = &m->subs[s];
    const double *qs = q + b->q0;
    int mm = b->m;
    double *GT = work;
    for (int j = 0; j < b->nel; j++) {
        fe3_geometric(&m->elems[b->elems[j]], G);
        const double *d = b->d + (size_t)j * mm;
        double P = 0;
        for (int c = 0; c < mm; c++)
            P += d[c] * qs[c];
        for (int c = 0; c < mm; c++)
            for (int r = 0; r < 12; r++) {
                double s2 = 0;
                for (int t = 0; t < 12; t++)
                    s2 += G[r + 12 * t] * DM(&b->T, 12 * j + t, c);
                GT[r + 12 * c] = s2;
            }
        for (int c = 0; c < mm; c++)
            for (int a = 0; a < mm; a++) {
                double s2 = 0;
                for (int r = 0; r < 12; r++)
                    s2 += DM(&b->T, 12 * j + r, a) * GT[r + 12 * c];
                Kt[a + (size_t)ld * c] += P * s2;
            }
        if (frozen)
            continue;
        for (int r = 0; r < 12; r++) {
            double s2 = 0;
            for (int c = 0; c < mm; c++)
                s2 += DM(&b->T, 12 * j + r, c) * qs[c];
            tq[r] = s2;
        }
        for (int r = 0; r < 12; r++) {
            double s2 = 0;
            for (int t = 0; t < 12; t++)
                s2 += G[r + 12 * t] * tq[t];
            gt[r] = s2;
        }
        for (int a = 0; a < mm; a++) {
            double v = 0;
            for (int r = 0; r < 12; r++)
                v += DM(&b->T, 12 * j + r, a) * gt[r];
            for (int c = 0; c < mm; c++)
                Kt[a + (size_t)ld * c] += v * d[c];
        }
    }
}

typedef void (*geo_sub_fn)(const sm_model *, int, const double *, int, double *, int, double *);
typedef void (*geo_force_fn)(const sm_model *, const double *, double *);

/* The block of every substructure by fn and by ref from the same nonzero start, compared with
 * memcmp (frozen and full); the full derivative of the middle substructure against central
 * differences of force.  work: wn max m_s, the reference's: wr max m_s. */
static void compare(const char *what, const sm_model *m, const double *q0, geo_sub_fn fn,
                    geo_sub_fn ref, geo_force_fn force, int wn, int wr)
{
    int n = m->n, mx = 1, same = 1, finite = 1;
    for (int s = 0; s < m->n_subs; s++)
        mx = m->subs[s].m > mx ? m->subs[s].m : mx;
    int lda = mx + 5; /* a block inside a larger matrix, as the tree form assembles it */
    double *q = dm_vec((size_t)n), *work = dm_vec((size_t)wn * mx), *wref = dm_vec((size_t)wr * mx);
    double *A = dm_vec((size_t)lda * mx), *B = dm_vec((size_t)lda * mx);
    double *f0 = dm_vec((size_t)n), *f1 = dm_vec((size_t)n);
    memcpy(q, q0, (size_t)n * sizeof(double));
    double fd_err = 0, fd_scale = 0;
    for (int frozen = 0; frozen <= 1; frozen++)
        for (int s = 0; s < m->n_subs; s++) {
            int mm = m->subs[s].m;
            for (size_t i = 0; i < (size_t)lda * mx; i++)
                A[i] = B[i] = 1e-3 * cos(0.37 * (double)i + s);
            fn(m, s, q, frozen, A, lda, work);
            ref(m, s, q, frozen, B, lda, wref);
            if (memcmp(A, B, (size_t)lda * mx * sizeof(double)) != 0)
                same = 0;
            for (size_t i = 0; i < (size_t)lda * mx; i++)
                if (!isfinite(A[i]))
                    finite = 0;
            if (frozen || s != m->n_subs / 2)
                continue;
            for (size_t i = 0; i < (size_t)lda * mx; i++)
                A[i] = 0;
            fn(m, s, q, 0, A, lda, work);
            for (int jc = 0; jc < mm; jc += 1 + mm / 7) {
                double h = 1e-6, qj = q[m->subs[s].q0 + jc];
                memset(f0, 0, (size_t)n * sizeof(double));
                memset(f1, 0, (size_t)n * sizeof(double));
                q[m->subs[s].q0 + jc] = qj + h;
                force(m, q, f1);
                q[m->subs[s].q0 + jc] = qj - h;
                force(m, q, f0);
                q[m->subs[s].q0 + jc] = qj;
                for (int ic = 0; ic < mm; ic++) {
                    int r = m->subs[s].q0 + ic;
                    double fd = (f1[r] - f0[r]) / (2 * h), an = A[(size_t)jc * lda + ic];
                    fd_err = fmax(fd_err, fabs(fd - an));
                    fd_scale = fmax(fd_scale, fabs(an));
                }
            }
        }
    TU_CHECK(same, "%s (%d subs, m_s <= %d): the 0.8.8 bits", what, m->n_subs, mx);
    TU_CHECK(finite, "%s: finite", what);
    TU_CHECK(fd_scale > 0 && fd_err <= 1e-6 * fd_scale,
             "%s: tangent against central differences of f_g: %.2e of %.2e", what, fd_err,
             fd_scale);
    free(q);
    free(work);
    free(wref);
    free(A);
    free(B);
    free(f0);
    free(f1);
}

static void check(sm_frame_scheme fs, int param, sm_basis basis, sm_mass_model mass, int elements)
{
    tu_angled a;
    tu_angled_beam(&a, 60, elements, elements);
    sm_options o;
    sm_default_options(&o);
    o.frames = fs;
    o.frames_param = param;
    o.basis = basis;
    o.mass = mass;
    sm_model *m;
    sm_diag dg;
    if (sm_model_new(&m, &a.st, &o, &dg) < 0) {
        TU_CHECK(0, "model: %s", dg.message);
        return;
    }
    char what[96];
    double *q = dm_vec((size_t)m->n);
    for (int i = 0; i < m->n; i++)
        q[i] = 0.3 * sin(1.7 * i + 0.4); /* a large, arbitrary deformation */
    snprintf(what, sizeof what, "planar, frames %d/%d, basis %d, mass %d", (int)fs, param,
             (int)basis, (int)mass);
    compare(what, m, q, lin_geometric_tangent_sub, geo_reference, lin_geometric_force, 5, 4);
    free(q);
    sm_model_free(m);
}

/* A twisted member carried out of the plane of rotation (DESIGN.md 7), spatial. */
static void check3(sm_frame_scheme fs, int param, int elements)
{
    static double xy[4] = {0.5, 0, 6.5, 0.3}, z[2] = {0, 0.8};
    sm_section sec;
    sm_member mem;
    sm_structure st;
    memset(&sec, 0, sizeof sec);
    memset(&mem, 0, sizeof mem);
    memset(&st, 0, sizeof st);
    sec.EA = 8.4e7, sec.EI_flap = 2800, sec.EI_edge = 25200, sec.GJ = 3883, sec.mu = 3.0;
    sec.i_flap = 1e-4, sec.i_edge = 9e-4, sec.ip_over_a = 1e-3 / 3.0;
    mem.from = 0, mem.to = 1, mem.section = 0, mem.elements = elements, mem.twist = 0.4;
    tu_one_member3(&st, xy, z, &sec, &mem);
    sm_options o;
    sm_default_options(&o);
    o.frames = fs;
    o.frames_param = param;
    sm_model *m;
    sm_diag dg;
    if (sm_model_new(&m, &st, &o, &dg) < 0) {
        TU_CHECK(0, "spatial model: %s", dg.message);
        return;
    }
    char what[96];
    double *q = dm_vec((size_t)m->n);
    for (int i = 0; i < m->n; i++)
        q[i] = 0.05 * sin(1.3 * i + 0.2);
    snprintf(what, sizeof what, "spatial, frames %d/%d, %d elements", (int)fs, param, elements);
    compare(what, m, q, lin3_geometric_tangent_sub, geo3_reference, lin3_geometric_force, 13, 12);
    free(q);
    sm_model_free(m);
}

int main(void)
{
    check(SM_FRAMES_SINGLE, 1, SM_BASIS_AUGMENTED, SM_MASS_LUMPED, 30);
    check(SM_FRAMES_SINGLE, 1, SM_BASIS_PAPER, SM_MASS_CONSISTENT, 12);
    check(SM_FRAMES_PER_MEMBER, 2, SM_BASIS_PAPER, SM_MASS_LUMPED, 8);
    check(SM_FRAMES_PER_MEMBER, 3, SM_BASIS_AUGMENTED, SM_MASS_LUMPED, 9);
    check(SM_FRAMES_PER_ELEMENT, 1, SM_BASIS_AUGMENTED, SM_MASS_LUMPED, 6);
    check(SM_FRAMES_ELEMENTS_PER_FRAME, 4, SM_BASIS_AUGMENTED, SM_MASS_CONSISTENT, 10);
    check3(SM_FRAMES_SINGLE, 1, 12);
    check3(SM_FRAMES_PER_ELEMENT, 1, 5);
    check3(SM_FRAMES_ELEMENTS_PER_FRAME, 3, 9);
    return tu_finish("geometric_tangent");
}
