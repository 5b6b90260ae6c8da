/* Text built piece by piece in px_mem memory, and numbers written so that
 * they read back exactly (internal; not installed). Used by the resolved
 * case (config/case_emit.c) and the run summary (solvers/summary.c). */
#ifndef PX_CORE_TEXT_H
#define PX_CORE_TEXT_H

#include <stddef.h>
#include <stdint.h>

#include "partix/context.h"

/* A growable NUL-terminated text. Zero-initialise, set ctx (and a label for
 * the memory accounting); p is px_mem memory owned by whoever takes it. An
 * allocation failure sets nomem and makes every later put a no-op. */
struct px_text {
  struct px_context *ctx; /* borrowed */
  const char *label;      /* static; NULL: "text" */
  char *p;                /* px_mem, owned */
  size_t len, cap;
  int nomem;
};

void px_text_put(struct px_text *t, const char *s, size_t n);
void px_text_puts(struct px_text *t, const char *s);

/* x in the shortest %g form that reads back as the same double; a whole
 * number below 1e9 as one ("150", not "1.5e+02"), a larger one when that is
 * not longer than the exponent form ("2.1e+11" stays). `buf` holds 40
 * bytes; returns buf, or "nan" / "inf" / "-inf". */
const char *px_text_real(double x, char buf[40]);

/* A byte count for people: "812 MB", "8.1 TB" (powers of 1000), or with
 * binary set "24 GiB" (powers of 1024, as systems report memory); 3
 * significant digits at most below 10 units. Returns buf. */
const char *px_text_bytes(double bytes, int binary, char *buf, size_t size);

/* 64-bit FNV-1a over n bytes more, from h (PX_FNV1A_OFFSET, its offset
 * basis, to start): the hashes of a resolved case, an input file, a
 * sweep's or part3d's fingerprints. */
#define PX_FNV1A_OFFSET 14695981039346656037ULL
uint64_t px_text_fnv1a(uint64_t h, const void *data, size_t n);

#endif
