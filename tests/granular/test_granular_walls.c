/* Particle–wall validation: moving-wall impact (relative restitution),
 * energy conservation in a closed box (e = 1, mu = 0), rolling and sliding
 * down an incline, the weight of a settled bed carried by the walls, and one
 * smooth wall across segment joints (convex: continuous force; concave
 * smooth: one contact, not two). */
#include "granular_test_util.h"

#define PI 3.14159265358979323846

static const double R = 0.002, M = 1.26e-4;

static void test_moving_wall_relative_restitution(struct px_context *ctx) {
  const double es[2] = {0.5, 0.9};
  int k;
  for (k = 0; k < 2; ++k) {
    struct px_gran_geom g;
    struct px_gran_motion mo;
    struct px_gran_sys *s = NULL;
    struct px_gran_stats_spec sp;
    const double V = 0.2, vin = -0.5;
    double t[2] = {0, 10}, zx[2] = {0, 0}, yy[2] = {0, 2}, rr[2] = {0, 0};
    double x = 0, y = 1.2 * R, r = R, m = M, rec[8];
    size_t seg, hits = 0;
    long step;
    px_gran_geom_init(&g);
    PX_CHECK_OK(ctx, gt_rect(ctx, &g, -0.05, 0, 0.05, 0.1, R, 0, "box"));
    PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 4 * R));
    px_gran_motion_init(&mo);
    mo.kind = PX_GRAN_MOTION_TABLE;
    mo.n = 2;
    mo.t = t, mo.x = zx, mo.y = yy, mo.r = rr;
    PX_CHECK_OK(ctx, px_gran_motion_check(ctx, &mo, "test"));
    PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s));
    gt_law(&s->pp, 2e5, es[k], 0.3);
    gt_law(&s->pw, 2e5, es[k], 0.3);
    px_gran_sys_set_walls(s, &g, &mo, 1);
    PX_CHECK_OK(ctx, px_gran_sys_add(s, 1, &x, &y, &r, &m));
    PX_CHECK_OK(ctx, px_gran_sys_set_velocity(s, 0, 0, vin, 0));
    PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
    memset(&sp, 0, sizeof sp);
    sp.finnie_n = 2;
    PX_CHECK_OK(ctx, px_gran_sys_stats_enable(s, &sp));
    for (step = 0; step < 20000; ++step) {
      px_gran_sys_step(s);
      px_gran_sys_get(s, 0, rec);
      if (rec[PX_GRAN_P_VY] > V && rec[1] - (V * s->t) > R * 1.05) break;
    }
    px_gran_sys_get(s, 0, rec);
    /* (v_out - V) = -e (v_in - V) */
    PX_CHECK_REL(rec[PX_GRAN_P_VY] - V, -es[k] * (vin - V), 0.005);
    PX_CHECK_NEAR(rec[PX_GRAN_P_VX], 0, 1e-12);
    for (seg = 0; seg < g.nseg; ++seg)
      if (s->stats.impacts[seg] > 0) {
        ++hits;
        /* the impact speed seen by the statistics is the relative approach speed */
        PX_CHECK_REL(s->stats.vn_sum[seg], V - vin, 0.01);
        PX_CHECK_REL(s->stats.en[seg], 0.5 * M * (V - vin) * (V - vin), 0.02);
      }
    PX_CHECK(hits == 1);
    px_gran_sys_free(s);
    px_gran_geom_free(ctx, &g);
  }
}

/* Discs on a lattice in a box with random velocities. */
static void fill_box(struct px_gran_sys *s, int nx, int ny, double x0, double y0, double spacing,
                     double rmin, double rmax, double vmax, uint64_t seed) {
  uint64_t rng[4];
  int i, j;
  px_rng_seed(rng, seed);
  for (j = 0; j < ny; ++j)
    for (i = 0; i < nx; ++i) {
      double x = x0 + spacing * i, y = y0 + spacing * j;
      double r = rmin + (rmax - rmin) * px_rng_uniform(rng);
      double m = 2500 * PI * r * r * 0.004;
      px_gran_sys_add(s, 1, &x, &y, &r, &m);
      px_gran_sys_set_velocity(s, (int32_t)(s->n - 1), vmax * (2 * px_rng_uniform(rng) - 1),
                               vmax * (2 * px_rng_uniform(rng) - 1), 0);
    }
}

