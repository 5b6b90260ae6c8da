/* Morton-ordered bounding-volume tree (see vortex_tree.h). */
#include "solvers/vortex/vortex_tree.h"

#include <math.h>
#include <string.h>

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

/* Spread the low 22 bits of v to the even bits. */
static uint64_t spread22(uint64_t v) {
  v &= 0x3fffffULL;
  v = (v | (v << 16)) & 0x0000ffff0000ffffULL;
  v = (v | (v << 8)) & 0x00ff00ff00ff00ffULL;
  v = (v | (v << 4)) & 0x0f0f0f0f0f0f0f0fULL;
  v = (v | (v << 2)) & 0x3333333333333333ULL;
  v = (v | (v << 1)) & 0x5555555555555555ULL;
  return v;
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
  size_t ncap = 2 * (cap / 4 + 1) + 64; /* leaves hold >= leaf/2 >= 4 points */
  px_mem_free(ctx, t->lo);
  px_mem_free(ctx, t->hi);
  px_mem_free(ctx, t->left);
  px_mem_free(ctx, t->bx0);
  t->lo = px_mem_alloc(ctx, "vortex.tree", ncap * sizeof(uint32_t));
  t->hi = px_mem_alloc(ctx, "vortex.tree", ncap * sizeof(uint32_t));
  t->left = px_mem_alloc(ctx, "vortex.tree", ncap * sizeof(int32_t));
  t->bx0 = px_mem_alloc(ctx, "vortex.tree", 4 * ncap * sizeof(double));
  if (!t->lo || !t->hi || !t->left || !t->bx0)
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for the wake tree nodes");
  t->node_cap = ncap;
  t->by0 = t->bx0 + ncap;
  t->bx1 = t->bx0 + 2 * ncap;
  t->by1 = t->bx0 + 3 * ncap;
  return PX_STATUS_OK;
}

/* Nodes in breadth-first order: children of node k are consecutive. */
static void build_nodes(struct px_vortex_tree *t) {
  size_t n = t->n;
  t->lo[0] = 0;
  t->hi[0] = (uint32_t)n;
  size_t count = 1;
  for (size_t k = 0; k < count; ++k) {
    uint32_t lo = t->lo[k], hi = t->hi[k];
    if ((size_t)(hi - lo) > t->leaf) {
      uint32_t mid = lo + (hi - lo) / 2;
      t->left[k] = (int32_t)count;
      t->lo[count] = lo;
      t->hi[count] = mid;
      t->lo[count + 1] = mid;
      t->hi[count + 1] = hi;
      count += 2;
    } else {
      t->left[k] = -1;
      for (uint32_t i = lo; i < hi; ++i) t->leaf_of[i] = (uint32_t)k;
    }
  }
  t->nnode = count;
  /* boxes bottom-up (children always follow their parent) */
  for (size_t k = count; k-- > 0;) {
    if (t->left[k] < 0) {
      double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
      for (uint32_t i = t->lo[k]; i < t->hi[k]; ++i) {
        double xi = t->sx[i], yi = t->sy[i];
        x0 = xi < x0 ? xi : x0; /* not fmin: a libm call (a NaN is skipped as by fmin) */
        x1 = xi > x1 ? xi : x1;
        y0 = yi < y0 ? yi : y0;
        y1 = yi > y1 ? yi : y1;
      }
      t->bx0[k] = x0;
      t->by0[k] = y0;
      t->bx1[k] = x1;
      t->by1[k] = y1;
    } else {
      size_t a = (size_t)t->left[k], b = a + 1;
      t->bx0[k] = t->bx0[a] < t->bx0[b] ? t->bx0[a] : t->bx0[b];
      t->by0[k] = t->by0[a] < t->by0[b] ? t->by0[a] : t->by0[b];
      t->bx1[k] = t->bx1[a] > t->bx1[b] ? t->bx1[a] : t->bx1[b];
      t->by1[k] = t->by1[a] > t->by1[b] ? t->by1[a] : t->by1[b];
    }
  }
}

enum px_status px_vortex_tree_build(struct px_context *ctx, struct px_vortex_tree *t, size_t n,
                                    const double *x, const double *y, int threads) {
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
    uint64_t ix = fx > 0.0 ? (fx < 4194303.0 ? (uint64_t)fx : 4194303u) : 0u;
    uint64_t iy = fy > 0.0 ? (fy < 4194303.0 ? (uint64_t)fy : 4194303u) : 0u;
    t->key[i] = spread22(ix) | (spread22(iy) << 1);
    t->order[i] = (uint32_t)i;
  }
  /* LSD radix sort, 4 passes of 11 bits over the 44-bit keys (stable, so the
   * result is a deterministic function of the input order and positions) */
  uint64_t *ka = t->key, *kb = t->key2;
  uint32_t *oa = t->order, *ob = t->ord2;
  size_t count[2048];
  for (int pass = 0; pass < 4; ++pass) {
    int shift = 11 * pass;
    memset(count, 0, sizeof count);
    for (size_t i = 0; i < n; ++i) count[(ka[i] >> shift) & 2047u]++;
    size_t sum = 0;
    for (int b = 0; b < 2048; ++b) {
      size_t c = count[b];
      count[b] = sum;
      sum += c;
    }
    for (size_t i = 0; i < n; ++i) {
      size_t d = count[(ka[i] >> shift) & 2047u]++;
      kb[d] = ka[i];
      ob[d] = oa[i];
    }
    uint64_t *tk = ka;
    ka = kb;
    kb = tk;
    uint32_t *to = oa;
    oa = ob;
    ob = to;
  }
  /* after an even number of passes the result is back in key/order */
  for (size_t i = 0; i < n; ++i) {
    t->sx[i] = x[t->order[i]];
    t->sy[i] = y[t->order[i]];
  }
  build_nodes(t);
  return PX_STATUS_OK;
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
    for (uint32_t i = t->lo[k]; i < t->hi[k]; ++i) {
      double dx = t->sx[i] - x, dy = t->sy[i] - y;
      if (dx * dx + dy * dy <= r2) {
        if (cnt == *cap) {
          size_t nc = *cap ? 2 * *cap : 256;
          uint32_t *nb = px_mem_realloc(ctx, "vortex.query", *buf, nc * sizeof(uint32_t));
          if (!nb) return (size_t)-1;
          *buf = nb;
          *cap = nc;
        }
        (*buf)[cnt++] = i;
      }
    }
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
