/* libFuzzer harness: the DXF reader (io/geometry/geo_dxf.h) and the granular
 * geometry that uses it.
 * The closed loops of arbitrary DXF text are split into boundary segments
 * (px_gran_geom_add_path at a segment length from the loops' length and the
 * input's first byte),
 * checked for crossings, oriented and binned (px_gran_geom_finish), and
 * queried (point in region, distance, segments near a point) as the solver
 * does. Every step either succeeds or fails with a message; it never
 * crashes, loops without end or allocates beyond the segment limits
 * (PX_GRAN_SEG_MAX, the bins' and crossing grids' caps). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "partix/partix.h"
#include "io/geometry/geo_dxf.h"
#include "solvers/granular/geometry.h"
#include "solvers/granular/wall_kernel.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  struct px_context *ctx = NULL;
  struct px_geo_path *paths = NULL;
  struct px_gran_geom g;
  size_t n = 0, i;
  double h = 1, L = 0;
  enum px_status st;
  if (size > 1u << 20) return 0;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 0;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  px_gran_geom_init(&g);
  st = px_geo_dxf_parse(ctx, "fuzz.dxf", (const char *)data, size, NULL, 1.0, 0.0, 0.0, 1e-6,
                        &paths, &n);
  /* the segment length from the loops' total length and the input's first
   * byte: 256 to 16384 segments in all (fast enough to fuzz), or 1e9 (the
   * segment limit refuses it before splitting), or 1 drawing unit (at most
   * 2e5 segments) */
  for (i = 0; i < n && st == PX_STATUS_OK; ++i) {
    size_t k;
    for (k = 0; k < paths[i].n; ++k) L += px_geo_prim_length(&paths[i].prims[k]);
  }
  if (st == PX_STATUS_OK && isfinite(L) && L > 0) {
    const int mode = size ? data[0] % 6 : 5;
    h = mode < 4 ? L / (256.0 * pow(4.0, mode)) : mode == 4 ? 1e-9 * L : 1.0;
    if (mode == 5 && L / h > 2e5) h = L / 2e5;
  }
  for (i = 0; i < n && st == PX_STATUS_OK; ++i)
    st = px_gran_geom_add_path(ctx, &g, &paths[i], h, 1e-6, "loop", 0, PX_GRAN_SIDE_AUTO);
  if (st == PX_STATUS_OK) st = px_gran_geom_finish(ctx, &g, 4 * h);
  if (st == PX_STATUS_OK) {
    /* queries at the contours' corners and centres, rest frames */
    double *frames = calloc(g.ncontours * PX_GRAN_CTR_COUNT + 1, sizeof *frames);
    int near[64];
    size_t c;
    for (c = 0; frames && c < g.ncontours; ++c) frames[c * PX_GRAN_CTR_COUNT + PX_GRAN_CTR_COS] = 1;
    for (c = 0; frames && c < g.ncontours; ++c) {
      const struct px_gran_contour *C = &g.contours[c];
      const double px[3] = {C->xmin, 0.5 * (C->xmin + C->xmax), C->xmax + h};
      const double py[3] = {C->ymin, 0.5 * (C->ymin + C->ymax), C->ymax + h};
      int k;
      for (k = 0; k < 3; ++k) {
        const double d = px_gran_geom_distance(&g, frames, px[k], py[k], 2 * h);
        if (!(d >= 0) || !(d <= 2 * h)) abort();
        (void)px_gran_geom_inside(&g, frames, px[k], py[k]);
        (void)px_gran_geom_near(&g, c, px[k], py[k], h, near, 64);
      }
    }
    free(frames);
  } else if (!px_context_message(ctx)[0] && st != PX_STATUS_NOMEM) {
    abort();
  }
  for (i = 0; i < n; ++i) px_geo_path_free(ctx, &paths[i]);
  px_mem_free(ctx, paths);
  px_gran_geom_free(ctx, &g);
  px_context_free(ctx);
  return 0;
}
