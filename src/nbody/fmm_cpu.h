/* Template of the cpu fast multipole method; instantiated by fmm_cpu_f32.c
 * and fmm_cpu_f64.c (see src/kernels/px_kernel.h).
 *
 * What is computed
 * ----------------
 * The smoothed Biot–Savart sum of include/partix/nbody.h,
 *   2π (u_i, v_i) = Σ_j Γ_j (−dy, dx) / max(|d|², ε²),   d = z_i − z_j,
 * split into a near field, summed pair by pair with the smoothing (P2P), and
 * a far field of point vortices, f(z) = Σ_j Γ_j / (z − z_j), for which
 * 2π (u − i v) = f / i, i.e. 2π u = Im f and 2π v = Re f. Far-field pairs are
 * at least ε apart (below), where max(r², ε²) = r²: there the smoothed and
 * the point-vortex kernels are the same function, so the far field is exact
 * up to the truncation of the expansions.
 *
 * Expansions (Greengard & Rokhlin, J. Comput. Phys. 73 (1987) 325, sec. 2;
 * the Cauchy-kernel form of fmm2d's cfmm2d), about a centre c with a scale
 * r > 0, coefficients stored scaled so that they are O(Σ|Γ|):
 *   multipole  f(z) = Σ_{k<p} ã_k r^k / (z − c)^{k+1},  ã_k = Σ_j Γ_j ((z_j − c)/r)^k   (P2M)
 *   local      f(z) = Σ_{l<p} b̃_l ((z − c)/r)^l                                     (L2P)
 * Translations (z0, δ complex; C(n, k) binomials):
 *   M2M  child (c, r_c) -> parent (c', r'), u = (c − c')/r', σ = r_c/r':
 *        ã'_k = Σ_{m<=k} C(k, m) u^{k−m} σ^m ã_m                 (exact: the moments)
 *   M2L  source (c_s, r_s) -> target (c_t, r_t), z0 = c_t − c_s,
 *        ρ_s = r_s/z0, ρ_t = r_t/z0:
 *        b̃_l += (−1)^l ρ_t^l / z0 · Σ_k C(k + l, k) ρ_s^k ã_k      (GR87 Lemma 2.3)
 *   L2L  parent (c, r) -> child (c', r'), u = (c' − c)/r, σ = r'/r:
 *        b̃'_m = σ^m Σ_{l>=m} C(l, m) u^{l−m} b̃_l                  (exact)
 *   P2L  b̃_l += −Σ_j Γ_j / s_j · (r_t/s_j)^l,  s_j = z_j − c_t
 *   M2P  f(z) = (q/r) Σ_k ã_k q^k,  q = r/(z − c)
 * M2L is written as a pre-scaling by ρ_s^k, a product with the fixed real
 * matrix C(k + l, k) and a post-scaling by (−ρ_t)^l / z0; the M2Ls of one
 * target cell are batched as columns, so the middle step is a small matrix
 * product (p × p real by p × 2m), register-blocked and vectorised.
 *
 * Tree and traversal
 * ------------------
 * Sources and targets are sorted into Morton order and get a quadtree each
 * (fmm_tree.c; one tree when the targets are the sources). Every cell has
 * the centre c of its points' bounding box and a radius R with every point
 * within R of c. A target cell t and a source cell s are well separated
 * (accepted) when
 *   (a)  R_t + R_s <= θ d,           d = |c_t − c_s|   (multipole acceptance)
 *   (b)  d − R_t − R_s >= ε (1 + 1e-6) + rounding slack.
 * Dual-tree traversal with fixed ownership (Dehnen, J. Comput. Phys. 179
 * (2002) 27, sec. 3, "interaction phase", organised per target cell as in
 * the adaptive lists of Carrier, Greengard & Rokhlin, SIAM J. Sci. Stat.
 * Comput. 9 (1988) 669): target cells are visited generation by
 * generation; a cell takes the source cells its parent handed down and
 * tests each: accepted pairs become an M2L (V list), P2L (X list), M2P (W
 * list, leaves only) or P2P, whichever the cost model says is cheapest;
 * rejected pairs split the source cell if the target is a leaf or the
 * source is the larger, are summed pair by pair if both are leaves, and are
 * handed down to the target's children otherwise.
 *
 * Why no pair closer than ε reaches the far field: for a point a of t and
 * b of s, |a − b| >= |c_t − c_s| − |a − c_t| − |b − c_s| >= d − R_t − R_s
 * (triangle inequality), and (b) makes that >= ε. R is an upper bound by
 * construction (rounded up by 1e-12 relative, far above the rounding of its
 * double computation from the points), d is computed in double with the
 * slack 4 DBL_EPSILON (|c_t| + |c_s|) covering its rounding. Pairs that fail
 * (b) are never accepted, so they end in P2P with the smoothed kernel.
 * (a) with θ < 1 gives the convergence ratios R_s/(d − R_t) and
 * R_t/(d − R_s) < 1 of the multipole and local series (GR87, Thm 2.1 and
 * Lemma 2.3); the truncation error of one interaction is about
 * Σ|Γ_s| / d · (θ/(2 − θ))^p for cells of similar size (fmm.c picks p and θ).
 *
 * Determinism: every target value is computed by one thread, in an order
 * fixed by the trees (traversal order, list order, fixed batch and chunk
 * widths); the trees are the stable sort by Morton key. Thread count and
 * schedule change who computes a cell, never the operations: results are
 * bitwise identical for any number of threads. */
#include <float.h>
#include <omp.h>
#include <string.h>

#include "kernels/biot_savart.h"
#include "nbody/fmm.h"
#include "partix/memory.h"
#include "partix/timer.h"

/* Elements of px_real in a 32-byte vector (gcc and clang use 256-bit
 * vectors with -march=native on AVX-512 Xeons unless told otherwise). */
#define PX_FMM_VW ((int)(32 / sizeof(px_real)))
/* Columns of one M2L batch: four vectors (16 double, 32 float). */
#define PX_FMM_MB (4 * PX_FMM_VW)
/* Particles per chunk of P2M / P2L (stack arrays). */
#define PX_FMM_CHUNK 64
/* Interaction kinds in the per-cell list. */
#define PX_FMM_M2L 0u
#define PX_FMM_P2L 1u
#define PX_FMM_M2P 2u
#define PX_FMM_P2P 3u

