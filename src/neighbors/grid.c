/* Uniform-grid neighbour search: public API, argument checks, dispatch to
 * the backend's implementation, and the brute-force reference. */
#include <math.h>
#include <string.h>

#include "neighbors/grid_impl.h"
#include "partix/memory.h"

static const void *const px_grid_table[] = {
    &px_grid_ops_cpu,
#ifdef PX_HAVE_OPENCL
    &px_grid_ops_opencl,
#endif
};

#define PX_GRID_MAX_INDEX 0x7fffffffu

/* The shape arguments of px_grid_create / px_grid_reshape checked; the
 * total number of cells into *ncells. */
static enum px_status px_grid_check_shape(struct px_backend *be, const char *what, int dims,
                                          const double *origin, double cell_size,
                                          const size_t *cells, size_t *ncells) {
  int a;
  *ncells = 1;
  if (!origin || !cells)
    return px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: origin or cells is NULL", what);
  if (!(cell_size > 0.0) || !isfinite(cell_size))
    return px_context_fail(be->ctx, PX_STATUS_INVALID,
                           "%s: cell size %g, expected a finite value > 0", what, cell_size);
  for (a = 0; a < dims; ++a) {
    if (!isfinite(origin[a]))
      return px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: origin[%d] is not finite", what, a);
    if (cells[a] < 1 || cells[a] > PX_GRID_MAX_INDEX / *ncells)
      return px_context_fail(be->ctx, PX_STATUS_INVALID,
                             "%s: cells[%d] = %zu; every count must be >= 1 and the total "
                             "below 2^31",
                             what, a, cells[a]);
    *ncells *= cells[a];
  }
  return PX_STATUS_OK;
}

/* A checked shape into g (no particles built yet). */
static void px_grid_set_shape(struct px_grid *g, const double *origin, double cell_size,
                              const size_t *cells, size_t ncells) {
  int a;
  g->cell_size = cell_size;
  g->inv_h = 1.0 / cell_size;
  g->ncells = ncells;
  g->n = 0;
  for (a = 0; a < 3; ++a) {
    g->origin[a] = a < g->dims ? origin[a] : 0.0;
    g->cells[a] = a < g->dims ? (int)cells[a] : 1;
  }
}

enum px_status px_grid_create(struct px_backend *be, int dims, const double *origin,
                              double cell_size, const size_t *cells, struct px_grid **out) {
  static const char *const what = "px_grid_create";
  struct px_grid *g;
  const struct px_grid_ops *ops;
  size_t ncells = 1;
  enum px_status st;
  if (!out || !be)
    return be ? px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: out is NULL", what)
              : PX_STATUS_INVALID;
  *out = NULL;
  if (dims != 2 && dims != 3)
    return px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: dims = %d, expected 2 or 3", what,
                           dims);
  PX_TRY(px_grid_check_shape(be, what, dims, origin, cell_size, cells, &ncells));
  ops = PX_BACKEND_PICK(be, "neighbour grid", px_grid_table);
  if (!ops) return px_context_status(be->ctx);
  g = px_mem_calloc(be->ctx, "neighbour grid", 1, sizeof *g);
  if (!g) return PX_STATUS_NOMEM;
  g->be = be;
  g->ops = ops;
  g->dims = dims;
  px_grid_set_shape(g, origin, cell_size, cells, ncells);
  st = px_buffer_create(be, "grid cells", 0, &g->cell);
  if (st == PX_STATUS_OK) st = px_buffer_create(be, "grid permutation", 0, &g->perm);
  if (st == PX_STATUS_OK) st = px_buffer_create(be, "grid cell start", ncells * 4, &g->start);
  if (st == PX_STATUS_OK) st = px_buffer_create(be, "grid cell end", ncells * 4, &g->end);
  if (st == PX_STATUS_OK) st = px_buffer_zero(g->start);
  if (st == PX_STATUS_OK) st = px_buffer_zero(g->end);
  if (st != PX_STATUS_OK) {
    px_grid_free(g);
    return st;
  }
  *out = g;
  return PX_STATUS_OK;
}

