/* Boundary geometry: primitives, contours, segments, bins and region queries. */
#include "solvers/granular/geometry.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/memory.h"
#include "solvers/granular/wall_kernel.h"

#define PX_GRAN_PI 3.14159265358979323846

void px_gran_geom_init(struct px_gran_geom *g) {
  memset(g, 0, sizeof *g);
  g->smooth_angle = 30.0 * PX_GRAN_PI / 180.0;
}

void px_gran_geom_free(struct px_context *ctx, struct px_gran_geom *g) {
  size_t c;
  if (!g) return;
  for (c = 0; c < g->ncontours; ++c) {
    px_mem_free(ctx, g->contours[c].bin_start);
    px_mem_free(ctx, g->contours[c].bin_seg);
    px_mem_free(ctx, g->contours[c].strip_start);
    px_mem_free(ctx, g->contours[c].strip_seg);
  }
  px_mem_free(ctx, g->contours);
  px_mem_free(ctx, g->ax);
  px_mem_free(ctx, g->ay);
  px_mem_free(ctx, g->tx);
  px_mem_free(ctx, g->ty);
  px_mem_free(ctx, g->len);
  px_mem_free(ctx, g->tpx);
  px_mem_free(ctx, g->tpy);
  px_mem_free(ctx, g->flags);
  px_mem_free(ctx, g->contour);
  memset(g, 0, sizeof *g);
}

static enum px_status px_gran_geom_grow(struct px_context *ctx, struct px_gran_geom *g,
                                        size_t need) {
  size_t cap;
  double **dv[7];
  int **iv[2];
  int k;
  if (need <= g->scap) return PX_STATUS_OK;
  cap = g->scap ? g->scap : 256;
  while (cap < need) cap *= 2;
  dv[0] = &g->ax, dv[1] = &g->ay, dv[2] = &g->tx, dv[3] = &g->ty, dv[4] = &g->len;
  dv[5] = &g->tpx, dv[6] = &g->tpy;
  iv[0] = &g->flags, iv[1] = &g->contour;
  for (k = 0; k < 7; ++k) {
    double *p = px_mem_realloc(ctx, "granular segments", *dv[k], cap * sizeof *p);
    if (!p) return PX_STATUS_NOMEM;
    *dv[k] = p;
  }
  for (k = 0; k < 2; ++k) {
    int *p = px_mem_realloc(ctx, "granular segments", *iv[k], cap * sizeof *p);
    if (!p) return PX_STATUS_NOMEM;
    *iv[k] = p;
  }
  g->scap = cap;
  return PX_STATUS_OK;
}

/* A coordinate of a contour point is usable: finite, |v| <= PX_GRAN_COORD_MAX. */
static int px_gran_coord_ok(double v) { return fabs(v) <= PX_GRAN_COORD_MAX; }

/* Why primitive q cannot be split (into buf), or NULL when it can: every
 * parameter finite, coordinates and radii within PX_GRAN_COORD_MAX, radii
 * and semi-axes > 0, arcs sweeping at most one turn (more would trace the
 * curve over itself). */
static const char *px_gran_prim_invalid(const struct px_geo_prim *q, char *buf, size_t size) {
  const double turn = 2 * PX_GRAN_PI * (1 + 1e-12);
  size_t k;
  switch (q->kind) {
    case PX_GEO_PRIM_LINE:
    case PX_GEO_PRIM_BEZIER2:
      for (k = 0; k < (q->kind == PX_GEO_PRIM_LINE ? 4u : 6u); ++k)
        if (!px_gran_coord_ok(q->p[k])) {
          snprintf(buf, size, "coordinate %g is not finite or beyond %g m", q->p[k],
                   PX_GRAN_COORD_MAX);
          return buf;
        }
      return NULL;
    case PX_GEO_PRIM_ARC:
      if (!px_gran_coord_ok(q->p[0]) || !px_gran_coord_ok(q->p[1]) || !(q->p[2] > 0) ||
          !(q->p[2] <= PX_GRAN_COORD_MAX)) {
        snprintf(buf, size, "arc centre (%g, %g) and radius %g: finite, radius in (0, %g] m",
                 q->p[0], q->p[1], q->p[2], PX_GRAN_COORD_MAX);
        return buf;
      }
      if (!(fabs(q->p[4] - q->p[3]) <= turn)) {
        snprintf(buf, size, "arc from %g to %g rad: sweeps more than one turn (or not finite)",
                 q->p[3], q->p[4]);
        return buf;
      }
      return NULL;
    case PX_GEO_PRIM_ELLIPSE:
      if (!px_gran_coord_ok(q->p[0]) || !px_gran_coord_ok(q->p[1]) || !(q->p[2] > 0) ||
          !(q->p[2] <= PX_GRAN_COORD_MAX) || !(q->p[3] > 0) || !(q->p[3] <= PX_GRAN_COORD_MAX) ||
          !isfinite(q->p[4])) {
        snprintf(buf, size,
                 "ellipse centre (%g, %g), semi-axes %g, %g, rotation %g: finite, semi-axes in "
                 "(0, %g] m",
                 q->p[0], q->p[1], q->p[2], q->p[3], q->p[4], PX_GRAN_COORD_MAX);
        return buf;
      }
      if (!(fabs(q->p[6] - q->p[5]) <= turn)) {
        snprintf(buf, size,
                 "elliptic arc from %g to %g rad: sweeps more than one turn (or not finite)",
                 q->p[5], q->p[6]);
        return buf;
      }
      return NULL;
    case PX_GEO_PRIM_POINTS:
      if (q->npts && !q->pts) return "no points";
      for (k = 0; k < 2 * q->npts; ++k)
        if (!px_gran_coord_ok(q->pts[k])) {
          snprintf(buf, size, "point %zu: coordinate %g is not finite or beyond %g m", k / 2 + 1,
                   q->pts[k], PX_GRAN_COORD_MAX);
          return buf;
        }
      return NULL;
  }
  return "unknown kind of piece";
}

