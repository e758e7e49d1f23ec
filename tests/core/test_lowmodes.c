/*
 * test_lowmodes.c — the sparse component modes of large frames (core/lowmodes.h, issue 10)
 * against the dense complete decomposition they replace.
 *
 * Each structure is built twice: with the default options (a frame of D >= 200 DOF keeping
 * modes_per_frame <= D/8 modes takes the sparse path) and with sm_options.solver =
 * SM_SOLVER_DENSE, the switch that forces the dense component modes (and the dense assembled
 * solve, which these few-coordinate models use anyway).
 *
 * How closely the two can agree is set by the dense path, which is the less accurate one for
 * long chains of short beams: Kbar of 400 elements has a condition number ~1e10, the dense
 * eigenvectors carry rounding up to 1e-4 (relative residual) and its K_s = N' Kbar N, summed in
 * double, loses up to 1e-7 of the lowest frequency to cancellation.  So every frame is measured
 * against Kbar and Mbar themselves, not only against the other path, and every number is
 * printed:
 *   - the sparse basis is certified: each kept mode x has |Kbar^-1 Mbar x - mu x| <= 1e-10 |mu x|
 *     (mu its Rayleigh quotient; Kbar^-1 by the sparse factor with iterative refinement, Kbar x
 *     by accurate dot products), no larger than the dense path's residual; span(N_kept) is
 *     invariant under Kbar^-1 Mbar to 1e-10 (largest principal angle); Kbar^-1 E (the static
 *     attachment loads) lies in span(N) to 1e-10;
 *   - the kept subspaces of the two paths: largest principal angle <= 1e-10, or <= the two
 *     bases' invariance defects / (1 - mu_nm+1 / mu_nm) where the dense one is worse (a
 *     subspace turned by theta from the exact one has a defect of at least (1 - rho) theta);
 *     lumped attachment columns equal entry by entry to 1e-10;
 *   - the natural frequencies of the assembled system through sm_solve, at rest and spinning
 *     (Coriolis and stiffening on): with the dense basis's K_s summed accurately, to 1e-9 plus
 *     the first-order effect of the dense basis's measured error; D = 300 frames (where the
 *     dense path is accurate) to 1e-9 flat; the plain dense path to that plus 4 x its K_s error.
 * Structures: cantilevers (planar 3 DOF/node, spatial precone blade 6 DOF/node) of D = 300 and
 * D = 1200 (400 planar / 200 spatial elements, as the issue asks), Y-shaped frames (a tree: the
 * reverse Cuthill-McKee ordering), two frames per structure (the large parent carries a child:
 * attachment columns for lumped mass, static unit-moment modes for consistent mass, 6 static
 * modes in space), lumped and consistent mass.
 */
#include "testutil.h"

#include "kind.h"
#include "spatial.h"
#include "lowmodes.h"

#include <lapacke.h>
#include <time.h>

#define PI 3.14159265358979323846

typedef struct shape {
    double xy[8], z[4];
    sm_section sec;
    sm_member mem[3];
    sm_structure st;
} shape;

/* A planar cantilever of ne elements along x (10 m, the paper's section). */
static void planar_beam(shape *s, int ne)
{
    memset(s, 0, sizeof *s);
    s->xy[2] = 10.0;
    s->sec.E = 7e10, s->sec.A = 4e-4, s->sec.I = 2e-7, s->sec.mu = 1.2;
    s->mem[0] = (sm_member){0, 1, 0, ne};
    s->st.n_joints = 2, s->st.joint_xy = s->xy, s->st.n_sections = 1, s->st.sections = &s->sec;
    s->st.n_members = 1, s->st.members = s->mem;
}

/* A planar Y: a 4 m stem to joint 1, two 4 m arms at +-30 deg (elements ne0, ne1, ne1). */
static void planar_y(shape *s, int ne0, int ne1)
{
    planar_beam(s, ne0);
    double xy[8] = {0, 0, 4, 0, 4 + 4 * cos(PI / 6), 4 * sin(PI / 6), 4 + 4 * cos(PI / 6), -4 * sin(PI / 6)};
    memcpy(s->xy, xy, sizeof xy);
    s->mem[1] = (sm_member){1, 2, 0, ne1};
    s->mem[2] = (sm_member){1, 3, 0, ne1};
    s->st.n_joints = 4, s->st.n_members = 3;
}

