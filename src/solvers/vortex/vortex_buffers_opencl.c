/* The opencl vortex engine's buffers (vortex_ocl_state.h): created with the
 * program, panels and the inverse generation matrix (px_vortex_panels_factor's, on the
 * host), grown with the wake, and the wake's transfers between host doubles
 * and device reals. */
#include <math.h>
#include <string.h>

#include "partix/memory.h"
#include "solvers/vortex/vortex_ocl_state.h"
#include "solvers/vortex/vortex_ranks.h"

extern const char px_cl_source_vortex[];

/* Host doubles <-> device reals. */
enum px_status px_vortex_ocl_put_reals(struct px_vortex_engine *e, struct px_buffer *b,
                                       const double *src, size_t n) {
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
enum px_status px_vortex_ocl_get_reals(struct px_vortex_engine *e, struct px_buffer *b, double *dst,
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
enum px_status px_vortex_ocl_reserve(struct px_vortex_engine *e, size_t n) {
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

void px_vortex_ocl_destroy(struct px_vortex_engine *e) {
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
                                d->nbs == sizeof(double) ? "-DVX_NB_REAL=double" VX_OCL_SIZES
                                                         : "-DVX_NB_REAL=float" VX_OCL_SIZES,
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
  if (n == 0) return px_vortex_ocl_reserve(e, 1024);
  PX_TRY(px_vortex_ocl_put_reals(e, d->p[P_X0], p->x0, n));
  PX_TRY(px_vortex_ocl_put_reals(e, d->p[P_Y0], p->y0, n));
  PX_TRY(px_vortex_ocl_put_reals(e, d->p[P_X1], p->x1, n));
  PX_TRY(px_vortex_ocl_put_reals(e, d->p[P_Y1], p->y1, n));
  PX_TRY(px_vortex_ocl_put_reals(e, d->p[P_TX], p->tx, n));
  PX_TRY(px_vortex_ocl_put_reals(e, d->p[P_TY], p->ty, n));
  PX_TRY(px_vortex_ocl_put_reals(e, d->p[P_LEN], p->len, n));
  cl_uint first[PX_VORTEX_MAX_BODIES + 1];
  for (size_t b = 0; b <= p->nbody; ++b) first[b] = (cl_uint)p->first[b];
  PX_TRY(px_buffer_write(d->p[P_FIRST], 0, (p->nbody + 1) * sizeof(cl_uint), first));
  double tmp[4 * PX_VORTEX_MAX_BODIES];
  for (size_t b = 0; b < p->nbody; ++b) {
    tmp[2 * b] = e->cfg.moment_center[b][0];
    tmp[2 * b + 1] = e->cfg.moment_center[b][1];
  }
  PX_TRY(px_vortex_ocl_put_reals(e, d->p[P_CENTER], tmp, 2 * p->nbody));
  for (size_t b = 0; b < p->nbody; ++b) {
    tmp[4 * b] = p->bxmin[b];
    tmp[4 * b + 1] = p->bymin[b];
    tmp[4 * b + 2] = p->bxmax[b];
    tmp[4 * b + 3] = p->bymax[b];
  }
  PX_TRY(px_vortex_ocl_put_reals(e, d->p[P_BBOX], tmp, 4 * p->nbody));
  /* Gauss points of the right-hand side's far field (as vortex_cpu.c) */
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
    if (st == PX_STATUS_OK)
      st = px_buffer_write(d->p[P_NB_GY], 0, 2 * n * sizeof(double), g + 2 * n);
  } else {
    float *f = (float *)g; /* in place: floats are narrower */
    for (size_t i = 0; i < 4 * n; ++i) f[i] = (float)g[i];
    st = px_buffer_write(d->p[P_NB_GX], 0, 2 * n * sizeof(float), f);
    if (st == PX_STATUS_OK)
      st = px_buffer_write(d->p[P_NB_GY], 0, 2 * n * sizeof(float), f + 2 * n);
  }
  px_mem_free(ctx, g);
  PX_TRY(st);
  /* the inverse of the generation matrix, row-major (px_vortex_panels_factor) */
  PX_TRY(px_vortex_ocl_put_reals(e, d->p[P_AINV], p->ainv, ns * ns));
  PX_TRY(px_buffer_zero(d->p[P_THROUGH]));
  PX_TRY(px_buffer_zero(d->p[P_ZERO]));
  d->host_dirty = 1;
  return px_vortex_ocl_reserve(e, 1024);
}

/* Upload the host wake (after px_vortex_engine_add or a checkpoint load). */
enum px_status px_vortex_ocl_upload(struct px_vortex_engine *e) {
  struct px_vortex_ocl *d = e->dev;
  struct px_vortex_wake *w = &e->w;
  PX_TRY(px_vortex_ocl_reserve(e, w->n + e->pan.n * 64));
  PX_TRY(px_vortex_ocl_put_reals(e, d->w[W_X], w->x, w->n));
  PX_TRY(px_vortex_ocl_put_reals(e, d->w[W_Y], w->y, w->n));
  PX_TRY(px_vortex_ocl_put_reals(e, d->w[W_G], w->g, w->n));
  PX_TRY(px_vortex_ocl_put_reals(e, d->w[W_U], w->u, w->n));
  PX_TRY(px_vortex_ocl_put_reals(e, d->w[W_V], w->v, w->n));
  PX_TRY(px_vortex_ocl_put_reals(e, d->w[W_E], w->e, w->n));
  if (e->pan.n) PX_TRY(px_vortex_ocl_put_reals(e, d->p[P_THROUGH], e->through, e->pan.n));
  d->host_dirty = 0;
  return PX_STATUS_OK;
}

void px_vortex_ocl_host_changed(struct px_vortex_engine *e) {
  struct px_vortex_ocl *d = e->dev;
  if (d) d->host_dirty = 1;
}

enum px_status px_vortex_ocl_sync(struct px_vortex_engine *e) {
  struct px_vortex_ocl *d = e->dev;
  struct px_vortex_wake *w = &e->w;
  if (d->host_dirty) return PX_STATUS_OK; /* the host holds the newest state */
  PX_TRY(px_vortex_wake_reserve(e->ctx, w, w->n));
  PX_TRY(px_vortex_ocl_get_reals(e, d->w[W_X], w->x, w->n));
  PX_TRY(px_vortex_ocl_get_reals(e, d->w[W_Y], w->y, w->n));
  PX_TRY(px_vortex_ocl_get_reals(e, d->w[W_G], w->g, w->n));
  PX_TRY(px_vortex_ocl_get_reals(e, d->w[W_U], w->u, w->n));
  PX_TRY(px_vortex_ocl_get_reals(e, d->w[W_V], w->v, w->n));
  PX_TRY(px_vortex_ocl_get_reals(e, d->w[W_E], w->e, w->n));
  for (size_t i = 0; i < w->n; ++i) {
    w->wu[i] = w->wv[i] = 0.0;
    w->born[i] = -1;
  }
  if (e->pan.n) {
    PX_TRY(px_vortex_ocl_get_reals(e, d->p[P_SOL], e->sol, e->pan.nsys));
    PX_TRY(px_vortex_ocl_get_reals(e, d->p[P_THROUGH], e->through, e->pan.n));
    PX_TRY(px_vortex_ocl_get_reals(e, d->p[P_OMEGA], e->omega, e->pan.n));
  }
  return PX_STATUS_OK;
}

enum px_status px_vortex_ocl_gather(struct px_vortex_engine *e, int sum, enum px_status st,
                                    size_t n, const int *which, size_t narr) {
  struct px_vortex_ocl *d = e->dev;
  if (px_vortex_ranks_count(e) < 2) return st;
  size_t lo, hi, rs = d->rs;
  px_vortex_ranks_share(e, n, &lo, &hi);
  size_t m = hi - lo;
  unsigned char *send = NULL;
  if (st == PX_STATUS_OK) {
    /* this rank's values, then room for every rank's */
    send = px_mem_alloc(e->ctx, "vortex.ocl", narr * (m + n) * rs + 1);
    if (!send) st = px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (gather)");
  }
  for (size_t a = 0; st == PX_STATUS_OK && a < narr && m > 0; ++a)
    st = px_buffer_read(d->w[which[a]], lo * rs, m * rs, send + a * m * rs);
  unsigned char *all = send ? send + narr * m * rs : NULL;
  st = px_vortex_ranks_gather_shares(e, sum, st, n, narr, rs, send, all);
  for (size_t a = 0; st == PX_STATUS_OK && a < narr && n > 0; ++a)
    st = px_buffer_write(d->w[which[a]], 0, n * rs, all + a * n * rs);
  px_mem_free(e->ctx, send);
  return st;
}
