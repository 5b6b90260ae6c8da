/* Block 3 of the `cpu` engine: eps* and the VVD diffusive velocities in one
 * neighbour search over the wake's tree (vortex_core.h; the formula in
 * vortex_kernel.h, shared with vortex.cl). */
/* sqrt never sees a negative argument here; without errno the VVD neighbour
 * loops vectorize (see vortex_core.c). */
#pragma GCC optimize("no-math-errno")
#include "solvers/vortex/vortex_core.h"

#include <math.h>
#include <omp.h>
#include <string.h>
#include <time.h>

#include "partix/memory.h"
#include "partix/nbody.h"
#include "partix/timer.h"
#include "solvers/vortex/vortex_core_impl.h"
#include "solvers/vortex/vortex_host.h"
#include "solvers/vortex/vortex_ranks.h"

#define PX_REAL double
#include "kernels/px_kernel.h"
#include "solvers/vortex/vortex_kernel.h"

/* ------------------------------------------------------------------------- */
/* Block 3: diffusive velocities (VVD) */

/* eps* of a vortex from the squared distances d2 (ascending, INFINITY where
 * fewer than 3 other vortices exist) to its 3 nearest (vx_eps_star). */
static double eps_value(const struct px_vortex_config *cfg, const double *d2) {
  return vx_eps_star(d2[0], d2[1], d2[2], cfg->eps_min);
}

/* Vortices per group of the VVD's neighbour search: one tree query per group,
 * each vortex then filtering the group's candidates (4 leaves of 16 measured
 * 5% faster in the diffusive block than one; with leaves of 32, 4 of them
 * another 3% faster than 2 and than 8: vortex_step, 2026-11-26). The lists
 * and sums do not depend on it. */
#define VX_GROUP 128

/* The VVD's guess of a vortex's eps*: this factor times its eps* of the step
 * before (px_vortex_engine_diffusive); it sets the group's reach and where
 * the 3 nearest are searched. */
#define VX_EPS_GUESS 1.1

/* Pack the neighbours of the vortex at sorted position sp within
 * sqrt(r2max) over the runs b->fl[0..2 nl) of sorted positions into b->pd,
 * grown to every candidate plus 8 of slack (the pack's vector stores).
 * Returns their number, (size_t)-1 when out of memory. */
static size_t vvd_pack_runs(struct px_vortex_engine *e, struct px_vortex_nbuf *b, const double *sg,
                            size_t nl, uint32_t sp, double r2max) {
  const struct px_vortex_tree *t = &e->tree;
  const uint32_t *lv = b->fl;
  size_t ncand = 8;
  for (size_t l = 0; l < nl; ++l) ncand += lv[2 * l + 1] - lv[2 * l];
  if (!px_vortex_arrays_reserve(e, &b->pd, &b->pd_cap, ncand, 3)) return (size_t)-1;
  double *pdx = b->pd, *pdy = b->pd + b->pd_cap, *pg = b->pd + 2 * b->pd_cap;
  return px_vortex_vvd_pack(t->sx, t->sy, sg, lv, nl, sp, t->sx[sp], t->sy[sp], r2max, pdx, pdy,
                            pg);
}

/* The VVD pair sums over the np neighbours packed in pdx, pdy, pg (offsets from the
 * vortex and circulations), in one vector loop; out: I1, sum |Gamma_j|
 * exp(-r/e), I2x, I2y. */
