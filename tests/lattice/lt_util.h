/* Helpers shared by the lattice tests: small bodies, engines by name, state
 * comparison, quasi-static relaxation. */
#ifndef LT_UTIL_H
#define LT_UTIL_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "px_test.h"
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

static inline enum px_status lt_engine_make(struct px_context *ctx, const struct px_lattice_model *m,
                                     const struct px_lattice_engine_i *vt,
                                     enum px_lattice_integrator integ, enum px_precision prec,
                                     enum px_lattice_scheme scheme, int threads,
                                     struct px_backend *be, struct lt_engine *out) {
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

/* Mean of a displacement component over a selection. */
static inline double lt_mean_u(struct px_context *ctx, const struct px_lattice_model *m,
                        const struct lt_el_d *y, const struct px_lattice_sel *s, int comp) {
  size_t *cells = NULL, n = 0, k;
  double sum = 0.0;
  if (px_lattice_select(ctx, &m->grid, s, &cells, &n) != PX_STATUS_OK) return NAN;
  for (k = 0; k < n; ++k) {
    const struct lt_el_d *e = &y[px_lattice_index(m, cells[k])];
    sum += comp == 0 ? e->u.x : (comp == 1 ? e->u.y : e->u.z);
  }
  px_mem_free(ctx, cells);
  return sum / (double)n;
}

/* Relax to static equilibrium (leapfrog + adaptive dynamic relaxation):
 * run until the monitored mean displacement changes by less than tol
 * (relative) over `chunk` steps, at most max_steps. Returns steps run or -1. */
static inline long lt_relax(struct px_context *ctx, const struct px_lattice_model *m, struct lt_engine *en,
                     double dt, const struct px_lattice_sel *probe, int comp, double tol,
                     long max_steps, double *value, struct lt_el_d *y) {
  long step = 0, chunk = 200;
  double prev = 0.0, alpha = 0.0;
  while (step < max_steps) {
    long k;
    for (k = 0; k < chunk; k += 10) {
      if (px_lattice_relax_update(en->vt, en->e, &alpha) != PX_STATUS_OK) return -1;
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

/* Largest difference of the state components of two states over occupied
 * cells, relative to the largest magnitude of that quantity in b. */
static inline void lt_state_diff(const struct px_lattice_model *m, const struct lt_el_d *a,
                          const struct lt_el_d *b, double out[4]) {
  double dmax[4] = {0, 0, 0, 0}, vmax[4] = {0, 0, 0, 0};
  size_t c;
  int k;
  for (c = 0; c < m->grid.ncell; ++c) {
    const struct lt_el_d *x = &a[px_lattice_index(m, c)], *y = &b[px_lattice_index(m, c)];
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

#endif
