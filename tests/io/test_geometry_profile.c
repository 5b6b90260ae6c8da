/* Profile files (io/geometry/geo_profile.h): a Selig airfoil and a closed
 * point list read to their points with their file lines, orientation
 * and closure as documented; a Selig airfoil re-panelled onto its curve
 * (an ellipse: vertices on it, area pi a b, the leading edge at vertex
 * n/2); bad files refused with FILE:LINE and the reason. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "io/geometry/geo_profile.h"
#include "px_test.h"

#define PI 3.14159265358979323846
#define MAXP 100001

static void write_file(const char *path, const char *text) {
  FILE *f = fopen(path, "w");
  if (!f) return;
  fputs(text, f);
  fclose(f);
}

static int message_has(struct px_context *ctx, const char *text) {
  int ok = strstr(px_context_message(ctx), text) != NULL;
  if (!ok) fprintf(stderr, "message: %s\n  expected: %s\n", px_context_message(ctx), text);
  return ok;
}

static void test_selig_points_and_lines(struct px_context *ctx) {
  struct px_geo_polyline p;
  int open_te = -1;
  /* title, blank line, comment; closed (last = first): the repeat dropped */
  write_file("wedge.dat",
             "WEDGE AIRFOIL\n\n1.0 0.0\n0.5 0.05\n0.0 0.0\n# lower\n0.5 -0.05\n1.0 0.0\n");
  PX_CHECK_OK(ctx, px_geo_profile_read_selig(ctx, "wedge.dat", MAXP, &p, &open_te));
  PX_CHECK(p.n == 4 && open_te == 0 && strcmp(p.source, "wedge.dat") == 0);
  if (p.n == 4) {
    const double ex[4] = {1.0, 0.5, 0.0, 0.5}, ey[4] = {0.0, 0.05, 0.0, -0.05};
    const int el[4] = {3, 4, 5, 7};
    for (int k = 0; k < 4; ++k) {
      PX_CHECK(p.x[k] == ex[k] && p.y[k] == ey[k]);
      PX_CHECK(p.line[k] == el[k]);
    }
    PX_CHECK_NEAR(px_geo_polyline_area(&p), 0.05, 1e-15);
  }
  px_geo_polyline_free(ctx, &p);
  /* lower surface first (clockwise): turned around with the closed trailing
   * edge kept first, as a counter-clockwise file lists the points (reversed
   * whole, the trailing edge came last and the chain started one point down
   * the upper surface) */
  write_file("cw.dat", "CW\n1.0 0.0\n0.5 -0.05\n0.0 0.0\n0.5 0.05\n1.0 0.0\n");
  PX_CHECK_OK(ctx, px_geo_profile_read_selig(ctx, "cw.dat", MAXP, &p, &open_te));
  PX_CHECK(p.n == 4 && px_geo_polyline_area(&p) > 0);
  if (p.n == 4) /* the points without the repeat: lines 2, 5, 4, 3 */
    PX_CHECK(p.x[0] == 1.0 && p.y[0] == 0.0 && p.line[0] == 2 && p.x[1] == 0.5 && p.y[1] == 0.05 &&
             p.line[1] == 5 && p.x[3] == 0.5 && p.y[3] == -0.05 && p.line[3] == 3);
  px_geo_polyline_free(ctx, &p);
  /* an open trailing edge (gap 1% of the chord) is kept, flagged */
  write_file("open_te.dat", "OPEN\n1.0 0.005\n0.5 0.05\n0.0 0.0\n0.5 -0.05\n1.0 -0.005\n");
  PX_CHECK_OK(ctx, px_geo_profile_read_selig(ctx, "open_te.dat", MAXP, &p, &open_te));
  PX_CHECK(p.n == 5 && open_te == 1);
  px_geo_polyline_free(ctx, &p);
}

