/*
 * xorshift.h — the codec tests' reproducible random numbers (Marsaglia's xorshift64, shifts 13,
 * 7, 17): numtext_test.c and jsonread_test.c, each with its own seed.
 */
#ifndef SPINMODAL_TESTS_XORSHIFT_H
#define SPINMODAL_TESTS_XORSHIFT_H

#include <stdint.h>

/* The next number of the sequence in *state (never 0). */
static inline uint64_t xorshift64(uint64_t *state)
{
    uint64_t x = *state;
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    return *state = x;
}

#endif /* SPINMODAL_TESTS_XORSHIFT_H */
