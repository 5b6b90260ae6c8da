/* opencl entry of the direct sum (kernel in src/compute/opencl/nbody_direct.cl;
 * compiled only with the opencl backend). */
#include "compute/opencl/opencl_impl.h"
#include "nbody/nbody_impl.h"

/* Default tile width: the original CUDA vortex code found 128 best. */
#define PX_NBODY_OPENCL_TILE 128

enum px_status px_nbody_cl_direct_range(struct px_backend *be, enum px_precision precision,
                                        size_t n_src, struct px_buffer *sx, struct px_buffer *sy,
                                        struct px_buffer *sg, size_t t0, size_t t1,
                                        struct px_buffer *tx, struct px_buffer *ty, double eps2,
                                        enum px_nbody_mode mode, struct px_buffer *u,
                                        struct px_buffer *v) {
  const size_t real = precision == PX_PRECISION_DOUBLE ? sizeof(cl_double) : sizeof(cl_float);
  /* the kernel's n_tgt bounds the global ids, which start at t0 */
  const cl_uint ns = (cl_uint)n_src, nt = (cl_uint)t1;
  const cl_int accumulate = mode == PX_NBODY_MODE_ADD;
  cl_program prog;
  cl_kernel k;
  struct px_opencl_args a;
  size_t w;
  PX_TRY(
      px_opencl_program_real(be, "nbody_direct", px_cl_source_nbody_direct, precision, "", &prog));
  PX_TRY(px_opencl_kernel(be, prog, "px_nbody_direct", &k));
  PX_TRY(px_opencl_local_size(be, k, PX_NBODY_OPENCL_TILE, &w));
  if (3 * w * real > px_opencl_local_mem(be))
    return px_context_fail(be->ctx, PX_STATUS_UNSUPPORTED,
                           "px_nbody_direct: a tile of %zu sources needs %zu bytes of local "
                           "memory; the device has %zu (choose a smaller work-group size)",
                           w, 3 * w * real, px_opencl_local_mem(be));
  px_opencl_args_begin(&a, be, k);
  px_opencl_args_u32(&a, "n_src", ns);
  px_opencl_args_mem(&a, "sx", sx);
  px_opencl_args_mem(&a, "sy", sy);
  px_opencl_args_mem(&a, "sg", sg);
  px_opencl_args_u32(&a, "n_tgt", nt);
  px_opencl_args_mem(&a, "tx", tx);
  px_opencl_args_mem(&a, "ty", ty);
  px_opencl_args_real(&a, "eps2", eps2);
  px_opencl_args_i32(&a, "accumulate", accumulate);
  px_opencl_args_mem(&a, "u", u);
  px_opencl_args_mem(&a, "v", v);
  px_opencl_args_local(&a, "lx", w * real);
  px_opencl_args_local(&a, "ly", w * real);
  px_opencl_args_local(&a, "lg", w * real);
  return px_opencl_args_launch_range(&a, t0, t1 > t0 ? t1 - t0 : 0, w);
}

static enum px_status px_nbody_cl_direct(struct px_backend *be, int threads,
                                         enum px_precision precision, size_t n_src,
                                         struct px_buffer *sx, struct px_buffer *sy,
                                         struct px_buffer *sg, size_t n_tgt, struct px_buffer *tx,
                                         struct px_buffer *ty, double eps2, enum px_nbody_mode mode,
                                         struct px_buffer *u, struct px_buffer *v) {
  (void)threads;
  return px_nbody_cl_direct_range(be, precision, n_src, sx, sy, sg, 0, n_tgt, tx, ty, eps2, mode, u,
                                  v);
}

const struct px_nbody_ops px_nbody_ops_opencl = {
    .backend = "opencl",
    .direct = px_nbody_cl_direct,
    .fmm = NULL, /* the direct sum is the device path (docs/fmm.md) */
};
