/* Boundary geometry: segment splitting of every primitive, orientation of
 * the normals into the media (container, part, hole), region queries, DXF
 * import (LINE, ARC, CIRCLE, LWPOLYLINE with bulges, SPLINE, ELLIPSE,
 * chaining with reversed pieces), clear errors for open and crossing
 * contours, motions; the cell list finds exactly the contacts of brute
 * force; user functions of E. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "granular_test_util.h"
#include "io/geometry/geo_dxf.h"
#include "solvers/granular/expr.h"
#include "solvers/granular/media.h"
#include "solvers/granular/wall_kernel.h"

#define PI 3.14159265358979323846

static double contour_perimeter(const struct px_gran_geom *g, size_t c) {
  return g->contours[c].length;
}

static void test_primitives_split_to_length(struct px_context *ctx) {
  struct px_gran_geom g;
  struct px_geo_path p;
  struct px_geo_prim q;
  const double h = 0.001;
  size_t k;
  px_gran_geom_init(&g);
  /* a D shape: line + half circle, a parabola and an elliptic arc closing a
   * second contour */
  px_geo_path_init(&p, "test");
  gt_line(&q, 0, 0, 0.1, 0);
  px_geo_path_add(ctx, &p, &q);
  memset(&q, 0, sizeof q);
  q.kind = PX_GEO_PRIM_ARC;
  q.p[0] = 0.05, q.p[1] = 0, q.p[2] = 0.05, q.p[3] = 0, q.p[4] = PI;
  px_geo_path_add(ctx, &p, &q);
  PX_CHECK_OK(ctx, px_gran_geom_add_path(ctx, &g, &p, h, 1e-9, "d", 0, PX_GRAN_SIDE_AUTO));
  px_geo_path_free(ctx, &p);
  px_geo_path_init(&p, "test");
  memset(&q, 0, sizeof q);
  q.kind = PX_GEO_PRIM_BEZIER2; /* parabola y = 0.01 + 100 (x - 0.05)^2 */
  q.p[0] = 0.04, q.p[1] = 0.02, q.p[2] = 0.05, q.p[3] = 0.0, q.p[4] = 0.06, q.p[5] = 0.02;
  px_geo_path_add(ctx, &p, &q);
  memset(&q, 0, sizeof q);
  q.kind = PX_GEO_PRIM_ELLIPSE; /* back over the top: half ellipse a = 0.01, b = 0.005 */
  q.p[0] = 0.05, q.p[1] = 0.02, q.p[2] = 0.01, q.p[3] = 0.005, q.p[4] = 0, q.p[5] = 0, q.p[6] = PI;
  px_geo_path_add(ctx, &p, &q);
  PX_CHECK_OK(ctx, px_gran_geom_add_path(ctx, &g, &p, h, 1e-9, "lens", 0, PX_GRAN_SIDE_AUTO));
  px_geo_path_free(ctx, &p);
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 0.004));
  /* perimeter of the D: 0.1 + pi 0.05 (the polygon of a circle is shorter by
   * ~ L^3/(24 R^2) per segment) */
  PX_CHECK_REL(contour_perimeter(&g, 0), 0.1 + PI * 0.05, 1e-4);
  /* segments of about h: ceil(length/h) per piece */
  PX_CHECK(g.contours[0].count == 100 + (size_t)ceil(PI * 0.05 / h - 1e-9));
  for (k = 0; k < g.nseg; ++k) PX_CHECK(g.len[k] <= h * (1 + 1e-9) && g.len[k] > 0.4 * h);
  /* parabola arc length: analytic for y = a x^2 with a = 200 over [-0.01, 0.01] */
  {
    const double a = 100, X = 0.01;
    const double Lp = 2 * (X * sqrt(1 + 4 * a * a * X * X) / 2 + asinh(2 * a * X) / (4 * a));
    /* ellipse half perimeter (Ramanujan) */
    const double ea = 0.01, eb = 0.005, hh = pow(ea - eb, 2) / pow(ea + eb, 2);
    const double Le = 0.5 * PI * (ea + eb) * (1 + 3 * hh / (10 + sqrt(4 - 3 * hh)));
    PX_CHECK_REL(contour_perimeter(&g, 1), Lp + Le, 2e-3);
  }
  px_gran_geom_free(ctx, &g);
}

