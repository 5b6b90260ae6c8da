/* The vortex solver's velocity sums through the fast multipole method:
 *  - a few steps with method fmm at tolerance 1e-9 agree with the direct sum
 *    (sheet intensities, convective velocities, positions: bounds below);
 *  - with the FMM the wake is bit-identical on 1 and 2 threads, and a
 *    checkpoint + resume continues bit-identically;
 *  - `auto` takes the FMM for a wake of thousands of vortices on cpu;
 *  - bad `velocity` keys are refused with their key path, and the FMM is
 *    refused on the opencl backend at vortex.velocity.method (POCL is a
 *    dependency: an opencl backend exists in every supported build). */
#include <math.h>
#include <string.h>

#include "partix/checkpoint.h"
#include "partix/memory.h"
#include "partix/sim.h"
#include "px_test.h"
#include "../io/px_test_fonts.h"
#include "solvers/vortex/vortex_core.h"
#include "vortex/vx_test_util.h"

/* A wake of n vortices around an ellipse: a jittered boundary layer of rows
 * plus a widening band behind the body, both signs of circulation. */
static void seed_wake(size_t n, double *x, double *y, double *g) {
  unsigned long long s = 987654321ULL;
  for (size_t i = 0; i < n; ++i) {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    double a = (double)(s >> 11) / 9007199254740992.0;
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    double b = (double)(s >> 11) / 9007199254740992.0;
    if (i % 2 == 0) { /* boundary layer: 0.01 .. 0.06 off the ellipse 0.5 x 0.25 */
      double th = 2.0 * 3.14159265358979323846 * a, h = 0.01 + 0.05 * b;
      x[i] = (0.5 + h) * cos(th);
      y[i] = (0.25 + h) * sin(th);
      g[i] = (y[i] > 0.0 ? -1.0 : 1.0) * 2e-4 * (0.5 + b);
    } else { /* wake band 0.6 .. 4 behind it */
      double xw = 0.6 + 3.4 * a, wd = 0.1 + 0.15 * xw;
      x[i] = xw;
      y[i] = wd * (2.0 * b - 1.0);
      g[i] = (y[i] > 0.0 ? -1.0 : 1.0) * 1e-4 * (0.2 + a);
    }
  }
}

static struct px_vortex_engine *make_engine(struct px_context *ctx, struct px_backend *be,
                                            const struct px_vortex_contour *c,
                                            enum px_nbody_method m, double tol, int threads,
                                            enum px_precision prec, size_t nwake) {
  struct px_vortex_config cfg;
  px_vortex_config_defaults(&cfg);
  cfg.nu = 0.002;
  cfg.dt = 0.01;
  cfg.vinf[0] = 1.0;
  cfg.vref = 1.0;
  cfg.eps = 0.008;
  cfg.eps_col = 0.001; /* few merges: the comparison follows the same vortices */
  cfg.gamma_max = 0.002;
  cfg.threads = threads;
  cfg.precision = prec;
  cfg.method = m;
  cfg.tolerance = tol;
  struct px_vortex_engine *e = NULL;
  if (px_vortex_engine_create(ctx, be, &cfg, c, 1, &e) != PX_STATUS_OK) return NULL;
  double *x = px_mem_alloc(ctx, "test", 3 * nwake * sizeof(double));
  seed_wake(nwake, x, x + nwake, x + 2 * nwake);
  enum px_status st = px_vortex_engine_add(e, nwake, x, x + nwake, x + 2 * nwake);
  px_mem_free(ctx, x);
  if (st != PX_STATUS_OK) {
    px_vortex_engine_free(e);
    return NULL;
  }
  return e;
}

