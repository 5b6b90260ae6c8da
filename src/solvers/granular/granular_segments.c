/* The per-segment report of the granular solver: the columns of the
 * segment table along a contour (read by the csv and vtk outputs and the
 * pictures), and what the outputs and the pictures share (world positions
 * of the contours, tidying a resumed run's stale picture). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "partix/file.h"
#include "partix/memory.h"
#include "solvers/granular/granular_output.h"
#include "solvers/granular/wall_kernel.h"

const char *const px_gran_seg_names[PX_GRAN_SEG_NCOL] = {"s",
                                                         "x",
                                                         "y",
                                                         "nx",
                                                         "ny",
                                                         "length",
                                                         "impacts",
                                                         "impact_rate",
                                                         "vn_mean",
                                                         "vn_rms",
                                                         "vn_max",
                                                         "vt_mean",
                                                         "energy_n",
                                                         "energy_t",
                                                         "energy_n_length",
                                                         "energy_t_length",
                                                         "energy_n_area",
                                                         "energy_t_area",
                                                         "impulse",
                                                         "load",
                                                         "sliding_work",
                                                         "archard_volume",
                                                         "archard_depth",
                                                         "finnie_volume",
                                                         "finnie_depth",
                                                         "contact_time",
                                                         "contact_fraction",
                                                         "duration_mean",
                                                         "first_impact",
                                                         "last_impact",
                                                         "hardening",
                                                         "residual_stress"};

/* Units of the columns; hardening and residual stress take the case's
 * (px_gran_seg_unit). */
static const char *const px_gran_seg_units[PX_GRAN_SEG_NCOL] = {
    "m",   "m",   "m", "-",   "-",   "m",     "-",     "1/s", "m/s", "m/s", "m/s",
    "m/s", "J",   "J", "J/m", "J/m", "J/m^2", "J/m^2", "N s", "N/m", "J",   "m^3",
    "m",   "m^3", "m", "s",   "-",   "s",     "s",     "s",   "",    ""};

/* World position of vertex k of the geometry (contour c) at frames. */
void px_gran_world(const struct px_gran_run *r, size_t c, size_t k, double *x, double *y) {
  const double *f = r->sys->frames + c * PX_GRAN_CTR_COUNT;
  const double ux = r->geom.ax[k] - f[PX_GRAN_CTR_PX], uy = r->geom.ay[k] - f[PX_GRAN_CTR_PY];
  *x = f[PX_GRAN_CTR_PX] + f[PX_GRAN_CTR_COS] * ux - f[PX_GRAN_CTR_SIN] * uy + f[PX_GRAN_CTR_DX];
  *y = f[PX_GRAN_CTR_PY] + f[PX_GRAN_CTR_SIN] * ux + f[PX_GRAN_CTR_COS] * uy + f[PX_GRAN_CTR_DY];
}

/* A resumed run removes the picture an earlier segment drew only because it
 * ended off the png schedule (struct px_sim_output: drop_picture), at the
 * first output of the run, whichever it is. */
void px_gran_resume_tidy(struct px_gran_run *r, const struct px_sim_output *o) {
  char name[64], path[1024];
  if (!o->resumed || o->render || r->resume_tidied) return;
  r->resume_tidied = 1;
  if (o->drop_picture < 0) return;
  snprintf(name, sizeof name, "particles_%08ld.png", o->drop_picture);
  if (px_file_join(r->ctx, path, sizeof path, o->dir, name) == PX_STATUS_OK) remove(path);
}

const char *px_gran_seg_unit(const struct px_gran_run *r, int q) {
  if (q == PX_GRAN_SEG_HARD) return r->hard_unit[0] ? r->hard_unit : "-";
  if (q == PX_GRAN_SEG_RES) return r->res_unit[0] ? r->res_unit : "-";
  return px_gran_seg_units[q];
}

/* Fill cols[q][k] (k over the segments of contour c) from r->view. */
void px_gran_seg_table(const struct px_gran_run *r, size_t c, double t, double **cols) {
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

double **px_gran_cols_alloc(struct px_context *ctx, size_t n) {
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

void px_gran_cols_free(struct px_context *ctx, double **cols) {
  int q;
  if (!cols) return;
  for (q = 0; q < PX_GRAN_SEG_NCOL; ++q) px_mem_free(ctx, cols[q]);
  px_mem_free(ctx, cols);
}
