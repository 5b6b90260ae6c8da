/* VTK XML output that ParaView opens directly: PolyData (.vtp: particles,
 * body contours, boundaries), ImageData (.vti: lattices, sampled fields) and
 * UnstructuredGrid (.vtu: cells of any VTK type), all with binary appended
 * data (format="appended", encoding="raw", header_type="UInt64", the byte
 * order of this machine), plus .pvd collections for time series.
 *
 * A `struct px_vtk` is a builder: set the geometry and topology, add data
 * arrays, then px_vtk_write. Bulk arrays (points, data arrays, explicit cells)
 * are BORROWED: they must stay valid and unchanged until px_vtk_write returns;
 * nothing is copied, and structure-of-arrays input is interleaved on the fly
 * while writing (in chunks, with fwrite). Names and small topology built with
 * the add_* functions are copied. Files are written atomically (file.h). */
#ifndef PARTIX_VTK_H
#define PARTIX_VTK_H

#include <stddef.h>
#include <stdint.h>

#include "partix/context.h"
#include "partix/export.h"
#include "partix/types.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_vtk;
struct px_vtk_series;

/* Where a data array lives. */
enum px_vtk_assoc { PX_VTK_ASSOC_POINT = 0, PX_VTK_ASSOC_CELL = 1 };

/* VTK cell type numbers (vtkCellType.h); the values are VTK's. */
enum px_vtk_cell {
  PX_VTK_CELL_VERTEX = 1,
  PX_VTK_CELL_POLY_VERTEX = 2,
  PX_VTK_CELL_LINE = 3,
  PX_VTK_CELL_POLY_LINE = 4,
  PX_VTK_CELL_TRIANGLE = 5,
  PX_VTK_CELL_POLYGON = 7,
  PX_VTK_CELL_PIXEL = 8,
  PX_VTK_CELL_QUAD = 9,
  PX_VTK_CELL_TETRA = 10,
  PX_VTK_CELL_VOXEL = 11,
  PX_VTK_CELL_HEXAHEDRON = 12
};

PX_API enum px_status px_vtk_create(struct px_context *ctx, struct px_vtk **out);
/* NULL-safe. */
PX_API void px_vtk_free(struct px_vtk *v);
/* Forget everything set or added (keeps the allocations for the next frame). */
PX_API void px_vtk_reset(struct px_vtk *v);

/* ---- Geometry ---------------------------------------------------------- */

/* n points from separate coordinate arrays of `dtype` (F32 or F64), borrowed.
 * z == NULL writes z = 0 (2D data). */
PX_API enum px_status px_vtk_set_points(struct px_vtk *v, enum px_dtype dtype, size_t n,
                                        const void *x, const void *y, const void *z);
/* n points from one interleaved array xyz (ncomp = 2: x,y pairs, z = 0; or 3). */
PX_API enum px_status px_vtk_set_points_aos(struct px_vtk *v, enum px_dtype dtype, size_t n,
                                            int ncomp, const void *xyz);
/* A regular grid (.vti): dims[k] points along axis k (dims[2] = 1 for 2D),
 * origin of point (0,0,0) and spacing, in world units. Point data has
 * dims[0]*dims[1]*dims[2] tuples, x fastest; cell data one per cell
 * (max(dims[k]-1, 1) along each axis). */
PX_API enum px_status px_vtk_set_image(struct px_vtk *v, const size_t dims[3],
                                       const double origin[3], const double spacing[3]);

/* ---- Topology ---------------------------------------------------------- */

/* One vertex cell per point (.vtp Verts; .vtu VTK_VERTEX cells): how
 * particles are shown as points. Generated while writing, no memory used. */
PX_API enum px_status px_vtk_add_vertices(struct px_vtk *v);
/* .vtp: a polyline through the point ids ids[0..count-1] (copied). closed
 * repeats ids[0] at the end. */
PX_API enum px_status px_vtk_add_polyline(struct px_vtk *v, size_t count, const int64_t *ids,
                                          int closed);
/* .vtp: a polyline through the consecutive points first .. first+count-1. */
PX_API enum px_status px_vtk_add_polyline_range(struct px_vtk *v, size_t first, size_t count,
                                                int closed);
/* .vtp: one 2-point line cell per segment between consecutive points
 * first .. first+count-1 (count-1 cells, or count when closed), so that cell
 * data can give a value per segment (e.g. impact energy along a contour). */
PX_API enum px_status px_vtk_add_segments(struct px_vtk *v, size_t first, size_t count, int closed);
/* .vtu: ncells cells, borrowed: offsets[i] is the END of cell i in
 * connectivity (VTK's convention: offsets[ncells-1] = connectivity length),
 * types[i] a px_vtk_cell value. */
