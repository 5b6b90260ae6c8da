/* The granular system over K ranks (`mpirun -np K partix run`): spatial
 * strips of the container with ghost discs, bit-identical to one rank.
 *
 * Decomposition: the cpu loops already split the particles into
 * s->nranges fixed ranges of equal disc count (8 per 2048 discs), and
 * every sum of a step is taken per range in a fixed order (cpu_loops.h).
 * Rank r owns the ranges [T r / K, T (r+1) / K): since the slots are
 * sorted by cell (rows of the neighbour grid), a run of ranges is a strip
 * of the container holding about N/K discs. The ranges are recut at every
 * rebuild (the discs are re-sorted: migration and rebalance as the bed
 * moves). A rank computes only its own ranges, exactly as one rank would,
 * so every force is summed in the 1-rank order; its grain is one range
 * (K > T leaves ranks idle).
 *
 * Storage is replicated (not distributed in this version): every rank
 * holds the global arrays, the neighbour list and the walls; a rank's own
 * slots are authoritative, the others are refreshed when needed:
 *   - per step, after the drift: the state of the ghosts (other ranks'
 *     discs that the pairs of this rank's ranges reach: partners j > i in
 *     later strips) from their owners, point to point;
 *   - per step, after the pair pass: the force records of the pairs of
 *     earlier strips whose partner is this rank's (the partner's sum takes
 *     them in the 1-rank order); a pair's contact history lives with its
 *     first disc's owner only, so it is never duplicated;
 *   - per step, all ranks: every range's largest displacement and speed,
 *     non-finite flag and contour reactions (one allgatherv), and in steps
 *     with wall events the events (a second one), so
 *     the statistics, reactions and the rebuild decision are summed over
 *     the ranges in range order on every rank, as on one rank;
 *   - at a rebuild: every owner's state, near-wall slots and contact
 *     histories to all ranks (px_gran_ranks_sync, allgatherv of O(N)), after which
 *     the rebuild runs identically on every rank; at an output or a
 *     checkpoint the same onto rank 0 only (gatherv). */
#include <stdio.h>
#include <string.h>

#include "partix/memory.h"
#include "solvers/granular/system_impl.h"
#include "solvers/granular/wall_kernel.h"

/* Index lists of one kind of message: those for rank q are
 * idx[start[q]..start[q+1]). */
struct px_gran_lists {
  size_t *start; /* owned, K + 1 */
  int32_t *idx;  /* owned */
};

struct px_gran_plan {
  size_t *ob;              /* owned, K + 1: rank r owns slots [ob[r], ob[r+1]) */
  struct px_gran_lists gs; /* ghost slots this rank sends to each earlier rank */
  struct px_gran_lists gr; /* ghost slots it receives from each later rank */
  struct px_gran_lists rs; /* pairs whose records it sends to each later rank */
  struct px_gran_lists rr; /* pairs whose records it receives from each earlier rank */
  unsigned char *mark;     /* owned, n: scratch */
  void *buf, *rbuf;        /* owned: message bytes */
  size_t *counts;          /* owned, K */
  int logged;              /* the decomposition was logged once at INFO */
};

void px_gran_ranks_own(const struct px_gran_sys *s, int *vt0, int *vt1) {
  const int K = s->nrank > 1 ? s->nrank : 1, r = s->nrank > 1 ? s->rank : 0;
  *vt0 = (int)((long)s->nranges * r / K);
  *vt1 = (int)((long)s->nranges * (r + 1) / K);
}

static void px_gran_ranks_bounds(const struct px_gran_sys *s, size_t *ob) {
  const int K = s->nrank;
  int r;
  for (r = 0; r <= K; ++r) ob[r] = s->rng_i[(long)s->nranges * r / K];
}

void px_gran_ranks_free(struct px_gran_sys *s) {
  struct px_gran_plan *P = s->plan;
  struct px_gran_lists *L[4];
  int k;
  if (!P) return;
  L[0] = &P->gs, L[1] = &P->gr, L[2] = &P->rs, L[3] = &P->rr;
  for (k = 0; k < 4; ++k) {
    px_mem_free(s->ctx, L[k]->start);
    px_mem_free(s->ctx, L[k]->idx);
  }
  px_mem_free(s->ctx, P->ob);
  px_mem_free(s->ctx, P->mark);
  px_mem_free(s->ctx, P->buf);
  px_mem_free(s->ctx, P->rbuf);
  px_mem_free(s->ctx, P->counts);
  px_mem_free(s->ctx, P);
  s->plan = NULL;
}

