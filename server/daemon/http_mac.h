/*
 * http_mac.h — GET /v1/analyses/{id}/mac?with={id}: the MAC table between the
 * modes of two stored results (http_mac.c; DESIGN.md 9.2).
 */
#ifndef SPINMODAL_HTTP_MAC_H
#define SPINMODAL_HTTP_MAC_H

#include "http_internal.h"

/** GET /v1/analyses/{id}/mac?with=ID2[&case=K][&case_b=K][&format=json|csv]. */
enum MHD_Result http_get_mac(struct MHD_Connection *c, http_req *r);

#endif /* SPINMODAL_HTTP_MAC_H */
