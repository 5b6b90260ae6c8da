/* The opencl lattice engine on a block of a decomposition over ranks
 * (struct px_lattice_block, lattice_ranks.c): the device updates the rows
 * [r0, r1) only, and the halo (the n1 rows on each side) of every force
 * pass's stage state crosses through the host.
 *
 * A pass: read this block's edges (its first and last n1 rows) of the stage
 * state from the device into a host copy, post their exchange
 * (halo_start), queue the kernels of the rows that do not read the halo,
 * wait for the exchange, write the received halo rows to the device, then
 * queue the kernels of the two edges and the boundary-condition kernel of this
 * block's elements. The element kernels take their range as the launch's
 * `pad` (the first entry) and `n` (the entries), so lattice.cl runs
 * unchanged: every element computes what it computes on one device, from
 * the same states, hence the same bits.
 *
 * Fracture: each rank breaks the links of its own elements (both ends of a
 * link across the cut decide alike from the same states); the broken ends
 * are summed over the ranks at every fracture pass. Link-once (whole-plane
 * blocks): the links of the halo plane z0 - 1 are evaluated too (the
 * z-links into plane z0), with its z-plus flags mirrored from this block's
 * plane z0.
 *
 * Per pass and cut: 2 x 13 messages of n0p n[1] reals (px_lattice_ranks),
 * and 2 x 13 reads and writes of as many reals over the device's bus.
 *
 * A block of a 2-D (y, z) rank grid (gather only): its faces cross through
 * the host alike (13 transfers of its y range per z face, 13 per own plane
 * of one row per y face; one packed message per face and way), its
 * kernels run plane by plane over its j range, the interior while the
 * faces travel.
 *
 * Poisson's ratio != 0 (px_lattice_ocl_blk_pass_vol): after the state's
 * halo (and fracture), each rank computes the volumetric coefficients of
 * its own elements and receives those of its halo through the block's
 * vol_start (one real per halo element, the cpu engine's exchange; the
 * edges' 3 components pass through the host copy's first 3), so that every
 * element again computes what it computes on one device. Nothing overlaps
 * the exchanges then. */
#include <string.h>

#include "partix/memory.h"
#include "solvers/lattice/lattice_opencl.h"
#include "solvers/lattice/lattice_ref.h"

/* Entries of a plane of the padded layout. */
static size_t px_lattice_ocl_plane(const struct px_lattice_ocl *e) {
  return e->m->n0p * (size_t)e->m->grid.n[1];
}

/* The n1 rows from row r (a plane's worth of entries) of the first nc
 * components of buf (the state: PX_LATTICE_NCOMP; the volumetric
 * coefficients: 3) from (write = 0) or to the device, through the host copy
 * e->mirror at the same offsets. */
static enum px_status px_lattice_ocl_xfer(struct px_lattice_ocl *e, struct px_buffer *buf, int nc,
                                          int write, long r) {
  const size_t plane = px_lattice_ocl_plane(e), bytes = plane * e->real;
  int k;
  for (k = 0; k < nc; ++k) {
    size_t off = ((size_t)k * e->ns + e->pad + (size_t)r * e->m->n0p) * e->real;
    char *h = (char *)e->mirror + off;
    PX_TRY(write ? px_buffer_write(buf, off, bytes, h) : px_buffer_read(buf, off, bytes, h));
  }
  return PX_STATUS_OK;
}

/* Rows of the grid. */
static long px_lattice_ocl_nrow(const struct px_lattice_ocl *e) {
  return (long)e->m->grid.n[1] * e->m->grid.n[2];
}

/* Read this block's edges of ys (nc components, px_lattice_ocl_xfer) into
 * the mirror. */
static enum px_status px_lattice_ocl_edges(struct px_lattice_ocl *e, struct px_buffer *ys, int nc) {
  const struct px_lattice_block *b = &e->blk;
  const long n1 = e->m->grid.n[1];
  /* rows [r0, r0 + n1) go down, [r1 - n1, r1) up (one read when the same) */
  if (b->r0 > 0) PX_TRY(px_lattice_ocl_xfer(e, ys, nc, 0, b->r0));
  if (b->r1 < px_lattice_ocl_nrow(e) && !(b->r0 > 0 && b->r1 - n1 == b->r0))
    PX_TRY(px_lattice_ocl_xfer(e, ys, nc, 0, b->r1 - n1));
  return PX_STATUS_OK;
}

