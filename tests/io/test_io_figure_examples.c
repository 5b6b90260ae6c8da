/* Example pictures for people to look at (PNG files in build/tests/io/examples/):
 * a vortex wake coloured by circulation around a filled NACA 0012, a part
 * contour coloured by a per-segment impact energy among granular discs, a
 * raster velocity field with a body, and two line plots (linear, log y).
 * Checks that each file decodes to the requested size, that its frame holds
 * the expected colours, and times the 50k-point snapshot. */
#include <cairo.h>
#include <math.h>
#include <string.h>

#include "io/figure_impl.h"
#include "partix/figure.h"
#include "partix/rng.h"
#include "px_test.h"
#include "px_test_fonts.h"

#define PI 3.14159265358979323846
#define NVORT 50000

/* NACA 0012 (chord 1) rotated by alpha about the quarter chord; n points
 * around the closed contour (trailing edge -> upper -> leading edge ->
 * lower). Thickness: NACA Report 824, y_t = 5 t (0.2969 sqrt(x) - 0.1260 x
 * - 0.3516 x^2 + 0.2843 x^3 - 0.1015 x^4), t = 0.12. */
static void naca0012(int n, double alpha, double *x, double *y) {
  int i;
  for (i = 0; i < n; ++i) {
    double s = 2.0 * PI * i / n, xc = 0.5 * (1.0 + cos(s)), yt, xr, yr;
    yt = 5.0 * 0.12 *
         (0.2969 * sqrt(xc) - 0.1260 * xc - 0.3516 * xc * xc + 0.2843 * xc * xc * xc -
          0.1015 * xc * xc * xc * xc);
    if (s > PI) yt = -yt;
    xr = xc - 0.25;
    yr = yt;
    x[i] = 0.25 + xr * cos(alpha) + yr * sin(alpha);
    y[i] = -xr * sin(alpha) + yr * cos(alpha);
  }
}

static int check_png(const char *path, int w, int h) {
  cairo_surface_t *s = cairo_image_surface_create_from_png(path);
  int ok = cairo_surface_status(s) == CAIRO_STATUS_SUCCESS &&
           cairo_image_surface_get_width(s) == w && cairo_image_surface_get_height(s) == h;
  cairo_surface_destroy(s);
  return ok;
}

/* Number of distinct-ish colours (coarse 4-bit histogram) inside a rectangle:
 * a picture that failed to draw is one or two colours. */
static int colour_variety(const char *path, const double r[4]) {
  cairo_surface_t *s = cairo_image_surface_create_from_png(path);
  static unsigned char seen[4096];
  int x, y, count = 0, stride;
  unsigned char *d;
  memset(seen, 0, sizeof seen);
  if (cairo_surface_status(s) != CAIRO_STATUS_SUCCESS) return 0;
  d = cairo_image_surface_get_data(s);
  stride = cairo_image_surface_get_stride(s);
  for (y = (int)r[1] + 2; y < (int)r[3] - 2; ++y)
    for (x = (int)r[0] + 2; x < (int)r[2] - 2; ++x) {
      unsigned v;
      uint32_t p;
      memcpy(&p, d + (size_t)y * (size_t)stride + 4 * (size_t)x, 4);
      v = ((p >> 20) & 0xf) << 8 | ((p >> 12) & 0xf) << 4 | ((p >> 4) & 0xf);
      if (!seen[v]) seen[v] = 1, ++count;
    }
  cairo_surface_destroy(s);
  return count;
}

