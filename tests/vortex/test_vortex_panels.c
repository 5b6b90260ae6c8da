/* Generation: the closed-form panel integrals against high-order quadrature,
 * and the whole linear system against potential flows known exactly; the
 * panel-crossing test of the non-penetration block. */
#include <stdio.h>
#include <string.h>

#include "partix/memory.h"
#include "px_test.h"
#include "solvers/vortex/vortex_panels.h"
#include "vortex/vx_test_util.h"

#define PX_REAL double
#include "kernels/px_kernel.h"
#include "solvers/vortex/vortex_kernel.h"

#define PI 3.14159265358979323846

/* Tanh-sinh (double exponential) quadrature of f over [a, b]; robust to
 * integrable endpoint singularities (the log of adjacent panels). */
typedef double (*fun1)(double t, const void *data);
static double tanh_sinh(fun1 f, const void *data, double a, double b) {
  const double h = 1.0 / 128.0;
  double s = 0.0, half = 0.5 * (b - a);
  for (int k = -600; k <= 600; ++k) {
    double t = k * h, u = 0.5 * PI * sinh(t);
    double w = 0.5 * PI * cosh(t) / (cosh(u) * cosh(u));
    /* distance to the nearer end, without cancellation */
    double d = 1.0 / (exp(fabs(u)) * cosh(u));
    if (d < 1e-13 || w < 1e-300) continue; /* the omitted ends weigh < 1e-12 */
    double x = (u >= 0.0) ? b - half * d : a + half * d;
    s += w * f(x, data);
  }
  return s * h * half;
}

struct seg_pair {
  double ax0, ay0, ax1, ay1, bx0, by0, bx1, by1;
};

/* tangential velocity at the point t (arc length) of the target induced by
 * the unit sheet on the source (closed-form point formula) */
static double tang_at(double t, const void *data) {
  const struct seg_pair *s = data;
  double L = hypot(s->ax1 - s->ax0, s->ay1 - s->ay0);
  double tx = (s->ax1 - s->ax0) / L, ty = (s->ay1 - s->ay0) / L;
  double u, v;
  px_vortex_segment_velocity(s->bx0, s->by0, s->bx1, s->by1, s->ax0 + t * tx, s->ay0 + t * ty, &u,
                             &v);
  return u * tx + v * ty;
}

static double coef_quadrature(const struct seg_pair *s) {
  double L = hypot(s->ax1 - s->ax0, s->ay1 - s->ay0);
  return tanh_sinh(tang_at, s, 0.0, L) / L;
}

/* brute-force Biot-Savart of the unit sheet at a point (Gauss-Legendre on
 * many sub-intervals) to check the point formula itself */
static void sheet_velocity_brute(const struct seg_pair *s, double x, double y, double *u,
                                 double *v) {
  static const double xg[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                               0.8611363115940526};
  static const double wg[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                               0.3478548451374538};
  double L = hypot(s->bx1 - s->bx0, s->by1 - s->by0);
  int m = 4000;
  *u = *v = 0.0;
  for (int j = 0; j < m; ++j)
    for (int q = 0; q < 4; ++q) {
      double f = (j + 0.5 * (1.0 + xg[q])) / m;
      double px = s->bx0 + f * (s->bx1 - s->bx0), py = s->by0 + f * (s->by1 - s->by0);
      double dx = x - px, dy = y - py, r2 = dx * dx + dy * dy;
      double w = 0.5 * wg[q] * L / m / (2.0 * PI * r2);
      *u += -dy * w;
      *v += dx * w;
    }
}

