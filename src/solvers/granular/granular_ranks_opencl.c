/* The granular opencl engine over K MPI ranks (`mpirun -np K partix run`
 * with backend.type: opencl): each rank's device steps the discs it owns,
 * bit-identical to one rank.
 *
 * Why no pair records travel (unlike the cpu loops, system_ranks.c): the
 * device keeps a full neighbour list per disc (both directions) with its
 * own copy of every pair's contact history (granular.cl), so each disc's
 * force is summed by its own work-item from its own rows and its
 * neighbours' state; the drift, the kick, the wall contacts and the list
 * rebuild are per disc too. A disc's new state therefore depends on which
 * device computes it only through its neighbours' (x, y, vx, vy, w): those
 * are exact copies, so the bits are those of one rank on any K.
 *
 * Ownership: the discs sorted by height (then id) cut into K runs of equal
 * count, i.e. K horizontal strips of about N/K discs, recut at every
 * rebuild from the positions every rank then holds (the cut only decides
 * who computes a disc, never its bits). Every device holds every array;
 * a rank's owned rows are authoritative, the others refreshed when needed:
 *   - per step, after the drift: the ghost rows (discs of other strips in
 *     the lists of this rank's discs), 5 state reals each, packed on the
 *     device (gran_pack), read, sent point to point to the ranks whose
 *     discs list them, and the received rows written and unpacked;
 *   - per step, all ranks: the largest displacement (allreduce MAX of the
 *     float's bits: exact), which decides the rebuild on every rank;
 *   - every 64 steps and at outputs: every rank's wall events, sorted as
 *     one rank sorts its own (the order depends on the events only);
 *   - at a rebuild: every owner's rows of the state a step changes (state,
 *     accelerations, contact histories, wall slots) to every device, which
 *     rebuilds every disc's lists itself; at an output or a checkpoint the
 *     same onto rank 0's device only, whose mirror is then downloaded. */
#include <stdlib.h>
#include <string.h>

#include "core/comm.h"
#include "partix/backend.h"
#include "partix/context.h"
#include "partix/memory.h"
#include "solvers/granular/granular_opencl_impl.h"
#include "solvers/granular/wall_kernel.h"

/* Bytes of a ghost row: x, y, vx, vy, w in the state precision. */
#define PX_GRAN_CL_GHOST_REALS 5

struct px_gran_cl_plan {
  int32_t *owner;      /* n: the rank stepping each disc */
  uint32_t *ids;       /* n: every rank's discs, rank by rank, ascending ids */
  size_t *ostart;      /* K + 1: rank q's discs are ids[ostart[q]..ostart[q+1]) */
  uint32_t *gidx;      /* ghost rows: those sent (by peer), then those received */
  size_t *gs, *gr;     /* K + 1 each: peer q's rows of the sent / received ones */
  size_t gcap;         /* rows B_GIDX and B_GBUF hold */
  unsigned char *mark; /* n: scratch */
  unsigned char *buf;  /* host staging of the ghost rows (gcap rows) */
  int logged;          /* the strips were logged once at INFO */
};

void px_gran_cl_ranks_free(struct px_gran_cl *e) {
  struct px_gran_cl_plan *P = e->plan;
  if (!P) return;
  px_mem_free(e->ctx, P->owner);
  px_mem_free(e->ctx, P->ids);
  px_mem_free(e->ctx, P->ostart);
  px_mem_free(e->ctx, P->gidx);
  px_mem_free(e->ctx, P->gs);
  px_mem_free(e->ctx, P->gr);
  px_mem_free(e->ctx, P->mark);
  px_mem_free(e->ctx, P->buf);
  px_mem_free(e->ctx, P);
  e->plan = NULL;
}

static enum px_status px_gran_cl_plan_alloc(struct px_gran_cl *e) {
  struct px_gran_cl_plan *P;
  const size_t n1 = e->n ? e->n : 1, K1 = (size_t)e->nrank + 1;
  if (e->plan) return PX_STATUS_OK;
  P = e->plan = px_mem_calloc(e->ctx, "granular opencl ranks", 1, sizeof *P);
  if (!P) return PX_STATUS_NOMEM;
  P->owner = px_mem_alloc(e->ctx, "granular opencl ranks", n1 * sizeof *P->owner);
  P->ids = px_mem_alloc(e->ctx, "granular opencl ranks", n1 * sizeof *P->ids);
  P->ostart = px_mem_calloc(e->ctx, "granular opencl ranks", K1, sizeof *P->ostart);
  P->gs = px_mem_calloc(e->ctx, "granular opencl ranks", K1, sizeof *P->gs);
  P->gr = px_mem_calloc(e->ctx, "granular opencl ranks", K1, sizeof *P->gr);
  P->mark = px_mem_alloc(e->ctx, "granular opencl ranks", n1);
  if (!P->owner || !P->ids || !P->ostart || !P->gs || !P->gr || !P->mark) return PX_STATUS_NOMEM;
  return PX_STATUS_OK;
}

