/* The lattice solver through the run driver (px_sim):
 *  - bad input gives located errors: an empty body, a disconnected body, a
 *    selection that matches nothing, E <= 0, rho <= 0, dt above the
 *    stability limit;
 *  - a non-finite state stops the run naming the element and the quantity;
 *  - a run writes its outputs (vti + pvd, probes.csv with units in its
 *    header, PNG; vtu for a body that does not fill its bounding box; no
 *    picture or plot with output.png false) and the probe reads the
 *    displacement of the element it selects;
 *  - the last state is written whatever the schedule (a run of 45 steps
 *    with outputs every 20: snapshot, picture and probes.csv row of step
 *    45), and summary.json reports the largest von Mises stress and
 *    displacement of the run with where they are;
 *  - `partix render` (px_sim_render) draws pictures and writes nothing else:
 *    every other file of the run folder is left byte for byte;
 *  - resume from a checkpoint continues bit-identically on cpu (float and
 *    double, RK4 and leapfrog with quasi-static damping);
 *  - on resume the picture settings and the quasi-static tolerance may
 *    change, the material may not (refused naming the key). */
#include <stdlib.h>
#include <sys/stat.h>

#include "io/px_test_fonts.h"
#include "lt_util.h"
#include "partix/sim.h"

static const char *const base_case =
    "solver: lattice\n"
    "backend: {type: cpu, precision: %s, threads: 1}\n"
    "time: {steps: %d}\n"
    "output: {dir: %s, every: %d, log_every: %d, checkpoint_every: %d, png: %s}\n"
    "lattice:\n"
    "  h: 1.0e-3\n"
    "  E: %s\n"
    "  rho: 7850\n"
    "  integrator: %s\n"
    "  quasi_static: %s\n"
    "  body:\n"
    "    - {type: box, min: [0, 0, 0], max: [0.012, 0.004, 0.003]}\n"
    "%s"
    "  boundary:\n"
    "    - {name: clamp, select: {face: x_min}, fix: [all]}\n"
    "    - {name: load, select: {face: x_max%s}, force: [0, 0, %s],\n"
    "       function: {type: ramp, t1: 2.0e-6}}\n"
    "  probes:\n"
    "    - {name: tip, select: {nearest: [0.012, 0.002, 0.003]}}\n";

struct opts {
  const char *prec, *dir, *png, *E, *integ, *qs, *extra_body, *load_sel, *force;
  int steps, every, log_every, ck_every;
};

static struct opts defaults(const char *dir) {
  struct opts o;
  o.prec = "double";
  o.dir = dir;
  o.png = "false";
  o.E = "2.1e11";
  o.integ = "rk4";
  o.qs = "false";
  o.extra_body = "";
  o.load_sel = "";
  o.force = "-20";
  o.steps = 40;
  o.every = 20;
  o.log_every = 10;
  o.ck_every = 0;
  return o;
}

static enum px_status make_sim(struct px_context *ctx, const struct opts *o, const char *const *ov,
                               size_t nov, struct px_sim **sim) {
  char text[4096];
  struct px_case *c = NULL;
  snprintf(text, sizeof text, base_case, o->prec, o->steps, o->dir, o->every, o->log_every,
           o->ck_every, o->png, o->E, o->integ, o->qs, o->extra_body, o->load_sel, o->force);
  *sim = NULL;
  px_context_clear(ctx);
  PX_TRY(px_case_load_string(ctx, "case.yaml", text, strlen(text), ov, nov, &c));
  px_test_fresh_case_dir(c); /* a new run each time */
  PX_TRY(px_sim_create(ctx, c, PX_SIM_MODE_RUN, sim));
  px_sim_set_progress(*sim, NULL, 0);
  return PX_STATUS_OK;
}

static void expect_error(struct px_context *ctx, const struct opts *o, const char *const *ov,
                         size_t nov, const char *want1, const char *want2) {
  struct px_sim *sim = NULL;
  enum px_status st = make_sim(ctx, o, ov, nov, &sim);
  PX_CHECK_MSG(st == PX_STATUS_CONFIG, "status %s: %s", px_status_name(st),
               px_context_message(ctx));
  PX_CHECK_MSG(strstr(px_context_message(ctx), want1) != NULL, "message: %s (want '%s')",
               px_context_message(ctx), want1);
  if (want2)
    PX_CHECK_MSG(strstr(px_context_message(ctx), want2) != NULL, "message: %s (want '%s')",
                 px_context_message(ctx), want2);
  px_sim_free(sim);
}

