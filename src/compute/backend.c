/* Backend dispatch: the public backend/buffer API, argument checks, and the
 * generic fallbacks for optional vtable entries. */
#include "compute/backend_impl.h"

#include <omp.h>
#include <stdint.h>
#include <string.h>

#include "partix/memory.h"

static const struct px_backend_i *const px_backend_registry[] = {
    &px_backend_cpu_i, PX_IF_OPENCL(&px_backend_opencl_i, )};

static const char *const px_backend_name_list[] = {"cpu", PX_IF_OPENCL("opencl", ) NULL};

const char *const *px_backend_names(void) { return px_backend_name_list; }

enum px_status px_backend_create(struct px_context *ctx, const char *name, int device, int threads,
                                 struct px_backend **out) {
  const struct px_backend_i *iface = NULL;
  struct px_backend *be;
  enum px_status st;
  size_t i;
  if (!out) return px_context_fail(ctx, PX_STATUS_INVALID, "px_backend_create: out is NULL");
  *out = NULL;
  if (!ctx) return PX_STATUS_INVALID;
  if (!name) return px_context_fail(ctx, PX_STATUS_INVALID, "px_backend_create: name is NULL");
  for (i = 0; i < PX_COUNTOF(px_backend_registry); ++i)
    if (strcmp(px_backend_registry[i]->name, name) == 0) iface = px_backend_registry[i];
  if (!iface) {
    char known[128] = "";
    for (i = 0; px_backend_name_list[i]; ++i) {
      if (i) strncat(known, ", ", sizeof known - strlen(known) - 1);
      strncat(known, px_backend_name_list[i], sizeof known - strlen(known) - 1);
    }
#ifndef PX_HAVE_OPENCL
    if (strcmp(name, "opencl") == 0)
      return px_context_fail(ctx, PX_STATUS_UNSUPPORTED,
                             "backend 'opencl' is not compiled into this build "
                             "(configure with -DPX_WITH_OPENCL=ON); available: %s",
                             known);
#endif
    return px_context_fail(ctx, PX_STATUS_NOT_FOUND, "unknown backend '%s' (available: %s)", name,
                           known);
  }
  if (threads < 0)
    return px_context_fail(ctx, PX_STATUS_INVALID,
                           "backend '%s': threads = %d, expected >= 0 (0 = all cores)", name,
                           threads);
  if (device < 0)
    return px_context_fail(ctx, PX_STATUS_INVALID, "backend '%s': device = %d, expected >= 0", name,
                           device);
  be = px_mem_calloc(ctx, "backend", 1, sizeof *be);
  if (!be) return PX_STATUS_NOMEM;
  be->iface = iface;
  be->ctx = ctx;
  be->threads = threads > 0 ? threads : omp_get_num_procs();
  be->threads_auto = threads == 0;
  if (be->threads < 1) be->threads = 1;
  st = iface->init(be, device);
  if (st != PX_STATUS_OK) {
    px_mem_free(ctx, be);
    return st;
  }
  px_log(ctx, PX_LOG_LEVEL_DEBUG, "backend %s: %s", iface->name, be->device);
  *out = be;
  return PX_STATUS_OK;
}

void px_backend_free(struct px_backend *be) {
  if (!be) return;
  if (be->live_buffers)
    px_log(be->ctx, PX_LOG_LEVEL_WARN,
           "backend %s freed with %zu buffer(s) still allocated (leaked)", be->iface->name,
           be->live_buffers);
  be->iface->release(be);
  px_mem_free(be->ctx, be);
}

const char *px_backend_name(const struct px_backend *be) { return be ? be->iface->name : "?"; }
const char *px_backend_device(const struct px_backend *be) { return be ? be->device : ""; }
struct px_context *px_backend_context(const struct px_backend *be) {
  return be ? be->ctx : NULL;
}
int px_backend_has_fp64(const struct px_backend *be) { return be ? be->fp64 : 0; }
int px_backend_threads(const struct px_backend *be) { return be ? be->threads : 0; }
int px_backend_threads_auto(const struct px_backend *be) { return be ? be->threads_auto : 0; }
int px_backend_host_memory(const struct px_backend *be) { return be ? be->host_memory : 0; }
size_t px_backend_workgroup(const struct px_backend *be) { return be ? be->workgroup : 0; }

