/* The granular solver through the run driver: a resumed run is
 * bit-identical to an uninterrupted one (cpu, same threads); bad input gives
 * clear errors (overlaps, particles outside, open contours, e > 1, negative
 * stiffness, dt above the stability limit, escapes, non-finite values);
 * the outputs exist and agree with the state; the engines are named as
 * their backends and say what they can (abm4 on cpu only, host threads as
 * the cpu backend's). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "granular_test_util.h"
#include "io/px_test_fonts.h"
#include "partix/checkpoint.h"
#include "partix/sim.h"
#include "solvers/granular/granular_engine.h"

static const char *const base_case =
    "solver: granular\n"
    "backend: {type: cpu, threads: 2, precision: mixed}\n"
    "time: {steps: 6000}\n"
    "output: {dir: out_solver, every: 1000, png_every: 6000, log_every: 100}\n"
    "granular:\n"
    "  settle: 0.0\n"
    "  media:\n"
    "    count: 300\n"
    "    radius: {distribution: uniform, min: 0.0018, max: 0.0022}\n"
    "    density: 7800\n"
    "    thickness: 0.004\n"
    "    fill: lattice\n"
    "  contact: {kn: 2e5, restitution: 0.6, friction: 0.4}\n"
    "  bodies:\n"
    "    - name: container\n"
    "      motion: {type: harmonic, amplitude: [0.002, 0.002], frequency: 60, phase: [0, 90], "
    "ramp: 0.002}\n"
    "  contours:\n"
    "    - {name: box, body: container, shape: {type: rectangle, min: [0, 0], max: [0.1, "
    "0.1]}, report: false}\n"
    "    - {name: part, body: container, shape: {type: circle, center: [0.05, 0.025], radius: "
    "0.008}}\n";

static enum px_status run_case(struct px_context *ctx, const char *text, const char *const *ov,
                               size_t nov) {
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  enum px_status st = px_case_load_string(ctx, "case.yaml", text, strlen(text), ov, nov, &c);
  if (st != PX_STATUS_OK) return st;
  px_test_fresh_case_dir(c); /* a new run each time */
  st = px_sim_create(ctx, c, PX_SIM_MODE_RUN, &sim);
  if (st == PX_STATUS_OK) {
    px_sim_set_progress(sim, NULL, 0);
    st = px_sim_run(sim);
  }
  px_sim_free(sim);
  return st;
}

/* Read a section of a checkpoint as bytes. */
static unsigned char *section(struct px_checkpoint *ck, const char *name, uint64_t *bytes) {
  enum px_dtype type;
  uint64_t count;
  unsigned char *data;
  if (px_checkpoint_find(ck, name, &type, &count) != PX_STATUS_OK) return NULL;
  *bytes = count * px_dtype_size(type);
  data = malloc((size_t)*bytes + 1);
  if (data && px_checkpoint_read(ck, name, type, count, data) != PX_STATUS_OK) {
    free(data);
    return NULL;
  }
  return data;
}

