/* Radius distributions and filling of the media region. */
#include "solvers/granular/media.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "partix/memory.h"
#include "partix/rng.h"
#include "solvers/granular/wall_kernel.h"

#define PX_GRAN_PI 3.14159265358979323846

double px_gran_dist_draw(const struct px_gran_dist_spec *d, uint64_t rng[4]) {
  switch (d->kind) {
    case PX_GRAN_DIST_NORMAL: {
      int tries;
      for (tries = 0; tries < 1000; ++tries) {
        const double r = d->mean + d->sd * px_rng_normal(rng);
        if (r >= d->min && r <= d->max) return r;
      }
      return d->mean;
    }
    case PX_GRAN_DIST_DISCRETE: {
      double total = 0, u;
      size_t k;
      for (k = 0; k < d->n; ++k) total += d->weights[k];
      u = px_rng_uniform(rng) * total;
      for (k = 0; k + 1 < d->n; ++k) {
        if (u < d->weights[k]) return d->radii[k];
        u -= d->weights[k];
      }
      return d->radii[d->n - 1];
    }
    default: return d->min + (d->max - d->min) * px_rng_uniform(rng);
  }
}

double px_gran_dist_rmax(const struct px_gran_dist_spec *d) {
  if (d->kind == PX_GRAN_DIST_DISCRETE) {
    double m = 0;
    size_t k;
    for (k = 0; k < d->n; ++k)
      if (d->radii[k] > m) m = d->radii[k];
    return m;
  }
  return d->max;
}

double px_gran_dist_rmin(const struct px_gran_dist_spec *d) {
  if (d->kind == PX_GRAN_DIST_DISCRETE) {
    double m = DBL_MAX;
    size_t k;
    for (k = 0; k < d->n; ++k)
      if (d->radii[k] < m) m = d->radii[k];
    return m;
  }
  return d->min;
}

double px_gran_dist_mean_area(const struct px_gran_dist_spec *d) {
  switch (d->kind) {
    case PX_GRAN_DIST_DISCRETE: {
      double tw = 0, a = 0;
      size_t k;
      for (k = 0; k < d->n; ++k) {
        tw += d->weights[k];
        a += d->weights[k] * d->radii[k] * d->radii[k];
      }
      return PX_GRAN_PI * a / tw;
    }
    case PX_GRAN_DIST_NORMAL: {
      uint64_t rng[4];
      double a = 0;
      int k;
      px_rng_seed(rng, 7);
      for (k = 0; k < 20000; ++k) {
        const double r = px_gran_dist_draw(d, rng);
        a += r * r;
      }
      return PX_GRAN_PI * a / 20000;
    }
    default: /* <r^2> of a uniform distribution */
      return PX_GRAN_PI * (d->max * d->max + d->max * d->min + d->min * d->min) / 3;
  }
}

double px_gran_geom_free_area(const struct px_gran_geom *g) {
  double a = 0;
  size_t c, k;
  for (c = 0; c < g->ncontours; ++c) {
    const struct px_gran_contour *C = &g->contours[c];
    double s = 0;
    for (k = 0; k < C->count; ++k) {
      const size_t i = C->first + k, j = C->first + (k + 1) % C->count;
      s += g->ax[i] * g->ay[j] - g->ax[j] * g->ay[i];
    }
    /* oriented with the media on the left: + for media inside, - outside */
    a += 0.5 * s;
  }
  return a;
}

/* Spatial hash of placed discs for the overlap test of random filling. */
struct px_gran_hash {
  double x0, y0, h;
  int nx, ny;
  int32_t *head, *next;
};

static int px_gran_hash_cell(const struct px_gran_hash *H, double x, double y, int *i, int *j) {
  const double fi = floor((x - H->x0) / H->h), fj = floor((y - H->y0) / H->h);
  if (!(fi >= 0) || !(fj >= 0) || !(fi < (double)H->nx) || !(fj < (double)H->ny)) return 0;
  *i = (int)fi;
  *j = (int)fj;
  return 1;
}

