/* Checkpoints of the granular system: every kept per-particle array and
 * the scalars of the run, and their loading, each section checked before
 * use (the file is untrusted). */
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
#include "solvers/granular/system_impl.h"
#include "solvers/granular/wall_kernel.h"

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
    const char *names[] = {"granular.pxi",  "granular.pth", "granular.pdm", "granular.pdp",
                           "granular.pri",  "granular.prj", "granular.pme", "granular.pre",
                           "granular.pdxr", "granular.pdyr"};
    const void *arrs[] = {s->pxi.p, s->pth.p, s->pdm.p, s->pdp.p,  s->pri.p,
                          s->prj.p, s->pme.p, s->pre.p, s->pdxr.p, s->pdyr.p};
    for (k = 0; k < 10; ++k)
      PX_TRY(px_checkpoint_write(w, names[k], PX_DTYPE_U8, np * cs, arrs[k]));
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
    const double *v[] = {S->impacts, S->vn_sum, S->vn2_sum, S->vn_max, S->vt_sum,  S->en,
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
  return px_context_fail(s->ctx, PX_STATUS_FORMAT,
                         "checkpoint section '%s': %s (a damaged or "
                         "forged checkpoint)",
                         section, msg);
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
                          (unsigned long long)have, px_dtype_name(t), count, px_dtype_name(type));
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

/* Section granular.scalars into sc: t, dt, step, rebuilds, rebuild flag,
 * ABM steps, and the counts of particles (the case's), pairs, wall
 * candidates and near-wall particles. */
static enum px_status px_gran_ck_scalars(struct px_gran_sys *s, struct px_checkpoint *ck,
                                         double sc[PX_GRAN_CK_SCALARS]) {
  const double step_max = 2147483647.0; /* the kernels count steps in int */
  const char *sec = "granular.scalars";
  double tc;
  size_t n;
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
    return px_gran_ck_bad(s, sec, "step %g: not the checkpoint's step %llu (or beyond %.0f)", sc[2],
                          (unsigned long long)px_checkpoint_step(ck), step_max);
  tc = px_gran_sys_contact_time(s);
  if (!(sc[0] >= 0) || !isfinite(sc[0]) || !(sc[1] > 0) || !(sc[1] <= tc / 5 * (1 + 1e-9)) ||
      !(sc[1] >= tc * 1e-6 * (1 - 1e-9)))
    return px_gran_ck_bad(s, sec,
                          "time %g s and time step %g s: needs t >= 0 and dt in [t_c / 1e6, "
                          "t_c / 5] with t_c = %g s of this case",
                          sc[0], sc[1], tc);
  if (!px_gran_ck_int(sc[3], 0, 9007199254740992.0) || !px_gran_ck_int(sc[4], 0, 1) ||
      !px_gran_ck_int(sc[5], 0, sc[2]))
    return px_gran_ck_bad(s, sec,
                          "rebuilds %g, rebuild flag %g, ABM steps %g: not counts (or "
                          "more ABM steps than steps)",
                          sc[3], sc[4], sc[5]);
  if (!px_gran_ck_int(sc[7], 0, (double)INT32_MAX) ||
      !px_gran_ck_int(sc[8], 0, (double)INT32_MAX) || !px_gran_ck_int(sc[9], 0, (double)n))
    return px_gran_ck_bad(s, sec,
                          "pair count %g, wall candidates %g, near-wall particles %g: "
                          "not counts within %d, %d and the %zu particles",
                          sc[7], sc[8], sc[9], INT32_MAX, INT32_MAX, n);
  if (!s->geom && (sc[8] > 0 || sc[9] > 0))
    return px_gran_ck_bad(s, sec, "%zu wall candidates for a case without contours", (size_t)sc[8]);
  return PX_STATUS_OK;
}

/* The kept per-particle arrays (n of each: the case's count) and where:
 * ids a permutation, radii and masses the case's, reals finite, wall slots
 * on segments of this geometry and started by step `step`. */
