/* The vortex solver through the run driver: a checkpoint/resume continuation
 * is bit-identical to an uninterrupted run (cpu, same threads), and so are
 * runs on 1 and 2 threads; bad input is
 * refused before any step with a message naming the key or file line; a
 * blow-up stops with a diagnosis. */
#include <string.h>

#include "partix/checkpoint.h"
#include "partix/memory.h"
#include "partix/sim.h"
#include "px_test.h"
#include "../io/px_test_fonts.h"
#include "solvers/vortex/vortex_core.h"
#include "vortex/vx_test_util.h"

static const char *base_case =
    "solver: vortex\n"
    "backend: {type: cpu, threads: 2, precision: %s}\n"
    "time: {dt: 0.02, steps: %d}\n"
    "output: {dir: %s, every: 1000, png: false, vtk: false, csv: true}\n"
    "vortex:\n"
    "  nu: 0.005\n"
    "  v_inf: [1.0, 0.0]\n"
    "  scheme: %s\n"
    "  bodies:\n"
    "    - {type: circle, radius: 0.5, panels: 64}\n";

static void test_resume(struct px_context *ctx, const char *scheme) {
  char text[2048];
  /* uninterrupted: 30 steps */
  snprintf(text, sizeof text, base_case, "mixed", 30, "out_vx_a", scheme);
  struct px_sim *a = vx_test_sim(ctx, "test.yaml", text);
  PX_CHECK(a != NULL);
  if (!a) return;
  PX_CHECK_OK(ctx, px_sim_run(a));
  px_sim_free(a);
  /* 12 steps, checkpoint, resume to 30 */
  snprintf(text, sizeof text, base_case, "mixed", 12, "out_vx_b", scheme);
  struct px_sim *b = vx_test_sim(ctx, "test.yaml", text);
  PX_CHECK(b != NULL);
  if (!b) return;
  PX_CHECK_OK(ctx, px_sim_run(b));
  px_sim_free(b);
  const char *ov[] = {"time.steps=30"};
  struct px_sim *r = NULL;
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "out_vx_b/checkpoint.pxc", ov, 1, &r));
  if (!r) return;
  px_sim_set_progress(r, NULL, 0);
  PX_CHECK(px_sim_step_index(r) == 12);
  PX_CHECK_OK(ctx, px_sim_run(r));
  px_sim_free(r);
  const char *sec[] = {"vortex.x", "vortex.y", "vortex.gamma", "vortex.absorbed"};
  for (int q = 0; q < 4; ++q) {
    size_t na = 0, nb = 0;
    double *da = vx_test_read_section(ctx, "out_vx_a/checkpoint.pxc", sec[q], &na);
    double *db = vx_test_read_section(ctx, "out_vx_b/checkpoint.pxc", sec[q], &nb);
    PX_CHECK(da && db);
    PX_CHECK_MSG(na == nb && na > 0, "%s: %zu vs %zu values", sec[q], na, nb);
    if (da && db && na == nb)
      PX_CHECK_MSG(memcmp(da, db, na * sizeof(double)) == 0, "%s differs after resume", sec[q]);
    px_mem_free(ctx, da);
    px_mem_free(ctx, db);
  }
  /* the loads CSV of the resumed run has one row per step, no duplicates */
  FILE *f = fopen("out_vx_b/loads.csv", "r");
  int lines = 0;
  char buf[4096];
  while (f && fgets(buf, sizeof buf, f)) ++lines;
  if (f) fclose(f);
  PX_CHECK_MSG(lines == 31, "loads.csv has %d lines, expected header + 30", lines);
}

static void expect_refused(struct px_context *ctx, const char *text, const char *what1,
                           const char *what2) {
  struct px_case *c = NULL;
  enum px_status s = px_case_load_string(ctx, "bad.yaml", text, strlen(text), NULL, 0, &c);
  struct px_sim *sim = NULL;
  if (s == PX_STATUS_OK) s = px_sim_create(ctx, c, PX_SIM_MODE_CHECK, &sim);
  PX_CHECK_MSG(s == PX_STATUS_CONFIG, "accepted or wrong status %s: %s", px_status_name(s),
               px_context_message(ctx));
  PX_CHECK(vx_test_message_has(ctx, what1));
  if (what2) PX_CHECK(vx_test_message_has(ctx, what2));
  px_sim_free(sim);
  px_context_clear(ctx);
}