static void test_resume_is_bit_identical(struct px_context *ctx) {
  const char *full[] = {"output.dir=out_solver_full"};
  const char *part[] = {"output.dir=out_solver_part", "time.steps=3500"};
  const char *more[] = {"time.steps=6000"};
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  struct px_checkpoint *a = NULL, *b = NULL;
  const char *names[] = {"granular.p.x",        "granular.p.y",     "granular.p.vx",
                         "granular.p.vy",       "granular.p.w",     "granular.p.fx",
                         "granular.p.id",       "granular.pxi",     "granular.pj",
                         "granular.stats.0",    "granular.stats.5", "granular.stats.8",
                         "granular.p.slots.xi", "granular.scalars"};
  size_t k;
  PX_CHECK_OK(ctx, run_case(ctx, base_case, full, 1));
  PX_CHECK_OK(ctx, run_case(ctx, base_case, part, 2));
  /* resume the partial run to the same end */
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "out_solver_part/checkpoint.pxc", more, 1, &sim));
  if (sim) {
    px_sim_set_progress(sim, NULL, 0);
    PX_CHECK_OK(ctx, px_sim_run(sim));
    px_sim_free(sim);
  }
  (void)c;
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, "out_solver_full/checkpoint.pxc", &a));
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, "out_solver_part/checkpoint.pxc", &b));
  if (!a || !b) {
    px_checkpoint_close(a);
    px_checkpoint_close(b);
    return;
  }
  PX_CHECK(px_checkpoint_step(a) == 6000 && px_checkpoint_step(b) == 6000);
  {
    /* the run really had contacts with walls, impacts on the part and rebuilds */
    uint64_t nb = 0, ns = 0, k2;
    double *sc = (double *)(void *)section(a, "granular.scalars", &nb);
    double *imp = (double *)(void *)section(a, "granular.stats.0", &ns);
    double total = 0;
    for (k2 = 0; imp && k2 < ns / sizeof(double); ++k2) total += imp[k2];
    PX_CHECK_MSG(sc && sc[3] >= 5, "rebuilds: %g", sc ? sc[3] : -1.0);
    PX_CHECK_MSG(total >= 20, "impacts on the part: %g", total);
    free(sc);
    free(imp);
  }
  for (k = 0; k < sizeof names / sizeof names[0]; ++k) {
    uint64_t na = 0, nb = 0;
    unsigned char *da = section(a, names[k], &na), *db = section(b, names[k], &nb);
    PX_CHECK_MSG(da && db && na == nb && memcmp(da, db, (size_t)na) == 0,
                 "section %s differs after resume", names[k]);
    free(da);
    free(db);
  }
  px_checkpoint_close(a);
  px_checkpoint_close(b);
}

/* The same with two threads: 4200 small discs (two threads need > 4096),
 * resumed after 700 of 1200 steps. */
static void test_resume_two_threads_is_bit_identical(struct px_context *ctx) {
  const char *common[] = {"granular.media.count=4200",
                          "granular.media.radius={distribution: uniform, min: 0.0006, max: 0.0007}",
                          "output.every=300",
                          "output.png_every=1200",
                          "granular.gravity=[0, -200]",
                          "granular.bodies[0].motion.amplitude=[0.001, 0.001]",
                          "granular.bodies[0].motion.frequency=400"};
  const char *full[9], *part[9], *more[] = {"time.steps=1200"};
  const char *names[] = {"granular.p.x",     "granular.p.y",     "granular.p.vx",   "granular.p.vy",
                         "granular.p.w",     "granular.p.id",    "granular.pxi",    "granular.pj",
                         "granular.stats.0", "granular.stats.5", "granular.scalars"};
  struct px_sim *sim = NULL;
  struct px_checkpoint *a = NULL, *b = NULL;
  size_t k;
  for (k = 0; k < 7; ++k) full[k] = part[k] = common[k];
  full[7] = "output.dir=out_solver_full2", full[8] = "time.steps=1200";
  part[7] = "output.dir=out_solver_part2", part[8] = "time.steps=700";
  PX_CHECK_OK(ctx, run_case(ctx, base_case, full, 9));
  PX_CHECK_OK(ctx, run_case(ctx, base_case, part, 9));
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "out_solver_part2/checkpoint.pxc", more, 1, &sim));
  if (sim) {
    px_sim_set_progress(sim, NULL, 0);
    PX_CHECK_OK(ctx, px_sim_run(sim));
    px_sim_free(sim);
  }
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, "out_solver_full2/checkpoint.pxc", &a));
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, "out_solver_part2/checkpoint.pxc", &b));
  if (a && b) {
    uint64_t nb = 0;
    double *sc = (double *)(void *)section(a, "granular.scalars", &nb);
    double *xs = (double *)(void *)section(a, "granular.p.x", &nb);
    PX_CHECK(px_checkpoint_step(a) == 1200 && px_checkpoint_step(b) == 1200);
    PX_CHECK_MSG(xs && nb == 4200 * sizeof(double), "discs: %g", (double)nb / sizeof(double));
    PX_CHECK_MSG(sc && sc[3] >= 3, "rebuilds: %g", sc ? sc[3] : -1.0);
    free(sc);
    free(xs);
    for (k = 0; k < sizeof names / sizeof names[0]; ++k) {
      uint64_t na = 0, nb2 = 0;
      unsigned char *da = section(a, names[k], &na), *db = section(b, names[k], &nb2);
      PX_CHECK_MSG(da && db && na == nb2 && memcmp(da, db, (size_t)na) == 0,
                   "section %s differs after resume (2 threads)", names[k]);
      free(da);
      free(db);
    }
  }
  px_checkpoint_close(a);
  px_checkpoint_close(b);
}

