/* The granular solver's reference engine (tests only, not in the backend
 * pick table of granular.c): the physics of the cpu and opencl engines
 * through the same functions (px_gran_pair, px_gran_wall_particle,
 * px_gran_vv_drift/kick, px_gran_ab4/am4 ..., compiled here in double),
 * driven by plain loops: one thread, every pair i < j of persistent ids by a
 * direct O(N^2) loop (no cell grid, no Verlet list, no reordering), every
 * wall segment a candidate of every particle. tests/granular/
 * test_granular_engines.c compares the fast engines with it.
 *
 * State, by persistent id, in double whatever the system's precision. It is
 * read from the prepared system through its public functions at `create`
 * and written back through s->ops->set at `sync`, so the engine does not
 * depend on the system's array layout.
 *
 * Histories: a pair's (tangential spring, rolling angle, largest overlap,
 * previous overlap) in a short list per lower id, kept while the pair is in
 * contact or its history is not the empty one; a pair without an entry has
 * the empty history, its previous overlap being recomputed from the
 * positions of the last committed evaluation (kept per id) when it touches
 * (the cpu list holds that value for every listed pair, and a pair that
 * comes into contact was listed the step before). A particle's wall
 * contacts: the PX_GRAN_WSLOTS slots of wall_kernel.h per id, matched to
 * segments by px_gran_wall_particle itself (the slot rule is physics: a
 * contact sliding over joints keeps its history).
 *
 * Not kept: wall statistics, the impact log and the contour reactions (the
 * reference is for the state): `create` refuses a system with statistics or
 * an impact log, and no checkpoint sections (save/load NULL) — a run is
 * compared from a freshly prepared system (step 0), whose contact histories
 * are empty and whose accelerations are recomputed here as prepare does. */
#define PX_REAL double
#define PX_GRAN_STATE double

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "partix/memory.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/granular_engine.h"
#include "solvers/granular/integrate_kernel.h"
#include "solvers/granular/wall_kernel.h"
/* last: px_kernel.h brings <tgmath.h>; this file calls math functions on
 * doubles only */
#include "solvers/granular/pair_kernel.h"

/* The history of pair (i, j), i < j, kept in i's list. */
struct px_gran_ref_ph {
  int32_t j;
  double xi, th, dm, dp; /* px_gran_contact's history: [m], [rad], [m], [m] */
};

struct px_gran_ref_plist {
  struct px_gran_ref_ph *h; /* owned */
  size_t n, cap;
};

/* Per-id arrays of doubles (PX_GRAN_REF_NARR of n each, one allocation). */
enum {
  PX_GRAN_REF_X,         /* state: x, y [m], vx, vy [m/s], w [rad/s] (5) */
  PX_GRAN_REF_AX = 5,    /* accelerations a = F/m + g [m/s^2], alpha [rad/s^2] (3) */
  PX_GRAN_REF_AN = 8,    /* new accelerations (velocity Verlet kick) (3) */
  PX_GRAN_REF_F = 11,    /* force and torque accumulators [N], [N m] (3) */
  PX_GRAN_REF_R = 14,    /* radius [m], mass [kg], 1/m, 1/I (4) */
  PX_GRAN_REF_PREV = 18, /* x, y of the last committed evaluation [m] (2) */
  PX_GRAN_REF_HIST = 20, /* ABM4: derivatives f_{n-1..n-3} of the state (15) */
  PX_GRAN_REF_XP = 35,   /* ABM4: predictor state (5) */
  PX_GRAN_REF_FA = 40,   /* ABM4: accelerations at the predictor (3) */
  PX_GRAN_REF_NV = 43,   /* ABM4: corrected state before it replaces the old (5) */
  PX_GRAN_REF_NARR = 48
};

