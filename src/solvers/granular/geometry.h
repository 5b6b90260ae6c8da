/* Boundary geometry of the granular solver (host side, double precision):
 * paths of primitives (io/geometry/geo_path.h: line, circular/elliptic arc,
 * parabolic arc, polyline; DXF import in io/geometry/geo_dxf.h) chained
 * into closed contours, splitting into segments of about a given length,
 * orientation so that normals point into the media, and queries on the
 * region the media may occupy (inside the container, outside parts).
 *
 * Contours belong to rigid bodies (each with its own motion); coordinates
 * given here are the body frame = world coordinates at zero displacement. */
#ifndef PX_GRAN_GEOMETRY_H
#define PX_GRAN_GEOMETRY_H

#include <stddef.h>

#include "io/geometry/geo_path.h"
#include "partix/context.h"

/* ------------------------------------------------------------------ limits */

/* What the solver takes, checked before anything is allocated or looped
 * over: boundary segments of all contours together (segment indices are
 * int in the wall lists, bins and checkpoints; each segment costs about
 * 400 bytes with its statistics), coordinates of contour points [m] (keeps
 * every difference and square of coordinates finite), and the pairs of
 * segments the crossing tests may compare (the segments of a contour piled
 * up in a few grid cells). */
#define PX_GRAN_SEG_MAX 1000000
#define PX_GRAN_COORD_MAX 1e12
#define PX_GRAN_CROSS_TESTS 4e8
/* Contours of all shapes together (each has its outputs and per-thread
 * force sums; a DXF shape gives one per closed loop). */
#define PX_GRAN_CONTOURS_MAX 1024
/* Discs (ids and pair indices are int32: a neighbour list of ~5 pairs per
 * disc stays far below 2^31; memory: px_gran_sys_particle_bytes). */
#define PX_GRAN_N_MAX 1e8

/* ------------------------------------------------------------------ geometry */

/* What lies on the media side of a contour. */
enum px_gran_side {
  PX_GRAN_SIDE_AUTO = 0, /* from nesting: media inside iff enclosed by an even
                            number of other contours (container inside, part
                            outside, hole in a part inside) */
  PX_GRAN_SIDE_INSIDE = 1,
  PX_GRAN_SIDE_OUTSIDE = 2
};

struct px_gran_contour {
  char name[64];
  int body;                      /* rigid body moving this contour */
  enum px_gran_side side;        /* requested */
  int media_inside;              /* resolved */
  int depth;                     /* number of other contours around it */
  size_t first, count;           /* its segments in the geometry's arrays */
  double length;                 /* perimeter [m] */
  double xmin, ymin, xmax, ymax; /* bounding box, body frame [m] */
  /* Segment bins in the body frame (built once): cell (i, j) holds
   * bin_seg[bin_start[j*nx+i] .. bin_start[j*nx+i+1]-1]. */
  double bx0, by0, bh; /* origin and cell size [m] */
  int bnx, bny;
  int *bin_start, *bin_seg; /* owned */
  /* Horizontal strips for the point-in-contour test (built once): strip j
   * (y in [sy0 + j sh, sy0 + (j + 1) sh), clamped at both ends) lists the
   * local indices k of the non-horizontal edges (k, k + 1) whose y-range
   * meets it: strip_seg[strip_start[j] .. strip_start[j + 1] - 1]. */
  double sy0, sh;
  int sny;
  int *strip_start, *strip_seg; /* owned */
};

/* All contours with their segments (global numbering, contour by contour,
 * in order along each contour with the media on the left). */
struct px_gran_geom {
  struct px_gran_contour *contours; /* owned */
  size_t ncontours, ccap;
  size_t nseg, scap;
  /* per segment (owned): start vertex, unit tangent, length, tangent of the
   * previous segment of the contour, flags (PX_GRAN_SEG_*), contour */
  double *ax, *ay, *tx, *ty, *len, *tpx, *tpy;
  int *flags, *contour;
  double smooth_angle; /* concave joints turning less than this are smooth [rad] */
};

