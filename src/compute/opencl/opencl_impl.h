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

/* ---- Private to the backend's files: opencl.c (the backend object, errors,
 * the vtable), opencl_device.c (platforms and devices), opencl_buffer.c
 * (buffers and scratch memory), opencl_program.c (program and kernel cache),
 * opencl_launch.c (arguments and launches). */

/* Longest build log kept in an error message (the first errors matter). */
#define PX_OPENCL_LOG_MAX 2400

struct px_opencl_program {
  char *key;          /* owned: "name\n options" */
  cl_program program; /* owned */
  size_t real;        /* bytes of its PX_REAL (0: none) */
};

struct px_opencl_kernel {
  cl_program program; /* borrowed from the program cache */
  char *name;         /* owned */
  cl_kernel kernel;   /* owned */
  size_t real;        /* bytes of its program's PX_REAL (0: none) */
  int checked;        /* 1: a px_opencl_args binding matched its signature */
};

struct px_opencl {
  cl_platform_id platform;
  cl_device_id device;
  cl_context context;     /* owned */
  cl_command_queue queue; /* owned, in order */
  char name[256];
  char platform_name[256];
  char c_version[128];
  cl_device_type type;
  cl_uint compute_units;
  cl_uint clock_mhz;
  cl_ulong global_mem;
  cl_ulong local_mem;
  cl_ulong max_alloc;
  size_t max_wg; /* min(CL_DEVICE_MAX_WORK_GROUP_SIZE, MAX_WORK_ITEM_SIZES[0]) */

  struct px_opencl_program *programs; /* owned */
  size_t nprograms, programs_cap;
  struct px_opencl_kernel *kernels; /* owned */
  size_t nkernels, kernels_cap;

  cl_mem scratch[PX_OPENCL_SCRATCH_SLOTS]; /* owned, may be NULL */
  size_t scratch_bytes[PX_OPENCL_SCRATCH_SLOTS];
};

static inline struct px_opencl *px_cl(struct px_backend *be) {
  return (struct px_opencl *)be->impl;
}

/* opencl_device.c */
/* Platforms into *out (malloc'ed, tiny table); 0 when there is no ICD. */
cl_uint px_opencl_platforms(cl_platform_id **out);
/* Devices of platform p into *out (malloc'ed); 0 when none. */
cl_uint px_opencl_platform_devices(cl_platform_id p, cl_device_id **out);
/* Every device of every platform, in the order backend.device numbers them
 * (the platforms', then each platform's), into *devs, and the platform of
 * each into *plats (both malloc'ed; NULL when the count is 0); the number
 * of platforms into *nplat unless NULL. */
cl_uint px_opencl_devices(cl_device_id **devs, cl_platform_id **plats, cl_uint *nplat);
int px_opencl_device_count(struct px_context *ctx);
/* A device info string into buf ("?" when the query fails). */
void px_opencl_string(cl_device_id d, cl_device_info what, char *buf, size_t size);
/* 1 if fp64 is usable on device d (cl_khr_fp64 and a double FP config). */
int px_opencl_query_fp64(cl_device_id d);
/* "OpenCL C 1.2 ..." -> 1, 2 (0, 0 when not of that form). */
void px_opencl_c_version(const char *s, int *major, int *minor);
void px_opencl_report(struct px_context *ctx, FILE *out);
/* The device a run opens when backend.device is not given: the first GPU or
 * accelerator over all platforms (`partix info`'s order), else device 0; the
 * rule itself on a list of n device types (px_opencl_pick_default). */
int px_opencl_default_device(void);
int px_opencl_pick_default(const cl_device_type *types, int n);

/* opencl_buffer.c: the buffer entries of the vtable */
enum px_status px_opencl_buffer_alloc(struct px_backend *be, struct px_buffer *buf,
                                      size_t capacity);
void px_opencl_buffer_release(struct px_backend *be, struct px_buffer *buf);
enum px_status px_opencl_buffer_write(struct px_buffer *buf, size_t offset, size_t bytes,
                                      const void *src);
enum px_status px_opencl_buffer_read(struct px_buffer *buf, size_t offset, size_t bytes, void *dst);
enum px_status px_opencl_buffer_copy(struct px_buffer *dst, size_t dst_offset,
                                     struct px_buffer *src, size_t src_offset, size_t bytes);
enum px_status px_opencl_buffer_zero(struct px_buffer *buf);
enum px_status px_opencl_finish(struct px_backend *be);
enum px_status px_opencl_lincomb(struct px_backend *be, enum px_dtype type, size_t n, int nterms,
                                 const double *coeffs, struct px_buffer *const *in,
                                 struct px_buffer *out);

#endif
