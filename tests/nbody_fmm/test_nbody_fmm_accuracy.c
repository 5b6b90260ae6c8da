/* The FMM meets the requested tolerance: relative L2 error and max error
 * (max |Δu| / max |u|) against the double direct sum below the tolerance,
 * on uniform, clustered (Gaussian blobs; a rolled-up vortex sheet) and
 * wake-like (Kármán street + two shear layers) vortex sets with ε of the
 * particle spacing (smoothing active in the near field), for tolerances
 * 1e-3, 1e-6, 1e-9 in double and 1e-3, 1e-5 in single precision, at
 * N = 20000 (all targets) and N = 1e5 (2000 targets sampled for the
 * reference). The errors are printed, with their ratio to the tolerance. */
#include "fmm_test.h"

static void check_set(struct px_context *ctx, struct px_backend *cpu, enum px_vset set, size_t n,
                      size_t nsample) {
  static const double tol_d[3] = {1e-3, 1e-6, 1e-9}, tol_s[2] = {1e-3, 1e-5};
  double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y), *g = malloc(n * sizeof *g);
  double *u = calloc(n, sizeof *u), *v = calloc(n, sizeof *v);
  double *ru = malloc(nsample * sizeof *ru), *rv = malloc(nsample * sizeof *rv);
  double *su = malloc(nsample * sizeof *su), *sv = malloc(nsample * sizeof *sv);
  double *tx = malloc(nsample * sizeof *tx), *ty = malloc(nsample * sizeof *ty);
  size_t *idx = malloc(nsample * sizeof *idx), i;
  const double eps = px_vset_make(set, n, 2024, x, y, g);
  uint64_t rng[PX_RNG_WORDS];
  int pi, k;
  px_rng_seed(rng, 77);
  for (i = 0; i < nsample; ++i)
    idx[i] = nsample == n ? i : (size_t)(px_rng_uniform(rng) * (double)n) % n;
  for (pi = 0; pi < 2; ++pi) {
    const enum px_precision p = pi ? PX_PRECISION_SINGLE : PX_PRECISION_DOUBLE;
    const double *tols = pi ? tol_s : tol_d;
    const int ntol = pi ? 2 : 3;
    /* the inputs as the tested precision stores them */
    px_test_round(p, n, x);
    px_test_round(p, n, y);
    px_test_round(p, n, g);
    for (i = 0; i < nsample; ++i) {
      tx[i] = x[idx[i]];
      ty[i] = y[idx[i]];
    }
    {
      struct px_fmm_problem ref = {n, nsample, x, y, g, tx, ty, nsample == n};
      px_fmm_test_reference(ctx, cpu, &ref, eps, ru, rv);
    }
    for (k = 0; k < ntol; ++k) {
      struct px_fmm_problem pb = {n, n, x, y, g, x, y, 1};
      struct px_nbody *nb = px_fmm_test_fmm(ctx, cpu, p, eps, tols[k]);
      double rel, mx;
      PX_CHECK_OK(ctx, px_fmm_test_run(ctx, cpu, nb, p, &pb, PX_NBODY_MODE_SET, u, v));
      for (i = 0; i < nsample; ++i) {
        su[i] = u[idx[i]];
        sv[i] = v[idx[i]];
      }
      px_fmm_test_errors(nsample, su, sv, ru, rv, &rel, &mx);
      printf("%-8s n=%-7zu %-6s tol %.0e order %2d: rel L2 %.2e (%.3f tol), max %.2e (%.3f tol)\n",
             px_vset_name(set), n, px_precision_name(p), tols[k], px_nbody_order(nb), rel,
             rel / tols[k], mx, mx / tols[k]);
      PX_CHECK_MSG(rel <= tols[k] && mx <= tols[k],
                   "%s n=%zu %s tolerance %.0e: rel L2 %.2e, max %.2e", px_vset_name(set), n,
                   px_precision_name(p), tols[k], rel, mx);
      px_nbody_free(nb);
    }
  }
  free(x);
  free(y);
  free(g);
  free(u);
  free(v);
  free(ru);
  free(rv);
  free(su);
  free(sv);
  free(tx);
  free(ty);
  free(idx);
}

int main(void) {
  struct px_context *ctx = NULL;
  struct px_backend *cpu;
  int s;
  if (px_context_create(&ctx) != PX_STATUS_OK) return EXIT_FAILURE;
  cpu = px_test_backend(ctx, "cpu", 2);
  for (s = 0; s < PX_VSET_COUNT; ++s) check_set(ctx, cpu, (enum px_vset)s, 20000, 20000);
  check_set(ctx, cpu, PX_VSET_WAKE, 100000, 2000);
  check_set(ctx, cpu, PX_VSET_BLOBS, 100000, 2000);
  px_backend_free(cpu);
  px_context_free(ctx);
  return px_test_report("test_nbody_fmm_accuracy");
}