/* Is a disc at (x, y) of radius r clear of the media boundary? */
static int px_gran_site_ok(const struct px_gran_geom *g, const double *frames, double x, double y,
                           double r, const double *window) {
  if (window && (x < window[0] || y < window[1] || x > window[2] || y > window[3])) return 0;
  if (!px_gran_geom_inside(g, frames, x, y)) return 0;
  return px_gran_geom_distance(g, frames, x, y, r * 1.01) >= r * 1.01;
}

struct px_gran_site {
  double x, y, key;
};

static int px_gran_site_cmp(const void *a, const void *b) {
  const struct px_gran_site *p = a, *q = b;
  if (p->key != q->key) return p->key < q->key ? -1 : 1;
  if (p->x != q->x) return p->x < q->x ? -1 : 1;
  return p->y < q->y ? -1 : (p->y > q->y);
}

/* The world box of the region to fill ([xmin, ymin, xmax, ymax]: the
 * contours', cut by the window) and the number of discs (count, or from the
 * fraction of the free area; the window's share of it sampled with rng,
 * seeded by the caller). */
static enum px_status px_gran_fill_plan(struct px_context *ctx, const struct px_gran_geom *g,
                                        const double *frames, const struct px_gran_dist_spec *dist,
                                        const struct px_gran_fill_spec *fill, uint64_t rng[4],
                                        double box[4], size_t *nout) {
  double xmin = DBL_MAX, ymin = DBL_MAX, xmax = -DBL_MAX, ymax = -DBL_MAX, nd;
  size_t c, k;
  *nout = 0;
  /* world bounding box of the contours whose media is inside */
  for (c = 0; c < g->ncontours; ++c) {
    const struct px_gran_contour *C = &g->contours[c];
    for (k = C->first; k < C->first + C->count; ++k) {
      const double *f = frames + c * PX_GRAN_CTR_COUNT;
      const double ux = g->ax[k] - f[PX_GRAN_CTR_PX], uy = g->ay[k] - f[PX_GRAN_CTR_PY];
      const double wx =
          f[PX_GRAN_CTR_PX] + f[PX_GRAN_CTR_COS] * ux - f[PX_GRAN_CTR_SIN] * uy + f[PX_GRAN_CTR_DX];
      const double wy =
          f[PX_GRAN_CTR_PY] + f[PX_GRAN_CTR_SIN] * ux + f[PX_GRAN_CTR_COS] * uy + f[PX_GRAN_CTR_DY];
      if (wx < xmin) xmin = wx;
      if (wx > xmax) xmax = wx;
      if (wy < ymin) ymin = wy;
      if (wy > ymax) ymax = wy;
    }
  }
  if (fill->window) {
    xmin = fmax(xmin, fill->window[0]);
    ymin = fmax(ymin, fill->window[1]);
    xmax = fmin(xmax, fill->window[2]);
    ymax = fmin(ymax, fill->window[3]);
  }
  if (fill->window &&
      (!(fill->window[2] > fill->window[0]) || !(fill->window[3] > fill->window[1])))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "window [%g, %g, %g, %g]: needs xmin < xmax and ymin < ymax",
                           fill->window[0], fill->window[1], fill->window[2], fill->window[3]);
  if (!(xmax > xmin) || !(ymax > ymin))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "window [%g, %g, %g, %g]: holds no part of the contours",
                           fill->window ? fill->window[0] : 0, fill->window ? fill->window[1] : 0,
                           fill->window ? fill->window[2] : 0, fill->window ? fill->window[3] : 0);
  box[0] = xmin, box[1] = ymin, box[2] = xmax, box[3] = ymax;
  /* how many */
  if (fill->count > 0) {
    nd = (double)fill->count;
  } else {
    double area = px_gran_geom_free_area(g);
    if (fill->window) {
      /* estimate the free area inside the window by sampling */
      size_t in = 0, m = 200000;
      for (k = 0; k < m; ++k) {
        const double px = xmin + (xmax - xmin) * px_rng_uniform(rng);
        const double py = ymin + (ymax - ymin) * px_rng_uniform(rng);
        in += (size_t)px_gran_geom_inside(g, frames, px, py);
      }
      area = (xmax - xmin) * (ymax - ymin) * (double)in / (double)m;
    }
    nd = floor(fill->fraction * area / px_gran_dist_mean_area(dist));
    if (!(nd >= 1))
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "fill fraction %g of the free area %g m^2 gives no particle",
                             fill->fraction, area);
  }
  if (!(nd <= PX_GRAN_N_MAX))
    return px_context_fail(
        ctx, PX_STATUS_CONFIG, "%.4g discs%s: more than the %.0e discs the solver takes", nd,
        fill->count > 0 ? "" : " (the fraction of the free area)", PX_GRAN_N_MAX);
  *nout = (size_t)nd;
  return PX_STATUS_OK;
}

