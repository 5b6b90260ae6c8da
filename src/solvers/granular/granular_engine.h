/* A granular engine advances a prepared system (system.h): the cpu loops
 * (granular_cpu.c, the system's own step) or the OpenCL kernels
 * (granular_opencl.c, device-resident state with the system as host
 * mirror). The solver picks one engine by backend name, once, with
 * PX_BACKEND_PICK (granular.c) and drives it through this table only: it
 * never asks which backend it runs on. Outputs and checkpoints read the
 * system after `sync`. No engine calls another engine's table; the opencl
 * engine uses the system's host services on its mirror (contour frames,
 * event statistics, and at `sync` the mirror's lists and wall reactions,
 * which the outputs read). */
#ifndef PX_GRAN_ENGINE_H
#define PX_GRAN_ENGINE_H

#include <stddef.h>
#include <stdint.h>

#include "partix/backend.h"
#include "partix/checkpoint.h"
#include "solvers/granular/system.h"

/* What an engine can do on a backend, asked before anything is built (the
 * case check refuses what it cannot, naming the key). */
struct px_gran_caps {
  int fp64;                /* double and mixed precision (the device computes in double) */
  int abm4;                /* integrator: abm4 (else velocity Verlet only) */
  int host_threads;        /* threads of the host loops (>= 1; 1: the engine does not use them) */
  int ranks;               /* runs one case over K > 1 MPI ranks (the gather below) */
  const char *why_no_abm4; /* borrowed, static: why abm4 is missing (messages); NULL if not */
};

struct px_gran_engine_i {
  const char *name; /* the backend's name (first member: PX_BACKEND_PICK) */
  /* Fill *caps for backend be; never fails. */
  void (*caps)(struct px_backend *be, struct px_gran_caps *caps);
  /* An engine for the prepared system s (borrowed for the engine's life:
   * the cpu engine steps it, the opencl engine keeps it as its host
   * mirror), ready to step from s->step. */
  enum px_status (*create)(struct px_backend *be, struct px_gran_sys *s, void **out);
  void (*destroy)(void *e);
  /* One step of dt [s], the step index `step` (the driver's count: a case
   * that gives time.dt after an automatic one steps with the driver's dt). */
  enum px_status (*step)(void *e, long step, double dt);
  /* Bring the state, the wall slots and the statistics into the system (for
   * outputs and checkpoints); nothing where they live there. */
  enum px_status (*sync)(void *e);
  /* Over K > 1 ranks (collective, every rank): the owners' state onto rank
   * 0's system as `sync` brings it there on one rank; NULL where the engine
   * runs on one rank only (caps.ranks 0). */
  enum px_status (*gather)(void *e);
  /* Sections of the engine's own state beside the system's (lists and
   * histories kept on a device), and their restoration after the system's
   * are loaded; NULL: none. */
  enum px_status (*save)(void *e, struct px_checkpoint_writer *w);
  enum px_status (*load)(void *e, struct px_checkpoint *ck);
  /* Optional (tests), NULL where the system is the state. Replace the
   * engine's state by the system's (positions, velocities, accelerations,
   * wall slots; lists rebuilt at the next step). */
  enum px_status (*upload)(void *e);
  /* Contacts (pairs of particle ids i < j with overlap > 0) through the
   * engine's own neighbour lists, sorted; *pairs owned by the caller
   * (px_mem_free on the system's context). */
  enum px_status (*contacts)(void *e, int32_t **pairs, size_t *np);
};

extern const struct px_gran_engine_i px_gran_engine_cpu;
/* With the opencl backend only (granular_opencl.c; listed with PX_IF_OPENCL). */
extern const struct px_gran_engine_i px_gran_engine_opencl;
/* Tests only, not picked by backend name (granular_ref.c): plain double
 * loops over all pairs and all segments calling the same physics, the
 * engine the others are compared with. */
extern const struct px_gran_engine_i px_gran_engine_ref;

#endif
