/* The case-file section of the granular solver. Documented for users in
 * docs/granular.md; `partix keys granular` prints it. */
#include "solvers/granular/granular_impl.h"

static const char *const px_gran_sides[] = {"auto", "inside", "outside", NULL};
static const char *const px_gran_models[] = {"linear", "hysteretic", NULL};
static const char *const px_gran_tangentials[] = {"spring", "viscous", "none", NULL};
static const char *const px_gran_integrators[] = {"verlet", "abm4", NULL};
static const char *const px_gran_dists[] = {"uniform", "normal", "discrete", NULL};
static const char *const px_gran_fills[] = {"lattice", "random", NULL};
static const char *const px_gran_energies[] = {"normal", "total", NULL};
static const char *const px_gran_colors[] = {"speed", "spin", "contacts", "id", NULL};

static const struct px_schema px_gran_point =
    PX_KEY_VECTOR("point", "a point [x, y] [m]", PX_LEN(2, 2));
static const struct px_schema px_gran_row = PX_KEY_VECTOR("row", "a table row", PX_LEN(2, 16));

/* ---- path pieces ---- */
static const struct px_schema px_gran_piece_line[] = {
    PX_KEY_VECTOR("from", "start point [m]", PX_LEN(2, 2), PX_REQUIRED),
    PX_KEY_VECTOR("to", "end point [m]", PX_LEN(2, 2), PX_REQUIRED), PX_KEY_END};
static const struct px_schema px_gran_piece_arc[] = {
    PX_KEY_VECTOR("center", "centre [m]", PX_LEN(2, 2), PX_REQUIRED),
    PX_KEY_REAL("radius", "radius [m]", PX_GT(0), PX_REQUIRED),
    PX_KEY_REAL("start", "start angle [deg] (from +x, counter-clockwise)", PX_REQUIRED),
    PX_KEY_REAL("end", "end angle [deg]; end < start runs clockwise", PX_REQUIRED), PX_KEY_END};
static const struct px_schema px_gran_piece_earc[] = {
    PX_KEY_VECTOR("center", "centre [m]", PX_LEN(2, 2), PX_REQUIRED),
    PX_KEY_VECTOR("axes", "semi-axes [a, b] [m]", PX_LEN(2, 2), PX_GT(0), PX_REQUIRED),
    PX_KEY_REAL("angle", "rotation of the a axis from +x [deg]", PX_DEFAULT("0")),
    PX_KEY_REAL("start", "start parameter angle [deg]", PX_REQUIRED),
    PX_KEY_REAL("end", "end parameter angle [deg]", PX_REQUIRED),
    PX_KEY_END};
static const struct px_schema px_gran_piece_parabola[] = {
    PX_KEY_VECTOR("from", "start point [m]", PX_LEN(2, 2), PX_REQUIRED),
    PX_KEY_VECTOR("control", "control point: the tangents at both ends meet here [m]", PX_LEN(2, 2),
                  PX_REQUIRED),
    PX_KEY_VECTOR("to", "end point [m]", PX_LEN(2, 2), PX_REQUIRED), PX_KEY_END};
static const struct px_schema px_gran_piece_polyline[] = {
    PX_KEY_LIST("points", &px_gran_point, "points [[x, y], ...] [m]", PX_LEN(2, 0), PX_REQUIRED),
    PX_KEY_BOOL("smooth",
                "the points sample a smooth curve (re-sampled evenly) rather than "
                "corners",
                PX_DEFAULT("false")),
    PX_KEY_END};
static const struct px_schema px_gran_piece_types[] = {
    PX_TYPE("line", px_gran_piece_line, "a straight line"),
    PX_TYPE("arc", px_gran_piece_arc, "a circular arc"),
    PX_TYPE("ellipse_arc", px_gran_piece_earc, "an elliptic arc"),
    PX_TYPE("parabola", px_gran_piece_parabola, "a parabolic arc (quadratic Bezier)"),
    PX_TYPE("polyline", px_gran_piece_polyline, "a polyline (or a sampled spline)"),
    PX_KEY_END};
static const struct px_schema px_gran_piece =
    PX_KEY_VARIANT("piece", px_gran_piece_types, "a piece of a contour", PX_WHAT("piece"));

