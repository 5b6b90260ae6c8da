/* The granular solver's cpu engine: the system steps itself (system.c, the
 * loops of cpu_loops.h per precision); state, lists and histories live in
 * the system, so there is nothing to sync, save or load beside it. */
#include "partix/backend.h"
#include "solvers/granular/granular_engine.h"

static void px_gran_cpu_caps(struct px_backend *be, struct px_gran_caps *caps) {
  const int threads = be ? px_backend_threads(be) : 1;
  caps->fp64 = 1;
  caps->abm4 = 1;
  caps->host_threads = threads > 0 ? threads : 1;
  caps->ranks = 1;
  caps->why_no_abm4 = NULL;
}

static enum px_status px_gran_cpu_create(struct px_backend *be, struct px_gran_sys *s, void **out) {
  (void)be;
  *out = s;
  return PX_STATUS_OK;
}

/* The system is the run's (freed by it). */
static void px_gran_cpu_destroy(void *e) { (void)e; }

static enum px_status px_gran_cpu_step(void *e, long step, double dt) {
  struct px_gran_sys *s = e;
  if (step != s->step || dt != s->dt) {
    if (dt != s->dt) s->dt = dt; /* the case gave time.dt after an automatic dt */
    s->step = step;
    s->t = (double)step * dt;
  }
  return px_gran_sys_step(s);
}

static enum px_status px_gran_cpu_sync(void *e) {
  (void)e;
  return PX_STATUS_OK;
}

/* Over ranks: the owners' slots onto rank 0 (system_ranks.c). */
static enum px_status px_gran_cpu_gather(void *e) { return px_gran_ranks_sync(e, 0); }

static enum px_status px_gran_cpu_contacts(void *e, int32_t **pairs, size_t *np) {
  return px_gran_sys_contacts_list(e, pairs, np);
}

const struct px_gran_engine_i px_gran_engine_cpu = {.name = "cpu",
                                                    .caps = px_gran_cpu_caps,
                                                    .create = px_gran_cpu_create,
                                                    .destroy = px_gran_cpu_destroy,
                                                    .step = px_gran_cpu_step,
                                                    .sync = px_gran_cpu_sync,
                                                    .gather = px_gran_cpu_gather,
                                                    .save = NULL,
                                                    .load = NULL,
                                                    .upload = NULL,
                                                    .contacts = px_gran_cpu_contacts};
