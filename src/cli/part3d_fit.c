/* partix part3d: where a section may go in the 2D case. The case's other
 * contours (the container, ...) as polygons [m] read from its keys as the
 * granular solver reads them (rectangle, polygon, circle, ellipse, path,
 * dxf), so that a section outside the container, or larger than it, is
 * refused before anything runs (part3d.c) instead of "finishing" with no
 * media around the part. Curved pieces are sampled finely enough for that
 * test (PX_PART3D_ARC_SAMPLES points a turn), not for the run. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/part3d.h"
#include "io/geometry/geo_dxf.h"
#include "io/geometry/geo_path.h"
#include "partix/memory.h"

#define PX_PART3D_ARC_SAMPLES 512

/* A growing list of points. */
struct pts {
  double *xy;
  size_t n, cap;
};

static int put(struct pts *s, double x, double y) {
  if (s->n == s->cap) {
    const size_t cap = s->cap ? 2 * s->cap : 64;
    double *xy = realloc(s->xy, 2 * cap * sizeof *xy);
    if (!xy) return -1;
    s->xy = xy;
    s->cap = cap;
  }
  s->xy[2 * s->n] = x;
  s->xy[2 * s->n + 1] = y;
  ++s->n;
  return 0;
}

/* The points of a primitive from its start (its end is the next one's
 * start): a line its start, a polyline its points but the last, a curve
 * samples at most 2 pi / PX_PART3D_ARC_SAMPLES apart in angle. */
static int put_prim(struct pts *s, const struct px_geo_prim *q) {
  size_t m = 1;
  if (q->kind == PX_GEO_PRIM_POINTS) {
    for (size_t i = 0; i + 1 < q->npts; ++i)
      if (put(s, q->pts[2 * i], q->pts[2 * i + 1])) return -1;
    return 0;
  }
  if (q->kind == PX_GEO_PRIM_ARC || q->kind == PX_GEO_PRIM_ELLIPSE) {
    const double sweep = q->kind == PX_GEO_PRIM_ARC ? q->p[4] - q->p[3] : q->p[6] - q->p[5];
    const double t = ceil(fabs(sweep) / (2 * 3.14159265358979323846) * PX_PART3D_ARC_SAMPLES);
    m = t >= 1 && t <= 64 * PX_PART3D_ARC_SAMPLES ? (size_t)t : PX_PART3D_ARC_SAMPLES;
  } else if (q->kind == PX_GEO_PRIM_BEZIER2) {
    m = 64;
  }
  for (size_t j = 0; j < m; ++j) {
    double x, y;
    px_geo_prim_eval(q, (double)j / (double)m, &x, &y);
    if (put(s, x, y)) return -1;
  }
  return 0;
}

static int put_path(struct pts *s, const struct px_geo_path *path) {
  for (size_t i = 0; i < path->n; ++i)
    if (put_prim(s, &path->prims[i])) return -1;
  return 0;
}

/* Appends the points as the region `name` (the points are taken over). */
static int add_region(struct px_part3d *p, const char *name, struct pts *s) {
  struct px_part3d_region *r = realloc(p->regions, (p->nregions + 1) * sizeof *r);
  if (!r) return -1;
  p->regions = r;
  r += p->nregions;
  memset(r, 0, sizeof *r);
  snprintf(r->name, sizeof r->name, "%s", name);
  r->xy = s->xy;
  r->n = s->n;
  s->xy = NULL;
  s->n = s->cap = 0;
  r->lo[0] = r->lo[1] = HUGE_VAL;
  r->hi[0] = r->hi[1] = -HUGE_VAL;
  for (size_t i = 0; i < r->n; ++i)
    for (int c = 0; c < 2; ++c) {
      r->lo[c] = fmin(r->lo[c], r->xy[2 * i + (size_t)c]);
      r->hi[c] = fmax(r->hi[c], r->xy[2 * i + (size_t)c]);
    }
  ++p->nregions;
  return 0;
}

static enum px_status vec2(const struct px_case *c, const char *sp, const char *key, double v[2]) {
  char k[512];
  snprintf(k, sizeof k, "%.300s.%.100s", sp, key);
  return px_case_get_vector(c, k, v, 2);
}

static enum px_status real(const struct px_case *c, const char *sp, const char *key, double *v) {
  char k[512];
  snprintf(k, sizeof k, "%.300s.%.100s", sp, key);
  return px_case_get_real(c, k, v);
}