/* FMM at 1e-9 against the direct sum, double precision: 3 steps. */
static void test_fmm_matches_direct(struct px_context *ctx) {
  struct px_vortex_contour c;
  PX_CHECK_OK(ctx, px_vortex_profile_ellipse(ctx, 0.5, 0.25, 200, &c));
  struct px_backend *be = NULL;
  PX_CHECK_OK(ctx, px_backend_create(ctx, "cpu", 0, 2, &be));
  const size_t nw = 6000;
  struct px_vortex_engine *ed =
      make_engine(ctx, be, &c, PX_NBODY_METHOD_DIRECT, 1e-9, 2, PX_PRECISION_DOUBLE, nw);
  struct px_vortex_engine *ef =
      make_engine(ctx, be, &c, PX_NBODY_METHOD_FMM, 1e-9, 2, PX_PRECISION_DOUBLE, nw);
  PX_CHECK(ed && ef);
  if (ed && ef) {
    for (int s = 0; s < 3; ++s) {
      PX_CHECK_OK(ctx, px_vortex_engine_step(ed));
      PX_CHECK_OK(ctx, px_vortex_engine_step(ef));
      PX_CHECK(px_nbody_last_method(ed->nbe) == PX_NBODY_METHOD_DIRECT);
      PX_CHECK(px_nbody_last_method(ef->nbe) == PX_NBODY_METHOD_FMM);
      /* sheet intensities (the right-hand side went through the FMM) */
      double dg = 0.0, gm = 0.0;
      for (size_t k = 0; k < ed->pan.n; ++k) {
        dg = fmax(dg, fabs(ed->sol[k] - ef->sol[k]));
        gm = fmax(gm, fabs(ed->sol[k]));
      }
      PX_CHECK_MSG(dg <= 1e-8 * gm, "step %d: sheet differs by %g (max %g)", s, dg, gm);
      /* same vortices (no merge decided differently), same positions */
      PX_CHECK_MSG(ed->w.n == ef->w.n, "step %d: %zu vs %zu vortices", s, ed->w.n, ef->w.n);
      if (ed->w.n != ef->w.n) break;
      double du2 = 0.0, u2 = 0.0, dumax = 0.0, umax = 0.0, dx = 0.0, dgam = 0.0, gamm = 0.0;
      for (size_t i = 0; i < ed->w.n; ++i) {
        double a = ed->w.u[i] - ef->w.u[i], b = ed->w.v[i] - ef->w.v[i];
        du2 += a * a + b * b;
        u2 += ed->w.u[i] * ed->w.u[i] + ed->w.v[i] * ed->w.v[i];
        dumax = fmax(dumax, hypot(a, b));
        umax = fmax(umax, hypot(ed->w.u[i], ed->w.v[i]));
        dx = fmax(dx, fmax(fabs(ed->w.x[i] - ef->w.x[i]), fabs(ed->w.y[i] - ef->w.y[i])));
        dgam = fmax(dgam, fabs(ed->w.g[i] - ef->w.g[i]));
        gamm = fmax(gamm, fabs(ed->w.g[i]));
      }
      printf(
          "step %d: N %zu, sheet %.2e, Gamma %.2e, velocity rel L2 %.2e max %.2e, "
          "positions %.2e (relative errors but the last, in m)\n",
          s, ed->w.n, dg / gm, dgam / gamm, sqrt(du2 / u2), dumax / umax, dx);
      /* circulations: the newborn ones carry the sheet's difference */
      PX_CHECK_MSG(dgam <= 1e-8 * gamm, "step %d: circulations differ by %g (max %g)", s, dgam,
                   gamm);
      /* velocities: relative L2 and max error below the tolerance 1e-9 */
      PX_CHECK_MSG(sqrt(du2 / u2) <= 1e-9, "step %d: rel. L2 velocity error %g", s, sqrt(du2 / u2));
      PX_CHECK_MSG(dumax <= 1e-9 * umax, "step %d: max velocity error %g of %g", s, dumax, umax);
      /* positions: the velocity error times the elapsed time (with margin
       * 10 for the diffusive velocity's dependence on the positions) */
      double bound = 10.0 * 1e-9 * umax * ed->cfg.dt * (s + 1);
      PX_CHECK_MSG(dx <= bound, "step %d: positions differ by %g (bound %g)", s, dx, bound);
    }
  }
  px_vortex_engine_free(ed);
  px_vortex_engine_free(ef);
  px_backend_free(be);
  px_vortex_contour_free(ctx, &c);
}