struct px_gran_cl_ykey {
  double y;
  uint32_t id;
};

static int px_gran_cl_ykey_cmp(const void *pa, const void *pb) {
  const struct px_gran_cl_ykey *a = pa, *b = pb;
  if (a->y != b->y) return a->y < b->y ? -1 : 1;
  return a->id < b->id ? -1 : a->id > b->id;
}

/* The strips: discs by height (then id) in K runs of equal count; each
 * rank's discs listed in ascending id (P->ids, P->ostart). */
static enum px_status px_gran_cl_plan_owners(struct px_gran_cl *e) {
  struct px_gran_cl_plan *P = e->plan;
  const size_t n = e->n;
  const int K = e->nrank;
  struct px_gran_cl_ykey *key =
      px_mem_alloc(e->ctx, "granular opencl ranks", (n ? n : 1) * sizeof *key);
  double *y = px_mem_alloc(e->ctx, "granular opencl ranks", (n ? n : 1) * sizeof *y);
  enum px_status st = key && y ? PX_STATUS_OK : PX_STATUS_NOMEM;
  size_t p, i;
  int q;
  if (st == PX_STATUS_OK) st = px_gran_cl_get(e, B_Y, y, n, e->ss);
  for (i = 0; i < n && st == PX_STATUS_OK; ++i) key[i].y = y[i], key[i].id = (uint32_t)i;
  if (st == PX_STATUS_OK) {
    qsort(key, n, sizeof *key, px_gran_cl_ykey_cmp);
    for (q = 0; q < K; ++q)
      for (p = n * (size_t)q / (size_t)K; p < n * (size_t)(q + 1) / (size_t)K; ++p)
        P->owner[key[p].id] = q;
    memset(P->ostart, 0, (size_t)(K + 1) * sizeof *P->ostart);
    for (i = 0; i < n; ++i) ++P->ostart[P->owner[i] + 1];
    for (q = 0; q < K; ++q) P->ostart[q + 1] += P->ostart[q];
    memcpy(P->gs, P->ostart, (size_t)(K + 1) * sizeof *P->gs); /* fill cursors */
    for (i = 0; i < n; ++i) P->ids[P->gs[P->owner[i]]++] = (uint32_t)i;
  }
  px_mem_free(e->ctx, key);
  px_mem_free(e->ctx, y);
  return st;
}

/* Room for `rows` ghost rows on the device and the host. */
static enum px_status px_gran_cl_plan_room(struct px_gran_cl *e, size_t rows) {
  struct px_gran_cl_plan *P = e->plan;
  const size_t rb = PX_GRAN_CL_GHOST_REALS * e->ss;
  if (rows <= P->gcap && P->gidx) return PX_STATUS_OK;
  rows = rows + rows / 2 + 64;
  px_buffer_free(e->b[B_GIDX]);
  px_buffer_free(e->b[B_GBUF]);
  e->b[B_GIDX] = e->b[B_GBUF] = NULL;
  px_mem_free(e->ctx, P->gidx);
  px_mem_free(e->ctx, P->buf);
  P->gcap = 0;
  P->gidx = px_mem_alloc(e->ctx, "granular opencl ranks", rows * sizeof *P->gidx);
  P->buf = px_mem_alloc(e->ctx, "granular opencl ranks", rows * rb);
  if (!P->gidx || !P->buf) return PX_STATUS_NOMEM;
  PX_TRY(px_buffer_create(e->be, "granular opencl ghosts", rows * sizeof(uint32_t), &e->b[B_GIDX]));
  PX_TRY(px_buffer_create(e->be, "granular opencl ghosts", rows * rb, &e->b[B_GBUF]));
  P->gcap = rows;
  return PX_STATUS_OK;
}

