/* The vortex solver through the run driver: a checkpoint/resume continuation
 * is bit-identical to an uninterrupted run (cpu, same threads), and so are
 * runs on 1 and 2 threads; bad input is
 * refused before any step with a message naming the key or file line; a
 * blow-up stops with a diagnosis; a time step too long for the case's scales
 * is warned about or refused; the moment centre is a point of the profile's
 * own frame; summary.json reports the load history of loads.csv; the last
 * state is always written and `render` writes pictures only. */
#include <dirent.h>
#include <math.h>
#include <string.h>

#include "partix/checkpoint.h"
#include "partix/memory.h"
#include "partix/sim.h"
#include "px_test.h"
#include "../io/px_test_fonts.h"
#include "solvers/vortex/vortex_core.h"
#include "solvers/vortex/vortex_core_impl.h"
#include "solvers/vortex/vortex_host.h"
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
  /* keys of what is drawn or reported may change on resume; the probes
   * (columns of probes.csv) may not */
  const char *bad[] = {"time.steps=30", "vortex.fields.probes=[[1, 1]]"};
  struct px_sim *r = NULL;
  PX_CHECK_STATUS(ctx, px_sim_resume(ctx, "out_vx_b/checkpoint.pxc", bad, 2, &r), PX_STATUS_CONFIG);
  PX_CHECK(vx_test_message_has(ctx, "vortex.fields.probes cannot change"));
  px_sim_free(r);
  r = NULL;
  px_context_clear(ctx);
  const char *ov[] = {"time.steps=30", "vortex.picture.width=400",
                      "vortex.fields.grid=[-1, 2, -1, 1]"};
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "out_vx_b/checkpoint.pxc", ov, 3, &r));
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
  /* summary.json covers the whole run, also when it was resumed */
  const char *q[] = {"cx_mean", "cy_std", "cm_mean", "cx_friction_mean", "window_from"};
  for (int k = 0; k < 5; ++k) {
    double va = vx_test_summary_value("out_vx_a/summary.json", q[k]);
    double vb = vx_test_summary_value("out_vx_b/summary.json", q[k]);
    PX_CHECK_MSG(isfinite(va) && va == vb, "%s: %.17g uninterrupted, %.17g resumed", q[k], va, vb);
  }
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
  const char *head =
      "solver: vortex\ntime: {dt: %s, steps: 10}\noutput: {dir: out_vx_bad}\n"
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
  const char *two =
      "solver: vortex\ntime: {dt: 0.01, steps: 10}\noutput: {dir: out_vx_bad}\n"
      "vortex:\n  nu: 0.01\n  v_inf: [1, 0]\n  bodies:\n"
      "    - {type: circle, radius: 0.5, panels: 64}\n"
      "    - {type: circle, radius: 0.5, panels: 64, position: [0.6, 0]}\n";
  expect_refused(ctx, two, "overlap", "vortex.bodies[1]");
  /* ramp without its time */
  const char *ramp =
      "solver: vortex\ntime: {dt: 0.01, steps: 10}\noutput: {dir: out_vx_bad}\n"
      "vortex:\n  nu: 0.01\n  v_inf: [1, 0]\n  start: linear\n  bodies:\n"
      "    - {type: circle, radius: 0.5, panels: 64}\n";
  expect_refused(ctx, ramp, "ramp_time", NULL);
  const char *rk3 =
      "solver: vortex\ntime: {dt: 0.01, steps: 10}\noutput: {dir: out_vx_bad}\n"
      "vortex:\n  nu: 0.01\n  v_inf: [1, 0]\n  scheme: rk3\n  bodies:\n"
      "    - {type: circle, radius: 0.5, panels: 64}\n";
  expect_refused(ctx, rk3, "bad.yaml:7:", "vortex.scheme");
  /* absurd values, refused at their key (file:line:col) with the bound, not
   * by an inner function or a misleading symptom */
  const char *still =
      "solver: vortex\ntime: {dt: 0.01, steps: 10}\noutput: {dir: out_vx_bad}\n"
      "vortex:\n  nu: 0.01\n  v_inf: [0, 0]\n  bodies:\n"
      "    - {type: circle, radius: 0.5, panels: 64}\n";
  expect_refused(ctx, still, "bad.yaml:6:10: vortex.v_inf", "give a reference speed v_ref > 0");
  {
    /* nu, the body (and what follows it), where and what the refusal says */
    static const struct {
      const char *nu, *body, *where, *what;
    } bad[] = {
        {"0.01", "{type: circle, radius: 0.5, panels: 64}\n  eps: 1e300",
         "bad.yaml:9:8: vortex.eps", "wider than the bodies' extent 1 m"},
        {"0.01", "{type: circle, radius: 1e300, panels: 64}",
         "bad.yaml:8:30: vortex.bodies[0].radius", "limited to +-1e+09 m"},
        {"0.01", "{type: ellipse, a: 1, b: 2e9, panels: 64}", "vortex.bodies[0].b",
         "limited to +-1e+09 m"},
        {"0.01", "{type: plate, length: 1e300, thickness: 1, panels: 64}",
         "vortex.bodies[0].length", "limited to +-1e+09 m"},
        {"0.01", "{type: naca, digits: \"0012\", panels: 64, scale: 1e300}",
         "vortex.bodies[0].scale", "takes the body 1e+300 m from the origin"},
        {"0.01", "{type: circle, radius: 0.5, panels: 64, position: [0, -3e9]}",
         "vortex.bodies[0].position", "limited to +-1e+09 m"},
        /* nu = 1e308 ran as if inviscid: one step diffuses sqrt(nu dt) = 1e153 m */
        {"1e308", "{type: circle, radius: 0.5, panels: 64}", "bad.yaml:5:7: vortex.nu",
         "more than the bodies' extent 1 m"},
        /* the bound: nu dt <= D^2 = 1 m^2 passes (nu = 100, dt = 0.01), above not */
        {"101", "{type: circle, radius: 0.5, panels: 64}", "vortex.nu",
         "nu <= D^2 / dt = 100 m^2/s"},
        /* a probe inside a body (it reported u = 0.011 m/s, p = -80 Pa at the
         * cylinder's centre, where the grid writes 0 and NaN) */
        {"0.01",
         "{type: circle, radius: 0.5, panels: 64}\n  fields: {probes: [[2, 0], [0.3, -0.1]]}",
         "bad.yaml:9:29: vortex.fields.probes[1]", "the probe (0.3, -0.1) m lies inside body 0"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
      snprintf(t, sizeof t, head, "0.01", bad[k].nu, bad[k].body);
      expect_refused(ctx, t, bad[k].where, bad[k].what);
    }
  }
  snprintf(t, sizeof t, head, "0.01", "99", "{type: circle, radius: 0.5, panels: 64}");
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  PX_CHECK_OK(ctx, px_case_load_string(ctx, "ok.yaml", t, strlen(t), NULL, 0, &c));
  if (c) PX_CHECK_OK(ctx, px_sim_create(ctx, c, PX_SIM_MODE_CHECK, &sim));
  px_sim_free(sim);
}

