/* Pictures of the granular solver (output.png_every, and at the end of a
 * run): the particles coloured by speed, spin, contacts or id with the
 * contours where they are; the contours coloured by a segment quantity; the
 * quantity along each reported contour; the time series of the media. The
 * files are listed in docs/granular.md. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "partix/csv.h"
#include "partix/figure.h"
#include "partix/file.h"
#include "partix/memory.h"
#include "partix/vtk.h"
#include "solvers/granular/granular_impl.h"
#include "solvers/granular/wall_kernel.h"

#include "solvers/granular/granular_output.h"

#define PX_GRAN_OUT_PI 3.14159265358979323846

/* ------------------------------------------------------------------ pictures */

/* Draw the contours (parts filled) into fig, where they are now (world) or
 * in their body frame. The figure borrows the point arrays until it is
 * drawn: they are kept in r->fig_x, r->fig_y (freed by the caller). */
static enum px_status px_gran_draw_contours(struct px_gran_run *r, struct px_figure *fig,
                                            int world) {
  const struct px_gran_geom *g = &r->geom;
  double *x = px_mem_alloc(r->ctx, "granular output", (g->nseg ? g->nseg : 1) * sizeof *x);
  double *y = px_mem_alloc(r->ctx, "granular output", (g->nseg ? g->nseg : 1) * sizeof *y);
  size_t c, k;
  enum px_status st = PX_STATUS_OK;
  if (!x || !y) {
    px_mem_free(r->ctx, x);
    px_mem_free(r->ctx, y);
    return PX_STATUS_NOMEM;
  }
  for (c = 0; c < g->ncontours; ++c) {
    const struct px_gran_contour *C = &g->contours[c];
    for (k = C->first; k < C->first + C->count; ++k) {
      if (world)
        px_gran_world(r, c, k, &x[k], &y[k]);
      else
        x[k] = g->ax[k], y[k] = g->ay[k];
    }
  }
  px_figure_set_line_width(fig, 1.5);
  px_figure_set_color(fig, 0.15, 0.15, 0.15);
  /* filled solids (media outside) first, then outlines of the containers */
  for (c = 0; c < g->ncontours && st == PX_STATUS_OK; ++c) {
    const struct px_gran_contour *C = &g->contours[c];
    if (C->media_inside) continue;
    px_figure_set_fill(fig, 0.72, 0.74, 0.78);
    st = px_figure_add_polyline(fig, PX_DTYPE_F64, C->count, x + C->first, y + C->first,
                                PX_FIGURE_LINE_FILLED);
  }
  for (c = 0; c < g->ncontours && st == PX_STATUS_OK; ++c) {
    const struct px_gran_contour *C = &g->contours[c];
    if (!C->media_inside) continue;
    st = px_figure_add_polyline(fig, PX_DTYPE_F64, C->count, x + C->first, y + C->first,
                                PX_FIGURE_LINE_CLOSED);
  }
  px_figure_set_line_width(fig, 1.0);
  r->fig_x = x;
  r->fig_y = y;
  return st;
}

