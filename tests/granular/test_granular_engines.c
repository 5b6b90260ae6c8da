/* Every granular engine against the plain double reference engine
 * (granular_ref.c: all pairs by a direct loop, every segment of every
 * contour, one thread), through the engine tables of granular_engine.h.
 *
 * Case: 392 discs (radii 1.5-2 mm, random velocities of 1.5 m/s, gaps of
 * 0.1-1 mm) falling in a box while a round part in the middle vibrates and
 * turns (harmonic motion of its own body), with friction and rolling
 * resistance on pairs and walls, on the linear and on the hysteretic law.
 * RUN_STEPS = 1500 steps (30 contact times): over 500 distinct pairs touch
 * (the reference counts them, sampled every 10 steps), discs hit the floor,
 * the walls and the moving part. Compared per persistent id: positions (over
 * the largest radius, 2 mm), velocities and spins (over the reference's
 * largest).
 *
 * Tolerances. The run is chaotic: a difference grows through the collisions
 * (about tenfold per 200-300 steps here), so each tolerance holds for a run
 * of a stated length:
 *  - double: the cpu engine evaluates the same functions in the same
 *    arithmetic; only the order of its force sums differs (a 1-ulp
 *    difference per sum). Measured: positions identical, velocities and
 *    spins within 2e-16 after RUN_STEPS (both laws, both integrators, 1 and
 *    2 threads); checked at 1e-12. The control run (particle friction
 *    coefficient times 1 + 1e-9) misses it by four orders of magnitude, so
 *    the check can fail.
 *  - mixed (double state, float contact arithmetic): a contact force carries
 *    float rounding (6e-8) of a separation kept in double; measured below
 *    1.2e-6 after FLOAT_STEPS = 100 (20 pairs touched); checked at 1e-5
 *    (a 1 % change of the friction coefficient gives 2e-4 to 2e-3).
 *  - single: positions near 0.05 m are kept to a float ulp (3.7e-9 m)
 *    while overlaps are 1e-5 m: each step rounds a moving disc's position by
 *    up to half an ulp (steps x ulp / 2 / 2 mm = 1.9e-4 after 100 steps,
 *    the measured position difference), and a force is known to ulp /
 *    overlap (4e-4, growing with the position error); measured 1.2e-3 after
 *    100 steps; checked at 5e-3. Single detects only gross errors.
 *  - opencl (argument "opencl"): on an elastic frictionless variant (forces
 *    from positions only). OpenCL C may contract a*b+c (pair_kernel.h), a
 *    1-ulp difference that the collisions amplify: measured 1.4e-13 after
 *    OPENCL_STEPS = 500, checked at 1e-12; single as above. "opencl-full"
 *    runs the full laws, linear and hysteretic (measured 6.7e-13 and
 *    1.8e-14 in positions; 4e-3 before the kick stopped racing with the
 *    neighbours' velocity reads).
 * Threads: the cpu engine uses at most one thread per 2048 discs (prepare),
 * so 1 vs 2 threads is compared on a second case of 4171 discs over
 * THREAD_STEPS = 150 steps, where the system must really run 2 threads.
 * ABM4: the cpu engine in every precision (opencl has velocity Verlet only). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "granular_test_util.h"
#include "partix/backend.h"
#include "partix/memory.h"
#include "solvers/granular/granular_engine.h"

#define PI 3.14159265358979323846
#define RUN_STEPS 1500
#define FLOAT_STEPS 100
#define OPENCL_STEPS 500
#define THREAD_STEPS 150
#define TOL_DOUBLE 1e-12
#define TOL_MIXED 1e-5
#define TOL_SINGLE 5e-3

#ifdef PX_HAVE_OPENCL
static const struct px_gran_engine_i *const opencl_engine = &px_gran_engine_opencl;
#else
static const struct px_gran_engine_i *const opencl_engine = NULL;
#endif

struct setup {
  const struct px_gran_geom *g;
  const struct px_gran_motion *mo; /* 2 bodies: the box (fixed), the part */
  int nx, ny;                      /* discs on a grid */
  int hysteretic;
  int elastic; /* e = 1, no friction, no rolling: forces from positions only */
  enum px_gran_integrator integ;
  double mu_scale; /* 1, or the control's perturbation */
};

