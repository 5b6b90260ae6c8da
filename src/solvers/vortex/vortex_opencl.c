/* The vortex step on an OpenCL device (kernels in vortex.cl). The wake lives
 * in device buffers for the whole run; the host reads back per step only the
 * scalars the step needs (number of newborn and surviving vortices, a
 * runaway/non-finite flag) and the loads, and the whole wake only for outputs
 * and checkpoints (px_vortex_engine_sync). The generation matrix is inverted
 * once on the host (LAPACKE dgetri) and the device multiplies by it. The
 * `opencl` engine of vortex_engine.h (compiled only with the backend): its
 * blocks here, its buffers and transfers in vortex_buffers_opencl.c. */
#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "compute/opencl/kernels.h"
#include "partix/memory.h"
#include "partix/nbody.h"
#include "partix/timer.h"
#include "nbody/nbody_impl.h"
#include "solvers/vortex/vortex_host.h"
#include "solvers/vortex/vortex_ocl_state.h"
#include "solvers/vortex/vortex_ranks.h"

/* Start binding the arguments of kernel `name` (vortex.cl) into *a. */
static enum px_status begin(struct px_vortex_ocl *d, const char *name, struct px_opencl_args *a) {
  cl_kernel k;
  PX_TRY(px_opencl_kernel(d->be, d->prog, name, &k));
  px_opencl_args_begin(a, d->be, k);
  return PX_STATUS_OK;
}

/* The panels as the kernels take them: start point, tangent and length
 * (frame: x0, y0, tx, ty, len), or start and end points (ends, under the
 * kernel's names for them). */
static void args_frame(struct px_opencl_args *a, struct px_vortex_ocl *d) {
  px_opencl_args_mem(a, "x0", d->p[P_X0]);
  px_opencl_args_mem(a, "y0", d->p[P_Y0]);
  px_opencl_args_mem(a, "tx", d->p[P_TX]);
  px_opencl_args_mem(a, "ty", d->p[P_TY]);
  px_opencl_args_mem(a, "len", d->p[P_LEN]);
}
static void args_ends(struct px_opencl_args *a, struct px_vortex_ocl *d, const char *x0,
                      const char *y0, const char *x1, const char *y1) {
  px_opencl_args_mem(a, x0, d->p[P_X0]);
  px_opencl_args_mem(a, y0, d->p[P_Y0]);
  px_opencl_args_mem(a, x1, d->p[P_X1]);
  px_opencl_args_mem(a, y1, d->p[P_Y1]);
}
/* The bodies' boxes for vx_crossed: nbody, then bbox. */
static void args_boxes(struct px_opencl_args *a, struct px_vortex_ocl *d, size_t nbody) {
  px_opencl_args_u32(a, "nbody", (uint32_t)nbody);
  px_opencl_args_mem(a, "bbox", d->p[P_BBOX]);
}

static void swap_sets(struct px_vortex_ocl *d) {
  for (int q = 0; q < 6; ++q) {
    struct px_buffer *t = d->w[W_X + q];
    d->w[W_X + q] = d->w[W_X2 + q];
    d->w[W_X2 + q] = t;
  }
}

/* Keep the vortices flagged in W_KEEP: scan, compact into set B, swap. */
static enum px_status compact(struct px_vortex_engine *e, size_t nw, size_t *out) {
  static const char *const src[6] = {"xs", "ys", "gs", "us", "vs", "es"};
  static const char *const dst[6] = {"xd", "yd", "gd", "ud", "vd", "ed"};
  struct px_vortex_ocl *d = e->dev;
  struct px_opencl_args a;
  uint32_t total = 0;
  PX_TRY(px_opencl_scan_u32(d->be, d->w[W_KEEP], d->w[W_POS], nw, &total));
  PX_TRY(begin(d, "vx_compact", &a));
  px_opencl_args_u32(&a, "nw", (uint32_t)nw);
  px_opencl_args_mem(&a, "keep", d->w[W_KEEP]);
  px_opencl_args_mem(&a, "pos", d->w[W_POS]);
  for (int q = 0; q < 6; ++q) px_opencl_args_mem(&a, src[q], d->w[W_X + q]);
  for (int q = 0; q < 6; ++q) px_opencl_args_mem(&a, dst[q], d->w[W_X2 + q]);
  PX_TRY(px_opencl_args_launch(&a, nw, 0));
  swap_sets(d);
  *out = total;
  return PX_STATUS_OK;
}

/* The wake's nw vortices into the N-body buffers (positions relative to the
 * bodies' centre, in the N-body precision). */
static enum px_status to_nb(struct px_vortex_engine *e, size_t nw) {
  struct px_vortex_ocl *d = e->dev;
  struct px_opencl_args a;
  PX_TRY(begin(d, "vx_to_nb", &a));
  px_opencl_args_u32(&a, "n", (uint32_t)nw);
  px_opencl_args_mem(&a, "x", d->w[W_X]);
  px_opencl_args_mem(&a, "y", d->w[W_Y]);
  px_opencl_args_mem(&a, "g", d->w[W_G]);
  px_opencl_args_real(&a, "cx", e->center[0]);
  px_opencl_args_real(&a, "cy", e->center[1]);
  px_opencl_args_mem(&a, "sx", d->w[W_NB_X]);
  px_opencl_args_mem(&a, "sy", d->w[W_NB_Y]);
  px_opencl_args_mem(&a, "sg", d->w[W_NB_G]);
  return px_opencl_args_launch(&a, nw, 0);
}