struct px_gran_ref {
  struct px_gran_sys *s;        /* borrowed: read at create, written at sync */
  struct px_context *ctx;       /* borrowed: the system's */
  size_t n;                     /* particles (ids 0 .. n-1) */
  double *mem;                  /* owned: PX_GRAN_REF_NARR arrays of n */
  double *a[PX_GRAN_REF_NARR];  /* into mem */
  struct px_gran_ref_plist *ph; /* owned, n: histories of pairs (i, j > i) */
  int have_prev;                /* a committed evaluation happened */
  /* walls: the geometry's own double arrays (borrowed) and the slots */
  const struct px_gran_geom *geom;
  struct px_gran_walls W;
  struct px_gran_wslots S;
  int *ints;      /* owned: slot ints (3 n PX_GRAN_WSLOTS), candidates (nseg),
                     cfirst, ccount (ncontours) */
  double *slotr;  /* owned: slot reals (10 n PX_GRAN_WSLOTS) */
  double *frames; /* owned: PX_GRAN_CTR_COUNT per contour */
  int *cand;      /* every segment, ascending */
  int nseg;
  struct px_gran_law lpp, lpw;
  double g[2], dt, t;
  long step, abm_steps;
  int abm;
};

static void px_gran_ref_caps(struct px_backend *be, struct px_gran_caps *caps) {
  (void)be;
  caps->fp64 = 1;
  caps->abm4 = 1;
  caps->host_threads = 1;
  caps->ranks = 0;
  caps->why_no_abm4 = NULL;
}

/* The kernel law from the case's, in double (as the cpu loops fill theirs). */
static void px_gran_ref_law(const struct px_gran_law_spec *spec, int cells, struct px_gran_law *L) {
  double p[PX_GRAN_LAW_COUNT];
  px_gran_law_params(spec, cells, p);
  L->kn = p[PX_GRAN_LAW_KN];
  L->k2 = p[PX_GRAN_LAW_K2];
  L->phif = p[PX_GRAN_LAW_PHIF];
  L->zeta2 = p[PX_GRAN_LAW_ZETA2];
  L->ct_ratio = p[PX_GRAN_LAW_CT];
  L->kt = p[PX_GRAN_LAW_KT];
  L->ikt = p[PX_GRAN_LAW_KT] > 0 ? 1 / p[PX_GRAN_LAW_KT] : 0;
  L->mu = p[PX_GRAN_LAW_MU];
  L->mur = p[PX_GRAN_LAW_MUR];
  L->kr = p[PX_GRAN_LAW_KR];
  L->gt = p[PX_GRAN_LAW_GT];
  L->normal = (int)p[PX_GRAN_LAW_NORMAL];
  L->tangential = (int)p[PX_GRAN_LAW_TANGENTIAL];
  L->clamp = p[PX_GRAN_LAW_CLAMP];
  L->cells = p[PX_GRAN_LAW_CELLS];
  L->rolling = L->mur > 0;
}

/* Contour frames at time t [s] (as px_gran_sys_frames: a contour of no
 * moving body stays where it is). */
static void px_gran_ref_frames(struct px_gran_ref *e, double t) {
  const struct px_gran_sys *s = e->s;
  size_t c;
  for (c = 0; e->geom && c < e->geom->ncontours; ++c) {
    const int b = e->geom->contours[c].body;
    double *f = e->frames + c * PX_GRAN_CTR_COUNT;
    if (s->motions && b >= 0 && (size_t)b < s->nbodies) {
      px_gran_motion_frame(&s->motions[b], t, f);
    } else {
      memset(f, 0, PX_GRAN_CTR_COUNT * sizeof *f);
      f[PX_GRAN_CTR_COS] = 1;
    }
  }
}

static struct px_gran_ref_ph *px_gran_ref_find(struct px_gran_ref_plist *l, int32_t j) {
  size_t k;
  for (k = 0; k < l->n; ++k)
    if (l->h[k].j == j) return &l->h[k];
  return NULL;
}

/* Keep h in list l (a new entry when at is NULL), or drop it when it is
 * the empty history of a pair apart (what a pair without an entry has). */
