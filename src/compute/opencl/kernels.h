/* OpenCL kernels for the modules and solver engines that run them: programs,
 * kernels, typed and named arguments, launches, a prefix sum (compiled only
 * with PX_HAVE_OPENCL). The backend's internals (context, queue, raw
 * buffers, error mapping) stay in opencl_impl.h, which solvers do not
 * include.
 *
 * Typical use in a module's foo_opencl.c, for a kernel
 * `px_foo_step(uint n, __global PX_REAL *x, PX_REAL dt)`:
 *
 *   cl_program prog;
 *   cl_kernel k;
 *   struct px_opencl_args a;
 *   PX_TRY(px_opencl_program_real(be, "foo", px_cl_source_foo, precision, "", &prog));
 *   PX_TRY(px_opencl_kernel(be, prog, "px_foo_step", &k));
 *   px_opencl_args_begin(&a, be, k);
 *   px_opencl_args_u32(&a, "n", n32);
 *   px_opencl_args_mem(&a, "x", x);
 *   px_opencl_args_real(&a, "dt", dt);          // float or double: the program's PX_REAL
 *   PX_TRY(px_opencl_args_launch(&a, n, 0));    // 0: backend/automatic size
 *
 * Arguments are bound in order by name and type: the first binding of each
 * kernel checks them against the kernel's signature (names, scalar types,
 * count) and fails naming the kernel and the argument; later bindings only
 * set them. The first failure is kept and returned by px_opencl_args_end.
 *
 * Programs are built once per (name, options) and kernels created once per
 * (program, name) for the backend's lifetime, so calling this every step
 * costs a cache lookup. Kernel objects are shared: set all arguments right
 * before each launch (a backend is used from one host thread at a time).
 * Kernels receive a global size rounded up to a multiple of the local size
 * and must guard `if (i >= n) return;` (or, with barriers, mask the work). */
#ifndef PX_OPENCL_KERNELS_H
#define PX_OPENCL_KERNELS_H

#include <CL/cl.h>
#include <stddef.h>
#include <stdint.h>

#include "partix/backend.h"

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
enum px_status px_opencl_arg_local(struct px_backend *be, cl_kernel k, cl_uint index, size_t bytes);

/* Typed, named argument binding (see the top of this file). */
struct px_opencl_args {
  struct px_backend *be;
  cl_kernel k;
  cl_uint n;         /* arguments bound so far */
  size_t real;       /* bytes of the program's PX_REAL (0: none) */
  int check;         /* 1: compare with the signature (first binding) */
  int *checked;      /* the kernel cache's flag (NULL: not a cached kernel) */
  enum px_status st; /* the first failure */
};
void px_opencl_args_begin(struct px_opencl_args *a, struct px_backend *be, cl_kernel k);
void px_opencl_args_mem(struct px_opencl_args *a, const char *name, struct px_buffer *buf);
void px_opencl_args_i32(struct px_opencl_args *a, const char *name, int32_t v);
void px_opencl_args_u32(struct px_opencl_args *a, const char *name, uint32_t v);
void px_opencl_args_f32(struct px_opencl_args *a, const char *name, float v);
void px_opencl_args_f64(struct px_opencl_args *a, const char *name, double v);
/* A real in the precision of the kernel's program (px_opencl_program_real). */
void px_opencl_args_real(struct px_opencl_args *a, const char *name, double v);
/* A __local array of `bytes` bytes. */
void px_opencl_args_local(struct px_opencl_args *a, const char *name, size_t bytes);
/* Any other value (a struct, a vector type) of `size` bytes. */
void px_opencl_args_value(struct px_opencl_args *a, const char *name, size_t size,
                          const void *value);
/* Checks the count at the first binding; the first failure, or OK. */
enum px_status px_opencl_args_end(struct px_opencl_args *a);
/* px_opencl_args_end, then px_opencl_launch of the kernel. */
enum px_status px_opencl_args_launch(struct px_opencl_args *a, size_t n, size_t local);
/* The same over the items [first, first + n) (px_opencl_launch_range). */
enum px_status px_opencl_args_launch_range(struct px_opencl_args *a, size_t first, size_t n,
                                           size_t local);

/* Work-group size for kernel k: the backend setting when not 0 (an error if
 * the kernel cannot run that size on this device), otherwise `preferred`
 * clamped to the kernel's CL_KERNEL_WORK_GROUP_SIZE and rounded down to its
 * CL_KERNEL_PREFERRED_WORK_GROUP_SIZE_MULTIPLE. */
enum px_status px_opencl_local_size(struct px_backend *be, cl_kernel k, size_t preferred,
                                    size_t *out);
/* Largest power of two <= min(cap, kernel limit, device limit) (>= 1): for
 * kernels whose algorithm needs one (scans, sorts); ignores the setting. */
enum px_status px_opencl_local_pow2(struct px_backend *be, cl_kernel k, size_t cap, size_t *out);
/* Local memory of the device in bytes. */
size_t px_opencl_local_mem(struct px_backend *be);
/* The device's global memory and its largest single allocation [bytes]. */
void px_opencl_memory(struct px_backend *be, double *global, double *max_alloc);

/* Enqueue 1D kernel over n items (n = 0: nothing). local = 0: px_opencl_local_size
 * with the generic preference (256). The global size is n rounded up to a
 * multiple of local. */
enum px_status px_opencl_launch(struct px_backend *be, cl_kernel k, size_t n, size_t local);
/* The same over the items [first, first + n): get_global_id(0) counts from
 * first (OpenCL's global work offset), so a kernel indexed by its global id
 * computes exactly the items it would in the whole launch, as in it (a share
 * of the targets of a sum: vortex over MPI ranks). The global size is n
 * rounded up to a multiple of local; the items past first + n are the
 * kernel's to skip (its bound on the global id). */
enum px_status px_opencl_launch_range(struct px_backend *be, cl_kernel k, size_t first, size_t n,
                                      size_t local);

/* Exclusive prefix sum of n uint32 values of `in` into `out` (may be the same
 * buffer), work-efficient (Blelloch) per work-group, recursive over block
 * sums. Scratch memory is kept by the backend. If total is not NULL it
 * receives the sum of all n inputs (a blocking read). */
enum px_status px_opencl_scan_u32(struct px_backend *be, struct px_buffer *in,
                                  struct px_buffer *out, size_t n, uint32_t *total);

#endif
