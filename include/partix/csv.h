/* CSV time series (loads, energies, diagnostics) and one-shot tables.
 *
 * A time series file has one header row with the column names and one row
 * per call of px_csv_row. The header is written atomically when the file is
 * created; each row is then appended with a single write and flushed, and a
 * failed write (e.g. a full disk) is cut back, so the file always holds whole
 * rows. A resumed run reopens the file, keeps the rows whose first column is
 * <= the resume value and appends after them. */
#ifndef PARTIX_CSV_H
#define PARTIX_CSV_H

#include <stddef.h>

#include "partix/context.h"
#include "partix/export.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_csv;

/* Create (or replace) `path` with a header row of ncols names (copied; a name
 * with a comma or a quote is quoted as in RFC 4180). */
PX_API enum px_status px_csv_open(struct px_context *ctx, const char *path, size_t ncols,
                                  const char *const names[], struct px_csv **out);
/* Continue the series of a resumed run. If `path` exists its header must be
 * exactly the one these names give (otherwise PX_STATUS_FORMAT, with both
 * headers in the message); the rows whose first column is <= resume_value are
 * kept (the file is rewritten atomically first, dropping later rows and any
 * torn last line) and new rows are appended after them. A missing file is
 * created as by px_csv_open. */
PX_API enum px_status px_csv_open_resume(struct px_context *ctx, const char *path, size_t ncols,
                                         const char *const names[], double resume_value,
                                         struct px_csv **out);
/* Significant digits of the values (%.Ng): 10 by default; 17 round-trips
 * doubles exactly. 1 <= digits <= 17. */
PX_API enum px_status px_csv_set_precision(struct px_csv *csv, int digits);
/* Append one row of ncols values and flush it to the file. */
PX_API enum px_status px_csv_row(struct px_csv *csv, const double *values);
/* Told every row px_csv_row has written, with its values as computed (the
 * file prints them with `digits` digits): keeps the series in memory
 * (partix/results.h). A failure it returns is px_csv_row's. */
typedef enum px_status (*px_csv_tap)(void *user, size_t ncols, const double *values);
PX_API void px_csv_set_tap(struct px_csv *csv, px_csv_tap fn, void *user);
/* Number of data rows in the file (kept on resume + appended). */
PX_API size_t px_csv_rows(const struct px_csv *csv);
/* Close and free; returns the status of the final close. NULL-safe. */
PX_API enum px_status px_csv_close(struct px_csv *csv);

/* Write a whole table atomically: a header row and nrows rows, column c
 * given by columns[c][0..nrows-1] (structure of arrays). `digits` as in
 * px_csv_set_precision (0 = default 10). */
PX_API enum px_status px_csv_write_table(struct px_context *ctx, const char *path, size_t ncols,
                                         const char *const names[], size_t nrows,
                                         const double *const columns[], int digits);

#ifdef __cplusplus
}
#endif
#endif
