/* Wall terms of the VVD on the cpu: the sums of vx_panel_wall over the panels
 * near one vortex, vectorized across panels and quadrature points.
 *
 * vx_panel_wall integrates one panel at a time: an atan2 and, per side of the
 * foot, m sub-intervals of 4-point Gauss-Legendre, each point an exponential.
 * Called per panel, nothing vectorizes (m varies, the loops are short) and the
 * libm atan2 is scalar; near a body this was a quarter of the step. Here the
 * same sub-intervals are first listed, 8 panels at a time (wall_block_*:
 * centre, half length, and the point's abscissa, height, weight and panel
 * normal), their quadrature points expanded in one vector loop and evaluated
 * in another, and the subtended angles by a branch-free atan2 (vortex_kernel.h's
 * vx_atan2) in a third. The points, weights and formulas are vx_panel_wall's:
 * the sums agree with it to rounding, and the AVX-512 listing gives the
 * scalar one's sums to the bit (tests/vortex/test_vortex_vvd.c checks these,
 * and vx_atan2 against atan2). */
#include "solvers/vortex/vortex_core.h"

#include <float.h>
#include <math.h>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

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

/* Up to 8 panels of one sum, as lanes: the point's abscissa s and height h
 * along each, its length L, the weight and the direction (nx, ny). */
struct wall_lanes {
  double s[8], h[8], L[8], w[8], nx[8], ny[8];
  int n;
};

/* The quadrature of vx_panel_wall for the panels of b: unless s3_only, the
 * arguments of their subtended angles (in panel order); then, per side of
 * the foot (the part before it, then the part after), the sub-intervals in
 * rounds: round i lists sub-interval i of each panel that has more than i,
 * in panel order. The points and weights are vx_panel_wall's; the order (not
 * panel by panel) is this block's, the same on both paths below, which
 * give the same lists and chunk boundaries, so the same sums. (Listed
 * panel by panel, with a branch per side and per sub-interval, the listing
 * cost as much as the sums: 2026-11-28.) */
static void wall_block_plain(struct wall_chunk *c, const struct wall_lanes *b, double e,
                             double cut) {
  double ta[8], tb[8], h[8], foot[8], scale[8];
  int valid[8], any = 0;
  for (int j = 0; j < b->n; ++j) {
    const double s = b->s[j];
    ta[j] = s - cut * e;
    tb[j] = s + cut * e;
    if (ta[j] < 0) ta[j] = 0;
    if (tb[j] > b->L[j]) tb[j] = b->L[j];
    valid[j] = ta[j] < tb[j];
    any |= valid[j];
    h[j] = vx_wall_height(b->h[j], s, b->L[j]);
    foot[j] = s < ta[j] ? ta[j] : (s > tb[j] ? tb[j] : s);
    const double ah = fabs(h[j]);
    scale[j] = (e > ah ? e : ah) * 0.75;
  }
  if (!any) return;
  if (!c->s3_only) {
    if (c->nk + 8 > WALL_PAN) wall_flush_angles(c);
    for (int j = 0; j < b->n; ++j) {
      if (!valid[j]) continue;
      c->ay[c->nk] = h[j] * (tb[j] - ta[j]);
      c->ax[c->nk] = h[j] * h[j] + (ta[j] - b->s[j]) * (tb[j] - b->s[j]);
      ++c->nk;
    }
  }
  for (int side = 0; side < 2; ++side) {
    double p0[8], hl[8], m[8], maxm = 0.0;
    int act[8];
    for (int j = 0; j < b->n; ++j) {
      p0[j] = side ? foot[j] : ta[j];
      const double len = (side ? tb[j] : foot[j]) - p0[j];
      act[j] = valid[j] && len > 0;
      /* m sub-intervals of at most scale: ceil(len / scale), 1 to 64 (64
       * for inf or NaN: a scale of 0) */
      const double mq = ceil(len / scale[j]);
      m[j] =
          len <= scale[j] ? 1.0 : (mq >= 1.0 ? (mq < 64.0 ? mq : 64.0) : (mq < 1.0 ? 1.0 : 64.0));
      hl[j] = len / m[j] * 0.5;
      if (act[j] && m[j] > maxm) maxm = m[j];
    }
    for (int i = 0; (double)i < maxm; ++i) {
      if (c->ni + 8 > WALL_INT) wall_flush_points(c);
      for (int j = 0; j < b->n; ++j) {
        if (!act[j] || !(m[j] > (double)i)) continue;
        const int k = c->ni++;
        c->icq[k] = p0[j] + (2 * (double)i + 1) * hl[j];
        c->ihl[k] = hl[j];
        c->is[k] = b->s[j];
        c->ih[k] = h[j];
        c->iw[k] = b->w[j];
        c->inx[k] = b->nx[j];
        c->iny[k] = b->ny[j];
      }
    }
  }
}

