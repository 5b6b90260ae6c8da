/* The cpu loops of the granular solver, instantiated once per precision by
 * cpu_f64.c, cpu_mixed.c and cpu_f32.c, which define before including:
 *   PX_REAL        contact arithmetic (float | double)
 *   PX_GRAN_STATE  state arithmetic (float | double)
 *   PX_GRAN_OPS    name of the exported ops table
 *   PX_GRAN_SFX(n) n with the instantiation's suffix
 * No include guard: one instantiation per translation unit. */
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <string.h>

#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/integrate_kernel.h"
#include "solvers/granular/system.h"
#include "solvers/granular/wall_kernel.h"

#define GS PX_GRAN_STATE
#define GR PX_REAL

/* Kernel law from the double parameters. */
static void PX_GRAN_SFX(law)(const struct px_gran_law_spec *spec, int cells,
                             struct px_gran_law *L) {
  double p[PX_GRAN_LAW_COUNT];
  px_gran_law_params(spec, cells, p);
  L->kn = (GR)p[PX_GRAN_LAW_KN];
  L->k2 = (GR)p[PX_GRAN_LAW_K2];
  L->phif = (GR)p[PX_GRAN_LAW_PHIF];
  L->zeta2 = (GR)p[PX_GRAN_LAW_ZETA2];
  L->ct_ratio = (GR)p[PX_GRAN_LAW_CT];
  L->kt = (GR)p[PX_GRAN_LAW_KT];
  L->mu = (GR)p[PX_GRAN_LAW_MU];
  L->mur = (GR)p[PX_GRAN_LAW_MUR];
  L->kr = (GR)p[PX_GRAN_LAW_KR];
  L->gt = (GR)p[PX_GRAN_LAW_GT];
  L->normal = (int)p[PX_GRAN_LAW_NORMAL];
  L->tangential = (int)p[PX_GRAN_LAW_TANGENTIAL];
  L->clamp = (GR)p[PX_GRAN_LAW_CLAMP];
  L->cells = (GR)p[PX_GRAN_LAW_CELLS];
  L->rolling = L->mur > (GR)0;
}

/* Pair loops, one per contact-model combination: [normal][tangential][rolling]. */
typedef void (*PX_GRAN_SFX(pair_fn))(const struct px_gran_law *, const GS *restrict,
                                     const GS *restrict, const GS *restrict, const GS *restrict,
                                     const GS *restrict, const GR *restrict, const GR *restrict,
                                     const int32_t *restrict, const int32_t *restrict,
                                     GR *restrict, GR *restrict, GR *restrict, GR *restrict,
                                     GR *restrict, GR *restrict, GR *restrict, GR *restrict,
                                     size_t, size_t, GR);