/* The case text with one line replaced (or appended under granular:). */
static enum px_status run_with(struct px_context *ctx, const char *const *ov, size_t nov) {
  return run_case(ctx, base_case, ov, nov);
}

static void expect_error(struct px_context *ctx, const char *const *ov, size_t nov,
                         enum px_status status, const char *needle) {
  const enum px_status st = run_with(ctx, ov, nov);
  PX_CHECK_MSG(st == status, "%s: got %s: %s", ov[0], px_status_name(st), px_context_message(ctx));
  PX_CHECK_MSG(strstr(px_context_message(ctx), needle) != NULL, "message \"%s\" lacks \"%s\"",
               px_context_message(ctx), needle);
  px_context_clear(ctx);
}

static void test_bad_input_is_reported(struct px_context *ctx) {
  {
    const char *ov[] = {"granular.contact.restitution=1.2"};
    expect_error(ctx, ov, 1, PX_STATUS_CONFIG, "granular.contact.restitution");
  }
  {
    const char *ov[] = {"granular.contact.kn=-5"};
    expect_error(ctx, ov, 1, PX_STATUS_CONFIG, "granular.contact.kn");
  }
  {
    const char *ov[] = {"time.dt=1e-4"};
    expect_error(ctx, ov, 1, PX_STATUS_CONFIG, "stability limit");
  }
  {
    /* an open path */
    const char *ov[] = {
        "granular.contours[1].shape={type: path, pieces: [{type: line, from: "
        "[0.04, 0.02], to: [0.06, 0.02]}, {type: line, from: [0.06, 0.02], to: "
        "[0.05, 0.04]}]}"};
    expect_error(ctx, ov, 1, PX_STATUS_CONFIG, "open");
  }
  {
    /* too many discs for the box */
    const char *ov[] = {"granular.media.count=5000"};
    expect_error(ctx, ov, 1, PX_STATUS_CONFIG, "granular.media");
  }
  {
    /* a contour naming a body that does not exist */
    const char *ov[] = {"granular.contours[1].body=lid"};
    expect_error(ctx, ov, 1, PX_STATUS_CONFIG, "no body named 'lid'");
  }
  {
    /* two contours crossing each other */
    const char *ov[] = {
        "granular.contours[1].shape={type: circle, center: [0.0, 0.05], radius: "
        "0.02}"};
    expect_error(ctx, ov, 1, PX_STATUS_CONFIG, "cross");
  }
}