#if defined(__AVX512F__)
/* The same with the lanes live of s, h, L, w, nx, ny in vector registers,
 * compressed into the lists. */
static inline __attribute__((always_inline)) void wall_block_avx(struct wall_chunk *c,
                                                                 __mmask8 live, __m512d s,
                                                                 __m512d h, __m512d L, __m512d w,
                                                                 __m512d nx, __m512d ny, double e,
                                                                 double cut) {
  const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0);
  const __m512d half = _mm512_set1_pd(0.5);
  const __m512d ve = _mm512_set1_pd(e), ce = _mm512_set1_pd(cut * e);
  __m512d ta = _mm512_sub_pd(s, ce), tb = _mm512_add_pd(s, ce);
  ta = _mm512_mask_mov_pd(ta, _mm512_cmp_pd_mask(ta, zero, _CMP_LT_OQ), zero);
  tb = _mm512_mask_mov_pd(tb, _mm512_cmp_pd_mask(tb, L, _CMP_GT_OQ), L);
  const __mmask8 valid = _mm512_mask_cmp_pd_mask(live, ta, tb, _CMP_LT_OQ);
  if (!valid) return;
  /* vx_wall_height */
  const __m512d hlim =
      _mm512_mul_pd(_mm512_set1_pd(64.0 * DBL_EPSILON), _mm512_add_pd(L, _mm512_abs_pd(s)));
  h = _mm512_mask_mov_pd(h, _mm512_cmp_pd_mask(_mm512_abs_pd(h), hlim, _CMP_LE_OQ), zero);
  if (!c->s3_only) {
    if (c->nk + 8 > WALL_PAN) wall_flush_angles(c);
    const __m512d ay = _mm512_mul_pd(h, _mm512_sub_pd(tb, ta));
    const __m512d ax = _mm512_add_pd(_mm512_mul_pd(h, h),
                                     _mm512_mul_pd(_mm512_sub_pd(ta, s), _mm512_sub_pd(tb, s)));
    _mm512_storeu_pd(c->ay + c->nk, _mm512_maskz_compress_pd(valid, ay));
    _mm512_storeu_pd(c->ax + c->nk, _mm512_maskz_compress_pd(valid, ax));
    c->nk += __builtin_popcount((unsigned)valid);
  }
  __m512d foot = _mm512_mask_mov_pd(s, _mm512_cmp_pd_mask(s, tb, _CMP_GT_OQ), tb);
  foot = _mm512_mask_mov_pd(foot, _mm512_cmp_pd_mask(s, ta, _CMP_LT_OQ), ta);
  const __m512d ah = _mm512_abs_pd(h);
  const __m512d scale = _mm512_mul_pd(
      _mm512_mask_mov_pd(ah, _mm512_cmp_pd_mask(ve, ah, _CMP_GT_OQ), ve), _mm512_set1_pd(0.75));
  for (int side = 0; side < 2; ++side) {
    const __m512d p0 = side ? foot : ta, len = _mm512_sub_pd(side ? tb : foot, p0);
    const __mmask8 act = _mm512_mask_cmp_pd_mask(valid, len, zero, _CMP_GT_OQ);
    if (!act) continue;
    /* one sub-interval each unless some side is longer than its scale:
     * then the divisions (len / 1 is len) */
    __m512d m = one, hl = _mm512_mul_pd(len, half);
    double maxm = 1.0;
    if (_mm512_mask_cmp_pd_mask(act, len, scale, _CMP_NLE_UQ)) {
      const __m512d mq = _mm512_roundscale_pd(_mm512_div_pd(len, scale),
                                              _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
      m = _mm512_set1_pd(64.0);
      m = _mm512_mask_mov_pd(m, _mm512_cmp_pd_mask(mq, one, _CMP_LT_OQ), one);
      m = _mm512_mask_mov_pd(m, _mm512_cmp_pd_mask(mq, one, _CMP_GE_OQ),
                             _mm512_min_pd(mq, _mm512_set1_pd(64.0)));
      m = _mm512_mask_mov_pd(m, _mm512_cmp_pd_mask(len, scale, _CMP_LE_OQ), one);
      hl = _mm512_mul_pd(_mm512_div_pd(len, m), half);
      maxm = _mm512_mask_reduce_max_pd(act, m);
    }
    for (int i = 0; (double)i < maxm; ++i) {
      if (c->ni + 8 > WALL_INT) wall_flush_points(c);
      const __m512d vi = _mm512_set1_pd((double)i);
      const __mmask8 em = _mm512_mask_cmp_pd_mask(act, m, vi, _CMP_GT_OQ);
      const __m512d q = _mm512_add_pd(p0, _mm512_mul_pd(_mm512_set1_pd(2 * (double)i + 1), hl));
      const int k = c->ni;
      _mm512_storeu_pd(c->icq + k, _mm512_maskz_compress_pd(em, q));
      _mm512_storeu_pd(c->ihl + k, _mm512_maskz_compress_pd(em, hl));
      _mm512_storeu_pd(c->is + k, _mm512_maskz_compress_pd(em, s));
      _mm512_storeu_pd(c->ih + k, _mm512_maskz_compress_pd(em, h));
      _mm512_storeu_pd(c->iw + k, _mm512_maskz_compress_pd(em, w));
      _mm512_storeu_pd(c->inx + k, _mm512_maskz_compress_pd(em, nx));
      _mm512_storeu_pd(c->iny + k, _mm512_maskz_compress_pd(em, ny));
      c->ni += __builtin_popcount((unsigned)em);
    }
  }
}
#endif

