/* opencl implementation of the neighbour grid (kernels in
 * src/compute/opencl/grid.cl, algorithm described there). Compiled only with
 * the opencl backend (CMakeLists.txt). */
#include "compute/opencl/opencl_impl.h"
#include "neighbors/grid_impl.h"
#include "partix/memory.h"

/* Scratch kept between builds (all u32 device buffers, owned). */
struct px_grid_cl {
  struct px_buffer *slot;       /* place of each particle in its cell, [n] */
  struct px_buffer *crowded;    /* [1]: some cell holds > PX_GRID_SMALL_CELL */
  struct px_buffer *k[2], *v;   /* ping-pong keys and values, [n] */
  struct px_buffer *kt, *vt;    /* tile-sorted keys and values, [n] */
  struct px_buffer *hist;       /* [16][ntiles], scanned into offsets */
  struct px_buffer *tile_start; /* [ntiles][16] */
};

static enum px_status px_grid_cl_impl(struct px_grid *g, struct px_grid_cl **out) {
  struct px_grid_cl *s = g->impl;
  if (!s) {
    s = px_mem_calloc(g->be->ctx, "grid sort scratch", 1, sizeof *s);
    if (!s) return PX_STATUS_NOMEM;
    g->impl = s;
  }
  if (!s->slot)
    PX_TRY(px_buffer_create(g->be, "grid cell slots", g->n * 4, &s->slot));
  else
    PX_TRY(px_buffer_resize(s->slot, g->n * 4));
  if (!s->crowded) PX_TRY(px_buffer_create(g->be, "grid crowded flag", 4, &s->crowded));
  *out = s;
  return PX_STATUS_OK;
}

/* Buffers of the radix-sort path. */
static enum px_status px_grid_cl_scratch(struct px_grid *g, size_t n, size_t ntiles) {
  struct px_grid_cl *s = g->impl;
  struct px_buffer **bufs[6];
  static const char *const labels[6] = {"grid sort keys",        "grid sort keys",
                                        "grid sort values",      "grid sort tile keys",
                                        "grid sort tile values", "grid sort histogram"};
  int i;
  bufs[0] = &s->k[0];
  bufs[1] = &s->k[1];
  bufs[2] = &s->v;
  bufs[3] = &s->kt;
  bufs[4] = &s->vt;
  bufs[5] = &s->hist;
  for (i = 0; i < 6; ++i) {
    const size_t bytes = (i == 5 ? 16 * ntiles : n) * sizeof(cl_uint);
    if (!*bufs[i])
      PX_TRY(px_buffer_create(g->be, labels[i], bytes, bufs[i]));
    else
      PX_TRY(px_buffer_resize(*bufs[i], bytes));
  }
  if (!s->tile_start)
    PX_TRY(px_buffer_create(g->be, "grid sort tile starts", 16 * ntiles * sizeof(cl_uint),
                            &s->tile_start));
  else
    PX_TRY(px_buffer_resize(s->tile_start, 16 * ntiles * sizeof(cl_uint)));
  return PX_STATUS_OK;
}

static void px_grid_cl_release(struct px_grid *g) {
  struct px_grid_cl *s = g->impl;
  if (!s) return;
  px_buffer_free(s->slot);
  px_buffer_free(s->crowded);
  px_buffer_free(s->k[0]);
  px_buffer_free(s->k[1]);
  px_buffer_free(s->v);
  px_buffer_free(s->kt);
  px_buffer_free(s->vt);
  px_buffer_free(s->hist);
  px_buffer_free(s->tile_start);
  px_mem_free(g->be->ctx, s);
  g->impl = NULL;
}

/* Cell of every particle (px_grid_cells_2d/3d). The program is built for
 * the coordinates' precision, so px_opencl_args_real passes the origin and
 * 1/h in it. */
