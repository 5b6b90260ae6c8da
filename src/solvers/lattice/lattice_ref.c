/* Reference lattice time step (see lattice_ref.h). */
#include "solvers/lattice/lattice_ref.h"

#include <math.h>
#include <string.h>

#include "partix/memory.h"

void px_lattice_lpar_d(const struct px_lattice_model *m, struct lt_lpar *p) {
  p->h2 = 0.5 * m->grid.h;
  p->k = m->k;
  p->cl = m->cl;
  p->kb = m->kb;
  p->dk = m->kt - m->kb;
  p->cr = m->cr;
}

void px_lattice_fpar_d(const struct px_lattice_model *m, struct lt_fpar *f) {
  f->ifn = m->par.f_nc > 0.0 ? 1.0 / m->par.f_nc : 0.0;
  f->ift = m->par.f_tc > 0.0 ? 1.0 / m->par.f_tc : 0.0;
  f->imb = m->par.m_bc > 0.0 ? 1.0 / m->par.m_bc : 0.0;
  f->imt = m->par.m_tc > 0.0 ? 1.0 / m->par.m_tc : 0.0;
}

static void px_lattice_rest(struct lt_el *y, size_t n) {
  size_t i;
  memset(y, 0, n * sizeof *y);
  for (i = 0; i < n; ++i) y[i].q.w = 1.0;
}

void px_lattice_ref_free(struct px_lattice_ref *r) {
  struct px_context *ctx;
  if (!r || !r->ctx) return;
  ctx = r->ctx;
  px_mem_free(ctx, r->y);
  px_mem_free(ctx, r->links);
  px_mem_free(ctx, r->ys);
  px_mem_free(ctx, r->k);
  px_mem_free(ctx, r->acc);
  px_mem_free(ctx, r->F);
  px_mem_free(ctx, r->T);
  px_mem_free(ctx, r->table);
  memset(r, 0, sizeof *r);
}

enum px_status px_lattice_ref_create(struct px_context *ctx, const struct px_lattice_model *m,
                                     enum px_lattice_integrator integ, struct px_lattice_ref *r) {
  size_t n = m->nalloc;
  memset(r, 0, sizeof *r);
  r->ctx = ctx;
  r->m = m;
  r->integ = integ;
  r->alpha = m->par.alpha;
  r->y = (struct lt_el *)px_mem_alloc(ctx, "lattice.ref", n * sizeof *r->y);
  r->ys = (struct lt_el *)px_mem_alloc(ctx, "lattice.ref", n * sizeof *r->ys);
  r->k = (struct lt_el *)px_mem_alloc(ctx, "lattice.ref", n * sizeof *r->k);
  r->acc = (struct lt_el *)px_mem_alloc(ctx, "lattice.ref", n * sizeof *r->acc);
  r->F = (struct lt_v3 *)px_mem_alloc(ctx, "lattice.ref", n * sizeof *r->F);
  r->T = (struct lt_v3 *)px_mem_alloc(ctx, "lattice.ref", n * sizeof *r->T);
  r->links = (uint8_t *)px_mem_alloc(ctx, "lattice.ref", n);
  r->table = (double *)px_mem_alloc(ctx, "lattice.ref",
                                    m->ngroup * PX_LATTICE_GROUP_STRIDE * sizeof(double));
  if (!r->y || !r->ys || !r->k || !r->acc || !r->F || !r->T || !r->links || !r->table) {
    px_lattice_ref_free(r);
    return PX_STATUS_NOMEM;
  }
  px_lattice_rest(r->y, n);
  memcpy(r->links, m->links, n);
  return PX_STATUS_OK;
}

/* Volumetric strain theta of element i (lattice_kernel.h: the mean stretch
 * of its intact links along each axis, summed) in plain loops; c[a] its
 * intact links along a, S[a] the sum of their stretches. */
