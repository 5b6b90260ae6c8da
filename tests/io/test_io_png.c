/* PNG pictures read back with cairo: colormap values against the published
 * tables, pixel colours where particles, contours, fills and raster cells
 * were drawn, the background, a monotonic colour bar, automatic ranges, and
 * line plots whose series pass through the expected pixels. */
#include <cairo.h>
#include <math.h>
#include <string.h>

#include "io/figure_impl.h"
#include "partix/figure.h"
#include "px_test.h"
#include "px_test_fonts.h"

/* ---- helpers ------------------------------------------------------------- */

struct image {
  cairo_surface_t *s;
  unsigned char *data;
  int w, h, stride;
};

static int image_load(struct image *im, const char *path) {
  im->s = cairo_image_surface_create_from_png(path);
  if (cairo_surface_status(im->s) != CAIRO_STATUS_SUCCESS) return 0;
  im->data = cairo_image_surface_get_data(im->s);
  im->w = cairo_image_surface_get_width(im->s);
  im->h = cairo_image_surface_get_height(im->s);
  im->stride = cairo_image_surface_get_stride(im->s);
  return 1;
}

static void image_free(struct image *im) { cairo_surface_destroy(im->s); }

/* 8-bit RGB of pixel (x, y) (opaque pictures: no premultiplication). */
static void pixel(const struct image *im, double x, double y, int rgb[3]) {
  int xi = (int)floor(x), yi = (int)floor(y);
  uint32_t p = 0;
  if (xi >= 0 && yi >= 0 && xi < im->w && yi < im->h)
    memcpy(&p, im->data + (size_t)yi * (size_t)im->stride + 4 * (size_t)xi, 4);
  rgb[0] = (int)((p >> 16) & 0xff);
  rgb[1] = (int)((p >> 8) & 0xff);
  rgb[2] = (int)(p & 0xff);
}

/* Largest channel difference between a pixel and a colour in [0, 1]. */
static int diff(const int rgb[3], const double c[3]) {
  int k, d = 0;
  for (k = 0; k < 3; ++k) {
    int e = abs(rgb[k] - (int)floor(c[k] * 255.0 + 0.5));
    if (e > d) d = e;
  }
  return d;
}

static void cmap(enum px_colormap m, double t, double rgb[3]) { px_colormap_eval(m, t, rgb); }

/* ---- colormaps ----------------------------------------------------------- */

static void check_rgb(enum px_colormap m, double t, double r, double g, double b, double tol) {
  double c[3];
  cmap(m, t, c);
  PX_CHECK_MSG(fabs(c[0] - r) <= tol && fabs(c[1] - g) <= tol && fabs(c[2] - b) <= tol,
               "%s(%g) = (%.6f, %.6f, %.6f), published (%.6f, %.6f, %.6f)", px_colormap_name(m), t,
               c[0], c[1], c[2], r, g, b);
}

