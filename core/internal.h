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
 */
#ifndef SM_INTERNAL_H
#define SM_INTERNAL_H

#include "spinmodal.h"
#include "dense.h"

/* FE node. */
typedef struct sm_node {
    double x, y;        /* undeformed position, hub frame */
    double mass;        /* lumped mass (element halves + point masses), kg */
    double point_mass;  /* point masses only, kg */
    int sub;            /* substructure that holds it as a free node, -1 for the clamp */
    int local;          /* free-node index within that substructure, -1 for the clamp */
    int joint;          /* joint index, -1 for member-interior nodes */
} sm_node;

/* FE element (2 nodes, 3 DOF each), oriented away from the clamp. */
typedef struct sm_elem {
    int n1, n2;         /* node indices, n1 nearer the clamp */
    int member;         /* member index */
    int sub;            /* substructure */
    double l;           /* length, m */
    double angle;       /* direction angle in the hub frame, rad */
    double EA, EI, mu;  /* section data */
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
};

/* ------------------------------------------------------------- fe.c */
void fe_stiffness_local(double EA, double EI, double l, double k[36]);
void fe_mass_consistent_local(double mu, double l, double m[36]);
void fe_rotation(double alpha, double c[36]);
void fe_to_frame(const double kloc[36], double alpha, double kfr[36]);
void fe_shape(double xi, double l, double s[12]);
void fe_geometric_bending(double l, double g[16]);

/* ------------------------------------------------------------- mesh.c */
int mesh_build(sm_model *m, const sm_structure *st, sm_diag *diag);

/* ------------------------------------------------------------- modes.c */
int modes_build(sm_model *m, sm_diag *diag);
int modes_count(const sm_options *o, const sm_sub *b, int *nm, int *na);

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

int frames_kin_alloc(const sm_model *m, sm_kin *k);
void frames_kin_free(sm_kin *k);
void frames_eval(const sm_model *m, const double *q, sm_kin *k);
void frames_centrifugal(const sm_model *m, const sm_kin *k, double *g);
void frames_hessian(const sm_model *m, const double *q, const sm_kin *k, dmat *H, double *work);

/* --------------------------------------------------------- linearize.c */
void lin_geometric_force(const sm_model *m, const double *q, double *fg);
void lin_geometric_tangent(const sm_model *m, const double *q, int frozen, dmat *Kt, double *work);
void lin_axial_forces(const sm_model *m, const double *q, double *P);
void lin_elastic_force(const sm_model *m, const double *q, double *f);
void lin_elastic_add(const sm_model *m, dmat *Kt);
void lin_mass(const sm_model *m, const sm_kin *k, dmat *M, dmat *W);
void lin_gyro(const sm_model *m, const sm_kin *k, double omega, dmat *C, dmat *W, dmat *X);
void lin_tangent(const sm_model *m, const double *q, const sm_kin *k, double s, int frozen, dmat *Kt,
                 dmat *M, dmat *H, dmat *W, double *work);

/* ------------------------------------------------------- equilibrium.c */
typedef struct sm_eq_out {
    int converged;
    int iterations;
    double residual;
    double last_s;      /* last Omega^2 with a converged equilibrium */
    int canceled;
    char message[256];
} sm_eq_out;

typedef struct sm_progress {
    sm_progress_fn cb;
    void *user;
    int done, total;
} sm_progress;

int eq_solve(const sm_model *m, double *q, double s_from, double s_to,
             int from_rest, sm_progress *pr, sm_eq_out *out);

/* -------------------------------------------------------------- eigen.c */
typedef struct sm_eig_out {
    int n_modes;
    double *wre, *wim;  /* eigenvalues lambda */
    double *xre, *xim;  /* n x n_modes modal-coordinate vectors (xim may be zero) */
    int negative;       /* negative eigenvalues of K* */
    double max_re;
} sm_eig_out;

int eig_solve(int n, const dmat *M, const dmat *C, const dmat *K, int coriolis,
              int modes, sm_eig_out *out);
void eig_out_free(sm_eig_out *o);

#endif
