/* Closed polylines: storage, area, perimeter, resampling (geo_polyline.h). */
#include "io/geometry/geo_polyline.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "partix/memory.h"

enum px_status px_geo_polyline_alloc(struct px_context *ctx, struct px_geo_polyline *p, size_t n,
                                     int with_lines) {
  memset(p, 0, sizeof *p);
  p->n = n;
  if (n <= SIZE_MAX / sizeof(double)) {
    p->x = px_mem_alloc(ctx, "geometry polyline", n * sizeof(double));
    p->y = px_mem_alloc(ctx, "geometry polyline", n * sizeof(double));
  }
  p->line = with_lines ? px_mem_calloc(ctx, "geometry polyline", n, sizeof(int)) : NULL;
  if (!p->x || !p->y || (with_lines && !p->line)) {
    px_geo_polyline_free(ctx, p);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for a profile of %zu points", n);
  }
  return PX_STATUS_OK;
}

void px_geo_polyline_free(struct px_context *ctx, struct px_geo_polyline *p) {
  if (!p) return;
  px_mem_free(ctx, p->x);
  px_mem_free(ctx, p->y);
  px_mem_free(ctx, p->line);
  p->x = p->y = NULL;
  p->line = NULL;
  p->n = 0;
}

double px_geo_polyline_area(const struct px_geo_polyline *p) {
  double s = 0.0;
  for (size_t k = 0; k < p->n; ++k) {
    size_t j = (k + 1) % p->n;
    s += p->x[k] * p->y[j] - p->x[j] * p->y[k];
  }
  return 0.5 * s;
}

double px_geo_polyline_perimeter(const struct px_geo_polyline *p) {
  double s = 0.0;
  for (size_t k = 0; k < p->n; ++k) {
    size_t j = (k + 1) % p->n;
    s += hypot(p->x[j] - p->x[k], p->y[j] - p->y[k]);
  }
  return s;
}

void px_geo_polyline_resample(size_t m, const double *px, const double *py, size_t n, double *x,
                              double *y) {
  /* cumulative length */
  double total = 0.0;
  for (size_t i = 0; i < m; ++i) {
    size_t j = (i + 1) % m;
    total += hypot(px[j] - px[i], py[j] - py[i]);
  }
  double acc = 0.0;
  size_t i = 0;
  double seg = hypot(px[1 % m] - px[0], py[1 % m] - py[0]);
  for (size_t k = 0; k < n; ++k) {
    double target = total * (double)k / (double)n;
    while (acc + seg < target && i + 1 < m) {
      acc += seg;
      ++i;
      size_t j = (i + 1) % m;
      seg = hypot(px[j] - px[i], py[j] - py[i]);
    }
    size_t j = (i + 1) % m;
    double f = seg > 0.0 ? (target - acc) / seg : 0.0;
    if (f < 0.0) f = 0.0;
    if (f > 1.0) f = 1.0;
    x[k] = px[i] + f * (px[j] - px[i]);
    y[k] = py[i] + f * (py[j] - py[i]);
  }
}
