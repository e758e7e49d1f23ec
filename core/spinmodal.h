/*
 * spinmodal.h — public API of libspinmodal, the numerical core.
 *
 * Modal analysis of beam structures spinning at a constant speed about the
 * hub (z) axis with the multi-reference-frame method of Kim & Yoo (2006),
 * see DESIGN.md section 1: planar structures (in the rotation plane, 3 DOF
 * per node) and spatial ones (sm_structure.spatial: 6 DOF per node with
 * flap, lead-lag, torsion and axial motion, twisted sections, offsets and
 * blade stations; DESIGN.md sections 7 and 8).  The core does no I/O, keeps
 * no global state and is re-entrant: distinct sm_model objects may be used
 * from distinct threads, and one sm_model may be solved from several threads
 * at once (sm_solve only reads the model).
 *
 * Usage:
 *   sm_structure st = {...};          // joints, sections, members, clamp
 *   sm_options opt; sm_default_options(&opt);
 *   sm_model *m; sm_diag d;
 *   if (sm_model_new(&m, &st, &opt, &d) < 0) { report d.message, d.item }
 *   sm_result *r;
 *   sm_solve(m, omegas, n, NULL, NULL, &r, &d);
 *   ... r->cases[i] ...
 *   sm_result_free(r); sm_model_free(m);
 *
 * Indices are 0-based.  Units are SI; angles in radians; frequencies rad/s.
 */
#ifndef SPINMODAL_H
#define SPINMODAL_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SM_VERSION "0.8.8"

/* One status table for the whole project (X-macro: name, value, text). */
#define SM_STATUS_MAP(X)                                                       \
    X(OK, 0, "success")                                                        \
    X(NOMEM, -1, "out of memory")                                              \
    X(INVALID_INPUT, -2, "invalid input")                                      \
    X(SINGULAR, -3, "singular matrix")                                         \
    X(NOT_CONVERGED, -4, "Newton-Raphson did not converge")                    \
    X(NO_EQUILIBRIUM, -5, "no dynamic equilibrium")                            \
    X(LAPACK_FAILED, -6, "LAPACK routine failed")                              \
    X(UNSTABLE, -7, "steady state is unstable")                                \
    X(CANCELED, -8, "canceled")                                                \
    X(LIMIT, -9, "size limit exceeded")

typedef enum sm_status {
#define SM_STATUS_ENUM(name, value, text) SM_##name = value,
    SM_STATUS_MAP(SM_STATUS_ENUM)
#undef SM_STATUS_ENUM
} sm_status;

/** Text for a status code; never NULL ("unknown status" for foreign codes). */
const char *sm_strerror(int status);

/** Library version string (SM_VERSION). */
const char *sm_version(void);

/* ---------------------------------------------------------------- input */

/** Section properties of a member.  A planar structure (sm_structure.spatial == 0) reads
 *  E, A, I and mu only; a spatial one (DESIGN.md 7.1) reads mu and the spatial block only. */
typedef struct sm_section {
    double E;   /* Young's modulus, Pa, > 0 (planar) */
    double A;   /* area, m^2, > 0 (planar) */
    double I;   /* in-plane second moment, m^4, > 0 (planar) */
    double mu;  /* mass per length, kg/m, > 0 (masses use mu*l); both kinds */
    /* spatial: stiffnesses about the section's principal axes (e1 along the member, e2 edgewise,
     * e3 flapwise, DESIGN.md 7.1), all > 0 */
    double EA;        /* axial, N */
    double EI_flap;   /* bending in the e3 direction (about e2), N m^2 */
    double EI_edge;   /* bending in the e2 direction (about e3), N m^2 */
    double GJ;        /* torsion, N m^2 */
    /* mass moments of inertia per length, kg m, >= 0: i_flap about e2 (turns with flap bending),
     * i_edge about e3; torsional inertia = i_flap + i_edge.  The codec fills the defaults of
     * DESIGN.md 7.1 (mu I/A); the core takes them as given. */
    double i_flap, i_edge;
    /* I_p/A of the torsional (Wagner) geometric stiffness P (I_p/A) int theta_x'^2, m^2, >= 0 */
    double ip_over_a;
    /* spatial, DESIGN.md 8: offsets from the member axis, m, along the section's principal axes
     * (index 0 along p2, edgewise/chordwise; 1 along p3, flapwise), finite, default 0:
     * cg = centre of mass (the mass moments i_flap, i_edge are about it), sc = shear centre
     * (bending and torsion act about it), tc = tension centre (the axial stiffness acts there) */
    double cg[2], sc[2], tc[2];
} sm_section;

/** Bits of sm_member.station_mask: the quantities the stations of a member give. */
enum sm_station_field {
    SM_ST_MU = 1u << 0,
    SM_ST_EA = 1u << 1,
    SM_ST_EI_FLAP = 1u << 2,
    SM_ST_EI_EDGE = 1u << 3,
    SM_ST_GJ = 1u << 4,
    SM_ST_I_FLAP = 1u << 5,
    SM_ST_I_EDGE = 1u << 6,
    SM_ST_IP_OVER_A = 1u << 7,
    SM_ST_TWIST = 1u << 8,
    SM_ST_INERTIA_TWIST = 1u << 9,
    SM_ST_CG = 1u << 10,
    SM_ST_SC = 1u << 11,
    SM_ST_TC = 1u << 12
};

/** A station along a member (DESIGN.md 8): the section quantities at span fraction s (0 at the
 *  member's `from` joint, 1 at `to`).  Between stations every quantity is linear in s and each
 *  element takes the integral mean over its length.  Only the fields named by the member's
 *  station_mask are read; the others come from the member's section (twist: member.twist;
 *  inertia twist: the structural twist). */
typedef struct sm_station {
    double s;
    double mu, EA, EI_flap, EI_edge, GJ, i_flap, i_edge, ip_over_a; /* as in sm_section */
    double twist;          /* rad, as sm_member.twist */
    double inertia_twist;  /* rad: angle of the principal axes of the mass moments (i_flap about
                              the first, i_edge about the second), right-handed about e1 from
                              (e2, e3) like twist */
    double cg[2], sc[2], tc[2]; /* as in sm_section */
} sm_station;

