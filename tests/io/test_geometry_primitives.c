/* Solver-neutral geometry primitives (io/geometry): the built-in closed
 * shapes against their analytic area, perimeter and orientation (circle,
 * ellipse, plate, NACA 4-digit), the polyline helpers, the primitives of a
 * path (length, ends, reversal, copies of points), and clear messages for
 * bad parameters. */
#include <string.h>

#include "io/geometry/geo_path.h"
#include "io/geometry/geo_polyline.h"
#include "io/geometry/geo_shape.h"
#include "px_test.h"

#define PI 3.14159265358979323846

static double edge(const struct px_geo_polyline *p, size_t k) {
  size_t j = (k + 1) % p->n;
  return hypot(p->x[j] - p->x[k], p->y[j] - p->y[k]);
}

/* Largest over smallest edge length. */
static double edge_ratio(const struct px_geo_polyline *p) {
  double lo = INFINITY, hi = 0;
  for (size_t k = 0; k < p->n; ++k) {
    lo = fmin(lo, edge(p, k));
    hi = fmax(hi, edge(p, k));
  }
  return hi / lo;
}

static int message_has(struct px_context *ctx, const char *text) {
  return strstr(px_context_message(ctx), text) != NULL;
}

/* The inscribed regular n-gon of radius r: area n r^2 sin(2 pi / n) / 2,
 * perimeter 2 n r sin(pi / n), counter-clockwise, every vertex at r. */
static void test_circle_is_a_regular_polygon(struct px_context *ctx) {
  struct px_geo_polyline p;
  const double r = 0.75;
  const size_t n = 90;
  PX_CHECK_OK(ctx, px_geo_shape_circle(ctx, r, n, &p));
  PX_CHECK(p.n == n && p.line == NULL && strcmp(p.source, "circle") == 0);
  PX_CHECK_REL(px_geo_polyline_area(&p), 0.5 * (double)n * r * r * sin(2 * PI / (double)n), 1e-13);
  PX_CHECK_REL(px_geo_polyline_perimeter(&p), 2 * (double)n * r * sin(PI / (double)n), 1e-13);
  for (size_t k = 0; k < n; ++k) PX_CHECK_NEAR(hypot(p.x[k], p.y[k]), r, 1e-15);
  PX_CHECK_NEAR(p.x[0], r, 0);
  PX_CHECK_NEAR(p.y[0], 0, 0);
  px_geo_polyline_free(ctx, &p);
  PX_CHECK(p.n == 0 && p.x == NULL);
}

/* An ellipse of semi-axes a, b: vertices on the curve, area -> pi a b and
 * perimeter -> Ramanujan's (error O(1/n^2) of an inscribed polygon),
 * counter-clockwise, edges of equal length. */
static void test_ellipse_area_perimeter_spacing(struct px_context *ctx) {
  struct px_geo_polyline p;
  const double a = 1.0, b = 0.25;
  const double h = (a - b) * (a - b) / ((a + b) * (a + b));
  const double ramanujan = PI * (a + b) * (1 + 3 * h / (10 + sqrt(4 - 3 * h)));
  PX_CHECK_OK(ctx, px_geo_shape_ellipse(ctx, a, b, 400, &p));
  PX_CHECK(p.n == 400 && strcmp(p.source, "ellipse") == 0);
  PX_CHECK_REL(px_geo_polyline_area(&p), PI * a * b, 1e-4);
  PX_CHECK_REL(px_geo_polyline_perimeter(&p), ramanujan, 1e-4);
  PX_CHECK(px_geo_polyline_area(&p) < PI * a * b); /* inscribed */
  for (size_t k = 0; k < p.n; ++k) {
    const double e = p.x[k] * p.x[k] / (a * a) + p.y[k] * p.y[k] / (b * b);
    PX_CHECK_NEAR(e, 1.0, 1e-6); /* on the 64 n-gon: within its sagitta */
  }
  {
    /* equal arcs s: a chord is s (1 - k^2 s^2 / 24) at curvature k, which
     * is largest (a / b^2) at the ends of the major axis */
    const double sk = ramanujan / 400 * a / (b * b);
    PX_CHECK(edge_ratio(&p) < 1 + 1.05 * sk * sk / 24);
    PX_CHECK(edge_ratio(&p) > 1 + 0.9 * sk * sk / 24);
  }
  px_geo_polyline_free(ctx, &p);
}

/* A stadium of length L and thickness t: area (L - t) t + pi t^2 / 4,
 * perimeter 2 (L - t) + pi t, vertices equally spaced along it. */
