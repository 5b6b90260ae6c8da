/* Conformance suite: every shared compute operation on the backend named by
 * argv[1] ("cpu" or "opencl"), compared with plain double references on the
 * host. Tolerances (and why):
 *   buffers, grid (cells, permutation, start/end, reorder, pair sets):
 *     exact. Integer results of a deterministic algorithm; cell coordinates
 *     use only correctly rounded operations (subtract, multiply, floor).
 *   lincomb: cpu bitwise equal to the same loop on the host (same operations
 *     in the same order, no contraction); opencl within 4 ulp of the result
 *     scale (the OpenCL compiler may fuse a*b+c).
 *   neighbour counts: exact except for pairs whose squared distance is
 *     within a relative 1e-5 (single) / 1e-12 (double) of range², where
 *     rounding may decide either way: lower <= count <= upper.
 *   direct sum, relative L2 error against the double reference computed
 *     from the same (rounded) inputs: double <= 1e-12; single <= 1e-5, the
 *     brief's figure: each term carries ~1e-7 relative rounding and sums of
 *     10^3 terms with cancellation lose one to two more digits (measured
 *     ~1e-7..1e-6, see the log). */
#include <math.h>
#include <stdint.h>

#include "compute/backend_impl.h"
#include "compute_test.h"
#ifdef PX_HAVE_OPENCL
#include "compute/opencl/opencl_impl.h"
#endif

static const char *g_backend = "cpu";

/* Which OpenCL grid-sort paths ran (from the trace log). */
static int g_radix_builds = 0, g_scatter_builds = 0;

static void trace_log(void *user, enum px_log_level level, const char *message) {
  (void)user;
  if (strstr(message, "grid build:")) {
    g_radix_builds += strstr(message, "radix sort") != NULL;
    g_scatter_builds += strstr(message, "scatter + per-cell sort") != NULL;
  } else if (level <= PX_LOG_LEVEL_WARN) {
    fprintf(stderr, "%s: %s\n", px_log_level_name(level), message);
  }
}

/* ------------------------------------------------------------------------ */
/* buffers                                                                   */

static void test_buffers(struct px_context *ctx, struct px_backend *be) {
  unsigned char pattern[1000], back[1000];
  struct px_buffer *a = NULL, *b = NULL, *empty = NULL;
  size_t i;
  for (i = 0; i < sizeof pattern; ++i) pattern[i] = (unsigned char)(i * 7 + 3);

  PX_CHECK_OK(ctx, px_buffer_create(be, "test a", 1000, &a));
  PX_CHECK_OK(ctx, px_buffer_create(be, "test b", 1000, &b));
  PX_CHECK(px_buffer_bytes(a) == 1000);
  PX_CHECK(strcmp(px_buffer_label(a), "test a") == 0);
  PX_CHECK(px_buffer_backend(a) == be);
  PX_CHECK((px_buffer_host(a) != NULL) == (px_backend_host_memory(be) != 0));

  /* write / read round trip, whole and partial */
  PX_CHECK_OK(ctx, px_buffer_write(a, 0, 1000, pattern));
  memset(back, 0, sizeof back);
  PX_CHECK_OK(ctx, px_buffer_read(a, 0, 1000, back));
  PX_CHECK(memcmp(back, pattern, 1000) == 0);
  PX_CHECK_OK(ctx, px_buffer_write(a, 100, 50, pattern + 500));
  PX_CHECK_OK(ctx, px_buffer_read(a, 90, 70, back));
  PX_CHECK(memcmp(back, pattern + 90, 10) == 0);
  PX_CHECK(memcmp(back + 10, pattern + 500, 50) == 0);
  PX_CHECK(memcmp(back + 60, pattern + 150, 10) == 0);

  /* device copy with offsets */
  PX_CHECK_OK(ctx, px_buffer_write(a, 0, 1000, pattern));
  PX_CHECK_OK(ctx, px_buffer_zero(b));
  PX_CHECK_OK(ctx, px_buffer_copy(b, 10, a, 200, 300));
  PX_CHECK_OK(ctx, px_buffer_read(b, 0, 1000, back));
  for (i = 0; i < 1000; ++i) {
    const unsigned char want = i >= 10 && i < 310 ? pattern[i - 10 + 200] : 0;
    if (back[i] != want) {
      PX_CHECK_MSG(back[i] == want, "byte %zu after copy", i);
      break;
    }
  }
  /* copy within one buffer, disjoint ranges */
  PX_CHECK_OK(ctx, px_buffer_copy(a, 600, a, 0, 100));
  PX_CHECK_OK(ctx, px_buffer_read(a, 600, 100, back));
  PX_CHECK(memcmp(back, pattern, 100) == 0);

  /* zero */
  PX_CHECK_OK(ctx, px_buffer_zero(a));
  PX_CHECK_OK(ctx, px_buffer_read(a, 0, 1000, back));
  for (i = 0; i < 1000 && back[i] == 0; ++i) {
  }
  PX_CHECK_MSG(i == 1000, "zeroed buffer has a non-zero byte at %zu", i);

  /* resize keeps the content: grow within and beyond capacity, shrink */
  PX_CHECK_OK(ctx, px_buffer_write(a, 0, 1000, pattern));
  PX_CHECK_OK(ctx, px_buffer_resize(a, 400));
  PX_CHECK(px_buffer_bytes(a) == 400);
  PX_CHECK_OK(ctx, px_buffer_resize(a, 1000));
  PX_CHECK_OK(ctx, px_buffer_read(a, 0, 400, back));
  PX_CHECK(memcmp(back, pattern, 400) == 0);
  PX_CHECK_OK(ctx, px_buffer_resize(a, 5000));
  PX_CHECK(px_buffer_bytes(a) == 5000);
  PX_CHECK_OK(ctx, px_buffer_read(a, 0, 1000, back));
  PX_CHECK(memcmp(back, pattern, 1000) == 0);
  PX_CHECK_OK(ctx, px_buffer_write(a, 4000, 1000, pattern));
  PX_CHECK_OK(ctx, px_buffer_read(a, 4000, 1000, back));
  PX_CHECK(memcmp(back, pattern, 1000) == 0);

  /* empty buffers */
  PX_CHECK_OK(ctx, px_buffer_create(be, "test empty", 0, &empty));
  PX_CHECK(px_buffer_bytes(empty) == 0);
  PX_CHECK_OK(ctx, px_buffer_write(empty, 0, 0, NULL));
  PX_CHECK_OK(ctx, px_buffer_read(empty, 0, 0, NULL));
  PX_CHECK_OK(ctx, px_buffer_zero(empty));
  PX_CHECK_OK(ctx, px_buffer_resize(empty, 16));
  PX_CHECK_OK(ctx, px_buffer_write(empty, 0, 16, pattern));
  PX_CHECK_OK(ctx, px_buffer_read(empty, 0, 16, back));
  PX_CHECK(memcmp(back, pattern, 16) == 0);

  /* misuse fails with INVALID and a message, and changes nothing */
  PX_CHECK_STATUS(ctx, px_buffer_write(b, 990, 20, pattern), PX_STATUS_INVALID);
  PX_CHECK(strstr(px_context_message(ctx), "outside buffer 'test b'") != NULL);
  PX_CHECK_STATUS(ctx, px_buffer_read(b, 1001, 0, back), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_buffer_read(b, (size_t)-1, 2, back), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_buffer_read(b, 0, 10, NULL), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_buffer_write(b, 0, 10, NULL), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_buffer_copy(b, 0, b, 10, 100), PX_STATUS_INVALID);
  PX_CHECK(strstr(px_context_message(ctx), "overlap") != NULL);
  PX_CHECK_STATUS(ctx, px_buffer_copy(b, 900, a, 0, 200), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_buffer_copy(NULL, 0, a, 0, 1), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_buffer_write(NULL, 0, 1, pattern), PX_STATUS_INVALID);
  if (strcmp(g_backend, "cpu") != 0) {
    struct px_backend *cpu = px_test_backend(ctx, "cpu", 1);
    struct px_buffer *c = NULL;
    PX_CHECK_OK(ctx, px_buffer_create(cpu, "test cpu", 100, &c));
    PX_CHECK_STATUS(ctx, px_buffer_copy(c, 0, a, 0, 10), PX_STATUS_INVALID);
    PX_CHECK(strstr(px_context_message(ctx), "different backends") != NULL);
    px_buffer_free(c);
    px_backend_free(cpu);
  }
  px_buffer_free(a);
  px_buffer_free(b);
  px_buffer_free(empty);
  px_buffer_free(NULL);
}

