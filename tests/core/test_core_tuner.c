/* The thread tuner (core/tuner.h) on a fake engine whose step costs a
 * time set per thread count, on a fake clock: it must pick the faster count, log each change
 * once, follow a machine whose load moves (the other count re-measured
 * periodically), keep a fixed count when off, and alternate exactly under
 * its test hook PX_TUNER_ALTERNATE, and put off probes of all threads while
 * the other cores are busy (a fake count of idle cores; the kernel's
 * counters parsed from a sample). */
#include <stdlib.h>
#include <string.h>

#include "core/tuner.h"
#include "partix/timer.h"
#include "px_test.h"

static int decisions;      /* log lines announcing a chosen count (info or debug) */
static int loud_decisions; /* of them, at the info level */
static int counted_quiet;  /* info lines that count the debug ones before them */
static int last_chosen;

static void count_log(void *user, enum px_log_level level, const char *msg) {
  (void)user;
  if ((level == PX_LOG_LEVEL_INFO || level == PX_LOG_LEVEL_DEBUG) &&
      strncmp(msg, "threads (fake): ", 16) == 0 && strstr(msg, " from step ")) {
    ++decisions;
    loud_decisions += level == PX_LOG_LEVEL_INFO;
    counted_quiet += level == PX_LOG_LEVEL_INFO && strstr(msg, "more changes since") != NULL;
    last_chosen = atoi(msg + 16);
  }
}

/* The fake engine's clock [s]: a step advances it by its cost, so the test
 * does not depend on the machine's load */
static double fake_now;
static double fake_clock(void) { return fake_now; }

/* Steps of the fake engine for `seconds` of fake time: a step on one thread
 * takes t1, on more t2 [s]. Returns the next step's index. */
static long run_fake(struct px_tuner *t, double seconds, double t1, double t2, long step0) {
  const double end = fake_now + seconds;
  long s = step0;
  while (fake_now < end) {
    const int th = px_tuner_begin(t);
    fake_now += th > 1 ? t2 : t1;
    px_tuner_end(t, s++);
  }
  return s;
}

static void test_picks_the_faster_and_follows_the_load(struct px_context *ctx) {
  struct px_tuner t;
  long s;
  int ok;
  decisions = 0;
  px_tuner_init(&t, ctx, "fake", 2, 1);
  t.clock = fake_clock;
  t.idle = NULL;
  PX_CHECK(px_tuner_tuning(&t));
  PX_CHECK(px_tuner_begin(&t) == 1); /* the warm-up and the first window on 1 */
  /* a busy machine: 2 threads take 3 ms a step, 1 thread 1 ms: after one
   * first (short) window on each, one thread: within 2 PX_TUNER_FIRST_S
   * and two steps */
  s = run_fake(&t, 2 * PX_TUNER_FIRST_S + 4 * 3e-3, 1e-3, 3e-3, 0);
  PX_CHECK_MSG(t.chosen == 1, "chose %d threads after the first windows (rates %g on 1, %g on 2)",
               t.chosen, t.rate[0], t.rate[1]);
  s = run_fake(&t, 1.2, 1e-3, 3e-3, s);
  PX_CHECK_MSG(t.chosen == 1, "chose %d threads (rates %g on 1, %g on 2)", t.chosen, t.rate[0],
               t.rate[1]);
  PX_CHECK(decisions == 1 && last_chosen == 1);
  /* the machine becomes free: 2 threads 1 ms, 1 thread 3 ms. Followed at
   * the next probe of 2 threads, at most 16 windows of 0.2 s later */
  ok = 0;
  {
    const double end = fake_now + 17 * PX_TUNER_WINDOW_S + 0.1;
    while (fake_now < end && !ok) {
      s = run_fake(&t, 0.01, 3e-3, 1e-3, s);
      ok = t.chosen == 2;
    }
  }
  PX_CHECK_MSG(ok, "still %d threads after the machine became free (rates %g on 1, %g on 2)",
               t.chosen, t.rate[0], t.rate[1]);
  PX_CHECK_MSG(decisions == 2 && last_chosen == 2, "%d decisions logged, last %d", decisions,
               last_chosen);
}