/** A straight member between two joints, split into equal elements. */
typedef struct sm_member {
    int from;      /* joint index */
    int to;        /* joint index */
    int section;   /* section index */
    int elements;  /* number of equal elements, >= 1 */
    /* spatial only (ignored, and must be zero, for a planar structure): */
    double twist;  /* rad, right-handed about e1: turns (e2, e3) to the principal axes */
    double e3[3];  /* a direction for e3 (hub frame, any length, not along the member), or all
                      zero for the default of DESIGN.md 7.1 (the part of the hub axis z normal to
                      e1; for a member along z, the part of the radial direction) */
    /* spatial only, DESIGN.md 8: n_stations 0 (none: the section is uniform) or >= 2 stations,
     * s strictly increasing from 0 to 1; station_mask the sm_station_field bits they give */
    int n_stations;
    const sm_station *stations;
    unsigned station_mask;
} sm_member;

/** A point mass attached to a joint (adds to the lumped/consistent mass). */
typedef struct sm_point_mass {
    int joint;     /* joint index */
    double mass;   /* kg, >= 0 */
    double inertia[3]; /* spatial only: rotary inertia about the hub axes x, y, z through the
                          centre of mass, kg m^2, >= 0 (planar: must be zero) */
    double products[3]; /* spatial only: products of inertia Ixy, Iyz, Izx (the tensor's
                           off-diagonal entries, hub axes), kg m^2; the tensor must be positive
                           semi-definite */
    double offset[3];   /* spatial only: centre of mass from the joint, hub frame at rest, m; it
                           turns with the joint's node */
} sm_point_mass;

/** An elastic support (issue 25, DESIGN.md 8.6): a point support at a joint, or a foundation
 *  (distributed springs and added mass) along a stretch of a member.  A support acts on the
 *  motion of FE nodes from rest — translation and small rotation, hub axes — through the
 *  nodes' motion at rest: its matrices in modal coordinates are J0' k J0 and J0' m J0, J0 the
 *  nodes' Jacobian at q = 0, built once with the model.  That is exact for a structure that
 *  does not spin (its steady state is rest); at speed it is the support linearised at rest,
 *  exact to first order in the support's steady deflection and rotation.  Added mass adds
 *  inertia only (no centrifugal or gyroscopic terms: it is a surrounding fluid's, not the
 *  structure's mass; a mass that spins is an sm_point_mass).  A foundation is lumped onto the
 *  nodes of the stretch (each node takes its tributary length, per element with that element's
 *  axes).  Planar models use the x, y and rz rows and columns, a foundation's lateral p2
 *  stiffness (the in-plane normal) and its axial one. */
typedef struct sm_support {
    int joint;    /* point support: joint index; -1 for a foundation */
    double K[36]; /* point: stiffness 6x6, column-major over (x, y, z, rx, ry, rz) in hub axes:
                     N/m, N/rad, N m/rad; symmetric (1e-9 relative), positive semi-definite */
    double M[36]; /* point: added mass 6x6, same layout: kg, kg m, kg m^2; symmetric, positive
                     semi-definite */
    int member;   /* foundation: member index; -1 for a point support */
    double from_s, to_s;    /* foundation: the stretch, m from the member's `from` joint along it,
                               0 <= from_s < to_s <= member length */
    double k_per_length[4]; /* foundation: axial, lateral p2 (edgewise), lateral p3 (flapwise),
                               torsion, member axes at rest: N/m per m (N/m^2) and N m/rad per m,
                               >= 0 */
    double
        added_mass_per_length; /* foundation: added mass in both lateral directions, kg/m, >= 0 */
} sm_support;

/** The structure.  Arrays are borrowed; sm_model_new copies what it needs. */
typedef struct sm_structure {
    int n_joints;
    const double *joint_xy;          /* 2*n_joints, hub frame, m */
    int n_sections;
    const sm_section *sections;      /* n_sections */
    int n_members;
    const sm_member *members;        /* n_members */
    int n_point_masses;
    const sm_point_mass *point_masses; /* n_point_masses, may be NULL if 0 */
    int clamp;                       /* joint index rigidly attached to the hub */
    /* 0: planar (DESIGN.md 1; joint_z must be NULL or all zero); 1: spatial (DESIGN.md 7:
     * 6 DOF per node, the spatial section data, twist, e3 and point-mass inertia) */
    int spatial;
    const double *joint_z;           /* n_joints z coordinates (m) or NULL (all zero) */
    int n_supports;                  /* elastic supports (sm_support), 0 for none */
    const sm_support *supports;      /* n_supports, may be NULL if 0 */
    /* 1: the clamp joint is not held by the hub but rests on the point supports at it (an elastic
     * clamp, a floating platform: their 6x6 stiffness and mass about the clamp joint, hub axes),
     * six more coordinates (its translation and rotation) ahead of the modal ones (DESIGN.md
     * 8.6).  Spatial structures, analysed at rest (speeds 0) only. */
    int base_free;
    /* with base_free: the directions the base is held in, bits 0..5 = x, y, z, rx, ry, rz (hub
     * axes; e.g. BModes' hub_conn 3 holds a tower's heave and yaw); 0: free in all six */
    unsigned base_held;
    /* the acceleration of gravity, m/s^2, hub frame (e.g. {0, -9.80665, 0} for a tower whose up
     * is hub y), a steady load on the structure at rest: the steady state under its own weight
     * and the linearisation there (DESIGN.md 8.8); all zero: none.  Spatial structures, speeds 0
     * only, not with a free base. */
    double gravity[3];
} sm_structure;

typedef enum sm_frame_scheme {
    SM_FRAMES_SINGLE = 0,            /* one frame for the whole structure */
    SM_FRAMES_PER_MEMBER,            /* frames_param runs per member */
    SM_FRAMES_ELEMENTS_PER_FRAME,    /* runs of frames_param elements */
    SM_FRAMES_PER_ELEMENT            /* one frame per element */
} sm_frame_scheme;

