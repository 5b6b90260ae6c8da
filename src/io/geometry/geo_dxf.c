/* DXF import: the ENTITIES section of an ASCII DXF file (group-code/value
 * pairs, any version) into closed paths of primitives.
 * Supported: LINE, ARC, CIRCLE, ELLIPSE, LWPOLYLINE (bulges), POLYLINE with
 * VERTEX/SEQEND, SPLINE (B-spline evaluated by de Boor's algorithm, rational
 * weights honoured; fit points when no control points) as a smooth polyline.
 * Entities with an extrusion direction (0, 0, -1) are mirrored in x (their
 * object coordinate system). Other entities (TEXT, DIMENSION, INSERT, ...)
 * are ignored and reported at debug level. */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "partix/memory.h"
#include "io/geometry/geo_dxf_impl.h"

#define PX_GEO_PI 3.14159265358979323846

/* One group: code and value text (borrowed from the file buffer, trimmed). */
struct px_geo_dxf_group {
  int code;
  const char *val;
  size_t len;
  size_t line; /* line of the code */
};

struct px_geo_dxf_reader {
  const char *name;
  const char *p, *end;
  size_t line;
  struct px_geo_dxf_group cur; /* current group */
  int have;                    /* cur is valid */
};

/* Next line [s, e) trimmed; returns 0 at the end of the text. */
static int px_geo_dxf_line(struct px_geo_dxf_reader *r, const char **s, size_t *len) {
  const char *a, *b;
  if (r->p >= r->end) return 0;
  a = r->p;
  b = a;
  while (b < r->end && *b != '\n') ++b;
  r->p = b < r->end ? b + 1 : b;
  ++r->line;
  while (a < b && (*a == ' ' || *a == '\t' || *a == '\r')) ++a;
  while (b > a && (b[-1] == ' ' || b[-1] == '\t' || b[-1] == '\r')) --b;
  *s = a;
  *len = (size_t)(b - a);
  return 1;
}

static enum px_status px_geo_dxf_next(struct px_context *ctx, struct px_geo_dxf_reader *r) {
  const char *s;
  size_t len;
  char buf[32];
  char *endp;
  long code;
  r->have = 0;
  if (!px_geo_dxf_line(r, &s, &len)) return PX_STATUS_OK;
  if (len == 0 || len >= sizeof buf)
    return px_context_fail(ctx, PX_STATUS_FORMAT, "%s:%zu: expected a DXF group code, found '%.*s'",
                           r->name, r->line, (int)(len > 40 ? 40 : len), s);
  memcpy(buf, s, len);
  buf[len] = '\0';
  errno = 0;
  code = strtol(buf, &endp, 10);
  if (*endp != '\0' || errno)
    return px_context_fail(ctx, PX_STATUS_FORMAT,
                           "%s:%zu: expected a DXF group code (an integer), found '%s' (is this a "
                           "binary DXF? only ASCII DXF is read)",
                           r->name, r->line, buf);
  r->cur.code = (int)code;
  r->cur.line = r->line;
  if (!px_geo_dxf_line(r, &s, &len))
    return px_context_fail(ctx, PX_STATUS_FORMAT,
                           "%s:%zu: group code %ld has no value (file truncated?)", r->name,
                           r->line, code);
  r->cur.val = s;
  r->cur.len = len;
  r->have = 1;
  return PX_STATUS_OK;
}

static int px_geo_dxf_is(const struct px_geo_dxf_group *g, int code, const char *text) {
  const size_t n = strlen(text);
  return g->code == code && g->len == n && memcmp(g->val, text, n) == 0;
}

static enum px_status px_geo_dxf_real(struct px_context *ctx, const struct px_geo_dxf_reader *r,
                                      double *out) {
  char buf[64];
  char *endp;
  if (r->cur.len == 0 || r->cur.len >= sizeof buf)
    return px_context_fail(ctx, PX_STATUS_FORMAT, "%s:%zu: group %d: expected a number", r->name,
                           r->cur.line + 1, r->cur.code);
  memcpy(buf, r->cur.val, r->cur.len);
  buf[r->cur.len] = '\0';
  errno = 0;
  *out = strtod(buf, &endp);
  if (*endp != '\0' || errno || !isfinite(*out))
    return px_context_fail(ctx, PX_STATUS_FORMAT, "%s:%zu: group %d: expected a number, found '%s'",
                           r->name, r->cur.line + 1, r->cur.code, buf);
  return PX_STATUS_OK;
}

/* An integer group (70, 71: 16-bit flags and counts in the DXF reference)
 * read as a (finite) real: clamped before the conversion, which would be
 * undefined beyond the range of int. Entities we ignore carry such groups
 * too, so an odd value is not an error. */
static int px_geo_dxf_int(double v) { return (int)(v > 1e9 ? 1e9 : v < -1e9 ? -1e9 : v); }

