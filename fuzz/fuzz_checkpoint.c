/* libFuzzer harness: the checkpoint reader on arbitrary bytes. The input's
 * CRCs are fixed up first (header, sections, end record; by the layout of
 * docs/checkpoint-format.md), so that the fuzzer reaches the checks behind
 * them instead of stopping at the first CRC. Every section the reader
 * accepts is then read back in full, in its own type and converted to f64.
 * Opening either succeeds or fails with a message; it never crashes, reads
 * out of bounds or allocates beyond the file's size. */
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
  struct px_checkpoint *ck = NULL;
  size_t i;
  if (size > 1u << 20) return 0;
  if (px_fuzz_write_checkpoint("checkpoint", data, size, 0, path) != 0) return 0;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 0;
  if (px_checkpoint_open(ctx, path, &ck) == PX_STATUS_OK) {
    for (i = 0; i < px_checkpoint_section_count(ck); ++i) {
      const char *name = NULL;
      enum px_dtype type;
      uint64_t count = 0;
      void *buf;
      double *as_f64;
      if (px_checkpoint_section(ck, i, &name, &type, &count) != PX_STATUS_OK) abort();
      if (count > size) abort(); /* a count the file cannot hold was accepted */
      buf = malloc(count * 8 + 1);
      as_f64 = malloc(count * sizeof *as_f64 + 1);
      if (buf && as_f64) {
        if (px_checkpoint_read(ck, name, type, count, buf) != PX_STATUS_OK) abort();
        (void)px_checkpoint_read(ck, name, PX_DTYPE_F64, count, as_f64);
      }
      free(buf);
      free(as_f64);
    }
    px_checkpoint_close(ck);
  } else if (!px_context_message(ctx)[0]) {
    abort();
  }
  px_context_free(ctx);
  return 0;
}
