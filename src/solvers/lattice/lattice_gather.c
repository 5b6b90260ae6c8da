/* The lattice over several ranks: the whole state and output fields onto
 * rank 0 for the writers (the solver's gather hook), and where an entry of
 * the whole layout lies in a rank's window (a checkpoint's state, read in
 * pieces: lattice_checkpoint.c). Each rank's engine holds only
 * its window (lattice_ranks.c); rank 0 receives the other blocks in
 * pieces of at most PX_LATTICE_GATHER_CHUNK entries, so that what it holds
 * beyond its window is the whole state and fields in the 1-rank layout
 * (gy, gl, fu, fv, fs, fvm, flinks: what a 1-rank run keeps for its
 * outputs and checkpoints) and one piece. */
#include <math.h>
#include <string.h>

#include "partix/memory.h"
#include "partix/sim.h"
#include "solvers/lattice/lattice_c.h"
#include "solvers/lattice/lattice_ranks_impl.h"

/* An entry of a block on its way to rank 0: the state in double, the
 * fields (u 3, v 3, stress 6, von Mises) and the link flags. */
struct px_lattice_rec {
  struct lt_el y;
  double f[13];
  uint8_t links;
};
_Static_assert(sizeof(struct px_lattice_rec) <= 216, "lattice.c's estimate: 216 B per entry");

/* Entries per message (216 B each: 13.5 MiB; lattice.c's memory estimate
 * counts it). */
#define PX_LATTICE_GATHER_CHUNK ((size_t)1 << 16)
/* The pieces' message tag (the halo's are below 40). */
#define PX_LATTICE_GATHER_TAG 48

size_t px_lattice_local_index(const struct px_lattice *L, size_t c) {
  size_t wj, wk;
  if (!L->ranks) return px_lattice_index(&L->m, c);
  return px_lattice_window_entry(L, px_lattice_index(&L->m, c), &wj, &wk);
}

size_t px_lattice_window_entry(const struct px_lattice *L, size_t gi, size_t *wj, size_t *wk) {
  const struct px_lattice_ranks *R = L->ranks;
  const struct px_lattice_model *m = &L->m;
  const size_t n1 = (size_t)m->grid.n[1];
  size_t r;
  long j, k;
  if (!R || gi < m->pad || gi >= m->nalloc - m->pad) return (size_t)-1;
  r = (gi - m->pad) / m->n0p;
  j = (long)(r % n1);
  k = (long)(r / n1);
  if (j < R->box[0] || j >= R->box[1] || k < R->box[2] || k >= R->box[3]) return (size_t)-1;
  *wj = (size_t)(j - R->box[0]);
  *wk = (size_t)(k - R->box[2]);
  return L->wm.pad + (gi - m->pad) % m->n0p + L->wm.n0p * (size_t)px_lattice_ranks_loc(R, j, k);
}

/* A walk over rank q's entries in order (its segments' rows, n0p entries
 * each): the padded index of each in the whole layout (gi) and, for this
 * rank's own, in its window (li). */
struct px_lattice_walk {
  int q;
  long s, ns, a, b, la, lb;
  size_t at; /* entry within the segment */
};

static void px_lattice_walk_seg(const struct px_lattice_ranks *R, struct px_lattice_walk *W) {
  for (; W->s < W->ns; ++W->s) {
    px_lattice_ranks_seg(R, W->q, W->s, &W->a, &W->b);
    if (W->q == R->rank) px_lattice_ranks_lseg(R, W->a, W->b, &W->la, &W->lb);
    if (W->b > W->a) return;
  }
}

static void px_lattice_walk_start(const struct px_lattice_ranks *R, int q,
                                  struct px_lattice_walk *W) {
  memset(W, 0, sizeof *W);
  W->q = q;
  W->ns = px_lattice_ranks_seg(R, q, 0, &W->a, &W->b);
  px_lattice_walk_seg(R, W);
}

