/* Status list, context messages and labelled aligned memory. */
#include <stdint.h>
#include <string.h>

#include "px_test.h"

static void test_status_messages_come_from_one_list(void) {
  int s;
  PX_CHECK(strcmp(px_status_message(PX_STATUS_OK), "success") == 0);
  PX_CHECK(strcmp(px_status_name(PX_STATUS_NOMEM), "NOMEM") == 0);
  for (s = 0; s < PX_STATUS_COUNT_; ++s) {
    PX_CHECK(px_status_message((enum px_status)s)[0] != '\0');
    PX_CHECK(px_status_name((enum px_status)s)[0] != '\0');
  }
  PX_CHECK(strcmp(px_status_message((enum px_status)999), "unknown status") == 0);
}

static enum px_status fails_deep(struct px_context *ctx) {
  return px_context_fail(ctx, PX_STATUS_IO, "cannot open %s", "x.yaml");
}

static enum px_status propagates(struct px_context *ctx) {
  PX_TRY(fails_deep(ctx));
  return PX_STATUS_OK;
}

static void test_context_keeps_the_message_and_prefixes(void) {
  struct px_context *ctx = NULL;
  PX_CHECK(px_context_create(&ctx) == PX_STATUS_OK);
  PX_CHECK(px_context_status(ctx) == PX_STATUS_OK);
  PX_CHECK(propagates(ctx) == PX_STATUS_IO);
  PX_CHECK(strcmp(px_context_message(ctx), "cannot open x.yaml") == 0);
  px_context_prefix(ctx, "loading case %d", 3);
  PX_CHECK(strcmp(px_context_message(ctx), "loading case 3: cannot open x.yaml") == 0);
  PX_CHECK(px_context_status(ctx) == PX_STATUS_IO);
  px_context_clear(ctx);
  PX_CHECK(px_context_message(ctx)[0] == '\0');
  px_context_free(ctx);
}

struct log_capture {
  int count;
  enum px_log_level last_level;
  char last[256];
};

static void capture(void *user, enum px_log_level level, const char *message) {
  struct log_capture *c = user;
  c->count++;
  c->last_level = level;
  strncpy(c->last, message, sizeof c->last - 1);
}

static void test_log_callback_respects_level(void) {
  struct px_context *ctx = NULL;
  struct log_capture cap = {0, PX_LOG_LEVEL_ERROR, ""};
  px_context_create(&ctx);
  px_context_set_log(ctx, capture, &cap);
  px_log(ctx, PX_LOG_LEVEL_INFO, "hello %d", 42);
  PX_CHECK(cap.count == 1);
  PX_CHECK(strcmp(cap.last, "hello 42") == 0);
  px_log(ctx, PX_LOG_LEVEL_DEBUG, "hidden");
  PX_CHECK(cap.count == 1);
  px_context_set_log_level(ctx, PX_LOG_LEVEL_DEBUG);
  px_log(ctx, PX_LOG_LEVEL_DEBUG, "shown");
  PX_CHECK(cap.count == 2 && cap.last_level == PX_LOG_LEVEL_DEBUG);
  px_context_free(ctx);
}

static void test_memory_is_aligned_and_accounted_by_label(void) {
  struct px_context *ctx = NULL;
  double *a, *b;
  char *c;
  px_context_create(&ctx);
  a = px_mem_alloc(ctx, "positions", 1000 * sizeof *a);
  b = px_mem_calloc(ctx, "velocities", 333, sizeof *b);
  PX_CHECK(a && b);
  PX_CHECK(((uintptr_t)a % PX_MEM_ALIGN) == 0 && ((uintptr_t)b % PX_MEM_ALIGN) == 0);
  PX_CHECK(b[0] == 0.0 && b[332] == 0.0);
  PX_CHECK(px_mem_current(ctx, "positions") == 8000);
  PX_CHECK(px_mem_current(ctx, NULL) == 8000 + 333 * 8);
  a[999] = 7.0;
  a = px_mem_realloc(ctx, NULL, a, 2000 * sizeof *a);
  PX_CHECK(a && a[999] == 7.0);
  PX_CHECK(px_mem_current(ctx, "positions") == 16000);
  PX_CHECK(px_mem_peak(ctx, "positions") >= 16000);
  px_mem_free(ctx, a);
  px_mem_free(ctx, b);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  PX_CHECK(px_mem_peak(ctx, NULL) >= 24000);
  c = px_mem_calloc(ctx, "huge", SIZE_MAX / 2, 4);
  PX_CHECK(c == NULL && px_context_status(ctx) == PX_STATUS_NOMEM);
  px_context_free(ctx);
}

static void test_rng_is_reproducible_and_uniform(void) {
  uint64_t s1[PX_RNG_WORDS], s2[PX_RNG_WORDS];
  double sum = 0, sum2 = 0;
  int i, n = 200000;
  px_rng_seed(s1, 12345);
  px_rng_seed(s2, 12345);
  for (i = 0; i < 100; ++i) PX_CHECK(px_rng_next(s1) == px_rng_next(s2));
  for (i = 0; i < n; ++i) {
    double u = px_rng_uniform(s1);
    PX_CHECK(u >= 0.0 && u < 1.0);
    sum += u;
    sum2 += u * u;
  }
  /* mean 1/2, variance 1/12; tolerances are ~5 standard errors */
  PX_CHECK_NEAR(sum / n, 0.5, 5 * sqrt(1.0 / 12 / n));
  PX_CHECK_NEAR(sum2 / n - (sum / n) * (sum / n), 1.0 / 12, 5e-3);
}

/* A message quoting a user's file shows its control characters as '?'
 * (C0, DEL, C1 in UTF-8, bytes that are not UTF-8: a terminal would act on
 * them), keeps newlines, tabs and UTF-8 text. */
static void test_messages_show_control_characters_as_question_marks(void) {
  struct px_context *ctx = NULL;
  px_context_create(&ctx);
  px_context_fail(ctx, PX_STATUS_CONFIG,
                  "a\x1b]0;t\x07"
                  "b\x7f|\xc2\x9b"
                  "2J|\x9b|\xe9|%s|\n\t|",
                  "\xc3\xa9\xe2\x86\x92\xf0\x9f\x98\x80");
  PX_CHECK_MSG(strcmp(px_context_message(ctx),
                      "a?]0;t?b?|??2J|?|?|\xc3\xa9\xe2\x86\x92\xf0\x9f\x98\x80|\n\t|") == 0,
               "%s", px_context_message(ctx));
  px_context_prefix(ctx, "f\x1b[31m");
  PX_CHECK(strncmp(px_context_message(ctx), "f?[31m: a?]0;t", 14) == 0);
  px_context_free(ctx);
}

int main(void) {
  test_status_messages_come_from_one_list();
  test_context_keeps_the_message_and_prefixes();
  test_log_callback_respects_level();
  test_memory_is_aligned_and_accounted_by_label();
  test_rng_is_reproducible_and_uniform();
  test_messages_show_control_characters_as_question_marks();
  return px_test_report("test_core_status");
}