static void vvd_pair_sums(double *pdx, double *pdy, double *pg, size_t np, double inv_e,
                          double tiny2, double out[4]) {
  /* padded with zero terms to a multiple of 8 (the slack): no scalar
   * remainder, whose exponential chains cost as much as a vector pass */
  size_t npad = (np + 7) & ~(size_t)7;
  for (size_t q = np; q < npad; ++q) pdx[q] = pdy[q] = pg[q] = 0.0;
  double i1 = 0.0, i1abs = 0.0, i2x = 0.0, i2y = 0.0;
  /* the distances and their reciprocals first, a chunk at a time (on the
   * stack): px_vortex_radii's estimate and Newton steps instead of a square
   * root and a division per pair */
  enum { CHUNK = 256 };
  double rr[CHUNK], ri[CHUNK];
  for (size_t c0 = 0; c0 < npad; c0 += CHUNK) {
    const size_t cn = npad - c0 < CHUNK ? npad - c0 : CHUNK;
    const double *cx = pdx + c0, *cy = pdy + c0, *cg = pg + c0;
    px_vortex_radii(cx, cy, cn, tiny2, rr, ri);
#pragma omp simd reduction(+ : i1, i1abs, i2x, i2y)
    for (size_t q = 0; q < cn; ++q) {
      double ex = vx_exp_neg(rr[q] * inv_e);
      double gj = cg[q], ge = gj * ex;
      i1 += ge;
      i1abs += fabs(gj) * ex;
      i2x += ge * cx[q] * ri[q];
      i2y += ge * cy[q] * ri[q];
    }
  }
  out[0] = i1;
  out[1] = i1abs;
  out[2] = i2x;
  out[3] = i2y;
}

/* The kernel's moments over the np neighbours vvd_pair_sums left packed in
 * pdx, pdy: M0 = sum exp(-r/e), M1 = sum r exp(-r/e) (vvd_moments; a second
 * pass, so that the default pair loop stays as it is). */
static void vvd_kernel_moments(const double *pdx, const double *pdy, size_t np, double inv_e,
                               double *m0, double *m1) {
  double s0 = 0.0, s1 = 0.0;
#pragma omp simd reduction(+ : s0, s1)
  for (size_t q = 0; q < np; ++q) {
    double r = sqrt(pdx[q] * pdx[q] + pdy[q] * pdy[q]);
    double ex = vx_exp_neg(r * inv_e);
    s0 += ex;
    s1 += ex * r;
  }
  *m0 = s0;
  *m1 = s1;
}

/* vvd_moments: covariance. The diffusive velocity -nu grad(omega) / omega
 * from the mean m and covariance V of the neighbour offsets d = x_i - x_j
 * weighted by w_j = Gamma_j exp(-|d|^2 / (2 eps*^2)), the vortex itself
 * included (d = 0), the weight cut where it falls below exp(-20) (|d| >
 * 6.3 eps*, the range of vx_exp_neg): W = nu V^-1 m. For a Gaussian field
 * and a Gaussian weight the weighted offsets are Gaussian, with V^-1 m =
 * -grad(omega) / omega exactly, whatever the field's width against eps*
 * and against the spacing (a discrete set enters m and V through the same
 * sums); the
 * published particle term I2 / (eps* I1) is the gradient of the field
 * smoothed by exp(-r/eps*), whose rate falls as sigma^2 / (sigma^2 + 3
 * eps*^2) for thin structures and exceeds 1 by the lattice factor m for thick
 * ones (docs/notes/vortex.md, "The VVD's diffusion rate"). Vorticity of each sign
 * diffuses on its own (the equation is linear), so only the neighbours of
 * the vortex's own sign enter: omega never crosses zero within a species.
 * Returns 0, leaving W to the published formula, where V is degenerate (a
 * lone vortex of its sign, all its neighbours on a line: vx_cov_velocity).
 * The weight and the solve are vortex_kernel.h's, shared with vortex.cl. */
static int vvd_covariance(const double *pdx, const double *pdy, const double *pg, size_t np,
                          double ei, double gi, double *wx, double *wy) {
  const double inv_e = 1.0 / ei;
  double s0 = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0, syy = 0.0;
#pragma omp simd reduction(+ : s0, sx, sy, sxx, sxy, syy)
  for (size_t q = 0; q < np; ++q) {
    double dx = pdx[q], dy = pdy[q], gq = pg[q];
    double w = gq * gi > 0.0 ? gq * vx_cov_weight(dx * dx + dy * dy, inv_e) : 0.0;
    s0 += w;
    sx += w * dx;
    sy += w * dy;
    sxx += w * dx * dx;
    sxy += w * dx * dy;
    syy += w * dy * dy;
  }
  return vx_cov_velocity(s0 + gi, sx, sy, sxx, sxy, syy, ei, wx, wy);
}

