/* The host state's private side (vortex_core.c), private to the vortex
 * solver: its setup and teardown for the driver (vortex_engine.c), and the
 * helpers the host engines' blocks share (work arrays, per-thread neighbour
 * lists, the buffers of the pair sums; vortex_cpu.c, vortex_diffusive.c,
 * vortex_ref.c). Engines and the driver include it; it includes no engine. */
#ifndef PX_VORTEX_CORE_IMPL_H
#define PX_VORTEX_CORE_IMPL_H

#include "solvers/vortex/vortex_core.h"

#define VX_PI 3.14159265358979323846

/* Shared setup and teardown of the host state, without an engine's own: the
 * driver's px_vortex_engine_create/free wrap them. fmm: the engine has the
 * fast multipole method (px_vortex_caps.fmm), so that the sums' evaluator
 * takes cfg->method and cfg->tolerance (float sums turn double below a
 * tolerance of 1e-5). */
enum px_status px_vortex_core_create(struct px_context *ctx, struct px_backend *be,
                                     const struct px_vortex_config *cfg, int fmm,
                                     const struct px_vortex_contour *bodies, size_t nbody,
                                     struct px_vortex_engine **out);
void px_vortex_core_free(struct px_vortex_engine *e);
/* Convective velocity of the wake alone at n points (no free stream, no
 * sync: the driver's px_vortex_engine_velocity adds both). */
enum px_status px_vortex_core_velocity(struct px_vortex_engine *e, size_t n, const double *x,
                                       const double *y, double *u, double *v);

/* Work arrays (single-precision right-hand side, moved positions, crossed
 * panels, merge partners and flags) for a wake of n vortices. */
enum px_status px_vortex_ensure_work(struct px_vortex_engine *e, size_t n);
/* Points of tree t within r of (x, y) into the calling thread's list (its
 * count into *cnt; NULL when out of memory). */
uint32_t *px_vortex_nbuf_query(struct px_vortex_engine *e, const struct px_vortex_tree *t, double x,
                               double y, double r, size_t *cnt);
/* One query of tree t for a group of points near each other: the points of
 * t within r of (cx, cy) become the calling thread's candidates (their
 * sorted positions and coordinates); returns their count, (size_t)-1 when
 * out of memory. A point (x, y) of the group with radius r_i, where
 * r >= r_i + |(x, y) - (cx, cy)| (with a margin for rounding), then takes
 * its list from them with px_vortex_nbuf_pick: the list px_vortex_nbuf_query
 * would give it, in the same order (a point within r_i lies in a leaf
 * within r_i, and the candidates keep the tree's order), at the cost of a
 * vector filter instead of a tree walk. */
size_t px_vortex_nbuf_group(struct px_vortex_engine *e, const struct px_vortex_tree *t, double cx,
                            double cy, double r);
/* The ng candidates of the last px_vortex_nbuf_group within r of (x, y)
 * (their sorted positions, or what the caller made of them in the thread's
 * b->gp, e.g. panel numbers; count into *cnt), in the thread's b->fp. */
uint32_t *px_vortex_nbuf_pick(struct px_vortex_engine *e, size_t ng, double x, double y, double r,
                              size_t *cnt);
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
