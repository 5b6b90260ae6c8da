/* Direct 2D Biot–Savart sum benchmark: N vortices acting on themselves
 * (N² pairs, the vortex solver's convective velocity), per backend,
 * precision, thread count and work-group/tile width. One JSON object per
 * line on stdout; seconds = best of up to --reps runs (fewer when a run is
 * long), pairs_per_s = N² / seconds; seconds_min/median/max over the runs;
 * sum_precision: float for single, double for double; threads_used: the team
 * an OpenMP region of the backend's threads gets (measured; cpu backend);
 * bytes_per_sum_model: inputs (x, y, gamma) read and outputs (u, v) written
 * once, 5 N reals (a lower bound, a model); load1_before/after, cpu_model:
 * bench_util.h.
 *
 *   nbody_direct [--quick] [--n 10000,50000] [--backend cpu|opencl|all]
 *                [--precision single|double|all] [--threads 1,2]
 *                [--workgroup 0,64,128] [--reps 3] [--separate]
 *
 * --separate: N targets distinct from the N sources (the general path; by
 * default the sources act on themselves, which the cpu backend evaluates
 * pair-symmetrically).
 * workgroup 0 = automatic: cpu tiles of 24 KiB of sources (2048 float,
 * 1024 double), opencl work-groups of 128. */
#include <math.h>

#include "bench_util.h"

static int g_separate = 0;

static int px_bench_run(struct px_context *ctx, const char *backend, int threads,
                        enum px_precision p, size_t n, size_t workgroup, int reps) {
  struct px_backend *be = NULL;
  struct px_buffer *x = NULL, *y = NULL, *g = NULL, *u = NULL, *v = NULL;
  struct px_buffer *tx = NULL, *ty = NULL;
  const size_t es = p == PX_PRECISION_SINGLE ? 4 : 8;
  double best = INFINITY, total = 0.0, eps = 1e-3, load0 = px_bench_load1();
  double *times = malloc((size_t)(reps > 0 ? reps : 1) * sizeof *times);
  uint64_t rng[PX_RNG_WORDS];
  unsigned char *host;
  size_t i;
  int r, runs = 0, ok = 0;
  if (px_backend_create(ctx, backend, px_backend_default_device(backend), threads, &be) !=
      PX_STATUS_OK)
    goto fail;
  if (px_backend_require(be, p) != PX_STATUS_OK) goto fail;
  if (px_backend_set_workgroup(be, workgroup) != PX_STATUS_OK) goto fail;
  if (px_buffer_create(be, "x", n * es, &x) || px_buffer_create(be, "y", n * es, &y) ||
      px_buffer_create(be, "gamma", n * es, &g) || px_buffer_create(be, "u", n * es, &u) ||
      px_buffer_create(be, "v", n * es, &v))
    goto fail;
  if (g_separate) {
    if (px_buffer_create(be, "tx", n * es, &tx) || px_buffer_create(be, "ty", n * es, &ty))
      goto fail;
  }
  host = malloc(n * es);
  px_rng_seed(rng, 42);
  for (r = 0; r < 3; ++r) {
    for (i = 0; i < n; ++i) {
      const double val = r == 2 ? px_rng_uniform(rng) - 0.5 : px_rng_uniform(rng);
      if (es == 4)
        ((float *)(void *)host)[i] = (float)val;
      else
        ((double *)(void *)host)[i] = val;
    }
    if (px_buffer_write(r == 0 ? x : r == 1 ? y : g, 0, n * es, host) != PX_STATUS_OK) {
      free(host);
      goto fail;
    }
  }
  if (g_separate) {
    /* targets: the sources' coordinates swapped (a different point set) */
    if (px_buffer_copy(tx, 0, y, 0, n * es) || px_buffer_copy(ty, 0, x, 0, n * es)) {
      free(host);
      goto fail;
    }
  } else {
    tx = x;
    ty = y;
  }
  free(host);
  /* warm-up: builds the OpenCL program, touches the memory */
  if (px_nbody_direct(be, p, n < 256 ? n : 256, x, y, g, n < 256 ? n : 256, tx, ty, eps,
                      PX_NBODY_MODE_SET, u, v) != PX_STATUS_OK ||
      px_backend_finish(be) != PX_STATUS_OK)
    goto fail;
  for (r = 0; r < reps && (runs == 0 || total < 6.0); ++r) {
    const double t0 = px_time_now();
    double dt;
    if (px_nbody_direct(be, p, n, x, y, g, n, tx, ty, eps, PX_NBODY_MODE_SET, u, v) !=
            PX_STATUS_OK ||
        px_backend_finish(be) != PX_STATUS_OK)
      goto fail;
    dt = px_time_now() - t0;
    total += dt;
    if (times) times[runs] = dt;
    ++runs;
    if (dt < best) best = dt;
  }
  const double load1 = px_bench_load1();
  const struct px_bench_stats st = px_bench_stats(times, times ? (size_t)runs : 0);
  printf("{\"bench\":\"nbody_direct\",\"backend\":");
  px_bench_json_string(stdout, backend);
  printf(",\"device\":");
  px_bench_json_string(stdout, px_backend_device(be));
  printf(
      ",\"precision\":\"%s\",\"sum_precision\":\"%s\",\"n\":%zu,\"targets\":\"%s\","
      "\"workgroup\":%zu,\"runs\":%d,\"seconds\":%.6f,\"seconds_min\":%.6f,"
      "\"seconds_median\":%.6f,\"seconds_max\":%.6f,\"pairs_per_s\":%.4e,"
      "\"bytes_per_sum_model\":%zu",
      px_precision_name(p), p == PX_PRECISION_SINGLE ? "float" : "double", n,
      g_separate ? "separate" : "self", workgroup, runs, best, st.min, st.median, st.max,
      (double)n * (double)n / best, 5 * n * es);
  px_bench_json_env(stdout, px_backend_threads(be),
                    strcmp(backend, "cpu") == 0 ? px_bench_threads_used(px_backend_threads(be)) : 0,
                    load0, load1);
  printf("}\n");
  fflush(stdout);
  ok = 1;
fail:
  free(times);
  if (!ok)
    fprintf(stderr, "nbody_direct %s %s n=%zu: %s: %s\n", backend, px_precision_name(p), n,
            px_status_name(px_context_status(ctx)), px_context_message(ctx));
  px_buffer_free(x);
  px_buffer_free(y);
  px_buffer_free(g);
  px_buffer_free(u);
  px_buffer_free(v);
  if (g_separate) {
    px_buffer_free(tx);
    px_buffer_free(ty);
  }
  px_backend_free(be);
  return ok;
}

