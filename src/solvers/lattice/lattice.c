/* The `lattice` solver: dynamic stress-strain state of a solid body as a
 * regular grid of bonded 6-DOF elements (spec: shared/spec/lattice.md; user
 * docs: docs/lattice.md). This file holds the case section, the setup from
 * a case, the time step and checkpoints; the physics is in lattice_kernel.h,
 * the loops in the engines (lattice_cpu.c, lattice_ocl.c), the outputs in
 * lattice_output.c. */
#include "solvers/lattice/lattice.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "compute/backend_impl.h"
#include "partix/memory.h"
#include "solvers/lattice/lattice_ref.h"

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
static const struct px_schema px_lattice_shape =
    PX_KEY_VARIANT("shape", px_lattice_shape_types, "a primitive, applied in list order",
                   PX_WHAT("shape"));

static const char *const px_lattice_faces[] = {"x_min", "x_max", "y_min", "y_max",
                                               "z_min", "z_max", NULL};
static const struct px_schema px_lattice_select_keys[] = {
    PX_KEY_ENUM("face", px_lattice_faces,
                "elements in the outermost layer of the body on that side"),
    PX_KEY_VECTOR("min", "box region: lower corner [m] (element centres are tested)",
                  PX_LEN(3, 3), PX_IN(-1e15, 1e15)),
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
static const struct px_schema px_lattice_bc = PX_KEY_MAP("bc", px_lattice_bc_keys,
                                                         "a boundary condition",
                                                         PX_WHAT("boundary condition"));

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
                "iso: isometric surface; top/front/side: along -z / +y / -x",
                PX_DEFAULT("iso")),
    PX_KEY_REAL("scale", "displacement magnification (0: largest displacement drawn as 5% of "
                "the body)", PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_END};

