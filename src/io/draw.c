#include "io/draw.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "partix/file.h"

void px_draw_font(cairo_t *cr, double size, int bold) {
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
}

double px_draw_text_width(cairo_t *cr, const char *s) {
  cairo_text_extents_t te;
  cairo_text_extents(cr, s, &te);
  return te.x_advance;
}

double px_draw_cap_height(cairo_t *cr) {
  cairo_text_extents_t te;
  cairo_text_extents(cr, "0H", &te);
  return -te.y_bearing;
}

void px_draw_text(cairo_t *cr, double x, double y, const char *s, double ax, double ay) {
  double w = px_draw_text_width(cr, s), cap = px_draw_cap_height(cr);
  /* baseline: ay = 0 -> y + cap, 0.5 -> y + cap/2, 1 -> y */
  cairo_move_to(cr, x - ax * w, y + cap * (1.0 - ay));
  cairo_show_text(cr, s);
}

void px_draw_text_vertical(cairo_t *cr, double x, double y, const char *s) {
  double w = px_draw_text_width(cr, s), cap = px_draw_cap_height(cr);
  cairo_save(cr);
  cairo_translate(cr, x, y);
  cairo_rotate(cr, -0.5 * 3.14159265358979323846);
  cairo_move_to(cr, -0.5 * w, 0.5 * cap);
  cairo_show_text(cr, s);
  cairo_restore(cr);
}

int px_draw_nice_ticks(double lo, double hi, int target, double ticks[PX_DRAW_MAX_TICKS],
                       double *step_out) {
  double raw, mag, norm, step;
  long k, k0, k1;
  int n = 0;
  if (!(hi > lo) || !isfinite(lo) || !isfinite(hi)) {
    *step_out = 1.0;
    return 0;
  }
  if (target < 1) target = 1;
  raw = (hi - lo) / target;
  mag = pow(10.0, floor(log10(raw)));
  norm = raw / mag;
  /* the smallest 1-2-5 step giving at most about `target` intervals */
  step = norm <= 1.0 + 1e-9 ? 1.0 : norm <= 2.0 + 1e-9 ? 2.0 : norm <= 5.0 + 1e-9 ? 5.0 : 10.0;
  step *= mag;
  k0 = (long)ceil(lo / step - 1e-9);
  k1 = (long)floor(hi / step + 1e-9);
  for (k = k0; k <= k1 && n < PX_DRAW_MAX_TICKS; ++k) ticks[n++] = (double)k * step;
  *step_out = step;
  return n;
}

static void px_draw_no_minus_zero(char *buf) {
  /* "-0", "-0.00", "-0e3" -> drop the sign */
  const char *p = buf + 1;
  if (buf[0] != '-') return;
  while (*p == '0' || *p == '.') ++p;
  if (*p == '\0' || *p == 'e') memmove(buf, buf + 1, strlen(buf));
}

void px_draw_format_tick(double value, double step, double maxabs, char *buf, size_t size) {
  int lstep = (int)floor(log10(step) + 1e-9);
  if (fabs(value) < 1e-9 * step) value = 0.0;
  if (maxabs >= 1e5 || maxabs < 1e-3) {
    /* m e E with just enough mantissa decimals for the step */
    int e = maxabs > 0 ? (int)floor(log10(maxabs) + 1e-12) : 0;
    int dec = e - lstep;
    if (value == 0.0) {
      snprintf(buf, size, "0");
      return;
    }
    if (dec < 0) dec = 0;
    snprintf(buf, size, "%.*fe%d", dec, value / pow(10.0, e), e);
  } else {
    int dec = lstep < 0 ? -lstep : 0;
    snprintf(buf, size, "%.*f", dec, value);
  }
  px_draw_no_minus_zero(buf);
}

void px_draw_format_value(double value, int digits, char *buf, size_t size) {
  if (value == 0.0) value = 0.0;
  snprintf(buf, size, "%.*g", digits, value);
  px_draw_no_minus_zero(buf);
}

enum px_status px_draw_check(struct px_context *ctx, cairo_t *cr, const char *what) {
  cairo_status_t st = cairo_status(cr);
  if (st == CAIRO_STATUS_SUCCESS) return PX_STATUS_OK;
  return px_context_fail(ctx, st == CAIRO_STATUS_NO_MEMORY ? PX_STATUS_NOMEM : PX_STATUS_INTERNAL,
                         "cairo failed while %s: %s", what, cairo_status_to_string(st));
}

enum px_status px_draw_check_surface(struct px_context *ctx, cairo_surface_t *s, const char *what) {
  cairo_status_t st = cairo_surface_status(s);
  if (st == CAIRO_STATUS_SUCCESS) return PX_STATUS_OK;
  return px_context_fail(ctx, st == CAIRO_STATUS_NO_MEMORY ? PX_STATUS_NOMEM : PX_STATUS_INTERNAL,
                         "cairo failed while %s: %s", what, cairo_status_to_string(st));
}

struct px_draw_sink {
  FILE *f;
  int err; /* errno of the first failed write */
};

static cairo_status_t px_draw_png_sink(void *closure, const unsigned char *data,
                                       unsigned int length) {
  struct px_draw_sink *sink = closure;
  if (fwrite(data, 1, length, sink->f) != length) {
    if (!sink->err) sink->err = errno ? errno : EIO;
    return CAIRO_STATUS_WRITE_ERROR;
  }
  return CAIRO_STATUS_SUCCESS;
}

enum px_status px_draw_write_png(struct px_context *ctx, cairo_surface_t *surface,
                                 const char *path) {
  struct px_file *file;
  struct px_draw_sink sink;
  cairo_status_t st;
  PX_TRY(px_draw_check_surface(ctx, surface, "drawing"));
  PX_TRY(px_file_open(ctx, path, &file));
  sink.f = px_file_stream(file);
  sink.err = 0;
  cairo_surface_flush(surface);
  st = cairo_surface_write_to_png_stream(surface, px_draw_png_sink, &sink);
  if (st != CAIRO_STATUS_SUCCESS) {
    enum px_status s;
    if (sink.err)
      s = px_context_fail(ctx, PX_STATUS_IO,
                          "cannot write %s: %s (the previous file, if any, is kept)", path,
                          strerror(sink.err));
    else
      s = px_context_fail(ctx, st == CAIRO_STATUS_NO_MEMORY ? PX_STATUS_NOMEM : PX_STATUS_IO,
                          "cannot encode %s as PNG: %s", path, cairo_status_to_string(st));
    px_file_abort(file);
    return s;
  }
  return px_file_commit(file);
}
