/* Damaged and incompatible checkpoints are refused with PX_STATUS_FORMAT and a
 * message that says what is wrong: truncation at every byte of a small file
 * and at sampled bytes of a larger one, single-bit flips everywhere, bad
 * magic, newer version, foreign byte order, trailing bytes, and files crafted
 * with valid CRCs but inconsistent content. The test also holds the file to
 * the byte layout of docs/checkpoint-format.md, with its own CRC code. */
#include <string.h>

#include "ck_util.h"
#include "io/crc32.h"
#include "partix/partix.h"

#define DIR_ "damage_tmp"

static struct px_context *ctx;

/* ------------------------------------------------ the documented layout */

struct layout {
  size_t header;        /* header bytes H */
  size_t nsec;          /* sections */
  size_t sec_off[16];   /* offset of each section header */
  size_t sec_bytes[16]; /* payload bytes */
  size_t end_off;       /* offset of the end record */
};

static uint32_t rd32(const unsigned char *p) {
  uint32_t v;
  memcpy(&v, p, 4);
  return v;
}
static uint64_t rd64(const unsigned char *p) {
  uint64_t v;
  memcpy(&v, p, 8);
  return v;
}
static void wr32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static void wr64(unsigned char *p, uint64_t v) { memcpy(p, &v, 8); }
static size_t pad8(size_t n) { return (8 - n % 8) % 8; }

/* Walk a valid file by the documented layout; 0 on success. */
static int parse_layout(const unsigned char *b, size_t n, struct layout *L) {
  size_t off;
  memset(L, 0, sizeof *L);
  if (n < 64 || memcmp(b, "PXCHKPT\0", 8) != 0) return -1;
  L->header = rd32(b + 16);
  off = L->header;
  while (off + 8 <= n && memcmp(b + off, "PXSECT\0\0", 8) == 0 && L->nsec < 16) {
    size_t bytes = (size_t)rd64(b + off + 24);
    L->sec_off[L->nsec] = off;
    L->sec_bytes[L->nsec++] = bytes;
    off += 96 + bytes + pad8(bytes) + 8;
  }
  if (off + 32 != n || memcmp(b + off, "PXEND\0\0\0", 8) != 0) return -1;
  L->end_off = off;
  return 0;
}

/* Recompute every CRC of a (possibly edited) file by the documented rules. */
static void refresh_crcs(unsigned char *b, const struct layout *L) {
  size_t i;
  wr32(b + L->header - 4, px_crc32_reference(0, b, L->header - 4));
  for (i = 0; i < L->nsec; ++i) {
    size_t len = 96 + L->sec_bytes[i] + pad8(L->sec_bytes[i]);
    wr32(b + L->sec_off[i] + len, px_crc32_reference(0, b + L->sec_off[i], len));
  }
  wr32(b + L->end_off + 24, px_crc32_reference(0, b, L->end_off + 24));
}

/* ------------------------------------------------------------ samples */

static const char *small_path = DIR_ "/small.chk";
static const char *large_path = DIR_ "/large.chk";

static void write_small(void) {
  struct px_checkpoint_writer *w = NULL;
  uint8_t a[3] = {1, 2, 3};
  double b[4] = {0.5, -1.0, 2.0, 1e300};
  uint32_t c[5] = {10, 20, 30, 40, 50};
  PX_CHECK_OK(ctx, px_checkpoint_writer_open(ctx, small_path, "granular",
                                             UINT64_C(0x1122334455667788), 77, 0.25, &w));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "a", PX_DTYPE_U8, 3, a));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "b", PX_DTYPE_F64, 4, b));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "empty", PX_DTYPE_I32, 0, NULL));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "c", PX_DTYPE_U32, 5, c));
  PX_CHECK_OK(ctx, px_checkpoint_writer_commit(w));
}

/* Three sections, the largest last and over the reader's 1 MiB buffer (so
 * that its validation takes several reads); small sections first keep the
 * many opens of the flip test cheap. */
