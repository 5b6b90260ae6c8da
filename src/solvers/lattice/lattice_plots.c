/* End-of-run plots (px_lattice_finish) and the summary.json quantities
 * (px_lattice_report) of the lattice solver. Both read probes.csv back, so
 * that they cover the whole run also when it was resumed. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/ioutil.h"
#include "partix/file.h"
#include "partix/memory.h"
#include "solvers/lattice/lattice.h"
#include "solvers/summary.h"

/* probes.csv of the run read back (the whole run, also across resumes):
 * the rows up to time tmax [s], ncol values each (owned, px_mem). */
struct px_lattice_rows {
  double *v;
  size_t nrow, ncol;
};

/* Read the rows; a missing file, or one written with other columns (another
 * case), gives no rows. */
static enum px_status px_lattice_read_rows(struct px_lattice *L, const char *dir, double tmax,
                                           struct px_lattice_rows *r) {
  char path[PX_LATTICE_PATH_MAX], *text = NULL, *p, *line_end;
  size_t len = 0, cap = 0, ncol = px_lattice_columns(L), commas = 0;
  enum px_status st;
  memset(r, 0, sizeof *r);
  r->ncol = ncol;
  PX_TRY(px_file_join(L->ctx, path, sizeof path, dir, "probes.csv"));
  st = px_ioutil_read_file(L->ctx, path, &text, &len);
  if (st == PX_STATUS_NOT_FOUND) {
    px_context_clear(L->ctx);
    return PX_STATUS_OK;
  }
  PX_TRY(st);
  /* the header: as many columns as this case writes (probe names hold no
   * commas) */
  line_end = strchr(text, '\n');
  for (p = text; line_end && p < line_end; ++p) commas += *p == ',';
  if (!line_end || commas + 1 != ncol) {
    px_mem_free(L->ctx, text);
    return PX_STATUS_OK;
  }
  p = line_end + 1;
  while (*p) {
    size_t k = 0;
    double *row;
    line_end = strchr(p, '\n');
    if (!line_end) break; /* a torn last line */
    if (r->nrow == cap) {
      size_t ncap = cap ? 2 * cap : 256;
      double *grown =
          (double *)px_mem_realloc(L->ctx, "lattice.csv", r->v, ncap * ncol * sizeof(double));
      if (!grown) {
        px_mem_free(L->ctx, text);
        return PX_STATUS_NOMEM;
      }
      r->v = grown;
      cap = ncap;
    }
    row = r->v + r->nrow * ncol;
    while (k < ncol && p < line_end) {
      char *end;
      row[k] = strtod(p, &end);
      if (end == p) break;
      ++k;
      p = end;
      if (*p == ',') ++p;
    }
    if (k == ncol && row[0] <= tmax) ++r->nrow;
    p = line_end + 1;
  }
  px_mem_free(L->ctx, text);
  return PX_STATUS_OK;
}

/* A line plot of one quantity of every probe from the rows: comp 0..3 (ux uy
 * uz von_mises), or -1: the displacement component that moves most. */
