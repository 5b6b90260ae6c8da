/* FMM vs direct summation of the 2D vortex velocity: time and error vs N,
 * tolerance, precision and threads. The N vortices act on themselves (the
 * wake's convective velocity). One JSON object per line on stdout.
 *
 *   vortex_fmm [--quick] [--n 1e4,5e4,1e5,1e6] [--tol 1e-3,1e-6,1e-9]
 *              [--precision single|double|all] [--threads 1,2]
 *              [--method direct|fmm|all] [--set uniform|blobs|sheet|wake]
 *              [--reps 5] [--sample 2000] [--direct-max 1e5]
 *              [--order P] [--leaf S] [--err E]
 *
 * seconds: best wall time of up to --reps runs (fewer when the runs exceed
 * ~10 s in total); the machine may be shared, so the best run is the least
 * disturbed one. cpu_seconds: the least process CPU time (all threads) of
 * the runs: with 1 thread, the undisturbed run time on a busy machine.
 * seconds_min/median/max: over the runs (seconds = seconds_min).
 * sum_precision: the arithmetic the sum ran in (the float FMM/direct loops
 * for single, double otherwise; single asked for less than 1e-5 runs at
 * 1e-5). threads_used: the team an OpenMP region of `threads` gets
 * (measured). bytes_per_sum_model: a lower bound of the memory traffic of
 * one sum, the inputs (x, y, gamma) read and outputs (u, v) written once:
 * 5 n reals. rel_l2 and max_rel: relative
 * L2 error and max |Δu| / max |u| over `sample` targets chosen at random (all targets when sample =
 * 0 or >= N), against the double-precision reference sum over all sources (inputs rounded to the
 * tested precision first, so that rounding of the inputs is not counted). Single precision stops at
 * tolerance 1e-5 (px_nbody_set_tolerance rejects less): smaller requested tolerances run once at
 * 1e-5 instead.
 * --order/--leaf/--err replace the parameters that the tolerance rule
 * picks (tuning; --err: truncation target of one interaction, default the
 * tolerance; pairs are accepted when their convergence ratio is at most
 * err^(1/order)). The direct sum runs only up to --direct-max vortices. */
#include <math.h>
#include <time.h>

#include "../tests/nbody_fmm/vortex_sets.h"
#include "bench_util.h"
#include "nbody/nbody_impl.h"

struct px_bench_opts {
  enum px_vset set;
  int reps;
  size_t sample;
  double direct_max;
  int order;
  double leaf;
  double err;
};

