/* Pictures of a closed triangle mesh (io/geometry/geo_mesh.h): three
 * orthographic views side by side, flat-shaded, plain grey or coloured by a
 * value per vertex with a colour bar, and 3D polylines (the sections) drawn
 * over the part. Internal; not installed. */
#ifndef PX_IO_MESH_VIEW_H
#define PX_IO_MESH_VIEW_H

#include <stddef.h>

#include "io/geometry/geo_mesh.h"
#include "partix/colormap.h"
#include "partix/context.h"

struct px_mesh_view {
  const struct px_geo_mesh *mesh; /* borrowed, checked (outward triangles) */
  const double *value;            /* borrowed: nv values, or NULL for a grey part */
  const char *label;              /* colour bar: "quantity [unit]" (with value) */
  enum px_colormap map;
  const char *title;             /* above the views, may be NULL */
  double dir[3][3];              /* each view's direction, from the eye into the scene */
  double up[3][3];               /* a direction that points up in each view */
  const char *view_name[3];      /* under each view, may be NULL */
  size_t npoly;                  /* polylines over the part */
  const size_t *poly_n;          /* borrowed: points of each (closed: last joins first) */
  const double *const *poly_xyz; /* borrowed: 3 poly_n[i] coordinates each */
};

/* Writes the picture (1800 x 640 pixels) to path as PNG, atomically. */
enum px_status px_mesh_view_png(struct px_context *ctx, const struct px_mesh_view *v,
                                const char *path);

#endif