/* The spatial section of bench_spatial's blade: distinct flap, edge and torsion stiffnesses. */
static void spatial_section(sm_section *sec)
{
    memset(sec, 0, sizeof *sec);
    sec->EA = 8.4e7, sec->EI_flap = 2800, sec->EI_edge = 25200, sec->GJ = 3883, sec->mu = 3.0;
    sec->i_flap = 1e-4, sec->i_edge = 9e-4, sec->ip_over_a = 1e-3 / 3.0;
}

/* The precone blade: hub radius 1 m, 10 m at 10 deg, ne elements. */
static void spatial_blade(shape *s, int ne)
{
    memset(s, 0, sizeof *s);
    double b = 10 * PI / 180;
    s->xy[0] = 1, s->xy[2] = 1 + 10 * cos(b), s->z[1] = 10 * sin(b);
    spatial_section(&s->sec);
    s->mem[0].from = 0, s->mem[0].to = 1, s->mem[0].elements = ne;
    s->st.n_joints = 2, s->st.joint_xy = s->xy, s->st.joint_z = s->z, s->st.n_sections = 1;
    s->st.sections = &s->sec, s->st.n_members = 1, s->st.members = s->mem, s->st.spatial = 1;
}

/* A spatial Y: stem along x, one arm rising in z, one turning in y (elements ne0, ne1, ne1). */
static void spatial_y(shape *s, int ne0, int ne1)
{
    spatial_blade(s, ne0);
    double xy[8] = {1, 0, 4, 0, 7, 0, 6, 2.5}, z[4] = {0, 0, 1.5, -0.5};
    memcpy(s->xy, xy, sizeof xy);
    memcpy(s->z, z, sizeof z);
    s->mem[1].from = 1, s->mem[1].to = 2, s->mem[1].elements = ne1;
    s->mem[2].from = 1, s->mem[2].to = 3, s->mem[2].elements = ne1;
    s->st.n_joints = 4, s->st.n_members = 3;
}

/* Orthonormal basis of the k columns of A (D x k) into Q (QR). */
static int orth(int D, int k, const double *A, double *Q)
{
    double tau[256];
    memcpy(Q, A, (size_t)D * k * sizeof(double));
    if (k > 256 || LAPACKE_dgeqrf(LAPACK_COL_MAJOR, D, k, Q, D, tau) != 0)
        return -1;
    return LAPACKE_dorgqr(LAPACK_COL_MAJOR, D, k, k, Q, D, tau) == 0 ? 0 : -1;
}

/* sin of the largest principal angle between span(A) and span(B) (D x k each):
 * || (I - Qa Qa') Qb ||_2. */