/* ---- shapes ---- */
static const struct px_schema px_gran_shape_rect[] = {
    PX_KEY_VECTOR("min", "lower-left corner [m]", PX_LEN(2, 2), PX_REQUIRED),
    PX_KEY_VECTOR("max", "upper-right corner [m]", PX_LEN(2, 2), PX_REQUIRED), PX_KEY_END};
static const struct px_schema px_gran_shape_circle[] = {
    PX_KEY_VECTOR("center", "centre [m]", PX_LEN(2, 2), PX_REQUIRED),
    PX_KEY_REAL("radius", "radius [m]", PX_GT(0), PX_REQUIRED), PX_KEY_END};
static const struct px_schema px_gran_shape_ellipse[] = {
    PX_KEY_VECTOR("center", "centre [m]", PX_LEN(2, 2), PX_REQUIRED),
    PX_KEY_VECTOR("axes", "semi-axes [a, b] [m]", PX_LEN(2, 2), PX_GT(0), PX_REQUIRED),
    PX_KEY_REAL("angle", "rotation of the a axis [deg]", PX_DEFAULT("0")), PX_KEY_END};
static const struct px_schema px_gran_shape_polygon[] = {
    PX_KEY_LIST("points", &px_gran_point, "corners [[x, y], ...] [m] (closed automatically)",
                PX_LEN(3, 0), PX_REQUIRED),
    PX_KEY_END};
static const struct px_schema px_gran_shape_path[] = {
    PX_KEY_LIST("pieces", &px_gran_piece,
                "pieces in order, each starting where the previous one ends; the last ends "
                "where the first starts",
                PX_LEN(1, 0), PX_REQUIRED),
    PX_KEY_END};
static const struct px_schema px_gran_shape_dxf[] = {
    PX_KEY_STRING("file", "DXF drawing (relative to the case file)", PX_REQUIRED, PX_INPUT_FILE),
    PX_KEY_STRING("layer", "only entities on this layer (empty: all)", PX_DEFAULT("\"\"")),
    PX_KEY_REAL("scale", "drawing units to metres (e.g. 0.001 for mm)", PX_GT(0), PX_LE(1e6),
                PX_DEFAULT("1")),
    PX_KEY_VECTOR("offset", "added after scaling [m]", PX_LEN(2, 2),
                  PX_IN(-PX_GRAN_COORD_MAX, PX_GRAN_COORD_MAX), PX_DEFAULT("[0, 0]")),
    PX_KEY_REAL("tolerance",
                "largest gap between entity ends that still joins them "
                "[drawing units]",
                PX_GT(0), PX_LE(PX_GRAN_COORD_MAX), PX_DEFAULT("1e-6")),
    PX_KEY_END};
static const struct px_schema px_gran_shape_types[] = {
    PX_TYPE("rectangle", px_gran_shape_rect, "an axis-aligned rectangle"),
    PX_TYPE("circle", px_gran_shape_circle, "a circle"),
    PX_TYPE("ellipse", px_gran_shape_ellipse, "an ellipse"),
    PX_TYPE("polygon", px_gran_shape_polygon, "a polygon"),
    PX_TYPE("path", px_gran_shape_path, "a chain of lines, arcs, parabolas and polylines"),
    PX_TYPE("dxf", px_gran_shape_dxf,
            "closed loops of a DXF drawing (LINE, ARC, CIRCLE, ELLIPSE, LWPOLYLINE, "
            "POLYLINE, SPLINE); several loops give several contours"),
    PX_KEY_END};

static const struct px_schema px_gran_contour_keys[] = {
    PX_KEY_STRING("name",
                  "name used in outputs (segments_NAME.csv, NAME_QUANTITY.png; a DXF "
                  "shape's further loops NAME.2, NAME.3, ...)",
                  PX_REQUIRED, PX_FILE_NAME, PX_WHAT("a contour name")),
    PX_KEY_STRING("body", "name of the body (in `bodies`) that moves it", PX_REQUIRED),
    PX_KEY_ENUM("side", px_gran_sides,
                "where the media is: auto (inside the outermost contour, outside a part, "
                "inside a hole of a part), inside or outside",
                PX_DEFAULT("auto")),
    PX_KEY_VARIANT("shape", px_gran_shape_types, "the contour's geometry", PX_REQUIRED),
    PX_KEY_BOOL("report", "write the impact statistics of this contour", PX_DEFAULT("true")),
    PX_KEY_END};
