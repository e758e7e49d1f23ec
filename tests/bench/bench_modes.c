/*
 * bench_modes.c — the model build of one large frame keeping few modes (issue 10): the dense
 * complete component-mode decomposition (sm_options.solver = SM_SOLVER_DENSE, the path of
 * every frame before core/solve/lowmodes.c) against the sparse path (the default), as ratios measured
 * in one run.
 *
 * One clamped cantilever in a single frame of D = 300, 600, 1200, 2400 DOF (planar: D/3
 * elements, 3 DOF per node; spatial: the precone blade with D/6 elements, 6 DOF per node),
 * modes_per_frame 8, lumped and consistent mass.  Each build runs in a child process (fork), so
 * that its peak resident memory (wait4's ru_maxrss) is its own; the time is the median of
 * repeated sm_model_new calls in that child (at least 3, or ~1 s).  Memory is reported above
 * the child's baseline (a build of a 2-element model).
 * Not a test: the machine is shared and noisy; read the ratios.
 * Usage: bench_modes [planar|spatial|all] [max D, default 2400]
 */
#define _DEFAULT_SOURCE /* wait4 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "spinmodal.h"

typedef struct frame_case {
    double xy[4], z[2];
    sm_section sec;
    sm_member mem;
    sm_structure st;
} frame_case;

/* A single-member cantilever of ne elements: planar (the paper's section, 10 m) or the spatial
 * precone blade (EI_flap != EI_edge, torsion, rotary inertia). */
static void frame_make(frame_case *f, int spatial, int ne)
{
    memset(f, 0, sizeof *f);
    f->mem.to = 1, f->mem.elements = ne;
    f->st.n_joints = 2, f->st.joint_xy = f->xy, f->st.n_sections = 1, f->st.sections = &f->sec;
    f->st.n_members = 1, f->st.members = &f->mem;
    if (!spatial) {
        f->xy[2] = 10.0;
        f->sec.E = 7e10, f->sec.A = 4e-4, f->sec.I = 2e-7, f->sec.mu = 1.2;
        return;
    }
    double b = 10 * 3.14159265358979323846 / 180;
    f->xy[0] = 1, f->xy[2] = 1 + 10 * cos(b), f->z[1] = 10 * sin(b);
    f->sec.EA = 8.4e7, f->sec.EI_flap = 2800, f->sec.EI_edge = 25200, f->sec.GJ = 3883, f->sec.mu = 3.0;
    f->sec.i_flap = 1e-4, f->sec.i_edge = 9e-4, f->sec.ip_over_a = 1e-3 / 3.0;
    f->st.joint_z = f->z, f->st.spatial = 1;
}

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

/* In the child: median build time (ms) of f under o, or -1. */
static double child_builds(const frame_case *f, const sm_options *o)
{
    double ts[64], total = 0;
    int reps = 0;
    while (reps < 64 && (reps < 3 || total < 1e3)) {
        sm_model *m = NULL;
        sm_diag d;
        double t0 = now_ms();
        if (sm_model_new(&m, &f->st, o, &d) < 0) {
            fprintf(stderr, "bench_modes: %s\n", d.message);
            return -1;
        }
        ts[reps] = now_ms() - t0;
        total += ts[reps++];
        sm_model_free(m);
    }
    qsort(ts, (size_t)reps, sizeof ts[0], cmp);
    return reps % 2 ? ts[reps / 2] : 0.5 * (ts[reps / 2 - 1] + ts[reps / 2]);
}

/* Build in a child: *ms its median time, *kb its peak resident memory (KiB).  0 or -1. */
static int measure(const frame_case *f, const sm_options *o, double *ms, long *kb)
{
    int fd[2];
    if (pipe(fd) != 0)
        return -1;
    fflush(stdout);
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        close(fd[0]);
        double t = child_builds(f, o);
        ssize_t w = write(fd[1], &t, sizeof t);
        _exit(w == (ssize_t)sizeof t && t >= 0 ? 0 : 1);
    }
    close(fd[1]);
    double t = -1;
    ssize_t r = read(fd[0], &t, sizeof t);
    close(fd[0]);
    int status = 0;
    struct rusage ru;
    if (wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0 ||
        r != (ssize_t)sizeof t)
        return -1;
    *ms = t;
    *kb = ru.ru_maxrss;
    return 0;
}

int main(int argc, char **argv)
{
    const char *which = argc > 1 ? argv[1] : "all";
    int max_d = argc > 2 ? atoi(argv[2]) : 2400;
    printf("spinmodal %s bench_modes (OPENBLAS_NUM_THREADS=%s): one frame, modes_per_frame 8, model build "
           "(sm_model_new) dense complete (old) vs sparse (new)\n",
           sm_version(), getenv("OPENBLAS_NUM_THREADS") ? getenv("OPENBLAS_NUM_THREADS") : "unset");
    frame_case f;
    sm_options o;
    double t0;
    long base = 0;
    sm_default_options(&o);
    frame_make(&f, 0, 2);
    if (measure(&f, &o, &t0, &base)) /* the child's baseline memory */
        return 1;
    printf("%-8s %-10s %5s %6s | %10s %10s %8s | %9s %9s %8s\n", "model", "mass", "D", "elems", "old ms",
           "new ms", "old/new", "old MiB", "new MiB", "old/new");
    for (int spatial = 0; spatial < 2; spatial++) {
        if ((spatial && !strcmp(which, "planar")) || (!spatial && !strcmp(which, "spatial")))
            continue;
        for (int mass = 0; mass < 2; mass++)
            for (int D = 300; D <= max_d; D *= 2) {
                int ne = spatial ? D / 6 : D / 3;
                double to, tn;
                long ko, kn;
                frame_make(&f, spatial, ne);
                sm_default_options(&o);
                o.frames = SM_FRAMES_SINGLE;
                o.mass = mass ? SM_MASS_CONSISTENT : SM_MASS_LUMPED;
                o.modes_per_frame = 8;
                sm_options od = o;
                od.solver = SM_SOLVER_DENSE;
                if (measure(&f, &od, &to, &ko) || measure(&f, &o, &tn, &kn)) {
                    fprintf(stderr, "bench_modes: a build failed (D %d)\n", D);
                    return 1;
                }
                double mo = (double)(ko - base) / 1024.0, mn = (double)(kn - base) / 1024.0;
                printf("%-8s %-10s %5d %6d | %10.1f %10.2f %8.1f | %9.1f %9.1f %8.1f\n", spatial ? "spatial" : "planar",
                       mass ? "consistent" : "lumped", D, ne, to, tn, to / tn, mo, mn, mn > 0.05 ? mo / mn : 0.0);
            }
    }
    printf("memory: peak resident above the baseline child (%.1f MiB)\n", (double)base / 1024.0);
    return 0;
}
