/* The vortex solver over the ranks of one run (vortex_ranks.h): the
 * engine's ranks, the shares of the split sums and their gathers. */
#include "solvers/vortex/vortex_ranks.h"

#include <string.h>

#include "partix/case.h"
#include "core/comm.h"
#include "nbody/nbody_impl.h"
#include "partix/memory.h"

enum px_status px_vortex_ranks_init(struct px_context *ctx, struct px_vortex_engine *e, int fmm,
                                    enum px_status st) {
  struct px_comm *comm = px_context_comm(ctx);
  int k = px_comm_size(comm);
  if (e) {
    e->comm = comm;
    e->comm_bytes = e->comm_last = 0.0;
    e->comm_step = -1;
  }
  if (k < 2) return st;
  PX_TRY(px_comm_agree(comm, ctx, st, NULL));
  struct px_vortex_panels *p = &e->pan;
  size_t ns = p->nsys;
  if (p->ainv) PX_TRY(px_comm_bcast(comm, p->ainv, ns * ns * sizeof(double), 0));
  if (p->lu_f) {
    PX_TRY(px_comm_bcast(comm, p->lu_f, ns * ns * sizeof(float), 0));
    PX_TRY(px_comm_bcast(comm, p->ipiv_f, ns * sizeof(int), 0));
  }
  if (!fmm) { /* the opencl engine (vortex_opencl.c) */
    px_log(ctx, PX_LOG_LEVEL_INFO,
           "vortex over %d ranks, the wake replicated on every rank's device; the convective "
           "and diffusive (eps*, VVD) direct sums split into %d contiguous target shares balanced "
           "by count (the sheet, loads, moves and "
           "restructuring whole on every rank); per step each rank receives one allgatherv of "
           "2N device reals per convective sum and 3N per diffusive sum: 10 N reals with rk2, "
           "5 N with euler (N vortices), and reads back 3N for the ranks' wake comparison",
           k, k);
    return PX_STATUS_OK;
  }
  px_log(ctx, PX_LOG_LEVEL_INFO,
         "vortex over %d ranks: the wake replicated on every rank; the convective FMM sums split "
         "by subtrees of the FMM's Morton order, the diffusive (VVD) sums and the merge "
         "partners' search by the vortex tree's groups and leaves, the crossing tests by "
         "contiguous shares, %d shares balanced by vortex count, the sheet's near-panel terms "
         "and the wall vorticity by contiguous shares of the panels (direct sums, the sheet's "
         "solve, removals and merges whole on every rank); per step each rank receives one "
         "allgatherv of 2N doubles per FMM sum, of 3N per diffusive sum, of N int32 partners, "
         "of N int32 crossed panels per crossing test and of n doubles per sheet and loads: "
         "92 N + 24 n bytes with rk2, 48 N + 16 n with euler (N vortices, n panels)",
         k, k);
  return PX_STATUS_OK;
}

int px_vortex_ranks_count(const struct px_vortex_engine *e) { return px_comm_size(e->comm); }

enum px_status px_vortex_ranks_check(struct px_case *c, struct px_context *ctx, int engine_ranks,
                                     const char *backend) {
  int k = px_comm_size(px_context_comm(ctx));
  if (k < 2 || engine_ranks) return PX_STATUS_OK;
  return px_case_fail(c, "backend.type",
                      "the vortex engine of backend '%s' does not split its sums over MPI ranks "
                      "(started as %d ranks): use backend cpu, or run on one rank",
                      backend, k);
}

void px_vortex_ranks_runs(const struct px_vortex_engine *e, const uint32_t *starts, size_t nrun,
                          size_t n, size_t *r0, size_t *r1, size_t *lo, size_t *hi) {
  size_t k = (size_t)px_comm_size(e->comm), r = (size_t)px_comm_rank(e->comm);
  size_t a = n * r / k, b = n * (r + 1) / k, g0 = nrun, g1 = nrun;
  /* the first run starting at or after a, and after b */
  for (size_t g = nrun; g-- > 0;) {
    if (starts[g] >= a) g0 = g;
    if (starts[g] >= b) g1 = g;
  }
  *r0 = g0;
  *r1 = g1 > g0 ? g1 : g0;
  *lo = g0 < nrun ? starts[g0] : n;
  *hi = g1 < nrun ? starts[g1] : n;
  if (*hi < *lo) *hi = *lo;
}

/* b bytes received in a gather of this step */
static void count_bytes(struct px_vortex_engine *e, double b) {
  e->comm_last = e->comm_step == e->step ? e->comm_last + b : b;
  e->comm_step = e->step;
  e->comm_bytes += b;
}

