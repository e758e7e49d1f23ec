/*
 * test_gravity_fd.c — the weight's terms of the spatial kind (DESIGN.md 8.8) against finite
 * differences at a DEFORMED steady state under gravity: a leaning column (0,0,0) -> (3,8,0) with
 * a tip mass whose centre of mass is offset [0.5, 0.3, -0.2] m and has a rotary inertia,
 * gravity -9.81 along hub y, per-element frames and 3 elements per frame, lumped and
 * consistent mass.  At q0 from eq_solve (load factor 1; the tip turns by a few degrees):
 *  1. the generalised weight f_w = sum m J'g (the kind's "centrifugal" with gravity) equals
 *     -dV/dq, V = -sum_p m_p g.r_p from sp_eval's positions of the mass points (the offset
 *     centres included), by central differences with Richardson extrapolation;
 *  2. the Newton tangent (dense_tangent at s = 1: K + df_g/dq - df_w/dq) equals the central
 *     differences of the residual F(q) = K q + f_g(q) - f_w(q);
 *  3. F(q0) ~ 0 (the steady state), and the tip has moved.
 * Dropping the offset's moment (dh x F) or the weight's load stiffness fails 1 or 2.
 */
#include "kind.h"
#include "spatial.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int fails = 0, checks = 0;

static void check(double err, double tol, const char *what)
{
    checks++;
    int ok = err <= tol;
    fails += !ok;
    printf("%s %s: err %.2e (limit %.1e)\n", ok ? "ok  " : "FAIL", what, err, tol);
}

/* V = -sum m g . r over the mass points at q (sp_eval's positions include the offsets). */
static double potential(const sm_model *m, const double *q, sp_kin *k)
{
    double v = 0;
    sp_eval(m, q, k);
    for (int p = 0; p < m->n_pt; p++)
        if (m->pt[p].sub >= 0)
            for (int i = 0; i < 3; i++)
                v -= m->pt[p].mass * m->grav[i] * k->r[3 * p + i];
    return v;
}

/* F(q) = K q + f_g(q) - f_w(q) into f; g: scratch (n). */
static void residual(const sm_model *m, const double *q, void *kin, double *g, double *f)
{
    memset(f, 0, (size_t)m->n * sizeof(double));
    m->kind->centrifugal(m, q, kin, NULL, g);
    lin_elastic_force(m, q, f);
    m->kind->geometric_force(m, q, f);
    for (int i = 0; i < m->n; i++)
        f[i] -= g[i];
}

