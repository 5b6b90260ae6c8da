/* YAML text -> node tree, from libfyaml's event stream. Building our own tree
 * (rather than keeping libfyaml's document) gives every node a position, lets
 * overrides and defaults carry their own origin, and bounds depth, size and
 * alias expansion against hostile input. libfyaml's diagnostics are collected
 * (never printed) and reformatted as FILE:LINE:COL messages. */
#include <libfyaml.h>
#include <stdarg.h>
#include <string.h>

#include "config/case_impl.h"
#include "partix/memory.h"

struct px_case_anchor {
  const char *name; /* arena */
  size_t len;
  struct px_case_node *node; /* borrowed (arena) */
  int open;                  /* the node is still being built */
};

struct px_case_frame {
  struct px_case_node *node;        /* MAP or SEQ being built */
  struct px_case_node *pending_key; /* MAP: the key waiting for its value */
  struct px_case_anchor *anchor;    /* this node's anchor, or NULL */
};

struct px_case_reader {
  struct px_case *c;
  int origin;
  struct px_case_frame frames[PX_CASE_MAX_DEPTH];
  size_t depth;
  struct px_case_node *root;
  int have_root;
  struct px_case_anchor *anchors; /* arena array */
  size_t nanchors, anchors_cap;
  struct px_case_loc last; /* position of the last event that had one */
  const char *text;        /* borrowed: the input */
  size_t len;
  int failed; /* -1 syntax/limit error reported, -2 no memory */
};

/* libfyaml calls this for anything it would print; errors are collected
 * separately (fy_diag_set_collect_errors), so the rest is dropped. */
static void px_case_fy_output(struct fy_diag *diag, void *user, const char *buf, size_t len) {
  (void)diag;
  (void)user;
  (void)buf;
  (void)len;
}

static void px_case_reader_error(struct px_case_reader *r, const struct px_case_loc *loc,
                                 const char *fmt, ...) PX_PRINTF(3, 4);
static void px_case_reader_error(struct px_case_reader *r, const struct px_case_loc *loc,
                                 const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  px_case_error_vadd(r->c, loc, "", fmt, ap);
  va_end(ap);
  if (!r->failed) r->failed = -1;
}

static void px_case_reader_nomem(struct px_case_reader *r) {
  if (r->c->arena.nodes >= PX_CASE_MAX_NODES) {
    px_case_reader_error(r, &r->last, "too many values in one case (more than %d)",
                         PX_CASE_MAX_NODES);
  } else {
    r->c->errors.nomem = 1;
    r->failed = -2;
  }
}

static struct px_case_anchor *px_case_anchor_find(struct px_case_reader *r, const char *name,
                                                  size_t len) {
  size_t i = r->nanchors;
  while (i-- > 0) /* the latest definition of a name wins (YAML rule) */
    if (r->anchors[i].len == len && memcmp(r->anchors[i].name, name, len) == 0)
      return &r->anchors[i];
  return NULL;
}

static struct px_case_anchor *px_case_anchor_add(struct px_case_reader *r, struct fy_token *tok,
                                                 struct px_case_node *node) {
  size_t len = 0;
  const char *name;
  struct px_case_anchor *a;
  if (!tok) return NULL;
  name = fy_token_get_text(tok, &len);
  if (!name) return NULL;
  if (r->nanchors >= PX_CASE_MAX_ANCHORS) {
    px_case_reader_error(r, &node->loc, "too many anchors (more than %d)", PX_CASE_MAX_ANCHORS);
    return NULL;
  }
  if (r->nanchors == r->anchors_cap) {
    size_t cap = r->anchors_cap ? 2 * r->anchors_cap : 8;
    struct px_case_anchor *grown = px_case_arena_alloc(&r->c->arena, cap * sizeof *grown);
    if (!grown) {
      px_case_reader_nomem(r);
      return NULL;
    }
    if (r->nanchors) memcpy(grown, r->anchors, r->nanchors * sizeof *grown);
    r->anchors = grown;
    r->anchors_cap = cap;
  }
  a = &r->anchors[r->nanchors];
  a->name = px_case_arena_strdup(&r->c->arena, name, len);
  if (!a->name) {
    px_case_reader_nomem(r);
    return NULL;
  }
  a->len = len;
  a->node = node;
  a->open = 1;
  r->nanchors++;
  return a;
}

