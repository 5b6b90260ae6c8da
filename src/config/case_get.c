/* Reading a resolved case by key path, and reporting semantic errors at the
 * location of a key. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "config/case_impl.h"

#define PX_CASE_MAX_SEGS 64

enum px_case_find {
  PX_CASE_FIND_OK,
  PX_CASE_FIND_ABSENT,    /* in the schema, not in the case */
  PX_CASE_FIND_MALFORMED, /* not a key path */
  PX_CASE_FIND_UNKNOWN,   /* not in the schema */
  PX_CASE_FIND_RANGE,     /* list index past the end */
  PX_CASE_FIND_NOT_LIST   /* [i] on something else */
};

/* The schema that a map's members follow. */
static const struct px_schema *px_case_member_keys(const struct px_case_node *map) {
  if (map->variant) return map->variant->keys;
  return map->schema ? map->schema->keys : NULL;
}

/* Walk `path`. *nearest is the deepest node reached (never NULL once the root
 * exists); *absent the schema of a missing key. */
static enum px_case_find px_case_find(const struct px_case *c, const char *path,
                                      struct px_case_node **found, struct px_case_node **nearest,
                                      const struct px_schema **absent) {
  struct px_case_seg segs[PX_CASE_MAX_SEGS];
  size_t nseg, i;
  struct px_case_node *node = c->root;
  *found = NULL;
  *nearest = node;
  *absent = NULL;
  if (!path) return PX_CASE_FIND_MALFORMED;
  nseg = px_case_path_parse(path, strlen(path), segs, PX_CASE_MAX_SEGS);
  if (!nseg) return PX_CASE_FIND_MALFORMED;
  if (!node) return PX_CASE_FIND_ABSENT;
  for (i = 0; i < nseg; ++i) {
    if (segs[i].name) {
      struct px_case_node *m;
      const struct px_schema *keys;
      size_t j;
      if (node->kind != PX_CASE_NODE_MAP) return PX_CASE_FIND_UNKNOWN;
      m = px_case_node_member(node, segs[i].name, segs[i].len);
      if (!m) {
        keys = px_case_member_keys(node);
        for (j = 0; keys && keys[j].name; ++j) {
          if (strlen(keys[j].name) == segs[i].len &&
              memcmp(keys[j].name, segs[i].name, segs[i].len) == 0) {
            *absent = &keys[j];
            return PX_CASE_FIND_ABSENT;
          }
        }
        return PX_CASE_FIND_UNKNOWN;
      }
      node = m;
    } else {
      if (node->kind != PX_CASE_NODE_SEQ) return PX_CASE_FIND_NOT_LIST;
      if (segs[i].index >= node->n) return PX_CASE_FIND_RANGE;
      node = node->items[segs[i].index];
    }
    *nearest = node;
  }
  *found = node;
  return PX_CASE_FIND_OK;
}

struct px_case_node *px_case_lookup(const struct px_case *c, const char *path) {
  struct px_case_node *found, *near;
  const struct px_schema *absent;
  if (!c || px_case_find(c, path, &found, &near, &absent) != PX_CASE_FIND_OK) return NULL;
  return found;
}

/* Find a value for a getter; NULL with the reason in the context. */
static struct px_case_node *px_case_get(const struct px_case *c, const char *path,
                                        enum px_status *st) {
  struct px_case_node *found, *near;
  const struct px_schema *absent;
  enum px_case_find f;
  if (!c) {
    *st = PX_STATUS_INVALID;
    return NULL;
  }
  f = px_case_find(c, path, &found, &near, &absent);
  switch (f) {
    case PX_CASE_FIND_OK: *st = PX_STATUS_OK; return found;
    case PX_CASE_FIND_ABSENT:
      *st = px_context_fail(c->ctx, PX_STATUS_NOT_FOUND,
                            "case key %s: not set in %s (an optional key without default)", path,
                            c->file);
      return NULL;
    case PX_CASE_FIND_MALFORMED:
      *st = px_context_fail(c->ctx, PX_STATUS_INVALID, "'%s' is not a case key path",
                            path ? path : "(null)");
      return NULL;
    case PX_CASE_FIND_UNKNOWN:
      *st = px_context_fail(c->ctx, PX_STATUS_INVALID,
                            "case key %s: no such key in the case schema", path);
      return NULL;
    case PX_CASE_FIND_RANGE:
      *st =
          px_context_fail(c->ctx, PX_STATUS_INVALID, "case key %s: list index out of range", path);
      return NULL;
    case PX_CASE_FIND_NOT_LIST:
      *st = px_context_fail(c->ctx, PX_STATUS_INVALID, "case key %s: indexes something not a list",
                            path);
      return NULL;
  }
  *st = PX_STATUS_INTERNAL;
  return NULL;
}

