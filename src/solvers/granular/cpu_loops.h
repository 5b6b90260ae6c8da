/* The cpu loops of the granular solver, instantiated once per precision by
 * cpu_f64.c, cpu_mixed.c and cpu_f32.c, which define before including:
 *   PX_REAL        contact arithmetic (float | double)
 *   PX_GRAN_STATE  state arithmetic (float | double)
 *   PX_GRAN_OPS    name of the exported ops table
 *   PX_GRAN_SFX(n) n with the instantiation's suffix
 * No include guard: one instantiation per translation unit. */

/* clang reports `omp simd` loops it leaves scalar as warnings; gcc (the
 * reference compiler here) vectorizes them. */
#if defined(__clang__)
#pragma clang diagnostic ignored "-Wpass-failed"
#endif
#include <math.h>
#include <omp.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "core/steal.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/integrate_kernel.h"
#include "solvers/granular/system.h"
#include "solvers/granular/wall_kernel.h"
/* last: px_kernel.h brings <tgmath.h>; the loops below call math functions
 * on doubles only, where it changes nothing */
#include "solvers/granular/pair_kernel.h"

#define GS PX_GRAN_STATE
#define GR PX_REAL
/* The system's arrays (union px_gran_reals) in this instantiation's types:
 * state precision (GS) and contact precision (GR). */
#define PX_GRAN_SA(u) _Generic((GS)0, float : (u).f, double : (u).d)
#define PX_GRAN_CA(u) _Generic((GR)0, float : (u).f, double : (u).d)
/* SIMD lanes of the pair loops: 512-bit vectors where the compiler would
 * otherwise pick 256 (gcc's default on AVX-512 machines). */
#ifndef PX_GRAN_SIMDLEN
#define PX_GRAN_SIMDLEN (64 / (int)sizeof(GR))
#endif
/* What the pair loops gather positions and velocities from. */
#ifdef PX_GRAN_RELPOS
#define PX_GRAN_PT GR
/* The first and the second real of pair i of an interleaved array (x, y, x,
 * y, ...), both from one 64-bit load: a vector loop then gathers each pair of
 * reals with one 64-bit gather instead of two 32-bit ones. */
static inline GR px_gran_lo(const GR *a, int32_t i) {
  uint64_t v;
  uint32_t u;
  GR f;
  memcpy(&v, a + 2 * (size_t)i, sizeof v);
  u = (uint32_t)v;
  memcpy(&f, &u, sizeof f);
  return f;
}
static inline GR px_gran_hi(const GR *a, int32_t i) {
  uint64_t v;
  uint32_t u;
  GR f;
  memcpy(&v, a + 2 * (size_t)i, sizeof v);
  u = (uint32_t)(v >> 32);
  memcpy(&f, &u, sizeof f);
  return f;
}
#else
#define PX_GRAN_PT GS
#endif

/* A particle's force accumulator (fx, fy, torque, a scratch lane nobody
 * reads) and a pair's record (fx, fy on i, the torques on i and j) as one
 * vector each: the scatter of a record adds it to i in one operation and
 * px_gran_on_j of it to j in another (a GCC/clang vector extension). */
typedef GR px_gran_v4 __attribute__((vector_size(4 * sizeof(GR))));

/* What j loses of a record p = (fx, fy, ti, tj): (fx, fy, -tj, ti), so that
 * subtracting it gives j's fx - fx, fy - fy and torque + tj, to the bit
 * the three scalar operations (x - (-t) is x + t in IEEE arithmetic). */
static inline px_gran_v4 px_gran_on_j(px_gran_v4 p) {
  return __builtin_shufflevector(p, -p, 0, 1, 7, 2);
}

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
  L->ikt = p[PX_GRAN_LAW_KT] > 0 ? (GR)(1 / p[PX_GRAN_LAW_KT]) : (GR)0;
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
typedef void (*PX_GRAN_SFX(pair_fn))(const struct px_gran_law *, const PX_GRAN_PT *restrict,
                                     const PX_GRAN_PT *restrict, const PX_GRAN_PT *restrict,
                                     const PX_GRAN_PT *restrict, const PX_GRAN_PT *restrict,
                                     const GR *restrict, const GR *restrict, const GR *restrict,
                                     const GR *restrict, const GR *restrict, const GR *restrict,
                                     const int32_t *restrict, const int32_t *restrict, GR *restrict,
                                     GR *restrict, GR *restrict, GR *restrict, GR *restrict,
                                     GR *restrict, GR *restrict, GR *restrict, size_t, size_t, GR);
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
    {{PX_GRAN_SFX(pairs_lin_none_0), PX_GRAN_SFX(pairs_lin_none_1)},
     {PX_GRAN_SFX(pairs_lin_spring_0), PX_GRAN_SFX(pairs_lin_spring_1)},
     {PX_GRAN_SFX(pairs_lin_visc_0), PX_GRAN_SFX(pairs_lin_visc_1)}},
    {{PX_GRAN_SFX(pairs_hys_none_0), PX_GRAN_SFX(pairs_hys_none_1)},
     {PX_GRAN_SFX(pairs_hys_spring_0), PX_GRAN_SFX(pairs_hys_spring_1)},
     {PX_GRAN_SFX(pairs_hys_visc_0), PX_GRAN_SFX(pairs_hys_visc_1)}}};