static void test_closed_form(void) {
  /* point formula vs brute force */
  struct seg_pair s = {0, 0, 0, 0, 0.1, -0.2, 0.9, 0.3};
  double pts[4][2] = {{0.5, 0.5}, {0.2, -0.4}, {1.5, 0.1}, {-0.3, 0.05}};
  for (int p = 0; p < 4; ++p) {
    double u, v, ub, vb;
    px_vortex_segment_velocity(s.bx0, s.by0, s.bx1, s.by1, pts[p][0], pts[p][1], &u, &v);
    sheet_velocity_brute(&s, pts[p][0], pts[p][1], &ub, &vb);
    PX_CHECK_NEAR(u, ub, 1e-10);
    PX_CHECK_NEAR(v, vb, 1e-10);
  }
  /* limits on the sheet: tangential jump -1/2 on the left (inner) side */
  double u, v;
  px_vortex_segment_velocity(0, 0, 1, 0, 0.5, 1e-12, &u, &v);
  PX_CHECK_NEAR(u, -0.5, 1e-9);
  px_vortex_segment_velocity(0, 0, 1, 0, 0.5, -1e-12, &u, &v);
  PX_CHECK_NEAR(u, 0.5, 1e-9);

  /* panel-averaged coefficient: closed form vs tanh-sinh of the point formula */
  struct seg_pair cases[] = {
      /* adjacent: target follows the source at various turning angles */
      {1, 0, 1.5, 0.4, 0, 0, 1, 0},
      {1, 0, 0.2, 0.3, 0, 0, 1, 0},  /* sharp fold (acute) */
      {1, 0, 2.0, 0.0, 0, 0, 1, 0},  /* collinear */
      {1, 0, 1.3, -0.8, 0, 0, 1, 0}, /* turning right */
      /* adjacent: target precedes the source */
      {-0.5, 0.7, 0, 0, 0, 0, 1, 0},
      {-1.0, 0.0, 0, 0, 0, 0, 1, 0}, /* collinear before */
      {0.8, -0.3, 0, 0, 0, 0, 1, 0}, /* acute, below */
      /* close but separate, parallel and crossing the cut x < 0 */
      {0.3, 0.01, 0.7, 0.01, 0, 0, 1, 0},
      {-0.2, 0.3, -0.2, -0.3, 0, 0, 1, 0}, /* crosses the axis left of the source */
      {1.2, 0.3, 1.2, -0.3, 0, 0, 1, 0},   /* crosses right of the source */
      {-0.5, -0.2, -0.1, 0.4, 0, 0, 1, 0},
      /* different lengths, rotated frames */
      {0.3, 0.9, 0.35, 0.95, 0.1, 0.2, 0.5, 0.8},
      {2.0, 1.0, 1.0, 2.5, -0.3, 0.1, 0.2, -0.6},
      /* far (Gauss branch) */
      {30.0, 1.0, 31.0, 1.5, 0, 0, 1, 0},
  };
  size_t nc = sizeof cases / sizeof cases[0];
  for (size_t c = 0; c < nc; ++c) {
    struct seg_pair *p = &cases[c];
    double cf =
        px_vortex_segment_coef(p->ax0, p->ay0, p->ax1, p->ay1, p->bx0, p->by0, p->bx1, p->by1);
    double q = coef_quadrature(p);
    PX_CHECK_MSG(fabs(cf - q) <= 1e-9 * fmax(1.0, fabs(q)),
                 "case %zu: closed form %.15g, quadrature %.15g", c, cf, q);
  }
  /* the Gauss branch against the closed form at the switch distance */
  double d = 8.0 * 2.0 + 0.5;
  double g = px_vortex_segment_coef(d, 0.3, d + 1.0, 0.8, 0, 0, 1, 0);
  struct seg_pair far = {d, 0.3, d + 1.0, 0.8, 0, 0, 1, 0};
  PX_CHECK_REL(g, coef_quadrature(&far), 1e-7);

  /* point vortex mean over a panel = quadrature of the point-vortex field */
  double pc = px_vortex_point_coef(0, 0, 1, 0.2, 0.4, 0.3);
  double sum = 0.0;
  int m = 20000;
  double L = hypot(1.0, 0.2), tx = 1.0 / L, ty = 0.2 / L;
  for (int j = 0; j < m; ++j) {
    double t = (j + 0.5) / m * L, x = t * tx - 0.4, y = t * ty - 0.3, r2 = x * x + y * y;
    sum += (-y * tx + x * ty) / (2.0 * PI * r2);
  }
  PX_CHECK_NEAR(pc, sum / m, 1e-7);
}

/* Potential flow around a circle: sheet intensity = slip velocity outside,
 * gamma = -2 V sin(theta) on a counter-clockwise contour (spec table: within
 * 1% at n = 200). */