static inline __attribute__((always_inline)) void wall_sum(const struct px_vortex_panels *p,
                                                           const uint32_t *idx, size_t n, double x,
                                                           double y, double e, double cut,
                                                           double *i3x, double *i3y, double *s0,
                                                           int plain) {
  struct wall_chunk c;
  struct wall_lanes b;
  c.ni = c.nk = c.s3_only = 0;
  c.inv_e = 1.0 / e;
  c.i3x = c.i3y = c.s0 = 0.0;
  b.n = 0;
#if !defined(__AVX512F__)
  plain = 1;
#else
  if (!plain) {
    /* the panels' data gathered 8 at a time (lanes written one by one and
     * loaded as a vector stall the load) */
    const __m512d vx = _mm512_set1_pd(x), vy = _mm512_set1_pd(y), one = _mm512_set1_pd(1.0);
    for (size_t q = 0; q < n; q += 8) {
      const size_t left = n - q;
      const __mmask8 live = left >= 8 ? (__mmask8)0xff : (__mmask8)((1u << left) - 1u);
      /* unsigned 32-bit indices widened (a 32-bit gather's are signed) */
      const __m512i k = _mm512_cvtepu32_epi64(_mm256_maskz_loadu_epi32(live, idx + q));
      const __m512d z = _mm512_setzero_pd();
      const __m512d rx = _mm512_sub_pd(vx, _mm512_mask_i64gather_pd(z, live, k, p->x0, 8));
      const __m512d ry = _mm512_sub_pd(vy, _mm512_mask_i64gather_pd(z, live, k, p->y0, 8));
      const __m512d tx = _mm512_mask_i64gather_pd(z, live, k, p->tx, 8);
      const __m512d ty = _mm512_mask_i64gather_pd(z, live, k, p->ty, 8);
      const __m512d L = _mm512_mask_i64gather_pd(z, live, k, p->len, 8);
      const __m512d s = _mm512_add_pd(_mm512_mul_pd(rx, tx), _mm512_mul_pd(ry, ty));
      const __m512d h = _mm512_sub_pd(_mm512_mul_pd(rx, ty), _mm512_mul_pd(ry, tx));
      /* outward normal (ty, -tx) */
      const __m512d ntx = _mm512_castsi512_pd(
          _mm512_xor_si512(_mm512_castpd_si512(tx), _mm512_castpd_si512(_mm512_set1_pd(-0.0))));
      wall_block_avx(&c, live, s, h, L, one, ty, ntx, e, cut);
    }
  }
#endif
  for (size_t q = 0; q < n && plain; ++q) {
    size_t k = idx[q];
    double rx = x - p->x0[k], ry = y - p->y0[k];
    double tx = p->tx[k], ty = p->ty[k];
    const int j = b.n++;
    b.s[j] = rx * tx + ry * ty;
    b.h[j] = rx * ty - ry * tx;
    b.L[j] = p->len[k];
    b.w[j] = 1.0;
    b.nx[j] = ty; /* outward normal (ty, -tx) */
    b.ny[j] = -tx;
    if (b.n == 8) {
      wall_block_plain(&c, &b, e, cut);
      b.n = 0;
    }
  }
  if (b.n) wall_block_plain(&c, &b, e, cut);
  wall_flush_points(&c);
  wall_flush_angles(&c);
  *i3x = c.i3x;
  *i3y = c.i3y;
  *s0 = c.s0;
}