/* Segments px_gran_split_prim makes of q at segment length h, as a double
 * (compared with PX_GRAN_SEG_MAX before anything is allocated; may be huge
 * or infinite for an extent far beyond h). */
static double px_gran_prim_segments(const struct px_geo_prim *q, double h) {
  double m = 0;
  size_t k;
  if (q->kind == PX_GEO_PRIM_POINTS && !q->smooth) {
    for (k = 0; k + 1 < q->npts; ++k) {
      const double L =
          hypot(q->pts[2 * k + 2] - q->pts[2 * k], q->pts[2 * k + 3] - q->pts[2 * k + 1]);
      if (L > 0) m += fmax(1, ceil(L / h - 1e-9));
    }
    return m;
  }
  return fmax(1, ceil(px_geo_prim_length(q) / h - 1e-9));
}

/* Vertices of a split primitive (without its end point) appended to
 * g->ax/ay from index *n on. The caller has checked the primitive
 * (px_gran_prim_invalid) and its number of segments (px_gran_prim_segments
 * <= PX_GRAN_SEG_MAX). */
static enum px_status px_gran_split_prim(struct px_context *ctx, struct px_gran_geom *g,
                                         const struct px_geo_prim *q, double h, size_t *n) {
  const double L = px_geo_prim_length(q);
  size_t m, k;
  if (q->kind == PX_GEO_PRIM_POINTS && !q->smooth) {
    /* corners: every piece alone */
    for (k = 0; k + 1 < q->npts; ++k) {
      struct px_geo_prim line;
      memset(&line, 0, sizeof line);
      line.kind = PX_GEO_PRIM_LINE;
      line.p[0] = q->pts[2 * k], line.p[1] = q->pts[2 * k + 1];
      line.p[2] = q->pts[2 * k + 2], line.p[3] = q->pts[2 * k + 3];
      if (hypot(line.p[2] - line.p[0], line.p[3] - line.p[1]) <= 0) continue;
      PX_TRY(px_gran_split_prim(ctx, g, &line, h, n));
    }
    return PX_STATUS_OK;
  }
  m = (size_t)ceil(L / h - 1e-9);
  if (m < 1) m = 1;
  PX_TRY(px_gran_geom_grow(ctx, g, *n + m + 1));
  if (q->kind == PX_GEO_PRIM_LINE || q->kind == PX_GEO_PRIM_ARC) {
    /* exact: equal arc length is equal parameter steps */
    for (k = 0; k < m; ++k) {
      px_geo_prim_eval(q, (double)k / (double)m, &g->ax[*n], &g->ay[*n]);
      ++*n;
    }
    return PX_STATUS_OK;
  }
  {
    /* equal arc length from a cumulative-length table */
    const size_t ns = q->kind == PX_GEO_PRIM_POINTS ? 0 : PX_GRAN_SAMPLES;
    double acc = 0, px0, py0, px1, py1, u0 = 0;
    size_t j = 0;
    if (q->kind == PX_GEO_PRIM_POINTS) {
      /* walk the polyline itself */
      size_t seg = 0;
      double segacc = 0;
      for (k = 0; k < m; ++k) {
        const double target = L * (double)k / (double)m;
        double sl;
        while (seg + 1 < q->npts - 1 &&
               segacc + (sl = hypot(q->pts[2 * seg + 2] - q->pts[2 * seg],
                                    q->pts[2 * seg + 3] - q->pts[2 * seg + 1])) <
                   target) {
          segacc += sl;
          ++seg;
        }
        sl =
            hypot(q->pts[2 * seg + 2] - q->pts[2 * seg], q->pts[2 * seg + 3] - q->pts[2 * seg + 1]);
        {
          const double f = sl > 0 ? (target - segacc) / sl : 0;
          g->ax[*n] = q->pts[2 * seg] + f * (q->pts[2 * seg + 2] - q->pts[2 * seg]);
          g->ay[*n] = q->pts[2 * seg + 1] + f * (q->pts[2 * seg + 3] - q->pts[2 * seg + 1]);
        }
        ++*n;
      }
      return PX_STATUS_OK;
    }
    px_geo_prim_eval(q, 0.0, &px0, &py0);
    g->ax[*n] = px0;
    g->ay[*n] = py0;
    ++*n;
    k = 1;
    for (j = 1; j <= ns && k < m; ++j) {
      const double u1 = (double)j / (double)ns;
      double dl;
      px_geo_prim_eval(q, u1, &px1, &py1);
      dl = hypot(px1 - px0, py1 - py0);
      while (k < m && acc + dl >= L * (double)k / (double)m) {
        const double f = dl > 0 ? (L * (double)k / (double)m - acc) / dl : 0;
        px_geo_prim_eval(q, u0 + f * (u1 - u0), &g->ax[*n], &g->ay[*n]);
        ++*n;
        ++k;
      }
      acc += dl;
      px0 = px1;
      py0 = py1;
      u0 = u1;
    }
    while (k < m) { /* rounding at the very end */
      px_geo_prim_eval(q, (double)k / (double)m, &g->ax[*n], &g->ay[*n]);
      ++*n;
      ++k;
    }
  }
  return PX_STATUS_OK;
}

