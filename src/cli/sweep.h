/* partix sweep (sweep.c): the sweep, its runs (sweep_run.c) and its table
 * (sweep_table.c: sweep.csv, sweep.json, sweep.png). */
#ifndef PX_CLI_SWEEP_H
#define PX_CLI_SWEEP_H

#include <libfyaml.h>
#include <stdint.h>
#include <stdio.h>
#include <sys/types.h>

#include "cli/cli.h"
#include "partix/partix.h"

#define PX_SWEEP_MAX_RUNS 10000
#define PX_SWEEP_MAX_KEYS 16
#define PX_SWEEP_MAX_JOBS 256

struct px_sweep_run {
  char name[160];                       /* folder name in the sweep folder */
  const char *value[PX_SWEEP_MAX_KEYS]; /* borrowed (document or taken): by varied key */
  char *taken[PX_SWEEP_MAX_KEYS]; /* owned: the case's value of a varied key the run leaves out */
  char *overrides[2 * PX_SWEEP_MAX_KEYS]; /* owned "key=value" strings */
  size_t noverrides;
  char status[32]; /* finished, failed, interrupted, not run */
  int exit;        /* the child's exit status (-1: not run) */
  double wall;     /* [s] measured by the sweep (this session) */
  char error[512]; /* the child's last message when it failed */
  pid_t pid;
  /* px_case_hash of the run's case (the base case with its overrides, as
   * px_sweep_check loads it): what defines the run. Recorded in
   * DIR/.NAME.fingerprint when the run starts; a folder made with another
   * is never skipped or resumed. */
  uint64_t fingerprint;
  int foreign; /* 1: its folder holds a run of other settings (left out of the table) */
};

struct px_sweep {
  const char *file;                   /* the sweep file (argument) */
  struct fy_document *doc;            /* owned */
  char base[4096];                    /* the base case, resolved against the file */
  char dir[4096];                     /* the sweep folder */
  const char *key[PX_SWEEP_MAX_KEYS]; /* borrowed: varied keys in order */
  size_t nkeys;
  const char *set_key[PX_SWEEP_MAX_KEYS], *set_value[PX_SWEEP_MAX_KEYS];
  size_t nset;
  const char *plot_x, *plot_y; /* borrowed, may be NULL */
  int plotted;                 /* 1: px_sweep_plot drew DIR/sweep.png this time */
  struct px_sweep_run *runs;   /* owned */
  size_t nruns;
};

/* The quantities of every run's summary.json (documents owned by the
 * caller), and the union of their names in order of appearance. */
struct px_sweep_table {
  struct fy_document **doc; /* by run, NULL when none */
  const char **name, **unit;
  size_t n;
};

/* The scalar text of a node, or NULL when it is not a scalar. */
static inline const char *px_sweep_scalar(struct fy_node *n) {
  return n && fy_node_is_scalar(n) ? fy_node_get_scalar0(n) : NULL;
}

/* Every run's case loads and validates; else prints the first error and
 * returns 2. Sets each run's fingerprint, and the
 * value of each varied key it leaves out to the one its case has (NULL when
 * the case has none: the solver chooses, as for time.dt). */
int px_sweep_check(struct px_sweep *s, struct px_context *ctx);
/* Runs the loaded and checked sweep here, at most jobs runs at a time
 * (skipping finished runs, resuming interrupted ones, refusing folders made
 * with other settings), then writes its
 * table; the sweep's exit status (0, 1 some run not finished, 130
 * interrupted by Ctrl-C or SIGTERM). partix sweep and partix part3d. */
int px_sweep_execute(struct px_sweep *s, struct px_cli *cli, struct px_context *ctx, long jobs);
/* 1 once Ctrl-C or SIGTERM stopped a sweep. */
int px_sweep_interrupted(void);
/* The table and last line of what the runs left (failed: runs not finished); the exit status. */
int px_sweep_finish(struct px_sweep *s, struct px_context *ctx, int failed);
#ifdef PX_HAVE_MPI
/* An MPI sweep: rank 0 hands the runs out to ranks 1..size-1; *failed counts those not finished. */
void px_sweep_mpi(struct px_sweep *s, const struct px_cli *cli, struct px_context *ctx, int rank,
                  int size, int *failed);
#endif
/* Read every run's summary.json into t (0, or -1 out of memory). */
int px_sweep_table_read(struct px_sweep *s, struct px_sweep_table *t);
void px_sweep_table_free(struct px_sweep *s, struct px_sweep_table *t);
/* DIR/sweep.csv and DIR/sweep.json, written atomically. */
enum px_status px_sweep_write_csv(struct px_context *ctx, struct px_sweep *s,
                                  const struct px_sweep_table *t);
enum px_status px_sweep_write_json(struct px_context *ctx, struct px_sweep *s,
                                   const struct px_sweep_table *t);
/* DIR/sweep.png: plot.y against plot.x. */
enum px_status px_sweep_plot(struct px_context *ctx, struct px_sweep *s,
                             const struct px_sweep_table *t);

#endif
