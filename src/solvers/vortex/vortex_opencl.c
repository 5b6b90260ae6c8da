/* The vortex step on an OpenCL device (kernels in vortex.cl). The wake lives
 * in device buffers for the whole run; the host reads back per step only the
 * scalars the step needs (number of newborn and surviving vortices, a
 * runaway/non-finite flag) and the loads, and the whole wake only for outputs
 * and checkpoints (px_vortex_engine_sync). The generation matrix is inverted
 * once on the host (LAPACKE dgetri) and the device multiplies by it. */
#include "solvers/vortex/vortex_opencl.h"

#ifdef PX_HAVE_OPENCL

#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "compute/opencl/kernels.h"
#include "partix/memory.h"
#include "partix/nbody.h"
#include "partix/timer.h"

extern const char px_cl_source_vortex[];

enum {
  /* wake, two sets (A: current, B: compaction target) */
  W_X, W_Y, W_G, W_U, W_V, W_E, W_X2, W_Y2, W_G2, W_U2, W_V2, W_E2,
  W_WU, W_WV, W_XN, W_YN, W_MX, W_MY, /* reals */
  W_BORN, W_HIT, W_PARTNER, W_KEEP, W_POS, /* ints */
  W_NB_X, W_NB_Y, W_NB_G, W_NB_U, W_NB_V, /* N-body precision */
  W_COUNT_
};
enum {
  P_X0, P_Y0, P_X1, P_Y1, P_TX, P_TY, P_LEN, P_AINV, P_RHS, P_SOL, P_THROUGH, P_PE, P_OMEGA,
  P_CENTER, P_BBOX, P_OUT, P_GX, P_GY, P_SOL1, P_ZERO, /* reals */
  P_FIRST, P_COUNT, P_START, P_FLAG, /* uints */
  P_NB_GX, P_NB_GY, P_NB_GU, P_NB_GV, /* N-body precision */
  P_COUNT_
};

struct px_vortex_ocl {
  struct px_backend *be; /* borrowed */
  enum px_precision real; /* storage precision on the device */
  size_t rs, nbs;         /* bytes of a real and of an N-body real */
  cl_program prog;
  struct px_buffer *w[W_COUNT_];
  size_t cap;             /* vortices the wake buffers hold */
  struct px_buffer *p[P_COUNT_];
  int host_dirty;         /* the host wake changed: upload before the next step */
};

static enum px_status kernel(struct px_vortex_ocl *d, const char *name, cl_kernel *k) {
  return px_opencl_kernel(d->be, d->prog, name, k);
}

/* Argument helpers: a real scalar in the storage precision, a uint, a buffer. */
static enum px_status arg_r(struct px_vortex_ocl *d, cl_kernel k, cl_uint i, double v) {
  if (d->real == PX_PRECISION_DOUBLE) return px_opencl_arg(d->be, k, i, sizeof v, &v);
  float f = (float)v;
  return px_opencl_arg(d->be, k, i, sizeof f, &f);
}
static enum px_status arg_u(struct px_vortex_ocl *d, cl_kernel k, cl_uint i, size_t v) {
  cl_uint u = (cl_uint)v;
  return px_opencl_arg(d->be, k, i, sizeof u, &u);
}
static enum px_status arg_i(struct px_vortex_ocl *d, cl_kernel k, cl_uint i, int v) {
  cl_int u = (cl_int)v;
  return px_opencl_arg(d->be, k, i, sizeof u, &u);
}
static enum px_status arg_b(struct px_vortex_ocl *d, cl_kernel k, cl_uint i, struct px_buffer *b) {
  return px_opencl_arg_mem(d->be, k, i, b);
}

/* Buffer arguments from *a on: set[idx[0]], set[idx[1]], ... */
static enum px_status arg_list(struct px_vortex_ocl *d, cl_kernel k, cl_uint *a,
                               struct px_buffer *const *set, const int *idx, int n) {
  for (int q = 0; q < n; ++q) PX_TRY(arg_b(d, k, (*a)++, set[idx[q]]));
  return PX_STATUS_OK;
}

/* The panels as the kernels take them: start point, tangent and length
 * (frame), or start and end points (ends). */
static const int panel_frame[] = {P_X0, P_Y0, P_TX, P_TY, P_LEN};
static const int panel_ends[] = {P_X0, P_Y0, P_X1, P_Y1};

/* Host doubles <-> device reals. */
static enum px_status put_reals(struct px_vortex_engine *e, struct px_buffer *b, const double *src,
                                size_t n) {
  struct px_vortex_ocl *d = e->dev;
  if (n == 0) return PX_STATUS_OK;
  if (d->real == PX_PRECISION_DOUBLE) return px_buffer_write(b, 0, n * sizeof(double), src);
  float *f = px_mem_alloc(e->ctx, "vortex.ocl", n * sizeof(float));
  if (!f) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory");
  for (size_t i = 0; i < n; ++i) f[i] = (float)src[i];
  enum px_status st = px_buffer_write(b, 0, n * sizeof(float), f);
  px_mem_free(e->ctx, f);
  return st;
}
static enum px_status get_reals(struct px_vortex_engine *e, struct px_buffer *b, double *dst,
                                size_t n) {
  struct px_vortex_ocl *d = e->dev;
  if (n == 0) return PX_STATUS_OK;
  if (d->real == PX_PRECISION_DOUBLE) return px_buffer_read(b, 0, n * sizeof(double), dst);
  float *f = px_mem_alloc(e->ctx, "vortex.ocl", n * sizeof(float));
  if (!f) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory");
  enum px_status st = px_buffer_read(b, 0, n * sizeof(float), f);
  for (size_t i = 0; st == PX_STATUS_OK && i < n; ++i) dst[i] = f[i];
  px_mem_free(e->ctx, f);
  return st;
}

