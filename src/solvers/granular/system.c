/* The granular system on the cpu backend: storage (particles, the arrays
 * of every precision), contact laws, wall frames and the checks of
 * `prepare`. Rebuilds of the lists in system_rebuild.c, the time step,
 * events and statistics in system_step.c, queries in system_query.c,
 * checkpoints in system_checkpoint.c, the table of per-particle arrays in
 * system_arrays.c; the loops are in cpu_loops.h. */
#include "solvers/granular/system.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/backend.h"
#include "partix/checkpoint.h"
#include "partix/memory.h"
#include "partix/neighbors.h"
#include "partix/timer.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/system_impl.h"
#include "solvers/granular/wall_kernel.h"

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
  bytes += sizeof(int32_t); /* where */
  /* ~5 pairs of the half list (2D, skin included): ends, 10 history and
   * property reals, 4 force reals, 4 scratch reals, cross index; the old list
   * during a rebuild */
  bytes += 5.0 * (3 * 4 + 18 * cs + 4 * 4 + 4 * cs);
  bytes += 4.0 * 4 + 2 * 4;  /* grid cells, wall lists */
  bytes += 2 * 8.0 + 3 * 4;  /* the grid's positions, cell, sorted cell, permutation */
  bytes += 8.0 * 8 + 24 * 2; /* filling: x, y, r, m, v; sites */
  return bytes;
}

enum px_status px_gran_sys_create(struct px_context *ctx, enum px_precision precision, int threads,
                                  struct px_gran_sys **out) {
  struct px_gran_sys *s = px_mem_calloc(ctx, "granular system", 1, sizeof *s);
  *out = NULL;
  if (!s) return PX_STATUS_NOMEM;
  s->ctx = ctx;
  s->precision = precision;
  s->threads = threads > 0 ? threads : 1;
  s->fail_id = -1;
  s->tune = 1;
  s->nranges = 4 * s->threads;
  s->pcache_n = PX_GRAN_PCACHE;
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
  s->comm = px_context_comm(ctx);
  s->nrank = px_comm_size(s->comm);
  s->rank = px_comm_rank(s->comm);
  *out = s;
  return PX_STATUS_OK;
}

void px_gran_stats_free(struct px_gran_sys *s) {
  struct px_gran_stats *st = &s->stats;
  double **v[] = {&st->impacts, &st->vn_sum, &st->vn2_sum, &st->vn_max, &st->vt_sum,  &st->en,
                  &st->et,      &st->finnie, &st->impulse, &st->slide,  &st->archard, &st->ctime,
                  &st->dur_sum, &st->ended,  &st->t_first, &st->t_last};
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
  px_mem_free(ctx, s->pcache);
  px_mem_free(ctx, s->pi);
  px_mem_free(ctx, s->pj);
  px_mem_free(ctx, s->pxi.p);
  px_mem_free(ctx, s->pth.p);
  px_mem_free(ctx, s->pdm.p);
  px_mem_free(ctx, s->pdp.p);
  px_mem_free(ctx, s->pfx.p);
  px_mem_free(ctx, s->pfy.p);
  px_mem_free(ctx, s->pti.p);
  px_mem_free(ctx, s->ptj.p);
  px_mem_free(ctx, s->phist_scratch.p);
  px_mem_free(ctx, s->pdxr.p);
  px_mem_free(ctx, s->pdyr.p);
  px_mem_free(ctx, s->pre.p);
  px_mem_free(ctx, s->pme.p);
  px_mem_free(ctx, s->prj.p);
  px_mem_free(ctx, s->pri.p);
  px_gran_ranks_free(s);
  px_mem_free(ctx, s->rng_i);
  px_mem_free(ctx, s->rng_q);
  px_mem_free(ctx, s->rng_hi);
  px_mem_free(ctx, s->rng_lo);
  px_mem_free(ctx, s->xstart);
  px_mem_free(ctx, s->xpair);
  px_mem_free(ctx, s->frames);
  px_mem_free(ctx, s->sframes.p);
  px_mem_free(ctx, s->frames_ref);
  px_mem_free(ctx, s->c_radius);
  px_mem_free(ctx, s->seg_ax.p);
  px_mem_free(ctx, s->seg_ay.p);
  px_mem_free(ctx, s->seg_tx.p);
  px_mem_free(ctx, s->seg_ty.p);
  px_mem_free(ctx, s->seg_len.p);
  px_mem_free(ctx, s->seg_tpx.p);
  px_mem_free(ctx, s->seg_tpy.p);
  px_mem_free(ctx, s->seg_cfirst);
  px_mem_free(ctx, s->seg_ccount);
  px_mem_free(ctx, s->wstart);
  px_mem_free(ctx, s->wcand);
  px_mem_free(ctx, s->near);
  px_grid_free(s->grid);
  px_buffer_free(s->gpos[0]);
  px_buffer_free(s->gpos[1]);
  px_buffer_free(s->gcell);
  px_backend_free(s->gbe);
  px_mem_free(ctx, s->scratch);
  px_mem_free(ctx, s->ev_i);
  px_mem_free(ctx, s->ev_r.p);
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
    return px_context_fail(s->ctx, PX_STATUS_CONFIG,
                           "%zu particles: more than the %.0e the "
                           "solver takes",
                           s->n + n, PX_GRAN_N_MAX);
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
                             "particle %zu: radius %g and mass %g must be > 0, position finite", at,
                             r[i], m[i]);
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