static enum px_status px_geo_dxf_push(struct px_context *ctx, struct px_geo_dxf_vec *a, double x) {
  if (a->n == a->cap) {
    size_t cap = a->cap ? 2 * a->cap : 16;
    double *g;
    if (cap > (size_t)-1 / sizeof *g) return PX_STATUS_NOMEM;
    g = px_mem_realloc(ctx, "geometry dxf", a->v, cap * sizeof *g);
    if (!g) return PX_STATUS_NOMEM;
    a->v = g;
    a->cap = cap;
  }
  a->v[a->n++] = x;
  return PX_STATUS_OK;
}

static enum px_status px_geo_dxf_new_piece(struct px_context *ctx, struct px_geo_dxf_pieces *ps,
                                           const char *type, size_t line,
                                           struct px_geo_dxf_piece **out) {
  struct px_geo_dxf_piece *p;
  if (ps->n >= PX_GEO_DXF_PIECES_MAX)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s:%zu: %s: more than %d entities to chain (each becomes at least "
                           "one boundary segment, and the solver takes at most %d)",
                           ps->name, line, type, PX_GEO_DXF_PIECES_MAX, PX_GEO_DXF_PIECES_MAX);
  if (ps->n == ps->cap) {
    size_t cap = ps->cap ? 2 * ps->cap : 16;
    struct px_geo_dxf_piece *g = px_mem_realloc(ctx, "geometry dxf", ps->v, cap * sizeof *g);
    if (!g) return PX_STATUS_NOMEM;
    ps->v = g;
    ps->cap = cap;
  }
  p = &ps->v[ps->n++];
  memset(p, 0, sizeof *p);
  px_geo_path_init(&p->path, NULL);
  snprintf(p->type, sizeof p->type, "%s", type);
  p->line = line;
  *out = p;
  return PX_STATUS_OK;
}

static enum px_status px_geo_dxf_line_prim(struct px_context *ctx, struct px_geo_path *path,
                                           double x0, double y0, double x1, double y1) {
  struct px_geo_prim q;
  memset(&q, 0, sizeof q);
  q.kind = PX_GEO_PRIM_LINE;
  q.p[0] = x0, q.p[1] = y0, q.p[2] = x1, q.p[3] = y1;
  return px_geo_path_add(ctx, path, &q);
}

/* Polyline segment from (x0, y0) to (x1, y1) with bulge b = tan(theta/4),
 * theta the included angle, > 0 counter-clockwise (DXF reference). */
static enum px_status px_geo_dxf_bulge(struct px_context *ctx, struct px_geo_path *path, double x0,
                                       double y0, double x1, double y1, double b) {
  struct px_geo_prim q;
  double dx = x1 - x0, dy = y1 - y0, c = hypot(dx, dy), s, R, mx, my, cx, cy, th;
  if (c <= 0) return PX_STATUS_OK;
  if (fabs(b) < 1e-12) return px_geo_dxf_line_prim(ctx, path, x0, y0, x1, y1);
  s = 0.5 * b * c;                      /* signed sagitta */
  R = (0.25 * c * c + s * s) / (2 * s); /* signed radius */
  mx = 0.5 * (x0 + x1);
  my = 0.5 * (y0 + y1);
  cx = mx + (-dy / c) * (R - s);
  cy = my + (dx / c) * (R - s);
  th = 4 * atan(b);
  memset(&q, 0, sizeof q);
  q.kind = PX_GEO_PRIM_ARC;
  q.p[0] = cx, q.p[1] = cy, q.p[2] = fabs(R);
  q.p[3] = atan2(y0 - cy, x0 - cx);
  q.p[4] = q.p[3] + th;
  return px_geo_path_add(ctx, path, &q);
}

/* De Boor evaluation of a (rational) B-spline of degree p (1..15) with n
 * > p control points (x, y, w; weights > 0) and n + p + 1 non-decreasing
 * knots at parameter u in [kn[p], kn[n]]. *span is the knot span found for
 * the previous, smaller u (p before the first call): the samples walk the
 * knots once, not once per sample. */
static void px_geo_dxf_deboor(int p, const double *kn, const double *cx, const double *cy,
                              const double *w, int n, double u, int *span, double *x, double *y) {
  double dx[16], dy[16], dw[16];
  int k = *span, j, r;
  while (k < n - 1 && u >= kn[k + 1]) ++k;
  *span = k;
  for (j = 0; j <= p; ++j) {
    const int i = j + k - p;
    const double wi = w ? w[i] : 1.0;
    dx[j] = cx[i] * wi;
    dy[j] = cy[i] * wi;
    dw[j] = wi;
  }
  for (r = 1; r <= p; ++r)
    for (j = p; j >= r; --j) {
      const int i = j + k - p;
      const double den = kn[i + p - r + 1] - kn[i];
      const double a = den > 0 ? (u - kn[i]) / den : 0;
      dx[j] = (1 - a) * dx[j - 1] + a * dx[j];
      dy[j] = (1 - a) * dy[j - 1] + a * dy[j];
      dw[j] = (1 - a) * dw[j - 1] + a * dw[j];
    }
  *x = dx[p] / dw[p];
  *y = dy[p] / dw[p];
}

