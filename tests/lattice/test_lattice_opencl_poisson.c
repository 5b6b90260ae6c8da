/* The opencl engine with Poisson's ratio != 0 (issue 23; POCL's CPU device
 * in CI) against the cpu engine in double (gather scheme: the volumetric
 * term of lattice_cpu_impl.h, itself checked against the reference engine by
 * test_lattice_poisson_engines), at nu = 0.3 and nu = -0.4, on the body with
 * a hole, clamp, ramped load, shaker and damping of test_lattice_opencl:
 *  - 30 steps of RK4 and of leapfrog, gather and link_once, float and
 *    double: the state within test_lattice_opencl's tolerances (relative to
 *    each quantity's largest magnitude: double 1e-9, float 1e-4); the
 *    device's stresses (all six components, with the P term) and
 *    synchronized velocities 1e-8 / 1e-3; the sums of the quasi-static
 *    relaxation (q.K q includes the volumetric forces) as there;
 *  - fracture on (bond strength 2e3 N), 60 RK4 steps, both schemes: double
 *    breaks the very same links (flags compared byte for byte) and keeps
 *    the state within 1e-9; float, whose rounding may break a link a step
 *    apart, breaks as many links within 5 % + 1 (the rule of
 *    test_lattice_poisson_engines), and its state is compared (1e-4) only
 *    where it broke the very same links.
 * A broken link leaves theta and c_a of both its ends on both engines (the
 * same fracture-then-coefficients order); a mismatch there shows as a state
 * difference far above 1e-9. */
#include <stdlib.h>

#include "lt_util.h"

#ifdef PX_HAVE_OPENCL
/* State, links, stresses and velocities of an engine after `steps` steps. */
struct run_out {
  struct lt_el *y;
  uint8_t *links;
  double *sigma, *v;
  long broken;
};

static void run_out_alloc(const struct px_lattice_model *m, struct run_out *o) {
  o->y = (struct lt_el *)malloc(m->nalloc * sizeof *o->y);
  o->links = (uint8_t *)malloc(m->nalloc);
  o->sigma = (double *)calloc(6 * m->nalloc, sizeof(double));
  o->v = (double *)calloc(3 * m->nalloc, sizeof(double));
}

static void run_out_free(struct run_out *o) {
  free(o->y);
  free(o->links);
  free(o->sigma);
  free(o->v);
}

static void run_engine(struct px_context *ctx, struct lt_engine *en, double dt, long steps,
                       struct run_out *o) {
  struct px_lattice_fields f;
  PX_CHECK_OK(ctx, en->vt->run(en->e, 0, 0.0, dt, steps));
  PX_CHECK_OK(ctx, en->vt->get_state(en->e, o->y, o->links));
  memset(&f, 0, sizeof f);
  f.sigma = o->sigma;
  f.v = o->v;
  PX_CHECK_OK(ctx, en->vt->fields(en->e, (double)steps * dt, dt, &f));
  o->broken = en->vt->broken(en->e);
}

/* Every opencl variant (scheme x precision) of integrator integ against the
 * double cpu engine on model m. */
