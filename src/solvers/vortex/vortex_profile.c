/* Body contours for the vortex solver (see vortex_profile.h): the shapes and
 * readers of io/geometry/ wrapped with this solver's panel limits and
 * checks, placement, and the checks (finite, oriented, no self-crossing, no
 * overlap between bodies). */
#include "solvers/vortex/vortex_profile.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "io/geometry/geo_profile.h"
#include "io/geometry/geo_shape.h"
#include "partix/memory.h"

#define VX_PI 3.14159265358979323846

/* Take over the arrays of a polyline of the geometry layer (both come from
 * px_mem_alloc of ctx); p is left empty. */
static void contour_take(struct px_vortex_contour *c, struct px_geo_polyline *p) {
  c->n = p->n;
  c->x = p->x;
  c->y = p->y;
  c->line = p->line;
  snprintf(c->source, sizeof c->source, "%s", p->source);
  memset(p, 0, sizeof *p);
}

void px_vortex_contour_free(struct px_context *ctx, struct px_vortex_contour *c) {
  if (!c) return;
  px_mem_free(ctx, c->x);
  px_mem_free(ctx, c->y);
  px_mem_free(ctx, c->line);
  c->x = c->y = NULL;
  c->line = NULL;
  c->n = 0;
}

double px_vortex_mean_panel_length(const struct px_vortex_contour *b, size_t nb) {
  double lmin = INFINITY;
  for (size_t i = 0; i < nb; ++i) {
    double per = 0.0;
    for (size_t k = 0; k < b[i].n; ++k) {
      size_t j = (k + 1) % b[i].n;
      per += hypot(b[i].x[j] - b[i].x[k], b[i].y[j] - b[i].y[k]);
    }
    lmin = fmin(lmin, per / (double)b[i].n);
  }
  return lmin;
}

static enum px_status check_panels(struct px_context *ctx, size_t n, const char *what) {
  if (n < PX_VORTEX_MIN_PANELS)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: %zu panels is too few (at least %d are needed; a few hundred "
                           "are usual)",
                           what, n, PX_VORTEX_MIN_PANELS);
  if (n > PX_VORTEX_MAX_PANELS)
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: %zu panels is too many (at most %d)", what,
                           n, PX_VORTEX_MAX_PANELS);
  return PX_STATUS_OK;
}

enum px_status px_vortex_profile_circle(struct px_context *ctx, double radius, size_t n,
                                        struct px_vortex_contour *out) {
  struct px_geo_polyline p;
  memset(out, 0, sizeof *out);
  PX_TRY(check_panels(ctx, n, "circle"));
  PX_TRY(px_geo_shape_circle(ctx, radius, n, &p));
  contour_take(out, &p);
  return PX_STATUS_OK;
}

enum px_status px_vortex_profile_ellipse(struct px_context *ctx, double a, double b, size_t n,
                                         struct px_vortex_contour *out) {
  struct px_geo_polyline p;
  memset(out, 0, sizeof *out);
  PX_TRY(check_panels(ctx, n, "ellipse"));
  PX_TRY(px_geo_shape_ellipse(ctx, a, b, n, &p));
  contour_take(out, &p);
  return PX_STATUS_OK;
}

enum px_status px_vortex_profile_plate(struct px_context *ctx, double length, double thickness,
                                       size_t n, struct px_vortex_contour *out) {
  struct px_geo_polyline p;
  memset(out, 0, sizeof *out);
  PX_TRY(check_panels(ctx, n, "plate"));
  PX_TRY(px_geo_shape_plate(ctx, length, thickness, n, &p));
  contour_take(out, &p);
  return PX_STATUS_OK;
}

enum px_status px_vortex_profile_naca4(struct px_context *ctx, const char *digits, size_t n,
                                       struct px_vortex_contour *out) {
  struct px_geo_polyline p;
  memset(out, 0, sizeof *out);
  PX_TRY(px_geo_shape_naca4_digits(ctx, digits));
  PX_TRY(check_panels(ctx, n, "naca"));
  PX_TRY(px_geo_shape_naca4(ctx, digits, n, &p));
  contour_take(out, &p);
  return PX_STATUS_OK;
}

/* ---------------------------------------------------------------------------
 * File input (io/geometry/geo_profile.h reads; the checks of a body are this
 * solver's, in between) */

