/* Outputs of the granular solver:
 *  - snapshots (output.every): particles_NNNNNN.vtp (radius, velocity, speed,
 *    spin, contacts, id) and walls_NNNNNN.vtp (contours where they are, one
 *    line cell per segment with the impact statistics so far), with .pvd
 *    series;
 *  - series (output.log_every): media.csv (kinetic energy, centre of mass and
 *    its travel, coordination number, wall forces) and speed_histogram.csv
 *    (one histogram per row);
 *  - pictures (output.png_every): particles_NNNNNN.png;
 *  - at the end: segments_CONTOUR.csv along each reported contour,
 *    contours.vtp, CONTOUR_QUANTITY.png (the contour coloured by the chosen
 *    quantity) and media.png (energy, centre of mass, coordination). */
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

/* World position of vertex k of the geometry (contour c) at frames. */
static void px_gran_world(const struct px_gran_run *r, size_t c, size_t k, double *x, double *y) {
  const double *f = r->sys->frames + c * PX_GRAN_CTR_COUNT;
  const double ux = r->geom.ax[k] - f[PX_GRAN_CTR_PX], uy = r->geom.ay[k] - f[PX_GRAN_CTR_PY];
  *x = f[PX_GRAN_CTR_PX] + f[PX_GRAN_CTR_COS] * ux - f[PX_GRAN_CTR_SIN] * uy + f[PX_GRAN_CTR_DX];
  *y = f[PX_GRAN_CTR_PY] + f[PX_GRAN_CTR_SIN] * ux + f[PX_GRAN_CTR_COS] * uy + f[PX_GRAN_CTR_DY];
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

/* Units and meanings, written to the docs and the VTK array names. */
static const char *const px_gran_seg_units[PX_GRAN_SEG_NCOL] = {
    "m", "m", "m", "-", "-", "m", "-", "1/s", "m/s", "m/s", "m/s", "m/s", "J", "J", "J/m",
    "J/m", "J/m^2", "J/m^2", "N s", "N/m", "J", "m^3", "m", "m^3", "m", "s", "-", "s", "s",
    "s", "", ""};

/* Fill cols[q][k] (k over the segments of contour c). */
static void px_gran_seg_table(const struct px_gran_run *r, size_t c, double t, double **cols) {
  const struct px_gran_geom *g = &r->geom;
  const struct px_gran_contour *C = &g->contours[c];
  const struct px_gran_stats *S = &r->sys->stats;
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

enum px_status px_gran_out_segments(struct px_gran_run *r, size_t c, const char *dir, double t) {
  const struct px_gran_contour *C = &r->geom.contours[c];
  double **cols = px_gran_cols_alloc(r->ctx, C->count);
  char name[160], path[1024];
  const char *names[PX_GRAN_SEG_NCOL];
  enum px_status st;
  int q;
  if (!cols) return PX_STATUS_NOMEM;
  px_gran_seg_table(r, c, t, cols);
  for (q = 0; q < PX_GRAN_SEG_NCOL; ++q) names[q] = px_gran_seg_names[q];
  snprintf(name, sizeof name, "segments_%s.csv", C->name);
  st = px_file_join(r->ctx, path, sizeof path, dir, name);
  if (st == PX_STATUS_OK)
    st = px_csv_write_table(r->ctx, path, PX_GRAN_SEG_NCOL, names, C->count,
                            (const double *const *)cols, 10);
  px_gran_cols_free(r->ctx, cols);
  return st;
}

/* All contours as .vtp: one 2-point line per segment, cell data = the
 * segment table. world: at the current frames (snapshots) or in the body
 * frame (end-of-run file). */
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
  px_gran_sys_stats_flush(s);
  snprintf(name, sizeof name, "walls_%08ld.vtp", o->step);
  PX_TRY(px_file_join(r->ctx, path, sizeof path, o->dir, name));
  PX_TRY(px_gran_walls_vtp(r, path, o->time, o->step, 1));
  PX_TRY(px_vtk_series_add(r->pvd_walls, o->time, name));
  /* the per-segment tables as they stand (the run may be stopped any time) */
  {
    size_t c;
    for (c = 0; c < r->geom.ncontours; ++c)
      if (r->report[c]) PX_TRY(px_gran_out_segments(r, c, o->dir, o->time));
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
  row[6] = atan2(vn, fabs(vt)) * 180 / 3.14159265358979323846;
  row[7] = 0.5 * m * vn * vn;
  row[8] = 0.5 * m * vt * vt;
  px_csv_row(r->csv_impacts, row); /* a failed row is lost, the run goes on */
}

enum px_status px_gran_out_series(struct px_gran_run *r, const struct px_sim_output *o) {
  struct px_gran_sys *s = r->sys;
  const size_t n = s->n, nc = r->geom.ncontours;
  double *buf, *row = NULL;
  double et = 0, er = 0, mt = 0, cx = 0, cy = 0, vmean = 0, vmaxv = 0, coord;
  size_t i, c;
  long bad;
  enum px_status st = PX_STATUS_OK;
  const size_t ncols = 12 + 2 * nc;
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
    /* travel of the centre of mass (path length) since the statistics start */
    if (o->time >= r->sspec.start) {
      if (!r->com_started) {
        r->com0[0] = cx, r->com0[1] = cy;
        r->com_prev[0] = cx, r->com_prev[1] = cy;
        r->com_started = 1;
      }
      r->travel += hypot(cx - r->com_prev[0], cy - r->com_prev[1]);
      r->com_prev[0] = cx, r->com_prev[1] = cy;
    }
    if (!r->csv_media) {
      const char *fixed[12] = {"time", "kinetic", "kinetic_rotation", "com_x", "com_y",
                               "com_dx", "com_dy", "com_travel", "speed_mean", "speed_max",
                               "coordination", "rebuilds"};
      const char **names = px_mem_alloc(r->ctx, "granular output", ncols * sizeof *names);
      char (*cn)[96] = px_mem_alloc(r->ctx, "granular output", (2 * nc + 1) * sizeof *cn);
      char path[1024];
      if (!names || !cn) st = PX_STATUS_NOMEM;
      for (i = 0; i < 12 && st == PX_STATUS_OK; ++i) names[i] = fixed[i];
      for (c = 0; c < nc && st == PX_STATUS_OK; ++c) {
        snprintf(cn[2 * c], 96, "force_x_%s", r->geom.contours[c].name);
        snprintf(cn[2 * c + 1], 96, "force_y_%s", r->geom.contours[c].name);
        names[12 + 2 * c] = cn[2 * c];
        names[13 + 2 * c] = cn[2 * c + 1];
      }
      if (st == PX_STATUS_OK) st = px_file_join(r->ctx, path, sizeof path, o->dir, "media.csv");
      if (st == PX_STATUS_OK)
        st = o->resumed ? px_csv_open_resume(r->ctx, path, ncols, names, o->keep_series, &r->csv_media)
                        : px_csv_open(r->ctx, path, ncols, names, &r->csv_media);
      if (st == PX_STATUS_OK) {
        /* the histogram file: time, then the counts per bin (bin edges in the
         * header: "v0-v1") */
        const size_t nh = (size_t)r->bins + 1;
        const char **hn = px_mem_alloc(r->ctx, "granular output", nh * sizeof *hn);
        char (*hc)[48] = px_mem_alloc(r->ctx, "granular output", nh * sizeof *hc);
        if (!hn || !hc) st = PX_STATUS_NOMEM;
        for (i = 0; i < nh && st == PX_STATUS_OK; ++i) {
          if (i == 0) snprintf(hc[i], 48, "time");
          else
            snprintf(hc[i], 48, "%.4g-%.4g", r->speed_max * (double)(i - 1) / r->bins,
                     r->speed_max * (double)i / r->bins);
          hn[i] = hc[i];
        }
        if (st == PX_STATUS_OK)
          st = px_file_join(r->ctx, path, sizeof path, o->dir, "speed_histogram.csv");
        if (st == PX_STATUS_OK)
          st = o->resumed ? px_csv_open_resume(r->ctx, path, nh, hn, o->keep_series, &r->csv_hist)
                          : px_csv_open(r->ctx, path, nh, hn, &r->csv_hist);
        px_mem_free(r->ctx, hn);
        px_mem_free(r->ctx, hc);
      }
      px_mem_free(r->ctx, names);
      px_mem_free(r->ctx, cn);
      if (st == PX_STATUS_OK && r->impact_log) {
        const char *in[9] = {"time", "contour", "segment", "particle", "vn", "vt", "angle_deg",
                             "energy_n", "energy_t"};
        st = px_file_join(r->ctx, path, sizeof path, o->dir, "impacts.csv");
        if (st == PX_STATUS_OK)
          st = o->resumed ? px_csv_open_resume(r->ctx, path, 9, in, o->resume_time, &r->csv_impacts)
                          : px_csv_open(r->ctx, path, 9, in, &r->csv_impacts);
        if (st == PX_STATUS_OK) {
          r->sys->impact_log = px_gran_log_impact;
          r->sys->impact_log_user = r;
        }
      }
    }
    if (st == PX_STATUS_OK) {
      row[0] = o->time, row[1] = et, row[2] = er, row[3] = cx, row[4] = cy;
      row[5] = r->com_started ? cx - r->com0[0] : 0;
      row[6] = r->com_started ? cy - r->com0[1] : 0;
      row[7] = r->travel, row[8] = vmean, row[9] = vmaxv, row[10] = coord;
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
      /* kept for the end-of-run plot */
      if (r->nplot == r->plot_cap) {
        const size_t cap = r->plot_cap ? 2 * r->plot_cap : 1024;
        double *a = px_mem_realloc(r->ctx, "granular output", r->plot_t, cap * sizeof *a);
        double *b = a ? px_mem_realloc(r->ctx, "granular output", r->plot_ke, cap * sizeof *b) : NULL;
        double *d = b ? px_mem_realloc(r->ctx, "granular output", r->plot_comy, cap * sizeof *d) : NULL;
        double *e = d ? px_mem_realloc(r->ctx, "granular output", r->plot_coord, cap * sizeof *e) : NULL;
        if (a) r->plot_t = a;
        if (b) r->plot_ke = b;
        if (d) r->plot_comy = d;
        if (e) {
          r->plot_coord = e;
          r->plot_cap = cap;
        }
      }
      if (r->nplot < r->plot_cap) {
        r->plot_t[r->nplot] = o->time;
        r->plot_ke[r->nplot] = et + er;
        r->plot_comy[r->nplot] = cy;
        r->plot_coord[r->nplot] = coord;
        ++r->nplot;
      }
    }
  }
  px_mem_free(r->ctx, buf);
  px_mem_free(r->ctx, row);
  return st;
}

/* ------------------------------------------------------------------ pictures */

/* Draw the contours (parts filled) into fig. */
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
  /* the figure borrows the arrays until it is drawn: keep them with it */
  if (st == PX_STATUS_OK) {
    px_figure_set_line_width(fig, 1.0);
  }
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
  const char *fields[4] = {"speed", "spin", "contacts", "id"};
  const char *units[4] = {"m/s", "rad/s", "", ""};
  buf = px_mem_alloc(r->ctx, "granular output", 6 * (n ? n : 1) * sizeof *buf);
  if (!buf) return PX_STATUS_NOMEM;
  {
    double *x = buf, *y = buf + n, *vx = buf + 2 * n, *vy = buf + 3 * n, *rad = buf + 4 * n;
    double *val = buf + 5 * n, *w = vx;
    size_t i;
    if (r->color == 1) px_gran_sys_export(s, x, y, NULL, NULL, w, rad, NULL, NULL);
    else px_gran_sys_export(s, x, y, vx, vy, NULL, rad, NULL, r->color == 3 ? val : NULL);
    if (r->color == 0)
      for (i = 0; i < n; ++i) val[i] = hypot(vx[i], vy[i]);
    else if (r->color == 1)
      for (i = 0; i < n; ++i) val[i] = w[i];
    else if (r->color == 2)
      px_gran_sys_coordination(s, val);
    st = px_figure_create(r->ctx, r->width, r->height, &fig);
    if (st == PX_STATUS_OK) {
      const char *t = NULL;
      if (px_case_has(r->c, "title")) px_case_get_string(r->c, "title", &t);
      snprintf(title, sizeof title, "%s%s%zu discs", t ? t : "", t ? " - " : "", n);
      px_figure_set_title(fig, title);
      px_figure_set_time(fig, o->time, "s");
      px_figure_set_colormap(fig, r->color == 1 ? PX_COLORMAP_COOLWARM : PX_COLORMAP_VIRIDIS);
      if (r->range > 0)
        px_figure_set_range(fig, r->color == 1 ? -r->range : 0, r->range);
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

/* The reported contours (body frame) coloured by quantity q, on one colour
 * scale, solids filled. */
static enum px_status px_gran_contours_png(struct px_gran_run *r, int q, const char *dir,
                                           double t) {
  const struct px_gran_geom *g = &r->geom;
  struct px_figure *fig = NULL;
  double **vals = px_mem_calloc(r->ctx, "granular output", g->ncontours, sizeof *vals);
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  char name[200], path[1024], title[256];
  size_t c;
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
  }
  if (st == PX_STATUS_OK && xmax >= xmin) st = px_figure_create(r->ctx, r->width, r->height, &fig);
  if (st == PX_STATUS_OK && fig) {
    const double mx = 0.08 * fmax(xmax - xmin, ymax - ymin);
    if (t >= r->sspec.start)
      snprintf(title, sizeof title, "%s [%s] over %.4g s", px_gran_seg_names[q],
               px_gran_seg_units[q], t - r->sspec.start);
    else
      snprintf(title, sizeof title, "%s [%s] (statistics from t = %.4g s)",
               px_gran_seg_names[q], px_gran_seg_units[q], r->sspec.start);
    px_figure_set_title(fig, title);
    px_figure_set_time(fig, t, "s");
    px_figure_set_colormap(fig, PX_COLORMAP_INFERNO);
    px_figure_set_field(fig, px_gran_seg_names[q], px_gran_seg_units[q]);
    px_figure_set_axis_labels(fig, "x [m]", "y [m]");
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
  double **cols = px_gran_cols_alloc(r->ctx, C->count);
  struct px_plot *p = NULL;
  char name[200], path[1024], title[256], ylab[96];
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
    snprintf(ylab, sizeof ylab, "%s [%s]", px_gran_seg_names[q], px_gran_seg_units[q]);
    px_plot_set_title(p, title);
    px_plot_set_labels(p, "s along the contour [m]", ylab);
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

static enum px_status px_gran_plot(struct px_gran_run *r, const char *dir, const char *file,
                                   const char *title, const char *ylabel, const double *y) {
  struct px_plot *p = NULL;
  char path[1024];
  enum px_status st;
  if (r->nplot < 2) return PX_STATUS_OK;
  PX_TRY(px_plot_create(r->ctx, 1000, 600, &p));
  px_plot_set_title(p, title);
  px_plot_set_labels(p, "t [s]", ylabel);
  st = px_plot_add_series(p, ylabel, r->nplot, r->plot_t, y);
  if (st == PX_STATUS_OK) st = px_file_join(r->ctx, path, sizeof path, dir, file);
  if (st == PX_STATUS_OK) st = px_plot_write_png(p, path);
  px_plot_free(p);
  return st;
}

enum px_status px_gran_out_finish(struct px_gran_run *r, const struct px_sim_output *o) {
  size_t c;
  char path[1024];
  int q = px_gran_seg_column(r->picture_quantity);
  if (q < 0) {
    px_log(r->ctx, PX_LOG_LEVEL_WARN,
           "granular.statistics.picture: no column '%s' in the segment table; using "
           "energy_n_area",
           r->picture_quantity);
    q = PX_GRAN_SEG_EN_AREA;
  }
  px_gran_sys_stats_flush(r->sys);
  for (c = 0; c < r->geom.ncontours; ++c) {
    if (!r->report[c]) continue;
    PX_TRY(px_gran_out_segments(r, c, o->dir, o->time));
    PX_TRY(px_gran_profile_png(r, c, q, o->dir, o->time));
  }
  PX_TRY(px_gran_contours_png(r, q, o->dir, o->time));
  /* the media at the end */
  PX_TRY(px_gran_out_picture(r, o));
  PX_TRY(px_file_join(r->ctx, path, sizeof path, o->dir, "contours.vtp"));
  PX_TRY(px_gran_walls_vtp(r, path, o->time, o->step, 0));
  PX_TRY(px_gran_plot(r, o->dir, "kinetic_energy.png", "kinetic energy of the media",
                      "E_kin [J]", r->plot_ke));
  PX_TRY(px_gran_plot(r, o->dir, "com_height.png", "centre of mass of the media", "y_com [m]",
                      r->plot_comy));
  PX_TRY(px_gran_plot(r, o->dir, "coordination.png", "mean coordination number", "z [-]",
                      r->plot_coord));
  if (r->sys->ev_overflow)
    px_log(r->ctx, PX_LOG_LEVEL_WARN,
           "%zu wall-contact events were lost (event buffers full): the statistics are "
           "slightly low",
           r->sys->ev_overflow);
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
}