static const struct px_schema px_gran_contour =
    PX_KEY_MAP("contour", px_gran_contour_keys, "a closed boundary", PX_WHAT("contour"));

/* ---- motions ---- */
#define PX_GRAN_MOTION_COMMON                                                            \
  PX_KEY_VECTOR("pivot", "centre of rotation [m]", PX_LEN(2, 2), PX_DEFAULT("[0, 0]")),  \
      PX_KEY_REAL("start", "when the motion starts [s] (-1: after `settle`)", PX_GE(-1), \
                  PX_DEFAULT("-1")),                                                     \
      PX_KEY_REAL("ramp", "fade-in time of the amplitude [s]", PX_GE(0), PX_DEFAULT("0"))
static const struct px_schema px_gran_motion_fixed[] = {PX_KEY_END};
static const struct px_schema px_gran_motion_harmonic[] = {
    PX_KEY_VECTOR("amplitude", "displacement amplitudes [A_x, A_y] [m]", PX_LEN(2, 2),
                  PX_DEFAULT("[0, 0]")),
    PX_KEY_REAL("frequency", "frequency [Hz]", PX_GT(0), PX_REQUIRED),
    PX_KEY_VECTOR("phase", "phases [phi_x, phi_y] [deg]: x = A_x sin(2 pi f t + phi_x)",
                  PX_LEN(2, 2), PX_DEFAULT("[0, 0]")),
    PX_KEY_REAL("rotation", "rotation amplitude [deg]", PX_DEFAULT("0")),
    PX_KEY_REAL("rotation_frequency", "frequency of the rotation [Hz] (0: frequency)", PX_GE(0),
                PX_DEFAULT("0")),
    PX_KEY_REAL("rotation_phase", "phase of the rotation [deg]", PX_DEFAULT("0")),
    PX_GRAN_MOTION_COMMON,
    PX_KEY_END};
static const struct px_schema px_gran_motion_table[] = {
    PX_KEY_LIST("rows", &px_gran_row, "rows [t, x, y, rotation] [s, m, m, deg] (or give `file`)",
                PX_LEN(2, 0)),
    PX_KEY_STRING("file", "CSV/whitespace table of t x y rotation rows (relative to the case)",
                  PX_INPUT_FILE),
    PX_KEY_BOOL("periodic", "repeat the table (its last row must equal its first)",
                PX_DEFAULT("false")),
    PX_GRAN_MOTION_COMMON, PX_KEY_END};
static const struct px_schema px_gran_motion_types[] = {
    PX_TYPE("fixed", px_gran_motion_fixed, "does not move"),
    PX_TYPE("harmonic", px_gran_motion_harmonic, "sinusoidal vibration in x, y and rotation"),
    PX_TYPE("table", px_gran_motion_table, "displacement and rotation from a table (cubic)"),
    PX_KEY_END};
static const struct px_schema px_gran_body_keys[] = {
    PX_KEY_STRING("name", "name the contours refer to", PX_REQUIRED),
    PX_KEY_VARIANT("motion", px_gran_motion_types, "prescribed rigid motion", PX_DEFAULT("fixed")),
    PX_KEY_END};
static const struct px_schema px_gran_body =
    PX_KEY_MAP("body", px_gran_body_keys, "a rigid body of contours", PX_WHAT("body"));

/* ---- media ---- */
static const struct px_schema px_gran_value = PX_KEY_REAL("value", "a value", PX_GT(0));
static const struct px_schema px_gran_radius_keys[] = {
    PX_KEY_ENUM("distribution", px_gran_dists, "size distribution", PX_DEFAULT("uniform")),
    PX_KEY_REAL("min", "smallest radius [m]", PX_GT(0)),
    PX_KEY_REAL("max", "largest radius [m]", PX_GT(0)),
    PX_KEY_REAL("mean", "normal: mean radius [m]", PX_GT(0)),
    PX_KEY_REAL("sd", "normal: standard deviation [m]", PX_GE(0)),
    PX_KEY_LIST("values", &px_gran_value, "discrete: radii [m]"),
    PX_KEY_LIST("weights", &px_gran_value, "discrete: number fractions (any sum)"),
    PX_KEY_END};