/* The rank owning slot j (the owners' slots ascend with the rank). */
static int px_gran_owner(const struct px_gran_plan *P, int K, size_t j) {
  int lo = 0, hi = K - 1;
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (P->ob[mid] <= j)
      lo = mid;
    else
      hi = mid - 1;
  }
  return lo;
}

static enum px_status px_gran_list_room(struct px_gran_sys *s, struct px_gran_lists *L, size_t n) {
  return px_gran_ensure(s, (void **)&L->idx, (n ? n : 1) * sizeof(int32_t), "granular ranks");
}

/* Ghost lists: the partners of this rank's pairs in later strips (by
 * owner, ascending slot), and this rank's discs that earlier strips' pairs
 * reach (by rank, ascending slot). */
static enum px_status px_gran_plan_ghosts(struct px_gran_sys *s, struct px_gran_plan *P) {
  const int K = s->nrank, me = s->rank;
  const size_t o0 = P->ob[me], o1 = P->ob[me + 1], n = s->n;
  size_t k, j, at = 0;
  int q;
  memset(P->mark, 0, n ? n : 1);
  for (k = (size_t)s->pstart[o0]; k < (size_t)s->pstart[o1]; ++k)
    if ((size_t)s->pj[k] >= o1) P->mark[s->pj[k]] = 1;
  for (j = o1, at = 0; j < n; ++j) at += P->mark[j];
  PX_TRY(px_gran_list_room(s, &P->gr, at));
  memset(P->gr.start, 0, (size_t)(K + 1) * sizeof(size_t));
  for (j = o1, at = 0; j < n; ++j)
    if (P->mark[j]) {
      P->gr.idx[at++] = (int32_t)j;
      ++P->gr.start[px_gran_owner(P, K, j) + 1];
    }
  for (q = 0; q < K; ++q) P->gr.start[q + 1] += P->gr.start[q];
  /* what earlier ranks need of this rank's discs */
  P->gs.start[0] = 0;
  at = 0;
  for (q = 0; q < K; ++q) {
    if (q < me) {
      memset(P->mark + o0, 0, o1 - o0);
      for (k = (size_t)s->pstart[P->ob[q]]; k < (size_t)s->pstart[P->ob[q + 1]]; ++k)
        if ((size_t)s->pj[k] >= o0 && (size_t)s->pj[k] < o1) P->mark[s->pj[k]] = 1;
      for (j = o0; j < o1; ++j)
        if (P->mark[j]) {
          PX_TRY(px_gran_list_room(s, &P->gs, at + 1));
          P->gs.idx[at++] = (int32_t)j;
        }
    }
    P->gs.start[q + 1] = at;
  }
  return PX_STATUS_OK;
}

/* Record lists: this rank's pairs whose partner a later rank owns (by
 * owner, ascending pair), and earlier ranks' pairs whose partner is this
 * rank's (by rank, ascending pair). */
static enum px_status px_gran_plan_records(struct px_gran_sys *s, struct px_gran_plan *P) {
  const int K = s->nrank, me = s->rank;
  const size_t o0 = P->ob[me], o1 = P->ob[me + 1];
  const size_t k0 = (size_t)s->pstart[o0], k1 = (size_t)s->pstart[o1];
  size_t k, at = 0;
  int q;
  memset(P->rs.start, 0, (size_t)(K + 1) * sizeof(size_t));
  for (k = k0; k < k1; ++k)
    if ((size_t)s->pj[k] >= o1) ++P->rs.start[px_gran_owner(P, K, (size_t)s->pj[k]) + 1];
  for (q = 0; q < K; ++q) P->rs.start[q + 1] += P->rs.start[q];
  PX_TRY(px_gran_list_room(s, &P->rs, P->rs.start[K]));
  {
    /* counting sort by owner, ascending pair within one owner */
    size_t *fill = P->counts;
    for (q = 0; q < K; ++q) fill[q] = P->rs.start[q];
    for (k = k0; k < k1; ++k)
      if ((size_t)s->pj[k] >= o1)
        P->rs.idx[fill[px_gran_owner(P, K, (size_t)s->pj[k])]++] = (int32_t)k;
  }
  P->rr.start[0] = 0;
  for (q = 0; q < K; ++q) {
    if (q < me)
      for (k = (size_t)s->pstart[P->ob[q]]; k < (size_t)s->pstart[P->ob[q + 1]]; ++k)
        if ((size_t)s->pj[k] >= o0 && (size_t)s->pj[k] < o1) {
          PX_TRY(px_gran_list_room(s, &P->rr, at + 1));
          P->rr.idx[at++] = (int32_t)k;
        }
    P->rr.start[q + 1] = at;
  }
  return PX_STATUS_OK;
}

