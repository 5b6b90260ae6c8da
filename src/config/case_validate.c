/* Validation of a parsed case against its schema: types, ranges, choices,
 * unknown and duplicate keys, required keys, defaults; builds the resolved
 * tree (members in schema order) and runs the cross-key checks. Every problem
 * is recorded (px_case_error_add) and validation goes on, so that one load
 * reports all errors. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/case_validate_impl.h"

/* ------------------------------------------------------------------------ */
/* Collections */

static int px_case_check_len(struct px_case_validator *v, const struct px_case_node *n,
                             const struct px_schema *s, const char *unit) {
  size_t count = n->n;
  const char *plural = "s";
  if (count >= s->len_min && (s->len_max == 0 || count <= s->len_max)) return 1;
  if (s->len_max && s->len_min == s->len_max) {
    if (s->len_min == 1) plural = "";
    px_case_verr(v, &n->loc, "must have exactly %zu %s%s (got %zu)", s->len_min, unit, plural,
                 count);
  } else if (count < s->len_min) {
    if (s->len_min == 1) plural = "";
    px_case_verr(v, &n->loc, "must have at least %zu %s%s (got %zu)", s->len_min, unit, plural,
                 count);
  } else {
    if (s->len_max == 1) plural = "";
    px_case_verr(v, &n->loc, "must have at most %zu %s%s (got %zu)", s->len_max, unit, plural,
                 count);
  }
  return 0;
}

static struct px_case_node *px_case_val_vector(struct px_case_validator *v, struct px_case_node *n,
                                               const struct px_schema *s) {
  char q[200];
  size_t i;
  int ok = 1;
  if (n->kind != PX_CASE_NODE_SEQ) {
    if (s->len_max && s->len_min == s->len_max)
      px_case_verr(v, &n->loc, "expected a list of %zu numbers (got %s)", s->len_min,
                   px_case_describe(q, sizeof q, n));
    else
      px_case_verr(v, &n->loc, "expected a list of numbers (got %s)",
                   px_case_describe(q, sizeof q, n));
    return NULL;
  }
  if (!px_case_check_len(v, n, s, "component")) ok = 0;
  for (i = 0; i < n->n; ++i) {
    struct px_case_node *e = n->items[i];
    size_t old = px_case_path_index(v, i);
    double x;
    if (px_case_need_scalar(v, e, "a real number") && px_case_parse_real(v, e, &x) &&
        px_case_check_range(v, e, s, x)) {
      e->v.real = x;
      e->schema = s;
      e->is_element = 1;
    } else {
      ok = 0;
    }
    px_case_path_pop(v, old);
  }
  if (!ok) return NULL;
  n->schema = s;
  return n;
}

static struct px_case_node *px_case_val_list(struct px_case_validator *v, struct px_case_node *n,
                                             const struct px_schema *s) {
  char q[200];
  size_t i, kept = 0;
  if (n->kind == PX_CASE_NODE_NULL) n->kind = PX_CASE_NODE_SEQ; /* "key:" = empty list */
  if (n->kind != PX_CASE_NODE_SEQ) {
    px_case_verr(v, &n->loc, "expected a list (got %s)", px_case_describe(q, sizeof q, n));
    return NULL;
  }
  px_case_check_len(v, n, s, "item");
  for (i = 0; i < n->n; ++i) {
    size_t old = px_case_path_index(v, i);
    struct px_case_node *item = px_case_val_node(v, n->items[i], s->item);
    px_case_path_pop(v, old);
    if (item) n->items[kept++] = item;
  }
  n->n = kept;
  n->schema = s;
  return n;
}

static int px_case_key_is(const struct px_case_node *m, const char *name) {
  return m->key && m->key_len == strlen(name) && memcmp(m->key, name, m->key_len) == 0;
}

static const struct px_schema *px_case_find_key(const struct px_schema *keys, const char *name,
                                                size_t len) {
  size_t i;
  for (i = 0; keys && keys[i].name; ++i)
    if (strlen(keys[i].name) == len && memcmp(keys[i].name, name, len) == 0) return &keys[i];
  return NULL;
}

