/* The thread tuner (tuner.h). */
#define _GNU_SOURCE /* sched_getaffinity: the cores this process may use */
#include "core/tuner.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#if defined(__linux__)
#include <sched.h>
#include <unistd.h>
#endif

#include "partix/timer.h"

/* A window ends after this many steps even if shorter than
 * PX_TUNER_WINDOW_S (tiny steps: the clock would be read too often for
 * nothing) */
#define PX_TUNER_WINDOW_MAX_STEPS 100000

/* One window of every PX_TUNER_PROBE_EVERY measures the count not chosen */
#define PX_TUNER_PROBE_EVERY 16
/* [s] a change of the count is logged at the info level at most this often
 * (the others at the debug level, counted in the next info line) */
#define PX_TUNER_LOG_EVERY_S 60.0

static int px_tuner_env_alternate(void) {
  const char *v = getenv("PX_TUNER_ALTERNATE");
  char *end;
  long k;
  if (!v || !*v) return 0;
  k = strtol(v, &end, 10);
  return *end == '\0' && k >= 1 && k <= 1000000 ? (int)k : 0;
}

void px_tuner_init(struct px_tuner *t, struct px_context *ctx, const char *name, int most, int on) {
  memset(t, 0, sizeof *t);
  t->ctx = ctx;
  t->name = name ? name : "engine";
  t->most = most > 1 ? most : 1;
  t->alternate = t->most > 1 ? px_tuner_env_alternate() : 0;
  t->on = t->most > 1 && (on || t->alternate > 0);
  /* tuning: the first (untimed) step and the first window on one thread,
   * then all (a step on all threads can cost many times one on 1 when a core
   * is taken; on a free machine the first window is 25 ms) */
  t->active = t->on && t->alternate == 0 ? 1 : t->most;
  t->gap = PX_TUNER_PROBE_EVERY * PX_TUNER_WINDOW_S;
  t->logged_at = -1;
  t->clock = px_time_now;
  t->idle = px_tuner_idle_cores;
  /* the idle cores counted from here: over the warm-up step and the first
   * window, before the first probe (a set-up on all threads before it counts
   * as this process's own use) */
  if (t->on && t->alternate == 0) t->idle(t);
  if (t->alternate > 0)
    px_log(ctx, PX_LOG_LEVEL_INFO,
           "threads (%s): PX_TUNER_ALTERNATE=%d: 1 and %d threads in turn every %d steps (a test "
           "of the tuner; results do not change)",
           t->name, t->alternate, t->most, t->alternate);
}

int px_tuner_tuning(const struct px_tuner *t) { return t->on && t->most > 1; }

int px_tuner_stat_ticks(const char *text, const unsigned char *in, int ncpu,
                        unsigned long long sum[2]) {
  int counted = 0;
  for (const char *p = text; p && *p; p = strchr(p, '\n'), p = p ? p + 1 : NULL) {
    /* "cpuK user nice system idle iowait irq softirq steal ..." (not the
     * "cpu " total line) */
    if (strncmp(p, "cpu", 3) != 0 || p[3] < '0' || p[3] > '9') continue;
    char *end;
    const long k = strtol(p + 3, &end, 10);
    if (k < 0 || k >= ncpu || !in[k]) continue;
    unsigned long long idle = 0, all = 0;
    for (int f = 0; f < 8; ++f) {
      const char *q = end;
      const unsigned long long v = strtoull(q, &end, 10);
      if (end == q) break;
      all += v;
      if (f == 3 || f == 4) idle += v; /* idle, iowait */
    }
    sum[0] += idle;
    sum[1] += all;
    ++counted;
  }
  return counted;
}

/* The CPUs a process may use, at most this many are looked at */
#define PX_TUNER_MAX_CPUS 1024

