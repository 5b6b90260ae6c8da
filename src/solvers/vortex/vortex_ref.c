/* The `reference` vortex engine (vortex_engine.h): the blocks of a step as
 * plain loops in double on one thread, every sum direct over all vortices or
 * all panels (no tree search, no FMM, no OpenMP, no packed vector loops), for
 * tests that cross-check the fast engines (tests/vortex/test_vortex_ref.c).
 * Its physics is theirs, written once: the per-pair and per-panel formulas of
 * vortex_kernel.h (Biot-Savart, the near-wall panel coefficient, eps*, the
 * wall integrals, the crossing test, the merge rules) and the serial parts of
 * a block around the sums (vortex_host.h: the sheet's solve and shedding, a
 * vortex's VVD velocity from its neighbours, the forces, Heun's stages,
 * merges and compaction). What it does its own way is finding what each sum
 * runs over: here, by testing every vortex and panel against the same
 * distance rules the trees answer.
 *
 * One exception to "no tree": restructuring merges in the wake's Morton order
 * and stores the wake in it (the order is part of the method: which of two
 * candidate merges comes first), so the reference builds the tree over the
 * survivors for that order only, and searches the partners by a double loop. */
#include "solvers/vortex/vortex_engine.h"

#include <math.h>
#include <string.h>

#include "partix/memory.h"
#include "solvers/vortex/vortex_core_impl.h"
#include "solvers/vortex/vortex_host.h"

#define PX_REAL double
#include "kernels/px_kernel.h"
#include "solvers/vortex/vortex_kernel.h"
#include "solvers/vortex/vortex_sheet.h"

/* Scratch of the diffusive block: one vortex's neighbours (offsets, then
 * circulations: 3 arrays of cap, 8 of slack) and panels within reach. */
struct ref_state {
  double *pd;
  size_t pd_cap;
  uint32_t *pl;
};

static void ref_caps(struct px_backend *be, struct px_vortex_caps *out) {
  (void)be;
  out->fp64 = 1;
  out->fmm = 0;
  out->mixed = 0;
}

static enum px_status ref_create(struct px_vortex_engine *e) {
  if (e->cfg.precision != PX_PRECISION_DOUBLE)
    return px_context_fail(e->ctx, PX_STATUS_UNSUPPORTED,
                           "the reference vortex engine runs in double precision only");
  struct ref_state *r = px_mem_calloc(e->ctx, "vortex.ref", 1, sizeof *r);
  if (!r) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory");
  r->pl = px_mem_alloc(e->ctx, "vortex.ref", (e->pan.n + 8) * sizeof(uint32_t));
  e->dev = r;
  if (!r->pl) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory");
  e->cfg.threads = 1; /* the host blocks' loops (Heun's predictor, the tree) */
  return PX_STATUS_OK;
}

static void ref_destroy(struct px_vortex_engine *e) {
  struct ref_state *r = e->dev;
  if (!r) return;
  px_mem_free(e->ctx, r->pd);
  px_mem_free(e->ctx, r->pl);
  px_mem_free(e->ctx, r);
  e->dev = NULL;
}

/* The smoothed Biot-Savart velocity of the whole wake at (x, y) [m/s]. */
static void wake_velocity(const struct px_vortex_wake *w, double eps2, double x, double y,
                          double *u, double *v) {
  double su = 0.0, sv = 0.0;
  for (size_t j = 0; j < w->n; ++j) {
    px_real2 t = px_biot_savart_term(x - w->x[j], y - w->y[j], w->g[j], eps2);
    su += t.x;
    sv += t.y;
  }
  *u = PX_BIOT_SAVART_SCALE * su;
  *v = PX_BIOT_SAVART_SCALE * sv;
}

/* Block 1: the right-hand side at each panel, the far field at its two Gauss
 * points plus the exact correction of the vortices within 2 L + eps of its
 * midpoint, then the shared solve and shedding. */
static enum px_status ref_generation(struct px_vortex_engine *e, double vx, double vy,
                                     const double *absorbed) {
  const struct px_vortex_panels *p = &e->pan;
  const struct px_vortex_wake *w = &e->w;
  const double eps2 = e->cfg.eps * e->cfg.eps;
  e->n_born = 0;
  if (p->n == 0) return PX_STATUS_OK;
  px_vortex_gauss_points(e);
  const double *gx = e->rhs_u, *gy = e->rhs_v;
  for (size_t i = 0; i < p->n; ++i) {
    double tx = p->tx[i], ty = p->ty[i], u0, v0, u1, v1;
    wake_velocity(w, eps2, gx[2 * i], gy[2 * i], &u0, &v0);
    wake_velocity(w, eps2, gx[2 * i + 1], gy[2 * i + 1], &u1, &v1);
    double wk = 0.5 * ((u0 + u1) * tx + (v0 + v1) * ty);
    if (w->n > 0) {
      double mx = 0.5 * (p->x0[i] + p->x1[i]), my = 0.5 * (p->y0[i] + p->y1[i]);
      double r = 2.0 * p->len[i] + e->cfg.eps, inv_len = 1.0 / p->len[i], corr = 0.0;
      for (size_t j = 0; j < w->n; ++j) {
        double dx = w->x[j] - mx, dy = w->y[j] - my;
        if (dx * dx + dy * dy > r * r) continue;
        corr += w->g[j] * vx_near_coef(p->x0[i], p->y0[i], p->x1[i], p->y1[i], inv_len, tx, ty,
                                       gx[2 * i], gy[2 * i], gx[2 * i + 1], gy[2 * i + 1], eps2,
                                       w->x[j], w->y[j]);
      }
      wk += corr;
    }
    e->sol[i] = -(vx * tx + vy * ty) - wk;
  }
  return px_vortex_sheet_shed(e, vx, vy, absorbed);
}

