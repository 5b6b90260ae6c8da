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

/* Uniform in [0, 1) (a 64-bit LCG; the tests' draws are reproducible). */
static double urand01(unsigned long long *s) {
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

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

/* px_gran_sys_coordination decides "in contact" from the squares of the
 * distance and the radii's sum away from the boundary and by hypot near it:
 * discs placed at distances from 1e-11 under to 1e-11 over r_i + r_j, along
 * an axis and on a diagonal (no exact squares), must count as the plain
 * test hypot(dx, dy) < r_i + r_j over the same pair list counts them
 * (double and mixed precision: a double state). */
static void test_coordination_boundary(struct px_context *ctx, enum px_precision prec) {
  static const double rel[] = {-1e-11, -1e-13, -1e-15, -4e-16, -2e-16, 0.0,
                               2e-16,  4e-16,  1e-15,  1e-13,  1e-11};
  /* NR pairs at the offsets rel along x and on a diagonal, then NF pairs
   * where the squares alone, dx^2 + dy^2 < c^2, would decide otherwise than
   * hypot (found by a search at random angles within 4e-16 of contact) */
  enum { NR = sizeof rel / sizeof rel[0], NF = 6, N = 4 * NR + 2 * NF };
  /* radii exact in float too: mixed keeps them in float */
  const double R0 = 0.001953125, R1 = 0.001220703125, c = R0 + R1;
  double x[N], y[N], r[N], m[N], z[N], zref[N], a[8], b[8];
  struct px_gran_sys *s = NULL;
  size_t i, total = 0;
  unsigned long long sd = 2026;
  int32_t k;
  int found = 0;
  for (int q = 0; q < NR; ++q)
    for (int diag = 0; diag < 2; ++diag) {
      const size_t at = (size_t)(4 * q + 2 * diag);
      const double d = c * (1.0 + rel[q]), cx = 0.0625 * (double)(2 * q + diag);
      x[at] = cx, y[at] = 0.0;
      x[at + 1] = cx + (diag ? d * 0.6 : d), y[at + 1] = diag ? d * 0.8 : 0.0;
    }
  for (long t = 0; t < 1000000 && found < NF; ++t) {
    const size_t at = (size_t)(4 * NR + 2 * found);
    const double cx = 0.0625 * (double)(2 * NR + found), th = 2.0 * PI * urand01(&sd);
    const double d = c * (1.0 + 8e-16 * (urand01(&sd) - 0.5));
    const double x1 = cx + d * cos(th), y1 = d * sin(th), dx = cx - x1, dy = -y1;
    if ((hypot(dx, dy) < c) == (dx * dx + dy * dy < c * c)) continue;
    x[at] = cx, y[at] = 0.0, x[at + 1] = x1, y[at + 1] = y1;
    ++found;
  }
  PX_CHECK_MSG(found == NF, "found %d of %d pairs where the squares and hypot disagree", found, NF);
  for (i = 0; i < N; ++i) r[i] = i % 2 ? R1 : R0, m[i] = 1e-4;
  PX_CHECK_OK(ctx, px_gran_sys_create(ctx, prec, 1, &s));
  if (!s) return;
  default_law(&s->pp, 2e5, 0.8);
  PX_CHECK_OK(ctx, px_gran_sys_add(s, N, x, y, r, m));
  PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 25));
  double ex[N], ey[N], er[N];
  px_gran_sys_export(s, ex, ey, NULL, NULL, NULL, er, NULL, NULL);
  const double mean = px_gran_sys_coordination(s, ex, ey, er, z);
  memset(zref, 0, sizeof zref);
  for (i = 0; i < s->n; ++i) {
    s->ops->get(s, i, a);
    for (k = s->pstart[i]; k < s->pstart[i + 1]; ++k) {
      s->ops->get(s, (size_t)s->pj[k], b);
      if (hypot(a[PX_GRAN_P_X] - b[PX_GRAN_P_X], a[PX_GRAN_P_Y] - b[PX_GRAN_P_Y]) <
          a[PX_GRAN_P_R] + b[PX_GRAN_P_R]) {
        zref[i] += 1;
        zref[s->pj[k]] += 1;
        total += 2;
      }
    }
  }
  PX_CHECK_MSG(s->npairs == N / 2, "%zu pairs listed, expected %d", s->npairs, N / 2);
  PX_CHECK_MSG(memcmp(z, zref, s->n * sizeof z[0]) == 0 && mean == (double)total / (double)s->n,
               "coordination %g against hypot's %g (%s)", mean, (double)total / (double)s->n,
               prec == PX_PRECISION_MIXED ? "mixed" : "double");
  /* the test can tell: some pairs touch, some do not */
  PX_CHECK(total > 0 && total < (size_t)N);
  px_gran_sys_free(s);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  test_zeta_formula();
  test_contact_time_formula(ctx);
  test_restitution_and_contact_time(ctx);
  test_hysteretic_restitution(ctx);
  /* (a single-precision state reaches the same double arithmetic, from
   * float positions that cannot be placed this close to the boundary) */
  test_coordination_boundary(ctx, PX_PRECISION_DOUBLE);
  test_coordination_boundary(ctx, PX_PRECISION_MIXED);
  px_context_free(ctx);
  return px_test_report("test_granular_contact");
}
