/* Physics of the vortex solver, written once as pure inline functions that
 * compile as C (the cpu loops, vortex_cpu.c and vortex_diffusive.c, PX_REAL =
 * double) and as OpenCL C (vortex.cl, PX_REAL = float or double), through
 * src/kernels/px_kernel.h.
 *
 * Notation: Gamma circulation (positive counter-clockwise), eps smoothing
 * radius of the Biot-Savart kernel, eps* (here `e`) VVD domain radius. The
 * smoothed Biot-Savart term itself is the platform's (kernels/biot_savart.h). */
#ifndef PX_VORTEX_KERNEL_H
#define PX_VORTEX_KERNEL_H

#include "kernels/biot_savart.h"

#if !defined(__OPENCL_VERSION__)
#include <stdint.h>
#include <string.h>
#endif

/* |v|, and |a| + |b| + |c| + |d| (summed left to right): the scale of the
 * rounding error of a product of coordinate differences, in the tests below
 * that take a point on a panel's line to its flow side. */
PX_FN px_real vx_abs(px_real v) { return v < 0 ? -v : v; }
PX_FN px_real vx_abs_sum4(px_real a, px_real b, px_real c, px_real d) {
  return vx_abs(a) + vx_abs(b) + vx_abs(c) + vx_abs(d);
}

/* VX_ATAN2: on the cpu (C, double) vx_atan2 below, branch-free and inline:
 * the panel coefficients and the sheet's velocity call it for every vortex
 * near every panel, where the C library's atan2 was 4% of the step and kept
 * the loops scalar; on OpenCL the built-in atan2. */
#if defined(__OPENCL_VERSION__)
#define VX_ATAN2(y, x) atan2(y, x)
#else
/* atan2(y, x) without branches or library calls, for vector loops. The ratio
 * a = min/max of |x|, |y| in [0, 1] is reduced to |t| <= tan(pi/12) by
 * atan a = pi/6 + atan((a sqrt3 - 1)/(a + sqrt3)) (for a > tan(pi/12)); atan t
 * is then its Taylor series to t^23 (truncation below 0.268^25/25 = 2e-16),
 * and the octant and sign are restored by selects. atan2(+-0, x < 0) = +-pi
 * as in C (copysign keeps the sign of a zero y). */
PX_FN double vx_atan2(double y, double x) {
  const double pi = 3.14159265358979323846, sqrt3 = 1.73205080756887729353;
  const double t12 = 0.26794919243112270647; /* tan(pi/12) = 2 - sqrt3 */
  double ax = fabs(x), ay = fabs(y);
  double mx = ax > ay ? ax : ay, mn = ax > ay ? ay : ax;
  double a = mx > 0.0 ? mn / mx : 0.0;
  int big = a > t12;
  double t = big ? (a * sqrt3 - 1.0) / (a + sqrt3) : a;
  double z = t * t;
  /* atan t = t + t z p(z), p = -1/3 + z/5 - z^2/7 + ... - z^10/23 */
  double p = -1.0 / 23.0;
  p = p * z + 1.0 / 21.0;
  p = p * z - 1.0 / 19.0;
  p = p * z + 1.0 / 17.0;
  p = p * z - 1.0 / 15.0;
  p = p * z + 1.0 / 13.0;
  p = p * z - 1.0 / 11.0;
  p = p * z + 1.0 / 9.0;
  p = p * z - 1.0 / 7.0;
  p = p * z + 1.0 / 5.0;
  p = p * z - 1.0 / 3.0;
  double r = t + t * z * p;
  r = big ? pi / 6.0 + r : r;
  r = ay > ax ? 0.5 * pi - r : r;
  r = x < 0.0 ? pi - r : r;
  return copysign(r, y);
}

#define VX_ATAN2(y, x) vx_atan2(y, x)

/* log(x) without branches or library calls, for vector loops (the sheet's
 * velocity near the wall, vx_sheet_velocity). x = m 2^k with m in
 * [sqrt(1/2), sqrt(2)) (a subnormal x scaled by 2^54 first); log m =
 * 2 atanh s = 2 (s + s^3/3 + ... + s^19/19), s = (m - 1)/(m + 1), |s| <=
 * 3 - 2 sqrt2 = 0.1716 (truncation below 0.1716^21/21 = 4e-18); k ln 2 in
 * two parts, the first with 21 significant bits (k times it exact). As in C:
 * log(+-0) = -inf, log(inf) = inf, NaN for x < 0 and for NaN. */
