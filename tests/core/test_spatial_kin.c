/*
 * test_spatial_kin.c — the derivatives of the spatial path (DESIGN.md 7.3) against central
 * differences, at a random deformed state of a branched, twisted, precone structure with
 * multi-node frames and truncated bases (static attachment modes):
 *  - J (d r_p / dq) against differences of the point positions;
 *  - W (hub rotation) against differences of the point orientations (log map);
 *  - g against differences of the centrifugal potential T0~;
 *  - the Newton tangent against differences of the residual F(q), K* (P frozen) symmetric;
 *  - M* symmetric positive definite, C* skew and equal to Omega (B - B'), B = db/dq by differences,
 *    b = sum m J'(e_z x r) + W' X e_z (the q-dot-linear part of the kinetic energy).
 */
#include "spatial.h"

#include <lapacke.h>
#include <math.h>
#include <string.h>

#include <stdio.h>
#include <stdlib.h>

static int fails = 0, checks = 0;

static void check(double err, double tol, const char *what)
{
    checks++;
    int ok = err <= tol;
    fails += !ok;
    printf("%s %-62s relative error %.2e (tol %.0e)\n", ok ? "ok  " : "FAIL", what, err, tol);
}

/* The structure: hub radius 0.5, a precone twisted blade O-A-B and a branch A-C out of plane
 * (with stations), offsets of masses and elastic centres. */
static sm_model *build(const sm_options *o)
{
    static double xy[8] = {0.5, 0, 3.5, 0.2, 6.5, 0.1, 3.6, 1.5};
    static double z[4] = {0, 0.4, 0.9, -0.6};
    static sm_section sec[2];
    static sm_member mem[3];
    static sm_point_mass pm;
    memset(sec, 0, sizeof sec);
    memset(mem, 0, sizeof mem);
    sec[0].EA = 8.4e7, sec[0].EI_flap = 2800, sec[0].EI_edge = 25200, sec[0].GJ = 3883, sec[0].mu = 3.0;
    sec[0].i_flap = 1e-4, sec[0].i_edge = 9e-4, sec[0].ip_over_a = 1e-3 / 3.0;
    sec[1] = sec[0];
    sec[1].EI_flap = 9000, sec[1].mu = 2.0, sec[1].i_flap = 3e-4;
    int ft[3][3] = {{0, 1, 0}, {1, 2, 0}, {1, 3, 1}}, el[3] = {4, 4, 3};
    for (int i = 0; i < 3; i++) {
        mem[i].from = ft[i][0], mem[i].to = ft[i][1], mem[i].section = ft[i][2], mem[i].elements = el[i];
        mem[i].twist = 0.3 * (i + 1);
    }
    pm.joint = 2, pm.mass = 1.5, pm.inertia[0] = 0.02, pm.inertia[1] = 0.05, pm.inertia[2] = 0.01;
    /* blade data (DESIGN.md 8): an offset point mass with products of inertia, section centres of
     * mass, shear and tension centres off the axis, and stations along the branch */
    pm.offset[0] = 0.1, pm.offset[1] = -0.2, pm.offset[2] = 0.15, pm.products[0] = 0.004, pm.products[2] = -0.003;
    sec[0].cg[0] = 0.05, sec[0].cg[1] = 0.02, sec[0].sc[0] = -0.03, sec[0].tc[1] = 0.01;
    static sm_station sta[3];
    memset(sta, 0, sizeof sta);
    for (int j = 0; j < 3; j++) {
        sta[j].s = 0.5 * j;
        sta[j].mu = 2.0 - 0.5 * j;
        sta[j].EI_flap = 9000 - 2000 * j;
        sta[j].twist = 0.1 + 0.2 * j * j;
        sta[j].inertia_twist = 0.2 - 0.1 * j;
        sta[j].cg[0] = 0.04 * j, sta[j].cg[1] = -0.01 * j;
        sta[j].sc[1] = 0.02 * j;
    }
    mem[2].n_stations = 3, mem[2].stations = sta;
    mem[2].station_mask = SM_ST_MU | SM_ST_EI_FLAP | SM_ST_TWIST | SM_ST_INERTIA_TWIST | SM_ST_CG | SM_ST_SC;
    sm_structure st;
    memset(&st, 0, sizeof st);
    st.n_joints = 4, st.joint_xy = xy, st.joint_z = z, st.n_sections = 2, st.sections = sec;
    st.n_members = 3, st.members = mem, st.n_point_masses = 1, st.point_masses = &pm, st.spatial = 1;
    sm_model *m = NULL;
    sm_diag d;
    if (sm_model_new(&m, &st, o, &d) < 0)
        printf("model: %s\n", d.message);
    return m;
}

