/* Stable LSD radix sort (see radix.h). */
#include "core/radix.h"

#include <omp.h>
#include <string.h>

#include "partix/memory.h"

#define PX_RADIX_SIZE (1u << PX_RADIX_BITS)

/* From PX_RADIX_SPLIT_MIN keys up to PX_RADIX_SPLIT_MAX, a sort on several
 * threads sorts the two halves of the keys on a thread each and merges them
 * on all: at 55k keys the passes whose scatter is shared by the threads were
 * no faster than one thread (their ranges of each digit share cache lines),
 * the halves 0.29 -> 0.19 ms (Zen 5 VM, 2026-11-28). Above, every pass
 * scatters on all threads (the FMM measured that faster from 200k keys). */
#define PX_RADIX_SPLIT_MIN 16384
#define PX_RADIX_SPLIT_MAX 200000

/* After a pass: the sorted entries are in the other buffers. */
static void radix_swap(uint64_t **key, uint64_t **key_tmp, uint32_t **idx, uint32_t **idx_tmp) {
  uint64_t *tk = *key;
  *key = *key_tmp;
  *key_tmp = tk;
  uint32_t *tp = *idx;
  *idx = *idx_tmp;
  *idx_tmp = tp;
}

/* The passes over (*key, *idx)[0..n) on one thread (hist: PX_RADIX_SIZE
 * entries), swapping the buffers after each pass not skipped. */
static void radix_serial(uint64_t **key, uint64_t **key_tmp, uint32_t **idx, uint32_t **idx_tmp,
                         size_t n, int bit_lo, int bit_hi, size_t *hist) {
  for (int shift = bit_lo; shift < bit_hi; shift += PX_RADIX_BITS) {
    const uint64_t *ka = *key;
    const uint32_t *pa = *idx;
    uint64_t *kb = *key_tmp;
    uint32_t *pb = *idx_tmp;
    memset(hist, 0, PX_RADIX_SIZE * sizeof *hist);
    for (size_t i = 0; i < n; ++i) ++hist[(ka[i] >> shift) & (PX_RADIX_SIZE - 1)];
    size_t sum = 0;
    int skip = 0;
    for (size_t d = 0; d < PX_RADIX_SIZE; ++d) {
      const size_t c = hist[d];
      if (c == n) skip = 1;
      hist[d] = sum;
      sum += c;
    }
    if (skip) continue;
    for (size_t i = 0; i < n; ++i) {
      const size_t o = hist[(ka[i] >> shift) & (PX_RADIX_SIZE - 1)]++;
      kb[o] = ka[i];
      pb[o] = pa[i];
    }
    radix_swap(key, key_tmp, idx, idx_tmp);
  }
}

/* The bits of a key that the passes sort: from bit_lo, whole digits */
struct radix_bits {
  int shift;
  uint64_t mask;
};

static struct radix_bits radix_bits(int bit_lo, int bit_hi) {
  const int width = (bit_hi - bit_lo + PX_RADIX_BITS - 1) / PX_RADIX_BITS * PX_RADIX_BITS;
  struct radix_bits r = {bit_lo, width >= 64 - bit_lo ? ~0ull >> bit_lo : (1ull << width) - 1};
  return r;
}

static inline uint64_t radix_part(struct radix_bits r, uint64_t k) {
  return (k >> r.shift) & r.mask;
}

int px_radix_insertion(uint64_t *key, uint32_t *idx, size_t n, int bit_lo, int bit_hi,
                       size_t budget) {
  const struct radix_bits r = radix_bits(bit_lo, bit_hi);
  size_t moves = 0;
  for (size_t i = 1; i < n; ++i) {
    const uint64_t k = key[i], kp = radix_part(r, k);
    if (kp >= radix_part(r, key[i - 1])) continue;
    const uint32_t o = idx[i];
    size_t j = i;
    do {
      key[j] = key[j - 1];
      idx[j] = idx[j - 1];
      --j;
    } while (j > 0 && radix_part(r, key[j - 1]) > kp && ++moves <= budget);
    key[j] = k;
    idx[j] = o;
    if (moves > budget) return 0;
  }
  return 1;
}

/* How many of the first d entries of the stable merge of sorted a[0..na)
 * and b[0..nb) (by the bits r; ties to a) come from a. */