static void test_plate_is_a_stadium(struct px_context *ctx) {
  struct px_geo_polyline p;
  const double L = 1.0, t = 0.1, h = 0.5 * t;
  PX_CHECK_OK(ctx, px_geo_shape_plate(ctx, L, t, 800, &p));
  PX_CHECK(strcmp(p.source, "plate 1 x 0.1") == 0);
  PX_CHECK_REL(px_geo_polyline_area(&p), (L - t) * t + PI * h * h, 1e-4);
  PX_CHECK_REL(px_geo_polyline_perimeter(&p), 2 * (L - t) + PI * t, 1e-4);
  for (size_t k = 0; k < p.n; ++k) {
    /* distance to the core segment [-(L/2 - h), L/2 - h] x {0} is h */
    const double cx = fmax(-(0.5 * L - h), fmin(0.5 * L - h, p.x[k]));
    PX_CHECK_NEAR(hypot(p.x[k] - cx, p.y[k]), h, 1e-12);
  }
  PX_CHECK(edge_ratio(&p) < 1.01);
  px_geo_polyline_free(ctx, &p);
}

/* NACA 0012: symmetric, trailing edge (1, 0) first, leading edge (0, 0) at
 * vertex n/2, area 2 int_0^1 y_t dx = 10 t (0.2969 2/3 - 0.1260/2 - 0.3516/3
 * + 0.2843/4 - 0.1036/5), thickest near x = 0.3 with 2 y_t = t. */
static void test_naca4_symmetric_section(struct px_context *ctx) {
  struct px_geo_polyline p;
  const double t = 0.12;
  const double area = 10 * t * (0.2969 * 2 / 3 - 0.1260 / 2 - 0.3516 / 3 + 0.2843 / 4 - 0.1036 / 5);
  double thick = 0;
  const size_t n = 400;
  PX_CHECK_OK(ctx, px_geo_shape_naca4(ctx, "0012", n, &p));
  PX_CHECK(p.n == n && strcmp(p.source, "naca 0012") == 0);
  PX_CHECK_NEAR(p.x[0], 1.0, 1e-15);
  PX_CHECK_NEAR(p.y[0], 0.0, 1e-15);
  PX_CHECK_NEAR(p.x[n / 2], 0.0, 1e-15);
  PX_CHECK_NEAR(p.y[n / 2], 0.0, 1e-15);
  for (size_t k = 1; k < n / 2; ++k) {
    PX_CHECK_NEAR(p.x[k], p.x[n - k], 1e-15);
    PX_CHECK_NEAR(p.y[k], -p.y[n - k], 1e-15);
    PX_CHECK(p.y[k] > 0);
    thick = fmax(thick, 2 * p.y[k]);
  }
  PX_CHECK_REL(thick, t, 1e-3);
  PX_CHECK_REL(px_geo_polyline_area(&p), area, 1e-3);
  px_geo_polyline_free(ctx, &p);
  /* a cambered 2412 is counter-clockwise too, its camber line above y = 0 */
  PX_CHECK_OK(ctx, px_geo_shape_naca4(ctx, "2412", 100, &p));
  PX_CHECK(px_geo_polyline_area(&p) > 0);
  PX_CHECK(p.y[25] + p.y[75] > 0);
  px_geo_polyline_free(ctx, &p);
}

static void test_resample_equal_arc_length(struct px_context *ctx) {
  /* a unit square resampled to 8 points: the corners and the midpoints */
  const double sx[4] = {0, 1, 1, 0}, sy[4] = {0, 0, 1, 1};
  const double ex[8] = {0, 0.5, 1, 1, 1, 0.5, 0, 0}, ey[8] = {0, 0, 0, 0.5, 1, 1, 1, 0.5};
  double x[8], y[8];
  (void)ctx;
  px_geo_polyline_resample(4, sx, sy, 8, x, y);
  for (int k = 0; k < 8; ++k) {
    PX_CHECK_NEAR(x[k], ex[k], 1e-15);
    PX_CHECK_NEAR(y[k], ey[k], 1e-15);
  }
}

static void test_bad_shape_parameters(struct px_context *ctx) {
  struct px_geo_polyline p;
  PX_CHECK_STATUS(ctx, px_geo_shape_circle(ctx, -1.0, 100, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "circle: radius must be > 0 (got -1)"));
  PX_CHECK_STATUS(ctx, px_geo_shape_circle(ctx, 1.0, 2, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "circle: 2 vertices is too few (at least 3)"));
  PX_CHECK_STATUS(ctx, px_geo_shape_ellipse(ctx, 1.0, NAN, 100, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "ellipse: semi-axes must be > 0"));
  PX_CHECK_STATUS(ctx, px_geo_shape_plate(ctx, 0.1, 0.2, 100, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "plate: need 0 < thickness < length (got length 0.1, thickness 0.2)"));
  PX_CHECK_STATUS(ctx, px_geo_shape_naca4(ctx, "00x2", 100, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "naca: expected 4 digits such as \"0012\" or \"2412\" (got \"00x2\")"));
  PX_CHECK_STATUS(ctx, px_geo_shape_naca4_digits(ctx, "12345"), PX_STATUS_CONFIG);
  PX_CHECK_OK(ctx, px_geo_shape_naca4_digits(ctx, "4415"));
  PX_CHECK_STATUS(ctx, px_geo_shape_naca4(ctx, "0012", 101, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "naca: the number of panels must be even (got 101)"));
  PX_CHECK_STATUS(ctx, px_geo_shape_naca4(ctx, "0000", 100, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "naca 0000: zero thickness"));
  PX_CHECK_STATUS(ctx, px_geo_shape_naca4(ctx, "2012", 100, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "camber and its position must both be zero or both non-zero"));
  PX_CHECK(p.n == 0 && p.x == NULL); /* a failed shape holds nothing */
}

