/* The thread tuner (tuner.h). */
#include "core/tuner.h"

#include <stdlib.h>
#include <string.h>

#include "partix/timer.h"

/* A window ends after this many steps even if shorter than
 * PX_TUNER_WINDOW_S (tiny steps: the clock would be read too often for
 * nothing) */
#define PX_TUNER_WINDOW_MAX_STEPS 100000

/* One window of every PX_TUNER_PROBE_EVERY measures the count not chosen */
#define PX_TUNER_PROBE_EVERY 16

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
  t->clock = px_time_now;
  if (t->alternate > 0)
    px_log(ctx, PX_LOG_LEVEL_INFO,
           "threads (%s): PX_TUNER_ALTERNATE=%d: 1 and %d threads in turn every %d steps (a test "
           "of the tuner; results do not change)",
           t->name, t->alternate, t->most, t->alternate);
}

int px_tuner_tuning(const struct px_tuner *t) { return t->on && t->most > 1; }

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
  } else if (!(t->rate[0] > 0 && t->rate[1] > 0) || t->since >= t->gap) {
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
  px_log(t->ctx, PX_LOG_LEVEL_INFO,
         "threads (%s): %d from step %ld (measured %.4g steps/s on %d threads, %.4g on 1; "
         "re-measured after at least %g s of steps; results do not change)",
         t->name, best, step + 1, t->rate[1], t->most, t->rate[0], t->gap);
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