enum px_status px_vortex_profile_read_selig(struct px_context *ctx, const char *path, size_t n,
                                            enum px_vortex_spacing spacing,
                                            struct px_vortex_contour *out) {
  struct px_geo_polyline p, q;
  struct px_vortex_contour raw = {0};
  int open_te = 0, reversed = 0;
  enum px_status st;
  memset(out, 0, sizeof *out);
  PX_TRY(check_panels(ctx, n, path));
  PX_TRY(px_geo_profile_read_selig(ctx, path, PX_VORTEX_FILE_MAX_POINTS, &p, &open_te));
  /* checks on the raw polygon, naming file lines (already counter-clockwise:
   * never reversed here) */
  contour_take(&raw, &p);
  st = px_vortex_profile_check(ctx, &raw, &reversed);
  if (st == PX_STATUS_OK)
    st = px_geo_profile_repanel_selig(
        ctx, path, raw.x, raw.y, raw.n, open_te, n,
        spacing == PX_VORTEX_SPACING_COSINE ? PX_GEO_SPACING_COSINE : PX_GEO_SPACING_UNIFORM, &q);
  if (st == PX_STATUS_OK) contour_take(out, &q);
  px_vortex_contour_free(ctx, &raw);
  return st;
}

enum px_status px_vortex_profile_read_points(struct px_context *ctx, const char *path, size_t n,
                                             struct px_vortex_contour *out) {
  struct px_geo_polyline p, q;
  struct px_vortex_contour raw = {0};
  int reversed = 0;
  enum px_status st;
  memset(out, 0, sizeof *out);
  PX_TRY(px_geo_profile_read_points(ctx, path, PX_VORTEX_FILE_MAX_POINTS, &p));
  contour_take(&raw, &p);
  if (n == 0) {
    st = px_vortex_profile_check(ctx, &raw, &reversed);
    if (st == PX_STATUS_OK)
      *out = raw;
    else
      px_vortex_contour_free(ctx, &raw);
    return st;
  }
  st = check_panels(ctx, n, path);
  if (st == PX_STATUS_OK) st = px_vortex_profile_check(ctx, &raw, &reversed);
  if (st == PX_STATUS_OK) st = px_geo_polyline_alloc(ctx, &q, n, 0);
  if (st == PX_STATUS_OK) {
    /* re-sampled from the checked (counter-clockwise) polygon */
    px_geo_polyline_resample(raw.n, raw.x, raw.y, n, q.x, q.y);
    snprintf(q.source, sizeof q.source, "%s", path);
    contour_take(out, &q);
  }
  px_vortex_contour_free(ctx, &raw);
  return st;
}

void px_vortex_profile_place_point(double x, double y, double x0, double y0, double scale,
                                   double angle_deg, double *ox, double *oy) {
  double a = -angle_deg * VX_PI / 180.0; /* clockwise */
  double ca = cos(a), sa = sin(a), sx = scale * x, sy = scale * y;
  *ox = x0 + ca * sx - sa * sy;
  *oy = y0 + sa * sx + ca * sy;
}

void px_vortex_profile_place(struct px_vortex_contour *c, double x0, double y0, double scale,
                             double angle_deg) {
  for (size_t k = 0; k < c->n; ++k)
    px_vortex_profile_place_point(c->x[k], c->y[k], x0, y0, scale, angle_deg, &c->x[k], &c->y[k]);
}

double px_vortex_profile_area(const struct px_vortex_contour *c) {
  double s = 0.0;
  for (size_t k = 0; k < c->n; ++k) {
    size_t j = (k + 1) % c->n;
    s += c->x[k] * c->y[j] - c->x[j] * c->y[k];
  }
  return 0.5 * s;
}

int px_vortex_profile_contains(const struct px_vortex_contour *c, double x, double y) {
  int in = 0;
  for (size_t k = 0, j = c->n - 1; k < c->n; j = k++) {
    if ((c->y[k] > y) != (c->y[j] > y)) {
      double xc = c->x[k] + (y - c->y[k]) * (c->x[j] - c->x[k]) / (c->y[j] - c->y[k]);
      if (x < xc) in = !in;
    }
  }
  return in;
}

