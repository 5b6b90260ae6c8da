/* The vortex-element engine on the CPU (see vortex_core.h). */
/* sqrt never sees a negative argument here; without errno it vectorizes (the
 * VVD neighbour loops). Other compilers ignore the pragma (-Wno-unknown-pragmas). */
#pragma GCC optimize("no-math-errno")
#include "solvers/vortex/vortex_core.h"

#include <math.h>
#include <omp.h>
#include <string.h>
#include <time.h>

#include "partix/memory.h"
#include "partix/nbody.h"
#include "partix/timer.h"
#include "solvers/vortex/vortex_opencl.h"

#define PX_REAL double
#include "kernels/px_kernel.h"
#include "solvers/vortex/vortex_kernel.h"

#define VX_PI 3.14159265358979323846

static const char *const block_names[PX_VORTEX_BLOCK_COUNT_] = {
    "generation", "convective", "diffusive", "loads", "move", "inside", "restructure"};

const char *const px_vortex_moment_names[] = {"none", "wake", "covariance", NULL};

const char *px_vortex_block_name(enum px_vortex_block b) {
  return (b >= 0 && b < PX_VORTEX_BLOCK_COUNT_) ? block_names[b] : "?";
}

double px_vortex_eps_min_default(double nu, double dt, double L) {
  const double floor = 0.5 * sqrt(nu * dt);
  return floor > 0.05 * L ? floor : 0.05 * L;
}

void px_vortex_config_defaults(struct px_vortex_config *cfg) {
  memset(cfg, 0, sizeof *cfg);
  cfg->rho = 1.0;
  cfg->ramp = PX_VORTEX_RAMP_IMPULSE;
  cfg->vortex_per_panel = 1;
  cfg->cutoff = 8.0;
  cfg->self_in_i1 = 0;
  cfg->sheet_exact = 1;
  cfg->newborn_rayleigh = 0;
  cfg->vvd_moments = PX_VORTEX_MOMENTS_NONE;
  cfg->precision = PX_PRECISION_MIXED;
  cfg->method = PX_NBODY_METHOD_AUTO;
  cfg->tolerance = 1e-6;
  cfg->threads = 1;
  cfg->dist_far = 1e30;
}

enum px_status px_vortex_config_check(struct px_context *ctx, const struct px_vortex_config *c) {
#define VX_REQ(cond, ...) \
  if (!(cond)) return px_context_fail(ctx, PX_STATUS_CONFIG, __VA_ARGS__)
  VX_REQ(c->nu > 0.0 && isfinite(c->nu), "nu must be > 0 (got %g)", c->nu);
  VX_REQ(c->dt > 0.0 && isfinite(c->dt), "dt must be > 0 (got %g)", c->dt);
  VX_REQ(c->rho > 0.0 && isfinite(c->rho), "rho must be > 0 (got %g)", c->rho);
  VX_REQ(isfinite(c->vinf[0]) && isfinite(c->vinf[1]), "free stream must be finite");
  VX_REQ(c->vref > 0.0 && isfinite(c->vref), "reference speed v_ref must be > 0 (got %g)", c->vref);
  VX_REQ(c->eps > 0.0, "eps (core radius) must be > 0 (got %g)", c->eps);
  VX_REQ(c->eps_col > 0.0, "eps_col must be > 0 (got %g)", c->eps_col);
  VX_REQ(c->gamma_max > 0.0, "gamma_max must be > 0 (got %g)", c->gamma_max);
  VX_REQ(c->delta >= 0.0, "delta must be >= 0 (got %g)", c->delta);
  VX_REQ(c->vortex_per_panel >= 1 && c->vortex_per_panel <= 64,
         "vortex_per_panel must be 1..64 (got %d)", c->vortex_per_panel);
  VX_REQ(c->dist_far > 0.0, "dist_far must be > 0 (got %g)", c->dist_far);
  VX_REQ(c->cutoff >= 3.0 && c->cutoff <= 20.0, "cutoff must be 3..20 (got %g)", c->cutoff);
  VX_REQ(c->ramp == PX_VORTEX_RAMP_IMPULSE || c->ramp_time > 0.0,
         "a ramped start needs ramp_time > 0 (got %g)", c->ramp_time);
  VX_REQ(c->threads >= 1, "threads must be >= 1");
  VX_REQ(c->method == PX_NBODY_METHOD_DIRECT || c->method == PX_NBODY_METHOD_FMM ||
             c->method == PX_NBODY_METHOD_AUTO,
         "velocity method must be direct, fmm or auto (got %d)", (int)c->method);
  VX_REQ(c->vvd_moments >= PX_VORTEX_MOMENTS_NONE && c->vvd_moments <= PX_VORTEX_MOMENTS_COVARIANCE,
         "vvd_moments must be none, wake or covariance (got %d)", c->vvd_moments);
  VX_REQ(c->tolerance >= 1e-12 && c->tolerance <= 0.1,
         "velocity tolerance must be between 1e-12 and 0.1 (got %g)", c->tolerance);
#undef VX_REQ
  return PX_STATUS_OK;
}

void px_vortex_vinf(const struct px_vortex_config *cfg, double t, double *vx, double *vy) {
  double f = 1.0;
  if (cfg->ramp != PX_VORTEX_RAMP_IMPULSE && t < cfg->ramp_time) {
    double s = t / cfg->ramp_time;
    f = cfg->ramp == PX_VORTEX_RAMP_LINEAR ? s : 0.5 * (1.0 - cos(VX_PI * s));
  }
  *vx = f * cfg->vinf[0];
  *vy = f * cfg->vinf[1];
}

/* ------------------------------------------------------------------------- */

void px_vortex_wake_free(struct px_context *ctx, struct px_vortex_wake *w) {
  px_mem_free(ctx, w->x);
  px_mem_free(ctx, w->born);
  memset(w, 0, sizeof *w);
}

enum px_status px_vortex_wake_reserve(struct px_context *ctx, struct px_vortex_wake *w,
                                      size_t n) {
  if (n <= w->cap && w->x) return PX_STATUS_OK;
  size_t cap = n + n / 2 + 1024;
  double *blk = px_mem_alloc(ctx, "vortex.wake", 10 * cap * sizeof(double));
  int32_t *born = px_mem_alloc(ctx, "vortex.wake", cap * sizeof(int32_t));
  if (!blk || !born) {
    px_mem_free(ctx, blk);
    px_mem_free(ctx, born);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for %zu vortices", n);
  }
  double *arr[10];
  for (int q = 0; q < 10; ++q) arr[q] = blk + (size_t)q * cap;
  if (w->x) {
    double *old[8] = {w->x, w->y, w->g, w->u, w->v, w->wu, w->wv, w->e};
    for (int q = 0; q < 8; ++q) memcpy(arr[q], old[q], w->n * sizeof(double));
    memcpy(born, w->born, w->n * sizeof(int32_t));
  }
  px_mem_free(ctx, w->x);
  px_mem_free(ctx, w->born);
  w->x = arr[0];
  w->y = arr[1];
  w->g = arr[2];
  w->u = arr[3];
  w->v = arr[4];
  w->wu = arr[5];
  w->wv = arr[6];
  w->e = arr[7];
  w->s1 = arr[8];
  w->s2 = arr[9];
  w->born = born;
  w->cap = cap;
  return PX_STATUS_OK;
}

static enum px_status ensure_work(struct px_vortex_engine *e, size_t n) {
  struct px_context *ctx = e->ctx;
  size_t nf = n + e->pan.nsys + 64;
  if (nf > e->fwork_cap) {
    px_mem_free(ctx, e->fwork);
    e->fwork_cap = nf + nf / 2;
    e->fwork = px_mem_alloc(ctx, "vortex.work", e->fwork_cap * sizeof(float));
    if (!e->fwork) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (work arrays)");
  }
  size_t nd = 2 * n + 64;
  if (nd > e->dwork_cap) {
    px_mem_free(ctx, e->dwork);
    px_mem_free(ctx, e->hit);
    px_mem_free(ctx, e->partner);
    px_mem_free(ctx, e->flag);
    e->dwork_cap = nd + nd / 2;
    size_t cap = e->dwork_cap / 2;
    e->dwork = px_mem_alloc(ctx, "vortex.work", e->dwork_cap * sizeof(double));
    e->hit = px_mem_alloc(ctx, "vortex.work", cap * sizeof(int32_t));
    e->partner = px_mem_alloc(ctx, "vortex.work", cap * sizeof(int32_t));
    e->flag = px_mem_alloc(ctx, "vortex.work", cap);
    if (!e->dwork || !e->hit || !e->partner || !e->flag)
      return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (work arrays)");
    e->xn = e->dwork;
    e->yn = e->dwork + cap;
  }
  return PX_STATUS_OK;
}

void px_vortex_engine_free(struct px_vortex_engine *e) {
  if (!e) return;
  struct px_context *ctx = e->ctx;
#ifdef PX_HAVE_OPENCL
  px_vortex_ocl_free(e);
#endif
  for (size_t b = 0; b < e->nbody; ++b) px_vortex_contour_free(ctx, &e->body[b]);
  px_vortex_panels_free(ctx, &e->pan);
  px_vortex_wake_free(ctx, &e->w);
  px_vortex_tree_free(ctx, &e->tree);
  px_vortex_tree_free(ctx, &e->ptree);
  for (int q = 0; q < 9; ++q) px_buffer_free(e->nb[q]);
  px_nbody_free(e->nbe);
  px_mem_free(ctx, e->sol);
  px_mem_free(ctx, e->born_first);
  px_mem_free(ctx, e->rk);
  px_mem_free(ctx, e->rk_born);
  px_mem_free(ctx, e->fwork);
  px_mem_free(ctx, e->dwork);
  px_mem_free(ctx, e->hit);
  px_mem_free(ctx, e->partner);
  px_mem_free(ctx, e->flag);
  if (e->nbuf)
    for (int t = 0; t < e->nthreads; ++t) {
      px_mem_free(ctx, e->nbuf[t].p);
      px_mem_free(ctx, e->nbuf[t].gl);
      px_mem_free(ctx, e->nbuf[t].fl);
      px_mem_free(ctx, e->nbuf[t].gp);
      px_mem_free(ctx, e->nbuf[t].fp);
      px_mem_free(ctx, e->nbuf[t].pd);
      px_mem_free(ctx, e->nbuf[t].lb);
      px_mem_free(ctx, e->nbuf[t].pc);
      px_mem_free(ctx, e->nbuf[t].ol);
    }
  px_mem_free(ctx, e->nbuf);
  px_mem_free(ctx, e);
}

