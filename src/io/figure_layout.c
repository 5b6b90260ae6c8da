/* Snapshot pictures: the layout (frame, ticks, colour bar, labels) from the
 * figure size, its view and its layers; see figure.c. */
#include "partix/figure.h"

#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io/draw.h"
#include "io/figure_impl.h"

/* ---- Layout -------------------------------------------------------------- */

static void px_fig_grow(double b[4], double x0, double x1, double y0, double y1) {
  if (!(isfinite(x0) && isfinite(x1) && isfinite(y0) && isfinite(y1))) return;
  if (x0 < b[0]) b[0] = x0;
  if (x1 > b[1]) b[1] = x1;
  if (y0 < b[2]) b[2] = y0;
  if (y1 > b[3]) b[3] = y1;
}

/* World bounds of all layers; returns 0 if there is nothing finite. */
static int px_fig_bounds(const struct px_figure *fig, double b[4]) {
  size_t k, i;
  b[0] = b[2] = INFINITY;
  b[1] = b[3] = -INFINITY;
  for (k = 0; k < fig->nlayers; ++k) {
    const struct px_fig_layer *l = &fig->layers[k];
    if (l->kind == PX_FIG_RASTER) {
      px_fig_grow(b, l->rect[0], l->rect[1], l->rect[2], l->rect[3]);
      continue;
    }
    for (i = 0; i < l->n; ++i) {
      double x = px_fig_get(l->dtype, l->x, i), y = px_fig_get(l->dtype, l->y, i), r = 0.0;
      if (l->kind == PX_FIG_DISCS) r = l->radius ? px_fig_get(l->dtype, l->radius, i) : l->size;
      if (!isfinite(r) || r < 0.0) r = 0.0;
      px_fig_grow(b, x - r, x + r, y - r, y + r);
    }
  }
  return b[0] <= b[1] && b[2] <= b[3];
}

/* Automatic or given colour range; sets has_scale. */
static void px_fig_range(const struct px_figure *fig, struct px_fig_layout *L) {
  double lo = INFINITY, hi = -INFINITY;
  size_t k, i;
  L->has_scale = 0;
  for (k = 0; k < fig->nlayers; ++k) {
    const struct px_fig_layer *l = &fig->layers[k];
    size_t nv = l->n;
    if (!l->values) continue;
    L->has_scale = 1;
    if (l->kind == PX_FIG_LINE_VALUES) nv = l->mode ? l->n : (l->n ? l->n - 1 : 0);
    for (i = 0; i < nv; ++i) {
      double v = px_fig_get(l->dtype, l->values, i);
      if (!isfinite(v)) continue;
      if (v < lo) lo = v;
      if (v > hi) hi = v;
    }
  }
  if (isfinite(fig->vmin) && isfinite(fig->vmax) && fig->vmax > fig->vmin) {
    L->vmin = fig->vmin;
    L->vmax = fig->vmax;
    return;
  }
  if (!(lo <= hi)) lo = 0.0, hi = 1.0;
  if (px_colormap_is_diverging(fig->map)) {
    double a = fmax(fabs(lo), fabs(hi));
    if (!(a > 0.0)) a = 1.0;
    L->vmin = -a;
    L->vmax = a;
  } else {
    if (hi == lo) {
      double d = lo != 0.0 ? 0.5 * fabs(lo) : 0.5;
      lo -= d;
      hi += d;
    }
    L->vmin = lo;
    L->vmax = hi;
  }
}

void px_fig_time_label(const struct px_figure *fig, char *buf, size_t size) {
  double t = fig->time == 0.0 ? 0.0 : fig->time;
  char num[64];
  snprintf(num, sizeof num, "%.6g", t);
  if (fig->time_unit[0])
    snprintf(buf, size, "t = %s %s", num, fig->time_unit);
  else
    snprintf(buf, size, "t = %s", num);
}

void px_fig_cbar_labels(const struct px_fig_layout *L, char lab[3][64]) {
  px_draw_format_value(L->vmin, 3, lab[0], sizeof lab[0]);
  px_draw_format_value(0.5 * (L->vmin + L->vmax), 3, lab[1], sizeof lab[1]);
  px_draw_format_value(L->vmax, 3, lab[2], sizeof lab[2]);
}

void px_fig_field_label(const struct px_figure *fig, char *buf, size_t size) {
  if (fig->field[0] && fig->unit[0])
    snprintf(buf, size, "%s [%s]", fig->field, fig->unit);
  else
    snprintf(buf, size, "%s", fig->field);
}

double px_fig_max_label_width(cairo_t *cr, const double *t, int n, double step,
                              double *maxabs_out) {
  double w = 0.0, maxabs = 0.0;
  char buf[64];
  int i;
  for (i = 0; i < n; ++i) maxabs = fmax(maxabs, fabs(t[i]));
  for (i = 0; i < n; ++i) {
    px_draw_format_tick(t[i], step, maxabs, buf, sizeof buf);
    w = fmax(w, px_draw_text_width(cr, buf));
  }
  if (maxabs_out) *maxabs_out = maxabs;
  return w;
}

enum px_status px_fig_layout(struct px_figure *fig, cairo_t *cr) {
  struct px_fig_layout *L = &fig->L;
  double W = fig->width, H = fig->height, fs, pad, top, bottom, left, right, v[4];
  int pass;

