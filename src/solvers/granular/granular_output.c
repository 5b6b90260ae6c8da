/* Outputs of the granular solver (the files are listed, column by column,
 * in docs/granular.md):
 *  - snapshots (output.every): particles_NNNNNNNN.vtp (radius, velocity,
 *    speed, spin, contacts, id) and walls_NNNNNNNN.vtp (contours where they
 *    are, one line cell per segment with the impact statistics so far), with
 *    .pvd series; the segment tables as they stand;
 *  - series (output.log_every): media.csv (kinetic energy, centre of mass and
 *    its travel, coordination number, wall forces), speed_histogram.csv (one
 *    histogram per row) and, as impacts happen, impacts.csv;
 *  - pictures (output.png_every): particles_NNNNNNNN.png;
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
#include "solvers/granular/wall_kernel.h"

#define PX_GRAN_OUT_PI 3.14159265358979323846

/* World position of vertex k of the geometry (contour c) at frames. */
static void px_gran_world(const struct px_gran_run *r, size_t c, size_t k, double *x, double *y) {
  const double *f = r->sys->frames + c * PX_GRAN_CTR_COUNT;
  const double ux = r->geom.ax[k] - f[PX_GRAN_CTR_PX], uy = r->geom.ay[k] - f[PX_GRAN_CTR_PY];
  *x = f[PX_GRAN_CTR_PX] + f[PX_GRAN_CTR_COS] * ux - f[PX_GRAN_CTR_SIN] * uy + f[PX_GRAN_CTR_DX];
  *y = f[PX_GRAN_CTR_PY] + f[PX_GRAN_CTR_SIN] * ux + f[PX_GRAN_CTR_COS] * uy + f[PX_GRAN_CTR_DY];
}

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

/* A resumed run removes the picture an earlier segment drew only because it
 * ended off the png schedule (struct px_sim_output: drop_picture), at the
 * first output of the run, whichever it is. */
static void px_gran_resume_tidy(struct px_gran_run *r, const struct px_sim_output *o) {
  char name[64], path[1024];
  if (!o->resumed || o->render || r->resume_tidied) return;
  r->resume_tidied = 1;
  if (o->drop_picture < 0) return;
  snprintf(name, sizeof name, "particles_%08ld.png", o->drop_picture);
  if (px_file_join(r->ctx, path, sizeof path, o->dir, name) == PX_STATUS_OK) remove(path);
}

/* ------------------------------------------------------------ statistics */

/* r->view: the statistics of the system with the contacts in progress added,
 * as they would be if every contact ended now. */