/* Value for a key the map does not give: error, default, empty map or none. */
static struct px_case_node *px_case_fill_absent(struct px_case_validator *v,
                                                const struct px_case_node *map,
                                                const struct px_schema *k) {
  struct px_case_node *raw = NULL, *res;
  size_t old;
  if (k->required) {
    if (k->doc && k->doc[0])
      px_case_verr(v, &map->key_loc, "missing required key '%s' (%s)", k->name, k->doc);
    else
      px_case_verr(v, &map->key_loc, "missing required key '%s'", k->name);
    return NULL;
  }
  if (k->def && k->type != PX_SCHEMA_TYPE_VARIANT) {
    int rc = px_case_yaml_parse(v->c, k->def, strlen(k->def), PX_CASE_ORIGIN_BUILTIN, &raw);
    if (rc == -2) {
      v->fatal = PX_STATUS_NOMEM;
      return NULL;
    }
    if (rc) return NULL; /* reported, "(built-in default)" */
    if (!raw) {
      raw = px_case_node_new(&v->c->arena, PX_CASE_NODE_NULL);
      if (!raw) {
        v->fatal = PX_STATUS_NOMEM;
        return NULL;
      }
      raw->loc.origin = PX_CASE_ORIGIN_BUILTIN;
    }
  } else if (k->type == PX_SCHEMA_TYPE_MAP || k->type == PX_SCHEMA_TYPE_VARIANT) {
    /* an absent section is an empty one: its defaults apply, its required
       keys are reported at the parent; a variant's default is its type */
    raw = px_case_node_new(&v->c->arena, PX_CASE_NODE_MAP);
    if (!raw) {
      v->fatal = PX_STATUS_NOMEM;
      return NULL;
    }
    raw->loc = map->key_loc;
  } else {
    return NULL;
  }
  if (k->type == PX_SCHEMA_TYPE_VARIANT && !k->def) return NULL;
  raw->key_loc = raw->loc;
  old = px_case_path_key(v, k->name, strlen(k->name));
  res = px_case_val_node(v, raw, k);
  px_case_path_pop(v, old);
  if (res) res->defaulted = 1;
  return res;
}

/* Validate a map against `keys`. `s` is the map's own schema (MAP, or the
 * VARIANT for a variant map whose chosen type gave `keys`); `type_node` is
 * the variant's `type` member, kept first. */
