/* Statistics of the load history for summary.json (vortex_report.h). */
#include "solvers/vortex/vortex_report.h"

#include <math.h>
#include <string.h>

#include "partix/memory.h"

#define VX_PI 3.14159265358979323846

void px_vortex_report_stats(const double *y, size_t n, double *mean, double *std) {
  if (n == 0) {
    *mean = *std = NAN;
    return;
  }
  double s = 0.0;
  for (size_t i = 0; i < n; ++i) s += y[i];
  double m = s / (double)n, v = 0.0;
  for (size_t i = 0; i < n; ++i) v += (y[i] - m) * (y[i] - m);
  *mean = m;
  *std = sqrt(v / (double)n);
}

/* Upward crossings of the level m by s[0..n) with hysteresis h: a crossing
 * (its time linearly interpolated) counts once the signal has been below
 * m - h since the last one and then rises above m + h. Returns the count; at
 * most cap stored in up[] (times) and at[] (the sample index after the
 * crossing). */
static size_t up_crossings(const double *t, const double *s, size_t n, double m, double h,
                           double *up, size_t *at, size_t cap) {
  size_t nc = 0;
  int armed = 0, have = 0;
  double tc = 0.0;
  size_t ic = 0;
  for (size_t i = 0; i < n; ++i) {
    if (s[i] < m - h) {
      armed = 1;
      have = 0;
    }
    if (armed && i > 0 && s[i - 1] < m && s[i] >= m) {
      double f = (m - s[i - 1]) / (s[i] - s[i - 1]);
      tc = t[i - 1] + f * (t[i] - t[i - 1]);
      ic = i;
      have = 1;
    }
    if (armed && have && s[i] > m + h) {
      if (nc < cap) {
        up[nc] = tc;
        at[nc] = ic;
      }
      ++nc;
      armed = have = 0;
    }
  }
  return nc;
}

enum px_status px_vortex_report_oscillation(struct px_context *ctx, const double *t,
                                            const double *y, size_t n,
                                            struct px_vortex_oscillation *out) {
  memset(out, 0, sizeof *out);
  if (n < 32 || !(t[n - 1] > t[0])) return PX_STATUS_OK;
  const double T = t[n - 1] - t[0];
  /* frequencies up to a quarter of the sampling rate, at most 4096 of them
   * (the cost is n K; a lift period is hundreds of steps) */
  const size_t K = n / 4 < 4096 ? n / 4 : 4096;
  double mean = 0.0, var = 0.0;
  for (size_t i = 0; i < n; ++i) mean += y[i];
  mean /= (double)n;
  for (size_t i = 0; i < n; ++i) var += (y[i] - mean) * (y[i] - mean);
  if (!(var > 0.0)) return PX_STATUS_OK;
  /* work: periodogram re/im (K + 2), smoothed signal, crossings */
  double *re = px_mem_calloc(ctx, "vortex.report", 2 * (K + 2) + 2 * n, sizeof(double));
  size_t *at = px_mem_alloc(ctx, "vortex.report", n * sizeof(size_t));
  if (!re || !at) {
    px_mem_free(ctx, re);
    px_mem_free(ctx, at);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for the lift analysis");
  }
  double *im = re + (K + 2), *sm = im + (K + 2), *up = sm + n;
  /* the DFT at f_k = k / T by the rotation exp(-2 pi i t_i / T)^k per sample
   * (no trigonometry inside the loop; rounding ~k eps, far below the
   * criteria's margins) */
  for (size_t i = 0; i < n; ++i) {
    double a = -2.0 * VX_PI * (t[i] - t[0]) / T, wr = cos(a), wi = sin(a);
    double zr = 1.0, zi = 0.0, d = y[i] - mean;
    for (size_t k = 1; k <= K + 1; ++k) {
      double nr = zr * wr - zi * wi;
      zi = zr * wi + zi * wr;
      zr = nr;
      re[k] += d * zr;
      im[k] += d * zi;
    }
  }
  size_t kp = 1;
  double pmax = -1.0;
  for (size_t k = 1; k <= K; ++k) {
    double p = re[k] * re[k] + im[k] * im[k];
    if (p > pmax) {
      pmax = p;
      kp = k;
    }
  }
  double band = 0.0;
  for (size_t k = kp - 1; k <= kp + 1; ++k)
    if (k >= 1) band += re[k] * re[k] + im[k] * im[k];
  /* Parseval: the one-sided bins of a real signal hold n var / 2 in all */
  out->peak_share = 2.0 * band / ((double)n * var);
  if (kp < 3 || out->peak_share < 0.5) goto done;
  {
    const double period = T / (double)kp;
    const double a0 = 2.0 * sqrt(pmax) / (double)n; /* the peak's amplitude */
    /* centred moving average over period / 12 (half-width in samples) */
    const double dts = T / (double)(n - 1);
    const double wd = period / 24.0 / dts + 0.5; /* NaN from a forged time column: n */
    size_t w = wd >= 0.0 && wd < (double)n ? (size_t)wd : n;
    for (size_t i = 0; i < n; ++i) {
      size_t lo = i > w ? i - w : 0, hi = i + w < n ? i + w : n - 1;
      double s = 0.0;
      for (size_t j = lo; j <= hi; ++j) s += y[j];
      sm[i] = s / (double)(hi - lo + 1);
    }
    size_t nc = up_crossings(t, sm, n, mean, 0.25 * a0, up, at, n);
    if (nc < 4) goto done;
    const double pm = (up[nc - 1] - up[0]) / (double)(nc - 1);
    double spread = 0.0, amp = 0.0;
    for (size_t c = 0; c + 1 < nc; ++c) {
      spread = fmax(spread, fabs((up[c + 1] - up[c]) - pm) / pm);
      double mx = -INFINITY, mn = INFINITY;
      for (size_t i = at[c]; i < at[c + 1]; ++i) {
        mx = fmax(mx, sm[i]);
        mn = fmin(mn, sm[i]);
      }
      amp += 0.5 * (mx - mn);
    }
    out->spread = spread;
    if (spread > 0.25) goto done;
    out->periodic = 1;
    out->cycles = nc - 1;
    out->frequency = 1.0 / pm;
    out->amplitude = amp / (double)(nc - 1);
  }
done:
  px_mem_free(ctx, re);
  px_mem_free(ctx, at);
  return PX_STATUS_OK;
}
