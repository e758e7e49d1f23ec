/*
 * diag.h — writing a refusal into an sm_diag (not installed; base layer).
 */
#ifndef SM_DIAG_H
#define SM_DIAG_H

#include "spinmodal.h"

/** Record an invalid input in d (may be NULL): status SM_INVALID_INPUT, the item, its index, the
 *  field (NULL: none) and the message; returns SM_INVALID_INPUT.  The one writer of input
 *  refusals for mesh.c and both kinds' checks (base/status.c). */
int smi_input_fail(sm_diag *d, sm_item item, int index, const char *field, const char *msg);

#endif
