/* Bodies on a regular grid (see lattice_grid.h). */
#include "solvers/lattice/lattice_grid.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "partix/memory.h"

static const char *const px_lattice_shape_names[] = {"box", "cylinder", "sphere"};

const char *px_lattice_face_name(enum px_lattice_face f) {
  static const char *const names[] = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};
  return (f >= 0 && f <= 5) ? names[f] : "none";
}

/* Bounding box of a primitive. */
static void px_lattice_prim_bounds(const struct px_lattice_prim *p, double lo[3], double hi[3]) {
  int a;
  for (a = 0; a < 3; ++a) {
    switch (p->shape) {
      case PX_LATTICE_SHAPE_BOX:
        lo[a] = p->p0[a];
        hi[a] = p->p1[a];
        break;
      case PX_LATTICE_SHAPE_CYLINDER: {
        /* exact extent of a disc of radius r normal to d: r sqrt(1 - d_a^2) */
        double d[3], len2 = 0.0, e;
        int b;
        for (b = 0; b < 3; ++b) {
          d[b] = p->p1[b] - p->p0[b];
          len2 += d[b] * d[b];
        }
        e = p->r * sqrt(fmax(0.0, 1.0 - d[a] * d[a] / len2));
        lo[a] = fmin(p->p0[a], p->p1[a]) - e;
        hi[a] = fmax(p->p0[a], p->p1[a]) + e;
        break;
      }
      case PX_LATTICE_SHAPE_SPHERE:
      default:
        lo[a] = p->p0[a] - p->r;
        hi[a] = p->p0[a] + p->r;
        break;
    }
  }
}

/* 1 if the point x is inside the primitive (boundary included, tolerance tol). */
static int px_lattice_prim_inside(const struct px_lattice_prim *p, const double x[3], double tol) {
  int a;
  switch (p->shape) {
    case PX_LATTICE_SHAPE_BOX:
      for (a = 0; a < 3; ++a)
        if (x[a] < p->p0[a] - tol || x[a] > p->p1[a] + tol) return 0;
      return 1;
    case PX_LATTICE_SHAPE_CYLINDER: {
      double d[3], w[3], len2 = 0.0, t = 0.0, r2 = 0.0, len;
      for (a = 0; a < 3; ++a) {
        d[a] = p->p1[a] - p->p0[a];
        w[a] = x[a] - p->p0[a];
        len2 += d[a] * d[a];
        t += w[a] * d[a];
      }
      len = sqrt(len2);
      t /= len2; /* axial coordinate, 0..1 */
      if (t * len < -tol || t * len > len + tol) return 0;
      for (a = 0; a < 3; ++a) {
        double q = w[a] - t * d[a];
        r2 += q * q;
      }
      return r2 <= (p->r + tol) * (p->r + tol);
    }
    case PX_LATTICE_SHAPE_SPHERE:
    default: {
      double r2 = 0.0;
      for (a = 0; a < 3; ++a) r2 += (x[a] - p->p0[a]) * (x[a] - p->p0[a]);
      return r2 <= (p->r + tol) * (p->r + tol);
    }
  }
}