/* Read this block's edges of the state ys (nc components) and post their
 * exchange (the mirror's PX_LATTICE_NCOMP components). */
static enum px_status px_lattice_ocl_halo_post(struct px_lattice_ocl *e, struct px_buffer *ys,
                                               int nc) {
  const struct px_lattice_block *b = &e->blk;
  PX_TRY(px_lattice_ocl_edges(e, ys, nc));
  return b->halo_start(b->arg, e->mirror, e->real, e->ns);
}

/* Wait for the exchange and write the halo rows to ys (nc components). */
static enum px_status px_lattice_ocl_halo_finish(struct px_lattice_ocl *e, struct px_buffer *ys,
                                                 int nc) {
  const struct px_lattice_block *b = &e->blk;
  PX_TRY(b->halo_wait(b->arg));
  if (b->r0 > 0) PX_TRY(px_lattice_ocl_xfer(e, ys, nc, 1, b->r0 - e->m->grid.n[1]));
  if (b->r1 < px_lattice_ocl_nrow(e)) PX_TRY(px_lattice_ocl_xfer(e, ys, nc, 1, b->r1));
  return PX_STATUS_OK;
}

/* The element kernels' range: rows [ra, rb) (0: empty). */
static int px_lattice_ocl_range(struct px_lattice_ocl *e, long ra, long rb) {
  if (ra >= rb) return 0;
  e->at = (cl_uint)(e->m->pad + (size_t)ra * e->m->n0p);
  e->cnt = (cl_uint)((size_t)(rb - ra) * e->m->n0p);
  return 1;
}

static void px_lattice_ocl_whole(struct px_lattice_ocl *e) {
  e->at = e->pad;
  e->cnt = e->n;
}

/* One force pass's kernel on the elements of a range. */
struct px_lattice_ocl_pass {
  int rk4, stage;
  struct px_buffer *ys, *yn;
  double cs, dt; /* [s] */
  cl_int kstep;
};

static enum px_status px_lattice_ocl_blk_kernel(struct px_lattice_ocl *e,
                                                const struct px_lattice_ocl_pass *p, int bc) {
  return p->rk4 ? px_lattice_ocl_rk4_stage(e, bc, p->stage, p->ys, p->yn, p->cs, p->dt, p->kstep)
                : px_lattice_ocl_lf_kernel(e, bc, p->ys, p->yn, p->dt, p->kstep);
}

/* kind 0: the pass's element kernel, 1: link-once links of ys, 2: fracture
 * at ys, 4: the volumetric coefficients of ys; on the rows [ra, rb). */
static enum px_status px_lattice_ocl_on(struct px_lattice_ocl *e,
                                        const struct px_lattice_ocl_pass *p, int kind, long ra,
                                        long rb) {
  enum px_status st;
  if (!px_lattice_ocl_range(e, ra, rb)) return PX_STATUS_OK;
  st = kind == 0   ? px_lattice_ocl_blk_kernel(e, p, 0)
       : kind == 1 ? px_lattice_ocl_links(e, p->ys)
       : kind == 2 ? px_lattice_ocl_fracture(e, p->ys)
                   : px_lattice_ocl_vol(e, p->ys);
  px_lattice_ocl_whole(e);
  return st;
}

/* The halo's z-plus link flags across the lower cut from this block's own
 * decisions (lattice_cpu.c px_lattice_cpu_mirror): the link-once links of
 * plane z0 - 1 (whole-plane blocks) read them. */