static void test_circle_potential(struct px_context *ctx) {
  struct px_vortex_contour c;
  PX_CHECK_OK(ctx, px_vortex_profile_circle(ctx, 1.0, 200, &c));
  struct px_vortex_panels p;
  PX_CHECK_OK(ctx, px_vortex_panels_build(ctx, &c, 1, &p));
  PX_CHECK_OK(ctx, px_vortex_panels_factor(ctx, &p, 1));
  double *rhs = px_mem_alloc(ctx, "test", p.nsys * sizeof(double));
  float *rhsf = px_mem_alloc(ctx, "test", p.nsys * sizeof(float));
  const double V = 1.0;
  for (size_t i = 0; i < p.n; ++i) rhs[i] = -(V * p.tx[i]);
  rhs[p.n] = 0.0;
  for (size_t i = 0; i < p.nsys; ++i) rhsf[i] = (float)rhs[i];
  double *rhs1 = px_mem_alloc(ctx, "test", p.nsys * sizeof(double));
  memcpy(rhs1, rhs, p.nsys * sizeof(double));
  PX_CHECK_OK(ctx, px_vortex_panels_solve(ctx, &p, rhs, 2));
  /* the product's rows are split over the threads, each summed alike */
  PX_CHECK_OK(ctx, px_vortex_panels_solve(ctx, &p, rhs1, 1));
  PX_CHECK(memcmp(rhs1, rhs, p.nsys * sizeof(double)) == 0);
  px_mem_free(ctx, rhs1);
  PX_CHECK_OK(ctx, px_vortex_panels_solve_f(ctx, &p, rhsf));
  double err = 0.0, errf = 0.0, circ = 0.0;
  for (size_t k = 0; k < p.n; ++k) {
    double th = atan2(0.5 * (p.y0[k] + p.y1[k]), 0.5 * (p.x0[k] + p.x1[k]));
    double exact = -2.0 * V * sin(th);
    err = fmax(err, fabs(rhs[k] - exact));
    errf = fmax(errf, fabs(rhsf[k] - exact));
    circ += rhs[k] * p.len[k];
  }
  printf("circle n=200: max |gamma - 2V sin| = %.3g V (%.3g%% of the peak), float %.3g V\n", err,
         50.0 * err, errf);
  PX_CHECK_MSG(err <= 0.01 * 2.0 * V, "surface speed off by %g", err);
  PX_CHECK_MSG(errf <= 0.01 * 2.0 * V, "float surface speed off by %g", errf);
  PX_CHECK_NEAR(circ, 0.0, 1e-12);
  PX_CHECK_NEAR(rhs[p.n], 0.0, 1e-10); /* regularizer vanishes */

  /* the same flow plus a point vortex outside: circle theorem (Milne-Thomson):
   * image -G at a^2/conj(z0) and +G at the centre keep the body circulation
   * zero. The slip velocity outside equals the tangential velocity of the
   * exact flow on the contour. */
  double G = 0.7, zx = 1.6, zy = 0.5;
  double r2 = zx * zx + zy * zy, ix = zx / r2, iy = zy / r2;
  for (size_t i = 0; i < p.n; ++i)
    rhs[i] = -(V * p.tx[i]) - G * px_vortex_point_coef(p.x0[i], p.y0[i], p.x1[i], p.y1[i], zx, zy);
  rhs[p.n] = 0.0;
  PX_CHECK_OK(ctx, px_vortex_panels_solve(ctx, &p, rhs, 2));
  err = 0.0;
  for (size_t k = 0; k < p.n; ++k) {
    /* exact tangential velocity, averaged over the panel (midpoint rule on
     * 64 sub-points of the chord, radially projected to the circle) */
    double s = 0.0;
    for (int q = 0; q < 64; ++q) {
      double f = (q + 0.5) / 64.0;
      double x = p.x0[k] + f * (p.x1[k] - p.x0[k]), y = p.y0[k] + f * (p.y1[k] - p.y0[k]);
      double th = atan2(y, x), cx = cos(th), cy = sin(th);
      double u = V * (1.0 - cos(2.0 * th)), v = -V * sin(2.0 * th); /* uniform flow on r = 1 */
      double srcs[3][3] = {{zx, zy, G}, {ix, iy, -G}, {0.0, 0.0, G}};
      for (int j = 0; j < 3; ++j) {
        double dx = cx - srcs[j][0], dy = cy - srcs[j][1], d2 = dx * dx + dy * dy;
        u += -srcs[j][2] * dy / (2.0 * PI * d2);
        v += srcs[j][2] * dx / (2.0 * PI * d2);
      }
      s += u * (-cy) + v * cx; /* tangent of the counter-clockwise circle */
    }
    err = fmax(err, fabs(rhs[k] - s / 64.0));
  }
  printf("circle + vortex: max |gamma - exact slip| = %.3g V\n", err);
  PX_CHECK_MSG(err <= 0.01 * 2.0 * V, "slip with a vortex off by %g", err);
  px_mem_free(ctx, rhs);
  px_mem_free(ctx, rhsf);
  px_vortex_panels_free(ctx, &p);
  px_vortex_contour_free(ctx, &c);
}

