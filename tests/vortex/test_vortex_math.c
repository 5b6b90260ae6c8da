/* The vortex kernels' branch-free functions for vector loops
 * (vortex_kernel.h) against the C library: vx_exp_neg (the VVD weights and
 * wall integrals), vx_atan2 (through px_vortex_atan2: panel coefficients,
 * wall angles, the sheet's velocity) and vx_log (the sheet's velocity). */
#include <float.h>
#include <string.h>

#include "px_test.h"
#include "vortex/vx_test_util.h"
#include "solvers/vortex/vortex_core.h"

#define PX_REAL double
#include "kernels/px_kernel.h"
#include "solvers/vortex/vortex_kernel.h"

#define PI 3.14159265358979323846

/* vx_exp_neg (the VVD weights and wall integrals on every backend) against
 * the C library over its range, and the clamp beyond it. */
static void test_exp_neg(void) {
  double worst = 0.0;
  for (int i = 0; i <= 400000; ++i) {
    double x = 20.0 * i / 400000.0;
    worst = fmax(worst, fabs(vx_exp_neg(x) / exp(-x) - 1.0));
  }
  printf("exp: max relative error of vx_exp_neg on [0, 20] %.3g\n", worst);
  PX_CHECK_MSG(worst < 3e-13, "vx_exp_neg relative error %.3g", worst);
  PX_CHECK(vx_exp_neg(0.0) == 1.0);
  PX_CHECK(vx_exp_neg(25.0) == vx_exp_neg(20.0));
}

/* px_vortex_atan2 (branch-free, for vector loops) against the C library over
 * all octants, near the axes and the octant boundaries, and signed zeros. */
static void test_atan2(void) {
  double worst = 0.0;
  unsigned long long s = 12345;
  for (int q = 0; q < 200000; ++q) {
    double u = vx_test_urand(&s), v = vx_test_urand(&s);
    double ang = 2.0 * PI * u, mag = pow(10.0, 12.0 * v - 6.0);
    double y = mag * sin(ang), x = mag * cos(ang);
    if (q % 7 == 0) y *= 1e-9;                          /* near the x axis */
    if (q % 11 == 0) x *= 1e-9;                         /* near the y axis */
    if (q % 13 == 0) y = x * (1.0 + 1e-12 * (u - 0.5)); /* |y| = |x| */
    if (q % 17 == 0) y = x * 0.26794919243112270647 * (1.0 + 1e-12 * (v - 0.5)); /* tan(pi/12) */
    worst = fmax(worst, fabs(px_vortex_atan2(y, x) - atan2(y, x)));
  }
  printf("atan2: max |px_vortex_atan2 - atan2| = %.3g\n", worst);
  PX_CHECK_MSG(worst < 4e-15, "px_vortex_atan2 error %.3g", worst);
  PX_CHECK(px_vortex_atan2(0.0, 1.0) == 0.0);
  PX_CHECK(px_vortex_atan2(0.0, -1.0) == PI);
  PX_CHECK(px_vortex_atan2(-0.0, -1.0) == -PI);
  PX_CHECK(px_vortex_atan2(0.0, 0.0) == 0.0);
  PX_CHECK_NEAR(px_vortex_atan2(1.0, 0.0), 0.5 * PI, 1e-16);
  PX_CHECK_NEAR(px_vortex_atan2(-1.0, 0.0), -0.5 * PI, 1e-16);
}

/* vx_log against the C library: relative error within 2 ulp over the
 * whole range (subnormals, around 1 where log x is small, around sqrt 2
 * where the reduction switches, powers of two), and the special values. */
static void test_log(void) {
  double worst = 0.0, worst_one = 0.0;
  unsigned long long s = 777;
  for (int q = 0; q < 300000; ++q) {
    const double u = vx_test_urand(&s), v = vx_test_urand(&s);
    double x = ldexp(1.0 + u, (int)(2100.0 * v) - 1074);                /* 2^-1074 .. 2^1025 */
    if (q % 5 == 0) x = 1.0 + (u - 0.5) * ldexp(1.0, -(int)(52.0 * v)); /* near 1 */
    if (q % 7 == 0) x = 1.4142135623730951 * (1.0 + (u - 0.5) * 1e-12); /* sqrt 2 */
    if (q % 11 == 0) x = ldexp(1.0, (int)(2000.0 * v) - 1000);          /* 2^k */
    if (!(x > 0.0) || !isfinite(x)) continue;
    const double ref = log(x), got = vx_log(x);
    if (fabs(x - 1.0) < 0.25) { /* log x small: its error relative to x - 1 */
      worst_one = fmax(worst_one, fabs(got - ref) / fabs(x - 1.0));
    } else {
      worst = fmax(worst, fabs(got - ref) / fabs(ref));
    }
  }
  printf("log: max relative error of vx_log %.3g (%.3g of x - 1 near 1)\n", worst, worst_one);
  PX_CHECK_MSG(worst <= 2.0 * DBL_EPSILON, "vx_log relative error %.3g", worst);
  PX_CHECK_MSG(worst_one <= 2.0 * DBL_EPSILON, "vx_log error near 1: %.3g of x - 1", worst_one);
  PX_CHECK(vx_log(1.0) == 0.0);
  PX_CHECK(vx_log(0.0) == -INFINITY && vx_log(-0.0) == -INFINITY);
  PX_CHECK(vx_log(INFINITY) == INFINITY);
  PX_CHECK(isnan(vx_log(-1.0)) && isnan(vx_log(NAN)) && isnan(vx_log(-INFINITY)));
  PX_CHECK_NEAR(vx_log(DBL_TRUE_MIN), log(DBL_TRUE_MIN), 1e-12);
  PX_CHECK_NEAR(vx_log(DBL_MAX), log(DBL_MAX), 1e-12);
}

int main(void) {
  test_exp_neg();
  test_atan2();
  test_log();
  return px_test_report("test_vortex_math");
}
