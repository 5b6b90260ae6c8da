/* Dynamic validation on the cpu engine (double; the wave also in single):
 *  - first bending frequency of a cantilever released from its static
 *    deflection: (1.8751)^2 sqrt(E I/(rho A L^4)) within 2 %;
 *  - longitudinal wave in a bar under a suddenly applied end force: the
 *    front (half the plateau velocity) travels at sqrt(E/rho) within 2 %;
 *  - energy without damping: a long bar in smooth bending plus a rigid spin
 *    (rotations of ~0.5 rad: the quaternion kinematics and the bending and
 *    twist law at large rotation), 1e4 steps, relative drift < 1e-4 for RK4
 *    and for leapfrog (double). */
#include <stdlib.h>

#include "lt_util.h"
#include "solvers/lattice/lattice_ref.h"

static const double h = 1e-3;

/* Cantilever nx x n x n released from its static deflection under a tip
 * load: period of the tip motion from its upward zero crossings. */
static void test_frequency(struct px_context *ctx) {
  int nx = 41, n = 2;
  struct px_lattice_grid g;
  struct px_lattice_model ml, mf;
  struct px_lattice_bc bc[2];
  struct px_lattice_params par = lt_steel();
  struct px_lattice_sel tip = lt_sel_face(PX_LATTICE_FACE_X_MAX);
  struct lt_engine en;
  struct lt_el *y;
  double value, dt, prev = 0.0, tprev = 0.0, first = -1.0, last = -1.0;
  int crossings = 0;
  long s;
  memset(bc, 0, sizeof bc);
  bc[0].sel = lt_sel_face(PX_LATTICE_FACE_X_MIN);
  bc[0].fix = 63;
  bc[1].sel = tip;
  bc[1].has_load = 1;
  bc[1].load[2] = -1.0;
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, nx, n, n, &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &ml, &g, &par, bc, 2));
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, nx, n, n, &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &mf, &g, &par, bc, 1));
  y = (struct lt_el *)malloc(ml.nalloc * sizeof *y);
  /* static deflection */
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &ml, &px_lattice_engine_cpu, PX_LATTICE_INTEGRATOR_LEAPFROG,
                                  PX_PRECISION_DOUBLE, PX_LATTICE_SCHEME_AUTO, 1, NULL, &en));
  dt = 0.9 * px_lattice_model_dt_limit(&ml, PX_LATTICE_INTEGRATOR_LEAPFROG);
  PX_CHECK(lt_relax(ctx, &ml, &en, dt, &tip, 2, 1e-7, 400000, &value, y) > 0);
  lt_engine_free(&en);
  /* release: free vibration, RK4, no damping */
  {
    size_t i;
    for (i = 0; i < ml.nalloc; ++i) {
      y[i].v = lt_v3_make(0, 0, 0);
      y[i].W = lt_v3_make(0, 0, 0);
    }
  }
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &mf, &px_lattice_engine_cpu, PX_LATTICE_INTEGRATOR_RK4,
                                  PX_PRECISION_DOUBLE, PX_LATTICE_SCHEME_AUTO, 1, NULL, &en));
  PX_CHECK_OK(ctx, en.vt->set_state(en.e, y, NULL));
  dt = 0.9 * px_lattice_model_dt_limit(&mf, PX_LATTICE_INTEGRATOR_RK4);
  prev = lt_mean_u(ctx, &mf, y, &tip, 2);
  for (s = 1; crossings < 4 && s < 400000; ++s) {
    double u, t = (double)s * dt * 4.0;
    if (en.vt->run(en.e, 4 * (s - 1), (double)(s - 1) * 4.0 * dt, dt, 4) != PX_STATUS_OK) break;
    en.vt->get_state(en.e, y, NULL);
    u = lt_mean_u(ctx, &mf, y, &tip, 2);
    if (prev < 0.0 && u >= 0.0) {
      double tc = tprev + (t - tprev) * (-prev) / (u - prev);
      if (first < 0.0) first = tc;
      last = tc;
      ++crossings;
    }
    prev = u;
    tprev = t;
  }
  lt_engine_free(&en);
  {
    /* the beam: clamped at the centre of the first layer, free at the outer
     * face of the last, so L = (nx - 1/2) h */
    double L = (nx - 0.5) * h, H = n * h, I = H * H * H * H / 12.0, A = H * H;
    double w1 = 1.8751 * 1.8751 * sqrt(LT_STEEL_E * I / (LT_STEEL_RHO * A * L * L * L * L));
    double period = (last - first) / (crossings - 1), w = 2.0 * 3.14159265358979 / period;
    printf("first bending frequency (%d x %d x %d): %.2f Hz, Euler-Bernoulli %.2f Hz, ratio %.4f\n",
           nx, n, n, w / (2 * 3.14159265358979), w1 / (2 * 3.14159265358979), w / w1);
    PX_CHECK(crossings == 4);
    PX_CHECK_REL(w, w1, 0.02);
  }
  free(y);
  px_lattice_model_free(ctx, &ml);
  px_lattice_model_free(ctx, &mf);
}

