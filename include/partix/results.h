/* A run's results in memory: the current state of each solver's particles
 * or elements, the time series it writes to CSV, and per-segment statistics,
 * as typed views over arrays, without reading the run's files back.
 *
 *   struct px_results *r = NULL;
 *   if (px_sim_results(sim, PX_RESULTS_STATE, &r) == PX_STATUS_OK) {
 *     const struct px_view *x = px_results_find(r, "x");
 *     for (size_t i = 0; i < x->length; ++i)
 *       use(*(const double *)((const char *)x->data + i * x->stride));
 *   }
 *   px_results_free(r);
 *
 * A results object owns its arrays: its views stay valid until
 * px_results_free, across later steps (a copy of the state at the step it
 * was taken; px_results_step says which). On K > 1 ranks px_sim_results is
 * collective (every rank calls it): the solver's `gather` brings the state
 * onto rank 0, whose results are the whole run's; the other ranks get an
 * empty results object. The series are rank 0's (it writes the CSV files);
 * px_sim_series gives the other ranks empty results. */
#ifndef PARTIX_RESULTS_H
#define PARTIX_RESULTS_H

#include <stddef.h>

#include "partix/export.h"
#include "partix/status.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_sim;
struct px_results;

/* The element type of a view. */
enum px_view_type {
  PX_VIEW_F64 = 0, /* double */
  PX_VIEW_F32 = 1, /* float */
  PX_VIEW_I64 = 2, /* int64_t */
  PX_VIEW_I32 = 3, /* int32_t */
  PX_VIEW_U8 = 4   /* uint8_t */
};

/* One array: `length` items of `components` values each (a 3-vector has 3,
 * a symmetric stress tensor 6), the values of an item contiguous, item i at
 * (const char *)data + i * stride. */
struct px_view {
  const char *name;  /* "x", "displacement", "Cl", ... */
  const char *units; /* SI units ("m", "m/s", "Pa", "N/m"); series: as the CSV
                        header gives them ("-" dimensionless); "" for counts
                        and indices of the state */
  enum px_view_type type;
  const void *data;
  size_t length;
  size_t components;
  ptrdiff_t stride; /* bytes between items */
};

/* What px_sim_results returns. */
enum px_results_kind {
  /* per particle / element / vortex (the arrays the VTK snapshots hold):
     granular per disc x y vx vy spin radius mass id contacts; lattice per
     element (cell order) cell, position (3, the centre), displacement (3),
     velocity (3), stress (6: XX YY ZZ XY YZ XZ), von_mises, broken_links
     (u8: links broken so far), rotation (3: the rotation vector, axis
     times angle [rad]); vortex per vortex x y gamma core_radius u v.
     Copies at full precision: where the solver computes in f32 or on a
     device, converted to double on the host. */
  PX_RESULTS_STATE = 0,
  /* per wall segment of the reported contours (granular: the columns of
     segments_*.csv, one row per segment, plus `contour`, the contour's
     index) */
  PX_RESULTS_SEGMENTS = 1
};

/* Size in bytes of one value; its name ("f64", "f32", "i64", "i32", "u8"). */
PX_API size_t px_view_type_size(enum px_view_type type);
PX_API const char *px_view_type_name(enum px_view_type type);

PX_API size_t px_results_count(const struct px_results *r);
/* View i (< px_results_count), NULL otherwise. */
PX_API const struct px_view *px_results_view(const struct px_results *r, size_t i);
/* The view called `name`, NULL if none. */
PX_API const struct px_view *px_results_find(const struct px_results *r, const char *name);
/* The step and time [s] the results were taken at. */
PX_API long px_results_step(const struct px_results *r);
PX_API double px_results_time(const struct px_results *r);
/* NULL-safe. */
PX_API void px_results_free(struct px_results *r);

/* The current state (or segment statistics) of the run. PX_STATUS_UNSUPPORTED
 * (message set) when the solver has none of this kind. Collective over ranks. */
PX_API enum px_status px_sim_results(struct px_sim *sim, enum px_results_kind kind,
                                     struct px_results **out);

/* Time series: the CSV files the run writes one row at a time (output.csv
 * on, rows every output.log_every steps), by file name without ".csv":
 * vortex "loads" and "probes", lattice "probes", granular "media",
 * "speed_histogram" and "impacts". A view per column, named and with units
 * as in the file's header ("cx [-]" -> name "cx", units "-"); values as
 * computed (the file prints 10 or 17 significant digits). Only the rows
 * written by this process: a resumed run's series start at its checkpoint.
 * Name i of the series the run has written so far, NULL past the last. */
PX_API const char *px_sim_series_name(const struct px_sim *sim, size_t i);
/* The series `name` as it stands (a copy); PX_STATUS_NOT_FOUND when the run
 * has written no such series. */
PX_API enum px_status px_sim_series(struct px_sim *sim, const char *name, struct px_results **out);

/* What a callback is told. */
enum px_sim_event {
  PX_SIM_EVENT_STEP = 0,      /* a step is done, with its outputs */
  PX_SIM_EVENT_OUTPUT = 1,    /* outputs (CSV rows, snapshots) were written */
  PX_SIM_EVENT_CHECKPOINT = 2 /* a checkpoint was written */
};
/* Called on every rank, from px_sim_step / px_sim_run, after the event; the
 * results functions may be called from it (collectively). fn NULL removes
 * the callback. */
typedef void (*px_sim_callback)(struct px_sim *sim, enum px_sim_event event, void *user);
PX_API void px_sim_set_callback(struct px_sim *sim, px_sim_callback fn, void *user);

#ifdef __cplusplus
}
#endif
#endif
