#include "partix/progress.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "partix/memory.h"
#include "partix/timer.h"

struct px_progress {
  struct px_context *ctx; /* borrowed */
  FILE *out;              /* borrowed */
  int terminal;
  long total;
  double interval;     /* seconds between plain lines */
  double t_start;      /* wall clock at creation */
  double t_last_print; /* wall clock of the last printed line */
  double t_rate;       /* wall clock of the last rate sample */
  long step_rate;      /* step at the last rate sample */
  double rate;         /* steps per second (smoothed), < 0 unknown */
  long first_step;     /* step at the first update (resumed runs start > 0) */
  long step, count;
  double time;
  int started, line_open;
};

enum px_status px_progress_create(struct px_context *ctx, FILE *out, int is_terminal,
                                  long total_steps, double plain_interval,
                                  struct px_progress **result) {
  struct px_progress *p;
  if (!ctx || !out || !result) return PX_STATUS_INVALID;
  p = px_mem_calloc(ctx, "progress", 1, sizeof *p);
  if (!p) return PX_STATUS_NOMEM;
  p->ctx = ctx;
  p->out = out;
  p->terminal = is_terminal < 0 ? isatty(fileno(out)) : is_terminal;
  p->total = total_steps > 0 ? total_steps : 0;
  p->interval = plain_interval > 0 ? plain_interval : 10.0;
  p->t_start = p->t_last_print = p->t_rate = px_time_now();
  p->rate = -1.0;
  p->count = -1;
  *result = p;
  return PX_STATUS_OK;
}

void px_progress_free(struct px_progress *p) {
  if (!p) return;
  if (p->line_open) fputc('\n', p->out);
  px_mem_free(p->ctx, p);
}

static void px_progress_hms(double seconds, char *buf, size_t size) {
  long s = seconds > 0 ? (long)(seconds + 0.5) : 0;
  if (s >= 86400)
    snprintf(buf, size, "%ldd%02ldh", s / 86400, (s % 86400) / 3600);
  else
    snprintf(buf, size, "%ld:%02ld:%02ld", s / 3600, (s % 3600) / 60, s % 60);
}

void px_progress_format(const struct px_progress *p, char *buf, size_t size) {
  char eta[32] = "-", elapsed[32];
  int n;
  size_t used;
  px_progress_hms(px_time_now() - p->t_start, elapsed, sizeof elapsed);
  if (p->total > 0)
    n = snprintf(buf, size, "step %ld/%ld (%.1f%%)  t = %.6g", p->step, p->total,
                 100.0 * (double)p->step / (double)p->total, p->time);
  else
    n = snprintf(buf, size, "step %ld  t = %.6g", p->step, p->time);
  used = n > 0 ? (size_t)n : 0;
  if (used >= size) return;
  if (p->count >= 0) {
    n = snprintf(buf + used, size - used, "  N = %ld", p->count);
    used += n > 0 ? (size_t)n : 0;
    if (used >= size) return;
  }
  if (p->rate > 0 && p->total > 0)
    px_progress_hms((double)(p->total - p->step) / p->rate, eta, sizeof eta);
  if (p->rate > 0)
    snprintf(buf + used, size - used, "  %.4g steps/s  elapsed %s  ETA %s", p->rate, elapsed, eta);
  else
    snprintf(buf + used, size - used, "  elapsed %s", elapsed);
}

static void px_progress_print(struct px_progress *p, int final) {
  char line[256];
  px_progress_format(p, line, sizeof line);
  if (p->terminal) {
    fprintf(p->out, "\r%s\033[K", line);
    p->line_open = 1;
    if (final) {
      fputc('\n', p->out);
      p->line_open = 0;
    }
  } else {
    fprintf(p->out, "%s\n", line);
  }
  fflush(p->out);
}

void px_progress_update(struct px_progress *p, long step, double t, long count) {
  double now;
  if (!p) return;
  now = px_time_now();
  if (!p->started) {
    p->started = 1;
    p->first_step = step;
    p->step_rate = step;
    p->t_rate = now;
  }
  p->step = step;
  p->time = t;
  p->count = count;
  /* Rate over windows of at least half a second, smoothed exponentially. */
  if (now - p->t_rate >= 0.5 && step > p->step_rate) {
    double sample = (double)(step - p->step_rate) / (now - p->t_rate);
    p->rate = p->rate < 0 ? sample : 0.7 * p->rate + 0.3 * sample;
    p->t_rate = now;
    p->step_rate = step;
  }
  if (now - p->t_last_print >= (p->terminal ? 0.2 : p->interval)) {
    p->t_last_print = now;
    px_progress_print(p, 0);
  }
}

void px_progress_finish(struct px_progress *p) {
  double now;
  /* no step was reported (a resumed run that only writes its end-of-run
     products): there is no progress to show, not "step 0 of N" */
  if (!p || !p->started) return;
  now = px_time_now();
  if (p->started && now > p->t_start && p->step > p->first_step)
    p->rate = (double)(p->step - p->first_step) / (now - p->t_start);
  px_progress_print(p, 1);
}