double px_tuner_idle_cores(struct px_tuner *t) {
#if defined(__linux__)
  cpu_set_t set;
  unsigned char in[PX_TUNER_MAX_CPUS];
  int ncpu = 0;
  if (sched_getaffinity(0, sizeof set, &set) != 0) return -1;
  for (size_t k = 0; k < PX_TUNER_MAX_CPUS && k < CPU_SETSIZE; ++k) {
    in[k] = (unsigned char)(CPU_ISSET(k, &set) != 0);
    if (in[k]) ncpu = (int)k + 1;
  }
  FILE *f = fopen("/proc/stat", "r");
  if (!f) return -1;
  char line[512];
  unsigned long long sum[2] = {0, 0};
  int counted = 0;
  /* the "cpu" lines come first */
  while (fgets(line, sizeof line, f) && strncmp(line, "cpu", 3) == 0)
    counted += px_tuner_stat_ticks(line, in, ncpu, sum);
  fclose(f);
  if (counted < 1) return -1;
  struct timespec now, cpu;
  if (clock_gettime(CLOCK_MONOTONIC, &now) != 0 ||
      clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu) != 0)
    return -1;
  const double wall = (double)now.tv_sec + 1e-9 * (double)now.tv_nsec;
  const double used = (double)cpu.tv_sec + 1e-9 * (double)cpu.tv_nsec;
  const unsigned long long p0 = t->idle_mark;
  const double w0 = t->idle_wall, c0 = t->idle_cpu, span = wall - w0;
  const long hz = sysconf(_SC_CLK_TCK);
  const double tick = 1.0 / (double)(hz > 0 ? hz : 100); /* [s] */
  /* the counters' error [cores]: under a tick per CPU at each end */
  const double err = (double)counted * tick / span;
  const int first = t->idle_wall == 0;
  t->cores = counted;
  if (!first && sum[0] >= p0 && span > 0 && t->idle_need > 0 && err > t->idle_need)
    return -2; /* too short to tell: the marks kept, the interval grows */
  t->idle_mark = sum[0];
  t->idle_wall = wall;
  t->idle_cpu = used;
  if (first || sum[0] < p0 || !(span > 0)) return -1;
  t->idle_err = err;
  /* the cores' idle time, plus what this process used beyond the one core
   * its steps run on (its own threads: spinning OpenMP or BLAS workers hold
   * a core that a step on all threads would get), per second */
  const double v = ((double)(sum[0] - p0) * tick + (used - c0)) / span - 1.0;
  return v > 0 ? v : 0;
#else
  (void)t;
  return -1;
#endif
}

/* A probe of all threads from one needs most - 1 cores beside the one this
 * thread runs on: held where under PX_TUNER_IDLE_NEED of that sat idle. */
#define PX_TUNER_IDLE_NEED 0.5

/* Whether a probe of all threads is to be put off now: 1, the other cores
 * busy (px_tuner_idle_cores, over the time since the last look); 2, not
 * known yet (too short a time for the counters: look again after the next
 * window, still on 1 thread); 0, probe. */
static int px_tuner_hold(struct px_tuner *t, long step) {
  if (!t->idle) return 0;
  /* more threads than cores: what the cores give (t->cores from the last
   * look) */
  const int use = t->cores > 0 && t->cores < t->most ? t->cores : t->most;
  const double need = PX_TUNER_IDLE_NEED * (double)(use - 1);
  t->idle_need = need;
  const double idle = t->idle(t);
  if (idle == -2) return 2;
  /* unknown, or the counters too coarse to tell */
  if (!(idle >= 0) || t->idle_err > need || idle >= need) return 0;
  if (t->holds++ == 0)
    px_log(t->ctx, PX_LOG_LEVEL_INFO,
           "threads (%s): 1 from step %ld: the other cores are busy (%.2g of a core idle beside "
           "this process; %d threads need %d); looked at again after at least %g s of steps; "
           "results do not change",
           t->name, step + 1, idle, t->most, use - 1, PX_TUNER_PROBE_EVERY * PX_TUNER_WINDOW_S);
  return 1;
}