enum px_status px_grid_reshape(struct px_grid *g, const double *origin, double cell_size,
                               const size_t *cells) {
  static const char *const what = "px_grid_reshape";
  size_t ncells;
  if (!g) return PX_STATUS_INVALID;
  PX_TRY(px_grid_check_shape(g->be, what, g->dims, origin, cell_size, cells, &ncells));
  /* only grown: a failure leaves buffers that still fit the old shape */
  if (px_buffer_bytes(g->start) < ncells * 4) PX_TRY(px_buffer_resize(g->start, ncells * 4));
  if (px_buffer_bytes(g->end) < ncells * 4) PX_TRY(px_buffer_resize(g->end, ncells * 4));
  px_grid_set_shape(g, origin, cell_size, cells, ncells);
  PX_TRY(px_buffer_zero(g->start));
  return px_buffer_zero(g->end);
}

void px_grid_free(struct px_grid *g) {
  if (!g) return;
  if (g->ops->release) g->ops->release(g);
  px_buffer_free(g->cell);
  px_buffer_free(g->perm);
  px_buffer_free(g->start);
  px_buffer_free(g->end);
  px_mem_free(g->be->ctx, g);
}

int px_grid_dims(const struct px_grid *g) { return g ? g->dims : 0; }
double px_grid_cell_size(const struct px_grid *g) { return g ? g->cell_size : 0.0; }
size_t px_grid_cell_count(const struct px_grid *g) { return g ? g->ncells : 0; }
size_t px_grid_particle_count(const struct px_grid *g) { return g ? g->n : 0; }
struct px_buffer *px_grid_cells(struct px_grid *g) {
  return g ? g->cell : NULL;
}
struct px_buffer *px_grid_permutation(struct px_grid *g) {
  return g ? g->perm : NULL;
}
struct px_buffer *px_grid_cell_start(struct px_grid *g) {
  return g ? g->start : NULL;
}
struct px_buffer *px_grid_cell_end(struct px_grid *g) {
  return g ? g->end : NULL;
}

static enum px_status px_grid_check_positions(struct px_grid *g, const char *what,
                                              enum px_precision precision, size_t n,
                                              struct px_buffer *x, struct px_buffer *y,
                                              struct px_buffer *z) {
  enum px_dtype type;
  PX_TRY(px_precision_dtype(g->be, what, precision, &type));
  PX_TRY(px_buffer_check(g->be, what, "x", x, n, type));
  PX_TRY(px_buffer_check(g->be, what, "y", y, n, type));
  if (g->dims == 3) {
    PX_TRY(px_buffer_check(g->be, what, "z", z, n, type));
  } else if (z) {
    return px_context_fail(g->be->ctx, PX_STATUS_INVALID, "%s: z given for a 2D grid (pass NULL)",
                           what);
  }
  return PX_STATUS_OK;
}

enum px_status px_grid_build(struct px_grid *g, enum px_precision precision, size_t n,
                             struct px_buffer *x, struct px_buffer *y, struct px_buffer *z) {
  static const char *const what = "px_grid_build";
  enum px_status st;
  if (!g) return PX_STATUS_INVALID;
  if (n > PX_GRID_MAX_INDEX)
    return px_context_fail(g->be->ctx, PX_STATUS_INVALID,
                           "%s: %zu particles exceed the 32-bit index range (2^31 - 1)", what, n);
  PX_TRY(px_grid_check_positions(g, what, precision, n, x, y, z));
  PX_TRY(px_buffer_resize(g->cell, n * 4));
  PX_TRY(px_buffer_resize(g->perm, n * 4));
  g->n = n;
  if (n == 0) {
    PX_TRY(px_buffer_zero(g->start));
    return px_buffer_zero(g->end);
  }
  st = g->ops->build(g, precision, x, y, z);
  if (st != PX_STATUS_OK) {
    g->n = 0;
    return px_context_prefix(g->be->ctx, "%s (%zu particles, %zu cells)", what, n, g->ncells);
  }
  return PX_STATUS_OK;
}

