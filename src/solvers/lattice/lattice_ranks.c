/* The lattice over several ranks (`mpirun -np K partix run`, K > 1).
 *
 * Decomposition: a rank grid py x pz over (y, z) (x rows stay whole: x is
 * the padded SIMD axis), chosen from the extents for the least halo area
 * (px_lattice_ranks_grid). py = 1 (a body thick in z, or link-once, which
 * splits z only): blocks of whole grid rows (a row: the n0p entries of one
 * (y, z); row r = y + n[1] z), in the order of the padded layout, so that a
 * rank's block is one contiguous range of every state component and the
 * engines' row loops (gather) run over a range unchanged. The gather scheme
 * cuts between any two rows, so a body thin in z (a plate: few planes of
 * many rows) still splits evenly; link-once sweeps whole z-planes, so its
 * blocks are whole planes. A block holds at least a plane's worth of rows
 * (n[1]), so that its halo, the n[1] rows on each side (the neighbours of
 * its elements along z reach n[1] rows away), belongs to its two
 * neighbouring ranks. The boundaries balance the elements per rank
 * (px_lattice_ranks_split). Each rank's engine holds its window only: its
 * block and halo, in a padded layout of their own (L->wm,
 * px_lattice_model_window; whole z-planes for row blocks), updates the
 * block and keeps the halo current (struct px_lattice_block,
 * lattice_engine.h): before every force pass each rank sends its first and
 * last n[1] rows of the pass's stage state to the neighbours, one message
 * per state component (13 per side, straight from and into the state
 * buffer), non-blocking, while the rows away from the cut are computed.
 * py > 1 (the gather scheme; a plate thin in z): rank
 * iy + py iz owns j in [jc[iy], jc[iy + 1]), k in [kc[iz], kc[iz + 1]),
 * each axis's cuts balancing the elements along it; its halo is one row
 * (y faces: the rows j0 - 1 and j1 of its planes) or one plane's part
 * (z faces: the rows [j0, j1) of the planes k0 - 1 and k1) on each side,
 * the links reaching face neighbours only; one message per face and way,
 * the 13 components packed back to back. With nu != 0 (the volumetric
 * term) each pass also exchanges the halo's coefficients P, computed by
 * their owners (px_lattice_vol_start): one component per halo element (the
 * axis of the links that reach it), one packed message per neighbour and
 * way.
 *
 * Global quantities as on one rank, to the bit: the Rayleigh sums are per
 * grid row (summed in row order on every rank after an allgather of the
 * rows), the broken-link count an exact integer sum. Fracture needs no
 * message: the two ranks that hold a link across the cut evaluate it from
 * the same states and decide alike. Outputs and checkpoints
 * (lattice_gather.c): every rank computes its block's fields and sends
 * them and its state, in pieces, to rank 0, which holds the whole state and
 * fields in the 1-rank layout for the writers; a load gives each rank its
 * window of the checkpoint's state. */
#include <string.h>

#include "core/comm.h"
#include "core/text.h"
#include "partix/memory.h"
#include "solvers/lattice/lattice.h"
#include "solvers/lattice/lattice_c.h"
#include "solvers/lattice/lattice_ranks_impl.h"

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

int px_lattice_ranks_grid(const int n[3], int size, int *py, int *pz) {
  /* cut faces per x cell: a z cut crosses n[1] of them, a y cut n[2] */
  double best = -1.0;
  int y;
  if (size < 1) return -1;
  for (y = 1; y <= size; ++y) {
    const int z = size / y;
    double area;
    if (y * z != size || y > n[1] || z > n[2]) continue;
    area = (double)(z - 1) * n[1] + (double)(y - 1) * n[2];
    /* <=: of equal areas the later one, with fewer z cuts, is kept */
    if (best < 0.0 || area <= best) {
      best = area;
      *py = y;
      *pz = z;
    }
  }
  return best < 0.0 ? -1 : 0;
}

