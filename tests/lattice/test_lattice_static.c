/* Static validation (quasi-static relaxation: leapfrog + adaptive dynamic
 * relaxation) on the cpu engine in double and single precision:
 *  - axial bar under an end force: delta = F L / (E A) within 0.5 %, and
 *    no lateral strain (Poisson's ratio 0);
 *  - cantilever with a tip load, 4 x 4 elements through the section,
 *    L/H = 5: Timoshenko's deflection P L^3/(3 E I) + P L/(kappa G A),
 *    G = E/2, kappa = 5/6 (Cowper 1966 with nu = 0), within 1 %;
 *  - single precision agrees with double within 0.2 % on both.
 * L is the distance between the centres of the clamped and the loaded
 * element layers (the clamp holds whole elements, the load acts at their
 * centres). */
#include <stdlib.h>

#include "lt_util.h"

static double run_static(struct px_context *ctx, int nx, int n, int bending, enum px_precision p,
                         double *lateral) {
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_bc bc[2];
  struct px_lattice_params par = lt_steel();
  struct px_lattice_sel tip = lt_sel_face(PX_LATTICE_FACE_X_MAX);
  struct lt_engine en;
  struct lt_el *y;
  double value = NAN, dt, h = 1e-3;
  long steps;
  memset(bc, 0, sizeof bc);
  bc[0].sel = lt_sel_face(PX_LATTICE_FACE_X_MIN);
  bc[0].fix = 63;
  bc[1].sel = tip;
  bc[1].has_load = 1;
  bc[1].load[bending ? 2 : 0] = bending ? -50.0 : 5000.0;
  if (px_lattice_grid_box(ctx, h, nx, n, n, &g) != PX_STATUS_OK) return NAN;
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &m, &g, &par, bc, 2));
  y = (struct lt_el *)malloc(m.nalloc * sizeof *y);
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_cpu, PX_LATTICE_INTEGRATOR_LEAPFROG,
                                  p, PX_LATTICE_SCHEME_AUTO, 1, NULL, &en));
  dt = 0.9 * px_lattice_model_dt_limit(&m, PX_LATTICE_INTEGRATOR_LEAPFROG);
  steps = lt_relax(ctx, &m, &en, dt, &tip, bending ? 2 : 0, 2e-6, 200000, &value, y);
  PX_CHECK_MSG(steps > 0, "relaxation did not converge");
  if (lateral) *lateral = lt_mean_u(ctx, &m, y, &tip, 1);
  lt_engine_free(&en);
  free(y);
  px_lattice_model_free(ctx, &m);
  return value;
}

int main(void) {
  struct px_context *ctx;
  double E = LT_STEEL_E, h = 1e-3;
  int prec;
  double axial[2], bend[2];
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  for (prec = 0; prec < 2; ++prec) {
    enum px_precision p = prec ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
    /* axial bar 21 x 3 x 3: F = 5 kN */
    {
      int nx = 21, n = 3;
      double L = (nx - 1) * h, A = (n * h) * (n * h), lat = 0.0;
      double ref = 5000.0 * L / (E * A);
      axial[prec] = run_static(ctx, nx, n, 0, p, &lat);
      printf("axial bar (%s): delta = %.6e m, F L/(E A) = %.6e m, ratio %.5f, lateral %.2e m\n",
             prec ? "double" : "single", axial[prec], ref, axial[prec] / ref, lat);
      PX_CHECK_REL(axial[prec], ref, 0.005);
      PX_CHECK_NEAR(lat, 0.0, 1e-6 * ref);
    }
    /* cantilever 21 x 4 x 4 (L/H = 5): P = 50 N */
    {
      int nx = 21, n = 4;
      double L = (nx - 1) * h, H = n * h, I = H * H * H * H / 12.0, A = H * H, G = 0.5 * E;
      double P = 50.0, ref = P * L * L * L / (3.0 * E * I) + P * L / (5.0 / 6.0 * G * A);
      bend[prec] = -run_static(ctx, nx, n, 1, p, NULL);
      printf("cantilever L/H = 5 (%s): tip %.6e m, Timoshenko %.6e m, ratio %.5f\n",
             prec ? "double" : "single", bend[prec], ref, bend[prec] / ref);
      PX_CHECK_REL(bend[prec], ref, 0.01);
    }
  }
  PX_CHECK_REL(axial[0], axial[1], 0.002);
  PX_CHECK_REL(bend[0], bend[1], 0.002);
  px_context_free(ctx);
  return px_test_report("test_lattice_static");
}