static void px_lattice_walk_next(const struct px_lattice_ranks *R, struct px_lattice_walk *W,
                                 size_t *gi, size_t *li) {
  const size_t n0p = R->L->m.n0p;
  *gi = R->L->m.pad + (size_t)W->a * n0p + W->at;
  *li = R->L->wm.pad + (size_t)W->la * n0p + W->at;
  if (++W->at == (size_t)(W->b - W->a) * n0p) {
    W->at = 0;
    ++W->s;
    px_lattice_walk_seg(R, W);
  }
}

/* Entries of rank q's block. */
static size_t px_lattice_ranks_entries(const struct px_lattice_ranks *R, int q) {
  size_t n = 0;
  long s, ns, a, b;
  for (s = 0, ns = 1; s < ns; ++s) {
    ns = px_lattice_ranks_seg(R, q, s, &a, &b);
    n += (size_t)(b - a) * R->L->m.n0p;
  }
  return n;
}

/* This rank's window: the state, flags and fields (local arrays). */
struct px_lattice_local {
  struct lt_el *y;
  uint8_t *links;
  struct px_lattice_fields f;
};

static void px_lattice_rec_pack(const struct px_lattice_local *w, size_t li,
                                struct px_lattice_rec *r) {
  memcpy(&r->y, &w->y[li], sizeof r->y);
  memcpy(r->f, w->f.u + 3 * li, 3 * sizeof(double));
  memcpy(r->f + 3, w->f.v + 3 * li, 3 * sizeof(double));
  memcpy(r->f + 6, w->f.sigma + 6 * li, 6 * sizeof(double));
  r->f[12] = w->f.vm[li];
  r->links = w->links[li];
}

static void px_lattice_rec_unpack(struct px_lattice *L, size_t gi, const struct px_lattice_rec *r) {
  memcpy(&L->gy[gi], &r->y, sizeof r->y);
  memcpy(L->fu + 3 * gi, r->f, 3 * sizeof(double));
  memcpy(L->fv + 3 * gi, r->f + 3, 3 * sizeof(double));
  memcpy(L->fs + 6 * gi, r->f + 6, 6 * sizeof(double));
  L->fvm[gi] = r->f[12];
  L->gl[gi] = L->flinks[gi] = r->links;
}

static void px_lattice_local_free(struct px_lattice *L, struct px_lattice_local *w) {
  px_mem_free(L->ctx, w->y);
  px_mem_free(L->ctx, w->links);
  px_mem_free(L->ctx, w->f.u);
  px_mem_free(L->ctx, w->f.v);
  px_mem_free(L->ctx, w->f.sigma);
  px_mem_free(L->ctx, w->f.vm);
}

static enum px_status px_lattice_local_alloc(struct px_lattice *L, struct px_lattice_local *w) {
  const size_t n = L->wm.nalloc;
  memset(w, 0, sizeof *w);
  w->y = (struct lt_el *)px_mem_alloc(L->ctx, "lattice.gather", n * sizeof *w->y);
  w->links = (uint8_t *)px_mem_alloc(L->ctx, "lattice.gather", n);
  w->f.u = (double *)px_mem_alloc(L->ctx, "lattice.gather", 3 * n * sizeof(double));
  w->f.v = (double *)px_mem_alloc(L->ctx, "lattice.gather", 3 * n * sizeof(double));
  w->f.sigma = (double *)px_mem_alloc(L->ctx, "lattice.gather", 6 * n * sizeof(double));
  w->f.vm = (double *)px_mem_alloc(L->ctx, "lattice.gather", n * sizeof(double));
  if (!w->y || !w->links || !w->f.u || !w->f.v || !w->f.sigma || !w->f.vm)
    return px_context_fail(L->ctx, PX_STATUS_NOMEM, "lattice: out of memory for the gather");
  return PX_STATUS_OK;
}

