/* The time step of the granular system (velocity Verlet or ABM4 through
 * the loops of cpu_loops.h), the thread tuner, wall events and the
 * per-segment statistics. */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/checkpoint.h"
#include "partix/memory.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/system_impl.h"
#include "solvers/granular/wall_kernel.h"

/* ------------------------------------------------------------------ step */

/* Largest displacement of any point of a contour since the last rebuild. */
static double px_gran_wall_drift_frames(const struct px_gran_sys *s, const double *frames) {
  double best = 0;
  size_t c;
  if (!s->geom) return 0;
  for (c = 0; c < s->geom->ncontours; ++c) {
    const double *f = frames + c * PX_GRAN_CTR_COUNT, *r = s->frames_ref + c * PX_GRAN_CTR_COUNT;
    const double dphi =
        atan2(f[PX_GRAN_CTR_SIN] * r[PX_GRAN_CTR_COS] - f[PX_GRAN_CTR_COS] * r[PX_GRAN_CTR_SIN],
              f[PX_GRAN_CTR_COS] * r[PX_GRAN_CTR_COS] + f[PX_GRAN_CTR_SIN] * r[PX_GRAN_CTR_SIN]);
    const double d =
        hypot(f[PX_GRAN_CTR_DX] - r[PX_GRAN_CTR_DX], f[PX_GRAN_CTR_DY] - r[PX_GRAN_CTR_DY]) +
        fabs(dphi) * s->c_radius[c];
    if (d > best) best = d;
  }
  return best;
}

