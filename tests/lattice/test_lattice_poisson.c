/* Poisson's ratio (the volumetric term, docs/notes/lattice-poisson.md):
 *  - uniaxial: a 24 x n x n block on a roller (x_min: u_x = 0) pulled by
 *    100 MPa on x_max, relaxed to statics; at the centre element the
 *    strains (central differences of the neighbours' displacements) and the
 *    element stress give E and nu by least squares of Hooke's law within
 *    1 % (nu = 0.3, 0.45, -0.3; double and float); sigma/eps_xx and
 *    the stress of an edge element of the free faces at the centre within
 *    1e-3 (8 x 8) and 1e-2 (16 x 16; the loaded ends' layer reaches the
 *    centre of this short bar), -eps_yy/eps_xx within 2e-3 and 2e-2;
 *  - waves: the phase speed of plane P and S waves of wavelength 32 h in
 *    the bulk, from the reference force law at the centre of a block:
 *    c_p = sqrt(E(1-nu)/(rho(1+nu)(1-2nu))) and c_s = sqrt(E/(2 rho (1+nu)))
 *    within 1 % (nu = 0.3, 0.45, -0.3);
 *  - fronts (long): fronts of a ramped load on the x_min face of 80-element
 *    bars whose other displacement components are held, timed at the centre
 *    row between x = 20 h and 60 h, in 8 x 8 and 16 x 16 sections: no
 *    farther from c_p, c_s in the finer one, and within 1 % extrapolated
 *    in h;
 *  - engines: the cpu engine (gather and link-once, double and float, RK4
 *    and leapfrog) against the plain reference engine on the body with a
 *    hole, clamp, loads and damping at nu = 0.3: states within 1e-9
 *    (double) and 2e-3 (float), stresses within 1e-9 (double); with
 *    breakable bonds the same links break;
 *  - threads: link-once RK4 at nu = 0.3 with breakable bonds on a body of
 *    35840 cells, float and double: the fused sweep on 1 and 2 threads
 *    (coefficients a plane ahead of the links, in per-thread windows) and
 *    the per-stage passes on 3 threads (coefficients of the whole stage
 *    state first) give bit-identical states, links and broken counts;
 *  - energy: undamped, the energy with the volumetric term is conserved
 *    (the forces are its exact gradient): drift < 1e-4 over 1000 RK4
 *    steps of a fifth of the limit, at nu = 0, 0.3 and -0.5.
 *  - cantilever: 41 x 4 x 4 and 81 x 8 x 8 elements, tip load, nu = 0.3:
 *    nearer Timoshenko (G = E/(2(1+nu))) in the finer, within 1 % of it
 *    extrapolated in h;
 *  - omega: the automatic time step's frequency bound holds the highest
 *    natural frequency (power iteration) of small bodies at four nu;
 *  - stable: an undamped, clamped and loaded cantilever at nu = 0.3 keeps
 *    its vibration amplitude over 10^5 leapfrog steps;
 *  - stress: a uniform stress state reads exactly at every element of a
 *    block, faces, edges and corners (cpu double and float, reference).
 * Argument: uniaxial, waves, engines, threads, energy, cantilever, stress,
 * omega, stable (default: these nine) or fronts. */
#include <stdlib.h>

#include "lt_util.h"
#include "solvers/lattice/lattice_ref.h"

static const double h = 1e-3;

/* Index of cell (i, j, k) of a box grid. */
static size_t cell_index(const struct px_lattice_model *m, int i, int j, int k) {
  return px_lattice_index(
      m, (size_t)i + (size_t)m->grid.n[0] * ((size_t)j + (size_t)m->grid.n[1] * (size_t)k));
}

static double comp(struct lt_v3 v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }

/* E and nu from the normal strains eps and stresses sig of one element:
 * least squares of E eps_a = sig_a - nu (sig_b + sig_c), a = x, y, z. */
static void hooke_fit(const double eps[3], const double sig[3], double *E, double *nu) {
  double a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0, det;
  int a;
  for (a = 0; a < 3; ++a) {
    double r1 = eps[a], r2 = sig[(a + 1) % 3] + sig[(a + 2) % 3];
    a11 += r1 * r1;
    a12 += r1 * r2;
    a22 += r2 * r2;
    b1 += r1 * sig[a];
    b2 += r2 * sig[a];
  }
  det = a11 * a22 - a12 * a12;
  *E = (a22 * b1 - a12 * b2) / det;
  *nu = (a11 * b2 - a12 * b1) / det;
}

/* The block with n x n elements in section: the local fit checked, the
 * global modulus sigma/eps_xx and ratio -eps_yy/eps_xx at the centre out
 * and checked against E and nu, with the stress of an edge element. */