/* Wake buffers for at least n vortices (contents of the A set kept). */
static enum px_status reserve(struct px_vortex_engine *e, size_t n) {
  struct px_vortex_ocl *d = e->dev;
  if (n <= d->cap && d->w[W_X]) return PX_STATUS_OK;
  size_t cap = n + n / 2 + 1024;
  for (int q = 0; q < W_COUNT_; ++q) {
    size_t es = q <= W_MY ? d->rs : (q <= W_POS ? sizeof(cl_uint) : d->nbs);
    if (!d->w[q]) {
      PX_TRY(px_buffer_create(d->be, "vortex.wake.device", cap * es, &d->w[q]));
    } else {
      PX_TRY(px_buffer_resize(d->w[q], cap * es));
    }
  }
  d->cap = cap;
  return PX_STATUS_OK;
}

void px_vortex_ocl_free(struct px_vortex_engine *e) {
  struct px_vortex_ocl *d = e->dev;
  if (!d) return;
  for (int q = 0; q < W_COUNT_; ++q) px_buffer_free(d->w[q]);
  for (int q = 0; q < P_COUNT_; ++q) px_buffer_free(d->p[q]);
  px_mem_free(e->ctx, d);
  e->dev = NULL;
}

enum px_status px_vortex_ocl_create(struct px_vortex_engine *e) {
  struct px_context *ctx = e->ctx;
  struct px_vortex_ocl *d = px_mem_calloc(ctx, "vortex.ocl", 1, sizeof *d);
  if (!d) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
  e->dev = d;
  d->be = e->be;
  d->real = (e->cfg.precision != PX_PRECISION_SINGLE && px_backend_has_fp64(e->be))
                ? PX_PRECISION_DOUBLE
                : PX_PRECISION_SINGLE;
  d->rs = d->real == PX_PRECISION_DOUBLE ? sizeof(double) : sizeof(float);
  d->nbs = e->nb_prec == PX_PRECISION_DOUBLE ? sizeof(double) : sizeof(float);
  PX_TRY(px_opencl_program_real(d->be, d->real == PX_PRECISION_DOUBLE ? "vortex_d" : "vortex_f",
                                px_cl_source_vortex, d->real,
                                d->nbs == sizeof(double) ? "-DVX_NB_REAL=double"
                                                         : "-DVX_NB_REAL=float",
                                &d->prog));
  const struct px_vortex_panels *p = &e->pan;
  size_t n = p->n, ns = p->nsys, nb = p->nbody ? p->nbody : 1, nn = n ? n : 1;
  size_t sizes[P_COUNT_] = {0};
  for (int q = P_X0; q <= P_LEN; ++q) sizes[q] = nn * d->rs;
  sizes[P_AINV] = (ns ? ns * ns : 1) * d->rs;
  sizes[P_RHS] = sizes[P_SOL] = sizes[P_SOL1] = (ns ? ns : 1) * d->rs;
  sizes[P_ZERO] = nn * d->rs;
  sizes[P_THROUGH] = sizes[P_PE] = sizes[P_OMEGA] = nn * d->rs;
  sizes[P_CENTER] = 2 * nb * d->rs;
  sizes[P_BBOX] = 4 * nb * d->rs;
  sizes[P_OUT] = 10 * nb * d->rs;
  sizes[P_GX] = sizes[P_GY] = 2 * nn * d->rs;
  sizes[P_FIRST] = (nb + 1) * sizeof(cl_uint);
  sizes[P_COUNT] = sizes[P_START] = nn * sizeof(cl_uint);
  sizes[P_FLAG] = 4 * sizeof(cl_uint);
  sizes[P_NB_GX] = sizes[P_NB_GY] = sizes[P_NB_GU] = sizes[P_NB_GV] = 2 * nn * d->nbs;
  for (int q = 0; q < P_COUNT_; ++q)
    PX_TRY(px_buffer_create(d->be, "vortex.panels.device", sizes[q], &d->p[q]));
  if (n == 0) return reserve(e, 1024);
  PX_TRY(put_reals(e, d->p[P_X0], p->x0, n));
  PX_TRY(put_reals(e, d->p[P_Y0], p->y0, n));
  PX_TRY(put_reals(e, d->p[P_X1], p->x1, n));
  PX_TRY(put_reals(e, d->p[P_Y1], p->y1, n));
  PX_TRY(put_reals(e, d->p[P_TX], p->tx, n));
  PX_TRY(put_reals(e, d->p[P_TY], p->ty, n));
  PX_TRY(put_reals(e, d->p[P_LEN], p->len, n));
  cl_uint first[PX_VORTEX_MAX_BODIES + 1];
  for (size_t b = 0; b <= p->nbody; ++b) first[b] = (cl_uint)p->first[b];
  PX_TRY(px_buffer_write(d->p[P_FIRST], 0, (p->nbody + 1) * sizeof(cl_uint), first));
  double tmp[4 * PX_VORTEX_MAX_BODIES];
  for (size_t b = 0; b < p->nbody; ++b) {
    tmp[2 * b] = e->cfg.moment_center[b][0];
    tmp[2 * b + 1] = e->cfg.moment_center[b][1];
  }
  PX_TRY(put_reals(e, d->p[P_CENTER], tmp, 2 * p->nbody));
  for (size_t b = 0; b < p->nbody; ++b) {
    tmp[4 * b] = p->bxmin[b];
    tmp[4 * b + 1] = p->bymin[b];
    tmp[4 * b + 2] = p->bxmax[b];
    tmp[4 * b + 3] = p->bymax[b];
  }
  PX_TRY(put_reals(e, d->p[P_BBOX], tmp, 4 * p->nbody));
  /* Gauss points of the right-hand side's far field (as vortex_core.c) */
  double *g = px_mem_alloc(ctx, "vortex.ocl", 4 * n * sizeof(double));
  if (!g) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
  const double gauss = 0.21132486540518711775;
  for (size_t i = 0; i < n; ++i) {
    double dx = p->x1[i] - p->x0[i], dy = p->y1[i] - p->y0[i];
    g[2 * i] = p->x0[i] + gauss * dx - e->center[0];
    g[2 * i + 1] = p->x1[i] - gauss * dx - e->center[0];
    g[2 * n + 2 * i] = p->y0[i] + gauss * dy - e->center[1];
    g[2 * n + 2 * i + 1] = p->y1[i] - gauss * dy - e->center[1];
  }
  enum px_status st = PX_STATUS_OK;
  if (d->nbs == sizeof(double)) {
    st = px_buffer_write(d->p[P_NB_GX], 0, 2 * n * sizeof(double), g);
    if (st == PX_STATUS_OK) st = px_buffer_write(d->p[P_NB_GY], 0, 2 * n * sizeof(double), g + 2 * n);
  } else {
    float *f = (float *)g; /* in place: floats are narrower */
    for (size_t i = 0; i < 4 * n; ++i) f[i] = (float)g[i];
    st = px_buffer_write(d->p[P_NB_GX], 0, 2 * n * sizeof(float), f);
    if (st == PX_STATUS_OK) st = px_buffer_write(d->p[P_NB_GY], 0, 2 * n * sizeof(float), f + 2 * n);
  }
  px_mem_free(ctx, g);
  PX_TRY(st);
  /* the inverse of the generation matrix (from the LU factors) */
  double *inv = px_mem_alloc(ctx, "vortex.ocl", ns * ns * sizeof(double));
  if (!inv) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for the inverse matrix");
  memcpy(inv, p->lu, ns * ns * sizeof(double));
  lapack_int info = LAPACKE_dgetri(LAPACK_COL_MAJOR, (lapack_int)ns, inv, (lapack_int)ns, p->ipiv);
  if (info != 0) {
    px_mem_free(ctx, inv);
    return px_context_fail(ctx, PX_STATUS_NUMERIC, "inverting the panel matrix failed (dgetri %d)",
                           (int)info);
  }
  /* column-major inverse = row-major transpose: transpose to row-major rows */
  for (size_t i = 0; i < ns; ++i)
    for (size_t j = i + 1; j < ns; ++j) {
      double t = inv[i * ns + j];
      inv[i * ns + j] = inv[j * ns + i];
      inv[j * ns + i] = t;
    }
  st = put_reals(e, d->p[P_AINV], inv, ns * ns);
  px_mem_free(ctx, inv);
  PX_TRY(st);
  PX_TRY(px_buffer_zero(d->p[P_THROUGH]));
  PX_TRY(px_buffer_zero(d->p[P_ZERO]));
  d->host_dirty = 1;
  return reserve(e, 1024);
}