enum px_status px_vortex_engine_create(struct px_context *ctx, struct px_backend *be,
                                       const struct px_vortex_config *cfg,
                                       const struct px_vortex_contour *bodies, size_t nbody,
                                       struct px_vortex_engine **out) {
  *out = NULL;
  PX_TRY(px_vortex_config_check(ctx, cfg));
  if (nbody > PX_VORTEX_MAX_BODIES)
    return px_context_fail(ctx, PX_STATUS_CONFIG, "at most %d bodies", PX_VORTEX_MAX_BODIES);
  struct px_vortex_engine *e = px_mem_calloc(ctx, "vortex.engine", 1, sizeof *e);
  if (!e) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
  e->ctx = ctx;
  e->be = be;
  e->nb_prec = cfg->precision == PX_PRECISION_DOUBLE ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
  /* float sums carry ~1e-7 rounding (more for large N): an FMM asked for less
   * than 1e-5 sums in double; the opencl step keeps its float direct sums */
  const int fmm_ok = be && strcmp(px_backend_name(be), "cpu") == 0 &&
                     cfg->method != PX_NBODY_METHOD_DIRECT;
  if (fmm_ok && cfg->tolerance < 1e-5) e->nb_prec = PX_PRECISION_DOUBLE;
  e->cfg = *cfg;
  if (e->cfg.eps_min <= 0.0)
    e->cfg.eps_min = px_vortex_eps_min_default(
        cfg->nu, cfg->dt, nbody ? px_vortex_mean_panel_length(bodies, nbody) : 0.0);
  {
    const double cfl = cfg->nu * cfg->dt / (e->cfg.eps_min * e->cfg.eps_min);
    if (cfl > 16.0)
      px_log(ctx, PX_LOG_LEVEL_WARN,
             "vortex.eps_min = %g gives nu dt / eps_min^2 = %.3g: a near-wall vortex at this "
             "floor can move ~%.3g eps* in one step (held only by the 1.5 v_ref cap), and the "
             "results will not converge as gamma_max is refined; eps_min >= 0.5 sqrt(nu dt) = "
             "%.3g keeps it at 4 (docs/notes/vortex.md, \"The gamma_max jump\")",
             e->cfg.eps_min, cfl, cfl, px_vortex_eps_min_default(cfg->nu, cfg->dt, 0.0));
  }
  if (!(e->cfg.eps_col_opposite > 0.0)) e->cfg.eps_col_opposite = 2.0 * cfg->eps_col;
  e->nthreads = cfg->threads;
  enum px_status st = PX_STATUS_OK;
#define VX_CHK(call)                  \
  do {                                \
    st = (call);                      \
    if (st != PX_STATUS_OK) goto fail; \
  } while (0)
  e->nbody = nbody;
  for (size_t b = 0; b < nbody; ++b) {
    struct px_vortex_contour *c = &e->body[b];
    c->n = bodies[b].n;
    c->x = px_mem_alloc(ctx, "vortex.profile", c->n * sizeof(double));
    c->y = px_mem_alloc(ctx, "vortex.profile", c->n * sizeof(double));
    if (!c->x || !c->y) {
      st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
      goto fail;
    }
    memcpy(c->x, bodies[b].x, c->n * sizeof(double));
    memcpy(c->y, bodies[b].y, c->n * sizeof(double));
    memcpy(c->source, bodies[b].source, sizeof c->source);
  }
  VX_CHK(px_vortex_panels_build(ctx, e->body, nbody, &e->pan));
  if (nbody > 0)
    VX_CHK(px_vortex_panels_factor(ctx, &e->pan, cfg->precision == PX_PRECISION_SINGLE));
  size_t n = e->pan.n;
  e->sol = px_mem_calloc(ctx, "vortex.panels", 8 * n + nbody + 8, sizeof(double));
  if (!e->sol) {
    st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
    goto fail;
  }
  e->through = e->sol + n + nbody;
  e->omega = e->through + n;
  e->pe = e->omega + n;
  e->rhs_u = e->pe + n;
  e->rhs_v = e->rhs_u + 2 * n;
  e->born_first = px_mem_calloc(ctx, "vortex.panels", n + 1, sizeof(size_t));
  if (!e->born_first) {
    st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
    goto fail;
  }
  /* panel midpoints tree */
  {
    double *mx = px_mem_alloc(ctx, "vortex.work", 2 * n * sizeof(double));
    if (!mx) {
      st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
      goto fail;
    }
    for (size_t k = 0; k < n; ++k) {
      mx[k] = 0.5 * (e->pan.x0[k] + e->pan.x1[k]);
      mx[n + k] = 0.5 * (e->pan.y0[k] + e->pan.y1[k]);
    }
    px_vortex_tree_init(&e->ptree);
    e->ptree.leaf = 8;
    st = px_vortex_tree_build(ctx, &e->ptree, n, mx, mx + n, 1);
    px_mem_free(ctx, mx);
    if (st != PX_STATUS_OK) goto fail;
  }
  px_vortex_tree_init(&e->tree);
  /* leaves of 32: the VVD tests fewer leaf boxes per vortex for more
   * candidates, 7% faster in its block than 16 (vortex_step, 2026-11-25) */
  e->tree.leaf = 32;
  e->nbuf = px_mem_calloc(ctx, "vortex.work", (size_t)e->nthreads, sizeof *e->nbuf);
  if (!e->nbuf) {
    st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
    goto fail;
  }
  /* geometry for far removal and merge growth */
  {
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    for (size_t b = 0; b < nbody; ++b) {
      x0 = fmin(x0, e->pan.bxmin[b]);
      y0 = fmin(y0, e->pan.bymin[b]);
      x1 = fmax(x1, e->pan.bxmax[b]);
      y1 = fmax(y1, e->pan.bymax[b]);
    }
    e->center[0] = nbody ? 0.5 * (x0 + x1) : 0.0;
    e->center[1] = nbody ? 0.5 * (y0 + y1) : 0.0;
    double vn = hypot(cfg->vinf[0], cfg->vinf[1]);
    e->stream_dir[0] = vn > 0.0 ? cfg->vinf[0] / vn : 1.0;
    e->stream_dir[1] = vn > 0.0 ? cfg->vinf[1] / vn : 0.0;
    e->s_right = -INFINITY;
    e->span = 0.0;
    for (size_t b = 0; b < nbody; ++b) {
      const struct px_vortex_contour *c = &e->body[b];
      double dmax = 0.0;
      for (size_t k = 0; k < c->n; ++k) {
        double s = c->x[k] * e->stream_dir[0] + c->y[k] * e->stream_dir[1];
        e->s_right = fmax(e->s_right, s);
        for (size_t j = k + 1; j < c->n; j += 1 + c->n / 512)
          dmax = fmax(dmax, hypot(c->x[k] - c->x[j], c->y[k] - c->y[j]));
      }
      if (!(e->cfg.ref_length[b] > 0.0)) e->cfg.ref_length[b] = dmax;
      e->span = fmax(e->span, e->cfg.ref_length[b]);
    }
    if (nbody == 0) { /* no body, no downstream: the merge growth factor stays 1 */
      e->s_right = INFINITY;
      e->span = 1.0;
    }
  }
  VX_CHK(px_vortex_wake_reserve(ctx, &e->w, 1024));
  VX_CHK(ensure_work(e, 1024));
  if (be) {
    VX_CHK(px_nbody_create(be, cfg->method, e->nb_prec, cfg->eps, &e->nbe));
    if (fmm_ok) /* the direct sum (opencl: always under auto) has no tolerance */
      VX_CHK(px_nbody_set_tolerance(e->nbe, cfg->tolerance));
  }
#ifdef PX_HAVE_OPENCL
  if (be && strcmp(px_backend_name(be), "opencl") == 0) VX_CHK(px_vortex_ocl_create(e));
#endif
#undef VX_CHK
  *out = e;
  return PX_STATUS_OK;
fail:
  px_vortex_engine_free(e);
  return st;
}

enum px_status px_vortex_engine_sync(struct px_vortex_engine *e) {
#ifdef PX_HAVE_OPENCL
  if (e->dev) return px_vortex_ocl_sync(e);
#endif
  (void)e;
  return PX_STATUS_OK;
}

void px_vortex_engine_host_changed(struct px_vortex_engine *e) {
#ifdef PX_HAVE_OPENCL
  if (e->dev) px_vortex_ocl_mark_dirty(e);
#endif
  (void)e;
}

enum px_status px_vortex_engine_add(struct px_vortex_engine *e, size_t n, const double *x,
                                    const double *y, const double *g) {
  PX_TRY(px_vortex_engine_sync(e));
  px_vortex_engine_host_changed(e);
  PX_TRY(px_vortex_wake_reserve(e->ctx, &e->w, e->w.n + n));
  for (size_t i = 0; i < n; ++i) {
    size_t k = e->w.n + i;
    e->w.x[k] = x[i];
    e->w.y[k] = y[i];
    e->w.g[k] = g[i];
    e->w.u[k] = e->w.v[k] = e->w.wu[k] = e->w.wv[k] = 0.0;
    e->w.e[k] = 0.0;
    e->w.born[k] = -1;
  }
  e->w.n += n;
  return PX_STATUS_OK;
}

/* A thread's neighbour buffer on first use (NULL stays the out-of-memory
 * signal of the queries). */
static uint32_t *nbuf_init(struct px_vortex_engine *e, struct px_vortex_nbuf *b) {
  b->p = px_mem_alloc(e->ctx, "vortex.query", 256 * sizeof(uint32_t));
  b->cap = b->p ? 256 : 0;
  return b->p;
}

static uint32_t *nbuf_query(struct px_vortex_engine *e, const struct px_vortex_tree *t, double x,
                            double y, double r, size_t *cnt) {
  struct px_vortex_nbuf *b = &e->nbuf[omp_get_thread_num()];
  if (!b->p && !nbuf_init(e, b)) {
    *cnt = 0;
    return NULL;
  }
  size_t c = px_vortex_tree_within(e->ctx, t, x, y, r, &b->p, &b->cap);
  if (c == (size_t)-1) {
    *cnt = 0;
    return NULL;
  }
  *cnt = c;
  return b->p;
}

