/* Checkpoints written and read back: every element type bit for bit (empty
 * and multi-MB sections included), header fields, section order, lookup,
 * type/count mismatches, piecewise writing and reading, wrong calls, and
 * memory bounded while validating. */
#include <math.h>
#include <string.h>
#include <time.h>

#include "ck_util.h"
#include "partix/partix.h"

#define DIR_ "roundtrip_tmp"

static struct px_context *ctx;

/* Sections written by write_sample(), in order. */
#define BIG_COUNT ((size_t)1 << 19) /* 4 MiB of f64 */
static uint8_t s_u8[13];
static int32_t s_i32[7];
static uint32_t s_u32[5];
static int64_t s_i64[6];
static uint64_t s_u64[3];
static float s_f32[9];
static double s_f64[10];
static double *s_big;

static void fill_sample(void) {
  size_t i;
  for (i = 0; i < 13; ++i) s_u8[i] = (uint8_t)(i * 37 + 255);
  s_i32[0] = INT32_MIN;
  s_i32[1] = INT32_MAX;
  s_i32[2] = -1;
  s_i32[3] = 0;
  s_i32[4] = 123456789;
  s_i32[5] = -987654321;
  s_i32[6] = 42;
  s_u32[0] = 0;
  s_u32[1] = UINT32_MAX;
  s_u32[2] = 0x80000000u;
  s_u32[3] = 0xDEADBEEFu;
  s_u32[4] = 1;
  s_i64[0] = INT64_MIN;
  s_i64[1] = INT64_MAX;
  s_i64[2] = -1;
  s_i64[3] = 0;
  s_i64[4] = INT64_C(1) << 53;
  s_i64[5] = -(INT64_C(1) << 40) - 7;
  s_u64[0] = UINT64_MAX;
  s_u64[1] = UINT64_C(0x0123456789ABCDEF);
  s_u64[2] = 0;
  s_f32[0] = 0.0f;
  s_f32[1] = -0.0f;
  s_f32[2] = 1e-45f; /* denormal */
  s_f32[3] = 3.4028235e38f;
  s_f32[4] = (float)INFINITY;
  s_f32[5] = -(float)INFINITY;
  s_f32[6] = (float)NAN;
  s_f32[7] = 0.1f;
  s_f32[8] = -1.5f;
  s_f64[0] = 0.0;
  s_f64[1] = -0.0;
  s_f64[2] = 4.9406564584124654e-324;
  s_f64[3] = 1.7976931348623157e308;
  s_f64[4] = INFINITY;
  s_f64[5] = -INFINITY;
  s_f64[6] = NAN;
  s_f64[7] = 0.1;
  s_f64[8] = 1.0 / 3.0;
  s_f64[9] = -2.5e-300;
  s_big = malloc(BIG_COUNT * sizeof *s_big);
  for (i = 0; i < BIG_COUNT; ++i) s_big[i] = sin((double)i) * 1e3 + (double)i;
}

static const uint64_t HASH = UINT64_C(0xDEADBEEFCAFEF00D);
static const uint64_t STEP = (UINT64_C(1) << 40) + 3;
static const double TIME = 12.345678901234567;

static enum px_status write_sample(const char *path) {
  struct px_checkpoint_writer *w;
  PX_TRY(px_checkpoint_writer_open(ctx, path, "granular", HASH, STEP, TIME, &w));
#define W_(name, type, arr, n)                                      \
  do {                                                              \
    enum px_status s_ = px_checkpoint_write(w, name, type, n, arr); \
    if (s_ != PX_STATUS_OK) {                                       \
      px_checkpoint_writer_abort(w);                                \
      return s_;                                                    \
    }                                                               \
  } while (0)
  W_("u8", PX_DTYPE_U8, s_u8, 13);
  W_("i32", PX_DTYPE_I32, s_i32, 7);
  W_("u32", PX_DTYPE_U32, s_u32, 5);
  W_("i64", PX_DTYPE_I64, s_i64, 6);
  W_("u64", PX_DTYPE_U64, s_u64, 3);
  W_("f32", PX_DTYPE_F32, s_f32, 9);
  W_("f64", PX_DTYPE_F64, s_f64, 10);
  W_("empty/u8", PX_DTYPE_U8, NULL, 0);
  W_("empty/i32", PX_DTYPE_I32, NULL, 0);
  W_("empty/u32", PX_DTYPE_U32, NULL, 0);
  W_("empty/i64", PX_DTYPE_I64, NULL, 0);
  W_("empty/u64", PX_DTYPE_U64, NULL, 0);
  W_("empty/f32", PX_DTYPE_F32, NULL, 0);
  W_("empty/f64", PX_DTYPE_F64, NULL, 0);
  W_("big:f64", PX_DTYPE_F64, s_big, BIG_COUNT);
#undef W_
  return px_checkpoint_writer_commit(w);
}

