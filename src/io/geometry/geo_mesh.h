/* Solver-neutral geometry, part 6: closed triangle meshes (a 3D part's
 * surface) read from STL (ASCII and binary) and Wavefront OBJ files, welded,
 * checked closed and manifold, and cut by planes into closed 2D contours
 * (geo_mesh_slice.c). Internal; not installed.
 *
 * Mesh files come from elsewhere and are not trusted (docs/running.md,
 * "What partix trusts"): a file is read only if it is a regular file of at
 * most PX_GEO_MESH_MAX_BYTES bytes, with at most PX_GEO_MESH_MAX_TRIANGLES
 * triangles and coordinates of magnitude at most PX_GEO_MESH_MAX_COORD (file
 * units). A file that is not of its format is refused (PX_STATUS_FORMAT)
 * with FILE:LINE (text) or FILE: byte OFFSET (binary STL); one beyond a limit
 * with PX_STATUS_CONFIG; an unreadable one with PX_STATUS_IO.
 *
 * Ownership: every array of a mesh belongs to it (px_mem of the context
 * that read it); px_geo_mesh_free releases them and leaves an empty mesh. */
#ifndef PX_IO_GEO_MESH_H
#define PX_IO_GEO_MESH_H

#include <stddef.h>

#include "io/geometry/geo_polyline.h"
#include "partix/context.h"

#define PX_GEO_MESH_MAX_BYTES (512L * 1024 * 1024)
#define PX_GEO_MESH_MAX_TRIANGLES 10000000
#define PX_GEO_MESH_MAX_COORD 1e9
/* Offending edges a failed check lists (the message gives their count). */
#define PX_GEO_MESH_REPORT_MAX 5

struct px_geo_mesh {
  size_t nv;         /* welded vertices */
  size_t nt;         /* triangles */
  double *xyz;       /* owned: 3 nv coordinates [file units, or as scaled] */
  size_t *tri;       /* owned: 3 nt vertex indices, counter-clockwise seen from outside
                        once px_geo_mesh_check has passed */
  long *where;       /* owned: per triangle, its 1-based line (text) or the byte offset
                        of its record (binary STL), for messages */
  int binary;        /* where holds byte offsets */
  size_t ne;         /* edges (filled by px_geo_mesh_check) */
  size_t *edge;      /* owned: 3 nt, edge index of triangle t's side k (vertex k to k+1) */
  size_t *ev;        /* owned: 2 ne, the edge's vertices, lower index first */
  int flipped;       /* px_geo_mesh_check reversed every triangle (inward file) */
  size_t degenerate; /* triangles dropped by welding (two corners merged) */
  char source[256];  /* the file path: names the mesh in messages */
};

/* Reads an STL (".stl", binary when its size is 84 + 50 N bytes for the N
 * of its header, else ASCII) or OBJ (".obj") file by its extension (case
 * ignored), welds vertices closer than weld_tol (file units; 0: only equal
 * ones) and drops the triangles welding made degenerate. Does not check the
 * mesh: call px_geo_mesh_check. On failure *out is empty. */
enum px_status px_geo_mesh_read(struct px_context *ctx, const char *path, double weld_tol,
                                struct px_geo_mesh *out);
/* The same from size bytes in memory (need not end in NUL); name is used in
 * messages and as the source; obj selects OBJ, else STL. */
enum px_status px_geo_mesh_parse(struct px_context *ctx, const char *name, const char *data,
                                 size_t size, int obj, double weld_tol, struct px_geo_mesh *out);
/* NULL-safe; the mesh is empty afterwards. */
void px_geo_mesh_free(struct px_context *ctx, struct px_geo_mesh *m);

/* Closed and manifold: every edge shared by exactly two triangles that run
 * along it in opposite directions (consistent orientation). Otherwise
 * PX_STATUS_CONFIG, listing up to PX_GEO_MESH_REPORT_MAX offending edges
 * (their end points and the lines or offsets of their triangles) and how
 * many there are. On success fills the edge table and orients the triangles
 * outward (a mesh of negative volume is reversed whole, m->flipped = 1). */
enum px_status px_geo_mesh_check(struct px_context *ctx, struct px_geo_mesh *m);

/* Multiplies every coordinate by scale (units: 0.001 for millimetres). */
void px_geo_mesh_scale(struct px_geo_mesh *m, double scale);
/* Enclosed volume (divergence theorem; positive when oriented outward),
 * surface area, and bounding box lo[3], hi[3] (any may be NULL). */
void px_geo_mesh_measure(const struct px_geo_mesh *m, double *volume, double *area, double lo[3],
                         double hi[3]);

/* An orthonormal right-handed frame (u, v, n) for sections: n = normal
 * normalised; u = the hint projected on the plane and normalised (the
 * vibration direction seen in the section); v = n x u. PX_STATUS_INVALID
 * when the normal is zero or the hint (nearly) parallel to it. */
enum px_status px_geo_mesh_frame(struct px_context *ctx, const double normal[3],
                                 const double hint[3], double u[3], double v[3], double n[3]);

/* The section of a checked mesh by the plane n . p = offset (u, v, n from
 * px_geo_mesh_frame): closed contours in plane coordinates (x = p . u,
 * y = p . v), the part's outer boundaries counter-clockwise and its holes
 * clockwise. A vertex on the plane counts as on its positive side, so that
 * a plane through vertices, edges or faces gives the limit of the sections
 * just below it (offset - 0, on the side -n): a plane touching the part at a
 * point or an edge gives nothing, one through a face from outside nothing,
 * one through a face from inside the face's polygon. A plane that misses
 * the part gives no contour (PX_STATUS_OK, *n_out = 0). *out (owned by the
 * caller: px_geo_polyline_free each, px_mem_free the array) gets *n_out
 * polylines, their source "SOURCE section at OFFSET". */
enum px_status px_geo_mesh_slice(struct px_context *ctx, const struct px_geo_mesh *m,
                                 const double u[3], const double v[3], const double n[3],
                                 double offset, struct px_geo_polyline **out, size_t *n_out);

#endif
