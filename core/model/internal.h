/*
 * internal.h — data structures shared by the core modules (not installed).
 *
 * The model (sm_model) is built once by mesh.c + modes.c and is read-only
 * afterwards, so several solves may share it.  Everything that changes during
 * a solve lives in a workspace (sm_ws) owned by that solve.
 *
 * Conventions: 0-based indices; dense matrices column-major (dmat); the
 * global modal coordinate vector q is the concatenation of the substructure
 * coordinates q_s in substructure order, and substructures are numbered so
 * that a parent always comes before its children.
 *
 * Every cross-module function is declared here with a doc comment: pointer
 * arguments are borrowed (the caller keeps ownership) unless the comment says
 * otherwise; "scratch" arguments are caller-allocated workspace; functions
 * returning int return an sm_status (SM_OK = 0, failures negative).  Nothing
 * here keeps global state.
 */
#ifndef SM_INTERNAL_H
#define SM_INTERNAL_H

#include "spinmodal.h"
#include "csym.h"
#include "dense.h"
#include "diag.h"

/* FE node. */
typedef struct sm_node {
    double x, y;        /* undeformed position, hub frame */
    double mass;        /* lumped mass (element halves + point masses), kg */
    double point_mass;  /* point masses only, kg */
    int sub;            /* substructure that holds it as a free node, -1 for the clamp */
    int local;          /* free-node index within that substructure, -1 for the clamp */
    int joint;          /* joint index, -1 for member-interior nodes */
    /* spatial kind only */
    double z;           /* undeformed z, hub frame */
    double rot[9];      /* lumped rotary inertia tensor about the node, hub axes at rest, kg m^2
                           (section tributaries + point-mass inertia), column-major 3x3 */
    double point_rot[9]; /* point-mass inertia alone (consistent mass keeps only this) */
    double first[3];    /* first moment of the lumped mass about the node, hub axes at rest,
                           kg m (section centres of mass and point-mass offsets, DESIGN.md 8);
                           rot is about the node, so it includes the parallel-axis terms */
    double point_first[3]; /* the point masses' part alone (consistent mass) */
    double ax[9];       /* principal axes at rest (sm_model_node_axes) */
    int member;         /* the member those axes belong to */
    double span;        /* the node's span fraction on it */
} sm_node;

/* FE element (2 nodes, 3 DOF each), oriented away from the clamp. */
typedef struct sm_elem {
    int n1, n2;         /* node indices, n1 nearer the clamp */
    int member;         /* member index */
    int sub;            /* substructure */
    double l;           /* length, m */
    double angle;       /* direction angle in the hub frame, rad */
    double EA, EI, mu;  /* section data */
    /* spatial models: principal axes at rest (hub frame) as the columns of ax (column-major
     * 3x3: e1 along the element, p2 edgewise, p3 flapwise, DESIGN.md 7.1) and the section */
    double ax[9];
    double GJ, EI_edge, EI_flap; /* torsion; bending in the p2 and p3 directions */
    double i_flap, i_edge;       /* mass moments per length about p2, p3, kg m */
    double rot_pl[9];            /* spatial: the section's rotary inertia per length about its centre
                                    of mass (torsion i_flap + i_edge, i_flap, i_edge in the inertia
                                    axes), hub axes at rest, kg m */
    double ip_over_a;            /* Wagner ratio I_p/A, m^2 */
    double sc[2], tc[2];         /* shear and tension centre offsets along (p2, p3), m (p2 as in
                                    ax: it turns with the element's direction) */
    double cg[3];                /* centre-of-mass offset from the axis, hub axes at rest, m */
    double end_s[2];             /* span fractions of n1, n2 on the member */
    double end_tw[2];            /* the member's twist at n1, n2 (rad) */
    double base_ax[9];           /* the member's axes without twist (from -> to; p3 from
                                    flap_direction): sm_model_member_axes */
} sm_elem;

/* A point that carries mass (lumped node, or quadrature point for consistent mass). */
typedef struct sm_mpoint {
    int sub;            /* substructure whose frame carries it */
    int node;           /* FE node index if it is a node, -1 for a quadrature point */
    double ub[2];       /* undeformed position in the substructure frame */
    double mass;        /* kg */
    const double *N;    /* translation rows in frame coords: (u,v) = N q_s; 2 x m_s,
                           column-major with leading dimension ldn */
    int ldn;            /* leading dimension of N */
} sm_mpoint;