#define PX_GRAN_PL_NAME PX_GRAN_SFX(pairs_lin_none_0)
#define PX_GRAN_PL_NORMAL PX_GRAN_NORMAL_LINEAR
#define PX_GRAN_PL_TANG PX_GRAN_TANGENTIAL_NONE
#define PX_GRAN_PL_ROLL 0
#include "solvers/granular/cpu_pair_loop.h"
#define PX_GRAN_PL_NAME PX_GRAN_SFX(pairs_lin_none_1)
#define PX_GRAN_PL_NORMAL PX_GRAN_NORMAL_LINEAR
#define PX_GRAN_PL_TANG PX_GRAN_TANGENTIAL_NONE
#define PX_GRAN_PL_ROLL 1
#include "solvers/granular/cpu_pair_loop.h"
#define PX_GRAN_PL_NAME PX_GRAN_SFX(pairs_lin_spring_0)
#define PX_GRAN_PL_NORMAL PX_GRAN_NORMAL_LINEAR
#define PX_GRAN_PL_TANG PX_GRAN_TANGENTIAL_SPRING
#define PX_GRAN_PL_ROLL 0
#include "solvers/granular/cpu_pair_loop.h"
#define PX_GRAN_PL_NAME PX_GRAN_SFX(pairs_lin_spring_1)
#define PX_GRAN_PL_NORMAL PX_GRAN_NORMAL_LINEAR
#define PX_GRAN_PL_TANG PX_GRAN_TANGENTIAL_SPRING
#define PX_GRAN_PL_ROLL 1
#include "solvers/granular/cpu_pair_loop.h"
#define PX_GRAN_PL_NAME PX_GRAN_SFX(pairs_lin_visc_0)
#define PX_GRAN_PL_NORMAL PX_GRAN_NORMAL_LINEAR
#define PX_GRAN_PL_TANG PX_GRAN_TANGENTIAL_VISCOUS
#define PX_GRAN_PL_ROLL 0
#include "solvers/granular/cpu_pair_loop.h"
#define PX_GRAN_PL_NAME PX_GRAN_SFX(pairs_lin_visc_1)
#define PX_GRAN_PL_NORMAL PX_GRAN_NORMAL_LINEAR
#define PX_GRAN_PL_TANG PX_GRAN_TANGENTIAL_VISCOUS
#define PX_GRAN_PL_ROLL 1
#include "solvers/granular/cpu_pair_loop.h"
#define PX_GRAN_PL_NAME PX_GRAN_SFX(pairs_hys_none_0)
#define PX_GRAN_PL_NORMAL PX_GRAN_NORMAL_HYSTERETIC
#define PX_GRAN_PL_TANG PX_GRAN_TANGENTIAL_NONE
#define PX_GRAN_PL_ROLL 0
#include "solvers/granular/cpu_pair_loop.h"
#define PX_GRAN_PL_NAME PX_GRAN_SFX(pairs_hys_none_1)
#define PX_GRAN_PL_NORMAL PX_GRAN_NORMAL_HYSTERETIC
#define PX_GRAN_PL_TANG PX_GRAN_TANGENTIAL_NONE
#define PX_GRAN_PL_ROLL 1
#include "solvers/granular/cpu_pair_loop.h"
#define PX_GRAN_PL_NAME PX_GRAN_SFX(pairs_hys_spring_0)
#define PX_GRAN_PL_NORMAL PX_GRAN_NORMAL_HYSTERETIC
#define PX_GRAN_PL_TANG PX_GRAN_TANGENTIAL_SPRING
#define PX_GRAN_PL_ROLL 0
#include "solvers/granular/cpu_pair_loop.h"
#define PX_GRAN_PL_NAME PX_GRAN_SFX(pairs_hys_spring_1)
#define PX_GRAN_PL_NORMAL PX_GRAN_NORMAL_HYSTERETIC
#define PX_GRAN_PL_TANG PX_GRAN_TANGENTIAL_SPRING
#define PX_GRAN_PL_ROLL 1
#include "solvers/granular/cpu_pair_loop.h"
#define PX_GRAN_PL_NAME PX_GRAN_SFX(pairs_hys_visc_0)
#define PX_GRAN_PL_NORMAL PX_GRAN_NORMAL_HYSTERETIC
#define PX_GRAN_PL_TANG PX_GRAN_TANGENTIAL_VISCOUS
#define PX_GRAN_PL_ROLL 0
#include "solvers/granular/cpu_pair_loop.h"
#define PX_GRAN_PL_NAME PX_GRAN_SFX(pairs_hys_visc_1)
#define PX_GRAN_PL_NORMAL PX_GRAN_NORMAL_HYSTERETIC
#define PX_GRAN_PL_TANG PX_GRAN_TANGENTIAL_VISCOUS
#define PX_GRAN_PL_ROLL 1
#include "solvers/granular/cpu_pair_loop.h"

