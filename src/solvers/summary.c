/* A run's summary: the quantities a solver reports, kept as JSON fragments. */
#include "solvers/summary.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/text.h"
#include "partix/memory.h"

struct px_summary_item {
  char *name;  /* px_mem, owned */
  char *value; /* px_mem, owned: the JSON value text */
  char *unit;  /* px_mem, owned; NULL: none */
  char *about; /* px_mem, owned */
};

struct px_summary {
  struct px_context *ctx;        /* borrowed */
  struct px_summary_item *items; /* px_mem, owned */
  size_t n, cap;
  int nomem;
};

/* The JSON text of one character of a string literal into out (UTF-8
 * bytes pass through; quote, backslash and control characters escaped). */
static size_t px_summary_escape(unsigned char ch, char out[8]) {
  if (ch == '"' || ch == '\\') {
    out[0] = '\\';
    out[1] = (char)ch;
    return 2;
  }
  if (ch == '\n') return (size_t)snprintf(out, 8, "\\n");
  if (ch == '\t') return (size_t)snprintf(out, 8, "\\t");
  if (ch < 0x20 || ch == 0x7F) return (size_t)snprintf(out, 8, "\\u%04x", ch);
  out[0] = (char)ch;
  return 1;
}

static void px_summary_put_string(struct px_text *b, const char *s) {
  px_text_put(b, "\"", 1);
  for (; s && *s; ++s) {
    char esc[8];
    px_text_put(b, esc, px_summary_escape((unsigned char)*s, esc));
  }
  px_text_put(b, "\"", 1);
}

void px_summary_fput_string(FILE *f, const char *s) {
  fputc('"', f);
  for (; s && *s; ++s) {
    char esc[8];
    fwrite(esc, 1, px_summary_escape((unsigned char)*s, esc), f);
  }
  fputc('"', f);
}

/* A real as JSON: px_text_real's form, null if not finite. */
static const char *px_summary_format_real(double x, char t[40]) {
  return isfinite(x) ? px_text_real(x, t) : "null";
}

void px_summary_fput_real(FILE *f, double x) {
  char t[40];
  fputs(px_summary_format_real(x, t), f);
}

static void px_summary_put_real(struct px_text *b, double x) {
  char t[40];
  px_text_puts(b, px_summary_format_real(x, t));
}

enum px_status px_summary_create(struct px_context *ctx, struct px_summary **out) {
  struct px_summary *s = px_mem_calloc(ctx, "summary", 1, sizeof *s);
  *out = NULL;
  if (!s) return PX_STATUS_NOMEM;
  s->ctx = ctx;
  *out = s;
  return PX_STATUS_OK;
}

static void px_summary_item_free(struct px_context *ctx, struct px_summary_item *it) {
  px_mem_free(ctx, it->name);
  px_mem_free(ctx, it->value);
  px_mem_free(ctx, it->unit);
  px_mem_free(ctx, it->about);
  memset(it, 0, sizeof *it);
}

void px_summary_clear(struct px_summary *s) {
  size_t i;
  if (!s) return;
  for (i = 0; i < s->n; ++i) px_summary_item_free(s->ctx, &s->items[i]);
  s->n = 0;
  s->nomem = 0;
}

void px_summary_free(struct px_summary *s) {
  if (!s) return;
  px_summary_clear(s);
  px_mem_free(s->ctx, s->items);
  px_mem_free(s->ctx, s);
}

static char *px_summary_dup(struct px_summary *s, const char *text) {
  size_t n;
  char *p;
  if (!text) return NULL;
  n = strlen(text);
  p = px_mem_alloc(s->ctx, "summary", n + 1);
  if (!p) {
    s->nomem = 1;
    return NULL;
  }
  memcpy(p, text, n + 1);
  return p;
}