static enum px_status px_lattice_prim_check(struct px_context *ctx, const struct px_lattice_prim *p,
                                            size_t i) {
  int a;
  const char *name = px_lattice_shape_names[p->shape];
  /* |x| <= PX_LATTICE_COORD_MAX keeps extents, squared distances and the
   * cylinder's axis length finite */
  for (a = 0; a < 3; ++a)
    if (!(fabs(p->p0[a]) <= PX_LATTICE_COORD_MAX) ||
        (p->shape != PX_LATTICE_SHAPE_SPHERE && !(fabs(p->p1[a]) <= PX_LATTICE_COORD_MAX)))
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "shape %zu (%s): coordinates must be finite and within +-%g m", i,
                             name, PX_LATTICE_COORD_MAX);
  if (p->shape == PX_LATTICE_SHAPE_BOX) {
    for (a = 0; a < 3; ++a)
      if (!(p->p1[a] > p->p0[a]))
        return px_context_fail(ctx, PX_STATUS_CONFIG,
                               "shape %zu (box): max[%d] = %g must exceed min[%d] = %g", i, a,
                               p->p1[a], a, p->p0[a]);
  } else {
    if (!(p->r > 0.0) || !(p->r <= PX_LATTICE_COORD_MAX))
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "shape %zu (%s): radius must be > 0 and <= %g m, got %g", i, name,
                             PX_LATTICE_COORD_MAX, p->r);
    if (p->shape == PX_LATTICE_SHAPE_CYLINDER) {
      double len2 = 0.0;
      for (a = 0; a < 3; ++a) len2 += (p->p1[a] - p->p0[a]) * (p->p1[a] - p->p0[a]);
      if (!(len2 > 0.0))
        return px_context_fail(ctx, PX_STATUS_CONFIG,
                               "shape %zu (cylinder): the two end centres coincide", i);
    }
  }
  return PX_STATUS_OK;
}

void px_lattice_grid_free(struct px_context *ctx, struct px_lattice_grid *g) {
  if (!g) return;
  px_mem_free(ctx, g->occ);
  memset(g, 0, sizeof *g);
}

void px_lattice_grid_centre(const struct px_lattice_grid *g, size_t c, double x[3]) {
  size_t n0 = (size_t)g->n[0], n1 = (size_t)g->n[1];
  size_t i = c % n0, j = (c / n0) % n1, k = c / (n0 * n1);
  x[0] = g->origin[0] + ((double)i + 0.5) * g->h;
  x[1] = g->origin[1] + ((double)j + 0.5) * g->h;
  x[2] = g->origin[2] + ((double)k + 0.5) * g->h;
}