static enum px_status px_lattice_ocl_mirror(struct px_lattice_ocl *e) {
  const struct px_lattice_block *b = &e->blk;
  const size_t plane = px_lattice_ocl_plane(e);
  const size_t lo = e->m->pad + (size_t)b->r0 * e->m->n0p; /* first own entry */
  uint8_t *own, *halo;
  size_t i;
  enum px_status st = PX_STATUS_OK;
  if (b->r0 == 0) return PX_STATUS_OK;
  own = (uint8_t *)px_mem_alloc(e->ctx, "lattice.ocl", 2 * plane);
  if (!own) return PX_STATUS_NOMEM;
  halo = own + plane;
  st = px_buffer_read(e->lm, lo, plane, own);
  if (st == PX_STATUS_OK) st = px_buffer_read(e->lp, lo - plane, plane, halo);
  for (i = 0; i < plane; ++i) halo[i] = (uint8_t)((halo[i] & ~4u) | (((unsigned)own[i] >> 3) & 4u));
  if (st == PX_STATUS_OK) st = px_buffer_write(e->lp, lo - plane, plane, halo);
  px_mem_free(e->ctx, own);
  return st;
}

/* The broken link ends of this pass: this rank's from the device counter
 * (then zeroed), summed over the ranks. */
static enum px_status px_lattice_ocl_ends(struct px_lattice_ocl *e) {
  int ends = 0, zero = 0;
  long v;
  PX_TRY(px_buffer_read(e->ends, 0, sizeof ends, &ends));
  PX_TRY(px_buffer_write(e->ends, 0, sizeof zero, &zero));
  v = ends;
  PX_TRY(e->blk.count(e->blk.arg, &v));
  e->ends_host += v;
  return PX_STATUS_OK;
}

/* --- a block of a 2-D (y, z) rank grid (b->j1 > 0; the gather scheme) --- */

/* Count rows first + i stride of the first nc components of buf
 * (px_lattice_ocl_xfer) from (write = 0) or to the device, through the host
 * copy e->mirror at the same offsets (consecutive rows: one transfer per
 * component). */
static enum px_status px_lattice_ocl_xfer_rows(struct px_lattice_ocl *e, struct px_buffer *buf,
                                               int nc, int write, long first, long count,
                                               long stride) {
  const size_t row = e->m->n0p * e->real;
  const long per = stride == 1 ? count : 1; /* rows per transfer */
  long i;
  int k;
  for (k = 0; k < nc; ++k)
    for (i = 0; i < count; i += per) {
      size_t off = ((size_t)k * e->ns + e->pad) * e->real + (size_t)(first + i * stride) * row;
      char *h = (char *)e->mirror + off;
      PX_TRY(write ? px_buffer_write(buf, off, (size_t)per * row, h)
                   : px_buffer_read(buf, off, (size_t)per * row, h));
    }
  return PX_STATUS_OK;
}

/* The faces of this 2-D block that have a neighbour: the rows sent (recv
 * = 0: read from ys) or received (1: written to ys), nc components; y faces
 * are a row per own plane, z faces the own rows of a plane. */
static enum px_status px_lattice_ocl_faces(struct px_lattice_ocl *e, struct px_buffer *ys, int nc,
                                           int recv) {
  const struct px_lattice_block *b = &e->blk;
  const long n1 = e->m->grid.n[1], n2 = e->m->grid.n[2], nk = b->k1 - b->k0;
  if (b->j0 > 0)
    PX_TRY(px_lattice_ocl_xfer_rows(e, ys, nc, recv, b->j0 - recv + n1 * b->k0, nk, n1));
  if (b->j1 < n1)
    PX_TRY(px_lattice_ocl_xfer_rows(e, ys, nc, recv, b->j1 - 1 + recv + n1 * b->k0, nk, n1));
  if (b->k0 > 0)
    PX_TRY(
        px_lattice_ocl_xfer_rows(e, ys, nc, recv, b->j0 + n1 * (b->k0 - recv), b->j1 - b->j0, 1));
  if (b->k1 < n2)
    PX_TRY(px_lattice_ocl_xfer_rows(e, ys, nc, recv, b->j0 + n1 * (b->k1 - 1 + recv), b->j1 - b->j0,
                                    1));
  return PX_STATUS_OK;
}

/* kind (px_lattice_ocl_on; 3: the Rayleigh row sums) on the rectangles
 * [q0, q1) of the 2-D block, one launch per plane. */