static void law(struct px_gran_law_spec *L, const struct setup *u, double e, double mu) {
  gt_law(L, 2e5, u->elastic ? 1.0 : e, u->elastic ? 0.0 : mu);
  L->mur = u->elastic ? 0.0 : 0.05;
  L->kr = 0.5;
  if (u->hysteretic) {
    L->normal = PX_GRAN_NORMAL_HYSTERETIC;
    L->phif = 0.05;
    L->damping = 0.05;
  }
}

/* The case as a prepared system of precision p with `threads` threads. */
static struct px_gran_sys *make(struct px_context *ctx, const struct setup *u, enum px_precision p,
                                int threads) {
  struct px_gran_sys *s = NULL;
  uint64_t rng[4];
  const double h = 0.0041; /* grid spacing [m]: gaps of 0.1 mm and more */
  int i, j;
  if (px_gran_sys_create(ctx, p, threads, &s) != PX_STATUS_OK) return NULL;
  law(&s->pp, u, 0.6, 0.4 * u->mu_scale);
  law(&s->pw, u, 0.5, 0.3);
  s->gravity[1] = -9.81;
  s->integrator = u->integ;
  px_gran_sys_set_walls(s, u->g, u->mo, 2);
  px_rng_seed(rng, 11);
  for (j = 0; j < u->ny; ++j)
    for (i = 0; i < u->nx; ++i) {
      const double x = 0.0025 + h * i + (j & 1) * 0.5 * h, y = 0.0025 + h * j;
      const double r = 0.0015 + 0.0005 * px_rng_uniform(rng), m = 7800 * PI * r * r * 0.004;
      const double vx = 1.5 * px_rng_normal(rng), vy = 1.5 * px_rng_normal(rng);
      /* clear of the part (centre of the box, radius 1 cm) */
      if (hypot(x - 0.046, y - 0.045) < 0.0105 + r) continue;
      if (px_gran_sys_add(s, 1, &x, &y, &r, &m) != PX_STATUS_OK ||
          px_gran_sys_set_velocity(s, (int32_t)s->n - 1, vx, vy, 0) != PX_STATUS_OK)
        break;
    }
  if (px_gran_sys_prepare(s, 0, 50) != PX_STATUS_OK) {
    printf("prepare: %s\n", px_context_message(ctx));
    px_gran_sys_free(s);
    return NULL;
  }
  return s;
}

/* Positions, velocities, spins by id, after `steps` steps on engine eng
 * (backend be). out: 5 n values (x, y, vx, vy, w per id). */
static int run(struct px_context *ctx, const struct setup *u, const struct px_gran_engine_i *eng,
               struct px_backend *be, enum px_precision p, int threads, long steps, double *out,
               size_t *n) {
  struct px_gran_sys *s = make(ctx, u, p, threads);
  void *e = NULL;
  long k;
  int ok = 0;
  size_t i;
  if (!s) return 0;
  if (threads > 1) PX_CHECK_MSG(s->threads == threads, "the system runs %d threads", s->threads);
  if (eng->create(be, s, &e) == PX_STATUS_OK) {
    ok = 1;
    for (k = 0; k < steps && ok; ++k)
      if (eng->step(e, k, s->dt) != PX_STATUS_OK) ok = 0; /* the driver's count */
    if (ok && eng->sync(e) != PX_STATUS_OK) ok = 0;
    eng->destroy(e);
  }
  PX_CHECK_MSG(ok, "%s: %s", eng->name, px_context_message(ctx));
  *n = s->n;
  for (i = 0; ok && i < s->n; ++i) {
    double rec[8];
    px_gran_sys_get(s, (int32_t)i, rec);
    memcpy(out + 5 * i, rec, 5 * sizeof(double));
  }
  px_gran_sys_free(s);
  return ok;
}

/* Largest differences of positions (over rmax), velocities and spins
 * (over the reference's largest) into d[3]. */