/* ------------------------------------------------------------------------ */
/* lincomb                                                                   */

static void test_lincomb_type(struct px_context *ctx, struct px_backend *be, enum px_dtype type) {
  enum { N = 1037 };
  const enum px_precision p = type == PX_DTYPE_F64 ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
  const int exact = px_backend_host_memory(be);
  const double ulp = type == PX_DTYPE_F64 ? 0x1p-52 : 0x1p-23;
  static double x[PX_LINCOMB_MAX][N], got[N];
  struct px_buffer *in[PX_LINCOMB_MAX], *out = NULL;
  double c[PX_LINCOMB_MAX];
  uint64_t rng[PX_RNG_WORDS];
  int k, nterms;
  size_t i;
  px_rng_seed(rng, 11);
  for (k = 0; k < PX_LINCOMB_MAX; ++k) {
    for (i = 0; i < N; ++i) x[k][i] = px_test_uniform(rng, -2.0, 2.0);
    px_test_round(p, N, x[k]);
    c[k] = px_test_uniform(rng, -1.5, 1.5);
    if (p == PX_PRECISION_SINGLE) c[k] = (double)(float)c[k];
    in[k] = px_test_upload(ctx, be, "lincomb in", p, N, x[k]);
  }
  out = px_test_upload(ctx, be, "lincomb out", p, N, x[0]);
  for (nterms = 1; nterms <= PX_LINCOMB_MAX; ++nterms) {
    double worst = 0.0;
    int mismatches = 0;
    PX_CHECK_OK(ctx, px_buffer_lincomb(out, type, N, nterms, c, in));
    px_test_download(ctx, out, p, N, got);
    for (i = 0; i < N; ++i) {
      /* the host loop in the element type, terms in order */
      double want, scale = 0.0;
      if (type == PX_DTYPE_F64) {
        double s = c[0] * x[0][i];
        for (k = 1; k < nterms; ++k) s = s + c[k] * x[k][i];
        want = s;
      } else {
        float s = (float)c[0] * (float)x[0][i];
        for (k = 1; k < nterms; ++k) s = s + (float)c[k] * (float)x[k][i];
        want = (double)s;
      }
      for (k = 0; k < nterms; ++k) scale += fabs(c[k] * x[k][i]);
      if (exact ? got[i] != want : fabs(got[i] - want) > 4.0 * ulp * scale) ++mismatches;
      if (scale > 0 && fabs(got[i] - want) / scale > worst) worst = fabs(got[i] - want) / scale;
    }
    PX_CHECK_MSG(mismatches == 0,
                 "lincomb %s with %d terms: %d of %d elements differ "
                 "(worst %.3g relative to the term scale)",
                 px_dtype_name(type), nterms, mismatches, N, worst);
  }
  /* out aliasing an input: y = 0.5 y + 2 x1 */
  {
    struct px_buffer *alias[2];
    double c2[2] = {0.5, 2.0};
    alias[0] = in[0];
    alias[1] = in[1];
    PX_CHECK_OK(ctx, px_buffer_lincomb(in[0], type, N, 2, c2, alias));
    px_test_download(ctx, in[0], p, N, got);
    for (i = 0, k = 0; i < N; ++i)
      if (fabs(got[i] - (0.5 * x[0][i] + 2.0 * x[1][i])) > 4.0 * ulp * (fabs(x[0][i]) + 4.0)) ++k;
    PX_CHECK_MSG(k == 0, "aliased lincomb: %d elements wrong", k);
  }
  /* misuse */
  PX_CHECK_STATUS(ctx, px_buffer_lincomb(out, type, N, 0, c, in), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_buffer_lincomb(out, type, N, PX_LINCOMB_MAX + 1, c, in),
                  PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_buffer_lincomb(out, type, N + 1, 2, c, in), PX_STATUS_INVALID);
  PX_CHECK(strstr(px_context_message(ctx), "holds") != NULL);
  PX_CHECK_STATUS(ctx, px_buffer_lincomb(out, PX_DTYPE_U32, N, 2, c, in), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_buffer_lincomb(out, type, N, 2, NULL, in), PX_STATUS_INVALID);
  {
    struct px_buffer *bad[2];
    bad[0] = in[0];
    bad[1] = NULL;
    PX_CHECK_STATUS(ctx, px_buffer_lincomb(out, type, N, 2, c, bad), PX_STATUS_INVALID);
  }
  PX_CHECK_OK(ctx, px_buffer_lincomb(out, type, 0, 2, c, in));
  for (k = 0; k < PX_LINCOMB_MAX; ++k) px_buffer_free(in[k]);
  px_buffer_free(out);
}

/* ------------------------------------------------------------------------ */
/* neighbour grid                                                            */

static int ref_axis_f32(float x, float o, float inv_h, int n) {
  const float s = floorf((x - o) * inv_h);
  if (!(s >= 0.0f)) return 0;
  if (s >= (float)n) return n - 1;
  return (int)s;
}

static int ref_axis_f64(double x, double o, double inv_h, int n) {
  const double s = floor((x - o) * inv_h);
  if (!(s >= 0.0)) return 0;
  if (s >= (double)n) return n - 1;
  return (int)s;
}

/* Cell by the definition (in the precision's arithmetic) and the stable
 * counting sort by the book. */
static void ref_grid(enum px_precision p, int dims, size_t n, const double *const *r,
                     const double *origin, double h, const size_t *cells, uint32_t *cell,
                     uint32_t *perm, uint32_t *start, uint32_t *end) {
  size_t ncells = 1, i, c;
  int a;
  uint32_t *fill;
  for (a = 0; a < dims; ++a) ncells *= cells[a];
  for (i = 0; i < n; ++i) {
    size_t idx = 0;
    for (a = dims - 1; a >= 0; --a) {
      const int ca =
          p == PX_PRECISION_SINGLE
              ? ref_axis_f32((float)r[a][i], (float)origin[a], (float)(1.0 / h), (int)cells[a])
              : ref_axis_f64(r[a][i], origin[a], 1.0 / h, (int)cells[a]);
      idx = idx * cells[a] + (size_t)ca;
    }
    cell[i] = (uint32_t)idx;
  }
  memset(start, 0, ncells * sizeof *start);
  for (i = 0; i < n; ++i) ++start[cell[i]];
  {
    uint32_t sum = 0;
    for (c = 0; c < ncells; ++c) {
      const uint32_t k = start[c];
      start[c] = sum;
      sum += k;
      end[c] = sum;
    }
  }
  fill = malloc(ncells * sizeof *fill);
  memcpy(fill, start, ncells * sizeof *fill);
  for (i = 0; i < n; ++i) perm[fill[cell[i]]++] = (uint32_t)i;
  free(fill);
}

