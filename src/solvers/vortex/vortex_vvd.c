/* Neighbour selection of the VVD (diffusive velocities) on the cpu: which
 * leaves of the wake tree a vortex reaches, and the packed list of its
 * neighbours within reach.
 *
 * The pair sums themselves vectorize well once the neighbours are packed
 * (vortex_diffusive.c); packing them is a compaction, which compilers do not
 * vectorize: as a scalar loop it cost more than the sums. With AVX-512 each
 * 8 candidates are tested at once and the accepted ones compressed into
 * place; without it, the plain loop (also kept as the reference the test
 * compares against). Both give the same list in the same order, so the sums
 * and the run's results do not depend on which one ran. The panels near a
 * vortex (its wall terms) are filtered from its group's the same way. */
#include "solvers/vortex/vortex_core.h"

#include <float.h>
#include <math.h>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

/* Insert v into the ascending d2[0..2] of the 3 smallest. */
static void low3_insert(double *d2, double v) {
  if (!(v < d2[2])) return;
  if (v < d2[1]) {
    d2[2] = d2[1];
    if (v < d2[0]) {
      d2[1] = d2[0];
      d2[0] = v;
    } else {
      d2[1] = v;
    }
  } else {
    d2[2] = v;
  }
}

size_t px_vortex_vvd_pack_plain(const double *sx, const double *sy, const double *sg, uint32_t lo,
                                uint32_t hi, uint32_t skip, double xi, double yi, double r2max,
                                double *pdx, double *pdy, double *pg, size_t np, double *low) {
  for (uint32_t sj = lo; sj < hi; ++sj) {
    double dx = xi - sx[sj], dy = yi - sy[sj], r2 = dx * dx + dy * dy;
    int in = r2 <= r2max && sj != skip;
    pdx[np] = dx;
    pdy[np] = dy;
    pg[np] = sg[sj];
    np += (size_t)in;
    if (low && in) low3_insert(low, r2);
  }
  return np;
}

void px_vortex_vvd_low3(const double *low, double *d2) {
#if defined(__AVX512F__)
  /* the lanes' ascending triples merged pairwise, 8 -> 4 -> 2 -> 1 lanes,
   * without branches: the k-th smallest of sorted a, b is the least of
   * max(a_i, b_j) over i + j = k (a_0 = b_0 = -inf) */
  __m512d a1 = _mm512_loadu_pd(low), a2 = _mm512_loadu_pd(low + 8);
  __m512d a3 = _mm512_loadu_pd(low + 16);
  static const long long sh[3][8] = {
      {4, 5, 6, 7, 0, 1, 2, 3}, {2, 3, 0, 1, 6, 7, 4, 5}, {1, 0, 3, 2, 5, 4, 7, 6}};
  for (int r = 0; r < 3; ++r) {
    __m512i ix = _mm512_loadu_si512(sh[r]);
    __m512d b1 = _mm512_permutexvar_pd(ix, a1), b2 = _mm512_permutexvar_pd(ix, a2);
    __m512d b3 = _mm512_permutexvar_pd(ix, a3);
    __m512d c1 = _mm512_min_pd(a1, b1);
    __m512d c2 = _mm512_min_pd(_mm512_min_pd(a2, b2), _mm512_max_pd(a1, b1));
    __m512d c3 = _mm512_min_pd(_mm512_min_pd(a3, b3),
                               _mm512_min_pd(_mm512_max_pd(a1, b2), _mm512_max_pd(a2, b1)));
    a1 = c1;
    a2 = c2;
    a3 = c3;
  }
  d2[0] = _mm512_cvtsd_f64(a1);
  d2[1] = _mm512_cvtsd_f64(a2);
  d2[2] = _mm512_cvtsd_f64(a3);
#else
  d2[0] = d2[1] = d2[2] = INFINITY;
  for (int q = 0; q < PX_VORTEX_VVD_LOW; ++q) low3_insert(d2, low[q]);
#endif
}

void px_vortex_radii_plain(const double *dx, const double *dy, size_t n, double tiny2, double *r,
                           double *rinv) {
  const double lim = tiny2 > DBL_MIN ? tiny2 : DBL_MIN;
  for (size_t q = 0; q < n; ++q) {
    double r2 = dx[q] * dx[q] + dy[q] * dy[q], v = sqrt(r2);
    r[q] = r2 > lim ? v : 0.0;
    if (rinv) rinv[q] = r2 > lim ? 1.0 / v : 0.0;
  }
}