/* Rank q's block, piece by piece: sent (q = this rank > 0) or received
 * into the whole arrays (rank 0; its own block copied). */
static enum px_status px_lattice_gather_block(struct px_lattice *L,
                                              const struct px_lattice_local *w,
                                              struct px_lattice_rec *piece, int q) {
  const struct px_lattice_ranks *R = L->ranks;
  const size_t total = px_lattice_ranks_entries(R, q);
  struct px_lattice_walk W;
  size_t done = 0, i, gi, li;
  px_lattice_walk_start(R, q, &W);
  if (q == 0 && R->rank == 0) {
    struct px_lattice_rec r;
    for (i = 0; i < total; ++i) {
      px_lattice_walk_next(R, &W, &gi, &li);
      px_lattice_rec_pack(w, li, &r);
      px_lattice_rec_unpack(L, gi, &r);
    }
    return PX_STATUS_OK;
  }
  while (done < total) {
    const size_t n =
        total - done < PX_LATTICE_GATHER_CHUNK ? total - done : PX_LATTICE_GATHER_CHUNK;
    struct px_comm_msg msg = {piece, n * sizeof *piece, R->rank == 0 ? q : 0, PX_LATTICE_GATHER_TAG,
                              R->rank == 0};
    if (R->rank != 0)
      for (i = 0; i < n; ++i) {
        px_lattice_walk_next(R, &W, &gi, &li);
        px_lattice_rec_pack(w, li, &piece[i]);
      }
    PX_TRY(px_comm_exchange(R->comm, &msg, 1));
    if (R->rank == 0)
      for (i = 0; i < n; ++i) {
        px_lattice_walk_next(R, &W, &gi, &li);
        px_lattice_rec_unpack(L, gi, &piece[i]);
      }
    done += n;
  }
  return PX_STATUS_OK;
}

enum px_status px_lattice_gather(void *state) {
  struct px_lattice *L = (struct px_lattice *)state;
  struct px_lattice_ranks *R = L->ranks;
  struct px_lattice_local w;
  struct px_lattice_rec *piece = NULL;
  const long step = px_sim_step_index(L->sim);
  const double t = px_sim_time(L->sim);
  size_t most = 1; /* entries of a piece */
  enum px_status st;
  int q;
  if (!R) return PX_STATUS_OK;
  st = px_lattice_local_alloc(L, &w);
  for (q = 0; q < R->size; ++q) {
    const size_t n = px_lattice_ranks_entries(R, q);
    if (n > most) most = n;
  }
  if (most > PX_LATTICE_GATHER_CHUNK) most = PX_LATTICE_GATHER_CHUNK;
  if (st == PX_STATUS_OK)
    piece = (struct px_lattice_rec *)px_mem_alloc(L->ctx, "lattice.gather", most * sizeof *piece);
  if (st == PX_STATUS_OK && !piece) st = PX_STATUS_NOMEM;
  if (st == PX_STATUS_OK && R->rank == 0) {
    /* the whole arrays: zero where no block writes (padding, as one rank
     * leaves it) */
    if (!L->gy)
      L->gy = (struct lt_el *)px_mem_calloc(L->ctx, "lattice.gather", L->m.nalloc, sizeof *L->gy);
    if (!L->gl) L->gl = (uint8_t *)px_mem_calloc(L->ctx, "lattice.gather", L->m.nalloc, 1);
    st = L->gy && L->gl ? px_lattice_fields_room(L) : PX_STATUS_NOMEM;
  }
  /* the fields' halo exchange is collective: all ranks go on, or none */
  st = px_comm_agree(R->comm, L->ctx, st, NULL);
  if (st == PX_STATUS_OK) st = L->vt->fields(L->e, t, px_sim_dt(L->sim), &w.f);
  if (st == PX_STATUS_OK) st = L->vt->get_state(L->e, w.y, w.links);
  st = px_comm_agree(R->comm, L->ctx, st, NULL);
  for (q = 0; st == PX_STATUS_OK && q < R->size; ++q)
    if (R->rank == 0 || q == R->rank) st = px_lattice_gather_block(L, &w, piece, q);
  if (st == PX_STATUS_OK && R->rank == 0) {
    /* the void entries before and after the grid, as one rank has them: at
     * rest (the window's first entry is one), no links, zero fields */
    const size_t m_pad = L->m.pad, tail = L->m.nalloc - m_pad;
    size_t i;
    for (i = 0; i < m_pad; ++i) {
      const size_t at[2] = {i, tail + i};
      int k;
      for (k = 0; k < 2; ++k) {
        L->gy[at[k]] = w.y[0];
        L->gl[at[k]] = L->flinks[at[k]] = 0;
        memset(L->fu + 3 * at[k], 0, 3 * sizeof(double));
        memset(L->fv + 3 * at[k], 0, 3 * sizeof(double));
        memset(L->fs + 6 * at[k], 0, 6 * sizeof(double));
        L->fvm[at[k]] = 0.0;
      }
    }
    L->fields_step = step;
    L->fields_time = t;
  }
  px_lattice_local_free(L, &w);
  px_mem_free(L->ctx, piece);
  return st;
}

