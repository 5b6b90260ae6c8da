/* The lattice over several ranks (`mpirun -np K partix run`, K > 1).
 *
 * Decomposition: blocks of whole grid rows (a row: the n0p entries of one
 * (y, z); row r = y + n[1] z), in the order of the padded layout, so that a
 * rank's block is one contiguous range of every state component and the
 * engines' row loops (gather) run over a range unchanged. The gather scheme
 * cuts between any two rows, so a body thin in z (a plate: few planes of
 * many rows) still splits evenly; link-once sweeps whole z-planes, so its
 * blocks are whole planes. A block holds at least a plane's worth of rows
 * (n[1]), so that its halo, the n[1] rows on each side (the neighbours of
 * its elements along z reach n[1] rows away), belongs to its two
 * neighbouring ranks. The boundaries balance the elements per rank
 * (px_lattice_ranks_split). Storage is replicated: every rank holds the
 * global arrays (memory is not distributed in this version), updates only
 * its block and keeps its halo current (struct px_lattice_block,
 * lattice_engine.h): before every force pass each rank sends its first and
 * last n[1] rows of the pass's stage state to the neighbours, one message
 * per state component (13 per side, straight from and into the state
 * buffer), non-blocking, while the rows away from the cut are computed.
 *
 * Global quantities as on one rank, to the bit: the Rayleigh sums are per
 * grid row (summed in row order on every rank after an allgather of the
 * rows), the broken-link count an exact integer sum. Fracture needs no
 * message: the two ranks that hold a link across the cut evaluate it from
 * the same states and decide alike. Outputs and checkpoints: gather brings
 * every block onto rank 0 (its state then reads as a 1-rank run's); load
 * gives every rank the whole state. */
#include <string.h>

#include "core/comm.h"
#include "core/text.h"
#include "partix/memory.h"
#include "solvers/lattice/lattice.h"
#include "solvers/lattice/lattice_c.h"

struct px_lattice_ranks {
  struct px_lattice *L; /* borrowed */
  struct px_comm *comm; /* borrowed */
  int rank, size;
  long *z;        /* size + 1 row boundaries: rank r holds the rows [z[r], z[r + 1]) */
  size_t plane;   /* entries of a plane of the padded layout: n0p n[1] */
  int planes;     /* blocks of whole planes (link-once) */
  size_t *counts; /* size entries (allgather counts) */
  double *rows;   /* 3 n[1] n[2] doubles: the rows' allgather */
  double *send;   /* 3 n[1] n[2] doubles: this rank's rows */
};

int px_lattice_ranks_split(const size_t *count, long nz, long minw, int size, long *z) {
  size_t total = 0;
  long k;
  int r;
  if (size < 1 || minw < 1 || nz / minw < size) return -1;
  for (k = 0; k < nz; ++k) total += count[k];
  z[0] = 0;
  z[size] = nz;
  {
    size_t cum = 0;
    long at = 0;
    for (r = 1; r < size; ++r) {
      /* the first unit at which the elements below reach r / size of all
       * (exact integer comparison: cum size >= total r) */
      while (at < nz && cum * (size_t)size < total * (size_t)r) cum += count[at++];
      z[r] = at;
      if (z[r] < z[r - 1] + minw) z[r] = z[r - 1] + minw;
      if (z[r] > nz - (size - r) * minw) z[r] = nz - (size - r) * minw;
      /* cum follows z[r] when clamped */
      for (cum = 0, at = 0; at < z[r]; ++at) cum += count[at];
    }
  }
  return 0;
}

/* --- struct px_lattice_block callbacks --- */

