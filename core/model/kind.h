/*
 * kind.h — the structure kind as an interface (not installed; issue 24, DESIGN.md 2).
 *
 * A model is planar (3 DOF per node, frames turning about the spin axis: Kim & Yoo's
 * formulation, frames.c, linearize.c, fe.c) or spatial (6 DOF per node, DESIGN.md 7:
 * spatial.h).  Everything that differs between the two is behind one table of
 * functions, smi_kind, with one implementation per kind (kind_planar.c, kind_spatial.c)
 * picked once, when the model is built (mesh_build sets m->kind).  The shared code —
 * the mesh walk, the component-mode driver, the Newton continuation, the linear-system
 * paths (linsys.c), the sweep — calls through m->kind and never asks which kind it has.
 *
 * The kinematics workspace is opaque (void *): each kind allocates its own (sm_kin,
 * sp_kin) in one of three sizes; the dense matrices a kind assembles live in an
 * smi_dense that the kind allocates for the use asked.  To add a structure kind (a
 * Timoshenko planar beam, a shell strip) is to write one more table.
 */
#ifndef SM_KIND_H
#define SM_KIND_H

#include "internal.h"

/* What a kinematics workspace or a set of dense matrices is for. */
enum {
    SMI_USE_TREE = 0,   /* the tree path: positions only, O(size) memory */
    SMI_USE_NEWTON = 1, /* the dense Newton tangent of the continuation */
    SMI_USE_MODES = 2   /* the dense K*, M*, C* and nodal shapes at a steady state */
};

/* Dense matrices of a kind: K (Newton tangent or K*), M*, C*, the centrifugal Jacobian H and
 * the kind's scratch W, X; which of them exist depends on the kind and the use. */
typedef struct smi_dense {
    dmat K, M, C, H, W, X;
} smi_dense;