static void test_colormaps_match_published_values(struct px_context *ctx) {
  double c[3];
  enum px_colormap m;
  /* endpoints: matplotlib _cm_listed.py entries 0 and 255 */
  check_rgb(PX_COLORMAP_VIRIDIS, 0.0, 0.267004, 0.004874, 0.329415, 1e-12);
  check_rgb(PX_COLORMAP_VIRIDIS, 1.0, 0.993248, 0.906157, 0.143936, 1e-12);
  check_rgb(PX_COLORMAP_INFERNO, 0.0, 0.001462, 0.000466, 0.013866, 1e-12);
  check_rgb(PX_COLORMAP_INFERNO, 1.0, 0.988362, 0.998364, 0.644924, 1e-12);
  /* Moreland 2009 CoolWarmFloat33: ends and the grey centre */
  check_rgb(PX_COLORMAP_COOLWARM, 0.0, 0.2298057, 0.298717966, 0.753683153, 1e-12);
  check_rgb(PX_COLORMAP_COOLWARM, 0.5, 0.865395197, 0.86541021, 0.865395561, 1e-12);
  check_rgb(PX_COLORMAP_COOLWARM, 1.0, 0.705673158, 0.01555616, 0.150232812, 1e-12);
  /* entries between our control points (interpolated) agree with the full
   * 256-entry tables to better than one 8-bit level (1/255 = 0.0039) */
  check_rgb(PX_COLORMAP_VIRIDIS, 2.0 / 255.0, 0.269944, 0.014625, 0.341379, 0.0025);
  check_rgb(PX_COLORMAP_VIRIDIS, 127.0 / 255.0, 0.128729, 0.563265, 0.551229, 0.0025);
  check_rgb(PX_COLORMAP_VIRIDIS, 193.0 / 255.0, 0.377779, 0.791781, 0.377939, 0.0025);
  check_rgb(PX_COLORMAP_VIRIDIS, 254.0 / 255.0, 0.983868, 0.904867, 0.136897, 0.0025);
  check_rgb(PX_COLORMAP_INFERNO, 2.0 / 255.0, 0.003299, 0.002249, 0.024239, 0.0025);
  check_rgb(PX_COLORMAP_INFERNO, 101.0 / 255.0, 0.572081, 0.145797, 0.406369, 0.0025);
  check_rgb(PX_COLORMAP_INFERNO, 246.0 / 255.0, 0.949545, 0.955063, 0.507860, 0.0025);
  check_rgb(PX_COLORMAP_INFERNO, 250.0 / 255.0, 0.961812, 0.975924, 0.571925, 0.0025);
  /* control points themselves are exact */
  check_rgb(PX_COLORMAP_VIRIDIS, 128.0 / 255.0, 0.127568, 0.566949, 0.550556, 1e-12);
  check_rgb(PX_COLORMAP_INFERNO, 100.0 / 255.0, 0.565854, 0.143567, 0.408258, 1e-12);
  check_rgb(PX_COLORMAP_COOLWARM, 0.75, 0.958003065, 0.602842431, 0.481775914, 1e-12);
  /* clamping and NaN */
  check_rgb(PX_COLORMAP_VIRIDIS, -3.0, 0.267004, 0.004874, 0.329415, 1e-12);
  check_rgb(PX_COLORMAP_INFERNO, 7.0, 0.988362, 0.998364, 0.644924, 1e-12);
  cmap(PX_COLORMAP_VIRIDIS, NAN, c);
  PX_CHECK(c[0] == 0.5 && c[1] == 0.5 && c[2] == 0.5);
  PX_CHECK(px_colormap_is_diverging(PX_COLORMAP_COOLWARM));
  PX_CHECK(!px_colormap_is_diverging(PX_COLORMAP_VIRIDIS));
  PX_CHECK_OK(ctx, px_colormap_parse(ctx, "inferno", &m));
  PX_CHECK(m == PX_COLORMAP_INFERNO);
  PX_CHECK_STATUS(ctx, px_colormap_parse(ctx, "jet", &m), PX_STATUS_INVALID);
  PX_CHECK(strstr(px_context_message(ctx), "viridis, inferno or coolwarm") != NULL);
}

/* ---- snapshots ----------------------------------------------------------- */

