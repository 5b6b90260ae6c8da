/* Hostile input to the granular solver (issue 19): what used to crash, hang,
 * read out of bounds or allocate gigabytes is refused with a message that
 * says where (the case key as FILE:LINE:COL, or the DXF file and line, or
 * the checkpoint section) and with the figures, before anything large is
 * allocated or any unbounded loop runs:
 *  - contours of huge extent (1e308: a cast of inf to size_t; 2.5e16: a
 *    capacity doubling that wrapped to 0 and looped for ever);
 *  - a DXF drawing that would need gigabytes of segments, files that are
 *    not regular files (DXF entities with absurd values: the reader's own
 *    test, tests/io/test_geometry_dxf.c);
 *  - sizes beyond what runs (discs, stiffness without a time step, a skin of
 *    kilometres, discs piled on one spot), at their keys;
 *  - a non-finite disc, found at the step it appears;
 *  - checkpoints with right CRCs and forged contents (indices, counts and
 *    scalars out of range, NaN, radii not the case's): each refused, naming
 *    its section (run under ASan too: label sanitize). */
#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "granular_test_util.h"
#include "px_test_ck.h"
#include "granular_test_util.h"
#include "io/geometry/geo_dxf.h"
#include "io/px_test_fonts.h"
#include "partix/checkpoint.h"
#include "partix/memory.h"
#include "partix/sim.h"

/* A small box with a round part; discs settle on the floor so that the
 * checkpoint has pairs, wall candidates and wall contacts. */
static const char *const base_case =
    "solver: granular\n"
    "backend: {type: cpu, threads: 1, precision: double}\n"
    "time: {steps: 500}\n"
    "output: {dir: out_hostile, every: 500, png_every: 500, log_every: 100}\n"
    "granular:\n"
    "  settle: 0.0\n"
    "  gravity: [0, -10000]\n"
    "  media:\n"
    "    count: 60\n"
    "    radius: {distribution: uniform, min: 0.0018, max: 0.0022}\n"
    "    density: 7800\n"
    "    thickness: 0.004\n"
    "  contact: {kn: 2e5, restitution: 0.6, friction: 0.4}\n"
    "  bodies:\n"
    "    - name: container\n"
    "      motion: {type: fixed}\n"
    "  contours:\n"
    "    - {name: box, body: container, shape: {type: rectangle, min: [0, 0], max: [0.05, "
    "0.05]}, report: false}\n"
    "    - {name: part, body: container, shape: {type: circle, center: [0.025, 0.03], radius: "
    "0.005}}\n";

/* The case built (not run) with overrides: its status. */
static enum px_status check_case(struct px_context *ctx, const char *text, const char *const *ov,
                                 size_t nov) {
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  enum px_status st = px_case_load_string(ctx, "case.yaml", text, strlen(text), ov, nov, &c);
  if (st != PX_STATUS_OK) return st;
  st = px_sim_create(ctx, c, PX_SIM_MODE_CHECK, &sim);
  px_sim_free(sim);
  return st;
}

/* The case with overrides is refused (CONFIG) at `key`, saying `needle`,
 * without allocating more than 64 MiB on the way. */
static void expect_refused_n(struct px_context *ctx, const char *const *ov, size_t nov,
                             const char *key, const char *needle) {
  const size_t before = px_mem_peak(ctx, NULL);
  const enum px_status st = check_case(ctx, base_case, ov, nov);
  const char *m = px_context_message(ctx);
  PX_CHECK_MSG(st == PX_STATUS_CONFIG, "%s: got %s: %s", ov[nov - 1], px_status_name(st), m);
  PX_CHECK_MSG(strstr(m, key) != NULL && strstr(m, needle) != NULL,
               "%s: message \"%s\" lacks \"%s\" or \"%s\"", ov[nov - 1], m, key, needle);
  PX_CHECK_MSG(px_mem_peak(ctx, NULL) <= before + (64u << 20), "%s: peak %zu bytes", ov[nov - 1],
               px_mem_peak(ctx, NULL));
  px_context_clear(ctx);
}

