/*
 * csym.h — symmetric sparse matrices of one frame (not installed; base layer: no model):
 * the pattern from its elements, assembly, products, principal submatrices, and the LDL'
 * factorisation in reverse Cuthill-McKee order (fill-free on the trees of 2-node beams a
 * frame is made of).  Used by the kinds' sparse bases (solve/lowmodes.h).
 *
 * Conventions as in dense.h: 0-based, column-major, int returns are sm_status, pointers
 * borrowed unless said otherwise, no global state.
 */
#ifndef SM_CSYM_H
#define SM_CSYM_H

#include "dense.h"

/* A symmetric sparse matrix, both triangles stored, compressed by columns. */
typedef struct csym {
    int n;     /* order */
    int *p;    /* n+1 column pointers into i, x */
    int *i;    /* p[n] row indices, ascending within each column */
    double *x; /* p[n] values */
} csym;

/* P A P' = L D L' (L unit lower triangular, D diagonal) of a positive definite csym A. */
typedef struct csym_ldl {
    int n;      /* order */
    int *perm;  /* n: perm[k] = row of A that is pivot k */
    int *lp;    /* n+1 column pointers of the strictly lower part of L */
    int *li;    /* lp[n] row indices (pivot order, ascending) */
    double *lx; /* lp[n] values */
    double *d;  /* n pivots, all > 0 */
} csym_ldl;

/* Where an assembly loop adds element entries: a dense matrix or a csym with the pattern. */
typedef struct csym_sink {
    dmat *dense;  /* used when not NULL */
    csym *sparse; /* used otherwise */
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

#endif
