/*
 * dense.h — a tiny column-major dense matrix used inside the core, and the
 * few helpers the numerics need.  LAPACK/BLAS are called on these directly
 * (leading dimension = rows).
 */
#ifndef SM_DENSE_H
#define SM_DENSE_H

#include <stddef.h>

typedef struct dmat {
    int rows;       /* number of rows (= leading dimension) */
    int cols;       /* number of columns */
    double *a;      /* rows*cols values, column-major; owned */
} dmat;

#define DM(M, i, j) ((M)->a[(size_t)(j) * (size_t)(M)->rows + (size_t)(i)])

/** Allocate a zeroed rows x cols matrix; returns SM_OK or SM_NOMEM. */
int dm_alloc(dmat *m, int rows, int cols);
/** Free the storage; safe on a zeroed struct. */
void dm_free(dmat *m);
/** Set all entries to zero. */
void dm_zero(dmat *m);
/** calloc wrapper for n doubles (NULL on failure or n == 0 gives a 1-element block). */
double *dm_vec(size_t n);
/** Euclidean norm of x[0..n). */
double dm_norm(const double *x, int n);
/** 1 when every entry of m is finite (no NaN, no infinity), else 0. */
int dm_finite(const dmat *m);
/**
 * The sm_status of a LAPACKE call's info: 0 -> SM_OK; LAPACK_WORK_MEMORY_ERROR
 * (a high-level LAPACKE wrapper could not allocate its workspace) -> SM_NOMEM;
 * any other negative value (an illegal argument, or a NaN found by LAPACKE's
 * input check) -> SM_LAPACK_FAILED; a positive value -> on_positive, whose
 * meaning depends on the routine (SM_SINGULAR for a factorisation that meets
 * a zero pivot or a matrix that is not positive definite, SM_LAPACK_FAILED
 * for an iteration that did not converge).
 */
int dm_lapack_status(int info, int on_positive);

/** Negative eigenvalues of a symmetric n x n matrix from its Bunch-Kaufman factors (LAPACK dsytrf,
 *  lower, column-major A with its ipiv): Sylvester's law of inertia; a 2x2 pivot block counts by
 *  its determinant.  The one inertia count of the core (eigen.c, tree.c). */
int dm_sytrf_negative(int n, const double *A, const int *ipiv);

/**
 * The il-th to iu-th smallest eigenvalues (1 <= il <= iu <= n) of the symmetric n x n matrix A
 * (lower triangle, column-major, leading dimension n; overwritten) in w[0..iu-il], ascending, and
 * their orthonormal vectors in the columns of Z (ld ldz).  dsyevr_bits = 1: LAPACKE_dsyevr('V',
 * 'I', 'L') itself (the bits of a kind with fixed_bits, the planar one).  dsyevr_bits = 0: the
 * same reduction T = Q' A Q, but where dsyevr finds a subset of T's eigenvalues by bisection
 * (dstebz: chains of dependent divisions, ~65 % of the time of a 50-150 sized problem, issue 27),
 * dsterf finds all of them by root-free QL/QR, block by unreduced block (dstebz's split test), and
 * dstein computes the vectors as dsyevr's subset route does: the same accuracy (eigenvalues within
 * O(eps |A|), vectors by the same inverse iteration), other last bits, ~45 % less time.  Returns a
 * LAPACK info: 0; negative for an argument, or LAPACK_WORK_MEMORY_ERROR; positive when an
 * iteration did not converge or dsyevr found fewer eigenvalues than asked (SM_LAPACK_FAILED
 * through dm_lapack_status).
 */
int dm_syev_range(int dsyevr_bits, int n, double *A, int il, int iu, double *w, double *Z, int ldz);

/**
 * The lowest eigenvalue of the symmetric n x n matrix A (lower triangle, leading dimension n;
 * overwritten) in *lambda, without vectors: LAPACK's dsyevx, with the bits LAPACKE_dsyevx gives.
 * Returns a LAPACK info as dm_syev_range does (negative for NaN in A, as LAPACKE's check).
 */
int dm_sy_lowest(int n, double *A, double *lambda);

/**
 * C (m x m, leading dimension m) = N' K N, K (n x n) and N (n x m) column-major, each entry with
 * the bits of the plain loops: (K N)(i, j) summed over p = 0..n-1 in order from 0, then
 * C(i, j) = sum over p in order of N(p, i) (K N)(p, j) — no BLAS, whose blocking reorders sums
 * (the planar kind's results are fixed to the byte, issue 27).  Written as column updates
 * (axpy) instead of dot products, so that the independent entries of a column are summed side by
 * side in vector registers while each one keeps its order.  K N in KN (n x m, caller's);
 * allocates an m x n transpose of N.  Returns SM_OK or SM_NOMEM.
 */
int dm_ptap_ordered(int n, int m, const double *K, const double *N, double *KN, double *C);

#endif