/* The ghost rows from the lists (cnt, nbr: every disc's, as the device has
 * them): received, the partners of this rank's discs that other ranks own
 * (by owner, ascending id); sent to rank q, this rank's discs in the lists
 * of q's discs (ascending id: the order q receives them in). */
static enum px_status px_gran_cl_plan_ghosts(struct px_gran_cl *e, const int32_t *cnt,
                                             const int32_t *nbr) {
  struct px_gran_cl_plan *P = e->plan;
  const size_t NM = PX_GRAN_CL_NMAX, n = e->n;
  const int K = e->nrank, me = e->rank;
  const uint32_t *mine = P->ids + P->ostart[me];
  const size_t nmine = P->ostart[me + 1] - P->ostart[me];
  size_t p, j, at, nsend = 0, nrecv = 0;
  int q, c;
  /* sizes first */
  for (q = 0; q <= K; ++q) P->gs[q] = P->gr[q] = 0;
  memset(P->mark, 0, n ? n : 1);
  for (p = 0; p < nmine; ++p)
    for (c = 0; c < cnt[mine[p]]; ++c) {
      const int32_t k = nbr[mine[p] * NM + (size_t)c];
      if (P->owner[k] != me && !P->mark[k]) P->mark[k] = 1, ++P->gr[P->owner[k] + 1], ++nrecv;
    }
  for (q = 0; q < K; ++q) {
    if (q == me) continue;
    for (p = 0; p < nmine; ++p) P->mark[mine[p]] = 0;
    for (p = P->ostart[q]; p < P->ostart[q + 1]; ++p)
      for (c = 0; c < cnt[P->ids[p]]; ++c) {
        const int32_t k = nbr[P->ids[p] * NM + (size_t)c];
        if (P->owner[k] == me && !P->mark[k]) P->mark[k] = 1, ++P->gs[q + 1], ++nsend;
      }
  }
  for (q = 0; q < K; ++q) P->gs[q + 1] += P->gs[q], P->gr[q + 1] += P->gr[q];
  PX_TRY(px_gran_cl_plan_room(e, nsend + nrecv));
  /* the rows sent: per peer, this rank's discs its lists reach, ascending */
  for (q = 0, at = 0; q < K; ++q) {
    if (q == me) continue;
    for (p = 0; p < nmine; ++p) P->mark[mine[p]] = 0;
    for (p = P->ostart[q]; p < P->ostart[q + 1]; ++p)
      for (c = 0; c < cnt[P->ids[p]]; ++c) {
        const int32_t k = nbr[P->ids[p] * NM + (size_t)c];
        if (P->owner[k] == me) P->mark[k] = 1;
      }
    for (p = 0; p < nmine; ++p)
      if (P->mark[mine[p]]) P->gidx[at++] = mine[p];
  }
  /* the rows received: per owner, ascending */
  memset(P->mark, 0, n ? n : 1);
  for (p = 0; p < nmine; ++p)
    for (c = 0; c < cnt[mine[p]]; ++c) {
      const int32_t k = nbr[mine[p] * NM + (size_t)c];
      if (P->owner[k] != me) P->mark[k] = 1;
    }
  {
    size_t cur[PX_COMM_BATCH_MAX]; /* K <= PX_COMM_BATCH_MAX (px_gran_cl_create) */
    for (q = 0; q < K; ++q) cur[q] = nsend + P->gr[q];
    for (j = 0; j < n; ++j)
      if (P->mark[j]) P->gidx[cur[P->owner[j]]++] = (uint32_t)j;
  }
  if (nsend + nrecv)
    PX_TRY(px_buffer_write(e->b[B_GIDX], 0, (nsend + nrecv) * sizeof(uint32_t), P->gidx));
  return PX_STATUS_OK;
}