static enum px_status px_gran_ref_keep(struct px_gran_ref *e, struct px_gran_ref_plist *l,
                                       struct px_gran_ref_ph *at, const struct px_gran_ref_ph *h) {
  const int empty = h->xi == 0 && h->th == 0 && h->dm == 0 && h->dp <= 0;
  if (at && empty) {
    *at = l->h[--l->n];
  } else if (at) {
    *at = *h;
  } else if (!empty) {
    if (l->n == l->cap) {
      const size_t cap = l->cap ? 2 * l->cap : 8;
      void *p = px_mem_realloc(e->ctx, "granular reference", l->h, cap * sizeof *l->h);
      if (!p) return PX_STATUS_NOMEM;
      l->h = p;
      l->cap = cap;
    }
    l->h[l->n++] = *h;
  }
  return PX_STATUS_OK;
}

/* Pair (i, j), i < j, at the state st: its force and torques added to the
 * accumulators; commit: its history kept. */
static enum px_status px_gran_ref_pair(struct px_gran_ref *e, double *const st[5], int32_t i,
                                       int32_t j, int commit) {
  double *const *a = e->a;
  const double *r = a[PX_GRAN_REF_R], *im = a[PX_GRAN_REF_R + 2];
  const double dx = st[0][i] - st[0][j], dy = st[1][i] - st[1][j];
  const double rs = r[i] + r[j];
  struct px_gran_ref_ph *at = px_gran_ref_find(&e->ph[i], j), h;
  double fx, fy, ti, tj;
  if (at) {
    h = *at;
  } else {
    /* no history and apart: the kernel would give no force and leave the
     * history empty (same arithmetic as px_gran_pair's overlap) */
    if (!(rs - sqrt(dx * dx + dy * dy) > 0)) return PX_STATUS_OK;
    memset(&h, 0, sizeof h);
    h.j = j;
    /* the overlap at the last committed evaluation (0: unknown, the start) */
    if (e->have_prev) {
      const double *px = a[PX_GRAN_REF_PREV], *py = a[PX_GRAN_REF_PREV + 1];
      const double ex = px[i] - px[j], ey = py[i] - py[j];
      h.dp = rs - sqrt(ex * ex + ey * ey);
    }
  }
  px_gran_pair(&e->lpp, dx, dy, st[2][i] - st[2][j], st[3][i] - st[3][j], st[4][i], st[4][j], r[i],
               r[j], px_gran_damping(&e->lpp, 1.0 / (im[i] + im[j])), r[i] * r[j] / (r[i] + r[j]),
               e->dt, &h.xi, &h.th, &h.dm, &h.dp, &fx, &fy, &ti, &tj);
  a[PX_GRAN_REF_F][i] += fx;
  a[PX_GRAN_REF_F + 1][i] += fy;
  a[PX_GRAN_REF_F + 2][i] += ti;
  a[PX_GRAN_REF_F][j] -= fx;
  a[PX_GRAN_REF_F + 1][j] -= fy;
  a[PX_GRAN_REF_F + 2][j] += tj;
  return commit ? px_gran_ref_keep(e, &e->ph[i], at, &h) : PX_STATUS_OK;
}

/* The wall contacts of particle i at the state st, added to the
 * accumulators (commit: slots kept; events dropped). */
static void px_gran_ref_wall(struct px_gran_ref *e, double *const st[5], int32_t i, int commit) {
  double *const *a = e->a;
  struct px_gran_wpart P;
  int evi[PX_GRAN_WEVENTS * PX_GRAN_EVI], noc = 0;
  double evr[PX_GRAN_WEVENTS * PX_GRAN_EVR], fx = 0, fy = 0, tq = 0;
  P.x = st[0][i], P.y = st[1][i], P.vx = st[2][i], P.vy = st[3][i], P.w = st[4][i];
  P.r = a[PX_GRAN_REF_R][i], P.m = a[PX_GRAN_REF_R + 1][i], P.id = (int)i;
  px_gran_wall_particle(&e->lpw, &e->W, &e->S, (int)i, &P, e->cand, e->nseg, e->dt, (int)e->step,
                        commit, &fx, &fy, &tq, evi, evr, NULL, NULL, NULL, &noc, NULL);
  a[PX_GRAN_REF_F][i] += fx;
  a[PX_GRAN_REF_F + 1][i] += fy;
  a[PX_GRAN_REF_F + 2][i] += tq;
}

/* One force evaluation at the state st (x, y, vx, vy, w by id): the
 * accelerations F/m + g and T/I into acc. commit: the histories and slots
 * are updated (else read only: an ABM4 predictor or the start). */
