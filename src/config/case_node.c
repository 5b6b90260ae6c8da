/* Node tree storage, error collection and small text helpers of case files. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "config/case_impl.h"
#include "partix/memory.h"

/* ------------------------------------------------------------------------ */
/* Arena */

#define PX_CASE_CHUNK_BYTES ((size_t)64 * 1024)
#define PX_CASE_ALIGN ((size_t)16)

struct px_case_arena_chunk {
  struct px_case_arena_chunk *next; /* owned */
  size_t used, size;                /* bytes of data */
};

static size_t px_case_chunk_header(void) {
  return (sizeof(struct px_case_arena_chunk) + PX_CASE_ALIGN - 1) & ~(PX_CASE_ALIGN - 1);
}

void *px_case_arena_alloc(struct px_case_arena *a, size_t bytes) {
  struct px_case_arena_chunk *ch = a->chunks;
  size_t need = (bytes + PX_CASE_ALIGN - 1) & ~(PX_CASE_ALIGN - 1);
  unsigned char *p;
  if (need < bytes) return NULL; /* overflow */
  if (!ch || ch->size - ch->used < need) {
    size_t size = need > PX_CASE_CHUNK_BYTES ? need : PX_CASE_CHUNK_BYTES;
    if (size > (size_t)-1 - px_case_chunk_header()) return NULL;
    ch = px_mem_alloc(a->ctx, "case", px_case_chunk_header() + size);
    if (!ch) return NULL;
    ch->used = 0;
    ch->size = size;
    if (a->chunks && need > PX_CASE_CHUNK_BYTES) {
      /* a big block: keep filling the current chunk afterwards */
      ch->next = a->chunks->next;
      a->chunks->next = ch;
    } else {
      ch->next = a->chunks;
      a->chunks = ch;
    }
  }
  p = (unsigned char *)ch + px_case_chunk_header() + ch->used;
  ch->used += need;
  memset(p, 0, need);
  return p;
}

char *px_case_arena_strdup(struct px_case_arena *a, const char *s, size_t len) {
  char *d;
  if (len == (size_t)-1) return NULL;
  d = px_case_arena_alloc(a, len + 1);
  if (!d) return NULL;
  if (len) memcpy(d, s, len);
  d[len] = '\0';
  return d;
}

void px_case_arena_free(struct px_case_arena *a) {
  struct px_case_arena_chunk *ch = a->chunks;
  while (ch) {
    struct px_case_arena_chunk *next = ch->next;
    px_mem_free(a->ctx, ch);
    ch = next;
  }
  a->chunks = NULL;
  a->nodes = 0;
}

struct px_case_node *px_case_node_new(struct px_case_arena *a, enum px_case_node_kind kind) {
  struct px_case_node *n;
  if (a->nodes >= PX_CASE_MAX_NODES) return NULL;
  n = px_case_arena_alloc(a, sizeof *n);
  if (!n) return NULL;
  a->nodes++;
  n->kind = kind;
  n->text = "";
  return n;
}

int px_case_node_append(struct px_case_arena *a, struct px_case_node *parent,
                        struct px_case_node *child) {
  if (parent->n == parent->cap) {
    size_t cap = parent->cap ? parent->cap * 2 : 4;
    struct px_case_node **items;
    if (cap > ((size_t)-1) / sizeof *items) return -1;
    /* the old array stays in the arena: amortised O(1), at most 2x memory */
    items = px_case_arena_alloc(a, cap * sizeof *items);
    if (!items) return -1;
    if (parent->n) memcpy(items, parent->items, parent->n * sizeof *items);
    parent->items = items;
    parent->cap = cap;
  }
  parent->items[parent->n++] = child;
  return 0;
}

struct px_case_node *px_case_node_copy(struct px_case_arena *a, const struct px_case_node *n,
                                       size_t max_depth, int *too_deep) {
  struct px_case_node *d;
  size_t i;
  if (max_depth == 0) {
    *too_deep = 1;
    return NULL;
  }
  d = px_case_node_new(a, n->kind);
  if (!d) return NULL;
  *d = *n;
  d->items = NULL;
  d->n = d->cap = 0;
  for (i = 0; i < n->n; ++i) {
    struct px_case_node *child = px_case_node_copy(a, n->items[i], max_depth - 1, too_deep);
    if (!child || px_case_node_append(a, d, child)) return NULL;
  }
  return d;
}

