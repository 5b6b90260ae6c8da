/* The granular system on the cpu backend: storage, rebuilds, time step,
 * events and statistics. The loops are in cpu_loops.h. */
#include "solvers/granular/system.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/checkpoint.h"
#include "partix/memory.h"
#include "partix/timer.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/wall_kernel.h"

#define PX_GRAN_PI 3.14159265358979323846
/* Events one thread can buffer within one step. */
#define PX_GRAN_EV_CAP_MIN 4096

/* ------------------------------------------------------------------ laws */

void px_gran_law_params(const struct px_gran_law_spec *spec, int cells,
                        double p[PX_GRAN_LAW_COUNT]) {
  double zeta = 0;
  memset(p, 0, PX_GRAN_LAW_COUNT * sizeof *p);
  p[PX_GRAN_LAW_KN] = spec->kn;
  p[PX_GRAN_LAW_NORMAL] = spec->normal;
  p[PX_GRAN_LAW_CLAMP] = spec->clamp;
  p[PX_GRAN_LAW_CELLS] = cells;
  if (spec->normal == PX_GRAN_NORMAL_HYSTERETIC) {
    p[PX_GRAN_LAW_K2] = spec->k2 > 0 ? spec->k2 : spec->kn / (spec->e * spec->e);
    p[PX_GRAN_LAW_PHIF] = spec->phif;
    zeta = spec->damping;
  } else if (spec->e < 1) {
    const double le = log(spec->e);
    zeta = -le / sqrt(PX_GRAN_PI * PX_GRAN_PI + le * le);
  }
  p[PX_GRAN_LAW_ZETA2] = 2 * zeta;
  p[PX_GRAN_LAW_CT] = spec->ct_ratio;
  p[PX_GRAN_LAW_KT] = spec->kt_ratio * spec->kn;
  p[PX_GRAN_LAW_MU] = spec->mu;
  p[PX_GRAN_LAW_MUR] = spec->mur;
  p[PX_GRAN_LAW_KR] = spec->kr;
  p[PX_GRAN_LAW_GT] = spec->gt;
  p[PX_GRAN_LAW_TANGENTIAL] = spec->mu > 0 ? spec->tangential : PX_GRAN_TANGENTIAL_NONE;
  if (spec->tangential == PX_GRAN_TANGENTIAL_SPRING && !(spec->kt_ratio > 0))
    p[PX_GRAN_LAW_TANGENTIAL] = PX_GRAN_TANGENTIAL_NONE;
}

/* ------------------------------------------------------------------ arrays */

/* A per-particle array: pointer, element size, elements per particle, and
 * whether it carries state across a rebuild (permuted) or is scratch. */
struct px_gran_arr {
  void **p;
  size_t esize, per;
  int keep;          /* carried across a rebuild (permuted) */
  const char *name;  /* checkpoint section, NULL: not saved (scratch) */
};

/* "s->slots.seg" -> "granular.p.slots.seg" (checkpoint section names),
 * "s->hist[k][d]" -> "granular.p.hist.N" */
