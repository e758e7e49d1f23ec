/*
 * modes3.c — component-mode bases of the substructures of a spatial model
 * (DESIGN.md 7.2) and the points that carry its inertia.
 *
 * Each substructure is clamped at its root; its free nodes have 6 DOF
 * (u, v, w, psi_x, psi_y, psi_z in frame axes).  The basis is the complete
 * set of its component modes, Mbar phi = mu Kbar phi (mu = 1/omega^2: Kbar is
 * positive definite, Mbar may be singular when an inertia is zero), lowest
 * frequencies first, each scaled to unit amplitude (modes3_scale).  With modes_per_frame: the n lowest modes plus the static
 * response to a unit force and moment at every node carrying a child frame
 * (6 per attachment), made Kbar-orthogonal to the kept modes and
 * diagonalised among themselves (Rayleigh-Ritz), so that the joint
 * kinematics are never lost.
 * A large frame keeping few modes (D >= 200, modes_per_frame <= D/8: lowmodes_use) takes them
 * from the sparse Kbar, Mbar instead (modes3_sub_sparse, lowmodes.h), then the same static
 * modes, Rayleigh-Ritz and scaling; small frames, complete bases and sm_options.solver ==
 * SM_SOLVER_DENSE keep the dense complete decomposition bit for bit.
 * Points: every FE node (lumped mass, rotary inertia, mode shapes) and, for
 * consistent mass, 4 Gauss points per element (Hermite bending in both
 * planes, linear axial and torsion; translational and torsional inertia).
 */
#include "spatial.h"
#include "lowmodes.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MODES3_GAUSS 4
static const double modes3_gx[MODES3_GAUSS] = {-0.86113631159405258, -0.33998104358485626,
                                               0.33998104358485626, 0.86113631159405258};
static const double modes3_gw[MODES3_GAUSS] = {0.34785484513745386, 0.65214515486254614,
                                               0.65214515486254614, 0.34785484513745386};

int modes3_count(const sm_options *o, const sm_sub *b, int *nm, int *na)
{
    int full = 6 * b->nfree;
    *nm = o->modes_per_frame > 0 && o->modes_per_frame < full ? o->modes_per_frame : full;
    *na = *nm < full ? 6 * b->n_attach : 0;
    if (*nm + *na >= full) { /* the attachment modes would complete the basis: take it whole */
        *nm = full;
        *na = 0;
    }
    return *nm + *na;
}

/* First frame DOF (0 .. 6F) of FE node k in substructure b, or -1 (the root, or not in b). */
static int modes3_dof(const sm_model *m, const sm_sub *b, int k)
{
    const sm_node *nd = &m->nodes[k];
    if (k == b->root || nd->sub != (int)(b - m->subs))
        return -1;
    return 6 * nd->local;
}

/* E = A0' ax: the element axes in frame coordinates (columns). */
static void modes3_axes(const sm_sub *b, const sm_elem *e, double E[9])
{
    rot3_tmul_r(b->A0, e->ax, E);
}

/* Kbar (D x D, frame DOFs) += the element stiffness: k_frame = Q' k_loc Q, local = E' frame. */
static void modes3_add_element(const sm_model *m, const sm_sub *b, const sm_elem *e, const csym_sink *K)
{
    double k[144], E[9];
    int idx[2] = {modes3_dof(m, b, e->n1), modes3_dof(m, b, e->n2)};
    fe3_stiffness(e, k);
    modes3_axes(b, e, E);
    /* kq = k Q, block by block: (k Q)_{., 3c..3c+2} = k_{., 3c..} E' */
    double kq[144], kf[144];
    for (int c = 0; c < 4; c++)
        for (int i = 0; i < 12; i++)
            for (int j = 0; j < 3; j++) {
                double s = 0;
                for (int p = 0; p < 3; p++)
                    s += k[i + 12 * (3 * c + p)] * E[j + 3 * p]; /* (E')_{p j} = E_{j p} */
                kq[i + 12 * (3 * c + j)] = s;
            }
    for (int c = 0; c < 4; c++) /* kf = Q' kq: rows block c: E (kq rows 3c..) */
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 12; j++) {
                double s = 0;
                for (int p = 0; p < 3; p++)
                    s += E[i + 3 * p] * kq[(3 * c + p) + 12 * j];
                kf[(3 * c + i) + 12 * j] = s;
            }
    for (int h = 0; h < 2; h++)
        for (int g = 0; g < 2; g++)
            if (idx[h] >= 0 && idx[g] >= 0)
                for (int i = 0; i < 6; i++)
                    for (int j = 0; j < 6; j++)
                        csym_sink_add(K, idx[h] + i, idx[g] + j, kf[(6 * h + i) + 12 * (6 * g + j)]);
}