enum px_status px_backend_set_workgroup(struct px_backend *be, size_t size) {
  if (!be) return PX_STATUS_INVALID;
  if (size > be->max_workgroup)
    return px_context_fail(be->ctx, PX_STATUS_INVALID,
                           "backend %s: work-group size %zu exceeds the device limit %zu "
                           "(0 = automatic)",
                           be->iface->name, size, be->max_workgroup);
  be->workgroup = size;
  return PX_STATUS_OK;
}

enum px_status px_backend_finish(struct px_backend *be) {
  if (!be) return PX_STATUS_INVALID;
  return be->iface->finish ? be->iface->finish(be) : PX_STATUS_OK;
}

enum px_status px_backend_require(struct px_backend *be, enum px_precision precision) {
  if (!be) return PX_STATUS_INVALID;
  switch (precision) {
    case PX_PRECISION_SINGLE: return PX_STATUS_OK;
    case PX_PRECISION_DOUBLE:
    case PX_PRECISION_MIXED:
      if (be->fp64) return PX_STATUS_OK;
      return px_context_fail(be->ctx, PX_STATUS_UNSUPPORTED,
                             "backend %s: device '%s' has no double-precision support "
                             "(cl_khr_fp64), which precision '%s' needs; use precision: single "
                             "or another device",
                             be->iface->name, be->device, px_precision_name(precision));
  }
  return px_context_fail(be->ctx, PX_STATUS_INVALID, "backend %s: unknown precision %d",
                         be->iface->name, (int)precision);
}

void px_backend_report(struct px_context *ctx, FILE *out) {
  size_t i;
  if (!out) return;
  fprintf(out, "compute backends:");
  for (i = 0; px_backend_name_list[i]; ++i) fprintf(out, " %s", px_backend_name_list[i]);
  fputc('\n', out);
  for (i = 0; i < PX_COUNTOF(px_backend_registry); ++i)
    if (px_backend_registry[i]->report) px_backend_registry[i]->report(ctx, out);
#ifndef PX_HAVE_OPENCL
  fprintf(out, "  opencl: not compiled in\n");
#endif
}

int px_backend_default_device(const char *name) {
  size_t i;
  for (i = 0; name && i < PX_COUNTOF(px_backend_registry); ++i)
    if (strcmp(px_backend_registry[i]->name, name) == 0)
      return px_backend_registry[i]->default_device ? px_backend_registry[i]->default_device() : 0;
  return 0;
}

int px_backend_opencl_device_count(struct px_context *ctx) {
  size_t i;
  for (i = 0; i < PX_COUNTOF(px_backend_registry); ++i)
    if (strcmp(px_backend_registry[i]->name, "opencl") == 0)
      return px_backend_registry[i]->device_count ? px_backend_registry[i]->device_count(ctx) : 1;
  return 0;
}

/* ------------------------------------------------------------------------ */
/* Kernel tables and argument checks                                         */

const void *px_backend_pick(struct px_backend *be, const char *module, const void *const *table,
                            size_t n) {
  size_t i;
  for (i = 0; i < n; ++i) {
    /* A pointer to a struct converts to a pointer to its first member. */
    const char *const *name = (const char *const *)table[i];
    if (strcmp(*name, be->iface->name) == 0) return table[i];
  }
  px_context_fail(be->ctx, PX_STATUS_UNSUPPORTED, "%s has no implementation for backend '%s'",
                  module, be->iface->name);
  return NULL;
}

enum px_status px_buffer_check(struct px_backend *be, const char *what, const char *arg,
                               struct px_buffer *buf, size_t n, enum px_dtype type) {
  size_t es = px_dtype_size(type);
  if (!buf) return px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: buffer %s is NULL", what, arg);
  if (buf->backend != be)
    return px_context_fail(be->ctx, PX_STATUS_INVALID,
                           "%s: buffer %s ('%s') belongs to backend %s, expected %s", what, arg,
                           buf->label, buf->backend->iface->name, be->iface->name);
  if (es == 0 || n > SIZE_MAX / es || buf->bytes < n * es)
    return px_context_fail(be->ctx, PX_STATUS_INVALID,
                           "%s: buffer %s ('%s') holds %zu bytes; %zu %s elements need %zu", what,
                           arg, buf->label, buf->bytes, n, px_dtype_name(type),
                           es && n <= SIZE_MAX / es ? n * es : SIZE_MAX);
  return PX_STATUS_OK;
}