static struct px_case_node *px_case_val_map(struct px_case_validator *v, struct px_case_node *n,
                                            const struct px_schema *s, const struct px_schema *keys,
                                            struct px_case_node *type_node) {
  char q[200], hint[128], list[400];
  size_t nkeys = 0, i, j, nout = 0;
  size_t errors_before = v->c->errors.total;
  unsigned char *claimed;
  size_t *first; /* per schema key (+ type): index of its first member */
  struct px_case_node **out;
  const char *chosen = NULL;
  int has_sections = 0, chosen_valid = 0;

  if (n->kind == PX_CASE_NODE_NULL) n->kind = PX_CASE_NODE_MAP; /* "key:" = empty map */
  if (n->kind != PX_CASE_NODE_MAP) {
    px_case_verr(v, &n->loc, "expected a map (got %s)", px_case_describe(q, sizeof q, n));
    return NULL;
  }
  while (keys && keys[nkeys].name) ++nkeys;
  claimed = px_case_arena_alloc(&v->c->arena, n->n + 1);
  first = px_case_arena_alloc(&v->c->arena, (nkeys + 1) * sizeof *first);
  out = px_case_arena_alloc(&v->c->arena, (nkeys + 2) * sizeof *out);
  if (!claimed || !first || !out) {
    v->fatal = PX_STATUS_NOMEM;
    return NULL;
  }

  /* which member is which key; later repeats of a key are duplicates
     (first[] keeps this O(members x keys) for hostile maps) */
  for (j = 0; j <= nkeys; ++j) first[j] = (size_t)-1;
  for (i = 0; i < n->n; ++i) {
    struct px_case_node *m = n->items[i];
    size_t ki;
    if (type_node && px_case_key_is(m, "type")) {
      ki = nkeys; /* the variant's type */
    } else {
      const struct px_schema *k = px_case_find_key(keys, m->key, m->key_len);
      if (!k) continue;
      ki = (size_t)(k - keys);
    }
    claimed[i] = 1;
    if (first[ki] == (size_t)-1) {
      first[ki] = i;
    } else {
      size_t old = px_case_path_key(v, m->key, m->key_len);
      const struct px_case_node *f = n->items[first[ki]];
      if (f->key_loc.origin == PX_CASE_ORIGIN_FILE && f->key_loc.line > 0)
        px_case_verr(v, &m->key_loc, "duplicate key (first given at line %d)", f->key_loc.line);
      else
        px_case_verr(v, &m->key_loc, "duplicate key");
      px_case_path_pop(v, old);
      claimed[i] = 2;
    }
  }
  for (i = 0; i < n->n; ++i) {
    struct px_case_node *m = n->items[i];
    size_t old;
    struct px_case_suggest sg;
    if (claimed[i]) continue;
    old = px_case_path_key(v, m->key, m->key_len);
    if (!px_case_verbose(v)) {
      px_case_verr(v, &m->key_loc, "unknown key");
    } else {
      px_case_suggest_init(&sg, m->key, m->key_len);
      if (type_node) px_case_suggest_try(&sg, "type");
      for (j = 0; j < nkeys; ++j) px_case_suggest_try(&sg, keys[j].name);
      if (sg.best)
        px_case_verr(v, &m->key_loc, "unknown key%s", px_case_suggest_text(hint, sizeof hint, &sg));
      else
        px_case_verr(v, &m->key_loc, "unknown key (expected one of: %s)",
                     px_case_list_keys(list, sizeof list, keys, type_node != NULL));
    }
    px_case_path_pop(v, old);
  }

  if (type_node) out[nout++] = type_node;
  for (j = 0; j < nkeys; ++j) {
    const struct px_schema *k = &keys[j];
    struct px_case_node *m = NULL, *res;
    if (k->section) {
      has_sections = 1;
      continue;
    }
    if (first[j] != (size_t)-1) m = n->items[first[j]];
    if (m) {
      size_t old = px_case_path_key(v, k->name, strlen(k->name));
      res = px_case_val_node(v, m, k);
      px_case_path_pop(v, old);
      if (res) res->key_loc = m->key_loc;
    } else {
      res = px_case_fill_absent(v, n, k);
    }
    if (v->fatal) return NULL;
    if (!res) continue;
    res->key = k->name;
    res->key_len = strlen(k->name);
    out[nout++] = res;
    if (k->type == PX_SCHEMA_TYPE_ENUM && strcmp(k->name, PX_CASE_SOLVER_KEY) == 0) {
      chosen = k->choices[res->v.index];
      chosen_valid = 1;
    }
  }

  /* solver sections: only the chosen solver's is kept */
  for (j = 0; has_sections && j < nkeys; ++j) {
    const struct px_schema *k = &keys[j];
    struct px_case_node *m = NULL, *res = NULL;
    if (!k->section) continue;
    if (first[j] != (size_t)-1) m = n->items[first[j]];
    if (chosen_valid && strcmp(chosen, k->name) != 0) {
      if (m) {
        size_t old = px_case_path_key(v, k->name, strlen(k->name));
        px_case_verr(v, &m->key_loc,
                     "this section is for solver '%s', but solver is '%s' (remove the "
                     "section or change the solver)",
                     k->name, chosen);
        px_case_path_pop(v, old);
      }
      continue;
    }
    if (m) {
      size_t old = px_case_path_key(v, k->name, strlen(k->name));
      res = px_case_val_node(v, m, k);
      px_case_path_pop(v, old);
      if (res) res->key_loc = m->key_loc;
    } else if (chosen_valid) {
      res = px_case_fill_absent(v, n, k);
    }
    if (v->fatal) return NULL;
    if (!res) continue;
    res->key = k->name;
    res->key_len = strlen(k->name);
    out[nout++] = res;
  }

  n->items = out;
  n->n = n->cap = nout;
  n->schema = s;
  n->ok = v->c->errors.total == errors_before;
  return n;
}