static double px_lattice_ref_theta(const struct px_lattice_model *m, const uint8_t *links,
                                   const struct lt_el *y, size_t i, double c[3], double S[3]) {
  const double h2 = 0.5 * m->grid.h;
  double th = 0.0;
  int a;
  for (a = 0; a < 3; ++a) {
    const size_t s = (size_t)m->stride[a];
    double sum = 0.0;
    int n = 0;
    if (links[i] & PX_LATTICE_LINK_PLUS(a)) {
      sum += lt_link_stretch(h2, a, y[i], y[i + s], lt_frame_col(y[i].q, a),
                             lt_frame_col(y[i + s].q, a));
      ++n;
    }
    if (links[i] & PX_LATTICE_LINK_MINUS(a)) {
      sum += lt_link_stretch(h2, a, y[i - s], y[i], lt_frame_col(y[i - s].q, a),
                             lt_frame_col(y[i].q, a));
      ++n;
    }
    c[a] = n;
    S[a] = sum;
    if (n) th += sum / n;
  }
  return th;
}

/* Coefficient P_a of element i [N] (lattice_kernel.h lt_vol_coef):
 * (lambda h^2 theta + (2 - c_a) mu h^2 S_a) / c_a for a free element
 * (m->vfree), without the second term for a held one; 0 at c_a = 0;
 * mu h^2 = k h/2. */
static double px_lattice_ref_vol(const struct px_lattice_model *m, const uint8_t *links,
                                 const struct lt_el *y, size_t i, int a) {
  double c[3], S[3], th = px_lattice_ref_theta(m, links, y, i, c, S);
  double h = m->grid.h, mh2 = m->vfree[i] ? 0.5 * m->k * h : 0.0;
  if (c[a] == 0) return 0.0;
  return (m->lam * h * h * th + (2.0 - c[a]) * mh2 * S[a]) / c[a];
}

/* The force of the link from i to its + neighbour j along a: lt_link's, plus
 * the volumetric force at nu != 0. */
static struct lt_lres px_lattice_ref_link(const struct px_lattice_model *m,
                                          const struct lt_lpar *lp, const uint8_t *links,
                                          const struct lt_el *y, size_t i, size_t j, int a) {
  struct lt_lres res = lt_link(lp, a, y[i], y[j], lt_frame_col(y[i].q, a), lt_frame_col(y[j].q, a));
  if (m->lam != 0.0)
    res.F = lt_vol_add(
        res.F, a, px_lattice_ref_vol(m, links, y, i, a) + px_lattice_ref_vol(m, links, y, j, a));
  return res;
}

/* 2/c_a for an element with link flags f: 1 with both links along a, 2
 * with one (the mean traction of the stress estimator, lattice_kernel.h). */
static double px_lattice_ref_axis_scale(uint8_t f, int a) {
  return (f & PX_LATTICE_LINK_PLUS(a)) && (f & PX_LATTICE_LINK_MINUS(a)) ? 1.0 : 2.0;
}

void px_lattice_ref_forces(const struct px_lattice_model *m, uint8_t *links, const struct lt_el *y,
                           int fracture, long *broken, struct lt_v3 *F, struct lt_v3 *T) {
  struct lt_lpar lp;
  struct lt_fpar fp;
  size_t c, n = m->nalloc;
  px_lattice_lpar_d(m, &lp);
  px_lattice_fpar_d(m, &fp);
  memset(F, 0, n * sizeof *F);
  memset(T, 0, n * sizeof *T);
  /* fracture first (the spring forces decide), so that the volumetric term
   * sees the links that remain */
  for (c = 0; fracture && c < m->grid.ncell; ++c) {
    size_t i = px_lattice_index(m, c);
    int a;
    for (a = 0; a < 3; ++a) {
      size_t j;
      struct lt_v3 b1;
      if (!(links[i] & PX_LATTICE_LINK_PLUS(a))) continue;
      j = i + (size_t)m->stride[a];
      b1 = lt_frame_col(y[i].q, a);
      if (lt_link_break(&lp, &fp, a, b1,
                        lt_link(&lp, a, y[i], y[j], b1, lt_frame_col(y[j].q, a))) >= 1.0) {
        links[i] &= (uint8_t)~PX_LATTICE_LINK_PLUS(a);
        links[j] &= (uint8_t)~PX_LATTICE_LINK_MINUS(a);
        if (broken) ++*broken;
      }
    }
  }
  for (c = 0; c < m->grid.ncell; ++c) {
    size_t i = px_lattice_index(m, c);
    int a;
    for (a = 0; a < 3; ++a) {
      size_t j;
      struct lt_v3 b1, b2;
      struct lt_lres res;
      if (!(links[i] & PX_LATTICE_LINK_PLUS(a))) continue;
      j = i + (size_t)m->stride[a];
      b1 = lt_frame_col(y[i].q, a);
      b2 = lt_frame_col(y[j].q, a);
      res = px_lattice_ref_link(m, &lp, links, y, i, j, a);
      F[i] = lt_v3_add(F[i], res.F);
      F[j] = lt_v3_sub(F[j], res.F);
      T[i] = lt_v3_add(T[i], lt_v3_add(lt_link_lever(lp.h2, a, b1, res.F), res.G));
      T[j] = lt_v3_add(T[j], lt_v3_sub(lt_link_lever(lp.h2, a, b2, res.F), res.G));
    }
  }
}

