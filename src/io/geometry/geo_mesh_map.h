/* Solver-neutral geometry, part 7: values known along the sections of a
 * mesh (geo_mesh.h: px_geo_mesh_slice), such as per-segment statistics of
 * 2D runs, interpolated onto the mesh's vertices. Internal; not installed.
 *
 * Method. A vertex p at height h = n . p between the planes of two
 * neighbouring sections k and k + 1 (offsets o_k <= h <= o_k+1) takes
 *   f(p) = (1 - t) f_k(p) + t f_k+1(p),   t = (h - o_k) / (o_k+1 - o_k),
 * where f_k(p) is section k's value at the point of its sample polylines
 * (each loop's samples joined in order, closed) nearest to p's projection
 * (p . u, p . v) on the plane, linear along that polyline between its two
 * samples. Below the first section and above the last, the nearest
 * section's value (t = 0). A linear field is reproduced exactly along the
 * normal; in the plane the error is that of the polyline through the
 * samples: zero on straight stretches, at most |grad f| times the distance
 * between the contour and the polyline (about the sample spacing times the
 * turning angle / 8 at a corner) elsewhere (test_geometry_map). */
#ifndef PX_IO_GEO_MESH_MAP_H
#define PX_IO_GEO_MESH_MAP_H

#include <stddef.h>

#include "io/geometry/geo_mesh.h"

/* One section's samples (borrowed arrays). */
struct px_geo_map_section {
  double offset;            /* the plane, n . p = offset */
  size_t n;                 /* samples */
  const double *x, *y;      /* plane coordinates (p . u, p . v) of the samples */
  size_t nloops;            /* closed loops: samples loop_start[i] to loop_start[i + 1] - 1 */
  const size_t *loop_start; /* nloops + 1 indices */
  const double *value;      /* n x nq values, sample-major */
};

/* out (nv x nq, vertex-major) gets every vertex's values by the method
 * above; sections in increasing offset, each with one sample at least
 * (PX_STATUS_INVALID otherwise). nearest (NULL or nv) gets the section
 * nearest each vertex along n. */
enum px_status px_geo_mesh_map(struct px_context *ctx, const struct px_geo_mesh *m,
                               const double u[3], const double v[3], const double n[3],
                               const struct px_geo_map_section *sec, size_t nsec, size_t nq,
                               double *out, int *nearest);

#endif