static const PX_GRAN_SFX(pair_fn) PX_GRAN_SFX(pair_loops)[2][3][2] = {
    {{PX_GRAN_SFX(pairs_lin_none_0), PX_GRAN_SFX(pairs_lin_none_1)}, {PX_GRAN_SFX(pairs_lin_spring_0), PX_GRAN_SFX(pairs_lin_spring_1)}, {PX_GRAN_SFX(pairs_lin_visc_0), PX_GRAN_SFX(pairs_lin_visc_1)}},
    {{PX_GRAN_SFX(pairs_hys_none_0), PX_GRAN_SFX(pairs_hys_none_1)}, {PX_GRAN_SFX(pairs_hys_spring_0), PX_GRAN_SFX(pairs_hys_spring_1)}, {PX_GRAN_SFX(pairs_hys_visc_0), PX_GRAN_SFX(pairs_hys_visc_1)}}};

/* Pair forces of pairs [k0, k1) into the per-pair records; commit = 0
 * writes the updated histories to scratch arrays (predictor evaluation). */
static void PX_GRAN_SFX(pair_pass)(struct px_gran_sys *s, const struct px_gran_law *law,
                                   const GS *x, const GS *y, const GS *vx, const GS *vy,
                                   const GS *w, size_t k0, size_t k1, int commit) {
  GR *h[4];
  const int nm = law->normal == PX_GRAN_NORMAL_HYSTERETIC;
  const int tm = law->tangential;
  const int rm = law->mur > (GR)0;
  h[0] = s->pxi, h[1] = s->pth, h[2] = s->pdm, h[3] = s->pdp;
  if (!commit) {
    /* a copy of this thread's range of the histories, updated and dropped */
    GR *scratch = s->phist_scratch;
    int q;
    for (q = 0; q < 4; ++q) {
      memcpy(scratch + (size_t)q * s->npairs + k0, h[q] + k0, (k1 - k0) * sizeof(GR));
      h[q] = scratch + (size_t)q * s->npairs;
    }
  }
  PX_GRAN_SFX(pair_loops)[nm][tm][rm](law, x, y, vx, vy, w, s->r, s->im, s->pi, s->pj, h[0], h[1],
                                      h[2], h[3],                                       s->pfx, s->pfy, s->pti, s->ptj, k0, k1, (GR)s->dt);
}

/* Wall contacts of near-wall particles near[q0..q1). */
static void PX_GRAN_SFX(wall_pass)(struct px_gran_sys *s, const struct px_gran_law *law,
                                   const GS *x, const GS *y, const GS *vx, const GS *vy,
                                   const GS *w, size_t q0, size_t q1, int commit, int tid) {
  const struct px_gran_geom *g = s->geom;
  struct px_gran_walls W;
  struct px_gran_wslots S;
  const GR *r = s->r, *m = s->m;
  GR *wfx = s->wfx, *wfy = s->wfy, *wtq = s->wtq;
  int evi[PX_GRAN_WEVENTS * PX_GRAN_EVI];
  GR evr[PX_GRAN_WEVENTS * PX_GRAN_EVR];
  int oc[PX_GRAN_WMAX];
  GR ofx[PX_GRAN_WMAX], ofy[PX_GRAN_WMAX];
  double *cf = s->cforce_t + (size_t)tid * 2 * s->ncontours;
  int *tev_i = s->ev_i + (size_t)tid * s->ev_cap * PX_GRAN_EVI;
  GR *tev_r = (GR *)s->ev_r + (size_t)tid * s->ev_cap * PX_GRAN_EVR;
  size_t q;
  W.ax = s->seg_ax, W.ay = s->seg_ay, W.tx = s->seg_tx, W.ty = s->seg_ty, W.len = s->seg_len;
  W.tpx = s->seg_tpx, W.tpy = s->seg_tpy, W.flags = g->flags, W.contour = g->contour;
  W.cfirst = s->seg_cfirst, W.ccount = s->seg_ccount, W.frame = s->sframes;
  S.seg = s->slots.seg, S.seg0 = s->slots.seg0, S.step0 = s->slots.step0;
  S.t0 = s->slots.t0, S.te = s->slots.te, S.xi = s->slots.xi, S.th = s->slots.th;
  S.dm = s->slots.dm, S.dp = s->slots.dp, S.imp = s->slots.imp, S.slw = s->slots.slw, S.arc = s->slots.arc;
  S.tim = s->slots.tim;
  for (q = q0; q < q1; ++q) {
    const int32_t i = s->near[q];
    struct px_gran_wpart P;
    GR fx = 0, fy = 0, tq = 0;
    int nev, noc = 0, e;
    P.x = x[i], P.y = y[i], P.vx = vx[i], P.vy = vy[i], P.w = w[i];
    P.r = r[i], P.m = m[i], P.id = s->id[i];
    nev = px_gran_wall_particle(law, &W, &S, (int)i, &P, s->wcand + s->wstart[i],
                                s->wstart[i + 1] - s->wstart[i], (GR)s->dt, (int)s->step, commit,
                                &fx, &fy, &tq, evi, evr, commit ? oc : NULL, ofx, ofy, &noc,
                                NULL);
    wfx[i] = fx;
    wfy[i] = fy;
    wtq[i] = tq;
    for (e = 0; e < noc; ++e) {
      cf[2 * oc[e]] -= (double)ofx[e];
      cf[2 * oc[e] + 1] -= (double)ofy[e];
    }
    for (e = 0; e < nev; ++e) {
      const size_t at = s->ev_n[tid];
      if (at >= s->ev_cap) {
#pragma omp atomic
        ++s->ev_overflow; /* statistics lose an event; reported at the end */
        continue;
      }
      memcpy(tev_i + at * PX_GRAN_EVI, evi + e * PX_GRAN_EVI, PX_GRAN_EVI * sizeof(int));
      memcpy(tev_r + at * PX_GRAN_EVR, evr + e * PX_GRAN_EVR, PX_GRAN_EVR * sizeof(GR));
      s->ev_n[tid] = at + 1;
    }
  }
}