/* Two counts within the noise of each other: 2 threads measure 2 % faster
 * in one probe and 2 % slower in the next. The first choice stays: no
 * swap at every probe (PX_TUNER_MARGIN), over a minute of steps. */
static void test_no_swaps_within_the_noise(struct px_context *ctx) {
  struct px_tuner t;
  long s = 0;
  int k;
  decisions = 0;
  px_tuner_init(&t, ctx, "fake", 2, 1);
  t.clock = fake_clock;
  t.idle = NULL;
  for (k = 0; k < 60; ++k) s = run_fake(&t, 1.0, 1e-3, k % 2 ? 0.98e-3 : 1.02e-3, s);
  PX_CHECK_MSG(decisions == 1, "%d decisions logged in a minute of steps (rates %g on 1, %g on 2)",
               decisions, t.rate[0], t.rate[1]);
  /* a real difference still moves it: 2 threads twice as fast */
  for (k = 0; k < 10 && t.chosen != 2; ++k) s = run_fake(&t, 1.0, 1e-3, 0.5e-3, s);
  PX_CHECK_MSG(t.chosen == 2, "still %d threads with 2 threads twice as fast", t.chosen);
}

/* A much slower count is probed for a few steps, not whole windows: 2
 * threads 5x slower than 1 (a busy core) over 10 s of steps: the first
 * window on 2 threads (PX_TUNER_FIRST_S, 5 steps) is unavoidable, then
 * each of the ~4 probes costs PX_TUNER_EARLY_STEPS steps (whole windows:
 * 40 each). */
static void test_short_probes(struct px_context *ctx) {
  struct px_tuner t;
  px_tuner_init(&t, ctx, "fake", 2, 1);
  t.clock = fake_clock;
  t.idle = NULL;
  run_fake(&t, 10.0, 1e-3, 5e-3, 0);
  PX_CHECK_MSG(t.chosen == 1, "chose %d threads", t.chosen);
  PX_CHECK_MSG(t.steps_parallel <= (long)(PX_TUNER_FIRST_S / 5e-3) + 2 + 5 * 3,
               "%ld of %ld steps on 2 threads (probes not cut short)", t.steps_parallel, t.steps);
  /* and the faster count is still measured over whole windows */
  PX_CHECK_MSG(t.rate[0] > 990.0 && t.rate[0] < 1010.0, "1-thread rate %g steps/s", t.rate[0]);
}

/* Steps of the fake engine (t1, t2 as in run_fake) for `seconds` of fake
 * time on a fresh tuner t: the share of that time spent on `threads`
 * threads. */
static double share_on(struct px_tuner *t, struct px_context *ctx, double seconds, double t1,
                       double t2, int threads) {
  const double end = fake_now + seconds;
  double on = 0, total = 0;
  long s = 0;
  px_tuner_init(t, ctx, "fake", 2, 1);
  t->clock = fake_clock;
  t->idle = NULL;
  while (fake_now < end) {
    const int th = px_tuner_begin(t);
    const double cost = th > 1 ? t2 : t1;
    fake_now += cost;
    total += cost;
    if (th == threads) on += cost;
    px_tuner_end(t, s++);
  }
  return on / total;
}

/* A free machine where 2 threads run 1.9x as fast as 1 (the granular box
 * at 9801 discs): each probe of 1 thread ends after an eighth of a window,
 * not a whole one at half speed. Over 30 s of steps the steps on 1 thread
 * (the first window, then ~9 probes) take under 2 % of the time (whole
 * windows: ~6 %), 2 threads stay chosen, and the 1-thread rate is still
 * measured (within 10 %). Probes of 2 threads are not cut so. */
static void test_probes_of_a_slower_count(struct px_context *ctx) {
  struct px_tuner t;
  double share = share_on(&t, ctx, 30.0, 2e-3, 1.05e-3, 1);
  PX_CHECK_MSG(t.chosen == 2, "chose %d threads", t.chosen);
  PX_CHECK_MSG(share <= 0.02, "%.3g of the time on 1 thread (probes not cut short)", share);
  PX_CHECK_MSG(t.rate[0] > 450.0 && t.rate[0] < 550.0, "1-thread rate %g steps/s", t.rate[0]);
  /* the other way round (1 thread chosen, 2 threads at 0.6 of its rate: a
   * competing load, under which steps on all threads vary) the probes of 2
   * threads keep their whole windows: ~9 of 0.2 s in 30 s */
  share = share_on(&t, ctx, 30.0, 1e-3, 1.6e-3, 2);
  PX_CHECK_MSG(t.chosen == 1, "chose %d threads", t.chosen);
  PX_CHECK_MSG(share >= 0.04, "%.3g of the time on 2 threads: its probes were cut short", share);
}

