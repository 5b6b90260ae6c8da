/* Template of the cpu direct sums; instantiated by direct_cpu_f32.c and
 * direct_cpu_f64.c (see src/kernels/px_kernel.h).
 *
 * 1. px_nbody_direct_cpu: any sources acting on any targets.
 * Loop nest: OpenMP over blocks of PX_NBODY_TARGET_BLOCK targets; per block,
 * over tiles of `tile` sources that stay in L1 (3 arrays); per target, a SIMD
 * reduction over the tile's sources. The reduction form (sources in the
 * vector lanes) vectorizes to one packed subtract/multiply/max/divide chain
 * per vector of pairs with contiguous loads, and measured as fast as or
 * faster than putting targets in the lanes (that variant reloads and stores
 * the accumulators for every source). The pair costs one division, the
 * bottleneck: about 13 cycles per 16-lane vdivps on this Xeon, the same per
 * lane as 8-lane vdivps, so gcc's choice of 256-bit vectors here costs
 * nothing (measured: 2.65 vs 2.68 G pairs/s with -mprefer-vector-width=512).
 * Each target's sum is computed by one thread in a fixed order, so the
 * result does not depend on the thread count.
 *
 * 2. px_nbody_self_cpu: sources acting on themselves (the vortex wake), each
 * pair evaluated once: K(r_i − r_j) goes to i with weight Γ_j and to j with
 * weight −Γ_i (K is odd), so half the divisions. At most
 * PX_NBODY_SELF_MAX_BLOCKS blocks (each a whole number of `tile`-sized
 * sub-tiles that stay in L1); the block pairs (a, b), a < b, are processed
 * in the rounds of a round-robin tournament (circle method), where no block
 * occurs twice, so the pairs of a round run in parallel without write
 * conflicts; diagonal blocks (a, a) take the pairs j > i. Few, large blocks
 * keep the barriers between rounds few (at most 64), which matters when a
 * thread is preempted on a shared machine. The blocks depend on n and the
 * tile only, and the order in which a particle's sum receives its terms is
 * fixed by the schedule, not by the threads: the result does not depend on
 * the thread count either. */
#include "kernels/biot_savart.h"
#include "nbody/nbody_impl.h"

#define PX_NBODY_TARGET_BLOCK 128
/* Automatic sub-tile of the self-interaction sum: 5 arrays of two sub-tiles
 * in L1; and the most blocks of its schedule. */
#define PX_NBODY_SELF_TILE 256
#define PX_NBODY_SELF_MAX_BLOCKS 64
/* Automatic tile: 3 source arrays in 24 KiB (half of a 48 KiB L1). */
#define PX_NBODY_CPU_TILE_BYTES (24 * 1024)