/* Everything the passes read, for one evaluation. */
struct px_fmm_run {
  struct px_fmm *fmm;
  const struct px_fmm_tree *S, *T;
  int p, p4;        /* order; p rounded up to a multiple of 4 */
  size_t stride;    /* px_real per cell of an expansion: re at [0, half), im at [half, 2 half) */
  size_t half;
  double theta, eps_mac;
  double cost_m2l, cost_exp;
  px_real eps2;
  const px_real *sx, *sy, *sg; /* sorted sources */
  const px_real *tx, *ty;      /* sorted targets */
  px_real *U, *V;              /* 2π u, 2π v of the sorted targets */
  px_real *mp, *lc;            /* multipoles of source cells, locals of target cells */
  const px_real *Tm;           /* M2L matrix C(k + l, k), p4 rows of p */
  const px_real *B;            /* binomials C(k, m), p × p */
};

static void PX_SFX(px_fmm_keys)(int threads, size_t n, const px_real *x, const px_real *y,
                               uint64_t *keys) {
  double xmin = HUGE_VAL, xmax = -HUGE_VAL, ymin = HUGE_VAL, ymax = -HUGE_VAL;
  double side, scale;
#pragma omp parallel for num_threads(threads) reduction(min : xmin, ymin) \
    reduction(max : xmax, ymax) if (n > 16384)
  for (size_t i = 0; i < n; ++i) {
    const double xi = (double)x[i], yi = (double)y[i];
    if (isfinite(xi) && isfinite(yi)) {
      xmin = xi < xmin ? xi : xmin;
      xmax = xi > xmax ? xi : xmax;
      ymin = yi < ymin ? yi : ymin;
      ymax = yi > ymax ? yi : ymax;
    }
  }
  if (!(xmin <= xmax)) xmin = xmax = ymin = ymax = 0.0; /* no finite point */
  side = xmax - xmin > ymax - ymin ? xmax - xmin : ymax - ymin;
  if (!(side > 0.0) || !isfinite(side)) side = 1.0;
  scale = 2147483648.0 / side * (1.0 - 1e-12);
#pragma omp parallel for num_threads(threads) if (n > 16384)
  for (size_t i = 0; i < n; ++i) {
    /* NaN fails s >= 0 and lands in cell 0; infinities clamp to an edge */
    const double sx = ((double)x[i] - xmin) * scale, sy = ((double)y[i] - ymin) * scale;
    const uint32_t qx = sx >= 0.0 ? (sx < 2147483647.0 ? (uint32_t)sx : 2147483647u) : 0u;
    const uint32_t qy = sy >= 0.0 ? (sy < 2147483647.0 ? (uint32_t)sy : 2147483647u) : 0u;
    keys[i] = px_fmm_morton(qx, qy);
  }
}

/* ------------------------------ geometry ------------------------------- */

/* geo of a leaf from its points [b, e); see struct px_fmm_tree. */
static void PX_SFX(px_fmm_geo_leaf)(const px_real *x, const px_real *y, size_t b, size_t e,
                                   double rmin, double *geo) {
  double xmin = HUGE_VAL, xmax = -HUGE_VAL, ymin = HUGE_VAL, ymax = -HUGE_VAL, cx, cy;
  double r2 = 0.0, R;
  size_t j;
  for (j = b; j < e; ++j) {
    const double xj = (double)x[j], yj = (double)y[j];
    xmin = xj < xmin ? xj : xmin;
    xmax = xj > xmax ? xj : xmax;
    ymin = yj < ymin ? yj : ymin;
    ymax = yj > ymax ? yj : ymax;
  }
  if (!(xmin <= xmax) || !(ymin <= ymax)) xmin = xmax = ymin = ymax = 0.0;
  cx = (double)(px_real)(0.5 * xmin + 0.5 * xmax);
  cy = (double)(px_real)(0.5 * ymin + 0.5 * ymax);
  for (j = b; j < e; ++j) {
    const double dx = (double)x[j] - cx, dy = (double)y[j] - cy, d2 = dx * dx + dy * dy;
    r2 = d2 > r2 ? d2 : r2; /* NaN coordinates leave r2 alone; see below */
  }
  R = sqrt(r2) * (1.0 + 1e-12);
  geo[0] = cx;
  geo[1] = cy;
  geo[2] = R;
  geo[3] = R > rmin ? R : rmin;
  geo[4] = xmin;
  geo[5] = xmax;
  geo[6] = ymin;
  geo[7] = ymax;
  /* A non-finite coordinate makes the radius infinite: such a cell is never
   * accepted, so its pairs are summed directly (and give NaN there, like
   * the direct sum does). */
  for (j = b; j < e; ++j)
    if (!isfinite((double)x[j]) || !isfinite((double)y[j])) geo[2] = geo[3] = HUGE_VAL;
}

static void PX_SFX(px_fmm_geo_parent)(const struct px_fmm_tree *t, size_t c, double rmin) {
  double *geo = t->geo + 8 * c;
  const size_t c0 = t->child[c], c1 = c0 + t->nchild[c];
  double xmin = HUGE_VAL, xmax = -HUGE_VAL, ymin = HUGE_VAL, ymax = -HUGE_VAL, cx, cy;
  double ax, ay, R, Rc = 0.0;
  size_t k;
  for (k = c0; k < c1; ++k) {
    const double *g = t->geo + 8 * k;
    xmin = g[4] < xmin ? g[4] : xmin;
    xmax = g[5] > xmax ? g[5] : xmax;
    ymin = g[6] < ymin ? g[6] : ymin;
    ymax = g[7] > ymax ? g[7] : ymax;
  }
  cx = (double)(px_real)(0.5 * xmin + 0.5 * xmax);
  cy = (double)(px_real)(0.5 * ymin + 0.5 * ymax);
  /* two upper bounds of the distance of a point from the centre: the far
   * corner of the bounding box, and the children's circles */
  ax = fabs(xmin - cx) > fabs(xmax - cx) ? fabs(xmin - cx) : fabs(xmax - cx);
  ay = fabs(ymin - cy) > fabs(ymax - cy) ? fabs(ymin - cy) : fabs(ymax - cy);
  R = sqrt(ax * ax + ay * ay);
  for (k = c0; k < c1; ++k) {
    const double *g = t->geo + 8 * k;
    const double dx = g[0] - cx, dy = g[1] - cy, b = sqrt(dx * dx + dy * dy) + g[2];
    Rc = b > Rc ? b : Rc;
  }
  R = (Rc < R ? Rc : R) * (1.0 + 1e-12);
  geo[0] = cx;
  geo[1] = cy;
  geo[2] = R;
  geo[3] = R > rmin ? R : rmin;
  geo[4] = xmin;
  geo[5] = xmax;
  geo[6] = ymin;
  geo[7] = ymax;
  for (k = c0; k < c1; ++k)
    if (!(t->geo[8 * k + 2] < HUGE_VAL)) geo[2] = geo[3] = HUGE_VAL;
}