static void diff(const double *a, const double *ref, size_t n, double rmax, double d[3]) {
  double vmax = 0, wmax = 0;
  size_t i;
  d[0] = d[1] = d[2] = 0;
  for (i = 0; i < n; ++i) {
    const double *q = ref + 5 * i, *o = a + 5 * i;
    vmax = fmax(vmax, hypot(q[2], q[3]));
    wmax = fmax(wmax, fabs(q[4]));
    d[0] = fmax(d[0], hypot(o[0] - q[0], o[1] - q[1]));
    d[1] = fmax(d[1], hypot(o[2] - q[2], o[3] - q[3]));
    d[2] = fmax(d[2], fabs(o[4] - q[4]));
  }
  d[0] /= rmax;
  d[1] /= vmax;
  if (wmax > 0) d[2] /= wmax; /* else no spin anywhere: the absolute difference */
}

/* Engine eng against the reference ref (ns steps): within tol, or (want_fail)
 * beyond it. */
static void compare(struct px_context *ctx, const struct setup *u, const char *what,
                    const struct px_gran_engine_i *eng, struct px_backend *be, enum px_precision p,
                    int threads, long steps, const double *ref, size_t nref, double tol,
                    int want_fail) {
  double *st = malloc(5 * nref * sizeof *st), d[3];
  size_t n = 0;
  if (!st) return;
  if (run(ctx, u, eng, be, p, threads, steps, st, &n)) {
    PX_CHECK(n == nref);
    diff(st, ref, n, 0.002, d);
    printf("  %-28s %5ld steps: x %.2e  v %.2e  w %.2e  (tolerance %.0e%s)\n", what, steps, d[0],
           d[1], d[2], tol, want_fail ? ", must exceed" : "");
    if (want_fail)
      PX_CHECK_MSG(fmax(d[0], fmax(d[1], d[2])) > tol, "%s: a perturbed run passes", what);
    else
      PX_CHECK_MSG(d[0] <= tol && d[1] <= tol && d[2] <= tol, "%s differs from the reference",
                   what);
  }
  free(st);
}

/* The reference's own count of what happened: contacts now (pairs and the
 * wall contacts are in the states' overlaps) and how many distinct pairs
 * touched at some step. */
static void reference_run(struct px_context *ctx, const struct setup *u, long steps, double *out,
                          size_t *n, size_t *touched) {
  struct px_gran_sys *s = make(ctx, u, PX_PRECISION_DOUBLE, 1);
  void *e = NULL;
  size_t np = 0, i, cap = 0, nt = 0;
  int32_t *pairs = NULL;
  int64_t *seen = NULL;
  long k;
  *n = 0;
  *touched = 0;
  if (!s) return;
  PX_CHECK_OK(ctx, px_gran_engine_ref.create(NULL, s, &e));
  for (k = 0; k < steps && e; ++k) {
    if (px_gran_engine_ref.step(e, k, s->dt) != PX_STATUS_OK) break;
    if (k % 10 != 9) continue;
    if (px_gran_engine_ref.contacts(e, &pairs, &np) != PX_STATUS_OK) break;
    for (i = 0; i < np; ++i) {
      const int64_t key = (int64_t)pairs[2 * i] * 1000000 + pairs[2 * i + 1];
      size_t q;
      for (q = 0; q < nt && seen[q] != key; ++q) continue;
      if (q < nt) continue;
      if (nt == cap) {
        cap = cap ? 2 * cap : 1024;
        seen = realloc(seen, cap * sizeof *seen);
        if (!seen) break;
      }
      seen[nt++] = key;
    }
    px_mem_free(ctx, pairs);
  }
  PX_CHECK_MSG(k == steps, "reference: %s", px_context_message(ctx));
  if (e) {
    PX_CHECK_OK(ctx, px_gran_engine_ref.sync(e));
    px_gran_engine_ref.destroy(e);
  }
  for (i = 0; i < s->n; ++i) {
    double rec[8];
    px_gran_sys_get(s, (int32_t)i, rec);
    memcpy(out + 5 * i, rec, 5 * sizeof(double));
  }
  *n = s->n;
  *touched = nt;
  free(seen);
  px_gran_sys_free(s);
}

