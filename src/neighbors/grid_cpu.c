/* cpu implementation of the neighbour grid: cell index (grid_cpu.h), then a
 * stable counting sort with per-thread histograms over contiguous chunks of
 * particles, so the permutation is the same for every thread count. */
#include <omp.h>
#include <string.h>

#include "neighbors/grid_impl.h"
#include "partix/memory.h"

/* Scratch kept between builds: per-thread histograms and range totals. */
struct px_grid_cpu {
  uint32_t *hist;  /* owned, [threads][ncells] */
  size_t hist_len; /* elements */
  size_t *totals;  /* owned, [threads] */
  size_t totals_len;
};

/* Threads for the sort: each costs a histogram of ncells counters that must
 * be cleared and scanned, so threads only help while that stays small next
 * to the n particles they split. */
static int px_grid_sort_threads(int threads, size_t n, size_t ncells) {
  size_t t = (size_t)threads;
  if (t > n / 16384 + 1) t = n / 16384 + 1;
  while (t > 1 && t * ncells > 2 * n + 65536) --t;
  return (int)t;
}

/* Stable counting sort of cell[0..n) into perm, start, end.
 *
 * Thread t owns particles [n t/T, n (t+1)/T) and cells [C t/T, C (t+1)/T).
 * 1. each thread counts its particles per cell into hist[t][.];
 * 2. each thread turns the counts of its cells into offsets, in cell-major
 *    then thread order (cell c of thread 0's chunk precedes cell c of thread
 *    1's chunk), starting from the total of the preceding cell ranges;
 * 3. each thread scatters its particles in index order.
 * Particles of a cell thus appear in index order: the stable sort. */
static void px_grid_cpu_sort(int threads, size_t n, size_t ncells, const uint32_t *cell,
                             uint32_t *perm, uint32_t *start, uint32_t *end, uint32_t *hist,
                             size_t *totals) {
#pragma omp parallel num_threads(threads)
  {
    const size_t t = (size_t)omp_get_thread_num(), nt = (size_t)omp_get_num_threads();
    const size_t i0 = n * t / nt, i1 = n * (t + 1) / nt;
    const size_t c0 = ncells * t / nt, c1 = ncells * (t + 1) / nt;
    uint32_t *h = hist + t * ncells;
    size_t i, c, s, base = 0, sum = 0;
    memset(h, 0, ncells * sizeof *h);
    for (i = i0; i < i1; ++i) ++h[cell[i]];
#pragma omp barrier
    for (c = c0; c < c1; ++c)
      for (s = 0; s < nt; ++s) sum += hist[s * ncells + c];
    totals[t] = sum;
#pragma omp barrier
    for (s = 0; s < t; ++s) base += totals[s];
    for (c = c0; c < c1; ++c) {
      start[c] = (uint32_t)base;
      for (s = 0; s < nt; ++s) {
        const uint32_t k = hist[s * ncells + c];
        hist[s * ncells + c] = (uint32_t)base;
        base += k;
      }
      end[c] = (uint32_t)base;
    }
#pragma omp barrier
    for (i = i0; i < i1; ++i) perm[h[cell[i]]++] = (uint32_t)i;
  }
}

static enum px_status px_grid_cpu_build(struct px_grid *g, enum px_precision precision,
                                        struct px_buffer *x, struct px_buffer *y,
                                        struct px_buffer *z) {
  struct px_context *ctx = g->be->ctx;
  struct px_grid_cpu *s = g->impl;
  const int threads = px_grid_sort_threads(g->be->threads, g->n, g->ncells);
  const size_t need = (size_t)threads * g->ncells;
  if (!s) {
    s = px_mem_calloc(ctx, "grid sort scratch", 1, sizeof *s);
    if (!s) return PX_STATUS_NOMEM;
    g->impl = s;
  }
  if (s->hist_len < need) {
    uint32_t *h = px_mem_realloc(ctx, "grid sort scratch", s->hist, need * sizeof *h);
    if (!h) return PX_STATUS_NOMEM;
    s->hist = h;
    s->hist_len = need;
  }
  if (s->totals_len < (size_t)threads) {
    size_t *t = px_mem_realloc(ctx, "grid sort scratch", s->totals, (size_t)threads * sizeof *t);
    if (!t) return PX_STATUS_NOMEM;
    s->totals = t;
    s->totals_len = (size_t)threads;
  }
  if (precision == PX_PRECISION_DOUBLE)
    px_grid_cpu_cells_f64(g->be->threads, g, x->host, y->host, z ? z->host : NULL, g->cell->host);
  else
    px_grid_cpu_cells_f32(g->be->threads, g, x->host, y->host, z ? z->host : NULL, g->cell->host);
  px_grid_cpu_sort(threads, g->n, g->ncells, g->cell->host, g->perm->host, g->start->host,
                   g->end->host, s->hist, s->totals);
  return PX_STATUS_OK;
}

static enum px_status px_grid_cpu_reorder(struct px_grid *g, size_t elem_size,
                                          struct px_buffer *src, struct px_buffer *dst) {
  const size_t n = g->n;
  const uint32_t *perm = g->perm->host;
  const int threads = g->be->threads;
  switch (elem_size) {
    case 8: {
      const uint64_t *s = src->host;
      uint64_t *d = dst->host;
#pragma omp parallel for num_threads(threads) schedule(static) if (n > 65536)
      for (size_t k = 0; k < n; ++k) d[k] = s[perm[k]];
      break;
    }
    case 4: {
      const uint32_t *s = src->host;
      uint32_t *d = dst->host;
#pragma omp parallel for num_threads(threads) schedule(static) if (n > 65536)
      for (size_t k = 0; k < n; ++k) d[k] = s[perm[k]];
      break;
    }
    default: {
      const unsigned char *s = src->host;
      unsigned char *d = dst->host;
#pragma omp parallel for num_threads(threads) schedule(static) if (n > 65536)
      for (size_t k = 0; k < n; ++k) memcpy(d + k * elem_size, s + perm[k] * elem_size, elem_size);
      break;
    }
  }
  return PX_STATUS_OK;
}

static enum px_status px_grid_cpu_count(struct px_grid *g, enum px_precision precision,
                                        struct px_buffer *x, struct px_buffer *y,
                                        struct px_buffer *z, double range, struct px_buffer *out) {
  if (precision == PX_PRECISION_DOUBLE)
    px_grid_cpu_count_f64(g->be->threads, g, x->host, y->host, z ? z->host : NULL, range,
                          out->host);
  else
    px_grid_cpu_count_f32(g->be->threads, g, x->host, y->host, z ? z->host : NULL, range,
                          out->host);
  return PX_STATUS_OK;
}

static void px_grid_cpu_release(struct px_grid *g) {
  struct px_grid_cpu *s = g->impl;
  if (!s) return;
  px_mem_free(g->be->ctx, s->hist);
  px_mem_free(g->be->ctx, s->totals);
  px_mem_free(g->be->ctx, s);
  g->impl = NULL;
}

const struct px_grid_ops px_grid_ops_cpu = {
    .backend = "cpu",
    .build = px_grid_cpu_build,
    .reorder = px_grid_cpu_reorder,
    .count_neighbours = px_grid_cpu_count,
    .release = px_grid_cpu_release,
};