static enum px_status px_lattice_halo_start(void *arg, void *buf, size_t real, size_t ns) {
  struct px_lattice_ranks *R = (struct px_lattice_ranks *)arg;
  const struct px_lattice_model *m = &R->L->m;
  struct px_comm_msg msg[4 * PX_LATTICE_NCOMP];
  /* the halo: the n[1] rows (a plane's entries) on each side */
  const size_t row = m->n0p * real, bytes = R->plane * real, n1 = (size_t)m->grid.n[1];
  const size_t r0 = (size_t)R->z[R->rank], r1 = (size_t)R->z[R->rank + 1];
  size_t n = 0;
  int k;
  for (k = 0; k < PX_LATTICE_NCOMP; ++k) {
    char *c = (char *)buf + ((size_t)k * ns + m->pad) * real;
    /* tag k: a rank's first n[1] rows going down; 16 + k: its last going up */
    if (R->rank > 0) {
      msg[n++] = (struct px_comm_msg){c + r0 * row, bytes, R->rank - 1, k, 0};
      msg[n++] = (struct px_comm_msg){c + (r0 - n1) * row, bytes, R->rank - 1, 16 + k, 1};
    }
    if (R->rank + 1 < R->size) {
      msg[n++] = (struct px_comm_msg){c + (r1 - n1) * row, bytes, R->rank + 1, 16 + k, 0};
      msg[n++] = (struct px_comm_msg){c + r1 * row, bytes, R->rank + 1, k, 1};
    }
  }
  return px_comm_start(R->comm, msg, n);
}

static enum px_status px_lattice_halo_wait(void *arg) {
  return px_comm_wait(((struct px_lattice_ranks *)arg)->comm);
}

static enum px_status px_lattice_rows(void *arg, double *rows, size_t k) {
  struct px_lattice_ranks *R = (struct px_lattice_ranks *)arg;
  const size_t n1 = (size_t)R->L->m.grid.n[1], nrow = n1 * (size_t)R->L->m.grid.n[2];
  const size_t r0 = (size_t)R->z[R->rank], own = (size_t)R->z[R->rank + 1] - r0;
  size_t a, q, at = 0;
  if (k > 3) return px_context_fail(R->L->ctx, PX_STATUS_INVALID, "lattice rows: %zu arrays", k);
  /* own rows of each array back to back: rank q sends k (z[q + 1] - z[q]) */
  for (a = 0; a < k; ++a) memcpy(R->send + a * own, rows + a * nrow + r0, own * sizeof(double));
  PX_TRY(px_comm_allgatherv(R->comm, R->send, k * own * sizeof(double), R->rows, NULL));
  for (q = 0; q < (size_t)R->size; ++q) {
    const size_t q0 = (size_t)R->z[q], nq = (size_t)R->z[q + 1] - q0;
    for (a = 0; a < k; ++a, at += nq)
      memcpy(rows + a * nrow + q0, R->rows + at, nq * sizeof(double));
  }
  return PX_STATUS_OK;
}

static enum px_status px_lattice_count_sum(void *arg, long *v) {
  return px_comm_allreduce_long(((struct px_lattice_ranks *)arg)->comm, v, 1, PX_COMM_SUM);
}

/* --- setup, gather --- */

void px_lattice_ranks_free(struct px_lattice *L) {
  struct px_lattice_ranks *R = L->ranks;
  if (!R) return;
  px_mem_free(L->ctx, R->z);
  px_mem_free(L->ctx, R->counts);
  px_mem_free(L->ctx, R->rows);
  px_mem_free(L->ctx, R->send);
  px_mem_free(L->ctx, R);
  L->ranks = NULL;
}

