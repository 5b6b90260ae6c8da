/* cpu vs opencl: the same packing in a vibrating box stepped on both
 * engines (through their tables, granular_engine.h) gives identical contact sets and agreeing
 * forces, positions and wall statistics (double precision; float within float tolerances). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "granular_test_util.h"
#include "solvers/granular/granular_engine.h"

#define PI 3.14159265358979323846

/* A 40 x 30 packing compressed by 5 % in a box that vibrates, with a round
 * obstacle. */
static struct px_gran_sys *make(struct px_context *ctx, enum px_precision p,
                                const struct px_gran_geom *g, const struct px_gran_motion *mo,
                                int elastic) {
  struct px_gran_sys *s = NULL;
  uint64_t rng[4];
  int i, j;
  if (px_gran_sys_create(ctx, p, 1, &s) != PX_STATUS_OK) return NULL;
  gt_law(&s->pp, 2e5, elastic ? 1.0 : 0.6, elastic ? 0.0 : 0.4);
  gt_law(&s->pw, 2e5, elastic ? 1.0 : 0.5, elastic ? 0.0 : 0.3);
  s->gravity[1] = -9.81;
  px_gran_sys_set_walls(s, g, mo, 1);
  px_rng_seed(rng, 5);
  for (j = 0; j < 30; ++j)
    for (i = 0; i < 42; ++i) {
      double x = 0.00205 + 0.00401 * i + (j & 1) * 0.002, y = 0.00205 + 0.00349 * j;
      double r = 0.0018 + 0.0002 * px_rng_uniform(rng), m = 7800 * PI * r * r * 0.004;
      if (hypot(x - 0.09, y - 0.12) < 0.015 + r * 1.02 || x > 0.18 - 0.00205) continue;
      px_gran_sys_add(s, 1, &x, &y, &r, &m);
      px_gran_sys_set_velocity(s, (int32_t)s->n - 1, 1.0 * px_rng_normal(rng),
                               1.0 * px_rng_normal(rng), 0);
    }
  if (px_gran_sys_prepare(s, 0, 50) != PX_STATUS_OK) {
    px_gran_sys_free(s);
    return NULL;
  }
  return s;
}

