/* Case validation: scalars (booleans, integers and reals within their
 * ranges, strings and file-name strings, enums). */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/case_validate_impl.h"

/* A name that may become part of a file name: [A-Za-z0-9._-]{1,64}, not
 * "." or ".." (so never a path, never hidden-file tricks beyond a leading
 * dot, never a character a shell or a file system treats specially). */
static int px_case_file_name_ok(const char *t, size_t n) {
  size_t i;
  if (n == 0 || n > 64 || (n == 1 && t[0] == '.') || (n == 2 && t[0] == '.' && t[1] == '.'))
    return 0;
  for (i = 0; i < n; ++i) {
    char c = t[i];
    if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' ||
          c == '_' || c == '-'))
      return 0;
  }
  return 1;
}
/* ------------------------------------------------------------------------ */
/* Scalars */

int px_case_need_scalar(struct px_case_validator *v, const struct px_case_node *n,
                        const char *expected) {
  char q[200];
  if (n->kind == PX_CASE_NODE_SCALAR) return 1;
  px_case_verr(v, &n->loc, "expected %s (got %s)", expected, px_case_describe(q, sizeof q, n));
  return 0;
}

static int px_case_word_is(const char *t, size_t len, const char *w) {
  size_t i;
  if (strlen(w) != len) return 0;
  for (i = 0; i < len; ++i) {
    char ch = t[i];
    if (ch >= 'A' && ch <= 'Z') ch = (char)(ch - 'A' + 'a');
    if (ch != w[i]) return 0;
  }
  return 1;
}

/* [+-]?[0-9]+ */
static int px_case_is_int(const char *t, size_t len) {
  size_t i = 0;
  if (i < len && (t[i] == '+' || t[i] == '-')) ++i;
  if (i == len) return 0;
  for (; i < len; ++i)
    if (t[i] < '0' || t[i] > '9') return 0;
  return 1;
}

/* [+-]?(digits[.digits?]|.digits)([eE][+-]?digits)? */
static int px_case_is_real(const char *t, size_t len) {
  size_t i = 0, mant = 0;
  if (i < len && (t[i] == '+' || t[i] == '-')) ++i;
  while (i < len && t[i] >= '0' && t[i] <= '9') ++i, ++mant;
  if (i < len && t[i] == '.') {
    ++i;
    while (i < len && t[i] >= '0' && t[i] <= '9') ++i, ++mant;
  }
  if (!mant) return 0;
  if (i < len && (t[i] == 'e' || t[i] == 'E')) {
    size_t exp = 0;
    ++i;
    if (i < len && (t[i] == '+' || t[i] == '-')) ++i;
    while (i < len && t[i] >= '0' && t[i] <= '9') ++i, ++exp;
    if (!exp) return 0;
  }
  return i == len;
}

/* YAML's spellings of infinity and not-a-number. */
static int px_case_is_nonfinite(const char *t, size_t len) {
  if (len && (t[0] == '+' || t[0] == '-')) ++t, --len;
  if (len && t[0] == '.') ++t, --len;
  return px_case_word_is(t, len, "inf") || px_case_word_is(t, len, "infinity") ||
         px_case_word_is(t, len, "nan");
}

static int px_case_range_ok(const struct px_schema *s, double x) {
  if (s->lo_bound == PX_SCHEMA_BOUND_INCL && !(x >= s->lo)) return 0;
  if (s->lo_bound == PX_SCHEMA_BOUND_EXCL && !(x > s->lo)) return 0;
  if (s->hi_bound == PX_SCHEMA_BOUND_INCL && !(x <= s->hi)) return 0;
  if (s->hi_bound == PX_SCHEMA_BOUND_EXCL && !(x < s->hi)) return 0;
  return 1;
}

int px_case_check_range(struct px_case_validator *v, const struct px_case_node *n,
                        const struct px_schema *s, double x) {
  int shown = n->len > 40 ? 40 : (int)n->len;
  if (px_case_range_ok(s, x)) return 1;
  if (s->lo_bound && s->hi_bound)
    px_case_verr(v, &n->loc, "must be in %c%g, %g%c (got %.*s)",
                 s->lo_bound == PX_SCHEMA_BOUND_INCL ? '[' : '(', s->lo, s->hi,
                 s->hi_bound == PX_SCHEMA_BOUND_INCL ? ']' : ')', shown, n->text);
  else if (s->lo_bound)
    px_case_verr(v, &n->loc, "must be %s %g (got %.*s)",
                 s->lo_bound == PX_SCHEMA_BOUND_INCL ? ">=" : ">", s->lo, shown, n->text);
  else
    px_case_verr(v, &n->loc, "must be %s %g (got %.*s)",
                 s->hi_bound == PX_SCHEMA_BOUND_INCL ? "<=" : "<", s->hi, shown, n->text);
  return 0;
}

