/*
 * import_bmodes.h — what the BModes importer's files share (not installed): the reader of one
 * file, what the .bmi says, the line readers (import_bmodes.c) and the tower's support lines
 * and their request parts (import_bmodes_support.c: guy wires, a platform or monopile).
 */
#ifndef SM_IMPORT_BMODES_H
#define SM_IMPORT_BMODES_H

#include "import_internal.h"

#define BM_MAX_ELEMENTS 10000 /* nselt */
#define BM_COLUMNS 13
#define BM_MAX_WIRES 16 /* n_attachments (BModes' comment line says at most 2) */

/* Reading one file of BModes. */
typedef struct bm_in {
    imp_reader r;
    const char *file;
    import_diag *d;
} bm_in;

/* What the .bmi says. */
typedef struct bm_main {
    char title[200];
    long beam_type, hub_conn, modepr, nselt;
    int hub_conn_line; /* line of hub_conn */
    double rot_rpm, rpm_mult, radius, hub_rad, precone, bl_thp;
    double rpm;         /* rot_rpm x rpm_mult, finite (checked where it is made) */
    int length_line;    /* line of hub_rad, which makes the length radius - hub_rad */
    double tip[9];      /* tip_mass, cm_loc, cm_axial, ixx, iyy, izz, ixy, izx, iyz */
    char sec_file[256]; /* as printed (ASCII) */
    char sec_raw[256];  /* as written, for the loader */
    int sec_line;       /* line of sec_props_file in the .bmi */
    double mult[10];    /* sec_mass .. tc_offst multipliers, file order */
    int tower;          /* beam_type 2 (DESIGN.md 8.5) */
    int speed_line;     /* line of rot_rpm */
    int beam_line;      /* line of beam_type */
    unsigned tw_zeroed; /* tower: columns (1 << column) the file gives and BModes overwrites */
    int tw_zeroed_line; /* the first line with one of them */
    long n_att;         /* tow_support 1: wire-attachment locations, 0 without */
    double wire[4][BM_MAX_WIRES]; /* n_wires, node_attach, wire_stfness, th_wire (deg) */
    int platform; /* tow_support 2: a platform (bm_platform), BModes' axes = tower axes */
    double draft, cm_pform, ref_msl; /* m below the MSL: tower base, platform c.m., ref. point */
    double pf[4][36]; /* mass (about the c.m.), hydro_M, hydro_K, mooring_K: row-major 6x6 */
    long n_distr[2];  /* n_secs_m_distr, n_secs_k_distr: read, unused by BModes v3.00 */
    double asym[4];   /* the largest |a_ij - a_ji| of each of pf before symmetrising it */
} bm_main;

/* ---- import_bmodes.c: reading a line of the .bmi (diagnostics name BModes' field) ---- */
/** The end of the file at field: a refusal naming it. */
int bm_ends(bm_in *b, const char *field);
/** A comment line (what: what it announces). */
int bm_com(bm_in *b, const char *what);
/** The first token of the next line into t. */
int bm_tok(bm_in *b, const char *field, imp_tok *t);
/** A number of the kind IMP_* into v. */
int bm_num(bm_in *b, const char *field, int kind, double *v);
/** An integer in [lo, hi] into v. */
int bm_int(bm_in *b, const char *field, long lo, long hi, long *v);
/** The JSON array of x[0..n) (new). */
json_t *bm_vec(const double *x, int n);

/* ---- import_bmodes_support.c: the tower's support (DESIGN.md 8.6) ---- */
/** The tower support lines after el_loc (tow_support 0, 1 wires, 2 a platform) into m. */
int bm_support(bm_in *b, bm_main *m);
/** tow_support 2 into doc's tower "platform" (with hub_conn 3 "held"); 0 or -1 (memory). */
int bm_tower_platform(json_t *doc, const bm_main *m);
/** tow_support 1 into doc's tower "wires" (own: BModes' own mesh, springs at its joints). */
int bm_tower_wires(json_t *doc, const bm_main *m, const json_t *el_loc, int own);

#endif