static void test_errors(struct px_context *ctx) {
  struct opts o = defaults("lt_solver_err");
  const char *dt_ov[] = {"time.dt=1e-6"};
  const char *empty_ov[] = {"lattice.body[0].max=[0.012, 0.004, 0.0004]"};
  const char *sel_ov[] = {"lattice.probes[0].select.nearest=[1, 1, 1]",
                          "lattice.probes[0].select.max=[0.0009, 0.0009, 0.0009]",
                          "lattice.probes[0].select.min=[0.0006, 0.0006, 0.0006]"};
  expect_error(ctx, &o, empty_ov, 1, "case.yaml:", "lattice.body: the body is empty");
  o.extra_body = "    - {type: box, min: [0.014, 0, 0], max: [0.015, 0.001, 0.001]}\n";
  expect_error(ctx, &o, NULL, 0, "lattice.body: the body is not connected", "2 separate parts");
  o = defaults("lt_solver_err");
  o.load_sel = ", min: [0, 0.01, 0]";
  expect_error(ctx, &o, NULL, 0, "lattice.boundary[1].select: the selection matches no element",
               "on face x_max");
  o = defaults("lt_solver_err");
  expect_error(ctx, &o, sel_ov, 3, "lattice.probes[0].select", "matches no element");
  /* E and rho <= 0 are reported at the value: E sits on line 7, column 6
   * of the generated case text; rho comes from an override */
  o.E = "-1";
  expect_error(ctx, &o, NULL, 0, "case.yaml:7:6: lattice.E", "must be > 0");
  o.E = "0";
  expect_error(ctx, &o, NULL, 0, "case.yaml:7:6: lattice.E", "must be > 0");
  {
    const char *rho_ov[] = {"lattice.rho=0"};
    o = defaults("lt_solver_err");
    expect_error(ctx, &o, rho_ov, 1, "lattice.rho", "must be > 0 (got 0)");
  }
  o = defaults("lt_solver_err");
  expect_error(ctx, &o, dt_ov, 1, "time.dt: dt = 1e-06 s is above the stability limit", "rk4");
}

static void test_blowup(struct px_context *ctx) {
  struct opts o = defaults("lt_solver_blowup");
  struct px_sim *sim = NULL;
  enum px_status st;
  o.force = "-1.0e300";
  PX_CHECK_OK(ctx, make_sim(ctx, &o, NULL, 0, &sim));
  if (!sim) return;
  st = px_sim_run(sim);
  PX_CHECK_MSG(st == PX_STATUS_NUMERIC, "status %s: %s", px_status_name(st),
               px_context_message(ctx));
  PX_CHECK_MSG(strstr(px_context_message(ctx), "of element (") != NULL &&
                   strstr(px_context_message(ctx), "is not finite") != NULL,
               "message: %s", px_context_message(ctx));
  printf("blow-up message: %s\n", px_context_message(ctx));
  px_sim_free(sim);
}

static int file_exists(const char *dir, const char *name) {
  char path[512];
  struct stat sb;
  snprintf(path, sizeof path, "%s/%s", dir, name);
  return stat(path, &sb) == 0 && sb.st_size > 0;
}

static void test_outputs(struct px_context *ctx) {
  struct opts o = defaults("lt_solver_out");
  struct px_sim *sim = NULL;
  FILE *f;
  char line[1024];
  int rows = 0;
  double last_uz = 0.0;
  o.png = "true";
  PX_CHECK_OK(ctx, make_sim(ctx, &o, NULL, 0, &sim));
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  PX_CHECK(file_exists("lt_solver_out", "lattice.pvd"));
  PX_CHECK(file_exists("lt_solver_out", "lattice_000000.vti"));
  PX_CHECK(file_exists("lt_solver_out", "lattice_000040.vti"));
  PX_CHECK(file_exists("lt_solver_out", "von_mises_000040.png"));
  PX_CHECK(file_exists("lt_solver_out", "probes.png"));
  f = fopen("lt_solver_out/probes.csv", "r");
  PX_CHECK(f != NULL);
  if (!f) return;
  PX_CHECK(fgets(line, sizeof line, f) != NULL);
  PX_CHECK_MSG(strncmp(line,
                       "t [s],tip.ux [m],tip.uy [m],tip.uz [m],tip.von_mises [Pa],"
                       "broken_links [-],damping [1/s],max_von_mises [Pa],",
                       107) == 0,
               "header %s", line);
  while (fgets(line, sizeof line, f)) {
    double t, ux, uy, uz;
    if (sscanf(line, "%lf,%lf,%lf,%lf", &t, &ux, &uy, &uz) == 4) last_uz = uz;
    ++rows;
  }
  fclose(f);
  PX_CHECK(rows == 5);
  /* the load pushes the tip down */
  PX_CHECK(last_uz < 0.0);
}