static double orient(double ax, double ay, double bx, double by, double cx, double cy) {
  return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

/* Closed segments [p1,p2] and [p3,p4] intersect (touching counts). */
static int segments_intersect(double x1, double y1, double x2, double y2, double x3, double y3,
                              double x4, double y4) {
  if (fmax(x1, x2) < fmin(x3, x4) || fmax(x3, x4) < fmin(x1, x2) || fmax(y1, y2) < fmin(y3, y4) ||
      fmax(y3, y4) < fmin(y1, y2))
    return 0;
  double d1 = orient(x3, y3, x4, y4, x1, y1), d2 = orient(x3, y3, x4, y4, x2, y2);
  double d3 = orient(x1, y1, x2, y2, x3, y3), d4 = orient(x1, y1, x2, y2, x4, y4);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return 1;
  /* collinear or touching cases */
  if (d1 == 0.0 && fmin(x3, x4) <= x1 && x1 <= fmax(x3, x4) && fmin(y3, y4) <= y1 &&
      y1 <= fmax(y3, y4))
    return 1;
  if (d2 == 0.0 && fmin(x3, x4) <= x2 && x2 <= fmax(x3, x4) && fmin(y3, y4) <= y2 &&
      y2 <= fmax(y3, y4))
    return 1;
  if (d3 == 0.0 && fmin(x1, x2) <= x3 && x3 <= fmax(x1, x2) && fmin(y1, y2) <= y3 &&
      y3 <= fmax(y1, y2))
    return 1;
  if (d4 == 0.0 && fmin(x1, x2) <= x4 && x4 <= fmax(x1, x2) && fmin(y1, y2) <= y4 &&
      y4 <= fmax(y1, y2))
    return 1;
  return 0;
}

/* A tree of boxes over runs of consecutive panels of a contour (panel k:
 * vertex k -> vertex k+1 mod n): node 0 spans all panels, a node of more
 * than VX_SEG_LEAF panels has two children (consecutive, left first) that
 * split its range in halves; the crossing tests visit only the nodes whose
 * boxes overlap the panel tested. Leaves hold 4..8 panels, so there are at
 * most 2 (n / 4 + 1) nodes and the depth is below 64. */
#define VX_SEG_LEAF 8
struct seg_tree {
  size_t nnode;
  size_t *lo, *hi;               /* owned: panel range [lo, hi) of each node */
  size_t *left;                  /* owned: first child, 0 for a leaf */
  double *bx0, *by0, *bx1, *by1; /* owned: box of each node */
};

static void seg_tree_free(struct px_context *ctx, struct seg_tree *t) {
  px_mem_free(ctx, t->lo);
  px_mem_free(ctx, t->bx0);
  memset(t, 0, sizeof *t);
}

static enum px_status seg_tree_build(struct px_context *ctx, const struct px_vortex_contour *c,
                                     struct seg_tree *t) {
  const size_t n = c->n, cap = 2 * (n / 4 + 1) + 8;
  memset(t, 0, sizeof *t);
  t->lo = px_mem_alloc(ctx, "vortex.profile", 3 * cap * sizeof(size_t));
  t->bx0 = px_mem_alloc(ctx, "vortex.profile", 4 * cap * sizeof(double));
  if (!t->lo || !t->bx0) {
    seg_tree_free(ctx, t);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory checking a contour of %zu panels",
                           n);
  }
  t->hi = t->lo + cap;
  t->left = t->lo + 2 * cap;
  t->by0 = t->bx0 + cap;
  t->bx1 = t->bx0 + 2 * cap;
  t->by1 = t->bx0 + 3 * cap;
  t->lo[0] = 0;
  t->hi[0] = n;
  size_t count = 1;
  for (size_t k = 0; k < count; ++k) {
    size_t lo = t->lo[k], hi = t->hi[k];
    t->left[k] = 0;
    if (hi - lo > VX_SEG_LEAF && count + 2 <= cap) {
      size_t mid = lo + (hi - lo) / 2;
      t->left[k] = count;
      t->lo[count] = lo;
      t->hi[count] = mid;
      t->lo[count + 1] = mid;
      t->hi[count + 1] = hi;
      count += 2;
    }
  }
  t->nnode = count;
  for (size_t k = count; k-- > 0;) {
    if (!t->left[k]) {
      double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
      for (size_t i = t->lo[k]; i < t->hi[k]; ++i) {
        size_t j = (i + 1) % n;
        x0 = fmin(x0, fmin(c->x[i], c->x[j]));
        x1 = fmax(x1, fmax(c->x[i], c->x[j]));
        y0 = fmin(y0, fmin(c->y[i], c->y[j]));
        y1 = fmax(y1, fmax(c->y[i], c->y[j]));
      }
      t->bx0[k] = x0;
      t->by0[k] = y0;
      t->bx1[k] = x1;
      t->by1[k] = y1;
    } else {
      size_t a = t->left[k], b = a + 1;
      t->bx0[k] = fmin(t->bx0[a], t->bx0[b]);
      t->by0[k] = fmin(t->by0[a], t->by0[b]);
      t->bx1[k] = fmax(t->bx1[a], t->bx1[b]);
      t->by1[k] = fmax(t->by1[a], t->by1[b]);
    }
  }
  return PX_STATUS_OK;
}