static void test_system_errors(struct px_context *ctx) {
  struct px_gran_geom g;
  struct px_gran_sys *s = NULL;
  const double R = 0.002, M = 1.26e-4;
  px_gran_geom_init(&g);
  PX_CHECK_OK(ctx, gt_rect(ctx, &g, 0, 0, 0.05, 0.05, R, 0, "box"));
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 4 * R));
  {
    /* overlapping initial particles */
    double x[2] = {0.02, 0.023}, y[2] = {0.02, 0.02}, r[2] = {R, R}, m[2] = {M, M};
    PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s));
    gt_law(&s->pp, 2e5, 0.5, 0.3);
    gt_law(&s->pw, 2e5, 0.5, 0.3);
    px_gran_sys_set_walls(s, &g, NULL, 0);
    px_gran_sys_add(s, 2, x, y, r, m);
    PX_CHECK_STATUS(ctx, px_gran_sys_prepare(s, 0, 50), PX_STATUS_CONFIG);
    PX_CHECK(strstr(px_context_message(ctx), "overlap") != NULL);
    px_gran_sys_free(s);
  }
  {
    /* a particle outside the container */
    double x[2] = {0.02, 0.07}, y[2] = {0.02, 0.02}, r[2] = {R, R}, m[2] = {M, M};
    PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s));
    gt_law(&s->pp, 2e5, 0.5, 0.3);
    gt_law(&s->pw, 2e5, 0.5, 0.3);
    px_gran_sys_set_walls(s, &g, NULL, 0);
    px_gran_sys_add(s, 2, x, y, r, m);
    PX_CHECK_STATUS(ctx, px_gran_sys_prepare(s, 0, 50), PX_STATUS_CONFIG);
    PX_CHECK(strstr(px_context_message(ctx), "particle 1") != NULL &&
             strstr(px_context_message(ctx), "outside") != NULL);
    px_gran_sys_free(s);
  }
  {
    /* a particle shot through the wall: stopped with a diagnosis */
    double x = 0.025, y = 0.01, r = R, m = M;
    long k;
    enum px_status st = PX_STATUS_OK;
    PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s));
    gt_law(&s->pp, 2e3, 0.5, 0.3);
    gt_law(&s->pw, 2e3, 0.5, 0.3); /* soft walls */
    px_gran_sys_set_walls(s, &g, NULL, 0);
    px_gran_sys_add(s, 1, &x, &y, &r, &m);
    px_gran_sys_set_velocity(s, 0, 0, -300, 0);
    PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
    for (k = 0; k < 100000 && st == PX_STATUS_OK; ++k) st = px_gran_sys_step(s);
    PX_CHECK(st == PX_STATUS_NUMERIC);
    PX_CHECK_MSG(strstr(px_context_message(ctx), "passed through contour 'box'") != NULL, "%s",
                 px_context_message(ctx));
    px_gran_sys_free(s);
  }
  {
    /* a non-finite velocity */
    double x = 0.025, y = 0.025, r = R, m = M;
    long k;
    enum px_status st = PX_STATUS_OK;
    PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s));
    gt_law(&s->pp, 2e5, 0.5, 0.3);
    gt_law(&s->pw, 2e5, 0.5, 0.3);
    px_gran_sys_set_walls(s, &g, NULL, 0);
    px_gran_sys_add(s, 1, &x, &y, &r, &m);
    PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
    px_gran_sys_set_velocity(s, 0, NAN, 0, 0);
    for (k = 0; k < 1000 && st == PX_STATUS_OK; ++k) st = px_gran_sys_step(s);
    PX_CHECK(st == PX_STATUS_NUMERIC);
    PX_CHECK(strstr(px_context_message(ctx), "non-finite") != NULL);
    px_gran_sys_free(s);
  }
  px_gran_geom_free(ctx, &g);
}

static void test_outputs_exist_and_agree(void) {
  /* the segment table of the part sums the statistics of the system */
  FILE *f = fopen("out_solver_full/segments_part.csv", "r");
  char line[4096];
  size_t rows = 0;
  PX_CHECK(f != NULL);
  if (!f) return;
  while (fgets(line, sizeof line, f)) ++rows;
  fclose(f);
  PX_CHECK(rows > 10); /* header + one row per segment */
  PX_CHECK(px_file_exists("out_solver_full/particles.pvd"));
  PX_CHECK(px_file_exists("out_solver_full/walls.pvd"));
  PX_CHECK(px_file_exists("out_solver_full/media.csv"));
  PX_CHECK(px_file_exists("out_solver_full/speed_histogram.csv"));
  PX_CHECK(px_file_exists("out_solver_full/part_energy_n_area.png"));
  PX_CHECK(px_file_exists("out_solver_full/particles_00006000.png"));
  PX_CHECK(px_file_exists("out_solver_full/contours.vtp"));
}

/* The base case with `from` replaced by `to` (the first occurrence): the
 * error must point at the line of the edit in the case file, and name the
 * key. */
static void expect_located(struct px_context *ctx, const char *text, const char *from,
                           const char *to, const char *key, const char *needle) {
  char buf[4096], prefix[64];
  const char *at = strstr(text, from), *p;
  int line = 1;
  enum px_status st;
  PX_CHECK_MSG(at != NULL, "'%s' not in the case", from);
  if (!at) return;
  for (p = text; p < at; ++p) line += *p == '\n';
  snprintf(buf, sizeof buf, "%.*s%s%s", (int)(at - text), text, to, at + strlen(from));
  st = run_case(ctx, buf, NULL, 0);
  snprintf(prefix, sizeof prefix, "case.yaml:%d:", line);
  PX_CHECK_MSG(st == PX_STATUS_CONFIG, "%s: got %s: %s", to, px_status_name(st),
               px_context_message(ctx));
  PX_CHECK_MSG(strstr(px_context_message(ctx), prefix) != NULL &&
                   strstr(px_context_message(ctx), key) != NULL &&
                   strstr(px_context_message(ctx), needle) != NULL,
               "message \"%s\" lacks \"%s\", \"%s\" or \"%s\"", px_context_message(ctx), prefix,
               key, needle);
  px_context_clear(ctx);
}