static void compare(struct px_context *ctx, struct px_backend *be, const struct px_lattice_model *m,
                    enum px_lattice_integrator integ, long steps) {
  const char *iname = integ == PX_LATTICE_INTEGRATOR_RK4 ? "rk4" : "leapfrog";
  const int frac = m->fracture;
  struct lt_engine cpu, en;
  struct run_out rc, ro;
  double dt = 0.8 * px_lattice_model_dt_limit(m, integ), d[4];
  int var;
  run_out_alloc(m, &rc);
  run_out_alloc(m, &ro);
  PX_CHECK_OK(ctx, lt_engine_make(ctx, m, &px_lattice_engine_cpu, integ, PX_PRECISION_DOUBLE,
                                  PX_LATTICE_SCHEME_GATHER, 1, NULL, &cpu));
  run_engine(ctx, &cpu, dt, steps, &rc);
  if (frac) {
    printf("nu = %g %s: cpu broke %ld links\n", m->par.nu, iname, rc.broken);
    PX_CHECK(rc.broken > 0);
  }
  for (var = 0; var < 4; ++var) {
    const int dbl = var & 1;
    enum px_precision p = dbl ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
    enum px_lattice_scheme sch = var & 2 ? PX_LATTICE_SCHEME_LINK_ONCE : PX_LATTICE_SCHEME_GATHER;
    double tol = dbl ? 1e-9 : 1e-4, ftol = dbl ? 1e-8 : 1e-3, ds, dv;
    if (dbl && !px_backend_has_fp64(be)) continue;
    PX_CHECK_OK(ctx, lt_engine_make(ctx, m, &px_lattice_engine_opencl, integ, p, sch, 0, be, &en));
    if (!en.e) continue;
    run_engine(ctx, &en, dt, steps, &ro);
    lt_state_diff(m, ro.y, rc.y, d);
    ds = lt_field_diff(m, ro.sigma, rc.sigma, 6);
    dv = lt_field_diff(m, ro.v, rc.v, 3);
    printf(
        "nu = %g opencl %s %s %s%s: rel. diff u %.2e v %.2e W %.2e q %.2e stress %.2e "
        "v(fields) %.2e; broken %ld (cpu %ld)\n",
        m->par.nu, iname, dbl ? "double" : "float", var & 2 ? "link_once" : "gather",
        frac ? " fracture" : "", d[0], d[1], d[2], d[3], ds, dv, ro.broken, rc.broken);
    if (frac && dbl) {
      PX_CHECK(ro.broken == rc.broken);
      PX_CHECK(memcmp(ro.links, rc.links, m->nalloc) == 0);
    } else if (frac) {
      PX_CHECK_NEAR((double)ro.broken, (double)rc.broken, 0.05 * (double)rc.broken + 1.0);
    }
    /* float with fracture: compared where it broke the very same links */
    if (!frac || dbl || memcmp(ro.links, rc.links, m->nalloc) == 0) {
      PX_CHECK_NEAR(d[0], 0.0, tol);
      PX_CHECK_NEAR(d[1], 0.0, tol);
      PX_CHECK_NEAR(d[2], 0.0, tol);
      PX_CHECK_NEAR(d[3], 0.0, tol);
      PX_CHECK_NEAR(ds, 0.0, ftol);
      PX_CHECK_NEAR(dv, 0.0, ftol);
      lt_check_rayleigh(ctx, &en, &cpu, tol, "opencl");
    }
    lt_engine_free(&en);
  }
  lt_engine_free(&cpu);
  run_out_free(&rc);
  run_out_free(&ro);
}

static void test_nu(struct px_context *ctx, struct px_backend *be, double nu) {
  struct px_lattice_model m;
  PX_CHECK_OK(ctx, lt_build_body_nu(ctx, &m, 0.0, 1e-3, nu));
  PX_CHECK(m.lam != 0.0);
  compare(ctx, be, &m, PX_LATTICE_INTEGRATOR_RK4, 30);
  compare(ctx, be, &m, PX_LATTICE_INTEGRATOR_LEAPFROG, 30);
  px_lattice_model_free(ctx, &m);
  PX_CHECK_OK(ctx, lt_build_body_nu(ctx, &m, 2e3, 1e-3, nu));
  compare(ctx, be, &m, PX_LATTICE_INTEGRATOR_RK4, 60);
  px_lattice_model_free(ctx, &m);
}
#endif

int main(void) {
#ifdef PX_HAVE_OPENCL
  struct px_context *ctx;
  struct px_backend *be = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  be = px_test_backend(ctx, "opencl", 0);
  printf("device: %s\n", px_backend_device(be));
  test_nu(ctx, be, 0.3);
  test_nu(ctx, be, -0.4);
  px_backend_free(be);
  px_context_free(ctx);
  return px_test_report("test_lattice_opencl_poisson");
#else
  return PX_TEST_SKIP;
#endif
}