PX_FN double vx_log(double x) {
  const double ln2_hi = 0x1.62e42p-1, ln2_lo = 4.7493250390316726e-07;
  const double sqrt2 = 1.4142135623730951;
  const int sub = x < 0x1p-1022;
  const double xs = x * 0x1p54;
  uint64_t b0, b1; /* the bits of both, then a select (a select's address
                    * taken kept gcc from vectorizing) */
  memcpy(&b0, &x, sizeof b0);
  memcpy(&b1, &xs, sizeof b1);
  const uint64_t b = sub ? b1 : b0;
  const uint64_t mb = (b & 0x000fffffffffffffull) | 0x3ff0000000000000ull;
  double m;
  memcpy(&m, &mb, sizeof m);
  /* (sub ? 54.0 : 0.0) here also kept gcc 12 from vectorizing */
  double k = (double)((int64_t)((b >> 52) & 0x7ff) - 1023 - 54 * (int64_t)sub);
  const int hi = m > sqrt2;
  m = hi ? 0.5 * m : m;
  k = hi ? k + 1.0 : k;
  const double s = (m - 1.0) / (m + 1.0), z = s * s;
  double p = 1.0 / 19.0;
  p = p * z + 1.0 / 17.0;
  p = p * z + 1.0 / 15.0;
  p = p * z + 1.0 / 13.0;
  p = p * z + 1.0 / 11.0;
  p = p * z + 1.0 / 9.0;
  p = p * z + 1.0 / 7.0;
  p = p * z + 1.0 / 5.0;
  p = p * z + 1.0 / 3.0;
  double r = k * ln2_hi + (k * ln2_lo + (2.0 * s + 2.0 * s * z * p));
  r = x == 0.0 ? -INFINITY : r;
  r = x == INFINITY ? INFINITY : r;
  return x >= 0.0 ? r : NAN;
}

#define VX_LOG(x) vx_log(x)
#endif
#if defined(__OPENCL_VERSION__)
#define VX_LOG(x) log(x)
#endif

/* VVD weights (Dynnikova 2004, eq. (7)-(9); Andronov, Guvernyuk & Dynnikova
 * 2006): neighbour j at distance r from vortex i contributes
 *   I1 += Gamma_j exp(-r/e),   I2 += Gamma_j exp(-r/e) (r_i - r_j)/r,
 * and the diffusive velocity is W = nu (I2 / (e I1) + I3 / I0). The
 * exponential of the scaled distance is returned; the caller accumulates. */
PX_FN px_real vx_vvd_weight(px_real r, px_real inv_e) { return exp(-r * inv_e); }

/* a * b + c in the exponential's polynomial: one rounding where the target
 * fuses it fast (FP_FAST_FMA, FP_FAST_FMAF: C99 <math.h> and OpenCL C; the
 * -march=native build on x86-64), else a product and a sum (a library fma
 * would be slow and keep the loops scalar). Results differ between the two at
 * rounding level only. */
#if (PX_REAL_IS_DOUBLE && defined(FP_FAST_FMA)) || (!PX_REAL_IS_DOUBLE && defined(FP_FAST_FMAF))
#define VX_MAD(a, b, c) fma(a, b, c)
#else
#define VX_MAD(a, b, c) ((a) * (b) + (c))
#endif

/* exp(-x) for 0 <= x <= 20 without branches or library calls, so that the
 * VVD neighbour loops vectorize: exp(-x) = (exp(-x/64))^64, the inner
 * exponential by its Taylor polynomial of degree 11 (|x/64| <= 0.3125:
 * truncation 2e-15, within 2e-13 of exp after the six squarings, x > 20
 * clamped; test_vortex_vvd). Used for the VVD weights exp(-r/eps*) and the
 * wall integrals on every backend. The polynomial is evaluated by Estrin's
 * scheme (pairs, then the powers y^2, y^4, y^8): 7 dependent operations
 * instead of Horner's 20 (4 with fused multiply-adds); the pair loops are
 * bound by this chain (the diffusive block 7% faster than with Horner's
 * degree 10, another 3-5% with VX_MAD fused). */