/* Errors written in the case file itself read FILE:LINE:COL: key: what. */
static void test_bad_input_is_located(struct px_context *ctx) {
  expect_located(ctx, base_case, "restitution: 0.6", "restitution: 1.2",
                 "granular.contact.restitution", "1.2");
  expect_located(ctx, base_case, "kn: 2e5", "kn: -2e5", "granular.contact.kn", "");
  expect_located(ctx, base_case, "time: {steps: 6000}", "time: {steps: 6000, dt: 1e-4}", "time.dt",
                 "stability limit");
  expect_located(ctx, base_case, "{type: circle, center: [0.05, 0.025], radius: 0.008}",
                 "{type: path, pieces: [{type: line, from: [0.04, 0.02], to: [0.06, 0.02]}, "
                 "{type: line, from: [0.06, 0.02], to: [0.05, 0.04]}]}",
                 "granular.contours[1].shape", "open");
  /* discs placed one by one: overlapping, outside the container, inside the
   * part; each error names the row */
  expect_located(
      ctx, base_case, "    count: 300\n",
      "    particles: [[0.02, 0.06, 0.002], [0.03, 0.06, 0.002], [0.0335, 0.06, 0.002]]\n",
      "granular.media.particles[2]", "overlap");
  expect_located(ctx, base_case, "    count: 300\n",
                 "    particles: [[0.02, 0.06, 0.002], [0.03, 0.06, 0.002], [0.13, 0.06, 0.002]]\n",
                 "granular.media.particles[2]", "outside");
  expect_located(ctx, base_case, "    count: 300\n",
                 "    particles: [[0.02, 0.06, 0.002], [0.05, 0.026, 0.002]]\n",
                 "granular.media.particles[1]", "outside");
  expect_located(ctx, base_case, "    count: 300\n",
                 "    particles: [[0.02, 0.06, 0.002], [0.03, 0.0985, 0.002]]\n",
                 "granular.media.particles[1]", "overlaps a boundary");
  expect_located(ctx, base_case, "    count: 300\n",
                 "    particles: [[0.02, 0.06, 0.002], [0.03, 0.06, -0.002]]\n",
                 "granular.media.particles[1]", "radius");
  expect_located(ctx, base_case, "  media:\n    count: 300\n",
                 "  media:\n    count: 300\n    fraction: 0.3\n", "granular.media", "exactly one");
}

/* Discs placed by hand with velocities: they move as given; one shot at a
 * soft wall passes through it, and the run stops with the diagnosis, the
 * step and the last good checkpoint to resume from. */
