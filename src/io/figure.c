/* Snapshot pictures: world-coordinate layers drawn with equal aspect into a
 * frame with ticks, a colour bar, a title and a time label.
 *
 * Layout (pixels): [title] / [frame | colour bar + ticks + label] /
 * [x tick labels] / [x label], with the y tick labels and y label left of the
 * frame. Sizes scale with the font size fs = min(width, height) / 40. */
#include "partix/figure.h"

#include <cairo.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "io/draw.h"
#include "io/figure_impl.h"
#include "partix/memory.h"

#define PX_FIG_TEXT 256
#define PX_FIG_BINS 256            /* colour levels for particles */
#define PX_FIG_BIN_NAN PX_FIG_BINS /* bin of NaN values */
#define PX_FIG_BIN_SOLID (PX_FIG_BINS + 1)
#define PX_FIG_NBINS (PX_FIG_BINS + 2)
#define PX_FIG_BIN_CULLED 0xffffu
#define PX_FIG_BATCH 4096 /* discs per cairo path */

enum px_fig_kind {
  PX_FIG_DISCS,
  PX_FIG_POINTS,
  PX_FIG_LINE,
  PX_FIG_LINE_VALUES,
  PX_FIG_RASTER,
  PX_FIG_MARKER, /* rect[0..1]: the point */
  PX_FIG_ARROW   /* rect[0..3]: tail x, y, head x, y */
};

struct px_fig_layer {
  enum px_fig_kind kind;
  enum px_dtype dtype;
  size_t n;           /* points (raster: cells) */
  size_t nx, ny;      /* raster cells */
  const void *x, *y;  /* borrowed */
  const void *radius; /* borrowed, may be NULL (discs: world units) */
  const void *values; /* borrowed, may be NULL */
  double size;        /* discs: r0 (world units); points: diameter (pixels) */
  double rect[4];     /* raster: xmin, xmax, ymin, ymax (world units) */
  int mode;           /* line: enum px_figure_line; line values: closed */
  double color[3], fill[3];
  double width;            /* line width, pixels */
  char label[PX_FIG_TEXT]; /* marker, arrow: text beside it ("" none) */
};

struct px_fig_layout {
  double fs;       /* font size, pixels */
  double frame[4]; /* x0, y0, x1, y1 (pixels, integers) */
  double world[4]; /* xmin, xmax, ymin, ymax shown (world units) */
  double scale;    /* pixels per world unit */
  int has_scale;   /* some layer has values: colour bar */
  double vmin, vmax;
  double cbar[4]; /* x0, y0, x1, y1 (pixels) */
  double xt[PX_DRAW_MAX_TICKS], yt[PX_DRAW_MAX_TICKS], xstep, ystep;
  int nxt, nyt;
};

struct px_figure {
  struct px_context *ctx; /* borrowed */
  int width, height;
  struct px_fig_layer *layers; /* owned */
  size_t nlayers, cap;
  int view_set;
  double view[4];
  double margin;
  enum px_colormap map;
  double vmin, vmax; /* NaN: automatic */
  char field[PX_FIG_TEXT], unit[64], title[PX_FIG_TEXT];
  char xlabel[PX_FIG_TEXT], ylabel[PX_FIG_TEXT], time_unit[32];
  double time; /* NaN: no time label */
  double bg[3], color[3], fill[3], line_width;
  struct px_fig_layout L;
};

static const double px_fig_ink[3] = {0.1, 0.1, 0.1};

static void px_fig_copy(char *dst, size_t size, const char *src) {
  if (!src) src = "";
  snprintf(dst, size, "%s", src);
}

static double px_fig_get(enum px_dtype t, const void *p, size_t i) {
  return t == PX_DTYPE_F32 ? (double)((const float *)p)[i] : ((const double *)p)[i];
}

enum px_status px_figure_create(struct px_context *ctx, int width, int height,
                                struct px_figure **out) {
  struct px_figure *fig;
  if (!ctx || !out) return PX_STATUS_INVALID;
  *out = NULL;
  if (width < 16 || height < 16 || width > 16384 || height > 16384)
    return px_context_fail(ctx, PX_STATUS_INVALID,
                           "figure size %d x %d pixels (expected 16 to 16384 each)", width, height);
  fig = px_mem_calloc(ctx, "figure", 1, sizeof *fig);
  if (!fig) return PX_STATUS_NOMEM;
  fig->ctx = ctx;
  fig->width = width;
  fig->height = height;
  fig->margin = 0.05;
  fig->map = PX_COLORMAP_VIRIDIS;
  fig->vmin = fig->vmax = NAN;
  fig->time = NAN;
  fig->bg[0] = fig->bg[1] = fig->bg[2] = 1.0;
  fig->color[0] = fig->color[1] = fig->color[2] = 0.15;
  fig->fill[0] = fig->fill[1] = fig->fill[2] = 0.72;
  fig->line_width = 1.5;
  px_fig_copy(fig->xlabel, sizeof fig->xlabel, "x");
  px_fig_copy(fig->ylabel, sizeof fig->ylabel, "y");
  *out = fig;
  return PX_STATUS_OK;
}

