/* Private layout of backends and buffers, and the per-module kernel-table
 * mechanism (never installed).
 *
 * A backend is a const vtable (struct px_backend_i) plus a context pointer
 * (struct px_backend), as in ggml's backend_i; operations are split into
 * REQUIRED ones that every backend implements and OPTIONAL ones that may be
 * NULL, in which case backend.c supplies a generic fallback built from the
 * required ones (as SUNDIALS' N_Vector ops do).
 *
 * Kernel tables (how shared kernels and solvers get per-backend code)
 * -------------------------------------------------------------------
 * Code that runs loops on a backend (grid build, direct sum, a solver's force
 * pass) does not extend the vtable. Each module defines a small ops struct
 * whose FIRST member is `const char *backend`, one const instance per
 * backend, and a table of pointers to them:
 *
 *     struct px_foo_ops {
 *       const char *backend;            // "cpu", "opencl": must be first
 *       enum px_status (*step)(struct px_foo *foo, ...);
 *     };
 *     extern const struct px_foo_ops px_foo_ops_cpu;     // foo_cpu.c
 *     #ifdef PX_HAVE_OPENCL
 *     extern const struct px_foo_ops px_foo_ops_opencl;  // foo_opencl.c
 *     #endif
 *
 *     static const void *const px_foo_table[] = {
 *       &px_foo_ops_cpu,
 *     #ifdef PX_HAVE_OPENCL
 *       &px_foo_ops_opencl,
 *     #endif
 *     };
 *
 *     const struct px_foo_ops *ops = PX_BACKEND_PICK(be, "foo", px_foo_table);
 *     if (!ops) return px_context_status(be->ctx);   // message already set
 *
 * The pick compares names only: solver code never tests for a backend type,
 * and a module without an implementation for some backend fails with
 * PX_STATUS_UNSUPPORTED and a message naming module and backend. Pick once
 * when a handle is created (store the ops pointer) or per call (it is a
 * strcmp over a two-entry table). `#ifdef PX_HAVE_OPENCL` is allowed only to
 * say "this backend is compiled in".
 *
 * Per-precision CPU loops are written once as a template header that uses
 * PX_REAL/PX_SFX (see src/kernels/px_kernel.h) and instantiated by two tiny
 * translation units (foo_cpu_f32.c: `#define PX_REAL float` + include),
 * exactly as the OpenCL program is built once per -DPX_REAL. */
#ifndef PX_BACKEND_IMPL_H
#define PX_BACKEND_IMPL_H

#include <stddef.h>

#include "partix/backend.h"

#define PX_COUNTOF(a) (sizeof(a) / sizeof((a)[0]))

/* The arguments when the opencl backend is compiled in, nothing otherwise:
 * the one place that asks, so that module and solver tables list their
 * OpenCL entries without an #ifdef of their own:
 *   static const void *const px_foo_table[] = {&px_foo_ops_cpu,
 *                                              PX_IF_OPENCL(&px_foo_ops_opencl, )};
 * (FOO_opencl.c files are compiled only with the backend: CMakeLists.txt). */
#ifdef PX_HAVE_OPENCL
#define PX_IF_OPENCL(...) __VA_ARGS__
#else
#define PX_IF_OPENCL(...)
#endif

/* Longest label kept for a buffer (longer ones are truncated). */
#define PX_BUFFER_LABEL_MAX 48

struct px_buffer {
  struct px_backend *backend; /* borrowed: the backend outlives its buffers */
  size_t bytes;               /* logical size */
  size_t capacity;            /* allocated bytes (>= bytes, >= 1) */
  void *host;                 /* cpu: owned px_mem block; NULL on device backends */
  void *handle;               /* opencl: owned cl_mem; NULL on host backends */
  char label[PX_BUFFER_LABEL_MAX];
};

struct px_backend_i {
  const char *name;

  /* ---- listing (optional) ---- */
  /* The lines of `partix info` for this backend ("  NAME: ..."). */
  void (*report)(struct px_context *ctx, FILE *out);
  /* Devices this backend can run on (NULL: one). */
  int (*device_count)(struct px_context *ctx);
  /* The device a run opens when backend.device is not given (NULL: 0). */
  int (*default_device)(void);