/* Crop g to the bounding box of its occupied cells. */
static enum px_status px_lattice_grid_crop(struct px_context *ctx, struct px_lattice_grid *g) {
  int lo[3] = {g->n[0], g->n[1], g->n[2]}, hi[3] = {-1, -1, -1}, n[3], a;
  size_t c, count = 0, ncell;
  uint8_t *occ;
  for (c = 0; c < g->ncell; ++c) {
    int ijk[3];
    if (!g->occ[c]) continue;
    ++count;
    ijk[0] = (int)(c % (size_t)g->n[0]);
    ijk[1] = (int)((c / (size_t)g->n[0]) % (size_t)g->n[1]);
    ijk[2] = (int)(c / ((size_t)g->n[0] * (size_t)g->n[1]));
    for (a = 0; a < 3; ++a) {
      if (ijk[a] < lo[a]) lo[a] = ijk[a];
      if (ijk[a] > hi[a]) hi[a] = ijk[a];
    }
  }
  g->count = count;
  if (count == 0) return PX_STATUS_OK;
  for (a = 0; a < 3; ++a) n[a] = hi[a] - lo[a] + 1;
  if (n[0] == g->n[0] && n[1] == g->n[1] && n[2] == g->n[2]) return PX_STATUS_OK;
  ncell = (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
  occ = (uint8_t *)px_mem_calloc(ctx, "lattice.grid", ncell, 1);
  if (!occ) return PX_STATUS_NOMEM;
  {
    int i, j, k;
    for (k = 0; k < n[2]; ++k)
      for (j = 0; j < n[1]; ++j)
        for (i = 0; i < n[0]; ++i)
          occ[(size_t)i + (size_t)n[0] * ((size_t)j + (size_t)n[1] * (size_t)k)] =
              g->occ[(size_t)(i + lo[0]) +
                     (size_t)g->n[0] *
                         ((size_t)(j + lo[1]) + (size_t)g->n[1] * (size_t)(k + lo[2]))];
  }
  px_mem_free(ctx, g->occ);
  g->occ = occ;
  for (a = 0; a < 3; ++a) {
    g->origin[a] += lo[a] * g->h;
    g->n[a] = n[a];
  }
  g->ncell = ncell;
  return PX_STATUS_OK;
}

enum px_status px_lattice_grid_plan(struct px_context *ctx, double h,
                                    const struct px_lattice_prim *prims, size_t nprim,
                                    struct px_lattice_grid *g, double *ncells) {
  double lo[3], hi[3], first_lo[3], cells[3], total;
  size_t i;
  int a;
  memset(g, 0, sizeof *g);
  if (ncells) *ncells = 0.0;
  if (!(h > 0.0) || !(h <= PX_LATTICE_COORD_MAX))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "grid spacing h must be > 0 and <= %g m, got %g",
                           PX_LATTICE_COORD_MAX, h);
  if (nprim == 0) return px_context_fail(ctx, PX_STATUS_CONFIG, "the body has no shapes");
  if (prims[0].op != PX_LATTICE_OP_UNION)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "shape 0: the first shape must be a union (a difference of "
                           "nothing is empty)");
  for (i = 0; i < nprim; ++i) PX_TRY(px_lattice_prim_check(ctx, &prims[i], i));
  /* Bounding box of the unions; cells aligned with the first shape. */
  px_lattice_prim_bounds(&prims[0], first_lo, hi);
  for (a = 0; a < 3; ++a) lo[a] = first_lo[a];
  for (i = 1; i < nprim; ++i) {
    double l[3], u[3];
    if (prims[i].op != PX_LATTICE_OP_UNION) continue;
    px_lattice_prim_bounds(&prims[i], l, u);
    for (a = 0; a < 3; ++a) {
      lo[a] = fmin(lo[a], l[a]);
      hi[a] = fmax(hi[a], u[a]);
    }
  }
  total = 1.0;
  for (a = 0; a < 3; ++a) {
    /* whole cells below the first shape's corner, then up to hi (the
     * coordinates are bounded, so only a tiny h makes these overflow) */
    double below = ceil((first_lo[a] - lo[a]) / h - 1e-9);
    cells[a] = ceil((hi[a] - first_lo[a]) / h - 1e-9) + below;
    if (cells[a] < 1.0) cells[a] = 1.0;
    total *= cells[a];
    g->origin[a] = first_lo[a] - below * h;
  }
  if (ncells) *ncells = total;
  /* written to refuse NaN and infinity too */
  if (!(total <= (double)PX_LATTICE_MAX_CELLS))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "the body's bounding box, %g x %g x %g m, holds %.3g cells of h = "
                           "%g m (%.4g x %.4g x %.4g); at most %zu (2^31 - 1) can be indexed: use "
                           "a larger h",
                           hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], total, h, cells[0],
                           cells[1], cells[2], PX_LATTICE_MAX_CELLS);
  g->h = h;
  g->ncell = 1;
  for (a = 0; a < 3; ++a) {
    g->n[a] = (int)cells[a];
    g->ncell *= (size_t)g->n[a];
  }
  return PX_STATUS_OK;
}