/* A piece of a `path` shape (as px_gran_piece reads it). */
static enum px_status piece(struct px_context *ctx, const struct px_case *c, const char *pp,
                            struct px_geo_path *path) {
  const double deg = 3.14159265358979323846 / 180;
  struct px_geo_prim q;
  const char *type = NULL;
  char key[512];
  memset(&q, 0, sizeof q);
  snprintf(key, sizeof key, "%.300s.type", pp);
  PX_TRY(px_case_get_string(c, key, &type));
  if (strcmp(type, "line") == 0) {
    q.kind = PX_GEO_PRIM_LINE;
    PX_TRY(vec2(c, pp, "from", q.p));
    PX_TRY(vec2(c, pp, "to", q.p + 2));
  } else if (strcmp(type, "arc") == 0) {
    q.kind = PX_GEO_PRIM_ARC;
    PX_TRY(vec2(c, pp, "center", q.p));
    PX_TRY(real(c, pp, "radius", &q.p[2]));
    PX_TRY(real(c, pp, "start", &q.p[3]));
    PX_TRY(real(c, pp, "end", &q.p[4]));
    q.p[3] *= deg, q.p[4] *= deg;
  } else if (strcmp(type, "ellipse_arc") == 0) {
    q.kind = PX_GEO_PRIM_ELLIPSE;
    PX_TRY(vec2(c, pp, "center", q.p));
    PX_TRY(vec2(c, pp, "axes", q.p + 2));
    PX_TRY(real(c, pp, "angle", &q.p[4]));
    PX_TRY(real(c, pp, "start", &q.p[5]));
    PX_TRY(real(c, pp, "end", &q.p[6]));
    q.p[4] *= deg, q.p[5] *= deg, q.p[6] *= deg;
  } else if (strcmp(type, "parabola") == 0) {
    q.kind = PX_GEO_PRIM_BEZIER2;
    PX_TRY(vec2(c, pp, "from", q.p));
    PX_TRY(vec2(c, pp, "control", q.p + 2));
    PX_TRY(vec2(c, pp, "to", q.p + 4));
  } else { /* polyline */
    size_t n;
    enum px_status st = PX_STATUS_OK;
    snprintf(key, sizeof key, "%.300s.points", pp);
    PX_TRY(px_case_count(c, key, &n));
    double *xy = malloc((2 * n + 2) * sizeof *xy);
    if (!xy) return PX_STATUS_NOMEM;
    for (size_t k = 0; k < n && st == PX_STATUS_OK; ++k) {
      snprintf(key, sizeof key, "%.300s.points[%zu]", pp, k);
      st = px_case_get_vector(c, key, xy + 2 * k, 2);
    }
    if (st == PX_STATUS_OK) st = px_geo_path_add_points(ctx, path, xy, n, 0);
    free(xy);
    return st;
  }
  return px_geo_path_add(ctx, path, &q);
}

/* Contour i of the case (its shape at sp) as one region, or a dxf shape's
 * loops as one region each. */
static enum px_status contour(struct px_part3d *p, struct px_context *ctx, const struct px_case *c,
                              const char *name, const char *sp) {
  const double deg = 3.14159265358979323846 / 180;
  const char *type = NULL;
  char key[512];
  struct pts s = {NULL, 0, 0};
  struct px_geo_path path;
  enum px_status st = PX_STATUS_OK;
  snprintf(key, sizeof key, "%.300s.type", sp);
  PX_TRY(px_case_get_string(c, key, &type));
  px_geo_path_init(&path, sp);
  if (strcmp(type, "rectangle") == 0) {
    double lo[2], hi[2];
    if ((st = vec2(c, sp, "min", lo)) == PX_STATUS_OK &&
        (st = vec2(c, sp, "max", hi)) == PX_STATUS_OK &&
        (put(&s, lo[0], lo[1]) || put(&s, hi[0], lo[1]) || put(&s, hi[0], hi[1]) ||
         put(&s, lo[0], hi[1])))
      st = PX_STATUS_NOMEM;
  } else if (strcmp(type, "polygon") == 0) {
    size_t n = 0;
    snprintf(key, sizeof key, "%.300s.points", sp);
    st = px_case_count(c, key, &n);
    for (size_t k = 0; k < n && st == PX_STATUS_OK; ++k) {
      double v[2];
      snprintf(key, sizeof key, "%.300s.points[%zu]", sp, k);
      st = px_case_get_vector(c, key, v, 2);
      if (st == PX_STATUS_OK && put(&s, v[0], v[1])) st = PX_STATUS_NOMEM;
    }
  } else if (strcmp(type, "circle") == 0 || strcmp(type, "ellipse") == 0) {
    struct px_geo_prim q;
    memset(&q, 0, sizeof q);
    q.kind = PX_GEO_PRIM_ELLIPSE;
    q.p[6] = 2 * 3.14159265358979323846;
    st = vec2(c, sp, "center", q.p);
    if (st == PX_STATUS_OK && type[0] == 'c') {
      st = real(c, sp, "radius", &q.p[2]);
      q.p[3] = q.p[2];
    } else if (st == PX_STATUS_OK) {
      st = vec2(c, sp, "axes", q.p + 2);
      if (st == PX_STATUS_OK) st = real(c, sp, "angle", &q.p[4]);
      q.p[4] *= deg;
    }
    if (st == PX_STATUS_OK && put_prim(&s, &q)) st = PX_STATUS_NOMEM;
  } else if (strcmp(type, "path") == 0) {
    size_t n = 0;
    snprintf(key, sizeof key, "%.300s.pieces", sp);
    st = px_case_count(c, key, &n);
    for (size_t k = 0; k < n && st == PX_STATUS_OK; ++k) {
      snprintf(key, sizeof key, "%.300s.pieces[%zu]", sp, k);
      st = piece(ctx, c, key, &path);
    }
    if (st == PX_STATUS_OK && put_path(&s, &path)) st = PX_STATUS_NOMEM;
  } else if (strcmp(type, "dxf") == 0) {
    char file[4096];
    const char *layer = NULL;
    double scale = 1, off[2] = {0, 0}, tol = 1e-6;
    struct px_geo_path *paths = NULL;
    size_t np = 0;
    snprintf(key, sizeof key, "%.300s.file", sp);
    st = px_case_input_path(c, key, file, sizeof file);
    snprintf(key, sizeof key, "%.300s.layer", sp);
    if (st == PX_STATUS_OK) st = px_case_get_string(c, key, &layer);
    if (st == PX_STATUS_OK) st = real(c, sp, "scale", &scale);
    if (st == PX_STATUS_OK) st = vec2(c, sp, "offset", off);
    if (st == PX_STATUS_OK) st = real(c, sp, "tolerance", &tol);
    if (st == PX_STATUS_OK)
      st = px_geo_dxf_read(ctx, file, layer, scale, off[0], off[1], tol * scale, &paths, &np);
    for (size_t k = 0; k < np; ++k) {
      char nm[128];
      snprintf(nm, sizeof nm, k ? "%.100s.%zu" : "%.100s", name, k + 1);
      if (st == PX_STATUS_OK && (put_path(&s, &paths[k]) || add_region(p, nm, &s)))
        st = PX_STATUS_NOMEM;
      s.n = 0;
      px_geo_path_free(ctx, &paths[k]);
    }
    px_mem_free(ctx, paths);
    free(s.xy);
    px_geo_path_free(ctx, &path);
    return st;
  } else {
    st = px_context_fail(ctx, PX_STATUS_CONFIG, "%s: shape type '%s' unknown to partix part3d", sp,
                         type);
  }
  px_geo_path_free(ctx, &path);
  if (st == PX_STATUS_OK && s.n >= 3 && add_region(p, name, &s)) st = PX_STATUS_NOMEM;
  free(s.xy);
  return st;
}