/* Parse a REAL; 1 on success (value in *x). */
int px_case_parse_real(struct px_case_validator *v, const struct px_case_node *n, double *x) {
  char q[200];
  if (!px_case_is_real(n->text, n->len)) {
    if (px_case_is_nonfinite(n->text, n->len))
      px_case_verr(v, &n->loc, "expected a finite real number (got %s)",
                   px_case_quote(q, sizeof q, n->text, n->len));
    else
      px_case_verr(v, &n->loc, "expected a real number (got %s)",
                   px_case_quote(q, sizeof q, n->text, n->len));
    return 0;
  }
  errno = 0;
  *x = strtod(n->text, NULL);
  if (!isfinite(*x)) {
    px_case_verr(v, &n->loc, "real number out of range (got %s)",
                 px_case_quote(q, sizeof q, n->text, n->len));
    return 0;
  }
  return 1;
}

struct px_case_node *px_case_val_scalar(struct px_case_validator *v, struct px_case_node *n,
                                        const struct px_schema *s) {
  char q[200];
  switch (s->type) {
    case PX_SCHEMA_TYPE_BOOL: {
      static const char *const yes[] = {"true", "yes", "on"};
      static const char *const no[] = {"false", "no", "off"};
      size_t i;
      if (!px_case_need_scalar(v, n, "true or false")) return NULL;
      for (i = 0; i < 3; ++i) {
        if (px_case_word_is(n->text, n->len, yes[i]))
          n->v.boolean = 1;
        else if (px_case_word_is(n->text, n->len, no[i]))
          n->v.boolean = 0;
        else
          continue;
        n->schema = s;
        return n;
      }
      px_case_verr(v, &n->loc, "expected true or false (got %s)",
                   px_case_quote(q, sizeof q, n->text, n->len));
      return NULL;
    }
    case PX_SCHEMA_TYPE_INT: {
      long x;
      char *end;
      if (!px_case_need_scalar(v, n, "an integer")) return NULL;
      if (!px_case_is_int(n->text, n->len)) {
        px_case_verr(v, &n->loc, "expected an integer (got %s)",
                     px_case_quote(q, sizeof q, n->text, n->len));
        return NULL;
      }
      errno = 0;
      x = strtol(n->text, &end, 10);
      if (errno == ERANGE) {
        px_case_verr(v, &n->loc, "integer out of range (got %s)",
                     px_case_quote(q, sizeof q, n->text, n->len));
        return NULL;
      }
      if (!px_case_check_range(v, n, s, (double)x)) return NULL;
      n->v.integer = x;
      n->schema = s;
      return n;
    }
    case PX_SCHEMA_TYPE_REAL: {
      double x;
      if (!px_case_need_scalar(v, n, "a real number")) return NULL;
      if (!px_case_parse_real(v, n, &x) || !px_case_check_range(v, n, s, x)) return NULL;
      n->v.real = x;
      n->schema = s;
      return n;
    }
    case PX_SCHEMA_TYPE_STRING:
      if (!px_case_need_scalar(v, n, "a string")) return NULL;
      if (memchr(n->text, '\0', n->len)) {
        px_case_verr(v, &n->loc, "a string must not contain NUL characters");
        return NULL;
      }
      if (s->file_name && !px_case_file_name_ok(n->text, n->len)) {
        px_case_verr(v, &n->loc,
                     "%s becomes part of output file names: use 1 to 64 of the characters "
                     "A-Z a-z 0-9 . _ - (got %s)",
                     s->what ? s->what : "this name", px_case_describe(q, sizeof q, n));
        return NULL;
      }
      n->schema = s;
      return n;
    case PX_SCHEMA_TYPE_ENUM: {
      char list[400], hint[128];
      const char *noun = s->what ? s->what : "value";
      struct px_case_suggest sg;
      size_t i;
      if (n->kind != PX_CASE_NODE_SCALAR) {
        px_case_verr(v, &n->loc, "expected one of: %s (got %s)",
                     px_case_list_choices(list, sizeof list, s->choices),
                     px_case_describe(q, sizeof q, n));
        return NULL;
      }
      for (i = 0; s->choices && s->choices[i]; ++i) {
        if (strlen(s->choices[i]) == n->len && memcmp(s->choices[i], n->text, n->len) == 0) {
          n->v.index = (int)i;
          n->schema = s;
          return n;
        }
      }
      if (!px_case_verbose(v)) {
        px_case_verr(v, &n->loc, "unknown %s", noun);
        return NULL;
      }
      px_case_quote(q, sizeof q, n->text, n->len);
      if (!s->choices || !s->choices[0]) {
        px_case_verr(v, &n->loc, "unknown %s %s: no %s is built into this partix (available: none)",
                     noun, q, noun);
        return NULL;
      }
      px_case_suggest_init(&sg, n->text, n->len);
      for (i = 0; s->choices[i]; ++i) px_case_suggest_try(&sg, s->choices[i]);
      px_case_verr(v, &n->loc, "unknown %s %s%s (choices: %s)", noun, q,
                   px_case_suggest_text(hint, sizeof hint, &sg),
                   px_case_list_choices(list, sizeof list, s->choices));
      return NULL;
    }
    default: return NULL;
  }
}