/* Bar nx x 2 x 2, force F suddenly applied on the x_min layer: the velocity
 * behind the front is F / (rho c A). The times at which elements k1 and k2
 * reach half of it give the front speed (k2 - k1) h / (t2 - t1), free of the
 * start-up at the loaded end. */
static void test_wave(struct px_context *ctx, enum px_precision p) {
  int nx = 160, n = 2, k1 = 40, k2 = 120, j;
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_bc bc;
  struct px_lattice_params par = lt_steel();
  struct lt_engine en;
  struct lt_el *y;
  double c = sqrt(LT_STEEL_E / LT_STEEL_RHO), F = -1000.0, A = (n * h) * (n * h);
  double vplat = F / (LT_STEEL_RHO * c * A), dt, tprev = 0.0, vprev[2] = {0, 0}, tf[2] = {-1, -1};
  size_t idx[2];
  long s;
  memset(&bc, 0, sizeof bc);
  bc.sel = lt_sel_face(PX_LATTICE_FACE_X_MIN);
  bc.has_load = 1;
  bc.load[0] = F;
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, nx, n, n, &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &m, &g, &par, &bc, 1));
  idx[0] = px_lattice_index(&m, (size_t)k1);
  idx[1] = px_lattice_index(&m, (size_t)k2);
  y = (struct lt_el *)malloc(m.nalloc * sizeof *y);
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_cpu, PX_LATTICE_INTEGRATOR_RK4, p,
                                  PX_LATTICE_SCHEME_AUTO, 1, NULL, &en));
  dt = 0.5 * h / c;
  for (s = 1; s < 1000 && tf[1] < 0.0; ++s) {
    double t = (double)s * dt;
    if (en.vt->run(en.e, s - 1, (double)(s - 1) * dt, dt, 1) != PX_STATUS_OK) break;
    en.vt->get_state(en.e, y, NULL);
    for (j = 0; j < 2; ++j) {
      double v = y[idx[j]].v.x;
      if (tf[j] < 0.0 && v / vplat >= 0.5 && vprev[j] / vplat < 0.5)
        tf[j] = tprev + (t - tprev) * (0.5 * vplat - vprev[j]) / (v - vprev[j]);
      vprev[j] = v;
    }
    tprev = t;
  }
  printf("wave front (%s): %.2f m/s, sqrt(E/rho) = %.2f m/s, ratio %.5f\n",
         p == PX_PRECISION_DOUBLE ? "double" : "single", (k2 - k1) * h / (tf[1] - tf[0]), c,
         (k2 - k1) * h / (tf[1] - tf[0]) / c);
  PX_CHECK(tf[0] > 0.0 && tf[1] > tf[0]);
  PX_CHECK_REL((k2 - k1) * h / (tf[1] - tf[0]), c, 0.02);
  lt_engine_free(&en);
  free(y);
  px_lattice_model_free(ctx, &m);
}

