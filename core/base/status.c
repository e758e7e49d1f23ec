/*
 * status.c — the project's status table (sm_status) as text, and the version.
 */
#include "spinmodal.h"

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
