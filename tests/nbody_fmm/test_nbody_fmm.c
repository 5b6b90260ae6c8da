/* The fast multipole method behind px_nbody_velocity: edge cases (0, 1, 2
 * vortices, coincident points, clusters closer than ε), separate targets,
 * the ADD mode, workspace reuse, non-finite input, thread-count
 * independence (bitwise), split evaluations (the ranks of a run), method
 * selection (AUTO) and the knobs' checks. Accuracy on large sets is
 * test_nbody_fmm_accuracy. */
#include "fmm_test.h"

static const double two_pi = 6.283185307179586476925;

/* 0, 1 and 2 vortices: nothing, a vortex alone (zero: ε > 0 removes the
 * self term) and a pair, both farther apart than ε and closer (then the
 * core's solid-body rotation Γ d / (2π ε²)). */
static void test_small(struct px_context *ctx, struct px_backend *cpu) {
  int pi, k;
  for (pi = 0; pi < 2; ++pi) {
    const enum px_precision p = pi ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
    const double tol = pi ? 1e-12 : 1e-6;
    for (k = 0; k < 2; ++k) {
      /* pair at distance 0.5 (eps 0.1), then 0.05 (eps 0.1) */
      const double d = k == 0 ? 0.5 : 0.05, eps = 0.1, g1 = 1.5, g2 = -0.75;
      const double x[2] = {0.25, 0.25 + 0.6 * d}, y[2] = {-0.5, -0.5 + 0.8 * d};
      const double gam[2] = {g1, g2};
      const double den = two_pi * (d * d > eps * eps ? d * d : eps * eps);
      struct px_fmm_problem pb = {2, 2, x, y, gam, x, y, 1};
      struct px_nbody *nb = px_fmm_test_fmm(ctx, cpu, p, eps, 1e-3);
      double u[2] = {7.0, 7.0}, v[2] = {7.0, 7.0};
      PX_CHECK_OK(ctx, px_fmm_test_run(ctx, cpu, nb, p, &pb, PX_NBODY_MODE_SET, u, v));
      /* u_1 = Γ_2 (−dy, dx) / (2π max(d², ε²)), (dx, dy) = r_1 − r_2 */
      PX_CHECK_NEAR(u[0], -g2 * (y[0] - y[1]) / den, tol * fabs(g2 / den) * d);
      PX_CHECK_NEAR(v[0], g2 * (x[0] - x[1]) / den, tol * fabs(g2 / den) * d);
      PX_CHECK_NEAR(u[1], -g1 * (y[1] - y[0]) / den, tol * fabs(g1 / den) * d);
      PX_CHECK_NEAR(v[1], g1 * (x[1] - x[0]) / den, tol * fabs(g1 / den) * d);
      /* one vortex: zero velocity */
      pb.ns = pb.nt = 1;
      PX_CHECK_OK(ctx, px_fmm_test_run(ctx, cpu, nb, p, &pb, PX_NBODY_MODE_SET, u, v));
      PX_CHECK(u[0] == 0.0 && v[0] == 0.0);
      /* no sources (so the targets are other buffers): SET writes zeros,
       * ADD keeps the outputs */
      u[0] = v[0] = 3.0;
      pb.ns = 0;
      pb.self = 0;
      PX_CHECK_OK(ctx, px_fmm_test_run(ctx, cpu, nb, p, &pb, PX_NBODY_MODE_ADD, u, v));
      PX_CHECK(u[0] == 3.0 && v[0] == 3.0);
      PX_CHECK_OK(ctx, px_fmm_test_run(ctx, cpu, nb, p, &pb, PX_NBODY_MODE_SET, u, v));
      PX_CHECK(u[0] == 0.0 && v[0] == 0.0);
      /* no targets: nothing to do */
      pb.ns = 2;
      pb.nt = 0;
      PX_CHECK_OK(ctx, px_fmm_test_run(ctx, cpu, nb, p, &pb, PX_NBODY_MODE_SET, u, v));
      px_nbody_free(nb);
    }
  }
}