/* Entity being collected. */
struct px_geo_dxf_ent {
  char type[16];
  size_t line;
  char layer[128];
  double x[4], y[4]; /* 10/20, 11/21 */
  double r40, r41, r42, r50, r51, ez;
  int i70, i71, have_layer;
  struct px_geo_dxf_vec vx, vy, bulge; /* LWPOLYLINE vertices; SPLINE control points */
  struct px_geo_dxf_vec fx, fy;        /* SPLINE fit points */
  struct px_geo_dxf_vec knots, weights;
};

static void px_geo_dxf_ent_reset(struct px_geo_dxf_ent *e) {
  struct px_geo_dxf_vec a = e->vx, b = e->vy, c = e->bulge, d = e->fx, f = e->fy, k = e->knots,
                        w = e->weights;
  memset(e, 0, sizeof *e);
  a.n = b.n = c.n = d.n = f.n = k.n = w.n = 0;
  e->vx = a, e->vy = b, e->bulge = c, e->fx = d, e->fy = f, e->knots = k, e->weights = w;
  e->ez = 1;
}

static void px_geo_dxf_ent_free(struct px_context *ctx, struct px_geo_dxf_ent *e) {
  px_mem_free(ctx, e->vx.v);
  px_mem_free(ctx, e->vy.v);
  px_mem_free(ctx, e->bulge.v);
  px_mem_free(ctx, e->fx.v);
  px_mem_free(ctx, e->fy.v);
  px_mem_free(ctx, e->knots.v);
  px_mem_free(ctx, e->weights.v);
}

/* |v| <= lim (and so finite). */
static int px_geo_dxf_within(double v, double lim) { return fabs(v) <= lim; }

/* Reduce an angle beyond a few turns to less than one (same direction),
 * so that making an end follow a start takes at most a few turns: angles
 * of 1e20 are finite, and adding a turn to them changes nothing. */
static double px_geo_dxf_angle(double a, double turn) {
  return fabs(a) > 2 * turn ? fmod(a, turn) : a;
}

/* Make the collected entity a piece (or ignore it). Every value it uses is
 * checked first (finite, within PX_GEO_DXF_COORD_MAX / PX_GEO_DXF_BULGE_MAX, radii
 * > 0, SPLINE control points, knots and weights consistent); the error
 * names the file and the entity's line. */
/* ARC, CIRCLE: centre, radius, angles [deg]. */
static enum px_status px_geo_dxf_emit_arc(struct px_context *ctx, const char *name,
                                          const struct px_geo_dxf_ent *e,
                                          struct px_geo_dxf_pieces *ps, double mir) {
  struct px_geo_dxf_piece *pc = NULL;
  struct px_geo_prim q;
  const double C = PX_GEO_DXF_COORD_MAX;
  memset(&q, 0, sizeof q);
  const int circle = e->type[0] == 'C';
  double a0, a1;
  int turns;
  if (!(e->r40 > 0) || !(e->r40 <= C) || !px_geo_dxf_within(e->x[0], C) ||
      !px_geo_dxf_within(e->y[0], C))
    return px_context_fail(ctx, PX_STATUS_FORMAT,
                           "%s:%zu: %s with centre (%g, %g) and radius %g (radius in (0, %g], "
                           "centre within +-%g drawing units)",
                           name, e->line, e->type, e->x[0], e->y[0], e->r40, C, C);
  a0 = circle ? 0 : px_geo_dxf_angle(e->r50, 360) * PX_GEO_PI / 180;
  a1 = circle ? 2 * PX_GEO_PI : px_geo_dxf_angle(e->r51, 360) * PX_GEO_PI / 180;
  for (turns = 0; !circle && a1 <= a0 && turns < 8; ++turns) a1 += 2 * PX_GEO_PI;
  if (!(a1 > a0))
    return px_context_fail(ctx, PX_STATUS_FORMAT, "%s:%zu: ARC from %g to %g degrees", name,
                           e->line, e->r50, e->r51);
  PX_TRY(px_geo_dxf_new_piece(ctx, ps, e->type, e->line, &pc));
  pc->closed = circle;
  q.kind = PX_GEO_PRIM_ARC;
  q.p[0] = mir * e->x[0], q.p[1] = e->y[0], q.p[2] = e->r40;
  if (mir < 0) { /* mirrored: angle a -> pi - a, direction reversed */
    q.p[3] = PX_GEO_PI - a0;
    q.p[4] = PX_GEO_PI - a1;
  } else {
    q.p[3] = a0;
    q.p[4] = a1;
  }
  return px_geo_path_add(ctx, &pc->path, &q);
}

