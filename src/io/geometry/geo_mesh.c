/* Triangle meshes: the closed-manifold check, measures and the section
 * frame (geo_mesh.h). Reading: geo_mesh_read.c; slicing: geo_mesh_slice.c. */
#include "io/geometry/geo_mesh.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/memory.h"

void px_geo_mesh_free(struct px_context *ctx, struct px_geo_mesh *m) {
  if (!m) return;
  px_mem_free(ctx, m->xyz);
  px_mem_free(ctx, m->tri);
  px_mem_free(ctx, m->where);
  px_mem_free(ctx, m->edge);
  px_mem_free(ctx, m->ev);
  memset(m, 0, sizeof *m);
}

/* One side of a triangle: the edge lo-hi, run from lo to hi when fwd. */
struct half {
  size_t lo, hi, t;
  int k, fwd;
};

static int half_cmp(const void *a, const void *b) {
  const struct half *x = a, *y = b;
  if (x->lo != y->lo) return x->lo < y->lo ? -1 : 1;
  if (x->hi != y->hi) return x->hi < y->hi ? -1 : 1;
  return x->t < y->t ? -1 : x->t > y->t;
}

/* Appends one offending edge (the run h[0..n-1] of its sides) to buf. */
static void report_edge(const struct px_geo_mesh *m, const struct half *h, size_t n, char *buf,
                        size_t size) {
  const double *a = m->xyz + 3 * h[0].lo, *b = m->xyz + 3 * h[0].hi;
  size_t len = strlen(buf);
  const char *why = n == 1  ? "open: on one triangle only"
                    : n > 2 ? "not manifold: on more than two triangles"
                            : "on two triangles that run along it the same way (their "
                              "orientations disagree)";
  snprintf(buf + len, size - len, "\n  edge (%g, %g, %g) - (%g, %g, %g): %s; triangles at", a[0],
           a[1], a[2], b[0], b[1], b[2], why);
  for (size_t i = 0; i < n && i < 4; ++i) {
    len = strlen(buf);
    snprintf(buf + len, size - len, "%s %s %ld", i ? "," : "", m->binary ? "byte" : "line",
             m->where[h[i].t]);
  }
  if (n > 4) {
    len = strlen(buf);
    snprintf(buf + len, size - len, ", ...");
  }
}

/* Every triangle reversed (corners 1 and 2 swapped), its edge table with
 * it: side k runs from corner k to k + 1, so the sides (0-1, 1-2, 2-0)
 * become (0-2, 2-1, 1-0), the old sides 2, 1, 0 (the slicer follows a
 * triangle's sides by this table). */
static void flip(struct px_geo_mesh *m) {
  for (size_t t = 0; t < m->nt; ++t) {
    const size_t s = m->tri[3 * t + 1];
    m->tri[3 * t + 1] = m->tri[3 * t + 2];
    m->tri[3 * t + 2] = s;
    if (m->edge) {
      const size_t e = m->edge[3 * t];
      m->edge[3 * t] = m->edge[3 * t + 2];
      m->edge[3 * t + 2] = e;
    }
  }
}

/* Edge table from the sorted sides; the count of offending edges, the
 * first PX_GEO_MESH_REPORT_MAX of them described in buf. */
static size_t build_edges(struct px_geo_mesh *m, const struct half *h, size_t nh, char *buf,
                          size_t size) {
  size_t bad = 0, e = 0;
  for (size_t i = 0; i < nh;) {
    size_t j = i + 1;
    while (j < nh && h[j].lo == h[i].lo && h[j].hi == h[i].hi) ++j;
    if (j - i != 2 || h[i].fwd == h[i + 1].fwd) {
      if (bad++ < PX_GEO_MESH_REPORT_MAX) report_edge(m, h + i, j - i, buf, size);
    }
    m->ev[2 * e] = h[i].lo;
    m->ev[2 * e + 1] = h[i].hi;
    for (size_t k = i; k < j; ++k) m->edge[3 * h[k].t + (size_t)h[k].k] = e;
    ++e;
    i = j;
  }
  m->ne = e;
  return bad;
}

