/* Typed, named OpenCL kernel arguments (compute/opencl/kernels.h): a kernel
 * bound by name runs and gives the exact result in float and in double
 * programs (px_opencl_args_real follows the program's PX_REAL); the first
 * binding of a kernel refuses a wrong name, a wrong scalar type and a wrong
 * argument count, naming the kernel and the argument. Skipped (77) without
 * an OpenCL device. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compute/opencl/kernels.h"
#include "compute_test.h"
#include "partix/partix.h"
#include "px_test.h"

/* y[i] = a * x[i] + b for i < n (a, b: the program's real; b2: a float in
 * every program; shift: an int). */
static const char px_test_source[] =
    "__kernel void px_test_axpb(uint n, __global const PX_REAL *x, __global PX_REAL *y,\n"
    "                           PX_REAL a, float b, int shift) {\n"
    "  const uint i = get_global_id(0);\n"
    "  if (i >= n) return;\n"
    "  y[i] = a * x[i] + (PX_REAL)b + (PX_REAL)shift;\n"
    "}\n";

#define N 100

/* Run the kernel of a program of `precision` with every argument right:
 * exact results (small integers and halves). */
static void test_binding_runs(struct px_backend *be, enum px_precision precision) {
  struct px_context *ctx = px_backend_context(be);
  const size_t es = precision == PX_PRECISION_DOUBLE ? 8 : 4;
  struct px_buffer *x = NULL, *y = NULL;
  cl_program prog;
  cl_kernel k;
  struct px_opencl_args a;
  unsigned char hx[N * 8], hy[N * 8];
  int i, pass;
  for (i = 0; i < N; ++i) {
    if (es == 8)
      ((double *)hx)[i] = i;
    else
      ((float *)hx)[i] = (float)i;
  }
  PX_CHECK_OK(ctx, px_buffer_create(be, "x", N * es, &x));
  PX_CHECK_OK(ctx, px_buffer_create(be, "y", N * es, &y));
  PX_CHECK_OK(ctx, px_buffer_write(x, 0, N * es, hx));
  PX_CHECK_OK(ctx, px_opencl_program_real(be, "test_args", px_test_source, precision, "", &prog));
  PX_CHECK_OK(ctx, px_opencl_kernel(be, prog, "px_test_axpb", &k));
  /* twice: the first binding checks the signature, the second only sets */
  for (pass = 0; pass < 2; ++pass) {
    px_opencl_args_begin(&a, be, k);
    px_opencl_args_u32(&a, "n", N);
    px_opencl_args_mem(&a, "x", x);
    px_opencl_args_mem(&a, "y", y);
    px_opencl_args_real(&a, "a", 2.0);
    px_opencl_args_f32(&a, "b", 0.5f);
    px_opencl_args_i32(&a, "shift", pass);
    PX_CHECK_OK(ctx, px_opencl_args_launch(&a, N, 0));
    PX_CHECK_OK(ctx, px_buffer_read(y, 0, N * es, hy));
    for (i = 0; i < N; ++i) {
      const double want = 2.0 * i + 0.5 + pass;
      const double got = es == 8 ? ((double *)hy)[i] : ((float *)hy)[i];
      PX_CHECK_MSG(got == want, "%s pass %d: y[%d] = %g, expected %g", es == 8 ? "double" : "float",
                   pass, i, got, want);
    }
  }
  px_buffer_free(x);
  px_buffer_free(y);
}

/* A binding that does not match the signature fails at its first use with
 * the kernel's and the argument's names. */
static void expect_refused(struct px_backend *be, int what, const char *expect) {
  struct px_context *ctx = px_backend_context(be);
  struct px_buffer *x = NULL;
  cl_program prog;
  cl_kernel k;
  struct px_opencl_args a;
  enum px_status st;
  PX_CHECK_OK(ctx, px_buffer_create(be, "x", N * 4, &x));
  /* a program of its own per case (distinct options), so that no earlier
     binding has marked the kernel checked */
  char opts[32];
  snprintf(opts, sizeof opts, "-DPX_TEST_CASE=%d", what);
  PX_CHECK_OK(ctx, px_opencl_program_real(be, "test_args", px_test_source, PX_PRECISION_SINGLE,
                                          opts, &prog));
  PX_CHECK_OK(ctx, px_opencl_kernel(be, prog, "px_test_axpb", &k));
  px_opencl_args_begin(&a, be, k);
  px_opencl_args_u32(&a, "n", N);
  px_opencl_args_mem(&a, what == 0 ? "xx" : "x", x); /* 0: a wrong name */
  px_opencl_args_mem(&a, "y", x);
  if (what == 1)
    px_opencl_args_f64(&a, "a", 2.0); /* 1: double for a float program's real */
  else
    px_opencl_args_real(&a, "a", 2.0);
  px_opencl_args_f32(&a, "b", 0.5f);
  if (what != 2) px_opencl_args_i32(&a, "shift", 0); /* 2: one argument short */
  st = px_opencl_args_launch(&a, N, 0);
  PX_CHECK_MSG(st == PX_STATUS_INTERNAL, "case %d: %s", what, px_status_name(st));
  PX_CHECK_MSG(strstr(px_context_message(ctx), "px_test_axpb") != NULL, "case %d: %s", what,
               px_context_message(ctx));
  PX_CHECK_MSG(strstr(px_context_message(ctx), expect) != NULL, "case %d: '%s' not in %s", what,
               expect, px_context_message(ctx));
  px_context_clear(ctx);
  px_buffer_free(x);
}

int main(void) {
  struct px_context *ctx = NULL;
  struct px_backend *be;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  be = px_test_backend(ctx, "opencl", 0);
  test_binding_runs(be, PX_PRECISION_SINGLE);
  if (px_backend_has_fp64(be)) test_binding_runs(be, PX_PRECISION_DOUBLE);
  expect_refused(be, 0, "argument 1 is 'x', bound as 'xx'");
  expect_refused(be, 1, "argument 3 'a' is of type float, bound as double");
  expect_refused(be, 2, "takes 6 arguments, 5 were bound");
  px_backend_free(be);
  px_context_free(ctx);
  return px_test_report("test_opencl_args");
}