/* ELLIPSE: centre, major axis, axis ratio, parameters [rad]. */
static enum px_status px_geo_dxf_emit_ellipse(struct px_context *ctx, const char *name,
                                              const struct px_geo_dxf_ent *e,
                                              struct px_geo_dxf_pieces *ps, double mir) {
  struct px_geo_dxf_piece *pc = NULL;
  struct px_geo_prim q;
  const double C = PX_GEO_DXF_COORD_MAX;
  memset(&q, 0, sizeof q);
  double a, t0, t1;
  int turns;
  if (!px_geo_dxf_within(e->x[0], C) || !px_geo_dxf_within(e->y[0], C) ||
      !px_geo_dxf_within(e->x[1], C) || !px_geo_dxf_within(e->y[1], C))
    return px_context_fail(ctx, PX_STATUS_FORMAT,
                           "%s:%zu: ELLIPSE centre (%g, %g) or major axis (%g, %g) beyond "
                           "+-%g drawing units",
                           name, e->line, e->x[0], e->y[0], e->x[1], e->y[1], C);
  a = hypot(e->x[1], e->y[1]);
  if (!(a > 0) || !(e->r40 > 0) || !(a * e->r40 <= 2 * C) || !isfinite(e->r41) || !isfinite(e->r42))
    return px_context_fail(ctx, PX_STATUS_FORMAT,
                           "%s:%zu: degenerate ELLIPSE (major semi-axis %g, axis ratio %g)", name,
                           e->line, a, e->r40);
  t0 = px_geo_dxf_angle(e->r41, 2 * PX_GEO_PI);
  t1 = px_geo_dxf_angle(e->r42, 2 * PX_GEO_PI);
  for (turns = 0; t1 <= t0 && turns < 8; ++turns) t1 += 2 * PX_GEO_PI;
  if (!(t1 > t0))
    return px_context_fail(ctx, PX_STATUS_FORMAT, "%s:%zu: ELLIPSE from %g to %g rad", name,
                           e->line, e->r41, e->r42);
  PX_TRY(px_geo_dxf_new_piece(ctx, ps, e->type, e->line, &pc));
  pc->closed = fabs(t1 - t0 - 2 * PX_GEO_PI) < 1e-9;
  q.kind = PX_GEO_PRIM_ELLIPSE;
  q.p[0] = e->x[0], q.p[1] = e->y[0], q.p[2] = a, q.p[3] = a * e->r40;
  q.p[4] = atan2(e->y[1], e->x[1]);
  q.p[5] = t0, q.p[6] = t1;
  if (mir < 0) { /* mirror: centre x, rotation, parameter direction */
    q.p[0] = -q.p[0];
    q.p[4] = PX_GEO_PI - q.p[4];
    q.p[5] = -t0, q.p[6] = -t1;
  }
  return px_geo_path_add(ctx, &pc->path, &q);
}

/* LWPOLYLINE, POLYLINE: vertices with bulges. */
static enum px_status px_geo_dxf_emit_polyline(struct px_context *ctx, const char *name,
                                               const struct px_geo_dxf_ent *e,
                                               struct px_geo_dxf_pieces *ps, double mir) {
  struct px_geo_dxf_piece *pc = NULL;
  const double C = PX_GEO_DXF_COORD_MAX;
  size_t k;
  const size_t n = e->vx.n;
  const int closed = e->i70 & 1;
  if (n < 2) return PX_STATUS_OK;
  for (k = 0; k < n; ++k) {
    const double b = k < e->bulge.n ? e->bulge.v[k] : 0;
    if (!px_geo_dxf_within(e->vx.v[k], C) || !px_geo_dxf_within(e->vy.v[k], C))
      return px_context_fail(ctx, PX_STATUS_FORMAT,
                             "%s:%zu: %s vertex %zu (%g, %g) beyond +-%g drawing units", name,
                             e->line, e->type, k + 1, e->vx.v[k], e->vy.v[k], C);
    if (!px_geo_dxf_within(b, PX_GEO_DXF_BULGE_MAX))
      return px_context_fail(ctx, PX_STATUS_FORMAT,
                             "%s:%zu: %s vertex %zu: bulge %g beyond +-%g (the bulge is the "
                             "tangent of a quarter of the arc's angle)",
                             name, e->line, e->type, k + 1, b, PX_GEO_DXF_BULGE_MAX);
  }
  PX_TRY(px_geo_dxf_new_piece(ctx, ps, e->type, e->line, &pc));
  pc->closed = closed;
  for (k = 0; k + 1 < n + (size_t)closed; ++k) {
    const size_t j = (k + 1) % n;
    const double b = k < e->bulge.n ? e->bulge.v[k] : 0;
    PX_TRY(px_geo_dxf_bulge(ctx, &pc->path, mir * e->vx.v[k], e->vy.v[k], mir * e->vx.v[j],
                            e->vy.v[j], mir * b));
  }
  if (pc->path.n == 0) {
    px_geo_path_free(ctx, &pc->path);
    --ps->n;
  }
  return PX_STATUS_OK;
}

/* A SPLINE's control points, knots and weights checked, and the curve
 * sampled into pts (x, y pairs; x mirrored by mir). */
