/* Plane sections of a closed triangle mesh (geo_mesh.h).
 *
 * Each vertex is on the positive side of the plane (signed distance
 * d >= 0) or the negative one, so that every edge is crossed or not, never
 * "touched": a triangle then has no crossed side or exactly two, and gives
 * one segment from the crossing of its side that runs from + to - to that
 * of its side that runs from - to +. With the triangle counter-clockwise
 * seen from outside that segment runs along n x (outward normal), i.e.
 * counter-clockwise around the material in the (u, v) plane: outer
 * boundaries come out counter-clockwise and holes clockwise. A crossed edge
 * is shared by two triangles, as the end of one segment and the start of
 * another, so following edge to edge closes every loop on a closed manifold
 * mesh whatever vertices lie on the plane. A vertex on the plane gives its
 * own coordinates exactly to every edge crossed there; the repeated points
 * and the there-and-back spikes that makes are removed, a loop left with
 * no area dropped (the plane touches the part at a point or an edge), and
 * two loops through the same points in opposite directions dropped both
 * (the plane touches the part along a ring of edges: the limit of a thin
 * annulus). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/geometry/geo_mesh.h"
#include "partix/memory.h"

#define LABEL "mesh section"

struct work {
  double *d, *X, *Y; /* per vertex: signed distance [units], plane coordinates */
  double *cx, *cy;   /* per edge: the crossing point */
  size_t *next;      /* per edge: the crossed edge the segment from it leads to */
  unsigned char *seen;
  double *px, *py; /* one loop's points */
};

static void work_free(struct px_context *ctx, struct work *w) {
  px_mem_free(ctx, w->d);
  px_mem_free(ctx, w->X);
  px_mem_free(ctx, w->Y);
  px_mem_free(ctx, w->cx);
  px_mem_free(ctx, w->cy);
  px_mem_free(ctx, w->next);
  px_mem_free(ctx, w->seen);
  px_mem_free(ctx, w->px);
  px_mem_free(ctx, w->py);
}

static int same(const struct work *w, size_t i, size_t j) {
  return w->px[i] == w->px[j] && w->py[i] == w->py[j];
}

static void copy_point(struct work *w, size_t to, size_t from) {
  w->px[to] = w->px[from];
  w->py[to] = w->py[from];
}

/* Removes repeated points and spikes (A B A -> A) from the closed loop of
 * n points, cyclically; returns the count left, from index *first on. */
static size_t clean_loop(struct work *w, size_t n, size_t *first) {
  size_t m = 0;
  for (size_t i = 0; i < n; ++i) {
    copy_point(w, m++, i);
    for (;;) {
      if (m >= 2 && same(w, m - 1, m - 2))
        m -= 1;
      else if (m >= 3 && same(w, m - 1, m - 3))
        m -= 2;
      else
        break;
    }
  }
  size_t s = 0;
  for (;;) {
    const size_t k = m - s;
    if (k >= 2 && same(w, m - 1, s))
      m -= 1;
    else if (k >= 3 && same(w, m - 2, s))
      m -= 2; /* ... A B | A: B is a spike */
    else if (k >= 3 && same(w, m - 1, s + 1))
      s += 2; /* B | A B ...: A is a spike */
    else
      break;
  }
  *first = s;
  return m - s;
}

/* Crossing points of the crossed edges and the segment links. */
static void link_segments(const struct px_geo_mesh *m, struct work *w) {
  for (size_t e = 0; e < m->ne; ++e) {
    const size_t a = m->ev[2 * e], b = m->ev[2 * e + 1];
    w->next[e] = SIZE_MAX;
    if ((w->d[a] >= 0) == (w->d[b] >= 0)) continue;
    if (w->d[a] == 0) {
      w->cx[e] = w->X[a];
      w->cy[e] = w->Y[a];
    } else if (w->d[b] == 0) {
      w->cx[e] = w->X[b];
      w->cy[e] = w->Y[b];
    } else {
      const double t = w->d[a] / (w->d[a] - w->d[b]);
      w->cx[e] = w->X[a] + t * (w->X[b] - w->X[a]);
      w->cy[e] = w->Y[a] + t * (w->Y[b] - w->Y[a]);
    }
  }
  for (size_t t = 0; t < m->nt; ++t) {
    size_t from = SIZE_MAX, to = SIZE_MAX;
    for (size_t k = 0; k < 3; ++k) {
      const int pa = w->d[m->tri[3 * t + k]] >= 0, pb = w->d[m->tri[3 * t + (k + 1) % 3]] >= 0;
      if (pa && !pb) from = m->edge[3 * t + k];
      if (!pa && pb) to = m->edge[3 * t + k];
    }
    if (from != SIZE_MAX && to != SIZE_MAX) w->next[from] = to;
  }
}

/* Appends the loop's points (from index first) to *out as a polyline. */
static enum px_status emit(struct px_context *ctx, const struct px_geo_mesh *m,
                           const struct work *w, size_t first, size_t n, double offset,
                           struct px_geo_polyline **out, size_t *n_out) {
  struct px_geo_polyline *o = px_mem_realloc(ctx, LABEL, *out, (*n_out + 1) * sizeof **out);
  if (!o) return PX_STATUS_NOMEM;
  *out = o;
  struct px_geo_polyline *p = o + *n_out;
  memset(p, 0, sizeof *p);
  PX_TRY(px_geo_polyline_alloc(ctx, p, n, 0));
  memcpy(p->x, w->px + first, n * sizeof(double));
  memcpy(p->y, w->py + first, n * sizeof(double));
  snprintf(p->source, sizeof p->source, "%.200s section at %g", m->source, offset);
  ++*n_out;
  return PX_STATUS_OK;
}

