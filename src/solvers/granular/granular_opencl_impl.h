/* The granular opencl engine's state, shared by its kernel side
 * (granular_opencl.c, built with OpenCL only) and its state side
 * (granular_opencl_state.c: buffers, transfers, checkpoints). */
#ifndef PX_GRAN_OPENCL_IMPL_H
#define PX_GRAN_OPENCL_IMPL_H

#include <stddef.h>
#include <stdint.h>

#include "partix/backend.h"
#include "partix/checkpoint.h"
#include "solvers/granular/system.h"

struct px_gran_cl_kernels;
struct px_gran_cl_plan;
struct px_comm;

#define PX_GRAN_CL_NMAX 16
#define PX_GRAN_CL_WCMAX 24
#define PX_GRAN_CL_DRAIN 64

enum {
  B_X,
  B_Y,
  B_VX,
  B_VY,
  B_W,
  B_AX,
  B_AY,
  B_AW,
  B_XR,
  B_YR, /* state precision */
  B_R,
  B_M,
  B_IM,
  B_II, /* contact precision */
  B_ID,
  B_NCOUNT,
  B_NBR,
  B_HXI,
  B_HTH,
  B_HDM,
  B_HDP, /* lists */
  B_ONCOUNT,
  B_ONBR,
  B_OXI,
  B_OTH,
  B_ODM,
  B_ODP, /* previous lists */
  B_SAX,
  B_SAY,
  B_STX,
  B_STY,
  B_SLEN,
  B_STPX,
  B_STPY,
  B_SFLAGS,
  B_SCONTOUR,
  B_CFIRST,
  B_CCOUNT,
  B_FRAMES,
  B_CBOX,
  B_CBIN,
  B_BINSTART,
  B_BINSEG, /* walls */
  B_WCOUNT,
  B_WCAND,
  B_SSEG,
  B_SSEG0,
  B_SSTEP0,
  B_ST0,
  B_STE,
  B_SXI,
  B_STH,
  B_SDM,
  B_SDP,
  B_SIMP,
  B_SSLW,
  B_SARC,
  B_STIM, /* wall slots */
  B_EVI,
  B_EVR,
  B_EVN,
  B_WFORCE,
  B_LAWP,
  B_LAWW,
  B_MAXD,
  B_OVF,
  B_ESC, /* one uint each: largest displacement (float bits), overflow, escape */
  B_VXN,
  B_VYN,
  B_WN,   /* the kicked velocities gran_forces writes (swapped with B_VX.. after
            it: every work-item reads its neighbours' velocities of the
            step's start, never one another work-item has already kicked) */
  B_OWN,  /* the discs this rank steps (uint ids; 0..n-1 on one rank) */
  B_GIDX, /* over ranks: the ghost rows sent, then those received (uint ids) */
  B_GBUF, /* over ranks: those rows packed (5 state reals each) */
  B_COUNT
};

struct px_gran_cl {
  struct px_backend *be;             /* borrowed */
  struct px_context *ctx;            /* borrowed */
  struct px_gran_sys *h;             /* borrowed: the host mirror */
  struct px_buffer *b[B_COUNT];      /* owned */
  struct px_grid *grid;              /* owned */
  struct px_gran_cl_kernels *kern;   /* owned (granular_opencl.c: the program's
                                        kernels, cached by the backend) */
  size_t n, nseg, ncontours, ss, cs; /* sizes; ss/cs: bytes of a state/contact real */
  size_t ev_cap;
  int need_rebuild;
  long step;
  long synced_step; /* step the mirror was last refreshed at */
  double t;
  int grid_nx, grid_ny;
  enum px_precision prec; /* of the state (grid build) */
  int *ev_i;              /* host copies of drained events (owned) */
  void *ev_r;
  /* over K > 1 MPI ranks (granular_ranks_opencl.c) */
  struct px_comm *comm;         /* borrowed: the run's ranks */
  int nrank, rank;              /* K and this rank */
  size_t nown;                  /* discs this rank steps (B_OWN) */
  struct px_gran_cl_plan *plan; /* owned: ownership and ghost lists (NULL: one rank) */
  int plan_ok;                  /* the plan matches the device's lists */
};

