/*
 * bench_core.c — wall-clock benchmark of libspinmodal through its public API.
 *
 * Times sm_model_new + sm_solve (from rest, so continuation is included) for
 * the angled beam of Kim & Yoo (2006), beta = 90 deg: joints O(0,0), C(5,0),
 * P(5,5), two members of 24 elements, E = 7e10, A = 4e-4, I = 2e-7,
 * mu = 1.2, clamped at O.
 *   (a) Omega = 20, per-element frames, augmented basis, lumped, Coriolis and
 *       stiffening on, 3 modes, mode shapes on;
 *   (b) Omega = 20, {"per_member": 8} (RF 16), paper basis, Coriolis off —
 *       the RF 16 row of Table 2;
 *   (c) a sweep of 101 speeds 0..20 rad/s with the options of (a).
 * Each case is repeated (at least --min-reps times, then until --seconds of
 * run time or --max-reps); the median is reported beside a target and the
 * first three frequencies, with reference values, so that accuracy stays
 * visible beside speed.  Not a test: it never fails on time, only on an API
 * error (exit 1).  See tests/bench/run.sh.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "spinmodal.h"

#define BENCH_MAX_REPS 1000   /* hard cap on repetitions of one case */

/* One benchmark case: options, speeds, target and reference frequencies. */
typedef struct bench_case {
    const char *name;         /* label of the table row */
    sm_frame_scheme frames;   /* frame scheme */
    int frames_param;         /* k for per_member */
    sm_basis basis;           /* paper / augmented */
    int coriolis;             /* 1 = gyroscopic eigenproblem */
    int n_speeds;             /* 1 = Omega 20; >1 = sweep 0..20 */
    double target_ms;         /* goal for the median */
    double ref[3];            /* reference w1..w3 at Omega = 20, rad/s */
    const char *ref_source;   /* where ref comes from */
} bench_case;

/* Measurements of one case. */
typedef struct bench_stats {
    int reps;                 /* repetitions run */
    double median_ms;         /* median wall time of model_new + solve */
    double min_ms;            /* fastest repetition */
    double freq[3];           /* w1..w3 at the last (highest) speed */
    int n_freq;               /* how many of freq are set */
    int solved;               /* cases with status SM_CASE_SOLVED */
    int n_cases;              /* cases in the result */
    sm_model_info info;       /* model sizes */
} bench_stats;

static double bench_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

static int bench_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median of t[0..n-1] (sorts t in place). */
static double bench_median(double *t, int n)
{
    qsort(t, (size_t)n, sizeof *t, bench_cmp_double);
    return (n % 2) ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
}

/* Options of case c on top of the defaults. */
static void bench_options(const bench_case *c, sm_options *o)
{
    sm_default_options(o);
    o->frames = c->frames;
    o->frames_param = c->frames_param;
    o->basis = c->basis;
    o->mass = SM_MASS_LUMPED;
    o->coriolis = c->coriolis;
    o->geometric_stiffening = 1;
    o->modes = 3;
    o->mode_shapes = 1;
}

/*
 * One timed repetition: build the model, solve all speeds, record results
 * into *s on the first repetition.  Returns SM_OK or the failing status
 * (message printed).
 */
static int bench_once(const bench_case *c, const sm_structure *st,
                      const double *omegas, double *ms, bench_stats *s)
{
    sm_options opt;
    sm_model *m = NULL;
    sm_result *r = NULL;
    sm_diag d;
    int rc, i;
    double t0;

    bench_options(c, &opt);
    memset(&d, 0, sizeof d);
    t0 = bench_now_ms();
    rc = sm_model_new(&m, st, &opt, &d);
    if (rc < 0) {
        fprintf(stderr, "bench %s: sm_model_new: %s: %s\n", c->name, sm_strerror(rc), d.message);
        goto done;
    }
    rc = sm_solve(m, omegas, c->n_speeds, NULL, NULL, &r, &d);
    *ms = bench_now_ms() - t0;
    if (rc < 0) {
        fprintf(stderr, "bench %s: sm_solve: %s: %s\n", c->name, sm_strerror(rc), d.message);
        goto done;
    }
    if (s->reps == 0) {
        const sm_case *last = &r->cases[r->n_cases - 1];   /* highest speed */
        sm_model_get_info(m, &s->info);
        s->n_cases = r->n_cases;
        s->solved = 0;
        for (i = 0; i < r->n_cases; i++)
            s->solved += r->cases[i].status == SM_CASE_SOLVED;
        s->n_freq = last->n_modes < 3 ? last->n_modes : 3;
        for (i = 0; i < s->n_freq; i++)
            s->freq[i] = last->frequency[i];
    }
done:
    sm_result_free(r);
    sm_model_free(m);
    return rc < 0 ? rc : SM_OK;
}

