/* The decomposition of the granular system over K ranks (system_ranks.c),
 * checked exhaustively on one process for every rank of K = 2..5 and 17
 * (more ranks than the 16 work ranges of 4800 discs: idle ranks), on the
 * neighbour list of a bed of discs:
 *  - the strips: rank r owns whole work ranges, the owners' slots tile
 *    [0, N) in rank order, and their disc counts differ by at most one
 *    range's (the balance);
 *  - the ghosts rank r receives from q are exactly the partners in q's
 *    slots of r's pairs (ascending, each once), all in later strips, and
 *    they are what q sends to r;
 *  - the pair records r sends to q are exactly r's pairs whose partner q
 *    owns (ascending), and they are what q receives from r.
 * Any pair the ranks would evaluate with a stale partner, or a partner's
 * force summed without a record, breaks one of these. */
#include <stdlib.h>
#include <string.h>

#include "granular_test_util.h"
#include "partix/rng.h"

#define NX 80
#define NY 60

static struct px_gran_sys *bed(struct px_context *ctx) {
  struct px_gran_sys *s = NULL;
  uint64_t rng[4];
  int i, j;
  if (px_gran_sys_create(ctx, PX_PRECISION_MIXED, 1, &s) != PX_STATUS_OK) return NULL;
  gt_law(&s->pp, 2e5, 0.7, 0.3);
  gt_law(&s->pw, 2e5, 0.6, 0.2);
  px_rng_seed(rng, 11);
  for (j = 0; j < NY; ++j)
    for (i = 0; i < NX; ++i) {
      /* radii 1.5 to 1.8 mm on a hexagonal lattice of 4 mm, jittered by up
       * to 0.2 mm: most neighbours (in the row and the rows above and below)
       * within the skin, some not */
      double x = 0.004 * i + 0.002 * (j % 2) + 0.0002 * px_rng_uniform(rng);
      double y = 0.0035 * j + 0.0002 * px_rng_uniform(rng);
      double r = 0.0015 + 0.0003 * px_rng_uniform(rng), m = 7800 * 3.14159265 * r * r * 0.004;
      px_gran_sys_add(s, 1, &x, &y, &r, &m);
    }
  PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
  return s;
}

/* The rank owning slot j, from the owners' first slots ob[0..K]. */
static int owner(const size_t *ob, int K, size_t j) {
  int q = 0;
  while (q + 1 < K && ob[q + 1] <= j) ++q;
  return q;
}

