/* N-body velocity sums: argument checks, dispatch by backend name, the
 * evaluator object and the plain double-precision reference. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "nbody/nbody_impl.h"
#include "partix/memory.h"

static const void *const px_nbody_table[] = {
    &px_nbody_ops_cpu,
#ifdef PX_HAVE_OPENCL
    &px_nbody_ops_opencl,
#endif
};

const char *px_nbody_method_name(enum px_nbody_method method) {
  switch (method) {
    case PX_NBODY_METHOD_DIRECT: return "direct";
  }
  return "?";
}

enum px_status px_nbody_method_parse(const char *name, enum px_nbody_method *out) {
  if (!name || !out) return PX_STATUS_INVALID;
  if (strcmp(name, "direct") == 0) {
    *out = PX_NBODY_METHOD_DIRECT;
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

enum px_status px_nbody_direct(struct px_backend *be, enum px_precision precision, size_t n_src,
                               struct px_buffer *src_x, struct px_buffer *src_y,
                               struct px_buffer *src_gamma, size_t n_tgt,
                               struct px_buffer *tgt_x, struct px_buffer *tgt_y, double eps,
                               enum px_nbody_mode mode, struct px_buffer *out_u,
                               struct px_buffer *out_v) {
  static const char *const what = "px_nbody_direct";
  const struct px_nbody_ops *ops;
  struct px_buffer *inputs[5];
  enum px_dtype type;
  int k;
  if (!be) return PX_STATUS_INVALID;
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
  if (n_tgt == 0) return PX_STATUS_OK;
  ops = PX_BACKEND_PICK(be, "direct N-body sum", px_nbody_table);
  if (!ops) return px_context_status(be->ctx);
  return ops->direct(be, precision, n_src, src_x, src_y, src_gamma, n_tgt, tgt_x, tgt_y,
                     eps * eps, mode, out_u, out_v);
}

struct px_nbody {
  struct px_backend *be; /* borrowed */
  enum px_nbody_method method;
  enum px_precision precision;
  double eps;
};

enum px_status px_nbody_create(struct px_backend *be, enum px_nbody_method method,
                               enum px_precision precision, double eps, struct px_nbody **out) {
  static const char *const what = "px_nbody_create";
  struct px_nbody *nb;
  enum px_dtype type;
  if (!be || !out) return be ? px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: out is NULL", what)
                             : PX_STATUS_INVALID;
  *out = NULL;
  if (method != PX_NBODY_METHOD_DIRECT)
    return px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: unknown method %d", what,
                           (int)method);
  PX_TRY(px_precision_dtype(be, what, precision, &type));
  PX_TRY(px_nbody_check_eps(be, what, precision, eps));
  nb = px_mem_calloc(be->ctx, "nbody evaluator", 1, sizeof *nb);
  if (!nb) return PX_STATUS_NOMEM;
  nb->be = be;
  nb->method = method;
  nb->precision = precision;
  nb->eps = eps;
  *out = nb;
  return PX_STATUS_OK;
}

void px_nbody_free(struct px_nbody *nb) {
  if (nb) px_mem_free(nb->be->ctx, nb);
}

enum px_nbody_method px_nbody_method(const struct px_nbody *nb) {
  return nb ? nb->method : PX_NBODY_METHOD_DIRECT;
}

enum px_status px_nbody_set_eps(struct px_nbody *nb, double eps) {
  if (!nb) return PX_STATUS_INVALID;
  PX_TRY(px_nbody_check_eps(nb->be, "px_nbody_set_eps", nb->precision, eps));
  nb->eps = eps;
  return PX_STATUS_OK;
}

enum px_status px_nbody_velocity(struct px_nbody *nb, size_t n_src, struct px_buffer *src_x,
                                 struct px_buffer *src_y, struct px_buffer *src_gamma,
                                 size_t n_tgt, struct px_buffer *tgt_x, struct px_buffer *tgt_y,
                                 enum px_nbody_mode mode, struct px_buffer *out_u,
                                 struct px_buffer *out_v) {
  if (!nb) return PX_STATUS_INVALID;
  switch (nb->method) {
    case PX_NBODY_METHOD_DIRECT:
      return px_nbody_direct(nb->be, nb->precision, n_src, src_x, src_y, src_gamma, n_tgt, tgt_x,
                             tgt_y, nb->eps, mode, out_u, out_v);
  }
  return px_context_fail(nb->be->ctx, PX_STATUS_INTERNAL, "px_nbody_velocity: bad method");
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