/* The whole file at dir/name, NUL-terminated (malloc), or NULL. */
static char *slurp(const char *dir, const char *name, size_t *len) {
  char path[512];
  FILE *f;
  char *buf;
  long n;
  snprintf(path, sizeof path, "%s/%s", dir, name);
  f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  n = ftell(f);
  rewind(f);
  buf = (char *)malloc((size_t)n + 1);
  if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
    free(buf);
    buf = NULL;
  }
  if (buf) buf[n] = '\0';
  if (len) *len = (size_t)n;
  fclose(f);
  return buf;
}

/* The "value" of quantity `name` in a summary.json text (NaN if absent). */
static double summary_value(const char *json, const char *name) {
  char key[128];
  const char *at;
  snprintf(key, sizeof key, "\"%s\": {\"value\": ", name);
  at = json ? strstr(json, key) : NULL;
  return at ? strtod(at + strlen(key), NULL) : NAN;
}

/* 45 steps with outputs every 20 (probe rows every 10): the end is off both
 * schedules, its state is written all the same; summary.json holds the
 * run's largest von Mises stress and displacement, as in probes.csv. */
static void test_final_state(struct px_context *ctx) {
  struct opts o = defaults("lt_solver_final");
  struct px_sim *sim = NULL;
  char *csv, *json, *line;
  double dt = 0.0, last_t = -1.0, vm_max = 0.0, u_max = 0.0;
  o.png = "true";
  o.steps = 45;
  PX_CHECK_OK(ctx, make_sim(ctx, &o, NULL, 0, &sim));
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  dt = px_sim_dt(sim);
  px_sim_free(sim);
  PX_CHECK(file_exists("lt_solver_final", "lattice_000045.vti"));
  PX_CHECK(file_exists("lt_solver_final", "von_mises_000045.png"));
  PX_CHECK(file_exists("lt_solver_final", "probes_von_mises.png"));
  csv = slurp("lt_solver_final", "probes.csv", NULL);
  json = slurp("lt_solver_final", "summary.json", NULL);
  PX_CHECK(csv && json);
  if (!csv || !json) {
    free(csv);
    free(json);
    return;
  }
  /* columns: t, tip (4), broken_links, damping, max_von_mises (+3), max_displacement */
  for (line = strchr(csv, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
    double v[12];
    int k = 0;
    char *p = line + 1, *end;
    for (k = 0; k < 12; ++k) {
      v[k] = strtod(p, &end);
      if (end == p) break;
      p = *end == ',' ? end + 1 : end;
    }
    if (k < 12) continue;
    last_t = v[0];
    vm_max = fmax(vm_max, v[7]);
    u_max = fmax(u_max, v[11]);
  }
  PX_CHECK_REL(last_t, 45 * dt, 1e-12);
  printf(
      "final state: last row t = %.6g s (45 dt = %.6g s); summary von_mises_max %.6g Pa "
      "(probes.csv %.6g), displacement_max %.6g m (probes.csv %.6g)\n",
      last_t, 45 * dt, summary_value(json, "von_mises_max"), vm_max,
      summary_value(json, "displacement_max"), u_max);
  PX_CHECK(vm_max > 0.0 && u_max > 0.0);
  PX_CHECK(summary_value(json, "von_mises_max") == vm_max);
  PX_CHECK(summary_value(json, "displacement_max") == u_max);
  PX_CHECK(strstr(json, "\"von_mises_max_at\": {\"value\": [") != NULL);
  PX_CHECK(strstr(json, "\"probe.tip.u\": {\"value\": [") != NULL);
  free(csv);
  free(json);
}

/* `partix render` of a finished run: its pictures drawn again, in another
 * view, and not one other file touched. */
static void test_render(struct px_context *ctx) {
  static const char *const keep[] = {"probes.csv",   "lattice.pvd", "lattice_000040.vti",
                                     "summary.json", "case.yaml",   "checkpoint.pxc"};
  const char *view[] = {"lattice.picture.view=top"};
  char *before[6], *after;
  size_t len_before[6], len_after = 0, k;
  struct px_sim *sim = NULL;
  struct stat sb;
  for (k = 0; k < 6; ++k) before[k] = slurp("lt_solver_out", keep[k], &len_before[k]);
  PX_CHECK(remove("lt_solver_out/von_mises_000040.png") == 0);
  PX_CHECK(remove("lt_solver_out/probes.png") == 0);
  PX_CHECK_OK(ctx,
              px_sim_open(ctx, "lt_solver_out/checkpoint.pxc", view, 1, PX_SIM_MODE_RENDER, &sim));
  if (sim) PX_CHECK_OK(ctx, px_sim_render(sim));
  px_sim_free(sim);
  PX_CHECK(file_exists("lt_solver_out", "von_mises_000040.png"));
  PX_CHECK(file_exists("lt_solver_out", "probes.png"));
  for (k = 0; k < 6; ++k) {
    after = slurp("lt_solver_out", keep[k], &len_after);
    PX_CHECK_MSG(before[k] && after && len_after == len_before[k] &&
                     memcmp(before[k], after, len_after) == 0,
                 "render changed %s", keep[k]);
    free(before[k]);
    free(after);
  }
  /* no snapshot of the rendered step written anew, no new files */
  PX_CHECK(stat("lt_solver_out/lattice_000041.vti", &sb) != 0);
}

/* Final state of a run directory's checkpoint (section lattice.state). */
static double *read_state(struct px_context *ctx, const char *dir, uint64_t *count) {
  char path[512];
  struct px_checkpoint *ck = NULL;
  double *y = NULL;
  enum px_dtype t;
  snprintf(path, sizeof path, "%s/checkpoint.pxc", dir);
  if (px_checkpoint_open(ctx, path, &ck) != PX_STATUS_OK) return NULL;
  if (px_checkpoint_find(ck, "lattice.state", &t, count) == PX_STATUS_OK) {
    y = (double *)malloc(*count * sizeof(double));
    if (px_checkpoint_read(ck, "lattice.state", PX_DTYPE_F64, *count, y) != PX_STATUS_OK) {
      free(y);
      y = NULL;
    }
  }
  px_checkpoint_close(ck);
  return y;
}

static void test_resume(struct px_context *ctx, const char *prec, const char *integ,
                        const char *qs) {
  struct opts o = defaults("lt_solver_full");
  struct px_sim *sim = NULL;
  double *a, *b;
  uint64_t na = 0, nb = 0;
  const char *more[] = {"time.steps=60"};
  o.prec = prec;
  o.integ = integ;
  o.qs = qs;
  o.steps = 60;
  o.every = 30;
  /* uninterrupted run of 60 steps */
  PX_CHECK_OK(ctx, make_sim(ctx, &o, NULL, 0, &sim));
  if (sim) PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  /* 30 steps, then resume from the checkpoint to 60 */
  o.dir = "lt_solver_half";
  o.steps = 30;
  PX_CHECK_OK(ctx, make_sim(ctx, &o, NULL, 0, &sim));
  if (sim) PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  sim = NULL;
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "lt_solver_half/checkpoint.pxc", more, 1, &sim));
  if (sim) {
    px_sim_set_progress(sim, NULL, 0);
    PX_CHECK_OK(ctx, px_sim_run(sim));
    PX_CHECK(px_sim_step_index(sim) == 60);
  }
  px_sim_free(sim);
  a = read_state(ctx, "lt_solver_full", &na);
  b = read_state(ctx, "lt_solver_half", &nb);
  PX_CHECK(a && b && na == nb && na > 0);
  if (a && b && na == nb) {
    uint64_t i, differ = 0;
    double umax = 0.0;
    for (i = 0; i < na; ++i) {
      if (memcmp(&a[i], &b[i], sizeof(double)) != 0) ++differ;
      if (i % 13 < 3) umax = fmax(umax, fabs(a[i]));
    }
    printf("resume %s %s quasi_static=%s: %llu of %llu values differ (max |u| %.3g m)\n", prec,
           integ, qs, (unsigned long long)differ, (unsigned long long)na, umax);
    PX_CHECK(differ == 0);
    PX_CHECK(umax > 0.0);
  }
  free(a);
  free(b);
}