/* One rank's lists against the pair list (failures counted in *bad). */
static void check_rank(struct px_gran_sys *s, const size_t *ob, int K, int r, size_t *bad,
                       size_t *ghosts, size_t *records) {
  const size_t o0 = ob[r], o1 = ob[r + 1];
  unsigned char *want = calloc(s->n, 1);
  int q;
  size_t k, j, c;
  if (!want) return;
  s->nrank = K, s->rank = r;
  PX_CHECK_OK(s->ctx, px_gran_ranks_lists(s));
  for (k = (size_t)s->pstart[o0]; k < (size_t)s->pstart[o1]; ++k) {
    if ((size_t)s->pj[k] >= o1) want[s->pj[k]] = 1;
    if ((size_t)s->pj[k] < o0) ++*bad; /* a partner before the strip: j > i broken */
  }
  for (q = 0; q < K; ++q) {
    const int32_t *g, *rs;
    const size_t ng = px_gran_ranks_list(s, 1, q, &g), nr = px_gran_ranks_list(s, 2, q, &rs);
    size_t at = 0;
    /* ghosts from q: the wanted partners in q's slots, ascending */
    for (j = ob[q]; j < ob[q + 1]; ++j)
      if (q != r && want[j]) {
        if (at >= ng || (size_t)g[at] != j) ++*bad;
        ++at;
      }
    if (at != ng) ++*bad;
    *ghosts += ng;
    /* records to q: r's pairs whose partner q owns, ascending */
    at = 0;
    for (k = (size_t)s->pstart[o0]; k < (size_t)s->pstart[o1]; ++k)
      if (q != r && owner(ob, K, (size_t)s->pj[k]) == q) {
        if (at >= nr || (size_t)rs[at] != k) ++*bad;
        ++at;
      }
    if (at != nr) ++*bad;
    *records += nr;
    if (q <= r && (ng || nr)) ++*bad; /* partners lie in later strips only */
  }
  /* what r sends must be what its peers receive: check from r's side that
   * q's receive lists (rebuilt as q) hold r's sends */
  for (q = 0; q < K; ++q) {
    int32_t *gs = NULL, *rr = NULL;
    const int32_t *p;
    size_t ngs = px_gran_ranks_list(s, 0, q, &p);
    gs = malloc((ngs + 1) * sizeof *gs);
    if (!gs) break;
    memcpy(gs, p, ngs * sizeof *gs);
    s->rank = q;
    PX_CHECK_OK(s->ctx, px_gran_ranks_lists(s));
    c = px_gran_ranks_list(s, 1, r, &p);
    if (c != ngs || (c && memcmp(p, gs, c * sizeof *p) != 0)) ++*bad;
    s->rank = r;
    PX_CHECK_OK(s->ctx, px_gran_ranks_lists(s));
    c = px_gran_ranks_list(s, 3, q, &p);
    rr = malloc((c + 1) * sizeof *rr);
    if (rr) {
      const int32_t *snd;
      size_t ns;
      memcpy(rr, p, c * sizeof *rr);
      s->rank = q;
      PX_CHECK_OK(s->ctx, px_gran_ranks_lists(s));
      ns = px_gran_ranks_list(s, 2, r, &snd);
      if (ns != c || (c && memcmp(snd, rr, c * sizeof *rr) != 0)) ++*bad;
      s->rank = r;
      PX_CHECK_OK(s->ctx, px_gran_ranks_lists(s));
    }
    free(gs);
    free(rr);
  }
  free(want);
}

int main(void) {
  struct px_context *ctx = NULL;
  struct px_gran_sys *s;
  static const int ks[] = {2, 3, 4, 5, 17};
  size_t m;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  s = bed(ctx);
  PX_CHECK(s != NULL);
  if (s) {
    const size_t range = s->n / (size_t)s->nranges;
    PX_CHECK_MSG(s->nranges == 16, "%d work ranges of %zu discs (16 expected)", s->nranges, s->n);
    PX_CHECK_MSG(s->npairs > s->n, "%zu pairs of %zu discs", s->npairs, s->n);
    for (m = 0; m < sizeof ks / sizeof ks[0]; ++m) {
      const int K = ks[m];
      size_t ob[32], bad = 0, ghosts = 0, records = 0, lo = s->n, hi = 0;
      int r, vt0, vt1, idle = 0;
      for (r = 0; r <= K; ++r) {
        s->nrank = K, s->rank = r < K ? r : K - 1;
        px_gran_ranks_own(s, &vt0, &vt1);
        ob[r] = s->rng_i[r < K ? vt0 : vt1];
      }
      PX_CHECK(ob[0] == 0 && ob[K] == s->n);
      for (r = 0; r < K; ++r) {
        const size_t nd = ob[r + 1] - ob[r];
        PX_CHECK(ob[r] <= ob[r + 1]);
        if (nd == 0) {
          ++idle;
          continue;
        }
        if (nd < lo) lo = nd;
        if (nd > hi) hi = nd;
      }
      PX_CHECK_MSG(hi - lo <= range + 1, "K = %d: %zu to %zu discs per rank", K, lo, hi);
      PX_CHECK(idle == (K > s->nranges ? K - s->nranges : 0));
      for (r = 0; r < K; ++r) {
        check_rank(s, ob, K, r, &bad, &ghosts, &records);
        px_gran_ranks_free(s);
      }
      printf(
          "K = %d: %zu to %zu discs per rank, %d idle, %zu ghosts, %zu boundary pairs; "
          "list errors: %zu\n",
          K, lo, hi, idle, ghosts, records, bad);
      PX_CHECK(bad == 0);
      PX_CHECK(K > s->nranges || (ghosts > 0 && records > 0));
    }
    s->nrank = 1, s->rank = 0;
    px_gran_sys_free(s);
  }
  px_context_free(ctx);
  return px_test_report("test_granular_ranks");
}