/* Grow a work list to hold n entries (contents kept); 0 when out of memory. */
static int list_reserve(struct px_vortex_engine *e, uint32_t **p, size_t *cap, size_t n) {
  if (n <= *cap && *p) return 1;
  size_t nc = n + n / 2 + 64;
  uint32_t *np = px_mem_realloc(e->ctx, "vortex.query", *p, nc * sizeof(uint32_t));
  if (!np) return 0;
  *p = np;
  *cap = nc;
  return 1;
}

/* Grow *p, `arrays` arrays of *cap doubles each back to back (the leaf boxes,
 * the packed neighbours), to hold n entries per array (contents not kept); 0
 * when out of memory. */
static int arrays_reserve(struct px_vortex_engine *e, double **p, size_t *cap, size_t n,
                          size_t arrays) {
  if (n <= *cap && *p) return 1;
  size_t nc = n + n / 2 + 64;
  double *np = px_mem_realloc(e->ctx, "vortex.query", *p, arrays * nc * sizeof(double));
  if (!np) return 0;
  *p = np;
  *cap = nc;
  return 1;
}

/* Leaves of tree t within r of (x, y), into *buf (grown). (size_t)-1 when out
 * of memory. */
static size_t leaves_into(struct px_vortex_engine *e, const struct px_vortex_tree *t, double x,
                          double y, double r, uint32_t **buf, size_t *cap) {
  if (!*buf && !list_reserve(e, buf, cap, 256)) return (size_t)-1;
  for (;;) {
    size_t c = px_vortex_tree_leaves(t, x, y, r, *buf, *cap);
    if (c <= *cap) return c;
    if (!list_reserve(e, buf, cap, c)) return (size_t)-1;
  }
}

/* Buffers of the N-body sums: set `which` (0: sources/outputs, 1: extra
 * targets) to hold at least n elements. */
static enum px_status nb_reserve(struct px_vortex_engine *e, int which, size_t n) {
  if (n <= e->nb_cap[which] && e->nb[which ? 5 : 0]) return PX_STATUS_OK;
  size_t cap = n + n / 2 + 256;
  size_t es = e->nb_prec == PX_PRECISION_DOUBLE ? sizeof(double) : sizeof(float);
  static const char *const names[9] = {"vortex.nbody.x", "vortex.nbody.y", "vortex.nbody.g",
                                       "vortex.nbody.u", "vortex.nbody.v", "vortex.nbody.tx",
                                       "vortex.nbody.ty", "vortex.nbody.tu", "vortex.nbody.tv"};
  int q0 = which ? 5 : 0, q1 = which ? 9 : 5;
  for (int q = q0; q < q1; ++q) {
    px_buffer_free(e->nb[q]);
    e->nb[q] = NULL;
    PX_TRY(px_buffer_create(e->be, names[q], cap * es, &e->nb[q]));
  }
  e->nb_cap[which] = cap;
  return PX_STATUS_OK;
}

/* Copy n doubles (minus `shift`) into a buffer of the sums' precision. Float
 * coordinates are taken relative to the bodies' centre, so that round-off is
 * uniform over the wake. */
static enum px_status nb_put(struct px_vortex_engine *e, struct px_buffer *b, const double *src,
                             size_t n, double shift) {
  void *h = px_buffer_host(b);
  int th = e->cfg.threads;
  if (e->nb_prec == PX_PRECISION_DOUBLE) {
    if (!h) return px_buffer_write(b, 0, n * sizeof(double), src);
    double *d = h;
#pragma omp parallel for num_threads(th) schedule(static)
    for (long i = 0; i < (long)n; ++i) d[i] = src[i] - shift;
    return PX_STATUS_OK;
  }
  float *f = h;
  if (!f) {
    if (n > e->fwork_cap) {
      px_mem_free(e->ctx, e->fwork);
      e->fwork_cap = n + n / 2;
      e->fwork = px_mem_alloc(e->ctx, "vortex.work", e->fwork_cap * sizeof(float));
      if (!e->fwork) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory");
    }
    f = e->fwork;
  }
#pragma omp parallel for num_threads(th) schedule(static)
  for (long i = 0; i < (long)n; ++i) f[i] = (float)(src[i] - shift);
  if (!h) return px_buffer_write(b, 0, n * sizeof(float), f);
  return PX_STATUS_OK;
}

static enum px_status nb_get(struct px_vortex_engine *e, struct px_buffer *b, double *dst,
                             size_t n) {
  void *h = px_buffer_host(b);
  if (e->nb_prec == PX_PRECISION_DOUBLE) {
    if (!h) return px_buffer_read(b, 0, n * sizeof(double), dst);
    memcpy(dst, h, n * sizeof(double));
    return PX_STATUS_OK;
  }
  const float *f = h;
  if (!f) {
    if (n > e->fwork_cap) {
      px_mem_free(e->ctx, e->fwork);
      e->fwork_cap = n + n / 2;
      e->fwork = px_mem_alloc(e->ctx, "vortex.work", e->fwork_cap * sizeof(float));
      if (!e->fwork) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory");
    }
    PX_TRY(px_buffer_read(b, 0, n * sizeof(float), e->fwork));
    f = e->fwork;
  }
  for (size_t i = 0; i < n; ++i) dst[i] = f[i];
  return PX_STATUS_OK;
}

/* Upload the wake as the sources of the pair sums. */
static enum px_status nb_sources(struct px_vortex_engine *e) {
  const struct px_vortex_wake *w = &e->w;
  PX_TRY(nb_reserve(e, 0, w->n));
  PX_TRY(nb_put(e, e->nb[0], w->x, w->n, e->center[0]));
  PX_TRY(nb_put(e, e->nb[1], w->y, w->n, e->center[1]));
  return nb_put(e, e->nb[2], w->g, w->n, 0.0);
}

/* Velocities (pair sum only) at nt extra targets from the uploaded wake. */
static enum px_status nb_targets(struct px_vortex_engine *e, size_t nt, const double *tx,
                                 const double *ty, double *u, double *v) {
  if (nt == 0) return PX_STATUS_OK;
  if (e->w.n == 0) {
    for (size_t i = 0; i < nt; ++i) u[i] = v[i] = 0.0;
    return PX_STATUS_OK;
  }
  PX_TRY(nb_reserve(e, 1, nt));
  PX_TRY(nb_put(e, e->nb[5], tx, nt, e->center[0]));
  PX_TRY(nb_put(e, e->nb[6], ty, nt, e->center[1]));
  PX_TRY(px_nbody_velocity(e->nbe, e->w.n, e->nb[0], e->nb[1], e->nb[2], nt, e->nb[5], e->nb[6],
                           PX_NBODY_MODE_SET, e->nb[7], e->nb[8]));
  PX_TRY(nb_get(e, e->nb[7], u, nt));
  return nb_get(e, e->nb[8], v, nt);
}

/* ------------------------------------------------------------------------- */
/* Block 1: generation */

static const double gauss2 = 0.21132486540518711775; /* (1 - 1/sqrt 3)/2 */

/* absorbed: the circulation each panel absorbed in the last step, which the
 * sheet returns to the flow (NULL: none, the second stage of rk2) */
