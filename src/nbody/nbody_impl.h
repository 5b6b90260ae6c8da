/* Private part of the N-body module: per-backend kernel table and the cpu
 * loops. */
#ifndef PX_NBODY_IMPL_H
#define PX_NBODY_IMPL_H

#include <stddef.h>

#include "compute/backend_impl.h"
#include "partix/nbody.h"

/* Per-backend direct sum (see "Kernel tables" in backend_impl.h). Arguments
 * are validated by direct.c; n_tgt > 0. eps2 = ε² in double. */
struct px_nbody_ops {
  const char *backend;
  enum px_status (*direct)(struct px_backend *be, enum px_precision precision, size_t n_src,
                           struct px_buffer *sx, struct px_buffer *sy, struct px_buffer *sg,
                           size_t n_tgt, struct px_buffer *tx, struct px_buffer *ty, double eps2,
                           enum px_nbody_mode mode, struct px_buffer *u, struct px_buffer *v);
};

extern const struct px_nbody_ops px_nbody_ops_cpu;
#ifdef PX_HAVE_OPENCL
extern const struct px_nbody_ops px_nbody_ops_opencl;
#endif

/* cpu tiled loops (direct_cpu.h), one instantiation per precision. `tile`:
 * sources per L1 block (0 = automatic). */
void px_nbody_direct_cpu_f32(int threads, size_t tile, size_t n_src, const float *sx,
                             const float *sy, const float *sg, size_t n_tgt, const float *tx,
                             const float *ty, float eps2, int accumulate, float *u, float *v);
void px_nbody_direct_cpu_f64(int threads, size_t tile, size_t n_src, const double *sx,
                             const double *sy, const double *sg, size_t n_tgt,
                             const double *tx, const double *ty, double eps2, int accumulate,
                             double *u, double *v);
/* Sources = targets, each pair once; su, sv: n elements of scratch. */
void px_nbody_self_cpu_f32(int threads, size_t tile, size_t n, const float *x, const float *y,
                           const float *g, float eps2, int accumulate, float *u, float *v,
                           float *su, float *sv);
void px_nbody_self_cpu_f64(int threads, size_t tile, size_t n, const double *x,
                           const double *y, const double *g, double eps2, int accumulate,
                           double *u, double *v, double *su, double *sv);

#endif
