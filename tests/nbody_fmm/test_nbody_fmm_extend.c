/* px_nbody_velocity_extend: the sums at the sources of the last FMM
 * evaluation from those and new ones (the vortex wake: the generation's sum
 * at the panels' Gauss points, then the convective one with the newborns)
 * against the double direct sum; bitwise the same on 1 and 2 threads and
 * split into parts as whole; the whole sum where the old sources changed,
 * where nothing is kept (an extension after an extension) and with the
 * direct method; no new sources. */
#include "fmm_test.h"

enum { NOLD = 12000, NNEW = 900, NTG = 3000, N = NOLD + NNEW };

/* The extension on host arrays: n sources, the first n_old the last
 * evaluation's; u, v receive n entries (n_old when *ext). */
static enum px_status run_extend(struct px_context *ctx, struct px_backend *be, struct px_nbody *nb,
                                 enum px_precision p, size_t n, const double *x, const double *y,
                                 const double *g, size_t n_old, double *u, double *v, int *ext) {
  struct px_buffer *bx = px_test_upload(ctx, be, "sx", p, n, x);
  struct px_buffer *by = px_test_upload(ctx, be, "sy", p, n, y);
  struct px_buffer *bg = px_test_upload(ctx, be, "sg", p, n, g);
  struct px_buffer *bu = px_test_upload(ctx, be, "u", p, n, u);
  struct px_buffer *bv = px_test_upload(ctx, be, "v", p, n, v);
  enum px_status st =
      px_nbody_velocity_extend(nb, n, bx, by, bg, n_old, PX_NBODY_MODE_SET, bu, bv, ext);
  if (st == PX_STATUS_OK) {
    px_test_download(ctx, bu, p, n, u);
    px_test_download(ctx, bv, p, n, v);
  }
  px_buffer_free(bx);
  px_buffer_free(by);
  px_buffer_free(bg);
  px_buffer_free(bu);
  px_buffer_free(bv);
  return st;
}

/* The evaluation an extension builds on: the old sources at other targets
 * (the generation's Gauss points), into scratch. */
static void run_base(struct px_context *ctx, struct px_backend *be, struct px_nbody *nb,
                     enum px_precision p, const double *x, const double *y, const double *g,
                     const double *tx, const double *ty) {
  static double su[NTG], sv[NTG];
  struct px_fmm_problem pb = {NOLD, NTG, x, y, g, tx, ty, 0};
  PX_CHECK_OK(ctx, px_fmm_test_run(ctx, be, nb, p, &pb, PX_NBODY_MODE_SET, su, sv));
}