enum px_status px_geo_mesh_check(struct px_context *ctx, struct px_geo_mesh *m) {
  const size_t nh = 3 * m->nt;
  struct half *h = px_mem_alloc(ctx, "mesh edges", (nh + 1) * sizeof *h);
  px_mem_free(ctx, m->edge);
  px_mem_free(ctx, m->ev);
  m->edge = px_mem_alloc(ctx, "mesh edges", (nh + 1) * sizeof *m->edge);
  m->ev = px_mem_alloc(ctx, "mesh edges", (2 * nh + 1) * sizeof *m->ev);
  m->ne = 0;
  if (!h || !m->edge || !m->ev) {
    px_mem_free(ctx, h);
    return PX_STATUS_NOMEM;
  }
  for (size_t t = 0; t < m->nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const size_t a = m->tri[3 * t + (size_t)k], b = m->tri[3 * t + (size_t)(k + 1) % 3];
      struct half *x = h + 3 * t + (size_t)k;
      x->lo = a < b ? a : b;
      x->hi = a < b ? b : a;
      x->t = t;
      x->k = k;
      x->fwd = a < b;
    }
  qsort(h, nh, sizeof *h, half_cmp);
  char buf[2048] = "";
  const size_t bad = build_edges(m, h, nh, buf, sizeof buf);
  px_mem_free(ctx, h);
  if (bad)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: the surface is not closed and manifold: %zu edge%s not shared by "
                           "exactly two consistently oriented triangles%s%s",
                           m->source, bad, bad == 1 ? " is" : "s are", buf,
                           bad > PX_GEO_MESH_REPORT_MAX ? "\n  ..." : "");
  double vol;
  px_geo_mesh_measure(m, &vol, NULL, NULL, NULL);
  m->flipped = vol < 0;
  if (m->flipped) flip(m);
  return PX_STATUS_OK;
}

void px_geo_mesh_scale(struct px_geo_mesh *m, double scale) {
  for (size_t i = 0; i < 3 * m->nv; ++i) m->xyz[i] *= scale;
}

void px_geo_mesh_measure(const struct px_geo_mesh *m, double *volume, double *area, double lo[3],
                         double hi[3]) {
  double V = 0, A = 0, l[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL},
         u[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (size_t t = 0; t < m->nt; ++t) {
    const double *a = m->xyz + 3 * m->tri[3 * t], *b = m->xyz + 3 * m->tri[3 * t + 1],
                 *c = m->xyz + 3 * m->tri[3 * t + 2];
    /* (b - a) x (c - a): twice the area along the outward normal; the
     * tetrahedron origin-a-b-c has volume a . (b x c) / 6 */
    const double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                 f[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double x[3] = {e[1] * f[2] - e[2] * f[1], e[2] * f[0] - e[0] * f[2],
                         e[0] * f[1] - e[1] * f[0]};
    A += 0.5 * sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    V += (a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) +
          a[2] * (b[0] * c[1] - b[1] * c[0])) /
         6.0;
  }
  for (size_t i = 0; i < m->nv; ++i)
    for (int k = 0; k < 3; ++k) {
      l[k] = fmin(l[k], m->xyz[3 * i + (size_t)k]);
      u[k] = fmax(u[k], m->xyz[3 * i + (size_t)k]);
    }
  if (volume) *volume = V;
  if (area) *area = A;
  if (lo) memcpy(lo, l, sizeof l);
  if (hi) memcpy(hi, u, sizeof u);
}

enum px_status px_geo_mesh_frame(struct px_context *ctx, const double normal[3],
                                 const double hint[3], double u[3], double v[3], double n[3]) {
  const double nn = sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
  if (!(nn > 0) || !isfinite(nn))
    return px_context_fail(ctx, PX_STATUS_INVALID,
                           "the section normal (%g, %g, %g) is not a direction", normal[0],
                           normal[1], normal[2]);
  for (int k = 0; k < 3; ++k) n[k] = normal[k] / nn;
  const double hh = sqrt(hint[0] * hint[0] + hint[1] * hint[1] + hint[2] * hint[2]);
  const double hn = hint[0] * n[0] + hint[1] * n[1] + hint[2] * n[2];
  for (int k = 0; k < 3; ++k) u[k] = hint[k] - hn * n[k];
  const double uu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  /* within 1e-6 rad of the normal the in-plane direction is noise */
  if (!(hh > 0) || !isfinite(hh) || !(uu > 1e-6 * hh))
    return px_context_fail(ctx, PX_STATUS_INVALID,
                           "the in-plane direction (%g, %g, %g) is zero or along the section "
                           "normal (%g, %g, %g): it gives the sections' x axis",
                           hint[0], hint[1], hint[2], normal[0], normal[1], normal[2]);
  for (int k = 0; k < 3; ++k) u[k] /= uu;
  v[0] = n[1] * u[2] - n[2] * u[1];
  v[1] = n[2] * u[0] - n[0] * u[2];
  v[2] = n[0] * u[1] - n[1] * u[0];
  return PX_STATUS_OK;
}