static const char *px_gran_arr_name(char (*names)[48], size_t n, const char *expr) {
  const char *p = strncmp(expr, "s->", 3) == 0 ? expr + 3 : expr;
  size_t k = 0, o = 0;
  char *out = names[n];
  o = (size_t)snprintf(out, 48, "granular.p.");
  for (k = 0; p[k] && o < 47; ++k) {
    const char ch = p[k];
    if ((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
        ch == '.' || ch == '_')
      out[o++] = ch;
  }
  if (strchr(p, '[')) o += (size_t)snprintf(out + o, 48 - o, ".%zu", n);
  out[o < 48 ? o : 47] = '\0';
  return out;
}

static size_t px_gran_arrays(struct px_gran_sys *s, struct px_gran_arr *a) {
  size_t n = 0;
  char(*names)[48] = s->arr_names;
  const size_t ss = s->ssize, cs = s->csize, W = PX_GRAN_WSLOTS;
  int k, d;
#define PX_GRAN_ARR(ptr, es, pp, kp)                                                         \
  (a[n].p = (void **)&(ptr), a[n].esize = (es), a[n].per = (pp), a[n].keep = (kp),           \
   a[n].name = (kp) ? px_gran_arr_name(names, n, #ptr) : NULL, ++n)
  PX_GRAN_ARR(s->x, ss, 1, 1);
  PX_GRAN_ARR(s->y, ss, 1, 1);
  PX_GRAN_ARR(s->vx, ss, 1, 1);
  PX_GRAN_ARR(s->vy, ss, 1, 1);
  PX_GRAN_ARR(s->w, ss, 1, 1);
  PX_GRAN_ARR(s->fx, ss, 1, 1);
  PX_GRAN_ARR(s->fy, ss, 1, 1);
  PX_GRAN_ARR(s->tq, ss, 1, 1);
  PX_GRAN_ARR(s->ax0, ss, 1, 0);
  PX_GRAN_ARR(s->ay0, ss, 1, 0);
  PX_GRAN_ARR(s->aw0, ss, 1, 0);
  PX_GRAN_ARR(s->r, cs, 1, 1);
  PX_GRAN_ARR(s->m, cs, 1, 1);
  PX_GRAN_ARR(s->im, cs, 1, 1);
  PX_GRAN_ARR(s->iI, cs, 1, 1);
  PX_GRAN_ARR(s->xr, ss, 1, 0);
  a[n - 1].name = "granular.p.xr";
  PX_GRAN_ARR(s->yr, ss, 1, 0);
  a[n - 1].name = "granular.p.yr";
  PX_GRAN_ARR(s->fox, cs, 1, 0);
  PX_GRAN_ARR(s->foy, cs, 1, 0);
  PX_GRAN_ARR(s->fvx, cs, 1, 0);
  PX_GRAN_ARR(s->fvy, cs, 1, 0);
  PX_GRAN_ARR(s->fvw, cs, 1, 0);
  PX_GRAN_ARR(s->ffx, cs, 1, 0);
  PX_GRAN_ARR(s->ffy, cs, 1, 0);
  PX_GRAN_ARR(s->ftq, cs, 1, 0);
  PX_GRAN_ARR(s->id, sizeof(int32_t), 1, 1);
  if (s->with_abm) {
    for (k = 0; k < 3; ++k)
      for (d = 0; d < 5; ++d) PX_GRAN_ARR(s->hist[k][d], ss, 1, 1);
    for (d = 0; d < 5; ++d) PX_GRAN_ARR(s->xp[d], ss, 1, 0);
    for (d = 0; d < 3; ++d) PX_GRAN_ARR(s->fa[d], ss, 1, 0);
  }
  PX_GRAN_ARR(s->slots.seg, sizeof(int), W, 1);
  PX_GRAN_ARR(s->slots.seg0, sizeof(int), W, 1);
  PX_GRAN_ARR(s->slots.step0, sizeof(int), W, 1);
  PX_GRAN_ARR(s->slots.t0, cs, W, 1);
  PX_GRAN_ARR(s->slots.te, cs, W, 1);
  PX_GRAN_ARR(s->slots.xi, cs, W, 1);
  PX_GRAN_ARR(s->slots.th, cs, W, 1);
  PX_GRAN_ARR(s->slots.dm, cs, W, 1);
  PX_GRAN_ARR(s->slots.dp, cs, W, 1);
  PX_GRAN_ARR(s->slots.imp, cs, W, 1);
  PX_GRAN_ARR(s->slots.slw, cs, W, 1);
  PX_GRAN_ARR(s->slots.arc, cs, W, 1);
  PX_GRAN_ARR(s->slots.tim, cs, W, 1);
  PX_GRAN_ARR(s->cell, sizeof(int32_t), 1, 0);
  PX_GRAN_ARR(s->order, sizeof(int32_t), 1, 0);
#undef PX_GRAN_ARR
  return n;
}

#define PX_GRAN_MAX_ARRAYS 72

double px_gran_sys_particle_bytes(enum px_precision precision, int abm) {
  /* the per-particle arrays of a system of this precision (px_gran_arrays
   * reads only the sizes and the integrator) */
  struct px_gran_arr a[PX_GRAN_MAX_ARRAYS];
  size_t na, k;
  double bytes = 0, cs;
  struct px_gran_sys s;
  memset(&s, 0, sizeof s);
  s.ssize = precision == PX_PRECISION_SINGLE ? sizeof(float) : sizeof(double);
  s.csize = precision == PX_PRECISION_DOUBLE ? sizeof(double) : sizeof(float);
  s.with_abm = abm;
  cs = (double)s.csize;
  na = px_gran_arrays(&s, a);
  for (k = 0; k < na; ++k) bytes += (double)(a[k].esize * a[k].per);
  bytes += sizeof(int32_t);                        /* where */
  /* ~5 pairs of the half list (2D, skin included): ends, 10 history and
   * property reals, 4 force reals, 4 scratch reals, cross index; the old list
   * during a rebuild */
  bytes += 5.0 * (3 * 4 + 18 * cs + 4 * 4 + 4 * cs);
  bytes += 4.0 * 4 + 2 * 4;                       /* grid cells, wall lists */
  bytes += 8.0 * 8 + 24 * 2;                      /* filling: x, y, r, m, v; sites */
  return bytes;
}

enum px_status px_gran_sys_create(struct px_context *ctx, enum px_precision precision,
                                  int threads, struct px_gran_sys **out) {
  struct px_gran_sys *s = px_mem_calloc(ctx, "granular system", 1, sizeof *s);
  *out = NULL;
  if (!s) return PX_STATUS_NOMEM;
  s->ctx = ctx;
  s->precision = precision;
  s->threads = threads > 0 ? threads : 1;
  s->fail_id = -1;
  s->tune = 1;
  s->nranges = 4 * s->threads;
  switch (precision) {
  case PX_PRECISION_DOUBLE:
    s->ssize = s->csize = sizeof(double);
    s->ops = &px_gran_cpu_ops_f64;
    break;
  case PX_PRECISION_MIXED:
    s->ssize = sizeof(double);
    s->csize = sizeof(float);
    s->ops = &px_gran_cpu_ops_mixed;
    break;
  default:
    s->ssize = s->csize = sizeof(float);
    s->ops = &px_gran_cpu_ops_f32;
    break;
  }
  s->skin = -1;
  s->integrator = PX_GRAN_INTEGRATOR_VERLET;
  s->reorder = 1;
  s->escaped_id = -1;
  *out = s;
  return PX_STATUS_OK;
}

static void px_gran_stats_free(struct px_gran_sys *s) {
  struct px_gran_stats *st = &s->stats;
  double **v[] = {&st->impacts, &st->vn_sum, &st->vn2_sum, &st->vn_max, &st->vt_sum,
                  &st->en,      &st->et,     &st->finnie,  &st->impulse, &st->slide,
                  &st->archard, &st->ctime,  &st->dur_sum, &st->ended,  &st->t_first,
                  &st->t_last};
  size_t k;
  for (k = 0; k < sizeof v / sizeof v[0]; ++k) {
    px_mem_free(s->ctx, *v[k]);
    *v[k] = NULL;
  }
}

void px_gran_sys_free(struct px_gran_sys *s) {
  struct px_gran_arr a[PX_GRAN_MAX_ARRAYS];
  size_t na, k;
  struct px_context *ctx;
  if (!s) return;
  ctx = s->ctx;
  na = px_gran_arrays(s, a);
  for (k = 0; k < na; ++k) px_mem_free(ctx, *a[k].p);
  px_mem_free(ctx, s->where);
  px_mem_free(ctx, s->pstart);
  px_mem_free(ctx, s->pi);
  px_mem_free(ctx, s->pj);
  px_mem_free(ctx, s->pxi);
  px_mem_free(ctx, s->pth);
  px_mem_free(ctx, s->pdm);
  px_mem_free(ctx, s->pdp);
  px_mem_free(ctx, s->pfx);
  px_mem_free(ctx, s->pfy);
  px_mem_free(ctx, s->pti);
  px_mem_free(ctx, s->ptj);
  px_mem_free(ctx, s->phist_scratch);
  px_mem_free(ctx, s->pdxr);
  px_mem_free(ctx, s->pdyr);
  px_mem_free(ctx, s->pre);
  px_mem_free(ctx, s->pme);
  px_mem_free(ctx, s->prj);
  px_mem_free(ctx, s->pri);
  px_mem_free(ctx, s->rng_i);
  px_mem_free(ctx, s->rng_q);
  px_mem_free(ctx, s->xstart);
  px_mem_free(ctx, s->xpair);
  px_mem_free(ctx, s->frames);
  px_mem_free(ctx, s->sframes);
  px_mem_free(ctx, s->frames_ref);
  px_mem_free(ctx, s->c_radius);
  px_mem_free(ctx, s->seg_ax);
  px_mem_free(ctx, s->seg_ay);
  px_mem_free(ctx, s->seg_tx);
  px_mem_free(ctx, s->seg_ty);
  px_mem_free(ctx, s->seg_len);
  px_mem_free(ctx, s->seg_tpx);
  px_mem_free(ctx, s->seg_tpy);
  px_mem_free(ctx, s->seg_cfirst);
  px_mem_free(ctx, s->seg_ccount);
  px_mem_free(ctx, s->wstart);
  px_mem_free(ctx, s->wcand);
  px_mem_free(ctx, s->near);
  px_mem_free(ctx, s->cstart);
  px_mem_free(ctx, s->scratch);
  px_mem_free(ctx, s->ev_i);
  px_mem_free(ctx, s->ev_r);
  px_mem_free(ctx, s->ev_n);
  px_mem_free(ctx, s->cforce);
  px_mem_free(ctx, s->cforce_t);
  px_gran_stats_free(s);
  px_mem_free(ctx, s);
}

enum px_status px_gran_sys_add(struct px_gran_sys *s, size_t n, const double *x, const double *y,
                               const double *r, const double *m) {
  struct px_gran_arr a[PX_GRAN_MAX_ARRAYS];
  size_t na, k, i;
  size_t cap = s->cap;
  if (s->n == 0 && s->cap == 0) s->with_abm = s->integrator == PX_GRAN_INTEGRATOR_ABM4;
  na = px_gran_arrays(s, a);
  if (n > (size_t)PX_GRAN_N_MAX || s->n + n > (size_t)PX_GRAN_N_MAX)
    return px_context_fail(s->ctx, PX_STATUS_CONFIG, "%zu particles: more than the %.0e the "
                           "solver takes", s->n + n, PX_GRAN_N_MAX);
  if (s->n + n > cap) {
    /* the first addition exactly (a case adds all its discs at once), then
     * doubling */
    cap = cap ? cap : s->n + n;
    while (cap < s->n + n) cap *= 2;
    for (k = 0; k < na; ++k) {
      void *p = px_mem_realloc(s->ctx, "granular particles", *a[k].p, cap * a[k].esize * a[k].per);
      if (!p) return PX_STATUS_NOMEM;
      *a[k].p = p;
    }
    {
      int32_t *wh = px_mem_realloc(s->ctx, "granular particles", s->where, cap * sizeof *wh);
      if (!wh) return PX_STATUS_NOMEM;
      s->where = wh;
    }
    s->cap = cap;
  }
  for (k = 0; k < na; ++k)
    memset((char *)*a[k].p + s->n * a[k].esize * a[k].per, 0, n * a[k].esize * a[k].per);
  for (i = 0; i < n; ++i) {
    double rec[8] = {0};
    const size_t at = s->n + i;
    if (!(r[i] > 0) || !(m[i] > 0) || !isfinite(x[i]) || !isfinite(y[i]))
      return px_context_fail(s->ctx, PX_STATUS_INVALID,
                             "particle %zu: radius %g and mass %g must be > 0, position finite",
                             at, r[i], m[i]);
    rec[PX_GRAN_P_X] = x[i];
    rec[PX_GRAN_P_Y] = y[i];
    rec[PX_GRAN_P_R] = r[i];
    rec[PX_GRAN_P_M] = m[i];
    s->ops->set(s, at, rec);
    s->id[at] = (int32_t)at;
    s->where[at] = (int32_t)at;
    for (k = 0; k < PX_GRAN_WSLOTS; ++k) s->slots.seg[at * PX_GRAN_WSLOTS + k] = -1;
  }
  s->n += n;
  s->need_rebuild = 1;
  return PX_STATUS_OK;
}

enum px_status px_gran_sys_set_velocity(struct px_gran_sys *s, int32_t id, double vx, double vy,
                                        double w) {
  double rec[8];
  size_t i;
  if (id < 0 || (size_t)id >= s->n)
    return px_context_fail(s->ctx, PX_STATUS_INVALID, "no particle with id %d", (int)id);
  i = (size_t)s->where[id];
  s->ops->get(s, i, rec);
  rec[PX_GRAN_P_VX] = vx;
  rec[PX_GRAN_P_VY] = vy;
  rec[PX_GRAN_P_W] = w;
  s->ops->set(s, i, rec);
  return PX_STATUS_OK;
}

void px_gran_sys_get(const struct px_gran_sys *s, int32_t id, double out[8]) {
  s->ops->get(s, (size_t)s->where[id], out);
}

void px_gran_sys_set_walls(struct px_gran_sys *s, const struct px_gran_geom *g,
                           const struct px_gran_motion *motions, size_t nbodies) {
  s->geom = g && g->ncontours ? g : NULL;
  s->motions = motions;
  s->nbodies = nbodies;
}

/* Copy a double array into state precision. */
static void *px_gran_to_state(struct px_gran_sys *s, const double *src, size_t n) {
  void *dst = px_mem_alloc(s->ctx, "granular walls", (n ? n : 1) * s->ssize);
  size_t k;
  if (!dst) return NULL;
  for (k = 0; k < n; ++k) {
    if (s->ssize == sizeof(double)) ((double *)dst)[k] = src[k];
    else ((float *)dst)[k] = (float)src[k];
  }
  return dst;
}

void px_gran_sys_frames(struct px_gran_sys *s, double t) {
  size_t c, k;
  if (!s->geom) return;
  for (c = 0; c < s->geom->ncontours; ++c) {
    const int b = s->geom->contours[c].body;
    double *f = s->frames + c * PX_GRAN_CTR_COUNT;
    if (s->motions && b >= 0 && (size_t)b < s->nbodies) {
      px_gran_motion_frame(&s->motions[b], t, f);
    } else {
      memset(f, 0, PX_GRAN_CTR_COUNT * sizeof *f);
      f[PX_GRAN_CTR_COS] = 1;
    }
    for (k = 0; k < PX_GRAN_CTR_COUNT; ++k) {
      if (s->ssize == sizeof(double)) ((double *)s->sframes)[c * PX_GRAN_CTR_COUNT + k] = f[k];
      else ((float *)s->sframes)[c * PX_GRAN_CTR_COUNT + k] = (float)f[k];
    }
  }
}

/* ------------------------------------------------------------------ checks */

double px_gran_law_contact_time(const struct px_gran_law_spec *L, double meff) {
  if (L->normal == PX_GRAN_NORMAL_HYSTERETIC) {
    const double k2 = L->k2 > 0 ? L->k2 : L->kn / (L->e * L->e);
    return 0.5 * PX_GRAN_PI * (sqrt(meff / L->kn) + sqrt(meff / k2));
  } else {
    double p[PX_GRAN_LAW_COUNT], zeta;
    px_gran_law_params(L, 0, p);
    zeta = 0.5 * p[PX_GRAN_LAW_ZETA2];
    return PX_GRAN_PI / (sqrt(L->kn / meff) * sqrt(1 - zeta * zeta));
  }
}

double px_gran_sys_contact_time(const struct px_gran_sys *s) {
  double mmin = DBL_MAX, tc;
  size_t i;
  for (i = 0; i < s->n; ++i) {
    double rec[8];
    s->ops->get(s, i, rec);
    if (rec[PX_GRAN_P_M] < mmin) mmin = rec[PX_GRAN_P_M];
  }
  if (s->n == 0) return 0;
  tc = px_gran_law_contact_time(&s->pp, 0.5 * mmin);
  if (s->geom) {
    const double tw = px_gran_law_contact_time(&s->pw, mmin);
    if (tw < tc) tc = tw;
  }
  return tc;
}

static enum px_status px_gran_check_law(struct px_context *ctx, const struct px_gran_law_spec *L,
                                        const char *what) {
  if (!(L->kn > 0))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: normal stiffness kn = %g must be > 0", what, L->kn);
  if (!(L->e > 0) || !(L->e <= 1))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: restitution e = %g must be in (0, 1] (e > 1 would create energy)",
                           what, L->e);
  if (L->normal == PX_GRAN_NORMAL_HYSTERETIC && L->k2 > 0 && !(L->k2 >= L->kn))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: unloading stiffness k2 = %g must be >= the loading stiffness %g",
                           what, L->k2, L->kn);
  if (!(L->mu >= 0) || !(L->kt_ratio >= 0) || !(L->ct_ratio >= 0) || !(L->mur >= 0) ||
      !(L->kr >= 0) || !(L->gt >= 0) || !(L->phif >= 0) || !(L->damping >= 0) ||
      !(L->damping < 1))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: friction, tangential/rolling stiffness and damping must be >= 0 "
                           "(damping ratio < 1)",
                           what);
  if (L->mur > 0 && !(L->kr > 0))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: rolling friction needs a rolling stiffness > 0",
                           what);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------ rebuild */

static enum px_status px_gran_ensure(struct px_gran_sys *s, void **p, size_t bytes,
                                     const char *label) {
  void *q;
  if (*p && px_mem_size(*p) >= bytes) return PX_STATUS_OK;
  q = px_mem_realloc(s->ctx, label, *p, bytes ? bytes : 1);
  if (!q) return PX_STATUS_NOMEM;
  *p = q;
  return PX_STATUS_OK;
}

/* Permute the kept per-particle arrays: new slot i takes old order[i]. */
static enum px_status px_gran_permute(struct px_gran_sys *s) {
  struct px_gran_arr a[PX_GRAN_MAX_ARRAYS];
  size_t na = px_gran_arrays(s, a), k, i;
  const size_t n = s->n;
  const int32_t *order = s->order;
  PX_TRY(px_gran_ensure(s, &s->scratch, n * 8 * PX_GRAN_WSLOTS, "granular scratch"));
  for (k = 0; k < na; ++k) {
    const size_t blk = a[k].esize * a[k].per;
    char *src = *a[k].p, *dst = s->scratch;
    if (!a[k].keep) continue;
    for (i = 0; i < n; ++i) memcpy(dst + i * blk, src + (size_t)order[i] * blk, blk);
    memcpy(src, dst, n * blk);
  }
  for (i = 0; i < n; ++i) s->where[s->id[i]] = (int32_t)i;
  return PX_STATUS_OK;
}

static void px_gran_copy_real(void *dst, size_t di, const void *src, size_t si, size_t cs,
                              double sign) {
  if (cs == sizeof(double)) ((double *)dst)[di] = sign * ((const double *)src)[si];
  else ((float *)dst)[di] = (float)sign * ((const float *)src)[si];
}

static double px_gran_rd(const void *p, size_t i, size_t es) {
  return es == sizeof(double) ? ((const double *)p)[i] : (double)((const float *)p)[i];
}