/*
 * Point interpolation S (6 x 12, column-major) at xi of an element: (u, v, w, psi) in frame axes
 * from the element's nodal frame DOFs (u1..psi1, u2..psi2), i.e. blockdiag(E, E) S_loc Q.
 */
static void modes3_interp(const sm_elem *e, const double E[9], double xi, double S[72])
{
    double sh[12], Sl[72];
    fe_shape(xi, e->l, sh); /* rows: axial, transverse; cols u1 v1 phi1 u2 v2 phi2 */
    memset(Sl, 0, sizeof Sl);
    for (int h = 0; h < 2; h++) {
        int o = 6 * h, p = 3 * h;
        Sl[0 + 6 * (o + 0)] = sh[0 + 2 * (p + 0)];         /* u  <- u_h */
        Sl[1 + 6 * (o + 1)] = sh[1 + 2 * (p + 1)];         /* v  <- v_h */
        Sl[1 + 6 * (o + 5)] = sh[1 + 2 * (p + 2)];         /* v  <- tz_h */
        Sl[2 + 6 * (o + 2)] = sh[1 + 2 * (p + 1)];         /* w  <- w_h */
        Sl[2 + 6 * (o + 4)] = -sh[1 + 2 * (p + 2)];        /* w  <- -ty_h */
        for (int r = 3; r < 6; r++)                        /* rotations: linear */
            Sl[r + 6 * (o + r)] = h ? xi : 1.0 - xi;
    }
    /* S = blockdiag(E, E) Sl Q, Q = blockdiag(E') x 4 */
    double T[72];
    for (int r = 0; r < 6; r++)
        for (int c = 0; c < 4; c++)
            for (int j = 0; j < 3; j++) {
                double s = 0;
                for (int p = 0; p < 3; p++)
                    s += Sl[r + 6 * (3 * c + p)] * E[j + 3 * p];
                T[r + 6 * (3 * c + j)] = s;
            }
    for (int b = 0; b < 2; b++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 12; j++) {
                double s = 0;
                for (int p = 0; p < 3; p++)
                    s += E[i + 3 * p] * T[(3 * b + p) + 6 * j];
                S[(3 * b + i) + 6 * j] = s;
            }
}

/* Mbar += m S_u' S_u + S_psi' I S_psi for a point with interpolation S (6 x 12) on idx. */
static void modes3_add_point_mass(const double S[72], const int idx[2], double mass, const double I[9],
                                  const csym_sink *M)
{
    double IS[36]; /* I S_psi: 3 x 12 */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 12; j++)
            IS[i + 3 * j] = I[i] * S[3 + 6 * j] + I[i + 3] * S[4 + 6 * j] + I[i + 6] * S[5 + 6 * j];
    for (int a = 0; a < 12; a++)
        for (int c = 0; c < 12; c++) {
            int ra = idx[a / 6], rc = idx[c / 6];
            if (ra < 0 || rc < 0)
                continue;
            double s = 0;
            for (int r = 0; r < 3; r++)
                s += mass * S[r + 6 * a] * S[r + 6 * c] + S[3 + r + 6 * a] * IS[r + 3 * c];
            csym_sink_add(M, ra + a % 6, rc + c % 6, s);
        }
}

/* I_frame = A0' I_hub A0. */
static void modes3_to_frame(const double A0[9], const double Ih[9], double If[9])
{
    double t[9];
    rot3_tmul_r(A0, Ih, t);
    rot3_mul_r(t, A0, If);
}

/* I (frame axes) = the torsional inertia (i_flap + i_edge) wl about the element axis e1 (the
 * first column of E), for a Gauss point of weight wl (m) of consistent mass. */
static void modes3_torsion_inertia(const sm_elem *e, const double E[9], double wl, double I[9])
{
    double ip = (e->i_flap + e->i_edge) * wl;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            I[r + 3 * c] = E[r] * ip * E[c];
}

