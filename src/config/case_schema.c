/* Schema listing (`partix help keys`) and schema self-check. */
#include <stdio.h>
#include <string.h>

#include "config/case_impl.h"
#include "partix/memory.h"

#define PX_SCHEMA_MAX_NESTING 16

/* ------------------------------------------------------------------------ */
/* Listing */

static void px_case_spec_range(char *buf, size_t size, const struct px_schema *k) {
  buf[0] = '\0';
  if (k->lo_bound && k->hi_bound)
    snprintf(buf, size, " in %c%g, %g%c", k->lo_bound == PX_SCHEMA_BOUND_INCL ? '[' : '(', k->lo,
             k->hi, k->hi_bound == PX_SCHEMA_BOUND_INCL ? ']' : ')');
  else if (k->lo_bound)
    snprintf(buf, size, " %s %g", k->lo_bound == PX_SCHEMA_BOUND_INCL ? ">=" : ">", k->lo);
  else if (k->hi_bound)
    snprintf(buf, size, " %s %g", k->hi_bound == PX_SCHEMA_BOUND_INCL ? "<=" : "<", k->hi);
}

static void px_case_spec_len(char *buf, size_t size, const struct px_schema *k) {
  if (k->len_max && k->len_min == k->len_max)
    snprintf(buf, size, "[%zu]", k->len_min);
  else if (k->len_max)
    snprintf(buf, size, "[%zu..%zu]", k->len_min, k->len_max);
  else if (k->len_min)
    snprintf(buf, size, "[%zu..]", k->len_min);
  else
    buf[0] = '\0';
}

static void px_case_spec(char *buf, size_t size, const struct px_schema *k) {
  char range[96], len[48], choices[256];
  size_t i, n = 0;
  px_case_spec_range(range, sizeof range, k);
  px_case_spec_len(len, sizeof len, k);
  choices[0] = '\0';
  if (k->type == PX_SCHEMA_TYPE_ENUM) {
    for (i = 0; k->choices && k->choices[i] && n + 2 < sizeof choices; ++i) {
      int w = snprintf(choices + n, sizeof choices - n, "%s%s", i ? "|" : "", k->choices[i]);
      if (w < 0) break;
      n += (size_t)w;
    }
    if (!n) snprintf(choices, sizeof choices, "(none built in)");
  }
  switch (k->type) {
    case PX_SCHEMA_TYPE_BOOL: snprintf(buf, size, "bool"); break;
    case PX_SCHEMA_TYPE_INT: snprintf(buf, size, "int%s", range); break;
    case PX_SCHEMA_TYPE_REAL: snprintf(buf, size, "real%s", range); break;
    case PX_SCHEMA_TYPE_STRING:
      snprintf(buf, size, "%s",
               k->file        ? "file (relative to the case)"
               : k->file_name ? "name [A-Za-z0-9._-]"
                              : "string");
      break;
    case PX_SCHEMA_TYPE_ENUM: snprintf(buf, size, "%s", choices); break;
    case PX_SCHEMA_TYPE_MAP: snprintf(buf, size, "map"); break;
    case PX_SCHEMA_TYPE_LIST: snprintf(buf, size, "list%s", len); break;
    case PX_SCHEMA_TYPE_VECTOR:
      snprintf(buf, size, "vector%s%s%s", len, range[0] ? " each" : "", range);
      break;
    case PX_SCHEMA_TYPE_VARIANT: snprintf(buf, size, "map by type"); break;
  }
  n = strlen(buf);
  if (k->required && n < size) snprintf(buf + n, size - n, ", required");
  n = strlen(buf);
  if (k->def && n < size) snprintf(buf + n, size - n, ", default %s", k->def);
}

static void px_case_print_line(FILE *out, const char *path, const char *spec, const char *doc) {
  fprintf(out, "%-34s %-30s  %s\n", path, spec, doc ? doc : "");
}

static void px_case_print_tree(FILE *out, const char *path, const struct px_schema *k, int depth);

static void px_case_print_children(FILE *out, const char *prefix, const struct px_schema *keys,
                                   int depth) {
  char path[PX_CASE_PATH_MAX];
  size_t i;
  for (i = 0; keys && keys[i].name; ++i) {
    px_case_path_join(path, sizeof path, prefix, keys[i].name);
    px_case_print_tree(out, path, &keys[i], depth + 1);
  }
}