/* Substructure: a run of elements with its own floating frame. */
typedef struct sm_sub {
    int root;           /* FE node of the frame origin */
    int parent;         /* parent substructure, -1 when clamped to the hub */
    int attach_local;   /* free-node index in the parent where the root sits */
    double theta0;      /* undeformed frame angle (x along the first element) */
    double beta;        /* theta0 - parent theta0 (eq. 36), or theta0 for a root */
    int nfree;          /* free nodes */
    int *free_nodes;    /* nfree FE node indices */
    double *ubar;       /* 2*nfree undeformed local positions */
    int nel;            /* elements */
    int *elems;         /* nel element indices */
    int n_attach;       /* attachment nodes (free nodes where children sit) */
    int *attach;        /* n_attach free-node indices */
    int m;              /* modal coordinates of this substructure */
    int q0;             /* offset of q_s in q */
    dmat N;             /* (3*nfree) x m: rows 3i,3i+1,3i+2 = u,v,phi of free node i */
    dmat K;             /* m x m: N' Kbar N (eq. 11) */
    dmat T;             /* (6*nel) x m: T_e = C(alpha) L_e N stacked (eq. 18) */
    double *d;          /* nel*m: d_e = EA/l (T_e[3,:] - T_e[0,:]) so P_e = d_e . q_s (eq. 24) */
    double *gq;         /* nel*4*4 bending block of G_e (rows/cols v1,phi1,v2,phi2), eq. 23 */
    double *qpN;        /* consistent mass: quadrature-point N storage */
    /* spatial models: ubar has 3 per free node, N has 6 rows per free node (u, v, w, then the
     * small rotation psi, frame coordinates), T 12 rows per element (element axes) */
    double A0[9];       /* frame orientation at rest: columns = frame axes in the hub frame */
    double Arel[9];     /* A0(parent)^T A0(this): orientation relative to the parent frame (A0 for a root) */
} sm_sub;

struct sm_model {
    sm_options opt;
    int n_nodes, n_elems, n_subs, n;   /* n = number of modal coordinates */
    int n_joints;
    sm_node *nodes;
    sm_elem *elems;
    sm_sub *subs;
    int *joint_node;    /* n_joints */
    int n_mp;
    sm_mpoint *mp;      /* mass points */
    int clamp_node;     /* = 0 */
    const struct smi_kind *kind; /* planar or spatial (kind.h): picked by mesh_build */
    int n_pt;           /* spatial: points = the FE nodes (0 .. n_nodes-1) + quadrature points */
    struct sp_point *pt; /* spatial: n_pt points (spatial.h) */
    int gravity;         /* 1: grav is a steady load at rest (sm_structure.gravity): the kind's
                           "centrifugal" force is the weight's and the load factor s is 1 */
    double grav[3];      /* m/s^2, hub frame */
    int base;            /* base coordinates when the clamp joint moves (sm_structure.base_free):
                           q[i] (i < base) its motion in direction base_dir[i] (0..5: x, y, z,
                           rx, ry, rz, hub axes), the directions not held; 0 otherwise */
    int base_dir[6];
    /* elastic supports (supports.c, DESIGN.md 8.6); has_supports 0: none, all empty */
    int has_supports;
    int n_sup;             /* nodes with a support */
    int *sup_node;         /* n_sup FE nodes */
    double *sup_k, *sup_m; /* 36 per support node: 6x6 stiffness and added mass, hub axes */
    dmat sup_K, sup_M;     /* n x n: sum J0' k J0, sum J0' m J0 (J0: the nodes' motion at rest) */
};

/* ------------------------------------------------------------- fe.c */
/* Element matrices of one 2-node planar frame element (DOF u1 v1 phi1 u2 v2
 * phi2), 6x6 column-major a[i + 6*j], written into caller arrays; no status. */

