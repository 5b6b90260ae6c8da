/* The reference engine adapter and the quasi-static relaxation (see
 * lattice_engine.h). */
#include "solvers/lattice/lattice_engine.h"

#include <math.h>
#include <string.h>

#include "partix/memory.h"
#include "solvers/lattice/lattice_ref.h"

enum px_status px_lattice_relax_update(const struct px_lattice_engine_i *vt, void *e, double *alpha,
                                       double *ratio) {
  double num = 0.0, den = 0.0, rate = 0.0;
  PX_TRY(vt->rayleigh(e, &num, &den, &rate));
  /* no displacement yet, or a field the links do not resist: keep alpha */
  if (den > 0.0 && num > 0.0) {
    *alpha = 2.0 * sqrt(num / den);
    vt->set_alpha(e, *alpha);
  }
  if (ratio) *ratio = num > 0.0 && den > 0.0 ? fabs(rate) / sqrt(num * den) : NAN;
  return PX_STATUS_OK;
}

/* ---------------------------------------------------------------------------
 * Reference engine */
struct px_lattice_ref_engine {
  struct px_lattice_ref r;
  struct px_context *ctx;
};

/* px_lattice_ref_create's state and workspace (tests only). */
static void px_lattice_refe_need(const struct px_lattice_layout *lay,
                                 const struct px_lattice_engine_opts *o,
                                 struct px_lattice_need *need) {
  (void)o;
  memset(need, 0, sizeof *need);
  need->host = (double)lay->nalloc * (4 * sizeof(struct lt_el) + 2 * sizeof(struct lt_v3) + 1);
}

static enum px_status px_lattice_refe_create(struct px_context *ctx,
                                             const struct px_lattice_model *m,
                                             const struct px_lattice_engine_opts *o, void **out) {
  struct px_lattice_ref_engine *e =
      (struct px_lattice_ref_engine *)px_mem_calloc(ctx, "lattice.ref", 1, sizeof *e);
  enum px_status st;
  if (!e) return PX_STATUS_NOMEM;
  e->ctx = ctx;
  st = px_lattice_ref_create(ctx, m, o->integ, &e->r);
  if (st != PX_STATUS_OK) {
    px_mem_free(ctx, e);
    return st;
  }
  *out = e;
  return PX_STATUS_OK;
}

static void px_lattice_refe_destroy(void *p) {
  struct px_lattice_ref_engine *e = (struct px_lattice_ref_engine *)p;
  if (!e) return;
  px_lattice_ref_free(&e->r);
  px_mem_free(e->ctx, e);
}

static enum px_status px_lattice_refe_run(void *p, long step, double t, double dt, long n) {
  struct px_lattice_ref_engine *e = (struct px_lattice_ref_engine *)p;
  long s;
  for (s = 0; s < n; ++s) {
    if (px_lattice_ref_step(&e->r, t + (double)s * dt, dt) != PX_STATUS_OK)
      return px_lattice_check_finite_d(e->ctx, e->r.m, e->r.y, step + s + 1);
  }
  return PX_STATUS_OK;
}

static enum px_status px_lattice_refe_get(void *p, struct lt_el *y, uint8_t *links) {
  struct px_lattice_ref_engine *e = (struct px_lattice_ref_engine *)p;
  if (y) memcpy(y, e->r.y, e->r.m->nalloc * sizeof *y);
  if (links) memcpy(links, e->r.links, e->r.m->nalloc);
  return PX_STATUS_OK;
}

static enum px_status px_lattice_refe_set(void *p, const struct lt_el *y, const uint8_t *links) {
  struct px_lattice_ref_engine *e = (struct px_lattice_ref_engine *)p;
  if (y) memcpy(e->r.y, y, e->r.m->nalloc * sizeof *y);
  if (links) memcpy(e->r.links, links, e->r.m->nalloc);
  return PX_STATUS_OK;
}

