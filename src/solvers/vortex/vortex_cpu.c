/* The `cpu` engine's blocks of a step (vortex_engine.h) but the diffusive
 * one (vortex_diffusive.c): generation, convective velocities, loads, the
 * move (Euler, Heun), non-penetration and restructuring, on the host in
 * double, OpenMP over the vortices or panels. */
/* sqrt never sees a negative argument here (see vortex_core.c). */
#pragma GCC optimize("no-math-errno")
#include "solvers/vortex/vortex_core.h"

#include <math.h>
#include <omp.h>
#include <string.h>
#include <time.h>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "partix/memory.h"
#include "partix/nbody.h"
#include "partix/timer.h"
#include "solvers/vortex/vortex_core_impl.h"
#include "solvers/vortex/vortex_engine.h"
#include "solvers/vortex/vortex_host.h"
#include "solvers/vortex/vortex_ranks.h"
#include "nbody/nbody_impl.h"

#define PX_REAL double
#include "kernels/px_kernel.h"
#include "solvers/vortex/vortex_kernel.h"
#include "solvers/vortex/vortex_sheet.h"

/* The blocks that look for the panels near each vortex (old_targets,
 * crossings) or the vortices near each panel (generation, loads) query the
 * tree once per group of VX_NEAR_GROUP consecutive vortices (neighbours:
 * the wake is in the tree's Morton order since the last restructuring) or
 * VX_PANEL_GROUP consecutive panels (neighbours along a contour), and each
 * member filters its own list from the group's (px_vortex_nbuf_group, _pick:
 * the same points in the same order as a query of its own). */
#define VX_NEAR_GROUP 64
#define VX_PANEL_GROUP 16
/* Points per group of leaves of the merge-partner search (merge_partners). */
#define VX_MERGE_GROUP 512

/* Members of the group starting at lg of a loop to hi in groups of g. */
static size_t group_len(long lg, long hi, long g) { return (size_t)(hi - lg < g ? hi - lg : g); }

/* Does the box [x0, x1] x [y0, y1], grown by r, meet a body's box? */
static int near_bodies(const struct px_vortex_panels *p, double x0, double y0, double x1, double y1,
                       double r) {
  int any = 0;
  for (size_t b = 0; b < p->nbody && !any; ++b)
    any = !(x1 + r < p->bxmin[b] || x0 - r > p->bxmax[b] || y1 + r < p->bymin[b] ||
            y0 - r > p->bymax[b]);
  return any;
}

/* The group query of tree t for the n members (mx, my)_q with radii mr_q
 * (not >= 0: a member that wants no list): about the centre of their box,
 * wide enough for each. Returns the candidates' count (0 also when no
 * member wants a list), (size_t)-1 when out of memory. */
static size_t near_group(struct px_vortex_engine *e, const struct px_vortex_tree *t,
                         const double *mx, const double *my, const double *mr, size_t n) {
  double gx0 = INFINITY, gx1 = -INFINITY, gy0 = INFINITY, gy1 = -INFINITY, rmax = 0.0;
  for (size_t q = 0; q < n; ++q) {
    if (!(mr[q] >= 0.0)) continue;
    gx0 = mx[q] < gx0 ? mx[q] : gx0; /* a NaN is left out, as its own query finds nothing */
    gx1 = mx[q] > gx1 ? mx[q] : gx1;
    gy0 = my[q] < gy0 ? my[q] : gy0;
    gy1 = my[q] > gy1 ? my[q] : gy1;
    rmax = mr[q] > rmax ? mr[q] : rmax;
  }
  if (!(gx0 <= gx1 && gy0 <= gy1)) return 0;
  const double hd = 0.5 * hypot(gx1 - gx0, gy1 - gy0);
  return px_vortex_nbuf_group(e, t, 0.5 * (gx0 + gx1), 0.5 * (gy0 + gy1),
                              (rmax + hd) * (1.0 + 1e-9) + 1e-300);
}

/* The panels [lg, min(lg + VX_PANEL_GROUP, hi)) as a group: their midpoints
 * into mx, my; returns their count. */
static size_t panel_group(const struct px_vortex_panels *p, long lg, long hi, double *mx,
                          double *my) {
  const size_t m = group_len(lg, hi, VX_PANEL_GROUP);
  for (size_t q = 0; q < m; ++q) {
    size_t k = (size_t)lg + q;
    mx[q] = 0.5 * (p->x0[k] + p->x1[k]);
    my[q] = 0.5 * (p->y0[k] + p->y1[k]);
  }
  return m;
}

/* ------------------------------------------------------------------------- */
/* Block 1: generation */

/* absorbed: the circulation each panel absorbed in the last step, which the
 * sheet returns to the flow (NULL: none, the second stage of rk2) */
