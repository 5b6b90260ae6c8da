/* The cpu engine's shared host helpers (vortex_core.c), for its blocks in
 * vortex_cpu.c and vortex_diffusive.c; private to the vortex solver. */
#ifndef PX_VORTEX_CPU_IMPL_H
#define PX_VORTEX_CPU_IMPL_H

#include "solvers/vortex/vortex_core.h"

#define VX_PI 3.14159265358979323846

/* Work arrays (single-precision right-hand side, moved positions, crossed
 * panels, merge partners and flags) for a wake of n vortices. */
enum px_status px_vortex_ensure_work(struct px_vortex_engine *e, size_t n);
/* Points of tree t within r of (x, y) into the calling thread's list (its
 * count into *cnt; NULL when out of memory). */
uint32_t *px_vortex_nbuf_query(struct px_vortex_engine *e, const struct px_vortex_tree *t, double x,
                               double y, double r, size_t *cnt);
/* Grow a work list to hold n entries (contents kept); 0 when out of memory. */
int px_vortex_list_reserve(struct px_vortex_engine *e, uint32_t **p, size_t *cap, size_t n);
/* Grow *p, `arrays` arrays of *cap doubles each back to back (the leaf boxes,
 * the packed neighbours), to hold n entries per array (contents not kept); 0
 * when out of memory. */
int px_vortex_arrays_reserve(struct px_vortex_engine *e, double **p, size_t *cap, size_t n,
                             size_t arrays);
/* Leaves of tree t within r of (x, y), into *buf (grown). (size_t)-1 when out
 * of memory. */
size_t px_vortex_leaves_into(struct px_vortex_engine *e, const struct px_vortex_tree *t, double x,
                             double y, double r, uint32_t **buf, size_t *cap);
/* n results of the pair sums, in their precision, into host doubles. */
enum px_status px_vortex_nb_get(struct px_vortex_engine *e, struct px_buffer *b, double *dst,
                                size_t n);
/* Upload the wake as the sources of the pair sums. */
enum px_status px_vortex_nb_sources(struct px_vortex_engine *e);
/* Velocities (pair sum only) at nt extra targets from the uploaded wake. */
enum px_status px_vortex_nb_targets(struct px_vortex_engine *e, size_t nt, const double *tx,
                                    const double *ty, double *u, double *v);

#endif