static void expect_refused(struct px_context *ctx, const char *ov, const char *key,
                           const char *needle) {
  expect_refused_n(ctx, &ov, 1, key, needle);
}

/* ------------------------------------------------------------------ geometry */

static void test_huge_contours_are_refused_at_their_key(struct px_context *ctx) {
  /* was: (size_t)ceil(inf) and a heap overflow (segfault) */
  expect_refused(ctx, "granular.contours[0].shape.max=[1e308, 1e308]",
                 "case.yaml:18:", "beyond 1e+12 m");
  /* was: the segment capacity doubled to 0 and the split looped for ever */
  expect_refused(ctx, "granular.contours[0].shape.max=[2.5e16, 0.16]", "granular.contours[0].shape",
                 "beyond 1e+12 m");
  /* within the coordinate bound, but 1.1e9 segments of 1.8 mm */
  expect_refused(ctx, "granular.contours[0].shape.max=[1e6, 0.05]", "granular.contours[0].shape",
                 "1.111e+09 segments");
  /* few segments (a coarse segment length), but a box of 1e11 disc
   * diameters */
  {
    const char *ov[] = {"granular.segment_length=100000",
                        "granular.contours[0].shape.max=[4e8, 4e8]"};
    const enum px_status st = check_case(ctx, base_case, ov, 2);
    PX_CHECK_MSG(st == PX_STATUS_CONFIG &&
                     strstr(px_context_message(ctx), "granular.contours[0].shape") &&
                     strstr(px_context_message(ctx), "diameters"),
                 "%s: %s", px_status_name(st), px_context_message(ctx));
    px_context_clear(ctx);
  }
  /* an arc piece sweeping two turns would trace the circle twice */
  expect_refused(ctx,
                 "granular.contours[1].shape={type: path, pieces: [{type: arc, center: [0.025, "
                 "0.03], radius: 0.005, start: 0, end: 720}]}",
                 "granular.contours[1].shape", "more than one turn");
}

/* The case with `from` replaced by `to` (once) is refused (CONFIG) with a
 * message holding each of needles[0..n-1]. */
static void expect_edit_refused(struct px_context *ctx, const char *from, const char *to,
                                const char *const *needles, size_t n) {
  char text[4096];
  const char *at = strstr(base_case, from);
  enum px_status st;
  size_t k;
  PX_CHECK(at != NULL);
  if (!at) return;
  snprintf(text, sizeof text, "%.*s%s%s", (int)(at - base_case), base_case, to, at + strlen(from));
  st = check_case(ctx, text, NULL, 0);
  PX_CHECK_MSG(st == PX_STATUS_CONFIG, "%s: got %s: %s", to, px_status_name(st),
               px_context_message(ctx));
  for (k = 0; k < n; ++k)
    PX_CHECK_MSG(strstr(px_context_message(ctx), needles[k]) != NULL,
                 "%s: message \"%s\" lacks \"%s\"", to, px_context_message(ctx), needles[k]);
  px_context_clear(ctx);
}

/* Two contours of one name wrote one segments_NAME.csv (the other's rows
 * lost), media.csv had force_x_NAME twice and summary.json one NAME.* set:
 * the second is refused at its name. */
static void test_duplicate_contour_names_are_refused(struct px_context *ctx) {
  static const char *const in_file[] = {"case.yaml:19:", "granular.contours[1].name",
                                        "a contour named 'box' already exists"};
  expect_edit_refused(ctx, "{name: part,", "{name: box,", in_file, 3);
  expect_refused(ctx, "granular.contours[1].name=box", "granular.contours[1].name",
                 "a contour named 'box' already exists");
  /* equal in summary.json, which writes '.' and '-' as '_' */
  {
    const char *ov[] = {"granular.contours[0].name=a.b", "granular.contours[1].name=a_b"};
    expect_refused_n(ctx, ov, 2, "granular.contours[1].name",
                     "contour 'a_b' and contour 'a.b' give the same summary.json keys");
  }
  /* names that differ are still taken */
  {
    const char *ov[] = {"granular.contours[1].name=box2"};
    PX_CHECK_OK(ctx, check_case(ctx, base_case, ov, 1));
  }
}

