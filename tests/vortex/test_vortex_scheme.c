/* Time integration of the wake: a co-rotating pair of equal vortices (no
 * body, no diffusion to speak of) keeps its separation d exactly and turns at
 * omega = Gamma / (pi d^2). Explicit Euler spirals outwards (first order: d^2
 * grows by (Gamma dt / (pi d))^2 each step, which the engine must reproduce);
 * Heun's method (vortex.scheme: rk2) must be far closer and converge at
 * second order or better. And the diffusion: a Lamb-Oseen vortex spreads
 * self-similarly (a vortex at r moves by W = r / (2 t)), which Euler's step
 * overshoots at first order and Heun's (both stages' VVD velocities) must
 * follow at second order. */
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

/* The Lamb-Oseen vortex (Gamma 1e-3: convection negligible, the VVD does
 * not depend on Gamma) on a lattice of spacing sigma0 / 5 at t0 = 1 (nu =
 * 0.005, sigma0^2 = 4 nu t0), moved in `steps` steps to t0 + 1: the
 * circulation-weighted <r^2> grows as 4 nu t exactly; returns
 * delta<r^2> / (4 nu). */
enum { SPREAD_M = 25, SPREAD_N = (2 * SPREAD_M + 1) * (2 * SPREAD_M + 1) }; /* to 5 sigma0 */

static double spread_rate(struct px_context *ctx, int rk2, int steps) {
  const double G = 1e-3, nu = 0.005, s0 = sqrt(4.0 * nu), h = s0 / 5.0;
  const int m = SPREAD_M;
  struct px_vortex_config cfg;
  px_vortex_config_defaults(&cfg);
  cfg.nu = nu;
  cfg.dt = 1.0 / steps;
  cfg.vref = 1.0;
  cfg.eps = h;
  cfg.eps_col = 1e-6 * h;
  cfg.gamma_max = 1.0;
  cfg.rk2 = rk2;
  cfg.threads = 2;
  cfg.precision = PX_PRECISION_DOUBLE;
  cfg.method = PX_NBODY_METHOD_DIRECT;
  struct px_backend *be = NULL;
  struct px_vortex_engine *e = NULL;
  PX_CHECK_OK(ctx, px_backend_create(ctx, "cpu", 0, 2, &be));
  PX_CHECK_OK(ctx, px_vortex_engine_create(ctx, be, &cfg, NULL, 0, &e));
  if (!e) return 0.0;
  double x[SPREAD_N], y[SPREAD_N], g[SPREAD_N];
  size_t k = 0;
  for (int i = -m; i <= m; ++i)
    for (int j = -m; j <= m; ++j, ++k) {
      x[k] = i * h;
      y[k] = j * h;
      g[k] = G / (4.0 * PI * nu) * exp(-(x[k] * x[k] + y[k] * y[k]) / (4.0 * nu)) * h * h;
    }
  PX_CHECK_OK(ctx, px_vortex_engine_add(e, SPREAD_N, x, y, g));
  double r2[2];
  for (int q = 0; q < 2; ++q) {
    if (q) /* t0 -> t0 + 1 */
      for (int s = 0; s < steps; ++s) PX_CHECK_OK(ctx, px_vortex_engine_step(e));
    double sr = 0.0, sg = 0.0, cx = 0.0, cy = 0.0;
    for (size_t i = 0; i < e->w.n; ++i) {
      cx += e->w.g[i] * e->w.x[i];
      cy += e->w.g[i] * e->w.y[i];
      sg += e->w.g[i];
    }
    cx /= sg;
    cy /= sg;
    for (size_t i = 0; i < e->w.n; ++i) {
      double dx = e->w.x[i] - cx, dy = e->w.y[i] - cy;
      sr += e->w.g[i] * (dx * dx + dy * dy);
    }
    r2[q] = sr / sg;
  }
  px_vortex_engine_free(e);
  px_backend_free(be);
  return (r2[1] - r2[0]) / (4.0 * nu);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  double eu1 = pair_error(ctx, 0, 100), eu2 = pair_error(ctx, 0, 200);
  double rk1 = pair_error(ctx, 1, 100), rk2 = pair_error(ctx, 1, 200);
  printf(
      "separation error after one turn: Euler %.3e (100 steps) %.3e (200); "
      "Heun %.3e (100) %.3e (200)\n",
      eu1, eu2, rk1, rk2);
  /* Euler moves each vortex by v dt = Gamma dt / (2 pi d) across the line of
   * centres: d^2 grows by (Gamma dt / (pi d))^2 a step */
  for (int q = 0; q < 2; ++q) {
    int steps = q ? 200 : 100;
    double c = 2.0 * PI / steps, r = 1.0; /* Gamma dt / pi (dt = 2 pi^2 / steps), d^2 */
    for (int s = 0; s < steps; ++s) r += c * c / r;
    double expect = sqrt(r) - 1.0, got = q ? eu2 : eu1;
    PX_CHECK_MSG(fabs(got - expect) < 0.01 * expect, "Euler, %d steps: %.4e, expected %.4e", steps,
                 got, expect);
  }
  PX_CHECK_MSG(rk1 < 0.02 * eu1, "Heun %.3e against Euler %.3e", rk1, eu1);
  PX_CHECK_MSG(rk2 < 0.25 * rk1, "Heun is at least second order: %.3e -> %.3e", rk1, rk2);
  /* the spreading rate at dt = 1/4, 1/8, 1/16: successive differences halve
   * (first order) with Euler, quarter (second order) with Heun */
  double re[3], rh[3];
  for (int q = 0; q < 3; ++q) {
    re[q] = spread_rate(ctx, 0, 4 << q);
    rh[q] = spread_rate(ctx, 1, 4 << q);
  }
  printf(
      "spreading rate nu_eff / nu at dt = 1/4, 1/8, 1/16: Euler %.5f %.5f %.5f, "
      "Heun %.5f %.5f %.5f\n",
      re[0], re[1], re[2], rh[0], rh[1], rh[2]);
  double qe = (re[0] - re[1]) / (re[1] - re[2]), qh = (rh[0] - rh[1]) / (rh[1] - rh[2]);
  printf("difference ratios: Euler %.2f (first order: 2), Heun %.2f (second order: 4)\n", qe, qh);
  PX_CHECK_MSG(qe > 1.6 && qe < 2.6, "Euler's diffusion is first order: ratio %.3g", qe);
  PX_CHECK_MSG(qh > 3.2, "Heun's diffusion is second order: ratio %.3g", qh);
  PX_CHECK_MSG(fabs(rh[0] - rh[2]) < 0.2 * fabs(re[0] - re[2]),
               "Heun's error at dt = 1/4 is a fraction of Euler's: %.3g against %.3g",
               rh[0] - rh[2], re[0] - re[2]);
  px_context_free(ctx);
  return px_test_report("test_vortex_scheme");
}