enum px_status px_gran_fill_count(struct px_context *ctx, const struct px_gran_geom *g,
                                  const double *frames, const struct px_gran_dist_spec *dist,
                                  const struct px_gran_fill_spec *fill, size_t *n) {
  uint64_t rng[4];
  double box[4];
  px_rng_seed(rng, fill->seed);
  return px_gran_fill_plan(ctx, g, frames, dist, fill, rng, box, n);
}

/* Hexagonal lattice filling of n discs into x, y, r (n each). */
static enum px_status px_gran_fill_lattice(struct px_context *ctx, const struct px_gran_geom *g,
                                           const double *frames,
                                           const struct px_gran_dist_spec *dist,
                                           const struct px_gran_fill_spec *fill, uint64_t rng[4],
                                           const double box[4], size_t n, double *x, double *y,
                                           double *r) {
  const double xmin = box[0], ymin = box[1], xmax = box[2], ymax = box[3];
  const double rmax = px_gran_dist_rmax(dist);
  size_t k;
  enum px_status st;
  /* hexagonal lattice: rows along the horizontal (perpendicular to down),
   * taken lowest row first. Row b's sites all have the key b * rowh -
   * c.down, so rows are scanned upwards from the lowest row that meets the
   * box, each only where it lies in the box, and the scan stops after the
   * row that completes n sites: the rows above would all sort after them. */
  const double pitch = 2 * rmax * (1 + fill->gap);
  const double rowh = pitch * sqrt(3.0) / 2;
  const double dx = fill->down[0], dy = fill->down[1];
  const double dn = hypot(dx, dy);
  const double ux = dn > 0 ? dx / dn : 0, uy = dn > 0 ? dy / dn : -1; /* down */
  const double vx = -uy, vy = ux;                                     /* along rows */
  const double R = hypot(xmax - xmin, ymax - ymin), cx = 0.5 * (xmin + xmax),
               cy = 0.5 * (ymin + ymax);
  struct px_gran_site *sites = NULL;
  size_t ns = 0, cap = 0;
  double tested = 0;
  long a, b, nrow, ncol;
  if (!(R / rowh <= 1e8) || !(R / pitch <= 1e8)) {
    st = px_context_fail(ctx, PX_STATUS_CONFIG,
                         "a lattice of pitch %g m over the contours' %g m x %g m: more than "
                         "1e8 rows or columns",
                         pitch, xmax - xmin, ymax - ymin);
    return st;
  }
  nrow = (long)(R / rowh) + 2;
  ncol = (long)(R / pitch) + 2;
  for (b = -nrow; b <= nrow && ns < n; ++b) {
    const double t = (double)b * rowh, off = (b & 1) ? 0.5 * pitch : 0;
    /* columns whose site lies in the box: px = cx - t ux + s vx in
     * [xmin, xmax], likewise y, with s = a pitch + off */
    double s0 = -DBL_MAX, s1 = DBL_MAX;
    long a0, a1;
    if (vx != 0) {
      const double p = (xmin - cx + t * ux) / vx, q = (xmax - cx + t * ux) / vx;
      s0 = fmax(s0, fmin(p, q)), s1 = fmin(s1, fmax(p, q));
    } else if (cx - t * ux < xmin || cx - t * ux > xmax) {
      continue;
    }
    if (vy != 0) {
      const double p = (ymin - cy + t * uy) / vy, q = (ymax - cy + t * uy) / vy;
      s0 = fmax(s0, fmin(p, q)), s1 = fmin(s1, fmax(p, q));
    } else if (cy - t * uy < ymin || cy - t * uy > ymax) {
      continue;
    }
    if (!(s1 >= s0)) continue;
    /* one column of margin each side: the exact box test below decides */
    a0 = (long)fmax(-(double)ncol, floor((s0 - off) / pitch) - 1);
    a1 = (long)fmin((double)ncol, ceil((s1 - off) / pitch) + 1);
    for (a = a0; a <= a1; ++a) {
      const double s = (double)a * pitch + off;
      const double px = cx + s * vx - t * ux, py = cy + s * vy - t * uy;
      if (px < xmin || px > xmax || py < ymin || py > ymax) continue;
      if (++tested > PX_GRAN_SITES_MAX) {
        px_mem_free(ctx, sites);
        st = px_context_fail(ctx, PX_STATUS_CONFIG,
                             "the lattice filling tested %.0e sites of pitch %g m and found "
                             "%zu of the %zu asked for; use fill: random, or a window",
                             PX_GRAN_SITES_MAX, pitch, ns, n);
        return st;
      }
      if (!px_gran_site_ok(g, frames, px, py, rmax, fill->window)) continue;
      if (ns == cap) {
        size_t nc = cap ? 2 * cap : 1024;
        struct px_gran_site *gs = px_mem_realloc(ctx, "granular fill", sites, nc * sizeof *gs);
        if (!gs) {
          px_mem_free(ctx, sites);
          st = PX_STATUS_NOMEM;
          return st;
        }
        sites = gs;
        cap = nc;
      }
      sites[ns].x = px;
      sites[ns].y = py;
      /* lowest first along "down" (largest projection on down), then along the row */
      sites[ns].key = -(px * ux + py * uy);
      ++ns;
    }
  }
  if (ns < n) {
    px_mem_free(ctx, sites);
    st = px_context_fail(ctx, PX_STATUS_CONFIG,
                         "the free region holds only %zu lattice sites of pitch %g m for the "
                         "%zu particles asked for (largest radius %g m); lower the count or "
                         "the fraction, or use fill: random",
                         ns, pitch, n, rmax);
    return st;
  }
  qsort(sites, ns, sizeof *sites, px_gran_site_cmp);
  for (k = 0; k < n; ++k) {
    x[k] = sites[k].x;
    y[k] = sites[k].y;
    r[k] = px_gran_dist_draw(dist, rng);
  }
  px_mem_free(ctx, sites);
  return PX_STATUS_OK;
}