/* CPU time of the whole process (all threads), seconds. */
static double px_bench_cpu(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void px_bench_error(size_t n, const double *x, const double *y, const double *g, double eps,
                           size_t ns, const size_t *idx, const double *u, const double *v,
                           double *rel_l2, double *max_rel) {
  double num = 0.0, den = 0.0, emax = 0.0, umax = 0.0;
  size_t k;
  for (k = 0; k < ns; ++k) {
    const size_t i = idx[k];
    double ru, rv, du, dv;
    px_nbody_direct_reference(n, x, y, g, 1, x + i, y + i, eps, &ru, &rv);
    du = u[i] - ru;
    dv = v[i] - rv;
    num += du * du + dv * dv;
    den += ru * ru + rv * rv;
    emax = sqrt(du * du + dv * dv) > emax ? sqrt(du * du + dv * dv) : emax;
    umax = sqrt(ru * ru + rv * rv) > umax ? sqrt(ru * ru + rv * rv) : umax;
  }
  *rel_l2 = den > 0.0 ? sqrt(num / den) : sqrt(num);
  *max_rel = umax > 0.0 ? emax / umax : emax;
}

/* The rule's parameters with the --order/--leaf/--err overrides. */
static void px_bench_params(const struct px_bench_opts *o, enum px_precision p, double tol,
                            struct px_fmm_params *prm) {
  px_fmm_params_for(p, tol, 0, prm);
  if (o->order > 0) prm->order = o->order;
  if (o->err > 0.0) prm->err = o->err;
  if (o->leaf > 0.0) prm->leaf = (size_t)o->leaf;
}

static int px_bench_case(struct px_context *ctx, const struct px_bench_opts *o, size_t n,
                         enum px_precision p, int threads, enum px_nbody_method method, double tol,
                         const double *x0, const double *y0, const double *g0, double eps,
                         const size_t *idx, size_t ns) {
  struct px_backend *be = NULL;
  struct px_nbody *nb = NULL;
  struct px_buffer *b[5] = {NULL, NULL, NULL, NULL, NULL};
  const size_t es = p == PX_PRECISION_SINGLE ? 4 : 8;
  double *x = NULL, *y = NULL, *g = NULL, *u = NULL, *v = NULL;
  void *host = NULL;
  double best = INFINITY, best_cpu = INFINITY, total = 0.0, rel = 0.0, mx = 0.0;
  double *times = malloc((size_t)o->reps * sizeof *times);
  const double load_before = px_bench_load1();
  size_t i;
  int r, runs = 0, ok = 0, k;
  if (px_backend_create(ctx, "cpu", 0, threads, &be) != PX_STATUS_OK) goto done;
  if (px_nbody_create(be, method, p, eps, &nb) != PX_STATUS_OK) goto done;
  if (method == PX_NBODY_METHOD_FMM) {
    if (px_nbody_set_tolerance(nb, tol) != PX_STATUS_OK) goto done;
    if (o->order > 0 || o->leaf > 0.0 || o->err > 0.0) {
      struct px_fmm_params prm;
      px_bench_params(o, p, tol, &prm);
      px_nbody_fmm_override(nb, &prm);
    }
  }
  x = malloc(n * sizeof *x);
  y = malloc(n * sizeof *y);
  g = malloc(n * sizeof *g);
  u = malloc(n * sizeof *u);
  v = malloc(n * sizeof *v);
  host = malloc(n * es);
  if (!x || !y || !g || !u || !v || !host || !times) goto done;
  for (i = 0; i < n; ++i) {
    x[i] = p == PX_PRECISION_SINGLE ? (double)(float)x0[i] : x0[i];
    y[i] = p == PX_PRECISION_SINGLE ? (double)(float)y0[i] : y0[i];
    g[i] = p == PX_PRECISION_SINGLE ? (double)(float)g0[i] : g0[i];
  }
  for (k = 0; k < 5; ++k)
    if (px_buffer_create(be, "bench", n * es, &b[k]) != PX_STATUS_OK) goto done;
  for (k = 0; k < 3; ++k) {
    const double *src = k == 0 ? x : k == 1 ? y : g;
    for (i = 0; i < n; ++i) {
      if (es == 4)
        ((float *)host)[i] = (float)src[i];
      else
        ((double *)host)[i] = src[i];
    }
    if (px_buffer_write(b[k], 0, n * es, host) != PX_STATUS_OK) goto done;
  }
  for (r = 0; r < o->reps && (runs == 0 || total < 10.0); ++r) {
    const double t0 = px_time_now(), c0 = px_bench_cpu();
    double dt, dc;
    if (px_nbody_velocity(nb, n, b[0], b[1], b[2], n, b[0], b[1], PX_NBODY_MODE_SET, b[3], b[4]) !=
        PX_STATUS_OK)
      goto done;
    dt = px_time_now() - t0;
    dc = px_bench_cpu() - c0;
    total += dt;
    times[runs++] = dt;
    if (dt < best) best = dt;
    if (dc < best_cpu) best_cpu = dc;
  }
  for (k = 0; k < 2; ++k) {
    double *dst = k == 0 ? u : v;
    if (px_buffer_read(b[3 + k], 0, n * es, host) != PX_STATUS_OK) goto done;
    for (i = 0; i < n; ++i) dst[i] = es == 4 ? (double)((float *)host)[i] : ((double *)host)[i];
  }
  const double load_after = px_bench_load1();
  const struct px_bench_stats sts = px_bench_stats(times, (size_t)runs);
  px_bench_error(n, x, y, g, eps, ns, idx, u, v, &rel, &mx);
  printf(
      "{\"bench\":\"vortex_fmm\",\"set\":\"%s\",\"method\":\"%s\",\"precision\":\"%s\","
      "\"sum_precision\":\"%s\",\"n\":%zu,\"eps\":%.3e,\"bytes_per_sum_model\":%zu",
      px_vset_name(o->set), px_nbody_method_name(method), px_precision_name(p),
      p == PX_PRECISION_SINGLE ? "float" : "double", n, eps, 5 * n * es);
  px_bench_json_env(stdout, threads, px_bench_threads_used(threads), load_before, load_after);
  if (method == PX_NBODY_METHOD_FMM) {
    const struct px_fmm_stats *st = px_nbody_fmm_stats(nb);
    struct px_fmm_params prm;
    px_bench_params(o, p, tol, &prm);
    printf(",\"tolerance\":%.0e,\"order\":%d,\"err\":%.1e,\"rho\":%.3f,\"leaf\":%zu", tol,
           prm.order, prm.err, exp(log(prm.err) / (double)prm.order), prm.leaf);
    printf(
        ",\"cells\":%zu,\"m2l\":%zu,\"p2l\":%zu,\"m2p\":%zu,\"p2p_pairs\":%.4e,"
        "\"m2l_terms\":%.4e,\"t_tree\":%.5f,\"t_up\":%.5f,\"t_down\":%.5f",
        st->src_cells, st->m2l, st->p2l, st->m2p, st->p2p_pairs, st->m2l_terms, st->t_tree,
        st->t_up, st->t_down);
  }
  printf(
      ",\"runs\":%d,\"seconds\":%.6f,\"seconds_min\":%.6f,\"seconds_median\":%.6f,"
      "\"seconds_max\":%.6f,\"cpu_seconds\":%.6f,\"sample\":%zu,\"rel_l2\":%.3e,"
      "\"max_rel\":%.3e}\n",
      runs, best, sts.min, sts.median, sts.max, best_cpu, ns, rel, mx);
  fflush(stdout);
  ok = 1;
done:
  if (!ok)
    fprintf(stderr, "vortex_fmm n=%zu %s %s: %s: %s\n", n, px_nbody_method_name(method),
            px_precision_name(p), px_status_name(px_context_status(ctx)), px_context_message(ctx));
  free(times);
  for (k = 0; k < 5; ++k) px_buffer_free(b[k]);
  px_nbody_free(nb);
  px_backend_free(be);
  free(x);
  free(y);
  free(g);
  free(u);
  free(v);
  free(host);
  return ok;
}

int main(int argc, char **argv) {
  struct px_context *ctx = NULL;
  struct px_bench_opts o;
  double ns[8] = {1e4, 5e4, 1e5, 1e6}, tols[8] = {1e-3, 1e-6, 1e-9}, threads[8] = {1, 2};
  int nn = 4, ntol = 3, nt = 2, i, failures = 0, a, t, k, m;
  const char *precision = "all", *method = "all";
  o.set = PX_VSET_UNIFORM;
  o.reps = 5;
  o.sample = 2000;
  o.direct_max = 1e5;
  o.order = 0;
  o.leaf = 0.0;
  o.err = 0.0;
  for (i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--quick") == 0) {
      ns[0] = 2e3;
      ns[1] = 2e4;
      nn = 2;
      o.reps = 2;
      o.sample = 500;
    } else if (strcmp(argv[i], "--n") == 0 && i + 1 < argc) {
      nn = px_bench_list(argv[++i], ns, 8);
    } else if (strcmp(argv[i], "--tol") == 0 && i + 1 < argc) {
      ntol = px_bench_list(argv[++i], tols, 8);
    } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
      nt = px_bench_list(argv[++i], threads, 8);
    } else if (strcmp(argv[i], "--precision") == 0 && i + 1 < argc) {
      precision = argv[++i];
    } else if (strcmp(argv[i], "--method") == 0 && i + 1 < argc) {
      method = argv[++i];
    } else if (strcmp(argv[i], "--set") == 0 && i + 1 < argc) {
      if (px_vset_parse(argv[++i], &o.set)) {
        fprintf(stderr, "unknown set '%s' (uniform, blobs, sheet, wake)\n", argv[i]);
        return 2;
      }
    } else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) {
      o.reps = atoi(argv[++i]);
    } else if (strcmp(argv[i], "--sample") == 0 && i + 1 < argc) {
      o.sample = (size_t)atof(argv[++i]);
    } else if (strcmp(argv[i], "--direct-max") == 0 && i + 1 < argc) {
      o.direct_max = atof(argv[++i]);
    } else if (strcmp(argv[i], "--order") == 0 && i + 1 < argc) {
      o.order = atoi(argv[++i]);
    } else if (strcmp(argv[i], "--leaf") == 0 && i + 1 < argc) {
      o.leaf = atof(argv[++i]);
    } else if (strcmp(argv[i], "--err") == 0 && i + 1 < argc) {
      o.err = atof(argv[++i]);
    } else {
      fprintf(stderr,
              "usage: %s [--quick] [--n N,..] [--tol T,..] [--precision single|double|all] "
              "[--threads T,..] [--method direct|fmm|all] [--set uniform|blobs|sheet|wake] "
              "[--reps K] [--sample M] [--direct-max N] [--order P] [--leaf S] "
              "[--err E]\n",
              argv[0]);
      return 2;
    }
  }
  if (o.reps < 1) o.reps = 1;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  for (a = 0; a < nn; ++a) {
    const size_t n = (size_t)ns[a];
    double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y), *g = malloc(n * sizeof *g);
    size_t *idx, nsamp = o.sample == 0 || o.sample >= n ? n : o.sample, j;
    uint64_t rng[PX_RNG_WORDS];
    double eps;
    idx = malloc((nsamp ? nsamp : 1) * sizeof *idx);
    if (!x || !y || !g || !idx) return 1;
    eps = px_vset_make(o.set, n, 1234, x, y, g);
    px_rng_seed(rng, 99);
    for (j = 0; j < nsamp; ++j)
      idx[j] = nsamp == n ? j : (size_t)(px_rng_uniform(rng) * (double)n) % n;
    for (k = 0; k < 2; ++k) {
      const enum px_precision p = k == 0 ? PX_PRECISION_SINGLE : PX_PRECISION_DOUBLE;
      if (strcmp(precision, "all") != 0 && strcmp(precision, px_precision_name(p)) != 0 &&
          !(p == PX_PRECISION_SINGLE && strcmp(precision, "float") == 0))
        continue;
      for (t = 0; t < nt; ++t) {
        for (m = 0; m < 2; ++m) {
          const enum px_nbody_method me = m == 0 ? PX_NBODY_METHOD_DIRECT : PX_NBODY_METHOD_FMM;
          if (strcmp(method, "all") != 0 && strcmp(method, px_nbody_method_name(me)) != 0) continue;
          if (me == PX_NBODY_METHOD_DIRECT) {
            if ((double)n > o.direct_max) continue;
            failures +=
                !px_bench_case(ctx, &o, n, p, (int)threads[t], me, 0.0, x, y, g, eps, idx, nsamp);
          } else {
            int q, floor_done = 0;
            for (q = 0; q < ntol; ++q) {
              double tol = tols[q];
              if (p == PX_PRECISION_SINGLE && tol < 1e-5) {
                /* single precision stops at 1e-5: run that once instead */
                if (floor_done) continue;
                tol = 1e-5;
                floor_done = 1;
              }
              failures +=
                  !px_bench_case(ctx, &o, n, p, (int)threads[t], me, tol, x, y, g, eps, idx, nsamp);
            }
          }
        }
      }
    }
    free(x);
    free(y);
    free(g);
    free(idx);
  }
  px_context_free(ctx);
  return failures ? 1 : 0;
}