/* Kbar and Mbar of substructure b (D = 6F), dense or into their sparse pattern. */
static void modes3_assemble(const sm_model *m, const sm_sub *b, const csym_sink *K, const csym_sink *M)
{
    int consistent = m->opt.mass == SM_MASS_CONSISTENT;
    for (int j = 0; j < b->nel; j++) {
        const sm_elem *e = &m->elems[b->elems[j]];
        modes3_add_element(m, b, e, K);
        if (!consistent)
            continue;
        double E[9], S[72], Ie[9];
        int idx[2] = {modes3_dof(m, b, e->n1), modes3_dof(m, b, e->n2)};
        modes3_axes(b, e, E);
        for (int g = 0; g < MODES3_GAUSS; g++) {
            double xi = 0.5 * (1.0 + modes3_gx[g]), wl = 0.5 * modes3_gw[g] * e->l;
            modes3_interp(e, E, xi, S);
            modes3_torsion_inertia(e, E, wl, Ie);
            modes3_add_point_mass(S, idx, e->mu * wl, Ie, M);
        }
    }
    for (int i = 0; i < b->nfree; i++) {
        const sm_node *nd = &m->nodes[b->free_nodes[i]];
        double If[9];
        modes3_to_frame(b->A0, consistent ? nd->point_rot : nd->rot, If);
        double mass = consistent ? nd->point_mass : nd->mass;
        for (int c = 0; c < 3; c++) {
            csym_sink_add(M, 6 * i + c, 6 * i + c, mass);
            for (int r = 0; r < 3; r++)
                csym_sink_add(M, 6 * i + 3 + r, 6 * i + 3 + c, If[r + 3 * c]);
        }
    }
}

/* Scale column x (D) of a mode to unit amplitude (largest |entry| = 1: 1 m or 1 rad).  Not
 * mass-normalisation: a mode with little or no mass (a rotation whose inertia is tiny or zero
 * inside the substructure, which still carries the child frames) would get entries of 1e5 and
 * more, and M* a spread that hides genuine inertia from the null-space split of eigen.c. */
static void modes3_scale(int D, double *x)
{
    double mx = 0;
    for (int r = 0; r < D; r++)
        mx = fmax(mx, fabs(x[r]));
    for (int r = 0; mx > 0 && r < D; r++)
        x[r] /= mx;
}

/*
 * Rayleigh-Ritz in the span of the columns of X (D x k, overwritten): Mbar y = mu Kbar y in that
 * span, columns returned Kbar-orthonormal in descending mu, mu in w (k).  work: none (allocates).
 */
static int modes3_ritz(int D, int k, const dmat *K, const dmat *M, double *X, double *w)
{
    int rc = SM_NOMEM;
    double *KX = dm_vec((size_t)D * k), *Kr = dm_vec((size_t)k * k), *Mr = dm_vec((size_t)k * k);
    double *Y = dm_vec((size_t)D * k);
    if (!KX || !Kr || !Mr || !Y)
        goto done;
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, D, k, D, 1.0, K->a, D, X, D, 0.0, KX, D);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, k, k, D, 1.0, X, D, KX, D, 0.0, Kr, k);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, D, k, D, 1.0, M->a, D, X, D, 0.0, KX, D);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, k, k, D, 1.0, X, D, KX, D, 0.0, Mr, k);
    rc = lowmodes_reduced(D, k, X, Kr, Mr, w, Y); /* descending mu, shared with lowmodes_ritz */
done:
    free(KX);
    free(Kr);
    free(Mr);
    free(Y);
    return rc;
}

