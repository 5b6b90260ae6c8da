/* A lattice engine advances the state of a model: the double-precision
 * reference (lattice_ref.c), the optimized cpu loops (lattice_cpu.c) or the
 * OpenCL kernels (lattice_opencl.c). The solver and the tests drive every engine
 * through this table; state crosses to the host only through get/set/fields
 * (at output, checkpoints and in tests). */
#ifndef PX_LATTICE_ENGINE_H
#define PX_LATTICE_ENGINE_H

#include "partix/backend.h"
#include "partix/types.h"
#include "solvers/lattice/lattice_model.h"

/* The state of one element, lattice_kernel.h compiled in double (host code
 * includes lattice_c.h for its layout). */
struct lt_el;

/* How links are evaluated. */
enum px_lattice_scheme {
  PX_LATTICE_SCHEME_AUTO = 0,     /* the faster one for the engine (benchmarked) */
  PX_LATTICE_SCHEME_GATHER = 1,   /* each element evaluates its 6 links */
  PX_LATTICE_SCHEME_LINK_ONCE = 2 /* each link once into per-axis arrays, then
                                     each element gathers its 6 results */
};

struct px_lattice_engine_opts {
  enum px_lattice_integrator integ;
  enum px_precision precision; /* single or double (mixed = single here) */
  enum px_lattice_scheme scheme;
  int threads;                /* cpu: OpenMP threads (0 = all) */
  int tune;                   /* cpu: 1 or `threads` per step, the faster
                                 measured (core/tuner.h); 0: always `threads` */
  struct px_backend *backend; /* borrowed; opencl: the device */
  int vol;                    /* lattice.poisson != 0: 3 volumetric reals per
                                 element more (the size check, need()) */
};

/* Output fields of one element set (host, padded layout, nalloc entries
 * each; any pointer may be NULL when not wanted). */
struct px_lattice_fields {
  double *u;      /* displacement, 3 per element [m] */
  double *v;      /* velocity, 3 per element [m/s] (leapfrog: synchronized) */
  double *sigma;  /* stress xx yy zz xy yz zx, 6 per element [Pa] */
  double *vm;     /* von Mises stress [Pa] */
  uint8_t *links; /* link flags (bits as PX_LATTICE_LINK_*) */
};

/* What an engine needs for a model of a given layout, known before anything
 * is built or allocated (px_lattice_need in lattice.c adds the model and the
 * outputs and refuses a case beyond the machine at lattice.h). Bytes [B]. */
struct px_lattice_need {
  double host;                   /* host memory of the engine (its transients included) */
  double device;                 /* device memory (0: the state lives on the host) */
  double device_have;            /* the device's global memory (0: unknown or none) */
  double buffer;                 /* the largest single device buffer */
  double buffer_max;             /* the device's largest allocation (0: unknown or none) */
  double nalloc_max;             /* most padded elements (layout nalloc) the engine can
                                    index (0: no limit below the grid's) */
  const char *index_why;         /* borrowed, static: why nalloc_max (messages) */
  enum px_lattice_scheme scheme; /* what create resolves the options' scheme
                                    to (auto: the engine's faster one) */
};

/* State components of an element in an engine's SoA buffers: u (3), q (4),
 * v (3), W (3). */
#define PX_LATTICE_NCOMP 13

/* A block of a decomposition over ranks (lattice_ranks.c): the engine
 * updates the grid rows r0 <= r < r1 only (row r = j + n[1] k, the entries
 * pad + r n0p .. + n0p of the padded layout; a plane is n[1] rows). The
 * state of the other rows it holds is stale except the halo, the n[1] rows
 * on each side ([r0 - n[1], r0) and [r1, r1 + n[1])), which the callbacks
 * refresh: a block holds at least n[1] rows, so that its halo is its
 * neighbours'. Link-once blocks are whole planes (r0, r1 multiples of
 * n[1]: its sweeps run by planes). The global quantities it computes (the
 * Rayleigh sums, the broken-link count) come out as on one rank. The
 * callbacks are collective over the ranks, called in the same order on
 * every rank. */
struct px_lattice_block {
  long r0, r1; /* rows this rank updates (0 <= r0 < r1 <= n[1] n[2]) */
  /* A block of a 2-D rank grid over (y, z) when j1 > 0 (the gather scheme
   * only; 0 for the row blocks above): the rows j + n[1] k for j in
   * [j0, j1), k in [k0, k1) (r0, r1 then bound them: j0 + n[1] k0 and
   * j1 + n[1] (k1 - 1)); its halo is the row j0 - 1 and j1 of each of its
   * planes and the rows [j0, j1) of the planes k0 - 1 and k1 (the links
   * reach the 6 face neighbours only, none diagonally). */
  long j0, j1, k0, k1;
  void *arg; /* the callbacks' first argument */
  /* Post the exchange of the halo planes of the SoA state buffer buf
   * (PX_LATTICE_NCOMP components of ns reals of `real` bytes, padded
   * layout): the rows [r0, r0 + n[1]) and [r1 - n[1], r1) go to the
   * neighbours, the halo rows arrive; they are written by halo_wait, and
   * buf's own rows must not change before it returns. */
  enum px_status (*halo_start)(void *arg, void *buf, size_t real, size_t ns);
  /* Post the exchange of the halo of the volumetric coefficients pv (3
   * components P_x P_y P_z of ns reals, padded layout; nu != 0), after the
   * state's halo_wait returned: only what an own element's links read,
   * P_a of the halo elements its links along a reach (row blocks: P_z of
   * the n[1] halo rows and P_y of the one row next to the cut; a 2-D grid:
   * P_y across a y cut, P_z across a z cut), one message per neighbour and
   * way. halo_wait completes it. */
  enum px_status (*vol_start)(void *arg, void *pv, size_t real, size_t ns);
  enum px_status (*halo_wait)(void *arg);
  /* rows: k arrays of per-row partial sums over the rows of the engine's
   * model (its window: n[1] n[2] of them), those of this block filled;
   * sums[a] = the sum of array a over every rank's rows, added in the
   * global row order (as one rank adds them). */
  enum px_status (*rows)(void *arg, const double *rows, size_t k, double *sums);
  /* *v = the sum of *v over the ranks (exact: integers). */
  enum px_status (*count)(void *arg, long *v);
};