static enum px_status px_lattice_ocl_on2(struct px_lattice_ocl *e,
                                         const struct px_lattice_ocl_pass *p, int kind, int q0,
                                         int q1) {
  const long n1 = e->m->grid.n[1];
  long r[4], k;
  int q;
  for (q = q0; q < q1; ++q) {
    px_lattice_block_rect(&e->blk, q, r);
    if (r[0] >= r[1]) continue;
    for (k = r[2]; k < r[3]; ++k) {
      if (kind == 3)
        PX_TRY(px_lattice_ocl_row_sums(e, r[0] + n1 * k, r[1] + n1 * k));
      else
        PX_TRY(px_lattice_ocl_on(e, p, kind, r[0] + n1 * k, r[1] + n1 * k));
    }
  }
  return PX_STATUS_OK;
}

/* The state's halo of ys exchanged, without overlap (a row block or a 2-D
 * block). */
static enum px_status px_lattice_ocl_blk_state(struct px_lattice_ocl *e, struct px_buffer *ys) {
  const struct px_lattice_block *b = &e->blk;
  if (b->j1 > 0) {
    PX_TRY(px_lattice_ocl_faces(e, ys, PX_LATTICE_NCOMP, 0));
    PX_TRY(b->halo_start(b->arg, e->mirror, e->real, e->ns));
    PX_TRY(b->halo_wait(b->arg));
    return px_lattice_ocl_faces(e, ys, PX_LATTICE_NCOMP, 1);
  }
  PX_TRY(px_lattice_ocl_halo_post(e, ys, PX_LATTICE_NCOMP));
  return px_lattice_ocl_halo_finish(e, ys, PX_LATTICE_NCOMP);
}

/* Volumetric term (nu != 0; lattice.cl lt_vol): the coefficients P_a of
 * this block's elements at ys (its state halo in place, this pass's
 * fracture decided), then those of the halo from the neighbours, which
 * computed them with their own link flags (a halo element's flags are not
 * kept on this rank). The edges' 3 components go through the mirror (the
 * layout of pv in its first 3 components), but the exchange (vol_start)
 * carries only the component the links across each cut read, one real per
 * halo element, as the cpu engine's; the halo components it does not fill
 * are written back unread. */
static enum px_status px_lattice_ocl_blk_vol(struct px_lattice_ocl *e, struct px_buffer *ys) {
  const struct px_lattice_block *b = &e->blk;
  struct px_lattice_ocl_pass p;
  memset(&p, 0, sizeof p);
  p.ys = ys;
  if (b->j1 > 0) {
    PX_TRY(px_lattice_ocl_on2(e, &p, 4, 0, 5));
    PX_TRY(px_lattice_ocl_faces(e, e->pv, 3, 0));
    PX_TRY(b->vol_start(b->arg, e->mirror, e->real, e->ns));
    PX_TRY(b->halo_wait(b->arg));
    return px_lattice_ocl_faces(e, e->pv, 3, 1);
  }
  PX_TRY(px_lattice_ocl_on(e, &p, 4, b->r0, b->r1));
  PX_TRY(px_lattice_ocl_edges(e, e->pv, 3));
  PX_TRY(b->vol_start(b->arg, e->mirror, e->real, e->ns));
  return px_lattice_ocl_halo_finish(e, e->pv, 3);
}

/* px_lattice_ocl_blk_pass with the volumetric term: the state's halo,
 * fracture, the coefficients and their halo, then the element kernels; no
 * kernel overlaps an exchange (the forces of every element read its
 * neighbours' coefficients, which wait for the state's halo). */
