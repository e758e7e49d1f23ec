/*
 * test_eigen_failed.c — an eigen-analysis that fails after a converged
 * equilibrium is reported as SM_CASE_EIGEN_FAILED, not as "no equilibrium".
 *
 * Provoked through the public API: a cantilever with E = 1e-200 Pa and
 * mu = 1e-307 kg/m (valid, finite, positive numbers).  Its component modes
 * are mass-normalised, so N ~ 1/sqrt(mu l) ~ 1e154 and the geometric term
 * T' G T ~ 1e308 overflows; at Omega = 0 the equilibrium is q = 0 (converged
 * without an iteration) and K* = K + P_e T' G T with P_e = 0 holds 0 * inf =
 * NaN, which LAPACKE rejects.  (With mu = 1e-305 the same beam solves: the
 * failure is an overflow, not a property of the structure.)  The case must
 * keep its equilibrium (converged = 1, nodes, axial forces) and say why in
 * message, and sm_solve must still return SM_OK and go on with other speeds.
 *
 * Then, at the internal level, eig_solve's statuses on matrices that cannot
 * be solved: NaN in K -> SM_LAPACK_FAILED, no mass -> SM_SINGULAR, with no
 * partial output left behind.
 */
#include "internal.h"

#include "testutil.h"

static void public_api(int coriolis)
{
    double xy[4] = {0, 0, 1, 0};
    sm_section sec = {1e-200, 1e-4, 1e-8, 1e-307};
    sm_member mem = {0, 1, 0, 4};
    sm_structure st = {2, xy, 1, &sec, 1, &mem, 0, NULL, 0};
    sm_options o;
    sm_default_options(&o);
    o.coriolis = coriolis;
    sm_model *m = NULL;
    sm_result *r = NULL;
    sm_diag d;
    TU_CHECK(sm_model_new(&m, &st, &o, &d) == SM_OK, "model builds: %s", d.message);
    if (!m)
        return;
    double om[2] = {0, 0};
    int rc = sm_solve(m, om, 2, NULL, NULL, &r, &d);
    TU_CHECK(rc == SM_OK, "sm_solve returns SM_OK (got %d: %s)", rc, d.message);
    for (int i = 0; r && i < r->n_cases; i++) {
        const sm_case *c = &r->cases[i];
        printf("coriolis %d case %d: status %d converged %d message \"%s\"\n", coriolis, i, c->status,
               c->converged, c->message);
        TU_CHECK(c->status == SM_CASE_EIGEN_FAILED, "status EIGEN_FAILED (got %d)", c->status);
        TU_CHECK(c->converged == 1 && c->last_omega == 0.0, "the equilibrium stays converged");
        TU_CHECK(c->n_nodes == 5 && c->nodes && c->nodes[3 * 4] == 1.0 && c->nodes[3 * 4 + 1] == 0.0,
                 "equilibrium node positions are filled (tip at rest at (1, 0))");
        TU_CHECK(c->n_elements == 4 && c->axial_force && c->axial_force[0] == 0.0, "axial forces filled");
        TU_CHECK(strstr(c->message, "eigen-analysis failed") && strstr(c->message, sm_strerror(SM_LAPACK_FAILED)) &&
                     strstr(c->message, "non-finite"),
                 "message gives the cause: %s", c->message);
        TU_CHECK(c->n_modes == 0 && !c->frequency && !c->shape_re && !c->shape_im, "no modes");
        TU_CHECK(c->stable == 0 && c->negative_eigenvalues == 0, "stability unknown (0)");
    }
    sm_result_free(r);
    sm_model_free(m);
    /* the same beam with a little more mass solves: the failure is the overflow */
    sec.mu = 1e-305;
    r = tu_solve1(&st, &o, 0.0, NULL);
    TU_CHECK(r && r->cases[0].status == SM_CASE_SOLVED && r->cases[0].n_modes == 3,
             "mu = 1e-305 solves (status %d)", r ? (int)r->cases[0].status : -1);
    sm_result_free(r);
}

static void internal_statuses(void)
{
    enum { N = 3 };
    dmat M = {0}, C = {0}, K = {0};
    sm_eig_out e;
    if (dm_alloc(&M, N, N) || dm_alloc(&C, N, N) || dm_alloc(&K, N, N)) {
        TU_CHECK(0, "alloc");
        goto done;
    }
    for (int i = 0; i < N; i++) {
        DM(&M, i, i) = 1.0;
        DM(&K, i, i) = (double)(i + 1);
    }
    for (int v = 0; v < 4; v++) { /* with and without Coriolis, both fixed_bits routes */
        int cor = v & 1, bits = v >> 1;
        TU_CHECK(eig_solve(N, &M, &C, &K, cor, 2, bits, &e) == SM_OK && e.n_modes == 2,
                 "well-posed problem solves");
        eig_out_free(&e);
        DM(&K, 1, 1) = NAN;
        int rc = eig_solve(N, &M, &C, &K, cor, 2, bits, &e);
        TU_CHECK(
            rc == SM_LAPACK_FAILED && e.n_modes == 0 && !e.wre && !e.xre,
            "NaN in K (coriolis %d, fixed_bits %d): SM_LAPACK_FAILED, no partial output (got %d)",
            cor, bits, rc);
        eig_out_free(&e);
        DM(&K, 1, 1) = 2.0;
        dm_zero(&M);
        rc = eig_solve(N, &M, &C, &K, cor, 2, bits, &e);
        TU_CHECK(rc == SM_SINGULAR && e.n_modes == 0 && !e.wre, "no mass (coriolis %d): SM_SINGULAR (got %d)", cor,
                 rc);
        eig_out_free(&e);
        for (int i = 0; i < N; i++)
            DM(&M, i, i) = 1.0;
    }
done:
    dm_free(&M);
    dm_free(&C);
    dm_free(&K);
}

int main(void)
{
    public_api(1);
    public_api(0);
    internal_statuses();
    return tu_finish("eigen_failed");
}