static void test_energy_conserved_elastic_frictionless(struct px_context *ctx) {
  struct px_gran_geom g;
  struct px_gran_sys *s = NULL;
  double e0, e1, drift = 0;
  long k;
  px_gran_geom_init(&g);
  PX_CHECK_OK(ctx, gt_rect(ctx, &g, 0, 0, 0.06, 0.06, 0.9 * R, 0, "box"));
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 4 * R));
  PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 2, &s));
  gt_law(&s->pp, 2e5, 1.0, 0.0);
  gt_law(&s->pw, 2e5, 1.0, 0.0);
  px_gran_sys_set_walls(s, &g, NULL, 0);
  fill_box(s, 10, 10, 0.005, 0.005, 0.0055, 0.9 * R, 1.1 * R, 0.5, 7);
  PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
  e0 = px_gran_sys_kinetic(s) + s->ops->elastic(s);
  for (k = 0; k < 100000; ++k) {
    if (px_gran_sys_step(s) != PX_STATUS_OK) {
      PX_CHECK_MSG(0, "step failed: %s", px_context_message(ctx));
      break;
    }
    if (k % 1000 == 999) {
      double e = px_gran_sys_kinetic(s) + s->ops->elastic(s);
      if (fabs(e / e0 - 1) > drift) drift = fabs(e / e0 - 1);
    }
  }
  e1 = px_gran_sys_kinetic(s) + s->ops->elastic(s);
  printf("energy: %ld rebuilds, relative drift at the end %.2e, max over samples %.2e\n",
         s->rebuilds, e1 / e0 - 1, drift);
  PX_CHECK(drift < 1e-3);
  PX_CHECK(s->rebuilds > 10); /* the particles really moved around */
  px_gran_sys_free(s);
  px_gran_geom_free(ctx, &g);
}

/* Disc on a floor with gravity tilted by theta: returns the acceleration
 * along the floor from a least-squares parabola over [t0, t1]. */
static double incline(struct px_context *ctx, double theta, double mu, enum px_gran_integrator it,
                      double *spin_ratio) {
  struct px_gran_geom g;
  struct px_gran_sys *s = NULL;
  double x = 0.01, y = R, r = R, m = M, rec[8];
  /* ABM4 costs ~3x per step: a shorter window (the fit is exact to 1e-6 either way) */
  const double t0 = 0.05, t1 = it == PX_GRAN_INTEGRATOR_ABM4 ? 0.13 : 0.25, G = 9.81;
  double S0 = 0, S1 = 0, S2 = 0, S3 = 0, S4 = 0, Y0 = 0, Y1 = 0, Y2 = 0, a;
  px_gran_geom_init(&g);
  gt_rect(ctx, &g, 0, 0, 0.6, 0.02, R, 0, "floor");
  px_gran_geom_finish(ctx, &g, 4 * R);
  PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s));
  gt_law(&s->pp, 2e5, 0.5, mu);
  gt_law(&s->pw, 2e5, 0.5, mu);
  s->gravity[0] = G * sin(theta);
  s->gravity[1] = -G * cos(theta);
  s->integrator = it;
  px_gran_sys_set_walls(s, &g, NULL, 0);
  PX_CHECK_OK(ctx, px_gran_sys_add(s, 1, &x, &y, &r, &m));
  PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
  while (s->t < t1) {
    if (px_gran_sys_step(s) != PX_STATUS_OK) break;
    if (s->t >= t0) {
      const double t = s->t - t0;
      px_gran_sys_get(s, 0, rec);
      S0 += 1, S1 += t, S2 += t * t, S3 += t * t * t, S4 += t * t * t * t;
      Y0 += rec[0], Y1 += rec[0] * t, Y2 += rec[0] * t * t;
    }
  }
  {
    /* normal equations of x = c0 + c1 t + c2 t^2 (Cramer) */
    const double A[3][3] = {{S0, S1, S2}, {S1, S2, S3}, {S2, S3, S4}};
    const double B[3] = {Y0, Y1, Y2};
    double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                 A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                 A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    double det2 = A[0][0] * (A[1][1] * B[2] - B[1] * A[2][1]) -
                  A[0][1] * (A[1][0] * B[2] - B[1] * A[2][0]) +
                  B[0] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    a = 2 * det2 / det;
  }
  px_gran_sys_get(s, 0, rec);
  *spin_ratio = -rec[PX_GRAN_P_W] * R / rec[PX_GRAN_P_VX];
  px_gran_sys_free(s);
  px_gran_geom_free(ctx, &g);
  return a;
}