  memset(L, 0, sizeof *L);
  fs = fmax(10.0, fmin(W, H) / 40.0);
  L->fs = fs;
  pad = 0.8 * fs;
  px_fig_range(fig, L);
  if (fig->view_set) {
    memcpy(v, fig->view, sizeof v);
    if (!(v[1] > v[0]) || !(v[3] > v[2]) || !isfinite(v[1] - v[0]) || !isfinite(v[3] - v[2]))
      return px_context_fail(fig->ctx, PX_STATUS_INVALID,
                             "figure view [%g, %g] x [%g, %g] is empty or not finite", v[0], v[1],
                             v[2], v[3]);
  } else {
    double m;
    if (!px_fig_bounds(fig, v)) v[0] = 0.0, v[1] = 1.0, v[2] = 0.0, v[3] = 1.0;
    if (v[1] - v[0] == 0.0 && v[3] - v[2] == 0.0) {
      double d = fmax(fabs(v[0]), fabs(v[2])) * 0.5;
      if (!(d > 0.0)) d = 0.5;
      v[0] -= d, v[1] += d, v[2] -= d, v[3] += d;
    }
    m = fig->margin * fmax(v[1] - v[0], v[3] - v[2]);
    v[0] -= m, v[1] += m, v[2] -= m, v[3] += m;
  }

  px_draw_font(cr, fs, 0);
  top = fig->title[0] ? pad + 1.5 * fs : pad;
  bottom = 0.35 * fs + 0.4 * fs + fs + (fig->xlabel[0] ? 1.6 * fs : 0.0) + pad;
  right = 1.5 * fs;
  if (L->has_scale) {
    char lab[3][64], fl[2 * PX_FIG_TEXT];
    double w = 0.0;
    int i;
    px_fig_cbar_labels(L, lab);
    for (i = 0; i < 3; ++i) w = fmax(w, px_draw_text_width(cr, lab[i]));
    px_fig_field_label(fig, fl, sizeof fl);
    right =
        1.2 * fs + 1.0 * fs + 0.3 * fs + 0.3 * fs + w + (fl[0] ? 0.5 * fs + 1.2 * fs : 0.0) + pad;
  }
  left = pad + (fig->ylabel[0] ? 1.6 * fs : 0.0) + 3.0 * fs + 0.35 * fs + 0.3 * fs;

  for (pass = 0; pass < 2; ++pass) {
    double pw, ph, vw = v[1] - v[0], vh = v[3] - v[2], cx, cy, wlab, maxabs;
    L->frame[0] = floor(left);
    L->frame[1] = floor(top);
    L->frame[2] = floor(W - right);
    L->frame[3] = floor(H - bottom);
    pw = L->frame[2] - L->frame[0];
    ph = L->frame[3] - L->frame[1];
    if (pw < 16.0 || ph < 16.0)
      return px_context_fail(fig->ctx, PX_STATUS_INVALID,
                             "figure of %d x %d pixels is too small for its labels and colour bar",
                             fig->width, fig->height);
    /* Equal aspect: widen the view along one axis to the frame's shape. */
    if (vw / vh < pw / ph)
      vw = vh * pw / ph;
    else
      vh = vw * ph / pw;
    cx = 0.5 * (v[0] + v[1]);
    cy = 0.5 * (v[2] + v[3]);
    L->world[0] = cx - 0.5 * vw, L->world[1] = cx + 0.5 * vw;
    L->world[2] = cy - 0.5 * vh, L->world[3] = cy + 0.5 * vh;
    L->scale = pw / vw;
    L->nxt = px_draw_nice_ticks(L->world[0], L->world[1], (int)fmax(2.0, pw / (6.0 * fs)), L->xt,
                                &L->xstep);
    L->nyt = px_draw_nice_ticks(L->world[2], L->world[3], (int)fmax(2.0, ph / (4.0 * fs)), L->yt,
                                &L->ystep);
    wlab = px_fig_max_label_width(cr, L->yt, L->nyt, L->ystep, &maxabs);
    left = pad + (fig->ylabel[0] ? 1.6 * fs : 0.0) + wlab + 0.35 * fs + 0.3 * fs;
  }
  if (L->has_scale) {
    L->cbar[0] = L->frame[2] + floor(1.2 * fs);
    L->cbar[1] = L->frame[1];
    L->cbar[2] = L->cbar[0] + floor(1.0 * fs);
    L->cbar[3] = L->frame[3];
  }
  return PX_STATUS_OK;
}

/* Layout with a scratch cairo context (for queries before drawing). */
static enum px_status px_fig_layout_scratch(struct px_figure *fig) {
  cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 1, 1);
  cairo_t *cr = cairo_create(s);
  enum px_status st = px_draw_check(fig->ctx, cr, "measuring text");
  if (st == PX_STATUS_OK) st = px_fig_layout(fig, cr);
  cairo_destroy(cr);
  cairo_surface_destroy(s);
  return st;
}

enum px_status px_figure_world_to_pixel(struct px_figure *fig, double x, double y, double *px,
                                        double *py) {
  if (!fig || !px || !py) return PX_STATUS_INVALID;
  PX_TRY(px_fig_layout_scratch(fig));
  px_fig_to_pixel(&fig->L, x, y, px, py);
  return PX_STATUS_OK;
}

enum px_status px_figure_layout_rects(struct px_figure *fig, double frame[4], double colorbar[4]) {
  if (!fig) return PX_STATUS_INVALID;
  PX_TRY(px_fig_layout_scratch(fig));
  memcpy(frame, fig->L.frame, sizeof fig->L.frame);
  memcpy(colorbar, fig->L.cbar, sizeof fig->L.cbar);
  return PX_STATUS_OK;
}

enum px_status px_figure_layout_range(struct px_figure *fig, double *vmin, double *vmax) {
  if (!fig) return PX_STATUS_INVALID;
  PX_TRY(px_fig_layout_scratch(fig));
  *vmin = fig->L.vmin;
  *vmax = fig->L.vmax;
  return PX_STATUS_OK;
}
