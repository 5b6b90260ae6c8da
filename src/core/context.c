#include "core/context_impl.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum px_status px_context_create(struct px_context **out) {
  struct px_context *ctx;
  if (!out) return PX_STATUS_INVALID;
  *out = NULL;
  ctx = calloc(1, sizeof *ctx);
  if (!ctx) return PX_STATUS_NOMEM;
  ctx->log_level = PX_LOG_LEVEL_INFO;
  if (mtx_init(&ctx->mem_lock, mtx_plain) != thrd_success) {
    free(ctx);
    return PX_STATUS_INTERNAL;
  }
  *out = ctx;
  return PX_STATUS_OK;
}

void px_context_free(struct px_context *ctx) {
  size_t i;
  if (!ctx) return;
  for (i = 0; i < ctx->nlabels; ++i) free(ctx->labels[i].name);
  free(ctx->labels);
  mtx_destroy(&ctx->mem_lock);
  free(ctx);
}

const char *px_context_message(const struct px_context *ctx) { return ctx ? ctx->message : ""; }

enum px_status px_context_status(const struct px_context *ctx) {
  return ctx ? ctx->status : PX_STATUS_INVALID;
}

void px_context_clear(struct px_context *ctx) {
  if (!ctx) return;
  ctx->status = PX_STATUS_OK;
  ctx->message[0] = '\0';
}

/* Control characters other than newline and tab in s become '?': messages
 * quote lines of the user's files (a profile, a drawing), and one holding
 * terminal escape sequences must not recolour or retitle the terminal it
 * is printed on. Those are the C0 controls, DEL, the C1 controls (U+0080 to
 * U+009F, two bytes in UTF-8) and any byte that is not part of valid UTF-8
 * (a raw 0x9B is a one-byte CSI to some terminals). */
static void px_context_printable(char *s) {
  unsigned char *p = (unsigned char *)s;
  while (*p) {
    size_t len = 0, k;
    if (*p < 0x80) {
      if ((*p < 0x20 && *p != '\n' && *p != '\t') || *p == 0x7f) *p = '?';
      ++p;
      continue;
    }
    if (*p >= 0xc2 && *p <= 0xdf)
      len = 2;
    else if (*p >= 0xe0 && *p <= 0xef)
      len = 3;
    else if (*p >= 0xf0 && *p <= 0xf4)
      len = 4;
    for (k = 1; k < len && (p[k] & 0xc0) == 0x80; ++k) {
    }
    if (len == 0 || k < len || (p[0] == 0xc2 && p[1] <= 0x9f)) {
      /* not UTF-8, or a C1 control: each of its bytes shown as '?' */
      const size_t bad = len && k == len ? len : 1;
      for (k = 0; k < bad; ++k) p[k] = '?';
      p += bad;
      continue;
    }
    p += len;
  }
}

enum px_status px_context_vfail(struct px_context *ctx, enum px_status status, const char *fmt,
                                va_list ap) {
  if (!ctx) return status;
  ctx->status = status;
  vsnprintf(ctx->message, sizeof ctx->message, fmt, ap);
  px_context_printable(ctx->message);
  px_log(ctx, PX_LOG_LEVEL_DEBUG, "failure (%s): %s", px_status_name(status), ctx->message);
  return status;
}

enum px_status px_context_fail(struct px_context *ctx, enum px_status status, const char *fmt,
                               ...) {
  va_list ap;
  va_start(ap, fmt);
  status = px_context_vfail(ctx, status, fmt, ap);
  va_end(ap);
  return status;
}

enum px_status px_context_prefix(struct px_context *ctx, const char *fmt, ...) {
  char prefix[1024];
  size_t plen, mlen;
  va_list ap;
  if (!ctx) return PX_STATUS_INVALID;
  va_start(ap, fmt);
  vsnprintf(prefix, sizeof prefix, fmt, ap);
  va_end(ap);
  px_context_printable(prefix);
  plen = strlen(prefix);
  mlen = strlen(ctx->message);
  if (mlen) {
    /* "<prefix>: <old message>", truncated to the buffer */
    size_t shift = plen + 2;
    if (shift >= sizeof ctx->message) shift = sizeof ctx->message - 1;
    if (mlen + shift >= sizeof ctx->message) mlen = sizeof ctx->message - 1 - shift;
    memmove(ctx->message + shift, ctx->message, mlen);
    ctx->message[shift + mlen] = '\0';
    memcpy(ctx->message, prefix, shift - 2 < plen ? shift - 2 : plen);
    if (shift >= 2) {
      ctx->message[shift - 2] = ':';
      ctx->message[shift - 1] = ' ';
    }
  } else {
    memcpy(ctx->message, prefix, plen + 1);
  }
  return ctx->status;
}

enum px_status px_context_append(struct px_context *ctx, const char *fmt, ...) {
  size_t used;
  va_list ap;
  if (!ctx) return PX_STATUS_INVALID;
  used = strlen(ctx->message);
  if (used + 1 < sizeof ctx->message) {
    va_start(ap, fmt);
    vsnprintf(ctx->message + used, sizeof ctx->message - used, fmt, ap);
    va_end(ap);
    px_context_printable(ctx->message + used);
  }
  return ctx->status;
}

void px_context_set_log(struct px_context *ctx, px_log_fn fn, void *user) {
  if (!ctx) return;
  ctx->log_fn = fn;
  ctx->log_user = user;
}

void px_context_set_memory_limit(struct px_context *ctx, size_t bytes) {
  if (ctx) ctx->mem_limit = bytes;
}

size_t px_context_memory_limit(const struct px_context *ctx) { return ctx ? ctx->mem_limit : 0; }

void px_context_get_log(const struct px_context *ctx, px_log_fn *fn, void **user) {
  if (fn) *fn = ctx ? ctx->log_fn : NULL;
  if (user) *user = ctx ? ctx->log_user : NULL;
}

void px_context_set_log_level(struct px_context *ctx, enum px_log_level level) {
  if (ctx) ctx->log_level = level;
}

enum px_log_level px_context_log_level(const struct px_context *ctx) {
  return ctx ? ctx->log_level : PX_LOG_LEVEL_INFO;
}

const char *px_log_level_name(enum px_log_level level) {
  switch (level) {
    case PX_LOG_LEVEL_ERROR: return "error";
    case PX_LOG_LEVEL_WARN: return "warning";
    case PX_LOG_LEVEL_INFO: return "info";
    case PX_LOG_LEVEL_DEBUG: return "debug";
    case PX_LOG_LEVEL_TRACE: return "trace";
  }
  return "log";
}

void px_log(struct px_context *ctx, enum px_log_level level, const char *fmt, ...) {
  char line[2048];
  va_list ap;
  if (!ctx || level > ctx->log_level) return;
  va_start(ap, fmt);
  vsnprintf(line, sizeof line, fmt, ap);
  va_end(ap);
  px_context_printable(line);
  if (ctx->log_fn) {
    ctx->log_fn(ctx->log_user, level, line);
  } else if (level == PX_LOG_LEVEL_INFO) {
    fprintf(stderr, "%s\n", line);
  } else {
    fprintf(stderr, "%s: %s\n", px_log_level_name(level), line);
  }
}

void px_context_set_interrupt_flag(struct px_context *ctx, const volatile sig_atomic_t *flag) {
  if (ctx) ctx->interrupt = flag;
}

int px_context_interrupted(const struct px_context *ctx) {
  return ctx && ctx->interrupt && *ctx->interrupt;
}