static enum px_status generation(struct px_vortex_engine *e, double vx, double vy,
                                 const double *absorbed) {
  struct px_context *ctx = e->ctx;
  const struct px_vortex_panels *p = &e->pan;
  struct px_vortex_wake *w = &e->w;
  size_t n = p->n;
  e->n_born = 0;
  if (n == 0) return PX_STATUS_OK; /* no body: nothing to generate */
  double *gx = e->rhs_u, *gy = e->rhs_v; /* 2n Gauss points, then velocities */
  double *gu = e->dwork, *gv = e->dwork + 2 * n;
  if (e->dwork_cap < 4 * n) {
    PX_TRY(ensure_work(e, 2 * n + w->n));
    gu = e->dwork;
    gv = e->dwork + 2 * n;
  }
  for (size_t i = 0; i < n; ++i) {
    double dx = p->x1[i] - p->x0[i], dy = p->y1[i] - p->y0[i];
    gx[2 * i] = p->x0[i] + gauss2 * dx;
    gy[2 * i] = p->y0[i] + gauss2 * dy;
    gx[2 * i + 1] = p->x1[i] - gauss2 * dx;
    gy[2 * i + 1] = p->y1[i] - gauss2 * dy;
  }
  double *rhs = e->sol;
  if (w->n > 0) {
    PX_TRY(px_vortex_tree_build(ctx, &e->tree, w->n, w->x, w->y, e->cfg.threads));
    PX_TRY(nb_sources(e));
    PX_TRY(nb_targets(e, 2 * n, gx, gy, gu, gv));
  } else {
    memset(gu, 0, 4 * n * sizeof(double));
  }
  const double eps2 = e->cfg.eps * e->cfg.eps;
  int oom = 0;
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 16)
  for (long li = 0; li < (long)n; ++li) {
    size_t i = (size_t)li;
    double tx = p->tx[i], ty = p->ty[i];
    double wk = 0.5 * ((gu[2 * i] + gu[2 * i + 1]) * tx + (gv[2 * i] + gv[2 * i + 1]) * ty);
    if (w->n > 0) {
      /* near vortices: replace the smoothed 2-point mean by the exact mean */
      double mx = 0.5 * (p->x0[i] + p->x1[i]), my = 0.5 * (p->y0[i] + p->y1[i]);
      size_t cnt;
      uint32_t *lst = nbuf_query(e, &e->tree, mx, my, 2.0 * p->len[i] + e->cfg.eps, &cnt);
      if (!lst) oom = 1;
      double inv_len = 1.0 / p->len[i], corr = 0.0;
      for (size_t q = 0; q < cnt; ++q) {
        uint32_t j = e->tree.order[lst[q]];
        double xj = w->x[j], yj = w->y[j], gj = w->g[j];
        double exact = vx_point_coef(p->x0[i], p->y0[i], p->x1[i], p->y1[i], inv_len, xj, yj);
        double a = 0.0;
        for (int s = 0; s < 2; ++s) {
          double dx = gx[2 * i + (size_t)s] - xj, dy = gy[2 * i + (size_t)s] - yj;
          px_real2 k = px_biot_savart_term(dx, dy, 1.0, eps2);
          a += 0.5 * (k.x * tx + k.y * ty);
        }
        corr += gj * (exact - a * (0.5 / VX_PI));
      }
      wk += corr;
    }
    rhs[i] = -(vx * tx + vy * ty) - wk;
  }
  if (oom) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)");
  for (size_t b = 0; b < p->nbody; ++b) {
    double s = 0.0;
    for (size_t k = p->first[b]; k < p->first[b + 1] && absorbed; ++k) s += absorbed[k];
    rhs[n + b] = s;
  }
  for (size_t i = 0; i < p->nsys; ++i)
    if (!isfinite(rhs[i]))
      return px_context_fail(ctx, PX_STATUS_NUMERIC,
                             "step %ld: non-finite velocity at panel %zu (free stream (%g, %g)); "
                             "the wake holds non-finite values",
                             e->step, i, vx, vy);
  if (e->cfg.precision == PX_PRECISION_SINGLE) {
    float *fr = e->fwork;
    for (size_t i = 0; i < p->nsys; ++i) fr[i] = (float)rhs[i];
    PX_TRY(px_vortex_panels_solve_f(ctx, p, fr));
    for (size_t i = 0; i < p->nsys; ++i) rhs[i] = fr[i];
  } else {
    PX_TRY(px_vortex_panels_solve(ctx, p, rhs));
  }
  /* runaway check: the sheet intensity is a slip velocity */
  for (size_t k = 0; k < n; ++k) {
    if (!isfinite(rhs[k]) || fabs(rhs[k]) > 1e3 * e->cfg.vref)
      return px_context_fail(ctx, PX_STATUS_NUMERIC,
                             "step %ld: runaway vorticity generation: sheet intensity %g on panel "
                             "%zu of body %d (more than 1000 v_ref); the wake is unstable: reduce "
                             "dt or check eps, eps_col and gamma_max",
                             e->step, rhs[k], k, p->body[k]);
  }
  /* shed: gamma_k L_k as m_k vortices a distance delta off the panel */
  size_t add = 0;
  for (size_t k = 0; k < n; ++k) {
    double gl = fabs(rhs[k] * p->len[k]);
    size_t m = (size_t)e->cfg.vortex_per_panel;
    double need = ceil(gl / e->cfg.gamma_max);
    if (need > (double)m) m = need > 64.0 ? 64 : (size_t)need;
    add += m;
  }
  PX_TRY(px_vortex_wake_reserve(ctx, w, w->n + add));
  size_t q = w->n;
  for (size_t k = 0; k < n; ++k) {
    double gl = rhs[k] * p->len[k];
    size_t m = (size_t)e->cfg.vortex_per_panel;
    double need = ceil(fabs(gl) / e->cfg.gamma_max);
    if (need > (double)m) m = need > 64.0 ? 64 : (size_t)need;
    double nx = p->ty[k], ny = -p->tx[k];
    e->born_first[k] = q;
    for (size_t j = 0; j < m; ++j) {
      double f = ((double)j + 0.5) / (double)m;
      w->x[q] = p->x0[k] + f * (p->x1[k] - p->x0[k]) + e->cfg.delta * nx;
      w->y[q] = p->y0[k] + f * (p->y1[k] - p->y0[k]) + e->cfg.delta * ny;
      w->g[q] = gl / (double)m;
      w->born[q] = (int32_t)k;
      ++q;
    }
  }
  e->born_first[n] = q;
  e->n_born = add;
  w->n = q;
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */
/* Block 2: convective velocities */

static enum px_status convective(struct px_vortex_engine *e, double vx, double vy) {
  struct px_vortex_wake *w = &e->w;
  size_t nold = w->n - e->n_born;
  /* all vortices as targets: the sources are the targets, which lets the
   * cpu sum evaluate each pair once; the newborn get their own velocity below */
  PX_TRY(nb_sources(e));
  PX_TRY(px_nbody_velocity(e->nbe, w->n, e->nb[0], e->nb[1], e->nb[2], w->n, e->nb[0], e->nb[1],
                           PX_NBODY_MODE_SET, e->nb[3], e->nb[4]));
  PX_TRY(nb_get(e, e->nb[3], w->u, w->n));
  PX_TRY(nb_get(e, e->nb[4], w->v, w->n));
  for (size_t i = 0; i < nold; ++i) {
    w->u[i] += vx;
    w->v[i] += vy;
  }
  if (e->cfg.sheet_exact && e->pan.n > 0 && e->n_born > 0) {
    /* near a panel the newborn row stands for the sheet gamma_k on it: replace
     * its smoothed field by the exact one of the sheet (VM2D: the wake sees
     * the free sheet, Boundary2DConstLayerAver::CalcConvVelocityToSetOfPointsFromSheets) */
    const struct px_vortex_panels *pp = &e->pan;
    const double eps2 = e->cfg.eps * e->cfg.eps, rr = 2.0 * pp->lmax + e->cfg.eps;
    int oom = 0;
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 256)
    for (long li = 0; li < (long)nold; ++li) {
      size_t i = (size_t)li;
      double xi = w->x[i], yi = w->y[i];
      double bx0 = xi, bx1 = xi, by0 = yi, by1 = yi;
      int any = 0;
      for (size_t b = 0; b < pp->nbody && !any; ++b)
        any = !(bx1 + rr < pp->bxmin[b] || bx0 - rr > pp->bxmax[b] || by1 + rr < pp->bymin[b] ||
                by0 - rr > pp->bymax[b]);
      if (!any) continue;
      size_t cnt;
      uint32_t *lst = nbuf_query(e, &e->ptree, xi, yi, rr, &cnt);
      if (!lst) {
        oom = 1;
        continue;
      }
      double cu = 0.0, cv = 0.0;
      for (size_t q = 0; q < cnt; ++q) {
        size_t k = e->ptree.order[lst[q]];
        double mx = 0.5 * (pp->x0[k] + pp->x1[k]) - xi, my = 0.5 * (pp->y0[k] + pp->y1[k]) - yi;
        double lim = 2.0 * pp->len[k] + e->cfg.eps;
        if (mx * mx + my * my > lim * lim) continue;
        double su, sv;
        px_vortex_segment_velocity(pp->x0[k], pp->y0[k], pp->x1[k], pp->y1[k], xi, yi, &su, &sv);
        double du = 0.0, dv = 0.0;
        for (size_t j = e->born_first[k]; j < e->born_first[k + 1]; ++j) {
          double dx = xi - w->x[j], dy = yi - w->y[j];
          px_real2 bk = px_biot_savart_term(dx, dy, w->g[j], eps2);
          du += bk.x;
          dv += bk.y;
        }
        cu += e->sol[k] * su - du * (0.5 / VX_PI);
        cv += e->sol[k] * sv - dv * (0.5 / VX_PI);
      }
      w->u[i] += cu;
      w->v[i] += cv;
    }
    if (oom) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)");
  }
  /* newborn: mean of the inner (0) and outer (gamma tau) limits of the sheet */
  const struct px_vortex_panels *p = &e->pan;
  for (size_t i = nold; i < w->n; ++i) {
    size_t k = (size_t)w->born[i];
    w->u[i] = 0.5 * e->sol[k] * p->tx[k];
    w->v[i] = 0.5 * e->sol[k] * p->ty[k];
  }
  for (size_t i = 0; i < w->n; ++i)
    if (!isfinite(w->u[i]) || !isfinite(w->v[i]))
      return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                             "step %ld: vortex %zu at (%g, %g) has a non-finite convective "
                             "velocity (%g, %g)",
                             e->step, i, w->x[i], w->y[i], w->u[i], w->v[i]);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */
/* Block 3: diffusive velocities (VVD) */

/* eps* of a vortex from the squared distances d2 (ascending, INFINITY where
 * fewer than 3 other vortices exist) to its 3 nearest: their rms, at least
 * eps_min. */
static double eps_value(const struct px_vortex_config *cfg, const double *d2) {
  double s = 0.0;
  int c = 0;
  for (int q = 0; q < 3; ++q)
    if (isfinite(d2[q])) {
      s += d2[q];
      ++c;
    }
  double ev = c ? sqrt(s / c) : cfg->eps_min;
  return ev > cfg->eps_min ? ev : cfg->eps_min;
}

/* Vortices per group of the VVD's neighbour search: one tree query per group,
 * each vortex then filtering the group's candidates (4 leaves of 16 measured
 * 5% faster in the diffusive block than one; with leaves of 32, 4 of them
 * another 3% faster than 2 and than 8: vortex_step, 2026-11-26). The lists
 * and sums do not depend on it. */
#define VX_GROUP 128

/* The VVD's search guess of a vortex's eps*: this factor times its eps* of
 * the step before (px_vortex_engine_diffusive). */
#define VX_EPS_GUESS 1.1

/* The nodes of tree t that hold at most gmax points and whose parent holds
 * more (or leaves, if larger), in ascending sorted order, into out (room for
 * t->nnode); returns their count. */
static size_t tree_groups(const struct px_vortex_tree *t, size_t gmax, uint32_t *out) {
  size_t n = 0;
  if (t->nnode == 0) return 0;
  uint32_t stack[128];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    uint32_t k = stack[--sp];
    if (t->left[k] < 0 || t->hi[k] - t->lo[k] <= gmax) {
      out[n++] = k;
      continue;
    }
    stack[sp++] = (uint32_t)(t->left[k] + 1);
    stack[sp++] = (uint32_t)t->left[k];
  }
  return n;
}

/* A newborn vortex's first-step drift off the wall: a sheet released at a
 * flat wall diffuses as omega ~ exp(-y^2 / (4 nu t)) / sqrt(pi nu t), whose
 * centroid is at 2 sqrt(nu t / pi) after t, so the mean drift over the step
 * is 2 sqrt(nu / (pi dt)). */
double px_vortex_newborn_drift(const struct px_vortex_config *cfg) {
  return cfg->newborn_rayleigh ? 2.0 * sqrt(cfg->nu / (VX_PI * cfg->dt)) : 0.0;
}

