/* The SIMD instruction set this build was compiled for ("AVX-512", "AVX2",
 * ..., "scalar"): what `#pragma omp simd` loops can use. A property of the
 * build (the compiler's target macros), reported by `partix info` and by the
 * cpu backend's description. */
#ifndef PX_CORE_SIMD_H
#define PX_CORE_SIMD_H

static inline const char *px_simd_isa(void) {
#if defined(__AVX512F__)
  return "AVX-512";
#elif defined(__AVX2__)
  return "AVX2";
#elif defined(__AVX__)
  return "AVX";
#elif defined(__SSE4_2__)
  return "SSE4.2";
#elif defined(__SSE2__)
  return "SSE2";
#elif defined(__ARM_FEATURE_SVE)
  return "SVE";
#elif defined(__ARM_NEON)
  return "NEON";
#else
  return "scalar";
#endif
}

#endif