/* Free the engine (buffers, grid, event copies, kernel handles). */
void px_gran_cl_free(struct px_gran_cl *e);
/* The mirror's particles and wall slots onto the device, in id order
 * (device index = id). */
enum px_status px_gran_cl_upload_state(struct px_gran_cl *e);
/* The contour frames of the mirror onto the device. */
enum px_status px_gran_cl_write_frames(struct px_gran_cl *e);
/* At create: the device buffers and laws; the walls (segments, bins,
 * contour boxes); the neighbour grid over where particles can be. */
enum px_status px_gran_cl_buffers(struct px_gran_cl *e);
enum px_status px_gran_cl_walls(struct px_gran_cl *e);
enum px_status px_gran_cl_grid(struct px_gran_cl *e);
/* Exchange buffers a and b (B_*). */
void px_gran_cl_swap(struct px_gran_cl *e, int a, int b);
/* Move the device's wall events into the mirror's statistics. */
enum px_status px_gran_cl_drain(struct px_gran_cl *e);
/* The state, wall slots and statistics into the mirror, whose lists and
 * wall reactions are rebuilt for the outputs. */
enum px_status px_gran_cl_download(struct px_gran_cl *e);
/* The device lists and histories in checkpoints, by particle id (loaded
 * sections checked before they reach the device). */
enum px_status px_gran_cl_save(struct px_gran_cl *e, struct px_checkpoint_writer *w);
enum px_status px_gran_cl_load(struct px_gran_cl *e, struct px_checkpoint *ck);
/* Contacts (pairs of ids i < j with overlap > 0) through the device's
 * lists, sorted; *pairs owned by the caller. */
enum px_status px_gran_cl_contacts(struct px_gran_cl *e, int32_t **pairs, size_t *np);
/* Replace the device state by the mirror's (lists rebuilt at the next
 * step). */
enum px_status px_gran_cl_upload(struct px_gran_cl *e);
/* Read a device array of reals (es bytes each) as doubles. */
enum px_status px_gran_cl_get(struct px_gran_cl *e, int k, double *v, size_t n, size_t es);
/* Sort `take` wall events (ev_i, ev_r: the device's record layout) into a
 * fixed order and sum them into the mirror's statistics. */
enum px_status px_gran_cl_feed(struct px_gran_cl *e, int *ev_i, void *ev_r, size_t take);

/* Over K > 1 ranks (granular_ranks_opencl.c; collective unless said). Each
 * rank steps the discs it owns (B_OWN), a strip of the container recut at
 * every rebuild: */
/* the ownership and ghost lists from the device's positions and lists
 * (every row of them current on every rank: after a create, a load, an
 * upload or a rebuild) */
enum px_status px_gran_cl_ranks_plan(struct px_gran_cl *e);
/* the ghost rows of this step's drifted state from their owners */
enum px_status px_gran_cl_ranks_ghosts(struct px_gran_cl *e);
/* the owners' rows of the state a step changes onto every rank's device
 * (root < 0) or rank root's only */
enum px_status px_gran_cl_ranks_state(struct px_gran_cl *e, int root);
/* every rank's wall events into every rank's mirror statistics, in the
 * order one rank sums them */
enum px_status px_gran_cl_ranks_drain(struct px_gran_cl *e);
/* the largest displacement of all ranks' discs (float bits, exact) */
enum px_status px_gran_cl_ranks_maxdisp(struct px_gran_cl *e, uint32_t *md);
/* The ghost rows idx[first..end) of B_GIDX: packed from the state into
 * B_GBUF, or (unpack) from it into the state (granular_opencl.c). */
enum px_status px_gran_cl_pack(struct px_gran_cl *e, int unpack, size_t first, size_t end);
/* not collective: the plan's memory */
void px_gran_cl_ranks_free(struct px_gran_cl *e);

#endif
