/* The granular solver on the opencl backend: all state resident in device
 * buffers (granular.cl), velocity Verlet. The host keeps a mirror system
 * (the cpu system of the same case, same precision) used for outputs and
 * checkpoints only: it is refreshed from the device when they fall due.
 * Per step the host writes the contour frames (9 values per contour) and
 * reads one number (the largest displacement since the rebuild); wall
 * events are drained every 64 steps and at outputs. Over K > 1 MPI ranks
 * each rank's device steps its own discs (B_OWN) and the ghost rows cross
 * through the host after the drift (granular_ranks_opencl.c). */
#include "solvers/granular/granular_engine.h"

/* Compiled only with the opencl backend (FOO_opencl.c, CMakeLists.txt); the
 * engine table of granular.c lists this engine with PX_IF_OPENCL. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compute/backend_impl.h"
#include "compute/opencl/kernels.h"
#include "partix/checkpoint.h"
#include "partix/memory.h"
#include "partix/neighbors.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/granular_opencl_impl.h"
#include "solvers/granular/wall_kernel.h"

extern const char px_cl_source_granular[];

/* The program's kernels (cached by the backend: handles only). */
struct px_gran_cl_kernels {
  cl_program prog;
  cl_kernel drift, forces, nbrs, walls, pack, unpack;
};

static enum px_status px_gran_cl_create(struct px_backend *be, struct px_gran_sys *h,
                                        struct px_gran_cl **out) {
  struct px_context *ctx = px_backend_context(be);
  struct px_gran_cl *e;
  const struct px_gran_geom *g = h->geom;
  enum px_status st = PX_STATUS_OK;
  char opts[256];
  enum px_precision real_prec;
  size_t n = h->n;
  *out = NULL;
  if (h->integrator != PX_GRAN_INTEGRATOR_VERLET)
    return px_context_fail(ctx, PX_STATUS_UNSUPPORTED,
                           "granular: the opencl engine integrates with velocity Verlet only "
                           "(integrator: abm4 runs on the cpu backend)");
  if (h->precision != PX_PRECISION_SINGLE) PX_TRY(px_backend_require(be, PX_PRECISION_DOUBLE));
  if (px_comm_size(h->comm) > PX_COMM_BATCH_MAX)
    return px_context_fail(ctx, PX_STATUS_UNSUPPORTED,
                           "granular: the opencl engine runs on at most %d MPI ranks (%d asked)",
                           PX_COMM_BATCH_MAX, px_comm_size(h->comm));
  e = px_mem_calloc(ctx, "granular opencl", 1, sizeof *e);
  if (!e) return PX_STATUS_NOMEM;
  e->be = be;
  e->ctx = ctx;
  e->h = h;
  e->n = n;
  e->ss = h->ssize;
  e->cs = h->csize;
  e->nseg = g ? g->nseg : 0;
  e->ncontours = g ? g->ncontours : 0;
  e->step = h->step;
  e->synced_step = h->step;
  e->t = h->t;
  e->prec = h->ssize == sizeof(double) ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
  e->need_rebuild = 1;
  e->ev_cap = 65536 + 16 * n;
  e->comm = h->comm;
  e->nrank = px_comm_size(h->comm);
  e->rank = px_comm_rank(h->comm);
  real_prec = h->csize == sizeof(double) ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
  snprintf(opts, sizeof opts, "-DPX_GRAN_STATE=%s -DPX_GRAN_NMAX=%d -DPX_GRAN_WCMAX=%d",
           h->ssize == sizeof(double) ? "double" : "float", PX_GRAN_CL_NMAX, PX_GRAN_CL_WCMAX);
  e->kern = px_mem_calloc(ctx, "granular opencl", 1, sizeof *e->kern);
  if (!e->kern) {
    st = PX_STATUS_NOMEM;
    goto fail;
  }
  {
    struct px_gran_cl_kernels *K = e->kern;
    st = px_opencl_program_real(be, "granular", px_cl_source_granular, real_prec, opts, &K->prog);
    if (st == PX_STATUS_OK) st = px_opencl_kernel(be, K->prog, "gran_drift", &K->drift);
    if (st == PX_STATUS_OK) st = px_opencl_kernel(be, K->prog, "gran_forces", &K->forces);
    if (st == PX_STATUS_OK) st = px_opencl_kernel(be, K->prog, "gran_neighbours", &K->nbrs);
    if (st == PX_STATUS_OK) st = px_opencl_kernel(be, K->prog, "gran_wall_candidates", &K->walls);
    if (st == PX_STATUS_OK) st = px_opencl_kernel(be, K->prog, "gran_pack", &K->pack);
    if (st == PX_STATUS_OK) st = px_opencl_kernel(be, K->prog, "gran_unpack", &K->unpack);
  }
  if (st != PX_STATUS_OK) goto fail;
  st = px_gran_cl_buffers(e);
  if (st == PX_STATUS_OK) st = px_gran_cl_walls(e);
  if (st == PX_STATUS_OK) st = px_gran_cl_upload_state(e);
  if (st == PX_STATUS_OK) st = px_gran_cl_grid(e);
  if (st != PX_STATUS_OK) goto fail;
  e->ev_i = px_mem_alloc(ctx, "granular opencl events", e->ev_cap * PX_GRAN_EVI * sizeof(int));
  e->ev_r = px_mem_alloc(ctx, "granular opencl events", e->ev_cap * PX_GRAN_EVR * e->cs);
  if (!e->ev_i || !e->ev_r) {
    st = PX_STATUS_NOMEM;
    goto fail;
  }
  *out = e;
  return PX_STATUS_OK;
fail:
  px_gran_cl_free(e);
  return st;
}