/* A probe that costs a lot is repeated seldom: 1 thread 80 ms a step, 2
 * threads 900 ms (a vortex step whose many parallel regions each wait for a
 * thread another process pushed off its core), over 60 s of steps: the
 * steps on 2 threads (the first probe, cut after one step, and the later
 * ones, each after 20 times the last one's loss) take under 8 % of the
 * time, against about 25 % with a probe every 16 windows. And the warm-up
 * step runs on 1 thread. */
static void test_costly_probes(struct px_context *ctx) {
  struct px_tuner t;
  const double end = fake_now + 60.0;
  double on2 = 0, total = 0;
  int probes = 0, was = 1;
  long s = 0;
  px_tuner_init(&t, ctx, "fake", 2, 1);
  t.clock = fake_clock;
  t.idle = NULL;
  while (fake_now < end) {
    const int th = px_tuner_begin(&t);
    const double cost = th > 1 ? 0.9 : 0.08;
    if (s == 0) PX_CHECK_MSG(th == 1, "the warm-up step ran on %d threads", th);
    probes += th > 1 && was == 1;
    was = th;
    fake_now += cost;
    total += cost;
    if (th > 1) on2 += cost;
    px_tuner_end(&t, s++);
  }
  PX_CHECK_MSG(t.chosen == 1, "chose %d threads", t.chosen);
  PX_CHECK_MSG(on2 <= 0.08 * total, "%.3g s of %.3g s on 2 threads in %d probes", on2, total,
               probes);
  PX_CHECK_MSG(probes >= 2 && probes <= 5, "%d probes of 2 threads in 60 s", probes);
}

/* The fake idle cores beside the process, what px_tuner_idle_cores would
 * read */
static double fake_idle_cores;
static int fake_idle_looks, fake_idle_short; /* looks; the first ones "too short" (-2) */
static double fake_idle(struct px_tuner *t) {
  (void)t;
  return ++fake_idle_looks <= fake_idle_short ? -2 : fake_idle_cores;
}

static int busy_logs;
static void count_busy_log(void *user, enum px_log_level level, const char *msg) {
  count_log(user, level, msg);
  if (level == PX_LOG_LEVEL_INFO && strstr(msg, "the other cores are busy")) ++busy_logs;
}

/* The other core taken by another process (0.1 of it idle): no step runs on
 * 2 threads, which would cost 5x (each waits for a descheduled thread), in
 * the first 3 s of steps; logged once. The core freed (0.9 idle): the
 * probes, at most 16 windows of steps apart, choose the faster 2 threads. */