static int cmp_u64(const void *a, const void *b) {
  const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return x < y ? -1 : x > y;
}

/* Pairs i < j closer than range, enumerated through the grid's arrays
 * (3^dims cells around each particle), sorted lexicographically. */
static size_t grid_pairs(int dims, size_t n, const double *const *r, const size_t *cells,
                         const uint32_t *cell, const uint32_t *perm, const uint32_t *start,
                         const uint32_t *end, double range, uint64_t **out) {
  size_t cap = 1024, count = 0, i;
  uint64_t *list = malloc(cap * sizeof *list);
  const int nx = (int)cells[0], ny = (int)cells[1], nz = dims == 3 ? (int)cells[2] : 1;
  for (i = 0; i < n; ++i) {
    const int c = (int)cell[i], cx = c % nx, cy = (c / nx) % ny, cz = c / (nx * ny);
    int ix, iy, iz;
    for (iz = cz - 1; iz <= cz + 1; ++iz)
      for (iy = cy - 1; iy <= cy + 1; ++iy)
        for (ix = cx - 1; ix <= cx + 1; ++ix) {
          uint32_t k;
          int c2;
          if (ix < 0 || iy < 0 || iz < 0 || ix >= nx || iy >= ny || iz >= nz) continue;
          c2 = (iz * ny + iy) * nx + ix;
          for (k = start[c2]; k < end[c2]; ++k) {
            const size_t j = perm[k];
            double d2 = 0.0;
            int a;
            if (j <= i) continue;
            for (a = 0; a < dims; ++a) d2 += (r[a][j] - r[a][i]) * (r[a][j] - r[a][i]);
            if (d2 < range * range) {
              if (count == cap) list = realloc(list, (cap *= 2) * sizeof *list);
              list[count++] = ((uint64_t)i << 32) | (uint64_t)j;
            }
          }
        }
  }
  qsort(list, count, sizeof *list, cmp_u64);
  *out = list;
  return count;
}

struct grid_case {
  enum px_precision p;
  int dims;
  size_t n;
  double h;
  size_t cells[3];
  double origin[3];
  int check_pairs;
  int reshape; /* 1: the grid starts as one cell elsewhere and is reshaped to
                  this one; 2: it starts with twice the cells per axis */
  const char *name;
};

/* Build on `be` and compare everything with the references. */
static void check_grid(struct px_context *ctx, struct px_backend *be, const struct grid_case *gc,
                       const double *const *r) {
  const size_t n = gc->n;
  const int dims = gc->dims;
  struct px_buffer *pos[3] = {NULL, NULL, NULL}, *counts = NULL, *dst = NULL;
  struct px_grid *g = NULL;
  size_t ncells = 1, i, bad;
  uint32_t *cell, *perm, *start, *end, *rcell, *rperm, *rstart, *rend;
  int a;
  for (a = 0; a < dims; ++a) ncells *= gc->cells[a];
  for (a = 0; a < dims; ++a) pos[a] = px_test_upload(ctx, be, "grid pos", gc->p, n, r[a]);
  if (gc->reshape) {
    /* another shape first, built with the same points, then reshaped: the
     * checks below see what a fresh grid of this shape would give */
    const double o[3] = {gc->origin[0] - 3.0, gc->origin[1] + 1.0, gc->origin[2] - 0.5};
    size_t c[3] = {1, 1, 1};
    for (a = 0; a < dims && gc->reshape == 2; ++a) c[a] = 2 * gc->cells[a];
    PX_CHECK_OK(ctx, px_grid_create(be, dims, o, 2.5 * gc->h, c, &g));
    if (!g) return;
    PX_CHECK_OK(ctx, px_grid_build(g, gc->p, n, pos[0], pos[1], pos[2]));
    /* a refused shape changes nothing */
    PX_CHECK_STATUS(ctx, px_grid_reshape(g, gc->origin, 0.0, gc->cells), PX_STATUS_INVALID);
    PX_CHECK(px_grid_cell_size(g) == 2.5 * gc->h && px_grid_particle_count(g) == n);
    PX_CHECK_OK(ctx, px_grid_reshape(g, gc->origin, gc->h, gc->cells));
    PX_CHECK(px_grid_particle_count(g) == 0 && px_grid_cell_size(g) == gc->h);
  } else {
    PX_CHECK_OK(ctx, px_grid_create(be, dims, gc->origin, gc->h, gc->cells, &g));
  }
  if (!g) return;
  PX_CHECK(px_grid_cell_count(g) == ncells);
  PX_CHECK_OK(ctx, px_grid_build(g, gc->p, n, pos[0], pos[1], pos[2]));
  PX_CHECK(px_grid_particle_count(g) == n);
  cell = malloc((n + 1) * 4);
  perm = malloc((n + 1) * 4);
  rcell = malloc((n + 1) * 4);
  rperm = malloc((n + 1) * 4);
  start = malloc(ncells * 4);
  end = malloc(ncells * 4);
  rstart = malloc(ncells * 4);
  rend = malloc(ncells * 4);
  PX_CHECK_OK(ctx, px_buffer_read(px_grid_cells(g), 0, n * 4, cell));
  PX_CHECK_OK(ctx, px_buffer_read(px_grid_permutation(g), 0, n * 4, perm));
  PX_CHECK_OK(ctx, px_buffer_read(px_grid_cell_start(g), 0, ncells * 4, start));
  PX_CHECK_OK(ctx, px_buffer_read(px_grid_cell_end(g), 0, ncells * 4, end));
  ref_grid(gc->p, dims, n, r, gc->origin, gc->h, gc->cells, rcell, rperm, rstart, rend);
  for (i = 0, bad = 0; i < n; ++i) bad += cell[i] != rcell[i];
  PX_CHECK_MSG(bad == 0, "%s [%s, %s]: %zu of %zu cell indices differ from the definition",
               gc->name, px_backend_name(be), px_precision_name(gc->p), bad, n);
  for (i = 0, bad = 0; i < n; ++i) bad += perm[i] != rperm[i];
  PX_CHECK_MSG(bad == 0,
               "%s [%s, %s]: %zu of %zu permutation entries differ from the stable "
               "counting sort",
               gc->name, px_backend_name(be), px_precision_name(gc->p), bad, n);
  for (i = 0, bad = 0; i < ncells; ++i) bad += start[i] != rstart[i] || end[i] != rend[i];
  PX_CHECK_MSG(bad == 0, "%s [%s, %s]: %zu of %zu cell ranges differ", gc->name,
               px_backend_name(be), px_precision_name(gc->p), bad, ncells);

  if (gc->check_pairs) {
    /* pair sets: through the grid == brute force (double distances of the
     * stored values in both) */
    const double range = 0.999 * gc->h;
    const double band = gc->p == PX_PRECISION_SINGLE ? 1e-5 : 1e-12;
    uint64_t *gp = NULL;
    uint32_t *bp = NULL, *cnt = malloc((n + 1) * 4);
    size_t ng = grid_pairs(dims, n, r, gc->cells, cell, perm, start, end, range, &gp), nb = 0;
    PX_CHECK_OK(ctx, px_neighbors_pairs_reference(ctx, dims, n, r[0], r[1], dims == 3 ? r[2] : NULL,
                                                  range, &bp, &nb));
    PX_CHECK_MSG(ng == nb, "%s: %zu pairs via the grid, %zu by brute force", gc->name, ng, nb);
    for (i = 0, bad = 0; i < ng && i < nb; ++i)
      bad += gp[i] != (((uint64_t)bp[2 * i] << 32) | (uint64_t)bp[2 * i + 1]);
    PX_CHECK_MSG(bad == 0, "%s: %zu pairs differ between grid and brute force", gc->name, bad);
    PX_CHECK(nb > 0);
    /* neighbour counts on the device, against brute-force bounds */
    PX_CHECK_OK(ctx, px_buffer_create(be, "neighbour counts", n * 4, &counts));
    PX_CHECK_OK(ctx, px_grid_count_neighbours(g, gc->p, pos[0], pos[1], pos[2], range, counts));
    PX_CHECK_OK(ctx, px_buffer_read(counts, 0, n * 4, cnt));
    for (i = 0, bad = 0; i < n; ++i) {
      size_t j, lo = 0, hi = 0;
      for (j = 0; j < n; ++j) {
        double d2 = 0.0;
        if (j == i) continue;
        for (a = 0; a < dims; ++a) d2 += (r[a][j] - r[a][i]) * (r[a][j] - r[a][i]);
        lo += d2 < range * range * (1.0 - band);
        hi += d2 < range * range * (1.0 + band);
      }
      bad += cnt[i] < lo || cnt[i] > hi;
    }
    PX_CHECK_MSG(bad == 0, "%s [%s, %s]: %zu neighbour counts outside the brute-force bounds",
                 gc->name, px_backend_name(be), px_precision_name(gc->p), bad);
    free(gp);
    px_mem_free(ctx, bp);
    free(cnt);
    px_buffer_free(counts);
  }

  /* reorder: 4-, 8- and 1-byte elements */
  {
    const enum px_dtype t = gc->p == PX_PRECISION_SINGLE ? PX_DTYPE_F32 : PX_DTYPE_F64;
    double *got = malloc((n + 1) * sizeof *got);
    unsigned char *b8 = malloc(n + 1), *g8 = malloc(n + 1);
    struct px_buffer *s8 = NULL, *d8 = NULL;
    dst = px_test_upload(ctx, be, "reorder dst", gc->p, n, r[0]);
    PX_CHECK_OK(ctx, px_grid_reorder(g, t, pos[0], dst));
    px_test_download(ctx, dst, gc->p, n, got);
    for (i = 0, bad = 0; i < n; ++i) bad += got[i] != r[0][perm[i]];
    PX_CHECK_MSG(bad == 0, "%s: reorder of %s: %zu elements wrong", gc->name, px_dtype_name(t),
                 bad);
    for (i = 0; i < n; ++i) b8[i] = (unsigned char)(i * 13);
    PX_CHECK_OK(ctx, px_buffer_create(be, "reorder u8", n + 1, &s8));
    PX_CHECK_OK(ctx, px_buffer_create(be, "reorder u8", n + 1, &d8));
    PX_CHECK_OK(ctx, px_buffer_write(s8, 0, n, b8));
    PX_CHECK_OK(ctx, px_grid_reorder(g, PX_DTYPE_U8, s8, d8));
    PX_CHECK_OK(ctx, px_buffer_read(d8, 0, n, g8));
    for (i = 0, bad = 0; i < n; ++i) bad += g8[i] != b8[perm[i]];
    PX_CHECK_MSG(bad == 0, "%s: reorder of u8: %zu elements wrong", gc->name, bad);
    PX_CHECK_STATUS(ctx, px_grid_reorder(g, t, pos[0], pos[0]), PX_STATUS_INVALID);
    px_buffer_free(s8);
    px_buffer_free(d8);
    px_buffer_free(dst);
    free(got);
    free(b8);
    free(g8);
  }
  free(cell);
  free(perm);
  free(rcell);
  free(rperm);
  free(start);
  free(end);
  free(rstart);
  free(rend);
  px_grid_free(g);
  for (a = 0; a < dims; ++a) px_buffer_free(pos[a]);
}