typedef enum sm_mass_model {
    SM_MASS_LUMPED = 0,              /* mu*(l_left+l_right)/2 per node, no rotary inertia */
    SM_MASS_CONSISTENT               /* consistent beam mass (extension) */
} sm_mass_model;

typedef enum sm_basis {
    SM_BASIS_AUGMENTED = 0,          /* paper basis + attachment rotations (default) */
    SM_BASIS_PAPER                   /* Kim & Yoo's condensed component modes */
} sm_basis;

/** Which mass moments of a spatial section act in M*, C* (sm_options.rotary_inertia, DESIGN.md
 *  8.5).  FULL: i_flap, i_edge are bending rotary inertia of the lumped nodes and their sum the
 *  torsional inertia.  TORSION: the torsional mass moment only, as BModes (Struct.f90:1222,
 *  1302).  Either way the centrifugal potential keeps the whole section tensor (the propeller
 *  moment of torsion, BModes' too), point masses and centre-of-mass offsets keep their inertia,
 *  and consistent mass is unchanged (its M* has torsion only already); planar models have none. */
typedef enum sm_rotary_inertia {
    SM_ROTARY_FULL = 0, /* default */
    SM_ROTARY_TORSION   /* torsional mass moment only */
} sm_rotary_inertia;

/** Most engine orders one solve looks for (sm_options.engine_orders, DESIGN.md 9.1). */
#define SM_MAX_ENGINE_ORDERS 16

/** Default of sm_options.max_dense_coordinates (the daemon's --max-coordinates default): one
 * dense eigen-analysis with Coriolis at 1000 coordinates is ~5.6 s and ~200 MB (issue 23: 4000
 * was 100 s to 6 min and 2.3 GB a speed). */
#define SM_DENSE_MAX_DEFAULT 1000

/** Most modes the structured (tree) eigen-analysis is asked for: its Krylov basis is at most 240
 * vectors, about 3.5 a mode; more modes take the dense path (issue 23). */
#define SM_TREE_MAX_MODES 64

/** Estimated seconds of one speed on the dense path of n coordinates on one core, at the low end
 * (few modes: 12 ms at 191 coordinates with Coriolis; with n/8 modes 1.0 s at 600 and 9.6 s at
 * 1200, a sixth of that without Coriolis): what the daemon's request check weighs against its job
 * time limit, refusing only what surely runs past it. */
double sm_dense_seconds(int n, int coriolis);

/** Analysis options; fill with sm_default_options first. */
typedef struct sm_options {
    sm_frame_scheme frames;          /* default SM_FRAMES_PER_ELEMENT */
    int frames_param;                /* k for PER_MEMBER, n for ELEMENTS_PER_FRAME */
    sm_mass_model mass;              /* default lumped */
    sm_basis basis;                  /* default augmented */
    sm_rotary_inertia rotary_inertia; /* default SM_ROTARY_FULL (spatial sections only) */
    int modes_per_frame;             /* 0 = all component modes */
    int modes;                       /* number of modes reported, default 3 */
    int geometric_stiffening;        /* default 1 */
    int coriolis;                    /* default 1 */
    int mode_shapes;                 /* default 1: fill shape_re/shape_im */
    /* Newton-Raphson / continuation */
    int min_increments;              /* increments in Omega^2 from rest, default 5 */
    int max_iterations;              /* Newton iterations per increment, default 40 */
    double tolerance;                /* ||dq|| <= tol*max(1,||q||), default 1e-10 */
    /* Linear algebra (not part of the JSON request; results do not depend on it beyond
     * round-off): SM_SOLVER_AUTO (default) picks by size; the others force a path (tests,
     * benchmarks).  SM_SOLVER_DENSE also keeps every frame's component modes on the dense
     * complete eigen-solve (AUTO and TREE take the few kept modes of a large frame, D >= 200
     * DOF and modes_per_frame <= D/8, by sparse subspace iteration: core/lowmodes.c). */
    int solver;                      /* sm_solver */
    /* The tree path hands an unstable steady state (K* not positive definite) or a stalled
     * iteration to the dense eigen-analysis only up to this many coordinates (its cost is ~n^3
     * time, ~10 n^2 doubles of memory); beyond, the case ends eigen_failed with the number of
     * negative eigenvalues of K*.  0: SM_DENSE_MAX_DEFAULT. */
    int max_dense_coordinates;
    /* Threads a sweep may use (not part of the JSON request; the results are the same bits on
     * any number): the continuation stays on the calling thread, and each speed's
     * linearisation, eigen-analysis and shapes run on up to threads - 1 workers beside it
     * (DESIGN.md 2.1).  0 or 1 (default): the calling thread only. */
    int threads;
    /* DESIGN.md 9.1: engine orders n > 0 (finite, at most SM_MAX_ENGINE_ORDERS) whose critical
     * speeds (w(Omega) = n Omega along each tracked mode) sm_solve finds in a sweep; 0: none */
    int n_engine_orders;
    double engine_orders[SM_MAX_ENGINE_ORDERS];
} sm_options;

/** Linear-algebra path of a solve (sm_options.solver). */
typedef enum sm_solver {
    SM_SOLVER_AUTO = 0,              /* dense for small models, tree-structured for large ones */
    SM_SOLVER_DENSE,                 /* dense matrices in the modal coordinates, LAPACK */
    SM_SOLVER_TREE                   /* block recursion along the frame tree + shift-invert Krylov */
} sm_solver;

/** Fill *o with the defaults of DESIGN.md section 3. */
void sm_default_options(sm_options *o);

/* ----------------------------------------------------------- diagnostics */

/** Which input item an INVALID_INPUT error refers to. */
typedef enum sm_item {
    SM_ITEM_NONE = 0,
    SM_ITEM_JOINT,
    SM_ITEM_SECTION,
    SM_ITEM_MEMBER,
    SM_ITEM_POINT_MASS,
    SM_ITEM_CLAMP,
    SM_ITEM_OPTIONS,
    SM_ITEM_SUPPORT
} sm_item;

