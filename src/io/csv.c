/* CSV writer. Rows are appended with write(2) on an O_APPEND descriptor
 * (no stdio buffer that could hold half a row after an error); a failed or
 * short write is cut back with ftruncate to the last whole row. */
#include "partix/csv.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <unistd.h>

#include "io/ioutil.h"
#include "partix/file.h"
#include "partix/memory.h"

#define PX_CSV_DEFAULT_DIGITS 10
/* Longest "%.17g" of a double: "-1.2345678901234567e-308" (24) + ',' */
#define PX_CSV_VALUE_MAX 32

struct px_csv {
  struct px_context *ctx; /* borrowed */
  char *path;             /* owned */
  int fd;                 /* owned, O_APPEND */
  size_t ncols;
  int digits;
  size_t rows;
  off_t size; /* bytes of the file up to the last whole row */
  char *line; /* owned scratch for one row */
  size_t line_cap;
  px_csv_tap tap; /* told each row written (px_csv_set_tap), NULL none */
  void *tap_user;
};

/* The header row (with '\n') in px_mem memory. */
static enum px_status px_csv_header(struct px_context *ctx, size_t ncols, const char *const names[],
                                    char **out, size_t *len) {
  size_t cap = 2, i, n = 0;
  char *h;
  *out = NULL;
  if (ncols == 0 || !names)
    return px_context_fail(ctx, PX_STATUS_INVALID, "a CSV file needs at least one column");
  for (i = 0; i < ncols; ++i) {
    if (!names[i] || !names[i][0])
      return px_context_fail(ctx, PX_STATUS_INVALID, "CSV column %zu has no name", i + 1);
    cap += 2 * strlen(names[i]) + 3;
  }
  h = px_mem_alloc(ctx, "csv", cap);
  if (!h) return PX_STATUS_NOMEM;
  for (i = 0; i < ncols; ++i) {
    const char *s = names[i];
    int quote = strpbrk(s, ",\"\r\n") != NULL;
    if (i) h[n++] = ',';
    if (quote) h[n++] = '"';
    for (; *s; ++s) {
      if (*s == '"') h[n++] = '"';
      h[n++] = *s;
    }
    if (quote) h[n++] = '"';
  }
  h[n++] = '\n';
  h[n] = '\0';
  *out = h;
  *len = n;
  return PX_STATUS_OK;
}

static void px_csv_free(struct px_csv *c) {
  if (!c) return;
  if (c->fd >= 0) close(c->fd);
  px_mem_free(c->ctx, c->line);
  px_mem_free(c->ctx, c->path);
  px_mem_free(c->ctx, c);
}

/* Open the (complete) file for appending rows after its `size` bytes. */
static enum px_status px_csv_attach(struct px_context *ctx, const char *path, size_t ncols,
                                    off_t size, size_t rows, struct px_csv **out) {
  struct px_csv *c = px_mem_calloc(ctx, "csv", 1, sizeof *c);
  if (!c) return PX_STATUS_NOMEM;
  c->ctx = ctx;
  c->fd = -1;
  c->ncols = ncols;
  c->digits = PX_CSV_DEFAULT_DIGITS;
  c->rows = rows;
  c->size = size;
  c->line_cap = ncols * PX_CSV_VALUE_MAX + 2;
  c->path = px_ioutil_strdup(ctx, "csv", path);
  c->line = px_mem_alloc(ctx, "csv", c->line_cap);
  if (!c->path || !c->line) {
    px_csv_free(c);
    return PX_STATUS_NOMEM;
  }
  c->fd = open(path, O_WRONLY | O_APPEND);
  if (c->fd < 0) {
    enum px_status s = px_context_fail(ctx, PX_STATUS_IO, "cannot open %s for appending: %s", path,
                                       strerror(errno));
    px_csv_free(c);
    return s;
  }
  *out = c;
  return PX_STATUS_OK;
}

enum px_status px_csv_open(struct px_context *ctx, const char *path, size_t ncols,
                           const char *const names[], struct px_csv **out) {
  char *header;
  size_t len;
  enum px_status s;
  if (!ctx || !path || !out) return PX_STATUS_INVALID;
  *out = NULL;
  PX_TRY(px_csv_header(ctx, ncols, names, &header, &len));
  s = px_file_write_all(ctx, path, header, len);
  px_mem_free(ctx, header);
  PX_TRY(s);
  return px_csv_attach(ctx, path, ncols, (off_t)len, 0, out);
}