static void test_every_dtype_round_trips_bit_for_bit(void) {
  const char *path = DIR_ "/all.chk";
  struct px_checkpoint *ck = NULL;
  time_t before = time(NULL), after;
  PX_CHECK_OK(ctx, write_sample(path));
  after = time(NULL);
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, path, &ck));
  if (!ck) return;
  PX_CHECK(strcmp(px_checkpoint_solver(ck), "granular") == 0);
  PX_CHECK(px_checkpoint_case_hash(ck) == HASH);
  PX_CHECK(px_checkpoint_step(ck) == STEP);
  PX_CHECK(memcmp(&(double){px_checkpoint_time(ck)}, &TIME, sizeof TIME) == 0);
  PX_CHECK(strcmp(px_checkpoint_version(ck), PX_VERSION_STRING) == 0);
  PX_CHECK(px_checkpoint_format_version(ck) == PX_CHECKPOINT_FORMAT_VERSION);
  PX_CHECK(px_checkpoint_created(ck) >= (uint64_t)before &&
           px_checkpoint_created(ck) <= (uint64_t)after);
  {
    uint8_t u8[13];
    int32_t i32[7];
    uint32_t u32[5];
    int64_t i64[6];
    uint64_t u64[3];
    float f32[9];
    double f64[10];
    double *big = malloc(BIG_COUNT * sizeof *big);
    PX_CHECK_OK(ctx, px_checkpoint_read(ck, "u8", PX_DTYPE_U8, 13, u8));
    PX_CHECK(memcmp(u8, s_u8, sizeof u8) == 0);
    PX_CHECK_OK(ctx, px_checkpoint_read(ck, "i32", PX_DTYPE_I32, 7, i32));
    PX_CHECK(memcmp(i32, s_i32, sizeof i32) == 0);
    PX_CHECK_OK(ctx, px_checkpoint_read(ck, "u32", PX_DTYPE_U32, 5, u32));
    PX_CHECK(memcmp(u32, s_u32, sizeof u32) == 0);
    PX_CHECK_OK(ctx, px_checkpoint_read(ck, "i64", PX_DTYPE_I64, 6, i64));
    PX_CHECK(memcmp(i64, s_i64, sizeof i64) == 0);
    PX_CHECK_OK(ctx, px_checkpoint_read(ck, "u64", PX_DTYPE_U64, 3, u64));
    PX_CHECK(memcmp(u64, s_u64, sizeof u64) == 0);
    PX_CHECK_OK(ctx, px_checkpoint_read(ck, "f32", PX_DTYPE_F32, 9, f32));
    PX_CHECK(memcmp(f32, s_f32, sizeof f32) == 0);
    PX_CHECK(signbit(f32[1]) && f32[1] == 0.0f && isnan(f32[6]));
    PX_CHECK_OK(ctx, px_checkpoint_read(ck, "f64", PX_DTYPE_F64, 10, f64));
    PX_CHECK(memcmp(f64, s_f64, sizeof f64) == 0);
    PX_CHECK(signbit(f64[1]) && f64[2] > 0.0 && isnan(f64[6]));
    PX_CHECK_OK(ctx, px_checkpoint_read(ck, "empty/f64", PX_DTYPE_F64, 0, NULL));
    PX_CHECK_OK(ctx, px_checkpoint_read(ck, "empty/u8", PX_DTYPE_U8, 0, NULL));
    PX_CHECK(big != NULL);
    if (big) {
      PX_CHECK_OK(ctx, px_checkpoint_read(ck, "big:f64", PX_DTYPE_F64, BIG_COUNT, big));
      PX_CHECK(memcmp(big, s_big, BIG_COUNT * sizeof *big) == 0);
      free(big);
    }
  }
  px_checkpoint_close(ck);
  PX_CHECK(ck_count_temps(DIR_, "all.chk") == 0);
}