/* The box (0.092 x 0.09 m) and the vibrating part (centre 0.046, 0.045,
 * radius 9.5 mm: harmonic translation of 0.5 mm and rotation of 0.2 rad at
 * 100 Hz about its centre, body 1). */
static void scene_motion(struct px_gran_motion mo[2]) {
  px_gran_motion_init(&mo[0]);
  px_gran_motion_init(&mo[1]);
  mo[1].kind = PX_GRAN_MOTION_HARMONIC;
  mo[1].pivot[0] = 0.046, mo[1].pivot[1] = 0.045;
  mo[1].amp[0] = mo[1].amp[1] = 0.0005;
  mo[1].amp[2] = 0.2;
  mo[1].freq[0] = mo[1].freq[1] = mo[1].freq[2] = 100;
  mo[1].phase[1] = PI / 2;
}

static void scene(struct px_context *ctx, struct px_gran_geom *g, struct px_gran_motion mo[2]) {
  px_gran_geom_init(g);
  PX_CHECK_OK(ctx, gt_rect(ctx, g, 0, 0, 0.092, 0.09, 0.002, 0, "box"));
  PX_CHECK_OK(ctx, gt_circle(ctx, g, 0.046, 0.045, 0.0095, 0, 0.0015, 1, "part"));
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, g, 0.008));
  scene_motion(mo);
}

/* The cpu engine, velocity Verlet (both laws) and ABM4. */
static void cpu_cases(struct px_context *ctx, struct setup *u, double *ref) {
  size_t nref = 0, touched = 0;
  int c;
  for (c = 0; c < 3; ++c) {
    u->hysteretic = c == 1;
    u->integ = c == 2 ? PX_GRAN_INTEGRATOR_ABM4 : PX_GRAN_INTEGRATOR_VERLET;
    printf("cpu engine, %s, %s law:\n", c == 2 ? "ABM4" : "velocity Verlet",
           u->hysteretic ? "hysteretic" : "linear");
    reference_run(ctx, u, RUN_STEPS, ref, &nref, &touched);
    printf("  reference: %zu discs, %zu distinct pairs touched\n", nref, touched);
    PX_CHECK(nref > 300 && touched > 300);
    compare(ctx, u, "cpu double", &px_gran_engine_cpu, NULL, PX_PRECISION_DOUBLE, 1, RUN_STEPS, ref,
            nref, TOL_DOUBLE, 0);
    if (c == 0) {
      u->mu_scale = 1 + 1e-9;
      compare(ctx, u, "cpu double, mu + 1e-9", &px_gran_engine_cpu, NULL, PX_PRECISION_DOUBLE, 1,
              RUN_STEPS, ref, nref, TOL_DOUBLE, 1);
      u->mu_scale = 1;
    }
    reference_run(ctx, u, FLOAT_STEPS, ref, &nref, &touched);
    printf("  reference after %d steps: %zu distinct pairs touched\n", FLOAT_STEPS, touched);
    PX_CHECK(touched >= 10);
    compare(ctx, u, "cpu mixed", &px_gran_engine_cpu, NULL, PX_PRECISION_MIXED, 1, FLOAT_STEPS, ref,
            nref, TOL_MIXED, 0);
    compare(ctx, u, "cpu single", &px_gran_engine_cpu, NULL, PX_PRECISION_SINGLE, 1, FLOAT_STEPS,
            ref, nref, TOL_SINGLE, 0);
  }
  u->hysteretic = 0;
  u->integ = PX_GRAN_INTEGRATOR_VERLET;
}

