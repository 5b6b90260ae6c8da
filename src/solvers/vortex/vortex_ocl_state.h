/* The opencl vortex engine's device state, shared by its blocks
 * (vortex_opencl.c) and its buffers and transfers (vortex_buffers_opencl.c);
 * private to them. Compiled only with the opencl backend. */
#ifndef PX_VORTEX_OCL_STATE_H
#define PX_VORTEX_OCL_STATE_H

#include <CL/cl.h>

#include "compute/opencl/kernels.h"
#include "solvers/vortex/vortex_engine.h"

/* Work-items of the one work-group per panel or per body that sums the wall
 * vorticity and the loads (vortex.cl: each takes every VX_OCL_GROUP-th
 * vortex or panel, then a tree reduction in local memory, the same order on
 * every device); passed to the kernels' build. */
#define VX_OCL_GROUP 64
/* Work-items of the merges' one work-group (vx_merge) */
#define VX_OCL_MERGE 256
#define VX_OCL_STR2(x) #x
#define VX_OCL_STR(x) VX_OCL_STR2(x)
#define VX_OCL_SIZES \
  " -DVX_OCL_GROUP=" VX_OCL_STR(VX_OCL_GROUP) " -DVX_OCL_MERGE=" VX_OCL_STR(VX_OCL_MERGE)

enum {
  /* wake, two sets (A: current, B: compaction target) */
  W_X,
  W_Y,
  W_G,
  W_U,
  W_V,
  W_E,
  W_X2,
  W_Y2,
  W_G2,
  W_U2,
  W_V2,
  W_E2,
  W_WU,
  W_WV,
  W_XN,
  W_YN,
  W_MX,
  W_MY, /* reals */
  W_BORN,
  W_HIT,
  W_PARTNER,
  W_KEEP,
  W_POS, /* ints */
  W_NB_X,
  W_NB_Y,
  W_NB_G,
  W_NB_U,
  W_NB_V, /* N-body precision */
  W_COUNT_
};
enum {
  P_X0,
  P_Y0,
  P_X1,
  P_Y1,
  P_TX,
  P_TY,
  P_LEN,
  P_AINV,
  P_RHS,
  P_SOL,
  P_THROUGH,
  P_PE,
  P_OMEGA,
  P_CENTER,
  P_BBOX,
  P_OUT,
  P_GX,
  P_GY,
  P_SOL1,
  P_ZERO, /* reals */
  P_FIRST,
  P_COUNT,
  P_START,
  P_FLAG, /* uints */
  P_NB_GX,
  P_NB_GY,
  P_NB_GU,
  P_NB_GV, /* N-body precision */
  P_COUNT_
};

struct px_vortex_ocl {
  struct px_backend *be;  /* borrowed */
  enum px_precision real; /* storage precision on the device */
  size_t rs, nbs;         /* bytes of a real and of an N-body real */
  cl_program prog;
  struct px_buffer *w[W_COUNT_];
  size_t cap; /* vortices the wake buffers hold */
  struct px_buffer *p[P_COUNT_];
  int host_dirty; /* the host wake changed: upload before the next step */
  /* the step in progress, between its blocks: vortices on the device, the
   * first newborn among them, newborns */
  size_t nw, nold, nborn;
};

/* Host doubles <-> device reals. */
enum px_status px_vortex_ocl_put_reals(struct px_vortex_engine *e, struct px_buffer *b,
                                       const double *src, size_t n);
enum px_status px_vortex_ocl_get_reals(struct px_vortex_engine *e, struct px_buffer *b, double *dst,
                                       size_t n);
/* Wake buffers for at least n vortices (contents of the A set kept). */
enum px_status px_vortex_ocl_reserve(struct px_vortex_engine *e, size_t n);
/* The engine's create and destroy (vortex_engine.h): device buffers,
 * program, panels and the inverse generation matrix. */
void px_vortex_ocl_destroy(struct px_vortex_engine *e);
enum px_status px_vortex_ocl_create(struct px_vortex_engine *e);
/* Upload the host wake (after px_vortex_engine_add or a checkpoint load). */
enum px_status px_vortex_ocl_upload(struct px_vortex_engine *e);
/* Collective over the run's ranks (K > 1; vortex_ranks.h): the ranks agree
 * on st (a failure anywhere fails all); then the wake buffers which[0..narr)
 * (reals), each rank having computed its share px_vortex_ranks_share of
 * their first n values, get every rank's share: read back, gathered as the
 * device's bytes, written back whole. One rank: st. */
enum px_status px_vortex_ocl_gather(struct px_vortex_engine *e, int sum, enum px_status st,
                                    size_t n, const int *which, size_t narr);
/* The engine's host_changed and sync (vortex_engine.h). */
void px_vortex_ocl_host_changed(struct px_vortex_engine *e);
enum px_status px_vortex_ocl_sync(struct px_vortex_engine *e);

#endif
