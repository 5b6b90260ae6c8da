/* The thread tuner shared by the cpu engines (internal; not installed).
 *
 * On a machine where another process competes for a core, an OpenMP step on
 * all threads waits at every barrier for the thread that was descheduled and
 * can run several times slower than the same step on one thread. The tuner
 * times the engine's steps (wall time inside the steps only, not output;
 * not the first, which warms up on one thread) in windows of about
 * PX_TUNER_WINDOW_S seconds (PX_TUNER_FIRST_S until both counts are
 * measured), on 1 thread first, then on all `most` threads, and uses the
 * faster (once chosen, a count is kept until the other measures 5 %
 * faster). The count not chosen is probed again after at least 16 windows'
 * worth of steps, and after 20 times what the last probe lost; a probe ends
 * after 3 steps at under half the chosen count's rate, after 1 at under a
 * tenth; a probe of 1 thread also after an eighth of a window at under
 * three quarters of the rate of all. A machine that becomes busy or free is
 * so followed within a few seconds, and a probe costs about 5 % of the run
 * at most (about 1 % on a free machine where all threads run twice as fast
 * as one). A change of the chosen count is logged (INFO, run.log) at most once a
 * minute; the changes between at DEBUG, counted in the next INFO line.
 * An engine using it must give the same bits on any thread count: the tuner
 * switches counts between steps.
 *
 * Before each probe of all threads from one, the tuner reads how much of
 * the cores this process may use (its CPU affinity) sat idle since the last
 * such look, beside its own use (Linux: /proc/stat and the process's CPU
 * time): where that is less than half of the cores the extra threads need,
 * another process holds them, and the probe (whose steps would each wait
 * for a descheduled thread) is put off by 16 windows' worth of steps,
 * logged once; the probe due after that runs (a short run beside a busy
 * core pays no probe; a long one measures, and a costly probe is spaced by
 * its cost as above). The first look covers the warm-up step and the first window;
 * where that is too short for the kernel's counters (10 ms ticks) to tell,
 * the first window is extended until it is not (at 2 cores, 40 ms).
 *
 * Test hook: the environment variable PX_TUNER_ALTERNATE=k (k >= 1) turns
 * the tuner on even where the user fixed the thread count, and makes it
 * alternate between 1 and `most` threads every k steps, whatever the
 * timings (tests compare such a run with a 1-thread run byte for byte). */
#ifndef PX_CORE_TUNER_H
#define PX_CORE_TUNER_H

#include "partix/context.h"

#define PX_TUNER_WINDOW_S 0.2  /* [s] of step wall time per measured window */
#define PX_TUNER_FIRST_S 0.025 /* [s] the same until both counts are measured */

struct px_tuner {
  struct px_context *ctx; /* borrowed: where decisions are logged */
  const char *name;       /* static: the solver, in the log lines */
  int most;               /* threads of a parallel step (>= 1) */
  int on;                 /* 0: always `most` threads */
  int alternate;          /* > 0: the test hook's period [steps] */
  int active;             /* threads of the current / next step */
  int chosen;             /* the count last decided (0: none yet) */
  double (*clock)(void);  /* [s]; px_time_now (init), a fake clock in tests */
  double t_begin;         /* clock() at the step's start [s] */
  double window_time;     /* step wall time in the current window [s] */
  long window_steps, windows;
  double rate[2];             /* [steps/s] on 1 thread, on `most` (0: not measured) */
  int probing;                /* the current window measures the count not chosen */
  double since, gap;          /* [s] step time since the last probe; due after gap */
  long steps, steps_parallel; /* steps ended; of them, on more than 1 thread */
  /* idle cores [number, averaged] beside this process since the last call
   * (px_tuner_idle_cores; a fake in tests; NULL: not looked at), < 0 where
   * unknown */
  double (*idle)(struct px_tuner *t);
  unsigned long long idle_mark; /* px_tuner_idle_cores: idle ticks at the last look */
  double idle_wall, idle_cpu;   /* and the wall clock, this process's CPU time [s] */
  double idle_err;              /* the error of the last idle count [cores] */
  double idle_need;             /* idle cores a probe needs: a shorter look than can tell
                                   them (its error above) returns -2, keeping the marks */
  int cores;                    /* CPUs this process may use (px_tuner_idle_cores; 0: unknown) */
  int held;                     /* probes of all threads put off: the other cores busy */
  long holds;                   /* how many times */
  double logged_at;             /* clock() of the last change logged at INFO (< 0: none) */
  long quiet_changes;           /* changes since then, logged at DEBUG only */
};

/* The cores idle beside this process's one [cores, averaged over the time
 * since the last call], among those it may run on: their idle time from the
 * kernel's counters (/proc/stat, in ticks), plus what this process used
 * beyond one core (its own spinning threads would give way to a step on all
 * threads); -1 where unknown (the first call, not Linux, unreadable); -2
 * where the interval is too short for its error (t->idle_err: a tick per
 * core over the interval) to be under t->idle_need, keeping the marks of
 * the last look so that the next call's interval is longer. Keeps its marks
 * and the number of such cores in t. */
double px_tuner_idle_cores(struct px_tuner *t);

/* The same from the text of /proc/stat and the CPUs counted (in[k] for
 * cpu k < ncpu, nonzero: counted): adds their idle and iowait ticks to
 * sum[0], all their ticks to sum[1]; returns the CPUs counted. */
int px_tuner_stat_ticks(const char *text, const unsigned char *in, int ncpu,
                        unsigned long long sum[2]);

/* A tuner for an engine of `most` threads; on: tune (the user left the
 * thread count to partix), else always `most` (the test hook aside). */
void px_tuner_init(struct px_tuner *t, struct px_context *ctx, const char *name, int most, int on);

/* At a step's start: the threads the step uses (1 or most). */
int px_tuner_begin(struct px_tuner *t);

/* At the step's end; `step`: the step just ended (for the log). */
void px_tuner_end(struct px_tuner *t, long step);

/* Whether the tuner may change the thread count (on, most > 1). */
int px_tuner_tuning(const struct px_tuner *t);

#endif
