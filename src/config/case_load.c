/* Loading a case: read the file, parse it, apply --set overrides, validate,
 * and produce the resolved text. */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "config/case_impl.h"
#include "core/text.h"
#include "partix/file.h"
#include "partix/memory.h"

/* ------------------------------------------------------------------------ */
/* Overrides */

#define PX_CASE_MAX_SEGS 64

/* Apply "key.path=value" number k (its value already parsed into `value`). */
static void px_case_apply_override(struct px_case *c, struct px_case_node **root, size_t k,
                                   struct px_case_node *value) {
  const char *text = c->overrides[k];
  const char *eq = strchr(text, '=');
  struct px_case_seg segs[PX_CASE_MAX_SEGS];
  struct px_case_loc loc;
  struct px_case_node *node;
  char path[PX_CASE_PATH_MAX];
  size_t nseg, i, plen = 0;
  /* undo of a failed override: it leaves no trace (no second, misleading
     error about a map or list it created on the way) */
  struct px_case_node *converted = NULL, *created_in = NULL;
  enum px_case_node_kind converted_kind = PX_CASE_NODE_NULL;

  loc.origin = (int)k;
  loc.line = loc.col = 0;
  nseg = px_case_path_parse(text, (size_t)(eq - text), segs, PX_CASE_MAX_SEGS);
  if (!nseg) {
    int shown = (int)(eq - text) > 200 ? 200 : (int)(eq - text);
    px_case_error_add(c, &loc, "",
                      "malformed key path '%.*s' (expected key.path=value, e.g. time.dt=0.001 or "
                      "vortex.bodies[0].angle=5)",
                      shown, text);
    return;
  }
  if (!*root) {
    *root = px_case_node_new(&c->arena, PX_CASE_NODE_MAP);
    if (!*root) {
      c->errors.nomem = 1;
      return;
    }
    (*root)->loc.origin = PX_CASE_ORIGIN_FILE;
    (*root)->loc.line = (*root)->loc.col = 1;
  }
  node = *root;
  value->loc = loc;
  value->key_loc = loc;
  path[0] = '\0';
  for (i = 0; i < nseg; ++i) {
    int last = i + 1 == nseg;
    struct px_case_node *child = NULL;
    size_t j;
    const char *what = node->kind == PX_CASE_NODE_SEQ ? "a list" : "a single value";
    if (segs[i].name) {
      if (node->kind == PX_CASE_NODE_NULL && !converted) {
        converted = node;
        node->kind = PX_CASE_NODE_MAP;
      }
      if (node->kind != PX_CASE_NODE_MAP) {
        size_t d = 0;
        while (d < segs[i].len && segs[i].name[d] >= '0' && segs[i].name[d] <= '9') ++d;
        if (node->kind == PX_CASE_NODE_SEQ && d == segs[i].len)
          px_case_error_add(c, &loc, path,
                            "is a list, not a map: cannot set '%.*s' inside it (an item of a "
                            "list is %s[%.*s])",
                            (int)segs[i].len, segs[i].name, path, (int)segs[i].len, segs[i].name);
        else
          px_case_error_add(c, &loc, path, "is %s, not a map: cannot set '%.*s' inside it", what,
                            (int)segs[i].len, segs[i].name);
        goto undo;
      }
      for (j = 0; j < node->n && !child; ++j) {
        struct px_case_node *m = node->items[j];
        if (m->key_len == segs[i].len && memcmp(m->key, segs[i].name, segs[i].len) == 0) {
          child = m;
          if (last) {
            value->key = m->key;
            value->key_len = m->key_len;
            node->items[j] = value;
          }
        }
      }
      if (!child) {
        child = last ? value
                     : px_case_node_new(&c->arena,
                                        segs[i + 1].name ? PX_CASE_NODE_MAP : PX_CASE_NODE_SEQ);
        if (!child) {
          c->errors.nomem = 1;
          return;
        }
        child->loc = child->key_loc = loc;
        child->key = px_case_arena_strdup(&c->arena, segs[i].name, segs[i].len);
        child->key_len = segs[i].len;
        if (!child->key || px_case_node_append(&c->arena, node, child)) {
          c->errors.nomem = 1;
          return;
        }
        if (!created_in) created_in = node;
      }
      if (plen + segs[i].len + 2 < sizeof path) {
        if (plen) path[plen++] = '.';
        memcpy(path + plen, segs[i].name, segs[i].len);
        plen += segs[i].len;
        path[plen] = '\0';
      }
    } else {
      size_t idx = segs[i].index;
      if (node->kind == PX_CASE_NODE_NULL && !converted) {
        converted = node;
        node->kind = PX_CASE_NODE_SEQ;
      }
      if (node->kind != PX_CASE_NODE_SEQ) {
        px_case_error_add(c, &loc, path, "is %s, not a list: cannot use [%zu] on it",
                          node->kind == PX_CASE_NODE_MAP ? "a map" : "a single value", idx);
        goto undo;
      }
      if (idx > node->n) {
        px_case_error_add(c, &loc, path,
                          "index [%zu] is out of range (the list has %zu item%s; [%zu] adds one)",
                          idx, node->n, node->n == 1 ? "" : "s", node->n);
        goto undo;
      }
      if (idx == node->n) {
        child = last ? value
                     : px_case_node_new(&c->arena,
                                        segs[i + 1].name ? PX_CASE_NODE_MAP : PX_CASE_NODE_SEQ);
        if (!child || px_case_node_append(&c->arena, node, child)) {
          c->errors.nomem = 1;
          return;
        }
        if (!created_in) created_in = node;
        child->loc = child->key_loc = loc;
      } else {
        child = node->items[idx];
        if (last) node->items[idx] = value;
      }
      {
        int w = snprintf(path + plen, sizeof path - plen, "[%zu]", idx);
        if (w > 0 && plen + (size_t)w < sizeof path) plen += (size_t)w;
        path[plen] = '\0';
      }
    }
    node = child;
  }
  return;
undo:
  if (created_in) created_in->n--; /* the first node created, appended last */
  if (converted) converted->kind = converted_kind;
}