/* Tags: the core schema's are accepted (!!str makes a string of anything);
 * application tags mean nothing to partix and are refused. */
static void px_case_apply_tag(struct px_case_reader *r, struct fy_token *tag,
                              struct px_case_node *node) {
  static const char core[] = "tag:yaml.org,2002:";
  size_t len = 0;
  const char *t;
  struct px_case_loc loc = node->loc;
  if (!tag) return;
  t = fy_token_get_text(tag, &len);
  if (!t) return;
  {
    const struct fy_mark *m = fy_token_start_mark(tag);
    if (m && r->origin == PX_CASE_ORIGIN_FILE) {
      loc.line = m->line + 1;
      loc.col = m->column + 1;
    }
  }
  if (len >= sizeof core - 1 && memcmp(t, core, sizeof core - 1) == 0) {
    if (len == sizeof core - 1 + 3 && memcmp(t + sizeof core - 1, "str", 3) == 0 &&
        node->kind != PX_CASE_NODE_MAP && node->kind != PX_CASE_NODE_SEQ) {
      node->kind = PX_CASE_NODE_SCALAR;
      node->quoted = 1;
    }
    return;
  }
  {
    char q[128];
    px_case_reader_error(r, &loc, "unsupported tag %s (partix knows only !!str)",
                         px_case_quote(q, sizeof q, t, len));
  }
}

static int px_case_is_null(const char *t, size_t len) {
  return len == 0 || (len == 1 && t[0] == '~') ||
         (len == 4 &&
          (memcmp(t, "null", 4) == 0 || memcmp(t, "Null", 4) == 0 || memcmp(t, "NULL", 4) == 0));
}

/* Hand a finished node to its parent (or make it the root). */
static void px_case_attach(struct px_case_reader *r, struct px_case_node *node) {
  struct px_case_frame *top;
  if (r->depth == 0) {
    r->root = node;
    r->have_root = 1;
    node->key_loc = node->loc;
    return;
  }
  top = &r->frames[r->depth - 1];
  if (top->node->kind == PX_CASE_NODE_SEQ) {
    node->key_loc = node->loc;
    if (px_case_node_append(&r->c->arena, top->node, node)) px_case_reader_nomem(r);
    return;
  }
  if (!top->pending_key) {
    top->pending_key = node;
    return;
  }
  if (top->pending_key->kind == PX_CASE_NODE_MAP || top->pending_key->kind == PX_CASE_NODE_SEQ) {
    px_case_reader_error(r, &top->pending_key->loc, "a key must be a plain name, not a %s",
                         top->pending_key->kind == PX_CASE_NODE_MAP ? "map" : "list");
    return;
  }
  node->key = top->pending_key->text;
  node->key_len = top->pending_key->len;
  node->key_loc = top->pending_key->loc;
  top->pending_key = NULL;
  if (px_case_node_append(&r->c->arena, top->node, node)) px_case_reader_nomem(r);
}

/* The value of the single-quoted scalar whose opening quote is at text[at]
 * (YAML 1.2 section 7.3.2: '' is a quote; a line break with the white space
 * around it folds to a space, n breaks to n - 1 newlines), into a px_mem
 * buffer owned by the caller. libfyaml 0.7.12 decodes runs of five or more
 * '' wrongly (its chunk iterator yields more quotes than it measured) and
 * leaks its chunk buffer doing so, so these scalars are decoded here, from
 * the text libfyaml has already checked. NULL if out of memory. */
