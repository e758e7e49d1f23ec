/*
 * lin3.c — the terms of the equations of a spatial model (DESIGN.md 7.3):
 * the geometric stiffening force and its tangent (both bending planes and
 * the Wagner torsion term, P frozen for K*), M*, C* (translational Coriolis
 * and the rotary-inertia gyroscopic part), the Newton tangent / K*, and the
 * nodal outputs (positions, triad rotations, mode shapes).
 */
#include "spatial.h"

#include <cblas.h>
#include <math.h>
#include <string.h>

/* tq (12) = T_e q_s for element j of substructure b. */
static void lin3_tq(const sm_sub *b, int j, const double *qs, double tq[12])
{
    for (int r = 0; r < 12; r++) {
        double s = 0;
        for (int c = 0; c < b->m; c++)
            s += DM(&b->T, 12 * j + r, c) * qs[c];
        tq[r] = s;
    }
}

/* P_e = d_e . q_s. */
static double lin3_axial(const sm_sub *b, int j, const double *qs)
{
    const double *d = b->d + (size_t)j * b->m;
    double P = 0;
    for (int c = 0; c < b->m; c++)
        P += d[c] * qs[c];
    return P;
}

void lin3_geometric_force(const sm_model *m, const double *q, double *f)
{
    double G[144], tq[12], gt[12];
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        const double *qs = q + b->q0;
        for (int j = 0; j < b->nel; j++) {
            fe3_geometric(&m->elems[b->elems[j]], G);
            lin3_tq(b, j, qs, tq);
            double P = lin3_axial(b, j, qs);
            for (int r = 0; r < 12; r++) { /* gt = P G T q */
                double s2 = 0;
                for (int c = 0; c < 12; c++)
                    s2 += G[r + 12 * c] * tq[c];
                gt[r] = P * s2;
            }
            for (int c = 0; c < b->m; c++) { /* f_s += T' gt */
                double s2 = 0;
                for (int r = 0; r < 12; r++)
                    s2 += DM(&b->T, 12 * j + r, c) * gt[r];
                f[b->q0 + c] += s2;
            }
        }
    }
}

/* Column k (mm) of Kt_ss += P T_e' g (g: a column of G T_e), then += v dc where v is given (the
 * derivative of P).  restrict: the 12 rows of Tr, v and k do not overlap, so that the loop over
 * the entries is vectorised without run-time overlap checks of 14 streams. */
static void lin3_geo_column(int mm, const double *restrict Tr, const double *restrict g, double P,
                            const double *restrict v, double dc, double *restrict k)
{
    /* two loops, not one with v dc scaled by 0: adding 0 would turn a -0 entry into +0 */
    if (!v) { /* Kt_ss += P T' G T */
        for (int a = 0; a < mm; a++) {
            double s2 = 0;
            for (int r = 0; r < 12; r++)
                s2 += Tr[(size_t)r * mm + a] * g[r];
            k[a] += P * s2;
        }
        return;
    }
    for (int a = 0; a < mm; a++) { /* + (T' G T q) d' */
        double s2 = 0;
        for (int r = 0; r < 12; r++)
            s2 += Tr[(size_t)r * mm + a] * g[r];
        k[a] += P * s2;
        k[a] += v[a] * dc;
    }
}

/*
 * Each element adds P_e T_e' G T_e (+ T_e' G T_e q_s d_e'), T_e the element's twelve rows of T_s.
 * Those rows are copied into work first, one contiguous row each (T_s is column-major with
 * 12 nel rows: a row of it is strided), and G T_e is formed a column at a time inside the
 * column loop, so the inner loop over the rows of Kt reads and writes contiguous memory (issue
 * 27: 57 % of a 360-coordinate one-frame spatial model's time, strided).  Every entry of Kt
 * receives the same operations in the same order as in solver 0.8.8 (sums over r = 0..11 from
 * 0, then P times the sum added, then the d_e' term; elements in order): the same bits
 * (test_geometric_tangent compares with that form).  work: >= 13 max m_s.
 */