static void test_snapshot_pixels(struct px_context *ctx) {
  struct px_figure *fig = NULL;
  struct image im;
  double x[3] = {2.0, 5.0, 8.0}, y[3] = {6.0, 6.0, 6.0}, v[3] = {1.0, 0.0, NAN};
  double px[2] = {3.0, 6.0}, py[2] = {1.5, 1.5}, pv = 1.0;
  double lx[3] = {1.0, 4.0, 7.0}, ly[3] = {3.5, 3.5, 3.5}, lv[2] = {0.0, 1.0};
  double sx[4] = {8.0, 9.5, 9.5, 8.0}, sy[4] = {1.0, 1.0, 2.5, 2.5};
  double bg[3] = {0.9, 0.95, 1.0}, solid[3] = {0.8, 0.1, 0.1}, fill[3] = {0.6, 0.6, 0.6};
  double top[3], bottom[3], nan_grey[3], c[3], frame[4], cbar[4], X, Y, tprev = -1.0;
  int rgb[3], row, monotonic = 1, close = 1;
  cmap(PX_COLORMAP_VIRIDIS, 1.0, top);
  cmap(PX_COLORMAP_VIRIDIS, 0.0, bottom);
  px_colormap_nan(nan_grey);

  PX_CHECK_OK(ctx, px_figure_create(ctx, 640, 480, &fig));
  px_figure_set_view(fig, 0.0, 10.0, 0.0, 10.0);
  px_figure_set_range(fig, 0.0, 1.0);
  px_figure_set_field(fig, "phi", "J");
  px_figure_set_title(fig, "pixel test");
  px_figure_set_time(fig, 1.234, "s");
  px_figure_set_background(fig, bg[0], bg[1], bg[2]);
  PX_CHECK_OK(ctx, px_figure_add_discs(fig, PX_DTYPE_F64, 3, x, y, NULL, 0.7, v));
  px_figure_set_color(fig, solid[0], solid[1], solid[2]);
  PX_CHECK_OK(ctx, px_figure_add_points(fig, PX_DTYPE_F64, 1, px, py, NULL, 12.0));
  PX_CHECK_OK(ctx, px_figure_add_points(fig, PX_DTYPE_F64, 1, px + 1, py + 1, &pv, 12.0));
  px_figure_set_line_width(fig, 8.0);
  PX_CHECK_OK(ctx, px_figure_add_polyline_values(fig, PX_DTYPE_F64, 3, lx, ly, 0, lv));
  px_figure_set_fill(fig, fill[0], fill[1], fill[2]);
  px_figure_set_line_width(fig, 1.0);
  PX_CHECK_OK(ctx, px_figure_add_polyline(fig, PX_DTYPE_F64, 4, sx, sy, PX_FIGURE_LINE_FILLED));
  PX_CHECK_OK(ctx, px_figure_write_png(fig, "pixels.png"));
  PX_CHECK(image_load(&im, "pixels.png"));
  PX_CHECK(im.w == 640 && im.h == 480);

  /* a particle with value = vmax has the colormap's top colour, vmin its
   * bottom colour, NaN grey */
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 2.0, 6.0, &X, &Y));
  pixel(&im, X, Y, rgb);
  PX_CHECK_MSG(diff(rgb, top) <= 1, "vmax particle (%d, %d, %d)", rgb[0], rgb[1], rgb[2]);
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 5.0 + 0.5, 6.0, &X, &Y)); /* inside r = 0.7 */
  pixel(&im, X, Y, rgb);
  PX_CHECK_MSG(diff(rgb, bottom) <= 1, "vmin particle (%d, %d, %d)", rgb[0], rgb[1], rgb[2]);
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 8.0, 6.0 - 0.5, &X, &Y));
  pixel(&im, X, Y, rgb);
  PX_CHECK(diff(rgb, nan_grey) <= 1);
  /* just outside a disc and in empty space: the background */
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 2.0 + 0.9, 6.0, &X, &Y));
  pixel(&im, X, Y, rgb);
  PX_CHECK_MSG(diff(rgb, bg) <= 1, "background (%d, %d, %d)", rgb[0], rgb[1], rgb[2]);
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 5.0, 8.5, &X, &Y));
  pixel(&im, X, Y, rgb);
  PX_CHECK(diff(rgb, bg) <= 1);
  /* a solid point (no values) has the line colour; a valued one the map's */
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 3.0, 1.5, &X, &Y));
  pixel(&im, X, Y, rgb);
  PX_CHECK(diff(rgb, solid) <= 1);
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 6.0, 1.5, &X, &Y));
  pixel(&im, X, Y, rgb);
  PX_CHECK(diff(rgb, top) <= 1);
  /* segments coloured by their own values */
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 2.5, 3.5, &X, &Y));
  pixel(&im, X, Y, rgb);
  PX_CHECK_MSG(diff(rgb, bottom) <= 1, "segment 0 (%d, %d, %d)", rgb[0], rgb[1], rgb[2]);
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 5.5, 3.5, &X, &Y));
  pixel(&im, X, Y, rgb);
  PX_CHECK_MSG(diff(rgb, top) <= 1, "segment 1 (%d, %d, %d)", rgb[0], rgb[1], rgb[2]);
  /* 8 px wide: 6 px off the line is background again */
  pixel(&im, X, Y + 6.0, rgb);
  PX_CHECK(diff(rgb, bg) <= 1);
  /* a filled body: fill colour inside */
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 8.75, 1.75, &X, &Y));
  pixel(&im, X, Y, rgb);
  PX_CHECK(diff(rgb, fill) <= 1);

  /* colour bar: from bottom to top the colours follow the map, t increasing */
  PX_CHECK_OK(ctx, px_figure_layout_rects(fig, frame, cbar));
  PX_CHECK(cbar[0] > frame[2] && cbar[2] < 640 && cbar[3] - cbar[1] > 100);
  for (row = (int)cbar[3] - 2; row > (int)cbar[1] + 1; --row) {
    double best = 1e9, tbest = 0.0;
    int k;
    pixel(&im, 0.5 * (cbar[0] + cbar[2]), row + 0.5, rgb);
    for (k = 0; k <= 1000; ++k) {
      double t = k / 1000.0, d;
      cmap(PX_COLORMAP_VIRIDIS, t, c);
      d = fabs(rgb[0] - 255.0 * c[0]) + fabs(rgb[1] - 255.0 * c[1]) + fabs(rgb[2] - 255.0 * c[2]);
      if (d < best) best = d, tbest = t;
    }
    if (best > 3.0) close = 0;
    if (tbest < tprev - 0.004) monotonic = 0;
    if (row == (int)cbar[3] - 2) PX_CHECK_MSG(tbest < 0.02, "colour bar bottom t = %g", tbest);
    tprev = tbest;
  }
  PX_CHECK_MSG(tprev > 0.98, "colour bar top t = %g", tprev);
  PX_CHECK(monotonic);
  PX_CHECK(close);
  image_free(&im);
  px_figure_free(fig);
}