/* ------------------------------ expansions ----------------------------- */

/* P2M: multipole of the sources [b, e) about the cell (geo). */
static void PX_SFX(px_fmm_p2m)(const struct px_fmm_run *R, size_t b, size_t e, const double *geo,
                              px_real *mre, px_real *mim) {
  const int p = R->p;
  const px_real cx = (px_real)geo[0], cy = (px_real)geo[1], ir = (px_real)(1.0 / geo[3]);
  px_real wr[PX_FMM_CHUNK], wi[PX_FMM_CHUNK], pr[PX_FMM_CHUNK], pi[PX_FMM_CHUNK];
  size_t j0;
  int k;
  for (k = 0; k < p; ++k) mre[k] = mim[k] = PX_R(0.0);
  for (j0 = b; j0 < e; j0 += PX_FMM_CHUNK) {
    const size_t m = e - j0 < PX_FMM_CHUNK ? e - j0 : PX_FMM_CHUNK;
    size_t j;
    for (j = 0; j < m; ++j) {
      wr[j] = (R->sx[j0 + j] - cx) * ir;
      wi[j] = (R->sy[j0 + j] - cy) * ir;
      pr[j] = R->sg[j0 + j];
      pi[j] = PX_R(0.0);
    }
    for (k = 0; k < p; ++k) {
      px_real sr = PX_R(0.0), si = PX_R(0.0);
#pragma omp simd reduction(+ : sr, si)
      for (j = 0; j < m; ++j) {
        const px_real t = pr[j] * wr[j] - pi[j] * wi[j];
        sr += pr[j];
        si += pi[j];
        pi[j] = pr[j] * wi[j] + pi[j] * wr[j];
        pr[j] = t;
      }
      mre[k] += sr;
      mim[k] += si;
    }
  }
}

/* Powers z^0 .. z^(p-1) of a complex number. */
static void PX_SFX(px_fmm_powers)(px_real zr, px_real zi, int p, px_real *re, px_real *im) {
  int k;
  re[0] = PX_R(1.0);
  im[0] = PX_R(0.0);
  for (k = 1; k < p; ++k) {
    re[k] = re[k - 1] * zr - im[k - 1] * zi;
    im[k] = re[k - 1] * zi + im[k - 1] * zr;
  }
}

/* M2M: add the multipole of child geometry gc to the parent's (gp). */
static void PX_SFX(px_fmm_m2m)(const struct px_fmm_run *R, const double *gp, const double *gc,
                              const px_real *cre, const px_real *cim, px_real *pre,
                              px_real *pim) {
  const int p = R->p;
  px_real ur[PX_FMM_MAX_ORDER], ui[PX_FMM_MAX_ORDER], br[PX_FMM_MAX_ORDER],
      bi[PX_FMM_MAX_ORDER], sr[PX_FMM_MAX_ORDER], si[PX_FMM_MAX_ORDER];
  int k, m;
  PX_SFX(px_fmm_powers)((px_real)((gc[0] - gp[0]) / gp[3]), (px_real)((gc[1] - gp[1]) / gp[3]),
                        p, ur, ui);
  PX_SFX(px_fmm_powers)((px_real)(gc[3] / gp[3]), PX_R(0.0), p, sr, si);
  for (m = 0; m < p; ++m) {
    br[m] = sr[m] * cre[m];
    bi[m] = sr[m] * cim[m];
  }
  for (k = 0; k < p; ++k) {
    const px_real *Bk = R->B + (size_t)k * (size_t)p;
    px_real ar = PX_R(0.0), ai = PX_R(0.0);
    for (m = 0; m <= k; ++m) {
      const px_real wr = Bk[m] * ur[k - m], wi = Bk[m] * ui[k - m];
      ar += wr * br[m] - wi * bi[m];
      ai += wr * bi[m] + wi * br[m];
    }
    pre[k] += ar;
    pim[k] += ai;
  }
}

/* L2L: the child's local expansion (gc) from its parent's (gp). */
static void PX_SFX(px_fmm_l2l)(const struct px_fmm_run *R, const double *gp, const double *gc,
                              const px_real *pre, const px_real *pim, px_real *cre,
                              px_real *cim) {
  const int p = R->p;
  px_real ur[PX_FMM_MAX_ORDER], ui[PX_FMM_MAX_ORDER], sr[PX_FMM_MAX_ORDER],
      si[PX_FMM_MAX_ORDER];
  int l, m;
  PX_SFX(px_fmm_powers)((px_real)((gc[0] - gp[0]) / gp[3]), (px_real)((gc[1] - gp[1]) / gp[3]),
                        p, ur, ui);
  PX_SFX(px_fmm_powers)((px_real)(gc[3] / gp[3]), PX_R(0.0), p, sr, si);
  for (m = 0; m < p; ++m) {
    px_real ar = PX_R(0.0), ai = PX_R(0.0);
    for (l = m; l < p; ++l) {
      const px_real c = R->B[(size_t)l * (size_t)p + (size_t)m];
      const px_real wr = c * ur[l - m], wi = c * ui[l - m];
      ar += wr * pre[l] - wi * pim[l];
      ai += wr * pim[l] + wi * pre[l];
    }
    cre[m] = sr[m] * ar;
    cim[m] = sr[m] * ai;
  }
}

/* P2L: add the sources [b, e) to the local expansion of target cell gt. */
static void PX_SFX(px_fmm_p2l)(const struct px_fmm_run *R, size_t b, size_t e, const double *gt,
                              px_real *lre, px_real *lim) {
  const int p = R->p;
  const px_real cx = (px_real)gt[0], cy = (px_real)gt[1], r = (px_real)gt[3];
  px_real qr[PX_FMM_CHUNK], qi[PX_FMM_CHUNK], wr[PX_FMM_CHUNK], wi[PX_FMM_CHUNK];
  size_t j0;
  int l;
  for (j0 = b; j0 < e; j0 += PX_FMM_CHUNK) {
    const size_t m = e - j0 < PX_FMM_CHUNK ? e - j0 : PX_FMM_CHUNK;
    size_t j;
    for (j = 0; j < m; ++j) {
      /* q = r / s, w = Γ / s = Γ q / r, s = z_j − c */
      const px_real sxr = R->sx[j0 + j] - cx, sxi = R->sy[j0 + j] - cy;
      const px_real inv = PX_R(1.0) / (sxr * sxr + sxi * sxi);
      const px_real g = R->sg[j0 + j];
      qr[j] = r * sxr * inv;
      qi[j] = -r * sxi * inv;
      wr[j] = g * sxr * inv;
      wi[j] = -g * sxi * inv;
    }
    for (l = 0; l < p; ++l) {
      px_real sr = PX_R(0.0), si = PX_R(0.0);
#pragma omp simd reduction(+ : sr, si)
      for (j = 0; j < m; ++j) {
        const px_real t = wr[j] * qr[j] - wi[j] * qi[j];
        sr += wr[j];
        si += wi[j];
        wi[j] = wr[j] * qi[j] + wi[j] * qr[j];
        wr[j] = t;
      }
      lre[l] -= sr;
      lim[l] -= si;
    }
  }
}