/* ------------------------------------------------------------------------ */
/* Loading */

void px_case_rehash(struct px_case *c) {
  c->hash = px_text_fnv1a(PX_FNV1A_OFFSET, c->resolved, c->resolved_len);
}

enum px_status px_case_load_string_schema(struct px_context *ctx, const struct px_schema *root,
                                          const char *name, const char *text, size_t len,
                                          const char *const *overrides, size_t noverrides,
                                          struct px_case **out) {
  struct px_case *c;
  struct px_case_node *raw = NULL, **values = NULL;
  enum px_status st = PX_STATUS_OK;
  size_t k;
  int rc;

  if (out) *out = NULL;
  if (!ctx || !out || !name || (!text && len) || (noverrides && !overrides))
    return px_context_fail(ctx, PX_STATUS_INVALID, "px_case_load: invalid argument");
  if (!root || root->type != PX_SCHEMA_TYPE_MAP)
    return px_context_fail(ctx, PX_STATUS_INTERNAL,
                           "px_case_load: the root schema is missing or not a map "
                           "(too many solver sections?)");
  for (k = 0; k < noverrides; ++k)
    if (!overrides[k])
      return px_context_fail(ctx, PX_STATUS_INVALID, "px_case_load: override %zu is NULL", k);
  if (len > PX_CASE_MAX_BYTES)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: the case is too large (%zu bytes; the limit is %u MiB)", name, len,
                           PX_CASE_MAX_BYTES >> 20);

  c = px_mem_calloc(ctx, "case", 1, sizeof *c);
  if (!c) return PX_STATUS_NOMEM;
  c->ctx = ctx;
  c->schema = root;
  c->arena.ctx = ctx;
  c->file = px_case_arena_strdup(&c->arena, name, strlen(name));
  if (noverrides) {
    c->overrides = px_case_arena_alloc(&c->arena, noverrides * sizeof *c->overrides);
    values = px_case_arena_alloc(&c->arena, noverrides * sizeof *values);
  }
  if (!c->file || (noverrides && (!c->overrides || !values))) {
    px_case_free(c);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory loading %s", name);
  }
  for (k = 0; k < noverrides; ++k) {
    c->overrides[k] = px_case_arena_strdup(&c->arena, overrides[k], strlen(overrides[k]));
    if (!c->overrides[k]) {
      px_case_free(c);
      return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory loading %s", name);
    }
  }
  c->noverrides = noverrides;

  rc = px_case_yaml_parse(c, text ? text : "", len, PX_CASE_ORIGIN_FILE, &raw);
  /* the overrides' values are parsed even after a syntax error in the file,
     so that all such errors show at once */
  for (k = 0; k < noverrides && rc != -2; ++k) {
    const char *eq = strchr(c->overrides[k], '=');
    struct px_case_loc loc;
    int vr;
    loc.origin = (int)k;
    loc.line = loc.col = 0;
    if (!eq) {
      px_case_error_add(c, &loc, "",
                        "missing '=' (expected --set key.path=value, e.g. --set time.steps=100)");
      continue;
    }
    vr = px_case_yaml_parse(c, eq + 1, strlen(eq + 1), (int)k, &values[k]);
    if (vr == -2) rc = -2;
    if (vr == 0 && !values[k]) { /* "key=" : null */
      values[k] = px_case_node_new(&c->arena, PX_CASE_NODE_NULL);
      if (!values[k]) rc = -2;
    }
  }
  if (rc == -2 || c->errors.nomem) {
    st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory loading %s", name);
    px_case_free(c);
    return st;
  }
  if (rc == 0 && (!raw || raw->kind == PX_CASE_NODE_MAP || raw->kind == PX_CASE_NODE_NULL)) {
    for (k = 0; k < noverrides; ++k)
      if (values[k]) px_case_apply_override(c, &raw, k, values[k]);
  }
  if (rc == 0 && !c->errors.nomem) st = px_case_validate(c, raw);
  if (st == PX_STATUS_OK && c->errors.total == 0 && !c->errors.nomem) st = px_case_emit(c);
  if (st == PX_STATUS_OK && (c->errors.total || c->errors.nomem))
    st = px_case_errors_commit(c);
  else if (st == PX_STATUS_NOMEM)
    st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory loading %s", name);
  else if (st != PX_STATUS_OK && px_context_status(ctx) != st)
    st = px_context_fail(ctx, st, "%s: loading the case failed (%s)", name, px_status_message(st));
  if (st != PX_STATUS_OK) {
    px_case_free(c);
    return st;
  }
  px_case_rehash(c);
  *out = c;
  return PX_STATUS_OK;
}

