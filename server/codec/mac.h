/*
 * mac.h — MAC tables between the modes of two results, or of a result and a
 * BModes .out shape table (DESIGN.md 9.2): the codec side of core's sm_mac.
 *
 * How it fits: the CLI (`spinmodal compare`) and the daemon
 * (GET /v1/analyses/{a}/mac/{b}) read each side into a codec_mac_set
 * (codec_mac_from_result from a result document, codec_mac_from_bmodes_out
 * from BModes' text), then codec_mac_doc calls sm_mac and writes the JSON
 * table, codec_mac_csv its CSV.  No numerics here beyond reading shapes.
 */
#ifndef SPINMODAL_CODEC_MAC_H
#define SPINMODAL_CODEC_MAC_H

#include <stddef.h>

#include <jansson.h>

#include "spinmodal.h"

/** Components compared: hub-frame translations, or BModes' flap and lag displacements. */
enum { CODEC_MAC_HUB = 0, CODEC_MAC_FLAP_LAG = 1 };

/** One side of a comparison: the shapes (sh points into the arrays) and what to show of it. */
typedef struct codec_mac_set {
    sm_mac_shapes sh;
    double *s, *re, *im, *freq_hz;
    int *seg;
    long case_no;     /* 1-based case of a result, 0 for a BModes table */
    double omega;     /* rad/s of that case (a BModes table: NAN) */
    const char *kind; /* "result" or "bmodes_out" */
    json_t *labels;   /* the modes' labels (strings or null), owned */
} codec_mac_set;

/** Frees what x owns and zeroes it. */
void codec_mac_set_free(codec_mac_set *x);

/**
 * Case case_no (1-based) of a result document into x: each member's nodes (model.members, a
 * spatial result with mode shapes) or, without members (planar), every node by index; the
 * components per `comp` (CODEC_MAC_FLAP_LAG: d.e3 and -d.e2, BModes' flap and lag; needs
 * members).  SM_INVALID_INPUT with the reason in err (no such case, no shapes), SM_NOMEM.
 */
int codec_mac_from_result(codec_mac_set *x, const json_t *result, long case_no, int comp, char *err,
                          size_t errcap);

/**
 * The mode-shape tables of a BModes .out (text, len bytes) into x: per mode its frequency,
 * span_loc and the flap and lag displacement columns (a tower's: s-s and f-a, the same
 * columns).  SM_INVALID_INPUT with "line N: ..." in err when it is not such a file.
 */
int codec_mac_from_bmodes_out(codec_mac_set *x, const char *text, size_t len, char *err,
                              size_t errcap);

/**
 * The MAC table of a against b (sm_mac): {"a": {...}, "b": {...}, "matching", "components",
 * "mac": [[...]] rows = modes of a, "best": per mode of a the mode of b of largest MAC}.
 * SM_INVALID_INPUT with sm_mac's reason in err, SM_NOMEM.
 */
int codec_mac_doc(json_t **doc, const codec_mac_set *a, const codec_mac_set *b, int comp, char *err,
                  size_t errcap);

/** The table as CSV: mode_a,frequency_hz_a,label_a, then one column per mode of b. */
int codec_mac_csv(char **out, size_t *len, const json_t *doc);

#endif /* SPINMODAL_CODEC_MAC_H */