const struct px_schema px_solver_lattice_keys[] = {
    PX_KEY_REAL("h", "grid spacing = element size [m]", PX_GT(0), PX_LE(1e15), PX_REQUIRED),
    PX_KEY_REAL("E", "Young's modulus [Pa] (the lattice has Poisson's ratio 0)", PX_GT(0),
                PX_REQUIRED),
    PX_KEY_REAL("rho", "density [kg/m^3]", PX_GT(0), PX_REQUIRED),
    PX_KEY_REAL("zeta", "damping ratio of the link dashpots [-]", PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_REAL("damping", "global mass damping [1/s]", PX_GE(0), PX_DEFAULT("0")),
    PX_KEY_BOOL("quasi_static", "relax to static equilibrium: adaptive critical mass damping "
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
    PX_KEY_LIST("body", &px_lattice_shape, "the body: primitives combined in order",
                PX_LEN(1, 256), PX_REQUIRED),
    PX_KEY_LIST("boundary", &px_lattice_bc, "boundary conditions", PX_LEN(0, 64)),
    PX_KEY_LIST("initial", &px_lattice_init, "initial velocities", PX_LEN(0, 256)),
    PX_KEY_LIST("probes", &px_lattice_probe,
                "probes written to probes.csv every output.log_every steps", PX_LEN(0, 64)),
    PX_KEY_MAP("picture", px_lattice_picture_keys, "the von Mises picture"),
    PX_KEY_END};

/* ---------------------------------------------------------------------------
 * Setup */

static const void *const px_lattice_engines[] = {
    &px_lattice_engine_cpu,
#ifdef PX_HAVE_OPENCL
    &px_lattice_engine_opencl,
#endif
};

static const char *px_lattice_path(char *buf, size_t size, const char *fmt, size_t i,
                                   const char *key) {
  char head[128];
  snprintf(head, sizeof head, fmt, i);
  return px_case_path_join(buf, size, head, key);
}

/* Read a selection map at `path` (e.g. "lattice.boundary[0].select"). */
static enum px_status px_lattice_read_sel(struct px_case *c, const char *path,
                                          struct px_lattice_sel *s) {
  char p[256];
  int a;
  memset(s, 0, sizeof *s);
  s->face = PX_LATTICE_FACE_NONE;
  if (px_case_has(c, px_case_path_join(p, sizeof p, path, "face"))) {
    int f;
    PX_TRY(px_case_get_enum(c, p, &f));
    s->face = (enum px_lattice_face)f;
  }
  for (a = 0; a < 3; ++a) {
    s->box_min[a] = -1e300;
    s->box_max[a] = 1e300;
  }
  if (px_case_has(c, px_case_path_join(p, sizeof p, path, "min"))) {
    PX_TRY(px_case_get_vector(c, p, s->box_min, 3));
    s->has_box = 1;
  }
  if (px_case_has(c, px_case_path_join(p, sizeof p, path, "max"))) {
    PX_TRY(px_case_get_vector(c, p, s->box_max, 3));
    s->has_box = 1;
  }
  if (px_case_has(c, px_case_path_join(p, sizeof p, path, "nearest"))) {
    PX_TRY(px_case_get_vector(c, p, s->point, 3));
    s->has_point = 1;
  }
  return PX_STATUS_OK;
}

/* Check a selection against the grid; a miss is reported at `path`. */
static enum px_status px_lattice_check_sel(struct px_lattice *L, struct px_case *c,
                                           const char *path, const struct px_lattice_sel *s,
                                           size_t **cells, size_t *count) {
  size_t *tmp = NULL, n = 0;
  if (px_lattice_select(L->ctx, &L->m.grid, s, cells ? cells : &tmp, count ? count : &n) !=
      PX_STATUS_OK) {
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", px_context_message(L->ctx));
    px_context_clear(L->ctx);
    return px_case_fail(c, path, "%s", msg);
  }
  px_mem_free(L->ctx, tmp);
  return PX_STATUS_OK;
}

static enum px_status px_lattice_read_tfun(struct px_lattice *L, struct px_case *c,
                                           const char *path, struct px_lattice_tfun *f) {
  char p[256];
  int type;
  memset(f, 0, sizeof *f);
  PX_TRY(px_case_get_enum(c, px_case_path_join(p, sizeof p, path, "type"), &type));
  f->kind = (enum px_lattice_tfun_kind)type;
  if (f->kind == PX_LATTICE_TFUN_RAMP) {
    PX_TRY(px_case_get_real(c, px_case_path_join(p, sizeof p, path, "t0"), &f->t0));
    PX_TRY(px_case_get_real(c, px_case_path_join(p, sizeof p, path, "t1"), &f->t1));
    if (!(f->t1 > f->t0))
      return px_case_fail(c, path, "ramp end t1 = %g must exceed start t0 = %g", f->t1, f->t0);
  } else if (f->kind == PX_LATTICE_TFUN_HARMONIC) {
    PX_TRY(px_case_get_real(c, px_case_path_join(p, sizeof p, path, "frequency"), &f->freq));
    /* sin(2 pi f t + phase) must not see an infinite argument */
    if (!isfinite(2.0 * 3.14159265358979323846 * f->freq))
      return px_case_fail(c, p, "frequency = %g Hz: 2 pi f overflows", f->freq);
    PX_TRY(px_case_get_real(c, px_case_path_join(p, sizeof p, path, "phase"), &f->phase));
  } else if (f->kind == PX_LATTICE_TFUN_TABLE) {
    size_t n = 0, nv = 0, i;
    char pv[256];
    PX_TRY(px_case_count(c, px_case_path_join(p, sizeof p, path, "t"), &n));
    PX_TRY(px_case_count(c, px_case_path_join(pv, sizeof pv, path, "value"), &nv));
    if (n != nv)
      return px_case_fail(c, path, "the table has %zu times but %zu values", n, nv);
    f->n = n;
    f->t = (double *)px_mem_alloc(L->ctx, "lattice.case", n * sizeof(double));
    f->v = (double *)px_mem_alloc(L->ctx, "lattice.case", n * sizeof(double));
    if (!f->t || !f->v) return PX_STATUS_NOMEM;
    PX_TRY(px_case_get_vector(c, p, f->t, n));
    PX_TRY(px_case_get_vector(c, pv, f->v, n));
    /* increasing, and the steps of t and value finite: the interpolation
     * v[lo] + (v[hi] - v[lo]) (t - t[lo]) / (t[hi] - t[lo]) stays finite */
    for (i = 1; i < n; ++i) {
      if (!(f->t[i] > f->t[i - 1]) || !isfinite(f->t[i] - f->t[i - 1]))
        return px_case_fail(c, p, "times must increase by finite steps (t[%zu] = %g after %g)",
                            i, f->t[i], f->t[i - 1]);
      if (!isfinite(f->v[i] - f->v[i - 1]))
        return px_case_fail(c, pv, "value[%zu] - value[%zu] = %g - %g overflows", i, i - 1,
                            f->v[i], f->v[i - 1]);
    }
  }
  return PX_STATUS_OK;
}

/* Text of a byte count: "350 GB" (decimal units) or "23 GiB" (binary). */
static void px_lattice_bytes_text(double b, int binary, char *buf, size_t size) {
  static const char *const dec[] = {"B", "kB", "MB", "GB", "TB", "PB", "EB"};
  static const char *const bin[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double unit = binary ? 1024.0 : 1000.0;
  int k = 0;
  while (b >= unit && k < 6) {
    b /= unit;
    ++k;
  }
  snprintf(buf, size, "%.*f %s", b < 10 && k ? 1 : 0, b, binary ? bin[k] : dec[k]);
}

/* Host memory of a run on the layout lay [B], the engine's (engine_host)
 * included: the larger of the setup's peak (occupancy, its cropped copy,
 * the connectivity check's two size_t per cell; then the model's link and
 * group bytes, the BC signatures and a selection, 8 B per cell each) and the
 * run's (model; fields of every padded entry, 13 doubles and the link
 * flags; per element the snapshot's floats (54 B), the voxels of a .vtu
 * (72 B) and the picture's discs (40 B); per corner point 24 B; a host copy
 * of the state in double for checkpoints and initial velocities). */
static double px_lattice_host_bytes(const struct px_lattice_layout *lay, double engine_host) {
  double ncell = (double)lay->ncell, nalloc = (double)lay->nalloc;
  double corners = ((double)lay->n[0] + 1) * ((double)lay->n[1] + 1) * ((double)lay->n[2] + 1);
  double setup = fmax(18.0 * ncell, 17.0 * ncell + 2.0 * nalloc);
  double model = ncell + 2.0 * nalloc;
  double outputs = nalloc * (13.0 * sizeof(double) + 1.0) + ncell * (54.0 + 72.0 + 40.0) +
                   24.0 * corners;
  double state = nalloc * (sizeof(struct lt_el_d) + 1.0);
  return fmax(setup, model + engine_host + outputs + state);
}

/* Refuse, before anything of the size of the grid is allocated, a lattice
 * that this machine (or its device) cannot hold or the engine cannot index:
 * at lattice.h, the key that sets the size, with the figures. Records the
 * host estimate in L->need_host (the probes add to it). */
static enum px_status px_lattice_need(struct px_lattice *L, struct px_case *c,
                                      const struct px_lattice_grid *g,
                                      const struct px_lattice_engine_opts *o) {
  struct px_lattice_layout lay;
  struct px_lattice_need en;
  char what[384], need[32], have[32], *value = NULL;
  enum px_status st = PX_STATUS_OK;
  px_lattice_model_layout(g->n, &lay);
  L->vt->need(&lay, o, &en);
  snprintf(what, sizeof what,
           "the lattice of %d x %d x %d cells of h = %g m (the body's bounding box; %zu entries "
           "with padding): model, %s engine state in %s precision, output fields and "
           "checkpoint buffers",
           g->n[0], g->n[1], g->n[2], g->h, lay.nalloc, L->vt->name,
           o->precision == PX_PRECISION_SINGLE ? "single" : "double");
  if (en.nalloc_max > 0 && (double)lay.nalloc > en.nalloc_max)
    return px_case_fail(c, "lattice.h",
                        "the lattice of %d x %d x %d cells of h = %g m (the body's bounding box) "
                        "has %zu entries with padding; %s: at most %.0f (use a larger h)",
                        g->n[0], g->n[1], g->n[2], g->h, lay.nalloc,
                        en.index_why ? en.index_why : "the engine", en.nalloc_max);
  L->need_host = px_lattice_host_bytes(&lay, en.host);
  PX_TRY(px_sim_require_memory(L->sim, L->need_host, "lattice.h", what));
  if (px_case_value_text(c, "lattice.h", &value) != PX_STATUS_OK) value = NULL;
  if (en.device > 0 && en.device_have > 0 && en.device > en.device_have) {
    px_lattice_bytes_text(en.device, 0, need, sizeof need);
    px_lattice_bytes_text(en.device_have, 1, have, sizeof have);
    st = px_case_fail(c, "lattice.h",
                      "lattice.h = %s needs %s of device memory for %s; the %s device has %s",
                      value ? value : "?", need, what, L->vt->name, have);
  } else if (en.buffer_max > 0 && en.buffer > en.buffer_max) {
    px_lattice_bytes_text(en.buffer, 0, need, sizeof need);
    px_lattice_bytes_text(en.buffer_max, 1, have, sizeof have);
    st = px_case_fail(c, "lattice.h",
                      "lattice.h = %s needs a device buffer of %s for %s; the %s device "
                      "allocates at most %s at once",
                      value ? value : "?", need, what, L->vt->name, have);
  }
  px_mem_free(L->ctx, value);
  return st;
}

/* The body: its primitives and h from the case, the grid planned and its
 * size checked against the machine (px_lattice_need) before the grid is
 * evaluated, then the connectivity. Shape errors are reported at
 * lattice.body, sizes at lattice.h. */
static enum px_status px_lattice_read_body(struct px_lattice *L, struct px_case *c,
                                           const struct px_lattice_engine_opts *o,
                                           struct px_lattice_grid *g) {
  size_t n = 0, i;
  struct px_lattice_prim *pr;
  double h;
  enum px_status st = PX_STATUS_OK;
  int reported = 0; /* st comes from px_case_fail (at its key) */
  char p[256];
  PX_TRY(px_case_get_real(c, "lattice.h", &h));
  PX_TRY(px_case_count(c, "lattice.body", &n));
  pr = (struct px_lattice_prim *)px_mem_calloc(L->ctx, "lattice.case", n, sizeof *pr);
  if (!pr) return PX_STATUS_NOMEM;
  for (i = 0; i < n && st == PX_STATUS_OK; ++i) {
    int type = 0, op = 0;
    st = px_case_get_enum(c, px_lattice_path(p, sizeof p, "lattice.body[%zu]", i, "type"), &type);
    if (st == PX_STATUS_OK)
      st = px_case_get_enum(c, px_lattice_path(p, sizeof p, "lattice.body[%zu]", i, "op"), &op);
    pr[i].shape = (enum px_lattice_shape)type;
    pr[i].op = (enum px_lattice_op)op;
    if (st != PX_STATUS_OK) break;
    if (pr[i].shape == PX_LATTICE_SHAPE_BOX) {
      st = px_case_get_vector(c, px_lattice_path(p, sizeof p, "lattice.body[%zu]", i, "min"),
                              pr[i].p0, 3);
      if (st == PX_STATUS_OK)
        st = px_case_get_vector(c, px_lattice_path(p, sizeof p, "lattice.body[%zu]", i, "max"),
                                pr[i].p1, 3);
    } else if (pr[i].shape == PX_LATTICE_SHAPE_CYLINDER) {
      st = px_case_get_vector(c, px_lattice_path(p, sizeof p, "lattice.body[%zu]", i, "p0"),
                              pr[i].p0, 3);
      if (st == PX_STATUS_OK)
        st = px_case_get_vector(c, px_lattice_path(p, sizeof p, "lattice.body[%zu]", i, "p1"),
                                pr[i].p1, 3);
      if (st == PX_STATUS_OK)
        st = px_case_get_real(c, px_lattice_path(p, sizeof p, "lattice.body[%zu]", i, "radius"),
                              &pr[i].r);
    } else {
      st = px_case_get_vector(c, px_lattice_path(p, sizeof p, "lattice.body[%zu]", i, "center"),
                              pr[i].p0, 3);
      if (st == PX_STATUS_OK)
        st = px_case_get_real(c, px_lattice_path(p, sizeof p, "lattice.body[%zu]", i, "radius"),
                              &pr[i].r);
    }
  }
  if (st == PX_STATUS_OK) {
    double cells = 0.0;
    reported = 1; /* every failure below is reported at its key */
    if (px_lattice_grid_plan(L->ctx, h, pr, n, g, &cells) != PX_STATUS_OK) {
      /* the message names the shape by index: report it at the body list,
       * or a grid too large to index at h */
      char msg[1024];
      snprintf(msg, sizeof msg, "%s", px_context_message(L->ctx));
      px_context_clear(L->ctx);
      st = px_case_fail(c, !(cells <= (double)PX_LATTICE_MAX_CELLS) ? "lattice.h" : "lattice.body",
                        "%s", msg);
    } else {
      st = px_lattice_need(L, c, g, o);
    }
    reported = st != PX_STATUS_OK;
  }
  if (st == PX_STATUS_OK) st = px_lattice_grid_build(L->ctx, h, pr, n, g);
  if (st == PX_STATUS_OK) st = px_lattice_grid_check_connected(L->ctx, g);
  if (st == PX_STATUS_CONFIG && !reported) {
    /* a case error of the body (not out of memory): at its key */
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", px_context_message(L->ctx));
    px_context_clear(L->ctx);
    st = px_case_fail(c, "lattice.body", "%s", msg);
  }
  if (st != PX_STATUS_OK) px_lattice_grid_free(L->ctx, g);
  px_mem_free(L->ctx, pr);
  return st;
}

static void px_lattice_free_bcs(struct px_context *ctx, struct px_lattice_bc *bc, size_t n) {
  size_t i;
  for (i = 0; bc && i < n; ++i) {
    px_mem_free(ctx, bc[i].accel_f.t);
    px_mem_free(ctx, bc[i].accel_f.v);
    px_mem_free(ctx, bc[i].load_f.t);
    px_mem_free(ctx, bc[i].load_f.v);
  }
  px_mem_free(ctx, bc);
}

static enum px_status px_lattice_read_bcs(struct px_lattice *L, struct px_case *c,
                                          const struct px_lattice_grid *g,
                                          struct px_lattice_bc **out, size_t *nout,
                                          char (*names)[96]) {
  size_t n = 0, i;
  struct px_lattice_bc *bc;
  char p[256], base[64];
  (void)g;
  *out = NULL;
  *nout = 0;
  PX_TRY(px_case_count(c, "lattice.boundary", &n));
  bc = (struct px_lattice_bc *)px_mem_calloc(L->ctx, "lattice.case", n ? n : 1, sizeof *bc);
  if (!bc) return PX_STATUS_NOMEM;
  *out = bc;
  *nout = n;
  for (i = 0; i < n; ++i) {
    size_t nf = 0, k;
    double v[3];
    snprintf(base, sizeof base, "lattice.boundary[%zu]", i);
    if (px_case_has(c, px_case_path_join(p, sizeof p, base, "name"))) {
      const char *nm;
      PX_TRY(px_case_get_string(c, p, &nm));
      snprintf(names[i], sizeof names[i], "boundary condition '%s'", nm);
    } else {
      snprintf(names[i], sizeof names[i], "%s", base);
    }
    bc[i].name = names[i];
    PX_TRY(px_lattice_read_sel(c, px_case_path_join(p, sizeof p, base, "select"), &bc[i].sel));
    PX_TRY(px_case_count(c, px_case_path_join(p, sizeof p, base, "fix"), &nf));
    for (k = 0; k < nf; ++k) {
      char q[256];
      int d;
      snprintf(q, sizeof q, "%s.fix[%zu]", base, k);
      PX_TRY(px_case_get_enum(c, q, &d));
      bc[i].fix |= d == 6 ? 63u : (1u << d);
    }
    if (px_case_has(c, px_case_path_join(p, sizeof p, base, "acceleration"))) {
      PX_TRY(px_case_get_vector(c, p, v, 3));
      memcpy(bc[i].accel, v, sizeof v);
      bc[i].has_accel = 1;
    }
    if (px_case_has(c, px_case_path_join(p, sizeof p, base, "angular_acceleration"))) {
      PX_TRY(px_case_get_vector(c, p, v, 3));
      memcpy(bc[i].accel + 3, v, sizeof v);
      bc[i].has_accel = 1;
    }
    if (px_case_has(c, px_case_path_join(p, sizeof p, base, "force"))) {
      PX_TRY(px_case_get_vector(c, p, v, 3));
      memcpy(bc[i].load, v, sizeof v);
      bc[i].has_load = 1;
    }
    if (px_case_has(c, px_case_path_join(p, sizeof p, base, "moment"))) {
      PX_TRY(px_case_get_vector(c, p, v, 3));
      memcpy(bc[i].load + 3, v, sizeof v);
      bc[i].has_load = 1;
    }
    if (!bc[i].fix && !bc[i].has_accel && !bc[i].has_load)
      PX_TRY(px_case_fail(c, base, "the boundary condition does nothing: give fix, "
                          "acceleration, angular_acceleration, force or moment"));
    PX_TRY(px_lattice_read_tfun(L, c, px_case_path_join(p, sizeof p, base, "function"),
                                &bc[i].accel_f));
    bc[i].load_f = bc[i].accel_f;
    if (bc[i].accel_f.kind == PX_LATTICE_TFUN_TABLE) {
      /* the model copies both; give the load its own arrays */
      PX_TRY(px_lattice_read_tfun(L, c, p, &bc[i].load_f));
    }
  }
  return PX_STATUS_OK;
}

static void px_lattice_destroy(void *state) {
  struct px_lattice *L = (struct px_lattice *)state;
  size_t i;
  if (!L) return;
  px_lattice_output_free(L);
  if (L->e) L->vt->destroy(L->e);
  for (i = 0; i < L->nprobe; ++i) px_mem_free(L->ctx, L->probes[i].cells);
  px_mem_free(L->ctx, L->probes);
  px_lattice_model_free(L->ctx, &L->m);
  px_mem_free(L->ctx, L);
}

/* Largest and smallest normal magnitude of the engine's reals. */
static double px_lattice_real_max(const struct px_lattice *L) {
  return L->precision == PX_PRECISION_SINGLE ? FLT_MAX : DBL_MAX;
}
static double px_lattice_real_min(const struct px_lattice *L) {
  return L->precision == PX_PRECISION_SINGLE ? FLT_MIN : DBL_MIN;
}

/* The key to blame for a constant that is a power of h times a material
 * value: h when it is outside [1 um, 1 km], else the material key. */
static const char *px_lattice_blame(const struct px_lattice *L, const char *material) {
  double h = L->m.grid.h;
  return h < 1e-6 || h > 1e3 ? "lattice.h" : material;
}

/* The model's constants as the engine holds them, each a normal number of
 * its precision (0 where the constant may vanish), and a stable time step:
 * otherwise the first step would divide by 0 or overflow (a blow-up
 * reported at step 1, or "invalid time step 0" without a key). Refused at
 * the key that sets the constant. */
static enum px_status px_lattice_check_scales(struct px_lattice *L, struct px_case *c) {
  const struct px_lattice_model *m = &L->m;
  const struct px_lattice_params *par = &m->par;
  struct lt_fpar_d fp;
  double lo = px_lattice_real_min(L), hi = px_lattice_real_max(L), omega;
  const char *prec = L->precision == PX_PRECISION_SINGLE ? "single" : "double";
  size_t i;
  struct {
    double v;
    const char *key, *what, *unit;
  } q[14];
  px_lattice_fpar_d(m, &fp);
  q[0].v = m->m, q[0].key = px_lattice_blame(L, "lattice.rho");
  q[0].what = "the element mass rho h^3", q[0].unit = "kg";
  q[1].v = 1.0 / m->m, q[1].key = q[0].key, q[1].what = "1/(rho h^3)", q[1].unit = "1/kg";
  q[2].v = m->I, q[2].key = q[0].key;
  q[2].what = "the element inertia rho h^5/6", q[2].unit = "kg m^2";
  q[3].v = 1.0 / m->I, q[3].key = q[0].key, q[3].what = "6/(rho h^5)", q[3].unit = "1/(kg m^2)";
  q[4].v = 0.5 * m->grid.h, q[4].key = "lattice.h", q[4].what = "h/2", q[4].unit = "m";
  q[5].v = m->k, q[5].key = px_lattice_blame(L, "lattice.E");
  q[5].what = "the link stiffness E h", q[5].unit = "N/m";
  q[6].v = m->kb, q[6].key = q[5].key, q[6].what = "the bending stiffness E h^3/12";
  q[6].unit = "N m";
  /* from here on 0 is allowed (no torsion correction, dashpot, strength) */
  q[7].v = m->kt - m->kb, q[7].key = q[5].key, q[7].what = "k_t - k_b", q[7].unit = "N m";
  q[8].v = m->cl, q[8].key = "lattice.zeta", q[8].what = "the link dashpot", q[8].unit = "N s/m";
  q[9].v = m->cr, q[9].key = "lattice.zeta", q[9].what = "the rotational dashpot";
  q[9].unit = "N m s";
  q[10].v = fp.ifn, q[10].key = "lattice.strength.normal", q[10].what = "1/normal";
  q[10].unit = "1/N";
  q[11].v = fp.ift, q[11].key = "lattice.strength.shear", q[11].what = "1/shear";
  q[11].unit = "1/N";
  q[12].v = fp.imb, q[12].key = "lattice.strength.bending", q[12].what = "1/bending";
  q[12].unit = "1/(N m)";
  q[13].v = fp.imt, q[13].key = "lattice.strength.twisting", q[13].what = "1/twisting";
  q[13].unit = "1/(N m)";
  for (i = 0; i < 14; ++i) {
    double a = fabs(q[i].v);
    if (!(a <= hi) || (a < lo && !(i >= 7 && a == 0.0)))
      return px_case_fail(c, q[i].key,
                          "%s = %g %s is not a normal number of %s precision (%g .. %g): the "
                          "engine cannot compute with E = %g Pa, rho = %g kg/m^3, h = %g m",
                          q[i].what, q[i].v, q[i].unit, prec, lo, hi, par->E, par->rho,
                          m->grid.h);
  }
  if (!(par->alpha <= hi))
    return px_case_fail(c, "lattice.damping", "%g 1/s is beyond %s precision (%g)", par->alpha,
                        prec, hi);
  omega = 3.74 * sqrt(par->E / par->rho) / m->grid.h;
  if (!(L->dt_limit >= lo && L->dt_limit <= hi)) {
    const char *key = L->integ == PX_LATTICE_INTEGRATOR_RK4 && par->alpha > 0.0
                          ? "lattice.damping"
                          : (par->zeta > 0.0 ? "lattice.zeta" : px_lattice_blame(L, "lattice.E"));
    return px_case_fail(c, key,
                        "no stable time step: the limit of %s for this lattice is %g s (highest "
                        "frequency 3.74 sqrt(E/rho)/h = %g rad/s, zeta = %g, damping = %g 1/s), "
                        "not a normal number of %s precision%s",
                        L->integ == PX_LATTICE_INTEGRATOR_RK4 ? "rk4" : "leapfrog", L->dt_limit,
                        omega, par->zeta, par->alpha, prec,
                        L->integ == PX_LATTICE_INTEGRATOR_RK4 && par->alpha > 0.0
                            ? " (leapfrog treats the global damping semi-implicitly: no limit)"
                            : "");
  }
  return PX_STATUS_OK;
}

/* Largest |factor| of a time function. */
static double px_lattice_tfun_amax(const struct px_lattice_tfun *f) {
  double a = 0.0;
  size_t i;
  if (f->kind != PX_LATTICE_TFUN_TABLE) return 1.0;
  for (i = 0; i < f->n; ++i) a = fmax(a, fabs(f->v[i]));
  return a;
}

/* Every prescribed acceleration and the acceleration each load gives an
 * element (spread over its selection, at the largest factor of its time
 * function) within the engine's precision, with room for the 64 boundary
 * conditions that may add up on one element: otherwise the group table or
 * the first kick holds infinities and step 1 blows up. */
static enum px_status px_lattice_check_loads(struct px_lattice *L, struct px_case *c) {
  static const char *const keys[4] = {"acceleration", "angular_acceleration", "force", "moment"};
  static const char *const units[4] = {"m/s^2", "rad/s^2", "N", "N m"};
  const struct px_lattice_model *m = &L->m;
  double hi = px_lattice_real_max(L) / 64.0;
  size_t i;
  int k;
  for (i = 0; i < m->nbc; ++i) {
    const struct px_lattice_bc *b = &m->bc[i];
    for (k = 0; k < 12; ++k) {
      int load = k >= 6, rot = (k % 6) >= 3;
      double v, f, a, per;
      char p[128];
      if (load ? !b->has_load : !b->has_accel) continue;
      f = px_lattice_tfun_amax(load ? &b->load_f : &b->accel_f);
      v = load ? b->load[k - 6] : b->accel[k];
      per = load ? (double)m->bc_count[i] * (rot ? m->I : m->m) : 1.0;
      a = fabs(v) * f / per;
      if (a <= hi) continue;
      snprintf(p, sizeof p, "lattice.boundary[%zu].%s", i, keys[k / 3]);
      return px_case_fail(c, p,
                          "component %d = %g %s (x %g, the largest factor of the time function%s) "
                          "accelerates an element by %g %s: beyond %s precision (at most %g, "
                          "with room for 64 boundary conditions on one element)",
                          k % 3, v, units[k / 3], f,
                          load ? ", spread over the selection's elements" : "", a,
                          rot ? "rad/s^2" : "m/s^2",
                          L->precision == PX_PRECISION_SINGLE ? "single" : "double", hi);
    }
  }
  return PX_STATUS_OK;
}

static enum px_status px_lattice_read_probes(struct px_lattice *L, struct px_case *c) {
  size_t n = 0, i, k;
  double lists = 0.0; /* bytes of the probes' element lists so far */
  char p[256], base[64];
  PX_TRY(px_case_count(c, "lattice.probes", &n));
  L->probes = (struct px_lattice_probe *)px_mem_calloc(L->ctx, "lattice.probes", n ? n : 1,
                                                        sizeof *L->probes);
  if (!L->probes) return PX_STATUS_NOMEM;
  L->nprobe = n;
  for (i = 0; i < n; ++i) {
    struct px_lattice_sel s;
    const char *nm;
    snprintf(base, sizeof base, "lattice.probes[%zu]", i);
    PX_TRY(px_case_get_string(c, px_case_path_join(p, sizeof p, base, "name"), &nm));
    if (strlen(nm) == 0 || strlen(nm) >= sizeof L->probes[i].name || strpbrk(nm, ",\"\n"))
      PX_TRY(px_case_fail(c, p, "a probe name is 1..63 characters without commas or quotes"));
    snprintf(L->probes[i].name, sizeof L->probes[i].name, "%s", nm);
    PX_TRY(px_lattice_read_sel(c, px_case_path_join(p, sizeof p, base, "select"), &s));
    PX_TRY(px_lattice_check_sel(L, c, p, &s, &L->probes[i].cells, &L->probes[i].count));
    /* the lists stay for the run: with the lattice they must fit too */
    lists += (double)L->probes[i].count * sizeof(size_t);
    PX_TRY(px_sim_require_memory(L->sim, L->need_host + lists, p,
                                 "the lattice and the element lists of its probes"));
    for (k = 0; k < L->probes[i].count; ++k)
      L->probes[i].cells[k] = px_lattice_index(&L->m, L->probes[i].cells[k]);
  }
  return PX_STATUS_OK;
}

static enum px_status px_lattice_initial(struct px_lattice *L, struct px_case *c) {
  size_t n = 0, i, k;
  struct lt_el_d *y;
  char p[256], base[64];
  enum px_status st = PX_STATUS_OK;
  PX_TRY(px_case_count(c, "lattice.initial", &n));
  if (n == 0) return PX_STATUS_OK;
  y = (struct lt_el_d *)px_mem_alloc(L->ctx, "lattice.initial", L->m.nalloc * sizeof *y);
  if (!y) return PX_STATUS_NOMEM;
  st = L->vt->get_state(L->e, y, NULL);
  for (i = 0; i < n && st == PX_STATUS_OK; ++i) {
    struct px_lattice_sel s;
    size_t *cells = NULL, cnt = 0;
    double v[3], w[3];
    snprintf(base, sizeof base, "lattice.initial[%zu]", i);
    st = px_lattice_read_sel(c, px_case_path_join(p, sizeof p, base, "select"), &s);
    if (st == PX_STATUS_OK) st = px_lattice_check_sel(L, c, p, &s, &cells, &cnt);
    if (st == PX_STATUS_OK)
      st = px_case_get_vector(c, px_case_path_join(p, sizeof p, base, "velocity"), v, 3);
    if (st == PX_STATUS_OK)
      st = px_case_get_vector(c, px_case_path_join(p, sizeof p, base, "angular_velocity"), w, 3);
    /* the engine's reals hold them (a float engine: +-3.4e38) */
    for (k = 0; st == PX_STATUS_OK && k < 6; ++k)
      if (!(fabs(k < 3 ? v[k] : w[k - 3]) <= px_lattice_real_max(L)))
        st = px_case_fail(c, px_case_path_join(p, sizeof p, base,
                                               k < 3 ? "velocity" : "angular_velocity"),
                          "component %zu = %g is beyond %s precision", k % 3,
                          k < 3 ? v[k] : w[k - 3],
                          L->precision == PX_PRECISION_SINGLE ? "single" : "double");
    for (k = 0; st == PX_STATUS_OK && k < cnt; ++k) {
      struct lt_el_d *e = &y[px_lattice_index(&L->m, cells[k])];
      e->v = lt_v3_make_d(v[0], v[1], v[2]);
      e->W = lt_v3_make_d(w[0], w[1], w[2]);
    }
    px_mem_free(L->ctx, cells);
  }
  if (st == PX_STATUS_OK) st = L->vt->set_state(L->e, y, NULL);
  px_mem_free(L->ctx, y);
  return st;
}

static enum px_status px_lattice_create(struct px_sim *sim, void **state) {
  struct px_context *ctx = px_sim_context(sim);
  struct px_case *c = (struct px_case *)px_sim_case(sim);
  struct px_lattice *L;
  struct px_lattice_grid g;
  struct px_lattice_params par;
  struct px_lattice_bc *bcs = NULL;
  struct px_lattice_engine_opts o;
  size_t nbc = 0, i;
  char (*names)[96] = NULL;
  int integ = 0, scheme = 0, view = 0;
  enum px_status st;
  *state = NULL;
  L = (struct px_lattice *)px_mem_calloc(ctx, "lattice", 1, sizeof *L);
  if (!L) return PX_STATUS_NOMEM;
  *state = L;
  L->sim = sim;
  L->ctx = ctx;
  L->fields_time = NAN;
  L->fields_step = -1;
  L->static_error = NAN;
  L->static_since = NAN;
  L->drawn_scale = NAN;
  memset(&par, 0, sizeof par);
  memset(&g, 0, sizeof g);
  PX_TRY(px_case_get_real(c, "lattice.E", &par.E));
  PX_TRY(px_case_get_real(c, "lattice.rho", &par.rho));
  PX_TRY(px_case_get_real(c, "lattice.zeta", &par.zeta));
  PX_TRY(px_case_get_real(c, "lattice.damping", &par.alpha));
  PX_TRY(px_case_get_real(c, "lattice.strength.normal", &par.f_nc));
  PX_TRY(px_case_get_real(c, "lattice.strength.shear", &par.f_tc));
  PX_TRY(px_case_get_real(c, "lattice.strength.bending", &par.m_bc));
  PX_TRY(px_case_get_real(c, "lattice.strength.twisting", &par.m_tc));
  PX_TRY(px_case_get_bool(c, "lattice.quasi_static", &L->quasi_static));
  PX_TRY(px_case_get_real(c, "lattice.static_tolerance", &L->static_tol));
  PX_TRY(px_case_get_enum(c, "lattice.integrator", &integ));
  PX_TRY(px_case_get_enum(c, "lattice.scheme", &scheme));
  PX_TRY(px_case_get_real(c, "lattice.dt_safety", &L->safety));
  PX_TRY(px_case_get_enum(c, "lattice.picture.view", &view));
  PX_TRY(px_case_get_real(c, "lattice.picture.scale", &L->picture_scale));
  L->view = (enum px_lattice_view)view;
  L->integ = (enum px_lattice_integrator)integ;
  if (px_case_has(c, "title")) {
    const char *t;
    PX_TRY(px_case_get_string(c, "title", &t));
    snprintf(L->title, sizeof L->title, "%s", t);
  }

  /* engine: by backend name; precision single or double (mixed = double);
   * picked first, so that the size check knows what it allocates */
  L->precision = px_sim_precision(sim) == PX_PRECISION_SINGLE ? PX_PRECISION_SINGLE
                                                               : PX_PRECISION_DOUBLE;
  L->vt = (const struct px_lattice_engine_i *)PX_BACKEND_PICK(px_sim_backend(sim), "lattice",
                                                              px_lattice_engines);
  if (!L->vt) return px_context_status(ctx);
  memset(&o, 0, sizeof o);
  o.integ = L->integ;
  o.precision = L->precision;
  o.scheme = (enum px_lattice_scheme)scheme;
  o.threads = px_backend_threads(px_sim_backend(sim));
  o.backend = px_sim_backend(sim);

  PX_TRY(px_lattice_read_body(L, c, &o, &g));
  {
    size_t nb = 0;
    PX_TRY(px_case_count(c, "lattice.boundary", &nb));
    names = (char(*)[96])px_mem_calloc(ctx, "lattice.case", nb ? nb : 1, sizeof *names);
    if (!names) {
      px_lattice_grid_free(ctx, &g);
      return PX_STATUS_NOMEM;
    }
  }
  st = px_lattice_read_bcs(L, c, &g, &bcs, &nbc, names);
  /* every selection must match something: report each at its key */
  for (i = 0; st == PX_STATUS_OK && i < nbc; ++i) {
    char p[128];
    snprintf(p, sizeof p, "lattice.boundary[%zu].select", i);
    L->m.grid = g; /* borrowed for the check */
    st = px_lattice_check_sel(L, c, p, &bcs[i].sel, NULL, NULL);
    memset(&L->m.grid, 0, sizeof L->m.grid);
  }
  if (st == PX_STATUS_OK) {
    st = px_lattice_model_build(ctx, &L->m, &g, &par, bcs, nbc);
    if (st == PX_STATUS_CONFIG) {
      char msg[1024];
      snprintf(msg, sizeof msg, "%s", px_context_message(ctx));
      px_context_clear(ctx);
      st = px_case_fail(c, "lattice", "%s", msg);
    }
  } else {
    px_lattice_grid_free(ctx, &g);
  }
  px_lattice_free_bcs(ctx, bcs, nbc);
  px_mem_free(ctx, names);
  PX_TRY(st);

  /* time step: automatic, or checked against the stability limit */
  L->dt_limit = px_lattice_model_dt_limit(&L->m, L->integ);
  PX_TRY(px_lattice_check_scales(L, c));
  PX_TRY(px_lattice_check_loads(L, c));
  if (px_case_has(c, "time.dt")) {
    double dt;
    PX_TRY(px_case_get_real(c, "time.dt", &dt));
    if (dt > L->dt_limit)
      return px_case_fail(c, "time.dt",
                          "dt = %g s is above the stability limit %g s of %s for this lattice "
                          "(%.3g h/c with h = %g m, c = sqrt(E/rho) = %.6g m/s); leave dt out "
                          "to get %g x the limit",
                          dt, L->dt_limit, L->integ == PX_LATTICE_INTEGRATOR_RK4 ? "rk4" : "leapfrog",
                          L->dt_limit * sqrt(par.E / par.rho) / L->m.grid.h, L->m.grid.h,
                          sqrt(par.E / par.rho), L->safety);
    /* the engine's dt (a float engine: below 1.2e-38 s it is 0 or loses
     * digits, and the body would not move) */
    if (!(dt >= px_lattice_real_min(L)))
      return px_case_fail(c, "time.dt", "dt = %g s is below what %s precision holds (%g s)", dt,
                          L->precision == PX_PRECISION_SINGLE ? "single" : "double",
                          px_lattice_real_min(L));
  }

  PX_TRY(L->vt->create(ctx, &L->m, &o, &L->e));
  if (o.scheme == PX_LATTICE_SCHEME_AUTO)
    px_sim_note_auto(sim, "lattice.scheme", "%s (the faster on the %s engine)",
                     L->vt->scheme(L->e) == PX_LATTICE_SCHEME_LINK_ONCE ? "link_once" : "gather",
                     L->vt->name);
  L->alpha = par.alpha;
  L->settle_time = px_lattice_model_settle_time(&L->m);
  PX_TRY(px_lattice_read_probes(L, c));
  PX_TRY(px_lattice_initial(L, c));
  {
    char est[32];
    px_lattice_bytes_text(L->need_host, 0, est, sizeof est);
    px_log(ctx, PX_LOG_LEVEL_INFO,
           "lattice: %zu elements (grid %d x %d x %d, h = %g m), %s on %s in %s precision, %zu "
           "bytes per grid cell, stable dt %.4g s; host memory at most %s (estimate with "
           "outputs and checkpoints)",
           L->m.grid.count, L->m.grid.n[0], L->m.grid.n[1], L->m.grid.n[2], L->m.grid.h,
           L->integ == PX_LATTICE_INTEGRATOR_RK4 ? "RK4" : "leapfrog", L->vt->name,
           L->precision == PX_PRECISION_SINGLE ? "single" : "double", L->vt->bytes(L->e),
           L->dt_limit, est);
  }
  return PX_STATUS_OK;
}

static enum px_status px_lattice_time_step(void *state, double *dt) {
  struct px_lattice *L = (struct px_lattice *)state;
  *dt = L->safety * L->dt_limit;
  return PX_STATUS_OK;
}

/* Steps between updates of the quasi-static damping and checks of
 * convergence. */
#define PX_LATTICE_RELAX_EVERY 10

/* Quasi-static convergence at time t, after a relaxation update. The
 * estimate static_error (px_lattice_relax_update) must stay <= static_tol
 * at every check for 1/omega = 2/alpha, a radian of the slowest mode: a
 * single check could fall on a moment when an oscillating mode is at rest.
 * Not before the loads have become constant (a body that follows a slow
 * ramp changes slowly without being static). */
static void px_lattice_static_check(struct px_lattice *L, double t) {
  int below = t >= L->settle_time && L->static_error <= L->static_tol;
  if (!below) {
    L->static_since = NAN;
    return;
  }
  if (isnan(L->static_since)) L->static_since = t;
  if (L->alpha > 0.0 && t - L->static_since >= 2.0 / L->alpha && !L->converged) {
    L->converged = 1;
    px_log(L->ctx, PX_LOG_LEVEL_INFO,
           "lattice: static equilibrium at t = %.6g s: static_error %.3g <= "
           "lattice.static_tolerance %.3g since t = %.6g s (1/omega = %.3g s)",
           t, L->static_error, L->static_tol, L->static_since, 2.0 / L->alpha);
  }
}

static enum px_status px_lattice_step(void *state, long step, double t, double dt) {
  struct px_lattice *L = (struct px_lattice *)state;
  L->fields_step = -1;
  PX_TRY(L->vt->run(L->e, step, t, dt, 1));
  if (L->quasi_static && (step + 1) % PX_LATTICE_RELAX_EVERY == 0) {
    PX_TRY(px_lattice_relax_update(L->vt, L->e, &L->alpha, &L->static_error));
    px_lattice_static_check(L, (double)(step + 1) * dt);
  }
  return PX_STATUS_OK;
}

static int px_lattice_done(const void *state) {
  const struct px_lattice *L = (const struct px_lattice *)state;
  return L->quasi_static && L->static_tol > 0.0 && L->converged;
}

/* ---------------------------------------------------------------------------
 * Checkpoints: the state in double (exact for a float engine too), the link
 * flags, the damping in use, the broken-link count and the quasi-static
 * convergence check (static_error, static_since; whether it had converged
 * is decided again at the next check, under the tolerance of the resumed
 * case). */
static enum px_status px_lattice_save(void *state, struct px_checkpoint_writer *w) {
  struct px_lattice *L = (struct px_lattice *)state;
  size_t n = L->m.nalloc;
  struct lt_el_d *y = (struct lt_el_d *)px_mem_alloc(L->ctx, "lattice.checkpoint", n * sizeof *y);
  uint8_t *links = (uint8_t *)px_mem_alloc(L->ctx, "lattice.checkpoint", n);
  double extra[2];
  enum px_status st;
  int64_t broken = L->vt->broken(L->e);
  if (!y || !links) {
    px_mem_free(L->ctx, y);
    px_mem_free(L->ctx, links);
    return PX_STATUS_NOMEM;
  }
  st = L->vt->get_state(L->e, y, links);
  extra[0] = L->alpha;
  extra[1] = (double)L->m.grid.count;
  if (st == PX_STATUS_OK)
    st = px_checkpoint_write(w, "lattice.state", PX_DTYPE_F64, (uint64_t)n * 13, y);
  if (st == PX_STATUS_OK) st = px_checkpoint_write(w, "lattice.links", PX_DTYPE_U8, n, links);
  if (st == PX_STATUS_OK) st = px_checkpoint_write(w, "lattice.scalars", PX_DTYPE_F64, 2, extra);
  if (st == PX_STATUS_OK) st = px_checkpoint_write(w, "lattice.broken", PX_DTYPE_I64, 1, &broken);
  if (st == PX_STATUS_OK) {
    double conv[2];
    conv[0] = L->static_error;
    conv[1] = L->static_since;
    st = px_checkpoint_write(w, "lattice.static", PX_DTYPE_F64, 2, conv);
  }
  px_mem_free(L->ctx, y);
  px_mem_free(L->ctx, links);
  return st;
}

/* ---------------------------------------------------------------------------
 * Checkpoint loading. The file is not trusted (docs/running.md, "What partix
 * trusts"): its CRCs only say it is what was written, not that a partix
 * wrote it. Every section is checked against the case before any of it is
 * used: sizes, link flags (only links the body has, both ends alike), the
 * broken-link count (the links the flags miss), the state (void cells and
 * padding at rest, elements finite within the engine's precision, unit
 * quaternions) and the scalars; a failure is PX_STATUS_FORMAT naming the
 * section. */

/* Grid cell of padded entry i, or (size_t)-1 for padding. */
static size_t px_lattice_cell_of(const struct px_lattice_model *m, size_t i) {
  size_t r, x;
  if (i < m->pad || i >= m->nalloc - m->pad) return (size_t)-1;
  r = (i - m->pad) / m->n0p;
  x = (i - m->pad) % m->n0p;
  return x < (size_t)m->grid.n[0] ? x + (size_t)m->grid.n[0] * r : (size_t)-1;
}

/* "element (i, j, k)" or "padding entry i" into buf. */
static const char *px_lattice_entry_name(const struct px_lattice_model *m, size_t i, char *buf,
                                         size_t size) {
  size_t c = px_lattice_cell_of(m, i), n0 = (size_t)m->grid.n[0], n1 = (size_t)m->grid.n[1];
  if (c == (size_t)-1)
    snprintf(buf, size, "padding entry %zu", i);
  else
    snprintf(buf, size, "%s (%zu, %zu, %zu)", m->grid.occ[c] ? "element" : "void cell", c % n0,
             (c / n0) % n1, c / (n0 * n1));
  return buf;
}

/* The section `name` holds `count` values of `type`: else FORMAT naming
 * it (before anything is allocated or read). */
static enum px_status px_lattice_ck_section(struct px_lattice *L, struct px_checkpoint *ck,
                                            const char *name, enum px_dtype type,
                                            uint64_t count) {
  enum px_dtype t;
  uint64_t n = 0;
  enum px_status st = px_checkpoint_find(ck, name, &t, &n);
  if (st == PX_STATUS_NOT_FOUND) {
    px_context_clear(L->ctx);
    return px_context_fail(L->ctx, PX_STATUS_FORMAT, "section '%s' is missing", name);
  }
  PX_TRY(st);
  if (t != type || n != count)
    return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                           "section '%s' holds %llu values of type %d; the case needs %llu of "
                           "type %d",
                           name, (unsigned long long)n, (int)t, (unsigned long long)count,
                           (int)type);
  return PX_STATUS_OK;
}

/* Link flags: a subset of the body's (links only break), bits 6-7 clear, both
 * ends of a link alike (fracture decides each link once, canonically). The
 * number of links missing into *missing. */
static enum px_status px_lattice_ck_links(struct px_lattice *L, const uint8_t *links,
                                          uint64_t *missing) {
  const struct px_lattice_model *m = &L->m;
  uint64_t ends = 0;
  size_t i;
  char a_name[96], b_name[96];
  for (i = 0; i < m->nalloc; ++i) {
    int a;
    if (links[i] & ~m->links[i])
      return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                             "section 'lattice.links': %s has link flags 0x%02x, its body only "
                             "0x%02x",
                             px_lattice_entry_name(m, i, a_name, sizeof a_name), links[i],
                             m->links[i]);
    for (a = 0; a < 3; ++a) {
      size_t j = i + (size_t)m->stride[a];
      if (!(m->links[i] & PX_LATTICE_LINK_PLUS(a))) continue;
      /* j < nalloc: a body link's plus end is an element */
      if (!(links[i] & PX_LATTICE_LINK_PLUS(a)) != !(links[j] & PX_LATTICE_LINK_MINUS(a)))
        return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                               "section 'lattice.links': the link between %s and %s is broken "
                               "at one end only",
                               px_lattice_entry_name(m, i, a_name, sizeof a_name),
                               px_lattice_entry_name(m, j, b_name, sizeof b_name));
      if (!(links[i] & PX_LATTICE_LINK_PLUS(a))) ++ends;
    }
  }
  *missing = ends;
  return PX_STATUS_OK;
}

