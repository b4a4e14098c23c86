/*
 * fuzz_rng.h -- the xorshift64 generator the deterministic fuzz drivers
 * share (fuzz_driver.h, fuzz_frame.c): a fixed seed, so a CI run's inputs
 * are the same every time and a finding can be replayed.
 */
#ifndef SILC_FUZZ_RNG_H
#define SILC_FUZZ_RNG_H

#include <stdint.h>

static uint64_t fuzz_rng = 0x9E3779B97F4A7C15ull;

static inline uint64_t fuzz_next(void)
{
    fuzz_rng ^= fuzz_rng << 13;
    fuzz_rng ^= fuzz_rng >> 7;
    fuzz_rng ^= fuzz_rng << 17;
    return fuzz_rng;
}

#endif
