/*
 * codec_test.h — what the files of the codec test share (codec_test.c runs
 * the data folders and the planar unit checks, spatial_units.c the unit
 * checks of spatial requests).
 */
#ifndef SPINMODAL_CODEC_TEST_H
#define SPINMODAL_CODEC_TEST_H

#include "codec.h"
#include "codec_internal.h" /* req_parse_codec_only */

/* Failure messages of the current case. */
typedef struct test_case {
    const char *name; /* folder name */
    int failures;     /* checks that failed */
} test_case;

/** Record a failed check of tc and print it (the first one prints the case name). */
void fail(test_case *tc, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/** Unit checks of spatial requests: diag pointers, result rows (spatial_units.c). */
void unit_spatial_diag(test_case *tc);
void unit_spatial_result(test_case *tc);

/** A solved blade-form request: frequency_hz, per_rev, rpm in JSON and CSV (blade_units.c). */
void unit_blade_result(test_case *tc);

/** The result's text against its tree, and the size estimate against it (size_units.c). */
void unit_result_size(test_case *tc);

#endif /* SPINMODAL_CODEC_TEST_H */