enum px_status px_gran_out_picture(struct px_gran_run *r, const struct px_sim_output *o) {
  struct px_gran_sys *s = r->sys;
  const size_t n = s->n;
  struct px_figure *fig = NULL;
  double *buf;
  char name[64], path[1024], title[256];
  enum px_status st;
  static const char *const fields[4] = {"speed", "spin", "contacts", "id"};
  static const char *const units[4] = {"m/s", "rad/s", "-", "-"};
  px_gran_resume_tidy(r, o);
  buf = px_mem_alloc(r->ctx, "granular output", 6 * (n ? n : 1) * sizeof *buf);
  if (!buf) return PX_STATUS_NOMEM;
  {
    double *x = buf, *y = buf + n, *vx = buf + 2 * n, *vy = buf + 3 * n, *rad = buf + 4 * n;
    double *val = buf + 5 * n, *w = vx, vmax = 0;
    size_t i;
    if (r->color == 1)
      px_gran_sys_export(s, x, y, NULL, NULL, w, rad, NULL, NULL);
    else
      px_gran_sys_export(s, x, y, vx, vy, NULL, rad, NULL, r->color == 3 ? val : NULL);
    if (r->color == 0)
      for (i = 0; i < n; ++i) val[i] = hypot(vx[i], vy[i]);
    else if (r->color == 1)
      for (i = 0; i < n; ++i) val[i] = w[i];
    else if (r->color == 2)
      px_gran_sys_coordination(s, x, y, rad, val);
    for (i = 0; i < n; ++i)
      if (fabs(val[i]) > vmax) vmax = fabs(val[i]);
    st = px_figure_create(r->ctx, r->width, r->height, &fig);
    if (st == PX_STATUS_OK) {
      const char *t = NULL;
      if (px_case_has(r->c, "title")) px_case_get_string(r->c, "title", &t);
      snprintf(title, sizeof title, "%s%s%zu disc%s", t ? t : "", t ? " - " : "", n,
               n == 1 ? "" : "s");
      px_figure_set_title(fig, title);
      px_figure_set_time(fig, o->time, "s");
      px_figure_set_colormap(fig, r->color == 1 ? PX_COLORMAP_COOLWARM : PX_COLORMAP_VIRIDIS);
      /* speeds, contact counts and ids start at 0 (a scale from the data
       * alone would put discs at rest in mid-scale); spin is symmetric */
      if (r->range > 0) {
        px_figure_set_range(fig, r->color == 1 ? -r->range : 0, r->range);
      } else if (r->color == 1) {
        if (!(vmax > 0)) px_figure_set_range(fig, -1, 1);
      } else if (r->color == 0) {
        px_figure_set_range(fig, 0, vmax > 0 ? vmax : r->speed_max);
      } else {
        px_figure_set_range(fig, 0, vmax > 0 ? vmax : 1);
      }
      px_figure_set_field(fig, fields[r->color], units[r->color]);
      px_figure_set_axis_labels(fig, "x [m]", "y [m]");
      st = px_gran_draw_contours(r, fig, 1);
    }
    if (st == PX_STATUS_OK) st = px_figure_add_discs(fig, PX_DTYPE_F64, n, x, y, rad, 0, val);
    if (st == PX_STATUS_OK) {
      snprintf(name, sizeof name, "particles_%08ld.png", o->step);
      st = px_file_join(r->ctx, path, sizeof path, o->dir, name);
    }
    if (st == PX_STATUS_OK) st = px_figure_write_png(fig, path);
  }
  px_figure_free(fig);
  px_mem_free(r->ctx, r->fig_x);
  px_mem_free(r->ctx, r->fig_y);
  r->fig_x = r->fig_y = NULL;
  px_mem_free(r->ctx, buf);
  return st;
}

/* Signed area of contour c in its body frame [m^2]: > 0 when it runs
 * counter-clockwise (shoelace formula). */
static double px_gran_contour_area(const struct px_gran_run *r, size_t c) {
  const struct px_gran_geom *g = &r->geom;
  const struct px_gran_contour *C = &g->contours[c];
  double a = 0;
  size_t k;
  for (k = 0; k < C->count; ++k) {
    const size_t i = C->first + k, j = C->first + (k + 1) % C->count;
    a += g->ax[i] * g->ay[j] - g->ax[j] * g->ay[i];
  }
  return 0.5 * a;
}

/* Mark where s = 0 is on contour c (a ring, labelled with the contour's name
 * when several are drawn) and which way s runs (an arrow along the first
 * segment, beside the contour on the media side). `size`: the extent of the
 * view [m]. */
static enum px_status px_gran_mark_s(struct px_gran_run *r, struct px_figure *fig, size_t c,
                                     double size, int named) {
  const struct px_gran_geom *g = &r->geom;
  const struct px_gran_contour *C = &g->contours[c];
  const size_t s0 = C->first;
  const double off = 0.025 * size; /* beside the contour, into the media [m] */
  const double len = fmin(0.06 * size, 0.25 * C->length); /* arrow length [m] */
  const double x0 = g->ax[s0] - off * g->ty[s0], y0 = g->ay[s0] + off * g->tx[s0];
  PX_TRY(px_figure_add_marker(fig, g->ax[s0], g->ay[s0], named ? C->name : "s = 0"));
  return px_figure_add_arrow(fig, x0, y0, x0 + len * g->tx[s0], y0 + len * g->ty[s0], NULL);
}

