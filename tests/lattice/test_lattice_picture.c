/* The von Mises picture is honest about its hot spot: on a 12 x 4 x 3 body
 * whose largest stress (5e8 Pa) sits in an element inside it (not drawn: the
 * picture shows surface elements) and whose surface peaks at 2e8 Pa, in the
 * top and iso views,
 *  - the colour scale runs from 0 to the body's largest von Mises stress,
 *    5e8 Pa (not to a percentile of the drawn values, which would saturate
 *    the peak and hide it);
 *  - a marker (red ring and cross, the picture's only red) is drawn where
 *    that element is: red pixels within 3 font sizes right of and above
 *    its projected centre, none on the far side of the body.
 * The picture hook runs on a solver state filled by hand (fields cached at
 * the output step), read back with cairo. */
#include <cairo.h>
#include <stdlib.h>
#include <sys/stat.h>

#include "io/figure_impl.h"
#include "io/px_test_fonts.h"
#include "lt_util.h"
#include "solvers/lattice/lattice.h"

/* 1 if a red pixel (the marker's colour 0.85, 0.1, 0.1) lies on the
 * segment from (x0, y0) to (x1, y1) of the picture. */
static int red_between(cairo_surface_t *s, double x0, double y0, double x1, double y1) {
  unsigned char *data = cairo_image_surface_get_data(s);
  int w = cairo_image_surface_get_width(s), h = cairo_image_surface_get_height(s);
  int stride = cairo_image_surface_get_stride(s), k;
  for (k = 0; k <= 200; ++k) {
    int x = (int)floor(x0 + (x1 - x0) * k / 200.0), y = (int)floor(y0 + (y1 - y0) * k / 200.0);
    uint32_t p;
    int r, g, b;
    if (x < 0 || y < 0 || x >= w || y >= h) continue;
    memcpy(&p, data + (size_t)y * (size_t)stride + 4 * (size_t)x, 4);
    r = (int)((p >> 16) & 0xff);
    g = (int)((p >> 8) & 0xff);
    b = (int)(p & 0xff);
    if (r > 150 && g < 90 && b < 90) return 1;
  }
  return 0;
}