/* Pair forces of pairs [k0, k1) into the per-pair records; commit = 0
 * writes the updated histories to scratch arrays (predictor evaluation).
 * pt: what the loops gather (see cpu_pair_loop.h). */
static void PX_GRAN_SFX(pair_pass)(struct px_gran_sys *s, const struct px_gran_law *law,
                                   const PX_GRAN_PT *const pt[5], size_t k0, size_t k1,
                                   int commit) {
  GR *h[4];
  const int nm = law->normal == PX_GRAN_NORMAL_HYSTERETIC;
  const int tm = law->tangential;
  const int rm = law->mur > (GR)0;
  h[0] = PX_GRAN_CA(s->pxi), h[1] = PX_GRAN_CA(s->pth), h[2] = PX_GRAN_CA(s->pdm),
  h[3] = PX_GRAN_CA(s->pdp);
  if (!commit) {
    /* a copy of this thread's range of the histories, updated and dropped */
    GR *scratch = PX_GRAN_CA(s->phist_scratch);
    int q;
    for (q = 0; q < 4; ++q) {
      memcpy(scratch + (size_t)q * s->npairs + k0, h[q] + k0, (k1 - k0) * sizeof(GR));
      h[q] = scratch + (size_t)q * s->npairs;
    }
  }
  PX_GRAN_SFX(pair_loops)
  [nm][tm][rm](law, pt[0], pt[1], pt[2], pt[3], pt[4], PX_GRAN_CA(s->pdxr), PX_GRAN_CA(s->pdyr),
               PX_GRAN_CA(s->pri), PX_GRAN_CA(s->prj), PX_GRAN_CA(s->pme), PX_GRAN_CA(s->pre),
               s->pi, s->pj, h[0], h[1], h[2], h[3], PX_GRAN_CA(s->pfx), PX_GRAN_CA(s->pfy),
               PX_GRAN_CA(s->pti), PX_GRAN_CA(s->ptj), k0, k1, (GR)s->dt);
}

/* Wall contacts of near-wall particles near[q0..q1), added to the force
 * accumulators; events and contour reactions go to the buffers of virtual
 * thread vt. */
static void PX_GRAN_SFX(wall_pass)(struct px_gran_sys *s, const struct px_gran_law *law,
                                   const GS *x, const GS *y, const GS *vx, const GS *vy,
                                   const GS *w, size_t q0, size_t q1, int commit, int vt) {
  const struct px_gran_geom *g = s->geom;
  struct px_gran_walls W;
  struct px_gran_wslots S;
  const GR *r = PX_GRAN_CA(s->r), *m = PX_GRAN_CA(s->m);
  GR *ff = PX_GRAN_CA(s->ff);
  int evi[PX_GRAN_WEVENTS * PX_GRAN_EVI];
  GR evr[PX_GRAN_WEVENTS * PX_GRAN_EVR];
  int oc[PX_GRAN_WMAX];
  GR ofx[PX_GRAN_WMAX], ofy[PX_GRAN_WMAX];
  double *cf = s->cforce_t + (size_t)vt * 2 * s->ncontours;
  int *tev_i = s->ev_i + (size_t)vt * s->ev_cap * PX_GRAN_EVI;
  GR *tev_r = PX_GRAN_CA(s->ev_r) + (size_t)vt * s->ev_cap * PX_GRAN_EVR;
  size_t q;
  W.ax = PX_GRAN_SA(s->seg_ax), W.ay = PX_GRAN_SA(s->seg_ay), W.tx = PX_GRAN_SA(s->seg_tx),
  W.ty = PX_GRAN_SA(s->seg_ty), W.len = PX_GRAN_SA(s->seg_len);
  W.tpx = PX_GRAN_SA(s->seg_tpx), W.tpy = PX_GRAN_SA(s->seg_tpy), W.flags = g->flags,
  W.contour = g->contour;
  W.cfirst = s->seg_cfirst, W.ccount = s->seg_ccount, W.frame = PX_GRAN_SA(s->sframes);
  S.seg = s->slots.seg, S.seg0 = s->slots.seg0, S.step0 = s->slots.step0;
  S.t0 = PX_GRAN_CA(s->slots.t0), S.te = PX_GRAN_CA(s->slots.te), S.xi = PX_GRAN_CA(s->slots.xi),
  S.th = PX_GRAN_CA(s->slots.th);
  S.dm = PX_GRAN_CA(s->slots.dm), S.dp = PX_GRAN_CA(s->slots.dp), S.imp = PX_GRAN_CA(s->slots.imp),
  S.slw = PX_GRAN_CA(s->slots.slw);
  S.arc = PX_GRAN_CA(s->slots.arc), S.tim = PX_GRAN_CA(s->slots.tim);
  for (q = q0; q < q1; ++q) {
    const int32_t i = s->near[q];
    struct px_gran_wpart P;
    GR fx = 0, fy = 0, tq = 0;
    int nev, noc = 0, e;
    P.x = x[i], P.y = y[i], P.vx = vx[i], P.vy = vy[i], P.w = w[i];
    P.r = r[i], P.m = m[i], P.id = s->id[i];
    nev = px_gran_wall_particle(law, &W, &S, (int)i, &P, s->wcand + s->wstart[i],
                                s->wstart[i + 1] - s->wstart[i], (GR)s->dt, (int)s->step, commit,
                                &fx, &fy, &tq, evi, evr, oc, ofx, ofy, &noc, NULL);
    ff[4 * i] += fx;
    ff[4 * i + 1] += fy;
    ff[4 * i + 2] += tq;
    for (e = 0; e < noc; ++e) {
      cf[2 * oc[e]] -= (double)ofx[e];
      cf[2 * oc[e] + 1] -= (double)ofy[e];
    }
    for (e = 0; e < nev; ++e) {
      const size_t at = s->ev_n[vt];
      if (at >= s->ev_cap) {
#pragma omp atomic
        ++s->ev_overflow; /* statistics lose an event; reported at the end */
        continue;
      }
      memcpy(tev_i + at * PX_GRAN_EVI, evi + e * PX_GRAN_EVI, PX_GRAN_EVI * sizeof(int));
      memcpy(tev_r + at * PX_GRAN_EVR, evr + e * PX_GRAN_EVR, PX_GRAN_EVR * sizeof(GR));
      s->ev_n[vt] = at + 1;
    }
  }
}