/* Time derivative of the state y into k (forces from the current flags). */
static void px_lattice_ref_deriv(struct px_lattice_ref *r, const struct lt_el *y, double t,
                                 int fracture) {
  const struct px_lattice_model *m = r->m;
  size_t i;
  px_lattice_model_groups(m, t, r->table);
  px_lattice_ref_forces(m, r->links, y, fracture, &r->broken, r->F, r->T);
  for (i = 0; i < m->nalloc; ++i) {
    const double *g = r->table + (size_t)m->group[i] * PX_LATTICE_GROUP_STRIDE;
    r->k[i].u = y[i].v;
    r->k[i].q = lt_qdot(y[i].q, y[i].W);
    {
      struct lt_dvw d =
          lt_accel(g, 1.0 / m->m, 1.0 / m->I, r->alpha, r->F[i], r->T[i], y[i].v, y[i].W);
      r->k[i].v = d.dv;
      r->k[i].W = d.dW;
    }
  }
}

/* out = y + s k (all 13 components) */
static void px_lattice_axpy(struct lt_el *out, const struct lt_el *y, double s,
                            const struct lt_el *k, size_t n) {
  size_t i;
  for (i = 0; i < n; ++i) {
    out[i].u = lt_v3_add(y[i].u, lt_v3_scale(s, k[i].u));
    out[i].v = lt_v3_add(y[i].v, lt_v3_scale(s, k[i].v));
    out[i].W = lt_v3_add(y[i].W, lt_v3_scale(s, k[i].W));
    out[i].q.w = y[i].q.w + s * k[i].q.w;
    out[i].q.x = y[i].q.x + s * k[i].q.x;
    out[i].q.y = y[i].q.y + s * k[i].q.y;
    out[i].q.z = y[i].q.z + s * k[i].q.z;
  }
}

static enum px_status px_lattice_ref_rk4(struct px_lattice_ref *r, double t, double dt) {
  const struct px_lattice_model *m = r->m;
  size_t n = m->nalloc, i;
  static const double c[4] = {0.0, 0.5, 0.5, 1.0};
  static const double b[4] = {1.0, 2.0, 2.0, 1.0};
  int s;
  memset(r->acc, 0, n * sizeof *r->acc);
  for (s = 0; s < 4; ++s) {
    const struct lt_el *ys = s == 0 ? r->y : r->ys;
    px_lattice_ref_deriv(r, ys, t + c[s] * dt, s == 0 && m->fracture);
    px_lattice_axpy(r->acc, r->acc, b[s], r->k, n);
    if (s < 3) px_lattice_axpy(r->ys, r->y, c[s + 1] * dt, r->k, n);
  }
  px_lattice_axpy(r->y, r->y, dt / 6.0, r->acc, n);
  for (i = 0; i < n; ++i) r->y[i].q = lt_qnormalize(r->y[i].q);
  return PX_STATUS_OK;
}