/* Bytes of the ghost state of one disc (x, y, vx, vy, w; mixed precision:
 * and their float copies). */
static size_t px_gran_ghost_row(const struct px_gran_sys *s) {
  return 5 * s->ssize + (s->precision == PX_PRECISION_MIXED ? 5 * s->csize : 0);
}

/* INFO on rank 0: the strips, discs and ghosts per rank, bytes per step. */
static enum px_status px_gran_plan_log(struct px_gran_sys *s, struct px_gran_plan *P) {
  const int K = s->nrank, me = s->rank;
  long mine[6], *all;
  size_t rowg = px_gran_ghost_row(s), rowr = 3 * s->csize;
  enum px_status st;
  int q;
  mine[0] = (long)(P->ob[me + 1] - P->ob[me]);
  mine[1] = (long)P->gr.start[K];
  mine[2] = (long)P->rr.start[K];
  mine[3] = (long)(P->gs.start[K] * rowg + P->rs.start[K] * rowr);
  mine[4] = mine[0] ? (long)(s->cell[P->ob[me]] / (uint32_t)s->gnx) : -1;
  mine[5] = mine[0] ? (long)(s->cell[P->ob[me + 1] - 1] / (uint32_t)s->gnx) : -1;
  all = px_mem_alloc(s->ctx, "granular ranks", (size_t)K * sizeof mine);
  if (!all) return PX_STATUS_NOMEM;
  st = px_comm_allgatherv(s->comm, mine, sizeof mine, all, NULL);
  if (st == PX_STATUS_OK && me == 0)
    for (q = 0; q < K; ++q) {
      const long *v = all + 6 * q;
      if (v[0] == 0) {
        px_log(s->ctx, P->logged ? PX_LOG_LEVEL_DEBUG : PX_LOG_LEVEL_WARN,
               "granular ranks: rank %d of %d idle: %d work ranges of about %zu discs for %d "
               "ranks (a range is the grain of the split: 8 per 2048 discs)",
               q, K, s->nranges, s->n / (size_t)s->nranges, K);
        continue;
      }
      px_log(s->ctx, P->logged ? PX_LOG_LEVEL_DEBUG : PX_LOG_LEVEL_INFO,
             "granular ranks: rank %d of %d: %ld discs (grid rows %ld to %ld, y %.4g to %.4g m), "
             "%ld ghost discs and %ld pair records received, %ld bytes sent per step "
             "(rebuild %ld)",
             q, K, v[0], v[4], v[5], s->gy0 + (double)v[4] * s->gh,
             s->gy0 + (double)(v[5] + 1) * s->gh, v[1], v[2], v[3], s->rebuilds);
    }
  P->logged = 1;
  px_mem_free(s->ctx, all);
  return st;
}

