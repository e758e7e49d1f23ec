/*
 * frames.c — chain kinematics of the floating frames (DESIGN.md 1.2-1.3,
 * Kim & Yoo eqs. 1, 36):
 *
 *   r_k = R_s + A(theta_s) (ubar_k + N_k q_s),      phi_k = theta_s - theta0_s + Nphi_k q_s
 *   R_c = r_e,  theta_c = theta_s + Nphi_e q_s + beta_c   (child c at node e of s)
 *   J_k = J_R,s + A'(theta_s) w_k J_theta,s + A(theta_s) N_k E_s
 *
 * and the two derived quantities the equilibrium needs: the generalised
 * centrifugal force g = sum m_k J_k' r_k and its derivative's second-order
 * part H = sum m_k r_k . d2 r_k / dq2 (so that dg/dq = M* + H), computed by a
 * leaves-to-root recursion: the total centrifugal "force" of a child subtree
 * acts on the parent at the attachment node.
 *
 * Frames are processed parents first; the columns of every Jacobian that
 * belong to substructure s or its ancestors are < q0_s + m_s, so loops stop
 * there.  Jacobians are stored transposed: one n-vector column per quantity.
 */
#include "internal.h"

#include <cblas.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

int frames_kin_alloc_light(const sm_model *m, sm_kin *k)
{
    memset(k, 0, sizeof *k);
    k->n = m->n;
    k->theta = dm_vec((size_t)m->n_subs);
    k->R = dm_vec(2 * (size_t)m->n_subs);
    k->rn = dm_vec(3 * (size_t)m->n_nodes);
    k->wn = dm_vec(2 * (size_t)m->n_nodes);
    k->rp = dm_vec(2 * (size_t)m->n_mp);
    k->wp = dm_vec(2 * (size_t)m->n_mp);
    k->fext = dm_vec(2 * (size_t)m->n_nodes);
    if (!k->theta || !k->R || !k->rn || !k->wn || !k->rp || !k->wp || !k->fext) {
        frames_kin_free(k);
        return SM_NOMEM;
    }
    return SM_OK;
}

int frames_kin_alloc(const sm_model *m, sm_kin *k)
{
    /* the light kinematics, then the dense Jacobians of the dense path */
    if (frames_kin_alloc_light(m, k) != SM_OK)
        return SM_NOMEM;
    if (dm_alloc(&k->Jth, m->n, m->n_subs) || dm_alloc(&k->Jtha, m->n, m->n_subs) ||
        dm_alloc(&k->JR, m->n, 2 * m->n_subs) ||
        dm_alloc(&k->Jn, m->n, 3 * m->n_nodes) || dm_alloc(&k->Jp, m->n, 2 * m->n_mp)) {
        frames_kin_free(k);
        return SM_NOMEM;
    }
    return SM_OK;
}

void frames_kin_free(sm_kin *k)
{
    free(k->theta);
    free(k->R);
    free(k->rn);
    free(k->wn);
    free(k->rp);
    free(k->wp);
    free(k->fext);
    dm_free(&k->Jth);
    dm_free(&k->Jtha);
    dm_free(&k->JR);
    dm_free(&k->Jn);
    dm_free(&k->Jp);
    memset(k, 0, sizeof *k);
}

/* Position, rotation and Jacobian columns of one point of substructure s. */
static void frames_point(const sm_sub *b, const sm_kin *k, int s, const double *q,
                         const double *ub, const double *N, int ldn, const double *Nphi,
                         double *r, double *w, double *jx, double *jy, double *jphi, double *phi)
{
    int mm = b->m, q0 = b->q0, lim = q0 + mm;
    double th = k->theta[s], c = cos(th), si = sin(th);
    const double *qs = q + q0;
    /* w = ubar + N q_s */
    w[0] = ub[0];
    w[1] = ub[1];
    for (int j = 0; j < mm; j++) {
        w[0] += N[(size_t)ldn * j] * qs[j];
        w[1] += N[(size_t)ldn * j + 1] * qs[j];
    }
    /* r = R + A w */
    r[0] = k->R[2 * s] + c * w[0] - si * w[1];
    r[1] = k->R[2 * s + 1] + si * w[0] + c * w[1];
    (void)lim;
    if (!k->Jn.a) { /* light kinematics (frames_kin_alloc_light): positions only */
        if (phi) {
            double p = th - b->theta0;
            for (int j = 0; j < mm; j++)
                p += Nphi[(size_t)ldn * j] * qs[j];
            *phi = p;
        }
        return;
    }
    /* J = J_R + (A' w) J_theta + A N E_s */
    double aw0 = -si * w[0] - c * w[1], aw1 = c * w[0] - si * w[1];
    const double *jrx = &DM(&k->JR, 0, 2 * s), *jry = &DM(&k->JR, 0, 2 * s + 1);
    const double *jt = &DM(&k->Jth, 0, s);
    for (int j = 0; j < q0; j++) {
        jx[j] = jrx[j] + aw0 * jt[j];
        jy[j] = jry[j] + aw1 * jt[j];
    }
    for (int j = 0; j < mm; j++) {
        double n0 = N[(size_t)ldn * j], n1 = N[(size_t)ldn * j + 1];
        jx[q0 + j] = c * n0 - si * n1;
        jy[q0 + j] = si * n0 + c * n1;
    }
    if (jphi) {
        double p = th - b->theta0;
        for (int j = 0; j < q0; j++)
            jphi[j] = jt[j];
        for (int j = 0; j < mm; j++) {
            jphi[q0 + j] = Nphi[(size_t)ldn * j];
            p += Nphi[(size_t)ldn * j] * qs[j];
        }
        *phi = p;
    }
}

