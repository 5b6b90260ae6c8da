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
#include "partix/results.h"
#include "partix/sim.h"

struct px_summary;
struct px_csv;

/* Why an output hook is called.
 *
 * A resumed run must leave its folder as an uninterrupted run would, file by
 * file. Hooks open their files lazily (on their first call): when `resumed`
 * is set they continue the earlier files instead of replacing them, keeping
 * what the earlier segment wrote up to the resume point:
 *  - time-series CSV (one row per log_every steps): rows with t <= keep_series
 *    (px_csv_open_resume(..., o->keep_series, ...));
 *  - event CSV (rows at the times things happened, e.g. impacts): rows with
 *    t <= resume_time;
 *  - .pvd series: entries with t <= keep_snapshot
 *    (px_vtk_series_open_resume(..., o->keep_snapshot, ...) also deletes the
 *    files of the entries it drops);
 *  - a PNG snapshot of step drop_picture (>= 0) was drawn only because an
 *    earlier segment ended there off the png schedule: delete it.
 * keep_* are half a step after resume_time when the resume step was on that
 * schedule (its row or frame is kept, however its time was rounded when
 * printed), half a step before when it was off the schedule (an earlier
 * segment's end-of-run output, which an uninterrupted run does not have). */
struct px_sim_output {
  struct px_sim *sim;   /* the run (borrowed): px_sim_csv_open keeps its series in
                           memory through it (partix/results.h) */
  long step;            /* steps done */
  double time;          /* simulated time [s] */
  const char *dir;      /* output directory (borrowed) */
  int resumed;          /* 1 for every output of a resumed run (see above) */
  double resume_time;   /* time of the checkpoint a resumed run started from [s] */
  double keep_series;   /* resumed: time-series CSV rows kept, t <= this [s] */
  double keep_snapshot; /* resumed: .pvd entries kept, t <= this [s] */
  long drop_picture;    /* resumed: step of a stale end-of-segment PNG, -1 none */
  int final;            /* 1: the end-of-run output, due whatever the schedule */
  int render;           /* 1: `partix render`: draw pictures only, write no other
                           file (no CSV, VTK, table) */
  int pictures;         /* 1: PNGs are wanted (output.png, or render): end-of-run
                           plots are drawn only then */
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
  /* 1 when the run has reached its goal before its last step (a
   * quasi-static relaxation that converged): the driver then ends the run
   * after this step as at its end (last outputs, checkpoint, summary); the
   * step count of the case is the most it may take. Optional. */
  int (*done)(const void *state);
  /* The run's results in memory (partix/results.h): add to `out` the views
   * of `kind` at the step o describes (px_results_add: copies), or return
   * PX_STATUS_UNSUPPORTED for a kind the solver has none of. Called on rank
   * 0 after `gather`, like the outputs. Optional. */
  enum px_status (*results)(void *state, const struct px_sim_output *o, enum px_results_kind kind,
                            struct px_results *out);
  /* Number of particles/elements (progress line); optional. */
  long (*count)(const void *state);
  /* The quantities a user reports (summary.json, `partix summary`): called
   * after every checkpoint and at the end of a run, also of a resumed one,
   * so it must cover the whole run (e.g. read the run's CSV back), not only
   * the steps of this process. Optional. */
  enum px_status (*report)(void *state, const struct px_sim_output *o, struct px_summary *sum);
  /* Keys of the solver's section that may change on resume besides the
   * platform's (time, output, backend except precision): key paths from the
   * root ("vortex.picture"), each covering its subtree; NULL-terminated, or
   * NULL for none. Any other changed key is refused by name. */
  const char *const *resume_keys;