static void test_incline_rolling_and_sliding(struct px_context *ctx, int it) {
  const double th = 20 * PI / 180, G = 9.81;
  double spin, a;
  {
    const enum px_gran_integrator in = it ? PX_GRAN_INTEGRATOR_ABM4 : PX_GRAN_INTEGRATOR_VERLET;
    /* rolling without slip: mu >= tan(theta)/3 */
    a = incline(ctx, th, 0.5, in, &spin);
    printf("%s rolling: a = %.5f, expected %.5f (err %.2e), w R / v = %.5f\n",
           it ? "abm4" : "verlet", a, 2.0 / 3.0 * G * sin(th), a / (2.0 / 3.0 * G * sin(th)) - 1,
           spin);
    PX_CHECK_REL(a, 2.0 / 3.0 * G * sin(th), 0.01);
    PX_CHECK_REL(spin, 1.0, 0.01);
    /* sliding: mu < tan(theta)/3 */
    a = incline(ctx, th, 0.08, in, &spin);
    printf("%s sliding: a = %.5f, expected %.5f (err %.2e), w R / v = %.5f\n",
           it ? "abm4" : "verlet", a, G * (sin(th) - 0.08 * cos(th)),
           a / (G * (sin(th) - 0.08 * cos(th))) - 1, spin);
    PX_CHECK_REL(a, G * (sin(th) - 0.08 * cos(th)), 0.01);
    PX_CHECK(spin < 0.9);
  }
}

static void test_settled_bed_weight_on_walls(struct px_context *ctx) {
  struct px_gran_geom g;
  struct px_gran_sys *s = NULL;
  double W = 0, fy = 0, fx = 0, f[2];
  long nav = 0;
  size_t i;
  px_gran_geom_init(&g);
  PX_CHECK_OK(ctx, gt_rect(ctx, &g, 0, 0, 0.08, 0.2, 0.9 * R, 0, "box"));
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 4 * R));
  PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 2, &s));
  gt_law(&s->pp, 2e4, 0.3, 0.5);
  gt_law(&s->pw, 2e4, 0.3, 0.5);
  s->gravity[1] = -9.81;
  px_gran_sys_set_walls(s, &g, NULL, 0);
  fill_box(s, 15, 12, 0.004, 0.004, 0.0051, 0.9 * R, 1.1 * R, 0.0, 3);
  PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
  for (i = 0; i < s->n; ++i) {
    double rec[8];
    s->ops->get(s, i, rec);
    W += rec[PX_GRAN_P_M] * 9.81;
  }
  while (s->t < 0.6) {
    if (px_gran_sys_step(s) != PX_STATUS_OK) {
      PX_CHECK_MSG(0, "%s", px_context_message(ctx));
      break;
    }
    if (s->t > 0.5) {
      px_gran_sys_wall_force(s, 0, f);
      fx += f[0];
      fy += f[1];
      ++nav;
    }
  }
  fx /= (double)nav;
  fy /= (double)nav;
  printf("settled bed: weight %.6f N, wall force (%.3e, %.6f) N, err %.2e, KE %.3e J\n", W, fx, fy,
         -fy / W - 1, px_gran_sys_kinetic(s));
  /* the media pushes the walls down with its weight */
  PX_CHECK_REL(-fy, W, 0.005);
  PX_CHECK_NEAR(fx, 0, 0.005 * W);
  px_gran_sys_free(s);
  px_gran_geom_free(ctx, &g);
}