static enum px_status PX_GRAN_SFX(forces)(struct px_gran_sys *s, void *const st[5],
                                          void *const acc[3], int commit) {
  const GS *x = st[0], *y = st[1], *vx = st[2], *vy = st[3], *w = st[4];
  GS *ax = acc[0], *ay = acc[1], *aw = acc[2];
  struct px_gran_law lpp, lpw;
  const size_t n = s->n;
  const GS gx = (GS)s->gravity[0], gy = (GS)s->gravity[1];
  int nthreads = s->threads > 0 ? s->threads : 1;
  PX_GRAN_SFX(law)(&s->pp, s->integrator == PX_GRAN_INTEGRATOR_VERLET, &lpp);
  PX_GRAN_SFX(law)(&s->pw, s->integrator == PX_GRAN_INTEGRATOR_VERLET, &lpw);
  if (commit && s->ncontours) memset(s->cforce_t, 0, (size_t)nthreads * 2 * s->ncontours * sizeof(double));
#pragma omp parallel num_threads(nthreads)
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    const size_t i0 = n * (size_t)t / (size_t)nt, i1 = n * (size_t)(t + 1) / (size_t)nt;
    const size_t q0 = s->nnear * (size_t)t / (size_t)nt;
    const size_t q1 = s->nnear * (size_t)(t + 1) / (size_t)nt;
    size_t i;
    PX_GRAN_SFX(pair_pass)(s, &lpp, x, y, vx, vy, w, (size_t)s->pstart[i0],
                           (size_t)s->pstart[i1], commit);
    if (s->geom) PX_GRAN_SFX(wall_pass)(s, &lpw, x, y, vx, vy, w, q0, q1, commit, t);
#pragma omp barrier
    {
      const GR *pfx = s->pfx, *pfy = s->pfy, *pti = s->pti, *ptj = s->ptj;
      const GR *im = s->im, *iI = s->iI;
      GR *wfx = s->wfx, *wfy = s->wfy, *wtq = s->wtq;
      const int32_t *pstart = s->pstart, *tstart = s->tstart, *tpair = s->tpair;
      for (i = i0; i < i1; ++i) {
        GS sx = (GS)wfx[i], sy = (GS)wfy[i], sw = (GS)wtq[i];
        int32_t k, q;
        for (k = pstart[i]; k < pstart[i + 1]; ++k) {
          sx += (GS)pfx[k];
          sy += (GS)pfy[k];
          sw += (GS)pti[k];
        }
        for (q = tstart[i]; q < tstart[i + 1]; ++q) {
          k = tpair[q];
          sx -= (GS)pfx[k];
          sy -= (GS)pfy[k];
          sw += (GS)ptj[k];
        }
        ax[i] = sx * (GS)im[i] + gx;
        ay[i] = sy * (GS)im[i] + gy;
        aw[i] = sw * (GS)iI[i];
        wfx[i] = 0;
        wfy[i] = 0;
        wtq[i] = 0;
      }
    }
  }
  if (commit && s->ncontours) {
    size_t c;
    int t;
    memset(s->cforce, 0, 2 * s->ncontours * sizeof(double));
    for (t = 0; t < nthreads; ++t)
      for (c = 0; c < 2 * s->ncontours; ++c) s->cforce[c] += s->cforce_t[(size_t)t * 2 * s->ncontours + c];
  }
  return PX_STATUS_OK;
}