static enum px_status generation(struct px_vortex_engine *e, double vx, double vy,
                                 const double *absorbed) {
  struct px_context *ctx = e->ctx;
  const struct px_vortex_panels *p = &e->pan;
  struct px_vortex_wake *w = &e->w;
  size_t n = p->n;
  e->n_born = 0;
  if (n == 0) return PX_STATUS_OK;       /* no body: nothing to generate */
  double *gx = e->rhs_u, *gy = e->rhs_v; /* 2n Gauss points, then velocities */
  double *gu = e->dwork, *gv = e->dwork + 2 * n;
  if (e->dwork_cap < 4 * n) {
    PX_TRY(px_vortex_ensure_work(e, 2 * n + w->n));
    gu = e->dwork;
    gv = e->dwork + 2 * n;
  }
  px_vortex_gauss_points(e);
  double *rhs = e->sol;
  if (w->n > 0) {
    /* the wake as the last restructuring compacted it, in that tree's order
     * but for the merged vortices (0-10 entries moved at 55k) */
    PX_TRY(px_vortex_tree_build(ctx, &e->tree, w->n, w->x, w->y, w->n, e->cfg.threads));
    PX_TRY(px_vortex_nb_sources(e));
    PX_TRY(px_vortex_nb_targets(e, 2 * n, gx, gy, gu, gv));
  } else {
    memset(gu, 0, 4 * n * sizeof(double));
  }
  const double eps2 = e->cfg.eps * e->cfg.eps;
  int oom = 0;
  /* over ranks each takes a contiguous share of the panels, gathered
   * below (each row is its own panel's: the same bits) */
  size_t lo = 0, hi = n;
  px_vortex_ranks_share(e, n, &lo, &hi);
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 1)
  for (long lg = (long)lo; lg < (long)hi; lg += VX_PANEL_GROUP) {
    double mx[VX_PANEL_GROUP], my[VX_PANEL_GROUP], mr[VX_PANEL_GROUP];
    const size_t m = panel_group(p, lg, (long)hi, mx, my);
    for (size_t q = 0; q < m; ++q)
      mr[q] = w->n > 0 ? 2.0 * p->len[(size_t)lg + q] + e->cfg.eps : -1.0;
    size_t ng = near_group(e, &e->tree, mx, my, mr, m);
    if (ng == (size_t)-1) {
      oom = 1;
      continue;
    }
    for (size_t q = 0; q < m; ++q) {
      size_t i = (size_t)lg + q;
      double tx = p->tx[i], ty = p->ty[i];
      double wk = 0.5 * ((gu[2 * i] + gu[2 * i + 1]) * tx + (gv[2 * i] + gv[2 * i + 1]) * ty);
      if (w->n > 0) {
        /* near vortices: replace the smoothed 2-point mean by the exact mean */
        size_t cnt = 0;
        uint32_t *lst = mr[q] >= 0.0 ? px_vortex_nbuf_pick(e, ng, mx[q], my[q], mr[q], &cnt) : NULL;
        double inv_len = 1.0 / p->len[i], corr = 0.0;
        /* one vector loop (summed in its lanes): a call per vortex with its
         * atan2 was most of this block's own time */
#pragma omp simd reduction(+ : corr)
        for (size_t k = 0; k < cnt; ++k) {
          uint32_t j = e->tree.order[lst[k]];
          corr += w->g[j] * vx_near_coef(p->x0[i], p->y0[i], p->x1[i], p->y1[i], inv_len, tx, ty,
                                         gx[2 * i], gy[2 * i], gx[2 * i + 1], gy[2 * i + 1], eps2,
                                         w->x[j], w->y[j]);
        }
        wk += corr;
      }
      rhs[i] = -(vx * tx + vy * ty) - wk;
    }
  }
  PX_TRY(px_vortex_ranks_gather_runs(
      e,
      oom ? px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)") : PX_STATUS_OK,
      n, lo, hi, rhs, sizeof(double)));
  return px_vortex_sheet_shed(e, vx, vy, absorbed);
}

/* ------------------------------------------------------------------------- */
/* Block 2: convective velocities */

/* The wake's pair sums at its old vortices into w->u, w->v (the newborns'
 * own velocity is set apart). Where the generation's FMM sum over the old
 * wake was the evaluator's last, its tree and multipoles serve again, the
 * newborns a tree of their own beside it (px_nbody_velocity_extend: the
 * upward pass and the tree of 55k vortices not done twice a step); else the
 * whole sum with all vortices as sources and targets. Over several ranks an
 * FMM sum is split (vortex_ranks.h): this rank's targets are then perm[q],
 * q in [*lo, *hi) of *nt (*perm NULL: every target, a direct sum run whole
 * on every rank), gathered by the caller. */