enum px_status px_grid_reorder(struct px_grid *g, enum px_dtype type, struct px_buffer *src,
                               struct px_buffer *dst) {
  static const char *const what = "px_grid_reorder";
  size_t es;
  if (!g) return PX_STATUS_INVALID;
  es = px_dtype_size(type);
  if (es == 0)
    return px_context_fail(g->be->ctx, PX_STATUS_INVALID, "%s: unknown element type %d", what,
                           (int)type);
  PX_TRY(px_buffer_check(g->be, what, "src", src, g->n, type));
  PX_TRY(px_buffer_check(g->be, what, "dst", dst, g->n, type));
  if (src == dst)
    return px_context_fail(g->be->ctx, PX_STATUS_INVALID,
                           "%s: source and destination are the same buffer ('%s'); a gather "
                           "cannot run in place",
                           what, src->label);
  if (g->n == 0) return PX_STATUS_OK;
  return g->ops->reorder(g, es, src, dst);
}

enum px_status px_grid_count_neighbours(struct px_grid *g, enum px_precision precision,
                                        struct px_buffer *x, struct px_buffer *y,
                                        struct px_buffer *z, double range, struct px_buffer *out) {
  static const char *const what = "px_grid_count_neighbours";
  if (!g) return PX_STATUS_INVALID;
  if (!(range > 0.0) || !(range <= g->cell_size))
    return px_context_fail(g->be->ctx, PX_STATUS_INVALID,
                           "%s: range %g must be > 0 and <= the cell size %g", what, range,
                           g->cell_size);
  PX_TRY(px_grid_check_positions(g, what, precision, g->n, x, y, z));
  PX_TRY(px_buffer_check(g->be, what, "out", out, g->n, PX_DTYPE_U32));
  if (g->n == 0) return PX_STATUS_OK;
  return g->ops->count_neighbours(g, precision, x, y, z, range, out);
}

enum px_status px_neighbors_pairs_reference(struct px_context *ctx, int dims, size_t n,
                                            const double *x, const double *y, const double *z,
                                            double range, uint32_t **pairs, size_t *npairs) {
  const double r2 = range * range;
  uint32_t *list = NULL;
  size_t count = 0, cap = 0, i, j;
  if (!pairs || !npairs || (dims != 2 && dims != 3) || (n && (!x || !y || (dims == 3 && !z))))
    return px_context_fail(ctx, PX_STATUS_INVALID,
                           "px_neighbors_pairs_reference: invalid arguments");
  *pairs = NULL;
  *npairs = 0;
  if (n > PX_GRID_MAX_INDEX)
    return px_context_fail(ctx, PX_STATUS_INVALID,
                           "px_neighbors_pairs_reference: %zu points exceed 2^31 - 1", n);
  for (i = 0; i < n; ++i)
    for (j = i + 1; j < n; ++j) {
      const double dx = x[j] - x[i], dy = y[j] - y[i], dz = dims == 3 ? z[j] - z[i] : 0.0;
      if (dx * dx + dy * dy + dz * dz < r2) {
        if (count == cap) {
          size_t grown = cap ? 2 * cap : 1024;
          uint32_t *p = px_mem_realloc(ctx, "reference pairs", list, 2 * grown * sizeof *p);
          if (!p) {
            px_mem_free(ctx, list);
            return PX_STATUS_NOMEM;
          }
          list = p;
          cap = grown;
        }
        list[2 * count] = (uint32_t)i;
        list[2 * count + 1] = (uint32_t)j;
        ++count;
      }
    }
  *pairs = list;
  *npairs = count;
  return PX_STATUS_OK;
}
