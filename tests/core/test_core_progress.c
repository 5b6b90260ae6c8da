/* The progress line: content, ETA, terminal vs plain output, timers. */
#include <string.h>
#include <time.h>

#include "px_test.h"

static void sleep_ms(long ms) {
  struct timespec ts;
  ts.tv_sec = ms / 1000;
  ts.tv_nsec = (ms % 1000) * 1000000L;
  nanosleep(&ts, NULL);
}

static void test_line_shows_step_time_count_rate_and_eta(void) {
  struct px_context *ctx = NULL;
  struct px_progress *p = NULL;
  char line[256];
  FILE *sink = tmpfile();
  long step;
  px_context_create(&ctx);
  PX_CHECK_OK(ctx, px_progress_create(ctx, sink, 0, 1000, 100.0, &p));
  for (step = 1; step <= 60; ++step) {
    px_progress_update(p, step, 0.01 * (double)step, 50000);
    sleep_ms(10);
  }
  px_progress_format(p, line, sizeof line);
  PX_CHECK_MSG(strstr(line, "step 60/1000 (6.0%)") != NULL, "%s", line);
  PX_CHECK_MSG(strstr(line, "t = 0.6") != NULL, "%s", line);
  PX_CHECK_MSG(strstr(line, "N = 50000") != NULL, "%s", line);
  PX_CHECK_MSG(strstr(line, "steps/s") != NULL, "%s", line);
  /* 940 steps left at <= 100 steps/s (10 ms per step): at least 9.4 s to go */
  {
    const char *eta = strstr(line, "ETA ");
    long h = -1, m = -1, sec = -1;
    PX_CHECK_MSG(eta && sscanf(eta, "ETA %ld:%ld:%ld", &h, &m, &sec) == 3, "%s", line);
    PX_CHECK_MSG(h * 3600 + m * 60 + sec >= 9, "%s", line);
  }
  px_progress_free(p);
  fclose(sink);
  px_context_free(ctx);
}

static void test_plain_output_prints_whole_lines_without_escapes(void) {
  struct px_context *ctx = NULL;
  struct px_progress *p = NULL;
  char buf[4096];
  size_t n;
  FILE *sink = tmpfile();
  px_context_create(&ctx);
  /* plain lines every 50 ms */
  PX_CHECK_OK(ctx, px_progress_create(ctx, sink, 0, 20, 0.05, &p));
  for (long step = 1; step <= 20; ++step) {
    px_progress_update(p, step, (double)step, -1);
    sleep_ms(10);
  }
  px_progress_finish(p);
  px_progress_free(p);
  rewind(sink);
  n = fread(buf, 1, sizeof buf - 1, sink);
  buf[n] = '\0';
  PX_CHECK(strchr(buf, '\r') == NULL && strchr(buf, '\033') == NULL);
  PX_CHECK(n > 0 && buf[n - 1] == '\n');
  PX_CHECK_MSG(strstr(buf, "step 20/20 (100.0%)") != NULL, "%s", buf);
  PX_CHECK(strstr(buf, "N =") == NULL); /* count < 0 is not shown */
  fclose(sink);
  px_context_free(ctx);
}

/* No step reported (a resumed run that only writes its end-of-run
 * products): finish prints nothing, not "step 0/N". */
static void test_finish_without_steps_prints_nothing(void) {
  struct px_context *ctx = NULL;
  struct px_progress *p = NULL;
  FILE *sink = tmpfile();
  px_context_create(&ctx);
  PX_CHECK_OK(ctx, px_progress_create(ctx, sink, 0, 50, 10.0, &p));
  px_progress_finish(p);
  px_progress_free(p);
  PX_CHECK(ftell(sink) == 0);
  fclose(sink);
  px_context_free(ctx);
}

static void test_terminal_output_rewrites_one_line(void) {
  struct px_context *ctx = NULL;
  struct px_progress *p = NULL;
  char buf[4096];
  size_t n;
  FILE *sink = tmpfile();
  px_context_create(&ctx);
  PX_CHECK_OK(ctx, px_progress_create(ctx, sink, 1, 0, 0, &p));
  for (long step = 1; step <= 30; ++step) {
    px_progress_update(p, step, (double)step, 7);
    sleep_ms(10);
  }
  px_progress_finish(p);
  px_progress_free(p);
  rewind(sink);
  n = fread(buf, 1, sizeof buf - 1, sink);
  buf[n] = '\0';
  PX_CHECK(buf[0] == '\r');
  PX_CHECK(strstr(buf, "\033[K") != NULL);
  PX_CHECK(strchr(buf, '\n') == buf + n - 1);                      /* one newline, at the end */
  PX_CHECK_MSG(strstr(buf, "step 30  t = 30") != NULL, "%s", buf); /* no total: no percentage */
  fclose(sink);
  px_context_free(ctx);
}

static void test_timeset_accumulates_named_slots(void) {
  struct px_context *ctx = NULL;
  struct px_timeset *ts = NULL;
  int a, b;
  px_context_create(&ctx);
  PX_CHECK_OK(ctx, px_timeset_create(ctx, &ts));
  a = px_timeset_slot(ts, "convective");
  b = px_timeset_slot(ts, "diffusive");
  PX_CHECK(a == 0 && b == 1 && px_timeset_slot(ts, "convective") == a);
  for (int i = 0; i < 3; ++i) {
    px_timeset_start(ts, a);
    sleep_ms(20);
    px_timeset_stop(ts, a);
  }
  PX_CHECK(px_timeset_calls(ts, a) == 3 && px_timeset_calls(ts, b) == 0);
  PX_CHECK(px_timeset_total(ts, a) >= 0.059 && px_timeset_total(ts, a) < 5.0);
  PX_CHECK(strcmp(px_timeset_name(ts, b), "diffusive") == 0);
  px_timeset_reset(ts);
  PX_CHECK(px_timeset_total(ts, a) == 0.0);
  px_timeset_free(ts);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
}

int main(void) {
  test_line_shows_step_time_count_rate_and_eta();
  test_plain_output_prints_whole_lines_without_escapes();
  test_terminal_output_rewrites_one_line();
  test_finish_without_steps_prints_nothing();
  test_timeset_accumulates_named_slots();
  return px_test_report("test_core_progress");
}