static void run(sm_mass_model mass, int per)
{
    double xy[4] = {0, 0, 3, 8}, z[2] = {0, 0};
    sm_section sec;
    memset(&sec, 0, sizeof sec);
    sec.EA = 1e9, sec.EI_flap = 4e6, sec.EI_edge = 6e6, sec.GJ = 3e6, sec.mu = 20;
    sec.i_flap = 0.02, sec.i_edge = 0.03, sec.ip_over_a = 0.05 / 20;
    sm_member mem;
    memset(&mem, 0, sizeof mem);
    mem.to = 1, mem.elements = 6;
    sm_point_mass pm;
    memset(&pm, 0, sizeof pm);
    pm.joint = 1, pm.mass = 300;
    pm.inertia[0] = 20, pm.inertia[1] = 30, pm.inertia[2] = 25;
    pm.offset[0] = 0.5, pm.offset[1] = 0.3, pm.offset[2] = -0.2;
    sm_structure st;
    memset(&st, 0, sizeof st);
    st.n_joints = 2, st.joint_xy = xy, st.joint_z = z, st.n_sections = 1, st.sections = &sec;
    st.n_members = 1, st.members = &mem, st.n_point_masses = 1, st.point_masses = &pm;
    st.spatial = 1, st.gravity[1] = -9.81;
    sm_options o;
    sm_default_options(&o);
    o.mass = mass;
    o.frames = per == 1 ? SM_FRAMES_PER_ELEMENT : SM_FRAMES_ELEMENTS_PER_FRAME;
    o.frames_param = per;
    sm_model *m = NULL;
    sm_diag d;
    char what[160];
    const char *tag = mass == SM_MASS_CONSISTENT ? "consistent" : "lumped";
    if (sm_model_new(&m, &st, &o, &d) != SM_OK) {
        printf("FAIL model: %s\n", d.message);
        fails++;
        return;
    }
    int n = m->n;
    double *q0 = calloc((size_t)n, sizeof(double)), *x = calloc((size_t)n, sizeof(double));
    double *g = calloc((size_t)n, sizeof(double)), *fp = calloc((size_t)n, sizeof(double));
    double *fm = calloc((size_t)n, sizeof(double)), *f0 = calloc((size_t)n, sizeof(double));
    sp_kin kp;
    memset(&kp, 0, sizeof kp);
    void *kin = m->kind->kin_new(m, SMI_USE_NEWTON);
    smi_dense D;
    double *work = calloc(12 * 64 + (size_t)n, sizeof(double));
    sm_eq_out eo;
    if (!q0 || !x || !g || !fp || !fm || !f0 || !kin || !work || sp_kin_alloc(m, &kp, 0) ||
        m->kind->dense_alloc(m, SMI_USE_NEWTON, &D) != SM_OK ||
        eq_solve(m, q0, 0.0, 1.0, 1, NULL, NULL, &eo) < 0 || !eo.converged) {
        printf("FAIL %s, %d el./frame: no steady state under gravity (%s)\n", tag, per, eo.message);
        fails++;
        goto done;
    }
    /* 3. the steady state */
    residual(m, q0, kin, g, f0);
    double fn = 0, gn = 0;
    for (int i = 0; i < n; i++)
        fn += f0[i] * f0[i], gn += g[i] * g[i];
    snprintf(what, sizeof what, "%s, %d el./frame: |F(q0)| / |f_w| at the steady state", tag, per);
    check(sqrt(fn / gn), 1e-9, what);
    sp_eval(m, q0, &kp);
    double tip = 0;
    for (int i = 0; i < 3; i++) {
        double r0 = i == 0 ? 3.0 : i == 1 ? 8.0 : 0.0;
        tip += (kp.r[3 * m->joint_node[1] + i] - r0) * (kp.r[3 * m->joint_node[1] + i] - r0);
    }
    printf("     %s, %d el./frame: the tip moved %.3f m under its weight\n", tag, per, sqrt(tip));
    /* 1. f_w = -dV/dq (Richardson of central differences, steps h and h/2) */
    m->kind->centrifugal(m, q0, kin, NULL, g);
    double err = 0, scale = 0;
    for (int j = 0; j < n; j++) {
        double h = 1e-4 * fmax(1.0, fabs(q0[j])), dv[2];
        for (int r = 0; r < 2; r++) {
            double hh = r ? h / 2 : h;
            memcpy(x, q0, (size_t)n * sizeof(double));
            x[j] = q0[j] + hh;
            double vp = potential(m, x, &kp);
            x[j] = q0[j] - hh;
            dv[r] = (vp - potential(m, x, &kp)) / (2 * hh);
        }
        double dfd = (4 * dv[1] - dv[0]) / 3;
        err = fmax(err, fabs(g[j] + dfd));
        scale = fmax(scale, fabs(g[j]));
    }
    snprintf(what, sizeof what, "%s, %d el./frame: f_w = -dV/dq (max rel.)", tag, per);
    check(err / scale, 1e-8, what);
    /* 2. the tangent against differences of F */
    m->kind->kin_eval(m, q0, kin);
    m->kind->centrifugal(m, q0, kin, NULL, g);
    m->kind->dense_tangent(m, q0, kin, 1.0, &D, work);
    double kmax = 0, ktmax = 0;
    err = 0;
    for (int j = 0; j < n; j++) {
        double h = 1e-5 * fmax(1.0, fabs(q0[j]));
        memcpy(x, q0, (size_t)n * sizeof(double));
        x[j] = q0[j] + h;
        residual(m, x, kin, g, fp);
        x[j] = q0[j] - h;
        residual(m, x, kin, g, fm);
        for (int i = 0; i < n; i++) {
            double fd = (fp[i] - fm[i]) / (2 * h);
            err = fmax(err, fabs(DM(&D.K, i, j) - fd));
            kmax = fmax(kmax, fabs(DM(&D.K, i, j)));
        }
    }
    /* the weight's part alone: the tangent less K and the geometric term (P from q) */
    m->kind->kin_eval(m, q0, kin);
    m->kind->centrifugal(m, q0, kin, NULL, g);
    m->kind->dense_tangent(m, q0, kin, 0.0, &D, work); /* s = 0: no weight */
    double *Kt0 = malloc((size_t)n * n * sizeof(double));
    if (Kt0) {
        memcpy(Kt0, D.K.a, (size_t)n * n * sizeof(double));
        m->kind->centrifugal(m, q0, kin, NULL, g);
        m->kind->dense_tangent(m, q0, kin, 1.0, &D, work);
        for (size_t i = 0; i < (size_t)n * n; i++)
            ktmax = fmax(ktmax, fabs(D.K.a[i] - Kt0[i]));
        free(Kt0);
    }
    snprintf(what, sizeof what,
             "%s, %d el./frame: Newton tangent = dF/dq by differences, relative to the weight's "
             "part of the tangent (%.1e of its largest entry)",
             tag, per, ktmax / kmax);
    check(err / ktmax, 1e-4, what);
    smi_dense_free(&D);
done:
    m->kind->kin_free(kin);
    sp_kin_free(&kp);
    free(q0), free(x), free(g), free(fp), free(fm), free(f0), free(work);
    sm_model_free(m);
}

int main(void)
{
    run(SM_MASS_LUMPED, 1);
    run(SM_MASS_LUMPED, 3);
    run(SM_MASS_CONSISTENT, 1);
    printf("gravity_fd: %d checks, %d failures\n", checks, fails);
    return fails ? 1 : 0;
}
