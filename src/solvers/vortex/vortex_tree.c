/* Morton-ordered bounding-volume tree (see vortex_tree.h). */
#include "solvers/vortex/vortex_tree.h"

#include <math.h>
#include <string.h>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "core/radix.h"
#include "partix/memory.h"

void px_vortex_tree_init(struct px_vortex_tree *t) { memset(t, 0, sizeof *t); }

void px_vortex_tree_free(struct px_context *ctx, struct px_vortex_tree *t) {
  px_mem_free(ctx, t->order);
  px_mem_free(ctx, t->sx);
  px_mem_free(ctx, t->sy);
  px_mem_free(ctx, t->lo);
  px_mem_free(ctx, t->hi);
  px_mem_free(ctx, t->left);
  px_mem_free(ctx, t->bx0);
  px_mem_free(ctx, t->key);
  px_mem_free(ctx, t->key2);
  px_mem_free(ctx, t->ord2);
  px_mem_free(ctx, t->leaf_of);
  px_vortex_tree_init(t);
}

/* Room for ncap nodes (their contents are kept). */
static enum px_status grow_nodes(struct px_context *ctx, struct px_vortex_tree *t, size_t ncap) {
  if (ncap <= t->node_cap && t->lo) return PX_STATUS_OK;
  uint32_t *lo = px_mem_realloc(ctx, "vortex.tree", t->lo, ncap * sizeof(uint32_t));
  if (lo) t->lo = lo;
  uint32_t *hi = px_mem_realloc(ctx, "vortex.tree", t->hi, ncap * sizeof(uint32_t));
  if (hi) t->hi = hi;
  int32_t *left = px_mem_realloc(ctx, "vortex.tree", t->left, ncap * sizeof(int32_t));
  if (left) t->left = left;
  double *box = px_mem_alloc(ctx, "vortex.tree", 4 * ncap * sizeof(double));
  if (!lo || !hi || !left || !box) {
    px_mem_free(ctx, box);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for the wake tree nodes");
  }
  if (t->bx0) { /* boxes are filled after the nodes: nothing to keep */
    px_mem_free(ctx, t->bx0);
  }
  t->bx0 = box;
  t->node_cap = ncap;
  t->by0 = t->bx0 + ncap;
  t->bx1 = t->bx0 + 2 * ncap;
  t->by1 = t->bx0 + 3 * ncap;
  return PX_STATUS_OK;
}

static enum px_status grow(struct px_context *ctx, struct px_vortex_tree *t, size_t n) {
  if (n <= t->cap && t->order) return PX_STATUS_OK;
  size_t cap = n + n / 2 + 64;
  px_mem_free(ctx, t->order);
  px_mem_free(ctx, t->sx);
  px_mem_free(ctx, t->sy);
  px_mem_free(ctx, t->key);
  px_mem_free(ctx, t->key2);
  px_mem_free(ctx, t->ord2);
  px_mem_free(ctx, t->leaf_of);
  t->leaf_of = px_mem_alloc(ctx, "vortex.tree", cap * sizeof(uint32_t));
  t->order = px_mem_alloc(ctx, "vortex.tree", cap * sizeof(uint32_t));
  t->ord2 = px_mem_alloc(ctx, "vortex.tree", cap * sizeof(uint32_t));
  t->sx = px_mem_alloc(ctx, "vortex.tree", cap * sizeof(double));
  t->sy = px_mem_alloc(ctx, "vortex.tree", cap * sizeof(double));
  t->key = px_mem_alloc(ctx, "vortex.tree", cap * sizeof(uint64_t));
  t->key2 = px_mem_alloc(ctx, "vortex.tree", cap * sizeof(uint64_t));
  if (!t->leaf_of || !t->order || !t->ord2 || !t->sx || !t->sy || !t->key || !t->key2)
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for the wake tree (%zu points)", n);
  t->cap = cap;
  /* cap / 2 nodes: room for leaves of 4 points on average (the wake's
   * leaves of at most 32 average 21, the panels' of at most 8 about 6);
   * build_nodes grows them where a tree needs more */
  return grow_nodes(ctx, t, 2 * (cap / 4 + 1) + 64);
}