static void px_case_print_tree(FILE *out, const char *path, const struct px_schema *k, int depth) {
  char spec[400], sub[PX_CASE_PATH_MAX];
  size_t i;
  if (depth > PX_SCHEMA_MAX_NESTING) return;
  px_case_spec(spec, sizeof spec, k);
  px_case_print_line(out, path, spec, k->doc);
  switch (k->type) {
    case PX_SCHEMA_TYPE_MAP: px_case_print_children(out, path, k->keys, depth); break;
    case PX_SCHEMA_TYPE_LIST:
      if (!k->item) break;
      snprintf(sub, sizeof sub, "%s[]", path);
      if (k->item->type == PX_SCHEMA_TYPE_MAP)
        px_case_print_children(out, sub, k->item->keys, depth);
      else /* a variant or a single value per item */
        px_case_print_tree(out, sub, k->item, depth + 1);
      break;
    case PX_SCHEMA_TYPE_VARIANT:
      for (i = 0; k->keys && k->keys[i].name; ++i) {
        char head[PX_CASE_PATH_MAX + 64];
        snprintf(head, sizeof head, "%s with type: %s", path, k->keys[i].name);
        px_case_print_line(out, head, "", k->keys[i].doc);
        px_case_print_children(out, path, k->keys[i].keys, depth + 1);
      }
      break;
    default: break;
  }
}

enum px_status px_case_print_schema(const struct px_schema *root, const char *section, FILE *out) {
  size_t i;
  if (!root || !out) return PX_STATUS_INVALID;
  if (!section) {
    px_case_print_children(out, "", root->keys, 0);
    return PX_STATUS_OK;
  }
  for (i = 0; root->keys && root->keys[i].name; ++i) {
    if (strcmp(root->keys[i].name, section) == 0) {
      px_case_print_tree(out, section, &root->keys[i], 1);
      return PX_STATUS_OK;
    }
  }
  return PX_STATUS_NOT_FOUND;
}

/* The schema node of key `name` (len bytes) among the children of k: a
 * map's keys, a variant's keys of every type (the first that has it). */
static const struct px_schema *px_schema_child(const struct px_schema *k, const char *name,
                                               size_t len) {
  size_t i, j;
  if (k->type == PX_SCHEMA_TYPE_LIST) k = k->item;
  if (!k) return NULL;
  if (k->type == PX_SCHEMA_TYPE_MAP) {
    for (i = 0; k->keys && k->keys[i].name; ++i)
      if (strlen(k->keys[i].name) == len && strncmp(k->keys[i].name, name, len) == 0)
        return &k->keys[i];
  } else if (k->type == PX_SCHEMA_TYPE_VARIANT) {
    for (i = 0; k->keys && k->keys[i].name; ++i)
      for (j = 0; k->keys[i].keys && k->keys[i].keys[j].name; ++j)
        if (strlen(k->keys[i].keys[j].name) == len &&
            strncmp(k->keys[i].keys[j].name, name, len) == 0)
          return &k->keys[i].keys[j];
  }
  return NULL;
}

const char *px_schema_key_doc(const struct px_schema *root, const char *path) {
  const struct px_schema *k = root;
  const char *at = path;
  int depth = 0;
  if (!root || !path) return NULL;
  while (k && *at && depth++ <= PX_SCHEMA_MAX_NESTING) {
    /* one segment: a key name up to '.', '[' or the end; list indices
       ("[2]") step into the list's item */
    size_t len = strcspn(at, ".[");
    k = px_schema_child(k, at, len);
    at += len;
    while (*at == '[') {
      const char *close = strchr(at, ']');
      if (!close) return NULL;
      at = close + 1;
    }
    if (*at == '.') ++at;
  }
  return k && k != root && !*at ? k->doc : NULL;
}

/* ------------------------------------------------------------------------ */
/* Self-check */

