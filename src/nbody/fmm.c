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
  thr = px_mem_realloc(fmm->ctx, "fmm thread scratch", fmm->thr,
                       (size_t)threads * sizeof *thr);
  if (!thr) return PX_STATUS_NOMEM;
  memset(thr + fmm->nthreads, 0, (size_t)(threads - fmm->nthreads) * sizeof *thr);
  fmm->thr = thr;
  fmm->nthreads = threads;
  return PX_STATUS_OK;
}

void px_fmm_params_for(enum px_precision precision, double tolerance, int order,
                       struct px_fmm_params *out) {
  const int pmax = precision == PX_PRECISION_SINGLE ? PX_FMM_MAX_ORDER_SINGLE : PX_FMM_MAX_ORDER;
  const double rho = 0.5 / 1.5; /* θ/(2 − θ) for θ = 0.5 */
  int p = order;
  out->theta = 0.5;
  if (p <= 0) {
    p = (int)ceil(log(tolerance) / log(rho));
  }
  if (p < 2) p = 2;
  if (p > pmax) p = pmax;
  out->order = p;
  out->leaf = precision == PX_PRECISION_SINGLE ? 64 : 48;
  out->cost_m2l = 0.15;
  out->cost_exp = 0.4;
}
