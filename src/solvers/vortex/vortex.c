/* The `vortex` solver: 2D viscous flow around profiles by the vortex element
 * method with viscous vortex domains (spec vortex.md). This file is the glue
 * between a case and the engine (vortex_core.h): the case section, the
 * automatic parameters and the step; the bodies are built in vortex_bodies.c,
 * the outputs are in vortex_output.c, the checkpoints in vortex_checkpoint.c
 * (vortex_solver.h). */
#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/csv.h"
#include "partix/figure.h"
#include "partix/memory.h"
#include "partix/vtk.h"
#include "solvers/solver.h"
#include "solvers/summary.h"
#include "solvers/vortex/vortex_core.h"
#include "solvers/vortex/vortex_engine.h"
#include "solvers/vortex/vortex_report.h"
#include "solvers/vortex/vortex_profile.h"
#include "solvers/vortex/vortex_ranks.h"
#include "solvers/vortex/vortex_solver.h"

#define VX_PI 3.14159265358979323846

/* ------------------------------------------------------------------------- */
/* Case section */

static const char *const vx_starts[] = {"impulse", "linear", "cosine", NULL};
static const char *const vx_spacings[] = {"cosine", "uniform", NULL};
static const char *const vx_sheets[] = {"exact", "vortices", NULL};
static const char *const vx_newborns[] = {"vvd", "rayleigh", NULL};
static const char *const vx_schemes[] = {"euler", "rk2", NULL};
/* order = enum px_nbody_method's values */
static const char *const vx_methods[] = {"direct", "fmm", "auto", NULL};
static const char *const vx_frictions[] = {"drift", "wall", NULL};

#define VX_BODY_PLACEMENT                                                                    \
  PX_KEY_VECTOR("position", "where the profile's own origin goes [m]", PX_LEN(2, 2),         \
                PX_DEFAULT("[0, 0]")),                                                       \
      PX_KEY_REAL("scale", "scale factor of the profile's own coordinates", PX_GT(0),        \
                  PX_DEFAULT("1")),                                                          \
      PX_KEY_REAL("angle",                                                                   \
                  "rotation about the origin, clockwise [deg] (the angle of attack for a "   \
                  "free stream along +x)",                                                   \
                  PX_IN(-360, 360), PX_DEFAULT("0")),                                        \
      PX_KEY_REAL("reference_length",                                                        \
                  "length of the force coefficients [m] (0: the profile's largest extent)",  \
                  PX_GE(0), PX_DEFAULT("0")),                                                \
      PX_KEY_VECTOR("moment_center",                                                         \
                    "point of the moment in the profile's own coordinates, scaled, rotated " \
                    "and moved with the profile (the own origin goes to position)",          \
                    PX_LEN(2, 2), PX_DEFAULT("[0, 0]"))

/* at most PX_VORTEX_MAX_PANELS (80 GB of panel matrix); a case whose
 * estimated memory exceeds the machine's is refused (vortex_bodies.c) */
#define VX_PANELS_KEY                                                            \
  PX_KEY_INT("panels", "number of panels (a few hundred is usual)", PX_REQUIRED, \
             PX_GE(PX_VORTEX_MIN_PANELS), PX_LE(PX_VORTEX_MAX_PANELS))

static const struct px_schema vx_circle_keys[] = {
    PX_KEY_REAL("radius", "radius [m]", PX_REQUIRED, PX_GT(0)), VX_PANELS_KEY, VX_BODY_PLACEMENT,
    PX_KEY_END};
static const struct px_schema vx_ellipse_keys[] = {
    PX_KEY_REAL("a", "semi-axis along x [m]", PX_REQUIRED, PX_GT(0)),
    PX_KEY_REAL("b", "semi-axis along y [m]", PX_REQUIRED, PX_GT(0)), VX_PANELS_KEY,
    VX_BODY_PLACEMENT, PX_KEY_END};
static const struct px_schema vx_plate_keys[] = {
    PX_KEY_REAL("length", "overall length, rounded ends included [m]", PX_REQUIRED, PX_GT(0)),
    PX_KEY_REAL("thickness", "thickness = diameter of the rounded ends [m]", PX_REQUIRED, PX_GT(0)),
    VX_PANELS_KEY, VX_BODY_PLACEMENT, PX_KEY_END};
static const struct px_schema vx_naca_keys[] = {
    PX_KEY_STRING("digits",
                  "NACA 4-digit designation, e.g. \"0012\" (chord 1, leading edge "
                  "at the origin)",
                  PX_REQUIRED),
    VX_PANELS_KEY, VX_BODY_PLACEMENT, PX_KEY_END};
