/* Triangle meshes read from STL (ASCII, binary) and OBJ files, and the
 * welding of their vertices (geo_mesh.h). */
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/geometry/geo_mesh.h"
#include "partix/memory.h"

#define LABEL "mesh"

/* A triangle soup: raw vertices (3 per STL facet, the v lines of an OBJ)
 * and triangles indexing them, with their lines or offsets. */
struct soup {
  double *xyz;
  size_t nv, capv;
  size_t *tri;
  long *where;
  size_t nt, capt, capw;
};

/* p with room for need elements (p itself, or moved); NULL when out of
 * memory (p still valid, *cap unchanged). */
static void *grow(struct px_context *ctx, void *p, size_t *cap, size_t need, size_t elem) {
  if (need <= *cap) return p;
  size_t c = *cap ? *cap : 256;
  while (c < need) c *= 2;
  void *q = px_mem_realloc(ctx, LABEL, p, c * elem);
  if (q) *cap = c;
  return q;
}

static enum px_status soup_vertex(struct px_context *ctx, struct soup *s, const double p[3]) {
  double *x = grow(ctx, s->xyz, &s->capv, 3 * (s->nv + 1), sizeof(double));
  if (!x) return PX_STATUS_NOMEM;
  s->xyz = x;
  memcpy(s->xyz + 3 * s->nv++, p, 3 * sizeof(double));
  return PX_STATUS_OK;
}

static enum px_status soup_triangle(struct px_context *ctx, struct soup *s, const char *name,
                                    size_t a, size_t b, size_t c, long where) {
  if (s->nt >= PX_GEO_MESH_MAX_TRIANGLES)
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: more than %d triangles (the limit)", name,
                           PX_GEO_MESH_MAX_TRIANGLES);
  size_t *tri = grow(ctx, s->tri, &s->capt, 3 * (s->nt + 1), sizeof(size_t));
  if (!tri) return PX_STATUS_NOMEM;
  s->tri = tri;
  long *w = grow(ctx, s->where, &s->capw, s->nt + 1, sizeof(long));
  if (!w) return PX_STATUS_NOMEM;
  s->where = w;
  s->tri[3 * s->nt] = a;
  s->tri[3 * s->nt + 1] = b;
  s->tri[3 * s->nt + 2] = c;
  s->where[s->nt++] = where;
  return PX_STATUS_OK;
}

static void soup_free(struct px_context *ctx, struct soup *s) {
  px_mem_free(ctx, s->xyz);
  px_mem_free(ctx, s->tri);
  px_mem_free(ctx, s->where);
  memset(s, 0, sizeof *s);
}

/* ---- welding: a hash of cells of size h over the representatives ---- */

struct weld {
  size_t cap;   /* slots, a power of two */
  int64_t *key; /* 3 per slot */
  size_t *head; /* first representative in the slot's cell, SIZE_MAX: empty */
  size_t *next; /* per welded vertex: next representative in its cell */
};

static size_t weld_slot(const struct weld *w, const int64_t k[3]) {
  uint64_t h = 1469598103934665603ull;
  for (int i = 0; i < 3; ++i) h = (h ^ (uint64_t)k[i]) * 1099511628211ull;
  size_t s = (size_t)(h ^ (h >> 29)) & (w->cap - 1);
  while (w->head[s] != SIZE_MAX && memcmp(w->key + 3 * s, k, 3 * sizeof(int64_t)) != 0)
    s = (s + 1) & (w->cap - 1);
  return s;
}

/* Cell of p: exact bit patterns when h == 0, else floor(p / h). */
static void weld_cell(const double p[3], double h, int64_t k[3]) {
  for (int i = 0; i < 3; ++i) {
    if (h > 0) {
      k[i] = (int64_t)floor(p[i] / h);
    } else {
      double x = p[i] == 0 ? 0.0 : p[i]; /* -0 and +0 are the same point */
      memcpy(&k[i], &x, sizeof x);
    }
  }
}

/* Representative of p within tol among those already placed, or SIZE_MAX. */
static size_t weld_find(const struct weld *w, const double *out, const double p[3], double h,
                        double tol) {
  int64_t k[3], c[3];
  weld_cell(p, h, k);
  const int r = h > 0 ? 1 : 0;
  for (int dx = -r; dx <= r; ++dx)
    for (int dy = -r; dy <= r; ++dy)
      for (int dz = -r; dz <= r; ++dz) {
        c[0] = k[0] + dx;
        c[1] = k[1] + dy;
        c[2] = k[2] + dz;
        for (size_t j = w->head[weld_slot(w, c)]; j != SIZE_MAX; j = w->next[j]) {
          const double *q = out + 3 * j;
          const double d2 = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                            (p[2] - q[2]) * (p[2] - q[2]);
          if (d2 <= tol * tol) return j;
        }
      }
  return SIZE_MAX;
}

