/* libFuzzer harness: the case loader (YAML parsing, schema validation of
 * every solver's section, defaults, the resolved text) on arbitrary bytes.
 * A load either succeeds, and then its resolved text loads again to the same
 * hash, or fails with a message; it never crashes, leaks or hangs. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "partix/partix.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  struct px_context *ctx = NULL;
  struct px_case *c = NULL, *again = NULL;
  if (size > 1u << 20) return 0;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 0;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  if (px_case_load_string(ctx, "fuzz.yaml", (const char *)data, size, NULL, 0, &c) ==
      PX_STATUS_OK) {
    const char *text = px_case_resolved_text(c);
    if (px_case_load_string(ctx, "again.yaml", text, strlen(text), NULL, 0, &again) !=
            PX_STATUS_OK ||
        px_case_hash(again) != px_case_hash(c))
      abort(); /* the resolved text must load back to itself */
  } else if (!px_context_message(ctx)[0]) {
    abort(); /* a failure says why */
  }
  px_case_free(again);
  px_case_free(c);
  px_context_free(ctx);
  return 0;
}