PX_FN px_real vx_exp_neg(px_real x) {
  px_real y = (x < PX_R(20.0) ? x : PX_R(20.0)) * PX_R(-0.015625);
  px_real y2 = y * y, y4 = y2 * y2, y8 = y4 * y4;
  px_real a01 = PX_R(1.0) + y, a23 = VX_MAD(y, PX_R(1.0 / 6.0), PX_R(0.5));
  px_real a45 = VX_MAD(y, PX_R(1.0 / 120.0), PX_R(1.0 / 24.0));
  px_real a67 = VX_MAD(y, PX_R(1.0 / 5040.0), PX_R(1.0 / 720.0));
  px_real a89 = VX_MAD(y, PX_R(1.0 / 362880.0), PX_R(1.0 / 40320.0));
  px_real a1011 = VX_MAD(y, PX_R(1.0 / 39916800.0), PX_R(1.0 / 3628800.0));
  px_real a03 = VX_MAD(y2, a23, a01), a47 = VX_MAD(y2, a67, a45);
  px_real a811 = VX_MAD(y2, a1011, a89);
  px_real p = VX_MAD(y8, a811, VX_MAD(y4, a47, a03));
  p = p * p;
  p = p * p;
  p = p * p;
  p = p * p;
  p = p * p;
  return p * p;
}

/* Mean over the segment a0 -> a1 of the tangential velocity induced by a
 * unit point vortex at (x, y): the circulation of a point vortex along a path
 * is Gamma/(2 pi) times the angle swept, so the mean is
 * Dtheta / (2 pi L), Dtheta = atan2((a0 - r) x (a1 - r), (a0 - r).(a1 - r)).
 * A vortex on the segment's line up to rounding (a newborn with delta = 0,
 * or one held there by rk2's predictor) counts as on the flow side (outward
 * normal (t_y, -t_x)), where Dtheta tends to -pi over the segment, as in
 * vx_wall_height: else the sign of a rounding error in the cross product
 * (FMA contraction differs between the cpu and OpenCL builds) picks +pi or
 * -pi, and the sheet changes by a slip velocity of 1/L. */
PX_FN px_real vx_point_coef(px_real ax0, px_real ay0, px_real ax1, px_real ay1, px_real inv_len,
                            px_real x, px_real y) {
  px_real sx = ax0 - x, sy = ay0 - y, px = ax1 - x, py = ay1 - y;
  px_real cr = sx * py - sy * px, dt = sx * px + sy * py;
  /* the rounding of the cross product of a point on the line: its inputs'
   * (relative to the coordinates) times the arms' lengths */
  px_real aw = vx_abs_sum4(ax0, ay0, x, y), arm = vx_abs_sum4(sx, sy, px, py);
  const px_real on_line = dt < 0 ? PX_R(-0.5) * inv_len : PX_R(0.0);
  const px_real off = VX_ATAN2(cr, dt) * inv_len * PX_R(0.15915494309189533577);
  return vx_abs(cr) <= PX_R(16.0) * PX_REAL_EPS * aw * arm ? on_line : off; /* no branch */
}

/* Velocity at (x, y) induced by a vortex sheet of unit intensity on the
 * straight segment (bx0, by0) -> (bx1, by1) (on it: the flow side's limit). In the
 * segment's frame (origin at its start, x' along it) the sheet on [0, L]
 * induces (1/2pi) int_0^L (-y', x' - s) / ((x' - s)^2 + y'^2) ds:
 *   u' = -(1/2pi) [atan2(y', x' - L) - atan2(y', x')]  (minus the subtended angle)
 *   v' =  (1/4pi) ln(|w|^2 / |w - L|^2),  w = (x', y').
 * Just above the sheet (on its left) u' -> -1/2: the half jump. */
