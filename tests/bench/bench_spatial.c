/*
 * bench_spatial.c — wall-clock benchmark of the spatial (3D) analysis beside the planar one
 * (issue 11).  Times sm_model_new + sm_solve from rest, median of repetitions, one process:
 *   (a)  planar: the beta = 90 deg angled beam, 24 + 24 lumped elements, per-element frames,
 *        augmented basis, Coriolis and stiffening, Omega = 20, 3 modes (bench_core case (a));
 *   (a3) the same mesh solved as spatial (EA, EI_edge = EI, EI_flap = EI, GJ, rotary inertia);
 *   (b1) a 3D blade (the R3 precone blade of reference/3d: hub radius 1 m, 10 m at 10 deg,
 *        per-element frames, Coriolis, 6 modes) with 48 elements at Omega = 10;
 *   (b21) the same blade, a 21-speed sweep 0..20 rad/s;
 *   growth: the blade with 48, 96, 192 elements at one speed, with the time split into
 *        equilibrium, linearisation and eigen-analysis (sm_case timings).
 * Not a test: ratios are what to read (the machines are shared and noisy).
 * Usage: bench_spatial [seconds per case, default 2]
 *        bench_spatial --growth ELEMENTS auto|dense|tree   one solve of the blade (W = 10, Coriolis,
 *        6 modes, no shapes) for tests/bench/growth.sh --spatial: "elements coordinates ms w1 w2 w3"
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "spinmodal.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

typedef struct timing {
    double median, eq, lin, eig; /* ms: whole run; split of the last speed of the first rep */
    double w[3];
    int n, solved, cases;
} timing;

/* Median time of model_new + solve over repetitions for `seconds`. */
static int run(const sm_structure *st, const sm_options *o, const double *om, int nom, double seconds, timing *t)
{
    double ts[200];
    int reps = 0;
    double total = 0;
    memset(t, 0, sizeof *t);
    while (reps < 200 && (reps < 3 || total < 1e3 * seconds)) {
        sm_model *m = NULL;
        sm_result *r = NULL;
        sm_diag d;
        double t0 = now_ms();
        if (sm_model_new(&m, st, o, &d) < 0 || sm_solve(m, om, nom, NULL, NULL, &r, &d) < 0) {
            fprintf(stderr, "bench_spatial: %s\n", d.message);
            sm_model_free(m);
            return 1;
        }
        ts[reps] = now_ms() - t0;
        total += ts[reps];
        if (reps == 0) {
            sm_model_info info;
            sm_model_get_info(m, &info);
            t->n = info.coordinates;
            t->cases = r->n_cases;
            for (int i = 0; i < r->n_cases; i++) {
                t->solved += r->cases[i].status == SM_CASE_SOLVED;
                t->eq += r->cases[i].t_equilibrium;
                t->lin += r->cases[i].t_linearize;
                t->eig += r->cases[i].t_eigen;
            }
            const sm_case *c = &r->cases[r->n_cases - 1];
            for (int i = 0; i < 3 && i < c->n_modes; i++)
                t->w[i] = c->frequency[i];
        }
        reps++;
        sm_result_free(r);
        sm_model_free(m);
    }
    qsort(ts, (size_t)reps, sizeof ts[0], cmp);
    t->median = reps % 2 ? ts[reps / 2] : 0.5 * (ts[reps / 2 - 1] + ts[reps / 2]);
    return 0;
}

static void show(const char *name, const timing *t)
{
    printf("%-44s n=%5d  median %9.2f ms  (equilibrium %8.2f, linearise %7.2f, eigen %7.2f ms)  %d/%d solved  "
           "w1..3 %.4f %.4f %.4f\n",
           name, t->n, t->median, t->eq, t->lin, t->eig, t->solved, t->cases, t->w[0], t->w[1], t->w[2]);
}

/* The precone blade with `ne` elements. */
static void blade(int ne, double *xy, double *z, sm_section *sec, sm_member *mem, sm_structure *st)
{
    double b = 10 * 3.14159265358979323846 / 180;
    xy[0] = 1, xy[1] = 0, xy[2] = 1 + 10 * cos(b), xy[3] = 0;
    z[0] = 0, z[1] = 10 * sin(b);
    memset(sec, 0, sizeof *sec);
    sec->EA = 8.4e7, sec->EI_flap = 2800, sec->EI_edge = 25200, sec->GJ = 3883, sec->mu = 3.0;
    sec->i_flap = 1e-4, sec->i_edge = 9e-4, sec->ip_over_a = 1e-3 / 3.0;
    memset(mem, 0, sizeof *mem);
    mem->from = 0, mem->to = 1, mem->elements = ne;
    memset(st, 0, sizeof *st);
    st->n_joints = 2, st->joint_xy = xy, st->joint_z = z, st->n_sections = 1, st->sections = sec;
    st->n_members = 1, st->members = mem, st->spatial = 1;
}