static enum px_status px_geo_dxf_spline_sample(struct px_context *ctx, const char *name,
                                               const struct px_geo_dxf_ent *e,
                                               struct px_geo_dxf_pieces *ps, double mir,
                                               struct px_geo_dxf_vec *pts) {
  const double C = PX_GEO_DXF_COORD_MAX;
  size_t k;
  enum px_status st = PX_STATUS_OK;
  const int p = e->i71;
  const size_t n = e->vx.n;
  const double *w = e->weights.n ? e->weights.v : NULL;
  size_t j, ns;
  int span = p;
  double u0, u1;
  if (p < 1 || p > 15 || n > (size_t)PX_GEO_DXF_PIECES_MAX || (size_t)p >= n ||
      e->knots.n != n + (size_t)p + 1)
    return px_context_fail(ctx, PX_STATUS_FORMAT,
                           "%s:%zu: SPLINE with degree %d, %zu control points and %zu knots "
                           "(expected degree 1 to 15, more control points than the degree "
                           "and control points + degree + 1 knots)",
                           name, e->line, p, n, e->knots.n);
  for (k = 0; k < e->knots.n; ++k)
    if (!px_geo_dxf_within(e->knots.v[k], C) || (k && !(e->knots.v[k] >= e->knots.v[k - 1])))
      return px_context_fail(ctx, PX_STATUS_FORMAT,
                             "%s:%zu: SPLINE knot %zu = %g: knots must be finite and "
                             "non-decreasing",
                             name, e->line, k + 1, e->knots.v[k]);
  if (w && e->weights.n != n)
    return px_context_fail(ctx, PX_STATUS_FORMAT,
                           "%s:%zu: SPLINE with %zu weights (group 41) for %zu control "
                           "points: one per point, or none",
                           name, e->line, e->weights.n, n);
  for (k = 0; w && k < n; ++k)
    if (!(w[k] > 0) || !(w[k] <= PX_GEO_DXF_WEIGHT_MAX))
      return px_context_fail(ctx, PX_STATUS_FORMAT,
                             "%s:%zu: SPLINE weight %zu = %g: weights must be in (0, %g]", name,
                             e->line, k + 1, w[k], PX_GEO_DXF_WEIGHT_MAX);
  u0 = e->knots.v[p];
  u1 = e->knots.v[n];
  if (!(u1 > u0))
    return px_context_fail(ctx, PX_STATUS_FORMAT,
                           "%s:%zu: SPLINE whose knots %d and %zu are equal (%g): no "
                           "parameter range to draw",
                           name, e->line, p + 1, n + 1, u0);
  /* 32 samples per control point (at least 256), 8 per point beyond
   * 2048 points */
  ns = n <= 2048 ? (32 * n < 256 ? 256 : 32 * n) : 8 * n + 49152;
  if (ns + 1 > PX_GEO_DXF_SAMPLES_MAX - ps->samples)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s:%zu: SPLINE with %zu control points: the SPLINEs of the file "
                           "sample more than %d points",
                           name, e->line, n, PX_GEO_DXF_SAMPLES_MAX);
  ps->samples += ns + 1;
  for (j = 0; j <= ns && st == PX_STATUS_OK; ++j) {
    double x, y;
    px_geo_dxf_deboor(p, e->knots.v, e->vx.v, e->vy.v, w, (int)n,
                      u0 + (u1 - u0) * (double)j / (double)ns, &span, &x, &y);
    st = px_geo_dxf_push(ctx, pts, mir * x);
    if (st == PX_STATUS_OK) st = px_geo_dxf_push(ctx, pts, y);
  }
  return st;
}

/* SPLINE: a B-spline (control points, knots, weights) or fit points. */
static enum px_status px_geo_dxf_emit_spline(struct px_context *ctx, const char *name,
                                             const struct px_geo_dxf_ent *e,
                                             struct px_geo_dxf_pieces *ps, double mir) {
  struct px_geo_dxf_piece *pc = NULL;
  const double C = PX_GEO_DXF_COORD_MAX;
  size_t k;
  const int closed = e->i70 & 1;
  struct px_geo_dxf_vec pts = {0};
  enum px_status st = PX_STATUS_OK;
  if (e->vx.n != e->vy.n || e->fx.n != e->fy.n)
    return px_context_fail(ctx, PX_STATUS_FORMAT,
                           "%s:%zu: SPLINE with %zu x (group 10) and %zu y (group 20) "
                           "control-point coordinates, %zu x (11) and %zu y (21) fit-point "
                           "coordinates: every point needs both",
                           name, e->line, e->vx.n, e->vy.n, e->fx.n, e->fy.n);
  for (k = 0; k < e->vx.n; ++k)
    if (!px_geo_dxf_within(e->vx.v[k], C) || !px_geo_dxf_within(e->vy.v[k], C))
      return px_context_fail(ctx, PX_STATUS_FORMAT,
                             "%s:%zu: SPLINE control point %zu (%g, %g) beyond +-%g drawing "
                             "units",
                             name, e->line, k + 1, e->vx.v[k], e->vy.v[k], C);
  for (k = 0; k < e->fx.n; ++k)
    if (!px_geo_dxf_within(e->fx.v[k], C) || !px_geo_dxf_within(e->fy.v[k], C))
      return px_context_fail(ctx, PX_STATUS_FORMAT,
                             "%s:%zu: SPLINE fit point %zu (%g, %g) beyond +-%g drawing units",
                             name, e->line, k + 1, e->fx.v[k], e->fy.v[k], C);
  if (e->vx.n >= 2) {
    st = px_geo_dxf_spline_sample(ctx, name, e, ps, mir, &pts);
  } else if (e->fx.n >= 2) {
    if (e->fx.n + 1 > PX_GEO_DXF_SAMPLES_MAX - ps->samples)
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "%s:%zu: SPLINE with %zu fit points: the SPLINEs of the file "
                             "hold more than %d points",
                             name, e->line, e->fx.n, PX_GEO_DXF_SAMPLES_MAX);
    ps->samples += e->fx.n + 1;
    for (k = 0; k < e->fx.n && st == PX_STATUS_OK; ++k) {
      st = px_geo_dxf_push(ctx, &pts, mir * e->fx.v[k]);
      if (st == PX_STATUS_OK) st = px_geo_dxf_push(ctx, &pts, e->fy.v[k]);
    }
    if (closed && st == PX_STATUS_OK) {
      st = px_geo_dxf_push(ctx, &pts, mir * e->fx.v[0]);
      if (st == PX_STATUS_OK) st = px_geo_dxf_push(ctx, &pts, e->fy.v[0]);
    }
  } else {
    return px_context_fail(ctx, PX_STATUS_FORMAT, "%s:%zu: SPLINE without control or fit points",
                           name, e->line);
  }
  if (st == PX_STATUS_OK) st = px_geo_dxf_new_piece(ctx, ps, e->type, e->line, &pc);
  if (st == PX_STATUS_OK) {
    pc->closed = closed;
    st = px_geo_path_add_points(ctx, &pc->path, pts.v, pts.n / 2, 1);
  }
  px_mem_free(ctx, pts.v);
  return st;
}

