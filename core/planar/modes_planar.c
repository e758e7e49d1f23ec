/*
 * modes_planar.c — the planar kind's component-mode bases N_s of the substructures (DESIGN.md 1.2,
 * Kim & Yoo eqs. 2, 11, 18, 24) and the mass points that carry the inertia.
 *
 * Each substructure is clamped at its root node.  Its free-node DOFs are
 * (u, v, phi) per node in the substructure frame.
 *  - lumped mass, basis "paper": the rotations are massless and are condensed
 *    statically, X = -Krr^-1 Krt, Kc = Ktt + Ktr X; Kc phi = w^2 Mt phi;
 *    N = [phi; X phi] (all 2F modes by default).
 *  - basis "augmented": in addition, for every attachment node (where a child
 *    frame sits) one column with zero translations, unit rotation at that
 *    node and the other rotations condensed.  Together with the paper modes it
 *    spans {(t, a, c(t, a))}: the attachment rotations are free coordinates.
 *  - consistent mass: modes of the full consistent-mass substructure; with a
 *    truncation and the augmented basis, unit-moment static modes are added
 *    (M-orthogonalised against the kept modes).
 *  - a large frame keeping few modes (D >= 200 DOF, modes_per_frame <= D/8:
 *    lowmodes_use) gets the same basis without D x D matrices: Kbar, Mbar in
 *    their sparse pattern, the nm lowest modes by subspace iteration on the
 *    sparse LDL' of Kbar (lowmodes.h), the attachment columns from that factor,
 *    the same order and normalisation (modes_sub_sparse).  Small frames,
 *    complete bases and sm_options.solver == SM_SOLVER_DENSE keep the dense
 *    path below bit for bit.
 * Then per element: T_e = C(alpha) L_e N, d_e (P_e = d_e . q_s) and the
 * bending block of G_e; and the mass points (nodes, or Gauss points of every
 * element for consistent mass, plus point masses).
 *
 * How it fits: model/modes.c drives the build and calls modes_planar_sub per frame and
 * modes_planar_points at the end through the planar kind's table (kind_planar.c).
 */
#include "kind.h"
#include "lowmodes.h"

#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Local DOF index (0..3F) of component c of FE node k in substructure b, or -1. */
static int modes_dof(const sm_model *m, const sm_sub *b, int k, int c)
{
    const sm_node *nd = &m->nodes[k];
    if (k == b->root || nd->sub != (int)(b - m->subs))
        return -1;
    return 3 * nd->local + c;
}

/* Kbar (and Mbar for consistent mass, M not NULL) of a substructure in its frame, dense or
 * into their sparse pattern. */
static void modes_assemble(const sm_model *m, const sm_sub *b, const csym_sink *K, const csym_sink *M)
{
    double kl[36], kf[36];
    for (int j = 0; j < b->nel; j++) {
        const sm_elem *e = &m->elems[b->elems[j]];
        double alpha = e->angle - b->theta0;
        int idx[6];
        for (int c = 0; c < 3; c++) {
            idx[c] = modes_dof(m, b, e->n1, c);
            idx[3 + c] = modes_dof(m, b, e->n2, c);
        }
        fe_stiffness_local(e->EA, e->EI, e->l, kl);
        fe_to_frame(kl, alpha, kf);
        for (int r = 0; r < 6; r++)
            for (int c = 0; c < 6; c++)
                if (idx[r] >= 0 && idx[c] >= 0)
                    csym_sink_add(K, idx[r], idx[c], kf[r + 6 * c]);
        if (M) {
            fe_mass_consistent_local(e->mu, e->l, kl);
            fe_to_frame(kl, alpha, kf);
            for (int r = 0; r < 6; r++)
                for (int c = 0; c < 6; c++)
                    if (idx[r] >= 0 && idx[c] >= 0)
                        csym_sink_add(M, idx[r], idx[c], kf[r + 6 * c]);
        }
    }
    if (M) /* point masses (translations) */
        for (int i = 0; i < b->nfree; i++) {
            double pm = m->nodes[b->free_nodes[i]].point_mass;
            csym_sink_add(M, 3 * i, 3 * i, pm);
            csym_sink_add(M, 3 * i + 1, 3 * i + 1, pm);
        }
}