/** Optional diagnostics out-parameter (like jansson's json_error_t). */
typedef struct sm_diag {
    int status;            /* sm_status of the failure */
    sm_item item;          /* offending input item, for INVALID_INPUT */
    int item_index;        /* its index (member, joint, ...) or -1 */
    char field[32];        /* offending field name ("to", "elements", "E"...) or "" */
    int iterations;        /* Newton iterations spent (equilibrium failures) */
    double residual;       /* last residual norm */
    double last_omega;     /* last speed with a converged equilibrium */
    char message[256];     /* a sentence for a user */
} sm_diag;

/* ---------------------------------------------------------------- model */

typedef struct sm_model sm_model;   /* opaque, immutable after sm_model_new */

/**
 * Build the FE mesh, the substructures (frames) and their component-mode
 * bases.  *out receives a new model owned by the caller (sm_model_free).
 * Returns SM_OK, SM_INVALID_INPUT (diag names the item: cycle, disconnected
 * member, zero-length member, non-positive property, bad index), SM_NOMEM,
 * SM_SINGULAR or SM_LAPACK_FAILED.  diag may be NULL.
 */
int sm_model_new(sm_model **out, const sm_structure *st, const sm_options *opt,
                 sm_diag *diag);

/** Free a model; NULL is a no-op. */
void sm_model_free(sm_model *m);

/** Sizes of a model, as reported in the result's "model" object. */
typedef struct sm_model_info {
    int nodes;          /* FE nodes, clamp node included */
    int elements;       /* FE elements */
    int frames;         /* substructures (reference frames) */
    int coordinates;    /* modal coordinates n */
    int max_frame_coordinates; /* largest number of modal coordinates of one substructure */
    int max_frame_nodes; /* largest number of FE nodes in one substructure (its component-mode
                            problem has ~3x that many DOF); free nodes: the frame's root node,
                            clamped in its basis, is not counted, so the DOF are exactly 3x */
    int spatial;        /* 1 for a spatial model (6 DOF per node), 0 planar */
    int node_dof;       /* values per node in nodes and mode shapes: 3 planar, 6 spatial */
    int structured;     /* 1 when the solves take the tree-structured path (cost ~ linear in
                           the size; sm_options.solver, or the automatic choice: at least 200
                           coordinates, frames of at most 40, 8 x modes <= coordinates and at
                           most SM_TREE_MAX_MODES modes), 0 for the dense path (cost ~
                           coordinates^3) */
} sm_model_info;

/** Sizes of the model m (borrowed) into *info. */
void sm_model_get_info(const sm_model *m, sm_model_info *info);

/** Check a structure and options the way sm_model_new does, without building the
 *  component-mode bases (cost linear in the size): numbers, indices, topology (a tree rooted
 *  at the clamp: cycles, disconnected members, joints on no member) and the sizes the model
 *  would have.  Fills *info (may be NULL).  Returns SM_OK, SM_INVALID_INPUT (diag exactly as
 *  sm_model_new would fill it for the same input) or SM_NOMEM. diag may be NULL.
 *  opt NULL means the defaults, as for sm_model_new.  SM_OK does not promise that
 *  sm_model_new succeeds: its component-mode solves may still fail (SM_SINGULAR,
 *  SM_LAPACK_FAILED) or run out of memory. */
int sm_structure_check(const sm_structure *st, const sm_options *opt, sm_model_info *info, sm_diag *diag);

/** FE node index of joint j (joints are FE nodes), or -1 if out of range. */
int sm_model_joint_node(const sm_model *m, int joint);

/** Member index that FE element e belongs to, or -1 if out of range. */
int sm_model_element_member(const sm_model *m, int element);

/** Undeformed position of FE node k: xy[0], xy[1]. Returns SM_OK or SM_INVALID_INPUT. */
int sm_model_node_position(const sm_model *m, int node, double xy[2]);

/** Undeformed position of FE node k in 3D: xyz[0..2] (z = 0 for a planar model). */
int sm_model_node_position3(const sm_model *m, int node, double xyz[3]);

/** Principal axes of FE node k at rest (hub frame): the columns of axes (column-major 3x3) are
 *  e1 (along the member, from -> to), p2 (edgewise) and p3 (flapwise) with the structural twist
 *  interpolated at the node; for a joint, those of the first member that reaches it.  *member and
 *  *s (either may be NULL) receive that member and the node's span fraction on it.  Spatial models
 *  only.  Returns SM_OK or SM_INVALID_INPUT (planar model, k out of range). */
int sm_model_node_axes(const sm_model *m, int node, double axes[9], int *member, double *s);

/** The FE nodes of member i from its `from` joint (s = 0) to its `to` joint (s = 1): up to cap
 *  node indices into nodes, their span fractions into s and the member's structural twist at
 *  each (rad, about e1 from the axes of sm_model_member_axes; the stations' twist interpolated)
 *  into twist.  Returns the number of nodes, elements + 1 (filled only when cap is at least
 *  that: call with cap 0 to size the arrays), or SM_INVALID_INPUT (planar model, no such
 *  member). */
int sm_model_member_nodes(const sm_model *m, int member, int cap, int *nodes, double *s,
                          double *twist);

/** The axes of member i without twist (hub frame, column-major 3x3): e1 from `from` to `to`,
 *  e3 its flap_direction made normal to e1 (DESIGN.md 7.1), e2 = e3 x e1 (edgewise; for a
 *  blade, in the rotor plane).  SM_OK or SM_INVALID_INPUT (planar model, no such member). */
int sm_model_member_axes(const sm_model *m, int member, double axes[9]);

/* ---------------------------------------------------------------- solve */

/**
 * Progress/cancel callback: called after each Newton iteration and after each
 * speed with done = speeds finished, total = speeds requested.  Return
 * nonzero to cancel; sm_solve then returns SM_CANCELED.  Called from the
 * thread running sm_solve.
 */
typedef int (*sm_progress_fn)(void *user, int done, int total);