/* The state: void cells and padding exactly at rest (their links are
 * evaluated and multiplied by 0: a NaN there would spread); elements finite
 * and within the engine's precision, orientation a unit quaternion (to
 * 1e-3: the engines renormalize every step, in float to ~1e-7). */
static enum px_status px_lattice_ck_state(struct px_lattice *L, const struct lt_el_d *y) {
  const struct px_lattice_model *m = &L->m;
  double hi = px_lattice_real_max(L);
  size_t i;
  char name[96];
  for (i = 0; i < m->nalloc; ++i) {
    const struct lt_el_d *e = &y[i];
    const double c[13] = {e->u.x, e->u.y, e->u.z, e->q.w, e->q.x, e->q.y, e->q.z,
                          e->v.x, e->v.y, e->v.z, e->W.x, e->W.y, e->W.z};
    static const char *const what[13] = {
        "displacement x", "displacement y", "displacement z", "orientation w",
        "orientation x", "orientation y", "orientation z", "velocity x", "velocity y",
        "velocity z", "angular velocity x", "angular velocity y", "angular velocity z"};
    int k;
    if (m->group[i] == 0) {
      for (k = 0; k < 13; ++k)
        if (c[k] != (k == 3 ? 1.0 : 0.0))
          return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                                 "section 'lattice.state': %s is not at rest (%s = %g)",
                                 px_lattice_entry_name(m, i, name, sizeof name), what[k], c[k]);
      continue;
    }
    for (k = 0; k < 13; ++k)
      if (!(fabs(c[k]) <= hi))
        return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                               "section 'lattice.state': %s has %s = %g (not a finite value of "
                               "%s precision)",
                               px_lattice_entry_name(m, i, name, sizeof name), what[k], c[k],
                               L->precision == PX_PRECISION_SINGLE ? "single" : "double");
    {
      /* scaled by the largest component: no overflow for finite ones */
      double big = fmax(fmax(fabs(e->q.w), fabs(e->q.x)), fmax(fabs(e->q.y), fabs(e->q.z)));
      double qn = 0.0;
      if (big > 0.0)
        qn = big * sqrt((e->q.w / big) * (e->q.w / big) + (e->q.x / big) * (e->q.x / big) +
                        (e->q.y / big) * (e->q.y / big) + (e->q.z / big) * (e->q.z / big));
      if (!(fabs(qn - 1.0) <= 1e-3))
        return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                               "section 'lattice.state': %s has an orientation quaternion of "
                               "norm %g (not 1)",
                               px_lattice_entry_name(m, i, name, sizeof name), qn);
    }
  }
  return PX_STATUS_OK;
}