static enum px_status px_geo_dxf_emit(struct px_context *ctx, const char *name,
                                      struct px_geo_dxf_ent *e, const char *layer,
                                      struct px_geo_dxf_pieces *ps) {
  struct px_geo_dxf_piece *pc = NULL;
  const double mir = e->ez < 0 ? -1.0 : 1.0; /* OCS (0,0,-1): x mirrored */
  const double C = PX_GEO_DXF_COORD_MAX;
  size_t k;
  if (layer && layer[0] && strcmp(layer, e->layer) != 0) return PX_STATUS_OK;
  if (strcmp(e->type, "LINE") == 0) {
    for (k = 0; k < 2; ++k)
      if (!px_geo_dxf_within(e->x[k], C) || !px_geo_dxf_within(e->y[k], C))
        return px_context_fail(ctx, PX_STATUS_FORMAT,
                               "%s:%zu: LINE end (%g, %g) beyond +-%g drawing units", name, e->line,
                               e->x[k], e->y[k], C);
    PX_TRY(px_geo_dxf_new_piece(ctx, ps, e->type, e->line, &pc));
    return px_geo_dxf_line_prim(ctx, &pc->path, e->x[0], e->y[0], e->x[1], e->y[1]);
  }
  if (strcmp(e->type, "ARC") == 0 || strcmp(e->type, "CIRCLE") == 0)
    return px_geo_dxf_emit_arc(ctx, name, e, ps, mir);
  if (strcmp(e->type, "ELLIPSE") == 0) return px_geo_dxf_emit_ellipse(ctx, name, e, ps, mir);
  if (strcmp(e->type, "LWPOLYLINE") == 0 || strcmp(e->type, "POLYLINE") == 0)
    return px_geo_dxf_emit_polyline(ctx, name, e, ps, mir);
  if (strcmp(e->type, "SPLINE") == 0) return px_geo_dxf_emit_spline(ctx, name, e, ps, mir);
  return PX_STATUS_OK;
}

/* A group of the entity being read (after its group 0): its layer, and the
 * values the entities take (others skipped). */