/**
 * sm_model_new that can be stopped: cb (may be NULL) is called with user
 * before each substructure's component modes after the first, with done =
 * substructures built and total = all of them; a nonzero return stops the
 * build and returns SM_CANCELED (*out NULL, diag says how far it got).  The
 * cost of one substructure is ~D^3 for its D = 3 (spatial 6) x free nodes DOF
 * when it keeps all or many of its modes, ~D when it keeps few of a large
 * frame (the sparse path), so this bounds how long a cancel, a time limit or
 * a shutdown waits.  Other returns as sm_model_new.
 */
int sm_model_build(sm_model **out, const sm_structure *st, const sm_options *opt,
                   sm_progress_fn cb, void *user, sm_diag *diag);

typedef enum sm_case_status {
    SM_CASE_SOLVED = 0,       /* equilibrium found, steady state stable */
    SM_CASE_UNSTABLE,         /* equilibrium found, K* has negative eigenvalues or Re(lambda) > 0 */
    SM_CASE_NO_EQUILIBRIUM,   /* continuation/Newton failed: see diagnostics */
    SM_CASE_EIGEN_FAILED      /* equilibrium found (converged = 1, its fields filled), but the
                                 eigen-analysis failed: message says why; no modes, and the
                                 stability fields are 0 (unknown) */
} sm_case_status;

/* Inside a frame the kinematics are linear (small rotations).  An
 * equilibrium whose nodes turn more than this relative to their own frame is
 * reported with a warning: its numbers describe the model, not the structure
 * (use more frames). */
#define SM_FRAME_ROTATION_LIMIT 1.0

/** Result of one speed.  Arrays are owned by the sm_result. */
typedef struct sm_case {
    double omega;             /* rad/s */
    sm_case_status status;
    /* equilibrium */
    int converged;            /* 1 when Newton converged at omega */
    int iterations;           /* Newton iterations spent for this speed */
    double residual;          /* ||F(q*)|| */
    double last_omega;        /* last speed reached (== omega when converged) */
    char message[256];        /* diagnostics sentence ("" when solved) */
    int n_nodes;
    int node_dof;             /* values per node in nodes and shapes: 3 planar, 6 spatial */
    double *nodes;            /* node_dof*n_nodes: planar x, y, phi (rad); spatial x, y, z and
                                 the rotation vector rx, ry, rz (rad, hub frame) of the node's
                                 triad from its undeformed orientation */
    int n_elements;
    double *axial_force;      /* n_elements: P_e, N (eq. 24) */
    double max_frame_rotation; /* rad: largest rotation of a node relative to its own frame */
    char warning[256];        /* "" or why the state is outside the model's validity (still reported) */
    /* stability */
    int stable;
    int negative_eigenvalues; /* of K* */
    double max_real_part;     /* max Re(lambda) over computed roots */
    /* modes (0 when no equilibrium) */
    int n_modes;
    double *frequency;        /* n_modes: |Im lambda|, rad/s */
    double *eig_re;           /* n_modes */
    double *eig_im;           /* n_modes */
    double *mac_to_previous;  /* n_modes: MAC to the tracked mode of the previous speed, -1 for the first speed */
    int *previous_index;      /* n_modes: index of that mode at the previous speed, -1 if none */
    double *shape_re;         /* n_modes * node_dof*n_nodes (planar dx,dy,dphi; spatial dx,dy,dz,
                                 rx,ry,rz per node, hub frame), or NULL */
    double *shape_im;         /* same, NULL without Coriolis or mode shapes */
    /* timing, ms */
    double t_equilibrium, t_linearize, t_eigen;
    int dense_fallback;       /* 1 when the structured (tree) eigen-analysis gave way to the dense
                                 one at this speed (K* indefinite or singular, no convergence) */
    /* error estimate (sm_estimate; NULL until it ran): n_modes each, NaN where none */
    double *error_estimate;   /* estimated |frequency - converged beam-model frequency|, rad/s */
    double *error_order;      /* convergence order used: observed, or SM_ESTIMATE_ORDER */
    /* DESIGN.md 9.1 (trust), each n_modes long, NULL when the case has no modes: */
    double *energy;           /* n_modes * SM_ENERGY_PARTS fractions: kinetic (axial, edge, flap,
                                 torsion) then strain (same order); each four sum to 1.  Planar:
                                 the edge slot holds the in-plane bending, flap and torsion are 0 */
    int *label_kind;          /* sm_mode_kind, from the strain fractions (dominant part > 60 %,
                                 else SM_MODE_COUPLED) */
    int *label_ordinal;       /* 1-based count among the modes of the same kind of this case in
                                 ascending frequency; 0 for SM_MODE_COUPLED */
    double *label_confidence; /* the dominant strain fraction */
    double *support_share;    /* n_modes: the elastic supports' share of the mode's strain energy
                                 (their springs over springs + members; DESIGN.md 8.7), NULL for a
                                 model without supports; the members' fractions in energy and
                                 the label stay the members' own */
    int *tracked_index;       /* the Campbell line (tracked mode) this mode belongs to, 0-based */
    int *track_flag;          /* 0, SM_TRACK_CROSSING or SM_TRACK_VEERING */
    int *track_partner;       /* tracked index of the other mode of the flagged pair, or -1 */
} sm_case;

/** Values per mode in sm_case.energy: kinetic axial, edge, flap, torsion, then strain. */
#define SM_ENERGY_PARTS 8

/** Kind of a mode (sm_case.label_kind, DESIGN.md 9.1). */
typedef enum sm_mode_kind {
    SM_MODE_AXIAL = 0, /* axial (stretching) */
    SM_MODE_EDGE,      /* edgewise: bending in the p2 direction (in-plane for a blade) */
    SM_MODE_FLAP,      /* flapwise: bending in the p3 direction (out of plane) */
    SM_MODE_TORSION,   /* torsion about the member axis */
    SM_MODE_COUPLED,   /* no part above 60 % of the strain energy */
    SM_MODE_BENDING,   /* planar models: in-plane bending */
    SM_MODE_RIGID      /* a rigid-body mode (frequency 0) of a free base (DESIGN.md 8.7) */
} sm_mode_kind;

/** Flags of sm_case.track_flag (DESIGN.md 9.1). */
enum sm_track_flag {
    SM_TRACK_CROSSING = 1,    /* two tracked modes swapped order since the previous speed, each
                                 keeping its shape (MAC >= 0.9): a true crossing */
    SM_TRACK_VEERING = 2      /* two tracked modes came close and exchanged shape: a veering */
};