int main(void) {
  struct px_context *ctx = NULL;
  struct px_backend *be = NULL;
  struct px_gran_geom g;
  struct px_gran_motion mo;
  int prec;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  be = px_test_backend(ctx, "opencl", 0);
  printf("device: %s\n", px_backend_device(be));
  px_gran_geom_init(&g);
  PX_CHECK_OK(ctx, gt_rect(ctx, &g, 0, 0, 0.18, 0.25, 0.0018, 0, "box"));
  PX_CHECK_OK(ctx, gt_circle(ctx, &g, 0.09, 0.12, 0.015, 0, 0.0018, 0, "part"));
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 0.008));
  px_gran_motion_init(&mo);
  mo.kind = PX_GRAN_MOTION_HARMONIC;
  mo.amp[0] = mo.amp[1] = 0.001;
  mo.freq[0] = mo.freq[1] = 40;
  mo.phase[1] = PI / 2;
  mo.ramp = 0.005;
  for (prec = 0; prec < 2 && be; ++prec) {
    const enum px_precision p = prec == 0 ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
    struct px_gran_sys *cpu = make(ctx, p, &g, &mo, 0), *mir = make(ctx, p, &g, &mo, 0);
    const struct px_gran_engine_i *ocl = &px_gran_engine_opencl;
    void *cl = NULL;
    struct px_gran_stats_spec sp;
    const double tol = 2e-4; /* [m], for discs of 2 mm: statistically the same run */
    double worst_x = 0, worst_a = 0, amax = 0, imp_cpu = 0, imp_cl = 0;
    size_t i, k;
    int32_t *a = NULL, *b = NULL;
    size_t na = 0, nb = 0;
    long step;
    PX_CHECK(cpu && mir);
    if (!cpu || !mir) break;
    memset(&sp, 0, sizeof sp);
    sp.finnie_n = 2;
    PX_CHECK_OK(ctx, px_gran_sys_stats_enable(cpu, &sp));
    PX_CHECK_OK(ctx, px_gran_sys_stats_enable(mir, &sp));
    PX_CHECK_OK(ctx, ocl->create(be, mir, &cl));
    if (!cl) break;
    /* the same accelerations at the same positions: an elastic frictionless
     * twin (forces depend on the positions only) is run on the cpu into a
     * dense state, copied to the device, and both take one step */
    {
      struct px_gran_sys *ec = make(ctx, p, &g, &mo, 1), *em = make(ctx, p, &g, &mo, 1);
      void *ecl = NULL;
      for (step = 0; step < 300 && ec && em; ++step) {
        PX_CHECK_OK(ctx, px_gran_sys_step(ec));
        PX_CHECK_OK(ctx, px_gran_sys_step(em));
      }
      if (ec && em) PX_CHECK_OK(ctx, ocl->create(be, em, &ecl));
      if (ecl) {
        PX_CHECK_OK(ctx, ocl->upload(ecl));
        PX_CHECK_OK(ctx, px_gran_sys_step(ec));
        PX_CHECK_OK(ctx, ocl->step(ecl, em->step, em->dt));
        PX_CHECK_OK(ctx, ocl->sync(ecl));
        for (i = 0; i < ec->n; ++i) {
          const size_t ic = (size_t)ec->where[i], ig = (size_t)em->where[i];
          const double ac = px_gran_reals_get(ec->fy, ic, ec->ssize);
          const double ag = px_gran_reals_get(em->fy, ig, em->ssize);
          if (fabs(ac - ag) > worst_a) worst_a = fabs(ac - ag);
          if (fabs(ac) > amax) amax = fabs(ac);
        }
        PX_CHECK_OK(ctx, ocl->contacts(ecl, &a, &na));
        PX_CHECK_OK(ctx, px_gran_sys_contacts_brute(ec, &b, &nb));
        printf(
            "%s, same state: %zu contacts on the device, %zu on the cpu; accelerations differ "
            "by %.3g of %.3g m/s^2\n",
            px_precision_name(p), na, nb, worst_a, amax);
        PX_CHECK(na > 150);
        PX_CHECK(na == nb && memcmp(a, b, 2 * na * sizeof *a) == 0);
        PX_CHECK(worst_a <= (prec == 0 ? 1e-9 : 2e-4) * amax);
        px_mem_free(ctx, a);
        px_mem_free(ctx, b);
      }
      if (ecl) ocl->destroy(ecl);
      px_gran_sys_free(ec);
      px_gran_sys_free(em);
    }
    /* the contact sets after 300 steps (packing, walls and obstacle in
     * contact) and statistics after 800 */
    for (step = 0; step < 800; ++step) {
      PX_CHECK_OK(ctx, px_gran_sys_step(cpu));
      PX_CHECK_OK(ctx, ocl->step(cl, mir->step, mir->dt));
      if (step == 300 || step == 799) {
        PX_CHECK_OK(ctx, ocl->contacts(cl, &a, &na));
        PX_CHECK_OK(ctx, px_gran_sys_contacts_brute(cpu, &b, &nb));
        printf("step %ld: %zu contacts through the device lists, %zu by cpu brute force\n", step,
               na, nb);
        PX_CHECK(na > 150);
        /* the two runs part by round-off growing through the collisions */
        PX_CHECK(fabs((double)na - (double)nb) <= 0.05 * (double)nb);
        px_mem_free(ctx, b);
        b = NULL;
        /* the device's lists, kept over the run with their skin, hold
         * exactly the contacts of the device's own state (brute force on
         * the downloaded positions) */
        PX_CHECK_OK(ctx, ocl->sync(cl));
        PX_CHECK_OK(ctx, px_gran_sys_contacts_brute(mir, &b, &nb));
        printf(
            "step %ld: %zu contacts through the device lists, %zu by brute force on the "
            "device state\n",
            step, na, nb);
        PX_CHECK(na == nb && b && memcmp(a, b, 2 * na * sizeof *a) == 0);
        px_mem_free(ctx, a);
        px_mem_free(ctx, b);
      }
    }
    PX_CHECK_OK(ctx, ocl->sync(cl));
    for (i = 0; i < cpu->n; ++i) {
      double rc[8], rg[8];
      px_gran_sys_get(cpu, (int32_t)i, rc);
      px_gran_sys_get(mir, (int32_t)i, rg);
      for (k = 0; k < 2; ++k)
        if (fabs(rc[k] - rg[k]) > worst_x) worst_x = fabs(rc[k] - rg[k]);
    }
    for (k = 0; k < g.nseg; ++k) {
      imp_cpu += cpu->stats.impacts[k];
      imp_cl += mir->stats.impacts[k];
    }
    printf(
        "%s, after 800 steps: positions differ by %.3g m at most (round-off grows through "
        "collisions); wall impacts cpu %g, opencl %g\n",
        px_precision_name(p), worst_x, imp_cpu, imp_cl);
    PX_CHECK(worst_x < tol);
    PX_CHECK(imp_cpu > 50);
    PX_CHECK(fabs(imp_cl - imp_cpu) <= 0.1 * imp_cpu);
    ocl->destroy(cl);
    px_gran_sys_free(cpu);
    px_gran_sys_free(mir);
  }
  px_gran_geom_free(ctx, &g);
  px_backend_free(be);
  px_context_free(ctx);
  return px_test_report("test_granular_opencl");
}
