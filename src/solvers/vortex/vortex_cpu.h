/* CPU kernels of the vortex solver (float and double instantiations of
 * vortex_kernel.h), and the double-precision physics helpers the engine uses
 * directly. */
#ifndef PX_VORTEX_CPU_H
#define PX_VORTEX_CPU_H

#include <stddef.h>

/* Velocities at nt targets induced by ns smoothed vortices (see
 * vortex_direct_tmpl.h); overwrites u, v. */
void px_vortex_direct_f(size_t nt, const float *tx, const float *ty, size_t ns, const float *sx,
                        const float *sy, const float *sg, float eps2, float *u, float *v,
                        int threads);
void px_vortex_direct_d(size_t nt, const double *tx, const double *ty, size_t ns,
                        const double *sx, const double *sy, const double *sg, double eps2,
                        double *u, double *v, int threads);

#endif