/* Annotations: a marker's ring and an arrow's head in the line colour at
 * the world points given, above the particles; the view does not grow to
 * include them. */
static void test_markers_and_arrows(struct px_context *ctx) {
  struct px_figure *fig = NULL;
  struct image im;
  double x[1] = {5.0}, y[1] = {5.0}, v[1] = {0.5}, red[3] = {0.9, 0.0, 0.0};
  double X, Y, X2, Y2, fs, frame[4], cbar[4];
  int rgb[3], k, ring = 0, head = 0, body = 0;
  PX_CHECK_OK(ctx, px_figure_create(ctx, 640, 480, &fig));
  PX_CHECK_OK(ctx, px_figure_add_discs(fig, PX_DTYPE_F64, 1, x, y, NULL, 2.0, v));
  px_figure_set_color(fig, red[0], red[1], red[2]);
  px_figure_set_line_width(fig, 2.0);
  PX_CHECK_OK(ctx, px_figure_add_marker(fig, 5.0, 5.0, "max 2.59e+08 Pa"));
  PX_CHECK_OK(ctx, px_figure_add_arrow(fig, 3.5, 3.5, 4.5, 3.5, "s"));
  PX_CHECK(px_figure_add_marker(fig, NAN, 0.0, NULL) == PX_STATUS_INVALID);
  PX_CHECK_OK(ctx, px_figure_write_png(fig, "annotations.png"));
  PX_CHECK(image_load(&im, "annotations.png"));
  PX_CHECK_OK(ctx, px_figure_layout_rects(fig, frame, cbar));
  fs = (im.w < im.h ? im.w : im.h) / 40.0;
  /* the view is the disc's (radius 2 around (5, 5), 5% margin), not widened
     by the annotations */
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 5.0, 5.0, &X, &Y));
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 7.0, 5.0, &X2, &Y2));
  PX_CHECK_MSG(X2 - X > 0.3 * (frame[2] - frame[0]), "disc radius %g px in a %g px frame", X2 - X,
               frame[2] - frame[0]);
  /* the ring of radius 0.6 fs around the marker is red somewhere */
  for (k = 0; k < 64; ++k) {
    double a = 6.283185307179586 * k / 64.0;
    pixel(&im, X + 0.6 * fs * cos(a), Y + 0.6 * fs * sin(a), rgb);
    if (diff(rgb, red) <= 40) ++ring;
  }
  PX_CHECK_MSG(ring > 16, "%d of 64 ring samples red", ring);
  /* the centre (inside the ring, off the cross) keeps the particle's colour */
  pixel(&im, X + 0.25 * fs, Y + 0.25 * fs, rgb);
  PX_CHECK(diff(rgb, red) > 100);
  /* the arrow: red along its body and just behind its head */
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 4.0, 3.5, &X, &Y));
  pixel(&im, X, Y, rgb);
  if (diff(rgb, red) <= 40) body = 1;
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 4.5, 3.5, &X, &Y));
  pixel(&im, X - 0.3 * fs, Y, rgb);
  if (diff(rgb, red) <= 40) head = 1;
  PX_CHECK(body && head);
  image_free(&im);
  px_figure_free(fig);
}

