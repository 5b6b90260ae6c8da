/* Physics of the vortex solver, written once as pure inline functions that
 * compile as C (cpu loops) and as OpenCL C (vortex.cl includes this file).
 *
 * The includer defines VX_REAL (float or double) and, in C, VX_K(name) to
 * give each instantiation its own names (e.g. name##_f, name##_d); the header
 * has no include guard so that C can instantiate it twice. In OpenCL C,
 * VX_REAL comes from the build options and VX_K(name) is name. VX_M(f) names
 * the math function f for VX_REAL (C: expf for float, exp for double; OpenCL C
 * overloads them).
 *
 * Notation: Gamma circulation (positive counter-clockwise), eps smoothing
 * radius of the Biot-Savart kernel, eps* (here `e`) VVD domain radius. */

#ifndef VX_REAL
#error "define VX_REAL before including vortex_kernel.h"
#endif
#ifndef VX_K
#define VX_K(name) name
#endif
#ifndef VX_M
#ifdef __OPENCL_VERSION__
#define VX_M(f) f
#else
#error "define VX_M(fn) (fn##f for float, fn for double) before including vortex_kernel.h"
#endif
#endif
#ifndef VX_FN
#ifdef __OPENCL_VERSION__
#define VX_FN inline
#else
#define VX_FN static inline
#endif
#endif
#ifndef VX_PI_D
#define VX_PI_D 3.14159265358979323846
#endif

/* Smoothed Biot-Savart factor (Rankine-type core, as in VM2D's boundDenom):
 * a vortex Gamma at r_j induces at r
 *   V = Gamma / (2 pi) * k x (r - r_j) / max(|r - r_j|^2, eps^2),
 * i.e. (u, v) += f * (-dy, dx) / (2 pi) with f returned here. The 1/(2 pi) is
 * applied once after the sum. */
VX_FN VX_REAL VX_K(vx_bs_factor)(VX_REAL dx, VX_REAL dy, VX_REAL g, VX_REAL eps2) {
  VX_REAL r2 = dx * dx + dy * dy;
  return g / (r2 > eps2 ? r2 : eps2);
}

/* VVD weights (Dynnikova 2004, eq. (7)-(9); Andronov, Guvernyuk & Dynnikova
 * 2006): neighbour j at distance r from vortex i contributes
 *   I1 += Gamma_j exp(-r/e),   I2 += Gamma_j exp(-r/e) (r_i - r_j)/r,
 * and the diffusive velocity is W = nu (I2 / (e I1) + I3 / I0). The
 * exponential of the scaled distance is returned; the caller accumulates. */
VX_FN VX_REAL VX_K(vx_vvd_weight)(VX_REAL r, VX_REAL inv_e) { return VX_M(exp)(-r * inv_e); }

/* Mean over the segment a0 -> a1 of the tangential velocity induced by a
 * unit point vortex at (x, y): the circulation of a point vortex along a path
 * is Gamma/(2 pi) times the angle swept, so the mean is
 * Dtheta / (2 pi L), Dtheta = atan2((a0 - r) x (a1 - r), (a0 - r).(a1 - r)). */
VX_FN VX_REAL VX_K(vx_point_coef)(VX_REAL ax0, VX_REAL ay0, VX_REAL ax1, VX_REAL ay1,
                                  VX_REAL inv_len, VX_REAL x, VX_REAL y) {
  VX_REAL sx = ax0 - x, sy = ay0 - y, px = ax1 - x, py = ay1 - y;
  return VX_M(atan2)(sx * py - sy * px, sx * px + sy * py) * inv_len * (VX_REAL)(0.5 / VX_PI_D);
}