/* Velocity Verlet, first half: drift with the extrapolated velocity. */
static void PX_GRAN_SFX(vv_drift)(struct px_gran_sys *s, double *maxdisp2) {
  GS *restrict x = s->x, *restrict y = s->y, *restrict vx = s->vx, *restrict vy = s->vy,
                *restrict w = s->w;
  const GS *restrict ax = s->fx, *restrict ay = s->fy, *restrict aw = s->tq;
  const GS *restrict xr = s->xr, *restrict yr = s->yr;
  const GS h = (GS)s->dt;
  const long n = (long)s->n;
  GS best = 0;
  long i;
#pragma omp parallel for simd num_threads(s->threads) schedule(static) reduction(max : best)
  for (i = 0; i < n; ++i) {
    GS xi = x[i], yi = y[i], vxi = vx[i], vyi = vy[i], wi = w[i], dx, dy, d2, dummy = 0;
    px_gran_vv_drift(&xi, &vxi, ax[i], h);
    px_gran_vv_drift(&yi, &vyi, ay[i], h);
    px_gran_vv_drift(&dummy, &wi, aw[i], h);
    x[i] = xi;
    y[i] = yi;
    vx[i] = vxi;
    vy[i] = vyi;
    w[i] = wi;
    dx = xi - xr[i];
    dy = yi - yr[i];
    d2 = dx * dx + dy * dy;
    best = d2 > best ? d2 : best;
  }
  *maxdisp2 = (double)best;
}

/* Velocity Verlet, second half: correct the velocities with the new
 * accelerations (in fx/fy/tq after the swap; old ones in ax0/ay0/aw0). */
static void PX_GRAN_SFX(vv_kick)(struct px_gran_sys *s) {
  GS *restrict vx = s->vx, *restrict vy = s->vy, *restrict w = s->w;
  const GS *restrict an = s->fx, *restrict bn = s->fy, *restrict cn = s->tq;
  const GS *restrict ao = s->ax0, *restrict bo = s->ay0, *restrict co = s->aw0;
  const GS h = (GS)s->dt;
  const long n = (long)s->n;
  long i;
#pragma omp parallel for simd num_threads(s->threads) schedule(static)
  for (i = 0; i < n; ++i) {
    vx[i] = px_gran_vv_kick(vx[i], ao[i], an[i], h);
    vy[i] = px_gran_vv_kick(vy[i], bo[i], bn[i], h);
    w[i] = px_gran_vv_kick(w[i], co[i], cn[i], h);
  }
}

/* ABM4 predictor (AB2 / Euler during the start-up) into xp. Derivatives:
 * of x, y the velocities, of vx, vy, w the accelerations in fx/fy/tq. */