void lin3_geometric_tangent_sub(const sm_model *m, int s, const double *q, int frozen, double *Kt, int ld,
                                double *work)
{
    double G[144], tq[12], gt[12], gc[12];
    const sm_sub *b = &m->subs[s];
    const double *qs = q + b->q0;
    int mm = b->m;
    double *Tr = work,
           *v = work + 12 * (size_t)mm; /* Tr: 12 x mm, rows of T_e; v = T_e' G T_e q_s */
    for (int j = 0; j < b->nel; j++) {
        fe3_geometric(&m->elems[b->elems[j]], G);
        double P = lin3_axial(b, j, qs);
        for (int c = 0; c < mm; c++)
            for (int r = 0; r < 12; r++)
                Tr[(size_t)r * mm + c] = DM(&b->T, 12 * j + r, c);
        const double *d = b->d + (size_t)j * mm;
        if (!frozen) { /* the derivative of P */
            lin3_tq(b, j, qs, tq);
            for (int r = 0; r < 12; r++) {
                double s2 = 0;
                for (int t = 0; t < 12; t++)
                    s2 += G[r + 12 * t] * tq[t];
                gt[r] = s2;
            }
            for (int a = 0; a < mm; a++) {
                double s2 = 0;
                for (int r = 0; r < 12; r++)
                    s2 += Tr[(size_t)r * mm + a] * gt[r];
                v[a] = s2;
            }
        }
        for (int c = 0; c < mm; c++) {
            for (int r = 0; r < 12; r++) { /* column c of G T_e */
                double s2 = 0;
                for (int t = 0; t < 12; t++)
                    s2 += G[r + 12 * t] * Tr[(size_t)t * mm + c];
                gc[r] = s2;
            }
            lin3_geo_column(mm, Tr, gc, P, frozen ? NULL : v, frozen ? 0.0 : d[c],
                            Kt + (size_t)ld * c);
        }
    }
}

void lin3_geometric_tangent(const sm_model *m, const double *q, int frozen, dmat *Kt, double *work)
{
    for (int s = 0; s < m->n_subs; s++) {
        const sm_sub *b = &m->subs[s];
        lin3_geometric_tangent_sub(m, s, q, frozen, &DM(Kt, b->q0, b->q0), Kt->rows, work);
    }
}

/* X = A_s Lambda(psi_p) I_p Lambda' A_s': the hub inertia of point p at k. */
void lin3_hub_inertia(const sm_model *m, const sp_kin *k, int pi, double X[9])
{
    const sp_point *p = &m->pt[pi];
    if (p->sub < 0) { /* a free base's clamp point, at rest: I is in hub axes */
        memcpy(X, p->I, 9 * sizeof(double));
        return;
    }
    sp_cx psi[3] = {k->psi[3 * pi], k->psi[3 * pi + 1], k->psi[3 * pi + 2]}, L[9], AL[9], Ic[9], t[9], u[9];
    for (int i = 0; i < 9; i++)
        Ic[i] = p->I[i];
    rot3_exp(psi, L, NULL);
    for (int i = 0; i < 9; i++)
        t[i] = k->A[9 * p->sub + i];
    rot3_mul(t, L, AL);
    rot3_mul(AL, Ic, t);
    /* u = t AL' */
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            u[i + 3 * j] = t[i] * AL[j] + t[i + 3] * AL[j + 3] + t[i + 6] * AL[j + 6];
    for (int i = 0; i < 9; i++)
        X[i] = creal(u[i]);
}

/* Z (n x 3) = J (n x 3, ld n) B (3x3). */
static void lin3_times(int n, const double *J, const double B[9], double *Z)
{
    for (int j = 0; j < 3; j++)
        for (int x = 0; x < n; x++)
            Z[(size_t)n * j + x] = J[x] * B[3 * j] + J[(size_t)n + x] * B[3 * j + 1] + J[2 * (size_t)n + x] * B[3 * j + 2];
}

/* Out = scale Z JW' over the points with mass or inertia, exactly symmetric or skew (sign). */
static void lin3_product(const sm_model *m, const sp_kin *k, const dmat *Z, double scale, int sign, dmat *Out)
{
    int n = m->n, P6 = 6 * m->n_pt;
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, n, n, P6, scale, Z->a, n, k->JW.a, n, 0.0, Out->a, n);
    for (int j = 0; j < n; j++)
        for (int i = 0; i < j; i++) {
            double a = 0.5 * (DM(Out, i, j) + sign * DM(Out, j, i));
            DM(Out, i, j) = a;
            DM(Out, j, i) = sign * a;
        }
    if (sign < 0)
        for (int i = 0; i < n; i++)
            DM(Out, i, i) = 0;
}

void lin3_mass(const sm_model *m, const sp_kin *k, dmat *M, dmat *Y)
{
    int n = m->n;
    dm_zero(Y);
    for (int pi = 0; pi < m->n_pt; pi++) {
        const sp_point *p = &m->pt[pi];
        if (p->sub < 0 && !m->base) /* the clamp, unless the base is free */
            continue;
        double mI[9] = {p->mass, 0, 0, 0, p->mass, 0, 0, 0, p->mass}, X[9];
        const double *J = &DM(&k->JW, 0, 6 * pi);
        lin3_times(n, J, mI, &DM(Y, 0, 6 * pi));
        if (p->has_I) {
            lin3_hub_inertia(m, k, pi, X);
            lin3_times(n, J + 3 * (size_t)n, X, &DM(Y, 0, 6 * pi + 3));
        }
    }
    lin3_product(m, k, Y, 1.0, 1, M);
}