static enum px_status convective_sums(struct px_vortex_engine *e, const uint32_t **perm, size_t *lo,
                                      size_t *hi, size_t *nt) {
  struct px_vortex_wake *w = &e->w;
  const size_t nold = w->n - e->n_born;
  int ext = 0;
  enum px_status st = px_vortex_nb_sources(e);
  px_vortex_ranks_split_sums(e, 1);
  if (st == PX_STATUS_OK)
    st = px_nbody_velocity_extend(e->nbe, w->n, e->nb[0], e->nb[1], e->nb[2], nold,
                                  PX_NBODY_MODE_SET, e->nb[3], e->nb[4], &ext);
  px_vortex_ranks_split_sums(e, 0);
  ++e->conv_sums;
  e->conv_extended += ext;
  *nt = ext ? nold : w->n;
  if (st == PX_STATUS_OK) st = px_vortex_nb_get(e, e->nb[3], w->u, *nt);
  if (st == PX_STATUS_OK) st = px_vortex_nb_get(e, e->nb[4], w->v, *nt);
  *perm = NULL;
  *lo = 0;
  *hi = *nt;
  if (st == PX_STATUS_OK && px_vortex_ranks_count(e) > 1 &&
      !px_nbody_part_targets(e->nbe, perm, lo, hi)) {
    *perm = NULL;
    *lo = 0;
    *hi = *nt;
  }
  return st;
}

/* The (vortex, panel) pairs of old_targets' sheet terms, a buffer at a
 * time: the sheets' fields (vx_sheet_velocity: two vx_atan2, a vx_log, as
 * px_vortex_sheet_term computes them) in one vector loop over the pairs,
 * then the newborns' terms and the sums per vortex in the pairs' order
 * (each vortex's panels in the order of its list, as panel by panel). Per
 * vortex a call per panel kept the loops scalar: 3-4% of a step near an
 * airfoil (2026-11-28), with ~4 panels within reach of each vortex there. */
enum { VX_SHEET_PAIRS = 256 };
struct sheet_pairs {
  uint32_t k[VX_SHEET_PAIRS], q[VX_SHEET_PAIRS];
  double u[VX_SHEET_PAIRS], v[VX_SHEET_PAIRS];
  size_t n;
};

/* The buffered pairs' terms added to cu[q], cv[q] of their vortices at
 * (mx[q], my[q]); the buffer emptied. */
static void sheet_flush(const struct px_vortex_engine *e, struct sheet_pairs *sp, const double *mx,
                        const double *my, double *cu, double *cv) {
  const struct px_vortex_panels *pp = &e->pan;
  const double *x0 = pp->x0, *y0 = pp->y0, *x1 = pp->x1, *y1 = pp->y1, *sol = e->sol;
  const uint32_t *pk = sp->k, *pq = sp->q;
  double *pu = sp->u, *pv = sp->v;
  const size_t n = sp->n;
#pragma omp simd
  for (size_t p = 0; p < n; ++p) {
    const uint32_t k = pk[p], q = pq[p];
    const px_real2 r = vx_sheet_velocity(x0[k], y0[k], x1[k], y1[k], mx[q], my[q]);
    pu[p] = sol[k] * r.x;
    pv[p] = sol[k] * r.y;
  }
  for (size_t p = 0; p < n; ++p) {
    const uint32_t k = pk[p], q = pq[p];
    double du, dv;
    px_vortex_sheet_newborns(e, k, mx[q], my[q], &du, &dv);
    cu[q] += pu[p] - du * (0.5 / VX_PI);
    cv[q] += pv[p] - dv * (0.5 / VX_PI);
  }
  sp->n = 0;
}

/* The old vortices among the targets q in [lo, hi) (vortex perm[q], or q
 * when perm is NULL): the free stream, and near a panel the newborn row's
 * smoothed field replaced by the exact one of the sheet gamma_k on it (VM2D:
 * the wake sees the free sheet,
 * Boundary2DConstLayerAver::CalcConvVelocityToSetOfPointsFromSheets): the
 * terms of px_vortex_sheet_term of the panels whose midpoint lies within
 * 2 L_k + eps, by sheet_flush. Per target: the same bits whichever targets
 * a rank holds. */
