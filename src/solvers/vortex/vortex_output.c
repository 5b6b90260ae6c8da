/* The vortex solver's outputs: the wake (.vtp series), loads CSV, fields
 * (.vti) and probes CSV, the pressure at points, PNG pictures, the load plot
 * and the summary's report (vortex_solver.h). */
#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/csv.h"
#include "partix/figure.h"
#include "partix/memory.h"
#include "partix/vtk.h"
#include "solvers/solver.h"
#include "solvers/summary.h"
#include "solvers/vortex/vortex_core.h"
#include "solvers/vortex/vortex_engine.h"
#include "solvers/vortex/vortex_report.h"
#include "solvers/vortex/vortex_profile.h"
#include "solvers/vortex/vortex_ranks.h"
#include "solvers/vortex/vortex_solver.h"

#define VX_PI 3.14159265358979323846

/* ------------------------------------------------------------------------- */
/* Pressure by the Cauchy-Lagrange integral (VM2D MeasureVP2D; Dynnikova):
 *   (p - p_inf)/rho = |V_inf|^2/2 - |V|^2/2 + sum_j V_j . v_j(r)
 *                     + sum_k alpha_k(r) (gamma_k L_k - absorbed_k) / (2 pi dt),
 * v_j(r) the velocity induced at r by vortex j, V_j its own velocity, and
 * alpha_k(r) the angle under which the segment from the body's inner point to
 * panel k's middle is seen from r: the potential jump carried by the
 * circulation created on panel k in the step. */