/* What one force evaluation needs, shared by the threads of a region. */
struct PX_GRAN_SFX(feval) {
  struct px_gran_sys *s;
  const GS *x, *y;         /* state the forces see */
  GS *vx, *vy, *w;         /* (kick: updated in place) */
  GS *ax, *ay, *aw;        /* accelerations out (kick: old in, new out) */
  const PX_GRAN_PT *pt[5]; /* what the pair loops gather */
  struct px_gran_law lpp, lpw;
  int commit, kick, drift;
  int vt0, vt1;                  /* the ranges this rank computes (all on one rank) */
  enum px_status st;             /* of the ranks' exchanges inside the region */
  double disp2[256], vmax2[256]; /* per range (drift / kick) */
  double nonfinite[256];         /* per range: 0 when every value the drift and the
                                    kick wrote is finite, NaN otherwise (sums of
                                    0 * value: exact, never overflow) */
  struct px_steal q[3];          /* the ranges of each phase (core/steal.h): one cut */
  int deps;                      /* tasks wait for their inputs only (one rank) */
  /* deps: phase p of range r is done; each flag on its own cache line, so
   * that a thread waiting for one range does not take the line another
   * thread is about to write (last: only the ranges used are zeroed) */
  struct {
    _Alignas(64) _Atomic int v;
  } done[3][256];
};

/* The threads' chunks of the ranges [vt0, vt1), the same for the three
 * phases (a thread's discs stay in its cache from the drift to the kick),
 * balanced by an estimate of each range's work: its pairs, discs and
 * near-wall discs. */
static void PX_GRAN_SFX(feval_cut)(struct PX_GRAN_SFX(feval) * F) {
  const struct px_gran_sys *s = F->s;
  const int n = F->vt1 - F->vt0, nt = s->active < 1 ? 1 : s->active;
  double weight[256];
  int bounds[PX_STEAL_MAX + 1], k;
  for (k = 0; k < n; ++k) {
    const int vt = F->vt0 + k;
    const size_t i0 = s->rng_i[vt], i1 = s->rng_i[vt + 1];
    weight[k] = (double)(s->pstart[i1] - s->pstart[i0]) + 2.0 * (double)(i1 - i0) +
                8.0 * (double)(s->rng_q[vt + 1] - s->rng_q[vt]);
  }
  px_steal_cut(weight, n, nt, bounds);
  for (k = 0; k < 3; ++k) px_steal_init(&F->q[k], bounds, nt);
}

static void PX_GRAN_SFX(feval_init)(struct PX_GRAN_SFX(feval) * F, struct px_gran_sys *s,
                                    const union px_gran_reals st[5],
                                    const union px_gran_reals acc[3], int commit, int kick,
                                    int drift) {
  int p, r;
  memset(F, 0, offsetof(struct PX_GRAN_SFX(feval), done));
  for (p = 0; p < 3; ++p)
    for (r = 0; r < s->nranges; ++r) atomic_init(&F->done[p][r].v, 0);
  F->s = s;
  F->x = PX_GRAN_SA(st[0]), F->y = PX_GRAN_SA(st[1]), F->vx = PX_GRAN_SA(st[2]);
  F->vy = PX_GRAN_SA(st[3]), F->w = PX_GRAN_SA(st[4]);
  F->ax = PX_GRAN_SA(acc[0]), F->ay = PX_GRAN_SA(acc[1]), F->aw = PX_GRAN_SA(acc[2]);
  F->commit = commit, F->kick = kick, F->drift = drift;
  F->vt1 = s->nranges;
  if (s->dist) px_gran_ranks_own(s, &F->vt0, &F->vt1);
  F->deps = !s->dist;
  PX_GRAN_SFX(law)(&s->pp, s->integrator == PX_GRAN_INTEGRATOR_VERLET, &F->lpp);
  PX_GRAN_SFX(law)(&s->pw, s->integrator == PX_GRAN_INTEGRATOR_VERLET, &F->lpw);
#ifdef PX_GRAN_RELPOS
  F->pt[0] = PX_GRAN_CA(s->fox), F->pt[1] = PX_GRAN_CA(s->fox) + 1, F->pt[2] = PX_GRAN_CA(s->fvx),
  F->pt[3] = PX_GRAN_CA(s->fvx) + 1, F->pt[4] = PX_GRAN_CA(s->fvw);
#else
  F->pt[0] = F->x, F->pt[1] = F->y, F->pt[2] = F->vx, F->pt[3] = F->vy, F->pt[4] = F->w;
#endif
  if (s->ncontours) memset(s->cforce_t, 0, (size_t)s->nranges * 2 * s->ncontours * sizeof(double));
  PX_GRAN_SFX(feval_cut)(F);
}

