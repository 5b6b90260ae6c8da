/* Loads of the vortex engine against analytic values, on the impulsively
 * started circular cylinder (D = 1, V = 1, Re = 550, 400 panels):
 *  - the first step's flux (pressure) force is the impulsive pressure: its
 *    impulse F dt is the sheet's vortex impulse 2 pi rho R^2 V (added mass
 *    pi rho R^2 V plus the pressure-gradient force on the displaced fluid);
 *  - the convective drift adds nothing to the vortex impulse
 *    (sum Gamma_i V_i = 0 when the total circulation vanishes; below 1e-3
 *    of the drag with float pair sums);
 *  - the friction is the impulse balance's diffusive drift
 *    rho sum Gamma_i (k x W_i) (the default); over T = tV/R = 0.1..0.2 and
 *    0.2..0.3 it follows the Rayleigh layer, C_Df = 2 sqrt(pi / (Re t))
 *    (Bar-Lev & Yang 1975, leading order) within 6% (measured +3.9% and
 *    +3.6%), and the total drag follows Koumoutsakos & Leonard (1995) within
 *    5% (measured +3.3% and +1.5%);
 *  - the wall-vorticity estimate of the friction lies above it by less than
 *    20% (measured 17.7% and 15.6%; on the Blasius plate 31%, docs/notes/vortex.md).
 * The floor of eps* is the default 0.5 sqrt(nu dt), with which the drag
 * converges as dt is refined (C_D at T = 0.15: 1.341 / 1.237 / 1.195 at dt =
 * 0.005 / 0.0025 / 0.00125, KL 1.157); until 2026-11-26 the test ran at dt =
 * 0.005 with the floor 0.04 L (nu dt / eps_min^2 = 92), which landed near KL
 * (-4.5%) but does not converge as gamma_max is refined (docs/notes/vortex.md, "The
 * gamma_max jump"). */
#include <math.h>
#include <string.h>

#include "px_test.h"
#include "solvers/vortex/vortex_core.h"

#define PI 3.14159265358979323846

/* Koumoutsakos & Leonard 1995, Re = 550, digitised (T = tV/R, C_D). */
static double kl550(double T) {
  static const double t[] = {0.14031, 0.18055, 0.22090, 0.27781, 0.34298, 0.44930};
  static const double c[] = {1.18352, 1.07127, 0.97449, 0.89316, 0.81955, 0.75361};
  for (int i = 0; i < 5; ++i)
    if (T <= t[i + 1]) return c[i] + (c[i + 1] - c[i]) * (T - t[i]) / (t[i + 1] - t[i]);
  return c[5];
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  struct px_backend *be = NULL;
  PX_CHECK_OK(ctx, px_backend_create(ctx, "cpu", 0, 2, &be));
  struct px_vortex_contour c;
  const int np = 400;
  const double re = 550.0, R = 0.5, L = PI * 2 * R / np;
  PX_CHECK_OK(ctx, px_vortex_profile_circle(ctx, R, (size_t)np, &c));
  struct px_vortex_config cfg;
  px_vortex_config_defaults(&cfg);
  cfg.nu = 1.0 / re;
  cfg.vinf[0] = 1.0;
  cfg.vref = 1.0;
  cfg.dt = 0.00125;
  cfg.eps = 0.5 * L;
  cfg.eps_col = L / 3;
  cfg.eps_min = 0.0; /* the default: 0.5 sqrt(nu dt) */
  cfg.gamma_max = 0.04 * L;
  cfg.delta = 1e-4 * L;
  cfg.dist_far = 20;
  cfg.threads = 2;
  cfg.ref_length[0] = 1.0;
  struct px_vortex_engine *e = NULL;
  PX_CHECK_OK(ctx, px_vortex_engine_create(ctx, be, &cfg, &c, 1, &e));
  if (!e) return 1;

  /* step 1: the impulsive start */
  PX_CHECK_OK(ctx, px_vortex_engine_step(e));
  const struct px_vortex_loads *ld = &e->loads[0];
  double impulse = 2.0 * PI * R * R;              /* rho = V = 1 */
  double fp_dt = (ld->fx - ld->fx_fric) * cfg.dt; /* the flux (pressure) part */
  printf("step 1: (F - F_friction) dt = %.6f (2 pi R^2 = %.6f), friction %.3g, Fy dt = %.2g\n",
         fp_dt, impulse, ld->fx_fric, ld->fy * cfg.dt);
  PX_CHECK_REL(fp_dt, impulse, 2e-3);
  PX_CHECK_NEAR(ld->fy * cfg.dt, 0.0, 1e-6);

  /* windows of T = 0.1 wide: friction, drift term, total */
  double sf = 0.0, sd = 0.0, sc = 0.0;
  int cnt = 0, win = 0;
  double tw = 0.1;
  while (e->time < 0.15 - 1e-9) {
    PX_CHECK_OK(ctx, px_vortex_engine_step(e));
    /* float pair sums and the exact sheet near the wall break the pairwise
     * antisymmetry slightly: |sum| stays below 4e-4 of the drag here */
    PX_CHECK_MSG(fabs(ld->fx_conv) < 1e-3 * fabs(ld->fx), "step %ld: convective drift %g, drag %g",
                 e->step, ld->fx_conv, ld->fx);
    PX_CHECK_NEAR(ld->fx_fric, ld->fx_diff, 1e-12 * fabs(ld->fx));
    sf += ld->fx_wall / 0.5;
    sd += ld->fx_diff / 0.5;
    sc += ld->cx;
    ++cnt;
    if (e->time >= 0.5 * tw - 1e-9) {
      double T = tw - 0.05, t = 0.5 * T;
      double fr = sf / cnt, dr = sd / cnt, cd = sc / cnt;
      double rayleigh = 2.0 * sqrt(PI / (re * t));
      printf(
          "T = %.2f: C_D %.4f (KL %.4f), wall-vorticity friction %.4f, drift friction %.4f, "
          "Rayleigh %.4f, %zu vortices\n",
          T, cd, kl550(T), fr, dr, rayleigh, e->w.n);
      if (win >= 1) { /* the first window holds the start's transient */
        PX_CHECK_REL(dr, rayleigh, 0.06);
        PX_CHECK_MSG(fr > dr && fr < 1.2 * dr,
                     "T = %.2f: wall-vorticity friction %g not within 0..20%% above the drift %g",
                     T, fr, dr);
        PX_CHECK_REL(cd, kl550(T), 0.05);
      }
      sf = sd = sc = 0.0;
      cnt = 0;
      ++win;
      tw += 0.1;
    }
  }
  PX_CHECK(win == 3);
  px_vortex_engine_free(e);
  px_vortex_contour_free(ctx, &c);
  px_backend_free(be);
  px_context_free(ctx);
  return px_test_report("test_vortex_loads");
}