PX_FN px_real2 vx_sheet_velocity(px_real bx0, px_real by0, px_real bx1, px_real by1, px_real x,
                                 px_real y) {
  px_real L = sqrt((bx1 - bx0) * (bx1 - bx0) + (by1 - by0) * (by1 - by0));
  px_real tx = (bx1 - bx0) / L, ty = (by1 - by0) / L;
  px_real rx = x - bx0, ry = y - by0;
  px_real xl = rx * tx + ry * ty, yl = -rx * ty + ry * tx;
  px_real up = -(VX_ATAN2(yl, xl - L) - VX_ATAN2(yl, xl)) * PX_R(0.15915494309189533577);
  /* a point on the segment up to rounding (a vortex held there by rk2's
   * predictor with delta = 0) is on the flow side, the right of the segment
   * (outward normal (t_y, -t_x): y' -> -0, u' -> +1/2), as in vx_point_coef;
   * else the rounding's sign picks +-1/2 */
  px_real aw = vx_abs_sum4(x, y, bx0, by0);
  const px_real on_side = ((xl > 0) & (xl < L)) ? PX_R(0.5) : PX_R(0.0); /* &: no branch */
  up = vx_abs(yl) <= PX_R(16.0) * PX_REAL_EPS * aw ? on_side : up;
  px_real r0 = xl * xl + yl * yl, r1 = (xl - L) * (xl - L) + yl * yl;
  px_real vp = VX_LOG(r0 / r1) * PX_R(0.07957747154594766788);
  return px_v2(up * tx - vp * ty, up * ty + vp * tx);
}

/* ((1 + x) e^-x - 1) / x^2 given ex = vx_exp_neg(x), accurate for small x
 * (series below 0.02); a select rather than a branch, so that loops over
 * quadrature points vectorize. */
PX_FN px_real vx_g1_ex(px_real x, px_real ex) {
  px_real xs = x < PX_R(0.02) ? PX_R(0.02) : x;
  px_real series = PX_R(-0.5) + x * (PX_R(1.0 / 3.0) + x * (PX_R(-0.125) + x * PX_R(1.0 / 30.0)));
  px_real closed = ((1 + xs) * ex - 1) / (xs * xs);
  return x < PX_R(0.02) ? series : closed;
}

/* A point on the panel's line up to rounding (newborn vortices with delta = 0
 * are placed exactly on their panel) counts as on the flow side: h = +0. Else
 * the sign of a rounding error in h (which differs between compilers: FMA
 * contraction) would pick -pi instead of +pi for the subtended angle and
 * triple I0. */
PX_FN px_real vx_wall_height(px_real h, px_real s, px_real L) {
  return vx_abs(h) <= PX_R(64.0) * PX_REAL_EPS * (L + vx_abs(s)) ? PX_R(0.0) : h;
}

/* Surface integrals of the VVD over one straight panel (Dynnikova 2004;
 * Kuzmina & Marchevsky). For a point at signed distance h from the panel line
 * (h > 0 on the outward, flow side) whose foot lies at abscissa s along the
 * panel [0, L], with domain radius e:
 *
 *   S3 = int_0^L exp(-rho/e) dt,                 rho^2 = (t - s)^2 + h^2,
 *   S0 = int_0^L h (1 + rho/e) exp(-rho/e) / rho^2 dt.
 *
 * I3 = sum_panels n_k S3 (outward normal) and
 * I0 = 2 pi e^2 - e^2 sum_panels S0 = int over the flow domain of exp(-|r - r'|/e) dA'
 * (the body's share of the plane integral turned into a contour integral:
 * div_xi[(r - xi) (e + |r - xi|) e^(-|r - xi|/e) / |r - xi|^2] = exp(-|r - xi|/e)/e
 * away from xi = r). S0 is split into the exact subtended angle (the
 * h / rho^2 part, singular as h -> 0) plus a smooth remainder integrated by
 * 4-point Gauss-Legendre on sub-intervals of length <= 0.75 max(e, |h|), split
 * at the foot; both are cut at `cut` e from the foot. */
