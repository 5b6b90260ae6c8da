/* Minimal test harness for partix tests: checks count failures, print where
 * they happened and what the values were, and main() returns the verdict.
 * Exit code 77 means "skipped" (ctest SKIP_RETURN_CODE). */
#ifndef PX_TEST_H
#define PX_TEST_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/partix.h"

static int px_test_failures = 0;
static int px_test_checks = 0;

#define PX_TEST_SKIP 77

#define PX_CHECK(cond)                                                         \
  do {                                                                         \
    ++px_test_checks;                                                          \
    if (!(cond)) {                                                             \
      ++px_test_failures;                                                      \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
    }                                                                          \
  } while (0)

#define PX_CHECK_MSG(cond, ...)                                                \
  do {                                                                         \
    ++px_test_checks;                                                          \
    if (!(cond)) {                                                             \
      ++px_test_failures;                                                      \
      fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__, __LINE__, #cond); \
      fprintf(stderr, __VA_ARGS__);                                            \
      fputc('\n', stderr);                                                     \
    }                                                                          \
  } while (0)

/* |a - b| <= tol (absolute). */
#define PX_CHECK_NEAR(a, b, tol)                                                                   \
  do {                                                                                             \
    double px_a_ = (double)(a), px_b_ = (double)(b), px_t_ = (double)(tol);                        \
    ++px_test_checks;                                                                              \
    if (!(fabs(px_a_ - px_b_) <= px_t_)) {                                                         \
      ++px_test_failures;                                                                          \
      fprintf(stderr, "%s:%d: %s = %.17g, %s = %.17g, |diff| = %.3g > %.3g\n", __FILE__, __LINE__, \
              #a, px_a_, #b, px_b_, fabs(px_a_ - px_b_), px_t_);                                   \
    }                                                                                              \
  } while (0)

/* |a - b| <= rtol * |b| (relative to the reference b). */
#define PX_CHECK_REL(a, b, rtol)                                                          \
  do {                                                                                    \
    double px_a_ = (double)(a), px_b_ = (double)(b), px_t_ = (double)(rtol);              \
    ++px_test_checks;                                                                     \
    if (!(fabs(px_a_ - px_b_) <= px_t_ * fabs(px_b_))) {                                  \
      ++px_test_failures;                                                                 \
      fprintf(stderr, "%s:%d: %s = %.17g, %s = %.17g, rel. diff %.3g > %.3g\n", __FILE__, \
              __LINE__, #a, px_a_, #b, px_b_, fabs(px_a_ - px_b_) / fabs(px_b_), px_t_);  \
    }                                                                                     \
  } while (0)

/* A partix call must succeed; prints the context's message otherwise. */
#define PX_CHECK_OK(ctx, call)                                                 \
  do {                                                                         \
    enum px_status px_s_ = (call);                                             \
    ++px_test_checks;                                                          \
    if (px_s_ != PX_STATUS_OK) {                                               \
      ++px_test_failures;                                                      \
      fprintf(stderr, "%s:%d: %s failed: %s: %s\n", __FILE__, __LINE__, #call, \
              px_status_name(px_s_), px_context_message(ctx));                 \
    }                                                                          \
  } while (0)

/* A partix call must fail with `status`. */
#define PX_CHECK_STATUS(ctx, call, status)                                                    \
  do {                                                                                        \
    enum px_status px_s_ = (call);                                                            \
    ++px_test_checks;                                                                         \
    if (px_s_ != (status)) {                                                                  \
      ++px_test_failures;                                                                     \
      fprintf(stderr, "%s:%d: %s returned %s, expected %s (%s)\n", __FILE__, __LINE__, #call, \
              px_status_name(px_s_), px_status_name(status), px_context_message(ctx));        \
    }                                                                                         \
  } while (0)

static int px_test_report(const char *name) {
  if (px_test_failures)
    fprintf(stderr, "%s: %d of %d checks FAILED\n", name, px_test_failures, px_test_checks);
  else
    printf("%s: all %d checks passed\n", name, px_test_checks);
  return px_test_failures ? EXIT_FAILURE : EXIT_SUCCESS;
}

/* Remove a test's run folder (a plain name in the test's build folder) before
 * it runs there again: a run refuses a folder that holds another run
 * (src/solvers/sim.c), and the build folder keeps the last test's runs. */
static inline void px_test_fresh_dir(const char *dir) {
  char cmd[512];
  if (!dir[0] || strchr(dir, '\'') || strstr(dir, "..") || dir[0] == '/') return;
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  if (system(cmd) != 0) fprintf(stderr, "px_test_fresh_dir: cannot remove %s\n", dir);
}

/* px_test_fresh_dir of case c's output.dir: before a test runs case c anew. */
static inline void px_test_fresh_case_dir(const struct px_case *c) {
  const char *dir = NULL;
  if (c && px_case_get_string(c, "output.dir", &dir) == PX_STATUS_OK && dir) px_test_fresh_dir(dir);
}

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

#endif
