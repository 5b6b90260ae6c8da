/* Three orthographic views of a closed mesh (mesh_view.h): triangles facing
 * the eye drawn far to near (painter's algorithm; enough for the convex and
 * mildly concave parts of a sectional study), each shaded by the angle
 * between its normal and the view; a grey part flat, a coloured one with
 * its corners' colours blended over the triangle (Gouraud). */
#include "io/mesh_view.h"

#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/draw.h"
#include "partix/memory.h"

#define W 1800
#define H 640
#define PANEL 520 /* [px] square of each view */
#define TOP 56    /* [px] title band */

struct camera {
  double d[3], r[3], u[3]; /* into the scene, right, up (unit) */
  double cx, cy;           /* screen centre of the panel [px] */
  double scale;            /* [px per mesh unit] */
  double c[3];             /* the part's centre */
};

static double dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double o[3]) {
  o[0] = a[1] * b[2] - a[2] * b[1];
  o[1] = a[2] * b[0] - a[0] * b[2];
  o[2] = a[0] * b[1] - a[1] * b[0];
}

static void unit3(double a[3]) {
  const double n = sqrt(dot3(a, a));
  if (n > 0)
    for (int k = 0; k < 3; ++k) a[k] /= n;
}

/* right = d x up, up = right x d: looking down -z with y up puts x right. */
static void camera_axes(struct camera *c, const double dir[3], const double up[3]) {
  memcpy(c->d, dir, sizeof c->d);
  unit3(c->d);
  cross3(c->d, up, c->r);
  if (dot3(c->r, c->r) < 1e-12) { /* up along the view: any perpendicular */
    const double alt[3] = {fabs(c->d[0]) < 0.9 ? 1 : 0, fabs(c->d[0]) < 0.9 ? 0 : 1, 0};
    cross3(c->d, alt, c->r);
  }
  unit3(c->r);
  cross3(c->r, c->d, c->u);
}

static void project(const struct camera *c, const double p[3], double *sx, double *sy) {
  const double q[3] = {p[0] - c->c[0], p[1] - c->c[1], p[2] - c->c[2]};
  *sx = c->cx + c->scale * dot3(q, c->r);
  *sy = c->cy - c->scale * dot3(q, c->u);
}

struct face {
  double depth;
  size_t t;
};

static int face_far_first(const void *a, const void *b) {
  const struct face *x = a, *y = b;
  return x->depth < y->depth ? 1 : x->depth > y->depth ? -1 : (x->t > y->t) - (x->t < y->t);
}

static enum px_status draw_view(struct px_context *ctx, cairo_t *cr, const struct px_mesh_view *v,
                                const struct camera *c, double lo, double hi) {
  const struct px_geo_mesh *m = v->mesh;
  struct face *f = px_mem_alloc(ctx, "mesh view", (m->nt + 1) * sizeof *f);
  size_t nf = 0;
  if (!f) return PX_STATUS_NOMEM;
  for (size_t t = 0; t < m->nt; ++t) {
    const double *a = m->xyz + 3 * m->tri[3 * t], *b = m->xyz + 3 * m->tri[3 * t + 1],
                 *e = m->xyz + 3 * m->tri[3 * t + 2];
    const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                 ae[3] = {e[0] - a[0], e[1] - a[1], e[2] - a[2]};
    double n[3];
    cross3(ab, ae, n);
    if (dot3(n, c->d) >= 0) continue; /* faces away from the eye (closed mesh) */
    f[nf].depth = (dot3(a, c->d) + dot3(b, c->d) + dot3(e, c->d)) / 3;
    f[nf++].t = t;
  }
  qsort(f, nf, sizeof *f, face_far_first);
  /* a coloured part: one mesh pattern, a Gouraud patch per triangle (its
   * corners' colours), in the same far-to-near order */
  cairo_pattern_t *pat = v->value ? cairo_pattern_create_mesh() : NULL;
  cairo_set_line_width(cr, 0.6);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  for (size_t i = 0; i < nf; ++i) {
    const size_t t = f[i].t;
    const double *p[3] = {m->xyz + 3 * m->tri[3 * t], m->xyz + 3 * m->tri[3 * t + 1],
                          m->xyz + 3 * m->tri[3 * t + 2]};
    const double ab[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]},
                 ae[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    double n[3], rgb[3], sx[3], sy[3];
    cross3(ab, ae, n);
    unit3(n);
    /* Lambert with the light at the eye, plus an ambient third */
    const double shade = 0.35 + 0.65 * fabs(dot3(n, c->d));
    for (int k = 0; k < 3; ++k) project(c, p[k], &sx[k], &sy[k]);
    if (pat) {
      cairo_mesh_pattern_begin_patch(pat);
      cairo_mesh_pattern_move_to(pat, sx[0], sy[0]);
      cairo_mesh_pattern_line_to(pat, sx[1], sy[1]);
      cairo_mesh_pattern_line_to(pat, sx[2], sy[2]);
      for (unsigned k = 0; k < 3; ++k) {
        const double val = v->value[m->tri[3 * t + k]];
        px_colormap_eval(v->map, hi > lo ? (val - lo) / (hi - lo) : 0.5, rgb);
        cairo_mesh_pattern_set_corner_color_rgb(pat, k, shade * rgb[0], shade * rgb[1],
                                                shade * rgb[2]);
      }
      cairo_mesh_pattern_end_patch(pat);
      continue;
    }
    rgb[0] = rgb[1] = rgb[2] = 0.78; /* a grey part */
    cairo_move_to(cr, sx[0], sy[0]);
    cairo_line_to(cr, sx[1], sy[1]);
    cairo_line_to(cr, sx[2], sy[2]);
    cairo_close_path(cr);
    cairo_set_source_rgb(cr, shade * rgb[0], shade * rgb[1], shade * rgb[2]);
    cairo_fill_preserve(cr); /* the same colour around: no hairline gaps */
    cairo_stroke(cr);
  }
  if (pat) {
    cairo_set_source(cr, pat);
    cairo_paint(cr);
    cairo_pattern_destroy(pat);
  }
  px_mem_free(ctx, f);
  cairo_set_source_rgb(cr, 0.75, 0.05, 0.05);
  cairo_set_line_width(cr, 2.0);
  for (size_t i = 0; i < v->npoly; ++i) {
    double sx, sy;
    for (size_t k = 0; k < v->poly_n[i]; ++k) {
      project(c, v->poly_xyz[i] + 3 * k, &sx, &sy);
      if (k == 0)
        cairo_move_to(cr, sx, sy);
      else
        cairo_line_to(cr, sx, sy);
    }
    cairo_close_path(cr);
    cairo_stroke(cr);
  }
  return PX_STATUS_OK;
}