/**
 * The number of modal coordinates substructure b gets under the options,
 * from its topology alone (nfree, n_attach): *nm component modes plus *na
 * attachment columns; returns *nm + *na.  Lumped mass: 2F condensed modes
 * (F free nodes), truncated to modes_per_frame, plus the attachment nodes for
 * the augmented basis.  Consistent mass: 3F modes, truncated, plus static
 * attachment modes for the augmented basis only when truncated (the full
 * basis already spans them).  modes_lumped/modes_consistent size N with it,
 * and sm_structure_check predicts the model's sizes with it.
 */
int modes_count(const sm_options *o, const sm_sub *b, int *nm, int *na)
{
    int full = o->mass == SM_MASS_CONSISTENT ? 3 * b->nfree : 2 * b->nfree;
    *nm = o->modes_per_frame > 0 && o->modes_per_frame < full ? o->modes_per_frame : full;
    if (o->basis != SM_BASIS_AUGMENTED)
        *na = 0;
    else if (o->mass == SM_MASS_CONSISTENT)
        *na = *nm < full ? b->n_attach : 0;
    else
        *na = b->n_attach;
    return *nm + *na;
}

static int modes_is_attach(const sm_sub *b, int i)
{
    for (int a = 0; a < b->n_attach; a++)
        if (b->attach[a] == i)
            return 1;
    return 0;
}

/*
 * Lumped mass: paper basis (condensed rotations) + attachment columns.
 * Fills b->N with 3F rows.
 */
