/*
 * spatial.h — the spatial (3D) path of the core, DESIGN.md 7 (not installed).
 *
 * A spatial model keeps the topology of the planar one (mesh.c: nodes,
 * elements, substructures, attachments) and adds, per node, 6 DOF (u, v, w
 * and the small rotation psi, frame coordinates) and rotary inertia.  The
 * modules:
 *   rot3.c    (base/rot3.h) 3x3 rotations: Rodrigues exp, its left tangent, log (complex, so
 *             that every kinematic quantity is analytic in q)
 *   fe3.c     space-frame element matrices (stiffness, consistent mass, geometric)
 *   mesh3.c   checks of the spatial input, element axes, nodal rotary inertia,
 *             frame orientations
 *   modes3.c  complete component-mode bases (+ static attachment modes under
 *             modes_per_frame), element maps T_e, d_e, the points
 *   frames3.c poses along the frame tree, J and W, the centrifugal force g and
 *             its Jacobian H (hessian3.c, in closed form)
 *   lin3.c    F(q), the Newton tangent, M*, C*, K*, nodal outputs
 * The Newton continuation (equilibrium.c), the eigen-analysis (eigen.c) and
 * the sweep (sweep.c) are shared with the planar path.
 *
 * Conventions: hub frame, e_z the spin axis; 3x3 matrices column-major
 * (a[i + 3 j]); a frame s has origin R_s and orientation A_s (columns = frame
 * axes in the hub frame); point p of s: r_p = R_s + A_s w_p, w_p = ub_p + N^u_p q_s,
 * psi_p = N^psi_p q_s, orientation A_s Lambda(psi_p); a child c at node e of
 * s: R_c = r_e, A_c = A_s Lambda(psi_e) Arel_c (DESIGN.md 7.2).
 */
#ifndef SM_SPATIAL_H
#define SM_SPATIAL_H

#include "internal.h"

#include "rot3.h"

/* A point that a frame carries: an FE node (shapes, lumped mass) or a quadrature point. */
typedef struct sp_point {
    int sub;            /* substructure whose frame carries it; -1 for the clamp node (fixed) */
    int node;           /* FE node, or -1 for a quadrature point */
    double ub[3];       /* undeformed position in the frame, m (hub position for the clamp) */
    double mass;        /* kg (0: carries no mass) */
    double I[9];        /* rotary inertia at rest in frame axes, kg m^2 */
    int has_I;          /* 1 when I is not all zero */
    double Ic[9];       /* rotary inertia in the centrifugal potential (the propeller moment
                           1/2 Omega^2 e_z' A Ic A' e_z), frame axes at rest: = I, except at the
                           Gauss points of consistent mass, whose I is torsion only (no bending
                           rotary inertia in M*, C*) while Ic is the whole section tensor:
                           without it torsion lost its centrifugal stiffening */
    int has_Ic;         /* 1 when Ic is not all zero */
    double c[3];        /* offset of the mass from the node it moves with, frame axes at rest, m:
                           it is at w + Lambda(psi) c (a section centre of mass or a point-mass
                           offset, DESIGN.md 8) */
    int has_c;          /* 1 when c is not zero */
    const double *N;    /* 6 x m_s rows (u, v, w, psi_x, psi_y, psi_z), column stride ldn */
    int ldn;
} sp_point;

/* -------------------------------------------------------------- fe3.c */
/* Element DOF order: u1 v1 w1 tx1 ty1 tz1 u2 v2 w2 tx2 ty2 tz2 in the element's principal axes
 * (e1, p2, p3); 12x12 column-major. */

/** k = space-frame stiffness: EA/l, GJ/l, bending in p2 (EI_edge, with tz) and in p3 (EI_flap,
 *  with ty; w' = -ty). */
void fe3_stiffness(const sm_elem *e, double k[144]);
/** g = geometric stiffness per unit axial force: the planar bending block of eq. 23 on (v, tz)
 *  and on (w, -ty), and the Wagner term (I_p/A)/l [1 -1; -1 1] on tx (DESIGN.md 7.3). */