/* INFO on rank 0: the rank grid, the blocks and the halo bytes per step. */
static void px_lattice_ranks_log(const struct px_lattice_ranks *R, const size_t *count) {
  const struct px_lattice *L = R->L;
  char blocks[512], bytes[32];
  size_t at = 0, real = L->precision == PX_PRECISION_SINGLE ? 4 : 8;
  /* per step: each force pass (4 RK4 stages or 1 leapfrog step) sends n[1]
   * rows (a plane's entries) of 13 components across each of the size - 1
   * cuts, both ways */
  double passes = L->integ == PX_LATTICE_INTEGRATOR_RK4 ? 4.0 : 1.0;
  double halo =
      passes * 2.0 * (double)(R->size - 1) * PX_LATTICE_NCOMP * (double)R->plane * (double)real;
  int r;
  blocks[0] = 0;
  for (r = 0; r < R->size && at < sizeof blocks; ++r) {
    size_t el = 0;
    long k;
    for (k = R->z[r]; k < R->z[r + 1]; ++k) el += count[k];
    at += (size_t)snprintf(blocks + at, sizeof blocks - at, "%s[%ld, %ld) %zu", r ? ", " : "",
                           R->z[r], R->z[r + 1], el);
  }
  px_text_bytes(halo, 0, bytes, sizeof bytes);
  px_log(L->ctx, PX_LOG_LEVEL_INFO,
         "lattice: %d ranks, blocks of grid rows (row y + %d z; %s; rows [r0, r1) and elements "
         "per rank: %s); halo %s per step (%g force pass%s x 2 ways x %d cut%s x 13 components x "
         "%zu entries of %zu B); every rank holds the whole lattice",
         R->size, L->m.grid.n[1], R->planes ? "whole z-planes: link_once" : "cut between any rows",
         blocks, bytes, passes, passes > 1 ? "es" : "", R->size - 1, R->size > 2 ? "s" : "",
         R->plane, real);
}

enum px_status px_lattice_ranks_create(struct px_lattice *L, struct px_case *c) {
  struct px_comm *comm = px_context_comm(L->ctx);
  const struct px_lattice_model *m = &L->m;
  const long nz = m->grid.n[2];
  const long n1 = m->grid.n[1];
  const size_t nrow = (size_t)n1 * (size_t)nz, n0 = (size_t)m->grid.n[0];
  struct px_lattice_ranks *R;
  struct px_lattice_block b;
  size_t *count, *plane;
  long k;
  int size = px_comm_size(comm);
  enum px_status st = PX_STATUS_OK;
  if (size < 2) return PX_STATUS_OK;
  if (!L->vt->set_block)
    return px_case_fail(c, "backend.type",
                        "the %s lattice engine runs on one rank only (%d ranks given): it "
                        "cannot update a block of rows; use backend.type: cpu or opencl, or "
                        "run without mpirun",
                        L->vt->name, size);
  if (nz < size)
    return px_case_fail(c, "lattice.body",
                        "%d ranks, but the body's grid (%d x %d x %ld cells of h = %g m) has only "
                        "%ld z-plane%s: each rank updates a block of at least a plane's worth of "
                        "rows (its halo), so at most one rank per plane",
                        size, m->grid.n[0], m->grid.n[1], nz, m->grid.h, nz, nz == 1 ? "" : "s");
  R = (struct px_lattice_ranks *)px_mem_calloc(L->ctx, "lattice.ranks", 1, sizeof *R);
  if (!R) return PX_STATUS_NOMEM;
  L->ranks = R;
  R->L = L;
  R->comm = comm;
  R->rank = px_comm_rank(comm);
  R->size = size;
  R->plane = m->n0p * (size_t)m->grid.n[1];
  R->z = (long *)px_mem_alloc(L->ctx, "lattice.ranks", ((size_t)size + 1) * sizeof(long));
  R->counts = (size_t *)px_mem_alloc(L->ctx, "lattice.ranks", (size_t)size * sizeof(size_t));
  R->rows = (double *)px_mem_alloc(L->ctx, "lattice.ranks", 3 * nrow * sizeof(double));
  R->send = (double *)px_mem_alloc(L->ctx, "lattice.ranks", 3 * nrow * sizeof(double));
  count = (size_t *)px_mem_calloc(L->ctx, "lattice.ranks", nrow, sizeof(size_t));
  plane = (size_t *)px_mem_calloc(L->ctx, "lattice.ranks", (size_t)nz, sizeof(size_t));
  if (!R->z || !R->counts || !R->rows || !R->send || !count || !plane) {
    px_mem_free(L->ctx, count);
    px_mem_free(L->ctx, plane);
    return PX_STATUS_NOMEM;
  }
  for (k = 0; k < (long)nrow; ++k) {
    size_t i;
    for (i = 0; i < n0; ++i) count[k] += m->grid.occ[(size_t)k * n0 + i];
  }
  /* link-once sweeps whole planes: split the planes; gather: the rows, a
   * plane's worth at least per rank */
  R->planes = L->vt->scheme(L->e) == PX_LATTICE_SCHEME_LINK_ONCE;
  if (R->planes) {
    long z;
    int r;
    for (z = 0; z < nz; ++z) {
      size_t sum = 0;
      for (k = 0; k < n1; ++k) sum += count[z * n1 + k];
      plane[z] = sum;
    }
    px_lattice_ranks_split(plane, nz, 1, size, R->z);
    for (r = 0; r <= size; ++r) R->z[r] *= n1;
  } else {
    px_lattice_ranks_split(count, (long)nrow, n1, size, R->z);
  }
  if (R->rank == 0) px_lattice_ranks_log(R, count);
  px_mem_free(L->ctx, count);
  px_mem_free(L->ctx, plane);
  b.r0 = R->z[R->rank];
  b.r1 = R->z[R->rank + 1];
  b.arg = R;
  b.halo_start = px_lattice_halo_start;
  b.halo_wait = px_lattice_halo_wait;
  b.rows = px_lattice_rows;
  b.count = px_lattice_count_sum;
  st = L->vt->set_block(L->e, &b);
  return st;
}