/** k = element stiffness in element coordinates: EA/l axial; 12EI/l^3, 6EI/l^2, 4EI/l, 2EI/l bending. */
void fe_stiffness_local(double EA, double EI, double l, double k[36]);
/** m = consistent mass in element coordinates (linear axial, Hermite cubic transverse), mu l/420 [...]. */
void fe_mass_consistent_local(double mu, double l, double m[36]);
/** c = C(alpha) of Kim & Yoo eq. 19: element DOFs = C * frame DOFs. */
void fe_rotation(double alpha, double c[36]);
/** kfr = C(alpha)' kloc C(alpha): an element matrix rotated into frame coordinates (kloc != kfr). */
void fe_to_frame(const double kloc[36], double alpha, double kfr[36]);
/** s = shape functions S(xi) of eq. 16 at xi in [0, 1], 2x6 column-major (s[r + 2*j]). */
void fe_shape(double xi, double l, double s[12]);
/** g = bending block of G_e (eq. 23) on (v1, phi1, v2, phi2), 4x4 column-major (axial part is zero). */
void fe_geometric_bending(double l, double g[16]);

/** The load factor of the continuation and of K* at speed omega: Omega^2, or 1 for a model
 *  loaded by gravity at rest (its "centrifugal" force is then the weight's, DESIGN.md 8.8). */
static inline double smi_load(const sm_model *m, double omega)
{
    return m->gravity ? 1.0 : omega * omega;
}

/* --------------------------------------------------------- supports.c */
/** Checks of st's supports (indices, symmetric and positive semi-definite 6x6 matrices, the
 *  foundations' stretches and values) and that o allows them; diag as mesh_check's. */
int supports_check(const sm_structure *st, const sm_options *o, sm_diag *d);
/** The supports of st lumped onto m's nodes (after mesh_build): m->sup_node, sup_k, sup_m.
 *  SM_OK or SM_NOMEM. */
int supports_lump(sm_model *m, const sm_structure *st);
/** m->sup_K and sup_M in modal coordinates (after the bases).  SM_OK or SM_NOMEM. */
int supports_build(sm_model *m);
/** Free what supports_lump and supports_build allocated. */
void supports_free(sm_model *m);
/** x' K x summed over the support nodes of the nodal shape s (node_dof values per node): the
 *  supports' strain energy in the labels' convention (no 1/2); 0 without supports. */
double supports_shape_energy(const sm_model *m, const double *s);

/* ------------------------------------------------------------- mesh.c */
/**
 * The mesh phase of a model: check st against m->opt (numbers, indices,
 * options), walk the members from the clamp (a tree: cycles, disconnected
 * members, joints on no member), number nodes and elements along the walk
 * and cut them into substructures (topology, ubar, attachments; not the
 * bases).  m: a zeroed model with opt set; mesh_build allocates its nodes,
 * elems, joint_node and subs (freed by sm_model_free, also after a failure).
 * st is borrowed (not kept).  Returns SM_OK, SM_INVALID_INPUT (diag names the
 * item, index and field; diag may be NULL) or SM_NOMEM.  Cost linear in the
 * size of the structure.
 */
int mesh_build(sm_model *m, const sm_structure *st, sm_diag *diag);

/* ------------------------------------------------------------- modes.c */
/**
 * The component-mode basis of every substructure of m (after mesh_build; a spatial model's
 * through modes3_sub and modes3_points of spatial.h):
 * N, K_s, T_e, d_e, G_e, the coordinate offsets q0 and m->n, and the mass
 * points m->mp.  Everything allocated belongs to m (sm_model_free).  Returns
 * SM_OK, SM_NOMEM, SM_SINGULAR (a substructure stiffness or mass matrix that
 * is not positive definite), SM_LAPACK_FAILED or SM_CANCELED (cb, may be
 * NULL, is asked before each substructure after the first with done =
 * substructures built, total = all of them; nonzero stops), with
 * diag->status and diag->message set (diag may be NULL).
 */
int modes_build(sm_model *m, sm_progress_fn cb, void *user, sm_diag *diag);
/**
 * Modal coordinates substructure b (topology from mesh_build) gets under the
 * options o: *nm component modes plus *na attachment columns (both written);
 * returns *nm + *na.  No allocation, no status; cost O(1).
 */
int modes_count(const sm_options *o, const sm_sub *b, int *nm, int *na);
/** *K, *M = Kbar and Mbar of planar substructure b (lumped mass = the node masses on u, v) in
 *  their sparse pattern, entry for entry the matrices of the dense path.  SM_OK or SM_NOMEM;
 *  K, M owned by the caller (csym_free, also after a failure). */
