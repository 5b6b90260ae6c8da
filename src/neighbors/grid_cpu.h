/* Template of the cpu grid loops that depend on the coordinate precision;
 * instantiated by grid_cpu_f32.c and grid_cpu_f64.c. */
#include "kernels/grid.h"
#include "neighbors/grid_impl.h"

void PX_SFX(px_grid_cpu_cells)(int threads, const struct px_grid *g, const px_real *x,
                               const px_real *y, const px_real *z, uint32_t *cell) {
  const size_t n = g->n;
  const px_real ox = (px_real)g->origin[0], oy = (px_real)g->origin[1];
  const px_real oz = (px_real)g->origin[2], inv_h = (px_real)g->inv_h;
  const int nx = g->cells[0], ny = g->cells[1], nz = g->cells[2];
  if (g->dims == 2) {
#pragma omp parallel for simd num_threads(threads) schedule(static) if (n > 32768)
    for (size_t i = 0; i < n; ++i)
      cell[i] = (uint32_t)px_grid_cell_2d(x[i], y[i], ox, oy, inv_h, nx, ny);
  } else {
#pragma omp parallel for simd num_threads(threads) schedule(static) if (n > 32768)
    for (size_t i = 0; i < n; ++i)
      cell[i] = (uint32_t)px_grid_cell_3d(x[i], y[i], z[i], ox, oy, oz, inv_h, nx, ny, nz);
  }
}

void PX_SFX(px_grid_cpu_count)(int threads, const struct px_grid *g, const px_real *x,
                               const px_real *y, const px_real *z, double range, uint32_t *out) {
  const size_t n = g->n;
  const px_real range2 = (px_real)(range * range);
  const uint32_t *cell = g->cell->host, *perm = g->perm->host;
  const uint32_t *start = g->start->host, *end = g->end->host;
  const int nx = g->cells[0], ny = g->cells[1], nz = g->cells[2];
  if (g->dims == 2) {
#pragma omp parallel for num_threads(threads) schedule(dynamic, 256) if (n > 4096)
    for (size_t i = 0; i < n; ++i)
      out[i] = px_grid_count_2d((unsigned int)i, range2, x, y, cell, perm, start, end, nx, ny);
  } else {
#pragma omp parallel for num_threads(threads) schedule(dynamic, 256) if (n > 4096)
    for (size_t i = 0; i < n; ++i)
      out[i] =
          px_grid_count_3d((unsigned int)i, range2, x, y, z, cell, perm, start, end, nx, ny, nz);
  }
}