/* L2P: set (U, V) of the targets [b, e) from the local expansion gt.
 * Horner in w = (z − c)/r, vectorised over a chunk of targets. */
static void PX_SFX(px_fmm_l2p)(const struct px_fmm_run *R, size_t b, size_t e, const double *gt,
                              const px_real *lre, const px_real *lim) {
  const int p = R->p;
  const px_real cx = (px_real)gt[0], cy = (px_real)gt[1], ir = (px_real)(1.0 / gt[3]);
  px_real wr[PX_FMM_CHUNK], wi[PX_FMM_CHUNK], ar[PX_FMM_CHUNK], ai[PX_FMM_CHUNK];
  size_t i0;
  for (i0 = b; i0 < e; i0 += PX_FMM_CHUNK) {
    const size_t m = e - i0 < PX_FMM_CHUNK ? e - i0 : PX_FMM_CHUNK;
    const px_real *tx = R->tx + i0, *ty = R->ty + i0;
    px_real *U = R->U + i0, *V = R->V + i0;
    size_t i;
    int l;
    for (i = 0; i < m; ++i) {
      wr[i] = (tx[i] - cx) * ir;
      wi[i] = (ty[i] - cy) * ir;
      ar[i] = lre[p - 1];
      ai[i] = lim[p - 1];
    }
    for (l = p - 2; l >= 0; --l) {
      const px_real br = lre[l], bi = lim[l];
#pragma omp simd
      for (i = 0; i < m; ++i) {
        const px_real t = ar[i] * wr[i] - ai[i] * wi[i] + br;
        ai[i] = ar[i] * wi[i] + ai[i] * wr[i] + bi;
        ar[i] = t;
      }
    }
    for (i = 0; i < m; ++i) {
      U[i] = ai[i];
      V[i] = ar[i];
    }
  }
}

/* M2P: add the multipole of source cell gs at the targets [b, e). */
static void PX_SFX(px_fmm_m2p)(const struct px_fmm_run *R, size_t b, size_t e, const double *gs,
                              const px_real *mre, const px_real *mim) {
  const int p = R->p;
  const px_real cx = (px_real)gs[0], cy = (px_real)gs[1], r = (px_real)gs[3];
  const px_real ir = (px_real)(1.0 / gs[3]);
  px_real qr[PX_FMM_CHUNK], qi[PX_FMM_CHUNK], ar[PX_FMM_CHUNK], ai[PX_FMM_CHUNK];
  size_t i0;
  for (i0 = b; i0 < e; i0 += PX_FMM_CHUNK) {
    const size_t m = e - i0 < PX_FMM_CHUNK ? e - i0 : PX_FMM_CHUNK;
    const px_real *tx = R->tx + i0, *ty = R->ty + i0;
    px_real *U = R->U + i0, *V = R->V + i0;
    size_t i;
    int k;
#pragma omp simd
    for (i = 0; i < m; ++i) {
      const px_real dx = tx[i] - cx, dy = ty[i] - cy, inv = r / (dx * dx + dy * dy);
      qr[i] = dx * inv;
      qi[i] = -dy * inv;
      ar[i] = mre[p - 1];
      ai[i] = mim[p - 1];
    }
    for (k = p - 2; k >= 0; --k) {
      const px_real br = mre[k], bi = mim[k];
#pragma omp simd
      for (i = 0; i < m; ++i) {
        const px_real t = ar[i] * qr[i] - ai[i] * qi[i] + br;
        ai[i] = ar[i] * qi[i] + ai[i] * qr[i] + bi;
        ar[i] = t;
      }
    }
#pragma omp simd
    for (i = 0; i < m; ++i) {
      U[i] += (ar[i] * qi[i] + ai[i] * qr[i]) * ir;
      V[i] += (ar[i] * qr[i] - ai[i] * qi[i]) * ir;
    }
  }
}

/* Y = T X for the M2L batch: T is p × p, X is p × ld and Y p × ld, ld a
 * multiple of 2 vectors. Register-blocked: 4 rows × 2 vectors of
 * accumulators (8 registers), then single remaining rows. fma() is an exact
 * fused operation, so the result does not depend on the compiler
 * (-ffp-contract=off holds everywhere else). */
static void PX_SFX(px_fmm_gemm)(int p, size_t ld, const px_real *T, const px_real *X,
                                px_real *Y) {
  enum { CB = 2 * PX_FMM_VW };
  int l0 = 0, k, c;
  size_t c0;
  for (; l0 + 4 <= p; l0 += 4) {
    const px_real *T0 = T + (size_t)l0 * (size_t)p, *T1 = T0 + p, *T2 = T1 + p, *T3 = T2 + p;
    for (c0 = 0; c0 < ld; c0 += CB) {
      px_real a0[CB], a1[CB], a2[CB], a3[CB];
      px_real *y = Y + (size_t)l0 * ld + c0;
      for (c = 0; c < CB; ++c) a0[c] = a1[c] = a2[c] = a3[c] = PX_R(0.0);
      for (k = 0; k < p; ++k) {
        const px_real *xk = X + (size_t)k * ld + c0;
        const px_real t0 = T0[k], t1 = T1[k], t2 = T2[k], t3 = T3[k];
#pragma omp simd
        for (c = 0; c < CB; ++c) {
          a0[c] = fma(t0, xk[c], a0[c]);
          a1[c] = fma(t1, xk[c], a1[c]);
          a2[c] = fma(t2, xk[c], a2[c]);
          a3[c] = fma(t3, xk[c], a3[c]);
        }
      }
      for (c = 0; c < CB; ++c) {
        y[c] = a0[c];
        y[ld + (size_t)c] = a1[c];
        y[2 * ld + (size_t)c] = a2[c];
        y[3 * ld + (size_t)c] = a3[c];
      }
    }
  }
  for (; l0 < p; ++l0) {
    const px_real *T0 = T + (size_t)l0 * (size_t)p;
    for (c0 = 0; c0 < ld; c0 += CB) {
      px_real a0[CB], a1[CB];
      px_real *y = Y + (size_t)l0 * ld + c0;
      for (c = 0; c < CB; ++c) a0[c] = a1[c] = PX_R(0.0);
      /* two partial sums (even / odd k) for latency; fixed order */
      for (k = 0; k + 1 < p; k += 2) {
        const px_real *xk = X + (size_t)k * ld + c0;
        const px_real t0 = T0[k], t1 = T0[k + 1];
#pragma omp simd
        for (c = 0; c < CB; ++c) {
          a0[c] = fma(t0, xk[c], a0[c]);
          a1[c] = fma(t1, xk[ld + (size_t)c], a1[c]);
        }
      }
      if (k < p) {
        const px_real *xk = X + (size_t)k * ld + c0;
        const px_real t0 = T0[k];
#pragma omp simd
        for (c = 0; c < CB; ++c) a0[c] = fma(t0, xk[c], a0[c]);
      }
      for (c = 0; c < CB; ++c) y[c] = a0[c] + a1[c];
    }
  }
}