/* Energy of a state on the host (the reference's energy function). */
static double energy_of(struct px_context *ctx, const struct px_lattice_model *m,
                        enum px_lattice_integrator integ, const struct lt_el *y, double t,
                        double dt) {
  struct px_lattice_ref r;
  double k = 0, p = 0;
  if (px_lattice_ref_create(ctx, m, integ, &r) != PX_STATUS_OK) return NAN;
  memcpy(r.y, y, m->nalloc * sizeof *y);
  px_lattice_ref_energy(&r, t, dt, &k, &p);
  px_lattice_ref_free(&r);
  return k + p;
}

static void test_energy(struct px_context *ctx, enum px_lattice_integrator integ) {
  int nx = 48, n = 4;
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_params par = lt_steel();
  struct lt_engine en;
  struct lt_el *y;
  double dt, e0, e1, drift = 0.0, Wz = 500.0;
  size_t c;
  int chunk;
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, nx, n, n, &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &m, &g, &par, NULL, 0));
  y = (struct lt_el *)calloc(m.nalloc, sizeof *y);
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_cpu, integ, PX_PRECISION_DOUBLE,
                                  PX_LATTICE_SCHEME_AUTO, 1, NULL, &en));
  en.vt->get_state(en.e, y, NULL);
  for (c = 0; c < m.grid.ncell; ++c) {
    struct lt_el *e = &y[px_lattice_index(&m, c)];
    double x[3];
    px_lattice_grid_centre(&m.grid, c, x);
    /* rigid spin about the bar's centre line + smooth bending velocity */
    e->W = lt_v3_make(0, 0, Wz);
    e->v = lt_v3_make(-Wz * (x[1] - 0.5 * n * h), Wz * (x[0] - 0.5 * nx * h),
                      0.5 * cos(2.0 * 3.14159265358979 * x[0] / (nx * h)));
  }
  PX_CHECK_OK(ctx, en.vt->set_state(en.e, y, NULL));
  dt = 0.9 * px_lattice_model_dt_limit(&m, integ);
  e0 = energy_of(ctx, &m, integ, y, 0.0, dt);
  for (chunk = 1; chunk <= 10; ++chunk) {
    PX_CHECK_OK(ctx, en.vt->run(en.e, (chunk - 1) * 1000, (chunk - 1) * 1000 * dt, dt, 1000));
    en.vt->get_state(en.e, y, NULL);
    e1 = energy_of(ctx, &m, integ, y, chunk * 1000 * dt, dt);
    drift = fmax(drift, fabs(e1 - e0) / e0);
  }
  printf("energy, %s, 1e4 steps, spin %.2f rad: max relative deviation %.2e\n",
         integ == PX_LATTICE_INTEGRATOR_RK4 ? "rk4" : "leapfrog", Wz * 1e4 * dt, drift);
  PX_CHECK_NEAR(drift, 0.0, 1e-4);
  lt_engine_free(&en);
  free(y);
  px_lattice_model_free(ctx, &m);
}

#include <time.h>
static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Argument: frequency, wave or energy (default: all three; ctest runs them
 * as three tests so that each stays short on a loaded machine). */
int main(int argc, char **argv) {
  struct px_context *ctx;
  const char *part = argc > 1 ? argv[1] : "all";
  int all = strcmp(part, "all") == 0;
  double t0;
  if (!all && strcmp(part, "frequency") != 0 && strcmp(part, "wave") != 0 &&
      strcmp(part, "energy") != 0) {
    fprintf(stderr, "usage: %s [frequency|wave|energy|all]\n", argv[0]);
    return 2;
  }
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  if (all || strcmp(part, "frequency") == 0) {
    t0 = now();
    test_frequency(ctx);
    printf("  (%.1f s)\n", now() - t0);
  }
  if (all || strcmp(part, "wave") == 0) {
    t0 = now();
    test_wave(ctx, PX_PRECISION_DOUBLE);
    test_wave(ctx, PX_PRECISION_SINGLE);
    printf("  (%.1f s)\n", now() - t0);
  }
  if (all || strcmp(part, "energy") == 0) {
    t0 = now();
    test_energy(ctx, PX_LATTICE_INTEGRATOR_RK4);
    test_energy(ctx, PX_LATTICE_INTEGRATOR_LEAPFROG);
    printf("  (%.1f s)\n", now() - t0);
  }
  px_context_free(ctx);
  return px_test_report("test_lattice_dynamic");
}
