/* Quadtree of the FMM: stable radix sort of Morton keys and the cells built
 * top-down on the sorted keys (precision-independent; the geometry and the
 * expansions are filled by fmm_cpu.h).
 *
 * Keys interleave 31-bit quantised coordinates (x in the even bits), so the
 * quadrant digit of level L (1..31) is bits [2(31-L), 2(31-L)+2) and every
 * cell of level L is a contiguous run of the sorted keys. */
#include <stdlib.h>
#include <string.h>

#include "core/radix.h"
#include "nbody/fmm.h"
#include "partix/memory.h"

/* The radix sort (core/radix.h: digits of 11 bits) orders key bits [30, 63)
 * = levels 1-16 in three passes; deeper levels are ordered afterwards only
 * inside runs that need it. */
#define PX_FMM_RADIX_LOW 30

int px_fmm_reserve(struct px_context *ctx, const char *label, void **ptr, size_t *cap,
                   size_t need) {
  void *p;
  size_t want;
  if (need <= *cap && *ptr) return 0;
  want = need + need / 2 + 64;
  p = px_mem_realloc(ctx, label, *ptr, want);
  if (!p) return -1;
  *ptr = p;
  *cap = want;
  return 0;
}

enum px_status px_fmm_tree_reserve(struct px_context *ctx, struct px_fmm_tree *t, size_t n) {
  size_t c8 = t->cap_n * sizeof(uint64_t), c4 = t->cap_n * sizeof(uint32_t);
  size_t c8b = c8, c4b = c4;
  const size_t m = n ? n : 1;
  if (m <= t->cap_n && t->keys) return PX_STATUS_OK;
  if (px_fmm_reserve(ctx, "fmm keys", (void **)&t->keys, &c8, m * sizeof(uint64_t)) ||
      px_fmm_reserve(ctx, "fmm keys", (void **)&t->keys_tmp, &c8b, m * sizeof(uint64_t)) ||
      px_fmm_reserve(ctx, "fmm permutation", (void **)&t->perm, &c4, m * sizeof(uint32_t)) ||
      px_fmm_reserve(ctx, "fmm permutation", (void **)&t->perm_tmp, &c4b, m * sizeof(uint32_t)))
    return PX_STATUS_NOMEM;
  /* all four arrays hold at least this many points */
  t->cap_n = c4 / sizeof(uint32_t);
  if (c4b / sizeof(uint32_t) < t->cap_n) t->cap_n = c4b / sizeof(uint32_t);
  if (c8 / sizeof(uint64_t) < t->cap_n) t->cap_n = c8 / sizeof(uint64_t);
  if (c8b / sizeof(uint64_t) < t->cap_n) t->cap_n = c8b / sizeof(uint64_t);
  return PX_STATUS_OK;
}

struct px_fmm_keyidx {
  uint64_t key;
  uint32_t idx;
};

static int px_fmm_keyidx_cmp(const void *a, const void *b) {
  const struct px_fmm_keyidx *x = a, *y = b;
  if (x->key != y->key) return x->key < y->key ? -1 : 1;
  return x->idx < y->idx ? -1 : (x->idx > y->idx);
}

/* Order by the full key the runs that share the radix-sorted high bits and
 * are longer than a leaf (only these are split below level 16). Ties keep
 * the input order (the comparison includes the index), so the order stays
 * the stable sort by key. */
static enum px_status px_fmm_refine(struct px_context *ctx, struct px_fmm_tree *t, size_t n,
                                    size_t leaf) {
  struct px_fmm_keyidx *tmp = NULL;
  size_t cap = 0, i = 0;
  while (i < n) {
    const uint64_t hi = t->keys[i] >> PX_FMM_RADIX_LOW;
    size_t j = i + 1, k;
    while (j < n && (t->keys[j] >> PX_FMM_RADIX_LOW) == hi) ++j;
    if (j - i > leaf) {
      int sorted = 1;
      for (k = i + 1; k < j && sorted; ++k) sorted = t->keys[k - 1] <= t->keys[k];
      if (!sorted) {
        if (px_fmm_reserve(ctx, "fmm sort scratch", (void **)&tmp, &cap, (j - i) * sizeof *tmp)) {
          px_mem_free(ctx, tmp);
          return PX_STATUS_NOMEM;
        }
        for (k = i; k < j; ++k) {
          tmp[k - i].key = t->keys[k];
          tmp[k - i].idx = t->perm[k];
        }
        qsort(tmp, j - i, sizeof *tmp, px_fmm_keyidx_cmp);
        for (k = i; k < j; ++k) {
          t->keys[k] = tmp[k - i].key;
          t->perm[k] = tmp[k - i].idx;
        }
      }
    }
    i = j;
  }
  px_mem_free(ctx, tmp);
  return PX_STATUS_OK;
}

