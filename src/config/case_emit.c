/* The resolved case as YAML text: keys in schema order, defaults filled in,
 * values in canonical form (reals in the shortest form that reads back to the
 * same double, strings double-quoted), so that equal runs have equal text and
 * loading the text again reproduces it exactly. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/case_impl.h"
#include "core/text.h"
#include "partix/memory.h"

static void px_case_indent(struct px_text *b, size_t n) {
  static const char spaces[] = "                                ";
  while (n > 0) {
    size_t k = n < sizeof spaces - 1 ? n : sizeof spaces - 1;
    px_text_put(b, spaces, k);
    n -= k;
  }
}

static void px_case_put_real(struct px_text *b, double x) {
  char t[40];
  px_text_puts(b, px_text_real(x, t));
}

static void px_case_put_string(struct px_text *b, const char *s, size_t len) {
  size_t i;
  px_text_put(b, "\"", 1);
  for (i = 0; i < len; ++i) {
    unsigned char ch = (unsigned char)s[i];
    char esc[8];
    if (ch == '"' || ch == '\\') {
      esc[0] = '\\';
      esc[1] = (char)ch;
      px_text_put(b, esc, 2);
    } else if (ch == '\n') {
      px_text_put(b, "\\n", 2);
    } else if (ch == '\t') {
      px_text_put(b, "\\t", 2);
    } else if (ch < 0x20 || ch == 0x7F) {
      snprintf(esc, sizeof esc, "\\x%02X", ch);
      px_text_puts(b, esc);
    } else {
      px_text_put(b, (const char *)&s[i], 1);
    }
  }
  px_text_put(b, "\"", 1);
}

static void px_case_put_scalar(struct px_text *b, const struct px_case_node *n) {
  char t[32];
  const struct px_schema *s = n->schema;
  if (n->is_type) {
    px_text_puts(b, n->text);
    return;
  }
  if (n->is_element) {
    px_case_put_real(b, n->v.real);
    return;
  }
  if (!s) { /* cannot happen in a validated tree */
    px_case_put_string(b, n->text, n->len);
    return;
  }
  switch (s->type) {
    case PX_SCHEMA_TYPE_BOOL: px_text_puts(b, n->v.boolean ? "true" : "false"); break;
    case PX_SCHEMA_TYPE_INT:
      snprintf(t, sizeof t, "%ld", n->v.integer);
      px_text_puts(b, t);
      break;
    case PX_SCHEMA_TYPE_REAL: px_case_put_real(b, n->v.real); break;
    case PX_SCHEMA_TYPE_ENUM: px_text_puts(b, s->choices[n->v.index]); break;
    default: px_case_put_string(b, n->text, n->len); break;
  }
}

static void px_case_put_flow(struct px_text *b, const struct px_case_node *n) {
  size_t i;
  if (n->kind == PX_CASE_NODE_MAP) {
    px_text_put(b, "{", 1);
    for (i = 0; i < n->n; ++i) {
      if (i) px_text_put(b, ", ", 2);
      px_text_put(b, n->items[i]->key, n->items[i]->key_len);
      px_text_put(b, ": ", 2);
      px_case_put_flow(b, n->items[i]);
    }
    px_text_put(b, "}", 1);
  } else if (n->kind == PX_CASE_NODE_SEQ) {
    px_text_put(b, "[", 1);
    for (i = 0; i < n->n; ++i) {
      if (i) px_text_put(b, ", ", 2);
      px_case_put_flow(b, n->items[i]);
    }
    px_text_put(b, "]", 1);
  } else {
    px_case_put_scalar(b, n);
  }
}

static void px_case_put_members(struct px_text *b, const struct px_case_node *map, size_t indent,
                                int first_inline);

/* After "key:" */
static void px_case_put_value(struct px_text *b, const struct px_case_node *n, size_t indent) {
  size_t i;
  if (n->kind == PX_CASE_NODE_MAP && n->n) {
    px_text_put(b, "\n", 1);
    px_case_put_members(b, n, indent + 2, 0);
  } else if (n->kind == PX_CASE_NODE_SEQ && n->n && n->items[0]->kind == PX_CASE_NODE_MAP) {
    px_text_put(b, "\n", 1);
    for (i = 0; i < n->n; ++i) {
      px_case_indent(b, indent + 2);
      px_text_put(b, "- ", 2);
      if (n->items[i]->kind == PX_CASE_NODE_MAP && n->items[i]->n) {
        px_case_put_members(b, n->items[i], indent + 4, 1);
      } else {
        px_case_put_flow(b, n->items[i]);
        px_text_put(b, "\n", 1);
      }
    }
  } else {
    px_text_put(b, " ", 1);
    px_case_put_flow(b, n);
    px_text_put(b, "\n", 1);
  }
}

static void px_case_put_members(struct px_text *b, const struct px_case_node *map, size_t indent,
                                int first_inline) {
  size_t i;
  for (i = 0; i < map->n; ++i) {
    const struct px_case_node *m = map->items[i];
    if (i || !first_inline) px_case_indent(b, indent);
    px_text_put(b, m->key, m->key_len);
    px_text_put(b, ":", 1);
    px_case_put_value(b, m, indent);
  }
}

enum px_status px_case_emit(struct px_case *c) {
  struct px_text b;
  memset(&b, 0, sizeof b);
  b.ctx = c->ctx;
  b.label = "case";
  if (c->root && c->root->n)
    px_case_put_members(&b, c->root, 0, 0);
  else
    px_text_puts(&b, "{}\n");
  if (b.nomem) {
    px_mem_free(c->ctx, b.p);
    return PX_STATUS_NOMEM;
  }
  c->resolved = b.p;
  c->resolved_len = b.len;
  return PX_STATUS_OK;
}

enum px_status px_case_emit_flow(struct px_context *ctx, const struct px_case_node *n,
                                 char **text) {
  struct px_text b;
  memset(&b, 0, sizeof b);
  b.ctx = ctx;
  b.label = "case";
  *text = NULL;
  px_text_puts(&b, "");
  if (n) px_case_put_flow(&b, n);
  if (b.nomem) {
    px_mem_free(ctx, b.p);
    return PX_STATUS_NOMEM;
  }
  *text = b.p;
  return PX_STATUS_OK;
}