long px_lattice_ranks_seg(const struct px_lattice_ranks *R, int q, long s, long *a, long *b) {
  const long n1 = R->L->m.grid.n[1];
  int iy, iz;
  if (R->py == 1) {
    *a = R->z[q];
    *b = R->z[q + 1];
    return 1;
  }
  iy = q % R->py;
  iz = q / R->py;
  *a = R->jc[iy] + n1 * (R->kc[iz] + s);
  *b = R->jc[iy + 1] + n1 * (R->kc[iz] + s);
  return R->kc[iz + 1] - R->kc[iz];
}

/* --- struct px_lattice_block callbacks --- */

/* Face f of this rank's 2-D block (0: y-, 1: y+, 2: z-, 3: z+): the
 * neighbour (-1: none) and the rows sent (recv = 0) or received there, as
 * count rows first + i stride of its window. */
static int px_lattice_ranks_face(const struct px_lattice_ranks *R, int f, int recv, long *first,
                                 long *count, long *stride) {
  const long n1 = R->n1w;
  const int iy = R->rank % R->py, iz = R->rank / R->py;
  const long j0 = R->jc[iy], j1 = R->jc[iy + 1], k0 = R->kc[iz], k1 = R->kc[iz + 1];
  if (f < 2) {
    const long j = f == 0 ? (recv ? j0 - 1 : j0) : (recv ? j1 : j1 - 1);
    *first = px_lattice_ranks_loc(R, j, k0);
    *count = k1 - k0;
    *stride = n1;
    if (f == 0) return iy > 0 ? R->rank - 1 : -1;
    return iy + 1 < R->py ? R->rank + 1 : -1;
  }
  *first = px_lattice_ranks_loc(R, j0, f == 2 ? (recv ? k0 - 1 : k0) : (recv ? k1 : k1 - 1));
  *count = j1 - j0;
  *stride = 1;
  if (f == 2) return iz > 0 ? R->rank - R->py : -1;
  return iz + 1 < R->pz ? R->rank + R->py : -1;
}

/* The rows of face f of every component of the state buffer into its
 * packed room (recv = 0: to send) or from it (recv = 1: received),
 * components back to back; bytes packed. */
static size_t px_lattice_ranks_pack(struct px_lattice_ranks *R, int f, int recv) {
  const struct px_lattice_model *m = &R->L->wm;
  const size_t row = m->n0p * R->hreal;
  char *room = R->pack + (size_t)(f + 4 * recv) * R->face;
  long first, count, stride, i;
  int c;
  px_lattice_ranks_face(R, f, recv, &first, &count, &stride);
  for (c = 0; c < PX_LATTICE_NCOMP; ++c) {
    char *base = (char *)R->hbuf + ((size_t)c * R->hns + m->pad) * R->hreal;
    for (i = 0; i < count; ++i, room += row) {
      char *at = base + (size_t)(first + i * stride) * row;
      if (recv)
        memcpy(at, room, row);
      else
        memcpy(room, at, row);
    }
  }
  return (size_t)PX_LATTICE_NCOMP * (size_t)count * row;
}

/* The 2-D halo: one message per face and way (tag: the direction of travel,
 * 0 -y, 1 +y, 2 -z, 3 +z), packed; unpacked by px_lattice_halo_wait. */
static enum px_status px_lattice_halo2_start(struct px_lattice_ranks *R) {
  struct px_comm_msg msg[8];
  size_t n = 0;
  int f;
  for (f = 0; f < 4; ++f) {
    long first, count, stride;
    const int peer = px_lattice_ranks_face(R, f, 0, &first, &count, &stride);
    size_t bytes;
    if (peer < 0) continue;
    bytes = px_lattice_ranks_pack(R, f, 0);
    msg[n++] = (struct px_comm_msg){R->pack + (size_t)f * R->face, bytes, peer, f, 0};
    msg[n++] = (struct px_comm_msg){R->pack + (size_t)(f + 4) * R->face, bytes, peer, f ^ 1, 1};
  }
  return px_comm_start(R->comm, msg, n);
}

