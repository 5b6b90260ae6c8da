/* The optimized cpu engine against the double reference, on a body with a
 * hole (void cells inside rows), a clamp, a ramped load, a harmonic
 * prescribed acceleration and link damping, 40 steps of RK4 and of leapfrog:
 *  - double, gather and link-once: state within 1e-9 of the reference
 *    (relative to each quantity's largest magnitude);
 *  - float: within 2e-3 (single-precision rounding of the stiff link law);
 *  - the sums of the quasi-static relaxation (q.K q, q.M q, q.M v) agree
 *    with the reference's within the same tolerances;
 *  - fracture: the cpu engine breaks the same links as the reference;
 *  - threads: on a body big enough for the cpu engine to use two threads
 *    (28880 cells), 1 and 2 threads give bit-identical states and links,
 *    both integrators, schemes and precisions, with fracture. */
#include <stdlib.h>

#include "lt_util.h"

static void run_case(struct px_context *ctx, const struct px_lattice_model *m,
                     enum px_lattice_integrator integ, long steps) {
  struct lt_engine ref, en;
  struct lt_el *yr = (struct lt_el *)malloc(m->nalloc * sizeof *yr);
  struct lt_el *yc = (struct lt_el *)malloc(m->nalloc * sizeof *yc);
  double dt = 0.8 * px_lattice_model_dt_limit(m, integ), d[4];
  int scheme, prec;
  const char *iname = integ == PX_LATTICE_INTEGRATOR_RK4 ? "rk4" : "leapfrog";
  PX_CHECK_OK(ctx, lt_engine_make(ctx, m, &px_lattice_engine_ref, integ, PX_PRECISION_DOUBLE,
                                  PX_LATTICE_SCHEME_AUTO, 1, NULL, &ref));
  PX_CHECK_OK(ctx, ref.vt->run(ref.e, 0, 0.0, dt, steps));
  ref.vt->get_state(ref.e, yr, NULL);
  for (scheme = PX_LATTICE_SCHEME_GATHER; scheme <= PX_LATTICE_SCHEME_LINK_ONCE; ++scheme)
    for (prec = 0; prec < 2; ++prec) {
      enum px_precision p = prec ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
      double tol = prec ? 1e-9 : 2e-3;
      PX_CHECK_OK(ctx, lt_engine_make(ctx, m, &px_lattice_engine_cpu, integ, p,
                                      (enum px_lattice_scheme)scheme, 2, NULL, &en));
      PX_CHECK_OK(ctx, en.vt->run(en.e, 0, 0.0, dt, steps));
      en.vt->get_state(en.e, yc, NULL);
      lt_state_diff(m, yc, yr, d);
      printf("%s scheme %d %s: rel. diff u %.2e v %.2e W %.2e q %.2e\n", iname, scheme,
             prec ? "double" : "float", d[0], d[1], d[2], d[3]);
      PX_CHECK_NEAR(d[0], 0.0, tol);
      PX_CHECK_NEAR(d[1], 0.0, tol);
      PX_CHECK_NEAR(d[2], 0.0, tol);
      PX_CHECK_NEAR(d[3], 0.0, tol);
      lt_check_rayleigh(ctx, &en, &ref, tol, "cpu");
      lt_engine_free(&en);
    }
  lt_engine_free(&ref);
  free(yr);
  free(yc);
}

/* Fracture: a weak normal strength, strong load: both engines break the
 * same links. */
