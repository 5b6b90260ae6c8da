/* The granular solver's run state (struct px_gran_run): what reading the
 * case (granular_case.c), the solver (granular.c), its outputs and its
 * checkpoints share. A header of its own so that granular_case.h, which
 * granular.c includes, needs nothing from granular_impl.h (one direction). */
#ifndef PX_GRAN_RUN_H
#define PX_GRAN_RUN_H

#include <stdio.h>

#include "partix/csv.h"
#include "partix/vtk.h"
#include "solvers/granular/expr.h"
#include "solvers/granular/granular_engine.h"
#include "solvers/granular/geometry.h"
#include "solvers/granular/media.h"
#include "solvers/granular/motion.h"
#include "solvers/granular/system.h"
#include "solvers/solver.h"
#include "solvers/summary.h"

#define PX_GRAN_NAME_MAX 64

struct px_gran_body {
  char name[PX_GRAN_NAME_MAX];
};

/* Which contours a case contour produced (a DXF shape may give several). */
struct px_gran_creport {
  int report; /* write statistics */
};

/* Columns of a row of the run's series (px_gran_run.plot). */
enum {
  PX_GRAN_PLOT_T,      /* time [s] */
  PX_GRAN_PLOT_KE,     /* kinetic energy, translation + rotation [J] */
  PX_GRAN_PLOT_COMY,   /* height of the centre of mass [m] */
  PX_GRAN_PLOT_COORD,  /* mean coordination number [-] */
  PX_GRAN_PLOT_TRAVEL, /* path length of the centre of mass [m] */
  PX_GRAN_PLOT_SPEED,  /* mean disc speed [m/s] */
  PX_GRAN_PLOT_NCOL
};

struct px_gran_run {
  struct px_sim *sim;                 /* borrowed */
  struct px_context *ctx;             /* borrowed */
  struct px_case *c;                  /* borrowed (owned by the sim) */
  struct px_gran_sys *sys;            /* owned: the system (the state, or the host mirror of an
                                         engine that keeps it elsewhere) */
  const struct px_gran_engine_i *eng; /* borrowed (static): picked by backend name */
  void *engine;                       /* owned by eng (destroy); NULL before it is made */
  struct px_gran_geom geom;           /* owned */
  struct px_gran_motion *motions;     /* owned, per body */
  struct px_gran_body *bodies;        /* owned */
  size_t nbodies;
  int *report;      /* owned, per geometry contour */
  double settle;    /* [s] */
  double thickness; /* disc thickness [m] */
  double dt;
  /* statistics */
  struct px_gran_stats_spec sspec;
  int energy_total; /* E for hardening: normal + tangential */
  struct px_gran_fn hardening, residual;
  char hard_unit[32], res_unit[32];
  char picture_quantity[48];
  double speed_max; /* histogram upper edge [m/s] */
  int bins;
  int impact_log;
  struct px_csv *csv_impacts; /* impacts.csv (impact_log), opened with the series, or
                                 at the first step of a resumed run */
  int impacts_checked;        /* 1 once a resumed run has looked at opening it */
  int resume_tidied;          /* 1 once a resumed run removed its stale picture */
  long first_step;            /* the first step this process took, -1 before */
  /* pictures */
  int color; /* 0 speed 1 spin 2 contacts 3 id */
  int width, height;
  double range;
  /* series state (kept in checkpoints) */
  double com0[2];     /* centre of mass when the statistics started [m] */
  double com_prev[2]; /* at the previous series row [m] */
  double travel;      /* path length of the centre of mass [m] */
  int com_started;
  /* outputs (opened lazily) */
  struct px_csv *csv_media, *csv_hist;
  struct px_vtk_series *pvd_particles, *pvd_walls;
  struct px_vtk *vtk;
  double *fig_x, *fig_y; /* contour points borrowed by a figure being drawn */
  /* The series of the whole run for the end-of-run plots and the summary:
   * rows PX_GRAN_PLOT_* of every scheduled series output (kept in
   * checkpoints, so a resumed run has the rows of the earlier segments).
   * The row of an end-of-run output off the log schedule is not one of them
   * (a resumed run never writes it): it is `last`, valid at step last_step
   * only. Owned. */
  double *plot;
  size_t nplot, plot_cap;
  double last[PX_GRAN_PLOT_NCOL];
  long last_step; /* -1: none */
  /* the statistics as they stand, for the outputs (px_gran_out_view) */
  struct px_gran_stats view; /* arrays borrowed from the system or view_buf */
  double *view_buf;          /* owned: 4 nseg */
};

/* Bring the engine's state into r->sys before it is read (outputs,
 * checkpoints); nothing before the engine exists. */
static inline enum px_status px_gran_sync(struct px_gran_run *r) {
  return r->engine ? r->eng->sync(r->engine) : PX_STATUS_OK;
}

#endif