static double px_gran_signed_area(const double *x, const double *y, size_t n) {
  double a = 0;
  size_t k;
  for (k = 0; k < n; ++k) {
    const size_t j = (k + 1) % n;
    a += x[k] * y[j] - x[j] * y[k];
  }
  return 0.5 * a;
}

/* Even–odd crossing test of a point against a closed polygon. */
int px_gran_poly_contains(const double *x, const double *y, size_t n, double px, double py) {
  size_t k;
  int in = 0;
  for (k = 0; k < n; ++k)
    if (px_gran_ray_crosses(x, y, k, (k + 1) % n, px, py)) in = !in;
  return in;
}

/* Proper crossing of segments p1p2 and p3p4 (touching at an end is not a
 * crossing). */
static int px_gran_cross(double x1, double y1, double x2, double y2, double x3, double y3,
                         double x4, double y4) {
  const double d1 = (x4 - x3) * (y1 - y3) - (y4 - y3) * (x1 - x3);
  const double d2 = (x4 - x3) * (y2 - y3) - (y4 - y3) * (x2 - x3);
  const double d3 = (x2 - x1) * (y3 - y1) - (y2 - y1) * (x3 - x1);
  const double d4 = (x2 - x1) * (y4 - y1) - (y2 - y1) * (x4 - x1);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

/* ------------------------------------------------------------------ crossings */

/* Closed vertex rings for the crossing tests: ring r is the polygon of the
 * vertices first[r] .. first[r] + count[r] - 1 of (x, y); segment k of ring
 * r runs from its vertex k to its vertex (k + 1) % count[r]. Borrowed. */
struct px_gran_rings {
  const double *x, *y;
  const size_t *first, *count;
  size_t n;
};

/* A segment's entry in one grid cell: the cell as i << 31 | j, the
 * segment (global index over the rings). */
struct px_gran_cell_seg {
  uint64_t key;
  int32_t seg;
};

static int px_gran_cell_seg_cmp(const void *a, const void *b) {
  const struct px_gran_cell_seg *p = a, *q = b;
  if (p->key != q->key) return p->key < q->key ? -1 : 1;
  return (p->seg > q->seg) - (p->seg < q->seg);
}

/* Proper crossings of segments of the rings: pairs within one ring (leaving
 * out neighbours) when `within`, pairs of two different rings otherwise.
 * Segments are put in the cells of a uniform grid they cover (cells about
 * the mean segment length, coarser while segments would cover more than 8
 * cells each on average), as a sorted list of (cell, segment) entries (only
 * the cells in use: a large contour of short segments needs no grid over
 * its whole box); a pair whose boxes share cells is tested once, in the
 * first cell they share. The work so grows with the number of segments, not
 * its square; segments piled up in a few cells (more than
 * PX_GRAN_CROSS_TESTS pairs to test) are refused (CONFIG, `what` starts the
 * message). On a crossing *found = 1 and hit[0], hit[1] = {ring, index in
 * the ring} of the two segments (hit[0] of the lower ring, or the lower
 * index). */
static enum px_status px_gran_find_cross(struct px_context *ctx, const struct px_gran_rings *R,
                                         int within, const char *what, int *found,
                                         size_t hit[2][2]) {
  const double *x = R->x, *y = R->y;
  double X0 = DBL_MAX, Y0 = DBL_MAX, X1 = -DBL_MAX, Y1 = -DBL_MAX, L = 0, c, tests = 0;
  size_t S = 0, r, k, cov = 0, *off = NULL, g0, g1;
  int32_t *box = NULL;
  struct px_gran_cell_seg *ent = NULL;
  enum px_status st = PX_STATUS_OK;
  *found = 0;
  for (r = 0; r < R->n; ++r) {
    for (k = 0; k < R->count[r]; ++k) {
      const size_t a = R->first[r] + k, b = R->first[r] + (k + 1) % R->count[r];
      X0 = fmin(X0, x[a]), X1 = fmax(X1, x[a]), Y0 = fmin(Y0, y[a]), Y1 = fmax(Y1, y[a]);
      L += hypot(x[b] - x[a], y[b] - y[a]);
    }
    S += R->count[r];
  }
  if (S < 2) return PX_STATUS_OK;
  off = px_mem_alloc(ctx, "granular crossings", (R->n + 1) * sizeof *off);
  box = px_mem_alloc(ctx, "granular crossings", 5 * S * sizeof *box);
  if (!off || !box) {
    st = PX_STATUS_NOMEM;
    goto done;
  }
  off[0] = 0;
  for (r = 0; r < R->n; ++r) off[r + 1] = off[r] + R->count[r];
  /* the cell: the mean segment length (at least 2^-30 of the box, so cell
   * indices fit in 31 bits), doubled while the segments would cover more
   * than 8 cells each on average */
  c = L / (double)S;
  c = fmax(c, fmax(X1 - X0, Y1 - Y0) / 1073741824.0);
  if (!(c > 0) || !isfinite(c)) c = 1;
  for (;;) {
    double total = 0;
    for (r = 0; r < R->n; ++r)
      for (k = 0; k < R->count[r]; ++k) {
        const size_t a = R->first[r] + k, b = R->first[r] + (k + 1) % R->count[r];
        const size_t s = off[r] + k;
        const int i0 = (int)((fmin(x[a], x[b]) - X0) / c), i1 = (int)((fmax(x[a], x[b]) - X0) / c);
        const int j0 = (int)((fmin(y[a], y[b]) - Y0) / c), j1 = (int)((fmax(y[a], y[b]) - Y0) / c);
        box[5 * s] = i0, box[5 * s + 1] = i1, box[5 * s + 2] = j0, box[5 * s + 3] = j1;
        box[5 * s + 4] = (int32_t)r;
        total += (double)(i1 - i0 + 1) * (double)(j1 - j0 + 1);
      }
    if (total <= 8.0 * (double)S + 1024) {
      cov = (size_t)total;
      break;
    }
    c *= 2;
  }
  ent = px_mem_alloc(ctx, "granular crossings", (cov ? cov : 1) * sizeof *ent);
  if (!ent) {
    st = PX_STATUS_NOMEM;
    goto done;
  }
  cov = 0;
  for (k = 0; k < S; ++k) {
    int i, j;
    for (j = box[5 * k + 2]; j <= box[5 * k + 3]; ++j)
      for (i = box[5 * k]; i <= box[5 * k + 1]; ++i) {
        ent[cov].key = (uint64_t)i << 31 | (uint64_t)j;
        ent[cov].seg = (int32_t)k;
        ++cov;
      }
  }
  qsort(ent, cov, sizeof *ent, px_gran_cell_seg_cmp);
  for (g0 = 0; g0 < cov; g0 = g1) {
    double m;
    for (g1 = g0 + 1; g1 < cov && ent[g1].key == ent[g0].key; ++g1) {
    }
    m = (double)(g1 - g0);
    tests += 0.5 * m * (m - 1);
  }
  if (!(tests <= PX_GRAN_CROSS_TESTS)) {
    st = px_context_fail(ctx, PX_STATUS_CONFIG,
                         "%s: %zu segments piled up in a few places (%.3g pairs closer than "
                         "%g m to test for crossings, more than %g): a drawing with entities "
                         "drawn over each other, or far shorter than the segment length?",
                         what, S, tests, c, PX_GRAN_CROSS_TESTS);
    goto done;
  }
  /* pairs of each cell, in cell order */
  for (g0 = 0; g0 < cov && !*found; g0 = g1) {
    const int ci = (int)(ent[g0].key >> 31), cj = (int)(ent[g0].key & 0x7fffffffu);
    size_t p, q;
    for (g1 = g0 + 1; g1 < cov && ent[g1].key == ent[g0].key; ++g1) {
    }
    for (p = g0; p < g1 && !*found; ++p)
      for (q = p + 1; q < g1; ++q) {
        const size_t s = (size_t)ent[p].seg, t = (size_t)ent[q].seg; /* s < t: sorted */
        size_t rs, rt, ks, kt, a, a1, b, b1;
        /* the first cell both boxes share */
        if ((box[5 * s] > box[5 * t] ? box[5 * s] : box[5 * t]) != ci ||
            (box[5 * s + 2] > box[5 * t + 2] ? box[5 * s + 2] : box[5 * t + 2]) != cj)
          continue;
        rs = (size_t)box[5 * s + 4], rt = (size_t)box[5 * t + 4];
        if ((rs == rt) != (within != 0)) continue;
        ks = s - off[rs], kt = t - off[rt];
        if (rs == rt && (kt == ks + 1 || (ks == 0 && kt + 1 == R->count[rs]))) continue;
        a = R->first[rs] + ks, a1 = R->first[rs] + (ks + 1) % R->count[rs];
        b = R->first[rt] + kt, b1 = R->first[rt] + (kt + 1) % R->count[rt];
        if (fmax(x[b], x[b1]) < fmin(x[a], x[a1]) || fmin(x[b], x[b1]) > fmax(x[a], x[a1]) ||
            fmax(y[b], y[b1]) < fmin(y[a], y[a1]) || fmin(y[b], y[b1]) > fmax(y[a], y[a1]))
          continue;
        if (px_gran_cross(x[a], y[a], x[a1], y[a1], x[b], y[b], x[b1], y[b1])) {
          *found = 1;
          hit[0][0] = rs, hit[0][1] = ks, hit[1][0] = rt, hit[1][1] = kt;
          break;
        }
      }
  }
done:
  px_mem_free(ctx, off);
  px_mem_free(ctx, box);
  px_mem_free(ctx, ent);
  return st;
}

enum px_status px_gran_geom_add_path(struct px_context *ctx, struct px_gran_geom *g,
                                     const struct px_geo_path *path, double h, double tol,
                                     const char *name, int body, enum px_gran_side side) {
  size_t k, n0 = g->nseg, n = g->nseg;
  double x0, y0, x1, y1, xs, ys, xe, ye;
  struct px_gran_contour *c;
  if (!(h > 0) || !(h <= PX_GRAN_COORD_MAX))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: segment length %g m must be in (0, %g]",
                           path->where, h, PX_GRAN_COORD_MAX);
  if (path->n == 0)
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: contour '%s' has no pieces", path->where,
                           name);
  /* every piece usable and the segments countable before any is made */
  {
    double total = 0, L = 0;
    char why[160];
    for (k = 0; k < path->n; ++k) {
      const char *bad = px_gran_prim_invalid(&path->prims[k], why, sizeof why);
      if (bad)
        return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: contour '%s': piece %zu: %s",
                               path->where, name, k + 1, bad);
    }
    for (k = 0; k < path->n; ++k) {
      total += px_gran_prim_segments(&path->prims[k], h);
      L += px_geo_prim_length(&path->prims[k]);
    }
    if (!(total + (double)g->nseg <= PX_GRAN_SEG_MAX))
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "%s: contour '%s' (perimeter %.4g m) makes %.4g segments of %g m%s: "
                             "more than the %d segments of all contours the solver takes; "
                             "check the extent (units) of the contour or raise the segment "
                             "length",
                             path->where, name, L, total, h,
                             g->nseg ? " after those of the contours before it" : "",
                             PX_GRAN_SEG_MAX);
  }
  /* continuity and closure */
  for (k = 0; k < path->n; ++k) {
    const struct px_geo_prim *q = &path->prims[k];
    const struct px_geo_prim *r = &path->prims[(k + 1) % path->n];
    px_geo_prim_ends(q, &x0, &y0, &xe, &ye);
    px_geo_prim_ends(r, &xs, &ys, &x1, &y1);
    if (hypot(xe - xs, ye - ys) > tol) {
      if (k + 1 == path->n)
        return px_context_fail(ctx, PX_STATUS_CONFIG,
                               "%s: contour '%s' is open: it ends at (%g, %g) but starts at "
                               "(%g, %g) (gap %g > tolerance %g); close it",
                               path->where, name, xe, ye, xs, ys, hypot(xe - xs, ye - ys), tol);
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "%s: contour '%s' is open between piece %zu, ending at (%g, %g), "
                             "and piece %zu, starting at (%g, %g) (gap %g > tolerance %g)",
                             path->where, name, k + 1, xe, ye, k + 2, xs, ys,
                             hypot(xe - xs, ye - ys), tol);
    }
    if (px_geo_prim_length(q) <= 0)
      return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: contour '%s': piece %zu has zero length",
                             path->where, name, k + 1);
  }
  for (k = 0; k < path->n; ++k) PX_TRY(px_gran_split_prim(ctx, g, &path->prims[k], h, &n));
  /* drop repeated vertices (pieces joining within tol) */
  {
    size_t w = n0;
    const double eps = 1e-9 * h;
    for (k = n0; k < n; ++k) {
      if (w > n0 && hypot(g->ax[k] - g->ax[w - 1], g->ay[k] - g->ay[w - 1]) <= eps) continue;
      g->ax[w] = g->ax[k];
      g->ay[w] = g->ay[k];
      ++w;
    }
    while (w - n0 > 1 && hypot(g->ax[w - 1] - g->ax[n0], g->ay[w - 1] - g->ay[n0]) <= eps) --w;
    n = w;
  }
  if (n - n0 < 3)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: contour '%s' encloses no area (fewer than 3 vertices at segment "
                           "length %g)",
                           path->where, name, h);
  /* self-crossing */
  {
    const size_t first = n0, count = n - n0;
    struct px_gran_rings R;
    size_t hit[2][2];
    int found = 0;
    char what[256];
    R.x = g->ax, R.y = g->ay, R.first = &first, R.count = &count, R.n = 1;
    snprintf(what, sizeof what, "%s: contour '%s'", path->where, name);
    PX_TRY(px_gran_find_cross(ctx, &R, 1, what, &found, hit));
    if (found) {
      const size_t a = n0 + hit[0][1], a1 = n0 + (hit[0][1] + 1) % count;
      return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: contour '%s' crosses itself near (%g, %g)",
                             path->where, name, 0.5 * (g->ax[a] + g->ax[a1]),
                             0.5 * (g->ay[a] + g->ay[a1]));
    }
  }
  if (fabs(px_gran_signed_area(g->ax + n0, g->ay + n0, n - n0)) <= 1e-12 * h * h)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: contour '%s' encloses no area (its signed area is 0: a line "
                           "traced back and forth, or a figure eight whose two loops, touching "
                           "at a point, cancel)",
                           path->where, name);
  if (g->ncontours >= PX_GRAN_CONTOURS_MAX)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: contour '%s' would be contour %zu: the solver takes at most %d "
                           "contours (closed loops of all shapes together)",
                           path->where, name, g->ncontours + 1, PX_GRAN_CONTOURS_MAX);
  if (g->ncontours == g->ccap) {
    size_t cap = g->ccap ? 2 * g->ccap : 4;
    struct px_gran_contour *grown =
        px_mem_realloc(ctx, "granular geometry", g->contours, cap * sizeof *grown);
    if (!grown) return PX_STATUS_NOMEM;
    g->contours = grown;
    g->ccap = cap;
  }
  c = &g->contours[g->ncontours++];
  memset(c, 0, sizeof *c);
  snprintf(c->name, sizeof c->name, "%s", name ? name : "contour");
  c->body = body;
  c->side = side;
  c->first = n0;
  c->count = n - n0;
  g->nseg = n;
  for (k = n0; k < n; ++k) g->contour[k] = (int)(g->ncontours - 1);
  return PX_STATUS_OK;
}