/* Coincident vortices add nothing to each other (ε > 0): 400 at one point
 * plus 3000 spread ones match the direct sum; a set that is one point only
 * (the tree cannot split it: one big leaf) gives exactly zero. */
static void test_coincident(struct px_context *ctx, struct px_backend *cpu) {
  enum { NC = 400, NS = 3000, N = NC + NS };
  double *x = malloc(N * sizeof *x), *y = malloc(N * sizeof *y), *g = malloc(N * sizeof *g);
  double *u = calloc(N, sizeof *u), *v = calloc(N, sizeof *v);
  double *ru = malloc(N * sizeof *ru), *rv = malloc(N * sizeof *rv), rel, mx;
  struct px_fmm_problem pb = {N, N, NULL, NULL, NULL, NULL, NULL, 1};
  struct px_nbody *nb;
  size_t i;
  const double eps = px_vset_make(PX_VSET_UNIFORM, NS, 3, x + NC, y + NC, g + NC);
  for (i = 0; i < NC; ++i) {
    x[i] = 0.3;
    y[i] = 0.3;
    g[i] = i % 2 ? 0.25 : -0.1;
  }
  pb.sx = pb.tx = x;
  pb.sy = pb.ty = y;
  pb.sg = g;
  px_fmm_test_reference(ctx, cpu, &pb, eps, ru, rv);
  nb = px_fmm_test_fmm(ctx, cpu, PX_PRECISION_DOUBLE, eps, 1e-9);
  PX_CHECK_OK(ctx,
              px_fmm_test_run(ctx, cpu, nb, PX_PRECISION_DOUBLE, &pb, PX_NBODY_MODE_SET, u, v));
  px_fmm_test_errors(N, u, v, ru, rv, &rel, &mx);
  PX_CHECK_MSG(rel <= 1e-9 && mx <= 1e-9, "coincident points: rel L2 %.2e, max %.2e", rel, mx);
  /* all on one point */
  pb.ns = pb.nt = NC;
  PX_CHECK_OK(ctx,
              px_fmm_test_run(ctx, cpu, nb, PX_PRECISION_DOUBLE, &pb, PX_NBODY_MODE_SET, u, v));
  for (i = 0; i < NC; ++i) PX_CHECK(u[i] == 0.0 && v[i] == 0.0);
  px_nbody_free(nb);
  free(x);
  free(y);
  free(g);
  free(u);
  free(v);
  free(ru);
  free(rv);
}

/* Two tight clusters (radius 1e-4) 3e-3 apart with ε = 1e-2: the opening
 * ratio alone would accept them as far field, where the point-vortex
 * kernel is 11 times the smoothed one; the ε condition keeps every such
 * pair in the near field, so the sum equals the direct sum. The clusters
 * are larger than a leaf, so they are separate cells that the traversal
 * does test. */
static void test_close_clusters(struct px_context *ctx, struct px_backend *cpu) {
  enum { NC = 300, N = 2 * NC };
  double x[N], y[N], g[N], u[N], v[N], ru[N], rv[N], rel, mx;
  struct px_fmm_problem pb = {N, N, x, y, g, x, y, 1};
  uint64_t rng[PX_RNG_WORDS];
  int pi;
  size_t i;
  px_rng_seed(rng, 11);
  for (i = 0; i < N; ++i) {
    const double a = 6.283185307 * px_rng_uniform(rng), r = 1e-4 * sqrt(px_rng_uniform(rng));
    x[i] = (i < NC ? 0.0 : 3e-3) + r * cos(a);
    y[i] = r * sin(a);
    g[i] = (i < NC ? 1.0 : -0.5) / NC;
  }
  for (pi = 0; pi < 2; ++pi) {
    const enum px_precision p = pi ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
    const double tol = pi ? 1e-9 : 1e-5;
    struct px_nbody *nb = px_fmm_test_fmm(ctx, cpu, p, 1e-2, tol);
    px_test_round(p, N, x);
    px_test_round(p, N, y);
    px_test_round(p, N, g);
    px_fmm_test_reference(ctx, cpu, &pb, 1e-2, ru, rv);
    PX_CHECK_OK(ctx, px_fmm_test_run(ctx, cpu, nb, p, &pb, PX_NBODY_MODE_SET, u, v));
    px_fmm_test_errors(N, u, v, ru, rv, &rel, &mx);
    PX_CHECK_MSG(rel <= tol && mx <= tol, "%s clusters closer than eps: rel L2 %.2e, max %.2e",
                 px_precision_name(p), rel, mx);
    px_nbody_free(nb);
  }
}

