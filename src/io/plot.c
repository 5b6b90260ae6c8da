/* Line plots of time series: several series on one pair of axes with 1-2-5
 * ticks, grid, legend, optional logarithmic y axis.
 *
 * Series colours: the Okabe-Ito palette (M. Okabe and K. Ito, "Color
 * Universal Design", 2008), distinguishable with the common forms of colour
 * blindness; yellow is last as it is faint on white. */
#include <cairo.h>
#include <math.h>
#include <string.h>

#include "io/draw.h"
#include "io/figure_impl.h"
#include "io/ioutil.h"
#include "partix/figure.h"
#include "partix/memory.h"

#define PX_PLOT_TEXT 256

struct px_plot_series {
  char *name;    /* owned */
  double *x, *y; /* owned */
  size_t n;
};

struct px_plot_layout {
  double fs;
  double frame[4];     /* x0, y0, x1, y1 (pixels) */
  double xr[2], yr[2]; /* data ranges shown (y in log10 units if log_y) */
  double xt[PX_DRAW_MAX_TICKS], yt[PX_DRAW_MAX_TICKS], xstep, ystep;
  int nxt, nyt;
  int ydecades; /* log y: ticks are powers of ten (labels 10^k) */
};

struct px_plot {
  struct px_context *ctx; /* borrowed */
  int width, height;
  char title[PX_PLOT_TEXT], xlabel[PX_PLOT_TEXT], ylabel[PX_PLOT_TEXT];
  double xrange[2], yrange[2]; /* NaN: automatic */
  int log_y;
  int markers;                   /* a filled disc at every data point */
  struct px_plot_series *series; /* owned */
  size_t nseries, cap;
  struct px_plot_layout L;
};

static const double px_plot_palette[8][3] = {
    {0.0 / 255, 114.0 / 255, 178.0 / 255},   /* blue */
    {213.0 / 255, 94.0 / 255, 0.0 / 255},    /* vermillion */
    {0.0 / 255, 158.0 / 255, 115.0 / 255},   /* bluish green */
    {204.0 / 255, 121.0 / 255, 167.0 / 255}, /* reddish purple */
    {230.0 / 255, 159.0 / 255, 0.0 / 255},   /* orange */
    {86.0 / 255, 180.0 / 255, 233.0 / 255},  /* sky blue */
    {0.0, 0.0, 0.0},                         /* black */
    {240.0 / 255, 228.0 / 255, 66.0 / 255}   /* yellow */
};

static const double px_plot_ink[3] = {0.1, 0.1, 0.1};

void px_plot_series_color(size_t i, double rgb[3]) {
  memcpy(rgb, px_plot_palette[i % 8], 3 * sizeof(double));
}

static void px_plot_copy(char *dst, size_t size, const char *src) {
  snprintf(dst, size, "%s", src ? src : "");
}

enum px_status px_plot_create(struct px_context *ctx, int width, int height, struct px_plot **out) {
  struct px_plot *p;
  if (!ctx || !out) return PX_STATUS_INVALID;
  *out = NULL;
  if (width < 16 || height < 16 || width > 16384 || height > 16384)
    return px_context_fail(ctx, PX_STATUS_INVALID,
                           "plot size %d x %d pixels (expected 16 to 16384 each)", width, height);
  p = px_mem_calloc(ctx, "plot", 1, sizeof *p);
  if (!p) return PX_STATUS_NOMEM;
  p->ctx = ctx;
  p->width = width;
  p->height = height;
  p->xrange[0] = p->xrange[1] = p->yrange[0] = p->yrange[1] = NAN;
  *out = p;
  return PX_STATUS_OK;
}

void px_plot_free(struct px_plot *p) {
  size_t i;
  if (!p) return;
  for (i = 0; i < p->nseries; ++i) {
    px_mem_free(p->ctx, p->series[i].name);
    px_mem_free(p->ctx, p->series[i].x);
    px_mem_free(p->ctx, p->series[i].y);
  }
  px_mem_free(p->ctx, p->series);
  px_mem_free(p->ctx, p);
}

