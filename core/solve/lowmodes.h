/*
 * lowmodes.h — the few lowest component modes of a large substructure without
 * dense matrices (issue 10), for modes.c and modes3.c (not installed):
 *   csym.c      symmetric sparse matrices of one frame (pattern from its
 *               elements, assembly, products, principal submatrices) and their
 *               LDL' factorisation in reverse Cuthill-McKee order (fill-free
 *               on the trees of 2-node beams a frame is made of)
 *   lowmodes.c  when to use them (lowmodes_use), subspace iteration on that
 *               factor for Mbar x = mu Kbar x, and the Rayleigh-Ritz step the
 *               dense and sparse paths share
 * A frame of D DOF keeping nm << D modes then costs O(D nm^2) time and
 * O(D nm) memory instead of O(D^3) and O(D^2).  The dense complete path stays
 * for small frames, complete bases and sm_options.solver == SM_SOLVER_DENSE
 * (the switch that forces it: "dense everywhere", for tests and benchmarks).
 *
 * Conventions as in internal.h: 0-based, column-major, int returns are
 * sm_status, pointers borrowed unless said otherwise, no global state.
 */
#ifndef SM_LOWMODES_H
#define SM_LOWMODES_H

#include "internal.h"

/* A symmetric sparse matrix, both triangles stored, compressed by columns. */
typedef struct csym {
    int n;              /* order */
    int *p;             /* n+1 column pointers into i, x */
    int *i;             /* p[n] row indices, ascending within each column */
    double *x;          /* p[n] values */
} csym;

/* P A P' = L D L' (L unit lower triangular, D diagonal) of a positive definite csym A. */
typedef struct csym_ldl {
    int n;              /* order */
    int *perm;          /* n: perm[k] = row of A that is pivot k */
    int *lp;            /* n+1 column pointers of the strictly lower part of L */
    int *li;            /* lp[n] row indices (pivot order, ascending) */
    double *lx;         /* lp[n] values */
    double *d;          /* n pivots, all > 0 */
} csym_ldl;

/* Where an assembly loop adds element entries: a dense matrix or a csym with the pattern. */
typedef struct csym_sink {
    dmat *dense;        /* used when not NULL */
    csym *sparse;       /* used otherwise */
} csym_sink;

/* ------------------------------------------------------------- csym.c */
/**
 * The pattern of the matrices of a frame: nn free nodes of bs DOF each (DOF
 * bs*a + c of node a), ne 2-node elements whose local node indices are ends[2e],
 * ends[2e+1] (-1 for the clamped root: no DOF).  Every DOF pair of a node and
 * of two nodes sharing an element is an entry; values zero.  A is owned by the
 * caller (csym_free, also after a failure).  SM_OK or SM_NOMEM.  O(nn bs^2).
 */
int csym_pattern(csym *A, int nn, int bs, int ne, const int *ends);
/** A(r, c) += v; (r, c) must be in the pattern (else ignored).  O(log column length). */
void csym_add(csym *A, int r, int c, double v);
/** The entry A(r, c), 0 outside the pattern. */
double csym_get(const csym *A, int r, int c);
/** B = A(keep, keep), keep: nk ascending indices; B owned by the caller.  SM_OK or SM_NOMEM. */
int csym_sub(const csym *A, int nk, const int *keep, csym *B);
/** Y = A X for k columns (leading dimensions ldx, ldy; X and Y distinct).  O(nnz k). */
void csym_mul(const csym *A, int k, const double *X, int ldx, double *Y, int ldy);
/** Y = A X like csym_mul, each entry an accurate dot product (as in twice the precision, then
 *  rounded): for products with Kbar, whose rows cancel on smooth vectors.  O(nnz k). */
void csym_mul_acc(const csym *A, int k, const double *X, int ldx, double *Y, int ldy);
/** Free the arrays of A and zero it; safe on a zeroed csym. */
void csym_free(csym *A);
/**
 * F = the LDL' factorisation of A in reverse Cuthill-McKee order.  SM_OK,
 * SM_NOMEM or SM_SINGULAR (a pivot <= 0: A is not positive definite); F owned
 * by the caller (csym_ldl_free, also after a failure).
 */