static char *px_case_single_quoted(struct px_case_reader *r, size_t at, size_t *len) {
  const char *t = r->text;
  size_t n = r->len, i = at + 1, o = 0, line = 0;
  char *out = px_mem_alloc(r->c->ctx, "case scalar", n - at + 1);
  if (!out) return NULL;
  while (i < n) {
    char ch = t[i];
    if (ch == '\'') {
      if (i + 1 < n && t[i + 1] == '\'') {
        out[o++] = '\'';
        i += 2;
        continue;
      }
      break; /* the closing quote */
    }
    if (ch == '\n' || ch == '\r') {
      size_t breaks = 0;
      while (o > line && (out[o - 1] == ' ' || out[o - 1] == '\t')) --o;
      while (i < n && (t[i] == ' ' || t[i] == '\t' || t[i] == '\n' || t[i] == '\r')) {
        if (t[i] == '\n' || (t[i] == '\r' && (i + 1 >= n || t[i + 1] != '\n'))) ++breaks;
        ++i;
      }
      if (breaks == 1)
        out[o++] = ' ';
      else
        while (--breaks > 0) out[o++] = '\n';
      line = o;
      continue;
    }
    out[o++] = ch;
    ++i;
  }
  out[o] = '\0';
  *len = o;
  return out;
}

static void px_case_event(struct px_case_reader *r, struct fy_event *e) {
  struct px_case_node *node;
  const struct fy_mark *m = fy_event_start_mark(e);
  struct px_case_loc loc;
  if (m && r->origin == PX_CASE_ORIGIN_FILE) {
    r->last.line = m->line + 1;
    r->last.col = m->column + 1;
    /* the mark of an alias is its name, that of a quoted scalar its first
       character: point at the '*' or the quote instead */
    if (m->input_pos > 0 && m->input_pos <= r->len && r->last.col > 1) {
      char before = r->text[m->input_pos - 1];
      if ((e->type == FYET_ALIAS && before == '*') ||
          (e->type == FYET_SCALAR && e->scalar.value &&
           ((before == '\'' && fy_token_scalar_style(e->scalar.value) == FYSS_SINGLE_QUOTED) ||
            (before == '"' && fy_token_scalar_style(e->scalar.value) == FYSS_DOUBLE_QUOTED))))
        r->last.col--;
    }
  }
  loc = r->last; /* an empty value has no mark: it sits at its key */

  switch (e->type) {
    case FYET_DOCUMENT_START:
      if (r->have_root) {
        px_case_reader_error(r, &loc,
                             "only one YAML document is allowed in a case file "
                             "(found a second '---')");
      }
      return;
    case FYET_SCALAR: {
      size_t len = 0;
      enum fy_scalar_style style =
          e->scalar.value ? fy_token_scalar_style(e->scalar.value) : FYSS_PLAIN;
      char *decoded = NULL;
      const char *t = "";
      const struct fy_mark *vm = e->scalar.value ? fy_token_start_mark(e->scalar.value) : NULL;
      if (style == FYSS_SINGLE_QUOTED && vm && vm->input_pos > 0 && vm->input_pos <= r->len &&
          r->text[vm->input_pos - 1] == '\'') {
        decoded = px_case_single_quoted(r, vm->input_pos - 1, &len);
        if (!decoded) {
          px_case_reader_nomem(r);
          return;
        }
        t = decoded;
      } else if (e->scalar.value) {
        t = fy_token_get_text(e->scalar.value, &len);
      }
      if (!t) {
        t = "";
        len = 0;
      }
      node = px_case_node_new(&r->c->arena, PX_CASE_NODE_SCALAR);
      if (!node) {
        px_mem_free(r->c->ctx, decoded);
        px_case_reader_nomem(r);
        return;
      }
      node->loc = loc;
      node->text = px_case_arena_strdup(&r->c->arena, t, len);
      px_mem_free(r->c->ctx, decoded);
      if (!node->text) {
        px_case_reader_nomem(r);
        return;
      }
      node->len = len;
      node->quoted = style != FYSS_PLAIN;
      if (!node->quoted && px_case_is_null(t, len)) node->kind = PX_CASE_NODE_NULL;
      px_case_apply_tag(r, e->scalar.tag, node);
      if (e->scalar.anchor) {
        struct px_case_anchor *a = px_case_anchor_add(r, e->scalar.anchor, node);
        if (a) a->open = 0;
      }
      px_case_attach(r, node);
      return;
    }
    case FYET_ALIAS: {
      size_t len = 0;
      const char *name = e->alias.anchor ? fy_token_get_text(e->alias.anchor, &len) : NULL;
      struct px_case_anchor *a = name ? px_case_anchor_find(r, name, len) : NULL;
      int shown = len > 40 ? 40 : (int)len;
      if (!a) {
        px_case_reader_error(r, &loc, "unknown alias '*%.*s' (no anchor '&%.*s' before it)", shown,
                             name ? name : "", shown, name ? name : "");
        return;
      }
      if (a->open) {
        px_case_reader_error(r, &loc, "alias '*%.*s' refers to a node that contains it", shown,
                             name);
        return;
      }
      {
        /* the copy sits below the open frames: together within the limit, so
           that no tree (and no recursion over it) is deeper than that */
        int too_deep = 0;
        node = px_case_node_copy(&r->c->arena, a->node, PX_CASE_MAX_DEPTH - r->depth, &too_deep);
        if (too_deep) {
          px_case_reader_error(r, &loc, "nesting deeper than %d levels (through aliases)",
                               PX_CASE_MAX_DEPTH);
          return;
        }
        if (!node) {
          px_case_reader_nomem(r);
          return;
        }
      }
      node->loc = loc;
      node->key = NULL;
      node->key_len = 0;
      px_case_attach(r, node);
      return;
    }
    case FYET_MAPPING_START:
    case FYET_SEQUENCE_START: {
      int is_map = e->type == FYET_MAPPING_START;
      struct px_case_frame *f;
      if (r->depth >= PX_CASE_MAX_DEPTH) {
        px_case_reader_error(r, &loc, "nesting deeper than %d levels", PX_CASE_MAX_DEPTH);
        return;
      }
      node = px_case_node_new(&r->c->arena, is_map ? PX_CASE_NODE_MAP : PX_CASE_NODE_SEQ);
      if (!node) {
        px_case_reader_nomem(r);
        return;
      }
      node->loc = loc;
      f = &r->frames[r->depth++];
      f->node = node;
      f->pending_key = NULL;
      f->anchor =
          px_case_anchor_add(r, is_map ? e->mapping_start.anchor : e->sequence_start.anchor, node);
      px_case_apply_tag(r, is_map ? e->mapping_start.tag : e->sequence_start.tag, node);
      return;
    }
    case FYET_MAPPING_END:
    case FYET_SEQUENCE_END: {
      struct px_case_frame *f;
      if (r->depth == 0) return; /* cannot happen with a well-formed stream */
      f = &r->frames[--r->depth];
      if (f->anchor) f->anchor->open = 0;
      px_case_attach(r, f->node);
      return;
    }
    default: return;
  }
}

