/* What a vortex run reports (summary.json): statistics of the load history
 * over a time window, and the detection of a periodic lift with its
 * frequency (Strouhal number). Plain arrays in, numbers out; the solver glue
 * (vortex.c) reads loads.csv back and adds the quantities. */
#ifndef PX_VORTEX_REPORT_H
#define PX_VORTEX_REPORT_H

#include <stddef.h>

#include "partix/context.h"
#include "partix/status.h"

/* Mean and population standard deviation of y[0..n) (NaN for n == 0). */
void px_vortex_report_stats(const double *y, size_t n, double *mean, double *std);

/* A periodic signal found by px_vortex_report_oscillation. */
struct px_vortex_oscillation {
  int periodic;      /* 1: the criteria below hold; the other fields are then set */
  double frequency;  /* cycles per unit of t over whole cycles [1/s] */
  double amplitude;  /* mean over the cycles of (max - min) / 2 of the smoothed signal */
  size_t cycles;     /* whole cycles between the first and the last upward crossing */
  double peak_share; /* share of the signal's variance in the three periodogram bins
                        around its peak (1 for a pure sine of whole cycles) */
  double spread;     /* largest deviation of one cycle's length from the mean [-] */
};

/* Whether y(t) (n samples, t increasing, nearly evenly spaced) oscillates
 * periodically about its mean, and at what frequency. Criteria, all needed:
 *  1. at least 32 samples;
 *  2. the periodogram |sum (y_i - mean) exp(-2 pi i f t_i)|^2 over
 *     f = k / (t_{n-1} - t_0), k = 1 .. min(n/4, 4096), peaks at k >= 3 (three periods
 *     or more in the window: a drift or a settling transient peaks at k = 1
 *     or 2), and the three bins around the peak hold at least half of the
 *     variance (a periodic signal; white noise spreads it over n/2 bins);
 *  3. the signal smoothed by a centred moving average over a twelfth of that
 *     period (which attenuates the fundamental by 1.1%: the step-to-step noise
 *     of the loads would cross the mean several times a period) crosses its
 *     mean upwards, with a hysteresis of a quarter of the periodogram's
 *     amplitude, at least 4 times (3 whole cycles), and no cycle's length
 *     differs from their mean by more than 25%.
 * Then the frequency is the number of whole cycles over the time between the
 * first and the last upward crossing (linearly interpolated), the amplitude
 * the mean of (max - min) / 2 of the smoothed signal over those cycles (the
 * same reading as bench/vortex_validate.sh cylinder100). Work space from ctx;
 * PX_STATUS_NOMEM when it fails. */
enum px_status px_vortex_report_oscillation(struct px_context *ctx, const double *t,
                                            const double *y, size_t n,
                                            struct px_vortex_oscillation *out);

#endif