static void test_point_list(struct px_context *ctx) {
  struct px_geo_polyline p;
  write_file("square.txt", "# a square\n0 0\n2, 0\n2 2 # corner\n\n0 2\n0 0\n");
  PX_CHECK_OK(ctx, px_geo_profile_read_points(ctx, "square.txt", MAXP, &p));
  PX_CHECK(p.n == 4);
  if (p.n == 4) {
    const double ex[4] = {0, 2, 2, 0}, ey[4] = {0, 0, 2, 2};
    const int el[4] = {2, 3, 4, 6};
    for (int k = 0; k < 4; ++k) PX_CHECK(p.x[k] == ex[k] && p.y[k] == ey[k] && p.line[k] == el[k]);
    PX_CHECK_NEAR(px_geo_polyline_area(&p), 4.0, 0);
    PX_CHECK_NEAR(px_geo_polyline_perimeter(&p), 8.0, 0);
  }
  px_geo_polyline_free(ctx, &p);
  /* as listed: a clockwise list stays clockwise (orienting is the caller's) */
  write_file("square_cw.txt", "0 0\n0 2\n2 2\n2 0\n0 0\n");
  PX_CHECK_OK(ctx, px_geo_profile_read_points(ctx, "square_cw.txt", MAXP, &p));
  PX_CHECK(p.n == 4 && px_geo_polyline_area(&p) < 0);
  px_geo_polyline_free(ctx, &p);
}

/* An elliptic "airfoil" x = 0.5 + 0.5 cos t, y = 0.1 sin t (chord 1,
 * trailing edge at x = 1) given by 121 points, re-panelled to 80: every
 * vertex on the ellipse (within the spline's error), the leading edge
 * (0, 0) at vertex 40, area pi 0.5 0.1, cosine spacing clustering vertices
 * at the edges. */
static void test_selig_repanel_onto_the_curve(struct px_context *ctx) {
  struct px_geo_polyline p, q;
  int open_te = 0;
  FILE *f = fopen("ellipse.dat", "w");
  if (!f) return;
  fprintf(f, "ELLIPSE 20%%\n");
  for (int i = 0; i <= 120; ++i) {
    const double t = 2 * PI * i / 120;
    fprintf(f, "%.17g %.17g\n", 0.5 + 0.5 * cos(t), 0.1 * sin(t));
  }
  fclose(f);
  PX_CHECK_OK(ctx, px_geo_profile_read_selig(ctx, "ellipse.dat", MAXP, &p, &open_te));
  PX_CHECK(p.n == 120 && open_te == 0);
  PX_CHECK_OK(ctx, px_geo_profile_repanel_selig(ctx, "ellipse.dat", p.x, p.y, p.n, open_te, 80,
                                                PX_GEO_SPACING_COSINE, &q));
  PX_CHECK(q.n == 80 && q.line == NULL && strcmp(q.source, "ellipse.dat") == 0);
  if (q.n == 80) {
    for (size_t k = 0; k < q.n; ++k) {
      const double e = pow((q.x[k] - 0.5) / 0.5, 2) + pow(q.y[k] / 0.1, 2);
      PX_CHECK_NEAR(e, 1.0, 1e-3);
    }
    PX_CHECK_NEAR(q.x[40], 0.0, 1e-6);
    PX_CHECK_NEAR(q.y[40], 0.0, 1e-4);
    PX_CHECK_NEAR(q.x[0], 1.0, 1e-12);
    PX_CHECK_REL(px_geo_polyline_area(&q), PI * 0.5 * 0.1, 3e-3);
    /* cosine spacing: the panels at the edges are shorter than mid-chord */
    PX_CHECK(hypot(q.x[1] - q.x[0], q.y[1] - q.y[0]) <
             0.5 * hypot(q.x[21] - q.x[20], q.y[21] - q.y[20]));
  }
  px_geo_polyline_free(ctx, &q);
  /* a repeated point: no spline through it */
  {
    const double x[4] = {1, 0, 0, 0.5}, y[4] = {0, 0.1, 0.1, -0.1};
    PX_CHECK_STATUS(
        ctx,
        px_geo_profile_repanel_selig(ctx, "dup.dat", x, y, 4, 0, 40, PX_GEO_SPACING_UNIFORM, &q),
        PX_STATUS_CONFIG);
    PX_CHECK(message_has(ctx, "dup.dat: points 2 and 3 coincide"));
  }
  px_geo_polyline_free(ctx, &p);
}

