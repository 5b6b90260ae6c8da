/* The opencl engine (POCL's CPU device in CI) against the double reference
 * on the body with a hole, clamp, ramped load, shaker and damping: 30 steps
 * of RK4 and of leapfrog, with each element gathering its six links and with
 * every link evaluated once (link_once). Stated tolerances (relative to each quantity's
 * largest magnitude): double 1e-9 (OpenCL may contract a*b+c into fma, so
 * agreement is to rounding, not bitwise), float 1e-4. Fracture: the same
 * links break (double). Outputs computed on the device (stress, von Mises)
 * and the sums of the quasi-static relaxation (q.K q, q.M q, q.M v, reduced
 * on the device) match the reference's. */
#include <stdlib.h>

#include "lt_util.h"

#ifdef PX_HAVE_OPENCL
static void compare(struct px_context *ctx, struct px_backend *be, const struct px_lattice_model *m,
                    enum px_lattice_integrator integ) {
  struct lt_engine ref, en;
  struct lt_el_d *yr = (struct lt_el_d *)malloc(m->nalloc * sizeof *yr);
  struct lt_el_d *yc = (struct lt_el_d *)malloc(m->nalloc * sizeof *yc);
  double *vr = (double *)calloc(m->nalloc, sizeof(double));
  double *vc = (double *)calloc(m->nalloc, sizeof(double));
  double dt = 0.8 * px_lattice_model_dt_limit(m, integ), d[4];
  int prec;
  long steps = 30;
  PX_CHECK_OK(ctx, lt_engine_make(ctx, m, &px_lattice_engine_ref, integ, PX_PRECISION_DOUBLE,
                                  PX_LATTICE_SCHEME_AUTO, 1, NULL, &ref));
  PX_CHECK_OK(ctx, ref.vt->run(ref.e, 0, 0.0, dt, steps));
  ref.vt->get_state(ref.e, yr, NULL);
  {
    struct px_lattice_fields f;
    memset(&f, 0, sizeof f);
    f.vm = vr;
    PX_CHECK_OK(ctx, ref.vt->fields(ref.e, (double)steps * dt, dt, &f));
  }
  for (prec = 0; prec < 4; ++prec) {
    enum px_precision p = prec & 1 ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
    enum px_lattice_scheme sch = prec & 2 ? PX_LATTICE_SCHEME_LINK_ONCE : PX_LATTICE_SCHEME_GATHER;
    double tol = prec & 1 ? 1e-9 : 1e-4, vmax = 0.0, vdiff = 0.0;
    struct px_lattice_fields f;
    size_t i;
    if (p == PX_PRECISION_DOUBLE && !px_backend_has_fp64(be)) continue;
    PX_CHECK_OK(ctx, lt_engine_make(ctx, m, &px_lattice_engine_opencl, integ, p, sch, 0, be, &en));
    if (!en.e) continue;
    PX_CHECK_OK(ctx, en.vt->run(en.e, 0, 0.0, dt, steps));
    PX_CHECK_OK(ctx, en.vt->get_state(en.e, yc, NULL));
    lt_state_diff(m, yc, yr, d);
    printf("opencl %s %s %s: rel. diff u %.2e v %.2e W %.2e q %.2e\n",
           integ == PX_LATTICE_INTEGRATOR_RK4 ? "rk4" : "leapfrog", prec & 1 ? "double" : "float",
           prec & 2 ? "link_once" : "gather", d[0], d[1], d[2], d[3]);
    PX_CHECK_NEAR(d[0], 0.0, tol);
    PX_CHECK_NEAR(d[1], 0.0, tol);
    PX_CHECK_NEAR(d[2], 0.0, tol);
    PX_CHECK_NEAR(d[3], 0.0, tol);
    memset(&f, 0, sizeof f);
    f.vm = vc;
    PX_CHECK_OK(ctx, en.vt->fields(en.e, (double)steps * dt, dt, &f));
    for (i = 0; i < m->nalloc; ++i) {
      vmax = fmax(vmax, vr[i]);
      vdiff = fmax(vdiff, fabs(vr[i] - vc[i]));
    }
    printf("  von Mises: max %.4g Pa, max diff %.2e\n", vmax, vdiff / vmax);
    PX_CHECK(vmax > 0.0);
    PX_CHECK_NEAR(vdiff / vmax, 0.0, prec & 1 ? 1e-8 : 1e-3);
    lt_check_rayleigh(ctx, &en, &ref, tol, "opencl");
    lt_engine_free(&en);
  }
  lt_engine_free(&ref);
  free(yr);
  free(yc);
  free(vr);
  free(vc);
}