enum px_status px_vortex_ranks_gather(struct px_vortex_engine *e, int sum, enum px_status st,
                                      const uint32_t *order, size_t n, size_t lo, size_t hi,
                                      double *const *arr, int narr) {
  struct px_comm *comm = e->comm;
  size_t k = (size_t)px_comm_size(comm), m = hi - lo, na = (size_t)narr;
  if (k < 2) return st;
  double *send = NULL;
  size_t *counts = NULL;
  if (st == PX_STATUS_OK && order) {
    send = px_mem_alloc(e->ctx, "vortex.ranks", (na * (m + n) + 1) * sizeof(double));
    counts = px_mem_alloc(e->ctx, "vortex.ranks", k * sizeof(size_t));
    if (!send || !counts) st = px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (gather)");
  }
  st = px_comm_agree(comm, e->ctx, st, NULL);
  if (st == PX_STATUS_OK && order) {
    double *recv = send + na * m;
    for (size_t a = 0; a < na; ++a)
      for (size_t q = lo; q < hi; ++q) send[a * m + q - lo] = arr[a][order[q]];
    st = px_comm_allgatherv(comm, send, na * m * sizeof(double), recv, counts);
    /* rank r's block: its count c of values of arr[0], then of arr[1], ... */
    size_t at = 0, q = 0;
    e->split_n[sum] = n;
    e->split_min[sum] = n;
    e->split_max[sum] = 0;
    for (size_t r = 0; st == PX_STATUS_OK && r < k; ++r) {
      size_t c = counts[r] / (na * sizeof(double));
      if (q + c > n) {
        st = px_context_fail(e->ctx, PX_STATUS_IO, "vortex gather: %zu values past %zu", q + c, n);
        break;
      }
      for (size_t a = 0; a < na; ++a)
        for (size_t j = 0; j < c; ++j) arr[a][order[q + j]] = recv[at + a * c + j];
      e->split_min[sum] = c < e->split_min[sum] ? c : e->split_min[sum];
      e->split_max[sum] = c > e->split_max[sum] ? c : e->split_max[sum];
      at += na * c;
      q += c;
    }
    if (st == PX_STATUS_OK && q != n)
      st = px_context_fail(e->ctx, PX_STATUS_IO, "vortex gather: %zu of %zu values", q, n);
    count_bytes(e, (double)(na * n * sizeof(double)));
  }
  px_mem_free(e->ctx, send);
  px_mem_free(e->ctx, counts);
  return st;
}

void px_vortex_ranks_share(const struct px_vortex_engine *e, size_t n, size_t *lo, size_t *hi) {
  size_t k = (size_t)px_comm_size(e->comm), r = (size_t)px_comm_rank(e->comm);
  *lo = n * r / k;
  *hi = n * (r + 1) / k;
}

enum px_status px_vortex_ranks_gather_shares(struct px_vortex_engine *e, int sum, enum px_status st,
                                             size_t n, size_t narr, size_t es, const void *send,
                                             void *out) {
  struct px_comm *comm = e->comm;
  size_t k = (size_t)px_comm_size(comm);
  if (k < 2) return st;
  unsigned char *recv = NULL;
  size_t *counts = NULL;
  if (st == PX_STATUS_OK) {
    recv = px_mem_alloc(e->ctx, "vortex.ranks", narr * n * es + 1);
    counts = px_mem_alloc(e->ctx, "vortex.ranks", k * sizeof(size_t));
    if (!recv || !counts) st = px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (gather)");
  }
  st = px_comm_agree(comm, e->ctx, st, NULL);
  if (st == PX_STATUS_OK) {
    /* every rank knows every share: one collective */
    for (size_t r = 0; r < k; ++r) counts[r] = narr * es * (n * (r + 1) / k - n * r / k);
    st = px_comm_allgatherv_known(comm, send, recv, counts);
  }
  if (st == PX_STATUS_OK) {
    /* rank r's block: its c values of array 0, then of array 1, ... */
    unsigned char *o = out;
    size_t at = 0;
    e->split_n[sum] = n;
    e->split_min[sum] = n;
    e->split_max[sum] = 0;
    for (size_t r = 0; r < k; ++r) {
      size_t q = n * r / k, c = n * (r + 1) / k - q;
      for (size_t a = 0; a < narr; ++a, at += c * es)
        memcpy(o + (a * n + q) * es, recv + at, c * es);
      e->split_min[sum] = c < e->split_min[sum] ? c : e->split_min[sum];
      e->split_max[sum] = c > e->split_max[sum] ? c : e->split_max[sum];
    }
    count_bytes(e, (double)(narr * n * es));
  }
  px_mem_free(e->ctx, recv);
  px_mem_free(e->ctx, counts);
  return st;
}