/* Block 1a, b: the right-hand side of the generation system for the wake's
 * nw vortices and the panels' absorbed circulation, and the sheet (P_SOL) by
 * the inverse matrix. */
static enum px_status ocl_sheet(struct px_vortex_engine *e, double vx, double vy,
                                struct px_buffer *absorbed, size_t nw) {
  struct px_vortex_ocl *d = e->dev;
  const struct px_vortex_panels *p = &e->pan;
  const struct px_vortex_config *c = &e->cfg;
  struct px_opencl_args a;
  size_t n = p->n;
  if (nw > 0) {
    PX_TRY(to_nb(e, nw));
    PX_TRY(px_nbody_direct(d->be, e->nb_prec, nw, d->w[W_NB_X], d->w[W_NB_Y], d->w[W_NB_G], 2 * n,
                           d->p[P_NB_GX], d->p[P_NB_GY], c->eps, PX_NBODY_MODE_SET, d->p[P_NB_GU],
                           d->p[P_NB_GV]));
  } else {
    PX_TRY(px_buffer_zero(d->p[P_NB_GU]));
    PX_TRY(px_buffer_zero(d->p[P_NB_GV]));
  }
  PX_TRY(begin(d, "vx_rhs", &a));
  px_opencl_args_u32(&a, "n", (uint32_t)n);
  px_opencl_args_u32(&a, "nbody", (uint32_t)p->nbody);
  px_opencl_args_mem(&a, "first", d->p[P_FIRST]);
  args_ends(&a, d, "x0", "y0", "x1", "y1");
  px_opencl_args_mem(&a, "tx", d->p[P_TX]);
  px_opencl_args_mem(&a, "ty", d->p[P_TY]);
  px_opencl_args_mem(&a, "len", d->p[P_LEN]);
  px_opencl_args_mem(&a, "gu", d->p[P_NB_GU]);
  px_opencl_args_mem(&a, "gv", d->p[P_NB_GV]);
  px_opencl_args_u32(&a, "nw", (uint32_t)nw);
  px_opencl_args_mem(&a, "x", d->w[W_X]);
  px_opencl_args_mem(&a, "y", d->w[W_Y]);
  px_opencl_args_mem(&a, "g", d->w[W_G]);
  px_opencl_args_real(&a, "eps", c->eps);
  px_opencl_args_real(&a, "vx", vx);
  px_opencl_args_real(&a, "vy", vy);
  px_opencl_args_real(&a, "gauss", 0.21132486540518711775); /* (1 - 1/sqrt 3)/2 */
  px_opencl_args_mem(&a, "through", absorbed);
  px_opencl_args_mem(&a, "rhs", d->p[P_RHS]);
  /* a work-group per panel and per body (VX_OCL_GROUP) */
  PX_TRY(px_opencl_args_launch(&a, p->nsys * VX_OCL_GROUP, VX_OCL_GROUP));
  PX_TRY(begin(d, "vx_solve", &a));
  px_opencl_args_u32(&a, "ns", (uint32_t)p->nsys);
  px_opencl_args_mem(&a, "ainv", d->p[P_AINV]);
  px_opencl_args_mem(&a, "rhs", d->p[P_RHS]);
  px_opencl_args_mem(&a, "sol", d->p[P_SOL]);
  return px_opencl_args_launch(&a, p->nsys * VX_OCL_GROUP, VX_OCL_GROUP); /* a group per row */
}

/* Block 1: the sheet for the wake's nw vortices, shed as newborn vortices
 * after them (their number into *nborn). absorbed: the circulation each panel
 * absorbed in the last step, which the sheet returns (P_ZERO: none). */