static enum px_status px_gran_ref_forces(struct px_gran_ref *e, double *const st[5],
                                         double *const acc[3], int commit) {
  double *const *a = e->a;
  const double *r = a[PX_GRAN_REF_R], *im = a[PX_GRAN_REF_R + 2], *iI = a[PX_GRAN_REF_R + 3];
  const int32_t n = (int32_t)e->n;
  int32_t i, j;
  int d;
  for (d = 0; d < 3; ++d) memset(a[PX_GRAN_REF_F + d], 0, e->n * sizeof(double));
  for (i = 0; i < n && e->geom; ++i) px_gran_ref_wall(e, st, i, commit);
  for (i = 0; i < n; ++i)
    for (j = i + 1; j < n; ++j) {
      /* skipped: a pair without history more than a contact distance apart
       * (px_gran_ref_pair would find it apart; saves most of the calls) */
      const double dx = st[0][i] - st[0][j], dy = st[1][i] - st[1][j], rs = r[i] + r[j];
      if (e->ph[i].n == 0 && dx * dx + dy * dy >= 4 * rs * rs) continue;
      PX_TRY(px_gran_ref_pair(e, st, i, j, commit));
    }
  for (i = 0; i < n; ++i) {
    acc[0][i] = a[PX_GRAN_REF_F][i] * im[i] + e->g[0];
    acc[1][i] = a[PX_GRAN_REF_F + 1][i] * im[i] + e->g[1];
    acc[2][i] = a[PX_GRAN_REF_F + 2][i] * iI[i];
  }
  if (commit) {
    memcpy(a[PX_GRAN_REF_PREV], st[0], e->n * sizeof(double));
    memcpy(a[PX_GRAN_REF_PREV + 1], st[1], e->n * sizeof(double));
    e->have_prev = 1;
  }
  return PX_STATUS_OK;
}

/* Velocity Verlet: drift, forces at the new time, kick. */
static enum px_status px_gran_ref_vv(struct px_gran_ref *e, double tnew) {
  double *const *a = e->a;
  double *st[5], *an[3];
  const double h = e->dt;
  size_t i;
  int d;
  for (d = 0; d < 5; ++d) st[d] = a[PX_GRAN_REF_X + d];
  for (d = 0; d < 3; ++d) an[d] = a[PX_GRAN_REF_AN + d];
  for (i = 0; i < e->n; ++i) {
    double dummy = 0;
    px_gran_vv_drift(&st[0][i], &st[2][i], a[PX_GRAN_REF_AX][i], h);
    px_gran_vv_drift(&st[1][i], &st[3][i], a[PX_GRAN_REF_AX + 1][i], h);
    px_gran_vv_drift(&dummy, &st[4][i], a[PX_GRAN_REF_AX + 2][i], h);
  }
  px_gran_ref_frames(e, tnew);
  PX_TRY(px_gran_ref_forces(e, st, an, 1));
  for (i = 0; i < e->n; ++i)
    for (d = 0; d < 3; ++d) {
      st[2 + d][i] = px_gran_vv_kick(st[2 + d][i], a[PX_GRAN_REF_AX + d][i], an[d][i], h);
      a[PX_GRAN_REF_AX + d][i] = an[d][i];
    }
  return PX_STATUS_OK;
}

/* ABM4 PECE (AB2/AM2, Euler's predictor at the very first step, while the
 * history fills), as integrate_kernel.h describes. */