int modes_frame_csym(const sm_model *m, const sm_sub *b, csym *K, csym *M);
/** Basis, K_s, T_e, d_e of planar substructure b (the planar kind's basis; modes_build calls it
 *  through m->kind).  SM_OK, SM_NOMEM, SM_SINGULAR or SM_LAPACK_FAILED. */
int modes_planar_sub(const sm_model *m, sm_sub *b);
/** The mass points m->mp of a planar model after every modes_planar_sub.  SM_OK or SM_NOMEM. */
int modes_planar_points(sm_model *m);

/* ------------------------------------------------------------ frames.c */
/* Kinematic state at q: frames, point positions and Jacobians. */
typedef struct sm_kin {
    int n;              /* coordinates */
    double *theta;      /* n_subs frame angles */
    double *R;          /* 2*n_subs frame origins */
    dmat Jth;           /* n_subs x n: d theta_s / dq  (row s) -- stored as n x n_subs columns */
    dmat JR;            /* n x (2*n_subs): columns 2s, 2s+1 = (dR_s/dq)' */
    double *rn;         /* 3*n_nodes: node x, y, phi (phi = rotation from undeformed) */
    dmat Jn;            /* n x (3*n_nodes): columns = (d r_k/dq)', (d phi_k/dq)' */
    double *wn;         /* 2*n_nodes: local deformed position w = ubar + N q_s */
    double *rp;         /* 2*n_mp: mass point positions */
    double *wp;         /* 2*n_mp: local deformed positions of mass points */
    double *fext;       /* 2*n_nodes: scratch for the Hessian recursion */
    dmat Jtha;          /* n x n_subs: scratch, column s = a_s (d theta_s/dq)' (Hessian) */
    dmat Jp;            /* n x (2*n_mp): columns = (d r_p/dq)' */
} sm_kin;

/** Allocate the arrays of *k (owned by k, frames_kin_free) for the sizes of m.
 *  Returns SM_OK or SM_NOMEM (then *k is freed and zeroed). */
int frames_kin_alloc(const sm_model *m, sm_kin *k);
/** Like frames_kin_alloc without the dense Jacobians (Jth, JR, Jn, Jp, Jtha stay empty): O(size)
 *  memory; frames_eval then computes positions only (tree.c works on this). */
int frames_kin_alloc_light(const sm_model *m, sm_kin *k);
/** Free the arrays of *k and zero it; safe on a zeroed or freed sm_kin. */
void frames_kin_free(sm_kin *k);
/** Kinematics at q (n coordinates): frame angles and origins through the chain (eq. 36), node
 *  and mass-point positions and their Jacobians, into k (allocated for m).  No status. */
void frames_eval(const sm_model *m, const double *q, sm_kin *k);
/** g (n) = sum_p m_p J_p' r_p at the kinematics k, so the centrifugal force is Omega^2 g. */
void frames_centrifugal(const sm_model *m, const sm_kin *k, double *g);
/** H += sum_p m_p r_p . d2 r_p/dq2 (n x n, symmetric) at the kinematics k of q.  Writes the
 *  scratch fields k->fext and k->Jtha (k is otherwise read-only); work: >= max m_s doubles. */
void frames_hessian(const sm_model *m, const double *q, const sm_kin *k, dmat *H, double *work);

/* --------------------------------------------------------- linearize.c */
/* Terms of F(q) and of the linearised equations.  q: n coordinates; matrices
 * n x n, caller-allocated; nothing is allocated; no status. */

/** fg += f_g(q) = sum_e P_e T_e' G_e T_e q_s (eqs. 22, 24, 26); fg: n. */
void lin_geometric_force(const sm_model *m, const double *q, double *fg);
/** Kt += d f_g/dq at q; frozen != 0: P_e held at P_e(q) (the paper's K*, symmetric), else the full
 *  derivative (Newton).  work: >= 5 max m_s doubles. */
void lin_geometric_tangent(const sm_model *m, const double *q, int frozen, dmat *Kt, double *work);
/** A += d f_g,s/dq_s of substructure s alone, m_s x m_s with leading dimension lda (the diagonal
 *  block of lin_geometric_tangent); frozen as there.  work: >= 5 max m_s doubles. */
void lin_geometric_tangent_sub(const sm_model *m, int s, const double *q, int frozen, double *A, int lda,
                               double *work);