enum px_status px_lattice_grid_build(struct px_context *ctx, double h,
                                     const struct px_lattice_prim *prims, size_t nprim,
                                     struct px_lattice_grid *g) {
  double tol;
  size_t i, c;
  int a;
  PX_TRY(px_lattice_grid_plan(ctx, h, prims, nprim, g, NULL));
  g->occ = (uint8_t *)px_mem_calloc(ctx, "lattice.grid", g->ncell, 1);
  if (!g->occ) return PX_STATUS_NOMEM;
  tol = 1e-6 * h;
  for (i = 0; i < nprim; ++i) {
    double l[3], u[3];
    int ilo[3], ihi[3], ii, jj, kk;
    uint8_t value = prims[i].op == PX_LATTICE_OP_UNION ? 1 : 0;
    px_lattice_prim_bounds(&prims[i], l, u);
    for (a = 0; a < 3; ++a) {
      double fl = floor((l[a] - g->origin[a]) / h - 0.5) - 1.0;
      double fu = ceil((u[a] - g->origin[a]) / h - 0.5) + 1.0;
      /* clamped before the conversion (NaN-safe: the coordinates are finite) */
      ilo[a] = !(fl >= 0.0) ? 0 : (fl > g->n[a] - 1 ? g->n[a] - 1 : (int)fl);
      ihi[a] = !(fu >= 0.0) ? -1 : (fu > g->n[a] - 1 ? g->n[a] - 1 : (int)fu);
    }
    for (kk = ilo[2]; kk <= ihi[2]; ++kk)
      for (jj = ilo[1]; jj <= ihi[1]; ++jj)
        for (ii = ilo[0]; ii <= ihi[0]; ++ii) {
          double x[3];
          c = (size_t)ii + (size_t)g->n[0] * ((size_t)jj + (size_t)g->n[1] * (size_t)kk);
          px_lattice_grid_centre(g, c, x);
          if (px_lattice_prim_inside(&prims[i], x, tol)) g->occ[c] = value;
        }
  }
  PX_TRY(px_lattice_grid_crop(ctx, g));
  if (g->count == 0) {
    px_lattice_grid_free(ctx, g);
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "the body is empty: no cell centre of the h = %g m grid lies inside "
                           "it (shapes smaller than h, or removed by a difference)",
                           h);
  }
  return PX_STATUS_OK;
}

enum px_status px_lattice_grid_box(struct px_context *ctx, double h, int n0, int n1, int n2,
                                   struct px_lattice_grid *g) {
  struct px_lattice_prim p;
  memset(&p, 0, sizeof p);
  p.shape = PX_LATTICE_SHAPE_BOX;
  p.op = PX_LATTICE_OP_UNION;
  p.p1[0] = n0 * h;
  p.p1[1] = n1 * h;
  p.p1[2] = n2 * h;
  return px_lattice_grid_build(ctx, h, &p, 1, g);
}