static void test_concave_smooth_joint_is_one_contact(struct px_context *ctx) {
  /* a disc resting at the bottom vertex of a polygonised circular container
   * touches both neighbouring segments; merged, it carries its weight on one
   * contact: overlap = m g / kn (two contacts would give half). */
  struct px_gran_geom g;
  struct px_gran_sys *s = NULL;
  const double Rc = 0.05, kn = 2e5;
  double x = 0, y = -Rc + 1.002 * R, r = R, m = M, rec[8], f[2] = {0, 0}, dmin = 1;
  size_t k;
  px_gran_geom_init(&g);
  PX_CHECK_OK(ctx, gt_circle(ctx, &g, 0, 0, Rc, -PI / 2, R, 0, "bowl"));
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 4 * R));
  PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s));
  gt_law(&s->pp, kn, 0.3, 0.5);
  gt_law(&s->pw, kn, 0.3, 0.5);
  s->gravity[1] = -9.81;
  px_gran_sys_set_walls(s, &g, NULL, 0);
  PX_CHECK_OK(ctx, px_gran_sys_add(s, 1, &x, &y, &r, &m));
  PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
  while (s->t < 0.05) px_gran_sys_step(s);
  px_gran_sys_get(s, 0, rec);
  px_gran_sys_wall_force(s, 0, f);
  for (k = 0; k < g.nseg; ++k) {
    /* distance to the segment lines near the bottom */
    const double d = (rec[1] - g.ay[k]) * g.tx[k] - (rec[0] - g.ax[k]) * g.ty[k];
    const double u = (rec[0] - g.ax[k]) * g.tx[k] + (rec[1] - g.ay[k]) * g.ty[k];
    if (u >= 0 && u < g.len[k] && d < dmin) dmin = d;
  }
  printf("bowl: x = %.3e, overlap %.4e, m g / kn = %.4e, wall force (%.3e, %.6e) vs weight %.6e\n",
         rec[0], R - dmin, M * 9.81 / kn, f[0], f[1], M * 9.81);
  PX_CHECK_REL(R - dmin, M * 9.81 / kn, 0.02);
  PX_CHECK_REL(-f[1], M * 9.81, 0.005);
  px_gran_sys_free(s);
  px_gran_geom_free(ctx, &g);
}

static void test_convex_joint_force_is_continuous(struct px_context *ctx) {
  /* a disc kept at constant overlap delta0 while it goes around the corner of
   * a square part (edge, vertex wedge, next edge): one contact everywhere,
   * force magnitude kn delta0 everywhere, direction turning continuously. */
  struct px_gran_geom g;
  struct px_gran_sys *s = NULL;
  const double kn = 2e5, d0 = 1e-5, L = 0.02;
  double x, y, r = R, m = M, worst = 0, prev_ang = 0;
  int k, first = 1;
  px_gran_geom_init(&g);
  PX_CHECK_OK(ctx, gt_rect(ctx, &g, -0.2, -0.2, 0.2, 0.2, R, 0, "container"));
  PX_CHECK_OK(ctx, gt_rect(ctx, &g, -L, -L, L, L, R, 1, "part"));
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 4 * R));
  PX_CHECK(g.contours[1].media_inside == 0);
  x = 0, y = L + R - d0;
  PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s));
  gt_law(&s->pp, kn, 1.0, 0.0);
  gt_law(&s->pw, kn, 1.0, 0.0);
  px_gran_sys_set_walls(s, &g, NULL, 0);
  y = L + R + 1e-4;
  PX_CHECK_OK(ctx, px_gran_sys_add(s, 1, &x, &y, &r, &m));
  PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 1e-7, 50));
  /* path at distance R - d0 from the part: top edge, corner arc, right edge */
  for (k = 0; k <= 400; ++k) {
    const double u = (double)k / 400 * 3;
    double px_, py_, rec[8], fx, fy, fm, ang;
    union px_gran_reals st[5], acc[3];
    if (u < 1)
      px_ = L * u, py_ = L + R - d0;
    else if (u < 2) {
      const double a = PI / 2 * (1 - (u - 1));
      px_ = L + (R - d0) * cos(a), py_ = L + (R - d0) * sin(a);
    } else
      px_ = L + R - d0, py_ = L - L * (u - 2);
    rec[0] = px_, rec[1] = py_, rec[2] = rec[3] = rec[4] = 0, rec[5] = R, rec[6] = M, rec[7] = 0;
    s->ops->set(s, 0, rec);
    PX_CHECK_OK(ctx, px_gran_sys_rebuild(s));
    st[0] = s->x, st[1] = s->y, st[2] = s->vx, st[3] = s->vy, st[4] = s->w;
    acc[0] = s->ax0, acc[1] = s->ay0, acc[2] = s->aw0;
    s->ops->forces(s, st, acc, 0, 0);
    fx = s->ax0.d[0] * M;
    fy = s->ay0.d[0] * M;
    fm = hypot(fx, fy);
    ang = atan2(fy, fx);
    if (fabs(fm / (kn * d0) - 1) > worst) worst = fabs(fm / (kn * d0) - 1);
    if (!first) PX_CHECK(fabs(ang - prev_ang) < 0.02); /* no jump in direction */
    prev_ang = ang;
    first = 0;
  }
  printf("convex corner: worst force magnitude deviation %.2e\n", worst);
  PX_CHECK(worst < 1e-6);
  px_gran_sys_free(s);
  px_gran_geom_free(ctx, &g);
}

