/* Internal queries on figures and plots (used by tests to find where things
 * were drawn). Not installed. */
#ifndef PX_IO_FIGURE_IMPL_H
#define PX_IO_FIGURE_IMPL_H

#include "partix/figure.h"

/* Frame (plot area) and colour bar of the current layout, as pixel rectangles
 * {x0, y0, x1, y1}; colorbar is all zero when the picture has no colour bar. */
enum px_status px_figure_layout_rects(struct px_figure *fig, double frame[4], double colorbar[4]);
/* Colour scale range of the current layout (after automatic ranging). */
enum px_status px_figure_layout_range(struct px_figure *fig, double *vmin, double *vmax);
/* Frame (plot area) of a line plot, {x0, y0, x1, y1} in pixels. */
enum px_status px_plot_layout_frame(struct px_plot *plot, double frame[4]);

#endif