static void test_bad_files_name_their_line(struct px_context *ctx) {
  struct px_geo_polyline p;
  int open_te = 0;
  char big[1200];
  write_file("garbage.txt", "0 0\n1 0\n1 one\n0 0\n");
  PX_CHECK_STATUS(ctx, px_geo_profile_read_points(ctx, "garbage.txt", MAXP, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx,
                       "garbage.txt:3: expected two numbers \"x y\" on this line, found "
                       "\"1 one\""));
  write_file("nan.dat", "T\n1 0\n0.5 nan\n0 0\n0.5 -0.1\n1 0\n");
  PX_CHECK_STATUS(ctx, px_geo_profile_read_selig(ctx, "nan.dat", MAXP, &p, &open_te),
                  PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "nan.dat:3: coordinate is not a finite number"));
  write_file("far.txt", "0 0\n1 2e9\n0 1\n0 0\n");
  PX_CHECK_STATUS(ctx, px_geo_profile_read_points(ctx, "far.txt", MAXP, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "far.txt:2: coordinate beyond +-1e+09"));
  memset(big, '1', sizeof big - 2);
  big[sizeof big - 2] = '\n';
  big[sizeof big - 1] = '\0';
  write_file("long.txt", big);
  PX_CHECK_STATUS(ctx, px_geo_profile_read_points(ctx, "long.txt", MAXP, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "long.txt:1: line longer than 1024 bytes"));
  {
    FILE *f = fopen("nul.txt", "wb");
    if (f) {
      fwrite("0 0\n1 \0 0\n", 1, 10, f);
      fclose(f);
    }
  }
  PX_CHECK_STATUS(ctx, px_geo_profile_read_points(ctx, "nul.txt", MAXP, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "nul.txt:2: NUL byte in the line: not a text file"));
  write_file("many.txt", "0 0\n1 0\n1 1\n0 1\n0.5 0.5\n0 0\n");
  PX_CHECK_STATUS(ctx, px_geo_profile_read_points(ctx, "many.txt", 5, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "many.txt:6: more than 5 points"));
  write_file("open.txt", "0 0\n1 0\n1 1\n0 1\n");
  PX_CHECK_STATUS(ctx, px_geo_profile_read_points(ctx, "open.txt", MAXP, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx,
                       "open.txt: contour not closed: the last point (line 4: 0 1) differs "
                       "from the first (line 1: 0 0)"));
  write_file("few.txt", "0 0\n1 0\n0 0\n");
  PX_CHECK_STATUS(ctx, px_geo_profile_read_points(ctx, "few.txt", MAXP, &p), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "few.txt: only 3 points"));
  write_file("lednicer.dat", "NACA 0012\n61. 61.\n\n0 0\n0.5 0.06\n1 0\n");
  PX_CHECK_STATUS(ctx, px_geo_profile_read_selig(ctx, "lednicer.dat", MAXP, &p, &open_te),
                  PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx,
                       "lednicer.dat:2: \"61 61\" looks like the point counts of a "
                       "Lednicer-format file"));
  write_file("gap.dat", "wide gap\n1.0 0.1\n0.5 0.06\n0.0 0.0\n0.5 -0.06\n1.0 -0.1\n");
  PX_CHECK_STATUS(ctx, px_geo_profile_read_selig(ctx, "gap.dat", MAXP, &p, &open_te),
                  PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx,
                       "gap.dat: contour not closed: the last point (line 6) is 0.2 from "
                       "the first (line 2)"));
  PX_CHECK_STATUS(ctx, px_geo_profile_read_points(ctx, "no_such_file.txt", MAXP, &p), PX_STATUS_IO);
  PX_CHECK(message_has(ctx, "no_such_file.txt: cannot open profile file"));
  mkdir("adir.dat", 0755);
  PX_CHECK_STATUS(ctx, px_geo_profile_read_selig(ctx, "adir.dat", MAXP, &p, &open_te),
                  PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "adir.dat: not a regular file (a directory)"));
  PX_CHECK(p.n == 0 && p.x == NULL && open_te == 0); /* a failed read holds nothing */
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  const size_t held = px_mem_current(ctx, NULL);
  test_selig_points_and_lines(ctx);
  test_point_list(ctx);
  test_selig_repanel_onto_the_curve(ctx);
  test_bad_files_name_their_line(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == held); /* nothing left allocated */
  px_context_free(ctx);
  return px_test_report("test_geometry_profile");
}