/* ------------------------------------------------------------------ motion */

/* The warnings of a check, joined. */
struct warnings {
  char text[4096];
  int n;
};

static void collect_warning(void *user, enum px_log_level level, const char *message) {
  struct warnings *w = user;
  if (level != PX_LOG_LEVEL_WARN) return;
  ++w->n;
  strncat(w->text, message, sizeof w->text - strlen(w->text) - 1);
  strncat(w->text, "\n", sizeof w->text - strlen(w->text) - 1);
}

/* The case with override `ov` checks (OK); *w gets its warnings. */
static void check_warnings(struct px_context *ctx, const char *ov, struct warnings *w) {
  px_log_fn fn;
  void *user;
  enum px_log_level level = px_context_log_level(ctx);
  memset(w, 0, sizeof *w);
  px_context_get_log(ctx, &fn, &user);
  px_context_set_log(ctx, collect_warning, w);
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  PX_CHECK_OK(ctx, check_case(ctx, base_case, &ov, 1));
  px_context_set_log(ctx, fn, user);
  px_context_set_log_level(ctx, level);
}

/* A harmonic motion with a phase and no ramp started with the walls
 * displaced by A sin(phase) in one step (discs thrown, with A = 1 m all
 * lost through the walls, the run "finished" with 0 impacts): a jump of
 * more than the smallest radius is refused at the phase, a smaller one or
 * a jump of the velocity alone is warned, a ramp (or no jump) is quiet. */
static void test_motion_jumps_are_warned_or_refused(struct px_context *ctx) {
  struct warnings w;
  /* 2 mm against discs of 1.8 mm; A = 1 m as the tester's */
  expect_refused(ctx,
                 "granular.bodies[0].motion={type: harmonic, amplitude: [0.002, 0.002], "
                 "frequency: 25, phase: [0, 90]}",
                 "granular.bodies[0].motion.phase", "displaced by 0.002 m");
  expect_refused(ctx,
                 "granular.bodies[0].motion={type: harmonic, amplitude: [1, 1], frequency: 25, "
                 "phase: [0, 90]}",
                 "granular.bodies[0].motion.phase", "smallest disc radius 0.0018 m");
  /* a rotation of 10 deg about a corner moves the far corner by 12 mm */
  expect_refused(ctx,
                 "granular.bodies[0].motion={type: harmonic, amplitude: [0, 0], frequency: 25, "
                 "rotation: 10, rotation_phase: 90}",
                 "granular.bodies[0].motion.rotation_phase", "displaced by 0.0123");
  /* a table that starts off its rest position */
  expect_refused(ctx, "granular.bodies[0].motion={type: table, rows: [[0, 0, 0.003], [0.1, 0, 0]]}",
                 "granular.bodies[0].motion.rows", "displaced by 0.003 m");
  /* 1 mm: warned with the jump and the way out */
  check_warnings(ctx,
                 "granular.bodies[0].motion={type: harmonic, amplitude: [0.002, 0.002], "
                 "frequency: 25, phase: [0, 30]}",
                 &w);
  PX_CHECK_MSG(w.n == 1 && strstr(w.text, "granular.bodies[0].motion.phase:") &&
                   strstr(w.text, "displaced by 0.001 m and moving at 0.4155") &&
                   strstr(w.text, "granular.bodies[0].motion.ramp"),
               "%d warnings: %s", w.n, w.text);
  /* phase 0: at rest, but at full speed */
  check_warnings(ctx,
                 "granular.bodies[0].motion={type: harmonic, amplitude: [0.002, 0.002], "
                 "frequency: 25, phase: [0, 0]}",
                 &w);
  PX_CHECK_MSG(w.n == 1 && strstr(w.text, "displaced by 0 m and moving at 0.4442"), "%d: %s", w.n,
               w.text);
  /* a ramp fades both in; a phase of 180 deg rounds sin to 1e-16 */
  check_warnings(ctx,
                 "granular.bodies[0].motion={type: harmonic, amplitude: [0.002, 0.002], "
                 "frequency: 25, phase: [0, 90], ramp: 0.04}",
                 &w);
  PX_CHECK_MSG(w.n == 0, "%d: %s", w.n, w.text);
}

