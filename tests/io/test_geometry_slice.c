/* Plane sections of closed meshes (io/geometry/geo_mesh.h) against the
 * exact sections of the faceted solids, within 1e-9 relative: a box cut
 * across (a rectangle), obliquely (a regular hexagon), through three
 * vertices (a triangle) and through two edges (a rectangle); a 64-sided
 * prism cut across (the 64-gon) and along its axis through vertices (a
 * rectangle); a torus cut through its equator's vertices (two 48-gons, the
 * inner one a clockwise hole) and through its axis (two 24-gons). Planes
 * that miss the part, touch it at a vertex or an edge, or lie on a face
 * from outside give nothing; on a face from inside, the face. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io/geometry/geo_mesh.h"
#include "px_test.h"
#include "px_test_mesh.h"

#define RTOL 1e-9

static void load(struct px_context *ctx, const struct tm_soup *s, struct px_geo_mesh *m) {
  size_t len;
  char *t = tm_stl_ascii(s, &len);
  PX_CHECK_OK(ctx, px_geo_mesh_parse(ctx, "solid.stl", t, len, 0, 0, m));
  PX_CHECK_OK(ctx, px_geo_mesh_check(ctx, m));
  free(t);
}

struct cut {
  size_t n;       /* contours */
  double area[8]; /* signed, per contour (by decreasing |area|) */
  double perim[8];
};

static struct cut slice(struct px_context *ctx, const struct px_geo_mesh *m, const double normal[3],
                        const double hint[3], double offset) {
  struct cut c;
  struct px_geo_polyline *p = NULL;
  double u[3], v[3], n[3];
  memset(&c, 0, sizeof c);
  PX_CHECK_OK(ctx, px_geo_mesh_frame(ctx, normal, hint, u, v, n));
  PX_CHECK_OK(ctx, px_geo_mesh_slice(ctx, m, u, v, n, offset, &p, &c.n));
  for (size_t i = 0; i < c.n && i < 8; ++i) {
    c.area[i] = px_geo_polyline_area(&p[i]);
    c.perim[i] = px_geo_polyline_perimeter(&p[i]);
    for (size_t j = i; j > 0 && fabs(c.area[j]) > fabs(c.area[j - 1]); --j) {
      double x = c.area[j];
      c.area[j] = c.area[j - 1];
      c.area[j - 1] = x;
      x = c.perim[j];
      c.perim[j] = c.perim[j - 1];
      c.perim[j - 1] = x;
    }
  }
  for (size_t i = 0; i < c.n; ++i) px_geo_polyline_free(ctx, &p[i]);
  px_mem_free(ctx, p);
  return c;
}

static double dot(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void test_box_sections(struct px_context *ctx) {
  struct tm_soup s = {0};
  struct px_geo_mesh m;
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 3, 5}, z[3] = {0, 0, 1}, x[3] = {1, 0, 0};
  tm_box(&s, lo, hi);
  load(ctx, &s, &m);
  struct cut c = slice(ctx, &m, z, x, 2.5);
  PX_CHECK(c.n == 1);
  PX_CHECK_REL(c.area[0], 6.0, RTOL); /* counter-clockwise: positive */
  PX_CHECK_REL(c.perim[0], 10.0, RTOL);
  c = slice(ctx, &m, z, x, 5.0); /* on the top face, from inside: the face */
  PX_CHECK(c.n == 1);
  PX_CHECK_REL(c.area[0], 6.0, RTOL);
  c = slice(ctx, &m, z, x, 0.0); /* on the bottom face, from outside */
  PX_CHECK(c.n == 0);
  c = slice(ctx, &m, z, x, 7.0); /* misses the part */
  PX_CHECK(c.n == 0);
  c = slice(ctx, &m, z, x, -1.0);
  PX_CHECK(c.n == 0);
  /* the normal reversed: the same rectangle, seen from below, still
   * counter-clockwise in its own frame */
  const double mz[3] = {0, 0, -1};
  c = slice(ctx, &m, mz, x, -2.5);
  PX_CHECK(c.n == 1);
  PX_CHECK_REL(c.area[0], 6.0, RTOL);
  px_geo_mesh_free(ctx, &m);
  tm_free(&s);

  /* the cube of side a = 2 across its diagonal (1, 1, 1) */
  const double a = 2, c0[3] = {0, 0, 0}, c1[3] = {a, a, a}, d[3] = {1, 1, 1}, h[3] = {1, -1, 0};
  tm_box(&s, c0, c1);
  load(ctx, &s, &m);
  double u[3], v[3], n[3];
  PX_CHECK_OK(ctx, px_geo_mesh_frame(ctx, d, h, u, v, n));
  const double mid[3] = {1, 1, 1}, corner[3] = {a, 0, 0}, top[3] = {a, a, a};
  c = slice(ctx, &m, d, h, dot(n, mid)); /* through six edge midpoints */
  PX_CHECK(c.n == 1);
  PX_CHECK_REL(c.area[0], 3 * sqrt(3.0) / 4 * a * a, RTOL);
  PX_CHECK_REL(c.perim[0], 3 * sqrt(2.0) * a, RTOL);
  c = slice(ctx, &m, d, h, dot(n, corner)); /* through three vertices */
  PX_CHECK(c.n == 1);
  PX_CHECK_REL(c.area[0], sqrt(3.0) / 2 * a * a, RTOL);
  PX_CHECK_REL(c.perim[0], 3 * sqrt(2.0) * a, RTOL);
  c = slice(ctx, &m, d, h, dot(n, top)); /* touches the far vertex */
  PX_CHECK(c.n == 0);
  c = slice(ctx, &m, d, h, 0.0); /* touches the origin, from outside */
  PX_CHECK(c.n == 0);
  /* normal (1, 1, 0): through the vertical edges x = a, y = 0 and x = 0,
   * y = a (a rectangle a sqrt 2 by a), touching the edge x = y = a */
  const double e[3] = {1, 1, 0}, zz[3] = {0, 0, 1}, ea[3] = {a, 0, 0}, eb[3] = {a, a, 0};
  PX_CHECK_OK(ctx, px_geo_mesh_frame(ctx, e, zz, u, v, n));
  c = slice(ctx, &m, e, zz, dot(n, ea));
  PX_CHECK(c.n == 1);
  PX_CHECK_REL(c.area[0], sqrt(2.0) * a * a, RTOL);
  PX_CHECK_REL(c.perim[0], 2 * sqrt(2.0) * a + 2 * a, RTOL);
  c = slice(ctx, &m, e, zz, dot(n, eb));
  PX_CHECK(c.n == 0);
  px_geo_mesh_free(ctx, &m);
  tm_free(&s);
}