void px_figure_free(struct px_figure *fig) {
  if (!fig) return;
  px_mem_free(fig->ctx, fig->layers);
  px_mem_free(fig->ctx, fig);
}

void px_figure_reset(struct px_figure *fig) {
  if (fig) fig->nlayers = 0;
}

void px_figure_set_view(struct px_figure *fig, double xmin, double xmax, double ymin, double ymax) {
  if (!fig) return;
  fig->view_set = 1;
  fig->view[0] = xmin, fig->view[1] = xmax, fig->view[2] = ymin, fig->view[3] = ymax;
}

void px_figure_fit_view(struct px_figure *fig, double margin) {
  if (!fig) return;
  fig->view_set = 0;
  fig->margin = margin >= 0.0 && isfinite(margin) ? margin : 0.05;
}

void px_figure_set_colormap(struct px_figure *fig, enum px_colormap map) {
  if (fig) fig->map = map;
}

void px_figure_set_range(struct px_figure *fig, double vmin, double vmax) {
  if (!fig) return;
  fig->vmin = vmin;
  fig->vmax = vmax;
}

void px_figure_set_field(struct px_figure *fig, const char *name, const char *unit) {
  if (!fig) return;
  px_fig_copy(fig->field, sizeof fig->field, name);
  px_fig_copy(fig->unit, sizeof fig->unit, unit);
}

void px_figure_set_title(struct px_figure *fig, const char *title) {
  if (fig) px_fig_copy(fig->title, sizeof fig->title, title);
}

void px_figure_set_time(struct px_figure *fig, double t, const char *unit) {
  if (!fig) return;
  fig->time = t;
  px_fig_copy(fig->time_unit, sizeof fig->time_unit, unit);
}

void px_figure_set_axis_labels(struct px_figure *fig, const char *xlabel, const char *ylabel) {
  if (!fig) return;
  px_fig_copy(fig->xlabel, sizeof fig->xlabel, xlabel);
  px_fig_copy(fig->ylabel, sizeof fig->ylabel, ylabel);
}

static double px_fig_clamp01(double c) { return c < 0.0 ? 0.0 : c > 1.0 ? 1.0 : c; }

void px_figure_set_background(struct px_figure *fig, double r, double g, double b) {
  if (!fig) return;
  fig->bg[0] = px_fig_clamp01(r), fig->bg[1] = px_fig_clamp01(g), fig->bg[2] = px_fig_clamp01(b);
}

void px_figure_set_color(struct px_figure *fig, double r, double g, double b) {
  if (!fig) return;
  fig->color[0] = px_fig_clamp01(r), fig->color[1] = px_fig_clamp01(g);
  fig->color[2] = px_fig_clamp01(b);
}

void px_figure_set_fill(struct px_figure *fig, double r, double g, double b) {
  if (!fig) return;
  fig->fill[0] = px_fig_clamp01(r), fig->fill[1] = px_fig_clamp01(g);
  fig->fill[2] = px_fig_clamp01(b);
}

void px_figure_set_line_width(struct px_figure *fig, double pixels) {
  if (fig && pixels > 0.0 && isfinite(pixels)) fig->line_width = pixels;
}

/* ---- Layers -------------------------------------------------------------- */

static enum px_status px_fig_new_layer(struct px_figure *fig, enum px_fig_kind kind,
                                       enum px_dtype dtype, const char *what,
                                       struct px_fig_layer **out) {
  struct px_fig_layer *l;
  if (dtype != PX_DTYPE_F32 && dtype != PX_DTYPE_F64)
    return px_context_fail(fig->ctx, PX_STATUS_INVALID,
                           "figure %s: data must be f32 or f64, not %s", what,
                           px_dtype_name(dtype));
  if (fig->nlayers == fig->cap) {
    size_t ncap = fig->cap ? 2 * fig->cap : 8;
    void *nl = px_mem_realloc(fig->ctx, "figure", fig->layers, ncap * sizeof *fig->layers);
    if (!nl) return PX_STATUS_NOMEM;
    fig->layers = nl;
    fig->cap = ncap;
  }
  l = &fig->layers[fig->nlayers++];
  memset(l, 0, sizeof *l);
  l->kind = kind;
  l->dtype = dtype;
  memcpy(l->color, fig->color, sizeof l->color);
  memcpy(l->fill, fig->fill, sizeof l->fill);
  l->width = fig->line_width;
  *out = l;
  return PX_STATUS_OK;
}

enum px_status px_figure_add_discs(struct px_figure *fig, enum px_dtype dtype, size_t n,
                                   const void *x, const void *y, const void *radius, double r0,
                                   const void *values) {
  struct px_fig_layer *l = NULL;
  if (!fig) return PX_STATUS_INVALID;
  if (n && (!x || !y))
    return px_context_fail(fig->ctx, PX_STATUS_INVALID, "figure discs: x and y are NULL");
  if (!radius && !(r0 > 0.0 && isfinite(r0)))
    return px_context_fail(fig->ctx, PX_STATUS_INVALID,
                           "figure discs: radius %g (need r0 > 0 or a radius array)", r0);
  PX_TRY(px_fig_new_layer(fig, PX_FIG_DISCS, dtype, "discs", &l));
  l->n = n, l->x = x, l->y = y, l->radius = radius, l->size = r0, l->values = values;
  return PX_STATUS_OK;
}