/* Upload the host wake (after px_vortex_engine_add or a checkpoint load). */
static enum px_status upload(struct px_vortex_engine *e) {
  struct px_vortex_ocl *d = e->dev;
  struct px_vortex_wake *w = &e->w;
  PX_TRY(reserve(e, w->n + e->pan.n * 64));
  PX_TRY(put_reals(e, d->w[W_X], w->x, w->n));
  PX_TRY(put_reals(e, d->w[W_Y], w->y, w->n));
  PX_TRY(put_reals(e, d->w[W_G], w->g, w->n));
  PX_TRY(put_reals(e, d->w[W_U], w->u, w->n));
  PX_TRY(put_reals(e, d->w[W_V], w->v, w->n));
  PX_TRY(put_reals(e, d->w[W_E], w->e, w->n));
  if (e->pan.n) PX_TRY(put_reals(e, d->p[P_THROUGH], e->through, e->pan.n));
  d->host_dirty = 0;
  return PX_STATUS_OK;
}

void px_vortex_ocl_mark_dirty(struct px_vortex_engine *e) {
  if (e->dev) e->dev->host_dirty = 1;
}

enum px_status px_vortex_ocl_sync(struct px_vortex_engine *e) {
  struct px_vortex_ocl *d = e->dev;
  struct px_vortex_wake *w = &e->w;
  if (d->host_dirty) return PX_STATUS_OK; /* the host holds the newest state */
  PX_TRY(px_vortex_wake_reserve(e->ctx, w, w->n));
  PX_TRY(get_reals(e, d->w[W_X], w->x, w->n));
  PX_TRY(get_reals(e, d->w[W_Y], w->y, w->n));
  PX_TRY(get_reals(e, d->w[W_G], w->g, w->n));
  PX_TRY(get_reals(e, d->w[W_U], w->u, w->n));
  PX_TRY(get_reals(e, d->w[W_V], w->v, w->n));
  PX_TRY(get_reals(e, d->w[W_E], w->e, w->n));
  for (size_t i = 0; i < w->n; ++i) {
    w->wu[i] = w->wv[i] = 0.0;
    w->born[i] = -1;
  }
  if (e->pan.n) {
    PX_TRY(get_reals(e, d->p[P_SOL], e->sol, e->pan.nsys));
    PX_TRY(get_reals(e, d->p[P_THROUGH], e->through, e->pan.n));
    PX_TRY(get_reals(e, d->p[P_OMEGA], e->omega, e->pan.n));
  }
  return PX_STATUS_OK;
}

static void swap_sets(struct px_vortex_ocl *d) {
  for (int q = 0; q < 6; ++q) {
    struct px_buffer *t = d->w[W_X + q];
    d->w[W_X + q] = d->w[W_X2 + q];
    d->w[W_X2 + q] = t;
  }
}

