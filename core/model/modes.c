/*
 * modes.c — the component-mode driver (DESIGN.md 1.2): the basis of every substructure through
 * its kind (m->kind->basis: planar/modes_planar.c, spatial/modes3.c), the coordinate offsets q0
 * and n, then the kind's mass points; a progress/cancel callback between frames.
 */
#include "kind.h"

#include <stdio.h>

static int modes_fail(sm_diag *d, int rc, const char *msg)
{
    if (d) {
        d->status = rc;
        snprintf(d->message, sizeof d->message, "%s", msg);
    }
    return rc;
}

int modes_build(sm_model *m, sm_progress_fn cb, void *user, sm_diag *d)
{
    int rc = SM_OK, q0 = m->base; /* a free base's coordinates come first */
    for (int s = 0; s < m->n_subs && rc == SM_OK; s++) {
        if (cb && s > 0 && cb(user, s, m->n_subs)) {
            d->status = SM_CANCELED;
            snprintf(d->message, sizeof d->message,
                     "canceled while building the component modes (%d of %d frames done)", s,
                     m->n_subs);
            return SM_CANCELED;
        }
        sm_sub *b = &m->subs[s];
        rc = m->kind->basis(m, b);
        b->q0 = q0;
        q0 += b->m;
    }
    m->n = q0;
    if (rc == SM_OK)
        rc = m->kind->points(m);
    if (rc < 0 && rc != SM_NOMEM)
        return modes_fail(d, rc, "could not compute the component modes of a substructure");
    if (rc == SM_NOMEM)
        return modes_fail(d, rc, "out of memory while building the component modes");
    return SM_OK;
}