static void example_wake(struct px_context *ctx) {
  struct px_figure *fig = NULL;
  static float vx[NVORT], vy[NVORT], gam[NVORT];
  double ax[200], ay[200], frame[4], cbar[4], t0;
  uint64_t rng[PX_RNG_WORDS];
  int i;
  px_rng_seed(rng, 42);
  naca0012(200, 8.0 * PI / 180.0, ax, ay);
  for (i = 0; i < NVORT; ++i) {
    double u = px_rng_uniform(rng), g, sign;
    if (u < 0.3) {
      /* two shear layers leaving the trailing edge, rolling up downstream */
      double s = 2.0 * px_rng_uniform(rng);
      sign = px_rng_uniform(rng) < 0.5 ? 1.0 : -1.0;
      vx[i] = (float)(1.0 + s);
      vy[i] = (float)(-0.14 + sign * (0.015 + 0.06 * s) + 0.08 * s * sin(2.5 * s) +
                      0.012 * px_rng_normal(rng));
      g = -sign * (0.8 + 0.2 * px_rng_normal(rng)) * exp(-0.5 * s);
    } else {
      /* a Karman street: eddies alternate in sign and side, grow and decay */
      int m = (int)(px_rng_uniform(rng) * 7.0);
      double sig = 0.09 + 0.02 * m, r = sig * sqrt(-2.0 * log(1.0 - px_rng_uniform(rng)));
      double th = 2.0 * PI * px_rng_uniform(rng), xc = 3.1 + 0.8 * m;
      double yc = -0.2 + ((m % 2) ? 0.2 : -0.2);
      sign = (m % 2) ? -1.0 : 1.0;
      th += sign * 2.5 * r / sig; /* spiral arms */
      vx[i] = (float)(xc + 1.3 * r * cos(th));
      vy[i] = (float)(yc + r * sin(th));
      g = sign * exp(-0.5 * r * r / (sig * sig)) * (1.0 + 0.2 * px_rng_normal(rng)) /
          (1.0 + 0.12 * m);
    }
    gam[i] = (float)(1e-3 * g);
  }
  PX_CHECK_OK(ctx, px_figure_create(ctx, 1400, 560, &fig));
  px_figure_set_view(fig, -0.5, 8.5, -1.1, 0.7);
  px_figure_set_colormap(fig, PX_COLORMAP_COOLWARM);
  px_figure_set_range(fig, -1e-3, 1e-3);
  px_figure_set_field(fig, "\xce\x93", "m\xc2\xb2/s"); /* Γ [m²/s] */
  px_figure_set_title(fig, "Vortex wake behind a NACA 0012 at \xce\xb1 = 8\xc2\xb0");
  px_figure_set_time(fig, 12.5, "s");
  px_figure_set_axis_labels(fig, "x [m]", "y [m]");
  PX_CHECK_OK(ctx, px_figure_add_points(fig, PX_DTYPE_F32, NVORT, vx, vy, gam, 2.0));
  px_figure_set_fill(fig, 0.6, 0.6, 0.6);
  px_figure_set_color(fig, 0.2, 0.2, 0.2);
  px_figure_set_line_width(fig, 1.2);
  PX_CHECK_OK(ctx, px_figure_add_polyline(fig, PX_DTYPE_F64, 200, ax, ay, PX_FIGURE_LINE_FILLED));
  t0 = px_time_now();
  PX_CHECK_OK(ctx, px_figure_write_png(fig, "examples/wake.png"));
  printf("wake.png: %d points drawn and written in %.3f s\n", NVORT, px_time_now() - t0);
  PX_CHECK(check_png("examples/wake.png", 1400, 560));
  PX_CHECK_OK(ctx, px_figure_layout_rects(fig, frame, cbar));
  PX_CHECK(colour_variety("examples/wake.png", frame) > 50);
  px_figure_free(fig);
}