static struct px_case_node *px_case_val_variant(struct px_case_validator *v, struct px_case_node *n,
                                                const struct px_schema *s) {
  char q[200], hint[128], list[400];
  const char *noun = s->what ? s->what : s->name;
  struct px_case_node *type = NULL;
  const struct px_schema *t = NULL;
  size_t i;
  int index = -1;
  if (n->kind == PX_CASE_NODE_NULL) n->kind = PX_CASE_NODE_MAP;
  if (n->kind != PX_CASE_NODE_MAP) {
    px_case_verr(v, &n->loc, "expected a map with a 'type' key (got %s)",
                 px_case_describe(q, sizeof q, n));
    return NULL;
  }
  for (i = 0; i < n->n && !type; ++i)
    if (px_case_key_is(n->items[i], "type")) type = n->items[i];
  if (!type && s->def) {
    type = px_case_node_new(&v->c->arena, PX_CASE_NODE_SCALAR);
    if (!type) {
      v->fatal = PX_STATUS_NOMEM;
      return NULL;
    }
    type->text = s->def;
    type->len = strlen(s->def);
    type->loc.origin = PX_CASE_ORIGIN_BUILTIN;
    type->key_loc = type->loc;
    type->defaulted = 1;
  }
  if (!type) {
    px_case_verr(v, &n->key_loc, "missing required key 'type' (%s%s%s, one of: %s)",
                 noun ? noun : "", noun ? " " : "", "type",
                 px_case_list_keys(list, sizeof list, s->keys, 0));
    return NULL;
  }
  {
    size_t old = px_case_path_key(v, "type", 4);
    if (px_case_need_scalar(v, type, "a type name")) {
      for (i = 0; s->keys && s->keys[i].name; ++i) {
        if (strlen(s->keys[i].name) == type->len &&
            memcmp(s->keys[i].name, type->text, type->len) == 0) {
          t = &s->keys[i];
          index = (int)i;
          break;
        }
      }
      if (!t) {
        struct px_case_suggest sg;
        px_case_suggest_init(&sg, type->text, type->len);
        for (i = 0; s->keys && s->keys[i].name; ++i) px_case_suggest_try(&sg, s->keys[i].name);
        px_case_verr(v, &type->loc, "unknown %s%stype %s%s (choices: %s)", noun ? noun : "",
                     noun ? " " : "", px_case_quote(q, sizeof q, type->text, type->len),
                     px_case_suggest_text(hint, sizeof hint, &sg),
                     px_case_list_keys(list, sizeof list, s->keys, 0));
      }
    }
    px_case_path_pop(v, old);
  }
  if (!t) return NULL;
  type->schema = s;
  type->is_type = 1;
  type->v.index = index;
  type->text = t->name; /* static: outlives nothing it should not */
  type->len = strlen(t->name);
  type->key = "type";
  type->key_len = 4;
  n = px_case_val_map(v, n, s, t->keys, type);
  if (n) n->variant = t;
  return n;
}

struct px_case_node *px_case_val_node(struct px_case_validator *v, struct px_case_node *n,
                                      const struct px_schema *s) {
  if (!s) return NULL;
  switch (s->type) {
    case PX_SCHEMA_TYPE_MAP: return px_case_val_map(v, n, s, s->keys, NULL);
    case PX_SCHEMA_TYPE_VARIANT: return px_case_val_variant(v, n, s);
    case PX_SCHEMA_TYPE_LIST: return px_case_val_list(v, n, s);
    case PX_SCHEMA_TYPE_VECTOR: return px_case_val_vector(v, n, s);
    default: return px_case_val_scalar(v, n, s);
  }
}