/* Over ranks (system_ranks.c), inside the region: stage 0, the ghosts'
 * state the pair loops gather (after the drift); stage 1, the pair records
 * of other ranks' pairs (after the pair pass). */
static enum px_status PX_GRAN_SFX(feval_halo)(struct PX_GRAN_SFX(feval) * F, int stage) {
  struct px_gran_sys *s = F->s;
  if (F->st != PX_STATUS_OK) return F->st;
  if (stage == 1) return px_gran_ranks_records(s);
#ifdef PX_GRAN_RELPOS
  void *const arr[8] = {(void *)F->x, (void *)F->y, F->vx,    F->vy,
                        F->w,         s->fox.p,     s->fvx.p, s->fvw.p};
  const size_t es[8] = {sizeof(GS), sizeof(GS),     sizeof(GS),     sizeof(GS),
                        sizeof(GS), 2 * sizeof(GR), 2 * sizeof(GR), sizeof(GR)};
  return px_gran_ranks_ghosts(s, arr, es, 8);
#else
  void *const arr[5] = {(void *)F->x, (void *)F->y, F->vx, F->vy, F->w};
  const size_t es[5] = {sizeof(GS), sizeof(GS), sizeof(GS), sizeof(GS), sizeof(GS)};
  return px_gran_ranks_ghosts(s, arr, es, 5);
#endif
}

/* Called by every thread of the region: over ranks, feval_halo on the
 * master thread (the process's main thread: MPI runs FUNNELED), the others
 * waiting at the barrier. */
static void PX_GRAN_SFX(feval_sync)(struct PX_GRAN_SFX(feval) * F, int stage) {
  if (!F->s->dist) return;
#pragma omp master
  F->st = PX_GRAN_SFX(feval_halo)(F, stage);
#pragma omp barrier
}

/* A force evaluation is split into s->nranges fixed particle ranges and
 * three phases per range; sums have the same order whatever thread runs a
 * range:
 *   0. (drift) velocity Verlet drift of the range; (mixed) float copies;
 *   1. zero the accumulators, add the wall forces, evaluate the range's
 *      pairs (SIMD), scatter them in pair order to i and to j (j in the
 *      range: pairs j > i of a cell-sorted list mostly stay inside);
 *   2. the pairs of earlier ranges whose j falls in this range (cross list,
 *      ascending), then the accelerations.
 * kick = 0: acc = F/m + g. kick = 1 (velocity Verlet): acc holds the old
 * accelerations on entry; v += dt/2 (a_new - a_old) and acc = a_new.
 * Each thread runs its own chunk of the ranges in every phase and then takes
 * the others' tails (feval_cut, core/steal.h). On one rank (F->deps) a task
 * waits only for the tasks it reads from, not for a whole phase: phase 1
 * of range t after phase 0 of ranges t .. rng_hi[t] (its pairs' partners),
 * phase 2 of range u after phase 1 of rng_lo[u] .. u (the pairs reaching
 * its discs, whose velocities its kick overwrites). Over ranks
 * (s->dist) each rank runs its own ranges [vt0, vt1) only, the phases
 * separated by barriers: after 0 it receives the ghosts its pairs reach,
 * after 1 the records of earlier ranks' pairs whose partner is its own
 * (feval_halo). */