/* Rectangle q of 2-D block b as {ja, jb, ka, kb} (the rows j in [ja, jb) of
 * the planes k in [ka, kb)): q = 0 its interior, whose elements read no
 * halo; q = 1..4 the bands along its faces, which partition the rest (the
 * cpu and opencl engines compute the interior while the halo travels). */
void px_lattice_block_rect(const struct px_lattice_block *b, int q, long r[4]);

struct px_lattice_engine_i {
  const char *name;
  /* Fill *need for the layout and options (see above); never fails. */
  void (*need)(const struct px_lattice_layout *lay, const struct px_lattice_engine_opts *o,
               struct px_lattice_need *need);
  enum px_status (*create)(struct px_context *ctx, const struct px_lattice_model *m,
                           const struct px_lattice_engine_opts *o, void **out);
  void (*destroy)(void *e);
  /* Advance n steps of dt from time t (step index of the first: `step`). */
  enum px_status (*run)(void *e, long step, double t, double dt, long n);
  /* Whole state to/from the host in double (padded layout). For leapfrog
   * the velocities are those at t - dt/2. */
  enum px_status (*get_state)(void *e, struct lt_el *y, uint8_t *links);
  enum px_status (*set_state)(void *e, const struct lt_el *y, const uint8_t *links);
  /* Output fields at time t, computed where the state lives. */
  enum px_status (*fields)(void *e, double t, double dt, const struct px_lattice_fields *f);
  /* Rayleigh quotient pieces of the current displacement field q (u and the
   * rotation vector theta = 2 vec(q)): num = q.K q (= -q.f_int) [J],
   * den = q.M q [kg m^2]; and rate = q.M dq/dt = sum m u.v + I theta.W
   * [kg m^2/s] of the stored velocities (leapfrog: those at t - dt/2). */
  enum px_status (*rayleigh)(void *e, double *num, double *den, double *rate);
  /* Global mass damping in use [1/s]. */
  void (*set_alpha)(void *e, double alpha);
  /* Links broken so far (and its restoration on resume), and bytes of
   * device/host memory per box cell. */
  long (*broken)(void *e);
  enum px_status (*set_broken)(void *e, long links);
  size_t (*bytes)(void *e);
  /* The link scheme in use (what `auto` resolved to). */
  enum px_lattice_scheme (*scheme)(void *e);
  /* Work on a block from now on (b copied; NULL: the whole grid, the
   * default). NULL for an engine that cannot: then a run on several ranks is
   * refused. Every rank holds the whole state (get_state, set_state and
   * fields read and write all of it: after a gather it is the global
   * state). */
  enum px_status (*set_block)(void *e, const struct px_lattice_block *b);
};

extern const struct px_lattice_engine_i px_lattice_engine_ref;
extern const struct px_lattice_engine_i px_lattice_engine_cpu;
/* lattice_opencl.c: built with the opencl backend only (PX_IF_OPENCL). */
extern const struct px_lattice_engine_i px_lattice_engine_opencl;

/* Quasi-static relaxation (adaptive dynamic relaxation, Underwood 1983, in
 * "Computational Methods for Transient Analysis", ch. 5): every `every`
 * steps set the global damping to 2 omega, omega^2 the Rayleigh quotient of
 * the current displacement field, i.e. critical damping of the mode the
 * solution is converging in. `ratio` (may be NULL) receives the relative
 * rate of change of the displacement field per radian of that mode,
 *   |q.M dq/dt| / (omega q.M q) = |q.M v| / sqrt(q.K q q.M q)  [-]
 * (NaN before the body is strained): near statics the slowest mode
 * dominates the remaining error e = q - q_static and, critically damped,
 * moves with v = -omega e, so the ratio estimates |q.M e| / q.M q, the
 * relative distance from the static solution along the displacement field.
 * The projection on q keeps the round-off noise of single precision out:
 * it is spread over the high modes (its kinetic energy alone would stall a
 * criterion at 1e-3..1e-2 on a float plate), which q barely contains. */
enum px_status px_lattice_relax_update(const struct px_lattice_engine_i *vt, void *e, double *alpha,
                                       double *ratio);

#endif
