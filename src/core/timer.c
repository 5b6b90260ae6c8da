#include "partix/timer.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "partix/memory.h"

double px_time_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

struct px_timer_slot {
  char name[48];
  double total;   /* seconds */
  double started; /* px_time_now() at start, < 0 when stopped */
  long calls;
};

struct px_timeset {
  struct px_context *ctx;      /* borrowed */
  struct px_timer_slot *slots; /* owned */
  int count, cap;
};

enum px_status px_timeset_create(struct px_context *ctx, struct px_timeset **out) {
  struct px_timeset *ts;
  if (!ctx || !out) return PX_STATUS_INVALID;
  ts = px_mem_calloc(ctx, "timers", 1, sizeof *ts);
  if (!ts) return PX_STATUS_NOMEM;
  ts->ctx = ctx;
  *out = ts;
  return PX_STATUS_OK;
}

void px_timeset_free(struct px_timeset *ts) {
  if (!ts) return;
  px_mem_free(ts->ctx, ts->slots);
  px_mem_free(ts->ctx, ts);
}

int px_timeset_slot(struct px_timeset *ts, const char *name) {
  int i;
  struct px_timer_slot *s;
  for (i = 0; i < ts->count; ++i)
    if (strncmp(ts->slots[i].name, name, sizeof ts->slots[i].name - 1) == 0) return i;
  if (ts->count == ts->cap) {
    int cap = ts->cap ? 2 * ts->cap : 16;
    struct px_timer_slot *grown =
        px_mem_realloc(ts->ctx, "timers", ts->slots, (size_t)cap * sizeof *grown);
    if (!grown) return -1;
    ts->slots = grown;
    ts->cap = cap;
  }
  s = &ts->slots[ts->count];
  memset(s, 0, sizeof *s);
  strncpy(s->name, name, sizeof s->name - 1);
  s->started = -1.0;
  return ts->count++;
}

void px_timeset_start(struct px_timeset *ts, int slot) {
  if (slot < 0 || slot >= ts->count) return;
  ts->slots[slot].started = px_time_now();
}

void px_timeset_stop(struct px_timeset *ts, int slot) {
  struct px_timer_slot *s;
  if (slot < 0 || slot >= ts->count) return;
  s = &ts->slots[slot];
  if (s->started < 0) return;
  s->total += px_time_now() - s->started;
  s->started = -1.0;
  s->calls++;
}

void px_timeset_reset(struct px_timeset *ts) {
  int i;
  for (i = 0; i < ts->count; ++i) {
    ts->slots[i].total = 0;
    ts->slots[i].calls = 0;
    ts->slots[i].started = -1.0;
  }
}

int px_timeset_count(const struct px_timeset *ts) { return ts->count; }

const char *px_timeset_name(const struct px_timeset *ts, int slot) {
  return (slot >= 0 && slot < ts->count) ? ts->slots[slot].name : "";
}

double px_timeset_total(const struct px_timeset *ts, int slot) {
  return (slot >= 0 && slot < ts->count) ? ts->slots[slot].total : 0.0;
}

long px_timeset_calls(const struct px_timeset *ts, int slot) {
  return (slot >= 0 && slot < ts->count) ? ts->slots[slot].calls : 0;
}

void px_timeset_report(const struct px_timeset *ts, FILE *out) {
  int i;
  double sum = 0;
  for (i = 0; i < ts->count; ++i) sum += ts->slots[i].total;
  fprintf(out, "%-24s %12s %10s %12s %8s\n", "timer", "total [s]", "calls", "mean [ms]", "share");
  for (i = 0; i < ts->count; ++i) {
    const struct px_timer_slot *s = &ts->slots[i];
    fprintf(out, "%-24s %12.4f %10ld %12.4f %7.1f%%\n", s->name, s->total, s->calls,
            s->calls ? 1e3 * s->total / (double)s->calls : 0.0,
            sum > 0 ? 100.0 * s->total / sum : 0.0);
  }
}
