/* Outputs of the granular solver (the files are listed, column by column,
 * in docs/granular.md):
 *  - snapshots (output.every): particles_NNNNNNNN.vtp (radius, velocity,
 *    speed, spin, contacts, id) and walls_NNNNNNNN.vtp (contours where they
 *    are, one line cell per segment with the impact statistics so far), with
 *    .pvd series; the segment tables as they stand;
 *  - series (output.log_every): media.csv (kinetic energy, centre of mass and
 *    its travel, coordination number, wall forces), speed_histogram.csv (one
 *    histogram per row) and, as impacts happen, impacts.csv;
 *  - pictures (output.png_every): particles_NNNNNNNN.png (granular_pictures.c);
 *  - at the end: segments_CONTOUR.csv along each reported contour,
 *    contours.vtp, contours_QUANTITY.png (the contours coloured by the chosen
 *    quantity), CONTOUR_QUANTITY.png (the quantity against s) and the time
 *    series of the media (kinetic_energy.png, com_height.png,
 *    coordination.png); `partix render` draws only these pictures;
 *  - the quantities of summary.json (px_gran_out_report).
 *
 * Outputs never change the run: the statistics are read through a view that
 * adds the contacts in progress (px_gran_out_view), and an end-of-run row off
 * the log schedule is not kept in the series state. So a run resumed from
 * any checkpoint leaves the same files as an uninterrupted one. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "partix/csv.h"
#include "partix/figure.h"
#include "partix/file.h"
#include "partix/memory.h"
#include "partix/vtk.h"
#include "solvers/granular/granular_impl.h"
#include "solvers/granular/granular_output.h"
#include "solvers/granular/wall_kernel.h"

#define PX_GRAN_OUT_PI 3.14159265358979323846

/* A time kept when a resumed run reopens a CSV: `t` widened by the rounding
 * of the CSV's 10 significant digits, so that a row written at exactly t
 * (printed up to 5e-10 relative above it) is kept [s]. Rows one step apart
 * differ by far more than this. */
static double px_gran_keep(double t) { return t + 1e-9 * fabs(t); }

/* Flags of the case's `output` section. */
static int px_gran_output_flag(const struct px_gran_run *r, const char *key) {
  int on = 1;
  if (px_case_get_bool(r->c, key, &on) != PX_STATUS_OK) on = 1;
  return on;
}

/* ------------------------------------------------------------ statistics */