static enum px_status px_geo_dxf_group(struct px_context *ctx, struct px_geo_dxf_reader *r,
                                       struct px_geo_dxf_ent *e, int in_polyline) {
  enum px_status st = PX_STATUS_OK;
  const int c = r->cur.code;
  double v = 0;
  if (c == 8) {
    const size_t n = r->cur.len < sizeof e->layer - 1 ? r->cur.len : sizeof e->layer - 1;
    memcpy(e->layer, r->cur.val, n);
    e->layer[n] = '\0';
    return PX_STATUS_OK;
  }
  if (c == 100 || c == 5 || c == 330 || c == 6 || c == 62 || c == 370 || (c >= 1000))
    return PX_STATUS_OK;
  if ((c >= 10 && c <= 59) || (c >= 70 && c <= 79) || (c >= 210 && c <= 230)) {
    st = px_geo_dxf_real(ctx, r, &v);
    if (st != PX_STATUS_OK) return st;
  } else {
    return PX_STATUS_OK;
  }
  if (strcmp(e->type, "LWPOLYLINE") == 0 || in_polyline) {
    if (c == 10) {
      if (!in_polyline) {
        st = px_geo_dxf_push(ctx, &e->vx, v);
        if (st == PX_STATUS_OK) st = px_geo_dxf_push(ctx, &e->vy, 0);
        if (st == PX_STATUS_OK) st = px_geo_dxf_push(ctx, &e->bulge, 0);
      } else if (e->vx.n) {
        e->vx.v[e->vx.n - 1] = v;
      }
    } else if (c == 20) {
      if (e->vy.n) e->vy.v[e->vy.n - 1] = v;
    } else if (c == 42) {
      if (e->bulge.n) e->bulge.v[e->bulge.n - 1] = v;
    } else if (c == 70 && (!in_polyline || e->vx.n == 0)) {
      e->i70 = px_geo_dxf_int(v);
    } else if (c == 230) {
      e->ez = v;
    }
    return st;
  }
  if (strcmp(e->type, "SPLINE") == 0) {
    if (c == 10)
      st = px_geo_dxf_push(ctx, &e->vx, v);
    else if (c == 20) {
      if (e->vx.n) st = px_geo_dxf_push(ctx, &e->vy, v);
    } else if (c == 11)
      st = px_geo_dxf_push(ctx, &e->fx, v);
    else if (c == 21) {
      if (e->fx.n) st = px_geo_dxf_push(ctx, &e->fy, v);
    } else if (c == 40)
      st = px_geo_dxf_push(ctx, &e->knots, v);
    else if (c == 41)
      st = px_geo_dxf_push(ctx, &e->weights, v);
    else if (c == 70)
      e->i70 = px_geo_dxf_int(v);
    else if (c == 71)
      e->i71 = px_geo_dxf_int(v);
    else if (c == 230)
      e->ez = v;
    return st;
  }
  if (c >= 10 && c <= 13)
    e->x[c - 10] = v;
  else if (c >= 20 && c <= 23)
    e->y[c - 20] = v;
  else if (c == 40)
    e->r40 = v;
  else if (c == 41)
    e->r41 = v;
  else if (c == 42)
    e->r42 = v;
  else if (c == 50)
    e->r50 = v;
  else if (c == 51)
    e->r51 = v;
  else if (c == 70)
    e->i70 = px_geo_dxf_int(v);
  else if (c == 71)
    e->i71 = px_geo_dxf_int(v);
  else if (c == 230)
    e->ez = v;
  return PX_STATUS_OK;
}

/* The ENTITIES section of the file into pieces ps (e: the entity being
 * read, reset here, freed by the caller). */
static enum px_status px_geo_dxf_read_entities(struct px_context *ctx, const char *name,
                                               const char *text, size_t size, const char *layer,
                                               struct px_geo_dxf_ent *e,
                                               struct px_geo_dxf_pieces *ps) {
  struct px_geo_dxf_reader r;
  enum px_status st = PX_STATUS_OK;
  int in_entities = 0, in_ent = 0, in_polyline = 0, saw_entities = 0;
  memset(&r, 0, sizeof r);
  r.name = name;
  r.p = text;
  r.end = text + size;
  px_geo_dxf_ent_reset(e);
  for (;;) {
    st = px_geo_dxf_next(ctx, &r);
    if (st != PX_STATUS_OK) return st;
    if (!r.have) break;
    if (r.cur.code == 0) {
      if (in_polyline) {
        /* old-style POLYLINE: VERTEX entities (10/20/42 follow) up to SEQEND */
        if (px_geo_dxf_is(&r.cur, 0, "VERTEX")) {
          st = px_geo_dxf_push(ctx, &e->vx, 0);
          if (st == PX_STATUS_OK) st = px_geo_dxf_push(ctx, &e->vy, 0);
          if (st == PX_STATUS_OK) st = px_geo_dxf_push(ctx, &e->bulge, 0);
          if (st != PX_STATUS_OK) return st;
          continue;
        }
        st = px_geo_dxf_emit(ctx, name, e, layer, ps);
        if (st != PX_STATUS_OK) return st;
        in_ent = in_polyline = 0;
        if (px_geo_dxf_is(&r.cur, 0, "SEQEND")) continue;
      } else if (in_ent) {
        /* an entity ends where the next group 0 begins */
        st = px_geo_dxf_emit(ctx, name, e, layer, ps);
        if (st != PX_STATUS_OK) return st;
        in_ent = 0;
      }
      if (px_geo_dxf_is(&r.cur, 0, "SECTION")) {
        st = px_geo_dxf_next(ctx, &r);
        if (st != PX_STATUS_OK) return st;
        in_entities = r.have && px_geo_dxf_is(&r.cur, 2, "ENTITIES");
        saw_entities |= in_entities;
        continue;
      }
      if (px_geo_dxf_is(&r.cur, 0, "ENDSEC")) {
        in_entities = 0;
        continue;
      }
      if (px_geo_dxf_is(&r.cur, 0, "EOF")) break;
      if (!in_entities) continue;
      px_geo_dxf_ent_reset(e);
      {
        const size_t n = r.cur.len < sizeof e->type - 1 ? r.cur.len : sizeof e->type - 1;
        memcpy(e->type, r.cur.val, n);
        e->type[n] = '\0';
      }
      e->line = r.cur.line;
      in_ent = 1;
      in_polyline = strcmp(e->type, "POLYLINE") == 0;
      if (strcmp(e->type, "INSERT") == 0)
        px_log(ctx, PX_LOG_LEVEL_WARN,
               "%s:%zu: INSERT (block reference) ignored: explode blocks in the CAD program", name,
               e->line);
      continue;
    }
    if (!in_ent) continue;
    st = px_geo_dxf_group(ctx, &r, e, in_polyline);
    if (st != PX_STATUS_OK) return st;
  }
  if (in_ent) {
    st = px_geo_dxf_emit(ctx, name, e, layer, ps);
    if (st != PX_STATUS_OK) return st;
  }
  if (!saw_entities)
    return px_context_fail(ctx, PX_STATUS_FORMAT, "%s: no ENTITIES section (is this a DXF file?)",
                           name);
  if (ps->n == 0)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: no LINE, ARC, CIRCLE, ELLIPSE, LWPOLYLINE, POLYLINE or SPLINE "
                           "entities%s%s%s",
                           name, layer && layer[0] ? " on layer '" : "",
                           layer && layer[0] ? layer : "", layer && layer[0] ? "'" : "");
  return PX_STATUS_OK;
}