static void test_normals_point_into_the_media(struct px_context *ctx) {
  struct px_gran_geom g;
  double frames[3 * PX_GRAN_CTR_COUNT];
  size_t c, k;
  px_gran_geom_init(&g);
  PX_CHECK_OK(ctx, gt_rect(ctx, &g, 0, 0, 1, 1, 0.05, 0, "container"));
  PX_CHECK_OK(ctx, gt_rect(ctx, &g, 0.3, 0.3, 0.7, 0.7, 0.05, 0, "part"));
  PX_CHECK_OK(ctx, gt_circle(ctx, &g, 0.5, 0.5, 0.1, 0, 0.02, 0, "hole"));
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 0.1));
  PX_CHECK(g.contours[0].media_inside == 1);
  PX_CHECK(g.contours[1].media_inside == 0);
  PX_CHECK(g.contours[2].media_inside == 1);
  memset(frames, 0, sizeof frames);
  for (c = 0; c < 3; ++c) frames[c * PX_GRAN_CTR_COUNT + PX_GRAN_CTR_COS] = 1;
  /* a point just off each segment along its normal is in the media */
  for (k = 0; k < g.nseg; ++k) {
    const double mx = g.ax[k] + 0.5 * g.len[k] * g.tx[k], my = g.ay[k] + 0.5 * g.len[k] * g.ty[k];
    PX_CHECK(px_gran_geom_inside(&g, frames, mx - 1e-4 * g.ty[k], my + 1e-4 * g.tx[k]) == 1);
    PX_CHECK(px_gran_geom_inside(&g, frames, mx + 1e-4 * g.ty[k], my - 1e-4 * g.tx[k]) == 0);
  }
  PX_CHECK(px_gran_geom_inside(&g, frames, 0.1, 0.1) == 1);   /* container */
  PX_CHECK(px_gran_geom_inside(&g, frames, 0.35, 0.35) == 0); /* in the part */
  PX_CHECK(px_gran_geom_inside(&g, frames, 0.5, 0.5) == 1);   /* in the hole */
  PX_CHECK(px_gran_geom_inside(&g, frames, 1.5, 0.5) == 0);   /* outside */
  /* the free area: 1 - 0.16 + pi 0.01 (polygon of the circle slightly less) */
  PX_CHECK_REL(px_gran_geom_free_area(&g), 1 - 0.16 + PI * 0.01, 1e-3);
  px_gran_geom_free(ctx, &g);
}

/* The strips' point-in-contour test (px_gran_contour_contains) against the
 * plain even-odd test over every edge: the same answer at random points,
 * at the vertices' heights (edges ending exactly on the ray) and at the
 * vertices themselves, for a container with a part and a hole and a
 * zigzag whose long slanted edges span many strips. */
