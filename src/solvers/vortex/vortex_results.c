/* The vortex solver's results in memory (partix/results.h): the wake's
 * vortices as the snapshots (wake_*.vtp) hold them. */
#include <stddef.h>

#include "solvers/vortex/vortex_solver.h"

enum px_status px_vortex_results(void *state, const struct px_sim_output *o,
                                 enum px_results_kind kind, struct px_results *out) {
  struct vx_state *s = state;
  struct px_vortex_wake *w;
  static const struct {
    const char *name, *units;
    size_t offset; /* of the array in struct px_vortex_wake */
  } cols[] = {{"x", "m", offsetof(struct px_vortex_wake, x)},
              {"y", "m", offsetof(struct px_vortex_wake, y)},
              {"gamma", "m^2/s", offsetof(struct px_vortex_wake, g)},
              {"core_radius", "m", offsetof(struct px_vortex_wake, e)},
              {"u", "m/s", offsetof(struct px_vortex_wake, u)},
              {"v", "m/s", offsetof(struct px_vortex_wake, v)}};
  size_t k;
  (void)o;
  if (kind != PX_RESULTS_STATE) return PX_STATUS_UNSUPPORTED;
  /* the wake on the host (an OpenCL engine keeps it on the device) */
  PX_TRY(px_vortex_engine_sync(s->e));
  w = &s->e->w;
  for (k = 0; k < sizeof cols / sizeof cols[0]; ++k) {
    const double *a = *(double *const *)((const char *)w + cols[k].offset);
    if (!px_results_add(out, cols[k].name, cols[k].units, PX_VIEW_F64, w->n, 1, w->n ? a : NULL))
      return px_context_fail(s->ctx, PX_STATUS_NOMEM, "out of memory (results of %zu vortices)",
                             w->n);
  }
  return PX_STATUS_OK;
}