/* Moves the soup into m, welding its vertices and dropping the triangles
 * whose corners merged. */
static enum px_status weld_soup(struct px_context *ctx, struct soup *s, double tol,
                                struct px_geo_mesh *m) {
  double maxabs = 0;
  for (size_t i = 0; i < 3 * s->nv; ++i) maxabs = fmax(maxabs, fabs(s->xyz[i]));
  /* cells no smaller than 1e-12 of the extent keep floor(p / h) within int64 */
  const double h = tol > 0 ? fmax(tol, 1e-12 * maxabs) : 0;
  struct weld w = {0};
  size_t *map = px_mem_alloc(ctx, LABEL, (s->nv + 1) * sizeof *map);
  w.cap = 16;
  while (w.cap < 2 * s->nv) w.cap *= 2;
  w.key = px_mem_alloc(ctx, LABEL, 3 * w.cap * sizeof *w.key);
  w.head = px_mem_alloc(ctx, LABEL, w.cap * sizeof *w.head);
  w.next = px_mem_alloc(ctx, LABEL, (s->nv + 1) * sizeof *w.next);
  m->xyz = px_mem_alloc(ctx, LABEL, (3 * s->nv + 1) * sizeof(double));
  enum px_status st = PX_STATUS_OK;
  if (!map || !w.key || !w.head || !w.next || !m->xyz) st = PX_STATUS_NOMEM;
  for (size_t i = 0; st == PX_STATUS_OK && i < w.cap; ++i) w.head[i] = SIZE_MAX;
  for (size_t i = 0; st == PX_STATUS_OK && i < s->nv; ++i) {
    const double *p = s->xyz + 3 * i;
    size_t j = weld_find(&w, m->xyz, p, h, tol);
    if (j == SIZE_MAX) {
      int64_t k[3];
      j = m->nv++;
      memcpy(m->xyz + 3 * j, p, 3 * sizeof(double));
      weld_cell(p, h, k);
      const size_t slot = weld_slot(&w, k);
      memcpy(w.key + 3 * slot, k, sizeof k);
      w.next[j] = w.head[slot];
      w.head[slot] = j;
    }
    map[i] = j;
  }
  size_t nt = 0;
  for (size_t t = 0; st == PX_STATUS_OK && t < s->nt; ++t) {
    const size_t a = map[s->tri[3 * t]], b = map[s->tri[3 * t + 1]], c = map[s->tri[3 * t + 2]];
    if (a == b || b == c || c == a) {
      m->degenerate++;
      continue;
    }
    s->tri[3 * nt] = a;
    s->tri[3 * nt + 1] = b;
    s->tri[3 * nt + 2] = c;
    s->where[nt++] = s->where[t];
  }
  px_mem_free(ctx, map);
  px_mem_free(ctx, w.key);
  px_mem_free(ctx, w.head);
  px_mem_free(ctx, w.next);
  if (st != PX_STATUS_OK) return st;
  m->nt = nt;
  m->tri = s->tri;
  m->where = s->where;
  s->tri = NULL;
  s->where = NULL;
  return PX_STATUS_OK;
}

/* ---- text: tokens with their lines ---- */

struct text {
  const char *p, *end;
  long line;
  const char *name;
};

/* Next whitespace-separated token on the current line into buf
 * (NUL-terminated; one too long for buf is cut and ends in "...", so that
 * it matches no keyword and parses as no number); 0 at the end of the line
 * or the text. */
static int token(struct text *t, char *buf, size_t size) {
  while (t->p < t->end && (*t->p == ' ' || *t->p == '\t' || *t->p == '\r')) ++t->p;
  const char *s = t->p;
  while (t->p < t->end && !isspace((unsigned char)*t->p)) ++t->p;
  size_t n = (size_t)(t->p - s);
  if (n < size) {
    memcpy(buf, s, n);
    buf[n] = 0;
  } else {
    memcpy(buf, s, size - 4);
    memcpy(buf + size - 4, "...", 4);
  }
  return n > 0;
}

/* Skips to the start of the next line; 0 at the end of the text. */
static int next_line(struct text *t) {
  while (t->p < t->end && *t->p != '\n') ++t->p;
  if (t->p >= t->end) return 0;
  ++t->p;
  if (t->p >= t->end) return 0; /* a final newline starts no line */
  ++t->line;
  return 1;
}