static enum px_status ocl_generation(struct px_vortex_engine *e, double vx, double vy,
                                     struct px_buffer *absorbed, size_t nw, size_t *nborn_out) {
  struct px_vortex_ocl *d = e->dev;
  const struct px_vortex_panels *p = &e->pan;
  const struct px_vortex_config *c = &e->cfg;
  struct px_opencl_args a;
  size_t n = p->n;
  *nborn_out = 0;
  if (n == 0) return PX_STATUS_OK;
  PX_TRY(ocl_sheet(e, vx, vy, absorbed, nw));
  PX_TRY(px_buffer_zero(d->p[P_FLAG]));
  PX_TRY(begin(d, "vx_shed_count", &a));
  px_opencl_args_u32(&a, "n", (uint32_t)n);
  px_opencl_args_mem(&a, "sol", d->p[P_SOL]);
  px_opencl_args_mem(&a, "len", d->p[P_LEN]);
  px_opencl_args_real(&a, "gmax", c->gamma_max);
  px_opencl_args_u32(&a, "vpp", (uint32_t)c->vortex_per_panel);
  px_opencl_args_real(&a, "limit", 1e3 * c->vref);
  px_opencl_args_mem(&a, "count", d->p[P_COUNT]);
  px_opencl_args_mem(&a, "bad", d->p[P_FLAG]);
  PX_TRY(px_opencl_args_launch(&a, n, 0));
  cl_uint bad[2] = {0, 0};
  PX_TRY(px_buffer_read(d->p[P_FLAG], 0, sizeof bad, bad));
  if (bad[0]) {
    PX_TRY(px_vortex_ocl_get_reals(e, d->p[P_SOL], e->sol, p->nsys));
    return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                           "step %ld: runaway vorticity generation: sheet intensity %g on panel "
                           "%u (more than 1000 v_ref, or not finite); the wake is unstable: "
                           "reduce dt or check eps, eps_col and gamma_max",
                           e->step, e->sol[bad[0] - 1], bad[0] - 1);
  }
  if (bad[1] && !e->cap_warned) { /* the sheet read back once a run, for the warning */
    PX_TRY(px_vortex_ocl_get_reals(e, d->p[P_SOL], e->sol, p->nsys));
    px_vortex_newborn_cap_warn(e, e->sol);
  }
  uint32_t total = 0;
  PX_TRY(px_opencl_scan_u32(d->be, d->p[P_COUNT], d->p[P_START], n, &total));
  PX_TRY(px_vortex_ocl_reserve(e, nw + total));
  PX_TRY(begin(d, "vx_shed", &a));
  px_opencl_args_u32(&a, "n", (uint32_t)n);
  px_opencl_args_u32(&a, "base", (uint32_t)nw);
  px_opencl_args_mem(&a, "start", d->p[P_START]);
  px_opencl_args_mem(&a, "count", d->p[P_COUNT]);
  px_opencl_args_mem(&a, "sol", d->p[P_SOL]);
  args_ends(&a, d, "x0", "y0", "x1", "y1");
  px_opencl_args_mem(&a, "tx", d->p[P_TX]);
  px_opencl_args_mem(&a, "ty", d->p[P_TY]);
  px_opencl_args_mem(&a, "len", d->p[P_LEN]);
  px_opencl_args_real(&a, "delta", c->delta);
  px_opencl_args_mem(&a, "x", d->w[W_X]);
  px_opencl_args_mem(&a, "y", d->w[W_Y]);
  px_opencl_args_mem(&a, "g", d->w[W_G]);
  px_opencl_args_mem(&a, "born", d->w[W_BORN]);
  PX_TRY(px_opencl_args_launch(&a, n, 0));
  *nborn_out = total;
  return PX_STATUS_OK;
}

/* Block 2 on the targets [lo, hi) of the nw vortices (ocl_convective). */
static enum px_status ocl_convective_part(struct px_vortex_engine *e, double vx, double vy,
                                          size_t nw, size_t nold, size_t nborn, size_t lo,
                                          size_t hi) {
  struct px_vortex_ocl *d = e->dev;
  const struct px_vortex_config *c = &e->cfg;
  struct px_opencl_args a;
  size_t n = e->pan.n;
  PX_TRY(to_nb(e, nw));
  if (lo == 0 && hi == nw) /* one rank: as it always was */
    PX_TRY(px_nbody_direct(d->be, e->nb_prec, nw, d->w[W_NB_X], d->w[W_NB_Y], d->w[W_NB_G], nold,
                           d->w[W_NB_X], d->w[W_NB_Y], c->eps, PX_NBODY_MODE_SET, d->w[W_NB_U],
                           d->w[W_NB_V]));
  else if (lo < nold) /* the old targets of the share; eps^2 as px_nbody_direct takes it */
    PX_TRY(px_nbody_cl_direct_range(d->be, e->nb_prec, nw, d->w[W_NB_X], d->w[W_NB_Y], d->w[W_NB_G],
                                    lo, hi < nold ? hi : nold, d->w[W_NB_X], d->w[W_NB_Y],
                                    c->eps * c->eps, PX_NBODY_MODE_SET, d->w[W_NB_U],
                                    d->w[W_NB_V]));
  PX_TRY(begin(d, "vx_convective", &a));
  px_opencl_args_u32(&a, "nw", (uint32_t)nw);
  px_opencl_args_u32(&a, "nold", (uint32_t)nold);
  px_opencl_args_mem(&a, "nu", d->w[W_NB_U]);
  px_opencl_args_mem(&a, "nv", d->w[W_NB_V]);
  px_opencl_args_mem(&a, "x", d->w[W_X]);
  px_opencl_args_mem(&a, "y", d->w[W_Y]);
  px_opencl_args_mem(&a, "g", d->w[W_G]);
  px_opencl_args_mem(&a, "born", d->w[W_BORN]);
  px_opencl_args_real(&a, "vx", vx);
  px_opencl_args_real(&a, "vy", vy);
  px_opencl_args_u32(&a, "n", (uint32_t)n);
  args_ends(&a, d, "x0", "y0", "x1", "y1");
  px_opencl_args_mem(&a, "tx", d->p[P_TX]);
  px_opencl_args_mem(&a, "ty", d->p[P_TY]);
  px_opencl_args_mem(&a, "len", d->p[P_LEN]);
  px_opencl_args_mem(&a, "sol", d->p[P_SOL]);
  px_opencl_args_mem(&a, "start", d->p[P_START]);
  px_opencl_args_mem(&a, "count", d->p[P_COUNT]);
  px_opencl_args_real(&a, "eps", c->eps);
  px_opencl_args_i32(&a, "exact", (c->sheet_exact && n > 0 && nborn > 0) ? 1 : 0);
  px_opencl_args_mem(&a, "u", d->w[W_U]);
  px_opencl_args_mem(&a, "v", d->w[W_V]);
  return px_opencl_args_launch_range(&a, lo, hi - lo, 0);
}

