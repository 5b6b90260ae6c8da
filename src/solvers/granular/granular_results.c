/* The granular solver's results in memory (partix/results.h): the discs as
 * the snapshots (particles_*.vtp) hold them, and the per-segment statistics
 * of the reported contours as segments_*.csv holds them. */
#include "solvers/granular/granular_impl.h"
#include "solvers/granular/granular_output.h"

static enum px_status px_gran_results_discs(struct px_gran_run *r, struct px_results *out) {
  const struct px_gran_sys *s = r->sys;
  const size_t n = s->n;
  double *x = px_results_add(out, "x", "m", PX_VIEW_F64, n, 1, NULL);
  double *y = px_results_add(out, "y", "m", PX_VIEW_F64, n, 1, NULL);
  double *vx = px_results_add(out, "vx", "m/s", PX_VIEW_F64, n, 1, NULL);
  double *vy = px_results_add(out, "vy", "m/s", PX_VIEW_F64, n, 1, NULL);
  double *w = px_results_add(out, "spin", "rad/s", PX_VIEW_F64, n, 1, NULL);
  double *rad = px_results_add(out, "radius", "m", PX_VIEW_F64, n, 1, NULL);
  double *m = px_results_add(out, "mass", "kg", PX_VIEW_F64, n, 1, NULL);
  double *id = px_results_add(out, "id", "", PX_VIEW_F64, n, 1, NULL);
  double *z = px_results_add(out, "contacts", "", PX_VIEW_F64, n, 1, NULL);
  if (!x || !y || !vx || !vy || !w || !rad || !m || !id || !z)
    return px_context_fail(r->ctx, PX_STATUS_NOMEM, "out of memory (results of %zu discs)", n);
  px_gran_sys_export(s, x, y, vx, vy, w, rad, m, id);
  px_gran_sys_coordination(s, x, y, rad, z);
  return PX_STATUS_OK;
}

/* The segments of every reported contour, contour after contour. */
static enum px_status px_gran_results_segments(struct px_gran_run *r, double t,
                                               struct px_results *out) {
  const struct px_gran_geom *g = &r->geom;
  double *col[PX_GRAN_SEG_NCOL], *contour, **tmp;
  size_t n = 0, c, k, at = 0;
  int q;
  PX_TRY(px_gran_out_view(r));
  for (c = 0; c < g->ncontours; ++c)
    if (r->report[c]) n += g->contours[c].count;
  contour = px_results_add(out, "contour", "", PX_VIEW_F64, n, 1, NULL);
  for (q = 0; q < PX_GRAN_SEG_NCOL; ++q)
    col[q] =
        px_results_add(out, px_gran_seg_names[q], px_gran_seg_unit(r, q), PX_VIEW_F64, n, 1, NULL);
  for (q = 0; q < PX_GRAN_SEG_NCOL; ++q)
    if (!col[q]) contour = NULL;
  if (!contour) return px_context_fail(r->ctx, PX_STATUS_NOMEM, "out of memory (segment results)");
  for (c = 0; c < g->ncontours; ++c) {
    const size_t cnt = g->contours[c].count;
    if (!r->report[c]) continue;
    tmp = px_gran_cols_alloc(r->ctx, cnt);
    if (!tmp) return px_context_fail(r->ctx, PX_STATUS_NOMEM, "out of memory (segment results)");
    px_gran_seg_table(r, c, t, tmp);
    for (k = 0; k < cnt; ++k) {
      contour[at + k] = (double)c;
      for (q = 0; q < PX_GRAN_SEG_NCOL; ++q) col[q][at + k] = tmp[q][k];
    }
    at += cnt;
    px_gran_cols_free(r->ctx, tmp);
  }
  return PX_STATUS_OK;
}

enum px_status px_gran_results(void *state, const struct px_sim_output *o,
                               enum px_results_kind kind, struct px_results *out) {
  struct px_gran_run *r = state;
  PX_TRY(px_gran_sync(r));
  if (kind == PX_RESULTS_STATE) return px_gran_results_discs(r, out);
  if (kind == PX_RESULTS_SEGMENTS) return px_gran_results_segments(r, o->time, out);
  return PX_STATUS_UNSUPPORTED;
}