/* Next token, across lines; 0 at the end of the text. */
static int token_any(struct text *t, char *buf, size_t size) {
  for (;;) {
    if (token(t, buf, size)) return 1;
    if (!next_line(t)) return 0;
  }
}

static int parse_coord(const char *s, double *x) {
  char *e;
  errno = 0;
  *x = strtod(s, &e);
  return e != s && !*e && isfinite(*x) && fabs(*x) <= PX_GEO_MESH_MAX_COORD;
}

static enum px_status bad_coord(struct px_context *ctx, const struct text *t, const char *tok) {
  return px_context_fail(ctx, PX_STATUS_FORMAT,
                         "%s:%ld: '%s' is not a coordinate (a finite number within +-%g)", t->name,
                         t->line, tok, PX_GEO_MESH_MAX_COORD);
}

/* "facet normal nx ny nz / outer loop / vertex x y z (3x) / endloop /
 * endfacet", after "facet" was read. */
static enum px_status stl_facet(struct px_context *ctx, struct text *t, struct soup *s) {
  char tok[64];
  const long line = t->line;
  static const char *const words[] = {"normal", "", "", "", "outer", "loop"};
  for (int i = 0; i < 6; ++i) {
    if (!token_any(t, tok, sizeof tok))
      return px_context_fail(ctx, PX_STATUS_FORMAT, "%s:%ld: the file ends inside a facet", t->name,
                             t->line);
    double x;
    if (words[i][0] ? strcmp(tok, words[i]) != 0 : !parse_coord(tok, &x))
      return px_context_fail(ctx, PX_STATUS_FORMAT, "%s:%ld: expected %s in a facet, found '%s'",
                             t->name, t->line, words[i][0] ? words[i] : "a normal component", tok);
  }
  for (int k = 0; k < 3; ++k) {
    double p[3];
    if (!token_any(t, tok, sizeof tok)) tok[0] = 0;
    if (strcmp(tok, "vertex") != 0)
      return px_context_fail(ctx, PX_STATUS_FORMAT,
                             "%s:%ld: expected vertex %d of 3 of a facet, found '%s'", t->name,
                             t->line, k + 1, tok[0] ? tok : "the end of the file");
    for (int i = 0; i < 3; ++i)
      if (!token(t, tok, sizeof tok)) {
        return px_context_fail(ctx, PX_STATUS_FORMAT,
                               "%s:%ld: a vertex needs 3 coordinates, found %d", t->name, t->line,
                               i);
      } else if (!parse_coord(tok, &p[i])) {
        return bad_coord(ctx, t, tok);
      }
    PX_TRY(soup_vertex(ctx, s, p));
  }
  if (!token_any(t, tok, sizeof tok) || strcmp(tok, "endloop") != 0)
    return px_context_fail(ctx, PX_STATUS_FORMAT,
                           "%s:%ld: expected endloop after 3 vertices (a facet is a triangle)",
                           t->name, t->line);
  if (!token_any(t, tok, sizeof tok) || strcmp(tok, "endfacet") != 0)
    return px_context_fail(ctx, PX_STATUS_FORMAT, "%s:%ld: expected endfacet", t->name, t->line);
  return soup_triangle(ctx, s, t->name, s->nv - 3, s->nv - 2, s->nv - 1, line);
}

static enum px_status parse_stl_ascii(struct px_context *ctx, struct text *t, struct soup *s) {
  char tok[64];
  int in_solid = 0, solids = 0;
  while (token_any(t, tok, sizeof tok)) {
    if (!in_solid && strcmp(tok, "solid") == 0) {
      in_solid = 1;
      ++solids;
      if (!next_line(t)) break; /* the name, if any, is the rest of the line */
    } else if (in_solid && strcmp(tok, "facet") == 0) {
      PX_TRY(stl_facet(ctx, t, s));
    } else if (in_solid && strcmp(tok, "endsolid") == 0) {
      in_solid = 0;
      if (!next_line(t)) break;
    } else {
      return px_context_fail(ctx, PX_STATUS_FORMAT, "%s:%ld: expected %s, found '%s'", t->name,
                             t->line, in_solid ? "facet or endsolid" : "solid", tok);
    }
  }
  if (in_solid)
    return px_context_fail(ctx, PX_STATUS_FORMAT, "%s:%ld: the file ends without endsolid", t->name,
                           t->line);
  if (!solids)
    return px_context_fail(ctx, PX_STATUS_FORMAT, "%s: an empty file is not an STL mesh", t->name);
  return PX_STATUS_OK;
}

static float le_float(const unsigned char *b) {
  uint32_t u = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
  float f;
  memcpy(&f, &u, sizeof f);
  return f;
}

