/* The context: carries the last error message, the log callback and level,
 * memory accounting and the interrupt flag. One per run; not shared between
 * threads that call partix concurrently. */
#ifndef PARTIX_CONTEXT_H
#define PARTIX_CONTEXT_H

#include <signal.h>
#include <stdarg.h>

#include "partix/export.h"
#include "partix/status.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_context;

enum px_log_level {
  PX_LOG_LEVEL_ERROR = 0,
  PX_LOG_LEVEL_WARN = 1,
  PX_LOG_LEVEL_INFO = 2,
  PX_LOG_LEVEL_DEBUG = 3,
  PX_LOG_LEVEL_TRACE = 4
};

/* Receives every log message at or below the context's level. `message` has no
 * trailing newline and is valid only during the call. */
typedef void (*px_log_fn)(void *user, enum px_log_level level, const char *message);

/* Create a context (log to stderr at INFO). Free with px_context_free. */
PX_API enum px_status px_context_create(struct px_context **out);
/* NULL-safe. */
PX_API void px_context_free(struct px_context *ctx);

/* The message of the last failure (empty string when none). Owned by ctx. */
PX_API const char *px_context_message(const struct px_context *ctx);
/* The status of the last failure (PX_STATUS_OK when none). */
PX_API enum px_status px_context_status(const struct px_context *ctx);
PX_API void px_context_clear(struct px_context *ctx);

/* Record a failure: sets the message from fmt and returns `status`, so that
 * `return px_context_fail(ctx, PX_STATUS_IO, "cannot open %s", path);` works. */
PX_API enum px_status px_context_fail(struct px_context *ctx, enum px_status status,
                                      const char *fmt, ...) PX_PRINTF(3, 4);
PX_API enum px_status px_context_vfail(struct px_context *ctx, enum px_status status,
                                       const char *fmt, va_list ap);
/* Prepend "<text>: " to the current message (adds where a failure happened as
 * it propagates up). Returns the current status. */
PX_API enum px_status px_context_prefix(struct px_context *ctx, const char *fmt, ...)
    PX_PRINTF(2, 3);

/* Append text to the current message (e.g. what the user can do next).
 * Returns the current status. */
PX_API enum px_status px_context_append(struct px_context *ctx, const char *fmt, ...)
    PX_PRINTF(2, 3);

/* Logging. fn == NULL restores the default (stderr: INFO lines as they
 * are, others prefixed "warning: ", "error: ", ...). */
PX_API void px_context_set_log(struct px_context *ctx, px_log_fn fn, void *user);
/* The current log callback (NULL: the default) and its user pointer. */
PX_API void px_context_get_log(const struct px_context *ctx, px_log_fn *fn, void **user);
PX_API void px_context_set_log_level(struct px_context *ctx, enum px_log_level level);
PX_API enum px_log_level px_context_log_level(const struct px_context *ctx);
PX_API void px_log(struct px_context *ctx, enum px_log_level level, const char *fmt, ...)
    PX_PRINTF(3, 4);
PX_API const char *px_log_level_name(enum px_log_level level);

/* The most memory a run may plan to use [bytes]: a problem whose estimate
 * (made from the case before allocating) exceeds it is refused at the key
 * that sets its size. 0 (the default) = the machine's physical memory; a
 * limit above that has no effect. E.g. for several runs sharing a node. */
PX_API void px_context_set_memory_limit(struct px_context *ctx, size_t bytes);
PX_API size_t px_context_memory_limit(const struct px_context *ctx);
/* Interrupt flag (borrowed; e.g. set by a SIGINT handler). Long loops poll
 * px_context_interrupted() and stop cleanly with PX_STATUS_INTERRUPTED. */
PX_API void px_context_set_interrupt_flag(struct px_context *ctx,
                                          const volatile sig_atomic_t *flag);
PX_API int px_context_interrupted(const struct px_context *ctx);

#ifdef __cplusplus
}
#endif
#endif
