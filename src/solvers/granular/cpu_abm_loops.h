/* The ABM4 predictor and corrector loops of the granular solver's cpu
 * engine: part of the instantiation of cpu_loops.h (which includes it; the
 * same macros GS, PX_GRAN_SA, PX_GRAN_SFX). No include guard: one
 * instantiation per translation unit. */

/* The slots the ABM4 loops update: over ranks (s->dist) this rank's own
 * [lo, hi) (its state and histories only are authoritative; every update is
 * per disc, so the bits do not depend on the cut), else all. */
static void PX_GRAN_SFX(abm_slots)(const struct px_gran_sys *s, long *lo, long *hi) {
  int vt0 = 0, vt1 = s->nranges;
  if (s->dist) px_gran_ranks_own(s, &vt0, &vt1);
  *lo = s->dist ? (long)s->rng_i[vt0] : 0;
  *hi = s->dist ? (long)s->rng_i[vt1] : (long)s->n;
}

/* ABM4 predictor (AB2 / Euler during the start-up) into xp. Derivatives:
 * of x, y the velocities, of vx, vy, w the accelerations in fx/fy/tq. */
static void PX_GRAN_SFX(abm_predict)(struct px_gran_sys *s) {
  GS *const y[5] = {PX_GRAN_SA(s->x), PX_GRAN_SA(s->y), PX_GRAN_SA(s->vx), PX_GRAN_SA(s->vy),
                    PX_GRAN_SA(s->w)};
  const GS *const f0[5] = {PX_GRAN_SA(s->vx), PX_GRAN_SA(s->vy), PX_GRAN_SA(s->fx),
                           PX_GRAN_SA(s->fy), PX_GRAN_SA(s->tq)};
  const GS h = (GS)s->dt;
  const long stage = s->abm_steps;
  long i0, n;
  int d;
  PX_GRAN_SFX(abm_slots)(s, &i0, &n);
  for (d = 0; d < 5; ++d) {
    GS *restrict out = PX_GRAN_SA(s->xp[d]);
    const GS *restrict yy = y[d], *restrict g0 = f0[d];
    const GS *restrict g1 = PX_GRAN_SA(s->hist[0][d]), *restrict g2 = PX_GRAN_SA(s->hist[1][d]),
                       *restrict g3 = PX_GRAN_SA(s->hist[2][d]);
    long i;
    if (stage >= 3) {
#pragma omp parallel for simd num_threads(s->active) schedule(static)
      for (i = i0; i < n; ++i) out[i] = px_gran_ab4(yy[i], g0[i], g1[i], g2[i], g3[i], h);
    } else if (stage >= 1) {
#pragma omp parallel for simd num_threads(s->active) schedule(static)
      for (i = i0; i < n; ++i) out[i] = px_gran_ab2(yy[i], g0[i], g1[i], h);
    } else {
#pragma omp parallel for simd num_threads(s->active) schedule(static)
      for (i = i0; i < n; ++i) out[i] = yy[i] + h * g0[i];
    }
  }
}

/* ABM4 corrector: y <- AM4 (AM2 during the start-up) with the predictor's
 * derivatives (velocities in xp, accelerations in fa); shifts the history.
 * *maxdisp2: the largest squared displacement since the last rebuild [m^2]
 * of the slots it updated (abm_slots), NaN when a new value is not finite. */
static void PX_GRAN_SFX(abm_correct)(struct px_gran_sys *s, double *maxdisp2) {
  GS *const y[5] = {PX_GRAN_SA(s->x), PX_GRAN_SA(s->y), PX_GRAN_SA(s->vx), PX_GRAN_SA(s->vy),
                    PX_GRAN_SA(s->w)};
  GS *const f0[5] = {PX_GRAN_SA(s->vx), PX_GRAN_SA(s->vy), PX_GRAN_SA(s->fx), PX_GRAN_SA(s->fy),
                     PX_GRAN_SA(s->tq)};
  const GS *const fp[5] = {PX_GRAN_SA(s->xp[2]), PX_GRAN_SA(s->xp[3]), PX_GRAN_SA(s->fa[0]),
                           PX_GRAN_SA(s->fa[1]), PX_GRAN_SA(s->fa[2])};
  const GS h = (GS)s->dt;
  const long stage = s->abm_steps;
  GS *restrict xr = PX_GRAN_SA(s->xr), *restrict yr = PX_GRAN_SA(s->yr);
  GS best = 0, bad = 0;
  long i, i0, n;
  /* new values of all five into xp (velocity derivatives read the old
   * velocities, so nothing is overwritten before all are computed) */
  GS *nv[5];
  int d;
  nv[0] = PX_GRAN_SA(s->ax0), nv[1] = PX_GRAN_SA(s->ay0), nv[2] = PX_GRAN_SA(s->aw0),
  nv[3] = PX_GRAN_SA(s->xp[0]), nv[4] = PX_GRAN_SA(s->xp[1]);
  PX_GRAN_SFX(abm_slots)(s, &i0, &n);
  for (d = 0; d < 5; ++d) {
    GS *restrict out = nv[d];
    const GS *restrict yy = y[d], *restrict g0 = f0[d], *restrict gp = fp[d];
    const GS *restrict g1 = PX_GRAN_SA(s->hist[0][d]), *restrict g2 = PX_GRAN_SA(s->hist[1][d]);
    if (stage >= 3) {
#pragma omp parallel for simd num_threads(s->active) schedule(static)
      for (i = i0; i < n; ++i) out[i] = px_gran_am4(yy[i], gp[i], g0[i], g1[i], g2[i], h);
    } else {
#pragma omp parallel for simd num_threads(s->active) schedule(static)
      for (i = i0; i < n; ++i) out[i] = px_gran_am2(yy[i], gp[i], g0[i], h);
    }
  }
  /* shift the history: f3 <- f2 <- f1 <- f_n (rotate the buffers) */
  for (d = 0; d < 5; ++d) {
    const union px_gran_reals oldest = s->hist[2][d];
    s->hist[2][d] = s->hist[1][d];
    s->hist[1][d] = s->hist[0][d];
    s->hist[0][d] = oldest;
    memcpy(PX_GRAN_SA(s->hist[0][d]) + i0, f0[d] + i0, (size_t)(n - i0) * sizeof(GS));
  }
  for (d = 0; d < 5; ++d) memcpy(y[d] + i0, nv[d] + i0, (size_t)(n - i0) * sizeof(GS));
  {
    const GS *restrict x = PX_GRAN_SA(s->x), *restrict yy = PX_GRAN_SA(s->y),
                       *restrict vx = PX_GRAN_SA(s->vx), *restrict vy = PX_GRAN_SA(s->vy),
                       *restrict w = PX_GRAN_SA(s->w);
#pragma omp parallel for simd num_threads(s->active) schedule(static) reduction(max : best) \
    reduction(+ : bad)
    for (i = i0; i < n; ++i) {
      const GS dx = x[i] - xr[i], dy = yy[i] - yr[i];
      const GS d2 = dx * dx + dy * dy;
      best = d2 > best ? d2 : best;
      /* 0 when every new value is finite, NaN otherwise */
      bad += (GS)0 * x[i] + (GS)0 * yy[i] + (GS)0 * vx[i] + (GS)0 * vy[i] + (GS)0 * w[i];
    }
  }
  /* a non-finite value: the caller finds the particle now */
  *maxdisp2 = bad != 0 ? (double)NAN : (double)best;
}
