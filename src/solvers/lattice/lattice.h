/* The lattice solver's run state (internal; shared by lattice.c and
 * lattice_output.c). */
#ifndef PX_LATTICE_H
#define PX_LATTICE_H

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

struct px_lattice {
  struct px_sim *sim;                      /* borrowed */
  struct px_context *ctx;                  /* borrowed */
  struct px_lattice_model m;               /* owned */
  const struct px_lattice_engine_i *vt;    /* static */
  void *e;                                 /* owned through vt->destroy */
  enum px_lattice_integrator integ;
  enum px_precision precision;
  double dt_limit, safety;
  int quasi_static;
  double alpha;                            /* global damping in use [1/s] */
  struct px_lattice_probe *probes;         /* owned */
  size_t nprobe;
  enum px_lattice_view view;
  double picture_scale;                    /* displacement magnification, 0 = auto */
  char title[128];
  /* outputs (owned, created on first use) */
  struct px_vtk *vtk;
  struct px_vtk_series *pvd;
  struct px_csv *csv;
  struct px_figure *fig;
  double *fu, *fv, *fs, *fvm;              /* host fields, padded layout */
  uint8_t *flinks;
  /* voxels of a body that does not fill its box (.vtu), built once: 8 corner
   * ids per element, corner coordinates, grid cell per element, number of
   * voxels at each corner */
  int64_t *vx_conn;
  float *vx_xyz, *vx_count;
  size_t *vx_cell, vx_npoint;
  double fields_time;                      /* time the fields were read (NaN: stale) */
  long fields_step;
  /* probe history for the end-of-run plot (owned) */
  double *hist;                            /* rows of 1 + nprobe values */
  size_t nhist, cap_hist;
};

/* Outputs (lattice_output.c). */
enum px_status px_lattice_fetch(struct px_lattice *L, const struct px_sim_output *o);
enum px_status px_lattice_snapshot(void *state, const struct px_sim_output *o);
enum px_status px_lattice_series(void *state, const struct px_sim_output *o);
enum px_status px_lattice_picture(void *state, const struct px_sim_output *o);
enum px_status px_lattice_finish(void *state, const struct px_sim_output *o);
void px_lattice_output_free(struct px_lattice *L);

#endif