enum { DIST_UNIFORM, DIST_CLUSTERED, DIST_OUTSIDE };

/* Points in the unit square/cube: uniform; 80% in five tight clusters (many
 * per cell) + 20% uniform; or 30% outside the grid, up to half a domain away. */
static void make_points(int dist, int dims, size_t n, uint64_t seed, double **r) {
  uint64_t rng[PX_RNG_WORDS];
  double centre[5][3];
  size_t i;
  int a, k;
  px_rng_seed(rng, seed);
  for (k = 0; k < 5; ++k)
    for (a = 0; a < 3; ++a) centre[k][a] = px_test_uniform(rng, 0.1, 0.9);
  for (i = 0; i < n; ++i) {
    const double u = px_rng_uniform(rng);
    for (a = 0; a < dims; ++a) {
      if (dist == DIST_CLUSTERED && u < 0.8)
        r[a][i] = centre[i % 5][a] + 0.01 * px_rng_normal(rng);
      else if (dist == DIST_OUTSIDE && u < 0.3)
        r[a][i] = px_test_uniform(rng, -0.5, 1.5);
      else
        r[a][i] = px_rng_uniform(rng);
    }
  }
}

static void test_grid(struct px_context *ctx, struct px_backend *be) {
  static const char *const dist_names[3] = {"uniform", "clustered", "outside"};
  double *r[3];
  size_t nmax = 40000, i;
  int a, dims, dist, pi;
  for (a = 0; a < 3; ++a) r[a] = malloc(nmax * sizeof(double));

  for (pi = 0; pi < 2; ++pi) {
    const enum px_precision p = pi ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
    for (dims = 2; dims <= 3; ++dims)
      for (dist = 0; dist < 3; ++dist) {
        char name[64];
        struct grid_case gc;
        memset(&gc, 0, sizeof gc);
        snprintf(name, sizeof name, "%dD %s", dims, dist_names[dist]);
        gc.p = p;
        gc.dims = dims;
        gc.n = dims == 2 ? 3000 : 2500;
        gc.h = dims == 2 ? 0.05 : 0.1;
        for (a = 0; a < dims; ++a) gc.cells[a] = dims == 2 ? 20 : 10;
        gc.check_pairs = 1;
        gc.name = name;
        make_points(dist, dims, gc.n, (uint64_t)(100 + 10 * dims + dist), r);
        for (a = 0; a < dims; ++a) px_test_round(p, gc.n, r[a]);
        check_grid(ctx, be, &gc, (const double *const *)r);
        /* the same shape reached by px_grid_reshape from a smaller and a
         * larger grid */
        gc.reshape = 1 + dist % 2;
        check_grid(ctx, be, &gc, (const double *const *)r);
      }
  }

  /* shapes: one cell (no radix pass on opencl), a million cells (5 passes,
   * multi-level scans), a shifted origin, and 40000 particles (the cpu sort
   * then uses two threads when it has them) */
  {
    struct grid_case gc;
    memset(&gc, 0, sizeof gc);
    gc.p = PX_PRECISION_SINGLE;
    gc.dims = 2;
    gc.n = 2000;
    gc.h = 2.0;
    gc.cells[0] = gc.cells[1] = 1;
    gc.check_pairs = 0;
    gc.name = "one cell";
    make_points(DIST_UNIFORM, 2, gc.n, 7, r);
    px_test_round(gc.p, gc.n, r[0]);
    px_test_round(gc.p, gc.n, r[1]);
    check_grid(ctx, be, &gc, (const double *const *)r);

    gc.p = PX_PRECISION_DOUBLE;
    gc.n = 5000;
    gc.h = 0.001;
    gc.cells[0] = gc.cells[1] = 1000;
    gc.origin[0] = -0.0005;
    gc.origin[1] = 0.0;
    gc.check_pairs = 1;
    gc.name = "million cells, crowded edges";
    make_points(DIST_OUTSIDE, 2, gc.n, 8, r);
    check_grid(ctx, be, &gc, (const double *const *)r);
    gc.name = "million cells, sparse";
    make_points(DIST_UNIFORM, 2, gc.n, 18, r);
    check_grid(ctx, be, &gc, (const double *const *)r);
    gc.name = "million cells, reshaped from one";
    gc.reshape = 1;
    check_grid(ctx, be, &gc, (const double *const *)r);
    gc.reshape = 0;

    gc.p = PX_PRECISION_SINGLE;
    gc.dims = 3;
    gc.n = 40000;
    gc.h = 0.05;
    gc.cells[0] = gc.cells[1] = gc.cells[2] = 20;
    gc.origin[0] = gc.origin[1] = gc.origin[2] = 0.0;
    gc.check_pairs = 0;
    gc.name = "40000 points";
    make_points(DIST_OUTSIDE, 3, gc.n, 9, r);
    for (a = 0; a < 3; ++a) px_test_round(gc.p, gc.n, r[a]);
    check_grid(ctx, be, &gc, (const double *const *)r);
    if (px_backend_host_memory(be)) {
      /* the same on one thread (this backend has px_backend_threads) */
      struct px_backend *one = px_test_backend(ctx, "cpu", 1);
      struct px_backend *two = px_test_backend(ctx, "cpu", 2);
      check_grid(ctx, one, &gc, (const double *const *)r);
      check_grid(ctx, two, &gc, (const double *const *)r);
      px_backend_free(one);
      px_backend_free(two);
    } else {
      /* a different work-group setting changes nothing */
      PX_CHECK_OK(ctx, px_backend_set_workgroup(be, 64));
      check_grid(ctx, be, &gc, (const double *const *)r);
      PX_CHECK_OK(ctx, px_backend_set_workgroup(be, 0));
    }
  }

  /* empty build, and misuse */
  {
    const double origin[3] = {0, 0, 0};
    const size_t cells[3] = {4, 4, 4};
    struct px_grid *g = NULL;
    struct px_buffer *x = NULL, *y = NULL, *out = NULL;
    uint32_t se[32];
    PX_CHECK_OK(ctx, px_grid_create(be, 2, origin, 0.25, cells, &g));
    PX_CHECK_OK(ctx, px_buffer_create(be, "x", 40, &x));
    PX_CHECK_OK(ctx, px_buffer_create(be, "y", 40, &y));
    PX_CHECK_OK(ctx, px_buffer_create(be, "out", 40, &out));
    PX_CHECK_OK(ctx, px_grid_build(g, PX_PRECISION_SINGLE, 0, x, y, NULL));
    PX_CHECK(px_grid_particle_count(g) == 0);
    PX_CHECK_OK(ctx, px_buffer_read(px_grid_cell_start(g), 0, 64, se));
    PX_CHECK_OK(ctx, px_buffer_read(px_grid_cell_end(g), 0, 64, se + 16));
    for (i = 0; i < 32 && se[i] == 0; ++i) {
    }
    PX_CHECK_MSG(i == 32, "empty grid has a non-empty cell range");
    PX_CHECK_STATUS(ctx, px_grid_build(g, PX_PRECISION_SINGLE, 11, x, y, NULL), PX_STATUS_INVALID);
    PX_CHECK(strstr(px_context_message(ctx), "holds 40 bytes") != NULL);
    PX_CHECK_STATUS(ctx, px_grid_build(g, PX_PRECISION_DOUBLE, 10, x, y, NULL), PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx, px_grid_build(g, PX_PRECISION_SINGLE, 10, NULL, y, NULL),
                    PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx, px_grid_build(g, PX_PRECISION_SINGLE, 10, x, y, x), PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx, px_grid_build(g, PX_PRECISION_MIXED, 10, x, y, NULL), PX_STATUS_INVALID);
    PX_CHECK_OK(ctx, px_grid_build(g, PX_PRECISION_SINGLE, 10, x, y, NULL));
    PX_CHECK_STATUS(ctx, px_grid_count_neighbours(g, PX_PRECISION_SINGLE, x, y, NULL, 0.3, out),
                    PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx, px_grid_count_neighbours(g, PX_PRECISION_SINGLE, x, y, NULL, 0.0, out),
                    PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx, px_grid_reorder(g, (enum px_dtype)99, x, out), PX_STATUS_INVALID);
    px_grid_free(g);
    g = NULL;
    PX_CHECK_STATUS(ctx, px_grid_create(be, 4, origin, 0.25, cells, &g), PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx, px_grid_create(be, 2, origin, 0.0, cells, &g), PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx, px_grid_create(be, 2, origin, NAN, cells, &g), PX_STATUS_INVALID);
    {
      const size_t zero[2] = {4, 0}, huge[3] = {100000, 100000, 1};
      PX_CHECK_STATUS(ctx, px_grid_create(be, 2, origin, 0.25, zero, &g), PX_STATUS_INVALID);
      PX_CHECK_STATUS(ctx, px_grid_create(be, 2, origin, 0.25, huge, &g), PX_STATUS_INVALID);
      PX_CHECK(strstr(px_context_message(ctx), "2^31") != NULL);
    }
    PX_CHECK(g == NULL);
    px_buffer_free(x);
    px_buffer_free(y);
    px_buffer_free(out);
  }
  for (a = 0; a < 3; ++a) free(r[a]);
}

