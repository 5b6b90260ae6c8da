/* Helpers shared by the lattice tests: small bodies, engines by name, state
 * comparison, quasi-static relaxation. */
#ifndef LT_UTIL_H
#define LT_UTIL_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "px_test.h"
#include "solvers/lattice/lattice_c.h"
#include "solvers/lattice/lattice_engine.h"

#define LT_STEEL_E 2.1e11
#define LT_STEEL_RHO 7850.0

static inline struct px_lattice_params lt_steel(void) {
  struct px_lattice_params p;
  memset(&p, 0, sizeof p);
  p.E = LT_STEEL_E;
  p.rho = LT_STEEL_RHO;
  return p;
}

static inline struct px_lattice_sel lt_sel_face(enum px_lattice_face f) {
  struct px_lattice_sel s;
  memset(&s, 0, sizeof s);
  s.face = f;
  return s;
}

static inline struct px_lattice_sel lt_sel_point(double x, double y, double z) {
  struct px_lattice_sel s;
  memset(&s, 0, sizeof s);
  s.face = PX_LATTICE_FACE_NONE;
  s.has_point = 1;
  s.point[0] = x;
  s.point[1] = y;
  s.point[2] = z;
  return s;
}

/* An engine instance by name: ref, cpu (scheme, precision, threads). */
struct lt_engine {
  const struct px_lattice_engine_i *vt;
  void *e;
  const char *label;
};

static inline enum px_status lt_engine_make(
    struct px_context *ctx, const struct px_lattice_model *m, const struct px_lattice_engine_i *vt,
    enum px_lattice_integrator integ, enum px_precision prec, enum px_lattice_scheme scheme,
    int threads, struct px_backend *be, struct lt_engine *out) {
  struct px_lattice_engine_opts o;
  memset(&o, 0, sizeof o);
  o.integ = integ;
  o.precision = prec;
  o.scheme = scheme;
  o.threads = threads;
  o.backend = be;
  out->vt = vt;
  out->e = NULL;
  return vt->create(ctx, m, &o, &out->e);
}

static inline void lt_engine_free(struct lt_engine *e) {
  if (e->e) e->vt->destroy(e->e);
  e->e = NULL;
}

/* Largest |a - b| over occupied cells, k components per element (k reals
 * per padded entry), relative to the largest |b|. */
static inline double lt_field_diff(const struct px_lattice_model *m, const double *a,
                                   const double *b, int k) {
  double d = 0.0, v = 0.0;
  size_t c;
  int j;
  for (c = 0; c < m->grid.ncell; ++c) {
    size_t i = px_lattice_index(m, c);
    if (!m->grid.occ[c]) continue;
    for (j = 0; j < k; ++j) {
      d = fmax(d, fabs(a[(size_t)k * i + (size_t)j] - b[(size_t)k * i + (size_t)j]));
      v = fmax(v, fabs(b[(size_t)k * i + (size_t)j]));
    }
  }
  return v > 0.0 ? d / v : d;
}

/* Mean of a displacement component over a selection. */
static inline double lt_mean_u(struct px_context *ctx, const struct px_lattice_model *m,
                               const struct lt_el *y, const struct px_lattice_sel *s, int comp) {
  size_t *cells = NULL, n = 0, k;
  double sum = 0.0;
  if (px_lattice_select(ctx, &m->grid, s, &cells, &n) != PX_STATUS_OK) return NAN;
  for (k = 0; k < n; ++k) {
    const struct lt_el *e = &y[px_lattice_index(m, cells[k])];
    sum += comp == 0 ? e->u.x : (comp == 1 ? e->u.y : e->u.z);
  }
  px_mem_free(ctx, cells);
  return sum / (double)n;
}

/* Relax to static equilibrium (leapfrog + adaptive dynamic relaxation):
 * run until the monitored mean displacement changes by less than tol
 * (relative) over `chunk` steps, at most max_steps. Returns steps run or -1. */
static inline long lt_relax(struct px_context *ctx, const struct px_lattice_model *m,
                            struct lt_engine *en, double dt, const struct px_lattice_sel *probe,
                            int comp, double tol, long max_steps, double *value, struct lt_el *y) {
  long step = 0, chunk = 200;
  double prev = 0.0, alpha = 0.0;
  while (step < max_steps) {
    long k;
    for (k = 0; k < chunk; k += 10) {
      if (px_lattice_relax_update(en->vt, en->e, &alpha, NULL) != PX_STATUS_OK) return -1;
      if (en->vt->run(en->e, step + k, (double)(step + k) * dt, dt, 10) != PX_STATUS_OK) return -1;
    }
    step += chunk;
    en->vt->get_state(en->e, y, NULL);
    *value = lt_mean_u(ctx, m, y, probe, comp);
    if (step > 2 * chunk && fabs(*value - prev) <= tol * fabs(*value)) return step;
    prev = *value;
  }
  return -1;
}

/* The quasi-static sums (rayleigh: q.K q, q.M q, q.M v) of engine `en`
 * against those of the reference `ref`: num and den relative, the rate
 * relative to sqrt(num den), its scale (the ratio static_error is
 * |rate| / sqrt(num den)); all within tol. */
static inline void lt_check_rayleigh(struct px_context *ctx, const struct lt_engine *en,
                                     const struct lt_engine *ref, double tol, const char *label) {
  double n[2] = {0, 0}, d[2] = {0, 0}, r[2] = {0, 0};
  PX_CHECK_OK(ctx, ref->vt->rayleigh(ref->e, &n[0], &d[0], &r[0]));
  PX_CHECK_OK(ctx, en->vt->rayleigh(en->e, &n[1], &d[1], &r[1]));
  printf(
      "  %s rayleigh sums: q.K q %.6e / %.6e J, q.M q %.6e / %.6e kg m^2, q.M v %.6e / "
      "%.6e kg m^2/s\n",
      label, n[1], n[0], d[1], d[0], r[1], r[0]);
  PX_CHECK(n[0] > 0.0 && d[0] > 0.0 && r[0] != 0.0);
  PX_CHECK_REL(n[1], n[0], tol);
  PX_CHECK_REL(d[1], d[0], tol);
  PX_CHECK_NEAR(r[1], r[0], tol * sqrt(n[0] * d[0]));
}

