/* Binary contacts against the analytic linear spring–dashpot:
 * e_out = e (within 0.5%) and t_c = pi / (omega0 sqrt(1 - zeta^2)) (within
 * 1%) for e = 0.2 ... 1.0, both integrators, all precisions; the
 * Walton–Braun hysteretic law gives e = sqrt(k1/k2). */
#include <math.h>
#include <string.h>

#include "px_test.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/system.h"

#define PI 3.14159265358979323846

static void default_law(struct px_gran_law_spec *L, double kn, double e) {
  memset(L, 0, sizeof *L);
  L->normal = PX_GRAN_NORMAL_LINEAR;
  L->tangential = PX_GRAN_TANGENTIAL_SPRING;
  L->kn = kn;
  L->e = e;
  L->kt_ratio = 1.0 / 3.0;
  L->ct_ratio = 0.5;
  L->mu = 0.5;
}

/* Two equal discs head-on at +-v0, initially `gap` apart; returns e_out and
 * the contact duration (zero crossings of the overlap interpolated
 * linearly). The step count per contact is not an integer and the gap
 * varies, so that the contact starts and ends at different phases within a
 * step (with an integer count, start and end errors can cancel). */
static void two_discs(struct px_context *ctx, enum px_precision prec, enum px_gran_integrator integ,
                      const struct px_gran_law_spec *law, double steps_per_contact, double gap,
                      double *e_out, double *tc_out, double *tc_ref) {
  const double R = 0.002, m = 1.26e-4, v0 = 0.5;
  const double x[2] = {-R - 0.5 * gap, R + 0.5 * gap}, y[2] = {0, 0}, r[2] = {R, R}, mm[2] = {m, m};
  struct px_gran_sys *s = NULL;
  double prev = -1, t_start = -1, t_end = -1, a[8], b[8];
  long k;
  PX_CHECK_OK(ctx, px_gran_sys_create(ctx, prec, 1, &s));
  if (!s) return;
  s->pp = *law;
  s->integrator = integ;
  PX_CHECK_OK(ctx, px_gran_sys_add(s, 2, x, y, r, mm));
  PX_CHECK_OK(ctx, px_gran_sys_set_velocity(s, 0, v0, 0, 0));
  PX_CHECK_OK(ctx, px_gran_sys_set_velocity(s, 1, -v0, 0, 0));
  PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, steps_per_contact));
  *tc_ref = px_gran_sys_contact_time(s);
  for (k = 0; k < 100000; ++k) {
    double delta;
    PX_CHECK_OK(ctx, px_gran_sys_step(s));
    px_gran_sys_get(s, 0, a);
    px_gran_sys_get(s, 1, b);
    delta = 2 * R - (b[0] - a[0]);
    if (prev <= 0 && delta > 0 && t_start < 0) t_start = s->t - s->dt * delta / (delta - prev);
    if (prev > 0 && delta <= 0 && t_start >= 0) t_end = s->t - s->dt * delta / (delta - prev);
    /* one more step after separation: the end-of-contact dashpot remainder */
    if (prev <= 0 && delta <= 0 && t_end >= 0) break;
    prev = delta;
  }
  px_gran_sys_get(s, 0, a);
  px_gran_sys_get(s, 1, b);
  *e_out = (b[2] - a[2]) / (2 * v0);
  *tc_out = t_end - t_start;
  px_gran_sys_free(s);
}

static void test_restitution_and_contact_time(struct px_context *ctx) {
  const double es[5] = {0.2, 0.4, 0.6, 0.8, 1.0};
  const double gaps[3] = {0.4e-3, 0.4003e-3, 0.4007e-3};
  const enum px_precision precs[3] = {PX_PRECISION_DOUBLE, PX_PRECISION_MIXED, PX_PRECISION_SINGLE};
  int k, p, it, q;
  for (it = 0; it < 2; ++it)
    for (p = 0; p < 3; ++p)
      for (k = 0; k < 5; ++k) {
        double worst_e = 0, worst_t = 0;
        for (q = 0; q < 3; ++q) {
          struct px_gran_law_spec L;
          double e, tc, tref;
          /* Verlet: 60 steps per contact; ABM4 (first order at contact
           * onset, see docs/granular.md): 400 */
          default_law(&L, 2e5, es[k]);
          two_discs(ctx, precs[p], it ? PX_GRAN_INTEGRATOR_ABM4 : PX_GRAN_INTEGRATOR_VERLET, &L,
                    it ? 400.37 : 60.37, gaps[q], &e, &tc, &tref);
          PX_CHECK_REL(e, es[k], 0.005);
          PX_CHECK_REL(tc, tref, 0.01);
          if (fabs(e / es[k] - 1) > fabs(worst_e)) worst_e = e / es[k] - 1;
          if (fabs(tc / tref - 1) > fabs(worst_t)) worst_t = tc / tref - 1;
        }
        printf("integrator %s precision %s e=%.2f: worst e error %.2e, t_c error %.2e\n",
               it ? "abm4" : "verlet", px_precision_name(precs[p]), es[k], worst_e, worst_t);
      }
}

static void test_contact_time_formula(struct px_context *ctx) {
  /* t_c from the law matches pi / (omega0 sqrt(1 - zeta^2)) with m* = m/2 */
  struct px_gran_law_spec L;
  const double m = 1.26e-4, kn = 2e5, e = 0.5;
  const double zeta = -log(e) / sqrt(PI * PI + log(e) * log(e));
  double e_out, tc, tref;
  default_law(&L, kn, e);
  two_discs(ctx, PX_PRECISION_DOUBLE, PX_GRAN_INTEGRATOR_VERLET, &L, 50, 0.4e-3, &e_out, &tc,
            &tref);
  PX_CHECK_REL(tref, PI / (sqrt(kn / (0.5 * m)) * sqrt(1 - zeta * zeta)), 1e-12);
}

static void test_hysteretic_restitution(struct px_context *ctx) {
  const double es[3] = {0.3, 0.6, 0.9};
  int k;
  for (k = 0; k < 3; ++k) {
    struct px_gran_law_spec L;
    double e, tc, tref;
    default_law(&L, 2e5, es[k]);
    L.normal = PX_GRAN_NORMAL_HYSTERETIC; /* k2 = k1 / e^2, constant (Walton & Braun) */
    two_discs(ctx, PX_PRECISION_DOUBLE, PX_GRAN_INTEGRATOR_VERLET, &L, 100.37, 0.4e-3, &e, &tc,
              &tref);
    PX_CHECK_REL(e, es[k], 0.005);
    printf("hysteretic e=%.2f: e_out=%.5f\n", es[k], e);
  }
}

static void test_zeta_formula(void) {
  /* zeta(e) reproduces e = exp(-zeta pi / sqrt(1 - zeta^2)) */
  double e;
  for (e = 0.1; e < 1.0; e += 0.1) {
    const double z = px_gran_zeta(e);
    PX_CHECK_REL(exp(-z * PI / sqrt(1 - z * z)), e, 1e-12);
  }
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  test_zeta_formula();
  test_contact_time_formula(ctx);
  test_restitution_and_contact_time(ctx);
  test_hysteretic_restitution(ctx);
  px_context_free(ctx);
  return px_test_report("test_granular_contact");
}
