/* Wall terms of the VVD on the cpu: the sums of vx_panel_wall over the panels
 * near one vortex, vectorized across panels and quadrature points.
 *
 * vx_panel_wall integrates one panel at a time: an atan2 and, per side of the
 * foot, m sub-intervals of 4-point Gauss-Legendre, each point an exponential.
 * Called per panel, nothing vectorizes (m varies, the loops are short) and the
 * libm atan2 is scalar; near a body this was a quarter of the step. Here the
 * same sub-intervals are first listed (scalar: centre, half length, and the
 * point's abscissa, height, weight and panel normal), their quadrature
 * points expanded in one vector loop and evaluated in another, and the
 * subtended angles by a branch-free atan2 (vortex_kernel.h's vx_atan2) in a third. The points,
 * weights and formulas are vx_panel_wall's: the sums agree with it to rounding
 * (tests/vortex/test_vortex_vvd.c checks both, and vx_atan2 against atan2). */
#include "solvers/vortex/vortex_core.h"

#include <math.h>

#define PX_REAL double
#include "solvers/vortex/vortex_kernel.h"

double px_vortex_atan2(double y, double x) { return vx_atan2(y, x); }

enum { WALL_PTS = 512, WALL_INT = WALL_PTS / 4, WALL_PAN = 128 };

/* Listed sub-intervals (a chunk: flushed into the sums when full, their 4
 * points each expanded first), panels, and the sums so far. */
struct wall_chunk {
  double du[WALL_PTS], h[WALL_PTS], w[WALL_PTS], nx[WALL_PTS], ny[WALL_PTS], rho[WALL_PTS];
  /* each sub-interval: its centre and half length, the point's abscissa and
   * height, the weight and the direction of its panel */
  double icq[WALL_INT], ihl[WALL_INT], is[WALL_INT], ih[WALL_INT], iw[WALL_INT];
  double inx[WALL_INT], iny[WALL_INT];
  double ay[WALL_PAN], ax[WALL_PAN];
  int ni, nk;
  int s3_only; /* the S3 sums only (no S0: no g1, no angles) */
  double inv_e, i3x, i3y, s0;
};

/* The 4 Gauss-Legendre points of each listed sub-interval, in one loop over
 * them: listed point by point, their 5 stores each and the loop's branches
 * cost more than their sums (the same values, in the same order) */
static int wall_expand(struct wall_chunk *c) {
  const double xg0 = 0.3399810435848563, xg1 = 0.8611363115940526;
  const double wg0 = 0.6521451548625461, wg1 = 0.3478548451374538;
  double *restrict du = c->du, *restrict hh = c->h, *restrict w = c->w;
  double *restrict nx = c->nx, *restrict ny = c->ny;
  const double *restrict cq = c->icq, *restrict hl = c->ihl, *restrict s = c->is;
  const double *restrict ih = c->ih, *restrict iw = c->iw, *restrict inx = c->inx,
                         *restrict iny = c->iny;
  const int ni = c->ni;
#pragma omp simd
  for (int i = 0; i < ni; ++i) {
    const double q = cq[i], l = hl[i], si = s[i], wi = iw[i];
    du[4 * i] = (q - xg1 * l) - si;
    du[4 * i + 1] = (q - xg0 * l) - si;
    du[4 * i + 2] = (q + xg0 * l) - si;
    du[4 * i + 3] = (q + xg1 * l) - si;
    w[4 * i] = wi * (wg1 * l);
    w[4 * i + 1] = wi * (wg0 * l);
    w[4 * i + 2] = wi * (wg0 * l);
    w[4 * i + 3] = wi * (wg1 * l);
    for (int j = 0; j < 4; ++j) {
      hh[4 * i + j] = ih[i];
      nx[4 * i + j] = inx[i];
      ny[4 * i + j] = iny[i];
    }
  }
  c->ni = 0;
  return 4 * ni;
}

static void wall_flush_points(struct wall_chunk *c) {
  const int np = wall_expand(c);
  double sx = 0.0, sy = 0.0, r0 = 0.0, inv_e = c->inv_e;
  const double *hh = c->h, *w = c->w, *nx = c->nx, *ny = c->ny, *rho = c->rho;
  /* the points' distances first (an estimate and Newton steps, not a square
   * root per point: px_vortex_radii) */
  px_vortex_radii(c->du, hh, (size_t)np, 0.0, c->rho, NULL);
  if (c->s3_only) {
#pragma omp simd reduction(+ : sx)
    for (int q = 0; q < np; ++q) sx += w[q] * vx_exp_neg(rho[q] * inv_e);
  } else {
#pragma omp simd reduction(+ : sx, sy, r0)
    for (int q = 0; q < np; ++q) {
      double x = rho[q] * inv_e;
      double ex = vx_exp_neg(x);
      double we = w[q] * ex;
      sx += nx[q] * we;
      sy += ny[q] * we;
      r0 += hh[q] * w[q] * vx_g1_ex(x, ex);
    }
  }
  c->i3x += sx;
  c->i3y += sy;
  c->s0 += r0 * inv_e * inv_e;
}