enum px_status px_csv_open_resume(struct px_context *ctx, const char *path, size_t ncols,
                                  const char *const names[], double resume_value,
                                  struct px_csv **out) {
  char *header = NULL, *text = NULL, *p, *nl;
  size_t hlen, tlen, rows = 0, lineno = 1, keep;
  enum px_status s;
  if (!ctx || !path || !out) return PX_STATUS_INVALID;
  *out = NULL;
  PX_TRY(px_csv_header(ctx, ncols, names, &header, &hlen));
  s = px_ioutil_read_file(ctx, path, &text, &tlen);
  if (s == PX_STATUS_NOT_FOUND) {
    px_context_clear(ctx);
    px_mem_free(ctx, header);
    return px_csv_open(ctx, path, ncols, names, out);
  }
  if (s != PX_STATUS_OK) {
    px_mem_free(ctx, header);
    return s;
  }
  /* The header must match exactly (ignoring a '\r' before the newline). */
  nl = strchr(text, '\n');
  {
    size_t have = nl ? (size_t)(nl - text) : strlen(text);
    if (have && text[have - 1] == '\r') --have;
    if (!nl || have != hlen - 1 || memcmp(text, header, have) != 0) {
      header[hlen - 1] = '\0';
      if (nl) *nl = '\0';
      s = px_context_fail(ctx, PX_STATUS_FORMAT,
                          "%s: cannot resume: its header is \"%.200s\" but this run writes "
                          "\"%.200s\" (move the old file away or resume the run that wrote it)",
                          path, text, header);
      px_mem_free(ctx, header);
      px_mem_free(ctx, text);
      return s;
    }
  }
  keep = (size_t)(nl - text) + 1;
  /* Keep whole rows up to the first one past resume_value. */
  for (p = nl + 1; *p; p = nl + 1) {
    char *end;
    double first;
    ++lineno;
    nl = strchr(p, '\n');
    if (!nl) break;                                       /* torn last line from a crash: dropped */
    if (nl == p || (nl == p + 1 && *p == '\r')) continue; /* blank line: dropped */
    first = strtod(p, &end);
    if (end == p) {
      *nl = '\0';
      s = px_context_fail(ctx, PX_STATUS_FORMAT,
                          "%s:%zu: cannot resume: the first column of \"%.80s\" is not a number",
                          path, lineno, p);
      px_mem_free(ctx, header);
      px_mem_free(ctx, text);
      return s;
    }
    if (!(first <= resume_value)) break;
    if ((size_t)(p - text) != keep) memmove(text + keep, p, (size_t)(nl - p) + 1);
    keep += (size_t)(nl - p) + 1;
    ++rows;
  }
  s = PX_STATUS_OK;
  if (keep != tlen) s = px_file_write_all(ctx, path, text, keep);
  px_mem_free(ctx, header);
  px_mem_free(ctx, text);
  PX_TRY(s);
  return px_csv_attach(ctx, path, ncols, (off_t)keep, rows, out);
}

enum px_status px_csv_set_precision(struct px_csv *csv, int digits) {
  if (!csv) return PX_STATUS_INVALID;
  if (digits < 1 || digits > 17)
    return px_context_fail(csv->ctx, PX_STATUS_INVALID,
                           "CSV precision %d digits (expected 1 to 17)", digits);
  csv->digits = digits;
  return PX_STATUS_OK;
}

/* Format values as one CSV row (with '\n') into buf of at least
 * ncols*PX_CSV_VALUE_MAX+2 bytes; returns its length. */
static size_t px_csv_format(char *buf, size_t ncols, const double *values, int digits) {
  size_t n = 0, i;
  for (i = 0; i < ncols; ++i) {
    int w;
    if (i) buf[n++] = ',';
    /* -0 is written as 0 */
    w = snprintf(buf + n, PX_CSV_VALUE_MAX, "%.*g", digits, values[i] == 0.0 ? 0.0 : values[i]);
    if (w > 0) n += (size_t)w;
  }
  buf[n++] = '\n';
  return n;
}

