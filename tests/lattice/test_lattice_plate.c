/* The original's test against CalculiX, run as a user runs it: the shipped
 * cases/lattice/plate.yaml (steel plate 100 x 50 x 5 mm, lower half of the
 * right face clamped, 100 N down at the top corner, h = 1 mm, 25000
 * elements, leapfrog + adaptive dynamic relaxation) through the run driver.
 *  - The run ends on its convergence criterion (lattice.static_tolerance),
 *    before the case's maximum step count, and summary.json says so.
 *  - Against tests/lattice/data/plate_ccx.txt, written by
 *    tests/lattice/ccx/plate_ccx.py (CalculiX C3D8I, nu = 0, 1 mm bricks
 *    aligned with the cells, the face clamp, the load over the corner cell):
 *    corner deflection within 3 %, von Mises stress at interior cells within
 *    10 % (not at the singular clamp edge or under the load). The deflection
 *    elsewhere ("uz" lines) is printed, not asserted.
 * The final state is read from the run's checkpoint and its fields computed
 * by the double reference engine.
 *
 * The lattice holds its clamp at the centres of the fixed elements
 * (x = 100 mm - h/2), so at h = 1 mm it is about 2 % stiffer than the face
 * clamp; the error is O(h) (docs/notes/lattice.md: h = 5/3, 1.25 mm give
 * -3.9 %, -2.7 %). Minutes on 2 cores: label long
 * (bench/lattice_validate.sh plate).
 *
 * Arguments: "single" or "double" (default: the case's, single), then the
 * reference file (default: the stored one). */
#include <stdlib.h>

#include "lt_util.h"
#include "partix/sim.h"

/* The run's final state (checkpoint section lattice.state, 13 values per
 * padded element) and link flags; NULL on failure. */
static double *read_state(struct px_context *ctx, const char *path, uint64_t *count,
                          uint8_t **links) {
  struct px_checkpoint *ck = NULL;
  double *y = NULL;
  enum px_dtype t;
  uint64_t nl = 0;
  *links = NULL;
  if (px_checkpoint_open(ctx, path, &ck) != PX_STATUS_OK) return NULL;
  if (px_checkpoint_find(ck, "lattice.state", &t, count) == PX_STATUS_OK &&
      px_checkpoint_find(ck, "lattice.links", &t, &nl) == PX_STATUS_OK) {
    y = (double *)malloc(*count * sizeof(double));
    *links = (uint8_t *)malloc(nl);
    if (!y || !*links ||
        px_checkpoint_read(ck, "lattice.state", PX_DTYPE_F64, *count, y) != PX_STATUS_OK ||
        px_checkpoint_read(ck, "lattice.links", PX_DTYPE_U8, nl, *links) != PX_STATUS_OK) {
      free(y);
      free(*links);
      y = NULL;
      *links = NULL;
    }
  }
  px_checkpoint_close(ck);
  return y;
}

int main(int argc, char **argv) {
  struct px_context *ctx;
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_bc bc[2];
  struct px_lattice_params par = lt_steel();
  struct px_lattice_sel corner = lt_sel_point(0.0, 0.05, 0.005);
  struct lt_engine en;
  struct px_lattice_fields f;
  double *y = NULL, *vm = NULL;
  uint8_t *links = NULL;
  uint64_t count = 0;
  long steps = 0, max_steps = 0;
  FILE *ref, *sf;
  char line[256], overrides[2][64];
  const char *ov[2];
  size_t nov = 1;
  int npoints = 0, converged = 0;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  snprintf(overrides[0], sizeof overrides[0], "output.dir=lt_plate");
  ov[0] = overrides[0];
  if (argc > 1) {
    snprintf(overrides[1], sizeof overrides[1], "backend.precision=%s", argv[1]);
    ov[nov++] = overrides[1];
  }
  PX_CHECK_OK(ctx, px_case_load(ctx, PX_SOURCE_DIR "/cases/lattice/plate.yaml", ov, nov, &c));
  if (c) PX_CHECK_OK(ctx, px_sim_create(ctx, c, PX_SIM_MODE_RUN, &sim));
  if (sim) {
    px_sim_set_progress(sim, NULL, 0);
    PX_CHECK_OK(ctx, px_sim_run(sim));
    steps = px_sim_step_index(sim);
    max_steps = px_sim_step_count(sim);
  }
  px_sim_free(sim);
  printf("plate (%s): stopped at step %ld of at most %ld\n", argc > 1 ? argv[1] : "single", steps,
         max_steps);
  PX_CHECK(steps > 0 && steps < max_steps);
  sf = fopen("lt_plate/summary.json", "r");
  PX_CHECK(sf != NULL);
  while (sf && fgets(line, sizeof line, sf))
    if (strstr(line, "\"static_converged\": {\"value\": true")) converged = 1;
  if (sf) fclose(sf);
  PX_CHECK(converged);

  /* the final state in the model the case builds */
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
  y = read_state(ctx, "lt_plate/checkpoint.pxc", &count, &links);
  PX_CHECK_MSG(y && count == 13 * (uint64_t)m.nalloc, "state of %llu values for %zu elements",
               (unsigned long long)count, m.nalloc);
  if (!y || count != 13 * (uint64_t)m.nalloc) return px_test_report("test_lattice_plate");
  vm = (double *)malloc(m.nalloc * sizeof *vm);
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_ref, PX_LATTICE_INTEGRATOR_LEAPFROG,
                                  PX_PRECISION_DOUBLE, PX_LATTICE_SCHEME_AUTO, 1, NULL, &en));
  PX_CHECK_OK(ctx, en.vt->set_state(en.e, (const struct lt_el *)y, links));
  memset(&f, 0, sizeof f);
  f.vm = vm;
  PX_CHECK_OK(ctx, en.vt->fields(en.e, 0.0, 0.0, &f));

  ref = fopen(argc > 2 ? argv[2] : PX_SOURCE_DIR "/tests/lattice/data/plate_ccx.txt", "r");
  PX_CHECK(ref != NULL);
  while (ref && fgets(line, sizeof line, ref)) {
    char name[32];
    double x, yy, z, v;
    if (line[0] == '#' || sscanf(line, "%31s %lf %lf %lf %lf", name, &x, &yy, &z, &v) != 5)
      continue;
    if (strcmp(name, "corner_uz") == 0) {
      double uz = lt_mean_u(ctx, &m, (const struct lt_el *)y, &corner, 2) * 1e3; /* mm */
      printf("corner deflection: lattice %.5f mm, CalculiX %.5f mm, ratio %.4f\n", uz, v, uz / v);
      PX_CHECK_REL(uz, v, 0.03);
    } else if (strcmp(name, "uz") == 0) {
      struct px_lattice_sel s = lt_sel_point(x * 1e-3, yy * 1e-3, z * 1e-3);
      double l = lt_mean_u(ctx, &m, (const struct lt_el *)y, &s, 2) * 1e3;
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
      printf(
          "von Mises at (%.1f, %.1f, %.1f) mm: lattice %.3f MPa, CalculiX %.3f MPa, ratio "
          "%.4f\n",
          x, yy, z, l, v, l / v);
      PX_CHECK_REL(l, v, 0.10);
      ++npoints;
    }
  }
  if (ref) fclose(ref);
  PX_CHECK(npoints >= 6);
  lt_engine_free(&en);
  free(y);
  free(links);
  free(vm);
  px_lattice_model_free(ctx, &m);
  px_context_free(ctx);
  return px_test_report("test_lattice_plate");
}
