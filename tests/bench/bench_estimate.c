/*
 * bench_estimate.c — the extra cost of the error estimate (issue 13, DESIGN.md 9.4): wall-clock
 * time of sm_model_new + sm_solve, and of the same plus sm_estimate (h/2 and h/4 solved), median
 * of repetitions, for
 *   (a) the planar beta = 90 deg angled beam, 24 + 24 lumped elements, per-element frames,
 *       Coriolis, Omega = 20, 3 modes (dense at h, tree-structured at h/2 and h/4);
 *   (b) a straight spatial blade (L = 31.623 m, mu = 100, EI_flap = 1e8), 12 elements, Omega = 12.
 * Not a test: the ratio is what to read (the machines are shared and noisy).  Measured while
 * the machine ran other test suites: (a) 91 ms -> 219 ms (x2.4), (b) 36 ms -> 333 ms (x9.3);
 * the 48-element spatial blade of bench_spatial costs 1.8 s + 6.5 s + 21.6 s (h, h/2, h/4).
 * Usage: bench_estimate [seconds per case, default 2]
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

/* Median ms of build + solve (+ estimate when est) over repetitions for `seconds`. */
static double run(const sm_structure *st, const sm_options *o, double omega, int est, double seconds)
{
    double ts[100], total = 0;
    int reps = 0;
    while (reps < 100 && (reps < 3 || total < 1e3 * seconds)) {
        sm_model *m = NULL;
        sm_result *r = NULL;
        sm_estimate_options eo;
        sm_diag d;
        double t0 = now_ms();
        sm_estimate_default_options(&eo);
        if (sm_model_new(&m, st, o, &d) < 0 || sm_solve(m, &omega, 1, NULL, NULL, &r, &d) < 0 ||
            (est && sm_estimate(m, st, o, &omega, 1, &eo, NULL, NULL, r, &d) < 0)) {
            fprintf(stderr, "bench_estimate: %s\n", d.message);
            sm_result_free(r);
            sm_model_free(m);
            return NAN;
        }
        ts[reps] = now_ms() - t0;
        total += ts[reps++];
        sm_result_free(r);
        sm_model_free(m);
    }
    qsort(ts, (size_t)reps, sizeof ts[0], cmp);
    return ts[reps / 2];
}

static void report(const char *name, const sm_structure *st, const sm_options *o, double omega,
                   double seconds)
{
    double a = run(st, o, omega, 0, seconds), b = run(st, o, omega, 1, seconds);
    printf("%-44s solve %9.2f ms   with error estimate %9.2f ms   x%.1f\n", name, a, b, b / a);
}

int main(int argc, char **argv)
{
    double seconds = argc > 1 ? atof(argv[1]) : 2.0;
    double xy[6] = {0, 0, 5, 0, 5, 5}, bxy[4] = {0, 0, 31.623, 0}, bz[2] = {0, 0};
    sm_section sec, bs;
    sm_member mem[2], bm;
    sm_structure st, bl;
    sm_options o;

    memset(&sec, 0, sizeof sec);
    sec.E = 7e10;
    sec.A = 4e-4;
    sec.I = 2e-7;
    sec.mu = 1.2;
    memset(mem, 0, sizeof mem);
    mem[0].from = 0, mem[0].to = 1, mem[0].elements = 24;
    mem[1].from = 1, mem[1].to = 2, mem[1].elements = 24;
    memset(&st, 0, sizeof st);
    st.n_joints = 3, st.joint_xy = xy, st.n_sections = 1, st.sections = &sec;
    st.n_members = 2, st.members = mem, st.clamp = 0;
    sm_default_options(&o);
    printf("spinmodal %s bench_estimate (median of repetitions, ~%g s per case)\n", sm_version(),
           seconds);
    report("(a) planar angled beam 24+24, W=20", &st, &o, 20.0, seconds);

    memset(&bs, 0, sizeof bs);
    bs.EA = 1e14, bs.EI_flap = 1e8, bs.EI_edge = 1e12, bs.GJ = 1e8, bs.mu = 100, bs.i_edge = 1e-3;
    bs.ip_over_a = 1e-5;
    memset(&bm, 0, sizeof bm);
    bm.from = 0, bm.to = 1, bm.elements = 12;
    memset(&bl, 0, sizeof bl);
    bl.n_joints = 2, bl.joint_xy = bxy, bl.joint_z = bz, bl.n_sections = 1, bl.sections = &bs;
    bl.n_members = 1, bl.members = &bm, bl.spatial = 1;
    report("(b) spatial blade 12 el, W=12", &bl, &o, 12.0, seconds);
    return 0;
}
