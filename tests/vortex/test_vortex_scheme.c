/* Time integration of the wake: a co-rotating pair of equal vortices (no
 * body, no diffusion to speak of) keeps its separation d exactly and turns at
 * omega = Gamma / (pi d^2). Explicit Euler spirals outwards (first order: d^2
 * grows by (Gamma dt / (pi d))^2 each step, which the engine must reproduce);
 * Heun's method (vortex.scheme: rk2) must be far closer and converge at
 * second order or better. */
#include <math.h>

#include "partix/backend.h"
#include "px_test.h"
#include "solvers/vortex/vortex_core.h"

#define PI 3.14159265358979323846

/* Relative error of the separation after one turn in `steps` steps. */
static double pair_error(struct px_context *ctx, int rk2, int steps) {
  const double G = 1.0, d = 1.0, period = 2.0 * PI / (G / (PI * d * d));
  struct px_vortex_config cfg;
  px_vortex_config_defaults(&cfg);
  cfg.nu = 1e-12;
  cfg.dt = period / steps;
  cfg.vref = 1.0;
  cfg.eps = 0.01;
  cfg.eps_col = 1e-6;
  cfg.eps_min = 0.01;
  cfg.gamma_max = 10.0;
  cfg.dist_far = 100.0;
  cfg.rk2 = rk2;
  cfg.threads = 1;
  cfg.precision = PX_PRECISION_DOUBLE;
  struct px_backend *be = NULL;
  struct px_vortex_engine *e = NULL;
  PX_CHECK_OK(ctx, px_backend_create(ctx, "cpu", 0, 1, &be));
  PX_CHECK_OK(ctx, px_vortex_engine_create(ctx, be, &cfg, NULL, 0, &e));
  if (!e) return 1e9;
  double x[2] = {-0.5 * d, 0.5 * d}, y[2] = {0.0, 0.0}, g[2] = {G, G};
  PX_CHECK_OK(ctx, px_vortex_engine_add(e, 2, x, y, g));
  for (int s = 0; s < steps; ++s) PX_CHECK_OK(ctx, px_vortex_engine_step(e));
  double err = 1e9;
  PX_CHECK(e->w.n == 2);
  if (e->w.n == 2) {
    err = fabs(hypot(e->w.x[1] - e->w.x[0], e->w.y[1] - e->w.y[0]) - d) / d;
    /* the pair's centre stays put */
    PX_CHECK(fabs(e->w.x[0] + e->w.x[1]) < 1e-9 && fabs(e->w.y[0] + e->w.y[1]) < 1e-9);
  }
  px_vortex_engine_free(e);
  px_backend_free(be);
  return err;
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  double eu1 = pair_error(ctx, 0, 100), eu2 = pair_error(ctx, 0, 200);
  double rk1 = pair_error(ctx, 1, 100), rk2 = pair_error(ctx, 1, 200);
  printf("separation error after one turn: Euler %.3e (100 steps) %.3e (200); "
         "Heun %.3e (100) %.3e (200)\n", eu1, eu2, rk1, rk2);
  /* Euler moves each vortex by v dt = Gamma dt / (2 pi d) across the line of
   * centres: d^2 grows by (Gamma dt / (pi d))^2 a step */
  for (int q = 0; q < 2; ++q) {
    int steps = q ? 200 : 100;
    double c = 2.0 * PI / steps, r = 1.0; /* Gamma dt / pi (dt = 2 pi^2 / steps), d^2 */
    for (int s = 0; s < steps; ++s) r += c * c / r;
    double expect = sqrt(r) - 1.0, got = q ? eu2 : eu1;
    PX_CHECK_MSG(fabs(got - expect) < 0.01 * expect, "Euler, %d steps: %.4e, expected %.4e",
                 steps, got, expect);
  }
  PX_CHECK_MSG(rk1 < 0.02 * eu1, "Heun %.3e against Euler %.3e", rk1, eu1);
  PX_CHECK_MSG(rk2 < 0.25 * rk1, "Heun is at least second order: %.3e -> %.3e", rk1, rk2);
  px_context_free(ctx);
  return px_test_report("test_vortex_scheme");
}