/* Add (or replace) an item whose value is the JSON text in b (taken over). */
static void px_summary_add(struct px_summary *s, const char *name, struct px_text *b,
                           const char *unit, const char *about) {
  struct px_summary_item *it = NULL;
  size_t i;
  if (!s) {
    px_mem_free(b->ctx, b->p);
    return;
  }
  if (b->nomem || !name) {
    s->nomem = s->nomem || b->nomem;
    px_mem_free(s->ctx, b->p);
    return;
  }
  for (i = 0; i < s->n; ++i)
    if (strcmp(s->items[i].name, name) == 0) {
      it = &s->items[i];
      px_summary_item_free(s->ctx, it);
      break;
    }
  if (!it) {
    if (s->n == s->cap) {
      size_t cap = s->cap ? 2 * s->cap : 16;
      struct px_summary_item *grown =
          px_mem_realloc(s->ctx, "summary", s->items, cap * sizeof *grown);
      if (!grown) {
        s->nomem = 1;
        px_mem_free(s->ctx, b->p);
        return;
      }
      s->items = grown;
      s->cap = cap;
    }
    it = &s->items[s->n++];
    memset(it, 0, sizeof *it);
  }
  it->value = b->p;
  it->name = px_summary_dup(s, name);
  it->unit = px_summary_dup(s, unit);
  it->about = px_summary_dup(s, about ? about : "");
  if (!it->name || !it->about || (unit && !it->unit)) {
    px_summary_item_free(s->ctx, it);
    s->n--;
    s->nomem = 1;
  }
}

static void px_summary_buf_init(struct px_text *b, const struct px_summary *s) {
  memset(b, 0, sizeof *b);
  b->ctx = s ? s->ctx : NULL;
  b->label = "summary";
}

void px_summary_real(struct px_summary *s, const char *name, double value, const char *unit,
                     const char *about) {
  struct px_text b;
  if (!s) return;
  px_summary_buf_init(&b, s);
  px_summary_put_real(&b, value);
  px_summary_add(s, name, &b, unit, about);
}

void px_summary_int(struct px_summary *s, const char *name, long value, const char *unit,
                    const char *about) {
  struct px_text b;
  char t[32];
  if (!s) return;
  px_summary_buf_init(&b, s);
  snprintf(t, sizeof t, "%ld", value);
  px_text_puts(&b, t);
  px_summary_add(s, name, &b, unit, about);
}

void px_summary_bool(struct px_summary *s, const char *name, int value, const char *about) {
  struct px_text b;
  if (!s) return;
  px_summary_buf_init(&b, s);
  px_text_puts(&b, value ? "true" : "false");
  px_summary_add(s, name, &b, NULL, about);
}

void px_summary_text(struct px_summary *s, const char *name, const char *value, const char *about) {
  struct px_text b;
  if (!s) return;
  px_summary_buf_init(&b, s);
  px_summary_put_string(&b, value ? value : "");
  px_summary_add(s, name, &b, NULL, about);
}

void px_summary_vector(struct px_summary *s, const char *name, size_t n, const double *v,
                       const char *unit, const char *about) {
  struct px_text b;
  size_t i;
  if (!s) return;
  px_summary_buf_init(&b, s);
  px_text_put(&b, "[", 1);
  for (i = 0; i < n; ++i) {
    if (i) px_text_put(&b, ", ", 2);
    px_summary_put_real(&b, v[i]);
  }
  px_text_put(&b, "]", 1);
  px_summary_add(s, name, &b, unit, about);
}

enum px_status px_summary_status(const struct px_summary *s) {
  return s && s->nomem ? PX_STATUS_NOMEM : PX_STATUS_OK;
}

enum px_status px_summary_json(const struct px_summary *s, int indent, char **text, size_t *len) {
  struct px_text b;
  size_t i;
  int k;
  *text = NULL;
  *len = 0;
  px_summary_buf_init(&b, s);
  px_text_puts(&b, "");
  for (i = 0; s && i < s->n; ++i) {
    const struct px_summary_item *it = &s->items[i];
    for (k = 0; k < indent; ++k) px_text_put(&b, " ", 1);
    px_summary_put_string(&b, it->name);
    px_text_puts(&b, ": {\"value\": ");
    px_text_puts(&b, it->value);
    if (it->unit) {
      px_text_puts(&b, ", \"unit\": ");
      px_summary_put_string(&b, it->unit);
    }
    px_text_puts(&b, ", \"about\": ");
    px_summary_put_string(&b, it->about);
    px_text_puts(&b, i + 1 < s->n ? "},\n" : "}\n");
  }
  if (b.nomem) {
    px_mem_free(b.ctx, b.p);
    return PX_STATUS_NOMEM;
  }
  *text = b.p;
  *len = b.len;
  return PX_STATUS_OK;
}