static int px_case_valid_name(const char *s, int allow_dot_plus) {
  if (!s || !*s) return 0;
  for (; *s; ++s) {
    char ch = *s;
    if ((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
        ch == '_' || ch == '-')
      continue;
    if (allow_dot_plus && (ch == '.' || ch == '+')) continue;
    return 0;
  }
  return 1;
}

static enum px_status px_case_check_one(struct px_case *c, const struct px_schema *k,
                                        const char *path, int depth);

static enum px_status px_case_check_keys(struct px_case *c, const struct px_schema *keys,
                                         const char *prefix, int depth, int in_variant) {
  char path[PX_CASE_PATH_MAX];
  size_t i, j;
  for (i = 0; keys[i].name; ++i) {
    px_case_path_join(path, sizeof path, prefix, keys[i].name);
    if (!px_case_valid_name(keys[i].name, 0))
      return px_context_fail(c->ctx, PX_STATUS_INTERNAL,
                             "schema: %s: key names must be [A-Za-z0-9_-]+", path);
    if (in_variant && strcmp(keys[i].name, "type") == 0)
      return px_context_fail(c->ctx, PX_STATUS_INTERNAL,
                             "schema: %s: 'type' is implicit in a variant", path);
    for (j = 0; j < i; ++j)
      if (strcmp(keys[i].name, keys[j].name) == 0)
        return px_context_fail(c->ctx, PX_STATUS_INTERNAL, "schema: %s: key defined twice", path);
    PX_TRY(px_case_check_one(c, &keys[i], path, depth + 1));
  }
  return PX_STATUS_OK;
}

static enum px_status px_case_check_one(struct px_case *c, const struct px_schema *k,
                                        const char *path, int depth) {
  char sub[PX_CASE_PATH_MAX];
  size_t i, j;
  struct px_context *ctx = c->ctx;
  int numeric = k->type == PX_SCHEMA_TYPE_INT || k->type == PX_SCHEMA_TYPE_REAL ||
                k->type == PX_SCHEMA_TYPE_VECTOR;
  if (depth > PX_SCHEMA_MAX_NESTING)
    return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: nested too deeply (recursive?)",
                           path);
  if (!k->doc || !k->doc[0])
    return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: no doc line", path);
  if (k->required && k->def)
    return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: both required and defaulted",
                           path);
  if (!numeric && (k->lo_bound || k->hi_bound))
    return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: a range on a non-number", path);
  if ((k->file || k->file_name) && k->type != PX_SCHEMA_TYPE_STRING)
    return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: an input file not a string", path);
  if (k->lo_bound && k->hi_bound &&
      (k->lo > k->hi || (k->lo == k->hi && (k->lo_bound == PX_SCHEMA_BOUND_EXCL ||
                                            k->hi_bound == PX_SCHEMA_BOUND_EXCL))))
    return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: empty range", path);
  if (k->len_max && k->len_min > k->len_max)
    return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: empty length range", path);
  switch (k->type) {
    case PX_SCHEMA_TYPE_ENUM:
      if (!k->choices ||
          (!k->choices[0] && strcmp(k->name ? k->name : "", PX_CASE_SOLVER_KEY) != 0))
        return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: an enum without choices",
                               path);
      for (i = 0; k->choices[i]; ++i) {
        if (!px_case_valid_name(k->choices[i], 1))
          return px_context_fail(ctx, PX_STATUS_INTERNAL,
                                 "schema: %s: choice '%s' must be [A-Za-z0-9_.+-]+", path,
                                 k->choices[i]);
        for (j = 0; j < i; ++j)
          if (strcmp(k->choices[i], k->choices[j]) == 0)
            return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: choice '%s' twice", path,
                                   k->choices[i]);
      }
      break;
    case PX_SCHEMA_TYPE_MAP:
      if (!k->keys)
        return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: a map without keys", path);
      PX_TRY(px_case_check_keys(c, k->keys, path, depth, 0));
      break;
    case PX_SCHEMA_TYPE_LIST:
      if (!k->item)
        return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: a list without item", path);
      snprintf(sub, sizeof sub, "%s[]", path);
      PX_TRY(px_case_check_one(c, k->item, sub, depth + 1));
      break;
    case PX_SCHEMA_TYPE_VARIANT:
      if (!k->keys || !k->keys[0].name)
        return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: a variant without types",
                               path);
      for (i = 0; k->keys[i].name; ++i) {
        const struct px_schema *t = &k->keys[i];
        snprintf(sub, sizeof sub, "%s(type: %s)", path, t->name);
        if (t->type != PX_SCHEMA_TYPE_MAP || !t->keys || !px_case_valid_name(t->name, 1))
          return px_context_fail(ctx, PX_STATUS_INTERNAL,
                                 "schema: %s: a variant type must be a PX_TYPE map with a "
                                 "[A-Za-z0-9_.+-]+ name",
                                 sub);
        for (j = 0; j < i; ++j)
          if (strcmp(t->name, k->keys[j].name) == 0)
            return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: type defined twice", sub);
        if (!t->doc || !t->doc[0])
          return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: no doc line", sub);
        PX_TRY(px_case_check_keys(c, t->keys, path, depth + 1, 1));
      }
      if (k->def) {
        for (i = 0; k->keys[i].name && strcmp(k->keys[i].name, k->def) != 0; ++i) continue;
        if (!k->keys[i].name)
          return px_context_fail(ctx, PX_STATUS_INTERNAL,
                                 "schema: %s: default type '%s' is not a type", path, k->def);
      }
      return PX_STATUS_OK; /* the default is a type name, checked above */
    default: break;
  }
  if (k->def) {
    enum px_status st;
    c->errors.n = c->errors.total = 0;
    st = px_case_validate_default(c, k, path);
    if (st != PX_STATUS_OK)
      return px_context_fail(ctx, st,
                             "schema: %s: checking the default "
                             "failed",
                             path);
    if (c->errors.n)
      return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: %s: bad default '%s': %s", path,
                             k->def, c->errors.list[0].text);
  }
  return PX_STATUS_OK;
}

enum px_status px_case_schema_check(struct px_context *ctx, const struct px_schema *root) {
  struct px_case *c;
  enum px_status st;
  if (!ctx) return PX_STATUS_INVALID;
  if (!root || root->type != PX_SCHEMA_TYPE_MAP || !root->keys)
    return px_context_fail(ctx, PX_STATUS_INTERNAL, "schema: the root must be a map with keys");
  c = px_mem_calloc(ctx, "case", 1, sizeof *c);
  if (!c) return PX_STATUS_NOMEM;
  c->ctx = ctx;
  c->schema = root;
  c->arena.ctx = ctx;
  c->file = "(schema)";
  st = px_case_check_keys(c, root->keys, "", 0, 0);
  px_case_free(c);
  return st;
}
