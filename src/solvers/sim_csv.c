/* The CSV files of the solvers' outputs: their headers and how a resumed
 * run continues them (struct px_sim_output). */
#include <stdarg.h>
#include <stdio.h>

#include "partix/csv.h"
#include "partix/file.h"
#include "partix/memory.h"
#include "solvers/solver.h"

enum px_status px_sim_columns_alloc(struct px_context *ctx, struct px_sim_columns *c, size_t n) {
  c->n = n;
  c->name = px_mem_calloc(ctx, "csv header", n ? n : 1, sizeof *c->name);
  c->text = px_mem_calloc(ctx, "csv header", n ? n : 1, sizeof *c->text);
  if (!c->name || !c->text) {
    px_sim_columns_free(ctx, c);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (a CSV header of %zu columns)", n);
  }
  for (size_t i = 0; i < n; ++i) c->name[i] = c->text[i];
  return PX_STATUS_OK;
}

void px_sim_columns_set(struct px_sim_columns *c, size_t i, const char *fmt, ...) {
  va_list ap;
  if (i >= c->n) return;
  va_start(ap, fmt);
  vsnprintf(c->text[i], sizeof c->text[i], fmt, ap);
  va_end(ap);
}

void px_sim_columns_free(struct px_context *ctx, struct px_sim_columns *c) {
  px_mem_free(ctx, c->name);
  px_mem_free(ctx, c->text);
  c->name = NULL;
  c->text = NULL;
  c->n = 0;
}

enum px_status px_sim_csv_open(struct px_context *ctx, const struct px_sim_output *o,
                               const char *name, size_t ncols, const char *const *names,
                               double keep, struct px_csv **out) {
  char path[4096]; /* as long as a path the file layer accepts */
  PX_TRY(px_file_join(ctx, path, sizeof path, o->dir, name));
  PX_TRY(o->resumed ? px_csv_open_resume(ctx, path, ncols, names, keep, out)
                    : px_csv_open(ctx, path, ncols, names, out));
  return o->sim ? px_sim_series_tap(o->sim, name, ncols, names, *out) : PX_STATUS_OK;
}