static const char *px_case_type_name(const struct px_case_node *n) {
  if (n->is_type) return "a variant type";
  if (n->is_element) return "a real";
  if (!n->schema) return "a value";
  switch (n->schema->type) {
    case PX_SCHEMA_TYPE_BOOL: return "a bool";
    case PX_SCHEMA_TYPE_INT: return "an integer";
    case PX_SCHEMA_TYPE_REAL: return "a real";
    case PX_SCHEMA_TYPE_STRING: return "a string";
    case PX_SCHEMA_TYPE_ENUM: return "an enum";
    case PX_SCHEMA_TYPE_MAP: return "a map";
    case PX_SCHEMA_TYPE_LIST: return "a list";
    case PX_SCHEMA_TYPE_VECTOR: return "a vector";
    case PX_SCHEMA_TYPE_VARIANT: return "a variant map";
  }
  return "a value";
}

static enum px_status px_case_wrong_type(const struct px_case *c, const char *path,
                                         const struct px_case_node *n, const char *wanted) {
  return px_context_fail(c->ctx, PX_STATUS_INVALID, "case key %s: holds %s, not %s", path,
                         px_case_type_name(n), wanted);
}

static int px_case_is(const struct px_case_node *n, enum px_schema_type t) {
  return n->schema && !n->is_type && !n->is_element && n->schema->type == t;
}

int px_case_has(const struct px_case *c, const char *path) {
  struct px_case_node *found, *near;
  const struct px_schema *absent;
  return c && px_case_find(c, path, &found, &near, &absent) == PX_CASE_FIND_OK;
}

enum px_status px_case_get_real(const struct px_case *c, const char *path, double *out) {
  enum px_status st;
  struct px_case_node *n = px_case_get(c, path, &st);
  if (!n) return st;
  if (!out) return PX_STATUS_INVALID;
  if (n->is_element || px_case_is(n, PX_SCHEMA_TYPE_REAL))
    *out = n->v.real;
  else if (px_case_is(n, PX_SCHEMA_TYPE_INT))
    *out = (double)n->v.integer;
  else
    return px_case_wrong_type(c, path, n, "a real");
  return PX_STATUS_OK;
}

enum px_status px_case_get_int(const struct px_case *c, const char *path, long *out) {
  enum px_status st;
  struct px_case_node *n = px_case_get(c, path, &st);
  if (!n) return st;
  if (!out) return PX_STATUS_INVALID;
  if (!px_case_is(n, PX_SCHEMA_TYPE_INT)) return px_case_wrong_type(c, path, n, "an integer");
  *out = n->v.integer;
  return PX_STATUS_OK;
}

enum px_status px_case_get_bool(const struct px_case *c, const char *path, int *out) {
  enum px_status st;
  struct px_case_node *n = px_case_get(c, path, &st);
  if (!n) return st;
  if (!out) return PX_STATUS_INVALID;
  if (!px_case_is(n, PX_SCHEMA_TYPE_BOOL)) return px_case_wrong_type(c, path, n, "a bool");
  *out = n->v.boolean;
  return PX_STATUS_OK;
}

enum px_status px_case_get_string(const struct px_case *c, const char *path, const char **out) {
  enum px_status st;
  struct px_case_node *n = px_case_get(c, path, &st);
  if (!n) return st;
  if (!out) return PX_STATUS_INVALID;
  if (n->is_type || px_case_is(n, PX_SCHEMA_TYPE_STRING))
    *out = n->text;
  else if (px_case_is(n, PX_SCHEMA_TYPE_ENUM))
    *out = n->schema->choices[n->v.index];
  else
    return px_case_wrong_type(c, path, n, "a string");
  return PX_STATUS_OK;
}

