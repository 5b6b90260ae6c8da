/* The physics headers compiled as C (double precision in this unit; the
 * float and OpenCL builds run in the conformance suite): analytic values of
 * the Biot–Savart kernel, the grid cell index and its clamping, the vector
 * helpers and the name mangling. */
#define PX_REAL double
#include "kernels/biot_savart.h"
#include "kernels/grid.h"
#include "px_test.h"

static int PX_SFX(px_test_mangled)(void) { return 64; }

static void test_biot_savart(void) {
  const double two_pi = 6.283185307179586;
  px_real2 u;
  /* Γ = 2π at the origin, point-vortex region: |u| = Γ/(2π r) = 1/r,
   * counter-clockwise (k × d) */
  u = px_biot_savart_velocity(1.0, 0.0, two_pi, 1e-4);
  PX_CHECK_NEAR(u.x, 0.0, 1e-15);
  PX_CHECK_NEAR(u.y, 1.0, 1e-15);
  u = px_biot_savart_velocity(0.0, 2.0, two_pi, 1e-4);
  PX_CHECK_NEAR(u.x, -0.5, 1e-15);
  PX_CHECK_NEAR(u.y, 0.0, 1e-15);
  u = px_biot_savart_velocity(-3.0, -4.0, two_pi, 1e-4);
  PX_CHECK_NEAR(u.x, 4.0 / 25.0, 1e-15);
  PX_CHECK_NEAR(u.y, -3.0 / 25.0, 1e-15);
  /* inside the core (eps = 1): solid-body rotation u = Γ/(2π ε²) k × d */
  u = px_biot_savart_velocity(0.5, 0.0, two_pi, 1.0);
  PX_CHECK_NEAR(u.y, 0.5, 1e-15);
  u = px_biot_savart_velocity(0.0, -0.25, two_pi, 1.0);
  PX_CHECK_NEAR(u.x, 0.25, 1e-15);
  /* continuous at the core edge, zero on the vortex itself */
  u = px_biot_savart_velocity(1.0, 0.0, two_pi, 1.0);
  PX_CHECK_NEAR(u.y, 1.0, 1e-15);
  u = px_biot_savart_velocity(0.0, 0.0, 5.0, 1e-3);
  PX_CHECK(u.x == 0.0 && u.y == 0.0);
  /* the un-normalised term times 1/(2π) is the velocity */
  u = px_biot_savart_term(0.3, -0.7, 2.0, 1e-6);
  PX_CHECK_NEAR(u.x * PX_BIOT_SAVART_SCALE, 2.0 / two_pi * 0.7 / 0.58, 1e-15);
  PX_CHECK_NEAR(u.y * PX_BIOT_SAVART_SCALE, 2.0 / two_pi * 0.3 / 0.58, 1e-15);
}

static void test_grid_index(void) {
  const px_real o = -1.0, inv_h = 1.0 / 0.25;
  PX_CHECK(px_grid_axis(-1.0, o, inv_h, 8) == 0);
  PX_CHECK(px_grid_axis(-1.0 + 2.5 * 0.25, o, inv_h, 8) == 2);
  PX_CHECK(px_grid_axis(-0.75, o, inv_h, 8) == 1); /* on a cell boundary: the upper cell */
  PX_CHECK(px_grid_axis(0.999, o, inv_h, 8) == 7);
  /* outside: clamped into the edge cells; NaN to cell 0 */
  PX_CHECK(px_grid_axis(-1.0 - 1e-12, o, inv_h, 8) == 0);
  PX_CHECK(px_grid_axis(-50.0, o, inv_h, 8) == 0);
  PX_CHECK(px_grid_axis(1.0, o, inv_h, 8) == 7);
  PX_CHECK(px_grid_axis(1e300, o, inv_h, 8) == 7);
  PX_CHECK(px_grid_axis(INFINITY, o, inv_h, 8) == 7);
  PX_CHECK(px_grid_axis(-INFINITY, o, inv_h, 8) == 0);
  PX_CHECK(px_grid_axis(NAN, o, inv_h, 8) == 0);
  /* x fastest */
  PX_CHECK(px_grid_cell_2d(0.3, 0.6, 0.0, 0.0, 4.0, 4, 3) == 2 * 4 + 1);
  PX_CHECK(px_grid_cell_3d(0.3, 0.6, 0.8, 0.0, 0.0, 0.0, 4.0, 4, 5, 6) == (3 * 5 + 2) * 4 + 1);
}

static void test_vectors(void) {
  const px_real2 a = px_v2(1.0, 2.0), b = px_v2(-3.0, 0.5);
  const px_real3 p = px_v3(1.0, 0.0, 0.0), q = px_v3(0.0, 1.0, 0.0);
  px_real2 r = px_v2_perp(a);
  px_real3 c = px_v3_cross(p, q);
  PX_CHECK(r.x == -2.0 && r.y == 1.0);
  PX_CHECK(px_v2_dot(a, b) == -2.0);
  PX_CHECK(px_v2_cross(a, b) == 0.5 + 6.0);
  PX_CHECK(px_v2_norm2(a) == 5.0);
  r = px_v2_sub(px_v2_add(a, b), px_v2_scale(b, 2.0));
  PX_CHECK(r.x == 4.0 && r.y == 1.5);
  PX_CHECK(c.x == 0.0 && c.y == 0.0 && c.z == 1.0);
  PX_CHECK(px_v3_dot(px_v3_add(p, q), px_v3_sub(p, q)) == 0.0);
  PX_CHECK(px_v3_norm2(px_v3_scale(p, 3.0)) == 9.0);
  PX_CHECK(px_maxr(1.0, 2.0) == 2.0 && px_minr(1.0, 2.0) == 1.0);
  PX_CHECK(px_clampi(-3, 0, 5) == 0 && px_clampi(9, 0, 5) == 5 && px_clampi(4, 0, 5) == 4);
  PX_CHECK(PX_REAL_IS_DOUBLE == 1);
  PX_CHECK(px_test_mangled_f64() == 64);
  PX_CHECK(sizeof(px_real) == 8 && sizeof(PX_R(0.5)) == 8);
}

int main(void) {
  test_biot_savart();
  test_grid_index();
  test_vectors();
  return px_test_report("test_compute_kernels");
}
