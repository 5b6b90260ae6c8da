/* The opencl backend: kernel arguments (by index, and typed and named with
 * a check against the kernel's signature), work-group sizes and launches. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compute/opencl/opencl_impl.h"

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
  return px_opencl_launch_range(be, k, 0, n, local);
}

enum px_status px_opencl_launch_range(struct px_backend *be, cl_kernel k, size_t first, size_t n,
                                      size_t local) {
  size_t global;
  cl_int err;
  if (n == 0) return PX_STATUS_OK;
  if (local == 0) PX_TRY(px_opencl_local_size(be, k, 256, &local));
  global = (n + local - 1) / local * local;
  /* first = 0: no offset at all, the launch as it always was */
  err = clEnqueueNDRangeKernel(px_cl(be)->queue, k, 1, first ? &first : NULL, &global, &local, 0,
                               NULL, NULL);
  if (err != CL_SUCCESS) {
    char name[128], what[256];
    px_opencl_kernel_name(k, name, sizeof name);
    snprintf(what, sizeof what, "launching kernel '%s' (global %zu from %zu, local %zu)", name,
             global, first, local);
    return px_opencl_check(be, err, what);
  }
  return PX_STATUS_OK;
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

enum px_status px_opencl_args_launch_range(struct px_opencl_args *a, size_t first, size_t n,
                                           size_t local) {
  PX_TRY(px_opencl_args_end(a));
  return px_opencl_launch_range(a->be, a->k, first, n, local);
}
