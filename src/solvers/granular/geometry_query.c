/* Region queries on a finished geometry: body frames, inside the media
 * region (through the contours' strips, built here), segments near a point
 * (bins), distance to the walls, arc length along a contour. */
#include "solvers/granular/geometry.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/memory.h"
#include "solvers/granular/wall_kernel.h"

void px_gran_geom_to_local(const double *f, double x, double y, double *lx, double *ly) {
  const double ux = x - f[PX_GRAN_CTR_PX] - f[PX_GRAN_CTR_DX];
  const double uy = y - f[PX_GRAN_CTR_PY] - f[PX_GRAN_CTR_DY];
  *lx = f[PX_GRAN_CTR_PX] + f[PX_GRAN_CTR_COS] * ux + f[PX_GRAN_CTR_SIN] * uy;
  *ly = f[PX_GRAN_CTR_PY] - f[PX_GRAN_CTR_SIN] * ux + f[PX_GRAN_CTR_COS] * uy;
}

/* The strip of y (clamped): floor is monotonic, so an edge whose y-range
 * holds y is listed in y's strip. */
static int px_gran_strip_of(const struct px_gran_contour *C, double y) {
  const double f = floor((y - C->sy0) / C->sh);
  if (!(f > 0)) return 0; /* NaN too */
  return f < (double)(C->sny - 1) ? (int)f : C->sny - 1;
}

int px_gran_contour_contains(const struct px_gran_geom *g, size_t c, double lx, double ly) {
  const struct px_gran_contour *C = &g->contours[c];
  const double *x = g->ax + C->first, *y = g->ay + C->first;
  const size_t n = C->count;
  int q, in = 0;
  if (!C->strip_start) return px_gran_poly_contains(x, y, n, lx, ly);
  {
    const int j = px_gran_strip_of(C, ly);
    /* the edges px_gran_poly_contains counts are those with min y <= ly <
     * max y: all in this strip; the same test and crossing, in another
     * order (the parity does not depend on it) */
    for (q = C->strip_start[j]; q < C->strip_start[j + 1]; ++q) {
      const size_t k = (size_t)C->strip_seg[q];
      if (px_gran_ray_crosses(x, y, k, (k + 1) % n, lx, ly)) in = !in;
    }
  }
  return in;
}

/* Strips of contour C: about one per two edges, fewer while the edges
 * would be listed more than 8 times each on average (long slanted edges). */
enum px_status px_gran_contour_strips(struct px_context *ctx, struct px_gran_geom *g,
                                      struct px_gran_contour *C) {
  const double *y = g->ay + C->first;
  const size_t n = C->count;
  size_t k, total;
  int ns = n / 2 > 1 ? (n / 2 < 65536 ? (int)(n / 2) : 65536) : 1, pass, *count;
  px_mem_free(ctx, C->strip_start);
  px_mem_free(ctx, C->strip_seg);
  C->strip_start = C->strip_seg = NULL;
  if (!(C->ymax > C->ymin)) return PX_STATUS_OK; /* flat: the plain test */
  for (;;) {
    C->sny = ns;
    C->sy0 = C->ymin;
    C->sh = (C->ymax - C->ymin) / ns;
    total = 0;
    for (k = 0; k < n; ++k) {
      const double a = y[k], b = y[(k + 1) % n];
      if (a != b)
        total += (size_t)(px_gran_strip_of(C, fmax(a, b)) - px_gran_strip_of(C, fmin(a, b)) + 1);
    }
    if (total <= 8 * n + 64 || ns == 1) break;
    ns /= 2;
  }
  C->strip_start = px_mem_calloc(ctx, "granular contour strips", (size_t)ns + 1, sizeof(int));
  count = px_mem_calloc(ctx, "granular contour strips", (size_t)ns + 1, sizeof(int));
  C->strip_seg = px_mem_alloc(ctx, "granular contour strips", (total + 1) * sizeof(int));
  if (!C->strip_start || !count || !C->strip_seg) {
    px_mem_free(ctx, count);
    return PX_STATUS_NOMEM;
  }
  for (pass = 0; pass < 2; ++pass) {
    int j;
    for (k = 0; k < n; ++k) {
      const double a = y[k], b = y[(k + 1) % n];
      if (a == b) continue; /* never crossed by a horizontal ray */
      for (j = px_gran_strip_of(C, fmin(a, b)); j <= px_gran_strip_of(C, fmax(a, b)); ++j)
        if (pass == 0)
          ++count[j];
        else
          C->strip_seg[C->strip_start[j] + count[j]++] = (int)k;
    }
    if (pass == 0) {
      int acc = 0;
      for (j = 0; j < ns; ++j) {
        C->strip_start[j] = acc;
        acc += count[j];
        count[j] = 0;
      }
      C->strip_start[ns] = acc;
    }
  }
  px_mem_free(ctx, count);
  return PX_STATUS_OK;
}

