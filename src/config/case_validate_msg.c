/* Case validation: the key path of the node being validated, error
 * messages, and "did you mean" suggestions. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/case_validate_impl.h"

/* ------------------------------------------------------------------------ */
/* Paths and messages */

size_t px_case_path_key(struct px_case_validator *v, const char *key, size_t len) {
  size_t old = v->plen, i, shown = len > 64 ? 64 : len;
  size_t room = sizeof v->path - 1;
  if (v->plen && v->plen < room) v->path[v->plen++] = '.';
  if (len == 0) key = "''", len = shown = 2; /* an empty key */
  for (i = 0; i < shown && v->plen < room; ++i) {
    char ch = key[i];
    int ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
             ch == '_' || ch == '-' || ch == '\'' || (unsigned char)ch >= 0x80;
    v->path[v->plen++] = ok ? ch : '?';
  }
  if (shown < len)
    for (i = 0; i < 3 && v->plen < room; ++i) v->path[v->plen++] = '.';
  v->path[v->plen] = '\0';
  return old;
}

size_t px_case_path_index(struct px_case_validator *v, size_t index) {
  size_t old = v->plen;
  int k = snprintf(v->path + v->plen, sizeof v->path - v->plen, "[%zu]", index);
  if (k > 0) v->plen += (size_t)k;
  if (v->plen >= sizeof v->path) v->plen = sizeof v->path - 1;
  v->path[v->plen] = '\0';
  return old;
}

void px_case_path_pop(struct px_case_validator *v, size_t old) {
  v->plen = old;
  v->path[old] = '\0';
}

void px_case_verr(struct px_case_validator *v, const struct px_case_loc *loc, const char *fmt,
                  ...) {
  va_list ap;
  va_start(ap, fmt);
  px_case_error_vadd(v->c, loc, v->path, fmt, ap);
  va_end(ap);
}

/* Errors past PX_CASE_MAX_ERRORS are only counted: skip building their text
 * (suggestions cost an edit distance per candidate). */
int px_case_verbose(const struct px_case_validator *v) {
  return v->c->errors.n < PX_CASE_MAX_ERRORS;
}

const char *px_case_describe(char *buf, size_t size, const struct px_case_node *n) {
  switch (n->kind) {
    case PX_CASE_NODE_NULL: return "null";
    case PX_CASE_NODE_MAP: return "a map";
    case PX_CASE_NODE_SEQ: return "a list";
    case PX_CASE_NODE_SCALAR: break;
  }
  return px_case_quote(buf, size, n->text, n->len);
}

void px_case_suggest_try(struct px_case_suggest *sg, const char *cand) {
  size_t clen = strlen(cand);
  size_t d = px_case_edit_distance(sg->word, sg->wlen, cand, clen);
  size_t limit = sg->wlen / 3 > 2 ? sg->wlen / 3 : 2;
  size_t longer = sg->wlen > clen ? sg->wlen : clen;
  if (d <= limit && d < longer && d < sg->dist) {
    sg->best = cand;
    sg->dist = d;
  }
}

void px_case_suggest_init(struct px_case_suggest *sg, const char *word, size_t wlen) {
  sg->word = word;
  sg->wlen = wlen;
  sg->best = NULL;
  sg->dist = (size_t)-1;
}

/* ", did you mean 'x'?" or "". */
const char *px_case_suggest_text(char *buf, size_t size, const struct px_case_suggest *sg) {
  if (!sg->best) return "";
  snprintf(buf, size, ", did you mean '%s'?", sg->best);
  return buf;
}

/* "a, b, c" (truncated) from a NULL-terminated list, or "none". */
const char *px_case_list_choices(char *buf, size_t size, const char *const *choices) {
  size_t i, len = 0;
  buf[0] = '\0';
  if (!choices || !choices[0]) {
    snprintf(buf, size, "none");
    return buf;
  }
  for (i = 0; choices[i]; ++i) {
    int k = snprintf(buf + len, size - len, "%s%s", i ? ", " : "", choices[i]);
    if (k < 0 || (size_t)k >= size - len) {
      if (size > 4) memcpy(buf + size - 4, "...", 4);
      break;
    }
    len += (size_t)k;
  }
  return buf;
}

/* The same from the names of a schema key array. */
const char *px_case_list_keys(char *buf, size_t size, const struct px_schema *keys, int with_type) {
  const char *names[PX_CASE_MAX_SECTIONS + 64];
  size_t i, n = 0;
  if (with_type) names[n++] = "type";
  for (i = 0; keys && keys[i].name && n + 1 < sizeof names / sizeof names[0]; ++i)
    names[n++] = keys[i].name;
  names[n] = NULL;
  return px_case_list_choices(buf, size, names);
}
