#include "io/ioutil.h"

#include <errno.h>
#include <string.h>

#include "partix/memory.h"

char *px_ioutil_strdup(struct px_context *ctx, const char *label, const char *s) {
  size_t n = strlen(s);
  char *d = px_mem_alloc(ctx, label, n + 1);
  if (d) memcpy(d, s, n + 1);
  return d;
}

void px_ioutil_xml_escape(FILE *f, const char *s) {
  const char *run = s;
  for (; *s; ++s) {
    const char *rep = NULL;
    switch (*s) {
      case '&': rep = "&amp;"; break;
      case '<': rep = "&lt;"; break;
      case '>': rep = "&gt;"; break;
      case '"': rep = "&quot;"; break;
      case '\'': rep = "&apos;"; break;
      default: break;
    }
    if (rep) {
      fwrite(run, 1, (size_t)(s - run), f);
      fputs(rep, f);
      run = s + 1;
    }
  }
  fwrite(run, 1, (size_t)(s - run), f);
}

enum px_status px_ioutil_read_file(struct px_context *ctx, const char *path, char **out,
                                   size_t *len) {
  FILE *f;
  char *buf = NULL;
  size_t cap = 0, n = 0;
  *out = NULL;
  if (len) *len = 0;
  f = fopen(path, "rb");
  if (!f) {
    int err = errno;
    return px_context_fail(ctx, err == ENOENT ? PX_STATUS_NOT_FOUND : PX_STATUS_IO,
                           "cannot open %s: %s", path, strerror(err));
  }
  for (;;) {
    size_t got;
    if (cap - n < 4096 + 1) {
      size_t ncap = cap ? 2 * cap : 65536;
      char *nb = px_mem_realloc(ctx, "io read", buf, ncap);
      if (!nb) {
        px_mem_free(ctx, buf);
        fclose(f);
        return px_context_prefix(ctx, "reading %s", path);
      }
      buf = nb;
      cap = ncap;
    }
    got = fread(buf + n, 1, cap - n - 1, f);
    n += got;
    if (got == 0) break;
  }
  if (ferror(f)) {
    int err = errno;
    px_mem_free(ctx, buf);
    fclose(f);
    return px_context_fail(ctx, PX_STATUS_IO, "cannot read %s: %s", path, strerror(err));
  }
  fclose(f);
  buf[n] = '\0';
  *out = buf;
  if (len) *len = n;
  return PX_STATUS_OK;
}

int px_ioutil_has_ext(const char *path, const char *ext) {
  size_t n = strlen(path), m = strlen(ext);
  return n > m && strcmp(path + n - m, ext) == 0;
}