/* Offset of the first byte that is not part of valid UTF-8 (no overlong
 * forms, no surrogates, nothing past U+10FFFF), or len. */
static size_t px_case_utf8_invalid(const char *text, size_t len) {
  const unsigned char *s = (const unsigned char *)text;
  size_t i = 0;
  while (i < len) {
    unsigned char c = s[i];
    size_t n, k;
    unsigned long cp;
    if (c < 0x80) {
      ++i;
      continue;
    }
    if (c >= 0xC2 && c <= 0xDF) {
      n = 1;
      cp = c & 0x1Fu;
    } else if (c >= 0xE0 && c <= 0xEF) {
      n = 2;
      cp = c & 0x0Fu;
    } else if (c >= 0xF0 && c <= 0xF4) {
      n = 3;
      cp = c & 0x07u;
    } else {
      return i;
    }
    if (len - i <= n) return i;
    for (k = 1; k <= n; ++k) {
      if ((s[i + k] & 0xC0) != 0x80) return i;
      cp = (cp << 6) | (s[i + k] & 0x3Fu);
    }
    if ((n == 2 && cp < 0x800) || (n == 3 && (cp < 0x10000 || cp > 0x10FFFF)) ||
        (cp >= 0xD800 && cp <= 0xDFFF))
      return i;
    i += n + 1;
  }
  return len;
}