/* The neighbours of the vortex at sorted position sp within cut * ei packed
 * into b->pd, and (panels > 0) the panels within cut * ei + L_max / 2 into
 * b->fp, each by a query of its own (a vortex whose eps* outgrew its group's
 * search): the same lists, in the same order, as the group's path. Returns
 * the neighbour count, or (size_t)-1 when out of memory. */
static size_t vvd_own_lists(struct px_vortex_engine *e, struct px_vortex_nbuf *b, const double *sg,
                            uint32_t sp, double ei, size_t *npanel) {
  const struct px_vortex_tree *t = &e->tree;
  const double cut = e->cfg.cutoff, xi = t->sx[sp], yi = t->sy[sp];
  size_t nl =
      px_vortex_leaves_into(e, t, xi, yi, cut * ei * (1.0 + 1e-9) + 1e-300, &b->ol, &b->ol_cap);
  if (nl == (size_t)-1 || !px_vortex_list_reserve(e, &b->fl, &b->fl_cap, 2 * nl)) return (size_t)-1;
  for (size_t l = 0; l < nl; ++l) {
    b->fl[2 * l] = t->lo[b->ol[l]];
    b->fl[2 * l + 1] = t->hi[b->ol[l]];
  }
  size_t np = vvd_pack_runs(e, b, sg, nl, sp, cut * ei * cut * ei);
  if (np == (size_t)-1) return np;
  *npanel = 0;
  if (e->pan.n > 0) {
    double r = cut * ei + 0.5 * e->pan.lmax;
    size_t c = px_vortex_tree_within(e->ctx, &e->ptree, xi, yi, r, &b->ol, &b->ol_cap);
    if (c == (size_t)-1 || !px_vortex_list_reserve(e, &b->fp, &b->fp_cap, c + 8)) return (size_t)-1;
    for (size_t q = 0; q < c; ++q) b->fp[q] = e->ptree.order[b->ol[q]];
    *npanel = c;
  }
  return np;
}

/* Block 3. eps* and the VVD sums from one tree query per group of vortices:
 * each vortex has a guess g of its eps* (10% over its eps* of the step
 * before; the exact 3-nearest search where none is known). Its 3 nearest are
 * searched within sqrt(3) g among the group's leaves, which gives eps*
 * exactly when at least 3 are found there (else the exact search), then its
 * neighbours within cut * eps* are packed from the group's leaves, or by a
 * query of the vortex's own where eps* outgrew the group's reach (cut times
 * the group's largest guess). The lists and sums are those of a separate
 * eps* search followed by the VVD's, at one traversal instead of two. (Until
 * 2026-11-28 the pack was at cut * g with the 3 nearest tracked on the way,
 * then narrowed: the same lists, ~1% slower.) */
/* The diffusive velocity [m/s] of the vortex at (xi, yi) of circulation gi,
 * eps* ei, born on panel `born` in this step (-1: not newborn), from its np
 * neighbours packed in pdx, pdy, pg and the pc panels within reach pl: the
 * VVD (vx_vvd_particle, vx_vvd_wall) or, away from walls, the covariance
 * estimate (vvd_moments), times nu, at most vcap (vcap 0: no cap); a newborn
 * drifts by px_vortex_newborn_drift instead when that is on. */