/* Block 2: convective velocities of the nw vortices, the last nborn of them
 * newborn (the first nold old). Over K ranks each rank's device computes its
 * contiguous share of the targets (a target's velocity does not depend on
 * the share: one work-item each), gathered into every rank's W_U, W_V. */
static enum px_status ocl_convective(struct px_vortex_engine *e, double vx, double vy, size_t nw,
                                     size_t nold, size_t nborn) {
  static const int uv[2] = {W_U, W_V};
  size_t lo, hi;
  if (nw == 0) return PX_STATUS_OK;
  px_vortex_ranks_share(e, nw, &lo, &hi);
  enum px_status st = ocl_convective_part(e, vx, vy, nw, nold, nborn, lo, hi);
  return px_vortex_ocl_gather(e, 0, st, nw, uv, 2);
}

/* Block 3 on the targets [lo, hi) of the nw vortices (ocl_diffusive). */
static enum px_status ocl_diffusive_part(struct px_vortex_engine *e, size_t nw, size_t nold,
                                         size_t lo, size_t hi) {
  struct px_vortex_ocl *d = e->dev;
  const struct px_vortex_panels *p = &e->pan;
  const struct px_vortex_config *c = &e->cfg;
  struct px_opencl_args a;
  size_t n = p->n;
  PX_TRY(begin(d, "vx_eps", &a));
  px_opencl_args_u32(&a, "nw", (uint32_t)nw);
  px_opencl_args_mem(&a, "x", d->w[W_X]);
  px_opencl_args_mem(&a, "y", d->w[W_Y]);
  px_opencl_args_real(&a, "emin", c->eps_min);
  px_opencl_args_mem(&a, "e", d->w[W_E]);
  PX_TRY(px_opencl_args_launch_range(&a, lo, hi - lo, 0));
  PX_TRY(begin(d, "vx_vvd", &a));
  px_opencl_args_u32(&a, "nw", (uint32_t)nw);
  px_opencl_args_mem(&a, "x", d->w[W_X]);
  px_opencl_args_mem(&a, "y", d->w[W_Y]);
  px_opencl_args_mem(&a, "g", d->w[W_G]);
  px_opencl_args_mem(&a, "e", d->w[W_E]);
  px_opencl_args_i32(&a, "self", c->self_in_i1);
  px_opencl_args_u32(&a, "n", (uint32_t)n);
  args_frame(&a, d);
  px_opencl_args_real(&a, "lmax", p->lmax);
  px_opencl_args_real(&a, "cut", c->cutoff);
  px_opencl_args_real(&a, "nu", c->nu);
  px_opencl_args_real(&a, "vcap", 1.5 * c->vref);
  px_opencl_args_mem(&a, "born", d->w[W_BORN]);
  px_opencl_args_u32(&a, "nold", (uint32_t)nold);
  px_opencl_args_real(&a, "w_born", n > 0 ? px_vortex_newborn_drift(c) : 0.0);
  px_opencl_args_i32(&a, "moments", c->vvd_moments);
  px_opencl_args_mem(&a, "wu", d->w[W_WU]);
  px_opencl_args_mem(&a, "wv", d->w[W_WV]);
  return px_opencl_args_launch_range(&a, lo, hi - lo, 0);
}

/* Block 3: eps* and the VVD diffusive velocities of the nw vortices (those
 * from nold on are the step's newborns). Over K ranks split as block 2: a
 * target's eps* and velocity need only its own eps* (vx_vvd), so the share's
 * three values are gathered once, at the end. */
static enum px_status ocl_diffusive(struct px_vortex_engine *e, size_t nw, size_t nold) {
  static const int ew[3] = {W_E, W_WU, W_WV};
  size_t lo, hi;
  px_vortex_ranks_share(e, nw, &lo, &hi);
  enum px_status st = ocl_diffusive_part(e, nw, nold, lo, hi);
  return px_vortex_ocl_gather(e, 1, st, nw, ew, 3);
}

/* Binds the step's positions, velocities and diffusive velocities: x, y, u,
 * v (and wu, wv when `diffusive`), under the kernels' names. */