static enum px_status old_targets(struct px_vortex_engine *e, double vx, double vy,
                                  const uint32_t *perm, size_t lo, size_t hi) {
  struct px_vortex_wake *w = &e->w;
  size_t nold = w->n - e->n_born;
  for (size_t q = lo; q < hi; ++q) {
    size_t i = perm ? perm[q] : q;
    if (i >= nold) continue;
    w->u[i] += vx;
    w->v[i] += vy;
  }
  if (!e->cfg.sheet_exact || e->pan.n == 0 || e->n_born == 0) return PX_STATUS_OK;
  const struct px_vortex_panels *pp = &e->pan;
  const double rr = 2.0 * pp->lmax + e->cfg.eps;
  int oom = 0;
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 4)
  for (long lg = (long)lo; lg < (long)hi; lg += VX_NEAR_GROUP) {
    const size_t m = group_len(lg, (long)hi, VX_NEAR_GROUP);
    double mx[VX_NEAR_GROUP], my[VX_NEAR_GROUP], mr[VX_NEAR_GROUP];
    double cu[VX_NEAR_GROUP], cv[VX_NEAR_GROUP];
    struct sheet_pairs sp;
    sp.n = 0;
    for (size_t q = 0; q < m; ++q) {
      size_t i = perm ? perm[lg + (long)q] : (size_t)lg + q;
      mx[q] = w->x[i];
      my[q] = w->y[i];
      mr[q] = i < nold && near_bodies(pp, mx[q], my[q], mx[q], my[q], rr) ? rr : -1.0;
      cu[q] = cv[q] = 0.0;
    }
    const size_t ng = near_group(e, &e->ptree, mx, my, mr, m);
    if (ng == (size_t)-1) {
      oom = 1;
      continue;
    }
    for (size_t q = 0; q < m; ++q) {
      if (!(mr[q] >= 0.0)) continue;
      size_t cnt;
      const uint32_t *lst = px_vortex_nbuf_pick(e, ng, mx[q], my[q], rr, &cnt);
      for (size_t c = 0; c < cnt; ++c) {
        const uint32_t k = e->ptree.order[lst[c]];
        if (!px_vortex_sheet_reach(e, k, mx[q], my[q])) continue;
        if (sp.n == VX_SHEET_PAIRS) sheet_flush(e, &sp, mx, my, cu, cv);
        sp.k[sp.n] = k;
        sp.q[sp.n++] = (uint32_t)q;
      }
    }
    sheet_flush(e, &sp, mx, my, cu, cv);
    for (size_t q = 0; q < m; ++q) {
      if (!(mr[q] >= 0.0)) continue;
      size_t i = perm ? perm[lg + (long)q] : (size_t)lg + q;
      w->u[i] += cu[q];
      w->v[i] += cv[q];
    }
  }
  if (oom) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)");
  return PX_STATUS_OK;
}

static enum px_status convective(struct px_vortex_engine *e, double vx, double vy) {
  struct px_vortex_wake *w = &e->w;
  const uint32_t *perm = NULL;
  size_t lo = 0, hi = 0, nt = w->n;
  /* the newborn get their own velocity below */
  enum px_status st = convective_sums(e, &perm, &lo, &hi, &nt);
  /* one rank, or a direct sum: every old vortex (as always); an FMM split
   * over ranks: this rank's targets, before the gather */
  if (st == PX_STATUS_OK) st = old_targets(e, vx, vy, perm, perm ? lo : 0, perm ? hi : nt);
  if (px_vortex_ranks_count(e) > 1) {
    double *const uv[2] = {w->u, w->v};
    PX_TRY(px_vortex_ranks_gather(e, 0, st, perm, nt, lo, hi, uv, 2));
  } else {
    PX_TRY(st);
  }
  return px_vortex_newborn_convective(e);
}

/* ------------------------------------------------------------------------- */
/* Block 4: loads */

static enum px_status loads(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  const struct px_vortex_panels *p = &e->pan;
  size_t n = p->n;
  /* panel domain radius: mean eps* of the vortices born on it */
  px_vortex_panel_radius(e);
  /* mean wall vorticity over each panel: omega(xi) = sum_j Gamma_j
   * exp(-|xi - r_j|/e) / (pi e^2), the VVD estimate at a wall point (where
   * I0 = pi e^2), averaged over the panel. It gives the friction only with
   * friction_wall (VM2D's viscousStress): that estimate depends on how the
   * near-wall vortices happen to be spaced relative to e. On the Blasius plate
   * (650 panels, t = 3) it read 31% above both the wall shear of the
   * simulated velocity field and the impulse balance below, which agree with
   * each other within 1%. Leaving the newborn row out was tried too: then it
   * fell 17-27% below the impulse balance at finer resolutions. */
  const double cut = e->cfg.cutoff;
  int oom = 0;
  /* over ranks each takes a contiguous share of the panels, gathered below */
  size_t lo = 0, hi = n;
  px_vortex_ranks_share(e, n, &lo, &hi);
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 1)
  for (long lg = (long)lo; lg < (long)hi; lg += VX_PANEL_GROUP) {
    double mx[VX_PANEL_GROUP], my[VX_PANEL_GROUP], mr[VX_PANEL_GROUP];
    const size_t m = panel_group(p, lg, (long)hi, mx, my);
    for (size_t q = 0; q < m; ++q) {
      size_t k = (size_t)lg + q;
      mr[q] = cut * e->pe[k] + 0.5 * p->len[k];
    }
    size_t ng = near_group(e, &e->tree, mx, my, mr, m);
    if (ng == (size_t)-1) {
      oom = 1;
      continue;
    }
    for (size_t q = 0; q < m; ++q) {
      size_t k = (size_t)lg + q, cnt = 0;
      double ek = e->pe[k];
      uint32_t *lst = mr[q] >= 0.0 ? px_vortex_nbuf_pick(e, ng, mx[q], my[q], mr[q], &cnt) : NULL;
      double acc = px_vortex_wall_s3_sum(p, k, e->tree.sx, e->tree.sy, w->g, e->tree.order, lst,
                                         cnt, ek, cut);
      e->omega[k] = acc / (VX_PI * ek * ek * p->len[k]);
    }
  }
  PX_TRY(px_vortex_ranks_gather_runs(
      e,
      oom ? px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)")
          : PX_STATUS_OK,
      n, lo, hi, e->omega, sizeof(double)));
  px_vortex_forces(e);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */
/* Block 6: non-penetration */

/* The first of the cnt panels lst (sorted positions of the panel tree)
 * that the path (x0, y0) -> (x1, y1) crosses, or -1. */
static int32_t first_crossed(const struct px_vortex_engine *e, const uint32_t *lst, size_t cnt,
                             double x0, double y0, double x1, double y1) {
  const struct px_vortex_panels *p = &e->pan;
  int32_t best = -1;
  double tbest = 2.0;
  for (size_t q = 0; q < cnt; ++q) {
    size_t k = e->ptree.order[lst[q]];
    double t;
    if (vx_seg_cross(x0, y0, x1, y1, p->x0[k], p->y0[k], p->x1[k], p->y1[k], &t) &&
        (t < tbest || (t == tbest && (int32_t)k < best))) {
      tbest = t;
      best = (int32_t)k;
    }
  }
  return best;
}

/* The radius about its midpoint within which a panel's centre must lie for
 * the panel to meet the path (x0, y0) -> (x1, y1). */
static double path_reach(const struct px_vortex_panels *p, double x0, double y0, double x1,
                         double y1) {
  return 0.5 * hypot(x1 - x0, y1 - y0) + 0.5 * p->lmax;
}

/* First panel crossed by the path (x0, y0) -> (x1, y1), or -1. */
static int32_t crossed_panel(struct px_vortex_engine *e, double x0, double y0, double x1, double y1,
                             int *oom) {
  const struct px_vortex_panels *p = &e->pan;
  /* stage 1: outside every body's box */
  if (!near_bodies(p, fmin(x0, x1), fmin(y0, y1), fmax(x0, x1), fmax(y0, y1), 0.0)) return -1;
  size_t cnt;
  uint32_t *lst = px_vortex_nbuf_query(e, &e->ptree, 0.5 * (x0 + x1), 0.5 * (y0 + y1),
                                       path_reach(p, x0, y0, x1, y1), &cnt);
  if (!lst) {
    *oom = 1;
    return -1;
  }
  return first_crossed(e, lst, cnt, x0, y0, x1, y1); /* stage 2: the few panels near the path */
}

/* crossed_panel for the paths (x0, y0)_i -> (x1, y1)_i, i in [lo, hi), into
 * hit[i]: one query of the panel tree per group of VX_NEAR_GROUP
 * consecutive paths (neighbours: the wake is in Morton order) that reach a
 * body's box, each path filtering its own panels from it (the same panels,
 * in the same order, so the same results). */
static void crossings(struct px_vortex_engine *e, const double *x0, const double *y0,
                      const double *x1, const double *y1, size_t lo, size_t hi, int32_t *hit,
                      int *oom) {
  const struct px_vortex_panels *p = &e->pan;
  int bad = 0;
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 4) reduction(| : bad)
  for (long lg = (long)lo; lg < (long)hi; lg += VX_NEAR_GROUP) {
    const size_t m = group_len(lg, (long)hi, VX_NEAR_GROUP);
    double mx[VX_NEAR_GROUP], my[VX_NEAR_GROUP], mr[VX_NEAR_GROUP];
    for (size_t q = 0; q < m; ++q) {
      size_t i = (size_t)lg + q;
      double ax = x0[i], ay = y0[i], bx = x1[i], by = y1[i];
      hit[i] = -1;
      mx[q] = 0.5 * (ax + bx);
      my[q] = 0.5 * (ay + by);
      /* stage 1: outside every body's box */
      mr[q] = near_bodies(p, fmin(ax, bx), fmin(ay, by), fmax(ax, bx), fmax(ay, by), 0.0)
                  ? path_reach(p, ax, ay, bx, by)
                  : -1.0;
    }
    const size_t ng = near_group(e, &e->ptree, mx, my, mr, m);
    if (ng == (size_t)-1) {
      bad = 1;
      continue;
    }
    for (size_t q = 0; q < m; ++q) {
      size_t i = (size_t)lg + q, cnt;
      if (!(mr[q] >= 0.0)) continue;
      uint32_t *lst = px_vortex_nbuf_pick(e, ng, mx[q], my[q], mr[q], &cnt);
      hit[i] = first_crossed(e, lst, cnt, x0[i], y0[i], x1[i], y1[i]);
    }
  }
  if (bad) *oom = 1;
}