/* Targets that are not the sources (panel control points on a circle in a
 * wake), added (mode ADD) onto a free stream. */
static void test_separate_targets(struct px_context *ctx, struct px_backend *cpu) {
  enum { NS = 20000, NT = 2576 };
  double *sx = malloc(NS * sizeof *sx), *sy = malloc(NS * sizeof *sy),
         *sg = malloc(NS * sizeof *sg);
  double tx[NT], ty[NT], u[NT], v[NT], ru[NT], rv[NT], rel, mx;
  struct px_fmm_problem pb = {NS, NT, sx, sy, sg, tx, ty, 0};
  const double eps = px_vset_make(PX_VSET_WAKE, NS, 5, sx, sy, sg);
  struct px_nbody *nb = px_fmm_test_fmm(ctx, cpu, PX_PRECISION_DOUBLE, eps, 1e-6);
  size_t i;
  for (i = 0; i < NT; ++i) {
    const double a = two_pi * ((double)i + 0.5) / NT;
    tx[i] = 0.5 * cos(a);
    ty[i] = 0.5 * sin(a);
    u[i] = 1.0;
    v[i] = 0.0;
  }
  px_fmm_test_reference(ctx, cpu, &pb, eps, ru, rv);
  for (i = 0; i < NT; ++i) ru[i] += 1.0;
  PX_CHECK_OK(ctx,
              px_fmm_test_run(ctx, cpu, nb, PX_PRECISION_DOUBLE, &pb, PX_NBODY_MODE_ADD, u, v));
  px_fmm_test_errors(NT, u, v, ru, rv, &rel, &mx);
  PX_CHECK_MSG(rel <= 1e-6 && mx <= 1e-6, "separate targets: rel L2 %.2e, max %.2e", rel, mx);
  px_nbody_free(nb);
  free(sx);
  free(sy);
  free(sg);
}

/* Bitwise the same results on 1, 2 and 3 threads (self and separate
 * targets, float and double), and the same on an evaluator that was used
 * before on other sizes (its workspace is reused) as on a fresh one. */
