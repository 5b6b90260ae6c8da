/* The opencl backend: programs built from the embedded sources on first use
 * and cached with their kernels for the backend's lifetime. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compute/opencl/opencl_impl.h"
#include "partix/memory.h"
#include "partix/timer.h"

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
