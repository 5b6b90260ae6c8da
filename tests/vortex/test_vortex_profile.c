/* Profiles: built-in shapes have the right size, orientation and spacing;
 * Selig files are re-panelled onto the true surface; bad input gets a clear
 * error naming the file line. */
#include <string.h>

#include "px_test.h"
#include "solvers/vortex/vortex_profile.h"

#define PI 3.14159265358979323846

static double seg(const struct px_vortex_contour *c, size_t k) {
  size_t j = (k + 1) % c->n;
  return hypot(c->x[j] - c->x[k], c->y[j] - c->y[k]);
}

static void write_file(const char *path, const char *text) {
  FILE *f = fopen(path, "w");
  fputs(text, f);
  fclose(f);
}

static double naca_yt(double t, double x) {
  return 5.0 * t *
         (0.2969 * sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x * x * x -
          0.1036 * x * x * x * x);
}

static void test_shapes(struct px_context *ctx) {
  struct px_vortex_contour c;
  int rev = 0;
  PX_CHECK_OK(ctx, px_vortex_profile_circle(ctx, 0.5, 400, &c));
  PX_CHECK_OK(ctx, px_vortex_profile_check(ctx, &c, &rev));
  PX_CHECK(rev == 0);
  /* inscribed 400-gon: area = n/2 r^2 sin(2 pi / n) */
  PX_CHECK_REL(px_vortex_profile_area(&c), 200.0 * 0.25 * sin(2.0 * PI / 400.0), 1e-12);
  PX_CHECK(px_vortex_profile_contains(&c, 0.1, 0.2));
  PX_CHECK(!px_vortex_profile_contains(&c, 0.6, 0.0));
  px_vortex_contour_free(ctx, &c);

  PX_CHECK_OK(ctx, px_vortex_profile_ellipse(ctx, 1.0, 0.25, 300, &c));
  PX_CHECK_OK(ctx, px_vortex_profile_check(ctx, &c, &rev));
  double lmin = 1e9, lmax = 0.0;
  for (size_t k = 0; k < c.n; ++k) {
    lmin = fmin(lmin, seg(&c, k));
    lmax = fmax(lmax, seg(&c, k));
  }
  PX_CHECK_MSG(lmax / lmin < 1.01, "ellipse panels not of equal length: %g .. %g", lmin, lmax);
  PX_CHECK_REL(px_vortex_profile_area(&c), PI * 0.25, 2e-4);
  px_vortex_contour_free(ctx, &c);

  PX_CHECK_OK(ctx, px_vortex_profile_plate(ctx, 1.0, 0.02, 1300, &c));
  PX_CHECK_OK(ctx, px_vortex_profile_check(ctx, &c, &rev));
  PX_CHECK(rev == 0);
  double xmin = 1, xmax = -1, ymin = 1, ymax = -1;
  lmin = 1e9;
  lmax = 0.0;
  for (size_t k = 0; k < c.n; ++k) {
    xmin = fmin(xmin, c.x[k]);
    xmax = fmax(xmax, c.x[k]);
    ymin = fmin(ymin, c.y[k]);
    ymax = fmax(ymax, c.y[k]);
    lmin = fmin(lmin, seg(&c, k));
    lmax = fmax(lmax, seg(&c, k));
  }
  PX_CHECK_NEAR(xmax, 0.5, 1e-12);
  PX_CHECK_NEAR(xmin, -0.5, 1e-6);
  PX_CHECK_NEAR(ymax, 0.01, 1e-6);
  PX_CHECK_NEAR(ymin, -0.01, 1e-6);
  PX_CHECK_MSG(lmax / lmin < 1.01, "plate panels uneven: %g .. %g", lmin, lmax);
  PX_CHECK_REL(lmax, (2.0 * 0.98 + PI * 0.02) / 1300.0, 0.01);
  px_vortex_contour_free(ctx, &c);

  PX_CHECK_OK(ctx, px_vortex_profile_naca4(ctx, "0012", 200, &c));
  PX_CHECK_OK(ctx, px_vortex_profile_check(ctx, &c, &rev));
  PX_CHECK(rev == 0);
  double tmax = 0.0;
  for (size_t k = 0; k < c.n; ++k) tmax = fmax(tmax, 2.0 * fabs(c.y[k]));
  PX_CHECK_NEAR(tmax, 0.12, 2e-4);
  PX_CHECK_NEAR(c.x[0], 1.0, 1e-12); /* trailing edge first */
  PX_CHECK_NEAR(c.y[0], 0.0, 1e-12);
  PX_CHECK_NEAR(c.x[100], 0.0, 1e-12); /* leading edge halfway */
  px_vortex_contour_free(ctx, &c);

  /* placement: angle of attack rotates clockwise (nose up for flow along +x) */
  PX_CHECK_OK(ctx, px_vortex_profile_naca4(ctx, "0012", 100, &c));
  px_vortex_profile_place(&c, 2.0, 1.0, 2.0, 10.0);
  PX_CHECK_NEAR(c.x[50], 2.0, 1e-12); /* leading edge at the position */
  PX_CHECK_NEAR(c.y[50], 1.0, 1e-12);
  PX_CHECK_NEAR(c.x[0], 2.0 + 2.0 * cos(10.0 * PI / 180.0), 1e-12);
  PX_CHECK_NEAR(c.y[0], 1.0 - 2.0 * sin(10.0 * PI / 180.0), 1e-12);
  px_vortex_contour_free(ctx, &c);
}