static void test_threads(struct px_context *ctx) {
  enum { N = 20000, NT = 4000 };
  double *x = malloc(N * sizeof *x), *y = malloc(N * sizeof *y), *g = malloc(N * sizeof *g);
  double *u[3], *v[3], *w[3], *z[3];
  const double eps = px_vset_make(PX_VSET_WAKE, N, 9, x, y, g);
  struct px_backend *be[3];
  int t, pi;
  for (t = 0; t < 3; ++t) be[t] = px_test_backend(ctx, "cpu", t + 1);
  for (t = 0; t < 3; ++t) {
    u[t] = calloc(N, sizeof(double));
    v[t] = calloc(N, sizeof(double));
    w[t] = calloc(N, sizeof(double));
    z[t] = calloc(N, sizeof(double));
  }
  for (pi = 0; pi < 2; ++pi) {
    const enum px_precision p = pi ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
    struct px_fmm_problem self = {N, N, x, y, g, x, y, 1};
    struct px_fmm_problem sep = {N, NT, x, y, g, x + 1, y + 3, 0};
    for (t = 0; t < 3; ++t) {
      struct px_nbody *nb = px_fmm_test_fmm(ctx, be[t], p, eps, pi ? 1e-9 : 1e-3);
      PX_CHECK_OK(ctx, px_fmm_test_run(ctx, be[t], nb, p, &self, PX_NBODY_MODE_SET, u[t], v[t]));
      PX_CHECK_OK(ctx, px_fmm_test_run(ctx, be[t], nb, p, &sep, PX_NBODY_MODE_SET, w[t], z[t]));
      px_nbody_free(nb);
    }
    for (t = 1; t < 3; ++t) {
      PX_CHECK_MSG(memcmp(u[0], u[t], N * sizeof(double)) == 0 &&
                       memcmp(v[0], v[t], N * sizeof(double)) == 0,
                   "%s FMM (self) differs between 1 and %d threads", px_precision_name(p), t + 1);
      PX_CHECK_MSG(memcmp(w[0], w[t], NT * sizeof(double)) == 0 &&
                       memcmp(z[0], z[t], NT * sizeof(double)) == 0,
                   "%s FMM (targets) differs between 1 and %d threads", px_precision_name(p),
                   t + 1);
    }
    {
      /* reuse: a small sum, a large one, the first again */
      struct px_nbody *nb = px_fmm_test_fmm(ctx, be[1], p, eps, pi ? 1e-9 : 1e-3);
      struct px_fmm_problem small = {1000, 1000, x + 7, y + 7, g + 7, x + 7, y + 7, 1};
      PX_CHECK_OK(ctx, px_fmm_test_run(ctx, be[1], nb, p, &sep, PX_NBODY_MODE_SET, w[1], z[1]));
      PX_CHECK_OK(ctx, px_fmm_test_run(ctx, be[1], nb, p, &small, PX_NBODY_MODE_SET, w[2], z[2]));
      PX_CHECK_OK(ctx, px_fmm_test_run(ctx, be[1], nb, p, &self, PX_NBODY_MODE_SET, u[1], v[1]));
      PX_CHECK_OK(ctx, px_fmm_test_run(ctx, be[1], nb, p, &sep, PX_NBODY_MODE_SET, w[2], z[2]));
      PX_CHECK_MSG(memcmp(u[0], u[1], N * sizeof(double)) == 0 &&
                       memcmp(v[0], v[1], N * sizeof(double)) == 0 &&
                       memcmp(w[0], w[2], NT * sizeof(double)) == 0 &&
                       memcmp(z[0], z[2], NT * sizeof(double)) == 0,
                   "%s FMM differs on a reused evaluator", px_precision_name(p));
      px_nbody_free(nb);
    }
  }
  for (t = 0; t < 3; ++t) {
    free(u[t]);
    free(v[t]);
    free(w[t]);
    free(z[t]);
    px_backend_free(be[t]);
  }
  free(x);
  free(y);
  free(g);
}

/* A split evaluation (px_nbody_set_part: the ranks of one run) writes only
 * its part's targets, and those bit for bit as the whole sum does; the
 * parts' Morton runs tile the targets in part order, each within a quarter
 * of an equal share (its subtrees hold at most n / (8 threads parts)
 * points). 2-4 parts, 1 and 2 threads, self and separate targets, float
 * and double. */