/* ------------------------------------------------------------------------ */
/* direct N-body sum                                                         */

static double g_worst_single = 0.0, g_worst_double = 0.0;

/* Relative L2 error of the direct sum against the double reference. */
static void check_nbody(struct px_context *ctx, struct px_backend *be, enum px_precision p,
                        size_t ns, size_t nt, int same, size_t workgroup) {
  const double eps = 0.01;
  const double tol = p == PX_PRECISION_DOUBLE ? 1e-12 : 1e-5;
  uint64_t rng[PX_RNG_WORDS];
  double *sx = malloc((ns + 1) * sizeof(double)), *sy = malloc((ns + 1) * sizeof(double));
  double *sg = malloc((ns + 1) * sizeof(double));
  double *tx = malloc((nt + 1) * sizeof(double)), *ty = malloc((nt + 1) * sizeof(double));
  double *u = malloc((nt + 1) * sizeof(double)), *v = malloc((nt + 1) * sizeof(double));
  double *ru = malloc((nt + 1) * sizeof(double)), *rv = malloc((nt + 1) * sizeof(double));
  struct px_buffer *bsx, *bsy, *bsg, *btx, *bty, *bu, *bv;
  double err2 = 0.0, ref2 = 0.0, rel;
  size_t i;
  px_rng_seed(rng, 1000 + ns + 7 * nt);
  for (i = 0; i < ns; ++i) {
    sx[i] = px_rng_uniform(rng);
    sy[i] = px_rng_uniform(rng);
    sg[i] = px_test_uniform(rng, -1.0, 1.0);
  }
  px_test_round(p, ns, sx);
  px_test_round(p, ns, sy);
  px_test_round(p, ns, sg);
  if (same) {
    memcpy(tx, sx, nt * sizeof(double));
    memcpy(ty, sy, nt * sizeof(double));
  } else {
    for (i = 0; i < nt; ++i) {
      tx[i] = px_test_uniform(rng, -0.2, 1.2);
      ty[i] = px_test_uniform(rng, -0.2, 1.2);
    }
    px_test_round(p, nt, tx);
    px_test_round(p, nt, ty);
  }
  px_nbody_direct_reference(ns, sx, sy, sg, nt, tx, ty, eps, ru, rv);
  bsx = px_test_upload(ctx, be, "src x", p, ns, sx);
  bsy = px_test_upload(ctx, be, "src y", p, ns, sy);
  bsg = px_test_upload(ctx, be, "src gamma", p, ns, sg);
  btx = same ? bsx : px_test_upload(ctx, be, "tgt x", p, nt, tx);
  bty = same ? bsy : px_test_upload(ctx, be, "tgt y", p, nt, ty);
  bu = px_test_upload(ctx, be, "u", p, nt, tx);
  bv = px_test_upload(ctx, be, "v", p, nt, ty);
  PX_CHECK_OK(ctx, px_backend_set_workgroup(be, workgroup));
  PX_CHECK_OK(
      ctx, px_nbody_direct(be, p, ns, bsx, bsy, bsg, nt, btx, bty, eps, PX_NBODY_MODE_SET, bu, bv));
  px_test_download(ctx, bu, p, nt, u);
  px_test_download(ctx, bv, p, nt, v);
  for (i = 0; i < nt; ++i) {
    err2 += (u[i] - ru[i]) * (u[i] - ru[i]) + (v[i] - rv[i]) * (v[i] - rv[i]);
    ref2 += ru[i] * ru[i] + rv[i] * rv[i];
  }
  rel = ref2 > 0 ? sqrt(err2 / ref2) : sqrt(err2);
  if (p == PX_PRECISION_SINGLE && rel > g_worst_single) g_worst_single = rel;
  if (p == PX_PRECISION_DOUBLE && rel > g_worst_double) g_worst_double = rel;
  PX_CHECK_MSG(rel <= tol,
               "direct sum [%s, %s, n_src %zu, n_tgt %zu%s, work-group %zu]: "
               "relative L2 error %.3g > %.3g",
               px_backend_name(be), px_precision_name(p), ns, nt, same ? ", sources = targets" : "",
               workgroup, rel, tol);
  /* ADD mode onto the result: doubles it; the evaluator gives the same */
  if (nt > 0) {
    struct px_nbody *nb = NULL;
    err2 = 0.0;
    PX_CHECK_OK(ctx, px_nbody_create(be, PX_NBODY_METHOD_DIRECT, p, eps, &nb));
    PX_CHECK_OK(ctx,
                px_nbody_velocity(nb, ns, bsx, bsy, bsg, nt, btx, bty, PX_NBODY_MODE_ADD, bu, bv));
    px_nbody_free(nb);
    px_test_download(ctx, bu, p, nt, ru);
    px_test_download(ctx, bv, p, nt, rv);
    for (i = 0; i < nt; ++i)
      err2 += (ru[i] - 2 * u[i]) * (ru[i] - 2 * u[i]) + (rv[i] - 2 * v[i]) * (rv[i] - 2 * v[i]);
    PX_CHECK_MSG(ref2 == 0 || sqrt(err2 / ref2) <= 2 * tol, "ADD mode: relative error %.3g",
                 sqrt(err2 / ref2));
  }
  PX_CHECK_OK(ctx, px_backend_set_workgroup(be, 0));
  px_buffer_free(bsx);
  px_buffer_free(bsy);
  px_buffer_free(bsg);
  if (!same) {
    px_buffer_free(btx);
    px_buffer_free(bty);
  }
  px_buffer_free(bu);
  px_buffer_free(bv);
  free(sx);
  free(sy);
  free(sg);
  free(tx);
  free(ty);
  free(u);
  free(v);
  free(ru);
  free(rv);
}

