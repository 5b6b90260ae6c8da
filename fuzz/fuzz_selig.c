/* libFuzzer harness: the profile readers of io/geometry/geo_profile.h on
 * arbitrary text (a Selig .dat airfoil; a closed list of points) and the
 * vortex solver's use of them (the Selig airfoil checked and re-panelled to
 * 64 cosine-spaced panels, the list checked and kept as it is). A read
 * either gives a polyline of finite vertices with their file lines, or
 * fails with a message; it never crashes or hangs. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "io/geometry/geo_profile.h"
#include "partix/partix.h"
#include "solvers/vortex/vortex_profile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check(struct px_context *ctx, enum px_status st, struct px_vortex_contour *c) {
  size_t i;
  if (st == PX_STATUS_OK) {
    for (i = 0; i < c->n; ++i)
      if (!isfinite(c->x[i]) || !isfinite(c->y[i])) abort();
    px_vortex_contour_free(ctx, c);
  } else if (!px_context_message(ctx)[0]) {
    abort();
  }
}

/* A polyline read from the file: finite vertices, each with a line of the
 * file (1-based, non-decreasing along a list as read). */
static void check_raw(struct px_context *ctx, enum px_status st, struct px_geo_polyline *p) {
  size_t i;
  if (st == PX_STATUS_OK) {
    if (p->n < 3 || !p->line) abort();
    for (i = 0; i < p->n; ++i)
      if (!isfinite(p->x[i]) || !isfinite(p->y[i]) || p->line[i] < 1) abort();
    px_geo_polyline_free(ctx, p);
  } else if (!px_context_message(ctx)[0]) {
    abort();
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static char path[64];
  struct px_context *ctx = NULL;
  struct px_vortex_contour c = {0};
  struct px_geo_polyline p;
  int open_te = 0;
  FILE *f;
  if (size > 1u << 20) return 0;
  if (!path[0]) snprintf(path, sizeof path, "/tmp/px_fuzz_profile_%ld.dat", (long)getpid());
  f = fopen(path, "wb");
  if (!f) return 0;
  fwrite(data, 1, size, f);
  fclose(f);
  if (px_context_create(&ctx) != PX_STATUS_OK) return 0;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  check_raw(ctx, px_geo_profile_read_selig(ctx, path, PX_VORTEX_FILE_MAX_POINTS, &p, &open_te), &p);
  px_context_clear(ctx);
  check_raw(ctx, px_geo_profile_read_points(ctx, path, PX_VORTEX_FILE_MAX_POINTS, &p), &p);
  px_context_clear(ctx);
  check(ctx, px_vortex_profile_read_selig(ctx, path, 64, PX_VORTEX_SPACING_COSINE, &c), &c);
  px_context_clear(ctx);
  check(ctx, px_vortex_profile_read_points(ctx, path, 0, &c), &c);
  px_context_free(ctx);
  return 0;
}