static void test_raster_cells_and_ranges(struct px_context *ctx) {
  struct px_figure *fig = NULL;
  struct image im;
  float v[4] = {0.0f, 1.0f, NAN, 0.5f}; /* cells (0,0) (1,0) (0,1) (1,1) */
  double c[3], X, Y, vmin, vmax, neg[2] = {-2.0, 0.5}, xy[2] = {0.0, 1.0};
  int rgb[3];
  PX_CHECK_OK(ctx, px_figure_create(ctx, 500, 400, &fig));
  px_figure_set_colormap(fig, PX_COLORMAP_INFERNO);
  PX_CHECK_OK(ctx, px_figure_add_raster(fig, PX_DTYPE_F32, 2, 2, v, 0.0, 4.0, 0.0, 4.0));
  PX_CHECK_OK(ctx, px_figure_layout_range(fig, &vmin, &vmax));
  PX_CHECK(vmin == 0.0 && vmax == 1.0); /* automatic: data min..max, NaN ignored */
  PX_CHECK_OK(ctx, px_figure_write_png(fig, "raster.png"));
  PX_CHECK(image_load(&im, "raster.png"));
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 1.0, 1.0, &X, &Y));
  pixel(&im, X, Y, rgb);
  cmap(PX_COLORMAP_INFERNO, 0.0, c);
  PX_CHECK(diff(rgb, c) <= 1);
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 3.0, 1.0, &X, &Y));
  pixel(&im, X, Y, rgb);
  cmap(PX_COLORMAP_INFERNO, 1.0, c);
  PX_CHECK(diff(rgb, c) <= 1);
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 1.0, 3.0, &X, &Y)); /* row 1 is above row 0 */
  pixel(&im, X, Y, rgb);
  px_colormap_nan(c);
  PX_CHECK(diff(rgb, c) <= 1);
  PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 3.0, 3.0, &X, &Y));
  pixel(&im, X, Y, rgb);
  cmap(PX_COLORMAP_INFERNO, 0.5, c);
  PX_CHECK(diff(rgb, c) <= 1);
  image_free(&im);

  /* equal aspect: one world unit is as many pixels along x as along y */
  {
    double x0, y0, x1, y1;
    PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 0.0, 0.0, &x0, &y0));
    PX_CHECK_OK(ctx, px_figure_world_to_pixel(fig, 4.0, 4.0, &x1, &y1));
    PX_CHECK_NEAR(x1 - x0, y0 - y1, 1e-9);
  }
  /* a diverging map's automatic range is symmetric around 0 */
  px_figure_reset(fig);
  px_figure_set_colormap(fig, PX_COLORMAP_COOLWARM);
  PX_CHECK_OK(ctx, px_figure_add_points(fig, PX_DTYPE_F64, 2, xy, xy, neg, 3.0));
  PX_CHECK_OK(ctx, px_figure_layout_range(fig, &vmin, &vmax));
  PX_CHECK(vmin == -2.0 && vmax == 2.0);
  px_figure_set_range(fig, -0.5, 3.0); /* given ranges are kept */
  PX_CHECK_OK(ctx, px_figure_layout_range(fig, &vmin, &vmax));
  PX_CHECK(vmin == -0.5 && vmax == 3.0);
  px_figure_free(fig);
}