/* ((1 + x) e^-x - 1) / x^2, accurate for small x (series below 0.02). */
VX_FN VX_REAL VX_K(vx_g1)(VX_REAL x) {
  if (x < (VX_REAL)0.02)
    return (VX_REAL)(-0.5) + x * ((VX_REAL)(1.0 / 3.0) +
                                  x * ((VX_REAL)(-0.125) + x * (VX_REAL)(1.0 / 30.0)));
  return ((1 + x) * VX_M(exp)(-x) - 1) / (x * x);
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
 * 4-point Gauss-Legendre on sub-intervals of length <= max(e, |h|)/2, split
 * at the foot; both are cut at `cut` e from the foot. */
VX_FN void VX_K(vx_panel_wall)(VX_REAL s, VX_REAL h, VX_REAL L, VX_REAL e, VX_REAL cut,
                               VX_REAL *S3, VX_REAL *S0) {
  VX_REAL ta = s - cut * e, tb = s + cut * e;
  if (ta < 0) ta = 0;
  if (tb > L) tb = L;
  *S3 = 0;
  *S0 = 0;
  if (!(ta < tb)) return;
  VX_REAL inv_e = 1 / e;
  /* exact angle subtended by [ta, tb] */
  VX_REAL ang = VX_M(atan2)(h * (tb - ta), h * h + (ta - s) * (tb - s));
  VX_REAL foot = s < ta ? ta : (s > tb ? tb : s);
  VX_REAL ah = h < 0 ? -h : h;
  VX_REAL scale = (e > ah ? e : ah) * (VX_REAL)0.5;
  const VX_REAL xg0 = (VX_REAL)0.3399810435848563, xg1 = (VX_REAL)0.8611363115940526;
  const VX_REAL wg0 = (VX_REAL)0.6521451548625461, wg1 = (VX_REAL)0.3478548451374538;
  VX_REAL e3 = 0, r0 = 0;
  for (int side = 0; side < 2; ++side) {
    VX_REAL p0 = side ? foot : ta, p1 = side ? tb : foot;
    VX_REAL len = p1 - p0;
    if (!(len > 0)) continue;
    int m = (int)VX_M(ceil)(len / scale);
    if (m < 1) m = 1;
    if (m > 64) m = 64;
    VX_REAL hl = len / (VX_REAL)m * (VX_REAL)0.5;
    for (int q = 0; q < m; ++q) {
      VX_REAL c = p0 + (2 * (VX_REAL)q + 1) * hl;
      VX_REAL tq[4] = {c - xg1 * hl, c - xg0 * hl, c + xg0 * hl, c + xg1 * hl};
      VX_REAL wq[4] = {wg1, wg0, wg0, wg1};
      for (int j = 0; j < 4; ++j) {
        VX_REAL du = tq[j] - s;
        VX_REAL rho = VX_M(sqrt)(du * du + h * h);
        VX_REAL x = rho * inv_e;
        e3 += wq[j] * hl * VX_M(exp)(-x);
        r0 += wq[j] * hl * VX_K(vx_g1)(x) * inv_e * inv_e;
      }
    }
  }
  *S3 = e3;
  *S0 = ang + h * r0;
}

/* Does the segment p -> q cross the panel a -> b? If so, returns 1 and the
 * parameter along p -> q in *t (0..1). Touching counts as crossing (a vortex
 * landing exactly on the wall is absorbed). */
VX_FN int VX_K(vx_seg_cross)(VX_REAL px, VX_REAL py, VX_REAL qx, VX_REAL qy, VX_REAL ax,
                             VX_REAL ay, VX_REAL bx, VX_REAL by, VX_REAL *t) {
  VX_REAL rx = qx - px, ry = qy - py, sx = bx - ax, sy = by - ay;
  VX_REAL den = rx * sy - ry * sx;
  if (den == 0) return 0; /* parallel: a grazing move along the wall is no crossing */
  VX_REAL wx = ax - px, wy = ay - py;
  VX_REAL tp = (wx * sy - wy * sx) / den, up = (wx * ry - wy * rx) / den;
  if (tp < 0 || tp > 1 || up < 0 || up > 1) return 0;
  *t = tp;
  return 1;
}