static void check_view(struct px_context *ctx, enum px_lattice_view view, const char *name) {
  struct px_lattice *L = (struct px_lattice *)px_mem_calloc(ctx, "test", 1, sizeof *L);
  struct px_lattice_grid g;
  struct px_lattice_params par = lt_steel();
  struct px_sim_output o;
  const int n0 = 12, n1 = 4, n2 = 3;
  const double h = 1e-3;
  size_t c, n, hot_cell = 0, far_cell = 0;
  double vmin = -1, vmax = -1, hx, hy, fx, fy, centre[3];
  char path[256];
  cairo_surface_t *s;
  if (!L) return;
  L->ctx = ctx;
  L->view = view;
  L->picture_scale = 1.0;
  L->drawn_scale = NAN;
  snprintf(L->title, sizeof L->title, "picture test");
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, n0, n1, n2, &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &L->m, &g, &par, NULL, 0));
  n = L->m.nalloc;
  L->fu = (double *)px_mem_calloc(ctx, "test", 3 * n, sizeof(double));
  L->fv = (double *)px_mem_calloc(ctx, "test", 3 * n, sizeof(double));
  L->fs = (double *)px_mem_calloc(ctx, "test", 6 * n, sizeof(double));
  L->fvm = (double *)px_mem_calloc(ctx, "test", n, sizeof(double));
  L->flinks = (uint8_t *)px_mem_calloc(ctx, "test", n, 1);
  PX_CHECK(L->fu && L->fv && L->fs && L->fvm && L->flinks);
  if (!L->fvm) return;
  /* 1 MPa plus a gradient along x; 2e8 Pa on the surface at (1, 0, 2);
   * 5e8 Pa inside at (9, 2, 1) */
  for (c = 0; c < L->m.grid.ncell; ++c) {
    size_t i = c % (size_t)n0, j = c / (size_t)n0 % (size_t)n1, k = c / (size_t)(n0 * n1);
    double v = 1e6 * (1.0 + (double)i);
    if (i == 1 && j == 0 && k == 2) v = 2e8;
    if (i == 9 && j == 2 && k == 1) {
      v = 5e8;
      hot_cell = c;
    }
    if (i == 1 && j == 1 && k == 2) far_cell = c;
    L->fvm[px_lattice_index(&L->m, c)] = v;
  }
  L->fields_step = 5;
  memset(&o, 0, sizeof o);
  o.step = 5;
  o.time = 1e-6;
  o.dir = "lt_picture";
  o.drop_picture = -1;
  mkdir("lt_picture", 0755);
  PX_CHECK_OK(ctx, px_lattice_picture(L, &o));
  PX_CHECK_OK(ctx, px_figure_layout_range(L->fig, &vmin, &vmax));
  printf("%s view: colour scale %g .. %g Pa (largest von Mises 5e8 Pa, inside the body)\n", name,
         vmin, vmax);
  PX_CHECK(vmin == 0.0);
  PX_CHECK(vmax == 5e8);
  /* where the marker must be: the projected centre of the hot element */
  {
    double r[3], up[3], d[3], p[3], q[3];
    if (view == PX_LATTICE_VIEW_TOP) {
      r[0] = 1, r[1] = 0, r[2] = 0, up[0] = 0, up[1] = 1, up[2] = 0;
    } else { /* iso: as lattice_output.c's view axes */
      double v[3] = {0.35, -0.8, 0.5}, nn = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), rn;
      int a;
      for (a = 0; a < 3; ++a) d[a] = v[a] / nn;
      r[0] = -d[1], r[1] = d[0], r[2] = 0;
      rn = sqrt(r[0] * r[0] + r[1] * r[1]);
      r[0] /= rn, r[1] /= rn;
      up[0] = d[1] * r[2] - d[2] * r[1];
      up[1] = d[2] * r[0] - d[0] * r[2];
      up[2] = d[0] * r[1] - d[1] * r[0];
    }
    px_lattice_grid_centre(&L->m.grid, hot_cell, p);
    px_lattice_grid_centre(&L->m.grid, far_cell, q);
    centre[0] = p[0] * r[0] + p[1] * r[1] + p[2] * r[2];
    centre[1] = p[0] * up[0] + p[1] * up[1] + p[2] * up[2];
    PX_CHECK_OK(ctx, px_figure_world_to_pixel(L->fig, centre[0], centre[1], &hx, &hy));
    PX_CHECK_OK(ctx,
                px_figure_world_to_pixel(L->fig, q[0] * r[0] + q[1] * r[1] + q[2] * r[2],
                                         q[0] * up[0] + q[1] * up[1] + q[2] * up[2], &fx, &fy));
  }
  snprintf(path, sizeof path, "lt_picture/von_mises_000005.png");
  s = cairo_image_surface_create_from_png(path);
  PX_CHECK(cairo_surface_status(s) == CAIRO_STATUS_SUCCESS);
  if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS) {
    /* the cross's arms: right of and above the centre (font size ~ 16 px) */
    PX_CHECK_MSG(red_between(s, hx + 2, hy, hx + 50, hy), "no marker right of (%.0f, %.0f)", hx,
                 hy);
    PX_CHECK_MSG(red_between(s, hx, hy - 2, hx, hy - 50), "no marker above (%.0f, %.0f)", hx, hy);
    /* the 2e8 Pa surface element is not marked */
    PX_CHECK_MSG(!red_between(s, fx - 6, fy, fx + 6, fy), "red at the surface peak (%.0f, %.0f)",
                 fx, fy);
    snprintf(path, sizeof path, "lt_picture/%s.png", name);
    cairo_surface_write_to_png(s, path);
  }
  cairo_surface_destroy(s);
  px_lattice_output_free(L);
  px_lattice_model_free(ctx, &L->m);
  px_mem_free(ctx, L);
}

int main(void) {
  struct px_context *ctx;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  check_view(ctx, PX_LATTICE_VIEW_TOP, "top");
  check_view(ctx, PX_LATTICE_VIEW_ISO, "iso");
  px_context_free(ctx);
  px_test_release_fonts();
  return px_test_report("test_lattice_picture");
}