static void write_large(void) {
  struct px_checkpoint_writer *w = NULL;
  size_t n = 140000, i;
  double *pos = malloc(n * sizeof *pos);
  float *vel = malloc(100001 * sizeof *vel);
  uint64_t ids[1000];
  for (i = 0; i < n; ++i) pos[i] = (double)i * 0.001;
  for (i = 0; i < 100001; ++i) vel[i] = (float)i;
  for (i = 0; i < 1000; ++i) ids[i] = i * i;
  PX_CHECK_OK(ctx, px_checkpoint_writer_open(ctx, large_path, "vortex", 5, 6, 7.0, &w));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "ids", PX_DTYPE_U64, 1000, ids));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "vel", PX_DTYPE_F32, 100001, vel));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "pos", PX_DTYPE_F64, n, pos));
  PX_CHECK_OK(ctx, px_checkpoint_writer_commit(w));
  free(pos);
  free(vel);
}

/* Open `data` written to a scratch file; returns the status (ck closed). */
static enum px_status open_bytes(const unsigned char *data, size_t n) {
  struct px_checkpoint *ck = NULL;
  enum px_status s;
  if (ck_spit(DIR_ "/x.chk", data, n) != 0) return PX_STATUS_INTERNAL;
  s = px_checkpoint_open(ctx, DIR_ "/x.chk", &ck);
  px_checkpoint_close(ck);
  return s;
}

/* ------------------------------------------------------------- tests */

static void test_file_follows_the_documented_layout(void) {
  size_t n;
  unsigned char *b = ck_slurp(small_path, &n);
  struct layout L;
  double t;
  PX_CHECK(b != NULL);
  if (!b) return;
  PX_CHECK(parse_layout(b, n, &L) == 0);
  PX_CHECK(rd32(b + 8) == 1);
  PX_CHECK(rd32(b + 12) == 0x01020304u);
  /* header: fixed 64 bytes + "granular" + version + CRC, rounded up to 8 */
  PX_CHECK(L.header ==
           64 + 8 + strlen(PX_VERSION_STRING) + 4 + pad8(76 + strlen(PX_VERSION_STRING)));
  PX_CHECK(L.header % 8 == 0);
  PX_CHECK(rd32(b + 20) == 0);
  PX_CHECK(rd64(b + 24) == UINT64_C(0x1122334455667788));
  PX_CHECK(rd64(b + 32) == 77);
  memcpy(&t, b + 40, 8);
  PX_CHECK(t == 0.25);
  PX_CHECK(rd32(b + 56) == 8 && memcmp(b + 64, "granular", 8) == 0);
  PX_CHECK(rd32(b + 60) == strlen(PX_VERSION_STRING));
  PX_CHECK(memcmp(b + 72, PX_VERSION_STRING, strlen(PX_VERSION_STRING)) == 0);
  PX_CHECK(rd32(b + L.header - 4) == px_crc32_reference(0, b, L.header - 4));
  PX_CHECK(L.nsec == 4);
  /* section "a": u8[3], 5 padding bytes */
  PX_CHECK(rd32(b + L.sec_off[0] + 8) == PX_DTYPE_U8);
  PX_CHECK(rd32(b + L.sec_off[0] + 12) == 1 && b[L.sec_off[0] + 32] == 'a');
  PX_CHECK(rd64(b + L.sec_off[0] + 16) == 3 && rd64(b + L.sec_off[0] + 24) == 3);
  PX_CHECK(L.sec_off[1] == L.sec_off[0] + 96 + 8 + 8);
  PX_CHECK(rd32(b + L.sec_off[0] + 104) == px_crc32_reference(0, b + L.sec_off[0], 104));
  PX_CHECK(rd32(b + L.sec_off[0] + 108) == 0);
  /* section "b": f64[4], payload 8-aligned */
  PX_CHECK(rd32(b + L.sec_off[1] + 8) == PX_DTYPE_F64 && L.sec_bytes[1] == 32);
  PX_CHECK((L.sec_off[1] + 96) % 8 == 0);
  PX_CHECK(L.sec_bytes[2] == 0 && L.sec_off[3] == L.sec_off[2] + 104);
  /* end record */
  PX_CHECK(rd64(b + L.end_off + 8) == 4);
  PX_CHECK(rd64(b + L.end_off + 16) == n);
  PX_CHECK(rd32(b + L.end_off + 24) == px_crc32_reference(0, b, L.end_off + 24));
  PX_CHECK(rd32(b + L.end_off + 28) == 0);
  PX_CHECK(n % 8 == 0);
  free(b);
}