/* Random sequential addition of n discs into x, y, r (n each). */
static enum px_status px_gran_fill_random(struct px_context *ctx, const struct px_gran_geom *g,
                                          const double *frames,
                                          const struct px_gran_dist_spec *dist,
                                          const struct px_gran_fill_spec *fill, uint64_t rng[4],
                                          const double box[4], size_t n, double *x, double *y,
                                          double *r) {
  const double xmin = box[0], ymin = box[1], xmax = box[2], ymax = box[3];
  const double rmax = px_gran_dist_rmax(dist);
  enum px_status st;
  /* random sequential addition with a cell hash (cell = 2 r_max) */
  struct px_gran_hash H;
  const size_t max_tries = 2000 * n + 100000;
  size_t tries = 0, k, placed = 0;
  /* cells of at least 2 r_max (discs that overlap lie in neighbouring
   * cells), coarser while there would be more than ~4 per disc */
  H.h = 2 * rmax;
  while (!(((xmax - xmin) / H.h + 1) * ((ymax - ymin) / H.h + 1) <= 4.0 * (double)n + 1024))
    H.h *= 2;
  H.x0 = xmin;
  H.y0 = ymin;
  H.nx = (int)((xmax - xmin) / H.h) + 1;
  H.ny = (int)((ymax - ymin) / H.h) + 1;
  H.head = px_mem_alloc(ctx, "granular fill", (size_t)H.nx * (size_t)H.ny * sizeof(int32_t));
  H.next = px_mem_alloc(ctx, "granular fill", n * sizeof(int32_t));
  if (!H.head || !H.next) {
    px_mem_free(ctx, H.head);
    px_mem_free(ctx, H.next);
    st = PX_STATUS_NOMEM;
    return st;
  }
  for (k = 0; k < (size_t)H.nx * (size_t)H.ny; ++k) H.head[k] = -1;
  while (placed < n && tries < max_tries) {
    const double rr = px_gran_dist_draw(dist, rng);
    const double px = xmin + (xmax - xmin) * px_rng_uniform(rng);
    const double py = ymin + (ymax - ymin) * px_rng_uniform(rng);
    int ci, cj, a, b, ok = 1;
    ++tries;
    if (!px_gran_hash_cell(&H, px, py, &ci, &cj)) continue;
    for (b = cj - 1; b <= cj + 1 && ok; ++b)
      for (a = ci - 1; a <= ci + 1 && ok; ++a) {
        int32_t q;
        if (a < 0 || b < 0 || a >= H.nx || b >= H.ny) continue;
        for (q = H.head[b * H.nx + a]; q >= 0; q = H.next[q])
          if (hypot(x[q] - px, y[q] - py) < (r[q] + rr) * 1.001) {
            ok = 0;
            break;
          }
      }
    if (!ok || !px_gran_site_ok(g, frames, px, py, rr, fill->window)) continue;
    x[placed] = px;
    y[placed] = py;
    r[placed] = rr;
    H.next[placed] = H.head[cj * H.nx + ci];
    H.head[cj * H.nx + ci] = (int32_t)placed;
    ++placed;
  }
  px_mem_free(ctx, H.head);
  px_mem_free(ctx, H.next);
  if (placed < n) {
    st = px_context_fail(ctx, PX_STATUS_CONFIG,
                         "random filling placed only %zu of %zu particles in %zu tries (random "
                         "sequential addition jams near a disc-area fraction of 0.5); lower the "
                         "count or the fraction, or use fill: lattice",
                         placed, n, tries);
    return st;
  }
  return PX_STATUS_OK;
}