/* DXF text of one ENTITIES section holding `ents`. */
static void dxf_text(char *buf, size_t size, const char *ents) {
  snprintf(buf, size, "0\nSECTION\n2\nENTITIES\n%s0\nENDSEC\n0\nEOF\n", ents);
}

/* A 172-byte drawing of a square 1e6 units wide as a contour at 1.8 mm
 * segments: 2.2e9 segments (an 8 GiB allocation before) refused before the
 * split allocates. */
static void test_dxf_extent_is_refused_before_allocating(struct px_context *ctx) {
  char text[512];
  struct px_geo_path *paths = NULL;
  struct px_gran_geom g;
  size_t n = 0, k, before;
  enum px_status st;
  dxf_text(text, sizeof text,
           "0\nLWPOLYLINE\n90\n4\n70\n1\n10\n0\n20\n0\n10\n1e6\n20\n0\n10\n1e6\n20\n1e6\n"
           "10\n0\n20\n1e6\n");
  PX_CHECK(strlen(text) < 200);
  PX_CHECK_OK(ctx, px_geo_dxf_parse(ctx, "big.dxf", text, strlen(text), NULL, 1.0, 0.0, 0.0, 1e-6,
                                    &paths, &n));
  PX_CHECK(n == 1);
  px_gran_geom_init(&g);
  before = px_mem_peak(ctx, NULL);
  st = n ? px_gran_geom_add_path(ctx, &g, &paths[0], 0.0018, 1e-6, "big", 0, PX_GRAN_SIDE_AUTO)
         : PX_STATUS_INTERNAL;
  PX_CHECK_MSG(st == PX_STATUS_CONFIG && strstr(px_context_message(ctx), "big.dxf:5") &&
                   strstr(px_context_message(ctx), "2.222e+09 segments"),
               "%s: %s", px_status_name(st), px_context_message(ctx));
  PX_CHECK_MSG(px_mem_peak(ctx, NULL) <= before + (1u << 20), "peak grew by %zu bytes",
               px_mem_peak(ctx, NULL) - before);
  px_context_clear(ctx);
  for (k = 0; k < n; ++k) px_geo_path_free(ctx, &paths[k]);
  px_mem_free(ctx, paths);
  px_gran_geom_free(ctx, &g);
}

/* Files that are not regular files (a device would be read for ever). */
static void test_devices_are_not_read(struct px_context *ctx) {
  struct px_geo_path *paths = NULL;
  size_t n = 0;
  enum px_status st = px_geo_dxf_read(ctx, "/dev/zero", NULL, 1.0, 0, 0, 1e-6, &paths, &n);
  PX_CHECK_MSG(st == PX_STATUS_IO && strstr(px_context_message(ctx), "/dev/zero") &&
                   strstr(px_context_message(ctx), "not a regular file"),
               "%s: %s", px_status_name(st), px_context_message(ctx));
  px_context_clear(ctx);
  /* was: fgets over /dev/zero returned empty lines for ever */
  expect_refused(ctx, "granular.bodies[0].motion={type: table, file: /dev/zero}",
                 "granular.bodies[0].motion.file", "not a regular file");
}

/* ------------------------------------------------------------------ sizes */

