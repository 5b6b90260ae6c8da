/* The vortex engine's host state (see vortex_core.h) that every engine
 * shares: configuration, wake arrays, panels, trees, work buffers and the
 * buffers of the pair sums; the cpu engine's blocks are in vortex_cpu.c and
 * vortex_diffusive.c. */
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
#include "solvers/vortex/vortex_core_impl.h"

#define PX_REAL double
#include "kernels/px_kernel.h"
#include "solvers/vortex/vortex_kernel.h"

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

/* A newborn vortex's first-step drift off the wall: a sheet released at a
 * flat wall diffuses as omega ~ exp(-y^2 / (4 nu t)) / sqrt(pi nu t), whose
 * centroid is at 2 sqrt(nu t / pi) after t, so the mean drift over the step
 * is 2 sqrt(nu / (pi dt)). */
double px_vortex_newborn_drift(const struct px_vortex_config *cfg) {
  return cfg->newborn_rayleigh ? 2.0 * sqrt(cfg->nu / (VX_PI * cfg->dt)) : 0.0;
}

/* ------------------------------------------------------------------------- */

void px_vortex_wake_free(struct px_context *ctx, struct px_vortex_wake *w) {
  px_mem_free(ctx, w->x);
  px_mem_free(ctx, w->born);
  memset(w, 0, sizeof *w);
}

