/* What the files of the granular system (system*.c) share and nothing else
 * sees: the table of per-particle arrays and small storage helpers. */
#ifndef PX_GRAN_SYSTEM_IMPL_H
#define PX_GRAN_SYSTEM_IMPL_H

#include "solvers/granular/system.h"

#define PX_GRAN_PI 3.14159265358979323846
/* Events one thread can buffer within one step. */
#define PX_GRAN_EV_CAP_MIN 4096
/* Most per-particle arrays of a system (px_gran_arrays). */
#define PX_GRAN_MAX_ARRAYS 72

/* A per-particle array: pointer, element size, elements per particle, and
 * whether it carries state across a rebuild (permuted) or is scratch. The
 * one place where the arrays of reals are seen as untyped bytes: p points
 * at the raw member `.p` of their union px_gran_reals (or at an int array's
 * pointer), for allocation, permutation and checkpoints. */
struct px_gran_arr {
  void **p;
  size_t esize, per;
  int keep;         /* carried across a rebuild (permuted) */
  const char *name; /* checkpoint section, NULL: not saved (scratch) */
};

/* The per-particle arrays of s into a[PX_GRAN_MAX_ARRAYS]; their count. */
size_t px_gran_arrays(struct px_gran_sys *s, struct px_gran_arr *a);
/* *p grown to hold `bytes` (kept when it does). */
enum px_status px_gran_ensure(struct px_gran_sys *s, void **p, size_t bytes, const char *label);
/* dst[di] = sign * src[si], reals of cs bytes. */
void px_gran_copy_real(union px_gran_reals dst, size_t di, union px_gran_reals src, size_t si,
                       size_t cs, double sign);
/* Free the per-segment statistics. */
void px_gran_stats_free(struct px_gran_sys *s);
/* Element i of a real array of es bytes, as double (the raw pointer of
 * the array table, px_gran_arr). */
double px_gran_rd(const void *p, size_t i, size_t es);
/* The work split of the threads over the pairs and the near-wall
 * particles (after a rebuild or a load). */
enum px_status px_gran_sys_split_pairs(struct px_gran_sys *s);
void px_gran_sys_split_near(struct px_gran_sys *s);
/* The largest distance a wall point moved since the last rebuild [m]. */
double px_gran_wall_drift(const struct px_gran_sys *s);

#endif