static enum px_status px_gran_ck_particles(struct px_gran_sys *s, struct px_checkpoint *ck,
                                           size_t n, double step) {
  struct px_gran_arr a[PX_GRAN_MAX_ARRAYS];
  const size_t na = px_gran_arrays(s, a), cs = s->csize, W = PX_GRAN_WSLOTS;
  const size_t nseg = s->geom ? s->geom->nseg : 0;
  double *mine = NULL; /* the case's r, m, 1/m, 1/I by id */
  unsigned char *seen = NULL;
  const char *sec;
  size_t k, i;
  enum px_status st = PX_STATUS_OK;
  /* the case's radii and masses by persistent id, before they are replaced */
  mine = px_mem_alloc(s->ctx, "granular checkpoint", (n ? n : 1) * 4 * sizeof *mine);
  seen = px_mem_calloc(s->ctx, "granular checkpoint", n ? n : 1, 1);
  if (!mine || !seen) {
    st = PX_STATUS_NOMEM;
    goto done;
  }
  for (i = 0; i < n; ++i) {
    const size_t id = (size_t)s->id[i];
    mine[4 * id + 0] = px_gran_reals_get(s->r, i, cs);
    mine[4 * id + 1] = px_gran_reals_get(s->m, i, cs);
    mine[4 * id + 2] = px_gran_reals_get(s->im, i, cs);
    mine[4 * id + 3] = px_gran_reals_get(s->iI, i, cs);
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
    if (px_gran_reals_get(s->r, i, cs) != mine[4 * id] ||
        px_gran_reals_get(s->m, i, cs) != mine[4 * id + 1] ||
        px_gran_reals_get(s->im, i, cs) != mine[4 * id + 2] ||
        px_gran_reals_get(s->iI, i, cs) != mine[4 * id + 3]) {
      st = px_gran_ck_bad(s, "granular.p.r",
                          "particle %zu: radius %g m and mass %g kg are not "
                          "the case's %g m and %g kg",
                          id, px_gran_reals_get(s->r, i, cs), px_gran_reals_get(s->m, i, cs),
                          mine[4 * id], mine[4 * id + 1]);
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
    lim = (a[k].p == &s->x.p || a[k].p == &s->y.p || a[k].p == &s->xr.p || a[k].p == &s->yr.p)
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
  /* wall slots: segments of this geometry (or -1), start steps not after
   * the checkpoint's */
  for (i = 0; i < n * W; ++i) {
    const int sg = s->slots.seg[i], s0 = s->slots.seg0[i], t0 = s->slots.step0[i];
    if (sg < -1 || (sg >= 0 && (size_t)sg >= nseg) || s0 < -1 || (s0 >= 0 && (size_t)s0 >= nseg) ||
        t0 < 0 || (double)t0 > step) {
      st = px_gran_ck_bad(s, "granular.p.slots.seg",
                          "slot %zu of particle %zu: segment %d, "
                          "start segment %d, start step %d (%zu segments, step %.0f)",
                          i % W, i / W, sg, s0, t0, nseg, step);
      goto done;
    }
  }

done:
  px_mem_free(s->ctx, mine);
  px_mem_free(s->ctx, seen);
  return st;
}

/* The half neighbour list (CSR by particle, partners after their owner)
 * with its histories and per-pair constants, np pairs. */
static enum px_status px_gran_ck_pairs(struct px_gran_sys *s, struct px_checkpoint *ck, size_t n,
                                       size_t np) {
  const size_t cs = s->csize;
  const char *sec;
  size_t k, i;
  enum px_status st;
  /* the half neighbour list: CSR by particle, partners after their owner */
  sec = "granular.pstart";
  st = px_gran_ck_read(s, ck, sec, PX_DTYPE_I32, n + 1, (void **)&s->pstart);
  if (st != PX_STATUS_OK) return st;
  if (s->pstart[0] != 0 || (size_t)s->pstart[n] != np)
    return px_gran_ck_bad(s, sec, "starts at %d and ends at %d, expected 0 and the %zu pairs",
                          (int)s->pstart[0], (int)s->pstart[n], np);
  for (i = 0; i < n; ++i)
    if (s->pstart[i + 1] < s->pstart[i])
      return px_gran_ck_bad(s, sec, "decreases at particle %zu", i);
  st = px_gran_ck_read(s, ck, "granular.pi", PX_DTYPE_I32, np, (void **)&s->pi);
  if (st == PX_STATUS_OK)
    st = px_gran_ck_read(s, ck, "granular.pj", PX_DTYPE_I32, np, (void **)&s->pj);
  if (st != PX_STATUS_OK) return st;
  for (i = 0; i < n; ++i) {
    int32_t q;
    for (q = s->pstart[i]; q < s->pstart[i + 1]; ++q)
      if (s->pi[q] != (int32_t)i || s->pj[q] <= (int32_t)i || (size_t)s->pj[q] >= n)
        return px_gran_ck_bad(s, s->pi[q] != (int32_t)i ? "granular.pi" : "granular.pj",
                              "pair %d: (%d, %d) in the list of particle %zu (partners are later "
                              "particles, below %zu)",
                              (int)q, (int)s->pi[q], (int)s->pj[q], i, n);
  }
  {
    const char *names[] = {"granular.pxi",  "granular.pth", "granular.pdm", "granular.pdp",
                           "granular.pri",  "granular.prj", "granular.pme", "granular.pre",
                           "granular.pdxr", "granular.pdyr"};
    void **arrs[] = {&s->pxi.p, &s->pth.p, &s->pdm.p, &s->pdp.p,  &s->pri.p,
                     &s->prj.p, &s->pme.p, &s->pre.p, &s->pdxr.p, &s->pdyr.p};
    for (k = 0; k < 10; ++k) {
      long bad;
      st = px_gran_ck_read(s, ck, names[k], PX_DTYPE_U8, np * cs, arrs[k]);
      if (st != PX_STATUS_OK) return st;
      bad = px_gran_ck_finite(*arrs[k], np, cs, 0);
      if (bad >= 0)
        return px_gran_ck_bad(s, names[k], "pair %ld: %g is not finite", bad,
                              px_gran_rd(*arrs[k], (size_t)bad, cs));
    }
    /* per-pair radii are those of its particles; damping and reduced radius
     * positive */
    for (k = 0; k < np; ++k)
      if (px_gran_reals_get(s->pri, k, cs) != px_gran_reals_get(s->r, (size_t)s->pi[k], cs) ||
          px_gran_reals_get(s->prj, k, cs) != px_gran_reals_get(s->r, (size_t)s->pj[k], cs) ||
          !(px_gran_reals_get(s->pme, k, cs) >= 0) || !(px_gran_reals_get(s->pre, k, cs) > 0))
        return px_gran_ck_bad(s, "granular.pri",
                              "pair %zu: radii %g, %g (particles' %g, %g), "
                              "damping %g, reduced radius %g",
                              k, px_gran_reals_get(s->pri, k, cs), px_gran_reals_get(s->prj, k, cs),
                              px_gran_reals_get(s->r, (size_t)s->pi[k], cs),
                              px_gran_reals_get(s->r, (size_t)s->pj[k], cs),
                              px_gran_reals_get(s->pme, k, cs), px_gran_reals_get(s->pre, k, cs));
  }
  {
    void **pa[] = {&s->pfx.p, &s->pfy.p, &s->pti.p, &s->ptj.p};
    for (k = 0; k < 4 && st == PX_STATUS_OK; ++k)
      st = px_gran_ensure(s, pa[k], (np ? np : 1) * cs, "granular pairs");
    if (st == PX_STATUS_OK)
      st = px_gran_ensure(s, &s->phist_scratch.p, 4 * (np ? np : 1) * cs, "granular pairs");
    if (st != PX_STATUS_OK) return st;
  }

  return PX_STATUS_OK;
}

/* The wall lists: CSR of nw candidate segments, the nn near-wall
 * particles. */
static enum px_status px_gran_ck_walls(struct px_gran_sys *s, struct px_checkpoint *ck, size_t n,
                                       size_t nw, size_t nn) {
  const size_t nseg = s->geom ? s->geom->nseg : 0;
  const char *sec;
  size_t i;
  enum px_status st;
  /* wall lists: CSR of candidate segments (ascending per particle, at most
   * as many as a rebuild makes), the near list exactly the particles with
   * candidates, ascending */
  sec = "granular.wstart";
  st = px_gran_ck_read(s, ck, sec, PX_DTYPE_I32, n + 1, (void **)&s->wstart);
  if (st == PX_STATUS_OK)
    st = px_gran_ck_read(s, ck, "granular.wcand", PX_DTYPE_I32, nw, (void **)&s->wcand);
  if (st == PX_STATUS_OK)
    st = px_gran_ck_read(s, ck, "granular.near", PX_DTYPE_I32, nn, (void **)&s->near);
  if (st != PX_STATUS_OK) return st;
  if (s->wstart[0] != 0 || (size_t)s->wstart[n] != nw)
    return px_gran_ck_bad(s, sec, "starts at %d and ends at %d, expected 0 and the %zu candidates",
                          (int)s->wstart[0], (int)s->wstart[n], nw);
  {
    size_t q = 0;
    for (i = 0; i < n; ++i) {
      int32_t c;
      const long long cnt = (long long)s->wstart[i + 1] - (long long)s->wstart[i];
      if (cnt < 0 || cnt > PX_GRAN_WCAND_MAX)
        return px_gran_ck_bad(s, sec, "particle %zu: %lld candidates (at most %d)", i, cnt,
                              PX_GRAN_WCAND_MAX);
      for (c = s->wstart[i]; c < s->wstart[i + 1]; ++c)
        if (s->wcand[c] < 0 || (size_t)s->wcand[c] >= nseg ||
            (c > s->wstart[i] && s->wcand[c] <= s->wcand[c - 1]))
          return px_gran_ck_bad(s, "granular.wcand",
                                "candidate %d of particle %zu: segment %d "
                                "(%zu segments, ascending)",
                                (int)(c - s->wstart[i]), i, (int)s->wcand[c], nseg);
      if (s->wstart[i + 1] > s->wstart[i]) {
        if (q >= nn || s->near[q] != (int32_t)i)
          return px_gran_ck_bad(s, "granular.near",
                                "entry %zu: %d, expected particle %zu (the "
                                "particles with candidates, ascending)",
                                q, q < nn ? (int)s->near[q] : -1, i);
        ++q;
      }
    }
    if (q != nn)
      return px_gran_ck_bad(s, "granular.near", "%zu entries for %zu particles with candidates", nn,
                            q);
  }
  return PX_STATUS_OK;
}

/* The contours' reference frames and reactions, and the per-segment
 * statistics. */
static enum px_status px_gran_ck_contours(struct px_gran_sys *s, struct px_checkpoint *ck) {
  const size_t nseg = s->geom ? s->geom->nseg : 0;
  const char *sec;
  size_t k;
  enum px_status st;
  if (s->geom) {
    long bad;
    sec = "granular.frames_ref";
    st = px_gran_ck_count(s, ck, sec, PX_DTYPE_F64, s->ncontours * PX_GRAN_CTR_COUNT);
    if (st == PX_STATUS_OK)
      st = px_checkpoint_read(ck, sec, PX_DTYPE_F64, s->ncontours * PX_GRAN_CTR_COUNT,
                              s->frames_ref);
    if (st != PX_STATUS_OK) return st;
    bad = px_gran_ck_finite(s->frames_ref, s->ncontours * PX_GRAN_CTR_COUNT, sizeof(double),
                            PX_GRAN_COORD_MAX);
    if (bad >= 0)
      return px_gran_ck_bad(s, sec, "value %ld = %g is not finite or beyond 1e12", bad,
                            s->frames_ref[bad]);
    sec = "granular.cforce";
    st = px_gran_ck_count(s, ck, sec, PX_DTYPE_F64, 2 * s->ncontours);
    if (st == PX_STATUS_OK)
      st = px_checkpoint_read(ck, sec, PX_DTYPE_F64, 2 * s->ncontours, s->cforce);
    if (st != PX_STATUS_OK) return st;
    bad = px_gran_ck_finite(s->cforce, 2 * s->ncontours, sizeof(double), 0);
    if (bad >= 0)
      return px_gran_ck_bad(s, sec, "value %ld = %g is not finite", bad, s->cforce[bad]);
  }
  if (s->stats_on) {
    struct px_gran_stats *S = &s->stats;
    double *v[] = {S->impacts, S->vn_sum, S->vn2_sum, S->vn_max, S->vt_sum,  S->en,
                   S->et,      S->finnie, S->impulse, S->slide,  S->archard, S->ctime,
                   S->dur_sum, S->ended,  S->t_first, S->t_last};
    char name[48];
    for (k = 0; k < sizeof v / sizeof v[0]; ++k) {
      long bad;
      snprintf(name, sizeof name, "granular.stats.%zu", k);
      st = px_gran_ck_count(s, ck, name, PX_DTYPE_F64, nseg);
      if (st == PX_STATUS_OK) st = px_checkpoint_read(ck, name, PX_DTYPE_F64, nseg, v[k]);
      if (st != PX_STATUS_OK) return st;
      bad = px_gran_ck_finite(v[k], nseg, sizeof(double), 0);
      if (bad >= 0) return px_gran_ck_bad(s, name, "segment %ld: %g is not finite", bad, v[k][bad]);
    }
  }
  return PX_STATUS_OK;
}

enum px_status px_gran_sys_load(struct px_gran_sys *s, struct px_checkpoint *ck) {
  double sc[PX_GRAN_CK_SCALARS];
  size_t n, np, nw, nn;
  PX_TRY(px_gran_ck_scalars(s, ck, sc));
  n = (size_t)sc[6];
  np = (size_t)sc[7];
  nw = (size_t)sc[8];
  nn = (size_t)sc[9];
  PX_TRY(px_gran_ck_particles(s, ck, n, sc[2]));
  PX_TRY(px_gran_ck_pairs(s, ck, n, np));
  PX_TRY(px_gran_ck_walls(s, ck, n, nw, nn));
  s->npairs = np;
  s->nwcand = nw;
  s->nnear = nn;
  PX_TRY(px_gran_ck_contours(s, ck));
  /* everything checked: the state is used from here on */
  s->t = sc[0], s->dt = sc[1], s->step = (long)sc[2], s->rebuilds = (long)sc[3];
  s->need_rebuild = (int)sc[4], s->abm_steps = (long)sc[5];
  PX_TRY(px_gran_sys_split_pairs(s));
  px_gran_sys_split_near(s);
  px_gran_sys_frames(s, s->t);
  return PX_STATUS_OK;
}
