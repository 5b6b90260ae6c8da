/* DXF drawings (io/geometry/geo_dxf.h): valid drawings read to their known
 * points and primitives (LINEs chained with a reversed one, LWPOLYLINE
 * bulges as half circles, a CIRCLE, an ARC in a mirrored object coordinate
 * system, an ELLIPSE, a degree-1 SPLINE sampled on its control polygon),
 * mapped by scale and offset, filtered by layer; bad drawings refused with
 * the file, the line and the reason, hostile ones (absurd values) without
 * crashing or hanging. */
#include <string.h>
#include <sys/stat.h>

#include "io/geometry/geo_dxf.h"
#include "partix/memory.h"
#include "px_test.h"

#define PI 3.14159265358979323846

static int message_has(struct px_context *ctx, const char *text) {
  int ok = strstr(px_context_message(ctx), text) != NULL;
  if (!ok) fprintf(stderr, "message: %s\n  expected: %s\n", px_context_message(ctx), text);
  return ok;
}

static void free_paths(struct px_context *ctx, struct px_geo_path *paths, size_t n) {
  for (size_t k = 0; k < n; ++k) px_geo_path_free(ctx, &paths[k]);
  px_mem_free(ctx, paths);
}

static double path_length(const struct px_geo_path *p) {
  double L = 0;
  for (size_t k = 0; k < p->n; ++k) L += px_geo_prim_length(&p->prims[k]);
  return L;
}

/* Every primitive starts where the one before ends, the last ends where
 * the first starts (within tol). */
static int path_is_closed_chain(const struct px_geo_path *p, double tol) {
  double x0, y0, x1, y1, sx, sy, ex, ey;
  px_geo_prim_ends(&p->prims[0], &sx, &sy, &ex, &ey);
  for (size_t k = 1; k < p->n; ++k) {
    px_geo_prim_ends(&p->prims[k], &x0, &y0, &x1, &y1);
    if (hypot(x0 - ex, y0 - ey) > tol) return 0;
    ex = x1, ey = y1;
  }
  return hypot(ex - sx, ey - sy) <= tol;
}

/* A 10 x 10 square in millimetres, its bottom edge drawn backwards, mapped
 * to metres at (1, 2): one closed path of four lines through the mapped
 * corners, named by the line of its first entity. */
static void test_lines_chain_into_a_square(struct px_context *ctx) {
  const char *text =
      "0\nSECTION\n2\nENTITIES\n"
      "0\nLINE\n8\nP\n10\n10\n20\n0\n11\n0\n21\n0\n" /* line 5: (10,0) -> (0,0) */
      "0\nLINE\n8\nP\n10\n10\n20\n10\n11\n10\n21\n0\n"
      "0\nLINE\n8\nP\n10\n0\n20\n0\n11\n0\n21\n10\n"
      "0\nLINE\n8\nP\n10\n0\n20\n10\n11\n10\n21\n10\n"
      "0\nENDSEC\n0\nEOF\n";
  struct px_geo_path *paths = NULL;
  size_t n = 0;
  PX_CHECK_OK(ctx, px_geo_dxf_parse(ctx, "sq.dxf", text, strlen(text), NULL, 0.001, 1.0, 2.0, 1e-9,
                                    &paths, &n));
  PX_CHECK(n == 1);
  if (n == 1) {
    const double cx[4] = {1.01, 1.0, 1.0, 1.01}, cy[4] = {2.0, 2.0, 2.01, 2.01};
    PX_CHECK(paths[0].n == 4 && strcmp(paths[0].where, "sq.dxf:5") == 0);
    PX_CHECK(path_is_closed_chain(&paths[0], 1e-15));
    PX_CHECK_NEAR(path_length(&paths[0]), 0.04, 1e-15);
    for (size_t k = 0; k < paths[0].n; ++k) {
      double x0, y0, x1, y1;
      PX_CHECK(paths[0].prims[k].kind == PX_GEO_PRIM_LINE);
      px_geo_prim_ends(&paths[0].prims[k], &x0, &y0, &x1, &y1);
      PX_CHECK_NEAR(x0, cx[k], 1e-15);
      PX_CHECK_NEAR(y0, cy[k], 1e-15);
    }
  }
  free_paths(ctx, paths, n);
}