/** P[e] = d_e . q_s, the axial force of every FE element (eq. 24), N; P: n_elems. */
void lin_axial_forces(const sm_model *m, const double *q, double *P);
/** f += K q, K = blockdiag(N_s' Kbar_s N_s) (eq. 11); f: n. */
void lin_elastic_force(const sm_model *m, const double *q, double *f);
/** Kt += K = blockdiag(K_s) (eq. 11). */
void lin_elastic_add(const sm_model *m, dmat *Kt);
/** M = M* = sum_p m_p J_p' J_p (eq. 42) at the kinematics k, full symmetric; W: n x 2 n_mp scratch. */
void lin_mass(const sm_model *m, const sm_kin *k, dmat *M, dmat *W);
/** C = C* = 2 omega sum_p m_p J_p' S J_p (eq. 43, skew) at k; W: n x 2 n_mp, X: n x n scratch. */
void lin_gyro(const sm_model *m, const sm_kin *k, double omega, dmat *C, dmat *W, dmat *X);
/**
 * Kt = K + d f_g/dq - s (M* + H) at q with its kinematics in k, s = Omega^2:
 * the Newton tangent (frozen = 0) or K* with P frozen (frozen != 0, eq. 44).
 * The one assembly of it; also leaves M* in M and H in H.  W: n x 2 n_mp
 * scratch; work: >= 5 max m_s doubles.  Writes the scratch fields of k
 * (frames_hessian).
 */
void lin_tangent(const sm_model *m, const double *q, const sm_kin *k, double s, int frozen, dmat *Kt,
                 dmat *M, dmat *H, dmat *W, double *work);

/* ------------------------------------------------------- equilibrium.c */
/* Outcome of one continuation (eq_solve). */
typedef struct sm_eq_out {
    int converged;      /* 1 when s_to was reached */
    int iterations;     /* Newton iterations spent */
    double residual;    /* ||F(q)|| at the returned q */
    double last_s;      /* last Omega^2 with a converged equilibrium */
    int canceled;       /* 1 when the progress callback asked to stop */
    int crossings;      /* critical points (sign changes of det Kt) crossed on the way: the
                           state beyond a bifurcation is an unstable steady state */
    double first_crossing_s; /* Omega^2 (mid-step) of the first of them; 0 when none */
    char message[256];  /* why it did not converge, or the error; "" on success */
} sm_eq_out;

/* Progress reporting through sm_solve's callback. */
typedef struct sm_progress {
    sm_progress_fn cb;  /* may be NULL */
    void *user;
    int done, total;    /* speeds finished / requested */
} sm_progress;

/* The workspace of a sequence of continuations (a sweep's speeds, equilibrium.c), kept from one
 * eq_solve to the next: allocated once, and for a kind without fixed_bits the factors of the
 * last Newton tangent, which predict the next speed's first step. */
typedef struct eq_carry eq_carry;

/** A carry for continuations of m: SM_OK or SM_NOMEM (*out NULL). */
int eq_carry_new(const sm_model *m, eq_carry **out);
void eq_carry_free(eq_carry *c);

/**
 * Continuation in s = Omega^2 from the equilibrium q at s_from (q = 0 with
 * from_rest: at least min_increments steps; a kind with stiffened_start first
 * tries one step from s_from = 0, DESIGN.md 7.3) to s_to, Newton-Raphson at each
 * step (DESIGN.md 1.3).  q (n, in/out): the equilibrium at s_to when
 * out->converged, else the last converged state (at out->last_s).  carry:
 * NULL, or the workspace of the continuation that ended at (q, s_from).  pr
 * may be NULL.  Returns SM_OK whether or not it converged or was canceled
 * (see *out), SM_NOMEM, or SM_LAPACK_FAILED when a factorisation or solve
 * reports an error (out->message says where).
 */
int eq_solve(const sm_model *m, double *q, double s_from, double s_to, int from_rest,
             eq_carry *carry, sm_progress *pr, sm_eq_out *out);

/* --------------------------------------------------------------- tree.c */
/* The linearised equations in block form along the frame tree (see the header of tree.c):
 * local blocks on (dy_s, dq_s) per substructure, a leaves-first block factorisation, O(n)
 * products and solves. */