static double max_angle(int D, int k, const double *A, const double *B)
{
    double *Qa = malloc((size_t)D * k * sizeof(double)), *Qb = malloc((size_t)D * k * sizeof(double));
    double *C = malloc((size_t)k * k * sizeof(double)), s[256], res = 1.0;
    if (Qa && Qb && C && k <= 256 && orth(D, k, A, Qa) == 0 && orth(D, k, B, Qb) == 0) {
        for (int i = 0; i < k; i++) /* C = Qa' Qb */
            for (int j = 0; j < k; j++) {
                double t = 0;
                for (int r = 0; r < D; r++)
                    t += Qa[(size_t)D * i + r] * Qb[(size_t)D * j + r];
                C[i + k * j] = t;
            }
        for (int j = 0; j < k; j++) /* Qb -= Qa C */
            for (int i = 0; i < k; i++)
                for (int r = 0; r < D; r++)
                    Qb[(size_t)D * j + r] -= Qa[(size_t)D * i + r] * C[i + k * j];
        if (LAPACKE_dgesdd(LAPACK_COL_MAJOR, 'N', D, k, Qb, D, s, NULL, 1, NULL, 1) == 0)
            res = s[0];
    }
    free(Qa);
    free(Qb);
    free(C);
    return res;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Accuracy of the basis of frame b of m, measured against Kbar, Mbar themselves (not against
 * the other path). */
typedef struct quality {
    double res;     /* worst inverse residual of the kept modes (see the header) */
    double kerr;    /* largest error of K_s against N' Kbar N summed accurately, relative to its diagonal */
    double stat;    /* static attachment modes (consistent or spatial): largest relative distance of
                       Kbar^-1 E (refined) from span(N); 0 when there are none */
    double defect;  /* largest principal angle between span(N_kept) and span(Kbar^-1 Mbar N_kept):
                       zero for an invariant subspace; a subspace turned by theta from the exact one
                       shows a defect ~(1 - rho) theta */
    double rho;     /* mu_nm+1 / mu_nm: the contraction of one inverse iteration outside the kept modes */
} quality;

/* Largest relative distance of the k columns of Z from span(N) (D x m). */
static double span_distance(int D, int m, const double *N, int k, const double *Z)
{
    double *Q = malloc((size_t)D * m * sizeof(double)), worst = 1;
    if (Q && orth(D, m, N, Q) == 0) {
        worst = 0;
        for (int j = 0; j < k; j++) {
            const double *z = Z + (size_t)D * j;
            double c[64], r2 = 0, z2 = 0;
            for (int i = 0; i < m && i < 64; i++) { /* c = Q' z */
                c[i] = 0;
                for (int r = 0; r < D; r++)
                    c[i] += Q[(size_t)D * i + r] * z[r];
            }
            for (int r = 0; r < D; r++) { /* |z - Q c| / |z| */
                double t = z[r];
                for (int i = 0; i < m && i < 64; i++)
                    t -= Q[(size_t)D * i + r] * c[i];
                r2 += t * t;
                z2 += z[r] * z[r];
            }
            worst = fmax(worst, sqrt(r2 / z2));
        }
    }
    free(Q);
    return worst;
}

static int frame_quality(const sm_model *m, const sm_sub *b, quality *qu)
{
    csym K = {0}, M = {0};
    csym_ldl F = {0};
    dmat Ks = {0};
    int D = b->N.rows, nm, na, rc = -1, fb = 0;
    if (m->kind->spatial)
        modes3_count(&m->opt, b, &nm, &na);
    else
        modes_count(&m->opt, b, &nm, &na);
    int p = lowmodes_block(D, nm + 1);
    double *Kx = malloc((size_t)D * sizeof(double)), *y = malloc((size_t)D * sizeof(double));
    double *Mx = malloc((size_t)D * sizeof(double)), *X = calloc((size_t)D * p, sizeof(double));
    double *mu = calloc((size_t)p, sizeof(double)), *Z = calloc((size_t)D * (na ? na : 1), sizeof(double));
    memset(qu, 0, sizeof *qu);
    if (!Kx || !y || !Mx || !X || !mu || !Z ||
        (m->kind->spatial ? modes3_frame_csym(m, b, &K, &M) : modes_frame_csym(m, b, &K, &M)) ||
        csym_factor(&K, &F) || lowmodes_project(&K, &b->N, &Ks) ||
        lowmodes_solve(&K, &F, &M, nm + 1, X, mu, &fb) || fb)
        goto done;
    qu->rho = mu[nm] / mu[nm - 1];
    for (int j = 0; j < nm; j++) {
        const double *x = b->N.a + (size_t)D * j;
        double xkx = 0, xmx = 0, r2 = 0, v2 = 0;
        csym_mul_acc(&K, 1, x, D, Kx, D);
        csym_mul(&M, 1, x, D, Mx, D);
        for (int r = 0; r < D; r++) {
            xkx += x[r] * Kx[r];
            xmx += x[r] * Mx[r];
        }
        double rq = xmx / xkx; /* Rayleigh quotient mu */
        memcpy(y, Mx, (size_t)D * sizeof(double));
        if (csym_solve_refined(&K, &F, 1, y, D))
            goto done;
        for (int r = 0; r < D; r++) { /* y - mu x */
            r2 += (y[r] - rq * x[r]) * (y[r] - rq * x[r]);
            v2 += rq * x[r] * rq * x[r];
        }
        qu->res = fmax(qu->res, sqrt(r2 / v2));
    }
    csym_mul(&M, nm, b->N.a, D, X, D); /* X = Kbar^-1 Mbar N_kept */
    if (csym_solve_refined(&K, &F, nm, X, D))
        goto done;
    qu->defect = max_angle(D, nm, b->N.a, X);
    for (int i = 0; i < b->m; i++)
        for (int j = 0; j < b->m; j++)
            qu->kerr = fmax(qu->kerr, fabs(DM(&Ks, i, j) - DM(&b->K, i, j)) / sqrt(DM(&Ks, i, i) * DM(&Ks, j, j)));
    if (na > 0 && (m->kind->spatial || m->opt.mass == SM_MASS_CONSISTENT)) { /* E: unit loads at the attachments */
        for (int a = 0; a < na; a++)
            Z[(size_t)D * a + (m->kind->spatial ? 6 * b->attach[a / 6] + a % 6 : 3 * b->attach[a] + 2)] = 1.0;
        if (csym_solve_refined(&K, &F, na, Z, D))
            goto done;
        qu->stat = span_distance(D, b->m, b->N.a, na, Z);
    }
    rc = 0;
done:
    free(Kx);
    free(y);
    free(Mx);
    free(X);
    free(mu);
    free(Z);
    dm_free(&Ks);
    csym_free(&K);
    csym_free(&M);
    csym_ldl_free(&F);
    return rc;
}

/* Largest relative frequency difference between two results (case c), -1 when unusable. */
static double freq_diff(const sm_result *a, const sm_result *b, int c)
{
    const sm_case *x = &a->cases[c], *y = &b->cases[c];
    double worst = 0;
    if (x->status != SM_CASE_SOLVED || y->status != SM_CASE_SOLVED || x->n_modes != 6 || y->n_modes != 6)
        return -1;
    for (int k = 0; k < 6; k++)
        worst = fmax(worst, fabs(x->frequency[k] - y->frequency[k]) / y->frequency[k]);
    return worst;
}

/*
 * Per frame of the pair: the sparse basis certified against Kbar, Mbar (kept-mode residuals and
 * invariance defect <= 1e-10, residuals no larger than the dense one's, Kbar^-1 E in its span to
 * 1e-10), and the kept subspaces of the two paths within 1e-10 of each other -- or within the
 * two bases' own measured errors, (defect_sparse + defect_dense) / (1 - rho), when that is
 * larger.  Lumped attachment columns (no eigen-solve in them) agree entry by entry to 1e-10.
 * (The principal angles of the whole bases are printed, not checked: a static mode is what is
 * left of Kbar^-1 E after the kept modes are taken out, often a few per cent of it, so the kept
 * subspace's own angle reappears there divided by that share.)
 */
typedef struct dense_err {
    double angle;   /* largest principal angle between the kept subspaces of the two paths */
    double defect;  /* largest invariance defect of the dense bases */
    double kerr;    /* largest K_s error of the dense path */
} dense_err;

static void compare_frames(const sm_model *ms, const sm_model *md, dense_err *de)
{
    memset(de, 0, sizeof *de);
    for (int b = 0; b < ms->n_subs; b++) {
        const sm_sub *bs = &ms->subs[b], *bd = &md->subs[b];
        int D = bs->N.rows, nm, na;
        if (ms->kind->spatial)
            modes3_count(&ms->opt, bs, &nm, &na);
        else
            modes_count(&ms->opt, bs, &nm, &na);
        double a_kept = max_angle(D, nm, bs->N.a, bd->N.a), a_all = max_angle(D, bs->m, bs->N.a, bd->N.a);
        quality qs = {1, 1, 1, 1, 1}, qd = {1, 1, 1, 1, 1};
        int ok = frame_quality(ms, bs, &qs) == 0 && frame_quality(md, bd, &qd) == 0;
        double tol = fmax(1e-10, (qs.defect + qd.defect) / (1 - qs.rho)), attach = 0, amax = 0;
        for (int j = nm; !ms->kind->spatial && ms->opt.mass == SM_MASS_LUMPED && j < bs->m; j++)
            for (int r = 0; r < D; r++) {
                attach = fmax(attach, fabs(DM(&bs->N, r, j) - DM(&bd->N, r, j)));
                amax = fmax(amax, fabs(DM(&bd->N, r, j)));
            }
        attach = amax > 0 ? attach / amax : 0;
        printf("  frame %d: D %4d, %d modes + %d attachment columns: largest principal angle of the kept modes "
               "%.1e (allowed %.1e), all columns %.1e\n"
               "    sparse: residual %.1e, invariance defect %.1e, Kbar^-1 E off the span %.1e\n"
               "    dense:  residual %.1e, invariance defect %.1e, Kbar^-1 E off the span %.1e, K_s error %.1e\n",
               b, D, nm, na, a_kept, tol, a_all, qs.res, qs.defect, qs.stat, qd.res, qd.defect, qd.stat, qd.kerr);
        TU_CHECK(ok && qs.res <= 1e-10 && qs.res <= fmax(qd.res, 1e-11) && qs.defect <= 1e-10 && qs.stat <= 1e-10,
                 "frame %d: sparse basis certified (residual %.1e, dense %.1e; defect %.1e; static %.1e)", b,
                 qs.res, qd.res, qs.defect, qs.stat);
        de->angle = fmax(de->angle, a_kept);
        de->defect = fmax(de->defect, qd.defect);
        de->kerr = fmax(de->kerr, qd.kerr);
        TU_CHECK(a_kept <= tol && attach <= 1e-10, "frame %d spans the dense subspace (%.1e; attachment columns %.1e)",
                 b, a_kept, attach);
        if (D >= 200) /* the sparse path was taken (a fallback would give the dense bits) */
            TU_CHECK(memcmp(bs->N.a, bd->N.a, (size_t)D * bs->m * sizeof(double)) != 0,
                     "frame %d: sparse component modes", b);
    }
}

/* md's K_s replaced by N' Kbar N summed accurately (the test owns md). */
static int accurate_ks(sm_model *md)
{
    for (int b = 0; b < md->n_subs; b++) {
        sm_sub *bd = &md->subs[b];
        csym K = {0}, M = {0};
        dmat Ks = {0};
        int rc = md->kind->spatial ? modes3_frame_csym(md, bd, &K, &M) : modes_frame_csym(md, bd, &K, &M);
        if (rc == SM_OK)
            rc = lowmodes_project(&K, &bd->N, &Ks);
        csym_free(&K);
        csym_free(&M);
        if (rc != SM_OK)
            return rc;
        dm_free(&bd->K);
        bd->K = Ks;
    }
    return SM_OK;
}

/*
 * Build st both ways and compare (see the header).  Frequencies: against the dense basis with its
 * K_s summed accurately to 1e-9 plus the first-order effect of the dense basis's own error (at
 * rest its invariance defect, spinning 10 x the measured angle between the paths), against the
 * plain dense path to that plus 4 x its K_s error; strict (D = 300 frames, where the dense path
 * is accurate) also to 1e-9 flat against the accurate-K_s dense basis.
 */
static void compare(const char *name, const sm_structure *st, sm_mass_model mass, sm_frame_scheme frames,
                    int fparam, int strict, double omega)
{
    sm_options o;
    sm_default_options(&o);
    o.frames = frames;
    o.frames_param = fparam;
    o.mass = mass;
    o.modes_per_frame = 8;
    o.modes = 6;
    sm_options od = o;
    od.solver = SM_SOLVER_DENSE;
    sm_model *ms = NULL, *md = NULL;
    sm_result *r1 = NULL, *r2 = NULL, *r3 = NULL;
    sm_diag d;
    double t0 = now_s();
    int rs = sm_model_new(&ms, st, &o, &d);
    double t1 = now_s();
    int rd = rs == SM_OK ? sm_model_new(&md, st, &od, &d) : rs;
    double t2 = now_s();
    TU_CHECK(rs == SM_OK && rd == SM_OK && ms->n == md->n, "%s: both models build (%s)", name, d.message);
    if (rs != SM_OK || rd != SM_OK || ms->n != md->n)
        goto done;
    printf("%s, %s mass, %d frame(s), modes_per_frame 8: build %.3f s sparse, %.3f s dense\n", name,
           mass == SM_MASS_CONSISTENT ? "consistent" : "lumped", ms->n_subs, t1 - t0, t2 - t1);
    dense_err de;
    compare_frames(ms, md, &de);
    double om[2] = {0.0, omega};
    int e1 = sm_solve(ms, om, 2, NULL, NULL, &r1, &d), e2 = sm_solve(md, om, 2, NULL, NULL, &r2, &d);
    int e3 = e2 == SM_OK ? accurate_ks(md) : e2;
    if (e3 == SM_OK)
        e3 = sm_solve(md, om, 2, NULL, NULL, &r3, &d);
    TU_CHECK(e1 == SM_OK && e2 == SM_OK && e3 == SM_OK, "all solve (%s)", d.message);
    for (int c = 0; e1 == SM_OK && e2 == SM_OK && e3 == SM_OK && c < 2; c++) {
        double plain = freq_diff(r1, r2, c), acc = freq_diff(r1, r3, c);
        printf("  Omega %3.1f: w1..3 %.9g %.9g %.9g rad/s; relative difference to dense %.1e, to dense with "
               "accurate K_s %.1e\n",
               om[c], r1->cases[c].n_modes > 2 ? r1->cases[c].frequency[0] : 0.0,
               r1->cases[c].n_modes > 2 ? r1->cases[c].frequency[1] : 0.0,
               r1->cases[c].n_modes > 2 ? r1->cases[c].frequency[2] : 0.0, plain, acc);
        double tol = 1e-9 + (c == 0 ? de.defect : 10 * de.angle);
        TU_CHECK(plain >= 0 && acc >= 0, "Omega %g: solved, 6 modes each", om[c]);
        TU_CHECK(acc <= tol && plain <= tol + 4 * de.kerr,
                 "Omega %g: frequencies agree (%.1e to %.1e, %.1e to %.1e)", om[c], acc, tol, plain,
                 tol + 4 * de.kerr);
        if (strict)
            TU_CHECK(acc <= 1e-9, "Omega %g: frequencies agree to 1e-9 (%.1e)", om[c], acc);
    }
done:
    sm_result_free(r1);
    sm_result_free(r2);
    sm_result_free(r3);
    sm_model_free(ms);
    sm_model_free(md);
}

int main(void)
{
    shape s;
    for (int mass = 0; mass < 2; mass++) {
        sm_mass_model mm = (sm_mass_model)mass;
        /* D = 300: the dense path is accurate enough for the literal comparison */
        planar_beam(&s, 100);
        compare("planar cantilever 100 el", &s.st, mm, SM_FRAMES_SINGLE, 1, 1, 2.0);
        planar_beam(&s, 200);
        compare("planar cantilever 2 x 100 el", &s.st, mm, SM_FRAMES_ELEMENTS_PER_FRAME, 100, 1, 2.0);
        spatial_blade(&s, 50);
        compare("spatial blade 50 el", &s.st, mm, SM_FRAMES_SINGLE, 1, 1, 3.0);
        spatial_blade(&s, 100);
        compare("spatial blade 2 x 50 el", &s.st, mm, SM_FRAMES_ELEMENTS_PER_FRAME, 50, 1, 3.0);
        /* D = 1200 and trees */
        planar_beam(&s, 400);
        compare("planar cantilever 400 el", &s.st, mm, SM_FRAMES_SINGLE, 1, 0, 2.0);
        planar_y(&s, 120, 140);
        compare("planar Y 120 + 2 x 140 el", &s.st, mm, SM_FRAMES_SINGLE, 1, 0, 2.0);
        planar_beam(&s, 400);
        compare("planar cantilever 250 + 150 el", &s.st, mm, SM_FRAMES_ELEMENTS_PER_FRAME, 250, 0, 2.0);
        spatial_blade(&s, 200);
        compare("spatial blade 200 el", &s.st, mm, SM_FRAMES_SINGLE, 1, 0, 3.0);
        spatial_y(&s, 60, 70);
        compare("spatial Y 60 + 2 x 70 el", &s.st, mm, SM_FRAMES_SINGLE, 1, 0, 2.0);
        spatial_blade(&s, 200);
        compare("spatial blade 120 + 80 el", &s.st, mm, SM_FRAMES_ELEMENTS_PER_FRAME, 120, 0, 3.0);
    }
    return tu_finish("lowmodes");
}