/* Scratch (px_real elements) of one M2L batch. */
static size_t PX_SFX(px_fmm_m2l_scratch)(int p4) {
  return (size_t)(2 * p4 * 2 * PX_FMM_MB + 8 * PX_FMM_MB);
}

/* M2L of m <= PX_FMM_MB source cells src[] into the local of target gt. */
static void PX_SFX(px_fmm_m2l_batch)(const struct px_fmm_run *R, const double *gt,
                                    const uint32_t *src, int m, px_real *lre, px_real *lim,
                                    px_real *work) {
  const int p = R->p, W = (m + PX_FMM_VW - 1) / PX_FMM_VW * PX_FMM_VW;
  const size_t ld = 2 * (size_t)W;
  px_real *X = work, *Y = X + (size_t)R->p4 * ld;
  px_real *sr = Y + (size_t)R->p4 * ld, *si = sr + PX_FMM_MB, *tr = si + PX_FMM_MB,
          *ti = tr + PX_FMM_MB, *vr = ti + PX_FMM_MB, *vi = vr + PX_FMM_MB, *Pr = vi + PX_FMM_MB,
          *Pi = Pr + PX_FMM_MB;
  int j, k, l;
  for (j = 0; j < W; ++j) {
    if (j < m) {
      const double *gs = R->S->geo + 8 * (size_t)src[j];
      const px_real *a = R->mp + (size_t)src[j] * R->stride;
      const double zr = gt[0] - gs[0], zi = gt[1] - gs[1], iz = 1.0 / (zr * zr + zi * zi);
      const double ivr = zr * iz, ivi = -zi * iz; /* 1 / z0 */
      sr[j] = (px_real)(gs[3] * ivr);
      si[j] = (px_real)(gs[3] * ivi);
      tr[j] = (px_real)(gt[3] * ivr);
      ti[j] = (px_real)(gt[3] * ivi);
      vr[j] = (px_real)ivr;
      vi[j] = (px_real)ivi;
      for (k = 0; k < p; ++k) {
        X[(size_t)k * ld + (size_t)j] = a[k];
        X[(size_t)k * ld + (size_t)(W + j)] = a[R->half + (size_t)k];
      }
    } else {
      sr[j] = si[j] = tr[j] = ti[j] = vr[j] = vi[j] = PX_R(0.0);
      for (k = 0; k < p; ++k)
        X[(size_t)k * ld + (size_t)j] = X[(size_t)k * ld + (size_t)(W + j)] = PX_R(0.0);
    }
    Pr[j] = PX_R(1.0);
    Pi[j] = PX_R(0.0);
  }
  /* X_k ← ã_k ρ_s^k */
  for (k = 0; k < p; ++k) {
    px_real *xr = X + (size_t)k * ld, *xi = xr + W;
#pragma omp simd
    for (j = 0; j < W; ++j) {
      const px_real ar = xr[j], ai = xi[j], qr = Pr[j], qi = Pi[j];
      xr[j] = ar * qr - ai * qi;
      xi[j] = ar * qi + ai * qr;
      Pr[j] = qr * sr[j] - qi * si[j];
      Pi[j] = qr * si[j] + qi * sr[j];
    }
  }
  PX_SFX(px_fmm_gemm)(p, ld, R->Tm, X, Y);
  /* b̃_l += (−1)^l Σ_j ρ_t^l / z0 · Y_l */
  for (l = 0; l < p; ++l) {
    const px_real *yr = Y + (size_t)l * ld, *yi = yr + W;
    px_real ar = PX_R(0.0), ai = PX_R(0.0);
#pragma omp simd reduction(+ : ar, ai)
    for (j = 0; j < W; ++j) {
      const px_real qr = vr[j], qi = vi[j];
      ar += qr * yr[j] - qi * yi[j];
      ai += qr * yi[j] + qi * yr[j];
      vr[j] = qr * tr[j] - qi * ti[j];
      vi[j] = qr * ti[j] + qi * tr[j];
    }
    if (l & 1) {
      lre[l] -= ar;
      lim[l] -= ai;
    } else {
      lre[l] += ar;
      lim[l] += ai;
    }
  }
}

/* P2P: add the sources g{x,y,g}[0, n) to the targets [b, e) (smoothed kernel). */
static void PX_SFX(px_fmm_p2p)(const struct px_fmm_run *R, size_t b, size_t e,
                              const px_real *gx, const px_real *gy, const px_real *gg,
                              size_t n) {
  const px_real eps2 = R->eps2;
  size_t i;
  for (i = b; i < e; ++i) {
    const px_real xi = R->tx[i], yi = R->ty[i];
    px_real au = PX_R(0.0), av = PX_R(0.0);
    size_t j;
#pragma omp simd reduction(+ : au, av)
    for (j = 0; j < n; ++j) {
      const px_real2 t = px_biot_savart_term(xi - gx[j], yi - gy[j], gg[j], eps2);
      au += t.x;
      av += t.y;
    }
    R->U[i] += au;
    R->V[i] += av;
  }
}

/* ------------------------------- passes -------------------------------- */

static int PX_SFX(px_fmm_push)(struct px_fmm *fmm, struct px_fmm_thread *th, size_t *len,
                              uint32_t c) {
  if (*len >= th->stack_cap / sizeof(uint32_t) &&
      px_fmm_reserve(fmm->ctx, "fmm traversal stack", (void **)&th->stack, &th->stack_cap,
                     (*len + 1) * sizeof(uint32_t)))
    return -1;
  th->stack[(*len)++] = c;
  return 0;
}

static int PX_SFX(px_fmm_list_add)(struct px_fmm *fmm, struct px_fmm_thread *th, size_t *len,
                                  uint32_t kind, uint32_t c) {
  if (2 * (*len + 1) > th->list_cap / sizeof(uint32_t) &&
      px_fmm_reserve(fmm->ctx, "fmm interaction lists", (void **)&th->list, &th->list_cap,
                     2 * (*len + 1) * sizeof(uint32_t)))
    return -1;
  th->list[2 * *len] = kind;
  th->list[2 * *len + 1] = c;
  ++*len;
  return 0;
}