/* 1-based line and column (in characters) of byte offset `at`. */
static void px_case_text_loc(const char *text, size_t at, struct px_case_loc *loc) {
  size_t i;
  loc->line = 1;
  loc->col = 1;
  for (i = 0; i < at; ++i) {
    if (text[i] == '\n') {
      loc->line++;
      loc->col = 1;
    } else if (((unsigned char)text[i] & 0xC0) != 0x80) {
      loc->col++;
    }
  }
}

int px_case_yaml_parse(struct px_case *c, const char *text, size_t len, int origin,
                       struct px_case_node **out) {
  struct px_case_reader *r;
  struct fy_diag_cfg dcfg;
  struct fy_diag *diag;
  struct fy_parse_cfg pcfg;
  struct fy_parser *p;
  struct fy_event *e;
  const char *nul;
  size_t bad, limit;
  int result;

  *out = NULL;
  r = px_case_arena_alloc(&c->arena, sizeof *r);
  if (!r) {
    c->errors.nomem = 1;
    return -2;
  }
  r->c = c;
  r->origin = origin;
  r->text = text;
  r->len = len;
  r->last.origin = origin;
  r->last.line = origin == PX_CASE_ORIGIN_FILE ? 1 : 0;
  r->last.col = origin == PX_CASE_ORIGIN_FILE ? 1 : 0;

  /* libfyaml is fed valid UTF-8 only: besides clearer messages, some
     invalid sequences make libfyaml 0.7 loop forever (e.g. "%\xdd") */
  nul = len ? memchr(text, '\0', len) : NULL;
  limit = nul ? (size_t)(nul - text) : len;
  bad = px_case_utf8_invalid(text, limit);
  if (nul || bad < limit) {
    size_t at = bad < limit ? bad : limit;
    struct px_case_loc loc = r->last;
    if (origin == PX_CASE_ORIGIN_FILE) px_case_text_loc(text, at, &loc);
    if (bad < limit)
      px_case_reader_error(r, &loc, "invalid UTF-8 byte 0x%02X (case files are UTF-8 text)",
                           (unsigned)(unsigned char)text[at]);
    else
      px_case_reader_error(r, &loc, "the text contains a NUL byte%s",
                           origin == PX_CASE_ORIGIN_FILE ? " (is this a binary file?)" : "");
    return -1;
  }

  fy_diag_cfg_default(&dcfg);
  dcfg.fp = NULL;
  dcfg.output_fn = px_case_fy_output;
  dcfg.user = NULL;
  dcfg.colorize = false;
  diag = fy_diag_create(&dcfg);
  if (!diag) {
    c->errors.nomem = 1;
    return -2;
  }
  fy_diag_set_collect_errors(diag, true);
  memset(&pcfg, 0, sizeof pcfg);
  pcfg.flags = FYPCF_QUIET | FYPCF_DISABLE_RECYCLING;
  pcfg.diag = diag;
  p = fy_parser_create(&pcfg);
  if (!p || fy_parser_set_string(p, text, len) != 0) {
    if (p) fy_parser_destroy(p);
    fy_diag_destroy(diag);
    c->errors.nomem = 1;
    return -2;
  }

  while (!r->failed && (e = fy_parser_parse(p)) != NULL) {
    px_case_event(r, e);
    fy_parser_event_free(p, e);
  }

  if (!r->failed && (fy_parser_get_stream_error(p) || fy_diag_got_error(diag))) {
    void *it = NULL;
    struct fy_diag_error *de;
    int reported = 0;
    while ((de = fy_diag_errors_iterate(diag, &it)) != NULL) {
      struct px_case_loc loc = r->last;
      if (de->type < FYET_ERROR) continue;
      if (origin == PX_CASE_ORIGIN_FILE && de->line > 0) {
        loc.line = de->line;
        loc.col = de->column > 0 ? de->column : 1;
      }
      px_case_reader_error(r, &loc, "YAML syntax error: %s", de->msg ? de->msg : "invalid YAML");
      reported = 1;
    }
    if (!reported) px_case_reader_error(r, &r->last, "YAML syntax error");
  }
  fy_parser_destroy(p);
  fy_diag_destroy(diag);

  result = r->failed;
  if (!result) *out = r->have_root ? r->root : NULL;
  return result;
}