/* Run case c repeatedly; fill *s.  Returns SM_OK or the first failure. */
static int bench_run(const bench_case *c, const sm_structure *st, int min_reps,
                     int max_reps, double budget_ms, bench_stats *s)
{
    double *omegas = NULL, *t = NULL, total = 0.0;
    int rc = SM_NOMEM, i;

    memset(s, 0, sizeof *s);
    omegas = malloc((size_t)c->n_speeds * sizeof *omegas);
    t = malloc((size_t)max_reps * sizeof *t);
    if (!omegas || !t)
        goto done;
    for (i = 0; i < c->n_speeds; i++)   /* Omega_i = 20 i/(n-1), or 20 alone */
        omegas[i] = c->n_speeds > 1 ? 20.0 * i / (c->n_speeds - 1) : 20.0;
    rc = SM_OK;
    while (s->reps < max_reps && (s->reps < min_reps || total < budget_ms)) {
        rc = bench_once(c, st, omegas, &t[s->reps], s);
        if (rc < 0)
            goto done;
        total += t[s->reps];
        s->reps++;
    }
    s->median_ms = bench_median(t, s->reps);
    s->min_ms = t[0];
done:
    free(t);
    free(omegas);
    return rc;
}

/*
 * Growth series (issue 14): the planar beta = 90 deg beam with e elements per member, per-element
 * frames, Omega = 20, Coriolis on, no mode shapes, one speed from rest; sm_model_new + sm_solve
 * wall time with the given solver.  One process per point, so that /usr/bin/time -v measures the
 * whole process (tests/bench/growth.sh).  Prints "elements coordinates ms w1 w2 w3".
 */
static int bench_growth_one(int elements, int solver)
{
    static const double joint_xy[] = {0, 0, 5, 0, 5, 5};
    static const sm_section sec[] = {{7e10, 4e-4, 2e-7, 1.2}};
    sm_member mem[2] = {{0, 1, 0, elements / 2}, {1, 2, 0, elements - elements / 2}};
    sm_structure st = {3, joint_xy, 1, sec, 2, mem, 0, NULL, 0};
    sm_options o;
    sm_model *m = NULL;
    sm_result *r = NULL;
    sm_diag d;
    double w = 20.0, t0 = bench_now_ms();
    sm_default_options(&o);
    o.mode_shapes = 0;
    o.solver = solver;
    int rc = sm_model_new(&m, &st, &o, &d);
    if (rc == SM_OK)
        rc = sm_solve(m, &w, 1, NULL, NULL, &r, &d);
    double ms = bench_now_ms() - t0;
    if (rc < 0) {
        fprintf(stderr, "growth %d: %s: %s\n", elements, sm_strerror(rc), d.message);
    } else {
        sm_model_info info;
        sm_model_get_info(m, &info);
        printf("%d %d %.2f", elements, info.coordinates, ms);
        for (int i = 0; i < r->cases[0].n_modes && i < 3; i++)
            printf(" %.12g", r->cases[0].frequency[i]);
        printf("\n");
    }
    sm_result_free(r);
    sm_model_free(m);
    return rc < 0 ? 1 : 0;
}

static void bench_usage(FILE *f)
{
    fprintf(f, "usage: bench_core [--min-reps N] [--max-reps N] [--seconds S] [a|b|c ...]\n"
               "       bench_core --growth ELEMENTS auto|dense|tree   (one solve; see growth.sh)\n"
               "  times sm_model_new + sm_solve for the angled beam (beta 90 deg), median of\n"
               "  repetitions; defaults: --min-reps 5 --max-reps 200 --seconds 2 (per case)\n");
}

