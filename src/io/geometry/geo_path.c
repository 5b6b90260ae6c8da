/* Paths of primitives (lines, arcs, ellipse arcs, quadratic Beziers, point
 * lists): building them, evaluating, reversing and measuring a primitive
 * (geo_path.h). */
#include "io/geometry/geo_path.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/memory.h"
void px_geo_path_init(struct px_geo_path *p, const char *where) {
  memset(p, 0, sizeof *p);
  if (where) {
    strncpy(p->where, where, sizeof p->where - 1);
    p->where[sizeof p->where - 1] = '\0';
  }
}

void px_geo_path_free(struct px_context *ctx, struct px_geo_path *p) {
  size_t i;
  if (!p) return;
  for (i = 0; i < p->n; ++i) px_mem_free(ctx, p->prims[i].pts);
  px_mem_free(ctx, p->prims);
  p->prims = NULL;
  p->n = p->cap = 0;
}

enum px_status px_geo_path_add(struct px_context *ctx, struct px_geo_path *p,
                               const struct px_geo_prim *prim) {
  if (p->n == p->cap) {
    size_t cap = p->cap ? 2 * p->cap : 8;
    struct px_geo_prim *grown;
    if (cap <= p->cap || cap > (size_t)-1 / sizeof *grown) return PX_STATUS_NOMEM;
    grown = px_mem_realloc(ctx, "geometry path", p->prims, cap * sizeof *grown);
    if (!grown) return PX_STATUS_NOMEM;
    p->prims = grown;
    p->cap = cap;
  }
  p->prims[p->n] = *prim;
  if (prim->kind == PX_GEO_PRIM_POINTS && prim->npts) {
    double *copy = prim->npts <= (size_t)-1 / (2 * sizeof *copy)
                       ? px_mem_alloc(ctx, "geometry path", 2 * prim->npts * sizeof *copy)
                       : NULL;
    if (!copy) return PX_STATUS_NOMEM;
    memcpy(copy, prim->pts, 2 * prim->npts * sizeof *copy);
    p->prims[p->n].pts = copy;
  } else {
    p->prims[p->n].pts = NULL;
  }
  ++p->n;
  return PX_STATUS_OK;
}

enum px_status px_geo_path_add_points(struct px_context *ctx, struct px_geo_path *p,
                                      const double *xy, size_t n, int smooth) {
  struct px_geo_prim q;
  memset(&q, 0, sizeof q);
  q.kind = PX_GEO_PRIM_POINTS;
  q.pts = (double *)(size_t)xy; /* copied by px_geo_path_add */
  q.npts = n;
  q.smooth = smooth;
  return px_geo_path_add(ctx, p, &q);
}

void px_geo_prim_eval(const struct px_geo_prim *q, double u, double *x, double *y) {
  const double *p = q->p;
  switch (q->kind) {
    case PX_GEO_PRIM_LINE:
      *x = p[0] + u * (p[2] - p[0]);
      *y = p[1] + u * (p[3] - p[1]);
      return;
    case PX_GEO_PRIM_ARC: {
      const double a = p[3] + u * (p[4] - p[3]);
      *x = p[0] + p[2] * cos(a);
      *y = p[1] + p[2] * sin(a);
      return;
    }
    case PX_GEO_PRIM_ELLIPSE: {
      const double t = p[5] + u * (p[6] - p[5]);
      const double ex = p[2] * cos(t), ey = p[3] * sin(t);
      const double c = cos(p[4]), s = sin(p[4]);
      *x = p[0] + c * ex - s * ey;
      *y = p[1] + s * ex + c * ey;
      return;
    }
    case PX_GEO_PRIM_BEZIER2: {
      const double w0 = (1 - u) * (1 - u), w1 = 2 * u * (1 - u), w2 = u * u;
      *x = w0 * p[0] + w1 * p[2] + w2 * p[4];
      *y = w0 * p[1] + w1 * p[3] + w2 * p[5];
      return;
    }
    case PX_GEO_PRIM_POINTS: {
      /* piecewise linear in the point index */
      double f;
      size_t k;
      if (q->npts < 2) {
        *x = q->npts ? q->pts[0] : 0;
        *y = q->npts ? q->pts[1] : 0;
        return;
      }
      f = u * (double)(q->npts - 1);
      k = (size_t)f;
      if (k >= q->npts - 1) k = q->npts - 2;
      f -= (double)k;
      *x = q->pts[2 * k] + f * (q->pts[2 * k + 2] - q->pts[2 * k]);
      *y = q->pts[2 * k + 1] + f * (q->pts[2 * k + 3] - q->pts[2 * k + 1]);
      return;
    }
  }
  *x = *y = 0;
}

void px_geo_prim_ends(const struct px_geo_prim *q, double *x0, double *y0, double *x1, double *y1) {
  px_geo_prim_eval(q, 0.0, x0, y0);
  px_geo_prim_eval(q, 1.0, x1, y1);
}

void px_geo_prim_reverse(struct px_geo_prim *q) {
  double t;
  size_t i;
  switch (q->kind) {
    case PX_GEO_PRIM_LINE:
      t = q->p[0], q->p[0] = q->p[2], q->p[2] = t;
      t = q->p[1], q->p[1] = q->p[3], q->p[3] = t;
      break;
    case PX_GEO_PRIM_ARC: t = q->p[3], q->p[3] = q->p[4], q->p[4] = t; break;
    case PX_GEO_PRIM_ELLIPSE: t = q->p[5], q->p[5] = q->p[6], q->p[6] = t; break;
    case PX_GEO_PRIM_BEZIER2:
      t = q->p[0], q->p[0] = q->p[4], q->p[4] = t;
      t = q->p[1], q->p[1] = q->p[5], q->p[5] = t;
      break;
    case PX_GEO_PRIM_POINTS:
      for (i = 0; i < q->npts / 2; ++i) {
        size_t j = q->npts - 1 - i;
        t = q->pts[2 * i], q->pts[2 * i] = q->pts[2 * j], q->pts[2 * j] = t;
        t = q->pts[2 * i + 1], q->pts[2 * i + 1] = q->pts[2 * j + 1], q->pts[2 * j + 1] = t;
      }
      break;
  }
}

double px_geo_prim_length(const struct px_geo_prim *q) {
  double L = 0, x0, y0, x1, y1;
  size_t k, n;
  switch (q->kind) {
    case PX_GEO_PRIM_LINE: return hypot(q->p[2] - q->p[0], q->p[3] - q->p[1]);
    case PX_GEO_PRIM_ARC: return fabs(q->p[2] * (q->p[4] - q->p[3]));
    case PX_GEO_PRIM_POINTS:
      for (k = 0; k + 1 < q->npts; ++k)
        L += hypot(q->pts[2 * k + 2] - q->pts[2 * k], q->pts[2 * k + 3] - q->pts[2 * k + 1]);
      return L;
    default:
      n = PX_GEO_SAMPLES;
      px_geo_prim_eval(q, 0.0, &x0, &y0);
      for (k = 1; k <= n; ++k) {
        px_geo_prim_eval(q, (double)k / (double)n, &x1, &y1);
        L += hypot(x1 - x0, y1 - y0);
        x0 = x1;
        y0 = y1;
      }
      return L;
  }
}