/* The basis N (D x m_s) of substructure b from Kbar, Mbar. */
static int modes3_basis(const sm_model *m, sm_sub *b, const dmat *K, const dmat *M)
{
    int D = 6 * b->nfree, nm, na, rc = SM_NOMEM;
    modes3_count(&m->opt, b, &nm, &na);
    b->m = nm + na;
    double *X = dm_vec((size_t)D * D), *w = dm_vec((size_t)D), *KF = dm_vec((size_t)D * D);
    if (!X || !w || !KF || dm_alloc(&b->N, D, b->m))
        goto done;
    for (int i = 0; i < D; i++) /* the complete basis: identity, diagonalised by Rayleigh-Ritz */
        X[(size_t)D * i + i] = 1.0;
    if ((rc = modes3_ritz(D, D, K, M, X, w)) < 0)
        goto done;
    memcpy(b->N.a, X, (size_t)D * nm * sizeof(double));
    if (na > 0) {
        /* static attachment modes: Kbar^-1 (unit force and moment at each attachment node) */
        double *Z = b->N.a + (size_t)D * nm;
        for (int a = 0; a < b->n_attach; a++)
            for (int c = 0; c < 6; c++)
                Z[(size_t)D * (6 * a + c) + 6 * b->attach[a] + c] = 1.0;
        memcpy(KF, K->a, (size_t)D * D * sizeof(double));
        if ((rc = dm_lapack_status(LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', D, na, KF, D, Z, D), SM_SINGULAR)) < 0)
            goto done;
        /* Z -= Phi (Phi' Kbar Z): Kbar-orthogonal to the kept (Kbar-orthonormal) modes */
        double *KZ = X; /* reuse: D x na */
        double *C = KF; /* nm x na */
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, D, na, D, 1.0, K->a, D, Z, D, 0.0, KZ, D);
        cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, nm, na, D, 1.0, b->N.a, D, KZ, D, 0.0, C, nm);
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, D, na, nm, -1.0, b->N.a, D, C, nm, 1.0, Z, D);
        if ((rc = modes3_ritz(D, na, K, M, Z, w + nm)) < 0)
            goto done;
    }
    for (int j = 0; j < b->m; j++)
        modes3_scale(D, b->N.a + (size_t)D * j);
    rc = SM_OK;
done:
    free(X);
    free(w);
    free(KF);
    return rc;
}

/* K_s = N' Kbar N (eq. 11), exactly symmetric. */
static int modes3_reduced_stiffness(sm_sub *b, const dmat *K)
{
    int D = 6 * b->nfree, mm = b->m;
    double *KN = dm_vec((size_t)D * mm);
    if (!KN || dm_alloc(&b->K, mm, mm)) {
        free(KN);
        return SM_NOMEM;
    }
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, D, mm, D, 1.0, K->a, D, b->N.a, D, 0.0, KN, D);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, mm, mm, D, 1.0, b->N.a, D, KN, D, 0.0, b->K.a, mm);
    for (int i = 0; i < mm; i++)
        for (int j = 0; j < i; j++)
            DM(&b->K, i, j) = DM(&b->K, j, i) = 0.5 * (DM(&b->K, i, j) + DM(&b->K, j, i));
    free(KN);
    return SM_OK;
}

/* T_e (12 rows per element: local DOFs = E' frame DOFs of each end) and d_e (P_e = d_e . q_s). */
static int modes3_elements(const sm_model *m, sm_sub *b)
{
    int mm = b->m;
    if (dm_alloc(&b->T, 12 * b->nel, mm))
        return SM_NOMEM;
    b->d = dm_vec((size_t)b->nel * mm);
    if (!b->d)
        return SM_NOMEM;
    for (int j = 0; j < b->nel; j++) {
        const sm_elem *e = &m->elems[b->elems[j]];
        double E[9];
        int idx[2] = {modes3_dof(m, b, e->n1), modes3_dof(m, b, e->n2)};
        modes3_axes(b, e, E);
        for (int h = 0; h < 2; h++) {
            if (idx[h] < 0)
                continue; /* the root: clamped in this basis */
            for (int c = 0; c < mm; c++)
                for (int g = 0; g < 2; g++) /* translation, rotation */
                    for (int i = 0; i < 3; i++) {
                        const double *x = &DM(&b->N, idx[h] + 3 * g, c);
                        DM(&b->T, 12 * j + 6 * h + 3 * g + i, c) = E[3 * i] * x[0] + E[3 * i + 1] * x[1] + E[3 * i + 2] * x[2];
                    }
        }
        for (int c = 0; c < mm; c++) {
            double u2 = DM(&b->T, 12 * j + 6, c), u1 = DM(&b->T, 12 * j, c);
            if (e->tc[0] != 0.0 || e->tc[1] != 0.0) { /* the strain of the tension centre */
                u2 += e->tc[1] * DM(&b->T, 12 * j + 10, c) - e->tc[0] * DM(&b->T, 12 * j + 11, c);
                u1 += e->tc[1] * DM(&b->T, 12 * j + 4, c) - e->tc[0] * DM(&b->T, 12 * j + 5, c);
            }
            b->d[(size_t)j * mm + c] = e->EA / e->l * (u2 - u1);
        }
    }
    return SM_OK;
}