/* The reported contours (body frame) coloured by quantity q, on one colour
 * scale, solids filled, with s = 0 and the direction of s marked. */
enum px_status px_gran_contours_png(struct px_gran_run *r, int q, const char *dir, double t) {
  const struct px_gran_geom *g = &r->geom;
  struct px_figure *fig = NULL;
  double **vals = px_mem_calloc(r->ctx, "granular output", g->ncontours, sizeof *vals);
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  char name[200], path[1024], title[256];
  size_t c, nrep = 0;
  enum px_status st = PX_STATUS_OK;
  if (!vals) return PX_STATUS_NOMEM;
  for (c = 0; c < g->ncontours && st == PX_STATUS_OK; ++c) {
    const struct px_gran_contour *C = &g->contours[c];
    double **cols;
    if (!r->report[c]) continue;
    cols = px_gran_cols_alloc(r->ctx, C->count);
    if (!cols) {
      st = PX_STATUS_NOMEM;
      break;
    }
    px_gran_seg_table(r, c, t, cols);
    vals[c] = cols[q];
    cols[q] = NULL;
    px_gran_cols_free(r->ctx, cols);
    xmin = fmin(xmin, C->xmin), xmax = fmax(xmax, C->xmax);
    ymin = fmin(ymin, C->ymin), ymax = fmax(ymax, C->ymax);
    ++nrep;
  }
  if (st == PX_STATUS_OK && xmax >= xmin) st = px_figure_create(r->ctx, r->width, r->height, &fig);
  if (st == PX_STATUS_OK && fig) {
    const double size = fmax(xmax - xmin, ymax - ymin), mx = 0.08 * size;
    const char *unit = px_gran_seg_unit(r, q);
    if (t >= r->sspec.start)
      snprintf(title, sizeof title, "%s [%s] over %.4g s", px_gran_seg_names[q], unit,
               t - r->sspec.start);
    else
      snprintf(title, sizeof title, "%s [%s] (statistics from t = %.4g s)", px_gran_seg_names[q],
               unit, r->sspec.start);
    px_figure_set_title(fig, title);
    px_figure_set_time(fig, t, "s");
    px_figure_set_colormap(fig, PX_COLORMAP_INFERNO);
    px_figure_set_field(fig, px_gran_seg_names[q], unit);
    px_figure_set_axis_labels(fig, "x [m] (body frame; ring: s = 0, arrow: direction of s)",
                              "y [m]");
    px_figure_set_view(fig, xmin - mx, xmax + mx, ymin - mx, ymax + mx);
    /* solids in light grey, holes white, then the coloured contours */
    px_figure_set_line_width(fig, 0.5);
    for (c = 0; c < g->ncontours && st == PX_STATUS_OK; ++c) {
      const struct px_gran_contour *C = &g->contours[c];
      if (!r->report[c]) continue;
      if (C->media_inside)
        px_figure_set_fill(fig, 1, 1, 1);
      else
        px_figure_set_fill(fig, 0.85, 0.86, 0.88);
      st = px_figure_add_polyline(fig, PX_DTYPE_F64, C->count, g->ax + C->first, g->ay + C->first,
                                  PX_FIGURE_LINE_FILLED);
    }
    px_figure_set_line_width(fig, 6.0);
    for (c = 0; c < g->ncontours && st == PX_STATUS_OK; ++c) {
      const struct px_gran_contour *C = &g->contours[c];
      if (!r->report[c]) continue;
      st = px_figure_add_polyline_values(fig, PX_DTYPE_F64, C->count, g->ax + C->first,
                                         g->ay + C->first, 1, vals[c]);
    }
    px_figure_set_line_width(fig, 1.5);
    px_figure_set_color(fig, 0.1, 0.35, 0.8);
    for (c = 0; c < g->ncontours && st == PX_STATUS_OK; ++c)
      if (r->report[c]) st = px_gran_mark_s(r, fig, c, size, nrep > 1);
    if (st == PX_STATUS_OK) {
      snprintf(name, sizeof name, "contours_%s.png", px_gran_seg_names[q]);
      st = px_file_join(r->ctx, path, sizeof path, dir, name);
    }
    if (st == PX_STATUS_OK) st = px_figure_write_png(fig, path);
  }
  px_figure_free(fig);
  for (c = 0; c < g->ncontours; ++c) px_mem_free(r->ctx, vals[c]);
  px_mem_free(r->ctx, vals);
  return st;
}

