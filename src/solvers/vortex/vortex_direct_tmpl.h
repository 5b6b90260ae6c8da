/* Direct (O(N M)) Biot-Savart summation on the CPU, instantiated for float and
 * double by vortex_cpu.c (VX_REAL, VX_K defined there). Targets are
 * independent, so the result does not depend on the thread count; the inner
 * loop is a SIMD reduction whose order is fixed by the build.
 *
 * This is the convective-velocity block's call, kept behind one function so
 * that the platform's px_nbody_* (or a fast multipole method) can replace it. */
void VX_K(px_vortex_direct)(size_t nt, const VX_REAL *tx, const VX_REAL *ty, size_t ns,
                            const VX_REAL *sx, const VX_REAL *sy, const VX_REAL *sg,
                            VX_REAL eps2, VX_REAL *u, VX_REAL *v, int threads) {
  const VX_REAL c = (VX_REAL)(0.5 / VX_PI_D);
  /* targets in blocks of 4 sharing each source load (register tiling) */
  long nb = (long)((nt + 3) / 4);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (long b = 0; b < nb; ++b) {
    size_t i0 = (size_t)b * 4;
    VX_REAL x[4], y[4];
    for (int q = 0; q < 4; ++q) {
      size_t i = i0 + (size_t)q < nt ? i0 + (size_t)q : nt - 1;
      x[q] = tx[i];
      y[q] = ty[i];
    }
    VX_REAL u0 = 0, v0 = 0, u1 = 0, v1 = 0, u2 = 0, v2 = 0, u3 = 0, v3 = 0;
#pragma omp simd reduction(+ : u0, v0, u1, v1, u2, v2, u3, v3)
    for (size_t j = 0; j < ns; ++j) {
      VX_REAL xj = sx[j], yj = sy[j], gj = sg[j];
      VX_REAL dx0 = x[0] - xj, dy0 = y[0] - yj;
      VX_REAL dx1 = x[1] - xj, dy1 = y[1] - yj;
      VX_REAL dx2 = x[2] - xj, dy2 = y[2] - yj;
      VX_REAL dx3 = x[3] - xj, dy3 = y[3] - yj;
      VX_REAL f0 = VX_K(vx_bs_factor)(dx0, dy0, gj, eps2);
      VX_REAL f1 = VX_K(vx_bs_factor)(dx1, dy1, gj, eps2);
      VX_REAL f2 = VX_K(vx_bs_factor)(dx2, dy2, gj, eps2);
      VX_REAL f3 = VX_K(vx_bs_factor)(dx3, dy3, gj, eps2);
      u0 -= f0 * dy0;
      v0 += f0 * dx0;
      u1 -= f1 * dy1;
      v1 += f1 * dx1;
      u2 -= f2 * dy2;
      v2 += f2 * dx2;
      u3 -= f3 * dy3;
      v3 += f3 * dx3;
    }
    VX_REAL ur[4] = {u0, u1, u2, u3}, vr[4] = {v0, v1, v2, v3};
    for (int q = 0; q < 4 && i0 + (size_t)q < nt; ++q) {
      u[i0 + (size_t)q] = ur[q] * c;
      v[i0 + (size_t)q] = vr[q] * c;
    }
  }
}
