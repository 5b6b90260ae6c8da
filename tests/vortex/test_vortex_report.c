/* What summary.json reports of a load history (vortex_report.h): the mean and
 * standard deviation against their closed forms, and the detection of a
 * periodic lift: a shedding-like signal (the Re = 100 cylinder's lift,
 * amplitude 0.33 at St 0.165, with step-to-step noise of 0.03) is found with
 * its frequency and amplitude; a settling transient, a noisy constant and a
 * window of two cycles are not reported as periodic. */
#include <math.h>
#include <stdio.h>

#include "px_test.h"
#include "solvers/vortex/vortex_report.h"

#define N_MAX 8000

/* Deterministic noise: a uniform LCG sum of 4 (about Gaussian), standard
 * deviation `sd`. */
static double noise(unsigned long long *state, double sd) {
  double s = 0.0;
  for (int k = 0; k < 4; ++k) {
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    s += (double)(*state >> 11) / 9007199254740992.0 - 0.5;
  }
  /* the sum of 4 uniforms on [-0.5, 0.5] has variance 4/12 */
  return sd * s / sqrt(4.0 / 12.0);
}

static void test_stats(void) {
  const double y[4] = {1.0, 2.0, 3.0, 4.0};
  double m, sd;
  px_vortex_report_stats(y, 4, &m, &sd);
  PX_CHECK_NEAR(m, 2.5, 1e-15);
  PX_CHECK_NEAR(sd, sqrt(1.25), 1e-15); /* population: sum (y - 2.5)^2 / 4 */
  px_vortex_report_stats(y, 0, &m, &sd);
  PX_CHECK(isnan(m) && isnan(sd));
}

static void test_shedding(struct px_context *ctx) {
  static double t[N_MAX], y[N_MAX];
  unsigned long long st = 12345;
  const double dt = 0.02, f = 0.165, a = 0.33;
  size_t n = 0;
  /* t = 75 .. 150 (the default window of a run to t = 150), phase off the
   * window's start */
  for (double tt = 75.0; tt <= 150.0 + 1e-9 && n < N_MAX; tt += dt, ++n) {
    t[n] = tt;
    y[n] = 0.01 + a * sin(2.0 * 3.14159265358979 * f * tt + 0.7) + noise(&st, 0.03);
  }
  struct px_vortex_oscillation o;
  PX_CHECK_OK(ctx, px_vortex_report_oscillation(ctx, t, y, n, &o));
  printf(
      "shedding: f %.5f (0.165), amplitude %.4f (0.33), %zu cycles, peak share %.3f, "
      "cycle spread %.3f\n",
      o.frequency, o.amplitude, o.cycles, o.peak_share, o.spread);
  PX_CHECK_MSG(o.periodic, "shedding not found (peak share %.3f, spread %.3f)", o.peak_share,
               o.spread);
  PX_CHECK_MSG(fabs(o.frequency - f) <= 0.005 * f, "frequency %.5f vs %.5f", o.frequency, f);
  /* the moving average over a twelfth of the period keeps 98.9% of the
   * fundamental; the noise left adds a little to (max - min) / 2 */
  PX_CHECK_MSG(fabs(o.amplitude - a) <= 0.03 * a, "amplitude %.4f vs %.4f", o.amplitude, a);
  PX_CHECK_MSG(o.cycles >= 10 && o.cycles <= 13, "%zu cycles in 75 time units at f = 0.165",
               o.cycles);
  /* a lower frequency (a ramped start's slow mode) is found as well */
  for (size_t i = 0; i < n; ++i)
    y[i] = 0.2 * cos(2.0 * 3.14159265358979 * 0.06 * t[i]) + noise(&st, 0.02);
  PX_CHECK_OK(ctx, px_vortex_report_oscillation(ctx, t, y, n, &o));
  PX_CHECK_MSG(o.periodic && fabs(o.frequency - 0.06) <= 0.005 * 0.06, "f = 0.06: %d %.5f",
               o.periodic, o.frequency);
}

static void test_not_periodic(struct px_context *ctx) {
  static double t[N_MAX], y[N_MAX];
  unsigned long long st = 777;
  struct px_vortex_oscillation o;
  size_t n = 2000;
  /* a settling lift (the NACA 0012 case after its start) with noise */
  for (size_t i = 0; i < n; ++i) {
    t[i] = 3.0 + 0.0015 * (double)i;
    y[i] = 0.29 + 0.05 * exp(-(t[i] - 3.0)) + noise(&st, 0.01);
  }
  PX_CHECK_OK(ctx, px_vortex_report_oscillation(ctx, t, y, n, &o));
  printf("settling: share %.3f\n", o.peak_share);
  PX_CHECK_MSG(!o.periodic, "a settling transient taken as periodic, f = %g", o.frequency);
  /* noise about a constant (the symmetric cylinder's lift before shedding) */
  for (size_t i = 0; i < n; ++i) y[i] = noise(&st, 0.01);
  PX_CHECK_OK(ctx, px_vortex_report_oscillation(ctx, t, y, n, &o));
  printf("noise: share %.3f\n", o.peak_share);
  PX_CHECK_MSG(!o.periodic, "noise taken as periodic (share %.3f)", o.peak_share);
  /* two cycles only */
  for (size_t i = 0; i < n; ++i) y[i] = sin(2.0 * 3.14159265358979 * 2.0 * (double)i / (double)n);
  PX_CHECK_OK(ctx, px_vortex_report_oscillation(ctx, t, y, n, &o));
  PX_CHECK_MSG(!o.periodic, "two cycles taken as a periodic signal");
  /* too few samples */
  PX_CHECK_OK(ctx, px_vortex_report_oscillation(ctx, t, y, 20, &o));
  PX_CHECK(!o.periodic);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  test_stats();
  test_shedding(ctx);
  test_not_periodic(ctx);
  px_context_free(ctx);
  return px_test_report("test_vortex_report");
}
