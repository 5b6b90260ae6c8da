/* The opencl engine (POCL's CPU device in CI) against the double reference
 * on the body with a hole, clamp, ramped load, shaker and damping: 30 steps
 * of RK4 and of leapfrog, with each element gathering its six links and with
 * every link evaluated once (link_once). Stated tolerances (relative to each quantity's
 * largest magnitude): double 1e-9 (OpenCL may contract a*b+c into fma, so
 * agreement is to rounding, not bitwise), float 1e-4. Fracture: the same
 * links break (double). Outputs computed on the device (stress, von Mises)
 * and the sums of the quasi-static relaxation (q.K q, q.M q, q.M v, summed
 * per grid row on the device) match the reference's. A blow-up is reported at the step
 * and element the cpu engine names (blowup_step). */
#include <stdlib.h>

#include "lt_util.h"

#ifdef PX_HAVE_OPENCL
static void compare(struct px_context *ctx, struct px_backend *be, const struct px_lattice_model *m,
                    enum px_lattice_integrator integ) {
  struct lt_engine ref, en;
  struct lt_el *yr = (struct lt_el *)malloc(m->nalloc * sizeof *yr);
  struct lt_el *yc = (struct lt_el *)malloc(m->nalloc * sizeof *yc);
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

static void fracture(struct px_context *ctx, struct px_backend *be, enum px_lattice_scheme scheme) {
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

/* A blow-up is reported at the step it appears, with the element and the
 * quantity, although the device's flags are read only every 16 steps
 * (before: "between steps 1 and 16", the element taken from the state at
 * step 16, where the NaN had spread). The step: the double cpu engine's,
 * which checks every step; dt a few times the stability limit so that the
 * state grows by orders of magnitude per step (the crossing step does not
 * depend on rounding), chosen so that it is not a multiple of 16. */
static void blowup_step(struct px_context *ctx, struct px_backend *be,
                        const struct px_lattice_model *m, enum px_lattice_integrator integ) {
  double factor;
  if (!px_backend_has_fp64(be)) return;
  for (factor = 3.0; factor < 6.0; factor += 0.25) {
    double dt = factor * px_lattice_model_dt_limit(m, integ);
    struct lt_engine cpu, en;
    char want[256], cpu_msg[1024];
    const char *elem;
    long s, k_cpu = -1;
    enum px_status st;
    PX_CHECK_OK(ctx, lt_engine_make(ctx, m, &px_lattice_engine_cpu, integ, PX_PRECISION_DOUBLE,
                                    PX_LATTICE_SCHEME_GATHER, 1, NULL, &cpu));
    for (s = 0; s < 400 && k_cpu < 0; ++s)
      if (cpu.vt->run(cpu.e, s, (double)s * dt, dt, 1) != PX_STATUS_OK) k_cpu = s + 1;
    snprintf(cpu_msg, sizeof cpu_msg, "%s", px_context_message(ctx));
    px_context_clear(ctx);
    lt_engine_free(&cpu);
    if (k_cpu < 0 || k_cpu % 16 == 0) continue;
    PX_CHECK_OK(ctx, lt_engine_make(ctx, m, &px_lattice_engine_opencl, integ, PX_PRECISION_DOUBLE,
                                    PX_LATTICE_SCHEME_GATHER, 0, be, &en));
    if (!en.e) return;
    st = en.vt->run(en.e, 0, 0.0, dt, 400);
    printf("blow-up (%s, dt = %.2f x limit): cpu at step %ld: %s\n  opencl: %s\n",
           integ == PX_LATTICE_INTEGRATOR_RK4 ? "rk4" : "leapfrog", factor, k_cpu, cpu_msg,
           px_context_message(ctx));
    PX_CHECK(st == PX_STATUS_NUMERIC);
    snprintf(want, sizeof want, "non-finite at step %ld (", k_cpu);
    PX_CHECK_MSG(strstr(px_context_message(ctx), want) != NULL, "message %s (want '%s')",
                 px_context_message(ctx), want);
    /* the same element and quantity as the cpu engine names */
    elem = strstr(cpu_msg, "the ");
    if (elem) {
      char head[160];
      const char *end = strstr(elem, " m is not finite");
      size_t len = end ? (size_t)(end - elem) : 0;
      snprintf(head, sizeof head, "%.*s", (int)(len < sizeof head ? len : sizeof head - 1), elem);
      PX_CHECK_MSG(len > 0 && strstr(px_context_message(ctx), head) != NULL,
                   "message %s (want '%s')", px_context_message(ctx), head);
    }
    px_context_clear(ctx);
    lt_engine_free(&en);
    return;
  }
  PX_CHECK_MSG(0, "no dt factor gave a blow-up off the 16-step checks");
}
#endif

int main(void) {
#ifdef PX_HAVE_OPENCL
  struct px_context *ctx;
  struct px_backend *be = NULL;
  struct px_lattice_model m;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  be = px_test_backend(ctx, "opencl", 0);
  printf("device: %s\n", px_backend_device(be));
  PX_CHECK_OK(ctx, lt_build_body(ctx, &m, 0.0));
  compare(ctx, be, &m, PX_LATTICE_INTEGRATOR_RK4);
  compare(ctx, be, &m, PX_LATTICE_INTEGRATOR_LEAPFROG);
  blowup_step(ctx, be, &m, PX_LATTICE_INTEGRATOR_RK4);
  blowup_step(ctx, be, &m, PX_LATTICE_INTEGRATOR_LEAPFROG);
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
