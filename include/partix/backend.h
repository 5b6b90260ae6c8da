/* Compute backends. A backend owns device memory (buffers) and runs loops:
 * `cpu` with OpenMP + SIMD on host memory, `opencl` as kernels on any OpenCL
 * 1.2+ device. Solvers and shared kernels see only this interface and pick
 * per-backend implementations by backend name; they never test for a type. */
#ifndef PARTIX_BACKEND_H
#define PARTIX_BACKEND_H

#include <stddef.h>
#include <stdio.h>

#include "partix/context.h"
#include "partix/export.h"
#include "partix/types.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_backend;
struct px_buffer;

/* Names of the backends compiled into this build, NULL-terminated ("cpu", ...). */
PX_API const char *const *px_backend_names(void);

/* Create a backend by name. `device`: OpenCL device index in the order
 * `partix info` lists them (all platforms), ignored by cpu. `threads`: CPU
 * threads for host loops (0 = all available cores). */
PX_API enum px_status px_backend_create(struct px_context *ctx, const char *name, int device,
                                        int threads, struct px_backend **out);
/* NULL-safe; all buffers of the backend must be freed first. */
PX_API void px_backend_free(struct px_backend *be);

PX_API const char *px_backend_name(const struct px_backend *be);
/* Human-readable device description ("2 threads, AVX-512" / "pthread-... (POCL)"). */
PX_API const char *px_backend_device(const struct px_backend *be);
PX_API struct px_context *px_backend_context(const struct px_backend *be);
/* 1 if the device computes in double precision (queried, never assumed). */
PX_API int px_backend_has_fp64(const struct px_backend *be);
/* Number of host threads used by host loops. */
PX_API int px_backend_threads(const struct px_backend *be);
/* 1 if the thread count was left to partix (threads = 0 at creation): the
 * cpu engines then tune the count they use while running (1 or all). */
PX_API int px_backend_threads_auto(const struct px_backend *be);
/* 1 if buffers live in host memory (px_buffer_host returns their pointer). */
PX_API int px_backend_host_memory(const struct px_backend *be);
/* Work-group size for kernels and tile width of tiled loops (0 = automatic,
 * chosen per kernel from the device's limits). */
PX_API enum px_status px_backend_set_workgroup(struct px_backend *be, size_t size);
PX_API size_t px_backend_workgroup(const struct px_backend *be);
/* Wait for all queued work to finish. */
PX_API enum px_status px_backend_finish(struct px_backend *be);
/* Fail with PX_STATUS_UNSUPPORTED (and a clear message) if the backend cannot
 * run `precision`, e.g. double on a device without fp64. */
PX_API enum px_status px_backend_require(struct px_backend *be, enum px_precision precision);

/* Print every compiled backend and every OpenCL platform and device (type,
 * compute units, memory, fp64, work-group limits). */
PX_API void px_backend_report(struct px_context *ctx, FILE *out);
/* The device index a run opens when the case gives no backend.device: for
 * opencl the first GPU or accelerator over all platforms, in the order of
 * px_backend_report (so a GPU is preferred to a CPU device such as POCL's
 * whichever platform the ICD loader lists first), else 0; 0 for the other
 * backends and unknown names. */
PX_API int px_backend_default_device(const char *name);
/* Number of OpenCL devices over all platforms (0 without OpenCL). */
PX_API int px_backend_opencl_device_count(struct px_context *ctx);

/* Buffers: untyped device memory of `bytes` bytes (label used for memory
 * accounting and error messages). Contents are undefined after create.
 * `bytes` may be 0 (an empty buffer, e.g. no particles yet). */
PX_API enum px_status px_buffer_create(struct px_backend *be, const char *label, size_t bytes,
                                       struct px_buffer **out);
/* NULL-safe. */
PX_API void px_buffer_free(struct px_buffer *buf);
PX_API size_t px_buffer_bytes(const struct px_buffer *buf);
/* The label given at creation (truncated to 47 characters). */
PX_API const char *px_buffer_label(const struct px_buffer *buf);
PX_API struct px_backend *px_buffer_backend(const struct px_buffer *buf);
/* Host pointer of a host-memory buffer, NULL on device backends. */
PX_API void *px_buffer_host(struct px_buffer *buf);
PX_API enum px_status px_buffer_write(struct px_buffer *buf, size_t offset, size_t bytes,
                                      const void *src);
PX_API enum px_status px_buffer_read(struct px_buffer *buf, size_t offset, size_t bytes, void *dst);
PX_API enum px_status px_buffer_copy(struct px_buffer *dst, size_t dst_offset,
                                     struct px_buffer *src, size_t src_offset, size_t bytes);
PX_API enum px_status px_buffer_zero(struct px_buffer *buf);
/* Change the size, keeping the first min(old, new) bytes. Shrinking keeps
 * the allocation; growing beyond it reallocates with 50% headroom, so that
 * a buffer grown by a little every step (a vortex wake) costs amortised O(1). */
PX_API enum px_status px_buffer_resize(struct px_buffer *buf, size_t bytes);

/* Most terms of one px_buffer_lincomb call. */
#define PX_LINCOMB_MAX 8

/* Linear combination on the buffers' device (the vector operation under the
 * integrators): out[i] = sum_{k < nterms} coeffs[k] * in[k][i] for i < n,
 * computed in the element type `type` (PX_DTYPE_F32 or PX_DTYPE_F64) with the
 * terms added in order k = 0, 1, ... `out` may be one of the inputs; all
 * buffers must belong to the same backend. 1 <= nterms <= PX_LINCOMB_MAX;
 * n = 0 does nothing. */
PX_API enum px_status px_buffer_lincomb(struct px_buffer *out, enum px_dtype type, size_t n,
                                        int nterms, const double *coeffs,
                                        struct px_buffer *const *in);

#ifdef __cplusplus
}
#endif
#endif