/* The first own row segment holding global row r, or -1 (the rank's
 * segments: one for row blocks, one per z-plane of a 2-D block). */
static long px_lattice_own_seg(const struct px_lattice_ranks *R, long r, long *a, long *b) {
  long s, ns = 1;
  for (s = 0; s < ns; ++s) {
    ns = px_lattice_ranks_seg(R, R->rank, s, a, b);
    if (ns == 0) break;
    if (r >= *a && r < *b) return s;
  }
  return -1;
}

/* The window's entry of entry gi of the whole layout when this rank owns
 * it (its block, not its halo), else (size_t)-1. */
static size_t px_lattice_own_entry(const struct px_lattice *L, size_t gi) {
  const struct px_lattice_model *m = &L->m;
  size_t wj, wk;
  long a, b;
  if (gi < m->pad || gi >= m->nalloc - m->pad) return (size_t)-1;
  if (px_lattice_own_seg(L->ranks, (long)((gi - m->pad) / m->n0p), &a, &b) < 0) return (size_t)-1;
  return px_lattice_window_entry(L, gi, &wj, &wk);
}

enum px_status px_lattice_gather_series(void *state) {
  struct px_lattice *L = (struct px_lattice *)state;
  struct px_lattice_ranks *R = L->ranks;
  const struct px_lattice_model *m = &L->m;
  const size_t n0 = (size_t)m->grid.n[0];
  struct px_lattice_fields f;
  size_t ncell = 0, i, k, at = 0;
  double *v = NULL, best[2] = {-1.0, -1.0}, cell[2];
  enum px_status st = PX_STATUS_OK;
  if (!R) return PX_STATUS_OK;
  for (i = 0; i < L->nprobe; ++i) ncell += L->probes[i].count;
  memset(&f, 0, sizeof f);
  /* the row reads u and von Mises only (the engines skip what is NULL) */
  f.u = (double *)px_mem_alloc(L->ctx, "lattice.gather", 3 * L->wm.nalloc * sizeof(double));
  f.vm = (double *)px_mem_alloc(L->ctx, "lattice.gather", L->wm.nalloc * sizeof(double));
  v = (double *)px_mem_calloc(L->ctx, "lattice.gather", 4 * ncell + 1, sizeof(double));
  if (!L->sacc)
    L->sacc =
        (double *)px_mem_alloc(L->ctx, "lattice.gather", (4 * L->nprobe + 4) * sizeof(double));
  if (!f.u || !f.vm || !v || !L->sacc)
    st = px_context_fail(L->ctx, PX_STATUS_NOMEM, "lattice: out of memory for the probes' row");
  /* the fields' halo exchange is collective: all ranks go on, or none */
  st = px_comm_agree(R->comm, L->ctx, st, NULL);
  if (st == PX_STATUS_OK) st = L->vt->fields(L->e, px_sim_time(L->sim), px_sim_dt(L->sim), &f);
  st = px_comm_agree(R->comm, L->ctx, st, NULL);
  if (st == PX_STATUS_OK) {
    /* each probe cell's values from its owner, zero from the others: the
     * sum over the ranks is the owner's value exactly (x + 0 = x; a -0
     * turns +0, which changes no sum that starts at +0), added on every
     * rank in the probe's cell order below as one rank adds them */
    for (i = 0; i < L->nprobe; ++i)
      for (k = 0; k < L->probes[i].count; ++k, ++at) {
        size_t li = px_lattice_own_entry(L, L->probes[i].cells[k]);
        if (li == (size_t)-1) continue;
        memcpy(v + 4 * at, f.u + 3 * li, 3 * sizeof(double));
        v[4 * at + 3] = f.vm[li];
      }
    /* the largest von Mises stress and |u| of the own cells, the first in
     * cell order on a tie (px_lattice_argmax's rule): the walk over this
     * rank's block visits its entries in ascending order, so its cells */
    struct px_lattice_walk W;
    const size_t total = px_lattice_ranks_entries(R, R->rank);
    size_t gi, li;
    cell[0] = cell[1] = -1.0;
    px_lattice_walk_start(R, R->rank, &W);
    for (k = 0; k < total; ++k) {
      px_lattice_walk_next(R, &W, &gi, &li);
      const size_t x = (gi - m->pad) % m->n0p, c = x + n0 * ((gi - m->pad) / m->n0p);
      const double *u = f.u + 3 * li;
      double val[2];
      int w;
      if (x >= n0 || !m->grid.occ[c]) continue; /* row padding, void cells */
      val[0] = f.vm[li];
      val[1] = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      for (w = 0; w < 2; ++w)
        if (val[w] > best[w]) {
          best[w] = val[w];
          cell[w] = (double)c;
        }
    }
  }
  if (st == PX_STATUS_OK && ncell > 0)
    st = px_comm_allreduce_double(R->comm, v, 4 * ncell, PX_COMM_SUM);
  if (st == PX_STATUS_OK) {
    /* the largest values, then the least cell holding each (exact) */
    double most[2] = {best[0], best[1]};
    st = px_comm_allreduce_double(R->comm, most, 2, PX_COMM_MAX);
    if (st == PX_STATUS_OK) {
      for (k = 0; k < 2; ++k) cell[k] = best[k] == most[k] && most[k] >= 0.0 ? cell[k] : HUGE_VAL;
      st = px_comm_allreduce_double(R->comm, cell, 2, PX_COMM_MIN);
    }
    for (k = 0; st == PX_STATUS_OK && k < 2; ++k) {
      /* none (no occupied cell, or every value NaN): 0 at cell 0 */
      L->sacc[4 * L->nprobe + 2 * k] = most[k] < 0.0 ? 0.0 : most[k];
      L->sacc[4 * L->nprobe + 2 * k + 1] = cell[k] == HUGE_VAL ? 0.0 : cell[k];
    }
  }
  if (st == PX_STATUS_OK) {
    for (at = 0, i = 0; i < L->nprobe; ++i) {
      double acc[4] = {0, 0, 0, 0};
      for (k = 0; k < L->probes[i].count; ++k, ++at) {
        int c;
        for (c = 0; c < 4; ++c) acc[c] += v[4 * at + (size_t)c];
      }
      memcpy(L->sacc + 4 * i, acc, sizeof acc);
    }
    L->series_step = px_sim_step_index(L->sim);
  }
  px_mem_free(L->ctx, f.u);
  px_mem_free(L->ctx, f.vm);
  px_mem_free(L->ctx, v);
  return st;
}
