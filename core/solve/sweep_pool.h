/*
 * sweep_pool.h — the speeds of a sweep finished on several threads (not installed; issue 27,
 * DESIGN.md 2.1).
 *
 * The continuation (sweep.c) stays on the thread that called sm_solve: each equilibrium starts
 * from the one before.  Once a speed's equilibrium is found, the rest of its case (steady-state
 * outputs, linearisation, eigen-analysis, shapes: sweep_case_finish) depends on that equilibrium
 * and the model alone, so a worker with its own smi_lin finishes it while the calling thread goes
 * on to the next speed.  Each case's numbers are the same bits on any number of threads.  The
 * progress callback is only ever called from the calling thread (spinmodal.h); workers stop
 * when the pool is told to.
 *
 * Warm starts (issue 27): the speeds, in ascending order, form chunks of SWEEP_WARM_CHUNK (a
 * spatial model on the tree path; chunks of one case otherwise, sweep_chunk); the
 * eigen-analysis of a chunk's first speed starts cold, each of the others from the modes of the
 * speed before it (smi_lin_warm).  One thread finishes a whole chunk in order, on its own
 * smi_lin, so a speed's start, and its bits, do not depend on the number of threads.
 */
#ifndef SM_SWEEP_POOL_H
#define SM_SWEEP_POOL_H

#include "linsys.h"

/* Consecutive speeds whose eigen-analyses chain their starts: the longer, the fewer cold starts
 * (−11 % instructions for a 101-speed spatial sweep at 8) and the fewer chunks to share among
 * threads (13 for 101 speeds). */
#define SWEEP_WARM_CHUNK 8

/** The cases one thread finishes in a row (a chunk): SWEEP_WARM_CHUNK where the eigen-analysis
 *  chains its starts (a spatial model on the tree path), else 1: there a case's bits do not depend
 *  on the case before, and any free thread takes the next case.  A planar sweep's last chunk of 8
 *  kept one thread busy for up to 8 cases after the continuation ended (issue 27 goal 3). */
int sweep_chunk(const sm_model *m);

/** Steady-state outputs of case c at its equilibrium q (c->converged set by the caller), and with
 *  c->converged its modes and shapes, on L (SMI_USE_MODES, this thread's own), then after(m, c)
 *  when c has modes (after may be NULL).  pr: the stop callback the tree path asks.  Returns
 *  SM_OK (an eigen-analysis failure is reported on the case), SM_NOMEM, SM_CANCELED or after's
 *  negative status. */
int sweep_case_finish(const sm_model *m, const double *q, smi_lin *L, const sm_progress *pr,
                      sweep_case_fn after, sm_case *c);

typedef struct sweep_pool sweep_pool;

/** A pool for n_cases cases of m (queued in ascending speed order) on threads - 1 workers
 *  (threads >= 2) besides the calling thread; after: sweep_case_finish's.  SM_OK or SM_NOMEM
 *  (*out NULL: finish the cases on the calling thread). */
int sweep_pool_new(const sm_model *m, int threads, int n_cases, sweep_case_fn after,
                   sweep_pool **out);
/** Queue case c at its equilibrium q (n values, copied).  SM_OK or SM_NOMEM (nothing queued). */
int sweep_pool_add(sweep_pool *p, sm_case *c, const double *q);
/** Cases finished so far (any thread). */
int sweep_pool_finished(sweep_pool *p);
/** Ask the workers to stop: the cases not started are left, a running eigen-analysis on the tree
 *  path stops at its next check. */
void sweep_pool_stop(sweep_pool *p);
/** Finish the queued cases, the calling thread taking its share of chunks on L with pr (its callback asked
 *  with the cases finished between them and while it waits; a nonzero answer before the last
 *  stops the pool), wait for the workers and end them.  Returns SM_OK, or the first SM_NOMEM or
 *  SM_CANCELED of any thread. */
int sweep_pool_finish(sweep_pool *p, smi_lin *L, sm_progress *pr);
/** End the workers (after sweep_pool_stop when cases are left) and free p; NULL is fine. */
void sweep_pool_free(sweep_pool *p);

#endif
