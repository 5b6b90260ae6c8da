#include "partix/memory.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/context_impl.h"

/* Every block is preceded by one alignment unit holding this header, so that
 * free and realloc know the size and label without a lookup table. */
struct px_mem_header {
  uint64_t magic;
  size_t bytes;
  size_t label;
};

#define PX_MEM_MAGIC UINT64_C(0x70786d656d626c6b) /* "pxmemblk" */
#define PX_MEM_HEADER PX_MEM_ALIGN

static struct px_mem_header *px_mem_header_of(const void *ptr) {
  return (struct px_mem_header *)(void *)((char *)(uintptr_t)ptr - PX_MEM_HEADER);
}

/* Called with the lock held. Returns the label index or SIZE_MAX. */
static size_t px_mem_label_index(struct px_context *ctx, const char *label) {
  size_t i;
  if (!label) label = "unlabelled";
  for (i = 0; i < ctx->nlabels; ++i)
    if (strcmp(ctx->labels[i].name, label) == 0) return i;
  if (ctx->nlabels == ctx->labels_cap) {
    size_t cap = ctx->labels_cap ? 2 * ctx->labels_cap : 16;
    struct px_mem_label *grown = realloc(ctx->labels, cap * sizeof *grown);
    if (!grown) return SIZE_MAX;
    ctx->labels = grown;
    ctx->labels_cap = cap;
  }
  {
    size_t n = strlen(label) + 1;
    char *copy = malloc(n);
    if (!copy) return SIZE_MAX;
    memcpy(copy, label, n);
    ctx->labels[ctx->nlabels].name = copy;
    ctx->labels[ctx->nlabels].current = 0;
    ctx->labels[ctx->nlabels].peak = 0;
  }
  return ctx->nlabels++;
}

static void *px_mem_raw(struct px_context *ctx, const char *label, size_t bytes) {
  size_t total, index;
  struct px_mem_header *h;
  if (bytes > SIZE_MAX - 2 * PX_MEM_ALIGN) {
    px_context_fail(ctx, PX_STATUS_NOMEM, "allocation of %zu bytes for '%s' is too large", bytes,
                    label ? label : "?");
    return NULL;
  }
  total = PX_MEM_HEADER + ((bytes + PX_MEM_ALIGN - 1) / PX_MEM_ALIGN) * PX_MEM_ALIGN;
  h = aligned_alloc(PX_MEM_ALIGN, total);
  if (!h) {
    px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory allocating %zu bytes for '%s'", bytes,
                    label ? label : "?");
    return NULL;
  }
  mtx_lock(&ctx->mem_lock);
  index = px_mem_label_index(ctx, label);
  if (index != SIZE_MAX) {
    struct px_mem_label *l = &ctx->labels[index];
    l->current += bytes;
    if (l->current > l->peak) l->peak = l->current;
  }
  ctx->mem_current += bytes;
  if (ctx->mem_current > ctx->mem_peak) ctx->mem_peak = ctx->mem_current;
  mtx_unlock(&ctx->mem_lock);
  h->magic = PX_MEM_MAGIC;
  h->bytes = bytes;
  h->label = index;
  return (char *)h + PX_MEM_HEADER;
}

void *px_mem_alloc(struct px_context *ctx, const char *label, size_t bytes) {
  if (!ctx) return NULL;
  return px_mem_raw(ctx, label, bytes);
}

void *px_mem_calloc(struct px_context *ctx, const char *label, size_t count, size_t size) {
  void *p;
  if (!ctx) return NULL;
  if (size && count > SIZE_MAX / size) {
    px_context_fail(ctx, PX_STATUS_NOMEM, "allocation of %zu x %zu bytes for '%s' overflows", count,
                    size, label ? label : "?");
    return NULL;
  }
  p = px_mem_raw(ctx, label, count * size);
  if (p) memset(p, 0, count * size);
  return p;
}

void px_mem_free(struct px_context *ctx, void *ptr) {
  struct px_mem_header *h;
  if (!ptr || !ctx) return;
  h = px_mem_header_of(ptr);
  mtx_lock(&ctx->mem_lock);
  if (h->label < ctx->nlabels) ctx->labels[h->label].current -= h->bytes;
  ctx->mem_current -= h->bytes;
  mtx_unlock(&ctx->mem_lock);
  h->magic = 0;
  free(h);
}

void *px_mem_realloc(struct px_context *ctx, const char *label, void *ptr, size_t bytes) {
  void *fresh;
  const char *name = label;
  if (!ctx) return NULL;
  if (ptr) {
    struct px_mem_header *h = px_mem_header_of(ptr);
    mtx_lock(&ctx->mem_lock);
    if (h->label < ctx->nlabels) name = ctx->labels[h->label].name;
    mtx_unlock(&ctx->mem_lock);
  }
  fresh = px_mem_raw(ctx, name, bytes);
  if (!fresh) return NULL;
  if (ptr) {
    size_t keep = px_mem_size(ptr);
    memcpy(fresh, ptr, keep < bytes ? keep : bytes);
    px_mem_free(ctx, ptr);
  }
  return fresh;
}

size_t px_mem_size(const void *ptr) { return ptr ? px_mem_header_of(ptr)->bytes : 0; }

static size_t px_mem_query(struct px_context *ctx, const char *label, int peak) {
  size_t i, value = 0;
  if (!ctx) return 0;
  mtx_lock(&ctx->mem_lock);
  if (!label) {
    value = peak ? ctx->mem_peak : ctx->mem_current;
  } else {
    for (i = 0; i < ctx->nlabels; ++i)
      if (strcmp(ctx->labels[i].name, label) == 0)
        value = peak ? ctx->labels[i].peak : ctx->labels[i].current;
  }
  mtx_unlock(&ctx->mem_lock);
  return value;
}

size_t px_mem_current(struct px_context *ctx, const char *label) {
  return px_mem_query(ctx, label, 0);
}

size_t px_mem_peak(struct px_context *ctx, const char *label) {
  return px_mem_query(ctx, label, 1);
}

void px_mem_report(struct px_context *ctx, FILE *out) {
  size_t i;
  if (!ctx || !out) return;
  mtx_lock(&ctx->mem_lock);
  fprintf(out, "%-32s %14s %14s\n", "memory label", "current [B]", "peak [B]");
  for (i = 0; i < ctx->nlabels; ++i)
    fprintf(out, "%-32s %14zu %14zu\n", ctx->labels[i].name, ctx->labels[i].current,
            ctx->labels[i].peak);
  fprintf(out, "%-32s %14zu %14zu\n", "total", ctx->mem_current, ctx->mem_peak);
  mtx_unlock(&ctx->mem_lock);
}
