/* N-body velocity sums: argument checks, dispatch by backend name, the
 * evaluator object and the plain double-precision reference. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "nbody/nbody_impl.h"
#include "partix/memory.h"

static const void *const px_nbody_table[] = {&px_nbody_ops_cpu,
                                             PX_IF_OPENCL(&px_nbody_ops_opencl, )};

const char *px_nbody_method_name(enum px_nbody_method method) {
  switch (method) {
    case PX_NBODY_METHOD_DIRECT: return "direct";
    case PX_NBODY_METHOD_FMM: return "fmm";
    case PX_NBODY_METHOD_AUTO: return "auto";
  }
  return "?";
}

enum px_status px_nbody_method_parse(const char *name, enum px_nbody_method *out) {
  static const enum px_nbody_method all[] = {PX_NBODY_METHOD_DIRECT, PX_NBODY_METHOD_FMM,
                                             PX_NBODY_METHOD_AUTO};
  size_t k;
  if (!name || !out) return PX_STATUS_INVALID;
  for (k = 0; k < PX_COUNTOF(all); ++k)
    if (strcmp(name, px_nbody_method_name(all[k])) == 0) {
      *out = all[k];
      return PX_STATUS_OK;
    }
  return PX_STATUS_INVALID;
}

/* eps > 0, and eps² a normal number in the arithmetic precision, so that
 * 1/max(r², ε²) is finite for coincident points. */
static enum px_status px_nbody_check_eps(struct px_backend *be, const char *what,
                                         enum px_precision precision, double eps) {
  const double eps2 = eps * eps;
  const double tiny = precision == PX_PRECISION_SINGLE ? (double)FLT_MIN : DBL_MIN;
  if (!(eps > 0.0) || !isfinite(eps2) || eps2 < tiny)
    return px_context_fail(be->ctx, PX_STATUS_INVALID,
                           "%s: core radius eps = %g; expected eps > 0 with eps^2 a normal %s "
                           "number (the cutoff keeps coincident and close pairs finite)",
                           what, eps, precision == PX_PRECISION_SINGLE ? "float" : "double");
  return PX_STATUS_OK;
}

/* Checks shared by every method; *type receives the element type. */
static enum px_status px_nbody_check_args(struct px_backend *be, const char *what,
                                          enum px_precision precision, size_t n_src,
                                          struct px_buffer *src_x, struct px_buffer *src_y,
                                          struct px_buffer *src_gamma, size_t n_tgt,
                                          struct px_buffer *tgt_x, struct px_buffer *tgt_y,
                                          double eps, enum px_nbody_mode mode,
                                          struct px_buffer *out_u, struct px_buffer *out_v) {
  struct px_buffer *inputs[5];
  enum px_dtype type;
  int k;
  PX_TRY(px_precision_dtype(be, what, precision, &type));
  if (mode != PX_NBODY_MODE_SET && mode != PX_NBODY_MODE_ADD)
    return px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: unknown mode %d", what, (int)mode);
  PX_TRY(px_nbody_check_eps(be, what, precision, eps));
  if (n_src > 0x7fffffffu || n_tgt > 0x7fffffffu)
    return px_context_fail(be->ctx, PX_STATUS_INVALID,
                           "%s: %zu sources / %zu targets exceed the 32-bit index range", what,
                           n_src, n_tgt);
  PX_TRY(px_buffer_check(be, what, "src_x", src_x, n_src, type));
  PX_TRY(px_buffer_check(be, what, "src_y", src_y, n_src, type));
  PX_TRY(px_buffer_check(be, what, "src_gamma", src_gamma, n_src, type));
  PX_TRY(px_buffer_check(be, what, "tgt_x", tgt_x, n_tgt, type));
  PX_TRY(px_buffer_check(be, what, "tgt_y", tgt_y, n_tgt, type));
  PX_TRY(px_buffer_check(be, what, "out_u", out_u, n_tgt, type));
  PX_TRY(px_buffer_check(be, what, "out_v", out_v, n_tgt, type));
  inputs[0] = src_x;
  inputs[1] = src_y;
  inputs[2] = src_gamma;
  inputs[3] = tgt_x;
  inputs[4] = tgt_y;
  for (k = 0; k < 5; ++k)
    if (inputs[k] == out_u || inputs[k] == out_v)
      return px_context_fail(be->ctx, PX_STATUS_INVALID,
                             "%s: output buffer '%s' is also an input; outputs are written "
                             "while inputs are read",
                             what, inputs[k]->label);
  if (out_u == out_v)
    return px_context_fail(be->ctx, PX_STATUS_INVALID,
                           "%s: out_u and out_v are the same buffer ('%s')", what, out_u->label);
  return PX_STATUS_OK;
}