static void test_strips_agree_with_plain_test(struct px_context *ctx) {
  struct px_gran_geom g;
  struct px_geo_path p;
  size_t c, k;
  int bad = 0, tested = 0;
  uint64_t rng = 12345;
  px_gran_geom_init(&g);
  PX_CHECK_OK(ctx, gt_rect(ctx, &g, 0, 0, 1, 1, 0.01, 0, "container"));
  PX_CHECK_OK(ctx, gt_rect(ctx, &g, 0.3, 0.3, 0.7, 0.7, 0.01, 0, "part"));
  PX_CHECK_OK(ctx, gt_circle(ctx, &g, 0.5, 0.5, 0.1, 0, 0.005, 0, "hole"));
  /* zigzag: 8 teeth between y = 1.2 and 1.9, closed below (split into
   * segments of 0.5: the slanted edges stay long) */
  {
    double xy[2 * 20];
    for (k = 0; k <= 16; ++k) xy[2 * k] = 0.1 * (double)k, xy[2 * k + 1] = k % 2 ? 1.9 : 1.2;
    xy[34] = 1.6, xy[35] = 1.1, xy[36] = 0, xy[37] = 1.1, xy[38] = 0, xy[39] = 1.2;
    px_geo_path_init(&p, "zigzag");
    gt_polyline(ctx, &p, xy, 20);
  }
  PX_CHECK_OK(ctx, px_gran_geom_add_path(ctx, &g, &p, 0.5, 1e-9, "zigzag", 0, PX_GRAN_SIDE_AUTO));
  px_geo_path_free(ctx, &p);
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 0.05));
  for (c = 0; c < g.ncontours; ++c) {
    const struct px_gran_contour *C = &g.contours[c];
    const double *x = g.ax + C->first, *y = g.ay + C->first;
    const double wx = C->xmax - C->xmin, wy = C->ymax - C->ymin;
    PX_CHECK(C->strip_start != NULL && C->sny >= 1);
    for (k = 0; k < 20000; ++k) {
      double px, py;
      rng = rng * 6364136223846793005ull + 1442695040888963407ull;
      px = C->xmin - 0.1 * wx + 1.2 * wx * (double)(rng >> 11) / 9007199254740992.0;
      rng = rng * 6364136223846793005ull + 1442695040888963407ull;
      py = C->ymin - 0.1 * wy + 1.2 * wy * (double)(rng >> 11) / 9007199254740992.0;
      if (k % 4 == 1) py = y[(k / 4) % C->count]; /* a vertex's height */
      if (k % 4 == 2) px = x[(k / 4) % C->count], py = y[(k / 4) % C->count]; /* a vertex */
      bad +=
          px_gran_contour_contains(&g, c, px, py) != px_gran_poly_contains(x, y, C->count, px, py);
      ++tested;
    }
  }
  PX_CHECK_MSG(bad == 0, "%d of %d points answered differently by the strips", bad, tested);
  /* the zigzag's slanted edges are listed in several strips each */
  PX_CHECK(g.contours[3].strip_start[g.contours[3].sny] > (int)g.contours[3].count);
  px_gran_geom_free(ctx, &g);
}

static void test_open_and_crossing_contours_fail(struct px_context *ctx) {
  struct px_gran_geom g;
  struct px_geo_path p;
  struct px_geo_prim q;
  px_gran_geom_init(&g);
  px_geo_path_init(&p, "test.yaml:7:3");
  gt_line(&q, 0, 0, 1, 0);
  px_geo_path_add(ctx, &p, &q);
  gt_line(&q, 1, 0, 1, 1);
  px_geo_path_add(ctx, &p, &q);
  PX_CHECK_STATUS(ctx, px_gran_geom_add_path(ctx, &g, &p, 0.1, 1e-9, "cup", 0, PX_GRAN_SIDE_AUTO),
                  PX_STATUS_CONFIG);
  PX_CHECK(strstr(px_context_message(ctx), "test.yaml:7:3: contour 'cup' is open") != NULL);
  px_geo_path_free(ctx, &p);
  /* a figure eight crosses itself */
  {
    const double xy[10] = {0, 0, 1, 1, 1, 0, 0, 1, 0, 0};
    px_geo_path_init(&p, "test");
    gt_polyline(ctx, &p, xy, 5);
  }
  PX_CHECK_STATUS(ctx, px_gran_geom_add_path(ctx, &g, &p, 0.1, 1e-9, "eight", 0, PX_GRAN_SIDE_AUTO),
                  PX_STATUS_CONFIG);
  PX_CHECK(strstr(px_context_message(ctx), "crosses itself") != NULL);
  px_geo_path_free(ctx, &p);
  /* the same figure eight cut so that both diagonals have a vertex at the
     middle: its loops touch there (no proper crossing) and cancel; the
     message says what such a contour may be */
  {
    const double xy[10] = {0, 0, 1, 1, 1, 0, 0, 1, 0, 0};
    px_geo_path_init(&p, "test");
    gt_polyline(ctx, &p, xy, 5);
  }
  PX_CHECK_STATUS(
      ctx, px_gran_geom_add_path(ctx, &g, &p, sqrt(2.0) / 10, 1e-9, "eight", 0, PX_GRAN_SIDE_AUTO),
      PX_STATUS_CONFIG);
  PX_CHECK_MSG(strstr(px_context_message(ctx), "encloses no area") != NULL &&
                   strstr(px_context_message(ctx), "figure eight") != NULL,
               "%s", px_context_message(ctx));
  px_geo_path_free(ctx, &p);
  px_gran_geom_free(ctx, &g);
}

