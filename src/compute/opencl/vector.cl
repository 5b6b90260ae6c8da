/* Vector operations under the integrators: px_buffer_lincomb. Built with
 * -DPX_REAL=float|double. */
#include "kernels/px_kernel.h"

/* out[i] = c0 x0[i] + c1 x1[i] + ... (nterms terms, added in order). out may
 * be one of the inputs: each work-item reads all inputs at i before writing. */
__kernel void px_vector_lincomb(const uint n, const int nterms, const px_real c0, const px_real c1,
                                const px_real c2, const px_real c3, const px_real c4,
                                const px_real c5, const px_real c6, const px_real c7,
                                __global const px_real *x0, __global const px_real *x1,
                                __global const px_real *x2, __global const px_real *x3,
                                __global const px_real *x4, __global const px_real *x5,
                                __global const px_real *x6, __global const px_real *x7,
                                __global px_real *out) {
  const uint i = get_global_id(0);
  px_real s;
  if (i >= n) return;
  s = c0 * x0[i];
  if (nterms > 1) s = s + c1 * x1[i];
  if (nterms > 2) s = s + c2 * x2[i];
  if (nterms > 3) s = s + c3 * x3[i];
  if (nterms > 4) s = s + c4 * x4[i];
  if (nterms > 5) s = s + c5 * x5[i];
  if (nterms > 6) s = s + c6 * x6[i];
  if (nterms > 7) s = s + c7 * x7[i];
  out[i] = s;
}
