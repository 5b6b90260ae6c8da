/* PNG pictures drawn by partix itself (cairo, antialiased):
 *
 * - snapshots (struct px_figure): particles, contours, bodies and raster
 *   fields in world coordinates with equal aspect, coloured by one scalar
 *   through a colormap, with a colour bar, time label, title and axes ticks;
 * - line plots (struct px_plot): time series (force coefficients, energies)
 *   with nice ticks, grid, legend and colour-blind-safe colours.
 *
 * Both are builders: set things up, add layers/series, then write the PNG
 * atomically (file.h). Snapshot layer data is BORROWED until the next
 * px_figure_write_png or px_figure_reset; plot series are copied. Coordinate
 * and value arrays of snapshots are F32 or F64. */
#ifndef PARTIX_FIGURE_H
#define PARTIX_FIGURE_H

#include <stddef.h>

#include "partix/colormap.h"
#include "partix/context.h"
#include "partix/export.h"
#include "partix/types.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_figure;
struct px_plot;

/* ==== Snapshots ========================================================== */

/* A width x height pixel picture (16 .. 16384 each). */
PX_API enum px_status px_figure_create(struct px_context *ctx, int width, int height,
                                       struct px_figure **out);
/* NULL-safe. */
PX_API void px_figure_free(struct px_figure *fig);
/* Remove all layers (for the next frame); every setting is kept. */
PX_API void px_figure_reset(struct px_figure *fig);

/* View: the world rectangle to show. It is widened along one axis to fill
 * the plot area with equal aspect (1 world unit = same pixels in x and y). */
PX_API void px_figure_set_view(struct px_figure *fig, double xmin, double xmax, double ymin,
                               double ymax);
/* Automatic view (the default): the bounds of all layers plus `margin` (a
 * fraction of the larger extent on each side, default 0.05). */
PX_API void px_figure_fit_view(struct px_figure *fig, double margin);
/* Pixel position (x right, y down, origin top-left) of world point (x, y)
 * in the picture that px_figure_write_png would draw now. */
PX_API enum px_status px_figure_world_to_pixel(struct px_figure *fig, double x, double y,
                                               double *px, double *py);

/* Colour scale shared by all layers with values. Range: vmin < vmax, or NaN
 * for both = automatic (data min..max; symmetric -m..m for a diverging map). */
PX_API void px_figure_set_colormap(struct px_figure *fig, enum px_colormap map);
PX_API void px_figure_set_range(struct px_figure *fig, double vmin, double vmax);
/* Colour bar label: field name and unit ("Γ", "m²/s"); copied. */
PX_API void px_figure_set_field(struct px_figure *fig, const char *name, const char *unit);

/* Labels (copied; NULL or "" removes). The time label reads "t = 1.234 s";
 * a NaN time hides it. */
PX_API void px_figure_set_title(struct px_figure *fig, const char *title);
PX_API void px_figure_set_time(struct px_figure *fig, double t, const char *unit);
PX_API void px_figure_set_axis_labels(struct px_figure *fig, const char *xlabel,
                                      const char *ylabel);
/* Components in [0, 1]; default white. */
PX_API void px_figure_set_background(struct px_figure *fig, double r, double g, double b);

/* Style of the layers added after the call: line colour (and the colour of
 * particles without values), fill colour of filled polylines, line width. */
PX_API void px_figure_set_color(struct px_figure *fig, double r, double g, double b);
PX_API void px_figure_set_fill(struct px_figure *fig, double r, double g, double b);
PX_API void px_figure_set_line_width(struct px_figure *fig, double pixels);

/* Particles as filled discs of world radius radius[i] (radius == NULL: r0
 * for all), coloured by values[i] through the scale (values == NULL: the
 * line colour; NaN: grey). Discs smaller than one pixel are drawn 1 px wide. */
PX_API enum px_status px_figure_add_discs(struct px_figure *fig, enum px_dtype dtype, size_t n,
                                          const void *x, const void *y, const void *radius,
                                          double r0, const void *values);
/* A point cloud (e.g. 50k vortices): dots of `diameter` pixels whatever the
 * zoom, coloured as px_figure_add_discs. */
