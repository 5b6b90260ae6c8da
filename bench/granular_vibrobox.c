/* The 2D vibrating box of bench/granular_vs_lammps.sh run by partix: the
 * same discs, stiffness, restitution, friction, time step and vibration as
 * /work/shared/research/lammps_vibro2d.in (LAMMPS gran/hooke/history):
 *
 *   d = 4 mm (+-10 % uniform), rho = 2500 kg/m^3, disc thickness d,
 *   kn = 2e5 N/m, kt = 2/7 kn, e = 0.8, mu = 0.4, gamma_t = gamma_n / 2,
 *   box L = 1.25 nx d wide, H = 3 ny d tall, moving on the circle
 *   x = A sin(wt), y = A sin(wt + pi/2), A = 2 mm, 25 Hz, g = 9.81,
 *   dt = t_c / 25 of two mean discs; N = (nx-1)(ny-1) discs on a square
 *   lattice of spacing 1.2 d.
 *
 * Usage: granular_vibrobox [nx ny nsettle nsteps threads precision integrator tune]
 * tune: "tune" (default: the run-time thread tuner may drop to one thread
 * when that is faster, as in `partix run`) or "fixed" (always `threads`).
 * Prints one JSON line: disc-steps/s over the timed window after settling
 * (and its min/median/max over the window's 5 blocks of steps, each timed),
 * the fraction of timed steps that ran on more than one thread, the
 * 1-minute load average before and after the timed window, and the time of
 * a neighbour-list rebuild (cell sort, reordering, pair and wall lists) of
 * the final state: best and mean of 20 forced rebuilds [ms], and the best
 * process cpu time of one (all threads; steadier on a shared machine).
 * threads_requested: the `threads` argument; threads_used: the team size a
 * parallel step gets (measured for the solver's thread count, which
 * px_gran_sys_prepare caps at what N discs can use); parallel_step_fraction: the fraction of
 * timed steps the tuner ran on more than one thread, and threads_used_mean
 * = 1 + (threads_used - 1) * that fraction. sum_precision: the arithmetic of
 * the contact sums (the `precision` argument: single, double, or mixed =
 * float contact forces on a double state (cpu_mixed.c)). bytes_per_step_model: a lower
 * bound of the memory traffic, the solver's allocated state (px_mem_current)
 * read once per step; it is a model, not a count. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "partix/partix.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/system.h"

#define PI 3.14159265358979323846

int main(int argc, char **argv) {
  const int nx = argc > 1 ? atoi(argv[1]) : 100, ny = argc > 2 ? atoi(argv[2]) : 100;
  const long nsettle = argc > 3 ? atol(argv[3]) : 150000, nsteps = argc > 4 ? atol(argv[4]) : 20000;
  const int threads = argc > 5 ? atoi(argv[5]) : 2;
  const char *prec_name = argc > 6 ? argv[6] : "double";
  const char *integ = argc > 7 ? argv[7] : "verlet";
  const int tune = !(argc > 8 && strcmp(argv[8], "fixed") == 0);
  const double d = 0.004, rho = 2500, A = 0.002, f = 25.0;
  const double L = nx * d * 1.25, H = ny * d * 3.0;
  struct px_context *ctx = NULL;
  struct px_gran_geom g;
  struct px_gran_motion mo;
  struct px_gran_sys *s = NULL;
  struct px_geo_path path;
  struct px_geo_prim q;
  enum px_precision prec;
  uint64_t rng[4];
  double meff, w0, zeta, gn, tc, dt, t0, t1, rmin = 1;
  int i, j;
  long k;
  if (nx < 2 || ny < 2 || nsettle < 0 || nsteps < 1 || threads < 1) {
    fprintf(stderr, "granular_vibrobox: nx, ny >= 2, nsettle >= 0, nsteps >= 1, threads >= 1\n");
    return 2;
  }
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  if (px_precision_parse(prec_name, &prec) != PX_STATUS_OK) {
    fprintf(stderr, "precision: single, double or mixed\n");
    return 2;
  }
  /* the box: 4 lines, split into segments of about the smallest radius */
  px_gran_geom_init(&g);
  px_geo_path_init(&path, "box");
  memset(&q, 0, sizeof q);
  q.kind = PX_GEO_PRIM_LINE;
  q.p[0] = 0, q.p[1] = 0, q.p[2] = L, q.p[3] = 0;
  px_geo_path_add(ctx, &path, &q);
  q.p[0] = L, q.p[1] = 0, q.p[2] = L, q.p[3] = H;
  px_geo_path_add(ctx, &path, &q);
  q.p[0] = L, q.p[1] = H, q.p[2] = 0, q.p[3] = H;
  px_geo_path_add(ctx, &path, &q);
  q.p[0] = 0, q.p[1] = H, q.p[2] = 0, q.p[3] = 0;
  px_geo_path_add(ctx, &path, &q);
  if (px_gran_geom_add_path(ctx, &g, &path, 0.45 * d, 1e-9, "box", 0, PX_GRAN_SIDE_AUTO) ||
      px_gran_geom_finish(ctx, &g, 2 * d)) {
    fprintf(stderr, "%s\n", px_context_message(ctx));
    return 1;
  }
  px_geo_path_free(ctx, &path);
  px_gran_motion_init(&mo);
  mo.kind = PX_GRAN_MOTION_HARMONIC;
  mo.amp[0] = A, mo.amp[1] = A;
  mo.freq[0] = f, mo.freq[1] = f;
  mo.phase[0] = 0, mo.phase[1] = PI / 2;

  if (px_gran_sys_create(ctx, prec, threads, &s) != PX_STATUS_OK) return 1;
  s->tune = tune;
  s->integrator = strcmp(integ, "abm4") == 0 ? PX_GRAN_INTEGRATOR_ABM4 : PX_GRAN_INTEGRATOR_VERLET;
  memset(&s->pp, 0, sizeof s->pp);
  s->pp.normal = PX_GRAN_NORMAL_LINEAR;
  s->pp.tangential = PX_GRAN_TANGENTIAL_SPRING;
  s->pp.kn = 2e5;
  s->pp.e = 0.8;
  s->pp.kt_ratio = 2.0 / 7.0;
  s->pp.ct_ratio = 0.5;
  s->pp.mu = 0.4;
  s->pw = s->pp;
  s->gravity[1] = -9.81;
  s->skin = 0.2 * d; /* LAMMPS: neighbor 0.2 d bin */
  px_gran_sys_set_walls(s, &g, &mo, 1);
  px_rng_seed(rng, 12345);
  for (j = 1; j < ny; ++j)
    for (i = 1; i < nx; ++i) {
      double x = i * 1.2 * d, y = j * 1.2 * d;
      double r = 0.5 * d * (0.9 + 0.2 * px_rng_uniform(rng));
      double m = rho * d * PI * r * r;
      if (r < rmin) rmin = r;
      px_gran_sys_add(s, 1, &x, &y, &r, &m);
    }
  /* dt = t_c / 25 of two mean discs, as in the LAMMPS input */
  meff = 0.5 * rho * d * PI * (0.5 * d) * (0.5 * d);
  w0 = sqrt(2e5 / meff);
  zeta = -log(0.8) / sqrt(PI * PI + log(0.8) * log(0.8));
  gn = 2 * zeta * w0;
  tc = PI / sqrt(w0 * w0 - 0.25 * gn * gn);
  dt = tc / 25;
  if (px_gran_sys_prepare(s, dt, 0) != PX_STATUS_OK) {
    fprintf(stderr, "%s\n", px_context_message(ctx));
    return 1;
  }
  for (k = 0; k < nsettle; ++k)
    if (px_gran_sys_step(s) != PX_STATUS_OK) {
      fprintf(stderr, "settling, step %ld: %s\n", k, px_context_message(ctx));
      return 1;
    }
  {
    const long rb0 = s->rebuilds, par0 = s->steps_parallel;
    const size_t np0 = s->npairs;
    const double load0 = px_bench_load1();
    double reb_best = INFINITY, reb_sum = 0, reb_cpu = INFINITY;
    struct timespec c0, c1;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
    /* the timed steps in 5 blocks, each timed: the spread of the rate */
    double brate[5];
    struct px_bench_stats bst;
    const int nblk = nsteps < 5 ? (int)nsteps : 5;
    t0 = px_time_now();
    for (int b = 0; b < nblk; ++b) {
      const long ka = nsteps * b / nblk, kb = nsteps * (b + 1) / nblk;
      const double tb = px_time_now();
      for (k = ka; k < kb; ++k)
        if (px_gran_sys_step(s) != PX_STATUS_OK) {
          fprintf(stderr, "step %ld: %s\n", k, px_context_message(ctx));
          return 1;
        }
      brate[b] = (double)s->n * (double)(kb - ka) / (px_time_now() - tb);
    }
    t1 = px_time_now();
    bst = px_bench_stats(brate, (size_t)nblk);
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
    for (k = 0; k < 20; ++k) {
      const double r0 = px_time_now();
      struct timespec q0, q1;
      double dr, dc;
      clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &q0);
      if (px_gran_sys_rebuild(s) != PX_STATUS_OK) {
        fprintf(stderr, "rebuild: %s\n", px_context_message(ctx));
        return 1;
      }
      dr = px_time_now() - r0;
      clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &q1);
      dc = (double)(q1.tv_sec - q0.tv_sec) + 1e-9 * (double)(q1.tv_nsec - q0.tv_nsec);
      reb_sum += dr;
      if (dr < reb_best) reb_best = dr;
      if (dc < reb_cpu) reb_cpu = dc;
    }
    {
      const double load_after = px_bench_load1();
      const int used = px_bench_threads_used(s->threads);
      const double pfrac = (double)(s->steps_parallel - par0) / (double)nsteps;
      const double wall = t1 - t0;
      const double cpu = (double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec);
      printf(
          "{\"bench\":\"granular_vibrobox\",\"code\":\"partix\",\"n\":%zu,\"steps\":%ld,"
          "\"precision\":\"%s\",\"sum_precision\":\"%s\",\"integrator\":\"%s\","
          "\"dt\":%.6g,\"seconds\":%.4f,\"cpu_seconds\":%.4f,\"disc_steps_per_s\":%.4g,"
          "\"disc_steps_per_s_min\":%.4g,\"disc_steps_per_s_median\":%.4g,"
          "\"disc_steps_per_s_max\":%.4g,\"blocks\":%d,"
          "\"disc_steps_per_cpu_s\":%.4g,\"rebuilds\":%ld,\"pairs_per_disc\":%.3f,"
          "\"segments\":%zu,\"near_wall\":%zu,\"tuner\":\"%s\","
          "\"parallel_step_fraction\":%.3f,\"threads_used_mean\":%.3f,"
          "\"bytes_per_step_model\":%zu",
          s->n, nsteps, prec_name,
          prec == PX_PRECISION_MIXED ? "float contact forces, double state" : prec_name, integ, dt,
          wall, cpu, (double)s->n * (double)nsteps / wall, bst.min, bst.median, bst.max, nblk,
          (double)s->n * (double)nsteps / cpu, s->rebuilds - rb0, (double)np0 / (double)s->n,
          g.nseg, s->nnear, tune ? "tune" : "fixed", pfrac, 1.0 + (used - 1) * pfrac,
          px_mem_current(ctx, NULL));
      px_bench_json_env(stdout, threads, used, load0, load_after);
      printf(",\"rebuild_ms_best\":%.4g,\"rebuild_ms_mean\":%.4g,\"rebuild_cpu_ms_best\":%.4g}\n",
             1e3 * reb_best, 1e3 * reb_sum / 20, 1e3 * reb_cpu);
    }
  }
  px_gran_sys_free(s);
  px_gran_geom_free(ctx, &g);
  px_context_free(ctx);
  return 0;
}