static inline void vx_vvd_velocity(const struct px_vortex_engine *e, double *pdx, double *pdy,
                                   double *pg, size_t np, const uint32_t *pl, size_t pc, double gi,
                                   double ei, double xi, double yi, int32_t born, double vcap,
                                   double *wx_out, double *wy_out) {
  const struct px_vortex_panels *p = &e->pan;
  const double cut = e->cfg.cutoff, nu = e->cfg.nu;
  const int self = e->cfg.self_in_i1, moments = e->cfg.vvd_moments;
  const double w_born = px_vortex_newborn_drift(&e->cfg);
  double inv_e = 1.0 / ei, tiny2 = 1e-24 * ei * ei;
  double wx = 0.0, wy = 0.0;
  /* away from walls, vvd_moments: covariance; else (or degenerate) the
   * published formula */
  if (!(moments == PX_VORTEX_MOMENTS_COVARIANCE && pc == 0 &&
        vvd_covariance(pdx, pdy, pg, np, ei, gi, &wx, &wy))) {
    double sums[4]; /* I1, sum |Gamma| exp, I2x, I2y */
    vvd_pair_sums(pdx, pdy, pg, np, inv_e, tiny2, sums);
    double i1 = sums[0], i1abs = sums[1], i2x = sums[2], i2y = sums[3];
    if (self) {
      i1 += gi;
      i1abs += fabs(gi);
    }
    double el = ei; /* the particle term's length: eps*, or M1 / (2 M0) (vvd_moments) */
    if (moments == PX_VORTEX_MOMENTS_WAKE && pc == 0) {
      double m0, m1;
      vvd_kernel_moments(pdx, pdy, np, inv_e, &m0, &m1);
      if (self) m0 += 1.0;
      el = vx_vvd_length(ei, m0, m1);
    }
    vx_vvd_particle(i1, i1abs, i2x, i2y, el, &wx, &wy);
    /* wall terms (none within reach: zero sums, added as such, so that a
     * -0 turns to +0 as on the device) */
    if (p->n > 0) {
      double s0 = 0.0, i3x = 0.0, i3y = 0.0;
      if (pc > 0) px_vortex_wall_sum(p, pl, pc, xi, yi, ei, cut, &i3x, &i3y, &s0);
      vx_vvd_wall(ei, s0, i3x, i3y, &wx, &wy);
    }
  }
  wx *= nu;
  wy *= nu;
  if (vcap > 0.0 && wx * wx + wy * wy > 0.98 * vcap * vcap) { /* hypot only near the cap */
    double m = hypot(wx, wy);
    if (m > vcap) {
      wx *= vcap / m;
      wy *= vcap / m;
    }
  }
  if (w_born > 0.0 && born >= 0) {
    size_t kb = (size_t)born;
    wx = w_born * p->ty[kb];
    wy = -w_born * p->tx[kb];
  }
  *wx_out = wx;
  *wy_out = wy;
}

/* The same for the reference engine (the cpu loop below calls the inline
 * one: it runs once per vortex). */
void px_vortex_vvd_velocity(const struct px_vortex_engine *e, double *pdx, double *pdy, double *pg,
                            size_t np, const uint32_t *pl, size_t pc, double gi, double ei,
                            double xi, double yi, int32_t born, double vcap, double *wx_out,
                            double *wy_out) {
  vx_vvd_velocity(e, pdx, pdy, pg, np, pl, pc, gi, ei, xi, yi, born, vcap, wx_out, wy_out);
}

/* Groups of neighbouring vortices per tree query of the VVD's search
 * (diffusive_share): one traversal for 4 groups, each group's leaves then
 * filtered from its list (2026-11-28, vortex_step at 55k vortices, 2
 * threads, alternated: the diffusive block 12.1-12.7 -> 11.7-12.1 ms; 8
 * groups no faster). */
#define VX_SUPER 4

/* One group of the VVD's search: tree node k, the largest search guess of
 * its vortices, its box's centre and the radius its leaves must cover. */
struct vvd_group {
  size_t k;
  double gmax, cx, cy, hd, rg;
};

/* The reach of group node k: each vortex's guess (the exact search where
 * none is known), the largest, and the radius. */
static void vvd_group_reach(struct px_vortex_engine *e, size_t k, double *eg, int compute_eps,
                            struct vvd_group *g) {
  const struct px_vortex_tree *t = &e->tree;
  uint32_t work[512];
  double gmax = 0.0;
  for (uint32_t sp = t->lo[k]; sp < t->hi[k]; ++sp) { /* not fmax: a libm call */
    if (compute_eps && !(eg[sp] > 0.0)) {
      /* no eps* known (an added or resumed vortex, the first newborns on a
       * panel): the exact search gives it */
      double d2[3];
      px_vortex_tree_knn_point(t, sp, 3, work, 512, d2);
      eg[sp] = eps_value(&e->cfg, d2);
    }
    gmax = eg[sp] > gmax ? eg[sp] : gmax;
  }
  g->k = k;
  g->gmax = gmax;
  g->cx = 0.5 * (t->bx0[k] + t->bx1[k]);
  g->cy = 0.5 * (t->by0[k] + t->by1[k]);
  g->hd = 0.5 * hypot(t->bx1[k] - t->bx0[k], t->by1[k] - t->by0[k]);
  /* margin against rounding in the distance tests */
  g->rg = (e->cfg.cutoff * gmax + g->hd) * (1.0 + 1e-9) + 1e-300;
}

