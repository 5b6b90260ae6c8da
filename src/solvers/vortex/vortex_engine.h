/* A vortex engine runs the blocks of a step where the wake lives: on the
 * host in double (`cpu`, vortex_cpu.c and vortex_diffusive.c) or in device
 * buffers (`opencl`, vortex_opencl.c, kernels in vortex.cl). One table per backend, picked once
 * by the backend's name (PX_BACKEND_PICK) when the engine is created; the
 * driver (vortex_engine.c) times the blocks and keeps the step count, so an
 * engine never calls another one and no solver file asks which backend it
 * runs on.
 *
 * The blocks of a step (vortex_core.h has the physics of each), in order:
 * begin, generation, convective, diffusive, loads, move, inside, restructure.
 * Their state between blocks (the newborns, the moved positions, the crossed
 * panels) lives in the engine (struct px_vortex_engine, or the device state
 * behind e->dev). */
#ifndef PX_VORTEX_ENGINE_H
#define PX_VORTEX_ENGINE_H

#include "partix/backend.h"
#include "solvers/vortex/vortex_core.h"

/* What an engine can compute on a backend; a case that asks for more is
 * refused at its key (vortex.c) instead of running different physics. */
struct px_vortex_caps {
  int fp64;  /* storage and sums in double (backend.precision double; mixed
                keeps its float sums either way) */
  int fmm;   /* the fast multipole method for the velocity sums (method fmm,
                and auto's choice of it above ~4e6 pairs) */
  int mixed; /* precision mixed: float pair sums with double storage */
  int ranks; /* splits its sums over the ranks of a run (vortex_ranks.h) */
};

struct px_vortex_engine_i {
  const char *backend; /* "cpu", "opencl": first member, for PX_BACKEND_PICK */
  void (*caps)(struct px_backend *be, struct px_vortex_caps *out);
  /* The engine's own state once the shared one (panels, trees, buffers of
   * the sums) is built; NULL: none. destroy frees it (NULL: nothing). */
  enum px_status (*create)(struct px_vortex_engine *e);
  void (*destroy)(struct px_vortex_engine *e);
  /* Blocks of the step at free stream (vx, vy) [m/s] (the step's start). */
  enum px_status (*begin)(struct px_vortex_engine *e);
  enum px_status (*generation)(struct px_vortex_engine *e, double vx, double vy);
  enum px_status (*convective)(struct px_vortex_engine *e, double vx, double vy);
  enum px_status (*diffusive)(struct px_vortex_engine *e);
  enum px_status (*loads)(struct px_vortex_engine *e);
  enum px_status (*move)(struct px_vortex_engine *e);
  enum px_status (*inside)(struct px_vortex_engine *e);
  enum px_status (*restructure)(struct px_vortex_engine *e);
  /* Wait for the block's work before the driver reads its clock (NULL: the
   * block ran to its end on the host). */
  enum px_status (*finish)(struct px_vortex_engine *e);
  /* Device -> host copy of the wake, sheet, absorbed circulation and wall
   * vorticity (NULL: the host copy is the state). */
  enum px_status (*sync)(struct px_vortex_engine *e);
  /* The host wake changed (checkpoint, added vortices): upload before the
   * next step (NULL: nothing to do). */
  void (*host_changed)(struct px_vortex_engine *e);
};

extern const struct px_vortex_engine_i px_vortex_engine_cpu;
extern const struct px_vortex_engine_i px_vortex_engine_opencl; /* with the opencl backend */
/* The reference (vortex_ref.c): plain loops in double on one thread, direct
 * O(N^2) sums, for tests that cross-check the others; not in the pick table
 * (px_vortex_engine_create_ops runs it). */
extern const struct px_vortex_engine_i px_vortex_engine_ref;

/* px_vortex_engine_create (vortex_core.h) with the engine ops instead of the
 * backend's own (tests: the reference); be still runs what the host state
 * sets up with it (the pair sums' evaluator). */
enum px_status px_vortex_engine_create_ops(struct px_context *ctx, struct px_backend *be,
                                           const struct px_vortex_engine_i *ops,
                                           const struct px_vortex_config *cfg,
                                           const struct px_vortex_contour *bodies, size_t nbody,
                                           struct px_vortex_engine **out);
/* The engine of backend be (NULL with the message set: none for it). */
const struct px_vortex_engine_i *px_vortex_engine_pick(struct px_backend *be);
/* What the engine of backend be can compute (PX_STATUS_UNSUPPORTED with a
 * message when there is none). */
enum px_status px_vortex_engine_caps(struct px_backend *be, struct px_vortex_caps *out);

#endif