void px_gran_geom_init(struct px_gran_geom *g);
void px_gran_geom_free(struct px_context *ctx, struct px_gran_geom *g);

/* Split a closed path into segments of about h (each primitive into
 * ceil(length / h) pieces of equal arc length, at least one) and add it as a
 * contour. Fails with PX_STATUS_CONFIG, before allocating, when a primitive
 * has non-finite or out-of-range parameters (coordinates beyond
 * PX_GRAN_COORD_MAX, radii <= 0, an arc sweeping more than a turn) or the
 * segments of all contours would be more than PX_GRAN_SEG_MAX; and when the
 * path is not closed (gap larger than tol), is degenerate, or crosses
 * itself. */
enum px_status px_gran_geom_add_path(struct px_context *ctx, struct px_gran_geom *g,
                                     const struct px_geo_path *path, double h, double tol,
                                     const char *name, int body, enum px_gran_side side);

/* After all contours are added: orient them (media on the left), set joint
 * flags, check that contours do not cross each other, and bin segments with
 * cells of about `cell` [m]. */
enum px_status px_gran_geom_finish(struct px_context *ctx, struct px_gran_geom *g, double cell);

/* Rigid placement of each contour (its body's): world = R(phi)(local -
 * pivot) + pivot + d, frames[c * PX_GRAN_CTR_COUNT + k] as in wall_kernel.h
 * (double). */
/* 1 if the point (world) is in the media region: on the media side of the
 * innermost contour around it. */
int px_gran_geom_inside(const struct px_gran_geom *g, const double *frames, double x, double y);
/* Smallest distance from the point (world) to any segment, searched up to
 * `range` (returns range when nothing is closer). */
double px_gran_geom_distance(const struct px_gran_geom *g, const double *frames, double x, double y,
                             double range);
/* Candidate segments of contour c within `range` of the point (body frame
 * coordinates lx, ly): appended to out (ascending, unique), returns the
 * number appended or -1 if more than cap. */
int px_gran_geom_near(const struct px_gran_geom *g, size_t c, double lx, double ly, double range,
                      int *out, int cap);
/* World -> body frame of contour c's body. */
void px_gran_geom_to_local(const double *frame, double x, double y, double *lx, double *ly);

/* Number of segments of contour c whose midpoints are (body frame) at
 * parameter s along the contour [m] from its first vertex: s_mid[k] for the
 * CSV; fills s (count values). */
void px_gran_geom_arclength(const struct px_gran_geom *g, size_t c, double *s);

/* Samples used to measure curved primitives (and to split them). */
#define PX_GRAN_SAMPLES PX_GEO_SAMPLES
/* Even-odd crossing test of point (px, py) against the closed polygon of
 * the n vertices x, y: 1 inside. */
int px_gran_poly_contains(const double *x, const double *y, size_t n, double px, double py);

/* Whether the ray from (px, py) towards +x crosses the edge from vertex k
 * to vertex e (half-open in y: the even-odd test of px_gran_poly_contains
 * and px_gran_contour_contains). */
static inline int px_gran_ray_crosses(const double *x, const double *y, size_t k, size_t e,
                                      double px, double py) {
  return (y[k] > py) != (y[e] > py) && x[k] + (py - y[k]) / (y[e] - y[k]) * (x[e] - x[k]) > px;
}

/* px_gran_poly_contains for contour c at the body-frame point (lx, ly),
 * through its strips: the same answer, testing only the edges of the
 * point's strip. */
int px_gran_contour_contains(const struct px_gran_geom *g, size_t c, double lx, double ly);

/* Build the strips of contour C (px_gran_geom_finish). */
enum px_status px_gran_contour_strips(struct px_context *ctx, struct px_gran_geom *g,
                                      struct px_gran_contour *C);

#endif
