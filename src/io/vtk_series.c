/* ParaView .pvd series: the list of VTK files of a run and their times,
 * written whole after each entry, and read back when a run resumes. */
#include "partix/vtk.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/ioutil.h"
#include "io/vtk_impl.h"
#include "partix/file.h"
#include "partix/memory.h"

/* ---- .pvd series --------------------------------------------------------- */

struct px_vtk_entry {
  double time;
  int part;
  char *file; /* owned */
};

struct px_vtk_series {
  struct px_context *ctx;       /* borrowed */
  char *path;                   /* owned */
  struct px_vtk_entry *entries; /* owned */
  size_t n, cap;
};

static enum px_status px_vtk_series_write(struct px_vtk_series *s) {
  struct px_file *file;
  FILE *f;
  size_t i;
  PX_TRY(px_file_open(s->ctx, s->path, &file));
  f = px_file_stream(file);
  fprintf(f,
          "<?xml version=\"1.0\"?>\n"
          "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"%s\">\n"
          "  <Collection>\n",
          px_vtk_byte_order());
  for (i = 0; i < s->n; ++i) {
    fprintf(f, "    <DataSet timestep=\"%.17g\" group=\"\" part=\"%d\" file=\"", s->entries[i].time,
            s->entries[i].part);
    px_ioutil_xml_escape(f, s->entries[i].file);
    fputs("\"/>\n", f);
  }
  fputs("  </Collection>\n</VTKFile>\n", f);
  return px_file_commit(file);
}

static enum px_status px_vtk_series_push(struct px_vtk_series *s, double time, int part,
                                         const char *file) {
  char *copy;
  PX_TRY(px_vtk_grow(s->ctx, (void **)&s->entries, &s->cap, s->n + 1, sizeof *s->entries));
  copy = px_ioutil_strdup(s->ctx, "vtk series", file);
  if (!copy) return PX_STATUS_NOMEM;
  s->entries[s->n].time = time;
  s->entries[s->n].part = part;
  s->entries[s->n].file = copy;
  ++s->n;
  return PX_STATUS_OK;
}

static enum px_status px_vtk_series_new(struct px_context *ctx, const char *path,
                                        struct px_vtk_series **out) {
  struct px_vtk_series *s;
  if (!ctx || !path || !out) return PX_STATUS_INVALID;
  *out = NULL;
  s = px_mem_calloc(ctx, "vtk series", 1, sizeof *s);
  if (!s) return PX_STATUS_NOMEM;
  s->ctx = ctx;
  s->path = px_ioutil_strdup(ctx, "vtk series", path);
  if (!s->path) {
    px_mem_free(ctx, s);
    return PX_STATUS_NOMEM;
  }
  *out = s;
  return PX_STATUS_OK;
}

void px_vtk_series_close(struct px_vtk_series *s) {
  size_t i;
  if (!s) return;
  for (i = 0; i < s->n; ++i) px_mem_free(s->ctx, s->entries[i].file);
  px_mem_free(s->ctx, s->entries);
  px_mem_free(s->ctx, s->path);
  px_mem_free(s->ctx, s);
}

enum px_status px_vtk_series_open(struct px_context *ctx, const char *path,
                                  struct px_vtk_series **out) {
  enum px_status st;
  PX_TRY(px_vtk_series_new(ctx, path, out));
  st = px_vtk_series_write(*out);
  if (st != PX_STATUS_OK) {
    px_vtk_series_close(*out);
    *out = NULL;
  }
  return st;
}