/* A wake of n vortices (uniform in a box behind the body, circulations of
 * either sign) added to e's: enough for the loops that run on all threads
 * from 16 384 vortices (the move, the checks, the merge's compaction). */
static void add_wake(struct px_context *ctx, struct px_vortex_engine *e, size_t n) {
  struct px_vortex_wake *w = &e->w;
  unsigned long long s = 4242;
  PX_CHECK_OK(ctx, px_vortex_wake_reserve(ctx, w, w->n + n));
  for (size_t q = 0; q < n; ++q) {
    const size_t i = w->n + q;
    w->x[i] = 11.0 + 4.0 * vx_test_urand(&s);
    w->y[i] = 9.0 + 2.0 * vx_test_urand(&s);
    w->g[i] = 1e-4 * (vx_test_urand(&s) - 0.5);
    w->u[i] = w->v[i] = w->wu[i] = w->wv[i] = w->e[i] = 0.0;
    w->born[i] = -1;
  }
  w->n += n;
}

/* The same run on 1 and on 2 threads: bit-identical wakes (fixed reductions,
 * per-target loops, sequential merge), also with 20 000 vortices more. */
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
    if (e[q]) {
      add_wake(ctx, e[q], 20000);
      for (int s = 0; s < 3; ++s) PX_CHECK_OK(ctx, px_vortex_engine_step(e[q]));
      w[q] = &e[q]->w;
    }
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

/* Block 7's drop on 1 and 2 threads (the shares' path from 16 384
 * vortices): absorbed, empty and far vortices removed in a stable order,
 * the survivors' moved positions in w->x, w->y and their other fields at
 * e->hit until px_vortex_drop_finish (a failed step) gathers them: both
 * against a plain loop. */