void fe3_geometric(const sm_elem *e, double g[144]);

/* ------------------------------------------------------------ mesh3.c */
/** Spatial checks of st (sections, twist, flap direction, z, point-mass inertia, options),
 *  as mesh_check does for the planar data; the same diag conventions. */
int mesh3_check(const sm_structure *st, const sm_options *o, sm_diag *d);
/** Element axes and sections, nodal rotary inertia (after mesh_nodes).  Returns SM_OK or
 *  SM_INVALID_INPUT (a member without a usable flapwise direction: diag names it). */
int mesh3_elements(sm_model *m, const sm_structure *st, sm_diag *d);
/** Frame orientations A0, Arel and the undeformed local positions ubar (3 per free node),
 *  after mesh_subs. */
void mesh3_subs(sm_model *m);

/* ----------------------------------------------------------- modes3.c */
/** modes_count for a spatial substructure (complete basis: 6 F; truncated: + 6 per attachment). */
int modes3_count(const sm_options *o, const sm_sub *b, int *nm, int *na);
/** Basis, K_s, T_e and d_e of spatial substructure b (modes_build calls it per substructure).
 *  Returns SM_OK, SM_NOMEM, SM_SINGULAR or SM_LAPACK_FAILED. */
int modes3_sub(const sm_model *m, sm_sub *b);
/** *K, *M = Kbar and Mbar of spatial substructure b in their sparse pattern, entry for entry the
 *  matrices of the dense path.  SM_OK or SM_NOMEM; K, M owned by the caller (csym_free). */
int modes3_frame_csym(const sm_model *m, const sm_sub *b, csym *K, csym *M);
/** The points m->pt of a spatial model, after every modes3_sub.  SM_OK or SM_NOMEM. */
int modes3_points(sm_model *m);

/* ---------------------------------------------------------- frames3.c */
/* Kinematic state of a spatial model at q. */
typedef struct sp_kin {
    int n, S, P;        /* coordinates, substructures, points */
    double *R, *A;      /* 3 S frame origins, 9 S orientations */
    double *r, *psi;    /* 3 P point positions (hub), 3 P small rotations (frame axes) */
    double *AT;         /* 9 P: A_s T(psi_p), the map from d psi_p to the hub rotation */
    double *dh;         /* 3 P: A_s Lambda(psi_p) c_p, the hub offset of an offset mass (0 else) */
    dmat JRT;           /* n x 6S: columns 6s+i = (d R_s,i / dq)', 6s+3+i = (d theta_s,i / dq)' */
    dmat JW;            /* n x 6P: columns 6p+i = (d r_p,i / dq)', 6p+3+i = (d theta_p,i / dq)'
                           (theta: the hub-frame rotation) */
    int jac;            /* 1 when JRT and JW are allocated */
    int *pt_ptr, *pt_idx; /* points of frame s: pt_idx[pt_ptr[s] .. pt_ptr[s+1]) */
    int *ch_ptr, *ch_idx; /* child frames of s, likewise */
    /* complex scratch of the centrifugal recursion */
    sp_cx *cq, *cR, *cA, *cF, *cg; /* n, 3S, 9S, 6S (subtree wrench), n */
    /* base state of the Jacobian (sp_centrifugal_jacobian, sp_hessian_base: hessian3.c) */
    sp_cx *lw, *lpsi, *lL, *lT; /* 3P, 3P, 9P, 9P: w, psi, Lambda(psi), T(psi) of every point */
    sp_cx *bR, *bA;     /* 3S, 9S: the poses at the base point */
    int *mark;          /* S: 1 for the frames of the subtree being stepped */
    sp_cx *bF;          /* 6S: subtree wrenches at the base point */
    double *bq;         /* n: with bvalid, the real q at which bR, bA, bF are the poses and the
                           subtree wrenches (sp_centrifugal or a Jacobian's base left them) */
    int bvalid;
    double *Psi;        /* 36S: d wrench_c / d pose_c under a rigid motion of c's subtree (6x6 each) */
    double *pb;         /* 12P: F, Mo, dh = A Lambda c, y = X e_z of each point at the base, real */
    double *Gown;       /* n x 6: d g_c / d pose_c, rows of c, under that rigid motion */
    double *v;          /* 6S: pose change of each frame below a stepped coordinate */
    int cached;         /* 1 while lw.. hold the base state */
} sp_kin;