/* Keep the vortices flagged in W_KEEP: scan, compact into set B, swap. */
static enum px_status compact(struct px_vortex_engine *e, size_t nw, size_t *out) {
  struct px_vortex_ocl *d = e->dev;
  uint32_t total = 0;
  PX_TRY(px_opencl_scan_u32(d->be, d->w[W_KEEP], d->w[W_POS], nw, &total));
  cl_kernel k;
  PX_TRY(kernel(d, "vx_compact", &k));
  PX_TRY(arg_u(d, k, 0, nw));
  PX_TRY(arg_b(d, k, 1, d->w[W_KEEP]));
  PX_TRY(arg_b(d, k, 2, d->w[W_POS]));
  for (int q = 0; q < 6; ++q) PX_TRY(arg_b(d, k, (cl_uint)(3 + q), d->w[W_X + q]));
  for (int q = 0; q < 6; ++q) PX_TRY(arg_b(d, k, (cl_uint)(9 + q), d->w[W_X2 + q]));
  PX_TRY(px_opencl_launch(d->be, k, nw, 0));
  swap_sets(d);
  *out = total;
  return PX_STATUS_OK;
}

/* Block 1: the sheet for the wake's nw vortices, shed as newborn vortices
 * after them (their number into *nborn). absorbed: the circulation each panel
 * absorbed in the last step, which the sheet returns (P_ZERO: none). */
static enum px_status ocl_generation(struct px_vortex_engine *e, double vx, double vy,
                                     struct px_buffer *absorbed, size_t nw, size_t *nborn_out) {
  struct px_vortex_ocl *d = e->dev;
  struct px_context *ctx = e->ctx;
  const struct px_vortex_panels *p = &e->pan;
  const struct px_vortex_config *c = &e->cfg;
  struct px_backend *be = d->be;
  size_t n = p->n, nborn = 0;
  cl_kernel k;
  if (n > 0) {
    if (nw > 0) {
      PX_TRY(kernel(d, "vx_to_nb", &k));
      PX_TRY(arg_u(d, k, 0, nw));
      PX_TRY(arg_b(d, k, 1, d->w[W_X]));
      PX_TRY(arg_b(d, k, 2, d->w[W_Y]));
      PX_TRY(arg_b(d, k, 3, d->w[W_G]));
      PX_TRY(arg_r(d, k, 4, e->center[0]));
      PX_TRY(arg_r(d, k, 5, e->center[1]));
      PX_TRY(arg_b(d, k, 6, d->w[W_NB_X]));
      PX_TRY(arg_b(d, k, 7, d->w[W_NB_Y]));
      PX_TRY(arg_b(d, k, 8, d->w[W_NB_G]));
      PX_TRY(px_opencl_launch(be, k, nw, 0));
      PX_TRY(px_nbody_direct(be, e->nb_prec, nw, d->w[W_NB_X], d->w[W_NB_Y], d->w[W_NB_G], 2 * n,
                             d->p[P_NB_GX], d->p[P_NB_GY], c->eps, PX_NBODY_MODE_SET,
                             d->p[P_NB_GU], d->p[P_NB_GV]));
    } else {
      PX_TRY(px_buffer_zero(d->p[P_NB_GU]));
      PX_TRY(px_buffer_zero(d->p[P_NB_GV]));
    }
    PX_TRY(kernel(d, "vx_rhs", &k));
    cl_uint a = 0;
    PX_TRY(arg_u(d, k, a++, n));
    PX_TRY(arg_u(d, k, a++, p->nbody));
    PX_TRY(arg_b(d, k, a++, d->p[P_FIRST]));
    for (int q = P_X0; q <= P_LEN; ++q) PX_TRY(arg_b(d, k, a++, d->p[q]));
    PX_TRY(arg_b(d, k, a++, d->p[P_NB_GU]));
    PX_TRY(arg_b(d, k, a++, d->p[P_NB_GV]));
    PX_TRY(arg_u(d, k, a++, nw));
    PX_TRY(arg_b(d, k, a++, d->w[W_X]));
    PX_TRY(arg_b(d, k, a++, d->w[W_Y]));
    PX_TRY(arg_b(d, k, a++, d->w[W_G]));
    PX_TRY(arg_r(d, k, a++, c->eps));
    PX_TRY(arg_r(d, k, a++, vx));
    PX_TRY(arg_r(d, k, a++, vy));
    PX_TRY(arg_r(d, k, a++, 0.21132486540518711775));
    PX_TRY(arg_b(d, k, a++, absorbed));
    PX_TRY(arg_b(d, k, a++, d->p[P_RHS]));
    PX_TRY(px_opencl_launch(be, k, p->nsys, 0));
    PX_TRY(kernel(d, "vx_solve", &k));
    PX_TRY(arg_u(d, k, 0, p->nsys));
    PX_TRY(arg_b(d, k, 1, d->p[P_AINV]));
    PX_TRY(arg_b(d, k, 2, d->p[P_RHS]));
    PX_TRY(arg_b(d, k, 3, d->p[P_SOL]));
    PX_TRY(px_opencl_launch(be, k, p->nsys, 0));
    PX_TRY(px_buffer_zero(d->p[P_FLAG]));
    PX_TRY(kernel(d, "vx_shed_count", &k));
    PX_TRY(arg_u(d, k, 0, n));
    PX_TRY(arg_b(d, k, 1, d->p[P_SOL]));
    PX_TRY(arg_b(d, k, 2, d->p[P_LEN]));
    PX_TRY(arg_r(d, k, 3, c->gamma_max));
    PX_TRY(arg_u(d, k, 4, (size_t)c->vortex_per_panel));
    PX_TRY(arg_r(d, k, 5, 1e3 * c->vref));
    PX_TRY(arg_b(d, k, 6, d->p[P_COUNT]));
    PX_TRY(arg_b(d, k, 7, d->p[P_FLAG]));
    PX_TRY(px_opencl_launch(be, k, n, 0));
    cl_uint bad = 0;
    PX_TRY(px_buffer_read(d->p[P_FLAG], 0, sizeof bad, &bad));
    if (bad) {
      double gk = 0.0;
      PX_TRY(get_reals(e, d->p[P_SOL], e->sol, p->nsys));
      gk = e->sol[bad - 1];
      return px_context_fail(ctx, PX_STATUS_NUMERIC,
                             "step %ld: runaway vorticity generation: sheet intensity %g on panel "
                             "%u (more than 1000 v_ref, or not finite); the wake is unstable: "
                             "reduce dt or check eps, eps_col and gamma_max",
                             e->step, gk, bad - 1);
    }
    uint32_t total = 0;
    PX_TRY(px_opencl_scan_u32(be, d->p[P_COUNT], d->p[P_START], n, &total));
    nborn = total;
    PX_TRY(reserve(e, nw + nborn));
    PX_TRY(kernel(d, "vx_shed", &k));
    a = 0;
    PX_TRY(arg_u(d, k, a++, n));
    PX_TRY(arg_u(d, k, a++, nw));
    PX_TRY(arg_b(d, k, a++, d->p[P_START]));
    PX_TRY(arg_b(d, k, a++, d->p[P_COUNT]));
    PX_TRY(arg_b(d, k, a++, d->p[P_SOL]));
    for (int q = P_X0; q <= P_LEN; ++q) PX_TRY(arg_b(d, k, a++, d->p[q]));
    PX_TRY(arg_r(d, k, a++, c->delta));
    PX_TRY(arg_b(d, k, a++, d->w[W_X]));
    PX_TRY(arg_b(d, k, a++, d->w[W_Y]));
    PX_TRY(arg_b(d, k, a++, d->w[W_G]));
    PX_TRY(arg_b(d, k, a++, d->w[W_BORN]));
    PX_TRY(px_opencl_launch(be, k, n, 0));
  }
  *nborn_out = nborn;
  return PX_STATUS_OK;
}

