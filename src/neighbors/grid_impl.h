/* Private layout of px_grid and its per-backend kernel table. */
#ifndef PX_GRID_IMPL_H
#define PX_GRID_IMPL_H

#include <stddef.h>
#include <stdint.h>

#include "compute/backend_impl.h"
#include "partix/neighbors.h"

struct px_grid;

/* Per-backend implementation (see "Kernel tables" in backend_impl.h).
 * Arguments are validated by grid.c; n = g->n > 0 when these are called. */
struct px_grid_ops {
  const char *backend;
  /* Fill g->cell, g->perm, g->start, g->end from the first g->n positions. */
  enum px_status (*build)(struct px_grid *g, enum px_precision precision, struct px_buffer *x,
                          struct px_buffer *y, struct px_buffer *z);
  /* dst[k] = src[perm[k]], elements of elem_size (1, 2, 4 or 8) bytes. */
  enum px_status (*reorder)(struct px_grid *g, size_t elem_size, struct px_buffer *src,
                            struct px_buffer *dst);
  enum px_status (*count_neighbours)(struct px_grid *g, enum px_precision precision,
                                     struct px_buffer *x, struct px_buffer *y, struct px_buffer *z,
                                     double range, struct px_buffer *out);
  /* Free g->impl (scratch of the backend's implementation); NULL-safe impl. */
  void (*release)(struct px_grid *g);
};

extern const struct px_grid_ops px_grid_ops_cpu;
#ifdef PX_HAVE_OPENCL
extern const struct px_grid_ops px_grid_ops_opencl;
#endif

struct px_grid {
  struct px_backend *be;         /* borrowed */
  const struct px_grid_ops *ops; /* static */
  int dims;
  double origin[3]; /* lower corner; unused axes 0 */
  double cell_size; /* h */
  double inv_h;     /* 1/h, rounded once to the kernels' precision */
  int cells[3];     /* per axis; unused axes 1 */
  size_t ncells;
  size_t n;                /* particles of the last build */
  struct px_buffer *cell;  /* owned, u32 [>= n] */
  struct px_buffer *perm;  /* owned, u32 [>= n] */
  struct px_buffer *start; /* owned, u32 [ncells] */
  struct px_buffer *end;   /* owned, u32 [ncells] */
  void *impl;              /* owned by ops (scratch) */
};

/* cpu loops, one instantiation per precision (grid_cpu.h). */
void px_grid_cpu_cells_f32(int threads, const struct px_grid *g, const float *x, const float *y,
                           const float *z, uint32_t *cell);
void px_grid_cpu_cells_f64(int threads, const struct px_grid *g, const double *x, const double *y,
                           const double *z, uint32_t *cell);
void px_grid_cpu_count_f32(int threads, const struct px_grid *g, const float *x, const float *y,
                           const float *z, double range, uint32_t *out);
void px_grid_cpu_count_f64(int threads, const struct px_grid *g, const double *x, const double *y,
                           const double *z, double range, uint32_t *out);

#endif