static const struct px_schema px_gran_particle_row =
    PX_KEY_VECTOR("particle",
                  "[x, y, r] or [x, y, r, vx, vy] or [x, y, r, vx, vy, w] "
                  "[m, m/s, rad/s]",
                  PX_LEN(3, 6));
static const struct px_schema px_gran_media_keys[] = {
    PX_KEY_INT("count", "number of discs (give one of count, fraction, particles)",
               PX_IN(1, PX_GRAN_N_MAX)),
    PX_KEY_REAL("fraction", "disc area / free area (give one of count, fraction, particles)",
                PX_IN(0, 0.95)),
    PX_KEY_LIST("particles", &px_gran_particle_row,
                "discs placed one by one, rows [x, y, r(, vx, vy(, w))] (instead of count or "
                "fraction; checked for overlaps and for lying in the media region)",
                PX_LEN(1, (size_t)PX_GRAN_N_MAX)),
    PX_KEY_MAP("radius", px_gran_radius_keys, "disc radii (with count or fraction)"),
    PX_KEY_REAL("density", "material density [kg/m^3]", PX_GT(0), PX_REQUIRED),
    PX_KEY_REAL("thickness", "disc thickness (m = rho pi r^2 t) [m]", PX_GT(0), PX_REQUIRED),
    PX_KEY_ENUM("fill", px_gran_fills, "placement: hexagonal lattice from the bottom, or random",
                PX_DEFAULT("lattice")),
    PX_KEY_REAL("gap", "lattice: extra spacing relative to the largest diameter", PX_GE(0),
                PX_DEFAULT("0.02")),
    PX_KEY_VECTOR("window", "only place centres in [xmin, ymin, xmax, ymax] [m]", PX_LEN(4, 4)),
    PX_KEY_INT("seed", "random seed", PX_GE(0), PX_DEFAULT("1")),
    PX_KEY_END};

/* ---- contact laws ---- */
/* The same keys for both laws; D(x) gives the default of `contact` (the
 * keys of `wall_contact` have none: what it does not give comes from
 * `contact`). */
#define PX_GRAN_LAW_KEYS(D)                                                                     \
  PX_KEY_ENUM(                                                                                  \
      "model", px_gran_models,                                                                  \
      "normal force: linear spring-dashpot, or hysteretic (Walton-Braun/Luding)" D("linear")),  \
      PX_KEY_REAL("kn", "normal stiffness [N/m] (hysteretic: loading k1)", PX_GT(0)),           \
      PX_KEY_REAL("restitution",                                                                \
                  "coefficient of restitution e (linear: sets the damping; hysteretic: "        \
                  "k2 = k1/e^2 unless k2 is given)",                                            \
                  PX_GT(0), PX_LE(1)),                                                          \
      PX_KEY_REAL("k2", "hysteretic: (largest) unloading stiffness [N/m] (0: from e)",          \
                  PX_GE(0) D("0")),                                                             \
      PX_KEY_REAL("phi_f", "hysteretic: Luding's plasticity depth (0: constant k2)",            \
                  PX_GE(0) D("0")),                                                             \
      PX_KEY_REAL("damping", "hysteretic: extra viscous damping ratio", PX_IN(0, 0.99) D("0")), \
      PX_KEY_ENUM("tangential", px_gran_tangentials,                                            \
                  "friction: Cundall-Strack spring + Coulomb, viscous capped by Coulomb, or "   \
                  "none" D("spring")),                                                          \
      PX_KEY_REAL("friction", "Coulomb friction coefficient mu", PX_GE(0) D("0.5")),            \
      PX_KEY_REAL("kt_ratio",                                                                   \
                  "tangential / normal stiffness (1/3 equalises the periods of "                \
                  "discs)",                                                                     \
                  PX_GE(0) D("0.3333333333333333")),                                            \
      PX_KEY_REAL("ct_ratio", "tangential / normal damping", PX_GE(0) D("0.5")),                \
      PX_KEY_REAL("viscous", "viscous friction coefficient [N s/m]", PX_GE(0) D("0")),          \
      PX_KEY_REAL("rolling_friction", "rolling friction coefficient mu_r (0: off)",             \
                  PX_GE(0) D("0")),                                                             \
      PX_KEY_REAL("rolling_stiffness",                                                          \
                  "rolling stiffness k_r = this * kn mu_r^2 R*^2 (Ai et al. 2011: 2.25)",       \
                  PX_GT(0) D("2.25")),                                                          \
      PX_KEY_BOOL("no_attraction",                                                              \
                  "clip the normal force at zero (no pull at the end of "                       \
                  "a contact)" D("false"))
