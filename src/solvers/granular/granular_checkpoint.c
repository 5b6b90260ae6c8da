/* Checkpoints of the granular solver: the system (system.c) and the state
 * of the run's series (centre-of-mass travel). */
#include <string.h>

#include "partix/checkpoint.h"
#include "solvers/granular/granular_impl.h"

enum px_status px_gran_save(struct px_gran_run *r, struct px_checkpoint_writer *w) {
  double v[8];
  PX_TRY(px_gran_sync(r));
  PX_TRY(px_gran_sys_save(r->sys, w));
#ifdef PX_HAVE_OPENCL
  if (r->cl) PX_TRY(px_gran_cl_save(r->cl, w));
#endif
  v[0] = r->com0[0], v[1] = r->com0[1], v[2] = r->com_prev[0], v[3] = r->com_prev[1];
  v[4] = r->travel, v[5] = r->com_started, v[6] = (double)r->sys->ev_overflow, v[7] = 0;
  return px_checkpoint_write(w, "granular.run", PX_DTYPE_F64, 8, v);
}

enum px_status px_gran_load(struct px_gran_run *r, struct px_checkpoint *ck) {
  double v[8];
  PX_TRY(px_gran_sys_load(r->sys, ck));
  PX_TRY(px_checkpoint_read(ck, "granular.run", PX_DTYPE_F64, 8, v));
  r->com0[0] = v[0], r->com0[1] = v[1], r->com_prev[0] = v[2], r->com_prev[1] = v[3];
  r->travel = v[4];
  r->com_started = (int)v[5];
  r->sys->ev_overflow = (size_t)v[6];
  r->dt = r->sys->dt;
#ifdef PX_HAVE_OPENCL
  if (r->cl) PX_TRY(px_gran_cl_load(r->cl, ck));
#endif
  r->synced_step = r->sys->step;
  return PX_STATUS_OK;
}
