/* The lattice solver's run state (internal; shared by lattice.c,
 * lattice_checkpoint.c, lattice_output.c and lattice_plots.c). */
#ifndef PX_LATTICE_H
#define PX_LATTICE_H

#include <float.h>

#include "partix/csv.h"
#include "partix/figure.h"
#include "partix/vtk.h"
#include "solvers/lattice/lattice_engine.h"
#include "solvers/solver.h"

/* A probe: the mean of the selected elements' values. */
struct px_lattice_probe {
  char name[64];
  size_t *cells; /* owned (px_mem); padded indices */
  size_t count;
};

enum px_lattice_view {
  PX_LATTICE_VIEW_ISO = 0,
  PX_LATTICE_VIEW_TOP = 1,
  PX_LATTICE_VIEW_FRONT = 2,
  PX_LATTICE_VIEW_SIDE = 3
};

struct px_lattice_ranks;

struct px_lattice {
  struct px_sim *sim;                   /* borrowed */
  struct px_context *ctx;               /* borrowed */
  struct px_lattice_model m;            /* owned */
  const struct px_lattice_engine_i *vt; /* static */
  void *e;                              /* owned through vt->destroy */
  enum px_lattice_integrator integ;
  enum px_precision precision;
  double dt_limit, safety;
  double need_host; /* host memory estimated for the run [B]
                       (px_lattice_need), probes excluded */
  int quasi_static;
  double alpha; /* global damping in use [1/s] */
  /* quasi-static convergence (lattice.static_tolerance; lattice.c) */
  double static_tol;               /* [-]; 0: run every step */
  double settle_time;              /* loads constant from this time on [s] */
  double static_error;             /* estimated relative distance from statics
                                      at the last check [-]
                                      (px_lattice_relax_update); NaN: none */
  double static_since;             /* time since when static_error <=
                                      static_tol at every check [s]; NaN */
  int converged;                   /* static equilibrium reached */
  struct px_lattice_probe *probes; /* owned */
  size_t nprobe;
  enum px_lattice_view view;
  double picture_scale; /* displacement magnification, 0 = auto */
  double drawn_scale;   /* the last picture's magnification; NaN */
  int cleaned;          /* resumed: the stale picture is deleted */
  char title[128];
  /* outputs (owned, created on first use) */
  struct px_vtk *vtk;
  struct px_vtk_series *pvd;
  struct px_csv *csv;
  struct px_figure *fig;
  double *fu, *fv, *fs, *fvm; /* host fields, padded layout */
  uint8_t *flinks;
  /* the last picture's discs (projected x, y [m], von Mises [Pa]): the
   * figure borrows them until its next picture */
  double *pic_x, *pic_y, *pic_v;
  size_t pic_cap;
  /* voxels of a body that does not fill its box (.vtu), built once: 8 corner
   * ids per element, corner coordinates, grid cell per element, number of
   * voxels at each corner */
  int64_t *vx_conn;
  float *vx_xyz, *vx_count;
  size_t *vx_cell, vx_npoint;
  struct px_lattice_ranks *ranks; /* owned; NULL on one rank (lattice_ranks.c) */
  /* Over ranks (lattice_ranks.c): the engine runs on the model of this
   * rank's window of the grid (its block and halo), wm; m stays the whole
   * body's (selections, outputs, checkpoints). On rank 0 after a gather, gy
   * and gl hold the whole state and link flags in m's layout. */
  struct px_lattice_model wm; /* owned */
  struct lt_el *gy;           /* owned; rank 0 over ranks */
  uint8_t *gl;                /* owned; rank 0 over ranks */
  double fields_time;         /* time the fields were read (NaN: stale) */
  long fields_step;
  /* Over ranks, a probes.csv row without the whole gather
   * (px_lattice_gather_series, at step series_step; -1 none): each probe's
   * sums of ux uy uz von_mises over its cells (4 nprobe, in cell order),
   * then the largest von Mises stress and its grid cell, the largest |u|
   * and its grid cell. */
  double *sacc; /* owned; 4 nprobe + 4 */
  long series_step;
};

/* Columns of probes.csv after "t [s]" and the 4 of each probe
 * (ux uy uz von_mises): offsets from 1 + 4 nprobe. */
enum px_lattice_col {
  PX_LATTICE_COL_BROKEN = 0,  /* broken_links [-] */
  PX_LATTICE_COL_DAMPING = 1, /* damping [1/s] */
  PX_LATTICE_COL_VM = 2,      /* max_von_mises [Pa], then its element centre x y z [m] */
  PX_LATTICE_COL_U = 6,       /* max_displacement [m], then its element centre x y z [m] */
  PX_LATTICE_COL_STATIC = 10, /* static_error [-] (quasi-static runs only) */
  PX_LATTICE_COL_END = 11
};

/* Largest and smallest normal magnitude of the engine's reals (setup and
 * checkpoint checks). */
static inline double px_lattice_real_max(const struct px_lattice *L) {
  return L->precision == PX_PRECISION_SINGLE ? FLT_MAX : DBL_MAX;
}
static inline double px_lattice_real_min(const struct px_lattice *L) {
  return L->precision == PX_PRECISION_SINGLE ? FLT_MIN : DBL_MIN;
}