void px_vortex_radii(const double *dx, const double *dy, size_t n, double tiny2, double *r,
                     double *rinv) {
#if defined(__AVX512F__)
  /* 1/sqrt by the 14-bit estimate and two Newton steps, v (3/2 - r2 v^2 / 2):
   * 14 -> 28 -> 53 bits, r = r2 v. A square root and a division per lane
   * had the largest share of the pair loops' time (vortex_diffusive.c,
   * vortex_wall.c). */
  const __m512d half = _mm512_set1_pd(0.5), c15 = _mm512_set1_pd(1.5);
  const __m512d lim = _mm512_set1_pd(tiny2 > DBL_MIN ? tiny2 : DBL_MIN);
  for (size_t q = 0; q < n; q += 8) {
    size_t left = n - q;
    __mmask8 live = left >= 8 ? (__mmask8)0xff : (__mmask8)((1u << left) - 1u);
    __m512d x = _mm512_maskz_loadu_pd(live, dx + q), y = _mm512_maskz_loadu_pd(live, dy + q);
    __m512d r2 = _mm512_add_pd(_mm512_mul_pd(x, x), _mm512_mul_pd(y, y));
    __mmask8 big = _mm512_cmp_pd_mask(r2, lim, _CMP_GT_OQ);
    __m512d v = _mm512_rsqrt14_pd(r2), h = _mm512_mul_pd(half, r2);
    v = _mm512_mul_pd(v, _mm512_fnmadd_pd(_mm512_mul_pd(h, v), v, c15));
    v = _mm512_mul_pd(v, _mm512_fnmadd_pd(_mm512_mul_pd(h, v), v, c15));
    _mm512_mask_storeu_pd(r + q, live, _mm512_maskz_mul_pd(big, r2, v));
    if (rinv) _mm512_mask_storeu_pd(rinv + q, live, _mm512_maskz_mov_pd(big, v));
  }
#else
  px_vortex_radii_plain(dx, dy, n, tiny2, r, rinv);
#endif
}

/* The candidates of the nr runs within sqrt(r2max) of (xi, yi), other than
 * skip: packed into pdx, pdy, pg (store: vvd_pack) or their 3 smallest
 * squared distances kept per lane in low (not NULL: vvd_near). Inlined into
 * its two users, each with its own constants. */
static inline __attribute__((always_inline)) size_t vvd_scan(const double *sx, const double *sy,
                                                             const double *sg, const uint32_t *runs,
                                                             size_t nr, uint32_t skip, double xi,
                                                             double yi, double r2max, double *pdx,
                                                             double *pdy, double *pg, double *low,
                                                             const int store) {
  size_t np = 0;
#if defined(__AVX512F__)
  /* all the runs in one call: the broadcasts and the 3 smallest stay in
   * registers (a call per run reloaded and stored them, 4-5 times a vortex) */
  const __m512d vx = _mm512_set1_pd(xi), vy = _mm512_set1_pd(yi), vr = _mm512_set1_pd(r2max);
  const __m512d inf = _mm512_set1_pd(INFINITY);
  const __m512i lane = _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0);
  /* the 3 smallest accepted r2 of each lane (a min/max insertion network) */
  __m512d m1 = inf, m2 = inf, m3 = inf;
  for (size_t l = 0; l < nr; ++l) {
    const uint32_t hi = runs[2 * l + 1];
    for (uint32_t sj = runs[2 * l]; sj < hi; sj += 8) {
      unsigned left = hi - sj;
      __mmask8 live = left >= 8 ? (__mmask8)0xff : (__mmask8)((1u << left) - 1u);
      __m512d x = _mm512_maskz_loadu_pd(live, sx + sj), y = _mm512_maskz_loadu_pd(live, sy + sj);
      __m512d dx = _mm512_sub_pd(vx, x), dy = _mm512_sub_pd(vy, y);
      /* separate multiply and add: the same rounding as the plain loop's
       * dx * dx + dy * dy (the build does not contract to FMA) */
      __m512d r2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
      __mmask8 in = _mm512_mask_cmp_pd_mask(live, r2, vr, _CMP_LE_OQ);
      if (skip - sj < 8u) /* the vortex itself is in this block */
        in &= (__mmask8)~_mm512_cmpeq_epi64_mask(lane, _mm512_set1_epi64((long long)(skip - sj)));
      if (store) {
        /* compress in registers, then a full-width store: the memory form
         * of vcompress is slow on some cores; the buffers hold 8 entries of
         * slack */
        __m512d g = _mm512_maskz_loadu_pd(live, sg + sj);
        _mm512_storeu_pd(pdx + np, _mm512_maskz_compress_pd(in, dx));
        _mm512_storeu_pd(pdy + np, _mm512_maskz_compress_pd(in, dy));
        _mm512_storeu_pd(pg + np, _mm512_maskz_compress_pd(in, g));
        np += (size_t)__builtin_popcount((unsigned)in);
      }
      if (low) {
        __m512d v = _mm512_mask_blend_pd(in, inf, r2);
        __m512d a = _mm512_min_pd(m1, v);
        v = _mm512_max_pd(m1, v);
        m1 = a;
        a = _mm512_min_pd(m2, v);
        v = _mm512_max_pd(m2, v);
        m2 = a;
        m3 = _mm512_min_pd(m3, v);
      }
    }
  }
  if (low) {
    _mm512_storeu_pd(low, m1);
    _mm512_storeu_pd(low + 8, m2);
    _mm512_storeu_pd(low + 16, m3);
  }
