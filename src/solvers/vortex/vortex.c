/* The `vortex` solver: 2D viscous flow around profiles by the vortex element
 * method with viscous vortex domains (spec vortex.md). This file is the glue
 * between a case and the engine (vortex_core.h): the case section, outputs
 * (wake .vtp, loads CSV, fields .vti and probes CSV, PNG pictures and the
 * load plot) and checkpoints. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/csv.h"
#include "partix/figure.h"
#include "partix/memory.h"
#include "partix/vtk.h"
#include "solvers/solver.h"
#include "solvers/vortex/vortex_core.h"

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

#define VX_BODY_PLACEMENT                                                                   \
  PX_KEY_VECTOR("position", "where the profile's own origin goes [m]", PX_LEN(2, 2),         \
                PX_DEFAULT("[0, 0]")),                                                      \
      PX_KEY_REAL("scale", "scale factor of the profile's own coordinates", PX_GT(0),         \
                  PX_DEFAULT("1")),                                                         \
      PX_KEY_REAL("angle",                                                                  \
                  "rotation about the origin, clockwise [deg] (the angle of attack for a "  \
                  "free stream along +x)",                                                  \
                  PX_IN(-360, 360), PX_DEFAULT("0")),                                       \
      PX_KEY_REAL("reference_length",                                                       \
                  "length of the force coefficients [m] (0: the profile's largest extent)", \
                  PX_GE(0), PX_DEFAULT("0")),                                               \
      PX_KEY_VECTOR("moment_center", "point of the moment [m] (default: position)",         \
                    PX_LEN(2, 2))

#define VX_PANELS_KEY                                                                       \
  PX_KEY_INT("panels", "number of panels (a few hundred is usual)", PX_REQUIRED,            \
             PX_GE(PX_VORTEX_MIN_PANELS), PX_LE(1000000))

static const struct px_schema vx_circle_keys[] = {
    PX_KEY_REAL("radius", "radius [m]", PX_REQUIRED, PX_GT(0)), VX_PANELS_KEY,
    VX_BODY_PLACEMENT, PX_KEY_END};
static const struct px_schema vx_ellipse_keys[] = {
    PX_KEY_REAL("a", "semi-axis along x [m]", PX_REQUIRED, PX_GT(0)),
    PX_KEY_REAL("b", "semi-axis along y [m]", PX_REQUIRED, PX_GT(0)), VX_PANELS_KEY,
    VX_BODY_PLACEMENT, PX_KEY_END};
static const struct px_schema vx_plate_keys[] = {
    PX_KEY_REAL("length", "overall length, rounded ends included [m]", PX_REQUIRED, PX_GT(0)),
    PX_KEY_REAL("thickness", "thickness = diameter of the rounded ends [m]", PX_REQUIRED,
                PX_GT(0)),
    VX_PANELS_KEY, VX_BODY_PLACEMENT, PX_KEY_END};
static const struct px_schema vx_naca_keys[] = {
    PX_KEY_STRING("digits", "NACA 4-digit designation, e.g. \"0012\" (chord 1, leading edge "
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
    PX_KEY_STRING("file", "closed list of \"x y\" points (relative to the case file)", PX_INPUT_FILE,
                  PX_REQUIRED),
    PX_KEY_INT("panels", "re-sample to this many panels (0: the points as given)", PX_GE(0),
               PX_LE(1000000), PX_DEFAULT("0")),
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
    PX_KEY_INT("every", "field output period [steps] (0: output.every)", PX_GE(0),
               PX_DEFAULT("0")),
    PX_KEY_VECTOR("grid", "velocity and pressure on a grid over [xmin, xmax, ymin, ymax] [m]",
                  PX_LEN(4, 4)),
    PX_KEY_VECTOR("cells", "grid points along x and y", PX_LEN(2, 2), PX_IN(2, 4096),
                  PX_DEFAULT("[200, 100]")),
    PX_KEY_LIST("probes", &(const struct px_schema)PX_KEY_VECTOR("probe", "a point [x, y] [m]",
                                                                 PX_LEN(2, 2)),
                "points where velocity and pressure are written every log step", PX_LEN(0, 1000)),
    PX_KEY_END};

static const struct px_schema vx_picture_keys[] = {
    PX_KEY_VECTOR("view", "shown region [xmin, xmax, ymin, ymax] [m] (default: bodies and wake)",
                  PX_LEN(4, 4)),
    PX_KEY_INT("width", "picture width [pixels]", PX_IN(64, 8192), PX_DEFAULT("1600")),
    PX_KEY_INT("height", "picture height [pixels]", PX_IN(64, 8192), PX_DEFAULT("900")),
    PX_KEY_REAL("gamma_range", "colour range +-G of the circulation [m^2/s] (0: automatic)",
                PX_GE(0), PX_DEFAULT("0")),
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
    return px_case_fail(c, px_case_path_join(p, sizeof p, path, "v_ref"),
                        "with no free stream (v_inf = [0, 0]) give a reference speed v_ref > 0");
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
    PX_KEY_REAL("v_ref", "reference speed for coefficients and the diffusive cap [m/s] (0: |v_inf|)",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("eps", "core radius of the vortices [m] (0: half the mean panel length)", PX_GE(0),
                PX_DEFAULT("0")),
    PX_KEY_REAL("eps_col", "merge radius of close vortices [m] (0: a third of the mean panel "
                           "length)",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("eps_col_opposite", "merge radius of close vortices of opposite signs [m] (0: "
                                    "2 eps_col, as VM2D)",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("eps_min", "smallest VVD domain radius eps* [m] (0: 0.05 mean panel "
                           "length, at least 0.5 sqrt(nu dt))",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("gamma_max", "largest circulation of a vortex after a merge, and of a newborn "
                             "one [m^2/s] (0: 0.05 v_ref x mean panel length)",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("delta", "distance of newborn vortices from the wall [m] (0: 1e-4 mean panel "
                         "length)",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_INT("vortex_per_panel", "vortices born on each panel per step (at least)", PX_IN(1, 64),
               PX_DEFAULT("1")),
    PX_KEY_REAL("dist_far", "vortices farther than this from the bodies are dropped [m] (0: 20 "
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
                "and diffusive block per step)",
                PX_DEFAULT("euler")),
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
                "docs/vortex-notes.md, \"The VVD's diffusion rate\"",
                PX_DEFAULT("none")),
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
    {.name = NULL, .check = vx_check_section}};

/* ------------------------------------------------------------------------- */
/* State */