/* The first size - 1 bytes of the file at path, NUL-terminated; 0 if it
 * cannot be read. */
static int read_head(const char *path, char *buf, size_t size) {
  FILE *f = fopen(path, "rb");
  size_t got;
  if (!f) return 0;
  got = fread(buf, 1, size - 1, f);
  fclose(f);
  buf[got] = '\0';
  return 1;
}

/* A body that does not fill its bounding box (a 2 x 2 mm hole through the
 * 12 x 4 x 3 mm bar) is written as voxels (.vtu): its 144 - 12 elements on
 * their 13 x 5 x 4 - 4 shared corners (the 4 corners inside the hole go). */
static void test_outputs_vtu(struct px_context *ctx) {
  struct opts o = defaults("lt_solver_vtu");
  struct px_sim *sim = NULL;
  char head[2048];
  o.extra_body =
      "    - {type: box, min: [0.005, 0.001, 0], max: [0.007, 0.003, 0.003], "
      "op: difference}\n";
  remove("lt_solver_vtu/probes.png"); /* of an earlier run of this test */
  remove("lt_solver_vtu/von_mises_000040.png");
  PX_CHECK_OK(ctx, make_sim(ctx, &o, NULL, 0, &sim));
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  PX_CHECK(file_exists("lt_solver_vtu", "lattice_000040.vtu"));
  PX_CHECK(!file_exists("lt_solver_vtu", "lattice_000040.vti"));
  /* output.png: false draws neither pictures nor plots */
  PX_CHECK(!file_exists("lt_solver_vtu", "von_mises_000040.png"));
  PX_CHECK(!file_exists("lt_solver_vtu", "probes.png"));
  PX_CHECK(read_head("lt_solver_vtu/lattice_000040.vtu", head, sizeof head));
  PX_CHECK_MSG(strstr(head, "NumberOfPoints=\"256\"") && strstr(head, "NumberOfCells=\"132\""),
               "header: %.400s", head);
  PX_CHECK(strstr(head, "Name=\"von_mises\"") != NULL);
  PX_CHECK(strstr(head, "<PointData") != NULL); /* the corner displacement */
  PX_CHECK(read_head("lt_solver_vtu/lattice.pvd", head, sizeof head));
  PX_CHECK(strstr(head, "lattice_000040.vtu") != NULL);
}