/* The opencl engine: elastic (full = 0) or the full laws. */
static void opencl_cases(struct px_context *ctx, struct setup *u, struct px_backend *ocl,
                         double *ref, int full) {
  size_t nref = 0, touched = 0;
  int c;
  u->elastic = !full;
  for (c = 0; c < 2; ++c) {
    u->hysteretic = c == 1 && full;
    if (c == 1 && !full) break;
    printf("opencl engine, velocity Verlet, %s law:\n", !full           ? "elastic frictionless"
                                                        : u->hysteretic ? "hysteretic"
                                                                        : "linear");
    reference_run(ctx, u, OPENCL_STEPS, ref, &nref, &touched);
    printf("  reference: %zu discs, %zu distinct pairs touched\n", nref, touched);
    PX_CHECK(touched > 100);
    if (px_backend_has_fp64(ocl))
      compare(ctx, u, "opencl double", opencl_engine, ocl, PX_PRECISION_DOUBLE, 1, OPENCL_STEPS,
              ref, nref, TOL_DOUBLE, 0);
    reference_run(ctx, u, FLOAT_STEPS, ref, &nref, &touched);
    compare(ctx, u, "opencl single", opencl_engine, ocl, PX_PRECISION_SINGLE, 1, FLOAT_STEPS, ref,
            nref, TOL_SINGLE, 0);
  }
  u->elastic = 0;
  u->hysteretic = 0;
}

/* 1 and 2 threads: 4200 discs (70 x 60) in a box of their own. */
static void thread_cases(struct px_context *ctx, double *ref) {
  struct px_gran_geom g;
  struct px_gran_motion mo[2];
  struct setup u;
  size_t nref = 0, touched = 0;
  px_gran_geom_init(&g);
  PX_CHECK_OK(ctx, gt_rect(ctx, &g, 0, 0, 0.292, 0.25, 0.002, 0, "box"));
  PX_CHECK_OK(ctx, gt_circle(ctx, &g, 0.046, 0.045, 0.0095, 0, 0.0015, 1, "part"));
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 0.008));
  scene_motion(mo);
  memset(&u, 0, sizeof u);
  u.g = &g, u.mo = mo, u.nx = 70, u.ny = 60, u.mu_scale = 1;
  printf("cpu engine, 1 and 2 threads, linear law:\n");
  reference_run(ctx, &u, THREAD_STEPS, ref, &nref, &touched);
  printf("  reference: %zu discs, %zu distinct pairs touched\n", nref, touched);
  PX_CHECK(nref > 4096 && touched > 300);
  compare(ctx, &u, "cpu double, 1 thread", &px_gran_engine_cpu, NULL, PX_PRECISION_DOUBLE, 1,
          THREAD_STEPS, ref, nref, TOL_DOUBLE, 0);
  compare(ctx, &u, "cpu double, 2 threads", &px_gran_engine_cpu, NULL, PX_PRECISION_DOUBLE, 2,
          THREAD_STEPS, ref, nref, TOL_DOUBLE, 0);
  px_gran_geom_free(ctx, &g);
}

/* No argument: the cpu engine. argv[1] "opencl": the opencl engine on the
 * elastic frictionless case; "opencl-full": on the full laws. */
int main(int argc, char **argv) {
  struct px_context *ctx = NULL;
  struct px_backend *ocl = NULL;
  struct px_gran_geom g;
  struct px_gran_motion mo[2];
  struct setup u;
  double *ref = NULL;
  const int cl = argc > 1 && strncmp(argv[1], "opencl", 6) == 0;
  const int full = cl && strcmp(argv[1], "opencl-full") == 0;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
#ifdef PX_HAVE_OPENCL
  if (cl && px_backend_opencl_device_count(ctx) > 0)
    PX_CHECK_OK(ctx, px_backend_create(ctx, "opencl", 0, 0, &ocl));
#endif
  if (cl && !ocl) {
    printf("no OpenCL device (or a build without OpenCL): skipped\n");
    px_context_free(ctx);
    return PX_TEST_SKIP;
  }
  scene(ctx, &g, mo);
  memset(&u, 0, sizeof u);
  u.g = &g, u.mo = mo, u.nx = 21, u.ny = 20, u.mu_scale = 1;
  ref = malloc(5 * 8192 * sizeof *ref);
  if (!ref) return 1;
  if (ocl) {
    opencl_cases(ctx, &u, ocl, ref, full);
  } else {
    cpu_cases(ctx, &u, ref);
    thread_cases(ctx, ref);
  }
  free(ref);
  px_gran_geom_free(ctx, &g);
  px_backend_free(ocl);
  px_context_free(ctx);
  return px_test_report("test_granular_engines");
}
