/* The `lattice` solver: dynamic stress-strain state of a solid body as a
 * regular grid of bonded 6-DOF elements (spec: shared/spec/lattice.md; user
 * docs: docs/lattice.md). This file holds the setup from a case and the
 * time step; the case section's keys are in lattice_schema.c, checkpoints in
 * lattice_checkpoint.c, the physics in lattice_kernel.h, the loops in the
 * engines (lattice_cpu.c, lattice_opencl.c), the outputs in lattice_output.c. */
#include "solvers/lattice/lattice.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "compute/backend_impl.h"
#include "core/comm.h"
#include "core/text.h"
#include "partix/memory.h"
#include "solvers/lattice/lattice_ref.h"

/* ---------------------------------------------------------------------------
 * Setup */

static const void *const px_lattice_engines[] = {&px_lattice_engine_cpu,
                                                 PX_IF_OPENCL(&px_lattice_engine_opencl, )};

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
    if (n != nv) return px_case_fail(c, path, "the table has %zu times but %zu values", n, nv);
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
        return px_case_fail(c, p, "times must increase by finite steps (t[%zu] = %g after %g)", i,
                            f->t[i], f->t[i - 1]);
      if (!isfinite(f->v[i] - f->v[i - 1]))
        return px_case_fail(c, pv, "value[%zu] - value[%zu] = %g - %g overflows", i, i - 1, f->v[i],
                            f->v[i - 1]);
    }
  }
  return PX_STATUS_OK;
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
      PX_TRY(px_case_fail(c, base,
                          "the boundary condition does nothing: give fix, "
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
  px_lattice_ranks_free(L);
  if (L->e) L->vt->destroy(L->e);
  px_lattice_model_free(L->ctx, &L->wm); /* after the engine, which borrows it */
  for (i = 0; i < L->nprobe; ++i) px_mem_free(L->ctx, L->probes[i].cells);
  px_mem_free(L->ctx, L->probes);
  px_lattice_model_free(L->ctx, &L->m);
  px_mem_free(L->ctx, L);
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
  struct lt_fpar fp;
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
                          q[i].what, q[i].v, q[i].unit, prec, lo, hi, par->E, par->rho, m->grid.h);
  }
  if (!(par->alpha <= hi))
    return px_case_fail(c, "lattice.damping", "%g 1/s is beyond %s precision (%g)", par->alpha,
                        prec, hi);
  omega = 3.74 * sqrt(par->E / par->rho) / m->grid.h * px_lattice_model_stiffen(m);
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
      return px_case_fail(
          c, p,
          "component %d = %g %s (x %g, the largest factor of the time function%s) "
          "accelerates an element by %g %s: beyond %s precision (at most %g, "
          "with room for 64 boundary conditions on one element)",
          k % 3, v, units[k / 3], f, load ? ", spread over the selection's elements" : "", a,
          rot ? "rad/s^2" : "m/s^2", L->precision == PX_PRECISION_SINGLE ? "single" : "double", hi);
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
    /* the name heads the probe's probes.csv columns and its summary.json
     * entries: a second probe of one name would write over the first's */
    for (k = 0; k < i; ++k)
      if (strcmp(L->probes[k].name, nm) == 0)
        PX_TRY(px_case_fail(c, p,
                            "a probe named '%s' already exists (lattice.probes[%zu]): each probe "
                            "writes its own NAME.* columns of probes.csv and summary.json "
                            "entries, which two of one name would overwrite",
                            nm, k));
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
  struct lt_el *y;
  char p[256], base[64];
  enum px_status st = PX_STATUS_OK;
  PX_TRY(px_case_count(c, "lattice.initial", &n));
  if (n == 0) return PX_STATUS_OK;
  /* the engine's state (over ranks, its window's) */
  y = (struct lt_el *)px_mem_alloc(L->ctx, "lattice.initial",
                                   px_lattice_engine_model(L)->nalloc * sizeof *y);
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
        st = px_case_fail(
            c, px_case_path_join(p, sizeof p, base, k < 3 ? "velocity" : "angular_velocity"),
            "component %zu = %g is beyond %s precision", k % 3, k < 3 ? v[k] : w[k - 3],
            L->precision == PX_PRECISION_SINGLE ? "single" : "double");
    for (k = 0; st == PX_STATUS_OK && k < cnt; ++k) {
      const size_t at = px_lattice_local_index(L, cells[k]);
      struct lt_el *e;
      if (at == (size_t)-1) continue; /* another rank's */
      e = &y[at];
      e->v = lt_v3_make(v[0], v[1], v[2]);
      e->W = lt_v3_make(w[0], w[1], w[2]);
    }
    px_mem_free(L->ctx, cells);
  }
  if (st == PX_STATUS_OK) st = L->vt->set_state(L->e, y, NULL);
  px_mem_free(L->ctx, y);
  return st;
}