/* Two bodies: each keeps its own circulation (the absorbed one). */
static void test_two_bodies(struct px_context *ctx) {
  struct px_vortex_contour c[2];
  PX_CHECK_OK(ctx, px_vortex_profile_circle(ctx, 0.5, 100, &c[0]));
  PX_CHECK_OK(ctx, px_vortex_profile_ellipse(ctx, 0.5, 0.2, 120, &c[1]));
  px_vortex_profile_place(&c[1], 2.0, 0.3, 1.0, 20.0);
  struct px_vortex_panels p;
  PX_CHECK_OK(ctx, px_vortex_panels_build(ctx, c, 2, &p));
  PX_CHECK(p.n == 220 && p.nsys == 222 && p.first[1] == 100);
  PX_CHECK_OK(ctx, px_vortex_panels_factor(ctx, &p, 0));
  double *rhs = px_mem_alloc(ctx, "test", p.nsys * sizeof(double));
  for (size_t i = 0; i < p.n; ++i) rhs[i] = -p.tx[i];
  rhs[p.n] = 0.3;
  rhs[p.n + 1] = -0.1;
  PX_CHECK_OK(ctx, px_vortex_panels_solve(ctx, &p, rhs, 2));
  double c0 = 0.0, c1 = 0.0;
  for (size_t k = 0; k < p.n; ++k) *(p.body[k] == 0 ? &c0 : &c1) += rhs[k] * p.len[k];
  PX_CHECK_NEAR(c0, 0.3, 1e-12);
  PX_CHECK_NEAR(c1, -0.1, 1e-12);
  PX_CHECK(fabs(rhs[p.n]) < 1e-6 && fabs(rhs[p.n + 1]) < 1e-6);
  px_mem_free(ctx, rhs);
  px_vortex_panels_free(ctx, &p);
  px_vortex_contour_free(ctx, &c[0]);
  px_vortex_contour_free(ctx, &c[1]);
}

/* The compressed inverse (px_vortex_panels_compress) against the dense
 * product: a NACA 0012 (sharp trailing edge, where the two surfaces' blocks
 * have full rank and stay dense) and, as one system, a circle and an
 * ellipse (two bodies: their rows and columns); the same bits on 1 and 2
 * threads; px_vortex_panels_solve uses it; too few panels: none. */
