/* FMM workspace and parameter rules (precision-independent part). */
#include <math.h>
#include <string.h>

#include "nbody/fmm.h"
#include "partix/memory.h"

void px_fmm_init(struct px_fmm *fmm, struct px_context *ctx) {
  memset(fmm, 0, sizeof *fmm);
  fmm->ctx = ctx;
}

static void px_fmm_tree_release(struct px_context *ctx, struct px_fmm_tree *t) {
  px_mem_free(ctx, t->keys);
  px_mem_free(ctx, t->keys_tmp);
  px_mem_free(ctx, t->perm);
  px_mem_free(ctx, t->perm_tmp);
  px_mem_free(ctx, t->cell);
  px_mem_free(ctx, t->box);
  px_mem_free(ctx, t->task);
  memset(t, 0, sizeof *t);
}

void px_fmm_release(struct px_fmm *fmm) {
  struct px_context *ctx = fmm->ctx;
  int k;
  if (!ctx) return;
  px_fmm_tree_release(ctx, &fmm->src);
  px_fmm_tree_release(ctx, &fmm->tgt);
  for (k = 0; k < fmm->nthreads; ++k) {
    struct px_fmm_thread *th = fmm->thr + k;
    px_mem_free(ctx, th->stack);
    px_mem_free(ctx, th->pass[0]);
    px_mem_free(ctx, th->pass[1]);
    px_mem_free(ctx, th->list);
    px_mem_free(ctx, th->sorted);
    px_mem_free(ctx, th->buf);
  }
  px_mem_free(ctx, fmm->thr);
  px_mem_free(ctx, fmm->points);
  px_mem_free(ctx, fmm->mpole);
  px_mem_free(ctx, fmm->local);
  px_mem_free(ctx, fmm->has_local);
  px_mem_free(ctx, fmm->pass_info);
  px_mem_free(ctx, fmm->tables);
  px_fmm_init(fmm, ctx);
}

enum px_status px_fmm_threads(struct px_fmm *fmm, int threads) {
  struct px_fmm_thread *thr;
  if (threads < 1) threads = 1;
  if (threads <= fmm->nthreads) return PX_STATUS_OK;
  thr = px_mem_realloc(fmm->ctx, "fmm thread scratch", fmm->thr, (size_t)threads * sizeof *thr);
  if (!thr) return PX_STATUS_NOMEM;
  memset(thr + fmm->nthreads, 0, (size_t)(threads - fmm->nthreads) * sizeof *thr);
  fmm->thr = thr;
  fmm->nthreads = threads;
  return PX_STATUS_OK;
}

/* The tolerance rule (docs/fmm.md).
 *
 * Every accepted interaction is truncated at its own order q, the smallest
 * with ρ^q <= E (ρ: its convergence ratio, fmm_cpu.h), so each carries a
 * relative truncation error of about E; we set E = tolerance. Measured
 * (test_nbody_fmm_accuracy and bench/vortex_fmm: uniform, Gaussian blobs,
 * vortex sheet and wake sets, N = 2e4 to 1e6, E from 1e-3 to 1e-12):
 * relative L2 error 0.001-0.07 E, max error (max |Δu| / max |u|) 0.001-0.13
 * E; the test checks both below the tolerance.
 *
 * p sets the acceptance ratio ρ = E^(1/p): a larger p accepts closer pairs
 * (less near field, fewer M2Ls) with longer expansions. Fastest at every
 * tolerance (bench/vortex_fmm, N = 5e4, uniform and wake, 1 thread): ρ
 * between 0.5 and 0.6, so p = ceil(ln E / ln 0.56): 12 at 1e-3, 24 at
 * 1e-6, 36 at 1e-9, capped at 40 (1e-12: ρ = 0.50). Single precision: the
 * same rule, capped at 24 (tolerances stop at 1e-5; float sums carry ~1e-7
 * rounding). A fixed order p (the expert knob) uses E = 0.5^p.
 * Leaves: 48 points in double, 64 in single (P2P costs half as much). */
void px_fmm_params_for(enum px_precision precision, double tolerance, int order,
                       struct px_fmm_params *out) {
  const int single = precision == PX_PRECISION_SINGLE;
  const int pmax = single ? PX_FMM_MAX_ORDER_SINGLE : PX_FMM_MAX_ORDER;
  int p;
  if (order > 0) {
    p = order < 2 ? 2 : (order > pmax ? pmax : order);
    out->err = pow(0.5, (double)p);
  } else {
    if (!(tolerance > 0.0)) tolerance = 1e-6;
    out->err = tolerance;
    p = (int)ceil(log(tolerance) / log(0.56) - 1e-9);
    p = p < 2 ? 2 : (p > pmax ? pmax : p);
  }
  out->order = p;
  out->leaf = single ? 64 : 48;
  out->cost_m2l = 0.15;
  out->cost_exp = 0.4;
}
