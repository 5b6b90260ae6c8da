#include "partix/rng.h"

#include <math.h>

/* splitmix64 (Steele, Lea & Flood 2014) expands a 64-bit seed into the state. */
static uint64_t px_rng_splitmix(uint64_t *x) {
  uint64_t z = (*x += UINT64_C(0x9E3779B97F4A7C15));
  z = (z ^ (z >> 30)) * UINT64_C(0xBF58476D1CE4E5B9);
  z = (z ^ (z >> 27)) * UINT64_C(0x94D049BB133111EB);
  return z ^ (z >> 31);
}

static uint64_t px_rng_rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

void px_rng_seed(uint64_t state[PX_RNG_WORDS], uint64_t seed) {
  int i;
  for (i = 0; i < PX_RNG_WORDS; ++i) state[i] = px_rng_splitmix(&seed);
}

/* xoshiro256** 1.0, Blackman & Vigna, "Scrambled linear pseudorandom number
 * generators", ACM TOMS 47 (2021). */
uint64_t px_rng_next(uint64_t s[PX_RNG_WORDS]) {
  const uint64_t result = px_rng_rotl(s[1] * 5, 7) * 9;
  const uint64_t t = s[1] << 17;
  s[2] ^= s[0];
  s[3] ^= s[1];
  s[1] ^= s[2];
  s[0] ^= s[3];
  s[2] ^= t;
  s[3] = px_rng_rotl(s[3], 45);
  return result;
}

double px_rng_uniform(uint64_t s[PX_RNG_WORDS]) {
  return (double)(px_rng_next(s) >> 11) * 0x1.0p-53;
}

double px_rng_normal(uint64_t s[PX_RNG_WORDS]) {
  const double two_pi = 6.283185307179586476925286766559;
  double u1 = 1.0 - px_rng_uniform(s); /* (0, 1] */
  double u2 = px_rng_uniform(s);
  return sqrt(-2.0 * log(u1)) * cos(two_pi * u2);
}
