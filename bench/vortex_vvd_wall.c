/* The VVD next to a wall, against the continuum (docs/notes/vortex.md, "The VVD's
 * diffusion rate"). Two measurements on rows of vortices over a wall (a
 * circle with panels of length h, locally flat), one row per h, one vortex
 * per panel:
 *
 * 1. A uniform layer (omega = 1, 24 rows) must not diffuse: W = 0. The VVD
 *    gets it from the balance of the one-sided particle term I2 / (eps* I1)
 *    and the wall term I3 / I0 (the body's share of the kernel integral, in
 *    the continuum); with particles the two cancel only as far as the sums
 *    equal their integrals. Printed per row (the 12 next to the wall): the
 *    mean normal drift W_n / (nu / h), > 0 away from the wall, for the rows
 *    at (k + offset) h.
 * 2. The rate: a layer omega = exp(-y^2 / (4 nu t)) at t0 (sigma0 =
 *    sqrt(2 nu t0)) on a wall through which no vorticity flows (the wall
 *    term; no generation here) stays half of a Gaussian whose
 *    circulation-weighted <y^2> grows as 2 nu t; the vortices move by W
 *    alone from t0 to 1.5 t0. Printed: nu_eff / nu, on the wall (`wall`: 1)
 *    and for the same layer mirrored to y < 0 in free space (`wall`: 0, also
 *    with vvd_moments: wake and covariance), at sigma0 / h = 2, 4, 8.
 *
 *   vortex_vvd_wall [offset ...]          (default 0.5 0.25 0; ~50 s)
 *
 * One JSON object per line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "partix/backend.h"
#include "partix/context.h"
#include "partix/memory.h"
#include "solvers/vortex/vortex_core.h"
#include "solvers/vortex/vortex_profile.h"
#include "vortex_bench.h"

#define PI 3.14159265358979323846

/* Measurement 1 for rows at (k + off) h; R = 2, 800 panels. */
static int run(struct px_context *ctx, double off, int moments) {
  const double R = 2.0, nu = 0.01;
  const int n = 800, rows = 24, show = 12;
  const double h = 2.0 * R * sin(PI / n); /* panel length */
  struct px_vortex_contour c;
  if (px_vortex_profile_circle(ctx, R, (size_t)n, &c) != PX_STATUS_OK) return 1;
  struct px_backend *be = NULL;
  struct px_vortex_engine *e = vx_bench_vvd_engine(ctx, h, nu, 0.01, 0.05 * h, 0, moments, &c, &be);
  if (!e) {
    px_vortex_contour_free(ctx, &c);
    return 1;
  }
  size_t np = (size_t)n * (size_t)rows, k = 0;
  double *x = malloc(3 * np * sizeof(double)), *y = x + np, *g = y + np;
  if (!x) return 1;
  /* the panels' nodes are at angles 2 pi q / n; a vortex over each panel's
   * middle */
  for (int r = 0; r < rows; ++r)
    for (int q = 0; q < n; ++q) {
      double rad = R * cos(PI / n) + (r + off) * h, a = 2.0 * PI * (q + 0.5) / n;
      x[k] = rad * cos(a);
      y[k] = rad * sin(a);
      g[k] = h * rad * 2.0 * PI / n; /* omega = 1 times the vortex's area */
      ++k;
    }
  int rc = px_vortex_engine_add(e, np, x, y, g) != PX_STATUS_OK;
  if (!rc) rc = px_vortex_engine_diffusive(e, 1, 0.0) != PX_STATUS_OK;
  if (!rc) {
    printf("{\"bench\":\"vortex_vvd_wall\",\"offset\":%.3f,\"vvd_moments\":%d,\"rows\":[", off,
           moments);
    for (int r = 0; r < show; ++r) {
      double s = 0.0;
      for (int q = 0; q < n; ++q) {
        size_t i = (size_t)r * (size_t)n + (size_t)q;
        double rad = hypot(x[i], y[i]);
        s += (e->w.wu[i] * x[i] + e->w.wv[i] * y[i]) / rad;
      }
      printf("%s%.4f", r ? "," : "", s / n / (nu / h));
    }
    printf("]}\n");
  }
  free(x);
  px_vortex_engine_free(e);
  px_backend_free(be);
  px_vortex_contour_free(ctx, &c);
  return rc;
}

/* Measurement 2 at sigma0 = sh h, rows at (k + off) h: R = 8 (sigma0 / R <=
 * 2%), 50 steps of t0 / 100; free_space: the layer and its mirror image,
 * no body. */