static void test_split(struct px_context *ctx) {
  enum { N = 20000, NT = 6000 };
  double *x = malloc(N * sizeof *x), *y = malloc(N * sizeof *y), *g = malloc(N * sizeof *g);
  double *u0 = malloc(N * sizeof *u0), *v0 = malloc(N * sizeof *v0);
  double *u = malloc(N * sizeof *u), *v = malloc(N * sizeof *v);
  const double eps = px_vset_make(PX_VSET_WAKE, N, 5, x, y, g);
  int t, pi, self, parts, part;
  for (t = 1; t <= 2; ++t) {
    struct px_backend *be = px_test_backend(ctx, "cpu", t);
    for (pi = 0; pi < 2; ++pi)
      for (self = 0; self < 2; ++self) {
        const enum px_precision p = pi ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
        struct px_fmm_problem pb = {N,   self ? N : NT, x, y, g, self ? x : x + 3, self ? y : y + 5,
                                    self};
        const size_t nt = pb.nt;
        struct px_nbody *nb = px_fmm_test_fmm(ctx, be, p, eps, pi ? 1e-9 : 1e-3);
        const uint32_t *perm = NULL;
        size_t lo = 0, hi = 0, q, i;
        PX_CHECK_OK(ctx, px_fmm_test_run(ctx, be, nb, p, &pb, PX_NBODY_MODE_SET, u0, v0));
        PX_CHECK(!px_nbody_part_targets(nb, &perm, &lo, &hi));
        for (parts = 2; parts <= 4; ++parts) {
          size_t next = 0;
          for (part = 0; part < parts; ++part) {
            int same = 1, untouched = 1;
            for (i = 0; i < nt; ++i) u[i] = v[i] = NAN;
            px_nbody_set_part(nb, part, parts);
            PX_CHECK_OK(ctx, px_fmm_test_run(ctx, be, nb, p, &pb, PX_NBODY_MODE_SET, u, v));
            PX_CHECK(px_nbody_part_targets(nb, &perm, &lo, &hi));
            PX_CHECK_MSG(lo == next && hi >= lo && hi <= nt,
                         "part %d of %d: run [%zu, %zu) does not follow %zu", part, parts, lo, hi,
                         next);
            next = hi;
            PX_CHECK_MSG(fabs((double)(hi - lo) - (double)nt / parts) <= 0.25 * (double)nt / parts,
                         "part %d of %d: %zu of %zu targets", part, parts, hi - lo, nt);
            for (q = 0; q < nt; ++q) {
              const size_t o = perm[q];
              if (q >= lo && q < hi)
                same &=
                    memcmp(u + o, u0 + o, sizeof *u) == 0 && memcmp(v + o, v0 + o, sizeof *v) == 0;
              else
                untouched &= isnan(u[o]) && isnan(v[o]);
            }
            PX_CHECK_MSG(same && untouched, "%s FMM (%s, %d threads), part %d of %d: %s",
                         px_precision_name(p), self ? "self" : "targets", t, part, parts,
                         same ? "wrote other targets" : "differs from the whole sum");
          }
          PX_CHECK_MSG(next == nt, "%d parts end at %zu of %zu targets", parts, next, nt);
        }
        px_nbody_set_part(nb, 0, 1);
        PX_CHECK_OK(ctx, px_fmm_test_run(ctx, be, nb, p, &pb, PX_NBODY_MODE_SET, u, v));
        PX_CHECK(!px_nbody_part_targets(nb, &perm, &lo, &hi));
        PX_CHECK(memcmp(u, u0, nt * sizeof *u) == 0 && memcmp(v, v0, nt * sizeof *v) == 0);
        px_nbody_free(nb);
      }
    px_backend_free(be);
  }
  free(x);
  free(y);
  free(g);
  free(u0);
  free(v0);
  free(u);
  free(v);
}

/* A NaN or infinite position gives NaN velocities (as the direct sum does:
 * every target sums the bad vortex) and neither a crash nor a hang. */