static void test_busy_cores_hold(struct px_context *ctx) {
  struct px_tuner t;
  long s;
  busy_logs = 0;
  px_context_set_log(ctx, count_busy_log, NULL);
  px_tuner_init(&t, ctx, "fake", 2, 1);
  t.clock = fake_clock;
  t.idle = fake_idle;
  fake_idle_cores = 0.1;
  fake_idle_looks = 0;
  s = run_fake(&t, 3.0, 1e-3, 5e-3, 0);
  PX_CHECK_MSG(t.steps_parallel == 0, "%ld of %ld steps on 2 threads beside a busy core",
               t.steps_parallel, t.steps);
  PX_CHECK_MSG(t.rate[0] > 990.0 && t.rate[0] < 1010.0, "1-thread rate %g steps/s", t.rate[0]);
  PX_CHECK_MSG(busy_logs == 1, "%d log lines on the busy cores", busy_logs);
  /* then a probe every other 16 windows of steps (one put off by a look,
   * the next measured, cut short): over 10 s two probes of 3 steps; the
   * looks not at every window (the counters, in 10 ms ticks, need the
   * longer interval) */
  s = run_fake(&t, 7.0, 1e-3, 5e-3, s);
  PX_CHECK_MSG(t.steps_parallel >= 3 && t.steps_parallel <= 2 * 3,
               "%ld steps on 2 threads in 10 s beside a busy core", t.steps_parallel);
  PX_CHECK_MSG(t.chosen == 1, "chose %d threads beside a busy core", t.chosen);
  PX_CHECK_MSG(fake_idle_looks <= 3, "the idle cores looked at %d times in 10 s of steps",
               fake_idle_looks);
  fake_idle_cores = 0.9;
  /* (two probes: the rate of 2 threads is a running mean over probes, the
   * first under the busy core) */
  s = run_fake(&t, 2 * 17 * PX_TUNER_WINDOW_S + 1.0, 1e-3, 0.55e-3, s);
  PX_CHECK_MSG(t.chosen == 2, "chose %d threads once the other core was free (rates %g, %g)",
               t.chosen, t.rate[0], t.rate[1]);
  /* more threads than cores: 8 threads on 2 cores need the 1 other core
   * idle, not 7 */
  px_tuner_init(&t, ctx, "fake", 8, 1);
  t.clock = fake_clock;
  t.idle = fake_idle;
  t.cores = 2;
  fake_idle_cores = 0.8;
  run_fake(&t, 1.0, 1e-3, 0.6e-3, 0);
  PX_CHECK_MSG(t.steps_parallel > 0 && t.chosen == 8, "8 threads on 2 cores, one idle: chose %d",
               t.chosen);
  /* on 8 cores, 0.8 idle beside this one: busy */
  px_tuner_init(&t, ctx, "fake", 8, 1);
  t.clock = fake_clock;
  t.idle = fake_idle;
  t.cores = 8;
  run_fake(&t, 1.0, 1e-3, 0.6e-3, 0);
  PX_CHECK_MSG(t.steps_parallel == 0, "8 threads on 8 cores, 0.8 idle: %ld steps on 8",
               t.steps_parallel);
  /* the first looks too short for the counters (-2): the first window goes
   * on, on 1 thread, until a look tells; here that the other core is busy */
  px_tuner_init(&t, ctx, "fake", 2, 1);
  t.clock = fake_clock;
  t.idle = fake_idle;
  fake_idle_cores = 0.1;
  fake_idle_looks = 0;
  fake_idle_short = 3;
  run_fake(&t, 1.0, 1e-3, 5e-3, 0);
  fake_idle_short = 0;
  PX_CHECK_MSG(t.steps_parallel == 0 && fake_idle_looks == 4,
               "%ld steps on 2 threads after %d looks, 3 of them too short", t.steps_parallel,
               fake_idle_looks);
  /* unknown (-1: not Linux, unreadable): the probes as before */
  px_tuner_init(&t, ctx, "fake", 2, 1);
  t.clock = fake_clock;
  t.idle = fake_idle;
  fake_idle_cores = -1;
  run_fake(&t, 1.0, 1e-3, 0.6e-3, 0);
  PX_CHECK_MSG(t.chosen == 2, "idle cores unknown: chose %d threads", t.chosen);
  px_context_set_log(ctx, count_log, NULL);
}

/* The kernel's counters: only the "cpuK" lines of the CPUs counted, idle
 * and iowait (the 4th and 5th fields) against all (the first 8). Then the
 * machine's own: -1 at the first look, then a count of idle cores within
 * those this process may use. */
static void test_stat_ticks(struct px_context *ctx) {
  static const char text[] =
      "cpu  900 0 900 9000 90 0 0 0 0 0\n"
      "cpu0 100 1 50 1000 7 2 3 4 0 0\n"
      "cpu1 200 0 20 30 0 0 0 0 0 0\n"
      "cpu2 10 0 10 5000 5 0 0 0 0 0\n"
      "intr 12345 1 2 3\n"
      "ctxt 99\n";
  const unsigned char in[3] = {1, 0, 1};
  unsigned long long sum[2] = {0, 0};
  const int n = px_tuner_stat_ticks(text, in, 3, sum);
  PX_CHECK_MSG(n == 2 && sum[0] == 1007 + 5005 && sum[1] == 1167 + 5025,
               "parsed %d CPUs, idle %llu of %llu ticks", n, sum[0], sum[1]);
  struct px_tuner t;
  px_tuner_init(&t, ctx, "fake", 2, 0); /* not tuning: no look at init */
  const double first = px_tuner_idle_cores(&t);
  PX_CHECK_MSG(first == -1, "first look: %g idle cores", first);
  const double t0 = px_time_now();
  while (px_time_now() - t0 < 0.2) { /* this thread busy */
  }
  const double idle = px_tuner_idle_cores(&t);
#if defined(__linux__)
  /* beside this thread, at most the other cores (and the counters' error) */
  PX_CHECK_MSG(t.cores >= 1 && idle >= 0 && idle <= t.cores - 1 + t.idle_err + 0.05,
               "%g of %d cores idle beside this thread (error %g)", idle, t.cores, t.idle_err);
#else
  (void)idle;
#endif
}