/* Read a whole file (at most PX_CASE_MAX_BYTES) into a px_mem buffer. */
static enum px_status px_case_read_file(struct px_context *ctx, const char *path, char **data,
                                        size_t *len) {
  FILE *f = fopen(path, "rb");
  char *buf = NULL;
  size_t cap = 0, n = 0;
  *data = NULL;
  *len = 0;
  if (!f)
    return px_context_fail(ctx, PX_STATUS_IO, "cannot open case file %s: %s", path,
                           strerror(errno));
  for (;;) {
    size_t got;
    if (n == cap) {
      size_t ncap = cap ? 2 * cap : 16384;
      char *grown;
      if (cap > PX_CASE_MAX_BYTES) {
        px_mem_free(ctx, buf);
        fclose(f);
        return px_context_fail(ctx, PX_STATUS_CONFIG,
                               "%s: the file is too large for a case file (more than %u MiB)", path,
                               PX_CASE_MAX_BYTES >> 20);
      }
      grown = px_mem_realloc(ctx, "case", buf, ncap + 1);
      if (!grown) {
        px_mem_free(ctx, buf);
        fclose(f);
        return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory reading %s", path);
      }
      buf = grown;
      cap = ncap;
    }
    got = fread(buf + n, 1, cap - n, f);
    n += got;
    if (got == 0) break;
  }
  if (ferror(f)) {
    int err = errno;
    px_mem_free(ctx, buf);
    fclose(f);
    return px_context_fail(ctx, PX_STATUS_IO, "cannot read case file %s: %s", path, strerror(err));
  }
  fclose(f);
  if (n > PX_CASE_MAX_BYTES) {
    px_mem_free(ctx, buf);
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: the file is too large for a case file (more than %u MiB)", path,
                           PX_CASE_MAX_BYTES >> 20);
  }
  buf[n] = '\0';
  *data = buf;
  *len = n;
  return PX_STATUS_OK;
}

enum px_status px_case_load_schema(struct px_context *ctx, const struct px_schema *root,
                                   const char *path, const char *const *overrides,
                                   size_t noverrides, struct px_case **out) {
  char *data;
  size_t len;
  enum px_status st;
  if (out) *out = NULL;
  if (!ctx || !path || !out)
    return px_context_fail(ctx, PX_STATUS_INVALID, "px_case_load: invalid argument");
  PX_TRY(px_case_read_file(ctx, path, &data, &len));
  st = px_case_load_string_schema(ctx, root, path, data, len, overrides, noverrides, out);
  px_mem_free(ctx, data);
  return st;
}

void px_case_free(struct px_case *c) {
  struct px_context *ctx;
  if (!c) return;
  ctx = c->ctx;
  px_mem_free(ctx, c->resolved);
  px_case_arena_free(&c->arena);
  px_mem_free(ctx, c);
}

const char *px_case_file(const struct px_case *c) { return c ? c->file : NULL; }
const char *px_case_solver(const struct px_case *c) { return c ? c->solver : NULL; }
uint64_t px_case_hash(const struct px_case *c) { return c ? c->hash : 0; }
const char *px_case_resolved_text(const struct px_case *c) { return c ? c->resolved : NULL; }

enum px_status px_case_write_resolved(const struct px_case *c, const char *path) {
  if (!c || !path) return PX_STATUS_INVALID;
  return px_file_write_all(c->ctx, path, c->resolved, c->resolved_len);
}
