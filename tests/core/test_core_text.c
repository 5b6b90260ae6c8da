/* Numbers written for people and for reading back (core/text.h). */
#include <stdlib.h>
#include <string.h>

#include "core/text.h"
#include "px_test.h"

static void check_bytes(double b, int binary, const char *want) {
  char buf[32];
  PX_CHECK(px_text_bytes(b, binary, buf, sizeof buf) == buf);
  if (strcmp(buf, want) != 0)
    fprintf(stderr, "px_text_bytes(%g, %d) = '%s', want '%s'\n", b, binary, buf, want);
  PX_CHECK(strcmp(buf, want) == 0);
}

static void test_bytes_read_as_people_write_them(void) {
  check_bytes(0, 0, "0 B");
  check_bytes(999, 0, "999 B");
  check_bytes(1000, 0, "1.0 kB");
  check_bytes(812e6, 0, "812 MB");
  check_bytes(8.1e12, 0, "8.1 TB");
  check_bytes(24.0 * 1024 * 1024 * 1024, 1, "24 GiB");
  check_bytes(1536, 1, "1.5 KiB");
  check_bytes(3e21, 0, "3000 EB"); /* beyond the last unit: counted in it */
}

static void test_reals_read_back_exactly(void) {
  const double xs[] = {0.1, 1.0 / 3.0, 150.0, 2.1e11, 6.02214076e23, -4.9e-324, 1e9, 123456789.0};
  char buf[40];
  for (size_t i = 0; i < sizeof xs / sizeof xs[0]; ++i)
    PX_CHECK(strtod(px_text_real(xs[i], buf), NULL) == xs[i]);
  PX_CHECK(strcmp(px_text_real(150.0, buf), "150") == 0);
  PX_CHECK(strcmp(px_text_real(2.1e11, buf), "2.1e+11") == 0);
  PX_CHECK(strcmp(px_text_real(0.1, buf), "0.1") == 0);
}

/* FNV-1a 64 against the published test vectors (Fowler, Noll, Vo), also
 * fed in pieces */
static void test_fnv1a_vectors(void) {
  PX_CHECK(px_text_fnv1a(PX_FNV1A_OFFSET, "", 0) == 0xcbf29ce484222325ULL);
  PX_CHECK(px_text_fnv1a(PX_FNV1A_OFFSET, "a", 1) == 0xaf63dc4c8601ec8cULL);
  PX_CHECK(px_text_fnv1a(PX_FNV1A_OFFSET, "foobar", 6) == 0x85944171f73967e8ULL);
  PX_CHECK(px_text_fnv1a(px_text_fnv1a(PX_FNV1A_OFFSET, "foo", 3), "bar", 3) ==
           0x85944171f73967e8ULL);
}

int main(void) {
  test_bytes_read_as_people_write_them();
  test_reals_read_back_exactly();
  test_fnv1a_vectors();
  return px_test_report("test_core_text");
}