static enum px_status ref_step_generation(struct px_vortex_engine *e, double vx, double vy) {
  PX_TRY(ref_generation(e, vx, vy, e->through));
  return px_vortex_ensure_work(e, e->w.n);
}

/* Block 2: the wake's field and the free stream at every old vortex, the
 * exact sheet of every panel near it (sheet_exact), the newborns' own. */
static enum px_status ref_convective(struct px_vortex_engine *e, double vx, double vy) {
  struct px_vortex_wake *w = &e->w;
  const size_t nold = w->n - e->n_born;
  const double eps2 = e->cfg.eps * e->cfg.eps;
  const int sheet = e->cfg.sheet_exact && e->pan.n > 0 && e->n_born > 0;
  for (size_t i = 0; i < nold; ++i) {
    double u, v, cu = 0.0, cv = 0.0;
    wake_velocity(w, eps2, w->x[i], w->y[i], &u, &v);
    for (size_t k = 0; sheet && k < e->pan.n; ++k)
      px_vortex_sheet_term(e, k, w->x[i], w->y[i], &cu, &cv);
    w->u[i] = u + vx + cu;
    w->v[i] = v + vy + cv;
  }
  return px_vortex_newborn_convective(e);
}

/* Block 3 for vortex i: eps* from the 3 smallest squared distances to the
 * others, its neighbours within cut eps* (offsets x_i - x_j) and the panels
 * whose midpoint lies within cut eps* + L_max / 2, then the shared VVD. */
static void ref_vvd(struct px_vortex_engine *e, struct ref_state *r, size_t i, double vcap) {
  struct px_vortex_wake *w = &e->w;
  const struct px_vortex_panels *p = &e->pan;
  const double cut = e->cfg.cutoff, xi = w->x[i], yi = w->y[i];
  double d2[3] = {INFINITY, INFINITY, INFINITY};
  for (size_t j = 0; j < w->n; ++j) {
    if (j == i) continue;
    double dx = xi - w->x[j], dy = yi - w->y[j], d = dx * dx + dy * dy;
    if (d >= d2[2]) continue;
    int q = 2;
    for (; q > 0 && d < d2[q - 1]; --q) d2[q] = d2[q - 1];
    d2[q] = d;
  }
  const double ei = vx_eps_star(d2[0], d2[1], d2[2], e->cfg.eps_min);
  w->e[i] = ei;
  double *pdx = r->pd, *pdy = r->pd + r->pd_cap, *pg = r->pd + 2 * r->pd_cap;
  const double r2 = cut * ei * cut * ei;
  size_t np = 0, pc = 0;
  for (size_t j = 0; j < w->n; ++j) {
    double dx = xi - w->x[j], dy = yi - w->y[j];
    if (j == i || !(dx * dx + dy * dy <= r2)) continue;
    pdx[np] = dx;
    pdy[np] = dy;
    pg[np] = w->g[j];
    ++np;
  }
  if (p->n > 0) {
    const double rp = cut * ei + 0.5 * p->lmax;
    for (size_t k = 0; k < p->n; ++k) {
      double dx = 0.5 * (p->x0[k] + p->x1[k]) - xi, dy = 0.5 * (p->y0[k] + p->y1[k]) - yi;
      if (dx * dx + dy * dy <= rp * rp) r->pl[pc++] = (uint32_t)k;
    }
  }
  px_vortex_vvd_velocity(e, pdx, pdy, pg, np, r->pl, pc, w->g[i], ei, xi, yi, w->born[i], vcap,
                         &w->wu[i], &w->wv[i]);
}

static enum px_status ref_diffusive(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  struct ref_state *r = e->dev;
  if (w->n == 0) return PX_STATUS_OK;
  if (w->n + 8 > r->pd_cap) {
    px_mem_free(e->ctx, r->pd);
    r->pd_cap = w->n + w->n / 2 + 8;
    r->pd = px_mem_alloc(e->ctx, "vortex.ref", 3 * r->pd_cap * sizeof(double));
    if (!r->pd) {
      r->pd_cap = 0;
      return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (reference neighbours)");
    }
  }
  for (size_t i = 0; i < w->n; ++i) ref_vvd(e, r, i, 1.5 * e->cfg.vref);
  return px_vortex_diffusive_finite(e);
}