/* The squared distances d2 (ascending, INFINITY where fewer) of the 3
 * nearest to the vortex at sorted position sp within sqrt(r2) among the
 * group's ngl leaves b->gl (their boxes in b->lb). */
static void vvd_near3(const struct px_vortex_tree *t, struct px_vortex_nbuf *b, size_t ngl,
                      uint32_t sp, double r2, double *d2) {
  const double xi = t->sx[sp], yi = t->sy[sp];
  double low[PX_VORTEX_VVD_LOW];
  const size_t nn = px_vortex_vvd_leaf_runs(t, b->gl, b->lb, ngl, b->lb_cap, xi, yi, r2, b->fl);
  px_vortex_vvd_near(t->sx, t->sy, b->fl, nn, sp, xi, yi, r2, low);
  px_vortex_vvd_low3(low, d2);
}

/* eps* and the diffusive velocities of group g's vortices, its ngl leaves
 * in b->gl. Returns 0, or 1 when out of memory. */
static int vvd_group_velocities(struct px_vortex_engine *e, struct px_vortex_nbuf *b,
                                const struct vvd_group *g, size_t ngl, const double *sg, double *eg,
                                int compute_eps, double vcap, int *nonfinite) {
  const struct px_vortex_tree *t = &e->tree;
  const struct px_vortex_panels *p = &e->pan;
  struct px_vortex_wake *w = &e->w;
  const double cut = e->cfg.cutoff, lmax = p->n > 0 ? p->lmax : 0.0, gmax = g->gmax;
  const size_t k = g->k;
  uint32_t work[512];
  /* the group's candidate panels, their centres contiguous (b->gp, b->pc) */
  size_t ngp = 0;
  if (p->n > 0)
    ngp = px_vortex_nbuf_group(e, &e->ptree, g->cx, g->cy,
                               (cut * gmax + 0.5 * lmax + g->hd) * (1.0 + 1e-9) + 1e-300);
  if (ngp == (size_t)-1 || !px_vortex_list_reserve(e, &b->fl, &b->fl_cap, 2 * ngl) ||
      !px_vortex_arrays_reserve(e, &b->lb, &b->lb_cap, ngl + 8, 6))
    return 1;
  px_vortex_vvd_leaf_boxes(t, b->gl, ngl, b->lb, b->lb_cap);
  /* by panel number: the wall sums read the panels */
  for (size_t q = 0; q < ngp; ++q) b->gp[q] = e->ptree.order[b->gp[q]];
  for (uint32_t sp = t->lo[k]; sp < t->hi[k]; ++sp) {
    size_t i = t->order[sp];
    double xi = t->sx[sp], yi = t->sy[sp], gi = eg[sp];
    double ei = gi;
    if (compute_eps) {
      /* eps* first, from the 3 nearest: the rms of their distances, so
       * the third lies within sqrt(3) eps*; searched within sqrt(3) times
       * the guess, which holds them whenever the guess does, and which
       * gives them exactly whenever it holds 3; else within cut times the
       * guess, which the group's leaves still cover, and the exact search
       * only where that holds fewer than 3 (vortex_step, 8 steps at 52k:
       * exact searches 7651 -> 14, the diffusive block 11.9 -> 11.7 ms
       * median, 2 threads, alternated, 2026-11-28); never beyond cut times
       * the guess (a cutoff below sqrt(3), outside the case schema's range) */
      const double r2n = (cut * cut < 3.0 ? cut * cut : 3.0) * gi * gi, r2c = cut * cut * gi * gi;
      double d2[3];
      vvd_near3(t, b, ngl, sp, r2n, d2);
      /* fewer than 3 there: 3 found within cut times the guess are the 3
       * nearest (the same squared distances as the exact search's) */
      if (!isfinite(d2[2]) && r2c > r2n) vvd_near3(t, b, ngl, sp, r2c, d2);
      if (!isfinite(d2[2])) px_vortex_tree_knn_point(t, sp, 3, work, 512, d2);
      ei = eps_value(&e->cfg, d2);
      w->e[i] = ei;
    }
    /* the neighbours within cut * eps*, packed (offsets and
     * circulations): from the leaves of the group's query within reach,
     * as runs of consecutive sorted positions (leaves are in ascending
     * order; neighbouring ones often touch: longer vector loops, fewer
     * scalar remainders), or beyond the group's reach by a query of the
     * vortex's own. Then one long vector loop over them: the
     * exponential's dependency chain overlaps across iterations, and
     * pairs out of reach cost nothing. */
    size_t np, pc = 0;
    int own = ei > gmax; /* the lists come from a query of the vortex's own */
    if (!own) {
      double r2 = cut * ei * cut * ei;
      size_t nl = px_vortex_vvd_leaf_runs(t, b->gl, b->lb, ngl, b->lb_cap, xi, yi, r2, b->fl);
      np = vvd_pack_runs(e, b, sg, nl, sp, r2);
    } else {
      np = vvd_own_lists(e, b, sg, sp, ei, &pc);
    }
    if (np == (size_t)-1) return 1;
    /* the panels within reach (the wall terms) */
    uint32_t *pl = b->fp;
    if (p->n > 0 && !own) pl = px_vortex_nbuf_pick(e, ngp, xi, yi, cut * ei + 0.5 * p->lmax, &pc);
    double wx, wy;
    vx_vvd_velocity(e, b->pd, b->pd + b->pd_cap, b->pd + 2 * b->pd_cap, np, pl, pc, sg[sp], ei, xi,
                    yi, w->born[i], vcap, &wx, &wy);
    w->wu[i] = wx;
    w->wv[i] = wy;
    if (!isfinite(wx) || !isfinite(wy)) *nonfinite = 1;
  }
  return 0;
}