static void test_compressed(struct px_context *ctx) {
  for (int cs = 0; cs < 2; ++cs) {
    struct px_vortex_contour c[2];
    size_t nb = 1;
    if (cs == 0) {
      PX_CHECK_OK(ctx, px_vortex_profile_naca4(ctx, "0012", 1200, &c[0]));
    } else {
      nb = 2;
      PX_CHECK_OK(ctx, px_vortex_profile_circle(ctx, 0.5, 700, &c[0]));
      PX_CHECK_OK(ctx, px_vortex_profile_ellipse(ctx, 0.5, 0.2, 500, &c[1]));
      px_vortex_profile_place(&c[1], 1.2, 0.3, 1.0, 20.0);
    }
    struct px_vortex_panels p;
    PX_CHECK_OK(ctx, px_vortex_panels_build(ctx, c, nb, &p));
    PX_CHECK_OK(ctx, px_vortex_panels_factor(ctx, &p, 0));
    PX_CHECK_OK(ctx, px_vortex_panels_compress(ctx, &p));
    PX_CHECK_MSG(p.hodlr != NULL, "case %d: no compressed inverse", cs);
    for (int once = p.hodlr != NULL; once; once = 0) {
      const size_t ns = p.nsys, dense = ns * ns * sizeof(double);
      printf("compressed inverse, case %d: %zu of %zu bytes, checked at %.2g\n", cs,
             px_vortex_hodlr_bytes(p.hodlr), dense, px_vortex_hodlr_check(p.hodlr));
      PX_CHECK(2 * px_vortex_hodlr_bytes(p.hodlr) <= dense);
      double *x = px_mem_alloc(ctx, "test", 4 * ns * sizeof(double));
      PX_CHECK(x != NULL);
      double *y1 = x + ns, *y2 = y1 + ns, *yd = y2 + ns, worst = 0.0;
      unsigned long long sd = 1234 + (unsigned long long)cs;
      for (int v = 0; v < 4; ++v) {
        for (size_t i = 0; i < ns; ++i) x[i] = vx_test_urand(&sd) - 0.5 + (v == 3 ? 3.0 : 0.0);
        double ymax = 0.0, err = 0.0;
        for (size_t i = 0; i < ns; ++i) {
          double s = 0.0;
          for (size_t j = 0; j < ns; ++j) s += p.ainv[i * ns + j] * x[j];
          yd[i] = s;
          ymax = fmax(ymax, fabs(s));
        }
        px_vortex_hodlr_apply(p.hodlr, x, y1, 1);
        px_vortex_hodlr_apply(p.hodlr, x, y2, 2);
        PX_CHECK_MSG(memcmp(y1, y2, ns * sizeof(double)) == 0, "1 and 2 threads differ");
        for (size_t i = 0; i < ns; ++i) err = fmax(err, fabs(y1[i] - yd[i]));
        worst = fmax(worst, err / ymax);
        /* the solve goes through it */
        memcpy(y2, x, ns * sizeof(double));
        PX_CHECK_OK(ctx, px_vortex_panels_solve(ctx, &p, y2, 2));
        PX_CHECK(memcmp(y1, y2, ns * sizeof(double)) == 0);
      }
      printf("  largest difference to the dense product %.3g of the largest entry\n", worst);
      PX_CHECK_MSG(worst < 1e-13, "compressed product off by %.3g", worst);
      px_mem_free(ctx, x);
    }
    px_vortex_panels_free(ctx, &p);
    for (size_t b = 0; b < nb; ++b) px_vortex_contour_free(ctx, &c[b]);
  }
  struct px_vortex_contour c;
  PX_CHECK_OK(ctx, px_vortex_profile_circle(ctx, 0.5, 100, &c));
  struct px_vortex_panels p;
  PX_CHECK_OK(ctx, px_vortex_panels_build(ctx, &c, 1, &p));
  PX_CHECK_OK(ctx, px_vortex_panels_factor(ctx, &p, 0));
  PX_CHECK_OK(ctx, px_vortex_panels_compress(ctx, &p));
  PX_CHECK(p.hodlr == NULL);
  px_vortex_panels_free(ctx, &p);
  px_vortex_contour_free(ctx, &c);
}

/* vx_seg_cross: crossings inside the segment and the panel, none beside
 * them; a start on the panel's line (a newborn vortex with delta = 0, placed
 * at a + f (b - a), off the line by rounding only) is on the flow side: no
 * crossing when it leaves towards the outward normal (t_y, -t_x), a
 * crossing at t = 0 when it heads into the body, whatever the sign of the
 * rounding. */