static enum px_status px_lattice_ref_leapfrog(struct px_lattice_ref *r, double t, double dt) {
  const struct px_lattice_model *m = r->m;
  size_t i;
  double h = 0.5 * r->alpha * dt, im = 1.0 / m->m, ii = 1.0 / m->I;
  px_lattice_model_groups(m, t, r->table);
  px_lattice_ref_forces(m, r->links, r->y, m->fracture, &r->broken, r->F, r->T);
  for (i = 0; i < m->nalloc; ++i) {
    const double *g = r->table + (size_t)m->group[i] * PX_LATTICE_GROUP_STRIDE;
    struct lt_el *e = &r->y[i];
    e->v.x = lt_kick(g[0], g[6], g[12], im, h, dt, r->F[i].x, e->v.x);
    e->v.y = lt_kick(g[1], g[7], g[13], im, h, dt, r->F[i].y, e->v.y);
    e->v.z = lt_kick(g[2], g[8], g[14], im, h, dt, r->F[i].z, e->v.z);
    e->W.x = lt_kick(g[3], g[9], g[15], ii, h, dt, r->T[i].x, e->W.x);
    e->W.y = lt_kick(g[4], g[10], g[16], ii, h, dt, r->T[i].y, e->W.y);
    e->W.z = lt_kick(g[5], g[11], g[17], ii, h, dt, r->T[i].z, e->W.z);
    e->u = lt_v3_add(e->u, lt_v3_scale(dt, e->v));
    e->q = lt_qrotate(e->q, lt_v3_scale(dt, e->W));
  }
  return PX_STATUS_OK;
}

enum px_status px_lattice_check_finite_d(struct px_context *ctx, const struct px_lattice_model *m,
                                         const struct lt_el *y, long step) {
  size_t c;
  (void)step; /* the run driver names the step */
  for (c = 0; c < m->grid.ncell; ++c) {
    const struct lt_el *e = &y[px_lattice_index(m, c)];
    const char *what = NULL;
    if (!m->grid.occ[c]) continue;
    if (!isfinite(e->u.x) || !isfinite(e->u.y) || !isfinite(e->u.z))
      what = "displacement";
    else if (!isfinite(e->v.x) || !isfinite(e->v.y) || !isfinite(e->v.z))
      what = "velocity";
    else if (!isfinite(e->W.x) || !isfinite(e->W.y) || !isfinite(e->W.z))
      what = "angular velocity";
    else if (!isfinite(e->q.w) || !isfinite(e->q.x) || !isfinite(e->q.y) || !isfinite(e->q.z))
      what = "orientation";
    if (what) {
      double x[3];
      size_t n0 = (size_t)m->grid.n[0], n1 = (size_t)m->grid.n[1];
      px_lattice_grid_centre(&m->grid, c, x);
      return px_context_fail(ctx, PX_STATUS_NUMERIC,
                             "the %s of element (%zu, %zu, %zu) at (%g, %g, %g) m is not "
                             "finite (time step too large for the damping/stiffness, or an "
                             "unbounded load)",
                             what, c % n0, (c / n0) % n1, c / (n0 * n1), x[0], x[1], x[2]);
    }
  }
  return PX_STATUS_OK;
}

enum px_status px_lattice_ref_step(struct px_lattice_ref *r, double t, double dt) {
  if (r->integ == PX_LATTICE_INTEGRATOR_LEAPFROG)
    PX_TRY(px_lattice_ref_leapfrog(r, t, dt));
  else
    PX_TRY(px_lattice_ref_rk4(r, t, dt));
  return px_lattice_check_finite_d(r->ctx, r->m, r->y, -1);
}