static void test_sliding_work_is_the_friction_dissipation(struct px_context *ctx) {
  /* a disc thrown along a floor without spin slides until it rolls at
   * v0 (1 + m r^2 / I)^-1 = 2 v0 / 3; friction dissipates m v0^2 / 6, which
   * the statistics report as the floor's sliding work */
  struct px_gran_geom g;
  struct px_gran_sys *s = NULL;
  struct px_gran_stats_spec sp;
  const double v0 = 0.5;
  double x = 0.01, y = R, r = R, m = M, rec[8], work = 0, e0;
  size_t k;
  px_gran_geom_init(&g);
  gt_rect(ctx, &g, 0, 0, 0.3, 0.02, R, 0, "floor");
  px_gran_geom_finish(ctx, &g, 4 * R);
  PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s));
  gt_law(&s->pp, 2e5, 0.5, 0.3);
  gt_law(&s->pw, 2e5, 0.5, 0.3);
  s->gravity[1] = -9.81;
  px_gran_sys_set_walls(s, &g, NULL, 0);
  PX_CHECK_OK(ctx, px_gran_sys_add(s, 1, &x, &y, &r, &m));
  PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
  /* settle on the floor first, then throw it */
  while (s->t < 0.01) px_gran_sys_step(s);
  px_gran_sys_set_velocity(s, 0, v0, 0, 0);
  memset(&sp, 0, sizeof sp);
  sp.finnie_n = 2;
  sp.start = s->t;
  PX_CHECK_OK(ctx, px_gran_sys_stats_enable(s, &sp));
  e0 = px_gran_sys_kinetic(s);
  while (s->t < 0.1) px_gran_sys_step(s);
  px_gran_sys_stats_flush(s);
  for (k = 0; k < g.nseg; ++k) work += s->stats.slide[k];
  {
    /* Archard's integral of fn |vt| dt: while sliding, mu times it is the
     * sliding work; once rolling, vt ~ 0 adds nothing */
    double arch = 0;
    for (k = 0; k < g.nseg; ++k) arch += s->stats.archard[k];
    PX_CHECK_REL(0.3 * arch, work, 0.01);
  }
  px_gran_sys_get(s, 0, rec);
  printf(
      "sliding: v = %.5f (2 v0 / 3 = %.5f), w r / v = %.5f, sliding work %.6e J, m v0^2 / 6 = "
      "%.6e J, kinetic energy lost %.6e J\n",
      rec[PX_GRAN_P_VX], 2 * v0 / 3, -rec[PX_GRAN_P_W] * R / rec[PX_GRAN_P_VX], work,
      M * v0 * v0 / 6, e0 - px_gran_sys_kinetic(s));
  PX_CHECK_REL(rec[PX_GRAN_P_VX], 2 * v0 / 3, 0.005);
  PX_CHECK_REL(work, M * v0 * v0 / 6, 0.01);
  px_gran_sys_free(s);
  px_gran_geom_free(ctx, &g);
}

/* A disc rolling on a floor against rolling resistance: the torque
 * mu_r R m g (slipping rolling spring) with friction keeping it rolling
 * gives m a = f, I dw/dt = f R - mu_r R m g with v = -w R, so
 * a = -(2/3) mu_r g for a disc (I = m R^2 / 2). */