static void test_nonfinite(struct px_context *ctx, struct px_backend *cpu) {
  enum { N = 5000 };
  double *x = malloc(N * sizeof *x), *y = malloc(N * sizeof *y), *g = malloc(N * sizeof *g);
  double *u = calloc(N, sizeof *u), *v = calloc(N, sizeof *v);
  struct px_fmm_problem pb = {N, N, x, y, g, x, y, 1};
  const double eps = px_vset_make(PX_VSET_BLOBS, N, 4, x, y, g);
  struct px_nbody *nb = px_fmm_test_fmm(ctx, cpu, PX_PRECISION_DOUBLE, eps, 1e-6);
  int k;
  size_t i, bad;
  for (k = 0; k < 2; ++k) {
    x[77] = k == 0 ? NAN : INFINITY;
    PX_CHECK_OK(ctx,
                px_fmm_test_run(ctx, cpu, nb, PX_PRECISION_DOUBLE, &pb, PX_NBODY_MODE_SET, u, v));
    for (i = bad = 0; i < N; ++i) bad += !(u[i] == u[i]) || !(v[i] == v[i]);
    PX_CHECK_MSG(bad == N, "%s position: %zu of %d velocities NaN, expected all (direct sum)",
                 k == 0 ? "NaN" : "infinite", bad, N);
  }
  px_nbody_free(nb);
  free(x);
  free(y);
  free(g);
  free(u);
  free(v);
}

/* Names, knobs and their checks, the UNSUPPORTED FMM on opencl and what
 * AUTO picks. */