/* 80-byte header, uint32 count N, N records of 50 bytes: normal, 3
 * vertices (12 little-endian float32) and a 2-byte attribute. */
static enum px_status parse_stl_binary(struct px_context *ctx, const char *name,
                                       const unsigned char *b, size_t n, struct soup *s) {
  for (size_t i = 0; i < n; ++i) {
    const size_t off = 84 + 50 * i;
    for (int k = 0; k < 3; ++k) {
      double p[3];
      for (int c = 0; c < 3; ++c) {
        const size_t at = off + 12 + 12 * (size_t)k + 4 * (size_t)c;
        p[c] = le_float(b + at);
        if (!isfinite(p[c]) || fabs(p[c]) > PX_GEO_MESH_MAX_COORD)
          return px_context_fail(ctx, PX_STATUS_FORMAT,
                                 "%s: byte %zu (triangle %zu, vertex %d): coordinate %g is not "
                                 "a finite number within +-%g",
                                 name, at, i + 1, k + 1, p[c], PX_GEO_MESH_MAX_COORD);
      }
      PX_TRY(soup_vertex(ctx, s, p));
    }
    PX_TRY(soup_triangle(ctx, s, name, s->nv - 3, s->nv - 2, s->nv - 1, (long)off));
  }
  return PX_STATUS_OK;
}

/* Binary when the size matches the header's count; else ASCII, which must
 * start with "solid". */
static enum px_status parse_stl(struct px_context *ctx, const char *name, const char *data,
                                size_t size, struct soup *s, int *binary) {
  const unsigned char *b = (const unsigned char *)data;
  *binary = 0;
  if (size >= 84) {
    const uint64_t n =
        (uint64_t)b[80] | (uint64_t)b[81] << 8 | (uint64_t)b[82] << 16 | (uint64_t)b[83] << 24;
    if (84 + 50 * n == size) {
      *binary = 1;
      if (n > PX_GEO_MESH_MAX_TRIANGLES)
        return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: %llu triangles, more than %d", name,
                               (unsigned long long)n, PX_GEO_MESH_MAX_TRIANGLES);
      return parse_stl_binary(ctx, name, b, (size_t)n, s);
    }
  }
  size_t i = 0;
  while (i < size && isspace((unsigned char)data[i])) ++i;
  if (size - i < 5 || memcmp(data + i, "solid", 5) != 0) {
    if (size < 84)
      return px_context_fail(ctx, PX_STATUS_FORMAT,
                             "%s: not an STL file: %zu bytes, neither ASCII (starting with "
                             "'solid') nor binary (84 bytes of header at least)",
                             name, size);
    const unsigned long n = (unsigned long)b[80] | (unsigned long)b[81] << 8 |
                            (unsigned long)b[82] << 16 | (unsigned long)b[83] << 24;
    return px_context_fail(ctx, PX_STATUS_FORMAT,
                           "%s: not an STL file: not ASCII (no 'solid' at the start), and as "
                           "binary its header (byte 80) counts %lu triangles, %.0f bytes, but "
                           "the file has %zu (truncated or damaged?)",
                           name, n, 84.0 + 50.0 * (double)n, size);
  }
  struct text t = {data, data + size, 1, name};
  return parse_stl_ascii(ctx, &t, s);
}

/* OBJ: "v x y z [w]" and "f i[/t[/n]] ..." (indices 1-based, negative
 * relative to the last vertex read), polygons fan-triangulated; other
 * statements (vt, vn, g, o, s, usemtl, l, ...) do not shape the surface. */