int main(int argc, char **argv)
{
    static const double joint_xy[] = {0, 0, 5, 0, 5, 5};              /* O, C, P */
    static const sm_section sec[] = {{7e10, 4e-4, 2e-7, 1.2}};
    static const sm_member mem[] = {{0, 1, 0, 24}, {1, 2, 0, 24}};
    static const bench_case cases[] = {
        {"(a) W=20 per-element augmented Coriolis", SM_FRAMES_PER_ELEMENT, 0,
         SM_BASIS_AUGMENTED, 1, 1, 20.0, {6.9980, 50.5067, 105.9240},
         "multiframe_checkpoints.csv augmented RF48 Coriolis on"},
        {"(b) W=20 RF16 paper no-Coriolis", SM_FRAMES_PER_MEMBER, 8,
         SM_BASIS_PAPER, 0, 1, 10.0, {7.33, 49.51, 107.89},
         "Kim & Yoo (2006) Table 2, RF 16, stiffening on"},
        {"(c) sweep 101 speeds 0..20 of (a)", SM_FRAMES_PER_ELEMENT, 0,
         SM_BASIS_AUGMENTED, 1, 101, 500.0, {6.9980, 50.5067, 105.9240},
         "as (a), at the last speed W=20"},
    };
    const int n_cases = (int)(sizeof cases / sizeof cases[0]);
    sm_structure st;
    int min_reps = 5, max_reps = 200, i, k, failures = 0;
    double seconds = 2.0;
    int run[3] = {0, 0, 0}, any = 0;

    if (argc == 4 && !strcmp(argv[1], "--growth")) {
        int solver = !strcmp(argv[3], "dense") ? SM_SOLVER_DENSE : !strcmp(argv[3], "tree") ? SM_SOLVER_TREE
                                                                                            : SM_SOLVER_AUTO;
        return bench_growth_one(atoi(argv[2]), solver);
    }
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--min-reps") && i + 1 < argc)
            min_reps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--max-reps") && i + 1 < argc)
            max_reps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--seconds") && i + 1 < argc)
            seconds = atof(argv[++i]);
        else if (argv[i][0] >= 'a' && argv[i][0] <= 'c' && argv[i][1] == '\0')
            run[argv[i][0] - 'a'] = any = 1;
        else {
            bench_usage(strcmp(argv[i], "--help") ? stderr : stdout);
            return strcmp(argv[i], "--help") ? 64 : 0;
        }
    }
    if (min_reps < 1)
        min_reps = 1;
    if (max_reps > BENCH_MAX_REPS)
        max_reps = BENCH_MAX_REPS;
    if (max_reps < min_reps)
        max_reps = min_reps;

    memset(&st, 0, sizeof st);
    st.n_joints = 3;
    st.joint_xy = joint_xy;
    st.n_sections = 1;
    st.sections = sec;
    st.n_members = 2;
    st.members = mem;
    st.clamp = 0;

    printf("spinmodal %s bench_core: angled beam beta=90 deg, 24+24 lumped elements, "
           "Omega=20 rad/s; time = sm_model_new + sm_solve from rest\n", sm_version());
    printf("OPENBLAS_NUM_THREADS=%s\n\n",
           getenv("OPENBLAS_NUM_THREADS") ? getenv("OPENBLAS_NUM_THREADS") : "(unset)");
    printf("%-40s %5s %6s %4s %10s %8s %9s %6s %9s %9s %9s\n", "case", "reps", "frames", "n",
           "median ms", "min ms", "target ms", "ratio", "w1", "w2", "w3");
    for (k = 0; k < n_cases; k++) {
        const bench_case *c = &cases[k];
        bench_stats s;
        int rc;

        if (any && !run[k])
            continue;
        rc = bench_run(c, &st, c->n_speeds > 1 ? (min_reps < 3 ? min_reps : 3) : min_reps,
                       max_reps, 1e3 * seconds, &s);
        if (rc < 0) {
            printf("%-40s FAILED: %s\n", c->name, sm_strerror(rc));
            failures++;
            continue;
        }
        printf("%-40s %5d %6d %4d %10.2f %8.2f %9.0f %6.2f", c->name, s.reps, s.info.frames,
               s.info.coordinates, s.median_ms, s.min_ms, c->target_ms, s.median_ms / c->target_ms);
        for (i = 0; i < s.n_freq; i++)
            printf(" %9.4f", s.freq[i]);
        if (s.solved != s.n_cases)
            printf("  (%d of %d speeds solved)", s.solved, s.n_cases);
        printf("\n%-40s %5s %6s %4s %10s %8s %9s %6s %9.4f %9.4f %9.4f  %s\n", "  reference", "",
               "", "", "", "", "", "", c->ref[0], c->ref[1], c->ref[2], c->ref_source);
    }
    printf("\nratio = median / target (< 1 meets the target); w in rad/s at Omega = 20.\n");
    return failures ? 1 : 0;
}
