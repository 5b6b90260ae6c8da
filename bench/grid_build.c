/* Neighbour-grid build benchmark: cell index, stable sort and cell ranges of
 * N particles uniform in the unit square (2D) or cube (3D), about one
 * particle per cell (the granular solver's situation: cell = diameter).
 * One JSON object per line; seconds = best of --reps builds,
 * particles_per_s = N / seconds; seconds_min/median/max over the builds;
 * threads_used: the team an OpenMP region of the backend's threads gets
 * (measured; cpu backend); bytes_per_build_model: the positions read once,
 * dims N reals (a lower bound, a model); load1_before/after, cpu_model:
 * bench_util.h.
 *
 *   grid_build [--quick] [--n 10000,100000,1000000] [--dims 2,3]
 *              [--backend cpu|opencl|all] [--precision single|double|all]
 *              [--threads 1,2] [--reps 5] */
#include <math.h>

#include "bench_util.h"

static int px_bench_grid(struct px_context *ctx, const char *backend, int threads,
                         enum px_precision p, int dims, size_t n, int reps) {
  struct px_backend *be = NULL;
  struct px_buffer *pos[3] = {NULL, NULL, NULL};
  struct px_grid *g = NULL;
  const size_t es = p == PX_PRECISION_SINGLE ? 4 : 8;
  const double origin[3] = {0.0, 0.0, 0.0};
  size_t cells[3] = {1, 1, 1}, i;
  double best = INFINITY, h, load0 = px_bench_load1();
  double *times = malloc((size_t)(reps > 0 ? reps : 1) * sizeof *times);
  uint64_t rng[PX_RNG_WORDS];
  unsigned char *host;
  int a, r, ok = 0;
  cells[0] = (size_t)ceil(pow((double)n, 1.0 / dims));
  for (a = 1; a < dims; ++a) cells[a] = cells[0];
  h = 1.0 / (double)cells[0];
  if (px_backend_create(ctx, backend, px_backend_default_device(backend), threads, &be) !=
      PX_STATUS_OK)
    goto fail;
  if (px_backend_require(be, p) != PX_STATUS_OK) goto fail;
  host = malloc(n * es);
  px_rng_seed(rng, 7);
  for (a = 0; a < dims; ++a) {
    for (i = 0; i < n; ++i) {
      const double val = px_rng_uniform(rng);
      if (es == 4)
        ((float *)(void *)host)[i] = (float)val;
      else
        ((double *)(void *)host)[i] = val;
    }
    if (px_buffer_create(be, "pos", n * es, &pos[a]) != PX_STATUS_OK ||
        px_buffer_write(pos[a], 0, n * es, host) != PX_STATUS_OK) {
      free(host);
      goto fail;
    }
  }
  free(host);
  if (px_grid_create(be, dims, origin, h, cells, &g) != PX_STATUS_OK) goto fail;
  /* warm-up: programs, buffers sized */
  if (px_grid_build(g, p, n, pos[0], pos[1], pos[2]) != PX_STATUS_OK ||
      px_backend_finish(be) != PX_STATUS_OK)
    goto fail;
  for (r = 0; r < reps; ++r) {
    const double t0 = px_time_now();
    double dt;
    if (px_grid_build(g, p, n, pos[0], pos[1], pos[2]) != PX_STATUS_OK ||
        px_backend_finish(be) != PX_STATUS_OK)
      goto fail;
    dt = px_time_now() - t0;
    if (times) times[r] = dt;
    if (dt < best) best = dt;
  }
  const double load1 = px_bench_load1();
  const struct px_bench_stats st = px_bench_stats(times, times ? (size_t)reps : 0);
  printf("{\"bench\":\"grid_build\",\"backend\":");
  px_bench_json_string(stdout, backend);
  printf(",\"device\":");
  px_bench_json_string(stdout, px_backend_device(be));
  printf(
      ",\"precision\":\"%s\",\"dims\":%d,\"n\":%zu,\"cells\":%zu,"
      "\"runs\":%d,\"seconds\":%.6f,\"seconds_min\":%.6f,\"seconds_median\":%.6f,"
      "\"seconds_max\":%.6f,\"particles_per_s\":%.4e,\"bytes_per_build_model\":%zu",
      px_precision_name(p), dims, n, px_grid_cell_count(g), reps, best, st.min, st.median, st.max,
      (double)n / best, (size_t)dims * n * es);
  px_bench_json_env(stdout, px_backend_threads(be),
                    strcmp(backend, "cpu") == 0 ? px_bench_threads_used(px_backend_threads(be)) : 0,
                    load0, load1);
  printf("}\n");
  fflush(stdout);
  ok = 1;
fail:
  free(times);
  if (!ok)
    fprintf(stderr, "grid_build %s %s n=%zu: %s: %s\n", backend, px_precision_name(p), n,
            px_status_name(px_context_status(ctx)), px_context_message(ctx));
  px_grid_free(g);
  for (a = 0; a < 3; ++a) px_buffer_free(pos[a]);
  px_backend_free(be);
  return ok;
}

int main(int argc, char **argv) {
  struct px_context *ctx = NULL;
  double ns[8] = {1e4, 1e5, 1e6}, threads[8] = {1, 2}, dims[3] = {2, 3};
  int nn = 3, nt = 2, nd = 2, reps = 5, i, failures = 0;
  const char *backend = "all", *precision = "all";
  const char *const *names;
  for (i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--quick") == 0) {
      ns[0] = 1e4;
      ns[1] = 1e5;
      nn = 2;
      reps = 3;
    } else if (strcmp(argv[i], "--n") == 0 && i + 1 < argc) {
      nn = px_bench_list(argv[++i], ns, 8);
    } else if (strcmp(argv[i], "--dims") == 0 && i + 1 < argc) {
      nd = px_bench_list(argv[++i], dims, 3);
    } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
      nt = px_bench_list(argv[++i], threads, 8);
    } else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) {
      reps = atoi(argv[++i]);
    } else if (strcmp(argv[i], "--backend") == 0 && i + 1 < argc) {
      backend = argv[++i];
    } else if (strcmp(argv[i], "--precision") == 0 && i + 1 < argc) {
      precision = argv[++i];
    } else {
      fprintf(stderr,
              "usage: %s [--quick] [--n N,..] [--dims 2,3] [--backend cpu|opencl|all] "
              "[--precision single|double|all] [--threads T,..] [--reps K]\n",
              argv[0]);
      return 2;
    }
  }
  if (reps < 1) reps = 1;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  for (names = px_backend_names(); *names; ++names) {
    int pi, ti, ni, di;
    const int cpu = strcmp(*names, "cpu") == 0;
    if (strcmp(backend, "all") != 0 && strcmp(backend, *names) != 0) continue;
    if (!cpu && px_backend_opencl_device_count(ctx) == 0) continue;
    for (pi = 0; pi < 2; ++pi) {
      const enum px_precision p = pi ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
      if (strcmp(precision, "all") != 0 && strcmp(precision, px_precision_name(p)) != 0) continue;
      for (ti = 0; ti < (cpu ? nt : 1); ++ti)
        for (di = 0; di < nd; ++di)
          for (ni = 0; ni < nn; ++ni)
            failures += !px_bench_grid(ctx, *names, cpu ? (int)threads[ti] : 0, p, (int)dims[di],
                                       (size_t)ns[ni], reps);
    }
  }
  px_context_free(ctx);
  return failures ? 1 : 0;
}