static enum px_status px_gran_ref_abm(struct px_gran_ref *e, double tnew) {
  double *const *a = e->a;
  double *y[5], *f0[5], *fp[5], *xp[5], *fa[3], *hist[3][5];
  const double h = e->dt;
  const long stage = e->abm_steps;
  size_t i;
  int d, k;
  for (d = 0; d < 5; ++d) {
    y[d] = a[PX_GRAN_REF_X + d];
    xp[d] = a[PX_GRAN_REF_XP + d];
    for (k = 0; k < 3; ++k) hist[k][d] = a[PX_GRAN_REF_HIST + 5 * k + d];
  }
  for (d = 0; d < 3; ++d) fa[d] = a[PX_GRAN_REF_FA + d];
  /* derivatives: of x, y the velocities, of vx, vy, w the accelerations */
  f0[0] = y[2], f0[1] = y[3], f0[2] = a[PX_GRAN_REF_AX], f0[3] = a[PX_GRAN_REF_AX + 1];
  f0[4] = a[PX_GRAN_REF_AX + 2];
  fp[0] = xp[2], fp[1] = xp[3], fp[2] = fa[0], fp[3] = fa[1], fp[4] = fa[2];
  for (d = 0; d < 5; ++d)
    for (i = 0; i < e->n; ++i)
      xp[d][i] = stage >= 3   ? px_gran_ab4(y[d][i], f0[d][i], hist[0][d][i], hist[1][d][i],
                                            hist[2][d][i], h)
                 : stage >= 1 ? px_gran_ab2(y[d][i], f0[d][i], hist[0][d][i], h)
                              : y[d][i] + h * f0[d][i];
  px_gran_ref_frames(e, tnew);
  PX_TRY(px_gran_ref_forces(e, xp, fa, 0));
  for (d = 0; d < 5; ++d)
    for (i = 0; i < e->n; ++i)
      a[PX_GRAN_REF_NV + d][i] =
          stage >= 3 ? px_gran_am4(y[d][i], fp[d][i], f0[d][i], hist[0][d][i], hist[1][d][i], h)
                     : px_gran_am2(y[d][i], fp[d][i], f0[d][i], h);
  for (d = 0; d < 5; ++d) {
    memcpy(hist[2][d], hist[1][d], e->n * sizeof(double));
    memcpy(hist[1][d], hist[0][d], e->n * sizeof(double));
    memcpy(hist[0][d], f0[d], e->n * sizeof(double));
  }
  for (d = 0; d < 5; ++d) memcpy(y[d], a[PX_GRAN_REF_NV + d], e->n * sizeof(double));
  PX_TRY(px_gran_ref_forces(e, y, f0 + 2, 1));
  ++e->abm_steps;
  return PX_STATUS_OK;
}

static void px_gran_ref_destroy(void *ev) {
  struct px_gran_ref *e = ev;
  size_t i;
  if (!e) return;
  for (i = 0; e->ph && i < e->n; ++i) px_mem_free(e->ctx, e->ph[i].h);
  px_mem_free(e->ctx, e->ph);
  px_mem_free(e->ctx, e->mem);
  px_mem_free(e->ctx, e->ints);
  px_mem_free(e->ctx, e->slotr);
  px_mem_free(e->ctx, e->frames);
  px_mem_free(e->ctx, e);
}

/* The walls: the geometry's double arrays, every segment a candidate, the
 * slots free. */
static enum px_status px_gran_ref_walls(struct px_gran_ref *e) {
  const struct px_gran_geom *g = e->geom;
  const size_t ns = e->n * PX_GRAN_WSLOTS, nc = g->ncontours;
  double *r[10];
  int *cfirst, *ccount;
  size_t k;
  e->nseg = (int)g->nseg;
  e->ints = px_mem_alloc(e->ctx, "granular reference", (3 * ns + g->nseg + 2 * nc) * sizeof(int));
  e->slotr = px_mem_calloc(e->ctx, "granular reference", 10 * ns, sizeof(double));
  e->frames = px_mem_calloc(e->ctx, "granular reference", nc * PX_GRAN_CTR_COUNT, sizeof(double));
  if (!e->ints || !e->slotr || !e->frames) return PX_STATUS_NOMEM;
  for (k = 0; k < 10; ++k) r[k] = e->slotr + k * ns;
  for (k = 0; k < 3 * ns; ++k) e->ints[k] = k < ns ? -1 : 0;
  e->cand = e->ints + 3 * ns;
  for (k = 0; k < g->nseg; ++k) e->cand[k] = (int)k;
  cfirst = e->cand + g->nseg;
  ccount = cfirst + nc;
  for (k = 0; k < nc; ++k) {
    cfirst[k] = (int)g->contours[k].first;
    ccount[k] = (int)g->contours[k].count;
  }
  e->W.ax = g->ax, e->W.ay = g->ay, e->W.tx = g->tx, e->W.ty = g->ty, e->W.len = g->len;
  e->W.tpx = g->tpx, e->W.tpy = g->tpy, e->W.flags = g->flags, e->W.contour = g->contour;
  e->W.cfirst = cfirst, e->W.ccount = ccount, e->W.frame = e->frames;
  e->S.seg = e->ints, e->S.seg0 = e->ints + ns, e->S.step0 = e->ints + 2 * ns;
  e->S.t0 = r[0], e->S.te = r[1], e->S.xi = r[2], e->S.th = r[3], e->S.dm = r[4];
  e->S.dp = r[5], e->S.imp = r[6], e->S.slw = r[7], e->S.arc = r[8], e->S.tim = r[9];
  return PX_STATUS_OK;
}

