/* Element types and precisions shared by buffers, kernels and checkpoints. */
#ifndef PARTIX_TYPES_H
#define PARTIX_TYPES_H

#include <stddef.h>

#include "partix/context.h"
#include "partix/export.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Stored element types. Values are part of the checkpoint format: append only. */
enum px_dtype {
  PX_DTYPE_U8 = 1,
  PX_DTYPE_I32 = 2,
  PX_DTYPE_U32 = 3,
  PX_DTYPE_I64 = 4,
  PX_DTYPE_U64 = 5,
  PX_DTYPE_F32 = 6,
  PX_DTYPE_F64 = 7
};

/* Size in bytes of one element (0 for an unknown type). */
PX_API size_t px_dtype_size(enum px_dtype type);
/* "f32", "f64", ... ("?" for an unknown type). */
PX_API const char *px_dtype_name(enum px_dtype type);

/* Arithmetic precision of a run. `mixed` is defined per solver (e.g. vortex:
 * float pair sums, double generation, restructuring and loads). */
enum px_precision { PX_PRECISION_SINGLE = 0, PX_PRECISION_DOUBLE = 1, PX_PRECISION_MIXED = 2 };

PX_API const char *px_precision_name(enum px_precision p);
/* Parse "single" | "double" | "mixed" (also "float"); PX_STATUS_INVALID otherwise. */
PX_API enum px_status px_precision_parse(const char *name, enum px_precision *out);

#ifdef __cplusplus
}
#endif
#endif
