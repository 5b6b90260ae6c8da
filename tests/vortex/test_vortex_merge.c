/* Restructuring rules on pairs of vortices (no body, so no downstream growth;
 * dt and nu tiny, so nothing moves): same signs merge within eps_col when
 * |Gamma1 + Gamma2| < gamma_max, at the |Gamma|-weighted centre; opposite
 * signs within eps_col_opposite (default 2 eps_col), at the stronger one.
 * Both backends. */
#include <math.h>
#include <string.h>

#include "partix/backend.h"
#include "px_test.h"
#include "solvers/vortex/vortex_core.h"

struct pair_case {
  double d, g1, g2, gamma_max, eps_col_opposite;
  size_t n_after; /* 1: merged */
};

static void run_pair(struct px_context *ctx, const char *backend, const struct pair_case *pc) {
  struct px_backend *be = NULL;
  if (px_backend_create(ctx, backend, 0, 1, &be) != PX_STATUS_OK) {
    px_context_clear(ctx);
    printf("%s: no device, skipped\n", backend);
    return;
  }
  struct px_vortex_config cfg;
  px_vortex_config_defaults(&cfg);
  cfg.nu = 1e-12;
  cfg.dt = 1e-9;
  cfg.vref = 1.0;
  cfg.eps = 0.01;
  cfg.eps_col = 0.01;
  cfg.eps_col_opposite = pc->eps_col_opposite;
  cfg.eps_min = 0.01;
  cfg.gamma_max = pc->gamma_max;
  cfg.dist_far = 100.0;
  cfg.threads = 1;
  cfg.precision = PX_PRECISION_DOUBLE;
  struct px_vortex_engine *e = NULL;
  PX_CHECK_OK(ctx, px_vortex_engine_create(ctx, be, &cfg, NULL, 0, &e));
  if (!e) {
    px_backend_free(be);
    return;
  }
  double x[2] = {0.3, 0.3 + pc->d}, y[2] = {0.2, 0.2}, g[2] = {pc->g1, pc->g2};
  PX_CHECK_OK(ctx, px_vortex_engine_add(e, 2, x, y, g));
  PX_CHECK_OK(ctx, px_vortex_engine_step(e));
  PX_CHECK_OK(ctx, px_vortex_engine_sync(e));
  PX_CHECK_MSG(e->w.n == pc->n_after, "%s, d %g, Gamma %g %g: %zu vortices, expected %zu", backend,
               pc->d, pc->g1, pc->g2, e->w.n, pc->n_after);
  if (e->w.n == 1 && pc->n_after == 1) {
    double a1 = fabs(pc->g1), a2 = fabs(pc->g2);
    double xm =
        pc->g1 * pc->g2 > 0.0 ? (a1 * x[0] + a2 * x[1]) / (a1 + a2) : (a1 >= a2 ? x[0] : x[1]);
    PX_CHECK_MSG(fabs(e->w.g[0] - (pc->g1 + pc->g2)) < 1e-12, "%s: merged Gamma %g", backend,
                 e->w.g[0]);
    PX_CHECK_MSG(fabs(e->w.x[0] - xm) < 1e-7 && fabs(e->w.y[0] - 0.2) < 1e-7,
                 "%s: merged at (%g, %g), expected (%g, 0.2)", backend, e->w.x[0], e->w.y[0], xm);
  }
  px_vortex_engine_free(e);
  px_backend_free(be);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  const struct pair_case cases[] = {
      {0.008, 1e-3, 2e-3, 1.0, 0.0, 1},    /* same sign, inside eps_col */
      {0.012, 1e-3, 2e-3, 1.0, 0.0, 2},    /* same sign, outside eps_col */
      {0.008, 1e-3, 2e-3, 2.5e-3, 0.0, 2}, /* same sign, over gamma_max */
      {0.015, 1e-3, -2e-3, 1.0, 0.0, 1},   /* opposite, inside 2 eps_col (default) */
      {0.025, 1e-3, -2e-3, 1.0, 0.0, 2},   /* opposite, outside 2 eps_col */
      {0.015, 1e-3, -2e-3, 1.0, 0.01, 2},  /* opposite, outside eps_col_opposite = eps_col */
      {0.008, 1e-3, -2e-3, 1.0, 0.01, 1},  /* opposite, inside it */
  };
  const char *backends[] = {"cpu", "opencl"};
  for (int b = 0; b < 2; ++b) {
#ifndef PX_HAVE_OPENCL
    if (b == 1) break;
#endif
    for (size_t q = 0; q < sizeof cases / sizeof cases[0]; ++q)
      run_pair(ctx, backends[b], &cases[q]);
  }
  px_context_free(ctx);
  return px_test_report("test_vortex_merge");
}