/* A real of the integrated state (PX_GRAN_STATE in granular.cl): the
 * program's PX_REAL is the contact precision, so the state's reals are bound
 * by their explicit width (they differ in mixed precision). */
static void px_gran_cl_args_state(struct px_opencl_args *a, const struct px_gran_cl *e,
                                  const char *name, double v) {
  if (e->ss == sizeof(double))
    px_opencl_args_f64(a, name, v);
  else
    px_opencl_args_f32(a, name, (float)v);
}

static void px_gran_cl_args_buf(struct px_opencl_args *a, const struct px_gran_cl *e,
                                const char *name, int k) {
  px_opencl_args_mem(a, name, e->b[k]);
}

/* The wall segments' geometry in the body frames (7 arrays in the order of
 * both kernels that take them). */
static void px_gran_cl_args_segments(struct px_opencl_args *a, const struct px_gran_cl *e) {
  px_gran_cl_args_buf(a, e, "sax", B_SAX);
  px_gran_cl_args_buf(a, e, "say", B_SAY);
  px_gran_cl_args_buf(a, e, "stx", B_STX);
  px_gran_cl_args_buf(a, e, "sty", B_STY);
  px_gran_cl_args_buf(a, e, "slen", B_SLEN);
  px_gran_cl_args_buf(a, e, "stpx", B_STPX);
  px_gran_cl_args_buf(a, e, "stpy", B_STPY);
}

