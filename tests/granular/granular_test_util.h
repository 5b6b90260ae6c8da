/* Helpers shared by the granular tests: simple contours and laws. */
#ifndef GRANULAR_TEST_UTIL_H
#define GRANULAR_TEST_UTIL_H

#include <math.h>
#include <string.h>

#include "px_test.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/geometry.h"
#include "solvers/granular/motion.h"
#include "solvers/granular/system.h"

#if defined(__GNUC__)
#define GT_UNUSED __attribute__((unused))
#else
#define GT_UNUSED
#endif

GT_UNUSED static void gt_law(struct px_gran_law_spec *L, double kn, double e, double mu) {
  memset(L, 0, sizeof *L);
  L->normal = PX_GRAN_NORMAL_LINEAR;
  L->tangential = PX_GRAN_TANGENTIAL_SPRING;
  L->kn = kn;
  L->e = e;
  L->kt_ratio = 1.0 / 3.0;
  L->ct_ratio = 0.5;
  L->mu = mu;
}

GT_UNUSED static void gt_line(struct px_geo_prim *q, double x0, double y0, double x1, double y1) {
  memset(q, 0, sizeof *q);
  q->kind = PX_GEO_PRIM_LINE;
  q->p[0] = x0, q->p[1] = y0, q->p[2] = x1, q->p[3] = y1;
}

/* The lines of the polyline (xy[0], xy[1]) .. (xy[2 n - 2], xy[2 n - 1])
 * added to path p. */
GT_UNUSED static void gt_polyline(struct px_context *ctx, struct px_geo_path *p, const double *xy,
                                  int n) {
  struct px_geo_prim q;
  int k;
  for (k = 0; k + 1 < n; ++k) {
    gt_line(&q, xy[2 * k], xy[2 * k + 1], xy[2 * k + 2], xy[2 * k + 3]);
    px_geo_path_add(ctx, p, &q);
  }
}

/* Rectangle [x0, x1] x [y0, y1] as a contour of body `body`. */
GT_UNUSED static enum px_status gt_rect(struct px_context *ctx, struct px_gran_geom *g, double x0,
                                        double y0, double x1, double y1, double h, int body,
                                        const char *name) {
  struct px_geo_path p;
  const double xy[10] = {x0, y0, x1, y0, x1, y1, x0, y1, x0, y0};
  enum px_status st;
  px_geo_path_init(&p, "test");
  gt_polyline(ctx, &p, xy, 5);
  st = px_gran_geom_add_path(ctx, g, &p, h, 1e-9, name, body, PX_GRAN_SIDE_AUTO);
  px_geo_path_free(ctx, &p);
  return st;
}

/* Full circle as one arc starting at angle a0. */
GT_UNUSED static enum px_status gt_circle(struct px_context *ctx, struct px_gran_geom *g, double cx,
                                          double cy, double R, double a0, double h, int body,
                                          const char *name) {
  struct px_geo_path p;
  struct px_geo_prim q;
  enum px_status st;
  px_geo_path_init(&p, "test");
  memset(&q, 0, sizeof q);
  q.kind = PX_GEO_PRIM_ARC;
  q.p[0] = cx, q.p[1] = cy, q.p[2] = R, q.p[3] = a0, q.p[4] = a0 + 2 * 3.14159265358979323846;
  px_geo_path_add(ctx, &p, &q);
  st = px_gran_geom_add_path(ctx, g, &p, h, 1e-9, name, body, PX_GRAN_SIDE_AUTO);
  px_geo_path_free(ctx, &p);
  return st;
}

#endif