PX_API enum px_status px_vtk_set_cells(struct px_vtk *v, size_t ncells, const int64_t *offsets,
                                       const int64_t *connectivity, const uint8_t *types);
/* .vtu: ncells cells all of one type with `nodes` points each (e.g.
 * hexahedra: 8); connectivity (ncells*nodes ids) borrowed. .vtp: the same
 * with triangles, quads or polygons: a surface (Polys, after the vertices
 * and lines in the cell order). */
PX_API enum px_status px_vtk_set_cells_uniform(struct px_vtk *v, size_t ncells,
                                               enum px_vtk_cell type, int nodes,
                                               const int64_t *connectivity);

/* ---- Data arrays ------------------------------------------------------- */
/* `n` is the number of tuples, checked at write against the number of points
 * or cells (.vtp cells are ordered vertices first, then lines, then polygons). dtype may be
 * any px_dtype. Names are copied; data is borrowed. A 2-component input is
 * written as a 3-component vector with third component 0, so that ParaView
 * treats it as a vector (glyphs, magnitude). */

/* Component k in comps[k] (structure of arrays), ncomp 1..9. */
PX_API enum px_status px_vtk_add_array(struct px_vtk *v, enum px_vtk_assoc assoc, const char *name,
                                       enum px_dtype dtype, size_t n, int ncomp,
                                       const void *const comps[]);
/* Interleaved: data[i*ncomp + k], ncomp 1..9. */
PX_API enum px_status px_vtk_add_array_aos(struct px_vtk *v, enum px_vtk_assoc assoc,
                                           const char *name, enum px_dtype dtype, size_t n,
                                           int ncomp, const void *data);
PX_API enum px_status px_vtk_add_scalar(struct px_vtk *v, enum px_vtk_assoc assoc, const char *name,
                                        enum px_dtype dtype, size_t n, const void *data);
/* A 3-component vector from separate arrays; z == NULL writes 0. */
PX_API enum px_status px_vtk_add_vector(struct px_vtk *v, enum px_vtk_assoc assoc, const char *name,
                                        enum px_dtype dtype, size_t n, const void *x, const void *y,
                                        const void *z);

/* Field data: TimeValue (Float64, what ParaView shows as the time) and Step
 * (Int64). */
PX_API void px_vtk_set_time(struct px_vtk *v, double time, int64_t step);
/* Any other named scalar in the field data (e.g. a force coefficient). */
PX_API enum px_status px_vtk_add_field(struct px_vtk *v, const char *name, double value);

/* Write the file; the extension picks the kind: .vtp PolyData (points
 * required), .vti ImageData (px_vtk_set_image required), .vtu
 * UnstructuredGrid (points and cells or vertices required). */
PX_API enum px_status px_vtk_write(struct px_vtk *v, const char *path);

/* ---- .pvd series ------------------------------------------------------- */
/* A collection of (time, file) entries that ParaView opens as one time
 * series. The .pvd is rewritten atomically after every add, so it is valid at
 * every moment of a run. File names are stored as given (normally relative
 * to the directory of the .pvd). */

/* Start a new series (an existing file is replaced by an empty collection). */
PX_API enum px_status px_vtk_series_open(struct px_context *ctx, const char *path,
                                         struct px_vtk_series **out);
/* Continue a resumed run: keep the entries of an existing `path` with time
 * <= t_resume, drop the rest (rewriting the file), add after them. The files
 * of dropped entries that are plain names next to the .pvd are deleted (they
 * belong to the abandoned continuation); other names are left alone. A
 * missing file starts an empty series; an unreadable one is
 * PX_STATUS_FORMAT. */
PX_API enum px_status px_vtk_series_open_resume(struct px_context *ctx, const char *path,
                                                double t_resume, struct px_vtk_series **out);
PX_API enum px_status px_vtk_series_add(struct px_vtk_series *s, double time, const char *file);
/* Several datasets at one time (e.g. particles + body) as parts 0, 1, ... */
PX_API enum px_status px_vtk_series_add_part(struct px_vtk_series *s, double time, int part,
                                             const char *file);
PX_API size_t px_vtk_series_count(const struct px_vtk_series *s);
/* Time and file of entry i (NULL/NaN when out of range). */
PX_API double px_vtk_series_time(const struct px_vtk_series *s, size_t i);
PX_API const char *px_vtk_series_file(const struct px_vtk_series *s, size_t i);
/* Free (the file on disk is already complete). NULL-safe. */
PX_API void px_vtk_series_close(struct px_vtk_series *s);

#ifdef __cplusplus
}
#endif
#endif