PX_FN void vx_panel_wall(px_real s, px_real h, px_real L, px_real e, px_real cut, px_real *S3,
                         px_real *S0) {
  px_real ta = s - cut * e, tb = s + cut * e;
  if (ta < 0) ta = 0;
  if (tb > L) tb = L;
  *S3 = 0;
  *S0 = 0;
  h = vx_wall_height(h, s, L);
  if (!(ta < tb)) return;
  px_real inv_e = 1 / e;
  /* exact angle subtended by [ta, tb] */
  px_real ang = atan2(h * (tb - ta), h * h + (ta - s) * (tb - s));
  px_real foot = s < ta ? ta : (s > tb ? tb : s);
  px_real ah = vx_abs(h);
  px_real scale = (e > ah ? e : ah) * PX_R(0.75);
  const px_real xg0 = PX_R(0.3399810435848563), xg1 = PX_R(0.8611363115940526);
  const px_real wg0 = PX_R(0.6521451548625461), wg1 = PX_R(0.3478548451374538);
  px_real e3 = 0, r0 = 0;
  for (int side = 0; side < 2; ++side) {
    px_real p0 = side ? foot : ta, p1 = side ? tb : foot;
    px_real len = p1 - p0;
    if (!(len > 0)) continue;
    int m = (int)ceil(len / scale);
    if (m < 1) m = 1;
    if (m > 64) m = 64;
    px_real hl = len / (px_real)m * PX_R(0.5);
    for (int q = 0; q < m; ++q) {
      px_real c = p0 + (2 * (px_real)q + 1) * hl;
      px_real tq[4] = {c - xg1 * hl, c - xg0 * hl, c + xg0 * hl, c + xg1 * hl};
      px_real wq[4] = {wg1, wg0, wg0, wg1};
      for (int j = 0; j < 4; ++j) {
        px_real du = tq[j] - s;
        px_real rho = sqrt(du * du + h * h);
        px_real x = rho * inv_e, ex = vx_exp_neg(x);
        e3 += wq[j] * hl * ex;
        r0 += wq[j] * hl * vx_g1_ex(x, ex) * inv_e * inv_e;
      }
    }
  }
  *S3 = e3;
  *S0 = ang + h * r0;
}

/* vvd_moments: covariance (vortex_diffusive.c, vvd_covariance). The weight of a
 * neighbour at squared distance r2 from a vortex of radius e (inv_e = 1/e),
 * exp(-r2 / (2 e^2)), cut where it falls below exp(-20) (r > 6.3 e, the
 * range of vx_exp_neg); the caller multiplies by Gamma_j of the same sign. */
PX_FN px_real vx_cov_weight(px_real r2, px_real inv_e) {
  px_real a = PX_R(0.5) * r2 * inv_e * inv_e;
  return a <= PX_R(20.0) ? vx_exp_neg(a) : PX_R(0.0);
}

/* The covariance diffusive velocity over nu, V^-1 m, from the weighted sums
 * s0 = sum w (the vortex itself included), (sx, sy) = sum w d and (sxx, sxy,
 * syy) = sum w d d^T over the offsets d = x_i - x_j. Returns 0 (W left to the
 * published formula) where V is degenerate: its smaller principal variance
 * below 0.02 e^2, a structure thinner than 0.14 e (not resolved by the
 * neighbours), or no weight at all. */
PX_FN int vx_cov_velocity(px_real s0, px_real sx, px_real sy, px_real sxx, px_real sxy, px_real syy,
                          px_real e, px_real *wx, px_real *wy) {
  px_real mx = sx / s0, my = sy / s0;
  px_real vxx = sxx / s0 - mx * mx, vxy = sxy / s0 - mx * my, vyy = syy / s0 - my * my;
  px_real det = vxx * vyy - vxy * vxy;
  px_real dq = (vxx - vyy) * (vxx - vyy) + PX_R(4.0) * vxy * vxy;
  px_real lmin = PX_R(0.5) * (vxx + vyy - sqrt(dq > 0 ? dq : PX_R(0.0)));
  if (!(det > 0) || !(lmin > PX_R(0.02) * e * e)) return 0;
  *wx = (vyy * mx - vxy * my) / det;
  *wy = (vxx * my - vxy * mx) / det;
  return 1;
}

/* eps* of a vortex, the radius of its VVD domain [m]: the rms of the squared
 * distances d0, d1, d2 to its 3 nearest neighbours (INFINITY where fewer
 * exist; any order), at least emin; emin alone without neighbours
 * (Dynnikova 2004, sec. 3). */