/** A critical speed (DESIGN.md 9.1): a tracked mode meets an engine order, w(Omega) = n Omega. */
typedef struct sm_critical {
    double order;             /* engine order n */
    int tracked_index;        /* the tracked mode (sm_case.tracked_index) */
    double omega;             /* rad/s: refined speed (the interpolated one when refined == 0) */
    double omega_interpolated; /* rad/s: linear interpolation of w - n Omega between the sweep
                                  speeds omega_below and omega_above */
    double omega_below, omega_above; /* the bracketing speeds of the sweep, rad/s */
    double frequency;         /* rad/s: the mode's frequency at omega */
    int refined;              /* 1: solves at single speeds converged on w = n Omega */
    int iterations;           /* single-speed solves spent refining */
    double residual;          /* |w(omega) - n omega| / (n omega) of the last refining solve, or
                                 of the interpolation when refined == 0 */
    int label_kind, label_ordinal; /* the mode's label at omega (or at the nearer sweep speed) */
    double label_confidence;
} sm_critical;

/** A divergence speed: between two speeds of a sweep the count of negative eigenvalues of K*
 *  changes, the lowest eigenvalue of K* passing through zero (a static instability). */
typedef struct sm_divergence {
    double omega;             /* rad/s: where that eigenvalue is zero (refined by regula falsi on
                                 single-speed solves; interpolated or the bracket's middle when
                                 refined == 0) */
    double omega_interpolated; /* rad/s: linear interpolation between the bracketing speeds */
    double omega_below, omega_above; /* the bracketing speeds of the sweep, rad/s */
    int onset;                /* 1: stability lost with rising speed (more negative eigenvalues
                                 above), 0: regained */
    int negative_below, negative_above; /* negative eigenvalues of K* at the two speeds */
    int refined;              /* 1: |d omega| <= 1e-6 omega */
    int iterations;           /* single-speed solves spent */
    int label_kind, label_ordinal; /* the softening mode: the lowest root on the stable side */
} sm_divergence;

typedef struct sm_result {
    int n_cases;
    sm_case *cases;           /* n_cases, in the order of the requested speeds */
    int n_critical;           /* DESIGN.md 9.1: critical speeds found (engine orders given) */
    sm_critical *critical;    /* n_critical, by order then speed, or NULL */
    int n_divergence;         /* divergence speeds found in the sweep */
    sm_divergence *divergence; /* n_divergence, ascending, or NULL */
    int refine_stopped;       /* 1 when cb asked to stop after every speed was solved: the
                                 critical and divergence speeds were not (all) refined, and
                                 those lists may be incomplete; the cases are whole */
} sm_result;

/** The text of a label: "1st flap", "2nd edge", "3rd torsion", "1st axial", "1st bending",
 *  "coupled" into buf (size bytes, always terminated).  Returns buf. */
char *sm_mode_label(int kind, int ordinal, char *buf, size_t size);

/** The name of a kind ("axial", "edge", "flap", "torsion", "coupled", "bending"); never NULL. */
const char *sm_mode_kind_name(int kind);

/**
 * Solve at each speed of omegas (rad/s, finite, >= 0 in any order: they are
 * processed in ascending order with continuation, reported in input order).
 * A speed without equilibrium is a reported case (SM_CASE_NO_EQUILIBRIUM),
 * not an error; continuation restarts from rest for the next speed.  An
 * eigen-analysis that fails at a converged equilibrium is a reported case too
 * (SM_CASE_EIGEN_FAILED); continuation goes on from that equilibrium.
 * Returns SM_OK (every case has a status), SM_CANCELED, SM_NOMEM,
 * SM_INVALID_INPUT (bad speeds) or SM_LAPACK_FAILED.  *out is set only on
 * SM_OK and is owned by the caller (sm_result_free).  cb and diag may be NULL.
 * A stop asked by cb once every speed is solved never discards them: the
 * result is SM_OK with refine_stopped set (issue 23).
 */
int sm_solve(const sm_model *m, const double *omegas, int n_omegas,
             sm_progress_fn cb, void *user, sm_result **out, sm_diag *diag);

/** Free a result; NULL is a no-op. */
void sm_result_free(sm_result *r);

/* ------------------------------------------------------- error estimate */

/** Theoretical order of the frequency error in the element length h (lumped mass, linear axial
 *  and torsion shape functions, frame kinematics: all O(h^2)); used when no order is observed. */
#define SM_ESTIMATE_ORDER 2.0

/** Settings of sm_estimate; fill with sm_estimate_default_options first. */
typedef struct sm_estimate_options {
    int levels;          /* refined levels to solve: 2 (h/2 and h/4: observed order, default) or
                            1 (h/2: SM_ESTIMATE_ORDER); fewer when the limits below say so */
    int max_elements;    /* a refined model may have at most this many FE elements; 0 = no cap */
    int max_coordinates; /* ... this many modal coordinates when solved on the dense path
                            (sm_model_info.structured == 0); 0 = no cap */
    int max_frame_dofs;  /* ... this many DOF in one frame's component-mode problem (3 per free
                            node planar, 6 spatial); 0 = no cap */
    double min_mac;      /* modes of two levels match only with a MAC at least this, default 0.5 */
} sm_estimate_options;

/** Fill *o with the defaults listed in sm_estimate_options (no caps). */
void sm_estimate_default_options(sm_estimate_options *o);

/**
 * The discretisation of refinement level `level` (0 = as given, 1 = h/2, 2 = h/4) of st/opt
 * (DESIGN.md 9): every member's elements x 2^level; frames {"per_member": k} become
 * k x 2^level, "per_element" and {"elements_per_frame": n} keep their rule (so the frames
 * double with the elements), "single" stays one frame.  members (st->n_members entries,
 * the caller's) receives the refined members; *st_out points into it and st's other arrays
 * (borrowed).  *opt_out is opt.  Returns SM_OK, SM_INVALID_INPUT (level outside 0..2) or
 * SM_LIMIT (a member would pass INT_MAX/4 elements).
 */