static int modes_lumped(const sm_model *m, sm_sub *b, const dmat *K)
{
    int F = b->nfree, T = 2 * F, rc = SM_NOMEM, nm, na;
    modes_count(&m->opt, b, &nm, &na);
    dmat Krr = {0}, X = {0}, Kc = {0}, Kcc = {0}, Y = {0};
    double *w = dm_vec((size_t)T), *sq = dm_vec((size_t)T);
    int *cidx = malloc((size_t)F * sizeof(int));
    if (!w || !sq || !cidx || dm_alloc(&Krr, F, F) || dm_alloc(&X, F, T) || dm_alloc(&Kc, T, T))
        goto done;
    for (int i = 0; i < F; i++)
        for (int j = 0; j < F; j++)
            DM(&Krr, i, j) = DM(K, 3 * i + 2, 3 * j + 2);
    /* X = -Krr^-1 Krt */
    for (int i = 0; i < F; i++)
        for (int j = 0; j < T; j++)
            DM(&X, i, j) = -DM(K, 3 * i + 2, 3 * (j / 2) + j % 2);
    rc = dm_lapack_status(LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', F, T, Krr.a, F, X.a, F), SM_SINGULAR);
    if (rc < 0)
        goto done;
    /* Kc = Ktt + Ktr X, scaled: D^-1/2 Kc D^-1/2 with D the node masses */
    for (int i = 0; i < T; i++)
        sq[i] = 1.0 / sqrt(m->nodes[b->free_nodes[i / 2]].mass);
    for (int i = 0; i < T; i++)
        for (int j = 0; j < T; j++) {
            double s = DM(K, 3 * (i / 2) + i % 2, 3 * (j / 2) + j % 2);
            for (int p = 0; p < F; p++)
                s += DM(K, 3 * (i / 2) + i % 2, 3 * p + 2) * DM(&X, p, j);
            DM(&Kc, i, j) = s * sq[i] * sq[j];
        }
    rc = dm_lapack_status(LAPACKE_dsyevd(LAPACK_COL_MAJOR, 'V', 'U', T, Kc.a, T, w), SM_LAPACK_FAILED);
    if (rc < 0)
        goto done;
    rc = SM_NOMEM;
    b->m = nm + na;
    if (dm_alloc(&b->N, 3 * F, b->m))
        goto done;
    for (int j = 0; j < nm; j++) {
        /* phi = D^-1/2 v (mass-normalised); rotations = X phi */
        for (int i = 0; i < T; i++)
            DM(&b->N, 3 * (i / 2) + i % 2, j) = sq[i] * DM(&Kc, i, j);
        for (int p = 0; p < F; p++) {
            double s = 0;
            for (int i = 0; i < T; i++)
                s += DM(&X, p, i) * sq[i] * DM(&Kc, i, j);
            DM(&b->N, 3 * p + 2, j) = s;
        }
    }
    if (na > 0) {
        /* attachment columns: t = 0, phi_a = 1, phi_c = -Kcc^-1 Kca */
        int nc = 0;
        for (int i = 0; i < F; i++)
            if (!modes_is_attach(b, i))
                cidx[nc++] = i;
        if (dm_alloc(&Kcc, nc, nc) || dm_alloc(&Y, nc, na))
            goto done;
        for (int i = 0; i < nc; i++) {
            for (int j = 0; j < nc; j++)
                DM(&Kcc, i, j) = DM(K, 3 * cidx[i] + 2, 3 * cidx[j] + 2);
            for (int a = 0; a < na; a++)
                DM(&Y, i, a) = -DM(K, 3 * cidx[i] + 2, 3 * b->attach[a] + 2);
        }
        if (nc > 0 &&
            (rc = dm_lapack_status(LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', nc, na, Kcc.a, nc, Y.a, nc),
                                   SM_SINGULAR)) < 0)
            goto done;
        for (int a = 0; a < na; a++) {
            DM(&b->N, 3 * b->attach[a] + 2, nm + a) = 1.0;
            for (int i = 0; i < nc; i++)
                DM(&b->N, 3 * cidx[i] + 2, nm + a) = DM(&Y, i, a);
        }
    }
    rc = SM_OK;
done:
    dm_free(&Krr);
    dm_free(&X);
    dm_free(&Kc);
    dm_free(&Kcc);
    dm_free(&Y);
    free(w);
    free(sq);
    free(cidx);
    return rc;
}

/* Consistent mass: modes of the full substructure (+ static attachment modes). */
static int modes_consistent(const sm_model *m, sm_sub *b, const dmat *K, const dmat *M)
{
    int D = 3 * b->nfree, rc = SM_NOMEM, nm, na;
    modes_count(&m->opt, b, &nm, &na);
    dmat A = {0}, B = {0}, F = {0};
    double *w = dm_vec((size_t)D), *mx = dm_vec((size_t)D);
    if (!w || !mx || dm_alloc(&A, D, D) || dm_alloc(&B, D, D))
        goto done;
    memcpy(A.a, K->a, (size_t)D * D * sizeof(double));
    memcpy(B.a, M->a, (size_t)D * D * sizeof(double));
    /* info > D: the mass matrix is not positive definite; 0 < info <= D: no convergence */
    int info = LAPACKE_dsygvd(LAPACK_COL_MAJOR, 1, 'V', 'U', D, A.a, D, B.a, D, w);
    rc = dm_lapack_status(info, info > D ? SM_SINGULAR : SM_LAPACK_FAILED);
    if (rc < 0)
        goto done;
    rc = SM_NOMEM;
    b->m = nm + na;
    if (dm_alloc(&b->N, D, b->m))
        goto done;
    memcpy(b->N.a, A.a, (size_t)D * nm * sizeof(double));
    if (na > 0) {
        if (dm_alloc(&F, D, D))
            goto done;
        memcpy(F.a, K->a, (size_t)D * D * sizeof(double));
        double *rhs = b->N.a + (size_t)D * nm;
        for (int a = 0; a < na; a++)
            rhs[(size_t)D * a + 3 * b->attach[a] + 2] = 1.0;
        rc = dm_lapack_status(LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', D, na, F.a, D, rhs, D), SM_SINGULAR);
        if (rc < 0)
            goto done;
        /* M-orthogonalise each static mode against the kept modes and earlier ones */
        for (int a = 0; a < nm + na; a++) {
            if (a < nm)
                continue;
            double *x = b->N.a + (size_t)D * a;
            for (int pass = 0; pass < 2; pass++)
                for (int j = 0; j < a; j++) {
                    const double *v = b->N.a + (size_t)D * j;
                    double s = 0;
                    for (int r = 0; r < D; r++) {
                        double t = 0;
                        for (int c = 0; c < D; c++)
                            t += DM(M, r, c) * x[c];
                        s += v[r] * t;
                    }
                    for (int r = 0; r < D; r++)
                        x[r] -= s * v[r];
                }
            double nrm = 0;
            for (int r = 0; r < D; r++) {
                double t = 0;
                for (int c = 0; c < D; c++)
                    t += DM(M, r, c) * x[c];
                nrm += x[r] * t;
            }
            rc = SM_SINGULAR;
            if (!(nrm > 1e-24))
                goto done;
            for (int r = 0; r < D; r++)
                x[r] /= sqrt(nrm);
        }
    }
    rc = SM_OK;
done:
    dm_free(&A);
    dm_free(&B);
    dm_free(&F);
    free(w);
    free(mx);
    return rc;
}

/* K_s = N' Kbar N (eq. 11). */
static int modes_reduced_stiffness(sm_sub *b, const dmat *K)
{
    int D = 3 * b->nfree, mm = b->m;
    dmat KN = {0};
    if (dm_alloc(&KN, D, mm) || dm_alloc(&b->K, mm, mm)) {
        dm_free(&KN);
        return SM_NOMEM;
    }
    /* the bits of the plain loops (dm_ptap_ordered), as fast as column updates allow */
    if (dm_ptap_ordered(D, mm, K->a, b->N.a, KN.a, b->K.a) != SM_OK) {
        dm_free(&KN);
        return SM_NOMEM;
    }
    for (int i = 0; i < mm; i++) /* exact symmetry */
        for (int j = 0; j < i; j++) {
            double s = 0.5 * (DM(&b->K, i, j) + DM(&b->K, j, i));
            DM(&b->K, i, j) = DM(&b->K, j, i) = s;
        }
    dm_free(&KN);
    return SM_OK;
}

/* T_e = C(alpha) L_e N (eq. 18), d_e (eq. 24) and the bending block of G_e (eq. 23). */
static int modes_elements(const sm_model *m, sm_sub *b)
{
    int mm = b->m;
    if (dm_alloc(&b->T, 6 * b->nel, mm))
        return SM_NOMEM;
    b->d = dm_vec((size_t)b->nel * mm);
    b->gq = dm_vec((size_t)b->nel * 16);
    if (!b->d || !b->gq)
        return SM_NOMEM;
    for (int j = 0; j < b->nel; j++) {
        const sm_elem *e = &m->elems[b->elems[j]];
        double alpha = e->angle - b->theta0, co = cos(alpha), si = sin(alpha);
        int ends[2] = {e->n1, e->n2};
        for (int h = 0; h < 2; h++) {
            int r0 = modes_dof(m, b, ends[h], 0);
            if (r0 < 0)
                continue; /* the root: clamped in this basis */
            for (int c = 0; c < mm; c++) {
                double u = DM(&b->N, r0, c), v = DM(&b->N, r0 + 1, c);
                DM(&b->T, 6 * j + 3 * h + 0, c) = co * u + si * v;
                DM(&b->T, 6 * j + 3 * h + 1, c) = -si * u + co * v;
                DM(&b->T, 6 * j + 3 * h + 2, c) = DM(&b->N, r0 + 2, c);
            }
        }
        for (int c = 0; c < mm; c++)
            b->d[(size_t)j * mm + c] =
                e->EA / e->l * (DM(&b->T, 6 * j + 3, c) - DM(&b->T, 6 * j + 0, c));
        fe_geometric_bending(e->l, b->gq + 16 * j);
    }
    return SM_OK;
}

/*
 * The sparse path (lowmodes.h) for a frame that keeps nm << D modes.  Both mass models are
 * solved on the full (u, v, phi) Kbar: with lumped mass Mbar = diag(node masses) on the
 * translations and zero on the rotations, and Kbar^-1 Mbar returns vectors whose rotations are
 * the condensed ones (phi = X t of modes_lumped), so the Ritz problem in their span is that of
 * Kc phi = w^2 Mt phi.  The conventions of the dense paths follow: ascending w^2, every column
 * mass-normalised (x' Mbar x = 1), then the attachment columns as there.
 */

/* N(:, j) = X(:, j) / sqrt(x' Mbar x) for j < nm (X from lowmodes_solve); work: D doubles. */
static int modes_sparse_kept(sm_sub *b, const csym *M, int nm, const double *X, double *work)
{
    int D = b->N.rows;
    for (int j = 0; j < nm; j++) {
        const double *x = X + (size_t)D * j;
        double nrm = 0;
        csym_mul(M, 1, x, D, work, D);
        for (int r = 0; r < D; r++) /* x' M x */
            nrm += x[r] * work[r];
        if (!(nrm > 0))
            return SM_SINGULAR;
        for (int r = 0; r < D; r++)
            DM(&b->N, r, j) = x[r] / sqrt(nrm);
    }
    return SM_OK;
}

/* Lumped mass: the attachment columns of modes_lumped (t = 0, phi_a = 1, phi_c = -Kcc^-1 Kca)
 * from the sparse Kcc, the rotations of the nodes that carry no child frame. */
static int modes_attach_sparse(sm_sub *b, const csym *K, int nm)
{
    int F = b->nfree, na = b->n_attach, nc = 0, rc = SM_NOMEM;
    int *keep = malloc((size_t)F * sizeof(int)), *map = malloc((size_t)F * sizeof(int));
    csym Kcc = {0};
    csym_ldl Fc = {0};
    double *Y = NULL;
    if (!keep || !map)
        goto done;
    for (int i = 0; i < F; i++) {
        map[i] = modes_is_attach(b, i) ? -1 : nc;
        if (map[i] >= 0)
            keep[nc++] = 3 * i + 2;
    }
    if (!(Y = dm_vec((size_t)nc * na)))
        goto done;
    for (int a = 0; a < na; a++) { /* Y = -Kca: column phi_a of Kbar on the rotations kept */
        int col = 3 * b->attach[a] + 2;
        for (int q = K->p[col]; q < K->p[col + 1]; q++)
            if (K->i[q] % 3 == 2 && map[K->i[q] / 3] >= 0)
                Y[(size_t)nc * a + map[K->i[q] / 3]] = -K->x[q];
    }
    if (nc > 0) { /* Y = Kcc^-1 Y */
        if ((rc = csym_sub(K, nc, keep, &Kcc)) < 0 || (rc = csym_factor(&Kcc, &Fc)) < 0)
            goto done;
        if ((rc = csym_solve_refined(&Kcc, &Fc, na, Y, nc)) < 0)
            goto done;
    }
    for (int a = 0; a < na; a++)
        for (int i = 0; i < F; i++)
            DM(&b->N, 3 * i + 2, nm + a) = map[i] < 0 ? (i == b->attach[a] ? 1.0 : 0.0) : Y[(size_t)nc * a + map[i]];
    rc = SM_OK;
done:
    free(keep);
    free(map);
    free(Y);
    csym_free(&Kcc);
    csym_ldl_free(&Fc);
    return rc;
}

/* Consistent mass: the static unit-moment modes of modes_consistent with the sparse factor Fk,
 * M-orthogonalised (two passes of modified Gram-Schmidt) against the kept modes and the earlier
 * ones, M-normalised. */
static int modes_consistent_attach_sparse(sm_sub *b, const csym *K, const csym_ldl *Fk, const csym *M, int nm,
                                          int na)
{
    int D = b->N.rows, rc;
    double *MV = dm_vec((size_t)D * (nm + na)), *Z = b->N.a + (size_t)D * nm;
    if (!MV)
        return SM_NOMEM;
    for (int a = 0; a < na; a++)
        Z[(size_t)D * a + 3 * b->attach[a] + 2] = 1.0;
    if ((rc = csym_solve_refined(K, Fk, na, Z, D)) < 0) /* Z = Kbar^-1 E */
        goto done;
    csym_mul(M, nm, b->N.a, D, MV, D); /* MV = M N: v_j' M x = (M v_j)' x */
    for (int a = nm; a < nm + na; a++) {
        double *x = b->N.a + (size_t)D * a, *mx = MV + (size_t)D * a, nrm = 0;
        for (int pass = 0; pass < 2; pass++)
            for (int j = 0; j < a; j++) {
                double s = 0;
                for (int r = 0; r < D; r++) /* s = v_j' M x */
                    s += MV[(size_t)D * j + r] * x[r];
                for (int r = 0; r < D; r++) /* x -= s v_j */
                    x[r] -= s * b->N.a[(size_t)D * j + r];
            }
        csym_mul(M, 1, x, D, mx, D);
        for (int r = 0; r < D; r++) /* x' M x */
            nrm += x[r] * mx[r];
        rc = SM_SINGULAR;
        if (!(nrm > 1e-24))
            goto done;
        for (int r = 0; r < D; r++) {
            x[r] /= sqrt(nrm);
            mx[r] /= sqrt(nrm);
        }
    }
    rc = SM_OK;
done:
    free(MV);
    return rc;
}

int modes_frame_csym(const sm_model *m, const sm_sub *b, csym *K, csym *M)
{
    int rc = lowmodes_frame_pattern(m, b, 3, K);
    if (rc == SM_OK)
        rc = lowmodes_frame_pattern(m, b, 3, M);
    if (rc < 0)
        return rc;
    csym_sink ks = {NULL, K}, ms = {NULL, M};
    int consistent = m->opt.mass == SM_MASS_CONSISTENT;
    modes_assemble(m, b, &ks, consistent ? &ms : NULL);
    for (int i = 0; !consistent && i < b->nfree; i++) {
        double mass = m->nodes[b->free_nodes[i]].mass;
        csym_add(M, 3 * i, 3 * i, mass);
        csym_add(M, 3 * i + 1, 3 * i + 1, mass);
    }
    return SM_OK;
}

/* modes_sub on the sparse path; *fallback = 1 (nothing allocated in b) sends it to the dense one. */
static int modes_sub_sparse(const sm_model *m, sm_sub *b, int *fallback)
{
    int D = 3 * b->nfree, nm, na, rc;
    modes_count(&m->opt, b, &nm, &na);
    csym K = {0}, M = {0};
    csym_ldl Fk = {0};
    int p = lowmodes_block(D, nm);
    double *X = dm_vec((size_t)D * p), *mu = dm_vec((size_t)p), *work = dm_vec((size_t)D);
    if (!X || !mu || !work) {
        rc = SM_NOMEM;
        goto done;
    }
    if ((rc = modes_frame_csym(m, b, &K, &M)) < 0 || (rc = csym_factor(&K, &Fk)) < 0)
        goto done;
    if ((rc = lowmodes_solve(&K, &Fk, &M, nm, X, mu, fallback)) < 0 || *fallback)
        goto done;
    b->m = nm + na;
    if ((rc = dm_alloc(&b->N, D, b->m)) < 0 || (rc = modes_sparse_kept(b, &M, nm, X, work)) < 0)
        goto done;
    if (na > 0)
        rc = m->opt.mass == SM_MASS_CONSISTENT ? modes_consistent_attach_sparse(b, &K, &Fk, &M, nm, na)
                                               : modes_attach_sparse(b, &K, nm);
    if (rc == SM_OK)
        rc = lowmodes_project(&K, &b->N, &b->K);
    if (rc == SM_OK)
        rc = modes_elements(m, b);
done:
    csym_free(&K);
    csym_free(&M);
    csym_ldl_free(&Fk);
    free(X);
    free(mu);
    free(work);
    return rc;
}

/* Basis, K_s, T_e and d_e of planar substructure b: sparse for a large frame keeping few modes
 * (lowmodes_use), else dense and complete. */
int modes_planar_sub(const sm_model *m, sm_sub *b)
{
    int D = 3 * b->nfree, nm, na, fallback = 0;
    modes_count(&m->opt, b, &nm, &na);
    if (lowmodes_use(&m->opt, D, nm)) {
        int rc = modes_sub_sparse(m, b, &fallback);
        if (rc < 0 || !fallback)
            return rc;
    }
    dmat K = {0}, M = {0};
    int rc = dm_alloc(&K, D, D);
    if (rc == SM_OK && m->opt.mass == SM_MASS_CONSISTENT)
        rc = dm_alloc(&M, D, D);
    if (rc == SM_OK) {
        csym_sink ks = {&K, NULL}, ms = {&M, NULL};
        modes_assemble(m, b, &ks, M.a ? &ms : NULL);
        rc = m->opt.mass == SM_MASS_CONSISTENT ? modes_consistent(m, b, &K, &M) : modes_lumped(m, b, &K);
    }
    if (rc == SM_OK)
        rc = modes_reduced_stiffness(b, &K);
    if (rc == SM_OK)
        rc = modes_elements(m, b);
    dm_free(&K);
    dm_free(&M);
    return rc;
}