static void test_rolling_resistance_decelerates(struct px_context *ctx) {
  struct px_gran_geom g;
  struct px_gran_sys *s = NULL;
  const double v0 = 0.3, mur = 0.05, G = 9.81;
  double x = 0.01, y = R, r = R, m = M, rec[8], t1, v1, a;
  px_gran_geom_init(&g);
  gt_rect(ctx, &g, 0, 0, 0.3, 0.02, R, 0, "floor");
  px_gran_geom_finish(ctx, &g, 4 * R);
  PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s));
  gt_law(&s->pp, 2e5, 0.5, 0.5);
  gt_law(&s->pw, 2e5, 0.5, 0.5);
  s->pw.mur = mur;
  s->pw.kr = 2.25 * mur * mur; /* Ai et al. 2011 */
  s->gravity[1] = -G;
  px_gran_sys_set_walls(s, &g, NULL, 0);
  PX_CHECK_OK(ctx, px_gran_sys_add(s, 1, &x, &y, &r, &m));
  PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
  while (s->t < 0.01) px_gran_sys_step(s); /* settle on the floor */
  px_gran_sys_set_velocity(s, 0, v0, 0, -v0 / R);
  while (s->t < 0.03) px_gran_sys_step(s);
  px_gran_sys_get(s, 0, rec);
  t1 = s->t, v1 = rec[PX_GRAN_P_VX];
  while (s->t < 0.13) px_gran_sys_step(s);
  px_gran_sys_get(s, 0, rec);
  a = (rec[PX_GRAN_P_VX] - v1) / (s->t - t1);
  printf("rolling resistance: a = %.6f, -(2/3) mu_r g = %.6f, w R / v = %.6f\n", a,
         -2.0 / 3.0 * mur * G, -rec[PX_GRAN_P_W] * R / rec[PX_GRAN_P_VX]);
  PX_CHECK_REL(a, -2.0 / 3.0 * mur * G, 0.01);
  PX_CHECK_REL(-rec[PX_GRAN_P_W] * R / rec[PX_GRAN_P_VX], 1.0, 0.01);
  px_gran_sys_free(s);
  px_gran_geom_free(ctx, &g);
}

/* Viscous friction capped by Coulomb (no history): a disc thrown along a
 * floor without spin first slides at the Coulomb cap (a = -mu g), then
 * rolls at 2 v0 / 3 like any friction law that stops the slip. */
static void test_viscous_friction_rolls_at_two_thirds(struct px_context *ctx) {
  struct px_gran_geom g;
  struct px_gran_sys *s = NULL;
  const double v0 = 0.5, mu = 0.3, G = 9.81;
  double x = 0.01, y = R, r = R, m = M, rec[8], t1, v1, a;
  px_gran_geom_init(&g);
  gt_rect(ctx, &g, 0, 0, 0.3, 0.02, R, 0, "floor");
  px_gran_geom_finish(ctx, &g, 4 * R);
  PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, 1, &s));
  gt_law(&s->pp, 2e5, 0.5, mu);
  gt_law(&s->pw, 2e5, 0.5, mu);
  s->pw.tangential = PX_GRAN_TANGENTIAL_VISCOUS;
  s->pw.gt = 0.1; /* gt v0 = 0.05 N >> mu m g = 3.7e-4 N: capped while sliding */
  s->gravity[1] = -G;
  px_gran_sys_set_walls(s, &g, NULL, 0);
  PX_CHECK_OK(ctx, px_gran_sys_add(s, 1, &x, &y, &r, &m));
  PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
  while (s->t < 0.01) px_gran_sys_step(s);
  px_gran_sys_set_velocity(s, 0, v0, 0, 0);
  while (s->t < 0.012) px_gran_sys_step(s);
  px_gran_sys_get(s, 0, rec);
  t1 = s->t, v1 = rec[PX_GRAN_P_VX];
  while (s->t < 0.03) px_gran_sys_step(s); /* slip stops at t ~ 0.01 + v0 / (3 mu g) = 0.067 */
  px_gran_sys_get(s, 0, rec);
  a = (rec[PX_GRAN_P_VX] - v1) / (s->t - t1);
  while (s->t < 0.1) px_gran_sys_step(s);
  px_gran_sys_get(s, 0, rec);
  printf(
      "viscous friction: sliding a = %.5f (-mu g = %.5f), then v = %.6f (2 v0 / 3 = %.6f), "
      "w R / v = %.6f\n",
      a, -mu * G, rec[PX_GRAN_P_VX], 2 * v0 / 3, -rec[PX_GRAN_P_W] * R / rec[PX_GRAN_P_VX]);
  PX_CHECK_REL(a, -mu * G, 0.01);
  PX_CHECK_REL(rec[PX_GRAN_P_VX], 2 * v0 / 3, 0.005);
  PX_CHECK_REL(-rec[PX_GRAN_P_W] * R / rec[PX_GRAN_P_VX], 1.0, 0.005);
  px_gran_sys_free(s);
  px_gran_geom_free(ctx, &g);
}