/* Quantity q along contour c (against the arc length s). */
enum px_status px_gran_profile_png(struct px_gran_run *r, size_t c, int q, const char *dir,
                                   double t) {
  const struct px_gran_contour *C = &r->geom.contours[c];
  const size_t s0 = C->first;
  double **cols = px_gran_cols_alloc(r->ctx, C->count);
  struct px_plot *p = NULL;
  char name[200], path[1024], title[256], ylab[96], xlab[256];
  enum px_status st;
  if (!cols) return PX_STATUS_NOMEM;
  px_gran_seg_table(r, c, t, cols);
  st = px_plot_create(r->ctx, 1200, 500, &p);
  if (st == PX_STATUS_OK) {
    if (t >= r->sspec.start)
      snprintf(title, sizeof title, "%s along %s over %.4g s", px_gran_seg_names[q], C->name,
               t - r->sspec.start);
    else
      snprintf(title, sizeof title, "%s along %s (statistics from t = %.4g s)",
               px_gran_seg_names[q], C->name, r->sspec.start);
    snprintf(ylab, sizeof ylab, "%s [%s]", px_gran_seg_names[q], px_gran_seg_unit(r, q));
    snprintf(xlab, sizeof xlab, "s [m] along %s: from (%.4g, %.4g) m (body frame), %s", C->name,
             r->geom.ax[s0], r->geom.ay[s0],
             px_gran_contour_area(r, c) > 0 ? "counter-clockwise" : "clockwise");
    px_plot_set_title(p, title);
    px_plot_set_labels(p, xlab, ylab);
    px_plot_set_xrange(p, 0, C->length);
    {
      /* a quantity of one sign from 0 (the automatic range of a contour not
       * hit yet would be -0.5..0.5) */
      double lo = 0, hi = 0;
      size_t k;
      for (k = 0; k < C->count; ++k) lo = fmin(lo, cols[q][k]), hi = fmax(hi, cols[q][k]);
      if (lo >= 0)
        px_plot_set_yrange(p, 0, hi > 0 ? 1.05 * hi : 1);
      else if (hi <= 0)
        px_plot_set_yrange(p, 1.05 * lo, 0);
    }
    st = px_plot_add_series(p, px_gran_seg_names[q], C->count, cols[PX_GRAN_SEG_S], cols[q]);
  }
  if (st == PX_STATUS_OK) {
    snprintf(name, sizeof name, "%s_%s.png", C->name, px_gran_seg_names[q]);
    st = px_file_join(r->ctx, path, sizeof path, dir, name);
  }
  if (st == PX_STATUS_OK) st = px_plot_write_png(p, path);
  px_plot_free(p);
  px_gran_cols_free(r->ctx, cols);
  return st;
}

/* Column col of the run's rows against time. */
enum px_status px_gran_plot(struct px_gran_run *r, const char *dir, const char *file,
                            const char *title, const char *ylabel, const double *rows, size_t n,
                            size_t col) {
  struct px_plot *p = NULL;
  char path[1024];
  double *t, *y;
  size_t i;
  enum px_status st;
  if (n < 2) return PX_STATUS_OK;
  t = px_mem_alloc(r->ctx, "granular output", 2 * n * sizeof *t);
  if (!t) return PX_STATUS_NOMEM;
  y = t + n;
  for (i = 0; i < n; ++i) {
    t[i] = rows[i * PX_GRAN_PLOT_NCOL + PX_GRAN_PLOT_T];
    y[i] = rows[i * PX_GRAN_PLOT_NCOL + col];
  }
  st = px_plot_create(r->ctx, 1000, 600, &p);
  if (st == PX_STATUS_OK) {
    px_plot_set_title(p, title);
    px_plot_set_labels(p, "t [s]", ylabel);
    st = px_plot_add_series(p, ylabel, n, t, y);
  }
  if (st == PX_STATUS_OK) st = px_file_join(r->ctx, path, sizeof path, dir, file);
  if (st == PX_STATUS_OK) st = px_plot_write_png(p, path);
  px_plot_free(p);
  px_mem_free(r->ctx, t);
  return st;
}