/* Wall candidates within r + skin for every particle (CSR), near list. */
static enum px_status px_gran_build_walls(struct px_gran_sys *s) {
  const struct px_gran_geom *g = s->geom;
  const size_t n = s->n;
  size_t i, c, total = 0;
  int buf[PX_GRAN_WCAND_MAX];
  PX_TRY(px_gran_ensure(s, (void **)&s->wstart, (n + 1) * sizeof(int32_t), "granular wall lists"));
  PX_TRY(px_gran_ensure(s, (void **)&s->near, (n ? n : 1) * sizeof(int32_t), "granular wall lists"));
  s->nnear = 0;
  for (i = 0; i < n; ++i) {
    double rec[8];
    int cnt = 0;
    s->ops->get(s, i, rec);
    s->wstart[i] = (int32_t)total;
    for (c = 0; c < g->ncontours; ++c) {
      const struct px_gran_contour *C = &g->contours[c];
      const double range = rec[PX_GRAN_P_R] + s->skin;
      double lx, ly;
      int got;
      px_gran_geom_to_local(s->frames + c * PX_GRAN_CTR_COUNT, rec[PX_GRAN_P_X],
                            rec[PX_GRAN_P_Y], &lx, &ly);
      if (lx < C->xmin - range || lx > C->xmax + range || ly < C->ymin - range ||
          ly > C->ymax + range)
        continue;
      got = px_gran_geom_near(g, c, lx, ly, range, buf + cnt, (int)(sizeof buf / sizeof buf[0]) - cnt);
      if (got < 0)
        return px_context_fail(s->ctx, PX_STATUS_NUMERIC,
                               "particle %d at (%g, %g) is near more than %zu boundary segments: "
                               "the segments are much shorter than the particle (raise "
                               "segment_length)",
                               (int)s->id[i], rec[PX_GRAN_P_X], rec[PX_GRAN_P_Y],
                               sizeof buf / sizeof buf[0]);
      cnt += got;
    }
    if (cnt) {
      PX_TRY(px_gran_ensure(s, (void **)&s->wcand, (total + (size_t)cnt) * sizeof(int32_t),
                            "granular wall lists"));
      memcpy(s->wcand + total, buf, (size_t)cnt * sizeof(int32_t));
      total += (size_t)cnt;
      s->near[s->nnear++] = (int32_t)i;
    }
  }
  s->wstart[n] = (int32_t)total;
  s->nwcand = total;
  return PX_STATUS_OK;
}

/* Is the particle (world x, y) behind the wall it is closest to among its
 * candidates? Returns the contour index or -1. */
static int px_gran_behind_wall(const struct px_gran_sys *s, size_t i, double x, double y) {
  const struct px_gran_geom *g = s->geom;
  int32_t q;
  double best = DBL_MAX, side = 1;
  int bestc = -1;
  for (q = s->wstart[i]; q < s->wstart[i + 1]; ++q) {
    const int sg = s->wcand[q];
    const int c = g->contour[sg];
    const struct px_gran_contour *C = &g->contours[c];
    double lx, ly, rx, ry, u, d, sd;
    px_gran_geom_to_local(s->frames + (size_t)c * PX_GRAN_CTR_COUNT, x, y, &lx, &ly);
    rx = lx - g->ax[sg];
    ry = ly - g->ay[sg];
    u = rx * g->tx[sg] + ry * g->ty[sg];
    if (u <= 0) {
      /* start vertex: pseudo-normal = sum of the two segment normals */
      const double nx = -g->tpy[sg] - g->ty[sg], ny = g->tpx[sg] + g->tx[sg];
      d = hypot(rx, ry);
      sd = rx * nx + ry * ny;
    } else if (u >= g->len[sg]) {
      const size_t k = (size_t)sg - C->first, nxt = C->first + (k + 1) % C->count;
      const double ex = rx - g->len[sg] * g->tx[sg], ey = ry - g->len[sg] * g->ty[sg];
      const double nx = -g->ty[sg] - g->ty[nxt], ny = g->tx[sg] + g->tx[nxt];
      d = hypot(ex, ey);
      sd = ex * nx + ey * ny;
    } else {
      sd = ry * g->tx[sg] - rx * g->ty[sg];
      d = fabs(sd);
    }
    if (d < best) {
      best = d;
      side = sd;
      bestc = c;
    }
  }
  return (bestc >= 0 && side < 0) ? bestc : -1;
}

/* Work split: fixed particle ranges and their cross pairs (j in a later
 * range), from the pair list. */
static enum px_status px_gran_sys_split_pairs(struct px_gran_sys *s) {
  const int T = s->nranges;
  const size_t n = s->n;
  int t;
  size_t k;
  int32_t *count;
  PX_TRY(px_gran_ensure(s, (void **)&s->rng_i, (size_t)(T + 1) * sizeof(size_t), "granular pairs"));
  PX_TRY(px_gran_ensure(s, (void **)&s->rng_q, (size_t)(T + 1) * sizeof(size_t), "granular pairs"));
  PX_TRY(px_gran_ensure(s, (void **)&s->xstart, (size_t)(T + 1) * sizeof(int32_t), "granular pairs"));
  PX_TRY(px_gran_ensure(s, (void **)&s->xpair, (s->npairs ? s->npairs : 1) * sizeof(int32_t),
                        "granular pairs"));
  count = px_mem_alloc(s->ctx, "granular pairs", (size_t)(T + 1) * sizeof *count);
  if (!count) return PX_STATUS_NOMEM;
  for (t = 0; t <= T; ++t) s->rng_i[t] = n * (size_t)t / (size_t)T;
  memset(s->xstart, 0, (size_t)(T + 1) * sizeof(int32_t));
  for (t = 0; t < T; ++t) {
    const size_t i1 = s->rng_i[t + 1];
    for (k = (size_t)s->pstart[s->rng_i[t]]; k < (size_t)s->pstart[i1]; ++k)
      if ((size_t)s->pj[k] >= i1) {
        int u = t + 1;
        while ((size_t)s->pj[k] >= s->rng_i[u + 1]) ++u;
        ++s->xstart[u + 1];
      }
  }
  for (t = 0; t < T; ++t) s->xstart[t + 1] += s->xstart[t];
  memcpy(count, s->xstart, (size_t)T * sizeof(int32_t));
  for (t = 0; t < T; ++t) {
    const size_t i1 = s->rng_i[t + 1];
    for (k = (size_t)s->pstart[s->rng_i[t]]; k < (size_t)s->pstart[i1]; ++k)
      if ((size_t)s->pj[k] >= i1) {
        int u = t + 1;
        while ((size_t)s->pj[k] >= s->rng_i[u + 1]) ++u;
        s->xpair[count[u]++] = (int32_t)k;
      }
  }
  px_mem_free(s->ctx, count);
  return PX_STATUS_OK;
}

/* Near-wall particles of each range (the near list is ascending). */
static void px_gran_sys_split_near(struct px_gran_sys *s) {
  int t;
  size_t q = 0;
  for (t = 0; t <= s->nranges; ++t) {
    while (q < s->nnear && (size_t)s->near[q] < s->rng_i[t]) ++q;
    s->rng_q[t] = q;
  }
  s->rng_q[s->nranges] = s->nnear;
}

enum px_status px_gran_sys_rebuild(struct px_gran_sys *s) {
  const size_t n = s->n;
  double xmin = DBL_MAX, ymin = DBL_MAX, xmax = -DBL_MAX, ymax = -DBL_MAX, h;
  size_t i, ncell;
  int32_t *count = NULL, *opstart = NULL, *opj = NULL;
  void *oxi = NULL, *oth = NULL, *odm = NULL, *odp = NULL;
  enum px_status st = PX_STATUS_OK;
  const size_t cs = s->csize;

  /* finite positions and the bounding box */
  for (i = 0; i < n; ++i) {
    double rec[8];
    s->ops->get(s, i, rec);
    if (!isfinite(rec[PX_GRAN_P_X]) || !isfinite(rec[PX_GRAN_P_Y]) ||
        !isfinite(rec[PX_GRAN_P_VX]) || !isfinite(rec[PX_GRAN_P_VY]) ||
        !isfinite(rec[PX_GRAN_P_W]))
      return px_context_fail(s->ctx, PX_STATUS_NUMERIC,
                             "step %ld (t = %g s): particle %d has a non-finite position or "
                             "velocity (x = %g, y = %g, vx = %g, vy = %g): the time step is "
                             "too large for the stiffness, or the input is wrong",
                             s->step, s->t, (int)s->id[i], rec[0], rec[1], rec[2], rec[3]);
    if (rec[0] < xmin) xmin = rec[0];
    if (rec[0] > xmax) xmax = rec[0];
    if (rec[1] < ymin) ymin = rec[1];
    if (rec[1] > ymax) ymax = rec[1];
  }
  if (n == 0) xmin = ymin = xmax = ymax = 0;
  if (!(xmax - xmin <= PX_GRAN_COORD_MAX) || !(ymax - ymin <= PX_GRAN_COORD_MAX))
    return px_context_fail(s->ctx, PX_STATUS_NUMERIC,
                           "step %ld (t = %g s): the particles spread over %g m x %g m, more "
                           "than %g m: some escaped the contours and flew away",
                           s->step, s->t, xmax - xmin, ymax - ymin, PX_GRAN_COORD_MAX);
  h = 2 * s->rmax + s->skin;
  while (((xmax - xmin) / h + 3) * ((ymax - ymin) / h + 3) > 4.0 * (double)n + 1e6) h *= 2;
  s->gh = h;
  s->gx0 = xmin - h;
  s->gy0 = ymin - h;
  s->gnx = (int)((xmax - s->gx0) / h) + 2;
  s->gny = (int)((ymax - s->gy0) / h) + 2;
  ncell = (size_t)s->gnx * (size_t)s->gny;
  PX_TRY(px_gran_ensure(s, (void **)&s->cstart, (ncell + 1) * sizeof(int32_t), "granular cells"));

  /* counting sort by cell (stable) */
  memset(s->cstart, 0, (ncell + 1) * sizeof(int32_t));
  for (i = 0; i < n; ++i) {
    double rec[8];
    int a, b;
    s->ops->get(s, i, rec);
    a = (int)((rec[0] - s->gx0) / h);
    b = (int)((rec[1] - s->gy0) / h);
    s->cell[i] = b * s->gnx + a;
    ++s->cstart[s->cell[i] + 1];
  }
  for (i = 0; i < ncell; ++i) s->cstart[i + 1] += s->cstart[i];
  {
    int32_t *fill = px_mem_alloc(s->ctx, "granular cells", (ncell ? ncell : 1) * sizeof *fill);
    if (!fill) return PX_STATUS_NOMEM;
    memcpy(fill, s->cstart, ncell * sizeof *fill);
    for (i = 0; i < n; ++i) s->order[fill[s->cell[i]]++] = (int32_t)i;
    px_mem_free(s->ctx, fill);
  }

  /* keep the old list (old particle indices) for the history transfer */
  opstart = s->pstart;
  opj = s->pj;
  oxi = s->pxi;
  oth = s->pth;
  odm = s->pdm;
  odp = s->pdp;
  s->pstart = NULL;
  s->pj = NULL;
  s->pxi = s->pth = s->pdm = s->pdp = NULL;
  st = px_gran_permute(s);
  if (st != PX_STATUS_OK) goto done;

  /* new list */
  count = px_mem_alloc(s->ctx, "granular pairs", (n + 1) * sizeof *count);
  s->pstart = px_mem_alloc(s->ctx, "granular pairs", (n + 1) * sizeof(int32_t));
  if (!count || !s->pstart) {
    st = PX_STATUS_NOMEM;
    goto done;
  }
  s->ops->build_pairs(s, s->skin, 0, count);
  {
    /* pair indices are int32: a list beyond them (discs piled on top of each
     * other, a skin far above the radii) is a failure, not a wrap */
    size_t total = 0;
    for (i = 0; i < n; ++i) total += (size_t)count[i];
    if (total > (size_t)INT32_MAX) {
      st = px_context_fail(s->ctx, PX_STATUS_NUMERIC,
                           "step %ld (t = %g s): %zu neighbour pairs within the cut-off (radii "
                           "+ skin %g m): more than the neighbour list holds; the discs are "
                           "piled up or the skin is far too large",
                           s->step, s->t, total, s->skin);
      goto done;
    }
  }
  s->pstart[0] = 0;
  for (i = 0; i < n; ++i) s->pstart[i + 1] = s->pstart[i] + count[i];
  s->npairs = (size_t)s->pstart[n];
  {
    const size_t np = s->npairs ? s->npairs : 1;
    void **pa[] = {(void **)&s->pi,  (void **)&s->pfx, (void **)&s->pfy, (void **)&s->pti,
                   (void **)&s->ptj, (void **)&s->pri, (void **)&s->prj, (void **)&s->pme,
                   (void **)&s->pre, (void **)&s->pdxr, (void **)&s->pdyr};
    const size_t es[] = {sizeof(int32_t), cs, cs, cs, cs, cs, cs, cs, cs, cs, cs};
    size_t k;
    for (k = 0; k < sizeof pa / sizeof pa[0]; ++k) {
      st = px_gran_ensure(s, pa[k], np * es[k], "granular pairs");
      if (st != PX_STATUS_OK) goto done;
    }
    st = px_gran_ensure(s, &s->phist_scratch, 4 * np * cs, "granular pairs");
    if (st != PX_STATUS_OK) goto done;
    s->pj = px_mem_alloc(s->ctx, "granular pairs", np * sizeof(int32_t));
    s->pxi = px_mem_calloc(s->ctx, "granular pairs", np, cs);
    s->pth = px_mem_calloc(s->ctx, "granular pairs", np, cs);
    s->pdm = px_mem_calloc(s->ctx, "granular pairs", np, cs);
    s->pdp = px_mem_calloc(s->ctx, "granular pairs", np, cs);
    if (!s->pj || !s->pxi || !s->pth || !s->pdm || !s->pdp) {
      st = PX_STATUS_NOMEM;
      goto done;
    }
  }
  s->ops->build_pairs(s, s->skin, 1, NULL);