/* Truncate the scratch copy to `cut` bytes (cuts must come in decreasing
 * order after a fresh ck_spit) and expect a "truncated" refusal. */
static void check_truncated(size_t cut, int *bad) {
  struct px_checkpoint *ck = NULL;
  enum px_status s = PX_STATUS_INTERNAL;
  if (truncate(DIR_ "/x.chk", (off_t)cut) == 0) s = px_checkpoint_open(ctx, DIR_ "/x.chk", &ck);
  px_checkpoint_close(ck);
  if (s != PX_STATUS_FORMAT || !ck_contains(px_context_message(ctx), "truncated")) {
    if (++*bad <= 5)
      fprintf(stderr, "cut at %zu: %s: %s\n", cut, px_status_name(s), px_context_message(ctx));
  }
}

static int cmp_size_desc(const void *a, const void *b) {
  size_t x = *(const size_t *)a, y = *(const size_t *)b;
  return x < y ? 1 : x > y ? -1 : 0;
}

static void test_truncation_at_every_byte_of_a_small_file_is_detected(void) {
  size_t n, cut;
  unsigned char *b = ck_slurp(small_path, &n);
  int bad = 0;
  PX_CHECK(b != NULL);
  if (!b) return;
  PX_CHECK(open_bytes(b, n) == PX_STATUS_OK);
  for (cut = n; cut-- > 0;) check_truncated(cut, &bad);
  PX_CHECK_MSG(bad == 0, "%d of %zu truncations not reported as truncated", bad, n);
  free(b);
}

static void test_truncation_of_a_large_file_is_detected_and_located(void) {
  size_t n, i, k, tried = 0, cuts[256];
  unsigned char *b = ck_slurp(large_path, &n);
  struct layout L;
  uint64_t seed = 2024;
  int bad = 0;
  PX_CHECK(b != NULL);
  if (!b) return;
  PX_CHECK(parse_layout(b, n, &L) == 0);
  /* around every boundary of the layout, and at random */
  for (i = 0; i <= L.nsec; ++i) {
    size_t base = i < L.nsec ? L.sec_off[i] : L.end_off;
    static const long deltas[] = {-9, -8, -4, -1, 0, 1, 8, 95, 96, 97, 200};
    for (k = 0; k < sizeof deltas / sizeof deltas[0]; ++k) {
      long cut = (long)base + deltas[k];
      if (cut >= 0 && (size_t)cut < n) cuts[tried++] = (size_t)cut;
    }
  }
  for (i = 0; i < 150; ++i) cuts[tried++] = (size_t)(ck_rand(&seed) % n);
  cuts[tried++] = n - 1;
  qsort(cuts, tried, sizeof cuts[0], cmp_size_desc);
  PX_CHECK(open_bytes(b, n) == PX_STATUS_OK);
  for (i = 0; i < tried; ++i) check_truncated(cuts[i], &bad);
  PX_CHECK_MSG(bad == 0, "%d of %zu truncations not reported as truncated", bad, tried);
  /* the message locates the cut: inside the payload of 'vel' */
  {
    size_t cut = L.sec_off[1] + 96 + 1000; /* 'vel' */
    PX_CHECK(open_bytes(b, cut) == PX_STATUS_FORMAT);
    {
      char want[256];
      snprintf(want, sizeof want,
               DIR_
               "/x.chk: truncated: file ends at byte %zu inside section 'vel' (expected "
               "400004 payload bytes)",
               cut);
      PX_CHECK_MSG(strcmp(px_context_message(ctx), want) == 0, "message: %s",
                   px_context_message(ctx));
    }
    PX_CHECK(open_bytes(b, L.end_off) == PX_STATUS_FORMAT);
    PX_CHECK(ck_contains(px_context_message(ctx),
                         "after section 'pos' (expected another section or the end marker)"));
  }
  free(b);
}