static int PX_SFX(px_fmm_pass_add)(struct px_fmm *fmm, struct px_fmm_thread *th, int parity,
                                  uint32_t c) {
  if (th->pass_len[parity] >= th->pass_cap[parity] / sizeof(uint32_t) &&
      px_fmm_reserve(fmm->ctx, "fmm hand-down lists", (void **)&th->pass[parity],
                     &th->pass_cap[parity], (th->pass_len[parity] + 1) * sizeof(uint32_t)))
    return -1;
  th->pass[parity][th->pass_len[parity]++] = c;
  return 0;
}

/* One target cell t of generation parity `parity`: its local expansion
 * (L2L + the accepted far field), its hand-down list, and for a leaf the
 * velocities of its targets. */
static void PX_SFX(px_fmm_target)(const struct px_fmm_run *R, struct px_fmm_thread *th,
                                 int tid, size_t t, int parity) {
  struct px_fmm *fmm = R->fmm;
  const struct px_fmm_tree *S = R->S, *T = R->T;
  const double *gt = T->geo + 8 * t;
  const int tleaf = T->nchild[t] == 0;
  const size_t nt = T->end[t] - T->begin[t];
  const double p2 = (double)R->p * (double)R->p, ctgt = R->cost_exp * (double)R->p;
  px_real *lre = R->lc + t * R->stride, *lim = lre + R->half;
  size_t sp = 0, nl = 0, k, pass0 = th->pass_len[parity];
  int has = 0, q;
  /* the source cells to examine */
  if (t == 0) {
    if (PX_SFX(px_fmm_push)(fmm, th, &sp, 0)) goto oom;
  } else {
    const size_t par = T->parent[t];
    const uint32_t *info = fmm->pass_info + 3 * par;
    const uint32_t *in = fmm->thr[info[0]].pass[parity ^ 1] + info[1];
    for (k = info[2]; k-- > 0;)
      if (PX_SFX(px_fmm_push)(fmm, th, &sp, in[k])) goto oom;
    if (fmm->has_local[par]) {
      const px_real *pl = R->lc + par * R->stride;
      PX_SFX(px_fmm_l2l)(R, T->geo + 8 * par, gt, pl, pl + R->half, lre, lim);
      has = 1;
    }
  }
  if (!has)
    for (q = 0; q < R->p; ++q) lre[q] = lim[q] = PX_R(0.0);
  while (sp > 0) {
    const uint32_t s = th->stack[--sp];
    const double *gs = S->geo + 8 * (size_t)s;
    const double dx = gt[0] - gs[0], dy = gt[1] - gs[1], d = sqrt(dx * dx + dy * dy);
    const double rsum = gt[2] + gs[2];
    const double slack =
        4.0 * DBL_EPSILON * (fabs(gt[0]) + fabs(gt[1]) + fabs(gs[0]) + fabs(gs[1]));
    const int sleaf = S->nchild[s] == 0;
    if (rsum <= R->theta * d && d - rsum >= R->eps_mac + slack) {
      const double ns = (double)(S->end[s] - S->begin[s]);
      double best = R->cost_m2l * p2, c;
      uint32_t kind = PX_FMM_M2L;
      c = ctgt * ns;
      if (c < best) best = c, kind = PX_FMM_P2L;
      if (tleaf) {
        c = ctgt * (double)nt;
        if (c < best) best = c, kind = PX_FMM_M2P;
        c = (double)nt * ns;
        if (c < best) best = c, kind = PX_FMM_P2P;
      }
      if (PX_SFX(px_fmm_list_add)(fmm, th, &nl, kind, s)) goto oom;
    } else if (tleaf) {
      if (sleaf) {
        if (PX_SFX(px_fmm_list_add)(fmm, th, &nl, PX_FMM_P2P, s)) goto oom;
      } else {
        for (k = S->nchild[s]; k-- > 0;)
          if (PX_SFX(px_fmm_push)(fmm, th, &sp, (uint32_t)(S->child[s] + k))) goto oom;
      }
    } else if (sleaf || gs[2] <= gt[2]) {
      if (PX_SFX(px_fmm_pass_add)(fmm, th, parity, s)) goto oom;
    } else {
      for (k = S->nchild[s]; k-- > 0;)
        if (PX_SFX(px_fmm_push)(fmm, th, &sp, (uint32_t)(S->child[s] + k))) goto oom;
    }
  }
  fmm->pass_info[3 * t] = (uint32_t)tid;
  fmm->pass_info[3 * t + 1] = (uint32_t)pass0;
  fmm->pass_info[3 * t + 2] = (uint32_t)(th->pass_len[parity] - pass0);
  /* far field into the local expansion: P2L, then M2L in batches */
  {
    const size_t need = PX_SFX(px_fmm_m2l_scratch)(R->p4) * sizeof(px_real);
    uint32_t batch[PX_FMM_MB];
    int m = 0;
    if (px_fmm_reserve(fmm->ctx, "fmm scratch", &th->buf, &th->buf_cap, need)) goto oom;
    for (k = 0; k < nl; ++k) {
      const uint32_t kind = th->list[2 * k], s = th->list[2 * k + 1];
      if (kind == PX_FMM_P2L) {
        PX_SFX(px_fmm_p2l)(R, S->begin[s], S->end[s], gt, lre, lim);
        has = 1;
        ++th->p2l;
        th->p2l_sources += (double)(S->end[s] - S->begin[s]);
      } else if (kind == PX_FMM_M2L) {
        batch[m++] = s;
        if (m == PX_FMM_MB) {
          PX_SFX(px_fmm_m2l_batch)(R, gt, batch, m, lre, lim, th->buf);
          m = 0;
        }
        has = 1;
        ++th->m2l;
      }
    }
    if (m > 0) PX_SFX(px_fmm_m2l_batch)(R, gt, batch, m, lre, lim, th->buf);
  }
  fmm->has_local[t] = (uint8_t)has;
  if (tleaf) {
    const size_t b = T->begin[t], e = T->end[t];
    size_t nn = 0, need = 0;
    px_real *gx, *gy, *gg;
    if (has) {
      PX_SFX(px_fmm_l2p)(R, b, e, gt, lre, lim);
    } else {
      for (k = b; k < e; ++k) R->U[k] = R->V[k] = PX_R(0.0);
    }
    for (k = 0; k < nl; ++k) {
      const uint32_t kind = th->list[2 * k], s = th->list[2 * k + 1];
      if (kind == PX_FMM_M2P) {
        const px_real *a = R->mp + (size_t)s * R->stride;
        PX_SFX(px_fmm_m2p)(R, b, e, S->geo + 8 * (size_t)s, a, a + R->half);
        ++th->m2p;
        th->m2p_targets += (double)nt;
      } else if (kind == PX_FMM_P2P) {
        need += S->end[s] - S->begin[s];
      }
    }
    if (need > 0) {
      if (px_fmm_reserve(fmm->ctx, "fmm scratch", &th->buf, &th->buf_cap,
                         3 * need * sizeof(px_real) + 192))
        goto oom;
      gx = th->buf;
      gy = gx + need;
      gg = gy + need;
      for (k = 0; k < nl; ++k) {
        const uint32_t kind = th->list[2 * k], s = th->list[2 * k + 1];
        if (kind == PX_FMM_P2P) {
          const size_t sb = S->begin[s], c = S->end[s] - sb;
          memcpy(gx + nn, R->sx + sb, c * sizeof(px_real));
          memcpy(gy + nn, R->sy + sb, c * sizeof(px_real));
          memcpy(gg + nn, R->sg + sb, c * sizeof(px_real));
          nn += c;
          ++th->p2p_cells;
        }
      }
      PX_SFX(px_fmm_p2p)(R, b, e, gx, gy, gg, nn);
      th->p2p_pairs += (double)nn * (double)nt;
    }
  }
  return;
oom:
  th->failed = 1;
}