PX_API enum px_status px_figure_add_points(struct px_figure *fig, enum px_dtype dtype, size_t n,
                                           const void *x, const void *y, const void *values,
                                           double diameter);

enum px_figure_line {
  PX_FIGURE_LINE_OPEN = 0,
  PX_FIGURE_LINE_CLOSED = 1,
  PX_FIGURE_LINE_FILLED = 2 /* closed, filled with the fill colour, outlined */
};
/* A polyline through n points (a contour, a body, a boundary). */
PX_API enum px_status px_figure_add_polyline(struct px_figure *fig, enum px_dtype dtype, size_t n,
                                             const void *x, const void *y,
                                             enum px_figure_line mode);
/* A polyline whose segment i (point i to i+1; for closed, also n-1 to 0) is
 * coloured by values[i] through the scale: n-1 values, or n when closed. */
PX_API enum px_status px_figure_add_polyline_values(struct px_figure *fig, enum px_dtype dtype,
                                                    size_t n, const void *x, const void *y,
                                                    int closed, const void *values);
/* A scalar field on nx x ny cells covering [xmin, xmax] x [ymin, ymax]:
 * values[j*nx + i] is cell (i, j), i along x, j along y (row 0 at ymin).
 * NaN cells (e.g. inside a body) are grey. */
PX_API enum px_status px_figure_add_raster(struct px_figure *fig, enum px_dtype dtype, size_t nx,
                                           size_t ny, const void *values, double xmin, double xmax,
                                           double ymin, double ymax);

/* Annotations, drawn above every layer in the line colour (with a white
 * halo) and never moving the automatic view: a marker (a ring with a cross)
 * at world point (x, y), e.g. where a field has its maximum; an arrow from
 * (x0, y0) to its head at (x1, y1), e.g. the direction of an arc length.
 * `label` (copied; NULL or "" none) is written beside the marker or the
 * arrow's tail, on the side that keeps it inside the frame. */
PX_API enum px_status px_figure_add_marker(struct px_figure *fig, double x, double y,
                                           const char *label);
PX_API enum px_status px_figure_add_arrow(struct px_figure *fig, double x0, double y0, double x1,
                                          double y1, const char *label);

/* Draw and write the PNG (atomic). */
PX_API enum px_status px_figure_write_png(struct px_figure *fig, const char *path);

/* ==== Line plots ========================================================= */

PX_API enum px_status px_plot_create(struct px_context *ctx, int width, int height,
                                     struct px_plot **out);
/* NULL-safe. */
PX_API void px_plot_free(struct px_plot *plot);
/* Labels with units, e.g. "t [s]", "C_x [-]" (copied; NULL removes). */
PX_API void px_plot_set_title(struct px_plot *plot, const char *title);
PX_API void px_plot_set_labels(struct px_plot *plot, const char *xlabel, const char *ylabel);
/* Axis ranges; NaN for both = automatic (x: data range; y: data range
 * plus 5 %). */
PX_API void px_plot_set_xrange(struct px_plot *plot, double min, double max);
PX_API void px_plot_set_yrange(struct px_plot *plot, double min, double max);
/* Logarithmic y axis (values <= 0 are left out). */
PX_API void px_plot_set_log_y(struct px_plot *plot, int on);
/* A filled disc (the series colour) at every data point, also in the
 * legend: for series of few points (a sweep's values), whose line alone
 * hides where the samples are. */
PX_API void px_plot_set_markers(struct px_plot *plot, int on);
/* Add a series of n (x, y) points (copied; NaN breaks the line). Series get
 * the colours of the Okabe-Ito palette in order. */
PX_API enum px_status px_plot_add_series(struct px_plot *plot, const char *name, size_t n,
                                         const double *x, const double *y);
/* sRGB colour of series i (0-based). */
PX_API void px_plot_series_color(size_t i, double rgb[3]);
/* Pixel position of data point (x, y) in the picture px_plot_write_png would
 * draw now. */
PX_API enum px_status px_plot_data_to_pixel(struct px_plot *plot, double x, double y, double *px,
                                            double *py);
PX_API enum px_status px_plot_write_png(struct px_plot *plot, const char *path);

#ifdef __cplusplus
}
#endif
#endif
