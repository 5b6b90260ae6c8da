/* Bodies on a regular grid: primitives (box, cylinder, sphere) combined by
 * union and difference and evaluated at cell centres, selections of elements
 * (box regions, body faces, the element nearest a point) and the
 * connectivity check. Plain C on host memory; independent of the backends. */
#ifndef PX_LATTICE_GRID_H
#define PX_LATTICE_GRID_H

#include <stddef.h>
#include <stdint.h>

#include "partix/context.h"
#include "partix/status.h"

enum px_lattice_shape {
  PX_LATTICE_SHAPE_BOX = 0,
  PX_LATTICE_SHAPE_CYLINDER = 1,
  PX_LATTICE_SHAPE_SPHERE = 2
};

enum px_lattice_op {
  PX_LATTICE_OP_UNION = 0,     /* add the cells whose centres are inside */
  PX_LATTICE_OP_DIFFERENCE = 1 /* remove them */
};

/* One primitive. Units: metres. */
struct px_lattice_prim {
  enum px_lattice_shape shape;
  enum px_lattice_op op;
  double p0[3]; /* box: min corner; cylinder: centre of one end; sphere: centre */
  double p1[3]; /* box: max corner; cylinder: centre of the other end */
  double r;     /* cylinder and sphere radius */
};

/* A body: occupancy of the cells of a box-shaped grid. Cell (i, j, k) has
 * index i + n[0] (j + n[1] k) and centre origin + (i + 1/2, j + 1/2, k + 1/2) h.
 * The grid is cropped to the occupied cells, so every face of the box holds
 * at least one element. */
struct px_lattice_grid {
  double h;         /* spacing [m] */
  double origin[3]; /* lower corner of cell (0, 0, 0) [m] */
  int n[3];         /* cells per axis */
  size_t ncell;     /* n[0] n[1] n[2] */
  size_t count;     /* occupied cells (elements) */
  uint8_t *occ;     /* owned (px_mem); ncell entries, 1 = occupied */
};

/* Faces of the body, for selections. */
enum px_lattice_face {
  PX_LATTICE_FACE_NONE = -1,
  PX_LATTICE_FACE_X_MIN = 0,
  PX_LATTICE_FACE_X_MAX = 1,
  PX_LATTICE_FACE_Y_MIN = 2,
  PX_LATTICE_FACE_Y_MAX = 3,
  PX_LATTICE_FACE_Z_MIN = 4,
  PX_LATTICE_FACE_Z_MAX = 5
};

/* A selection of elements: the conditions given are combined with AND.
 *   box:     centre inside [box_min, box_max] (inclusive, tolerance 1e-6 h)
 *   face:    element in the outermost layer of the body on that side (the
 *            first/last occupied layer of the grid along the axis)
 *   nearest: then only the one element (of those matching the others)
 *            nearest to `point` (ties: lowest index)
 * With none given, every element is selected. */
struct px_lattice_sel {
  int has_box;
  double box_min[3], box_max[3];
  enum px_lattice_face face;
  int has_point;
  double point[3];
};

/* Largest grid (cells of the body's bounding box) accepted: cell indices
 * and per-axis counts stay within int32 and the padded layout
 * (lattice_model.h, up to 16x the cells for thin bodies) within what size_t
 * arithmetic of the engines holds. Memory runs out long before on most
 * machines (px_lattice_need in lattice.c refuses that earlier). */
#define PX_LATTICE_MAX_CELLS (((size_t)1 << 31) - 1)
/* Largest |coordinate| and radius of a primitive or selection [m]: every
 * squared distance and extent then stays finite (1e30 << DBL_MAX). */
#define PX_LATTICE_COORD_MAX 1e15

/* The grid of a body without evaluating it (nothing allocated): spacing,
 * origin, cells per axis and ncell of the bounding box of the unions,
 * aligned with the lower corner of the first primitive; occ stays NULL and
 * count 0. Fails (PX_STATUS_CONFIG, the message says which primitive) on a
 * degenerate or non-finite primitive, or a bounding box of more than
 * PX_LATTICE_MAX_CELLS cells of h (also one whose extent overflows; then
 * *cells, when not NULL, holds that count: > PX_LATTICE_MAX_CELLS,
 * infinite or NaN). */
enum px_status px_lattice_grid_plan(struct px_context *ctx, double h,
                                    const struct px_lattice_prim *prims, size_t nprim,
                                    struct px_lattice_grid *g, double *cells);

/* Evaluate the primitives in order (the first must be a union) on the grid
 * of px_lattice_grid_plan. Fails (PX_STATUS_CONFIG, message says which
 * primitive) on a degenerate primitive, an empty body or a body too large to
 * index. g is overwritten; free with px_lattice_grid_free. */
enum px_status px_lattice_grid_build(struct px_context *ctx, double h,
                                     const struct px_lattice_prim *prims, size_t nprim,
                                     struct px_lattice_grid *g);
/* A box body of n0 x n1 x n2 elements with its lower corner at the origin. */
enum px_status px_lattice_grid_box(struct px_context *ctx, double h, int n0, int n1, int n2,
                                   struct px_lattice_grid *g);
void px_lattice_grid_free(struct px_context *ctx, struct px_lattice_grid *g);

/* Centre of cell `c` [m]. */
void px_lattice_grid_centre(const struct px_lattice_grid *g, size_t c, double x[3]);

/* Fail with PX_STATUS_CONFIG unless the elements form one face-connected
 * body; the message gives the number of parts and where the smallest is. */
enum px_status px_lattice_grid_check_connected(struct px_context *ctx,
                                               const struct px_lattice_grid *g);

/* Cells (indices, ascending) matched by `sel`. *cells is px_mem-allocated
 * (free with px_mem_free). Fails with PX_STATUS_CONFIG if nothing matches. */
enum px_status px_lattice_select(struct px_context *ctx, const struct px_lattice_grid *g,
                                 const struct px_lattice_sel *sel, size_t **cells, size_t *count);

/* "x_min" ... "z_max" for a face. */
const char *px_lattice_face_name(enum px_lattice_face f);

#endif