static void wall_flush_angles(struct wall_chunk *c) {
  double sa = 0.0;
  const double *ay = c->ay, *ax = c->ax;
#pragma omp simd reduction(+ : sa)
  for (int k = 0; k < c->nk; ++k) sa += vx_atan2(ay[k], ax[k]);
  c->s0 += sa;
  c->nk = 0;
}

/* List the quadrature points of vx_panel_wall for a point at abscissa s and
 * height h off a panel of length L (weights times wgt, direction (nx, ny))
 * and, unless s3_only, the arguments of its subtended angle. Always inlined:
 * as a call per panel it cost 1.5% of the diffusive block. */
static inline __attribute__((always_inline)) void wall_panel(struct wall_chunk *c, double s,
                                                             double h, double L, double e,
                                                             double cut, double wgt, double nx,
                                                             double ny) {
  double ta = s - cut * e, tb = s + cut * e;
  if (ta < 0) ta = 0;
  if (tb > L) tb = L;
  if (!(ta < tb)) return;
  h = vx_wall_height(h, s, L);
  if (!c->s3_only) {
    if (c->nk == WALL_PAN) wall_flush_angles(c);
    c->ay[c->nk] = h * (tb - ta);
    c->ax[c->nk] = h * h + (ta - s) * (tb - s);
    ++c->nk;
  }
  double foot = s < ta ? ta : (s > tb ? tb : s);
  double ah = fabs(h), scale = (e > ah ? e : ah) * 0.75;
  for (int side = 0; side < 2; ++side) {
    double p0 = side ? foot : ta, p1 = side ? tb : foot;
    double len = p1 - p0;
    if (!(len > 0)) continue;
    /* one sub-interval where len <= scale (most panels: shorter than eps*),
     * decided without the division's latency (len <= scale is ceil(len /
     * scale) <= 1 for positive numbers) */
    int m = 1;
    if (!(len <= scale)) {
      const double mq = ceil(len / scale); /* inf or NaN when scale is 0: 64 */
      m = mq >= 1.0 ? (mq < 64.0 ? (int)mq : 64) : (mq < 1.0 ? 1 : 64);
    }
    double hl = (m == 1 ? len : len / (double)m) * 0.5; /* len / 1 is len */
    for (int i = 0; i < m; ++i) {
      if (c->ni == WALL_INT) wall_flush_points(c);
      const int k = c->ni++;
      c->icq[k] = p0 + (2 * (double)i + 1) * hl;
      c->ihl[k] = hl;
      c->is[k] = s;
      c->ih[k] = h;
      c->iw[k] = wgt;
      c->inx[k] = nx;
      c->iny[k] = ny;
    }
  }
}

void px_vortex_wall_sum(const struct px_vortex_panels *p, const uint32_t *idx, size_t n, double x,
                        double y, double e, double cut, double *i3x, double *i3y, double *s0) {
  struct wall_chunk c;
  c.ni = c.nk = c.s3_only = 0;
  c.inv_e = 1.0 / e;
  c.i3x = c.i3y = c.s0 = 0.0;
  for (size_t q = 0; q < n; ++q) {
    size_t k = idx[q];
    double rx = x - p->x0[k], ry = y - p->y0[k];
    double tx = p->tx[k], ty = p->ty[k];
    double s = rx * tx + ry * ty, h = rx * ty - ry * tx;
    wall_panel(&c, s, h, p->len[k], e, cut, 1.0, ty, -tx); /* outward normal (ty, -tx) */
  }
  wall_flush_points(&c);
  wall_flush_angles(&c);
  *i3x = c.i3x;
  *i3y = c.i3y;
  *s0 = c.s0;
}

double px_vortex_wall_s3_sum(const struct px_vortex_panels *p, size_t k, const double *sx,
                             const double *sy, const double *g, const uint32_t *order,
                             const uint32_t *lst, size_t n, double e, double cut) {
  struct wall_chunk c;
  c.ni = c.nk = 0;
  c.s3_only = 1;
  c.inv_e = 1.0 / e;
  c.i3x = c.i3y = c.s0 = 0.0;
  double tx = p->tx[k], ty = p->ty[k];
  for (size_t q = 0; q < n; ++q) {
    uint32_t sj = lst[q];
    double rx = sx[sj] - p->x0[k], ry = sy[sj] - p->y0[k];
    double s = rx * tx + ry * ty, h = rx * ty - ry * tx;
    wall_panel(&c, s, h, p->len[k], e, cut, g[order[sj]], 1.0, 0.0);
  }
  wall_flush_points(&c);
  return c.i3x;
}
