/* Part of the template lattice_cpu_impl.h (included by it once per real
 * type, after LT_SIMD and px_real): the per-row flag rows the simd loops
 * read. */
#ifndef PX_LATTICE_CPU_FLAGS_IMPL_H
#define PX_LATTICE_CPU_FLAGS_IMPL_H

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

/* The link flags (lt_lfl) of the simd loops come from a per-row real array
 * (lt_cpu_row_flags) rather than from the uint8 link bytes: gcc sizes a
 * loop's vector by its narrowest type, so one uint8 load makes it 64 lanes
 * wide (8 zmm registers per double, no vector iteration at all for rows
 * under 64 cells) or 16 lanes of 128-bit vectors (4 xmm registers per
 * float), whatever simdlen says; with reals only it is one register per
 * value. */

/* Flags of row cells x in [lo, hi) (element base + x) into fl[c os + x]:
 * c = 0..5 the link flags in lt_lfl order, c = 6 the free flag. The bytes
 * of the cells `ahead` elements further (the row the sweep takes two rows
 * later: every caller goes row by row, 2 n0) are prefetched: the loads of
 * the link bytes missed the cache and were most of this function's time,
 * which was 9 % of an RK4 link-once step at 100^3 in float; with the
 * prefetch and the vector loop below 2.6 %, the step about 10 % faster
 * (lattice_step, one thread, alternated, 2026-11-28). */
static void lt_cpu_row_flags(const uint8_t *restrict lpv, const uint8_t *restrict lmv,
                             const uint8_t *restrict frv, size_t base, long lo, long hi,
                             px_real *restrict fl, size_t os, size_t ahead) {
  long x;
  /* addresses by integers: the rows ahead of the body's last ones lie past
   * its arrays (a prefetch never faults) */
  const uintptr_t pa = (uintptr_t)(lpv + base) + ahead, pb = (uintptr_t)(lmv + base) + ahead,
                  pc = (uintptr_t)(frv + base) + ahead;
  for (x = lo; x < hi; x += 64) {
    __builtin_prefetch((const void *)(pa + (uintptr_t)x));
    __builtin_prefetch((const void *)(pb + (uintptr_t)x));
    __builtin_prefetch((const void *)(pc + (uintptr_t)x));
  }
#if defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512VL__)
  /* a vector of reals at a time, the row's tail masked: the simd loop
   * below runs 64 byte lanes (its narrowest type), leaving rows of fewer
   * cells, and each row's last up to 63, to a scalar loop */
#if PX_REAL_IS_DOUBLE
  enum { W = 8 };
#else
  enum { W = 16 };
#endif
  const __m512i one = _mm512_set1_epi32(1);
  for (x = lo; x < hi; x += W) {
    const long left = hi - x;
    const __mmask16 m = left >= W ? (__mmask16)((1u << W) - 1u) : (__mmask16)((1u << left) - 1u);
    const size_t i = base + (size_t)x, xs = (size_t)x;
    /* the bytes as 32-bit lanes, each flag bit shifted down to bit 0 */
    const __m512i lp = _mm512_cvtepu8_epi32(_mm_maskz_loadu_epi8(m, lpv + i));
    const __m512i lm = _mm512_cvtepu8_epi32(_mm_maskz_loadu_epi8(m, lmv + i));
    const __m512i fr = _mm512_cvtepu8_epi32(_mm_maskz_loadu_epi8(m, frv + i));
    const __m512i f[7] = {_mm512_and_si512(lp, one),
                          _mm512_and_si512(_mm512_srli_epi32(lp, 1), one),
                          _mm512_and_si512(_mm512_srli_epi32(lp, 2), one),
                          _mm512_and_si512(_mm512_srli_epi32(lm, 3), one),
                          _mm512_and_si512(_mm512_srli_epi32(lm, 4), one),
                          _mm512_and_si512(_mm512_srli_epi32(lm, 5), one),
                          fr};
    for (int c = 0; c < 7; ++c) {
#if PX_REAL_IS_DOUBLE
      _mm512_mask_storeu_pd(fl + (size_t)c * os + xs, (__mmask8)m,
                            _mm512_cvtepi32_pd(_mm512_castsi512_si256(f[c])));
#else
      _mm512_mask_storeu_ps(fl + (size_t)c * os + xs, m, _mm512_cvtepi32_ps(f[c]));
#endif
    }
  }
#else
  /* the seven flag rows are disjoint (os >= the row's cells): without the
   * simd pragma gcc left this loop scalar, 12 % of an RK4 link-once step */
#pragma omp simd
  for (x = lo; x < hi; ++x) {
    const size_t i = base + (size_t)x, xs = (size_t)x;
    const unsigned lp = lpv[i], lm = lmv[i];
    fl[xs] = (px_real)(lp & 1u);
    fl[os + xs] = (px_real)((lp >> 1) & 1u);
    fl[2 * os + xs] = (px_real)((lp >> 2) & 1u);
    fl[3 * os + xs] = (px_real)((lm >> 3) & 1u);
    fl[4 * os + xs] = (px_real)((lm >> 4) & 1u);
    fl[5 * os + xs] = (px_real)((lm >> 5) & 1u);
    fl[6 * os + xs] = (px_real)frv[i];
  }
#endif
}

/* Flags of row cell x from the flag rows. */
PX_FN_INLINE struct lt_lfl lt_lfl_row(const px_real *restrict fl, size_t os, size_t x) {
  struct lt_lfl f;
  f.xp = fl[x];
  f.yp = fl[os + x];
  f.zp = fl[2 * os + x];
  f.xm = fl[3 * os + x];
  f.ym = fl[4 * os + x];
  f.zm = fl[5 * os + x];
  return f;
}

#endif