static void PX_GRAN_SFX(feval_p0)(struct PX_GRAN_SFX(feval) * F, int vt) {
  struct px_gran_sys *s = F->s;
  const GS h = (GS)s->dt;
  const size_t i0 = s->rng_i[vt], i1 = s->rng_i[vt + 1];
  size_t i;
  if (F->drift) {
    GS *restrict x = PX_GRAN_SA(s->x), *restrict y = PX_GRAN_SA(s->y),
                 *restrict vx = PX_GRAN_SA(s->vx), *restrict vy = PX_GRAN_SA(s->vy),
                 *restrict w = PX_GRAN_SA(s->w);
    const GS *restrict ax = PX_GRAN_SA(s->fx), *restrict ay = PX_GRAN_SA(s->fy),
                       *restrict aw = PX_GRAN_SA(s->tq);
    const GS *restrict xr = PX_GRAN_SA(s->xr), *restrict yr = PX_GRAN_SA(s->yr);
#ifdef PX_GRAN_RELPOS
    GR *restrict fo = PX_GRAN_CA(s->fox), *restrict fv = PX_GRAN_CA(s->fvx),
                 *restrict fvw = PX_GRAN_CA(s->fvw);
#endif
    GS best = 0, bad = 0;
#pragma omp simd reduction(max : best) reduction(+ : bad)
    for (i = i0; i < i1; ++i) {
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
#ifdef PX_GRAN_RELPOS
      /* the float copies the pair loops gather, in the same pass */
      fo[2 * i] = (GR)dx;
      fo[2 * i + 1] = (GR)dy;
      fv[2 * i] = (GR)vxi;
      fv[2 * i + 1] = (GR)vyi;
      fvw[i] = (GR)wi;
#endif
      d2 = dx * dx + dy * dy;
      best = d2 > best ? d2 : best;
      bad += (GS)0 * xi + (GS)0 * yi;
    }
    F->disp2[vt] = (double)best;
    F->nonfinite[vt] += (double)bad;
  }
#ifdef PX_GRAN_RELPOS
  else {
    /* float offsets from the rebuild positions and float velocities */
    const GS *restrict x = F->x, *restrict y = F->y, *restrict vx = F->vx, *restrict vy = F->vy,
                       *restrict w = F->w;
    const GS *restrict xr = PX_GRAN_SA(s->xr), *restrict yr = PX_GRAN_SA(s->yr);
    GR *restrict fo = PX_GRAN_CA(s->fox), *restrict fv = PX_GRAN_CA(s->fvx),
                 *restrict fvw = PX_GRAN_CA(s->fvw);
#pragma omp simd
    for (i = i0; i < i1; ++i) {
      fo[2 * i] = (GR)(x[i] - xr[i]);
      fo[2 * i + 1] = (GR)(y[i] - yr[i]);
      fv[2 * i] = (GR)vx[i];
      fv[2 * i + 1] = (GR)vy[i];
      fvw[i] = (GR)w[i];
    }
  }
#endif
}

static void PX_GRAN_SFX(feval_p1)(struct PX_GRAN_SFX(feval) * F, int vt) {
  struct px_gran_sys *s = F->s;
  const size_t i0 = s->rng_i[vt], i1 = s->rng_i[vt + 1];
  const size_t k0 = (size_t)s->pstart[i0], k1 = (size_t)s->pstart[i1];
  px_gran_v4 *restrict ff = (px_gran_v4 *)PX_GRAN_CA(s->ff);
  const GR *restrict pfx = PX_GRAN_CA(s->pfx), *restrict pfy = PX_GRAN_CA(s->pfy),
                     *restrict pti = PX_GRAN_CA(s->pti), *restrict ptj = PX_GRAN_CA(s->ptj);
  const int32_t *restrict pi = s->pi, *restrict pj = s->pj;
  size_t k;
  memset(ff + i0, 0, (i1 - i0) * sizeof(px_gran_v4));
  if (s->geom) PX_GRAN_SFX(wall_pass)
  (s, &F->lpw, F->x, F->y, F->vx, F->vy, F->w, s->rng_q[vt], s->rng_q[vt + 1], F->commit, vt);
  PX_GRAN_SFX(pair_pass)(s, &F->lpp, F->pt, k0, k1, F->commit);
  for (k = k0; k < k1; ++k) {
    const int32_t i = pi[k], j = pj[k];
    const px_gran_v4 p = {pfx[k], pfy[k], pti[k], ptj[k]};
    ff[i] += p;
    if ((size_t)j < i1) ff[j] -= px_gran_on_j(p);
  }
}

static void PX_GRAN_SFX(feval_p2)(struct PX_GRAN_SFX(feval) * F, int vt) {
  struct px_gran_sys *s = F->s;
  const GS gx = (GS)s->gravity[0], gy = (GS)s->gravity[1], h = (GS)s->dt;
  const size_t i0 = s->rng_i[vt], i1 = s->rng_i[vt + 1];
  GR *restrict ff = PX_GRAN_CA(s->ff);
  const GR *restrict im = PX_GRAN_CA(s->im), *restrict iI = PX_GRAN_CA(s->iI);
  GS *restrict ax = F->ax, *restrict ay = F->ay, *restrict aw = F->aw;
  int32_t q;
  size_t i;
  for (q = s->xstart[vt]; q < s->xstart[vt + 1]; ++q) {
    const int32_t k = s->xpair[q], j = s->pj[k];
    const px_gran_v4 p = {PX_GRAN_CA(s->pfx)[k], PX_GRAN_CA(s->pfy)[k], PX_GRAN_CA(s->pti)[k],
                          PX_GRAN_CA(s->ptj)[k]};
    ((px_gran_v4 *)ff)[j] -= px_gran_on_j(p);
  }
  if (F->kick) {
    GS *restrict vxx = F->vx, *restrict vyy = F->vy, *restrict ww = F->w;
    GS vm = 0, bad = 0;
#pragma omp simd reduction(max : vm) reduction(+ : bad)
    for (i = i0; i < i1; ++i) {
      const GS anx = (GS)ff[4 * i] * (GS)im[i] + gx, any = (GS)ff[4 * i + 1] * (GS)im[i] + gy;
      const GS anw = (GS)ff[4 * i + 2] * (GS)iI[i];
      const GS nvx = px_gran_vv_kick(vxx[i], ax[i], anx, h);
      const GS nvy = px_gran_vv_kick(vyy[i], ay[i], any, h);
      const GS v2 = nvx * nvx + nvy * nvy;
      vxx[i] = nvx;
      vyy[i] = nvy;
      ww[i] = px_gran_vv_kick(ww[i], aw[i], anw, h);
      ax[i] = anx;
      ay[i] = any;
      aw[i] = anw;
      vm = v2 > vm ? v2 : vm;
      bad += (GS)0 * nvx + (GS)0 * nvy + (GS)0 * ww[i];
    }
    F->vmax2[vt] = (double)vm;
    F->nonfinite[vt] += (double)bad;
  } else {
#pragma omp simd
    for (i = i0; i < i1; ++i) {
      ax[i] = (GS)ff[4 * i] * (GS)im[i] + gx;
      ay[i] = (GS)ff[4 * i + 1] * (GS)im[i] + gy;
      aw[i] = (GS)ff[4 * i + 2] * (GS)iI[i];
    }
  }
}