/* Bottom-up pass over a tree: geometry, and for the source tree the
 * multipoles (P2M at leaves, M2M from the children). */
static void PX_SFX(px_fmm_upward)(const struct px_fmm_run *R, const struct px_fmm_tree *t,
                                 const px_real *x, const px_real *y, int multipoles,
                                 int threads, double rmin) {
#pragma omp parallel num_threads(threads) if (t->ncells > 64)
  {
    int g;
    for (g = t->ngen - 1; g >= 0; --g) {
#pragma omp for schedule(dynamic, 8)
      for (size_t c = t->gen[g]; c < t->gen[g + 1]; ++c) {
        double *geo = t->geo + 8 * c;
        if (t->nchild[c] == 0) {
          PX_SFX(px_fmm_geo_leaf)(x, y, t->begin[c], t->end[c], rmin, geo);
          if (multipoles) {
            px_real *a = R->mp + c * R->stride;
            PX_SFX(px_fmm_p2m)(R, t->begin[c], t->end[c], geo, a, a + R->half);
          }
        } else {
          PX_SFX(px_fmm_geo_parent)(t, c, rmin);
          if (multipoles) {
            px_real *a = R->mp + c * R->stride;
            const size_t c0 = t->child[c], c1 = c0 + t->nchild[c];
            size_t k;
            int q;
            for (q = 0; q < R->p; ++q) a[q] = a[R->half + (size_t)q] = PX_R(0.0);
            for (k = c0; k < c1; ++k) {
              const px_real *ac = R->mp + k * R->stride;
              PX_SFX(px_fmm_m2m)(R, geo, t->geo + 8 * k, ac, ac + R->half, a, a + R->half);
            }
          }
        }
      }
    }
  }
}