/* A closed LWPOLYLINE (0,0) -> (2,0) -bulge 1-> (2,2) -> (0,2) -bulge 1->
 * (0,0): a stadium of two lines and two half circles of radius 1
 * (perimeter 4 + 2 pi); a CIRCLE of radius 3; an ARC in the mirrored
 * object coordinate system (extrusion 0 0 -1) closed by a LINE. */
static void test_bulges_circles_and_mirrored_arcs(struct px_context *ctx) {
  const char *text =
      "0\nSECTION\n2\nENTITIES\n"
      "0\nLWPOLYLINE\n8\nA\n90\n4\n70\n1\n10\n0\n20\n0\n10\n2\n20\n0\n42\n1\n"
      "10\n2\n20\n2\n10\n0\n20\n2\n42\n1\n"
      "0\nCIRCLE\n8\nB\n10\n10\n20\n0\n40\n3\n"
      /* ARC centre (5, 20) r 1 from 0 to 180 deg, mirrored: centre
       * (-5, 20), from (-6, 20) to (-4, 20) */
      "0\nARC\n8\nA\n10\n5\n20\n20\n40\n1\n50\n0\n51\n180\n230\n-1\n"
      "0\nLINE\n8\nA\n10\n-6\n20\n20\n11\n-4\n21\n20\n"
      "0\nENDSEC\n0\nEOF\n";
  struct px_geo_path *paths = NULL;
  size_t n = 0;
  PX_CHECK_OK(ctx,
              px_geo_dxf_parse(ctx, "mix.dxf", text, strlen(text), "", 1, 0, 0, 1e-9, &paths, &n));
  PX_CHECK(n == 3);
  if (n == 3) {
    const struct px_geo_prim *a = &paths[0].prims[1];
    PX_CHECK(paths[0].n == 4 && path_is_closed_chain(&paths[0], 1e-12));
    PX_CHECK_REL(path_length(&paths[0]), 4 + 2 * PI, 1e-14);
    PX_CHECK(a->kind == PX_GEO_PRIM_ARC);
    PX_CHECK_NEAR(a->p[0], 2, 1e-15);
    PX_CHECK_NEAR(a->p[1], 1, 1e-15);
    PX_CHECK_NEAR(a->p[2], 1, 1e-15);
    PX_CHECK_NEAR(a->p[4] - a->p[3], PI, 1e-15); /* counter-clockwise half turn */
    PX_CHECK(paths[1].n == 1 && paths[1].prims[0].kind == PX_GEO_PRIM_ARC);
    PX_CHECK_REL(path_length(&paths[1]), 6 * PI, 1e-15);
    PX_CHECK(paths[2].n == 2 && path_is_closed_chain(&paths[2], 1e-12));
    PX_CHECK_NEAR(paths[2].prims[0].p[0], -5, 0);
    PX_CHECK_NEAR(paths[2].prims[0].p[1], 20, 0);
    PX_CHECK_REL(path_length(&paths[2]), PI + 2, 1e-15);
  }
  free_paths(ctx, paths, n);
  /* layer B alone: the circle */
  PX_CHECK_OK(ctx,
              px_geo_dxf_parse(ctx, "mix.dxf", text, strlen(text), "B", 1, 0, 0, 1e-9, &paths, &n));
  PX_CHECK(n == 1 && paths[0].n == 1 && strcmp(paths[0].where, "mix.dxf:33") == 0);
  free_paths(ctx, paths, n);
  PX_CHECK_STATUS(
      ctx, px_geo_dxf_parse(ctx, "mix.dxf", text, strlen(text), "C", 1, 0, 0, 1e-9, &paths, &n),
      PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx,
                       "mix.dxf: no LINE, ARC, CIRCLE, ELLIPSE, LWPOLYLINE, POLYLINE or "
                       "SPLINE entities on layer 'C'"));
  PX_CHECK(paths == NULL && n == 0);
}

/* A full ELLIPSE (semi-axes 2 and 1) and a degree-1 SPLINE on (0,0),
 * (1,0), (1,1) closed by a LINE: lengths from Ramanujan's formula and
 * 2 + sqrt 2; the spline's samples lie on its control polygon. */
