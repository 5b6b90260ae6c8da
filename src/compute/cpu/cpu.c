/* The cpu backend: buffers are 64-byte-aligned px_mem blocks in host memory;
 * loops run with OpenMP (num_threads(be->threads), never the global
 * omp_set_num_threads) and `#pragma omp simd`. */
#include <omp.h>
#include <stdio.h>
#include <string.h>

#include "compute/backend_impl.h"
#include "compute/cpu/cpu_impl.h"
#include "core/simd.h"
#include "partix/memory.h"

/* CPU model from /proc/cpuinfo where there is one (Linux); "CPU" otherwise. */
static void px_cpu_model(char *buf, size_t size) {
  char line[512];
  FILE *f = fopen("/proc/cpuinfo", "r");
  snprintf(buf, size, "CPU");
  if (!f) return;
  while (fgets(line, sizeof line, f)) {
    if (strncmp(line, "model name", 10) == 0) {
      char *colon = strchr(line, ':');
      if (colon) {
        char *s = colon + 1;
        size_t len;
        while (*s == ' ' || *s == '\t') ++s;
        len = strcspn(s, "\r\n");
        snprintf(buf, size, "%.*s", (int)len, s);
      }
      break;
    }
  }
  fclose(f);
}

void px_cpu_describe(int threads, char *buf, size_t size) {
  char model[160];
  px_cpu_model(model, sizeof model);
  snprintf(buf, size, "%s, %d thread%s, %s", model, threads, threads == 1 ? "" : "s",
           px_simd_isa());
}

static enum px_status px_cpu_init(struct px_backend *be, int device) {
  (void)device;
  be->impl = NULL;
  be->fp64 = 1;
  be->host_memory = 1;
  /* The workgroup setting is the tile width of tiled host loops. */
  be->max_workgroup = (size_t)1 << 16;
  px_cpu_describe(be->threads, be->device, sizeof be->device);
  return PX_STATUS_OK;
}

static void px_cpu_release(struct px_backend *be) { (void)be; }

static enum px_status px_cpu_buffer_alloc(struct px_backend *be, struct px_buffer *buf,
                                          size_t capacity) {
  buf->host = px_mem_alloc(be->ctx, buf->label, capacity);
  return buf->host ? PX_STATUS_OK : PX_STATUS_NOMEM;
}

static void px_cpu_buffer_release(struct px_backend *be, struct px_buffer *buf) {
  px_mem_free(be->ctx, buf->host);
  buf->host = NULL;
}

static enum px_status px_cpu_buffer_realloc(struct px_buffer *buf, size_t capacity) {
  void *p = px_mem_realloc(buf->backend->ctx, buf->label, buf->host, capacity);
  if (!p) return PX_STATUS_NOMEM;
  buf->host = p;
  buf->capacity = capacity;
  return PX_STATUS_OK;
}

static enum px_status px_cpu_buffer_write(struct px_buffer *buf, size_t offset, size_t bytes,
                                          const void *src) {
  memcpy((char *)buf->host + offset, src, bytes);
  return PX_STATUS_OK;
}

static enum px_status px_cpu_buffer_read(struct px_buffer *buf, size_t offset, size_t bytes,
                                         void *dst) {
  memcpy(dst, (const char *)buf->host + offset, bytes);
  return PX_STATUS_OK;
}

static enum px_status px_cpu_buffer_copy(struct px_buffer *dst, size_t dst_offset,
                                         struct px_buffer *src, size_t src_offset, size_t bytes) {
  memcpy((char *)dst->host + dst_offset, (const char *)src->host + src_offset, bytes);
  return PX_STATUS_OK;
}

static enum px_status px_cpu_buffer_zero(struct px_buffer *buf) {
  memset(buf->host, 0, buf->bytes);
  return PX_STATUS_OK;
}

static enum px_status px_cpu_lincomb(struct px_backend *be, enum px_dtype type, size_t n,
                                     int nterms, const double *coeffs, struct px_buffer *const *in,
                                     struct px_buffer *out) {
  int k;
  if (type == PX_DTYPE_F64) {
    const double *x[PX_LINCOMB_MAX];
    for (k = 0; k < nterms; ++k) x[k] = in[k]->host;
    px_cpu_lincomb_f64(be->threads, n, nterms, coeffs, x, out->host);
  } else {
    const float *x[PX_LINCOMB_MAX];
    for (k = 0; k < nterms; ++k) x[k] = in[k]->host;
    px_cpu_lincomb_f32(be->threads, n, nterms, coeffs, x, out->host);
  }
  return PX_STATUS_OK;
}

/* "  cpu: <model>, <cores> threads, <isa>" */
static void px_cpu_report(struct px_context *ctx, FILE *out) {
  char cpu[256];
  (void)ctx;
  px_cpu_describe(omp_get_num_procs(), cpu, sizeof cpu);
  fprintf(out, "  cpu: %s\n", cpu);
}

const struct px_backend_i px_backend_cpu_i = {
    .name = "cpu",
    .report = px_cpu_report,
    .init = px_cpu_init,
    .release = px_cpu_release,
    .buffer_alloc = px_cpu_buffer_alloc,
    .buffer_release = px_cpu_buffer_release,
    .buffer_write = px_cpu_buffer_write,
    .buffer_read = px_cpu_buffer_read,
    .buffer_copy = px_cpu_buffer_copy,
    .buffer_zero = px_cpu_buffer_zero,
    .buffer_realloc = px_cpu_buffer_realloc,
    .finish = NULL, /* host loops are synchronous */
    .lincomb = px_cpu_lincomb,
};
