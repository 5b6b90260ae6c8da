/* Random numbers: xoshiro256** (Blackman & Vigna 2018) seeded by splitmix64.
 * The state is four 64-bit words owned by the caller, so it can be saved in a
 * checkpoint and restored exactly. */
#ifndef PARTIX_RNG_H
#define PARTIX_RNG_H

#include <stdint.h>

#include "partix/export.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PX_RNG_WORDS 4

PX_API void px_rng_seed(uint64_t state[PX_RNG_WORDS], uint64_t seed);
PX_API uint64_t px_rng_next(uint64_t state[PX_RNG_WORDS]);
/* Uniform in [0, 1) with 53 random bits. */
PX_API double px_rng_uniform(uint64_t state[PX_RNG_WORDS]);
/* Standard normal (Box–Muller, no cached value so the state stays 4 words). */
PX_API double px_rng_normal(uint64_t state[PX_RNG_WORDS]);

#ifdef __cplusplus
}
#endif
#endif