/* Largest difference of the state components of two states over occupied
 * cells, relative to the largest magnitude of that quantity in b. */
static inline void lt_state_diff(const struct px_lattice_model *m, const struct lt_el *a,
                                 const struct lt_el *b, double out[4]) {
  double dmax[4] = {0, 0, 0, 0}, vmax[4] = {0, 0, 0, 0};
  size_t c;
  int k;
  for (c = 0; c < m->grid.ncell; ++c) {
    const struct lt_el *x = &a[px_lattice_index(m, c)], *y = &b[px_lattice_index(m, c)];
    double d[4], v[4];
    if (!m->grid.occ[c]) continue;
    d[0] = fmax(fabs(x->u.x - y->u.x), fmax(fabs(x->u.y - y->u.y), fabs(x->u.z - y->u.z)));
    d[1] = fmax(fabs(x->v.x - y->v.x), fmax(fabs(x->v.y - y->v.y), fabs(x->v.z - y->v.z)));
    d[2] = fmax(fabs(x->W.x - y->W.x), fmax(fabs(x->W.y - y->W.y), fabs(x->W.z - y->W.z)));
    d[3] = fmax(fabs(x->q.x - y->q.x), fmax(fabs(x->q.y - y->q.y), fabs(x->q.z - y->q.z)));
    v[0] = fmax(fabs(y->u.x), fmax(fabs(y->u.y), fabs(y->u.z)));
    v[1] = fmax(fabs(y->v.x), fmax(fabs(y->v.y), fabs(y->v.z)));
    v[2] = fmax(fabs(y->W.x), fmax(fabs(y->W.y), fabs(y->W.z)));
    v[3] = fmax(fabs(y->q.x), fmax(fabs(y->q.y), fabs(y->q.z)));
    for (k = 0; k < 4; ++k) {
      if (d[k] > dmax[k]) dmax[k] = d[k];
      if (v[k] > vmax[k]) vmax[k] = v[k];
    }
  }
  for (k = 0; k < 4; ++k) out[k] = vmax[k] > 0 ? dmax[k] / vmax[k] : dmax[k];
}

/* A 14 x 7 x 5 mm body with a through hole (void cells inside rows), a
 * clamp, a ramped load, a harmonic prescribed acceleration, link and global
 * damping, element size h, Poisson's ratio nu; fnc > 0 makes bonds
 * breakable. */
static inline enum px_status lt_build_body_nu(struct px_context *ctx, struct px_lattice_model *m,
                                              double fnc, double h, double nu) {
  struct px_lattice_prim p[2];
  struct px_lattice_grid g;
  struct px_lattice_bc bc[3];
  struct px_lattice_params par = lt_steel();
  memset(p, 0, sizeof p);
  memset(bc, 0, sizeof bc);
  p[0].shape = PX_LATTICE_SHAPE_BOX;
  p[0].p1[0] = 14e-3;
  p[0].p1[1] = 7e-3;
  p[0].p1[2] = 5e-3;
  p[1].shape = PX_LATTICE_SHAPE_CYLINDER;
  p[1].op = PX_LATTICE_OP_DIFFERENCE;
  p[1].p0[0] = 7e-3;
  p[1].p0[1] = 3.5e-3;
  p[1].p0[2] = -1e-3;
  p[1].p1[0] = 7e-3;
  p[1].p1[1] = 3.5e-3;
  p[1].p1[2] = 6e-3;
  p[1].r = 1.6e-3;
  PX_TRY(px_lattice_grid_build(ctx, h, p, 2, &g));
  bc[0].sel = lt_sel_face(PX_LATTICE_FACE_X_MIN);
  bc[0].fix = 63;
  bc[0].name = "clamp";
  bc[1].sel = lt_sel_face(PX_LATTICE_FACE_X_MAX);
  bc[1].has_load = 1;
  bc[1].load[1] = 2e4;
  bc[1].load[2] = -3e4;
  bc[1].load[3] = 10.0;
  bc[1].load_f.kind = PX_LATTICE_TFUN_RAMP;
  bc[1].load_f.t1 = 2e-6;
  bc[1].name = "load";
  bc[2].sel = lt_sel_point(14e-3, 7e-3, 5e-3);
  bc[2].fix = 1;
  bc[2].has_accel = 1;
  bc[2].accel[0] = 5e5;
  bc[2].accel_f.kind = PX_LATTICE_TFUN_HARMONIC;
  bc[2].accel_f.freq = 2e5;
  bc[2].name = "shaker";
  par.zeta = 0.05;
  par.alpha = 1e4;
  par.f_nc = fnc;
  par.nu = nu;
  return px_lattice_model_build(ctx, m, &g, &par, bc, 3);
}

/* The body above with Poisson's ratio 0. */
static inline enum px_status lt_build_body_h(struct px_context *ctx, struct px_lattice_model *m,
                                             double fnc, double h) {
  return lt_build_body_nu(ctx, m, fnc, h, 0.0);
}

/* The body above with 1 mm elements (490 cells). */
static inline enum px_status lt_build_body(struct px_context *ctx, struct px_lattice_model *m,
                                           double fnc) {
  return lt_build_body_h(ctx, m, fnc, 1e-3);
}

#endif