static enum px_status px_grid_cl_cells(struct px_grid *g, cl_program prog, struct px_buffer *x,
                                       struct px_buffer *y, struct px_buffer *z) {
  struct px_backend *be = g->be;
  const int d3 = g->dims == 3;
  struct px_opencl_args a;
  cl_kernel k;
  PX_TRY(px_opencl_kernel(be, prog, d3 ? "px_grid_cells_3d" : "px_grid_cells_2d", &k));
  px_opencl_args_begin(&a, be, k);
  px_opencl_args_u32(&a, "n", (uint32_t)g->n);
  px_opencl_args_mem(&a, "x", x);
  px_opencl_args_mem(&a, "y", y);
  if (d3) px_opencl_args_mem(&a, "z", z);
  px_opencl_args_real(&a, "ox", g->origin[0]); /* [m] */
  px_opencl_args_real(&a, "oy", g->origin[1]);
  if (d3) px_opencl_args_real(&a, "oz", g->origin[2]);
  px_opencl_args_real(&a, "inv_h", g->inv_h); /* [1/m] */
  px_opencl_args_i32(&a, "nx", g->cells[0]);
  px_opencl_args_i32(&a, "ny", g->cells[1]);
  if (d3) px_opencl_args_i32(&a, "nz", g->cells[2]);
  px_opencl_args_mem(&a, "cell", g->cell);
  return px_opencl_args_launch(&a, g->n, 0);
}

/* start/end from atomic counts and an exclusive scan; the slots and the
 * crowded flag for the choice of sort. */
static enum px_status px_grid_cl_ranges(struct px_grid *g, cl_program prog, struct px_grid_cl *s) {
  struct px_backend *be = g->be;
  const cl_uint n = (cl_uint)g->n, ncells = (cl_uint)g->ncells;
  struct px_opencl_args a;
  cl_kernel count, ends;
  PX_TRY(px_opencl_kernel(be, prog, "px_grid_count_cells", &count));
  PX_TRY(px_opencl_kernel(be, prog, "px_grid_cell_ends", &ends));
  PX_TRY(px_buffer_zero(g->start));
  PX_TRY(px_buffer_zero(s->crowded));
  px_opencl_args_begin(&a, be, count);
  px_opencl_args_u32(&a, "n", n);
  px_opencl_args_mem(&a, "cell", g->cell);
  px_opencl_args_mem(&a, "counts", g->start);
  px_opencl_args_mem(&a, "slot", s->slot);
  px_opencl_args_mem(&a, "crowded", s->crowded);
  PX_TRY(px_opencl_args_launch(&a, g->n, 0));
  PX_TRY(px_opencl_scan_u32(be, g->start, g->start, g->ncells, NULL));
  px_opencl_args_begin(&a, be, ends);
  px_opencl_args_u32(&a, "ncells", ncells);
  px_opencl_args_u32(&a, "n", n);
  px_opencl_args_mem(&a, "start", g->start);
  px_opencl_args_mem(&a, "end", g->end);
  return px_opencl_args_launch(&a, g->ncells, 0);
}