static const struct px_schema vx_selig_keys[] = {
    PX_KEY_STRING("file", "Selig .dat airfoil file (relative to the case file)", PX_REQUIRED,
                  PX_INPUT_FILE),
    VX_PANELS_KEY,
    PX_KEY_ENUM("spacing", vx_spacings, "re-panelling: clustered at the edges or uniform",
                PX_DEFAULT("cosine")),
    VX_BODY_PLACEMENT, PX_KEY_END};
static const struct px_schema vx_points_keys[] = {
    PX_KEY_STRING("file", "closed list of \"x y\" points (relative to the case file)",
                  PX_INPUT_FILE, PX_REQUIRED),
    PX_KEY_INT("panels", "re-sample to this many panels (0: the points as given)", PX_GE(0),
               PX_LE(PX_VORTEX_MAX_PANELS), PX_DEFAULT("0")),
    VX_BODY_PLACEMENT, PX_KEY_END};

static const struct px_schema vx_body_types[] = {
    PX_TYPE("circle", vx_circle_keys, "a circular cylinder"),
    PX_TYPE("ellipse", vx_ellipse_keys, "an elliptic cylinder"),
    PX_TYPE("plate", vx_plate_keys, "a flat plate with semicircular ends"),
    PX_TYPE("naca", vx_naca_keys, "a NACA 4-digit airfoil"),
    PX_TYPE("selig", vx_selig_keys, "an airfoil from a Selig .dat file"),
    PX_TYPE("points", vx_points_keys, "a polygon from a file of points"),
    PX_KEY_END};
static const struct px_schema vx_body =
    PX_KEY_VARIANT("body", vx_body_types, "a fixed profile", PX_WHAT("body"));