static void uniaxial(struct px_context *ctx, double nu, enum px_precision p, int n, double *Eg,
                     double *nug) {
  const int nx = 24;
  const double sigma = 1e8;
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_bc bc[2];
  struct px_lattice_params par = lt_steel();
  struct px_lattice_sel tip = lt_sel_face(PX_LATTICE_FACE_X_MAX);
  struct px_lattice_fields f;
  struct lt_engine en;
  struct lt_el *y;
  double value = NAN, dt, eps[3], sig[3], E, nuf;
  size_t i;
  long steps;
  int a;
  memset(bc, 0, sizeof bc);
  memset(&f, 0, sizeof f);
  par.nu = nu;
  bc[0].sel = lt_sel_face(PX_LATTICE_FACE_X_MIN);
  bc[0].fix = 1; /* roller: u_x = 0 */
  bc[1].sel = tip;
  bc[1].has_load = 1;
  bc[1].load[0] = sigma * (n * h) * (n * h);
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, nx, n, n, &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &m, &g, &par, bc, 2));
  y = (struct lt_el *)malloc(m.nalloc * sizeof *y);
  f.sigma = (double *)calloc(6 * m.nalloc, sizeof(double));
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_cpu, PX_LATTICE_INTEGRATOR_LEAPFROG,
                                  p, PX_LATTICE_SCHEME_AUTO, 1, NULL, &en));
  dt = 0.9 * px_lattice_model_dt_limit(&m, PX_LATTICE_INTEGRATOR_LEAPFROG);
  steps = lt_relax(ctx, &m, &en, dt, &tip, 0, 1e-7, 400000, &value, y);
  PX_CHECK_MSG(steps > 0, "relaxation did not converge");
  PX_CHECK_OK(ctx, en.vt->fields(en.e, (double)steps * dt, dt, &f));
  i = cell_index(&m, nx / 2, n / 2, n / 2);
  for (a = 0; a < 3; ++a) {
    size_t s = (size_t)m.stride[a];
    eps[a] = (comp(y[i + s].u, a) - comp(y[i - s].u, a)) / (2.0 * h);
    sig[a] = f.sigma[6 * i + (size_t)a];
  }
  hooke_fit(eps, sig, &E, &nuf);
  printf(
      "uniaxial nu = %g (%s, %d x %d x %d, %ld steps): centre strains %.4e %.4e %.4e, stresses "
      "%.4e %.4e "
      "%.4e Pa; E %.5e Pa (ratio %.5f), nu %.5f; sigma/eps_xx %.5e, -eps_yy/eps_xx %.5f\n",
      nu, p == PX_PRECISION_DOUBLE ? "double" : "float", nx, n, n, steps, eps[0], eps[1], eps[2],
      sig[0], sig[1], sig[2], E, E / LT_STEEL_E, nuf, sigma / eps[0], -eps[1] / eps[0]);
  PX_CHECK_REL(E, LT_STEEL_E, 0.01);
  PX_CHECK_NEAR(nuf, nu, 0.01 * fabs(nu));
  *Eg = sigma / eps[0];
  *nug = -eps[1] / eps[0];
  {
    /* the free faces carry the uniform state exactly (their cubes' half
     * springs); the loaded and the roller end keep the original estimate,
     * whose O(h) layer reaches the centre of the 16 x 16 section (24 long):
     * sigma/eps_xx and an edge element of the free faces at the centre
     * within 1e-3 (n = 8) and 1e-2 (n = 16); the faces alone once made
     * the 8 x 8 section 2.2 % soft */
    const double tol = n <= 8 ? 1e-3 : 1e-2;
    const size_t ie = cell_index(&m, nx / 2, 0, 0);
    const double *se = f.sigma + 6 * ie;
    printf("uniaxial nu = %g (%s, n = %d): edge element stress %.6e %.3e %.3e Pa\n", nu,
           p == PX_PRECISION_DOUBLE ? "double" : "float", n, se[0], se[1], se[2]);
    PX_CHECK_REL(*Eg, LT_STEEL_E, tol);
    PX_CHECK_NEAR(*nug, nu, 2.0 * tol); /* nu = -0.3: 1.1e-3 at 8 x 8 */
    PX_CHECK_REL(se[0], sigma, tol);
    PX_CHECK_NEAR(se[1], 0.0, tol * sigma);
    PX_CHECK_NEAR(se[2], 0.0, tol * sigma);
  }
  lt_engine_free(&en);
  free(f.sigma);
  free(y);
  px_lattice_model_free(ctx, &m);
}

/* Speed of the front of a plane wave [m/s]: P (shear = 0, load along x,
 * u_y and u_z held) or S (shear = 1, load along y, u_x and u_z held). */
static double wave_speed(struct px_context *ctx, double nu, int shear, double c_ref, int n) {
  const int nx = 80, k1 = 20, k2 = 60, comp_ = shear ? 1 : 0;
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_bc bc[2];
  struct px_lattice_params par = lt_steel();
  struct lt_engine en;
  struct lt_el *y;
  double F = -1000.0, A = (n * h) * (n * h), vplat, dt, tprev = 0.0, vprev[2] = {0, 0};
  double tf[2] = {-1, -1};
  size_t idx[2];
  long s;
  int j;
  memset(bc, 0, sizeof bc);
  par.nu = nu;
  bc[0].sel.has_box = 1;
  bc[0].sel.face = PX_LATTICE_FACE_NONE;
  for (j = 0; j < 3; ++j) {
    bc[0].sel.box_min[j] = -1.0;
    bc[0].sel.box_max[j] = 1.0;
  }
  bc[0].fix = shear ? (1 | 4) : (2 | 4);
  bc[1].sel = lt_sel_face(PX_LATTICE_FACE_X_MIN);
  bc[1].has_load = 1;
  bc[1].load[comp_] = F;
  /* ramped over 20 h/c: no short waves, so the lattice's dispersion does
   * not smear the front (its 50 % point moves at the long-wave speed) */
  bc[1].load_f.kind = PX_LATTICE_TFUN_RAMP;
  bc[1].load_f.t1 = 20.0 * h / c_ref;
  vplat = F / (LT_STEEL_RHO * c_ref * A);
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, nx, n, n, &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &m, &g, &par, bc, 2));
  idx[0] = cell_index(&m, k1, n / 2, n / 2);
  idx[1] = cell_index(&m, k2, n / 2, n / 2);
  y = (struct lt_el *)malloc(m.nalloc * sizeof *y);
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_cpu, PX_LATTICE_INTEGRATOR_RK4,
                                  PX_PRECISION_DOUBLE, PX_LATTICE_SCHEME_AUTO, 1, NULL, &en));
  dt = 0.25 * h / c_ref;
  for (s = 1; s < 4000 && tf[1] < 0.0; ++s) {
    double t = (double)s * dt;
    if (en.vt->run(en.e, s - 1, (double)(s - 1) * dt, dt, 1) != PX_STATUS_OK) break;
    en.vt->get_state(en.e, y, NULL);
    for (j = 0; j < 2; ++j) {
      double v = comp(y[idx[j]].v, comp_);
      if (tf[j] < 0.0 && v / vplat >= 0.5 && vprev[j] / vplat < 0.5)
        tf[j] = tprev + (t - tprev) * (0.5 * vplat - vprev[j]) / (v - vprev[j]);
      vprev[j] = v;
    }
    tprev = t;
  }
  PX_CHECK(tf[0] > 0.0 && tf[1] > tf[0]);
  lt_engine_free(&en);
  free(y);
  px_lattice_model_free(ctx, &m);
  return (k2 - k1) * h / (tf[1] - tf[0]);
}