/* Block 6: over this rank's contiguous share of the vortices (all on one
 * rank; vortex_ranks.h), the crossed panels gathered (4 bytes a vortex). */
static enum px_status inside(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  int oom = 0;
  size_t lo = 0, hi = w->n;
  px_vortex_ranks_share(e, w->n, &lo, &hi);
  crossings(e, w->x, w->y, e->xn, e->yn, lo, hi, e->hit, &oom);
  enum px_status st =
      oom ? px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)")
          : PX_STATUS_OK;
  PX_TRY(px_vortex_ranks_gather_runs(e, st, w->n, lo, hi, e->hit, sizeof(int32_t)));
  px_vortex_absorb(e);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */
/* Block 7: restructuring */

static double growth(const struct px_vortex_engine *e, double x, double y) {
  return vx_merge_growth(x * e->stream_dir[0] + y * e->stream_dir[1], e->s_right, e->span);
}

/* The first sorted position in [lo, hi) other than skip whose vortex (of
 * circulation sg[sj]) may merge with the one at (xi, yi) of circulation gi
 * (vx_merge_ok) at a squared distance below *dbest: that distance into
 * *dbest and the position into *best. The nearest is found by a vector
 * distance test (with AVX-512: the few points within reach then tested in
 * full) or a branch-free vector minimum (a partner is rare: most runs hold
 * none), then the first position at that distance by a second, scalar
 * pass: the partner that the plain ascending scan with a strict `<`
 * chooses. */
static void merge_scan(const double *sx, const double *sy, const double *sg, uint32_t lo,
                       uint32_t hi, uint32_t skip, double xi, double yi, double gi, double rs,
                       double ro, double gcap, double *dbest, int32_t *best) {
  const double *restrict x = sx + lo, *restrict y = sy + lo, *restrict g = sg + lo;
  const size_t n = hi - lo, self = (size_t)skip - lo; /* wraps when skip < lo: no match */
  double dmin = INFINITY;
#if defined(__AVX512F__)
  /* the distance test alone, 8 at a time: an eligible point lies within
   * max(rs, ro) (vx_merge_ok's tests are strict), and few do; those few are
   * tested in full (the same d2: separate multiply and add, as below) */
  const double rb = rs > ro ? rs : ro;
  const __m512d vx = _mm512_set1_pd(xi), vy = _mm512_set1_pd(yi), vr = _mm512_set1_pd(rb * rb);
  for (size_t q0 = 0; q0 < n; q0 += 8) {
    const size_t left = n - q0;
    const __mmask8 live = left >= 8 ? (__mmask8)0xff : (__mmask8)((1u << left) - 1u);
    __m512d dx = _mm512_sub_pd(_mm512_maskz_loadu_pd(live, x + q0), vx);
    __m512d dy = _mm512_sub_pd(_mm512_maskz_loadu_pd(live, y + q0), vy);
    __m512d d2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
    unsigned near = _mm512_mask_cmp_pd_mask(live, d2, vr, _CMP_LT_OQ);
    while (near) {
      const size_t q = q0 + (size_t)__builtin_ctz(near);
      near &= near - 1;
      double ex = x[q] - xi, ey = y[q] - yi, e2 = ex * ex + ey * ey;
      if (q != self && vx_merge_ok(gi, g[q], e2, rs, ro, gcap) && e2 < dmin) dmin = e2;
    }
  }
#else
#pragma omp simd reduction(min : dmin)
  for (size_t q = 0; q < n; ++q) {
    double dx = x[q] - xi, dy = y[q] - yi, d2 = dx * dx + dy * dy;
    int ok = vx_merge_ok(gi, g[q], d2, rs, ro, gcap) && q != self;
    double c = ok ? d2 : INFINITY;
    dmin = c < dmin ? c : dmin;
  }
#endif
  if (!(dmin < *dbest)) return;
  for (size_t q = 0; q < n; ++q) {
    double dx = x[q] - xi, dy = y[q] - yi, d2 = dx * dx + dy * dy;
    if (q != self && d2 == dmin && vx_merge_ok(gi, g[q], d2, rs, ro, gcap)) {
      *dbest = dmin;
      *best = (int32_t)(lo + q);
      return;
    }
  }
}

/* The merge partner of each vortex of the wake (sorted by e->tree) into
 * e->partner, by sorted position (-1: none): the nearest eligible neighbour,
 * same-sign within eps_col (grown downstream, growth) whose merged
 * circulation stays under gamma_max, opposite-sign within eps_col_opposite;
 * ties to the lower sorted position. */