/* cpu: the same sums, bit for bit, on 1 and 2 threads (each target's terms
 * arrive in an order fixed by the loop structure, not by the threads). */
static void check_nbody_threads(struct px_context *ctx) {
  enum { NS = 3001, NT = 1500 };
  struct px_backend *be[2];
  struct px_buffer *b[2][7];
  float out[2][4][NT], self[2][2][NS];
  uint64_t rng[PX_RNG_WORDS];
  float host[5][NS];
  int t, k;
  size_t i;
  px_rng_seed(rng, 5);
  for (k = 0; k < 5; ++k)
    for (i = 0; i < NS; ++i) host[k][i] = (float)px_rng_uniform(rng);
  for (t = 0; t < 2; ++t) {
    be[t] = px_test_backend(ctx, "cpu", t + 1);
    for (k = 0; k < 7; ++k) {
      PX_CHECK_OK(ctx, px_buffer_create(be[t], "threads", sizeof host[0], &b[t][k]));
      if (k < 5) PX_CHECK_OK(ctx, px_buffer_write(b[t][k], 0, sizeof host[0], host[k]));
    }
    PX_CHECK_OK(ctx, px_nbody_direct(be[t], PX_PRECISION_SINGLE, NS, b[t][0], b[t][1], b[t][2], NT,
                                     b[t][3], b[t][4], 0.01, PX_NBODY_MODE_SET, b[t][5], b[t][6]));
    PX_CHECK_OK(ctx, px_buffer_read(b[t][5], 0, sizeof out[t][0], out[t][0]));
    PX_CHECK_OK(ctx, px_buffer_read(b[t][6], 0, sizeof out[t][1], out[t][1]));
    PX_CHECK_OK(ctx, px_nbody_direct(be[t], PX_PRECISION_SINGLE, NS, b[t][0], b[t][1], b[t][2], NS,
                                     b[t][0], b[t][1], 0.01, PX_NBODY_MODE_SET, b[t][5], b[t][6]));
    PX_CHECK_OK(ctx, px_buffer_read(b[t][5], 0, sizeof self[t][0], self[t][0]));
    PX_CHECK_OK(ctx, px_buffer_read(b[t][6], 0, sizeof self[t][1], self[t][1]));
  }
  PX_CHECK_MSG(memcmp(out[0], out[1], 2 * sizeof out[0][0]) == 0,
               "direct sum differs between 1 and 2 threads");
  PX_CHECK_MSG(memcmp(self[0], self[1], sizeof self[0]) == 0,
               "self-interaction sum differs between 1 and 2 threads");
  for (t = 0; t < 2; ++t) {
    for (k = 0; k < 7; ++k) px_buffer_free(b[t][k]);
    px_backend_free(be[t]);
  }
}