static void test_bad_input(struct px_context *ctx) {
  const char *head = "solver: vortex\ntime: {dt: %s, steps: 10}\noutput: {dir: out_vx_bad}\n"
                     "vortex:\n  nu: %s\n  v_inf: [1, 0]\n  bodies:\n    - %s\n";
  char t[2048];
  snprintf(t, sizeof t, head, "0.01", "0", "{type: circle, radius: 0.5, panels: 64}");
  expect_refused(ctx, t, "vortex.nu", NULL);
  snprintf(t, sizeof t, head, "-0.01", "0.01", "{type: circle, radius: 0.5, panels: 64}");
  expect_refused(ctx, t, "time.dt", NULL);
  snprintf(t, sizeof t, head, "0.01", "0.01", "{type: circle, radius: 0.5, panels: 4}");
  expect_refused(ctx, t, "panels", NULL);
  FILE *f = fopen("nan_profile.dat", "w");
  fputs("bad airfoil\n1 0\n0.5 0.06\n0 0\n0.5 nan\n1 0\n", f);
  fclose(f);
  snprintf(t, sizeof t, head, "0.01", "0.01", "{type: selig, file: nan_profile.dat, panels: 64}");
  expect_refused(ctx, t, "nan_profile.dat:5:", "vortex.bodies[0]");
  f = fopen("open_profile.txt", "w");
  fputs("0 0\n1 0\n1 1\n0 1\n", f);
  fclose(f);
  snprintf(t, sizeof t, head, "0.01", "0.01", "{type: points, file: open_profile.txt}");
  expect_refused(ctx, t, "not closed", NULL);
  f = fopen("crossing_profile.txt", "w");
  fputs("0 0\n1 1\n1 0\n0 1\n0 0\n", f);
  fclose(f);
  snprintf(t, sizeof t, head, "0.01", "0.01", "{type: points, file: crossing_profile.txt}");
  expect_refused(ctx, t, "self-intersecting", "line 2");
  /* two overlapping bodies */
  const char *two = "solver: vortex\ntime: {dt: 0.01, steps: 10}\noutput: {dir: out_vx_bad}\n"
                    "vortex:\n  nu: 0.01\n  v_inf: [1, 0]\n  bodies:\n"
                    "    - {type: circle, radius: 0.5, panels: 64}\n"
                    "    - {type: circle, radius: 0.5, panels: 64, position: [0.6, 0]}\n";
  expect_refused(ctx, two, "overlap", "vortex.bodies[1]");
  /* ramp without its time */
  const char *ramp = "solver: vortex\ntime: {dt: 0.01, steps: 10}\noutput: {dir: out_vx_bad}\n"
                     "vortex:\n  nu: 0.01\n  v_inf: [1, 0]\n  start: linear\n  bodies:\n"
                     "    - {type: circle, radius: 0.5, panels: 64}\n";
  expect_refused(ctx, ramp, "ramp_time", NULL);
  const char *rk3 = "solver: vortex\ntime: {dt: 0.01, steps: 10}\noutput: {dir: out_vx_bad}\n"
                    "vortex:\n  nu: 0.01\n  v_inf: [1, 0]\n  scheme: rk3\n  bodies:\n"
                    "    - {type: circle, radius: 0.5, panels: 64}\n";
  expect_refused(ctx, rk3, "bad.yaml:7:", "vortex.scheme");
}

/* The same run on 1 and on 2 threads: bit-identical wakes (fixed reductions,
 * per-target loops, sequential merge). */