/* Where node [lo, hi) of the sorted keys splits: at the first key with the
 * highest bit in which key[lo] and key[hi - 1] differ set (the same prefix
 * above it), so that each child is a cell of the Morton grid; at the middle
 * index if the keys are all equal. */
static uint32_t split_at(const uint64_t *key, uint32_t lo, uint32_t hi) {
  const uint64_t a = key[lo], b = key[hi - 1];
  if (a == b) return lo + (hi - lo) / 2;
  const int bit = 63 - __builtin_clzll(a ^ b);
  const uint64_t first = ((a >> bit) | 1u) << bit; /* a has 0 there, b 1 */
  /* the first position in [lo + 1, hi - 1] with key >= first (key[hi - 1]
   * is): a binary search without branches, whose outcomes are random */
  uint32_t base = lo + 1, m = hi - 1 - lo;
  while (m > 1) {
    const uint32_t half = m / 2;
    base = key[base + half - 1] < first ? base + half : base;
    m -= half;
  }
  return base;
}

#if defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512CD__)
#define VX_SPLIT_SCAN 1
/* d[i], i < n - 1: 1 + the highest bit in which sorted keys i and i + 1
 * differ, 0 where they are equal. */
static void split_bits(const uint64_t *key, size_t n, uint8_t *d) {
  for (size_t i = 0; i + 1 < n; i += 8) {
    const size_t left = n - 1 - i;
    const __mmask8 m = left >= 8 ? (__mmask8)0xff : (__mmask8)((1u << left) - 1u);
    const __m512i x = _mm512_xor_si512(_mm512_maskz_loadu_epi64(m, key + i),
                                       _mm512_maskz_loadu_epi64(m, key + i + 1));
    /* 64 - lzcnt: 0 for x = 0 */
    const __m512i b = _mm512_sub_epi64(_mm512_set1_epi64(64), _mm512_lzcnt_epi64(x));
    _mm512_mask_cvtepi64_storeu_epi8(d + i, m, b);
  }
}

/* split_at by a scan of d (split_bits): the highest bit in which key[lo]
 * and key[hi - 1] differ turns from 0 to 1 between exactly one pair of
 * neighbours in [lo, hi), the first (and only) one whose d is that bit's;
 * 64 neighbours compared at a time. The binary search's loads depend on each
 * other and miss the cache: with it the nodes took ~0.15 ms at 55k points,
 * alone on one thread while the others waited (2026-11-28). */
static uint32_t split_scan(const uint8_t *d, const uint64_t *key, uint32_t lo, uint32_t hi) {
  const uint64_t a = key[lo], b = key[hi - 1];
  if (a == b) return lo + (hi - lo) / 2;
  const __m512i v = _mm512_set1_epi8((char)(64 - __builtin_clzll(a ^ b)));
  for (uint32_t j = lo; j + 1 < hi; j += 64) {
    const uint32_t left = hi - 1 - j;
    const __mmask64 live = left >= 64 ? ~(__mmask64)0 : (((__mmask64)1 << left) - 1u);
    const __mmask64 eq = _mm512_mask_cmpeq_epi8_mask(live, _mm512_maskz_loadu_epi8(live, d + j), v);
    if (eq) return j + (uint32_t)__builtin_ctzll(eq) + 1u;
  }
  return split_at(key, lo, hi); /* not reached: the keys are sorted */
}
#else
#define VX_SPLIT_SCAN 0
#endif