static void px_gran_reverse_range(double *v, size_t n) {
  size_t i;
  for (i = 0; i < n / 2; ++i) {
    double t = v[i];
    v[i] = v[n - 1 - i];
    v[n - 1 - i] = t;
  }
}

/* Each contour's box, its depth of nesting, the side of the media, and its
 * direction: media on the left (counter-clockwise when the media is
 * inside). */
static void px_gran_geom_orient(struct px_gran_geom *g) {
  size_t c, k, d;
  /* boxes first (the nesting test below skips contours whose box is away) */
  for (c = 0; c < g->ncontours; ++c) {
    struct px_gran_contour *C = &g->contours[c];
    C->xmin = C->ymin = DBL_MAX;
    C->xmax = C->ymax = -DBL_MAX;
    for (k = C->first; k < C->first + C->count; ++k) {
      C->xmin = fmin(C->xmin, g->ax[k]);
      C->xmax = fmax(C->xmax, g->ax[k]);
      C->ymin = fmin(C->ymin, g->ay[k]);
      C->ymax = fmax(C->ymax, g->ay[k]);
    }
  }
  /* media side from nesting */
  for (c = 0; c < g->ncontours; ++c) {
    struct px_gran_contour *C = &g->contours[c];
    int depth = 0;
    for (d = 0; d < g->ncontours; ++d) {
      const struct px_gran_contour *D = &g->contours[d];
      const double px = g->ax[C->first], py = g->ay[C->first];
      if (d == c || px < D->xmin || px > D->xmax || py < D->ymin || py > D->ymax) continue;
      depth += px_gran_poly_contains(g->ax + D->first, g->ay + D->first, D->count, g->ax[C->first],
                                     g->ay[C->first]);
    }
    C->depth = depth;
    C->media_inside = C->side == PX_GRAN_SIDE_INSIDE    ? 1
                      : C->side == PX_GRAN_SIDE_OUTSIDE ? 0
                                                        : (depth % 2 == 0);
    /* media on the left: counter-clockwise when the media is inside */
    {
      const double a = px_gran_signed_area(g->ax + C->first, g->ay + C->first, C->count);
      if ((a > 0) != (C->media_inside != 0)) {
        px_gran_reverse_range(g->ax + C->first, C->count);
        px_gran_reverse_range(g->ay + C->first, C->count);
      }
    }
  }
}

