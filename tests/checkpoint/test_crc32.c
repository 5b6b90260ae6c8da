/* CRC-32 (IEEE 802.3): the standard check value, slicing-by-16 against the
 * bit-at-a-time definition, incremental against one-shot, combination. */
#include <string.h>

#include "ck_util.h"
#include "io/crc32.h"
#include "partix/timer.h"

static void test_check_value_is_cbf43926(void) {
  PX_CHECK(px_crc32_update(0, "123456789", 9) == UINT32_C(0xCBF43926));
  PX_CHECK(px_crc32_reference(0, "123456789", 9) == UINT32_C(0xCBF43926));
  /* Known values (zlib crc32): empty input, one 'a', 32 zero bytes. */
  PX_CHECK(px_crc32_update(0, NULL, 0) == 0);
  PX_CHECK(px_crc32_update(0, "a", 1) == UINT32_C(0xE8B7BE43));
  {
    unsigned char zeros[32] = {0};
    PX_CHECK(px_crc32_update(0, zeros, 32) == UINT32_C(0x190A55AD));
  }
}

static void test_slicing_matches_bitwise_definition_at_every_length_and_alignment(void) {
  unsigned char data[1024 + 8];
  uint64_t seed = 12345;
  size_t i, off, n;
  int bad = 0;
  for (i = 0; i < sizeof data; ++i) data[i] = (unsigned char)ck_rand(&seed);
  for (off = 0; off < 8; ++off)
    for (n = 0; n <= 300; ++n)
      if (px_crc32_update(0, data + off, n) != px_crc32_reference(0, data + off, n)) ++bad;
  PX_CHECK_MSG(bad == 0, "%d of 2408 (offset, length) pairs differ", bad);
  PX_CHECK(px_crc32_update(0x1234u, data, 1024) == px_crc32_reference(0x1234u, data, 1024));
}

static void test_incremental_equals_one_shot_at_every_split(void) {
  unsigned char data[777];
  uint64_t seed = 99;
  uint32_t whole;
  size_t i, split;
  int bad = 0;
  for (i = 0; i < sizeof data; ++i) data[i] = (unsigned char)ck_rand(&seed);
  whole = px_crc32_update(0, data, sizeof data);
  for (split = 0; split <= sizeof data; ++split) {
    uint32_t c = px_crc32_update(0, data, split);
    c = px_crc32_update(c, data + split, sizeof data - split);
    if (c != whole) ++bad;
  }
  PX_CHECK_MSG(bad == 0, "%d splits differ", bad);
  /* three pieces, byte by byte */
  {
    uint32_t c = 0;
    for (i = 0; i < sizeof data; ++i) c = px_crc32_update(c, data + i, 1);
    PX_CHECK(c == whole);
  }
}

static void test_combine_equals_crc_of_concatenation(void) {
  static unsigned char data[70000];
  uint64_t seed = 7;
  size_t i, k;
  size_t splits[] = {0, 1, 7, 8, 9, 255, 4096, 65535, 69999, 70000};
  uint32_t whole;
  for (i = 0; i < sizeof data; ++i) data[i] = (unsigned char)ck_rand(&seed);
  whole = px_crc32_update(0, data, sizeof data);
  for (k = 0; k < sizeof splits / sizeof splits[0]; ++k) {
    size_t s = splits[k];
    uint32_t a = px_crc32_update(0, data, s), b = px_crc32_update(0, data + s, sizeof data - s);
    PX_CHECK_MSG(px_crc32_combine(a, b, sizeof data - s) == whole, "split at %zu", s);
  }
}

/* Informational: throughput of the table-driven CRC (a checkpoint of several
 * hundred MB goes through it twice: on writing and on loading). */
static void test_throughput_is_reported(void) {
  size_t n = (size_t)32 << 20, i;
  unsigned char *data = malloc(n);
  double t0, t1;
  uint32_t c;
  PX_CHECK(data != NULL);
  if (!data) return;
  for (i = 0; i < n; ++i) data[i] = (unsigned char)(i * 2654435761u >> 24);
  t0 = px_time_now();
  c = px_crc32_update(0, data, n);
  t1 = px_time_now();
  PX_CHECK(c == px_crc32_update(px_crc32_update(0, data, n / 2), data + n / 2, n - n / 2));
  printf("crc32: %.0f MB/s (slicing-by-16)\n", (double)n / 1e6 / (t1 - t0 > 0 ? t1 - t0 : 1e-9));
  free(data);
}

int main(void) {
  test_check_value_is_cbf43926();
  test_slicing_matches_bitwise_definition_at_every_length_and_alignment();
  test_incremental_equals_one_shot_at_every_split();
  test_combine_equals_crc_of_concatenation();
  test_throughput_is_reported();
  return px_test_report("test_crc32");
}