PX_FN px_real vx_eps_star(px_real d0, px_real d1, px_real d2, px_real emin) {
  px_real s = 0;
  int c = 0;
  if (isfinite(d0)) {
    s += d0;
    ++c;
  }
  if (isfinite(d1)) {
    s += d1;
    ++c;
  }
  if (isfinite(d2)) {
    s += d2;
    ++c;
  }
  px_real ev = c ? sqrt(s / (px_real)c) : emin;
  return ev > emin ? ev : emin;
}

/* The length of the VVD's particle term with vvd_moments `wake` (no panel
 * within reach): M1 / (2 M0) from the kernel's moments M0 = sum exp(-r/e),
 * M1 = sum r exp(-r/e) of the neighbours, e itself without any. */
PX_FN px_real vx_vvd_length(px_real e, px_real m0, px_real m1) {
  return m1 > 0 ? PX_R(0.5) * m1 / m0 : e;
}

/* The VVD diffusive velocity over nu (Dynnikova 2004, eq. (9); Andronov,
 * Guvernyuk & Dynnikova 2006), its particle term I2 / (el I1) [1/m] into
 * (*wx, *wy) from the sums I1 = sum Gamma_j exp(-r/e), i1abs = sum |Gamma_j|
 * exp(-r/e) and I2 = sum Gamma_j exp(-r/e) (r_i - r_j)/r; zero where I1 is
 * lost to cancellation (|I1| <= 1e-10 sum |Gamma_j| exp(-r/e): a vortex
 * between neighbours of both signs). el: eps*, or vx_vvd_length. */
PX_FN void vx_vvd_particle(px_real i1, px_real i1abs, px_real i2x, px_real i2y, px_real el,
                           px_real *wx, px_real *wy) {
  *wx = 0;
  *wy = 0;
  if (fabs(i1) > PX_R(1e-10) * i1abs) {
    *wx = i2x / (i1 * el);
    *wy = i2y / (i1 * el);
  }
}

/* Adds the wall term I3 / I0 [1/m] of a vortex of eps* e to (*wx, *wy): I3
 * and S0 summed over the panels within reach (vx_panel_wall; 0 without any),
 * I0 = e^2 (2 pi - S0), held at 0.1 pi e^2 or more (a vortex on the wall
 * sees half its domain, S0 -> pi; the floor keeps I0 off zero at corners). */
PX_FN void vx_vvd_wall(px_real e, px_real s0, px_real i3x, px_real i3y, px_real *wx, px_real *wy) {
  px_real i0 = e * e * (PX_R(6.283185307179586477) - s0);
  px_real i0min = PX_R(0.3141592653589793) * e * e;
  if (i0 < i0min) i0 = i0min;
  *wx += i3x / i0;
  *wy += i3y / i0;
}

/* Does the segment p -> q cross the panel a -> b? If so, returns 1 and the
 * parameter along p -> q in *t (0..1). Touching counts as crossing (a vortex
 * landing exactly on the wall is absorbed). A start on the panel's line up
 * to rounding (a newborn vortex with delta = 0) counts as on the flow side,
 * as in vx_wall_height: crossed at t = 0 when the path heads into the body
 * (against the outward normal (t_y, -t_x)), not when it leaves the wall.
 * Else the sign of a rounding error (which differs between compilers: FMA
 * contraction) would absorb a newborn at its start or not. */
PX_FN int vx_seg_cross(px_real px, px_real py, px_real qx, px_real qy, px_real ax, px_real ay,
                       px_real bx, px_real by, px_real *t) {
  px_real rx = qx - px, ry = qy - py, sx = bx - ax, sy = by - ay;
  px_real den = rx * sy - ry * sx;
  if (den == 0) return 0; /* parallel: a grazing move along the wall is no crossing */
  px_real wx = ax - px, wy = ay - py;
  px_real hp = wx * sy - wy * sx; /* den times t: the start's offset from the line */
  /* the rounding of a start computed on the line is relative to the
   * coordinates, not to its distance from a */
  px_real aw = vx_abs_sum4(px, py, ax, ay), as = vx_abs(sx) + vx_abs(sy);
  if (vx_abs(hp) <= PX_R(64.0) * PX_REAL_EPS * aw * as) {
    if (den > 0) return 0; /* leaves the wall to the flow side */
    hp = 0;
  }
  px_real tp = hp / den, up = (wx * ry - wy * rx) / den;
  if (tp < 0 || tp > 1 || up < 0 || up > 1) return 0;
  *t = tp;
  return 1;
}