/* A DXF drawing in millimetres: the outline of a plate 100 x 60 with rounded
 * right corners (LINEs and ARCs in mixed directions), a circular hole
 * (CIRCLE), a slot (closed LWPOLYLINE with two bulges = half circles) and a
 * closed SPLINE. */
static const char *const dxf_text =
    "0\nSECTION\n2\nHEADER\n9\n$ACADVER\n1\nAC1015\n0\nENDSEC\n"
    "0\nSECTION\n2\nENTITIES\n"
    /* bottom edge, drawn right to left (reversed on chaining) */
    "0\nLINE\n8\nPART\n10\n90.0\n20\n0.0\n30\n0.0\n11\n0.0\n21\n0.0\n31\n0.0\n"
    "0\nLINE\n8\nPART\n10\n0.0\n20\n0.0\n11\n0.0\n21\n60.0\n"
    "0\nLINE\n8\nPART\n10\n0.0\n20\n60.0\n11\n90.0\n21\n60.0\n"
    /* right side: two quarter arcs of radius 10 and a line */
    "0\nARC\n8\nPART\n10\n90.0\n20\n50.0\n40\n10.0\n50\n0.0\n51\n90.0\n"
    "0\nLINE\n8\nPART\n10\n100.0\n20\n50.0\n11\n100.0\n21\n10.0\n"
    "0\nARC\n8\nPART\n10\n90.0\n20\n10.0\n40\n10.0\n50\n270.0\n51\n360.0\n"
    /* a hole */
    "0\nCIRCLE\n8\nPART\n10\n30.0\n20\n30.0\n40\n8.0\n"
    /* a slot: (55,25)-(75,25) bulge 1 to (75,35), line back, bulge 1 to start */
    "0\nLWPOLYLINE\n8\nPART\n90\n4\n70\n1\n10\n55.0\n20\n25.0\n10\n75.0\n20\n25.0\n42\n1.0\n"
    "10\n75.0\n20\n35.0\n10\n55.0\n20\n35.0\n42\n1.0\n"
    /* an entity on another layer */
    "0\nCIRCLE\n8\nDIMENSIONS\n10\n0.0\n20\n0.0\n40\n500.0\n"
    "0\nTEXT\n8\nPART\n10\n1\n20\n1\n1\nhello\n"
    "0\nENDSEC\n0\nEOF\n";

