/* Input files named by a case (PX_INPUT_FILE keys) and the values a run
 * records: where a relative name is found, and rewriting the names when the
 * run driver copies the files into the run folder. */
#include <stdio.h>
#include <string.h>

#include "config/case_impl.h"
#include "partix/memory.h"

enum px_status px_case_input_path(const struct px_case *c, const char *path, char *buf,
                                  size_t size) {
  const struct px_case_node *n;
  const char *f, *slash;
  int w;
  if (!c || !buf || size == 0) return PX_STATUS_INVALID;
  buf[0] = '\0';
  n = px_case_lookup(c, path);
  if (!n || n->kind != PX_CASE_NODE_SCALAR || !n->schema || !n->schema->file)
    return px_context_fail(c->ctx, PX_STATUS_INVALID, "case key %s: not an input file",
                           path ? path : "(null)");
  f = c->file;
  slash = f ? strrchr(f, '/') : NULL;
  if (n->file_base && n->text[0] != '/')
    w = snprintf(buf, size, "%s/%s", n->file_base, n->text);
  else if (n->text[0] == '/' || n->loc.origin >= 0 || !slash)
    w = snprintf(buf, size, "%s", n->text);
  else
    w = snprintf(buf, size, "%.*s/%s", (int)(slash - f), f, n->text);
  if (w < 0 || (size_t)w >= size)
    return px_context_fail(c->ctx, PX_STATUS_INVALID, "case key %s: file name too long", path);
  return PX_STATUS_OK;
}

enum px_status px_case_value_text(const struct px_case *c, const char *path, char **text) {
  *text = NULL;
  if (!c) return PX_STATUS_INVALID;
  return px_case_emit_flow(c->ctx, px_case_lookup(c, path), text);
}

struct px_case_walk {
  struct px_case *c;
  const char *base; /* arena */
  px_case_input_fn fn;
  void *user;
  int changed;
};

static enum px_status px_case_walk_inputs(struct px_case_walk *w, struct px_case_node *n,
                                          char *path, size_t len, size_t size, int depth) {
  size_t i;
  if (!n || depth > PX_CASE_MAX_DEPTH) return PX_STATUS_OK;
  if (n->kind == PX_CASE_NODE_SCALAR && n->schema && n->schema->file && !n->is_type) {
    char source[4096], value[4096];
    PX_TRY(px_case_input_path(w->c, path, source, sizeof source));
    value[0] = '\0';
    PX_TRY(w->fn(w->user, path, source, value, sizeof value));
    if (value[0] && strcmp(value, n->text) != 0) {
      char *copy = px_case_arena_strdup(&w->c->arena, value, strlen(value));
      if (!copy) return PX_STATUS_NOMEM;
      n->text = copy;
      n->len = strlen(value);
      n->file_base = w->base;
      w->changed = 1;
    }
    return PX_STATUS_OK;
  }
  for (i = 0; i < n->n; ++i) {
    int k;
    if (n->kind == PX_CASE_NODE_MAP)
      k = snprintf(path + len, size - len, "%s%.*s", len ? "." : "", (int)n->items[i]->key_len,
                   n->items[i]->key);
    else if (n->kind == PX_CASE_NODE_SEQ)
      k = snprintf(path + len, size - len, "[%zu]", i);
    else
      break;
    if (k < 0 || (size_t)k >= size - len) continue; /* too deep to name: no input */
    PX_TRY(px_case_walk_inputs(w, n->items[i], path, len + (size_t)k, size, depth + 1));
    path[len] = '\0';
  }
  return PX_STATUS_OK;
}

enum px_status px_case_relocate_inputs(struct px_case *c, const char *base, px_case_input_fn fn,
                                       void *user) {
  struct px_case_walk w;
  char path[PX_CASE_PATH_MAX];
  char *old;
  size_t old_len;
  enum px_status st;
  if (!c || !fn) return PX_STATUS_INVALID;
  memset(&w, 0, sizeof w);
  w.c = c;
  w.base = px_case_arena_strdup(&c->arena, base ? base : ".", strlen(base ? base : "."));
  if (!w.base) return PX_STATUS_NOMEM;
  w.fn = fn;
  w.user = user;
  path[0] = '\0';
  PX_TRY(px_case_walk_inputs(&w, c->root, path, 0, sizeof path, 0));
  if (!w.changed) return PX_STATUS_OK;
  old = c->resolved;
  old_len = c->resolved_len;
  c->resolved = NULL;
  st = px_case_emit(c);
  if (st != PX_STATUS_OK) {
    c->resolved = old;
    c->resolved_len = old_len;
    return st;
  }
  px_mem_free(c->ctx, old);
  px_case_rehash(c);
  return PX_STATUS_OK;
}