static enum px_status px_lattice_plot(struct px_lattice *L, const struct px_sim_output *o,
                                      const struct px_lattice_rows *rows, const char *file,
                                      const char *title, const char *ylabel, int comp) {
  struct px_plot *plot = NULL;
  char path[PX_LATTICE_PATH_MAX], name[96];
  size_t i, k;
  double *tx, *yy;
  enum px_status st;
  static const char *const comp_name[4] = {"ux", "uy", "uz", "von_mises"};
  PX_TRY(px_plot_create(L->ctx, 1000, 600, &plot));
  tx = (double *)px_mem_alloc(L->ctx, "lattice.plot", rows->nrow * sizeof(double));
  yy = (double *)px_mem_alloc(L->ctx, "lattice.plot", rows->nrow * sizeof(double));
  st = tx && yy ? PX_STATUS_OK : PX_STATUS_NOMEM;
  snprintf(path, sizeof path, "%s%s%s", L->title, L->title[0] ? " - " : "", title);
  px_plot_set_title(plot, path);
  px_plot_set_labels(plot, "t [s]", ylabel);
  for (i = 0; st == PX_STATUS_OK && i < L->nprobe; ++i) {
    int show = comp;
    if (comp < 0) {
      double big[3] = {0, 0, 0};
      int a;
      for (k = 0; k < rows->nrow; ++k)
        for (a = 0; a < 3; ++a)
          big[a] = fmax(big[a], fabs(rows->v[k * rows->ncol + 1 + 4 * i + (size_t)a]));
      show = big[2] >= big[1] && big[2] >= big[0] ? 2 : (big[1] >= big[0] ? 1 : 0);
    }
    for (k = 0; k < rows->nrow; ++k) {
      tx[k] = rows->v[k * rows->ncol];
      yy[k] = rows->v[k * rows->ncol + 1 + 4 * i + (size_t)show];
    }
    snprintf(name, sizeof name, "%s.%s", L->probes[i].name, comp_name[show]);
    st = px_plot_add_series(plot, name, rows->nrow, tx, yy);
  }
  if (st == PX_STATUS_OK) st = px_file_join(L->ctx, path, sizeof path, o->dir, file);
  if (st == PX_STATUS_OK) st = px_plot_write_png(plot, path);
  px_mem_free(L->ctx, tx);
  px_mem_free(L->ctx, yy);
  px_plot_free(plot);
  return st;
}

/* A line plot of one run-wide column of the rows (offset `tail` after the
 * probes' columns) against time; `level` > 0 adds it as a horizontal line
 * named level_name (e.g. a tolerance). */
static enum px_status px_lattice_plot_column(struct px_lattice *L, const struct px_sim_output *o,
                                             const struct px_lattice_rows *rows, const char *file,
                                             const char *title, const char *ylabel,
                                             const char *name, size_t tail, int log_y, double level,
                                             const char *level_name) {
  struct px_plot *plot = NULL;
  char path[PX_LATTICE_PATH_MAX];
  size_t k, col = 1 + 4 * L->nprobe + tail;
  double *tx, *yy, tl[2], yl[2];
  enum px_status st;
  PX_TRY(px_plot_create(L->ctx, 1000, 600, &plot));
  tx = (double *)px_mem_alloc(L->ctx, "lattice.plot", rows->nrow * sizeof(double));
  yy = (double *)px_mem_alloc(L->ctx, "lattice.plot", rows->nrow * sizeof(double));
  st = tx && yy ? PX_STATUS_OK : PX_STATUS_NOMEM;
  snprintf(path, sizeof path, "%s%s%s", L->title, L->title[0] ? " - " : "", title);
  px_plot_set_title(plot, path);
  px_plot_set_labels(plot, "t [s]", ylabel);
  px_plot_set_log_y(plot, log_y);
  for (k = 0; st == PX_STATUS_OK && k < rows->nrow; ++k) {
    tx[k] = rows->v[k * rows->ncol];
    yy[k] = rows->v[k * rows->ncol + col];
  }
  if (st == PX_STATUS_OK) st = px_plot_add_series(plot, name, rows->nrow, tx, yy);
  tl[0] = rows->v[0];
  tl[1] = rows->v[(rows->nrow - 1) * rows->ncol];
  yl[0] = yl[1] = level;
  if (st == PX_STATUS_OK && level > 0) st = px_plot_add_series(plot, level_name, 2, tl, yl);
  if (st == PX_STATUS_OK) st = px_file_join(L->ctx, path, sizeof path, o->dir, file);
  if (st == PX_STATUS_OK) st = px_plot_write_png(plot, path);
  px_mem_free(L->ctx, tx);
  px_mem_free(L->ctx, yy);
  px_plot_free(plot);
  return st;
}

/* End of a run (and `partix render`): the probe plots from probes.csv, so
 * that they cover the whole run, resumed or not; the quasi-static verdict. */