/* Block 2: convective velocities of the nw vortices, the last nborn of them
 * newborn (the first nold old). */
static enum px_status ocl_convective(struct px_vortex_engine *e, double vx, double vy, size_t nw,
                                     size_t nold, size_t nborn) {
  struct px_vortex_ocl *d = e->dev;
  const struct px_vortex_panels *p = &e->pan;
  const struct px_vortex_config *c = &e->cfg;
  struct px_backend *be = d->be;
  size_t n = p->n;
  cl_kernel k;
  if (nw > 0) {
    PX_TRY(kernel(d, "vx_to_nb", &k));
    PX_TRY(arg_u(d, k, 0, nw));
    PX_TRY(arg_b(d, k, 1, d->w[W_X]));
    PX_TRY(arg_b(d, k, 2, d->w[W_Y]));
    PX_TRY(arg_b(d, k, 3, d->w[W_G]));
    PX_TRY(arg_r(d, k, 4, e->center[0]));
    PX_TRY(arg_r(d, k, 5, e->center[1]));
    PX_TRY(arg_b(d, k, 6, d->w[W_NB_X]));
    PX_TRY(arg_b(d, k, 7, d->w[W_NB_Y]));
    PX_TRY(arg_b(d, k, 8, d->w[W_NB_G]));
    PX_TRY(px_opencl_launch(be, k, nw, 0));
    PX_TRY(px_nbody_direct(be, e->nb_prec, nw, d->w[W_NB_X], d->w[W_NB_Y], d->w[W_NB_G], nold,
                           d->w[W_NB_X], d->w[W_NB_Y], c->eps, PX_NBODY_MODE_SET, d->w[W_NB_U],
                           d->w[W_NB_V]));
    PX_TRY(kernel(d, "vx_convective", &k));
    cl_uint a = 0;
    PX_TRY(arg_u(d, k, a++, nw));
    PX_TRY(arg_u(d, k, a++, nold));
    PX_TRY(arg_b(d, k, a++, d->w[W_NB_U]));
    PX_TRY(arg_b(d, k, a++, d->w[W_NB_V]));
    PX_TRY(arg_b(d, k, a++, d->w[W_X]));
    PX_TRY(arg_b(d, k, a++, d->w[W_Y]));
    PX_TRY(arg_b(d, k, a++, d->w[W_G]));
    PX_TRY(arg_b(d, k, a++, d->w[W_BORN]));
    PX_TRY(arg_r(d, k, a++, vx));
    PX_TRY(arg_r(d, k, a++, vy));
    PX_TRY(arg_u(d, k, a++, n));
    for (int q = P_X0; q <= P_LEN; ++q) PX_TRY(arg_b(d, k, a++, d->p[q]));
    PX_TRY(arg_b(d, k, a++, d->p[P_SOL]));
    PX_TRY(arg_b(d, k, a++, d->p[P_START]));
    PX_TRY(arg_b(d, k, a++, d->p[P_COUNT]));
    PX_TRY(arg_r(d, k, a++, c->eps));
    PX_TRY(arg_i(d, k, a++, (c->sheet_exact && n > 0 && nborn > 0) ? 1 : 0));
    PX_TRY(arg_b(d, k, a++, d->w[W_U]));
    PX_TRY(arg_b(d, k, a++, d->w[W_V]));
    PX_TRY(px_opencl_launch(be, k, nw, 0));
  }
  return PX_STATUS_OK;
}

/* Block 3: eps* and the VVD diffusive velocities of the nw vortices (those
 * from nold on are the step's newborns). */