/* The smallest panel j >= jmin of contour c (tree t) other than `skip` whose
 * closed segment meets the segment (x1, y1) -> (x2, y2): its index, or
 * (size_t)-1 for none; (size_t)-2 when *budget (box and segment tests left)
 * runs out first. Boxes are compared as segments_intersect does (touching
 * counts), so no crossing it would find is pruned. */
static size_t seg_tree_first(const struct px_vortex_contour *c, const struct seg_tree *t, double x1,
                             double y1, double x2, double y2, size_t jmin, size_t skip,
                             double *budget) {
  const double qx0 = fmin(x1, x2), qx1 = fmax(x1, x2), qy0 = fmin(y1, y2), qy1 = fmax(y1, y2);
  size_t stack[160], top = 0;
  if (t->nnode == 0) return (size_t)-1;
  stack[top++] = 0;
  while (top) {
    size_t k = stack[--top];
    *budget -= 1.0;
    if (*budget < 0.0) return (size_t)-2;
    if (t->hi[k] <= jmin || t->bx1[k] < qx0 || qx1 < t->bx0[k] || t->by1[k] < qy0 ||
        qy1 < t->by0[k])
      continue;
    if (t->left[k]) {
      stack[top++] = t->left[k] + 1; /* right after left: the smallest j first */
      stack[top++] = t->left[k];
      continue;
    }
    for (size_t j = t->lo[k] > jmin ? t->lo[k] : jmin; j < t->hi[k]; ++j) {
      if (j == skip) continue;
      *budget -= 1.0;
      size_t j1 = (j + 1) % c->n;
      if (segments_intersect(x1, y1, x2, y2, c->x[j], c->y[j], c->x[j1], c->y[j1])) return j;
    }
    if (*budget < 0.0) return (size_t)-2;
  }
  return (size_t)-1;
}

/* "panel 12 (line 14 -> line 15)" or "panel 12 ((x, y) -> (x, y))" */
static void describe_panel(const struct px_vortex_contour *c, size_t k, char *buf, size_t size) {
  size_t j = (k + 1) % c->n;
  if (c->line)
    snprintf(buf, size, "the segment from line %d to line %d", c->line[k], c->line[j]);
  else
    snprintf(buf, size, "panel %zu ((%g, %g) -> (%g, %g))", k, c->x[k], c->y[k], c->x[j], c->y[j]);
}

static void reverse_contour(struct px_vortex_contour *c) {
  /* keep vertex 0 first: reverse vertices 1..n-1 */
  for (size_t i = 1, j = c->n - 1; i < j; ++i, --j) {
    double t = c->x[i];
    c->x[i] = c->x[j];
    c->x[j] = t;
    t = c->y[i];
    c->y[i] = c->y[j];
    c->y[j] = t;
    if (c->line) {
      int l = c->line[i];
      c->line[i] = c->line[j];
      c->line[j] = l;
    }
  }
}