static enum px_status pressure(struct vx_state *s, size_t n, const double *x, const double *y,
                               const double *u, const double *v, double *p) {
  const struct px_vortex_engine *e = s->e;
  const struct px_vortex_wake *w = &e->w;
  const struct px_vortex_panels *pp = &e->pan;
  double vx, vy;
  px_vortex_vinf(&e->cfg, e->time, &vx, &vy);
  double eps2 = e->cfg.eps * e->cfg.eps, rho = e->cfg.rho, dt = e->cfg.dt;
  double vinf2 = e->cfg.vinf[0] * e->cfg.vinf[0] + e->cfg.vinf[1] * e->cfg.vinf[1];
  double inner[PX_VORTEX_MAX_BODIES][2];
  for (size_t b = 0; b < e->nbody; ++b) {
    double sx = 0.0, sy = 0.0;
    for (size_t k = 0; k < e->body[b].n; ++k) {
      sx += e->body[b].x[k];
      sy += e->body[b].y[k];
    }
    inner[b][0] = sx / (double)e->body[b].n;
    inner[b][1] = sy / (double)e->body[b].n;
  }
#pragma omp parallel for num_threads(e->cfg.threads) schedule(static)
  for (long li = 0; li < (long)n; ++li) {
    size_t i = (size_t)li;
    double acc = 0.0;
    for (size_t j = 0; j < w->n; ++j) {
      double dx = x[i] - w->x[j], dy = y[i] - w->y[j], r2 = dx * dx + dy * dy;
      double f = w->g[j] / (2.0 * VX_PI * (r2 > eps2 ? r2 : eps2));
      acc += f * (-dy * w->u[j] + dx * w->v[j]);
    }
    for (size_t k = 0; k < pp->n; ++k) {
      size_t b = (size_t)pp->body[k];
      double cx = 0.5 * (pp->x0[k] + pp->x1[k]) - x[i], cy = 0.5 * (pp->y0[k] + pp->y1[k]) - y[i];
      double ix = inner[b][0] - x[i], iy = inner[b][1] - y[i];
      double al = atan2(cx * iy - cy * ix, cx * ix + cy * iy);
      acc += al * (e->sol[k] * pp->len[k] - e->through[k]) / (2.0 * VX_PI * dt);
    }
    p[i] = rho * (0.5 * vinf2 - 0.5 * (u[i] * u[i] + v[i] * v[i]) + acc);
  }
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */
/* Outputs */

static enum px_status out_path(const struct px_sim_output *o, const char *name, char *buf,
                               size_t size) {
  int n = snprintf(buf, size, "%s/%s", o->dir, name);
  return (n < 0 || (size_t)n >= size) ? PX_STATUS_INVALID : PX_STATUS_OK;
}

/* A resumed run: delete the picture of the resume step that an earlier
 * segment drew only because it ended there (struct px_sim_output), once,
 * from whichever output hook runs first. */
static enum px_status vx_tidy(struct vx_state *s, const struct px_sim_output *o) {
  char path[1024], name[64];
  if (!o->resumed || o->render || s->tidied) return PX_STATUS_OK;
  s->tidied = 1;
  if (o->drop_picture < 0) return PX_STATUS_OK;
  snprintf(name, sizeof name, "wake_%06ld.png", o->drop_picture);
  PX_TRY(out_path(o, name, path, sizeof path));
  if (remove(path) != 0 && errno != ENOENT)
    return px_context_fail(s->ctx, PX_STATUS_IO,
                           "cannot remove %s (a picture of an earlier "
                           "segment's end): %s",
                           path, strerror(errno));
  return PX_STATUS_OK;
}

/* Open fields.pvd (continued on resume). */
static enum px_status vx_open_fields(struct vx_state *s, const struct px_sim_output *o) {
  char path[1024];
  PX_TRY(out_path(o, "fields.pvd", path, sizeof path));
  return o->resumed ? px_vtk_series_open_resume(s->ctx, path, o->keep_snapshot, &s->pvd_field)
                    : px_vtk_series_open(s->ctx, path, &s->pvd_field);
}

enum px_status px_vortex_output_snapshot(void *state, const struct px_sim_output *o) {
  struct vx_state *s = state;
  struct px_context *ctx = s->ctx;
  struct px_vortex_engine *e = s->e;
  char path[1024], name[128];
  PX_TRY(vx_tidy(s, o));
  PX_TRY(px_vortex_engine_sync(e));
  if (!s->vtk) PX_TRY(px_vtk_create(ctx, &s->vtk));
  if (!s->pvd_wake) {
    PX_TRY(out_path(o, "wake.pvd", path, sizeof path));
    if (o->resumed)
      PX_TRY(px_vtk_series_open_resume(ctx, path, o->keep_snapshot, &s->pvd_wake));
    else
      PX_TRY(px_vtk_series_open(ctx, path, &s->pvd_wake));
    /* a resumed run drops the field entries after its checkpoint even when
     * it writes no field itself */
    if (s->has_grid && o->resumed && !s->pvd_field) PX_TRY(vx_open_fields(s, o));
    /* the bodies once */
    px_vtk_reset(s->vtk);
    size_t np = e->pan.n;
    PX_TRY(px_vtk_set_points(s->vtk, PX_DTYPE_F64, np, e->pan.x0, e->pan.y0, NULL));
    for (size_t b = 0; b < e->nbody; ++b)
      PX_TRY(px_vtk_add_polyline_range(s->vtk, e->pan.first[b],
                                       e->pan.first[b + 1] - e->pan.first[b], 1));
    PX_TRY(out_path(o, "bodies.vtp", path, sizeof path));
    PX_TRY(px_vtk_write(s->vtk, path));
  }
  struct px_vortex_wake *w = &e->w;
  px_vtk_reset(s->vtk);
  PX_TRY(px_vtk_set_points(s->vtk, PX_DTYPE_F64, w->n, w->x, w->y, NULL));
  PX_TRY(px_vtk_add_vertices(s->vtk));
  PX_TRY(px_vtk_add_scalar(s->vtk, PX_VTK_ASSOC_POINT, "Gamma", PX_DTYPE_F64, w->n, w->g));
  PX_TRY(px_vtk_add_scalar(s->vtk, PX_VTK_ASSOC_POINT, "core_radius", PX_DTYPE_F64, w->n, w->e));
  PX_TRY(px_vtk_add_vector(s->vtk, PX_VTK_ASSOC_POINT, "velocity", PX_DTYPE_F64, w->n, w->u, w->v,
                           NULL));
  px_vtk_set_time(s->vtk, o->time, o->step);
  snprintf(name, sizeof name, "wake_%06ld.vtp", o->step);
  PX_TRY(out_path(o, name, path, sizeof path));
  PX_TRY(px_vtk_write(s->vtk, path));
  PX_TRY(px_vtk_series_add(s->pvd_wake, o->time, name));
  /* fields on the grid: with the snapshots whose step fields.every divides,
   * and with the last state (o->final: off the snapshot schedule, so a
   * resumed run drops it as the wake's) */
  long fe = s->field_every > 0 ? s->field_every : 0;
  if (s->has_grid && (fe == 0 || o->step % fe == 0 || o->final)) {
    size_t nx = s->cells[0], ny = s->cells[1], n = nx * ny;
    double *buf = px_mem_alloc(ctx, "vortex.fields", 5 * n * sizeof(double));
    if (!buf) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for the field grid");
    double *gx = buf, *gy = buf + n, *gu = buf + 2 * n, *gv = buf + 3 * n, *gp = buf + 4 * n;
    double dx = (s->grid[1] - s->grid[0]) / (double)(nx - 1);
    double dy = (s->grid[3] - s->grid[2]) / (double)(ny - 1);
    for (size_t j = 0; j < ny; ++j)
      for (size_t i = 0; i < nx; ++i) {
        gx[j * nx + i] = s->grid[0] + (double)i * dx;
        gy[j * nx + i] = s->grid[2] + (double)j * dy;
      }
    enum px_status st = px_vortex_engine_velocity(e, n, gx, gy, gu, gv);
    if (st == PX_STATUS_OK) st = pressure(s, n, gx, gy, gu, gv, gp);
    for (size_t q = 0; st == PX_STATUS_OK && q < n; ++q)
      for (size_t b = 0; b < e->nbody; ++b)
        if (px_vortex_profile_contains(&e->body[b], gx[q], gy[q])) {
          gu[q] = gv[q] = 0.0;
          gp[q] = NAN;
        }
    if (st == PX_STATUS_OK && !s->pvd_field) st = vx_open_fields(s, o);
    if (st == PX_STATUS_OK) {
      size_t dims[3] = {nx, ny, 1};
      double org[3] = {s->grid[0], s->grid[2], 0.0}, sp[3] = {dx, dy, 1.0};
      px_vtk_reset(s->vtk);
      st = px_vtk_set_image(s->vtk, dims, org, sp);
      if (st == PX_STATUS_OK)
        st = px_vtk_add_vector(s->vtk, PX_VTK_ASSOC_POINT, "velocity", PX_DTYPE_F64, n, gu, gv,
                               NULL);
      if (st == PX_STATUS_OK)
        st = px_vtk_add_scalar(s->vtk, PX_VTK_ASSOC_POINT, "pressure", PX_DTYPE_F64, n, gp);
      px_vtk_set_time(s->vtk, o->time, o->step);
      snprintf(name, sizeof name, "fields_%06ld.vti", o->step);
      if (st == PX_STATUS_OK) st = out_path(o, name, path, sizeof path);
      if (st == PX_STATUS_OK) st = px_vtk_write(s->vtk, path);
      if (st == PX_STATUS_OK) st = px_vtk_series_add(s->pvd_field, o->time, name);
    }
    px_mem_free(ctx, buf);
    PX_TRY(st);
  }
  return PX_STATUS_OK;
}

/* loads.csv: "t [s]", "step [-]", "vortices [-]", then these columns of each
 * body (name and unit; per unit span: forces in N/m, moments in N m/m) */
#define VX_LOAD_COLS 13
static const char *const vx_load_cols[VX_LOAD_COLS][2] = {
    {"cx", "-"},           {"cy", "-"},       {"cm", "-"},       {"cx_friction", "-"},
    {"cy_friction", "-"},  {"fx", "N/m"},     {"fy", "N/m"},     {"m", "N m/m"},
    {"absorbed", "m^2/s"}, {"cx_drift", "-"}, {"cy_drift", "-"}, {"cx_wall", "-"},
    {"cy_wall", "-"}};
enum { VX_COL_CX = 0, VX_COL_CY = 1, VX_COL_CM = 2, VX_COL_CXF = 3 };

/* Header of loads.csv column q of body b ("cx [-]"; "cx_1 [-]" with several
 * bodies). */
static void vx_load_name(char *buf, size_t size, size_t q, size_t b, size_t nb) {
  if (nb == 1)
    snprintf(buf, size, "%s [%s]", vx_load_cols[q][0], vx_load_cols[q][1]);
  else
    snprintf(buf, size, "%s_%zu [%s]", vx_load_cols[q][0], b, vx_load_cols[q][1]);
}

enum px_status px_vortex_output_series(void *state, const struct px_sim_output *o) {
  struct vx_state *s = state;
  struct px_context *ctx = s->ctx;
  struct px_vortex_engine *e = s->e;
  size_t nb = e->nbody, ncol = 3 + VX_LOAD_COLS * nb;
  PX_TRY(vx_tidy(s, o));
  if (o->step == 0 && !o->resumed) return PX_STATUS_OK; /* loads exist after a step */
  if (!s->csv_loads) {
    struct px_sim_columns cols;
    PX_TRY(px_sim_columns_alloc(ctx, &cols, ncol));
    px_sim_columns_set(&cols, 0, "t [s]");
    px_sim_columns_set(&cols, 1, "step [-]");
    px_sim_columns_set(&cols, 2, "vortices [-]");
    for (size_t b = 0; b < nb; ++b)
      for (size_t q = 0; q < VX_LOAD_COLS; ++q)
        vx_load_name(cols.text[3 + b * VX_LOAD_COLS + q], sizeof cols.text[0], q, b, nb);
    enum px_status st =
        px_sim_csv_open(ctx, o, "loads.csv", ncol, cols.name, o->keep_series, &s->csv_loads);
    px_sim_columns_free(ctx, &cols);
    PX_TRY(st);
  }
  double row[3 + VX_LOAD_COLS * PX_VORTEX_MAX_BODIES];
  row[0] = o->time;
  row[1] = (double)o->step;
  row[2] = (double)e->w.n;
  double q = 0.5 * e->cfg.rho * e->cfg.vref * e->cfg.vref;
  for (size_t b = 0; b < nb; ++b) {
    const struct px_vortex_loads *L = &e->loads[b];
    double *r = row + 3 + b * VX_LOAD_COLS, c = e->cfg.ref_length[b];
    r[0] = L->cx;
    r[1] = L->cy;
    r[2] = L->cm;
    r[3] = L->fx_fric / (q * c);
    r[4] = L->fy_fric / (q * c);
    r[5] = L->fx;
    r[6] = L->fy;
    r[7] = L->m;
    r[8] = L->absorbed;
    /* the two friction estimates (vortex_cpu.c, loads): the impulse
     * balance's diffusive drift and the wall-vorticity estimate */
    r[9] = L->fx_diff / (q * c);
    r[10] = L->fy_diff / (q * c);
    r[11] = L->fx_wall / (q * c);
    r[12] = L->fy_wall / (q * c);
  }
  PX_TRY(px_csv_row(s->csv_loads, row));
  if (s->nprobe) {
    PX_TRY(px_vortex_engine_sync(e));
    if (!s->csv_probes) {
      size_t nc = 1 + 3 * s->nprobe;
      struct px_sim_columns cols;
      PX_TRY(px_sim_columns_alloc(ctx, &cols, nc));
      px_sim_columns_set(&cols, 0, "t [s]");
      for (size_t i = 0; i < s->nprobe; ++i) {
        px_sim_columns_set(&cols, 1 + 3 * i, "u_%zu [m/s]", i);
        px_sim_columns_set(&cols, 2 + 3 * i, "v_%zu [m/s]", i);
        px_sim_columns_set(&cols, 3 + 3 * i, "p_%zu [Pa]", i);
      }
      enum px_status st =
          px_sim_csv_open(ctx, o, "probes.csv", nc, cols.name, o->keep_series, &s->csv_probes);
      px_sim_columns_free(ctx, &cols);
      PX_TRY(st);
    }
    size_t n = s->nprobe;
    double *buf = px_mem_alloc(ctx, "vortex.fields", (5 * n + 1) * sizeof(double));
    if (!buf) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
    double *px = buf, *py = buf + n, *pu = buf + 2 * n, *pv = buf + 3 * n, *pr = buf + 4 * n;
    for (size_t i = 0; i < n; ++i) {
      px[i] = s->probe[2 * i];
      py[i] = s->probe[2 * i + 1];
    }
    enum px_status st = px_vortex_engine_velocity(e, n, px, py, pu, pv);
    if (st == PX_STATUS_OK) st = pressure(s, n, px, py, pu, pv, pr);
    double *prow = px_mem_alloc(ctx, "vortex.fields", (1 + 3 * n) * sizeof(double));
    if (st == PX_STATUS_OK && !prow) st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
    if (st == PX_STATUS_OK) {
      prow[0] = o->time;
      for (size_t i = 0; i < n; ++i) {
        prow[1 + 3 * i] = pu[i];
        prow[2 + 3 * i] = pv[i];
        prow[3 + 3 * i] = pr[i];
      }
      st = px_csv_row(s->csv_probes, prow);
    }
    px_mem_free(ctx, prow);
    px_mem_free(ctx, buf);
    PX_TRY(st);
  }
  return PX_STATUS_OK;
}

/* The k-th smallest of a[0..n) (k < n; a is reordered): Hoare's selection
 * with the middle element as pivot, deterministic. */
static double vx_select(double *a, size_t n, size_t k) {
  size_t lo = 0, hi = n - 1;
  while (lo < hi) {
    double pivot = a[lo + (hi - lo) / 2];
    size_t i = lo, j = hi;
    while (i <= j) {
      while (a[i] < pivot) ++i;
      while (a[j] > pivot) --j;
      if (i <= j) {
        double t = a[i];
        a[i] = a[j];
        a[j] = t;
        ++i;
        if (j == 0) break;
        --j;
      }
    }
    if (k <= j)
      hi = j;
    else if (k >= i)
      lo = i;
    else
      return a[k];
  }
  return a[k];
}

enum px_status px_vortex_output_picture(void *state, const struct px_sim_output *o) {
  struct vx_state *s = state;
  struct px_context *ctx = s->ctx;
  struct px_vortex_engine *e = s->e;
  char path[1024], name[128];
  PX_TRY(vx_tidy(s, o));
  PX_TRY(px_vortex_engine_sync(e));
  if (!s->fig) PX_TRY(px_figure_create(ctx, s->pic_w, s->pic_h, &s->fig));
  struct px_figure *f = s->fig;
  px_figure_reset(f);
  px_figure_set_colormap(f, PX_COLORMAP_COOLWARM);
  px_figure_set_field(f, "Γ", "m²/s");
  double g = s->gamma_range;
  if (!(g > 0.0)) {
    /* automatic, per picture: 1.5 times the median |Gamma|, so the typical
     * vortex is well coloured. Measured on the shipped cases' last frames:
     * gamma_max leaves the weak vortices of the Blasius plate's thick layer
     * white (median 0.07 gamma_max), the mean follows the few large merged
     * vortices of a long wake (Re = 100: mean 2.8 times the median, 1% of
     * the vortices above 40 times it); the median is 0.7-0.9 gamma_max on
     * the cylinder and airfoil cases. gamma_max for an empty wake. */
    g = e->cfg.gamma_max;
    if (e->w.n) {
      double *a = px_mem_alloc(ctx, "vortex.picture", e->w.n * sizeof(double));
      if (!a) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
      for (size_t i = 0; i < e->w.n; ++i) a[i] = fabs(e->w.g[i]);
      double med = vx_select(a, e->w.n, e->w.n / 2);
      px_mem_free(ctx, a);
      if (med > 0.0) g = 1.5 * med;
    }
  }
  px_figure_set_range(f, -g, g);
  px_figure_set_title(f, s->title ? s->title : "vortex wake");
  px_figure_set_time(f, o->time, "s");
  px_figure_set_axis_labels(f, "x [m]", "y [m]");
  px_figure_set_view(f, s->view[0], s->view[1], s->view[2], s->view[3]);
  /* an empty wake (the initial state) still gets its colour bar, so that
   * every frame of a run has the same layout */
  const double none = 0.0;
  if (e->w.n)
    PX_TRY(px_figure_add_points(f, PX_DTYPE_F64, e->w.n, e->w.x, e->w.y, e->w.g, 2.5));
  else
    PX_TRY(px_figure_add_points(f, PX_DTYPE_F64, 0, &none, &none, &none, 2.5));
  px_figure_set_color(f, 0.15, 0.15, 0.15);
  px_figure_set_fill(f, 0.45, 0.45, 0.45);
  for (size_t b = 0; b < e->nbody; ++b)
    PX_TRY(px_figure_add_polyline(f, PX_DTYPE_F64, e->body[b].n, e->body[b].x, e->body[b].y,
                                  PX_FIGURE_LINE_FILLED));
  snprintf(name, sizeof name, "wake_%06ld.png", o->step);
  PX_TRY(out_path(o, name, path, sizeof path));
  return px_figure_write_png(f, path);
}

/* The load history of the whole run, read back from loads.csv (so it covers
 * the earlier segments of a resumed run): per row the time [s], the vortex
 * count and per body C_x, C_y, C_m and the friction part of C_x, found by
 * their header names. */
struct vx_history {
  size_t n, cap, nb;
  double *t;    /* owned: n times [s] */
  double *vort; /* owned: n vortex counts */
  double *c;    /* owned: row i, body b, quantity q (VX_COL_*) at (i nb + b) 4 + q */
};

static void vx_history_free(struct px_context *ctx, struct vx_history *h) {
  px_mem_free(ctx, h->t);
  px_mem_free(ctx, h->vort);
  px_mem_free(ctx, h->c);
  memset(h, 0, sizeof *h);
}

/* Split a CSV line in place at commas (names of ours carry no quotes or
 * commas); returns the number of fields, at most max. */
static size_t vx_csv_split(char *line, char **field, size_t max) {
  size_t n = 0;
  char *p = line;
  while (n < max) {
    field[n++] = p;
    char *comma = strchr(p, ',');
    if (!comma) break;
    *comma = '\0';
    p = comma + 1;
  }
  char *end = field[n - 1] + strcspn(field[n - 1], "\r\n");
  *end = '\0';
  return n;
}

/* *found = 0 (and OK) when the run has no loads.csv (output.csv off, or no
 * step yet). */
static enum px_status vx_history_read(struct vx_state *s, const struct px_sim_output *o,
                                      struct vx_history *h, int *found) {
  struct px_context *ctx = s->ctx;
  const size_t nb = s->e->nbody, ncol = 3 + VX_LOAD_COLS * nb;
  char path[1024];
  memset(h, 0, sizeof *h);
  h->nb = nb;
  *found = 0;
  PX_TRY(out_path(o, "loads.csv", path, sizeof path));
  FILE *fp = fopen(path, "r");
  if (!fp) return PX_STATUS_OK;
  const size_t linecap = 32 * ncol + 256;
  char *line = px_mem_alloc(ctx, "vortex.history", linecap);
  char **field = px_mem_alloc(ctx, "vortex.history", (ncol + 1) * sizeof *field);
  size_t *col = px_mem_alloc(ctx, "vortex.history", (4 * nb + 2) * sizeof *col);
  enum px_status st = (line && field && col) ? PX_STATUS_OK : PX_STATUS_NOMEM;
  /* the header: where each wanted column is */
  if (st == PX_STATUS_OK && fgets(line, (int)linecap, fp)) {
    size_t nf = vx_csv_split(line, field, ncol + 1);
    for (size_t k = 0; k < 4 * nb + 2; ++k) {
      char want[64];
      if (k == 0)
        snprintf(want, sizeof want, "t [s]");
      else if (k == 1)
        snprintf(want, sizeof want, "vortices [-]");
      else
        vx_load_name(want, sizeof want, (k - 2) % 4, (k - 2) / 4, nb);
      col[k] = nf;
      for (size_t f = 0; f < nf; ++f)
        if (strcmp(field[f], want) == 0) col[k] = f;
      if (col[k] == nf)
        st = px_context_fail(ctx, PX_STATUS_FORMAT, "%s: no column '%s' in its header", path, want);
    }
    *found = st == PX_STATUS_OK;
  }
  while (st == PX_STATUS_OK && fgets(line, (int)linecap, fp)) {
    if (!strchr(line, '\n')) break; /* a torn last line */
    size_t nf = vx_csv_split(line, field, ncol + 1);
    if (nf != ncol) continue;
    if (h->n == h->cap) {
      size_t cap = h->cap ? 2 * h->cap : 1024;
      double *t = px_mem_realloc(ctx, "vortex.history", h->t, cap * sizeof(double));
      if (t) h->t = t;
      double *v = px_mem_realloc(ctx, "vortex.history", h->vort, cap * sizeof(double));
      if (v) h->vort = v;
      double *c = px_mem_realloc(ctx, "vortex.history", h->c, cap * 4 * nb * sizeof(double));
      if (c) h->c = c;
      if (!t || !v || !c) {
        st = PX_STATUS_NOMEM;
        break;
      }
      h->cap = cap;
    }
    h->t[h->n] = strtod(field[col[0]], NULL);
    if (!isfinite(h->t[h->n])) continue; /* not a row a run writes */
    h->vort[h->n] = strtod(field[col[1]], NULL);
    for (size_t k = 0; k < 4 * nb; ++k) h->c[h->n * 4 * nb + k] = strtod(field[col[2 + k]], NULL);
    ++h->n;
  }
  fclose(fp);
  px_mem_free(ctx, line);
  px_mem_free(ctx, field);
  px_mem_free(ctx, col);
  if (st == PX_STATUS_NOMEM) st = px_context_fail(ctx, st, "out of memory reading %s", path);
  if (st != PX_STATUS_OK) vx_history_free(ctx, h);
  return st;
}

/* Quantity q (VX_COL_*) of body b over rows [i0, i1) into y. */
static void vx_history_column(const struct vx_history *h, size_t b, size_t q, size_t i0, size_t i1,
                              double *y) {
  for (size_t i = i0; i < i1; ++i) y[i - i0] = h->c[(i * h->nb + b) * 4 + q];
}

/* loads.png: C_x, C_y and C_m of every body over the whole run. */
static enum px_status plot_loads(struct vx_state *s, const struct px_sim_output *o) {
  struct px_context *ctx = s->ctx;
  struct vx_history h;
  int found = 0;
  char path[1024];
  PX_TRY(vx_history_read(s, o, &h, &found));
  if (!found || h.n < 2) {
    vx_history_free(ctx, &h);
    return PX_STATUS_OK; /* no CSV output: no plot */
  }
  const size_t n = h.n, nb = h.nb;
  double *y = px_mem_alloc(ctx, "vortex.plot", n * sizeof(double));
  struct px_plot *pl = NULL;
  enum px_status st = y ? px_plot_create(ctx, 1400, 700, &pl)
                        : px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
  if (st == PX_STATUS_OK) {
    static const char *const sym[3] = {"C_x", "C_y", "C_m"};
    px_plot_set_title(pl, s->title ? s->title : "force and moment coefficients");
    px_plot_set_labels(pl, "t [s]", "C_x, C_y, C_m [-]");
    /* the impulsive start's spike (the first steps' loads are impulse
     * differences over dt) would squeeze the curves: the y range is that of
     * the data after the first tenth of the run */
    double lo = INFINITY, hi = -INFINITY;
    for (size_t b = 0; b < nb; ++b)
      for (size_t q = 0; q < 3; ++q)
        for (size_t i = n / 10; i < n; ++i) {
          double v = h.c[(i * nb + b) * 4 + q];
          lo = fmin(lo, v);
          hi = fmax(hi, v);
        }
    if (isfinite(lo) && hi > lo) {
      double pad = 0.1 * (hi - lo);
      px_plot_set_yrange(pl, lo - pad, hi + pad);
    }
    for (size_t b = 0; b < nb && st == PX_STATUS_OK; ++b)
      for (size_t q = 0; q < 3 && st == PX_STATUS_OK; ++q) {
        char nm[64];
        if (nb > 1)
          snprintf(nm, sizeof nm, "%s body %zu", sym[q], b);
        else
          snprintf(nm, sizeof nm, "%s", sym[q]);
        vx_history_column(&h, b, q, 0, n, y);
        st = px_plot_add_series(pl, nm, n, h.t, y);
      }
    if (st == PX_STATUS_OK) st = out_path(o, "loads.png", path, sizeof path);
    if (st == PX_STATUS_OK) st = px_plot_write_png(pl, path);
  }
  px_plot_free(pl);
  px_mem_free(ctx, y);
  vx_history_free(ctx, &h);
  return st;
}

enum px_status px_vortex_output_finish(void *state, const struct px_sim_output *o) {
  struct vx_state *s = state;
  PX_TRY(vx_tidy(s, o));
  px_vortex_ranks_report(s->e);
  if (s->fric_n >= 100 && s->fric_wall != 0.0) {
    double r = s->fric_drift / s->fric_wall;
    if (r < 0.75 || r > 1.33)
      px_log(s->ctx, PX_LOG_LEVEL_WARN,
             "the two friction estimates differ: mean x friction %.4g N/m from the vortices' "
             "diffusive drift, %.4g N/m from the wall vorticity (last %ld steps; the loads use "
             "the %s, friction: %s); the drift sum picks up noise from far-wake vortices in long "
             "wakes, the wall estimate read 15-45%% higher where it was checked "
             "(docs/notes/vortex.md: \"Long wakes\", \"Loads and friction\"); loads.csv has both",
             s->fric_drift / (double)s->fric_n, s->fric_wall / (double)s->fric_n, s->fric_n,
             s->e->cfg.friction_wall ? "wall vorticity" : "drift",
             s->e->cfg.friction_wall ? "wall" : "drift");
  }
  if (s->csv_loads) PX_TRY(px_csv_close(s->csv_loads));
  s->csv_loads = NULL;
  if (s->csv_probes) PX_TRY(px_csv_close(s->csv_probes));
  s->csv_probes = NULL;
  /* rendering draws the load plot again from the run's loads.csv: a picture
     (none with output.png: false) */
  return o->pictures ? plot_loads(s, o) : PX_STATUS_OK;
}

/* "body_1." before the names of body 1's quantities when there are several
 * bodies, "" with one. */
static void vx_body_prefix(char *buf, size_t size, size_t b, size_t nb) {
  if (nb > 1)
    snprintf(buf, size, "body_%zu.", b);
  else
    buf[0] = '\0';
}

/* summary.json: over the window [from, to] of the whole run's loads.csv
 * (default: the second half of the time so far), per body the mean and
 * standard deviation of C_x, C_y, C_m and the mean friction part of C_x;
 * whether C_y oscillates periodically (px_vortex_report_oscillation) and
 * then its frequency, Strouhal number f c / v_ref and amplitude; the
 * Reynolds number v_ref c / nu (c the reference length); the vortex count. */
enum px_status px_vortex_output_report(void *state, const struct px_sim_output *o,
                                       struct px_summary *sum) {
  struct vx_state *s = state;
  struct px_context *ctx = s->ctx;
  const struct px_vortex_engine *e = s->e;
  const size_t nb = e->nbody;
  char name[96], about[256], pre[32];
  px_summary_int(sum, "vortices", (long)e->w.n, "-", "vortices in the wake at the last step");
  for (size_t b = 0; b < nb; ++b) {
    vx_body_prefix(pre, sizeof pre, b, nb);
    snprintf(name, sizeof name, "%sreynolds", pre);
    px_summary_real(sum, name, e->cfg.vref * e->cfg.ref_length[b] / e->cfg.nu, "-",
                    "Reynolds number v_ref c / nu (c the reference length)");
  }
  struct vx_history h;
  int found = 0;
  PX_TRY(vx_history_read(s, o, &h, &found));
  if (!found || h.n == 0) {
    vx_history_free(ctx, &h);
    return PX_STATUS_OK; /* no loads.csv (output.csv off, or no step yet) */
  }
  double t1 = s->report_to > 0.0 ? s->report_to : o->time;
  double t0 = s->report_from >= 0.0 ? s->report_from : 0.5 * o->time;
  size_t i0 = 0, i1 = 0;
  while (i0 < h.n && h.t[i0] < t0 - 1e-9 * fabs(t0)) ++i0;
  i1 = i0;
  while (i1 < h.n && h.t[i1] <= t1 + 1e-9 * fabs(t1)) ++i1;
  size_t m = i1 - i0;
  px_summary_real(sum, "window_from", t0, "s",
                  "start of the averaging window (vortex.report.from)");
  px_summary_real(sum, "window_to", t1, "s", "end of the averaging window (vortex.report.to)");
  px_summary_int(sum, "window_samples", (long)m, "-", "rows of loads.csv in the window");
  double *y = m ? px_mem_alloc(ctx, "vortex.report", m * sizeof(double)) : NULL;
  if (m && !y) {
    vx_history_free(ctx, &h);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
  }
  static const char *const key[4] = {"cx", "cy", "cm", "cx_friction"};
  static const char *const what[4] = {
      "force coefficient along x (the drag for a free stream along +x)",
      "force coefficient along y (the lift for a free stream along +x)",
      "moment coefficient about the moment centre (counter-clockwise positive)",
      "friction part of C_x"};
  enum px_status st = PX_STATUS_OK;
  for (size_t b = 0; b < nb && m && st == PX_STATUS_OK; ++b) {
    vx_body_prefix(pre, sizeof pre, b, nb);
    for (size_t q = 0; q < 4; ++q) {
      double mean, sd;
      vx_history_column(&h, b, q, i0, i1, y);
      px_vortex_report_stats(y, m, &mean, &sd);
      snprintf(name, sizeof name, "%s%s_mean", pre, key[q]);
      snprintf(about, sizeof about, "mean over the window of the %s", what[q]);
      px_summary_real(sum, name, mean, "-", about);
      if (q == 3) continue;
      snprintf(name, sizeof name, "%s%s_std", pre, key[q]);
      snprintf(about, sizeof about, "standard deviation over the window of the %s", what[q]);
      px_summary_real(sum, name, sd, "-", about);
    }
    struct px_vortex_oscillation osc;
    vx_history_column(&h, b, VX_COL_CY, i0, i1, y);
    st = px_vortex_report_oscillation(ctx, h.t + i0, y, m, &osc);
    if (st != PX_STATUS_OK) break;
    snprintf(name, sizeof name, "%slift_periodic", pre);
    px_summary_bool(sum, name, osc.periodic,
                    "C_y oscillates periodically in the window (three cycles or more of one "
                    "frequency: docs/vortex.md, \"Outputs\")");
    if (!osc.periodic) continue;
    snprintf(name, sizeof name, "%sstrouhal", pre);
    px_summary_real(sum, name, osc.frequency * e->cfg.ref_length[b] / e->cfg.vref, "-",
                    "Strouhal number f c / v_ref of the lift (c the reference length)");
    snprintf(name, sizeof name, "%slift_frequency", pre);
    px_summary_real(sum, name, osc.frequency, "Hz", "frequency f of the lift's oscillation");
    snprintf(name, sizeof name, "%scy_amplitude", pre);
    px_summary_real(sum, name, osc.amplitude, "-",
                    "amplitude of C_y: mean (max - min) / 2 over the cycles");
    snprintf(name, sizeof name, "%slift_cycles", pre);
    px_summary_int(sum, name, (long)osc.cycles, "-", "whole lift cycles in the window");
  }
  px_mem_free(ctx, y);
  vx_history_free(ctx, &h);
  return st;
}