/* INFO on rank 0, once: the discs, ghost rows and bytes of each rank. */
static enum px_status px_gran_cl_plan_log(struct px_gran_cl *e) {
  struct px_gran_cl_plan *P = e->plan;
  const int K = e->nrank, me = e->rank;
  const size_t rb = PX_GRAN_CL_GHOST_REALS * e->ss;
  long mine[3], *all;
  enum px_status st;
  int q;
  /* the same condition on every rank: once there are lists (after the first
   * rebuild, or the lists of a checkpoint) */
  if (P->logged || e->need_rebuild) return PX_STATUS_OK;
  mine[0] = (long)(P->ostart[me + 1] - P->ostart[me]);
  mine[1] = (long)P->gr[K];
  mine[2] = (long)(P->gs[K] * rb);
  all = px_mem_alloc(e->ctx, "granular opencl ranks", (size_t)K * sizeof mine);
  if (!all) return PX_STATUS_NOMEM;
  st = px_comm_allgatherv(e->comm, mine, sizeof mine, all, NULL);
  for (q = 0; q < K && st == PX_STATUS_OK && me == 0; ++q)
    px_log(e->ctx, PX_LOG_LEVEL_INFO,
           "granular ranks (opencl): rank %d of %d: %ld discs, %ld ghost discs received, %ld "
           "bytes sent per step (strips recut at every rebuild)",
           q, K, all[3 * q], all[3 * q + 1], all[3 * q + 2]);
  P->logged = 1;
  px_mem_free(e->ctx, all);
  return st;
}

enum px_status px_gran_cl_ranks_plan(struct px_gran_cl *e) {
  const size_t n = e->n, NM = PX_GRAN_CL_NMAX;
  int32_t *cnt, *nbr;
  enum px_status st;
  PX_TRY(px_gran_cl_plan_alloc(e));
  PX_TRY(px_gran_cl_plan_owners(e));
  e->nown = e->plan->ostart[e->rank + 1] - e->plan->ostart[e->rank];
  if (e->nown)
    PX_TRY(px_buffer_write(e->b[B_OWN], 0, e->nown * sizeof(uint32_t),
                           e->plan->ids + e->plan->ostart[e->rank]));
  cnt = px_mem_alloc(e->ctx, "granular opencl ranks", (n ? n : 1) * sizeof *cnt);
  nbr = px_mem_alloc(e->ctx, "granular opencl ranks", (n ? n : 1) * NM * sizeof *nbr);
  st = cnt && nbr ? PX_STATUS_OK : PX_STATUS_NOMEM;
  if (st == PX_STATUS_OK) st = px_buffer_read(e->b[B_NCOUNT], 0, n * 4, cnt);
  if (st == PX_STATUS_OK) st = px_buffer_read(e->b[B_NBR], 0, n * NM * 4, nbr);
  if (st == PX_STATUS_OK) st = px_gran_cl_plan_ghosts(e, cnt, nbr);
  px_mem_free(e->ctx, cnt);
  px_mem_free(e->ctx, nbr);
  PX_TRY(st);
  e->plan_ok = 1;
  return px_gran_cl_plan_log(e);
}

enum px_status px_gran_cl_ranks_ghosts(struct px_gran_cl *e) {
  struct px_gran_cl_plan *P = e->plan;
  const int K = e->nrank;
  const size_t rb = PX_GRAN_CL_GHOST_REALS * e->ss, ns = P->gs[K], nr = P->gr[K];
  struct px_comm_msg msg[PX_COMM_BATCH_MAX];
  size_t nm = 0;
  int q, pass;
  if (ns) {
    PX_TRY(px_gran_cl_pack(e, 0, 0, ns));
    PX_TRY(px_buffer_read(e->b[B_GBUF], 0, ns * rb, P->buf));
  }
  for (pass = 0; pass < 2; ++pass)
    for (q = 0; q < K; ++q) {
      const size_t *L = pass ? P->gr : P->gs, c = L[q + 1] - L[q];
      if (c == 0) continue;
      if (nm == PX_COMM_BATCH_MAX)
        return px_context_fail(e->ctx, PX_STATUS_UNSUPPORTED,
                               "granular: more than %d ghost messages per step (fewer ranks)",
                               PX_COMM_BATCH_MAX);
      msg[nm].buf = P->buf + ((pass ? ns : 0) + L[q]) * rb;
      msg[nm].bytes = c * rb;
      msg[nm].peer = q;
      msg[nm].tag = 3;
      msg[nm].recv = pass;
      ++nm;
    }
  PX_TRY(px_comm_exchange(e->comm, msg, nm));
  if (nr) {
    PX_TRY(px_buffer_write(e->b[B_GBUF], ns * rb, nr * rb, P->buf + ns * rb));
    PX_TRY(px_gran_cl_pack(e, 1, ns, ns + nr));
  }
  return PX_STATUS_OK;
}