enum px_status PX_SFX(px_fmm_cpu)(struct px_fmm *fmm, const struct px_fmm_params *prm,
                                  const struct px_fmm_args *a) {
  struct px_context *ctx = fmm->ctx;
  struct px_fmm_run R;
  const int threads = a->threads;
  const size_t ns = a->n_src, nt = a->n_tgt;
  const size_t pad = 64 / sizeof(px_real);
  const size_t nsp = (ns + pad - 1) / pad * pad, ntp = (nt + pad - 1) / pad * pad;
  const double t0 = px_time_now();
  double t1, t2;
  struct px_fmm_tree *S = &fmm->src, *T = a->self ? &fmm->src : &fmm->tgt;
  px_real *pts;
  size_t i, need, ncell;
  int k, l, failed = 0;
  memset(&fmm->stats, 0, sizeof fmm->stats);
  memset(&R, 0, sizeof R);
  R.fmm = fmm;
  R.S = S;
  R.T = T;
  R.p = prm->order;
  R.p4 = (R.p + 3) / 4 * 4;
  R.half = (size_t)(R.p + PX_FMM_VW - 1) / (size_t)PX_FMM_VW * (size_t)PX_FMM_VW;
  R.stride = 2 * R.half;
  R.theta = prm->theta;
  R.eps_mac = a->eps * (1.0 + 1e-6);
  R.eps2 = (px_real)(a->eps * a->eps);
  R.cost_m2l = prm->cost_m2l;
  R.cost_exp = prm->cost_exp;
  PX_TRY(px_fmm_threads(fmm, threads));

  /* trees */
  PX_TRY(px_fmm_tree_reserve(ctx, S, ns));
  PX_SFX(px_fmm_keys)(threads, ns, a->sx, a->sy, S->keys);
  PX_TRY(px_fmm_tree_build(ctx, S, threads, ns, prm->leaf));
  if (!a->self) {
    PX_TRY(px_fmm_tree_reserve(ctx, T, nt));
    PX_SFX(px_fmm_keys)(threads, nt, a->tx, a->ty, T->keys);
    PX_TRY(px_fmm_tree_build(ctx, T, threads, nt, prm->leaf));
  }

  /* sorted points and velocities */
  need = (3 * nsp + (a->self ? 0 : 2 * ntp) + 2 * ntp) * sizeof(px_real);
  if (px_fmm_reserve(ctx, "fmm points", &fmm->points, &fmm->points_cap, need))
    return PX_STATUS_NOMEM;
  pts = fmm->points;
  R.sx = pts;
  R.sy = pts + nsp;
  R.sg = pts + 2 * nsp;
  R.tx = a->self ? R.sx : pts + 3 * nsp;
  R.ty = a->self ? R.sy : pts + 3 * nsp + ntp;
  R.U = pts + 3 * nsp + (a->self ? 0 : 2 * ntp);
  R.V = R.U + ntp;
  {
    const px_real *sx = a->sx, *sy = a->sy, *sg = a->sg, *tx = a->tx, *ty = a->ty;
    px_real *ox = pts, *oy = pts + nsp, *og = pts + 2 * nsp;
    px_real *otx = (px_real *)(uintptr_t)R.tx, *oty = (px_real *)(uintptr_t)R.ty;
    const uint32_t *sp = S->perm, *tp = T->perm;
    const int self = a->self;
#pragma omp parallel num_threads(threads) if (ns + nt > 16384)
    {
#pragma omp for schedule(static)
      for (size_t j = 0; j < ns; ++j) {
        ox[j] = sx[sp[j]];
        oy[j] = sy[sp[j]];
        og[j] = sg[sp[j]];
      }
      if (!self) {
#pragma omp for schedule(static)
        for (size_t j = 0; j < nt; ++j) {
          otx[j] = tx[tp[j]];
          oty[j] = ty[tp[j]];
        }
      }
    }
  }

  /* expansions and tables */
  if (px_fmm_reserve(ctx, "fmm multipoles", &fmm->mpole, &fmm->mpole_cap,
                     S->ncells * R.stride * sizeof(px_real)) ||
      px_fmm_reserve(ctx, "fmm locals", &fmm->local, &fmm->local_cap,
                     T->ncells * R.stride * sizeof(px_real)) ||
      px_fmm_reserve(ctx, "fmm tables", &fmm->tables, &fmm->tables_cap,
                     (size_t)(R.p4 + R.p) * (size_t)R.p * sizeof(px_real)))
    return PX_STATUS_NOMEM;
  ncell = T->ncells;
  if (ncell > fmm->cell_cap) {
    size_t c1 = fmm->cell_cap, c2 = fmm->cell_cap * 3 * sizeof(uint32_t);
    if (px_fmm_reserve(ctx, "fmm cell flags", (void **)&fmm->has_local, &c1, ncell) ||
        px_fmm_reserve(ctx, "fmm cell lists", (void **)&fmm->pass_info, &c2,
                       3 * ncell * sizeof(uint32_t)))
      return PX_STATUS_NOMEM;
    fmm->cell_cap = c1 < c2 / (3 * sizeof(uint32_t)) ? c1 : c2 / (3 * sizeof(uint32_t));
  }
  R.mp = fmm->mpole;
  R.lc = fmm->local;
  {
    px_real *Tm = fmm->tables, *Bm = Tm + (size_t)R.p4 * (size_t)R.p;
    /* Pascal's triangle in double: exact while C(n, k) < 2^53 (n <= 56,
     * i.e. p <= 29), rounded to 1e-16 relative beyond; then cast */
    double row[2 * PX_FMM_MAX_ORDER + 1];
    int n;
    for (l = 0; l < R.p4; ++l)
      for (k = 0; k < R.p; ++k) Tm[(size_t)l * (size_t)R.p + (size_t)k] = PX_R(0.0);
    row[0] = 1.0;
    for (n = 0; n <= 2 * R.p - 2; ++n) {
      /* row n of Pascal's triangle: C(n, 0..n) */
      if (n > 0) {
        row[n] = 1.0;
        for (k = n - 1; k > 0; --k) row[k] += row[k - 1];
      }
      for (k = 0; k <= n; ++k) {
        l = n - k; /* C(k + l, k) with k + l = n */
        if (k < R.p && l < R.p) Tm[(size_t)l * (size_t)R.p + (size_t)k] = (px_real)row[k];
        if (n < R.p) Bm[(size_t)n * (size_t)R.p + (size_t)k] = (px_real)row[k];
      }
      if (n < R.p)
        for (k = n + 1; k < R.p; ++k) Bm[(size_t)n * (size_t)R.p + (size_t)k] = PX_R(0.0);
    }
    R.Tm = Tm;
    R.B = Bm;
  }
  t1 = px_time_now();

  PX_SFX(px_fmm_upward)(&R, S, R.sx, R.sy, 1, threads, 1e-3 * a->eps);
  if (!a->self) PX_SFX(px_fmm_upward)(&R, T, R.tx, R.ty, 0, threads, 1e-3 * a->eps);
  t2 = px_time_now();

  for (k = 0; k < fmm->nthreads; ++k) {
    struct px_fmm_thread *th = fmm->thr + k;
    th->failed = 0;
    th->m2l = th->p2l = th->m2p = th->p2p_cells = 0;
    th->p2p_pairs = th->m2p_targets = th->p2l_sources = 0.0;
    th->pass_len[0] = th->pass_len[1] = 0;
  }
#pragma omp parallel num_threads(threads) if (T->ncells > 1)
  {
    const int tid = omp_get_thread_num();
    struct px_fmm_thread *th = fmm->thr + tid;
    int g;
    for (g = 0; g < T->ngen; ++g) {
      th->pass_len[g & 1] = 0;
#pragma omp for schedule(dynamic, 2)
      for (size_t c = T->gen[g]; c < T->gen[g + 1]; ++c)
        if (!th->failed) PX_SFX(px_fmm_target)(&R, th, tid, c, g & 1);
    }
  }
  for (k = 0; k < fmm->nthreads; ++k) {
    const struct px_fmm_thread *th = fmm->thr + k;
    failed |= th->failed;
    fmm->stats.m2l += th->m2l;
    fmm->stats.p2l += th->p2l;
    fmm->stats.m2p += th->m2p;
    fmm->stats.p2p_cells += th->p2p_cells;
    fmm->stats.p2p_pairs += th->p2p_pairs;
    fmm->stats.m2p_targets += th->m2p_targets;
    fmm->stats.p2l_sources += th->p2l_sources;
  }
  if (failed) return px_context_status(ctx) != PX_STATUS_OK ? px_context_status(ctx)
                                                             : PX_STATUS_NOMEM;

  /* back to the input order, with the 1/(2π) */
  {
    const px_real *U = R.U, *V = R.V;
    px_real *u = a->u, *v = a->v;
    const uint32_t *tp = T->perm;
    const int acc = a->accumulate;
#pragma omp parallel for num_threads(threads) schedule(static) if (nt > 16384)
    for (size_t j = 0; j < nt; ++j) {
      const size_t o = tp[j];
      u[o] = (acc ? u[o] : PX_R(0.0)) + PX_BIOT_SAVART_SCALE * U[j];
      v[o] = (acc ? v[o] : PX_R(0.0)) + PX_BIOT_SAVART_SCALE * V[j];
    }
  }
  fmm->stats.src_cells = S->ncells;
  fmm->stats.tgt_cells = T->ncells;
  fmm->stats.src_generations = S->ngen;
  fmm->stats.tgt_generations = T->ngen;
  for (i = 0; i < S->ncells; ++i) fmm->stats.src_leaves += S->nchild[i] == 0;
  for (i = 0; i < T->ncells; ++i) fmm->stats.tgt_leaves += T->nchild[i] == 0;
  fmm->stats.t_tree = t1 - t0;
  fmm->stats.t_up = t2 - t1;
  fmm->stats.t_total = px_time_now() - t0;
  fmm->stats.t_down = fmm->stats.t_total - fmm->stats.t_up - fmm->stats.t_tree;
  return PX_STATUS_OK;
}