/* Nodes in breadth-first order: children of node k are consecutive. */
static enum px_status build_nodes(struct px_context *ctx, struct px_vortex_tree *t, int threads) {
  size_t n = t->n;
  t->lo[0] = 0;
  t->hi[0] = (uint32_t)n;
  size_t count = 1;
#if VX_SPLIT_SCAN
  /* the neighbours' bits in the sort's scratch (cap >= n keys) */
  uint8_t *d = (uint8_t *)t->key2;
  split_bits(t->key, n, d);
#endif
  for (size_t k = 0; k < count; ++k) {
    uint32_t lo = t->lo[k], hi = t->hi[k];
    if ((size_t)(hi - lo) > t->leaf) {
#if VX_SPLIT_SCAN
      const uint32_t mid = split_scan(d, t->key, lo, hi);
#else
      const uint32_t mid = split_at(t->key, lo, hi);
#endif
      if (count + 2 > t->node_cap) PX_TRY(grow_nodes(ctx, t, t->node_cap + t->node_cap / 2 + 64));
      t->left[k] = (int32_t)count;
      t->lo[count] = lo;
      t->hi[count] = mid;
      t->lo[count + 1] = mid;
      t->hi[count + 1] = hi;
      count += 2;
    } else {
      t->left[k] = -1;
    }
  }
  t->nnode = count;
  /* the leaves' boxes and points' leaves on all threads (a pass over every
   * point: most of this function's time, serial 0.1 ms at 55k points),
   * then the inner nodes' boxes bottom-up (children follow their parent) */
#pragma omp parallel for num_threads(threads) schedule(static) if (n > 8192)
  for (long lk = 0; lk < (long)count; ++lk) {
    const size_t k = (size_t)lk;
    if (t->left[k] >= 0) continue;
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    for (uint32_t i = t->lo[k]; i < t->hi[k]; ++i) {
      double xi = t->sx[i], yi = t->sy[i];
      x0 = xi < x0 ? xi : x0; /* not fmin: a libm call (a NaN is skipped as by fmin) */
      x1 = xi > x1 ? xi : x1;
      y0 = yi < y0 ? yi : y0;
      y1 = yi > y1 ? yi : y1;
      t->leaf_of[i] = (uint32_t)k;
    }
    t->bx0[k] = x0;
    t->by0[k] = y0;
    t->bx1[k] = x1;
    t->by1[k] = y1;
  }
  for (size_t k = count; k-- > 0;) {
    if (t->left[k] < 0) continue;
    size_t a = (size_t)t->left[k], b = a + 1;
    t->bx0[k] = t->bx0[a] < t->bx0[b] ? t->bx0[a] : t->bx0[b];
    t->by0[k] = t->by0[a] < t->by0[b] ? t->by0[a] : t->by0[b];
    t->bx1[k] = t->bx1[a] > t->bx1[b] ? t->bx1[a] : t->bx1[b];
    t->by1[k] = t->by1[a] > t->by1[b] ? t->by1[a] : t->by1[b];
  }
  return PX_STATUS_OK;
}

/* The stable sort of (t->key, t->order)[0..n) by the 44-bit keys, when the
 * first `sorted` keys are expected almost in order (the wake as the last
 * step's restructuring left it, compacted in this tree's order, with the
 * newborns behind). Those are put in order by insertion, which costs a scan
 * and a few moves, and the rest by the radix sort, then the two merged
 * (ties to the first part: its points come first in the input); where the
 * insertion would move more than n/8 entries, the radix sort takes all.
 * Every path gives the unique stable sort: the same tree. */
static int sort_keys(struct px_context *ctx, struct px_vortex_tree *t, size_t n, size_t sorted,
                     int threads) {
  if (sorted > n) sorted = n;
  if (sorted < 2 || !px_radix_insertion(t->key, t->order, sorted, 0, 44, n / 8))
    return px_radix_sort(ctx, &t->key, &t->key2, &t->order, &t->ord2, n, 0, 44, threads);
  const size_t tail = n - sorted;
  if (tail == 0) return 0;
  uint64_t *k1 = t->key + sorted, *kt = t->key2 + sorted;
  uint32_t *o1 = t->order + sorted, *ot = t->ord2 + sorted;
  if (px_radix_sort(ctx, &k1, &kt, &o1, &ot, tail, 0, 44, threads)) return -1;
  if (k1 != t->key + sorted) { /* the sorted tail beside the head, the output apart */
    memcpy(t->key + sorted, k1, tail * sizeof *k1);
    memcpy(t->order + sorted, o1, tail * sizeof *o1);
  }
  px_radix_merge(t->key, t->order, sorted, t->key + sorted, t->order + sorted, tail, t->key2,
                 t->ord2, 0, 44, threads);
  uint64_t *tk = t->key;
  t->key = t->key2;
  t->key2 = tk;
  uint32_t *to = t->order;
  t->order = t->ord2;
  t->ord2 = to;
  return 0;
}