int csym_factor(const csym *A, csym_ldl *F);
/** B = A^-1 B for k columns (leading dimension ldb) with the factor F; work: n doubles. */
void csym_solve(const csym_ldl *F, int k, double *B, int ldb, double *work);
/** B = A^-1 B (k columns, leading dimension ldb) with the factor F of A and one step of
 *  iterative refinement (residual by csym_mul_acc).  SM_OK or SM_NOMEM. */
int csym_solve_refined(const csym *A, const csym_ldl *F, int k, double *B, int ldb);
/** Free the arrays of F and zero it; safe on a zeroed one. */
void csym_ldl_free(csym_ldl *F);

/** T(r, c) += v into whichever matrix t holds (the dense one exactly as DM(...) += v). */
static inline void csym_sink_add(const csym_sink *t, int r, int c, double v)
{
    if (t->dense)
        DM(t->dense, r, c) += v;
    else
        csym_add(t->sparse, r, c, v);
}

/* ------------------------------------------------------ modes.c, modes3.c */
/**
 * *K, *M = Kbar and Mbar of substructure b of a planar (modes_frame_csym:
 * lumped mass = the node masses on u, v) or spatial (modes3_frame_csym) model
 * in their sparse pattern, entry for entry the matrices of the dense path.
 * SM_OK or SM_NOMEM; K, M owned by the caller (csym_free, also after a failure).
 */
int modes_frame_csym(const sm_model *m, const sm_sub *b, csym *K, csym *M);
int modes3_frame_csym(const sm_model *m, const sm_sub *b, csym *K, csym *M);

/* --------------------------------------------------------- lowmodes.c */
/**
 * *A = the empty pattern (csym_pattern) of the matrices of substructure b of m
 * with bs DOF per free node (3 planar, 6 spatial), in the free-node order of
 * b.  SM_OK or SM_NOMEM; A owned by the caller (csym_free).
 */
int lowmodes_frame_pattern(const sm_model *m, const sm_sub *b, int bs, csym *A);
/**
 * 1 when a frame of D DOF keeping nm eigenmodes (modes_count, modes3_count)
 * takes them from lowmodes_solve: D >= LOWMODES_MIN_DOFS, 8 nm <= D and
 * o->solver != SM_SOLVER_DENSE.  O(1).
 */
int lowmodes_use(const sm_options *o, int D, int nm);
/**
 * The columns of X (D x p, p = lowmodes_block(D, nm)) = the lowest modes of
 * Mbar x = mu Kbar x (M positive semi-definite, K positive definite with its
 * factor F), K-orthonormal in descending mu (mu: p), by subspace iteration
 * until the nm first have converged (residual of Kbar^-1 Mbar below 1e-12 of
 * their mu, or at the rounding noise: lowmodes.c), then lowmodes_ritz.
 * *fallback = 1 (and X unspecified, SM_OK returned) when it does not converge
 * in 100 iterations or the projected problem is singular: use the dense path.
 * SM_OK, SM_NOMEM or SM_LAPACK_FAILED.  O(D nm^2) time, O(D nm) memory.
 */
int lowmodes_solve(const csym *K, const csym_ldl *F, const csym *M, int nm, double *X, double *mu,
                   int *fallback);
/** The block size lowmodes_solve works with for nm modes of D DOF: min(D, max(2 nm, nm + 8)). */
int lowmodes_block(int D, int nm);
/**
 * Rayleigh-Ritz in the span of the k columns of X (D x k, overwritten):
 * M y = mu K y there, columns returned K-orthonormal in descending mu (w: k),
 * like modes3.c's dense modes3_ritz.  SM_OK, SM_NOMEM, SM_SINGULAR (X'KX
 * not positive definite) or SM_LAPACK_FAILED.
 */
int lowmodes_ritz(const csym *K, const csym *M, int k, double *X, double *w);
/**
 * The reduced step of both Rayleigh-Ritz forms: from Kr = X'KX and Mr = X'MX
 * (k x k, destroyed), X (D x k) := X Z with Mr Z = Kr Z diag(mu), Z'Kr Z = I,
 * columns in descending mu (w: k).  Y: D x k scratch.  SM_OK, SM_SINGULAR or
 * SM_LAPACK_FAILED.
 */
int lowmodes_reduced(int D, int k, double *X, double *Kr, double *Mr, double *w, double *Y);
/** Ks = N' K N (m x m, allocated into *Ks, exactly symmetric; eq. 11).  SM_OK or SM_NOMEM. */
int lowmodes_project(const csym *K, const dmat *N, dmat *Ks);

#endif