/* Argument: a group ("impact", "joints", "incline", "incline_abm4", "friction", "bulk") or none
 * (all); ctest runs the groups as separate tests so that each stays short on a loaded machine. */
static int group(int argc, char **argv, const char *name) {
  return argc < 2 || strcmp(argv[1], name) == 0;
}

/* Segments far shorter than a disc: the rebuild's wall lists refuse a disc
 * near more segments than a list holds, naming it (found on all threads,
 * reported for the first disc in slot order, as one thread would). */
static void test_too_many_wall_candidates_are_refused(struct px_context *ctx) {
  int threads;
  for (threads = 1; threads <= 2; ++threads) {
    struct px_gran_geom g;
    struct px_gran_sys *s = NULL;
    /* disc 0 in the middle, disc 1 at 1.2 R above the floor: within its
     * r + skin (1.4 R), 1.44 R of floor, 864 segments of R / 600 */
    double x[2] = {0, 0.01}, y[2] = {0.05, 1.2 * R}, r[2] = {R, R}, m[2] = {M, M};
    enum px_status st;
    px_gran_geom_init(&g);
    PX_CHECK_OK(ctx, gt_rect(ctx, &g, -0.05, 0, 0.05, 0.1, R / 600, 0, "box"));
    PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 4 * R));
    PX_CHECK_OK(ctx, px_gran_sys_create(ctx, PX_PRECISION_DOUBLE, threads, &s));
    gt_law(&s->pp, 2e5, 0.5, 0.3);
    gt_law(&s->pw, 2e5, 0.5, 0.3);
    px_gran_sys_set_walls(s, &g, NULL, 0);
    PX_CHECK_OK(ctx, px_gran_sys_add(s, 2, x, y, r, m));
    st = px_gran_sys_prepare(s, 0, 50);
    PX_CHECK_MSG(st == PX_STATUS_NUMERIC && strstr(px_context_message(ctx),
                                                   "particle 1 at (0.01, 0.0024) is near more "
                                                   "than 512 boundary segments"),
                 "%d threads: %s: %s", threads, px_status_name(st), px_context_message(ctx));
    px_context_clear(ctx);
    px_gran_sys_free(s);
    px_gran_geom_free(ctx, &g);
  }
}

int main(int argc, char **argv) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  if (group(argc, argv, "impact")) test_moving_wall_relative_restitution(ctx);
  if (group(argc, argv, "joints")) {
    test_too_many_wall_candidates_are_refused(ctx);
    test_convex_joint_force_is_continuous(ctx);
    test_concave_smooth_joint_is_one_contact(ctx);
  }
  if (group(argc, argv, "incline")) {
    test_incline_rolling_and_sliding(ctx, 0); /* velocity Verlet */
    test_sliding_work_is_the_friction_dissipation(ctx);
  }
  if (group(argc, argv, "incline_abm4")) test_incline_rolling_and_sliding(ctx, 1);
  if (group(argc, argv, "friction")) {
    test_rolling_resistance_decelerates(ctx);
    test_viscous_friction_rolls_at_two_thirds(ctx);
  }
  if (group(argc, argv, "bulk")) {
    test_settled_bed_weight_on_walls(ctx);
    test_energy_conserved_elastic_frictionless(ctx);
  }
  px_context_free(ctx);
  return px_test_report("test_granular_walls");
}