/* ------------------------------------------------------------------------ */
/* Cross-key checks */

static void px_case_run_checks(struct px_case_validator *v, struct px_case_node *n) {
  size_t i;
  if (v->fatal) return;
  if (n->kind == PX_CASE_NODE_MAP && n->schema) {
    px_schema_check_fn check = n->variant ? n->variant->check : n->schema->check;
    if (check && n->ok) {
      size_t before = v->c->errors.total;
      enum px_status st = check(v->c, v->path);
      if (st == PX_STATUS_CONFIG && v->c->errors.total == before) /* said nothing */
        px_case_verr(v, &n->key_loc, "invalid (a check failed without saying why)");
      else if (st != PX_STATUS_OK && st != PX_STATUS_CONFIG) {
        v->fatal = st;
        return;
      }
    }
    for (i = 0; i < n->n; ++i) {
      size_t old = px_case_path_key(v, n->items[i]->key, n->items[i]->key_len);
      px_case_run_checks(v, n->items[i]);
      px_case_path_pop(v, old);
    }
  } else if (n->kind == PX_CASE_NODE_SEQ && n->schema && n->schema->type == PX_SCHEMA_TYPE_LIST) {
    for (i = 0; i < n->n; ++i) {
      size_t old = px_case_path_index(v, i);
      px_case_run_checks(v, n->items[i]);
      px_case_path_pop(v, old);
    }
  }
}

enum px_status px_case_validate(struct px_case *c, struct px_case_node *raw) {
  struct px_case_validator *v = px_case_arena_alloc(&c->arena, sizeof *v);
  struct px_case_node *root;
  if (!v) return PX_STATUS_NOMEM;
  v->c = c;
  v->fatal = PX_STATUS_OK;
  if (!raw) { /* an empty file: an empty map */
    raw = px_case_node_new(&c->arena, PX_CASE_NODE_MAP);
    if (!raw) return PX_STATUS_NOMEM;
    raw->loc.origin = PX_CASE_ORIGIN_FILE;
    raw->loc.line = raw->loc.col = 1;
  }
  raw->key_loc = raw->loc;
  root = px_case_val_map(v, raw, c->schema, c->schema->keys, NULL);
  if (v->fatal) return v->fatal;
  c->root = root;
  if (root) {
    struct px_case_node *solver =
        px_case_node_member(root, PX_CASE_SOLVER_KEY, strlen(PX_CASE_SOLVER_KEY));
    if (solver && solver->schema && solver->schema->type == PX_SCHEMA_TYPE_ENUM)
      c->solver = solver->schema->choices[solver->v.index];
    c->loading = 1;
    px_case_run_checks(v, root);
    c->loading = 0;
  }
  return v->fatal;
}

enum px_status px_case_validate_default(struct px_case *c, const struct px_schema *key,
                                        const char *path) {
  struct px_case_validator *v = px_case_arena_alloc(&c->arena, sizeof *v);
  struct px_case_node parent;
  if (!v) return PX_STATUS_NOMEM;
  v->c = c;
  v->fatal = PX_STATUS_OK;
  snprintf(v->path, sizeof v->path, "%s", path);
  v->plen = strlen(v->path);
  /* px_case_fill_absent appends the key itself */
  {
    const char *dot = strrchr(v->path, '.');
    size_t keep = dot ? (size_t)(dot - v->path) : 0;
    px_case_path_pop(v, keep);
  }
  memset(&parent, 0, sizeof parent);
  parent.kind = PX_CASE_NODE_MAP;
  parent.loc.origin = PX_CASE_ORIGIN_BUILTIN;
  parent.key_loc = parent.loc;
  px_case_fill_absent(v, &parent, key);
  return v->fatal;
}
