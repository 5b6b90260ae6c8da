/* Checkpoints of the granular solver: the system (system.c), the state of
 * the run's series (centre-of-mass travel) and the rows of the series so far
 * (granular.plot: the end-of-run plots and summary.json cover the whole run,
 * also when it was resumed). */
#include <math.h>
#include <string.h>

#include "partix/checkpoint.h"
#include "partix/memory.h"
#include "solvers/granular/granular_impl.h"

enum px_status px_gran_save(struct px_gran_run *r, struct px_checkpoint_writer *w) {
  double v[8], last[PX_GRAN_PLOT_NCOL + 1];
  PX_TRY(px_gran_sync(r));
  PX_TRY(px_gran_sys_save(r->sys, w));
  if (r->eng->save) PX_TRY(r->eng->save(r->engine, w));
  v[0] = r->com0[0], v[1] = r->com0[1], v[2] = r->com_prev[0], v[3] = r->com_prev[1];
  v[4] = r->travel, v[5] = r->com_started, v[6] = (double)r->sys->ev_overflow, v[7] = 0;
  PX_TRY(px_checkpoint_write(w, "granular.run", PX_DTYPE_F64, 8, v));
  PX_TRY(px_checkpoint_write(w, "granular.plot", PX_DTYPE_F64,
                             (uint64_t)r->nplot * PX_GRAN_PLOT_NCOL, r->plot));
  /* the end-of-run row off the log schedule, for `partix render` (step, row) */
  last[0] = (double)r->last_step;
  memcpy(last + 1, r->last, sizeof r->last);
  return px_checkpoint_write(w, "granular.plot_last", PX_DTYPE_F64, PX_GRAN_PLOT_NCOL + 1, last);
}

/* A forged value of section `name` (the file is untrusted: its CRCs may be
 * right and its contents not). */
static enum px_status px_gran_ck_value(struct px_gran_run *r, const char *name, const char *what,
                                       double v) {
  return px_context_fail(r->ctx, PX_STATUS_FORMAT,
                         "checkpoint section '%s': %s = %g is out of range (a damaged or forged "
                         "checkpoint)",
                         name, what, v);
}

enum px_status px_gran_load(struct px_gran_run *r, struct px_checkpoint *ck) {
  double v[8], last[PX_GRAN_PLOT_NCOL + 1];
  enum px_dtype type;
  uint64_t count = 0;
  size_t k;
  PX_TRY(px_gran_sys_load(r->sys, ck));
  PX_TRY(px_checkpoint_read(ck, "granular.run", PX_DTYPE_F64, 8, v));
  for (k = 0; k < 5; ++k)
    if (!(fabs(v[k]) <= PX_GRAN_COORD_MAX))
      return px_gran_ck_value(r, "granular.run", "a centre-of-mass value", v[k]);
  if (!(v[4] >= 0)) return px_gran_ck_value(r, "granular.run", "the travel", v[4]);
  if (v[5] != 0 && v[5] != 1) return px_gran_ck_value(r, "granular.run", "the started flag", v[5]);
  if (!(v[6] >= 0 && v[6] <= 9007199254740992.0 && v[6] == floor(v[6])))
    return px_gran_ck_value(r, "granular.run", "the count of lost events", v[6]);
  r->com0[0] = v[0], r->com0[1] = v[1], r->com_prev[0] = v[2], r->com_prev[1] = v[3];
  r->travel = v[4];
  r->com_started = (int)v[5];
  r->sys->ev_overflow = (size_t)v[6];
  r->dt = r->sys->dt;
  if (px_checkpoint_find(ck, "granular.plot", &type, &count) == PX_STATUS_NOT_FOUND) {
    /* a checkpoint of an earlier partix: no series rows, no end-of-run row */
    px_context_clear(r->ctx);
    px_log(r->ctx, PX_LOG_LEVEL_WARN,
           "this checkpoint does not hold the media series so far (an earlier partix wrote "
           "it): the end-of-run plots and the time averages of summary.json start here");
    r->nplot = 0;
    r->last_step = -1;
    if (r->eng->load) PX_TRY(r->eng->load(r->engine, ck));
    return PX_STATUS_OK;
  }
  if (type != PX_DTYPE_F64 || count % PX_GRAN_PLOT_NCOL != 0)
    return px_context_fail(r->ctx, PX_STATUS_FORMAT,
                           "section 'granular.plot': %llu values of type %d, expected rows "
                           "of %d doubles",
                           (unsigned long long)count, (int)type, PX_GRAN_PLOT_NCOL);
  {
    /* rows: as many as the file holds (the section's size bounds the
     * allocation), every value finite, times not after the checkpoint's */
    const size_t n = (size_t)(count / PX_GRAN_PLOT_NCOL);
    double *rows =
        px_mem_alloc(r->ctx, "granular output", (n ? n : 1) * PX_GRAN_PLOT_NCOL * sizeof *rows);
    if (!rows) return PX_STATUS_NOMEM;
    if (n) {
      enum px_status st = px_checkpoint_read(ck, "granular.plot", PX_DTYPE_F64, count, rows);
      for (k = 0; k < n * PX_GRAN_PLOT_NCOL && st == PX_STATUS_OK; ++k)
        if (!isfinite(rows[k]) ||
            (k % PX_GRAN_PLOT_NCOL == PX_GRAN_PLOT_T &&
             !(rows[k] >= 0 && rows[k] <= r->sys->t * (1 + 1e-9) + r->sys->dt)))
          st = px_gran_ck_value(
              r, "granular.plot",
              k % PX_GRAN_PLOT_NCOL == PX_GRAN_PLOT_T ? "a row's time" : "a value", rows[k]);
      if (st != PX_STATUS_OK) {
        px_mem_free(r->ctx, rows);
        return st;
      }
    }
    px_mem_free(r->ctx, r->plot);
    r->plot = rows;
    r->plot_cap = n ? n : 1;
    r->nplot = n;
  }
  PX_TRY(px_checkpoint_read(ck, "granular.plot_last", PX_DTYPE_F64, PX_GRAN_PLOT_NCOL + 1, last));
  if (!(last[0] >= -1 && last[0] <= (double)r->sys->step && last[0] == floor(last[0])))
    return px_gran_ck_value(r, "granular.plot_last", "the step", last[0]);
  for (k = 1; k <= PX_GRAN_PLOT_NCOL; ++k)
    if (!isfinite(last[k])) return px_gran_ck_value(r, "granular.plot_last", "a value", last[k]);
  /* a continued run writes its own end-of-run row; `partix render` draws the
   * end of the run it renders */
  if (px_sim_mode(r->sim) == PX_SIM_MODE_RENDER) {
    r->last_step = (long)last[0];
    memcpy(r->last, last + 1, sizeof r->last);
  } else {
    r->last_step = -1;
    memset(r->last, 0, sizeof r->last);
  }
  if (r->eng->load) PX_TRY(r->eng->load(r->engine, ck));
  return PX_STATUS_OK;
}
