/* libFuzzer harness: a run opened from arbitrary checkpoint bytes, for every
 * solver (seeds: a checkpoint of each), then stepped. The CRCs are fixed up
 * (checkpoint_input.h); when the input's last byte is odd the header's case hash is
 * made to match the stored case too, so that mutated cases are built as
 * well as mutated states. Opening either refuses the file with a message
 * or gives a run that steps (or stops with a message); it never crashes,
 * reads out of bounds, hangs or allocates beyond what the case asks for
 * (within a memory limit of 256 MiB: px_context_set_memory_limit). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "checkpoint_input.h"
#include "partix/partix.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  char path[64];
  struct px_context *ctx = NULL;
  struct px_sim *sim = NULL;
  int k;
  if (size > 1u << 20) return 0;
  if (px_fuzz_write_checkpoint("resume", data, size, size && (data[size - 1] & 1), path) != 0)
    return 0;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 0;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  /* a forged case may ask for any size a machine could hold: the fuzzer's
     memory limit (-rss_limit_mb) is far below that */
  px_context_set_memory_limit(ctx, (size_t)256 << 20);
  if (px_sim_open(ctx, path, NULL, 0, PX_SIM_MODE_CHECK, &sim) == PX_STATUS_OK) {
    for (k = 0; k < 3 && px_sim_step(sim) == PX_STATUS_OK; ++k) {
    }
    px_sim_free(sim);
  } else if (!px_context_message(ctx)[0]) {
    abort();
  }
  px_context_free(ctx);
  return 0;
}