static void PX_GRAN_SFX(abm_predict)(struct px_gran_sys *s) {
  GS *const y[5] = {s->x, s->y, s->vx, s->vy, s->w};
  const GS *const f0[5] = {s->vx, s->vy, s->fx, s->fy, s->tq};
  const GS h = (GS)s->dt;
  const long n = (long)s->n;
  const long stage = s->abm_steps;
  int d;
  for (d = 0; d < 5; ++d) {
    GS *restrict out = s->xp[d];
    const GS *restrict yy = y[d], *restrict g0 = f0[d];
    const GS *restrict g1 = s->hist[0][d], *restrict g2 = s->hist[1][d],
                       *restrict g3 = s->hist[2][d];
    long i;
    if (stage >= 3) {
#pragma omp parallel for simd num_threads(s->threads) schedule(static)
      for (i = 0; i < n; ++i) out[i] = px_gran_ab4(yy[i], g0[i], g1[i], g2[i], g3[i], h);
    } else if (stage >= 1) {
#pragma omp parallel for simd num_threads(s->threads) schedule(static)
      for (i = 0; i < n; ++i) out[i] = px_gran_ab2(yy[i], g0[i], g1[i], h);
    } else {
#pragma omp parallel for simd num_threads(s->threads) schedule(static)
      for (i = 0; i < n; ++i) out[i] = yy[i] + h * g0[i];
    }
  }
}

/* ABM4 corrector: y <- AM4 (AM2 during the start-up) with the predictor's
 * derivatives (velocities in xp, accelerations in fa); shifts the history. */
static void PX_GRAN_SFX(abm_correct)(struct px_gran_sys *s, double *maxdisp2) {
  GS *const y[5] = {s->x, s->y, s->vx, s->vy, s->w};
  GS *const f0[5] = {s->vx, s->vy, s->fx, s->fy, s->tq};
  const GS *const fp[5] = {s->xp[2], s->xp[3], s->fa[0], s->fa[1], s->fa[2]};
  const GS h = (GS)s->dt;
  const long n = (long)s->n;
  const long stage = s->abm_steps;
  GS *restrict xr = s->xr, *restrict yr = s->yr;
  GS best = 0;
  long i;
  /* new values of all five into xp (velocity derivatives read the old
   * velocities, so nothing is overwritten before all are computed) */
  GS *nv[5];
  int d;
  nv[0] = s->ax0, nv[1] = s->ay0, nv[2] = s->aw0, nv[3] = s->xp[0], nv[4] = s->xp[1];
  for (d = 0; d < 5; ++d) {
    GS *restrict out = nv[d];
    const GS *restrict yy = y[d], *restrict g0 = f0[d], *restrict gp = fp[d];
    const GS *restrict g1 = s->hist[0][d], *restrict g2 = s->hist[1][d];
    if (stage >= 3) {
#pragma omp parallel for simd num_threads(s->threads) schedule(static)
      for (i = 0; i < n; ++i) out[i] = px_gran_am4(yy[i], gp[i], g0[i], g1[i], g2[i], h);
    } else {
#pragma omp parallel for simd num_threads(s->threads) schedule(static)
      for (i = 0; i < n; ++i) out[i] = px_gran_am2(yy[i], gp[i], g0[i], h);
    }
  }
  /* shift the history: f3 <- f2 <- f1 <- f_n (rotate the buffers) */
  for (d = 0; d < 5; ++d) {
    void *oldest = s->hist[2][d];
    s->hist[2][d] = s->hist[1][d];
    s->hist[1][d] = s->hist[0][d];
    s->hist[0][d] = oldest;
    memcpy(s->hist[0][d], f0[d], (size_t)n * sizeof(GS));
  }
  for (d = 0; d < 5; ++d) memcpy(y[d], nv[d], (size_t)n * sizeof(GS));
  {
    const GS *restrict x = s->x, *restrict yy = s->y;
#pragma omp parallel for simd num_threads(s->threads) schedule(static) reduction(max : best)
    for (i = 0; i < n; ++i) {
      const GS dx = x[i] - xr[i], dy = yy[i] - yr[i];
      const GS d2 = dx * dx + dy * dy;
      best = d2 > best ? d2 : best;
    }
  }
  *maxdisp2 = (double)best;
}