static enum px_status parse_obj(struct px_context *ctx, const char *name, const char *data,
                                size_t size, struct soup *s) {
  struct text t = {data, data + size, 1, name};
  char tok[64];
  do {
    if (!token(&t, tok, sizeof tok) || tok[0] == '#') continue;
    if (strcmp(tok, "v") == 0) {
      double p[3];
      for (int i = 0; i < 3; ++i) {
        if (!token(&t, tok, sizeof tok))
          return px_context_fail(ctx, PX_STATUS_FORMAT,
                                 "%s:%ld: a vertex needs 3 coordinates, found %d", name, t.line, i);
        if (!parse_coord(tok, &p[i])) return bad_coord(ctx, &t, tok);
      }
      if (s->nv >= 3 * (size_t)PX_GEO_MESH_MAX_TRIANGLES)
        return px_context_fail(ctx, PX_STATUS_CONFIG, "%s:%ld: more than %d vertices", name, t.line,
                               3 * PX_GEO_MESH_MAX_TRIANGLES);
      PX_TRY(soup_vertex(ctx, s, p));
    } else if (strcmp(tok, "f") == 0) {
      size_t first = 0, prev = 0;
      int k = 0;
      while (token(&t, tok, sizeof tok)) {
        char *e;
        errno = 0;
        const long long i = strtoll(tok, &e, 10);
        size_t idx;
        if (e == tok || (*e && *e != '/') || errno || i == 0 ||
            (i > 0 ? (unsigned long long)i > s->nv : (unsigned long long)-(i + 1) >= s->nv))
          return px_context_fail(ctx, PX_STATUS_FORMAT,
                                 "%s:%ld: face corner '%s' is not the index of a vertex read so "
                                 "far (1 to %zu, or -1 to -%zu)",
                                 name, t.line, tok, s->nv, s->nv);
        idx = i > 0 ? (size_t)(i - 1) : s->nv - (size_t)(-i);
        if (k == 0) first = idx;
        if (k >= 2) PX_TRY(soup_triangle(ctx, s, name, first, prev, idx, t.line));
        prev = idx;
        ++k;
      }
      if (k < 3)
        return px_context_fail(ctx, PX_STATUS_FORMAT,
                               "%s:%ld: a face needs 3 corners at least, found %d", name, t.line,
                               k);
    }
  } while (next_line(&t));
  if (!s->nt)
    return px_context_fail(ctx, PX_STATUS_FORMAT, "%s: no face ('f' line): not an OBJ mesh", name);
  return PX_STATUS_OK;
}

enum px_status px_geo_mesh_parse(struct px_context *ctx, const char *name, const char *data,
                                 size_t size, int obj, double weld_tol, struct px_geo_mesh *out) {
  struct soup s = {0};
  memset(out, 0, sizeof *out);
  snprintf(out->source, sizeof out->source, "%s", name);
  if (!(weld_tol >= 0) || !isfinite(weld_tol))
    return px_context_fail(ctx, PX_STATUS_INVALID, "%s: weld tolerance %g is not >= 0", name,
                           weld_tol);
  enum px_status st = obj ? parse_obj(ctx, name, data, size, &s)
                          : parse_stl(ctx, name, data, size, &s, &out->binary);
  if (st == PX_STATUS_OK) st = weld_soup(ctx, &s, weld_tol, out);
  soup_free(ctx, &s);
  if (st == PX_STATUS_OK && out->nt == 0)
    st = px_context_fail(ctx, PX_STATUS_FORMAT, "%s: no triangle left after welding", name);
  if (st != PX_STATUS_OK) px_geo_mesh_free(ctx, out);
  return st;
}

enum px_status px_geo_mesh_read(struct px_context *ctx, const char *path, double weld_tol,
                                struct px_geo_mesh *out) {
  memset(out, 0, sizeof *out);
  const size_t len = strlen(path);
  int obj;
  if (len >= 4 && strcasecmp(path + len - 4, ".obj") == 0)
    obj = 1;
  else if (len >= 4 && strcasecmp(path + len - 4, ".stl") == 0)
    obj = 0;
  else
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: a part's surface is read from a .stl or .obj file", path);
  /* O_NONBLOCK: a FIFO without a writer is refused at once, not waited on */
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0)
    return px_context_fail(ctx, PX_STATUS_IO, "%s: cannot open mesh file: %s", path,
                           strerror(errno));
  struct stat sb;
  if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode) || sb.st_size > PX_GEO_MESH_MAX_BYTES) {
    const int regular = S_ISREG(sb.st_mode);
    close(fd);
    return regular
               ? px_context_fail(ctx, PX_STATUS_CONFIG,
                                 "%s: %lld bytes, more than a mesh file may hold (%ld)", path,
                                 (long long)sb.st_size, (long)PX_GEO_MESH_MAX_BYTES)
               : px_context_fail(ctx, PX_STATUS_CONFIG,
                                 "%s: not a regular file; a mesh is read from a plain file", path);
  }
  char *buf = px_mem_alloc(ctx, LABEL, (size_t)sb.st_size + 1);
  if (!buf) {
    close(fd);
    return PX_STATUS_NOMEM;
  }
  size_t got = 0;
  while (got < (size_t)sb.st_size) {
    const ssize_t r = read(fd, buf + got, (size_t)sb.st_size - got);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) break;
    got += (size_t)r;
  }
  close(fd);
  enum px_status st;
  if (got != (size_t)sb.st_size)
    st = px_context_fail(ctx, PX_STATUS_IO, "%s: cannot read mesh file (%zu of %lld bytes)", path,
                         got, (long long)sb.st_size);
  else
    st = px_geo_mesh_parse(ctx, path, buf, got, obj, weld_tol, out);
  px_mem_free(ctx, buf);
  return st;
}
