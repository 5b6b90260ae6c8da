/* Neighbour search on a uniform grid (2D or 3D): the cell of every particle,
 * a stable counting sort into cell order (a permutation) and the start/end
 * of every cell in that order, built on the particles' backend. The result
 * is deterministic and identical on every backend and thread count: it is
 * exactly the stable counting sort by cell (ties in particle-index order).
 *
 * Cell of a point: c_a = clamp(floor((x_a − origin_a) · (1/h)), 0, n_a − 1)
 * per axis a, flattened with x fastest: c = (c_z · n_y + c_y) · n_x + c_x.
 * Points outside the grid (and NaN) are clamped into the edge cells rather
 * than dropped: clamping keeps every pair closer than h in adjacent cells
 * (it moves both points of a pair monotonically), so no pair is lost and
 * no index leaves the arrays; whether particles may leave the domain is the
 * solver's decision, checked by the solver with a diagnosis.
 *
 * Interaction range: two points closer than `range` lie in the same or
 * adjacent cells if range <= h minus rounding; in single precision keep
 * h >= range · (1 + 1e-5) (a relative margin of a few float ulps of the
 * largest cell coordinate), in double h >= range · (1 + 1e-12). */
#ifndef PARTIX_NEIGHBORS_H
#define PARTIX_NEIGHBORS_H

#include <stddef.h>
#include <stdint.h>

#include "partix/backend.h"
#include "partix/context.h"
#include "partix/export.h"
#include "partix/types.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_grid;

/* A grid of cells[0] x cells[1] (x cells[2]) cubic cells of edge cell_size
 * (> 0, >= the interaction range) whose lower corner is origin[0..dims).
 * dims is 2 or 3; every cell count >= 1 and their product < 2^31. */
PX_API enum px_status px_grid_create(struct px_backend *be, int dims, const double *origin,
                                     double cell_size, const size_t *cells, struct px_grid **out);
/* NULL-safe. */
PX_API void px_grid_free(struct px_grid *g);
/* Give g a new origin, cell size and cell counts (same dims, same rules as
 * px_grid_create), keeping its buffers and the backend's scratch: for a
 * grid that follows the particles' bounding box from build to build. The
 * grid then holds no particles (as after px_grid_create) until the next
 * build. When the arguments are refused or memory runs out, the grid keeps
 * its previous shape and particles. */
PX_API enum px_status px_grid_reshape(struct px_grid *g, const double *origin, double cell_size,
                                      const size_t *cells);

PX_API int px_grid_dims(const struct px_grid *g);
PX_API double px_grid_cell_size(const struct px_grid *g);
/* Total number of cells. */
PX_API size_t px_grid_cell_count(const struct px_grid *g);
/* Number of particles of the last build (0 before the first). */
PX_API size_t px_grid_particle_count(const struct px_grid *g);

/* Bin n particles (n < 2^31; 0 is allowed) whose coordinates are the first
 * n elements of x, y (and z in 3D; NULL in 2D), of the precision's element
 * type (single: f32, double: f64). */
PX_API enum px_status px_grid_build(struct px_grid *g, enum px_precision precision, size_t n,
                                    struct px_buffer *x, struct px_buffer *y, struct px_buffer *z);

/* Results of the last build: u32 buffers owned by the grid, valid until the
 * next build or px_grid_free (their px_buffer_bytes may exceed what is used).
 *   cells[i]        cell of particle i (i < n, particle order)
 *   permutation[k]  particle at position k of the cell order (k < n)
 *   cell_start[c], cell_end[c]  the particles of cell c are
 *                   permutation[cell_start[c] .. cell_end[c]); empty cells
 *                   have start == end (the position where they would be). */
PX_API struct px_buffer *px_grid_cells(struct px_grid *g);
PX_API struct px_buffer *px_grid_permutation(struct px_grid *g);
PX_API struct px_buffer *px_grid_cell_start(struct px_grid *g);
PX_API struct px_buffer *px_grid_cell_end(struct px_grid *g);

/* Gather into cell order: dst[k] = src[permutation[k]] for k < n (n of the
 * last build), elements of `type`. Use it to reorder particle data
 * periodically for memory locality. src and dst must be different buffers. */
PX_API enum px_status px_grid_reorder(struct px_grid *g, enum px_dtype type, struct px_buffer *src,
                                      struct px_buffer *dst);

/* For every particle i of the last build: the number of particles j != i with
 * |r_i − r_j| < range, found through the 3x3 (3x3x3) cells around i's cell
 * (src/kernels/grid.h holds this loop as the pattern for solver kernels).
 * x, y (z) must be the positions of the last build; out receives n u32.
 * 0 < range <= cell_size. */
PX_API enum px_status px_grid_count_neighbours(struct px_grid *g, enum px_precision precision,
                                               struct px_buffer *x, struct px_buffer *y,
                                               struct px_buffer *z, double range,
                                               struct px_buffer *out);

/* Reference: all pairs (i, j), i < j, with |r_i − r_j| < range, by brute
 * force on the host in double precision (O(n^2)); z NULL in 2D. *pairs
 * receives 2·npairs indices (i0, j0, i1, j1, ...) sorted lexicographically,
 * allocated with px_mem_alloc(ctx) (free with px_mem_free). */
PX_API enum px_status px_neighbors_pairs_reference(struct px_context *ctx, int dims, size_t n,
                                                   const double *x, const double *y,
                                                   const double *z, double range, uint32_t **pairs,
                                                   size_t *npairs);

#ifdef __cplusplus
}
#endif
#endif
