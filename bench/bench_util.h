/* Small helpers shared by the benchmarks: option lists and JSON output. */
#ifndef PX_BENCH_UTIL_H
#define PX_BENCH_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/partix.h"

/* Parse "a,b,c" of positive numbers into out (at most max); returns count. */
static inline int px_bench_list(const char *s, double *out, int max) {
  int n = 0;
  while (s && *s && n < max) {
    char *end;
    const double v = strtod(s, &end);
    if (end == s || !(v > 0)) break;
    out[n++] = v;
    s = *end == ',' ? end + 1 : end;
  }
  return n;
}

/* A JSON string value (quotes and backslashes escaped, control chars dropped). */
static inline void px_bench_json_string(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; ++s) {
    if (*s == '"' || *s == '\\') fputc('\\', f);
    if ((unsigned char)*s >= 0x20) fputc(*s, f);
  }
  fputc('"', f);
}

#endif