void px_vortex_ranks_leaves(const struct px_vortex_engine *e, const struct px_vortex_tree *t,
                            size_t *a, size_t *b, size_t *lo, size_t *hi) {
  size_t k = (size_t)px_comm_size(e->comm), r = (size_t)px_comm_rank(e->comm), n = t->n;
  *a = n * r / k;
  *b = n * (r + 1) / k;
  /* leaves tile [0, n) in runs of the sorted order: those starting in
   * [a, b) cover one run */
  size_t l0 = n, l1 = 0;
  for (size_t q = 0; q < t->nnode; ++q)
    if (t->left[q] < 0 && t->lo[q] >= *a && t->lo[q] < *b) {
      l0 = t->lo[q] < l0 ? t->lo[q] : l0;
      l1 = t->hi[q] > l1 ? t->hi[q] : l1;
    }
  *lo = l0 < l1 ? l0 : 0;
  *hi = l0 < l1 ? l1 : 0;
}

enum px_status px_vortex_ranks_gather_runs(struct px_vortex_engine *e, enum px_status st, size_t n,
                                           size_t lo, size_t hi, void *v, size_t es) {
  struct px_comm *comm = e->comm;
  size_t k = (size_t)px_comm_size(comm);
  if (k < 2) return st;
  unsigned char *recv = NULL;
  if (st == PX_STATUS_OK) {
    recv = px_mem_alloc(e->ctx, "vortex.ranks", (n + 1) * es);
    if (!recv) st = px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (gather)");
  }
  st = px_comm_agree(comm, e->ctx, st, NULL);
  if (st == PX_STATUS_OK) {
    /* the runs come back in rank order, which is the values' order */
    st = px_comm_allgatherv(comm, (unsigned char *)v + lo * es, (hi - lo) * es, recv, NULL);
    if (st == PX_STATUS_OK) memcpy(v, recv, n * es);
    count_bytes(e, (double)(n * es));
  }
  px_mem_free(e->ctx, recv);
  return st;
}

enum px_status px_vortex_ranks_verify(struct px_vortex_engine *e, enum px_status st) {
  if (px_comm_size(e->comm) < 2) return st;
  PX_TRY(px_comm_agree(e->comm, e->ctx, st, NULL));
  const struct px_vortex_wake *w = &e->w;
  /* FNV-1a's step over the 64-bit patterns, in wake order */
  uint64_t hsh = 1469598103934665603u;
  const double *arr[3] = {w->x, w->y, w->g};
  for (int a = 0; a < 3; ++a)
    for (size_t i = 0; i < w->n; ++i) {
      uint64_t b;
      memcpy(&b, arr[a] + i, sizeof b);
      hsh = (hsh ^ b) * 1099511628211u;
    }
  /* equal on every rank iff the maxima of v and -v are opposite */
  long v[4] = {(long)(hsh >> 1), -(long)(hsh >> 1), (long)w->n, -(long)w->n};
  PX_TRY(px_comm_allreduce_long(e->comm, v, 4, PX_COMM_MAX));
  if (v[0] == -v[1] && v[2] == -v[3]) return PX_STATUS_OK;
  return px_context_fail(e->ctx, PX_STATUS_INTERNAL,
                         "step %ld: the ranks' copies of the wake differ (%ld to %ld vortices): "
                         "the ranks rounded the replicated blocks differently (nodes with "
                         "different CPUs or libraries?); run on one kind of node, or on one rank",
                         e->step, -v[3], v[2]);
}

void px_vortex_ranks_split_sums(struct px_vortex_engine *e, int on) {
  int k = px_comm_size(e->comm);
  if (k > 1) px_nbody_set_part(e->nbe, on ? px_comm_rank(e->comm) : 0, on ? k : 1);
}

void px_vortex_ranks_report(const struct px_vortex_engine *e) {
  int k = px_comm_size(e->comm);
  if (k < 2) return;
  size_t n = e->split_n[1];
  px_log(e->ctx, PX_LOG_LEVEL_INFO,
         "vortex over %d ranks: last split of the convective sum %zu to %zu of %zu "
         "vortices per rank (0 of 0: cpu direct sums only, whole on every rank), of the diffusive "
         "sum %zu to %zu of %zu; rank 0 received %.4g MB in the gathers, %.4g bytes = %.3g N "
         "in the last step's, and spent %.3g s in communication",
         k, e->split_min[0], e->split_max[0], e->split_n[0], e->split_min[1], e->split_max[1], n,
         e->comm_bytes / 1e6, e->comm_last, n > 0 ? e->comm_last / (double)n : 0.0,
         px_comm_seconds(e->comm));
}