static enum px_status px_gran_cl_rebuild(struct px_gran_cl *e) {
  struct px_gran_sys *h = e->h;
  const cl_uint n = (cl_uint)e->n;
  const uint32_t zero = 0;
  uint32_t ovf = 0, esc = 0;
  struct px_opencl_args a;
  PX_TRY(px_grid_build(e->grid, e->prec, e->n, e->b[B_X], e->b[B_Y], NULL));
  /* the previous lists become the old ones */
  px_gran_cl_swap(e, B_NCOUNT, B_ONCOUNT);
  px_gran_cl_swap(e, B_NBR, B_ONBR);
  px_gran_cl_swap(e, B_HXI, B_OXI);
  px_gran_cl_swap(e, B_HTH, B_OTH);
  px_gran_cl_swap(e, B_HDM, B_ODM);
  px_gran_cl_swap(e, B_HDP, B_ODP);
  PX_TRY(px_buffer_write(e->b[B_OVF], 0, 4, &zero));
  PX_TRY(px_buffer_write(e->b[B_ESC], 0, 4, &zero));
  px_opencl_args_begin(&a, e->be, e->kern->nbrs);
  px_opencl_args_u32(&a, "n", n);
  px_gran_cl_args_state(&a, e, "cut_extra", h->skin);
  px_gran_cl_args_buf(&a, e, "x", B_X);
  px_gran_cl_args_buf(&a, e, "y", B_Y);
  px_gran_cl_args_buf(&a, e, "r", B_R);
  px_opencl_args_mem(&a, "cell", px_grid_cells(e->grid));
  px_opencl_args_mem(&a, "perm", px_grid_permutation(e->grid));
  px_opencl_args_mem(&a, "start", px_grid_cell_start(e->grid));
  px_opencl_args_mem(&a, "end", px_grid_cell_end(e->grid));
  px_opencl_args_i32(&a, "nx", e->grid_nx);
  px_opencl_args_i32(&a, "ny", e->grid_ny);
  px_gran_cl_args_buf(&a, e, "ocount", B_ONCOUNT);
  px_gran_cl_args_buf(&a, e, "onbr", B_ONBR);
  px_gran_cl_args_buf(&a, e, "oxi", B_OXI);
  px_gran_cl_args_buf(&a, e, "oth", B_OTH);
  px_gran_cl_args_buf(&a, e, "odm", B_ODM);
  px_gran_cl_args_buf(&a, e, "odp", B_ODP);
  px_gran_cl_args_buf(&a, e, "ncount", B_NCOUNT);
  px_gran_cl_args_buf(&a, e, "nbr", B_NBR);
  px_gran_cl_args_buf(&a, e, "hxi", B_HXI);
  px_gran_cl_args_buf(&a, e, "hth", B_HTH);
  px_gran_cl_args_buf(&a, e, "hdm", B_HDM);
  px_gran_cl_args_buf(&a, e, "hdp", B_HDP);
  px_gran_cl_args_buf(&a, e, "overflow", B_OVF);
  PX_TRY(px_opencl_args_launch(&a, e->n, 0));
  /* wall candidates (also the reference positions and the escape check) */
  px_opencl_args_begin(&a, e->be, e->kern->walls);
  px_opencl_args_u32(&a, "n", n);
  px_gran_cl_args_state(&a, e, "skin", h->skin);
  px_gran_cl_args_buf(&a, e, "x", B_X);
  px_gran_cl_args_buf(&a, e, "y", B_Y);
  px_gran_cl_args_buf(&a, e, "r", B_R);
  px_gran_cl_args_buf(&a, e, "xr", B_XR);
  px_gran_cl_args_buf(&a, e, "yr", B_YR);
  px_opencl_args_i32(&a, "ncontours", (int32_t)e->ncontours);
  px_gran_cl_args_buf(&a, e, "frames", B_FRAMES);
  px_gran_cl_args_buf(&a, e, "cbox", B_CBOX);
  px_gran_cl_args_buf(&a, e, "cbin", B_CBIN);
  px_gran_cl_args_buf(&a, e, "bin_start", B_BINSTART);
  px_gran_cl_args_buf(&a, e, "bin_seg", B_BINSEG);
  px_gran_cl_args_segments(&a, e);
  px_gran_cl_args_buf(&a, e, "cfirst", B_CFIRST);
  px_gran_cl_args_buf(&a, e, "ccount", B_CCOUNT);
  px_gran_cl_args_buf(&a, e, "wcount", B_WCOUNT);
  px_gran_cl_args_buf(&a, e, "wcand", B_WCAND);
  px_gran_cl_args_buf(&a, e, "overflow", B_OVF);
  px_gran_cl_args_buf(&a, e, "escaped", B_ESC);
  PX_TRY(px_opencl_args_launch(&a, e->n, 0));
  PX_TRY(px_buffer_read(e->b[B_OVF], 0, 4, &ovf));
  PX_TRY(px_buffer_read(e->b[B_ESC], 0, 4, &esc));
  if (ovf)
    return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                           "particle %u has more than %d neighbours or %d wall segments within "
                           "reach at step %ld (overlaps far too deep: the time step is too "
                           "large or the stiffness too low)",
                           ovf - 1, PX_GRAN_CL_NMAX, PX_GRAN_CL_WCMAX, e->step);
  if (esc)
    return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                           "particle %u has passed through a boundary at step %ld (t = %g s) "
                           "(its centre is behind the wall): the wall is too soft or the time "
                           "step too large for the impact speed",
                           esc - 1, e->step, e->t);
  e->need_rebuild = 0;
  return PX_STATUS_OK;
}

/* A launch over this rank's discs (none: an idle rank launches nothing). */
static enum px_status px_gran_cl_launch(struct px_opencl_args *a, size_t n) {
  if (n == 0) return px_opencl_args_end(a);
  return px_opencl_args_launch(a, n, 0);
}