enum px_status px_vortex_tree_build(struct px_context *ctx, struct px_vortex_tree *t, size_t n,
                                    const double *x, const double *y, size_t sorted, int threads) {
  if (n > 0xfffffff0u) return px_context_fail(ctx, PX_STATUS_UNSUPPORTED, "more than 4e9 vortices");
  PX_TRY(grow(ctx, t, n));
  t->n = n;
  if (!t->leaf) t->leaf = 16;
  if (n == 0) {
    t->nnode = 0;
    return PX_STATUS_OK;
  }
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
#pragma omp simd reduction(min : x0, y0) reduction(max : x1, y1)
  for (size_t i = 0; i < n; ++i) {
    x0 = x[i] < x0 ? x[i] : x0;
    x1 = x[i] > x1 ? x[i] : x1;
    y0 = y[i] < y0 ? y[i] : y0;
    y1 = y[i] > y1 ? y[i] : y1;
  }
  double span = fmax(x1 - x0, y1 - y0);
  double scale = span > 0.0 ? 4194303.0 / span : 0.0;
#pragma omp parallel for num_threads(threads) schedule(static)
  for (long li = 0; li < (long)n; ++li) {
    size_t i = (size_t)li;
    /* clamped: a NaN or infinite coordinate (a wake that blew up, checked
       after the build) must not reach the conversion, undefined outside
       [0, 2^64) */
    double fx = (x[i] - x0) * scale, fy = (y[i] - y0) * scale;
    uint32_t ix = fx > 0.0 ? (fx < 4194303.0 ? (uint32_t)fx : 4194303u) : 0u;
    uint32_t iy = fy > 0.0 ? (fy < 4194303.0 ? (uint32_t)fy : 4194303u) : 0u;
    t->key[i] = px_morton2(ix, iy); /* 22 bits each: a 44-bit key */
    t->order[i] = (uint32_t)i;
  }
  /* the stable sort of the 44-bit keys (a deterministic function of the
   * input order and positions; sort_keys) */
  if (sort_keys(ctx, t, n, sorted, threads))
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for the wake tree (%zu points)", n);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (long li = 0; li < (long)n; ++li) {
    size_t i = (size_t)li;
    t->sx[i] = x[t->order[i]];
    t->sy[i] = y[t->order[i]];
  }
  return build_nodes(ctx, t, threads);
}

static double box_dist2(const struct px_vortex_tree *t, size_t k, double x, double y) {
  return px_vortex_tree_box_dist2(t, k, x, y);
}

size_t px_vortex_tree_leaves(const struct px_vortex_tree *t, double x, double y, double r,
                             uint32_t *leaves, size_t cap) {
  size_t cnt = 0;
  if (t->n == 0) return 0;
  double r2 = r * r;
  uint32_t stack[128];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    size_t k = stack[--sp];
    if (box_dist2(t, k, x, y) > r2) continue;
    if (t->left[k] >= 0) {
      stack[sp++] = (uint32_t)(t->left[k] + 1);
      stack[sp++] = (uint32_t)t->left[k];
      continue;
    }
    if (cnt < cap) leaves[cnt] = (uint32_t)k;
    ++cnt;
  }
  return cnt;
}

size_t px_vortex_tree_groups(const struct px_vortex_tree *t, size_t gmax, uint32_t *out) {
  size_t n = 0;
  if (t->nnode == 0) return 0;
  uint32_t stack[128];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    uint32_t k = stack[--sp];
    if (t->left[k] < 0 || t->hi[k] - t->lo[k] <= gmax) {
      out[n++] = k;
      continue;
    }
    stack[sp++] = (uint32_t)(t->left[k] + 1);
    stack[sp++] = (uint32_t)t->left[k];
  }
  return n;
}