static const struct px_schema vx_field_keys[] = {
    PX_KEY_INT("every",
               "field output period [steps]: the grid is written with the wake snapshots "
               "(output.every) whose step this divides, and with the last state (0: with "
               "every snapshot)",
               PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_VECTOR("grid", "velocity and pressure on a grid over [xmin, xmax, ymin, ymax] [m]",
                  PX_LEN(4, 4)),
    PX_KEY_VECTOR("cells", "grid points along x and y", PX_LEN(2, 2), PX_IN(2, 4096),
                  PX_DEFAULT("[200, 100]")),
    PX_KEY_LIST("probes",
                &(const struct px_schema)PX_KEY_VECTOR("probe", "a point [x, y] [m]", PX_LEN(2, 2)),
                "points where velocity and pressure are written every log step", PX_LEN(0, 1000)),
    PX_KEY_END};

static const struct px_schema vx_picture_keys[] = {
    PX_KEY_VECTOR("view",
                  "shown region [xmin, xmax, ymin, ymax] [m] (default: the bodies, 0.75 "
                  "reference lengths upstream, 4 downstream, 1.25 across)",
                  PX_LEN(4, 4)),
    PX_KEY_INT("width", "picture width [pixels]", PX_IN(64, 8192), PX_DEFAULT("1600")),
    PX_KEY_INT("height", "picture height [pixels]", PX_IN(64, 8192), PX_DEFAULT("900")),
    PX_KEY_REAL("gamma_range",
                "colour range +-G of the circulation [m^2/s] (0: 1.5 times the median "
                "|Gamma| of each picture's vortices)",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_END};

static const struct px_schema vx_report_keys[] = {
    PX_KEY_REAL("from",
                "start of the time window of the averages, standard deviations and lift "
                "frequency in summary.json [s] (default: half the run's time so far)",
                PX_GE(0)),
    PX_KEY_REAL("to", "end of that window [s] (default: the run's time so far)", PX_GT(0)),
    PX_KEY_END};

static const struct px_schema vx_velocity_keys[] = {
    PX_KEY_ENUM("method", vx_methods,
                "how the wake's velocity sums are evaluated: direct pair sum, fast multipole "
                "method (cpu only), or auto (direct on opencl and for small wakes, fmm above)",
                PX_DEFAULT("auto")),
    PX_KEY_REAL("tolerance",
                "FMM accuracy: relative L2 error of the velocity sums (below 1e-5 the FMM sums "
                "in double also in single/mixed precision)",
                PX_IN(1e-12, 0.1), PX_DEFAULT("1e-6")),
    PX_KEY_END};

static enum px_status vx_check_section(struct px_case *c, const char *path) {
  char p[256];
  int start = 0;
  double T = 0.0, vinf[2] = {0, 0}, vref = 0.0;
  PX_TRY(px_case_get_enum(c, px_case_path_join(p, sizeof p, path, "start"), &start));
  PX_TRY(px_case_get_real(c, px_case_path_join(p, sizeof p, path, "ramp_time"), &T));
  if (start != 0 && !(T > 0.0))
    return px_case_fail(c, px_case_path_join(p, sizeof p, path, "ramp_time"),
                        "a %s start needs ramp_time > 0 (the time to reach full speed [s])",
                        vx_starts[start]);
  PX_TRY(px_case_get_vector(c, px_case_path_join(p, sizeof p, path, "v_inf"), vinf, 2));
  PX_TRY(px_case_get_real(c, px_case_path_join(p, sizeof p, path, "v_ref"), &vref));
  if (!(hypot(vinf[0], vinf[1]) > 0.0) && !(vref > 0.0))
    return px_case_fail(c, px_case_path_join(p, sizeof p, path, "v_inf"),
                        "with no free stream (v_inf = [0, 0]) give a reference speed v_ref > 0 "
                        "(the speed of the coefficients and of the diffusive cap)");
  return PX_STATUS_OK;
}

const struct px_schema px_solver_vortex_keys[] = {
    PX_KEY_REAL("rho", "fluid density [kg/m^3]", PX_GT(0), PX_DEFAULT("1")),
    PX_KEY_REAL("nu", "kinematic viscosity [m^2/s] (Re = V L / nu)", PX_REQUIRED, PX_GT(0)),
    PX_KEY_VECTOR("v_inf", "free-stream velocity [m/s]", PX_REQUIRED, PX_LEN(2, 2)),
    PX_KEY_ENUM("start", vx_starts, "how the free stream starts: at once, or ramped",
                PX_DEFAULT("impulse")),
    PX_KEY_REAL("ramp_time", "time to reach full speed for a linear/cosine start [s]", PX_GE(0),
                PX_DEFAULT("0")),
    PX_KEY_REAL("v_ref",
                "reference speed for coefficients and the diffusive cap [m/s] (0: |v_inf|)",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("eps", "core radius of the vortices [m] (0: half the mean panel length)", PX_GE(0),
                PX_DEFAULT("0")),
    PX_KEY_REAL("eps_col",
                "merge radius of close vortices [m] (0: a third of the mean panel "
                "length)",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("eps_col_opposite",
                "merge radius of close vortices of opposite signs [m] (0: "
                "2 eps_col, as VM2D)",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("eps_min",
                "smallest VVD domain radius eps* [m] (0: 0.05 mean panel "
                "length, at least 0.5 sqrt(nu dt))",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("gamma_max",
                "largest circulation of a vortex after a merge, and of a newborn "
                "one [m^2/s] (0: 0.05 v_ref x mean panel length)",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("delta",
                "distance of newborn vortices from the wall [m] (0: 1e-4 mean panel "
                "length)",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_INT("vortex_per_panel", "vortices born on each panel per step (at least)", PX_IN(1, 64),
               PX_DEFAULT("1")),
    PX_KEY_REAL("dist_far",
                "vortices farther than this from the bodies are dropped [m] (0: 20 "
                "reference lengths)",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("cutoff", "VVD neighbourhood radius in units of eps*", PX_IN(3, 20),
                PX_DEFAULT("8")),
    PX_KEY_ENUM("sheet", vx_sheets,
                "how vortices near the wall feel the newborn sheet: exact panel integral or "
                "smoothed vortices",
                PX_DEFAULT("exact")),
    PX_KEY_ENUM("scheme", vx_schemes,
                "the move: explicit Euler, or Heun's second-order method with a second "
                "sheet solved for the predicted wake (rk2; one more generation, convective "
                "and diffusive block per step; 1.8-2x the cost of euler, which needs a 4-8x "
                "smaller dt where the wake rolls up: docs/vortex.md)",
                PX_DEFAULT("rk2")),
    PX_KEY_ENUM("newborn", vx_newborns,
                "diffusive velocity of a newborn vortex in its first step: its VVD velocity "
                "(vvd, as VM2D), or the mean drift of a sheet diffusing from a flat wall, "
                "2 sqrt(nu / (pi dt)) off the wall (rayleigh; docs/vortex.md)",
                PX_DEFAULT("vvd")),
    PX_KEY_ENUM("vvd_moments", px_vortex_moment_names,
                "the VVD's particle term for vortices with no panel within reach: as "
                "published (none, as VM2D); with the length M1 / (2 M0) of the vortex's own "
                "neighbours (wake: removes the ~10% excess diffusion of lattice-like vortex "
                "sets); or from the Gaussian-weighted mean and covariance of its same-sign "
                "neighbours (covariance: exact for Gaussian vorticity at any resolution); "
                "docs/notes/vortex.md, \"The VVD's diffusion rate\"",
                PX_DEFAULT("wake")),
    PX_KEY_MAP("velocity", vx_velocity_keys,
               "convective velocity sums: method and accuracy (docs/vortex.md)"),
    PX_KEY_ENUM("friction", vx_frictions,
                "wall friction: drift = rho sum Gamma (k x W) of the vortices' diffusive "
                "velocities (the model's impulse balance; short wakes); wall = rho nu "
                "omega_wall from the VVD estimate of the wall vorticity (VM2D; long wakes, "
                "where the drift sum picks up the far wake: docs/vortex.md)",
                PX_DEFAULT("drift")),
    PX_KEY_LIST("bodies", &vx_body, "the fixed profiles", PX_REQUIRED, PX_LEN(1, 64)),
    PX_KEY_MAP("fields", vx_field_keys, "velocity and pressure output on request"),
    PX_KEY_MAP("picture", vx_picture_keys, "PNG snapshots of the wake"),
    PX_KEY_MAP("report", vx_report_keys, "the time window of what summary.json reports"),
    {.name = NULL, .check = vx_check_section}};

/* ------------------------------------------------------------------------- */
/* State */

static enum px_status vx_get_real(struct vx_state *s, const char *key, double *v) {
  char p[128];
  snprintf(p, sizeof p, "vortex.%s", key);
  return px_case_get_real(s->c, p, v);
}

/* The time step against the case's scales (docs/vortex.md, "The time
 * step"). A vortex born on a panel travels about V dt in its first
 * step (V = max(v_ref, |v_inf|)), while the generation, the wall's exact near
 * field and the non-penetration test see the wake at the ends of the step:
 * the loads drift with that travel in units of Ls = min(L, 2 eps), L the mean
 * panel length and eps the core radius (which smooths the near field).
 * Measured (docs/notes/vortex.md, "The time step"): cylinder at Re = 200,
 * mean C_x over t = 1.5..2.5, within 1% up to V dt = 2.5 Ls with rk2 (+7%
 * with Euler), +5% (+14%) at 5 Ls, +15% (+23%) at 10 Ls; NACA 0012 at 5 deg
 * with Euler, mean C_y over t = 3..4, -3% / -6% / -12% / -28% at 2 / 4 / 10
 * / 20 Ls. Above 2 Ls a warning, above 10 Ls a refusal. A ramp over fewer
 * than 5 steps is an impulsive start: a warning. */
static enum px_status vx_check_dt(struct vx_state *s, const struct px_vortex_config *cfg,
                                  double L) {
  const double V = fmax(cfg->vref, hypot(cfg->vinf[0], cfg->vinf[1]));
  const double Ls = fmin(L, 2.0 * cfg->eps), travel = V * cfg->dt / Ls;
  if (travel > 10.0)
    return px_case_fail(
        s->c, "time.dt",
        "dt = %.4g s is too long for this case: a vortex travels V dt = %.3g m per step, %.3g "
        "times the wall's length scale min(L, 2 eps) = %.3g m (L = %.3g m the mean panel "
        "length, eps = %.3g m the core radius, V = %.3g m/s), so the wall layer is not resolved "
        "in time and the loads are off by 15%% or more. Use dt <= %.4g s (one length scale "
        "per step; without time.dt the solver takes %.4g s)",
        cfg->dt, V * cfg->dt, travel, Ls, L, cfg->eps, V, Ls / V, 0.5 * L / cfg->vref);
  if (travel > 2.0)
    px_log(s->ctx, PX_LOG_LEVEL_WARN,
           "time.dt = %.4g s: a vortex travels %.3g times the wall's length scale min(L, 2 eps) "
           "= %.3g m per step (V = %.3g m/s); beyond 2 the loads drift by several per cent "
           "(docs/vortex.md, \"The time step\"); dt <= %.4g s is recommended",
           cfg->dt, travel, Ls, V, Ls / V);
  if (cfg->ramp != PX_VORTEX_RAMP_IMPULSE && cfg->ramp_time > 0.0 && cfg->ramp_time < 5.0 * cfg->dt)
    px_log(s->ctx, PX_LOG_LEVEL_WARN,
           "vortex.ramp_time = %.4g s is %.3g steps of dt = %.4g s: the start is as abrupt as an "
           "impulsive one; ramp_time >= 5 dt = %.4g s resolves the ramp",
           cfg->ramp_time, cfg->ramp_time / cfg->dt, cfg->dt, 5.0 * cfg->dt);
  return PX_STATUS_OK;
}

/* Record the values chosen for the keys the case leaves to the solver (0):
 * `given` is the configuration as the case gave it, L the mean panel
 * length [m]. */
static void vx_note_automatic(struct vx_state *s, const struct px_vortex_config *given, double L) {
  const struct px_vortex_config *cfg = &s->e->cfg;
  struct px_sim *sim = s->sim;
  double v = 0.0;
  if (vx_get_real(s, "v_ref", &v) == PX_STATUS_OK && !(v > 0.0))
    px_sim_note_auto(sim, "vortex.v_ref", "%.6g m/s (|v_inf|)", cfg->vref);
  if (!(given->eps > 0.0))
    px_sim_note_auto(sim, "vortex.eps", "%.6g m (L/2, L = %.6g m the mean panel length)", cfg->eps,
                     L);
  if (!(given->eps_col > 0.0))
    px_sim_note_auto(sim, "vortex.eps_col", "%.6g m (L/3)", cfg->eps_col);
  if (!(given->eps_col_opposite > 0.0))
    px_sim_note_auto(sim, "vortex.eps_col_opposite", "%.6g m (2 eps_col)", cfg->eps_col_opposite);
  if (!(given->eps_min > 0.0))
    px_sim_note_auto(sim, "vortex.eps_min",
                     "%.6g m (0.05 L = %.6g m, at least 0.5 sqrt(nu dt) "
                     "= %.6g m)",
                     cfg->eps_min, 0.05 * L, 0.5 * sqrt(cfg->nu * cfg->dt));
  if (!(given->gamma_max > 0.0))
    px_sim_note_auto(sim, "vortex.gamma_max", "%.6g m^2/s (0.05 v_ref L)", cfg->gamma_max);
  if (!(given->delta > 0.0)) px_sim_note_auto(sim, "vortex.delta", "%.6g m (1e-4 L)", cfg->delta);
  if (!(given->dist_far > 0.0 && given->dist_far < 1e29))
    px_sim_note_auto(sim, "vortex.dist_far", "%.6g m (20 reference lengths)", cfg->dist_far);
  struct px_vortex_caps caps;
  if (given->method == PX_NBODY_METHOD_AUTO &&
      px_vortex_engine_caps(px_sim_backend(sim), &caps) == PX_STATUS_OK)
    px_sim_note_auto(sim, "vortex.velocity.method", "%s",
                     caps.fmm ? "auto: per sum, the direct sum below about 4e6 source x target "
                                "pairs (~2000 vortices), the FMM above"
                              : "auto: the direct sum on the device");
  for (size_t b = 0; b < s->e->nbody; ++b)
    if (!(given->ref_length[b] > 0.0)) {
      char key[64];
      snprintf(key, sizeof key, "vortex.bodies[%zu].reference_length", b);
      px_sim_note_auto(sim, key, "%.6g m (the profile's largest extent)", cfg->ref_length[b]);
    }
}

static void vx_destroy(void *state) {
  struct vx_state *s = state;
  if (!s) return;
  px_vortex_engine_free(s->e);
  px_vtk_free(s->vtk);
  px_vtk_series_close(s->pvd_wake);
  px_vtk_series_close(s->pvd_field);
  px_csv_close(s->csv_loads);
  px_csv_close(s->csv_probes);
  px_figure_free(s->fig);
  px_mem_free(s->ctx, s->probe);
  px_mem_free(s->ctx, s);
}

/* The engine's configuration as the case sets it (0 where the case leaves a
 * value to vx_create's automatic choice). */
static enum px_status vx_read_config(struct vx_state *s, struct px_vortex_config *cfg) {
  struct px_case *c = s->c;
  /* the section's cross-key checks here too: the solver sections are plugged
   * into the root schema as plain maps (registry.c), so the check of the
   * keys' terminator is not run by the case validation */
  PX_TRY(vx_check_section(c, "vortex"));
  px_vortex_config_defaults(cfg);
  int start = 0, sheet = 0;
  long vpp = 1;
  PX_TRY(vx_get_real(s, "rho", &cfg->rho));
  PX_TRY(vx_get_real(s, "nu", &cfg->nu));
  PX_TRY(px_case_get_vector(c, "vortex.v_inf", cfg->vinf, 2));
  PX_TRY(px_case_get_enum(c, "vortex.start", &start));
  cfg->ramp = start == 0 ? PX_VORTEX_RAMP_IMPULSE
                         : (start == 1 ? PX_VORTEX_RAMP_LINEAR : PX_VORTEX_RAMP_COSINE);
  PX_TRY(vx_get_real(s, "ramp_time", &cfg->ramp_time));
  PX_TRY(vx_get_real(s, "v_ref", &cfg->vref));
  if (!(cfg->vref > 0.0)) cfg->vref = hypot(cfg->vinf[0], cfg->vinf[1]);
  PX_TRY(vx_get_real(s, "eps", &cfg->eps));
  PX_TRY(vx_get_real(s, "eps_col", &cfg->eps_col));
  PX_TRY(vx_get_real(s, "eps_col_opposite", &cfg->eps_col_opposite));
  PX_TRY(vx_get_real(s, "eps_min", &cfg->eps_min));
  PX_TRY(vx_get_real(s, "gamma_max", &cfg->gamma_max));
  PX_TRY(vx_get_real(s, "delta", &cfg->delta));
  PX_TRY(px_case_get_int(c, "vortex.vortex_per_panel", &vpp));
  cfg->vortex_per_panel = (int)vpp;
  PX_TRY(vx_get_real(s, "dist_far", &cfg->dist_far));
  PX_TRY(vx_get_real(s, "cutoff", &cfg->cutoff));
  PX_TRY(px_case_get_enum(c, "vortex.sheet", &sheet));
  cfg->sheet_exact = sheet == 0;
  int newborn = 0, scheme = 0;
  PX_TRY(px_case_get_enum(c, "vortex.newborn", &newborn));
  cfg->newborn_rayleigh = newborn == 1;
  PX_TRY(px_case_get_enum(c, "vortex.scheme", &scheme));
  cfg->rk2 = scheme == 1;
  int moments = 0;
  PX_TRY(px_case_get_enum(c, "vortex.vvd_moments", &moments));
  cfg->vvd_moments = moments;
  int method = 2;
  PX_TRY(px_case_get_enum(c, "vortex.velocity.method", &method));
  cfg->method = (enum px_nbody_method)method;
  PX_TRY(vx_get_real(s, "velocity.tolerance", &cfg->tolerance));
  int friction = 0;
  PX_TRY(px_case_get_enum(c, "vortex.friction", &friction));
  cfg->friction_wall = friction == 1;
  return PX_STATUS_OK;
}

/* The outputs' settings: fields and probes, the picture (its view, when the
 * case leaves it, around the bodies), the summary's window, the title. */
static enum px_status vx_read_outputs(struct vx_state *s) {
  struct px_sim *sim = s->sim;
  struct px_context *ctx = s->ctx;
  struct px_case *c = s->c;
  enum px_status st = PX_STATUS_OK;
  PX_TRY(px_case_get_int(c, "vortex.fields.every", &s->field_every));
  s->has_grid = px_case_has(c, "vortex.fields.grid");
  if (s->has_grid) {
    double cells[2];
    PX_TRY(px_case_get_vector(c, "vortex.fields.grid", s->grid, 4));
    PX_TRY(px_case_get_vector(c, "vortex.fields.cells", cells, 2));
    s->cells[0] = (size_t)cells[0];
    s->cells[1] = (size_t)cells[1];
    if (!(s->grid[1] > s->grid[0] && s->grid[3] > s->grid[2])) {
      st = px_case_fail(c, "vortex.fields.grid", "need xmin < xmax and ymin < ymax");
      return st;
    }
  }
  PX_TRY(px_case_count(c, "vortex.fields.probes", &s->nprobe));
  if (s->nprobe) {
    s->probe = px_mem_alloc(ctx, "vortex.solver", 2 * s->nprobe * sizeof(double));
    if (!s->probe) {
      st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
      return st;
    }
    for (size_t i = 0; i < s->nprobe; ++i) {
      char p[64];
      snprintf(p, sizeof p, "vortex.fields.probes[%zu]", i);
      PX_TRY(px_case_get_vector(c, p, s->probe + 2 * i, 2));
      /* inside a body the model's fluid is at rest and the wake's field
       * meaningless (the grid writes 0 and NaN there): a probe there is a
       * mistake in the case */
      const double x = s->probe[2 * i], y = s->probe[2 * i + 1];
      for (size_t b = 0; b < s->e->nbody; ++b)
        if (px_vortex_profile_contains(&s->e->body[b], x, y))
          return px_case_fail(c, p,
                              "the probe (%g, %g) m lies inside body %zu (vortex.bodies[%zu]), "
                              "where the fluid is at rest; probes must lie in the flow",
                              x, y, b, b);
    }
  }
  long w = 1600, h = 900;
  PX_TRY(px_case_get_int(c, "vortex.picture.width", &w));
  PX_TRY(px_case_get_int(c, "vortex.picture.height", &h));
  s->pic_w = (int)w;
  s->pic_h = (int)h;
  if (px_case_has(c, "vortex.picture.view")) {
    PX_TRY(px_case_get_vector(c, "vortex.picture.view", s->view, 4));
    if (!(s->view[1] > s->view[0] && s->view[3] > s->view[2])) {
      st = px_case_fail(c, "vortex.picture.view", "need xmin < xmax and ymin < ymax");
      return st;
    }
  } else {
    /* the bodies with room for the near wake: 0.75 reference lengths
     * upstream, 4 downstream, 1.25 above and below the bodies' middle (in
     * x and y: a free stream along +x) */
    const struct px_vortex_engine *e = s->e;
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY, span = 0.0;
    for (size_t b = 0; b < e->nbody; ++b) {
      x0 = fmin(x0, e->pan.bxmin[b]);
      x1 = fmax(x1, e->pan.bxmax[b]);
      y0 = fmin(y0, e->pan.bymin[b]);
      y1 = fmax(y1, e->pan.bymax[b]);
      span = fmax(span, e->cfg.ref_length[b]);
    }
    s->view[0] = x0 - 0.75 * span;
    s->view[1] = x1 + 4.0 * span;
    s->view[2] = 0.5 * (y0 + y1) - 1.25 * span;
    s->view[3] = 0.5 * (y0 + y1) + 1.25 * span;
    px_sim_note_auto(sim, "vortex.picture.view",
                     "[%.6g, %.6g, %.6g, %.6g] m (the bodies, 0.75 "
                     "reference lengths upstream, 4 downstream, 1.25 across)",
                     s->view[0], s->view[1], s->view[2], s->view[3]);
  }
  PX_TRY(px_case_get_real(c, "vortex.picture.gamma_range", &s->gamma_range));
  if (!(s->gamma_range > 0.0))
    px_sim_note_auto(sim, "vortex.picture.gamma_range",
                     "1.5 times the median |Gamma| of each picture's vortices (gamma_max = "
                     "%.6g m^2/s without vortices)",
                     s->e->cfg.gamma_max);
  s->report_from = s->report_to = -1.0;
  if (px_case_has(c, "vortex.report.from"))
    PX_TRY(px_case_get_real(c, "vortex.report.from", &s->report_from));
  if (px_case_has(c, "vortex.report.to"))
    PX_TRY(px_case_get_real(c, "vortex.report.to", &s->report_to));
  if (s->report_from >= 0.0 && s->report_to >= 0.0 && !(s->report_to > s->report_from)) {
    st = px_case_fail(c, "vortex.report.to", "the window's end %g s is not after its start %g s",
                      s->report_to, s->report_from);
    return st;
  }
  if (px_case_has(c, "title")) PX_TRY(px_case_get_string(c, "title", &s->title));
  return PX_STATUS_OK;
}

static enum px_status vx_create(struct px_sim *sim, void **state) {
  struct px_context *ctx = px_sim_context(sim);
  struct vx_state *s = px_mem_calloc(ctx, "vortex.solver", 1, sizeof *s);
  if (!s) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
  *state = s;
  s->sim = sim;
  s->ctx = ctx;
  s->c = (struct px_case *)px_sim_case(sim);
  struct px_case *c = s->c;
  struct px_vortex_config cfg;
  PX_TRY(vx_read_config(s, &cfg));
  /* bodies */
  size_t nb = 0;
  struct px_vortex_contour body[PX_VORTEX_MAX_BODIES];
  memset(body, 0, sizeof body);
  PX_TRY(px_vortex_bodies_build(s, &cfg, body, &nb));
  enum px_status st = PX_STATUS_OK;
  /* automatic numerical parameters from the mean panel length (each one the
   * case leaves at 0 is recorded: run.log, summary.json "automatic") */
  double L = px_vortex_mean_panel_length(body, nb);
  const struct px_vortex_config given = cfg;
  /* the bodies' extent D [m], the largest side of their boxes: the scale a
   * core radius or one step's diffusion length must stay under */
  double D = 0.0;
  for (size_t i = 0; i < nb; ++i) {
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (size_t k = 0; k < body[i].n; ++k) {
      x0 = fmin(x0, body[i].x[k]);
      x1 = fmax(x1, body[i].x[k]);
      y0 = fmin(y0, body[i].y[k]);
      y1 = fmax(y1, body[i].y[k]);
    }
    D = fmax(D, fmax(x1 - x0, y1 - y0));
  }
  /* a core wider than the bodies smooths their whole wall layer (and the
   * pair sums need eps^2 a normal double): the default is L / 2 */
  if (cfg.eps > D) {
    st = px_case_fail(c, "vortex.eps",
                      "eps = %g m, the vortices' core radius, is wider than the bodies' extent "
                      "%g m: it would smooth away the whole wall layer; eps must be at most the "
                      "bodies' extent (0: half the mean panel length, %g m)",
                      cfg.eps, D, 0.5 * L);
    goto done;
  }
  if (!(cfg.eps > 0.0)) cfg.eps = 0.5 * L;
  if (!(cfg.eps_col > 0.0)) cfg.eps_col = L / 3.0;
  if (!(cfg.gamma_max > 0.0)) cfg.gamma_max = 0.05 * cfg.vref * L;
  if (!(cfg.delta > 0.0)) cfg.delta = 1e-4 * L;
  if (!(cfg.dist_far > 0.0)) cfg.dist_far = 1e30; /* set from the bodies' size below */
  /* time step: the case's, or half a panel length per reference speed */
  if (px_case_has(c, "time.dt")) {
    st = px_case_get_real(c, "time.dt", &cfg.dt);
    if (st == PX_STATUS_OK) st = vx_check_dt(s, &cfg, L);
    if (st != PX_STATUS_OK) goto done;
  } else {
    cfg.dt = 0.5 * L / cfg.vref;
  }
  /* one step's diffusion length sqrt(nu dt) beyond the bodies' extent: the
   * wall layer grows past the whole body in one step and the VVD's domains
   * (at least 0.5 sqrt(nu dt) by default) are wider than the bodies, so
   * nothing near the wall is resolved (nu = 1e308 ran as if inviscid) */
  if (!(sqrt(cfg.nu * cfg.dt) <= D)) {
    st = px_case_fail(c, "vortex.nu",
                      "nu = %g m^2/s diffuses sqrt(nu dt) = %g m in one step of dt = %g s, more "
                      "than the bodies' extent %g m (Re = v_ref D / nu = %.3g): the wall layer "
                      "is not resolved; the vortex method needs nu <= D^2 / dt = %.3g m^2/s at "
                      "this step (or a shorter time.dt)",
                      cfg.nu, sqrt(cfg.nu * cfg.dt), cfg.dt, D, cfg.vref * D / cfg.nu,
                      D * D / cfg.dt);
    goto done;
  }
  /* eps_min 0: the engine's default (px_vortex_eps_min_default) */
  struct px_backend *be = px_sim_backend(sim);
  cfg.threads = px_backend_threads(be);
  /* a count the user fixed is kept; left to partix, the host's is tuned */
  cfg.tune = px_backend_threads_auto(be) && px_backend_host_memory(be);
  cfg.precision = px_sim_precision(sim);
  st = px_backend_require(
      be, cfg.precision == PX_PRECISION_DOUBLE ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE);
  if (st != PX_STATUS_OK) goto done;
  /* what the backend's engine cannot compute is refused here, at its key */
  struct px_vortex_caps caps;
  st = px_vortex_engine_caps(be, &caps);
  if (st == PX_STATUS_OK) st = px_vortex_ranks_check(c, ctx, caps.ranks, px_backend_name(be));
  if (st != PX_STATUS_OK) goto done;
  if (cfg.method == PX_NBODY_METHOD_FMM && !caps.fmm) {
    st = px_case_fail(c, "vortex.velocity.method",
                      "the fast multipole method runs on the cpu backend only, not on '%s' "
                      "(there the direct sum is the fast path); use method direct or auto",
                      px_backend_name(be));
    goto done;
  }
  st = px_vortex_engine_create(ctx, be, &cfg, body, nb, &s->e);
  if (st != PX_STATUS_OK) goto done;
  if (!(s->e->cfg.dist_far > 0.0 && s->e->cfg.dist_far < 1e29)) {
    double span = 0.0;
    for (size_t i = 0; i < nb; ++i) span = fmax(span, s->e->cfg.ref_length[i]);
    s->e->cfg.dist_far = 20.0 * span;
  }
  vx_note_automatic(s, &given, L);
  st = vx_read_outputs(s);
done:
  for (size_t i = 0; i < nb; ++i) px_vortex_contour_free(ctx, &body[i]);
  return st;
}

static enum px_status vx_time_step(void *state, double *dt) {
  struct vx_state *s = state;
  *dt = s->e->cfg.dt;
  return PX_STATUS_OK;
}

static enum px_status vx_step(void *state, long step, double t, double dt) {
  struct vx_state *s = state;
  (void)t;
  s->e->cfg.dt = dt;
  s->e->step = step;
  s->e->time = (double)step * dt;
  PX_TRY(px_vortex_engine_step(s->e));
  if (step >= 100)
    for (size_t b = 0; b < s->e->pan.nbody; ++b) {
      s->fric_drift += s->e->loads[b].fx_diff;
      s->fric_wall += s->e->loads[b].fx_wall;
      s->fric_n += b == 0;
    }
  return PX_STATUS_OK;
}

static long vx_count(const void *state) {
  const struct vx_state *s = state;
  return (long)s->e->w.n;
}

static const char *const vx_resume_keys[] = {"vortex.picture",      "vortex.report",
                                             "vortex.fields.every", "vortex.fields.grid",
                                             "vortex.fields.cells", NULL};

const struct px_solver_i px_solver_vortex = {
    .name = "vortex",
    .summary = "2D viscous flow around profiles, vortex element method (viscous vortex domains)",
    .create = vx_create,
    .destroy = vx_destroy,
    .time_step = vx_time_step,
    .step = vx_step,
    .snapshot = px_vortex_output_snapshot,
    .series = px_vortex_output_series,
    .picture = px_vortex_output_picture,
    .finish = px_vortex_output_finish,
    .save = px_vortex_checkpoint_save,
    .load = px_vortex_checkpoint_load,
    .count = vx_count,
    .report = px_vortex_output_report,
    .results = px_vortex_results,
    .resume_keys = vx_resume_keys,
    .ranks = 1, /* the wake replicated, its sums split (vortex_ranks.h): gather NULL */
};