static void test_drop(struct px_context *ctx) {
  struct px_vortex_contour c;
  PX_CHECK_OK(ctx, px_vortex_profile_circle(ctx, 0.5, 64, &c));
  for (int q = 0; q < 2; ++q) {
    struct px_backend *be = NULL;
    struct px_vortex_engine *e = NULL;
    const int threads = q + 1;
    PX_CHECK_OK(ctx, px_backend_create(ctx, "cpu", 0, threads, &be));
    struct px_vortex_config cfg;
    vx_test_cylinder_config(&cfg, 0.01, 0.007, threads);
    cfg.dist_far = 100.0; /* [m]: the wake lies within 20 of the body */
    PX_CHECK_OK(ctx, px_vortex_engine_create(ctx, be, &cfg, &c, 1, &e));
    if (!e) {
      px_backend_free(be);
      continue;
    }
    add_wake(ctx, e, 30000);
    struct px_vortex_wake *w = &e->w;
    const size_t n = w->n;
    PX_CHECK_OK(ctx, px_vortex_ensure_work(e, n));
    double *want = px_mem_alloc(ctx, "test", 8 * n * sizeof(double));
    PX_CHECK(want != NULL);
    if (!want) {
      px_vortex_engine_free(e);
      px_backend_free(be);
      break;
    }
    size_t m = 0, nfar = 0;
    for (size_t i = 0; i < n; ++i) {
      w->u[i] = (double)i;
      w->v[i] = 2.0 * (double)i;
      w->wu[i] = 3.0 * (double)i;
      w->wv[i] = 4.0 * (double)i;
      w->e[i] = 5.0 * (double)i;
      w->born[i] = (int32_t)(i % 7);
      if (i % 89 == 0) w->g[i] = 0.0;
      e->hit[i] = i % 97 == 0 ? (int32_t)(i % 64) : -1;
      e->xn[i] = w->x[i] + 1e-3;
      e->yn[i] = i % 101 == 0 ? 1e9 : w->y[i] - 1e-3;
      if (e->hit[i] >= 0 || w->g[i] == 0.0) continue;
      if (i % 101 == 0) {
        ++nfar;
        continue;
      }
      const double f[8] = {e->xn[i], e->yn[i], w->g[i],  w->u[i],
                           w->v[i],  w->wu[i], w->wv[i], w->e[i]};
      for (int k = 0; k < 8; ++k) want[(size_t)k * n + m] = f[k];
      ++m;
    }
    const size_t got = px_vortex_drop(e);
    PX_CHECK_MSG(got == m && w->n == m && e->n_far == nfar, "%zu (%zu far) vs %zu (%zu)", got,
                 e->n_far, m, nfar);
    if (got == m) {
      PX_CHECK(memcmp(w->x, want, m * sizeof(double)) == 0 &&
               memcmp(w->y, want + n, m * sizeof(double)) == 0);
      px_vortex_drop_finish(e);
      double *const have[6] = {w->g, w->u, w->v, w->wu, w->wv, w->e};
      for (int k = 0; k < 6; ++k)
        PX_CHECK_MSG(memcmp(have[k], want + (size_t)(k + 2) * n, m * sizeof(double)) == 0,
                     "field %d after the drop (%d threads)", k, threads);
      int born = 1;
      for (size_t i = 0; i < m; ++i) born &= w->born[i] == -1;
      PX_CHECK(born);
    }
    px_mem_free(ctx, want);
    px_vortex_engine_free(e);
    px_backend_free(be);
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

/* ---- the cap on newborns per panel ------------------------------------ */

static int vx_cap_warnings;
static char vx_cap_message[2048];
static void vx_capture_cap(void *user, enum px_log_level level, const char *msg) {
  (void)user;
  if (level == PX_LOG_LEVEL_WARN && strstr(msg, "vortex.gamma_max")) {
    ++vx_cap_warnings;
    snprintf(vx_cap_message, sizeof vx_cap_message, "%s", msg);
  }
}

/* Two Euler steps of a 64-panel cylinder with gamma_max = gmax on `backend`
 * (skipped when it cannot be made): the newborns of the first step, and the
 * warnings about the cap (the last one in vx_cap_message); *gl the largest
 * |gamma L| of the first step's sheet. */
static size_t vx_cap_run(struct px_context *ctx, const char *backend, double gmax, double *gl,
                         int *skipped) {
  struct px_backend *be = NULL;
  *skipped = 0;
  *gl = 0.0;
  if (px_backend_create(ctx, backend, 0, 1, &be) != PX_STATUS_OK) {
    px_context_clear(ctx);
    *skipped = 1;
    return 0;
  }
  struct px_vortex_contour c;
  PX_CHECK_OK(ctx, px_vortex_profile_circle(ctx, 0.5, 64, &c));
  struct px_vortex_config cfg;
  vx_test_cylinder_config(&cfg, 0.025, 0.016, 1);
  cfg.gamma_max = gmax;
  cfg.precision = PX_PRECISION_DOUBLE;
  if (strcmp(backend, "cpu") != 0) cfg.precision = PX_PRECISION_MIXED;
  struct px_vortex_engine *e = NULL;
  size_t born = 0;
  vx_cap_warnings = 0;
  vx_cap_message[0] = '\0';
  px_context_set_log(ctx, vx_capture_cap, NULL);
  PX_CHECK_OK(ctx, px_vortex_engine_create(ctx, be, &cfg, &c, 1, &e));
  if (e) {
    PX_CHECK_OK(ctx, px_vortex_engine_step(e));
    PX_CHECK_OK(ctx, px_vortex_engine_sync(e));
    born = e->n_born;
    for (size_t k = 0; k < e->pan.n; ++k) *gl = fmax(*gl, fabs(e->sol[k] * e->pan.len[k]));
    e->step = 1;
    e->time = cfg.dt;
    PX_CHECK_OK(ctx, px_vortex_engine_step(e));
  }
  px_context_set_log(ctx, NULL, NULL);
  px_vortex_engine_free(e);
  px_vortex_contour_free(ctx, &c);
  px_backend_free(be);
  return born;
}

/* A panel sheds at most 64 newborns a step (VX_NEWBORN_MAX): a gamma_max
 * under the largest |gamma L| / 64 no longer refines the wall layer there,
 * and the run says so once, with the effective gamma_max; above it, no
 * warning and every panel sheds ceil(|gamma L| / gamma_max). On cpu and, when
 * there is a device, opencl (its count kernel flags the capped panel). */
static void test_newborn_cap(struct px_context *ctx) {
  const char *backends[] = {"cpu", "opencl"};
  for (int b = 0; b < 2; ++b) {
    double gl = 0.0;
    int skipped = 0;
    /* the impulsive start's sheet: |gamma L| up to 2 V L = 0.098 m^2/s */
    size_t fine = vx_cap_run(ctx, backends[b], 1e-9, &gl, &skipped);
    if (skipped) {
      printf("test_vortex_solver: no %s backend, its newborn cap check skipped\n", backends[b]);
      continue;
    }
    PX_CHECK_MSG(fine == 64 * 64, "%s: %zu newborns with gamma_max = 1e-9, not 64 per panel",
                 backends[b], fine);
    PX_CHECK_MSG(vx_cap_warnings == 1, "%s: %d warnings about the cap in two steps (expected 1)",
                 backends[b], vx_cap_warnings);
    char want[128];
    snprintf(want, sizeof want, "the effective gamma_max is up to %g m^2/s", gl / 64.0);
    PX_CHECK_MSG(strstr(vx_cap_message, want) != NULL, "%s: \"%s\" lacks \"%s\"", backends[b],
                 vx_cap_message, want);
    PX_CHECK(strstr(vx_cap_message, "vortex.gamma_max = 1e-09 m^2/s") != NULL);
    /* under the cap: 48 newborns on the strongest panel of the first step */
    double g2 = 0.0;
    vx_cap_run(ctx, backends[b], gl / 48.0, &g2, &skipped);
    PX_CHECK_MSG(vx_cap_warnings == 0, "%s: gamma_max = |gamma L| / 48 warned: %s", backends[b],
                 vx_cap_message);
  }
}

/* ---- time step against the case's scales ------------------------------ */

static int vx_dt_warned;
static void vx_capture_warning(void *user, enum px_log_level level, const char *msg) {
  (void)user;
  if (level == PX_LOG_LEVEL_WARN && strstr(msg, "time.dt")) vx_dt_warned = 1;
}

/* `partix check` of a circle of 64 panels (mean panel length L = 2 sin(pi/64)
 * r = 0.049068 m, eps = L/2, so min(L, 2 eps) = L) at V = 1 m/s with the step
 * of `travel` panel lengths: the status, and whether a warning named time.dt. */
static enum px_status vx_check_travel(struct px_context *ctx, double travel, int *warned) {
  const double L = 2.0 * sin(3.14159265358979323846 / 64.0) * 0.5;
  char t[1024];
  snprintf(t, sizeof t,
           "solver: vortex\ntime: {dt: %.17g, steps: 10}\noutput: {dir: out_vx_dt}\n"
           "vortex:\n  nu: 0.005\n  v_inf: [1, 0]\n  bodies:\n"
           "    - {type: circle, radius: 0.5, panels: 64}\n",
           travel * L);
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  vx_dt_warned = 0;
  px_context_set_log(ctx, vx_capture_warning, NULL);
  enum px_status s = px_case_load_string(ctx, "dt.yaml", t, strlen(t), NULL, 0, &c);
  if (s == PX_STATUS_OK) s = px_sim_create(ctx, c, PX_SIM_MODE_CHECK, &sim);
  px_sim_free(sim);
  px_context_set_log(ctx, NULL, NULL);
  *warned = vx_dt_warned;
  return s;
}

/* A vortex born on a panel travels V dt in its first step; the loads drift
 * by several per cent beyond two panel lengths per step and by 15% or more
 * beyond ten (docs/notes/vortex.md, "The time step"): 1.9 L passes silently,
 * 2.1 L is warned about, 9.9 L still runs, 10.1 L is refused at time.dt with
 * the recommended step L / V. */
static void test_dt_limits(struct px_context *ctx) {
  int w = 0;
  PX_CHECK_OK(ctx, vx_check_travel(ctx, 1.9, &w));
  PX_CHECK_MSG(!w, "V dt = 1.9 L warned about");
  PX_CHECK_OK(ctx, vx_check_travel(ctx, 2.1, &w));
  PX_CHECK_MSG(w, "V dt = 2.1 L not warned about");
  PX_CHECK_OK(ctx, vx_check_travel(ctx, 9.9, &w));
  PX_CHECK_MSG(w, "V dt = 9.9 L not warned about");
  PX_CHECK_STATUS(ctx, vx_check_travel(ctx, 10.1, &w), PX_STATUS_CONFIG);
  PX_CHECK(vx_test_message_has(ctx, "time.dt"));
  PX_CHECK(vx_test_message_has(ctx, "dt <= 0.04907 s"));
  px_context_clear(ctx);
}

/* ---- the moment centre in the profile's own frame ---------------------- */

#define VX_MC_ROWS 16

/* Run a NACA 0012 (80 panels, chord 1) at `angle` [deg] in the stream
 * (vx, vy) with the moment centre [mcx, 0] of its own frame, 6 steps in
 * double precision with the direct sum and without merges (eps_col 1e-9 m:
 * the merge pass runs in the Morton order of the global frame, which a
 * rotation changes, and the step-to-step noise of the loads would then
 * differ between two frames by ~1% of C_x; without merges the two agree to
 * 1e-11 for 9 steps, then a vortex on the edge of absorption goes one way in
 * one frame and the other way in the other); read cm, fx, fy, m of
 * loads.csv. */
static size_t vx_run_naca(struct px_context *ctx, const char *dir, double vx, double vy,
                          double angle, double mcx, double (*out)[VX_MC_ROWS]) {
  char text[2048], path[256];
  snprintf(text, sizeof text,
           "solver: vortex\n"
           "backend: {type: cpu, threads: 2, precision: double}\n"
           "time: {dt: 0.01, steps: 6}\n"
           "output: {dir: %s, every: 1000, png: false, vtk: false, csv: true}\n"
           "vortex:\n"
           "  nu: 0.001\n"
           "  v_inf: [%.17g, %.17g]\n"
           "  velocity: {method: direct}\n"
           "  eps_col: 1e-9\n"
           "  bodies:\n"
           "    - {type: naca, digits: \"0012\", panels: 80, angle: %g, moment_center: [%g, 0],"
           " reference_length: 1}\n",
           dir, vx, vy, angle, mcx);
  struct px_sim *sim = vx_test_sim(ctx, "naca.yaml", text);
  PX_CHECK(sim != NULL);
  if (!sim) return 0;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  static const char *const col[4] = {"cm [-]", "fx [N/m]", "fy [N/m]", "m [N m/m]"};
  size_t n = 0;
  snprintf(path, sizeof path, "%s/loads.csv", dir);
  for (int k = 0; k < 4; ++k) n = vx_test_csv_column(path, col[k], out[k], VX_MC_ROWS);
  return n;
}

/* One flow seen from two frames: the profile rotated by 5 deg (nose up) in a
 * stream along +x, and the profile unrotated in a stream turned by 5 deg the
 * other way. The moment is a scalar, so C_m about the quarter chord
 * (moment_center [0.25, 0] in both cases) must agree to rounding (the CSV's
 * 10 digits); before the centre was placed with the profile, the rotated
 * case's [0.25, 0] lay 0.022 c off its chord line and C_m differed by about
 * 0.022 C_x.
 * And between two centres A, B of one run M_B = M_A + (r_A - r_B) x F, with
 * r_A - r_B the quarter chord rotated with the profile. */
static void test_moment_center(struct px_context *ctx) {
  const double a = 5.0 * 3.14159265358979323846 / 180.0;
  double A[4][VX_MC_ROWS], B[4][VX_MC_ROWS], C[4][VX_MC_ROWS];
  size_t na = vx_run_naca(ctx, "out_vx_mc_a", 1.0, 0.0, 5.0, 0.25, A);
  size_t nb = vx_run_naca(ctx, "out_vx_mc_b", cos(a), sin(a), 0.0, 0.25, B);
  size_t nc = vx_run_naca(ctx, "out_vx_mc_c", 1.0, 0.0, 5.0, 0.0, C);
  PX_CHECK_MSG(na == 6 && nb == 6 && nc == 6, "rows %zu %zu %zu", na, nb, nc);
  if (na != 6 || nb != 6 || nc != 6) return;
  double worst = 0.0, worst_id = 0.0;
  for (size_t i = 0; i < 6; ++i) {
    double cx = A[1][i] / 0.5; /* q c = 0.5 rho V^2 c = 0.5 */
    worst = fmax(worst, fabs(A[0][i] - B[0][i]) / fmax(fabs(cx), 1.0));
    /* M_C = M_A + (r_A - r_C) x F, r_A - r_C = the quarter chord rotated
     * clockwise by 5 deg = 0.25 (cos a, -sin a) */
    double rx = 0.25 * cos(a), ry = -0.25 * sin(a);
    double mc = A[3][i] + rx * A[2][i] - ry * A[1][i];
    double scale = fabs(A[3][i]) + fabs(A[1][i]) + fabs(A[2][i]);
    worst_id = fmax(worst_id, fabs(C[3][i] - mc) / scale);
  }
  printf(
      "moment centre: C_m rotated vs unrotated frame %.2e (per unit C_x), transform "
      "identity %.2e\n",
      worst, worst_id);
  PX_CHECK_MSG(worst < 1e-6,
               "C_m about the quarter chord differs by %.3g C_x between the "
               "rotated and the unrotated frame",
               worst);
  PX_CHECK_MSG(worst_id < 1e-8, "M_B = M_A + (r_A - r_B) x F off by %.3g", worst_id);
}

/* ---- summary.json from loads.csv -------------------------------------- */

/* The averages of summary.json are those of loads.csv over the window: by
 * default the second half of the run's time, else vortex.report.from/to. */
static void test_summary(struct px_context *ctx) {
  static const char *fmt =
      "solver: vortex\n"
      "backend: {type: cpu, threads: 2}\n"
      "time: {dt: 0.02, steps: 40}\n"
      "output: {dir: %s, every: 1000, png: false, vtk: false, csv: true}\n"
      "vortex:\n"
      "  nu: 0.005\n"
      "  v_inf: [1.0, 0.0]\n"
      "  bodies:\n"
      "    - {type: circle, radius: 0.5, panels: 64}\n"
      "%s";
  for (int k = 0; k < 2; ++k) {
    char text[1024], dir[64], path[128];
    snprintf(dir, sizeof dir, "out_vx_summary%d", k);
    snprintf(text, sizeof text, fmt, dir, k ? "  report: {from: 0.3, to: 0.6}\n" : "");
    struct px_sim *sim = vx_test_sim(ctx, "summary.yaml", text);
    PX_CHECK(sim != NULL);
    if (!sim) return;
    PX_CHECK_OK(ctx, px_sim_run(sim));
    px_sim_free(sim);
    double t[64], cx[64], cm[64];
    snprintf(path, sizeof path, "%s/loads.csv", dir);
    size_t n = vx_test_csv_column(path, "t [s]", t, 64);
    PX_CHECK(vx_test_csv_column(path, "cx [-]", cx, 64) == n && n == 40);
    PX_CHECK(vx_test_csv_column(path, "cm [-]", cm, 64) == n);
    double t0 = k ? 0.3 : 0.4, t1 = k ? 0.6 : 0.8, s = 0.0, s2 = 0.0;
    size_t m = 0;
    for (size_t i = 0; i < n; ++i)
      if (t[i] >= t0 - 1e-12 && t[i] <= t1 + 1e-12) {
        s += cx[i];
        ++m;
      }
    double mean = s / (double)m, cmm = 0.0;
    for (size_t i = 0; i < n; ++i)
      if (t[i] >= t0 - 1e-12 && t[i] <= t1 + 1e-12) cmm += cm[i];
    cmm /= (double)m;
    for (size_t i = 0; i < n; ++i)
      if (t[i] >= t0 - 1e-12 && t[i] <= t1 + 1e-12) s2 += (cm[i] - cmm) * (cm[i] - cmm);
    snprintf(path, sizeof path, "%s/summary.json", dir);
    PX_CHECK_NEAR(vx_test_summary_value(path, "window_from"), t0, 1e-12);
    PX_CHECK_NEAR(vx_test_summary_value(path, "window_to"), t1, 1e-12);
    PX_CHECK_NEAR(vx_test_summary_value(path, "window_samples"), (double)m, 0.0);
    PX_CHECK_REL(vx_test_summary_value(path, "cx_mean"), mean, 1e-12);
    PX_CHECK_REL(vx_test_summary_value(path, "cm_std"), sqrt(s2 / (double)m), 1e-9);
    PX_CHECK_REL(vx_test_summary_value(path, "reynolds"), 200.0, 1e-12);
    /* 0.8 s of a symmetric start: no shedding */
    PX_CHECK(vx_test_summary_value(path, "lift_periodic") == 0.0);
    PX_CHECK(isnan(vx_test_summary_value(path, "strouhal")));
  }
}

/* With several bodies each body's columns and quantities carry its index:
 * "cx_1 [-]" in loads.csv, "body_1.cx_mean" in summary.json. */
static void test_summary_bodies(struct px_context *ctx) {
  const char *text =
      "solver: vortex\n"
      "backend: {type: cpu, threads: 2}\n"
      "time: {dt: 0.02, steps: 10}\n"
      "output: {dir: out_vx_summary_two, every: 1000, png: false, vtk: false}\n"
      "vortex:\n"
      "  nu: 0.005\n"
      "  v_inf: [1.0, 0.0]\n"
      "  bodies:\n"
      "    - {type: circle, radius: 0.5, panels: 64}\n"
      "    - {type: circle, radius: 0.25, panels: 32, position: [2, 0.5]}\n";
  struct px_sim *sim = vx_test_sim(ctx, "two.yaml", text);
  PX_CHECK(sim != NULL);
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  double t[16], c1[16];
  size_t n = vx_test_csv_column("out_vx_summary_two/loads.csv", "t [s]", t, 16);
  PX_CHECK(n == 10 && vx_test_csv_column("out_vx_summary_two/loads.csv", "cx_1 [-]", c1, 16) == n);
  double s = 0.0;
  size_t m = 0;
  for (size_t i = 0; i < n; ++i)
    if (t[i] >= 0.1 - 1e-12) {
      s += c1[i];
      ++m;
    }
  const char *js = "out_vx_summary_two/summary.json";
  PX_CHECK(m == 6);
  PX_CHECK_REL(vx_test_summary_value(js, "body_1.cx_mean"), s / (double)m, 1e-12);
  /* the small cylinder: Re = v_ref c / nu with c its diameter 0.5 */
  PX_CHECK_REL(vx_test_summary_value(js, "body_1.reynolds"), 100.0, 1e-9);
  PX_CHECK(isnan(vx_test_summary_value(js, "cx_mean")));
}

/* ---- the last state, and render --------------------------------------- */

/* Content of every file of a folder (names and bytes), for comparison. */
struct vx_folder {
  size_t n;
  char name[64][64];
  char *data[64]; /* malloc'd */
  size_t len[64];
};

static void vx_folder_read(const char *dir, struct vx_folder *f) {
  memset(f, 0, sizeof *f);
  DIR *d = opendir(dir);
  struct dirent *de;
  while (d && (de = readdir(d)) != NULL && f->n < 64) {
    char path[256];
    if (de->d_name[0] == '.') continue;
    snprintf(path, sizeof path, "%.100s/%.150s", dir, de->d_name);
    FILE *fp = fopen(path, "rb");
    if (!fp) continue; /* a folder (input/) */
    fseek(fp, 0, SEEK_END);
    long len = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    f->data[f->n] = malloc((size_t)len + 1);
    f->len[f->n] = f->data[f->n] ? fread(f->data[f->n], 1, (size_t)len, fp) : 0;
    fclose(fp);
    snprintf(f->name[f->n], sizeof f->name[0], "%.63s", de->d_name);
    ++f->n;
  }
  if (d) closedir(d);
}

static void vx_folder_free(struct vx_folder *f) {
  for (size_t i = 0; i < f->n; ++i) free(f->data[i]);
}

static const struct vx_folder *vx_folder_find(const struct vx_folder *f, const char *name,
                                              size_t *at) {
  for (size_t i = 0; i < f->n; ++i)
    if (strcmp(f->name[i], name) == 0) {
      *at = i;
      return f;
    }
  return NULL;
}

/* A run of 7 steps with outputs every 3: the last state (step 7, off every
 * schedule) is written all the same (wake, fields, picture, loads row); then
 * `render` from its checkpoint draws the pictures again (the deleted
 * wake_000007.png and loads.png come back) and changes no other file and
 * writes no new one. */
static void test_final_and_render(struct px_context *ctx) {
  const char *text =
      "solver: vortex\n"
      "backend: {type: cpu, threads: 2}\n"
      "time: {dt: 0.02, steps: 7}\n"
      "output: {dir: out_vx_render, every: 3, png_every: 3, log_every: 2}\n"
      "vortex:\n"
      "  nu: 0.005\n"
      "  v_inf: [1.0, 0.0]\n"
      "  bodies:\n"
      "    - {type: circle, radius: 0.5, panels: 64}\n"
      "  fields: {grid: [-1, 2, -1, 1], cells: [12, 8], probes: [[1.0, 0.2]]}\n"
      "  picture: {width: 320, height: 200}\n";
  struct px_sim *sim = vx_test_sim(ctx, "render.yaml", text);
  PX_CHECK(sim != NULL);
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  struct vx_folder before, after;
  vx_folder_read("out_vx_render", &before);
  size_t at;
  static const char *const last[] = {"wake_000007.vtp", "wake_000007.png", "fields_000007.vti",
                                     "loads.png", "summary.json"};
  for (int k = 0; k < 5; ++k)
    PX_CHECK_MSG(vx_folder_find(&before, last[k], &at), "no %s after a run of 7 steps", last[k]);
  double t[8];
  PX_CHECK(vx_test_csv_column("out_vx_render/loads.csv", "t [s]", t, 8) == 4 &&
           fabs(t[3] - 0.14) < 1e-12);
  PX_CHECK(vx_test_csv_column("out_vx_render/probes.csv", "t [s]", t, 8) == 4 &&
           fabs(t[3] - 0.14) < 1e-12);
  remove("out_vx_render/wake_000007.png");
  remove("out_vx_render/loads.png");
  struct px_sim *r = NULL;
  PX_CHECK_OK(ctx,
              px_sim_open(ctx, "out_vx_render/checkpoint.pxc", NULL, 0, PX_SIM_MODE_RENDER, &r));
  if (r) PX_CHECK_OK(ctx, px_sim_render(r));
  px_sim_free(r);
  vx_folder_read("out_vx_render", &after);
  PX_CHECK_MSG(after.n == before.n, "%zu files before render, %zu after", before.n, after.n);
  for (size_t i = 0; i < after.n; ++i) {
    int found = vx_folder_find(&before, after.name[i], &at) != NULL;
    PX_CHECK_MSG(found, "render wrote %s", after.name[i]);
    const char *dot = strrchr(after.name[i], '.');
    if (!found || (dot && strcmp(dot, ".png") == 0)) continue;
    PX_CHECK_MSG(
        after.len[i] == before.len[at] && memcmp(after.data[i], before.data[at], after.len[i]) == 0,
        "render changed %s", after.name[i]);
  }
  vx_folder_free(&before);
  vx_folder_free(&after);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  test_resume(ctx, "euler");
  test_resume(ctx, "rk2");
  test_bad_input(ctx);
  test_threads(ctx);
  test_drop(ctx);
  test_blowup(ctx);
  test_newborn_cap(ctx);
  test_dt_limits(ctx);
  test_moment_center(ctx);
  test_summary(ctx);
  test_summary_bodies(ctx);
  test_final_and_render(ctx);
  px_context_free(ctx);
  px_test_release_fonts(); /* the load plot drew text */
  return px_test_report("test_vortex_solver");
}