void px_plot_set_title(struct px_plot *p, const char *title) {
  if (p) px_plot_copy(p->title, sizeof p->title, title);
}

void px_plot_set_labels(struct px_plot *p, const char *xlabel, const char *ylabel) {
  if (!p) return;
  px_plot_copy(p->xlabel, sizeof p->xlabel, xlabel);
  px_plot_copy(p->ylabel, sizeof p->ylabel, ylabel);
}

void px_plot_set_xrange(struct px_plot *p, double min, double max) {
  if (p) p->xrange[0] = min, p->xrange[1] = max;
}

void px_plot_set_yrange(struct px_plot *p, double min, double max) {
  if (p) p->yrange[0] = min, p->yrange[1] = max;
}

void px_plot_set_log_y(struct px_plot *p, int on) {
  if (p) p->log_y = on != 0;
}

void px_plot_set_markers(struct px_plot *p, int on) {
  if (p) p->markers = on != 0;
}

/* A marker's radius (pixels): visible beside the line (width fs / 6). */
static double px_plot_marker_radius(const struct px_plot_layout *L) {
  return fmax(4.0, 0.35 * L->fs);
}

enum px_status px_plot_add_series(struct px_plot *p, const char *name, size_t n, const double *x,
                                  const double *y) {
  struct px_plot_series *s;
  if (!p) return PX_STATUS_INVALID;
  if (n && (!x || !y))
    return px_context_fail(p->ctx, PX_STATUS_INVALID, "plot series '%s': x or y is NULL",
                           name ? name : "");
  if (p->nseries == p->cap) {
    size_t ncap = p->cap ? 2 * p->cap : 4;
    void *ns = px_mem_realloc(p->ctx, "plot", p->series, ncap * sizeof *p->series);
    if (!ns) return PX_STATUS_NOMEM;
    p->series = ns;
    p->cap = ncap;
  }
  s = &p->series[p->nseries];
  memset(s, 0, sizeof *s);
  s->name = px_ioutil_strdup(p->ctx, "plot", name ? name : "");
  s->x = px_mem_alloc(p->ctx, "plot", (n ? n : 1) * sizeof *s->x);
  s->y = px_mem_alloc(p->ctx, "plot", (n ? n : 1) * sizeof *s->y);
  if (!s->name || !s->x || !s->y) {
    px_mem_free(p->ctx, s->name);
    px_mem_free(p->ctx, s->x);
    px_mem_free(p->ctx, s->y);
    return PX_STATUS_NOMEM;
  }
  if (n) {
    memcpy(s->x, x, n * sizeof *x);
    memcpy(s->y, y, n * sizeof *y);
  }
  s->n = n;
  ++p->nseries;
  return PX_STATUS_OK;
}

/* ---- Layout -------------------------------------------------------------- */

/* y as plotted: log10(y) on a log axis (NaN for y <= 0). */
static double px_plot_yv(const struct px_plot *p, double y) {
  if (!p->log_y) return y;
  return y > 0.0 ? log10(y) : NAN;
}

static void px_plot_data_range(const struct px_plot *p, double xr[2], double yr[2]) {
  size_t k, i;
  xr[0] = yr[0] = INFINITY;
  xr[1] = yr[1] = -INFINITY;
  for (k = 0; k < p->nseries; ++k) {
    const struct px_plot_series *s = &p->series[k];
    for (i = 0; i < s->n; ++i) {
      double x = s->x[i], y = px_plot_yv(p, s->y[i]);
      if (!isfinite(x) || !isfinite(y)) continue;
      if (x < xr[0]) xr[0] = x;
      if (x > xr[1]) xr[1] = x;
      if (y < yr[0]) yr[0] = y;
      if (y > yr[1]) yr[1] = y;
    }
  }
}

static void px_plot_widen(double r[2]) {
  if (!(r[0] <= r[1])) {
    r[0] = 0.0;
    r[1] = 1.0;
  } else if (r[0] == r[1]) {
    double d = r[0] != 0.0 ? 0.5 * fabs(r[0]) : 0.5;
    r[0] -= d;
    r[1] += d;
  }
}