static enum px_status ocl_diffusive(struct px_vortex_engine *e, size_t nw, size_t nold) {
  struct px_vortex_ocl *d = e->dev;
  const struct px_vortex_panels *p = &e->pan;
  const struct px_vortex_config *c = &e->cfg;
  struct px_backend *be = d->be;
  size_t n = p->n;
  cl_kernel k;
  PX_TRY(kernel(d, "vx_eps", &k));
  PX_TRY(arg_u(d, k, 0, nw));
  PX_TRY(arg_b(d, k, 1, d->w[W_X]));
  PX_TRY(arg_b(d, k, 2, d->w[W_Y]));
  PX_TRY(arg_r(d, k, 3, c->eps_min));
  PX_TRY(arg_b(d, k, 4, d->w[W_E]));
  PX_TRY(px_opencl_launch(be, k, nw, 0));
  PX_TRY(kernel(d, "vx_vvd", &k));
  cl_uint a = 0;
  PX_TRY(arg_u(d, k, a++, nw));
  static const int wv[] = {W_X, W_Y, W_G, W_E};
  PX_TRY(arg_list(d, k, &a, d->w, wv, 4));
  PX_TRY(arg_i(d, k, a++, c->self_in_i1));
  PX_TRY(arg_u(d, k, a++, n));
  PX_TRY(arg_list(d, k, &a, d->p, panel_frame, 5));
  PX_TRY(arg_r(d, k, a++, p->lmax));
  PX_TRY(arg_r(d, k, a++, c->cutoff));
  PX_TRY(arg_r(d, k, a++, c->nu));
  PX_TRY(arg_r(d, k, a++, 1.5 * c->vref));
  PX_TRY(arg_b(d, k, a++, d->w[W_BORN]));
  PX_TRY(arg_u(d, k, a++, nold));
  PX_TRY(arg_r(d, k, a++, n > 0 ? px_vortex_newborn_drift(c) : 0.0));
  PX_TRY(arg_i(d, k, a++, c->vvd_moments));
  PX_TRY(arg_b(d, k, a++, d->w[W_WU]));
  PX_TRY(arg_b(d, k, a++, d->w[W_WV]));
  PX_TRY(px_opencl_launch(be, k, nw, 0));
  return PX_STATUS_OK;
}

/* Block 5 with rk2 (vortex_core.c, heun): the step's positions and
 * velocities into the second wake set (free until the compaction; its
 * circulation and eps* arrays hold the diffusive velocities), the predictor
 * move, a second sheet shed after the nw vortices, the convective and
 * diffusive velocities of the predicted wake with it, then the mean
 * velocities at the step's positions; the first stage's sheet is restored.
 * nold: the first of the step's newborns. The second diffusive pass counts
 * in the diffusive block; the rest of the stage in the caller's (move and
 * non-penetration, block_time[PX_VORTEX_BLOCK_INSIDE]). */
static enum px_status ocl_heun(struct px_vortex_engine *e, size_t nw, size_t nold) {
  struct px_vortex_ocl *d = e->dev;
  const struct px_vortex_config *c = &e->cfg;
  struct px_backend *be = d->be;
  cl_kernel k;
  PX_TRY(kernel(d, "vx_rk2_predict", &k));
  /* the step's positions, velocities and diffusive velocities; their copies
   * in the second set (x1, y1, u1, v1; W1 in its circulation and eps* arrays) */
  static const int wv[] = {W_X, W_Y, W_U, W_V, W_WU, W_WV};
  static const int stage1[] = {W_X2, W_Y2, W_U2, W_V2}, stage1_w[] = {W_G2, W_E2};
  cl_uint a = 0;
  PX_TRY(arg_u(d, k, a++, nw));
  PX_TRY(arg_list(d, k, &a, d->w, wv, 6));
  PX_TRY(arg_r(d, k, a++, c->dt));
  PX_TRY(arg_list(d, k, &a, d->w, stage1, 4));
  PX_TRY(arg_u(d, k, a++, e->pan.n));
  PX_TRY(arg_list(d, k, &a, d->p, panel_ends, 4));
  PX_TRY(arg_u(d, k, a++, e->pan.nbody));
  PX_TRY(arg_b(d, k, a++, d->p[P_BBOX]));
  PX_TRY(arg_list(d, k, &a, d->w, stage1_w, 2));
  PX_TRY(px_opencl_launch(be, k, nw, 0));
  PX_TRY(px_buffer_copy(d->p[P_SOL1], 0, d->p[P_SOL], 0, px_buffer_bytes(d->p[P_SOL])));
  double vx, vy;
  px_vortex_vinf(c, e->time + c->dt, &vx, &vy);
  size_t nb2 = 0;
  PX_TRY(ocl_generation(e, vx, vy, d->p[P_ZERO], nw, &nb2));
  PX_TRY(ocl_convective(e, vx, vy, nw + nb2, nw, nb2));
  { /* W2: timed in the diffusive block (as on the cpu), not in the caller's */
    PX_TRY(px_backend_finish(be));
    double t0 = px_time_now();
    PX_TRY(ocl_diffusive(e, nw + nb2, nold));
    PX_TRY(px_backend_finish(be));
    double t = px_time_now() - t0;
    e->block_time[PX_VORTEX_BLOCK_DIFFUSIVE] += t;
    e->block_time[PX_VORTEX_BLOCK_INSIDE] -= t;
  }
  PX_TRY(kernel(d, "vx_rk2_correct", &k));
  a = 0;
  PX_TRY(arg_u(d, k, a++, nw));
  PX_TRY(arg_list(d, k, &a, d->w, wv, 4));
  PX_TRY(arg_list(d, k, &a, d->w, stage1, 4));
  PX_TRY(arg_list(d, k, &a, d->w, wv + 4, 2));
  PX_TRY(arg_list(d, k, &a, d->w, stage1_w, 2));
  PX_TRY(px_opencl_launch(be, k, nw, 0));
  return px_buffer_copy(d->p[P_SOL], 0, d->p[P_SOL1], 0, px_buffer_bytes(d->p[P_SOL]));
}

enum px_status px_vortex_ocl_step(struct px_vortex_engine *e, double vx, double vy) {
  struct px_vortex_ocl *d = e->dev;
  struct px_context *ctx = e->ctx;
  const struct px_vortex_panels *p = &e->pan;
  const struct px_vortex_config *c = &e->cfg;
  struct px_backend *be = d->be;
  size_t n = p->n, nw = e->w.n;
  cl_kernel k;
  double t0;
  if (d->host_dirty) PX_TRY(upload(e));
  PX_TRY(reserve(e, nw + 64 * n + 1));