static enum px_status merge_partners(struct px_vortex_engine *e, size_t a, size_t b) {
  struct px_vortex_wake *w = &e->w;
  const struct px_vortex_tree *t = &e->tree;
  const double ec = e->cfg.eps_col, eo = e->cfg.eps_col_opposite, gmax = e->cfg.gamma_max;
  const double emax = ec > eo ? ec : eo;
  int oom = 0;
  /* circulations in sorted order: contiguous reads in the scans (w->s1 is
   * scratch; px_vortex_merge reuses it after) */
  double *sg = w->s1;
#pragma omp parallel for num_threads(e->cfg.threads) schedule(static)
  for (size_t sp = 0; sp < t->n; ++sp) sg[sp] = w->g[e->hit[t->order[sp]]]; /* px_vortex_drop */
  /* partner search (parallel, each vortex on its own): the nearest eligible
   * neighbour, ties to the lower sorted position. Each leaf's candidates:
   * the leaves within its largest reach plus its half-diagonal, taken from
   * one tree query per group of neighbouring leaves (VX_MERGE_GROUP points,
   * px_vortex_vvd_leaves_within on the group's boxes: the list a query of
   * the leaf's own gives;
   * a query per leaf was ~1% of a step, 2026-11-28; taking the group's
   * list for every vortex, as the diffusive block's vortices do, measured
   * slower here); each vortex scans the points of the candidate leaves
   * within its reach, as runs of consecutive sorted positions in the
   * leaves' order (px_vortex_vvd_leaf_runs, a vector box test): every point
   * farther than ro fails the tests below, so the partner is the one a
   * query of its own would give. */
  uint32_t *grp = px_mem_alloc(e->ctx, "vortex.work", (t->nnode ? t->nnode : 1) * sizeof(uint32_t));
  if (!grp) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (merge groups)");
  const size_t ngrp = px_vortex_tree_groups(t, VX_MERGE_GROUP, grp);
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 4)
  for (long lg = 0; lg < (long)ngrp; ++lg) {
    struct px_vortex_nbuf *nb = &e->nbuf[omp_get_thread_num()];
    /* the group's leaves in this rank's share, and each one's reach */
    uint32_t lv[VX_MERGE_GROUP], stack[2 * VX_MERGE_GROUP]; /* depth <= points */
    double lx[VX_MERGE_GROUP], ly[VX_MERGE_GROUP], lr[VX_MERGE_GROUP];
    size_t nlv = 0;
    int sp0 = 0;
    stack[sp0++] = grp[lg];
    while (sp0 > 0) {
      const uint32_t k = stack[--sp0];
      if (t->left[k] >= 0) {
        stack[sp0++] = (uint32_t)(t->left[k] + 1);
        stack[sp0++] = (uint32_t)t->left[k];
        continue;
      }
      if (t->lo[k] < a || t->lo[k] >= b) continue;
      double romax = 0.0;
      for (uint32_t sp = t->lo[k]; sp < t->hi[k]; ++sp)
        romax = fmax(romax, emax * growth(e, t->sx[sp], t->sy[sp]));
      const double hd = 0.5 * hypot(t->bx1[k] - t->bx0[k], t->by1[k] - t->by0[k]);
      lv[nlv] = k;
      lx[nlv] = 0.5 * (t->bx0[k] + t->bx1[k]);
      ly[nlv] = 0.5 * (t->by0[k] + t->by1[k]);
      lr[nlv++] = (romax + hd) * (1.0 + 1e-9) + 1e-300;
    }
    if (nlv == 0) continue;
    double gx, gy;
    const double rg = px_vortex_cover(lx, ly, lr, nlv, &gx, &gy);
    const size_t nsl = px_vortex_leaves_into(e, t, gx, gy, rg, &nb->sl, &nb->sl_cap);
    if (nsl == (size_t)-1 || !px_vortex_list_reserve(e, &nb->gl, &nb->gl_cap, nsl + 8) ||
        !px_vortex_list_reserve(e, &nb->fl, &nb->fl_cap, 2 * nsl + 2) ||
        !px_vortex_arrays_reserve(e, &nb->lb, &nb->lb_cap, nsl + 8, 6) ||
        !px_vortex_arrays_reserve(e, &nb->sb, &nb->sb_cap, nsl + 8, 6)) {
      oom = 1;
      continue;
    }
    /* the group's leaves' boxes once, each leaf's list by a vector test */
    px_vortex_vvd_leaf_boxes(t, nb->sl, nsl, nb->sb, nb->sb_cap);
    for (size_t q = 0; q < nlv; ++q) {
      const size_t k = lv[q];
      const size_t ngl = px_vortex_vvd_leaves_within(nb->sl, nb->sb, nsl, nb->sb_cap, lx[q], ly[q],
                                                     lr[q] * lr[q], nb->gl);
      px_vortex_vvd_leaf_boxes(t, nb->gl, ngl, nb->lb, nb->lb_cap);
      for (uint32_t sp = t->lo[k]; sp < t->hi[k]; ++sp) {
        double xi = t->sx[sp], yi = t->sy[sp], gi = sg[sp];
        double f = growth(e, xi, yi);
        double rs = ec * f, ro = eo * f, rb = rs > ro ? rs : ro, gcap = gmax * f * f;
        int32_t best = -1;
        double dbest = INFINITY;
        size_t nr =
            px_vortex_vvd_leaf_runs(t, nb->gl, nb->lb, ngl, nb->lb_cap, xi, yi, rb * rb, nb->fl);
        for (size_t r = 0; r < nr; ++r)
          merge_scan(t->sx, t->sy, sg, nb->fl[2 * r], nb->fl[2 * r + 1], sp, xi, yi, gi, rs, ro,
                     gcap, &dbest, &best);
        e->partner[sp] = best;
      }
    }
  }
  px_mem_free(e->ctx, grp);
  if (oom) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)");
  return PX_STATUS_OK;
}