/* px_nbody_direct on `threads` threads (cpu). */
static enum px_status px_nbody_direct_on(struct px_backend *be, int threads,
                                         enum px_precision precision, size_t n_src,
                                         struct px_buffer *src_x, struct px_buffer *src_y,
                                         struct px_buffer *src_gamma, size_t n_tgt,
                                         struct px_buffer *tgt_x, struct px_buffer *tgt_y,
                                         double eps, enum px_nbody_mode mode,
                                         struct px_buffer *out_u, struct px_buffer *out_v) {
  const struct px_nbody_ops *ops;
  if (!be) return PX_STATUS_INVALID;
  PX_TRY(px_nbody_check_args(be, "px_nbody_direct", precision, n_src, src_x, src_y, src_gamma,
                             n_tgt, tgt_x, tgt_y, eps, mode, out_u, out_v));
  if (n_tgt == 0) return PX_STATUS_OK;
  ops = PX_BACKEND_PICK(be, "direct N-body sum", px_nbody_table);
  if (!ops) return px_context_status(be->ctx);
  return ops->direct(be, threads, precision, n_src, src_x, src_y, src_gamma, n_tgt, tgt_x, tgt_y,
                     eps * eps, mode, out_u, out_v);
}

enum px_status px_nbody_direct(struct px_backend *be, enum px_precision precision, size_t n_src,
                               struct px_buffer *src_x, struct px_buffer *src_y,
                               struct px_buffer *src_gamma, size_t n_tgt, struct px_buffer *tgt_x,
                               struct px_buffer *tgt_y, double eps, enum px_nbody_mode mode,
                               struct px_buffer *out_u, struct px_buffer *out_v) {
  return px_nbody_direct_on(be, be ? be->threads : 1, precision, n_src, src_x, src_y, src_gamma,
                            n_tgt, tgt_x, tgt_y, eps, mode, out_u, out_v);
}

/* AUTO's crossover on the cpu (docs/fmm.md, measured with bench/vortex_fmm,
 * one thread, wake set): the FMM overtakes the direct sum at N ≈ 700 in
 * double (tolerance 1e-6) and N ≈ 1000 in single (1e-3 .. 1e-5); two
 * threads speed the direct sum up more than the small FMM. Below 2000 x
 * 2000 pairs the direct sum costs at most ~1 ms, and it is exact. */
const double px_nbody_auto_pairs = 4.0e6;

struct px_nbody {
  struct px_backend *be;          /* borrowed */
  const struct px_nbody_ops *ops; /* borrowed (static table) */
  enum px_nbody_method method;
  enum px_nbody_method last;
  enum px_precision precision;
  double eps;
  double tolerance; /* requested relative L2 error of the FMM */
  int order;        /* 0: from the tolerance */
  int override;     /* prm below replaces the tolerance rule */
  struct px_fmm_params prm;
  struct px_fmm fmm; /* owned workspace */
  int threads;       /* of the cpu sums; 0: the backend's (px_nbody_set_threads) */
};

void px_nbody_set_threads(struct px_nbody *nb, int threads) {
  if (nb) nb->threads = threads > 0 ? threads : 0;
}

enum px_status px_nbody_create(struct px_backend *be, enum px_nbody_method method,
                               enum px_precision precision, double eps, struct px_nbody **out) {
  static const char *const what = "px_nbody_create";
  const struct px_nbody_ops *ops;
  struct px_nbody *nb;
  enum px_dtype type;
  if (!be || !out)
    return be ? px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: out is NULL", what)
              : PX_STATUS_INVALID;
  *out = NULL;
  if (method != PX_NBODY_METHOD_DIRECT && method != PX_NBODY_METHOD_FMM &&
      method != PX_NBODY_METHOD_AUTO)
    return px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: unknown method %d", what, (int)method);
  PX_TRY(px_precision_dtype(be, what, precision, &type));
  PX_TRY(px_nbody_check_eps(be, what, precision, eps));
  ops = PX_BACKEND_PICK(be, "N-body sum", px_nbody_table);
  if (!ops) return px_context_status(be->ctx);
  if (method == PX_NBODY_METHOD_FMM && !ops->fmm)
    return px_context_fail(be->ctx, PX_STATUS_UNSUPPORTED,
                           "%s: the fast multipole method runs on the cpu backend only, not on "
                           "'%s' (there the direct sum is the fast path below ~1e5 vortices); "
                           "use method 'direct' or 'auto'",
                           what, px_backend_name(be));
  nb = px_mem_calloc(be->ctx, "nbody evaluator", 1, sizeof *nb);
  if (!nb) return PX_STATUS_NOMEM;
  nb->be = be;
  nb->ops = ops;
  nb->method = method;
  nb->last = method;
  nb->precision = precision;
  nb->eps = eps;
  nb->tolerance = 1e-6;
  px_fmm_init(&nb->fmm, be->ctx);
  *out = nb;
  return PX_STATUS_OK;
}