static void test_fixed_and_single(struct px_context *ctx) {
  struct px_tuner t;
  int k;
  px_tuner_init(&t, ctx, "fake", 4, 0); /* the user fixed 4 threads */
  PX_CHECK(!px_tuner_tuning(&t));
  for (k = 0; k < 50; ++k) {
    PX_CHECK(px_tuner_begin(&t) == 4);
    px_tuner_end(&t, k);
  }
  px_tuner_init(&t, ctx, "fake", 1, 1); /* one thread: nothing to tune */
  PX_CHECK(!px_tuner_tuning(&t) && px_tuner_begin(&t) == 1);
}

static void test_alternate_hook(struct px_context *ctx) {
  struct px_tuner t;
  int k, bad = 0;
  setenv("PX_TUNER_ALTERNATE", "3", 1);
  px_tuner_init(&t, ctx, "fake", 2, 0); /* on even with a fixed count */
  PX_CHECK(px_tuner_tuning(&t));
  for (k = 0; k < 30; ++k) {
    const int want = (k / 3) % 2 == 0 ? 2 : 1;
    if (px_tuner_begin(&t) != want) ++bad;
    px_tuner_end(&t, k);
  }
  PX_CHECK_MSG(bad == 0, "%d steps off the 2,2,2,1,1,1 pattern", bad);
  setenv("PX_TUNER_ALTERNATE", "0", 1); /* not a period: ignored */
  px_tuner_init(&t, ctx, "fake", 2, 0);
  PX_CHECK(!px_tuner_tuning(&t));
  unsetenv("PX_TUNER_ALTERNATE");
}

/* A machine whose load comes and goes every 4 s: the count follows it, but
 * a change is logged at the info level (console, run.log) at most once a
 * minute; the others at the debug level, counted in the next info line. */
static void test_changes_are_logged_once_a_minute(struct px_context *ctx) {
  struct px_tuner t;
  long s = 0;
  int k;
  const double t0 = fake_now;
  decisions = loud_decisions = counted_quiet = 0;
  px_tuner_init(&t, ctx, "fake", 2, 1);
  t.clock = fake_clock;
  t.idle = NULL;
  for (k = 0; k < 40; ++k) s = run_fake(&t, 4.0, k % 2 ? 3e-3 : 1e-3, k % 2 ? 1e-3 : 3e-3, s);
  PX_CHECK_MSG(decisions >= 10, "%d changes over 160 s of alternating load", decisions);
  PX_CHECK_MSG(loud_decisions <= 1 + (int)((fake_now - t0) / 60.0),
               "%d of %d changes logged at the info level in %g s", loud_decisions, decisions,
               fake_now - t0);
  PX_CHECK_MSG(counted_quiet >= 1, "no info line counted the changes before it");
}

int main(void) {
  struct px_context *ctx;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log(ctx, count_log, NULL);
  px_context_set_log_level(ctx, PX_LOG_LEVEL_DEBUG);
  unsetenv("PX_TUNER_ALTERNATE");
  test_fixed_and_single(ctx);
  test_alternate_hook(ctx);
  test_picks_the_faster_and_follows_the_load(ctx);
  test_short_probes(ctx);
  test_probes_of_a_slower_count(ctx);
  test_costly_probes(ctx);
  test_no_swaps_within_the_noise(ctx);
  test_busy_cores_hold(ctx);
  test_stat_ticks(ctx);
  test_changes_are_logged_once_a_minute(ctx);
  px_context_free(ctx);
  return px_test_report("test_core_tuner");
}
