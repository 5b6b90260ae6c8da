/* The original's test against CalculiX: steel plate 100 x 50 x 5 mm, lower
 * half of the right face clamped, 100 N down at the top corner, relaxed to
 * the static solution (leapfrog + adaptive dynamic relaxation, h = 1 mm,
 * 25000 elements). Reference numbers: tests/lattice/data/plate_ccx.txt,
 * written by tests/lattice/ccx/plate_ccx.py (CalculiX C3D8I, nu = 0, 1 mm
 * bricks aligned with the cells, the face clamp, the load over the corner
 * cell). Targets (spec): corner deflection within 3 %, von Mises stress at
 * interior cells within 10 % (not at the singular clamp edge or under the
 * load). The deflection elsewhere ("uz" lines) is printed, not asserted.
 *
 * The lattice holds its clamp at the centres of the fixed elements
 * (x = 100 mm - h/2), so at h = 1 mm it is about 2 % stiffer than the face
 * clamp; the error is O(h) (docs/lattice.md: h = 5/3, 1.25 mm give -3.9 %,
 * -2.7 %). Minutes on 2 cores: label long (bench/lattice_validate.sh plate).
 *
 * Argument: "single" or "double" (default single). */
#include <stdlib.h>

#include "lt_util.h"

int main(int argc, char **argv) {
  struct px_context *ctx;
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_bc bc[2];
  struct px_lattice_params par = lt_steel();
  struct px_lattice_sel corner = lt_sel_point(0.0, 0.05, 0.005);
  struct lt_engine en;
  struct lt_el_d *y;
  struct px_lattice_fields f;
  double value = 0.0, dt, *vm;
  enum px_precision p = argc > 1 && strcmp(argv[1], "double") == 0 ? PX_PRECISION_DOUBLE
                                                                    : PX_PRECISION_SINGLE;
  long steps;
  FILE *ref;
  char line[256];
  int npoints = 0;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  memset(bc, 0, sizeof bc);
  bc[0].sel = lt_sel_face(PX_LATTICE_FACE_X_MAX);
  bc[0].sel.has_box = 1;
  bc[0].sel.box_min[0] = bc[0].sel.box_min[1] = bc[0].sel.box_min[2] = -1.0;
  bc[0].sel.box_max[0] = bc[0].sel.box_max[2] = 1.0;
  bc[0].sel.box_max[1] = 0.025;
  bc[0].fix = 63;
  bc[1].sel = corner;
  bc[1].has_load = 1;
  bc[1].load[2] = -100.0;
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, 1e-3, 100, 50, 5, &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &m, &g, &par, bc, 2));
  y = (struct lt_el_d *)malloc(m.nalloc * sizeof *y);
  vm = (double *)malloc(m.nalloc * sizeof *vm);
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_cpu, PX_LATTICE_INTEGRATOR_LEAPFROG,
                                  p, PX_LATTICE_SCHEME_AUTO, 0, NULL, &en));
  dt = 0.9 * px_lattice_model_dt_limit(&m, PX_LATTICE_INTEGRATOR_LEAPFROG);
  steps = lt_relax(ctx, &m, &en, dt, &corner, 2, 1e-5, 300000, &value, y);
  printf("plate (%s): relaxed in %ld steps\n", p == PX_PRECISION_DOUBLE ? "double" : "single",
         steps);
  PX_CHECK(steps > 0);
  memset(&f, 0, sizeof f);
  f.vm = vm;
  PX_CHECK_OK(ctx, en.vt->fields(en.e, 0.0, dt, &f));
  ref = fopen(argc > 2 ? argv[2] : PX_SOURCE_DIR "/tests/lattice/data/plate_ccx.txt", "r");
  PX_CHECK(ref != NULL);
  while (ref && fgets(line, sizeof line, ref)) {
    char name[32];
    double x, yy, z, v;
    if (line[0] == '#' || sscanf(line, "%31s %lf %lf %lf %lf", name, &x, &yy, &z, &v) != 5)
      continue;
    if (strcmp(name, "corner_uz") == 0) {
      double uz = value * 1e3; /* mm */
      printf("corner deflection: lattice %.5f mm, CalculiX %.5f mm, ratio %.4f\n", uz, v, uz / v);
      PX_CHECK_REL(uz, v, 0.03);
    } else if (strcmp(name, "uz") == 0) {
      struct px_lattice_sel s = lt_sel_point(x * 1e-3, yy * 1e-3, z * 1e-3);
      double l = lt_mean_u(ctx, &m, y, &s, 2) * 1e3;
      printf("deflection at (%.1f, %.1f, %.1f) mm: lattice %.5f mm, CalculiX %.5f mm, ratio %.4f\n",
             x, yy, z, l, v, l / v);
    } else if (strcmp(name, "von_mises") == 0) {
      struct px_lattice_sel s = lt_sel_point(x * 1e-3, yy * 1e-3, z * 1e-3);
      size_t *cells = NULL, n = 0;
      double l;
      PX_CHECK_OK(ctx, px_lattice_select(ctx, &m.grid, &s, &cells, &n));
      if (!cells) continue;
      l = vm[px_lattice_index(&m, cells[0])] * 1e-6; /* MPa */
      px_mem_free(ctx, cells);
      printf("von Mises at (%.1f, %.1f, %.1f) mm: lattice %.3f MPa, CalculiX %.3f MPa, ratio "
             "%.4f\n", x, yy, z, l, v, l / v);
      PX_CHECK_REL(l, v, 0.10);
      ++npoints;
    }
  }
  if (ref) fclose(ref);
  PX_CHECK(npoints >= 6);
  lt_engine_free(&en);
  free(y);
  free(vm);
  px_lattice_model_free(ctx, &m);
  px_context_free(ctx);
  return px_test_report("test_lattice_plate");
}
