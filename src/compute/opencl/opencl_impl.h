/* opencl backend internals: helpers for kernel modules and solvers that run
 * OpenCL programs (compiled only with PX_HAVE_OPENCL).
 *
 * Typical use in a module's foo_opencl.c:
 *
 *   cl_program prog;
 *   cl_kernel k;
 *   PX_TRY(px_opencl_program_real(be, "foo", px_cl_source_foo, precision, "", &prog));
 *   PX_TRY(px_opencl_kernel(be, prog, "px_foo_step", &k));
 *   PX_TRY(px_opencl_arg(be, k, 0, sizeof n32, &n32));
 *   PX_TRY(px_opencl_arg_mem(be, k, 1, x));
 *   PX_TRY(px_opencl_launch(be, k, n, 0));      // 0: backend/automatic size
 *
 * Programs are built once per (name, options) and kernels created once per
 * (program, name) for the backend's lifetime, so calling this every step
 * costs a cache lookup. Kernel objects are shared: set all arguments right
 * before each launch (a backend is used from one host thread at a time).
 * Kernels receive a global size rounded up to a multiple of the local size
 * and must guard `if (i >= n) return;` (or, with barriers, mask the work). */
#ifndef PX_OPENCL_IMPL_H
#define PX_OPENCL_IMPL_H

#include <CL/cl.h>
#include <stdint.h>

#include "compute/backend_impl.h"

/* Embedded OpenCL C programs (generated from src/compute/opencl/<name>.cl). */
extern const char px_cl_source_scan[];
extern const char px_cl_source_vector[];
extern const char px_cl_source_grid[];
extern const char px_cl_source_nbody_direct[];

/* "CL_OUT_OF_RESOURCES" for -5; "CL_UNKNOWN_ERROR" for codes not in the table. */
const char *px_opencl_error_name(cl_int err);
/* OK for CL_SUCCESS; otherwise records "<what>: <NAME> (<code>) on <device>"
 * as PX_STATUS_BACKEND (PX_STATUS_NOMEM for allocation failures). */
enum px_status px_opencl_check(struct px_backend *be, cl_int err, const char *what);

cl_context px_opencl_context(struct px_backend *be);
cl_command_queue px_opencl_queue(struct px_backend *be);
cl_device_id px_opencl_device(struct px_backend *be);
/* The buffer's cl_mem (borrowed). */
cl_mem px_opencl_mem(struct px_buffer *buf);

/* Build (or fetch from the cache) program `name` from `source` with
 * "-cl-std=CL1.2 <options>". A failed build records the build log (trimmed)
 * in the message. */
enum px_status px_opencl_program(struct px_backend *be, const char *name, const char *source,
                                 const char *options, cl_program *out);
/* Same with "-DPX_REAL=float|double" prepended; double on a device without
 * fp64 fails with PX_STATUS_UNSUPPORTED (px_backend_require). */
enum px_status px_opencl_program_real(struct px_backend *be, const char *name, const char *source,
                                      enum px_precision precision, const char *options,
                                      cl_program *out);
/* Kernel `name` of `program`, created once and cached. */
enum px_status px_opencl_kernel(struct px_backend *be, cl_program program, const char *name,
                                cl_kernel *out);

/* clSetKernelArg with the kernel name and argument index in the message. */
enum px_status px_opencl_arg(struct px_backend *be, cl_kernel k, cl_uint index, size_t size,
                             const void *value);
enum px_status px_opencl_arg_mem(struct px_backend *be, cl_kernel k, cl_uint index,
                                 struct px_buffer *buf);
/* A __local array of `bytes` bytes. */
enum px_status px_opencl_arg_local(struct px_backend *be, cl_kernel k, cl_uint index,
                                   size_t bytes);

/* Work-group size for kernel k: the backend setting when not 0 (an error if
 * the kernel cannot run that size on this device), otherwise `preferred`
 * clamped to the kernel's CL_KERNEL_WORK_GROUP_SIZE and rounded down to its
 * CL_KERNEL_PREFERRED_WORK_GROUP_SIZE_MULTIPLE. */
enum px_status px_opencl_local_size(struct px_backend *be, cl_kernel k, size_t preferred,
                                    size_t *out);
/* Largest power of two <= min(cap, kernel limit, device limit) (>= 1): for
 * kernels whose algorithm needs one (scans, sorts); ignores the setting. */
enum px_status px_opencl_local_pow2(struct px_backend *be, cl_kernel k, size_t cap,
                                    size_t *out);
/* Backend-owned device scratch memory: slot 0..PX_OPENCL_SCRATCH_SLOTS-1,
 * at least `bytes` bytes (grown as needed, never shrunk), content undefined,
 * valid until the next call for the same slot. Slot 0 is used by
 * px_opencl_scan_u32; callers of the scan must not hold slot 0. */
#define PX_OPENCL_SCRATCH_SLOTS 4
enum px_status px_opencl_scratch(struct px_backend *be, int slot, size_t bytes, cl_mem *out);
/* Local memory of the device in bytes. */
size_t px_opencl_local_mem(struct px_backend *be);

/* Enqueue 1D kernel over n items (n = 0: nothing). local = 0: px_opencl_local_size
 * with the generic preference (256). The global size is n rounded up to a
 * multiple of local. */
enum px_status px_opencl_launch(struct px_backend *be, cl_kernel k, size_t n, size_t local);

/* Exclusive prefix sum of n uint32 values of `in` into `out` (may be the same
 * buffer), work-efficient (Blelloch) per work-group, recursive over block
 * sums. Scratch memory is kept by the backend. If total is not NULL it
 * receives the sum of all n inputs (a blocking read). */
enum px_status px_opencl_scan_u32(struct px_backend *be, struct px_buffer *in,
                                  struct px_buffer *out, size_t n, uint32_t *total);

#endif