/* Flip one bit of the scratch copy (which holds b) in place, open, restore. */
static void check_flip(const unsigned char *b, size_t bit, int *bad) {
  struct px_checkpoint *ck = NULL;
  enum px_status s = PX_STATUS_INTERNAL;
  FILE *f = fopen(DIR_ "/x.chk", "r+b");
  unsigned char flipped = (unsigned char)(b[bit / 8] ^ (1u << (bit % 8)));
  if (f && fseek(f, (long)(bit / 8), SEEK_SET) == 0 && fputc(flipped, f) != EOF && fflush(f) == 0) {
    s = px_checkpoint_open(ctx, DIR_ "/x.chk", &ck);
    px_checkpoint_close(ck);
    fseek(f, (long)(bit / 8), SEEK_SET);
    fputc(b[bit / 8], f);
  }
  if (f) fclose(f);
  if (s != PX_STATUS_FORMAT && ++*bad <= 5)
    fprintf(stderr, "flip of bit %zu (byte %zu) not detected: %s: %s\n", bit % 8, bit / 8,
            px_status_name(s), px_context_message(ctx));
}

static void test_every_single_bit_flip_in_a_small_file_is_detected(void) {
  size_t n, bit;
  unsigned char *b = ck_slurp(small_path, &n);
  int bad = 0;
  PX_CHECK(b != NULL);
  if (!b) return;
  PX_CHECK(open_bytes(b, n) == PX_STATUS_OK);
  for (bit = 0; bit < 8 * n; ++bit) check_flip(b, bit, &bad);
  PX_CHECK_MSG(bad == 0, "%d of %zu bit flips not detected", bad, 8 * n);
  PX_CHECK(open_bytes(b, n) == PX_STATUS_OK); /* every flip was undone */
  free(b);
}

static void test_bit_flips_across_a_large_file_are_detected(void) {
  size_t n, i, k, tried = 0;
  unsigned char *b = ck_slurp(large_path, &n);
  struct layout L;
  uint64_t seed = 77;
  int bad = 0;
  PX_CHECK(b != NULL);
  if (!b) return;
  PX_CHECK(parse_layout(b, n, &L) == 0);
  PX_CHECK(open_bytes(b, n) == PX_STATUS_OK);
  /* every bit of the header and of each section trailer, every 4th bit of
   * the section headers, every 2nd of the end record, sampled payload bits */
  for (i = 0; i < 8 * L.header; ++i, ++tried) check_flip(b, i, &bad);
  for (i = 0; i < L.nsec; ++i) {
    size_t off = L.sec_off[i], len = 96 + L.sec_bytes[i] + pad8(L.sec_bytes[i]);
    for (k = i % 4; k < 8 * 96; k += 4, ++tried) check_flip(b, 8 * off + k, &bad);
    for (k = 0; k < 8 * 8; ++k, ++tried) check_flip(b, 8 * (off + len) + k, &bad);
    for (k = 0; k < 40; ++k, ++tried)
      check_flip(b, 8 * (off + 96) + ck_rand(&seed) % (8 * (len - 96)), &bad);
    check_flip(b, 8 * (off + len) - 1, &bad); /* last padding/payload bit */
  }
  for (i = 0; i < 8 * 32; i += 2, ++tried) check_flip(b, 8 * L.end_off + i, &bad);
  PX_CHECK_MSG(bad == 0, "%d of %zu bit flips not detected", bad, tried);
  PX_CHECK(open_bytes(b, n) == PX_STATUS_OK);
  /* a payload flip names the section and both CRCs */
  b[L.sec_off[2] + 96 + 12345] ^= 0x10;
  PX_CHECK(open_bytes(b, n) == PX_STATUS_FORMAT);
  PX_CHECK(ck_contains(px_context_message(ctx), "x.chk: CRC mismatch in section 'pos' (stored 0x"));
  PX_CHECK(ck_contains(px_context_message(ctx), "): the file is damaged"));
  free(b);
}

