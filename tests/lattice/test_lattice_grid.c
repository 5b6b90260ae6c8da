/* Bodies on the grid: primitives and CSG counts, cropping and alignment,
 * selections (faces, boxes, nearest point, combinations), and the errors for
 * empty bodies, empty selections and disconnected bodies. */
#include <math.h>
#include <string.h>

#include "px_test.h"
#include "solvers/lattice/lattice_grid.h"

static struct px_lattice_prim prim_box(double x0, double y0, double z0, double x1, double y1,
                                       double z1, enum px_lattice_op op) {
  struct px_lattice_prim p;
  memset(&p, 0, sizeof p);
  p.shape = PX_LATTICE_SHAPE_BOX;
  p.op = op;
  p.p0[0] = x0;
  p.p0[1] = y0;
  p.p0[2] = z0;
  p.p1[0] = x1;
  p.p1[1] = y1;
  p.p1[2] = z1;
  return p;
}

static size_t count_sel(struct px_context *ctx, const struct px_lattice_grid *g,
                        const struct px_lattice_sel *s, size_t *first) {
  size_t *cells = NULL, n = 0;
  if (px_lattice_select(ctx, g, s, &cells, &n) != PX_STATUS_OK) return 0;
  if (first) *first = cells[0];
  px_mem_free(ctx, cells);
  return n;
}

static struct px_lattice_sel sel_none(void) {
  struct px_lattice_sel s;
  memset(&s, 0, sizeof s);
  s.face = PX_LATTICE_FACE_NONE;
  return s;
}

static void test_box_and_faces(struct px_context *ctx) {
  struct px_lattice_grid g;
  struct px_lattice_sel s = sel_none();
  size_t first = 0;
  double x[3];
  /* the original's plate, 100 x 50 x 5 mm with h = 1 mm */
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, 1e-3, 100, 50, 5, &g));
  PX_CHECK(g.count == 25000 && g.n[0] == 100 && g.n[1] == 50 && g.n[2] == 5);
  PX_CHECK_NEAR(g.origin[0], 0.0, 1e-15);
  PX_CHECK(count_sel(ctx, &g, &s, NULL) == 25000);
  s.face = PX_LATTICE_FACE_X_MAX;
  PX_CHECK(count_sel(ctx, &g, &s, &first) == 250);
  px_lattice_grid_centre(&g, first, x);
  PX_CHECK_NEAR(x[0], 0.0995, 1e-12);
  /* lower half of the right face: y <= 25 mm */
  s.has_box = 1;
  s.box_min[0] = s.box_min[1] = s.box_min[2] = -1.0;
  s.box_max[0] = s.box_max[2] = 1.0;
  s.box_max[1] = 0.025;
  PX_CHECK(count_sel(ctx, &g, &s, NULL) == 125);
  /* top corner: nearest element to (0, 50, 5) mm */
  s = sel_none();
  s.has_point = 1;
  s.point[0] = 0.0;
  s.point[1] = 0.05;
  s.point[2] = 0.005;
  PX_CHECK(count_sel(ctx, &g, &s, &first) == 1);
  px_lattice_grid_centre(&g, first, x);
  PX_CHECK_NEAR(x[0], 0.0005, 1e-12);
  PX_CHECK_NEAR(x[1], 0.0495, 1e-12);
  PX_CHECK_NEAR(x[2], 0.0045, 1e-12);
  /* nearest within a face */
  s.face = PX_LATTICE_FACE_Z_MIN;
  PX_CHECK(count_sel(ctx, &g, &s, &first) == 1);
  px_lattice_grid_centre(&g, first, x);
  PX_CHECK_NEAR(x[2], 0.0005, 1e-12);
  /* a box selection outside the body is an error that says where the body is */
  s = sel_none();
  s.has_box = 1;
  s.box_min[0] = 0.2;
  s.box_max[0] = 0.3;
  s.box_max[1] = s.box_max[2] = 1.0;
  PX_CHECK(count_sel(ctx, &g, &s, NULL) == 0);
  PX_CHECK(px_context_status(ctx) == PX_STATUS_CONFIG);
  PX_CHECK(strstr(px_context_message(ctx), "matches no element") != NULL);
  PX_CHECK(strstr(px_context_message(ctx), "[0, 0.1]") != NULL);
  px_context_clear(ctx);
  px_lattice_grid_free(ctx, &g);
}