void px_nbody_free(struct px_nbody *nb) {
  if (!nb) return;
  px_fmm_release(&nb->fmm);
  px_mem_free(nb->be->ctx, nb);
}

enum px_nbody_method px_nbody_method(const struct px_nbody *nb) {
  return nb ? nb->method : PX_NBODY_METHOD_DIRECT;
}

enum px_nbody_method px_nbody_last_method(const struct px_nbody *nb) {
  return nb ? nb->last : PX_NBODY_METHOD_DIRECT;
}

enum px_status px_nbody_set_eps(struct px_nbody *nb, double eps) {
  if (!nb) return PX_STATUS_INVALID;
  PX_TRY(px_nbody_check_eps(nb->be, "px_nbody_set_eps", nb->precision, eps));
  nb->eps = eps;
  return PX_STATUS_OK;
}

enum px_status px_nbody_set_tolerance(struct px_nbody *nb, double tolerance) {
  const double lo = nb && nb->precision == PX_PRECISION_SINGLE ? 1e-5 : 1e-12;
  if (!nb) return PX_STATUS_INVALID;
  if (!(tolerance >= lo && tolerance <= 0.1))
    return px_context_fail(nb->be->ctx, PX_STATUS_INVALID,
                           "px_nbody_set_tolerance: tolerance %g; expected a relative L2 error "
                           "between %g and 0.1 in %s precision%s",
                           tolerance, lo, px_precision_name(nb->precision),
                           nb->precision == PX_PRECISION_SINGLE
                               ? " (float sums carry ~1e-7 rounding, more for large N; use "
                                 "double below 1e-5)"
                               : "");
  nb->tolerance = tolerance;
  return PX_STATUS_OK;
}

double px_nbody_tolerance(const struct px_nbody *nb) { return nb ? nb->tolerance : 0.0; }

enum px_status px_nbody_set_order(struct px_nbody *nb, int order) {
  const int pmax =
      nb && nb->precision == PX_PRECISION_SINGLE ? PX_FMM_MAX_ORDER_SINGLE : PX_FMM_MAX_ORDER;
  if (!nb) return PX_STATUS_INVALID;
  if (order != 0 && (order < 2 || order > pmax))
    return px_context_fail(nb->be->ctx, PX_STATUS_INVALID,
                           "px_nbody_set_order: order %d; expected 0 (from the tolerance) or "
                           "2..%d in %s precision",
                           order, pmax, px_precision_name(nb->precision));
  nb->order = order;
  return PX_STATUS_OK;
}

static void px_nbody_params(const struct px_nbody *nb, struct px_fmm_params *prm) {
  if (nb->override)
    *prm = nb->prm;
  else
    px_fmm_params_for(nb->precision, nb->tolerance, nb->order, prm);
}

int px_nbody_order(const struct px_nbody *nb) {
  struct px_fmm_params prm;
  if (!nb) return 0;
  px_nbody_params(nb, &prm);
  return prm.order;
}

void px_nbody_fmm_override(struct px_nbody *nb, const struct px_fmm_params *prm) {
  nb->override = prm != NULL;
  if (prm) nb->prm = *prm;
}

const struct px_fmm_stats *px_nbody_fmm_stats(const struct px_nbody *nb) { return &nb->fmm.stats; }

void px_nbody_set_part(struct px_nbody *nb, int part, int parts) {
  nb->fmm.part = parts > 1 ? part : 0;
  nb->fmm.parts = parts > 1 ? parts : 1;
}

int px_nbody_part_targets(const struct px_nbody *nb, const uint32_t **perm, size_t *lo,
                          size_t *hi) {
  const struct px_fmm *f = &nb->fmm;
  if (!f->split) return 0;
  /* the targets' tree: the sources' when they are the targets (no tgt tree) */
  *perm = f->self ? f->src.perm : f->tgt.perm;
  *lo = f->split_lo;
  *hi = f->split_hi;
  return 1;
}

/* The method a sum of n_src sources at n_tgt targets runs by: nb's, or for
 * `auto` the FMM from px_nbody_auto_pairs pairs where the backend has one. */
static enum px_nbody_method px_nbody_pick(const struct px_nbody *nb, size_t n_src, size_t n_tgt) {
  if (nb->method != PX_NBODY_METHOD_AUTO) return nb->method;
  return nb->ops->fmm && (double)n_src * (double)n_tgt >= px_nbody_auto_pairs
             ? PX_NBODY_METHOD_FMM
             : PX_NBODY_METHOD_DIRECT;
}

