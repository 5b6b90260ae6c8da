/* Benchmark of one vortex-solver time step at the size of the original
 * paper's headline (N ~ 50,000 wake vortices, n = 2576 panels): time per step
 * and per block, per backend and precision, and memory per vortex.
 *
 *   vortex_step [N] [panels] [backend] [precision] [threads] [steps] [method] [tolerance]
 *               [scheme] [vvd_moments]
 *
 * defaults 50000 2576 cpu mixed 2 3 auto 1e-6 euler none (method: direct | fmm | auto,
 * the case key vortex.velocity.method; scheme: euler | rk2, vortex.scheme, whose
 * second stage counts in the move block; vvd_moments: none | wake | covariance,
 * vortex.vvd_moments). The wake is synthetic but shaped like a
 * real one: a boundary layer of jittered rows around a NACA 0012 (chord 1)
 * and a widening wake behind it, with circulations of both signs; the merge
 * radius is set below the spacing so that N stays as built. One step is run
 * first to warm up (tree, buffers); the next `steps` are timed. Prints one
 * JSON object per line: wall seconds per step and block, and process CPU
 * seconds (all threads; on a shared machine the undisturbed cost: with one
 * thread, the time the step takes on a free core). sum_rel_l2, sum_max_rel: error of the method's
 * velocity sum at 2000 sampled vortices after the run (relative L2 and max
 * |du| / max |u| against the plain double sum over all vortices).
 * What ran: storage_precision is that of the wake arrays (always double on
 * the host); pair_sum_precision is that of the convective pair sums (direct
 * or FMM), the engine's nb_prec: double for `double`, float for `single` and
 * `mixed` except that an FMM asked for a tolerance below 1e-5 sums in double
 * (px_vortex_core_create), so `single` at the default 1e-6 runs a double
 * FMM: such a row's `precision` reads `single+fmm_double` (`mixed+fmm_double`),
 * not `single`. The float FMM runs at tolerances from 1e-5 (docs/fmm.md,
 * its error table). step_s_min/median/max: over the timed steps. threads: 0 (or
 * "auto") runs on all cores with the thread tuner (core/tuner.h) choosing 1
 * or all per step, as `partix run` does with backend.threads 0; tuner:
 * "tune" or "fixed", parallel_step_fraction: the share of the timed steps
 * run on more than one thread, threads_used_mean = 1 + (threads_used - 1) x
 * that share. threads_used: the team an OpenMP region of `threads` gets
 * (measured). bytes_per_step_model:
 * a lower bound of the memory traffic, the engine's allocated memory
 * (px_mem_current) read once per step, but the dense panel inverse where
 * the solve reads its compressed copy; a model, not a count.
 * panel_solve_s: the generation's solve alone (median of 21) by the inverse
 * the engine uses (panel_inverse: compressed, dense; float_lu in single
 * precision, not timed: null), panel_solve_dense_s by the dense one,
 * panel_inverse_bytes the size of the one used. convective_extended_fraction:
 * the share of the timed steps' convective sums that extended the
 * generation's FMM sum (px_nbody_velocity_extend) rather than running whole
 * (null where none ran on the cpu engine). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "partix/partix.h"
#include "partix/backend.h"
#include "solvers/vortex/vortex_core.h"

static double urand(unsigned long long *s) {
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*s >> 11) / 9007199254740992.0;
}

int main(int argc, char **argv) {
  size_t N = argc > 1 ? (size_t)atol(argv[1]) : 50000;
  size_t n = argc > 2 ? (size_t)atol(argv[2]) : 2576;
  const char *bname = argc > 3 ? argv[3] : "cpu";
  const char *pname = argc > 4 ? argv[4] : "mixed";
  /* 0 or "auto": all cores, the count used tuned per step (core/tuner.h),
   * as `partix run` with backend.threads 0 */
  int threads = argc > 5 ? atoi(argv[5]) : 2;
  int steps = argc > 6 ? atoi(argv[6]) : 3;
  const char *mname = argc > 7 ? argv[7] : "auto";
  double tol = argc > 8 ? atof(argv[8]) : 1e-6;
  const char *scheme = argc > 9 ? argv[9] : "euler";
  if (strcmp(scheme, "euler") != 0 && strcmp(scheme, "rk2") != 0) {
    fprintf(stderr, "unknown scheme %s (euler or rk2)\n", scheme);
    return 2;
  }
  const char *moments = argc > 10 ? argv[10] : "none";
  int mi = 0;
  while (px_vortex_moment_names[mi] && strcmp(moments, px_vortex_moment_names[mi]) != 0) ++mi;
  if (!px_vortex_moment_names[mi]) {
    fprintf(stderr, "unknown vvd_moments %s (choices:", moments);
    for (int k = 0; px_vortex_moment_names[k]; ++k)
      fprintf(stderr, " %s", px_vortex_moment_names[k]);
    fprintf(stderr, ")\n");
    return 2;
  }
  enum px_nbody_method method;
  if (px_nbody_method_parse(mname, &method) != PX_STATUS_OK) {
    fprintf(stderr, "unknown method %s\n", mname);
    return 2;
  }
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  enum px_precision prec;
  if (px_precision_parse(pname, &prec) != PX_STATUS_OK) {
    fprintf(stderr, "unknown precision %s\n", pname);
    return 2;
  }
  struct px_backend *be = NULL;
  if (px_backend_create(ctx, bname, px_backend_default_device(bname), threads, &be) !=
      PX_STATUS_OK) {
    fprintf(stderr, "%s\n", px_context_message(ctx));
    return 77;
  }
  struct px_vortex_contour c;
  if (px_vortex_profile_naca4(ctx, "0012", n + (n % 2), &c) != PX_STATUS_OK) return 1;
  px_vortex_profile_place(&c, 0.0, 0.0, 1.0, 5.0);
  struct px_vortex_config cfg;
  px_vortex_config_defaults(&cfg);
  cfg.nu = 1e-4;
  cfg.vinf[0] = 1.0;
  cfg.vref = 1.0;
  double L = 2.04 / (double)n;
  cfg.dt = L;
  cfg.eps = 0.5 * L;
  cfg.eps_col = 0.05 * L;
  cfg.eps_min = 0.1 * L;
  cfg.gamma_max = 1.0; /* no splitting: the warm-up step adds n vortices */
  cfg.delta = 1e-4 * L;
  cfg.dist_far = 30.0;
  cfg.threads = px_backend_threads(be);
  cfg.tune = px_backend_threads_auto(be);
  cfg.precision = prec;
  cfg.method = method;
  cfg.tolerance = tol;
  cfg.rk2 = strcmp(scheme, "rk2") == 0;
  cfg.vvd_moments = mi;
  cfg.ref_length[0] = 1.0;
  struct px_vortex_engine *e = NULL;
  double t0 = px_time_now();
  if (px_vortex_engine_create(ctx, be, &cfg, &c, 1, &e) != PX_STATUS_OK) {
    fprintf(stderr, "%s\n", px_context_message(ctx));
    return 1;
  }
  double t_setup = px_time_now() - t0;
  /* synthetic wake: 60% in a boundary layer band, 40% in the wake */
  double *x = malloc(3 * N * sizeof(double)), *y = x + N, *g = y + N;
  unsigned long long seed = 12345;
  size_t nbl = N * 6 / 10, k = 0;
  size_t rows = 12, per_row = nbl / rows;
  for (size_t r = 0; r < rows && k < nbl; ++r)
    for (size_t q = 0; q < per_row && k < nbl; ++q, ++k) {
      size_t pk = (q * c.n) / per_row, pj = (pk + 1) % c.n;
      double f = urand(&seed);
      double px = c.x[pk] + f * (c.x[pj] - c.x[pk]), py = c.y[pk] + f * (c.y[pj] - c.y[pk]);
      double tx = c.x[pj] - c.x[pk], ty = c.y[pj] - c.y[pk], tl = hypot(tx, ty);
      double h = (0.5 + (double)r + 0.3 * (urand(&seed) - 0.5)) * 0.004;
      x[k] = px + h * ty / tl;
      y[k] = py - h * tx / tl;
      g[k] = (py > 0 ? -1.0 : 1.0) * 1e-5 * (1.0 + urand(&seed));
    }
  for (; k < N; ++k) {
    double s = urand(&seed), xw = 1.05 + 9.0 * s * s;
    double wdt = 0.02 + 0.08 * (xw - 1.0);
    double yy = wdt * (urand(&seed) - 0.5) * 2.0 - 0.09;
    x[k] = xw;
    y[k] = yy;
    g[k] = (yy > -0.09 ? -1.0 : 1.0) * 2e-5 * urand(&seed);
  }
  if (px_vortex_engine_add(e, N, x, y, g) != PX_STATUS_OK) return 1;
  free(x);
  /* warm-up step, then keep N about constant: the step adds n newborn
   * vortices that the timed steps carry */
  if (px_vortex_engine_step(e) != PX_STATUS_OK) {
    fprintf(stderr, "%s\n", px_context_message(ctx));
    return 1;
  }
  double blocks0[PX_VORTEX_BLOCK_COUNT_];
  memcpy(blocks0, e->block_time, sizeof blocks0);
  double cpu0[PX_VORTEX_BLOCK_COUNT_];
  memcpy(cpu0, e->block_cpu, sizeof cpu0);
  double diff0[2];
  memcpy(diff0, e->diffusive_time, sizeof diff0);
  size_t n_start = e->w.n;
  struct timespec c0, c1;
  double *step_t = malloc((size_t)(steps > 0 ? steps : 1) * sizeof *step_t);
  const double load_before = px_bench_load1();
  const long tuned0 = e->tuner.steps, par0 = e->tuner.steps_parallel;
  const long conv0 = e->conv_sums, ext0 = e->conv_extended;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
  t0 = px_time_now();
  for (int s = 0; s < steps; ++s) {
    const double ts = px_time_now();
    if (px_vortex_engine_step(e) != PX_STATUS_OK) {
      fprintf(stderr, "%s\n", px_context_message(ctx));
      return 1;
    }
    step_t[s] = px_time_now() - ts;
  }
  double per = (px_time_now() - t0) / steps;
  const double load_after = px_bench_load1();
  const struct px_bench_stats st = px_bench_stats(step_t, (size_t)steps);
  free(step_t);
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
  double cpu = ((double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec)) / steps;
  size_t mem = px_mem_current(ctx, NULL), matrix = px_mem_current(ctx, "vortex.matrix");
  /* a single or mixed row whose FMM summed in double (tolerance < 1e-5) is
   * not labelled `single` / `mixed`: its sums, the bulk of the step, are
   * those of `double` (issue 22) */
  char plabel[48];
  snprintf(plabel, sizeof plabel, "%s%s", pname,
           prec != PX_PRECISION_DOUBLE && e->nb_prec == PX_PRECISION_DOUBLE ? "+fmm_double" : "");
  printf(
      "{\"bench\":\"vortex_step\",\"backend\":\"%s\",\"device\":\"%s\",\"precision\":\"%s\","
      "\"method\":\"%s\",\"used\":\"%s\",\"tolerance\":%g,\"scheme\":\"%s\",\"vvd_moments\":\"%s\","
      "\"storage_precision\":\"double\",\"pair_sum_precision\":\"%s\","
      "\"N\":%zu,\"N_end\":%zu,\"panels\":%zu,\"steps\":%d,\"setup_s\":%.3f,"
      "\"step_s\":%.4f,\"step_s_min\":%.4f,\"step_s_median\":%.4f,\"step_s_max\":%.4f,"
      "\"step_cpu_s\":%.4f",
      bname, px_backend_device(be), plabel, mname,
      px_nbody_method_name(e->nbe ? px_nbody_last_method(e->nbe) : PX_NBODY_METHOD_DIRECT), tol,
      scheme, moments, px_precision_name(e->nb_prec), n_start, e->w.n, e->pan.n, steps, t_setup,
      per, st.min, st.median, st.max, cpu);
  {
    /* the share of the timed steps run on more than one thread */
    const int most = e->nthreads;
    const long ts = e->tuner.steps - tuned0;
    const double frac = px_tuner_tuning(&e->tuner) && ts > 0
                            ? (double)(e->tuner.steps_parallel - par0) / (double)ts
                            : (most > 1 ? 1.0 : 0.0);
    printf(",\"tuner\":\"%s\",\"parallel_step_fraction\":%.3f,\"threads_used_mean\":%.3f",
           px_tuner_tuning(&e->tuner) ? "tune" : "fixed", frac, 1.0 + (most - 1) * frac);
  }
  px_bench_json_env(stdout, threads, px_bench_threads_used(threads), load_before, load_after);
  for (int b = 0; b < PX_VORTEX_BLOCK_COUNT_; ++b)
    printf(",\"%s_s\":%.4f", px_vortex_block_name((enum px_vortex_block)b),
           (e->block_time[b] - blocks0[b]) / steps);
  if (strcmp(bname, "cpu") == 0) {
    for (int b = 0; b < PX_VORTEX_BLOCK_COUNT_; ++b)
      printf(",\"%s_cpu_s\":%.4f", px_vortex_block_name((enum px_vortex_block)b),
             (e->block_cpu[b] - cpu0[b]) / steps);
    /* the diffusive block's parts */
    static const char *const part[2] = {"tree", "vvd"};
    for (int q = 0; q < 2; ++q)
      printf(",\"diffusive_%s_s\":%.4f", part[q], (e->diffusive_time[q] - diff0[q]) / steps);
  }
  /* accuracy of the velocity sums of this method: the pair sum at 2000
   * sampled vortices against the plain double reference over all vortices */
  double rel_l2 = 0.0, max_rel = 0.0;
  size_t nonfinite = 0;
  {
    size_t ns = e->w.n < 2000 ? e->w.n : 2000;
    double *sx = malloc(6 * ns * sizeof(double)), *sy = sx + ns, *su = sy + ns, *sv = su + ns;
    double *ru = sv + ns, *rv = ru + ns;
    for (size_t q = 0; q < ns; ++q) {
      size_t i = (q * 7919) % e->w.n;
      sx[q] = e->w.x[i];
      sy[q] = e->w.y[i];
    }
    double vx, vy;
    px_vortex_vinf(&e->cfg, e->time, &vx, &vy);
    if (px_vortex_engine_velocity(e, ns, sx, sy, su, sv) != PX_STATUS_OK) return 1;
    px_nbody_direct_reference(e->w.n, e->w.x, e->w.y, e->w.g, ns, sx, sy, e->cfg.eps, ru, rv);
    double num = 0.0, den = 0.0, emax = 0.0, umax = 0.0;
    for (size_t q = 0; q < ns; ++q) {
      double du = su[q] - vx - ru[q], dv = sv[q] - vy - rv[q];
      if (!isfinite(du) || !isfinite(dv)) { /* counted and reported, not summed */
        ++nonfinite;
        continue;
      }
      num += du * du + dv * dv;
      den += ru[q] * ru[q] + rv[q] * rv[q];
      emax = fmax(emax, hypot(du, dv));
      umax = fmax(umax, hypot(ru[q], rv[q]));
    }
    rel_l2 = sqrt(num / den);
    max_rel = emax / umax;
    free(sx);
  }
  /* a NaN or infinite velocity at a sample (seen once, on an NVIDIA H200 at
     N = 52,559, not on POCL) is counted in sum_nonfinite, and the JSON stays
     valid: null where no finite error exists */
  if (isfinite(rel_l2))
    printf(",\"sum_rel_l2\":%.2e,\"sum_max_rel\":%.2e", rel_l2, max_rel);
  else
    printf(",\"sum_rel_l2\":null,\"sum_max_rel\":null");
  printf(",\"sum_nonfinite\":%zu", nonfinite);
  /* FNV-1a over the wake's bytes: identical arithmetic gives the same hash */
  unsigned long long hsh = 1469598103934665603ULL;
  const double *arrs[3] = {e->w.x, e->w.y, e->w.g};
  for (int a = 0; a < 3; ++a) {
    const unsigned char *bytes = (const unsigned char *)arrs[a];
    for (size_t q = 0; q < e->w.n * sizeof(double); ++q) hsh = (hsh ^ bytes[q]) * 1099511628211ULL;
  }
  printf(",\"wake_hash\":\"%016llx\"", hsh);
  /* the generation's solve alone (median of 21), by the compressed inverse
   * where the engine made one (px_vortex_panels_compress) and by the dense
   * one: the per-step model reads only the one the solve uses */
  struct px_vortex_panels *pp = &e->pan;
  size_t dense = pp->nsys * pp->nsys * sizeof(double), read = mem;
  double solve[2] = {NAN, NAN};
  double *rhs = malloc(2 * pp->nsys * sizeof(double)), ts[21];
  for (int which = 0; which < 2 && rhs && prec != PX_PRECISION_SINGLE; ++which) {
    for (int r = 0; r < 21; ++r) {
      for (size_t i = 0; i < pp->nsys; ++i) rhs[i] = 1.0 / (1.0 + (double)i);
      const double a = px_time_now();
      if (which == 0)
        px_vortex_panels_solve(ctx, pp, rhs, threads);
      else
        px_vortex_panels_dense_product(pp, rhs, rhs + pp->nsys, threads);
      ts[r] = px_time_now() - a;
    }
    solve[which] = px_bench_stats(ts, 21).median;
  }
  free(rhs);
  if (pp->hodlr) read -= dense;
  /* the share of the timed convective sums that extended the generation's
   * FMM sum (its tree and multipoles kept; null: none ran, other engines) */
  if (e->conv_sums > conv0)
    printf(",\"convective_extended_fraction\":%.3f",
           (double)(e->conv_extended - ext0) / (double)(e->conv_sums - conv0));
  else
    printf(",\"convective_extended_fraction\":null");
  if (prec == PX_PRECISION_SINGLE) /* the engine solves by its float LU: not timed */
    printf(",\"panel_solve_s\":null,\"panel_solve_dense_s\":null,\"panel_inverse\":\"float_lu\"");
  else
    printf(
        ",\"panel_solve_s\":%.2e,\"panel_solve_dense_s\":%.2e,\"panel_inverse\":\"%s\","
        "\"panel_inverse_bytes\":%zu",
        solve[0], solve[1], pp->hodlr ? "compressed" : "dense",
        pp->hodlr ? px_vortex_hodlr_bytes(pp->hodlr) : dense);
  printf(
      ",\"bytes_total\":%zu,\"bytes_matrix\":%zu,\"bytes_per_vortex\":%.1f,"
      "\"bytes_per_step_model\":%zu}\n",
      mem, matrix, (double)(mem - matrix) / (double)e->w.n, read);
  px_vortex_engine_free(e);
  px_vortex_contour_free(ctx, &c);
  px_backend_free(be);
  px_context_free(ctx);
  return 0;
}