static void args_motion(struct px_opencl_args *a, struct px_vortex_ocl *d, int diffusive) {
  px_opencl_args_mem(a, "x", d->w[W_X]);
  px_opencl_args_mem(a, "y", d->w[W_Y]);
  px_opencl_args_mem(a, "u", d->w[W_U]);
  px_opencl_args_mem(a, "v", d->w[W_V]);
  if (!diffusive) return;
  px_opencl_args_mem(a, "wu", d->w[W_WU]);
  px_opencl_args_mem(a, "wv", d->w[W_WV]);
}
/* Their first-stage copies in the second wake set: x1, y1, u1, v1 (and the
 * diffusive velocities wu1, wv1 in its circulation and eps* arrays). */
static void args_stage1(struct px_opencl_args *a, struct px_vortex_ocl *d, int diffusive) {
  if (diffusive) {
    px_opencl_args_mem(a, "wu1", d->w[W_G2]);
    px_opencl_args_mem(a, "wv1", d->w[W_E2]);
    return;
  }
  px_opencl_args_mem(a, "x1", d->w[W_X2]);
  px_opencl_args_mem(a, "y1", d->w[W_Y2]);
  px_opencl_args_mem(a, "u1", d->w[W_U2]);
  px_opencl_args_mem(a, "v1", d->w[W_V2]);
}

/* Block 5 with rk2 (vortex_cpu.c, heun): the step's positions and
 * velocities into the second wake set (free until the compaction; its
 * circulation and eps* arrays hold the diffusive velocities), the predictor
 * move, a second sheet shed after the nw vortices, the convective and
 * diffusive velocities of the predicted wake with it, then the mean
 * velocities at the step's positions; the first stage's sheet is restored.
 * nold: the first of the step's newborns. The second diffusive pass counts
 * in the diffusive block; the rest of the stage in the move's. */
static enum px_status ocl_heun(struct px_vortex_engine *e, size_t nw, size_t nold) {
  struct px_vortex_ocl *d = e->dev;
  const struct px_vortex_config *c = &e->cfg;
  struct px_backend *be = d->be;
  struct px_opencl_args a;
  PX_TRY(begin(d, "vx_rk2_predict", &a));
  px_opencl_args_u32(&a, "nw", (uint32_t)nw);
  args_motion(&a, d, 1);
  px_opencl_args_real(&a, "dt", c->dt);
  args_stage1(&a, d, 0);
  px_opencl_args_u32(&a, "n", (uint32_t)e->pan.n);
  args_ends(&a, d, "px0", "py0", "px1", "py1");
  args_boxes(&a, d, e->pan.nbody);
  args_stage1(&a, d, 1);
  PX_TRY(px_opencl_args_launch(&a, nw, 0));
  PX_TRY(px_buffer_copy(d->p[P_SOL1], 0, d->p[P_SOL], 0, px_buffer_bytes(d->p[P_SOL])));
  double vx, vy;
  px_vortex_vinf(c, e->time + c->dt, &vx, &vy);
  size_t nb2 = 0;
  PX_TRY(ocl_generation(e, vx, vy, d->p[P_ZERO], nw, &nb2));
  PX_TRY(ocl_convective(e, vx, vy, nw + nb2, nw, nb2));
  { /* W2: timed in the diffusive block (as on the cpu), not in the caller's */
    PX_TRY(px_backend_finish(be));
    double t0 = px_time_now();
    PX_TRY(ocl_diffusive(e, nw + nb2, nold));
    PX_TRY(px_backend_finish(be));
    double t = px_time_now() - t0;
    e->block_time[PX_VORTEX_BLOCK_DIFFUSIVE] += t;
    e->block_time[PX_VORTEX_BLOCK_MOVE] -= t;
  }
  PX_TRY(begin(d, "vx_rk2_correct", &a));
  px_opencl_args_u32(&a, "nw", (uint32_t)nw);
  args_motion(&a, d, 0);
  args_stage1(&a, d, 0);
  px_opencl_args_mem(&a, "wu", d->w[W_WU]);
  px_opencl_args_mem(&a, "wv", d->w[W_WV]);
  args_stage1(&a, d, 1);
  PX_TRY(px_opencl_args_launch(&a, nw, 0));
  return px_buffer_copy(d->p[P_SOL], 0, d->p[P_SOL1], 0, px_buffer_bytes(d->p[P_SOL]));
}

/* Block 4: the wall vorticity per panel and the loads per body of the nw
 * vortices (the newborn from nold on) into e->loads. */