enum px_status px_lattice_finish(void *state, const struct px_sim_output *o) {
  struct px_lattice *L = (struct px_lattice *)state;
  struct px_lattice_rows rows;
  enum px_status st = PX_STATUS_OK;
  PX_TRY(px_lattice_resume_clean(L, o));
  if (!o->render && isfinite(L->drawn_scale) && L->picture_scale <= 0)
    px_sim_note_auto(L->sim, "lattice.picture.scale",
                     "%.4g (the last picture's: the largest displacement drawn as 5%% of the "
                     "body; each picture chooses its own and gives it in its title)",
                     L->drawn_scale);
  if (!o->render && L->quasi_static) {
    px_sim_note_auto(L->sim, "lattice.damping",
                     "%.6g 1/s at the end (quasi_static: adaptive, 2 x the Rayleigh-quotient "
                     "frequency; the damping column of probes.csv)",
                     L->alpha);
    if (!L->converged)
      px_log(L->ctx, PX_LOG_LEVEL_WARN,
             "lattice: statics not reached in %ld steps (t = %.6g s): static_error %.3g, "
             "lattice.static_tolerance %.3g%s; continue with `partix resume %s/checkpoint.pxc "
             "--more N`",
             o->step, o->time, L->static_error, L->static_tol,
             o->time < L->settle_time ? " (the loads still change)" : "", o->dir);
  }
  if (!o->pictures) return PX_STATUS_OK; /* output.png: false */
  PX_TRY(px_lattice_read_rows(L, o->dir, o->time + 0.5 * px_sim_dt(L->sim), &rows));
  if (rows.nrow >= 2 && L->nprobe > 0) {
    st = px_lattice_plot(L, o, &rows, "probes.png", "probe displacement", "displacement [m]", -1);
    if (st == PX_STATUS_OK)
      st = px_lattice_plot(L, o, &rows, "probes_von_mises.png", "probe von Mises stress",
                           "von Mises [Pa]", 3);
  }
  if (st == PX_STATUS_OK && rows.nrow >= 2 && L->quasi_static)
    st =
        px_lattice_plot_column(L, o, &rows, "static_error.png", "convergence to statics",
                               "static_error [-]", "estimated relative distance from statics",
                               PX_LATTICE_COL_STATIC, 1, L->static_tol, "lattice.static_tolerance");
  if (st == PX_STATUS_OK && rows.nrow >= 2 && L->m.fracture)
    st = px_lattice_plot_column(L, o, &rows, "broken_links.png", "fracture", "broken links [-]",
                                "broken_links", PX_LATTICE_COL_BROKEN, 0, 0.0, NULL);
  px_mem_free(L->ctx, rows.v);
  return st;
}

/* summary.json: the quantities a user reports, from probes.csv (the whole
 * run, also across resumes; with output.csv off, from the state now). A
 * quasi-static run reports its last state (the static solution), any other
 * the largest values over the run's rows (sampled every output.log_every
 * steps). */
