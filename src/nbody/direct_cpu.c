/* cpu entry of the direct sum: host pointers into the per-precision loops;
 * sources that are the targets (same buffers) take the symmetric sum. */
#include "nbody/nbody_impl.h"
#include "partix/memory.h"

static enum px_status px_nbody_cpu_direct(struct px_backend *be, int threads,
                                          enum px_precision precision, size_t n_src,
                                          struct px_buffer *sx, struct px_buffer *sy,
                                          struct px_buffer *sg, size_t n_tgt, struct px_buffer *tx,
                                          struct px_buffer *ty, double eps2,
                                          enum px_nbody_mode mode, struct px_buffer *u,
                                          struct px_buffer *v) {
  const int add = mode == PX_NBODY_MODE_ADD;
  if (sx == tx && sy == ty && n_src == n_tgt) {
    /* self-interaction: each pair once (needs 2n of scratch) */
    const size_t es = precision == PX_PRECISION_DOUBLE ? sizeof(double) : sizeof(float);
    void *scratch = px_mem_alloc(be->ctx, "nbody self-interaction sums", 2 * n_tgt * es);
    if (!scratch) return PX_STATUS_NOMEM;
    if (precision == PX_PRECISION_DOUBLE) {
      double *s = scratch;
      px_nbody_self_cpu_f64(threads, be->workgroup, n_tgt, sx->host, sy->host, sg->host, eps2, add,
                            u->host, v->host, s, s + n_tgt);
    } else {
      float *s = scratch;
      px_nbody_self_cpu_f32(threads, be->workgroup, n_tgt, sx->host, sy->host, sg->host,
                            (float)eps2, add, u->host, v->host, s, s + n_tgt);
    }
    px_mem_free(be->ctx, scratch);
    return PX_STATUS_OK;
  }
  if (precision == PX_PRECISION_DOUBLE)
    px_nbody_direct_cpu_f64(threads, be->workgroup, n_src, sx->host, sy->host, sg->host, n_tgt,
                            tx->host, ty->host, eps2, add, u->host, v->host);
  else
    px_nbody_direct_cpu_f32(threads, be->workgroup, n_src, sx->host, sy->host, sg->host, n_tgt,
                            tx->host, ty->host, (float)eps2, add, u->host, v->host);
  return PX_STATUS_OK;
}

/* The FMM on host arrays; sources that are the targets share one tree. */
static enum px_status px_nbody_cpu_fmm(struct px_backend *be, int threads, struct px_fmm *fmm,
                                       enum px_precision precision, const struct px_fmm_params *prm,
                                       size_t n_src, struct px_buffer *sx, struct px_buffer *sy,
                                       struct px_buffer *sg, size_t n_tgt, struct px_buffer *tx,
                                       struct px_buffer *ty, double eps, enum px_nbody_mode mode,
                                       struct px_buffer *u, struct px_buffer *v) {
  struct px_fmm_args a;
  (void)be;
  a.threads = threads;
  a.n_src = n_src;
  a.n_tgt = n_tgt;
  a.sx = sx->host;
  a.sy = sy->host;
  a.sg = sg->host;
  a.tx = tx->host;
  a.ty = ty->host;
  a.self = sx == tx && sy == ty && n_src == n_tgt;
  a.eps = eps;
  a.accumulate = mode == PX_NBODY_MODE_ADD;
  a.u = u->host;
  a.v = v->host;
  return precision == PX_PRECISION_DOUBLE ? px_fmm_cpu_f64(fmm, prm, &a)
                                          : px_fmm_cpu_f32(fmm, prm, &a);
}

/* The extension of the last FMM evaluation (fmm.h) on host arrays. */
static int px_nbody_cpu_fmm_extend(struct px_backend *be, int threads, struct px_fmm *fmm,
                                   enum px_precision precision, const struct px_fmm_params *prm,
                                   size_t n_src, struct px_buffer *sx, struct px_buffer *sy,
                                   struct px_buffer *sg, size_t n_old, double eps,
                                   enum px_nbody_mode mode, struct px_buffer *u,
                                   struct px_buffer *v) {
  struct px_fmm_args a;
  (void)be;
  a.threads = threads;
  a.n_src = n_src;
  a.n_tgt = n_old;
  a.sx = a.tx = sx->host;
  a.sy = a.ty = sy->host;
  a.sg = sg->host;
  a.self = 1;
  a.eps = eps;
  a.accumulate = mode == PX_NBODY_MODE_ADD;
  a.u = u->host;
  a.v = v->host;
  return precision == PX_PRECISION_DOUBLE ? px_fmm_cpu_extend_f64(fmm, prm, &a, n_old)
                                          : px_fmm_cpu_extend_f32(fmm, prm, &a, n_old);
}

const struct px_nbody_ops px_nbody_ops_cpu = {
    .backend = "cpu",
    .direct = px_nbody_cpu_direct,
    .fmm = px_nbody_cpu_fmm,
    .fmm_extend = px_nbody_cpu_fmm_extend,
};