typedef struct tree_ws {
    int S, n;           /* substructures, coordinates */
    int d;              /* frame-pose coordinates: 3 planar (x, y, theta), 6 spatial (dR, dtheta) */
    int fixed_bits;     /* the kind's fixed_bits (kind.h): LAPACK front solves, the links of the
                           latest iterate, dgeev projections, every refinement */
    int max_m;          /* largest m_s */
    int *mp_ptr;        /* S+1: mass points of s are mp_idx[mp_ptr[s] .. mp_ptr[s+1]) */
    int *mp_idx;        /* n_mp mass point indices grouped by substructure */
    size_t *loc_off;    /* S+1: offset of the (d+m_s)^2 local blocks of s in Kl, Ml, Cl */
    size_t *fr_off;     /* S+1: offset of the (m_s+2d)^2 front of s in F */
    size_t *v_off;      /* S+1: offset of the m_s+2d vector of s in z and ipiv (xd in X) */
    double *Kl;         /* local K* (or Newton tangent) blocks, order (frame pose d, q_s) */
    double *Ml;         /* local M* blocks */
    double *Cl;         /* local C* blocks without the factor 2 Omega */
    double *F;          /* fronts: factors after tree_factor */
    double *Finv;       /* spatial symmetric fronts: F_s^-1 itself (tree_factor, read by the
                           solves of tree_solve; NULL until needed), offsets fr_off */
    double *X;          /* (m_s+2d) x d per s: F_s^-1 E_w */
    int *ipiv;          /* pivots of the fronts */
    double *lk;         /* 4 per s: cos, sin of the parent's angle and A' w_e (the link T_s);
                           spatial: 3 per s, a = R_s - R_parent (T_s = [I -skew(a); 0 I]) */
    double *D;          /* spatial: 6 x m_parent per s (ld 6), the link D_s = [A N^u_e; A T N^psi_e] */
    size_t *d_off;      /* spatial: S+1 offsets of D_s */
    double *Cc;         /* d x (m_parent + d) per s (ld d): the coupling C_s = [-D_s, -T_s] to the
                           parent's front, built by tree_factor, read by tree_solve */
    size_t *c_off;      /* S+1 offsets of C_s in Cc */
    double *z;          /* sum (m_s+2d): solve vector */
    double *u, *v;      /* d S each: forward / adjoint recursion vectors */
    double *work;       /* small scratch */
    double omega;       /* Omega of the last tree_assemble (C* = 2 Omega Cl) */
    int sym;            /* fronts factored by dsytrf (1) or dgetrf (0) */
    int neg;            /* negative eigenvalues of the factored matrix (sym) */
    int det_sign;       /* sign of its determinant (LU) */
    /* The warm start of a spatial sweep's eigen-analysis (eigen_tree.c, issue 27): warm (n, or
     * NULL) the sum of the last accepted modes' vectors on this workspace, warm_ok 1 when it is
     * set, warm_next 1 when the next eig_solve_tree may start from it (smi_lin_warm; cleared
     * by that call). */
    double *warm;
    int warm_ok, warm_next;
} tree_ws;

enum { TREE_K = 0, TREE_M = 1, TREE_C = 2 };

/** 1 when solves of m use the tree path: m->opt.solver, or by size for SM_SOLVER_AUTO. */
int tree_use(const sm_model *m);

/**
 * The choice of tree_use from sizes alone (for sm_structure_check, before any
 * basis exists): solver is sm_options.solver, n the coordinates, max_m the
 * largest frame's coordinates, modes the modes requested.
 */
int tree_choose(int solver, int n, int max_m, int modes);
/** Allocate *t for m (O(sum m_s^2)); SM_OK or SM_NOMEM (then *t is zeroed). */
int tree_alloc(const sm_model *m, tree_ws *t);
/** Free and zero *t; safe on a zeroed one. */
void tree_free(tree_ws *t);
/** g (n) = sum_p m_p J_p' r_p at the (light) kinematics k, as frames_centrifugal. */
void tree_centrifugal(const sm_model *m, const sm_kin *k, tree_ws *t, double *g);
/** Local blocks at q (kinematics k of q; k->fext is scratch) for s2 = Omega^2: Kl of the Newton
 *  tangent (frozen 0) or of K* (frozen 1), Ml, and Cl when gyro.  Returns 1 when all are finite. */