static void test_sizes_beyond_what_runs_are_refused_at_their_key(struct px_context *ctx) {
  /* was: "out of memory" without a location, after the attempt */
  expect_refused(ctx, "granular.media.count=1000000000", "granular.media.count", "1e+08");
  /* a fraction of a box of 1e4 disc diameters: 1.1e8 discs */
  {
    static const char media[] =
        "granular.media={fraction: 0.9, radius: {min: 0.0018, max: "
        "0.0022}, density: 7800, thickness: 0.004}";
    const char *ov[] = {"granular.contours[0].shape.max=[40, 40]", "granular.segment_length=0.001",
                        "granular.contours[1].shape.center=[20, 20]", media};
    expect_refused_n(ctx, ov, 4, "granular.media.fraction", "discs the solver takes");
  }
  /* was: "invalid time step 0" without a location */
  expect_refused(ctx, "granular.contact.kn=1e308", "granular.contact.kn",
                 "not a positive finite time");
  /* a contact time of 1e-14 s: 1e13 steps to t = 0.1 s (the statistics
   * count steps in int) */
  {
    const char *ov[] = {"time={end: 0.1}", "granular.contact.kn=1e25"};
    expect_refused_n(ctx, ov, 2, "granular.contact.kn", "steps a granular run may take");
  }
  expect_refused(ctx, "granular.wall_contact={kn: 1e308}", "granular.wall_contact.kn",
                 "not a positive finite time");
  expect_refused(ctx, "granular.media.window=[0.04, 0.0, 0.01, 0.05]", "granular.media.window",
                 "xmin < xmax");
  expect_refused(ctx, "granular.skin=1000", "granular.skin", "times the largest radius");
  /* 2000 discs on one spot: refused at the second row, before a neighbour
   * list of 2 million pairs */
  {
    char *text = malloc(2000 * 24 + 4096), *o;
    const char *from = "    count: 60\n", *at = strstr(base_case, from);
    size_t k;
    enum px_status st;
    if (!text || !at) {
      free(text);
      PX_CHECK(0);
      return;
    }
    o = text + sprintf(text, "%.*s    particles: [", (int)(at - base_case), base_case);
    for (k = 0; k < 2000; ++k) o += sprintf(o, "%s[0.01, 0.01, 0.002]", k ? ", " : "");
    sprintf(o, "]\n%s", at + strlen(from));
    st = check_case(ctx, text, NULL, 0);
    PX_CHECK_MSG(st == PX_STATUS_CONFIG &&
                     strstr(px_context_message(ctx), "granular.media.particles[1]") &&
                     strstr(px_context_message(ctx), "overlap"),
                 "%s: %s", px_status_name(st), px_context_message(ctx));
    px_context_clear(ctx);
    free(text);
  }
  /* beyond this machine's memory, when it has less than the estimate */
  {
    const char *ov[] = {"granular.media.count=100000000", "backend.precision=double",
                        "granular.integrator=abm4"};
    const double need = 1e8 * px_gran_sys_particle_bytes(PX_PRECISION_DOUBLE, 1);
    const double have = (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGESIZE);
    if (need > have) {
      const enum px_status st = check_case(ctx, base_case, ov, 3);
      PX_CHECK_MSG(st == PX_STATUS_CONFIG &&
                       strstr(px_context_message(ctx), "granular.media.count = 100000000") &&
                       strstr(px_context_message(ctx), "this machine has"),
                   "%s: %s", px_status_name(st), px_context_message(ctx));
      px_context_clear(ctx);
    }
  }
}

/* ------------------------------------------------------------------ NaN */

/* Two steel discs (r = 2 mm) at rest in a 5 cm box, set up for `integrator`
 * with disc 1 given velocity (vx, 0); g is the box. NULL on failure. */
static struct px_gran_sys *two_discs_in_a_box(struct px_context *ctx, int abm, double vx,
                                              struct px_gran_geom *g) {
  struct px_gran_sys *s = NULL;
  double x[2] = {0.02, 0.03}, y[2] = {0.02, 0.02}, r[2] = {0.002, 0.002}, m[2];
  m[0] = m[1] = 7800 * 3.14159265358979323846 * 0.002 * 0.002 * 0.004;
  px_gran_geom_init(g);
  PX_CHECK_OK(ctx, gt_rect(ctx, g, 0, 0, 0.05, 0.05, 0.002, 0, "box"));
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, g, 0.008));
  PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s));
  if (!s) return NULL;
  s->integrator = abm ? PX_GRAN_INTEGRATOR_ABM4 : PX_GRAN_INTEGRATOR_VERLET;
  gt_law(&s->pp, 2e5, 0.5, 0.3);
  gt_law(&s->pw, 2e5, 0.5, 0.3);
  px_gran_sys_set_walls(s, g, NULL, 0);
  PX_CHECK_OK(ctx, px_gran_sys_add(s, 2, x, y, r, m));
  if (vx != 0) px_gran_sys_set_velocity(s, 1, vx, 0, 0);
  PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
  return s;
}