static enum px_status px_lattice_refe_fields(void *p, double t, double dt,
                                             const struct px_lattice_fields *f) {
  struct px_lattice_ref_engine *e = (struct px_lattice_ref_engine *)p;
  struct px_lattice_ref *r = &e->r;
  const struct px_lattice_model *m = r->m;
  size_t i, n = m->nalloc;
  if (f->u)
    for (i = 0; i < n; ++i) {
      f->u[3 * i] = r->y[i].u.x;
      f->u[3 * i + 1] = r->y[i].u.y;
      f->u[3 * i + 2] = r->y[i].u.z;
    }
  if (f->v) {
    int sync = r->integ == PX_LATTICE_INTEGRATOR_LEAPFROG;
    if (sync) {
      px_lattice_model_groups(m, t, r->table);
      px_lattice_ref_forces(m, r->links, r->y, 0, NULL, r->F, r->T);
    }
    for (i = 0; i < n; ++i) {
      struct lt_v3 v = r->y[i].v;
      if (sync) {
        const double *g = r->table + (size_t)m->group[i] * PX_LATTICE_GROUP_STRIDE;
        struct lt_dvw d =
            lt_accel(g, 1.0 / m->m, 1.0 / m->I, r->alpha, r->F[i], r->T[i], r->y[i].v, r->y[i].W);
        v = lt_v3_add(v, lt_v3_scale(0.5 * dt, d.dv));
      }
      f->v[3 * i] = v.x;
      f->v[3 * i + 1] = v.y;
      f->v[3 * i + 2] = v.z;
    }
  }
  if (f->sigma || f->vm) {
    struct lt_sym *s = (struct lt_sym *)px_mem_alloc(e->ctx, "lattice.ref", n * sizeof *s);
    if (!s) return PX_STATUS_NOMEM;
    px_lattice_ref_stress(r, s);
    for (i = 0; i < n; ++i) {
      if (f->sigma) {
        f->sigma[6 * i] = s[i].xx;
        f->sigma[6 * i + 1] = s[i].yy;
        f->sigma[6 * i + 2] = s[i].zz;
        f->sigma[6 * i + 3] = s[i].xy;
        f->sigma[6 * i + 4] = s[i].yz;
        f->sigma[6 * i + 5] = s[i].zx;
      }
      if (f->vm) f->vm[i] = lt_von_mises(s[i]);
    }
    px_mem_free(e->ctx, s);
  }
  if (f->links) memcpy(f->links, r->links, n);
  return PX_STATUS_OK;
}

static enum px_status px_lattice_refe_rayleigh(void *p, double *num, double *den, double *rate) {
  struct px_lattice_ref_engine *e = (struct px_lattice_ref_engine *)p;
  struct px_lattice_ref *r = &e->r;
  const struct px_lattice_model *m = r->m;
  double a = 0.0, b = 0.0, k = 0.0;
  size_t c;
  px_lattice_ref_forces(m, r->links, r->y, 0, NULL, r->F, r->T);
  for (c = 0; c < m->grid.ncell; ++c) {
    size_t i = px_lattice_index(m, c);
    const struct lt_el *y = &r->y[i];
    struct lt_v3 th;
    if (m->group[i] == 0) continue;
    th = lt_v3_make(2.0 * y->q.x, 2.0 * y->q.y, 2.0 * y->q.z);
    a -= lt_v3_dot(y->u, r->F[i]) + lt_v3_dot(th, r->T[i]);
    b += m->m * lt_v3_dot(y->u, y->u) + m->I * lt_v3_dot(th, th);
    k += m->m * lt_v3_dot(y->u, y->v) + m->I * lt_v3_dot(th, y->W);
  }
  *num = a;
  *den = b;
  *rate = k;
  return PX_STATUS_OK;
}

static void px_lattice_refe_alpha(void *p, double alpha) {
  ((struct px_lattice_ref_engine *)p)->r.alpha = alpha;
}

static long px_lattice_refe_broken(void *p) {
  return ((struct px_lattice_ref_engine *)p)->r.broken;
}

static enum px_status px_lattice_refe_set_broken(void *p, long links) {
  ((struct px_lattice_ref_engine *)p)->r.broken = links;
  return PX_STATUS_OK;
}

static size_t px_lattice_refe_bytes(void *p) {
  (void)p;
  return 5 * sizeof(struct lt_el) + 2 * sizeof(struct lt_v3) + 1;
}

static enum px_lattice_scheme px_lattice_refe_scheme(void *p) {
  (void)p;
  return PX_LATTICE_SCHEME_GATHER;
}

const struct px_lattice_engine_i px_lattice_engine_ref = {"ref",
                                                          px_lattice_refe_need,
                                                          px_lattice_refe_create,
                                                          px_lattice_refe_destroy,
                                                          px_lattice_refe_run,
                                                          px_lattice_refe_get,
                                                          px_lattice_refe_set,
                                                          px_lattice_refe_fields,
                                                          px_lattice_refe_rayleigh,
                                                          px_lattice_refe_alpha,
                                                          px_lattice_refe_broken,
                                                          px_lattice_refe_set_broken,
                                                          px_lattice_refe_bytes,
                                                          px_lattice_refe_scheme,
                                                          NULL};

void px_lattice_block_rect(const struct px_lattice_block *b, int q, long r[4]) {
  const long ja = b->j0 + 1 < b->j1 ? b->j0 + 1 : b->j1, jb = b->j1 - 1 > ja ? b->j1 - 1 : ja;
  const long ka = b->k0 + 1 < b->k1 ? b->k0 + 1 : b->k1, kb = b->k1 - 1 > ka ? b->k1 - 1 : ka;
  /* {j range, k range}: the interior, then the bands below and above in z
   * (whole width) and beside in y (between them) */
  const long rect[5][4] = {{ja, jb, ka, kb},
                           {b->j0, b->j1, b->k0, ka},
                           {b->j0, b->j1, kb, b->k1},
                           {b->j0, ja, ka, kb},
                           {jb, b->j1, ka, kb}};
  memcpy(r, rect[q], sizeof rect[q]);
}