static enum px_status px_gran_out_view(struct px_gran_run *r) {
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

/* Columns of the per-segment report. */
enum {
  PX_GRAN_SEG_S, PX_GRAN_SEG_X, PX_GRAN_SEG_Y, PX_GRAN_SEG_NX, PX_GRAN_SEG_NY, PX_GRAN_SEG_LEN,
  PX_GRAN_SEG_IMPACTS, PX_GRAN_SEG_RATE, PX_GRAN_SEG_VN_MEAN, PX_GRAN_SEG_VN_RMS,
  PX_GRAN_SEG_VN_MAX, PX_GRAN_SEG_VT_MEAN, PX_GRAN_SEG_EN, PX_GRAN_SEG_ET,
  PX_GRAN_SEG_EN_LEN, PX_GRAN_SEG_ET_LEN, PX_GRAN_SEG_EN_AREA, PX_GRAN_SEG_ET_AREA,
  PX_GRAN_SEG_IMPULSE, PX_GRAN_SEG_LOAD, PX_GRAN_SEG_SLIDE, PX_GRAN_SEG_ARCH_V,
  PX_GRAN_SEG_ARCH_D, PX_GRAN_SEG_FIN_V, PX_GRAN_SEG_FIN_D, PX_GRAN_SEG_CTIME,
  PX_GRAN_SEG_CFRAC, PX_GRAN_SEG_DUR, PX_GRAN_SEG_FIRST, PX_GRAN_SEG_LAST, PX_GRAN_SEG_HARD,
  PX_GRAN_SEG_RES, PX_GRAN_SEG_NCOL
};

static const char *const px_gran_seg_names[PX_GRAN_SEG_NCOL] = {
    "s", "x", "y", "nx", "ny", "length", "impacts", "impact_rate", "vn_mean", "vn_rms",
    "vn_max", "vt_mean", "energy_n", "energy_t", "energy_n_length", "energy_t_length",
    "energy_n_area", "energy_t_area", "impulse", "load", "sliding_work", "archard_volume",
    "archard_depth", "finnie_volume", "finnie_depth", "contact_time", "contact_fraction",
    "duration_mean", "first_impact", "last_impact", "hardening", "residual_stress"};

/* Units of the columns; hardening and residual stress take the case's
 * (px_gran_seg_unit). */
static const char *const px_gran_seg_units[PX_GRAN_SEG_NCOL] = {
    "m", "m", "m", "-", "-", "m", "-", "1/s", "m/s", "m/s", "m/s", "m/s", "J", "J", "J/m",
    "J/m", "J/m^2", "J/m^2", "N s", "N/m", "J", "m^3", "m", "m^3", "m", "s", "-", "s", "s",
    "s", "", ""};

static const char *px_gran_seg_unit(const struct px_gran_run *r, int q) {
  if (q == PX_GRAN_SEG_HARD) return r->hard_unit[0] ? r->hard_unit : "-";
  if (q == PX_GRAN_SEG_RES) return r->res_unit[0] ? r->res_unit : "-";
  return px_gran_seg_units[q];
}

/* Fill cols[q][k] (k over the segments of contour c) from r->view. */
static void px_gran_seg_table(const struct px_gran_run *r, size_t c, double t, double **cols) {
  const struct px_gran_geom *g = &r->geom;
  const struct px_gran_contour *C = &g->contours[c];
  const struct px_gran_stats *S = &r->view;
  const double window = t - r->sspec.start;
  const double th = r->thickness;
  double acc = 0;
  size_t k;
  for (k = 0; k < C->count; ++k) {
    const size_t s = C->first + k;
    const double L = g->len[s], n = S->impacts[s];
    const double earea_n = S->en[s] / (L * th), earea_t = S->et[s] / (L * th);
    const double E = r->energy_total ? earea_n + earea_t : earea_n;
    cols[PX_GRAN_SEG_S][k] = acc + 0.5 * L;
    acc += L;
    cols[PX_GRAN_SEG_X][k] = g->ax[s] + 0.5 * L * g->tx[s];
    cols[PX_GRAN_SEG_Y][k] = g->ay[s] + 0.5 * L * g->ty[s];
    cols[PX_GRAN_SEG_NX][k] = -g->ty[s];
    cols[PX_GRAN_SEG_NY][k] = g->tx[s];
    cols[PX_GRAN_SEG_LEN][k] = L;
    cols[PX_GRAN_SEG_IMPACTS][k] = n;
    cols[PX_GRAN_SEG_RATE][k] = window > 0 ? n / window : 0;
    cols[PX_GRAN_SEG_VN_MEAN][k] = n > 0 ? S->vn_sum[s] / n : 0;
    cols[PX_GRAN_SEG_VN_RMS][k] = n > 0 ? sqrt(S->vn2_sum[s] / n) : 0;
    cols[PX_GRAN_SEG_VN_MAX][k] = S->vn_max[s];
    cols[PX_GRAN_SEG_VT_MEAN][k] = n > 0 ? S->vt_sum[s] / n : 0;
    cols[PX_GRAN_SEG_EN][k] = S->en[s];
    cols[PX_GRAN_SEG_ET][k] = S->et[s];
    cols[PX_GRAN_SEG_EN_LEN][k] = S->en[s] / L;
    cols[PX_GRAN_SEG_ET_LEN][k] = S->et[s] / L;
    cols[PX_GRAN_SEG_EN_AREA][k] = earea_n;
    cols[PX_GRAN_SEG_ET_AREA][k] = earea_t;
    cols[PX_GRAN_SEG_IMPULSE][k] = S->impulse[s];
    cols[PX_GRAN_SEG_LOAD][k] = window > 0 ? S->impulse[s] / (window * L) : 0;
    cols[PX_GRAN_SEG_SLIDE][k] = S->slide[s];
    /* Archard 1953: V = K Fn s / H */
    cols[PX_GRAN_SEG_ARCH_V][k] = r->sspec.archard_k * S->archard[s] / r->sspec.hardness;
    cols[PX_GRAN_SEG_ARCH_D][k] = cols[PX_GRAN_SEG_ARCH_V][k] / (L * th);
    /* Finnie 1960: V = k m V^n f(alpha), summed over impacts */
    cols[PX_GRAN_SEG_FIN_V][k] = r->sspec.finnie_k * S->finnie[s];
    cols[PX_GRAN_SEG_FIN_D][k] = cols[PX_GRAN_SEG_FIN_V][k] / (L * th);
    cols[PX_GRAN_SEG_CTIME][k] = S->ctime[s];
    cols[PX_GRAN_SEG_CFRAC][k] = window > 0 ? S->ctime[s] / window : 0;
    cols[PX_GRAN_SEG_DUR][k] = S->ended[s] > 0 ? S->dur_sum[s] / S->ended[s] : 0;
    cols[PX_GRAN_SEG_FIRST][k] = S->t_first[s];
    cols[PX_GRAN_SEG_LAST][k] = S->t_last[s];
    cols[PX_GRAN_SEG_HARD][k] = r->hardening.kind ? px_gran_fn_eval(&r->hardening, E) : 0;
    cols[PX_GRAN_SEG_RES][k] = r->residual.kind ? px_gran_fn_eval(&r->residual, E) : 0;
  }
}

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

static double **px_gran_cols_alloc(struct px_context *ctx, size_t n) {
  double **cols = px_mem_calloc(ctx, "granular output", PX_GRAN_SEG_NCOL, sizeof *cols);
  int q;
  if (!cols) return NULL;
  for (q = 0; q < PX_GRAN_SEG_NCOL; ++q) {
    cols[q] = px_mem_calloc(ctx, "granular output", n ? n : 1, sizeof(double));
    if (!cols[q]) {
      int p;
      for (p = 0; p < q; ++p) px_mem_free(ctx, cols[p]);
      px_mem_free(ctx, cols);
      return NULL;
    }
  }
  return cols;
}

static void px_gran_cols_free(struct px_context *ctx, double **cols) {
  int q;
  if (!cols) return;
  for (q = 0; q < PX_GRAN_SEG_NCOL; ++q) px_mem_free(ctx, cols[q]);
  px_mem_free(ctx, cols);
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
      if (world) px_gran_world(r, c, s, &px[s], &py[s]);
      else px[s] = g->ax[s], py[s] = g->ay[s];
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
    px_gran_sys_coordination(s, z);
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
  static const char *const in[9] = {"t [s]",      "contour [-]", "segment [-]",
                                    "particle [-]", "vn [m/s]",  "vt [m/s]",
                                    "angle [deg]",  "energy_n [J]", "energy_t [J]"};
  char path[1024];
  if (r->csv_impacts || !r->impact_log) return PX_STATUS_OK;
  PX_TRY(px_file_join(r->ctx, path, sizeof path, dir, "impacts.csv"));
  PX_TRY(resumed ? px_csv_open_resume(r->ctx, path, 9, in, px_gran_keep(resume_time),
                                      &r->csv_impacts)
                 : px_csv_open(r->ctx, path, 9, in, &r->csv_impacts));
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
      "t [s]",         "kinetic [J]",        "kinetic_rotation [J]", "com_x [m]",
      "com_y [m]",     "com_dx [m]",         "com_dy [m]",           "com_travel [m]",
      "speed_mean [m/s]", "speed_max [m/s]", "coordination [-]",     "rebuilds [-]"};
  const size_t nc = r->geom.ncontours, ncols = 12 + 2 * nc, nh = (size_t)r->bins + 1;
  const double keep = px_gran_keep(o->keep_series);
  const char **names = px_mem_alloc(r->ctx, "granular output", ncols * sizeof *names);
  char (*cn)[96] = px_mem_alloc(r->ctx, "granular output", (2 * nc + 1) * sizeof *cn);
  const char **hn = px_mem_alloc(r->ctx, "granular output", nh * sizeof *hn);
  char (*hc)[64] = px_mem_alloc(r->ctx, "granular output", nh * sizeof *hc);
  char path[1024];
  size_t i, c;
  enum px_status st = PX_STATUS_OK;
  if (!names || !cn || !hn || !hc) st = PX_STATUS_NOMEM;
  for (i = 0; i < 12 && st == PX_STATUS_OK; ++i) names[i] = fixed[i];
  for (c = 0; c < nc && st == PX_STATUS_OK; ++c) {
    snprintf(cn[2 * c], 96, "force_x_%s [N]", r->geom.contours[c].name);
    snprintf(cn[2 * c + 1], 96, "force_y_%s [N]", r->geom.contours[c].name);
    names[12 + 2 * c] = cn[2 * c];
    names[13 + 2 * c] = cn[2 * c + 1];
  }
  if (st == PX_STATUS_OK) st = px_file_join(r->ctx, path, sizeof path, o->dir, "media.csv");
  if (st == PX_STATUS_OK)
    st = o->resumed ? px_csv_open_resume(r->ctx, path, ncols, names, keep, &r->csv_media)
                    : px_csv_open(r->ctx, path, ncols, names, &r->csv_media);
  /* the histogram: time, then the number of discs per speed bin, the bin
   * in the name ("0.05-0.1 m/s [-]") */
  for (i = 0; i < nh && st == PX_STATUS_OK; ++i) {
    if (i == 0) snprintf(hc[i], sizeof hc[i], "t [s]");
    else
      snprintf(hc[i], sizeof hc[i], "%.4g-%.4g m/s [-]",
               r->speed_max * (double)(i - 1) / r->bins, r->speed_max * (double)i / r->bins);
    hn[i] = hc[i];
  }
  if (st == PX_STATUS_OK)
    st = px_file_join(r->ctx, path, sizeof path, o->dir, "speed_histogram.csv");
  if (st == PX_STATUS_OK)
    st = o->resumed ? px_csv_open_resume(r->ctx, path, nh, hn, keep, &r->csv_hist)
                    : px_csv_open(r->ctx, path, nh, hn, &r->csv_hist);
  px_mem_free(r->ctx, names);
  px_mem_free(r->ctx, cn);
  px_mem_free(r->ctx, hn);
  px_mem_free(r->ctx, hc);
  PX_TRY(st);
  return px_gran_impacts_open(r, o->dir, o->resumed, o->resume_time);
}