int px_tuner_begin(struct px_tuner *t) {
  if (t->on && t->alternate == 0) t->t_begin = t->clock();
  return t->active;
}

/* A probe (a window on the count not chosen) is followed by at least
 * PX_TUNER_PROBE_EVERY windows' worth of step time on the chosen count, and
 * by PX_TUNER_PROBE_COST times the time the probe lost against the chosen
 * count: a probe of 2 threads that a competing process slows 10x costs a
 * step every few seconds, one that costs a second (a vortex step whose
 * dozens of parallel regions each wait for a descheduled thread) one every
 * 20 s, about 5 % of the run. */
#define PX_TUNER_PROBE_COST 20.0
/* Once a count is chosen, the other must measure this much faster to take
 * over: two counts within the machine's noise of each other (a few per
 * cent between windows on a shared VM) would otherwise swap at every
 * probe, each swap costing a window on the slower one. */
#define PX_TUNER_MARGIN 1.05

/* The decision after a window: after a probe, when the next probe is due;
 * the other count at the start (until both are measured) and when a probe
 * is due; else the faster measured count. */
static void px_tuner_decide(struct px_tuner *t, long step, double time, long steps) {
  int best;
  const int other = t->active > 1 ? 1 : t->most;
  ++t->windows;
  if (t->probing) {
    /* this window was a probe: what it cost against the count not probed */
    const double r = t->rate[t->active > 1 ? 0 : 1];
    const double lost = r > 0 ? time - (double)steps / r : 0;
    t->probing = 0;
    t->since = 0;
    t->gap = PX_TUNER_PROBE_EVERY * PX_TUNER_WINDOW_S;
    if (PX_TUNER_PROBE_COST * lost > t->gap) t->gap = PX_TUNER_PROBE_COST * lost;
  } else if ((!(t->rate[0] > 0 && t->rate[1] > 0) && !t->held) || t->since >= t->gap) {
    /* a look at the other cores puts off a probe once: the next one, if
     * still due, measures (a step on all threads beside a busy core can
     * still be faster; where it is not, the probe's cost spaces the next) */
    const int hold = other > 1 && !t->held ? px_tuner_hold(t, step) : 0;
    if (hold == 2) return; /* stay on 1 and look again after the next window */
    t->held = hold;
    if (t->held) { /* stay on 1; look again after PX_TUNER_PROBE_EVERY windows */
      t->since = 0;
      t->gap = PX_TUNER_PROBE_EVERY * PX_TUNER_WINDOW_S;
      return;
    }
    t->active = other;
    t->probing = 1;
    return;
  }
  if (!(t->rate[0] > 0 && t->rate[1] > 0)) return;
  best = t->rate[1] >= t->rate[0] ? t->most : 1;
  if (t->chosen && best != t->chosen &&
      t->rate[best > 1 ? 1 : 0] < PX_TUNER_MARGIN * t->rate[t->chosen > 1 ? 1 : 0])
    best = t->chosen;
  t->active = best;
  if (best == t->chosen) return;
  t->chosen = best;
  /* on a machine whose load comes and goes the count may change every few
     seconds: a change within PX_TUNER_LOG_EVERY_S of the last one logged
     goes to the debug level, counted in the next info line */
  {
    const double now = t->clock();
    const int loud = t->logged_at < 0 || now - t->logged_at >= PX_TUNER_LOG_EVERY_S;
    char more[96] = "";
    if (loud && t->quiet_changes > 0)
      snprintf(more, sizeof more, "; %ld more changes since the last such line", t->quiet_changes);
    px_log(t->ctx, loud ? PX_LOG_LEVEL_INFO : PX_LOG_LEVEL_DEBUG,
           "threads (%s): %d from step %ld (measured %.4g steps/s on %d threads, %.4g on 1; "
           "re-measured after at least %g s of steps; results do not change%s)",
           t->name, best, step + 1, t->rate[1], t->most, t->rate[0], t->gap, more);
    if (loud) {
      t->logged_at = now;
      t->quiet_changes = 0;
    } else {
      ++t->quiet_changes;
    }
  }
}