static void test_nbody(struct px_context *ctx, struct px_backend *be) {
  const int cpu = px_backend_host_memory(be);
  /* cpu: tile widths (sources per block); opencl: work-group sizes */
  const size_t wg[4] = {0, 16, cpu ? 100 : 96, cpu ? 4096 : 128};
  int pi, w;
  for (pi = 0; pi < 2; ++pi) {
    const enum px_precision p = pi ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
    check_nbody(ctx, be, p, 1, 1, 1, 0);
    check_nbody(ctx, be, p, 7, 5, 0, 0);
    check_nbody(ctx, be, p, 0, 33, 0, 0);
    check_nbody(ctx, be, p, 1000, 1000, 1, 0);
    for (w = 0; w < 4; ++w) {
      check_nbody(ctx, be, p, 1337, 999, 0, wg[w]);
      check_nbody(ctx, be, p, 2049, 2049, 1, wg[w]);
    }
  }
  printf("direct sum [%s]: worst relative L2 error single %.3g, double %.3g\n", px_backend_name(be),
         g_worst_single, g_worst_double);
  if (cpu) check_nbody_threads(ctx);

  /* misuse */
  {
    struct px_buffer *a = NULL, *b = NULL, *c = NULL, *u = NULL, *v = NULL;
    struct px_nbody *nb = NULL;
    PX_CHECK_OK(ctx, px_buffer_create(be, "a", 400, &a));
    PX_CHECK_OK(ctx, px_buffer_create(be, "b", 400, &b));
    PX_CHECK_OK(ctx, px_buffer_create(be, "c", 400, &c));
    PX_CHECK_OK(ctx, px_buffer_create(be, "u", 400, &u));
    PX_CHECK_OK(ctx, px_buffer_create(be, "v", 400, &v));
    PX_CHECK_OK(ctx, px_nbody_direct(be, PX_PRECISION_SINGLE, 100, a, b, c, 0, a, b, 0.1,
                                     PX_NBODY_MODE_SET, u, v));
    PX_CHECK_STATUS(ctx,
                    px_nbody_direct(be, PX_PRECISION_SINGLE, 100, a, b, c, 100, a, b, 0.0,
                                    PX_NBODY_MODE_SET, u, v),
                    PX_STATUS_INVALID);
    PX_CHECK(strstr(px_context_message(ctx), "eps") != NULL);
    PX_CHECK_STATUS(ctx,
                    px_nbody_direct(be, PX_PRECISION_SINGLE, 100, a, b, c, 100, a, b, 1e-30,
                                    PX_NBODY_MODE_SET, u, v),
                    PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx,
                    px_nbody_direct(be, PX_PRECISION_SINGLE, 101, a, b, c, 100, a, b, 0.1,
                                    PX_NBODY_MODE_SET, u, v),
                    PX_STATUS_INVALID);
    PX_CHECK(strstr(px_context_message(ctx), "src_x") != NULL);
    PX_CHECK_STATUS(ctx,
                    px_nbody_direct(be, PX_PRECISION_DOUBLE, 100, a, b, c, 10, a, b, 0.1,
                                    PX_NBODY_MODE_SET, u, v),
                    PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx,
                    px_nbody_direct(be, PX_PRECISION_SINGLE, 100, a, NULL, c, 100, a, b, 0.1,
                                    PX_NBODY_MODE_SET, u, v),
                    PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx,
                    px_nbody_direct(be, PX_PRECISION_SINGLE, 100, a, b, c, 100, a, b, 0.1,
                                    PX_NBODY_MODE_SET, a, v),
                    PX_STATUS_INVALID);
    PX_CHECK(strstr(px_context_message(ctx), "also an input") != NULL);
    PX_CHECK_STATUS(ctx,
                    px_nbody_direct(be, PX_PRECISION_SINGLE, 100, a, b, c, 100, a, b, 0.1,
                                    PX_NBODY_MODE_SET, u, u),
                    PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx,
                    px_nbody_direct(be, PX_PRECISION_MIXED, 100, a, b, c, 100, a, b, 0.1,
                                    PX_NBODY_MODE_SET, u, v),
                    PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx,
                    px_nbody_direct(be, PX_PRECISION_SINGLE, 100, a, b, c, 100, a, b, 0.1,
                                    (enum px_nbody_mode)7, u, v),
                    PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx,
                    px_nbody_create(be, PX_NBODY_METHOD_DIRECT, PX_PRECISION_SINGLE, -1.0, &nb),
                    PX_STATUS_INVALID);
    PX_CHECK(nb == NULL);
    {
      enum px_nbody_method m;
      PX_CHECK_OK(ctx, px_nbody_method_parse("direct", &m));
      PX_CHECK(m == PX_NBODY_METHOD_DIRECT && strcmp(px_nbody_method_name(m), "direct") == 0);
      PX_CHECK(px_nbody_method_parse("fmm-typo", &m) == PX_STATUS_INVALID);
    }
    px_buffer_free(a);
    px_buffer_free(b);
    px_buffer_free(c);
    px_buffer_free(u);
    px_buffer_free(v);
  }
}

/* ------------------------------------------------------------------------ */
/* precision a device cannot run                                             */

static void test_no_fp64(struct px_context *ctx, struct px_backend *be) {
  struct px_buffer *a = NULL, *b = NULL;
  struct px_integrator *it = NULL;
  const double c[1] = {1.0};
  const int saved = be->fp64;
  PX_CHECK(px_backend_has_fp64(be) == 1); /* cpu always; POCL's CPU device has cl_khr_fp64 */
  PX_CHECK_OK(ctx, px_backend_require(be, PX_PRECISION_DOUBLE));
  PX_CHECK_OK(ctx, px_buffer_create(be, "a", 800, &a));
  PX_CHECK_OK(ctx, px_buffer_create(be, "b", 800, &b));
  be->fp64 = 0; /* pretend the device lacks cl_khr_fp64 */
  PX_CHECK_OK(ctx, px_backend_require(be, PX_PRECISION_SINGLE));
  PX_CHECK_STATUS(ctx, px_backend_require(be, PX_PRECISION_DOUBLE), PX_STATUS_UNSUPPORTED);
  PX_CHECK(strstr(px_context_message(ctx), "double") != NULL);
  PX_CHECK_STATUS(ctx, px_buffer_lincomb(b, PX_DTYPE_F64, 100, 1, c, &a), PX_STATUS_UNSUPPORTED);
  PX_CHECK_STATUS(
      ctx,
      px_nbody_direct(be, PX_PRECISION_DOUBLE, 10, a, a, a, 10, a, a, 0.1, PX_NBODY_MODE_SET, b, b),
      PX_STATUS_UNSUPPORTED);
  PX_CHECK_STATUS(ctx, px_integrator_create(be, PX_INTEGRATOR_RK4, PX_DTYPE_F64, 10, &it),
                  PX_STATUS_UNSUPPORTED);
  PX_CHECK(it == NULL);
  be->fp64 = saved;
  px_buffer_free(a);
  px_buffer_free(b);
}

