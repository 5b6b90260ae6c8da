/* The vortex time step on an OpenCL device (vortex_opencl.c, vortex.cl):
 * used by the engine when its backend is `opencl`. */
#ifndef PX_VORTEX_OPENCL_H
#define PX_VORTEX_OPENCL_H

#include "solvers/vortex/vortex_core.h"

#ifdef PX_HAVE_OPENCL
/* Device buffers, program, panels and the inverse generation matrix. */
enum px_status px_vortex_ocl_create(struct px_vortex_engine *e);
void px_vortex_ocl_free(struct px_vortex_engine *e);
/* One step with the free stream (vx, vy); the engine does the bookkeeping. */
enum px_status px_vortex_ocl_step(struct px_vortex_engine *e, double vx, double vy);
/* Device wake -> host arrays (for outputs and checkpoints). */
enum px_status px_vortex_ocl_sync(struct px_vortex_engine *e);
/* The host wake changed: upload it before the next step. */
void px_vortex_ocl_mark_dirty(struct px_vortex_engine *e);
#endif

#endif