static void test_seg_cross(void) {
  double t = -1.0;
  /* panel (0,0) -> (1,0): outward normal (0, -1) */
  PX_CHECK(vx_seg_cross(0.5, -0.1, 0.5, 0.1, 0.0, 0.0, 1.0, 0.0, &t) && fabs(t - 0.5) < 1e-15);
  PX_CHECK(!vx_seg_cross(1.5, -0.1, 1.5, 0.1, 0.0, 0.0, 1.0, 0.0, &t));  /* beside the panel */
  PX_CHECK(!vx_seg_cross(0.5, -0.3, 0.5, -0.1, 0.0, 0.0, 1.0, 0.0, &t)); /* short of it */
  PX_CHECK(vx_seg_cross(0.5, -0.1, 0.5, 0.0, 0.0, 0.0, 1.0, 0.0, &t) && t == 1.0); /* lands on it */
  PX_CHECK(!vx_seg_cross(0.3, 0.0, 0.3, -0.1, 0.0, 0.0, 1.0, 0.0, &t));            /* leaves it */
  PX_CHECK(vx_seg_cross(0.3, 0.0, 0.3, 0.1, 0.0, 0.0, 1.0, 0.0, &t) && t == 0.0);  /* enters */
  /* slanted panels, starts computed on them */
  int leave_crossed = 0, enter_missed = 0, tried = 0;
  for (int k = 0; k < 50; ++k) {
    double ax = 0.1 + 0.37 * k, ay = 0.7 - 0.11 * k, ang = 0.1 + 0.123 * k, len = 0.013 * (k + 1);
    double bx = ax + len * cos(ang), by = ay + len * sin(ang);
    double tx = (bx - ax) / len, ty = (by - ay) / len;
    for (int q = 1; q < 100; ++q) {
      double f = q / 100.0, px = ax + f * (bx - ax), py = ay + f * (by - ay);
      double d = 0.3 * len; /* a move of 0.3 panel lengths, slanted */
      leave_crossed += vx_seg_cross(px, py, px + d * (ty + 0.2 * tx), py + d * (-tx + 0.2 * ty), ax,
                                    ay, bx, by, &t);
      enter_missed += !vx_seg_cross(px, py, px - d * (ty - 0.2 * tx), py - d * (-tx - 0.2 * ty), ax,
                                    ay, bx, by, &t) ||
                      t != 0.0;
      ++tried;
    }
  }
  printf("seg_cross: %d starts on a panel: %d absorbed when leaving, %d missed when entering\n",
         tried, leave_crossed, enter_missed);
  PX_CHECK(leave_crossed == 0);
  PX_CHECK(enter_missed == 0);
}

/* A vortex on a panel (computed on it: rounding puts it on either side)
 * induces the flow side's limit: the panel-mean tangential velocity
 * vx_point_coef -> -1/(2L) (the angle -pi) and the sheet's own velocity
 * vx_sheet_velocity -> +1/2 along the panel, as a point 1e-9 L off the
 * panel on the outward side (t_y, -t_x) does; rk2's predictor holds
 * vortices there (delta = 0), and the sign of the rounding differed between
 * the cpu and the OpenCL builds. */
static void test_on_panel(void) {
  int bad_coef = 0, bad_sheet = 0, tried = 0;
  double worst = 0.0;
  for (int k = 0; k < 50; ++k) {
    double ax = 0.1 + 0.37 * k, ay = 0.7 - 0.11 * k, ang = 0.1 + 0.123 * k, len = 0.013 * (k + 1);
    double bx = ax + len * cos(ang), by = ay + len * sin(ang);
    double tx = (bx - ax) / len, ty = (by - ay) / len, inv = 1.0 / len;
    for (int q = 1; q < 100; ++q) {
      double f = q / 100.0, px = ax + f * (bx - ax), py = ay + f * (by - ay);
      double ox = px + 1e-9 * len * ty, oy = py - 1e-9 * len * tx; /* off it, flow side */
      double c = vx_point_coef(ax, ay, bx, by, inv, px, py);
      double c_off = vx_point_coef(ax, ay, bx, by, inv, ox, oy);
      px_real2 u = vx_sheet_velocity(ax, ay, bx, by, px, py);
      px_real2 u_off = vx_sheet_velocity(ax, ay, bx, by, ox, oy);
      double ut = u.x * tx + u.y * ty, ut_off = u_off.x * tx + u_off.y * ty;
      bad_coef += fabs(c - c_off) > 1e-6 * inv;
      bad_sheet += fabs(ut - ut_off) > 1e-6;
      worst = fmax(worst, fmax(fabs(c - c_off) / inv, fabs(ut - ut_off)));
      ++tried;
    }
  }
  printf(
      "on a panel: %d points, %d panel means and %d sheet velocities off the flow side's "
      "limit (largest difference %.2e)\n",
      tried, bad_coef, bad_sheet, worst);
  PX_CHECK(bad_coef == 0);
  PX_CHECK(bad_sheet == 0);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  test_closed_form();
  test_circle_potential(ctx);
  test_two_bodies(ctx);
  test_compressed(ctx);
  test_seg_cross();
  test_on_panel();
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  return px_test_report("test_vortex_panels");
}