enum px_status px_precision_dtype(struct px_backend *be, const char *what,
                                  enum px_precision precision, enum px_dtype *out) {
  switch (precision) {
    case PX_PRECISION_SINGLE: *out = PX_DTYPE_F32; return PX_STATUS_OK;
    case PX_PRECISION_DOUBLE: *out = PX_DTYPE_F64; return px_backend_require(be, precision);
    case PX_PRECISION_MIXED:
      return px_context_fail(be->ctx, PX_STATUS_INVALID,
                             "%s: precision 'mixed' is defined per solver; call with single or "
                             "double",
                             what);
  }
  return px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: unknown precision %d", what,
                         (int)precision);
}

/* ------------------------------------------------------------------------ */
/* Buffers                                                                   */

enum px_status px_buffer_create(struct px_backend *be, const char *label, size_t bytes,
                                struct px_buffer **out) {
  struct px_buffer *buf;
  enum px_status st;
  if (!out)
    return be ? px_context_fail(be->ctx, PX_STATUS_INVALID, "px_buffer_create: out is NULL")
              : PX_STATUS_INVALID;
  *out = NULL;
  if (!be) return PX_STATUS_INVALID;
  if (!label) label = "buffer";
  buf = px_mem_calloc(be->ctx, "buffer handles", 1, sizeof *buf);
  if (!buf) return PX_STATUS_NOMEM;
  buf->backend = be;
  strncpy(buf->label, label, sizeof buf->label - 1);
  buf->bytes = bytes;
  buf->capacity = bytes ? bytes : 1;
  st = be->iface->buffer_alloc(be, buf, buf->capacity);
  if (st != PX_STATUS_OK) {
    px_context_prefix(be->ctx, "buffer '%s' (%zu bytes) on backend %s", buf->label, bytes,
                      be->iface->name);
    px_mem_free(be->ctx, buf);
    return st;
  }
  ++be->live_buffers;
  *out = buf;
  return PX_STATUS_OK;
}

void px_buffer_free(struct px_buffer *buf) {
  struct px_backend *be;
  if (!buf) return;
  be = buf->backend;
  be->iface->buffer_release(be, buf);
  --be->live_buffers;
  px_mem_free(be->ctx, buf);
}

size_t px_buffer_bytes(const struct px_buffer *buf) { return buf ? buf->bytes : 0; }
const char *px_buffer_label(const struct px_buffer *buf) { return buf ? buf->label : ""; }
struct px_backend *px_buffer_backend(const struct px_buffer *buf) {
  return buf ? buf->backend : NULL;
}
void *px_buffer_host(struct px_buffer *buf) { return buf ? buf->host : NULL; }

static enum px_status px_buffer_range(struct px_buffer *buf, const char *what, size_t offset,
                                      size_t bytes) {
  if (offset > buf->bytes || bytes > buf->bytes - offset)
    return px_context_fail(buf->backend->ctx, PX_STATUS_INVALID,
                           "%s: range [%zu, %zu + %zu) is outside buffer '%s' of %zu bytes", what,
                           offset, offset, bytes, buf->label, buf->bytes);
  return PX_STATUS_OK;
}

enum px_status px_buffer_write(struct px_buffer *buf, size_t offset, size_t bytes,
                               const void *src) {
  if (!buf) return PX_STATUS_INVALID;
  PX_TRY(px_buffer_range(buf, "px_buffer_write", offset, bytes));
  if (bytes == 0) return PX_STATUS_OK;
  if (!src)
    return px_context_fail(buf->backend->ctx, PX_STATUS_INVALID,
                           "px_buffer_write: source is NULL (buffer '%s')", buf->label);
  return buf->backend->iface->buffer_write(buf, offset, bytes, src);
}

