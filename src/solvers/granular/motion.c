/* Prescribed rigid motion of boundary bodies. */
#include "solvers/granular/motion.h"

#include <math.h>
#include <string.h>

#include "partix/memory.h"
#include "solvers/granular/wall_kernel.h"

#define PX_GRAN_PI 3.14159265358979323846

void px_gran_motion_init(struct px_gran_motion *m) {
  memset(m, 0, sizeof *m);
  m->kind = PX_GRAN_MOTION_FIXED;
}

void px_gran_motion_free(struct px_context *ctx, struct px_gran_motion *m) {
  if (!m) return;
  px_mem_free(ctx, m->t);
  px_mem_free(ctx, m->x);
  px_mem_free(ctx, m->y);
  px_mem_free(ctx, m->r);
  m->t = m->x = m->y = m->r = NULL;
  m->n = 0;
}

enum px_status px_gran_motion_check(struct px_context *ctx, const struct px_gran_motion *m,
                                    const char *where) {
  size_t k;
  if (!(m->ramp >= 0) || !isfinite(m->start))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: start must be finite and ramp >= 0", where);
  if (m->kind == PX_GRAN_MOTION_HARMONIC) {
    for (k = 0; k < 3; ++k)
      if (!isfinite(m->amp[k]) || !(m->freq[k] >= 0) || !isfinite(m->phase[k]))
        return px_context_fail(ctx, PX_STATUS_CONFIG,
                               "%s: amplitude, frequency (>= 0) and phase must be finite", where);
  }
  if (m->kind == PX_GRAN_MOTION_TABLE) {
    if (m->n < 2)
      return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: a motion table needs at least 2 rows",
                             where);
    for (k = 0; k < m->n; ++k)
      if (!isfinite(m->t[k]) || !isfinite(m->x[k]) || !isfinite(m->y[k]) || !isfinite(m->r[k]))
        return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: table row %zu is not finite", where,
                               k + 1);
    for (k = 1; k < m->n; ++k)
      if (!(m->t[k] > m->t[k - 1]))
        return px_context_fail(ctx, PX_STATUS_CONFIG,
                               "%s: table times must increase (row %zu: t = %g after %g)", where,
                               k + 1, m->t[k], m->t[k - 1]);
    if (m->periodic &&
        (fabs(m->x[0] - m->x[m->n - 1]) > 1e-12 || fabs(m->y[0] - m->y[m->n - 1]) > 1e-12 ||
         fabs(m->r[0] - m->r[m->n - 1]) > 1e-12))
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "%s: a periodic table must end where it starts (first row = last "
                             "row)",
                             where);
  }
  return PX_STATUS_OK;
}

/* Catmull–Rom value and derivative of column v at time tau. */
static void px_gran_table(const struct px_gran_motion *m, const double *v, double tau, double *val,
                          double *der) {
  const size_t n = m->n;
  size_t k = 0, lo, hi;
  double h, u, m0, m1, h00, h10, h01, h11;
  double T = m->t[n - 1] - m->t[0];
  double t = tau + m->t[0];
  if (m->periodic) {
    t = m->t[0] + fmod(tau, T);
    if (t < m->t[0]) t += T;
  } else {
    if (t <= m->t[0]) {
      *val = v[0];
      *der = 0;
      return;
    }
    if (t >= m->t[n - 1]) {
      *val = v[n - 1];
      *der = 0;
      return;
    }
  }
  lo = 0;
  hi = n - 1;
  while (hi - lo > 1) { /* bisection: t[lo] <= t < t[hi] */
    size_t mid = (lo + hi) / 2;
    if (m->t[mid] <= t)
      lo = mid;
    else
      hi = mid;
  }
  k = lo;
  h = m->t[k + 1] - m->t[k];
  u = (t - m->t[k]) / h;
  /* tangents by centred differences (one-sided at the ends, wrapped when periodic) */
  if (k > 0)
    m0 = (v[k + 1] - v[k - 1]) / (m->t[k + 1] - m->t[k - 1]);
  else if (m->periodic)
    m0 = (v[1] - v[n - 2]) / (m->t[1] - m->t[0] + m->t[n - 1] - m->t[n - 2]);
  else
    m0 = (v[1] - v[0]) / (m->t[1] - m->t[0]);
  if (k + 2 < n)
    m1 = (v[k + 2] - v[k]) / (m->t[k + 2] - m->t[k]);
  else if (m->periodic)
    m1 = (v[1] - v[n - 2]) / (m->t[1] - m->t[0] + m->t[n - 1] - m->t[n - 2]);
  else
    m1 = (v[n - 1] - v[n - 2]) / (m->t[n - 1] - m->t[n - 2]);
  h00 = 2 * u * u * u - 3 * u * u + 1;
  h10 = u * u * u - 2 * u * u + u;
  h01 = -2 * u * u * u + 3 * u * u;
  h11 = u * u * u - u * u;
  *val = h00 * v[k] + h10 * h * m0 + h01 * v[k + 1] + h11 * h * m1;
  *der = ((6 * u * u - 6 * u) * v[k] + (3 * u * u - 4 * u + 1) * h * m0 +
          (-6 * u * u + 6 * u) * v[k + 1] + (3 * u * u - 2 * u) * h * m1) /
         h;
}

