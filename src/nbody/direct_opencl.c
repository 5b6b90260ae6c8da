/* opencl entry of the direct sum (kernel in src/compute/opencl/nbody_direct.cl). */
#ifdef PX_HAVE_OPENCL

#include "compute/opencl/opencl_impl.h"
#include "nbody/nbody_impl.h"

/* Default tile width: the original CUDA vortex code found 128 best. */
#define PX_NBODY_OPENCL_TILE 128

static enum px_status px_nbody_cl_direct(struct px_backend *be, enum px_precision precision,
                                         size_t n_src, struct px_buffer *sx,
                                         struct px_buffer *sy, struct px_buffer *sg,
                                         size_t n_tgt, struct px_buffer *tx,
                                         struct px_buffer *ty, double eps2,
                                         enum px_nbody_mode mode, struct px_buffer *u,
                                         struct px_buffer *v) {
  const size_t real = precision == PX_PRECISION_DOUBLE ? sizeof(cl_double) : sizeof(cl_float);
  const cl_uint ns = (cl_uint)n_src, nt = (cl_uint)n_tgt;
  const cl_int accumulate = mode == PX_NBODY_MODE_ADD;
  cl_program prog;
  cl_kernel k;
  size_t w;
  PX_TRY(px_opencl_program_real(be, "nbody_direct", px_cl_source_nbody_direct, precision, "",
                                &prog));
  PX_TRY(px_opencl_kernel(be, prog, "px_nbody_direct", &k));
  PX_TRY(px_opencl_local_size(be, k, PX_NBODY_OPENCL_TILE, &w));
  if (3 * w * real > px_opencl_local_mem(be))
    return px_context_fail(be->ctx, PX_STATUS_UNSUPPORTED,
                           "px_nbody_direct: a tile of %zu sources needs %zu bytes of local "
                           "memory; the device has %zu (choose a smaller work-group size)",
                           w, 3 * w * real, px_opencl_local_mem(be));
  PX_TRY(px_opencl_arg(be, k, 0, sizeof ns, &ns));
  PX_TRY(px_opencl_arg_mem(be, k, 1, sx));
  PX_TRY(px_opencl_arg_mem(be, k, 2, sy));
  PX_TRY(px_opencl_arg_mem(be, k, 3, sg));
  PX_TRY(px_opencl_arg(be, k, 4, sizeof nt, &nt));
  PX_TRY(px_opencl_arg_mem(be, k, 5, tx));
  PX_TRY(px_opencl_arg_mem(be, k, 6, ty));
  if (precision == PX_PRECISION_DOUBLE) {
    PX_TRY(px_opencl_arg(be, k, 7, sizeof eps2, &eps2));
  } else {
    const cl_float e = (cl_float)eps2;
    PX_TRY(px_opencl_arg(be, k, 7, sizeof e, &e));
  }
  PX_TRY(px_opencl_arg(be, k, 8, sizeof accumulate, &accumulate));
  PX_TRY(px_opencl_arg_mem(be, k, 9, u));
  PX_TRY(px_opencl_arg_mem(be, k, 10, v));
  PX_TRY(px_opencl_arg_local(be, k, 11, w * real));
  PX_TRY(px_opencl_arg_local(be, k, 12, w * real));
  PX_TRY(px_opencl_arg_local(be, k, 13, w * real));
  return px_opencl_launch(be, k, n_tgt, w);
}

const struct px_nbody_ops px_nbody_ops_opencl = {
    .backend = "opencl",
    .direct = px_nbody_cl_direct,
};

#else
/* ISO C forbids an empty translation unit. */
typedef int px_nbody_opencl_disabled;
#endif