/* Block 4: each panel's wall vorticity, the S3 integral (vx_panel_wall) of
 * every vortex within cut e_k + L_k / 2 of its midpoint, then the forces. */
static enum px_status ref_loads(struct px_vortex_engine *e) {
  const struct px_vortex_wake *w = &e->w;
  const struct px_vortex_panels *p = &e->pan;
  const double cut = e->cfg.cutoff;
  px_vortex_panel_radius(e);
  for (size_t k = 0; k < p->n; ++k) {
    double ek = e->pe[k], acc = 0.0;
    double mx = 0.5 * (p->x0[k] + p->x1[k]), my = 0.5 * (p->y0[k] + p->y1[k]);
    double r = cut * ek + 0.5 * p->len[k];
    for (size_t j = 0; j < w->n; ++j) {
      double dx = w->x[j] - mx, dy = w->y[j] - my;
      if (dx * dx + dy * dy > r * r) continue;
      double rx = w->x[j] - p->x0[k], ry = w->y[j] - p->y0[k], s3, s0;
      vx_panel_wall(rx * p->tx[k] + ry * p->ty[k], rx * p->ty[k] - ry * p->tx[k], p->len[k], ek,
                    cut, &s3, &s0);
      acc += w->g[j] * s3;
    }
    e->omega[k] = acc / (VX_PI * ek * ek * p->len[k]);
  }
  px_vortex_forces(e);
  return PX_STATUS_OK;
}

/* The first panel the path crosses (the smallest parameter, ties to the
 * lower panel), or -1: every panel tested. */
static int32_t ref_crossed(struct px_vortex_engine *e, double x0, double y0, double x1, double y1,
                           int *oom) {
  const struct px_vortex_panels *p = &e->pan;
  (void)oom;
  int32_t best = -1;
  double tbest = 2.0;
  for (size_t k = 0; k < p->n; ++k) {
    double t;
    if (vx_seg_cross(x0, y0, x1, y1, p->x0[k], p->y0[k], p->x1[k], p->y1[k], &t) && t < tbest) {
      tbest = t;
      best = (int32_t)k;
    }
  }
  return best;
}

/* Block 5: Euler, or Heun with this engine's blocks as its second stage. */
static enum px_status ref_move(struct px_vortex_engine *e) {
  static const struct px_vortex_stages stages = {ref_generation, ref_convective, ref_diffusive,
                                                 ref_crossed, NULL};
  return px_vortex_move(e, &stages);
}

static enum px_status ref_inside(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  for (size_t i = 0; i < w->n; ++i)
    e->hit[i] = ref_crossed(e, w->x[i], w->y[i], e->xn[i], e->yn[i], NULL);
  px_vortex_absorb(e);
  return PX_STATUS_OK;
}

/* Block 7: the survivors, each one's nearest eligible partner by a double
 * loop over the Morton order (ties to the lower position), the shared merge. */
static enum px_status ref_restructure(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  size_t m = px_vortex_drop(e);
  if (m > 0) {
    enum px_status st = px_vortex_tree_build(e->ctx, &e->tree, m, w->x, w->y, 0, 1);
    if (st != PX_STATUS_OK) {
      px_vortex_drop_finish(e);
      return st;
    }
    const struct px_vortex_tree *t = &e->tree;
    const double ec = e->cfg.eps_col, eo = e->cfg.eps_col_opposite, gmax = e->cfg.gamma_max;
    for (size_t sp = 0; sp < m; ++sp) {
      double xi = t->sx[sp], yi = t->sy[sp], gi = w->g[e->hit[t->order[sp]]];
      double f =
          vx_merge_growth(xi * e->stream_dir[0] + yi * e->stream_dir[1], e->s_right, e->span);
      double rs = ec * f, ro = eo * f, gcap = gmax * f * f, dbest = INFINITY;
      int32_t best = -1;
      for (size_t sj = 0; sj < m; ++sj) {
        double dx = t->sx[sj] - xi, dy = t->sy[sj] - yi, d2 = dx * dx + dy * dy;
        if (sj != sp && vx_merge_ok(gi, w->g[e->hit[t->order[sj]]], d2, rs, ro, gcap) &&
            d2 < dbest) {
          dbest = d2;
          best = (int32_t)sj;
        }
      }
      e->partner[sp] = best;
    }
    PX_TRY(px_vortex_merge(e, ref_crossed));
  }
  double c = 0.0;
  for (size_t i = 0; i < w->n; ++i) c += w->g[i];
  e->circulation = c;
  return PX_STATUS_OK;
}

const struct px_vortex_engine_i px_vortex_engine_ref = {
    .backend = "reference",
    .caps = ref_caps,
    .create = ref_create,
    .destroy = ref_destroy,
    .begin = px_vortex_host_begin,
    .generation = ref_step_generation,
    .convective = ref_convective,
    .diffusive = ref_diffusive,
    .loads = ref_loads,
    .move = ref_move,
    .inside = ref_inside,
    .restructure = ref_restructure,
};
