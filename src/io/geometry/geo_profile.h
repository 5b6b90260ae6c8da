/* Solver-neutral geometry, part 5: closed contours read from text files
 * into polylines (geo_polyline.h) whose vertices carry their file lines:
 * Selig .dat airfoils and plain lists of points, and the re-panelling of a
 * Selig airfoil by a cubic spline. Internal; not installed.
 *
 * Profile files come from elsewhere and are not trusted (docs/running.md,
 * "What partix trusts"): a file is read only if it is a regular file (not a
 * device, a pipe or a directory) of at most PX_GEO_PROFILE_MAX_BYTES bytes,
 * with lines of at most PX_GEO_PROFILE_MAX_LINE bytes, at most the caller's
 * max_points points and coordinates of magnitude at most
 * PX_GEO_PROFILE_MAX_COORD (the profile's own units: a solver scales and
 * places it). Coordinates within +-1e9 keep every product of two (areas,
 * crossings) finite. A file beyond a limit, or not of the format, is
 * refused (PX_STATUS_CONFIG, or PX_STATUS_IO when it cannot be read) with
 * FILE:LINE and the limit. */
#ifndef PX_IO_GEO_PROFILE_H
#define PX_IO_GEO_PROFILE_H

#include <stddef.h>

#include "io/geometry/geo_polyline.h"

#define PX_GEO_PROFILE_MAX_BYTES (16L * 1024 * 1024)
#define PX_GEO_PROFILE_MAX_LINE 1024
#define PX_GEO_PROFILE_MAX_COORD 1e9

enum px_geo_spacing {
  PX_GEO_SPACING_UNIFORM = 0, /* equal steps of the spline's arc-length parameter */
  PX_GEO_SPACING_COSINE = 1   /* clustered at leading and trailing edges */
};

/* Selig .dat airfoil: a title line, then "x y" from the trailing edge over
 * the upper surface to the leading edge and back along the lower surface.
 * Refused: a Lednicer-format file (point counts first), fewer than 5 points,
 * no extent in x, a gap between the last and the first point of more than
 * 2% of the chord. *out gets the points as a closed polygon (a repeated
 * first point dropped), counter-clockwise (a clockwise file is reversed
 * whole: the points, repeat dropped, in reverse order), with their
 * lines, source = path; *open_te = 1 when the trailing edge is open (a gap
 * of at most 2% of the chord, closed by the polygon's last edge). */
enum px_status px_geo_profile_read_selig(struct px_context *ctx, const char *path, int max_points,
                                         struct px_geo_polyline *out, int *open_te);
/* Plain list of "x y" lines ('#' comments allowed), explicitly closed (the
 * last point repeats the first, within 1e-9 of the contour's size): *out
 * gets the points without the repeated one, as listed, with their lines,
 * source = path. */
enum px_status px_geo_profile_read_points(struct px_context *ctx, const char *path, int max_points,
                                          struct px_geo_polyline *out);
/* A Selig airfoil (np points x, y as px_geo_profile_read_selig gives them,
 * the caller having checked that no edge is zero-length or crosses
 * another) re-panelled to n >= 4 panels: a natural cubic spline in chord
 * length through the points (closing at the trailing edge), split at the
 * leading edge (minimum x of the spline) into n / 2 panels over the upper
 * surface and the rest over the lower, with the given spacing; an open
 * trailing edge keeps one straight panel. path names the airfoil in
 * messages and is *out's source. */
enum px_status px_geo_profile_repanel_selig(struct px_context *ctx, const char *path,
                                            const double *x, const double *y, size_t np,
                                            int open_te, size_t n, enum px_geo_spacing spacing,
                                            struct px_geo_polyline *out);

#endif
