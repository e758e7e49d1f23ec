/*
 * test_sweep.c — speed sweeps: continuation gives the same answers as
 * independent solves, results come back in input order for unsorted speeds,
 * modes are tracked by MAC (adjacent speeds: MAC near 1, index matched),
 * mode shapes are normalised (largest translation 1, clamp at rest), the
 * progress callback sees every speed and can cancel, but a stop after the last speed
 * keeps the solved cases (refine_stopped when it cut a refinement short).
 */
#include "testutil.h"

typedef struct prog {
    int calls, last_done, cancel_at;
} prog;

/* A stop that arrives with the last speed (a time limit, issue 23): returns 1 from done == total on. */
static int stop_at_end(void *user, int done, int total)
{
    int *calls = user;
    ++*calls;
    return done >= total;
}

static int on_progress(void *user, int done, int total)
{
    prog *p = user;
    p->calls++;
    if (done < p->last_done || done > total)
        p->last_done = -1000; /* flags a non-monotone report */
    else
        p->last_done = done;
    return p->cancel_at > 0 && p->calls >= p->cancel_at;
}

int main(void)
{
    tu_angled a;
    tu_angled_beam(&a, 90, 12, 12);
    sm_options o;
    sm_default_options(&o);
    sm_model *m;
    sm_diag d;
    TU_CHECK(sm_model_new(&m, &a.st, &o, &d) == SM_OK, "model");
    double om[6] = {20, 0, 4, 8, 12, 16};
    sm_result *r;
    prog p = {0, 0, 0};
    TU_CHECK(sm_solve(m, om, 6, on_progress, &p, &r, &d) == SM_OK, "sweep");
    TU_CHECK(p.last_done == 6 && p.calls >= 6, "progress reached 6/6 (last %d, calls %d)", p.last_done, p.calls);
    for (int i = 0; i < 6; i++)
        TU_CHECK(r->cases[i].omega == om[i] && r->cases[i].status == SM_CASE_SOLVED, "case %d in input order", i);
    /* each speed alone, from rest */
    for (int i = 0; i < 6; i++) {
        sm_result *s;
        sm_solve(m, &om[i], 1, NULL, NULL, &s, &d);
        for (int j = 0; j < 3; j++)
            TU_NEAR(r->cases[i].frequency[j], s->cases[0].frequency[j], 1e-7 * s->cases[0].frequency[j],
                    "omega %g w%d continuation = from rest", om[i], j + 1);
        sm_result_free(s);
    }
    /* MAC tracking between ascending neighbours: 0 -> 4 -> 8 -> ... (input index 1,2,3,4,5,0) */
    int ord[6] = {1, 2, 3, 4, 5, 0};
    TU_CHECK(r->cases[1].mac_to_previous[0] == -1, "first speed has no previous");
    for (int t = 1; t < 6; t++) {
        sm_case *c = &r->cases[ord[t]];
        for (int j = 0; j < 3; j++) {
            TU_CHECK(c->previous_index[j] == j, "omega %g mode %d tracked to %d", c->omega, j, c->previous_index[j]);
            TU_CHECK(c->mac_to_previous[j] > 0.7 && c->mac_to_previous[j] <= 1 + 1e-12, "omega %g mode %d MAC %.4f",
                     c->omega, j, c->mac_to_previous[j]);
        }
    }
    /* shapes: clamp node fixed, max |translation| = 1 */
    sm_case *c = &r->cases[0];
    int nn = c->n_nodes, clamp = sm_model_joint_node(m, 0);
    for (int j = 0; j < c->n_modes; j++) {
        double mx = 0;
        for (int k = 0; k < nn; k++)
            for (int h = 0; h < 2; h++)
                mx = fmax(mx, hypot(c->shape_re[(size_t)j * 3 * nn + 3 * k + h],
                                    c->shape_im[(size_t)j * 3 * nn + 3 * k + h]));
        TU_NEAR(mx, 1.0, 1e-12, "mode %d normalised", j + 1);
        TU_CHECK(c->shape_re[(size_t)j * 3 * nn + 3 * clamp] == 0, "clamp at rest");
    }
    sm_result_free(r);
    /* cancel after a few progress calls */
    p = (prog){0, 0, 3};
    r = NULL;
    TU_CHECK(sm_solve(m, om, 6, on_progress, &p, &r, &d) == SM_CANCELED && r == NULL, "cancel returns SM_CANCELED");
    TU_CHECK(p.calls == 3, "no progress after cancel (%d calls)", p.calls);
    /* a stop after every speed is solved keeps them (issue 23: a finished job was recorded
     * "timeout" and its result thrown away) */
    int calls = 0;
    r = NULL;
    TU_CHECK(sm_solve(m, om, 6, stop_at_end, &calls, &r, &d) == SM_OK && r, "a stop after the last speed: SM_OK");
    for (int i = 0; r && i < 6; i++)
        TU_CHECK(r->cases[i].status == SM_CASE_SOLVED && r->cases[i].n_modes == 3, "kept case %d", i);
    TU_CHECK(r && !r->refine_stopped, "nothing to refine: refine_stopped 0");
    sm_result_free(r);
    /* ... and during the refinement of critical speeds: the cases stay, refine_stopped says so */
    sm_model_free(m);
    o.n_engine_orders = 1;
    o.engine_orders[0] = 1;
    TU_CHECK(sm_model_new(&m, &a.st, &o, &d) == SM_OK, "model with engine order 1");
    r = NULL;
    TU_CHECK(sm_solve(m, om, 6, NULL, NULL, &r, &d) == SM_OK && r && r->n_critical > 0 && !r->refine_stopped,
             "without a stop the 1P crossing is refined (%d)", r ? r->n_critical : -1);
    sm_result_free(r);
    r = NULL;
    calls = 0;
    TU_CHECK(sm_solve(m, om, 6, stop_at_end, &calls, &r, &d) == SM_OK && r, "a stop during refinement: SM_OK");
    TU_CHECK(r && r->refine_stopped && r->n_critical == 0, "refine_stopped 1, no unrefined critical speed");
    for (int i = 0; r && i < 6; i++)
        TU_CHECK(r->cases[i].status == SM_CASE_SOLVED && r->cases[i].n_modes == 3, "kept case %d", i);
    sm_result_free(r);
    /* invalid speeds */
    double bad[2] = {1, -1};
    TU_CHECK(sm_solve(m, bad, 2, NULL, NULL, &r, &d) == SM_INVALID_INPUT && d.item_index == 1,
             "negative speed rejected with its index");
    sm_model_free(m);
    return tu_finish("sweep");
}