void PX_SFX(px_nbody_direct_cpu)(int threads, size_t tile, size_t n_src, const px_real *sx,
                                 const px_real *sy, const px_real *sg, size_t n_tgt,
                                 const px_real *tx, const px_real *ty, px_real eps2, int accumulate,
                                 px_real *u, px_real *v) {
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

/* Pairs i in [i0, i1), j in [j0, j1) of one block pair, or of one diagonal
 * block (diagonal != 0: j > i only). Sums without 1/(2π) into su, sv. */
static void PX_SFX(px_nbody_block_pair)(size_t i0, size_t i1, size_t j0, size_t j1, int diagonal,
                                        const px_real *x, const px_real *y, const px_real *g,
                                        px_real eps2, px_real *su, px_real *sv) {
  size_t i;
  for (i = i0; i < i1; ++i) {
    const px_real xi = x[i], yi = y[i], gi = g[i];
    const size_t jb = diagonal ? i + 1 : j0;
    px_real au = PX_R(0.0), av = PX_R(0.0);
    size_t j;
#pragma omp simd reduction(+ : au, av)
    for (j = jb; j < j1; ++j) {
      const px_real2 k = px_biot_savart_kernel(xi - x[j], yi - y[j], eps2);
      au += g[j] * k.x;
      av += g[j] * k.y;
      su[j] -= gi * k.x;
      sv[j] -= gi * k.y;
    }
    su[i] += au;
    sv[i] += av;
  }
}

/* Particles [a0, a1) against [b0, b1) (diagonal: a block with itself, pairs
 * j > i), sub-tile by sub-tile. */
static void PX_SFX(px_nbody_self_blocks)(size_t a0, size_t a1, size_t b0, size_t b1, int diagonal,
                                         size_t tile, const px_real *x, const px_real *y,
                                         const px_real *g, px_real eps2, px_real *su, px_real *sv) {
  size_t i0, j0;
  for (i0 = a0; i0 < a1; i0 += tile) {
    const size_t i1 = a1 - i0 < tile ? a1 : i0 + tile;
    if (diagonal) PX_SFX(px_nbody_block_pair)(i0, i1, i0, i1, 1, x, y, g, eps2, su, sv);
    for (j0 = diagonal ? i1 : b0; j0 < b1; j0 += tile) {
      const size_t j1 = b1 - j0 < tile ? b1 : j0 + tile;
      PX_SFX(px_nbody_block_pair)(i0, i1, j0, j1, 0, x, y, g, eps2, su, sv);
    }
  }
}

void PX_SFX(px_nbody_self_cpu)(int threads, size_t tile, size_t n, const px_real *x,
                               const px_real *y, const px_real *g, px_real eps2, int accumulate,
                               px_real *u, px_real *v, px_real *su, px_real *sv) {
  size_t block, nb, teams, rounds;
  int parallel;
  if (tile == 0) tile = PX_NBODY_SELF_TILE;
  block = tile;
  if ((n + block - 1) / block > PX_NBODY_SELF_MAX_BLOCKS) {
    block = (n + PX_NBODY_SELF_MAX_BLOCKS - 1) / PX_NBODY_SELF_MAX_BLOCKS;
    block = (block + tile - 1) / tile * tile;
  }
  nb = (n + block - 1) / block;
  teams = nb + (nb & 1); /* even; block nb is a bye when nb is odd */
  rounds = teams - 1;
  parallel = (double)n * (double)n > 4.0e5 && nb > 1;
#pragma omp parallel num_threads(threads) if (parallel)
  {
    size_t r;
#pragma omp for schedule(static)
    for (size_t i = 0; i < n; ++i) su[i] = sv[i] = PX_R(0.0);
#pragma omp for schedule(static)
    for (size_t b = 0; b < nb; ++b) {
      const size_t i0 = b * block, i1 = n - i0 < block ? n : i0 + block;
      PX_SFX(px_nbody_self_blocks)(i0, i1, i0, i1, 1, tile, x, y, g, eps2, su, sv);
    }
    for (r = 0; r < rounds; ++r) {
#pragma omp for schedule(static)
      for (size_t k = 0; k < teams / 2; ++k) {
        /* circle method: team teams-1 stays, the others rotate */
        const size_t a = k == 0 ? teams - 1 : (r + k) % (teams - 1);
        const size_t b = k == 0 ? r : (r + teams - 1 - k) % (teams - 1);
        if (a < nb && b < nb) {
          const size_t i0 = a * block, i1 = n - i0 < block ? n : i0 + block;
          const size_t j0 = b * block, j1 = n - j0 < block ? n : j0 + block;
          PX_SFX(px_nbody_self_blocks)(i0, i1, j0, j1, 0, tile, x, y, g, eps2, su, sv);
        }
      }
    }
#pragma omp for schedule(static)
    for (size_t i = 0; i < n; ++i) {
      u[i] = (accumulate ? u[i] : PX_R(0.0)) + PX_BIOT_SAVART_SCALE * su[i];
      v[i] = (accumulate ? v[i] : PX_R(0.0)) + PX_BIOT_SAVART_SCALE * sv[i];
    }
  }
}