/* First-order extrapolation in 1/n from sections of n and 2n elements:
 * the layer of elements at the faces differs from the bulk (the
 * rotational restraint of the shear springs; the held end of a
 * cantilever, its clamp at the element centres), an error proportional to
 * h/width. */
static double extrap(double v_n, double v_2n) { return 2.0 * v_2n - v_n; }

static void test_fronts(struct px_context *ctx) {
  const double nu = 0.3, E = LT_STEEL_E, rho = LT_STEEL_RHO;
  const double cp = sqrt(E * (1.0 - nu) / (rho * (1.0 + nu) * (1.0 - 2.0 * nu)));
  const double cs = sqrt(E / (2.0 * rho * (1.0 + nu)));
  double vp[2], vs[2], p, s;
  int k;
  for (k = 0; k < 2; ++k) {
    vp[k] = wave_speed(ctx, nu, 0, cp, 8 << k);
    vs[k] = wave_speed(ctx, nu, 1, cs, 8 << k);
    printf(
        "waves nu = %g, %d x %d section: P front %.2f m/s (c_p %.2f, ratio %.5f), S front %.2f "
        "m/s (c_s %.2f, ratio %.5f)\n",
        nu, 8 << k, 8 << k, vp[k], cp, vp[k] / cp, vs[k], cs, vs[k] / cs);
  }
  p = extrap(vp[0], vp[1]);
  s = extrap(vs[0], vs[1]);
  printf("waves nu = %g, extrapolated in h: P %.2f m/s (ratio %.5f), S %.2f m/s (ratio %.5f)\n", nu,
         p, p / cp, s, s / cs);
  /* not diverging in h (the held P-wave bar has no face layer effect:
   * both sections give the same front), and at the analytic speeds */
  PX_CHECK(fabs(vp[1] - cp) <= fabs(vp[0] - cp) + 1e-9 * cp);
  PX_CHECK(fabs(vs[1] - cs) < fabs(vs[0] - cs));
  PX_CHECK_REL(p, cp, 0.01);
  PX_CHECK_REL(s, cs, 0.01);
}

/* Phase speed of a plane wave of wavelength 32 h in the bulk, from the
 * reference force law: the displacement field u = A sin(k x) along x (P)
 * or y (S; with the elements turned by the field's rotation
 * (1/2) du_y/dx about z, where they rest in a long wave) on a
 * 40 x 9 x 9 block; at the centre element, five elements from every face,
 * the force is -m c^2 k^2 u for the bulk lattice (the faces do not reach
 * it: a link reaches two elements, the volumetric term three). */
static double phase_speed(struct px_context *ctx, double nu, int shear) {
  const int nx = 40, n = 9, ic = 8; /* sin(k x) = 1 at the centre of element 8 */
  const double k = 2.0 * 3.14159265358979323846 / (32.0 * h), A = 1e-7;
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_params par = lt_steel();
  struct lt_el *y;
  struct lt_v3 *F, *T;
  uint8_t *links;
  size_t c, i;
  double x[3], u, f, mass;
  par.nu = nu;
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, nx, n, n, &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &m, &g, &par, NULL, 0));
  y = (struct lt_el *)calloc(m.nalloc, sizeof *y);
  F = (struct lt_v3 *)calloc(m.nalloc, sizeof *F);
  T = (struct lt_v3 *)calloc(m.nalloc, sizeof *T);
  links = (uint8_t *)malloc(m.nalloc);
  memcpy(links, m.links, m.nalloc);
  for (i = 0; i < m.nalloc; ++i) y[i].q.w = 1.0;
  for (c = 0; c < m.grid.ncell; ++c) {
    struct lt_el *e = &y[px_lattice_index(&m, c)];
    double ph;
    px_lattice_grid_centre(&m.grid, c, x);
    ph = k * (x[0] - (ic + 0.5) * h) + 0.5 * 3.14159265358979323846;
    if (shear) {
      double th = 0.5 * A * k * cos(ph);
      e->u.y = A * sin(ph);
      e->q.w = cos(0.5 * th);
      e->q.z = sin(0.5 * th);
    } else {
      e->u.x = A * sin(ph);
    }
  }
  px_lattice_ref_forces(&m, links, y, 0, NULL, F, T);
  i = cell_index(&m, ic, n / 2, n / 2);
  u = shear ? y[i].u.y : y[i].u.x;
  f = shear ? F[i].y : F[i].x;
  mass = m.m;
  free(y);
  free(F);
  free(T);
  free(links);
  px_lattice_model_free(ctx, &m);
  return sqrt(-f / (mass * k * k * u));
}

static void test_waves(struct px_context *ctx) {
  const double E = LT_STEEL_E, rho = LT_STEEL_RHO, nus[3] = {0.3, 0.45, -0.3};
  int j;
  for (j = 0; j < 3; ++j) {
    const double nu = nus[j];
    const double cp = sqrt(E * (1.0 - nu) / (rho * (1.0 + nu) * (1.0 - 2.0 * nu)));
    const double cs = sqrt(E / (2.0 * rho * (1.0 + nu)));
    double vp = phase_speed(ctx, nu, 0), vs = phase_speed(ctx, nu, 1);
    printf(
        "plane waves nu = %g, wavelength 32 h: P %.2f m/s (c_p %.2f, ratio %.5f), S %.2f m/s "
        "(c_s %.2f, ratio %.5f)\n",
        nu, vp, cp, vp / cp, vs, cs, vs / cs);
    PX_CHECK_REL(vp, cp, 0.01);
    PX_CHECK_REL(vs, cs, 0.01);
  }
}

