/* The lattice over several ranks: the decomposition's state, shared by
 * lattice_ranks.c (the plan and the halo callbacks) and lattice_gather.c
 * (the whole state onto rank 0 and back to the windows). Internal. */
#ifndef PX_LATTICE_RANKS_IMPL_H
#define PX_LATTICE_RANKS_IMPL_H

#include "core/comm.h"
#include "solvers/lattice/lattice.h"

struct px_lattice_ranks {
  struct px_lattice *L; /* borrowed */
  struct px_comm *comm; /* borrowed */
  int rank, size;
  int py, pz;    /* the rank grid (y x z); py = 1: blocks of rows (z) */
  long *z;       /* size + 1 row boundaries: rank r holds the rows [z[r], z[r + 1]) */
  long *jc, *kc; /* py > 1: py + 1 y and pz + 1 z boundaries */
  char *pack;    /* py > 1: 8 faces (4 sent, 4 received) of face bytes */
  size_t face;   /* bytes of a face's room: 13 components of its longer one */
  void *hbuf;    /* the state buffer of the exchange in flight */
  size_t hreal, hns;
  int hvol;       /* the exchange in flight: the volumetric coefficients */
  char *vpack;    /* nu != 0: 8 faces (4 sent, 4 received) of vface bytes */
  size_t vface;   /* bytes of a face's room for the coefficients */
  size_t plane;   /* entries of a plane of the padded layout: n0p n[1] */
  int planes;     /* blocks of whole planes (link-once) */
  size_t *counts; /* size entries (allgather counts) */
  double *rows;   /* 3 n[1] n[2] doubles: the rows' allgather */
  double *send;   /* 3 n[1] n[2] doubles: this rank's rows */
  double *all;    /* 3 n[1] n[2] doubles: every row's sums, in row order */
  /* this rank's window (L->wm): the cells with y in [box[0], box[1]) and z
   * in [box[2], box[3]), its rows j + n1w k (j, k from the window's
   * corner); lr0, lr1: the block's rows there (row blocks) */
  long box[4], n1w, lr0, lr1;
};

/* The window's row of the grid's row j + n[1] k. */
static inline long px_lattice_ranks_loc(const struct px_lattice_ranks *R, long j, long k) {
  return j - R->box[0] + R->n1w * (k - R->box[2]);
}

/* Rank q's rows (global numbering: row j + n[1] k) as segments [*a, *b)
 * of consecutive rows: returns their number, fills segment s (< the
 * number). */
long px_lattice_ranks_seg(const struct px_lattice_ranks *R, int q, long s, long *a, long *b);
/* This rank's segment [a, b) (global rows) as rows [*la, *lb) of its
 * window. */
void px_lattice_ranks_lseg(const struct px_lattice_ranks *R, long a, long b, long *la, long *lb);

#endif