enum px_status px_lattice_gather(void *state) {
  struct px_lattice *L = (struct px_lattice *)state;
  struct px_lattice_ranks *R = L->ranks;
  const struct px_lattice_model *m = &L->m;
  struct lt_el *y = NULL, *own = NULL;
  uint8_t *links = NULL, *ownl = NULL;
  size_t first, n;
  enum px_status st = PX_STATUS_OK;
  if (!R) return PX_STATUS_OK;
  first = m->pad + (size_t)R->z[R->rank] * m->n0p;
  n = (size_t)(R->z[R->rank + 1] - R->z[R->rank]) * m->n0p;
  y = (struct lt_el *)px_mem_alloc(L->ctx, "lattice.gather", m->nalloc * sizeof *y);
  links = (uint8_t *)px_mem_alloc(L->ctx, "lattice.gather", m->nalloc);
  if (R->rank == 0) {
    /* rank 0 receives into y and links, where its own block lies too (a
     * send buffer must not overlap the receive buffer): it sends a copy */
    own = (struct lt_el *)px_mem_alloc(L->ctx, "lattice.gather", n * sizeof *own);
    ownl = (uint8_t *)px_mem_alloc(L->ctx, "lattice.gather", n);
  }
  if (!y || !links || (R->rank == 0 && (!own || !ownl)))
    st = px_context_fail(L->ctx, PX_STATUS_NOMEM, "lattice: out of memory for the gather");
  if (st == PX_STATUS_OK) st = L->vt->get_state(L->e, y, links);
  if (st == PX_STATUS_OK && own) {
    memcpy(own, y + first, n * sizeof *y);
    memcpy(ownl, links + first, n);
  }
  /* all ranks go on to the gathers, or none */
  st = px_comm_agree(R->comm, L->ctx, st, NULL);
  /* the blocks follow one another in rank order: rank 0 receives the
   * planes [0, n[2]) back to back, from its first plane on */
  if (st == PX_STATUS_OK)
    st = px_comm_gatherv(R->comm, own ? (void *)own : (void *)(y + first), n * sizeof *y,
                         y + m->pad, NULL, 0);
  if (st == PX_STATUS_OK)
    st = px_comm_gatherv(R->comm, ownl ? ownl : links + first, n, links + m->pad, NULL, 0);
  if (st == PX_STATUS_OK && R->rank == 0) st = L->vt->set_state(L->e, y, links);
  px_mem_free(L->ctx, y);
  px_mem_free(L->ctx, links);
  px_mem_free(L->ctx, own);
  px_mem_free(L->ctx, ownl);
  return st;
}
