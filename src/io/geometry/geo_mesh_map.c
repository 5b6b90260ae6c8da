/* Section values onto mesh vertices (geo_mesh_map.h). */
#include "io/geometry/geo_mesh_map.h"

#include <math.h>
#include <string.h>

#include "partix/memory.h"

/* Section s's values at the plane point (X, Y) into f (nq). */
static void section_value(const struct px_geo_map_section *s, size_t nq, double X, double Y,
                          double *f) {
  double best = HUGE_VAL;
  size_t ia = 0, ib = 0;
  double w = 0;
  for (size_t l = 0; l < s->nloops; ++l) {
    const size_t a0 = s->loop_start[l], a1 = s->loop_start[l + 1];
    for (size_t a = a0; a < a1; ++a) {
      const size_t b = a + 1 < a1 ? a + 1 : a0; /* closed */
      const double ex = s->x[b] - s->x[a], ey = s->y[b] - s->y[a];
      const double L2 = ex * ex + ey * ey;
      double t = L2 > 0 ? ((X - s->x[a]) * ex + (Y - s->y[a]) * ey) / L2 : 0;
      t = t < 0 ? 0 : t > 1 ? 1 : t;
      const double dx = s->x[a] + t * ex - X, dy = s->y[a] + t * ey - Y;
      const double d2 = dx * dx + dy * dy;
      if (d2 < best) {
        best = d2;
        ia = a;
        ib = b;
        w = t;
      }
    }
  }
  for (size_t q = 0; q < nq; ++q)
    f[q] = (1 - w) * s->value[ia * nq + q] + w * s->value[ib * nq + q];
}

enum px_status px_geo_mesh_map(struct px_context *ctx, const struct px_geo_mesh *m,
                               const double u[3], const double v[3], const double n[3],
                               const struct px_geo_map_section *sec, size_t nsec, size_t nq,
                               double *out, int *nearest) {
  if (!nsec || !nq)
    return px_context_fail(ctx, PX_STATUS_INVALID, "%s: no section to map from", m->source);
  for (size_t k = 0; k < nsec; ++k)
    if (!sec[k].n || !sec[k].nloops || (k && !(sec[k].offset > sec[k - 1].offset)))
      return px_context_fail(ctx, PX_STATUS_INVALID,
                             "%s: section %zu (at %g) has no sample or is out of order", m->source,
                             k + 1, sec[k].offset);
  double *g = px_mem_alloc(ctx, "mesh map", nq * sizeof *g);
  if (!g) return PX_STATUS_NOMEM;
  for (size_t i = 0; i < m->nv; ++i) {
    const double *p = m->xyz + 3 * i;
    const double h = n[0] * p[0] + n[1] * p[1] + n[2] * p[2];
    const double X = u[0] * p[0] + u[1] * p[1] + u[2] * p[2];
    const double Y = v[0] * p[0] + v[1] * p[1] + v[2] * p[2];
    double *f = out + i * nq;
    size_t k = 0;
    while (k + 1 < nsec && h > sec[k + 1].offset) ++k;
    double t = 0;
    if (k + 1 < nsec && h > sec[k].offset)
      t = (h - sec[k].offset) / (sec[k + 1].offset - sec[k].offset);
    section_value(&sec[k], nq, X, Y, f);
    if (t > 0) {
      section_value(&sec[k + 1], nq, X, Y, g);
      for (size_t q = 0; q < nq; ++q) f[q] = (1 - t) * f[q] + t * g[q];
    }
    if (nearest) nearest[i] = (int)(t > 0.5 ? k + 1 : k);
  }
  px_mem_free(ctx, g);
  return PX_STATUS_OK;
}
