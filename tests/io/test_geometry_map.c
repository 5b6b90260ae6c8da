/* Section values onto mesh vertices (io/geometry/geo_mesh_map.h), on an
 * analytic field f = 3 + 2 z + x - y / 2 (and a constant 7) over a 32-sided
 * prism whose sides have 8 rows of vertices, from 4 sections normal to z:
 * - sampled at the sections' own corners, every vertex between the first
 *   and the last section gets f exactly (1e-12), and a vertex beyond them
 *   the nearest section's value;
 * - sampled at segment midpoints (8 per side, as a 2D run reports them),
 *   the error is at most |grad f in the plane| times the distance between a
 *   corner and the chord of the samples around it, (h / 2) sin(pi / 32),
 *   and reaches half of that bound (the bound is what the method costs). */
#include <math.h>
#include <string.h>

#include "io/geometry/geo_mesh_map.h"
#include "px_test.h"
#include "px_test_mesh.h"

#define N 32
#define K 4
#define H 2.0

static double field(double x, double y, double z) { return 3 + 2 * z + x - 0.5 * y; }

struct samples {
  double x[8 * N], y[8 * N], val[2 * 8 * N];
  size_t n, start[2];
};

/* Samples of section at offset o: the corners, or the midpoints of 8
 * equal pieces of each side. */
static void sample(struct px_context *ctx, const struct px_geo_mesh *m, const double u[3],
                   const double v[3], const double n[3], double o, int midpoints,
                   struct samples *s) {
  struct px_geo_polyline *c = NULL;
  size_t nc = 0;
  PX_CHECK_OK(ctx, px_geo_mesh_slice(ctx, m, u, v, n, o, &c, &nc));
  PX_CHECK(nc == 1 && c[0].n == N);
  s->n = 0;
  if (nc == 1 && c[0].n == N) {
    if (midpoints) {
      double px[8 * N + 1], py[8 * N + 1];
      px_geo_polyline_resample(N, c[0].x, c[0].y, 8 * N, px, py);
      px[8 * N] = px[0];
      py[8 * N] = py[0];
      for (size_t i = 0; i < 8 * N; ++i) {
        s->x[i] = 0.5 * (px[i] + px[i + 1]);
        s->y[i] = 0.5 * (py[i] + py[i + 1]);
      }
      s->n = 8 * N;
    } else {
      memcpy(s->x, c[0].x, N * sizeof(double));
      memcpy(s->y, c[0].y, N * sizeof(double));
      s->n = N;
    }
  }
  for (size_t i = 0; i < s->n; ++i) {
    s->val[2 * i] = field(s->x[i], s->y[i], o); /* u = x, v = y, n = z */
    s->val[2 * i + 1] = 7;
  }
  s->start[0] = 0;
  s->start[1] = s->n;
  for (size_t i = 0; i < nc; ++i) px_geo_polyline_free(ctx, &c[i]);
  px_mem_free(ctx, c);
}

static void run(struct px_context *ctx, int midpoints) {
  struct tm_soup s = {0};
  struct px_geo_mesh m;
  size_t len;
  tm_prism(&s, 1, H, N, 8);
  char *t = tm_stl_ascii(&s, &len);
  PX_CHECK_OK(ctx, px_geo_mesh_parse(ctx, "prism.stl", t, len, 0, 0, &m));
  PX_CHECK_OK(ctx, px_geo_mesh_check(ctx, &m));
  free(t);
  const double z[3] = {0, 0, 1}, x[3] = {1, 0, 0};
  double u[3], v[3], n[3];
  PX_CHECK_OK(ctx, px_geo_mesh_frame(ctx, z, x, u, v, n));
  static struct samples sm[K];
  struct px_geo_map_section sec[K];
  for (int k = 0; k < K; ++k) {
    const double o = H * (k + 0.5) / K; /* 0.25, 0.75, ...: through vertex rows */
    sample(ctx, &m, u, v, n, o, midpoints, &sm[k]);
    sec[k].offset = o;
    sec[k].n = sm[k].n;
    sec[k].x = sm[k].x;
    sec[k].y = sm[k].y;
    sec[k].nloops = 1;
    sec[k].loop_start = sm[k].start;
    sec[k].value = sm[k].val;
  }
  double *out = malloc(2 * m.nv * sizeof *out);
  int *near = malloc(m.nv * sizeof *near);
  PX_CHECK_OK(ctx, px_geo_mesh_map(ctx, &m, u, v, n, sec, K, 2, out, near));
  /* samples h apart along sides of length 2 sin(pi / N) */
  const double h = 2 * sin(TM_PI / N) / 8, grad = sqrt(1 + 0.25);
  const double bound = midpoints ? grad * 0.5 * h * sin(TM_PI / N) : 0;
  double worst = 0;
  for (size_t i = 0; i < m.nv; ++i) {
    const double *p = m.xyz + 3 * i;
    const double lo = sec[0].offset, hi = sec[K - 1].offset;
    const double zc = p[2] < lo ? lo : p[2] > hi ? hi : p[2];
    if (p[0] == 0 && p[1] == 0) continue; /* the caps' centres: not on a section */
    const double e = fabs(out[2 * i] - field(p[0], p[1], zc));
    worst = fmax(worst, e);
    PX_CHECK_MSG(e <= bound + 1e-12, "vertex (%g, %g, %g): error %g > %g", p[0], p[1], p[2], e,
                 bound);
    PX_CHECK_NEAR(out[2 * i + 1], 7.0, 1e-12);
    int nk = 0; /* the nearest section along z, the lower one on a tie */
    for (int k = 1; k < K; ++k)
      if (fabs(p[2] - sec[k].offset) < fabs(p[2] - sec[nk].offset)) nk = k;
    PX_CHECK(near[i] == nk);
  }
  if (midpoints) PX_CHECK_MSG(worst >= 0.5 * bound, "worst %g, bound %g", worst, bound);
  free(out);
  free(near);
  px_geo_mesh_free(ctx, &m);
  tm_free(&s);
}

static void test_bad_sections(struct px_context *ctx) {
  struct px_geo_mesh m;
  struct px_geo_map_section sec[2];
  double out[2];
  const double u[3] = {1, 0, 0}, v[3] = {0, 1, 0}, n[3] = {0, 0, 1};
  memset(&m, 0, sizeof m);
  memset(sec, 0, sizeof sec);
  PX_CHECK_STATUS(ctx, px_geo_mesh_map(ctx, &m, u, v, n, sec, 0, 1, out, NULL), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_geo_mesh_map(ctx, &m, u, v, n, sec, 2, 1, out, NULL), PX_STATUS_INVALID);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  const size_t held = px_mem_current(ctx, NULL);
  run(ctx, 0);
  run(ctx, 1);
  test_bad_sections(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == held); /* nothing left allocated */
  px_context_free(ctx);
  return px_test_report("test_geometry_map");
}