enum px_status px_geo_dxf_parse(struct px_context *ctx, const char *name, const char *text,
                                size_t size, const char *layer, double scale, double dx, double dy,
                                double tol, struct px_geo_path **paths, size_t *npaths) {
  struct px_geo_dxf_ent e;
  struct px_geo_dxf_pieces ps = {0};
  enum px_status st;
  size_t k, nout = 0;
  struct px_geo_path *out = NULL;

  *paths = NULL;
  *npaths = 0;
  /* the mapping keeps every coordinate (within PX_GEO_DXF_COORD_MAX drawing
   * units) and every distance finite */
  if (!(scale > 0 && scale <= 1e100) || !(fabs(dx) <= 1e100) || !(fabs(dy) <= 1e100) ||
      !(tol >= 0 && tol <= 1e100))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: scale %g, offset (%g, %g) and tolerance %g: a scale in (0, "
                           "1e100], offset and tolerance within 1e100",
                           name, scale, dx, dy, tol);
  memset(&e, 0, sizeof e);
  ps.name = name;
  st = px_geo_dxf_read_entities(ctx, name, text, size, layer, &e, &ps);
  if (st == PX_STATUS_OK) {
    for (k = 0; k < ps.n; ++k) {
      size_t j;
      for (j = 0; j < ps.v[k].path.n; ++j)
        px_geo_dxf_transform(&ps.v[k].path.prims[j], scale, dx, dy);
    }
    out = px_mem_calloc(ctx, "geometry dxf", ps.n, sizeof *out);
    st = out ? px_geo_dxf_chain(ctx, name, &ps, tol, out, &nout) : PX_STATUS_NOMEM;
  }
  if (st == PX_STATUS_OK) {
    *paths = out;
    *npaths = nout;
    out = NULL;
    nout = 0;
  }
  if (out) {
    for (k = 0; k < nout; ++k) px_geo_path_free(ctx, &out[k]);
    px_mem_free(ctx, out);
  }
  for (k = 0; k < ps.n; ++k) px_geo_path_free(ctx, &ps.v[k].path);
  px_mem_free(ctx, ps.v);
  px_geo_dxf_ent_free(ctx, &e);
  return st;
}

enum px_status px_geo_dxf_read(struct px_context *ctx, const char *file, const char *layer,
                               double scale, double dx, double dy, double tol,
                               struct px_geo_path **paths, size_t *npaths) {
  FILE *f = fopen(file, "rb");
  char *text;
  long size;
  size_t got;
  enum px_status st;
  struct stat sb;
  if (!f)
    return px_context_fail(ctx, PX_STATUS_IO, "cannot open DXF file '%s': %s", file,
                           strerror(errno));
  /* a regular file of bounded size (not a device, pipe or directory: their
   * size says nothing about what reading them gives) */
  if (fstat(fileno(f), &sb) != 0 || !S_ISREG(sb.st_mode)) {
    fclose(f);
    return px_context_fail(ctx, PX_STATUS_IO, "DXF file '%s' is not a regular file", file);
  }
  if ((double)sb.st_size > PX_GEO_DXF_FILE_MAX) {
    fclose(f);
    return px_context_fail(ctx, PX_STATUS_IO,
                           "DXF file '%s' holds %.0f MiB: more than the %.0f "
                           "MiB a drawing may hold",
                           file, (double)sb.st_size / 1048576.0, PX_GEO_DXF_FILE_MAX / 1048576.0);
  }
  if (fseek(f, 0, SEEK_END) != 0 || (size = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0 ||
      (double)size > PX_GEO_DXF_FILE_MAX) {
    fclose(f);
    return px_context_fail(ctx, PX_STATUS_IO, "cannot read DXF file '%s'", file);
  }
  text = px_mem_alloc(ctx, "geometry dxf", (size_t)size + 1);
  if (!text) {
    fclose(f);
    return PX_STATUS_NOMEM;
  }
  got = fread(text, 1, (size_t)size, f);
  fclose(f);
  if (got != (size_t)size) {
    px_mem_free(ctx, text);
    return px_context_fail(ctx, PX_STATUS_IO, "cannot read DXF file '%s'", file);
  }
  text[size] = '\0';
  st = px_geo_dxf_parse(ctx, file, text, (size_t)size, layer, scale, dx, dy, tol, paths, npaths);
  px_mem_free(ctx, text);
  return st;
}
