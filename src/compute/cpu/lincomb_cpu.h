/* Template of the cpu lincomb loop; instantiated once per precision by
 * lincomb_cpu_f32.c and lincomb_cpu_f64.c (see src/kernels/px_kernel.h). */
#include "compute/cpu/cpu_impl.h"
#include "kernels/px_kernel.h"
#include "partix/backend.h"

/* Elements per block: the partial sums of a block stay in L1 while every
 * input is streamed once, and out may alias an input (a block is read
 * completely before it is written). */
#define PX_LINCOMB_BLOCK 1024

void PX_SFX(px_cpu_lincomb)(int threads, size_t n, int nterms, const double *coeffs,
                            const px_real *const *in, px_real *out) {
  const size_t nblocks = (n + PX_LINCOMB_BLOCK - 1) / PX_LINCOMB_BLOCK;
  px_real c[PX_LINCOMB_MAX];
  int k;
  for (k = 0; k < nterms; ++k) c[k] = (px_real)coeffs[k];
#pragma omp parallel for num_threads(threads) schedule(static) if (nblocks > 16)
  for (size_t b = 0; b < nblocks; ++b) {
    const size_t i0 = b * PX_LINCOMB_BLOCK;
    const size_t m = n - i0 < PX_LINCOMB_BLOCK ? n - i0 : PX_LINCOMB_BLOCK;
    px_real acc[PX_LINCOMB_BLOCK];
    const px_real *x = in[0] + i0;
    const px_real c0 = c[0];
    size_t i;
    int t;
#pragma omp simd
    for (i = 0; i < m; ++i) acc[i] = c0 * x[i];
    for (t = 1; t < nterms; ++t) {
      const px_real ct = c[t];
      x = in[t] + i0;
#pragma omp simd
      for (i = 0; i < m; ++i) acc[i] = acc[i] + ct * x[i];
    }
#pragma omp simd
    for (i = 0; i < m; ++i) out[i0 + i] = acc[i];
  }
}