/* FMM (mixed precision: float sums at 1e-5) on 1 and 2 threads: bit-identical. */
static void test_fmm_threads(struct px_context *ctx) {
  struct px_vortex_contour c;
  PX_CHECK_OK(ctx, px_vortex_profile_ellipse(ctx, 0.5, 0.25, 200, &c));
  struct px_vortex_engine *e[2] = {NULL, NULL};
  struct px_backend *be[2] = {NULL, NULL};
  for (int q = 0; q < 2; ++q) {
    PX_CHECK_OK(ctx, px_backend_create(ctx, "cpu", 0, q + 1, &be[q]));
    e[q] = make_engine(ctx, be[q], &c, PX_NBODY_METHOD_AUTO, 1e-5, q + 1, PX_PRECISION_MIXED, 3000);
    PX_CHECK(e[q] != NULL);
    for (int s = 0; e[q] && s < 2; ++s) PX_CHECK_OK(ctx, px_vortex_engine_step(e[q]));
    if (e[q]) PX_CHECK(px_nbody_last_method(e[q]->nbe) == PX_NBODY_METHOD_FMM);
  }
  if (e[0] && e[1]) {
    PX_CHECK_MSG(e[0]->w.n == e[1]->w.n, "%zu vs %zu vortices", e[0]->w.n, e[1]->w.n);
    size_t n = e[0]->w.n;
    if (n == e[1]->w.n)
      PX_CHECK(memcmp(e[0]->w.x, e[1]->w.x, n * sizeof(double)) == 0 &&
               memcmp(e[0]->w.y, e[1]->w.y, n * sizeof(double)) == 0 &&
               memcmp(e[0]->w.g, e[1]->w.g, n * sizeof(double)) == 0);
    PX_CHECK(e[0]->loads[0].cx == e[1]->loads[0].cx);
  }
  for (int q = 0; q < 2; ++q) {
    px_vortex_engine_free(e[q]);
    px_backend_free(be[q]);
  }
  px_vortex_contour_free(ctx, &c);
}

/* Checkpoint + resume with the FMM (forced at every size): bit-identical to
 * the uninterrupted run. */
static void test_fmm_resume(struct px_context *ctx) {
  const char *fmt =
      "solver: vortex\n"
      "backend: {type: cpu, threads: 2, precision: mixed}\n"
      "time: {dt: 0.02, steps: %d}\n"
      "output: {dir: %s, every: 1000, png: false, vtk: false, csv: true}\n"
      "vortex:\n"
      "  nu: 0.005\n"
      "  v_inf: [1.0, 0.0]\n"
      "  velocity: {method: fmm, tolerance: 1e-6}\n"
      "  bodies:\n"
      "    - {type: circle, radius: 0.5, panels: 64}\n";
  char text[1024];
  snprintf(text, sizeof text, fmt, 10, "out_vx_fmm_a");
  struct px_sim *a = vx_test_sim(ctx, "fmm.yaml", text);
  PX_CHECK(a != NULL);
  if (!a) return;
  PX_CHECK_OK(ctx, px_sim_run(a));
  px_sim_free(a);
  snprintf(text, sizeof text, fmt, 4, "out_vx_fmm_b");
  struct px_sim *b = vx_test_sim(ctx, "fmm.yaml", text);
  PX_CHECK(b != NULL);
  if (!b) return;
  PX_CHECK_OK(ctx, px_sim_run(b));
  px_sim_free(b);
  const char *ov[] = {"time.steps=10"};
  struct px_sim *r = NULL;
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "out_vx_fmm_b/checkpoint.pxc", ov, 1, &r));
  if (!r) return;
  px_sim_set_progress(r, NULL, 0);
  PX_CHECK_OK(ctx, px_sim_run(r));
  px_sim_free(r);
  const char *sec[] = {"vortex.x", "vortex.y", "vortex.gamma"};
  for (int q = 0; q < 3; ++q) {
    size_t na = 0, nb = 0;
    double *da = vx_test_read_section(ctx, "out_vx_fmm_a/checkpoint.pxc", sec[q], &na);
    double *db = vx_test_read_section(ctx, "out_vx_fmm_b/checkpoint.pxc", sec[q], &nb);
    PX_CHECK(da && db);
    PX_CHECK_MSG(na == nb && na > 0, "%s: %zu vs %zu values", sec[q], na, nb);
    if (da && db && na == nb)
      PX_CHECK_MSG(memcmp(da, db, na * sizeof(double)) == 0, "%s differs after resume", sec[q]);
    px_mem_free(ctx, da);
    px_mem_free(ctx, db);
  }
}

