/* The run driver's private layout (sim.c, sim_log.c, sim_run.c,
 * sim_resume.c): struct px_sim and the functions its files share. */
#ifndef PX_SIM_IMPL_H
#define PX_SIM_IMPL_H

#include <stdint.h>
#include <stdio.h>

#include "core/comm.h"
#include "partix/timer.h"
#include "solvers/solver.h"

#define PX_SIM_PATH_MAX 4096
/* Most steps a run may take (time.steps' schema range). */
#define PX_SIM_MAX_STEPS 1e12
/* Most CPU threads per logical core: more only slows a run. */
#define PX_SIM_THREADS_PER_CORE 4

struct px_sim {
  struct px_context *ctx;           /* borrowed */
  struct px_case *c;                /* owned */
  const struct px_solver_i *solver; /* static */
  void *state;                      /* owned through solver->destroy */
  struct px_backend *be;            /* owned */
  enum px_precision precision;
  enum px_sim_mode mode;
  long step;   /* steps done */
  long nsteps; /* steps to reach */
  double dt;   /* [s] */
  char outdir[PX_SIM_PATH_MAX];
  char ckpath[PX_SIM_PATH_MAX];
  long every, png_every, log_every, ck_every;
  int vtk, csv, png;
  FILE *progress_out; /* borrowed */
  int progress_tty;
  int resumed;
  double resume_time;
  double keep_series, keep_snapshot; /* see struct px_sim_output */
  long drop_picture;
  long last_checkpoint;      /* step of the last checkpoint written, -1 none */
  struct px_timeset *timers; /* owned */
  int t_step, t_output, t_checkpoint;
  char **autos; /* px_mem, owned: "key\tvalue" of each automatic setting */
  size_t nauto;
  char **inputs; /* px_mem, owned: "name\tbytes\thash" of each input file */
  size_t ninput;
  /* run.log: every log message at INFO or more detailed (whatever the console
     shows), buffered until the run folder is opened */
  FILE *log;    /* owned; NULL before the folder is opened */
  int lock_fd;  /* the run folder, flock'ed while this run writes it; -1 none */
  char *logbuf; /* px_mem, owned: lines waiting for the file */
  size_t loglen, logcap;
  int log_tee;           /* 1 while the tee below is installed */
  px_log_fn log_prev_fn; /* the context's log callback before the tee */
  void *log_prev_user;
  enum px_log_level console_level; /* the context's level before the tee */
  double wall_start;               /* px_time_now() when this process started the run */
  double wall_before;              /* wall time of earlier segments (resumed runs) [s] */
  char title[256];
  /* ranks (core/comm.h): every rank steps, rank 0 alone writes the folder */
  struct px_comm *comm; /* borrowed from the context */
  int rank0;            /* 1 on rank 0 (and on a single rank) */
  long gathered;        /* step of the last solver gather, -1 none */
  int stop;             /* 1: the ranks agreed to stop (an interrupt) */
  int started;          /* the step-0 outputs are written (or not due: resumed) */
  int ended;            /* the end-of-run products are written */
  /* results in memory (sim_results.c) */
  struct px_sim_table **tables; /* px_mem, owned: the series written so far */
  size_t ntables;
  int wrote;                /* 1: the last px_sim_outputs wrote something */
  px_sim_callback callback; /* NULL none */
  void *callback_user;
};

/* sim.c */
/* 64-bit FNV-1a of a buffer (names an input file's content in summary.json). */
uint64_t px_sim_fnv(const char *data, size_t len);
/* Everything of a run that writes nothing: backend, solver, schedule. fresh:
 * a new run (RUN mode), whose folder must not hold another run's record
 * (checked before the solver is built); 0 for a resumed run or a render. */
enum px_status px_sim_build(struct px_context *ctx, struct px_case *c, enum px_sim_mode mode,
                            const char *outdir, int fresh, struct px_sim **out);
/* The string `field` of DIR/summary.json into buf: "" when there is no
 * summary.json, "unreadable" or "unknown" when it cannot be read or lacks
 * the field. */
void px_sim_summary_field(struct px_context *ctx, const char *dir, const char *field, char *buf,
                          size_t size);
/* Make the run folder and lock it for this process (flock, held until
 * px_sim_free): a second partix writing it is refused. */
enum px_status px_sim_lock_outdir(struct px_sim *sim);
/* Release it (a run that finished or stopped; taken again if it writes). */
void px_sim_unlock_outdir(struct px_sim *sim);
/* Open the run folder (RUN mode): the folder, run.log, copies of the input
 * files, and the resolved case.yaml. */
enum px_status px_sim_open_outputs(struct px_sim *sim, const char *how);

/* sim_log.c: run.log */
void px_sim_log_append(struct px_sim *sim, const char *text, size_t n);
/* One line of run.log: "2026-11-26 17:40:01 warning: message". */
void px_sim_log_line(struct px_sim *sim, enum px_log_level level, const char *message);
void px_sim_tee_install(struct px_sim *sim);
void px_sim_tee_remove(struct px_sim *sim);
/* Open RUN_DIR/run.log for appending and write out what was logged before. */
enum px_status px_sim_log_open(struct px_sim *sim);

/* sim_run.c: outputs, summary.json, checkpoints, the time loop */
/* On K > 1 ranks: the solver's state onto rank 0 (its gather, once per
 * step) before rank 0 writes outputs or a checkpoint. Collective. */
enum px_status px_sim_gather(struct px_sim *sim);
void px_sim_output_info(struct px_sim *sim, struct px_sim_output *o);

/* sim_results.c */
void px_sim_tables_free(struct px_sim *sim);
/* Tell the run's callback (if any) of `event`. */
void px_sim_notify(struct px_sim *sim, enum px_sim_event event);

#endif
