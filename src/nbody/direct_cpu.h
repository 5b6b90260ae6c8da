/* Template of the cpu direct sum; instantiated by direct_cpu_f32.c and
 * direct_cpu_f64.c (see src/kernels/px_kernel.h).
 *
 * Loop nest: OpenMP over blocks of PX_NBODY_TARGET_BLOCK targets; per block,
 * over tiles of `tile` sources that stay in L1 (3 arrays); per target, a SIMD
 * reduction over the tile's sources. The reduction form (sources in the
 * vector lanes) vectorizes to one packed subtract/multiply/max/divide chain
 * per 16 (float) or 8 (double) pairs with contiguous loads, which measured
 * as fast as or faster than putting targets in the lanes (that variant
 * reloads and stores the accumulators for every source). The pair costs one
 * division, the bottleneck (about 13 cycles per 16-lane vdivps here).
 * Each target's sum is computed by one thread in a fixed order, so the
 * result does not depend on the thread count. */
#include "kernels/biot_savart.h"
#include "nbody/nbody_impl.h"

#define PX_NBODY_TARGET_BLOCK 128
/* Automatic tile: 3 source arrays in 24 KiB (half of a 48 KiB L1). */
#define PX_NBODY_CPU_TILE_BYTES (24 * 1024)

void PX_SFX(px_nbody_direct_cpu)(int threads, size_t tile, size_t n_src, const px_real *sx,
                                 const px_real *sy, const px_real *sg, size_t n_tgt,
                                 const px_real *tx, const px_real *ty, px_real eps2,
                                 int accumulate, px_real *u, px_real *v) {
  const size_t nblocks = (n_tgt + PX_NBODY_TARGET_BLOCK - 1) / PX_NBODY_TARGET_BLOCK;
  const int parallel = (double)n_src * (double)n_tgt > 2.0e5 && nblocks > 1;
  if (tile == 0) tile = PX_NBODY_CPU_TILE_BYTES / (3 * sizeof(px_real));
#pragma omp parallel for num_threads(threads) schedule(static) if (parallel)
  for (size_t b = 0; b < nblocks; ++b) {
    const size_t i0 = b * PX_NBODY_TARGET_BLOCK;
    const size_t m = n_tgt - i0 < PX_NBODY_TARGET_BLOCK ? n_tgt - i0 : PX_NBODY_TARGET_BLOCK;
    px_real su[PX_NBODY_TARGET_BLOCK], sv[PX_NBODY_TARGET_BLOCK];
    size_t i, j0;
    for (i = 0; i < m; ++i) su[i] = sv[i] = PX_R(0.0);
    for (j0 = 0; j0 < n_src; j0 += tile) {
      const size_t j1 = n_src - j0 < tile ? n_src : j0 + tile;
      for (i = 0; i < m; ++i) {
        const px_real xi = tx[i0 + i], yi = ty[i0 + i];
        px_real au = PX_R(0.0), av = PX_R(0.0);
        size_t j;
#pragma omp simd reduction(+ : au, av)
        for (j = j0; j < j1; ++j) {
          const px_real2 t = px_biot_savart_term(xi - sx[j], yi - sy[j], sg[j], eps2);
          au += t.x;
          av += t.y;
        }
        su[i] += au;
        sv[i] += av;
      }
    }
    if (accumulate) {
      for (i = 0; i < m; ++i) {
        u[i0 + i] = u[i0 + i] + PX_BIOT_SAVART_SCALE * su[i];
        v[i0 + i] = v[i0 + i] + PX_BIOT_SAVART_SCALE * sv[i];
      }
    } else {
      for (i = 0; i < m; ++i) {
        u[i0 + i] = PX_BIOT_SAVART_SCALE * su[i];
        v[i0 + i] = PX_BIOT_SAVART_SCALE * sv[i];
      }
    }
  }
}