double px_vortex_cover(const double *x, const double *y, const double *r, size_t n, double *cx,
                       double *cy) {
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY, rs = 0.0;
  for (size_t q = 0; q < n; ++q) {
    x0 = x[q] < x0 ? x[q] : x0;
    x1 = x[q] > x1 ? x[q] : x1;
    y0 = y[q] < y0 ? y[q] : y0;
    y1 = y[q] > y1 ? y[q] : y1;
  }
  *cx = 0.5 * (x0 + x1);
  *cy = 0.5 * (y0 + y1);
  for (size_t q = 0; q < n; ++q) {
    const double d = hypot(x[q] - *cx, y[q] - *cy) + r[q];
    rs = d > rs ? d : rs;
  }
  return rs * (1.0 + 1e-9) + 1e-300;
}

size_t px_vortex_tree_leaves_of(const struct px_vortex_tree *t, const uint32_t *cand, size_t n,
                                double x, double y, double r, uint32_t *out) {
  const double r2 = r * r;
  size_t cnt = 0;
  for (size_t q = 0; q < n; ++q) {
    out[cnt] = cand[q];
    cnt += !(box_dist2(t, cand[q], x, y) > r2); /* px_vortex_tree_leaves's test */
  }
  return cnt;
}

/* The sorted positions i in [lo, hi) within sqrt(r2) of (x, y), ascending,
 * appended to out at cnt (room for hi - lo + 16 more); returns the new count.
 * With AVX-512 8 points are tested at once and the hits compressed into
 * place: the same test (separate multiply and add: the build does not
 * contract to FMA) and the same list as the scalar loop, whose
 * data-dependent branch mispredicted on the per-panel queries' dense
 * near-wall leaves. */
static size_t leaf_within(const struct px_vortex_tree *t, uint32_t lo, uint32_t hi, double x,
                          double y, double r2, uint32_t *out, size_t cnt) {
#if defined(__AVX512F__) && defined(__AVX512VL__)
  const __m512d vx = _mm512_set1_pd(x), vy = _mm512_set1_pd(y), vr = _mm512_set1_pd(r2);
  const __m256i step = _mm256_set1_epi32(8);
  __m256i id =
      _mm256_add_epi32(_mm256_set1_epi32((int)lo), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
  for (uint32_t i = lo; i < hi; i += 8) {
    unsigned left = hi - i;
    __mmask8 live = left >= 8 ? (__mmask8)0xff : (__mmask8)((1u << left) - 1u);
    __m512d dx = _mm512_sub_pd(_mm512_maskz_loadu_pd(live, t->sx + i), vx);
    __m512d dy = _mm512_sub_pd(_mm512_maskz_loadu_pd(live, t->sy + i), vy);
    __m512d d2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
    __mmask8 in = _mm512_mask_cmp_pd_mask(live, d2, vr, _CMP_LE_OQ);
    _mm256_storeu_si256((__m256i *)(out + cnt), _mm256_maskz_compress_epi32(in, id));
    cnt += (size_t)__builtin_popcount((unsigned)in);
    id = _mm256_add_epi32(id, step);
  }
  return cnt;
#else
  for (uint32_t i = lo; i < hi; ++i) {
    double dx = t->sx[i] - x, dy = t->sy[i] - y;
    out[cnt] = i;
    cnt += dx * dx + dy * dy <= r2;
  }
  return cnt;
#endif
}

size_t px_vortex_tree_within(struct px_context *ctx, const struct px_vortex_tree *t, double x,
                             double y, double r, uint32_t **buf, size_t *cap) {
  size_t cnt = 0;
  if (t->n == 0) return 0;
  double r2 = r * r;
  uint32_t stack[128];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    size_t k = stack[--sp];
    if (box_dist2(t, k, x, y) > r2) continue;
    if (t->left[k] >= 0) {
      /* push the right child first so the left is visited first: results come
       * out in ascending sorted position */
      stack[sp++] = (uint32_t)(t->left[k] + 1);
      stack[sp++] = (uint32_t)t->left[k];
      continue;
    }
    /* room for every point of the leaf, plus the vector stores' slack */
    size_t need = cnt + (t->hi[k] - t->lo[k]) + 16;
    if (need > *cap) {
      size_t nc = 2 * *cap > need ? 2 * *cap : need + 256;
      uint32_t *nb = px_mem_realloc(ctx, "vortex.query", *buf, nc * sizeof(uint32_t));
      if (!nb) return (size_t)-1;
      *buf = nb;
      *cap = nc;
    }
    cnt = leaf_within(t, t->lo[k], t->hi[k], x, y, r2, *buf, cnt);
  }
  return cnt;
}

