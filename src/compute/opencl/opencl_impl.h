/* opencl backend internals: the context, queue and device, raw buffers and
 * error mapping, scratch memory and the embedded programs of the platform's
 * own kernels. Modules that run kernels use compute/opencl/kernels.h (which
 * this includes); solvers use only that. Compiled only with PX_HAVE_OPENCL. */
#ifndef PX_OPENCL_IMPL_H
#define PX_OPENCL_IMPL_H

#include <CL/cl.h>
#include <stdint.h>

#include "compute/backend_impl.h"
#include "compute/opencl/kernels.h"

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
/* A raw cl_mem argument (scratch memory) for px_opencl_args. */
void px_opencl_args_clmem(struct px_opencl_args *a, const char *name, cl_mem m);

/* Backend-owned device scratch memory: slot 0..PX_OPENCL_SCRATCH_SLOTS-1,
 * at least `bytes` bytes (grown as needed, never shrunk), content undefined,
 * valid until the next call for the same slot. Slot 0 is used by
 * px_opencl_scan_u32; callers of the scan must not hold slot 0. */
#define PX_OPENCL_SCRATCH_SLOTS 4
enum px_status px_opencl_scratch(struct px_backend *be, int slot, size_t bytes, cl_mem *out);

#endif