double px_gran_wall_drift(const struct px_gran_sys *s) {
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

enum px_status px_gran_sys_check_finite(struct px_gran_sys *s, long step, double t) {
  double et, er, rec[8];
  long bad;
  s->ops->energy(s, &et, &er, &bad);
  if (bad < 0) return PX_STATUS_OK;
  s->ops->get(s, (size_t)bad, rec);
  return px_context_fail(s->ctx, PX_STATUS_NUMERIC,
                         "particle %d has a non-finite position or velocity at step %ld (t = %g "
                         "s) (x = %g, y = %g, vx = %g, vy = %g, w = %g): the time step is too "
                         "large for the stiffness, or the input is wrong",
                         (int)rec[PX_GRAN_P_ID], step, t, rec[0], rec[1], rec[2], rec[3], rec[4]);
}

/* One ABM4 PECE step (predict, forces, correct, forces): *maxd2, the
 * largest squared displacement of any disc since the last rebuild [m^2]. */
static enum px_status px_gran_abm_step(struct px_gran_sys *s, double tnew, double *maxd2) {
  union px_gran_reals st[5], acc[3];
  int d;
  s->ops->abm_predict(s);
  px_gran_sys_frames(s, tnew);
  for (d = 0; d < 5; ++d) st[d] = s->xp[d];
  acc[0] = s->fa[0], acc[1] = s->fa[1], acc[2] = s->fa[2];
  PX_TRY(s->ops->forces(s, st, acc, 0, 0));
  s->ops->abm_correct(s, maxd2);
  if (s->dist) {
    /* each rank corrected its own discs: the largest displacement and
     * whether any value is non-finite, over all (MAX: exact on any K) */
    double v[2];
    v[0] = *maxd2 != *maxd2, v[1] = v[0] != 0 ? 0 : *maxd2;
    PX_TRY(px_comm_allreduce_double(s->comm, v, 2, PX_COMM_MAX));
    *maxd2 = v[0] != 0 ? (double)NAN : v[1];
  }
  /* a value became non-finite in this step (the corrector flags it): the
   * first such particle in slot order, from the owners' state */
  if (*maxd2 != *maxd2) {
    if (s->dist) PX_TRY(px_gran_ranks_sync(s, -1));
    s->dist = 0;
    PX_TRY(px_gran_sys_check_finite(s, s->step + 1, tnew));
  }
  st[0] = s->x, st[1] = s->y, st[2] = s->vx, st[3] = s->vy, st[4] = s->w;
  acc[0] = s->fx, acc[1] = s->fy, acc[2] = s->tq;
  PX_TRY(s->ops->forces(s, st, acc, 1, 0));
  ++s->abm_steps;
  return PX_STATUS_OK;
}

enum px_status px_gran_sys_step(struct px_gran_sys *s) {
  double maxd2 = 0;
  const double tnew = s->t + s->dt;
  /* the tuner picks 1 or all threads per step (a count change does not
   * change any result: fixed ranges) */
  int tune;
  if (s->threads > 1 && s->tuner.most != s->threads)
    px_tuner_init(&s->tuner, s->ctx, "granular", s->threads, s->tune);
  tune = s->threads > 1 && px_tuner_tuning(&s->tuner);
  if (tune) s->active = px_tuner_begin(&s->tuner);
  if (s->integrator == PX_GRAN_INTEGRATOR_VERLET) {
    double maxv2 = 0;
    enum px_status st;
    /* the rebuild is decided at the end of the previous step, with a margin
     * for this step's drift: one parallel region per step. Over ranks, every
     * rank rebuilds from the owners' state (system_ranks.c) */
    if (s->need_rebuild && s->nrank > 1) PX_TRY(px_gran_ranks_sync(s, -1));
    if (s->need_rebuild) PX_TRY(px_gran_sys_rebuild(s));
    if (s->nrank > 1) PX_TRY(px_gran_ranks_begin(s));
    px_gran_sys_frames(s, tnew);
    s->dist = s->nrank > 1;
    st = s->ops->vv_step(s, &maxd2, &maxv2);
    s->dist = 0;
    PX_TRY(st);
    /* a value became non-finite in this step (the loops flag it; every
     * rank knows it): the first such particle in slot order, as on one rank */
    if (maxv2 != maxv2 && s->nrank > 1) PX_TRY(px_gran_ranks_sync(s, -1));
    if (maxv2 != maxv2) PX_TRY(px_gran_sys_check_finite(s, s->step + 1, tnew));
    {
      const double margin = 2 * sqrt(maxv2) * s->dt + 1e-3 * s->skin;
      const double d = sqrt(maxd2) + margin;
      const double dw = px_gran_wall_drift_next(s, s->t + 2 * s->dt);
      if (2 * d > s->skin || d + dw > s->skin) s->need_rebuild = 1;
    }
  } else {
    /* over ranks as velocity Verlet: a rank predicts and corrects its own
     * discs, each force evaluation takes the ghosts of the state it sees */
    enum px_status st;
    if (s->need_rebuild && s->nrank > 1) PX_TRY(px_gran_ranks_sync(s, -1));
    if (s->need_rebuild) PX_TRY(px_gran_sys_rebuild(s));
    if (s->nrank > 1) PX_TRY(px_gran_ranks_begin(s));
    s->dist = s->nrank > 1;
    st = px_gran_abm_step(s, tnew, &maxd2);
    s->dist = 0;
    PX_TRY(st);
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
  if (tune) px_tuner_end(&s->tuner, s->step - 1);
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
      double r0 = px_gran_reals_get(s->ev_r, base + e * PX_GRAN_EVR + 0, s->csize);
      double r1 = px_gran_reals_get(s->ev_r, base + e * PX_GRAN_EVR + 1, s->csize);
      double r2 = px_gran_reals_get(s->ev_r, base + e * PX_GRAN_EVR + 2, s->csize);
      double r3 = px_gran_reals_get(s->ev_r, base + e * PX_GRAN_EVR + 3, s->csize);
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
  double **v[] = {&st->impacts, &st->vn_sum, &st->vn2_sum, &st->vn_max, &st->vt_sum,  &st->en,
                  &st->et,      &st->finnie, &st->impulse, &st->slide,  &st->archard, &st->ctime,
                  &st->dur_sum, &st->ended,  &st->t_first, &st->t_last};
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
      evr[nev * PX_GRAN_EVR + 0] = px_gran_reals_get(s->slots.imp, at, s->csize);
      evr[nev * PX_GRAN_EVR + 1] = px_gran_reals_get(s->slots.slw, at, s->csize);
      evr[nev * PX_GRAN_EVR + 2] = px_gran_reals_get(s->slots.arc, at, s->csize);
      evr[nev * PX_GRAN_EVR + 3] = px_gran_reals_get(s->slots.tim, at, s->csize);
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
    impulse[seg] += px_gran_reals_get(s->slots.imp, at, s->csize);
    slide[seg] += px_gran_reals_get(s->slots.slw, at, s->csize);
    archard[seg] += px_gran_reals_get(s->slots.arc, at, s->csize);
    ctime[seg] += px_gran_reals_get(s->slots.tim, at, s->csize);
  }
}

void px_gran_sys_wall_force(const struct px_gran_sys *s, size_t c, double f[2]) {
  f[0] = s->cforce ? s->cforce[2 * c] : 0;
  f[1] = s->cforce ? s->cforce[2 * c + 1] : 0;
}

double px_gran_sys_wall_drift_now(const struct px_gran_sys *s) { return px_gran_wall_drift(s); }

void px_gran_sys_set_reference_frames(struct px_gran_sys *s) {
  if (s->geom)
    memcpy(s->frames_ref, s->frames, s->geom->ncontours * PX_GRAN_CTR_COUNT * sizeof(double));
}

enum px_status px_gran_sys_wall_reactions(struct px_gran_sys *s) {
  union px_gran_reals st[5], acc[3];
  st[0] = s->x, st[1] = s->y, st[2] = s->vx, st[3] = s->vy, st[4] = s->w;
  acc[0] = s->ax0, acc[1] = s->ay0, acc[2] = s->aw0;
  return s->ops->forces(s, st, acc, 0, 0);
}
