/* Morton keys and their stable LSD radix sort, with a 32-bit payload
 * (internal; not installed), shared by the FMM's quadtree and the vortex
 * wake's tree.
 *
 * Each pass sorts by one 11-bit digit: per-thread histograms over contiguous
 * chunks of the input, then every thread scatters its chunk to offsets that
 * put equal digits in chunk order; from 16k to 200k keys, several threads
 * instead sort the two halves on a thread each and merge them on all. The
 * result is the unique stable sort, whatever the number of threads. A pass
 * whose digit is the same for every key is skipped (it would leave the
 * order as it is). */
#ifndef PX_CORE_RADIX_H
#define PX_CORE_RADIX_H

#include <stddef.h>
#include <stdint.h>

#include "partix/context.h"

#define PX_RADIX_BITS 11

/* The low 31 bits of v spread to the even bits. */
static inline uint64_t px_spread_even(uint32_t v) {
  uint64_t x = v & 0x7fffffffu;
  x = (x | (x << 16)) & 0x0000ffff0000ffffull;
  x = (x | (x << 8)) & 0x00ff00ff00ff00ffull;
  x = (x | (x << 4)) & 0x0f0f0f0f0f0f0f0full;
  x = (x | (x << 2)) & 0x3333333333333333ull;
  x = (x | (x << 1)) & 0x5555555555555555ull;
  return x;
}

/* The Morton key of two coordinates of up to 31 bits: x in the even bits, y
 * in the odd ones. Inline, so that loops over points vectorize (as a call
 * per point the FMM's key loop was a serial 0.4 ms of each vortex step at
 * 55k points). */
static inline uint64_t px_morton2(uint32_t x, uint32_t y) {
  return px_spread_even(x) | (px_spread_even(y) << 1);
}

/* Sorts (*key, *idx)[0..n) by key bits [bit_lo, bit_hi), a digit of
 * PX_RADIX_BITS bits at a time from bit_lo (the last digit may reach past
 * bit_hi), on `threads` OpenMP threads. *key_tmp and *idx_tmp are scratch of
 * n entries; the pointers are swapped so that *key and *idx hold the sorted
 * result. Returns 0, or -1 (nothing sorted, nothing reported) when the
 * histograms cannot be allocated. */
int px_radix_sort(struct px_context *ctx, uint64_t **key, uint64_t **key_tmp, uint32_t **idx,
                  uint32_t **idx_tmp, size_t n, int bit_lo, int bit_hi, int threads);

/* Sorts (key, idx)[0..n) by key bits [bit_lo, bit_hi) (as px_radix_sort
 * reads them) by insertion, in place, when that moves at most `budget`
 * entries: the input almost in order (a wake between two of its trees).
 * Returns 1 when sorted (the stable sort); 0 when it gave up, leaving a
 * permutation in which equal keys keep their order, so that px_radix_sort
 * of it is the stable sort of the input. */
int px_radix_insertion(uint64_t *key, uint32_t *idx, size_t n, int bit_lo, int bit_hi,
                       size_t budget);

/* The stable merge of (ka, ia)[0..na) and (kb, ib)[0..nb), each sorted by
 * key bits [bit_lo, bit_hi) as px_radix_sort leaves them, ties to a (whose
 * entries came first: the merge of two stably sorted parts is the stable
 * sort of the whole), into (ko, io)[0..na + nb), which must not overlap
 * them; on `threads` threads from 16k entries, each writing its share of
 * the output. */
void px_radix_merge(const uint64_t *ka, const uint32_t *ia, size_t na, const uint64_t *kb,
                    const uint32_t *ib, size_t nb, uint64_t *ko, uint32_t *io, int bit_lo,
                    int bit_hi, int threads);

#endif