int px_gran_geom_inside(const struct px_gran_geom *g, const double *frames, double x, double y) {
  /* the innermost contour around the point decides; around none, the point
   * is in the media only if no contour holds the media inside (an open
   * domain around parts) */
  size_t c;
  int best = -1, bestc = -1, any_inside = 0;
  for (c = 0; c < g->ncontours; ++c) {
    const struct px_gran_contour *C = &g->contours[c];
    double lx, ly;
    any_inside |= C->media_inside;
    px_gran_geom_to_local(frames + c * PX_GRAN_CTR_COUNT, x, y, &lx, &ly);
    if (lx < C->xmin || lx > C->xmax || ly < C->ymin || ly > C->ymax) continue;
    if (px_gran_contour_contains(g, c, lx, ly) && C->depth > best) {
      best = C->depth;
      bestc = (int)c;
    }
  }
  if (bestc < 0) return !any_inside;
  return g->contours[bestc].media_inside != 0;
}

/* Distance from (px, py) to segment s. */
static double px_gran_seg_distance(const struct px_gran_geom *g, size_t s, double px, double py) {
  const double rx = px - g->ax[s], ry = py - g->ay[s];
  double u = rx * g->tx[s] + ry * g->ty[s];
  if (u < 0) u = 0;
  if (u > g->len[s]) u = g->len[s];
  return hypot(rx - u * g->tx[s], ry - u * g->ty[s]);
}

/* Cells [*a, *b] of a bin row or column (n cells of size h from origin)
 * that [lo, hi] overlaps, clamped in floating point before any conversion
 * (a point far away or not finite has none); 0 when there are none. */
static int px_gran_bin_span(double lo, double hi, double origin, double h, int n, int *a, int *b) {
  const double f0 = floor((lo - origin) / h), f1 = floor((hi - origin) / h);
  if (!(f1 >= 0) || !(f0 <= (double)(n - 1))) return 0;
  *a = f0 > 0 ? (int)f0 : 0;
  *b = f1 < (double)(n - 1) ? (int)f1 : n - 1;
  return 1;
}

int px_gran_geom_near(const struct px_gran_geom *g, size_t c, double lx, double ly, double range,
                      int *out, int cap) {
  const struct px_gran_contour *C = &g->contours[c];
  int i0, i1, j0, j1;
  int i, j, n = 0;
  if (!px_gran_bin_span(lx - range, lx + range, C->bx0, C->bh, C->bnx, &i0, &i1) ||
      !px_gran_bin_span(ly - range, ly + range, C->by0, C->bh, C->bny, &j0, &j1))
    return 0;
  for (j = j0; j <= j1; ++j)
    for (i = i0; i <= i1; ++i) {
      const size_t cc = (size_t)j * (size_t)C->bnx + (size_t)i;
      int q;
      for (q = C->bin_start[cc]; q < C->bin_start[cc + 1]; ++q) {
        const int s = C->bin_seg[q];
        int a, dup = 0;
        if (px_gran_seg_distance(g, (size_t)s, lx, ly) >= range) continue;
        /* insertion into the sorted unique list */
        for (a = 0; a < n; ++a)
          if (out[a] == s) {
            dup = 1;
            break;
          }
        if (dup) continue;
        if (n == cap) return -1;
        a = n++;
        while (a > 0 && out[a - 1] > s) {
          out[a] = out[a - 1];
          --a;
        }
        out[a] = s;
      }
    }
  return n;
}

double px_gran_geom_distance(const struct px_gran_geom *g, const double *frames, double x, double y,
                             double range) {
  double best = range;
  size_t c;
  for (c = 0; c < g->ncontours; ++c) {
    const struct px_gran_contour *C = &g->contours[c];
    double lx, ly;
    int i0, i1, j0, j1, i, j;
    px_gran_geom_to_local(frames + c * PX_GRAN_CTR_COUNT, x, y, &lx, &ly);
    if (!px_gran_bin_span(lx - range, lx + range, C->bx0, C->bh, C->bnx, &i0, &i1) ||
        !px_gran_bin_span(ly - range, ly + range, C->by0, C->bh, C->bny, &j0, &j1))
      continue;
    for (j = j0; j <= j1; ++j)
      for (i = i0; i <= i1; ++i) {
        const size_t cc = (size_t)j * (size_t)C->bnx + (size_t)i;
        int q;
        for (q = C->bin_start[cc]; q < C->bin_start[cc + 1]; ++q) {
          const double d = px_gran_seg_distance(g, (size_t)C->bin_seg[q], lx, ly);
          if (d < best) best = d;
        }
      }
  }
  return best;
}

void px_gran_geom_arclength(const struct px_gran_geom *g, size_t c, double *s) {
  const struct px_gran_contour *C = &g->contours[c];
  double acc = 0;
  size_t k;
  for (k = 0; k < C->count; ++k) {
    s[k] = acc + 0.5 * g->len[C->first + k];
    acc += g->len[C->first + k];
  }
}
