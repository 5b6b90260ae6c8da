/* The opencl backend: any OpenCL 1.2+ device (GPUs of any vendor, POCL's CPU
 * device in CI). Buffers are cl_mem objects; one in-order command queue per
 * backend; programs are built from the embedded sources on first use and
 * cached for the backend's lifetime. Capabilities (fp64, work-group and
 * local-memory limits) are queried, never assumed from vendor names. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compute/opencl/opencl_impl.h"
#include "partix/memory.h"
#include "partix/timer.h"

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

static struct px_opencl *px_cl(struct px_backend *be) { return (struct px_opencl *)be->impl; }

const char *px_opencl_error_name(cl_int err) {
  switch (err) {
#define PX_CL_ERR_(e) \
  case e: return #e;
    PX_CL_ERR_(CL_SUCCESS)
    PX_CL_ERR_(CL_DEVICE_NOT_FOUND)
    PX_CL_ERR_(CL_DEVICE_NOT_AVAILABLE)
    PX_CL_ERR_(CL_COMPILER_NOT_AVAILABLE)
    PX_CL_ERR_(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    PX_CL_ERR_(CL_OUT_OF_RESOURCES)
    PX_CL_ERR_(CL_OUT_OF_HOST_MEMORY)
    PX_CL_ERR_(CL_PROFILING_INFO_NOT_AVAILABLE)
    PX_CL_ERR_(CL_MEM_COPY_OVERLAP)
    PX_CL_ERR_(CL_IMAGE_FORMAT_MISMATCH)
    PX_CL_ERR_(CL_IMAGE_FORMAT_NOT_SUPPORTED)
    PX_CL_ERR_(CL_BUILD_PROGRAM_FAILURE)
    PX_CL_ERR_(CL_MAP_FAILURE)
    PX_CL_ERR_(CL_MISALIGNED_SUB_BUFFER_OFFSET)
    PX_CL_ERR_(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
    PX_CL_ERR_(CL_COMPILE_PROGRAM_FAILURE)
    PX_CL_ERR_(CL_LINKER_NOT_AVAILABLE)
    PX_CL_ERR_(CL_LINK_PROGRAM_FAILURE)
    PX_CL_ERR_(CL_DEVICE_PARTITION_FAILED)
    PX_CL_ERR_(CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
    PX_CL_ERR_(CL_INVALID_VALUE)
    PX_CL_ERR_(CL_INVALID_DEVICE_TYPE)
    PX_CL_ERR_(CL_INVALID_PLATFORM)
    PX_CL_ERR_(CL_INVALID_DEVICE)
    PX_CL_ERR_(CL_INVALID_CONTEXT)
    PX_CL_ERR_(CL_INVALID_QUEUE_PROPERTIES)
    PX_CL_ERR_(CL_INVALID_COMMAND_QUEUE)
    PX_CL_ERR_(CL_INVALID_HOST_PTR)
    PX_CL_ERR_(CL_INVALID_MEM_OBJECT)
    PX_CL_ERR_(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR)
    PX_CL_ERR_(CL_INVALID_IMAGE_SIZE)
    PX_CL_ERR_(CL_INVALID_SAMPLER)
    PX_CL_ERR_(CL_INVALID_BINARY)
    PX_CL_ERR_(CL_INVALID_BUILD_OPTIONS)
    PX_CL_ERR_(CL_INVALID_PROGRAM)
    PX_CL_ERR_(CL_INVALID_PROGRAM_EXECUTABLE)
    PX_CL_ERR_(CL_INVALID_KERNEL_NAME)
    PX_CL_ERR_(CL_INVALID_KERNEL_DEFINITION)
    PX_CL_ERR_(CL_INVALID_KERNEL)
    PX_CL_ERR_(CL_INVALID_ARG_INDEX)
    PX_CL_ERR_(CL_INVALID_ARG_VALUE)
    PX_CL_ERR_(CL_INVALID_ARG_SIZE)
    PX_CL_ERR_(CL_INVALID_KERNEL_ARGS)
    PX_CL_ERR_(CL_INVALID_WORK_DIMENSION)
    PX_CL_ERR_(CL_INVALID_WORK_GROUP_SIZE)
    PX_CL_ERR_(CL_INVALID_WORK_ITEM_SIZE)
    PX_CL_ERR_(CL_INVALID_GLOBAL_OFFSET)
    PX_CL_ERR_(CL_INVALID_EVENT_WAIT_LIST)
    PX_CL_ERR_(CL_INVALID_EVENT)
    PX_CL_ERR_(CL_INVALID_OPERATION)
    PX_CL_ERR_(CL_INVALID_GL_OBJECT)
    PX_CL_ERR_(CL_INVALID_BUFFER_SIZE)
    PX_CL_ERR_(CL_INVALID_MIP_LEVEL)
    PX_CL_ERR_(CL_INVALID_GLOBAL_WORK_SIZE)
    PX_CL_ERR_(CL_INVALID_PROPERTY)
    PX_CL_ERR_(CL_INVALID_IMAGE_DESCRIPTOR)
    PX_CL_ERR_(CL_INVALID_COMPILER_OPTIONS)
    PX_CL_ERR_(CL_INVALID_LINKER_OPTIONS)
    PX_CL_ERR_(CL_INVALID_DEVICE_PARTITION_COUNT)
#undef PX_CL_ERR_
    case -1001: return "CL_PLATFORM_NOT_FOUND_KHR";
  }
  return "CL_UNKNOWN_ERROR";
}

enum px_status px_opencl_check(struct px_backend *be, cl_int err, const char *what) {
  enum px_status st = PX_STATUS_BACKEND;
  if (err == CL_SUCCESS) return PX_STATUS_OK;
  if (err == CL_MEM_OBJECT_ALLOCATION_FAILURE || err == CL_OUT_OF_HOST_MEMORY) st = PX_STATUS_NOMEM;
  return px_context_fail(be->ctx, st, "%s: %s (%d) on OpenCL device '%s'", what,
                         px_opencl_error_name(err), (int)err, be->impl ? px_cl(be)->name : "?");
}

cl_context px_opencl_context(struct px_backend *be) { return px_cl(be)->context; }
cl_command_queue px_opencl_queue(struct px_backend *be) { return px_cl(be)->queue; }
cl_device_id px_opencl_device(struct px_backend *be) { return px_cl(be)->device; }
cl_mem px_opencl_mem(struct px_buffer *buf) { return (cl_mem)buf->handle; }
size_t px_opencl_local_mem(struct px_backend *be) { return (size_t)px_cl(be)->local_mem; }

/* ------------------------------------------------------------------------ */
/* Device enumeration (all platforms, in platform order)                     */

