/* Block 2, the sheet near the wall (sheet_exact): the exact field of the
 * sheet on panel k at (xi, yi) minus the smoothed one of its newborns, added
 * to (*cu, *cv) where panel k's midpoint lies within 2 L_k + eps. Inline:
 * the cpu engine calls it for every vortex near every panel. Include after
 * kernels/px_kernel.h compiled in double (PX_REAL double) and
 * vortex_core_impl.h. */
#ifndef PX_VORTEX_SHEET_H
#define PX_VORTEX_SHEET_H

#include "kernels/biot_savart.h"
#include "solvers/vortex/vortex_core_impl.h"
#include "solvers/vortex/vortex_panels.h"

/* Is (xi, yi) within reach of panel k's sheet term: its midpoint within
 * 2 L_k + eps? */
static inline int px_vortex_sheet_reach(const struct px_vortex_engine *e, size_t k, double xi,
                                        double yi) {
  const struct px_vortex_panels *pp = &e->pan;
  double mx = 0.5 * (pp->x0[k] + pp->x1[k]) - xi, my = 0.5 * (pp->y0[k] + pp->y1[k]) - yi;
  double lim = 2.0 * pp->len[k] + e->cfg.eps;
  return !(mx * mx + my * my > lim * lim);
}

/* The smoothed field at (xi, yi) of panel k's newborns, without the 1/(2 pi),
 * into (*du, *dv). */
static inline void px_vortex_sheet_newborns(const struct px_vortex_engine *e, size_t k, double xi,
                                            double yi, double *du, double *dv) {
  const struct px_vortex_wake *w = &e->w;
  const double eps2 = e->cfg.eps * e->cfg.eps;
  double su = 0.0, sv = 0.0;
  for (size_t j = e->born_first[k]; j < e->born_first[k + 1]; ++j) {
    px_real2 bk = px_biot_savart_term(xi - w->x[j], yi - w->y[j], w->g[j], eps2);
    su += bk.x;
    sv += bk.y;
  }
  *du = su;
  *dv = sv;
}

static inline void px_vortex_sheet_term(const struct px_vortex_engine *e, size_t k, double xi,
                                        double yi, double *cu, double *cv) {
  const struct px_vortex_panels *pp = &e->pan;
  if (!px_vortex_sheet_reach(e, k, xi, yi)) return;
  double su, sv, du, dv;
  px_vortex_segment_velocity(pp->x0[k], pp->y0[k], pp->x1[k], pp->y1[k], xi, yi, &su, &sv);
  px_vortex_sheet_newborns(e, k, xi, yi, &du, &dv);
  *cu += e->sol[k] * su - du * (0.5 / VX_PI);
  *cv += e->sol[k] * sv - dv * (0.5 / VX_PI);
}

#endif