static void test_dxf_import(struct px_context *ctx) {
  struct px_geo_path *paths = NULL;
  struct px_gran_geom g;
  size_t np = 0, k;
  PX_CHECK_OK(ctx, px_geo_dxf_parse(ctx, "plate.dxf", dxf_text, strlen(dxf_text), "PART", 0.001, 0,
                                    0, 1e-9, &paths, &np));
  PX_CHECK(np == 3);
  px_gran_geom_init(&g);
  for (k = 0; k < np; ++k) {
    char name[32];
    snprintf(name, sizeof name, "c%zu", k);
    PX_CHECK_OK(
        ctx, px_gran_geom_add_path(ctx, &g, &paths[k], 0.0005, 1e-9, name, 0, PX_GRAN_SIDE_AUTO));
    px_geo_path_free(ctx, &paths[k]);
  }
  px_mem_free(ctx, paths);
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 0.002));
  if (g.ncontours == 3) {
    /* outline: 90 + 60 + 90 + 40 + 2 quarter circles of 10 (mm) */
    PX_CHECK_REL(g.contours[0].length, (90 + 60 + 90 + 40 + PI * 10) * 1e-3, 2e-4);
    /* hole: circumference of r 8; slot: 2 x 20 + a circle of r 5 */
    PX_CHECK_REL(g.contours[1].length, 2 * PI * 8e-3, 2e-3);
    PX_CHECK_REL(g.contours[2].length, (40 + 2 * PI * 5) * 1e-3, 2e-3);
    /* the plate alone: the hole and the slot are holes in the media */
    PX_CHECK(g.contours[0].media_inside == 1);
    PX_CHECK(g.contours[1].media_inside == 0 && g.contours[2].media_inside == 0);
    PX_CHECK_REL(px_gran_geom_free_area(&g),
                 (100 * 60 - (4 - PI) * 100 / 4 * 2 - PI * 64 - (200 + PI * 25)) * 1e-6, 2e-3);
  }
  px_gran_geom_free(ctx, &g);
  /* an open drawing */
  {
    const char *open =
        "0\nSECTION\n2\nENTITIES\n0\nLINE\n10\n0\n20\n0\n11\n1\n21\n0\n0\nLINE\n10\n1\n20\n0\n11\n1"
        "\n21\n"
        "1\n0\nENDSEC\n0\nEOF\n";
    PX_CHECK_STATUS(
        ctx,
        px_geo_dxf_parse(ctx, "open.dxf", open, strlen(open), NULL, 1, 0, 0, 1e-9, &paths, &np),
        PX_STATUS_CONFIG);
    PX_CHECK(strstr(px_context_message(ctx), "open contour") != NULL);
  }
  /* a spline: a closed periodic-looking B-spline through 8 control points on
   * a circle of radius 10 (degree 3, clamped knots, last = first) is a
   * closed smooth loop with perimeter below the control polygon's */
  {
    char text[4096];
    size_t off = 0;
    int i;
    off += (size_t)snprintf(text + off, sizeof text - off,
                            "0\nSECTION\n2\nENTITIES\n0\nSPLINE\n70\n1\n71\n3\n72\n13\n73\n9\n");
    {
      const double kn[13] = {0, 0, 0, 0, 1, 2, 3, 4, 5, 6, 6, 6, 6};
      for (i = 0; i < 13; ++i)
        off += (size_t)snprintf(text + off, sizeof text - off, "40\n%g\n", kn[i]);
    }
    for (i = 0; i <= 8; ++i) {
      const double a = 2 * PI * (i % 8) / 8;
      off += (size_t)snprintf(text + off, sizeof text - off, "10\n%.12f\n20\n%.12f\n", 10 * cos(a),
                              10 * sin(a));
    }
    off += (size_t)snprintf(text + off, sizeof text - off, "0\nENDSEC\n0\nEOF\n");
    PX_CHECK_OK(ctx,
                px_geo_dxf_parse(ctx, "spline.dxf", text, off, NULL, 1, 0, 0, 1e-6, &paths, &np));
    PX_CHECK(np == 1);
    if (np == 1) {
      px_gran_geom_init(&g);
      PX_CHECK_OK(ctx,
                  px_gran_geom_add_path(ctx, &g, &paths[0], 0.2, 1e-6, "s", 0, PX_GRAN_SIDE_AUTO));
      PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 1));
      PX_CHECK(g.contours[0].length > 30 && g.contours[0].length < 8 * 2 * 10 * sin(PI / 8));
      px_gran_geom_free(ctx, &g);
      px_geo_path_free(ctx, &paths[0]);
    }
    px_mem_free(ctx, paths);
  }
}