/* Platforms into *out (malloc'ed, tiny table); 0 when there is no ICD. */
static cl_uint px_opencl_platforms(cl_platform_id **out) {
  cl_uint n = 0;
  *out = NULL;
  if (clGetPlatformIDs(0, NULL, &n) != CL_SUCCESS || n == 0) return 0;
  *out = malloc(n * sizeof **out);
  if (!*out) return 0;
  if (clGetPlatformIDs(n, *out, NULL) != CL_SUCCESS) {
    free(*out);
    *out = NULL;
    return 0;
  }
  return n;
}

static cl_uint px_opencl_platform_devices(cl_platform_id p, cl_device_id **out) {
  cl_uint n = 0;
  *out = NULL;
  if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 0, NULL, &n) != CL_SUCCESS || n == 0) return 0;
  *out = malloc(n * sizeof **out);
  if (!*out) return 0;
  if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, n, *out, NULL) != CL_SUCCESS) {
    free(*out);
    *out = NULL;
    return 0;
  }
  return n;
}

static int px_opencl_device_count(struct px_context *ctx) {
  cl_platform_id *ps;
  cl_uint np = px_opencl_platforms(&ps), i;
  int count = 0;
  (void)ctx;
  for (i = 0; i < np; ++i) {
    cl_device_id *ds;
    count += (int)px_opencl_platform_devices(ps[i], &ds);
    free(ds);
  }
  free(ps);
  return count;
}

static void px_opencl_string(cl_device_id d, cl_device_info what, char *buf, size_t size) {
  buf[0] = '\0';
  if (clGetDeviceInfo(d, what, size, buf, NULL) != CL_SUCCESS) snprintf(buf, size, "?");
  buf[size - 1] = '\0';
}

/* 1 if the space-separated list `list` contains `token`. */
static int px_opencl_has_token(const char *list, const char *token) {
  size_t len = strlen(token);
  const char *p = list;
  while ((p = strstr(p, token)) != NULL) {
    if ((p == list || p[-1] == ' ') && (p[len] == ' ' || p[len] == '\0')) return 1;
    p += len;
  }
  return 0;
}

/* fp64 is usable when the device advertises cl_khr_fp64 (or, on OpenCL 3.0,
 * the __opencl_c_fp64 feature shows up as a non-zero double FP config) and
 * reports a non-empty CL_DEVICE_DOUBLE_FP_CONFIG. */
static int px_opencl_query_fp64(cl_device_id d) {
  char ext[4096];
  cl_device_fp_config cfg = 0;
  size_t len = 0;
  if (clGetDeviceInfo(d, CL_DEVICE_EXTENSIONS, 0, NULL, &len) != CL_SUCCESS) return 0;
  if (len > sizeof ext) {
    char *big = malloc(len);
    int has;
    if (!big) return 0;
    has = clGetDeviceInfo(d, CL_DEVICE_EXTENSIONS, len, big, NULL) == CL_SUCCESS &&
          px_opencl_has_token(big, "cl_khr_fp64");
    free(big);
    if (!has) return 0;
  } else {
    px_opencl_string(d, CL_DEVICE_EXTENSIONS, ext, sizeof ext);
    if (!px_opencl_has_token(ext, "cl_khr_fp64")) return 0;
  }
  if (clGetDeviceInfo(d, CL_DEVICE_DOUBLE_FP_CONFIG, sizeof cfg, &cfg, NULL) != CL_SUCCESS)
    return 0;
  return cfg != 0;
}

