/* Wall-clock timing: a monotonic clock and named accumulating timers for
 * per-block profiles of a time step. */
#ifndef PARTIX_TIMER_H
#define PARTIX_TIMER_H

#include <stdio.h>

#include "partix/context.h"
#include "partix/export.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Seconds since an arbitrary fixed point (monotonic). */
PX_API double px_time_now(void);

struct px_timeset;

PX_API enum px_status px_timeset_create(struct px_context *ctx, struct px_timeset **out);
PX_API void px_timeset_free(struct px_timeset *ts);
/* Index of the timer named `name`, created on first use (name copied).
 * Returns -1 (and records the failure) when out of memory. */
PX_API int px_timeset_slot(struct px_timeset *ts, const char *name);
PX_API void px_timeset_start(struct px_timeset *ts, int slot);
PX_API void px_timeset_stop(struct px_timeset *ts, int slot);
PX_API void px_timeset_reset(struct px_timeset *ts);
PX_API int px_timeset_count(const struct px_timeset *ts);
PX_API const char *px_timeset_name(const struct px_timeset *ts, int slot);
/* Accumulated seconds and number of start/stop pairs of a slot. */
PX_API double px_timeset_total(const struct px_timeset *ts, int slot);
PX_API long px_timeset_calls(const struct px_timeset *ts, int slot);
/* One line per timer: name, total s, calls, mean ms, share of the sum. */
PX_API void px_timeset_report(const struct px_timeset *ts, FILE *out);

#ifdef __cplusplus
}
#endif
#endif