/* T0~ = sum 1/2 m |P r|^2 + 1/2 e' X e at the kinematics k. */
static double potential(const sm_model *m, const sp_kin *k)
{
    double T = 0;
    for (int p = 0; p < m->n_pt; p++) {
        const sp_point *pt = &m->pt[p];
        if (pt->sub < 0)
            continue;
        const double *r = k->r + 3 * p;
        T += 0.5 * pt->mass * (r[0] * r[0] + r[1] * r[1]);
        /* e' A L I L' A' e: v = L' A' e */
        sp_cx psi[3] = {k->psi[3 * p], k->psi[3 * p + 1], k->psi[3 * p + 2]}, L[9], e[3] = {0, 0, 1}, a[3], v[3];
        sp_cx A[9];
        for (int i = 0; i < 9; i++)
            A[i] = k->A[9 * pt->sub + i];
        rot3_exp(psi, L, NULL);
        rot3_tmv(A, e, a);
        rot3_tmv(L, a, v);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                T += 0.5 * creal(v[i] * pt->Ic[i + 3 * j] * v[j]);
    }
    return T;
}

/* Hub orientation A_s Lambda(psi_p) of point p at k. */
static void orientation(const sm_model *m, const sp_kin *k, int p, double O[9])
{
    sp_cx psi[3] = {k->psi[3 * p], k->psi[3 * p + 1], k->psi[3 * p + 2]}, L[9];
    double Lr[9];
    rot3_exp(psi, L, NULL);
    for (int i = 0; i < 9; i++)
        Lr[i] = creal(L[i]);
    rot3_mul_r(k->A + 9 * m->pt[p].sub, Lr, O);
}

/* F(q) = K q + f_g - s g. */
static void residual(const sm_model *m, const double *q, double s, sp_kin *k, double *F, double *g)
{
    memset(F, 0, (size_t)m->n * sizeof(double));
    lin_elastic_force(m, q, F);
    lin3_geometric_force(m, q, F);
    sp_centrifugal(m, q, k, g);
    for (int i = 0; i < m->n; i++)
        F[i] -= s * g[i];
}

/* b (n) = sum m J'(e x r) + W' X e at k (jac). */
static void gyro_vector(const sm_model *m, const sp_kin *k, double *b)
{
    int n = m->n;
    memset(b, 0, (size_t)n * sizeof(double));
    for (int p = 0; p < m->n_pt; p++) {
        const sp_point *pt = &m->pt[p];
        if (pt->sub < 0)
            continue;
        const double *r = k->r + 3 * p;
        double f[3] = {-pt->mass * r[1], pt->mass * r[0], 0}, O[9], X[9], t[9], Xe[3];
        orientation(m, k, p, O);
        rot3_mul_r(O, pt->I, t);
        for (int j = 0; j < 3; j++) /* X = t O' */
            for (int i = 0; i < 3; i++)
                X[i + 3 * j] = t[i] * O[j] + t[i + 3] * O[j + 3] + t[i + 6] * O[j + 6];
        for (int i = 0; i < 3; i++)
            Xe[i] = X[i + 6];
        for (int x = 0; x < n; x++)
            for (int i = 0; i < 3; i++)
                b[x] += DM(&k->JW, x, 6 * p + i) * f[i] + DM(&k->JW, x, 6 * p + 3 + i) * Xe[i];
    }
}

static double rel(double num, double den)
{
    return num / fmax(den, 1e-300);
}