void px_gran_motion_eval(const struct px_gran_motion *m, double t, double d[2], double v[2],
                         double *phi, double *w) {
  double tau = t - m->start, s = 1, ds = 0, D[3] = {0, 0, 0}, V[3] = {0, 0, 0};
  int k;
  d[0] = d[1] = v[0] = v[1] = 0;
  *phi = *w = 0;
  if (m->kind == PX_GRAN_MOTION_FIXED || tau <= 0) return;
  if (m->ramp > 0 && tau < m->ramp) {
    s = 0.5 * (1 - cos(PX_GRAN_PI * tau / m->ramp));
    ds = 0.5 * PX_GRAN_PI / m->ramp * sin(PX_GRAN_PI * tau / m->ramp);
  }
  if (m->kind == PX_GRAN_MOTION_HARMONIC) {
    for (k = 0; k < 3; ++k) {
      const double om = 2 * PX_GRAN_PI * m->freq[k];
      D[k] = m->amp[k] * sin(om * tau + m->phase[k]);
      V[k] = m->amp[k] * om * cos(om * tau + m->phase[k]);
    }
  } else {
    px_gran_table(m, m->x, tau, &D[0], &V[0]);
    px_gran_table(m, m->y, tau, &D[1], &V[1]);
    px_gran_table(m, m->r, tau, &D[2], &V[2]);
  }
  d[0] = s * D[0];
  d[1] = s * D[1];
  *phi = s * D[2];
  v[0] = s * V[0] + ds * D[0];
  v[1] = s * V[1] + ds * D[1];
  *w = s * V[2] + ds * D[2];
}

void px_gran_motion_onset(const struct px_gran_motion *m, double d[2], double v[2], double *phi,
                          double *w) {
  double D[3] = {0, 0, 0}, V[3] = {0, 0, 0};
  int k;
  if (m->kind == PX_GRAN_MOTION_HARMONIC) {
    for (k = 0; k < 3; ++k) {
      D[k] = m->amp[k] * sin(m->phase[k]);
      V[k] = m->amp[k] * 2 * PX_GRAN_PI * m->freq[k] * cos(m->phase[k]);
    }
  } else if (m->kind == PX_GRAN_MOTION_TABLE && m->n >= 2) {
    /* the first row and the tangent px_gran_table takes on the first
     * interval at u = 0 (wrapped when periodic) */
    const double *col[3] = {m->x, m->y, m->r};
    const size_t n = m->n;
    for (k = 0; k < 3; ++k) {
      const double *c = col[k];
      D[k] = c[0];
      V[k] = m->periodic ? (c[1] - c[n - 2]) / (m->t[1] - m->t[0] + m->t[n - 1] - m->t[n - 2])
                         : (c[1] - c[0]) / (m->t[1] - m->t[0]);
    }
  }
  /* a ramp's envelope starts at 0 with slope 0: no jump */
  if (m->ramp > 0) D[0] = D[1] = D[2] = V[0] = V[1] = V[2] = 0;
  d[0] = D[0], d[1] = D[1], *phi = D[2];
  v[0] = V[0], v[1] = V[1], *w = V[2];
}

double px_gran_motion_max_speed(const struct px_gran_motion *m, double radius) {
  double T = 0, best = 0;
  int k;
  const int n = 4096;
  if (m->kind == PX_GRAN_MOTION_FIXED) return 0;
  if (m->kind == PX_GRAN_MOTION_HARMONIC) {
    double fmin = 0;
    for (k = 0; k < 3; ++k)
      if (m->freq[k] > 0 && (fmin == 0 || m->freq[k] < fmin)) fmin = m->freq[k];
    T = fmin > 0 ? 1 / fmin : 1;
  } else {
    T = m->t[m->n - 1] - m->t[0];
  }
  T += m->ramp;
  for (k = 0; k <= n; ++k) {
    double d[2], v[2], phi, w, sp;
    px_gran_motion_eval(m, m->start + T * k / n, d, v, &phi, &w);
    sp = hypot(v[0], v[1]) + fabs(w) * radius;
    if (sp > best) best = sp;
  }
  return best;
}

void px_gran_motion_frame(const struct px_gran_motion *m, double t, double *f) {
  double d[2], v[2], phi, w;
  px_gran_motion_eval(m, t, d, v, &phi, &w);
  f[PX_GRAN_CTR_COS] = cos(phi);
  f[PX_GRAN_CTR_SIN] = sin(phi);
  f[PX_GRAN_CTR_PX] = m->pivot[0];
  f[PX_GRAN_CTR_PY] = m->pivot[1];
  f[PX_GRAN_CTR_DX] = d[0];
  f[PX_GRAN_CTR_DY] = d[1];
  f[PX_GRAN_CTR_VX] = v[0];
  f[PX_GRAN_CTR_VY] = v[1];
  f[PX_GRAN_CTR_W] = w;
}