static void test_extend(struct px_context *ctx) {
  double *x = malloc(N * sizeof *x), *y = malloc(N * sizeof *y), *g = malloc(N * sizeof *g);
  double *tx = malloc(NTG * sizeof *tx), *ty = malloc(NTG * sizeof *ty);
  double *ru = malloc(N * sizeof *ru), *rv = malloc(N * sizeof *rv);
  double *u[2], *v[2], *w = malloc(N * sizeof *w), *z = malloc(N * sizeof *z);
  /* one wake: its last NNEW vortices are the new ones, among the others */
  const double eps = px_vset_make(PX_VSET_WAKE, N, 11, x, y, g);
  struct px_backend *be[2];
  int t, pi, ext;
  size_t i;
  for (i = 0; i < NTG; ++i) {
    tx[i] = x[4 * i] + 0.5 * eps;
    ty[i] = y[4 * i] - 0.25 * eps;
  }
  for (t = 0; t < 2; ++t) {
    be[t] = px_test_backend(ctx, "cpu", t + 1);
    u[t] = malloc(N * sizeof(double));
    v[t] = malloc(N * sizeof(double));
  }
  {
    /* the reference: the double direct sum at the old sources from all */
    struct px_fmm_problem all = {N, NOLD, x, y, g, x, y, 0};
    px_fmm_test_reference(ctx, be[1], &all, eps, ru, rv);
  }
  for (pi = 0; pi < 2; ++pi) {
    const enum px_precision p = pi ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
    const double tol = pi ? 1e-9 : 1e-4;
    double rel, mx;
    for (t = 0; t < 2; ++t) {
      struct px_nbody *nb = px_fmm_test_fmm(ctx, be[t], p, eps, tol);
      for (i = 0; i < N; ++i) u[t][i] = v[t][i] = NAN;
      run_base(ctx, be[t], nb, p, x, y, g, tx, ty);
      PX_CHECK_OK(ctx, run_extend(ctx, be[t], nb, p, N, x, y, g, NOLD, u[t], v[t], &ext));
      PX_CHECK_MSG(ext == 1, "%s, %d threads: not extended", px_precision_name(p), t + 1);
      PX_CHECK(isnan(u[t][NOLD]) && isnan(v[t][N - 1])); /* the new ones: not targets */
      px_fmm_test_errors(NOLD, u[t], v[t], ru, rv, &rel, &mx);
      PX_CHECK_MSG(rel <= tol && mx <= tol,
                   "%s extension, %d threads: rel L2 %.3g, max %.3g (tolerance %g)",
                   px_precision_name(p), t + 1, rel, mx, tol);
      /* an extension keeps nothing to extend: the whole sum (all N written) */
      PX_CHECK_OK(ctx, run_extend(ctx, be[t], nb, p, N, x, y, g, NOLD, w, z, &ext));
      PX_CHECK(ext == 0 && !isnan(w[N - 1]));
      px_fmm_test_errors(NOLD, w, z, ru, rv, &rel, &mx);
      PX_CHECK_MSG(rel <= tol && mx <= tol, "%s whole sum: rel L2 %.3g", px_precision_name(p), rel);
      /* an old source moved (by a bit): the whole sum */
      run_base(ctx, be[t], nb, p, x, y, g, tx, ty);
      {
        const double keep = x[NOLD / 2];
        x[NOLD / 2] = nextafter(keep, 1e300) + (pi ? 0.0 : 1e-6 * fabs(keep));
        PX_CHECK_OK(ctx, run_extend(ctx, be[t], nb, p, N, x, y, g, NOLD, w, z, &ext));
        PX_CHECK_MSG(ext == 0, "%s: extended though an old source moved", px_precision_name(p));
        x[NOLD / 2] = keep;
      }
      /* no new sources: the kept evaluation's tree for the old ones alone */
      run_base(ctx, be[t], nb, p, x, y, g, tx, ty);
      PX_CHECK_OK(ctx, run_extend(ctx, be[t], nb, p, NOLD, x, y, g, NOLD, w, z, &ext));
      PX_CHECK(ext == 1);
      {
        struct px_fmm_problem old = {NOLD, NOLD, x, y, g, x, y, 0};
        double *qu = malloc(NOLD * sizeof *qu), *qv = malloc(NOLD * sizeof *qv);
        px_fmm_test_reference(ctx, be[1], &old, eps, qu, qv);
        px_fmm_test_errors(NOLD, w, z, qu, qv, &rel, &mx);
        PX_CHECK_MSG(rel <= tol && mx <= tol, "%s, no new sources: rel L2 %.3g, max %.3g",
                     px_precision_name(p), rel, mx);
        free(qu);
        free(qv);
      }
      px_nbody_free(nb);
    }
    PX_CHECK_MSG(memcmp(u[0], u[1], NOLD * sizeof(double)) == 0 &&
                     memcmp(v[0], v[1], NOLD * sizeof(double)) == 0,
                 "%s extension differs between 1 and 2 threads", px_precision_name(p));
    /* split into 2 and 3 parts (the ranks): each part's targets as the
     * whole extension gives them, the others untouched, the runs tiling
     * the old sources */
    for (int parts = 2; parts <= 3; ++parts) {
      struct px_nbody *nb = px_fmm_test_fmm(ctx, be[1], p, eps, tol);
      size_t next = 0;
      for (int part = 0; part < parts; ++part) {
        const uint32_t *perm = NULL;
        size_t lo = 0, hi = 0, q;
        int same = 1, untouched = 1;
        for (i = 0; i < N; ++i) w[i] = z[i] = NAN;
        run_base(ctx, be[1], nb, p, x, y, g, tx, ty);
        px_nbody_set_part(nb, part, parts);
        PX_CHECK_OK(ctx, run_extend(ctx, be[1], nb, p, N, x, y, g, NOLD, w, z, &ext));
        px_nbody_set_part(nb, 0, 1);
        PX_CHECK(ext == 1 && px_nbody_part_targets(nb, &perm, &lo, &hi));
        PX_CHECK_MSG(lo == next && hi >= lo && hi <= NOLD, "part %d of %d: [%zu, %zu)", part, parts,
                     lo, hi);
        next = hi;
        for (q = 0; q < NOLD; ++q) {
          const size_t o = perm[q];
          if (q >= lo && q < hi)
            same &=
                memcmp(w + o, u[1] + o, sizeof *w) == 0 && memcmp(z + o, v[1] + o, sizeof *z) == 0;
          else
            untouched &= isnan(w[o]) && isnan(z[o]);
        }
        PX_CHECK_MSG(same && untouched, "%s extension, part %d of %d: %s", px_precision_name(p),
                     part, parts, same ? "wrote other targets" : "differs from the whole");
      }
      PX_CHECK_MSG(next == NOLD, "%d parts end at %zu of %d", parts, next, (int)NOLD);
      px_nbody_free(nb);
    }
  }
  {
    /* the direct method: the whole sum, as px_nbody_velocity gives it */
    struct px_nbody *nb = NULL;
    struct px_fmm_problem all = {N, N, x, y, g, x, y, 1};
    PX_CHECK_OK(ctx, px_nbody_create(be[1], PX_NBODY_METHOD_DIRECT, PX_PRECISION_DOUBLE, eps, &nb));
    PX_CHECK_OK(ctx, px_fmm_test_run(ctx, be[1], nb, PX_PRECISION_DOUBLE, &all, PX_NBODY_MODE_SET,
                                     u[0], v[0]));
    PX_CHECK_OK(ctx, run_extend(ctx, be[1], nb, PX_PRECISION_DOUBLE, N, x, y, g, NOLD, w, z, &ext));
    PX_CHECK(ext == 0 && memcmp(w, u[0], N * sizeof *w) == 0 &&
             memcmp(z, v[0], N * sizeof *z) == 0);
    px_nbody_free(nb);
  }
  for (t = 0; t < 2; ++t) {
    free(u[t]);
    free(v[t]);
    px_backend_free(be[t]);
  }
  free(x);
  free(y);
  free(g);
  free(tx);
  free(ty);
  free(ru);
  free(rv);
  free(w);
  free(z);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return EXIT_FAILURE;
  test_extend(ctx);
  px_context_free(ctx);
  return px_test_report("test_nbody_fmm_extend");
}
