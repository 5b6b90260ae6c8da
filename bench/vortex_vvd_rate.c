/* How fast the VVD diffuses, against the exact rate: a Lamb-Oseen vortex
 * sampled on a square lattice of spacing h is moved by its diffusive
 * velocities alone from t0 = 1 to t1 = 2 (nu = 0.005, sigma0 = sqrt(4 nu t0));
 * the circulation-weighted mean of r^2 grows as 4 nu t exactly, so
 *   nu_eff / nu = (<r^2>(t1) - <r^2>(t0)) / (4 nu (t1 - t0))
 * is the VVD's diffusion rate relative to the true one (1 is exact).
 *
 * Alongside, the discrete kernel moments behind it (docs/notes/vortex.md, "The
 * VVD's diffusion rate"): for a linear vorticity field the VVD estimate
 * I2 / (eps* I1) equals the true -grad(omega)/omega times
 *   m = M1 / (2 eps* M0),  M0 = sum_j exp(-r_j/eps*),  M1 = sum_j r_j exp(-r_j/eps*)
 * over the neighbours within the cutoff (plus 1 in M0 when the vortex itself
 * counts in I1); the continuum integrals give m = 1. Printed: its mean over
 * the vortices within sigma0 of the centre at t0.
 *
 *   vortex_vvd_rate [h/sigma0 ...]      (default 0.28 0.2 0.14 0.1 0.071)
 *
 * One JSON object per line and lattice spacing, for self_in_i1 = 0 (default)
 * and 1, and for vvd_moments: covariance (2; its moment_ratio is that of
 * eps*, which it does not use); dt = 0.02 (the rate does not depend on dt:
 * 0.005 gives the same to 0.3%). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "partix/backend.h"
#include "partix/context.h"
#include "partix/memory.h"
#include "solvers/vortex/vortex_core.h"
#include "vortex_bench.h"

#define PI 3.14159265358979323846

static double mean_r2(const struct px_vortex_wake *w) {
  double s = 0.0, g = 0.0;
  for (size_t i = 0; i < w->n; ++i) {
    s += w->g[i] * (w->x[i] * w->x[i] + w->y[i] * w->y[i]);
    g += w->g[i];
  }
  return s / g;
}

/* mean of M1 / (2 eps* M0) over the vortices within r0 of the origin
 * (brute force over the wake; eps* from the engine's last diffusive block) */
static double moment_ratio(const struct px_vortex_wake *w, double cut, int self, double r0) {
  double sum = 0.0;
  int cnt = 0;
  for (size_t i = 0; i < w->n; ++i) {
    if (hypot(w->x[i], w->y[i]) > r0) continue;
    double e = w->e[i], m0 = self ? 1.0 : 0.0, m1 = 0.0;
    for (size_t j = 0; j < w->n; ++j) {
      double r = hypot(w->x[j] - w->x[i], w->y[j] - w->y[i]);
      if (j == i || r > cut * e) continue;
      m0 += exp(-r / e);
      m1 += r * exp(-r / e);
    }
    sum += m1 / (2.0 * e * m0);
    ++cnt;
  }
  return cnt ? sum / cnt : NAN;
}

static int run(struct px_context *ctx, double hs, int self, int moments) {
  const double G = 1.0, nu = 0.005, t0 = 1.0, t1 = 2.0, dt = 0.02;
  const double s0 = sqrt(4.0 * nu * t0), h = hs * s0;
  struct px_backend *be = NULL;
  struct px_vortex_engine *e = vx_bench_vvd_engine(ctx, h, nu, dt, 0.0, self, moments, NULL, &be);
  if (!e) return 1;
  int m = (int)(5.0 / hs + 0.5); /* lattice to 5 sigma0 */
  size_t np = (size_t)(2 * m + 1) * (size_t)(2 * m + 1), k = 0;
  double *x = malloc(3 * np * sizeof(double)), *y = x + np, *g = y + np;
  if (!x) return 1;
  for (int i = -m; i <= m; ++i)
    for (int j = -m; j <= m; ++j) {
      double px = i * h, py = j * h;
      x[k] = px;
      y[k] = py;
      g[k] = G / (4.0 * PI * nu * t0) * exp(-(px * px + py * py) / (4.0 * nu * t0)) * h * h;
      ++k;
    }
  int rc = px_vortex_engine_add(e, np, x, y, g) != PX_STATUS_OK;
  double a = mean_r2(&e->w), ratio = NAN;
  int steps = (int)((t1 - t0) / dt + 0.5);
  for (int s = 0; !rc && s < steps; ++s) {
    rc = px_vortex_engine_diffusive(e, 1, 1.0) != PX_STATUS_OK;
    if (s == 0) ratio = moment_ratio(&e->w, e->cfg.cutoff, self, s0);
    for (size_t i = 0; !rc && i < e->w.n; ++i) {
      e->w.x[i] += e->w.wu[i] * dt;
      e->w.y[i] += e->w.wv[i] * dt;
    }
  }
  double b = mean_r2(&e->w);
  if (!rc)
    printf(
        "{\"bench\":\"vortex_vvd_rate\",\"h_over_sigma0\":%.4f,\"vortices\":%zu,"
        "\"self_in_i1\":%d,\"vvd_moments\":%d,\"nu_eff_over_nu\":%.4f,"
        "\"moment_ratio\":%.4f}\n",
        hs, np, self, moments, (b - a) / (4.0 * nu * (t1 - t0)), ratio);
  free(x);
  px_vortex_engine_free(e);
  px_backend_free(be);
  return rc;
}

int main(int argc, char **argv) {
  static const double def[] = {0.28, 0.2, 0.14, 0.1, 0.071};
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  int n = argc > 1 ? argc - 1 : 5, rc = 0;
  for (int q = 0; q < n && !rc; ++q) {
    double hs = argc > 1 ? atof(argv[q + 1]) : def[q];
    if (!(hs > 0.02 && hs < 1.0)) {
      fprintf(stderr, "vortex_vvd_rate: h/sigma0 must be in (0.02, 1) (got %s)\n", argv[q + 1]);
      return 2;
    }
    rc = run(ctx, hs, 0, PX_VORTEX_MOMENTS_NONE) || run(ctx, hs, 1, PX_VORTEX_MOMENTS_NONE) ||
         run(ctx, hs, 0, PX_VORTEX_MOMENTS_COVARIANCE);
  }
  px_context_free(ctx);
  return rc;
}