/** Allocate k for m; jac: also the dense Jacobians JRT, JW (O(n (S + P))).  SM_OK or SM_NOMEM. */
int sp_kin_alloc(const sm_model *m, sp_kin *k, int jac);
/** Free and zero k; safe on a zeroed one. */
void sp_kin_free(sp_kin *k);
/* frames3.c's pieces that hessian3.c differentiates (and the tests step: not for other files). */
/** w, psi (and with want_L Lambda(psi), T(psi)) of point pi at complex q. */
void sp_point_state(const sm_model *m, sp_kin *k, int pi, const sp_cx *q, int want_L, sp_cx w[3],
                    sp_cx psi[3], sp_cx L[9], sp_cx T[9]);
/** Force F and moment Mo (hub frame, added to what they hold) of the centrifugal potential (or of
 *  the weight, grav non-NULL) on point p at its local state (w, L) in a frame at (R, A), aw = A w. */
void sp_point_wrench(const sp_point *p, const sp_cx R[3], const sp_cx A[9], const sp_cx aw[3],
                     const sp_cx L[9], const double *grav, sp_cx F[3], sp_cx Mo[3]);
/** The pose (R, A) of frame s from its parent's at complex q. */
void sp_pose(const sm_model *m, sp_kin *k, int s, const sp_cx *q);
/** The subtree wrench of frame s (points of s and the wrenches of its children). */
void sp_frame_wrench(const sm_model *m, sp_kin *k, int s, const sp_cx *q);
/** The contribution of point p of frame b (pose A, T, offset aw; force F, moment Mo) to gs and
 *  to the frame's wrench Fs, Ms. */
void sp_apply(const sm_sub *b, const sp_point *p, const sp_cx A[9], const sp_cx T[9], const sp_cx aw[3],
              const sp_cx F[3], const sp_cx Mo[3], sp_cx *gs, sp_cx *Fs, sp_cx *Ms);
/** g at the complex q of k (k->cq), into k->cg: poses, then wrenches leaves first. */
void sp_centrifugal_c(const sm_model *m, sp_kin *k);

/** Poses and points at q (real); with k->jac also JRT and JW. */
void sp_eval(const sm_model *m, const double *q, sp_kin *k);
/** g (n) = d T0~/dq, T0~ = sum_p 1/2 m_p |P r_p|^2 + 1/2 e_z' A_p I_p A_p' e_z (DESIGN.md 7.3):
 *  the centrifugal force is Omega^2 g.  Uses the complex scratch of k. */
void sp_centrifugal(const sm_model *m, const double *q, sp_kin *k, double *g);
/** H (n x n) = dg/dq at q, column by column in closed form (hessian3.c): a coordinate of frame s
 *  moves the points of s (their rows), below s the subtrees move rigidly (their 6-column
 *  responses are computed once per Jacobian, leaves first), the rows above s are H's symmetry. */
void sp_centrifugal_jacobian(const sm_model *m, const double *q, sp_kin *k, dmat *H);

/** The base of the block Hessian (tree3.c): local state, poses, subtree wrenches, each point's
 *  force and moment (k->pb) and the rigid-motion responses Gown (rows of each frame, n x 6) and
 *  Psi at q; k->cached until sp_hessian_end. */