/* The near-wake correction of a panel's right-hand side per unit circulation
 * of a vortex at (x, y): the exact mean tangential velocity over the panel
 * a0 -> a1 (vx_point_coef) minus the smoothed field's mean at the panel's
 * two Gauss points g0, g1 (the far-field sum's), along the tangent (tx, ty);
 * eps2 the smoothing radius squared. */
PX_FN px_real vx_near_coef(px_real ax0, px_real ay0, px_real ax1, px_real ay1, px_real inv_len,
                           px_real tx, px_real ty, px_real g0x, px_real g0y, px_real g1x,
                           px_real g1y, px_real eps2, px_real x, px_real y) {
  px_real exact = vx_point_coef(ax0, ay0, ax1, ay1, inv_len, x, y);
  px_real a = 0;
  px_real2 k0 = px_biot_savart_term(g0x - x, g0y - y, PX_R(1.0), eps2);
  a += PX_R(0.5) * (k0.x * tx + k0.y * ty);
  px_real2 k1 = px_biot_savart_term(g1x - x, g1y - y, PX_R(1.0), eps2);
  a += PX_R(0.5) * (k1.x * tx + k1.y * ty);
  return exact - a * (PX_R(0.5) / PX_R(3.14159265358979323846));
}

/* The most newborn vortices one panel sheds in one stage: bounds the wake's
 * growth (memory, and the pair sums' N^2) when gamma_max is tiny against a
 * panel's |gamma L|; a capped panel's newborns carry |gamma L| / 64 each,
 * more than gamma_max (the engine warns once: px_vortex_newborn_cap_warn). */
#define VX_NEWBORN_MAX 64

/* Newborn vortices a panel sheds for its sheet circulation |gamma L| = gl:
 * at least per_panel, enough that none carries more than gmax, at most
 * VX_NEWBORN_MAX. */
PX_FN int vx_newborn_count(px_real gl, px_real gmax, int per_panel) {
  int m = per_panel;
  px_real need = ceil(gl / gmax);
  if (need > (px_real)m) m = need > (px_real)VX_NEWBORN_MAX ? VX_NEWBORN_MAX : (int)need;
  return m;
}

/* Is the panel's count capped: would gl need more than VX_NEWBORN_MAX
 * newborns of at most gmax (ceil(gl / gmax) > 64 exactly when gl / gmax >
 * 64)? */
PX_FN int vx_newborn_capped(px_real gl, px_real gmax) {
  return gl / gmax > (px_real)VX_NEWBORN_MAX;
}

/* The merge radii's growth factor at a point s = r . stream_dir downstream:
 * 1 up to the bodies' downstream end s_right, then (s - s_right) / span. */
PX_FN px_real vx_merge_growth(px_real s, px_real s_right, px_real span) {
  px_real f = (s - s_right) / (span > 0 ? span : PX_R(1.0));
  return f > 1 ? f : PX_R(1.0);
}

/* May vortices of circulations gi, gj at squared distance d2 merge? Same
 * sign: within rs, the merged circulation under gcap; opposite signs: within
 * ro. */
PX_FN int vx_merge_ok(px_real gi, px_real gj, px_real d2, px_real rs, px_real ro, px_real gcap) {
  return gi * gj > 0 ? (d2 < rs * rs && fabs(gi + gj) < gcap) : d2 < ro * ro;
}

/* Where the merged vortex of (xi, yi, gi) and (xj, yj, gj) goes: the centre
 * of |Gamma| for the same sign, else the stronger one's place (i on a tie). */
PX_FN void vx_merge_position(px_real gi, px_real gj, px_real xi, px_real yi, px_real xj, px_real yj,
                             px_real *x, px_real *y) {
  if (gi * gj > 0) {
    px_real ai = fabs(gi), aj = fabs(gj);
    *x = (ai * xi + aj * xj) / (ai + aj);
    *y = (ai * yi + aj * yj) / (ai + aj);
  } else if (fabs(gi) >= fabs(gj)) {
    *x = xi;
    *y = yi;
  } else {
    *x = xj;
    *y = yj;
  }
}

#endif
