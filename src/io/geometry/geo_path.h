/* Solver-neutral geometry, part 1: paths of primitives (line, circular arc,
 * elliptic arc, parabolic arc, polyline) in double precision, as drawings and
 * case files describe boundaries. The DXF reader (geo_dxf.h) gives them; a
 * solver splits them into its own segments. Internal; not installed.
 *
 * Ownership: a path owns its primitive array and the point array of each
 * PX_GEO_PRIM_POINTS primitive (px_geo_path_add copies them);
 * px_geo_path_free releases both and leaves an empty path. Units are the
 * caller's (the DXF reader maps drawing units to the caller's). */
#ifndef PX_IO_GEO_PATH_H
#define PX_IO_GEO_PATH_H

#include <stddef.h>

#include "partix/context.h"

enum px_geo_prim_kind {
  PX_GEO_PRIM_LINE = 0,    /* p0 -> p1 */
  PX_GEO_PRIM_ARC = 1,     /* circle centre, radius, angle a0 -> a1 [rad] (a1 < a0: clockwise) */
  PX_GEO_PRIM_ELLIPSE = 2, /* centre, semi-axes a, b, rotation, parameter t0 -> t1 [rad] */
  PX_GEO_PRIM_BEZIER2 = 3, /* parabolic arc: quadratic Bezier p0, control, p1 */
  PX_GEO_PRIM_POINTS = 4   /* polyline through given points (splines, sampled) */
};

/* One primitive. Points of PX_GEO_PRIM_POINTS are owned by the path. */
struct px_geo_prim {
  enum px_geo_prim_kind kind;
  double p[8]; /* LINE: x0 y0 x1 y1; ARC: cx cy r a0 a1; ELLIPSE: cx cy a b rot t0 t1;
                  BEZIER2: x0 y0 cx cy x1 y1 */
  double *pts; /* POINTS: x0 y0 x1 y1 ... (owned) */
  size_t npts; /* POINTS: number of points */
  int smooth;  /* POINTS: 1 if the points sample a smooth curve (resampled by
                  arc length); 0 if they are corners (each piece split alone) */
};

/* A chain of primitives, end of one = start of the next. */
struct px_geo_path {
  struct px_geo_prim *prims; /* owned */
  size_t n, cap;
  char where[160]; /* for messages: "case.yaml:12:5" or "part.dxf:7" */
};

/* Samples used to measure curved primitives (ellipse and parabolic arcs). */
#define PX_GEO_SAMPLES 2048

/* An empty path; where (may be NULL) is copied, truncated to fit. */
void px_geo_path_init(struct px_geo_path *p, const char *where);
/* NULL-safe; the path is empty afterwards (where kept). */
void px_geo_path_free(struct px_context *ctx, struct px_geo_path *p);
/* Appends a copy of prim (and of its points). */
enum px_status px_geo_path_add(struct px_context *ctx, struct px_geo_path *p,
                               const struct px_geo_prim *prim);
/* Appends a PX_GEO_PRIM_POINTS primitive: copies n points (x, y pairs). */
enum px_status px_geo_path_add_points(struct px_context *ctx, struct px_geo_path *p,
                                      const double *xy, size_t n, int smooth);
/* Start and end point of a primitive. */
void px_geo_prim_ends(const struct px_geo_prim *q, double *x0, double *y0, double *x1, double *y1);
/* Point at parameter u in [0, 1] (POINTS: piecewise linear in the index). */
void px_geo_prim_eval(const struct px_geo_prim *q, double u, double *x, double *y);
/* Reverse the direction of a primitive. */
void px_geo_prim_reverse(struct px_geo_prim *q);
/* Arc length (ellipse and parabolic arcs: polygon of PX_GEO_SAMPLES chords). */
double px_geo_prim_length(const struct px_geo_prim *q);

#endif