enum px_status px_gran_cl_ranks_maxdisp(struct px_gran_cl *e, uint32_t *md) {
  /* the bits as a double (exact below 2^53): their largest on every rank is
   * the atomic_max one device takes over all discs (NaN and inf included) */
  double v = (double)*md;
  PX_TRY(px_comm_allreduce_double(e->comm, &v, 1, PX_COMM_MAX));
  *md = (uint32_t)v;
  return PX_STATUS_OK;
}

/* The per-disc arrays a step changes, and the bytes of a disc's row in
 * each: the state and accelerations, the contact histories of its list,
 * its wall slots. The lists themselves, the wall candidates and reference
 * positions are rebuilt by every device from the same positions (the same
 * everywhere); radii, masses and ids never change. */
static size_t px_gran_cl_state_arrays(const struct px_gran_cl *e, int *k, size_t *row) {
  static const int st[] = {B_X, B_Y, B_VX, B_VY, B_W, B_AX, B_AY, B_AW};
  static const int hi[] = {B_HXI, B_HTH, B_HDM, B_HDP};
  static const int wi[] = {B_SSEG, B_SSEG0, B_SSTEP0};
  static const int wr[] = {B_ST0, B_STE,  B_SXI,  B_STH,  B_SDM,
                           B_SDP, B_SIMP, B_SSLW, B_SARC, B_STIM};
  size_t na = 0, q;
  for (q = 0; q < 8; ++q) k[na] = st[q], row[na++] = e->ss;
  for (q = 0; q < 4; ++q) k[na] = hi[q], row[na++] = PX_GRAN_CL_NMAX * e->cs;
  if (!e->ncontours) return na;
  for (q = 0; q < 3; ++q) k[na] = wi[q], row[na++] = PX_GRAN_WSLOTS * sizeof(int32_t);
  for (q = 0; q < 10; ++q) k[na] = wr[q], row[na++] = PX_GRAN_WSLOTS * e->cs;
  return na;
}

/* Each disc's rows of the arrays (copies: the device's whole arrays) to
 * (pack) or from the rows at b, R bytes per disc, discs ids[0..m). */
static void px_gran_cl_state_copy(unsigned char *const *copy, const size_t *row, size_t na,
                                  const uint32_t *ids, size_t m, unsigned char *b, size_t R,
                                  int unpack) {
  size_t p, a, off;
  for (p = 0; p < m; ++p)
    for (a = 0, off = 0; a < na; off += row[a], ++a) {
      unsigned char *d = copy[a] + (size_t)ids[p] * row[a], *o = b + p * R + off;
      if (unpack)
        memcpy(d, o, row[a]);
      else
        memcpy(o, d, row[a]);
    }
}

enum px_status px_gran_cl_ranks_state(struct px_gran_cl *e, int root) {
  struct px_gran_cl_plan *P;
  int k[32];
  size_t row[32], counts[PX_COMM_BATCH_MAX], na, a, R = 0; /* K <= PX_COMM_BATCH_MAX */
  unsigned char *copy[32], *send = NULL, *recv = NULL;
  const int K = e->nrank, me = e->rank, get = root < 0 || root == me;
  enum px_status st = PX_STATUS_OK;
  int q;
  if (!e->plan_ok) PX_TRY(px_gran_cl_ranks_plan(e));
  P = e->plan;
  na = px_gran_cl_state_arrays(e, k, row);
  for (a = 0; a < na; ++a) R += row[a], copy[a] = NULL;
  for (a = 0; a < na && st == PX_STATUS_OK; ++a) {
    copy[a] = px_mem_alloc(e->ctx, "granular opencl ranks", e->n * row[a] + 1);
    if (!copy[a]) st = PX_STATUS_NOMEM;
    if (st == PX_STATUS_OK) st = px_buffer_read(e->b[k[a]], 0, e->n * row[a], copy[a]);
  }
  if (st == PX_STATUS_OK) {
    send = px_mem_alloc(e->ctx, "granular opencl ranks", e->nown * R + 1);
    if (get) recv = px_mem_alloc(e->ctx, "granular opencl ranks", e->n * R + 1);
    if (!send || (get && !recv)) st = PX_STATUS_NOMEM;
  }
  if (st == PX_STATUS_OK) {
    px_gran_cl_state_copy(copy, row, na, P->ids + P->ostart[me], e->nown, send, R, 0);
    for (q = 0; q < K; ++q) counts[q] = (P->ostart[q + 1] - P->ostart[q]) * R;
    st = root < 0 ? px_comm_allgatherv_known(e->comm, send, recv, counts)
                  : px_comm_gatherv(e->comm, send, e->nown * R, recv, NULL, root);
  }
  /* the rows arrive rank by rank, as P->ids lists the discs */
  for (q = 0; q < K && st == PX_STATUS_OK && get; ++q)
    if (q != me)
      px_gran_cl_state_copy(copy, row, na, P->ids + P->ostart[q], P->ostart[q + 1] - P->ostart[q],
                            recv + P->ostart[q] * R, R, 1);
  for (a = 0; a < na && st == PX_STATUS_OK && get; ++a)
    st = px_buffer_write(e->b[k[a]], 0, e->n * row[a], copy[a]);
  for (a = 0; a < na; ++a) px_mem_free(e->ctx, copy[a]);
  px_mem_free(e->ctx, send);
  px_mem_free(e->ctx, recv);
  return st;
}

