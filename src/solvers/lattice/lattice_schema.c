/* The `lattice` case section: its keys, types, limits and defaults
 * (px_solver_lattice_keys; lattice.c reads a case checked against them). */
#include "solvers/lattice/lattice.h"

/* ---------------------------------------------------------------------------
 * Case section. Coordinates and radii are bounded by PX_LATTICE_COORD_MAX
 * (1e15 m: every extent and squared distance stays finite); sizes that do
 * not fit the machine are refused from the layout (px_lattice_need). */

static const char *const px_lattice_ops[] = {"union", "difference", NULL};
static const struct px_schema px_lattice_box_keys[] = {
    PX_KEY_VECTOR("min", "lower corner [m]", PX_LEN(3, 3), PX_IN(-1e15, 1e15), PX_REQUIRED),
    PX_KEY_VECTOR("max", "upper corner [m]", PX_LEN(3, 3), PX_IN(-1e15, 1e15), PX_REQUIRED),
    PX_KEY_ENUM("op", px_lattice_ops, "add the cells (union) or remove them (difference)",
                PX_DEFAULT("union")),
    PX_KEY_END};
static const struct px_schema px_lattice_cyl_keys[] = {
    PX_KEY_VECTOR("p0", "centre of one end [m]", PX_LEN(3, 3), PX_IN(-1e15, 1e15), PX_REQUIRED),
    PX_KEY_VECTOR("p1", "centre of the other end [m]", PX_LEN(3, 3), PX_IN(-1e15, 1e15),
                  PX_REQUIRED),
    PX_KEY_REAL("radius", "radius [m]", PX_GT(0), PX_LE(1e15), PX_REQUIRED),
    PX_KEY_ENUM("op", px_lattice_ops, "add the cells (union) or remove them (difference)",
                PX_DEFAULT("union")),
    PX_KEY_END};
static const struct px_schema px_lattice_sphere_keys[] = {
    PX_KEY_VECTOR("center", "centre [m]", PX_LEN(3, 3), PX_IN(-1e15, 1e15), PX_REQUIRED),
    PX_KEY_REAL("radius", "radius [m]", PX_GT(0), PX_LE(1e15), PX_REQUIRED),
    PX_KEY_ENUM("op", px_lattice_ops, "add the cells (union) or remove them (difference)",
                PX_DEFAULT("union")),
    PX_KEY_END};
static const struct px_schema px_lattice_shape_types[] = {
    PX_TYPE("box", px_lattice_box_keys, "an axis-aligned box"),
    PX_TYPE("cylinder", px_lattice_cyl_keys, "a cylinder between two end centres"),
    PX_TYPE("sphere", px_lattice_sphere_keys, "a sphere"), PX_KEY_END};
static const struct px_schema px_lattice_shape = PX_KEY_VARIANT(
    "shape", px_lattice_shape_types, "a primitive, applied in list order", PX_WHAT("shape"));

static const char *const px_lattice_faces[] = {"x_min", "x_max", "y_min", "y_max",
                                               "z_min", "z_max", NULL};
static const struct px_schema px_lattice_select_keys[] = {
    PX_KEY_ENUM("face", px_lattice_faces,
                "elements in the outermost layer of the body on that side"),
    PX_KEY_VECTOR("min", "box region: lower corner [m] (element centres are tested)", PX_LEN(3, 3),
                  PX_IN(-1e15, 1e15)),
    PX_KEY_VECTOR("max", "box region: upper corner [m]", PX_LEN(3, 3), PX_IN(-1e15, 1e15)),
    PX_KEY_VECTOR("nearest", "then only the element nearest this point [m]", PX_LEN(3, 3),
                  PX_IN(-1e15, 1e15)),
    PX_KEY_END};