static enum px_status ocl_loads(struct px_vortex_engine *e, size_t nw, size_t nold) {
  struct px_vortex_ocl *d = e->dev;
  const struct px_vortex_panels *p = &e->pan;
  const struct px_vortex_config *c = &e->cfg;
  struct px_opencl_args a;
  PX_TRY(begin(d, "vx_wall", &a));
  px_opencl_args_u32(&a, "n", (uint32_t)p->n);
  px_opencl_args_mem(&a, "start", d->p[P_START]);
  px_opencl_args_mem(&a, "count", d->p[P_COUNT]);
  px_opencl_args_u32(&a, "nold", (uint32_t)nold);
  px_opencl_args_mem(&a, "e", d->w[W_E]);
  px_opencl_args_real(&a, "emin", c->eps_min);
  args_frame(&a, d);
  px_opencl_args_u32(&a, "nw", (uint32_t)nw);
  px_opencl_args_mem(&a, "x", d->w[W_X]);
  px_opencl_args_mem(&a, "y", d->w[W_Y]);
  px_opencl_args_mem(&a, "g", d->w[W_G]);
  px_opencl_args_real(&a, "cut", c->cutoff);
  px_opencl_args_mem(&a, "pe", d->p[P_PE]);
  px_opencl_args_mem(&a, "omega", d->p[P_OMEGA]);
  /* a work-group per panel (vortex_kernel.h, VX_OCL_GROUP) */
  PX_TRY(px_opencl_args_launch(&a, p->n * VX_OCL_GROUP, VX_OCL_GROUP));
  PX_TRY(begin(d, "vx_loads", &a));
  px_opencl_args_u32(&a, "nbody", (uint32_t)p->nbody);
  px_opencl_args_mem(&a, "first", d->p[P_FIRST]);
  args_frame(&a, d);
  px_opencl_args_mem(&a, "sol", d->p[P_SOL]);
  px_opencl_args_mem(&a, "through", d->p[P_THROUGH]);
  px_opencl_args_mem(&a, "omega", d->p[P_OMEGA]);
  px_opencl_args_mem(&a, "center", d->p[P_CENTER]);
  px_opencl_args_real(&a, "rho", c->rho);
  px_opencl_args_real(&a, "nu", c->nu);
  px_opencl_args_u32(&a, "nw", (uint32_t)nw);
  px_opencl_args_mem(&a, "x", d->w[W_X]);
  px_opencl_args_mem(&a, "y", d->w[W_Y]);
  px_opencl_args_mem(&a, "g", d->w[W_G]);
  px_opencl_args_mem(&a, "wu", d->w[W_WU]);
  px_opencl_args_mem(&a, "wv", d->w[W_WV]);
  px_opencl_args_mem(&a, "out", d->p[P_OUT]);
  PX_TRY(px_opencl_args_launch(&a, p->nbody * VX_OCL_GROUP, VX_OCL_GROUP));
  double out[10 * PX_VORTEX_MAX_BODIES];
  PX_TRY(px_vortex_ocl_get_reals(e, d->p[P_OUT], out, 10 * p->nbody));
  double q = 0.5 * c->rho * c->vref * c->vref;
  for (size_t b = 0; b < p->nbody; ++b) {
    struct px_vortex_loads *L = &e->loads[b];
    double *o = out + 10 * b;
    L->fx_conv = L->fy_conv = 0.0; /* not computed on the device */
    L->fx_diff = o[7];
    L->fy_diff = o[8];
    L->fx_wall = o[3];
    L->fy_wall = o[4];
    if (!c->friction_wall) { /* the drift term is the friction (vortex_cpu.c, loads) */
      o[3] = o[7];
      o[4] = o[8];
      o[5] = o[9];
    }
    L->fx_fric = o[3];
    L->fy_fric = o[4];
    L->m_fric = o[5];
    L->fx = c->rho / c->dt * o[0] + o[3];
    L->fy = c->rho / c->dt * o[1] + o[4];
    L->m = c->rho / c->dt * o[2] + o[5];
    L->cx = L->fx / (q * c->ref_length[b]);
    L->cy = L->fy / (q * c->ref_length[b]);
    L->cm = L->m / (q * c->ref_length[b] * c->ref_length[b]);
    L->absorbed = o[6];
  }
  return PX_STATUS_OK;
}

/* Blocks 5, 6a: the move of the step's vortices (Euler, or Heun with rk2)
 * into W_XN, W_YN and the panel each one crossed into W_HIT. */
static enum px_status ocl_move(struct px_vortex_engine *e) {
  struct px_vortex_ocl *d = e->dev;
  const struct px_vortex_panels *p = &e->pan;
  const struct px_vortex_config *c = &e->cfg;
  struct px_opencl_args a;
  size_t nw = d->nw;
  if (nw == 0) return PX_STATUS_OK;
  if (c->rk2) PX_TRY(ocl_heun(e, nw, d->nold));
  PX_TRY(begin(d, "vx_move", &a));
  px_opencl_args_u32(&a, "nw", (uint32_t)nw);
  args_motion(&a, d, 1);
  px_opencl_args_real(&a, "dt", c->dt);
  px_opencl_args_u32(&a, "n", (uint32_t)p->n);
  args_ends(&a, d, "x0", "y0", "x1", "y1");
  args_boxes(&a, d, p->nbody);
  px_opencl_args_mem(&a, "xn", d->w[W_XN]);
  px_opencl_args_mem(&a, "yn", d->w[W_YN]);
  px_opencl_args_mem(&a, "hit", d->w[W_HIT]);
  return px_opencl_args_launch(&a, nw, 0);
}