struct vx_state {
  struct px_sim *sim;        /* borrowed */
  struct px_context *ctx;    /* borrowed */
  struct px_case *c;         /* borrowed (owned by the sim) */
  struct px_vortex_engine *e; /* owned */
  struct px_vtk *vtk;        /* owned */
  struct px_vtk_series *pvd_wake, *pvd_field; /* owned */
  struct px_csv *csv_loads, *csv_probes;      /* owned */
  struct px_figure *fig;     /* owned */
  double *probe;             /* owned: 2 * nprobe coordinates */
  size_t nprobe;
  int has_grid;
  double grid[4];
  size_t cells[2];
  long field_every;
  int pic_view;
  double view[4];
  double gamma_range;
  int pic_w, pic_h;
  const char *title;         /* borrowed from the case */
  /* the two friction estimates (x, all bodies) summed over the steps after
   * the first 100 of this process, compared at the end (vx_finish) */
  double fric_drift, fric_wall;
  long fric_n;
};

static enum px_status vx_get_real(struct vx_state *s, const char *key, double *v) {
  char p[128];
  snprintf(p, sizeof p, "vortex.%s", key);
  return px_case_get_real(s->c, p, v);
}

/* Build body i from the case: shape, placement, checks. A failure is
 * reported at the body's key path with the profile module's message. */
