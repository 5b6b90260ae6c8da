/* What the DXF reader (geo_dxf.c) and the chaining of its pieces
 * (geo_dxf_chain.c) share. */
#ifndef PX_IO_GEO_DXF_IMPL_H
#define PX_IO_GEO_DXF_IMPL_H

#include <stddef.h>

#include "io/geometry/geo_dxf.h"

/* What a drawing may hold (checked before allocating or looping):
 * coordinates and radii in drawing units (keeps every product and square
 * finite; mapped to the caller's units a solver checks them against its
 * own limits), the bulge of a polyline vertex (tan of a quarter of
 * the included angle: 1e6 is an arc 4e-6 rad short of a full circle),
 * SPLINE weights, pieces (PX_GEO_DXF_PIECES_MAX, geo_dxf.h), points
 * sampled from SPLINEs in the whole file, and the size of the file. */
#define PX_GEO_DXF_COORD_MAX 1e15
#define PX_GEO_DXF_BULGE_MAX 1e6
#define PX_GEO_DXF_WEIGHT_MAX 1e15
#define PX_GEO_DXF_SAMPLES_MAX 4000000
#define PX_GEO_DXF_FILE_MAX (256.0 * 1024 * 1024)

/* A growable array of doubles. */
struct px_geo_dxf_vec {
  double *v;
  size_t n, cap;
};

/* A piece: one entity as a path (open or closed). */
struct px_geo_dxf_piece {
  struct px_geo_path path;
  int closed;
  size_t line; /* where the entity starts */
  char type[16];
};

struct px_geo_dxf_pieces {
  struct px_geo_dxf_piece *v;
  size_t n, cap;
  size_t samples;   /* points sampled from SPLINEs so far */
  const char *name; /* the file, for messages (borrowed) */
};

/* Map primitive q from drawing units: x -> s x + (dx, dy). */
void px_geo_dxf_transform(struct px_geo_prim *q, double s, double dx, double dy);
/* Chain the pieces ps into closed loops within tolerance tol (mapped
 * units): out holds ps->n paths (owned by the caller, also on failure),
 * *nout of them made. */
enum px_status px_geo_dxf_chain(struct px_context *ctx, const char *name,
                                struct px_geo_dxf_pieces *ps, double tol, struct px_geo_path *out,
                                size_t *nout);

#endif