static void test_selig(struct px_context *ctx) {
  /* a NACA 0012 written from the formula, 121 points, Selig order */
  char text[20000];
  size_t pos = (size_t)snprintf(text, sizeof text, "NACA 0012 test section\n");
  int np = 60;
  for (int j = np; j >= 0; --j) {
    double x = 0.5 * (1.0 - cos(PI * j / np));
    pos += (size_t)snprintf(text + pos, sizeof text - pos, "%.8f %.8f\n", x, naca_yt(0.12, x));
  }
  for (int j = 1; j <= np; ++j) {
    double x = 0.5 * (1.0 - cos(PI * j / np));
    pos += (size_t)snprintf(text + pos, sizeof text - pos, "%.8f %.8f\n", x, -naca_yt(0.12, x));
  }
  write_file("naca0012_test.dat", text);
  struct px_vortex_contour c;
  PX_CHECK_OK(ctx, px_vortex_profile_read_selig(ctx, "naca0012_test.dat", 160,
                                                PX_VORTEX_SPACING_COSINE, &c));
  PX_CHECK(c.n == 160);
  double err = 0.0, xle = 1.0;
  for (size_t k = 0; k < c.n; ++k) {
    if (c.x[k] < 0.0) continue;
    err = fmax(err, fabs(fabs(c.y[k]) - naca_yt(0.12, c.x[k])));
    xle = fmin(xle, c.x[k]);
  }
  PX_CHECK_MSG(err < 2e-4, "re-panelled points off the NACA surface by %g", err);
  PX_CHECK_NEAR(xle, 0.0, 1e-6);
  PX_CHECK_NEAR(c.x[0], 1.0, 1e-9);
  PX_CHECK_NEAR(c.x[80], 0.0, 1e-5);
  PX_CHECK(c.y[40] > 0.0 && c.y[120] < 0.0); /* upper surface first: counter-clockwise */
  int rev = 0;
  PX_CHECK_OK(ctx, px_vortex_profile_check(ctx, &c, &rev));
  PX_CHECK(rev == 0);
  /* cosine spacing: panels at the leading edge much shorter than mid-chord */
  PX_CHECK(seg(&c, 79) < 0.2 * seg(&c, 40));
  px_vortex_contour_free(ctx, &c);

  /* uniform spacing */
  PX_CHECK_OK(ctx, px_vortex_profile_read_selig(ctx, "naca0012_test.dat", 160,
                                                PX_VORTEX_SPACING_UNIFORM, &c));
  PX_CHECK(seg(&c, 79) > 0.5 * seg(&c, 40));
  px_vortex_contour_free(ctx, &c);

  /* an open trailing edge (gap 0.2% chord) gets a closing panel */
  write_file("open_te.dat",
             "open\n1.0 0.001\n0.5 0.06\n0.1 0.04\n0.0 0.0\n0.1 -0.04\n0.5 -0.06\n1.0 -0.001\n");
  PX_CHECK_OK(ctx,
              px_vortex_profile_read_selig(ctx, "open_te.dat", 40, PX_VORTEX_SPACING_COSINE, &c));
  PX_CHECK_NEAR(c.x[c.n - 1], 1.0, 1e-9);
  PX_CHECK_NEAR(c.y[c.n - 1], -0.001, 1e-9);
  px_vortex_contour_free(ctx, &c);

  /* clockwise file (lower surface first) is accepted and turned around */
  write_file("cw.dat", "cw\n1.0 0.0\n0.5 -0.06\n0.1 -0.04\n0.0 0.0\n0.1 0.04\n0.5 0.06\n1.0 0.0\n");
  PX_CHECK_OK(ctx, px_vortex_profile_read_selig(ctx, "cw.dat", 40, PX_VORTEX_SPACING_COSINE, &c));
  PX_CHECK(c.n == 40 && c.y[10] > 0.0);
  PX_CHECK(px_vortex_profile_area(&c) > 0.0);
  px_vortex_contour_free(ctx, &c);
}