  /* ---- required ---- */
  /* Fill be->impl, be->device, be->fp64, be->host_memory, be->max_workgroup
   * (be->ctx, be->threads are set before). `device`: index over all devices
   * of this backend (ignored by cpu). */
  enum px_status (*init)(struct px_backend *be, int device);
  /* Free be->impl (all buffers are gone). */
  void (*release)(struct px_backend *be);
  /* Allocate `capacity` (>= 1) bytes into buf->host or buf->handle. */
  enum px_status (*buffer_alloc)(struct px_backend *be, struct px_buffer *buf, size_t capacity);
  /* Free buf->host / buf->handle (not buf itself). */
  void (*buffer_release)(struct px_backend *be, struct px_buffer *buf);
  /* Ranges are checked by backend.c before these are called. */
  enum px_status (*buffer_write)(struct px_buffer *buf, size_t offset, size_t bytes,
                                 const void *src);
  enum px_status (*buffer_read)(struct px_buffer *buf, size_t offset, size_t bytes, void *dst);
  enum px_status (*buffer_copy)(struct px_buffer *dst, size_t dst_offset, struct px_buffer *src,
                                size_t src_offset, size_t bytes);

  /* ---- optional (NULL: generic fallback in backend.c) ---- */
  /* Zero the first buf->bytes bytes. Fallback: writes from a zeroed host block. */
  enum px_status (*buffer_zero)(struct px_buffer *buf);
  /* Change the allocation to `capacity` bytes keeping min(old, new) bytes of
   * content. Fallback: alloc + copy + release. */
  enum px_status (*buffer_realloc)(struct px_buffer *buf, size_t capacity);
  /* Wait for queued work. Fallback: nothing to wait for. */
  enum px_status (*finish)(struct px_backend *be);
  /* out[i] = sum_k c[k] * in[k][i], i < n, in the element type `type`
   * (F32/F64); out may be one of the inputs. Fallback: on the host. */
  enum px_status (*lincomb)(struct px_backend *be, enum px_dtype type, size_t n, int nterms,
                            const double *coeffs, struct px_buffer *const *in,
                            struct px_buffer *out);
};

struct px_backend {
  const struct px_backend_i *iface; /* borrowed (static) */
  struct px_context *ctx;           /* borrowed */
  void *impl;                       /* owned by iface (freed by release) */
  int threads;                      /* host threads for host loops (>= 1) */
  int threads_auto;                 /* 1: `threads` was left to partix (0 asked) */
  size_t workgroup;                 /* work-group size / tile width; 0 = automatic */
  size_t max_workgroup;             /* largest accepted workgroup setting */
  int fp64;                         /* device computes in double (queried) */
  int host_memory;                  /* buffers live in host memory */
  size_t live_buffers;              /* buffers not yet freed */
  char device[256];                 /* human-readable description */
};

/* Kernel tables: return the entry of `table` (n pointers to ops structs
 * whose first member is `const char *backend`) whose backend name equals
 * be's, or NULL after recording PX_STATUS_UNSUPPORTED ("<module> has no
 * implementation for backend '<name>'"). */
const void *px_backend_pick(struct px_backend *be, const char *module, const void *const *table,
                            size_t n);
#define PX_BACKEND_PICK(be, module, table) \
  px_backend_pick((be), (module), (table), PX_COUNTOF(table))

/* Argument checks shared by kernel modules; each records a message naming
 * `what` (the calling function) and returns PX_STATUS_INVALID on failure. */
/* buf non-NULL, on backend be, and holding at least n elements of `type`. */
enum px_status px_buffer_check(struct px_backend *be, const char *what, const char *arg,
                               struct px_buffer *buf, size_t n, enum px_dtype type);
/* Element type of a precision's arrays: SINGLE -> F32, DOUBLE -> F64;
 * MIXED is a solver-level choice and is rejected here. */
enum px_status px_precision_dtype(struct px_backend *be, const char *what,
                                  enum px_precision precision, enum px_dtype *out);

/* Backends compiled in (registered in backend.c). */
extern const struct px_backend_i px_backend_cpu_i;
extern const struct px_backend_i px_backend_opencl_i; /* with PX_HAVE_OPENCL */

#endif
