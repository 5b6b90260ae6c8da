/* Accuracy vs cost of the granular integrators on the validation cases:
 * velocity Verlet (with the dashpot onset/end correction) and the original
 * Adams-Bashforth-Moulton 4 predictor-corrector (two force evaluations per
 * step). For each integrator and resolution (steps per contact):
 *   - restitution error of a head-on two-disc impact, worst over e in
 *     {0.2, 0.5, 0.8} and 5 contact phases within a step;
 *   - contact-time error (same runs);
 *   - relative energy drift of an elastic frictionless gas of 100 discs in a
 *     box over 20 000 steps (kinetic + elastic);
 *   - force evaluations per contact time (the cost), and the CPU time of
 *     the gas run per step (one thread).
 * One JSON line per (integrator, resolution); every line also carries
 * sum_precision (double: the runs use PX_PRECISION_DOUBLE), threads_requested
 * / threads_used (1: the system is created with one thread) and the load
 * average before and after the timed gas run (bench_util.h). This decides the default
 * (docs/granular.md). */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "partix/partix.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/system.h"

#define PI 3.14159265358979323846

static double cpu_seconds(void) {
  struct timespec c;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c);
  return (double)c.tv_sec + 1e-9 * (double)c.tv_nsec;
}

static void law(struct px_gran_law_spec *L, double e, double mu) {
  memset(L, 0, sizeof *L);
  L->normal = PX_GRAN_NORMAL_LINEAR;
  L->tangential = PX_GRAN_TANGENTIAL_SPRING;
  L->kn = 2e5;
  L->e = e;
  L->kt_ratio = 1.0 / 3.0;
  L->ct_ratio = 0.5;
  L->mu = mu;
}

static void two_discs(struct px_context *ctx, enum px_gran_integrator it, double e, double spc,
                      double gap, double *eerr, double *terr) {
  const double R = 0.002, m = 1.26e-4, v0 = 0.5;
  double x[2] = {-R - 0.5 * gap, R + 0.5 * gap}, y[2] = {0, 0}, r[2] = {R, R}, mm[2] = {m, m};
  struct px_gran_sys *s = NULL;
  double prev = -1, ts = -1, te = -1, a[8], b[8], tref;
  long k;
  px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s);
  law(&s->pp, e, 0.5);
  s->integrator = it;
  px_gran_sys_add(s, 2, x, y, r, mm);
  px_gran_sys_set_velocity(s, 0, v0, 0, 0);
  px_gran_sys_set_velocity(s, 1, -v0, 0, 0);
  px_gran_sys_prepare(s, 0, spc);
  tref = px_gran_sys_contact_time(s);
  for (k = 0; k < 200000; ++k) {
    double d;
    px_gran_sys_step(s);
    px_gran_sys_get(s, 0, a);
    px_gran_sys_get(s, 1, b);
    d = 2 * R - (b[0] - a[0]);
    if (prev <= 0 && d > 0 && ts < 0) ts = s->t - s->dt * d / (d - prev);
    if (prev > 0 && d <= 0 && ts >= 0) te = s->t - s->dt * d / (d - prev);
    if (prev <= 0 && d <= 0 && te >= 0) break;
    prev = d;
  }
  *eerr = (b[2] - a[2]) / (2 * v0) / e - 1;
  *terr = (te - ts) / tref - 1;
  px_gran_sys_free(s);
}

