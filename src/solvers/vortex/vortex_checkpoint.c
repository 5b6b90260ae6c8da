/* The vortex solver's checkpoints (vortex_solver.h): sections written and
 * read back, each checked before use. */
#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/csv.h"
#include "partix/figure.h"
#include "partix/memory.h"
#include "partix/vtk.h"
#include "solvers/solver.h"
#include "solvers/summary.h"
#include "solvers/vortex/vortex_core.h"
#include "solvers/vortex/vortex_engine.h"
#include "solvers/vortex/vortex_report.h"
#include "solvers/vortex/vortex_profile.h"
#include "solvers/vortex/vortex_solver.h"

/* ------------------------------------------------------------------------- */
/* Checkpoints: the wake and the circulation absorbed by each panel in the last
 * step (it enters the next generation and the next loads). Everything else is
 * recomputed from these. */

enum px_status px_vortex_checkpoint_save(void *state, struct px_checkpoint_writer *w) {
  struct vx_state *s = state;
  struct px_vortex_engine *e = s->e;
  PX_TRY(px_vortex_engine_sync(e));
  uint64_t n = e->w.n;
  PX_TRY(px_checkpoint_write(w, "vortex.n", PX_DTYPE_U64, 1, &n));
  PX_TRY(px_checkpoint_write(w, "vortex.x", PX_DTYPE_F64, n, e->w.x));
  PX_TRY(px_checkpoint_write(w, "vortex.y", PX_DTYPE_F64, n, e->w.y));
  PX_TRY(px_checkpoint_write(w, "vortex.gamma", PX_DTYPE_F64, n, e->w.g));
  PX_TRY(px_checkpoint_write(w, "vortex.velocity_u", PX_DTYPE_F64, n, e->w.u));
  PX_TRY(px_checkpoint_write(w, "vortex.velocity_v", PX_DTYPE_F64, n, e->w.v));
  PX_TRY(px_checkpoint_write(w, "vortex.absorbed", PX_DTYPE_F64, e->pan.n, e->through));
  return PX_STATUS_OK;
}

/* A checkpoint comes from elsewhere and is not trusted (docs/running.md,
 * "What partix trusts"): its CRCs only say that it is what some writer
 * wrote. Before any of it is used, every section must be there with the type
 * and count this case gives it, the vortex count must be one a run of this
 * case can reach, and every value must be finite and in the range a run
 * keeps it in; otherwise PX_STATUS_FORMAT naming the section (the driver
 * puts the file's name in front). */
static enum px_status vx_ck_section(struct vx_state *s, struct px_checkpoint *ck, const char *name,
                                    enum px_dtype type, uint64_t count) {
  enum px_dtype t = PX_DTYPE_U8;
  uint64_t n = 0;
  if (px_checkpoint_find(ck, name, &t, &n) != PX_STATUS_OK)
    return px_context_fail(s->ctx, PX_STATUS_FORMAT,
                           "section '%s' is missing: not a checkpoint of this vortex case", name);
  if (t != type || n != count)
    return px_context_fail(s->ctx, PX_STATUS_FORMAT,
                           "section '%s' holds %llu values of type %s; this case has %llu of "
                           "type %s",
                           name, (unsigned long long)n, px_dtype_name(t), (unsigned long long)count,
                           px_dtype_name(type));
  return PX_STATUS_OK;
}

/* The first value of a[0..n) that is not finite or, when lim >= 0, exceeds
 * lim in magnitude: its index, or n when all are fine. */
static size_t vx_first_bad(const double *a, size_t n, double lim) {
  for (size_t i = 0; i < n; ++i)
    if (!isfinite(a[i]) || (lim >= 0.0 && fabs(a[i]) > lim)) return i;
  return n;
}