/* The state by id from the system, the laws, the walls, and the
 * accelerations at the start (no commit: the histories start with the first
 * step, as px_gran_sys_prepare computes them). */
static enum px_status px_gran_ref_init(struct px_gran_ref *e) {
  struct px_gran_sys *s = e->s;
  double *const *a = e->a;
  double *st[5], *acc[3];
  int32_t id;
  int d;
  for (id = 0; id < (int32_t)e->n; ++id) {
    double rec[8];
    px_gran_sys_get(s, id, rec);
    for (d = 0; d < 5; ++d) a[PX_GRAN_REF_X + d][id] = rec[PX_GRAN_P_X + d];
    a[PX_GRAN_REF_R][id] = rec[PX_GRAN_P_R];
    a[PX_GRAN_REF_R + 1][id] = rec[PX_GRAN_P_M];
    /* as the system's set: 1/m and 1/I of a disc, I = m r^2 / 2 */
    a[PX_GRAN_REF_R + 2][id] = 1.0 / rec[PX_GRAN_P_M];
    a[PX_GRAN_REF_R + 3][id] = 2.0 / (rec[PX_GRAN_P_M] * rec[PX_GRAN_P_R] * rec[PX_GRAN_P_R]);
  }
  e->abm = s->integrator == PX_GRAN_INTEGRATOR_ABM4;
  px_gran_ref_law(&s->pp, !e->abm, &e->lpp);
  px_gran_ref_law(&s->pw, !e->abm, &e->lpw);
  e->g[0] = s->gravity[0], e->g[1] = s->gravity[1];
  e->dt = s->dt, e->t = s->t, e->step = s->step;
  if (e->geom) PX_TRY(px_gran_ref_walls(e));
  px_gran_ref_frames(e, e->t);
  for (d = 0; d < 5; ++d) st[d] = a[PX_GRAN_REF_X + d];
  for (d = 0; d < 3; ++d) acc[d] = a[PX_GRAN_REF_AX + d];
  return px_gran_ref_forces(e, st, acc, 0);
}

static enum px_status px_gran_ref_create(struct px_backend *be, struct px_gran_sys *s, void **out) {
  struct px_gran_ref *e;
  enum px_status st;
  int k;
  (void)be;
  *out = NULL;
  if (s->step != 0 || s->stats_on || s->impact_log)
    return px_context_fail(s->ctx, PX_STATUS_INVALID,
                           "the granular reference engine starts from a freshly prepared "
                           "system (step 0) and keeps no wall statistics or impact log");
  e = px_mem_calloc(s->ctx, "granular reference", 1, sizeof *e);
  if (!e) return PX_STATUS_NOMEM;
  e->s = s;
  e->ctx = s->ctx;
  e->n = s->n;
  e->geom = s->geom;
  e->mem = px_mem_calloc(s->ctx, "granular reference", PX_GRAN_REF_NARR * e->n, sizeof(double));
  e->ph = px_mem_calloc(s->ctx, "granular reference", e->n, sizeof *e->ph);
  if (!e->mem || !e->ph) {
    px_gran_ref_destroy(e);
    return PX_STATUS_NOMEM;
  }
  for (k = 0; k < PX_GRAN_REF_NARR; ++k) e->a[k] = e->mem + (size_t)k * e->n;
  st = px_gran_ref_init(e);
  if (st != PX_STATUS_OK) {
    px_gran_ref_destroy(e);
    return st;
  }
  *out = e;
  return PX_STATUS_OK;
}