static void test_uniaxial(struct px_context *ctx) {
  double e, v;
  uniaxial(ctx, 0.3, PX_PRECISION_DOUBLE, 8, &e, &v);
  uniaxial(ctx, 0.3, PX_PRECISION_DOUBLE, 16, &e, &v);
  uniaxial(ctx, 0.45, PX_PRECISION_DOUBLE, 8, &e, &v);
  uniaxial(ctx, -0.3, PX_PRECISION_DOUBLE, 8, &e, &v);
  uniaxial(ctx, 0.3, PX_PRECISION_SINGLE, 8, &e, &v);
}

static void engines_case(struct px_context *ctx, const struct px_lattice_model *m,
                         enum px_lattice_integrator integ, long steps, int fracture) {
  struct lt_engine ref, en;
  struct lt_el *yr = (struct lt_el *)malloc(m->nalloc * sizeof *yr);
  struct lt_el *yc = (struct lt_el *)malloc(m->nalloc * sizeof *yc);
  double *sr = (double *)calloc(6 * m->nalloc, sizeof(double));
  double *sc = (double *)calloc(6 * m->nalloc, sizeof(double));
  double dt = 0.8 * px_lattice_model_dt_limit(m, integ), d[4];
  struct px_lattice_fields f;
  int scheme, prec;
  const char *iname = integ == PX_LATTICE_INTEGRATOR_RK4 ? "rk4" : "leapfrog";
  memset(&f, 0, sizeof f);
  PX_CHECK_OK(ctx, lt_engine_make(ctx, m, &px_lattice_engine_ref, integ, PX_PRECISION_DOUBLE,
                                  PX_LATTICE_SCHEME_AUTO, 1, NULL, &ref));
  PX_CHECK_OK(ctx, ref.vt->run(ref.e, 0, 0.0, dt, steps));
  ref.vt->get_state(ref.e, yr, NULL);
  f.sigma = sr;
  PX_CHECK_OK(ctx, ref.vt->fields(ref.e, (double)steps * dt, dt, &f));
  if (fracture) {
    printf("fracture nu = %g: reference broke %ld links\n", m->par.nu, ref.vt->broken(ref.e));
    PX_CHECK(ref.vt->broken(ref.e) > 0);
  }
  for (scheme = PX_LATTICE_SCHEME_GATHER; scheme <= PX_LATTICE_SCHEME_LINK_ONCE; ++scheme)
    for (prec = 0; prec < 2; ++prec) {
      enum px_precision p = prec ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
      double tol = prec ? 1e-9 : 2e-3, ds;
      PX_CHECK_OK(ctx, lt_engine_make(ctx, m, &px_lattice_engine_cpu, integ, p,
                                      (enum px_lattice_scheme)scheme, 2, NULL, &en));
      PX_CHECK_OK(ctx, en.vt->run(en.e, 0, 0.0, dt, steps));
      en.vt->get_state(en.e, yc, NULL);
      f.sigma = sc;
      PX_CHECK_OK(ctx, en.vt->fields(en.e, (double)steps * dt, dt, &f));
      lt_state_diff(m, yc, yr, d);
      ds = lt_field_diff(m, sc, sr, 6);
      printf("nu = %g %s scheme %d %s%s: rel. diff u %.2e v %.2e W %.2e q %.2e stress %.2e\n",
             m->par.nu, iname, scheme, prec ? "double" : "float", fracture ? " fracture" : "", d[0],
             d[1], d[2], d[3], ds);
      if (fracture) {
        /* float may break a link a step apart from double */
        if (prec)
          PX_CHECK(en.vt->broken(en.e) == ref.vt->broken(ref.e));
        else
          PX_CHECK_NEAR((double)en.vt->broken(en.e), (double)ref.vt->broken(ref.e),
                        0.05 * (double)ref.vt->broken(ref.e) + 1.0);
      }
      if (!fracture || prec) {
        PX_CHECK_NEAR(d[0], 0.0, tol);
        PX_CHECK_NEAR(d[1], 0.0, tol);
        PX_CHECK_NEAR(d[2], 0.0, tol);
        PX_CHECK_NEAR(d[3], 0.0, tol);
        if (prec) PX_CHECK_NEAR(ds, 0.0, tol);
      }
      lt_engine_free(&en);
    }
  lt_engine_free(&ref);
  free(yr);
  free(yc);
  free(sr);
  free(sc);
}

static void test_engines(struct px_context *ctx) {
  struct px_lattice_model m;
  PX_CHECK_OK(ctx, lt_build_body_nu(ctx, &m, 0.0, 1e-3, 0.3));
  engines_case(ctx, &m, PX_LATTICE_INTEGRATOR_RK4, 40, 0);
  engines_case(ctx, &m, PX_LATTICE_INTEGRATOR_LEAPFROG, 40, 0);
  px_lattice_model_free(ctx, &m);
  PX_CHECK_OK(ctx, lt_build_body_nu(ctx, &m, 2e3, 1e-3, 0.3));
  engines_case(ctx, &m, PX_LATTICE_INTEGRATOR_RK4, 40, 1);
  px_lattice_model_free(ctx, &m);
}

/* Largest |u| of the occupied cells [m]. */
static double max_u(const struct px_lattice_model *m, const struct lt_el *y) {
  double v = 0.0;
  size_t c;
  for (c = 0; c < m->grid.ncell; ++c) {
    const struct lt_el *e = &y[px_lattice_index(m, c)];
    if (m->grid.occ[c]) v = fmax(v, fmax(fabs(e->u.x), fmax(fabs(e->u.y), fabs(e->u.z))));
  }
  return v;
}

/* The fused link-once RK4 sweep (1, 2 threads) against the per-stage
 * passes (3 threads: lattice_cpu.c runs the fused sweep on at most 2), bit
 * for bit. */