/* The engine and, over MPI ranks, its decomposition, with lattice.scheme
 * auto resolved and noted: the engine's faster scheme, but gather when
 * there are more ranks than z-planes (link-once splits z only and would be
 * refused; gather takes a (y, z) rank grid). */
static enum px_status px_lattice_engine_start(struct px_lattice *L, struct px_sim *sim,
                                              struct px_case *c, struct px_lattice_engine_opts *o) {
  const int ranks = px_comm_size(px_context_comm(L->ctx));
  const int asked = o->scheme == PX_LATTICE_SCHEME_AUTO;
  const int few = asked && ranks > L->m.grid.n[2];
  if (few) o->scheme = PX_LATTICE_SCHEME_GATHER;
  PX_TRY(px_lattice_ranks_create(L, c, o));
  if (few)
    px_sim_note_auto(sim, "lattice.scheme",
                     "gather (%d ranks, %d z-plane%s: link_once splits z only, gather a y x z "
                     "rank grid)",
                     ranks, L->m.grid.n[2], L->m.grid.n[2] == 1 ? "" : "s");
  else if (asked)
    px_sim_note_auto(sim, "lattice.scheme", "%s (the faster on the %s engine)",
                     L->vt->scheme(L->e) == PX_LATTICE_SCHEME_LINK_ONCE ? "link_once" : "gather",
                     L->vt->name);
  return PX_STATUS_OK;
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
  char(*names)[96] = NULL;
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
  L->series_step = -1;
  L->static_error = NAN;
  L->static_since = NAN;
  L->drawn_scale = NAN;
  memset(&par, 0, sizeof par);
  memset(&g, 0, sizeof g);
  PX_TRY(px_case_get_real(c, "lattice.E", &par.E));
  PX_TRY(px_case_get_real(c, "lattice.poisson", &par.nu));
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
  L->precision =
      px_sim_precision(sim) == PX_PRECISION_SINGLE ? PX_PRECISION_SINGLE : PX_PRECISION_DOUBLE;
  L->vt = (const struct px_lattice_engine_i *)PX_BACKEND_PICK(px_sim_backend(sim), "lattice",
                                                              px_lattice_engines);
  if (!L->vt) return px_context_status(ctx);
  memset(&o, 0, sizeof o);
  o.integ = L->integ;
  o.precision = L->precision;
  o.scheme = (enum px_lattice_scheme)scheme;
  o.threads = px_backend_threads(px_sim_backend(sim));
  o.tune = px_backend_threads_auto(px_sim_backend(sim));
  o.backend = px_sim_backend(sim);
  o.vol = par.nu != 0.0;

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
                          dt, L->dt_limit,
                          L->integ == PX_LATTICE_INTEGRATOR_RK4 ? "rk4" : "leapfrog",
                          L->dt_limit * sqrt(par.E / par.rho) / L->m.grid.h, L->m.grid.h,
                          sqrt(par.E / par.rho), L->safety);
    /* the engine's dt (a float engine: below 1.2e-38 s it is 0 or loses
     * digits, and the body would not move) */
    if (!(dt >= px_lattice_real_min(L)))
      return px_case_fail(c, "time.dt", "dt = %g s is below what %s precision holds (%g s)", dt,
                          L->precision == PX_PRECISION_SINGLE ? "single" : "double",
                          px_lattice_real_min(L));
  }

  PX_TRY(px_lattice_engine_start(L, sim, c, &o));
  L->alpha = par.alpha;
  L->settle_time = px_lattice_model_settle_time(&L->m);
  PX_TRY(px_lattice_read_probes(L, c));
  PX_TRY(px_lattice_initial(L, c));
  {
    char est[32];
    px_text_bytes(L->need_host, 0, est, sizeof est);
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
  L->series_step = -1;
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
    .results = px_lattice_results,
    .resume_keys = px_lattice_resume_keys,
    .ranks = 1,
    .gather = px_lattice_gather,
    .gather_series = px_lattice_gather_series};