static enum px_status px_lattice_halo_start(void *arg, void *buf, size_t real, size_t ns) {
  struct px_lattice_ranks *R = (struct px_lattice_ranks *)arg;
  const struct px_lattice_model *m = &R->L->wm;
  struct px_comm_msg msg[4 * PX_LATTICE_NCOMP];
  /* the halo: the n[1] rows (a plane's entries) on each side */
  const size_t row = m->n0p * real, bytes = R->plane * real, n1 = (size_t)m->grid.n[1];
  const size_t r0 = (size_t)R->lr0, r1 = (size_t)R->lr1;
  size_t n = 0;
  int k;
  R->hbuf = buf;
  R->hreal = real;
  R->hns = ns;
  R->hvol = 0;
  if (R->py > 1) return px_lattice_halo2_start(R);
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

/* The volumetric coefficients' halo (nu != 0) at face f (a 2-D grid: 0 y-,
 * 1 y+, 2 z-, 3 z+; row blocks: 2 the rank below, 3 the rank above) as
 * segments {component, first row, rows, row stride} of the rows sent
 * (recv = 0) or received there: P_a of the state halo's rows, a the axis
 * the face cuts (the links across it are along a), and for row blocks P_y
 * of the row next to the cut (its y-link with the cut's first row). Returns
 * the neighbour (-1: none); *nseg segments. */
static int px_lattice_ranks_vface(const struct px_lattice_ranks *R, int f, int recv, long seg[2][4],
                                  int *nseg) {
  const long n1 = R->L->m.grid.n[1];
  long r0, r1;
  if (R->py > 1) {
    seg[0][0] = f < 2 ? 1 : 2;
    *nseg = 1;
    return px_lattice_ranks_face(R, f, recv, &seg[0][1], &seg[0][2], &seg[0][3]);
  }
  r0 = R->lr0;
  r1 = R->lr1;
  seg[0][0] = 2;
  seg[0][1] = f == 2 ? (recv ? r0 - n1 : r0) : (recv ? r1 : r1 - n1);
  seg[0][2] = n1;
  seg[1][0] = 1;
  seg[1][1] = f == 2 ? (recv ? r0 - 1 : r0) : (recv ? r1 : r1 - 1);
  seg[1][2] = 1;
  seg[0][3] = seg[1][3] = 1;
  *nseg = 2;
  if (f == 2) return R->rank > 0 ? R->rank - 1 : -1;
  if (f == 3) return R->rank + 1 < R->size ? R->rank + 1 : -1;
  return -1;
}

/* The coefficients' rows of face f into its packed room (recv = 0: to send)
 * or from it (recv = 1); bytes packed. */
static size_t px_lattice_ranks_vpack(struct px_lattice_ranks *R, int f, int recv) {
  const struct px_lattice_model *m = &R->L->wm;
  const size_t row = m->n0p * R->hreal;
  char *const start = R->vpack + (size_t)(f + 4 * recv) * R->vface;
  char *room = start;
  long seg[2][4], i;
  int nseg, s;
  px_lattice_ranks_vface(R, f, recv, seg, &nseg);
  for (s = 0; s < nseg; ++s) {
    char *base = (char *)R->hbuf + ((size_t)seg[s][0] * R->hns + m->pad) * R->hreal;
    for (i = 0; i < seg[s][2]; ++i, room += row) {
      char *at = base + (size_t)(seg[s][1] + i * seg[s][3]) * row;
      if (recv)
        memcpy(at, room, row);
      else
        memcpy(room, at, row);
    }
  }
  return (size_t)(room - start);
}

/* The coefficients' halo: one packed message per neighbour and way (tag 32
 * + the direction of travel, as px_lattice_halo2_start's). */
static enum px_status px_lattice_vol_start(void *arg, void *pv, size_t real, size_t ns) {
  struct px_lattice_ranks *R = (struct px_lattice_ranks *)arg;
  struct px_comm_msg msg[8];
  size_t n = 0;
  int f;
  R->hbuf = pv;
  R->hreal = real;
  R->hns = ns;
  R->hvol = 1;
  for (f = 0; f < 4; ++f) {
    long seg[2][4];
    int nseg;
    const int peer = px_lattice_ranks_vface(R, f, 0, seg, &nseg);
    size_t bytes;
    if (peer < 0) continue;
    bytes = px_lattice_ranks_vpack(R, f, 0);
    msg[n++] = (struct px_comm_msg){R->vpack + (size_t)f * R->vface, bytes, peer, 32 + f, 0};
    msg[n++] =
        (struct px_comm_msg){R->vpack + (size_t)(f + 4) * R->vface, bytes, peer, 32 + (f ^ 1), 1};
  }
  return px_comm_start(R->comm, msg, n);
}

static enum px_status px_lattice_halo_wait(void *arg) {
  struct px_lattice_ranks *R = (struct px_lattice_ranks *)arg;
  int f;
  PX_TRY(px_comm_wait(R->comm));
  for (f = 0; f < 4; ++f) {
    long first, count, stride, seg[2][4];
    int nseg;
    if (R->hvol) {
      if (px_lattice_ranks_vface(R, f, 1, seg, &nseg) >= 0) px_lattice_ranks_vpack(R, f, 1);
    } else if (R->py > 1 && px_lattice_ranks_face(R, f, 1, &first, &count, &stride) >= 0) {
      px_lattice_ranks_pack(R, f, 1);
    }
  }
  return PX_STATUS_OK;
}

void px_lattice_ranks_lseg(const struct px_lattice_ranks *R, long a, long b, long *la, long *lb) {
  const long n1 = R->L->m.grid.n[1];
  *la = px_lattice_ranks_loc(R, a % n1, a / n1);
  *lb = *la + (b - a);
}

static enum px_status px_lattice_rows(void *arg, const double *rows, size_t k, double *sums) {
  struct px_lattice_ranks *R = (struct px_lattice_ranks *)arg;
  const size_t nrow = (size_t)R->L->m.grid.n[1] * (size_t)R->L->m.grid.n[2];
  const size_t nwin = (size_t)R->L->wm.grid.n[1] * (size_t)R->L->wm.grid.n[2];
  size_t a, at = 0, r;
  long s, ns, r0, r1, l0, l1;
  int q;
  if (k > 3) return px_context_fail(R->L->ctx, PX_STATUS_INVALID, "lattice rows: %zu arrays", k);
  /* own rows of each array back to back, segment by segment */
  for (a = 0; a < k; ++a)
    for (s = 0, ns = 1; s < ns; ++s) {
      ns = px_lattice_ranks_seg(R, R->rank, s, &r0, &r1);
      px_lattice_ranks_lseg(R, r0, r1, &l0, &l1);
      memcpy(R->send + at, rows + a * nwin + l0, (size_t)(l1 - l0) * sizeof(double));
      at += (size_t)(l1 - l0);
    }
  PX_TRY(px_comm_allgatherv(R->comm, R->send, at * sizeof(double), R->rows, NULL));
  for (q = 0, at = 0; q < R->size; ++q)
    for (a = 0; a < k; ++a)
      for (s = 0, ns = 1; s < ns; ++s) {
        ns = px_lattice_ranks_seg(R, q, s, &r0, &r1);
        memcpy(R->all + a * nrow + r0, R->rows + at, (size_t)(r1 - r0) * sizeof(double));
        at += (size_t)(r1 - r0);
      }
  /* in row order, as one rank adds them */
  for (a = 0; a < k; ++a) {
    double sum = 0.0;
    for (r = 0; r < nrow; ++r) sum += R->all[a * nrow + r];
    sums[a] = sum;
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
  px_mem_free(L->ctx, R->jc);
  px_mem_free(L->ctx, R->kc);
  px_mem_free(L->ctx, R->pack);
  px_mem_free(L->ctx, R->vpack);
  px_mem_free(L->ctx, R->counts);
  px_mem_free(L->ctx, R->rows);
  px_mem_free(L->ctx, R->send);
  px_mem_free(L->ctx, R->all);
  px_mem_free(L->ctx, R);
  L->ranks = NULL;
  px_mem_free(L->ctx, L->gy);
  px_mem_free(L->ctx, L->gl);
  L->gy = NULL;
  L->gl = NULL;
}

/* Elements of rank q's block. */
static size_t px_lattice_ranks_elements(const struct px_lattice_ranks *R, const size_t *count,
                                        int q) {
  size_t el = 0;
  long s, ns, a, b, r;
  for (s = 0, ns = 1; s < ns; ++s)
    for (ns = px_lattice_ranks_seg(R, q, s, &a, &b), r = a; r < b; ++r) el += count[r];
  return el;
}

/* INFO on rank 0: the rank grid, the blocks and the halo bytes per step;
 * why: "" or why the grid is not the extents' choice. */
static void px_lattice_ranks_log(const struct px_lattice_ranks *R, const size_t *count,
                                 const char *why) {
  const struct px_lattice *L = R->L;
  const long n1 = L->m.grid.n[1], n2 = L->m.grid.n[2];
  char blocks[512], bytes[32];
  size_t at = 0, real = L->precision == PX_PRECISION_SINGLE ? 4 : 8;
  /* per step: each force pass (4 RK4 stages or 1 leapfrog step) sends, both
   * ways across every cut, 13 components of the rows along it: n[1] rows
   * per row-block cut (a plane's worth); on a 2-D grid, n[2] rows per y cut
   * (one per plane) and n[1] per z cut */
  const double passes = L->integ == PX_LATTICE_INTEGRATOR_RK4 ? 4.0 : 1.0;
  const double rows = R->py > 1
                          ? (double)(R->py - 1) * (double)n2 + (double)(R->pz - 1) * (double)n1
                          : (double)(R->size - 1) * (double)n1;
  const double halo = passes * 2.0 * PX_LATTICE_NCOMP * rows * (double)L->m.n0p * (double)real;
  /* messages per pass: 13 per cut and way for row blocks, 1 per neighbour
   * pair and way for a 2-D grid */
  const long msgs = R->py > 1 ? 2L * (R->pz * (R->py - 1) + R->py * (R->pz - 1))
                              : 2L * PX_LATTICE_NCOMP * (R->size - 1);
  /* nu != 0: each pass then also sends, both ways, one component of the
   * volumetric coefficients of the same rows (row blocks: and of the row
   * next to each cut), one packed message per neighbour and way */
  const double vrows = R->py > 1 ? rows : rows + (double)(R->size - 1);
  const double vol = passes * 2.0 * vrows * (double)L->m.n0p * (double)real;
  const long vmsgs = R->py > 1 ? msgs : 2L * (R->size - 1);
  char vtext[160], vbytes[32], held[256];
  int r;
  vtext[0] = 0;
  snprintf(held, sizeof held,
           "each rank's engine holds its window (block and halo; rank 0: y [%ld, %ld) z [%ld, "
           "%ld), %.3g%% of the grid's rows)",
           R->box[0], R->box[1], R->box[2], R->box[3],
           100.0 * (double)(R->box[1] - R->box[0]) * (double)(R->box[3] - R->box[2]) /
               ((double)n1 * (double)n2));
  if (L->m.lam != 0.0) {
    px_text_bytes(vol, 0, vbytes, sizeof vbytes);
    snprintf(vtext, sizeof vtext,
             "; poisson != 0: volumetric coefficients %s per step (%g rows x 1 component, %ld "
             "messages per pass)",
             vbytes, vrows, vmsgs);
  }
  blocks[0] = 0;
  for (r = 0; r < R->size && at < sizeof blocks; ++r) {
    const size_t el = px_lattice_ranks_elements(R, count, r);
    if (R->py > 1)
      at += (size_t)snprintf(blocks + at, sizeof blocks - at, "%sy [%ld, %ld) z [%ld, %ld) %zu",
                             r ? ", " : "", R->jc[r % R->py], R->jc[r % R->py + 1],
                             R->kc[r / R->py], R->kc[r / R->py + 1], el);
    else
      at += (size_t)snprintf(blocks + at, sizeof blocks - at, "%s[%ld, %ld) %zu", r ? ", " : "",
                             R->z[r], R->z[r + 1], el);
  }
  px_text_bytes(halo, 0, bytes, sizeof bytes);
  if (R->py > 1)
    px_log(L->ctx, PX_LOG_LEVEL_INFO,
           "lattice: ranks %d x %d (y x z), blocks of j and k ranges (y and z ranges and "
           "elements per rank: %s); halo %s per step (%g force pass%s x 2 ways x %g rows of "
           "%zu entries x 13 components of %zu B; %ld messages per pass)%s; %s",
           R->py, R->pz, blocks, bytes, passes, passes > 1 ? "es" : "", rows, L->m.n0p, real, msgs,
           vtext, held);
  else
    px_log(L->ctx, PX_LOG_LEVEL_INFO,
           "lattice: ranks 1 x %d (y x z)%s, blocks of grid rows (row y + %ld z; %s; rows "
           "[r0, r1) and elements per rank: %s); halo %s per step (%g force pass%s x 2 ways x "
           "%g rows of %zu entries x 13 components of %zu B; %ld messages per pass)%s; %s",
           R->size, why, n1, R->planes ? "whole z-planes: link_once" : "cut between any rows",
           blocks, bytes, passes, passes > 1 ? "es" : "", rows, L->m.n0p, real, msgs, vtext, held);
}

/* The y and z cuts of a py x pz grid (py > 1), each axis balancing the
 * elements along it (count: per row), and the packing room of its halo. */
static enum px_status px_lattice_ranks_cuts(struct px_lattice_ranks *R, const size_t *count) {
  struct px_lattice *L = R->L;
  const long n1 = L->m.grid.n[1], n2 = L->m.grid.n[2];
  size_t *cy = (size_t *)px_mem_calloc(L->ctx, "lattice.ranks", (size_t)n1, sizeof(size_t));
  size_t *cz = (size_t *)px_mem_calloc(L->ctx, "lattice.ranks", (size_t)n2, sizeof(size_t));
  long j, k;
  R->jc = (long *)px_mem_alloc(L->ctx, "lattice.ranks", ((size_t)R->py + 1) * sizeof(long));
  R->kc = (long *)px_mem_alloc(L->ctx, "lattice.ranks", ((size_t)R->pz + 1) * sizeof(long));
  if (!cy || !cz || !R->jc || !R->kc) {
    px_mem_free(L->ctx, cy);
    px_mem_free(L->ctx, cz);
    return PX_STATUS_NOMEM;
  }
  for (k = 0; k < n2; ++k)
    for (j = 0; j < n1; ++j) {
      cy[j] += count[j + n1 * k];
      cz[k] += count[j + n1 * k];
    }
  /* py <= n[1], pz <= n[2] (px_lattice_ranks_grid): the splits succeed */
  px_lattice_ranks_split(cy, n1, 1, R->py, R->jc);
  px_lattice_ranks_split(cz, n2, 1, R->pz, R->kc);
  px_mem_free(L->ctx, cy);
  px_mem_free(L->ctx, cz);
  {
    /* a face's room: 13 components of its rows, n0p reals of at most 8 B
     * each; a y face has a row per own plane, a z face one per own y (the
     * neighbours across share those ranges) */
    const long nk = R->kc[R->rank / R->py + 1] - R->kc[R->rank / R->py];
    const long nj = R->jc[R->rank % R->py + 1] - R->jc[R->rank % R->py];
    R->face = (size_t)PX_LATTICE_NCOMP * (size_t)(nk > nj ? nk : nj) * L->m.n0p * sizeof(double);
  }
  R->pack = (char *)px_mem_alloc(L->ctx, "lattice.ranks", 8 * R->face);
  return R->pack ? PX_STATUS_OK : PX_STATUS_NOMEM;
}

/* The rank grid (R->py, R->pz) for this engine and scheme, or a refusal at
 * lattice.body; *why: "" or why the grid is not the extents' choice. */
static enum px_status px_lattice_ranks_choose(struct px_lattice_ranks *R, struct px_case *c,
                                              const char **why) {
  const struct px_lattice *L = R->L;
  const struct px_lattice_model *m = &L->m;
  const long nz = m->grid.n[2];
  /* 2-D grids: the gather scheme (link-once sweeps whole z-planes) */
  const int two = !R->planes;
  int py = 0, pz = 0, fits = px_lattice_ranks_grid(m->grid.n, R->size, &py, &pz) == 0;
  *why = "";
  if (two && fits) {
    R->py = py;
    R->pz = pz;
    return PX_STATUS_OK;
  }
  if (nz < R->size)
    return px_case_fail(c, "lattice.body",
                        "%d ranks, but the body's grid (%d x %d x %ld cells of h = %g m) has only "
                        "%ld z-plane%s: each rank updates a block of at least a plane's worth of "
                        "rows (its halo), so at most one rank per plane%s",
                        R->size, m->grid.n[0], m->grid.n[1], nz, m->grid.h, nz, nz == 1 ? "" : "s",
                        two ? " (and no py x pz grid of the ranks fits the y and z extents)"
                            : "; lattice.scheme: gather splits y too (a py x pz rank grid)");
  R->py = 1;
  R->pz = R->size;
  if (fits && py > 1)
    *why =
        " (link_once splits z only: the extents would choose a y x z grid, which "
        "lattice.scheme: gather takes)";
  return PX_STATUS_OK;
}

/* This rank's window (R->box, R->n1w): its block and the halo its links
 * read. Row blocks: whole z-planes from the one holding row r0 - n[1] to
 * the one holding r1 + n[1] - 1, y whole; a 2-D block: one cell more on
 * each side in y and z (where the grid goes on). */
static void px_lattice_ranks_window(struct px_lattice_ranks *R) {
  const long n1 = R->L->m.grid.n[1], n2 = R->L->m.grid.n[2];
  if (R->py > 1) {
    const int iy = R->rank % R->py, iz = R->rank / R->py;
    R->box[0] = R->jc[iy] > 0 ? R->jc[iy] - 1 : 0;
    R->box[1] = R->jc[iy + 1] < n1 ? R->jc[iy + 1] + 1 : n1;
    R->box[2] = R->kc[iz] > 0 ? R->kc[iz] - 1 : 0;
    R->box[3] = R->kc[iz + 1] < n2 ? R->kc[iz + 1] + 1 : n2;
  } else {
    const long r0 = R->z[R->rank], r1 = R->z[R->rank + 1];
    R->box[0] = 0;
    R->box[1] = n1;
    R->box[2] = r0 >= n1 ? (r0 - n1) / n1 : 0;
    R->box[3] = (r1 + n1 - 1) / n1 + 1 < n2 ? (r1 + n1 - 1) / n1 + 1 : n2;
  }
  R->n1w = R->box[1] - R->box[0];
  R->lr0 = R->py > 1 ? 0 : R->z[R->rank] - n1 * R->box[2];
  R->lr1 = R->py > 1 ? 0 : R->z[R->rank + 1] - n1 * R->box[2];
}

/* The decomposition: rank grid, cuts and the message rooms (before the
 * engine exists: planes = the scheme sweeps whole planes). */
static enum px_status px_lattice_ranks_plan(struct px_lattice *L, struct px_case *c) {
  struct px_lattice_ranks *R = L->ranks;
  const struct px_lattice_model *m = &L->m;
  const long nz = m->grid.n[2];
  const long n1 = m->grid.n[1];
  const size_t nrow = (size_t)n1 * (size_t)nz, n0 = (size_t)m->grid.n[0];
  const int size = R->size;
  size_t *count, *plane;
  const char *why = "";
  long k;
  enum px_status st = PX_STATUS_OK;
  PX_TRY(px_lattice_ranks_choose(R, c, &why));
  R->z = (long *)px_mem_alloc(L->ctx, "lattice.ranks", ((size_t)size + 1) * sizeof(long));
  R->counts = (size_t *)px_mem_alloc(L->ctx, "lattice.ranks", (size_t)size * sizeof(size_t));
  R->rows = (double *)px_mem_alloc(L->ctx, "lattice.ranks", 3 * nrow * sizeof(double));
  R->send = (double *)px_mem_alloc(L->ctx, "lattice.ranks", 3 * nrow * sizeof(double));
  R->all = (double *)px_mem_alloc(L->ctx, "lattice.ranks", 3 * nrow * sizeof(double));
  count = (size_t *)px_mem_calloc(L->ctx, "lattice.ranks", nrow, sizeof(size_t));
  plane = (size_t *)px_mem_calloc(L->ctx, "lattice.ranks", (size_t)nz, sizeof(size_t));
  if (!R->z || !R->counts || !R->rows || !R->send || !R->all || !count || !plane) {
    px_mem_free(L->ctx, count);
    px_mem_free(L->ctx, plane);
    return PX_STATUS_NOMEM;
  }
  for (k = 0; k < (long)nrow; ++k) {
    size_t i;
    for (i = 0; i < n0; ++i) count[k] += m->grid.occ[(size_t)k * n0 + i];
  }
  if (R->py > 1) {
    st = px_lattice_ranks_cuts(R, count);
  } else if (R->planes) {
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
  if (st == PX_STATUS_OK) px_lattice_ranks_window(R);
  if (st == PX_STATUS_OK && R->rank == 0) px_lattice_ranks_log(R, count, why);
  px_mem_free(L->ctx, count);
  px_mem_free(L->ctx, plane);
  PX_TRY(st);
  if (m->lam != 0.0) {
    /* the coefficients' face rooms (px_lattice_ranks_vface): a 2-D face's
     * rows (as R->face's), or a plane's rows and the row next to the cut */
    long rows = n1 + 1;
    if (R->py > 1) {
      const long nk = R->kc[R->rank / R->py + 1] - R->kc[R->rank / R->py];
      const long nj = R->jc[R->rank % R->py + 1] - R->jc[R->rank % R->py];
      rows = nk > nj ? nk : nj;
    }
    R->vface = (size_t)rows * m->n0p * sizeof(double);
    R->vpack = (char *)px_mem_alloc(L->ctx, "lattice.ranks", 8 * R->vface);
    if (!R->vpack) return PX_STATUS_NOMEM;
  }
  return PX_STATUS_OK;
}

enum px_status px_lattice_ranks_create(struct px_lattice *L, struct px_case *c,
                                       const struct px_lattice_engine_opts *o) {
  struct px_comm *comm = px_context_comm(L->ctx);
  struct px_lattice_ranks *R;
  struct px_lattice_block b;
  struct px_lattice_layout lay;
  struct px_lattice_need need;
  int size = px_comm_size(comm);
  if (size < 2) return L->vt->create(L->ctx, &L->m, o, &L->e);
  if (!L->vt->set_block)
    return px_case_fail(c, "backend.type",
                        "the %s lattice engine runs on one rank only (%d ranks given): it "
                        "cannot update a block of rows; use backend.type: cpu or opencl, or "
                        "run without mpirun",
                        L->vt->name, size);
  R = (struct px_lattice_ranks *)px_mem_calloc(L->ctx, "lattice.ranks", 1, sizeof *R);
  if (!R) return PX_STATUS_NOMEM;
  L->ranks = R;
  R->L = L;
  R->comm = comm;
  R->rank = px_comm_rank(comm);
  R->size = size;
  R->plane = L->m.n0p * (size_t)L->m.grid.n[1];
  /* link-once sweeps whole planes: split the planes; gather: the rows, a
   * plane's worth at least per rank, or a 2-D grid */
  px_lattice_model_layout(L->m.grid.n, &lay);
  L->vt->need(&lay, o, &need);
  R->planes = need.scheme == PX_LATTICE_SCHEME_LINK_ONCE;
  PX_TRY(px_lattice_ranks_plan(L, c));
  PX_TRY(px_lattice_model_window(L->ctx, &L->m, R->box, &L->wm));
  PX_TRY(L->vt->create(L->ctx, &L->wm, o, &L->e));
  if (L->vt->scheme(L->e) != need.scheme)
    return px_context_fail(L->ctx, PX_STATUS_INVALID,
                           "lattice ranks: the %s engine's scheme is not the one planned for",
                           L->vt->name);
  memset(&b, 0, sizeof b);
  if (R->py > 1) {
    const int iy = R->rank % R->py, iz = R->rank / R->py;
    b.j0 = R->jc[iy] - R->box[0];
    b.j1 = R->jc[iy + 1] - R->box[0];
    b.k0 = R->kc[iz] - R->box[2];
    b.k1 = R->kc[iz + 1] - R->box[2];
    b.r0 = b.j0 + R->n1w * b.k0;
    b.r1 = b.j1 + R->n1w * (b.k1 - 1);
  } else {
    b.r0 = R->lr0;
    b.r1 = R->lr1;
  }
  b.arg = R;
  b.halo_start = px_lattice_halo_start;
  b.vol_start = px_lattice_vol_start;
  b.halo_wait = px_lattice_halo_wait;
  b.rows = px_lattice_rows;
  b.count = px_lattice_count_sum;
  return L->vt->set_block(L->e, &b);
}