static void test_sections_enumerate_in_write_order(void) {
  static const char *names[] = {"u8",        "i32",       "u32",       "i64",       "u64",
                                "f32",       "f64",       "empty/u8",  "empty/i32", "empty/u32",
                                "empty/i64", "empty/u64", "empty/f32", "empty/f64", "big:f64"};
  static const enum px_dtype types[] = {PX_DTYPE_U8,  PX_DTYPE_I32, PX_DTYPE_U32, PX_DTYPE_I64,
                                        PX_DTYPE_U64, PX_DTYPE_F32, PX_DTYPE_F64, PX_DTYPE_U8,
                                        PX_DTYPE_I32, PX_DTYPE_U32, PX_DTYPE_I64, PX_DTYPE_U64,
                                        PX_DTYPE_F32, PX_DTYPE_F64, PX_DTYPE_F64};
  static const uint64_t counts[] = {13, 7, 5, 6, 3, 9, 10, 0, 0, 0, 0, 0, 0, 0, BIG_COUNT};
  struct px_checkpoint *ck = NULL;
  size_t i;
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, DIR_ "/all.chk", &ck));
  if (!ck) return;
  PX_CHECK(px_checkpoint_section_count(ck) == 15);
  for (i = 0; i < 15; ++i) {
    const char *name = NULL;
    enum px_dtype t = PX_DTYPE_U8;
    uint64_t n = 99;
    PX_CHECK_OK(ctx, px_checkpoint_section(ck, i, &name, &t, &n));
    PX_CHECK_MSG(name && strcmp(name, names[i]) == 0, "section %zu is '%s'", i,
                 name ? name : "(null)");
    PX_CHECK(t == types[i]);
    PX_CHECK(n == counts[i]);
  }
  PX_CHECK_STATUS(ctx, px_checkpoint_section(ck, 15, NULL, NULL, NULL), PX_STATUS_INVALID);
  px_checkpoint_close(ck);
}

static void test_find_reports_type_and_count_or_lists_sections(void) {
  const char *path = DIR_ "/find.chk";
  struct px_checkpoint_writer *w = NULL;
  struct px_checkpoint *ck = NULL;
  float x[4] = {1, 2, 3, 4};
  enum px_dtype t;
  uint64_t n;
  PX_CHECK_OK(ctx, px_checkpoint_writer_open(ctx, path, "vortex", 1, 2, 3.0, &w));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "pos_x", PX_DTYPE_F32, 4, x));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "pos_y", PX_DTYPE_F32, 4, x));
  PX_CHECK_OK(ctx, px_checkpoint_writer_commit(w));
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, path, &ck));
  if (!ck) return;
  PX_CHECK_OK(ctx, px_checkpoint_find(ck, "pos_y", &t, &n));
  PX_CHECK(t == PX_DTYPE_F32 && n == 4);
  PX_CHECK_OK(ctx, px_checkpoint_find(ck, "pos_x", NULL, NULL));
  PX_CHECK_STATUS(ctx, px_checkpoint_find(ck, "gamma", &t, &n), PX_STATUS_NOT_FOUND);
  PX_CHECK_MSG(strcmp(px_context_message(ctx), DIR_ "/find.chk: no section 'gamma' (the file has "
                                                    "2: pos_x, pos_y)") == 0,
               "message: %s", px_context_message(ctx));
  PX_CHECK_STATUS(ctx, px_checkpoint_read(ck, "gamma", PX_DTYPE_F64, 1, x), PX_STATUS_NOT_FOUND);
  PX_CHECK(ck_contains(px_context_message(ctx), "pos_x, pos_y"));
  px_checkpoint_close(ck);
}