struct px_case_node *px_case_node_member(const struct px_case_node *map, const char *key,
                                         size_t len) {
  size_t i;
  if (!map || map->kind != PX_CASE_NODE_MAP) return NULL;
  for (i = 0; i < map->n; ++i) {
    const struct px_case_node *m = map->items[i];
    if (m->key_len == len && memcmp(m->key, key, len) == 0) return map->items[i];
  }
  return NULL;
}

/* ------------------------------------------------------------------------ */
/* Errors */

void px_case_error_add(struct px_case *c, const struct px_case_loc *loc, const char *path,
                       const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  px_case_error_vadd(c, loc, path, fmt, ap);
  va_end(ap);
}

void px_case_error_vadd(struct px_case *c, const struct px_case_loc *loc, const char *path,
                        const char *fmt, va_list ap) {
  char msg[1024];
  struct px_case_error *e;
  size_t plen, mlen;
  c->errors.total++;
  if (c->errors.n >= PX_CASE_MAX_ERRORS) return;
  vsnprintf(msg, sizeof msg, fmt, ap);
  plen = path ? strlen(path) : 0;
  mlen = strlen(msg);
  e = &c->errors.list[c->errors.n];
  e->text = px_case_arena_alloc(&c->arena, plen + mlen + 3);
  if (!e->text) {
    c->errors.nomem = 1;
    return;
  }
  if (plen) {
    memcpy(e->text, path, plen);
    memcpy(e->text + plen, ": ", 2);
    plen += 2;
  }
  memcpy(e->text + plen, msg, mlen + 1);
  e->loc = *loc;
  c->errors.n++;
}

/* Sort key: the file first (by position), then overrides in order, then
 * built-in defaults. */
static int px_case_loc_before(const struct px_case_loc *a, const struct px_case_loc *b) {
  long ka = a->origin == PX_CASE_ORIGIN_FILE      ? -1
            : a->origin == PX_CASE_ORIGIN_BUILTIN ? (long)1 << 30
                                                  : a->origin;
  long kb = b->origin == PX_CASE_ORIGIN_FILE      ? -1
            : b->origin == PX_CASE_ORIGIN_BUILTIN ? (long)1 << 30
                                                  : b->origin;
  if (ka != kb) return ka < kb;
  if (a->line != b->line) return a->line < b->line;
  return a->col < b->col;
}

static int px_case_loc_prefix(const struct px_case *c, const struct px_case_loc *loc, char *buf,
                              size_t size) {
  if (loc->origin >= 0 && (size_t)loc->origin < c->noverrides)
    return snprintf(buf, size, "--set %s: ", c->overrides[loc->origin]);
  if (loc->origin == PX_CASE_ORIGIN_BUILTIN)
    return snprintf(buf, size, "%s: (built-in default) ", c->file);
  if (loc->line > 0) return snprintf(buf, size, "%s:%d:%d: ", c->file, loc->line, loc->col);
  return snprintf(buf, size, "%s: ", c->file);
}

enum px_status px_case_errors_commit(struct px_case *c) {
  char msg[4000];
  size_t i, j, len = 0, shown = 0;
  struct px_case_errors *e = &c->errors;
  if (e->nomem)
    return px_context_fail(c->ctx, PX_STATUS_NOMEM, "out of memory reading %s", c->file);
  /* stable insertion sort by location */
  for (i = 1; i < e->n; ++i) {
    struct px_case_error t = e->list[i];
    j = i;
    while (j > 0 && px_case_loc_before(&t.loc, &e->list[j - 1].loc)) {
      e->list[j] = e->list[j - 1];
      --j;
    }
    e->list[j] = t;
  }
  msg[0] = '\0';
  for (i = 0; i < e->n; ++i) {
    char prefix[600];
    int np = px_case_loc_prefix(c, &e->list[i].loc, prefix, sizeof prefix);
    size_t tl = strlen(e->list[i].text);
    size_t pl = np > 0 ? (size_t)np : 0;
    if (pl >= sizeof prefix) pl = sizeof prefix - 1;
    /* keep room for the "more errors" line */
    if (len + (len ? 1 : 0) + pl + tl + 64 >= sizeof msg) break;
    if (len) msg[len++] = '\n';
    memcpy(msg + len, prefix, pl);
    len += pl;
    memcpy(msg + len, e->list[i].text, tl);
    len += tl;
    msg[len] = '\0';
    shown++;
  }
  if (e->total > shown)
    snprintf(msg + len, sizeof msg - len, "%s(%zu more error%s not shown)", len ? "\n" : "",
             e->total - shown, e->total - shown == 1 ? "" : "s");
  return px_context_fail(c->ctx, PX_STATUS_CONFIG, "%s", msg);
}