void lin3_gyro(const sm_model *m, const sp_kin *k, double omega, dmat *C, dmat *Y)
{
    int n = m->n;
    dm_zero(Y);
    for (int pi = 0; pi < m->n_pt; pi++) {
        const sp_point *p = &m->pt[pi];
        if (p->sub < 0 && !m->base) /* the clamp, unless the base is free */
            continue;
        /* 2 m S, S = skew(e_z) */
        double S2[9] = {0, 2 * p->mass, 0, -2 * p->mass, 0, 0, 0, 0, 0}, X[9], Yp[9];
        const double *J = &DM(&k->JW, 0, 6 * pi);
        lin3_times(n, J, S2, &DM(Y, 0, 6 * pi));
        if (!p->has_I)
            continue;
        lin3_hub_inertia(m, k, pi, X);
        lin3_gyro_rotary(X, Yp);
        lin3_times(n, J + 3 * (size_t)n, Yp, &DM(Y, 0, 6 * pi + 3));
    }
    lin3_product(m, k, Y, omega, -1, C);
}

void lin3_gyro_rotary(const double X[9], double Yp[9])
{
    /* Y_p = -skew(X e) + X S + S X, X e = third column of X */
    double xe[3] = {X[6], X[7], X[8]};
    double Sk[9] = {0, xe[2], -xe[1], -xe[2], 0, xe[0], xe[1], -xe[0], 0};
    double XS[9] = {X[3], X[4], X[5], -X[0], -X[1], -X[2], 0, 0, 0}; /* X S: columns (X e2, -X e1, 0) */
    double SX[9];
    for (int j = 0; j < 3; j++) { /* S X: rows (-X row 2, X row 1, 0) */
        SX[0 + 3 * j] = -X[1 + 3 * j];
        SX[1 + 3 * j] = X[0 + 3 * j];
        SX[2 + 3 * j] = 0;
    }
    for (int i = 0; i < 9; i++)
        Yp[i] = -Sk[i] + XS[i] + SX[i];
}

void lin3_tangent(const sm_model *m, const double *q, sp_kin *k, double s, int frozen, dmat *Kt, dmat *H,
                  double *work)
{
    int n = m->n;
    dm_zero(Kt);
    lin_elastic_add(m, Kt);
    if (m->opt.geometric_stiffening)
        lin3_geometric_tangent(m, q, frozen, Kt, work);
    if (s == 0.0)
        return;
    sp_centrifugal_jacobian(m, q, k, H);
    for (size_t i = 0; i < (size_t)n * n; i++)
        Kt->a[i] -= s * H->a[i];
}

double lin3_nodes(const sm_model *m, const sp_kin *k, double *nodes, int *at)
{
    double rot = 0;
    *at = -1;
    for (int nd = 0; nd < m->n_nodes; nd++) {
        const sp_point *p = &m->pt[nd];
        double *o = nodes + 6 * nd;
        memcpy(o, k->r + 3 * nd, 3 * sizeof(double));
        memset(o + 3, 0, 3 * sizeof(double));
        if (p->sub < 0)
            continue;
        /* triad rotation from rest: A_s Lambda(psi) A0_s' */
        const double *ps = k->psi + 3 * nd;
        sp_cx psi[3] = {ps[0], ps[1], ps[2]}, L[9];
        double Lr[9], AL[9], R[9];
        rot3_exp(psi, L, NULL);
        for (int i = 0; i < 9; i++)
            Lr[i] = creal(L[i]);
        rot3_mul_r(k->A + 9 * p->sub, Lr, AL);
        for (int j = 0; j < 3; j++) /* R = AL A0' */
            for (int i = 0; i < 3; i++) {
                const double *A0 = m->subs[p->sub].A0;
                R[i + 3 * j] = AL[i] * A0[j] + AL[i + 3] * A0[j + 3] + AL[i + 6] * A0[j + 6];
            }
        rot3_log(R, o + 3);
        double a = sqrt(ps[0] * ps[0] + ps[1] * ps[1] + ps[2] * ps[2]);
        if (a > rot) {
            rot = a;
            *at = nd;
        }
    }
    return rot;
}

void lin3_nodal(const sm_model *m, const sp_kin *k, const double *x, double *y)
{
    cblas_dgemv(CblasColMajor, CblasTrans, m->n, 6 * m->n_nodes, 1.0, k->JW.a, m->n, x, 1, 0.0, y, 1);
}