/* Segment frames (direction, length, the previous direction) and joint
 * flags (convex, smooth), each contour's length and box. */
static void px_gran_geom_frames(struct px_gran_geom *g) {
  size_t c, k;
  for (c = 0; c < g->ncontours; ++c) {
    struct px_gran_contour *C = &g->contours[c];
    const size_t f = C->first, m = C->count;
    C->length = 0;
    C->xmin = C->ymin = DBL_MAX;
    C->xmax = C->ymax = -DBL_MAX;
    for (k = 0; k < m; ++k) {
      const size_t s = f + k, e = f + (k + 1) % m;
      const double dx = g->ax[e] - g->ax[s], dy = g->ay[e] - g->ay[s];
      const double L = hypot(dx, dy);
      g->len[s] = L;
      g->tx[s] = dx / L;
      g->ty[s] = dy / L;
      C->length += L;
      C->xmin = fmin(C->xmin, g->ax[s]);
      C->xmax = fmax(C->xmax, g->ax[s]);
      C->ymin = fmin(C->ymin, g->ay[s]);
      C->ymax = fmax(C->ymax, g->ay[s]);
    }
    for (k = 0; k < m; ++k) {
      const size_t s = f + k, p = f + (k + m - 1) % m;
      const double cr = g->tx[p] * g->ty[s] - g->ty[p] * g->tx[s];
      const double dt = g->tx[p] * g->tx[s] + g->ty[p] * g->ty[s];
      const double turn = atan2(cr, dt); /* > 0: left turn = concave seen from the media */
      g->tpx[s] = g->tx[p];
      g->tpy[s] = g->ty[p];
      g->flags[s] = 0;
      if (turn < -1e-12)
        g->flags[s] |= PX_GRAN_SEG_CONVEX;
      else if (turn < g->smooth_angle)
        g->flags[s] |= PX_GRAN_SEG_SMOOTH;
    }
  }
}