enum px_status px_csv_row(struct px_csv *csv, const double *values) {
  size_t len, done = 0;
  if (!csv || !values) return PX_STATUS_INVALID;
  len = px_csv_format(csv->line, csv->ncols, values, csv->digits);
  while (done < len) {
    ssize_t w = write(csv->fd, csv->line + done, len - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      int err = w < 0 ? errno : EIO;
      /* Cut a partly written row so the file keeps whole rows only. */
      int cut = ftruncate(csv->fd, csv->size);
      return px_context_fail(csv->ctx, PX_STATUS_IO, "cannot append a row to %s: %s (%s)",
                             csv->path, strerror(err),
                             cut == 0 ? "the file keeps its previous rows"
                                      : "and the partial row could not be removed");
    }
    done += (size_t)w;
  }
  csv->size += (off_t)len;
  ++csv->rows;
  if (csv->tap) return csv->tap(csv->tap_user, csv->ncols, values);
  return PX_STATUS_OK;
}

void px_csv_set_tap(struct px_csv *csv, px_csv_tap fn, void *user) {
  if (!csv) return;
  csv->tap = fn;
  csv->tap_user = user;
}

size_t px_csv_rows(const struct px_csv *csv) { return csv ? csv->rows : 0; }

enum px_status px_csv_close(struct px_csv *csv) {
  enum px_status s = PX_STATUS_OK;
  if (!csv) return PX_STATUS_OK;
  if (fsync(csv->fd) != 0 && errno != EINVAL && errno != EROFS)
    s = px_context_fail(csv->ctx, PX_STATUS_IO, "cannot sync %s: %s", csv->path, strerror(errno));
  if (close(csv->fd) != 0 && s == PX_STATUS_OK)
    s = px_context_fail(csv->ctx, PX_STATUS_IO, "cannot close %s: %s", csv->path, strerror(errno));
  csv->fd = -1;
  px_csv_free(csv);
  return s;
}

enum px_status px_csv_write_table(struct px_context *ctx, const char *path, size_t ncols,
                                  const char *const names[], size_t nrows,
                                  const double *const columns[], int digits) {
  char *header, *line;
  double *row;
  size_t len, r, c;
  struct px_file *file;
  FILE *f;
  enum px_status s = PX_STATUS_OK;
  if (!ctx || !path) return PX_STATUS_INVALID;
  if (digits == 0) digits = PX_CSV_DEFAULT_DIGITS;
  if (digits < 1 || digits > 17)
    return px_context_fail(ctx, PX_STATUS_INVALID, "%s: CSV precision %d digits (expected 1 to 17)",
                           path, digits);
  if (nrows && !columns)
    return px_context_fail(ctx, PX_STATUS_INVALID, "%s: no columns given", path);
  for (c = 0; nrows && c < ncols; ++c)
    if (!columns[c])
      return px_context_fail(ctx, PX_STATUS_INVALID, "%s: column %zu (%s) is NULL", path, c + 1,
                             names && names[c] ? names[c] : "?");
  PX_TRY(px_csv_header(ctx, ncols, names, &header, &len));
  line = px_mem_alloc(ctx, "csv", ncols * PX_CSV_VALUE_MAX + 2);
  row = px_mem_alloc(ctx, "csv", ncols * sizeof *row);
  if (!line || !row) {
    px_mem_free(ctx, header);
    px_mem_free(ctx, line);
    px_mem_free(ctx, row);
    return PX_STATUS_NOMEM;
  }
  s = px_file_open(ctx, path, &file);
  if (s == PX_STATUS_OK) {
    f = px_file_stream(file);
    if (fwrite(header, 1, len, f) != len) s = PX_STATUS_IO;
    for (r = 0; r < nrows && s == PX_STATUS_OK; ++r) {
      size_t n;
      for (c = 0; c < ncols; ++c) row[c] = columns[c][r];
      n = px_csv_format(line, ncols, row, digits);
      if (fwrite(line, 1, n, f) != n) s = PX_STATUS_IO;
    }
    if (s != PX_STATUS_OK) {
      s = px_context_fail(ctx, PX_STATUS_IO,
                          "cannot write %s: %s (the previous file, if any, is kept)", path,
                          strerror(errno));
      px_file_abort(file);
    } else {
      s = px_file_commit(file);
    }
  }
  px_mem_free(ctx, header);
  px_mem_free(ctx, line);
  px_mem_free(ctx, row);
  return s;
}