/* Wait until ranges a .. b are done with phase p. A thread waits on phase
 * p only after every queue of phase p is empty (feval_run), so every task
 * waited for has been taken by a thread that runs it through: a phase-0
 * task never waits, a phase-1 task only for phase 0, so the waits cannot
 * close a cycle. */
static void PX_GRAN_SFX(feval_wait)(struct PX_GRAN_SFX(feval) * F, int p, int a, int b) {
  unsigned turns = 0;
  int r;
  for (r = a; r <= b; ++r)
    while (!atomic_load_explicit(&F->done[p][r].v, memory_order_acquire)) px_steal_pause(&turns);
}

/* Task vt of phase p, after the tasks it reads from (F->deps). */
static void PX_GRAN_SFX(feval_task)(struct PX_GRAN_SFX(feval) * F, int p, int vt) {
  const struct px_gran_sys *s = F->s;
  if (F->deps && p == 1) PX_GRAN_SFX(feval_wait)(F, 0, vt, s->rng_hi[vt]);
  if (F->deps && p == 2) PX_GRAN_SFX(feval_wait)(F, 1, s->rng_lo[vt], vt);
  if (p == 0)
    PX_GRAN_SFX(feval_p0)(F, vt);
  else if (p == 1)
    PX_GRAN_SFX(feval_p1)(F, vt);
  else
    PX_GRAN_SFX(feval_p2)(F, vt);
  if (F->deps) atomic_store_explicit(&F->done[p][vt].v, 1, memory_order_release);
}

/* The body of a force evaluation, called by every thread of a parallel
 * region (the phases and their order above). */
static void PX_GRAN_SFX(feval_run)(struct PX_GRAN_SFX(feval) * F) {
  const int me = omp_get_thread_num();
  int p, k;
  for (p = 0; p < 3; ++p) {
    for (k = px_steal_next(&F->q[p], me); k >= 0; k = px_steal_next(&F->q[p], me))
      PX_GRAN_SFX(feval_task)(F, p, F->vt0 + k);
    if (!F->deps && p < 2) {
#pragma omp barrier
      PX_GRAN_SFX(feval_sync)(F, p);
    }
  }
}

static void PX_GRAN_SFX(feval_finish)(struct PX_GRAN_SFX(feval) * F) {
  struct px_gran_sys *s = F->s;
  if (s->ncontours) {
    size_t c;
    int t;
    memset(s->cforce, 0, 2 * s->ncontours * sizeof(double));
    for (t = 0; t < s->nranges; ++t)
      for (c = 0; c < 2 * s->ncontours; ++c)
        s->cforce[c] += s->cforce_t[(size_t)t * 2 * s->ncontours + c];
  }
}

/* One force evaluation at the state st (x, y, vx, vy, w), see feval_run. */
static enum px_status PX_GRAN_SFX(forces)(struct px_gran_sys *s, const union px_gran_reals st[5],
                                          const union px_gran_reals acc[3], int commit, int kick) {
  struct PX_GRAN_SFX(feval) F;
  if (s->threads > 64) return px_context_fail(s->ctx, PX_STATUS_INVALID, "at most 64 threads");
  PX_GRAN_SFX(feval_init)(&F, s, st, acc, commit, kick, 0);
#pragma omp parallel num_threads(s->active)
  PX_GRAN_SFX(feval_run)(&F);
  if (s->dist && F.st == PX_STATUS_OK)
    F.st = px_gran_ranks_reduce(s, F.disp2, F.vmax2, F.nonfinite);
  if (F.st != PX_STATUS_OK) return F.st;
  PX_GRAN_SFX(feval_finish)(&F);
  return PX_STATUS_OK;
}

/* A whole velocity Verlet step in one parallel region: drift, forces (with
 * the histories committed), kick. Returns the largest squared displacement
 * since the last rebuild and the largest squared speed. */