static void test_read_says_what_differs_in_type_or_count(void) {
  const char *path = DIR_ "/mismatch.chk";
  struct px_checkpoint_writer *w = NULL;
  struct px_checkpoint *ck = NULL;
  float *x = calloc(49872, sizeof *x);
  double *y = calloc(50000, sizeof *y);
  PX_CHECK_OK(ctx, px_checkpoint_writer_open(ctx, path, "vortex", 1, 2, 3.0, &w));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "pos_x", PX_DTYPE_F32, 49872, x));
  PX_CHECK_OK(ctx, px_checkpoint_writer_commit(w));
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, path, &ck));
  if (ck) {
    PX_CHECK_STATUS(ctx, px_checkpoint_read(ck, "pos_x", PX_DTYPE_F64, 50000, y), PX_STATUS_FORMAT);
    PX_CHECK_MSG(strcmp(px_context_message(ctx),
                        DIR_ "/mismatch.chk: section 'pos_x': expected 50000 f64, file has "
                             "49872 f32") == 0,
                 "message: %s", px_context_message(ctx));
    /* same type, other count; same count, other type */
    PX_CHECK_STATUS(ctx, px_checkpoint_read(ck, "pos_x", PX_DTYPE_F32, 49871, x), PX_STATUS_FORMAT);
    PX_CHECK(ck_contains(px_context_message(ctx), "expected 49871 f32, file has 49872 f32"));
    PX_CHECK_STATUS(ctx, px_checkpoint_read(ck, "pos_x", PX_DTYPE_I32, 49872, x), PX_STATUS_FORMAT);
    PX_CHECK(ck_contains(px_context_message(ctx), "expected 49872 i32, file has 49872 f32"));
    /* and the right request still works afterwards */
    PX_CHECK_OK(ctx, px_checkpoint_read(ck, "pos_x", PX_DTYPE_F32, 49872, x));
    px_checkpoint_close(ck);
  }
  free(x);
  free(y);
}

static void test_piecewise_write_and_read_equal_whole_ones(void) {
  const char *path = DIR_ "/chunks.chk";
  enum { N = 100003 };
  struct px_checkpoint_writer *w = NULL;
  struct px_checkpoint *ck = NULL;
  int64_t *a = malloc(N * sizeof *a), *b = malloc(N * sizeof *b);
  size_t i, done, step;
  uint64_t seed = 5;
  for (i = 0; i < N; ++i) a[i] = (int64_t)ck_rand(&seed);
  PX_CHECK_OK(ctx, px_checkpoint_writer_open(ctx, path, "lattice", 9, 10, 0.5, &w));
  PX_CHECK_OK(ctx, px_checkpoint_write_begin(w, "streamed", PX_DTYPE_I64, N));
  for (done = 0, step = 1; done < N; done += step, step = step * 3 + 1) {
    if (step > N - done) step = N - done;
    PX_CHECK_OK(ctx, px_checkpoint_write_chunk(w, a + done, step));
  }
  PX_CHECK_OK(ctx, px_checkpoint_write_end(w));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "whole", PX_DTYPE_I64, N, a));
  PX_CHECK_OK(ctx, px_checkpoint_writer_commit(w));
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, path, &ck));
  if (ck) {
    memset(b, 0, N * sizeof *b);
    PX_CHECK_OK(ctx, px_checkpoint_read(ck, "streamed", PX_DTYPE_I64, N, b));
    PX_CHECK(memcmp(a, b, N * sizeof *b) == 0);
    memset(b, 0, N * sizeof *b);
    PX_CHECK_OK(ctx, px_checkpoint_read_begin(ck, "whole", PX_DTYPE_I64, N));
    for (done = 0, step = 7; done < N; done += step, step *= 2) {
      if (step > N - done) step = N - done;
      PX_CHECK_OK(ctx, px_checkpoint_read_chunk(ck, b + done, step));
    }
    PX_CHECK_OK(ctx, px_checkpoint_read_end(ck));
    PX_CHECK(memcmp(a, b, N * sizeof *b) == 0);
    /* reading past the end, or ending early, is a wrong call */
    PX_CHECK_OK(ctx, px_checkpoint_read_begin(ck, "whole", PX_DTYPE_I64, N));
    PX_CHECK_STATUS(ctx, px_checkpoint_read_chunk(ck, b, N + 1), PX_STATUS_INVALID);
    PX_CHECK_OK(ctx, px_checkpoint_read_begin(ck, "whole", PX_DTYPE_I64, N));
    PX_CHECK_OK(ctx, px_checkpoint_read_chunk(ck, b, 10));
    PX_CHECK_STATUS(ctx, px_checkpoint_read_end(ck), PX_STATUS_INVALID);
    PX_CHECK(ck_contains(px_context_message(ctx), "after 10 of its 100003 elements"));
    px_checkpoint_close(ck);
  }
  free(a);
  free(b);
}

/* Each wrong call fails, poisons the writer (commit refuses), leaves the
 * previous checkpoint in place and no temporary behind. */