enum px_status px_gran_cl_ranks_drain(struct px_gran_cl *e) {
  const int K = e->nrank;
  const size_t ri = PX_GRAN_EVI * sizeof(int), rr = PX_GRAN_EVR * e->cs;
  size_t counts[PX_COMM_BATCH_MAX], total = 0, take = 0, all = 0, off;
  uint32_t nev = 0;
  const uint32_t zero = 0;
  uint64_t lost = 0;
  unsigned char *send = NULL, *recv = NULL;
  int *evi = NULL;
  unsigned char *evr = NULL;
  enum px_status st = PX_STATUS_OK;
  int q;
  if (!e->ncontours) return PX_STATUS_OK;
  PX_TRY(px_buffer_read(e->b[B_EVN], 0, 4, &nev));
  take = nev < e->ev_cap ? nev : e->ev_cap;
  /* this rank's message: the events it lost, then its events' ints and reals */
  send = px_mem_alloc(e->ctx, "granular opencl events", sizeof lost + take * (ri + rr));
  if (!send) return PX_STATUS_NOMEM;
  lost = nev - take;
  memcpy(send, &lost, sizeof lost);
  if (take) st = px_buffer_read(e->b[B_EVI], 0, take * ri, send + sizeof lost);
  if (take && st == PX_STATUS_OK)
    st = px_buffer_read(e->b[B_EVR], 0, take * rr, send + sizeof lost + take * ri);
  if (nev && st == PX_STATUS_OK) st = px_buffer_write(e->b[B_EVN], 0, 4, &zero);
  if (st == PX_STATUS_OK)
    st = px_comm_allgather_size(e->comm, sizeof lost + take * (ri + rr), counts);
  for (q = 0; q < K && st == PX_STATUS_OK; ++q) total += counts[q];
  if (st == PX_STATUS_OK) {
    recv = px_mem_alloc(e->ctx, "granular opencl events", total);
    if (!recv) st = PX_STATUS_NOMEM;
  }
  if (st == PX_STATUS_OK) st = px_comm_allgatherv_known(e->comm, send, recv, counts);
  if (st == PX_STATUS_OK) {
    all = (total - (size_t)K * sizeof lost) / (ri + rr);
    evi = px_mem_alloc(e->ctx, "granular opencl events", all * ri + 1);
    evr = px_mem_alloc(e->ctx, "granular opencl events", all * rr + 1);
    if (!evi || !evr) st = PX_STATUS_NOMEM;
  }
  /* every rank's events back to back, then in the one-rank order */
  for (q = 0, off = 0, take = 0; q < K && st == PX_STATUS_OK; off += counts[q], ++q) {
    const size_t m = (counts[q] - sizeof lost) / (ri + rr);
    memcpy(&lost, recv + off, sizeof lost);
    e->h->ev_overflow += (size_t)lost;
    memcpy((unsigned char *)evi + take * ri, recv + off + sizeof lost, m * ri);
    memcpy(evr + take * rr, recv + off + sizeof lost + m * ri, m * rr);
    take += m;
  }
  if (st == PX_STATUS_OK && all) st = px_gran_cl_feed(e, evi, evr, all);
  px_mem_free(e->ctx, send);
  px_mem_free(e->ctx, recv);
  px_mem_free(e->ctx, evi);
  px_mem_free(e->ctx, evr);
  return st;
}