/* Pairs j > i within r_i + r_j + cut_extra over the cell grid (particles
 * sorted by cell). pass 0: count[i] = number of pairs of i; pass 1: fill pj
 * from pstart (pi too). */
static void PX_GRAN_SFX(build_pairs)(struct px_gran_sys *s, double cut_extra, int pass,
                                     int32_t *count) {
  const GS *x = s->x, *y = s->y;
  const GR *r = s->r;
  const long n = (long)s->n;
  const int nx = s->gnx, ny = s->gny;
  const double x0 = s->gx0, y0 = s->gy0, hh = s->gh;
  const GS ce = (GS)cut_extra;
  long i;
#pragma omp parallel for num_threads(s->threads) schedule(static)
  for (i = 0; i < n; ++i) {
    const int ci = (int)(((double)x[i] - x0) / hh), cj = (int)(((double)y[i] - y0) / hh);
    int a, b, cnt = 0;
    int32_t at = pass ? s->pstart[i] : 0;
    for (b = cj - 1; b <= cj + 1; ++b) {
      if (b < 0 || b >= ny) continue;
      for (a = ci - 1; a <= ci + 1; ++a) {
        int32_t c, q;
        if (a < 0 || a >= nx) continue;
        c = b * nx + a;
        for (q = s->cstart[c]; q < s->cstart[c + 1]; ++q) {
          GS dx, dy, cut;
          if (q <= i) continue;
          dx = x[i] - x[q];
          dy = y[i] - y[q];
          cut = (GS)r[i] + (GS)r[q] + ce;
          if (dx * dx + dy * dy >= cut * cut) continue;
          if (pass) {
            s->pi[at] = (int32_t)i;
            s->pj[at] = q;
            ++at;
          }
          ++cnt;
        }
      }
    }
    if (!pass) count[i] = cnt;
  }
}

static void PX_GRAN_SFX(energy)(const struct px_gran_sys *s, double *ek_t, double *ek_r,
                                long *bad) {
  const GS *x = s->x, *y = s->y, *vx = s->vx, *vy = s->vy, *w = s->w;
  const GR *m = s->m, *iI = s->iI;
  double et = 0, er = 0;
  long i, first = -1;
  for (i = 0; i < (long)s->n; ++i) {
    const double v2 = (double)vx[i] * (double)vx[i] + (double)vy[i] * (double)vy[i];
    et += 0.5 * (double)m[i] * v2;
    er += 0.5 * (double)w[i] * (double)w[i] / (double)iI[i];
    if (first < 0 && !(isfinite((double)x[i]) && isfinite((double)y[i]) && isfinite(v2) &&
                       isfinite((double)w[i])))
      first = i;
  }
  *ek_t = et;
  *ek_r = er;
  *bad = first;
}