int px_part3d_regions(struct px_part3d *p, struct px_context *ctx, const struct px_case *c) {
  size_t n = 0;
  char key[256];
  const char *side = NULL;
  snprintf(key, sizeof key, "granular.contours[%d].side", p->contour_index);
  p->part_inside = px_case_get_string(c, key, &side) == PX_STATUS_OK && strcmp(side, "inside") == 0;
  if (px_case_count(c, "granular.contours", &n) != PX_STATUS_OK) n = 0;
  for (size_t i = 0; i < n; ++i) {
    char sp[128];
    const char *name = "?";
    if ((int)i == p->contour_index) continue;
    /* where the media is not (a second part, side: outside) holds no part */
    snprintf(key, sizeof key, "granular.contours[%zu].side", i);
    if (px_case_get_string(c, key, &side) == PX_STATUS_OK && strcmp(side, "outside") == 0) continue;
    snprintf(key, sizeof key, "granular.contours[%zu].name", i);
    if (px_case_get_string(c, key, &name) != PX_STATUS_OK) name = "?";
    snprintf(sp, sizeof sp, "granular.contours[%zu].shape", i);
    const enum px_status st = contour(p, ctx, c, name, sp);
    if (st == PX_STATUS_NOMEM) {
      fprintf(stderr, "partix part3d: out of memory reading the contours of %s\n", p->base);
      return PX_CLI_EXIT_FAILURE;
    }
    if (st != PX_STATUS_OK) {
      fprintf(stderr, "%s: %s: %s\n", p->file, p->base, px_context_message(ctx));
      return PX_CLI_EXIT_USAGE;
    }
  }
  return 0;
}

void px_part3d_regions_free(struct px_part3d *p) {
  for (size_t i = 0; i < p->nregions; ++i) free(p->regions[i].xy);
  free(p->regions);
  p->regions = NULL;
  p->nregions = 0;
}

/* Inside the closed polygon (crossing number; a point on its boundary may
 * count either way). */
static int inside(const struct px_part3d_region *r, double x, double y) {
  int in = 0;
  for (size_t i = 0, j = r->n - 1; i < r->n; j = i++) {
    const double xi = r->xy[2 * i], yi = r->xy[2 * i + 1];
    const double xj = r->xy[2 * j], yj = r->xy[2 * j + 1];
    if ((yi > y) != (yj > y) && x < xj + (y - yj) / (yi - yj) * (xi - xj)) in = !in;
  }
  return in;
}

const struct px_part3d_region *px_part3d_container(const struct px_part3d *p, size_t k) {
  for (size_t i = 0; i < p->nregions; ++i) {
    const struct px_part3d_region *r = &p->regions[i];
    int all = 1;
    for (size_t l = 0; all && l < p->nloops[k]; ++l) {
      const struct px_geo_polyline *q = &p->loops[k][l];
      for (size_t j = 0; all && j < q->n; ++j)
        all = inside(r, q->x[j] - p->cu + p->center[0], q->y[j] - p->cv + p->center[1]);
    }
    if (all) return r;
  }
  return NULL;
}