enum px_status px_vortex_wake_reserve(struct px_context *ctx, struct px_vortex_wake *w, size_t n) {
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
    /* the old arrays hold at most w->cap vortices: an OpenCL engine's sync
       sets w->n to the device's count, which may exceed it, before it
       reserves the room to copy that count back */
    const size_t keep = w->n < w->cap ? w->n : w->cap;
    double *old[8] = {w->x, w->y, w->g, w->u, w->v, w->wu, w->wv, w->e};
    for (int q = 0; q < 8; ++q) memcpy(arr[q], old[q], keep * sizeof(double));
    memcpy(born, w->born, keep * sizeof(int32_t));
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

enum px_status px_vortex_ensure_work(struct px_vortex_engine *e, size_t n) {
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

void px_vortex_core_free(struct px_vortex_engine *e) {
  if (!e) return;
  struct px_context *ctx = e->ctx;
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
      px_mem_free(ctx, e->nbuf[t].sl);
      px_mem_free(ctx, e->nbuf[t].sb);
    }
  px_mem_free(ctx, e->nbuf);
  px_mem_free(ctx, e);
}

enum px_status px_vortex_core_create(struct px_context *ctx, struct px_backend *be,
                                     const struct px_vortex_config *cfg, int fmm,
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
   * than 1e-5 sums in double; an engine without the FMM (opencl) keeps its
   * float direct sums */
  const int fmm_ok = be && fmm && cfg->method != PX_NBODY_METHOD_DIRECT;
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
#define VX_CHK(call)                   \
  do {                                 \
    st = (call);                       \
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
    st = px_vortex_tree_build(ctx, &e->ptree, n, mx, mx + n, 0, 1);
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
  VX_CHK(px_vortex_ensure_work(e, 1024));
  if (be) {
    VX_CHK(px_nbody_create(be, cfg->method, e->nb_prec, cfg->eps, &e->nbe));
    if (fmm_ok) /* the direct sum (opencl: always under auto) has no tolerance */
      VX_CHK(px_nbody_set_tolerance(e->nbe, cfg->tolerance));
  }
#undef VX_CHK
  *out = e;
  return PX_STATUS_OK;
fail:
  px_vortex_core_free(e);
  return st;
}

/* A thread's neighbour buffer on first use (NULL stays the out-of-memory
 * signal of the queries). */
static uint32_t *nbuf_init(struct px_vortex_engine *e, struct px_vortex_nbuf *b) {
  b->p = px_mem_alloc(e->ctx, "vortex.query", 256 * sizeof(uint32_t));
  b->cap = b->p ? 256 : 0;
  return b->p;
}

uint32_t *px_vortex_nbuf_query(struct px_vortex_engine *e, const struct px_vortex_tree *t, double x,
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

size_t px_vortex_nbuf_group(struct px_vortex_engine *e, const struct px_vortex_tree *t, double cx,
                            double cy, double r) {
  struct px_vortex_nbuf *b = &e->nbuf[omp_get_thread_num()];
  size_t c = px_vortex_tree_within(e->ctx, t, cx, cy, r, &b->gp, &b->gp_cap);
  if (c == (size_t)-1 || !px_vortex_list_reserve(e, &b->fp, &b->fp_cap, c + 8) ||
      !px_vortex_arrays_reserve(e, &b->pc, &b->pc_cap, c, 2))
    return (size_t)-1;
  for (size_t q = 0; q < c; ++q) {
    b->pc[q] = t->sx[b->gp[q]];
    b->pc[b->pc_cap + q] = t->sy[b->gp[q]];
  }
  return c;
}

uint32_t *px_vortex_nbuf_pick(struct px_vortex_engine *e, size_t ng, double x, double y, double r,
                              size_t *cnt) {
  struct px_vortex_nbuf *b = &e->nbuf[omp_get_thread_num()];
  *cnt = px_vortex_vvd_filter(b->pc, b->pc + b->pc_cap, b->gp, ng, x, y, r * r, b->fp);
  return b->fp;
}

/* Grow a work list to hold n entries (contents kept); 0 when out of memory. */
int px_vortex_list_reserve(struct px_vortex_engine *e, uint32_t **p, size_t *cap, size_t n) {
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
int px_vortex_arrays_reserve(struct px_vortex_engine *e, double **p, size_t *cap, size_t n,
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
size_t px_vortex_leaves_into(struct px_vortex_engine *e, const struct px_vortex_tree *t, double x,
                             double y, double r, uint32_t **buf, size_t *cap) {
  if (!*buf && !px_vortex_list_reserve(e, buf, cap, 256)) return (size_t)-1;
  for (;;) {
    size_t c = px_vortex_tree_leaves(t, x, y, r, *buf, *cap);
    if (c <= *cap) return c;
    if (!px_vortex_list_reserve(e, buf, cap, c)) return (size_t)-1;
  }
}

/* Buffers of the N-body sums: set `which` (0: sources/outputs, 1: extra
 * targets) to hold at least n elements. */
static enum px_status nb_reserve(struct px_vortex_engine *e, int which, size_t n) {
  if (n <= e->nb_cap[which] && e->nb[which ? 5 : 0]) return PX_STATUS_OK;
  size_t cap = n + n / 2 + 256;
  size_t es = e->nb_prec == PX_PRECISION_DOUBLE ? sizeof(double) : sizeof(float);
  static const char *const names[9] = {"vortex.nbody.x",  "vortex.nbody.y",  "vortex.nbody.g",
                                       "vortex.nbody.u",  "vortex.nbody.v",  "vortex.nbody.tx",
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

enum px_status px_vortex_nb_get(struct px_vortex_engine *e, struct px_buffer *b, double *dst,
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
enum px_status px_vortex_nb_sources(struct px_vortex_engine *e) {
  const struct px_vortex_wake *w = &e->w;
  PX_TRY(nb_reserve(e, 0, w->n));
  PX_TRY(nb_put(e, e->nb[0], w->x, w->n, e->center[0]));
  PX_TRY(nb_put(e, e->nb[1], w->y, w->n, e->center[1]));
  return nb_put(e, e->nb[2], w->g, w->n, 0.0);
}

/* Velocities (pair sum only) at nt extra targets from the uploaded wake. */
enum px_status px_vortex_nb_targets(struct px_vortex_engine *e, size_t nt, const double *tx,
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
  PX_TRY(px_vortex_nb_get(e, e->nb[7], u, nt));
  return px_vortex_nb_get(e, e->nb[8], v, nt);
}

double px_vortex_cpu_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

enum px_status px_vortex_core_velocity(struct px_vortex_engine *e, size_t n, const double *x,
                                       const double *y, double *u, double *v) {
  PX_TRY(px_vortex_nb_sources(e));
  for (size_t i0 = 0; i0 < n; i0 += 65536) { /* bounded target buffers */
    size_t m = n - i0 < 65536 ? n - i0 : 65536;
    PX_TRY(px_vortex_nb_targets(e, m, x + i0, y + i0, u + i0, v + i0));
  }
  return PX_STATUS_OK;
}