static void test_foreign_and_newer_files_are_refused_with_their_reason(void) {
  size_t n;
  unsigned char *b = ck_slurp(small_path, &n), *c;
  struct layout L;
  char want[256];
  PX_CHECK(b != NULL);
  if (!b) return;
  PX_CHECK(parse_layout(b, n, &L) == 0);
  c = malloc(n + 128);

  /* bad magic: a flipped first byte, and a text file */
  memcpy(c, b, n);
  c[0] = 'Q';
  PX_CHECK(open_bytes(c, n) == PX_STATUS_FORMAT);
  PX_CHECK(strcmp(px_context_message(ctx), DIR_ "/x.chk: not a partix checkpoint (bad magic)") ==
           0);
  PX_CHECK(open_bytes((const unsigned char *)"solver: granular\n", 17) == PX_STATUS_FORMAT);
  PX_CHECK(ck_contains(px_context_message(ctx), "bad magic"));

  /* a newer format version, with a valid header CRC */
  memcpy(c, b, n);
  wr32(c + 8, 2);
  refresh_crcs(c, &L);
  PX_CHECK(open_bytes(c, n) == PX_STATUS_FORMAT);
  PX_CHECK_MSG(strcmp(px_context_message(ctx), DIR_ "/x.chk: format version 2 is newer than "
                                                    "this partix (reads 1)") == 0,
               "message: %s", px_context_message(ctx));

  /* the whole header as a machine of the other byte order writes it */
  {
    static const size_t u32s[] = {8, 12, 16, 20, 56, 60};
    static const size_t u64s[] = {24, 32, 40, 48};
    size_t i, j;
    memcpy(c, b, n);
    for (i = 0; i < 6; ++i)
      for (j = 0; j < 2; ++j) {
        unsigned char t = c[u32s[i] + j];
        c[u32s[i] + j] = c[u32s[i] + 3 - j];
        c[u32s[i] + 3 - j] = t;
      }
    for (i = 0; i < 4; ++i)
      for (j = 0; j < 4; ++j) {
        unsigned char t = c[u64s[i] + j];
        c[u64s[i] + j] = c[u64s[i] + 7 - j];
        c[u64s[i] + 7 - j] = t;
      }
    PX_CHECK(open_bytes(c, n) == PX_STATUS_FORMAT);
    {
      const uint32_t probe = 1;
      int little = *(const unsigned char *)&probe == 1;
      snprintf(want, sizeof want, DIR_ "/x.chk: written on a %s-endian machine",
               little ? "big" : "little");
    }
    PX_CHECK_MSG(ck_contains(px_context_message(ctx), want), "message: %s",
                 px_context_message(ctx));
  }

  /* trailing bytes after the end marker */
  memcpy(c, b, n);
  c[n] = '\n';
  PX_CHECK(open_bytes(c, n + 1) == PX_STATUS_FORMAT);
  PX_CHECK(ck_contains(px_context_message(ctx), "1 bytes of trailing junk after the end marker"));
  memset(c + n, 0, 100);
  PX_CHECK(open_bytes(c, n + 100) == PX_STATUS_FORMAT);
  PX_CHECK(ck_contains(px_context_message(ctx), "100 bytes of trailing junk"));
  /* a second copy appended (e.g. a botched concatenation) */
  memcpy(c, b, n);
  {
    unsigned char *two = malloc(2 * n);
    memcpy(two, b, n);
    memcpy(two + n, b, n);
    PX_CHECK(open_bytes(two, 2 * n) == PX_STATUS_FORMAT);
    PX_CHECK(ck_contains(px_context_message(ctx), "trailing junk"));
    free(two);
  }

  /* an empty file */
  PX_CHECK(open_bytes(b, 0) == PX_STATUS_FORMAT);
  PX_CHECK(ck_contains(px_context_message(ctx), "truncated"));
  free(c);
  free(b);
}