int tree_assemble(const sm_model *m, const double *q, sm_kin *k, double s2, int frozen, int gyro, tree_ws *t);
/** Factor the block system of Kl (after tree_assemble): sym = 1 for K* (sets t->neg, the negative
 *  eigenvalues of K*), 0 for the tangent (sets t->det_sign = sign det).  SM_OK, SM_SINGULAR (a
 *  singular front), SM_NOMEM or SM_LAPACK_FAILED. */
int tree_factor(const sm_model *m, tree_ws *t, int sym);
/** x = K^-1 x (n) with the factors of tree_factor.  SM_OK or SM_LAPACK_FAILED. */
int tree_solve(const sm_model *m, tree_ws *t, double *x);
/** y = A x for A = K (TREE_K), M* (TREE_M) or C* (TREE_C) of the last tree_assemble; x, y: n. */
void tree_apply(const sm_model *m, tree_ws *t, int which, const double *x, double *y);
/** y[i] = A_i x for the n_ops operators which[i] (TREE_K, TREE_M, TREE_C): one forward recursion
 *  for all of them, each y[i] the bits of tree_apply's (issue 27). */
void tree_apply_n(const sm_model *m, tree_ws *t, int n_ops, const int *which, const double *x,
                  double *const *y);
/** u (d S) = the frame pose increments dy/dq x (forward recursion along the tree, links of the
 *  last assembly). */
void tree_forward(const sm_model *m, const tree_ws *t, const double *x, double *u);
/** y += the adjoint recursion of the tree's links applied to v (d S; destroyed): the transpose of
 *  tree_forward, for products and right-hand sides (tree.c; the planar blocks use it). */
void tree_adjoint(const sm_model *m, const tree_ws *t, double *v, double *y);
/** d (3 n_nodes) = nodal (dx, dy, dphi) = J_k x in the hub frame at the kinematics k. */
void tree_nodal(const sm_model *m, const sm_kin *k, tree_ws *t, const double *x, double *d);

/* -------------------------------------------------------------- eigen.c */
/* Eigen-analysis output; arrays owned by the struct (eig_out_free). */
typedef struct sm_eig_out {
    int n_modes;
    double *wre, *wim;  /* n_modes eigenvalues lambda */
    double *xre, *xim;  /* n x n_modes modal-coordinate vectors (xim may be zero) */
    int negative;       /* negative eigenvalues of K* */
    double max_re;      /* largest Re(lambda) over the computed roots */
} sm_eig_out;

/**
 * Eigen-analysis of the linearised equations (DESIGN.md 1.4): with coriolis,
 * (lambda^2 M + lambda C + K) x = 0, else K x = w^2 M x, after exact
 * condensation of the null space of M.  M, C, K: n x n, borrowed (C unused
 * without coriolis).  *out receives min(modes, rank M) modes, ascending, and
 * owns its arrays (eig_out_free).  Returns SM_OK, SM_NOMEM, SM_SINGULAR (M
 * has no range, or the stiffness on its null space is exactly singular) or
 * SM_LAPACK_FAILED (a LAPACK error, e.g. non-finite input); on failure *out
 * is empty (nothing to free).  fixed_bits: the kind's (kind.h); 1 keeps LAPACK's dsyevr for
 * the symmetric eigenproblems, 0 takes dm_syev_range's route without bisection (the same
 * accuracy, other last bits; issue 27).
 */
int eig_solve(int n, const dmat *M, const dmat *C, const dmat *K, int coriolis, int modes,
              int fixed_bits, sm_eig_out *out);
/**
 * The same analysis on the tree form (tree_assemble with frozen = 1 and gyro = coriolis done):
 * factors K*, and when K* is positive definite finds the lowest modes by shift-invert Arnoldi and
 * a projection solved by eig_solve (see tree.c).  *fallback receives 1 when the dense path must be
 * used instead (K* not positive definite, a singular front, no convergence); then *out is empty
 * and the return is SM_OK.  pr (may be NULL): its callback is asked every 8 Krylov vectors (a
 * 2000-element blade's 64 modes are ~8 s of them), nonzero stops with SM_CANCELED.
 * Returns SM_OK, SM_NOMEM, SM_CANCELED or SM_LAPACK_FAILED.
 */