/* Pack the neighbours of the vortex at sorted position sp within
 * sqrt(r2max) over the runs b->fl[0..2 nl) of sorted positions into b->pd,
 * grown to every candidate plus 8 of slack (the pack's vector stores); low:
 * as in px_vortex_vvd_pack. Returns their number, (size_t)-1 when out of
 * memory. */
static size_t vvd_pack_runs(struct px_vortex_engine *e, struct px_vortex_nbuf *b, const double *sg,
                            size_t nl, uint32_t sp, double r2max, double *low) {
  const struct px_vortex_tree *t = &e->tree;
  const uint32_t *lv = b->fl;
  size_t ncand = 8;
  for (size_t l = 0; l < nl; ++l) ncand += lv[2 * l + 1] - lv[2 * l];
  if (!arrays_reserve(e, &b->pd, &b->pd_cap, ncand, 3)) return (size_t)-1;
  double *pdx = b->pd, *pdy = b->pd + b->pd_cap, *pg = b->pd + 2 * b->pd_cap;
  size_t np = 0;
  for (size_t l = 0; l < nl; ++l)
    np = px_vortex_vvd_pack(t->sx, t->sy, sg, lv[2 * l], lv[2 * l + 1], sp, t->sx[sp], t->sy[sp],
                            r2max, pdx, pdy, pg, np, low);
  return np;
}

/* The VVD pair sums over the np neighbours packed in b->pd (offsets from the
 * vortex and circulations), in one vector loop; out: I1, sum |Gamma_j|
 * exp(-r/e), I2x, I2y. */
static void vvd_pair_sums(struct px_vortex_nbuf *b, size_t np, double inv_e, double tiny2,
                          double out[4]) {
  double *pdx = b->pd, *pdy = b->pd + b->pd_cap, *pg = b->pd + 2 * b->pd_cap;
  /* padded with zero terms to a multiple of 8 (the slack): no scalar
   * remainder, whose exponential chains cost as much as a vector pass */
  size_t npad = (np + 7) & ~(size_t)7;
  for (size_t q = np; q < npad; ++q) pdx[q] = pdy[q] = pg[q] = 0.0;
  double i1 = 0.0, i1abs = 0.0, i2x = 0.0, i2y = 0.0;
#pragma omp simd reduction(+ : i1, i1abs, i2x, i2y)
  for (size_t q = 0; q < npad; ++q) {
    double dx = pdx[q], dy = pdy[q];
    double r2 = dx * dx + dy * dy;
    double r = sqrt(r2);
    double ex = vx_exp_neg(r * inv_e);
    double gj = pg[q], ge = gj * ex;
    double rinv = r2 > tiny2 ? 1.0 / r : 0.0;
    i1 += ge;
    i1abs += fabs(gj) * ex;
    i2x += ge * dx * rinv;
    i2y += ge * dy * rinv;
  }
  out[0] = i1;
  out[1] = i1abs;
  out[2] = i2x;
  out[3] = i2y;
}

/* The kernel's moments over the np neighbours vvd_pair_sums left packed in
 * b->pd: M0 = sum exp(-r/e), M1 = sum r exp(-r/e) (vvd_moments; a second
 * pass, so that the default pair loop stays as it is). */