/* Contours must not cross each other. */
static enum px_status px_gran_geom_uncrossed(struct px_context *ctx, const struct px_gran_geom *g) {
  size_t c;
  size_t *first = px_mem_alloc(ctx, "granular crossings", 2 * g->ncontours * sizeof *first);
  struct px_gran_rings R;
  size_t hit[2][2];
  int found = 0;
  enum px_status st;
  if (!first) return PX_STATUS_NOMEM;
  for (c = 0; c < g->ncontours; ++c) {
    first[c] = g->contours[c].first;
    first[g->ncontours + c] = g->contours[c].count;
  }
  R.x = g->ax, R.y = g->ay, R.first = first, R.count = first + g->ncontours, R.n = g->ncontours;
  st = px_gran_find_cross(ctx, &R, 0, "the contours", &found, hit);
  px_mem_free(ctx, first);
  PX_TRY(st);
  if (found) {
    const size_t s = g->contours[hit[0][0]].first + hit[0][1];
    return px_context_fail(
        ctx, PX_STATUS_CONFIG, "contours '%s' and '%s' cross each other near (%g, %g)",
        g->contours[hit[0][0]].name, g->contours[hit[1][0]].name, g->ax[s], g->ay[s]);
  }
  return PX_STATUS_OK;
}

/* Segment bins of contour C in its body frame: cells of at least `cell`
 * [m], CSR of the segments that touch each cell. */