/* Read the Selig file `a` and `b` (160 panels, cosine): 1 when their panels
 * are the same to the bit (+0 and -0 alike), the first difference printed. */
static int selig_same(struct px_context *ctx, const char *a, const char *b) {
  struct px_vortex_contour ca, cb;
  PX_CHECK_OK(ctx, px_vortex_profile_read_selig(ctx, a, 160, PX_VORTEX_SPACING_COSINE, &ca));
  PX_CHECK_OK(ctx, px_vortex_profile_read_selig(ctx, b, 160, PX_VORTEX_SPACING_COSINE, &cb));
  int same = ca.n == cb.n;
  for (size_t k = 0; same && k < ca.n; ++k)
    if (!(ca.x[k] == cb.x[k] && ca.y[k] == cb.y[k])) {
      fprintf(stderr, "%s vs %s: vertex %zu (%.17g, %.17g) vs (%.17g, %.17g)\n", a, b, k, ca.x[k],
              ca.y[k], cb.x[k], cb.y[k]);
      same = 0;
    }
  px_vortex_contour_free(ctx, &ca);
  px_vortex_contour_free(ctx, &cb);
  return same;
}

/* A clockwise Selig file is the counter-clockwise one turned around
 * (docs/vortex.md, "Bodies"): the same panels to the bit, the trailing edge
 * first, closed (the point repeated at the end, as cases/vortex/naca0012.dat)
 * or open (two trailing-edge points). Reversing the whole list used to move
 * a closed trailing edge's point to the end: the clockwise contour started
 * one point down the upper surface. */
static void test_selig_clockwise(struct px_context *ctx) {
  const int np = 60;
  double x[2 * 60 + 1], y[2 * 60 + 1];
  for (int j = np; j >= 0; --j) { /* upper surface, trailing edge to nose */
    x[np - j] = 0.5 * (1.0 - cos(PI * j / np));
    y[np - j] = naca_yt(0.12, x[np - j]);
  }
  for (int j = 1; j <= np; ++j) { /* lower surface, nose to trailing edge */
    x[np + j] = 0.5 * (1.0 - cos(PI * j / np));
    y[np + j] = -naca_yt(0.12, x[np + j]);
  }
  const int m = 2 * np + 1;
  for (int open = 0; open < 2; ++open) {
    /* open: the trailing edge at y = +-0.0006 */
    double d = open ? 0.0006 : 0.0;
    char ccw[20000], cw[20000];
    size_t pa = (size_t)snprintf(ccw, sizeof ccw, "ccw\n");
    size_t pb = (size_t)snprintf(cw, sizeof cw, "cw\n");
    for (int i = 0; i < m; ++i) {
      double ya = y[i] + (i == 0 ? d : i == m - 1 ? -d : 0.0);
      pa += (size_t)snprintf(ccw + pa, sizeof ccw - pa, "%.8f %.8f\n", x[i], ya);
      int r = m - 1 - i; /* the same points, lower surface first */
      double yb = y[r] + (r == 0 ? d : r == m - 1 ? -d : 0.0);
      pb += (size_t)snprintf(cw + pb, sizeof cw - pb, "%.8f %.8f\n", x[r], yb);
    }
    write_file("selig_ccw.dat", ccw);
    write_file("selig_cw.dat", cw);
    PX_CHECK_MSG(selig_same(ctx, "selig_ccw.dat", "selig_cw.dat"),
                 "%s trailing edge: the clockwise file's panels differ", open ? "open" : "closed");
    struct px_vortex_contour c;
    PX_CHECK_OK(
        ctx, px_vortex_profile_read_selig(ctx, "selig_cw.dat", 160, PX_VORTEX_SPACING_COSINE, &c));
    PX_CHECK_MSG(c.x[0] == 1.0 && c.y[0] == d, "first vertex (%.17g, %.17g)", c.x[0], c.y[0]);
    px_vortex_contour_free(ctx, &c);
  }
  remove("selig_ccw.dat");
  remove("selig_cw.dat");
}

static int message_has(struct px_context *ctx, const char *what) {
  const char *m = px_context_message(ctx);
  int ok = strstr(m, what) != NULL;
  if (!ok) fprintf(stderr, "message \"%s\" lacks \"%s\"\n", m, what);
  return ok;
}

