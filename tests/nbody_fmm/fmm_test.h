/* Helpers of the FMM tests: one velocity sum on a backend from host double
 * arrays (inputs converted to the precision under test), the reference
 * double direct sum, and error norms. */
#ifndef PX_FMM_TEST_H
#define PX_FMM_TEST_H

#include "compute/compute_test.h"
#include "nbody/nbody_impl.h"
#include "vortex_sets.h"

/* Sources (sx, sy, sg: ns) acting on targets (tx, ty: nt); self: the
 * targets are the sources (one set of buffers, as the wake uses it). */
struct px_fmm_problem {
  size_t ns, nt;
  const double *sx, *sy, *sg, *tx, *ty;
  int self;
};

/* Run nb on `be` (the evaluator's backend) in precision p: u, v receive
 * the velocities (mode ADD adds to the values u, v hold on entry). */
static inline enum px_status px_fmm_test_run(struct px_context *ctx, struct px_backend *be,
                                             struct px_nbody *nb, enum px_precision p,
                                             const struct px_fmm_problem *pb,
                                             enum px_nbody_mode mode, double *u, double *v) {
  struct px_buffer *bsx = px_test_upload(ctx, be, "sx", p, pb->ns, pb->sx);
  struct px_buffer *bsy = px_test_upload(ctx, be, "sy", p, pb->ns, pb->sy);
  struct px_buffer *bsg = px_test_upload(ctx, be, "sg", p, pb->ns, pb->sg);
  struct px_buffer *btx = pb->self ? bsx : px_test_upload(ctx, be, "tx", p, pb->nt, pb->tx);
  struct px_buffer *bty = pb->self ? bsy : px_test_upload(ctx, be, "ty", p, pb->nt, pb->ty);
  struct px_buffer *bu = px_test_upload(ctx, be, "u", p, pb->nt, u);
  struct px_buffer *bv = px_test_upload(ctx, be, "v", p, pb->nt, v);
  enum px_status st = px_nbody_velocity(nb, pb->ns, bsx, bsy, bsg, pb->nt, btx, bty, mode, bu, bv);
  if (st == PX_STATUS_OK) {
    px_test_download(ctx, bu, p, pb->nt, u);
    px_test_download(ctx, bv, p, pb->nt, v);
  }
  px_buffer_free(bsx);
  px_buffer_free(bsy);
  px_buffer_free(bsg);
  if (!pb->self) {
    px_buffer_free(btx);
    px_buffer_free(bty);
  }
  px_buffer_free(bu);
  px_buffer_free(bv);
  return st;
}

/* The reference: the double-precision direct sum (tiled cpu loops, exact to
 * ~1e-15) of the same inputs, u, v set. */
static inline void px_fmm_test_reference(struct px_context *ctx, struct px_backend *cpu,
                                         const struct px_fmm_problem *pb, double eps, double *u,
                                         double *v) {
  struct px_nbody *nb = NULL;
  size_t i;
  PX_CHECK_OK(ctx, px_nbody_create(cpu, PX_NBODY_METHOD_DIRECT, PX_PRECISION_DOUBLE, eps, &nb));
  for (i = 0; i < pb->nt; ++i) u[i] = v[i] = 0.0;
  PX_CHECK_OK(ctx, px_fmm_test_run(ctx, cpu, nb, PX_PRECISION_DOUBLE, pb, PX_NBODY_MODE_SET, u, v));
  px_nbody_free(nb);
}

/* Relative L2 error sqrt(Σ|Δu|² / Σ|u_ref|²) and max error max|Δu| / max|u_ref|
 * over n targets. */
static inline void px_fmm_test_errors(size_t n, const double *u, const double *v, const double *ru,
                                      const double *rv, double *rel_l2, double *rel_max) {
  double num = 0.0, den = 0.0, emax = 0.0, umax = 0.0;
  size_t i;
  for (i = 0; i < n; ++i) {
    const double du = u[i] - ru[i], dv = v[i] - rv[i];
    const double e = sqrt(du * du + dv * dv), r = sqrt(ru[i] * ru[i] + rv[i] * rv[i]);
    num += du * du + dv * dv;
    den += ru[i] * ru[i] + rv[i] * rv[i];
    emax = e > emax || e != e ? e : emax;
    umax = r > umax ? r : umax;
  }
  *rel_l2 = den > 0.0 ? sqrt(num / den) : sqrt(num);
  *rel_max = umax > 0.0 ? emax / umax : emax;
}

/* An FMM evaluator for precision p and tolerance tol on `be`. */
static inline struct px_nbody *px_fmm_test_fmm(struct px_context *ctx, struct px_backend *be,
                                               enum px_precision p, double eps, double tol) {
  struct px_nbody *nb = NULL;
  PX_CHECK_OK(ctx, px_nbody_create(be, PX_NBODY_METHOD_FMM, p, eps, &nb));
  if (!nb) exit(EXIT_FAILURE);
  PX_CHECK_OK(ctx, px_nbody_set_tolerance(nb, tol));
  return nb;
}

#endif
