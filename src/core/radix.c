/* Stable LSD radix sort (see radix.h). */
#include "core/radix.h"

#include <omp.h>
#include <string.h>

#include "partix/memory.h"

#define PX_RADIX_SIZE (1u << PX_RADIX_BITS)

int px_radix_sort(struct px_context *ctx, uint64_t **key, uint64_t **key_tmp, uint32_t **idx,
                  uint32_t **idx_tmp, size_t n, int bit_lo, int bit_hi, int threads) {
  const int nt = threads > 1 && n >= (size_t)threads * PX_RADIX_SIZE ? threads : 1;
  size_t *hist = px_mem_alloc(ctx, "radix histograms", (size_t)nt * PX_RADIX_SIZE * sizeof(size_t));
  if (!hist) return -1;
  for (int shift = bit_lo; shift < bit_hi; shift += PX_RADIX_BITS) {
    const uint64_t *ka = *key;
    const uint32_t *pa = *idx;
    uint64_t *kb = *key_tmp;
    uint32_t *pb = *idx_tmp;
    int skip = 0;
#pragma omp parallel num_threads(nt)
    {
      const size_t id = (size_t)omp_get_thread_num(), team = (size_t)omp_get_num_threads();
      const size_t lo = n * id / team, hi = n * (id + 1) / team;
      size_t *h = hist + id * PX_RADIX_SIZE;
      memset(h, 0, PX_RADIX_SIZE * sizeof *h);
      for (size_t i = lo; i < hi; ++i) ++h[(ka[i] >> shift) & (PX_RADIX_SIZE - 1)];
#pragma omp barrier
#pragma omp single
      {
        size_t sum = 0;
        for (size_t d = 0; d < PX_RADIX_SIZE; ++d) {
          size_t total = 0;
          for (size_t tt = 0; tt < team; ++tt) total += hist[tt * PX_RADIX_SIZE + d];
          if (total == n) skip = 1;
          for (size_t tt = 0; tt < team; ++tt) {
            const size_t c = hist[tt * PX_RADIX_SIZE + d];
            hist[tt * PX_RADIX_SIZE + d] = sum;
            sum += c;
          }
        }
      }
      if (!skip) {
        for (size_t i = lo; i < hi; ++i) {
          const size_t o = h[(ka[i] >> shift) & (PX_RADIX_SIZE - 1)]++;
          kb[o] = ka[i];
          pb[o] = pa[i];
        }
      }
    }
    if (!skip) {
      uint64_t *tk = *key;
      *key = *key_tmp;
      *key_tmp = tk;
      uint32_t *tp = *idx;
      *idx = *idx_tmp;
      *idx_tmp = tp;
    }
  }
  px_mem_free(ctx, hist);
  return 0;
}