enum px_status px_fmm_tree_cells(struct px_context *ctx, struct px_fmm_tree *t, size_t need) {
  size_t c0, c1, want;
  if (need <= t->cap_cells && t->cell) return PX_STATUS_OK;
  want = need + need / 2 + 16;
  c0 = t->cap_cells * sizeof(struct px_fmm_cell);
  c1 = t->cap_cells * 4 * sizeof(double);
  if (px_fmm_reserve(ctx, "fmm cells", (void **)&t->cell, &c0, want * sizeof(struct px_fmm_cell)) ||
      px_fmm_reserve(ctx, "fmm cell boxes", (void **)&t->box, &c1, want * 4 * sizeof(double)))
    return PX_STATUS_NOMEM;
  t->cap_cells = want;
  return PX_STATUS_OK;
}

/* First index in [lo, hi) whose digit ((key >> shift) & 3) is >= q (hi if
 * none); the digits are non-decreasing over the range (a run of one cell).
 * Without branches (a select per halving): their outcomes are random, and
 * the mispredictions were most of the tree build's time (2026-11-28). */
static size_t px_fmm_lower(const uint64_t *keys, size_t lo, size_t hi, int shift, unsigned q) {
  if (lo >= hi) return lo;
  size_t base = lo, n = hi - lo;
  while (n > 1) {
    const size_t half = n / 2;
    base = ((unsigned)(keys[base + half] >> shift) & 3u) < q ? base + half : base;
    n -= half;
  }
  return base + (((unsigned)(keys[base] >> shift) & 3u) < q);
}

enum px_status px_fmm_tree_build(struct px_context *ctx, struct px_fmm_tree *t, int threads,
                                 size_t n, size_t leaf) {
  size_t i, lo, hi;
  uint8_t *depth = NULL;
  size_t depth_cap = 0;
  enum px_status st = PX_STATUS_OK;
  t->n = n;
  t->ncells = 0;
  t->ngen = 0;
  t->maxleaf = 0;
  if (leaf < 1) leaf = 1;
  for (i = 0; i < n; ++i) t->perm[i] = (uint32_t)i;
  /* key bits [30, 63): levels 1-16; by insertion where the points come
   * almost in Morton order (the vortex wake as its last tree left it: a
   * scan and a few moves instead of the radix sort's passes, 0.05 against
   * 0.2 ms at 55k points, 2026-11-28) */
  if (!px_radix_insertion(t->keys, t->perm, n, PX_FMM_RADIX_LOW, 63, n / 8) &&
      px_radix_sort(ctx, &t->keys, &t->keys_tmp, &t->perm, &t->perm_tmp, n, PX_FMM_RADIX_LOW, 63,
                    threads))
    return PX_STATUS_NOMEM;
  PX_TRY(px_fmm_refine(ctx, t, n, leaf));
  PX_TRY(px_fmm_tree_cells(ctx, t, 64));
  if (px_fmm_reserve(ctx, "fmm cell depths", (void **)&depth, &depth_cap, t->cap_cells))
    return PX_STATUS_NOMEM;
  memset(t->cell, 0, sizeof *t->cell);
  t->cell[0].begin = 0;
  t->cell[0].end = (uint32_t)n;
  t->cell[0].parent = UINT32_MAX;
  depth[0] = 0;
  t->ncells = 1;
  t->gen[0] = 0;
  lo = 0;
  hi = 1;
  while (lo < hi) {
    size_t c;
    if (t->ngen >= PX_FMM_MAX_GEN) {
      st = px_context_fail(ctx, PX_STATUS_INTERNAL, "fmm tree: more than %d generations",
                           PX_FMM_MAX_GEN);
      break;
    }
    for (c = lo; c < hi; ++c) {
      const size_t b = t->cell[c].begin, e = t->cell[c].end;
      unsigned d = depth[c];
      size_t q[5];
      int nonempty = 0, k;
      t->cell[c].nchild = 0;
      t->cell[c].child = 0;
      if (e - b <= leaf) continue;
      while (d < PX_FMM_KEY_LEVELS) {
        const int shift = 2 * (PX_FMM_KEY_LEVELS - (int)d - 1);
        q[0] = b;
        q[4] = e;
        for (k = 1; k < 4; ++k) q[k] = px_fmm_lower(t->keys, q[k - 1], e, shift, (unsigned)k);
        nonempty = 0;
        for (k = 0; k < 4; ++k) nonempty += q[k + 1] > q[k];
        ++d;
        if (nonempty >= 2) break;
      }
      if (nonempty < 2) continue; /* coincident at the deepest level: a big leaf */
      if (px_fmm_tree_cells(ctx, t, t->ncells + 4) ||
          px_fmm_reserve(ctx, "fmm cell depths", (void **)&depth, &depth_cap, t->cap_cells)) {
        st = PX_STATUS_NOMEM;
        break;
      }
      t->cell[c].child = (uint32_t)t->ncells;
      t->cell[c].nchild = (uint32_t)nonempty;
      for (k = 0; k < 4; ++k) {
        if (q[k + 1] > q[k]) {
          struct px_fmm_cell *cc = t->cell + t->ncells;
          memset(cc, 0, sizeof *cc);
          cc->begin = (uint32_t)q[k];
          cc->end = (uint32_t)q[k + 1];
          cc->parent = (uint32_t)c;
          depth[t->ncells++] = (uint8_t)d;
        }
      }
    }
    if (st != PX_STATUS_OK) break;
    t->gen[++t->ngen] = hi;
    lo = hi;
    hi = t->ncells;
  }
  px_mem_free(ctx, depth);
  if (st != PX_STATUS_OK) return st;
  for (i = 0; i < t->ncells; ++i)
    if (!t->cell[i].nchild && t->cell[i].end - t->cell[i].begin > t->maxleaf)
      t->maxleaf = t->cell[i].end - t->cell[i].begin;
  return PX_STATUS_OK;
}