static void vvd_kernel_moments(const struct px_vortex_nbuf *b, size_t np, double inv_e,
                               double *m0, double *m1) {
  const double *pdx = b->pd, *pdy = b->pd + b->pd_cap;
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
static int vvd_covariance(const struct px_vortex_nbuf *b, size_t np, double ei, double gi,
                          double *wx, double *wy) {
  const double inv_e = 1.0 / ei;
  const double *pdx = b->pd, *pdy = b->pd + b->pd_cap, *pg = b->pd + 2 * b->pd_cap;
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
  size_t nl = leaves_into(e, t, xi, yi, cut * ei * (1.0 + 1e-9) + 1e-300, &b->ol, &b->ol_cap);
  if (nl == (size_t)-1 || !list_reserve(e, &b->fl, &b->fl_cap, 2 * nl)) return (size_t)-1;
  for (size_t l = 0; l < nl; ++l) {
    b->fl[2 * l] = t->lo[b->ol[l]];
    b->fl[2 * l + 1] = t->hi[b->ol[l]];
  }
  size_t np = vvd_pack_runs(e, b, sg, nl, sp, cut * ei * cut * ei, NULL);
  if (np == (size_t)-1) return np;
  *npanel = 0;
  if (e->pan.n > 0) {
    double r = cut * ei + 0.5 * e->pan.lmax;
    size_t c = px_vortex_tree_within(e->ctx, &e->ptree, xi, yi, r, &b->ol, &b->ol_cap);
    if (c == (size_t)-1 || !list_reserve(e, &b->fp, &b->fp_cap, c + 8)) return (size_t)-1;
    for (size_t q = 0; q < c; ++q) b->fp[q] = e->ptree.order[b->ol[q]];
    *npanel = c;
  }
  return np;
}

/* Block 3. eps* and the VVD sums in one neighbour search: each vortex packs
 * its neighbours within cut times a guess g of its eps* (10% over its eps*
 * of the step before; the exact 3-nearest search where none is known); its
 * 3 nearest are among them when at least 3 are found, which gives eps*
 * exactly; the pack is then narrowed to cut * eps* (g >= eps*, the common
 * case) or redone (g < eps*: from the group's leaves, or by a query of the
 * vortex's own beyond the group's reach). The lists and sums are those of a
 * separate eps* search followed by the VVD's, at one traversal instead of
 * two. */
enum px_status px_vortex_engine_diffusive(struct px_vortex_engine *e, int compute_eps,
                                          double vcap) {
  struct px_vortex_wake *w = &e->w;
  if (w->n == 0) return PX_STATUS_OK;
  PX_TRY(ensure_work(e, w->n));
  double t0 = px_time_now();
  PX_TRY(px_vortex_tree_build(e->ctx, &e->tree, w->n, w->x, w->y, e->cfg.threads));
  const struct px_vortex_tree *t = &e->tree;
  uint32_t *grp = px_mem_alloc(e->ctx, "vortex.work", t->nnode * sizeof(uint32_t));
  if (!grp) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (neighbour groups)");
  size_t ngrp = tree_groups(t, VX_GROUP, grp);
  double t1 = px_time_now();
  e->diffusive_time[0] += t1 - t0;
  const struct px_vortex_panels *p = &e->pan;
  const double cut = e->cfg.cutoff, nu = e->cfg.nu;
  const int self = e->cfg.self_in_i1, moments = e->cfg.vvd_moments;
  const double w_born = px_vortex_newborn_drift(&e->cfg);
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
  /* One tree query per group of neighbouring vortices (tree_groups):
   * the leaves and panels within the largest radius of the group's vortices
   * plus the group's half-diagonal, then for each vortex the subset within
   * its own radius, by the same tests and in the same order as a query of its
   * own (identical sums, a fraction of the traversal). */
  const double lmax = p->n > 0 ? p->lmax : 0.0;
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 2) reduction(| : nonfinite)
  for (long lg = 0; lg < (long)ngrp; ++lg) {
    size_t k = grp[lg];
    struct px_vortex_nbuf *b = &e->nbuf[omp_get_thread_num()];
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
    double cx = 0.5 * (t->bx0[k] + t->bx1[k]), cy = 0.5 * (t->by0[k] + t->by1[k]);
    double hd = 0.5 * hypot(t->bx1[k] - t->bx0[k], t->by1[k] - t->by0[k]);
    /* margin against rounding in the distance tests */
    double rg = (cut * gmax + hd) * (1.0 + 1e-9) + 1e-300;
    size_t ngl = leaves_into(e, t, cx, cy, rg, &b->gl, &b->gl_cap);
    size_t ngp = 0;
    if (ngl != (size_t)-1 && p->n > 0)
      ngp = px_vortex_tree_within(e->ctx, &e->ptree, cx, cy,
                                  (cut * gmax + 0.5 * lmax + hd) * (1.0 + 1e-9) + 1e-300, &b->gp,
                                  &b->gp_cap);
    if (ngl == (size_t)-1 || ngp == (size_t)-1 || !list_reserve(e, &b->fl, &b->fl_cap, 2 * ngl) ||
        !list_reserve(e, &b->fp, &b->fp_cap, ngp + 8) ||
        !arrays_reserve(e, &b->lb, &b->lb_cap, ngl + 8, 6) ||
        !arrays_reserve(e, &b->pc, &b->pc_cap, ngp, 2)) {
      oom = 1;
      continue;
    }
    px_vortex_vvd_leaf_boxes(t, b->gl, ngl, b->lb, b->lb_cap);
    /* the candidate panels' centres, contiguous, and their panel numbers */
    for (size_t q = 0; q < ngp; ++q) {
      uint32_t pi = b->gp[q];
      b->pc[q] = e->ptree.sx[pi];
      b->pc[b->pc_cap + q] = e->ptree.sy[pi];
      b->gp[q] = e->ptree.order[pi];
    }
    for (uint32_t sp = t->lo[k]; sp < t->hi[k]; ++sp) {
    size_t i = t->order[sp];
    double xi = t->sx[sp], yi = t->sy[sp], gi = eg[sp];
    /* the leaves within reach of the guess, as runs of consecutive sorted
     * positions (leaves are in ascending order; neighbouring ones often
     * touch): longer vector loops, fewer scalar remainders */
    size_t nl = px_vortex_vvd_leaf_runs(t, b->gl, b->lb, ngl, b->lb_cap, xi, yi,
                                        cut * gi * cut * gi, b->fl);
    /* the neighbours within reach, packed (offsets and circulations), then
     * one long vector loop over them: the exponential's dependency chain
     * overlaps across iterations, and pairs out of reach cost nothing */
    double low[PX_VORTEX_VVD_LOW];
    for (int q = 0; q < PX_VORTEX_VVD_LOW; ++q) low[q] = INFINITY;
    size_t np = vvd_pack_runs(e, b, sg, nl, sp, cut * gi * cut * gi, compute_eps ? low : NULL);
    if (np == (size_t)-1) {
      oom = 1;
      break;
    }
    double ei = gi;
    int own = 0; /* the lists come from a query of the vortex's own */
    size_t pc = 0;
    if (compute_eps) {
      double d2[3];
      px_vortex_vvd_low3(low, d2);
      /* fewer than 3 within reach: the exact search */
      if (!isfinite(d2[2])) px_vortex_tree_knn_point(t, sp, 3, work, 512, d2);
      ei = eps_value(&e->cfg, d2);
      w->e[i] = ei;
      if (ei > gi && ei <= gmax) { /* the guess fell short: again from the group's lists */
        double r2 = cut * ei * cut * ei;
        nl = px_vortex_vvd_leaf_runs(t, b->gl, b->lb, ngl, b->lb_cap, xi, yi, r2, b->fl);
        np = vvd_pack_runs(e, b, sg, nl, sp, r2, NULL);
      } else if (ei > gi) { /* beyond the group's reach: a search of its own */
        np = vvd_own_lists(e, b, sg, sp, ei, &pc);
        own = 1;
      } else if (ei < gi) {
        np = px_vortex_vvd_shrink(b->pd, b->pd + b->pd_cap, b->pd + 2 * b->pd_cap, np,
                                  cut * ei * cut * ei);
      }
      if (np == (size_t)-1) {
        oom = 1;
        break;
      }
    }
    double inv_e = 1.0 / ei, tiny2 = 1e-24 * ei * ei;
    /* the panels within reach (the wall terms) */
    uint32_t *pl = b->fp;
    if (p->n > 0 && !own) {
      double r = cut * ei + 0.5 * p->lmax;
      pc = px_vortex_vvd_filter(b->pc, b->pc + b->pc_cap, b->gp, ngp, xi, yi, r * r, pl);
    }
    double wx = 0.0, wy = 0.0;
    /* away from walls, vvd_moments: covariance; else (or degenerate) the
     * published formula */
    if (!(moments == PX_VORTEX_MOMENTS_COVARIANCE && pc == 0 &&
          vvd_covariance(b, np, ei, sg[sp], &wx, &wy))) {
      double sums[4]; /* I1, sum |Gamma| exp, I2x, I2y */
      vvd_pair_sums(b, np, inv_e, tiny2, sums);
      double i1 = sums[0], i1abs = sums[1], i2x = sums[2], i2y = sums[3];
      if (self) {
        i1 += sg[sp];
        i1abs += fabs(sg[sp]);
      }
      double el = ei; /* the particle term's length: eps*, or M1 / (2 M0) (vvd_moments) */
      if (moments == PX_VORTEX_MOMENTS_WAKE && pc == 0) {
        double m0, m1;
        vvd_kernel_moments(b, np, inv_e, &m0, &m1);
        if (self) m0 += 1.0;
        if (m1 > 0.0) el = 0.5 * m1 / m0;
      }
      if (fabs(i1) > 1e-10 * i1abs) {
        wx = i2x / (i1 * el);
        wy = i2y / (i1 * el);
      }
      /* wall terms (none within reach: zero, added as such, so that a -0
       * turns to +0 as through the sums) */
      if (p->n > 0 && pc == 0) {
        wx += 0.0;
        wy += 0.0;
      } else if (p->n > 0) {
        double s0, i3x, i3y;
        px_vortex_wall_sum(p, pl, pc, xi, yi, ei, cut, &i3x, &i3y, &s0);
        double i0 = ei * ei * (2.0 * VX_PI - s0);
        double i0min = 0.1 * VX_PI * ei * ei;
        if (i0 < i0min) i0 = i0min;
        wx += i3x / i0;
        wy += i3y / i0;
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
    if (w_born > 0.0 && w->born[i] >= 0) {
      size_t kb = (size_t)w->born[i];
      wx = w_born * p->ty[kb];
      wy = -w_born * p->tx[kb];
    }
    w->wu[i] = wx;
    w->wv[i] = wy;
    if (!isfinite(wx) || !isfinite(wy)) nonfinite = 1;
    }
  }
  px_mem_free(e->ctx, grp);
  e->diffusive_time[1] += px_time_now() - t1;
  if (oom) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)");
  for (size_t i = 0; nonfinite && i < w->n; ++i) /* the first one, for the message */
    if (!isfinite(w->wu[i]) || !isfinite(w->wv[i]))
      return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                             "step %ld: vortex %zu at (%g, %g) has a non-finite diffusive "
                             "velocity (eps* = %g)",
                             e->step, i, w->x[i], w->y[i], w->e[i]);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */
/* Block 4: loads */

static enum px_status loads(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  const struct px_vortex_panels *p = &e->pan;
  size_t n = p->n, nold = w->n - e->n_born;
  /* panel domain radius: mean eps* of the vortices born on it */
  for (size_t k = 0; k < n; ++k) e->pe[k] = 0.0;
  for (size_t k = 0; k < n; ++k) e->omega[k] = 0.0; /* used as a counter first */
  for (size_t i = nold; i < w->n; ++i) {
    size_t k = (size_t)w->born[i];
    e->pe[k] += w->e[i];
    e->omega[k] += 1.0;
  }
  for (size_t k = 0; k < n; ++k)
    e->pe[k] = e->omega[k] > 0.0 ? e->pe[k] / e->omega[k] : e->cfg.eps_min;
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
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 16)
  for (long lk = 0; lk < (long)n; ++lk) {
    size_t k = (size_t)lk;
    double ek = e->pe[k];
    double mx = 0.5 * (p->x0[k] + p->x1[k]), my = 0.5 * (p->y0[k] + p->y1[k]);
    size_t cnt;
    uint32_t *lst = nbuf_query(e, &e->tree, mx, my, cut * ek + 0.5 * p->len[k], &cnt);
    if (!lst) {
      oom = 1;
      continue;
    }
    double acc = px_vortex_wall_s3_sum(p, k, e->tree.sx, e->tree.sy, w->g, e->tree.order, lst, cnt,
                                       ek, cut);
    e->omega[k] = acc / (VX_PI * ek * ek * p->len[k]);
  }
  if (oom) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)");
  /* forces: F = (rho/dt) sum_k delta_k (k x r_k) with delta_k = gamma_k L_k -
   * absorbed_k, the vorticity flux through panel k in the step (Dynnikova's
   * vortex-impulse form; VM2D Mechanics2DRigidImmovable), plus the friction.
   * The force is the rate of change of the vortex impulse rho sum Gamma_i
   * (k x r_i): generation gives the flux term, the motion of the vortices
   * rho sum Gamma_i (k x (V_i + W_i)), whose convective part vanishes (the
   * pair sums are antisymmetric, the circulation sums to zero) and whose
   * diffusive part is the friction: rho sum Gamma_i (k x W_i) is the viscous
   * stress at the wall in the continuum limit (sum Gamma W = -nu int grad omega
   * dA = nu contour integral of omega n). That drift term is the default
   * friction (below); rho nu omega_k L_k tau_k with the wall-vorticity estimate
   * is the alternative (friction_wall). Moment likewise, with
   * rho sum Gamma_i (r_i - c) . W_i. */
  double rho = e->cfg.rho, dt = e->cfg.dt, nu = e->cfg.nu;
  double q = 0.5 * rho * e->cfg.vref * e->cfg.vref;
  for (size_t b = 0; b < p->nbody; ++b) {
    double cx = e->cfg.moment_center[b][0], cy = e->cfg.moment_center[b][1];
    double fx = 0.0, fy = 0.0, m = 0.0, ffx = 0.0, ffy = 0.0, fm = 0.0;
    for (size_t k = p->first[b]; k < p->first[b + 1]; ++k) {
      double d = e->sol[k] * p->len[k] - e->through[k];
      double rx = 0.5 * (p->x0[k] + p->x1[k]) - cx, ry = 0.5 * (p->y0[k] + p->y1[k]) - cy;
      fx += -d * ry;
      fy += d * rx;
      m += 0.5 * d * (rx * rx + ry * ry);
      double tf = rho * nu * e->omega[k] * p->len[k];
      ffx += tf * p->tx[k];
      ffy += tf * p->ty[k];
      fm += tf * (rx * p->ty[k] - ry * p->tx[k]);
    }
    struct px_vortex_loads *L = &e->loads[b];
    L->fx_wall = ffx;
    L->fy_wall = ffy;
    L->fx_fric = ffx;
    L->fy_fric = ffy;
    L->m_fric = fm;
    L->fx = rho / dt * fx + ffx;
    L->fy = rho / dt * fy + ffy;
    L->m = rho / dt * m + fm;
    double c = e->cfg.ref_length[b];
    L->cx = L->fx / (q * c);
    L->cy = L->fy / (q * c);
    L->cm = L->m / (q * c * c);
    double ab = 0.0;
    for (size_t k = p->first[b]; k < p->first[b + 1]; ++k) ab += e->through[k];
    L->absorbed = ab;
  }
  /* impulse balance of the vortices' own motion, rho sum Gamma_i (k x V_i)
   * and rho sum Gamma_i (k x W_i), per body: each vortex counts for the body
   * whose moment centre is nearest (one body: all of them) */
  {
    double cv[2 * PX_VORTEX_MAX_BODIES], dfv[3 * PX_VORTEX_MAX_BODIES];
    memset(cv, 0, sizeof cv);
    memset(dfv, 0, sizeof dfv);
    for (size_t i = 0; i < w->n; ++i) {
      size_t bb = 0;
      double best = INFINITY;
      for (size_t b = 0; b < p->nbody && p->nbody > 1; ++b) {
        double dx = w->x[i] - e->cfg.moment_center[b][0], dy = w->y[i] - e->cfg.moment_center[b][1];
        if (dx * dx + dy * dy < best) {
          best = dx * dx + dy * dy;
          bb = b;
        }
      }
      double g = w->g[i];
      cv[2 * bb] += -g * w->v[i];
      cv[2 * bb + 1] += g * w->u[i];
      dfv[3 * bb] += -g * w->wv[i];
      dfv[3 * bb + 1] += g * w->wu[i];
      dfv[3 * bb + 2] += g * ((w->x[i] - e->cfg.moment_center[bb][0]) * w->wu[i] +
                              (w->y[i] - e->cfg.moment_center[bb][1]) * w->wv[i]);
    }
    for (size_t b = 0; b < p->nbody; ++b) {
      struct px_vortex_loads *L = &e->loads[b];
      L->fx_conv = rho * cv[2 * b];
      L->fy_conv = rho * cv[2 * b + 1];
      L->fx_diff = rho * dfv[3 * b];
      L->fy_diff = rho * dfv[3 * b + 1];
      if (!e->cfg.friction_wall) {
        /* the friction the model's momentum balance implies (default) */
        L->fx += L->fx_diff - L->fx_fric;
        L->fy += L->fy_diff - L->fy_fric;
        L->m += rho * dfv[3 * b + 2] - L->m_fric;
        L->fx_fric = L->fx_diff;
        L->fy_fric = L->fy_diff;
        L->m_fric = rho * dfv[3 * b + 2];
        double c = e->cfg.ref_length[b];
        L->cx = L->fx / (q * c);
        L->cy = L->fy / (q * c);
        L->cm = L->m / (q * c * c);
      }
    }
  }
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */
/* Block 6: non-penetration */