/* Union-find with path halving over cell indices. */
static size_t px_lattice_uf_find(size_t *parent, size_t x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

enum px_status px_lattice_grid_check_connected(struct px_context *ctx,
                                               const struct px_lattice_grid *g) {
  size_t *parent, *size, c, parts = 0, smallest = 0, where = 0;
  size_t n0 = (size_t)g->n[0], n01 = n0 * (size_t)g->n[1];
  enum px_status st = PX_STATUS_OK;
  if (g->count == 0) return px_context_fail(ctx, PX_STATUS_CONFIG, "the body is empty");
  parent = (size_t *)px_mem_alloc(ctx, "lattice.connect", g->ncell * sizeof *parent);
  size = (size_t *)px_mem_calloc(ctx, "lattice.connect", g->ncell, sizeof *size);
  if (!parent || !size) {
    px_mem_free(ctx, parent);
    px_mem_free(ctx, size);
    return PX_STATUS_NOMEM;
  }
  for (c = 0; c < g->ncell; ++c) parent[c] = c;
  for (c = 0; c < g->ncell; ++c) {
    size_t i = c % n0, j = (c / n0) % (size_t)g->n[1], k = c / n01;
    size_t nb[3];
    int a, has[3];
    if (!g->occ[c]) continue;
    has[0] = i + 1 < n0;
    has[1] = j + 1 < (size_t)g->n[1];
    has[2] = k + 1 < (size_t)g->n[2];
    nb[0] = c + 1;
    nb[1] = c + n0;
    nb[2] = c + n01;
    for (a = 0; a < 3; ++a)
      if (has[a] && g->occ[nb[a]]) {
        size_t r1 = px_lattice_uf_find(parent, c), r2 = px_lattice_uf_find(parent, nb[a]);
        if (r1 != r2) parent[r2 < r1 ? r1 : r2] = r2 < r1 ? r2 : r1;
      }
  }
  for (c = 0; c < g->ncell; ++c)
    if (g->occ[c]) ++size[px_lattice_uf_find(parent, c)];
  for (c = 0; c < g->ncell; ++c)
    if (g->occ[c] && parent[c] == c) {
      ++parts;
      if (smallest == 0 || size[c] < smallest) {
        smallest = size[c];
        where = c;
      }
    }
  if (parts > 1) {
    double x[3];
    px_lattice_grid_centre(g, where, x);
    st = px_context_fail(ctx, PX_STATUS_CONFIG,
                         "the body is not connected: it falls into %zu separate parts (elements "
                         "joined only through faces count as connected); the smallest has %zu "
                         "element%s, one of them at (%g, %g, %g) m",
                         parts, smallest, smallest == 1 ? "" : "s", x[0], x[1], x[2]);
  }
  px_mem_free(ctx, parent);
  px_mem_free(ctx, size);
  return st;
}

enum px_status px_lattice_select(struct px_context *ctx, const struct px_lattice_grid *g,
                                 const struct px_lattice_sel *sel, size_t **cells, size_t *count) {
  size_t c, n = 0, best = 0, *out;
  double best_d2 = INFINITY, tol = 1e-6 * g->h;
  int layer = -1, axis = 0;
  size_t n0 = (size_t)g->n[0], n01 = n0 * (size_t)g->n[1];
  *cells = NULL;
  *count = 0;
  if (sel->face != PX_LATTICE_FACE_NONE) {
    /* the first/last occupied layer along the axis (the grid is cropped, so
     * that is layer 0 or n - 1) */
    axis = (int)sel->face / 2;
    layer = ((int)sel->face % 2) ? g->n[axis] - 1 : 0;
  }
  out = (size_t *)px_mem_alloc(ctx, "lattice.selection", (g->count ? g->count : 1) * sizeof *out);
  if (!out) return PX_STATUS_NOMEM;
  for (c = 0; c < g->ncell; ++c) {
    double x[3];
    int a, ok = 1;
    if (!g->occ[c]) continue;
    if (layer >= 0) {
      size_t ijk[3];
      ijk[0] = c % n0;
      ijk[1] = (c / n0) % (size_t)g->n[1];
      ijk[2] = c / n01;
      if (ijk[axis] != (size_t)layer) continue;
    }
    px_lattice_grid_centre(g, c, x);
    if (sel->has_box)
      for (a = 0; a < 3; ++a)
        if (x[a] < sel->box_min[a] - tol || x[a] > sel->box_max[a] + tol) ok = 0;
    if (!ok) continue;
    if (sel->has_point) {
      double d2 = 0.0;
      for (a = 0; a < 3; ++a) d2 += (x[a] - sel->point[a]) * (x[a] - sel->point[a]);
      if (n == 0 || d2 < best_d2) { /* the first match whatever d2 (a far point) */
        best_d2 = d2;
        best = c;
      }
      ++n;
      continue;
    }
    out[n++] = c;
  }
  if (n == 0) {
    px_mem_free(ctx, out);
    return px_context_fail(
        ctx, PX_STATUS_CONFIG,
        "the selection matches no element%s%s%s (the body spans "
        "[%g, %g] x [%g, %g] x [%g, %g] m; element centres are tested)",
        sel->face != PX_LATTICE_FACE_NONE ? " on face " : "",
        sel->face != PX_LATTICE_FACE_NONE ? px_lattice_face_name(sel->face) : "",
        sel->has_box ? " inside the box" : "", g->origin[0], g->origin[0] + g->n[0] * g->h,
        g->origin[1], g->origin[1] + g->n[1] * g->h, g->origin[2], g->origin[2] + g->n[2] * g->h);
  }
  if (sel->has_point) {
    out[0] = best;
    n = 1;
  }
  if (n < (g->count ? g->count : 1)) {
    /* keep what matched only: probes hold their lists for the run */
    size_t *fit = (size_t *)px_mem_realloc(ctx, "lattice.selection", out, n * sizeof *out);
    if (fit) out = fit;
  }
  *cells = out;
  *count = n;
  return PX_STATUS_OK;
}