/* A disc given a NaN velocity is reported at the first step after (the
 * scan every 256 steps found it up to 255 steps late), for both
 * integrators. */
static void test_nan_is_found_at_its_step(struct px_context *ctx) {
  int abm;
  for (abm = 0; abm < 2; ++abm) {
    struct px_gran_geom g;
    struct px_gran_sys *s = two_discs_in_a_box(ctx, abm, 0, &g);
    enum px_status st = PX_STATUS_OK;
    long k;
    if (!s) return;
    for (k = 0; k < 300 && st == PX_STATUS_OK; ++k) st = px_gran_sys_step(s); /* to step 300 */
    PX_CHECK_OK(ctx, st);
    px_gran_sys_set_velocity(s, 1, NAN, 0, 0);
    st = px_gran_sys_step(s);
    PX_CHECK_MSG(st == PX_STATUS_NUMERIC && strstr(px_context_message(ctx), "step 301 (") &&
                     strstr(px_context_message(ctx), "particle 1 "),
                 "%s: %s: %s", abm ? "abm4" : "verlet", px_status_name(st),
                 px_context_message(ctx));
    px_context_clear(ctx);
    px_gran_sys_free(s);
    px_gran_geom_free(ctx, &g);
  }
}

/* A disc shot at 1e6 m/s crossed the 5 cm box in one step and flew on
 * beyond the reach of the "passed through" check (com_x = 1494 m at the
 * end, the run "finished"): stopped at the next rebuild with the disc, its
 * position, the container's extent and the likely cause, for both
 * integrators. A disc at 1 m/s in the same box runs on. */
static void test_disc_outside_the_container_stops_the_run(struct px_context *ctx) {
  int k;
  for (k = 0; k < 3; ++k) {
    struct px_gran_geom g;
    struct px_gran_sys *s = two_discs_in_a_box(ctx, k == 1, k == 2 ? 1 : 1e6, &g);
    enum px_status st = PX_STATUS_OK;
    long n;
    if (!s) return;
    for (n = 0; n < 200 && st == PX_STATUS_OK; ++n) st = px_gran_sys_step(s);
    if (k == 2) {
      PX_CHECK_OK(ctx, st);
    } else {
      PX_CHECK_MSG(st == PX_STATUS_NUMERIC && strstr(px_context_message(ctx), "particle 1 at (") &&
                       strstr(px_context_message(ctx), "has left the container at step ") &&
                       strstr(px_context_message(ctx), "x -0.002 to 0.052 m") &&
                       strstr(px_context_message(ctx), "time step is too large for the speeds"),
                   "%s: %s: %s", k ? "abm4" : "verlet", px_status_name(st),
                   px_context_message(ctx));
    }
    px_context_clear(ctx);
    px_gran_sys_free(s);
    px_gran_geom_free(ctx, &g);
  }
}

/* ------------------------------------------------------------------ outputs */

/* output.png: false: no picture at all, also none at the end of the run. */
static void test_png_false_draws_nothing(struct px_context *ctx) {
  const char *ov[] = {"output.dir=out_hostile_nopng", "output.png=false", "time.steps=40"};
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  DIR *d;
  struct dirent *e;
  int pngs = 0, files = 0;
  px_test_fresh_dir("out_hostile_nopng");
  PX_CHECK_OK(ctx, px_case_load_string(ctx, "case.yaml", base_case, strlen(base_case), ov, 3, &c));
  PX_CHECK_OK(ctx, px_sim_create(ctx, c, PX_SIM_MODE_RUN, &sim));
  if (!sim) return;
  px_sim_set_progress(sim, NULL, 0);
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  d = opendir("out_hostile_nopng");
  PX_CHECK(d != NULL);
  while (d && (e = readdir(d))) {
    const size_t n = strlen(e->d_name);
    ++files;
    pngs += n > 4 && strcmp(e->d_name + n - 4, ".png") == 0;
  }
  if (d) closedir(d);
  PX_CHECK_MSG(files > 5 && pngs == 0, "%d files, %d pictures", files, pngs);
}