/* ------------------------------------------------------------------------ */
/* Text helpers */

const char *px_case_quote(char *buf, size_t size, const char *text, size_t len) {
  const size_t max_shown = 40;
  size_t i, o = 0;
  if (size < 16) {
    if (size) buf[0] = '\0';
    return buf;
  }
  buf[o++] = '\'';
  for (i = 0; i < len; ++i) {
    unsigned char ch = (unsigned char)text[i];
    /* room for the longest escape, "...", the quote and the NUL */
    if (o + 10 > size || (i >= max_shown && (ch & 0xC0) != 0x80)) {
      memcpy(buf + o, "...", 3);
      o += 3;
      break;
    }
    if (ch == '\\' || ch == '\'') {
      buf[o++] = '\\';
      buf[o++] = (char)ch;
    } else if (ch == '\n') {
      buf[o++] = '\\';
      buf[o++] = 'n';
    } else if (ch == '\t') {
      buf[o++] = '\\';
      buf[o++] = 't';
    } else if (ch < 0x20 || ch == 0x7F) {
      o += (size_t)snprintf(buf + o, size - o, "\\x%02X", ch);
    } else {
      buf[o++] = (char)ch;
    }
  }
  buf[o++] = '\'';
  buf[o] = '\0';
  return buf;
}

static int px_case_name_char(char ch) {
  return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
         ch == '_' || ch == '-';
}

size_t px_case_path_parse(const char *path, size_t plen, struct px_case_seg *segs, size_t max) {
  size_t i = 0, n = 0;
  if (!path || plen == 0) return 0;
  for (;;) {
    size_t start = i;
    if (n >= max) return 0;
    while (i < plen && px_case_name_char(path[i])) ++i;
    if (i == start) return 0; /* a key must follow the start or a '.' */
    segs[n].name = path + start;
    segs[n].len = i - start;
    segs[n].index = 0;
    ++n;
    while (i < plen && path[i] == '[') {
      size_t idx = 0, digits = 0;
      ++i;
      while (i < plen && path[i] >= '0' && path[i] <= '9') {
        if (++digits > 9) return 0;
        idx = idx * 10 + (size_t)(path[i] - '0');
        ++i;
      }
      if (!digits || i >= plen || path[i] != ']') return 0;
      ++i;
      if (n >= max) return 0;
      segs[n].name = NULL;
      segs[n].len = 0;
      segs[n].index = idx;
      ++n;
    }
    if (i == plen) return n;
    if (path[i] != '.') return 0;
    ++i;
  }
}

const char *px_case_path_join(char *buf, size_t size, const char *path, const char *key) {
  if (!size) return buf;
  if (path && path[0])
    snprintf(buf, size, "%s.%s", path, key);
  else
    snprintf(buf, size, "%s", key);
  return buf;
}

static unsigned char px_case_lower(char ch) {
  unsigned char u = (unsigned char)ch;
  return (u >= 'A' && u <= 'Z') ? (unsigned char)(u - 'A' + 'a') : u;
}

size_t px_case_edit_distance(const char *a, size_t alen, const char *b, size_t blen) {
  size_t rows[3][65]; /* rows i-2, i-1, i of the dynamic programme */
  size_t i, j;
  if (alen > 64 || blen > 64) return (size_t)-1;
  for (j = 0; j <= blen; ++j) rows[1][j] = j;
  for (i = 1; i <= alen; ++i) {
    size_t *cur = rows[(i + 1) % 3], *prev = rows[i % 3], *prev2 = rows[(i + 2) % 3];
    /* rows are rotated so that row i-1 sits at index i % 3 */
    cur[0] = i;
    for (j = 1; j <= blen; ++j) {
      size_t cost = px_case_lower(a[i - 1]) == px_case_lower(b[j - 1]) ? 0 : 1;
      size_t best = prev[j] + 1;
      if (cur[j - 1] + 1 < best) best = cur[j - 1] + 1;
      if (prev[j - 1] + cost < best) best = prev[j - 1] + cost;
      if (i > 1 && j > 1 && px_case_lower(a[i - 1]) == px_case_lower(b[j - 2]) &&
          px_case_lower(a[i - 2]) == px_case_lower(b[j - 1]) && prev2[j - 2] + 1 < best)
        best = prev2[j - 2] + 1;
      cur[j] = best;
    }
  }
  return rows[(alen + 1) % 3][blen];
}