static enum px_status px_gran_ref_step(void *ev, long step, double dt) {
  struct px_gran_ref *e = ev;
  size_t i;
  int d;
  if (step != e->step || dt != e->dt) {
    e->dt = dt; /* the case gave time.dt after an automatic dt */
    e->step = step;
    e->t = (double)step * dt;
  }
  PX_TRY(e->abm ? px_gran_ref_abm(e, e->t + e->dt) : px_gran_ref_vv(e, e->t + e->dt));
  e->t += e->dt;
  ++e->step;
  for (i = 0; i < e->n; ++i)
    for (d = 0; d < 5; ++d)
      if (!isfinite(e->a[PX_GRAN_REF_X + d][i]))
        return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                               "particle %zu has a non-finite state at step %ld (reference engine)",
                               i, e->step);
  return PX_STATUS_OK;
}

/* The state into the system's slots (its order: the ids it reports). */
static enum px_status px_gran_ref_sync(void *ev) {
  struct px_gran_ref *e = ev;
  struct px_gran_sys *s = e->s;
  double *ids = px_mem_alloc(e->ctx, "granular reference", (e->n ? e->n : 1) * sizeof(double));
  size_t k;
  int d;
  if (!ids) return PX_STATUS_NOMEM;
  px_gran_sys_export(s, NULL, NULL, NULL, NULL, NULL, NULL, NULL, ids);
  for (k = 0; k < e->n; ++k) {
    const size_t id = (size_t)ids[k];
    double rec[8];
    for (d = 0; d < 5; ++d) rec[PX_GRAN_P_X + d] = e->a[PX_GRAN_REF_X + d][id];
    rec[PX_GRAN_P_R] = e->a[PX_GRAN_REF_R][id];
    rec[PX_GRAN_P_M] = e->a[PX_GRAN_REF_R + 1][id];
    rec[PX_GRAN_P_ID] = ids[k];
    s->ops->set(s, k, rec);
  }
  px_mem_free(e->ctx, ids);
  s->step = e->step;
  s->t = e->t;
  return PX_STATUS_OK;
}

/* Pairs of ids i < j with overlap > 0 (px_gran_pair's), sorted. */
static enum px_status px_gran_ref_contacts(void *ev, int32_t **pairs, size_t *np) {
  struct px_gran_ref *e = ev;
  const double *x = e->a[PX_GRAN_REF_X], *y = e->a[PX_GRAN_REF_X + 1], *r = e->a[PX_GRAN_REF_R];
  size_t cap = 64, n = 0;
  int32_t i, j, *p = px_mem_alloc(e->ctx, "granular contacts", 2 * cap * sizeof *p);
  if (!p) return PX_STATUS_NOMEM;
  for (i = 0; i < (int32_t)e->n; ++i)
    for (j = i + 1; j < (int32_t)e->n; ++j) {
      const double dx = x[i] - x[j], dy = y[i] - y[j];
      if (!(r[i] + r[j] - sqrt(dx * dx + dy * dy) > 0)) continue;
      if (n == cap) {
        int32_t *q = px_mem_realloc(e->ctx, "granular contacts", p, 4 * cap * sizeof *p);
        if (!q) {
          px_mem_free(e->ctx, p);
          return PX_STATUS_NOMEM;
        }
        p = q;
        cap *= 2;
      }
      p[2 * n] = i;
      p[2 * n + 1] = j;
      ++n;
    }
  *pairs = p;
  *np = n;
  return PX_STATUS_OK;
}

const struct px_gran_engine_i px_gran_engine_ref = {.name = "reference",
                                                    .caps = px_gran_ref_caps,
                                                    .create = px_gran_ref_create,
                                                    .destroy = px_gran_ref_destroy,
                                                    .step = px_gran_ref_step,
                                                    .sync = px_gran_ref_sync,
                                                    .save = NULL,
                                                    .load = NULL,
                                                    .upload = NULL,
                                                    .contacts = px_gran_ref_contacts};