enum px_status px_case_get_enum(const struct px_case *c, const char *path, int *out) {
  enum px_status st;
  struct px_case_node *n = px_case_get(c, path, &st);
  if (!n) return st;
  if (!out) return PX_STATUS_INVALID;
  if (!n->is_type && !px_case_is(n, PX_SCHEMA_TYPE_ENUM))
    return px_case_wrong_type(c, path, n, "an enum");
  *out = n->v.index;
  return PX_STATUS_OK;
}

enum px_status px_case_count(const struct px_case *c, const char *path, size_t *out) {
  struct px_case_node *found, *near;
  const struct px_schema *absent;
  enum px_status st;
  if (!c || !out) return PX_STATUS_INVALID;
  if (px_case_find(c, path, &found, &near, &absent) == PX_CASE_FIND_ABSENT && absent &&
      (absent->type == PX_SCHEMA_TYPE_LIST || absent->type == PX_SCHEMA_TYPE_VECTOR)) {
    *out = 0;
    return PX_STATUS_OK;
  }
  found = px_case_get(c, path, &st);
  if (!found) return st;
  if (!px_case_is(found, PX_SCHEMA_TYPE_LIST) && !px_case_is(found, PX_SCHEMA_TYPE_VECTOR))
    return px_case_wrong_type(c, path, found, "a list");
  *out = found->n;
  return PX_STATUS_OK;
}

enum px_status px_case_get_vector(const struct px_case *c, const char *path, double *out,
                                  size_t n) {
  enum px_status st;
  struct px_case_node *v = px_case_get(c, path, &st);
  size_t i;
  if (!v) return st;
  if (!out && n) return PX_STATUS_INVALID;
  if (!px_case_is(v, PX_SCHEMA_TYPE_VECTOR)) return px_case_wrong_type(c, path, v, "a vector");
  if (v->n != n)
    return px_context_fail(c->ctx, PX_STATUS_INVALID,
                           "case key %s: has %zu components, the caller expects %zu", path, v->n,
                           n);
  for (i = 0; i < n; ++i) out[i] = v->items[i]->v.real;
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------ */
/* Semantic errors found by solvers */

enum px_status px_case_fail(struct px_case *c, const char *path, const char *fmt, ...) {
  char msg[1024];
  struct px_case_seg segs[PX_CASE_MAX_SEGS];
  struct px_case_loc loc;
  struct px_case_node *node;
  size_t nseg, i;
  int is_default = 0;
  va_list ap;
  if (!c) return PX_STATUS_CONFIG;
  msg[0] = '\0';
  if (fmt) {
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
  }

  /* the location: the node itself, or its nearest ancestor that the user
     wrote (a default has no position of its own) */
  node = c->root;
  loc.origin = PX_CASE_ORIGIN_FILE;
  loc.line = loc.col = 0;
  if (node) loc = node->key_loc;
  nseg = path ? px_case_path_parse(path, strlen(path), segs, PX_CASE_MAX_SEGS) : 0;
  for (i = 0; node && i < nseg; ++i) {
    struct px_case_node *next = NULL;
    if (segs[i].name)
      next = px_case_node_member(node, segs[i].name, segs[i].len);
    else if (node->kind == PX_CASE_NODE_SEQ && segs[i].index < node->n)
      next = node->items[segs[i].index];
    if (!next) break;
    node = next;
    if (node->key_loc.origin == PX_CASE_ORIGIN_BUILTIN) {
      is_default = 1;
    } else {
      /* a value points at itself, a map or list at its key */
      loc = (node->kind == PX_CASE_NODE_MAP || node->kind == PX_CASE_NODE_SEQ) &&
                    (!node->schema || node->schema->type != PX_SCHEMA_TYPE_VECTOR)
                ? node->key_loc
                : node->loc;
    }
  }
  if (is_default)
    px_case_error_add(c, &loc, path ? path : "", "%s (default value)", msg);
  else
    px_case_error_add(c, &loc, path ? path : "", "%s", msg);
  if (c->loading) return PX_STATUS_CONFIG;
  return px_case_errors_commit(c);
}