int eig_solve_tree(const sm_model *m, tree_ws *t, int coriolis, int modes, const sm_progress *pr,
                   sm_eig_out *out, int *fallback);
/** Free the arrays of *o and zero it; safe on a zeroed or freed sm_eig_out. */
void eig_out_free(sm_eig_out *o);

/**
 * Allocate o's arrays for k modes of n coordinates (eigen.c; eigen_tree.c
 * uses it too).  Returns SM_OK or SM_NOMEM (o then holds what was allocated:
 * eig_out_free).
 */
int eig_alloc_out(sm_eig_out *o, int n, int k);

/* One root of a companion-form eigenproblem, sorted by key (eigen.c, eigen_tree.c). */
typedef struct eig_root {
    double re, im, key;  /* the root, and its sort key (ascending = lowest first) */
    int col;             /* its eigenvector's column */
} eig_root;

/** qsort order of eig_root by key, ascending. */
int eig_root_cmp(const void *a, const void *b);

/* ------------------------------------------- labels.c, track.c, critical.c (DESIGN.md 9.1) */
/** Energy fractions, label kind, ordinal and confidence of every mode of c (allocated into c,
 *  freed by sm_result_free) from its nodal shapes; nothing when c has no modes or no shapes.
 *  Returns SM_OK or SM_NOMEM. */
int lab_case(const sm_model *m, sm_case *c);
/** MAC of mode a of case A and mode b of case B over the nodal translations (both with shapes,
 *  same model), in [0, 1]. */
double track_mac(const sm_case *A, int a, const sm_case *B, int b);
/** Optimal assignment maximising the sum of mac (nr x nc, row-major, rows = current modes,
 *  columns = previous ones): match[r] = column of row r, or -1 when nr > nc leaves it out.
 *  Hungarian method, O(max(nr, nc)^3).  Returns SM_OK or SM_NOMEM. */
int track_assign(int nr, int nc, const double *mac, int *match);
/** Tracking of the sweep r (ord: the n case indices in ascending speed; shapes present):
 *  mac_to_previous, previous_index, tracked_index, track_flag, track_partner.  SM_OK or SM_NOMEM. */
int track_sweep(sm_result *r, const int *ord, int n);
/** What a caller of sweep_run does to each case with modes once its modes and nodal shapes are
 *  in, on the thread that finished the case (post/labels.c's lab_case: a higher layer's, passed
 *  down).  SM_OK or a negative status, which stops the sweep. */
typedef int (*sweep_case_fn)(const sm_model *m, sm_case *c);
/** Every speed of omegas (n_omegas >= 1, finite, >= 0; else SM_INVALID_INPUT in diag): the
 *  equilibrium, modes and nodal shapes of each, kept, and after(m, case) on each case with modes
 *  (after may be NULL); no tracking or refinements (solve/sweep.c; sm_solve adds them).  *out
 *  owned by the caller.  Returns as sm_solve. */
int sweep_run(const sm_model *m, const double *omegas, int n_omegas, sm_progress_fn cb, void *user,
              sweep_case_fn after, sm_result **out, sm_diag *diag);
/** ord (n case indices) = the speeds of omegas in ascending order, ties in input order.
 *  SM_OK or SM_NOMEM. */
int sweep_order(const double *omegas, int n, int *ord);
/** Critical speeds of the tracked sweep r for m->opt.engine_orders into r->critical (cb, user:
 *  the caller's cancel callback, asked between refining solves).  SM_OK, SM_NOMEM, SM_CANCELED. */
int crit_find(const sm_model *m, sm_result *r, const int *ord, int n, sm_progress_fn cb, void *user);

/* ------------------------------------------------------------ diverge.c */
/** Divergence speeds of a solved sweep (ord: the speeds in ascending order) into r->divergence:
 *  SM_OK, SM_NOMEM or SM_CANCELED. */
int div_find(const sm_model *m, sm_result *r, const int *ord, int n, sm_progress_fn cb, void *user);
/** *lambda = the lowest eigenvalue of K* (dense, P frozen) at the steady state of omega, from rest.
 *  SM_OK; SM_NO_EQUILIBRIUM without one; SM_NOMEM, SM_LAPACK_FAILED or SM_CANCELED (cb). */
int sweep_lowest(const sm_model *m, double omega, sm_progress_fn cb, void *user, double *lambda);

#endif