/* The lists of the current neighbour list (after a rebuild or a load). */
enum px_status px_gran_ranks_lists(struct px_gran_sys *s) {
  struct px_gran_plan *P = s->plan;
  const size_t K1 = (size_t)s->nrank + 1;
  if (!P) {
    struct px_gran_lists *L[4];
    int k;
    P = s->plan = px_mem_calloc(s->ctx, "granular ranks", 1, sizeof *P);
    if (!P) return PX_STATUS_NOMEM;
    L[0] = &P->gs, L[1] = &P->gr, L[2] = &P->rs, L[3] = &P->rr;
    P->ob = px_mem_calloc(s->ctx, "granular ranks", K1, sizeof(size_t));
    P->counts = px_mem_calloc(s->ctx, "granular ranks", K1, sizeof(size_t));
    if (!P->ob || !P->counts) return PX_STATUS_NOMEM;
    for (k = 0; k < 4; ++k) {
      L[k]->start = px_mem_calloc(s->ctx, "granular ranks", K1, sizeof(size_t));
      if (!L[k]->start) return PX_STATUS_NOMEM;
    }
  }
  PX_TRY(px_gran_ensure(s, (void **)&P->mark, s->n ? s->n : 1, "granular ranks"));
  px_gran_ranks_bounds(s, P->ob);
  /* every list has storage, empty or not (its pointer is never NULL) */
  PX_TRY(px_gran_list_room(s, &P->gs, 0));
  PX_TRY(px_gran_list_room(s, &P->rr, 0));
  PX_TRY(px_gran_plan_ghosts(s, P));
  PX_TRY(px_gran_plan_records(s, P));
  {
    /* one buffer holds a step's ghost or record messages, sent and received */
    const size_t g = (P->gs.start[s->nrank] + P->gr.start[s->nrank]) * px_gran_ghost_row(s);
    const size_t r = (P->rs.start[s->nrank] + P->rr.start[s->nrank]) * 3 * s->csize;
    PX_TRY(px_gran_ensure(s, &P->buf, g > r ? g : r, "granular ranks"));
  }
  s->plan_ok = 1;
  return PX_STATUS_OK;
}

size_t px_gran_ranks_list(const struct px_gran_sys *s, int kind, int q, const int32_t **idx) {
  const struct px_gran_plan *P = s->plan;
  const struct px_gran_lists *L;
  if (!P || kind < 0 || kind > 3 || q < 0 || q >= s->nrank) return 0;
  L = kind == 0 ? &P->gs : kind == 1 ? &P->gr : kind == 2 ? &P->rs : &P->rr;
  *idx = L->idx + L->start[q];
  return L->start[q + 1] - L->start[q];
}

enum px_status px_gran_ranks_begin(struct px_gran_sys *s) {
  if (s->plan_ok) return PX_STATUS_OK;
  PX_TRY(px_gran_ranks_lists(s));
  return px_gran_plan_log(s, s->plan);
}

/* Messages of one exchange: the rows of send lists packed, receive lists
 * unpacked; each row is es[a] bytes of each array a at the listed index. */
static enum px_status px_gran_exchange(struct px_gran_sys *s, const struct px_gran_lists *snd,
                                       const struct px_gran_lists *rcv, void *const *arr,
                                       const size_t *es, int narr, int tag) {
  struct px_gran_plan *P = s->plan;
  struct px_comm_msg msg[PX_COMM_BATCH_MAX];
  unsigned char *b = P->buf;
  size_t row = 0, off = 0, nm = 0, i;
  int q, a, pass;
  for (a = 0; a < narr; ++a) row += es[a];
  for (pass = 0; pass < 2; ++pass) {
    const struct px_gran_lists *L = pass ? rcv : snd;
    for (q = 0; q < s->nrank; ++q) {
      const size_t c0 = L->start[q], c1 = L->start[q + 1];
      if (c1 == c0) continue;
      if (nm == PX_COMM_BATCH_MAX)
        return px_context_fail(s->ctx, PX_STATUS_UNSUPPORTED,
                               "granular: more than %d ghost messages per step (fewer ranks)",
                               PX_COMM_BATCH_MAX);
      if (!pass)
        for (i = c0; i < c1; ++i) {
          unsigned char *o = b + off + (i - c0) * row;
          for (a = 0; a < narr; ++a) {
            memcpy(o, (unsigned char *)arr[a] + (size_t)L->idx[i] * es[a], es[a]);
            o += es[a];
          }
        }
      msg[nm].buf = b + off;
      msg[nm].bytes = (c1 - c0) * row;
      msg[nm].peer = q;
      msg[nm].tag = tag;
      msg[nm].recv = pass;
      ++nm;
      off += (c1 - c0) * row;
    }
  }
  PX_TRY(px_comm_exchange(s->comm, msg, nm));
  off = snd->start[s->nrank] * row;
  for (i = 0; i < rcv->start[s->nrank]; ++i) {
    const unsigned char *o = b + off + i * row;
    for (a = 0; a < narr; ++a) {
      memcpy((unsigned char *)arr[a] + (size_t)rcv->idx[i] * es[a], o, es[a]);
      o += es[a];
    }
  }
  return PX_STATUS_OK;
}