  /* Runs over several ranks (`mpirun -np K partix run`, K > 1; the ranks are
   * px_context_comm of the run's context, src/core/comm.h). Every rank runs
   * the driver: create, time_step, step, done and load on every rank (load
   * reads the same checkpoint file on each: a checkpoint holds the global
   * state in the 1-rank format, so a run resumes on any rank count), and
   * they must agree (time_step, done, count: global values, the same on
   * every rank). Outputs, save, report and finish are called on rank 0
   * only, after `gather`. A step that fails on one rank fails the run on all
   * (the driver agrees on each step's status).
   * `ranks`: 1 when the solver decomposes its cases over the ranks; 0 refuses
   * K > 1 at create, naming the solver. */
  int ranks;
  /* Collective, K > 1 only: bring everything the outputs and `save` read
   * onto rank 0 (its state then reads as a 1-rank run's). NULL: it is there
   * already (a replicated state). */
  enum px_status (*gather)(void *state);
  /* Collective, K > 1 only, optional: what `series` alone reads, when no
   * other output or save is due at this step (the driver calls `gather`
   * instead when one is, or when this is NULL): a CSV row of a few numbers
   * should not move the whole state. */
  enum px_status (*gather_series)(void *state);
};

/* Registered solvers, NULL-terminated. */
const struct px_solver_i *const *px_solver_registry(void);
/* The root schema of this build: the platform's keys and every solver's
 * section, built once (thread-safe); NULL only if there are more sections
 * than a root holds. px_case_load and px_case_load_string use it. */
const struct px_schema *px_case_root_schema(void);
const struct px_solver_i *px_solver_find(const char *name);

/* Accessors for solvers. */
struct px_backend *px_sim_backend(const struct px_sim *sim);
enum px_precision px_sim_precision(const struct px_sim *sim);
enum px_sim_mode px_sim_mode(const struct px_sim *sim);
/* Record the value chosen for an automatic setting (a key the case leaves
 * to partix): logged at INFO as "automatic: KEY = VALUE" (console and
 * run.log) and listed in summary.json under "automatic". */
void px_sim_note_auto(struct px_sim *sim, const char *key, const char *fmt, ...) PX_PRINTF(3, 4);
/* Refuse, before allocating, a problem whose memory (an estimate from the
 * case: `bytes` for `what`, e.g. "the panel matrix") exceeds this machine's
 * physical memory: PX_STATUS_CONFIG at `key` (the case key that sets the
 * size), e.g. "vortex.bodies[0].panels = 100000: needs 80 GB for the panel
 * matrix; this machine has 24 GiB of memory". PX_STATUS_OK otherwise. */
enum px_status px_sim_require_memory(struct px_sim *sim, double bytes, const char *key,
                                     const char *what);
/* "OUTDIR/name" into buf. */
enum px_status px_sim_output_path(const struct px_sim *sim, const char *name, char *buf,
                                  size_t size);

/* The header of a CSV a solver writes: n names "quantity [unit]" formatted
 * into one allocation (sim_csv.c). */
struct px_sim_columns {
  size_t n;
  const char **name; /* n pointers into text, for px_csv_open */
  char (*text)[96];
};
/* Room for n names (all empty); PX_STATUS_NOMEM with the message set. */
enum px_status px_sim_columns_alloc(struct px_context *ctx, struct px_sim_columns *c, size_t n);
/* Name i (truncated at 95 characters). */
void px_sim_columns_set(struct px_sim_columns *c, size_t i, const char *fmt, ...) PX_PRINTF(3, 4);
/* NULL-safe on a zeroed struct. */
void px_sim_columns_free(struct px_context *ctx, struct px_sim_columns *c);
/* Results for solvers (sim_results.c): a view of `length` items of
 * `components` values copied from `data` (NULL: zeros) into `r`; returns
 * its storage (to fill), NULL when out of memory. */
void *px_results_add(struct px_results *r, const char *name, const char *units,
                     enum px_view_type type, size_t length, size_t components, const void *data);
/* Open the CSV `name` in o's folder with the header of ncols names: a
 * fresh run creates it; a resumed run continues it, keeping the rows whose
 * time (first column) is <= keep [s] (o->keep_series for a time series,
 * about o->resume_time for an event CSV: struct px_sim_output). */
enum px_status px_sim_csv_open(struct px_context *ctx, const struct px_sim_output *o,
                               const char *name, size_t ncols, const char *const *names,
                               double keep, struct px_csv **out);
/* The series of the run in memory: every row written to `csv` (opened as
 * `name`, e.g. "loads.csv", with the header `names`) also goes into the
 * run's table of that name (px_sim_series). px_sim_csv_open does this. */
enum px_status px_sim_series_tap(struct px_sim *sim, const char *name, size_t ncols,
                                 const char *const *names, struct px_csv *csv);

#endif