static void test_api(struct px_context *ctx, struct px_backend *cpu) {
  enum px_nbody_method m;
  struct px_nbody *nb = NULL;
  int prev = 0, order;
  double tol;
  PX_CHECK_OK(ctx, px_nbody_method_parse("fmm", &m));
  PX_CHECK(m == PX_NBODY_METHOD_FMM);
  PX_CHECK_OK(ctx, px_nbody_method_parse("auto", &m));
  PX_CHECK(m == PX_NBODY_METHOD_AUTO);
  PX_CHECK_OK(ctx, px_nbody_method_parse("direct", &m));
  PX_CHECK(m == PX_NBODY_METHOD_DIRECT);
  PX_CHECK(px_nbody_method_parse("tree", &m) == PX_STATUS_INVALID);
  PX_CHECK(strcmp(px_nbody_method_name(PX_NBODY_METHOD_FMM), "fmm") == 0);
  PX_CHECK(strcmp(px_nbody_method_name(PX_NBODY_METHOD_AUTO), "auto") == 0);

  PX_CHECK_OK(ctx, px_nbody_create(cpu, PX_NBODY_METHOD_FMM, PX_PRECISION_DOUBLE, 0.01, &nb));
  PX_CHECK(px_nbody_tolerance(nb) == 1e-6);
  PX_CHECK_STATUS(ctx, px_nbody_set_tolerance(nb, 0.0), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_nbody_set_tolerance(nb, 0.5), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_nbody_set_tolerance(nb, 1e-13), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_nbody_set_tolerance(nb, NAN), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_nbody_set_order(nb, 1), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_nbody_set_order(nb, PX_FMM_MAX_ORDER + 1), PX_STATUS_INVALID);
  /* a smaller tolerance never lowers the order */
  for (tol = 0.1; tol >= 1e-12; tol *= 0.1) {
    PX_CHECK_OK(ctx, px_nbody_set_tolerance(nb, tol));
    order = px_nbody_order(nb);
    PX_CHECK_MSG(order >= prev && order >= 2 && order <= PX_FMM_MAX_ORDER,
                 "order %d at tolerance %g after %d", order, tol, prev);
    prev = order;
  }
  PX_CHECK_OK(ctx, px_nbody_set_order(nb, 17));
  PX_CHECK(px_nbody_order(nb) == 17);
  PX_CHECK_OK(ctx, px_nbody_set_order(nb, 0));
  PX_CHECK(px_nbody_order(nb) == prev);
  px_nbody_free(nb);

  PX_CHECK_OK(ctx, px_nbody_create(cpu, PX_NBODY_METHOD_FMM, PX_PRECISION_SINGLE, 0.01, &nb));
  PX_CHECK_STATUS(ctx, px_nbody_set_tolerance(nb, 1e-6), PX_STATUS_INVALID);
  PX_CHECK(strstr(px_context_message(ctx), "double") != NULL);
  PX_CHECK_OK(ctx, px_nbody_set_tolerance(nb, 1e-5));
  PX_CHECK_STATUS(ctx, px_nbody_set_order(nb, PX_FMM_MAX_ORDER_SINGLE + 1), PX_STATUS_INVALID);
  px_nbody_free(nb);

  /* AUTO on the cpu: direct below the crossover, FMM above */
  {
    enum { N = 4000 };
    double *x = malloc(N * sizeof *x), *y = malloc(N * sizeof *y), *g = malloc(N * sizeof *g);
    double *u = calloc(N, sizeof *u), *v = calloc(N, sizeof *v);
    const double eps = px_vset_make(PX_VSET_UNIFORM, N, 1, x, y, g);
    const size_t small = 1000, large = (size_t)ceil(sqrt(px_nbody_auto_pairs)) + 1;
    struct px_fmm_problem pb = {small, small, x, y, g, x, y, 1};
    PX_CHECK(large <= N);
    PX_CHECK_OK(ctx, px_nbody_create(cpu, PX_NBODY_METHOD_AUTO, PX_PRECISION_DOUBLE, eps, &nb));
    PX_CHECK(px_nbody_last_method(nb) == PX_NBODY_METHOD_AUTO);
    PX_CHECK_OK(ctx,
                px_fmm_test_run(ctx, cpu, nb, PX_PRECISION_DOUBLE, &pb, PX_NBODY_MODE_SET, u, v));
    PX_CHECK(px_nbody_last_method(nb) == PX_NBODY_METHOD_DIRECT);
    pb.ns = pb.nt = large;
    PX_CHECK_OK(ctx,
                px_fmm_test_run(ctx, cpu, nb, PX_PRECISION_DOUBLE, &pb, PX_NBODY_MODE_SET, u, v));
    PX_CHECK(px_nbody_last_method(nb) == PX_NBODY_METHOD_FMM);
    px_nbody_free(nb);

#ifdef PX_HAVE_OPENCL
    if (px_backend_opencl_device_count(ctx) > 0) {
      /* the OpenCL direct sum is the device path: FMM is refused there,
       * AUTO runs the direct sum at any size */
      struct px_backend *cl = px_test_backend(ctx, "opencl", 0);
      PX_CHECK_STATUS(ctx, px_nbody_create(cl, PX_NBODY_METHOD_FMM, PX_PRECISION_SINGLE, eps, &nb),
                      PX_STATUS_UNSUPPORTED);
      PX_CHECK(nb == NULL && strstr(px_context_message(ctx), "auto") != NULL);
      PX_CHECK_OK(ctx, px_nbody_create(cl, PX_NBODY_METHOD_AUTO, PX_PRECISION_SINGLE, eps, &nb));
      PX_CHECK_OK(ctx,
                  px_fmm_test_run(ctx, cl, nb, PX_PRECISION_SINGLE, &pb, PX_NBODY_MODE_SET, u, v));
      PX_CHECK(px_nbody_last_method(nb) == PX_NBODY_METHOD_DIRECT);
      px_nbody_free(nb);
      px_backend_free(cl);
    }
#endif
    free(x);
    free(y);
    free(g);
    free(u);
    free(v);
  }
}

int main(void) {
  struct px_context *ctx = NULL;
  struct px_backend *cpu;
  if (px_context_create(&ctx) != PX_STATUS_OK) return EXIT_FAILURE;
  cpu = px_test_backend(ctx, "cpu", 2);
  test_small(ctx, cpu);
  test_coincident(ctx, cpu);
  test_close_clusters(ctx, cpu);
  test_separate_targets(ctx, cpu);
  test_threads(ctx);
  test_split(ctx);
  test_nonfinite(ctx, cpu);
  test_api(ctx, cpu);
  px_backend_free(cpu);
  px_context_free(ctx);
  return px_test_report("test_nbody_fmm");
}
