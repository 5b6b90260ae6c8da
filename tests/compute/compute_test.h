/* Helpers shared by the compute tests: backend by name (argv[1]), random
 * data, and host <-> buffer transfers that convert double data to the
 * precision under test. */
#ifndef PX_COMPUTE_TEST_H
#define PX_COMPUTE_TEST_H

#include <stdint.h>
#include <string.h>

#include "partix/partix.h"
#include "px_test.h"

/* The backend under test; exits 77 (skipped) when the opencl backend is
 * compiled in but this machine has no OpenCL device (genuinely absent
 * hardware), fails otherwise. */
static inline struct px_backend *px_test_backend(struct px_context *ctx, const char *name,
                                                 int threads) {
  struct px_backend *be = NULL;
  enum px_status st;
  if (strcmp(name, "opencl") == 0 && px_backend_opencl_device_count(ctx) == 0) {
    fprintf(stderr, "no OpenCL device on this machine: skipped\n");
    exit(PX_TEST_SKIP);
  }
  st = px_backend_create(ctx, name, 0, threads, &be);
  if (st != PX_STATUS_OK) {
    fprintf(stderr, "cannot create backend %s: %s: %s\n", name, px_status_name(st),
            px_context_message(ctx));
    exit(EXIT_FAILURE);
  }
  return be;
}

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