#else
  if (low)
    for (int q = 0; q < PX_VORTEX_VVD_LOW; ++q) low[q] = INFINITY;
  for (size_t l = 0; l < nr; ++l) {
    if (store) {
      np = px_vortex_vvd_pack_plain(sx, sy, sg, runs[2 * l], runs[2 * l + 1], skip, xi, yi, r2max,
                                    pdx, pdy, pg, np, low);
    } else {
      for (uint32_t sj = runs[2 * l]; sj < runs[2 * l + 1]; ++sj) {
        double dx = xi - sx[sj], dy = yi - sy[sj], r2 = dx * dx + dy * dy;
        if (r2 <= r2max && sj != skip) low3_insert(low, r2);
      }
    }
  }
#endif
  return np;
}

size_t px_vortex_vvd_pack(const double *sx, const double *sy, const double *sg,
                          const uint32_t *runs, size_t nr, uint32_t skip, double xi, double yi,
                          double r2max, double *pdx, double *pdy, double *pg) {
  return vvd_scan(sx, sy, sg, runs, nr, skip, xi, yi, r2max, pdx, pdy, pg, NULL, 1);
}

void px_vortex_vvd_near(const double *sx, const double *sy, const uint32_t *runs, size_t nr,
                        uint32_t skip, double xi, double yi, double r2max, double *low) {
  (void)vvd_scan(sx, sy, NULL, runs, nr, skip, xi, yi, r2max, NULL, NULL, NULL, low, 0);
}

size_t px_vortex_vvd_filter_plain(const double *cx, const double *cy, const uint32_t *idx, size_t n,
                                  double xi, double yi, double r2, uint32_t *out) {
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
  uint64_t *lh = (uint64_t *)(lb + 5 * cap);
  for (size_t q = 0; q < nl; ++q) {
    uint32_t l = leaves[q];
    lb[q] = t->bx0[l];
    lb[cap + q] = t->bx1[l];
    lb[2 * cap + q] = t->by0[l];
    lb[3 * cap + q] = t->by1[l];
    lh[q] = (uint64_t)t->lo[l] | (uint64_t)t->hi[l] << 32;
  }
}

/* px_vortex_tree_box_dist2 of leaf q of the boxes lb (as
 * px_vortex_vvd_leaf_boxes lays them out) from (x, y). */
static inline double lb_box_dist2(const double *lb, size_t cap, size_t q, double x, double y) {
  double a = lb[q] - x, b = x - lb[cap + q], c = lb[2 * cap + q] - y, d = y - lb[3 * cap + q];
  double dx = a > b ? a : b, dy = c > d ? c : d;
  dx = dx > 0.0 ? dx : 0.0;
  dy = dy > 0.0 ? dy : 0.0;
  return dx * dx + dy * dy;
}

#if defined(__AVX512F__)
/* Leaves q .. q + 7 of the boxes lb (as px_vortex_vvd_leaf_boxes lays them
 * out, nl in all) within sqrt(r2) of (vx, vy) by px_vortex_tree_box_dist2's
 * test (max of the two sides, clamped at 0); *live: those that exist. */
static inline __attribute__((always_inline)) __mmask8 leaf_boxes_in(const double *lb, size_t cap,
                                                                    size_t q, size_t nl, __m512d vx,
                                                                    __m512d vy, __m512d vr,
                                                                    __mmask8 *live) {
  const double *bx0 = lb, *bx1 = lb + cap, *by0 = lb + 2 * cap, *by1 = lb + 3 * cap;
  const __m512d zero = _mm512_setzero_pd();
  const size_t left = nl - q;
  const __mmask8 lv = left >= 8 ? (__mmask8)0xff : (__mmask8)((1u << left) - 1u);
  __m512d a = _mm512_sub_pd(_mm512_maskz_loadu_pd(lv, bx0 + q), vx);
  __m512d b = _mm512_sub_pd(vx, _mm512_maskz_loadu_pd(lv, bx1 + q));
  __m512d c = _mm512_sub_pd(_mm512_maskz_loadu_pd(lv, by0 + q), vy);
  __m512d d = _mm512_sub_pd(vy, _mm512_maskz_loadu_pd(lv, by1 + q));
  __m512d dx = _mm512_max_pd(_mm512_max_pd(a, b), zero);
  __m512d dy = _mm512_max_pd(_mm512_max_pd(c, d), zero);
  __m512d d2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
  *live = lv;
  return _mm512_mask_cmp_pd_mask(lv, d2, vr, _CMP_LE_OQ);
}
#endif

