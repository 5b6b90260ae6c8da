/* Solver-neutral geometry, part 3: closed polylines (contours of n vertices,
 * the last joined to the first) in double precision, as the built-in shapes
 * (geo_shape.h) and the profile readers (geo_profile.h) give them.
 * Internal; not installed.
 *
 * Ownership: x, y and line belong to the polyline; px_geo_polyline_free
 * releases them and leaves n = 0. A solver may take the arrays over (move
 * the pointers and zero the polyline): they come from px_mem_alloc of the
 * same context, so px_mem_free releases them wherever they end up. */
#ifndef PX_IO_GEO_POLYLINE_H
#define PX_IO_GEO_POLYLINE_H

#include <stddef.h>

#include "partix/context.h"

struct px_geo_polyline {
  size_t n;         /* number of vertices (= of edges: closed) */
  double *x;        /* owned: n abscissae */
  double *y;        /* owned: n ordinates */
  int *line;        /* owned or NULL: 1-based line of each vertex in the file it was read
                       from, for messages */
  char source[256]; /* "circle", "naca 0012" or the file path: names it in messages */
};

/* n vertices (x, y uninitialised; line zeroed when with_lines, else NULL);
 * source emptied. On failure the polyline is empty and the message says
 * "out of memory for a profile of N points". */
enum px_status px_geo_polyline_alloc(struct px_context *ctx, struct px_geo_polyline *p, size_t n,
                                     int with_lines);
/* NULL-safe. */
void px_geo_polyline_free(struct px_context *ctx, struct px_geo_polyline *p);
/* Signed area (shoelace formula): positive for counter-clockwise vertices. */
double px_geo_polyline_area(const struct px_geo_polyline *p);
/* Perimeter, closing edge included. */
double px_geo_polyline_perimeter(const struct px_geo_polyline *p);
/* n points (x, y) equally spaced in arc length along the closed polygon of
 * the m points px, py (m >= 1), starting at point 0. */
void px_geo_polyline_resample(size_t m, const double *px, const double *py, size_t n, double *x,
                              double *y);

#endif
