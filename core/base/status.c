/*
 * status.c — the project's status table (sm_status) as text, the version, and the one writer
 * of input refusals into an sm_diag (diag.h).
 */
#include "diag.h"
#include "spinmodal.h"

#include <stdio.h>

const char *sm_strerror(int status)
{
    switch (status) {
#define SM_STATUS_TEXT(name, value, text) \
    case SM_##name:                       \
        return text;
        SM_STATUS_MAP(SM_STATUS_TEXT)
#undef SM_STATUS_TEXT
    default:
        return "unknown status";
    }
}

const char *sm_version(void)
{
    return SM_VERSION;
}

int smi_input_fail(sm_diag *d, sm_item item, int index, const char *field, const char *msg)
{
    if (d) {
        d->status = SM_INVALID_INPUT;
        d->item = item;
        d->item_index = index;
        snprintf(d->field, sizeof d->field, "%s", field ? field : "");
        snprintf(d->message, sizeof d->message, "%s", msg);
    }
    return SM_INVALID_INPUT;
}