enum px_status px_lattice_report(void *state, const struct px_sim_output *o,
                                 struct px_summary *sum) {
  struct px_lattice *L = (struct px_lattice *)state;
  struct px_lattice_rows rows;
  size_t base = 1 + 4 * L->nprobe, k, i, best_vm = 0, best_u = 0;
  const double *last;
  double *own = NULL, first_break = NAN;
  char name[128];
  int whole;
  PX_TRY(px_lattice_read_rows(L, o->dir, o->time + 0.5 * px_sim_dt(L->sim), &rows));
  whole = rows.nrow > 0;
  if (!whole) {
    /* no probes.csv: one row of the state now */
    struct px_sim_output now = *o;
    size_t cell;
    now.render = 0;
    PX_TRY(px_lattice_fetch(L, &now));
    own = (double *)px_mem_calloc(L->ctx, "lattice.report", rows.ncol, sizeof(double));
    if (!own) return PX_STATUS_NOMEM;
    own[0] = o->time;
    for (i = 0; i < L->nprobe; ++i)
      for (k = 0; k < L->probes[i].count; ++k) {
        size_t j = L->probes[i].cells[k];
        int a;
        for (a = 0; a < 3; ++a)
          own[1 + 4 * i + (size_t)a] += L->fu[3 * j + (size_t)a] / (double)L->probes[i].count;
        own[1 + 4 * i + 3] += L->fvm[j] / (double)L->probes[i].count;
      }
    own[base + PX_LATTICE_COL_BROKEN] = (double)L->vt->broken(L->e);
    own[base + PX_LATTICE_COL_DAMPING] = L->alpha;
    cell = px_lattice_argmax(L, 0, &own[base + PX_LATTICE_COL_VM]);
    px_lattice_centre_tidy(L, cell, &own[base + PX_LATTICE_COL_VM + 1]);
    cell = px_lattice_argmax(L, 1, &own[base + PX_LATTICE_COL_U]);
    px_lattice_centre_tidy(L, cell, &own[base + PX_LATTICE_COL_U + 1]);
    rows.v = own;
    rows.nrow = 1;
  }
  last = rows.v + (rows.nrow - 1) * rows.ncol;
  if (L->quasi_static) {
    best_vm = best_u = rows.nrow - 1;
  } else {
    for (k = 0; k < rows.nrow; ++k) {
      const double *r = rows.v + k * rows.ncol;
      if (r[base + PX_LATTICE_COL_VM] > rows.v[best_vm * rows.ncol + base + PX_LATTICE_COL_VM])
        best_vm = k;
      if (r[base + PX_LATTICE_COL_U] > rows.v[best_u * rows.ncol + base + PX_LATTICE_COL_U])
        best_u = k;
    }
  }
  for (k = 0; k < rows.nrow; ++k)
    if (rows.v[k * rows.ncol + base + PX_LATTICE_COL_BROKEN] > 0) {
      first_break = rows.v[k * rows.ncol];
      break;
    }
  px_summary_int(sum, "elements", (long)L->m.grid.count, "-", "elements of the body");
  if (L->quasi_static) {
    px_summary_bool(sum, "static_converged", L->converged,
                    "static equilibrium reached: static_error <= lattice.static_tolerance");
    px_summary_real(sum, "static_error", L->static_error, "-",
                    "the estimated relative distance from the static solution at the end "
                    "(probes.csv static_error)");
    px_summary_real(sum, "static_tolerance", L->static_tol, "-", "lattice.static_tolerance");
  }
  {
    const double *r = rows.v + best_vm * rows.ncol;
    px_summary_real(sum, "von_mises_max", r[base + PX_LATTICE_COL_VM], "Pa",
                    L->quasi_static ? "largest element von Mises stress of the last state"
                                    : "largest element von Mises stress over the run");
    px_summary_vector(sum, "von_mises_max_at", 3, r + base + PX_LATTICE_COL_VM + 1, "m",
                      "centre of that element (undeformed)");
    if (!L->quasi_static)
      px_summary_real(sum, "von_mises_max_time", r[0], "s", "time of that maximum");
    r = rows.v + best_u * rows.ncol;
    px_summary_real(sum, "displacement_max", r[base + PX_LATTICE_COL_U], "m",
                    L->quasi_static ? "largest element displacement |u| of the last state"
                                    : "largest element displacement |u| over the run");
    px_summary_vector(sum, "displacement_max_at", 3, r + base + PX_LATTICE_COL_U + 1, "m",
                      "centre of that element (undeformed)");
    if (!L->quasi_static)
      px_summary_real(sum, "displacement_max_time", r[0], "s", "time of that maximum");
  }
  if (!whole)
    px_summary_text(sum, "sampled", "last state only",
                    "output.csv is off: the figures above are of the last state, not the run");
  {
    /* read back from probes.csv, a file of the run folder that may come
     * from elsewhere: a count only when it is one (a cast of 1e30 or NaN
     * is undefined), else the engine's */
    double b = last[base + PX_LATTICE_COL_BROKEN];
    long nb = b >= 0.0 && b <= 9e15 && b == floor(b) ? (long)b : L->vt->broken(L->e);
    px_summary_int(sum, "broken_links", nb, "-", "bonds broken so far");
  }
  if (isfinite(first_break))
    px_summary_real(sum, "first_break_time", first_break, "s",
                    "first probes.csv row with a broken bond");
  for (i = 0; i < L->nprobe; ++i) {
    snprintf(name, sizeof name, "probe.%s.u", L->probes[i].name);
    px_summary_vector(sum, name, 3, last + 1 + 4 * i, "m",
                      "mean displacement of the probe's elements at the end");
    snprintf(name, sizeof name, "probe.%s.von_mises", L->probes[i].name);
    px_summary_real(sum, name, last[1 + 4 * i + 3], "Pa",
                    "mean von Mises stress of the probe's elements at the end");
  }
  px_mem_free(L->ctx, rows.v);
  return PX_STATUS_OK;
}
