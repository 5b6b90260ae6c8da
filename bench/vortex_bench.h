/* Setup shared by the VVD benchmarks (vortex_vvd_rate, vortex_vvd_wall). */
#ifndef PX_VORTEX_BENCH_H
#define PX_VORTEX_BENCH_H

#include "partix/backend.h"
#include "partix/context.h"
#include "solvers/vortex/vortex_core.h"

/* A cpu engine (2 threads, double precision) for vortices on a lattice of
 * spacing h moved by their diffusive velocities: eps = h, eps_col = h / 4,
 * gamma_max = 1; eps_min > 0 replaces the default; body: a wall, or NULL.
 * NULL on failure (the context has the message); *be to free after the
 * engine. */
static inline struct px_vortex_engine *vx_bench_vvd_engine(struct px_context *ctx, double h,
                                                           double nu, double dt, double eps_min,
                                                           int self, int moments,
                                                           const struct px_vortex_contour *body,
                                                           struct px_backend **be) {
  struct px_vortex_config cfg;
  px_vortex_config_defaults(&cfg);
  cfg.nu = nu;
  cfg.dt = dt;
  cfg.vref = 1.0;
  cfg.eps = h;
  cfg.eps_col = 0.25 * h;
  cfg.gamma_max = 1.0;
  if (eps_min > 0.0) cfg.eps_min = eps_min;
  cfg.self_in_i1 = self;
  cfg.vvd_moments = moments;
  cfg.threads = 2;
  cfg.precision = PX_PRECISION_DOUBLE;
  struct px_vortex_engine *e = NULL;
  *be = NULL;
  if (px_backend_create(ctx, "cpu", 0, 2, be) != PX_STATUS_OK) return NULL;
  if (px_vortex_engine_create(ctx, *be, &cfg, body, body ? 1 : 0, &e) != PX_STATUS_OK) {
    px_backend_free(*be);
    *be = NULL;
    return NULL;
  }
  return e;
}

#endif