/* Log axis ticks: powers of ten (every `every` decades) when the range holds
 * at least two, otherwise 1-2-5 multiples. Ticks are stored as log10 values. */
static void px_plot_log_ticks(struct px_plot_layout *L, int target) {
  double lo = L->yr[0], hi = L->yr[1];
  long k0 = (long)ceil(lo - 1e-9), k1 = (long)floor(hi + 1e-9), k;
  L->nyt = 0;
  if (k1 - k0 + 1 >= 2) {
    long every = (k1 - k0 + 1 + target - 1) / target;
    if (every < 1) every = 1;
    L->ydecades = 1;
    L->ystep = (double)every;
    for (k = k0; k <= k1 && L->nyt < PX_DRAW_MAX_TICKS; ++k)
      if ((k - k0) % every == 0) L->yt[L->nyt++] = (double)k;
    return;
  }
  L->ydecades = 0;
  for (k = (long)floor(lo) - 1; k <= (long)ceil(hi) && L->nyt < PX_DRAW_MAX_TICKS; ++k) {
    static const double m[3] = {1.0, 2.0, 5.0};
    int j;
    for (j = 0; j < 3 && L->nyt < PX_DRAW_MAX_TICKS; ++j) {
      double v = log10(m[j]) + (double)k;
      if (v >= lo - 1e-9 && v <= hi + 1e-9) L->yt[L->nyt++] = v;
    }
  }
  L->ystep = 1.0;
  if (L->nyt < 3) {
    /* less than a factor of 5: linear 1-2-5 ticks of the values themselves */
    double vals[PX_DRAW_MAX_TICKS], step;
    int n = px_draw_nice_ticks(pow(10.0, lo), pow(10.0, hi), target, vals, &step), j;
    L->nyt = 0;
    for (j = 0; j < n; ++j)
      if (vals[j] > 0.0) L->yt[L->nyt++] = log10(vals[j]);
  }
}

/* Width of a y tick label (log decades: "10" + superscript exponent). */
static double px_plot_ytick_width(cairo_t *cr, const struct px_plot *p, int i, double maxabs) {
  const struct px_plot_layout *L = &p->L;
  char buf[64];
  if (p->log_y && L->ydecades) {
    double w10 = px_draw_text_width(cr, "10"), we;
    snprintf(buf, sizeof buf, "%ld", (long)floor(L->yt[i] + 0.5));
    cairo_save(cr);
    cairo_set_font_size(cr, 0.7 * L->fs);
    we = px_draw_text_width(cr, buf);
    cairo_restore(cr);
    return w10 + we;
  }
  if (p->log_y) {
    px_draw_format_value(pow(10.0, L->yt[i]), 6, buf, sizeof buf);
  } else {
    px_draw_format_tick(L->yt[i], L->ystep, maxabs, buf, sizeof buf);
  }
  return px_draw_text_width(cr, buf);
}

static double px_plot_ymaxabs(const struct px_plot_layout *L) {
  double m = 0.0;
  int i;
  for (i = 0; i < L->nyt; ++i) m = fmax(m, fabs(L->yt[i]));
  return m;
}

static enum px_status px_plot_layout(struct px_plot *p, cairo_t *cr) {
  struct px_plot_layout *L = &p->L;
  double W = p->width, H = p->height, fs, pad, top, bottom, left, right;
  double dxr[2], dyr[2];
  int pass, i;
  memset(L, 0, sizeof *L);
  fs = fmax(10.0, fmin(W, H) / 40.0);
  L->fs = fs;
  pad = 0.8 * fs;
  px_plot_data_range(p, dxr, dyr);
  if (isfinite(p->xrange[0]) && isfinite(p->xrange[1]) && p->xrange[1] > p->xrange[0]) {
    L->xr[0] = p->xrange[0], L->xr[1] = p->xrange[1];
  } else {
    L->xr[0] = dxr[0], L->xr[1] = dxr[1];
    px_plot_widen(L->xr);
  }
  if (isfinite(p->yrange[0]) && isfinite(p->yrange[1]) && p->yrange[1] > p->yrange[0]) {
    L->yr[0] = px_plot_yv(p, p->yrange[0]);
    L->yr[1] = px_plot_yv(p, p->yrange[1]);
    if (!(L->yr[1] > L->yr[0]))
      return px_context_fail(p->ctx, PX_STATUS_INVALID,
                             "plot y range [%g, %g] on a log axis needs positive values",
                             p->yrange[0], p->yrange[1]);
  } else {
    double m;
    L->yr[0] = dyr[0], L->yr[1] = dyr[1];
    px_plot_widen(L->yr);
    m = 0.05 * (L->yr[1] - L->yr[0]);
    L->yr[0] -= m;
    L->yr[1] += m;
  }