static void test_motion_laws(struct px_context *ctx) {
  struct px_gran_motion m;
  double d[2], v[2], phi, w, tt[5] = {0, 0.25, 0.5, 0.75, 1}, xx[5] = {0, 1, 0, -1, 0},
                             yy[5] = {0, 0, 0, 0, 0}, rr[5] = {0, 0, 0, 0, 0};
  px_gran_motion_init(&m);
  m.kind = PX_GRAN_MOTION_HARMONIC;
  m.amp[0] = 0.002, m.amp[1] = 0.001, m.freq[0] = m.freq[1] = 25, m.phase[1] = PI / 2;
  PX_CHECK_OK(ctx, px_gran_motion_check(ctx, &m, "m"));
  px_gran_motion_eval(&m, 0.01, d, v, &phi, &w);
  PX_CHECK_NEAR(d[0], 0.002 * sin(2 * PI * 25 * 0.01), 1e-15);
  PX_CHECK_NEAR(v[1], -0.001 * 2 * PI * 25 * sin(2 * PI * 25 * 0.01), 1e-12);
  /* start and ramp: nothing before, the envelope after */
  m.start = 0.1, m.ramp = 0.02;
  px_gran_motion_eval(&m, 0.05, d, v, &phi, &w);
  PX_CHECK(d[0] == 0 && d[1] == 0 && v[0] == 0);
  px_gran_motion_eval(&m, 0.11, d, v, &phi, &w);
  PX_CHECK_NEAR(d[1], 0.5 * 0.001 * sin(2 * PI * 25 * 0.01 + PI / 2), 1e-15);
  /* periodic table: a continuous, smooth velocity through the wrap */
  px_gran_motion_init(&m);
  m.kind = PX_GRAN_MOTION_TABLE;
  m.n = 5, m.t = tt, m.x = xx, m.y = yy, m.r = rr, m.periodic = 1;
  PX_CHECK_OK(ctx, px_gran_motion_check(ctx, &m, "m"));
  px_gran_motion_eval(&m, 0.25, d, v, &phi, &w);
  PX_CHECK_NEAR(d[0], 1, 1e-12);
  {
    double d1[2], v1[2], d2[2], v2[2];
    px_gran_motion_eval(&m, 1 - 1e-9, d1, v1, &phi, &w);
    px_gran_motion_eval(&m, 1 + 1e-9, d2, v2, &phi, &w);
    PX_CHECK_NEAR(v1[0], v2[0], 1e-6);
    PX_CHECK_NEAR(d1[0], d2[0], 1e-6);
    /* velocity = derivative of the displacement */
    px_gran_motion_eval(&m, 0.4, d1, v1, &phi, &w);
    px_gran_motion_eval(&m, 0.4 + 1e-6, d2, v2, &phi, &w);
    PX_CHECK_NEAR((d2[0] - d1[0]) / 1e-6, v1[0], 1e-4);
  }
  xx[4] = 0.5; /* not closing */
  PX_CHECK_STATUS(ctx, px_gran_motion_check(ctx, &m, "bodies[0].motion"), PX_STATUS_CONFIG);
}