enum px_status px_figure_add_points(struct px_figure *fig, enum px_dtype dtype, size_t n,
                                    const void *x, const void *y, const void *values,
                                    double diameter) {
  struct px_fig_layer *l = NULL;
  if (!fig) return PX_STATUS_INVALID;
  if (n && (!x || !y))
    return px_context_fail(fig->ctx, PX_STATUS_INVALID, "figure points: x and y are NULL");
  if (!(diameter > 0.0 && diameter < 1000.0))
    return px_context_fail(fig->ctx, PX_STATUS_INVALID,
                           "figure points: diameter %g pixels (expected 0 < d < 1000)", diameter);
  PX_TRY(px_fig_new_layer(fig, PX_FIG_POINTS, dtype, "points", &l));
  l->n = n, l->x = x, l->y = y, l->values = values, l->size = diameter;
  return PX_STATUS_OK;
}

enum px_status px_figure_add_polyline(struct px_figure *fig, enum px_dtype dtype, size_t n,
                                      const void *x, const void *y, enum px_figure_line mode) {
  struct px_fig_layer *l = NULL;
  if (!fig) return PX_STATUS_INVALID;
  if (n && (!x || !y))
    return px_context_fail(fig->ctx, PX_STATUS_INVALID, "figure polyline: x and y are NULL");
  PX_TRY(px_fig_new_layer(fig, PX_FIG_LINE, dtype, "polyline", &l));
  l->n = n, l->x = x, l->y = y, l->mode = (int)mode;
  return PX_STATUS_OK;
}

enum px_status px_figure_add_polyline_values(struct px_figure *fig, enum px_dtype dtype, size_t n,
                                             const void *x, const void *y, int closed,
                                             const void *values) {
  struct px_fig_layer *l = NULL;
  if (!fig) return PX_STATUS_INVALID;
  if (n && (!x || !y || !values))
    return px_context_fail(fig->ctx, PX_STATUS_INVALID,
                           "figure polyline with values: x, y or values is NULL");
  PX_TRY(px_fig_new_layer(fig, PX_FIG_LINE_VALUES, dtype, "polyline with values", &l));
  l->n = n, l->x = x, l->y = y, l->mode = closed != 0, l->values = values;
  return PX_STATUS_OK;
}

enum px_status px_figure_add_raster(struct px_figure *fig, enum px_dtype dtype, size_t nx,
                                    size_t ny, const void *values, double xmin, double xmax,
                                    double ymin, double ymax) {
  struct px_fig_layer *l = NULL;
  if (!fig) return PX_STATUS_INVALID;
  if (!values || nx < 1 || ny < 1 || nx > 32767 || ny > 32767)
    return px_context_fail(fig->ctx, PX_STATUS_INVALID,
                           "figure raster: %zu x %zu cells (expected 1 to 32767 each, values "
                           "not NULL)",
                           nx, ny);
  if (!(xmax > xmin) || !(ymax > ymin) || !isfinite(xmax - xmin) || !isfinite(ymax - ymin))
    return px_context_fail(fig->ctx, PX_STATUS_INVALID,
                           "figure raster: rectangle [%g, %g] x [%g, %g] is empty", xmin, xmax,
                           ymin, ymax);
  PX_TRY(px_fig_new_layer(fig, PX_FIG_RASTER, dtype, "raster", &l));
  l->nx = nx, l->ny = ny, l->n = nx * ny, l->values = values;
  l->rect[0] = xmin, l->rect[1] = xmax, l->rect[2] = ymin, l->rect[3] = ymax;
  return PX_STATUS_OK;
}

static enum px_status px_fig_add_annotation(struct px_figure *fig, enum px_fig_kind kind,
                                            const double pts[4], const char *label) {
  struct px_fig_layer *l;
  if (!fig) return PX_STATUS_INVALID;
  if (!isfinite(pts[0]) || !isfinite(pts[1]) || !isfinite(pts[2]) || !isfinite(pts[3]))
    return px_context_fail(fig->ctx, PX_STATUS_INVALID, "figure %s: point not finite",
                           kind == PX_FIG_MARKER ? "marker" : "arrow");
  PX_TRY(px_fig_new_layer(fig, kind, PX_DTYPE_F64, "annotation", &l));
  memcpy(l->rect, pts, sizeof l->rect);
  px_fig_copy(l->label, sizeof l->label, label ? label : "");
  return PX_STATUS_OK;
}

enum px_status px_figure_add_marker(struct px_figure *fig, double x, double y, const char *label) {
  const double pts[4] = {x, y, x, y};
  return px_fig_add_annotation(fig, PX_FIG_MARKER, pts, label);
}

enum px_status px_figure_add_arrow(struct px_figure *fig, double x0, double y0, double x1,
                                   double y1, const char *label) {
  const double pts[4] = {x0, y0, x1, y1};
  return px_fig_add_annotation(fig, PX_FIG_ARROW, pts, label);
}

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