#define PX_GRAN_D(x) , PX_DEFAULT(x)
#define PX_GRAN_NOD(x)
static const struct px_schema px_gran_contact_keys[] = {PX_GRAN_LAW_KEYS(PX_GRAN_D), PX_KEY_END};
static const struct px_schema px_gran_wall_contact_keys[] = {PX_GRAN_LAW_KEYS(PX_GRAN_NOD),
                                                             PX_KEY_END};

/* kn and restitution are required in `contact`. */
static enum px_status px_gran_check_contact(struct px_case *c, const char *path) {
  char a[256];
  enum px_status st = PX_STATUS_OK;
  if (!px_case_has(c, px_case_path_join(a, sizeof a, path, "kn")))
    st = px_case_fail(c, path, "missing required key 'kn' (normal stiffness [N/m])");
  if (!px_case_has(c, px_case_path_join(a, sizeof a, path, "restitution")))
    st = px_case_fail(c, path,
                      "missing required key 'restitution' (coefficient of "
                      "restitution, 0 < e <= 1)");
  return st;
}

/* ---- statistics ---- */
static const struct px_schema px_gran_fn_keys[] = {
    PX_KEY_STRING("expression",
                  "function of E, the specific impact energy [J/m^2], e.g. "
                  "\"350 * (1 - exp(-E / 2000))\""),
    PX_KEY_LIST("table", &px_gran_row, "rows [E, value], linear between rows"),
    PX_KEY_STRING("unit", "unit of the value, shown in the tables and pictures (empty: -)",
                  PX_DEFAULT("\"\"")),
    PX_KEY_END};
static const struct px_schema px_gran_archard_keys[] = {
    PX_KEY_REAL("k", "Archard wear coefficient K [-]", PX_GE(0), PX_DEFAULT("1e-4")),
    PX_KEY_REAL("hardness", "hardness of the part H [Pa]", PX_GT(0), PX_DEFAULT("2e9")),
    PX_KEY_END};
static const struct px_schema px_gran_finnie_keys[] = {
    PX_KEY_REAL("k",
                "Finnie coefficient: removed volume per impact = k m V^n f(angle) "
                "[m^3 / (kg (m/s)^n)]",
                PX_GE(0), PX_DEFAULT("1e-10")),
    PX_KEY_REAL("exponent", "velocity exponent n (Finnie: 2)", PX_GT(0), PX_DEFAULT("2")),
    PX_KEY_END};
