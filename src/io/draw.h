/* Drawing helpers shared by snapshots (figure.c) and line plots (plot.c):
 * text placement, "nice" axis ticks, tick labels, cairo error checks and
 * atomic PNG output. Internal; not installed. */
#ifndef PX_IO_DRAW_H
#define PX_IO_DRAW_H

#include <cairo.h>
#include <stddef.h>

#include "partix/context.h"

#define PX_DRAW_MAX_TICKS 32

/* Select the UI font ("DejaVu Sans", falling back to cairo's sans-serif)
 * at `size` pixels. */
void px_draw_font(cairo_t *cr, double size, int bold);
/* Width in pixels of s in the current font. */
double px_draw_text_width(cairo_t *cr, const char *s);
/* Draw s anchored at (x, y): ax = 0 left, 0.5 centre, 1 right; ay = 0 top,
 * 0.5 middle, 1 bottom of the digits/capitals (baseline = bottom). */
void px_draw_text(cairo_t *cr, double x, double y, const char *s, double ax, double ay);
/* The same, rotated by -90 degrees (reading bottom to top), centred at (x, y)
 * along the text and with its middle at x. */
void px_draw_text_vertical(cairo_t *cr, double x, double y, const char *s);
/* Height of capitals/digits in the current font (pixels). */
double px_draw_cap_height(cairo_t *cr);

/* Ticks at multiples of a 1-2-5 step inside [lo, hi], about `target` of them.
 * Returns the count (<= PX_DRAW_MAX_TICKS) and the step. */
int px_draw_nice_ticks(double lo, double hi, int target, double ticks[PX_DRAW_MAX_TICKS],
                       double *step);
/* Label for a tick value with as many decimals as the step needs ("0.25",
 * "-3", "1.5e6"); never "-0". */
void px_draw_format_tick(double value, double step, double maxabs, char *buf, size_t size);
/* Short label with `digits` significant digits (colour bar ticks); never "-0". */
void px_draw_format_value(double value, int digits, char *buf, size_t size);

/* Fail with a message naming `what` if the cairo context is in error. */
enum px_status px_draw_check(struct px_context *ctx, cairo_t *cr, const char *what);
enum px_status px_draw_check_surface(struct px_context *ctx, cairo_surface_t *s, const char *what);
/* Write the surface as PNG to `path` atomically (px_file). */
enum px_status px_draw_write_png(struct px_context *ctx, cairo_surface_t *surface,
                                 const char *path);

#endif