typedef struct smi_kind {
    const char *name;    /* "planar" | "spatial" */
    int spatial;         /* 1: the model is reported as spatial (sm_model_info) */
    int axes;            /* 1: members have principal axes and twist (sm_model_member_axes) */
    int node_dof;        /* values per node in nodal outputs and shapes: 3 | 6 */
    int pose_dof;        /* frame pose coordinates in the tree path: 3 | 6 */
    int ubar_dim;        /* undeformed local coordinates per free node: 2 | 3 */
    int stiffened_start; /* 1: the continuation from rest starts with a small increment and a
                            stiffened predictor (equilibrium.c, DESIGN.md 7.3) */
    int fixed_bits;      /* 1: results are fixed to the byte (the planar kind, issue 27): the
                            solver keeps the operations that produced them.  0 (spatial): a
                            sweep predicts with the carried Newton tangent (eq_carry), and the
                            tree path solves its fronts itself, projects by the Hermitian
                            inverse form and stops refining once it corrects nothing (tree.c,
                            eigen_tree.c): the same answers to ~1e-12, in other last bits */

    /* ---- model build (mesh.c, modes.c, model.c) ---- */
    /** Length of a member from its joints' differences (the kind's own rounding). */
    double (*length)(double dx, double dy, double dz);
    /** The kind's checks of st (sections, kind-only fields); diag as mesh_check's. */
    int (*check)(const sm_structure *st, const sm_options *o, sm_diag *d);
    /** Element axes and sections after mesh_nodes (NULL: nothing to do).  SM_OK or
     *  SM_INVALID_INPUT. */
    int (*elements)(sm_model *m, const sm_structure *st, sm_diag *d);
    /** Frame orientations and the undeformed local positions ubar after mesh_subs. */
    void (*subs)(sm_model *m);
    /** Modal coordinates of substructure b: *nm component modes, *na attachment columns. */
    int (*count)(const sm_options *o, const sm_sub *b, int *nm, int *na);
    /** Basis, K_s, T_e, d_e of substructure b.  SM_OK, SM_NOMEM, SM_SINGULAR, SM_LAPACK_FAILED. */
    int (*basis)(const sm_model *m, sm_sub *b);
    /** The mass points of m after every basis.  SM_OK or SM_NOMEM. */
    int (*points)(sm_model *m);

    /* ---- kinematics ---- */
    /** A kinematics workspace for use (SMI_USE_*), NULL when out of memory. */
    void *(*kin_new)(const sm_model *m, int use);
    /** Free a workspace of kin_new; NULL is fine. */
    void (*kin_free)(void *k);
    /** Kinematics at q (with the Jacobians where the workspace has them). */
    void (*kin_eval)(const sm_model *m, const double *q, void *k);
    /** J (n x node_dof, column-major) = the motion of FE node nd itself (not of a mass offset
     *  from it) per modal coordinate, at the kinematics in k (a SMI_USE_MODES workspace). */
    void (*node_jacobian)(const sm_model *m, const void *k, int nd, double *J);

    /* ---- forces and the linearised system ---- */
    /** g (n) with Omega^2 g the centrifugal force at q; leaves the kinematics of q in k (t: the
     *  tree path's workspace, NULL on the dense path). */
    void (*centrifugal)(const sm_model *m, const double *q, void *k, tree_ws *t, double *g);
    /** f += f_g(q), the geometric (axial-force) term of F. */
    void (*geometric_force)(const sm_model *m, const double *q, double *f);
    /** Allocate the dense matrices of use (SMI_USE_NEWTON or SMI_USE_MODES) in D (zeroed).
     *  SM_OK or SM_NOMEM (D then holds what was allocated: smi_dense_free). */
    int (*dense_alloc)(const sm_model *m, int use, smi_dense *D);
    /** D->K = the Newton tangent at q, s = Omega^2, from the kinematics in k (the last
     *  centrifugal at q).  work: >= 12 max m_s doubles. */
    void (*dense_tangent)(const sm_model *m, const double *q, void *k, double s, smi_dense *D,
                          double *work);
    /** At q: kinematics, D->K = K* (P frozen; not yet symmetrised), D->M = M*, and with gyro
     *  D->C = C* at omega. */
    void (*dense_linearize)(const sm_model *m, const double *q, void *k, double omega, int gyro,
                            smi_dense *D, double *work);
    /** The tree path's local blocks at q: lin 0 the Newton tangent (kinematics from the last
     *  centrifugal at q), lin 1 K* (P frozen), M* and, with gyro, C*.  1 when all are finite. */
    int (*tree_assemble)(const sm_model *m, const double *q, void *k, double s, int lin, int gyro,
                         tree_ws *t);

    /* ---- outputs ---- */
    /** yr, yi (node_dof n_nodes each) = the nodal motion of the modal vector xr + i xi at the
     *  kinematics in k (t: the tree workspace of the last assembly, or NULL for the dense
     *  Jacobians); both parts in one pass where the kind can. */
    void (*nodal)(const sm_model *m, void *k, tree_ws *t, const double *xr, const double *xi,
                  double *yr, double *yi);
    /** nodes (node_dof n_nodes) = the steady-state positions and rotations at the kinematics
     *  in k; returns the largest rotation of a node relative to its frame, its node in *at. */
    double (*nodes)(const sm_model *m, void *k, double *nodes, int *at);

    /* ---- mode labels (labels.c, DESIGN.md 9.1) ---- */
    int label_bending; /* 1: the bending slot is labelled "bending" (no edge / flap split) */
    /** Element e's axes t, p2, p3 (hub frame) at the steady state of case c. */
    void (*label_axes)(const sm_model *m, const sm_case *c, const sm_elem *e, double t[3],
                       double p2[3], double p3[3]);
    /** Node k of the real nodal shape s as a translation d and a rotation r in 3D. */
    void (*label_node)(const double *s, int k, double d[3], double r[3]);
    /** e += the rotary kinetic parts at one end of E (tx, r2, r3: its rotation about t, p2,
     *  p3); NULL: the kind has no rotary inertia. */
    void (*label_rotary)(const sm_elem *E, double tx, double r2, double r3,
                         double e[SM_ENERGY_PARTS]);
    /** e[5..7] += bending and torsion strain of E from its ends' motion. */
    void (*label_strain)(const sm_elem *E, const double v[2], const double w[2], const double tx[2],
                         const double r2[2], const double r3[2], double e[SM_ENERGY_PARTS]);
    /** e += the point-mass rotary parts at the far node of element el for shape s, ax: its
     *  axes t, p2, p3 (label_axes); NULL: none. */
    void (*label_point)(const sm_model *m, int el, const double ax[9], const double *s,
                        double e[SM_ENERGY_PARTS]);
} smi_kind;

extern const smi_kind smi_kind_planar;  /* kind_planar.c */
extern const smi_kind smi_kind_spatial; /* kind_spatial.c */

/** The kind of structure st (mesh.c: the one place that picks; mesh_build stores it in m->kind). */
const smi_kind *smi_kind_of(const sm_structure *st);

/** Free the matrices of D and zero it; safe on a zeroed one. */
void smi_dense_free(smi_dense *D);

#endif