static void fracture(struct px_context *ctx, struct px_backend *be,
                     enum px_lattice_scheme scheme) {
  struct px_lattice_model m;
  struct lt_engine ref, en;
  uint8_t *lr, *lc;
  double dt;
  if (!px_backend_has_fp64(be)) return;
  PX_CHECK_OK(ctx, lt_build_body(ctx, &m, 2e3));
  dt = 0.8 * px_lattice_model_dt_limit(&m, PX_LATTICE_INTEGRATOR_RK4);
  lr = (uint8_t *)malloc(m.nalloc);
  lc = (uint8_t *)malloc(m.nalloc);
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_ref, PX_LATTICE_INTEGRATOR_RK4,
                                  PX_PRECISION_DOUBLE, PX_LATTICE_SCHEME_AUTO, 1, NULL, &ref));
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_opencl, PX_LATTICE_INTEGRATOR_RK4,
                                  PX_PRECISION_DOUBLE, scheme, 0, be, &en));
  PX_CHECK_OK(ctx, ref.vt->run(ref.e, 0, 0.0, dt, 60));
  PX_CHECK_OK(ctx, en.vt->run(en.e, 0, 0.0, dt, 60));
  ref.vt->get_state(ref.e, NULL, lr);
  en.vt->get_state(en.e, NULL, lc);
  printf("fracture (%s): reference %ld, opencl %ld links broken\n",
         scheme == PX_LATTICE_SCHEME_LINK_ONCE ? "link_once" : "gather", ref.vt->broken(ref.e),
         en.vt->broken(en.e));
  PX_CHECK(ref.vt->broken(ref.e) > 0);
  PX_CHECK(en.vt->broken(en.e) == ref.vt->broken(ref.e));
  PX_CHECK(memcmp(lr, lc, m.nalloc) == 0);
  lt_engine_free(&en);
  lt_engine_free(&ref);
  free(lr);
  free(lc);
  px_lattice_model_free(ctx, &m);
}
#endif

int main(void) {
#ifdef PX_HAVE_OPENCL
  struct px_context *ctx;
  struct px_backend *be = NULL;
  struct px_lattice_model m;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  if (px_backend_opencl_device_count(ctx) == 0) {
    printf("no OpenCL device: skipped\n");
    px_context_free(ctx);
    return PX_TEST_SKIP;
  }
  PX_CHECK_OK(ctx, px_backend_create(ctx, "opencl", 0, 0, &be));
  if (!be) return px_test_report("test_lattice_opencl");
  printf("device: %s\n", px_backend_device(be));
  PX_CHECK_OK(ctx, lt_build_body(ctx, &m, 0.0));
  compare(ctx, be, &m, PX_LATTICE_INTEGRATOR_RK4);
  compare(ctx, be, &m, PX_LATTICE_INTEGRATOR_LEAPFROG);
  px_lattice_model_free(ctx, &m);
  fracture(ctx, be, PX_LATTICE_SCHEME_GATHER);
  fracture(ctx, be, PX_LATTICE_SCHEME_LINK_ONCE);
  px_backend_free(be);
  px_context_free(ctx);
  return px_test_report("test_lattice_opencl");
#else
  return PX_TEST_SKIP;
#endif
}