static enum px_status PX_GRAN_SFX(vv_step)(struct px_gran_sys *s, double *maxdisp2, double *maxv2) {
  struct PX_GRAN_SFX(feval) F;
  union px_gran_reals st[5], acc[3];
  int t;
  if (s->threads > 64) return px_context_fail(s->ctx, PX_STATUS_INVALID, "at most 64 threads");
  st[0] = s->x, st[1] = s->y, st[2] = s->vx, st[3] = s->vy, st[4] = s->w;
  acc[0] = s->fx, acc[1] = s->fy, acc[2] = s->tq;
  PX_GRAN_SFX(feval_init)(&F, s, st, acc, 1, 1, 1);
#pragma omp parallel num_threads(s->active)
  PX_GRAN_SFX(feval_run)(&F);
  /* every range's results on every rank, summed below in range order */
  if (s->dist && F.st == PX_STATUS_OK)
    F.st = px_gran_ranks_reduce(s, F.disp2, F.vmax2, F.nonfinite);
  if (F.st != PX_STATUS_OK) return F.st;
  PX_GRAN_SFX(feval_finish)(&F);
  int bad = 0;
  *maxdisp2 = *maxv2 = 0;
  for (t = 0; t < s->nranges; ++t) {
    if (F.disp2[t] > *maxdisp2) *maxdisp2 = F.disp2[t];
    if (F.vmax2[t] > *maxv2) *maxv2 = F.vmax2[t];
    bad |= F.nonfinite[t] != 0;
  }
  /* a non-finite position or velocity: the caller finds the particle now,
   * at the step it appeared */
  if (bad) *maxv2 = (double)NAN;
  return PX_STATUS_OK;
}

#include "solvers/granular/cpu_abm_loops.h"

/* Pair `at` of the list: (i, q) and what it keeps from the rebuild. */
static inline void PX_GRAN_SFX(pair_fill)(struct px_gran_sys *s, int32_t at, int32_t i, int32_t q) {
  const GS *x = PX_GRAN_SA(s->x), *y = PX_GRAN_SA(s->y);
  const GR *r = PX_GRAN_CA(s->r), *im = PX_GRAN_CA(s->im);
  const double meff = 1.0 / ((double)im[i] + (double)im[q]);
  s->pi[at] = i;
  s->pj[at] = q;
  PX_GRAN_CA(s->pri)[at] = r[i];
  PX_GRAN_CA(s->prj)[at] = r[q];
  PX_GRAN_CA(s->pme)[at] = (GR)(s->pp_zeta2 * sqrt(meff * s->pp.kn));
  PX_GRAN_CA(s->pre)[at] = r[i] * r[q] / (r[i] + r[q]);
  PX_GRAN_CA(s->pdxr)[at] = (GR)(x[i] - x[q]);
  PX_GRAN_CA(s->pdyr)[at] = (GR)(y[i] - y[q]);
}

/* Pairs j > i within r_i + r_j + cut_extra over the cell grid (particles
 * sorted by cell; the cell of each slot is the grid's, so every particle is
 * searched from the cell it is listed in). pass 0: count[i] = number of
 * pairs of i, the first s->pcache_n partners kept in s->pcache; pass 1:
 * fill pj from pstart (pi too), from the kept partners where they are all
 * (most particles: the search runs once), else by the search again. */
static void PX_GRAN_SFX(build_pairs)(struct px_gran_sys *s, double cut_extra, int pass,
                                     int32_t *count) {
  const GS *x = PX_GRAN_SA(s->x), *y = PX_GRAN_SA(s->y);
  const GR *r = PX_GRAN_CA(s->r);
  const long n = (long)s->n;
  const int nx = s->gnx, ny = s->gny, pc = s->pcache_n;
  const GS ce = (GS)cut_extra;
  long i;
#pragma omp parallel for num_threads(s->active) schedule(static)
  for (i = 0; i < n; ++i) {
    const int ci = (int)(s->cell[i] % (uint32_t)nx), cj = (int)(s->cell[i] / (uint32_t)nx);
    int32_t *kept = s->pcache + (size_t)i * (size_t)pc;
    int a, b, cnt = 0;
    int32_t at = pass ? s->pstart[i] : 0;
    if (pass && s->pstart[i + 1] - at <= pc) {
      for (; at < s->pstart[i + 1]; ++at, ++cnt)
        PX_GRAN_SFX(pair_fill)(s, at, (int32_t)i, kept[cnt]);
      continue;
    }
    /* partners q > i only: the discs are sorted by cell, so the stencil's
     * cells of lower index (the row below, the cell to the left) hold none
     * and its own cell those after i; the rest in the same order as a
     * sweep of the whole stencil */
    for (b = cj; b <= cj + 1; ++b) {
      if (b >= ny) continue;
      for (a = b == cj ? ci : ci - 1; a <= ci + 1; ++a) {
        int32_t c, q;
        if (a < 0 || a >= nx) continue;
        c = b * nx + a;
        q = (int32_t)s->cstart[c];
        if (c == (int32_t)s->cell[i]) q = (int32_t)i + 1;
        for (; q < (int32_t)s->cend[c]; ++q) {
          GS dx, dy, cut;
          dx = x[i] - x[q];
          dy = y[i] - y[q];
          cut = (GS)r[i] + (GS)r[q] + ce;
          if (dx * dx + dy * dy >= cut * cut) continue;
          if (pass)
            PX_GRAN_SFX(pair_fill)(s, at++, (int32_t)i, q);
          else if (cnt < pc)
            kept[cnt] = q;
          ++cnt;
        }
      }
    }
    if (!pass) count[i] = cnt;
  }
}

