/* Uniform-grid cell index and the neighbour-iteration pattern, written once
 * for the cpu loops and the OpenCL programs (include/partix/neighbors.h
 * describes the grid).
 *
 * The cell coordinate multiplies by the reciprocal cell size (computed once
 * on the host in double, then rounded to px_real) instead of dividing:
 * OpenCL's single-precision division is not correctly rounded (2.5 ulp
 * allowed), multiplication and subtraction are, so the cell of every point
 * is bit-identical on every backend. */
#ifndef PX_KERNELS_GRID_H
#define PX_KERNELS_GRID_H

#include "kernels/px_kernel.h"

/* Cell coordinate along one axis: clamp(floor((x − origin)·inv_h), 0, n − 1).
 * Points below the grid and NaN go to 0, points above to n − 1 (compared in
 * px_real before converting, so huge coordinates never overflow an int).
 * Clamping before the conversion makes truncation equal floor (no floor
 * call), and the selects keep it branch-free: clang and OpenCL compilers
 * vectorize the loop over particles; gcc 12 keeps it scalar under its
 * default -ftrapping-math (a few ns per particle, small next to the sort). */
PX_FN int px_grid_axis(px_real x, px_real origin, px_real inv_h, int n) {
  px_real s = (x - origin) * inv_h;
  s = s >= PX_R(0.0) ? s : PX_R(0.0); /* also NaN -> 0 */
  s = s < (px_real)n ? s : (px_real)(n - 1);
  return (int)s; /* truncation: floor, since s >= 0 here */
}

/* Flattened cell index, x fastest. */
PX_FN int px_grid_cell_2d(px_real x, px_real y, px_real ox, px_real oy, px_real inv_h, int nx,
                          int ny) {
  return px_grid_axis(y, oy, inv_h, ny) * nx + px_grid_axis(x, ox, inv_h, nx);
}

PX_FN int px_grid_cell_3d(px_real x, px_real y, px_real z, px_real ox, px_real oy, px_real oz,
                          px_real inv_h, int nx, int ny, int nz) {
  return (px_grid_axis(z, oz, inv_h, nz) * ny + px_grid_axis(y, oy, inv_h, ny)) * nx +
         px_grid_axis(x, ox, inv_h, nx);
}

/* ---------------------------------------------------------------------------
 * The neighbour-iteration pattern. Copy this loop into a force kernel: for
 * particle i, visit the 3x3 block of cells around its cell (skipping those
 * outside the grid), and in each cell the particles perm[start[c]..end[c]).
 * Here the positions are read in particle order through perm; after
 * px_grid_reorder of the particle data into cell order, use k directly as
 * the particle index instead (contiguous reads, the point of reordering).
 * Returns the number of j != i with |r_i − r_j|² < range2. */
PX_FN unsigned int px_grid_count_2d(const unsigned int i, const px_real range2,
                                    const PX_GLOBAL px_real *x, const PX_GLOBAL px_real *y,
                                    const PX_GLOBAL unsigned int *cell,
                                    const PX_GLOBAL unsigned int *perm,
                                    const PX_GLOBAL unsigned int *start,
                                    const PX_GLOBAL unsigned int *end, const int nx, const int ny) {
  const px_real xi = x[i], yi = y[i];
  const int c = (int)cell[i], cx = c % nx, cy = c / nx;
  unsigned int count = 0;
  int ix, iy;
  for (iy = cy - 1; iy <= cy + 1; ++iy) {
    if (iy < 0 || iy >= ny) continue;
    for (ix = cx - 1; ix <= cx + 1; ++ix) {
      const int c2 = iy * nx + ix;
      unsigned int k;
      if (ix < 0 || ix >= nx) continue;
      for (k = start[c2]; k < end[c2]; ++k) {
        const unsigned int j = perm[k];
        const px_real dx = x[j] - xi, dy = y[j] - yi;
        if (j != i && dx * dx + dy * dy < range2) ++count;
      }
    }
  }
  return count;
}

/* The same over the 3x3x3 block in 3D. */
PX_FN unsigned int px_grid_count_3d(const unsigned int i, const px_real range2,
                                    const PX_GLOBAL px_real *x, const PX_GLOBAL px_real *y,
                                    const PX_GLOBAL px_real *z, const PX_GLOBAL unsigned int *cell,
                                    const PX_GLOBAL unsigned int *perm,
                                    const PX_GLOBAL unsigned int *start,
                                    const PX_GLOBAL unsigned int *end, const int nx, const int ny,
                                    const int nz) {
  const px_real xi = x[i], yi = y[i], zi = z[i];
  const int c = (int)cell[i], cx = c % nx, cy = (c / nx) % ny, cz = c / (nx * ny);
  unsigned int count = 0;
  int ix, iy, iz;
  for (iz = cz - 1; iz <= cz + 1; ++iz) {
    if (iz < 0 || iz >= nz) continue;
    for (iy = cy - 1; iy <= cy + 1; ++iy) {
      if (iy < 0 || iy >= ny) continue;
      for (ix = cx - 1; ix <= cx + 1; ++ix) {
        const int c2 = (iz * ny + iy) * nx + ix;
        unsigned int k;
        if (ix < 0 || ix >= nx) continue;
        for (k = start[c2]; k < end[c2]; ++k) {
          const unsigned int j = perm[k];
          const px_real dx = x[j] - xi, dy = y[j] - yi, dz = z[j] - zi;
          if (j != i && dx * dx + dy * dy + dz * dz < range2) ++count;
        }
      }
    }
  }
  return count;
}

#endif