size_t px_vortex_vvd_leaves_within(const uint32_t *leaves, const double *lb, size_t nl, size_t cap,
                                   double xi, double yi, double r2, uint32_t *out) {
  size_t m = 0;
#if defined(__AVX512F__) && defined(__AVX512VL__)
  const __m512d vx = _mm512_set1_pd(xi), vy = _mm512_set1_pd(yi), vr = _mm512_set1_pd(r2);
  for (size_t q = 0; q < nl; q += 8) {
    __mmask8 live;
    const __mmask8 in = leaf_boxes_in(lb, cap, q, nl, vx, vy, vr, &live);
    __m256i id = _mm256_maskz_loadu_epi32(live, leaves + q);
    _mm256_storeu_si256((__m256i *)(out + m), _mm256_maskz_compress_epi32(in, id));
    m += (size_t)__builtin_popcount((unsigned)in);
  }
#else
  for (size_t q = 0; q < nl; ++q) {
    out[m] = leaves[q];
    m += !(lb_box_dist2(lb, cap, q, xi, yi) > r2);
  }
#endif
  return m;
}

size_t px_vortex_vvd_leaf_runs_plain(const struct px_vortex_tree *t, const uint32_t *leaves,
                                     double *lb, size_t nl, size_t cap, double xi, double yi,
                                     double r2, uint32_t *runs) {
  double *d2 = lb + 4 * cap; /* scratch */
#pragma omp simd
  for (size_t q = 0; q < nl; ++q) d2[q] = lb_box_dist2(lb, cap, q, xi, yi);
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

size_t px_vortex_vvd_leaf_runs(const struct px_vortex_tree *t, const uint32_t *leaves, double *lb,
                               size_t nl, size_t cap, double xi, double yi, double r2,
                               uint32_t *runs) {
#if defined(__AVX512F__)
  /* the leaves within reach compressed 8 at a time (their point ranges,
   * lo | hi << 32, into the scratch array), then merged into runs: the
   * scalar loop sees the ~quarter of the leaves within reach only */
  (void)t;
  (void)leaves;
  const uint64_t *lh = (const uint64_t *)(lb + 5 * cap);
  uint64_t *hit = (uint64_t *)(lb + 4 * cap);
  const __m512d vx = _mm512_set1_pd(xi), vy = _mm512_set1_pd(yi), vr = _mm512_set1_pd(r2);
  size_t nh = 0;
  for (size_t q = 0; q < nl; q += 8) {
    __mmask8 live;
    const __mmask8 in = leaf_boxes_in(lb, cap, q, nl, vx, vy, vr, &live);
    __m512i r = _mm512_maskz_loadu_epi64(live, lh + q);
    _mm512_storeu_si512((void *)(hit + nh), _mm512_maskz_compress_epi64(in, r));
    nh += (size_t)__builtin_popcount((unsigned)in);
  }
  if (nh == 0) return 0;
  /* touching ranges merged without a branch (taken or not about equally
   * often: as a branch, its mispredictions were most of this function's
   * time): the run so far is written at nr each time and kept (nr advances)
   * where the next range does not continue it */
  size_t nr = 0;
  uint32_t rlo = (uint32_t)hit[0], rhi = (uint32_t)(hit[0] >> 32);
  for (size_t k = 1; k < nh; ++k) {
    const uint32_t lo = (uint32_t)hit[k], hi = (uint32_t)(hit[k] >> 32);
    const uint32_t gap = rhi != lo;
    runs[2 * nr] = rlo;
    runs[2 * nr + 1] = rhi;
    nr += gap;
    rlo ^= (rlo ^ lo) & (0u - gap); /* gap ? lo : rlo, which gcc turns into a branch */
    rhi = hi;
  }
  runs[2 * nr] = rlo;
  runs[2 * nr + 1] = rhi;
  return nr + 1;
#else
  return px_vortex_vvd_leaf_runs_plain(t, leaves, lb, nl, cap, xi, yi, r2, runs);
#endif
}