static void PX_GRAN_SFX(energy)(const struct px_gran_sys *s, double *ek_t, double *ek_r,
                                long *bad) {
  const GS *x = PX_GRAN_SA(s->x), *y = PX_GRAN_SA(s->y), *vx = PX_GRAN_SA(s->vx),
           *vy = PX_GRAN_SA(s->vy), *w = PX_GRAN_SA(s->w);
  const GR *m = PX_GRAN_CA(s->m), *iI = PX_GRAN_CA(s->iI);
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
  const GS *x = PX_GRAN_SA(s->x), *y = PX_GRAN_SA(s->y);
  const GR *r = PX_GRAN_CA(s->r);
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
    W.ax = PX_GRAN_SA(s->seg_ax), W.ay = PX_GRAN_SA(s->seg_ay), W.tx = PX_GRAN_SA(s->seg_tx),
    W.ty = PX_GRAN_SA(s->seg_ty), W.len = PX_GRAN_SA(s->seg_len);
    W.tpx = PX_GRAN_SA(s->seg_tpx), W.tpy = PX_GRAN_SA(s->seg_tpy), W.flags = g->flags,
    W.contour = g->contour;
    W.cfirst = s->seg_cfirst, W.ccount = s->seg_ccount, W.frame = PX_GRAN_SA(s->sframes);
    S.seg = s->slots.seg, S.seg0 = s->slots.seg0, S.step0 = s->slots.step0;
    S.t0 = PX_GRAN_CA(s->slots.t0), S.te = PX_GRAN_CA(s->slots.te), S.xi = PX_GRAN_CA(s->slots.xi),
    S.th = PX_GRAN_CA(s->slots.th);
    S.dm = PX_GRAN_CA(s->slots.dm), S.dp = PX_GRAN_CA(s->slots.dp),
    S.imp = PX_GRAN_CA(s->slots.imp), S.slw = PX_GRAN_CA(s->slots.slw);
    S.arc = PX_GRAN_CA(s->slots.arc), S.tim = PX_GRAN_CA(s->slots.tim);
    for (q = 0; q < s->nnear; ++q) {
      const int32_t i = s->near[q];
      struct px_gran_wpart P;
      GR fx = 0, fy = 0, tq = 0, ee = 0;
      int noc = 0;
      P.x = x[i], P.y = y[i], P.vx = PX_GRAN_SA(s->vx)[i], P.vy = PX_GRAN_SA(s->vy)[i];
      P.w = PX_GRAN_SA(s->w)[i], P.r = r[i], P.m = PX_GRAN_CA(s->m)[i], P.id = s->id[i];
      px_gran_wall_particle(&L, &W, &S, (int)i, &P, s->wcand + s->wstart[i],
                            s->wstart[i + 1] - s->wstart[i], (GR)s->dt, (int)s->step, 0, &fx, &fy,
                            &tq, NULL, NULL, NULL, NULL, NULL, &noc, &ee);
      e += (double)ee;
    }
  }
  return e;
}

static void PX_GRAN_SFX(get)(const struct px_gran_sys *s, size_t i, double out[8]) {
  out[PX_GRAN_P_X] = (double)PX_GRAN_SA(s->x)[i];
  out[PX_GRAN_P_Y] = (double)PX_GRAN_SA(s->y)[i];
  out[PX_GRAN_P_VX] = (double)PX_GRAN_SA(s->vx)[i];
  out[PX_GRAN_P_VY] = (double)PX_GRAN_SA(s->vy)[i];
  out[PX_GRAN_P_W] = (double)PX_GRAN_SA(s->w)[i];
  out[PX_GRAN_P_R] = (double)PX_GRAN_CA(s->r)[i];
  out[PX_GRAN_P_M] = (double)PX_GRAN_CA(s->m)[i];
  out[PX_GRAN_P_ID] = (double)s->id[i];
}

static void PX_GRAN_SFX(set)(struct px_gran_sys *s, size_t i, const double in[8]) {
  PX_GRAN_SA(s->x)[i] = (GS)in[PX_GRAN_P_X];
  PX_GRAN_SA(s->y)[i] = (GS)in[PX_GRAN_P_Y];
  PX_GRAN_SA(s->vx)[i] = (GS)in[PX_GRAN_P_VX];
  PX_GRAN_SA(s->vy)[i] = (GS)in[PX_GRAN_P_VY];
  PX_GRAN_SA(s->w)[i] = (GS)in[PX_GRAN_P_W];
  PX_GRAN_CA(s->r)[i] = (GR)in[PX_GRAN_P_R];
  PX_GRAN_CA(s->m)[i] = (GR)in[PX_GRAN_P_M];
  PX_GRAN_CA(s->im)[i] = (GR)(1.0 / in[PX_GRAN_P_M]);
  PX_GRAN_CA(s->iI)[i] = (GR)(2.0 / (in[PX_GRAN_P_M] * in[PX_GRAN_P_R] * in[PX_GRAN_P_R]));
}

const struct px_gran_cpu_ops PX_GRAN_OPS = {
    PX_GRAN_SFX(forces),      PX_GRAN_SFX(vv_step),     PX_GRAN_SFX(abm_predict),
    PX_GRAN_SFX(abm_correct), PX_GRAN_SFX(build_pairs), PX_GRAN_SFX(energy),
    PX_GRAN_SFX(get),         PX_GRAN_SFX(set),         PX_GRAN_SFX(elastic)};

#undef GS
#undef GR
#undef PX_GRAN_PT
#undef PX_GRAN_SA
#undef PX_GRAN_CA