static enum px_status px_lattice_ocl_blk_pass_vol(struct px_lattice_ocl *e,
                                                  const struct px_lattice_ocl_pass *p, int frac) {
  const struct px_lattice_block *b = &e->blk;
  const long rh = b->r0 > 0 ? b->r0 - e->m->grid.n[1] : b->r0;
  PX_TRY(px_lattice_ocl_blk_state(e, p->ys));
  if (frac) {
    if (b->j1 > 0)
      PX_TRY(px_lattice_ocl_on2(e, p, 2, 0, 5));
    else
      PX_TRY(px_lattice_ocl_on(e, p, 2, b->r0, b->r1));
    PX_TRY(px_lattice_ocl_ends(e));
    if (e->l1) PX_TRY(px_lattice_ocl_mirror(e));
  }
  PX_TRY(px_lattice_ocl_blk_vol(e, p->ys));
  if (b->j1 > 0) {
    PX_TRY(px_lattice_ocl_on2(e, p, 0, 0, 5));
  } else {
    /* link-once: the halo plane's z-links too (rh) */
    if (e->l1) PX_TRY(px_lattice_ocl_on(e, p, 1, rh, b->r1));
    PX_TRY(px_lattice_ocl_on(e, p, 0, b->r0, b->r1));
  }
  if (e->nbc) PX_TRY(px_lattice_ocl_blk_kernel(e, p, 1));
  return PX_STATUS_OK;
}

/* px_lattice_ocl_blk_pass on a 2-D block: its faces read and exchanged,
 * the interior queued meanwhile, then the received faces written and the
 * bands along them queued. */
static enum px_status px_lattice_ocl_blk2_pass(struct px_lattice_ocl *e,
                                               const struct px_lattice_ocl_pass *p, int frac) {
  const struct px_lattice_block *b = &e->blk;
  PX_TRY(px_lattice_ocl_faces(e, p->ys, PX_LATTICE_NCOMP, 0));
  PX_TRY(b->halo_start(b->arg, e->mirror, e->real, e->ns));
  PX_TRY(px_lattice_ocl_on2(e, p, frac ? 2 : 0, 0, 1));
  PX_TRY(b->halo_wait(b->arg));
  PX_TRY(px_lattice_ocl_faces(e, p->ys, PX_LATTICE_NCOMP, 1));
  PX_TRY(px_lattice_ocl_on2(e, p, frac ? 2 : 0, 1, 5));
  if (frac) {
    PX_TRY(px_lattice_ocl_ends(e));
    PX_TRY(px_lattice_ocl_on2(e, p, 0, 0, 5));
  }
  if (e->nbc) PX_TRY(px_lattice_ocl_blk_kernel(e, p, 1));
  return PX_STATUS_OK;
}

/* One force pass of the block, with fracture at ys first when frac. */
static enum px_status px_lattice_ocl_blk_pass(struct px_lattice_ocl *e,
                                              const struct px_lattice_ocl_pass *p, int frac) {
  const struct px_lattice_block *b = &e->blk;
  const long n1 = e->m->grid.n[1];
  /* lower edge [r0, a), interior [a, c), upper edge [c, r1): the edges are
   * the n1 rows next to the halo */
  const long a = b->r0 + n1 < b->r1 ? b->r0 + n1 : b->r1;
  const long c = b->r1 - n1 > a ? b->r1 - n1 : a;
  /* link-once links of rows whose + z neighbour row is this block's */
  const long lk = c < b->r1 - n1 ? c : b->r1 - n1;
  const long rh = b->r0 > 0 ? b->r0 - n1 : b->r0;
  if (e->pv) return px_lattice_ocl_blk_pass_vol(e, p, frac);
  if (b->j1 > 0) return px_lattice_ocl_blk2_pass(e, p, frac);
  PX_TRY(px_lattice_ocl_halo_post(e, p->ys, PX_LATTICE_NCOMP));
  if (frac) {
    PX_TRY(px_lattice_ocl_on(e, p, 2, a, c));
    PX_TRY(px_lattice_ocl_halo_finish(e, p->ys, PX_LATTICE_NCOMP));
    PX_TRY(px_lattice_ocl_on(e, p, 2, b->r0, a));
    PX_TRY(px_lattice_ocl_on(e, p, 2, c, b->r1));
    PX_TRY(px_lattice_ocl_ends(e));
    if (e->l1) {
      PX_TRY(px_lattice_ocl_mirror(e));
      PX_TRY(px_lattice_ocl_on(e, p, 1, rh, b->r1));
    }
    PX_TRY(px_lattice_ocl_on(e, p, 0, b->r0, b->r1));
  } else {
    if (e->l1) PX_TRY(px_lattice_ocl_on(e, p, 1, b->r0, lk));
    PX_TRY(px_lattice_ocl_on(e, p, 0, a, c));
    PX_TRY(px_lattice_ocl_halo_finish(e, p->ys, PX_LATTICE_NCOMP));
    if (e->l1) {
      PX_TRY(px_lattice_ocl_on(e, p, 1, rh, b->r0));
      PX_TRY(px_lattice_ocl_on(e, p, 1, lk > b->r0 ? lk : b->r0, b->r1));
    }
    PX_TRY(px_lattice_ocl_on(e, p, 0, b->r0, a));
    PX_TRY(px_lattice_ocl_on(e, p, 0, c, b->r1));
  }
  if (e->nbc) PX_TRY(px_lattice_ocl_blk_kernel(e, p, 1));
  return PX_STATUS_OK;
}