static int rate(struct px_context *ctx, double sh, double off, int free_space, int moments) {
  const double R = 8.0, nu = 0.001;
  const int n = 3200;
  const double h = 2.0 * R * sin(PI / n), R0 = R * cos(PI / n);
  const double s0 = sh * h, t0 = s0 * s0 / (2.0 * nu), dt = t0 / 100.0;
  const int rows = (int)(5.0 * sh + 1.0), steps = 50;
  struct px_vortex_contour c;
  if (px_vortex_profile_circle(ctx, R, (size_t)n, &c) != PX_STATUS_OK) return 1;
  struct px_backend *be = NULL;
  struct px_vortex_engine *e =
      vx_bench_vvd_engine(ctx, h, nu, dt, 0.05 * h, 0, moments, free_space ? NULL : &c, &be);
  if (!e) {
    px_vortex_contour_free(ctx, &c);
    return 1;
  }
  size_t nr = free_space ? 2 * (size_t)rows : (size_t)rows;
  size_t np = (size_t)n * nr, k = 0;
  double *x = malloc(3 * np * sizeof(double)), *y = x + np, *g = y + np;
  if (!x) return 1;
  for (size_t r = 0; r < nr; ++r)
    for (int q = 0; q < n; ++q) {
      double yk = (r < (size_t)rows ? 1.0 : -1.0) * ((double)(r % (size_t)rows) + off) * h;
      double rad = R0 + yk, a = 2.0 * PI * (q + 0.5) / n;
      x[k] = rad * cos(a);
      y[k] = rad * sin(a);
      g[k] = exp(-yk * yk / (4.0 * nu * t0)) * h * rad * 2.0 * PI / n;
      ++k;
    }
  int rc = px_vortex_engine_add(e, np, x, y, g) != PX_STATUS_OK;
  double a0 = 0.0, a1 = 0.0;
  for (int s = 0; !rc && s <= steps; ++s) {
    double sy = 0.0, sg = 0.0;
    for (size_t i = 0; i < e->w.n; ++i) {
      double d = hypot(e->w.x[i], e->w.y[i]) - R0;
      sy += e->w.g[i] * d * d;
      sg += e->w.g[i];
    }
    if (s == 0) a0 = sy / sg;
    if (s == steps) {
      a1 = sy / sg;
      break;
    }
    rc = px_vortex_engine_diffusive(e, 1, 0.0) != PX_STATUS_OK;
    for (size_t i = 0; !rc && i < e->w.n; ++i) {
      e->w.x[i] += e->w.wu[i] * dt;
      e->w.y[i] += e->w.wv[i] * dt;
    }
  }
  if (!rc)
    printf(
        "{\"bench\":\"vortex_vvd_wall\",\"sigma0_over_h\":%.2f,\"offset\":%.2f,"
        "\"wall\":%d,\"vvd_moments\":%d,\"vortices\":%zu,\"nu_eff_over_nu\":%.4f}\n",
        sh, off, !free_space, moments, np, (a1 - a0) / (2.0 * nu * steps * dt));
  free(x);
  px_vortex_engine_free(e);
  px_backend_free(be);
  px_vortex_contour_free(ctx, &c);
  return rc;
}

int main(int argc, char **argv) {
  static const double def[] = {0.5, 0.25, 0.0};
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  int n = argc > 1 ? argc - 1 : 3, rc = 0;
  for (int q = 0; q < n && !rc; ++q) {
    double off = argc > 1 ? atof(argv[q + 1]) : def[q];
    if (!(off >= 0.0 && off <= 1.0)) {
      fprintf(stderr, "vortex_vvd_wall: offset must be in [0, 1] (got %s)\n", argv[q + 1]);
      return 2;
    }
    rc = run(ctx, off, 0);
  }
  static const double sh[] = {2.0, 4.0, 8.0};
  for (int q = 0; q < 3 && !rc; ++q)
    rc = rate(ctx, sh[q], 0.5, 1, PX_VORTEX_MOMENTS_NONE) ||
         rate(ctx, sh[q], 0.5, 1, PX_VORTEX_MOMENTS_WAKE) ||
         rate(ctx, sh[q], 0.5, 1, PX_VORTEX_MOMENTS_COVARIANCE) ||
         rate(ctx, sh[q], 0.5, 0, PX_VORTEX_MOMENTS_NONE) ||
         rate(ctx, sh[q], 0.0, 0, PX_VORTEX_MOMENTS_NONE);
  px_context_free(ctx);
  return rc;
}