  /* contact histories from the old list: new pair (i, j) was (order[i],
   * order[j]) in old indices, owned by either end */
  if (opstart) {
#pragma omp parallel for num_threads(s->active) schedule(static)
    for (long ii = 0; ii < (long)n; ++ii) {
      int32_t k;
      for (k = s->pstart[ii]; k < s->pstart[ii + 1]; ++k) {
        const int32_t oi = s->order[ii], oj = s->order[s->pj[k]];
        int32_t q;
        int found = 0;
        for (q = opstart[oi]; q < opstart[oi + 1]; ++q)
          if (opj[q] == oj) {
            px_gran_copy_real(s->pxi, (size_t)k, oxi, (size_t)q, cs, 1);
            px_gran_copy_real(s->pth, (size_t)k, oth, (size_t)q, cs, 1);
            px_gran_copy_real(s->pdm, (size_t)k, odm, (size_t)q, cs, 1);
            px_gran_copy_real(s->pdp, (size_t)k, odp, (size_t)q, cs, 1);
            found = 1;
            break;
          }
        if (found) continue;
        for (q = opstart[oj]; q < opstart[oj + 1]; ++q)
          if (opj[q] == oi) {
            /* ownership swapped: the scalar tangential spring and the largest
             * overlap are symmetric, the rolling angle changes sign */
            px_gran_copy_real(s->pxi, (size_t)k, oxi, (size_t)q, cs, 1);
            px_gran_copy_real(s->pth, (size_t)k, oth, (size_t)q, cs, -1);
            px_gran_copy_real(s->pdm, (size_t)k, odm, (size_t)q, cs, 1);
            px_gran_copy_real(s->pdp, (size_t)k, odp, (size_t)q, cs, 1);
            break;
          }
      }
    }
  }

  st = px_gran_sys_split_pairs(s);
  if (st != PX_STATUS_OK) goto done;

  /* walls */
  if (s->geom) {
    st = px_gran_build_walls(s);
    if (st != PX_STATUS_OK) goto done;
    memcpy(s->frames_ref, s->frames, s->geom->ncontours * PX_GRAN_CTR_COUNT * sizeof(double));
    for (i = 0; i < s->nnear; ++i) {
      const size_t p = (size_t)s->near[i];
      double rec[8];
      int c;
      s->ops->get(s, p, rec);
      c = px_gran_behind_wall(s, p, rec[0], rec[1]);
      if (c >= 0) {
        s->escaped_id = s->id[p];
        st = px_context_fail(s->ctx, PX_STATUS_NUMERIC,
                             "step %ld (t = %g s): particle %d at (%g, %g) has passed through "
                             "contour '%s' (its centre is behind the wall): the wall is too "
                             "soft or the time step too large for the impact speed (|v| = %g "
                             "m/s)",
                             s->step, s->t, (int)s->id[p], rec[0], rec[1],
                             s->geom->contours[c].name, hypot(rec[2], rec[3]));
        goto done;
      }
    }
  } else {
    PX_TRY(px_gran_ensure(s, (void **)&s->wstart, (n + 1) * sizeof(int32_t), "granular wall lists"));
    memset(s->wstart, 0, (n + 1) * sizeof(int32_t));
    s->nnear = 0;
  }
  px_gran_sys_split_near(s);
  /* reference positions */
  memcpy(s->xr, s->x, n * s->ssize);
  memcpy(s->yr, s->y, n * s->ssize);
  ++s->rebuilds;
  s->need_rebuild = 0;
done:
  px_mem_free(s->ctx, count);
  px_mem_free(s->ctx, opstart);
  px_mem_free(s->ctx, opj);
  px_mem_free(s->ctx, oxi);
  px_mem_free(s->ctx, oth);
  px_mem_free(s->ctx, odm);
  px_mem_free(s->ctx, odp);
  return st;
}

/* ------------------------------------------------------------------ prepare */

enum px_status px_gran_sys_prepare(struct px_gran_sys *s, double dt, double steps_per_contact) {
  size_t i;
  double tc;
  if (s->integrator == PX_GRAN_INTEGRATOR_ABM4 && !s->with_abm)
    return px_context_fail(s->ctx, PX_STATUS_INVALID,
                           "granular: the integrator must be chosen before particles are added");
  PX_TRY(px_gran_check_law(s->ctx, &s->pp, "particle-particle contact"));
  if (s->geom) PX_TRY(px_gran_check_law(s->ctx, &s->pw, "particle-wall contact"));
  if (s->n == 0) return px_context_fail(s->ctx, PX_STATUS_CONFIG, "there are no particles");
  s->rmax = 0;
  s->rmin = DBL_MAX;
  for (i = 0; i < s->n; ++i) {
    double rec[8];
    s->ops->get(s, i, rec);
    if (rec[PX_GRAN_P_R] > s->rmax) s->rmax = rec[PX_GRAN_P_R];
    if (rec[PX_GRAN_P_R] < s->rmin) s->rmin = rec[PX_GRAN_P_R];
  }
  if (s->skin < 0) s->skin = 0.2 * 2 * s->rmax;
  if (!(s->skin <= PX_GRAN_SKIN_MAX * s->rmax))
    return px_context_fail(s->ctx, PX_STATUS_CONFIG,
                           "skin %g m: more than %g times the largest radius %g m (every disc "
                           "would list hundreds of neighbours; 0.2 to 1 radius is usual)",
                           s->skin, PX_GRAN_SKIN_MAX, s->rmax);
  /* a parallel region costs microseconds: below ~2000 particles per thread
   * the threads wait more than they work (fixed by n, so runs stay
   * reproducible) */
  {
    const int useful = (int)(s->n / 2048) > 1 ? (int)(s->n / 2048) : 1;
    if (s->threads > useful) s->threads = useful;
    if (s->threads > 64) s->threads = 64;
    /* work is split into 4 ranges per thread, taken dynamically: a thread
     * that is descheduled does not hold the others back as long; the split
     * (and so every sum) depends only on the thread count asked for */
    s->nranges = 4 * s->threads;
    s->active = s->threads;
  }
  {
    double p[PX_GRAN_LAW_COUNT];
    px_gran_law_params(&s->pp, 0, p);
    s->pp_zeta2 = p[PX_GRAN_LAW_ZETA2];
  }
  tc = px_gran_sys_contact_time(s);
  if (!(tc > 0) || !isfinite(tc))
    return px_context_fail(s->ctx, PX_STATUS_CONFIG,
                           "the contact duration of the lightest pair t_c = %g s is not a "
                           "positive finite time (stiffness kn = %g N/m, wall %g N/m): the "
                           "stiffness is out of all proportion to the masses",
                           tc, s->pp.kn, s->pw.kn);
  if (!(dt > 0)) {
    if (!(steps_per_contact >= 5) || !(steps_per_contact <= 1e6))
      return px_context_fail(s->ctx, PX_STATUS_CONFIG,
                             "steps per contact = %g: must be in [5, 1e6] (25-50 recommended)",
                             steps_per_contact);
    dt = tc / steps_per_contact;
    if (!(dt > 0))
      return px_context_fail(s->ctx, PX_STATUS_CONFIG,
                             "dt = t_c / %g = %g s with t_c = %g s: not a positive time step",
                             steps_per_contact, dt, tc);
  }
  if (dt > tc / 5)
    return px_context_fail(s->ctx, PX_STATUS_CONFIG,
                           "dt = %g s is above the stability limit t_c/5 = %g s (t_c = %g s is "
                           "the contact duration of the lightest pair); use dt <= t_c/25 or "
                           "leave dt out to have it computed",
                           dt, tc / 5, tc);
  if (dt < tc * 1e-6)
    return px_context_fail(s->ctx, PX_STATUS_CONFIG,
                           "dt = %g s resolves a contact with %.3g steps (t_c = %g s): more than "
                           "1e6 steps per contact only costs time",
                           dt, tc / dt, tc);
  if (dt > tc / 20)
    px_log(s->ctx, PX_LOG_LEVEL_WARN,
           "dt = %g s resolves a contact with only %.1f steps (t_c = %g s): restitution and "
           "contact forces will be inaccurate; 25-50 steps per contact are recommended",
           dt, tc / dt, tc);
  s->dt = dt;

  /* walls in state precision */
  if (s->geom) {
    const struct px_gran_geom *g = s->geom;
    const size_t nc = g->ncontours;
    size_t c;
    s->ncontours = nc;
    s->frames = px_mem_calloc(s->ctx, "granular walls", nc * PX_GRAN_CTR_COUNT, sizeof(double));
    s->frames_ref = px_mem_calloc(s->ctx, "granular walls", nc * PX_GRAN_CTR_COUNT, sizeof(double));
    s->sframes = px_mem_calloc(s->ctx, "granular walls", nc * PX_GRAN_CTR_COUNT, s->ssize);
    s->c_radius = px_mem_calloc(s->ctx, "granular walls", nc, sizeof(double));
    s->seg_cfirst = px_mem_alloc(s->ctx, "granular walls", nc * sizeof(int));
    s->seg_ccount = px_mem_alloc(s->ctx, "granular walls", nc * sizeof(int));
    s->cforce = px_mem_calloc(s->ctx, "granular walls", 2 * nc, sizeof(double));
    s->cforce_t = px_mem_calloc(s->ctx, "granular walls", 2 * nc * (size_t)s->nranges, sizeof(double));
    if (!s->frames || !s->frames_ref || !s->sframes || !s->c_radius || !s->seg_cfirst ||
        !s->seg_ccount || !s->cforce || !s->cforce_t)
      return PX_STATUS_NOMEM;
    for (c = 0; c < nc; ++c) {
      const struct px_gran_contour *C = &g->contours[c];
      const struct px_gran_motion *m =
          s->motions && C->body >= 0 && (size_t)C->body < s->nbodies ? &s->motions[C->body] : NULL;
      size_t k;
      s->seg_cfirst[c] = (int)C->first;
      s->seg_ccount[c] = (int)C->count;
      for (k = C->first; k < C->first + C->count; ++k) {
        const double dx = g->ax[k] - (m ? m->pivot[0] : 0), dy = g->ay[k] - (m ? m->pivot[1] : 0);
        const double rr = hypot(dx, dy);
        if (rr > s->c_radius[c]) s->c_radius[c] = rr;
      }
    }
    if (!(s->seg_ax = px_gran_to_state(s, g->ax, g->nseg)) ||
        !(s->seg_ay = px_gran_to_state(s, g->ay, g->nseg)) ||
        !(s->seg_tx = px_gran_to_state(s, g->tx, g->nseg)) ||
        !(s->seg_ty = px_gran_to_state(s, g->ty, g->nseg)) ||
        !(s->seg_len = px_gran_to_state(s, g->len, g->nseg)) ||
        !(s->seg_tpx = px_gran_to_state(s, g->tpx, g->nseg)) ||
        !(s->seg_tpy = px_gran_to_state(s, g->tpy, g->nseg)))
      return PX_STATUS_NOMEM;
    px_gran_sys_frames(s, s->t);
    /* every particle inside the media region and clear of the walls */
    for (i = 0; i < s->n; ++i) {
      double rec[8], d;
      s->ops->get(s, i, rec);
      s->fail_id = (int32_t)rec[PX_GRAN_P_ID];
      if (!px_gran_geom_inside(g, s->frames, rec[0], rec[1]))
        return px_context_fail(s->ctx, PX_STATUS_CONFIG,
                               "particle %d at (%g, %g) is outside the region of the media "
                               "(outside the container or inside a part)",
                               (int)s->id[i], rec[0], rec[1]);
      d = px_gran_geom_distance(g, s->frames, rec[0], rec[1], rec[PX_GRAN_P_R]);
      if (d < rec[PX_GRAN_P_R] * (1 - 1e-6))
        return px_context_fail(s->ctx, PX_STATUS_CONFIG,
                               "particle %d at (%g, %g) with radius %g overlaps a boundary (its "
                               "centre is %g from it)",
                               (int)s->id[i], rec[0], rec[1], rec[PX_GRAN_P_R], d);
      s->fail_id = -1;
    }
  }
  /* event buffers */
  s->ev_cap = PX_GRAN_EV_CAP_MIN + 3 * PX_GRAN_WSLOTS * 64;
  s->ev_i = px_mem_alloc(s->ctx, "granular events", (size_t)s->nranges * s->ev_cap * PX_GRAN_EVI * sizeof(int));
  s->ev_r = px_mem_alloc(s->ctx, "granular events", (size_t)s->nranges * s->ev_cap * PX_GRAN_EVR * s->csize);
  s->ev_n = px_mem_calloc(s->ctx, "granular events", (size_t)s->nranges, sizeof(size_t));
  if (!s->ev_i || !s->ev_r || !s->ev_n) return PX_STATUS_NOMEM;