/* One solve of the blade with ne elements (growth.sh --spatial: one process per point). */
static int growth_one(int ne, int solver)
{
    double bxy[4], bz[2], w = 10.0;
    sm_section bs;
    sm_member bm;
    sm_structure bst;
    sm_options o;
    sm_model *m = NULL;
    sm_result *r = NULL;
    sm_diag d;
    blade(ne, bxy, bz, &bs, &bm, &bst);
    sm_default_options(&o);
    o.modes = 6;
    o.mode_shapes = 0;
    o.solver = solver;
    double t0 = now_ms();
    int rc = sm_model_new(&m, &bst, &o, &d);
    if (rc == SM_OK)
        rc = sm_solve(m, &w, 1, NULL, NULL, &r, &d);
    double ms = now_ms() - t0;
    if (rc < 0) {
        fprintf(stderr, "growth %d: %s: %s\n", ne, sm_strerror(rc), d.message);
    } else {
        sm_model_info info;
        sm_model_get_info(m, &info);
        printf("%d %d %.2f", ne, info.coordinates, ms);
        for (int i = 0; i < r->cases[0].n_modes && i < 3; i++)
            printf(" %.12g", r->cases[0].frequency[i]);
        printf("\n");
    }
    sm_result_free(r);
    sm_model_free(m);
    return rc < 0 ? 1 : 0;
}

int main(int argc, char **argv)
{
    if (argc == 4 && !strcmp(argv[1], "--growth")) {
        int solver = !strcmp(argv[3], "dense") ? SM_SOLVER_DENSE : !strcmp(argv[3], "tree") ? SM_SOLVER_TREE
                                                                                            : SM_SOLVER_AUTO;
        return growth_one(atoi(argv[2]), solver);
    }
    double sec_budget = argc > 1 ? atof(argv[1]) : 2.0;
    printf("spinmodal %s bench_spatial (OPENBLAS_NUM_THREADS=%s); time = sm_model_new + sm_solve from rest\n",
           sm_version(), getenv("OPENBLAS_NUM_THREADS") ? getenv("OPENBLAS_NUM_THREADS") : "unset");
    /* (a) planar and (a3) the same mesh as spatial */
    double xy[6] = {0, 0, 5, 0, 5, 5}, z3[3] = {0, 0, 0}, w20 = 20.0;
    sm_section sp;
    memset(&sp, 0, sizeof sp);
    sp.E = 7e10, sp.A = 4e-4, sp.I = 2e-7, sp.mu = 1.2;
    sm_member mem[2];
    memset(mem, 0, sizeof mem);
    mem[0].to = 1, mem[0].elements = 24, mem[1].from = 1, mem[1].to = 2, mem[1].elements = 24;
    sm_structure st;
    memset(&st, 0, sizeof st);
    st.n_joints = 3, st.joint_xy = xy, st.n_sections = 1, st.sections = &sp, st.n_members = 2, st.members = mem;
    sm_options o;
    sm_default_options(&o);
    timing ta, ta3, tb, ts;
    if (run(&st, &o, &w20, 1, sec_budget, &ta))
        return 1;
    show("(a)  planar angled beam 48 el, W=20", &ta);
    sp.EA = sp.E * sp.A, sp.EI_edge = sp.E * sp.I, sp.EI_flap = sp.E * sp.I, sp.GJ = 0.77 * sp.E * sp.I;
    sp.i_flap = sp.mu * sp.I / sp.A, sp.i_edge = sp.i_flap, sp.ip_over_a = 2 * sp.I / sp.A;
    st.spatial = 1, st.joint_z = z3;
    o.modes = 6; /* the 3 in-plane modes lie among the 6 lowest */
    if (run(&st, &o, &w20, 1, sec_budget, &ta3))
        return 1;
    show("(a3) same mesh as spatial, W=20, 6 modes", &ta3);
    /* (b) the blade */
    double bxy[4], bz[2], w10 = 10.0, sweep[21];
    sm_section bs;
    sm_member bm;
    sm_structure bst;
    blade(48, bxy, bz, &bs, &bm, &bst);
    if (run(&bst, &o, &w10, 1, sec_budget, &tb))
        return 1;
    show("(b1) 3D blade 48 el, W=10", &tb);
    for (int i = 0; i < 21; i++)
        sweep[i] = i;
    if (run(&bst, &o, sweep, 21, sec_budget, &ts))
        return 1;
    show("(b21) 3D blade 48 el, 21 speeds 0..20", &ts);
    printf("ratios: (a3)/(a) = %.2f (3D vs planar, same mesh); (b1)/(a) = %.2f; (b21)/(b1) = %.1f\n",
           ta3.median / ta.median, tb.median / ta.median, ts.median / tb.median);
    printf("growth of the 3D blade, one speed (W=10):\n");
    double prev = 0;
    for (int ne = 48; ne <= 192; ne *= 2) {
        timing tg;
        blade(ne, bxy, bz, &bs, &bm, &bst);
        if (run(&bst, &o, &w10, 1, sec_budget, &tg))
            return 1;
        char name[64];
        snprintf(name, sizeof name, "     blade %d el", ne);
        show(name, &tg);
        if (prev > 0)
            printf("     x%.1f for x2 elements\n", tg.median / prev);
        prev = tg.median;
    }
    return 0;
}