static void test_figure_errors(struct px_context *ctx) {
  struct px_figure *fig = NULL;
  int xi[2] = {0, 1};
  double x[2] = {0.0, 1.0};
  PX_CHECK_STATUS(ctx, px_figure_create(ctx, 8, 400, &fig), PX_STATUS_INVALID);
  PX_CHECK(fig == NULL);
  PX_CHECK_OK(ctx, px_figure_create(ctx, 300, 200, &fig));
  PX_CHECK_STATUS(ctx, px_figure_add_points(fig, PX_DTYPE_I32, 2, xi, xi, NULL, 2.0),
                  PX_STATUS_INVALID);
  PX_CHECK(strstr(px_context_message(ctx), "f32 or f64") != NULL);
  PX_CHECK_STATUS(ctx, px_figure_add_discs(fig, PX_DTYPE_F64, 2, x, x, NULL, -1.0, NULL),
                  PX_STATUS_INVALID);
  px_figure_set_view(fig, 1.0, 1.0, 0.0, 1.0);
  PX_CHECK_STATUS(ctx, px_figure_write_png(fig, "never.png"), PX_STATUS_INVALID);
  PX_CHECK(strstr(px_context_message(ctx), "never.png") != NULL);
  px_figure_fit_view(fig, 0.05);
  PX_CHECK_STATUS(ctx, px_figure_write_png(fig, "no/such/dir/x.png"), PX_STATUS_IO);
  PX_CHECK(strstr(px_context_message(ctx), "no/such/dir/x.png") != NULL);
  px_figure_free(fig);
}

/* ---- line plots ---------------------------------------------------------- */

/* 1 if a pixel within `r` of (X, Y) is within `tol` of colour c. */
static int near_colour(const struct image *im, double X, double Y, int r, const double c[3],
                       int tol) {
  int dx, dy, rgb[3];
  for (dy = -r; dy <= r; ++dy)
    for (dx = -r; dx <= r; ++dx) {
      pixel(im, X + dx, Y + dy, rgb);
      if (diff(rgb, c) <= tol) return 1;
    }
  return 0;
}

/* The legend goes where it hides the least of the lines, not only of their
 * points: a diagonal of two points passes under the upper-right corner,
 * which holds none of its points; the legend must leave it visible. */