  px_draw_font(cr, fs, 0);
  top = p->title[0] ? pad + 1.6 * fs : pad;
  bottom = 0.35 * fs + 0.4 * fs + fs + (p->xlabel[0] ? 1.6 * fs : 0.0) + pad;
  right = pad + 1.5 * fs; /* room for half of the last x tick label */
  left = pad + (p->ylabel[0] ? 1.6 * fs : 0.0) + 3.0 * fs + 0.65 * fs;
  for (pass = 0; pass < 2; ++pass) {
    double pw, ph, w = 0.0, maxabs;
    L->frame[0] = floor(left);
    L->frame[1] = floor(top);
    L->frame[2] = floor(W - right);
    L->frame[3] = floor(H - bottom);
    pw = L->frame[2] - L->frame[0];
    ph = L->frame[3] - L->frame[1];
    if (pw < 16.0 || ph < 16.0)
      return px_context_fail(p->ctx, PX_STATUS_INVALID,
                             "plot of %d x %d pixels is too small for its labels", p->width,
                             p->height);
    L->nxt =
        px_draw_nice_ticks(L->xr[0], L->xr[1], (int)fmax(2.0, pw / (6.0 * fs)), L->xt, &L->xstep);
    if (p->log_y)
      px_plot_log_ticks(L, (int)fmax(2.0, ph / (3.0 * fs)));
    else
      L->nyt =
          px_draw_nice_ticks(L->yr[0], L->yr[1], (int)fmax(2.0, ph / (3.0 * fs)), L->yt, &L->ystep);
    maxabs = px_plot_ymaxabs(L);
    for (i = 0; i < L->nyt; ++i) w = fmax(w, px_plot_ytick_width(cr, p, i, maxabs));
    left = pad + (p->ylabel[0] ? 1.6 * fs : 0.0) + w + 0.65 * fs;
  }
  return PX_STATUS_OK;
}

static void px_plot_to_pixel(const struct px_plot *p, double x, double y, double *px, double *py) {
  const struct px_plot_layout *L = &p->L;
  double yv = px_plot_yv(p, y);
  *px = L->frame[0] + (x - L->xr[0]) / (L->xr[1] - L->xr[0]) * (L->frame[2] - L->frame[0]);
  *py = L->frame[3] - (yv - L->yr[0]) / (L->yr[1] - L->yr[0]) * (L->frame[3] - L->frame[1]);
}

static enum px_status px_plot_layout_scratch(struct px_plot *p) {
  cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 1, 1);
  cairo_t *cr = cairo_create(s);
  enum px_status st = px_draw_check(p->ctx, cr, "measuring text");
  if (st == PX_STATUS_OK) st = px_plot_layout(p, cr);
  cairo_destroy(cr);
  cairo_surface_destroy(s);
  return st;
}

enum px_status px_plot_data_to_pixel(struct px_plot *p, double x, double y, double *px,
                                     double *py) {
  if (!p || !px || !py) return PX_STATUS_INVALID;
  PX_TRY(px_plot_layout_scratch(p));
  px_plot_to_pixel(p, x, y, px, py);
  return PX_STATUS_OK;
}