void px_lattice_ref_energy(struct px_lattice_ref *r, double t, double dt, double *kinetic,
                           double *elastic) {
  const struct px_lattice_model *m = r->m;
  struct lt_lpar lp;
  double ek = 0.0, ep = 0.0;
  size_t c;
  int sync = r->integ == PX_LATTICE_INTEGRATOR_LEAPFROG;
  px_lattice_lpar_d(m, &lp);
  if (sync) {
    px_lattice_model_groups(m, t, r->table);
    px_lattice_ref_forces(m, r->links, r->y, 0, NULL, r->F, r->T);
  }
  for (c = 0; c < m->grid.ncell; ++c) {
    size_t i = px_lattice_index(m, c);
    struct lt_v3 v = r->y[i].v, W = r->y[i].W;
    int a;
    if (!m->grid.occ[c]) continue;
    if (sync) {
      const double *g = r->table + (size_t)m->group[i] * PX_LATTICE_GROUP_STRIDE;
      /* half a kick without damping: the energy of the conservative system */
      struct lt_dvw d = lt_accel(g, 1.0 / m->m, 1.0 / m->I, 0.0, r->F[i], r->T[i], v, W);
      v = lt_v3_add(v, lt_v3_scale(0.5 * dt, d.dv));
      W = lt_v3_add(W, lt_v3_scale(0.5 * dt, d.dW));
    }
    ek += 0.5 * m->m * lt_v3_dot(v, v) + 0.5 * m->I * lt_v3_dot(W, W);
    if (m->lam != 0.0) {
      /* (lambda/2) h^3 theta^2, and for a free element (mu/2) h^3 s^2
       * along each axis with one link (its cube's half of the normal
       * spring beyond the link) */
      double cn[3], S[3], th = px_lattice_ref_theta(m, r->links, r->y, i, cn, S);
      const double h = m->grid.h;
      int b;
      ep += m->lam * h * h * h / 2.0 * th * th;
      for (b = 0; b < 3; ++b)
        if (cn[b] == 1 && m->vfree[i]) ep += 0.25 * m->k * h * h * S[b] * S[b];
    }
    for (a = 0; a < 3; ++a) {
      size_t j;
      struct lt_lres res;
      if (!(r->links[i] & PX_LATTICE_LINK_PLUS(a))) continue;
      j = i + (size_t)m->stride[a];
      res =
          lt_link(&lp, a, r->y[i], r->y[j], lt_frame_col(r->y[i].q, a), lt_frame_col(r->y[j].q, a));
      ep += lt_link_energy(&lp, res);
    }
  }
  *kinetic = ek;
  *elastic = ep;
}

void px_lattice_ref_stress(const struct px_lattice_ref *r, struct lt_sym *s) {
  const struct px_lattice_model *m = r->m;
  struct lt_lpar lp;
  size_t c, n = m->nalloc;
  double inv_v = 1.0 / (m->grid.h * m->grid.h * m->grid.h);
  struct lt_m3 *M = (struct lt_m3 *)px_mem_calloc(r->ctx, "lattice.ref", n, sizeof *M);
  px_lattice_lpar_d(m, &lp);
  memset(s, 0, n * sizeof *s);
  if (!M) return; /* out of memory: zero stress (a test tool; px_mem reports it) */
  /* each link once, its lever-arm products to both ends; per axis the mean
   * over the intact links (kernel: lt_stress_fin) */
  for (c = 0; c < m->grid.ncell; ++c) {
    size_t i = px_lattice_index(m, c);
    int a;
    for (a = 0; a < 3; ++a) {
      size_t j;
      struct lt_lres res;
      if (!(r->links[i] & PX_LATTICE_LINK_PLUS(a))) continue;
      j = i + (size_t)m->stride[a];
      res = px_lattice_ref_link(m, &lp, r->links, r->y, i, j, a);
      M[i] = lt_m3_add(M[i], lp.h2 * px_lattice_ref_axis_scale(r->links[i], a), a,
                       lt_frame_col(r->y[i].q, a), res.F);
      M[j] = lt_m3_add(M[j], lp.h2 * px_lattice_ref_axis_scale(r->links[j], a), a,
                       lt_frame_col(r->y[j].q, a), res.F);
    }
  }
  for (c = 0; c < m->grid.ncell; ++c) {
    size_t i = px_lattice_index(m, c);
    double cn[3];
    int a;
    for (a = 0; a < 3; ++a)
      cn[a] = (double)(((r->links[i] & PX_LATTICE_LINK_PLUS(a)) != 0) +
                       ((r->links[i] & PX_LATTICE_LINK_MINUS(a)) != 0));
    s[i] = lt_stress_fin(M[i], cn[0], cn[1], cn[2]);
    s[i].xx *= inv_v;
    s[i].yy *= inv_v;
    s[i].zz *= inv_v;
    s[i].xy *= inv_v;
    s[i].yz *= inv_v;
    s[i].zx *= inv_v;
  }
  px_mem_free(r->ctx, M);
}
