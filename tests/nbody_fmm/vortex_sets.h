/* Vortex particle sets for the FMM tests and bench/vortex_fmm: positions,
 * circulations and a core radius ε comparable to the particle spacing (so
 * the smoothing max(r², ε²) is active in the near field), deterministic for
 * a seed. Shared by tests/nbody_fmm and bench/vortex_fmm.c (header only). */
#ifndef PX_VORTEX_SETS_H
#define PX_VORTEX_SETS_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "partix/rng.h"

enum px_vset {
  PX_VSET_UNIFORM = 0, /* unit square, Γ uniform in [−0.5, 0.5] */
  PX_VSET_BLOBS = 1,   /* Gaussian blobs of different sizes and signs */
  PX_VSET_SHEET = 2,   /* a rolled-up vortex sheet (shear layer): points on a curve */
  PX_VSET_WAKE = 3,    /* Kármán street of blobs + two shear layers behind a cylinder */
  PX_VSET_COUNT = 4
};

static inline const char *px_vset_name(enum px_vset s) {
  static const char *const names[] = {"uniform", "blobs", "sheet", "wake"};
  return (unsigned)s < PX_VSET_COUNT ? names[s] : "?";
}

static inline int px_vset_parse(const char *name, enum px_vset *out) {
  int k;
  for (k = 0; k < PX_VSET_COUNT; ++k)
    if (strcmp(name, px_vset_name((enum px_vset)k)) == 0) {
      *out = (enum px_vset)k;
      return 0;
    }
  return -1;
}

/* Fill x, y, g (n each) and return ε. */
static inline double px_vset_make(enum px_vset set, size_t n, uint64_t seed, double *x, double *y,
                                  double *g) {
  const double two_pi = 6.283185307179586;
  uint64_t rng[PX_RNG_WORDS];
  size_t i;
  px_rng_seed(rng, seed);
  if (n == 0) return 1e-3;
  switch (set) {
    case PX_VSET_UNIFORM:
      for (i = 0; i < n; ++i) {
        x[i] = px_rng_uniform(rng);
        y[i] = px_rng_uniform(rng);
        g[i] = px_rng_uniform(rng) - 0.5;
      }
      /* spacing 1/sqrt(n): ε of one spacing */
      return 1.0 / sqrt((double)n);
    case PX_VSET_BLOBS: {
      /* 7 blobs, σ from 0.002 to 0.1, alternating signs, one dense core */
      static const double bx[7] = {0.1, 0.8, 0.5, 0.3, 0.9, 0.55, 0.2};
      static const double by[7] = {0.2, 0.7, 0.5, 0.8, 0.1, 0.52, 0.6};
      static const double bs[7] = {0.05, 0.1, 0.002, 0.02, 0.03, 0.01, 0.004};
      for (i = 0; i < n; ++i) {
        const size_t b = i % 7;
        x[i] = bx[b] + bs[b] * px_rng_normal(rng);
        y[i] = by[b] + bs[b] * px_rng_normal(rng);
        g[i] = (b & 1 ? -1.0 : 1.0) * (0.5 + px_rng_uniform(rng)) / (double)n;
      }
      /* the densest blob (σ = 0.002 with n/7 points) has spacing ~ 0.005/sqrt(n/7) */
      return 0.005 / sqrt((double)n / 7.0);
    }
    case PX_VSET_SHEET:
      /* Kelvin–Helmholtz-like sheet: y = 0.05 sin(2πx) + a rolled-up spiral
       * part, points nearly on a curve (sheet thickness 1e-4), equal Γ */
      for (i = 0; i < n; ++i) {
        const double s = ((double)i + 0.5) / (double)n;
        if (i % 4 == 3) {
          /* spiral core around (0.5, 0): r = 0.1 θ/(8π) */
          const double th = 8.0 * two_pi * 0.5 * px_rng_uniform(rng);
          const double r = 0.1 * th / (8.0 * two_pi * 0.5);
          x[i] = 0.5 + r * cos(th);
          y[i] = r * sin(th);
        } else {
          x[i] = s;
          y[i] = 0.05 * sin(two_pi * s);
        }
        x[i] += 1e-4 * px_rng_normal(rng);
        y[i] += 1e-4 * px_rng_normal(rng);
        g[i] = 1.0 / (double)n;
      }
      /* spacing along the curve ~ 1/n (length ~1.2 for 3n/4 points) */
      return 2.0 / (double)n;
    case PX_VSET_WAKE: {
      /* cylinder of diameter 1 at the origin, flow in +x. 30% of the
       * particles in two shear layers leaving the top (Γ < 0) and bottom
       * (Γ > 0) separation points and spreading; 70% in a Kármán street of
       * 12 Gaussian blobs, alternating rows, growing cores, decaying
       * strength. Total circulation close to zero, as in a real wake. */
      const size_t nshear = n * 3 / 10;
      for (i = 0; i < n; ++i) {
        if (i < nshear) {
          const int top = (int)(i & 1);
          const double s = 2.5 * pow(px_rng_uniform(rng), 0.7); /* arc length from separation */
          const double spread = 0.005 + 0.04 * s;
          x[i] = 0.4 + s + spread * px_rng_normal(rng);
          y[i] = (top ? 1.0 : -1.0) * (0.5 + 0.15 * s - 0.08 * s * s) + spread * px_rng_normal(rng);
          g[i] = (top ? -1.0 : 1.0) * 3.0 / (double)nshear;
        } else {
          const int k = (int)((i - nshear) % 12);
          const double cx = 3.2 + 2.0 * (double)k, cy = (k & 1) ? 0.45 : -0.45;
          const double sigma = 0.12 + 0.03 * (double)k;
          const double strength = (k & 1 ? -1.0 : 1.0) * 2.5 * exp(-0.05 * (double)k);
          x[i] = cx + sigma * px_rng_normal(rng);
          y[i] = cy + sigma * px_rng_normal(rng);
          g[i] = strength * 12.0 / (double)(n - nshear);
        }
      }
      /* spacing in the shear layers near separation ~ 0.01 / sqrt(n/1e4) */
      return 0.01 / sqrt((double)n / 1.0e4);
    }
    case PX_VSET_COUNT: break;
  }
  return 1e-3;
}

#endif