  /* 1. generation */
  t0 = px_time_now();
  size_t nborn = 0;
  PX_TRY(ocl_generation(e, vx, vy, d->p[P_THROUGH], nw, &nborn));
  size_t nold = nw;
  nw += nborn;
  e->n_born = nborn;
  PX_TRY(px_backend_finish(be));
  e->block_time[PX_VORTEX_BLOCK_GENERATION] += px_time_now() - t0;

  /* 2. convective */
  t0 = px_time_now();
  PX_TRY(ocl_convective(e, vx, vy, nw, nold, nborn));
  PX_TRY(px_backend_finish(be));
  e->block_time[PX_VORTEX_BLOCK_CONVECTIVE] += px_time_now() - t0;

  /* 3. diffusive */
  t0 = px_time_now();
  if (nw > 0) PX_TRY(ocl_diffusive(e, nw, nold));
  PX_TRY(px_backend_finish(be));
  e->block_time[PX_VORTEX_BLOCK_DIFFUSIVE] += px_time_now() - t0;

  /* 4. loads */
  t0 = px_time_now();
  if (n > 0) {
    PX_TRY(kernel(d, "vx_wall", &k));
    cl_uint a = 0;
    PX_TRY(arg_u(d, k, a++, n));
    PX_TRY(arg_b(d, k, a++, d->p[P_START]));
    PX_TRY(arg_b(d, k, a++, d->p[P_COUNT]));
    PX_TRY(arg_u(d, k, a++, nold));
    PX_TRY(arg_b(d, k, a++, d->w[W_E]));
    PX_TRY(arg_r(d, k, a++, c->eps_min));
    PX_TRY(arg_list(d, k, &a, d->p, panel_frame, 5));
    PX_TRY(arg_u(d, k, a++, nw));
    PX_TRY(arg_b(d, k, a++, d->w[W_X]));
    PX_TRY(arg_b(d, k, a++, d->w[W_Y]));
    PX_TRY(arg_b(d, k, a++, d->w[W_G]));
    PX_TRY(arg_r(d, k, a++, c->cutoff));
    PX_TRY(arg_b(d, k, a++, d->p[P_PE]));
    PX_TRY(arg_b(d, k, a++, d->p[P_OMEGA]));
    PX_TRY(px_opencl_launch(be, k, n, 0));
    PX_TRY(kernel(d, "vx_loads", &k));
    a = 0;
    PX_TRY(arg_u(d, k, a++, p->nbody));
    PX_TRY(arg_b(d, k, a++, d->p[P_FIRST]));
    PX_TRY(arg_list(d, k, &a, d->p, panel_frame, 5));
    PX_TRY(arg_b(d, k, a++, d->p[P_SOL]));
    PX_TRY(arg_b(d, k, a++, d->p[P_THROUGH]));
    PX_TRY(arg_b(d, k, a++, d->p[P_OMEGA]));
    PX_TRY(arg_b(d, k, a++, d->p[P_CENTER]));
    PX_TRY(arg_r(d, k, a++, c->rho));
    PX_TRY(arg_r(d, k, a++, c->nu));
    PX_TRY(arg_u(d, k, a++, nw));
    PX_TRY(arg_b(d, k, a++, d->w[W_X]));
    PX_TRY(arg_b(d, k, a++, d->w[W_Y]));
    PX_TRY(arg_b(d, k, a++, d->w[W_G]));
    PX_TRY(arg_b(d, k, a++, d->w[W_WU]));
    PX_TRY(arg_b(d, k, a++, d->w[W_WV]));
    PX_TRY(arg_b(d, k, a++, d->p[P_OUT]));
    PX_TRY(px_opencl_launch(be, k, p->nbody, 0));
    double out[10 * PX_VORTEX_MAX_BODIES];
    PX_TRY(get_reals(e, d->p[P_OUT], out, 10 * p->nbody));
    double q = 0.5 * c->rho * c->vref * c->vref;
    for (size_t b = 0; b < p->nbody; ++b) {
      struct px_vortex_loads *L = &e->loads[b];
      double *o = out + 10 * b;
      L->fx_conv = L->fy_conv = 0.0; /* not computed on the device */
      L->fx_diff = o[7];
      L->fy_diff = o[8];
      L->fx_wall = o[3];
      L->fy_wall = o[4];
      if (!c->friction_wall) { /* the drift term is the friction (vortex_core.c, loads) */
        o[3] = o[7];
        o[4] = o[8];
        o[5] = o[9];
      }
      L->fx_fric = o[3];
      L->fy_fric = o[4];
      L->m_fric = o[5];
      L->fx = c->rho / c->dt * o[0] + o[3];
      L->fy = c->rho / c->dt * o[1] + o[4];
      L->m = c->rho / c->dt * o[2] + o[5];
      L->cx = L->fx / (q * c->ref_length[b]);
      L->cy = L->fy / (q * c->ref_length[b]);
      L->cm = L->m / (q * c->ref_length[b] * c->ref_length[b]);
      L->absorbed = o[6];
    }
  }
  e->block_time[PX_VORTEX_BLOCK_LOADS] += px_time_now() - t0;

  /* 5, 6. move and non-penetration */
  t0 = px_time_now();
  if (c->rk2 && nw > 0) PX_TRY(ocl_heun(e, nw, nold));
  if (nw > 0) {
    PX_TRY(kernel(d, "vx_move", &k));
    cl_uint a = 0;
    PX_TRY(arg_u(d, k, a++, nw));
    static const int wv[] = {W_X, W_Y, W_U, W_V, W_WU, W_WV};
    PX_TRY(arg_list(d, k, &a, d->w, wv, 6));
    PX_TRY(arg_r(d, k, a++, c->dt));
    PX_TRY(arg_u(d, k, a++, n));
    PX_TRY(arg_list(d, k, &a, d->p, panel_ends, 4));
    PX_TRY(arg_u(d, k, a++, p->nbody));
    PX_TRY(arg_b(d, k, a++, d->p[P_BBOX]));
    PX_TRY(arg_b(d, k, a++, d->w[W_XN]));
    PX_TRY(arg_b(d, k, a++, d->w[W_YN]));
    PX_TRY(arg_b(d, k, a++, d->w[W_HIT]));
    PX_TRY(px_opencl_launch(be, k, nw, 0));
    if (n > 0) {
      PX_TRY(kernel(d, "vx_through", &k));
      PX_TRY(arg_u(d, k, 0, n));
      PX_TRY(arg_u(d, k, 1, nw));
      PX_TRY(arg_b(d, k, 2, d->w[W_HIT]));
      PX_TRY(arg_b(d, k, 3, d->w[W_G]));
      PX_TRY(arg_b(d, k, 4, d->p[P_THROUGH]));
      PX_TRY(px_opencl_launch(be, k, n, 0));
    }
  }
  PX_TRY(px_backend_finish(be));
  e->block_time[PX_VORTEX_BLOCK_INSIDE] += px_time_now() - t0;