static const struct px_schema px_gran_stats_keys[] = {
    PX_KEY_REAL("start", "accumulate impacts from this time [s] (-1: after `settle`)", PX_GE(-1),
                PX_DEFAULT("-1")),
    PX_KEY_REAL("impact_velocity_min", "impacts slower than this (normal) are not counted [m/s]",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_ENUM("energy", px_gran_energies,
                "specific energy E for hardening/residual stress: normal or normal + "
                "tangential impact energy per unit surface",
                PX_DEFAULT("normal")),
    PX_KEY_MAP("archard", px_gran_archard_keys, "sliding wear V = K Fn s / H"),
    PX_KEY_MAP("finnie", px_gran_finnie_keys, "erosion per impact (Finnie 1960)"),
    PX_KEY_MAP("hardening", px_gran_fn_keys, "work hardening as a function of E"),
    PX_KEY_MAP("residual_stress", px_gran_fn_keys, "residual stress as a function of E"),
    PX_KEY_STRING("picture",
                  "quantity colouring the contour pictures (a column of the "
                  "segment CSV)",
                  PX_DEFAULT("energy_n_area")),
    PX_KEY_REAL("speed_max", "upper edge of the speed histogram [m/s] (0: automatic)", PX_GE(0),
                PX_DEFAULT("0")),
    PX_KEY_INT("bins", "bins of the speed histogram", PX_IN(2, 1000), PX_DEFAULT("40")),
    PX_KEY_BOOL("impact_log",
                "write every counted impact on a reported contour to impacts.csv "
                "(time, contour, segment, particle, vn, vt, angle, energies)",
                PX_DEFAULT("false")),
    PX_KEY_END};

static const struct px_schema px_gran_picture_keys[] = {
    PX_KEY_ENUM("color", px_gran_colors, "what colours the discs", PX_DEFAULT("speed")),
    PX_KEY_INT("width", "picture width [pixels]", PX_IN(64, 8192), PX_DEFAULT("1400")),
    PX_KEY_INT("height", "picture height [pixels]", PX_IN(64, 8192), PX_DEFAULT("1000")),
    PX_KEY_REAL("range", "upper end of the colour scale (0: automatic)", PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_END};

/* Exactly one of count / fraction; the radius keys of the distribution. */
static enum px_status px_gran_check_media(struct px_case *c, const char *path) {
  char a[256], b[256];
  const int has_count = px_case_has(c, px_case_path_join(a, sizeof a, path, "count"));
  const int has_frac = px_case_has(c, px_case_path_join(b, sizeof b, path, "fraction"));
  const int has_list = px_case_has(c, px_case_path_join(a, sizeof a, path, "particles"));
  if (has_count + has_frac + has_list != 1)
    return px_case_fail(c, path,
                        "give exactly one of 'count' (number of discs), 'fraction' "
                        "(disc area / free area) or 'particles' (a list of [x, y, r] rows)");
  if (!has_list && !px_case_has(c, px_case_path_join(a, sizeof a, path, "radius")))
    return px_case_fail(c, path, "'radius' (the size distribution) is needed with '%s'",
                        has_count ? "count" : "fraction");
  return PX_STATUS_OK;
}

const struct px_schema px_solver_granular_keys[] = {
    PX_KEY_VECTOR("gravity", "gravitational acceleration [m/s^2]", PX_LEN(2, 2),
                  PX_DEFAULT("[0, -9.81]")),
    PX_KEY_REAL("settle",
                "time to settle under gravity before the motions and statistics "
                "start [s]",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_ENUM("integrator", px_gran_integrators,
                "velocity Verlet (default; second order with the contact-onset correction) or "
                "the original Adams-Bashforth-Moulton 4 predictor-corrector",
                PX_DEFAULT("verlet")),
    PX_KEY_REAL("steps_per_contact",
                "automatic dt = t_c / this (t_c: contact time of the "
                "lightest pair)",
                PX_IN(5, 1e6), PX_DEFAULT("50")),
    PX_KEY_REAL("skin", "neighbour-list skin [m] (0: 0.4 of the largest radius)", PX_GE(0),
                PX_DEFAULT("0")),
    PX_KEY_REAL("segment_length", "boundary segment length [m] (0: the smallest radius)",
                PX_IN(0, PX_GRAN_COORD_MAX), PX_DEFAULT("0")),
    PX_KEY_REAL("smooth_angle",
                "concave joints turning less than this are smooth (one "
                "contact) [deg]",
                PX_IN(0, 90), PX_DEFAULT("30")),
    PX_KEY_MAP("media", px_gran_media_keys, "the media discs", PX_REQUIRED,
               PX_VALIDATE(px_gran_check_media)),
    PX_KEY_MAP("contact", px_gran_contact_keys, "particle-particle contact law", PX_REQUIRED,
               PX_VALIDATE(px_gran_check_contact)),
    PX_KEY_MAP("wall_contact", px_gran_wall_contact_keys,
               "particle-wall contact law (keys not given: as `contact`)"),
    PX_KEY_LIST("bodies", &px_gran_body, "rigid bodies and their motions", PX_LEN(1, 64),
                PX_REQUIRED),
    PX_KEY_LIST("contours", &px_gran_contour, "closed boundaries (container, parts)",
                PX_LEN(1, 256), PX_REQUIRED),
    PX_KEY_MAP("statistics", px_gran_stats_keys, "impact statistics along the contours"),
    PX_KEY_MAP("picture", px_gran_picture_keys, "PNG snapshots"),
    PX_KEY_END};