static int px_fmm_u64_cmp(const void *a, const void *b) {
  const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return x < y ? -1 : (x > y);
}

enum px_status px_fmm_tree_tasks(struct px_context *ctx, struct px_fmm_tree *t, int threads) {
  const size_t limit = threads > 1 ? t->n / (8 * (size_t)threads) : t->n;
  size_t c, ntop = 0, nfront = 0;
  uint8_t *top;
  uint64_t *key;
  if (px_fmm_reserve(ctx, "fmm tasks", (void **)&t->task, &t->task_cap,
                     (t->ncells + 1) * sizeof(uint32_t)))
    return PX_STATUS_NOMEM;
  /* cells are in generation order: parents come before their children */
  top = px_mem_alloc(ctx, "fmm tasks", t->ncells ? t->ncells : 1);
  if (!top) return PX_STATUS_NOMEM;
  for (c = 0; c < t->ncells; ++c) {
    const struct px_fmm_cell *cell = t->cell + c;
    const int under_top = c == 0 || top[cell->parent];
    top[c] = (uint8_t)(under_top && cell->nchild > 0 && cell->end - cell->begin > limit);
    if (top[c]) t->task[ntop++] = (uint32_t)c;
  }
  for (c = 0; c < t->ncells; ++c)
    if (!top[c] && (c == 0 || top[t->cell[c].parent])) t->task[ntop + nfront++] = (uint32_t)c;
  px_mem_free(ctx, top);
  /* subtree roots largest first (ties by index): sort keys (~size, index) */
  key = px_mem_alloc(ctx, "fmm tasks", (nfront ? nfront : 1) * sizeof *key);
  if (!key) return PX_STATUS_NOMEM;
  for (c = 0; c < nfront; ++c) {
    const struct px_fmm_cell *cell = t->cell + t->task[ntop + c];
    key[c] = (uint64_t)(0xffffffffu - (cell->end - cell->begin)) << 32 | t->task[ntop + c];
  }
  qsort(key, nfront, sizeof *key, px_fmm_u64_cmp);
  for (c = 0; c < nfront; ++c) t->task[ntop + c] = (uint32_t)key[c];
  px_mem_free(ctx, key);
  t->ntop = ntop;
  t->nfront = nfront;
  return PX_STATUS_OK;
}