/* The permutation by a stable LSD radix sort of the cell indices. */
static enum px_status px_grid_cl_sort(struct px_grid *g, cl_program prog) {
  struct px_backend *be = g->be;
  const cl_uint n = (cl_uint)g->n;
  struct px_opencl_args a;
  cl_kernel tile, scatter, iota;
  size_t w, local_cap, ntiles;
  int bits = 0, passes, p;
  struct px_grid_cl *s;
  while (bits < 32 && ((size_t)1 << bits) < g->ncells) ++bits;
  passes = (bits + 3) / 4;
  if (passes == 0) {
    PX_TRY(px_opencl_kernel(be, prog, "px_grid_iota", &iota));
    px_opencl_args_begin(&a, be, iota);
    px_opencl_args_u32(&a, "n", n);
    px_opencl_args_mem(&a, "perm", g->perm);
    return px_opencl_args_launch(&a, g->n, 0);
  }
  PX_TRY(px_opencl_kernel(be, prog, "px_radix_tile", &tile));
  PX_TRY(px_opencl_kernel(be, prog, "px_radix_scatter", &scatter));
  /* lk, lv and ls: 3w + 32 uints of local memory */
  local_cap = (px_opencl_local_mem(be) / sizeof(cl_uint) - 32) / 3;
  PX_TRY(px_opencl_local_pow2(be, tile, local_cap < 256 ? local_cap : 256, &w));
  if (w < 16)
    return px_context_fail(be->ctx, PX_STATUS_UNSUPPORTED,
                           "neighbour grid: the radix-sort kernel needs work-groups of at least "
                           "16 work-items; this device allows %zu",
                           w);
  ntiles = (g->n + w - 1) / w;
  PX_TRY(px_grid_cl_scratch(g, g->n, ntiles));
  s = g->impl;
  for (p = 0; p < passes; ++p) {
    const cl_uint shift = (cl_uint)(4 * p), nt32 = (cl_uint)ntiles, w32 = (cl_uint)w;
    const cl_int first = p == 0, write_keys = p + 1 < passes;
    struct px_buffer *kin = p == 0 ? g->cell : s->k[(p - 1) % 2];
    struct px_buffer *vout = (passes - 1 - p) % 2 == 0 ? g->perm : s->v;
    struct px_buffer *vin = p == 0 ? g->cell : ((passes - p) % 2 == 0 ? g->perm : s->v);
    px_opencl_args_begin(&a, be, tile);
    px_opencl_args_u32(&a, "n", n);
    px_opencl_args_u32(&a, "shift", shift);
    px_opencl_args_i32(&a, "first", first);
    px_opencl_args_mem(&a, "kin", kin);
    px_opencl_args_mem(&a, "vin", vin);
    px_opencl_args_mem(&a, "kt", s->kt);
    px_opencl_args_mem(&a, "vt", s->vt);
    px_opencl_args_mem(&a, "hist", s->hist);
    px_opencl_args_mem(&a, "tile_start", s->tile_start);
    px_opencl_args_u32(&a, "ntiles", nt32);
    px_opencl_args_local(&a, "lk", w * sizeof(cl_uint));
    px_opencl_args_local(&a, "lv", w * sizeof(cl_uint));
    px_opencl_args_local(&a, "ls", (w + 32) * sizeof(cl_uint));
    PX_TRY(px_opencl_args_launch(&a, ntiles * w, w));
    PX_TRY(px_opencl_scan_u32(be, s->hist, s->hist, 16 * ntiles, NULL));
    px_opencl_args_begin(&a, be, scatter);
    px_opencl_args_u32(&a, "n", n);
    px_opencl_args_u32(&a, "shift", shift);
    px_opencl_args_u32(&a, "tile_w", w32);
    px_opencl_args_u32(&a, "ntiles", nt32);
    px_opencl_args_mem(&a, "kt", s->kt);
    px_opencl_args_mem(&a, "vt", s->vt);
    px_opencl_args_mem(&a, "offsets", s->hist);
    px_opencl_args_mem(&a, "tile_start", s->tile_start);
    px_opencl_args_mem(&a, "kout", s->k[p % 2]);
    px_opencl_args_mem(&a, "vout", vout);
    px_opencl_args_i32(&a, "write_keys", write_keys);
    PX_TRY(px_opencl_args_launch(&a, g->n, 0));
  }
  return PX_STATUS_OK;
}

/* Small-cells path: scatter by slot, then sort every cell's slice. */
static enum px_status px_grid_cl_scatter_sort(struct px_grid *g, cl_program prog,
                                              struct px_grid_cl *s) {
  struct px_backend *be = g->be;
  const cl_uint n = (cl_uint)g->n, ncells = (cl_uint)g->ncells;
  struct px_opencl_args a;
  cl_kernel scatter, sort;
  PX_TRY(px_opencl_kernel(be, prog, "px_grid_scatter", &scatter));
  PX_TRY(px_opencl_kernel(be, prog, "px_grid_sort_cells", &sort));
  px_opencl_args_begin(&a, be, scatter);
  px_opencl_args_u32(&a, "n", n);
  px_opencl_args_mem(&a, "cell", g->cell);
  px_opencl_args_mem(&a, "slot", s->slot);
  px_opencl_args_mem(&a, "start", g->start);
  px_opencl_args_mem(&a, "perm", g->perm);
  PX_TRY(px_opencl_args_launch(&a, g->n, 0));
  px_opencl_args_begin(&a, be, sort);
  px_opencl_args_u32(&a, "ncells", ncells);
  px_opencl_args_mem(&a, "start", g->start);
  px_opencl_args_mem(&a, "end", g->end);
  px_opencl_args_mem(&a, "perm", g->perm);
  return px_opencl_args_launch(&a, g->ncells, 0);
}