enum px_status px_buffer_read(struct px_buffer *buf, size_t offset, size_t bytes, void *dst) {
  if (!buf) return PX_STATUS_INVALID;
  PX_TRY(px_buffer_range(buf, "px_buffer_read", offset, bytes));
  if (bytes == 0) return PX_STATUS_OK;
  if (!dst)
    return px_context_fail(buf->backend->ctx, PX_STATUS_INVALID,
                           "px_buffer_read: destination is NULL (buffer '%s')", buf->label);
  return buf->backend->iface->buffer_read(buf, offset, bytes, dst);
}

enum px_status px_buffer_copy(struct px_buffer *dst, size_t dst_offset, struct px_buffer *src,
                              size_t src_offset, size_t bytes) {
  if (!dst || !src) {
    struct px_buffer *any = dst ? dst : src;
    return any ? px_context_fail(any->backend->ctx, PX_STATUS_INVALID,
                                 "px_buffer_copy: %s buffer is NULL",
                                 dst ? "source" : "destination")
               : PX_STATUS_INVALID;
  }
  if (dst->backend != src->backend)
    return px_context_fail(dst->backend->ctx, PX_STATUS_INVALID,
                           "px_buffer_copy: '%s' (%s) and '%s' (%s) belong to different backends; "
                           "copy through the host with px_buffer_read/px_buffer_write",
                           src->label, src->backend->iface->name, dst->label,
                           dst->backend->iface->name);
  PX_TRY(px_buffer_range(src, "px_buffer_copy (source)", src_offset, bytes));
  PX_TRY(px_buffer_range(dst, "px_buffer_copy (destination)", dst_offset, bytes));
  if (bytes == 0) return PX_STATUS_OK;
  if (src == dst && src_offset < dst_offset + bytes && dst_offset < src_offset + bytes)
    return px_context_fail(dst->backend->ctx, PX_STATUS_INVALID,
                           "px_buffer_copy: ranges [%zu, +%zu) and [%zu, +%zu) of buffer '%s' "
                           "overlap",
                           src_offset, bytes, dst_offset, bytes, dst->label);
  return dst->backend->iface->buffer_copy(dst, dst_offset, src, src_offset, bytes);
}

enum px_status px_buffer_zero(struct px_buffer *buf) {
  enum { CHUNK = 1 << 16 };
  struct px_backend *be;
  unsigned char *zeros;
  size_t off;
  enum px_status st = PX_STATUS_OK;
  if (!buf) return PX_STATUS_INVALID;
  be = buf->backend;
  if (buf->bytes == 0) return PX_STATUS_OK;
  if (be->iface->buffer_zero) return be->iface->buffer_zero(buf);
  zeros = px_mem_calloc(be->ctx, "buffer zero fallback", 1, CHUNK);
  if (!zeros) return PX_STATUS_NOMEM;
  for (off = 0; off < buf->bytes && st == PX_STATUS_OK; off += CHUNK) {
    size_t len = buf->bytes - off < CHUNK ? buf->bytes - off : CHUNK;
    st = be->iface->buffer_write(buf, off, len, zeros);
  }
  px_mem_free(be->ctx, zeros);
  return st;
}

/* Generic reallocation: a new block, the kept content copied over, then the
 * handles swapped so that the caller's px_buffer pointer stays valid. */
static enum px_status px_buffer_realloc_generic(struct px_buffer *buf, size_t capacity) {
  struct px_backend *be = buf->backend;
  struct px_buffer fresh = *buf;
  size_t keep = buf->bytes < capacity ? buf->bytes : capacity;
  enum px_status st;
  fresh.host = NULL;
  fresh.handle = NULL;
  fresh.capacity = capacity;
  fresh.bytes = capacity;
  PX_TRY(be->iface->buffer_alloc(be, &fresh, capacity));
  st = keep ? be->iface->buffer_copy(&fresh, 0, buf, 0, keep) : PX_STATUS_OK;
  if (st != PX_STATUS_OK) {
    be->iface->buffer_release(be, &fresh);
    return st;
  }
  be->iface->buffer_release(be, buf);
  buf->host = fresh.host;
  buf->handle = fresh.handle;
  buf->capacity = capacity;
  return PX_STATUS_OK;
}

