/* Labelled, 64-byte-aligned allocation with per-label accounting, so that a
 * run can report where its memory goes (e.g. bytes per particle). */
#ifndef PARTIX_MEMORY_H
#define PARTIX_MEMORY_H

#include <stddef.h>
#include <stdio.h>

#include "partix/context.h"
#include "partix/export.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PX_MEM_ALIGN 64

/* Allocate `bytes` (64-byte aligned) under `label` (copied). Returns NULL and
 * records PX_STATUS_NOMEM in ctx on failure. Thread-safe. */
PX_API void *px_mem_alloc(struct px_context *ctx, const char *label, size_t bytes);
/* Same, zero-filled; count*size overflow is a failure. */
PX_API void *px_mem_calloc(struct px_context *ctx, const char *label, size_t count, size_t size);
/* Resize keeping the label and the content; ptr may be NULL (then it allocates
 * under `label`). On failure the old block is left untouched and NULL returned. */
PX_API void *px_mem_realloc(struct px_context *ctx, const char *label, void *ptr, size_t bytes);
/* NULL-safe. `ptr` must come from px_mem_alloc/calloc/realloc of this ctx. */
PX_API void px_mem_free(struct px_context *ctx, void *ptr);
/* Usable size of an allocation. */
PX_API size_t px_mem_size(const void *ptr);

/* Bytes currently allocated and the high-water mark, in total or for one label
 * (label NULL = all). */
PX_API size_t px_mem_current(struct px_context *ctx, const char *label);
PX_API size_t px_mem_peak(struct px_context *ctx, const char *label);
/* A table of labels with current and peak bytes. */
PX_API void px_mem_report(struct px_context *ctx, FILE *out);

#ifdef __cplusplus
}
#endif
#endif