/* Block 6b: the circulation each panel absorbed in the move (P_THROUGH). */
static enum px_status ocl_inside(struct px_vortex_engine *e) {
  struct px_vortex_ocl *d = e->dev;
  const struct px_vortex_panels *p = &e->pan;
  struct px_opencl_args a;
  size_t nw = d->nw;
  if (nw == 0 || p->n == 0) return PX_STATUS_OK;
  PX_TRY(begin(d, "vx_through", &a));
  px_opencl_args_u32(&a, "n", (uint32_t)p->n);
  px_opencl_args_u32(&a, "nw", (uint32_t)nw);
  px_opencl_args_mem(&a, "hit", d->w[W_HIT]);
  px_opencl_args_mem(&a, "g", d->w[W_G]);
  px_opencl_args_mem(&a, "through", d->p[P_THROUGH]);
  return px_opencl_args_launch(&a, p->n * VX_OCL_GROUP, VX_OCL_GROUP);
}

/* Block 7b: merge close pairs among the m survivors (partners chosen in
 * parallel, merges applied in order by one work-item down the list of
 * candidates), compact; the count left into *out. */
static enum px_status ocl_merge(struct px_vortex_engine *e, size_t m, size_t *out) {
  struct px_vortex_ocl *d = e->dev;
  const struct px_vortex_panels *p = &e->pan;
  const struct px_vortex_config *c = &e->cfg;
  struct px_opencl_args a;
  PX_TRY(begin(d, "vx_partner", &a));
  px_opencl_args_u32(&a, "nw", (uint32_t)m);
  px_opencl_args_mem(&a, "x", d->w[W_X]);
  px_opencl_args_mem(&a, "y", d->w[W_Y]);
  px_opencl_args_mem(&a, "g", d->w[W_G]);
  px_opencl_args_real(&a, "ec", c->eps_col);
  px_opencl_args_real(&a, "eo", c->eps_col_opposite);
  px_opencl_args_real(&a, "gmax", c->gamma_max);
  px_opencl_args_real(&a, "sdx", e->stream_dir[0]);
  px_opencl_args_real(&a, "sdy", e->stream_dir[1]);
  px_opencl_args_real(&a, "s_right", e->s_right);
  px_opencl_args_real(&a, "span", e->span > 0.0 ? e->span : 1.0);
  px_opencl_args_u32(&a, "n", (uint32_t)p->n);
  args_ends(&a, d, "x0", "y0", "x1", "y1");
  args_boxes(&a, d, p->nbody);
  px_opencl_args_mem(&a, "partner", d->w[W_PARTNER]);
  px_opencl_args_mem(&a, "mx", d->w[W_MX]);
  px_opencl_args_mem(&a, "my", d->w[W_MY]);
  PX_TRY(px_opencl_args_launch(&a, m, 0));
  PX_TRY(begin(d, "vx_merge", &a));
  px_opencl_args_u32(&a, "nw", (uint32_t)m);
  px_opencl_args_mem(&a, "partner", d->w[W_PARTNER]);
  px_opencl_args_mem(&a, "mx", d->w[W_MX]);
  px_opencl_args_mem(&a, "my", d->w[W_MY]);
  px_opencl_args_mem(&a, "x", d->w[W_X]);
  px_opencl_args_mem(&a, "y", d->w[W_Y]);
  px_opencl_args_mem(&a, "g", d->w[W_G]);
  px_opencl_args_mem(&a, "keep", d->w[W_KEEP]);
  px_opencl_args_mem(&a, "merged", d->p[P_FLAG]);
  px_opencl_args_mem(&a, "cand", d->w[W_POS]); /* scratch: compact's scan writes it after */
  PX_TRY(px_opencl_args_launch(&a, VX_OCL_MERGE, VX_OCL_MERGE));
  return compact(e, m, out);
}

/* Block 7: drop the absorbed, empty and far vortices among the nw moved ones,
 * merge close pairs, check the new state is finite; the wake's new count into
 * *out. */