enum px_status px_gran_ranks_ghosts(struct px_gran_sys *s, void *const *arr, const size_t *es,
                                    int narr) {
  return px_gran_exchange(s, &s->plan->gs, &s->plan->gr, arr, es, narr, 1);
}

enum px_status px_gran_ranks_records(struct px_gran_sys *s) {
  void *const arr[3] = {s->pfx.p, s->pfy.p, s->ptj.p};
  const size_t es[3] = {s->csize, s->csize, s->csize};
  return px_gran_exchange(s, &s->plan->rs, &s->plan->rr, arr, es, 3, 2);
}

/* Doubles of rank q's per-step header: the events it lost, then per range
 * its largest squared displacement and speed, non-finite flag, event count
 * and contour reactions (a size every rank knows). */
static size_t px_gran_head_bytes(const struct px_gran_sys *s, int q) {
  const int v0 = (int)((long)s->nranges * q / s->nrank);
  const int v1 = (int)((long)s->nranges * (q + 1) / s->nrank);
  return (1 + (size_t)(v1 - v0) * (4 + 2 * s->ncontours)) * sizeof(double);
}

/* Bytes of rank q's events of this step (from the event counts of its
 * ranges, known to all after the headers). */
static size_t px_gran_event_bytes(const struct px_gran_sys *s, int q) {
  const int v0 = (int)((long)s->nranges * q / s->nrank);
  const int v1 = (int)((long)s->nranges * (q + 1) / s->nrank);
  size_t nb = 0;
  int t;
  for (t = v0; t < v1; ++t) nb += s->ev_n[t] * (PX_GRAN_EVI * sizeof(int) + PX_GRAN_EVR * s->csize);
  return nb;
}

/* Rank q's header to (pack) or from b. Returns the events lost. */
static double px_gran_head_copy(struct px_gran_sys *s, int q, unsigned char *b, double *disp2,
                                double *vmax2, double *nonfinite, int unpack) {
  const size_t nc2 = 2 * s->ncontours;
  const int v0 = (int)((long)s->nranges * q / s->nrank);
  const int v1 = (int)((long)s->nranges * (q + 1) / s->nrank);
  double lost = (double)(s->ev_overflow - s->ev_lost_synced);
  size_t off = sizeof(double);
  int t;
  if (unpack)
    memcpy(&lost, b, sizeof lost);
  else
    memcpy(b, &lost, sizeof lost);
  for (t = v0; t < v1; ++t) {
    double h[4] = {disp2[t], vmax2[t], nonfinite[t], (double)s->ev_n[t]};
    double *cf = s->cforce_t + (size_t)t * nc2;
    if (unpack) {
      memcpy(h, b + off, sizeof h);
      disp2[t] = h[0], vmax2[t] = h[1], nonfinite[t] = h[2];
      s->ev_n[t] = (size_t)h[3];
      if (nc2) memcpy(cf, b + off + sizeof h, nc2 * sizeof(double));
    } else {
      memcpy(b + off, h, sizeof h);
      if (nc2) memcpy(b + off + sizeof h, cf, nc2 * sizeof(double));
    }
    off += sizeof h + nc2 * sizeof(double);
  }
  return lost;
}

/* Rank q's events to (pack) or from b, range by range. */
static void px_gran_event_copy(struct px_gran_sys *s, int q, unsigned char *b, int unpack) {
  const size_t er = PX_GRAN_EVR * s->csize, ei = PX_GRAN_EVI * sizeof(int);
  const int v0 = (int)((long)s->nranges * q / s->nrank);
  const int v1 = (int)((long)s->nranges * (q + 1) / s->nrank);
  size_t off = 0;
  int t;
  for (t = v0; t < v1; ++t) {
    unsigned char *pi = (unsigned char *)(s->ev_i + (size_t)t * s->ev_cap * PX_GRAN_EVI);
    unsigned char *pr = (unsigned char *)s->ev_r.p + (size_t)t * s->ev_cap * er;
    const size_t ni = s->ev_n[t] * ei, nr = s->ev_n[t] * er;
    if (unpack) {
      memcpy(pi, b + off, ni);
      memcpy(pr, b + off + ni, nr);
    } else {
      memcpy(b + off, pi, ni);
      memcpy(b + off + ni, pr, nr);
    }
    off += ni + nr;
  }
}