enum px_status px_buffer_resize(struct px_buffer *buf, size_t bytes) {
  struct px_backend *be;
  size_t capacity;
  enum px_status st;
  if (!buf) return PX_STATUS_INVALID;
  be = buf->backend;
  if (bytes <= buf->capacity) {
    buf->bytes = bytes;
    return PX_STATUS_OK;
  }
  capacity = buf->capacity + buf->capacity / 2;
  if (capacity < bytes || capacity < buf->capacity) capacity = bytes;
  st = be->iface->buffer_realloc ? be->iface->buffer_realloc(buf, capacity)
                                 : px_buffer_realloc_generic(buf, capacity);
  if (st != PX_STATUS_OK)
    return px_context_prefix(be->ctx, "resizing buffer '%s' from %zu to %zu bytes", buf->label,
                             buf->bytes, bytes);
  buf->bytes = bytes;
  return PX_STATUS_OK;
}

/* Host fallback for lincomb: every input read to the host, combined in the
 * element type, written back. Correct everywhere, fast nowhere. */
static enum px_status px_lincomb_host(struct px_backend *be, enum px_dtype type, size_t n,
                                      int nterms, const double *coeffs, struct px_buffer *const *in,
                                      struct px_buffer *out) {
  size_t es = px_dtype_size(type), i;
  unsigned char *acc, *tmp;
  enum px_status st = PX_STATUS_OK;
  int k;
  acc = px_mem_alloc(be->ctx, "lincomb fallback", n * es);
  tmp = px_mem_alloc(be->ctx, "lincomb fallback", n * es);
  if (!acc || !tmp) {
    px_mem_free(be->ctx, acc);
    px_mem_free(be->ctx, tmp);
    return PX_STATUS_NOMEM;
  }
  for (k = 0; k < nterms && st == PX_STATUS_OK; ++k) {
    st = be->iface->buffer_read(in[k], 0, n * es, k == 0 ? acc : tmp);
    if (st != PX_STATUS_OK) break;
    if (type == PX_DTYPE_F64) {
      double *a = (double *)(void *)acc, *t = (double *)(void *)tmp;
      if (k == 0)
        for (i = 0; i < n; ++i) a[i] = coeffs[0] * a[i];
      else
        for (i = 0; i < n; ++i) a[i] = a[i] + coeffs[k] * t[i];
    } else {
      float *a = (float *)(void *)acc, *t = (float *)(void *)tmp;
      float c = (float)coeffs[k];
      if (k == 0)
        for (i = 0; i < n; ++i) a[i] = c * a[i];
      else
        for (i = 0; i < n; ++i) a[i] = a[i] + c * t[i];
    }
  }
  if (st == PX_STATUS_OK) st = be->iface->buffer_write(out, 0, n * es, acc);
  px_mem_free(be->ctx, acc);
  px_mem_free(be->ctx, tmp);
  return st;
}

enum px_status px_buffer_lincomb(struct px_buffer *out, enum px_dtype type, size_t n, int nterms,
                                 const double *coeffs, struct px_buffer *const *in) {
  static const char *const what = "px_buffer_lincomb";
  struct px_backend *be;
  int k;
  if (!out) return PX_STATUS_INVALID;
  be = out->backend;
  if (type != PX_DTYPE_F32 && type != PX_DTYPE_F64)
    return px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: element type %s, expected f32 or f64",
                           what, px_dtype_name(type));
  if (type == PX_DTYPE_F64) PX_TRY(px_backend_require(be, PX_PRECISION_DOUBLE));
  if (nterms < 1 || nterms > PX_LINCOMB_MAX)
    return px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: %d terms, expected 1 to %d", what,
                           nterms, PX_LINCOMB_MAX);
  if (!coeffs || !in)
    return px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: coefficients or inputs are NULL", what);
  PX_TRY(px_buffer_check(be, what, "out", out, n, type));
  for (k = 0; k < nterms; ++k) {
    char arg[16];
    snprintf(arg, sizeof arg, "in[%d]", k);
    PX_TRY(px_buffer_check(be, what, arg, in[k], n, type));
  }
  if (n == 0) return PX_STATUS_OK;
  if (be->iface->lincomb) return be->iface->lincomb(be, type, n, nterms, coeffs, in, out);
  return px_lincomb_host(be, type, n, nterms, coeffs, in, out);
}
