/*
 * fuzz.h — the libFuzzer entry point, declared once for the fuzz targets and
 * for main.c, the replay driver that runs them without a fuzzing engine.
 */
#ifndef SPINMODAL_FUZZ_H
#define SPINMODAL_FUZZ_H

#include <stddef.h>
#include <stdint.h>

/**
 * Run one input (borrowed, size bytes, not NUL-terminated) through the target.
 * Returns 0; an invariant violation calls abort().
 */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#endif /* SPINMODAL_FUZZ_H */
