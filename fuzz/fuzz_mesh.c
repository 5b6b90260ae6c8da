/* libFuzzer harness: the surface mesh readers (io/geometry/geo_mesh.h),
 * the closed-manifold check and the plane sections.
 * The input's first byte picks the format (STL or OBJ) and the weld
 * tolerance; the rest is the file. A mesh that reads and passes the check
 * is cut by planes across its bounding box and through its first vertex,
 * normal to z and to (1, 1, 1): every step either succeeds or fails with a
 * message, and every contour has 3 points at least, all finite. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "io/geometry/geo_mesh.h"
#include "partix/partix.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void cut(struct px_context *ctx, const struct px_geo_mesh *m, const double normal[3]) {
  double u[3], v[3], n[3], lo[3], hi[3];
  const double hint[3] = {1, 0, 0};
  if (px_geo_mesh_frame(ctx, normal, hint, u, v, n) != PX_STATUS_OK) abort();
  px_geo_mesh_measure(m, NULL, NULL, lo, hi);
  double dlo = HUGE_VAL, dhi = -HUGE_VAL;
  for (int c = 0; c < 8; ++c) {
    const double p[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
    const double d = n[0] * p[0] + n[1] * p[1] + n[2] * p[2];
    dlo = fmin(dlo, d);
    dhi = fmax(dhi, d);
  }
  for (int k = 0; k <= 5; ++k) {
    const double *p0 = m->xyz;
    const double off =
        k < 5 ? dlo + (dhi - dlo) * (k + 0.5) / 5 : n[0] * p0[0] + n[1] * p0[1] + n[2] * p0[2];
    struct px_geo_polyline *c = NULL;
    size_t nc = 0;
    const enum px_status st = px_geo_mesh_slice(ctx, m, u, v, n, off, &c, &nc);
    if (st != PX_STATUS_OK && !px_context_message(ctx)[0] && st != PX_STATUS_NOMEM) abort();
    for (size_t i = 0; i < nc; ++i) {
      if (c[i].n < 3) abort();
      for (size_t j = 0; j < c[i].n; ++j)
        if (!isfinite(c[i].x[j]) || !isfinite(c[i].y[j])) abort();
      px_geo_polyline_free(ctx, &c[i]);
    }
    px_mem_free(ctx, c);
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  struct px_context *ctx = NULL;
  struct px_geo_mesh m;
  if (size < 1 || size > 1u << 20) return 0;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 0;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  const int obj = data[0] & 1;
  const double tol = data[0] & 2 ? 1e-6 : 0;
  enum px_status st = px_geo_mesh_parse(ctx, obj ? "fuzz.obj" : "fuzz.stl", (const char *)data + 1,
                                        size - 1, obj, tol, &m);
  if (st == PX_STATUS_OK) {
    st = px_geo_mesh_check(ctx, &m);
    if (st == PX_STATUS_OK) {
      const double z[3] = {0, 0, 1}, d[3] = {1, 1, 1};
      cut(ctx, &m, z);
      cut(ctx, &m, d);
    }
  }
  if (st != PX_STATUS_OK && !px_context_message(ctx)[0] && st != PX_STATUS_NOMEM) abort();
  px_geo_mesh_free(ctx, &m);
  px_context_free(ctx);
  return 0;
}