static void test_threads(struct px_context *ctx) {
  struct px_lattice_model m;
  struct lt_el *y[3];
  uint8_t *l[3];
  int prec, th;
  /* 56 x 28 x 20 cells, rows padded to 64: 35840 >= 2 x 16384, so the
   * engine runs the 3 threads asked for (one per 16384 cells) */
  PX_CHECK_OK(ctx, lt_build_body_nu(ctx, &m, 5.0, 0.25e-3, 0.3));
  if (px_test_failures) return;
  PX_CHECK(m.n0p * (size_t)m.grid.n[1] * (size_t)m.grid.n[2] >= 2 * 16384);
  for (th = 0; th < 3; ++th) {
    y[th] = (struct lt_el *)malloc(m.nalloc * sizeof *y[th]);
    l[th] = (uint8_t *)malloc(m.nalloc);
  }
  for (prec = 0; prec < 2; ++prec) {
    const double dt = 0.8 * px_lattice_model_dt_limit(&m, PX_LATTICE_INTEGRATOR_RK4);
    long broken[3];
    for (th = 0; th < 3; ++th) {
      struct lt_engine en;
      PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_cpu, PX_LATTICE_INTEGRATOR_RK4,
                                      prec ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE,
                                      PX_LATTICE_SCHEME_LINK_ONCE, th + 1, NULL, &en));
      PX_CHECK_OK(ctx, en.vt->run(en.e, 0, 0.0, dt, 30));
      en.vt->get_state(en.e, y[th], l[th]);
      broken[th] = en.vt->broken(en.e);
      lt_engine_free(&en);
    }
    /* the body moved and bonds broke: the comparison covers the term */
    printf("threads: link-once rk4 %s nu = 0.3: %ld links broken, max |u| %.3e m\n",
           prec ? "double" : "float", broken[2], max_u(&m, y[2]));
    PX_CHECK(broken[2] > 0);
    PX_CHECK(max_u(&m, y[2]) > 0.0);
    for (th = 0; th < 2; ++th) {
      PX_CHECK(memcmp(y[th], y[2], m.nalloc * sizeof *y[th]) == 0);
      PX_CHECK(memcmp(l[th], l[2], m.nalloc) == 0);
      PX_CHECK(broken[th] == broken[2]);
    }
  }
  for (th = 0; th < 3; ++th) {
    free(y[th]);
    free(l[th]);
  }
  px_lattice_model_free(ctx, &m);
}

static void test_energy(struct px_context *ctx, double nu) {
  const int nx = 16, n = 6;
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_params par = lt_steel();
  struct px_lattice_ref r;
  double dt, k = 0, p = 0, e0, drift = 0.0, Wz = 300.0;
  size_t c;
  int s;
  par.nu = nu;
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, nx, n, n, &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &m, &g, &par, NULL, 0));
  PX_CHECK_OK(ctx, px_lattice_ref_create(ctx, &m, PX_LATTICE_INTEGRATOR_RK4, &r));
  for (c = 0; c < m.grid.ncell; ++c) {
    struct lt_el *e = &r.y[px_lattice_index(&m, c)];
    double x[3], L = nx * h;
    px_lattice_grid_centre(&m.grid, c, x);
    /* spin, compression along x and a lateral breathing: theta != 0 */
    e->W = lt_v3_make(0, 0, Wz);
    e->v = lt_v3_make(-Wz * (x[1] - 0.5 * n * h) + 2.0 * sin(6.283185307179586 * x[0] / L),
                      Wz * (x[0] - 0.5 * L) + 1.0 * (x[1] - 0.5 * n * h) / (n * h),
                      0.5 * cos(6.283185307179586 * x[0] / L));
  }
  /* a fifth of the limit: RK4's own damping of the highest modes stays
   * below the tolerance */
  dt = 0.2 * px_lattice_model_dt_limit(&m, PX_LATTICE_INTEGRATOR_RK4);
  px_lattice_ref_energy(&r, 0.0, dt, &k, &p);
  e0 = k + p;
  for (s = 1; s <= 1000; ++s) {
    PX_CHECK_OK(ctx, px_lattice_ref_step(&r, (double)(s - 1) * dt, dt));
    if (s % 100 == 0) {
      px_lattice_ref_energy(&r, (double)s * dt, dt, &k, &p);
      drift = fmax(drift, fabs(k + p - e0) / e0);
    }
  }
  printf(
      "energy nu = %g, rk4, 1000 steps: elastic %.3e J of %.3e J; max relative deviation "
      "%.2e\n",
      nu, p, e0, drift);
  PX_CHECK(p > 1e-3 * e0);
  PX_CHECK_NEAR(drift, 0.0, 1e-4);
  px_lattice_ref_free(&r);
  px_lattice_model_free(ctx, &m);
}

/* Tip deflection of a cantilever of (10 n + 1) x n x n elements (L = 10 n h
 * between the clamped and the loaded layer's centres, L/H = 10), 10 N down
 * at the tip, nu = 0.3, relaxed; the ratio to Timoshenko's
 * P L^3/(3 E I) + P L/(kappa G A), G = E/(2(1+nu)), Cowper's
 * kappa = 10(1+nu)/(12+11nu). */
