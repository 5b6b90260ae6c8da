/* What the DXF reader (dxf.c) and the chaining of its pieces (dxf_chain.c)
 * share. */
#ifndef PX_GRAN_DXF_IMPL_H
#define PX_GRAN_DXF_IMPL_H

#include <stddef.h>

#include "solvers/granular/geometry.h"

/* What a drawing may hold (checked before allocating or looping):
 * coordinates and radii in drawing units (keeps every product and square
 * finite; scaled to metres they are checked again against
 * PX_GRAN_COORD_MAX), the bulge of a polyline vertex (tan of a quarter of
 * the included angle: 1e6 is an arc 4e-6 rad short of a full circle),
 * SPLINE weights, pieces (entities used: each becomes at least one segment,
 * so more than PX_GRAN_SEG_MAX can never run), points sampled from SPLINEs
 * in the whole file, and the size of the file. */
#define PX_DXF_COORD_MAX 1e15
#define PX_DXF_BULGE_MAX 1e6
#define PX_DXF_WEIGHT_MAX 1e15
#define PX_DXF_PIECES_MAX PX_GRAN_SEG_MAX
#define PX_DXF_SAMPLES_MAX 4000000
#define PX_DXF_FILE_MAX (256.0 * 1024 * 1024)

/* A growable array of doubles. */
struct px_dxf_vec {
  double *v;
  size_t n, cap;
};

/* A piece: one entity as a path (open or closed). */
struct px_dxf_piece {
  struct px_gran_path path;
  int closed;
  size_t line; /* where the entity starts */
  char type[16];
};

struct px_dxf_pieces {
  struct px_dxf_piece *v;
  size_t n, cap;
  size_t samples;   /* points sampled from SPLINEs so far */
  const char *name; /* the file, for messages (borrowed) */
};

/* Map primitive q from drawing units: x -> s x + (dx, dy) [m]. */
void px_dxf_transform(struct px_gran_prim *q, double s, double dx, double dy);
/* Chain the pieces ps into closed loops within tolerance tol [m]: out holds
 * ps->n paths (owned by the caller, also on failure), *nout of them made. */
enum px_status px_dxf_chain(struct px_context *ctx, const char *name, struct px_dxf_pieces *ps,
                            double tol, struct px_gran_path *out, size_t *nout);

#endif
