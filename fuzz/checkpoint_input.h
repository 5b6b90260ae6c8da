/* Shared by the checkpoint harnesses: write fuzzer bytes as a checkpoint
 * file with every CRC its structure points at made right (header, sections,
 * end record; by the layout of docs/checkpoint-format.md), and optionally
 * the header's case hash, so that a fuzzer reaches the checks behind them
 * instead of stopping at the first CRC. */
#ifndef PX_FUZZ_CHECKPOINT_H
#define PX_FUZZ_CHECKPOINT_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/crc32.h"

static inline uint64_t get_u64(const uint8_t *p) {
  uint64_t v;
  memcpy(&v, p, 8);
  return v;
}

static inline uint32_t get_u32(const uint8_t *p) {
  uint32_t v;
  memcpy(&v, p, 4);
  return v;
}

static inline void put_u32(uint8_t *p, uint32_t v) { memcpy(p, &v, 4); }

static inline void px_fuzz_fix_crcs(uint8_t *b, size_t n) {
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

/* Set the header's case hash (offset 24) to the FNV-1a 64 of the section
 * named "case", as the writer does (px_case_hash of the stored text). */
static inline void px_fuzz_fix_case_hash(uint8_t *b, size_t n) {
  size_t off;
  uint32_t h;
  if (n < 64) return;
  h = get_u32(b + 16);
  if (h < 68 || h > n || h % 8) return;
  for (off = h; off + 104 <= n && memcmp(b + off, "PXSECT\0\0", 8) == 0;) {
    uint64_t p = get_u64(b + off + 24), pad = (8 - p % 8) % 8;
    uint32_t ln = get_u32(b + off + 12);
    if (p > n || off + 96 + p + pad + 8 > n) return;
    if (ln == 4 && memcmp(b + off + 32, "case", 4) == 0) {
      uint64_t fnv = 14695981039346656037u;
      size_t i;
      for (i = 0; i < p; ++i) {
        fnv ^= b[off + 96 + i];
        fnv *= 1099511628211u;
      }
      memcpy(b + 24, &fnv, 8);
      return;
    }
    off += 96 + p + pad + 8;
  }
}

/* The input as the checkpoint file /tmp/px_fuzz_NAME_PID.pxc (its path into
 * path, 64 bytes), CRCs fixed, and the case hash when fix_hash is set.
 * 0 on success. */
static inline int px_fuzz_write_checkpoint(const char *name, const uint8_t *data, size_t size,
                                           int fix_hash, char path[64]) {
  uint8_t *b;
  FILE *f;
  snprintf(path, 64, "/tmp/px_fuzz_%s_%ld.pxc", name, (long)getpid());
  b = malloc(size ? size : 1);
  if (!b) return -1;
  memcpy(b, data, size);
  if (fix_hash) px_fuzz_fix_case_hash(b, size);
  px_fuzz_fix_crcs(b, size);
  f = fopen(path, "wb");
  if (f) {
    fwrite(b, 1, size, f);
    fclose(f);
  }
  free(b);
  return f ? 0 : -1;
}

#endif