/* ------------------------------------------------------------------ checkpoints */

static void test_forged_checkpoints_are_refused(struct px_context *ctx) {
  const char *ov[] = {"output.checkpoint_every=500"};
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  struct px_test_ck f;
  const char *forged = "out_hostile/forged.pxc";
  const double nan = NAN;
  double nseg = 0;
  int32_t slot_seg = -1;
  long slot_at = -1;
  size_t k;
  px_test_fresh_dir("out_hostile");
  PX_CHECK_OK(ctx, px_case_load_string(ctx, "case.yaml", base_case, strlen(base_case), ov, 1, &c));
  PX_CHECK_OK(ctx, px_sim_create(ctx, c, PX_SIM_MODE_RUN, &sim));
  if (!sim) return;
  px_sim_set_progress(sim, NULL, 0);
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  if (!px_test_ck_load(ctx, "out_hostile/checkpoint.pxc", &f)) {
    PX_CHECK(0);
    px_test_ck_free(&f);
    return;
  }
  /* the run has what is forged below: pairs, wall candidates, a wall contact */
  {
    const struct px_test_ck_sec *sc = px_test_ck_find(&f, "granular.scalars"),
                                *sl = px_test_ck_find(&f, "granular.p.slots.seg");
    const struct px_test_ck_sec *st0 = px_test_ck_find(&f, "granular.stats.0");
    double v[10];
    PX_CHECK(sc && sl && st0);
    if (!sc || !sl || !st0) {
      px_test_ck_free(&f);
      return;
    }
    memcpy(v, sc->data, sizeof v);
    PX_CHECK_MSG(v[7] >= 10 && v[8] >= 10 && v[9] >= 5, "pairs %g, candidates %g, near %g", v[7],
                 v[8], v[9]);
    nseg = (double)st0->count;
    for (k = 0; k < sl->count / 4; ++k) {
      memcpy(&slot_seg, sl->data + 4 * k, 4);
      if (slot_seg >= 0) {
        slot_at = (long)k;
        break;
      }
    }
    PX_CHECK_MSG(slot_at >= 0, "no wall contact in the checkpoint");
  }
  /* written again unchanged, it loads */
  PX_CHECK_OK(ctx, px_test_ck_write(ctx, &f, forged));
  PX_CHECK_OK(ctx, px_test_ck_verify(ctx, forged));
  {
    const struct px_test_forgery fs[] = {
        /* index arrays */
        {"granular.pj", PX_DTYPE_I32, 0, 1e6, "granular.pj"},
        {"granular.pj", PX_DTYPE_I32, 0, -1, "granular.pj"},
        {"granular.pj", PX_DTYPE_I32, 0, 0, "granular.pj"},
        {"granular.pi", PX_DTYPE_I32, 0, 12345, "granular.pi"},
        {"granular.pstart", PX_DTYPE_I32, -1, 3, "granular.pstart"},
        {"granular.pstart", PX_DTYPE_I32, 1, -7, "granular.pstart"},
        {"granular.near", PX_DTYPE_I32, 0, 100000, "granular.near"},
        {"granular.near", PX_DTYPE_I32, 0, -2, "granular.near"},
        {"granular.wcand", PX_DTYPE_I32, 0, 1e6, "granular.wcand"},
        {"granular.wcand", PX_DTYPE_I32, 0, -1, "granular.wcand"},
        {"granular.wstart", PX_DTYPE_I32, 1, -5, "granular.wstart"},
        {"granular.wstart", PX_DTYPE_I32, -1, 1e9, "granular.wstart"},
        /* fuzz_granular_resume: a count taken as wstart[2] - wstart[1] overflowed */
        {"granular.wstart", PX_DTYPE_I32, 1, -2147483648.0, "granular.wstart"},
        {"granular.p.slots.seg", PX_DTYPE_I32, slot_at, nseg + 3, "granular.p.slots.seg"},
        {"granular.p.slots.seg", PX_DTYPE_I32, 0, -9, "granular.p.slots.seg"},
        {"granular.p.slots.seg0", PX_DTYPE_I32, slot_at, 1e6, "granular.p.slots.seg"},
        {"granular.p.slots.step0", PX_DTYPE_I32, slot_at, 1e9, "granular.p.slots.seg"},
        {"granular.p.id", PX_DTYPE_I32, 0, 1e6, "granular.p.id"},
        {"granular.where", PX_DTYPE_I32, 0, 1e6, "granular.where"},
        /* counts and scalars: NaN, -1, 1e30 where counts and positive values are */
        {"granular.scalars", PX_DTYPE_F64, 7, nan, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 7, -1, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 7, 1e30, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 7, 2.5, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 8, 1e30, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 9, nan, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 6, 1e30, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 2, 1e30, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 2, nan, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 1, nan, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 1, -1, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 1, 1e30, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 0, nan, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 3, -1, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 4, 0.5, "granular.scalars"},
        {"granular.scalars", PX_DTYPE_F64, 5, 1e30, "granular.scalars"},
        {"granular.run", PX_DTYPE_F64, 5, 0.5, "granular.run"},
        {"granular.run", PX_DTYPE_F64, 6, -1, "granular.run"},
        {"granular.run", PX_DTYPE_F64, 4, nan, "granular.run"},
        {"granular.plot_last", PX_DTYPE_F64, 0, nan, "granular.plot_last"},
        {"granular.plot_last", PX_DTYPE_F64, 0, 1e30, "granular.plot_last"},
        {"granular.plot", PX_DTYPE_F64, 0, 1e30, "granular.plot"},
        /* reals */
        {"granular.p.x", PX_DTYPE_F64, 3, nan, "granular.p.x"},
        {"granular.p.vy", PX_DTYPE_F64, 3, INFINITY, "granular.p.vy"},
        {"granular.p.x", PX_DTYPE_F64, 0, 1e30, "granular.p.x"},
        {"granular.p.r", PX_DTYPE_F64, 0, 1.0, "granular.p.r"},
        {"granular.p.m", PX_DTYPE_F64, 0, -1, "granular.p.r"},
        {"granular.p.slots.xi", PX_DTYPE_F64, 0, nan, "granular.p.slots.xi"},
        {"granular.pxi", PX_DTYPE_F64, 0, INFINITY, "granular.pxi"},
        {"granular.pri", PX_DTYPE_F64, 0, 1e30, "granular.pri"},
        {"granular.frames_ref", PX_DTYPE_F64, 0, nan, "granular.frames_ref"},
        {"granular.cforce", PX_DTYPE_F64, 1, nan, "granular.cforce"},
        {"granular.stats.0", PX_DTYPE_F64, 0, nan, "granular.stats.0"},
        {"granular.stats.15", PX_DTYPE_F64, 1, INFINITY, "granular.stats.15"},
        /* a section shorter than its count says */
        {"granular.pi", PX_DTYPE_U8, 0, 0, "granular.pi"},
        {"granular.wcand", PX_DTYPE_U8, 0, 0, "granular.wcand"},
        {"granular.near", PX_DTYPE_U8, 0, 0, "granular.near"},
        {"granular.pxi", PX_DTYPE_U8, 0, 0, "granular.pxi"},
    };
    px_test_ck_expect_refused(ctx, &f, fs, sizeof fs / sizeof fs[0], forged);
  }
  px_test_ck_free(&f);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  test_huge_contours_are_refused_at_their_key(ctx);
  test_duplicate_contour_names_are_refused(ctx);
  test_motion_jumps_are_warned_or_refused(ctx);
  test_dxf_extent_is_refused_before_allocating(ctx);
  test_devices_are_not_read(ctx);
  test_sizes_beyond_what_runs_are_refused_at_their_key(ctx);
  test_nan_is_found_at_its_step(ctx);
  test_disc_outside_the_container_stops_the_run(ctx);
  test_png_false_draws_nothing(ctx);
  test_forged_checkpoints_are_refused(ctx);
  px_context_free(ctx);
  px_test_release_fonts(); /* LeakSanitizer: only real leaks */
  return px_test_report("test_granular_hostile");
}
