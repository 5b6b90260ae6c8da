/* The opencl backend: buffers (cl_mem objects on the in-order queue), the
 * linear combination of buffers, and the backend's scratch memory. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compute/opencl/opencl_impl.h"

enum px_status px_opencl_buffer_alloc(struct px_backend *be, struct px_buffer *buf,
                                      size_t capacity) {
  struct px_opencl *cl = px_cl(be);
  cl_int err;
  cl_mem mem;
  if ((cl_ulong)capacity > cl->max_alloc)
    return px_context_fail(be->ctx, PX_STATUS_NOMEM,
                           "buffer '%s': %zu bytes exceed the largest allocation of OpenCL "
                           "device '%s' (%llu bytes)",
                           buf->label, capacity, cl->name, (unsigned long long)cl->max_alloc);
  mem = clCreateBuffer(cl->context, CL_MEM_READ_WRITE, capacity, NULL, &err);
  if (err != CL_SUCCESS) {
    char what[128];
    snprintf(what, sizeof what, "allocating buffer '%s' (%zu bytes)", buf->label, capacity);
    return px_opencl_check(be, err, what);
  }
  buf->handle = mem;
  return PX_STATUS_OK;
}

void px_opencl_buffer_release(struct px_backend *be, struct px_buffer *buf) {
  (void)be;
  if (buf->handle) clReleaseMemObject((cl_mem)buf->handle);
  buf->handle = NULL;
}

enum px_status px_opencl_buffer_write(struct px_buffer *buf, size_t offset, size_t bytes,
                                      const void *src) {
  struct px_backend *be = buf->backend;
  cl_int err = clEnqueueWriteBuffer(px_cl(be)->queue, (cl_mem)buf->handle, CL_TRUE, offset, bytes,
                                    src, 0, NULL, NULL);
  if (err != CL_SUCCESS) {
    char what[128];
    snprintf(what, sizeof what, "writing %zu bytes to buffer '%s'", bytes, buf->label);
    return px_opencl_check(be, err, what);
  }
  return PX_STATUS_OK;
}

enum px_status px_opencl_buffer_read(struct px_buffer *buf, size_t offset, size_t bytes,
                                     void *dst) {
  struct px_backend *be = buf->backend;
  cl_int err = clEnqueueReadBuffer(px_cl(be)->queue, (cl_mem)buf->handle, CL_TRUE, offset, bytes,
                                   dst, 0, NULL, NULL);
  if (err != CL_SUCCESS) {
    char what[128];
    snprintf(what, sizeof what, "reading %zu bytes from buffer '%s'", bytes, buf->label);
    return px_opencl_check(be, err, what);
  }
  return PX_STATUS_OK;
}

enum px_status px_opencl_buffer_copy(struct px_buffer *dst, size_t dst_offset,
                                     struct px_buffer *src, size_t src_offset, size_t bytes) {
  struct px_backend *be = dst->backend;
  cl_int err = clEnqueueCopyBuffer(px_cl(be)->queue, (cl_mem)src->handle, (cl_mem)dst->handle,
                                   src_offset, dst_offset, bytes, 0, NULL, NULL);
  if (err != CL_SUCCESS) {
    char what[160];
    snprintf(what, sizeof what, "copying %zu bytes from buffer '%s' to '%s'", bytes, src->label,
             dst->label);
    return px_opencl_check(be, err, what);
  }
  return PX_STATUS_OK;
}

enum px_status px_opencl_buffer_zero(struct px_buffer *buf) {
  struct px_backend *be = buf->backend;
  const cl_uchar zero = 0;
  cl_int err = clEnqueueFillBuffer(px_cl(be)->queue, (cl_mem)buf->handle, &zero, 1, 0, buf->bytes,
                                   0, NULL, NULL);
  if (err != CL_SUCCESS) {
    char what[128];
    snprintf(what, sizeof what, "zeroing buffer '%s'", buf->label);
    return px_opencl_check(be, err, what);
  }
  return PX_STATUS_OK;
}

enum px_status px_opencl_finish(struct px_backend *be) {
  return px_opencl_check(be, clFinish(px_cl(be)->queue), "waiting for the OpenCL queue");
}

enum px_status px_opencl_lincomb(struct px_backend *be, enum px_dtype type, size_t n, int nterms,
                                 const double *coeffs, struct px_buffer *const *in,
                                 struct px_buffer *out) {
  const enum px_precision p = type == PX_DTYPE_F64 ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
  cl_program prog;
  cl_kernel k;
  const cl_uint n32 = (cl_uint)n;
  struct px_opencl_args a;
  int i;
  if (n > 0xffffffffu)
    return px_context_fail(be->ctx, PX_STATUS_INVALID,
                           "px_buffer_lincomb: %zu elements exceed the OpenCL kernels' 32-bit "
                           "index range",
                           n);
  PX_TRY(px_opencl_program_real(be, "vector", px_cl_source_vector, p, "", &prog));
  PX_TRY(px_opencl_kernel(be, prog, "px_vector_lincomb", &k));
  px_opencl_args_begin(&a, be, k);
  px_opencl_args_u32(&a, "n", n32);
  px_opencl_args_i32(&a, "nterms", nterms);
  for (i = 0; i < PX_LINCOMB_MAX; ++i) {
    static const char *const cname[PX_LINCOMB_MAX] = {"c0", "c1", "c2", "c3",
                                                      "c4", "c5", "c6", "c7"};
    px_opencl_args_real(&a, cname[i], i < nterms ? coeffs[i] : 0.0);
  }
  /* Unused inputs point at in[0]; the kernel never reads them. */
  for (i = 0; i < PX_LINCOMB_MAX; ++i) {
    static const char *const xname[PX_LINCOMB_MAX] = {"x0", "x1", "x2", "x3",
                                                      "x4", "x5", "x6", "x7"};
    px_opencl_args_mem(&a, xname[i], in[i < nterms ? i : 0]);
  }
  px_opencl_args_mem(&a, "out", out);
  return px_opencl_args_launch(&a, n, 0);
}
enum px_status px_opencl_scratch(struct px_backend *be, int slot, size_t bytes, cl_mem *out) {
  struct px_opencl *cl = px_cl(be);
  cl_int err;
  if (slot < 0 || slot >= PX_OPENCL_SCRATCH_SLOTS)
    return px_context_fail(be->ctx, PX_STATUS_INTERNAL, "opencl scratch slot %d out of range",
                           slot);
  if (bytes == 0) bytes = 1;
  if (cl->scratch[slot] && cl->scratch_bytes[slot] >= bytes) {
    *out = cl->scratch[slot];
    return PX_STATUS_OK;
  }
  if (cl->scratch[slot]) clReleaseMemObject(cl->scratch[slot]);
  cl->scratch[slot] = NULL;
  cl->scratch_bytes[slot] = 0;
  bytes += bytes / 2;
  cl->scratch[slot] = clCreateBuffer(cl->context, CL_MEM_READ_WRITE, bytes, NULL, &err);
  if (err != CL_SUCCESS) {
    cl->scratch[slot] = NULL;
    return px_opencl_check(be, err, "allocating OpenCL scratch memory");
  }
  cl->scratch_bytes[slot] = bytes;
  *out = cl->scratch[slot];
  return PX_STATUS_OK;
}

void px_opencl_memory(struct px_backend *be, double *global, double *max_alloc) {
  const struct px_opencl *cl = px_cl(be);
  *global = (double)cl->global_mem;
  *max_alloc = (double)cl->max_alloc;
}