enum px_status px_gran_out_view(struct px_gran_run *r) {
  const struct px_gran_sys *s = r->sys;
  const size_t ns = r->geom.nseg ? r->geom.nseg : 1;
  double *b;
  if (!r->view_buf) {
    r->view_buf = px_mem_alloc(r->ctx, "granular output", 4 * ns * sizeof *r->view_buf);
    if (!r->view_buf) return PX_STATUS_NOMEM;
  }
  b = r->view_buf;
  r->view = s->stats;
  memcpy(b, s->stats.impulse, ns * sizeof *b);
  memcpy(b + ns, s->stats.slide, ns * sizeof *b);
  memcpy(b + 2 * ns, s->stats.archard, ns * sizeof *b);
  memcpy(b + 3 * ns, s->stats.ctime, ns * sizeof *b);
  r->view.impulse = b;
  r->view.slide = b + ns;
  r->view.archard = b + 2 * ns;
  r->view.ctime = b + 3 * ns;
  px_gran_sys_stats_pending(s, r->view.impulse, r->view.slide, r->view.archard, r->view.ctime);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------ segment table */

static int px_gran_seg_column(const char *name) {
  int q;
  for (q = 0; q < PX_GRAN_SEG_NCOL; ++q)
    if (strcmp(px_gran_seg_names[q], name) == 0) return q;
  return -1;
}

/* The column of statistics.picture (energy_n_area, with a warning, when the
 * case names no column). */
static int px_gran_picture_column(struct px_gran_run *r) {
  const int q = px_gran_seg_column(r->picture_quantity);
  if (q >= 0) return q;
  px_log(r->ctx, PX_LOG_LEVEL_WARN,
         "granular.statistics.picture: no column '%s' in the segment table; using "
         "energy_n_area",
         r->picture_quantity);
  return PX_GRAN_SEG_EN_AREA;
}

/* segments_CONTOUR.csv from r->view. */
static enum px_status px_gran_segments_csv(struct px_gran_run *r, size_t c, const char *dir,
                                           double t) {
  const struct px_gran_contour *C = &r->geom.contours[c];
  double **cols = px_gran_cols_alloc(r->ctx, C->count);
  char name[160], path[1024], heads[PX_GRAN_SEG_NCOL][64];
  const char *names[PX_GRAN_SEG_NCOL];
  enum px_status st;
  int q;
  if (!cols) return PX_STATUS_NOMEM;
  px_gran_seg_table(r, c, t, cols);
  for (q = 0; q < PX_GRAN_SEG_NCOL; ++q) {
    snprintf(heads[q], sizeof heads[q], "%s [%s]", px_gran_seg_names[q], px_gran_seg_unit(r, q));
    names[q] = heads[q];
  }
  snprintf(name, sizeof name, "segments_%s.csv", C->name);
  st = px_file_join(r->ctx, path, sizeof path, dir, name);
  if (st == PX_STATUS_OK)
    st = px_csv_write_table(r->ctx, path, PX_GRAN_SEG_NCOL, names, C->count,
                            (const double *const *)cols, 10);
  px_gran_cols_free(r->ctx, cols);
  return st;
}

enum px_status px_gran_out_segments(struct px_gran_run *r, size_t c, const char *dir, double t) {
  PX_TRY(px_gran_out_view(r));
  return px_gran_segments_csv(r, c, dir, t);
}

/* All contours as .vtp: one 2-point line per segment, cell data = the
 * segment table (r->view). world: at the current frames (snapshots) or in
 * the body frame (end-of-run file). */
static enum px_status px_gran_walls_vtp(struct px_gran_run *r, const char *path, double t,
                                        long step, int world) {
  const struct px_gran_geom *g = &r->geom;
  const size_t ns = g->nseg;
  double *px = px_mem_alloc(r->ctx, "granular output", (ns ? ns : 1) * sizeof *px);
  double *py = px_mem_alloc(r->ctx, "granular output", (ns ? ns : 1) * sizeof *py);
  double *cid = px_mem_alloc(r->ctx, "granular output", (ns ? ns : 1) * sizeof *cid);
  double **cols = px_gran_cols_alloc(r->ctx, ns);
  double **tmp = NULL;
  enum px_status st = PX_STATUS_OK;
  size_t c, k;
  int q;
  if (!px || !py || !cid || !cols) {
    st = PX_STATUS_NOMEM;
    goto done;
  }
  if (!r->vtk) {
    st = px_vtk_create(r->ctx, &r->vtk);
    if (st != PX_STATUS_OK) goto done;
  }
  px_vtk_reset(r->vtk);
  for (c = 0; c < g->ncontours; ++c) {
    const struct px_gran_contour *C = &g->contours[c];
    tmp = px_gran_cols_alloc(r->ctx, C->count);
    if (!tmp) {
      st = PX_STATUS_NOMEM;
      goto done;
    }
    px_gran_seg_table(r, c, t, tmp);
    for (k = 0; k < C->count; ++k) {
      const size_t s = C->first + k;
      if (world)
        px_gran_world(r, c, s, &px[s], &py[s]);
      else
        px[s] = g->ax[s], py[s] = g->ay[s];
      cid[s] = (double)c;
      for (q = 0; q < PX_GRAN_SEG_NCOL; ++q) cols[q][s] = tmp[q][k];
    }
    px_gran_cols_free(r->ctx, tmp);
    tmp = NULL;
  }
  st = px_vtk_set_points(r->vtk, PX_DTYPE_F64, ns, px, py, NULL);
  for (c = 0; c < g->ncontours && st == PX_STATUS_OK; ++c)
    st = px_vtk_add_segments(r->vtk, g->contours[c].first, g->contours[c].count, 1);
  if (st == PX_STATUS_OK)
    st = px_vtk_add_scalar(r->vtk, PX_VTK_ASSOC_CELL, "contour", PX_DTYPE_F64, ns, cid);
  for (q = PX_GRAN_SEG_LEN; q < PX_GRAN_SEG_NCOL && st == PX_STATUS_OK; ++q)
    st = px_vtk_add_scalar(r->vtk, PX_VTK_ASSOC_CELL, px_gran_seg_names[q], PX_DTYPE_F64, ns,
                           cols[q]);
  if (st == PX_STATUS_OK)
    st = px_vtk_add_vector(r->vtk, PX_VTK_ASSOC_CELL, "normal", PX_DTYPE_F64, ns,
                           cols[PX_GRAN_SEG_NX], cols[PX_GRAN_SEG_NY], NULL);
  if (st == PX_STATUS_OK) {
    px_vtk_set_time(r->vtk, t, step);
    st = px_vtk_write(r->vtk, path);
  }
done:
  px_gran_cols_free(r->ctx, tmp);
  px_gran_cols_free(r->ctx, cols);
  px_mem_free(r->ctx, px);
  px_mem_free(r->ctx, py);
  px_mem_free(r->ctx, cid);
  return st;
}

/* ------------------------------------------------------------------ snapshot */

enum px_status px_gran_out_snapshot(struct px_gran_run *r, const struct px_sim_output *o) {
  struct px_gran_sys *s = r->sys;
  const size_t n = s->n;
  double *buf = NULL;
  char name[64], path[1024];
  enum px_status st = PX_STATUS_OK;
  if (o->render) return PX_STATUS_OK;
  px_gran_resume_tidy(r, o);
  if (!r->pvd_particles) {
    PX_TRY(px_file_join(r->ctx, path, sizeof path, o->dir, "particles.pvd"));
    PX_TRY(o->resumed ? px_vtk_series_open_resume(r->ctx, path, o->keep_snapshot, &r->pvd_particles)
                      : px_vtk_series_open(r->ctx, path, &r->pvd_particles));
    PX_TRY(px_file_join(r->ctx, path, sizeof path, o->dir, "walls.pvd"));
    PX_TRY(o->resumed ? px_vtk_series_open_resume(r->ctx, path, o->keep_snapshot, &r->pvd_walls)
                      : px_vtk_series_open(r->ctx, path, &r->pvd_walls));
  }
  buf = px_mem_alloc(r->ctx, "granular output", 10 * (n ? n : 1) * sizeof *buf);
  if (!buf) return PX_STATUS_NOMEM;
  {
    double *x = buf, *y = buf + n, *vx = buf + 2 * n, *vy = buf + 3 * n, *w = buf + 4 * n;
    double *rad = buf + 5 * n, *id = buf + 6 * n, *sp = buf + 7 * n, *z = buf + 8 * n;
    size_t i;
    px_gran_sys_export(s, x, y, vx, vy, w, rad, NULL, id);
    px_gran_sys_coordination(s, x, y, rad, z);
    for (i = 0; i < n; ++i) sp[i] = hypot(vx[i], vy[i]);
    if (!r->vtk) st = px_vtk_create(r->ctx, &r->vtk);
    if (st == PX_STATUS_OK) {
      px_vtk_reset(r->vtk);
      st = px_vtk_set_points(r->vtk, PX_DTYPE_F64, n, x, y, NULL);
    }
    if (st == PX_STATUS_OK) st = px_vtk_add_vertices(r->vtk);
    if (st == PX_STATUS_OK)
      st = px_vtk_add_scalar(r->vtk, PX_VTK_ASSOC_POINT, "radius", PX_DTYPE_F64, n, rad);
    if (st == PX_STATUS_OK)
      st = px_vtk_add_vector(r->vtk, PX_VTK_ASSOC_POINT, "velocity", PX_DTYPE_F64, n, vx, vy, NULL);
    if (st == PX_STATUS_OK)
      st = px_vtk_add_scalar(r->vtk, PX_VTK_ASSOC_POINT, "speed", PX_DTYPE_F64, n, sp);
    if (st == PX_STATUS_OK)
      st = px_vtk_add_scalar(r->vtk, PX_VTK_ASSOC_POINT, "spin", PX_DTYPE_F64, n, w);
    if (st == PX_STATUS_OK)
      st = px_vtk_add_scalar(r->vtk, PX_VTK_ASSOC_POINT, "contacts", PX_DTYPE_F64, n, z);
    if (st == PX_STATUS_OK)
      st = px_vtk_add_scalar(r->vtk, PX_VTK_ASSOC_POINT, "id", PX_DTYPE_F64, n, id);
    if (st == PX_STATUS_OK) {
      px_vtk_set_time(r->vtk, o->time, o->step);
      snprintf(name, sizeof name, "particles_%08ld.vtp", o->step);
      st = px_file_join(r->ctx, path, sizeof path, o->dir, name);
    }
    if (st == PX_STATUS_OK) st = px_vtk_write(r->vtk, path);
    if (st == PX_STATUS_OK) st = px_vtk_series_add(r->pvd_particles, o->time, name);
  }
  px_mem_free(r->ctx, buf);
  PX_TRY(st);
  PX_TRY(px_gran_out_view(r));
  snprintf(name, sizeof name, "walls_%08ld.vtp", o->step);
  PX_TRY(px_file_join(r->ctx, path, sizeof path, o->dir, name));
  PX_TRY(px_gran_walls_vtp(r, path, o->time, o->step, 1));
  PX_TRY(px_vtk_series_add(r->pvd_walls, o->time, name));
  /* the per-segment tables as they stand (the run may be stopped any time) */
  if (px_gran_output_flag(r, "output.csv")) {
    size_t c;
    for (c = 0; c < r->geom.ncontours; ++c)
      if (r->report[c]) PX_TRY(px_gran_segments_csv(r, c, o->dir, o->time));
  }
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------ series */

/* Every counted impact on a reported contour, as it is counted. */
static void px_gran_log_impact(void *user, int seg, int id, double t, double vn, double vt,
                               double m) {
  struct px_gran_run *r = user;
  const int c = r->geom.contour[seg];
  double row[9];
  if (!r->csv_impacts || !r->report[c]) return;
  row[0] = t;
  row[1] = c;
  row[2] = seg - (int)r->geom.contours[c].first;
  row[3] = id;
  row[4] = vn;
  row[5] = vt;
  row[6] = atan2(vn, fabs(vt)) * 180 / PX_GRAN_OUT_PI;
  row[7] = 0.5 * m * vn * vn;
  row[8] = 0.5 * m * vt * vt;
  px_csv_row(r->csv_impacts, row); /* a failed row is lost, the run goes on */
}

/* Open impacts.csv (an event CSV: a resumed run keeps the rows up to its
 * resume time). */
static enum px_status px_gran_impacts_open(struct px_gran_run *r, const char *dir, int resumed,
                                           double resume_time) {
  static const char *const in[9] = {"t [s]",        "contour [-]",  "segment [-]",
                                    "particle [-]", "vn [m/s]",     "vt [m/s]",
                                    "angle [deg]",  "energy_n [J]", "energy_t [J]"};
  char path[1024];
  if (r->csv_impacts || !r->impact_log) return PX_STATUS_OK;
  PX_TRY(px_file_join(r->ctx, path, sizeof path, dir, "impacts.csv"));
  PX_TRY(resumed
             ? px_csv_open_resume(r->ctx, path, 9, in, px_gran_keep(resume_time), &r->csv_impacts)
             : px_csv_open(r->ctx, path, 9, in, &r->csv_impacts));
  PX_TRY(px_sim_series_tap(r->sim, "impacts.csv", 9, in, r->csv_impacts));
  r->sys->impact_log = px_gran_log_impact;
  r->sys->impact_log_user = r;
  return PX_STATUS_OK;
}

enum px_status px_gran_out_impacts_resume(struct px_gran_run *r, double t) {
  if (r->impacts_checked) return PX_STATUS_OK;
  r->impacts_checked = 1;
  if (!r->impact_log || px_sim_mode(r->sim) != PX_SIM_MODE_RUN ||
      !px_gran_output_flag(r, "output.csv"))
    return PX_STATUS_OK;
  return px_gran_impacts_open(r, px_sim_output_dir(r->sim), 1, t);
}

/* media.csv and speed_histogram.csv. */
static enum px_status px_gran_series_open(struct px_gran_run *r, const struct px_sim_output *o) {
  static const char *const fixed[12] = {
      "t [s]",           "kinetic [J]",      "kinetic_rotation [J]",
      "com_x [m]",       "com_y [m]",        "com_dx [m]",
      "com_dy [m]",      "com_travel [m]",   "speed_mean [m/s]",
      "speed_max [m/s]", "coordination [-]", "rebuilds [-]"};
  const size_t nc = r->geom.ncontours, ncols = 12 + 2 * nc, nh = (size_t)r->bins + 1;
  const double keep = px_gran_keep(o->keep_series);
  struct px_sim_columns media = {0}, hist = {0};
  size_t i, c;
  enum px_status st = px_sim_columns_alloc(r->ctx, &media, ncols);
  if (st == PX_STATUS_OK) st = px_sim_columns_alloc(r->ctx, &hist, nh);
  if (st == PX_STATUS_OK) {
    for (i = 0; i < 12; ++i) px_sim_columns_set(&media, i, "%s", fixed[i]);
    for (c = 0; c < nc; ++c) {
      px_sim_columns_set(&media, 12 + 2 * c, "force_x_%s [N]", r->geom.contours[c].name);
      px_sim_columns_set(&media, 13 + 2 * c, "force_y_%s [N]", r->geom.contours[c].name);
    }
    /* the histogram: time, then the number of discs per speed bin, the bin
     * in the name ("0.05-0.1 m/s [-]") */
    px_sim_columns_set(&hist, 0, "t [s]");
    for (i = 1; i < nh; ++i)
      px_sim_columns_set(&hist, i, "%.4g-%.4g m/s [-]", r->speed_max * (double)(i - 1) / r->bins,
                         r->speed_max * (double)i / r->bins);
    st = px_sim_csv_open(r->ctx, o, "media.csv", ncols, media.name, keep, &r->csv_media);
  }
  if (st == PX_STATUS_OK)
    st = px_sim_csv_open(r->ctx, o, "speed_histogram.csv", nh, hist.name, keep, &r->csv_hist);
  px_sim_columns_free(r->ctx, &media);
  px_sim_columns_free(r->ctx, &hist);
  PX_TRY(st);
  return px_gran_impacts_open(r, o->dir, o->resumed, o->resume_time);
}

/* Append a row to the run's series (px_gran_run.plot). */
static enum px_status px_gran_plot_push(struct px_gran_run *r, const double *row) {
  if (r->nplot == r->plot_cap) {
    const size_t cap = r->plot_cap ? 2 * r->plot_cap : 1024;
    double *a =
        px_mem_realloc(r->ctx, "granular output", r->plot, cap * PX_GRAN_PLOT_NCOL * sizeof *a);
    if (!a) return PX_STATUS_NOMEM;
    r->plot = a;
    r->plot_cap = cap;
  }
  memcpy(r->plot + r->nplot * PX_GRAN_PLOT_NCOL, row, PX_GRAN_PLOT_NCOL * sizeof *row);
  ++r->nplot;
  return PX_STATUS_OK;
}

enum px_status px_gran_out_series(struct px_gran_run *r, const struct px_sim_output *o) {
  struct px_gran_sys *s = r->sys;
  const size_t n = s->n, nc = r->geom.ncontours;
  double *buf, *row = NULL, prow[PX_GRAN_PLOT_NCOL];
  double et = 0, er = 0, mt = 0, cx = 0, cy = 0, vmean = 0, vmaxv = 0, coord;
  double travel = r->travel, com0[2], prev[2];
  int started = r->com_started;
  size_t i, c;
  long bad;
  enum px_status st = PX_STATUS_OK;
  const size_t ncols = 12 + 2 * nc;
  if (o->render) return PX_STATUS_OK;
  px_gran_resume_tidy(r, o);
  buf = px_mem_alloc(r->ctx, "granular output", 8 * (n ? n : 1) * sizeof *buf);
  row = px_mem_alloc(r->ctx, "granular output", (ncols + (size_t)r->bins + 1) * sizeof *row);
  if (!buf || !row) {
    px_mem_free(r->ctx, buf);
    px_mem_free(r->ctx, row);
    return PX_STATUS_NOMEM;
  }
  {
    double *x = buf, *y = buf + n, *vx = buf + 2 * n, *vy = buf + 3 * n, *m = buf + 4 * n;
    double *z = buf + 5 * n, *rad = buf + 7 * n;
    px_gran_sys_export(s, x, y, vx, vy, NULL, rad, m, NULL);
    s->ops->energy(s, &et, &er, &bad);
    double *speed = buf + 6 * n; /* for the histogram below */
    for (i = 0; i < n; ++i) {
      const double sp = speed[i] = hypot(vx[i], vy[i]);
      mt += m[i];
      cx += m[i] * x[i];
      cy += m[i] * y[i];
      vmean += sp;
      if (sp > vmaxv) vmaxv = sp;
    }
    cx /= mt;
    cy /= mt;
    vmean /= (double)(n ? n : 1);
    coord = px_gran_sys_coordination(s, x, y, rad, z);
    /* travel of the centre of mass (path length) since the statistics
     * start, along the scheduled rows: a row of the end of the run off the
     * schedule shows the travel up to it but does not enter the state (a
     * resumed run would not have it) */
    com0[0] = r->com0[0], com0[1] = r->com0[1];
    prev[0] = r->com_prev[0], prev[1] = r->com_prev[1];
    if (o->time >= r->sspec.start) {
      if (!started) {
        com0[0] = prev[0] = cx;
        com0[1] = prev[1] = cy;
        started = 1;
      }
      travel += hypot(cx - prev[0], cy - prev[1]);
      prev[0] = cx, prev[1] = cy;
    }
    if (!o->final) {
      r->com0[0] = com0[0], r->com0[1] = com0[1];
      r->com_prev[0] = prev[0], r->com_prev[1] = prev[1];
      r->travel = travel;
      r->com_started = started;
    }
    if (!r->csv_media) st = px_gran_series_open(r, o);
    if (st == PX_STATUS_OK) {
      row[0] = o->time, row[1] = et, row[2] = er, row[3] = cx, row[4] = cy;
      row[5] = started ? cx - com0[0] : 0;
      row[6] = started ? cy - com0[1] : 0;
      row[7] = travel, row[8] = vmean, row[9] = vmaxv, row[10] = coord;
      row[11] = (double)s->rebuilds;
      for (c = 0; c < nc; ++c) px_gran_sys_wall_force(s, c, row + 12 + 2 * c);
      st = px_csv_row(r->csv_media, row);
    }
    if (st == PX_STATUS_OK) {
      double *h = row;
      memset(h, 0, ((size_t)r->bins + 1) * sizeof *h);
      h[0] = o->time;
      for (i = 0; i < n; ++i) {
        long b = (long)(speed[i] / r->speed_max * r->bins);
        if (b >= r->bins) b = r->bins - 1;
        h[1 + b] += 1;
      }
      st = px_csv_row(r->csv_hist, h);
    }
    if (st == PX_STATUS_OK) {
      prow[PX_GRAN_PLOT_T] = o->time;
      prow[PX_GRAN_PLOT_KE] = et + er;
      prow[PX_GRAN_PLOT_COMY] = cy;
      prow[PX_GRAN_PLOT_COORD] = coord;
      prow[PX_GRAN_PLOT_TRAVEL] = travel;
      prow[PX_GRAN_PLOT_SPEED] = vmean;
      if (o->final) {
        memcpy(r->last, prow, sizeof prow);
        r->last_step = o->step;
      } else {
        st = px_gran_plot_push(r, prow);
      }
    }
  }
  px_mem_free(r->ctx, buf);
  px_mem_free(r->ctx, row);
  return st;
}

/* The rows of the run's series for the end-of-run plots and the summary at
 * step `step`: the scheduled rows, and the end-of-run row when it belongs to
 * this step. Column q of row i: (*rows)[i * PX_GRAN_PLOT_NCOL + q]; owned by
 * the caller. */
static enum px_status px_gran_rows(struct px_gran_run *r, long step, double **rows, size_t *n) {
  const int with_last = r->last_step >= 0 && r->last_step == step;
  const size_t m = r->nplot + (with_last ? 1 : 0);
  *rows = px_mem_alloc(r->ctx, "granular output", (m ? m : 1) * PX_GRAN_PLOT_NCOL * sizeof **rows);
  if (!*rows) return PX_STATUS_NOMEM;
  if (r->nplot) memcpy(*rows, r->plot, r->nplot * PX_GRAN_PLOT_NCOL * sizeof **rows);
  if (with_last) memcpy(*rows + r->nplot * PX_GRAN_PLOT_NCOL, r->last, sizeof r->last);
  *n = m;
  return PX_STATUS_OK;
}

enum px_status px_gran_out_finish(struct px_gran_run *r, const struct px_sim_output *o) {
  const int q = px_gran_picture_column(r);
  const int pictures = o->pictures;
  double *rows = NULL;
  size_t c, nrows = 0;
  char path[1024];
  enum px_status st = PX_STATUS_OK;
  px_gran_resume_tidy(r, o);
  PX_TRY(px_gran_out_view(r));
  if (!o->render && px_gran_output_flag(r, "output.csv"))
    for (c = 0; c < r->geom.ncontours; ++c)
      if (r->report[c]) PX_TRY(px_gran_segments_csv(r, c, o->dir, o->time));
  if (!o->render && px_gran_output_flag(r, "output.vtk")) {
    PX_TRY(px_file_join(r->ctx, path, sizeof path, o->dir, "contours.vtp"));
    PX_TRY(px_gran_walls_vtp(r, path, o->time, o->step, 0));
  }
  if (pictures) {
    for (c = 0; c < r->geom.ncontours; ++c)
      if (r->report[c]) PX_TRY(px_gran_profile_png(r, c, q, o->dir, o->time));
    PX_TRY(px_gran_contours_png(r, q, o->dir, o->time));
    PX_TRY(px_gran_rows(r, o->step, &rows, &nrows));
    st = px_gran_plot(r, o->dir, "kinetic_energy.png", "kinetic energy of the media", "E_kin [J]",
                      rows, nrows, PX_GRAN_PLOT_KE);
    if (st == PX_STATUS_OK)
      st = px_gran_plot(r, o->dir, "com_height.png", "centre of mass of the media", "y_com [m]",
                        rows, nrows, PX_GRAN_PLOT_COMY);
    if (st == PX_STATUS_OK)
      st = px_gran_plot(r, o->dir, "coordination.png", "mean coordination number", "z [-]", rows,
                        nrows, PX_GRAN_PLOT_COORD);
    px_mem_free(r->ctx, rows);
    PX_TRY(st);
  }
  if (!o->render && r->sys->ev_overflow)
    px_log(r->ctx, PX_LOG_LEVEL_WARN,
           "%zu wall-contact events were lost (event buffers full): the statistics are "
           "slightly low",
           r->sys->ev_overflow);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------ summary */

/* `name` made a summary name part: characters other than letters, digits
 * and '_' become '_' ("rib.2" -> "rib_2": dots group quantities). */
static void px_gran_summary_part(char *buf, size_t size, const char *name) {
  size_t i;
  snprintf(buf, size, "%s", name);
  for (i = 0; buf[i]; ++i) {
    const char ch = buf[i];
    if (!((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9')))
      buf[i] = '_';
  }
}

/* Time average of column col over the rows with t >= t0 (trapezoids; the
 * one value when only one row qualifies; NaN when none). */
static double px_gran_time_mean(const double *rows, size_t n, size_t col, double t0) {
  double area = 0, span = 0, one = NAN;
  size_t i, used = 0;
  for (i = 0; i < n; ++i) {
    const double *a = rows + i * PX_GRAN_PLOT_NCOL;
    if (a[PX_GRAN_PLOT_T] < t0) continue;
    if (used++ == 0) {
      one = a[col];
      continue;
    }
    {
      const double *b = a - PX_GRAN_PLOT_NCOL;
      const double h = a[PX_GRAN_PLOT_T] - b[PX_GRAN_PLOT_T];
      area += 0.5 * h * (a[col] + b[col]);
      span += h;
    }
  }
  return span > 0 ? area / span : one;
}

enum px_status px_gran_out_report(struct px_gran_run *r, const struct px_sim_output *o,
                                  struct px_summary *sum) {
  const struct px_gran_geom *g = &r->geom;
  const double window = o->time > r->sspec.start ? o->time - r->sspec.start : 0;
  double *rows = NULL, mass = 0;
  size_t c, i, nrows = 0;
  char key[160], about[256], part[72];
  PX_TRY(px_gran_sync(r));
  PX_TRY(px_gran_out_view(r));
  for (i = 0; i < r->sys->n; ++i) {
    double rec[8];
    r->sys->ops->get(r->sys, i, rec);
    mass += rec[PX_GRAN_P_M];
  }
  px_summary_int(sum, "media.count", (long)r->sys->n, "-", "media discs");
  px_summary_real(sum, "media.mass", mass, "kg", "mass of the media (rho pi r^2 thickness)");
  px_summary_real(sum, "statistics.start", r->sspec.start, "s", "time the impact statistics start");
  px_summary_real(sum, "statistics.window", window, "s",
                  "time over which the impact statistics are accumulated");
  for (c = 0; c < g->ncontours; ++c) {
    const struct px_gran_contour *C = &g->contours[c];
    double **cols;
    double impacts = 0, en = 0, et = 0, arch = 0, fin = 0, vn = 0, hard = -INFINITY;
    double res = 0, arch_d = 0, fin_d = 0, at[2];
    size_t k, most_n = 0, most_e = 0;
    if (!r->report[c]) continue;
    cols = px_gran_cols_alloc(r->ctx, C->count);
    if (!cols) return PX_STATUS_NOMEM;
    px_gran_seg_table(r, c, o->time, cols);
    for (k = 0; k < C->count; ++k) {
      const double n = cols[PX_GRAN_SEG_IMPACTS][k];
      impacts += n;
      vn += n * cols[PX_GRAN_SEG_VN_MEAN][k];
      en += cols[PX_GRAN_SEG_EN][k];
      et += cols[PX_GRAN_SEG_ET][k];
      arch += cols[PX_GRAN_SEG_ARCH_V][k];
      fin += cols[PX_GRAN_SEG_FIN_V][k];
      arch_d = fmax(arch_d, cols[PX_GRAN_SEG_ARCH_D][k]);
      fin_d = fmax(fin_d, cols[PX_GRAN_SEG_FIN_D][k]);
      hard = fmax(hard, cols[PX_GRAN_SEG_HARD][k]);
      if (fabs(cols[PX_GRAN_SEG_RES][k]) > fabs(res)) res = cols[PX_GRAN_SEG_RES][k];
      if (n > cols[PX_GRAN_SEG_IMPACTS][most_n]) most_n = k;
      if (cols[PX_GRAN_SEG_EN_AREA][k] > cols[PX_GRAN_SEG_EN_AREA][most_e]) most_e = k;
    }
    px_gran_summary_part(part, sizeof part, C->name);
#define PX_GRAN_KEY(suffix) (snprintf(key, sizeof key, "%s.%s", part, suffix), key)
#define PX_GRAN_ABOUT(...) (snprintf(about, sizeof about, __VA_ARGS__), about)
    px_summary_int(sum, PX_GRAN_KEY("impacts"), (long)impacts, "-",
                   PX_GRAN_ABOUT("impacts counted on contour %s", C->name));
    px_summary_real(sum, PX_GRAN_KEY("impact_rate"), window > 0 ? impacts / window : 0, "1/s",
                    PX_GRAN_ABOUT("impacts per second on %s", C->name));
    px_summary_real(sum, PX_GRAN_KEY("vn_mean"), impacts > 0 ? vn / impacts : 0, "m/s",
                    PX_GRAN_ABOUT("mean normal impact speed on %s", C->name));
    px_summary_real(sum, PX_GRAN_KEY("impact_energy_mean"), impacts > 0 ? en / impacts : 0, "J",
                    PX_GRAN_ABOUT("mean normal impact energy m vn^2/2 per impact on %s", C->name));
    px_summary_real(sum, PX_GRAN_KEY("energy_n"), en, "J",
                    PX_GRAN_ABOUT("normal impact energy on %s, summed", C->name));
    px_summary_real(sum, PX_GRAN_KEY("energy_t"), et, "J",
                    PX_GRAN_ABOUT("tangential impact energy on %s, summed", C->name));
    px_summary_real(sum, PX_GRAN_KEY("archard_volume"), arch, "m^3",
                    PX_GRAN_ABOUT("removal by sliding wear (Archard) on %s", C->name));
    px_summary_real(sum, PX_GRAN_KEY("archard_depth_max"), arch_d, "m",
                    PX_GRAN_ABOUT("largest Archard depth of a segment of %s", C->name));
    px_summary_real(sum, PX_GRAN_KEY("finnie_volume"), fin, "m^3",
                    PX_GRAN_ABOUT("removal by erosion (Finnie) on %s", C->name));
    px_summary_real(sum, PX_GRAN_KEY("finnie_depth_max"), fin_d, "m",
                    PX_GRAN_ABOUT("largest Finnie depth of a segment of %s", C->name));
    /* where: null while nothing was hit */
    {
      const int hit = cols[PX_GRAN_SEG_IMPACTS][most_n] > 0;
      at[0] = hit ? cols[PX_GRAN_SEG_X][most_n] : NAN;
      at[1] = hit ? cols[PX_GRAN_SEG_Y][most_n] : NAN;
      px_summary_int(sum, PX_GRAN_KEY("most_impacts.impacts"),
                     (long)cols[PX_GRAN_SEG_IMPACTS][most_n], "-",
                     PX_GRAN_ABOUT("impacts on the segment of %s hit most often", C->name));
      px_summary_real(sum, PX_GRAN_KEY("most_impacts.s"), hit ? cols[PX_GRAN_SEG_S][most_n] : NAN,
                      "m", PX_GRAN_ABOUT("where it is: s of its midpoint along %s", C->name));
      px_summary_vector(sum, PX_GRAN_KEY("most_impacts.at"), 2, at, "m",
                        "its midpoint [x, y] (body frame)");
    }
    {
      const int hit = cols[PX_GRAN_SEG_EN_AREA][most_e] > 0;
      at[0] = hit ? cols[PX_GRAN_SEG_X][most_e] : NAN;
      at[1] = hit ? cols[PX_GRAN_SEG_Y][most_e] : NAN;
      px_summary_real(sum, PX_GRAN_KEY("most_energy.energy_n_area"),
                      cols[PX_GRAN_SEG_EN_AREA][most_e], "J/m^2",
                      PX_GRAN_ABOUT("normal impact energy per unit surface on the segment of %s "
                                    "that received the most",
                                    C->name));
      px_summary_real(sum, PX_GRAN_KEY("most_energy.s"), hit ? cols[PX_GRAN_SEG_S][most_e] : NAN,
                      "m", PX_GRAN_ABOUT("where it is: s of its midpoint along %s", C->name));
    }
    px_summary_vector(sum, PX_GRAN_KEY("most_energy.at"), 2, at, "m",
                      "its midpoint [x, y] (body frame)");
    if (r->hardening.kind)
      px_summary_real(sum, PX_GRAN_KEY("hardening_max"), hard,
                      px_gran_seg_unit(r, PX_GRAN_SEG_HARD),
                      PX_GRAN_ABOUT("largest hardening along %s", C->name));
    if (r->residual.kind)
      px_summary_real(sum, PX_GRAN_KEY("residual_stress_extreme"), res,
                      px_gran_seg_unit(r, PX_GRAN_SEG_RES),
                      PX_GRAN_ABOUT("residual stress of largest magnitude along %s", C->name));
#undef PX_GRAN_KEY
#undef PX_GRAN_ABOUT
    px_gran_cols_free(r->ctx, cols);
  }
  PX_TRY(px_gran_rows(r, o->step, &rows, &nrows));
  px_summary_real(sum, "media.kinetic_mean",
                  px_gran_time_mean(rows, nrows, PX_GRAN_PLOT_KE, r->sspec.start), "J",
                  "kinetic energy of the media (translation + rotation), time average over "
                  "the statistics window (media.csv rows)");
  px_summary_real(sum, "media.speed_mean",
                  px_gran_time_mean(rows, nrows, PX_GRAN_PLOT_SPEED, r->sspec.start), "m/s",
                  "mean disc speed, time average over the statistics window");
  px_summary_real(sum, "media.com_y_mean",
                  px_gran_time_mean(rows, nrows, PX_GRAN_PLOT_COMY, r->sspec.start), "m",
                  "height of the centre of mass, time average over the statistics window");
  px_summary_real(sum, "media.coordination_mean",
                  px_gran_time_mean(rows, nrows, PX_GRAN_PLOT_COORD, r->sspec.start), "-",
                  "contacts per disc, time average over the statistics window");
  px_summary_real(sum, "media.com_travel",
                  nrows ? rows[(nrows - 1) * PX_GRAN_PLOT_NCOL + PX_GRAN_PLOT_TRAVEL] : 0, "m",
                  "path length of the centre of mass since the statistics started (last "
                  "media.csv row)");
  px_mem_free(r->ctx, rows);
  if (r->sys->ev_overflow)
    px_summary_int(sum, "statistics.events_lost", (long)r->sys->ev_overflow, "-",
                   "wall-contact events lost (event buffers full): the statistics are low");
  return PX_STATUS_OK;
}

void px_gran_out_close(struct px_gran_run *r) {
  px_csv_close(r->csv_media);
  px_csv_close(r->csv_hist);
  px_vtk_series_close(r->pvd_particles);
  px_vtk_series_close(r->pvd_walls);
  px_vtk_free(r->vtk);
  px_csv_close(r->csv_impacts);
  if (r->sys) r->sys->impact_log = NULL;
  r->csv_media = r->csv_hist = r->csv_impacts = NULL;
  r->pvd_particles = r->pvd_walls = NULL;
  r->vtk = NULL;
  px_mem_free(r->ctx, r->view_buf);
  r->view_buf = NULL;
}