int main(void) {
  struct px_context *ctx = NULL;
  const double spcs[] = {20.3, 30.3, 50.3, 80.3, 120.3, 200.3, 400.3};
  const double es[] = {0.2, 0.5, 0.8};
  int it, k;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  for (it = 0; it < 2; ++it)
    for (k = 0; k < (int)(sizeof spcs / sizeof spcs[0]); ++k) {
      const enum px_gran_integrator in = it ? PX_GRAN_INTEGRATOR_ABM4 : PX_GRAN_INTEGRATOR_VERLET;
      double we = 0, wt = 0, drift = 0, t0, t1, load0 = -1, load1 = -1;
      int q, p;
      for (q = 0; q < 3; ++q)
        for (p = 0; p < 5; ++p) {
          double ee, tt;
          two_discs(ctx, in, es[q], spcs[k], 0.4e-3 + 1e-7 * p * 1.37, &ee, &tt);
          if (fabs(ee) > fabs(we)) we = ee;
          if (fabs(tt) > fabs(wt)) wt = tt;
        }
      {
        /* elastic gas in a box */
        struct px_gran_geom g;
        struct px_geo_path path;
        struct px_geo_prim pr;
        struct px_gran_sys *s = NULL;
        uint64_t rng[4];
        double e0 = 0;
        long st;
        int i, j;
        px_gran_geom_init(&g);
        px_geo_path_init(&path, "box");
        memset(&pr, 0, sizeof pr);
        pr.kind = PX_GEO_PRIM_LINE;
        pr.p[0] = 0, pr.p[1] = 0, pr.p[2] = 0.06, pr.p[3] = 0;
        px_geo_path_add(ctx, &path, &pr);
        pr.p[0] = 0.06, pr.p[1] = 0, pr.p[2] = 0.06, pr.p[3] = 0.06;
        px_geo_path_add(ctx, &path, &pr);
        pr.p[0] = 0.06, pr.p[1] = 0.06, pr.p[2] = 0, pr.p[3] = 0.06;
        px_geo_path_add(ctx, &path, &pr);
        pr.p[0] = 0, pr.p[1] = 0.06, pr.p[2] = 0, pr.p[3] = 0;
        px_geo_path_add(ctx, &path, &pr);
        px_gran_geom_add_path(ctx, &g, &path, 0.0018, 1e-9, "box", 0, PX_GRAN_SIDE_AUTO);
        px_geo_path_free(ctx, &path);
        px_gran_geom_finish(ctx, &g, 0.008);
        px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s);
        s->integrator = in;
        law(&s->pp, 1.0, 0.0);
        law(&s->pw, 1.0, 0.0);
        px_gran_sys_set_walls(s, &g, NULL, 0);
        px_rng_seed(rng, 7);
        for (j = 0; j < 10; ++j)
          for (i = 0; i < 10; ++i) {
            double x = 0.005 + 0.0055 * i, y = 0.005 + 0.0055 * j, r = 0.002, m = 1.26e-4;
            px_gran_sys_add(s, 1, &x, &y, &r, &m);
            px_gran_sys_set_velocity(s, (int32_t)s->n - 1, 0.5 * (2 * px_rng_uniform(rng) - 1),
                                     0.5 * (2 * px_rng_uniform(rng) - 1), 0);
          }
        px_gran_sys_prepare(s, 0, spcs[k]);
        e0 = px_gran_sys_kinetic(s) + s->ops->elastic(s);
        load0 = px_bench_load1();
        t0 = cpu_seconds(); /* one thread: CPU time is robust to a shared machine */
        for (st = 0; st < 20000; ++st) {
          px_gran_sys_step(s);
          if (st % 500 == 499) {
            const double e1 = px_gran_sys_kinetic(s) + s->ops->elastic(s);
            if (fabs(e1 / e0 - 1) > drift) drift = fabs(e1 / e0 - 1);
          }
        }
        t1 = cpu_seconds();
        load1 = px_bench_load1();
        px_gran_sys_free(s);
        px_gran_geom_free(ctx, &g);
      }
      printf(
          "{\"bench\":\"granular_integrators\",\"integrator\":\"%s\",\"steps_per_contact\":%.1f,"
          "\"force_evaluations_per_contact\":%.1f,\"restitution_error_max\":%.3g,"
          "\"contact_time_error_max\":%.3g,\"energy_drift_20000_steps\":%.3g,"
          "\"gas_us_per_step\":%.2f,\"sum_precision\":\"double\"",
          it ? "abm4" : "verlet", spcs[k], (it ? 2 : 1) * spcs[k], we, wt, drift,
          (t1 - t0) / 20000 * 1e6);
      px_bench_json_env(stdout, 1, px_bench_threads_used(1), load0, load1);
      printf("}\n");
      fflush(stdout);
    }
  px_context_free(ctx);
  return 0;
}