/** Evaluate frames, node and mass-point positions and (unless k is light) Jacobians at q. */
void frames_eval(const sm_model *m, const double *q, sm_kin *k)
{
    /* The Jacobians are not cleared here: every call writes the same entries (column prefixes
     * up to each frame's last coordinate, fixed by the topology), and the rest stay zero from
     * frames_kin_alloc's calloc.  Clearing ~0.5 MB at each of the ~3 500 calls of a 101-speed
     * sweep of the 48-element angled beam was a tenth of its equilibrium (issue 27). */
    int jac = k->Jn.a != NULL;
    const sm_node *c0 = &m->nodes[m->clamp_node];
    k->rn[3 * m->clamp_node] = c0->x;
    k->rn[3 * m->clamp_node + 1] = c0->y;
    k->rn[3 * m->clamp_node + 2] = 0.0;
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        if (b->parent < 0) {
            k->theta[s] = b->beta;
            k->R[2 * s] = m->nodes[b->root].x;
            k->R[2 * s + 1] = m->nodes[b->root].y;
        } else {
            const sm_sub *p = &m->subs[b->parent];
            int a = b->attach_local, e = b->root;
            /* eq. 36: theta_c = theta_s + Nphi_e q_s + beta_c, R_c = r_e */
            double th = k->theta[b->parent] + b->beta;
            for (int j = 0; j < p->m; j++)
                th += DM(&p->N, 3 * a + 2, j) * q[p->q0 + j];
            k->theta[s] = th;
            k->R[2 * s] = k->rn[3 * e];
            k->R[2 * s + 1] = k->rn[3 * e + 1];
            if (jac) {
                int lim = p->q0 + p->m;
                memcpy(&DM(&k->Jth, 0, s), &DM(&k->Jth, 0, b->parent), (size_t)lim * sizeof(double));
                for (int j = 0; j < p->m; j++)
                    DM(&k->Jth, p->q0 + j, s) += DM(&p->N, 3 * a + 2, j);
                memcpy(&DM(&k->JR, 0, 2 * s), &DM(&k->Jn, 0, 3 * e), (size_t)lim * sizeof(double));
                memcpy(&DM(&k->JR, 0, 2 * s + 1), &DM(&k->Jn, 0, 3 * e + 1), (size_t)lim * sizeof(double));
            }
        }
        for (int i = 0; i < b->nfree; i++) {
            int nd = b->free_nodes[i];
            const double *N = b->N.a + 3 * i;
            frames_point(b, k, s, q, b->ubar + 2 * i, N, b->N.rows, N + 2, k->rn + 3 * nd, k->wn + 2 * nd,
                         jac ? &DM(&k->Jn, 0, 3 * nd) : NULL, jac ? &DM(&k->Jn, 0, 3 * nd + 1) : NULL,
                         jac ? &DM(&k->Jn, 0, 3 * nd + 2) : NULL, k->rn + 3 * nd + 2);
        }
    }
    for (int p = 0; p < m->n_mp; p++) {
        const sm_mpoint *mp = &m->mp[p];
        if (mp->node >= 0) { /* a node: copy */
            int nd = mp->node, lim = m->subs[mp->sub].q0 + m->subs[mp->sub].m;
            k->rp[2 * p] = k->rn[3 * nd];
            k->rp[2 * p + 1] = k->rn[3 * nd + 1];
            k->wp[2 * p] = k->wn[2 * nd];
            k->wp[2 * p + 1] = k->wn[2 * nd + 1];
            if (jac) {
                memcpy(&DM(&k->Jp, 0, 2 * p), &DM(&k->Jn, 0, 3 * nd), (size_t)lim * sizeof(double));
                memcpy(&DM(&k->Jp, 0, 2 * p + 1), &DM(&k->Jn, 0, 3 * nd + 1), (size_t)lim * sizeof(double));
            }
        } else {
            frames_point(&m->subs[mp->sub], k, mp->sub, q, mp->ub, mp->N, mp->ldn, NULL, k->rp + 2 * p,
                         k->wp + 2 * p, jac ? &DM(&k->Jp, 0, 2 * p) : NULL,
                         jac ? &DM(&k->Jp, 0, 2 * p + 1) : NULL, NULL, NULL);
        }
    }
}

