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
/* Backend vtable                                                            */

static enum px_status px_opencl_init(struct px_backend *be, int device) {
  cl_platform_id *ps;
  cl_device_id *ds;
  cl_device_id chosen = NULL;
  cl_platform_id chosen_platform = NULL;
  struct px_opencl *cl;
  cl_int err;
  cl_uint np;
  int ndev, major, minor;
  size_t items[3] = {0, 0, 0};
  ndev = (int)px_opencl_devices(&ds, &ps, &np);
  if (device >= 0 && device < ndev) {
    chosen = ds[device];
    chosen_platform = ps[device];
  }
  free(ds);
  free(ps);
  if (np == 0)
    return px_context_fail(be->ctx, PX_STATUS_UNSUPPORTED,
                           "backend opencl: no OpenCL platform found (is an ICD such as "
                           "pocl-opencl-icd or a GPU driver installed?)");
  if (!chosen)
    return px_context_fail(be->ctx, PX_STATUS_NOT_FOUND,
                           "backend opencl: device %d does not exist; %d device%s found over "
                           "all platforms (numbered from 0, see `partix info`)",
                           device, ndev, ndev == 1 ? "" : "s");

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

const struct px_backend_i px_backend_opencl_i = {
    .name = "opencl",
    .report = px_opencl_report,
    .device_count = px_opencl_device_count,
    .default_device = px_opencl_default_device,
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