static double cantilever(struct px_context *ctx, int n) {
  const int nx = 10 * n + 1;
  const double nu = 0.3, E = LT_STEEL_E, P = 10.0;
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_bc bc[2];
  struct px_lattice_params par = lt_steel();
  struct px_lattice_sel tip = lt_sel_face(PX_LATTICE_FACE_X_MAX);
  struct lt_engine en;
  struct lt_el *y;
  double L = (nx - 1) * h, H = n * h, I = H * H * H * H / 12.0, A = H * H;
  double G = E / (2.0 * (1.0 + nu)), kappa = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu);
  double ref = P * L * L * L / (3.0 * E * I) + P * L / (kappa * G * A), value = NAN, dt;
  long steps;
  memset(bc, 0, sizeof bc);
  par.nu = nu;
  bc[0].sel = lt_sel_face(PX_LATTICE_FACE_X_MIN);
  bc[0].fix = 63;
  bc[1].sel = tip;
  bc[1].has_load = 1;
  bc[1].load[2] = -P;
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, nx, n, n, &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &m, &g, &par, bc, 2));
  y = (struct lt_el *)malloc(m.nalloc * sizeof *y);
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_cpu, PX_LATTICE_INTEGRATOR_LEAPFROG,
                                  PX_PRECISION_DOUBLE, PX_LATTICE_SCHEME_AUTO, 2, NULL, &en));
  dt = 0.9 * px_lattice_model_dt_limit(&m, PX_LATTICE_INTEGRATOR_LEAPFROG);
  steps = lt_relax(ctx, &m, &en, dt, &tip, 2, 2e-6, 400000, &value, y);
  PX_CHECK_MSG(steps > 0, "relaxation did not converge");
  printf(
      "cantilever nu = %g, %d x %d x %d (%ld steps): tip %.6e m, Timoshenko %.6e m, ratio "
      "%.5f\n",
      nu, nx, n, n, steps, -value, ref, -value / ref);
  lt_engine_free(&en);
  free(y);
  px_lattice_model_free(ctx, &m);
  return -value / ref;
}

/* Cantilever, sections 4 x 4 and 8 x 8: converging (the finer nearer),
 * and within 1 % of Timoshenko extrapolated in h (the clamp, held at the
 * element centres, stiffens by O(h); the section's bending is within
 * O(h^2): docs/notes/lattice-poisson.md). */
static void test_cantilever(struct px_context *ctx) {
  const double r4 = cantilever(ctx, 4), r8 = cantilever(ctx, 8), ex = extrap(r4, r8);
  printf("cantilever nu = 0.3, extrapolated in h: ratio %.5f\n", ex);
  PX_CHECK(fabs(r8 - 1.0) < fabs(r4 - 1.0));
  PX_CHECK_NEAR(ex, 1.0, 0.01);
}

/* A uniform stress state (sigma_xx, sigma_yy, sigma_zz) = (100, -50, 30)
 * MPa: the six faces of a 6 x 5 x 4 block loaded by the tractions, spread
 * equally over their elements, nu = 0 (the uniform strain is then the
 * lattice's exact static state), relaxed; every element, faces, edges and
 * corners included, reads the applied stress (the mean-traction estimator
 * of lattice_kernel.h; the plain Love-Weber sum read half on faces, a
 * quarter on edges). engine: cpu (double, float) or the reference. */
static void uniform_stress(struct px_context *ctx, const struct px_lattice_engine_i *vt,
                           enum px_precision p) {
  const int n[3] = {6, 5, 4};
  const double sig[3] = {1e8, -5e7, 3e7};
  const enum px_lattice_face fm[3] = {PX_LATTICE_FACE_X_MIN, PX_LATTICE_FACE_Y_MIN,
                                      PX_LATTICE_FACE_Z_MIN};
  const enum px_lattice_face fp[3] = {PX_LATTICE_FACE_X_MAX, PX_LATTICE_FACE_Y_MAX,
                                      PX_LATTICE_FACE_Z_MAX};
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_bc bc[6];
  struct px_lattice_params par = lt_steel();
  struct px_lattice_sel probe = lt_sel_face(PX_LATTICE_FACE_X_MAX);
  struct px_lattice_fields f;
  struct lt_engine en;
  struct lt_el *y;
  double value = NAN, dt, worst = 0.0, tol = p == PX_PRECISION_DOUBLE ? 1e-6 : 1e-4;
  size_t c;
  long steps;
  int a, k;
  memset(bc, 0, sizeof bc);
  memset(&f, 0, sizeof f);
  for (a = 0; a < 3; ++a) {
    double area = (n[(a + 1) % 3] * h) * (n[(a + 2) % 3] * h);
    bc[2 * a].sel = lt_sel_face(fm[a]);
    bc[2 * a].has_load = 1;
    bc[2 * a].load[a] = -sig[a] * area;
    bc[2 * a + 1].sel = lt_sel_face(fp[a]);
    bc[2 * a + 1].has_load = 1;
    bc[2 * a + 1].load[a] = sig[a] * area;
  }
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, n[0], n[1], n[2], &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &m, &g, &par, bc, 6));
  y = (struct lt_el *)malloc(m.nalloc * sizeof *y);
  f.sigma = (double *)calloc(6 * m.nalloc, sizeof(double));
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, vt, PX_LATTICE_INTEGRATOR_LEAPFROG, p,
                                  PX_LATTICE_SCHEME_AUTO, 1, NULL, &en));
  dt = 0.9 * px_lattice_model_dt_limit(&m, PX_LATTICE_INTEGRATOR_LEAPFROG);
  steps = lt_relax(ctx, &m, &en, dt, &probe, 0, p == PX_PRECISION_DOUBLE ? 1e-11 : 1e-7, 200000,
                   &value, y);
  PX_CHECK_MSG(steps > 0, "relaxation did not converge");
  PX_CHECK_OK(ctx, en.vt->fields(en.e, (double)steps * dt, dt, &f));
  for (c = 0; c < m.grid.ncell; ++c) {
    const double *sg = f.sigma + 6 * px_lattice_index(&m, c);
    for (k = 0; k < 6; ++k) {
      double d = fabs(sg[k] - (k < 3 ? sig[k] : 0.0)) / sig[0];
      if (d > worst) worst = d;
    }
  }
  {
    /* a corner and the middle of the x_max face, for the record */
    const double *s0 = f.sigma + 6 * px_lattice_index(&m, 0);
    const double *s1 = f.sigma + 6 * cell_index(&m, n[0] - 1, n[1] / 2, n[2] / 2);
    printf(
        "uniform stress (%s, %s, %ld steps): corner %.6e %.6e %.6e Pa, x_max face "
        "%.6e %.6e %.6e Pa; worst relative error over all %zu elements %.2e\n",
        vt->name, p == PX_PRECISION_DOUBLE ? "double" : "float", steps, s0[0], s0[1], s0[2], s1[0],
        s1[1], s1[2], m.grid.ncell, worst);
  }
  PX_CHECK_NEAR(worst, 0.0, tol);
  lt_engine_free(&en);
  free(f.sigma);
  free(y);
  px_lattice_model_free(ctx, &m);
}