static void px_fig_time_label(const struct px_figure *fig, char *buf, size_t size) {
  double t = fig->time == 0.0 ? 0.0 : fig->time;
  char num[64];
  snprintf(num, sizeof num, "%.6g", t);
  if (fig->time_unit[0])
    snprintf(buf, size, "t = %s %s", num, fig->time_unit);
  else
    snprintf(buf, size, "t = %s", num);
}

static void px_fig_cbar_labels(const struct px_fig_layout *L, char lab[3][64]) {
  px_draw_format_value(L->vmin, 3, lab[0], sizeof lab[0]);
  px_draw_format_value(0.5 * (L->vmin + L->vmax), 3, lab[1], sizeof lab[1]);
  px_draw_format_value(L->vmax, 3, lab[2], sizeof lab[2]);
}

static void px_fig_field_label(const struct px_figure *fig, char *buf, size_t size) {
  if (fig->field[0] && fig->unit[0])
    snprintf(buf, size, "%s [%s]", fig->field, fig->unit);
  else
    snprintf(buf, size, "%s", fig->field);
}

static double px_fig_max_label_width(cairo_t *cr, const double *t, int n, double step,
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

static enum px_status px_fig_layout(struct px_figure *fig, cairo_t *cr) {
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

static void px_fig_to_pixel(const struct px_fig_layout *L, double x, double y, double *px,
                            double *py) {
  *px = L->frame[0] + (x - L->world[0]) * L->scale;
  *py = L->frame[3] - (y - L->world[2]) * L->scale;
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

/* ---- Drawing ------------------------------------------------------------- */

static double px_fig_t(const struct px_fig_layout *L, double v) {
  return (v - L->vmin) / (L->vmax - L->vmin);
}

static void px_fig_value_color(const struct px_figure *fig, double v, double rgb[3]) {
  px_colormap_eval(fig->map, isfinite(v) ? px_fig_t(&fig->L, v) : NAN, rgb);
}

static unsigned px_fig_bin(const struct px_fig_layout *L, double v) {
  double t;
  if (isnan(v)) return PX_FIG_BIN_NAN;
  t = px_fig_t(L, v);
  if (!(t > 0.0)) return 0;
  if (t >= 1.0) return PX_FIG_BINS - 1;
  return (unsigned)floor(t * (PX_FIG_BINS - 1) + 0.5);
}

/* Discs and point clouds: particles are sorted into colour bins (counting
 * sort) so that each colour is one filled path of many sub-paths — one fill
 * per bin batch instead of one per particle. */
static enum px_status px_fig_draw_particles(struct px_figure *fig, cairo_t *cr,
                                            const struct px_fig_layer *l) {
  const struct px_fig_layout *L = &fig->L;
  struct px_context *ctx = fig->ctx;
  size_t n = l->n, i, count[PX_FIG_NBINS + 1], start[PX_FIG_NBINS + 1];
  unsigned order_of_bins[PX_FIG_NBINS];
  uint16_t *bin;
  size_t *order;
  unsigned b, k;
  int diverging = px_colormap_is_diverging(fig->map);
  double fx0 = L->frame[0], fy0 = L->frame[1], fx1 = L->frame[2], fy1 = L->frame[3];
  if (n == 0) return PX_STATUS_OK;
  bin = px_mem_alloc(ctx, "figure", n * sizeof *bin);
  order = px_mem_alloc(ctx, "figure", n * sizeof *order);
  if (!bin || !order) {
    px_mem_free(ctx, bin);
    px_mem_free(ctx, order);
    return PX_STATUS_NOMEM;
  }
  memset(count, 0, sizeof count);
  for (i = 0; i < n; ++i) {
    double x = px_fig_get(l->dtype, l->x, i), y = px_fig_get(l->dtype, l->y, i), px, py, r;
    if (l->kind == PX_FIG_DISCS) {
      r = (l->radius ? px_fig_get(l->dtype, l->radius, i) : l->size) * L->scale;
      if (!(r >= 0.5)) r = 0.5;
    } else {
      r = 0.5 * l->size;
    }
    px_fig_to_pixel(L, x, y, &px, &py);
    if (!isfinite(px) || !isfinite(py) || px + r < fx0 || px - r > fx1 || py + r < fy0 ||
        py - r > fy1) {
      bin[i] = PX_FIG_BIN_CULLED;
      continue;
    }
    b = l->values ? px_fig_bin(L, px_fig_get(l->dtype, l->values, i)) : PX_FIG_BIN_SOLID;
    bin[i] = (uint16_t)b;
    ++count[b];
  }
  start[0] = 0;
  for (b = 0; b < PX_FIG_NBINS; ++b) start[b + 1] = start[b] + count[b];
  for (i = 0; i < n; ++i)
    if (bin[i] != PX_FIG_BIN_CULLED) order[start[bin[i]]++] = i;
  for (b = PX_FIG_NBINS; b > 0; --b) start[b] = start[b - 1];
  start[0] = 0;

  /* Draw order: solid, NaN, then values — for a diverging map from the
   * centre outwards so that strong values of either sign are on top. */
  order_of_bins[0] = PX_FIG_BIN_SOLID;
  order_of_bins[1] = PX_FIG_BIN_NAN;
  for (k = 0; k < PX_FIG_BINS; ++k) {
    if (!diverging) {
      b = k;
    } else {
      unsigned half = PX_FIG_BINS / 2, j = k / 2;
      b = (k % 2) ? half + j : half - 1 - j;
    }
    order_of_bins[2 + k] = b;
  }

  for (k = 0; k < PX_FIG_NBINS; ++k) {
    double rgb[3];
    size_t j, batch = 0;
    b = order_of_bins[k];
    if (!count[b]) continue;
    if (b == PX_FIG_BIN_SOLID)
      memcpy(rgb, l->color, sizeof rgb);
    else if (b == PX_FIG_BIN_NAN)
      px_colormap_nan(rgb);
    else
      px_colormap_eval(fig->map, (double)b / (PX_FIG_BINS - 1), rgb);
    cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
    cairo_new_path(cr);
    for (j = start[b]; j < start[b] + count[b]; ++j) {
      size_t p = order[j];
      double px, py, r;
      px_fig_to_pixel(L, px_fig_get(l->dtype, l->x, p), px_fig_get(l->dtype, l->y, p), &px, &py);
      if (l->kind == PX_FIG_DISCS) {
        r = (l->radius ? px_fig_get(l->dtype, l->radius, p) : l->size) * L->scale;
        if (!(r >= 0.5)) r = 0.5;
        cairo_new_sub_path(cr);
        cairo_arc(cr, px, py, r, 0.0, 2.0 * 3.14159265358979323846);
      } else if (l->size <= 2.0) {
        cairo_rectangle(cr, px - 0.5 * l->size, py - 0.5 * l->size, l->size, l->size);
      } else {
        cairo_new_sub_path(cr);
        cairo_arc(cr, px, py, 0.5 * l->size, 0.0, 2.0 * 3.14159265358979323846);
      }
      if (++batch == PX_FIG_BATCH) {
        cairo_fill(cr);
        batch = 0;
      }
    }
    cairo_fill(cr);
  }
  px_mem_free(ctx, bin);
  px_mem_free(ctx, order);
  return px_draw_check(ctx, cr, "drawing particles");
}

static void px_fig_draw_line(struct px_figure *fig, cairo_t *cr, const struct px_fig_layer *l) {
  const struct px_fig_layout *L = &fig->L;
  size_t i;
  int pen = 0;
  if (l->n < 2) return;
  cairo_new_path(cr);
  for (i = 0; i < l->n; ++i) {
    double px, py;
    px_fig_to_pixel(L, px_fig_get(l->dtype, l->x, i), px_fig_get(l->dtype, l->y, i), &px, &py);
    if (!isfinite(px) || !isfinite(py)) {
      pen = 0; /* a NaN point breaks the line */
      continue;
    }
    if (pen)
      cairo_line_to(cr, px, py);
    else
      cairo_move_to(cr, px, py);
    pen = 1;
  }
  if (l->mode != PX_FIGURE_LINE_OPEN) cairo_close_path(cr);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  if (l->mode == PX_FIGURE_LINE_FILLED) {
    cairo_set_source_rgb(cr, l->fill[0], l->fill[1], l->fill[2]);
    cairo_fill_preserve(cr);
  }
  cairo_set_source_rgb(cr, l->color[0], l->color[1], l->color[2]);
  cairo_set_line_width(cr, l->width);
  cairo_stroke(cr);
}

/* A label in a white box beside pixel (px, py): right of it (side > 0), left
 * (side < 0), or (side 0) on the side away from the nearer frame edge. */
static void px_fig_draw_label_at(const struct px_fig_layout *L, cairo_t *cr, double px, double py,
                                 const char *text, double gap, int side) {
  double fs = L->fs, w, cap;
  int right = side ? side > 0 : px < 0.5 * (L->frame[0] + L->frame[2]);
  double bx, by;
  if (!text[0]) return;
  px_draw_font(cr, 0.9 * fs, 0);
  w = px_draw_text_width(cr, text);
  cap = px_draw_cap_height(cr);
  bx = right ? px + gap : px - gap - w - 0.6 * fs;
  by = py - 0.5 * cap - 0.3 * fs;
  if (by < L->frame[1]) by = L->frame[1];
  if (by + cap + 0.6 * fs > L->frame[3]) by = L->frame[3] - cap - 0.6 * fs;
  cairo_set_source_rgba(cr, 1.0, 1.0, 1.0, 0.85);
  cairo_rectangle(cr, bx, by, w + 0.6 * fs, cap + 0.6 * fs);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, px_fig_ink[0], px_fig_ink[1], px_fig_ink[2]);
  px_draw_text(cr, bx + 0.3 * fs, by + 0.3 * fs, text, 0.0, 0.0);
}

/* A ring with a cross (white halo, then the line colour), or an arrow with a
 * filled head; their labels. */
static void px_fig_draw_annotation(struct px_figure *fig, cairo_t *cr,
                                   const struct px_fig_layer *l) {
  const struct px_fig_layout *L = &fig->L;
  double fs = L->fs, ax, ay, bx, by;
  int pass;
  px_fig_to_pixel(L, l->rect[0], l->rect[1], &ax, &ay);
  px_fig_to_pixel(L, l->rect[2], l->rect[3], &bx, &by);
  if (!isfinite(ax) || !isfinite(ay) || !isfinite(bx) || !isfinite(by)) return;
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  for (pass = 0; pass < 2; ++pass) {
    double w = l->width > 0 ? l->width : 1.5;
    if (pass == 0)
      cairo_set_source_rgb(cr, 1.0, 1.0, 1.0), w += 2.5;
    else
      cairo_set_source_rgb(cr, l->color[0], l->color[1], l->color[2]);
    cairo_set_line_width(cr, w);
    cairo_new_path(cr);
    if (l->kind == PX_FIG_MARKER) {
      double r = 0.6 * fs;
      cairo_arc(cr, ax, ay, r, 0.0, 6.283185307179586);
      cairo_move_to(cr, ax - 1.6 * r, ay);
      cairo_line_to(cr, ax - 0.4 * r, ay);
      cairo_move_to(cr, ax + 0.4 * r, ay);
      cairo_line_to(cr, ax + 1.6 * r, ay);
      cairo_move_to(cr, ax, ay - 1.6 * r);
      cairo_line_to(cr, ax, ay - 0.4 * r);
      cairo_move_to(cr, ax, ay + 0.4 * r);
      cairo_line_to(cr, ax, ay + 1.6 * r);
      cairo_stroke(cr);
    } else {
      double dx = bx - ax, dy = by - ay, len = sqrt(dx * dx + dy * dy), h = 0.8 * fs;
      double ux, uy;
      if (!(len > 0)) return;
      ux = dx / len;
      uy = dy / len;
      if (h > 0.5 * len) h = 0.5 * len;
      cairo_move_to(cr, ax, ay);
      cairo_line_to(cr, bx - ux * h, by - uy * h);
      cairo_stroke(cr);
      cairo_move_to(cr, bx, by);
      cairo_line_to(cr, bx - ux * h - uy * 0.45 * h, by - uy * h + ux * 0.45 * h);
      cairo_line_to(cr, bx - ux * h + uy * 0.45 * h, by - uy * h - ux * 0.45 * h);
      cairo_close_path(cr);
      if (pass == 0)
        cairo_stroke(cr);
      else
        cairo_fill(cr);
    }
  }
  if (l->kind == PX_FIG_MARKER)
    px_fig_draw_label_at(L, cr, ax, ay, l->label, 1.2 * fs, 0);
  else /* before the tail, away from the arrow */
    px_fig_draw_label_at(L, cr, ax, ay, l->label, 0.4 * fs, bx >= ax ? -1 : 1);
}

static void px_fig_draw_line_values(struct px_figure *fig, cairo_t *cr,
                                    const struct px_fig_layer *l) {
  const struct px_fig_layout *L = &fig->L;
  size_t nseg = l->mode ? l->n : (l->n ? l->n - 1 : 0), s;
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_set_line_width(cr, l->width);
  for (s = 0; s < nseg; ++s) {
    size_t a = s, b = (s + 1) % l->n;
    double ax, ay, bx, by, rgb[3];
    px_fig_to_pixel(L, px_fig_get(l->dtype, l->x, a), px_fig_get(l->dtype, l->y, a), &ax, &ay);
    px_fig_to_pixel(L, px_fig_get(l->dtype, l->x, b), px_fig_get(l->dtype, l->y, b), &bx, &by);
    if (!isfinite(ax) || !isfinite(ay) || !isfinite(bx) || !isfinite(by)) continue;
    px_fig_value_color(fig, px_fig_get(l->dtype, l->values, s), rgb);
    cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
    cairo_move_to(cr, ax, ay);
    cairo_line_to(cr, bx, by);
    cairo_stroke(cr);
  }
}

static uint32_t px_fig_argb(const double rgb[3]) {
  uint32_t r = (uint32_t)(rgb[0] * 255.0 + 0.5), g = (uint32_t)(rgb[1] * 255.0 + 0.5);
  uint32_t b = (uint32_t)(rgb[2] * 255.0 + 0.5);
  return 0xff000000u | (r << 16) | (g << 8) | b;
}

static enum px_status px_fig_draw_raster(struct px_figure *fig, cairo_t *cr,
                                         const struct px_fig_layer *l) {
  const struct px_fig_layout *L = &fig->L;
  cairo_surface_t *img;
  unsigned char *data;
  int stride;
  size_t i, j;
  double x0, y0, x1, y1;
  img = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, (int)l->nx, (int)l->ny);
  PX_TRY(px_draw_check_surface(fig->ctx, img, "creating the raster image"));
  cairo_surface_flush(img);
  data = cairo_image_surface_get_data(img);
  stride = cairo_image_surface_get_stride(img);
  for (j = 0; j < l->ny; ++j) {
    /* image row 0 is the top (j = ny-1) */
    uint32_t *row = (uint32_t *)(void *)(data + (size_t)stride * (l->ny - 1 - j));
    for (i = 0; i < l->nx; ++i) {
      double rgb[3];
      px_fig_value_color(fig, px_fig_get(l->dtype, l->values, j * l->nx + i), rgb);
      row[i] = px_fig_argb(rgb);
    }
  }
  cairo_surface_mark_dirty(img);
  px_fig_to_pixel(L, l->rect[0], l->rect[3], &x0, &y0);
  px_fig_to_pixel(L, l->rect[1], l->rect[2], &x1, &y1);
  cairo_save(cr);
  cairo_rectangle(cr, x0, y0, x1 - x0, y1 - y0);
  cairo_clip(cr);
  cairo_translate(cr, x0, y0);
  cairo_scale(cr, (x1 - x0) / (double)l->nx, (y1 - y0) / (double)l->ny);
  cairo_set_source_surface(cr, img, 0.0, 0.0);
  cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
  cairo_pattern_set_extend(cairo_get_source(cr), CAIRO_EXTEND_PAD);
  cairo_paint(cr);
  cairo_restore(cr);
  cairo_surface_destroy(img);
  return px_draw_check(fig->ctx, cr, "drawing a raster field");
}

static void px_fig_draw_axes(struct px_figure *fig, cairo_t *cr) {
  const struct px_fig_layout *L = &fig->L;
  double fs = L->fs, tick = 0.35 * fs, maxabs = 0.0, ylab_w;
  double x0 = L->frame[0], y0 = L->frame[1], x1 = L->frame[2], y1 = L->frame[3];
  char buf[64];
  int i;
  cairo_set_source_rgb(cr, 0.25, 0.25, 0.25);
  cairo_set_line_width(cr, 1.0);
  cairo_rectangle(cr, x0 + 0.5, y0 + 0.5, x1 - x0 - 1.0, y1 - y0 - 1.0);
  cairo_stroke(cr);
  px_draw_font(cr, fs, 0);
  for (i = 0; i < L->nxt; ++i) maxabs = fmax(maxabs, fabs(L->xt[i]));
  for (i = 0; i < L->nxt; ++i) {
    double px = floor(x0 + (L->xt[i] - L->world[0]) * L->scale) + 0.5;
    cairo_set_source_rgb(cr, 0.25, 0.25, 0.25);
    cairo_move_to(cr, px, y1);
    cairo_line_to(cr, px, y1 + tick);
    cairo_stroke(cr);
    px_draw_format_tick(L->xt[i], L->xstep, maxabs, buf, sizeof buf);
    cairo_set_source_rgb(cr, px_fig_ink[0], px_fig_ink[1], px_fig_ink[2]);
    px_draw_text(cr, px, y1 + tick + 0.4 * fs, buf, 0.5, 0.0);
  }
  ylab_w = px_fig_max_label_width(cr, L->yt, L->nyt, L->ystep, &maxabs);
  for (i = 0; i < L->nyt; ++i) {
    double py = floor(y1 - (L->yt[i] - L->world[2]) * L->scale) + 0.5;
    cairo_set_source_rgb(cr, 0.25, 0.25, 0.25);
    cairo_move_to(cr, x0, py);
    cairo_line_to(cr, x0 - tick, py);
    cairo_stroke(cr);
    px_draw_format_tick(L->yt[i], L->ystep, maxabs, buf, sizeof buf);
    cairo_set_source_rgb(cr, px_fig_ink[0], px_fig_ink[1], px_fig_ink[2]);
    px_draw_text(cr, x0 - tick - 0.3 * fs, py, buf, 1.0, 0.5);
  }
  cairo_set_source_rgb(cr, px_fig_ink[0], px_fig_ink[1], px_fig_ink[2]);
  if (fig->xlabel[0])
    px_draw_text(cr, 0.5 * (x0 + x1), y1 + tick + 0.4 * fs + fs + 0.6 * fs, fig->xlabel, 0.5, 0.0);
  if (fig->ylabel[0])
    px_draw_text_vertical(cr, x0 - tick - 0.3 * fs - ylab_w - 0.5 * fs - 0.5 * fs, 0.5 * (y0 + y1),
                          fig->ylabel);
}

static void px_fig_draw_colorbar(struct px_figure *fig, cairo_t *cr) {
  const struct px_fig_layout *L = &fig->L;
  double fs = L->fs, x0 = L->cbar[0], y0 = L->cbar[1], x1 = L->cbar[2], y1 = L->cbar[3];
  double h = y1 - y0, wmax = 0.0, ys[3];
  char lab[3][64], fl[2 * PX_FIG_TEXT];
  int row, i;
  /* One pixel row per colour, t from 0 at the bottom to 1 at the top. */
  for (row = 0; row < (int)h; ++row) {
    double rgb[3], t = ((double)row + 0.5) / h;
    px_colormap_eval(fig->map, t, rgb);
    cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
    cairo_rectangle(cr, x0, y1 - (double)row - 1.0, x1 - x0, 1.0);
    cairo_fill(cr);
  }
  cairo_set_source_rgb(cr, 0.25, 0.25, 0.25);
  cairo_set_line_width(cr, 1.0);
  cairo_rectangle(cr, x0 + 0.5, y0 + 0.5, x1 - x0 - 1.0, h - 1.0);
  cairo_stroke(cr);
  px_fig_cbar_labels(L, lab);
  ys[0] = y1 - 0.5, ys[1] = floor(0.5 * (y0 + y1)) + 0.5, ys[2] = y0 + 0.5;
  px_draw_font(cr, fs, 0);
  for (i = 0; i < 3; ++i) {
    double ay = i == 0 ? 1.0 : i == 2 ? 0.0 : 0.5; /* keep end labels inside the bar's span */
    cairo_set_source_rgb(cr, 0.25, 0.25, 0.25);
    cairo_move_to(cr, x1, ys[i]);
    cairo_line_to(cr, x1 + 0.3 * fs, ys[i]);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, px_fig_ink[0], px_fig_ink[1], px_fig_ink[2]);
    px_draw_text(cr, x1 + 0.6 * fs, ys[i], lab[i], 0.0, ay);
    wmax = fmax(wmax, px_draw_text_width(cr, lab[i]));
  }
  px_fig_field_label(fig, fl, sizeof fl);
  if (fl[0])
    px_draw_text_vertical(cr, x1 + 0.6 * fs + wmax + 0.5 * fs + 0.6 * fs, 0.5 * (y0 + y1), fl);
}

