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

#include "io/crc32.h"
#include "partix/partix.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static uint64_t get_u64(const uint8_t *p) {
  uint64_t v;
  memcpy(&v, p, 8);
  return v;
}

static uint32_t get_u32(const uint8_t *p) {
  uint32_t v;
  memcpy(&v, p, 4);
  return v;
}

static void put_u32(uint8_t *p, uint32_t v) { memcpy(p, &v, 4); }

/* Make every CRC the file's structure points at right. */
static void fix_crcs(uint8_t *b, size_t n) {
  size_t off;
  uint32_t h;
  if (n < 64) return;
  h = get_u32(b + 16);
  if (h < 68 || h > n || h % 8) return;
  put_u32(b + h - 4, px_crc32_update(0, b, h - 4));
  off = h;
  while (off + 32 <= n) {
    if (memcmp(b + off, "PXSECT\0\0", 8) == 0 && off + 104 <= n) {
      uint64_t p = get_u64(b + off + 24), pad = (8 - p % 8) % 8;
      if (p > n || off + 96 + p + pad + 8 > n) return;
      put_u32(b + off + 96 + p + pad, px_crc32_update(0, b + off, 96 + p + pad));
      off += 96 + p + pad + 8;
    } else if (memcmp(b + off, "PXEND\0\0\0", 8) == 0) {
      put_u32(b + off + 24, px_crc32_update(0, b, off + 24));
      return;
    } else {
      return;
    }
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static char path[64];
  struct px_context *ctx = NULL;
  struct px_checkpoint *ck = NULL;
  uint8_t *b;
  FILE *f;
  size_t i;
  if (size > 1u << 20) return 0;
  if (!path[0]) snprintf(path, sizeof path, "/tmp/px_fuzz_ck_%ld.pxc", (long)getpid());
  b = malloc(size ? size : 1);
  if (!b) return 0;
  memcpy(b, data, size);
  fix_crcs(b, size);
  f = fopen(path, "wb");
  if (!f) {
    free(b);
    return 0;
  }
  fwrite(b, 1, size, f);
  fclose(f);
  free(b);
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