enum px_status px_vortex_profile_check(struct px_context *ctx, struct px_vortex_contour *c,
                                       int *reversed) {
  *reversed = 0;
  const char *src = c->source[0] ? c->source : "profile";
  if (c->n < 3)
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: a contour needs at least 3 points (got %zu)",
                           src, c->n);
  for (size_t k = 0; k < c->n; ++k) {
    if (!isfinite(c->x[k]) || !isfinite(c->y[k])) {
      if (c->line)
        return px_context_fail(ctx, PX_STATUS_CONFIG, "%s:%d: coordinate is not finite", src,
                               c->line[k]);
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "%s: vertex %zu has a non-finite coordinate (%g, %g)", src, k, c->x[k],
                             c->y[k]);
    }
  }
  double size = 0.0;
  for (size_t k = 1; k < c->n; ++k) size = fmax(size, hypot(c->x[k] - c->x[0], c->y[k] - c->y[0]));
  for (size_t k = 0; k < c->n; ++k) {
    size_t j = (k + 1) % c->n;
    if (hypot(c->x[j] - c->x[k], c->y[j] - c->y[k]) <= 1e-12 * size) {
      if (c->line)
        return px_context_fail(ctx, PX_STATUS_CONFIG,
                               "%s:%d: point repeats the point of line %d (zero-length segment)",
                               src, c->line[j], c->line[k]);
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "%s: vertices %zu and %zu coincide (zero-length panel)", src, k, j);
    }
  }
  /* self-intersection: folds of adjacent panels (a panel running straight
   * back along the previous one), then every pair of non-adjacent panels
   * whose boxes overlap (seg_tree) */
  size_t n = c->n;
  for (size_t k = 0; k < n; ++k) {
    size_t k1 = (k + 1) % n, k2 = (k + 2) % n;
    double ax = c->x[k1] - c->x[k], ay = c->y[k1] - c->y[k];
    double bx = c->x[k2] - c->x[k1], by = c->y[k2] - c->y[k1];
    double cr = ax * by - ay * bx, dt = ax * bx + ay * by;
    if (dt < 0.0 && fabs(cr) <= 1e-12 * hypot(ax, ay) * hypot(bx, by)) {
      char d1[160];
      describe_panel(c, k, d1, sizeof d1);
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "%s: the contour folds back on itself at %s (self-intersection)", src,
                             d1);
    }
  }
  struct seg_tree t;
  PX_TRY(seg_tree_build(ctx, c, &t));
  double budget = PX_VORTEX_CHECK_BUDGET(n);
  size_t hit = (size_t)-1, k = 0;
  for (k = 0; k < n; ++k) {
    size_t k1 = (k + 1) % n;
    /* j > k + 1: not adjacent; panel n - 1 is adjacent to panel 0 through
       the closure */
    hit = seg_tree_first(c, &t, c->x[k], c->y[k], c->x[k1], c->y[k1], k + 2,
                         k == 0 ? n - 1 : (size_t)-1, &budget);
    if (hit != (size_t)-1) break;
  }
  seg_tree_free(ctx, &t);
  if (hit == (size_t)-2)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: the self-intersection check of this contour of %zu panels gave up "
                           "after %.3g tests at panel %zu: too many of its panels lie close "
                           "together (a smooth contour needs 30-45 tests per panel)",
                           src, n, PX_VORTEX_CHECK_BUDGET(n), k);
  if (hit != (size_t)-1) {
    char d1[160], d2[160];
    describe_panel(c, k, d1, sizeof d1);
    describe_panel(c, hit, d2, sizeof d2);
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: self-intersecting contour: %s crosses %s",
                           src, d1, d2);
  }
  double area = px_vortex_profile_area(c);
  if (!(fabs(area) > 1e-12 * size * size))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: the contour encloses no area", src);
  if (area < 0.0) {
    reverse_contour(c);
    *reversed = 1;
  }
  return PX_STATUS_OK;
}

enum px_status px_vortex_profile_check_pair(struct px_context *ctx,
                                            const struct px_vortex_contour *a,
                                            const struct px_vortex_contour *b) {
  struct seg_tree t;
  PX_TRY(seg_tree_build(ctx, b, &t));
  double budget = PX_VORTEX_CHECK_BUDGET(a->n + b->n);
  size_t hit = (size_t)-1, k = 0;
  for (k = 0; k < a->n; ++k) {
    size_t k1 = (k + 1) % a->n;
    hit = seg_tree_first(b, &t, a->x[k], a->y[k], a->x[k1], a->y[k1], 0, (size_t)-1, &budget);
    if (hit != (size_t)-1) break;
  }
  seg_tree_free(ctx, &t);
  if (hit == (size_t)-2)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "bodies %s and %s: the overlap check gave up after %.3g tests at "
                           "panel %zu of the first: too many of their panels lie close together",
                           a->source, b->source, PX_VORTEX_CHECK_BUDGET(a->n + b->n), k);
  if (hit != (size_t)-1)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "bodies %s and %s overlap: panel %zu of the first crosses panel "
                           "%zu of the second",
                           a->source, b->source, k, hit);
  if (px_vortex_profile_contains(b, a->x[0], a->y[0]) ||
      px_vortex_profile_contains(a, b->x[0], b->y[0]))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "bodies %s and %s overlap: one lies inside the other", a->source,
                           b->source);
  return PX_STATUS_OK;
}