static void test_plot_legend_avoids_lines(struct px_context *ctx) {
  struct px_plot *p = NULL;
  struct image im;
  double x[2] = {0.0, 1.0}, y[2] = {0.0, 1.0}, c0[3], X, Y;
  px_plot_series_color(0, c0);
  PX_CHECK_OK(ctx, px_plot_create(ctx, 800, 500, &p));
  px_plot_set_labels(p, "x [m]", "y [m]");
  px_plot_set_xrange(p, 0.0, 1.0);
  px_plot_set_yrange(p, 0.0, 1.0);
  PX_CHECK_OK(ctx, px_plot_add_series(p, "a long legend entry for a diagonal", 2, x, y));
  PX_CHECK_OK(ctx, px_plot_write_png(p, "plot_legend.png"));
  PX_CHECK(image_load(&im, "plot_legend.png"));
  PX_CHECK_OK(ctx, px_plot_data_to_pixel(p, 0.93, 0.93, &X, &Y));
  PX_CHECK_MSG(near_colour(&im, X, Y, 1, c0, 12),
               "the line under the upper-right corner is hidden");
  PX_CHECK_OK(ctx, px_plot_data_to_pixel(p, 0.07, 0.07, &X, &Y));
  PX_CHECK(near_colour(&im, X, Y, 1, c0, 12));
  image_free(&im);
  px_plot_free(p);
}

static void test_plot_series_pass_through_their_pixels(struct px_context *ctx) {
  struct px_plot *p = NULL;
  struct image im;
  double x[101], y[101], flat[101], c0[3], c1[3], X, Y, frame[4];
  int i, on = 0, off = 0;
  for (i = 0; i <= 100; ++i) x[i] = 0.1 * i, y[i] = 2.0 * x[i] + 1.0, flat[i] = 0.5;
  px_plot_series_color(0, c0);
  px_plot_series_color(1, c1);
  PX_CHECK(diff((int[3]){0, 114, 178}, c0) == 0); /* Okabe-Ito blue first */
  PX_CHECK_OK(ctx, px_plot_create(ctx, 800, 500, &p));
  px_plot_set_title(p, "test");
  px_plot_set_labels(p, "x [m]", "y [m]");
  PX_CHECK_OK(ctx, px_plot_add_series(p, "2x+1", 101, x, y));
  PX_CHECK_OK(ctx, px_plot_add_series(p, "0.5", 101, x, flat));
  PX_CHECK_OK(ctx, px_plot_write_png(p, "plot.png"));
  PX_CHECK(image_load(&im, "plot.png"));
  for (i = 1; i <= 9; ++i) {
    PX_CHECK_OK(ctx, px_plot_data_to_pixel(p, (double)i, 2.0 * i + 1.0, &X, &Y));
    on += near_colour(&im, X, Y, 1, c0, 12);
    /* well below the line (and off the flat series): not the series colour */
    PX_CHECK_OK(ctx, px_plot_data_to_pixel(p, (double)i, 2.0 * i - 1.5, &X, &Y));
    off += near_colour(&im, X, Y, 1, c0, 60);
  }
  PX_CHECK_MSG(on == 9, "series 0 found at %d of 9 points", on);
  PX_CHECK_MSG(off == 0, "series colour off the line at %d points", off);
  PX_CHECK_OK(ctx, px_plot_data_to_pixel(p, 5.0, 0.5, &X, &Y));
  PX_CHECK(near_colour(&im, X, Y, 1, c1, 12));
  /* automatic ranges: x exactly the data, y padded by 5 % */
  PX_CHECK_OK(ctx, px_plot_layout_frame(p, frame));
  PX_CHECK_OK(ctx, px_plot_data_to_pixel(p, 0.0, 0.5 - 0.05 * 20.5, &X, &Y));
  PX_CHECK_NEAR(X, frame[0], 1e-9);
  PX_CHECK_NEAR(Y, frame[3], 1e-9);
  PX_CHECK_OK(ctx, px_plot_data_to_pixel(p, 10.0, 21.0 + 0.05 * 20.5, &X, &Y));
  PX_CHECK_NEAR(X, frame[2], 1e-9);
  PX_CHECK_NEAR(Y, frame[1], 1e-9);
  image_free(&im);
  px_plot_free(p);

  /* log y: y = 10^x is a straight line in pixels */
  PX_CHECK_OK(ctx, px_plot_create(ctx, 600, 400, &p));
  px_plot_set_log_y(p, 1);
  for (i = 0; i <= 100; ++i) y[i] = pow(10.0, 0.04 * i), x[i] = 0.04 * i;
  PX_CHECK_OK(ctx, px_plot_add_series(p, NULL, 101, x, y));
  PX_CHECK_OK(ctx, px_plot_write_png(p, "plot_log.png"));
  PX_CHECK(image_load(&im, "plot_log.png"));
  {
    double xa, ya, xb, yb, xm, ym;
    PX_CHECK_OK(ctx, px_plot_data_to_pixel(p, 0.0, 1.0, &xa, &ya));
    PX_CHECK_OK(ctx, px_plot_data_to_pixel(p, 4.0, 1e4, &xb, &yb));
    PX_CHECK_OK(ctx, px_plot_data_to_pixel(p, 2.0, 100.0, &xm, &ym));
    PX_CHECK_NEAR(xm, 0.5 * (xa + xb), 1e-9);
    PX_CHECK_NEAR(ym, 0.5 * (ya + yb), 1e-9);
    PX_CHECK(near_colour(&im, xm, ym, 1, c0, 12));
  }
  image_free(&im);
  px_plot_free(p);
}