enum px_status px_vortex_checkpoint_load(void *state, struct px_checkpoint *ck) {
  struct vx_state *s = state;
  struct px_vortex_engine *e = s->e;
  struct px_context *ctx = s->ctx;
  const uint64_t step = px_checkpoint_step(ck);
  const double time = px_checkpoint_time(ck);
  /* the driver has checked the header's step and time against the case;
     again here, where they become the engine's long and double */
  if (step > (uint64_t)LONG_MAX / 2 || !isfinite(time) || time < 0.0)
    return px_context_fail(ctx, PX_STATUS_FORMAT, "header: step %llu at t = %g s",
                           (unsigned long long)step, time);
  /* Bounds from the case (vortex_core.c): a step sheds at most 64 vortices
   * per panel (generation; the rk2 predictor's are dropped again), merges and
   * removals only lower the count, so after `step` steps the wake holds at
   * most step x 64 x panels vortices (and fewer than 2^31: the trees' int32
   * indices). Each newborn vortex carries at most |gamma_k| L_k <= 1e3 v_ref
   * L_k (the runaway check), a merged one the sum of its parts, an absorbed
   * circulation what the wake held: each |Gamma| and each panel's absorbed
   * circulation is at most step x 1e3 v_ref P, P the bodies' perimeter [m].
   * The restructuring drops every vortex farther than dist_far from the
   * bodies' centre (1e-5 relative slack: device positions are floats). */
  const double npan = (double)e->pan.n;
  double per = 0.0;
  for (size_t k = 0; k < e->pan.n; ++k) per += e->pan.len[k];
  const double nmax = fmin((double)step * 64.0 * npan, 2147483647.0);
  const double gmax = (double)step * 1e3 * e->cfg.vref * per;
  const double far = e->cfg.dist_far * (1.0 + 1e-5);
  static const char *const arr[5] = {"vortex.x", "vortex.y", "vortex.gamma", "vortex.velocity_u",
                                     "vortex.velocity_v"};
  uint64_t n = 0;
  PX_TRY(vx_ck_section(s, ck, "vortex.n", PX_DTYPE_U64, 1));
  PX_TRY(px_checkpoint_read(ck, "vortex.n", PX_DTYPE_U64, 1, &n));
  if ((double)n > nmax)
    return px_context_fail(ctx, PX_STATUS_FORMAT,
                           "section 'vortex.n': %llu vortices, more than a run of this case "
                           "holds after %llu steps (at most %.0f: 64 newborn vortices per step on "
                           "each of its %zu panels)",
                           (unsigned long long)n, (unsigned long long)step, nmax, e->pan.n);
  for (int q = 0; q < 5; ++q) PX_TRY(vx_ck_section(s, ck, arr[q], PX_DTYPE_F64, n));
  PX_TRY(vx_ck_section(s, ck, "vortex.absorbed", PX_DTYPE_F64, e->pan.n));
  /* read into the wake's arrays while it counts no vortex (w.n = 0): used
     only once every value has passed */
  PX_TRY(px_vortex_wake_reserve(ctx, &e->w, (size_t)n));
  e->w.n = 0;
  double *dst[5] = {e->w.x, e->w.y, e->w.g, e->w.u, e->w.v};
  for (int q = 0; q < 5; ++q) PX_TRY(px_checkpoint_read(ck, arr[q], PX_DTYPE_F64, n, dst[q]));
  double *absorbed = px_mem_alloc(ctx, "vortex.checkpoint", (e->pan.n + 1) * sizeof(double));
  if (!absorbed) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
  enum px_status st = px_checkpoint_read(ck, "vortex.absorbed", PX_DTYPE_F64, e->pan.n, absorbed);
  size_t bad = 0;
  for (int q = 0; q < 5 && st == PX_STATUS_OK; ++q) {
    bad = vx_first_bad(dst[q], (size_t)n, q == 2 ? gmax : -1.0);
    if (bad < n)
      st = px_context_fail(ctx, PX_STATUS_FORMAT, "section '%s': value %zu is %g%s", arr[q], bad,
                           dst[q][bad],
                           q == 2 ? ", not a circulation a run of this case reaches" : "");
  }
  for (size_t i = 0; st == PX_STATUS_OK && i < (size_t)n; ++i) {
    const double dx = e->w.x[i] - e->center[0], dy = e->w.y[i] - e->center[1];
    if (hypot(dx, dy) > far)
      st = px_context_fail(ctx, PX_STATUS_FORMAT,
                           "sections 'vortex.x', 'vortex.y': vortex %zu at (%g, %g) lies %g m "
                           "from the "
                           "bodies' centre, beyond vortex.dist_far = %g m (a run drops it)",
                           i, e->w.x[i], e->w.y[i], hypot(dx, dy), e->cfg.dist_far);
  }
  if (st == PX_STATUS_OK) {
    bad = vx_first_bad(absorbed, e->pan.n, gmax);
    if (bad < e->pan.n)
      st = px_context_fail(ctx, PX_STATUS_FORMAT,
                           "section 'vortex.absorbed': panel %zu absorbed %g m^2/s, not a "
                           "circulation a run of this case reaches (at most %g)",
                           bad, absorbed[bad], gmax);
  }
  if (st == PX_STATUS_OK) memcpy(e->through, absorbed, e->pan.n * sizeof(double));
  px_mem_free(ctx, absorbed);
  PX_TRY(st);
  e->w.n = (size_t)n;
  for (size_t i = 0; i < e->w.n; ++i) {
    e->w.wu[i] = e->w.wv[i] = e->w.e[i] = 0.0;
    e->w.born[i] = -1;
  }
  e->step = (long)step;
  e->time = time;
  px_vortex_engine_host_changed(e);
  return PX_STATUS_OK;
}

/* Keys that change only what is drawn or reported, never the state: they
 * may change when a run is resumed (the probes may not: they are columns
 * of probes.csv). */
