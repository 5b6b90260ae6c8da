#include "partix/types.h"

#include <string.h>

size_t px_dtype_size(enum px_dtype type) {
  switch (type) {
    case PX_DTYPE_U8: return 1;
    case PX_DTYPE_I32:
    case PX_DTYPE_U32:
    case PX_DTYPE_F32: return 4;
    case PX_DTYPE_I64:
    case PX_DTYPE_U64:
    case PX_DTYPE_F64: return 8;
  }
  return 0;
}

const char *px_dtype_name(enum px_dtype type) {
  switch (type) {
    case PX_DTYPE_U8: return "u8";
    case PX_DTYPE_I32: return "i32";
    case PX_DTYPE_U32: return "u32";
    case PX_DTYPE_I64: return "i64";
    case PX_DTYPE_U64: return "u64";
    case PX_DTYPE_F32: return "f32";
    case PX_DTYPE_F64: return "f64";
  }
  return "?";
}

const char *px_precision_name(enum px_precision p) {
  switch (p) {
    case PX_PRECISION_SINGLE: return "single";
    case PX_PRECISION_DOUBLE: return "double";
    case PX_PRECISION_MIXED: return "mixed";
  }
  return "?";
}

enum px_status px_precision_parse(const char *name, enum px_precision *out) {
  if (!name || !out) return PX_STATUS_INVALID;
  if (strcmp(name, "single") == 0 || strcmp(name, "float") == 0) {
    *out = PX_PRECISION_SINGLE;
  } else if (strcmp(name, "double") == 0) {
    *out = PX_PRECISION_DOUBLE;
  } else if (strcmp(name, "mixed") == 0) {
    *out = PX_PRECISION_MIXED;
  } else {
    return PX_STATUS_INVALID;
  }
  return PX_STATUS_OK;
}