/* Markers: a disc at each data point, wider than the line; none between
 * points and none without px_plot_set_markers. */
static void test_plot_markers_show_the_points(struct px_context *ctx) {
  const double x[3] = {0.0, 1.0, 2.0}, y[3] = {1.0, 1.0, 1.0};
  double c0[3], X, Y, X1, Y1;
  int on;
  px_plot_series_color(0, c0);
  for (on = 0; on <= 1; ++on) {
    struct px_plot *p = NULL;
    struct image im = {0};
    int i, hits = 0;
    PX_CHECK_OK(ctx, px_plot_create(ctx, 800, 500, &p));
    px_plot_set_labels(p, "x [m]", "y [m]");
    px_plot_set_yrange(p, 0.0, 2.0);
    px_plot_set_markers(p, on);
    PX_CHECK_OK(ctx, px_plot_add_series(p, "three points", 3, x, y));
    PX_CHECK_OK(ctx, px_plot_write_png(p, "plot_markers.png"));
    PX_CHECK(image_load(&im, "plot_markers.png"));
    for (i = 0; i < 3; ++i) {
      /* 3 pixels above the point: beyond the line's half width (1 px at
         this size), inside the marker (radius >= 4 px) */
      PX_CHECK_OK(ctx, px_plot_data_to_pixel(p, x[i], y[i], &X, &Y));
      hits += near_colour(&im, X, Y - 3.0, 0, c0, 40);
    }
    PX_CHECK_MSG(hits == (on ? 3 : 0), "markers %s: series colour beside %d of 3 points",
                 on ? "on" : "off", hits);
    /* halfway between two points: the line only */
    PX_CHECK_OK(ctx, px_plot_data_to_pixel(p, 0.5, 1.0, &X1, &Y1));
    PX_CHECK(near_colour(&im, X1, Y1, 0, c0, 12));
    PX_CHECK(!near_colour(&im, X1, Y1 - 3.0, 0, c0, 40));
    image_free(&im);
    px_plot_free(p);
  }
}

int main(void) {
  struct px_context *ctx = NULL;
  px_context_create(&ctx);
  test_colormaps_match_published_values(ctx);
  test_snapshot_pixels(ctx);
  test_markers_and_arrows(ctx);
  test_plot_legend_avoids_lines(ctx);
  test_raster_cells_and_ranges(ctx);
  test_figure_errors(ctx);
  test_plot_series_pass_through_their_pixels(ctx);
  test_plot_markers_show_the_points(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  px_test_release_fonts();
  return px_test_report("test_io_png");
}