static const char *case_fmt =
    "solver: vortex\n"
    "backend: {type: %s}\n"
    "time: {dt: 0.01, steps: 2}\n"
    "output: {dir: out_vx_fmm}\n"
    "vortex:\n"
    "  nu: 0.01\n"
    "  v_inf: [1, 0]\n"
    "  velocity: %s\n"
    "  bodies:\n"
    "    - {type: circle, radius: 0.5, panels: 64}\n";

static enum px_status check_case(struct px_context *ctx, const char *backend,
                                 const char *velocity) {
  char t[1024];
  snprintf(t, sizeof t, case_fmt, backend, velocity);
  struct px_case *c = NULL;
  enum px_status s = px_case_load_string(ctx, "vel.yaml", t, strlen(t), NULL, 0, &c);
  struct px_sim *sim = NULL;
  if (s == PX_STATUS_OK) s = px_sim_create(ctx, c, PX_SIM_MODE_CHECK, &sim);
  px_sim_free(sim);
  return s;
}

static void test_keys(struct px_context *ctx) {
  /* accepted */
  PX_CHECK_OK(ctx, check_case(ctx, "cpu", "{method: fmm, tolerance: 1e-9}"));
  PX_CHECK_OK(ctx, check_case(ctx, "cpu", "{method: direct}"));
  PX_CHECK_OK(ctx, check_case(ctx, "cpu", "{}"));
  /* refused, located: line 8 holds the velocity map */
  PX_CHECK(check_case(ctx, "cpu", "{method: tree}") == PX_STATUS_CONFIG);
  PX_CHECK(vx_test_message_has(ctx, "vortex.velocity.method"));
  PX_CHECK(vx_test_message_has(ctx, "vel.yaml:8:"));
  PX_CHECK(vx_test_message_has(ctx, "fmm"));
  px_context_clear(ctx);
  PX_CHECK(check_case(ctx, "cpu", "{method: fmm, tolerance: 1e-15}") == PX_STATUS_CONFIG);
  PX_CHECK(vx_test_message_has(ctx, "vortex.velocity.tolerance"));
  PX_CHECK(vx_test_message_has(ctx, "vel.yaml:8:"));
  px_context_clear(ctx);
  PX_CHECK(check_case(ctx, "cpu", "{method: fmm, tolerance: 0.5}") == PX_STATUS_CONFIG);
  PX_CHECK(vx_test_message_has(ctx, "vortex.velocity.tolerance"));
  px_context_clear(ctx);
  PX_CHECK(check_case(ctx, "cpu", "{method: fmm, order: 12}") == PX_STATUS_CONFIG);
  PX_CHECK(vx_test_message_has(ctx, "order"));
  px_context_clear(ctx);
  /* the FMM on opencl: refused at the method key */
  PX_CHECK(check_case(ctx, "opencl", "{method: fmm}") == PX_STATUS_CONFIG);
  PX_CHECK(vx_test_message_has(ctx, "vortex.velocity.method"));
  PX_CHECK(vx_test_message_has(ctx, "cpu backend only"));
  px_context_clear(ctx);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  test_fmm_matches_direct(ctx);
  test_fmm_threads(ctx);
  test_fmm_resume(ctx);
  test_keys(ctx);
  px_context_free(ctx);
  px_test_release_fonts(); /* the resumed run's load plot may draw text */
  return px_test_report("test_vortex_fmm");
}