/* Elastic energy of the contacts, kn delta^2 / 2 (linear law) [J]. */
static double PX_GRAN_SFX(elastic)(struct px_gran_sys *s) {
  const GS *x = s->x, *y = s->y;
  const GR *r = s->r;
  double e = 0;
  size_t k, q;
  for (k = 0; k < s->npairs; ++k) {
    const int32_t i = s->pi[k], j = s->pj[k];
    const double dx = (double)x[i] - (double)x[j], dy = (double)y[i] - (double)y[j];
    const double d = (double)r[i] + (double)r[j] - sqrt(dx * dx + dy * dy);
    if (d > 0) e += 0.5 * s->pp.kn * d * d;
  }
  if (s->geom) {
    struct px_gran_law L;
    struct px_gran_walls W;
    struct px_gran_wslots S;
    const struct px_gran_geom *g = s->geom;
    PX_GRAN_SFX(law)(&s->pw, 0, &L);
    W.ax = s->seg_ax, W.ay = s->seg_ay, W.tx = s->seg_tx, W.ty = s->seg_ty, W.len = s->seg_len;
    W.tpx = s->seg_tpx, W.tpy = s->seg_tpy, W.flags = g->flags, W.contour = g->contour;
    W.cfirst = s->seg_cfirst, W.ccount = s->seg_ccount, W.frame = s->sframes;
    S.seg = s->slots.seg, S.seg0 = s->slots.seg0, S.step0 = s->slots.step0;
    S.t0 = s->slots.t0, S.te = s->slots.te, S.xi = s->slots.xi, S.th = s->slots.th;
    S.dm = s->slots.dm, S.dp = s->slots.dp, S.imp = s->slots.imp, S.slw = s->slots.slw;
    S.arc = s->slots.arc, S.tim = s->slots.tim;
    for (q = 0; q < s->nnear; ++q) {
      const int32_t i = s->near[q];
      struct px_gran_wpart P;
      GR fx = 0, fy = 0, tq = 0, ee = 0;
      int noc = 0;
      P.x = x[i], P.y = y[i], P.vx = ((const GS *)s->vx)[i], P.vy = ((const GS *)s->vy)[i];
      P.w = ((const GS *)s->w)[i], P.r = r[i], P.m = ((const GR *)s->m)[i], P.id = s->id[i];
      px_gran_wall_particle(&L, &W, &S, (int)i, &P, s->wcand + s->wstart[i],
                            s->wstart[i + 1] - s->wstart[i], (GR)s->dt, (int)s->step, 0, &fx,
                            &fy, &tq, NULL, NULL, NULL, NULL, NULL, &noc, &ee);
      e += (double)ee;
    }
  }
  return e;
}

static void PX_GRAN_SFX(get)(const struct px_gran_sys *s, size_t i, double out[8]) {
  out[PX_GRAN_P_X] = (double)((const GS *)s->x)[i];
  out[PX_GRAN_P_Y] = (double)((const GS *)s->y)[i];
  out[PX_GRAN_P_VX] = (double)((const GS *)s->vx)[i];
  out[PX_GRAN_P_VY] = (double)((const GS *)s->vy)[i];
  out[PX_GRAN_P_W] = (double)((const GS *)s->w)[i];
  out[PX_GRAN_P_R] = (double)((const GR *)s->r)[i];
  out[PX_GRAN_P_M] = (double)((const GR *)s->m)[i];
  out[PX_GRAN_P_ID] = (double)s->id[i];
}

static void PX_GRAN_SFX(set)(struct px_gran_sys *s, size_t i, const double in[8]) {
  ((GS *)s->x)[i] = (GS)in[PX_GRAN_P_X];
  ((GS *)s->y)[i] = (GS)in[PX_GRAN_P_Y];
  ((GS *)s->vx)[i] = (GS)in[PX_GRAN_P_VX];
  ((GS *)s->vy)[i] = (GS)in[PX_GRAN_P_VY];
  ((GS *)s->w)[i] = (GS)in[PX_GRAN_P_W];
  ((GR *)s->r)[i] = (GR)in[PX_GRAN_P_R];
  ((GR *)s->m)[i] = (GR)in[PX_GRAN_P_M];
  ((GR *)s->im)[i] = (GR)(1.0 / in[PX_GRAN_P_M]);
  ((GR *)s->iI)[i] = (GR)(2.0 / (in[PX_GRAN_P_M] * in[PX_GRAN_P_R] * in[PX_GRAN_P_R]));
}

const struct px_gran_cpu_ops PX_GRAN_OPS = {
    PX_GRAN_SFX(forces),      PX_GRAN_SFX(vv_drift), PX_GRAN_SFX(vv_kick),
    PX_GRAN_SFX(abm_predict), PX_GRAN_SFX(abm_correct), PX_GRAN_SFX(build_pairs),
    PX_GRAN_SFX(energy),      PX_GRAN_SFX(get),      PX_GRAN_SFX(set),
    PX_GRAN_SFX(elastic)};

#undef GS
#undef GR