  /* 7. restructuring: drop, then merge */
  t0 = px_time_now();
  size_t m = 0;
  if (nw > 0) {
    PX_TRY(kernel(d, "vx_keep", &k));
    PX_TRY(arg_u(d, k, 0, nw));
    PX_TRY(arg_b(d, k, 1, d->w[W_HIT]));
    PX_TRY(arg_b(d, k, 2, d->w[W_G]));
    PX_TRY(arg_b(d, k, 3, d->w[W_XN]));
    PX_TRY(arg_b(d, k, 4, d->w[W_YN]));
    PX_TRY(arg_r(d, k, 5, e->center[0]));
    PX_TRY(arg_r(d, k, 6, e->center[1]));
    PX_TRY(arg_r(d, k, 7, c->dist_far * c->dist_far));
    PX_TRY(arg_b(d, k, 8, d->w[W_KEEP]));
    PX_TRY(px_opencl_launch(be, k, nw, 0));
    /* the moved positions become the positions of the compacted set */
    struct px_buffer *t;
    t = d->w[W_X];
    d->w[W_X] = d->w[W_XN];
    d->w[W_XN] = t;
    t = d->w[W_Y];
    d->w[W_Y] = d->w[W_YN];
    d->w[W_YN] = t;
    PX_TRY(compact(e, nw, &m));
    e->n_far = nw - m; /* absorbed ones included */
    if (m > 0) {
      PX_TRY(kernel(d, "vx_partner", &k));
      cl_uint a = 0;
      PX_TRY(arg_u(d, k, a++, m));
      PX_TRY(arg_b(d, k, a++, d->w[W_X]));
      PX_TRY(arg_b(d, k, a++, d->w[W_Y]));
      PX_TRY(arg_b(d, k, a++, d->w[W_G]));
      PX_TRY(arg_r(d, k, a++, c->eps_col));
      PX_TRY(arg_r(d, k, a++, c->eps_col_opposite));
      PX_TRY(arg_r(d, k, a++, c->gamma_max));
      PX_TRY(arg_r(d, k, a++, e->stream_dir[0]));
      PX_TRY(arg_r(d, k, a++, e->stream_dir[1]));
      PX_TRY(arg_r(d, k, a++, e->s_right));
      PX_TRY(arg_r(d, k, a++, e->span > 0.0 ? e->span : 1.0));
      PX_TRY(arg_u(d, k, a++, n));
      PX_TRY(arg_list(d, k, &a, d->p, panel_ends, 4));
      PX_TRY(arg_u(d, k, a++, p->nbody));
      PX_TRY(arg_b(d, k, a++, d->p[P_BBOX]));
      PX_TRY(arg_b(d, k, a++, d->w[W_PARTNER]));
      PX_TRY(arg_b(d, k, a++, d->w[W_MX]));
      PX_TRY(arg_b(d, k, a++, d->w[W_MY]));
      PX_TRY(px_opencl_launch(be, k, m, 0));
      PX_TRY(kernel(d, "vx_merge", &k));
      PX_TRY(arg_u(d, k, 0, m));
      PX_TRY(arg_b(d, k, 1, d->w[W_PARTNER]));
      PX_TRY(arg_b(d, k, 2, d->w[W_MX]));
      PX_TRY(arg_b(d, k, 3, d->w[W_MY]));
      PX_TRY(arg_b(d, k, 4, d->w[W_X]));
      PX_TRY(arg_b(d, k, 5, d->w[W_Y]));
      PX_TRY(arg_b(d, k, 6, d->w[W_G]));
      PX_TRY(arg_b(d, k, 7, d->w[W_KEEP]));
      PX_TRY(arg_b(d, k, 8, d->p[P_FLAG]));
      PX_TRY(px_opencl_launch(be, k, 1, 1));
      size_t m2 = 0;
      PX_TRY(compact(e, m, &m2));
      e->n_merged = m - m2;
      m = m2;
    }
    /* non-finite check of the new state */
    PX_TRY(px_buffer_zero(d->p[P_FLAG]));
    if (m > 0) {
      PX_TRY(kernel(d, "vx_finite", &k));
      PX_TRY(arg_u(d, k, 0, m));
      PX_TRY(arg_b(d, k, 1, d->w[W_X]));
      PX_TRY(arg_b(d, k, 2, d->w[W_Y]));
      PX_TRY(arg_b(d, k, 3, d->p[P_FLAG]));
      PX_TRY(px_opencl_launch(be, k, m, 0));
      cl_uint bad = 0;
      PX_TRY(px_buffer_read(d->p[P_FLAG], 0, sizeof bad, &bad));
      if (bad)
        return px_context_fail(ctx, PX_STATUS_NUMERIC,
                               "step %ld: vortex %u has a non-finite position after the move "
                               "(non-finite convective or diffusive velocity)",
                               e->step, bad - 1);
    }
  }
  e->w.n = m;
  e->block_time[PX_VORTEX_BLOCK_RESTRUCT] += px_time_now() - t0;
  return PX_STATUS_OK;
}

#endif