enum px_status px_gran_ranks_reduce(struct px_gran_sys *s, double *disp2, double *vmax2,
                                    double *nonfinite) {
  struct px_gran_plan *P = s->plan;
  const int K = s->nrank, me = s->rank;
  size_t total = 0, off;
  double lost = 0;
  int q;
  /* one collective: the headers, whose sizes every rank knows */
  for (q = 0; q < K; ++q) total += P->counts[q] = px_gran_head_bytes(s, q);
  PX_TRY(px_gran_ensure(s, &P->rbuf, total, "granular ranks"));
  PX_TRY(px_gran_ensure(s, &P->buf, P->counts[me] + 1, "granular ranks"));
  px_gran_head_copy(s, me, P->buf, disp2, vmax2, nonfinite, 0);
  PX_TRY(px_comm_allgatherv_known(s->comm, P->buf, P->rbuf, P->counts));
  for (q = 0, off = 0; q < K; ++q) {
    lost +=
        px_gran_head_copy(s, q, (unsigned char *)P->rbuf + off, disp2, vmax2, nonfinite, q != me);
    off += P->counts[q];
  }
  /* each rank counted only its own ranges' lost events */
  s->ev_overflow = s->ev_lost_synced + (size_t)lost;
  s->ev_lost_synced = s->ev_overflow;
  /* a second one for the wall events, in the steps that have any */
  for (q = 0, total = 0; q < K; ++q) total += P->counts[q] = px_gran_event_bytes(s, q);
  if (total == 0) return PX_STATUS_OK;
  PX_TRY(px_gran_ensure(s, &P->rbuf, total, "granular ranks"));
  PX_TRY(px_gran_ensure(s, &P->buf, P->counts[me] + 1, "granular ranks"));
  px_gran_event_copy(s, me, P->buf, 0);
  PX_TRY(px_comm_allgatherv_known(s->comm, P->buf, P->rbuf, P->counts));
  for (q = 0, off = 0; q < K; ++q) {
    if (q != me) px_gran_event_copy(s, q, (unsigned char *)P->rbuf + off, 1);
    off += P->counts[q];
  }
  return PX_STATUS_OK;
}

/* What the owners' state holds of each per-particle array: 0 nothing (kept
 * arrays that only a rebuild changes, the same on every rank: radii,
 * masses, ids), 1 every owned disc, 2 the owned discs of the near-wall list
 * (wall slots: only the wall pass of a near disc's owner writes them, so
 * the others' copies are the same on every rank since the last rebuild). */
static int px_gran_sync_kind(const struct px_gran_sys *s, const struct px_gran_arr *a) {
  if (!a->keep || a->p == (void **)&s->r.p || a->p == (void **)&s->m.p ||
      a->p == (void **)&s->im.p || a->p == (void **)&s->iI.p || a->p == (void **)&s->id)
    return 0;
  return a->per == PX_GRAN_WSLOTS ? 2 : 1;
}

/* The near-wall list's entries [*q0, *q1) in slots [lo, hi) (ascending). */
static void px_gran_near_span(const struct px_gran_sys *s, size_t lo, size_t hi, size_t *q0,
                              size_t *q1) {
  size_t a = 0, b = s->nnear;
  while (a < b) {
    const size_t m = (a + b) / 2;
    if ((size_t)s->near[m] < lo)
      a = m + 1;
    else
      b = m;
  }
  *q0 = a;
  b = s->nnear;
  while (a < b) {
    const size_t m = (a + b) / 2;
    if ((size_t)s->near[m] < hi)
      a = m + 1;
    else
      b = m;
  }
  *q1 = a;
}

/* Bytes of rank q's owned state: its slots of the arrays a step changes,
 * the wall slots of its near-wall discs, the contact histories of its
 * pairs. */