static enum px_status px_gran_cl_step(struct px_gran_cl *e) {
  struct px_gran_sys *h = e->h;
  const double tnew = e->t + h->dt;
  uint32_t md = 0;
  const uint32_t zero = 0;
  struct px_opencl_args a;
  h->t = e->t;
  h->step = e->step;
  if (e->nrank > 1 && !e->plan_ok) PX_TRY(px_gran_cl_ranks_plan(e));
  px_gran_sys_frames(h, tnew);
  PX_TRY(px_gran_cl_write_frames(e));
  PX_TRY(px_buffer_write(e->b[B_MAXD], 0, 4, &zero));
  px_opencl_args_begin(&a, e->be, e->kern->drift);
  px_opencl_args_u32(&a, "n", (cl_uint)e->nown);
  px_gran_cl_args_buf(&a, e, "own", B_OWN);
  px_gran_cl_args_state(&a, e, "h", h->dt);
  px_gran_cl_args_buf(&a, e, "x", B_X);
  px_gran_cl_args_buf(&a, e, "y", B_Y);
  px_gran_cl_args_buf(&a, e, "vx", B_VX);
  px_gran_cl_args_buf(&a, e, "vy", B_VY);
  px_gran_cl_args_buf(&a, e, "w", B_W);
  px_gran_cl_args_buf(&a, e, "ax", B_AX);
  px_gran_cl_args_buf(&a, e, "ay", B_AY);
  px_gran_cl_args_buf(&a, e, "aw", B_AW);
  px_gran_cl_args_buf(&a, e, "xr", B_XR);
  px_gran_cl_args_buf(&a, e, "yr", B_YR);
  px_gran_cl_args_buf(&a, e, "maxdisp", B_MAXD);
  PX_TRY(px_gran_cl_launch(&a, e->nown));
  PX_TRY(px_buffer_read(e->b[B_MAXD], 0, 4, &md));
  if (e->nrank > 1) PX_TRY(px_gran_cl_ranks_maxdisp(e, &md));
  {
    float df;
    double d, dw;
    memcpy(&df, &md, sizeof df);
    d = (double)df;
    if (!(d <= DBL_MAX)) {
      /* a position became non-finite (the drift's largest displacement is
       * NaN or inf: as unsigned bits they are above every finite float):
       * found at this step's drift, one step after a non-finite velocity */
      if (e->nrank > 1) {
        /* every rank finds the first such disc in the whole state */
        PX_TRY(px_gran_cl_ranks_state(e, -1));
        PX_TRY(px_gran_cl_ranks_drain(e));
      }
      PX_TRY(px_gran_cl_download(e));
      PX_TRY(px_gran_sys_check_finite(h, e->step + 1, tnew));
      return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                             "a particle's displacement is not finite at step %ld (t = %g s)",
                             e->step + 1, tnew);
    }
    dw = px_gran_sys_wall_drift_now(h);
    if (e->need_rebuild || 2 * d > h->skin || d + dw > h->skin) {
      /* over ranks every device rebuilds every disc's lists from the
       * owners' state, then the strips are recut */
      if (e->nrank > 1) PX_TRY(px_gran_cl_ranks_state(e, -1));
      PX_TRY(px_gran_cl_rebuild(e));
      px_gran_sys_set_reference_frames(h);
      ++h->rebuilds;
      if (e->nrank > 1) PX_TRY(px_gran_cl_ranks_plan(e));
    } else if (e->nrank > 1) {
      PX_TRY(px_gran_cl_ranks_ghosts(e));
    }
  }
  px_opencl_args_begin(&a, e->be, e->kern->forces);
  px_opencl_args_u32(&a, "n", (cl_uint)e->nown);
  px_gran_cl_args_buf(&a, e, "own", B_OWN);
  px_opencl_args_real(&a, "dt", h->dt);
  px_opencl_args_i32(&a, "step_no", (int32_t)e->step);
  px_gran_cl_args_state(&a, e, "gx", h->gravity[0]);
  px_gran_cl_args_state(&a, e, "gy", h->gravity[1]);
  px_gran_cl_args_buf(&a, e, "lawp", B_LAWP);
  px_gran_cl_args_buf(&a, e, "laww", B_LAWW);
  px_gran_cl_args_buf(&a, e, "x", B_X);
  px_gran_cl_args_buf(&a, e, "y", B_Y);
  px_gran_cl_args_buf(&a, e, "vx", B_VX);
  px_gran_cl_args_buf(&a, e, "vy", B_VY);
  px_gran_cl_args_buf(&a, e, "w", B_W);
  px_gran_cl_args_buf(&a, e, "ax", B_AX);
  px_gran_cl_args_buf(&a, e, "ay", B_AY);
  px_gran_cl_args_buf(&a, e, "aw", B_AW);
  px_gran_cl_args_buf(&a, e, "r", B_R);
  px_gran_cl_args_buf(&a, e, "m", B_M);
  px_gran_cl_args_buf(&a, e, "im", B_IM);
  px_gran_cl_args_buf(&a, e, "iI", B_II);
  px_gran_cl_args_buf(&a, e, "id", B_ID);
  px_gran_cl_args_buf(&a, e, "ncount", B_NCOUNT);
  px_gran_cl_args_buf(&a, e, "nbr", B_NBR);
  px_gran_cl_args_buf(&a, e, "hxi", B_HXI);
  px_gran_cl_args_buf(&a, e, "hth", B_HTH);
  px_gran_cl_args_buf(&a, e, "hdm", B_HDM);
  px_gran_cl_args_buf(&a, e, "hdp", B_HDP);
  px_opencl_args_i32(&a, "has_walls", e->ncontours > 0);
  px_gran_cl_args_segments(&a, e);
  px_gran_cl_args_buf(&a, e, "sflags", B_SFLAGS);
  px_gran_cl_args_buf(&a, e, "scontour", B_SCONTOUR);
  px_gran_cl_args_buf(&a, e, "cfirst", B_CFIRST);
  px_gran_cl_args_buf(&a, e, "ccount", B_CCOUNT);
  px_gran_cl_args_buf(&a, e, "frames", B_FRAMES);
  px_gran_cl_args_buf(&a, e, "wcount", B_WCOUNT);
  px_gran_cl_args_buf(&a, e, "wcand", B_WCAND);
  px_gran_cl_args_buf(&a, e, "sseg", B_SSEG);
  px_gran_cl_args_buf(&a, e, "sseg0", B_SSEG0);
  px_gran_cl_args_buf(&a, e, "sstep0", B_SSTEP0);
  px_gran_cl_args_buf(&a, e, "st0", B_ST0);
  px_gran_cl_args_buf(&a, e, "ste", B_STE);
  px_gran_cl_args_buf(&a, e, "sxi", B_SXI);
  px_gran_cl_args_buf(&a, e, "sth", B_STH);
  px_gran_cl_args_buf(&a, e, "sdm", B_SDM);
  px_gran_cl_args_buf(&a, e, "sdp", B_SDP);
  px_gran_cl_args_buf(&a, e, "simp", B_SIMP);
  px_gran_cl_args_buf(&a, e, "sslw", B_SSLW);
  px_gran_cl_args_buf(&a, e, "sarc", B_SARC);
  px_gran_cl_args_buf(&a, e, "stim", B_STIM);
  px_gran_cl_args_buf(&a, e, "ev_i", B_EVI);
  px_gran_cl_args_buf(&a, e, "ev_r", B_EVR);
  px_gran_cl_args_buf(&a, e, "ev_n", B_EVN);
  px_opencl_args_u32(&a, "ev_cap", (uint32_t)e->ev_cap);
  px_gran_cl_args_buf(&a, e, "wforce", B_WFORCE);
  px_gran_cl_args_buf(&a, e, "vxn", B_VXN);
  px_gran_cl_args_buf(&a, e, "vyn", B_VYN);
  px_gran_cl_args_buf(&a, e, "wn", B_WN);
  PX_TRY(px_gran_cl_launch(&a, e->nown));
  px_gran_cl_swap(e, B_VX, B_VXN);
  px_gran_cl_swap(e, B_VY, B_VYN);
  px_gran_cl_swap(e, B_W, B_WN);
  ++e->step;
  e->t = tnew;
  h->step = e->step;
  h->t = e->t;
  if (e->step % PX_GRAN_CL_DRAIN == 0)
    PX_TRY(e->nrank > 1 ? px_gran_cl_ranks_drain(e) : px_gran_cl_drain(e));
  return PX_STATUS_OK;
}