static void test_backend_info(struct px_context *ctx, struct px_backend *be) {
  const char *const *names = px_backend_names();
  struct px_backend *none = NULL;
  char text[8192];
  FILE *f = tmpfile();
  size_t len;
  PX_CHECK(strcmp(names[0], "cpu") == 0);
  PX_CHECK(strcmp(px_backend_name(be), g_backend) == 0);
  PX_CHECK(strlen(px_backend_device(be)) > 0);
  PX_CHECK(px_backend_threads(be) >= 1);
  PX_CHECK(px_backend_context(be) == ctx);
  PX_CHECK_OK(ctx, px_backend_finish(be));
  PX_CHECK_STATUS(ctx, px_backend_create(ctx, "cuda", 0, 0, &none), PX_STATUS_NOT_FOUND);
  PX_CHECK(strstr(px_context_message(ctx), "available: cpu") != NULL);
  PX_CHECK_STATUS(ctx, px_backend_create(ctx, "cpu", 0, -1, &none), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_backend_set_workgroup(be, (size_t)1 << 40), PX_STATUS_INVALID);
  PX_CHECK(px_backend_workgroup(be) == 0);
#ifdef PX_HAVE_OPENCL
  PX_CHECK_STATUS(ctx, px_backend_create(ctx, "opencl", 1000, 0, &none), PX_STATUS_NOT_FOUND);
  PX_CHECK(strstr(px_context_message(ctx), "device 1000 does not exist") != NULL);
  {
    /* backend.device not given: the first GPU or accelerator in the list,
     * whatever platform comes first, else device 0 */
    const cl_device_type cpu = CL_DEVICE_TYPE_CPU, gpu = CL_DEVICE_TYPE_GPU;
    const cl_device_type pocl_then_gpu[3] = {cpu, cpu | CL_DEVICE_TYPE_DEFAULT, gpu};
    const cl_device_type acc_then_gpu[2] = {CL_DEVICE_TYPE_ACCELERATOR, gpu};
    const cl_device_type cpus[2] = {cpu, cpu};
    const int n = px_backend_opencl_device_count(ctx), def = px_backend_default_device("opencl");
    PX_CHECK(px_opencl_pick_default(pocl_then_gpu, 3) == 2);
    PX_CHECK(px_opencl_pick_default(acc_then_gpu, 2) == 0);
    PX_CHECK(px_opencl_pick_default(cpus, 2) == 0);
    PX_CHECK(px_opencl_pick_default(NULL, 0) == 0);
    PX_CHECK(def >= 0 && (def < n || def == 0));
  }
#endif
  PX_CHECK(px_backend_default_device("cpu") == 0);
  PX_CHECK(px_backend_default_device("cuda") == 0);
  PX_CHECK(none == NULL);
  if (f) {
    px_backend_report(ctx, f);
    rewind(f);
    len = fread(text, 1, sizeof text - 1, f);
    text[len] = '\0';
    fclose(f);
    PX_CHECK(strstr(text, "compute backends: cpu") != NULL);
    PX_CHECK(strstr(text, "cpu: ") != NULL);
#ifdef PX_HAVE_OPENCL
    if (px_backend_opencl_device_count(ctx) > 0) {
      PX_CHECK(strstr(text, "opencl platform 0:") != NULL);
      PX_CHECK(strstr(text, "device 0:") != NULL);
      PX_CHECK(strstr(text, "(the default: backend.device not given)") != NULL);
      PX_CHECK(strstr(text, "fp64") != NULL);
    }
#endif
  }
}

#ifdef PX_HAVE_OPENCL
/* The OpenCL helpers solvers build on: program cache, build log in the
 * message, error names, and the prefix sum at block boundaries. */
static void test_opencl_helpers(struct px_context *ctx, struct px_backend *be) {
  static const char *const broken =
      "__kernel void k(__global float *x) { x[0] = undeclared_thing; }";
  static const char *const good =
      "__kernel void k(__global float *x) { x[get_global_id(0)] = 2.0f; }";
  static const size_t sizes[] = {1, 2, 511, 512, 513, 1023, 1024, 1025, 262144, 262145, 1000003};
  cl_program p1 = NULL, p2 = NULL;
  cl_kernel k1 = NULL, k2 = NULL;
  size_t t;
  PX_CHECK(strcmp(px_opencl_error_name(CL_OUT_OF_RESOURCES), "CL_OUT_OF_RESOURCES") == 0);
  PX_CHECK(strcmp(px_opencl_error_name(-9999), "CL_UNKNOWN_ERROR") == 0);
  PX_CHECK_STATUS(ctx, px_opencl_check(be, CL_INVALID_WORK_GROUP_SIZE, "launching test"),
                  PX_STATUS_BACKEND);
  PX_CHECK(strstr(px_context_message(ctx), "launching test: CL_INVALID_WORK_GROUP_SIZE (-54)") !=
           NULL);
  PX_CHECK_STATUS(ctx, px_opencl_check(be, CL_MEM_OBJECT_ALLOCATION_FAILURE, "x"), PX_STATUS_NOMEM);
  printf("building a deliberately broken program (the OpenCL compiler may echo its error):\n");
  fflush(stdout);
  PX_CHECK_STATUS(ctx, px_opencl_program(be, "broken", broken, "", &p1), PX_STATUS_BACKEND);
  PX_CHECK(strstr(px_context_message(ctx), "failed to build") != NULL);
  PX_CHECK(strstr(px_context_message(ctx), "build log") != NULL);
  PX_CHECK(strstr(px_context_message(ctx), "undeclared_thing") != NULL);
  PX_CHECK_OK(ctx, px_opencl_program(be, "good", good, "-DX=1", &p1));
  PX_CHECK_OK(ctx, px_opencl_program(be, "good", good, "-DX=1", &p2));
  PX_CHECK(p1 == p2 && p1 != NULL); /* cached per (name, options) */
  PX_CHECK_OK(ctx, px_opencl_program(be, "good", good, "-DX=2", &p2));
  PX_CHECK(p1 != p2);
  PX_CHECK_OK(ctx, px_opencl_kernel(be, p1, "k", &k1));
  PX_CHECK_OK(ctx, px_opencl_kernel(be, p1, "k", &k2));
  PX_CHECK(k1 == k2 && k1 != NULL);
  PX_CHECK_STATUS(ctx, px_opencl_kernel(be, p1, "missing", &k2), PX_STATUS_BACKEND);
  PX_CHECK(strstr(px_context_message(ctx), "CL_INVALID_KERNEL_NAME") != NULL);
  for (t = 0; t < PX_COUNTOF(sizes); ++t) {
    const size_t n = sizes[t];
    uint32_t *in = malloc(n * 4), *out = malloc(n * 4), total = 0, sum = 0;
    struct px_buffer *b = NULL;
    size_t i, bad = 0;
    for (i = 0; i < n; ++i) in[i] = (uint32_t)((i * 2654435761u) >> 28);
    PX_CHECK_OK(ctx, px_buffer_create(be, "scan", n * 4, &b));
    PX_CHECK_OK(ctx, px_buffer_write(b, 0, n * 4, in));
    PX_CHECK_OK(ctx, px_opencl_scan_u32(be, b, b, n, &total));
    PX_CHECK_OK(ctx, px_buffer_read(b, 0, n * 4, out));
    for (i = 0; i < n; ++i) {
      bad += out[i] != sum;
      sum += in[i];
    }
    PX_CHECK_MSG(bad == 0 && total == sum, "prefix sum of %zu values: %zu wrong, total %u vs %u", n,
                 bad, total, sum);
    px_buffer_free(b);
    free(in);
    free(out);
  }
}
#endif

int main(int argc, char **argv) {
  struct px_context *ctx = NULL;
  struct px_backend *be;
  if (argc > 1) g_backend = argv[1];
  if (px_context_create(&ctx) != PX_STATUS_OK) return EXIT_FAILURE;
  px_context_set_log(ctx, trace_log, NULL);
  px_context_set_log_level(ctx, PX_LOG_LEVEL_TRACE);
  be = px_test_backend(ctx, g_backend, 0);
  printf("backend %s: %s\n", px_backend_name(be), px_backend_device(be));
  test_backend_info(ctx, be);
  test_buffers(ctx, be);
  test_lincomb_type(ctx, be, PX_DTYPE_F32);
  test_lincomb_type(ctx, be, PX_DTYPE_F64);
  test_grid(ctx, be);
  if (!px_backend_host_memory(be)) {
    /* both OpenCL sort paths ran (uniform grids: scatter + per-cell sort;
     * clusters, points clamped to the edges: radix sort) */
    printf("grid builds on %s: %d scatter + per-cell sort, %d radix sort\n", g_backend,
           g_scatter_builds, g_radix_builds);
    PX_CHECK(g_scatter_builds >= 4 && g_radix_builds >= 4);
  }
  test_nbody(ctx, be);
  test_no_fp64(ctx, be);
#ifdef PX_HAVE_OPENCL
  if (strcmp(g_backend, "opencl") == 0) test_opencl_helpers(ctx, be);
#endif
  px_backend_free(be);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  return px_test_report("test_compute_conformance");
}
