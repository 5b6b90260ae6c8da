/* The vortex engine's driver (vortex_engine.h): the engine picked once by
 * the backend's name, the blocks of a step timed in order, the host copy of
 * the wake brought up to date for outputs, added vortices and velocities at
 * points. */
#include "solvers/vortex/vortex_engine.h"

#include "compute/backend_impl.h"
#include "nbody/nbody_impl.h"
#include "partix/timer.h"
#include "solvers/vortex/vortex_core_impl.h"
#include "solvers/vortex/vortex_ranks.h"

static const void *const px_vortex_engines[] = {&px_vortex_engine_cpu,
                                                PX_IF_OPENCL(&px_vortex_engine_opencl, )};

const struct px_vortex_engine_i *px_vortex_engine_pick(struct px_backend *be) {
  return (const struct px_vortex_engine_i *)PX_BACKEND_PICK(be, "vortex", px_vortex_engines);
}

enum px_status px_vortex_engine_caps(struct px_backend *be, struct px_vortex_caps *out) {
  const struct px_vortex_engine_i *ops = px_vortex_engine_pick(be);
  out->fp64 = out->fmm = out->mixed = out->ranks = 0;
  if (!ops) return px_context_status(px_backend_context(be));
  ops->caps(be, out);
  return PX_STATUS_OK;
}

enum px_status px_vortex_engine_create(struct px_context *ctx, struct px_backend *be,
                                       const struct px_vortex_config *cfg,
                                       const struct px_vortex_contour *bodies, size_t nbody,
                                       struct px_vortex_engine **out) {
  *out = NULL;
  if (!be) return px_context_fail(ctx, PX_STATUS_INVALID, "vortex engine: no backend");
  const struct px_vortex_engine_i *ops = px_vortex_engine_pick(be);
  if (!ops) return px_context_status(ctx);
  return px_vortex_engine_create_ops(ctx, be, ops, cfg, bodies, nbody, out);
}

enum px_status px_vortex_engine_create_ops(struct px_context *ctx, struct px_backend *be,
                                           const struct px_vortex_engine_i *ops,
                                           const struct px_vortex_config *cfg,
                                           const struct px_vortex_contour *bodies, size_t nbody,
                                           struct px_vortex_engine **out) {
  *out = NULL;
  if (!be) return px_context_fail(ctx, PX_STATUS_INVALID, "vortex engine: no backend");
  struct px_vortex_caps caps = {0};
  ops->caps(be, &caps);
  struct px_vortex_engine *e = NULL;
  enum px_status st = px_vortex_core_create(ctx, be, cfg, caps.fmm, bodies, nbody, &e);
  st = px_vortex_ranks_init(ctx, e, caps.fmm, st);
  if (st != PX_STATUS_OK) {
    px_vortex_engine_free(e);
    return st;
  }
  e->ops = ops;
  if (ops->create) {
    st = ops->create(e);
    if (st != PX_STATUS_OK) {
      px_vortex_engine_free(e);
      return st;
    }
  }
  *out = e;
  return PX_STATUS_OK;
}

void px_vortex_engine_free(struct px_vortex_engine *e) {
  if (!e) return;
  if (e->ops && e->ops->destroy) e->ops->destroy(e);
  px_vortex_core_free(e);
}

/* Block b of the step at free stream (vx, vy). */
static enum px_status run_block(struct px_vortex_engine *e, enum px_vortex_block b, double vx,
                                double vy) {
  const struct px_vortex_engine_i *ops = e->ops;
  switch (b) {
    case PX_VORTEX_BLOCK_GENERATION: return ops->generation(e, vx, vy);
    case PX_VORTEX_BLOCK_CONVECTIVE: return ops->convective(e, vx, vy);
    case PX_VORTEX_BLOCK_DIFFUSIVE: return ops->diffusive(e);
    case PX_VORTEX_BLOCK_LOADS: return ops->loads(e);
    case PX_VORTEX_BLOCK_MOVE: return ops->move(e);
    case PX_VORTEX_BLOCK_INSIDE: return ops->inside(e);
    case PX_VORTEX_BLOCK_RESTRUCT: return ops->restructure(e);
    case PX_VORTEX_BLOCK_COUNT_: break;
  }
  return PX_STATUS_OK;
}

enum px_status px_vortex_engine_step(struct px_vortex_engine *e) {
  const struct px_vortex_engine_i *ops = e->ops;
  double vx, vy;
  px_vortex_vinf(&e->cfg, e->time, &vx, &vy);
  e->last_vinf[0] = vx;
  e->last_vinf[1] = vy;
  if (e->tuner.most == 0) px_tuner_init(&e->tuner, e->ctx, "vortex", e->cfg.threads, e->cfg.tune);
  if (px_tuner_tuning(&e->tuner)) {
    /* the engine's loops and its pair sums (FMM, direct) alike */
    e->cfg.threads = px_tuner_begin(&e->tuner);
    if (e->nbe) px_nbody_set_threads(e->nbe, e->cfg.threads);
  }
  PX_TRY(ops->begin(e));
  for (int b = 0; b < PX_VORTEX_BLOCK_COUNT_; ++b) {
    double t0 = px_time_now(), c0 = px_vortex_cpu_seconds();
    PX_TRY(run_block(e, (enum px_vortex_block)b, vx, vy));
    if (ops->finish) PX_TRY(ops->finish(e));
    e->block_time[b] += px_time_now() - t0;
    e->block_cpu[b] += px_vortex_cpu_seconds() - c0;
  }
  if (px_tuner_tuning(&e->tuner)) px_tuner_end(&e->tuner, e->step);
  e->step++;
  e->time = (double)e->step * e->cfg.dt;
  return PX_STATUS_OK;
}

enum px_status px_vortex_engine_sync(struct px_vortex_engine *e) {
  return e->ops->sync ? e->ops->sync(e) : PX_STATUS_OK;
}

void px_vortex_engine_host_changed(struct px_vortex_engine *e) {
  if (e->ops->host_changed) e->ops->host_changed(e);
}

enum px_status px_vortex_engine_add(struct px_vortex_engine *e, size_t n, const double *x,
                                    const double *y, const double *g) {
  PX_TRY(px_vortex_engine_sync(e));
  px_vortex_engine_host_changed(e);
  PX_TRY(px_vortex_wake_reserve(e->ctx, &e->w, e->w.n + n));
  for (size_t i = 0; i < n; ++i) {
    size_t k = e->w.n + i;
    e->w.x[k] = x[i];
    e->w.y[k] = y[i];
    e->w.g[k] = g[i];
    e->w.u[k] = e->w.v[k] = e->w.wu[k] = e->w.wv[k] = 0.0;
    e->w.e[k] = 0.0;
    e->w.born[k] = -1;
  }
  e->w.n += n;
  return PX_STATUS_OK;
}

enum px_status px_vortex_engine_velocity(struct px_vortex_engine *e, size_t n, const double *x,
                                         const double *y, double *u, double *v) {
  double vx, vy;
  px_vortex_vinf(&e->cfg, e->time, &vx, &vy);
  PX_TRY(px_vortex_engine_sync(e));
  PX_TRY(px_vortex_core_velocity(e, n, x, y, u, v));
  for (size_t i = 0; i < n; ++i) {
    u[i] += vx;
    v[i] += vy;
  }
  return PX_STATUS_OK;
}