enum px_status px_gran_fill(struct px_context *ctx, const struct px_gran_geom *g,
                            const double *frames, const struct px_gran_dist_spec *dist,
                            const struct px_gran_fill_spec *fill, double **xo, double **yo,
                            double **ro, size_t *no) {
  uint64_t rng[4];
  double box[4];
  size_t n;
  double *x = NULL, *y = NULL, *r = NULL;
  enum px_status st = PX_STATUS_OK;
  *xo = *yo = *ro = NULL;
  *no = 0;
  px_rng_seed(rng, fill->seed);
  PX_TRY(px_gran_fill_plan(ctx, g, frames, dist, fill, rng, box, &n));
  x = px_mem_alloc(ctx, "granular fill", n * sizeof *x);
  y = px_mem_alloc(ctx, "granular fill", n * sizeof *y);
  r = px_mem_alloc(ctx, "granular fill", n * sizeof *r);
  if (!x || !y || !r) {
    st = PX_STATUS_NOMEM;
    goto done;
  }
  if (fill->method == PX_GRAN_FILL_LATTICE)
    st = px_gran_fill_lattice(ctx, g, frames, dist, fill, rng, box, n, x, y, r);
  else
    st = px_gran_fill_random(ctx, g, frames, dist, fill, rng, box, n, x, y, r);
  if (st != PX_STATUS_OK) goto done;
  *xo = x;
  *yo = y;
  *ro = r;
  *no = n;
  return PX_STATUS_OK;
done:
  px_mem_free(ctx, x);
  px_mem_free(ctx, y);
  px_mem_free(ctx, r);
  return st;
}