static enum px_status px_gran_contour_bins(struct px_context *ctx, const struct px_gran_geom *g,
                                           struct px_gran_contour *C, double cell) {
  size_t k;
  double h = cell > 0 && cell <= PX_GRAN_COORD_MAX ? cell : 1;
  size_t ncell, total = 0;
  int *count;
  int pass;
  /* at most ~4M cells per contour, and at most ~16 cells per segment on
   * average (segments far longer than the cell: a segment length far
   * above the particles) */
  for (;;) {
    double cover = 0;
    if (((C->xmax - C->xmin) / h + 3) * ((C->ymax - C->ymin) / h + 3) <= 4e6) {
      for (k = 0; k < C->count; ++k) {
        const size_t s = C->first + k, e = C->first + (k + 1) % C->count;
        cover += (floor((fmax(g->ax[s], g->ax[e]) - C->xmin) / h) -
                  floor((fmin(g->ax[s], g->ax[e]) - C->xmin) / h) + 1) *
                 (floor((fmax(g->ay[s], g->ay[e]) - C->ymin) / h) -
                  floor((fmin(g->ay[s], g->ay[e]) - C->ymin) / h) + 1);
      }
      if (cover <= 16.0 * (double)C->count + 4e6) break;
    }
    h *= 2;
  }
  C->bh = h;
  C->bx0 = C->xmin - h;
  C->by0 = C->ymin - h;
  C->bnx = (int)((C->xmax - C->bx0) / h) + 2;
  C->bny = (int)((C->ymax - C->by0) / h) + 2;
  ncell = (size_t)C->bnx * (size_t)C->bny;
  px_mem_free(ctx, C->bin_start);
  px_mem_free(ctx, C->bin_seg);
  C->bin_seg = NULL;
  C->bin_start = px_mem_calloc(ctx, "granular segment bins", ncell + 1, sizeof(int));
  count = px_mem_calloc(ctx, "granular segment bins", ncell + 1, sizeof(int));
  if (!C->bin_start || !count) {
    px_mem_free(ctx, count);
    return PX_STATUS_NOMEM;
  }
  /* two passes: count, then fill */
  for (pass = 0; pass < 2; ++pass) {
    for (k = 0; k < C->count; ++k) {
      const size_t s = C->first + k, e = C->first + (k + 1) % C->count;
      const int i0 = (int)((fmin(g->ax[s], g->ax[e]) - C->bx0) / h);
      const int i1 = (int)((fmax(g->ax[s], g->ax[e]) - C->bx0) / h);
      const int j0 = (int)((fmin(g->ay[s], g->ay[e]) - C->by0) / h);
      const int j1 = (int)((fmax(g->ay[s], g->ay[e]) - C->by0) / h);
      int i, j;
      for (j = j0; j <= j1; ++j)
        for (i = i0; i <= i1; ++i) {
          const size_t cc = (size_t)j * (size_t)C->bnx + (size_t)i;
          if (pass == 0)
            ++count[cc];
          else
            C->bin_seg[C->bin_start[cc] + count[cc]++] = (int)s;
        }
    }
    if (pass == 0) {
      for (k = 0; k < ncell; ++k) {
        C->bin_start[k] = (int)total;
        total += (size_t)count[k];
        count[k] = 0;
      }
      C->bin_start[ncell] = (int)total;
      C->bin_seg = px_mem_alloc(ctx, "granular segment bins", (total + 1) * sizeof(int));
      if (!C->bin_seg) {
        px_mem_free(ctx, count);
        return PX_STATUS_NOMEM;
      }
    }
  }
  px_mem_free(ctx, count);
  return PX_STATUS_OK;
}

enum px_status px_gran_geom_finish(struct px_context *ctx, struct px_gran_geom *g, double cell) {
  size_t c;
  if (g->ncontours == 0)
    return px_context_fail(ctx, PX_STATUS_CONFIG, "the geometry has no contours");
  px_gran_geom_orient(g);
  px_gran_geom_frames(g);
  PX_TRY(px_gran_geom_uncrossed(ctx, g));
  for (c = 0; c < g->ncontours; ++c) {
    PX_TRY(px_gran_contour_bins(ctx, g, &g->contours[c], cell));
    PX_TRY(px_gran_contour_strips(ctx, g, &g->contours[c]));
  }
  return PX_STATUS_OK;
}