/** g = sum_p m_p J_p' r_p (so the centrifugal generalised force is Omega^2 g). */
void frames_centrifugal(const sm_model *m, const sm_kin *k, double *g)
{
    memset(g, 0, (size_t)m->n * sizeof(double));
    for (int p = 0; p < m->n_mp; p++) {
        const sm_sub *b = &m->subs[m->mp[p].sub];
        int lim = b->q0 + b->m;
        double fx = m->mp[p].mass * k->rp[2 * p], fy = m->mp[p].mass * k->rp[2 * p + 1];
        const double *jx = &DM(&k->Jp, 0, 2 * p), *jy = &DM(&k->Jp, 0, 2 * p + 1);
        for (int j = 0; j < lim; j++)
            g[j] += jx[j] * fx + jy[j] * fy;
    }
}

/* Accumulate force f at local position w with translation rows N into (a, gs). */
static void frames_hess_point(double c, double si, const double *f, const double *w,
                              const double *N, int ldn, int mm, double *a, double *gs)
{
    /* a += f . (A'' w) = -f . (A w) */
    *a -= f[0] * (c * w[0] - si * w[1]) + f[1] * (si * w[0] + c * w[1]);
    /* gs += N' A'' f  with A' = [[-s,-c],[c,-s]] */
    double t0 = -si * f[0] + c * f[1], t1 = -c * f[0] - si * f[1];
    for (int j = 0; j < mm; j++)
        gs[j] += N[(size_t)ldn * j] * t0 + N[(size_t)ldn * j + 1] * t1;
}

/**
 * H = sum_p m_p r_p . d2 r_p/dq2 (symmetric, added to *H).  work: >= n doubles.
 * Per substructure s with total subtree force F acting through its frame:
 *   H += a_s Jth Jth' + E_s g_s Jth' + Jth g_s' E_s'
 *   a_s = -sum f.(A w),  g_s = sum N' A'' f,  and F_s is passed to the parent
 *   as a force at the attachment node (R_s = r_e).
 */
void frames_hessian(const sm_model *m, const double *q, const sm_kin *k, dmat *H, double *work)
{
    (void)q;
    double *F = k->fext;
    memset(F, 0, 2 * (size_t)m->n_nodes * sizeof(double));
    /* mass points grouped by substructure: iterate substructures leaves first */
    for (int s = m->n_subs - 1; s >= 0; s--) {
        const sm_sub *b = &m->subs[s];
        int mm = b->m, q0 = b->q0;
        double th = k->theta[s], c = cos(th), si = sin(th), a = 0, Ft[2] = {0, 0};
        double *gs = work;
        memset(gs, 0, (size_t)mm * sizeof(double));
        for (int p = 0; p < m->n_mp; p++) {
            const sm_mpoint *mp = &m->mp[p];
            if (mp->sub != s)
                continue;
            double f[2] = {mp->mass * k->rp[2 * p], mp->mass * k->rp[2 * p + 1]};
            frames_hess_point(c, si, f, k->wp + 2 * p, mp->N, mp->ldn, mm, &a, gs);
            Ft[0] += f[0];
            Ft[1] += f[1];
        }
        for (int i = 0; i < b->n_attach; i++) {
            int nd = b->free_nodes[b->attach[i]];
            const double *f = F + 2 * nd;
            frames_hess_point(c, si, f, k->wn + 2 * nd, b->N.a + 3 * b->attach[i], b->N.rows, mm, &a, gs);
            Ft[0] += f[0];
            Ft[1] += f[1];
        }
        if (b->parent >= 0) {
            F[2 * b->root] += Ft[0];
            F[2 * b->root + 1] += Ft[1];
        }
        const double *jt = &DM(&k->Jth, 0, s);
        double *jta = &DM(&k->Jtha, 0, s);
        /* column s of Jth is zero from row q0 on: theta_s depends on its ancestors only */
        for (int j = 0; j < q0; j++)
            jta[j] = a * jt[j];
        memset(jta + q0, 0, (size_t)(m->n - q0) * sizeof(double));
        for (int j = 0; j < q0; j++) {
            if (jt[j] == 0.0)
                continue;
            for (int i = 0; i < mm; i++) {
                DM(H, q0 + i, j) += gs[i] * jt[j];
                DM(H, j, q0 + i) += gs[i] * jt[j];
            }
        }
    }
    /* H += sum_s a_s Jth_s Jth_s' = Jtha Jth' (one BLAS-3 call instead of n_subs rank-1 updates) */
    if (m->n > 0 && m->n_subs > 0)
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, m->n, m->n, m->n_subs, 1.0, k->Jtha.a,
                    m->n, k->Jth.a, m->n, 1.0, H->a, m->n);
}