/* Checkpoints (lattice_checkpoint.c). */
enum px_status px_lattice_save(void *state, struct px_checkpoint_writer *w);
enum px_status px_lattice_load(void *state, struct px_checkpoint *ck);

/* Several ranks (lattice_ranks.c): split the grid over the ranks of the
 * run's communicator (blocks of grid rows, or a 2-D (y, z) rank grid),
 * build the model of this rank's window (L->wm) and create the engine on
 * it (options o), working on its block; refuses, at its key, an engine
 * without blocks or more ranks than the grid can take. On one rank: the
 * engine on the whole model. */
enum px_status px_lattice_ranks_create(struct px_lattice *L, struct px_case *c,
                                       const struct px_lattice_engine_opts *o);
void px_lattice_ranks_free(struct px_lattice *L);
/* The solver's gather hook: every block's state, link flags and output
 * fields (at the current step) onto rank 0 (L->gy, L->gl, L->fu ...). */
enum px_status px_lattice_gather(void *state);
/* The solver's gather hook for a probes.csv row alone: each rank's fields
 * of its block reduced to the row's inputs on every rank (L->sacc), not
 * the whole state onto rank 0. Collective. */
enum px_status px_lattice_gather_series(void *state);
/* The engine's padded entry of grid cell c (m's numbering), or (size_t)-1
 * when c is outside this rank's window. */
size_t px_lattice_local_index(const struct px_lattice *L, size_t c);
/* Over ranks: the engine's (window's) padded entry of entry gi of m's
 * layout, its row (*wj, *wk) from the window's corner; (size_t)-1 when gi
 * lies outside the window (and on one rank). */
size_t px_lattice_window_entry(const struct px_lattice *L, size_t gi, size_t *wj, size_t *wk);
/* The engine's model: L->wm over ranks, L->m on one rank. */
static inline const struct px_lattice_model *px_lattice_engine_model(const struct px_lattice *L) {
  return L->ranks ? &L->wm : &L->m;
}
/* Boundaries z[0..size] (z[0] = 0, z[size] = n) of `size` blocks of units
 * (planes or grid rows) of at least `minw` units each, balancing the
 * elements (count[k] in unit k) per block: boundary r is the first unit at
 * which the blocks below hold at least r / size of the elements, moved to
 * leave every block minw units. -1 when n < size minw, size < 1 or
 * minw < 1. */
int px_lattice_ranks_split(const size_t *count, long n, long minw, int size, long *z);
/* The rank grid py x pz = size over (y, z) for a grid of n[0] x n[1] x n[2]
 * cells (x rows stay whole: x is the padded SIMD axis) with the least halo
 * area, counted from the extents: (pz - 1) n[0] n[1] + (py - 1) n[0] n[2]
 * cut faces (ties: fewer z cuts), each block at least one cell wide
 * (py <= n[1], pz <= n[2]). -1 when no grid fits (size < 1). */
int px_lattice_ranks_grid(const int n[3], int size, int *py, int *pz);

/* Refuse, before anything of the size of the grid g is allocated, a
 * lattice that this machine (or its device) cannot hold or the engine
 * (options o) cannot index: at lattice.h, with the figures; over ranks, a
 * rank's share. Records the host estimate in L->need_host (lattice_need.c). */
enum px_status px_lattice_need(struct px_lattice *L, struct px_case *c,
                               const struct px_lattice_grid *g,
                               const struct px_lattice_engine_opts *o);

/* Longest output path [bytes]. */
#define PX_LATTICE_PATH_MAX 4096

/* Outputs (lattice_output.c; lattice_plots.c: px_lattice_finish and
 * px_lattice_report, from probes.csv read back). */
enum px_status px_lattice_fetch(struct px_lattice *L, const struct px_sim_output *o);
/* The host fields (fu, fv, fs, fvm, flinks: m's layout), allocated once. */
enum px_status px_lattice_fields_room(struct px_lattice *L);
enum px_status px_lattice_snapshot(void *state, const struct px_sim_output *o);
enum px_status px_lattice_series(void *state, const struct px_sim_output *o);
/* Results in memory (lattice_results.c): px_solver_i.results. */
enum px_status px_lattice_results(void *state, const struct px_sim_output *o,
                                  enum px_results_kind kind, struct px_results *out);
enum px_status px_lattice_picture(void *state, const struct px_sim_output *o);
enum px_status px_lattice_finish(void *state, const struct px_sim_output *o);
enum px_status px_lattice_report(void *state, const struct px_sim_output *o,
                                 struct px_summary *sum);
void px_lattice_output_free(struct px_lattice *L);
/* Columns of probes.csv. */
size_t px_lattice_columns(const struct px_lattice *L);
/* A resumed run: delete, once, the picture an earlier segment drew only
 * because it ended off the picture schedule (struct px_sim_output). */
enum px_status px_lattice_resume_clean(struct px_lattice *L, const struct px_sim_output *o);
/* The element (grid cell) with the largest von Mises stress (which = 0) or
 * |u| (which = 1) in the fetched fields, and that value; ties: the first. */
size_t px_lattice_argmax(const struct px_lattice *L, int which, double *value);
/* The centre of grid cell c [m], rounded to 15 significant digits. */
void px_lattice_centre_tidy(const struct px_lattice *L, size_t c, double x[3]);

#endif
