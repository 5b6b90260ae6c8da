/* Solver-neutral geometry, part 2: DXF drawings (ASCII, any version) read
 * into closed paths of primitives (geo_path.h). Internal; not installed.
 *
 * Errors are PX_STATUS_FORMAT (the text is not a DXF file the reader
 * understands), PX_STATUS_CONFIG (a drawing beyond a limit, an open contour,
 * nothing to read on the layer) or PX_STATUS_IO, with a message that names
 * the file and, for an entity, its line ("part.dxf:12: ..."). */
#ifndef PX_IO_GEO_DXF_H
#define PX_IO_GEO_DXF_H

#include <stddef.h>

#include "io/geometry/geo_path.h"
#include "partix/context.h"

/* Entities (LINE, ARC, ...) a drawing may use: each becomes at least one
 * segment of a boundary; a solver that takes fewer segments says so
 * (granular: PX_GRAN_SEG_MAX, the same number). */
#define PX_GEO_DXF_PIECES_MAX 1000000

/* Read a DXF file and chain its LINE, ARC, CIRCLE, ELLIPSE, LWPOLYLINE
 * (with bulges), POLYLINE/VERTEX and SPLINE entities in model space into
 * closed paths (reversing pieces as needed; endpoints match within tol, in
 * mapped units). layer == NULL or "" takes every layer. Coordinates are
 * mapped as x' = scale * x + dx (same for y). On success *paths holds
 * *npaths paths, each with `where` = "FILE:LINE" of its first entity (owned
 * by the caller: px_geo_path_free each, then px_mem_free the array); on
 * failure *paths is NULL and *npaths 0. */
enum px_status px_geo_dxf_read(struct px_context *ctx, const char *file, const char *layer,
                               double scale, double dx, double dy, double tol,
                               struct px_geo_path **paths, size_t *npaths);
/* Same from size bytes of text in memory (need not end in NUL; name used in
 * messages). */
enum px_status px_geo_dxf_parse(struct px_context *ctx, const char *name, const char *text,
                                size_t size, const char *layer, double scale, double dx, double dy,
                                double tol, struct px_geo_path **paths, size_t *npaths);

#endif
