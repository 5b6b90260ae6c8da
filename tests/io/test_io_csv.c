/* CSV time series: header + rows, resume truncation, header mismatch,
 * torn last line, precision, and one-shot tables read back exactly. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/ioutil.h"
#include "partix/csv.h"
#include "px_test.h"

static const char *const names[3] = {"t [s]", "Cx", "Cy"};

static char *slurp(struct px_context *ctx, const char *path) {
  char *text = NULL;
  if (px_ioutil_read_file(ctx, path, &text, NULL) != PX_STATUS_OK) return NULL;
  return text;
}

static size_t count_lines(const char *s) {
  size_t n = 0;
  for (; *s; ++s) n += *s == '\n';
  return n;
}

static void test_series_has_header_and_whole_rows(struct px_context *ctx) {
  struct px_csv *csv = NULL;
  char *text;
  int i;
  PX_CHECK_OK(ctx, px_csv_open(ctx, "series.csv", 3, names, &csv));
  for (i = 0; i < 10; ++i) {
    double t = 0.1 * i, row[3];
    row[0] = t;
    row[1] = 2.0 * t;
    row[2] = -t;
    PX_CHECK_OK(ctx, px_csv_row(csv, row));
  }
  PX_CHECK(px_csv_rows(csv) == 10);
  /* Rows are in the file before close (a crashed run keeps them). */
  text = slurp(ctx, "series.csv");
  PX_CHECK(text && count_lines(text) == 11);
  px_mem_free(ctx, text);
  PX_CHECK_OK(ctx, px_csv_close(csv));
  text = slurp(ctx, "series.csv");
  PX_CHECK(text != NULL);
  if (text) {
    PX_CHECK(strncmp(text, "t [s],Cx,Cy\n0,0,0\n0.1,0.2,-0.1\n", 31) == 0);
    /* 0.1*3 = 0.30000000000000004 prints as 0.3 with 10 digits */
    PX_CHECK(strstr(text, "\n0.3,0.6,-0.3\n") != NULL);
    PX_CHECK(strstr(text, "\n0.9,1.8,-0.9\n") != NULL);
  }
  px_mem_free(ctx, text);
}

static void test_resume_keeps_rows_up_to_time_and_appends(struct px_context *ctx) {
  struct px_csv *csv = NULL;
  double row[3] = {0.5, 1.0, -0.5};
  char *text;
  FILE *f;
  PX_CHECK_OK(ctx, px_csv_open_resume(ctx, "series.csv", 3, names, 0.45, &csv));
  PX_CHECK(px_csv_rows(csv) == 5); /* t = 0, 0.1, 0.2, 0.3, 0.4 */
  PX_CHECK_OK(ctx, px_csv_row(csv, row));
  PX_CHECK(px_csv_rows(csv) == 6);
  PX_CHECK_OK(ctx, px_csv_close(csv));
  text = slurp(ctx, "series.csv");
  PX_CHECK(text && count_lines(text) == 7);
  PX_CHECK(text && strstr(text, "\n0.4,0.8,-0.4\n0.5,1,-0.5\n") != NULL);
  PX_CHECK(text && strstr(text, "0.9") == NULL);
  px_mem_free(ctx, text);

  /* A torn last line (a crash in the middle of a write) is dropped. */
  f = fopen("series.csv", "ab");
  fputs("0.6,1.2", f);
  fclose(f);
  PX_CHECK_OK(ctx, px_csv_open_resume(ctx, "series.csv", 3, names, 100.0, &csv));
  PX_CHECK(px_csv_rows(csv) == 6);
  row[0] = 0.6;
  PX_CHECK_OK(ctx, px_csv_row(csv, row));
  PX_CHECK_OK(ctx, px_csv_close(csv));
  text = slurp(ctx, "series.csv");
  PX_CHECK(text && count_lines(text) == 8);
  PX_CHECK(text && strstr(text, "0.6,1.20.6") == NULL);
  PX_CHECK(text && strstr(text, "\n0.5,1,-0.5\n0.6,1,-0.5\n") != NULL);
  px_mem_free(ctx, text);

  /* Resuming where no file exists starts a new one. */
  remove("fresh.csv");
  PX_CHECK_OK(ctx, px_csv_open_resume(ctx, "fresh.csv", 3, names, 1.0, &csv));
  PX_CHECK(px_csv_rows(csv) == 0);
  PX_CHECK_OK(ctx, px_csv_close(csv));
  text = slurp(ctx, "fresh.csv");
  PX_CHECK(text && strcmp(text, "t [s],Cx,Cy\n") == 0);
  px_mem_free(ctx, text);
}