/* A copy of a double array in state precision (owned by the caller; .p
 * NULL when out of memory). */
static union px_gran_reals px_gran_to_state(struct px_gran_sys *s, const double *src, size_t n) {
  union px_gran_reals dst;
  size_t k;
  dst.p = px_mem_alloc(s->ctx, "granular walls", (n ? n : 1) * s->ssize);
  if (dst.p)
    for (k = 0; k < n; ++k) px_gran_reals_set(dst, k, s->ssize, src[k]);
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
    for (k = 0; k < PX_GRAN_CTR_COUNT; ++k)
      px_gran_reals_set(s->sframes, c * PX_GRAN_CTR_COUNT + k, s->ssize, f[k]);
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
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: normal stiffness kn = %g must be > 0", what,
                           L->kn);
  if (!(L->e > 0) || !(L->e <= 1))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: restitution e = %g must be in (0, 1] (e > 1 would create energy)",
                           what, L->e);
  if (L->normal == PX_GRAN_NORMAL_HYSTERETIC && L->k2 > 0 && !(L->k2 >= L->kn))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: unloading stiffness k2 = %g must be >= the loading stiffness %g",
                           what, L->k2, L->kn);
  if (!(L->mu >= 0) || !(L->kt_ratio >= 0) || !(L->ct_ratio >= 0) || !(L->mur >= 0) ||
      !(L->kr >= 0) || !(L->gt >= 0) || !(L->phif >= 0) || !(L->damping >= 0) || !(L->damping < 1))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: friction, tangential/rolling stiffness and damping must be >= 0 "
                           "(damping ratio < 1)",
                           what);
  if (L->mur > 0 && !(L->kr > 0))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: rolling friction needs a rolling stiffness > 0", what);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------ prepare */

/* The time step [s]: dt as given, or t_c / steps_per_contact when dt <= 0,
 * checked against the contact duration t_c of the lightest pair. */
static enum px_status px_gran_prepare_dt(struct px_gran_sys *s, double dt,
                                         double steps_per_contact) {
  double tc;
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
  return PX_STATUS_OK;
}

/* The walls in state precision (segments, frames, each contour's reach
 * from its pivot), and every particle inside the media region and clear of
 * the walls. */