/* First panel crossed by the path (x0, y0) -> (x1, y1), or -1. */
static int32_t crossed_panel(struct px_vortex_engine *e, double x0, double y0, double x1,
                             double y1, int *oom) {
  const struct px_vortex_panels *p = &e->pan;
  double bx0 = fmin(x0, x1), bx1 = fmax(x0, x1), by0 = fmin(y0, y1), by1 = fmax(y0, y1);
  int any = 0;
  for (size_t b = 0; b < p->nbody && !any; ++b)
    any = !(bx1 < p->bxmin[b] || bx0 > p->bxmax[b] || by1 < p->bymin[b] || by0 > p->bymax[b]);
  if (!any) return -1; /* stage 1: outside every body's box */
  size_t cnt;
  uint32_t *lst = nbuf_query(e, &e->ptree, 0.5 * (x0 + x1), 0.5 * (y0 + y1),
                             0.5 * hypot(x1 - x0, y1 - y0) + 0.5 * p->lmax, &cnt);
  if (!lst) {
    *oom = 1;
    return -1;
  }
  int32_t best = -1;
  double tbest = 2.0;
  for (size_t q = 0; q < cnt; ++q) { /* stage 2: the few panels near the path */
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

static enum px_status inside(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  int oom = 0;
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 256)
  for (long li = 0; li < (long)w->n; ++li) {
    size_t i = (size_t)li;
    e->hit[i] = crossed_panel(e, w->x[i], w->y[i], e->xn[i], e->yn[i], &oom);
  }
  if (oom) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)");
  for (size_t k = 0; k < e->pan.n; ++k) e->through[k] = 0.0;
  size_t na = 0;
  for (size_t i = 0; i < w->n; ++i)
    if (e->hit[i] >= 0) {
      e->through[e->hit[i]] += w->g[i];
      ++na;
    }
  e->n_absorbed = na;
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */
/* Block 7: restructuring */

static double growth(const struct px_vortex_engine *e, double x, double y) {
  double s = x * e->stream_dir[0] + y * e->stream_dir[1];
  double f = (s - e->s_right) / (e->span > 0.0 ? e->span : 1.0);
  return f > 1.0 ? f : 1.0;
}

static enum px_status restructure(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  struct px_context *ctx = e->ctx;
  /* move, drop absorbed, far and empty vortices (stable) */
  size_t m = 0, nfar = 0;
  double far2 = e->cfg.dist_far * e->cfg.dist_far;
  for (size_t i = 0; i < w->n; ++i) {
    if (e->hit[i] >= 0 || w->g[i] == 0.0) continue;
    double dx = e->xn[i] - e->center[0], dy = e->yn[i] - e->center[1];
    if (dx * dx + dy * dy > far2) {
      ++nfar;
      continue;
    }
    w->x[m] = e->xn[i];
    w->y[m] = e->yn[i];
    w->g[m] = w->g[i];
    w->u[m] = w->u[i];
    w->v[m] = w->v[i];
    w->wu[m] = w->wu[i];
    w->wv[m] = w->wv[i];
    w->e[m] = w->e[i];
    w->born[m] = -1;
    ++m;
  }
  w->n = m;
  e->n_far = nfar;
  e->n_merged = 0;
  if (m == 0) return PX_STATUS_OK;
  PX_TRY(px_vortex_tree_build(ctx, &e->tree, m, w->x, w->y, e->cfg.threads));
  const struct px_vortex_tree *t = &e->tree;
  const double ec = e->cfg.eps_col, eo = e->cfg.eps_col_opposite, gmax = e->cfg.gamma_max;
  const double emax = ec > eo ? ec : eo;
  int oom = 0;
  /* partner search (parallel, each vortex on its own): the nearest eligible
   * neighbour, ties to the lower sorted position. One tree query per leaf
   * (radius: the leaf's largest plus its half-diagonal; groups of 64 as in
   * the diffusive block measured slower here); each vortex scans
   * the points of the candidate leaves near it in ascending sorted position:
   * every point farther than ro fails the tests below, so the partner is the
   * one a query of its own would give. */
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 16)
  for (long lk = 0; lk < (long)t->nnode; ++lk) {
    size_t k = (size_t)lk;
    if (t->left[k] >= 0) continue;
    struct px_vortex_nbuf *b = &e->nbuf[omp_get_thread_num()];
    double romax = 0.0;
    for (uint32_t sp = t->lo[k]; sp < t->hi[k]; ++sp)
      romax = fmax(romax, emax * growth(e, t->sx[sp], t->sy[sp]));
    double cx = 0.5 * (t->bx0[k] + t->bx1[k]), cy = 0.5 * (t->by0[k] + t->by1[k]);
    double hd = 0.5 * hypot(t->bx1[k] - t->bx0[k], t->by1[k] - t->by0[k]);
    size_t ngl = leaves_into(e, t, cx, cy, (romax + hd) * (1.0 + 1e-9) + 1e-300, &b->gl,
                             &b->gl_cap);
    if (ngl == (size_t)-1) {
      oom = 1;
      continue;
    }
    for (uint32_t sp = t->lo[k]; sp < t->hi[k]; ++sp) {
      size_t i = t->order[sp];
      double xi = t->sx[sp], yi = t->sy[sp], gi = w->g[i];
      double f = growth(e, xi, yi);
      double rs = ec * f, ro = eo * f, rb = rs > ro ? rs : ro, gcap = gmax * f * f;
      int32_t best = -1;
      double dbest = INFINITY;
      for (size_t q = 0; q < ngl; ++q) {
        uint32_t l = b->gl[q];
        if (px_vortex_tree_box_dist2(t, l, xi, yi) > rb * rb) continue;
        for (uint32_t sj = t->lo[l]; sj < t->hi[l]; ++sj) {
          if (sj == sp) continue;
          double gj = w->g[t->order[sj]];
          double dx = t->sx[sj] - xi, dy = t->sy[sj] - yi, d2 = dx * dx + dy * dy;
          int ok;
          if (gi * gj > 0.0)
            ok = d2 < rs * rs && fabs(gi + gj) < gcap;
          else
            ok = d2 < ro * ro;
          if (ok && d2 < dbest) {
            dbest = d2;
            best = (int32_t)sj;
          }
        }
      }
      e->partner[sp] = best;
    }
  }
  if (oom) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)");
  /* sequential merge in sorted order (deterministic) */
  memset(e->flag, 0, m);
  double *nx = e->xn, *ny = e->yn; /* reused: positions in sorted order */
  size_t merged = 0;
  for (size_t sp = 0; sp < m; ++sp) {
    nx[sp] = t->sx[sp];
    ny[sp] = t->sy[sp];
  }
  for (size_t sp = 0; sp < m; ++sp) {
    if (e->flag[sp]) continue;
    int32_t sq = e->partner[sp];
    if (sq < 0 || e->flag[sq]) continue;
    size_t i = t->order[sp], j = t->order[(size_t)sq];
    double gi = w->g[i], gj = w->g[j], g = gi + gj;
    double x, y;
    if (gi * gj > 0.0) {
      double ai = fabs(gi), aj = fabs(gj);
      x = (ai * nx[sp] + aj * nx[sq]) / (ai + aj);
      y = (ai * ny[sp] + aj * ny[sq]) / (ai + aj);
    } else if (fabs(gi) >= fabs(gj)) {
      x = nx[sp];
      y = ny[sp];
    } else {
      x = nx[sq];
      y = ny[sq];
    }
    /* a merge must not carry circulation into a body */
    if (crossed_panel(e, nx[sp], ny[sp], x, y, &oom) >= 0 ||
        crossed_panel(e, nx[sq], ny[sq], x, y, &oom) >= 0)
      continue;
    nx[sp] = x;
    ny[sp] = y;
    w->g[i] = g;
    w->g[j] = 0.0;
    e->flag[sp] = e->flag[sq] = 1;
    ++merged;
  }
  if (oom) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)");
  e->n_merged = merged;
  /* compact in sorted (Morton) order: keeps the wake spatially coherent */
  size_t k = 0;
  /* gather into sorted order through scratch (the diffusive velocities are
   * not needed any more); the convective velocities are kept for outputs */
  double *tg = w->wu, *te = w->wv, *tu = w->s1, *tv = w->s2;
  for (size_t sp = 0; sp < m; ++sp) {
    size_t i = t->order[sp];
    tg[sp] = w->g[i];
    te[sp] = w->e[i];
    tu[sp] = w->u[i];
    tv[sp] = w->v[i];
  }
  for (size_t sp = 0; sp < m; ++sp) {
    if (tg[sp] == 0.0) continue;
    w->x[k] = nx[sp];
    w->y[k] = ny[sp];
    w->g[k] = tg[sp];
    w->e[k] = te[sp];
    w->u[k] = tu[sp];
    w->v[k] = tv[sp];
    ++k;
  }
  for (size_t i = 0; i < k; ++i) {
    w->wu[i] = w->wv[i] = 0.0;
    w->born[i] = -1;
  }
  w->n = k;
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */

/* CPU time of the process (all threads) [s]. */
static double vx_cpu_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Block 5 with rk2: Heun's method. The first stage's velocities V1 and W1
 * are those of the step's start; the predictor moves every vortex by (V1 +
 * W1) dt (unless that move crosses a panel, see below), a second sheet is
 * solved for the predicted wake (no absorbed circulation to return, the free
 * stream of the step's end) and shed as temporary vortices on the panels,
 * whose field, with the exact-sheet correction near the wall, gives V2 at the
 * predicted positions, and the VVD of the predicted wake with them gives W2
 * (the diffusive block once more, timed as such); the vortices then move from
 * their start by ((V1 + V2) / 2 + (W1 + W2) / 2) dt into xn, and the
 * temporaries go. The first stage's sheet stays the step's sheet (loads,
 * pressure). Until 2026-11-26 the diffusion stayed explicit Euler (W1 alone):
 * the lift amplitude of the cylinder at Re = 100 then still moved by 5% from
 * dt = 0.02 to 0.01 (docs/notes/vortex.md, "Time stepping"). */
static enum px_status heun(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  struct px_context *ctx = e->ctx;
  const size_t n1 = w->n, np = e->pan.n, ns = e->pan.nsys;
  const double dt = e->cfg.dt;
  if (n1 > e->rk_cap || !e->rk) {
    px_mem_free(ctx, e->rk);
    e->rk_cap = n1 + n1 / 2 + 64;
    e->rk = px_mem_alloc(ctx, "vortex.work", (6 * e->rk_cap + ns) * sizeof(double));
    if (!e->rk) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (rk2 stage)");
  }
  if (!e->rk_born) {
    e->rk_born = px_mem_alloc(ctx, "vortex.work", (np + 1) * sizeof(size_t));
    if (!e->rk_born) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (rk2 stage)");
  }
  double *x1 = e->rk, *y1 = x1 + e->rk_cap, *u1 = y1 + e->rk_cap, *v1 = u1 + e->rk_cap;
  double *wu1 = v1 + e->rk_cap, *wv1 = wu1 + e->rk_cap, *sol1 = wv1 + e->rk_cap;
  memcpy(x1, w->x, n1 * sizeof(double));
  memcpy(y1, w->y, n1 * sizeof(double));
  memcpy(u1, w->u, n1 * sizeof(double));
  memcpy(v1, w->v, n1 * sizeof(double));
  memcpy(wu1, w->wu, n1 * sizeof(double));
  memcpy(wv1, w->wv, n1 * sizeof(double));
  memcpy(sol1, e->sol, ns * sizeof(double));
  if (np > 0) memcpy(e->rk_born, e->born_first, (np + 1) * sizeof(size_t));
  const size_t born1 = e->n_born;
  /* The predictor. A vortex whose predicted move crosses a panel would be
   * absorbed at the step's end; left inside the body it would sit next to the
   * panels' control points and bend the second sheet and its neighbours'
   * second-stage velocities (about 1% of the vortices per step on the
   * cylinder and the airfoil; on the NACA case C_y went from Euler's 0.29 to
   * 0.44). It waits at its start position instead, where the second stage
   * evaluates the predicted field. */
  int oom = 0;
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 256)
  for (long li = 0; li < (long)n1; ++li) {
    size_t i = (size_t)li;
    double qx = x1[i] + (u1[i] + wu1[i]) * dt, qy = y1[i] + (v1[i] + wv1[i]) * dt;
    if (np > 0 && crossed_panel(e, x1[i], y1[i], qx, qy, &oom) >= 0) {
      qx = x1[i];
      qy = y1[i];
    }
    w->x[i] = qx;
    w->y[i] = qy;
  }
  double vx, vy;
  px_vortex_vinf(&e->cfg, e->time + dt, &vx, &vy);
  enum px_status s = oom ? px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)")
                         : generation(e, vx, vy, NULL);
  if (s == PX_STATUS_OK) s = ensure_work(e, w->n);
  if (s == PX_STATUS_OK) s = convective(e, vx, vy);
  if (s == PX_STATUS_OK) { /* W2: counted in the diffusive block, not in the move's */
    double t0 = px_time_now(), c0 = vx_cpu_now();
    s = px_vortex_engine_diffusive(e, 1, 1.5 * e->cfg.vref);
    double t = px_time_now() - t0, c = vx_cpu_now() - c0;
    e->block_time[PX_VORTEX_BLOCK_DIFFUSIVE] += t;
    e->block_cpu[PX_VORTEX_BLOCK_DIFFUSIVE] += c;
    e->block_time[PX_VORTEX_BLOCK_MOVE] -= t;
    e->block_cpu[PX_VORTEX_BLOCK_MOVE] -= c;
  }
  if (s == PX_STATUS_OK)
    for (size_t i = 0; i < n1; ++i) {
      double um = 0.5 * (u1[i] + w->u[i]), vm = 0.5 * (v1[i] + w->v[i]);
      double wum = 0.5 * (wu1[i] + w->wu[i]), wvm = 0.5 * (wv1[i] + w->wv[i]);
      e->xn[i] = x1[i] + (um + wum) * dt;
      e->yn[i] = y1[i] + (vm + wvm) * dt;
      w->u[i] = um;
      w->v[i] = vm;
      w->wu[i] = wum;
      w->wv[i] = wvm;
    }
  /* back to the step's wake and sheet (also after a failure: the state stays
   * the step's start for the diagnosis and the checkpoint) */
  if (s != PX_STATUS_OK) {
    memcpy(w->u, u1, n1 * sizeof(double));
    memcpy(w->v, v1, n1 * sizeof(double));
    memcpy(w->wu, wu1, n1 * sizeof(double));
    memcpy(w->wv, wv1, n1 * sizeof(double));
  }
  w->n = n1;
  memcpy(w->x, x1, n1 * sizeof(double));
  memcpy(w->y, y1, n1 * sizeof(double));
  memcpy(e->sol, sol1, ns * sizeof(double));
  if (np > 0) memcpy(e->born_first, e->rk_born, (np + 1) * sizeof(size_t));
  e->n_born = born1;
  return s;
}

enum px_status px_vortex_engine_step(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  double vx, vy, t0, c0;
  px_vortex_vinf(&e->cfg, e->time, &vx, &vy);
  e->last_vinf[0] = vx;
  e->last_vinf[1] = vy;
#ifdef PX_HAVE_OPENCL
  if (e->dev) {
    PX_TRY(px_vortex_ocl_step(e, vx, vy));
    e->step++;
    e->time = (double)e->step * e->cfg.dt;
    return PX_STATUS_OK;
  }
#endif
  PX_TRY(ensure_work(e, w->n + e->pan.n));
  for (size_t i = 0; i < w->n; ++i)
    if (!isfinite(w->x[i]) || !isfinite(w->y[i]) || !isfinite(w->g[i]))
      return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                             "step %ld: vortex %zu has a non-finite position or circulation "
                             "(x = %g, y = %g, Gamma = %g)",
                             e->step, i, w->x[i], w->y[i], w->g[i]);

  t0 = px_time_now();
  c0 = vx_cpu_now();
  PX_TRY(generation(e, vx, vy, e->through));
  PX_TRY(ensure_work(e, w->n));
  e->block_time[PX_VORTEX_BLOCK_GENERATION] += px_time_now() - t0;
  e->block_cpu[PX_VORTEX_BLOCK_GENERATION] += vx_cpu_now() - c0;

  t0 = px_time_now();
  c0 = vx_cpu_now();
  PX_TRY(convective(e, vx, vy));
  e->block_time[PX_VORTEX_BLOCK_CONVECTIVE] += px_time_now() - t0;
  e->block_cpu[PX_VORTEX_BLOCK_CONVECTIVE] += vx_cpu_now() - c0;

  t0 = px_time_now();
  c0 = vx_cpu_now();
  PX_TRY(px_vortex_engine_diffusive(e, 1, 1.5 * e->cfg.vref));
  e->block_time[PX_VORTEX_BLOCK_DIFFUSIVE] += px_time_now() - t0;
  e->block_cpu[PX_VORTEX_BLOCK_DIFFUSIVE] += vx_cpu_now() - c0;

  t0 = px_time_now();
  c0 = vx_cpu_now();
  PX_TRY(loads(e));
  e->block_time[PX_VORTEX_BLOCK_LOADS] += px_time_now() - t0;
  e->block_cpu[PX_VORTEX_BLOCK_LOADS] += vx_cpu_now() - c0;

  t0 = px_time_now();
  c0 = vx_cpu_now();
  if (e->cfg.rk2) {
    PX_TRY(heun(e));
  } else {
    double dt = e->cfg.dt;
    for (size_t i = 0; i < w->n; ++i) {
      e->xn[i] = w->x[i] + (w->u[i] + w->wu[i]) * dt;
      e->yn[i] = w->y[i] + (w->v[i] + w->wv[i]) * dt;
    }
  }
  e->block_time[PX_VORTEX_BLOCK_MOVE] += px_time_now() - t0;
  e->block_cpu[PX_VORTEX_BLOCK_MOVE] += vx_cpu_now() - c0;

  t0 = px_time_now();
  c0 = vx_cpu_now();
  PX_TRY(inside(e));
  e->block_time[PX_VORTEX_BLOCK_INSIDE] += px_time_now() - t0;
  e->block_cpu[PX_VORTEX_BLOCK_INSIDE] += vx_cpu_now() - c0;

  t0 = px_time_now();
  c0 = vx_cpu_now();
  PX_TRY(restructure(e));
  e->block_time[PX_VORTEX_BLOCK_RESTRUCT] += px_time_now() - t0;
  e->block_cpu[PX_VORTEX_BLOCK_RESTRUCT] += vx_cpu_now() - c0;

  double c = 0.0;
  for (size_t i = 0; i < w->n; ++i) c += w->g[i];
  e->circulation = c;
  e->step++;
  e->time = (double)e->step * e->cfg.dt;
  return PX_STATUS_OK;
}

enum px_status px_vortex_engine_velocity(struct px_vortex_engine *e, size_t n, const double *x,
                                         const double *y, double *u, double *v) {
  double vx, vy;
  px_vortex_vinf(&e->cfg, e->time, &vx, &vy);
  PX_TRY(px_vortex_engine_sync(e));
  PX_TRY(nb_sources(e));
  for (size_t i0 = 0; i0 < n; i0 += 65536) { /* bounded target buffers */
    size_t m = n - i0 < 65536 ? n - i0 : 65536;
    PX_TRY(nb_targets(e, m, x + i0, y + i0, u + i0, v + i0));
  }
  for (size_t i = 0; i < n; ++i) {
    u[i] += vx;
    v[i] += vy;
  }
  return PX_STATUS_OK;
}
