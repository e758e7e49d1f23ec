/*
 * lowmodes.h — the few lowest component modes of a large substructure without
 * dense matrices (issue 10), for the kinds' bases (not installed); the sparse
 * matrices themselves are base/csym.h:
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

#include "csym.h"
#include "internal.h"

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