int main(int argc, char **argv) {
  struct px_context *ctx = NULL;
  double ns[8] = {1e4, 5e4, 1e5}, threads[8] = {1, 2}, wgs[8] = {0};
  int nn = 3, nt = 2, nw = 1, reps = 3, i, failures = 0;
  const char *backend = "all", *precision = "all";
  const char *const *names;
  for (i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--quick") == 0) {
      ns[0] = 2e3;
      ns[1] = 1e4;
      nn = 2;
      reps = 2;
    } else if (strcmp(argv[i], "--n") == 0 && i + 1 < argc) {
      nn = px_bench_list(argv[++i], ns, 8);
    } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
      nt = px_bench_list(argv[++i], threads, 8);
    } else if (strcmp(argv[i], "--workgroup") == 0 && i + 1 < argc) {
      const char *s = argv[++i];
      nw = strcmp(s, "0") == 0 ? 1 : px_bench_list(s, wgs, 8);
      if (strcmp(s, "0") == 0) wgs[0] = 0;
    } else if (strcmp(argv[i], "--separate") == 0) {
      g_separate = 1;
    } else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) {
      reps = atoi(argv[++i]);
    } else if (strcmp(argv[i], "--backend") == 0 && i + 1 < argc) {
      backend = argv[++i];
    } else if (strcmp(argv[i], "--precision") == 0 && i + 1 < argc) {
      precision = argv[++i];
    } else {
      fprintf(stderr,
              "usage: %s [--quick] [--n N,..] [--backend cpu|opencl|all] "
              "[--precision single|double|all] [--threads T,..] [--workgroup W,..] [--reps K] "
              "[--separate]\n",
              argv[0]);
      return 2;
    }
  }
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  for (names = px_backend_names(); *names; ++names) {
    int pi, ti, ni, wi;
    if (strcmp(backend, "all") != 0 && strcmp(backend, *names) != 0) continue;
    if (strcmp(*names, "opencl") == 0 && px_backend_opencl_device_count(ctx) == 0) continue;
    for (pi = 0; pi < 2; ++pi) {
      const enum px_precision p = pi ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
      if (strcmp(precision, "all") != 0 && strcmp(precision, px_precision_name(p)) != 0) continue;
      /* host threads only matter to cpu loops */
      for (ti = 0; ti < (strcmp(*names, "cpu") == 0 ? nt : 1); ++ti)
        for (wi = 0; wi < nw; ++wi)
          for (ni = 0; ni < nn; ++ni)
            failures +=
                !px_bench_run(ctx, *names, strcmp(*names, "cpu") == 0 ? (int)threads[ti] : 0, p,
                              (size_t)ns[ni], (size_t)wgs[wi], reps);
    }
  }
  px_context_free(ctx);
  return failures ? 1 : 0;
}