static void test_threads(struct px_context *ctx) {
  struct px_vortex_contour c;
  PX_CHECK_OK(ctx, px_vortex_profile_ellipse(ctx, 0.5, 0.25, 96, &c));
  px_vortex_profile_place(&c, 0.0, 0.0, 1.0, 10.0);
  struct px_vortex_wake *w[2] = {NULL, NULL};
  struct px_vortex_engine *e[2] = {NULL, NULL};
  struct px_backend *be[2] = {NULL, NULL};
  for (int q = 0; q < 2; ++q) {
    PX_CHECK_OK(ctx, px_backend_create(ctx, "cpu", 0, q + 1, &be[q]));
    struct px_vortex_config cfg;
    vx_test_cylinder_config(&cfg, 0.01, 0.007, q + 1);
    PX_CHECK_OK(ctx, px_vortex_engine_create(ctx, be[q], &cfg, &c, 1, &e[q]));
    for (int s = 0; e[q] && s < 15; ++s) PX_CHECK_OK(ctx, px_vortex_engine_step(e[q]));
    if (e[q]) w[q] = &e[q]->w;
  }
  if (w[0] && w[1]) {
    PX_CHECK_MSG(w[0]->n == w[1]->n, "%zu vs %zu vortices", w[0]->n, w[1]->n);
    if (w[0]->n == w[1]->n)
      PX_CHECK(memcmp(w[0]->x, w[1]->x, w[0]->n * sizeof(double)) == 0 &&
               memcmp(w[0]->y, w[1]->y, w[0]->n * sizeof(double)) == 0 &&
               memcmp(w[0]->g, w[1]->g, w[0]->n * sizeof(double)) == 0);
    PX_CHECK(e[0]->loads[0].cx == e[1]->loads[0].cx);
  }
  for (int q = 0; q < 2; ++q) {
    px_vortex_engine_free(e[q]);
    px_backend_free(be[q]);
  }
  px_vortex_contour_free(ctx, &c);
}

static void test_blowup(struct px_context *ctx) {
  struct px_backend *be = NULL;
  PX_CHECK_OK(ctx, px_backend_create(ctx, "cpu", 0, 1, &be));
  struct px_vortex_contour c;
  PX_CHECK_OK(ctx, px_vortex_profile_circle(ctx, 0.5, 64, &c));
  struct px_vortex_config cfg;
  px_vortex_config_defaults(&cfg);
  cfg.nu = 0.01;
  cfg.dt = 0.01;
  cfg.vinf[0] = 1.0;
  cfg.vref = 1.0;
  cfg.eps = cfg.eps_col = 0.01;
  cfg.gamma_max = 0.01;
  struct px_vortex_engine *e = NULL;
  PX_CHECK_OK(ctx, px_vortex_engine_create(ctx, be, &cfg, &c, 1, &e));
  /* a non-finite vortex */
  double x = NAN, y = 1.0, g = 0.1;
  PX_CHECK_OK(ctx, px_vortex_engine_add(e, 1, &x, &y, &g));
  PX_CHECK_STATUS(ctx, px_vortex_engine_step(e), PX_STATUS_NUMERIC);
  PX_CHECK(vx_test_message_has(ctx, "non-finite"));
  PX_CHECK(vx_test_message_has(ctx, "step 0"));
  px_vortex_engine_free(e);
  /* runaway circulation next to the wall */
  PX_CHECK_OK(ctx, px_vortex_engine_create(ctx, be, &cfg, &c, 1, &e));
  x = 0.0;
  y = 0.5001;
  g = 1e6;
  PX_CHECK_OK(ctx, px_vortex_engine_add(e, 1, &x, &y, &g));
  PX_CHECK_STATUS(ctx, px_vortex_engine_step(e), PX_STATUS_NUMERIC);
  PX_CHECK(vx_test_message_has(ctx, "runaway"));
  px_vortex_engine_free(e);
  px_vortex_contour_free(ctx, &c);
  px_backend_free(be);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  test_resume(ctx, "euler");
  test_resume(ctx, "rk2");
  test_bad_input(ctx);
  test_threads(ctx);
  test_blowup(ctx);
  px_context_free(ctx);
  px_test_release_fonts(); /* the load plot drew text */
  return px_test_report("test_vortex_solver");
}