static enum px_status trace(struct px_context *ctx, const struct px_geo_mesh *m, struct work *w,
                            double offset, struct px_geo_polyline **out, size_t *n_out) {
  for (size_t e0 = 0; e0 < m->ne; ++e0) {
    if (w->next[e0] == SIZE_MAX || w->seen[e0]) continue;
    size_t n = 0, e = e0;
    do {
      w->seen[e] = 1;
      w->px[n] = w->cx[e];
      w->py[n++] = w->cy[e];
      e = w->next[e];
    } while (e != SIZE_MAX && e != e0 && !w->seen[e] && n < m->ne);
    if (e != e0)
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "%s: the section at %g does not close (the mesh's edge table does "
                             "not match its triangles: px_geo_mesh_check must pass first)",
                             m->source, offset);
    size_t first;
    n = clean_loop(w, n, &first);
    if (n < 3) continue;
    double area = 0;
    for (size_t i = 0; i < n; ++i) {
      const size_t a = first + i, b = first + (i + 1) % n;
      area += w->px[a] * w->py[b] - w->px[b] * w->py[a];
    }
    if (area == 0) continue;
    PX_TRY(emit(ctx, m, w, first, n, offset, out, n_out));
  }
  return PX_STATUS_OK;
}

/* 1 if b runs through a's points in the opposite direction. */
static int reversed(const struct px_geo_polyline *a, const struct px_geo_polyline *b) {
  if (a->n != b->n) return 0;
  size_t s = 0;
  while (s < b->n && (b->x[s] != a->x[0] || b->y[s] != a->y[0])) ++s;
  if (s == b->n) return 0;
  for (size_t k = 0; k < a->n; ++k) {
    const size_t j = (s + b->n - k % b->n) % b->n;
    if (a->x[k] != b->x[j] || a->y[k] != b->y[j]) return 0;
  }
  return 1;
}

/* Drops the pairs of loops that cancel (a ring of edges on the plane). */
static void cancel_pairs(struct px_context *ctx, struct px_geo_polyline *p, size_t *n) {
  for (size_t i = 0; i < *n; ++i)
    for (size_t j = i + 1; j < *n; ++j) {
      if (!reversed(&p[i], &p[j])) continue;
      px_geo_polyline_free(ctx, &p[j]);
      px_geo_polyline_free(ctx, &p[i]);
      p[j] = p[--*n];
      p[i] = p[--*n];
      --i;
      break;
    }
}

enum px_status px_geo_mesh_slice(struct px_context *ctx, const struct px_geo_mesh *m,
                                 const double u[3], const double v[3], const double n[3],
                                 double offset, struct px_geo_polyline **out, size_t *n_out) {
  *out = NULL;
  *n_out = 0;
  if (!m->edge || m->ne == 0)
    return px_context_fail(ctx, PX_STATUS_INVALID, "%s: slicing a mesh that was not checked",
                           m->source);
  struct work w = {0};
  const size_t nv = m->nv + 1, ne = m->ne + 1;
  w.d = px_mem_alloc(ctx, LABEL, nv * sizeof(double));
  w.X = px_mem_alloc(ctx, LABEL, nv * sizeof(double));
  w.Y = px_mem_alloc(ctx, LABEL, nv * sizeof(double));
  w.cx = px_mem_alloc(ctx, LABEL, ne * sizeof(double));
  w.cy = px_mem_alloc(ctx, LABEL, ne * sizeof(double));
  w.next = px_mem_alloc(ctx, LABEL, ne * sizeof(size_t));
  w.seen = px_mem_calloc(ctx, LABEL, ne, 1);
  w.px = px_mem_alloc(ctx, LABEL, ne * sizeof(double));
  w.py = px_mem_alloc(ctx, LABEL, ne * sizeof(double));
  enum px_status st = PX_STATUS_OK;
  if (!w.d || !w.X || !w.Y || !w.cx || !w.cy || !w.next || !w.seen || !w.px || !w.py)
    st = PX_STATUS_NOMEM;
  for (size_t i = 0; st == PX_STATUS_OK && i < m->nv; ++i) {
    const double *p = m->xyz + 3 * i;
    w.d[i] = n[0] * p[0] + n[1] * p[1] + n[2] * p[2] - offset;
    w.X[i] = u[0] * p[0] + u[1] * p[1] + u[2] * p[2];
    w.Y[i] = v[0] * p[0] + v[1] * p[1] + v[2] * p[2];
  }
  if (st == PX_STATUS_OK) {
    link_segments(m, &w);
    st = trace(ctx, m, &w, offset, out, n_out);
  }
  if (st == PX_STATUS_OK) cancel_pairs(ctx, *out, n_out);
  work_free(ctx, &w);
  if (st != PX_STATUS_OK) {
    for (size_t i = 0; i < *n_out; ++i) px_geo_polyline_free(ctx, &(*out)[i]);
    px_mem_free(ctx, *out);
    *out = NULL;
    *n_out = 0;
  }
  return st;
}