static void draw_colorbar(cairo_t *cr, const struct px_mesh_view *v, double lo, double hi) {
  const double x0 = 3 * PANEL + 90, x1 = x0 + 24, y0 = TOP + 60, y1 = H - 80;
  for (int row = 0; row < (int)(y1 - y0); ++row) {
    double rgb[3];
    px_colormap_eval(v->map, (row + 0.5) / (y1 - y0), rgb);
    cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
    cairo_rectangle(cr, x0, y1 - row - 1, x1 - x0, 1);
    cairo_fill(cr);
  }
  cairo_set_source_rgb(cr, 0.25, 0.25, 0.25);
  cairo_set_line_width(cr, 1);
  cairo_rectangle(cr, x0 + 0.5, y0 + 0.5, x1 - x0 - 1, y1 - y0 - 1);
  cairo_stroke(cr);
  px_draw_font(cr, 16, 0);
  double wmax = 0;
  for (int i = 0; i < 3; ++i) {
    char lab[64];
    const double val = lo + (hi - lo) * i / 2.0, y = y1 - (y1 - y0) * i / 2.0;
    px_draw_format_value(val, 3, lab, sizeof lab);
    cairo_move_to(cr, x1, y);
    cairo_line_to(cr, x1 + 5, y);
    cairo_stroke(cr);
    px_draw_text(cr, x1 + 9, y, lab, 0, i == 0 ? 1 : i == 2 ? 0 : 0.5);
    wmax = fmax(wmax, px_draw_text_width(cr, lab));
  }
  if (v->label) px_draw_text_vertical(cr, x1 + 9 + wmax + 22, 0.5 * (y0 + y1), v->label);
}

/* The part's centre and the scale that fits its largest view in a panel. */
static void fit(const struct px_mesh_view *v, struct camera cam[3]) {
  double lo[3], hi[3], ext = 0;
  px_geo_mesh_measure(v->mesh, NULL, NULL, lo, hi);
  for (int i = 0; i < 3; ++i) {
    double a = HUGE_VAL, b = -HUGE_VAL, c = HUGE_VAL, d = -HUGE_VAL;
    for (int k = 0; k < 3; ++k) cam[i].c[k] = 0.5 * (lo[k] + hi[k]);
    for (size_t j = 0; j < v->mesh->nv; ++j) {
      const double *p = v->mesh->xyz + 3 * j;
      a = fmin(a, dot3(p, cam[i].r));
      b = fmax(b, dot3(p, cam[i].r));
      c = fmin(c, dot3(p, cam[i].u));
      d = fmax(d, dot3(p, cam[i].u));
    }
    ext = fmax(ext, fmax(b - a, d - c));
  }
  for (int i = 0; i < 3; ++i) {
    cam[i].scale = ext > 0 ? 0.86 * PANEL / ext : 1;
    cam[i].cx = 40 + PANEL * (i + 0.5);
    cam[i].cy = TOP + 0.5 * PANEL;
  }
}

enum px_status px_mesh_view_png(struct px_context *ctx, const struct px_mesh_view *v,
                                const char *path) {
  struct camera cam[3];
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (size_t i = 0; v->value && i < v->mesh->nv; ++i)
    if (isfinite(v->value[i])) {
      lo = fmin(lo, v->value[i]);
      hi = fmax(hi, v->value[i]);
    }
  if (!(lo <= hi)) lo = hi = 0;
  for (int i = 0; i < 3; ++i) camera_axes(&cam[i], v->dir[i], v->up[i]);
  fit(v, cam);
  cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
  cairo_t *cr = cairo_create(s);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  enum px_status st = PX_STATUS_OK;
  for (int i = 0; i < 3 && st == PX_STATUS_OK; ++i) {
    st = draw_view(ctx, cr, v, &cam[i], lo, hi);
    if (v->view_name[i]) {
      px_draw_font(cr, 17, 0);
      cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
      px_draw_text(cr, cam[i].cx, TOP + PANEL + 30, v->view_name[i], 0.5, 1);
    }
  }
  if (st == PX_STATUS_OK && v->value) draw_colorbar(cr, v, lo, hi);
  if (st == PX_STATUS_OK && v->title) {
    px_draw_font(cr, 22, 1);
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    px_draw_text(cr, W / 2.0, 38, v->title, 0.5, 1);
  }
  if (st == PX_STATUS_OK) st = px_draw_check(ctx, cr, path);
  cairo_destroy(cr);
  if (st == PX_STATUS_OK) st = px_draw_write_png(ctx, s, path);
  cairo_surface_destroy(s);
  return st;
}
