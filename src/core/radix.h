/* Stable LSD radix sort of 64-bit keys with a 32-bit payload (internal; not
 * installed), shared by the FMM's quadtree and the vortex wake's tree.
 *
 * Each pass sorts by one 11-bit digit: per-thread histograms over contiguous
 * chunks of the input, then every thread scatters its chunk to offsets that
 * put equal digits in chunk order. The result is the unique stable sort,
 * whatever the number of threads. A pass whose digit is the same for every
 * key is skipped (it would leave the order as it is). */
#ifndef PX_CORE_RADIX_H
#define PX_CORE_RADIX_H

#include <stddef.h>
#include <stdint.h>

#include "partix/context.h"

#define PX_RADIX_BITS 11

/* Sorts (*key, *idx)[0..n) by key bits [bit_lo, bit_hi), a digit of
 * PX_RADIX_BITS bits at a time from bit_lo (the last digit may reach past
 * bit_hi), on `threads` OpenMP threads. *key_tmp and *idx_tmp are scratch of
 * n entries; the pointers are swapped so that *key and *idx hold the sorted
 * result. Returns 0, or -1 (nothing sorted, nothing reported) when the
 * histograms cannot be allocated. */
int px_radix_sort(struct px_context *ctx, uint64_t **key, uint64_t **key_tmp, uint32_t **idx,
                  uint32_t **idx_tmp, size_t n, int bit_lo, int bit_hi, int threads);

#endif