static void example_contour(struct px_context *ctx) {
  struct px_figure *fig = NULL;
  enum { NC = 240, ND = 400 };
  double cx[NC], cy[NC], e[NC], dx[ND], dy[ND], dr[ND], frame[4], cbar[4];
  uint64_t rng[PX_RNG_WORDS];
  int i, nd = 0;
  px_rng_seed(rng, 7);
  /* a rounded part (superellipse) hit from the upper left */
  for (i = 0; i < NC; ++i) {
    double s = 2.0 * PI * i / NC, c = cos(s), sn = sin(s);
    cx[i] = 0.6 * copysign(pow(fabs(c), 0.6), c);
    cy[i] = 0.35 * copysign(pow(fabs(sn), 0.6), sn);
  }
  for (i = 0; i < NC; ++i) {
    double mx = 0.5 * (cx[i] + cx[(i + 1) % NC]), my = 0.5 * (cy[i] + cy[(i + 1) % NC]);
    double d = hypot(mx + 0.35, my - 0.3);
    e[i] = 2.5 * exp(-d * d / 0.08) + 0.05 * px_rng_uniform(rng);
  }
  while (nd < ND) {
    double x = -1.2 + 2.4 * px_rng_uniform(rng), y = 0.2 + 0.8 * px_rng_uniform(rng);
    double r = 0.02 + 0.02 * px_rng_uniform(rng);
    if (pow(fabs(x) / 0.65, 2.0 / 0.6) + pow(fabs(y) / 0.4, 2.0 / 0.6) < 1.0) continue;
    dx[nd] = x, dy[nd] = y, dr[nd] = r, ++nd;
  }
  PX_CHECK_OK(ctx, px_figure_create(ctx, 1000, 650, &fig));
  px_figure_set_colormap(fig, PX_COLORMAP_INFERNO);
  px_figure_set_range(fig, 0.0, 2.5);
  px_figure_set_field(fig, "impact energy", "J");
  px_figure_set_title(fig, "Impact energy along the part contour");
  px_figure_set_time(fig, 0.0375, "s");
  px_figure_set_axis_labels(fig, "x [m]", "y [m]");
  px_figure_set_color(fig, 0.55, 0.62, 0.72);
  PX_CHECK_OK(ctx, px_figure_add_discs(fig, PX_DTYPE_F64, ND, dx, dy, dr, 0.0, NULL));
  px_figure_set_line_width(fig, 7.0);
  PX_CHECK_OK(ctx, px_figure_add_polyline_values(fig, PX_DTYPE_F64, NC, cx, cy, 1, e));
  PX_CHECK_OK(ctx, px_figure_write_png(fig, "examples/contour.png"));
  PX_CHECK(check_png("examples/contour.png", 1000, 650));
  PX_CHECK_OK(ctx, px_figure_layout_rects(fig, frame, cbar));
  PX_CHECK(colour_variety("examples/contour.png", frame) > 20);
  px_figure_free(fig);
}

static void example_raster(struct px_context *ctx) {
  struct px_figure *fig = NULL;
  enum { NX = 240, NY = 120, NB = 100 };
  static double speed[NX * NY];
  double bx[NB], by[NB], frame[4], cbar[4];
  int i, j;
  /* Two Lamb-Oseen vortices (core radius 0.15) in a uniform stream, a
   * cylinder of radius 0.3 at the origin (NaN inside). */
  for (j = 0; j < NY; ++j)
    for (i = 0; i < NX; ++i) {
      double x = -2.0 + 6.0 * (i + 0.5) / NX, y = -1.5 + 3.0 * (j + 0.5) / NY, u = 1.0, v = 0.0;
      int k;
      for (k = 0; k < 2; ++k) {
        double xv = 1.5, yv = k ? 0.4 : -0.4, g = k ? -1.5 : 1.5, dx = x - xv, dy = y - yv;
        double r2 = dx * dx + dy * dy, f = g / (2.0 * PI * r2) * (1.0 - exp(-r2 / 0.0225));
        u += -f * dy;
        v += f * dx;
      }
      speed[j * NX + i] = x * x + y * y < 0.09 ? NAN : hypot(u, v);
    }
  for (i = 0; i < NB; ++i) {
    bx[i] = 0.3 * cos(2.0 * PI * i / NB);
    by[i] = 0.3 * sin(2.0 * PI * i / NB);
  }
  PX_CHECK_OK(ctx, px_figure_create(ctx, 1000, 560, &fig));
  px_figure_set_colormap(fig, PX_COLORMAP_INFERNO);
  px_figure_set_field(fig, "|u|", "m/s");
  px_figure_set_title(fig, "Velocity magnitude, mid-plane slice");
  px_figure_set_time(fig, 3.0, "s");
  px_figure_set_axis_labels(fig, "x [m]", "y [m]");
  PX_CHECK_OK(ctx, px_figure_add_raster(fig, PX_DTYPE_F64, NX, NY, speed, -2.0, 4.0, -1.5, 1.5));
  px_figure_set_color(fig, 1.0, 1.0, 1.0);
  px_figure_set_line_width(fig, 1.5);
  PX_CHECK_OK(ctx, px_figure_add_polyline(fig, PX_DTYPE_F64, NB, bx, by, PX_FIGURE_LINE_CLOSED));
  PX_CHECK_OK(ctx, px_figure_write_png(fig, "examples/raster.png"));
  PX_CHECK(check_png("examples/raster.png", 1000, 560));
  PX_CHECK_OK(ctx, px_figure_layout_rects(fig, frame, cbar));
  PX_CHECK(colour_variety("examples/raster.png", frame) > 50);
  px_figure_free(fig);
}