enum px_status px_lattice_ocl_run_blk(struct px_lattice_ocl *e, long step, double t, double dt,
                                      long n) {
  static const double cst[4] = {0.0, 0.5, 0.5, 1.0};
  long s;
  for (s = 0; s < n; ++s) {
    double ts = t + (double)s * dt;
    struct px_lattice_ocl_pass p;
    if (e->unchecked == 0) e->first_unchecked = step + s + 1;
    p.kstep = (cl_int)e->unchecked + 1;
    p.dt = dt;
    if (e->integ == PX_LATTICE_INTEGRATOR_RK4) {
      int st;
      p.rk4 = 1;
      for (st = 0; st < 4; ++st) {
        p.stage = st;
        p.ys = st == 0 ? e->buf[0] : (st == 2 ? e->buf[2] : e->buf[1]);
        p.yn = st == 1 ? e->buf[2] : e->buf[1];
        p.cs = st == 2 ? dt : 0.5 * dt;
        PX_TRY(px_lattice_ocl_table(e, ts + cst[st] * dt, 0));
        PX_TRY(px_lattice_ocl_blk_pass(e, &p, st == 0 && e->m->fracture));
      }
    } else {
      p.rk4 = 0;
      p.stage = -1;
      p.ys = e->buf[e->cur];
      p.yn = e->buf[1 - e->cur];
      p.cs = 0.0;
      PX_TRY(px_lattice_ocl_table(e, ts, 0));
      PX_TRY(px_lattice_ocl_blk_pass(e, &p, e->m->fracture));
      e->cur = 1 - e->cur;
    }
    e->t_end[e->unchecked] = ts + dt;
    if (++e->unchecked >= PX_LATTICE_OCL_CHECK) PX_TRY(px_lattice_ocl_check(e, step + s + 1));
  }
  return PX_STATUS_OK;
}

/* This block's rows of the current state (its halo exchanged meanwhile),
 * then every rank's rows into e->rowsum. */
enum px_status px_lattice_ocl_rayleigh_blk(struct px_lattice_ocl *e, double sums[3]) {
  const struct px_lattice_block *b = &e->blk;
  const long n1 = e->m->grid.n[1];
  const long a = b->r0 + n1 < b->r1 ? b->r0 + n1 : b->r1;
  const long c = b->r1 - n1 > a ? b->r1 - n1 : a;
  struct px_buffer *y = px_lattice_ocl_state(e);
  if (e->pv) {
    /* q.K q includes the volumetric forces: the coefficients first */
    PX_TRY(px_lattice_ocl_blk_state(e, y));
    PX_TRY(px_lattice_ocl_blk_vol(e, y));
    if (b->j1 > 0)
      PX_TRY(px_lattice_ocl_on2(e, NULL, 3, 0, 5));
    else
      PX_TRY(px_lattice_ocl_row_sums(e, b->r0, b->r1));
    return b->rows(b->arg, e->rowsum, 3, sums);
  }
  if (b->j1 > 0) {
    PX_TRY(px_lattice_ocl_faces(e, y, PX_LATTICE_NCOMP, 0));
    PX_TRY(b->halo_start(b->arg, e->mirror, e->real, e->ns));
    PX_TRY(px_lattice_ocl_on2(e, NULL, 3, 0, 1));
    PX_TRY(b->halo_wait(b->arg));
    PX_TRY(px_lattice_ocl_faces(e, y, PX_LATTICE_NCOMP, 1));
    PX_TRY(px_lattice_ocl_on2(e, NULL, 3, 1, 5));
    return b->rows(b->arg, e->rowsum, 3, sums);
  }
  PX_TRY(px_lattice_ocl_halo_post(e, y, PX_LATTICE_NCOMP));
  PX_TRY(px_lattice_ocl_row_sums(e, a, c));
  PX_TRY(px_lattice_ocl_halo_finish(e, y, PX_LATTICE_NCOMP));
  PX_TRY(px_lattice_ocl_row_sums(e, b->r0, a));
  PX_TRY(px_lattice_ocl_row_sums(e, c, b->r1));
  return b->rows(b->arg, e->rowsum, 3, sums);
}