static void test_cell_list_finds_all_contacts(struct px_context *ctx) {
  /* a compressed random packing (overlaps allowed by placing, then the
   * positions are set directly): contacts from the neighbour list equal
   * those of brute force, after many rebuilds and reorderings */
  struct px_gran_sys *s = NULL;
  uint64_t rng[4];
  int prec;
  for (prec = 0; prec < 3; ++prec) {
    const enum px_precision p = prec == 0   ? PX_PRECISION_DOUBLE
                                : prec == 1 ? PX_PRECISION_MIXED
                                            : PX_PRECISION_SINGLE;
    int32_t *a = NULL, *b = NULL;
    size_t na = 0, nb = 0, i;
    long k;
    px_rng_seed(rng, 11 + (uint64_t)prec);
    PX_CHECK_OK(ctx, px_gran_sys_create(ctx, p, 2, &s));
    gt_law(&s->pp, 2e5, 0.9, 0.3);
    for (i = 0; i < 3000; ++i) {
      double x = 0.3 * (double)(i % 60) / 60.0 + 0.002, y = 0.3 * (double)(i / 60) / 50.0;
      double r = 0.0009 + 0.0011 * px_rng_uniform(rng), m = 1e-4;
      px_gran_sys_add(s, 1, &x, &y, &r, &m);
      px_gran_sys_set_velocity(s, (int32_t)i, 0.5 * px_rng_normal(rng), 0.5 * px_rng_normal(rng),
                               0);
    }
    PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
    /* compress: a lattice of pitch 3.5 mm for radii up to 2 mm, so that many
     * discs overlap, then let it spring apart through many rebuilds */
    for (i = 0; i < s->n; ++i) {
      double rec[8];
      s->ops->get(s, i, rec);
      rec[0] = 0.0035 * (double)(rec[PX_GRAN_P_ID] - 60 * floor(rec[PX_GRAN_P_ID] / 60));
      rec[1] = 0.0035 * floor(rec[PX_GRAN_P_ID] / 60);
      s->ops->set(s, i, rec);
    }
    PX_CHECK_OK(ctx, px_gran_sys_rebuild(s));
    for (k = 0; k <= 600; ++k) {
      if (k % 200 == 0) {
        PX_CHECK_OK(ctx, px_gran_sys_contacts_list(s, &a, &na));
        PX_CHECK_OK(ctx, px_gran_sys_contacts_brute(s, &b, &nb));
        PX_CHECK_MSG(na == nb && na > 100, "step %ld: %zu vs %zu", k, na, nb);
        PX_CHECK(na == nb && memcmp(a, b, 2 * na * sizeof *a) == 0);
        if (k < 600) {
          px_mem_free(ctx, a);
          px_mem_free(ctx, b);
        }
      }
      if (k < 600) px_gran_sys_step(s);
    }
    PX_CHECK(s->rebuilds > 3);
    printf("precision %s: %zu contacts in the list, %zu by brute force, %ld rebuilds\n",
           px_precision_name(p), na, nb, s->rebuilds);
    px_mem_free(ctx, a);
    px_mem_free(ctx, b);
    px_gran_sys_free(s);
  }
}

static void test_user_functions(struct px_context *ctx) {
  struct px_gran_fn f;
  const double tx[3] = {0, 100, 300}, ty[3] = {0, 50, 60};
  PX_CHECK_OK(ctx,
              px_gran_fn_compile(ctx, &f, "350 * (1 - exp(-E / 2000)) + max(E, 2)^2 / 4", "E"));
  PX_CHECK_NEAR(px_gran_fn_eval(&f, 1000), 350 * (1 - exp(-0.5)) + 1000.0 * 1000.0 / 4, 1e-9);
  PX_CHECK_NEAR(px_gran_fn_eval(&f, 0), 1, 1e-12);
  PX_CHECK_NEAR(px_gran_fn_eval(&f, 3), 350 * (1 - exp(-3.0 / 2000)) + 2.25, 1e-12);
  PX_CHECK_OK(ctx, px_gran_fn_compile(ctx, &f, "-2^2", "E"));
  PX_CHECK_NEAR(px_gran_fn_eval(&f, 0), 4, 0); /* unary minus binds tighter, as written */
  PX_CHECK_STATUS(ctx, px_gran_fn_compile(ctx, &f, "3 * X", "E"), PX_STATUS_CONFIG);
  PX_CHECK(strstr(px_context_message(ctx), "unknown name 'X'") != NULL);
  PX_CHECK_STATUS(ctx, px_gran_fn_compile(ctx, &f, "(E + 1", "E"), PX_STATUS_CONFIG);
  PX_CHECK_OK(ctx, px_gran_fn_table(ctx, &f, tx, ty, 3));
  PX_CHECK_NEAR(px_gran_fn_eval(&f, 50), 25, 1e-12);
  PX_CHECK_NEAR(px_gran_fn_eval(&f, 200), 55, 1e-12);
  PX_CHECK_NEAR(px_gran_fn_eval(&f, 1000), 60, 0);
  px_gran_fn_free(ctx, &f);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  test_primitives_split_to_length(ctx);
  test_normals_point_into_the_media(ctx);
  test_strips_agree_with_plain_test(ctx);
  test_open_and_crossing_contours_fail(ctx);
  test_dxf_import(ctx);
  test_motion_laws(ctx);
  test_user_functions(ctx);
  test_cell_list_finds_all_contacts(ctx);
  px_context_free(ctx);
  return px_test_report("test_granular_geometry");
}
