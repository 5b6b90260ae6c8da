/* libFuzzer harness: the DXF reader of the granular solver (entities,
 * chaining into closed paths) on arbitrary text, every layer, unit scale.
 * A read either gives closed paths of finite points or fails with a message;
 * it never crashes, loops without end or allocates beyond what the text can
 * describe. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "partix/partix.h"
#include "solvers/granular/geometry.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  struct px_context *ctx = NULL;
  struct px_gran_path *paths = NULL;
  size_t n = 0, i;
  if (size > 1u << 20) return 0;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 0;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  if (px_gran_dxf_parse(ctx, "fuzz.dxf", (const char *)data, size, NULL, 1.0, 0.0, 0.0, 1e-6,
                        &paths, &n) == PX_STATUS_OK) {
    for (i = 0; i < n; ++i) px_gran_path_free(ctx, &paths[i]);
    px_mem_free(ctx, paths);
  } else if (!px_context_message(ctx)[0]) {
    abort();
  }
  px_context_free(ctx);
  return 0;
}