static void check_wrong_call(int which) {
  const char *path = DIR_ "/all.chk";
  struct px_checkpoint_writer *w = NULL;
  struct px_checkpoint *ck = NULL;
  double v[4] = {1, 2, 3, 4};
  enum px_status s = PX_STATUS_OK;
  char long_name[80];
  memset(long_name, 'n', 64);
  long_name[64] = '\0';
  PX_CHECK_OK(ctx, px_checkpoint_writer_open(ctx, path, "granular", 1, 1, 1.0, &w));
  if (!w) return;
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "v", PX_DTYPE_F64, 4, v));
  switch (which) {
    case 0:
      s = px_checkpoint_write(w, "v", PX_DTYPE_F64, 4, v);
      PX_CHECK(ck_contains(px_context_message(ctx), "section 'v' written twice"));
      break;
    case 1: s = px_checkpoint_write(w, "", PX_DTYPE_F64, 4, v); break;
    case 2: s = px_checkpoint_write(w, long_name, PX_DTYPE_F64, 4, v); break;
    case 3: s = px_checkpoint_write(w, "a b", PX_DTYPE_F64, 4, v); break;
    case 4: s = px_checkpoint_write(w, "t", (enum px_dtype)99, 4, v); break;
    case 5: s = px_checkpoint_write(w, "nodata", PX_DTYPE_F64, 4, NULL); break;
    case 6:
      PX_CHECK_OK(ctx, px_checkpoint_write_begin(w, "c", PX_DTYPE_F64, 3));
      s = px_checkpoint_write_chunk(w, v, 4);
      break;
    case 7:
      PX_CHECK_OK(ctx, px_checkpoint_write_begin(w, "c", PX_DTYPE_F64, 3));
      PX_CHECK_OK(ctx, px_checkpoint_write_chunk(w, v, 2));
      s = px_checkpoint_write_end(w);
      PX_CHECK(ck_contains(px_context_message(ctx), "after 2 of its 3 elements"));
      break;
    case 8:
      PX_CHECK_OK(ctx, px_checkpoint_write_begin(w, "c", PX_DTYPE_F64, 3));
      s = px_checkpoint_write(w, "d", PX_DTYPE_F64, 1, v);
      break;
    case 9:
      PX_CHECK_OK(ctx, px_checkpoint_write_begin(w, "c", PX_DTYPE_F64, 3));
      s = px_checkpoint_write_end(w);
      break;
  }
  PX_CHECK_MSG(s == PX_STATUS_INVALID, "wrong call %d returned %s", which, px_status_name(s));
  PX_CHECK_STATUS(ctx, px_checkpoint_writer_commit(w), PX_STATUS_INVALID);
  PX_CHECK(ck_contains(px_context_message(ctx), "not written"));
  PX_CHECK(ck_count_temps(DIR_, "all.chk") == 0);
  /* the previous checkpoint is intact */
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, path, &ck));
  PX_CHECK(px_checkpoint_step(ck) == STEP);
  px_checkpoint_close(ck);
}

static void test_wrong_writer_calls_fail_and_keep_the_previous_checkpoint(void) {
  int i;
  for (i = 0; i < 10; ++i) check_wrong_call(i);
  /* commit with a section still open */
  {
    struct px_checkpoint_writer *w = NULL;
    PX_CHECK_OK(ctx, px_checkpoint_writer_open(ctx, DIR_ "/all.chk", "granular", 1, 1, 1.0, &w));
    PX_CHECK_OK(ctx, px_checkpoint_write_begin(w, "open", PX_DTYPE_U8, 1));
    PX_CHECK_STATUS(ctx, px_checkpoint_writer_commit(w), PX_STATUS_INVALID);
    PX_CHECK(ck_contains(px_context_message(ctx), "section 'open' was begun but not ended"));
  }
  /* bad solver names */
  {
    struct px_checkpoint_writer *w = NULL;
    PX_CHECK_STATUS(ctx, px_checkpoint_writer_open(ctx, DIR_ "/x.chk", "", 1, 1, 1.0, &w),
                    PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx, px_checkpoint_writer_open(ctx, DIR_ "/x.chk", NULL, 1, 1, 1.0, &w),
                    PX_STATUS_INVALID);
    PX_CHECK(w == NULL);
  }
  PX_CHECK(ck_count_temps(DIR_, "all.chk") == 0);
  px_checkpoint_writer_abort(NULL);
}