int sm_estimate_refine(const sm_structure *st, const sm_options *opt, int level,
                       sm_member *members, sm_structure *st_out, sm_options *opt_out);

/**
 * How many refined levels of st/opt sm_estimate would solve: the largest L <= est->levels
 * whose level-L model passes est's caps (sm_structure_check sizes, no model is built) into
 * *levels, the sizes of that finest model into *finest (may be NULL).  L = 0 (none fits)
 * returns SM_LIMIT with diag->message naming the cap and the size; the paper basis
 * (which converges to a different answer as frames are added, DESIGN.md 1.2) returns
 * SM_INVALID_INPUT with diag->item SM_ITEM_OPTIONS, field "substructure_modes".  Other
 * returns as sm_structure_check.  diag may be NULL.
 */
int sm_estimate_plan(const sm_structure *st, const sm_options *opt,
                     const sm_estimate_options *est, int *levels, sm_model_info *finest,
                     sm_diag *diag);

/**
 * Error estimate of every frequency of res, the result of sm_solve(m, omegas, n) with m built
 * from st and opt (DESIGN.md 9): solves the refined levels of sm_estimate_plan at the same
 * speeds (with mode shapes, and more modes than asked so that reordered modes are found),
 * matches each mode level to level by MAC on the nodes of m (never by index), and
 * Richardson-extrapolates: with three levels and an observed ratio r = (f1 - f2)/(f0 - f1) in
 * (0, 2^-1/2] the order is -log2 r and the estimate |f0 - f1|/(1 - r); otherwise, or with two
 * levels, the order SM_ESTIMATE_ORDER (three levels that did not converge regularly:
 * max(|f0 - f1|, |f1 - f2|) with that order).  Fills each case's error_estimate and
 * error_order (allocated here, n_modes each; NaN for a mode that was not matched or a case
 * without modes at the base or first refined level).  If res's cases carry no mode shapes, m is solved
 * once more with shapes.  cb (may be NULL) is called as in sm_solve with done and total
 * counting speeds over all solves of the estimate; nonzero cancels (SM_CANCELED).  Returns
 * SM_OK, SM_LIMIT, SM_INVALID_INPUT (as sm_estimate_plan, or res not of n cases),
 * SM_CANCELED, SM_NOMEM, or a model-build or solve failure of a refined level (diag says
 * which).  res is modified only on SM_OK.  diag may be NULL.
 */
int sm_estimate(const sm_model *m, const sm_structure *st, const sm_options *opt,
                const double *omegas, int n_omegas, const sm_estimate_options *est,
                sm_progress_fn cb, void *user, sm_result *res, sm_diag *diag);

/* ------------------------------------------------ ElastoDyn mode shapes */

/** A fitted mode below this share of its bending strain energy in the selected direction is
 *  fitted with a warning (DESIGN §B). */
#define SM_ED_CLEAN 0.9

/** One ElastoDyn polynomial (DESIGN §B "ElastoDyn polynomial fit"): phi(x) = sum over
 *  k = 2..6 of coef[k-2] x^k, x from the flexible root (0) to the tip (1). */
typedef struct sm_ed_fit {
    int mode;       /* index of the fitted mode in its case; -1: no mode qualified */
    int direction;  /* 0: direction a (blade flap, tower fore-aft), 1: direction b */
    double coef[5]; /* C2..C6, C6 = 1 - (C2 + ... + C5): phi(0) = phi'(0) = 0, phi(1) = 1 */
    double tip;     /* the signed tip displacement the shape was divided by (input units) */
    double share;   /* the direction's share of the bending strain energy (NaN: none given) */
    int warning;    /* 1 when share < SM_ED_CLEAN */
    double rms, max_residual; /* residuals phi(x_j) - y_j/tip over the nodes (root included) */
    double tip_slope_fe;      /* d(y/tip)/dx at the tip from the FE rotations, NaN when not given */
    double tip_slope_fit;     /* phi'(1) = sum k C_k */
    double tip_slope_error;   /* (tip_slope_fit - tip_slope_fe) / |tip_slope_fe|, NaN when not
                                 given */
} sm_ed_fit;

/**
 * Fit one shape: y[0..n) at x[0..n) (x in [0, 1], the last node the tip, x = 1), tip_slope
 * dy/dx at the tip in the units of y per unit x (NaN: unknown).  Normalises by the signed
 * tip value y[n-1] and solves the unweighted least squares on the basis x^k - x^6 (k = 2..5)
 * with right-hand side y/tip - x^6.  fit->mode, direction, share and warning are left for
 * the caller (set to -1, 0, NaN, 0).  Returns SM_OK, SM_INVALID_INPUT (n < 4, x outside
 * [0, 1] or the last x not 1, a zero or non-finite tip value), SM_NOMEM or SM_LAPACK_FAILED.
 */
int sm_elastodyn_fit(int n, const double *x, const double *y, double tip_slope, sm_ed_fit *fit);

/** phi(x) of a fit's coefficients (C2..C6); *slope (may be NULL) receives phi'(x). */
double sm_elastodyn_eval(const double coef[5], double x, double *slope);

/** The modes of one case along one flexible member, projected on two bending directions a
 *  and b (blade: flap and edge in the principal axes; tower: fore-aft and side-side).
 *  All arrays borrowed. */
typedef struct sm_ed_shapes {
    int n_modes;            /* modes of the case, ascending frequency */
    int n_nodes;            /* nodes along the member, root first, >= 4 */
    const double *x;        /* n_nodes: distance from the flexible root / flexible length */
    const double *re;       /* n_modes * 2 * n_nodes: mode k, direction d, node j at
                               re[(2k + d) n_nodes + j] (displacement) */
    const double *im;       /* the same imaginary parts (Coriolis), or NULL */
    const double *slope_re; /* n_modes * 2: d(displacement)/dx at the tip, [2k + d], or NULL */
    const double *slope_im; /* the same imaginary parts, or NULL */
    const double *energy;   /* n_modes * SM_ENERGY_PARTS (sm_case.energy) */
    int part[2];            /* the energy slot (SM_MODE_EDGE or SM_MODE_FLAP) of a and b */
} sm_ed_shapes;

