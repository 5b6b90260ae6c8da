/* Helpers shared by the compute tests (the backend by name, argv[1]:
 * px_test_backend of px_test.h), random data, and host <-> buffer transfers that convert double
 * data to the precision under test. */
#ifndef PX_COMPUTE_TEST_H
#define PX_COMPUTE_TEST_H

#include <stdint.h>
#include <string.h>

#include "partix/partix.h"
#include "px_test.h"

static inline double px_test_uniform(uint64_t rng[PX_RNG_WORDS], double a, double b) {
  return a + (b - a) * px_rng_uniform(rng);
}

/* Round values to the precision's element type in place (so that references
 * computed from them use exactly the stored inputs). */
static inline void px_test_round(enum px_precision p, size_t n, double *v) {
  size_t i;
  if (p == PX_PRECISION_SINGLE)
    for (i = 0; i < n; ++i) v[i] = (double)(float)v[i];
}

/* A buffer holding n values converted to the precision's type. */
static inline struct px_buffer *px_test_upload(struct px_context *ctx, struct px_backend *be,
                                               const char *label, enum px_precision p, size_t n,
                                               const double *v) {
  struct px_buffer *b = NULL;
  const size_t es = p == PX_PRECISION_SINGLE ? 4 : 8;
  size_t i;
  PX_CHECK_OK(ctx, px_buffer_create(be, label, n * es, &b));
  if (!b) exit(EXIT_FAILURE);
  if (p == PX_PRECISION_SINGLE) {
    float *f = malloc((n ? n : 1) * sizeof *f);
    for (i = 0; i < n; ++i) f[i] = (float)v[i];
    PX_CHECK_OK(ctx, px_buffer_write(b, 0, n * es, f));
    free(f);
  } else {
    PX_CHECK_OK(ctx, px_buffer_write(b, 0, n * es, v));
  }
  return b;
}

/* n values of the precision's type read back as doubles. */
static inline void px_test_download(struct px_context *ctx, struct px_buffer *b,
                                    enum px_precision p, size_t n, double *v) {
  size_t i;
  if (p == PX_PRECISION_SINGLE) {
    float *f = malloc((n ? n : 1) * sizeof *f);
    PX_CHECK_OK(ctx, px_buffer_read(b, 0, n * 4, f));
    for (i = 0; i < n; ++i) v[i] = (double)f[i];
    free(f);
  } else {
    PX_CHECK_OK(ctx, px_buffer_read(b, 0, n * 8, v));
  }
}

#endif