static void test_abort_leaves_no_file(void) {
  struct px_checkpoint_writer *w = NULL;
  double v = 1;
  PX_CHECK_OK(ctx, px_checkpoint_writer_open(ctx, DIR_ "/aborted.chk", "granular", 1, 1, 1.0, &w));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "v", PX_DTYPE_F64, 1, &v));
  PX_CHECK(ck_count_temps(DIR_, "aborted.chk") == 1);
  px_checkpoint_writer_abort(w);
  PX_CHECK(!px_file_exists(DIR_ "/aborted.chk"));
  PX_CHECK(ck_count_temps(DIR_, "aborted.chk") == 0);
}

static void test_a_checkpoint_without_sections_is_valid(void) {
  struct px_checkpoint_writer *w = NULL;
  struct px_checkpoint *ck = NULL;
  PX_CHECK_OK(ctx, px_checkpoint_writer_open(ctx, DIR_ "/none.chk", "lattice", 0, 0, 0.0, &w));
  PX_CHECK_OK(ctx, px_checkpoint_writer_commit(w));
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, DIR_ "/none.chk", &ck));
  PX_CHECK(px_checkpoint_section_count(ck) == 0);
  PX_CHECK_STATUS(ctx, px_checkpoint_find(ck, "x", NULL, NULL), PX_STATUS_NOT_FOUND);
  PX_CHECK(ck_contains(px_context_message(ctx), "the file has no sections"));
  px_checkpoint_close(ck);
}

static void test_missing_files_and_directories_are_io_errors(void) {
  struct px_checkpoint *ck = NULL;
  struct px_checkpoint_writer *w = NULL;
  PX_CHECK_STATUS(ctx, px_checkpoint_open(ctx, DIR_ "/absent.chk", &ck), PX_STATUS_IO);
  PX_CHECK(ck_contains(px_context_message(ctx), "absent.chk: No such file or directory"));
  PX_CHECK_STATUS(ctx, px_checkpoint_open(ctx, DIR_, &ck), PX_STATUS_IO);
  PX_CHECK(ck_contains(px_context_message(ctx), "not a regular file"));
  PX_CHECK(ck == NULL);
  PX_CHECK_STATUS(
      ctx, px_checkpoint_writer_open(ctx, DIR_ "/no/such/dir/x.chk", "granular", 1, 1, 1.0, &w),
      PX_STATUS_IO);
  PX_CHECK(ck_contains(px_context_message(ctx), "cannot write " DIR_ "/no/such/dir/x.chk"));
  PX_CHECK(w == NULL);
}

/* Validation streams through a fixed buffer: opening a 12 MB file must not
 * allocate anything near its size. */
static void test_open_uses_bounded_memory(void) {
  struct px_context *c2 = NULL;
  struct px_checkpoint_writer *w = NULL;
  struct px_checkpoint *ck = NULL;
  size_t n = (size_t)1 << 19;
  double *v = calloc(n, sizeof *v);
  PX_CHECK_OK(ctx, px_checkpoint_writer_open(ctx, DIR_ "/large.chk", "granular", 1, 1, 1.0, &w));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "a", PX_DTYPE_F64, n, v));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "b", PX_DTYPE_F64, n, v));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "c", PX_DTYPE_F64, n, v));
  PX_CHECK_OK(ctx, px_checkpoint_writer_commit(w));
  px_context_create(&c2);
  PX_CHECK_OK(c2, px_checkpoint_open(c2, DIR_ "/large.chk", &ck));
  PX_CHECK_MSG(px_mem_peak(c2, NULL) <= ((size_t)1 << 20) + 8192,
               "peak %zu bytes while validating a 12 MB file", px_mem_peak(c2, NULL));
  px_checkpoint_close(ck);
  PX_CHECK(px_mem_current(c2, NULL) == 0);
  px_context_free(c2);
  free(v);
}

int main(void) {
  px_context_create(&ctx);
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  ck_scratch(DIR_);
  fill_sample();
  test_every_dtype_round_trips_bit_for_bit();
  test_sections_enumerate_in_write_order();
  test_find_reports_type_and_count_or_lists_sections();
  test_read_says_what_differs_in_type_or_count();
  test_piecewise_write_and_read_equal_whole_ones();
  test_wrong_writer_calls_fail_and_keep_the_previous_checkpoint();
  test_abort_leaves_no_file();
  test_a_checkpoint_without_sections_is_valid();
  test_missing_files_and_directories_are_io_errors();
  test_open_uses_bounded_memory();
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  free(s_big);
  px_context_free(ctx);
  ck_rm_rf(DIR_);
  return px_test_report("test_checkpoint_roundtrip");
}