static enum px_status build_body(struct vx_state *s, size_t i, struct px_vortex_contour *out,
                                 double ref[3]) {
  char p[160], q[200];
  struct px_case *c = s->c;
  snprintf(p, sizeof p, "vortex.bodies[%zu]", i);
  const char *type = NULL;
  snprintf(q, sizeof q, "%s.type", p);
  PX_TRY(px_case_get_string(c, q, &type));
  long panels = 0;
  snprintf(q, sizeof q, "%s.panels", p);
  PX_TRY(px_case_get_int(c, q, &panels));
  enum px_status st = PX_STATUS_OK;
  struct px_context *ctx = s->ctx;
  memset(out, 0, sizeof *out);
  if (strcmp(type, "circle") == 0) {
    double r;
    snprintf(q, sizeof q, "%s.radius", p);
    PX_TRY(px_case_get_real(c, q, &r));
    st = px_vortex_profile_circle(ctx, r, (size_t)panels, out);
  } else if (strcmp(type, "ellipse") == 0) {
    double a, b;
    snprintf(q, sizeof q, "%s.a", p);
    PX_TRY(px_case_get_real(c, q, &a));
    snprintf(q, sizeof q, "%s.b", p);
    PX_TRY(px_case_get_real(c, q, &b));
    st = px_vortex_profile_ellipse(ctx, a, b, (size_t)panels, out);
  } else if (strcmp(type, "plate") == 0) {
    double l, t;
    snprintf(q, sizeof q, "%s.length", p);
    PX_TRY(px_case_get_real(c, q, &l));
    snprintf(q, sizeof q, "%s.thickness", p);
    PX_TRY(px_case_get_real(c, q, &t));
    st = px_vortex_profile_plate(ctx, l, t, (size_t)panels, out);
  } else if (strcmp(type, "naca") == 0) {
    const char *d;
    snprintf(q, sizeof q, "%s.digits", p);
    PX_TRY(px_case_get_string(c, q, &d));
    st = px_vortex_profile_naca4(ctx, d, (size_t)panels, out);
  } else {
    char path[4096];
    snprintf(q, sizeof q, "%s.file", p);
    if (px_case_input_path(c, q, path, sizeof path) != PX_STATUS_OK)
      return px_case_fail(c, q, "file name too long");
    if (strcmp(type, "selig") == 0) {
      int sp = 0;
      snprintf(q, sizeof q, "%s.spacing", p);
      PX_TRY(px_case_get_enum(c, q, &sp));
      st = px_vortex_profile_read_selig(
          ctx, path, (size_t)panels, sp == 0 ? PX_VORTEX_SPACING_COSINE : PX_VORTEX_SPACING_UNIFORM,
          out);
    } else {
      st = px_vortex_profile_read_points(ctx, path, (size_t)panels, out);
    }
  }
  if (st == PX_STATUS_OK) {
    double pos[2], scale, angle;
    snprintf(q, sizeof q, "%s.position", p);
    PX_TRY(px_case_get_vector(c, q, pos, 2));
    snprintf(q, sizeof q, "%s.scale", p);
    PX_TRY(px_case_get_real(c, q, &scale));
    snprintf(q, sizeof q, "%s.angle", p);
    PX_TRY(px_case_get_real(c, q, &angle));
    px_vortex_profile_place(out, pos[0], pos[1], scale, angle);
    int rev = 0;
    st = px_vortex_profile_check(ctx, out, &rev);
    snprintf(q, sizeof q, "%s.reference_length", p);
    PX_TRY(px_case_get_real(c, q, &ref[0]));
    ref[1] = pos[0];
    ref[2] = pos[1];
    snprintf(q, sizeof q, "%s.moment_center", p);
    if (px_case_has(c, q)) {
      double mc[2];
      PX_TRY(px_case_get_vector(c, q, mc, 2));
      ref[1] = mc[0];
      ref[2] = mc[1];
    }
  }
  if (st == PX_STATUS_NOMEM || st == PX_STATUS_INTERNAL) return st;
  if (st != PX_STATUS_OK) {
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", px_context_message(ctx));
    px_vortex_contour_free(ctx, out);
    return px_case_fail(c, p, "%s", msg);
  }
  return PX_STATUS_OK;
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
  px_vortex_config_defaults(&cfg);
  int start = 0, sheet = 0;
  long vpp = 1;
  PX_TRY(vx_get_real(s, "rho", &cfg.rho));
  PX_TRY(vx_get_real(s, "nu", &cfg.nu));
  PX_TRY(px_case_get_vector(c, "vortex.v_inf", cfg.vinf, 2));
  PX_TRY(px_case_get_enum(c, "vortex.start", &start));
  cfg.ramp = start == 0 ? PX_VORTEX_RAMP_IMPULSE
                        : (start == 1 ? PX_VORTEX_RAMP_LINEAR : PX_VORTEX_RAMP_COSINE);
  PX_TRY(vx_get_real(s, "ramp_time", &cfg.ramp_time));
  PX_TRY(vx_get_real(s, "v_ref", &cfg.vref));
  if (!(cfg.vref > 0.0)) cfg.vref = hypot(cfg.vinf[0], cfg.vinf[1]);
  PX_TRY(vx_get_real(s, "eps", &cfg.eps));
  PX_TRY(vx_get_real(s, "eps_col", &cfg.eps_col));
  PX_TRY(vx_get_real(s, "eps_col_opposite", &cfg.eps_col_opposite));
  PX_TRY(vx_get_real(s, "eps_min", &cfg.eps_min));
  PX_TRY(vx_get_real(s, "gamma_max", &cfg.gamma_max));
  PX_TRY(vx_get_real(s, "delta", &cfg.delta));
  PX_TRY(px_case_get_int(c, "vortex.vortex_per_panel", &vpp));
  cfg.vortex_per_panel = (int)vpp;
  PX_TRY(vx_get_real(s, "dist_far", &cfg.dist_far));
  PX_TRY(vx_get_real(s, "cutoff", &cfg.cutoff));
  PX_TRY(px_case_get_enum(c, "vortex.sheet", &sheet));
  cfg.sheet_exact = sheet == 0;
  int newborn = 0, scheme = 0;
  PX_TRY(px_case_get_enum(c, "vortex.newborn", &newborn));
  cfg.newborn_rayleigh = newborn == 1;
  PX_TRY(px_case_get_enum(c, "vortex.scheme", &scheme));
  cfg.rk2 = scheme == 1;
  int moments = 0;
  PX_TRY(px_case_get_enum(c, "vortex.vvd_moments", &moments));
  cfg.vvd_moments = moments;
  int method = 2;
  PX_TRY(px_case_get_enum(c, "vortex.velocity.method", &method));
  cfg.method = (enum px_nbody_method)method;
  PX_TRY(vx_get_real(s, "velocity.tolerance", &cfg.tolerance));
  int friction = 0;
  PX_TRY(px_case_get_enum(c, "vortex.friction", &friction));
  cfg.friction_wall = friction == 1;
  /* bodies */
  size_t nb = 0;
  PX_TRY(px_case_count(c, "vortex.bodies", &nb));
  struct px_vortex_contour body[PX_VORTEX_MAX_BODIES];
  memset(body, 0, sizeof body);
  enum px_status st = PX_STATUS_OK, worst = PX_STATUS_OK;
  for (size_t i = 0; i < nb; ++i) {
    double ref[3];
    st = build_body(s, i, &body[i], ref);
    if (st != PX_STATUS_OK) {
      if (st != PX_STATUS_CONFIG) goto done;
      worst = st;
      continue;
    }
    cfg.ref_length[i] = ref[0];
    cfg.moment_center[i][0] = ref[1];
    cfg.moment_center[i][1] = ref[2];
  }
  if (worst != PX_STATUS_OK) {
    st = worst;
    goto done;
  }
  for (size_t i = 0; i < nb; ++i)
    for (size_t j = i + 1; j < nb; ++j)
      if (px_vortex_profile_check_pair(ctx, &body[i], &body[j]) != PX_STATUS_OK) {
        char msg[1024], p[64];
        snprintf(msg, sizeof msg, "%s", px_context_message(ctx));
        snprintf(p, sizeof p, "vortex.bodies[%zu]", j);
        st = px_case_fail(c, p, "%s", msg);
        goto done;
      }
  /* automatic numerical parameters from the mean panel length */
  double L = px_vortex_mean_panel_length(body, nb);
  if (!(cfg.eps > 0.0)) cfg.eps = 0.5 * L;
  if (!(cfg.eps_col > 0.0)) cfg.eps_col = L / 3.0;
  if (!(cfg.gamma_max > 0.0)) cfg.gamma_max = 0.05 * cfg.vref * L;
  if (!(cfg.delta > 0.0)) cfg.delta = 1e-4 * L;
  if (!(cfg.dist_far > 0.0)) cfg.dist_far = 1e30; /* set from the bodies' size below */
  /* time step: the case's, or one panel length per reference speed */
  if (px_case_has(c, "time.dt"))
    PX_TRY(px_case_get_real(c, "time.dt", &cfg.dt));
  else
    cfg.dt = 0.5 * L / cfg.vref;
  /* eps_min 0: the engine's default (px_vortex_eps_min_default) */
  struct px_backend *be = px_sim_backend(sim);
  cfg.threads = px_backend_threads(be);
  cfg.precision = px_sim_precision(sim);
  st = px_backend_require(be, cfg.precision == PX_PRECISION_DOUBLE ? PX_PRECISION_DOUBLE
                                                                   : PX_PRECISION_SINGLE);
  if (st != PX_STATUS_OK) goto done;
  if (cfg.method == PX_NBODY_METHOD_FMM && strcmp(px_backend_name(be), "cpu") != 0) {
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
  /* outputs */
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
      goto done;
    }
  }
  PX_TRY(px_case_count(c, "vortex.fields.probes", &s->nprobe));
  if (s->nprobe) {
    s->probe = px_mem_alloc(ctx, "vortex.solver", 2 * s->nprobe * sizeof(double));
    if (!s->probe) {
      st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
      goto done;
    }
    for (size_t i = 0; i < s->nprobe; ++i) {
      char p[64];
      snprintf(p, sizeof p, "vortex.fields.probes[%zu]", i);
      PX_TRY(px_case_get_vector(c, p, s->probe + 2 * i, 2));
    }
  }
  s->pic_view = px_case_has(c, "vortex.picture.view");
  if (s->pic_view) PX_TRY(px_case_get_vector(c, "vortex.picture.view", s->view, 4));
  long w = 1600, h = 900;
  PX_TRY(px_case_get_int(c, "vortex.picture.width", &w));
  PX_TRY(px_case_get_int(c, "vortex.picture.height", &h));
  s->pic_w = (int)w;
  s->pic_h = (int)h;
  PX_TRY(px_case_get_real(c, "vortex.picture.gamma_range", &s->gamma_range));
  if (px_case_has(c, "title")) PX_TRY(px_case_get_string(c, "title", &s->title));
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