static void test_errors(struct px_context *ctx) {
  struct px_vortex_contour c;
  write_file("nan.dat", "bad\n1.0 0.0\n0.5 0.06\nnan 0.04\n0.0 0.0\n0.5 -0.06\n1.0 0.0\n");
  PX_CHECK_STATUS(ctx,
                  px_vortex_profile_read_selig(ctx, "nan.dat", 40, PX_VORTEX_SPACING_COSINE, &c),
                  PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "nan.dat:4:"));
  PX_CHECK(message_has(ctx, "not a finite number"));

  write_file("garbage.txt", "0 0\n1 0\n1 oops\n0 0\n");
  PX_CHECK_STATUS(ctx, px_vortex_profile_read_points(ctx, "garbage.txt", 0, &c), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "garbage.txt:3:"));

  write_file("open.txt", "0 0\n1 0\n1 1\n0 1\n");
  PX_CHECK_STATUS(ctx, px_vortex_profile_read_points(ctx, "open.txt", 0, &c), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "not closed"));
  PX_CHECK(message_has(ctx, "line 4"));

  /* bow tie: 0,0 -> 1,1 -> 1,0 -> 0,1 -> back */
  write_file("bowtie.txt", "# bow tie\n0 0\n1 1\n1 0\n0 1\n0 0\n");
  PX_CHECK_STATUS(ctx, px_vortex_profile_read_points(ctx, "bowtie.txt", 0, &c), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "self-intersecting"));
  PX_CHECK(message_has(ctx, "line 2 to line 3"));

  write_file("selig_open.dat", "wide gap\n1.0 0.1\n0.5 0.06\n0.0 0.0\n0.5 -0.06\n1.0 -0.1\n");
  PX_CHECK_STATUS(
      ctx, px_vortex_profile_read_selig(ctx, "selig_open.dat", 40, PX_VORTEX_SPACING_COSINE, &c),
      PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "not closed"));

  write_file("lednicer.dat",
             "NACA 0012 lednicer\n3. 3.\n\n0 0\n0.5 0.06\n1 0\n\n0 0\n0.5 -0.06\n1 0\n");
  PX_CHECK_STATUS(
      ctx, px_vortex_profile_read_selig(ctx, "lednicer.dat", 40, PX_VORTEX_SPACING_COSINE, &c),
      PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "Lednicer"));

  PX_CHECK_STATUS(ctx, px_vortex_profile_circle(ctx, 1.0, 4, &c), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "too few"));
  PX_CHECK_STATUS(ctx, px_vortex_profile_circle(ctx, -1.0, 100, &c), PX_STATUS_CONFIG);
  PX_CHECK_STATUS(ctx, px_vortex_profile_naca4(ctx, "00x2", 100, &c), PX_STATUS_CONFIG);
  PX_CHECK_STATUS(
      ctx, px_vortex_profile_read_selig(ctx, "no_such_file.dat", 100, PX_VORTEX_SPACING_COSINE, &c),
      PX_STATUS_IO);

  /* overlapping bodies */
  struct px_vortex_contour a, b;
  PX_CHECK_OK(ctx, px_vortex_profile_circle(ctx, 1.0, 64, &a));
  PX_CHECK_OK(ctx, px_vortex_profile_circle(ctx, 1.0, 64, &b));
  px_vortex_profile_place(&b, 1.5, 0.0, 1.0, 0.0);
  PX_CHECK_STATUS(ctx, px_vortex_profile_check_pair(ctx, &a, &b), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "overlap"));
  px_vortex_profile_place(&b, 1.5, 0.0, 1.0, 0.0); /* now at x = 3: apart */
  PX_CHECK_OK(ctx, px_vortex_profile_check_pair(ctx, &a, &b));
  px_vortex_profile_place(&b, -0.6, 0.0, 0.2, 0.0); /* small circle inside a */
  PX_CHECK_STATUS(ctx, px_vortex_profile_check_pair(ctx, &a, &b), PX_STATUS_CONFIG);
  px_vortex_contour_free(ctx, &a);
  px_vortex_contour_free(ctx, &b);

  /* clockwise point list is reversed */
  write_file("cw.txt", "0 0\n0 1\n1 1\n1 0\n0 0\n");
  PX_CHECK_OK(ctx, px_vortex_profile_read_points(ctx, "cw.txt", 0, &c));
  PX_CHECK(c.n == 4 && px_vortex_profile_area(&c) > 0.0);
  px_vortex_contour_free(ctx, &c);
  PX_CHECK_OK(ctx, px_vortex_profile_read_points(ctx, "cw.txt", 40, &c));
  PX_CHECK(c.n == 40);
  PX_CHECK_NEAR(seg(&c, 3), 0.1, 1e-12);
  px_vortex_contour_free(ctx, &c);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  test_shapes(ctx);
  test_selig(ctx);
  test_selig_clockwise(ctx);
  test_errors(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  return px_test_report("test_vortex_profile");
}
