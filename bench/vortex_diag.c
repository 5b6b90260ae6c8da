/* Drag split of the impulsively started cylinder (D = 1, V = 1) for
 * convergence studies: per time window, the drag coefficient, its friction
 * part (wall vorticity), its vorticity-flux (pressure) part, and the two
 * terms of the wake's impulse balance: rho sum Gamma_i (k x V_i) (convective
 * drift, zero when the circulation sums to zero) and rho sum Gamma_i (k x W_i)
 * (diffusive drift, the friction implied by the model's momentum balance).
 *   vortex_diag Re panels dt gamma_max/(V L) eps_min/L t_end [window] [eps/L]
 * (t in D/V; the first column is T = t V / R at the window's centre). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "partix/backend.h"
#include "partix/context.h"
#include "solvers/vortex/vortex_core.h"

int main(int argc, char **argv) {
  double re = argc > 1 ? atof(argv[1]) : 550;
  int np = argc > 2 ? atoi(argv[2]) : 400;
  double dt = argc > 3 ? atof(argv[3]) : 0.005;
  double gm = argc > 4 ? atof(argv[4]) : 0.04;
  double em = argc > 5 ? atof(argv[5]) : 0.04;
  double tend = argc > 6 ? atof(argv[6]) : 1.0;
  double win = argc > 7 ? atof(argv[7]) : 0.1;
  double epsf = argc > 8 ? atof(argv[8]) : 0.5;
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  struct px_backend *be = NULL;
  if (px_backend_create(ctx, "cpu", 0, 1, &be) != PX_STATUS_OK) return 1;
  struct px_vortex_contour c;
  if (px_vortex_profile_circle(ctx, 0.5, (size_t)np, &c) != PX_STATUS_OK) return 1;
  double L = 3.14159265358979 / np;
  struct px_vortex_config cfg;
  px_vortex_config_defaults(&cfg);
  cfg.nu = 1.0 / re;
  cfg.vinf[0] = 1.0;
  cfg.vref = 1.0;
  cfg.dt = dt;
  cfg.eps = epsf * L;
  cfg.eps_col = L / 3;
  cfg.eps_min = em * L;
  cfg.gamma_max = gm * L;
  cfg.delta = 1e-4 * L;
  cfg.dist_far = 20;
  cfg.ref_length[0] = 1.0;
  struct px_vortex_engine *e = NULL;
  if (px_vortex_engine_create(ctx, be, &cfg, &c, 1, &e) != PX_STATUS_OK) {
    fprintf(stderr, "%s\n", px_context_message(ctx));
    return 1;
  }
  double acc[6] = {0};
  int na = 0;
  double tw = win;
  printf("# T=tV/R  Cd  Cd_fric  Cd_flux  Cd_convdrift  Cd_diffdrift  N\n");
  while (e->time < tend - 1e-9) {
    if (px_vortex_engine_step(e) != PX_STATUS_OK) {
      fprintf(stderr, "%s\n", px_context_message(ctx));
      return 1;
    }
    const struct px_vortex_loads *l = &e->loads[0];
    if (e->step == 1) continue;
    double q = 0.5;
    acc[0] += l->cx;
    acc[1] += l->fx_fric / q;
    acc[2] += (l->fx - l->fx_fric) / q;
    acc[3] += l->fx_conv / q;
    acc[4] += l->fx_diff / q;
    ++na;
    if (e->time >= tw - 1e-9) {
      printf("%.3f %.4f %.4f %.4f %.4f %.4f %zu\n", 2 * (e->time - 0.5 * win), acc[0] / na,
             acc[1] / na, acc[2] / na, acc[3] / na, acc[4] / na, e->w.n);
      fflush(stdout);
      for (int k = 0; k < 6; ++k) acc[k] = 0;
      na = 0;
      tw += win;
    }
  }
  px_vortex_engine_free(e);
  px_vortex_contour_free(ctx, &c);
  px_backend_free(be);
  px_context_free(ctx);
  return 0;
}