static const struct px_schema px_lattice_tf_const_keys[] = {PX_KEY_END};
static const struct px_schema px_lattice_tf_ramp_keys[] = {
    PX_KEY_REAL("t0", "start of the ramp [s] (0 before)", PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("t1", "end of the ramp [s] (1 after)", PX_GT(0), PX_REQUIRED), PX_KEY_END};
static const struct px_schema px_lattice_tf_harm_keys[] = {
    PX_KEY_REAL("frequency", "frequency [Hz]", PX_GE(0), PX_REQUIRED),
    PX_KEY_REAL("phase", "phase [rad]", PX_DEFAULT("0")), PX_KEY_END};
static const struct px_schema px_lattice_tf_table_keys[] = {
    PX_KEY_VECTOR("t", "times [s], increasing", PX_LEN(1, 1000000), PX_REQUIRED),
    PX_KEY_VECTOR("value", "factor at each time (linear in between, constant outside)",
                  PX_LEN(1, 1000000), PX_REQUIRED),
    PX_KEY_END};
static const struct px_schema px_lattice_tf_types[] = {
    PX_TYPE("constant", px_lattice_tf_const_keys, "1 at all times"),
    PX_TYPE("ramp", px_lattice_tf_ramp_keys, "0 before t0, linear to 1 at t1, then 1"),
    PX_TYPE("harmonic", px_lattice_tf_harm_keys, "sin(2 pi frequency t + phase)"),
    PX_TYPE("table", px_lattice_tf_table_keys, "piecewise linear through (t, value) points"),
    PX_KEY_END};

static const char *const px_lattice_dofs[] = {"ux", "uy", "uz", "rx", "ry", "rz", "all", NULL};
static const struct px_schema px_lattice_dof =
    PX_KEY_ENUM("dof", px_lattice_dofs, "a degree of freedom", PX_WHAT("degree of freedom"));
static const struct px_schema px_lattice_bc_keys[] = {
    PX_KEY_STRING("name", "name (for messages)"),
    PX_KEY_MAP("select", px_lattice_select_keys, "which elements"),
    PX_KEY_LIST("fix", &px_lattice_dof,
                "fixed degrees of freedom, global frame (zero acceleration, or the prescribed "
                "one)",
                PX_LEN(0, 7)),
    PX_KEY_VECTOR("acceleration", "prescribed acceleration added to each element [m/s^2]",
                  PX_LEN(3, 3)),
    PX_KEY_VECTOR("angular_acceleration", "prescribed angular acceleration [rad/s^2]",
                  PX_LEN(3, 3)),
    PX_KEY_VECTOR("force", "total force on the selection, spread equally [N]", PX_LEN(3, 3)),
    PX_KEY_VECTOR("moment", "total moment on the selection, spread equally [N m]", PX_LEN(3, 3)),
    PX_KEY_VARIANT("function", px_lattice_tf_types,
                   "time function multiplying acceleration, force and moment",
                   PX_DEFAULT("constant")),
    PX_KEY_END};
static const struct px_schema px_lattice_bc =
    PX_KEY_MAP("bc", px_lattice_bc_keys, "a boundary condition", PX_WHAT("boundary condition"));

static const struct px_schema px_lattice_probe_keys[] = {
    PX_KEY_STRING("name", "column prefix in probes.csv", PX_REQUIRED),
    PX_KEY_MAP("select", px_lattice_select_keys, "elements averaged"), PX_KEY_END};
static const struct px_schema px_lattice_probe =
    PX_KEY_MAP("probe", px_lattice_probe_keys, "a probe", PX_WHAT("probe"));

static const struct px_schema px_lattice_init_keys[] = {
    PX_KEY_MAP("select", px_lattice_select_keys, "which elements"),
    PX_KEY_VECTOR("velocity", "initial velocity [m/s]", PX_LEN(3, 3), PX_DEFAULT("[0, 0, 0]")),
    PX_KEY_VECTOR("angular_velocity", "initial angular velocity [rad/s]", PX_LEN(3, 3),
                  PX_DEFAULT("[0, 0, 0]")),
    PX_KEY_END};
static const struct px_schema px_lattice_init =
    PX_KEY_MAP("initial", px_lattice_init_keys, "an initial velocity", PX_WHAT("initial state"));

static const struct px_schema px_lattice_strength_keys[] = {
    PX_KEY_REAL("normal", "tensile force that breaks a bond alone [N] (0: never)", PX_GE(0),
                PX_DEFAULT("0")),
    PX_KEY_REAL("shear", "shear force [N] (0: never)", PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("bending", "bending moment [N m] (0: never)", PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("twisting", "twisting moment [N m] (0: never)", PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_END};

static const char *const px_lattice_integrators[] = {"rk4", "leapfrog", NULL};
static const char *const px_lattice_schemes[] = {"auto", "gather", "link_once", NULL};
static const char *const px_lattice_views[] = {"iso", "top", "front", "side", NULL};
static const struct px_schema px_lattice_picture_keys[] = {
    PX_KEY_ENUM("view", px_lattice_views,
                "iso: isometric surface; top/front/side: along -z / +y / -x", PX_DEFAULT("iso")),
    PX_KEY_REAL("scale",
                "displacement magnification (0: largest displacement drawn as 5% of "
                "the body)",
                PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_END};

const struct px_schema px_solver_lattice_keys[] = {
    PX_KEY_REAL("h", "grid spacing = element size [m]", PX_GT(0), PX_LE(1e15), PX_REQUIRED),
    PX_KEY_REAL("E", "Young's modulus [Pa]", PX_GT(0), PX_REQUIRED),
    PX_KEY_REAL("poisson",
                "Poisson's ratio [-] (0: the link springs alone; otherwise a volumetric term, "
                "docs/notes/lattice-poisson.md)",
                PX_GT(-1), PX_LT(0.5), PX_DEFAULT("0")),
    PX_KEY_REAL("rho", "density [kg/m^3]", PX_GT(0), PX_REQUIRED),
    PX_KEY_REAL("zeta", "damping ratio of the link dashpots [-]", PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("damping", "global mass damping [1/s]", PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_BOOL("quasi_static",
                "relax to static equilibrium: adaptive critical mass damping "
                "(Underwood's dynamic relaxation); the run ends when it is reached",
                PX_DEFAULT("false")),
    PX_KEY_REAL("static_tolerance",
                "quasi_static: the run ends once static_error, the estimated relative distance "
                "from the static solution (probes.csv), has stayed below this for a radian of "
                "the slowest mode; time.steps or time.end is then the most it runs (0: run them "
                "all) [-]",
                PX_GE(0), PX_LT(1), PX_DEFAULT("1e-4")),
    PX_KEY_ENUM("integrator", px_lattice_integrators, "time integrator", PX_DEFAULT("rk4")),
    PX_KEY_ENUM("scheme", px_lattice_schemes,
                "link evaluation: each element its 6 links, or each link once", PX_DEFAULT("auto")),
    PX_KEY_REAL("dt_safety", "automatic dt = dt_safety x stability limit", PX_GT(0), PX_LE(1),
                PX_DEFAULT("0.9")),
    PX_KEY_MAP("strength", px_lattice_strength_keys,
               "bond strengths; B = f_n/normal + |f_t|/shear + |M_b|/bending + |M_t|/twisting "
               ">= 1 breaks a bond"),
    PX_KEY_LIST("body", &px_lattice_shape, "the body: primitives combined in order", PX_LEN(1, 256),
                PX_REQUIRED),
    PX_KEY_LIST("boundary", &px_lattice_bc, "boundary conditions", PX_LEN(0, 64)),
    PX_KEY_LIST("initial", &px_lattice_init, "initial velocities", PX_LEN(0, 256)),
    PX_KEY_LIST("probes", &px_lattice_probe,
                "probes written to probes.csv every output.log_every steps", PX_LEN(0, 64)),
    PX_KEY_MAP("picture", px_lattice_picture_keys, "the von Mises picture"),
    PX_KEY_END};