static void test_resume_with_other_columns_is_an_error(struct px_context *ctx) {
  static const char *const other[3] = {"t [s]", "Cx", "Cz"};
  struct px_csv *csv = NULL;
  char *before = slurp(ctx, "series.csv"), *after;
  PX_CHECK_STATUS(ctx, px_csv_open_resume(ctx, "series.csv", 3, other, 0.2, &csv),
                  PX_STATUS_FORMAT);
  PX_CHECK(csv == NULL);
  PX_CHECK(strstr(px_context_message(ctx), "series.csv") != NULL);
  PX_CHECK(strstr(px_context_message(ctx), "\"t [s],Cx,Cy\"") != NULL);
  PX_CHECK(strstr(px_context_message(ctx), "\"t [s],Cx,Cz\"") != NULL);
  after = slurp(ctx, "series.csv");
  PX_CHECK(before && after && strcmp(before, after) == 0); /* untouched */
  px_mem_free(ctx, before);
  px_mem_free(ctx, after);
  /* Fewer columns is a mismatch as well. */
  PX_CHECK_STATUS(ctx, px_csv_open_resume(ctx, "series.csv", 2, names, 0.2, &csv),
                  PX_STATUS_FORMAT);
}

static void test_precision_17_round_trips(struct px_context *ctx) {
  struct px_csv *csv = NULL;
  double row[3] = {1.0 / 3.0, 0.1, -2.0 / 7.0};
  char *text;
  PX_CHECK_OK(ctx, px_csv_open(ctx, "exact.csv", 3, names, &csv));
  PX_CHECK_STATUS(ctx, px_csv_set_precision(csv, 18), PX_STATUS_INVALID);
  PX_CHECK_OK(ctx, px_csv_set_precision(csv, 17));
  PX_CHECK_OK(ctx, px_csv_row(csv, row));
  PX_CHECK_OK(ctx, px_csv_close(csv));
  text = slurp(ctx, "exact.csv");
  if (text) {
    double a = 0, b = 0, c = 0;
    PX_CHECK(sscanf(text, "t [s],Cx,Cy\n%lf,%lf,%lf\n", &a, &b, &c) == 3);
    PX_CHECK(a == 1.0 / 3.0 && b == 0.1 && c == -2.0 / 7.0);
    PX_CHECK(strstr(text, "\n0.33333333333333331,") != NULL);
  }
  PX_CHECK(text != NULL);
  px_mem_free(ctx, text);
}

static void test_table_round_trip(struct px_context *ctx) {
  static const char *const tnames[3] = {"segment", "s [m], arc", "E \"impact\" [J]"};
  double seg[50], s[50], e[50];
  const double *cols[3];
  char *text, *p;
  size_t i;
  int ok = 1;
  for (i = 0; i < 50; ++i) {
    seg[i] = (double)i;
    s[i] = 0.1 * (double)i;
    e[i] = exp(-(double)i / 7.0);
  }
  cols[0] = seg, cols[1] = s, cols[2] = e;
  PX_CHECK_OK(ctx, px_csv_write_table(ctx, "table.csv", 3, tnames, 50, cols, 17));
  text = slurp(ctx, "table.csv");
  PX_CHECK(text != NULL);
  if (!text) return;
  PX_CHECK(strncmp(text, "segment,\"s [m], arc\",\"E \"\"impact\"\" [J]\"\n", 40) == 0);
  PX_CHECK(count_lines(text) == 51);
  p = strchr(text, '\n') + 1;
  for (i = 0; i < 50 && ok; ++i) {
    char *end;
    ok = strtod(p, &end) == seg[i] && *end == ',';
    ok = ok && strtod(end + 1, &end) == s[i] && *end == ',';
    ok = ok && strtod(end + 1, &end) == e[i] && *end == '\n';
    p = end + 1;
  }
  PX_CHECK_MSG(ok, "row %zu differs", i - 1);
  px_mem_free(ctx, text);
  /* Bad arguments are errors with a message. */
  cols[1] = NULL;
  PX_CHECK_STATUS(ctx, px_csv_write_table(ctx, "table.csv", 3, tnames, 50, cols, 17),
                  PX_STATUS_INVALID);
  PX_CHECK(strstr(px_context_message(ctx), "column 2") != NULL);
}

int main(void) {
  struct px_context *ctx = NULL;
  px_context_create(&ctx);
  test_series_has_header_and_whole_rows(ctx);
  test_resume_keeps_rows_up_to_time_and_appends(ctx);
  test_resume_with_other_columns_is_an_error(ctx);
  test_precision_17_round_trips(ctx);
  test_table_round_trip(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  return px_test_report("test_io_csv");
}