static enum px_status px_gran_prepare_walls(struct px_gran_sys *s) {
  size_t i;
  const struct px_gran_geom *g = s->geom;
  const size_t nc = g->ncontours;
  size_t c;
  s->ncontours = nc;
  s->frames = px_mem_calloc(s->ctx, "granular walls", nc * PX_GRAN_CTR_COUNT, sizeof(double));
  s->frames_ref = px_mem_calloc(s->ctx, "granular walls", nc * PX_GRAN_CTR_COUNT, sizeof(double));
  s->sframes.p = px_mem_calloc(s->ctx, "granular walls", nc * PX_GRAN_CTR_COUNT, s->ssize);
  s->c_radius = px_mem_calloc(s->ctx, "granular walls", nc, sizeof(double));
  s->seg_cfirst = px_mem_alloc(s->ctx, "granular walls", nc * sizeof(int));
  s->seg_ccount = px_mem_alloc(s->ctx, "granular walls", nc * sizeof(int));
  s->cforce = px_mem_calloc(s->ctx, "granular walls", 2 * nc, sizeof(double));
  s->cforce_t =
      px_mem_calloc(s->ctx, "granular walls", 2 * nc * (size_t)s->nranges, sizeof(double));
  if (!s->frames || !s->frames_ref || !s->sframes.p || !s->c_radius || !s->seg_cfirst ||
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
  if (!(s->seg_ax = px_gran_to_state(s, g->ax, g->nseg)).p ||
      !(s->seg_ay = px_gran_to_state(s, g->ay, g->nseg)).p ||
      !(s->seg_tx = px_gran_to_state(s, g->tx, g->nseg)).p ||
      !(s->seg_ty = px_gran_to_state(s, g->ty, g->nseg)).p ||
      !(s->seg_len = px_gran_to_state(s, g->len, g->nseg)).p ||
      !(s->seg_tpx = px_gran_to_state(s, g->tpx, g->nseg)).p ||
      !(s->seg_tpy = px_gran_to_state(s, g->tpy, g->nseg)).p)
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
  return PX_STATUS_OK;
}

/* No two discs overlap at the start (the lists are built). */
static enum px_status px_gran_check_overlaps(struct px_gran_sys *s) {
  size_t i;
  int32_t k;
  for (i = 0; i < s->n; ++i)
    for (k = s->pstart[i]; k < s->pstart[i + 1]; ++k) {
      double a[8], b[8];
      s->ops->get(s, i, a);
      s->ops->get(s, (size_t)s->pj[k], b);
      if (hypot(a[0] - b[0], a[1] - b[1]) < (a[PX_GRAN_P_R] + b[PX_GRAN_P_R]) * (1 - 1e-6)) {
        s->fail_id =
            (int32_t)(a[PX_GRAN_P_ID] > b[PX_GRAN_P_ID] ? a[PX_GRAN_P_ID] : b[PX_GRAN_P_ID]);
        return px_context_fail(s->ctx, PX_STATUS_CONFIG,
                               "particles %d at (%g, %g) and %d at (%g, %g) overlap by %g m at "
                               "the start (radii %g and %g)",
                               (int)a[PX_GRAN_P_ID], a[0], a[1], (int)b[PX_GRAN_P_ID], b[0], b[1],
                               a[PX_GRAN_P_R] + b[PX_GRAN_P_R] - hypot(a[0] - b[0], a[1] - b[1]),
                               a[PX_GRAN_P_R], b[PX_GRAN_P_R]);
      }
    }
  return PX_STATUS_OK;
}

enum px_status px_gran_sys_prepare(struct px_gran_sys *s, double dt, double steps_per_contact) {
  size_t i;
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
    /* work is split into ranges taken dynamically by the threads (a thread
     * that is descheduled does not hold the others back as long): 4 below
     * 4096 discs, 8 per 2048 discs above (256 to 512 discs each, at most
     * 256 ranges). The split (and so every sum) depends on the number of
     * discs only, not on the threads asked for: the same bits on any thread
     * count; and a range is the grain of the ranks (system_ranks.c) */
    s->nranges = useful > 1 ? (8 * useful < 256 ? 8 * useful : 256) : 4;
    s->active = s->threads;
  }
  {
    double p[PX_GRAN_LAW_COUNT];
    px_gran_law_params(&s->pp, 0, p);
    s->pp_zeta2 = p[PX_GRAN_LAW_ZETA2];
  }
  PX_TRY(px_gran_prepare_dt(s, dt, steps_per_contact));
  if (s->geom) PX_TRY(px_gran_prepare_walls(s));
  /* event buffers */
  s->ev_cap = PX_GRAN_EV_CAP_MIN + 3 * PX_GRAN_WSLOTS * 64;
  s->ev_i = px_mem_alloc(s->ctx, "granular events",
                         (size_t)s->nranges * s->ev_cap * PX_GRAN_EVI * sizeof(int));
  s->ev_r.p = px_mem_alloc(s->ctx, "granular events",
                           (size_t)s->nranges * s->ev_cap * PX_GRAN_EVR * s->csize);
  s->ev_n = px_mem_calloc(s->ctx, "granular events", (size_t)s->nranges, sizeof(size_t));
  if (!s->ev_i || !s->ev_r.p || !s->ev_n) return PX_STATUS_NOMEM;

  PX_TRY(px_gran_sys_rebuild(s));
  PX_TRY(px_gran_check_overlaps(s));
  /* accelerations at the start */
  {
    const union px_gran_reals st[5] = {s->x, s->y, s->vx, s->vy, s->w};
    const union px_gran_reals acc[3] = {s->fx, s->fy, s->tq};
    /* no commit: the histories start with the first step */
    PX_TRY(s->ops->forces(s, st, acc, 0, 0));
  }
  return PX_STATUS_OK;
}