static void test_csg(struct px_context *ctx) {
  struct px_lattice_grid g;
  struct px_lattice_prim p[3];
  double h = 1e-3, r = 10e-3, expect;
  size_t c, n;
  /* sphere: about 4/3 pi r^3 / h^3 cells (centre-inside sampling) */
  memset(p, 0, sizeof p);
  p[0].shape = PX_LATTICE_SHAPE_SPHERE;
  p[0].r = r;
  PX_CHECK_OK(ctx, px_lattice_grid_build(ctx, h, p, 1, &g));
  expect = 4.0 / 3.0 * 3.14159265358979 * r * r * r / (h * h * h);
  PX_CHECK_REL((double)g.count, expect, 0.02);
  PX_CHECK(g.n[0] == 20 && g.n[1] == 20 && g.n[2] == 20);
  px_lattice_grid_free(ctx, &g);

  /* plate with a through hole: box minus cylinder along z */
  p[0] = prim_box(0, 0, 0, 0.04, 0.02, 0.002, PX_LATTICE_OP_UNION);
  memset(&p[1], 0, sizeof p[1]);
  p[1].shape = PX_LATTICE_SHAPE_CYLINDER;
  p[1].op = PX_LATTICE_OP_DIFFERENCE;
  p[1].p0[0] = 0.02;
  p[1].p0[1] = 0.01;
  p[1].p0[2] = -0.001;
  p[1].p1[0] = 0.02;
  p[1].p1[1] = 0.01;
  p[1].p1[2] = 0.003;
  p[1].r = 0.005;
  PX_CHECK_OK(ctx, px_lattice_grid_build(ctx, h, p, 2, &g));
  expect = 2.0 * (800.0 - 3.14159265358979 * 25.0);
  PX_CHECK_REL((double)g.count, expect, 0.03);
  /* symmetric hole: the cell at the hole centre is empty, a corner is full */
  n = 0;
  for (c = 0; c < g.ncell; ++c) n += g.occ[c];
  PX_CHECK(n == g.count);
  PX_CHECK(g.occ[19 + 40 * 9] == 0 && g.occ[0] == 1);
  PX_CHECK_OK(ctx, px_lattice_grid_check_connected(ctx, &g));
  px_lattice_grid_free(ctx, &g);

  /* union of two boxes touching along a face; the grid is aligned with the
   * first shape and spans both */
  p[0] = prim_box(0, 0, 0, 0.01, 0.002, 0.002, PX_LATTICE_OP_UNION);
  p[1] = prim_box(0.01, -0.004, 0, 0.012, 0.006, 0.002, PX_LATTICE_OP_UNION);
  PX_CHECK_OK(ctx, px_lattice_grid_build(ctx, h, p, 2, &g));
  PX_CHECK(g.count == 10 * 2 * 2 + 2 * 10 * 2);
  PX_CHECK(g.n[0] == 12 && g.n[1] == 10 && g.n[2] == 2);
  PX_CHECK_NEAR(g.origin[1], -0.004, 1e-15);
  PX_CHECK_OK(ctx, px_lattice_grid_check_connected(ctx, &g));
  px_lattice_grid_free(ctx, &g);

  /* cropping: a difference that removes one end shrinks the grid */
  p[0] = prim_box(0, 0, 0, 0.01, 0.002, 0.002, PX_LATTICE_OP_UNION);
  p[1] = prim_box(-1, -1, -1, 0.003, 1, 1, PX_LATTICE_OP_DIFFERENCE);
  PX_CHECK_OK(ctx, px_lattice_grid_build(ctx, h, p, 2, &g));
  PX_CHECK(g.count == 7 * 4 && g.n[0] == 7);
  PX_CHECK_NEAR(g.origin[0], 0.003, 1e-15);
  px_lattice_grid_free(ctx, &g);
}