static void test_ellipse_and_spline(struct px_context *ctx) {
  const char *text =
      "0\nSECTION\n2\nENTITIES\n"
      "0\nELLIPSE\n10\n0\n20\n0\n11\n2\n21\n0\n40\n0.5\n41\n0\n42\n6.283185307179586\n"
      "0\nSPLINE\n70\n0\n71\n1\n40\n0\n40\n0\n40\n1\n40\n2\n40\n2\n"
      "10\n10\n20\n0\n10\n11\n20\n0\n10\n11\n20\n1\n"
      "0\nLINE\n10\n11\n20\n1\n11\n10\n21\n0\n"
      "0\nENDSEC\n0\nEOF\n";
  struct px_geo_path *paths = NULL;
  size_t n = 0;
  const double h = 1.0 / 9; /* ((a - b) / (a + b))^2 */
  PX_CHECK_OK(ctx,
              px_geo_dxf_parse(ctx, "es.dxf", text, strlen(text), NULL, 1, 0, 0, 1e-9, &paths, &n));
  PX_CHECK(n == 2);
  if (n == 2) {
    const struct px_geo_prim *e = &paths[0].prims[0], *s = &paths[1].prims[0];
    PX_CHECK(e->kind == PX_GEO_PRIM_ELLIPSE && e->p[2] == 2 && e->p[3] == 1);
    PX_CHECK_REL(path_length(&paths[0]), PI * 3 * (1 + 3 * h / (10 + sqrt(4 - 3 * h))), 1e-6);
    PX_CHECK(s->kind == PX_GEO_PRIM_POINTS && s->smooth == 1 && s->npts == 257);
    for (size_t k = 0; k < s->npts; ++k) {
      const double x = s->pts[2 * k], y = s->pts[2 * k + 1];
      PX_CHECK((y == 0 && x >= 10 && x <= 11) || (x == 11 && y >= 0 && y <= 1));
    }
    PX_CHECK_REL(path_length(&paths[1]), 2 + sqrt(2.0), 1e-14);
    PX_CHECK(path_is_closed_chain(&paths[1], 1e-12));
  }
  free_paths(ctx, paths, n);
}

static void test_bad_drawings_name_their_line(struct px_context *ctx) {
  struct px_geo_path *paths = NULL;
  size_t n = 0;
  struct {
    const char *text, *message;
    enum px_status st;
  } bad[] = {
      {"0\nSECTION\n2\nENTITIES\nabc\nLINE\n",
       "bad.dxf:5: expected a DXF group code (an integer), found 'abc' (is this a binary DXF?",
       PX_STATUS_FORMAT},
      {"0\nSECTION\n2\nENTITIES\n0\nLINE\n10\nxyz\n",
       "bad.dxf:8: group 10: expected a number, found 'xyz'", PX_STATUS_FORMAT},
      {"0\nSECTION\n2", "bad.dxf:3: group code 2 has no value (file truncated?)", PX_STATUS_FORMAT},
      {"0\nSECTION\n2\nHEADER\n0\nENDSEC\n0\nEOF\n",
       "bad.dxf: no ENTITIES section (is this a DXF file?)", PX_STATUS_FORMAT},
      {"0\nSECTION\n2\nENTITIES\n0\nCIRCLE\n10\n0\n20\n0\n40\n-1\n0\nENDSEC\n",
       "bad.dxf:5: CIRCLE with centre (0, 0) and radius -1", PX_STATUS_FORMAT},
      {"0\nSECTION\n2\nENTITIES\n0\nLINE\n10\n0\n20\n0\n11\n1\n21\n0\n0\nLINE\n10\n1\n20\n0\n"
       "11\n1\n21\n1\n0\nENDSEC\n",
       "bad.dxf: open contour: the chain starting with the LINE at line 5 (from (0, 0)) ends at "
       "(1, 1)",
       PX_STATUS_CONFIG},
      {"0\nSECTION\n2\nENTITIES\n0\nSPLINE\n71\n3\n10\n0\n20\n0\n10\n1\n20\n0\n0\nENDSEC\n",
       "bad.dxf:5: SPLINE with degree 3, 2 control points and 0 knots", PX_STATUS_FORMAT},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
    PX_CHECK_STATUS(ctx,
                    px_geo_dxf_parse(ctx, "bad.dxf", bad[k].text, strlen(bad[k].text), NULL, 1, 0,
                                     0, 1e-9, &paths, &n),
                    bad[k].st);
    PX_CHECK(message_has(ctx, bad[k].message));
    PX_CHECK(paths == NULL && n == 0);
  }
  PX_CHECK_STATUS(ctx, px_geo_dxf_parse(ctx, "s.dxf", "", 0, NULL, 0, 0, 0, 1e-6, &paths, &n),
                  PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx,
                       "s.dxf: scale 0, offset (0, 0) and tolerance 1e-06: a scale in (0, "
                       "1e100]"));
  PX_CHECK_STATUS(ctx, px_geo_dxf_read(ctx, "no_such.dxf", NULL, 1, 0, 0, 1e-6, &paths, &n),
                  PX_STATUS_IO);
  PX_CHECK(message_has(ctx, "cannot open DXF file 'no_such.dxf'"));
  mkdir("adir.dxf", 0755);
  PX_CHECK_STATUS(ctx, px_geo_dxf_read(ctx, "adir.dxf", NULL, 1, 0, 0, 1e-6, &paths, &n),
                  PX_STATUS_IO);
  PX_CHECK(message_has(ctx, "DXF file 'adir.dxf' is not a regular file"));
}