static void test_resume_keys(struct px_context *ctx) {
  const char *ok[] = {"time.steps=70", "lattice.picture.view=top", "lattice.picture.scale=100",
                      "lattice.static_tolerance=1e-3"};
  const char *bad[] = {"time.steps=70", "lattice.E=1e11"};
  struct px_sim *sim = NULL;
  enum px_status st;
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "lt_solver_half/checkpoint.pxc", ok, 4, &sim));
  px_sim_free(sim);
  sim = NULL;
  px_context_clear(ctx);
  st = px_sim_resume(ctx, "lt_solver_half/checkpoint.pxc", bad, 2, &sim);
  PX_CHECK_MSG(st == PX_STATUS_CONFIG && strstr(px_context_message(ctx), "lattice.E cannot change"),
               "status %s: %s", px_status_name(st), px_context_message(ctx));
  PX_CHECK(strstr(px_context_message(ctx), "lattice.picture") != NULL);
  px_sim_free(sim);
  px_context_clear(ctx);
}

int main(void) {
  struct px_context *ctx;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  test_errors(ctx);
  test_blowup(ctx);
  test_outputs(ctx);
  test_outputs_vtu(ctx);
  test_final_state(ctx);
  test_render(ctx);
  test_resume(ctx, "double", "rk4", "false");
  test_resume(ctx, "single", "rk4", "false");
  test_resume(ctx, "single", "leapfrog", "true");
  test_resume_keys(ctx);
  px_context_free(ctx);
  px_test_release_fonts(); /* the probe plot drew text */
  return px_test_report("test_lattice_solver");
}