/* An undamped cantilever 24 x 4 x 4 at nu = 0.3, clamped, its x_max face
 * and an edge element loaded from rest (forces on held elements), leapfrog
 * at 0.9 of the limit for 100000 steps: the vibration about the static state
 * keeps its amplitude (tip u_x and a corner's u_y, u_z: the largest
 * excursion from the run's mean over the last tenth within 5 % of the
 * first tenth's). Forces that were not a gradient at the loaded elements
 * (an earlier rule: they shared theta equally) made it grow 10-50 fold and
 * blow up near step 10^5: test_stable fails then. */
static void test_stable(struct px_context *ctx) {
  enum { NS = 1000, EVERY = 100 };
  const int nx = 24, n = 4;
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_bc bc[3];
  struct px_lattice_params par = lt_steel();
  struct lt_engine en;
  struct lt_el *y;
  double *u = (double *)calloc(3 * NS, sizeof *u), dt, worst = 0.0;
  size_t it, ic;
  int s, k;
  memset(bc, 0, sizeof bc);
  par.nu = 0.3;
  bc[0].sel = lt_sel_face(PX_LATTICE_FACE_X_MIN);
  bc[0].fix = 63;
  bc[1].sel = lt_sel_face(PX_LATTICE_FACE_X_MAX);
  bc[1].has_load = 1;
  bc[1].load[0] = 1600.0;
  bc[1].load[1] = 300.0;
  bc[1].load[2] = -200.0;
  bc[2].sel = lt_sel_point(12.5e-3, 3.5e-3, 3.5e-3);
  bc[2].has_load = 1;
  bc[2].load[2] = 50.0;
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, nx, n, n, &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &m, &g, &par, bc, 3));
  it = cell_index(&m, nx - 1, n / 2, n / 2);
  ic = cell_index(&m, nx - 1, n - 1, n - 1);
  y = (struct lt_el *)malloc(m.nalloc * sizeof *y);
  PX_CHECK_OK(ctx, lt_engine_make(ctx, &m, &px_lattice_engine_cpu, PX_LATTICE_INTEGRATOR_LEAPFROG,
                                  PX_PRECISION_DOUBLE, PX_LATTICE_SCHEME_AUTO, 1, NULL, &en));
  dt = 0.9 * px_lattice_model_dt_limit(&m, PX_LATTICE_INTEGRATOR_LEAPFROG);
  for (s = 0; s < NS; ++s) {
    if (en.vt->run(en.e, (long)s * EVERY, (double)s * EVERY * dt, dt, EVERY) != PX_STATUS_OK) {
      PX_CHECK_MSG(0, "blew up by step %d: %s", (s + 1) * EVERY, px_context_message(ctx));
      break;
    }
    en.vt->get_state(en.e, y, NULL);
    u[3 * s] = y[it].u.x;
    u[3 * s + 1] = y[ic].u.y;
    u[3 * s + 2] = y[ic].u.z;
  }
  for (k = 0; k < 3; ++k) {
    double mean = 0.0, first = 0.0, last = 0.0;
    for (s = 0; s < NS; ++s) mean += u[3 * s + k] / NS;
    for (s = 0; s < NS / 10; ++s) {
      first = fmax(first, fabs(u[3 * s + k] - mean));
      last = fmax(last, fabs(u[3 * (NS - 1 - s) + k] - mean));
    }
    printf(
        "stable nu = 0.3, undamped loaded cantilever, %d steps: %s amplitude %.4e m first "
        "tenth, %.4e m last (ratio %.4f)\n",
        NS * EVERY, k == 0 ? "tip u_x" : (k == 1 ? "corner u_y" : "corner u_z"), first, last,
        last / first);
    worst = fmax(worst, last / first);
  }
  PX_CHECK(worst == worst && worst < 1.05);
  lt_engine_free(&en);
  free(y);
  free(u);
  px_lattice_model_free(ctx, &m);
}

/* The highest natural frequency of a body [rad/s] by power iteration on
 * the linearized reference force law: A v = -M^-1 (G(eps v) - G(-eps v))/(2 eps),
 * v the 6 DOFs of every element (displacements, small rotations), M the
 * element mass and inertia; with `clamp` the x_min face fixed (its DOFs held
 * at 0). The Rayleigh quotient in the M inner product is a lower bound of
 * omega_max^2 when A is M-symmetric (a free body) and converges to it. */