/* The file reader gives what the parser gives for the same text. */
static void test_read_a_file(struct px_context *ctx) {
  const char *text = "0\nSECTION\n2\nENTITIES\n0\nCIRCLE\n10\n1\n20\n1\n40\n0.5\n0\nENDSEC\n";
  struct px_geo_path *paths = NULL;
  size_t n = 0;
  FILE *f = fopen("circle.dxf", "w");
  if (!f) return;
  fputs(text, f);
  fclose(f);
  PX_CHECK_OK(ctx, px_geo_dxf_read(ctx, "circle.dxf", NULL, 2, 0, 0, 1e-6, &paths, &n));
  PX_CHECK(n == 1 && strcmp(paths[0].where, "circle.dxf:5") == 0);
  if (n == 1) {
    PX_CHECK(paths[0].prims[0].p[0] == 2 && paths[0].prims[0].p[2] == 1);
    PX_CHECK_REL(path_length(&paths[0]), 2 * PI, 1e-15);
  }
  free_paths(ctx, paths, n);
}

/* DXF text of one ENTITIES section holding `ents`. */
static void dxf_text(char *buf, size_t size, const char *ents) {
  snprintf(buf, size, "0\nSECTION\n2\nENTITIES\n%s0\nENDSEC\n0\nEOF\n", ents);
}

/* Parse a DXF text: the status; on success the paths are freed and *np set. */
static enum px_status dxf_parse(struct px_context *ctx, const char *ents, size_t *np,
                                double *sweep) {
  char text[4096];
  struct px_geo_path *paths = NULL;
  size_t n = 0, k;
  enum px_status st;
  dxf_text(text, sizeof text, ents);
  st = px_geo_dxf_parse(ctx, "hostile.dxf", text, strlen(text), NULL, 1.0, 0.0, 0.0, 1e-6, &paths,
                        &n);
  if (np) *np = n;
  if (sweep) *sweep = 0;
  for (k = 0; k < n; ++k) {
    size_t j;
    for (j = 0; sweep && j < paths[k].n; ++j) {
      const struct px_geo_prim *q = &paths[k].prims[j];
      if (q->kind == PX_GEO_PRIM_ARC) *sweep = fabs(q->p[4] - q->p[3]);
      if (q->kind == PX_GEO_PRIM_ELLIPSE) *sweep = fabs(q->p[6] - q->p[5]);
    }
    px_geo_path_free(ctx, &paths[k]);
  }
  px_mem_free(ctx, paths);
  return st;
}

/* The entities are refused with FORMAT, naming the file and the line of the
 * entity (its group 0 is on line 5 of the text). */
static void expect_dxf_refused(struct px_context *ctx, const char *what, const char *ents,
                               const char *needle) {
  const enum px_status st = dxf_parse(ctx, ents, NULL, NULL);
  const char *m = px_context_message(ctx);
  PX_CHECK_MSG(st == PX_STATUS_FORMAT, "%s: got %s: %s", what, px_status_name(st), m);
  PX_CHECK_MSG(strstr(m, "hostile.dxf:5:") != NULL && strstr(m, needle) != NULL,
               "%s: message \"%s\" lacks \"hostile.dxf:5:\" or \"%s\"", what, m, needle);
  px_context_clear(ctx);
}

/* Hostile entities (issue 19; moved from tests/granular/test_granular_hostile.c):
 * what used to crash or hang is refused with the file and the entity's
 * line, or read as what it means. */