static enum px_status restructure(struct px_vortex_engine *e) {
  size_t m = px_vortex_drop(e);
  if (m == 0) return PX_STATUS_OK;
  /* no hint: the moved wake is far from the last tree's order (insertion
   * would move 4e7-9e7 entries at 55k vortices) */
  enum px_status st = px_vortex_tree_build(e->ctx, &e->tree, m, e->w.x, e->w.y, 0, e->cfg.threads);
  if (st == PX_STATUS_OK) {
    /* over several ranks, each searches the partners of its leaves (those
     * starting in its share of the tree's Morton order) and all get all */
    size_t a = 0, b = m, lo = 0, hi = m;
    px_vortex_ranks_leaves(e, &e->tree, &a, &b, &lo, &hi);
    st = merge_partners(e, a, b);
    st = px_vortex_ranks_gather_runs(e, st, m, lo, hi, e->partner, sizeof(int32_t));
  }
  if (st == PX_STATUS_OK) return px_vortex_merge(e, crossed_panel);
  px_vortex_drop_finish(e); /* the wake whole for the diagnosis */
  return st;
}

/* ---- the cpu engine's blocks (vortex_engine.h) ---------------------------- */

static void cpu_caps(struct px_backend *be, struct px_vortex_caps *out) {
  (void)be;
  out->fp64 = out->fmm = out->mixed = out->ranks = 1;
}

/* The panel matrix's inverse compressed for the solve of every step
 * (px_vortex_panels_compress; not in single precision, which solves by
 * its float LU). After px_vortex_ranks_init: every rank compresses the same
 * broadcast inverse. */
static enum px_status cpu_create(struct px_vortex_engine *e) {
  struct px_vortex_panels *p = &e->pan;
  if (p->n == 0 || e->cfg.precision == PX_PRECISION_SINGLE) return PX_STATUS_OK;
  PX_TRY(px_vortex_panels_compress(e->ctx, p));
  const double dense = 8.0 * (double)p->nsys * (double)p->nsys / 1e6;
  if (p->hodlr)
    px_log(e->ctx, PX_LOG_LEVEL_INFO,
           "panel matrix: the solve reads a compressed inverse of %.1f MB instead of %.1f MB "
           "(off-diagonal blocks of low rank; within %.1e of the dense product)",
           (double)px_vortex_hodlr_bytes(p->hodlr) / 1e6, dense, px_vortex_hodlr_check(p->hodlr));
  return PX_STATUS_OK;
}

static enum px_status cpu_generation(struct px_vortex_engine *e, double vx, double vy) {
  PX_TRY(generation(e, vx, vy, e->through));
  return px_vortex_ensure_work(e, e->w.n);
}

static enum px_status cpu_diffusive(struct px_vortex_engine *e) {
  return px_vortex_engine_diffusive(e, 1, 1.5 * e->cfg.vref);
}

/* Block 5 into xn, yn: explicit Euler, or Heun's method with rk2, whose
 * second stage runs this engine's blocks. */
static enum px_status cpu_move(struct px_vortex_engine *e) {
  static const struct px_vortex_stages stages = {generation, convective, cpu_diffusive,
                                                 crossed_panel, crossings};
  return px_vortex_move(e, &stages);
}

/* Block 7, then the wake's total circulation (a diagnostic of the step);
 * over several ranks, their copies of the wake checked alike. */
static enum px_status cpu_restructure(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  enum px_status st = restructure(e);
  double c = 0.0;
  for (size_t i = 0; st == PX_STATUS_OK && i < w->n; ++i) c += w->g[i];
  e->circulation = c;
  return px_vortex_ranks_verify(e, st);
}

const struct px_vortex_engine_i px_vortex_engine_cpu = {
    .backend = "cpu",
    .caps = cpu_caps,
    .create = cpu_create,
    .begin = px_vortex_host_begin,
    .generation = cpu_generation,
    .convective = convective,
    .diffusive = cpu_diffusive,
    .loads = loads,
    .move = cpu_move,
    .inside = inside,
    .restructure = cpu_restructure,
};
