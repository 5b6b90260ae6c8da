/* Pictures of a part with its sections (io/mesh_view.h), for people to look
 * at: build/tests/io/examples/mesh_torus_sections.png (a torus, grey, with
 * 5 sections across its axis drawn over it) and mesh_prism_height.png (a
 * 32-sided prism coloured by height, with its colour bar). Checks that each
 * decodes to 1800 x 640 pixels, that the torus's hole shows the background
 * in the view along its axis while its ring is shaded grey, and that the
 * sections are drawn in red. */
#include <cairo.h>
#include <string.h>
#include <sys/stat.h>

#include "io/mesh_view.h"
#include "px_test.h"
#include "px_test_fonts.h"
#include "px_test_mesh.h"

static void load(struct px_context *ctx, const struct tm_soup *s, struct px_geo_mesh *m) {
  size_t len;
  char *t = tm_stl_ascii(s, &len);
  PX_CHECK_OK(ctx, px_geo_mesh_parse(ctx, "part.stl", t, len, 0, 0, m));
  PX_CHECK_OK(ctx, px_geo_mesh_check(ctx, m));
  free(t);
}

/* The pixel (x, y) of a decoded PNG as 0xRRGGBB. */
static unsigned pixel(cairo_surface_t *s, int x, int y) {
  const unsigned char *d = cairo_image_surface_get_data(s);
  const int stride = cairo_image_surface_get_stride(s);
  unsigned v;
  memcpy(&v, d + (size_t)y * (size_t)stride + 4 * (size_t)x, 4);
  return v & 0xffffffu;
}

static int count_red(cairo_surface_t *s) {
  int n = 0;
  for (int y = 0; y < cairo_image_surface_get_height(s); ++y)
    for (int x = 0; x < 1600; ++x) {
      const unsigned p = pixel(s, x, y);
      if ((p >> 16) > 150 && ((p >> 8) & 255) < 60 && (p & 255) < 60) ++n;
    }
  return n;
}

static void view_setup(struct px_mesh_view *v) {
  static const double dir[3][3] = {{0, 0, -1}, {0, 1, 0}, {-1, -1.5, -1}};
  static const double up[3][3] = {{0, 1, 0}, {0, 0, 1}, {0, 0, 1}};
  memcpy(v->dir, dir, sizeof dir);
  memcpy(v->up, up, sizeof up);
  v->view_name[0] = "along -z";
  v->view_name[1] = "along +y";
  v->view_name[2] = "oblique";
}

static void test_torus_with_sections(struct px_context *ctx) {
  struct tm_soup s = {0};
  struct px_geo_mesh m;
  struct px_mesh_view v;
  tm_torus(&s, 2, 0.6, 64, 24);
  load(ctx, &s, &m);
  memset(&v, 0, sizeof v);
  view_setup(&v);
  v.mesh = &m;
  v.title = "torus R = 2, r = 0.6: 5 sections normal to x";
  /* sections x = -2.4 ... 2.4: their contours lifted back to 3D */
  const double nrm[3] = {1, 0, 0}, hint[3] = {0, 1, 0};
  double u[3], w[3], n[3];
  PX_CHECK_OK(ctx, px_geo_mesh_frame(ctx, nrm, hint, u, w, n));
  size_t counts[16], np = 0;
  double *xyz[16];
  for (int k = 0; k < 5; ++k) {
    const double off = -2.4 + 1.2 * k;
    struct px_geo_polyline *c = NULL;
    size_t nc = 0;
    PX_CHECK_OK(ctx, px_geo_mesh_slice(ctx, &m, u, w, n, off, &c, &nc));
    for (size_t i = 0; i < nc; ++i) {
      if (np < 16) {
        xyz[np] = malloc(3 * c[i].n * sizeof(double));
        counts[np] = c[i].n;
        for (size_t j = 0; j < c[i].n; ++j)
          for (int q = 0; q < 3; ++q)
            xyz[np][3 * j + (size_t)q] = c[i].x[j] * u[q] + c[i].y[j] * w[q] + off * n[q];
        ++np;
      }
      px_geo_polyline_free(ctx, &c[i]);
    }
    px_mem_free(ctx, c);
  }
  PX_CHECK(np == 8); /* 1, 2, 2, 2, 1: the middle three through the hole */
  v.npoly = np;
  v.poly_n = counts;
  v.poly_xyz = (const double *const *)xyz;
  mkdir("examples", 0755);
  PX_CHECK_OK(ctx, px_mesh_view_png(ctx, &v, "examples/mesh_torus_sections.png"));
  cairo_surface_t *png = cairo_image_surface_create_from_png("examples/mesh_torus_sections.png");
  PX_CHECK(cairo_surface_status(png) == CAIRO_STATUS_SUCCESS);
  PX_CHECK(cairo_image_surface_get_width(png) == 1800 &&
           cairo_image_surface_get_height(png) == 640);
  /* the first view (along -z), centred at (300, 316): the hole is white,
   * the ring at 2 (of a 5.2 wide part in 447 px) shaded grey */
  PX_CHECK(pixel(png, 300, 316) == 0xffffffu);
  const unsigned ring = pixel(png, 300 + 172, 316);
  PX_CHECK_MSG(ring != 0xffffffu && (ring >> 16) == (ring & 255), "ring pixel %06x", ring);
  PX_CHECK(count_red(png) > 1000);
  cairo_surface_destroy(png);
  for (size_t i = 0; i < np; ++i) free(xyz[i]);
  px_geo_mesh_free(ctx, &m);
  tm_free(&s);
}

static void test_prism_coloured(struct px_context *ctx) {
  struct tm_soup s = {0};
  struct px_geo_mesh m;
  struct px_mesh_view v;
  tm_cylinder(&s, 1, 3, 32);
  load(ctx, &s, &m);
  double *z = malloc(m.nv * sizeof *z);
  for (size_t i = 0; i < m.nv; ++i) z[i] = m.xyz[3 * i + 2];
  memset(&v, 0, sizeof v);
  view_setup(&v);
  v.mesh = &m;
  v.value = z;
  v.label = "height [m]";
  v.map = PX_COLORMAP_VIRIDIS;
  v.title = "prism coloured by height";
  PX_CHECK_OK(ctx, px_mesh_view_png(ctx, &v, "examples/mesh_prism_height.png"));
  cairo_surface_t *png = cairo_image_surface_create_from_png("examples/mesh_prism_height.png");
  PX_CHECK(cairo_surface_status(png) == CAIRO_STATUS_SUCCESS);
  PX_CHECK(cairo_image_surface_get_width(png) == 1800);
  PX_CHECK(count_red(png) == 0); /* no sections */
  cairo_surface_destroy(png);
  free(z);
  px_geo_mesh_free(ctx, &m);
  tm_free(&s);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  const size_t held = px_mem_current(ctx, NULL);
  test_torus_with_sections(ctx);
  test_prism_coloured(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == held); /* nothing left allocated */
  px_context_free(ctx);
  px_test_release_fonts();
  return px_test_report("test_io_mesh_view");
}