int main(void)
{
    sm_options o;
    sm_default_options(&o);
    o.frames = SM_FRAMES_PER_MEMBER;
    o.frames_param = 2;
    o.modes_per_frame = 5;
    sm_model *m = build(&o);
    if (!m)
        return 1;
    int n = m->n, P = m->n_pt;
    printf("model: %d coordinates, %d frames, %d points (per_member 2, modes_per_frame 5 + attachment modes)\n", n,
           m->n_subs, P);
    sp_kin k, kp, km;
    if (sp_kin_alloc(m, &k, 1) || sp_kin_alloc(m, &kp, 1) || sp_kin_alloc(m, &km, 1))
        return 1;
    double *q = dm_vec((size_t)n), *qp = dm_vec((size_t)n), *F1 = dm_vec((size_t)n), *F2 = dm_vec((size_t)n);
    double *g = dm_vec((size_t)n), *gw = dm_vec((size_t)n), *b1 = dm_vec((size_t)n), *b2 = dm_vec((size_t)n);
    double *work = dm_vec((size_t)(12 * n + n));
    dmat Kt = {0}, Ks = {0}, H = {0}, M = {0}, C = {0}, Y = {0}, B = {0};
    if (dm_alloc(&Kt, n, n) || dm_alloc(&Ks, n, n) || dm_alloc(&H, n, n) || dm_alloc(&M, n, n) || dm_alloc(&C, n, n) ||
        dm_alloc(&Y, n, 6 * P) || dm_alloc(&B, n, n))
        return 1;
    srand(7);
    for (int i = 0; i < n; i++)
        q[i] = 0.04 * (2.0 * rand() / RAND_MAX - 1.0);
    sp_eval(m, q, &k);
    double h = 1e-6, s = 9.0, omega = 3.0;
    double eJ = 0, nJ = 0, eW = 0, nW = 0, eg = 0, ng = 0, eK = 0, nK = 0, eB = 0, nB = 0;
    sp_centrifugal(m, q, &k, g);
    for (int j = 0; j < n; j++) {
        memcpy(qp, q, (size_t)n * sizeof(double));
        qp[j] = q[j] + h;
        sp_eval(m, qp, &kp);
        qp[j] = q[j] - h;
        sp_eval(m, qp, &km);
        for (int p = 0; p < P; p++) {
            if (m->pt[p].sub < 0)
                continue;
            double Op[9], Om[9], R[9], v[3];
            for (int i = 0; i < 3; i++) {
                double d = (kp.r[3 * p + i] - km.r[3 * p + i]) / (2 * h);
                eJ = fmax(eJ, fabs(d - DM(&k.JW, j, 6 * p + i)));
                nJ = fmax(nJ, fabs(d));
            }
            orientation(m, &kp, p, Op);
            orientation(m, &km, p, Om);
            for (int c = 0; c < 3; c++) /* R = Op Om' */
                for (int i = 0; i < 3; i++)
                    R[i + 3 * c] = Op[i] * Om[c] + Op[i + 3] * Om[c + 3] + Op[i + 6] * Om[c + 6];
            rot3_log(R, v);
            for (int i = 0; i < 3; i++) {
                double d = v[i] / (2 * h);
                eW = fmax(eW, fabs(d - DM(&k.JW, j, 6 * p + 3 + i)));
                nW = fmax(nW, fabs(d));
            }
        }
        double dT = (potential(m, &kp) - potential(m, &km)) / (2 * h);
        eg = fmax(eg, fabs(dT - g[j]));
        ng = fmax(ng, fabs(dT));
        /* tangent column j by differences of F */
        qp[j] = q[j] + h;
        residual(m, qp, s, &kp, F1, gw);
        qp[j] = q[j] - h;
        residual(m, qp, s, &km, F2, gw);
        for (int i = 0; i < n; i++)
            DM(&H, i, j) = (F1[i] - F2[i]) / (2 * h);
        /* B column j by differences of b */
        qp[j] = q[j] + h;
        sp_eval(m, qp, &kp);
        gyro_vector(m, &kp, b1);
        qp[j] = q[j] - h;
        sp_eval(m, qp, &km);
        gyro_vector(m, &km, b2);
        for (int i = 0; i < n; i++)
            DM(&B, i, j) = (b1[i] - b2[i]) / (2 * h);
    }
    check(rel(eJ, nJ), 1e-7, "J against central differences of the positions");
    check(rel(eW, nW), 1e-7, "W against central differences of the orientations");
    check(rel(eg, ng), 1e-7, "g against central differences of T0~");
    dmat Hc = {0};
    dm_alloc(&Hc, n, n);
    lin3_tangent(m, q, &k, s, 0, &Kt, &Hc, work);
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            eK = fmax(eK, fabs(DM(&Kt, i, j) - DM(&H, i, j)));
            nK = fmax(nK, fabs(DM(&H, i, j)));
        }
    check(rel(eK, nK), 1e-6, "Newton tangent against central differences of F");
    lin3_tangent(m, q, &k, s, 1, &Ks, &Hc, work);
    double asym = 0, nks = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            asym = fmax(asym, fabs(DM(&Ks, i, j) - DM(&Ks, j, i)));
            nks = fmax(nks, fabs(DM(&Ks, i, j)));
        }
    check(rel(asym, nks), 1e-9, "K* (P frozen) symmetric");
    lin3_mass(m, &k, &M, &Y);
    lin3_gyro(m, &k, omega, &C, &Y);
    double nM = 0, nC = 0, sk = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            nM = fmax(nM, fabs(DM(&M, i, j)));
            nC = fmax(nC, fabs(DM(&C, i, j)));
            sk = fmax(sk, fabs(DM(&C, i, j) + DM(&C, j, i)));
            double want = omega * (DM(&B, i, j) - DM(&B, j, i));
            eB = fmax(eB, fabs(DM(&C, i, j) - want));
            nB = fmax(nB, fabs(want));
        }
    check(rel(sk, nC), 1e-12, "C* skew");
    check(rel(eB, nB), 1e-6, "C* = Omega (B - B') with B = db/dq by differences");
    double *L = dm_vec((size_t)n * n);
    memcpy(L, M.a, (size_t)n * n * sizeof(double));
    int info = LAPACKE_dpotrf(LAPACK_COL_MAJOR, 'L', n, L, n);
    checks++;
    fails += info != 0;
    printf("%s M* positive definite (rotary inertia everywhere): dpotrf info %d\n", info ? "FAIL" : "ok  ", info);
    free(L);
    printf("spatial_kin: %d checks, %d failures\n", checks, fails);
    sp_kin_free(&k);
    sp_kin_free(&kp);
    sp_kin_free(&km);
    free(q), free(qp), free(F1), free(F2), free(g), free(gw), free(b1), free(b2), free(work);
    dm_free(&Kt), dm_free(&Ks), dm_free(&H), dm_free(&M), dm_free(&C), dm_free(&Y), dm_free(&B), dm_free(&Hc);
    sm_model_free(m);
    return fails ? 1 : 0;
}