static enum px_status ocl_restructure(struct px_vortex_engine *e, size_t nw, size_t *out) {
  struct px_vortex_ocl *d = e->dev;
  const struct px_vortex_config *c = &e->cfg;
  struct px_opencl_args a;
  size_t m = 0;
  PX_TRY(begin(d, "vx_keep", &a));
  px_opencl_args_u32(&a, "nw", (uint32_t)nw);
  px_opencl_args_mem(&a, "hit", d->w[W_HIT]);
  px_opencl_args_mem(&a, "g", d->w[W_G]);
  px_opencl_args_mem(&a, "xn", d->w[W_XN]);
  px_opencl_args_mem(&a, "yn", d->w[W_YN]);
  px_opencl_args_real(&a, "cx", e->center[0]);
  px_opencl_args_real(&a, "cy", e->center[1]);
  px_opencl_args_real(&a, "far2", c->dist_far * c->dist_far);
  px_opencl_args_mem(&a, "keep", d->w[W_KEEP]);
  PX_TRY(px_opencl_args_launch(&a, nw, 0));
  /* the moved positions become the positions of the compacted set */
  struct px_buffer *t;
  t = d->w[W_X];
  d->w[W_X] = d->w[W_XN];
  d->w[W_XN] = t;
  t = d->w[W_Y];
  d->w[W_Y] = d->w[W_YN];
  d->w[W_YN] = t;
  PX_TRY(compact(e, nw, &m));
  e->n_far = nw - m; /* absorbed ones included */
  if (m > 0) {
    size_t m2 = 0;
    PX_TRY(ocl_merge(e, m, &m2));
    e->n_merged = m - m2;
    m = m2;
  }
  /* non-finite check of the new state */
  PX_TRY(px_buffer_zero(d->p[P_FLAG]));
  *out = m;
  if (m == 0) return PX_STATUS_OK;
  PX_TRY(begin(d, "vx_finite", &a));
  px_opencl_args_u32(&a, "nw", (uint32_t)m);
  px_opencl_args_mem(&a, "a", d->w[W_X]);
  px_opencl_args_mem(&a, "b", d->w[W_Y]);
  px_opencl_args_mem(&a, "bad", d->p[P_FLAG]);
  PX_TRY(px_opencl_args_launch(&a, m, 0));
  cl_uint bad = 0;
  PX_TRY(px_buffer_read(d->p[P_FLAG], 0, sizeof bad, &bad));
  if (bad)
    return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                           "step %ld: vortex %u has a non-finite position after the move "
                           "(non-finite convective or diffusive velocity)",
                           e->step, bad - 1);
  return PX_STATUS_OK;
}

/* ---- the blocks of the step (vortex_engine.h) ----------------------------- */

static void ocl_caps(struct px_backend *be, struct px_vortex_caps *out) {
  out->fp64 = px_backend_has_fp64(be);
  out->fmm = 0; /* the direct sums on the device are its fast path */
  out->mixed = 1;
  out->ranks = 1; /* the direct sums split by targets (ocl_convective, ocl_diffusive) */
}

static enum px_status ocl_begin(struct px_vortex_engine *e) {
  struct px_vortex_ocl *d = e->dev;
  if (d->host_dirty) PX_TRY(px_vortex_ocl_upload(e));
  d->nw = d->nold = e->w.n;
  d->nborn = 0;
  return px_vortex_ocl_reserve(e, d->nw + 64 * e->pan.n + 1);
}

static enum px_status ocl_step_generation(struct px_vortex_engine *e, double vx, double vy) {
  struct px_vortex_ocl *d = e->dev;
  PX_TRY(ocl_generation(e, vx, vy, d->p[P_THROUGH], d->nw, &d->nborn));
  d->nold = d->nw;
  d->nw += d->nborn;
  e->n_born = d->nborn;
  return PX_STATUS_OK;
}

static enum px_status ocl_step_convective(struct px_vortex_engine *e, double vx, double vy) {
  struct px_vortex_ocl *d = e->dev;
  return ocl_convective(e, vx, vy, d->nw, d->nold, d->nborn);
}

static enum px_status ocl_step_diffusive(struct px_vortex_engine *e) {
  struct px_vortex_ocl *d = e->dev;
  return d->nw > 0 ? ocl_diffusive(e, d->nw, d->nold) : PX_STATUS_OK;
}

static enum px_status ocl_step_loads(struct px_vortex_engine *e) {
  struct px_vortex_ocl *d = e->dev;
  return e->pan.n > 0 ? ocl_loads(e, d->nw, d->nold) : PX_STATUS_OK;
}

static enum px_status ocl_step_restructure(struct px_vortex_engine *e) {
  struct px_vortex_ocl *d = e->dev;
  size_t m = 0;
  enum px_status st = d->nw > 0 ? ocl_restructure(e, d->nw, &m) : PX_STATUS_OK;
  if (st == PX_STATUS_OK) e->w.n = m;
  if (px_vortex_ranks_count(e) < 2) return st;
  /* the ranks' wakes compared (vortex_ranks.h) on the host copy: 3 m reals
   * read back per step */
  if (st == PX_STATUS_OK) st = px_vortex_ocl_sync(e);
  return px_vortex_ranks_verify(e, st);
}

static enum px_status ocl_finish(struct px_vortex_engine *e) {
  struct px_vortex_ocl *d = e->dev;
  return px_backend_finish(d->be);
}

const struct px_vortex_engine_i px_vortex_engine_opencl = {
    .backend = "opencl",
    .caps = ocl_caps,
    .create = px_vortex_ocl_create,
    .destroy = px_vortex_ocl_destroy,
    .begin = ocl_begin,
    .generation = ocl_step_generation,
    .convective = ocl_step_convective,
    .diffusive = ocl_step_diffusive,
    .loads = ocl_step_loads,
    .move = ocl_move,
    .inside = ocl_inside,
    .restructure = ocl_step_restructure,
    .finish = ocl_finish,
    .sync = px_vortex_ocl_sync,
    .host_changed = px_vortex_ocl_host_changed,
};