static void test_errors(struct px_context *ctx) {
  struct px_lattice_grid g;
  struct px_lattice_prim p[3];
  /* a difference removes everything: empty body */
  p[0] = prim_box(0, 0, 0, 0.01, 0.01, 0.01, PX_LATTICE_OP_UNION);
  p[1] = prim_box(-1, -1, -1, 1, 1, 1, PX_LATTICE_OP_DIFFERENCE);
  PX_CHECK_STATUS(ctx, px_lattice_grid_build(ctx, 1e-3, p, 2, &g), PX_STATUS_CONFIG);
  PX_CHECK(strstr(px_context_message(ctx), "empty") != NULL);
  /* a shape thinner than the grid has no cell centre inside */
  p[0] = prim_box(0, 0, 0, 0.01, 0.01, 0.0004, PX_LATTICE_OP_UNION);
  PX_CHECK_STATUS(ctx, px_lattice_grid_build(ctx, 1e-3, p, 1, &g), PX_STATUS_CONFIG);
  /* degenerate shapes and bad spacing */
  p[0] = prim_box(0, 0, 0, 0.01, 0.0, 0.01, PX_LATTICE_OP_UNION);
  PX_CHECK_STATUS(ctx, px_lattice_grid_build(ctx, 1e-3, p, 1, &g), PX_STATUS_CONFIG);
  PX_CHECK(strstr(px_context_message(ctx), "max[1]") != NULL);
  p[0] = prim_box(0, 0, 0, 0.01, 0.01, 0.01, PX_LATTICE_OP_UNION);
  PX_CHECK_STATUS(ctx, px_lattice_grid_build(ctx, 0.0, p, 1, &g), PX_STATUS_CONFIG);
  p[0].op = PX_LATTICE_OP_DIFFERENCE;
  PX_CHECK_STATUS(ctx, px_lattice_grid_build(ctx, 1e-3, p, 1, &g), PX_STATUS_CONFIG);
  /* two boxes 1 mm apart: disconnected */
  p[0] = prim_box(0, 0, 0, 0.004, 0.002, 0.002, PX_LATTICE_OP_UNION);
  p[1] = prim_box(0.005, 0, 0, 0.006, 0.001, 0.001, PX_LATTICE_OP_UNION);
  PX_CHECK_OK(ctx, px_lattice_grid_build(ctx, 1e-3, p, 2, &g));
  PX_CHECK_STATUS(ctx, px_lattice_grid_check_connected(ctx, &g), PX_STATUS_CONFIG);
  PX_CHECK(strstr(px_context_message(ctx), "2 separate parts") != NULL);
  PX_CHECK(strstr(px_context_message(ctx), "smallest has 1 element,") != NULL);
  PX_CHECK(strstr(px_context_message(ctx), "(0.0055, 0.0005, 0.0005)") != NULL);
  px_lattice_grid_free(ctx, &g);
  /* touching only along an edge is not connected */
  p[0] = prim_box(0, 0, 0, 0.001, 0.001, 0.001, PX_LATTICE_OP_UNION);
  p[1] = prim_box(0.001, 0.001, 0, 0.002, 0.002, 0.001, PX_LATTICE_OP_UNION);
  PX_CHECK_OK(ctx, px_lattice_grid_build(ctx, 1e-3, p, 2, &g));
  PX_CHECK_STATUS(ctx, px_lattice_grid_check_connected(ctx, &g), PX_STATUS_CONFIG);
  px_lattice_grid_free(ctx, &g);
  px_context_clear(ctx);
}

int main(void) {
  struct px_context *ctx;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  test_box_and_faces(ctx);
  test_csg(ctx);
  test_errors(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  return px_test_report("test_lattice_grid");
}
