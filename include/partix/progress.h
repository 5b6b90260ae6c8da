/* Progress of a run: on a terminal one self-overwriting line (step, time,
 * particle count, steps/s, ETA); elsewhere a plain line every few seconds. */
#ifndef PARTIX_PROGRESS_H
#define PARTIX_PROGRESS_H

#include <stdio.h>

#include "partix/context.h"
#include "partix/export.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_progress;

/* `out` is borrowed. `total_steps` > 0 gives the ETA (0 = unknown). If
 * `is_terminal` < 0 it is detected with isatty(fileno(out)).
 * `plain_interval` is the period of plain lines in seconds (<= 0: 10 s). */
PX_API enum px_status px_progress_create(struct px_context *ctx, FILE *out, int is_terminal,
                                         long total_steps, double plain_interval,
                                         struct px_progress **result);
PX_API void px_progress_free(struct px_progress *p);
/* Report that `step` steps are done at simulated time `t` with `count`
 * particles (count < 0: not shown). Cheap: prints at most a few times a second. */
PX_API void px_progress_update(struct px_progress *p, long step, double t, long count);
/* Print the final line (and end the terminal line). */
PX_API void px_progress_finish(struct px_progress *p);
/* Format the current line into buf (for tests and GUIs). */
PX_API void px_progress_format(const struct px_progress *p, char *buf, size_t size);

#ifdef __cplusplus
}
#endif
#endif
