/* Internal queries on figures and plots (used by tests to find where things
 * were drawn), and the private layout of figures. Not installed. */
#ifndef PX_IO_FIGURE_IMPL_H
#define PX_IO_FIGURE_IMPL_H

#include <cairo.h>
#include <stddef.h>

#include "io/draw.h"
#include "partix/figure.h"

/* Frame (plot area) and colour bar of the current layout, as pixel rectangles
 * {x0, y0, x1, y1}; colorbar is all zero when the picture has no colour bar. */
enum px_status px_figure_layout_rects(struct px_figure *fig, double frame[4], double colorbar[4]);
/* Colour scale range of the current layout (after automatic ranging). */
enum px_status px_figure_layout_range(struct px_figure *fig, double *vmin, double *vmax);
/* Frame (plot area) of a line plot, {x0, y0, x1, y1} in pixels. */
enum px_status px_plot_layout_frame(struct px_plot *plot, double frame[4]);

/* ---- Private layout of snapshot pictures (figure.c: the figure and its
 * layers; figure_layout.c: where everything goes; figure_draw.c: drawing) */

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

static inline double px_fig_get(enum px_dtype t, const void *p, size_t i) {
  return t == PX_DTYPE_F32 ? (double)((const float *)p)[i] : ((const double *)p)[i];
}

static inline void px_fig_to_pixel(const struct px_fig_layout *L, double x, double y, double *px,
                                   double *py) {
  *px = L->frame[0] + (x - L->world[0]) * L->scale;
  *py = L->frame[3] - (y - L->world[2]) * L->scale;
}

/* figure_layout.c */
/* Lay the figure out for drawing with cr (text sizes): fig->L. */
enum px_status px_fig_layout(struct px_figure *fig, cairo_t *cr);
void px_fig_time_label(const struct px_figure *fig, char *buf, size_t size);
void px_fig_cbar_labels(const struct px_fig_layout *L, char lab[3][64]);
void px_fig_field_label(const struct px_figure *fig, char *buf, size_t size);
/* Widest of the n tick labels t (pixels); *maxabs_out: largest |t|. */
double px_fig_max_label_width(cairo_t *cr, const double *t, int n, double step, double *maxabs_out);

#endif