/* Append a row to the run's series (px_gran_run.plot). */
static enum px_status px_gran_plot_push(struct px_gran_run *r, const double *row) {
  if (r->nplot == r->plot_cap) {
    const size_t cap = r->plot_cap ? 2 * r->plot_cap : 1024;
    double *a = px_mem_realloc(r->ctx, "granular output", r->plot,
                               cap * PX_GRAN_PLOT_NCOL * sizeof *a);
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
  buf = px_mem_alloc(r->ctx, "granular output", 7 * (n ? n : 1) * sizeof *buf);
  row = px_mem_alloc(r->ctx, "granular output", (ncols + (size_t)r->bins + 1) * sizeof *row);
  if (!buf || !row) {
    px_mem_free(r->ctx, buf);
    px_mem_free(r->ctx, row);
    return PX_STATUS_NOMEM;
  }
  {
    double *x = buf, *y = buf + n, *vx = buf + 2 * n, *vy = buf + 3 * n, *m = buf + 4 * n;
    double *z = buf + 5 * n;
    px_gran_sys_export(s, x, y, vx, vy, NULL, NULL, m, NULL);
    s->ops->energy(s, &et, &er, &bad);
    for (i = 0; i < n; ++i) {
      const double sp = hypot(vx[i], vy[i]);
      mt += m[i];
      cx += m[i] * x[i];
      cy += m[i] * y[i];
      vmean += sp;
      if (sp > vmaxv) vmaxv = sp;
    }
    cx /= mt;
    cy /= mt;
    vmean /= (double)(n ? n : 1);
    coord = px_gran_sys_coordination(s, z);
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
        long b = (long)(hypot(vx[i], vy[i]) / r->speed_max * r->bins);
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
      if (world) px_gran_world(r, c, k, &x[k], &y[k]);
      else x[k] = g->ax[k], y[k] = g->ay[k];
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
    if (r->color == 1) px_gran_sys_export(s, x, y, NULL, NULL, w, rad, NULL, NULL);
    else px_gran_sys_export(s, x, y, vx, vy, NULL, rad, NULL, r->color == 3 ? val : NULL);
    if (r->color == 0)
      for (i = 0; i < n; ++i) val[i] = hypot(vx[i], vy[i]);
    else if (r->color == 1)
      for (i = 0; i < n; ++i) val[i] = w[i];
    else if (r->color == 2)
      px_gran_sys_coordination(s, val);
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
    if (st == PX_STATUS_OK)
      st = px_figure_add_discs(fig, PX_DTYPE_F64, n, x, y, rad, 0, val);
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
static enum px_status px_gran_contours_png(struct px_gran_run *r, int q, const char *dir,
                                           double t) {
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
      snprintf(title, sizeof title, "%s [%s] (statistics from t = %.4g s)",
               px_gran_seg_names[q], unit, r->sspec.start);
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
      if (C->media_inside) px_figure_set_fill(fig, 1, 1, 1);
      else px_figure_set_fill(fig, 0.85, 0.86, 0.88);
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
static enum px_status px_gran_profile_png(struct px_gran_run *r, size_t c, int q, const char *dir,
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
    snprintf(xlab, sizeof xlab, "s [m] along %s: from (%.4g, %.4g) m (body frame), %s",
             C->name, r->geom.ax[s0], r->geom.ay[s0],
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
      if (lo >= 0) px_plot_set_yrange(p, 0, hi > 0 ? 1.05 * hi : 1);
      else if (hi <= 0) px_plot_set_yrange(p, 1.05 * lo, 0);
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
static enum px_status px_gran_plot(struct px_gran_run *r, const char *dir, const char *file,
                                   const char *title, const char *ylabel, const double *rows,
                                   size_t n, size_t col) {
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
    st = px_gran_plot(r, o->dir, "kinetic_energy.png", "kinetic energy of the media",
                      "E_kin [J]", rows, nrows, PX_GRAN_PLOT_KE);
    if (st == PX_STATUS_OK)
      st = px_gran_plot(r, o->dir, "com_height.png", "centre of mass of the media",
                        "y_com [m]", rows, nrows, PX_GRAN_PLOT_COMY);
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
  px_summary_real(sum, "statistics.start", r->sspec.start, "s",
                  "time the impact statistics start");
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
                    PX_GRAN_ABOUT("mean normal impact energy m vn^2/2 per impact on %s",
                                  C->name));
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
