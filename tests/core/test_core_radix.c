/* Morton keys and the shared radix sort (core/radix.h). The sort against a
 * plain stable sort: keys drawn so that digits repeat (equal keys, equal
 * digits under a bit range) and so that some digits are the same for every
 * key (skipped passes); the same result on 1, 2 and 3 threads, and teams
 * whose chunks hold a handful of keys each. */
#include <stdlib.h>
#include <string.h>

#include "core/radix.h"
#include "partix/context.h"
#include "px_test.h"

static uint64_t rng_state = 88172645463325252ull;

static uint64_t next_u64(void) { /* xorshift64 */
  rng_state ^= rng_state << 13;
  rng_state ^= rng_state >> 7;
  rng_state ^= rng_state << 17;
  return rng_state;
}

/* The reference: a stable sort of (key, idx) by key bits [lo, hi), by
 * qsort on (those bits, input position). */
struct plain_item {
  uint64_t part, key;
  uint32_t idx, pos;
};

static int plain_cmp(const void *x, const void *y) {
  const struct plain_item *a = x, *b = y;
  if (a->part != b->part) return a->part < b->part ? -1 : 1;
  return a->pos < b->pos ? -1 : (a->pos > b->pos);
}

static void plain_sort(uint64_t *key, uint32_t *idx, size_t n, int lo, int hi) {
  const uint64_t mask = (hi >= 64 ? ~0ull : (1ull << hi) - 1) & ~((1ull << lo) - 1);
  struct plain_item *it = malloc((n ? n : 1) * sizeof *it);
  for (size_t i = 0; i < n; ++i) {
    it[i].part = key[i] & mask;
    it[i].key = key[i];
    it[i].idx = idx[i];
    it[i].pos = (uint32_t)i;
  }
  qsort(it, n, sizeof *it, plain_cmp);
  for (size_t i = 0; i < n; ++i) {
    key[i] = it[i].key;
    idx[i] = it[i].idx;
  }
  free(it);
}

/* Key i of n: random bits kept by `keep` */
static uint64_t key_kept(size_t i, size_t n, uint64_t keep) {
  (void)i;
  (void)n;
  return next_u64() & keep;
}

/* Key i of n: the first half with the same top digit (bits [33, 44)), the
 * second not, 256 keys to each value of the rest: sorted apart
 * (radix_split), the first half skips a pass the second makes, and the
 * halves end in different buffers; equal keys within each */
static uint64_t key_skips_differ(size_t i, size_t n, uint64_t keep) {
  (void)keep;
  uint64_t v = next_u64() & ((1ull << 33) - 1) & ~0xffull;
  if (i >= n / 2) v |= (next_u64() & 0x7ffull) << 33;
  return v;
}

static void check_keys(struct px_context *ctx, size_t n, int lo, int hi, int threads,
                       uint64_t (*key_of)(size_t, size_t, uint64_t), uint64_t keep) {
  uint64_t *k = malloc(n * sizeof *k), *kt = malloc(n * sizeof *kt), *kr = malloc(n * sizeof *kr);
  uint32_t *p = malloc(n * sizeof *p), *pt = malloc(n * sizeof *pt), *pr = malloc(n * sizeof *pr);
  uint64_t *k0 = k, *kt0 = kt;
  for (size_t i = 0; i < n; ++i) {
    k[i] = kr[i] = key_of(i, n, keep);
    p[i] = pr[i] = (uint32_t)i;
  }
  PX_CHECK(px_radix_sort(ctx, &k, &kt, &p, &pt, n, lo, hi, threads) == 0);
  plain_sort(kr, pr, n, lo, hi);
  /* the bits past hi take part in the last digit: compare the order, and
   * the keys themselves (carried whole) */
  int same = 1;
  for (size_t i = 0; i < n; ++i) same &= p[i] == pr[i] && k[i] == kr[i];
  PX_CHECK_MSG(same, "n %zu, bits [%d, %d), %d threads, keep %llx%s: not the stable sort", n, lo,
               hi, threads, (unsigned long long)keep,
               key_of == key_skips_differ ? ", halves with different skipped passes" : "");
  /* the buffers were swapped, not lost */
  PX_CHECK((k == k0 && kt == kt0) || (k == kt0 && kt == k0));
  free(k);
  free(kt);
  free(kr);
  free(p);
  free(pt);
  free(pr);
}

static void check_case(struct px_context *ctx, size_t n, int lo, int hi, int threads,
                       uint64_t keep) {
  check_keys(ctx, n, lo, hi, threads, key_kept, keep);
}

/* px_radix_insertion: on keys almost in order (sorted, then a few moved
 * and a tail appended) the stable sort by the bit range, equal keys under
 * the range in their input order; where it would move more than its
 * budget it gives up, and px_radix_sort of what it left is the stable sort
 * of the input. */
