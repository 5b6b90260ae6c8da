/* The `vortex` solver: 2D viscous flow around profiles by the vortex element
 * method with viscous vortex domains (spec vortex.md). This file is the glue
 * between a case and the engine (vortex_core.h): the case section, outputs
 * (wake .vtp, loads CSV, fields .vti and probes CSV, PNG pictures and the
 * load plot) and checkpoints. */
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
#include "solvers/vortex/vortex_report.h"
#include "solvers/vortex/vortex_profile.h"

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
      PX_KEY_VECTOR("moment_center",                                                        \
                    "point of the moment in the profile's own coordinates, scaled, rotated "  \
                    "and moved with the profile (the own origin goes to position)",           \
                    PX_LEN(2, 2), PX_DEFAULT("[0, 0]"))

/* at most PX_VORTEX_MAX_PANELS (80 GB of panel matrix); a case whose
 * estimated memory exceeds the machine's is refused (vx_check_memory) */
#define VX_PANELS_KEY                                                                       \
  PX_KEY_INT("panels", "number of panels (a few hundred is usual)", PX_REQUIRED,            \
             PX_GE(PX_VORTEX_MIN_PANELS), PX_LE(PX_VORTEX_MAX_PANELS))

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
    PX_KEY_LIST("probes", &(const struct px_schema)PX_KEY_VECTOR("probe", "a point [x, y] [m]",
                                                                 PX_LEN(2, 2)),
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
    PX_KEY_REAL("v_ref",
                "reference speed for coefficients and the diffusive cap [m/s] (0: |v_inf|)",
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
  double view[4];           /* shown region [m]: the case's or the automatic one */
  double gamma_range;        /* colour range +-G [m^2/s]; 0: per picture (vx_picture) */
  int pic_w, pic_h;
  const char *title;         /* borrowed from the case */
  double report_from, report_to; /* summary.json window [s]; < 0: the default */
  int tidied;                /* resumed: the stale end-of-segment picture is gone */
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
    /* the moment centre is a point of the profile's own frame, placed with
     * it: an angle-of-attack sweep keeps it on the same point of the body */
    double mc[2];
    snprintf(q, sizeof q, "%s.moment_center", p);
    PX_TRY(px_case_get_vector(c, q, mc, 2));
    px_vortex_profile_place_point(mc[0], mc[1], pos[0], pos[1], scale, angle, &ref[1], &ref[2]);
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

/* Memory of the case, estimated before anything is built [bytes] (owners:
 * vortex_panels.c, vortex_core.c, vortex_tree.c, the nbody sums):
 *  - the panel matrix, nsys = panels + bodies unknowns: 8 nsys^2 bytes,
 *    LU-factored in place, and a 4 nsys^2 single-precision copy with
 *    precision single (px_vortex_panels_factor);
 *  - per panel about 512 bytes (geometry, sheet, wall terms, the panel tree,
 *    the generation's work arrays), 1 kB more while an ellipse is built (64
 *    samples per panel);
 *  - per vortex about 512 bytes: the wake (10 doubles and an int, grown by
 *    half: 126), work arrays (40), the wake tree (70), the pair sums' buffers
 *    (60), the rk2 stage (72), the FMM's expansions (about 100); the wake's
 *    size is not known before the run, so the estimate holds the first
 *    step's newborn vortices, panels x vortex_per_panel: a lower bound;
 *  - per field-grid point about 160 bytes: positions, velocities and
 *    pressure (40), the pair sums' targets (48), the VTK arrays (72).
 * count[i]: the panels of body i; key[i]: the case key that sets them. */
#define VX_BYTES_PER_PANEL 512.0
#define VX_BYTES_PER_ELLIPSE_PANEL 1024.0
#define VX_BYTES_PER_VORTEX 512.0
#define VX_BYTES_PER_GRID_POINT 160.0
static enum px_status vx_check_memory(struct vx_state *s, size_t nb, const size_t *count,
                                      char (*key)[64], const int *ellipse) {
  struct px_case *c = s->c;
  long vpp = 1;
  PX_TRY(px_case_get_int(c, "vortex.vortex_per_panel", &vpp));
  double n = 0.0, build = 0.0;
  size_t big = 0;
  for (size_t i = 0; i < nb; ++i) {
    n += (double)count[i];
    if (ellipse[i]) build = fmax(build, VX_BYTES_PER_ELLIPSE_PANEL * (double)count[i]);
    if (count[i] > count[big]) big = i;
  }
  const double ns = n + (double)nb;
  const int single = px_sim_precision(s->sim) == PX_PRECISION_SINGLE;
  const double matrix = (single ? 12.0 : 8.0) * ns * ns + (single ? 8.0 : 4.0) * ns;
  const double body = matrix + VX_BYTES_PER_PANEL * n + build +
                      VX_BYTES_PER_VORTEX * n * (double)vpp;
  char what[256];
  snprintf(what, sizeof what,
           "the %.0f x %.0f panel matrix of the bodies' %.0f panels%s, with the panels and the "
           "first step's vortices",
           ns, ns, n, single ? " (and its single-precision copy)" : "");
  PX_TRY(px_sim_require_memory(s->sim, body, key[big], what));
  if (px_case_has(c, "vortex.fields.grid")) {
    double cells[2] = {0, 0};
    PX_TRY(px_case_get_vector(c, "vortex.fields.cells", cells, 2));
    const double grid = VX_BYTES_PER_GRID_POINT * cells[0] * cells[1];
    snprintf(what, sizeof what,
             "the %.0f x %.0f field grid (%.3g GB) besides the panel matrix, the panels and the "
             "first step's vortices (%.3g GB)",
             cells[0], cells[1], grid / 1e9, body / 1e9);
    PX_TRY(px_sim_require_memory(s->sim, body + grid, "vortex.fields.cells", what));
  }
  return PX_STATUS_OK;
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
  if (cfg->ramp != PX_VORTEX_RAMP_IMPULSE && cfg->ramp_time > 0.0 &&
      cfg->ramp_time < 5.0 * cfg->dt)
    px_log(s->ctx, PX_LOG_LEVEL_WARN,
           "vortex.ramp_time = %.4g s is %.3g steps of dt = %.4g s: the start is as abrupt as an "
           "impulsive one; ramp_time >= 5 dt = %.4g s resolves the ramp",
           cfg->ramp_time, cfg->ramp_time / cfg->dt, cfg->dt, 5.0 * cfg->dt);
  return PX_STATUS_OK;
}

/* Record the values chosen for the keys the case leaves to the solver (0):
 * `given` is the configuration as the case gave it, L the mean panel
 * length [m]. */
static void vx_note_automatic(struct vx_state *s, const struct px_vortex_config *given,
                              double L) {
  const struct px_vortex_config *cfg = &s->e->cfg;
  struct px_sim *sim = s->sim;
  double v = 0.0;
  if (vx_get_real(s, "v_ref", &v) == PX_STATUS_OK && !(v > 0.0))
    px_sim_note_auto(sim, "vortex.v_ref", "%.6g m/s (|v_inf|)", cfg->vref);
  if (!(given->eps > 0.0))
    px_sim_note_auto(sim, "vortex.eps", "%.6g m (L/2, L = %.6g m the mean panel length)",
                     cfg->eps, L);
  if (!(given->eps_col > 0.0))
    px_sim_note_auto(sim, "vortex.eps_col", "%.6g m (L/3)", cfg->eps_col);
  if (!(given->eps_col_opposite > 0.0))
    px_sim_note_auto(sim, "vortex.eps_col_opposite", "%.6g m (2 eps_col)",
                     cfg->eps_col_opposite);
  if (!(given->eps_min > 0.0))
    px_sim_note_auto(sim, "vortex.eps_min", "%.6g m (0.05 L = %.6g m, at least 0.5 sqrt(nu dt) "
                     "= %.6g m)", cfg->eps_min, 0.05 * L, 0.5 * sqrt(cfg->nu * cfg->dt));
  if (!(given->gamma_max > 0.0))
    px_sim_note_auto(sim, "vortex.gamma_max", "%.6g m^2/s (0.05 v_ref L)", cfg->gamma_max);
  if (!(given->delta > 0.0))
    px_sim_note_auto(sim, "vortex.delta", "%.6g m (1e-4 L)", cfg->delta);
  if (!(given->dist_far > 0.0 && given->dist_far < 1e29))
    px_sim_note_auto(sim, "vortex.dist_far", "%.6g m (20 reference lengths)", cfg->dist_far);
  if (given->method == PX_NBODY_METHOD_AUTO)
    px_sim_note_auto(sim, "vortex.velocity.method", "%s",
                     strcmp(px_backend_name(px_sim_backend(sim)), "cpu") == 0
                         ? "auto: per sum, the direct sum below about 4e6 source x target "
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
  if (nb > PX_VORTEX_MAX_BODIES) return px_case_fail(c, "vortex.bodies", "more than %d bodies",
                                                     PX_VORTEX_MAX_BODIES);
  /* the memory the case needs, before any body is built: from the panel
   * counts the case gives, and again below once the files of point lists
   * kept as they are (panels: 0) have been read */
  size_t count[PX_VORTEX_MAX_BODIES];
  char count_key[PX_VORTEX_MAX_BODIES][64];
  int ellipse[PX_VORTEX_MAX_BODIES], counted = 1;
  for (size_t i = 0; i < nb; ++i) {
    char q[64];
    const char *type = NULL;
    long panels = 0;
    snprintf(q, sizeof q, "vortex.bodies[%zu].type", i);
    PX_TRY(px_case_get_string(c, q, &type));
    snprintf(count_key[i], sizeof count_key[i], "vortex.bodies[%zu].panels", i);
    PX_TRY(px_case_get_int(c, count_key[i], &panels));
    if (panels <= 0) { /* points kept as given: the file sets the count */
      snprintf(count_key[i], sizeof count_key[i], "vortex.bodies[%zu].file", i);
      counted = 0;
    }
    count[i] = panels > 0 ? (size_t)panels : 0;
    ellipse[i] = strcmp(type, "ellipse") == 0;
  }
  PX_TRY(vx_check_memory(s, nb, count, count_key, ellipse));
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
  if (!counted) {
    for (size_t i = 0; i < nb; ++i) count[i] = body[i].n;
    st = vx_check_memory(s, nb, count, count_key, ellipse);
    if (st != PX_STATUS_OK) goto done;
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
  /* automatic numerical parameters from the mean panel length (each one the
   * case leaves at 0 is recorded: run.log, summary.json "automatic") */
  double L = px_vortex_mean_panel_length(body, nb);
  const struct px_vortex_config given = cfg;
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
  vx_note_automatic(s, &given, L);
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
  long w = 1600, h = 900;
  PX_TRY(px_case_get_int(c, "vortex.picture.width", &w));
  PX_TRY(px_case_get_int(c, "vortex.picture.height", &h));
  s->pic_w = (int)w;
  s->pic_h = (int)h;
  if (px_case_has(c, "vortex.picture.view")) {
    PX_TRY(px_case_get_vector(c, "vortex.picture.view", s->view, 4));
    if (!(s->view[1] > s->view[0] && s->view[3] > s->view[2])) {
      st = px_case_fail(c, "vortex.picture.view", "need xmin < xmax and ymin < ymax");
      goto done;
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
    px_sim_note_auto(sim, "vortex.picture.view", "[%.6g, %.6g, %.6g, %.6g] m (the bodies, 0.75 "
                     "reference lengths upstream, 4 downstream, 1.25 across)",
                     s->view[0], s->view[1], s->view[2], s->view[3]);
  }
  PX_TRY(px_case_get_real(c, "vortex.picture.gamma_range", &s->gamma_range));
  if (!(s->gamma_range > 0.0))
    px_sim_note_auto(sim, "vortex.picture.gamma_range",
                     "1.5 times the median |Gamma| of each picture's vortices (gamma_max = "
                     "%.6g m^2/s without vortices)", s->e->cfg.gamma_max);
  s->report_from = s->report_to = -1.0;
  if (px_case_has(c, "vortex.report.from"))
    PX_TRY(px_case_get_real(c, "vortex.report.from", &s->report_from));
  if (px_case_has(c, "vortex.report.to"))
    PX_TRY(px_case_get_real(c, "vortex.report.to", &s->report_to));
  if (s->report_from >= 0.0 && s->report_to >= 0.0 && !(s->report_to > s->report_from)) {
    st = px_case_fail(c, "vortex.report.to", "the window's end %g s is not after its start %g s",
                      s->report_to, s->report_from);
    goto done;
  }
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

/* A resumed run: delete the picture of the resume step that an earlier
 * segment drew only because it ended there (struct px_sim_output), once,
 * from whichever output hook runs first. */
static enum px_status vx_tidy(struct vx_state *s, const struct px_sim_output *o) {
  char path[1024], name[64];
  if (!o->resumed || o->render || s->tidied) return PX_STATUS_OK;
  s->tidied = 1;
  if (o->drop_picture < 0) return PX_STATUS_OK;
  snprintf(name, sizeof name, "wake_%06ld.png", o->drop_picture);
  PX_TRY(out_path(o, name, path, sizeof path));
  if (remove(path) != 0 && errno != ENOENT)
    return px_context_fail(s->ctx, PX_STATUS_IO, "cannot remove %s (a picture of an earlier "
                           "segment's end): %s", path, strerror(errno));
  return PX_STATUS_OK;
}

/* Open fields.pvd (continued on resume). */
static enum px_status vx_open_fields(struct vx_state *s, const struct px_sim_output *o) {
  char path[1024];
  PX_TRY(out_path(o, "fields.pvd", path, sizeof path));
  return o->resumed ? px_vtk_series_open_resume(s->ctx, path, o->keep_snapshot, &s->pvd_field)
                    : px_vtk_series_open(s->ctx, path, &s->pvd_field);
}

static enum px_status vx_snapshot(void *state, const struct px_sim_output *o) {
  struct vx_state *s = state;
  struct px_context *ctx = s->ctx;
  struct px_vortex_engine *e = s->e;
  char path[1024], name[128];
  PX_TRY(vx_tidy(s, o));
  PX_TRY(px_vortex_engine_sync(e));
  if (!s->vtk) PX_TRY(px_vtk_create(ctx, &s->vtk));
  if (!s->pvd_wake) {
    PX_TRY(out_path(o, "wake.pvd", path, sizeof path));
    if (o->resumed)
      PX_TRY(px_vtk_series_open_resume(ctx, path, o->keep_snapshot, &s->pvd_wake));
    else
      PX_TRY(px_vtk_series_open(ctx, path, &s->pvd_wake));
    /* a resumed run drops the field entries after its checkpoint even when
     * it writes no field itself */
    if (s->has_grid && o->resumed && !s->pvd_field) PX_TRY(vx_open_fields(s, o));
    /* the bodies once */
    px_vtk_reset(s->vtk);
    size_t np = e->pan.n;
    PX_TRY(px_vtk_set_points(s->vtk, PX_DTYPE_F64, np, e->pan.x0, e->pan.y0, NULL));
    for (size_t b = 0; b < e->nbody; ++b)
      PX_TRY(px_vtk_add_polyline_range(s->vtk, e->pan.first[b],
                                       e->pan.first[b + 1] - e->pan.first[b], 1));
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
  /* fields on the grid: with the snapshots whose step fields.every divides,
   * and with the last state (o->final: off the snapshot schedule, so a
   * resumed run drops it as the wake's) */
  long fe = s->field_every > 0 ? s->field_every : 0;
  if (s->has_grid && (fe == 0 || o->step % fe == 0 || o->final)) {
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
    if (st == PX_STATUS_OK && !s->pvd_field) st = vx_open_fields(s, o);
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

/* loads.csv: "t [s]", "step [-]", "vortices [-]", then these columns of each
 * body (name and unit; per unit span: forces in N/m, moments in N m/m) */
#define VX_LOAD_COLS 13
static const char *const vx_load_cols[VX_LOAD_COLS][2] = {
    {"cx", "-"},       {"cy", "-"},       {"cm", "-"},         {"cx_friction", "-"},
    {"cy_friction", "-"}, {"fx", "N/m"},  {"fy", "N/m"},       {"m", "N m/m"},
    {"absorbed", "m^2/s"}, {"cx_drift", "-"}, {"cy_drift", "-"}, {"cx_wall", "-"},
    {"cy_wall", "-"}};
enum { VX_COL_CX = 0, VX_COL_CY = 1, VX_COL_CM = 2, VX_COL_CXF = 3 };

/* Header of loads.csv column q of body b ("cx [-]"; "cx_1 [-]" with several
 * bodies). */
static void vx_load_name(char *buf, size_t size, size_t q, size_t b, size_t nb) {
  if (nb == 1)
    snprintf(buf, size, "%s [%s]", vx_load_cols[q][0], vx_load_cols[q][1]);
  else
    snprintf(buf, size, "%s_%zu [%s]", vx_load_cols[q][0], b, vx_load_cols[q][1]);
}

static enum px_status vx_series(void *state, const struct px_sim_output *o) {
  struct vx_state *s = state;
  struct px_context *ctx = s->ctx;
  struct px_vortex_engine *e = s->e;
  char path[1024];
  size_t nb = e->nbody, ncol = 3 + VX_LOAD_COLS * nb;
  PX_TRY(vx_tidy(s, o));
  if (o->step == 0 && !o->resumed) return PX_STATUS_OK; /* loads exist after a step */
  if (!s->csv_loads) {
    char(*names)[48] = px_mem_alloc(ctx, "vortex.csv", ncol * sizeof *names);
    const char **np = px_mem_alloc(ctx, "vortex.csv", ncol * sizeof *np);
    if (!names || !np) {
      px_mem_free(ctx, names);
      px_mem_free(ctx, np);
      return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
    }
    snprintf(names[0], 48, "t [s]");
    snprintf(names[1], 48, "step [-]");
    snprintf(names[2], 48, "vortices [-]");
    for (size_t b = 0; b < nb; ++b)
      for (size_t q = 0; q < VX_LOAD_COLS; ++q)
        vx_load_name(names[3 + b * VX_LOAD_COLS + q], 48, q, b, nb);
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
    r[0] = L->cx;
    r[1] = L->cy;
    r[2] = L->cm;
    r[3] = L->fx_fric / (q * c);
    r[4] = L->fy_fric / (q * c);
    r[5] = L->fx;
    r[6] = L->fy;
    r[7] = L->m;
    r[8] = L->absorbed;
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
      snprintf(names[0], 32, "t [s]");
      for (size_t i = 0; i < s->nprobe; ++i) {
        snprintf(names[1 + 3 * i], 32, "u_%zu [m/s]", i);
        snprintf(names[2 + 3 * i], 32, "v_%zu [m/s]", i);
        snprintf(names[3 + 3 * i], 32, "p_%zu [Pa]", i);
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

/* The k-th smallest of a[0..n) (k < n; a is reordered): Hoare's selection
 * with the middle element as pivot, deterministic. */
static double vx_select(double *a, size_t n, size_t k) {
  size_t lo = 0, hi = n - 1;
  while (lo < hi) {
    double pivot = a[lo + (hi - lo) / 2];
    size_t i = lo, j = hi;
    while (i <= j) {
      while (a[i] < pivot) ++i;
      while (a[j] > pivot) --j;
      if (i <= j) {
        double t = a[i];
        a[i] = a[j];
        a[j] = t;
        ++i;
        if (j == 0) break;
        --j;
      }
    }
    if (k <= j)
      hi = j;
    else if (k >= i)
      lo = i;
    else
      return a[k];
  }
  return a[k];
}

static enum px_status vx_picture(void *state, const struct px_sim_output *o) {
  struct vx_state *s = state;
  struct px_context *ctx = s->ctx;
  struct px_vortex_engine *e = s->e;
  char path[1024], name[128];
  PX_TRY(vx_tidy(s, o));
  PX_TRY(px_vortex_engine_sync(e));
  if (!s->fig) PX_TRY(px_figure_create(ctx, s->pic_w, s->pic_h, &s->fig));
  struct px_figure *f = s->fig;
  px_figure_reset(f);
  px_figure_set_colormap(f, PX_COLORMAP_COOLWARM);
  px_figure_set_field(f, "Γ", "m²/s");
  double g = s->gamma_range;
  if (!(g > 0.0)) {
    /* automatic, per picture: 1.5 times the median |Gamma|, so the typical
     * vortex is well coloured. Measured on the shipped cases' last frames:
     * gamma_max leaves the weak vortices of the Blasius plate's thick layer
     * white (median 0.07 gamma_max), the mean follows the few large merged
     * vortices of a long wake (Re = 100: mean 2.8 times the median, 1% of
     * the vortices above 40 times it); the median is 0.7-0.9 gamma_max on
     * the cylinder and airfoil cases. gamma_max for an empty wake. */
    g = e->cfg.gamma_max;
    if (e->w.n) {
      double *a = px_mem_alloc(ctx, "vortex.picture", e->w.n * sizeof(double));
      if (!a) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
      for (size_t i = 0; i < e->w.n; ++i) a[i] = fabs(e->w.g[i]);
      double med = vx_select(a, e->w.n, e->w.n / 2);
      px_mem_free(ctx, a);
      if (med > 0.0) g = 1.5 * med;
    }
  }
  px_figure_set_range(f, -g, g);
  px_figure_set_title(f, s->title ? s->title : "vortex wake");
  px_figure_set_time(f, o->time, "s");
  px_figure_set_axis_labels(f, "x [m]", "y [m]");
  px_figure_set_view(f, s->view[0], s->view[1], s->view[2], s->view[3]);
  /* an empty wake (the initial state) still gets its colour bar, so that
   * every frame of a run has the same layout */
  const double none = 0.0;
  if (e->w.n)
    PX_TRY(px_figure_add_points(f, PX_DTYPE_F64, e->w.n, e->w.x, e->w.y, e->w.g, 2.5));
  else
    PX_TRY(px_figure_add_points(f, PX_DTYPE_F64, 0, &none, &none, &none, 2.5));
  px_figure_set_color(f, 0.15, 0.15, 0.15);
  px_figure_set_fill(f, 0.45, 0.45, 0.45);
  for (size_t b = 0; b < e->nbody; ++b)
    PX_TRY(px_figure_add_polyline(f, PX_DTYPE_F64, e->body[b].n, e->body[b].x, e->body[b].y,
                                  PX_FIGURE_LINE_FILLED));
  snprintf(name, sizeof name, "wake_%06ld.png", o->step);
  PX_TRY(out_path(o, name, path, sizeof path));
  return px_figure_write_png(f, path);
}

/* The load history of the whole run, read back from loads.csv (so it covers
 * the earlier segments of a resumed run): per row the time [s], the vortex
 * count and per body C_x, C_y, C_m and the friction part of C_x, found by
 * their header names. */
struct vx_history {
  size_t n, cap, nb;
  double *t;    /* owned: n times [s] */
  double *vort; /* owned: n vortex counts */
  double *c;    /* owned: row i, body b, quantity q (VX_COL_*) at (i nb + b) 4 + q */
};

static void vx_history_free(struct px_context *ctx, struct vx_history *h) {
  px_mem_free(ctx, h->t);
  px_mem_free(ctx, h->vort);
  px_mem_free(ctx, h->c);
  memset(h, 0, sizeof *h);
}

/* Split a CSV line in place at commas (names of ours carry no quotes or
 * commas); returns the number of fields, at most max. */
static size_t vx_csv_split(char *line, char **field, size_t max) {
  size_t n = 0;
  char *p = line;
  while (n < max) {
    field[n++] = p;
    char *comma = strchr(p, ',');
    if (!comma) break;
    *comma = '\0';
    p = comma + 1;
  }
  char *end = field[n - 1] + strcspn(field[n - 1], "\r\n");
  *end = '\0';
  return n;
}

/* *found = 0 (and OK) when the run has no loads.csv (output.csv off, or no
 * step yet). */
static enum px_status vx_history_read(struct vx_state *s, const struct px_sim_output *o,
                                      struct vx_history *h, int *found) {
  struct px_context *ctx = s->ctx;
  const size_t nb = s->e->nbody, ncol = 3 + VX_LOAD_COLS * nb;
  char path[1024];
  memset(h, 0, sizeof *h);
  h->nb = nb;
  *found = 0;
  PX_TRY(out_path(o, "loads.csv", path, sizeof path));
  FILE *fp = fopen(path, "r");
  if (!fp) return PX_STATUS_OK;
  const size_t linecap = 32 * ncol + 256;
  char *line = px_mem_alloc(ctx, "vortex.history", linecap);
  char **field = px_mem_alloc(ctx, "vortex.history", (ncol + 1) * sizeof *field);
  size_t *col = px_mem_alloc(ctx, "vortex.history", (4 * nb + 2) * sizeof *col);
  enum px_status st = (line && field && col) ? PX_STATUS_OK : PX_STATUS_NOMEM;
  /* the header: where each wanted column is */
  if (st == PX_STATUS_OK && fgets(line, (int)linecap, fp)) {
    size_t nf = vx_csv_split(line, field, ncol + 1);
    for (size_t k = 0; k < 4 * nb + 2; ++k) {
      char want[64];
      if (k == 0)
        snprintf(want, sizeof want, "t [s]");
      else if (k == 1)
        snprintf(want, sizeof want, "vortices [-]");
      else
        vx_load_name(want, sizeof want, (k - 2) % 4, (k - 2) / 4, nb);
      col[k] = nf;
      for (size_t f = 0; f < nf; ++f)
        if (strcmp(field[f], want) == 0) col[k] = f;
      if (col[k] == nf)
        st = px_context_fail(ctx, PX_STATUS_FORMAT, "%s: no column '%s' in its header", path,
                             want);
    }
    *found = st == PX_STATUS_OK;
  }
  while (st == PX_STATUS_OK && fgets(line, (int)linecap, fp)) {
    if (!strchr(line, '\n')) break; /* a torn last line */
    size_t nf = vx_csv_split(line, field, ncol + 1);
    if (nf != ncol) continue;
    if (h->n == h->cap) {
      size_t cap = h->cap ? 2 * h->cap : 1024;
      double *t = px_mem_realloc(ctx, "vortex.history", h->t, cap * sizeof(double));
      if (t) h->t = t;
      double *v = px_mem_realloc(ctx, "vortex.history", h->vort, cap * sizeof(double));
      if (v) h->vort = v;
      double *c = px_mem_realloc(ctx, "vortex.history", h->c, cap * 4 * nb * sizeof(double));
      if (c) h->c = c;
      if (!t || !v || !c) {
        st = PX_STATUS_NOMEM;
        break;
      }
      h->cap = cap;
    }
    h->t[h->n] = strtod(field[col[0]], NULL);
    if (!isfinite(h->t[h->n])) continue; /* not a row a run writes */
    h->vort[h->n] = strtod(field[col[1]], NULL);
    for (size_t k = 0; k < 4 * nb; ++k) h->c[h->n * 4 * nb + k] = strtod(field[col[2 + k]], NULL);
    ++h->n;
  }
  fclose(fp);
  px_mem_free(ctx, line);
  px_mem_free(ctx, field);
  px_mem_free(ctx, col);
  if (st == PX_STATUS_NOMEM) st = px_context_fail(ctx, st, "out of memory reading %s", path);
  if (st != PX_STATUS_OK) vx_history_free(ctx, h);
  return st;
}

/* Quantity q (VX_COL_*) of body b over rows [i0, i1) into y. */
static void vx_history_column(const struct vx_history *h, size_t b, size_t q, size_t i0,
                              size_t i1, double *y) {
  for (size_t i = i0; i < i1; ++i) y[i - i0] = h->c[(i * h->nb + b) * 4 + q];
}

/* loads.png: C_x, C_y and C_m of every body over the whole run. */
static enum px_status plot_loads(struct vx_state *s, const struct px_sim_output *o) {
  struct px_context *ctx = s->ctx;
  struct vx_history h;
  int found = 0;
  char path[1024];
  PX_TRY(vx_history_read(s, o, &h, &found));
  if (!found || h.n < 2) {
    vx_history_free(ctx, &h);
    return PX_STATUS_OK; /* no CSV output: no plot */
  }
  const size_t n = h.n, nb = h.nb;
  double *y = px_mem_alloc(ctx, "vortex.plot", n * sizeof(double));
  struct px_plot *pl = NULL;
  enum px_status st = y ? px_plot_create(ctx, 1400, 700, &pl)
                        : px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
  if (st == PX_STATUS_OK) {
    static const char *const sym[3] = {"C_x", "C_y", "C_m"};
    px_plot_set_title(pl, s->title ? s->title : "force and moment coefficients");
    px_plot_set_labels(pl, "t [s]", "C_x, C_y, C_m [-]");
    /* the impulsive start's spike (the first steps' loads are impulse
     * differences over dt) would squeeze the curves: the y range is that of
     * the data after the first tenth of the run */
    double lo = INFINITY, hi = -INFINITY;
    for (size_t b = 0; b < nb; ++b)
      for (size_t q = 0; q < 3; ++q)
        for (size_t i = n / 10; i < n; ++i) {
          double v = h.c[(i * nb + b) * 4 + q];
          lo = fmin(lo, v);
          hi = fmax(hi, v);
        }
    if (isfinite(lo) && hi > lo) {
      double pad = 0.1 * (hi - lo);
      px_plot_set_yrange(pl, lo - pad, hi + pad);
    }
    for (size_t b = 0; b < nb && st == PX_STATUS_OK; ++b)
      for (size_t q = 0; q < 3 && st == PX_STATUS_OK; ++q) {
        char nm[64];
        if (nb > 1)
          snprintf(nm, sizeof nm, "%s body %zu", sym[q], b);
        else
          snprintf(nm, sizeof nm, "%s", sym[q]);
        vx_history_column(&h, b, q, 0, n, y);
        st = px_plot_add_series(pl, nm, n, h.t, y);
      }
    if (st == PX_STATUS_OK) st = out_path(o, "loads.png", path, sizeof path);
    if (st == PX_STATUS_OK) st = px_plot_write_png(pl, path);
  }
  px_plot_free(pl);
  px_mem_free(ctx, y);
  vx_history_free(ctx, &h);
  return st;
}

static enum px_status vx_finish(void *state, const struct px_sim_output *o) {
  struct vx_state *s = state;
  PX_TRY(vx_tidy(s, o));
  if (s->fric_n >= 100 && s->fric_wall != 0.0) {
    double r = s->fric_drift / s->fric_wall;
    if (r < 0.75 || r > 1.33)
      px_log(s->ctx, PX_LOG_LEVEL_WARN,
             "the two friction estimates differ: mean x friction %.4g N/m from the vortices' "
             "diffusive drift, %.4g N/m from the wall vorticity (last %ld steps; the loads use "
             "the %s, friction: %s); the drift sum picks up noise from far-wake vortices in long "
             "wakes, the wall estimate read 15-45%% higher where it was checked "
             "(docs/notes/vortex.md: \"Long wakes\", \"Loads and friction\"); loads.csv has both",
             s->fric_drift / (double)s->fric_n, s->fric_wall / (double)s->fric_n, s->fric_n,
             s->e->cfg.friction_wall ? "wall vorticity" : "drift",
             s->e->cfg.friction_wall ? "wall" : "drift");
  }
  if (s->csv_loads) PX_TRY(px_csv_close(s->csv_loads));
  s->csv_loads = NULL;
  if (s->csv_probes) PX_TRY(px_csv_close(s->csv_probes));
  s->csv_probes = NULL;
  /* rendering draws the load plot again from the run's loads.csv: a picture
     (none with output.png: false) */
  return o->pictures ? plot_loads(s, o) : PX_STATUS_OK;
}

/* "body_1." before the names of body 1's quantities when there are several
 * bodies, "" with one. */
static void vx_body_prefix(char *buf, size_t size, size_t b, size_t nb) {
  if (nb > 1)
    snprintf(buf, size, "body_%zu.", b);
  else
    buf[0] = '\0';
}

/* summary.json: over the window [from, to] of the whole run's loads.csv
 * (default: the second half of the time so far), per body the mean and
 * standard deviation of C_x, C_y, C_m and the mean friction part of C_x;
 * whether C_y oscillates periodically (px_vortex_report_oscillation) and
 * then its frequency, Strouhal number f c / v_ref and amplitude; the
 * Reynolds number v_ref c / nu (c the reference length); the vortex count. */
static enum px_status vx_report(void *state, const struct px_sim_output *o,
                                struct px_summary *sum) {
  struct vx_state *s = state;
  struct px_context *ctx = s->ctx;
  const struct px_vortex_engine *e = s->e;
  const size_t nb = e->nbody;
  char name[96], about[256], pre[32];
  px_summary_int(sum, "vortices", (long)e->w.n, "-", "vortices in the wake at the last step");
  for (size_t b = 0; b < nb; ++b) {
    vx_body_prefix(pre, sizeof pre, b, nb);
    snprintf(name, sizeof name, "%sreynolds", pre);
    px_summary_real(sum, name, e->cfg.vref * e->cfg.ref_length[b] / e->cfg.nu, "-",
                    "Reynolds number v_ref c / nu (c the reference length)");
  }
  struct vx_history h;
  int found = 0;
  PX_TRY(vx_history_read(s, o, &h, &found));
  if (!found || h.n == 0) {
    vx_history_free(ctx, &h);
    return PX_STATUS_OK; /* no loads.csv (output.csv off, or no step yet) */
  }
  double t1 = s->report_to > 0.0 ? s->report_to : o->time;
  double t0 = s->report_from >= 0.0 ? s->report_from : 0.5 * o->time;
  size_t i0 = 0, i1 = 0;
  while (i0 < h.n && h.t[i0] < t0 - 1e-9 * fabs(t0)) ++i0;
  i1 = i0;
  while (i1 < h.n && h.t[i1] <= t1 + 1e-9 * fabs(t1)) ++i1;
  size_t m = i1 - i0;
  px_summary_real(sum, "window_from", t0, "s",
                  "start of the averaging window (vortex.report.from)");
  px_summary_real(sum, "window_to", t1, "s", "end of the averaging window (vortex.report.to)");
  px_summary_int(sum, "window_samples", (long)m, "-", "rows of loads.csv in the window");
  double *y = m ? px_mem_alloc(ctx, "vortex.report", m * sizeof(double)) : NULL;
  if (m && !y) {
    vx_history_free(ctx, &h);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
  }
  static const char *const key[4] = {"cx", "cy", "cm", "cx_friction"};
  static const char *const what[4] = {
      "force coefficient along x (the drag for a free stream along +x)",
      "force coefficient along y (the lift for a free stream along +x)",
      "moment coefficient about the moment centre (counter-clockwise positive)",
      "friction part of C_x"};
  enum px_status st = PX_STATUS_OK;
  for (size_t b = 0; b < nb && m && st == PX_STATUS_OK; ++b) {
    vx_body_prefix(pre, sizeof pre, b, nb);
    for (size_t q = 0; q < 4; ++q) {
      double mean, sd;
      vx_history_column(&h, b, q, i0, i1, y);
      px_vortex_report_stats(y, m, &mean, &sd);
      snprintf(name, sizeof name, "%s%s_mean", pre, key[q]);
      snprintf(about, sizeof about, "mean over the window of the %s", what[q]);
      px_summary_real(sum, name, mean, "-", about);
      if (q == 3) continue;
      snprintf(name, sizeof name, "%s%s_std", pre, key[q]);
      snprintf(about, sizeof about, "standard deviation over the window of the %s", what[q]);
      px_summary_real(sum, name, sd, "-", about);
    }
    struct px_vortex_oscillation osc;
    vx_history_column(&h, b, VX_COL_CY, i0, i1, y);
    st = px_vortex_report_oscillation(ctx, h.t + i0, y, m, &osc);
    if (st != PX_STATUS_OK) break;
    snprintf(name, sizeof name, "%slift_periodic", pre);
    px_summary_bool(sum, name, osc.periodic,
                    "C_y oscillates periodically in the window (three cycles or more of one "
                    "frequency: docs/vortex.md, \"Outputs\")");
    if (!osc.periodic) continue;
    snprintf(name, sizeof name, "%sstrouhal", pre);
    px_summary_real(sum, name, osc.frequency * e->cfg.ref_length[b] / e->cfg.vref, "-",
                    "Strouhal number f c / v_ref of the lift (c the reference length)");
    snprintf(name, sizeof name, "%slift_frequency", pre);
    px_summary_real(sum, name, osc.frequency, "Hz", "frequency f of the lift's oscillation");
    snprintf(name, sizeof name, "%scy_amplitude", pre);
    px_summary_real(sum, name, osc.amplitude, "-",
                    "amplitude of C_y: mean (max - min) / 2 over the cycles");
    snprintf(name, sizeof name, "%slift_cycles", pre);
    px_summary_int(sum, name, (long)osc.cycles, "-", "whole lift cycles in the window");
  }
  px_mem_free(ctx, y);
  vx_history_free(ctx, &h);
  return st;
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

/* A checkpoint comes from elsewhere and is not trusted (docs/running.md,
 * "What partix trusts"): its CRCs only say that it is what some writer
 * wrote. Before any of it is used, every section must be there with the type
 * and count this case gives it, the vortex count must be one a run of this
 * case can reach, and every value must be finite and in the range a run
 * keeps it in; otherwise PX_STATUS_FORMAT naming the section (the driver
 * puts the file's name in front). */
static enum px_status vx_ck_section(struct vx_state *s, struct px_checkpoint *ck,
                                    const char *name, enum px_dtype type, uint64_t count) {
  enum px_dtype t = PX_DTYPE_U8;
  uint64_t n = 0;
  if (px_checkpoint_find(ck, name, &t, &n) != PX_STATUS_OK)
    return px_context_fail(s->ctx, PX_STATUS_FORMAT,
                           "section '%s' is missing: not a checkpoint of this vortex case", name);
  if (t != type || n != count)
    return px_context_fail(s->ctx, PX_STATUS_FORMAT,
                           "section '%s' holds %llu values of type %s; this case has %llu of "
                           "type %s",
                           name, (unsigned long long)n, px_dtype_name(t),
                           (unsigned long long)count, px_dtype_name(type));
  return PX_STATUS_OK;
}

/* The first value of a[0..n) that is not finite or, when lim >= 0, exceeds
 * lim in magnitude: its index, or n when all are fine. */
static size_t vx_first_bad(const double *a, size_t n, double lim) {
  for (size_t i = 0; i < n; ++i)
    if (!isfinite(a[i]) || (lim >= 0.0 && fabs(a[i]) > lim)) return i;
  return n;
}

static enum px_status vx_load(void *state, struct px_checkpoint *ck) {
  struct vx_state *s = state;
  struct px_vortex_engine *e = s->e;
  struct px_context *ctx = s->ctx;
  const uint64_t step = px_checkpoint_step(ck);
  const double time = px_checkpoint_time(ck);
  /* the driver has checked the header's step and time against the case;
     again here, where they become the engine's long and double */
  if (step > (uint64_t)LONG_MAX / 2 || !isfinite(time) || time < 0.0)
    return px_context_fail(ctx, PX_STATUS_FORMAT, "header: step %llu at t = %g s",
                           (unsigned long long)step, time);
  /* Bounds from the case (vortex_core.c): a step sheds at most 64 vortices
   * per panel (generation; the rk2 predictor's are dropped again), merges and
   * removals only lower the count, so after `step` steps the wake holds at
   * most step x 64 x panels vortices (and fewer than 2^31: the trees' int32
   * indices). Each newborn vortex carries at most |gamma_k| L_k <= 1e3 v_ref
   * L_k (the runaway check), a merged one the sum of its parts, an absorbed
   * circulation what the wake held: each |Gamma| and each panel's absorbed
   * circulation is at most step x 1e3 v_ref P, P the bodies' perimeter [m].
   * The restructuring drops every vortex farther than dist_far from the
   * bodies' centre (1e-5 relative slack: device positions are floats). */
  const double npan = (double)e->pan.n;
  double per = 0.0;
  for (size_t k = 0; k < e->pan.n; ++k) per += e->pan.len[k];
  const double nmax = fmin((double)step * 64.0 * npan, 2147483647.0);
  const double gmax = (double)step * 1e3 * e->cfg.vref * per;
  const double far = e->cfg.dist_far * (1.0 + 1e-5);
  static const char *const arr[5] = {"vortex.x", "vortex.y", "vortex.gamma",
                                     "vortex.velocity_u", "vortex.velocity_v"};
  uint64_t n = 0;
  PX_TRY(vx_ck_section(s, ck, "vortex.n", PX_DTYPE_U64, 1));
  PX_TRY(px_checkpoint_read(ck, "vortex.n", PX_DTYPE_U64, 1, &n));
  if ((double)n > nmax)
    return px_context_fail(ctx, PX_STATUS_FORMAT,
                           "section 'vortex.n': %llu vortices, more than a run of this case "
                           "holds after %llu steps (at most %.0f: 64 newborn vortices per step on "
                           "each of its %zu panels)",
                           (unsigned long long)n, (unsigned long long)step, nmax, e->pan.n);
  for (int q = 0; q < 5; ++q) PX_TRY(vx_ck_section(s, ck, arr[q], PX_DTYPE_F64, n));
  PX_TRY(vx_ck_section(s, ck, "vortex.absorbed", PX_DTYPE_F64, e->pan.n));
  /* read into the wake's arrays while it counts no vortex (w.n = 0): used
     only once every value has passed */
  PX_TRY(px_vortex_wake_reserve(ctx, &e->w, (size_t)n));
  e->w.n = 0;
  double *dst[5] = {e->w.x, e->w.y, e->w.g, e->w.u, e->w.v};
  for (int q = 0; q < 5; ++q) PX_TRY(px_checkpoint_read(ck, arr[q], PX_DTYPE_F64, n, dst[q]));
  double *absorbed = px_mem_alloc(ctx, "vortex.checkpoint", (e->pan.n + 1) * sizeof(double));
  if (!absorbed) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
  enum px_status st =
      px_checkpoint_read(ck, "vortex.absorbed", PX_DTYPE_F64, e->pan.n, absorbed);
  size_t bad = 0;
  for (int q = 0; q < 5 && st == PX_STATUS_OK; ++q) {
    bad = vx_first_bad(dst[q], (size_t)n, q == 2 ? gmax : -1.0);
    if (bad < n)
      st = px_context_fail(ctx, PX_STATUS_FORMAT, "section '%s': value %zu is %g%s", arr[q], bad,
                           dst[q][bad],
                           q == 2 ? ", not a circulation a run of this case reaches" : "");
  }
  for (size_t i = 0; st == PX_STATUS_OK && i < (size_t)n; ++i) {
    const double dx = e->w.x[i] - e->center[0], dy = e->w.y[i] - e->center[1];
    if (hypot(dx, dy) > far)
      st = px_context_fail(ctx, PX_STATUS_FORMAT,
                           "sections 'vortex.x', 'vortex.y': vortex %zu at (%g, %g) lies %g m "
                           "from the "
                           "bodies' centre, beyond vortex.dist_far = %g m (a run drops it)",
                           i, e->w.x[i], e->w.y[i], hypot(dx, dy), e->cfg.dist_far);
  }
  if (st == PX_STATUS_OK) {
    bad = vx_first_bad(absorbed, e->pan.n, gmax);
    if (bad < e->pan.n)
      st = px_context_fail(ctx, PX_STATUS_FORMAT,
                           "section 'vortex.absorbed': panel %zu absorbed %g m^2/s, not a "
                           "circulation a run of this case reaches (at most %g)",
                           bad, absorbed[bad], gmax);
  }
  if (st == PX_STATUS_OK) memcpy(e->through, absorbed, e->pan.n * sizeof(double));
  px_mem_free(ctx, absorbed);
  PX_TRY(st);
  e->w.n = (size_t)n;
  for (size_t i = 0; i < e->w.n; ++i) {
    e->w.wu[i] = e->w.wv[i] = e->w.e[i] = 0.0;
    e->w.born[i] = -1;
  }
  e->step = (long)step;
  e->time = time;
  px_vortex_engine_host_changed(e);
  return PX_STATUS_OK;
}

/* Keys that change only what is drawn or reported, never the state: they
 * may change when a run is resumed (the probes may not: they are columns
 * of probes.csv). */
static const char *const vx_resume_keys[] = {"vortex.picture", "vortex.report",
                                             "vortex.fields.every", "vortex.fields.grid",
                                             "vortex.fields.cells", NULL};

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
    .report = vx_report,
    .resume_keys = vx_resume_keys,
};
