/* Solver-neutral geometry, part 4: built-in closed shapes as polylines
 * (geo_polyline.h) of n vertices, counter-clockwise, centred on the origin
 * (NACA: leading edge at the origin, chord 1 along +x). Each checks its own
 * parameters (PX_STATUS_CONFIG, the message starts with the shape's name);
 * how many vertices a solver wants is the solver's to check, these only
 * need PX_GEO_SHAPE_MIN_VERTICES. Internal; not installed. */
#ifndef PX_IO_GEO_SHAPE_H
#define PX_IO_GEO_SHAPE_H

#include <stddef.h>

#include "io/geometry/geo_polyline.h"

/* Fewest vertices of a shape (a triangle). */
#define PX_GEO_SHAPE_MIN_VERTICES 3

/* Circle of the given radius; vertex k at angle 2 pi k / n. */
enum px_status px_geo_shape_circle(struct px_context *ctx, double radius, size_t n,
                                   struct px_geo_polyline *out);
/* Semi-axes a (along x) and b (along y); vertices equally spaced in arc
 * length (of a polygon of 64 n points), the first at (a, 0). */
enum px_status px_geo_shape_ellipse(struct px_context *ctx, double a, double b, size_t n,
                                    struct px_geo_polyline *out);
/* Flat plate of overall length `length` (ends included) and thickness
 * `thickness`, with semicircular ends (a stadium); vertices equally spaced
 * in arc length from (length / 2, 0). */
enum px_status px_geo_shape_plate(struct px_context *ctx, double length, double thickness, size_t n,
                                  struct px_geo_polyline *out);
/* PX_STATUS_CONFIG unless digits are four decimal digits ("0012"). */
enum px_status px_geo_shape_naca4_digits(struct px_context *ctx, const char *digits);
/* NACA 4-digit "MPTT" with the closed trailing edge (coefficient -0.1036);
 * n even; cosine spacing in x; from the trailing edge over the upper surface
 * to the leading edge (vertex n / 2) and back along the lower surface. */
enum px_status px_geo_shape_naca4(struct px_context *ctx, const char *digits, size_t n,
                                  struct px_geo_polyline *out);

#endif
