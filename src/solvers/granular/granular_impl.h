/* The granular solver's private declarations (internal to
 * src/solvers/granular): the run state (granular_run.h), the solver table,
 * outputs and checkpoints. */
#ifndef PX_GRAN_IMPL_H
#define PX_GRAN_IMPL_H

#include "solvers/granular/granular_run.h"

extern const struct px_schema px_solver_granular_keys[];
extern const struct px_solver_i px_solver_granular;

/* Outputs (granular_output.c). */
enum px_status px_gran_out_snapshot(struct px_gran_run *r, const struct px_sim_output *o);
enum px_status px_gran_out_series(struct px_gran_run *r, const struct px_sim_output *o);
enum px_status px_gran_out_picture(struct px_gran_run *r, const struct px_sim_output *o);
enum px_status px_gran_out_finish(struct px_gran_run *r, const struct px_sim_output *o);
/* Per-segment report table of contour c into columns (see the names). */
enum px_status px_gran_out_segments(struct px_gran_run *r, size_t c, const char *dir, double t);
void px_gran_out_close(struct px_gran_run *r);
/* The quantities of summary.json (the report hook). */
enum px_status px_gran_out_report(struct px_gran_run *r, const struct px_sim_output *o,
                                  struct px_summary *sum);
/* Open impacts.csv of a resumed run before its first step (impacts of the
 * steps before the first output would be lost otherwise); t: resume time [s]. */
enum px_status px_gran_out_impacts_resume(struct px_gran_run *r, double t);

/* Results in memory (granular_results.c): px_solver_i.results. */
enum px_status px_gran_results(void *state, const struct px_sim_output *o,
                               enum px_results_kind kind, struct px_results *out);

/* Checkpoints (granular_checkpoint.c). */
enum px_status px_gran_save(struct px_gran_run *r, struct px_checkpoint_writer *w);
enum px_status px_gran_load(struct px_gran_run *r, struct px_checkpoint *ck);

#endif