/* ------------------------------------------------------------------------- */
/* Pressure by the Cauchy-Lagrange integral (VM2D MeasureVP2D; Dynnikova):
 *   (p - p_inf)/rho = |V_inf|^2/2 - |V|^2/2 + sum_j V_j . v_j(r)
 *                     + sum_k alpha_k(r) (gamma_k L_k - absorbed_k) / (2 pi dt),
 * v_j(r) the velocity induced at r by vortex j, V_j its own velocity, and
 * alpha_k(r) the angle under which the segment from the body's inner point to
 * panel k's middle is seen from r: the potential jump carried by the
 * circulation created on panel k in the step. */
static enum px_status pressure(struct vx_state *s, size_t n, const double *x, const double *y,
                               const double *u, const double *v, double *p) {
  const struct px_vortex_engine *e = s->e;
  const struct px_vortex_wake *w = &e->w;
  const struct px_vortex_panels *pp = &e->pan;
  double vx, vy;
  px_vortex_vinf(&e->cfg, e->time, &vx, &vy);
  double eps2 = e->cfg.eps * e->cfg.eps, rho = e->cfg.rho, dt = e->cfg.dt;
  double vinf2 = e->cfg.vinf[0] * e->cfg.vinf[0] + e->cfg.vinf[1] * e->cfg.vinf[1];
  double inner[PX_VORTEX_MAX_BODIES][2];
  for (size_t b = 0; b < e->nbody; ++b) {
    double sx = 0.0, sy = 0.0;
    for (size_t k = 0; k < e->body[b].n; ++k) {
      sx += e->body[b].x[k];
      sy += e->body[b].y[k];
    }
    inner[b][0] = sx / (double)e->body[b].n;
    inner[b][1] = sy / (double)e->body[b].n;
  }
#pragma omp parallel for num_threads(e->cfg.threads) schedule(static)
  for (long li = 0; li < (long)n; ++li) {
    size_t i = (size_t)li;
    double acc = 0.0;
    for (size_t j = 0; j < w->n; ++j) {
      double dx = x[i] - w->x[j], dy = y[i] - w->y[j], r2 = dx * dx + dy * dy;
      double f = w->g[j] / (2.0 * VX_PI * (r2 > eps2 ? r2 : eps2));
      acc += f * (-dy * w->u[j] + dx * w->v[j]);
    }
    for (size_t k = 0; k < pp->n; ++k) {
      size_t b = (size_t)pp->body[k];
      double cx = 0.5 * (pp->x0[k] + pp->x1[k]) - x[i], cy = 0.5 * (pp->y0[k] + pp->y1[k]) - y[i];
      double ix = inner[b][0] - x[i], iy = inner[b][1] - y[i];
      double al = atan2(cx * iy - cy * ix, cx * ix + cy * iy);
      acc += al * (e->sol[k] * pp->len[k] - e->through[k]) / (2.0 * VX_PI * dt);
    }
    p[i] = rho * (0.5 * vinf2 - 0.5 * (u[i] * u[i] + v[i] * v[i]) + acc);
  }
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */
/* Outputs */

static enum px_status out_path(const struct px_sim_output *o, const char *name, char *buf,
                               size_t size) {
  int n = snprintf(buf, size, "%s/%s", o->dir, name);
  return (n < 0 || (size_t)n >= size) ? PX_STATUS_INVALID : PX_STATUS_OK;
}

static enum px_status vx_snapshot(void *state, const struct px_sim_output *o) {
  struct vx_state *s = state;
  struct px_context *ctx = s->ctx;
  struct px_vortex_engine *e = s->e;
  char path[1024], name[128];
  PX_TRY(px_vortex_engine_sync(e));
  if (!s->vtk) PX_TRY(px_vtk_create(ctx, &s->vtk));
  if (!s->pvd_wake) {
    PX_TRY(out_path(o, "wake.pvd", path, sizeof path));
    if (o->resumed)
      PX_TRY(px_vtk_series_open_resume(ctx, path, o->keep_snapshot, &s->pvd_wake));
    else
      PX_TRY(px_vtk_series_open(ctx, path, &s->pvd_wake));
    /* the bodies once */
    px_vtk_reset(s->vtk);
    size_t np = e->pan.n;
    PX_TRY(px_vtk_set_points(s->vtk, PX_DTYPE_F64, np, e->pan.x0, e->pan.y0, NULL));
    for (size_t b = 0; b < e->nbody; ++b)
      PX_TRY(px_vtk_add_polyline_range(s->vtk, e->pan.first[b], e->pan.first[b + 1] - e->pan.first[b], 1));
    PX_TRY(out_path(o, "bodies.vtp", path, sizeof path));
    PX_TRY(px_vtk_write(s->vtk, path));
  }
  struct px_vortex_wake *w = &e->w;
  px_vtk_reset(s->vtk);
  PX_TRY(px_vtk_set_points(s->vtk, PX_DTYPE_F64, w->n, w->x, w->y, NULL));
  PX_TRY(px_vtk_add_vertices(s->vtk));
  PX_TRY(px_vtk_add_scalar(s->vtk, PX_VTK_ASSOC_POINT, "Gamma", PX_DTYPE_F64, w->n, w->g));
  PX_TRY(px_vtk_add_scalar(s->vtk, PX_VTK_ASSOC_POINT, "core_radius", PX_DTYPE_F64, w->n, w->e));
  PX_TRY(px_vtk_add_vector(s->vtk, PX_VTK_ASSOC_POINT, "velocity", PX_DTYPE_F64, w->n, w->u, w->v,
                           NULL));
  px_vtk_set_time(s->vtk, o->time, o->step);
  snprintf(name, sizeof name, "wake_%06ld.vtp", o->step);
  PX_TRY(out_path(o, name, path, sizeof path));
  PX_TRY(px_vtk_write(s->vtk, path));
  PX_TRY(px_vtk_series_add(s->pvd_wake, o->time, name));
  /* fields on the grid */
  long fe = s->field_every > 0 ? s->field_every : 0;
  if (s->has_grid && (fe == 0 || o->step % fe == 0)) {
    size_t nx = s->cells[0], ny = s->cells[1], n = nx * ny;
    double *buf = px_mem_alloc(ctx, "vortex.fields", 5 * n * sizeof(double));
    if (!buf) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for the field grid");
    double *gx = buf, *gy = buf + n, *gu = buf + 2 * n, *gv = buf + 3 * n, *gp = buf + 4 * n;
    double dx = (s->grid[1] - s->grid[0]) / (double)(nx - 1);
    double dy = (s->grid[3] - s->grid[2]) / (double)(ny - 1);
    for (size_t j = 0; j < ny; ++j)
      for (size_t i = 0; i < nx; ++i) {
        gx[j * nx + i] = s->grid[0] + (double)i * dx;
        gy[j * nx + i] = s->grid[2] + (double)j * dy;
      }
    enum px_status st = px_vortex_engine_velocity(e, n, gx, gy, gu, gv);
    if (st == PX_STATUS_OK) st = pressure(s, n, gx, gy, gu, gv, gp);
    for (size_t q = 0; st == PX_STATUS_OK && q < n; ++q)
      for (size_t b = 0; b < e->nbody; ++b)
        if (px_vortex_profile_contains(&e->body[b], gx[q], gy[q])) {
          gu[q] = gv[q] = 0.0;
          gp[q] = NAN;
        }
    if (st == PX_STATUS_OK && !s->pvd_field) {
      PX_TRY(out_path(o, "fields.pvd", path, sizeof path));
      st = o->resumed ? px_vtk_series_open_resume(ctx, path, o->keep_snapshot, &s->pvd_field)
                      : px_vtk_series_open(ctx, path, &s->pvd_field);
    }
    if (st == PX_STATUS_OK) {
      size_t dims[3] = {nx, ny, 1};
      double org[3] = {s->grid[0], s->grid[2], 0.0}, sp[3] = {dx, dy, 1.0};
      px_vtk_reset(s->vtk);
      st = px_vtk_set_image(s->vtk, dims, org, sp);
      if (st == PX_STATUS_OK)
        st = px_vtk_add_vector(s->vtk, PX_VTK_ASSOC_POINT, "velocity", PX_DTYPE_F64, n, gu, gv,
                               NULL);
      if (st == PX_STATUS_OK)
        st = px_vtk_add_scalar(s->vtk, PX_VTK_ASSOC_POINT, "pressure", PX_DTYPE_F64, n, gp);
      px_vtk_set_time(s->vtk, o->time, o->step);
      snprintf(name, sizeof name, "fields_%06ld.vti", o->step);
      if (st == PX_STATUS_OK) st = out_path(o, name, path, sizeof path);
      if (st == PX_STATUS_OK) st = px_vtk_write(s->vtk, path);
      if (st == PX_STATUS_OK) st = px_vtk_series_add(s->pvd_field, o->time, name);
    }
    px_mem_free(ctx, buf);
    PX_TRY(st);
  }
  return PX_STATUS_OK;
}

#define VX_LOAD_COLS 13

static enum px_status vx_series(void *state, const struct px_sim_output *o) {
  struct vx_state *s = state;
  struct px_context *ctx = s->ctx;
  struct px_vortex_engine *e = s->e;
  char path[1024];
  size_t nb = e->nbody, ncol = 3 + VX_LOAD_COLS * nb;
  if (o->step == 0 && !o->resumed) return PX_STATUS_OK; /* loads exist after a step */
  if (!s->csv_loads) {
    static const char *const cols[VX_LOAD_COLS] = {"Cx", "Cy", "Cm", "Cx_friction", "Cy_friction",
                                                   "Fx", "Fy", "M", "absorbed", "Cx_drift",
                                                   "Cy_drift", "Cx_wall", "Cy_wall"};
    char(*names)[48] = px_mem_alloc(ctx, "vortex.csv", ncol * sizeof *names);
    const char **np = px_mem_alloc(ctx, "vortex.csv", ncol * sizeof *np);
    if (!names || !np) {
      px_mem_free(ctx, names);
      px_mem_free(ctx, np);
      return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
    }
    snprintf(names[0], 48, "t");
    snprintf(names[1], 48, "step");
    snprintf(names[2], 48, "vortices");
    for (size_t b = 0; b < nb; ++b)
      for (size_t q = 0; q < VX_LOAD_COLS; ++q) {
        if (nb == 1)
          snprintf(names[3 + b * VX_LOAD_COLS + q], 48, "%s", cols[q]);
        else
          snprintf(names[3 + b * VX_LOAD_COLS + q], 48, "%s_%zu", cols[q], b);
      }
    for (size_t q = 0; q < ncol; ++q) np[q] = names[q];
    enum px_status st = out_path(o, "loads.csv", path, sizeof path);
    if (st == PX_STATUS_OK)
      st = o->resumed ? px_csv_open_resume(ctx, path, ncol, np, o->keep_series, &s->csv_loads)
                      : px_csv_open(ctx, path, ncol, np, &s->csv_loads);
    px_mem_free(ctx, names);
    px_mem_free(ctx, np);
    PX_TRY(st);
  }
  double row[3 + VX_LOAD_COLS * PX_VORTEX_MAX_BODIES];
  row[0] = o->time;
  row[1] = (double)o->step;
  row[2] = (double)e->w.n;
  double q = 0.5 * e->cfg.rho * e->cfg.vref * e->cfg.vref;
  for (size_t b = 0; b < nb; ++b) {
    const struct px_vortex_loads *L = &e->loads[b];
    double *r = row + 3 + b * VX_LOAD_COLS, c = e->cfg.ref_length[b];
    double ab = L->absorbed;
    r[0] = L->cx;
    r[1] = L->cy;
    r[2] = L->cm;
    r[3] = L->fx_fric / (q * c);
    r[4] = L->fy_fric / (q * c);
    r[5] = L->fx;
    r[6] = L->fy;
    r[7] = L->m;
    r[8] = ab;
    /* the two friction estimates (vortex_core.c, loads): the impulse
     * balance's diffusive drift and the wall-vorticity estimate */
    r[9] = L->fx_diff / (q * c);
    r[10] = L->fy_diff / (q * c);
    r[11] = L->fx_wall / (q * c);
    r[12] = L->fy_wall / (q * c);
  }
  PX_TRY(px_csv_row(s->csv_loads, row));
  if (s->nprobe) {
    PX_TRY(px_vortex_engine_sync(e));
    if (!s->csv_probes) {
      size_t nc = 1 + 3 * s->nprobe;
      char(*names)[32] = px_mem_alloc(ctx, "vortex.csv", nc * sizeof *names);
      const char **np = px_mem_alloc(ctx, "vortex.csv", nc * sizeof *np);
      if (!names || !np) {
        px_mem_free(ctx, names);
        px_mem_free(ctx, np);
        return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
      }
      snprintf(names[0], 32, "t");
      for (size_t i = 0; i < s->nprobe; ++i) {
        snprintf(names[1 + 3 * i], 32, "u_%zu", i);
        snprintf(names[2 + 3 * i], 32, "v_%zu", i);
        snprintf(names[3 + 3 * i], 32, "p_%zu", i);
      }
      for (size_t i = 0; i < nc; ++i) np[i] = names[i];
      enum px_status st = out_path(o, "probes.csv", path, sizeof path);
      if (st == PX_STATUS_OK)
        st = o->resumed ? px_csv_open_resume(ctx, path, nc, np, o->keep_series, &s->csv_probes)
                        : px_csv_open(ctx, path, nc, np, &s->csv_probes);
      px_mem_free(ctx, names);
      px_mem_free(ctx, np);
      PX_TRY(st);
    }
    size_t n = s->nprobe;
    double *buf = px_mem_alloc(ctx, "vortex.fields", (5 * n + 1) * sizeof(double));
    if (!buf) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
    double *px = buf, *py = buf + n, *pu = buf + 2 * n, *pv = buf + 3 * n, *pr = buf + 4 * n;
    for (size_t i = 0; i < n; ++i) {
      px[i] = s->probe[2 * i];
      py[i] = s->probe[2 * i + 1];
    }
    enum px_status st = px_vortex_engine_velocity(e, n, px, py, pu, pv);
    if (st == PX_STATUS_OK) st = pressure(s, n, px, py, pu, pv, pr);
    double *prow = px_mem_alloc(ctx, "vortex.fields", (1 + 3 * n) * sizeof(double));
    if (st == PX_STATUS_OK && !prow) st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
    if (st == PX_STATUS_OK) {
      prow[0] = o->time;
      for (size_t i = 0; i < n; ++i) {
        prow[1 + 3 * i] = pu[i];
        prow[2 + 3 * i] = pv[i];
        prow[3 + 3 * i] = pr[i];
      }
      st = px_csv_row(s->csv_probes, prow);
    }
    px_mem_free(ctx, prow);
    px_mem_free(ctx, buf);
    PX_TRY(st);
  }
  return PX_STATUS_OK;
}

static enum px_status vx_picture(void *state, const struct px_sim_output *o) {
  struct vx_state *s = state;
  struct px_context *ctx = s->ctx;
  struct px_vortex_engine *e = s->e;
  char path[1024], name[128];
  PX_TRY(px_vortex_engine_sync(e));
  if (!s->fig) PX_TRY(px_figure_create(ctx, s->pic_w, s->pic_h, &s->fig));
  struct px_figure *f = s->fig;
  px_figure_reset(f);
  px_figure_set_colormap(f, PX_COLORMAP_COOLWARM);
  px_figure_set_field(f, "Γ", "m²/s");
  if (s->gamma_range > 0.0)
    px_figure_set_range(f, -s->gamma_range, s->gamma_range);
  else {
    /* automatic range: typical vortices well coloured */
    double m = 0.0;
    for (size_t i = 0; i < e->w.n; ++i) m += fabs(e->w.g[i]);
    m = e->w.n ? 1.5 * m / (double)e->w.n : 1.0;
    px_figure_set_range(f, -m, m);
  }
  px_figure_set_title(f, s->title ? s->title : "vortex wake");
  px_figure_set_time(f, o->time, "s");
  px_figure_set_axis_labels(f, "x [m]", "y [m]");
  if (s->pic_view) {
    px_figure_set_view(f, s->view[0], s->view[1], s->view[2], s->view[3]);
  } else {
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY, span = 0.0;
    for (size_t b = 0; b < e->nbody; ++b) {
      x0 = fmin(x0, e->pan.bxmin[b]);
      x1 = fmax(x1, e->pan.bxmax[b]);
      y0 = fmin(y0, e->pan.bymin[b]);
      y1 = fmax(y1, e->pan.bymax[b]);
      span = fmax(span, e->cfg.ref_length[b]);
    }
    px_figure_set_view(f, x0 - 0.75 * span, x1 + 4.0 * span, 0.5 * (y0 + y1) - 1.25 * span,
                       0.5 * (y0 + y1) + 1.25 * span);
  }
  if (e->w.n) PX_TRY(px_figure_add_points(f, PX_DTYPE_F64, e->w.n, e->w.x, e->w.y, e->w.g, 2.5));
  px_figure_set_color(f, 0.15, 0.15, 0.15);
  px_figure_set_fill(f, 0.45, 0.45, 0.45);
  for (size_t b = 0; b < e->nbody; ++b)
    PX_TRY(px_figure_add_polyline(f, PX_DTYPE_F64, e->body[b].n, e->body[b].x, e->body[b].y,
                                  PX_FIGURE_LINE_FILLED));
  snprintf(name, sizeof name, "wake_%06ld.png", o->step);
  PX_TRY(out_path(o, name, path, sizeof path));
  return px_figure_write_png(f, path);
}

/* The load plot from loads.csv (the whole run, also across resumes). */
static enum px_status plot_loads(struct vx_state *s, const struct px_sim_output *o) {
  struct px_context *ctx = s->ctx;
  char path[1024];
  PX_TRY(out_path(o, "loads.csv", path, sizeof path));
  FILE *fp = fopen(path, "r");
  if (!fp) return PX_STATUS_OK; /* no CSV output: no plot */
  size_t cap = 1024, n = 0, nb = s->e->nbody;
  double *t = px_mem_alloc(ctx, "vortex.plot", cap * sizeof(double));
  double *cx = px_mem_alloc(ctx, "vortex.plot", cap * nb * 2 * sizeof(double));
  char line[65536];
  enum px_status st = (t && cx) ? PX_STATUS_OK : px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
  int header = 1;
  while (st == PX_STATUS_OK && fgets(line, sizeof line, fp)) {
    if (header) {
      header = 0;
      continue;
    }
    double v[3 + VX_LOAD_COLS * PX_VORTEX_MAX_BODIES];
    size_t nv = 0;
    char *p = line;
    while (nv < 3 + VX_LOAD_COLS * nb) {
      char *end;
      v[nv] = strtod(p, &end);
      if (end == p) break;
      ++nv;
      p = end;
      while (*p == ',' || *p == ' ') ++p;
    }
    if (nv < 3 + VX_LOAD_COLS * nb) continue;
    if (n == cap) {
      cap *= 2;
      double *nt = px_mem_realloc(ctx, "vortex.plot", t, cap * sizeof(double));
      if (!nt) {
        st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
        break;
      }
      t = nt;
      double *nc = px_mem_realloc(ctx, "vortex.plot", cx, cap * nb * 2 * sizeof(double));
      if (!nc) {
        st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
        break;
      }
      cx = nc;
    }
    t[n] = v[0];
    for (size_t b = 0; b < nb; ++b) {
      cx[(2 * b) * cap + n] = v[3 + b * VX_LOAD_COLS];
      cx[(2 * b + 1) * cap + n] = v[4 + b * VX_LOAD_COLS];
    }
    ++n;
  }
  fclose(fp);
  if (st == PX_STATUS_OK && n > 1) {
    /* the columns were stored with the capacity at the time: re-pack */
    struct px_plot *pl = NULL;
    st = px_plot_create(ctx, 1400, 700, &pl);
    if (st == PX_STATUS_OK) {
      px_plot_set_title(pl, s->title ? s->title : "force coefficients");
      px_plot_set_labels(pl, "t [s]", "C [-]");
      /* the impulsive start spike hides the curves: clip the y range to the
       * data after the first tenth of the run */
      double lo = INFINITY, hi = -INFINITY;
      for (size_t b = 0; b < nb; ++b)
        for (size_t q = n / 10; q < n; ++q)
          for (int k = 0; k < 2; ++k) {
            double y = cx[(2 * b + (size_t)k) * cap + q];
            lo = fmin(lo, y);
            hi = fmax(hi, y);
          }
      if (isfinite(lo) && hi > lo) {
        double pad = 0.1 * (hi - lo);
        px_plot_set_yrange(pl, lo - pad, hi + pad);
      }
      for (size_t b = 0; b < nb && st == PX_STATUS_OK; ++b) {
        char nm[64];
        snprintf(nm, sizeof nm, nb > 1 ? "C_x body %zu" : "C_x", b);
        st = px_plot_add_series(pl, nm, n, t, cx + (2 * b) * cap);
        snprintf(nm, sizeof nm, nb > 1 ? "C_y body %zu" : "C_y", b);
        if (st == PX_STATUS_OK) st = px_plot_add_series(pl, nm, n, t, cx + (2 * b + 1) * cap);
      }
      if (st == PX_STATUS_OK) st = out_path(o, "loads.png", path, sizeof path);
      if (st == PX_STATUS_OK) st = px_plot_write_png(pl, path);
      px_plot_free(pl);
    }
  }
  px_mem_free(ctx, t);
  px_mem_free(ctx, cx);
  return st;
}

static enum px_status vx_finish(void *state, const struct px_sim_output *o) {
  struct vx_state *s = state;
  if (s->fric_n >= 100 && s->fric_wall != 0.0) {
    double r = s->fric_drift / s->fric_wall;
    if (r < 0.75 || r > 1.33)
      px_log(s->ctx, PX_LOG_LEVEL_WARN,
             "the two friction estimates differ: mean x friction %.4g N/m from the vortices' "
             "diffusive drift, %.4g N/m from the wall vorticity (last %ld steps; the loads use "
             "the %s, friction: %s); the drift sum picks up noise from far-wake vortices in long "
             "wakes, the wall estimate reads 15-30%% high where it was checked "
             "(docs/vortex-notes.md: \"Long wakes\", \"Loads and friction\"); loads.csv has both",
             s->fric_drift / (double)s->fric_n, s->fric_wall / (double)s->fric_n, s->fric_n,
             s->e->cfg.friction_wall ? "wall vorticity" : "drift",
             s->e->cfg.friction_wall ? "wall" : "drift");
  }
  if (s->csv_loads) PX_TRY(px_csv_close(s->csv_loads));
  s->csv_loads = NULL;
  if (s->csv_probes) PX_TRY(px_csv_close(s->csv_probes));
  s->csv_probes = NULL;
  return plot_loads(s, o);
}

/* ------------------------------------------------------------------------- */
/* Checkpoints: the wake and the circulation absorbed by each panel in the last
 * step (it enters the next generation and the next loads). Everything else is
 * recomputed from these. */

static enum px_status vx_save(void *state, struct px_checkpoint_writer *w) {
  struct vx_state *s = state;
  struct px_vortex_engine *e = s->e;
  PX_TRY(px_vortex_engine_sync(e));
  uint64_t n = e->w.n;
  PX_TRY(px_checkpoint_write(w, "vortex.n", PX_DTYPE_U64, 1, &n));
  PX_TRY(px_checkpoint_write(w, "vortex.x", PX_DTYPE_F64, n, e->w.x));
  PX_TRY(px_checkpoint_write(w, "vortex.y", PX_DTYPE_F64, n, e->w.y));
  PX_TRY(px_checkpoint_write(w, "vortex.gamma", PX_DTYPE_F64, n, e->w.g));
  PX_TRY(px_checkpoint_write(w, "vortex.velocity_u", PX_DTYPE_F64, n, e->w.u));
  PX_TRY(px_checkpoint_write(w, "vortex.velocity_v", PX_DTYPE_F64, n, e->w.v));
  PX_TRY(px_checkpoint_write(w, "vortex.absorbed", PX_DTYPE_F64, e->pan.n, e->through));
  return PX_STATUS_OK;
}

static enum px_status vx_load(void *state, struct px_checkpoint *ck) {
  struct vx_state *s = state;
  struct px_vortex_engine *e = s->e;
  uint64_t n = 0;
  PX_TRY(px_checkpoint_read(ck, "vortex.n", PX_DTYPE_U64, 1, &n));
  PX_TRY(px_vortex_wake_reserve(s->ctx, &e->w, (size_t)n));
  PX_TRY(px_checkpoint_read(ck, "vortex.x", PX_DTYPE_F64, n, e->w.x));
  PX_TRY(px_checkpoint_read(ck, "vortex.y", PX_DTYPE_F64, n, e->w.y));
  PX_TRY(px_checkpoint_read(ck, "vortex.gamma", PX_DTYPE_F64, n, e->w.g));
  PX_TRY(px_checkpoint_read(ck, "vortex.velocity_u", PX_DTYPE_F64, n, e->w.u));
  PX_TRY(px_checkpoint_read(ck, "vortex.velocity_v", PX_DTYPE_F64, n, e->w.v));
  PX_TRY(px_checkpoint_read(ck, "vortex.absorbed", PX_DTYPE_F64, e->pan.n, e->through));
  e->w.n = (size_t)n;
  for (size_t i = 0; i < e->w.n; ++i) {
    e->w.wu[i] = e->w.wv[i] = e->w.e[i] = 0.0;
    e->w.born[i] = -1;
  }
  e->step = (long)px_checkpoint_step(ck);
  e->time = px_checkpoint_time(ck);
  px_vortex_engine_host_changed(e);
  return PX_STATUS_OK;
}

const struct px_solver_i px_solver_vortex = {
    .name = "vortex",
    .summary = "2D viscous flow around profiles, vortex element method (viscous vortex domains)",
    .create = vx_create,
    .destroy = vx_destroy,
    .time_step = vx_time_step,
    .step = vx_step,
    .snapshot = vx_snapshot,
    .series = vx_series,
    .picture = vx_picture,
    .finish = vx_finish,
    .save = vx_save,
    .load = vx_load,
    .count = vx_count,
};