  PX_TRY(px_gran_sys_rebuild(s));
  /* initial overlaps */
  {
    int32_t k;
    for (i = 0; i < s->n; ++i)
      for (k = s->pstart[i]; k < s->pstart[i + 1]; ++k) {
        double a[8], b[8];
        s->ops->get(s, i, a);
        s->ops->get(s, (size_t)s->pj[k], b);
        if (hypot(a[0] - b[0], a[1] - b[1]) <
            (a[PX_GRAN_P_R] + b[PX_GRAN_P_R]) * (1 - 1e-6)) {
          s->fail_id = (int32_t)(a[PX_GRAN_P_ID] > b[PX_GRAN_P_ID] ? a[PX_GRAN_P_ID] : b[PX_GRAN_P_ID]);
          return px_context_fail(s->ctx, PX_STATUS_CONFIG,
                                 "particles %d at (%g, %g) and %d at (%g, %g) overlap by %g m at "
                                 "the start (radii %g and %g)",
                                 (int)a[PX_GRAN_P_ID], a[0], a[1], (int)b[PX_GRAN_P_ID], b[0],
                                 b[1], a[PX_GRAN_P_R] + b[PX_GRAN_P_R] - hypot(a[0] - b[0], a[1] - b[1]),
                                 a[PX_GRAN_P_R], b[PX_GRAN_P_R]);
        }
      }
  }
  /* accelerations at the start */
  {
    void *st[5] = {s->x, s->y, s->vx, s->vy, s->w};
    void *acc[3] = {s->fx, s->fy, s->tq};
    /* no commit: the histories start with the first step */
    PX_TRY(s->ops->forces(s, st, acc, 0, 0));
  }
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------ step */

/* Largest displacement of any point of a contour since the last rebuild. */
static double px_gran_wall_drift_frames(const struct px_gran_sys *s, const double *frames) {
  double best = 0;
  size_t c;
  if (!s->geom) return 0;
  for (c = 0; c < s->geom->ncontours; ++c) {
    const double *f = frames + c * PX_GRAN_CTR_COUNT, *r = s->frames_ref + c * PX_GRAN_CTR_COUNT;
    const double dphi = atan2(f[PX_GRAN_CTR_SIN] * r[PX_GRAN_CTR_COS] - f[PX_GRAN_CTR_COS] * r[PX_GRAN_CTR_SIN],
                              f[PX_GRAN_CTR_COS] * r[PX_GRAN_CTR_COS] + f[PX_GRAN_CTR_SIN] * r[PX_GRAN_CTR_SIN]);
    const double d = hypot(f[PX_GRAN_CTR_DX] - r[PX_GRAN_CTR_DX], f[PX_GRAN_CTR_DY] - r[PX_GRAN_CTR_DY]) +
                     fabs(dphi) * s->c_radius[c];
    if (d > best) best = d;
  }
  return best;
}

static double px_gran_wall_drift(const struct px_gran_sys *s) {
  return px_gran_wall_drift_frames(s, s->frames);
}

/* Wall drift since the last rebuild at a later time t. */
static double px_gran_wall_drift_next(const struct px_gran_sys *s, double t) {
  double f[PX_GRAN_CTR_COUNT * 8], best = 0;
  size_t c;
  if (!s->geom) return 0;
  for (c = 0; c < s->geom->ncontours; ++c) {
    const int b = s->geom->contours[c].body;
    const double *r = s->frames_ref + c * PX_GRAN_CTR_COUNT;
    double dphi, d;
    if (!s->motions || b < 0 || (size_t)b >= s->nbodies) continue;
    px_gran_motion_frame(&s->motions[b], t, f);
    dphi = atan2(f[PX_GRAN_CTR_SIN] * r[PX_GRAN_CTR_COS] - f[PX_GRAN_CTR_COS] * r[PX_GRAN_CTR_SIN],
                 f[PX_GRAN_CTR_COS] * r[PX_GRAN_CTR_COS] + f[PX_GRAN_CTR_SIN] * r[PX_GRAN_CTR_SIN]);
    d = hypot(f[PX_GRAN_CTR_DX] - r[PX_GRAN_CTR_DX], f[PX_GRAN_CTR_DY] - r[PX_GRAN_CTR_DY]) +
        fabs(dphi) * s->c_radius[c];
    if (d > best) best = d;
  }
  return best;
}

/* Windows of steps lasting about 0.2 s: the rate of all threads
 * (tune_rate[1]) and of one thread (tune_rate[0]) are measured in turn (one
 * window of one thread every 16 windows), and the faster one is used. A
 * thread count change does not change any result. */
static void px_gran_tune_threads(struct px_gran_sys *s) {
  const double now = px_time_now();
  double dt;
  if (s->tune_steps == 0) s->tune_t0 = now;
  ++s->tune_steps;
  dt = now - s->tune_t0;
  if (dt < 0.2 && s->tune_steps < 100000) return;
  {
    const int k = s->active > 1 ? 1 : 0;
    const double rate = (double)s->tune_steps / dt;
    s->tune_rate[k] = s->tune_rate[k] > 0 ? 0.5 * (s->tune_rate[k] + rate) : rate;
  }
  ++s->tune_windows;
  s->tune_steps = 0;
  if (s->tune_windows % 16 == 1) {
    /* probe the other setting for one window */
    s->active = s->active > 1 ? 1 : s->threads;
  } else if (s->tune_rate[0] > 0 && s->tune_rate[1] > 0) {
    s->active = s->tune_rate[1] >= s->tune_rate[0] ? s->threads : 1;
  }
}

enum px_status px_gran_sys_check_finite(struct px_gran_sys *s, long step, double t) {
  double et, er, rec[8];
  long bad;
  s->ops->energy(s, &et, &er, &bad);
  if (bad < 0) return PX_STATUS_OK;
  s->ops->get(s, (size_t)bad, rec);
  return px_context_fail(s->ctx, PX_STATUS_NUMERIC,
                         "step %ld (t = %g s): particle %d has a non-finite position or "
                         "velocity (x = %g, y = %g, vx = %g, vy = %g, w = %g): the time step is "
                         "too large for the stiffness, or the input is wrong",
                         step, t, (int)rec[PX_GRAN_P_ID], rec[0], rec[1], rec[2], rec[3], rec[4]);
}

enum px_status px_gran_sys_step(struct px_gran_sys *s) {
  double maxd2 = 0;
  const double tnew = s->t + s->dt;
  if (s->integrator == PX_GRAN_INTEGRATOR_VERLET) {
    double maxv2 = 0;
    /* the rebuild is decided at the end of the previous step, with a margin
     * for this step's drift: one parallel region per step */
    if (s->need_rebuild) PX_TRY(px_gran_sys_rebuild(s));
    px_gran_sys_frames(s, tnew);
    PX_TRY(s->ops->vv_step(s, &maxd2, &maxv2));
    /* a value became non-finite in this step (the loops flag it) */
    if (maxv2 != maxv2) PX_TRY(px_gran_sys_check_finite(s, s->step + 1, tnew));
    {
      const double margin = 2 * sqrt(maxv2) * s->dt + 1e-3 * s->skin;
      const double d = sqrt(maxd2) + margin;
      const double dw = px_gran_wall_drift_next(s, s->t + 2 * s->dt);
      if (2 * d > s->skin || d + dw > s->skin) s->need_rebuild = 1;
    }
  } else {
    void *st[5], *acc[3];
    int d;
    if (s->need_rebuild) PX_TRY(px_gran_sys_rebuild(s));
    s->ops->abm_predict(s);
    px_gran_sys_frames(s, tnew);
    for (d = 0; d < 5; ++d) st[d] = s->xp[d];
    acc[0] = s->fa[0], acc[1] = s->fa[1], acc[2] = s->fa[2];
    PX_TRY(s->ops->forces(s, st, acc, 0, 0));
    s->ops->abm_correct(s, &maxd2);
    /* a value became non-finite in this step (the corrector flags it) */
    if (maxd2 != maxd2) PX_TRY(px_gran_sys_check_finite(s, s->step + 1, tnew));
    st[0] = s->x, st[1] = s->y, st[2] = s->vx, st[3] = s->vy, st[4] = s->w;
    acc[0] = s->fx, acc[1] = s->fy, acc[2] = s->tq;
    PX_TRY(s->ops->forces(s, st, acc, 1, 0));
    ++s->abm_steps;
    {
      /* checked for the next step, with a margin for its motion */
      const double dd = sqrt(maxd2), dw = px_gran_wall_drift(s);
      if (2 * dd > 0.8 * s->skin || dd + dw > 0.8 * s->skin) s->need_rebuild = 1;
    }
  }
  px_gran_sys_events(s);
  s->t = tnew;
  ++s->step;
  if (s->active > 1) ++s->steps_parallel;
  if (s->threads > 1 && s->tune) px_gran_tune_threads(s);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------ events */

/* Finnie's angle function (Finnie 1960, "Erosion of surfaces by solid
 * particles", Wear 3:87–103): f = sin 2a - 3 sin^2 a for tan a <= 1/3,
 * cos^2 a / 3 above; a = impact angle from the surface. Zero at normal
 * incidence (a ductile-erosion law). */
static double px_gran_finnie_f(double vn, double vt) {
  const double a = atan2(vn, fabs(vt));
  if (tan(a) <= 1.0 / 3.0) return sin(2 * a) - 3 * sin(a) * sin(a);
  return cos(a) * cos(a) / 3;
}

void px_gran_sys_events(struct px_gran_sys *s) {
  int t;
  struct px_gran_stats *S = &s->stats;
  for (t = 0; t < s->nranges; ++t) {
    const int *ei = s->ev_i + (size_t)t * s->ev_cap * PX_GRAN_EVI;
    const size_t base = (size_t)t * s->ev_cap * PX_GRAN_EVR;
    size_t e;
    for (e = 0; e < s->ev_n[t]; ++e) {
      const int type = ei[e * PX_GRAN_EVI], seg = ei[e * PX_GRAN_EVI + 1];
      double r0 = px_gran_rd(s->ev_r, base + e * PX_GRAN_EVR + 0, s->csize);
      double r1 = px_gran_rd(s->ev_r, base + e * PX_GRAN_EVR + 1, s->csize);
      double r2 = px_gran_rd(s->ev_r, base + e * PX_GRAN_EVR + 2, s->csize);
      double r3 = px_gran_rd(s->ev_r, base + e * PX_GRAN_EVR + 3, s->csize);
      /* end of the step the event belongs to */
      const double tend = (double)(ei[e * PX_GRAN_EVI + 3] + 1) * s->dt;
      if (!s->stats_on || seg < 0) continue;
      if (type == PX_GRAN_EV_IMPACT) {
        const double t0 = tend - r3;
        if (t0 < s->sspec.start || r0 < s->sspec.vmin) continue;
        S->impacts[seg] += 1;
        S->vn_sum[seg] += r0;
        S->vn2_sum[seg] += r0 * r0;
        if (r0 > S->vn_max[seg]) S->vn_max[seg] = r0;
        S->vt_sum[seg] += r1;
        S->en[seg] += 0.5 * r2 * r0 * r0;
        S->et[seg] += 0.5 * r2 * r1 * r1;
        S->finnie[seg] += r2 * pow(hypot(r0, r1), s->sspec.finnie_n) * px_gran_finnie_f(r0, r1);
        if (S->t_first[seg] < 0) S->t_first[seg] = t0;
        S->t_last[seg] = t0;
        if (s->impact_log)
          s->impact_log(s->impact_log_user, seg, ei[e * PX_GRAN_EVI + 2], t0, r0, r1, r2);
      } else if (type == PX_GRAN_EV_FLUSH) {
        if (tend < s->sspec.start) continue;
        S->impulse[seg] += r0;
        S->slide[seg] += r1;
        S->archard[seg] += r2;
        S->ctime[seg] += r3;
      } else if (type == PX_GRAN_EV_END) {
        const double tstart = tend - s->dt - r0;
        if (tstart < s->sspec.start) continue;
        S->dur_sum[seg] += r0;
        S->ended[seg] += 1;
      }
    }
    s->ev_n[t] = 0;
  }
}

enum px_status px_gran_sys_stats_enable(struct px_gran_sys *s,
                                        const struct px_gran_stats_spec *spec) {
  struct px_gran_stats *st = &s->stats;
  double **v[] = {&st->impacts, &st->vn_sum, &st->vn2_sum, &st->vn_max, &st->vt_sum,
                  &st->en,      &st->et,     &st->finnie,  &st->impulse, &st->slide,
                  &st->archard, &st->ctime,  &st->dur_sum, &st->ended,  &st->t_first,
                  &st->t_last};
  size_t k, nseg = s->geom ? s->geom->nseg : 0;
  s->sspec = *spec;
  px_gran_stats_free(s);
  for (k = 0; k < sizeof v / sizeof v[0]; ++k) {
    *v[k] = px_mem_calloc(s->ctx, "granular statistics", nseg ? nseg : 1, sizeof(double));
    if (!*v[k]) return PX_STATUS_NOMEM;
  }
  for (k = 0; k < nseg; ++k) st->t_first[k] = st->t_last[k] = -1;
  st->t_begin = spec->start;
  s->stats_on = 1;
  return PX_STATUS_OK;
}

void px_gran_sys_stats_flush(struct px_gran_sys *s) {
  size_t q;
  int evi[PX_GRAN_WEVENTS * PX_GRAN_EVI];
  double evr[PX_GRAN_WEVENTS * PX_GRAN_EVR];
  if (!s->geom) return;
  for (q = 0; q < s->n; ++q) {
    int k, nev = 0;
    for (k = 0; k < PX_GRAN_WSLOTS; ++k) {
      const size_t at = q * PX_GRAN_WSLOTS + (size_t)k;
      if (s->slots.seg[at] < 0) continue;
      evi[nev * PX_GRAN_EVI] = PX_GRAN_EV_FLUSH;
      evi[nev * PX_GRAN_EVI + 1] = s->slots.seg[at];
      evr[nev * PX_GRAN_EVR + 0] = px_gran_rd(s->slots.imp, at, s->csize);
      evr[nev * PX_GRAN_EVR + 1] = px_gran_rd(s->slots.slw, at, s->csize);
      evr[nev * PX_GRAN_EVR + 2] = px_gran_rd(s->slots.arc, at, s->csize);
      evr[nev * PX_GRAN_EVR + 3] = px_gran_rd(s->slots.tim, at, s->csize);
      px_gran_copy_real(s->slots.imp, at, s->slots.imp, at, s->csize, 0);
      px_gran_copy_real(s->slots.slw, at, s->slots.slw, at, s->csize, 0);
      px_gran_copy_real(s->slots.arc, at, s->slots.arc, at, s->csize, 0);
      px_gran_copy_real(s->slots.tim, at, s->slots.tim, at, s->csize, 0);
      ++nev;
    }
    if (s->stats_on && s->t >= s->sspec.start)
      for (k = 0; k < nev; ++k) {
        const int seg = evi[k * PX_GRAN_EVI + 1];
        s->stats.impulse[seg] += evr[k * PX_GRAN_EVR + 0];
        s->stats.slide[seg] += evr[k * PX_GRAN_EVR + 1];
        s->stats.archard[seg] += evr[k * PX_GRAN_EVR + 2];
        s->stats.ctime[seg] += evr[k * PX_GRAN_EVR + 3];
      }
  }
}

void px_gran_sys_stats_pending(const struct px_gran_sys *s, double *impulse, double *slide,
                               double *archard, double *ctime) {
  size_t at;
  /* the same condition and order as px_gran_sys_stats_flush */
  if (!s->geom || !s->stats_on || !(s->t >= s->sspec.start)) return;
  for (at = 0; at < s->n * PX_GRAN_WSLOTS; ++at) {
    const int seg = s->slots.seg[at];
    if (seg < 0) continue;
    impulse[seg] += px_gran_rd(s->slots.imp, at, s->csize);
    slide[seg] += px_gran_rd(s->slots.slw, at, s->csize);
    archard[seg] += px_gran_rd(s->slots.arc, at, s->csize);
    ctime[seg] += px_gran_rd(s->slots.tim, at, s->csize);
  }
}

void px_gran_sys_wall_force(const struct px_gran_sys *s, size_t c, double f[2]) {
  f[0] = s->cforce ? s->cforce[2 * c] : 0;
  f[1] = s->cforce ? s->cforce[2 * c + 1] : 0;
}

/* ------------------------------------------------------------------ queries */

double px_gran_sys_kinetic(const struct px_gran_sys *s) {
  double et, er;
  long bad;
  s->ops->energy(s, &et, &er, &bad);
  return et + er;
}

double px_gran_sys_potential(const struct px_gran_sys *s) {
  double e = 0;
  size_t i;
  for (i = 0; i < s->n; ++i) {
    double rec[8];
    s->ops->get(s, i, rec);
    e -= rec[PX_GRAN_P_M] * (s->gravity[0] * rec[0] + s->gravity[1] * rec[1]);
  }
  return e;
}

static int px_gran_pair_cmp(const void *a, const void *b) {
  const int32_t *p = a, *q = b;
  if (p[0] != q[0]) return p[0] < q[0] ? -1 : 1;
  if (p[1] != q[1]) return p[1] < q[1] ? -1 : 1;
  return 0;
}

static enum px_status px_gran_push_pair(struct px_gran_sys *s, int32_t **v, size_t *n, size_t *cap,
                                        int32_t a, int32_t b) {
  if (*n == *cap) {
    size_t c = *cap ? 2 * *cap : 256;
    int32_t *g = px_mem_realloc(s->ctx, "granular contacts", *v, 2 * c * sizeof *g);
    if (!g) return PX_STATUS_NOMEM;
    *v = g;
    *cap = c;
  }
  (*v)[2 * *n] = a < b ? a : b;
  (*v)[2 * *n + 1] = a < b ? b : a;
  ++*n;
  return PX_STATUS_OK;
}

enum px_status px_gran_sys_contacts_brute(const struct px_gran_sys *s, int32_t **pairs,
                                          size_t *n) {
  size_t i, j, cap = 0;
  struct px_gran_sys *m = (struct px_gran_sys *)(size_t)s;
  *pairs = NULL;
  *n = 0;
  for (i = 0; i < s->n; ++i) {
    double a[8];
    s->ops->get(s, i, a);
    for (j = i + 1; j < s->n; ++j) {
      double b[8];
      s->ops->get(s, j, b);
      if (hypot(a[0] - b[0], a[1] - b[1]) < a[PX_GRAN_P_R] + b[PX_GRAN_P_R])
        PX_TRY(px_gran_push_pair(m, pairs, n, &cap, s->id[i], s->id[j]));
    }
  }
  qsort(*pairs, *n, 2 * sizeof(int32_t), px_gran_pair_cmp);
  return PX_STATUS_OK;
}

enum px_status px_gran_sys_contacts_list(const struct px_gran_sys *s, int32_t **pairs,
                                         size_t *n) {
  size_t i, cap = 0;
  struct px_gran_sys *m = (struct px_gran_sys *)(size_t)s;
  *pairs = NULL;
  *n = 0;
  for (i = 0; i < s->n; ++i) {
    int32_t k;
    double a[8];
    s->ops->get(s, i, a);
    for (k = s->pstart[i]; k < s->pstart[i + 1]; ++k) {
      double b[8];
      s->ops->get(s, (size_t)s->pj[k], b);
      if (hypot(a[0] - b[0], a[1] - b[1]) < a[PX_GRAN_P_R] + b[PX_GRAN_P_R])
        PX_TRY(px_gran_push_pair(m, pairs, n, &cap, s->id[i], s->id[s->pj[k]]));
    }
  }
  qsort(*pairs, *n, 2 * sizeof(int32_t), px_gran_pair_cmp);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------ exports */

void px_gran_sys_export(const struct px_gran_sys *s, double *x, double *y, double *vx, double *vy,
                        double *w, double *r, double *m, double *id) {
  size_t i;
  for (i = 0; i < s->n; ++i) {
    double rec[8];
    s->ops->get(s, i, rec);
    if (x) x[i] = rec[PX_GRAN_P_X];
    if (y) y[i] = rec[PX_GRAN_P_Y];
    if (vx) vx[i] = rec[PX_GRAN_P_VX];
    if (vy) vy[i] = rec[PX_GRAN_P_VY];
    if (w) w[i] = rec[PX_GRAN_P_W];
    if (r) r[i] = rec[PX_GRAN_P_R];
    if (m) m[i] = rec[PX_GRAN_P_M];
    if (id) id[i] = rec[PX_GRAN_P_ID];
  }
}

double px_gran_sys_coordination(const struct px_gran_sys *s, double *z) {
  size_t i, total = 0;
  int32_t k;
  for (i = 0; i < s->n; ++i) z[i] = 0;
  for (i = 0; i < s->n; ++i) {
    double a[8];
    s->ops->get(s, i, a);
    for (k = s->pstart[i]; k < s->pstart[i + 1]; ++k) {
      double b[8];
      s->ops->get(s, (size_t)s->pj[k], b);
      if (hypot(a[0] - b[0], a[1] - b[1]) < a[PX_GRAN_P_R] + b[PX_GRAN_P_R]) {
        z[i] += 1;
        z[s->pj[k]] += 1;
        total += 2;
      }
    }
    if (s->geom) {
      int q;
      for (q = 0; q < PX_GRAN_WSLOTS; ++q)
        if (s->slots.seg[i * PX_GRAN_WSLOTS + (size_t)q] >= 0) {
          z[i] += 1;
          total += 1;
        }
    }
  }
  return s->n ? (double)total / (double)s->n : 0;
}

/* ------------------------------------------------------------------ checkpoints */

#define PX_GRAN_CK_SCALARS 10

enum px_status px_gran_sys_save(const struct px_gran_sys *s, struct px_checkpoint_writer *w) {
  struct px_gran_arr a[PX_GRAN_MAX_ARRAYS];
  struct px_gran_sys *m = (struct px_gran_sys *)(size_t)s;
  size_t na = px_gran_arrays(m, a), k;
  const size_t n = s->n, np = s->npairs, cs = s->csize;
  double sc[PX_GRAN_CK_SCALARS];
  sc[0] = s->t, sc[1] = s->dt, sc[2] = (double)s->step, sc[3] = (double)s->rebuilds;
  sc[4] = s->need_rebuild, sc[5] = (double)s->abm_steps, sc[6] = (double)n, sc[7] = (double)np;
  sc[8] = (double)s->nwcand, sc[9] = (double)s->nnear;
  PX_TRY(px_checkpoint_write(w, "granular.scalars", PX_DTYPE_F64, PX_GRAN_CK_SCALARS, sc));
  for (k = 0; k < na; ++k)
    if (a[k].name)
      PX_TRY(px_checkpoint_write(w, a[k].name, PX_DTYPE_U8, n * a[k].esize * a[k].per, *a[k].p));
  PX_TRY(px_checkpoint_write(w, "granular.where", PX_DTYPE_I32, n, s->where));
  PX_TRY(px_checkpoint_write(w, "granular.pstart", PX_DTYPE_I32, n + 1, s->pstart));
  PX_TRY(px_checkpoint_write(w, "granular.pi", PX_DTYPE_I32, np, s->pi));
  PX_TRY(px_checkpoint_write(w, "granular.pj", PX_DTYPE_I32, np, s->pj));
  {
    const char *names[] = {"granular.pxi", "granular.pth", "granular.pdm", "granular.pdp",
                           "granular.pri", "granular.prj", "granular.pme", "granular.pre",
                           "granular.pdxr", "granular.pdyr"};
    const void *arrs[] = {s->pxi, s->pth, s->pdm, s->pdp, s->pri,
                          s->prj, s->pme, s->pre, s->pdxr, s->pdyr};
    for (k = 0; k < 10; ++k) PX_TRY(px_checkpoint_write(w, names[k], PX_DTYPE_U8, np * cs, arrs[k]));
  }
  PX_TRY(px_checkpoint_write(w, "granular.wstart", PX_DTYPE_I32, n + 1, s->wstart));
  PX_TRY(px_checkpoint_write(w, "granular.wcand", PX_DTYPE_I32, s->nwcand, s->wcand));
  PX_TRY(px_checkpoint_write(w, "granular.near", PX_DTYPE_I32, s->nnear, s->near));
  if (s->geom) {
    PX_TRY(px_checkpoint_write(w, "granular.frames_ref", PX_DTYPE_F64,
                               s->ncontours * PX_GRAN_CTR_COUNT, s->frames_ref));
    PX_TRY(px_checkpoint_write(w, "granular.cforce", PX_DTYPE_F64, 2 * s->ncontours, s->cforce));
  }
  if (s->stats_on) {
    const struct px_gran_stats *S = &s->stats;
    const double *v[] = {S->impacts, S->vn_sum, S->vn2_sum, S->vn_max, S->vt_sum, S->en,
                         S->et,      S->finnie, S->impulse, S->slide,  S->archard, S->ctime,
                         S->dur_sum, S->ended,  S->t_first, S->t_last};
    const size_t nseg = s->geom ? s->geom->nseg : 0;
    char name[48];
    for (k = 0; k < sizeof v / sizeof v[0]; ++k) {
      snprintf(name, sizeof name, "granular.stats.%zu", k);
      PX_TRY(px_checkpoint_write(w, name, PX_DTYPE_F64, nseg, v[k]));
    }
  }
  return PX_STATUS_OK;
}

/* ---- loading: the file is untrusted ----
 *
 * A checkpoint's CRCs may be right and its contents forged: every count is
 * checked against the case (and against the section's size in the file
 * before anything is allocated for it), every index against the counts,
 * every scalar for range and integrality, every real for finiteness, and
 * the discs' radii and masses against those the case makes, before the
 * state is used. A failure is PX_STATUS_FORMAT naming the section. */

static enum px_status px_gran_ck_bad(struct px_gran_sys *s, const char *section, const char *fmt,
                                     ...) PX_PRINTF(3, 4);
static enum px_status px_gran_ck_bad(struct px_gran_sys *s, const char *section, const char *fmt,
                                     ...) {
  char msg[512];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return px_context_fail(s->ctx, PX_STATUS_FORMAT, "checkpoint section '%s': %s (a damaged or "
                         "forged checkpoint)", section, msg);
}

/* v is an integer in [lo, hi] (so it converts exactly). */
static int px_gran_ck_int(double v, double lo, double hi) {
  return v >= lo && v <= hi && v == floor(v);
}

/* The section holds `count` elements of `type` (checked before its buffer
 * is allocated: the count comes from another section). */
static enum px_status px_gran_ck_count(struct px_gran_sys *s, struct px_checkpoint *ck,
                                       const char *name, enum px_dtype type, size_t count) {
  enum px_dtype t;
  uint64_t have = 0;
  PX_TRY(px_checkpoint_find(ck, name, &t, &have));
  if (t != type || have != (uint64_t)count)
    return px_gran_ck_bad(s, name, "%llu values of type %s, expected %zu of type %s",
                          (unsigned long long)have, px_dtype_name(t), count,
                          px_dtype_name(type));
  return PX_STATUS_OK;
}

/* Read a section of `count` elements into *p, (re)allocated to fit, after
 * checking the count against the file. */
static enum px_status px_gran_ck_read(struct px_gran_sys *s, struct px_checkpoint *ck,
                                      const char *name, enum px_dtype type, size_t count,
                                      void **p) {
  PX_TRY(px_gran_ck_count(s, ck, name, type, count));
  PX_TRY(px_gran_ensure(s, p, (count ? count : 1) * px_dtype_size(type), "granular checkpoint"));
  return px_checkpoint_read(ck, name, type, count, *p);
}

/* Every one of the count reals of es bytes at p is finite (and, with
 * lim > 0, |v| <= lim); the first that is not, or -1. */
static long px_gran_ck_finite(const void *p, size_t count, size_t es, double lim) {
  size_t k;
  for (k = 0; k < count; ++k) {
    const double v = px_gran_rd(p, k, es);
    if (!isfinite(v) || (lim > 0 && !(fabs(v) <= lim))) return (long)k;
  }
  return -1;
}

enum px_status px_gran_sys_load(struct px_gran_sys *s, struct px_checkpoint *ck) {
  struct px_gran_arr a[PX_GRAN_MAX_ARRAYS];
  size_t na = px_gran_arrays(s, a), k, n, np, nw, nn, i;
  double sc[PX_GRAN_CK_SCALARS], tc;
  const size_t cs = s->csize, ss = s->ssize, W = PX_GRAN_WSLOTS;
  const size_t nseg = s->geom ? s->geom->nseg : 0;
  const double step_max = 2147483647.0; /* the kernels count steps in int */
  double *mine = NULL;                    /* the case's r, m, 1/m, 1/I by id */
  unsigned char *seen = NULL;
  enum px_status st = PX_STATUS_OK;
  const char *sec = "granular.scalars";

  /* scalars: counts against the case, integers where integers belong */
  PX_TRY(px_gran_ck_count(s, ck, sec, PX_DTYPE_F64, PX_GRAN_CK_SCALARS));
  PX_TRY(px_checkpoint_read(ck, sec, PX_DTYPE_F64, PX_GRAN_CK_SCALARS, sc));
  if (!px_gran_ck_int(sc[6], 0, (double)PX_GRAN_N_MAX))
    return px_gran_ck_bad(s, sec, "particle count %g is not a count", sc[6]);
  n = (size_t)sc[6];
  if (n != s->n)
    return px_context_fail(s->ctx, PX_STATUS_FORMAT,
                           "the checkpoint holds %zu particles but the case makes %zu (was the "
                           "case's media changed?)",
                           n, s->n);
  if (!px_gran_ck_int(sc[2], 0, step_max) || (double)px_checkpoint_step(ck) != sc[2])
    return px_gran_ck_bad(s, sec, "step %g: not the checkpoint's step %llu (or beyond %.0f)",
                          sc[2], (unsigned long long)px_checkpoint_step(ck), step_max);
  tc = px_gran_sys_contact_time(s);
  if (!(sc[0] >= 0) || !isfinite(sc[0]) || !(sc[1] > 0) || !(sc[1] <= tc / 5 * (1 + 1e-9)) ||
      !(sc[1] >= tc * 1e-6 * (1 - 1e-9)))
    return px_gran_ck_bad(s, sec,
                          "time %g s and time step %g s: needs t >= 0 and dt in [t_c / 1e6, "
                          "t_c / 5] with t_c = %g s of this case",
                          sc[0], sc[1], tc);
  if (!px_gran_ck_int(sc[3], 0, 9007199254740992.0) || !px_gran_ck_int(sc[4], 0, 1) ||
      !px_gran_ck_int(sc[5], 0, sc[2]))
    return px_gran_ck_bad(s, sec, "rebuilds %g, rebuild flag %g, ABM steps %g: not counts (or "
                          "more ABM steps than steps)",
                          sc[3], sc[4], sc[5]);
  if (!px_gran_ck_int(sc[7], 0, (double)INT32_MAX) || !px_gran_ck_int(sc[8], 0, (double)INT32_MAX) ||
      !px_gran_ck_int(sc[9], 0, (double)n))
    return px_gran_ck_bad(s, sec, "pair count %g, wall candidates %g, near-wall particles %g: "
                          "not counts within %d, %d and the %zu particles",
                          sc[7], sc[8], sc[9], INT32_MAX, INT32_MAX, n);
  np = (size_t)sc[7];
  nw = (size_t)sc[8];
  nn = (size_t)sc[9];
  if (!s->geom && (nw || nn))
    return px_gran_ck_bad(s, sec, "%zu wall candidates for a case without contours", nw);

  /* the case's radii and masses by persistent id, before they are replaced */
  mine = px_mem_alloc(s->ctx, "granular checkpoint", (n ? n : 1) * 4 * sizeof *mine);
  seen = px_mem_calloc(s->ctx, "granular checkpoint", n ? n : 1, 1);
  if (!mine || !seen) {
    st = PX_STATUS_NOMEM;
    goto done;
  }
  for (i = 0; i < n; ++i) {
    const size_t id = (size_t)s->id[i];
    mine[4 * id + 0] = px_gran_rd(s->r, i, cs);
    mine[4 * id + 1] = px_gran_rd(s->m, i, cs);
    mine[4 * id + 2] = px_gran_rd(s->im, i, cs);
    mine[4 * id + 3] = px_gran_rd(s->iI, i, cs);
  }

  /* per-particle arrays (n of each: the case's count) */
  for (k = 0; k < na; ++k) {
    const size_t bytes = n * a[k].esize * a[k].per;
    if (!a[k].name) continue;
    st = px_gran_ck_count(s, ck, a[k].name, PX_DTYPE_U8, bytes);
    if (st == PX_STATUS_OK) st = px_checkpoint_read(ck, a[k].name, PX_DTYPE_U8, bytes, *a[k].p);
    if (st != PX_STATUS_OK) goto done;
  }
  sec = "granular.where";
  st = px_gran_ck_count(s, ck, sec, PX_DTYPE_I32, n);
  if (st == PX_STATUS_OK) st = px_checkpoint_read(ck, sec, PX_DTYPE_I32, n, s->where);
  if (st != PX_STATUS_OK) goto done;
  /* ids: a permutation of 0 .. n-1, where its inverse */
  for (i = 0; i < n; ++i) {
    const int32_t id = s->id[i];
    if (id < 0 || (size_t)id >= n || seen[id]) {
      st = px_gran_ck_bad(s, "granular.p.id", "slot %zu: id %d is out of range or repeated", i,
                          (int)id);
      goto done;
    }
    seen[id] = 1;
    if (s->where[id] != (int32_t)i) {
      st = px_gran_ck_bad(s, sec, "id %d: slot %d, but it is in slot %zu", (int)id,
                          (int)s->where[id], i);
      goto done;
    }
  }
  /* radius and mass are the case's; the state finite */
  for (i = 0; i < n; ++i) {
    const size_t id = (size_t)s->id[i];
    if (px_gran_rd(s->r, i, cs) != mine[4 * id] || px_gran_rd(s->m, i, cs) != mine[4 * id + 1] ||
        px_gran_rd(s->im, i, cs) != mine[4 * id + 2] ||
        px_gran_rd(s->iI, i, cs) != mine[4 * id + 3]) {
      st = px_gran_ck_bad(s, "granular.p.r", "particle %zu: radius %g m and mass %g kg are not "
                          "the case's %g m and %g kg",
                          id, px_gran_rd(s->r, i, cs), px_gran_rd(s->m, i, cs), mine[4 * id],
                          mine[4 * id + 1]);
      goto done;
    }
  }
  for (k = 0; k < na; ++k) {
    long bad;
    double lim;
    /* reals: state (ss) or contact precision (cs); positions also bounded */
    if (!a[k].name || a[k].p == (void **)&s->id || a[k].p == (void **)&s->slots.seg ||
        a[k].p == (void **)&s->slots.seg0 || a[k].p == (void **)&s->slots.step0)
      continue;
    lim = (a[k].p == &s->x || a[k].p == &s->y || a[k].p == &s->xr || a[k].p == &s->yr)
              ? PX_GRAN_COORD_MAX
              : 0;
    bad = px_gran_ck_finite(*a[k].p, n * a[k].per, a[k].esize, lim);
    if (bad >= 0) {
      st = px_gran_ck_bad(s, a[k].name, "value %ld = %g is not finite%s", bad,
                          px_gran_rd(*a[k].p, (size_t)bad, a[k].esize),
                          lim > 0 ? " or beyond 1e12 m" : "");
      goto done;
    }
  }
  (void)ss;
  /* wall slots: segments of this geometry (or -1), start steps not after
   * the checkpoint's */
  for (i = 0; i < n * W; ++i) {
    const int sg = s->slots.seg[i], s0 = s->slots.seg0[i], t0 = s->slots.step0[i];
    if (sg < -1 || (sg >= 0 && (size_t)sg >= nseg) || s0 < -1 || (s0 >= 0 && (size_t)s0 >= nseg) ||
        t0 < 0 || (double)t0 > sc[2]) {
      st = px_gran_ck_bad(s, "granular.p.slots.seg", "slot %zu of particle %zu: segment %d, "
                          "start segment %d, start step %d (%zu segments, step %.0f)",
                          i % W, i / W, sg, s0, t0, nseg, sc[2]);
      goto done;
    }
  }

  /* the half neighbour list: CSR by particle, partners after their owner */
  sec = "granular.pstart";
  st = px_gran_ck_read(s, ck, sec, PX_DTYPE_I32, n + 1, (void **)&s->pstart);
  if (st != PX_STATUS_OK) goto done;
  if (s->pstart[0] != 0 || (size_t)s->pstart[n] != np) {
    st = px_gran_ck_bad(s, sec, "starts at %d and ends at %d, expected 0 and the %zu pairs",
                        (int)s->pstart[0], (int)s->pstart[n], np);
    goto done;
  }
  for (i = 0; i < n; ++i)
    if (s->pstart[i + 1] < s->pstart[i]) {
      st = px_gran_ck_bad(s, sec, "decreases at particle %zu", i);
      goto done;
    }
  st = px_gran_ck_read(s, ck, "granular.pi", PX_DTYPE_I32, np, (void **)&s->pi);
  if (st == PX_STATUS_OK) st = px_gran_ck_read(s, ck, "granular.pj", PX_DTYPE_I32, np, (void **)&s->pj);
  if (st != PX_STATUS_OK) goto done;
  for (i = 0; i < n; ++i) {
    int32_t q;
    for (q = s->pstart[i]; q < s->pstart[i + 1]; ++q)
      if (s->pi[q] != (int32_t)i || s->pj[q] <= (int32_t)i || (size_t)s->pj[q] >= n) {
        st = px_gran_ck_bad(s, s->pi[q] != (int32_t)i ? "granular.pi" : "granular.pj",
                            "pair %d: (%d, %d) in the list of particle %zu (partners are later "
                            "particles, below %zu)",
                            (int)q, (int)s->pi[q], (int)s->pj[q], i, n);
        goto done;
      }
  }
  {
    const char *names[] = {"granular.pxi", "granular.pth", "granular.pdm", "granular.pdp",
                           "granular.pri", "granular.prj", "granular.pme", "granular.pre",
                           "granular.pdxr", "granular.pdyr"};
    void **arrs[] = {&s->pxi, &s->pth, &s->pdm, &s->pdp, &s->pri,
                     &s->prj, &s->pme, &s->pre, &s->pdxr, &s->pdyr};
    for (k = 0; k < 10; ++k) {
      long bad;
      st = px_gran_ck_read(s, ck, names[k], PX_DTYPE_U8, np * cs, arrs[k]);
      if (st != PX_STATUS_OK) goto done;
      bad = px_gran_ck_finite(*arrs[k], np, cs, 0);
      if (bad >= 0) {
        st = px_gran_ck_bad(s, names[k], "pair %ld: %g is not finite", bad,
                            px_gran_rd(*arrs[k], (size_t)bad, cs));
        goto done;
      }
    }
    /* per-pair radii are those of its particles; damping and reduced radius
     * positive */
    for (k = 0; k < np; ++k)
      if (px_gran_rd(s->pri, k, cs) != px_gran_rd(s->r, (size_t)s->pi[k], cs) ||
          px_gran_rd(s->prj, k, cs) != px_gran_rd(s->r, (size_t)s->pj[k], cs) ||
          !(px_gran_rd(s->pme, k, cs) >= 0) || !(px_gran_rd(s->pre, k, cs) > 0)) {
        st = px_gran_ck_bad(s, "granular.pri", "pair %zu: radii %g, %g (particles' %g, %g), "
                            "damping %g, reduced radius %g",
                            k, px_gran_rd(s->pri, k, cs), px_gran_rd(s->prj, k, cs),
                            px_gran_rd(s->r, (size_t)s->pi[k], cs),
                            px_gran_rd(s->r, (size_t)s->pj[k], cs), px_gran_rd(s->pme, k, cs),
                            px_gran_rd(s->pre, k, cs));
        goto done;
      }
  }
  {
    void **pa[] = {&s->pfx, &s->pfy, &s->pti, &s->ptj};
    for (k = 0; k < 4 && st == PX_STATUS_OK; ++k)
      st = px_gran_ensure(s, pa[k], (np ? np : 1) * cs, "granular pairs");
    if (st == PX_STATUS_OK)
      st = px_gran_ensure(s, &s->phist_scratch, 4 * (np ? np : 1) * cs, "granular pairs");
    if (st != PX_STATUS_OK) goto done;
  }

  /* wall lists: CSR of candidate segments (ascending per particle, at most
   * as many as a rebuild makes), the near list exactly the particles with
   * candidates, ascending */
  sec = "granular.wstart";
  st = px_gran_ck_read(s, ck, sec, PX_DTYPE_I32, n + 1, (void **)&s->wstart);
  if (st == PX_STATUS_OK)
    st = px_gran_ck_read(s, ck, "granular.wcand", PX_DTYPE_I32, nw, (void **)&s->wcand);
  if (st == PX_STATUS_OK)
    st = px_gran_ck_read(s, ck, "granular.near", PX_DTYPE_I32, nn, (void **)&s->near);
  if (st != PX_STATUS_OK) goto done;
  if (s->wstart[0] != 0 || (size_t)s->wstart[n] != nw) {
    st = px_gran_ck_bad(s, sec, "starts at %d and ends at %d, expected 0 and the %zu candidates",
                        (int)s->wstart[0], (int)s->wstart[n], nw);
    goto done;
  }
  {
    size_t q = 0;
    for (i = 0; i < n; ++i) {
      int32_t c;
      const long long cnt = (long long)s->wstart[i + 1] - (long long)s->wstart[i];
      if (cnt < 0 || cnt > PX_GRAN_WCAND_MAX) {
        st = px_gran_ck_bad(s, sec, "particle %zu: %lld candidates (at most %d)", i, cnt,
                            PX_GRAN_WCAND_MAX);
        goto done;
      }
      for (c = s->wstart[i]; c < s->wstart[i + 1]; ++c)
        if (s->wcand[c] < 0 || (size_t)s->wcand[c] >= nseg ||
            (c > s->wstart[i] && s->wcand[c] <= s->wcand[c - 1])) {
          st = px_gran_ck_bad(s, "granular.wcand", "candidate %d of particle %zu: segment %d "
                              "(%zu segments, ascending)",
                              (int)(c - s->wstart[i]), i, (int)s->wcand[c], nseg);
          goto done;
        }
      if (s->wstart[i + 1] > s->wstart[i]) {
        if (q >= nn || s->near[q] != (int32_t)i) {
          st = px_gran_ck_bad(s, "granular.near", "entry %zu: %d, expected particle %zu (the "
                              "particles with candidates, ascending)",
                              q, q < nn ? (int)s->near[q] : -1, i);
          goto done;
        }
        ++q;
      }
    }
    if (q != nn) {
      st = px_gran_ck_bad(s, "granular.near", "%zu entries for %zu particles with candidates", nn,
                          q);
      goto done;
    }
  }
  s->npairs = np;
  s->nwcand = nw;
  s->nnear = nn;
  if (s->geom) {
    long bad;
    sec = "granular.frames_ref";
    st = px_gran_ck_count(s, ck, sec, PX_DTYPE_F64, s->ncontours * PX_GRAN_CTR_COUNT);
    if (st == PX_STATUS_OK)
      st = px_checkpoint_read(ck, sec, PX_DTYPE_F64, s->ncontours * PX_GRAN_CTR_COUNT,
                              s->frames_ref);
    if (st != PX_STATUS_OK) goto done;
    bad = px_gran_ck_finite(s->frames_ref, s->ncontours * PX_GRAN_CTR_COUNT, sizeof(double),
                            PX_GRAN_COORD_MAX);
    if (bad >= 0) {
      st = px_gran_ck_bad(s, sec, "value %ld = %g is not finite or beyond 1e12", bad,
                          s->frames_ref[bad]);
      goto done;
    }
    sec = "granular.cforce";
    st = px_gran_ck_count(s, ck, sec, PX_DTYPE_F64, 2 * s->ncontours);
    if (st == PX_STATUS_OK)
      st = px_checkpoint_read(ck, sec, PX_DTYPE_F64, 2 * s->ncontours, s->cforce);
    if (st != PX_STATUS_OK) goto done;
    bad = px_gran_ck_finite(s->cforce, 2 * s->ncontours, sizeof(double), 0);
    if (bad >= 0) {
      st = px_gran_ck_bad(s, sec, "value %ld = %g is not finite", bad, s->cforce[bad]);
      goto done;
    }
  }
  if (s->stats_on) {
    struct px_gran_stats *S = &s->stats;
    double *v[] = {S->impacts, S->vn_sum, S->vn2_sum, S->vn_max, S->vt_sum, S->en,
                   S->et,      S->finnie, S->impulse, S->slide,  S->archard, S->ctime,
                   S->dur_sum, S->ended,  S->t_first, S->t_last};
    char name[48];
    for (k = 0; k < sizeof v / sizeof v[0]; ++k) {
      long bad;
      snprintf(name, sizeof name, "granular.stats.%zu", k);
      st = px_gran_ck_count(s, ck, name, PX_DTYPE_F64, nseg);
      if (st == PX_STATUS_OK) st = px_checkpoint_read(ck, name, PX_DTYPE_F64, nseg, v[k]);
      if (st != PX_STATUS_OK) goto done;
      bad = px_gran_ck_finite(v[k], nseg, sizeof(double), 0);
      if (bad >= 0) {
        st = px_gran_ck_bad(s, name, "segment %ld: %g is not finite", bad, v[k][bad]);
        goto done;
      }
    }
  }
  /* everything checked: the state is used from here on */
  s->t = sc[0], s->dt = sc[1], s->step = (long)sc[2], s->rebuilds = (long)sc[3];
  s->need_rebuild = (int)sc[4], s->abm_steps = (long)sc[5];
  st = px_gran_sys_split_pairs(s);
  if (st != PX_STATUS_OK) goto done;
  px_gran_sys_split_near(s);
  px_gran_sys_frames(s, s->t);
done:
  px_mem_free(s->ctx, mine);
  px_mem_free(s->ctx, seen);
  return st;
}

double px_gran_sys_wall_drift_now(const struct px_gran_sys *s) { return px_gran_wall_drift(s); }

void px_gran_sys_set_reference_frames(struct px_gran_sys *s) {
  if (s->geom)
    memcpy(s->frames_ref, s->frames, s->geom->ncontours * PX_GRAN_CTR_COUNT * sizeof(double));
}

enum px_status px_gran_sys_wall_reactions(struct px_gran_sys *s) {
  void *st[5], *acc[3];
  st[0] = s->x, st[1] = s->y, st[2] = s->vx, st[3] = s->vy, st[4] = s->w;
  acc[0] = s->ax0, acc[1] = s->ay0, acc[2] = s->aw0;
  return s->ops->forces(s, st, acc, 0, 0);
}
