/* The solver interface (internal). A solver is a const table of functions,
 * registered by name in registry.c; the run driver (sim.c) owns the time
 * loop, the output schedule, progress, checkpoints and failure handling, and
 * calls the solver for physics and for its own outputs.
 *
 * Adding a solver: write src/solvers/NAME/ with a `const struct px_solver_i
 * px_solver_NAME` and its case-section keys `const struct px_schema
 * px_solver_NAME_keys[]`, add NAME to PX_SOLVER_LIST in registry.c, add
 * tests/NAME/, cases/NAME/, docs/NAME.md and bench/NAME_*.c. */
#ifndef PX_SOLVER_H
#define PX_SOLVER_H

#include "config/schema.h"
#include "partix/backend.h"
#include "partix/case.h"
#include "partix/checkpoint.h"
#include "partix/sim.h"

/* Why an output hook is called. */
struct px_sim_output {
  long step;           /* steps done */
  double time;         /* simulated time [s] */
  const char *dir;     /* output directory (borrowed) */
  int resumed;         /* 1 on the first output of a resumed run */
  double resume_time;  /* time of the checkpoint a resumed run started from */
};

struct px_solver_i {
  const char *name;    /* the case's `solver:` value and the name of its section */
  const char *summary; /* one line for `partix info` */

  /* Build the problem from the case (px_sim_case) on the backend
   * (px_sim_backend). Report case errors with px_case_fail. Required. */
  enum px_status (*create)(struct px_sim *sim, void **state);
  void (*destroy)(void *state);
  /* Stable time step when the case gives none (optional: then time.dt is
   * required). */
  enum px_status (*time_step)(void *state, double *dt);
  /* Advance from t to t + dt (step = steps done before this one). A blow-up
   * returns PX_STATUS_NUMERIC with the particle/element and quantity. */
  enum px_status (*step)(void *state, long step, double t, double dt);
  /* Outputs (all optional): snapshot files (VTK), time-series rows (CSV),
   * pictures (PNG), and end-of-run products (plots, summaries). */
  enum px_status (*snapshot)(void *state, const struct px_sim_output *o);
  enum px_status (*series)(void *state, const struct px_sim_output *o);
  enum px_status (*picture)(void *state, const struct px_sim_output *o);
  enum px_status (*finish)(void *state, const struct px_sim_output *o);
  /* Everything the next step reads (required for checkpoints). */
  enum px_status (*save)(void *state, struct px_checkpoint_writer *w);
  enum px_status (*load)(void *state, struct px_checkpoint *ck);
  /* Number of particles/elements (progress line); optional. */
  long (*count)(const void *state);
};

/* Registered solvers, NULL-terminated. */
const struct px_solver_i *const *px_solver_registry(void);
const struct px_solver_i *px_solver_find(const char *name);

/* Accessors for solvers. */
struct px_backend *px_sim_backend(const struct px_sim *sim);
enum px_precision px_sim_precision(const struct px_sim *sim);
enum px_sim_mode px_sim_mode(const struct px_sim *sim);
/* "OUTDIR/name" into buf. */
enum px_status px_sim_output_path(const struct px_sim *sim, const char *name, char *buf,
                                  size_t size);

#endif
