/* Writing speed of the output writers for one frame of a large run:
 * a .vtp of 1e6 2D particles (f64 points from x[], y[], a scalar and a
 * 2-component vector interleaved on the fly) and a 50k-point PNG snapshot.
 * Usage: bench_io_vtk [N] [DIR]. Prints one JSON object per line; bytes is
 * counted (the file's size); the writers are serial (threads 1); the load
 * average is read before and after each write (bench_util.h). */
#include <stdio.h>
#include <stdlib.h>

#include "bench_util.h"
#include "partix/partix.h"
#include "partix/figure.h"
#include "partix/vtk.h"

int main(int argc, char **argv) {
  size_t n = argc > 1 ? (size_t)strtoull(argv[1], NULL, 10) : 1000000, i;
  const char *dir = argc > 2 ? argv[2] : ".";
  struct px_context *ctx = NULL;
  struct px_vtk *v = NULL;
  struct px_figure *fig = NULL;
  double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y), *g = malloc(n * sizeof *g);
  double *u = malloc(n * sizeof *u), *w = malloc(n * sizeof *w), t0, dt, load0, load1;
  char path[4096];
  FILE *f;
  long bytes = 0;
  uint64_t rng[PX_RNG_WORDS];
  if (!x || !y || !g || !u || !w || px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_rng_seed(rng, 1);
  for (i = 0; i < n; ++i) {
    x[i] = px_rng_normal(rng);
    y[i] = px_rng_normal(rng);
    g[i] = px_rng_normal(rng) * 1e-3;
    u[i] = -y[i];
    w[i] = x[i];
  }
  px_file_join(ctx, path, sizeof path, dir, "bench_io_vtk.vtp");
  px_vtk_create(ctx, &v);
  px_vtk_set_points(v, PX_DTYPE_F64, n, x, y, NULL);
  px_vtk_add_vertices(v);
  px_vtk_add_scalar(v, PX_VTK_ASSOC_POINT, "Gamma", PX_DTYPE_F64, n, g);
  px_vtk_add_vector(v, PX_VTK_ASSOC_POINT, "velocity", PX_DTYPE_F64, n, u, w, NULL);
  load0 = px_bench_load1();
  t0 = px_time_now();
  if (px_vtk_write(v, path) != PX_STATUS_OK) {
    fprintf(stderr, "%s\n", px_context_message(ctx));
    return 1;
  }
  dt = px_time_now() - t0;
  load1 = px_bench_load1();
  f = fopen(path, "rb");
  if (f) {
    fseek(f, 0, SEEK_END);
    bytes = ftell(f);
    fclose(f);
  }
  remove(path);
  printf(
      "{\"bench\": \"vtk_write_vtp\", \"particles\": %zu, \"bytes\": %ld, \"seconds\": %.4f, "
      "\"MB_per_s\": %.1f",
      n, bytes, dt, (double)bytes / dt / 1e6);
  px_bench_json_env(stdout, 1, 1, load0, load1);
  printf("}\n");
  px_vtk_free(v);

  px_file_join(ctx, path, sizeof path, dir, "bench_io_png.png");
  px_figure_create(ctx, 1200, 800, &fig);
  px_figure_set_colormap(fig, PX_COLORMAP_COOLWARM);
  px_figure_add_points(fig, PX_DTYPE_F64, n < 50000 ? n : 50000, x, y, g, 2.0);
  load0 = px_bench_load1();
  t0 = px_time_now();
  if (px_figure_write_png(fig, path) != PX_STATUS_OK) {
    fprintf(stderr, "%s\n", px_context_message(ctx));
    return 1;
  }
  dt = px_time_now() - t0;
  remove(path);
  load1 = px_bench_load1();
  printf("{\"bench\": \"png_snapshot_points\", \"points\": %zu, \"seconds\": %.4f",
         n < 50000 ? n : 50000, dt);
  px_bench_json_env(stdout, 1, 1, load0, load1);
  printf("}\n");
  px_figure_free(fig);
  px_context_free(ctx);
  free(x), free(y), free(g), free(u), free(w);
  return 0;
}