static void px_fig_draw_labels(struct px_figure *fig, cairo_t *cr) {
  const struct px_fig_layout *L = &fig->L;
  double fs = L->fs;
  if (fig->title[0]) {
    px_draw_font(cr, 1.15 * fs, 1);
    cairo_set_source_rgb(cr, px_fig_ink[0], px_fig_ink[1], px_fig_ink[2]);
    px_draw_text(cr, 0.5 * (L->frame[0] + L->frame[2]), L->frame[1] - 0.6 * fs, fig->title, 0.5,
                 1.0);
  }
  if (isfinite(fig->time)) {
    char buf[128];
    double w, cap, bx, by, bw, bh;
    px_fig_time_label(fig, buf, sizeof buf);
    px_draw_font(cr, fs, 0);
    w = px_draw_text_width(cr, buf);
    cap = px_draw_cap_height(cr);
    bx = L->frame[0] + 0.5 * fs;
    by = L->frame[1] + 0.5 * fs;
    bw = w + 0.8 * fs;
    bh = cap + 0.8 * fs;
    cairo_set_source_rgba(cr, 1.0, 1.0, 1.0, 0.8);
    cairo_rectangle(cr, bx, by, bw, bh);
    cairo_fill(cr);
    cairo_set_source_rgb(cr, px_fig_ink[0], px_fig_ink[1], px_fig_ink[2]);
    px_draw_text(cr, bx + 0.4 * fs, by + 0.4 * fs, buf, 0.0, 0.0);
  }
}