enum px_status px_lattice_ocl_blk_current(struct px_lattice_ocl *e) {
  struct px_buffer *y = px_lattice_ocl_state(e);
  PX_TRY(px_lattice_ocl_blk_state(e, y));
  return e->pv ? px_lattice_ocl_blk_vol(e, y) : PX_STATUS_OK;
}

long px_lattice_ocl_broken_blk(struct px_lattice_ocl *e) { return e->ends_host / 2; }

enum px_status px_lattice_ocl_set_broken_blk(struct px_lattice_ocl *e, long links) {
  int zero = 0;
  e->ends_host = 2 * links;
  return px_buffer_write(e->ends, 0, sizeof zero, &zero);
}

enum px_status px_lattice_ocl_set_block(void *p, const struct px_lattice_block *b) {
  struct px_lattice_ocl *e = (struct px_lattice_ocl *)p;
  const struct px_lattice_model *m = e->m;
  size_t i, lo, hi;
  cl_uint *list, nbc = 0;
  int ends = 0;
  enum px_status st;
  if (!b) {
    if (e->has_blk)
      return px_context_fail(e->ctx, PX_STATUS_UNSUPPORTED,
                             "the opencl lattice engine cannot return from a block to the whole "
                             "grid");
    return PX_STATUS_OK;
  }
  if (b->j1 > 0 && e->l1)
    return px_context_fail(e->ctx, PX_STATUS_UNSUPPORTED,
                           "the opencl lattice engine's link_once scheme updates blocks of whole "
                           "z-planes only, not the (y, z) blocks of a 2-D rank grid");
  if (!e->mirror)
    e->mirror = px_mem_alloc(e->ctx, "lattice.ocl", PX_LATTICE_NCOMP * e->ns * e->real);
  if (!e->mirror) return PX_STATUS_NOMEM;
  memset(e->mirror, 0, PX_LATTICE_NCOMP * e->ns * e->real);
  /* the broken ends so far (a global count) move to the host */
  PX_TRY(px_buffer_read(e->ends, 0, sizeof ends, &ends));
  if (!e->has_blk) e->ends_host = ends;
  PX_TRY(px_lattice_ocl_set_broken_blk(e, e->ends_host / 2));
  e->blk = *b;
  e->has_blk = 1;
  /* the boundary-condition kernels run on this block's elements only */
  lo = m->pad + (size_t)b->r0 * m->n0p;
  hi = m->pad + (size_t)b->r1 * m->n0p;
  list = (cl_uint *)px_mem_alloc(e->ctx, "lattice.ocl", (hi - lo) * sizeof *list + 1);
  if (!list) return PX_STATUS_NOMEM;
  for (i = lo; i < hi; ++i) {
    /* a 2-D block: the rows of its j range only */
    const long j = (long)((i - m->pad) / m->n0p) % m->grid.n[1];
    if (m->group[i] > 1 && (b->j1 == 0 || (j >= b->j0 && j < b->j1))) list[nbc++] = (cl_uint)i;
  }
  st = nbc ? px_buffer_write(e->list, 0, nbc * sizeof *list, list) : PX_STATUS_OK;
  px_mem_free(e->ctx, list);
  e->nbc = nbc;
  return st;
}
