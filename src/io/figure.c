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

#include "io/figure_impl.h"
#include "partix/memory.h"

static void px_fig_copy(char *dst, size_t size, const char *src) {
  if (!src) src = "";
  snprintf(dst, size, "%s", src);
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
