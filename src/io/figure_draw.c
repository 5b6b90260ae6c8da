/* Snapshot pictures: drawing the layers, axes, colour bar and labels into
 * a PNG file; see figure.c. */
#include "partix/figure.h"

#include <cairo.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "io/draw.h"
#include "io/figure_impl.h"
#include "partix/memory.h"

static const double px_fig_ink[3] = {0.1, 0.1, 0.1};
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