void sp_hessian_base(const sm_model *m, const double *q, sp_kin *k);
/** col (m_s) = rows of frame s of H e_j for coordinate j of frame s (after sp_hessian_base): the
 *  points of s move, its children take the pose change, their subtrees move rigidly (Psi). */
void sp_hessian_own(const sm_model *m, sp_kin *k, int s, int j, double *col);
/** End of the block Hessian: k->cached 0, so that sp_point_state evaluates again. */
void sp_hessian_end(const sm_model *m, sp_kin *k);

/* ------------------------------------------------------------- lin3.c */
/** f += f_g(q) = sum_e P_e T_e' G_e T_e q_s (the 3D G of fe3_geometric). */
void lin3_geometric_force(const sm_model *m, const double *q, double *f);
/** Kt += d f_g / dq; frozen: P_e held at P_e(q). work: >= 13 max m_s doubles. */
void lin3_geometric_tangent(const sm_model *m, const double *q, int frozen, dmat *Kt, double *work);
/** Kt (m_s x m_s block of frame s, leading dimension ld) += d f_g,s / dq_s, as lin3_geometric_tangent. */
void lin3_geometric_tangent_sub(const sm_model *m, int s, const double *q, int frozen, double *Kt, int ld,
                                double *work);
/** X = A_s Lambda(psi_p) I_p Lambda' A_s': the hub inertia of point pi at k. */
void lin3_hub_inertia(const sm_model *m, const sp_kin *k, int pi, double X[9]);
/** Yp = -skew(X e_z) + X S + S X: the rotary gyroscopic matrix of a hub inertia X (lin3_gyro). */
void lin3_gyro_rotary(const double X[9], double Yp[9]);
/** M = M* = sum_p m_p J_p' J_p + W_p' X_p W_p at k (jac), X_p the hub inertia. Y: n x 6P scratch. */
void lin3_mass(const sm_model *m, const sp_kin *k, dmat *M, dmat *Y);
/** C = C* = Omega sum_p (2 m_p J_p' S J_p + W_p' Y_p W_p), S = skew(e_z),
 *  Y_p = -skew(X_p e_z) + X_p S + S X_p (skew).  Y: n x 6P scratch. */
void lin3_gyro(const sm_model *m, const sp_kin *k, double omega, dmat *C, dmat *Y);
/** Kt = K + d f_g/dq - s H at q, frozen as lin3_geometric_tangent; H (n x n) receives dg/dq
 *  (untouched when s = 0).  Uses the complex scratch of k.  work: >= 13 max m_s doubles. */
void lin3_tangent(const sm_model *m, const double *q, sp_kin *k, double s, int frozen, dmat *Kt, dmat *H,
                  double *work);
/** nodes (6 n_nodes) = x, y, z and the rotation vector of each node's triad (DESIGN.md 7.3);
 *  returns the largest |psi| (rotation relative to the own frame) and its node in *at. */
double lin3_nodes(const sm_model *m, const sp_kin *k, double *nodes, int *at);
/** y (6 n_nodes) = (J_k x, W_k x) per node at k (jac). */
void lin3_nodal(const sm_model *m, const sp_kin *k, const double *x, double *y);

/* ------------------------------------------------------------ tree3.c */
/** The local blocks of tree.c for a spatial model at q (pose coordinates dR, dtheta of each frame):
 *  Kl of the Newton tangent (frozen 0) or of K* (frozen 1) from the block Hessian
 *  [0 Gown'; Gown Hd] of frames3.c; Ml and Cl when lin (Cl only with gyro).  k: kinematics
 *  without Jacobians, evaluated here.  Returns 1 when all are finite. */
int tree3_assemble(const sm_model *m, const double *q, sp_kin *k, double s2, int frozen, int lin, int gyro,
                   tree_ws *t);
/** y (6 n_nodes) = (J_k x, W_k x) per node at the kinematics of the last tree3_assemble. */
void tree3_nodal(const sm_model *m, const sp_kin *k, tree_ws *t, const double *x, double *y);

#endif