/* Until both counts are measured the windows are PX_TUNER_FIRST_S long: a
 * short run (or the first second of a long one) on a machine where a
 * competing process makes the threads wait runs on the faster count after
 * about 2 PX_TUNER_FIRST_S, not 2 PX_TUNER_WINDOW_S; the later windows,
 * longer, average the noise out of the choice. */
static double px_tuner_window(const struct px_tuner *t) {
  return t->rate[0] > 0 && t->rate[1] > 0 ? PX_TUNER_WINDOW_S : PX_TUNER_FIRST_S;
}

/* A window on a count already measured faster the other way ends after
 * PX_TUNER_EARLY_STEPS steps once it runs at under half that count's rate,
 * and after one step at under a tenth: probing 2 threads that a competing
 * process slows 5x then costs a few steps, not a whole window (a short run
 * loses less too). A probe of one thread (where all threads were chosen)
 * also ends after PX_TUNER_EARLY_SHARE of a window (and PX_TUNER_EARLY_STEPS
 * steps) at under PX_TUNER_SLOWER of their rate: on a free machine where 2
 * threads run nearly twice as fast, an eighth of a window at half speed,
 * not a whole one (a probe took ~5 % of the granular benchmark's timed
 * steps). One thread waits for no other, so its rate over a few steps is
 * close to its rate over a window; the steps of all threads under a
 * competing load vary too much for that (a thread descheduled or not), and
 * their probes keep the rules above. The choice is the same: the slower
 * stays slower (taking over needs PX_TUNER_MARGIN the other way). */
#define PX_TUNER_EARLY_STEPS 3
#define PX_TUNER_EARLY_SHARE 0.125
#define PX_TUNER_SLOWER 0.75

static int px_tuner_clearly_slower(const struct px_tuner *t) {
  const double other = t->rate[t->active > 1 ? 0 : 1];
  double rate;
  if (!(other > 0) || t->window_steps < 1 || !(t->window_time > 0)) return 0;
  rate = (double)t->window_steps / t->window_time;
  if (rate < 0.1 * other) return 1;
  if (t->window_steps < PX_TUNER_EARLY_STEPS) return 0;
  return rate < 0.5 * other || (t->probing && t->active == 1 && rate < PX_TUNER_SLOWER * other &&
                                t->window_time >= PX_TUNER_EARLY_SHARE * px_tuner_window(t));
}

void px_tuner_end(struct px_tuner *t, long step) {
  ++t->steps;
  if (t->active > 1) ++t->steps_parallel;
  if (!t->on) return;
  ++t->window_steps;
  if (t->alternate > 0) {
    if (t->window_steps >= t->alternate) {
      t->window_steps = 0;
      t->active = t->active > 1 ? 1 : t->most;
    }
    return;
  }
  /* the first step warms up (allocations, first trees and lists): not timed */
  if (t->steps == 1) {
    t->window_steps = 0;
    return;
  }
  {
    const double dt = t->clock() - t->t_begin;
    t->window_time += dt;
    if (!t->probing) t->since += dt;
  }
  if (t->window_time < px_tuner_window(t) && t->window_steps < PX_TUNER_WINDOW_MAX_STEPS &&
      !px_tuner_clearly_slower(t))
    return;
  {
    /* a running mean over windows, so one disturbed window does not flip
     * the choice alone */
    const int k = t->active > 1 ? 1 : 0;
    const double rate = t->window_time > 0 ? (double)t->window_steps / t->window_time : 0;
    t->rate[k] = t->rate[k] > 0 ? 0.5 * (t->rate[k] + rate) : rate;
  }
  {
    const double time = t->window_time;
    const long steps = t->window_steps;
    t->window_time = 0;
    t->window_steps = 0;
    px_tuner_decide(t, step, time, steps);
  }
}