enum px_status px_nbody_velocity(struct px_nbody *nb, size_t n_src, struct px_buffer *src_x,
                                 struct px_buffer *src_y, struct px_buffer *src_gamma, size_t n_tgt,
                                 struct px_buffer *tgt_x, struct px_buffer *tgt_y,
                                 enum px_nbody_mode mode, struct px_buffer *out_u,
                                 struct px_buffer *out_v) {
  enum px_nbody_method m;
  struct px_fmm_params prm;
  int threads;
  if (!nb) return PX_STATUS_INVALID;
  threads = nb->threads > 0 ? nb->threads : nb->be->threads;
  m = px_nbody_pick(nb, n_src, n_tgt);
  nb->last = m;
  nb->fmm.split = 0; /* set again by a split FMM evaluation */
  if (m == PX_NBODY_METHOD_DIRECT)
    return px_nbody_direct_on(nb->be, threads, nb->precision, n_src, src_x, src_y, src_gamma, n_tgt,
                              tgt_x, tgt_y, nb->eps, mode, out_u, out_v);
  PX_TRY(px_nbody_check_args(nb->be, "px_nbody_velocity", nb->precision, n_src, src_x, src_y,
                             src_gamma, n_tgt, tgt_x, tgt_y, nb->eps, mode, out_u, out_v));
  if (n_tgt == 0) return PX_STATUS_OK;
  if (n_src == 0) {
    /* nothing to sum: the direct sum's loops set or keep the outputs */
    return px_nbody_direct_on(nb->be, threads, nb->precision, n_src, src_x, src_y, src_gamma, n_tgt,
                              tgt_x, tgt_y, nb->eps, mode, out_u, out_v);
  }
  px_nbody_params(nb, &prm);
  return nb->ops->fmm(nb->be, threads, &nb->fmm, nb->precision, &prm, n_src, src_x, src_y,
                      src_gamma, n_tgt, tgt_x, tgt_y, nb->eps, mode, out_u, out_v);
}

enum px_status px_nbody_velocity_extend(struct px_nbody *nb, size_t n_src, struct px_buffer *src_x,
                                        struct px_buffer *src_y, struct px_buffer *src_gamma,
                                        size_t n_old, enum px_nbody_mode mode,
                                        struct px_buffer *out_u, struct px_buffer *out_v,
                                        int *extended) {
  struct px_fmm_params prm;
  int r;
  *extended = 0;
  if (!nb) return PX_STATUS_INVALID;
  /* the last evaluation an FMM one, this one too (the rule of
   * px_nbody_velocity), on a backend that extends */
  if (nb->last == PX_NBODY_METHOD_FMM && nb->ops->fmm_extend && n_old > 0 && n_old <= n_src &&
      px_nbody_pick(nb, n_src, n_src) == PX_NBODY_METHOD_FMM) {
    PX_TRY(px_nbody_check_args(nb->be, "px_nbody_velocity_extend", nb->precision, n_src, src_x,
                               src_y, src_gamma, n_src, src_x, src_y, nb->eps, mode, out_u, out_v));
    px_nbody_params(nb, &prm);
    nb->fmm.split = 0;
    r = nb->ops->fmm_extend(nb->be, nb->threads > 0 ? nb->threads : nb->be->threads, &nb->fmm,
                            nb->precision, &prm, n_src, src_x, src_y, src_gamma, n_old, nb->eps,
                            mode, out_u, out_v);
    if (r < 0)
      return px_context_status(nb->be->ctx) != PX_STATUS_OK ? px_context_status(nb->be->ctx)
                                                            : PX_STATUS_NOMEM;
    if (r > 0) {
      *extended = 1;
      return PX_STATUS_OK;
    }
  }
  return px_nbody_velocity(nb, n_src, src_x, src_y, src_gamma, n_src, src_x, src_y, mode, out_u,
                           out_v);
}

void px_nbody_direct_reference(size_t n_src, const double *src_x, const double *src_y,
                               const double *src_gamma, size_t n_tgt, const double *tgt_x,
                               const double *tgt_y, double eps, double *out_u, double *out_v) {
  const double eps2 = eps * eps, two_pi = 6.283185307179586476925;
  size_t i, j;
  for (i = 0; i < n_tgt; ++i) {
    double u = 0.0, v = 0.0;
    for (j = 0; j < n_src; ++j) {
      const double dx = tgt_x[i] - src_x[j], dy = tgt_y[i] - src_y[j];
      const double r2 = dx * dx + dy * dy;
      const double w = src_gamma[j] / (two_pi * (r2 > eps2 ? r2 : eps2));
      u -= dy * w;
      v += dx * w;
    }
    out_u[i] = u;
    out_v[i] = v;
  }
}