enum px_status px_gran_cl_pack(struct px_gran_cl *e, int unpack, size_t first, size_t end) {
  struct px_opencl_args a;
  if (end <= first) return PX_STATUS_OK;
  px_opencl_args_begin(&a, e->be, unpack ? e->kern->unpack : e->kern->pack);
  px_opencl_args_u32(&a, "n", (cl_uint)end);
  px_gran_cl_args_buf(&a, e, "idx", B_GIDX);
  if (unpack) px_gran_cl_args_buf(&a, e, "buf", B_GBUF);
  px_gran_cl_args_buf(&a, e, "x", B_X);
  px_gran_cl_args_buf(&a, e, "y", B_Y);
  px_gran_cl_args_buf(&a, e, "vx", B_VX);
  px_gran_cl_args_buf(&a, e, "vy", B_VY);
  px_gran_cl_args_buf(&a, e, "w", B_W);
  if (!unpack) px_gran_cl_args_buf(&a, e, "buf", B_GBUF);
  return px_opencl_args_launch_range(&a, first, end - first, 0);
}

/* ---- the engine table (granular_engine.h) -------------------------------- */

static void px_gran_cl_caps(struct px_backend *be, struct px_gran_caps *caps) {
  caps->fp64 = px_backend_has_fp64(be);
  caps->abm4 = 0;
  caps->host_threads = 1;
  caps->ranks = 1;
  caps->why_no_abm4 =
      "the opencl engine integrates with velocity Verlet only; abm4 runs on the cpu backend";
}