static void test_insertion(struct px_context *ctx) {
  enum { N = 20000 };
  static const int range[2][2] = {{0, 44}, {30, 63}};
  for (int rr = 0; rr < 2; ++rr) {
    const int lo = range[rr][0], hi = range[rr][1];
    for (int variant = 0; variant < 3; ++variant) {
      uint64_t *k = malloc(N * sizeof *k), *kt = malloc(N * sizeof *kt),
               *kr = malloc(N * sizeof *kr);
      uint32_t *p = malloc(N * sizeof *p), *pt = malloc(N * sizeof *pt),
               *pr = malloc(N * sizeof *pr);
      /* sorted keys with repeats under the range (the low bits random) */
      for (size_t i = 0; i < N; ++i)
        k[i] = (((uint64_t)i / 3) << 34) | (next_u64() & 0x3ffffffffull);
      if (lo == 0)
        for (size_t i = 0; i < N; ++i) k[i] &= (1ull << 44) - 1;
      for (size_t i = 0; i < N; ++i) p[i] = (uint32_t)i;
      plain_sort(k, p, N, 0, 64); /* in order */
      /* a few entries moved a little (as merges move vortices); variant 1:
       * and the tail of 200 random keys (behind the insertion budget then:
       * it gives up or sorts them, whichever); variant 2: the reversed
       * order (beyond any budget) */
      for (int m = 0; m < 20; ++m) {
        const size_t a = next_u64() % (N - 64), b = a + 1 + next_u64() % 63; /* nearby */
        const uint64_t t = k[a];
        k[a] = k[b];
        k[b] = t;
      }
      if (variant == 1)
        for (size_t i = N - 200; i < N; ++i)
          k[i] = next_u64() & (lo == 0 ? (1ull << 44) - 1 : ~0ull);
      if (variant == 2)
        for (size_t i = 0; i < N / 2; ++i) {
          const uint64_t t = k[i];
          k[i] = k[N - 1 - i];
          k[N - 1 - i] = t;
        }
      for (size_t i = 0; i < N; ++i) {
        kr[i] = k[i];
        p[i] = pr[i] = (uint32_t)i;
      }
      plain_sort(kr, pr, N, lo, hi);
      const int done = px_radix_insertion(k, p, N, lo, hi, N / 8);
      if (variant != 1) /* the tail: either outcome is right */
        PX_CHECK_MSG(variant == 0 ? done : !done, "bits [%d, %d), variant %d: %s", lo, hi, variant,
                     done ? "sorted" : "gave up");
      uint64_t *k0 = k, *kt0 = kt;
      uint32_t *p0 = p, *pt0 = pt;
      if (!done) PX_CHECK(px_radix_sort(ctx, &k, &kt, &p, &pt, N, lo, hi, 2) == 0);
      int same = 1;
      for (size_t i = 0; i < N; ++i) same &= p[i] == pr[i] && k[i] == kr[i];
      PX_CHECK_MSG(same, "bits [%d, %d), variant %d: not the stable sort", lo, hi, variant);
      free(k0);
      free(kt0);
      free(p0);
      free(pt0);
      free(kr);
      free(pr);
    }
  }
}

/* Morton keys: x in the even bits, y in the odd, 31 bits each. */
static void test_morton(void) {
  PX_CHECK(px_morton2(0, 0) == 0);
  PX_CHECK(px_morton2(1, 0) == 1 && px_morton2(0, 1) == 2 && px_morton2(3, 0) == 5);
  PX_CHECK(px_morton2(5, 3) == 0x1b); /* x 101, y 011: 01 10 11 */
  PX_CHECK(px_morton2(0x7fffffffu, 0) == 0x1555555555555555ull);
  PX_CHECK(px_morton2(0, 0x7fffffffu) == 0x2aaaaaaaaaaaaaaaull);
  /* bit 31 is not a coordinate bit */
  PX_CHECK(px_morton2(0x80000000u, 0x80000000u) == 0);
  /* the order of the keys is the quadtree's: a coordinate's higher bits first */
  PX_CHECK(px_morton2(2, 0) > px_morton2(1, 1) && px_morton2(0, 2) > px_morton2(1, 1));
}

int main(void) {
  struct px_context *ctx = NULL;
  test_morton();
  PX_CHECK(px_context_create(&ctx) == PX_STATUS_OK);
  test_insertion(ctx);
  for (int threads = 1; threads <= 3; ++threads) {
    /* few distinct keys: long runs of equal keys (stability) */
    check_case(ctx, 20000, 0, 44, threads, 0x7full << 20);
    /* every digit in use, 4 passes */
    check_case(ctx, 30011, 0, 44, threads, (1ull << 44) - 1);
    /* a middle digit the same for all keys (its pass skipped) */
    check_case(ctx, 9000, 0, 44, threads, ((1ull << 44) - 1) & ~(0x7ffull << 11));
    /* the FMM's range: key bits [30, 63) */
    check_case(ctx, 25000, 30, 63, threads, ~0ull >> 1);
    /* halves sorted apart and merged (16k-200k keys on several threads):
     * odd counts, equal keys across the halves, halves whose skipped passes
     * differ (the first half's top digit uniform, the second's not) */
    check_case(ctx, 50001, 0, 44, threads, 0x3full << 30);
    check_case(ctx, 199999, 30, 63, threads, ~0ull >> 1);
    check_keys(ctx, 40000, 0, 44, threads, key_skips_differ, 0);
    /* tiny inputs (one thread whatever asked) and none */
    check_case(ctx, 5, 0, 44, threads, (1ull << 44) - 1);
    check_case(ctx, 1, 0, 44, threads, (1ull << 44) - 1);
  }
  check_case(ctx, 0, 0, 44, 2, (1ull << 44) - 1);
  px_context_free(ctx);
  return px_test_report("test_core_radix");
}
