/* Neighbour selection of the VVD (diffusive velocities) on the cpu: which
 * leaves of the wake tree a vortex reaches, and the packed list of its
 * neighbours within reach.
 *
 * The pair sums themselves vectorize well once the neighbours are packed
 * (vortex_core.c); packing them is a compaction, which compilers do not
 * vectorize: as a scalar loop it cost more than the sums. With AVX-512 each
 * 8 candidates are tested at once and the accepted ones compressed into
 * place; without it, the plain loop (also kept as the reference the test
 * compares against). Both give the same list in the same order, so the sums
 * and the run's results do not depend on which one ran. The panels near a
 * vortex (its wall terms) are filtered from its group's the same way. */
#include "solvers/vortex/vortex_core.h"

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

size_t px_vortex_vvd_pack_plain(const double *sx, const double *sy, const double *sg, uint32_t lo,
                                uint32_t hi, uint32_t skip, double xi, double yi, double r2max,
                                double *pdx, double *pdy, double *pg, size_t np) {
  for (uint32_t sj = lo; sj < hi; ++sj) {
    double dx = xi - sx[sj], dy = yi - sy[sj];
    pdx[np] = dx;
    pdy[np] = dy;
    pg[np] = sg[sj];
    np += (dx * dx + dy * dy <= r2max && sj != skip);
  }
  return np;
}

size_t px_vortex_vvd_pack(const double *sx, const double *sy, const double *sg, uint32_t lo,
                          uint32_t hi, uint32_t skip, double xi, double yi, double r2max,
                          double *pdx, double *pdy, double *pg, size_t np) {
#if defined(__AVX512F__)
  const __m512d vx = _mm512_set1_pd(xi), vy = _mm512_set1_pd(yi), vr = _mm512_set1_pd(r2max);
  const __m512i lane = _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0);
  uint32_t sj = lo;
  for (; sj < hi; sj += 8) {
    unsigned left = hi - sj;
    __mmask8 live = left >= 8 ? (__mmask8)0xff : (__mmask8)((1u << left) - 1u);
    __m512d x = _mm512_maskz_loadu_pd(live, sx + sj), y = _mm512_maskz_loadu_pd(live, sy + sj);
    __m512d g = _mm512_maskz_loadu_pd(live, sg + sj);
    __m512d dx = _mm512_sub_pd(vx, x), dy = _mm512_sub_pd(vy, y);
    /* separate multiply and add: the same rounding as the plain loop's
     * dx * dx + dy * dy (the build does not contract to FMA) */
    __m512d r2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
    __mmask8 in = _mm512_mask_cmp_pd_mask(live, r2, vr, _CMP_LE_OQ);
    if (skip - sj < 8u) /* the vortex itself is in this block */
      in &= (__mmask8)~_mm512_cmpeq_epi64_mask(lane, _mm512_set1_epi64((long long)(skip - sj)));
    /* compress in registers, then a full-width store: the memory form of
     * vcompress is slow on some cores; the buffers hold 8 entries of slack */
    _mm512_storeu_pd(pdx + np, _mm512_maskz_compress_pd(in, dx));
    _mm512_storeu_pd(pdy + np, _mm512_maskz_compress_pd(in, dy));
    _mm512_storeu_pd(pg + np, _mm512_maskz_compress_pd(in, g));
    np += (size_t)__builtin_popcount((unsigned)in);
  }
  return np;
#else
  return px_vortex_vvd_pack_plain(sx, sy, sg, lo, hi, skip, xi, yi, r2max, pdx, pdy, pg, np);
#endif
}

size_t px_vortex_vvd_filter_plain(const double *cx, const double *cy, const uint32_t *idx,
                                  size_t n, double xi, double yi, double r2, uint32_t *out) {
  size_t m = 0;
  for (size_t q = 0; q < n; ++q) {
    double dx = cx[q] - xi, dy = cy[q] - yi;
    out[m] = idx[q];
    m += dx * dx + dy * dy <= r2;
  }
  return m;
}

size_t px_vortex_vvd_filter(const double *cx, const double *cy, const uint32_t *idx, size_t n,
                            double xi, double yi, double r2, uint32_t *out) {
#if defined(__AVX512F__) && defined(__AVX512VL__)
  const __m512d vx = _mm512_set1_pd(xi), vy = _mm512_set1_pd(yi), vr = _mm512_set1_pd(r2);
  size_t m = 0;
  for (size_t q = 0; q < n; q += 8) {
    size_t left = n - q;
    __mmask8 live = left >= 8 ? (__mmask8)0xff : (__mmask8)((1u << left) - 1u);
    __m512d dx = _mm512_sub_pd(_mm512_maskz_loadu_pd(live, cx + q), vx);
    __m512d dy = _mm512_sub_pd(_mm512_maskz_loadu_pd(live, cy + q), vy);
    __m512d d2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
    __mmask8 in = _mm512_mask_cmp_pd_mask(live, d2, vr, _CMP_LE_OQ);
    __m256i id = _mm256_maskz_loadu_epi32(live, idx + q);
    _mm256_storeu_si256((__m256i *)(out + m), _mm256_maskz_compress_epi32(in, id));
    m += (size_t)__builtin_popcount((unsigned)in);
  }
  return m;
#else
  return px_vortex_vvd_filter_plain(cx, cy, idx, n, xi, yi, r2, out);
#endif
}

void px_vortex_vvd_leaf_boxes(const struct px_vortex_tree *t, const uint32_t *leaves, size_t nl,
                              double *lb, size_t cap) {
  for (size_t q = 0; q < nl; ++q) {
    uint32_t l = leaves[q];
    lb[q] = t->bx0[l];
    lb[cap + q] = t->bx1[l];
    lb[2 * cap + q] = t->by0[l];
    lb[3 * cap + q] = t->by1[l];
  }
}

size_t px_vortex_vvd_leaf_runs(const struct px_vortex_tree *t, const uint32_t *leaves, double *lb,
                               size_t nl, size_t cap, double xi, double yi, double r2,
                               uint32_t *runs) {
  const double *bx0 = lb, *bx1 = lb + cap, *by0 = lb + 2 * cap, *by1 = lb + 3 * cap;
  double *d2 = lb + 4 * cap;
#pragma omp simd
  for (size_t q = 0; q < nl; ++q) {
    /* px_vortex_tree_box_dist2 */
    double a = bx0[q] - xi, b = xi - bx1[q], c = by0[q] - yi, d = yi - by1[q];
    double dx = a > b ? a : b, dy = c > d ? c : d;
    dx = dx > 0.0 ? dx : 0.0;
    dy = dy > 0.0 ? dy : 0.0;
    d2[q] = dx * dx + dy * dy;
  }
  size_t nr = 0;
  for (size_t q = 0; q < nl; ++q) {
    if (d2[q] > r2) continue;
    uint32_t l = leaves[q];
    if (nr > 0 && runs[2 * nr - 1] == t->lo[l]) {
      runs[2 * nr - 1] = t->hi[l];
    } else {
      runs[2 * nr] = t->lo[l];
      runs[2 * nr + 1] = t->hi[l];
      ++nr;
    }
  }
  return nr;
}