static enum px_status px_gran_cl_engine_create(struct px_backend *be, struct px_gran_sys *s,
                                               void **out) {
  struct px_gran_cl *e = NULL;
  enum px_status st;
  *out = NULL;
  PX_TRY(px_gran_cl_create(be, s, &e));
  /* the frames of the start on the device */
  px_gran_sys_frames(e->h, e->t);
  st = px_gran_cl_write_frames(e);
  if (st != PX_STATUS_OK) {
    px_gran_cl_free(e);
    return st;
  }
  *out = e;
  return PX_STATUS_OK;
}

static void px_gran_cl_engine_destroy(void *e) {
  if (e) px_gran_cl_ranks_free(e);
  px_gran_cl_free(e);
}

/* The driver's step index and dt are those of the mirror the engine was
 * made from (the device keeps its own count). */
static enum px_status px_gran_cl_engine_step(void *e, long step, double dt) {
  (void)step;
  (void)dt;
  return px_gran_cl_step(e);
}

static enum px_status px_gran_cl_engine_sync(void *ev) {
  struct px_gran_cl *e = ev;
  if (e->synced_step == e->step) return PX_STATUS_OK;
  PX_TRY(px_gran_cl_download(e));
  e->synced_step = e->step;
  return PX_STATUS_OK;
}

/* Over ranks: every rank's events into the statistics, the owners' rows
 * onto rank 0's device, whose mirror is then refreshed from it (the other
 * ranks' mirrors are not read: outputs and checkpoints are rank 0's). */
static enum px_status px_gran_cl_engine_gather(void *ev) {
  struct px_gran_cl *e = ev;
  if (e->nrank < 2) return px_gran_cl_engine_sync(ev);
  if (e->synced_step == e->step) return PX_STATUS_OK;
  PX_TRY(px_gran_cl_ranks_drain(e));
  PX_TRY(px_gran_cl_ranks_state(e, 0));
  if (e->rank == 0) PX_TRY(px_gran_cl_download(e));
  e->synced_step = e->step;
  return PX_STATUS_OK;
}

static enum px_status px_gran_cl_engine_save(void *e, struct px_checkpoint_writer *w) {
  return px_gran_cl_save(e, w);
}

static enum px_status px_gran_cl_engine_load(void *e, struct px_checkpoint *ck) {
  return px_gran_cl_load(e, ck);
}

static enum px_status px_gran_cl_engine_upload(void *e) { return px_gran_cl_upload(e); }

static enum px_status px_gran_cl_engine_contacts(void *e, int32_t **pairs, size_t *np) {
  return px_gran_cl_contacts(e, pairs, np);
}

const struct px_gran_engine_i px_gran_engine_opencl = {.name = "opencl",
                                                       .caps = px_gran_cl_caps,
                                                       .create = px_gran_cl_engine_create,
                                                       .destroy = px_gran_cl_engine_destroy,
                                                       .step = px_gran_cl_engine_step,
                                                       .sync = px_gran_cl_engine_sync,
                                                       .gather = px_gran_cl_engine_gather,
                                                       .save = px_gran_cl_engine_save,
                                                       .load = px_gran_cl_engine_load,
                                                       .upload = px_gran_cl_engine_upload,
                                                       .contacts = px_gran_cl_engine_contacts};
