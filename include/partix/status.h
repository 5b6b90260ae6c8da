/* Status codes: every fallible partix function returns one. The library never
 * exits or aborts; on failure it returns a status and leaves a message in the
 * context (see context.h). */
#ifndef PARTIX_STATUS_H
#define PARTIX_STATUS_H

#include "partix/export.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The one list: X(NAME, message). Enum values are PX_STATUS_<NAME>. */
#define PX_STATUS_LIST(X)                                 \
  X(OK, "success")                                        \
  X(INVALID, "invalid argument")                          \
  X(NOMEM, "out of memory")                               \
  X(IO, "input/output error")                             \
  X(CONFIG, "invalid case")                               \
  X(FORMAT, "corrupt or incompatible file")               \
  X(NOT_FOUND, "not found")                               \
  X(UNSUPPORTED, "not supported by this build or device") \
  X(BACKEND, "compute backend error")                     \
  X(NUMERIC, "numerical failure")                         \
  X(INTERRUPTED, "interrupted")                           \
  X(INTERNAL, "internal error")

enum px_status {
#define PX_STATUS_ENUM_(name, msg) PX_STATUS_##name,
  PX_STATUS_LIST(PX_STATUS_ENUM_)
#undef PX_STATUS_ENUM_
      PX_STATUS_COUNT_
};

/* Short, static description of a status ("out of memory"). Never NULL. */
PX_API const char *px_status_message(enum px_status status);
/* Name of a status ("NOMEM"). Never NULL. */
PX_API const char *px_status_name(enum px_status status);

/* Propagate a failure to the caller. Never compiled out. */
#define PX_TRY(call)                                           \
  do {                                                         \
    enum px_status px_try_status_ = (call);                    \
    if (px_try_status_ != PX_STATUS_OK) return px_try_status_; \
  } while (0)

#ifdef __cplusplus
}
#endif
#endif