enum px_status px_figure_write_png(struct px_figure *fig, const char *path) {
  cairo_surface_t *surface;
  cairo_t *cr;
  enum px_status st;
  size_t k;
  if (!fig || !path) return PX_STATUS_INVALID;
  surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, fig->width, fig->height);
  cr = cairo_create(surface);
  st = px_draw_check(fig->ctx, cr, "creating the picture");
  if (st == PX_STATUS_OK) st = px_fig_layout(fig, cr);
  if (st == PX_STATUS_OK) {
    const struct px_fig_layout *L = &fig->L;
    cairo_set_source_rgb(cr, fig->bg[0], fig->bg[1], fig->bg[2]);
    cairo_paint(cr);
    cairo_save(cr);
    cairo_rectangle(cr, L->frame[0], L->frame[1], L->frame[2] - L->frame[0],
                    L->frame[3] - L->frame[1]);
    cairo_clip(cr);
    for (k = 0; k < fig->nlayers && st == PX_STATUS_OK; ++k) {
      const struct px_fig_layer *l = &fig->layers[k];
      switch (l->kind) {
        case PX_FIG_DISCS:
        case PX_FIG_POINTS: st = px_fig_draw_particles(fig, cr, l); break;
        case PX_FIG_LINE: px_fig_draw_line(fig, cr, l); break;
        case PX_FIG_LINE_VALUES: px_fig_draw_line_values(fig, cr, l); break;
        case PX_FIG_RASTER: st = px_fig_draw_raster(fig, cr, l); break;
        case PX_FIG_MARKER:
        case PX_FIG_ARROW: break; /* above every layer, below */
      }
    }
    for (k = 0; k < fig->nlayers && st == PX_STATUS_OK; ++k) {
      const struct px_fig_layer *l = &fig->layers[k];
      if (l->kind == PX_FIG_MARKER || l->kind == PX_FIG_ARROW) px_fig_draw_annotation(fig, cr, l);
    }
    cairo_restore(cr);
    if (st == PX_STATUS_OK) {
      px_fig_draw_axes(fig, cr);
      if (L->has_scale) px_fig_draw_colorbar(fig, cr);
      px_fig_draw_labels(fig, cr);
      st = px_draw_check(fig->ctx, cr, "drawing the picture");
    }
  }
  cairo_destroy(cr);
  if (st != PX_STATUS_OK)
    px_context_prefix(fig->ctx, "picture %s", path);
  else
    st = px_draw_write_png(fig->ctx, surface, path);
  cairo_surface_destroy(surface);
  return st;
}