/*
 * Lumped mass with SM_ROTARY_TORSION (DESIGN.md 8.5): the nodes' I carries the sections' torsional
 * mass moment only; their Ic (the propeller moment) gets the bending parts back, half an
 * element's rot_pl less its torsion on each end, as consistent mass's Gauss points have it and
 * BModes (Struct.f90:1067, 1298: the torsional stiffness Omega^2 (i_edge - i_flap) cos 2theta).
 */
static void modes3_bending_ic(sm_model *m)
{
    for (int j = 0; j < m->n_elems; j++) {
        const sm_elem *e = &m->elems[j];
        int ends[2] = {e->n1, e->n2};
        double B[9], Bf[9], ip = e->i_flap + e->i_edge;
        for (int i = 0; i < 9; i++) /* bending part, hub axes: rot_pl - ip e1 e1' */
            B[i] = 0.5 * e->l * (e->rot_pl[i] - ip * e->ax[i % 3] * e->ax[i / 3]);
        for (int h = 0; h < 2; h++) {
            sp_point *p = &m->pt[ends[h]];
            if (m->nodes[ends[h]].sub < 0)
                continue;
            if (p->has_Ic != 2)
                memcpy(p->Ic, p->I, sizeof p->Ic);
            p->has_Ic = 2; /* set: not a copy of I */
            modes3_to_frame(m->subs[m->nodes[ends[h]].sub].A0, B, Bf);
            for (int i = 0; i < 9; i++)
                p->Ic[i] += Bf[i];
        }
    }
}