static void test_listed_particles_and_escape(struct px_context *ctx) {
  char buf[4096];
  const char *from = "    count: 300\n", *at = strstr(base_case, from);
  const char *ok[] = {"output.dir=out_solver_listed", "time.steps=200",
                      "granular.bodies[0].motion={type: fixed}", "granular.gravity=[0, 0]"};
  const char *esc[] = {"output.dir=out_solver_escape", "time.steps=400",
                       "output.checkpoint_every=5", "granular.contact.kn=2e3",
                       "granular.bodies[0].motion={type: fixed}"};
  struct px_checkpoint *ck = NULL;
  enum px_status st;
  if (!at) return;
  /* disc 0 at rest, disc 1 moving right at 0.5 m/s, far from everything */
  snprintf(buf, sizeof buf, "%.*s%s%s", (int)(at - base_case), base_case,
           "    particles: [[0.02, 0.06, 0.002], [0.03, 0.07, 0.002, 0.5, 0, 3]]\n",
           at + strlen(from));
  PX_CHECK_OK(ctx, run_case(ctx, buf, ok, 4));
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, "out_solver_listed/checkpoint.pxc", &ck));
  if (ck) {
    uint64_t nb = 0, nid = 0;
    double *xs = (double *)(void *)section(ck, "granular.p.x", &nb);
    int32_t *ids = (int32_t *)(void *)section(ck, "granular.p.id", &nid);
    double dtv = 0;
    size_t k;
    PX_CHECK(xs && ids && nb == 2 * sizeof(double));
    for (k = 0; xs && ids && k < 2; ++k) {
      /* x = x0 + vx t after 200 steps */
      dtv = px_checkpoint_time(ck) / 200.0;
      if (ids[k] == 0) PX_CHECK_NEAR(xs[k], 0.02, 1e-15);
      if (ids[k] == 1) PX_CHECK_REL(xs[k], 0.03 + 0.5 * 200 * dtv, 1e-12);
    }
    free(xs);
    free(ids);
    px_checkpoint_close(ck);
  }
  snprintf(buf, sizeof buf, "%.*s%s%s", (int)(at - base_case), base_case,
           "    particles: [[0.05, 0.06, 0.002], [0.05, 0.08, 0.002, 0, 60]]\n", at + strlen(from));
  st = run_case(ctx, buf, esc, 5);
  PX_CHECK_MSG(st == PX_STATUS_NUMERIC, "escape: got %s: %s", px_status_name(st),
               px_context_message(ctx));
  PX_CHECK_MSG(strstr(px_context_message(ctx), "passed through contour 'box'") != NULL &&
                   strstr(px_context_message(ctx), "step ") != NULL &&
                   strstr(px_context_message(ctx), "last good checkpoint") != NULL &&
                   strstr(px_context_message(ctx), "out_solver_escape/checkpoint.pxc") != NULL,
               "escape: %s", px_context_message(ctx));
  {
    /* one step named, the one whose state is checked (was "step 28 (t =
     * ...): step 27 (t = ...): particle ...": the runner's step and the
     * rebuild's) */
    const char *m = px_context_message(ctx), *nl = strchr(m, '\n'), *p;
    int steps = 0;
    for (p = strstr(m, "step "); p && (!nl || p < nl); p = strstr(p + 1, "step "))
      steps += p[5] >= '0' && p[5] <= '9';
    PX_CHECK_MSG(steps == 1 && strstr(m, " at step "), "escape: %d steps named: %s", steps, m);
  }
  px_context_clear(ctx);
}

/* The engine table: each engine carries its backend's name (what
 * PX_BACKEND_PICK matches) and answers the capability query: the cpu
 * engine runs abm4 and double, with the backend's threads; the opencl
 * engine refuses abm4 (and says why) and runs its host loops on one
 * thread. */
static void test_engines_say_what_they_can(struct px_context *ctx) {
  struct px_backend *be = NULL;
  struct px_gran_caps caps;
  PX_CHECK(strcmp(px_gran_engine_cpu.name, "cpu") == 0);
  PX_CHECK(strcmp(px_gran_engine_opencl.name, "opencl") == 0);
  PX_CHECK_OK(ctx, px_backend_create(ctx, "cpu", 0, 2, &be));
  if (be) {
    memset(&caps, 0, sizeof caps);
    px_gran_engine_cpu.caps(be, &caps);
    PX_CHECK(caps.abm4 == 1 && caps.fp64 == 1 && caps.why_no_abm4 == NULL);
    PX_CHECK_MSG(caps.host_threads == px_backend_threads(be), "host threads %d, backend %d",
                 caps.host_threads, px_backend_threads(be));
    px_backend_free(be);
    be = NULL;
  }
  if (px_backend_opencl_device_count(ctx) > 0 &&
      px_backend_create(ctx, "opencl", 0, 0, &be) == PX_STATUS_OK) {
    memset(&caps, 0, sizeof caps);
    px_gran_engine_opencl.caps(be, &caps);
    PX_CHECK(caps.abm4 == 0 && caps.host_threads == 1);
    PX_CHECK(caps.why_no_abm4 && strstr(caps.why_no_abm4, "Verlet") != NULL);
    px_backend_free(be);
  }
  px_context_clear(ctx);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  test_engines_say_what_they_can(ctx);
  test_system_errors(ctx);
  test_resume_is_bit_identical(ctx);
  test_resume_two_threads_is_bit_identical(ctx);
  test_outputs_exist_and_agree();
  test_bad_input_is_reported(ctx);
  test_bad_input_is_located(ctx);
  test_listed_particles_and_escape(ctx);
  px_context_free(ctx);
  px_test_release_fonts(); /* LeakSanitizer: only real leaks */
  return px_test_report("test_granular_solver");
}