void px_vortex_tree_knn_point(const struct px_vortex_tree *t, uint32_t sp, int k, uint32_t *work,
                              size_t cap, double *d2) {
  for (int q = 0; q < k; ++q) d2[q] = INFINITY;
  double x = t->sx[sp], y = t->sy[sp];
  /* the k nearest within the point's own leaf bound the search radius */
  uint32_t leaf = t->leaf_of[sp];
  for (uint32_t i = t->lo[leaf]; i < t->hi[leaf]; ++i) {
    if (i == sp) continue;
    double dx = t->sx[i] - x, dy = t->sy[i] - y, e = dx * dx + dy * dy;
    if (e < d2[k - 1]) {
      int q = k - 1;
      while (q > 0 && d2[q - 1] > e) {
        d2[q] = d2[q - 1];
        --q;
      }
      d2[q] = e;
    }
  }
  if (!isfinite(d2[k - 1]) || cap == 0) {
    px_vortex_tree_knn(t, x, y, sp, k, d2);
    return;
  }
  size_t nl = px_vortex_tree_leaves(t, x, y, sqrt(d2[k - 1]), work, cap);
  if (nl > cap) {
    px_vortex_tree_knn(t, x, y, sp, k, d2);
    return;
  }
  for (size_t l = 0; l < nl; ++l) {
    if (work[l] == leaf) continue;
    for (uint32_t i = t->lo[work[l]]; i < t->hi[work[l]]; ++i) {
      double dx = t->sx[i] - x, dy = t->sy[i] - y, e = dx * dx + dy * dy;
      if (e < d2[k - 1]) {
        int q = k - 1;
        while (q > 0 && d2[q - 1] > e) {
          d2[q] = d2[q - 1];
          --q;
        }
        d2[q] = e;
      }
    }
  }
}

void px_vortex_tree_knn(const struct px_vortex_tree *t, double x, double y, uint32_t skip, int k,
                        double *d2) {
  for (int q = 0; q < k; ++q) d2[q] = INFINITY;
  if (t->n == 0) return;
  uint32_t stack[128];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    size_t nd = stack[--sp];
    if (box_dist2(t, nd, x, y) >= d2[k - 1]) continue;
    if (t->left[nd] >= 0) {
      size_t a = (size_t)t->left[nd], b = a + 1;
      /* nearer child last (popped first) */
      if (box_dist2(t, a, x, y) <= box_dist2(t, b, x, y)) {
        stack[sp++] = (uint32_t)b;
        stack[sp++] = (uint32_t)a;
      } else {
        stack[sp++] = (uint32_t)a;
        stack[sp++] = (uint32_t)b;
      }
      continue;
    }
    for (uint32_t i = t->lo[nd]; i < t->hi[nd]; ++i) {
      if (i == skip) continue;
      double dx = t->sx[i] - x, dy = t->sy[i] - y, e = dx * dx + dy * dy;
      if (e < d2[k - 1]) {
        int q = k - 1;
        while (q > 0 && d2[q - 1] > e) {
          d2[q] = d2[q - 1];
          --q;
        }
        d2[q] = e;
      }
    }
  }
}