enum px_status px_plot_layout_frame(struct px_plot *p, double frame[4]) {
  if (!p) return PX_STATUS_INVALID;
  PX_TRY(px_plot_layout_scratch(p));
  memcpy(frame, p->L.frame, sizeof p->L.frame);
  return PX_STATUS_OK;
}

/* ---- Drawing ------------------------------------------------------------- */

static void px_plot_draw_axes(struct px_plot *p, cairo_t *cr) {
  const struct px_plot_layout *L = &p->L;
  double fs = L->fs, tick = 0.35 * fs, x0 = L->frame[0], y0 = L->frame[1], x1 = L->frame[2];
  double y1 = L->frame[3], maxabs = 0.0, wmax = 0.0, ymaxabs = px_plot_ymaxabs(L);
  char buf[64];
  int i;
  /* grid */
  cairo_set_line_width(cr, 1.0);
  cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
  for (i = 0; i < L->nxt; ++i) {
    double px = floor(x0 + (L->xt[i] - L->xr[0]) / (L->xr[1] - L->xr[0]) * (x1 - x0)) + 0.5;
    cairo_move_to(cr, px, y0);
    cairo_line_to(cr, px, y1);
  }
  for (i = 0; i < L->nyt; ++i) {
    double py = floor(y1 - (L->yt[i] - L->yr[0]) / (L->yr[1] - L->yr[0]) * (y1 - y0)) + 0.5;
    cairo_move_to(cr, x0, py);
    cairo_line_to(cr, x1, py);
  }
  cairo_stroke(cr);
  /* frame, ticks, labels */
  cairo_set_source_rgb(cr, 0.25, 0.25, 0.25);
  cairo_rectangle(cr, x0 + 0.5, y0 + 0.5, x1 - x0 - 1.0, y1 - y0 - 1.0);
  cairo_stroke(cr);
  px_draw_font(cr, fs, 0);
  for (i = 0; i < L->nxt; ++i) maxabs = fmax(maxabs, fabs(L->xt[i]));
  for (i = 0; i < L->nxt; ++i) {
    double px = floor(x0 + (L->xt[i] - L->xr[0]) / (L->xr[1] - L->xr[0]) * (x1 - x0)) + 0.5;
    cairo_set_source_rgb(cr, 0.25, 0.25, 0.25);
    cairo_move_to(cr, px, y1);
    cairo_line_to(cr, px, y1 + tick);
    cairo_stroke(cr);
    px_draw_format_tick(L->xt[i], L->xstep, maxabs, buf, sizeof buf);
    cairo_set_source_rgb(cr, px_plot_ink[0], px_plot_ink[1], px_plot_ink[2]);
    px_draw_text(cr, px, y1 + tick + 0.4 * fs, buf, 0.5, 0.0);
  }
  for (i = 0; i < L->nyt; ++i) {
    double py = floor(y1 - (L->yt[i] - L->yr[0]) / (L->yr[1] - L->yr[0]) * (y1 - y0)) + 0.5;
    double xr = x0 - tick - 0.3 * fs, w = px_plot_ytick_width(cr, p, i, ymaxabs);
    cairo_set_source_rgb(cr, 0.25, 0.25, 0.25);
    cairo_move_to(cr, x0, py);
    cairo_line_to(cr, x0 - tick, py);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, px_plot_ink[0], px_plot_ink[1], px_plot_ink[2]);
    wmax = fmax(wmax, w);
    if (p->log_y && L->ydecades) {
      /* 10 with a raised, smaller exponent */
      double w10 = px_draw_text_width(cr, "10");
      snprintf(buf, sizeof buf, "%ld", (long)floor(L->yt[i] + 0.5));
      px_draw_text(cr, xr - w, py, "10", 0.0, 0.5);
      px_draw_font(cr, 0.7 * fs, 0);
      px_draw_text(cr, xr - w + w10, py - 0.45 * fs, buf, 0.0, 0.5);
      px_draw_font(cr, fs, 0);
    } else {
      if (p->log_y)
        px_draw_format_value(pow(10.0, L->yt[i]), 6, buf, sizeof buf);
      else
        px_draw_format_tick(L->yt[i], L->ystep, ymaxabs, buf, sizeof buf);
      px_draw_text(cr, xr, py, buf, 1.0, 0.5);
    }
  }
  if (p->xlabel[0])
    px_draw_text(cr, 0.5 * (x0 + x1), y1 + tick + 0.4 * fs + fs + 0.6 * fs, p->xlabel, 0.5, 0.0);
  if (p->ylabel[0])
    px_draw_text_vertical(cr, x0 - tick - 0.3 * fs - wmax - 1.0 * fs, 0.5 * (y0 + y1), p->ylabel);
  if (p->title[0]) {
    px_draw_font(cr, 1.15 * fs, 1);
    px_draw_text(cr, 0.5 * (x0 + x1), y0 - 0.6 * fs, p->title, 0.5, 1.0);
  }
}

