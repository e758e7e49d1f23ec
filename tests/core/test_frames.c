/*
 * test_frames.c — chain kinematics: J_k against central differences of r_k,
 * the Hessian term H against differences of g (so dg/dq = M* + H), and the
 * Newton tangent against differences of the residual's geometric part, on a
 * deformed state of the angled beam with several frame schemes.
 */
#include "internal.h"
#include "testutil.h"

static void check_scheme(sm_frame_scheme fs, int param, sm_basis basis, sm_mass_model mass)
{
    tu_angled a;
    tu_angled_beam(&a, 60, 6, 6);
    sm_options o;
    sm_default_options(&o);
    o.frames = fs;
    o.frames_param = param;
    o.basis = basis;
    o.mass = mass;
    sm_model *m;
    sm_diag d;
    if (sm_model_new(&m, &a.st, &o, &d) < 0) {
        TU_CHECK(0, "model: %s", d.message);
        return;
    }
    int n = m->n;
    double *q = calloc((size_t)n, sizeof(double)), *g0 = calloc((size_t)n, sizeof(double));
    double *g1 = calloc((size_t)n, sizeof(double)), *work = calloc((size_t)(8 * n + 64), sizeof(double));
    for (int i = 0; i < n; i++)
        q[i] = 0.3 * sin(1.7 * i + 0.4); /* a large, arbitrary deformation */
    sm_kin k, kp, km;
    frames_kin_alloc(m, &k);
    frames_kin_alloc(m, &kp);
    frames_kin_alloc(m, &km);
    frames_eval(m, q, &k);
    double h = 1e-6, ej = 0, eh = 0, scale = 0;
    dmat M, H, W;
    dm_alloc(&M, n, n);
    dm_alloc(&H, n, n);
    dm_alloc(&W, n, 2 * m->n_mp);
    lin_mass(m, &k, &M, &W);
    frames_hessian(m, q, &k, &H, work);
    for (int j = 0; j < n; j++) {
        double s = q[j];
        q[j] = s + h;
        frames_eval(m, q, &kp);
        frames_centrifugal(m, &kp, g1);
        q[j] = s - h;
        frames_eval(m, q, &km);
        frames_centrifugal(m, &km, g0);
        q[j] = s;
        for (int c = 0; c < 3 * m->n_nodes; c++) {
            double fd = (kp.rn[c] - km.rn[c]) / (2 * h);
            ej = fmax(ej, fabs(fd - DM(&k.Jn, j, c)));
        }
        for (int i = 0; i < n; i++) {
            double fd = (g1[i] - g0[i]) / (2 * h);
            eh = fmax(eh, fabs(fd - DM(&M, i, j) - DM(&H, i, j)));
            scale = fmax(scale, fabs(fd));
        }
    }
    TU_CHECK(ej < 1e-6, "scheme %d/%d basis %d: J differs from finite differences by %g", fs, param, basis, ej);
    TU_CHECK(eh < 1e-6 * scale, "scheme %d/%d basis %d: dg/dq differs from M*+H by %g (scale %g)", fs, param,
             basis, eh, scale);
    printf("scheme %d/%d basis %d mass %d: n=%d |J-FD| %.1e |dg/dq-(M+H)| %.1e\n", fs, param, basis, mass, n, ej, eh);
    /* geometric tangent (full) against differences of f_g */
    dmat Kt;
    dm_alloc(&Kt, n, n);
    lin_geometric_tangent(m, q, 0, &Kt, work);
    double eg = 0, gs = 0;
    for (int j = 0; j < n; j++) {
        double s = q[j];
        memset(g1, 0, (size_t)n * sizeof(double));
        memset(g0, 0, (size_t)n * sizeof(double));
        q[j] = s + h;
        lin_geometric_force(m, q, g1);
        q[j] = s - h;
        lin_geometric_force(m, q, g0);
        q[j] = s;
        for (int i = 0; i < n; i++) {
            double fd = (g1[i] - g0[i]) / (2 * h);
            eg = fmax(eg, fabs(fd - DM(&Kt, i, j)));
            gs = fmax(gs, fabs(fd));
        }
    }
    TU_CHECK(eg < 1e-6 * fmax(gs, 1), "geometric tangent differs from finite differences by %g (scale %g)", eg, gs);
    dm_free(&Kt);
    dm_free(&M);
    dm_free(&H);
    dm_free(&W);
    frames_kin_free(&k);
    frames_kin_free(&kp);
    frames_kin_free(&km);
    free(q);
    free(g0);
    free(g1);
    free(work);
    sm_model_free(m);
}

int main(void)
{
    check_scheme(SM_FRAMES_SINGLE, 1, SM_BASIS_PAPER, SM_MASS_LUMPED);
    check_scheme(SM_FRAMES_PER_MEMBER, 2, SM_BASIS_PAPER, SM_MASS_LUMPED);
    check_scheme(SM_FRAMES_PER_MEMBER, 3, SM_BASIS_AUGMENTED, SM_MASS_LUMPED);
    check_scheme(SM_FRAMES_PER_ELEMENT, 1, SM_BASIS_AUGMENTED, SM_MASS_LUMPED);
    check_scheme(SM_FRAMES_ELEMENTS_PER_FRAME, 4, SM_BASIS_AUGMENTED, SM_MASS_CONSISTENT);
    return tu_finish("frames");
}