/* Decode the XML entities we write (and numeric ones) in place. */
static void px_vtk_xml_unescape(char *s) {
  static const struct {
    const char *ent;
    char c;
  } ents[] = {{"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
  char *r = s, *w = s;
  while (*r) {
    size_t k;
    int done = 0;
    if (*r == '&') {
      for (k = 0; k < sizeof ents / sizeof ents[0]; ++k) {
        size_t len = strlen(ents[k].ent);
        if (strncmp(r, ents[k].ent, len) == 0) {
          *w++ = ents[k].c;
          r += len;
          done = 1;
          break;
        }
      }
    }
    if (!done) *w++ = *r++;
  }
  *w = '\0';
}

/* `name` next to the file `path` (in the same folder) into buf; 0 if it does
 * not fit. */
static int px_vtk_sibling(const char *path, const char *name, char *buf, size_t size) {
  const char *slash = strrchr(path, '/');
  int n = slash ? snprintf(buf, size, "%.*s/%s", (int)(slash - path), path, name)
                : snprintf(buf, size, "%s", name);
  return n > 0 && (size_t)n < size;
}

/* Parse the attributes of the element starting at *p (just after its name)
 * up to '/>' or '>'. Fills timestep/part/file; returns 0 on a syntax error. */
static int px_vtk_parse_dataset(char **p, double *time, int *part, char **file, int *have_time) {
  char *q = *p;
  *have_time = 0;
  *part = 0;
  *file = NULL;
  for (;;) {
    char *name, *value, quote;
    size_t nlen;
    while (*q == ' ' || *q == '\t' || *q == '\n' || *q == '\r') ++q;
    if (q[0] == '/' && q[1] == '>') {
      *p = q + 2;
      return 1;
    }
    if (q[0] == '>') {
      *p = q + 1;
      return 1;
    }
    name = q;
    while ((*q >= 'a' && *q <= 'z') || (*q >= 'A' && *q <= 'Z') || *q == '_' || *q == '-' ||
           *q == ':' || (*q >= '0' && *q <= '9'))
      ++q;
    nlen = (size_t)(q - name);
    if (!nlen) return 0;
    while (*q == ' ' || *q == '\t') ++q;
    if (*q != '=') return 0;
    ++q;
    while (*q == ' ' || *q == '\t') ++q;
    quote = *q;
    if (quote != '"' && quote != '\'') return 0;
    value = ++q;
    while (*q && *q != quote) ++q;
    if (!*q) return 0;
    *q++ = '\0';
    if (nlen == 8 && strncmp(name, "timestep", 8) == 0) {
      char *end;
      *time = strtod(value, &end);
      if (end == value) return 0;
      *have_time = 1;
    } else if (nlen == 4 && strncmp(name, "part", 4) == 0) {
      *part = atoi(value);
    } else if (nlen == 4 && strncmp(name, "file", 4) == 0) {
      px_vtk_xml_unescape(value);
      *file = value;
    }
  }
}

enum px_status px_vtk_series_open_resume(struct px_context *ctx, const char *path, double t_resume,
                                         struct px_vtk_series **out) {
  struct px_vtk_series *s;
  char *text = NULL, *p;
  enum px_status st;
  size_t len;
  PX_TRY(px_vtk_series_new(ctx, path, &s));
  st = px_ioutil_read_file(ctx, path, &text, &len);
  if (st == PX_STATUS_NOT_FOUND) {
    px_context_clear(ctx);
    st = PX_STATUS_OK;
  } else if (st == PX_STATUS_OK) {
    if (!strstr(text, "<VTKFile") || !strstr(text, "type=\"Collection\"")) {
      st =
          px_context_fail(ctx, PX_STATUS_FORMAT,
                          "%s is not a VTK collection (.pvd) file; cannot resume its series", path);
    }
    p = text;
    while (st == PX_STATUS_OK && (p = strstr(p, "<DataSet")) != NULL) {
      size_t at = (size_t)(p - text);
      double t = 0.0;
      int part = 0, have_time = 0;
      char *file = NULL;
      p += 8;
      if (!px_vtk_parse_dataset(&p, &t, &part, &file, &have_time) || !have_time || !file) {
        st = px_context_fail(ctx, PX_STATUS_FORMAT,
                             "%s: byte %zu: a <DataSet> element needs timestep=\"..\" and "
                             "file=\"..\" attributes",
                             path, at);
        break;
      }
      if (t <= t_resume) {
        st = px_vtk_series_push(s, t, part, file);
      } else if (!strchr(file, '/') && !strchr(file, '\\') && strcmp(file, ".") != 0 &&
                 strcmp(file, "..") != 0) {
        /* The dropped entry's file belongs to the continuation being
         * replaced (an uninterrupted run would not have it, or will write it
         * again): delete it. Only plain names next to the .pvd. */
        char dropped[4096];
        if (px_vtk_sibling(path, file, dropped, sizeof dropped)) remove(dropped);
      }
    }
  }
  px_mem_free(ctx, text);
  if (st == PX_STATUS_OK) st = px_vtk_series_write(s);
  if (st != PX_STATUS_OK) {
    px_vtk_series_close(s);
    return st;
  }
  *out = s;
  return PX_STATUS_OK;
}

enum px_status px_vtk_series_add_part(struct px_vtk_series *s, double time, int part,
                                      const char *file) {
  if (!s || !file || !file[0]) return PX_STATUS_INVALID;
  if (!isfinite(time))
    return px_context_fail(s->ctx, PX_STATUS_INVALID, "%s: time %g of %s is not finite", s->path,
                           time, file);
  PX_TRY(px_vtk_series_push(s, time, part, file));
  if (px_vtk_series_write(s) != PX_STATUS_OK) {
    /* Keep memory equal to the file on disk (which still has the old list). */
    --s->n;
    px_mem_free(s->ctx, s->entries[s->n].file);
    return px_context_status(s->ctx);
  }
  return PX_STATUS_OK;
}

enum px_status px_vtk_series_add(struct px_vtk_series *s, double time, const char *file) {
  return px_vtk_series_add_part(s, time, 0, file);
}

size_t px_vtk_series_count(const struct px_vtk_series *s) { return s ? s->n : 0; }

double px_vtk_series_time(const struct px_vtk_series *s, size_t i) {
  return s && i < s->n ? s->entries[i].time : NAN;
}

const char *px_vtk_series_file(const struct px_vtk_series *s, size_t i) {
  return s && i < s->n ? s->entries[i].file : NULL;
}