/* Primitives: lengths against closed forms, ends, reversal. */
static void test_path_primitives(struct px_context *ctx) {
  struct px_geo_prim q;
  struct px_geo_path path;
  double x0, y0, x1, y1;
  memset(&q, 0, sizeof q);
  q.kind = PX_GEO_PRIM_LINE;
  q.p[0] = 1, q.p[1] = 2, q.p[2] = 4, q.p[3] = 6;
  PX_CHECK_NEAR(px_geo_prim_length(&q), 5.0, 1e-15);
  px_geo_prim_reverse(&q);
  px_geo_prim_ends(&q, &x0, &y0, &x1, &y1);
  PX_CHECK(x0 == 4 && y0 == 6 && x1 == 1 && y1 == 2);
  /* a clockwise quarter arc of radius 2 about (1, 1): from (3, 1) to (1, -1) */
  q.kind = PX_GEO_PRIM_ARC;
  q.p[0] = 1, q.p[1] = 1, q.p[2] = 2, q.p[3] = 0, q.p[4] = -PI / 2;
  PX_CHECK_REL(px_geo_prim_length(&q), PI, 1e-15);
  px_geo_prim_ends(&q, &x0, &y0, &x1, &y1);
  PX_CHECK_NEAR(x0, 3, 1e-15);
  PX_CHECK_NEAR(y0, 1, 1e-15);
  PX_CHECK_NEAR(x1, 1, 1e-15);
  PX_CHECK_NEAR(y1, -1, 1e-15);
  /* a full ellipse with equal semi-axes 0.5, rotated: circumference pi */
  q.kind = PX_GEO_PRIM_ELLIPSE;
  q.p[0] = 0, q.p[1] = 0, q.p[2] = 0.5, q.p[3] = 0.5, q.p[4] = 0.3, q.p[5] = 0, q.p[6] = 2 * PI;
  PX_CHECK_REL(px_geo_prim_length(&q), PI, 1e-6); /* 2048 chords: (pi/2048)^2 / 6 */
  /* the parabola y = x^2 from (0, 0) to (1, 1): control (0.5, 0); length
   * sqrt(5)/2 + asinh(2)/4 */
  q.kind = PX_GEO_PRIM_BEZIER2;
  q.p[0] = 0, q.p[1] = 0, q.p[2] = 0.5, q.p[3] = 0, q.p[4] = 1, q.p[5] = 1;
  PX_CHECK_REL(px_geo_prim_length(&q), sqrt(5.0) / 2 + asinh(2.0) / 4, 1e-6);
  /* points are copied into the path: changing the caller's array later
   * changes nothing; reversal reverses them */
  {
    double xy[6] = {0, 0, 3, 4, 3, 0};
    px_geo_path_init(&path, "test:1");
    PX_CHECK_OK(ctx, px_geo_path_add_points(ctx, &path, xy, 3, 0));
    xy[2] = 100;
    PX_CHECK(path.n == 1 && path.prims[0].pts != xy && path.prims[0].pts[2] == 3);
    PX_CHECK_NEAR(px_geo_prim_length(&path.prims[0]), 9.0, 1e-15);
    px_geo_prim_reverse(&path.prims[0]);
    px_geo_prim_ends(&path.prims[0], &x0, &y0, &x1, &y1);
    PX_CHECK(x0 == 3 && y0 == 0 && x1 == 0 && y1 == 0);
    px_geo_prim_eval(&path.prims[0], 0.5, &x0, &y0);
    PX_CHECK(x0 == 3 && y0 == 4); /* the middle point */
    PX_CHECK(strcmp(path.where, "test:1") == 0);
    px_geo_path_free(ctx, &path);
    PX_CHECK(path.n == 0 && path.prims == NULL);
  }
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  const size_t held = px_mem_current(ctx, NULL);
  test_circle_is_a_regular_polygon(ctx);
  test_ellipse_area_perimeter_spacing(ctx);
  test_plate_is_a_stadium(ctx);
  test_naca4_symmetric_section(ctx);
  test_resample_equal_arc_length(ctx);
  test_bad_shape_parameters(ctx);
  test_path_primitives(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == held); /* nothing left allocated */
  px_context_free(ctx);
  return px_test_report("test_geometry_primitives");
}