/* The points: FE nodes first (index = node), then the Gauss points of consistent mass. */
int modes3_points(sm_model *m)
{
    int consistent = m->opt.mass == SM_MASS_CONSISTENT, n_off = 0;
    for (int k = 0; k < m->n_nodes; k++) {
        const double *f = consistent ? m->nodes[k].point_first : m->nodes[k].first;
        n_off += m->nodes[k].sub >= 0 && (f[0] != 0.0 || f[1] != 0.0 || f[2] != 0.0);
    }
    m->n_pt = m->n_nodes + (consistent ? MODES3_GAUSS * m->n_elems : 0) + n_off;
    m->pt = calloc((size_t)m->n_pt, sizeof(sp_point));
    if (!m->pt)
        return SM_NOMEM;
    for (int k = 0; k < m->n_nodes; k++) {
        const sm_node *nd = &m->nodes[k];
        sp_point *p = &m->pt[k];
        p->node = k;
        p->sub = nd->sub;
        if (nd->sub < 0) { /* the clamp: fixed at its hub position */
            p->ub[0] = nd->x, p->ub[1] = nd->y, p->ub[2] = nd->z;
            if (m->base) { /* a free base: its mass and inertia (hub axes) move with it */
                p->mass = consistent ? nd->point_mass : nd->mass;
                memcpy(p->I, consistent ? nd->point_rot : nd->rot, sizeof p->I);
            }
            continue;
        }
        const sm_sub *b = &m->subs[nd->sub];
        memcpy(p->ub, b->ubar + 3 * nd->local, sizeof p->ub);
        p->mass = consistent ? nd->point_mass : nd->mass;
        modes3_to_frame(b->A0, consistent ? nd->point_rot : nd->rot, p->I);
        p->N = b->N.a + 6 * nd->local;
        p->ldn = b->N.rows;
    }
    int np = m->n_nodes;
    if (consistent)
        np += MODES3_GAUSS * m->n_elems;
    for (int k = 0; k < m->n_nodes; k++) { /* offset masses (DESIGN.md 8): the node keeps the
                                              rotary inertia about the centre of mass */
        const sm_node *nd = &m->nodes[k];
        const double *f = consistent ? nd->point_first : nd->first;
        if (nd->sub < 0 || (f[0] == 0.0 && f[1] == 0.0 && f[2] == 0.0))
            continue;
        sp_point *p = &m->pt[k], *o = &m->pt[np++];
        double c[3] = {f[0] / p->mass, f[1] / p->mass, f[2] / p->mass}, par[9] = {0}, cf[9];
        double c2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                par[i + 3 * j] = p->mass * ((i == j ? c2 : 0.0) - c[i] * c[j]);
        modes3_to_frame(m->subs[nd->sub].A0, par, cf);
        for (int i = 0; i < 9; i++)
            p->I[i] -= cf[i]; /* parallel axes: about the centre of mass */
        *o = *p;
        o->node = -1;
        memset(o->I, 0, sizeof o->I);
        const double *A0 = m->subs[nd->sub].A0;
        for (int i = 0; i < 3; i++) /* frame axes at rest */
            o->c[i] = A0[3 * i] * c[0] + A0[3 * i + 1] * c[1] + A0[3 * i + 2] * c[2];
        o->has_c = 1;
        p->mass = 0.0;
    }
    if (!consistent) {
        if (m->opt.rotary_inertia == SM_ROTARY_TORSION)
            modes3_bending_ic(m);
        goto inertia;
    }
    np = m->n_nodes;
    for (int s = 0; s < m->n_subs; s++) {
        sm_sub *b = &m->subs[s];
        int mm = b->m, D = 6 * b->nfree;
        b->qpN = dm_vec((size_t)b->nel * MODES3_GAUSS * 6 * mm);
        if (!b->qpN)
            return SM_NOMEM;
        for (int j = 0; j < b->nel; j++) {
            const sm_elem *e = &m->elems[b->elems[j]];
            double E[9], S[72], u[2][3] = {{0}};
            int idx[2] = {modes3_dof(m, b, e->n1), modes3_dof(m, b, e->n2)};
            modes3_axes(b, e, E);
            for (int h = 0; h < 2; h++)
                if (idx[h] >= 0)
                    memcpy(u[h], b->ubar + idx[h] / 2, sizeof u[h]); /* 6 local -> 3 ubar */
            for (int g = 0; g < MODES3_GAUSS; g++) {
                double xi = 0.5 * (1.0 + modes3_gx[g]), wl = 0.5 * modes3_gw[g] * e->l;
                double *Nq = b->qpN + (size_t)(MODES3_GAUSS * j + g) * 6 * mm;
                modes3_interp(e, E, xi, S);
                for (int c = 0; c < mm; c++) /* N_p = S [N rows of the two ends] */
                    for (int r = 0; r < 6; r++) {
                        double v = 0;
                        for (int h = 0; h < 2; h++)
                            if (idx[h] >= 0)
                                for (int i = 0; i < 6; i++)
                                    v += S[r + 6 * (6 * h + i)] * b->N.a[(size_t)D * c + idx[h] + i];
                        Nq[6 * c + r] = v;
                    }
                sp_point *p = &m->pt[np++];
                p->sub = s;
                p->node = -1;
                for (int i = 0; i < 3; i++)
                    p->ub[i] = u[0][i] + xi * (u[1][i] - u[0][i]);
                p->mass = e->mu * wl;
                modes3_torsion_inertia(e, E, wl, p->I);
                double Iw[9];
                for (int i = 0; i < 9; i++)
                    Iw[i] = e->rot_pl[i] * wl;
                modes3_to_frame(b->A0, Iw, p->Ic);
                p->has_Ic = 2; /* set: not a copy of I */
                if (e->cg[0] != 0.0 || e->cg[1] != 0.0 || e->cg[2] != 0.0) {
                    const double *A0 = b->A0;
                    for (int i = 0; i < 3; i++)
                        p->c[i] = A0[3 * i] * e->cg[0] + A0[3 * i + 1] * e->cg[1] + A0[3 * i + 2] * e->cg[2];
                    p->has_c = 1;
                }
                p->N = Nq;
                p->ldn = 6;
            }
        }
    }
inertia:
    for (int k = 0; k < m->n_pt; k++) {
        sp_point *p = &m->pt[k];
        if (p->has_Ic != 2) /* every point but a consistent-mass Gauss point */
            memcpy(p->Ic, p->I, sizeof p->Ic);
        p->has_I = p->has_Ic = 0;
        for (int i = 0; i < 9; i++) {
            p->has_I |= p->I[i] != 0.0;
            p->has_Ic |= p->Ic[i] != 0.0;
        }
    }
    return SM_OK;
}

/*
 * The basis N of b from the sparse Kbar (factor F) and Mbar when it keeps nm << D modes
 * (lowmodes.h): the nm lowest by subspace iteration, then the same steps as modes3_basis --
 * static attachment modes, Kbar-orthogonal to the kept ones, Rayleigh-Ritz among themselves,
 * every column scaled by modes3_scale.  *fallback = 1 (nothing allocated) when the iteration
 * does not converge: the caller takes the dense path.
 */