static void test_cylinder_sections(struct px_context *ctx) {
  struct tm_soup s = {0};
  struct px_geo_mesh m;
  const int N = 64;
  const double R = 1, H = 2, z[3] = {0, 0, 1}, x[3] = {1, 0, 0}, y[3] = {0, 1, 0};
  tm_cylinder(&s, R, H, N);
  load(ctx, &s, &m);
  const double area = 0.5 * N * R * R * sin(2 * TM_PI / N), perim = 2 * N * R * sin(TM_PI / N);
  struct cut c = slice(ctx, &m, z, x, 0.7);
  PX_CHECK(c.n == 1);
  PX_CHECK_REL(c.area[0], area, RTOL);
  PX_CHECK_REL(c.perim[0], perim, RTOL);
  c = slice(ctx, &m, z, x, H); /* the top cap, its centre vertex on the plane */
  PX_CHECK(c.n == 1);
  PX_CHECK_REL(c.area[0], area, RTOL);
  /* along the axis, through the vertices at 0 and 180 degrees and the
   * caps' centres: the rectangle 2R by H */
  c = slice(ctx, &m, y, x, 0.0);
  PX_CHECK(c.n == 1);
  PX_CHECK_REL(c.area[0], 2 * R * H, RTOL);
  PX_CHECK_REL(c.perim[0], 4 * R + 2 * H, RTOL);
  px_geo_mesh_free(ctx, &m);
  tm_free(&s);
}

static void test_torus_sections_with_holes(struct px_context *ctx) {
  struct tm_soup s = {0};
  struct px_geo_mesh m;
  const int N = 48, M = 24;
  const double R = 2, r = 0.5, z[3] = {0, 0, 1}, x[3] = {1, 0, 0}, y[3] = {0, 1, 0};
  tm_torus(&s, R, r, N, M);
  load(ctx, &s, &m);
  PX_CHECK(m.nv == (size_t)(N * M) && m.nt == (size_t)(2 * N * M) && m.flipped == 0);
  /* the equator: the vertex rings at radii R + r and R - r on the plane */
  struct cut c = slice(ctx, &m, z, x, 0.0);
  const double k = 0.5 * N * sin(2 * TM_PI / N), p = 2 * N * sin(TM_PI / N);
  PX_CHECK(c.n == 2);
  PX_CHECK_REL(c.area[0], k * (R + r) * (R + r), RTOL);
  PX_CHECK_REL(c.area[1], -k * (R - r) * (R - r), RTOL); /* the hole, clockwise */
  PX_CHECK_REL(c.perim[0], p * (R + r), RTOL);
  PX_CHECK_REL(c.perim[1], p * (R - r), RTOL);
  /* through the axis, at the vertices of 90 and 270 degrees: two 24-gons */
  c = slice(ctx, &m, x, y, 0.0);
  const double a = 0.5 * M * r * r * sin(2 * TM_PI / M), q = 2 * M * r * sin(TM_PI / M);
  PX_CHECK(c.n == 2);
  PX_CHECK_REL(c.area[0], a, RTOL);
  PX_CHECK_REL(c.area[1], a, RTOL);
  PX_CHECK_REL(c.perim[0], q, RTOL);
  PX_CHECK_REL(c.perim[1], q, RTOL);
  c = slice(ctx, &m, z, x, r); /* touches the top ring from outside */
  PX_CHECK(c.n == 0);
  c = slice(ctx, &m, z, x, 1.5 * r);
  PX_CHECK(c.n == 0);
  px_geo_mesh_free(ctx, &m);
  tm_free(&s);
}

static void test_bad_calls(struct px_context *ctx) {
  struct px_geo_mesh m;
  struct px_geo_polyline *p = NULL;
  size_t n = 7;
  double u[3], v[3], w[3];
  const double zero[3] = {0, 0, 0}, z[3] = {0, 0, 1}, z2[3] = {0, 0, 3};
  PX_CHECK_STATUS(ctx, px_geo_mesh_frame(ctx, zero, z, u, v, w), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_geo_mesh_frame(ctx, z, z2, u, v, w), PX_STATUS_INVALID);
  memset(&m, 0, sizeof m);
  PX_CHECK_STATUS(ctx, px_geo_mesh_slice(ctx, &m, u, v, z, 0, &p, &n), PX_STATUS_INVALID);
  PX_CHECK(p == NULL && n == 0);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  const size_t held = px_mem_current(ctx, NULL);
  test_box_sections(ctx);
  test_cylinder_sections(ctx);
  test_torus_sections_with_holes(ctx);
  test_bad_calls(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == held); /* nothing left allocated */
  px_context_free(ctx);
  return px_test_report("test_geometry_slice");
}