static void px_plot_draw_series(struct px_plot *p, cairo_t *cr) {
  const struct px_plot_layout *L = &p->L;
  size_t k, i;
  cairo_save(cr);
  cairo_rectangle(cr, L->frame[0], L->frame[1], L->frame[2] - L->frame[0],
                  L->frame[3] - L->frame[1]);
  cairo_clip(cr);
  cairo_set_line_width(cr, fmax(2.0, L->fs / 6.0));
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  for (k = 0; k < p->nseries; ++k) {
    const struct px_plot_series *s = &p->series[k];
    int pen = 0;
    double rgb[3];
    px_plot_series_color(k, rgb);
    cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
    cairo_new_path(cr);
    for (i = 0; i < s->n; ++i) {
      double px, py;
      px_plot_to_pixel(p, s->x[i], s->y[i], &px, &py);
      if (!isfinite(px) || !isfinite(py)) {
        pen = 0;
        continue;
      }
      /* keep far-off points within cairo's fixed-point range */
      px = fmax(-1e5, fmin(1e5, px));
      py = fmax(-1e5, fmin(1e5, py));
      if (pen)
        cairo_line_to(cr, px, py);
      else
        cairo_move_to(cr, px, py), cairo_line_to(cr, px, py); /* a lone point shows as a dot */
      pen = 1;
    }
    cairo_stroke(cr);
  }
  cairo_restore(cr);
  /* markers unclipped, so that a point on the frame (the ends of an
     automatic x range) shows a whole disc; points outside are left out */
  for (k = 0; p->markers && k < p->nseries; ++k) {
    const struct px_plot_series *s = &p->series[k];
    double rgb[3];
    px_plot_series_color(k, rgb);
    cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
    cairo_new_path(cr);
    for (i = 0; i < s->n; ++i) {
      double px, py;
      px_plot_to_pixel(p, s->x[i], s->y[i], &px, &py);
      if (!(px >= L->frame[0] - 0.5 && px <= L->frame[2] + 0.5 && py >= L->frame[1] - 0.5 &&
            py <= L->frame[3] + 0.5))
        continue;
      cairo_new_sub_path(cr);
      cairo_arc(cr, px, py, px_plot_marker_radius(L), 0.0, 6.283185307179586);
    }
    cairo_fill(cr);
  }
}