static void test_dxf_entities_are_validated(struct px_context *ctx) {
  const double turn = 2 * 3.14159265358979323846;
  double sweep = 0;
  size_t np = 0;
  enum px_status st;
  expect_dxf_refused(ctx, "LINE 1e300 long", "0\nLINE\n10\n0\n20\n0\n11\n1e300\n21\n0\n",
                     "LINE end");
  expect_dxf_refused(ctx, "bulge 1e300",
                     "0\nLWPOLYLINE\n90\n2\n70\n1\n10\n0\n20\n0\n42\n1e300\n10\n1\n20\n0\n",
                     "bulge");
  /* was: a NULL dereference (no y at all) */
  expect_dxf_refused(ctx, "SPLINE without code 20",
                     "0\nSPLINE\n70\n8\n71\n1\n40\n0\n40\n0\n40\n1\n40\n1\n10\n0\n10\n1\n",
                     "every point needs both");
  /* was: a read past the fit points' y */
  expect_dxf_refused(ctx, "SPLINE without code 21",
                     "0\nSPLINE\n70\n8\n71\n3\n11\n0\n11\n1\n11\n2\n", "every point needs both");
  /* was: 0/0 points */
  expect_dxf_refused(ctx, "SPLINE with all weights 0",
                     "0\nSPLINE\n70\n8\n71\n1\n40\n0\n40\n0\n40\n1\n40\n1\n"
                     "10\n0\n20\n0\n41\n0\n10\n1\n20\n1\n41\n0\n",
                     "weight");
  /* was: de Boor read 16 control points of 2 */
  {
    char ents[1024];
    int k, o;
    o = snprintf(ents, sizeof ents, "0\nSPLINE\n70\n8\n71\n15\n");
    for (k = 0; k < 18; ++k) o += snprintf(ents + o, sizeof ents - (size_t)o, "40\n%d\n", k);
    snprintf(ents + o, sizeof ents - (size_t)o, "10\n0\n20\n0\n10\n1\n20\n1\n");
    expect_dxf_refused(ctx, "SPLINE of degree 15 with 2 control points", ents,
                       "more control points than the degree");
  }
  /* was: `while (a1 <= a0) a1 += 2 pi` for ever (1e20 + 2 pi == 1e20); now
   * the angles are taken modulo a turn: a closed circle */
  st = dxf_parse(ctx, "0\nARC\n10\n0\n20\n0\n40\n1\n50\n1e20\n51\n1e20\n", &np, &sweep);
  PX_CHECK_MSG(st == PX_STATUS_OK && np == 1, "ARC at 1e20 deg: %s: %s", px_status_name(st),
               px_context_message(ctx));
  PX_CHECK_NEAR(sweep, turn, 1e-9);
  px_context_clear(ctx);
  st = dxf_parse(ctx, "0\nELLIPSE\n10\n0\n20\n0\n11\n2\n21\n0\n40\n0.5\n41\n1e20\n42\n1e20\n", &np,
                 &sweep);
  PX_CHECK_MSG(st == PX_STATUS_OK && np == 1, "ELLIPSE at 1e20 rad: %s: %s", px_status_name(st),
               px_context_message(ctx));
  PX_CHECK_NEAR(sweep, turn, 1e-9);
  px_context_clear(ctx);
  /* a pie slice whose arc runs from 7200 to 7290 degrees (20 turns on):
   * still a quarter turn */
  st = dxf_parse(ctx,
                 "0\nARC\n10\n0\n20\n0\n40\n1\n50\n7200\n51\n7290\n"
                 "0\nLINE\n10\n0\n20\n1\n11\n0\n21\n0\n0\nLINE\n10\n0\n20\n0\n11\n1\n21\n0\n",
                 &np, &sweep);
  PX_CHECK_MSG(st == PX_STATUS_OK && np == 1, "pie: %s: %s", px_status_name(st),
               px_context_message(ctx));
  PX_CHECK_NEAR(sweep, 0.25 * turn, 1e-9);
  px_context_clear(ctx);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  const size_t held = px_mem_current(ctx, NULL);
  test_lines_chain_into_a_square(ctx);
  test_bulges_circles_and_mirrored_arcs(ctx);
  test_ellipse_and_spline(ctx);
  test_bad_drawings_name_their_line(ctx);
  test_read_a_file(ctx);
  test_dxf_entities_are_validated(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == held); /* nothing left allocated */
  px_context_free(ctx);
  return px_test_report("test_geometry_dxf");
}