/* px_vortex_engine_diffusive for this rank's share of the vortex tree's
 * groups (vortex_ranks.h): the vortices at sorted positions [*lo, *hi). */
static enum px_status diffusive_share(struct px_vortex_engine *e, int compute_eps, double vcap,
                                      size_t *lo, size_t *hi) {
  struct px_vortex_wake *w = &e->w;
  *lo = *hi = 0;
  if (w->n == 0) return PX_STATUS_OK;
  PX_TRY(px_vortex_ensure_work(e, w->n));
  double t0 = px_time_now();
  /* the generation's tree's points, in its order, with the newborns behind */
  const size_t nold = w->n - e->n_born;
  PX_TRY(px_vortex_tree_build(e->ctx, &e->tree, w->n, w->x, w->y, nold, e->cfg.threads));
  const struct px_vortex_tree *t = &e->tree;
  uint32_t *grp = px_mem_alloc(e->ctx, "vortex.work", 2 * t->nnode * sizeof(uint32_t));
  if (!grp) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (neighbour groups)");
  size_t ngrp = px_vortex_tree_groups(t, VX_GROUP, grp), g0 = 0, g1 = ngrp;
  *hi = w->n;
  if (px_vortex_ranks_count(e) > 1) {
    /* the groups' first sorted positions, ascending (depth first, left
     * first), into the tail of grp */
    uint32_t *first = grp + ngrp;
    for (size_t g = 0; g < ngrp; ++g) first[g] = t->lo[grp[g]];
    px_vortex_ranks_runs(e, first, ngrp, w->n, &g0, &g1, lo, hi);
  }
  double t1 = px_time_now();
  e->diffusive_time[0] += t1 - t0;
  int oom = 0, nonfinite = 0;
  /* circulations in tree order (contiguous reads in the neighbour loops),
   * and each vortex's search guess */
  double *sg = e->xn, *eg = e->yn;
#pragma omp parallel for num_threads(e->cfg.threads) schedule(static)
  for (size_t sp = 0; sp < w->n; ++sp) {
    size_t i = t->order[sp];
    sg[sp] = w->g[i];
    double ep = w->e[i];
    /* a newborn: the mean eps* of the last step's newborns on its panel */
    if (w->born[i] >= 0) ep = e->pe[w->born[i]];
    eg[sp] = compute_eps ? VX_EPS_GUESS * ep : w->e[i];
  }
  /* One tree query per VX_SUPER consecutive groups of neighbouring vortices
   * (px_vortex_tree_groups), each group then taking from it the leaves within the
   * largest radius of its vortices plus its half-diagonal (a query of its
   * own gives the same: a leaf's test does not depend on the traversal),
   * and each vortex from those the subset within its own radius, by the
   * same tests and in the same order as a query of its own (identical sums,
   * a fraction of the traversal). */
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 1) reduction(| : nonfinite)
  for (long ls = (long)g0; ls < (long)g1; ls += VX_SUPER) {
    struct px_vortex_nbuf *b = &e->nbuf[omp_get_thread_num()];
    const size_t ng = (size_t)((long)g1 - ls < VX_SUPER ? (long)g1 - ls : VX_SUPER);
    struct vvd_group gr[VX_SUPER];
    double gx[VX_SUPER], gy[VX_SUPER], gw[VX_SUPER], sx, sy;
    for (size_t q = 0; q < ng; ++q) {
      vvd_group_reach(e, grp[ls + (long)q], eg, compute_eps, &gr[q]);
      gx[q] = gr[q].cx;
      gy[q] = gr[q].cy;
      gw[q] = gr[q].rg;
    }
    const double rs = px_vortex_cover(gx, gy, gw, ng, &sx, &sy);
    size_t nsl = px_vortex_leaves_into(e, t, sx, sy, rs, &b->sl, &b->sl_cap);
    if (nsl == (size_t)-1 || !px_vortex_list_reserve(e, &b->gl, &b->gl_cap, nsl + 8) ||
        !px_vortex_arrays_reserve(e, &b->sb, &b->sb_cap, nsl + 8, 6)) {
      oom = 1;
      continue;
    }
    /* the query's leaves' boxes once, each group's list by a vector test */
    px_vortex_vvd_leaf_boxes(t, b->sl, nsl, b->sb, b->sb_cap);
    int full = 0; /* out of memory in this thread (oom is shared: written only) */
    for (size_t q = 0; q < ng && !full; ++q) {
      const size_t ngl = px_vortex_vvd_leaves_within(b->sl, b->sb, nsl, b->sb_cap, gr[q].cx,
                                                     gr[q].cy, gr[q].rg * gr[q].rg, b->gl);
      full = vvd_group_velocities(e, b, &gr[q], ngl, sg, eg, compute_eps, vcap, &nonfinite);
    }
    if (full) oom = 1;
  }
  px_mem_free(e->ctx, grp);
  e->diffusive_time[1] += px_time_now() - t1;
  if (oom) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)");
  /* over several ranks the check follows the gather (every rank the same) */
  return nonfinite && px_vortex_ranks_count(e) < 2 ? px_vortex_diffusive_finite(e) : PX_STATUS_OK;
}

enum px_status px_vortex_engine_diffusive(struct px_vortex_engine *e, int compute_eps,
                                          double vcap) {
  size_t lo, hi;
  enum px_status st = diffusive_share(e, compute_eps, vcap, &lo, &hi);
  if (px_vortex_ranks_count(e) < 2) return st;
  struct px_vortex_wake *w = &e->w;
  /* eps* is an input without compute_eps */
  double *const out[3] = {w->wu, w->wv, w->e};
  st = px_vortex_ranks_gather(e, 1, st, w->n ? e->tree.order : NULL, w->n, lo, hi, out,
                              compute_eps ? 3 : 2);
  return st == PX_STATUS_OK ? px_vortex_diffusive_finite(e) : st;
}