/**
 * Select and fit (DESIGN §B): fits[0 .. want[0]) are the want[0] lowest modes whose kinetic
 * energy in direction a exceeds that in b, fits[want[0] .. want[0] + want[1]) the want[1]
 * lowest with b above a; a mode whose kinetic bending (a + b) is below its axial plus
 * torsion is no candidate (torsion and axial modes are excluded by energy).  A complex mode
 * is turned so that its tip displacement is real: y = Re(z / z_tip) x |z_tip|.  A slot with
 * no qualifying mode has mode -1.  Returns SM_OK or the first failure of sm_elastodyn_fit
 * (SM_INVALID_INPUT also for want outside 0..8 or a bad part).
 */
int sm_elastodyn_fit_modes(const sm_ed_shapes *s, const int want[2], sm_ed_fit *fits);

/** Relative frequency gap below which two modes are a degenerate pair (DESIGN §B). */
#define SM_ED_DEGENERATE 1e-4

/**
 * Rotate degenerate pairs to pure directions before sm_elastodyn_fit_modes classifies them
 * (DESIGN §B: a symmetric tower's fore-aft and side-side modes share a frequency, and the
 * eigensolver returns any two orthogonal mixtures).  For each pair of consecutive modes k,
 * k + 1 with |freq[k+1] - freq[k]| < SM_ED_DEGENERATE freq[k+1]: the two combinations whose
 * tip displacement in direction b, resp. a, is zero replace them (mode k pure a, k + 1 pure
 * b), each scaled to a largest |displacement| of 1; their energy entries are made from the
 * new shapes' nodal displacements (kinetic and strain alike: the a and b parts in proportion
 * to the sums of squares, axial and torsion the smaller of the pair's).  s's arrays re, im,
 * slope_re, slope_im and energy are modified in place (the caller's buffers, cast from s).
 * Returns the number of pairs rotated.
 */
int sm_elastodyn_degenerate(sm_ed_shapes *s, const double *freq);

/**
 * Project one mode shape on a member's principal axes (DESIGN.md 9.3): rows[6 j .. 6 j + 6)
 * the displacement and small rotation (hub frame) of the member's node j (n nodes, root
 * first), ax the member's axes without twist [e1 | e2 | e3] (sm_model_member_axes),
 * twist[j] the structural twist there (rad about e1), length the member's length.  out[j]
 * receives the flap displacement p3.u and out[n + j] the edge displacement p2.u, with
 * p2 = cos t e2 + sin t e3, p3 = -sin t e2 + cos t e3; slope[0], slope[1] the tip slopes
 * d(flap)/dx = -L p2.r and d(edge)/dx = L p3.r per unit x = s (the twist rate times the
 * displacement left out).  All arrays borrowed.
 */
void sm_elastodyn_project(int n, const double ax[9], const double *twist, double length,
                          const double *rows, double *out, double slope[2]);

/** The blade's three ElastoDyn shapes, in this order in sm_elastodyn_blade's fits. */
enum { SM_ED_FLAP1, SM_ED_FLAP2, SM_ED_EDGE1, SM_ED_BLADE_FITS };

/**
 * BldFl1Sh, BldFl2Sh, BldEdgSh of case c (a case of sm_solve(m, ...) with mode shapes and
 * labels) along member `member` of the spatial model m, its `from` joint the flexible root:
 * each node's displacement projected on its principal axes (p3 flap, p2 edge: the member's
 * axes turned by the structural twist at the node, as ElastoDyn's shapes are), the tip
 * slopes from the rotations, then sm_elastodyn_fit_modes with want {2, 1}.  Returns SM_OK,
 * SM_INVALID_INPUT (planar model, no such member, a case without shapes or energies, fewer
 * than 4 nodes), SM_NOMEM or a failure of sm_elastodyn_fit.
 */
int sm_elastodyn_blade(const sm_model *m, const sm_case *c, int member,
                       sm_ed_fit fits[SM_ED_BLADE_FITS]);

/* ------------------------------------------------ MAC between two results (DESIGN.md 9.2) */

/**
 * One set of mode shapes sampled at points along the members of a structure, as read from a
 * result (its member nodes) or another program's table (BModes' span stations).  Points of
 * segment k (a member) are [seg_start[k], seg_start[k + 1]) in ascending span fraction s.
 */
typedef struct sm_mac_shapes {
    int n_modes;          /* modes in re / im */
    int n_points;         /* sample points per mode */
    int n_comp;           /* values per point, all compared (e.g. translations) */
    int n_segments;       /* members; 0 or 1 with seg_start NULL: one segment of all points */
    const int *seg_start; /* n_segments + 1 offsets into the points, or NULL */
    const double *s;      /* n_points span fractions, or NULL (then matching by index only) */
    const double *re;     /* n_modes * n_points * n_comp */
    const double *im;     /* same, or NULL for real shapes */
} sm_mac_shapes;

/** How sm_mac matched the points of the two sets. */
enum { SM_MAC_BY_INDEX = 0, SM_MAC_INTERPOLATED_A = 1, SM_MAC_INTERPOLATED_B = 2 };

/**
 * mac[i * b->n_modes + j] = |a_i^H b_j|^2 / (a_i^H a_i  b_j^H b_j) between mode i of a and
 * mode j of b.  Points match by index when the two sets have the same segments and points
 * (and the same s where both give s, to 1e-9); otherwise, per segment, the set with more
 * points is interpolated linearly in s at the other's points (*how says which), which needs
 * s on both sides, the same number of segments and the sampled points inside the other's
 * span.  A zero shape gives MAC 0.  Returns SM_OK, or SM_INVALID_INPUT with the reason in
 * why (different components, segments or node counts without s, no modes, bad s).
 */
int sm_mac(const sm_mac_shapes *a, const sm_mac_shapes *b, double *mac, int *how, char *why,
           size_t why_size);

#ifdef __cplusplus
}
#endif

#endif /* SPINMODAL_H */