static int modes3_basis_sparse(const sm_model *m, sm_sub *b, const csym *K, const csym_ldl *F, const csym *M,
                               int *fallback)
{
    int D = 6 * b->nfree, nm, na, rc = SM_NOMEM;
    modes3_count(&m->opt, b, &nm, &na);
    int p = lowmodes_block(D, nm);
    double *X = dm_vec((size_t)D * p), *w = dm_vec((size_t)p + na), *KZ = dm_vec((size_t)D * (na ? na : 1));
    double *C = dm_vec((size_t)nm * (na ? na : 1));
    if (!X || !w || !KZ || !C)
        goto done;
    if ((rc = lowmodes_solve(K, F, M, nm, X, w, fallback)) < 0 || *fallback)
        goto done;
    rc = SM_NOMEM;
    b->m = nm + na;
    if (dm_alloc(&b->N, D, b->m))
        goto done;
    memcpy(b->N.a, X, (size_t)D * nm * sizeof(double));
    if (na > 0) {
        /* static attachment modes: Kbar^-1 (unit force and moment at each attachment node) */
        double *Z = b->N.a + (size_t)D * nm;
        for (int a = 0; a < b->n_attach; a++)
            for (int c = 0; c < 6; c++)
                Z[(size_t)D * (6 * a + c) + 6 * b->attach[a] + c] = 1.0;
        if ((rc = csym_solve_refined(K, F, na, Z, D)) < 0)
            goto done;
        /* Z -= Phi (Phi' Kbar Z): Kbar-orthogonal to the kept (Kbar-orthonormal) modes */
        csym_mul_acc(K, na, Z, D, KZ, D);
        cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, nm, na, D, 1.0, b->N.a, D, KZ, D, 0.0, C, nm);
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, D, na, nm, -1.0, b->N.a, D, C, nm, 1.0, Z, D);
        if ((rc = lowmodes_ritz(K, M, na, Z, w + nm)) < 0)
            goto done;
    }
    for (int j = 0; j < b->m; j++)
        modes3_scale(D, b->N.a + (size_t)D * j);
    rc = SM_OK;
done:
    free(X);
    free(w);
    free(KZ);
    free(C);
    return rc;
}

int modes3_frame_csym(const sm_model *m, const sm_sub *b, csym *K, csym *M)
{
    int rc = lowmodes_frame_pattern(m, b, 6, K);
    if (rc == SM_OK)
        rc = lowmodes_frame_pattern(m, b, 6, M);
    if (rc == SM_OK) {
        csym_sink ks = {NULL, K}, ms = {NULL, M};
        modes3_assemble(m, b, &ks, &ms);
    }
    return rc;
}

/* modes3_sub on the sparse path: Kbar, Mbar in their pattern, the basis, K_s, T_e, d_e. */
static int modes3_sub_sparse(const sm_model *m, sm_sub *b, int *fallback)
{
    csym K = {0}, M = {0};
    csym_ldl F = {0};
    int rc = modes3_frame_csym(m, b, &K, &M);
    if (rc == SM_OK)
        rc = csym_factor(&K, &F);
    if (rc == SM_OK)
        rc = modes3_basis_sparse(m, b, &K, &F, &M, fallback);
    if (rc == SM_OK && !*fallback)
        rc = lowmodes_project(&K, &b->N, &b->K);
    if (rc == SM_OK && !*fallback)
        rc = modes3_elements(m, b);
    csym_free(&K);
    csym_free(&M);
    csym_ldl_free(&F);
    return rc;
}

int modes3_sub(const sm_model *m, sm_sub *b)
{
    int D = 6 * b->nfree, nm, na, fallback = 0;
    modes3_count(&m->opt, b, &nm, &na);
    if (lowmodes_use(&m->opt, D, nm)) {
        int rc = modes3_sub_sparse(m, b, &fallback);
        if (rc < 0 || !fallback)
            return rc;
    }
    dmat K = {0}, M = {0};
    int rc = dm_alloc(&K, D, D);
    if (rc == SM_OK)
        rc = dm_alloc(&M, D, D);
    if (rc == SM_OK) {
        csym_sink ks = {&K, NULL}, ms = {&M, NULL};
        modes3_assemble(m, b, &ks, &ms);
        rc = modes3_basis(m, b, &K, &M);
    }
    if (rc == SM_OK)
        rc = modes3_reduced_stiffness(b, &K);
    if (rc == SM_OK)
        rc = modes3_elements(m, b);
    dm_free(&K);
    dm_free(&M);
    return rc;
}