#ifndef PX_OMEGA_IT
#define PX_OMEGA_IT 1500
#endif
static double omega_max(struct px_context *ctx, double nu, int nx, int ny, int nz, int clamp) {
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_params par = lt_steel();
  struct px_lattice_bc bc;
  struct lt_el *y;
  struct lt_v3 *F, *T;
  uint8_t *links;
  double *v, *w, lam = 0.0, eps;
  size_t i, n, j;
  int it;
  memset(&bc, 0, sizeof bc);
  par.nu = nu;
  bc.sel = lt_sel_face(PX_LATTICE_FACE_X_MIN);
  bc.fix = 63;
  PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, nx, ny, nz, &g));
  PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &m, &g, &par, &bc, clamp ? 1 : 0));
  n = m.nalloc;
  eps = 1e-6 * h;
  y = (struct lt_el *)calloc(n, sizeof *y);
  F = (struct lt_v3 *)calloc(n, sizeof *F);
  T = (struct lt_v3 *)calloc(n, sizeof *T);
  links = (uint8_t *)malloc(n);
  v = (double *)calloc(6 * n, sizeof *v);
  w = (double *)calloc(6 * n, sizeof *w);
  memcpy(links, m.links, n);
  /* a deterministic start with every mode in it */
  for (i = 0; i < n; ++i)
    if (m.group[i] == 1)
      for (j = 0; j < 6; ++j)
        v[6 * i + j] = sin(1.0 + 0.7 * (double)(6 * i + j)) / (j < 3 ? 1.0 : h);
  for (it = 0; it < PX_OMEGA_IT; ++it) {
    double num = 0.0, den = 0.0, sg;
    int k;
    memset(w, 0, 6 * n * sizeof *w);
    for (k = 0; k < 2; ++k) {
      sg = k == 0 ? 1.0 : -1.0;
      for (i = 0; i < n; ++i) {
        const double *vi = v + 6 * i;
        memset(&y[i], 0, sizeof y[i]);
        y[i].u = lt_v3_make(sg * eps * vi[0], sg * eps * vi[1], sg * eps * vi[2]);
        y[i].q.w = 1.0;
        y[i].q.x = 0.5 * sg * eps * vi[3];
        y[i].q.y = 0.5 * sg * eps * vi[4];
        y[i].q.z = 0.5 * sg * eps * vi[5];
      }
      px_lattice_ref_forces(&m, links, y, 0, NULL, F, T);
      for (i = 0; i < n; ++i) {
        if (m.group[i] != 1) continue; /* void, or held by the clamp */
        w[6 * i + 0] -= sg * F[i].x / (2.0 * eps * m.m);
        w[6 * i + 1] -= sg * F[i].y / (2.0 * eps * m.m);
        w[6 * i + 2] -= sg * F[i].z / (2.0 * eps * m.m);
        w[6 * i + 3] -= sg * T[i].x / (2.0 * eps * m.I);
        w[6 * i + 4] -= sg * T[i].y / (2.0 * eps * m.I);
        w[6 * i + 5] -= sg * T[i].z / (2.0 * eps * m.I);
      }
    }
    for (i = 0; i < 6 * n; ++i) {
      const double mass = (i % 6) < 3 ? m.m : m.I;
      num += mass * v[i] * w[i];
      den += mass * v[i] * v[i];
    }
    lam = num / den;
    den = 0.0;
    for (i = 0; i < 6 * n; ++i) den += ((i % 6) < 3 ? m.m : m.I) * w[i] * w[i];
    den = sqrt(den);
    for (i = 0; i < 6 * n; ++i) v[i] = w[i] / den;
  }
  free(y);
  free(F);
  free(T);
  free(links);
  free(v);
  free(w);
  px_lattice_model_free(ctx, &m);
  return sqrt(lam);
}

/* The automatic time step's frequency bound (3.74 c/h times
 * px_lattice_model_stiffen) holds the highest frequency of blocks, walls
 * one and two elements thick, bars and a clamped block, at nu = 0, 0.3,
 * 0.45 and -0.5; printed with how loose it is. */
static void test_omega(struct px_context *ctx) {
  static const int body[9][4] = {{6, 6, 6, 0}, {2, 6, 6, 0}, {1, 6, 6, 0},
                                 {3, 3, 3, 0}, {2, 2, 2, 0}, {8, 2, 2, 0},
                                 {8, 1, 1, 0}, {4, 2, 1, 0}, {6, 4, 4, 1}};
  const double nus[4] = {0.0, 0.3, 0.45, -0.5};
  int b, j;
  for (j = 0; j < 4; ++j)
    for (b = 0; b < 9; ++b) {
      struct px_lattice_grid g;
      struct px_lattice_model m;
      struct px_lattice_params par = lt_steel();
      double w, bound;
      par.nu = nus[j];
      PX_CHECK_OK(ctx, px_lattice_grid_box(ctx, h, body[b][0], body[b][1], body[b][2], &g));
      PX_CHECK_OK(ctx, px_lattice_model_build(ctx, &m, &g, &par, NULL, 0));
      bound = 3.74 * sqrt(par.E / par.rho) / h * px_lattice_model_stiffen(&m);
      px_lattice_model_free(ctx, &m);
      w = omega_max(ctx, nus[j], body[b][0], body[b][1], body[b][2], body[b][3]);
      printf("omega_max nu = %g, %d x %d x %d%s: %.5g rad/s = %.4f c/h, bound %.4f c/h (%.3f)\n",
             nus[j], body[b][0], body[b][1], body[b][2], body[b][3] ? " clamped" : "", w,
             w * h / sqrt(par.E / par.rho), bound * h / sqrt(par.E / par.rho), w / bound);
      PX_CHECK(w <= bound);
    }
}

int main(int argc, char **argv) {
  struct px_context *ctx;
  const char *part = argc > 1 ? argv[1] : "all";
  int all = strcmp(part, "all") == 0;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  if (all || strcmp(part, "uniaxial") == 0) {
    test_uniaxial(ctx);
  }
  if (all || strcmp(part, "waves") == 0) test_waves(ctx);
  if (strcmp(part, "fronts") == 0) test_fronts(ctx);
  if (all || strcmp(part, "omega") == 0) test_omega(ctx);
  if (all || strcmp(part, "stable") == 0) test_stable(ctx);
  if (all || strcmp(part, "cantilever") == 0) test_cantilever(ctx);
  if (all || strcmp(part, "stress") == 0) {
    uniform_stress(ctx, &px_lattice_engine_cpu, PX_PRECISION_DOUBLE);
    uniform_stress(ctx, &px_lattice_engine_cpu, PX_PRECISION_SINGLE);
    uniform_stress(ctx, &px_lattice_engine_ref, PX_PRECISION_DOUBLE);
  }
  if (all || strcmp(part, "engines") == 0) test_engines(ctx);
  if (all || strcmp(part, "threads") == 0) test_threads(ctx);
  if (all || strcmp(part, "energy") == 0) {
    test_energy(ctx, 0.0);
    test_energy(ctx, 0.3);
    test_energy(ctx, -0.5);
  }
  px_context_free(ctx);
  return px_test_report("test_lattice_poisson");
}