static void example_plots(struct px_context *ctx) {
  struct px_plot *p = NULL;
  enum { N = 801 };
  static double t[N], cx[N], cy[N], ek[N], ens[N];
  double frame[4];
  int i;
  for (i = 0; i < N; ++i) {
    t[i] = 20.0 * i / (N - 1);
    cx[i] = 0.32 + 0.04 * sin(2.0 * PI * 0.42 * t[i]) + 0.4 * exp(-t[i]);
    cy[i] = 0.9 * (1.0 - exp(-t[i] / 1.5)) + 0.35 * sin(2.0 * PI * 0.21 * t[i]);
    ek[i] = 0.5 * exp(-t[i] / 3.0);
    ens[i] = 40.0 * exp(-t[i] / 1.2) + 1e-3;
  }
  PX_CHECK_OK(ctx, px_plot_create(ctx, 1000, 560, &p));
  px_plot_set_title(p, "Force coefficients");
  px_plot_set_labels(p, "t [s]", "C [-]");
  PX_CHECK_OK(ctx, px_plot_add_series(p, "C_x (drag)", N, t, cx));
  PX_CHECK_OK(ctx, px_plot_add_series(p, "C_y (lift)", N, t, cy));
  PX_CHECK_OK(ctx, px_plot_write_png(p, "examples/plot_coefficients.png"));
  PX_CHECK(check_png("examples/plot_coefficients.png", 1000, 560));
  PX_CHECK_OK(ctx, px_plot_layout_frame(p, frame));
  PX_CHECK(colour_variety("examples/plot_coefficients.png", frame) > 5);
  px_plot_free(p);

  PX_CHECK_OK(ctx, px_plot_create(ctx, 800, 500, &p));
  px_plot_set_title(p, "Energy decay");
  px_plot_set_labels(p, "t [s]", "E [J]");
  px_plot_set_log_y(p, 1);
  PX_CHECK_OK(ctx, px_plot_add_series(p, "kinetic", N, t, ek));
  PX_CHECK_OK(ctx, px_plot_add_series(p, "enstrophy", N, t, ens));
  PX_CHECK_OK(ctx, px_plot_write_png(p, "examples/plot_energy_log.png"));
  PX_CHECK(check_png("examples/plot_energy_log.png", 800, 500));
  px_plot_free(p);
}

int main(void) {
  struct px_context *ctx = NULL;
  px_context_create(&ctx);
  PX_CHECK_OK(ctx, px_file_mkdirs(ctx, "examples"));
  example_wake(ctx);
  example_contour(ctx);
  example_raster(ctx);
  example_plots(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  px_test_release_fonts();
  return px_test_report("test_io_figure_examples");
}
