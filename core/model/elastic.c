/*
 * elastic.c — the elastic terms of a model, the same for every structure kind
 * (Kim & Yoo eqs. 11, 24): f_e = K q with K = blockdiag(N_s' Kbar_s N_s), K itself, and the
 * axial force P_e = d_e . q_s of every element.
 *
 * How it fits: model layer; the continuation (solve/equilibrium.c), the sweep's outputs and
 * both kinds' tangents use them.  Declared in internal.h (lin_* names kept).
 */
#include "internal.h"

#include <cblas.h>

/** P[e] = d_e . q_s, the axial force of every FE element e (eq. 24), N. */
void lin_axial_forces(const sm_model *m, const double *q, double *P)
{
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        for (int j = 0; j < b->nel; j++) {
            double t = 0;
            for (int i = 0; i < b->m; i++)
                t += b->d[(size_t)j * b->m + i] * q[b->q0 + i];
            P[b->elems[j]] = t;
        }
    }
}

/** f += blockdiag(K_s) q, and the supports' K_sup q (supports.c). */
void lin_elastic_force(const sm_model *m, const double *q, double *f)
{
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        for (int i = 0; i < b->m; i++) {
            double t = 0;
            for (int j = 0; j < b->m; j++)
                t += DM(&b->K, i, j) * q[b->q0 + j];
            f[b->q0 + i] += t;
        }
    }
    if (m->has_supports)
        cblas_dgemv(CblasColMajor, CblasNoTrans, m->n, m->n, 1.0, m->sup_K.a, m->n, q, 1, 1.0, f,
                    1);
}

/** Kt += blockdiag(K_s), and the supports' K_sup. */
void lin_elastic_add(const sm_model *m, dmat *Kt)
{
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        for (int j = 0; j < b->m; j++)
            for (int i = 0; i < b->m; i++)
                DM(Kt, b->q0 + i, b->q0 + j) += DM(&b->K, i, j);
    }
    for (size_t i = 0; m->has_supports && i < (size_t)m->n * (size_t)m->n; i++)
        Kt->a[i] += m->sup_K.a[i];
}