static enum px_status px_grid_cl_build(struct px_grid *g, enum px_precision precision,
                                       struct px_buffer *x, struct px_buffer *y,
                                       struct px_buffer *z) {
  struct px_grid_cl *s;
  cl_program prog;
  cl_uint crowded = 0;
  PX_TRY(px_grid_cl_impl(g, &s));
  PX_TRY(px_opencl_program_real(g->be, "grid", px_cl_source_grid, precision, "", &prog));
  PX_TRY(px_grid_cl_cells(g, prog, x, y, z));
  PX_TRY(px_grid_cl_ranges(g, prog, s));
  /* one scalar to the host per build: which sort */
  PX_TRY(px_buffer_read(s->crowded, 0, sizeof crowded, &crowded));
  px_log(g->be->ctx, PX_LOG_LEVEL_TRACE, "grid build: %zu particles in %zu cells: %s", g->n,
         g->ncells, crowded ? "radix sort (crowded cells)" : "scatter + per-cell sort");
  return crowded ? px_grid_cl_sort(g, prog) : px_grid_cl_scatter_sort(g, prog, s);
}

static enum px_status px_grid_cl_reorder(struct px_grid *g, size_t elem_size, struct px_buffer *src,
                                         struct px_buffer *dst) {
  struct px_backend *be = g->be;
  const cl_uint n = (cl_uint)g->n;
  const char *name;
  struct px_opencl_args a;
  cl_program prog;
  cl_kernel k;
  switch (elem_size) {
    case 1: name = "px_gather_u8"; break;
    case 2: name = "px_gather_u16"; break;
    case 4: name = "px_gather_u32"; break;
    case 8: name = "px_gather_u64"; break;
    default:
      return px_context_fail(be->ctx, PX_STATUS_UNSUPPORTED,
                             "px_grid_reorder: %zu-byte elements are not supported on opencl",
                             elem_size);
  }
  /* The gathers do not depend on PX_REAL; the float build always exists. */
  PX_TRY(px_opencl_program_real(be, "grid", px_cl_source_grid, PX_PRECISION_SINGLE, "", &prog));
  PX_TRY(px_opencl_kernel(be, prog, name, &k));
  px_opencl_args_begin(&a, be, k);
  px_opencl_args_u32(&a, "n", n);
  px_opencl_args_mem(&a, "perm", g->perm);
  px_opencl_args_mem(&a, "src", src);
  px_opencl_args_mem(&a, "dst", dst);
  return px_opencl_args_launch(&a, g->n, 0);
}

static enum px_status px_grid_cl_count(struct px_grid *g, enum px_precision precision,
                                       struct px_buffer *x, struct px_buffer *y,
                                       struct px_buffer *z, double range, struct px_buffer *out) {
  struct px_backend *be = g->be;
  const int d3 = g->dims == 3;
  struct px_opencl_args a;
  cl_program prog;
  cl_kernel k;
  PX_TRY(px_opencl_program_real(be, "grid", px_cl_source_grid, precision, "", &prog));
  PX_TRY(px_opencl_kernel(be, prog, d3 ? "px_grid_neighbours_3d" : "px_grid_neighbours_2d", &k));
  px_opencl_args_begin(&a, be, k);
  px_opencl_args_u32(&a, "n", (uint32_t)g->n);
  px_opencl_args_real(&a, "range2", range * range); /* [m^2] */
  px_opencl_args_mem(&a, "x", x);
  px_opencl_args_mem(&a, "y", y);
  if (d3) px_opencl_args_mem(&a, "z", z);
  px_opencl_args_mem(&a, "cell", g->cell);
  px_opencl_args_mem(&a, "perm", g->perm);
  px_opencl_args_mem(&a, "start", g->start);
  px_opencl_args_mem(&a, "end", g->end);
  px_opencl_args_i32(&a, "nx", g->cells[0]);
  px_opencl_args_i32(&a, "ny", g->cells[1]);
  if (d3) px_opencl_args_i32(&a, "nz", g->cells[2]);
  px_opencl_args_mem(&a, "out", out);
  return px_opencl_args_launch(&a, g->n, 0);
}

const struct px_grid_ops px_grid_ops_opencl = {
    .backend = "opencl",
    .build = px_grid_cl_build,
    .reorder = px_grid_cl_reorder,
    .count_neighbours = px_grid_cl_count,
    .release = px_grid_cl_release,
};