void px_vortex_wall_sum(const struct px_vortex_panels *p, const uint32_t *idx, size_t n, double x,
                        double y, double e, double cut, double *i3x, double *i3y, double *s0) {
  wall_sum(p, idx, n, x, y, e, cut, i3x, i3y, s0, 0);
}

void px_vortex_wall_sum_plain(const struct px_vortex_panels *p, const uint32_t *idx, size_t n,
                              double x, double y, double e, double cut, double *i3x, double *i3y,
                              double *s0) {
  wall_sum(p, idx, n, x, y, e, cut, i3x, i3y, s0, 1);
}

static inline __attribute__((always_inline)) double wall_s3_sum(
    const struct px_vortex_panels *p, size_t k, const double *sx, const double *sy, const double *g,
    const uint32_t *order, const uint32_t *lst, size_t n, double e, double cut, int plain) {
  struct wall_chunk c;
  struct wall_lanes b;
  c.ni = c.nk = 0;
  c.s3_only = 1;
  c.inv_e = 1.0 / e;
  c.i3x = c.i3y = c.s0 = 0.0;
  b.n = 0;
  double tx = p->tx[k], ty = p->ty[k];
#if !defined(__AVX512F__)
  plain = 1;
#else
  if (!plain) {
    const __m512d x0 = _mm512_set1_pd(p->x0[k]), y0 = _mm512_set1_pd(p->y0[k]);
    const __m512d vtx = _mm512_set1_pd(tx), vty = _mm512_set1_pd(ty);
    const __m512d L = _mm512_set1_pd(p->len[k]), one = _mm512_set1_pd(1.0);
    const __m512d z = _mm512_setzero_pd();
    for (size_t q = 0; q < n; q += 8) {
      const size_t left = n - q;
      const __mmask8 live = left >= 8 ? (__mmask8)0xff : (__mmask8)((1u << left) - 1u);
      /* unsigned 32-bit indices widened (a 32-bit gather's are signed) */
      const __m512i sj = _mm512_cvtepu32_epi64(_mm256_maskz_loadu_epi32(live, lst + q));
      const __m512d rx = _mm512_sub_pd(_mm512_mask_i64gather_pd(z, live, sj, sx, 8), x0);
      const __m512d ry = _mm512_sub_pd(_mm512_mask_i64gather_pd(z, live, sj, sy, 8), y0);
      const __m512i oj = _mm512_cvtepu32_epi64(
          _mm512_mask_i64gather_epi32(_mm256_setzero_si256(), live, sj, (const int *)order, 4));
      const __m512d w = _mm512_mask_i64gather_pd(z, live, oj, g, 8);
      const __m512d s = _mm512_add_pd(_mm512_mul_pd(rx, vtx), _mm512_mul_pd(ry, vty));
      const __m512d h = _mm512_sub_pd(_mm512_mul_pd(rx, vty), _mm512_mul_pd(ry, vtx));
      wall_block_avx(&c, live, s, h, L, w, one, z, e, cut);
    }
  }
#endif
  for (size_t q = 0; q < n && plain; ++q) {
    uint32_t sj = lst[q];
    double rx = sx[sj] - p->x0[k], ry = sy[sj] - p->y0[k];
    const int j = b.n++;
    b.s[j] = rx * tx + ry * ty;
    b.h[j] = rx * ty - ry * tx;
    b.L[j] = p->len[k];
    b.w[j] = g[order[sj]];
    b.nx[j] = 1.0;
    b.ny[j] = 0.0;
    if (b.n == 8) {
      wall_block_plain(&c, &b, e, cut);
      b.n = 0;
    }
  }
  if (b.n) wall_block_plain(&c, &b, e, cut);
  wall_flush_points(&c);
  return c.i3x;
}

double px_vortex_wall_s3_sum(const struct px_vortex_panels *p, size_t k, const double *sx,
                             const double *sy, const double *g, const uint32_t *order,
                             const uint32_t *lst, size_t n, double e, double cut) {
  return wall_s3_sum(p, k, sx, sy, g, order, lst, n, e, cut, 0);
}

double px_vortex_wall_s3_sum_plain(const struct px_vortex_panels *p, size_t k, const double *sx,
                                   const double *sy, const double *g, const uint32_t *order,
                                   const uint32_t *lst, size_t n, double e, double cut) {
  return wall_s3_sum(p, k, sx, sy, g, order, lst, n, e, cut, 1);
}