static void run_fracture(struct px_context *ctx) {
  struct px_lattice_model m;
  struct lt_engine ref, en;
  uint8_t *lr, *lc;
  double dt;
  int prec;
  if (lt_build_body(ctx, &m, 2e3) != PX_STATUS_OK) {
    PX_CHECK_OK(ctx, PX_STATUS_INTERNAL);
    return;
  }
  dt = 0.8 * px_lattice_model_dt_limit(&m, PX_LATTICE_INTEGRATOR_RK4);
  lr = (uint8_t *)malloc(m.nalloc);
  lc = (uint8_t *)malloc(m.nalloc);
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_ref, PX_LATTICE_INTEGRATOR_RK4,
                                  PX_PRECISION_DOUBLE, PX_LATTICE_SCHEME_AUTO, 1, NULL, &ref));
  PX_CHECK_OK(ctx, ref.vt->run(ref.e, 0, 0.0, dt, 60));
  ref.vt->get_state(ref.e, NULL, lr);
  printf("fracture: reference broke %ld links\n", ref.vt->broken(ref.e));
  PX_CHECK(ref.vt->broken(ref.e) > 0);
  for (prec = 0; prec < 2; ++prec) {
    int scheme;
    for (scheme = PX_LATTICE_SCHEME_GATHER; scheme <= PX_LATTICE_SCHEME_LINK_ONCE; ++scheme) {
      PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_cpu, PX_LATTICE_INTEGRATOR_RK4,
                                      prec ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE,
                                      (enum px_lattice_scheme)scheme, 2, NULL, &en));
      PX_CHECK_OK(ctx, en.vt->run(en.e, 0, 0.0, dt, 60));
      en.vt->get_state(en.e, NULL, lc);
      if (prec) {
        PX_CHECK(en.vt->broken(en.e) == ref.vt->broken(ref.e));
        PX_CHECK(memcmp(lr, lc, m.nalloc) == 0);
      } else {
        /* float may decide a borderline link differently */
        PX_CHECK_NEAR((double)en.vt->broken(en.e), (double)ref.vt->broken(ref.e),
                      0.05 * (double)ref.vt->broken(ref.e) + 1.0);
      }
      lt_engine_free(&en);
    }
  }
  lt_engine_free(&ref);
  free(lr);
  free(lc);
  px_lattice_model_free(ctx, &m);
}

/* The cpu engine's result does not depend on its thread count (the small
 * body above runs on one thread whatever is asked). */
static void run_threads(struct px_context *ctx) {
  struct px_lattice_model m;
  struct lt_el *y[2];
  uint8_t *l[2];
  int integ, prec, scheme, th;
  if (lt_build_body_h(ctx, &m, 5.0, 0.3e-3) != PX_STATUS_OK) {
    PX_CHECK_OK(ctx, PX_STATUS_INTERNAL);
    return;
  }
  for (th = 0; th < 2; ++th) {
    y[th] = (struct lt_el *)malloc(m.nalloc * sizeof *y[th]);
    l[th] = (uint8_t *)malloc(m.nalloc);
  }
  for (integ = 0; integ < 2; ++integ)
    for (prec = 0; prec < 2; ++prec)
      for (scheme = PX_LATTICE_SCHEME_GATHER; scheme <= PX_LATTICE_SCHEME_LINK_ONCE; ++scheme) {
        enum px_lattice_integrator in = (enum px_lattice_integrator)integ;
        double dt = 0.8 * px_lattice_model_dt_limit(&m, in);
        long broken[2];
        for (th = 0; th < 2; ++th) {
          struct lt_engine en;
          PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_cpu, in,
                                          prec ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE,
                                          (enum px_lattice_scheme)scheme, th + 1, NULL, &en));
          PX_CHECK_OK(ctx, en.vt->run(en.e, 0, 0.0, dt, 20));
          en.vt->get_state(en.e, y[th], l[th]);
          broken[th] = en.vt->broken(en.e);
          lt_engine_free(&en);
        }
        printf("threads: %s scheme %d %s: %ld links broken\n", integ ? "leapfrog" : "rk4", scheme,
               prec ? "double" : "float", broken[0]);
        PX_CHECK(memcmp(y[0], y[1], m.nalloc * sizeof *y[0]) == 0);
        PX_CHECK(memcmp(l[0], l[1], m.nalloc) == 0);
        PX_CHECK(broken[0] == broken[1]);
      }
  for (th = 0; th < 2; ++th) {
    free(y[th]);
    free(l[th]);
  }
  px_lattice_model_free(ctx, &m);
}

int main(void) {
  struct px_context *ctx;
  struct px_lattice_model m;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  PX_CHECK_OK(ctx, lt_build_body(ctx, &m, 0.0));
  if (px_test_failures) return px_test_report("test_lattice_engines");
  run_case(ctx, &m, PX_LATTICE_INTEGRATOR_RK4, 40);
  run_case(ctx, &m, PX_LATTICE_INTEGRATOR_LEAPFROG, 40);
  px_lattice_model_free(ctx, &m);
  run_fracture(ctx);
  run_threads(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  return px_test_report("test_lattice_engines");
}