static const char *px_opencl_type_name(cl_device_type t) {
  if (t & CL_DEVICE_TYPE_GPU) return "GPU";
  if (t & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  if (t & CL_DEVICE_TYPE_CPU) return "CPU";
  return "other";
}

/* "OpenCL C 1.2 PoCL" -> 1, 2 */
static void px_opencl_c_version(const char *s, int *major, int *minor) {
  *major = 0;
  *minor = 0;
  if (strncmp(s, "OpenCL C ", 9) == 0) sscanf(s + 9, "%d.%d", major, minor);
}

static void px_opencl_report(struct px_context *ctx, FILE *out) {
  cl_platform_id *ps;
  cl_uint np = px_opencl_platforms(&ps), i, j;
  int index = 0;
  (void)ctx;
  if (np == 0) {
    fprintf(out, "  opencl: no OpenCL platform found (no ICD installed or none loadable)\n");
    return;
  }
  for (i = 0; i < np; ++i) {
    char name[256], vendor[256], version[256];
    cl_device_id *ds;
    cl_uint nd;
    if (clGetPlatformInfo(ps[i], CL_PLATFORM_NAME, sizeof name, name, NULL) != CL_SUCCESS)
      snprintf(name, sizeof name, "?");
    if (clGetPlatformInfo(ps[i], CL_PLATFORM_VENDOR, sizeof vendor, vendor, NULL) != CL_SUCCESS)
      snprintf(vendor, sizeof vendor, "?");
    if (clGetPlatformInfo(ps[i], CL_PLATFORM_VERSION, sizeof version, version, NULL) != CL_SUCCESS)
      snprintf(version, sizeof version, "?");
    name[sizeof name - 1] = vendor[sizeof vendor - 1] = version[sizeof version - 1] = '\0';
    fprintf(out, "  opencl platform %u: %s (%s), %s\n", i, name, vendor, version);
    nd = px_opencl_platform_devices(ps[i], &ds);
    if (nd == 0) fprintf(out, "    no devices\n");
    for (j = 0; j < nd; ++j, ++index) {
      char dname[256], cver[128];
      cl_device_type type = 0;
      cl_uint cu = 0, clock = 0;
      cl_ulong gmem = 0, lmem = 0;
      size_t wg = 0;
      px_opencl_string(ds[j], CL_DEVICE_NAME, dname, sizeof dname);
      px_opencl_string(ds[j], CL_DEVICE_OPENCL_C_VERSION, cver, sizeof cver);
      clGetDeviceInfo(ds[j], CL_DEVICE_TYPE, sizeof type, &type, NULL);
      clGetDeviceInfo(ds[j], CL_DEVICE_MAX_COMPUTE_UNITS, sizeof cu, &cu, NULL);
      clGetDeviceInfo(ds[j], CL_DEVICE_MAX_CLOCK_FREQUENCY, sizeof clock, &clock, NULL);
      clGetDeviceInfo(ds[j], CL_DEVICE_GLOBAL_MEM_SIZE, sizeof gmem, &gmem, NULL);
      clGetDeviceInfo(ds[j], CL_DEVICE_LOCAL_MEM_SIZE, sizeof lmem, &lmem, NULL);
      clGetDeviceInfo(ds[j], CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof wg, &wg, NULL);
      fprintf(out,
              "    device %d: %s\n"
              "      type %s, %u compute units at %u MHz, global memory %.1f MiB, "
              "local memory %.1f KiB\n"
              "      max work-group size %zu, fp64 %s, %s\n",
              index, dname, px_opencl_type_name(type), cu, clock, (double)gmem / (1024.0 * 1024.0),
              (double)lmem / 1024.0, wg, px_opencl_query_fp64(ds[j]) ? "yes" : "no", cver);
    }
    free(ds);
  }
  free(ps);
}

/* ------------------------------------------------------------------------ */
/* Backend vtable                                                            */

static enum px_status px_opencl_init(struct px_backend *be, int device) {
  cl_platform_id *ps;
  cl_uint np = px_opencl_platforms(&ps), i;
  cl_device_id chosen = NULL;
  cl_platform_id chosen_platform = NULL;
  struct px_opencl *cl;
  cl_int err;
  int index = 0, major, minor;
  size_t items[3] = {0, 0, 0};
  if (np == 0)
    return px_context_fail(be->ctx, PX_STATUS_UNSUPPORTED,
                           "backend opencl: no OpenCL platform found (is an ICD such as "
                           "pocl-opencl-icd or a GPU driver installed?)");
  for (i = 0; i < np && !chosen; ++i) {
    cl_device_id *ds;
    cl_uint nd = px_opencl_platform_devices(ps[i], &ds);
    if (device < index + (int)nd) {
      chosen = ds[device - index];
      chosen_platform = ps[i];
    }
    index += (int)nd;
    free(ds);
  }
  free(ps);
  if (!chosen)
    return px_context_fail(be->ctx, PX_STATUS_NOT_FOUND,
                           "backend opencl: device %d does not exist; %d device%s found over "
                           "all platforms (numbered from 0, see `partix info`)",
                           device, index, index == 1 ? "" : "s");

  cl = px_mem_calloc(be->ctx, "opencl backend", 1, sizeof *cl);
  if (!cl) return PX_STATUS_NOMEM;
  be->impl = cl;
  cl->platform = chosen_platform;
  cl->device = chosen;
  px_opencl_string(chosen, CL_DEVICE_NAME, cl->name, sizeof cl->name);
  px_opencl_string(chosen, CL_DEVICE_OPENCL_C_VERSION, cl->c_version, sizeof cl->c_version);
  if (clGetPlatformInfo(chosen_platform, CL_PLATFORM_NAME, sizeof cl->platform_name,
                        cl->platform_name, NULL) != CL_SUCCESS)
    snprintf(cl->platform_name, sizeof cl->platform_name, "?");
  cl->platform_name[sizeof cl->platform_name - 1] = '\0';
  clGetDeviceInfo(chosen, CL_DEVICE_TYPE, sizeof cl->type, &cl->type, NULL);
  clGetDeviceInfo(chosen, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof cl->compute_units, &cl->compute_units,
                  NULL);
  clGetDeviceInfo(chosen, CL_DEVICE_MAX_CLOCK_FREQUENCY, sizeof cl->clock_mhz, &cl->clock_mhz,
                  NULL);
  clGetDeviceInfo(chosen, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof cl->global_mem, &cl->global_mem, NULL);
  clGetDeviceInfo(chosen, CL_DEVICE_LOCAL_MEM_SIZE, sizeof cl->local_mem, &cl->local_mem, NULL);
  clGetDeviceInfo(chosen, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof cl->max_alloc, &cl->max_alloc, NULL);
  clGetDeviceInfo(chosen, CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof cl->max_wg, &cl->max_wg, NULL);
  if (clGetDeviceInfo(chosen, CL_DEVICE_MAX_WORK_ITEM_SIZES, sizeof items, items, NULL) ==
          CL_SUCCESS &&
      items[0] && items[0] < cl->max_wg)
    cl->max_wg = items[0];
  if (cl->max_wg == 0) cl->max_wg = 1;

  px_opencl_c_version(cl->c_version, &major, &minor);
  if (major < 1 || (major == 1 && minor < 2)) {
    enum px_status st = px_context_fail(
        be->ctx, PX_STATUS_UNSUPPORTED,
        "backend opencl: device %d '%s' supports '%s'; partix kernels need OpenCL C 1.2", device,
        cl->name, cl->c_version);
    px_mem_free(be->ctx, cl);
    be->impl = NULL;
    return st;
  }
  be->fp64 = px_opencl_query_fp64(chosen);
  be->host_memory = 0;
  be->max_workgroup = cl->max_wg;

  cl->context = clCreateContext(NULL, 1, &chosen, NULL, NULL, &err);
  if (err == CL_SUCCESS) cl->queue = clCreateCommandQueue(cl->context, chosen, 0, &err);
  if (err != CL_SUCCESS) {
    enum px_status st = px_opencl_check(be, err, "backend opencl: creating context and queue");
    if (cl->context) clReleaseContext(cl->context);
    px_mem_free(be->ctx, cl);
    be->impl = NULL;
    return st;
  }
  snprintf(be->device, sizeof be->device, "%.100s (%.60s; %.40s; %u compute units; fp64 %s)",
           cl->name, cl->platform_name, cl->c_version, cl->compute_units, be->fp64 ? "yes" : "no");
  return PX_STATUS_OK;
}

static void px_opencl_release(struct px_backend *be) {
  struct px_opencl *cl = px_cl(be);
  size_t i;
  int s;
  if (!cl) return;
  if (cl->queue) clFinish(cl->queue);
  for (i = 0; i < cl->nkernels; ++i) {
    clReleaseKernel(cl->kernels[i].kernel);
    px_mem_free(be->ctx, cl->kernels[i].name);
  }
  for (i = 0; i < cl->nprograms; ++i) {
    clReleaseProgram(cl->programs[i].program);
    px_mem_free(be->ctx, cl->programs[i].key);
  }
  px_mem_free(be->ctx, cl->kernels);
  px_mem_free(be->ctx, cl->programs);
  for (s = 0; s < PX_OPENCL_SCRATCH_SLOTS; ++s)
    if (cl->scratch[s]) clReleaseMemObject(cl->scratch[s]);
  if (cl->queue) clReleaseCommandQueue(cl->queue);
  if (cl->context) clReleaseContext(cl->context);
  px_mem_free(be->ctx, cl);
  be->impl = NULL;
}

static enum px_status px_opencl_buffer_alloc(struct px_backend *be, struct px_buffer *buf,
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

static void px_opencl_buffer_release(struct px_backend *be, struct px_buffer *buf) {
  (void)be;
  if (buf->handle) clReleaseMemObject((cl_mem)buf->handle);
  buf->handle = NULL;
}

static enum px_status px_opencl_buffer_write(struct px_buffer *buf, size_t offset, size_t bytes,
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

static enum px_status px_opencl_buffer_read(struct px_buffer *buf, size_t offset, size_t bytes,
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

static enum px_status px_opencl_buffer_copy(struct px_buffer *dst, size_t dst_offset,
                                            struct px_buffer *src, size_t src_offset,
                                            size_t bytes) {
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

static enum px_status px_opencl_buffer_zero(struct px_buffer *buf) {
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

static enum px_status px_opencl_finish(struct px_backend *be) {
  return px_opencl_check(be, clFinish(px_cl(be)->queue), "waiting for the OpenCL queue");
}

static enum px_status px_opencl_lincomb(struct px_backend *be, enum px_dtype type, size_t n,
                                        int nterms, const double *coeffs,
                                        struct px_buffer *const *in, struct px_buffer *out) {
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

const struct px_backend_i px_backend_opencl_i = {
    .name = "opencl",
    .report = px_opencl_report,
    .device_count = px_opencl_device_count,
    .init = px_opencl_init,
    .release = px_opencl_release,
    .buffer_alloc = px_opencl_buffer_alloc,
    .buffer_release = px_opencl_buffer_release,
    .buffer_write = px_opencl_buffer_write,
    .buffer_read = px_opencl_buffer_read,
    .buffer_copy = px_opencl_buffer_copy,
    .buffer_zero = px_opencl_buffer_zero,
    .buffer_realloc = NULL, /* generic: new cl_mem + device copy */
    .finish = px_opencl_finish,
    .lincomb = px_opencl_lincomb,
};

/* ------------------------------------------------------------------------ */
/* Programs and kernels                                                      */

static char *px_opencl_strdup(struct px_context *ctx, const char *s) {
  size_t n = strlen(s) + 1;
  char *c = px_mem_alloc(ctx, "opencl cache", n);
  if (c) memcpy(c, s, n);
  return c;
}

/* The build log, trimmed to PX_OPENCL_LOG_MAX characters (owned by caller:
 * px_mem_free). */
static char *px_opencl_build_log(struct px_backend *be, cl_program program) {
  struct px_opencl *cl = px_cl(be);
  size_t len = 0;
  char *log;
  if (clGetProgramBuildInfo(program, cl->device, CL_PROGRAM_BUILD_LOG, 0, NULL, &len) !=
          CL_SUCCESS ||
      len == 0)
    return NULL;
  log = px_mem_alloc(be->ctx, "opencl build log", len + 1);
  if (!log) return NULL;
  if (clGetProgramBuildInfo(program, cl->device, CL_PROGRAM_BUILD_LOG, len, log, NULL) !=
      CL_SUCCESS) {
    px_mem_free(be->ctx, log);
    return NULL;
  }
  log[len] = '\0';
  if (len > PX_OPENCL_LOG_MAX) {
    static const char more[] = "\n[... build log truncated]";
    memcpy(log + PX_OPENCL_LOG_MAX - sizeof more, more, sizeof more);
  }
  return log;
}

/* px_opencl_program, recording the size of the program's PX_REAL (0: none). */
static enum px_status px_opencl_program_build(struct px_backend *be, const char *name,
                                              const char *source, const char *options, size_t real,
                                              cl_program *out);

enum px_status px_opencl_program(struct px_backend *be, const char *name, const char *source,
                                 const char *options, cl_program *out) {
  return px_opencl_program_build(be, name, source, options, 0, out);
}

static enum px_status px_opencl_program_build(struct px_backend *be, const char *name,
                                              const char *source, const char *options, size_t real,
                                              cl_program *out) {
  struct px_opencl *cl = px_cl(be);
  char key[512], full[512];
  size_t i;
  cl_int err;
  cl_program program;
  double t0;
  if (!options) options = "";
  snprintf(key, sizeof key, "%s\n%s", name, options);
  for (i = 0; i < cl->nprograms; ++i)
    if (strcmp(cl->programs[i].key, key) == 0) {
      *out = cl->programs[i].program;
      return PX_STATUS_OK;
    }
  /* the argument names and types, for px_opencl_args's checks (no effect on
     the code generated) */
  snprintf(full, sizeof full, "-cl-std=CL1.2 -cl-kernel-arg-info %s", options);
  t0 = px_time_now();
  program = clCreateProgramWithSource(cl->context, 1, &source, NULL, &err);
  if (err != CL_SUCCESS) {
    char what[160];
    snprintf(what, sizeof what, "creating OpenCL program '%s'", name);
    return px_opencl_check(be, err, what);
  }
  err = clBuildProgram(program, 1, &cl->device, full, NULL, NULL);
  if (err != CL_SUCCESS) {
    char *log = px_opencl_build_log(be, program);
    enum px_status st = px_context_fail(
        be->ctx, PX_STATUS_BACKEND,
        "OpenCL program '%s' failed to build on '%s' (%s; options \"%s\"); build log:\n%s", name,
        cl->name, px_opencl_error_name(err), full, log ? log : "(empty)");
    px_mem_free(be->ctx, log);
    clReleaseProgram(program);
    return st;
  }
  if (cl->nprograms == cl->programs_cap) {
    size_t cap = cl->programs_cap ? 2 * cl->programs_cap : 8;
    struct px_opencl_program *grown =
        px_mem_realloc(be->ctx, "opencl cache", cl->programs, cap * sizeof *grown);
    if (!grown) {
      clReleaseProgram(program);
      return PX_STATUS_NOMEM;
    }
    cl->programs = grown;
    cl->programs_cap = cap;
  }
  cl->programs[cl->nprograms].key = px_opencl_strdup(be->ctx, key);
  if (!cl->programs[cl->nprograms].key) {
    clReleaseProgram(program);
    return PX_STATUS_NOMEM;
  }
  cl->programs[cl->nprograms].program = program;
  cl->programs[cl->nprograms].real = real;
  ++cl->nprograms;
  px_log(be->ctx, PX_LOG_LEVEL_DEBUG, "opencl: built program '%s' (%s) in %.2f s", name, options,
         px_time_now() - t0);
  *out = program;
  return PX_STATUS_OK;
}

enum px_status px_opencl_program_real(struct px_backend *be, const char *name, const char *source,
                                      enum px_precision precision, const char *options,
                                      cl_program *out) {
  char full[448];
  const char *real;
  switch (precision) {
    case PX_PRECISION_SINGLE: real = "float"; break;
    case PX_PRECISION_DOUBLE:
      PX_TRY(px_backend_require(be, precision));
      real = "double";
      break;
    default:
      return px_context_fail(be->ctx, PX_STATUS_INVALID,
                             "OpenCL program '%s': precision must be single or double", name);
  }
  snprintf(full, sizeof full, "-DPX_REAL=%s %s", real, options ? options : "");
  return px_opencl_program_build(be, name, source, full, real[0] == 'f' ? 4 : 8, out);
}

enum px_status px_opencl_kernel(struct px_backend *be, cl_program program, const char *name,
                                cl_kernel *out) {
  struct px_opencl *cl = px_cl(be);
  size_t i;
  cl_int err;
  cl_kernel k;
  for (i = 0; i < cl->nkernels; ++i)
    if (cl->kernels[i].program == program && strcmp(cl->kernels[i].name, name) == 0) {
      *out = cl->kernels[i].kernel;
      return PX_STATUS_OK;
    }
  k = clCreateKernel(program, name, &err);
  if (err != CL_SUCCESS) {
    char what[160];
    snprintf(what, sizeof what, "creating OpenCL kernel '%s'", name);
    return px_opencl_check(be, err, what);
  }
  if (cl->nkernels == cl->kernels_cap) {
    size_t cap = cl->kernels_cap ? 2 * cl->kernels_cap : 16;
    struct px_opencl_kernel *grown =
        px_mem_realloc(be->ctx, "opencl cache", cl->kernels, cap * sizeof *grown);
    if (!grown) {
      clReleaseKernel(k);
      return PX_STATUS_NOMEM;
    }
    cl->kernels = grown;
    cl->kernels_cap = cap;
  }
  cl->kernels[cl->nkernels].name = px_opencl_strdup(be->ctx, name);
  if (!cl->kernels[cl->nkernels].name) {
    clReleaseKernel(k);
    return PX_STATUS_NOMEM;
  }
  cl->kernels[cl->nkernels].program = program;
  cl->kernels[cl->nkernels].kernel = k;
  cl->kernels[cl->nkernels].real = 0;
  cl->kernels[cl->nkernels].checked = 0;
  for (i = 0; i < cl->nprograms; ++i)
    if (cl->programs[i].program == program) cl->kernels[cl->nkernels].real = cl->programs[i].real;
  ++cl->nkernels;
  *out = k;
  return PX_STATUS_OK;
}

static void px_opencl_kernel_name(cl_kernel k, char *buf, size_t size) {
  if (clGetKernelInfo(k, CL_KERNEL_FUNCTION_NAME, size, buf, NULL) != CL_SUCCESS)
    snprintf(buf, size, "?");
  buf[size - 1] = '\0';
}

enum px_status px_opencl_arg(struct px_backend *be, cl_kernel k, cl_uint index, size_t size,
                             const void *value) {
  cl_int err = clSetKernelArg(k, index, size, value);
  if (err != CL_SUCCESS) {
    char name[128], what[192];
    px_opencl_kernel_name(k, name, sizeof name);
    snprintf(what, sizeof what, "setting argument %u of kernel '%s'", index, name);
    return px_opencl_check(be, err, what);
  }
  return PX_STATUS_OK;
}

enum px_status px_opencl_arg_mem(struct px_backend *be, cl_kernel k, cl_uint index,
                                 struct px_buffer *buf) {
  cl_mem m = (cl_mem)buf->handle;
  return px_opencl_arg(be, k, index, sizeof m, &m);
}

enum px_status px_opencl_arg_local(struct px_backend *be, cl_kernel k, cl_uint index,
                                   size_t bytes) {
  return px_opencl_arg(be, k, index, bytes, NULL);
}

static enum px_status px_opencl_kernel_limits(struct px_backend *be, cl_kernel k, size_t *max,
                                              size_t *multiple) {
  struct px_opencl *cl = px_cl(be);
  cl_int err =
      clGetKernelWorkGroupInfo(k, cl->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof *max, max, NULL);
  if (err == CL_SUCCESS)
    err = clGetKernelWorkGroupInfo(k, cl->device, CL_KERNEL_PREFERRED_WORK_GROUP_SIZE_MULTIPLE,
                                   sizeof *multiple, multiple, NULL);
  if (err != CL_SUCCESS) return px_opencl_check(be, err, "querying kernel work-group limits");
  if (*max > cl->max_wg) *max = cl->max_wg;
  if (*max == 0) *max = 1;
  if (*multiple == 0) *multiple = 1;
  return PX_STATUS_OK;
}

enum px_status px_opencl_local_size(struct px_backend *be, cl_kernel k, size_t preferred,
                                    size_t *out) {
  size_t max, multiple, size;
  PX_TRY(px_opencl_kernel_limits(be, k, &max, &multiple));
  if (be->workgroup) {
    if (be->workgroup > max) {
      char name[128];
      px_opencl_kernel_name(k, name, sizeof name);
      return px_context_fail(be->ctx, PX_STATUS_UNSUPPORTED,
                             "work-group size %zu is too large for kernel '%s' on '%s' "
                             "(at most %zu); set a smaller one or 0 (automatic)",
                             be->workgroup, name, px_cl(be)->name, max);
    }
    *out = be->workgroup;
    return PX_STATUS_OK;
  }
  size = preferred < max ? preferred : max;
  if (size >= multiple) size -= size % multiple;
  *out = size ? size : 1;
  return PX_STATUS_OK;
}

enum px_status px_opencl_local_pow2(struct px_backend *be, cl_kernel k, size_t cap, size_t *out) {
  size_t max, multiple, size = 1;
  PX_TRY(px_opencl_kernel_limits(be, k, &max, &multiple));
  if (cap < max) max = cap;
  while (size * 2 <= max) size *= 2;
  *out = size;
  return PX_STATUS_OK;
}

enum px_status px_opencl_launch(struct px_backend *be, cl_kernel k, size_t n, size_t local) {
  size_t global;
  cl_int err;
  if (n == 0) return PX_STATUS_OK;
  if (local == 0) PX_TRY(px_opencl_local_size(be, k, 256, &local));
  global = (n + local - 1) / local * local;
  err = clEnqueueNDRangeKernel(px_cl(be)->queue, k, 1, NULL, &global, &local, 0, NULL, NULL);
  if (err != CL_SUCCESS) {
    char name[128], what[224];
    px_opencl_kernel_name(k, name, sizeof name);
    snprintf(what, sizeof what, "launching kernel '%s' (global %zu, local %zu)", name, global,
             local);
    return px_opencl_check(be, err, what);
  }
  return PX_STATUS_OK;
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

/* ---- typed, named kernel arguments -------------------------------------- */

void px_opencl_args_begin(struct px_opencl_args *a, struct px_backend *be, cl_kernel k) {
  struct px_opencl *cl = px_cl(be);
  size_t i;
  memset(a, 0, sizeof *a);
  a->be = be;
  a->k = k;
  a->st = PX_STATUS_OK;
  for (i = 0; i < cl->nkernels; ++i)
    if (cl->kernels[i].kernel == k) {
      a->real = cl->kernels[i].real;
      a->checked = &cl->kernels[i].checked;
      a->check = !cl->kernels[i].checked;
      break;
    }
}

/* 1 for the names of OpenCL C's built-in scalar types. */
static int px_opencl_scalar_type(const char *t) {
  static const char *const names[] = {"char", "uchar", "short", "ushort", "int",  "uint",
                                      "long", "ulong", "float", "double", "half", "size_t"};
  size_t i;
  for (i = 0; i < sizeof names / sizeof names[0]; ++i)
    if (strcmp(t, names[i]) == 0) return 1;
  return 0;
}

/* At the first binding of a kernel: argument a->n must be called `name` and,
 * when `type` is not NULL, be of that type (the kernel's own names and type
 * names, from -cl-kernel-arg-info; skipped where the device keeps none). */
static void px_opencl_args_check(struct px_opencl_args *a, const char *name, const char *type) {
  char have[128], kname[128];
  if (a->st != PX_STATUS_OK || !a->check) return;
  px_opencl_kernel_name(a->k, kname, sizeof kname);
  if (clGetKernelArgInfo(a->k, a->n, CL_KERNEL_ARG_NAME, sizeof have, have, NULL) == CL_SUCCESS) {
    have[sizeof have - 1] = '\0';
    if (strcmp(have, name) != 0) {
      a->st = px_context_fail(a->be->ctx, PX_STATUS_INTERNAL,
                              "OpenCL kernel '%s': argument %u is '%s', bound as '%s'", kname,
                              (unsigned)a->n, have, name);
      return;
    }
  }
  if (type && clGetKernelArgInfo(a->k, a->n, CL_KERNEL_ARG_TYPE_NAME, sizeof have, have, NULL) ==
                  CL_SUCCESS) {
    have[sizeof have - 1] = '\0';
    /* a typedef (px_real) is reported by its name: its size is checked by
       clSetKernelArg */
    if (px_opencl_scalar_type(have) && strcmp(have, type) != 0)
      a->st = px_context_fail(a->be->ctx, PX_STATUS_INTERNAL,
                              "OpenCL kernel '%s': argument %u '%s' is of type %s, bound as %s",
                              kname, (unsigned)a->n, name, have, type);
  }
}

static void px_opencl_args_set(struct px_opencl_args *a, const char *name, const char *type,
                               size_t size, const void *value) {
  px_opencl_args_check(a, name, type);
  if (a->st == PX_STATUS_OK) a->st = px_opencl_arg(a->be, a->k, a->n, size, value);
  ++a->n;
}

void px_opencl_args_mem(struct px_opencl_args *a, const char *name, struct px_buffer *buf) {
  cl_mem m = buf ? px_opencl_mem(buf) : NULL;
  px_opencl_args_set(a, name, NULL, sizeof m, &m);
}

void px_opencl_args_clmem(struct px_opencl_args *a, const char *name, cl_mem m) {
  px_opencl_args_set(a, name, NULL, sizeof m, &m);
}

void px_opencl_args_i32(struct px_opencl_args *a, const char *name, int32_t v) {
  const cl_int x = v;
  px_opencl_args_set(a, name, "int", sizeof x, &x);
}

void px_opencl_args_u32(struct px_opencl_args *a, const char *name, uint32_t v) {
  const cl_uint x = v;
  px_opencl_args_set(a, name, "uint", sizeof x, &x);
}

void px_opencl_args_f32(struct px_opencl_args *a, const char *name, float v) {
  const cl_float x = v;
  px_opencl_args_set(a, name, "float", sizeof x, &x);
}

void px_opencl_args_f64(struct px_opencl_args *a, const char *name, double v) {
  const cl_double x = v;
  px_opencl_args_set(a, name, "double", sizeof x, &x);
}

void px_opencl_args_real(struct px_opencl_args *a, const char *name, double v) {
  if (a->real == 4) {
    px_opencl_args_f32(a, name, (float)v);
  } else if (a->real == 8) {
    px_opencl_args_f64(a, name, v);
  } else {
    if (a->st == PX_STATUS_OK)
      a->st = px_context_fail(a->be->ctx, PX_STATUS_INTERNAL,
                              "OpenCL argument '%s': a real of a program built without "
                              "px_opencl_program_real",
                              name);
    ++a->n;
  }
}

void px_opencl_args_local(struct px_opencl_args *a, const char *name, size_t bytes) {
  px_opencl_args_set(a, name, NULL, bytes, NULL);
}

void px_opencl_args_value(struct px_opencl_args *a, const char *name, size_t size,
                          const void *value) {
  px_opencl_args_set(a, name, NULL, size, value);
}

enum px_status px_opencl_args_end(struct px_opencl_args *a) {
  cl_uint have = 0;
  char kname[128];
  if (a->st != PX_STATUS_OK || !a->check) return a->st;
  if (clGetKernelInfo(a->k, CL_KERNEL_NUM_ARGS, sizeof have, &have, NULL) == CL_SUCCESS &&
      have != a->n) {
    px_opencl_kernel_name(a->k, kname, sizeof kname);
    return a->st = px_context_fail(a->be->ctx, PX_STATUS_INTERNAL,
                                   "OpenCL kernel '%s' takes %u arguments, %u were bound", kname,
                                   (unsigned)have, (unsigned)a->n);
  }
  if (a->checked) *a->checked = 1;
  return PX_STATUS_OK;
}

enum px_status px_opencl_args_launch(struct px_opencl_args *a, size_t n, size_t local) {
  PX_TRY(px_opencl_args_end(a));
  return px_opencl_launch(a->be, a->k, n, local);
}