static enum px_status px_lattice_load(void *state, struct px_checkpoint *ck) {
  struct px_lattice *L = (struct px_lattice *)state;
  const struct px_lattice_model *m = &L->m;
  size_t n = m->nalloc;
  struct lt_el_d *y = NULL;
  uint8_t *links = NULL;
  double extra[2] = {0, 0}, conv[2] = {NAN, NAN}, omega;
  double alpha_max;
  int64_t broken = 0;
  uint64_t missing = 0;
  int has_static = 0;
  enum px_status st;
  /* sizes first, from the index: nothing read or allocated yet */
  PX_TRY(px_lattice_ck_section(L, ck, "lattice.state", PX_DTYPE_F64, (uint64_t)n * 13));
  PX_TRY(px_lattice_ck_section(L, ck, "lattice.links", PX_DTYPE_U8, n));
  PX_TRY(px_lattice_ck_section(L, ck, "lattice.scalars", PX_DTYPE_F64, 2));
  PX_TRY(px_lattice_ck_section(L, ck, "lattice.broken", PX_DTYPE_I64, 1));
  {
    enum px_dtype t;
    uint64_t cnt;
    /* optional: checkpoints from before quasi-static convergence */
    if (px_checkpoint_find(ck, "lattice.static", &t, &cnt) == PX_STATUS_OK) {
      PX_TRY(px_lattice_ck_section(L, ck, "lattice.static", PX_DTYPE_F64, 2));
      has_static = 1;
    } else {
      px_context_clear(L->ctx);
    }
  }
  /* the scalars */
  PX_TRY(px_checkpoint_read(ck, "lattice.scalars", PX_DTYPE_F64, 2, extra));
  PX_TRY(px_checkpoint_read(ck, "lattice.broken", PX_DTYPE_I64, 1, &broken));
  if (has_static) PX_TRY(px_checkpoint_read(ck, "lattice.static", PX_DTYPE_F64, 2, conv));
  if (!(extra[1] == (double)m->grid.count))
    return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                           "section 'lattice.scalars': the checkpoint holds %g elements but the "
                           "case builds %zu",
                           extra[1], m->grid.count);
  /* the damping in use: the case's, or (quasi-static) 2 omega of a
   * Rayleigh quotient, at most twice the highest frequency 3.74 c/h (x2
   * for round-off), or the case's initial one */
  omega = 3.74 * sqrt(m->par.E / m->par.rho) / m->grid.h;
  alpha_max = fmax(m->par.alpha, 4.0 * omega);
  if (L->quasi_static ? !(extra[0] >= 0.0 && extra[0] <= alpha_max)
                      : !(extra[0] == m->par.alpha))
    return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                           "section 'lattice.scalars': damping %g 1/s %s", extra[0],
                           L->quasi_static ? "outside [0, 4 x the highest frequency]"
                                           : "differs from the case's lattice.damping");
  /* static_error (>= 0) and the time since it stayed below the tolerance
   * (>= 0; it may lie past the checkpoint's time after a resume with a
   * smaller time.dt, which only delays convergence); NaN: none */
  if (!(isnan(conv[0]) || (conv[0] >= 0.0 && conv[0] < INFINITY)) ||
      !(isnan(conv[1]) || (conv[1] >= 0.0 && conv[1] < INFINITY)))
    return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                           "section 'lattice.static': static_error %g and the time since it "
                           "converged %g s must be finite and >= 0 (or NaN: none)",
                           conv[0], conv[1]);
  /* the arrays */
  y = (struct lt_el_d *)px_mem_alloc(L->ctx, "lattice.checkpoint", n * sizeof *y);
  links = (uint8_t *)px_mem_alloc(L->ctx, "lattice.checkpoint", n);
  if (!y || !links) {
    px_mem_free(L->ctx, y);
    px_mem_free(L->ctx, links);
    return PX_STATUS_NOMEM;
  }
  st = px_checkpoint_read(ck, "lattice.state", PX_DTYPE_F64, (uint64_t)n * 13, y);
  if (st == PX_STATUS_OK) st = px_checkpoint_read(ck, "lattice.links", PX_DTYPE_U8, n, links);
  if (st == PX_STATUS_OK) st = px_lattice_ck_links(L, links, &missing);
  if (st == PX_STATUS_OK && !(broken >= 0 && (uint64_t)broken == missing))
    st = px_context_fail(L->ctx, PX_STATUS_FORMAT,
                         "section 'lattice.broken': %lld broken links, but the link flags miss "
                         "%llu",
                         (long long)broken, (unsigned long long)missing);
  if (st == PX_STATUS_OK) st = px_lattice_ck_state(L, y);
  /* all checked: use it */
  if (st == PX_STATUS_OK) st = L->vt->set_state(L->e, y, links);
  if (st == PX_STATUS_OK) st = L->vt->set_broken(L->e, (long)broken);
  if (st == PX_STATUS_OK) {
    L->alpha = extra[0];
    L->vt->set_alpha(L->e, L->alpha);
    if (has_static) {
      L->static_error = conv[0];
      L->static_since = conv[1];
    }
  }
  px_mem_free(L->ctx, y);
  px_mem_free(L->ctx, links);
  return st;
}

static long px_lattice_count(const void *state) {
  return (long)((const struct px_lattice *)state)->m.grid.count;
}

/* Keys that may change on resume: what the pictures show and when a
 * quasi-static run counts as converged. */
static const char *const px_lattice_resume_keys[] = {"lattice.picture", "lattice.static_tolerance",
                                                     NULL};

const struct px_solver_i px_solver_lattice = {
    .name = "lattice",
    .summary = "dynamic stress-strain state of a solid: bonded 6-DOF elements on a regular grid",
    .create = px_lattice_create,
    .destroy = px_lattice_destroy,
    .time_step = px_lattice_time_step,
    .step = px_lattice_step,
    .snapshot = px_lattice_snapshot,
    .series = px_lattice_series,
    .picture = px_lattice_picture,
    .finish = px_lattice_finish,
    .save = px_lattice_save,
    .load = px_lattice_load,
    .done = px_lattice_done,
    .count = px_lattice_count,
    .report = px_lattice_report,
    .resume_keys = px_lattice_resume_keys};