/* Files whose CRCs are all valid but whose content breaks a rule of the
 * format (as a buggy or hostile writer could produce). */
static void test_consistent_crcs_do_not_hide_broken_rules(void) {
  size_t n;
  unsigned char *b = ck_slurp(small_path, &n), *c;
  struct layout L;
  PX_CHECK(b != NULL);
  if (!b) return;
  PX_CHECK(parse_layout(b, n, &L) == 0);
  c = malloc(n);

  /* the control: refreshing CRCs of an unchanged file keeps it valid */
  memcpy(c, b, n);
  refresh_crcs(c, &L);
  PX_CHECK(memcmp(c, b, n) == 0);

#define EDIT_AND_EXPECT(edit, text)                                         \
  do {                                                                      \
    memcpy(c, b, n);                                                        \
    edit;                                                                   \
    refresh_crcs(c, &L);                                                    \
    PX_CHECK(open_bytes(c, n) == PX_STATUS_FORMAT);                         \
    PX_CHECK_MSG(ck_contains(px_context_message(ctx), text), "message: %s", \
                 px_context_message(ctx));                                  \
  } while (0)

  EDIT_AND_EXPECT(c[L.sec_off[1] + 32] = 'a', "section 'a' appears twice");
  EDIT_AND_EXPECT(wr64(c + L.end_off + 8, 5),
                  "the end marker counts 5 sections but the file has 4");
  EDIT_AND_EXPECT(wr32(c + 20, 1), "header flags 0x00000001");
  EDIT_AND_EXPECT(wr32(c + 8, 0), "format version 0 is not valid");
  EDIT_AND_EXPECT(wr32(c + L.sec_off[1] + 8, 42), "unknown element type 42");
  EDIT_AND_EXPECT(wr32(c + L.sec_off[1] + 8, PX_DTYPE_F32),
                  "4 elements of f32 do not make 32 bytes");
  EDIT_AND_EXPECT(c[L.sec_off[1] + 32] = ' ', "bad byte 0x20 in its name field");
  EDIT_AND_EXPECT(wr32(c + L.sec_off[1] + 12, 0), "name length 0");
  EDIT_AND_EXPECT(c[L.sec_off[0] + 96 + 3] = 1, "nonzero padding after section 'a'");
  EDIT_AND_EXPECT(c[L.sec_off[0] + 96 + 8 + 5] = 1, "nonzero padding after section 'a'");
  EDIT_AND_EXPECT(wr64(c + L.end_off + 16, n + 8), "damaged end marker");
  EDIT_AND_EXPECT(c[64] = ' ', "damaged header (invalid character in the solver name)");
  EDIT_AND_EXPECT(c[72] = 0x01, "damaged header (invalid character in the version)");
  if (L.header - 4 > 72 + strlen(PX_VERSION_STRING))
    EDIT_AND_EXPECT(c[L.header - 5] = 'x', "damaged header (nonzero padding");
  EDIT_AND_EXPECT(memcpy(c + L.sec_off[1], "PXSECX\0\0", 8),
                  "expected a section or the end marker at byte");
#undef EDIT_AND_EXPECT
  free(c);
  free(b);
}

int main(void) {
  px_context_create(&ctx);
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  ck_scratch(DIR_);
  write_small();
  write_large();
  test_file_follows_the_documented_layout();
  test_truncation_at_every_byte_of_a_small_file_is_detected();
  test_truncation_of_a_large_file_is_detected_and_located();
  test_every_single_bit_flip_in_a_small_file_is_detected();
  test_bit_flips_across_a_large_file_are_detected();
  test_foreign_and_newer_files_are_refused_with_their_reason();
  test_consistent_crcs_do_not_hide_broken_rules();
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  ck_rm_rf(DIR_);
  return px_test_report("test_checkpoint_damage");
}