static size_t merge_split(struct radix_bits r, const uint64_t *a, size_t na, const uint64_t *b,
                          size_t nb, size_t d) {
  size_t lo = d > nb ? d - nb : 0, hi = d < na ? d : na;
  while (lo < hi) {
    const size_t mid = lo + (hi - lo) / 2;
    if (radix_part(r, a[mid]) <= radix_part(r, b[d - mid - 1]))
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

void px_radix_merge(const uint64_t *ka, const uint32_t *ia, size_t na, const uint64_t *kb,
                    const uint32_t *ib, size_t nb, uint64_t *ko, uint32_t *io, int bit_lo,
                    int bit_hi, int threads) {
  const struct radix_bits r = radix_bits(bit_lo, bit_hi);
  const size_t n = na + nb;
#pragma omp parallel num_threads(threads > 1 && n >= PX_RADIX_SPLIT_MIN ? threads : 1)
  {
    /* each thread its share of the output, from where the merge path
     * crosses its first and last entries */
    const size_t t = (size_t)omp_get_thread_num(), team = (size_t)omp_get_num_threads();
    const size_t d0 = n * t / team, d1 = n * (t + 1) / team;
    size_t i = merge_split(r, ka, na, kb, nb, d0), j = d0 - i;
    const size_t i1 = merge_split(r, ka, na, kb, nb, d1), j1 = d1 - i1;
    size_t o = d0;
    while (i < i1 && j < j1) {
      if (radix_part(r, kb[j]) < radix_part(r, ka[i])) {
        ko[o] = kb[j];
        io[o++] = ib[j++];
      } else {
        ko[o] = ka[i];
        io[o++] = ia[i++];
      }
    }
    for (; i < i1; ++i, ++o) {
      ko[o] = ka[i];
      io[o] = ia[i];
    }
    for (; j < j1; ++j, ++o) {
      ko[o] = kb[j];
      io[o] = ib[j];
    }
  }
}

/* The two halves sorted on a thread each (keys [0, m) and [m, n), each
 * half of both buffers its own), then merged into the other buffer on
 * `threads` threads (px_radix_merge). */
static void radix_split(uint64_t **key, uint64_t **key_tmp, uint32_t **idx, uint32_t **idx_tmp,
                        size_t n, int bit_lo, int bit_hi, int threads, size_t *hist) {
  const size_t m = n / 2, len[2] = {m, n - m};
  uint64_t *k[2] = {*key, *key + m}, *kt[2] = {*key_tmp, *key_tmp + m};
  uint32_t *p[2] = {*idx, *idx + m}, *pt[2] = {*idx_tmp, *idx_tmp + m};
#pragma omp parallel num_threads(2)
  {
    const int h = omp_get_thread_num();
    if (omp_get_num_threads() == 2) {
      radix_serial(&k[h], &kt[h], &p[h], &pt[h], len[h], bit_lo, bit_hi,
                   hist + (size_t)h * PX_RADIX_SIZE);
    } else {
      for (int q = 0; q < 2; ++q)
        radix_serial(&k[q], &kt[q], &p[q], &pt[q], len[q], bit_lo, bit_hi, hist);
    }
  }
  /* both sorted halves in one buffer (their skipped passes may differ) */
  const int first_in_key = k[0] == *key;
  if (first_in_key != (k[1] == *key + m)) {
    memcpy(kt[1], k[1], len[1] * sizeof *k[1]);
    memcpy(pt[1], p[1], len[1] * sizeof *p[1]);
    k[1] = kt[1];
    p[1] = pt[1];
  }
  uint64_t *src = first_in_key ? *key : *key_tmp, *dst = first_in_key ? *key_tmp : *key;
  uint32_t *psrc = first_in_key ? *idx : *idx_tmp, *pdst = first_in_key ? *idx_tmp : *idx;
  px_radix_merge(k[0], p[0], len[0], k[1], p[1], len[1], dst, pdst, bit_lo, bit_hi, threads);
  *key = dst;
  *key_tmp = src;
  *idx = pdst;
  *idx_tmp = psrc;
}

int px_radix_sort(struct px_context *ctx, uint64_t **key, uint64_t **key_tmp, uint32_t **idx,
                  uint32_t **idx_tmp, size_t n, int bit_lo, int bit_hi, int threads) {
  const int split = threads > 1 && n >= PX_RADIX_SPLIT_MIN && n < PX_RADIX_SPLIT_MAX;
  const int nt = !split && threads > 1 && n >= (size_t)threads * PX_RADIX_SIZE ? threads : 1;
  size_t *hist = px_mem_alloc(ctx, "radix histograms",
                              (size_t)(split ? 2 : nt) * PX_RADIX_SIZE * sizeof(size_t));
  if (!hist) return -1;
  if (split) {
    radix_split(key, key_tmp, idx, idx_tmp, n, bit_lo, bit_hi, threads, hist);
  } else if (nt == 1) {
    radix_serial(key, key_tmp, idx, idx_tmp, n, bit_lo, bit_hi, hist);
  } else {
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
        radix_swap(key, key_tmp, idx, idx_tmp);
      }
    }
  }
  px_mem_free(ctx, hist);
  return 0;
}
