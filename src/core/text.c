#include "core/text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/memory.h"

void px_text_put(struct px_text *t, const char *s, size_t n) {
  if (t->nomem) return;
  if (t->len + n + 1 > t->cap) {
    size_t cap = t->cap ? t->cap : 256;
    char *grown;
    while (cap < t->len + n + 1) cap *= 2;
    grown = px_mem_realloc(t->ctx, t->label ? t->label : "text", t->p, cap);
    if (!grown) {
      t->nomem = 1;
      return;
    }
    t->p = grown;
    t->cap = cap;
  }
  memcpy(t->p + t->len, s, n);
  t->len += n;
  t->p[t->len] = '\0';
}

void px_text_puts(struct px_text *t, const char *s) { px_text_put(t, s, strlen(s)); }

const char *px_text_real(double x, char buf[40]) {
  char whole[40];
  int prec;
  if (isnan(x)) return "nan";
  if (isinf(x)) return x > 0 ? "inf" : "-inf";
  for (prec = 1; prec <= 17; ++prec) {
    snprintf(buf, 40, "%.*g", prec, x);
    if (strtod(buf, NULL) == x) break;
  }
  if (strchr(buf, 'e') && x == floor(x) && fabs(x) < 1e17) {
    snprintf(whole, sizeof whole, "%.0f", x);
    if ((fabs(x) < 1e9 || strlen(whole) <= strlen(buf)) && strtod(whole, NULL) == x)
      memcpy(buf, whole, strlen(whole) + 1);
  }
  return buf;
}

const char *px_text_bytes(double b, int binary, char *buf, size_t size) {
  static const char *const dec[] = {"B", "kB", "MB", "GB", "TB", "PB", "EB"};
  static const char *const bin[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double unit = binary ? 1024.0 : 1000.0;
  int k = 0;
  while (b >= unit && k < 6) {
    b /= unit;
    ++k;
  }
  snprintf(buf, size, "%.*f %s", b < 10 && k ? 1 : 0, b, binary ? bin[k] : dec[k]);
  return buf;
}

uint64_t px_text_fnv1a(uint64_t h, const void *data, size_t n) {
  const unsigned char *b = data;
  for (size_t i = 0; i < n; ++i) {
    h ^= b[i];
    h *= 1099511628211ULL; /* the FNV 64-bit prime */
  }
  return h;
}