/* Legend in the frame corner that covers the least of the lines. */
static void px_plot_draw_legend(struct px_plot *p, cairo_t *cr) {
  const struct px_plot_layout *L = &p->L;
  double fs = L->fs, wname = 0.0, bw, bh, line = 2.2 * fs, rowh = 1.5 * fs, best_x = 0, best_y = 0;
  size_t k, i, best = (size_t)-1, named = 0;
  int c;
  px_draw_font(cr, fs, 0);
  for (k = 0; k < p->nseries; ++k) {
    if (!p->series[k].name[0]) continue;
    ++named;
    wname = fmax(wname, px_draw_text_width(cr, p->series[k].name));
  }
  if (!named) return;
  bw = 0.6 * fs + line + 0.5 * fs + wname + 0.7 * fs;
  bh = 0.5 * fs + (double)named * rowh + 0.3 * fs;
  for (c = 0; c < 4; ++c) {
    /* upper right, upper left, lower right, lower left */
    double bx = (c % 2 == 0) ? L->frame[2] - 0.6 * fs - bw : L->frame[0] + 0.6 * fs;
    double by = (c < 2) ? L->frame[1] + 0.6 * fs : L->frame[3] - 0.6 * fs - bh;
    size_t covered = 0;
    /* the lines, not only their points: a segment between two samples (a
       peak) is sampled every few pixels */
    for (k = 0; k < p->nseries; ++k) {
      double qx = NAN, qy = NAN;
      for (i = 0; i < p->series[k].n; ++i) {
        double px, py, len;
        int m, steps;
        px_plot_to_pixel(p, p->series[k].x[i], p->series[k].y[i], &px, &py);
        if (!isfinite(px) || !isfinite(py)) {
          qx = qy = NAN;
          continue;
        }
        len = isfinite(qx) ? hypot(px - qx, py - qy) : 0.0;
        steps = len > 4.0 ? (int)fmin(len / 4.0, 256.0) : 0;
        for (m = 0; m <= steps; ++m) {
          double f = steps ? (double)m / steps : 1.0;
          double sx = steps ? qx + f * (px - qx) : px, sy = steps ? qy + f * (py - qy) : py;
          covered += sx >= bx && sx <= bx + bw && sy >= by && sy <= by + bh;
        }
        qx = px;
        qy = py;
      }
    }
    if (covered < best) best = covered, best_x = bx, best_y = by;
  }
  cairo_set_source_rgba(cr, 1.0, 1.0, 1.0, 0.88);
  cairo_rectangle(cr, floor(best_x) + 0.5, floor(best_y) + 0.5, floor(bw), floor(bh));
  cairo_fill_preserve(cr);
  cairo_set_source_rgb(cr, 0.7, 0.7, 0.7);
  cairo_set_line_width(cr, 1.0);
  cairo_stroke(cr);
  cairo_set_line_width(cr, fmax(2.0, fs / 6.0));
  i = 0;
  for (k = 0; k < p->nseries; ++k) {
    double rgb[3], y;
    if (!p->series[k].name[0]) continue;
    y = best_y + 0.5 * fs + ((double)i + 0.5) * rowh;
    px_plot_series_color(k, rgb);
    cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
    cairo_move_to(cr, best_x + 0.6 * fs, y);
    cairo_line_to(cr, best_x + 0.6 * fs + line, y);
    cairo_stroke(cr);
    if (p->markers) {
      cairo_arc(cr, best_x + 0.6 * fs + 0.5 * line, y, px_plot_marker_radius(L), 0.0,
                6.283185307179586);
      cairo_fill(cr);
    }
    cairo_set_source_rgb(cr, px_plot_ink[0], px_plot_ink[1], px_plot_ink[2]);
    px_draw_text(cr, best_x + 0.6 * fs + line + 0.5 * fs, y, p->series[k].name, 0.0, 0.5);
    ++i;
  }
}

enum px_status px_plot_write_png(struct px_plot *p, const char *path) {
  cairo_surface_t *surface;
  cairo_t *cr;
  enum px_status st;
  if (!p || !path) return PX_STATUS_INVALID;
  surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, p->width, p->height);
  cr = cairo_create(surface);
  st = px_draw_check(p->ctx, cr, "creating the plot");
  if (st == PX_STATUS_OK) st = px_plot_layout(p, cr);
  if (st == PX_STATUS_OK) {
    cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
    cairo_paint(cr);
    px_plot_draw_axes(p, cr);
    px_plot_draw_series(p, cr);
    px_plot_draw_legend(p, cr);
    st = px_draw_check(p->ctx, cr, "drawing the plot");
    if (st != PX_STATUS_OK) px_context_prefix(p->ctx, "plot %s", path);
  } else {
    px_context_prefix(p->ctx, "plot %s", path);
  }
  cairo_destroy(cr);
  if (st == PX_STATUS_OK) st = px_draw_write_png(p->ctx, surface, path);
  cairo_surface_destroy(surface);
  return st;
}
