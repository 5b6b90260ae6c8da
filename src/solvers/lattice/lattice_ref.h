/* Reference implementation of the lattice time step: double precision, plain
 * loops, every link evaluated once and scattered to both ends, stages in
 * separate passes. Slow and obviously correct; the optimized cpu and opencl
 * engines are tested against it. */
#ifndef PX_LATTICE_REF_H
#define PX_LATTICE_REF_H

#include "solvers/lattice/lattice_c.h"
#include "solvers/lattice/lattice_model.h"

struct px_lattice_ref {
  struct px_context *ctx;           /* borrowed */
  const struct px_lattice_model *m; /* borrowed */
  enum px_lattice_integrator integ;
  /* State, padded layout (nalloc entries). RK4: values at t. Leapfrog: u, q
   * at t and v, W at t - dt/2. */
  struct lt_el *y; /* owned */
  uint8_t *links;  /* owned; current link flags */
  double alpha;    /* global damping in use [1/s] */
  long broken;     /* links broken so far */
  /* workspace (owned) */
  struct lt_el *ys, *k, *acc;
  struct lt_v3 *F, *T;
  double *table; /* ngroup x stride */
};

enum px_status px_lattice_ref_create(struct px_context *ctx, const struct px_lattice_model *m,
                                     enum px_lattice_integrator integ, struct px_lattice_ref *r);
void px_lattice_ref_free(struct px_lattice_ref *r);

/* Link constants of the model in the kernel's form. */
void px_lattice_lpar_d(const struct px_lattice_model *m, struct lt_lpar *p);
void px_lattice_fpar_d(const struct px_lattice_model *m, struct lt_fpar *f);

/* Sum of link forces F and torques T (global frame) on every element for
 * state y and link flags `links`. With `fracture`, links whose breaking
 * measure reaches 1 are cleared in `links` first (counted in *broken). */
void px_lattice_ref_forces(const struct px_lattice_model *m, uint8_t *links, const struct lt_el *y,
                           int fracture, long *broken, struct lt_v3 *F, struct lt_v3 *T);

/* Advance from t to t + dt. PX_STATUS_NUMERIC (naming the element and the
 * quantity) if the new state is not finite. */
enum px_status px_lattice_ref_step(struct px_lattice_ref *r, double t, double dt);

/* Kinetic and elastic energy [J] at time t. For leapfrog the velocities are
 * synchronized to t first (v(t) = v(t - dt/2) + dt/2 a(t)). */
void px_lattice_ref_energy(struct px_lattice_ref *r, double t, double dt, double *kinetic,
                           double *elastic);

/* Love-Weber stress of every element (padded layout, zero for void). */
void px_lattice_ref_stress(const struct px_lattice_ref *r, struct lt_sym *s);

/* PX_STATUS_NUMERIC naming the first element with a non-finite state. */
enum px_status px_lattice_check_finite_d(struct px_context *ctx, const struct px_lattice_model *m,
                                         const struct lt_el *y, long step);

#endif