static size_t px_gran_sync_bytes(const struct px_gran_sys *s, const struct px_gran_arr *a,
                                 size_t na, const size_t *ob, int q) {
  const size_t np = (size_t)s->pstart[ob[q + 1]] - (size_t)s->pstart[ob[q]];
  size_t k, q0, q1, nb = 4 * np * s->csize;
  px_gran_near_span(s, ob[q], ob[q + 1], &q0, &q1);
  for (k = 0; k < na; ++k) {
    const int kind = px_gran_sync_kind(s, &a[k]);
    if (kind) nb += (kind == 1 ? ob[q + 1] - ob[q] : q1 - q0) * a[k].esize * a[k].per;
  }
  return nb;
}

/* Rank q's owned state to (pack) or from (unpack) b. */
static void px_gran_sync_copy(struct px_gran_sys *s, const struct px_gran_arr *a, size_t na,
                              const size_t *ob, int q, unsigned char *b, int unpack) {
  void *const hist[4] = {s->pxi.p, s->pth.p, s->pdm.p, s->pdp.p};
  const size_t k0 = (size_t)s->pstart[ob[q]], np = (size_t)s->pstart[ob[q + 1]] - k0;
  size_t k, off = 0, q0, q1, e;
  px_gran_near_span(s, ob[q], ob[q + 1], &q0, &q1);
  for (k = 0; k < na; ++k) {
    const size_t row = a[k].esize * a[k].per;
    const int kind = px_gran_sync_kind(s, &a[k]);
    unsigned char *p = (unsigned char *)*a[k].p;
    if (kind == 1) {
      const size_t nb = (ob[q + 1] - ob[q]) * row;
      if (unpack)
        memcpy(p + ob[q] * row, b + off, nb);
      else
        memcpy(b + off, p + ob[q] * row, nb);
      off += nb;
    } else if (kind == 2) {
      for (e = q0; e < q1; ++e, off += row) {
        if (unpack)
          memcpy(p + (size_t)s->near[e] * row, b + off, row);
        else
          memcpy(b + off, p + (size_t)s->near[e] * row, row);
      }
    }
  }
  for (k = 0; k < 4 && np; ++k) {
    unsigned char *p = (unsigned char *)hist[k] + k0 * s->csize;
    if (unpack)
      memcpy(p, b + off, np * s->csize);
    else
      memcpy(b + off, p, np * s->csize);
    off += np * s->csize;
  }
}

enum px_status px_gran_ranks_sync(struct px_gran_sys *s, int root) {
  struct px_gran_arr a[PX_GRAN_MAX_ARRAYS];
  const int K = s->nrank;
  size_t na, total = 0, off = 0, *ob;
  void *send = NULL, *recv = NULL;
  enum px_status st = PX_STATUS_OK;
  int q;
  if (K <= 1) return PX_STATUS_OK;
  na = px_gran_arrays(s, a);
  ob = px_mem_alloc(s->ctx, "granular ranks", (size_t)(K + 1) * sizeof *ob);
  if (!ob) return PX_STATUS_NOMEM;
  px_gran_ranks_bounds(s, ob);
  for (q = 0; q < K; ++q) total += px_gran_sync_bytes(s, a, na, ob, q);
  send = px_mem_alloc(s->ctx, "granular ranks", px_gran_sync_bytes(s, a, na, ob, s->rank) + 1);
  if (root < 0 || root == s->rank) recv = px_mem_alloc(s->ctx, "granular ranks", total + 1);
  if (!send || (!recv && (root < 0 || root == s->rank))) st = PX_STATUS_NOMEM;
  if (st == PX_STATUS_OK) {
    const size_t nb = px_gran_sync_bytes(s, a, na, ob, s->rank);
    px_gran_sync_copy(s, a, na, ob, s->rank, send, 0);
    st = root < 0 ? px_comm_allgatherv(s->comm, send, nb, recv, NULL)
                  : px_comm_gatherv(s->comm, send, nb, recv, NULL, root);
  }
  for (q = 0; q < K && st == PX_STATUS_OK && recv; ++q) {
    if (q != s->rank) px_gran_sync_copy(s, a, na, ob, q, (unsigned char *)recv + off, 1);
    off += px_gran_sync_bytes(s, a, na, ob, q);
  }
  px_mem_free(s->ctx, send);
  px_mem_free(s->ctx, recv);
  px_mem_free(s->ctx, ob);
  return st;
}
