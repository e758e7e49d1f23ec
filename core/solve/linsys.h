/*
 * linsys.h — the linearised system of a model at a state q, on one of two paths (not
 * installed; issue 24, DESIGN.md 2).
 *
 * The dense path assembles n x n matrices (Newton tangent, or K*, M*, C*) and factors them
 * with LAPACK; the tree path keeps local blocks per frame and factors them along the frame
 * tree in O(n) memory (tree.c).  Which path a model takes is decided once (tree_use, or the
 * dense fallback of an eigen-analysis); which kind of structure it is, by m->kind
 * (kind.h).  The continuation (equilibrium.c) and the sweep (sweep.c) see neither choice:
 * they call the functions below.
 *
 * An smi_lin is allocated for one use: SMI_USE_NEWTON (tangent, factor, solve, sign of the
 * determinant) or SMI_USE_MODES (K*, M*, C*, eigen-analysis, nodal shapes and steady-state
 * outputs).  Statuses are sm_status values.
 */
#ifndef SM_LINSYS_H
#define SM_LINSYS_H

#include "kind.h"

typedef struct smi_lin smi_lin;

/** A linear system of m for use (SMI_USE_NEWTON or SMI_USE_MODES) on the tree path (tree 1) or
 *  the dense one (tree 0) into *out.  SM_OK or SM_NOMEM (*out NULL). */
int smi_lin_new(const sm_model *m, int use, int tree, smi_lin **out);
/** Free L; NULL is fine. */
void smi_lin_free(smi_lin *L);
/** 1 when L is on the tree path. */
int smi_lin_is_tree(const smi_lin *L);

/** g (n): Omega^2 g is the centrifugal force at q; leaves the kinematics of q in L. */
void smi_lin_centrifugal(const sm_model *m, const double *q, smi_lin *L, double *g);
/** The Newton tangent at q and s = Omega^2 (kinematics from the last smi_lin_centrifugal at q on
 *  the planar kind), factored.  SM_OK, SM_SINGULAR (an exactly zero pivot or singular front: no
 *  usable factors), SM_NOMEM or SM_LAPACK_FAILED. */
int smi_lin_tangent(const sm_model *m, const double *q, double s, smi_lin *L);
/** x = Kt^-1 x (n) with the factors of smi_lin_tangent.  SM_OK or SM_LAPACK_FAILED. */
int smi_lin_solve(const sm_model *m, smi_lin *L, double *x);
/** Sign of det Kt from the factors: a change between two steady states brackets a critical point. */
int smi_lin_det_sign(const sm_model *m, const smi_lin *L);

/** Kinematics at q (positions, rotations; Jacobians on the dense path). */
void smi_lin_eval(const sm_model *m, const double *q, smi_lin *L);
/** nodes (node_dof n_nodes) = steady-state positions and rotations at the kinematics in L;
 *  returns the largest rotation of a node relative to its frame (its node in *at, -1: none). */
double smi_lin_nodes(const sm_model *m, smi_lin *L, double *nodes, int *at);
/** K* (P frozen, symmetric), M* and with m->opt.coriolis C* at q and omega.  Returns 1 when the
 *  tree blocks are finite (always 1 on the dense path: see smi_lin_finite). */
int smi_lin_linearize(const sm_model *m, const double *q, double omega, smi_lin *L);
/** 1 when the dense K*, M*, C* have only finite entries. */
int smi_lin_finite(const smi_lin *L);
/** The eigen-analysis of the last smi_lin_linearize into *e (eig_solve / eig_solve_tree):
 *  *fallback 1 when the tree path cannot give the modes and the dense one must (then e is empty
 *  and SM_OK returned); pr (may be NULL): the tree path's stop callback. */
int smi_lin_eigen(const sm_model *m, smi_lin *L, const sm_progress *pr, sm_eig_out *e,
                  int *fallback);
/** Whether the next smi_lin_eigen on L may start from the modes of the last one on L (chain 1:
 *  a sweep's consecutive speeds, sweep_pool.h's SWEEP_WARM_CHUNK) or starts cold (chain 0).  Only a
 *  spatial model's tree path uses it (eig_solve_tree); each smi_lin_eigen reads it once. */
void smi_lin_warm(smi_lin *L, int chain);
/** Negative eigenvalues of K* found by the tree path's factorisation (0 on the dense path). */
int smi_lin_negative(const smi_lin *L);
/** yr, yi (node_dof n_nodes each) = nodal motion of the modal vector xr + i xi at the last
 *  linearisation. */
void smi_lin_nodal(const sm_model *m, smi_lin *L, const double *xr, const double *xi, double *yr,
                   double *yi);
/** *lambda = the lowest eigenvalue of the dense K* of the last smi_lin_linearize (destroys it).
 *  SM_OK, SM_NOMEM or SM_LAPACK_FAILED. */
int smi_lin_lowest(const sm_model *m, smi_lin *L, double *lambda);

#endif
