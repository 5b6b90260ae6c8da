/* Direct 2D Biot–Savart sum with local-memory tiles (nbody/direct_opencl.c).
 * Built with -DPX_REAL=float|double.
 *
 * One work-item per target; the work-group loads a tile of w sources (w =
 * the work-group size, the tunable tile width) into local memory, every
 * work-item sums over the tile, and the group moves to the next tile.
 * Summation order: per work-item, source j of a tile goes to partial sum
 * j mod PX_NBODY_LANES (remainder of the tile to sum 0); the partial sums
 * are added in lane order at the end. The loop bounds are uniform over the
 * group so every work-item reaches every barrier; items past n_tgt compute
 * nothing useful and write nothing. */
#include "kernels/biot_savart.h"

/* Each work-item keeps PX_NBODY_LANES independent partial sums over the
 * tile (sources j, j+1, ... go to lanes 0, 1, ...). Without it a CPU OpenCL
 * compiler cannot vectorize the per-work-item sum (that needs reassociation,
 * i.e. -cl-unsafe-math-optimizations); with it the lanes vectorize as they
 * stand (POCL, this machine: 10x, 0.25 -> 2.6 G pairs/s in float). On GPUs
 * it is plain instruction-level parallelism. 8 float / 4 double measured
 * best on AVX-512. */
#ifndef PX_NBODY_LANES
#if PX_REAL_IS_DOUBLE
#define PX_NBODY_LANES 4
#else
#define PX_NBODY_LANES 8
#endif
#endif

__kernel void px_nbody_direct(const uint n_src, __global const px_real *sx,
                              __global const px_real *sy, __global const px_real *sg,
                              const uint n_tgt, __global const px_real *tx,
                              __global const px_real *ty, const px_real eps2, const int accumulate,
                              __global px_real *u, __global px_real *v, __local px_real *lx,
                              __local px_real *ly, __local px_real *lg) {
  const uint i = get_global_id(0), lid = get_local_id(0), w = get_local_size(0);
  const int active = i < n_tgt;
  const px_real xi = active ? tx[i] : PX_R(0.0), yi = active ? ty[i] : PX_R(0.0);
  px_real au[PX_NBODY_LANES], av[PX_NBODY_LANES], su = PX_R(0.0), sv = PX_R(0.0);
  uint j0, j, l;
  for (l = 0; l < PX_NBODY_LANES; ++l) au[l] = av[l] = PX_R(0.0);
  for (j0 = 0; j0 < n_src; j0 += w) {
    const uint m = min(w, n_src - j0);
    if (lid < m) {
      lx[lid] = sx[j0 + lid];
      ly[lid] = sy[j0 + lid];
      lg[lid] = sg[j0 + lid];
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    for (j = 0; j + PX_NBODY_LANES <= m; j += PX_NBODY_LANES) {
      for (l = 0; l < PX_NBODY_LANES; ++l) {
        const px_real2 t = px_biot_savart_term(xi - lx[j + l], yi - ly[j + l], lg[j + l], eps2);
        au[l] += t.x;
        av[l] += t.y;
      }
    }
    for (; j < m; ++j) {
      const px_real2 t = px_biot_savart_term(xi - lx[j], yi - ly[j], lg[j], eps2);
      au[0] += t.x;
      av[0] += t.y;
    }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  for (l = 0; l < PX_NBODY_LANES; ++l) {
    su += au[l];
    sv += av[l];
  }
  if (!active) return;
  if (accumulate) {
    u[i] = u[i] + PX_BIOT_SAVART_SCALE * su;
    v[i] = v[i] + PX_BIOT_SAVART_SCALE * sv;
  } else {
    u[i] = PX_BIOT_SAVART_SCALE * su;
    v[i] = PX_BIOT_SAVART_SCALE * sv;
  }
}
