/* The vortex solver's state between its files (private): the case glue
 * (vortex.c), the bodies (vortex_bodies.c), the outputs (vortex_output.c) and
 * the checkpoints (vortex_checkpoint.c), as the entries of px_solver_vortex. */
#ifndef PX_VORTEX_SOLVER_H
#define PX_VORTEX_SOLVER_H

#include "partix/csv.h"
#include "partix/figure.h"
#include "partix/vtk.h"
#include "solvers/solver.h"
#include "solvers/summary.h"
#include "solvers/vortex/vortex_core.h"

struct vx_state {
  struct px_sim *sim;                         /* borrowed */
  struct px_context *ctx;                     /* borrowed */
  struct px_case *c;                          /* borrowed (owned by the sim) */
  struct px_vortex_engine *e;                 /* owned */
  struct px_vtk *vtk;                         /* owned */
  struct px_vtk_series *pvd_wake, *pvd_field; /* owned */
  struct px_csv *csv_loads, *csv_probes;      /* owned */
  struct px_figure *fig;                      /* owned */
  double *probe;                              /* owned: 2 * nprobe coordinates */
  size_t nprobe;
  int has_grid;
  double grid[4];
  size_t cells[2];
  long field_every;
  double view[4];     /* shown region [m]: the case's or the automatic one */
  double gamma_range; /* colour range +-G [m^2/s]; 0: per picture (px_vortex_output_picture) */
  int pic_w, pic_h;
  const char *title;             /* borrowed from the case */
  double report_from, report_to; /* summary.json window [s]; < 0: the default */
  int tidied;                    /* resumed: the stale end-of-segment picture is gone */
  /* the two friction estimates (x, all bodies) summed over the steps after
   * the first 100 of this process, compared at the end (px_vortex_output_finish) */
  double fric_drift, fric_wall;
  long fric_n;
};

/* Bodies (vortex_bodies.c): vx_create's bodies built and checked, freed on failure. */
enum px_status px_vortex_bodies_build(struct vx_state *s, struct px_vortex_config *cfg,
                                      struct px_vortex_contour *body, size_t *nb_out);

/* Outputs (vortex_output.c): the px_solver_i entries of the same names. */
enum px_status px_vortex_output_snapshot(void *state, const struct px_sim_output *o);
enum px_status px_vortex_output_series(void *state, const struct px_sim_output *o);
enum px_status px_vortex_output_picture(void *state, const struct px_sim_output *o);
enum px_status px_vortex_output_finish(void *state, const struct px_sim_output *o);
enum px_status px_vortex_output_report(void *state, const struct px_sim_output *o,
                                       struct px_summary *sum);

/* Results in memory (vortex_results.c): px_solver_i.results. */
enum px_status px_vortex_results(void *state, const struct px_sim_output *o,
                                 enum px_results_kind kind, struct px_results *out);

/* Checkpoints (vortex_checkpoint.c). */
enum px_status px_vortex_checkpoint_save(void *state, struct px_checkpoint_writer *w);
enum px_status px_vortex_checkpoint_load(void *state, struct px_checkpoint *ck);

#endif
