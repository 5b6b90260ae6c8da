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
 * Expansions (Greengard & Rokhlin, J. Comput. Phys. 73 (1987) 315, sec. 2,
 * "GR87" below; the Cauchy-kernel form of fmm2d's cfmm2d), about a centre c
 * with a scale r > 0, coefficients stored scaled so that they are O(Σ|Γ|):
 *   multipole  f(z) = Σ_{k<p} ã_k r^k / (z − c)^{k+1},  ã_k = Σ_j Γ_j ((z_j − c)/r)^k   (P2M)
 *   local      f(z) = Σ_{l<p} b̃_l ((z − c)/r)^l                                     (L2P)
 * Translations (z0, δ complex; C(n, k) binomials):
 *   M2M  child (c, r_c) -> parent (c', r'), u = (c − c')/r', σ = r_c/r':
 *        ã'_k = Σ_{m<=k} C(k, m) u^{k−m} σ^m ã_m                 (exact: the moments)
 *   M2L  source (c_s, r_s) -> target (c_t, r_t), z0 = c_t − c_s,
 *        ρ_s = r_s/z0, ρ_t = r_t/z0:
 *        b̃_l += (−1)^l ρ_t^l / z0 · Σ_k C(k + l, k) ρ_s^k ã_k      (GR87, conversion
 *                                                                of a multipole into
 *                                                                a local expansion)
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
 * within R of c. For a target cell t and a source cell s at d = |c_t − c_s|
 * the multipole series of s converges at the points of t with ratio
 * a = R_s / (d − R_t) and the local series of t with b = R_t / (d − R_s)
 * (GR87 sec. 2: multipole expansion and its conversion into a local
 * expansion, with their error bounds: truncating both series at order q
 * leaves at most Σ|Γ_s| (a^q / ((1 − a)(d − R_t)) + b^q / ((1 − b)(d − R_s)))
 * of f, from the binomial double series of 1/(z − z_j)). The
 * pair is accepted (well separated) when
 *   (a)  max(a, b) <= ρ = E^(1/p)     (so that order q <= p reaches E)
 *   (b)  d − R_t − R_s >= ε (1 + 1e-6) + rounding slack,
 * and each accepted interaction uses its own order, the smallest q with
 * max(a, b)^q <= E (E: fmm.c, the requested tolerance). Compared with a
 * fixed opening angle (R_t + R_s <= θ d) this accepts pairs by their actual
 * convergence, so a small cell next to a large one is not under-resolved
 * and the expansions need no reserve for it (p = ln E / ln ρ, not ln E /
 * ln θ); measured 20-30% faster at equal error.
 * Dual-tree traversal with fixed ownership (Dehnen, J. Comput. Phys. 179
 * (2002) 27, sec. 3, "interaction phase", organised per target cell as in
 * the adaptive lists of Carrier, Greengard & Rokhlin, SIAM J. Sci. Stat.
 * Comput. 9 (1988) 669): a target cell takes the source cells its parent
 * handed down and tests each: accepted pairs become an M2L (V list), P2L
 * (X list), M2P (W list, leaves only) or P2P, whichever the cost model
 * says is cheapest; rejected pairs split the source cell if the target is
 * a leaf or the source is the larger, are summed pair by pair if both are
 * leaves, and are handed down to the target's children otherwise.
 *
 * Why no pair closer than ε reaches the far field: for a point a of t and
 * b of s, |a − b| >= |c_t − c_s| − |a − c_t| − |b − c_s| >= d − R_t − R_s
 * (triangle inequality), and (b) makes that >= ε. R is an upper bound by
 * construction (rounded up by 1e-12 relative, far above the rounding of its
 * double computation from the points), d is computed in double with the
 * slack 4 DBL_EPSILON (|c_t| + |c_s|) covering its rounding. Pairs that fail
 * (b) are never accepted, so they end in P2P with the smoothed kernel.
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
  int p;         /* order: coefficients 0..p-1 */
  size_t stride; /* px_real per cell of an expansion: re at [0, half), im at [half, 2 half) */
  size_t half;
  double rho, eps_mac; /* acceptance: convergence ratios <= rho = E^(1/p) */
  double cost_m2l, cost_exp;
  /* ln E: the order of one interaction is the smallest q with ρ^q <= E
   * (ρ its convergence ratio), at most p. */
  double lnE;
  px_real eps2;
  const px_real *sx, *sy, *sg; /* sorted sources */
  const px_real *tx, *ty;      /* sorted targets */
  px_real *U, *V;              /* 2π u, 2π v of the sorted targets */
  px_real *mp, *lc;            /* multipoles of source cells, locals of target cells */
  const px_real *Tm;           /* M2L matrix C(k + l, k), p × p */
  const px_real *B;            /* binomials C(k, m), p × p (row k) */
  const px_real *Bt;           /* its transpose */
};

static void PX_SFX(px_fmm_keys)(int threads, size_t n, const px_real *x, const px_real *y,
                                uint64_t *keys) {
  double xmin = HUGE_VAL, xmax = -HUGE_VAL, ymin = HUGE_VAL, ymax = -HUGE_VAL;
  double side, scale;
#pragma omp parallel for num_threads(threads) reduction(min           \
                                                        : xmin, ymin) \
    reduction(max                                                     \
              : xmax, ymax) if (n > 200000)
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
#pragma omp parallel for num_threads(threads) if (n > 200000)
  for (size_t i = 0; i < n; ++i) {
    /* NaN fails s >= 0 and lands in cell 0; infinities clamp to an edge */
    const double sx = ((double)x[i] - xmin) * scale, sy = ((double)y[i] - ymin) * scale;
    const uint32_t qx = sx >= 0.0 ? (sx < 2147483647.0 ? (uint32_t)sx : 2147483647u) : 0u;
    const uint32_t qy = sy >= 0.0 ? (sy < 2147483647.0 ? (uint32_t)sy : 2147483647u) : 0u;
    keys[i] = px_fmm_morton(qx, qy);
  }
}

/* ------------------------------ geometry ------------------------------- */

/* x rounded to the working precision, as a double. Through a volatile:
 * gcc 12.2 at -O3 -march=native SLP-vectorises the two centre coordinates
 * and drops the (double)(float) round trip of one of them (a
 * miscompilation, found by test_nbody_fmm_accuracy: float errors 30 times
 * larger); a volatile store and load cannot be elided. */
static double PX_SFX(px_fmm_round)(double x) {
  volatile px_real r = (px_real)x;
  return (double)r;
}

/* Geometry of a leaf from its points [b, e); see struct px_fmm_cell. */
static void PX_SFX(px_fmm_geo_leaf)(const px_real *x, const px_real *y, double rmin,
                                    struct px_fmm_cell *c, double *box) {
  const size_t b = c->begin, e = c->end;
  double xmin = HUGE_VAL, xmax = -HUGE_VAL, ymin = HUGE_VAL, ymax = -HUGE_VAL, cx, cy;
  double r2 = 0.0, R;
  int finite = 1;
  size_t j;
  for (j = b; j < e; ++j) {
    const double xj = (double)x[j], yj = (double)y[j];
    finite &= isfinite(xj) && isfinite(yj);
    xmin = xj < xmin ? xj : xmin;
    xmax = xj > xmax ? xj : xmax;
    ymin = yj < ymin ? yj : ymin;
    ymax = yj > ymax ? yj : ymax;
  }
  if (!(xmin <= xmax) || !(ymin <= ymax)) xmin = xmax = ymin = ymax = 0.0;
  cx = PX_SFX(px_fmm_round)(0.5 * xmin + 0.5 * xmax);
  cy = PX_SFX(px_fmm_round)(0.5 * ymin + 0.5 * ymax);
  for (j = b; j < e; ++j) {
    const double dx = (double)x[j] - cx, dy = (double)y[j] - cy, d2 = dx * dx + dy * dy;
    r2 = d2 > r2 ? d2 : r2;
  }
  R = sqrt(r2) * (1.0 + 1e-12);
  /* A non-finite coordinate makes the radius infinite: such a cell is never
   * accepted, so its pairs are summed directly (and give NaN, like the
   * direct sum). */
  if (!finite) R = HUGE_VAL;
  c->cx = cx;
  c->cy = cy;
  c->R = R;
  c->r = R > rmin ? R : rmin;
  box[0] = xmin;
  box[1] = xmax;
  box[2] = ymin;
  box[3] = ymax;
}

static void PX_SFX(px_fmm_geo_parent)(const struct px_fmm_tree *t, size_t c, double rmin) {
  struct px_fmm_cell *cell = t->cell + c;
  double *box = t->box + 4 * c;
  const size_t c0 = cell->child, c1 = c0 + cell->nchild;
  double xmin = HUGE_VAL, xmax = -HUGE_VAL, ymin = HUGE_VAL, ymax = -HUGE_VAL, cx, cy;
  double ax, ay, R, Rc = 0.0;
  int finite = 1;
  size_t k;
  for (k = c0; k < c1; ++k) {
    const double *g = t->box + 4 * k;
    xmin = g[0] < xmin ? g[0] : xmin;
    xmax = g[1] > xmax ? g[1] : xmax;
    ymin = g[2] < ymin ? g[2] : ymin;
    ymax = g[3] > ymax ? g[3] : ymax;
    finite &= t->cell[k].R < HUGE_VAL;
  }
  cx = PX_SFX(px_fmm_round)(0.5 * xmin + 0.5 * xmax);
  cy = PX_SFX(px_fmm_round)(0.5 * ymin + 0.5 * ymax);
  /* two upper bounds of the distance of a point from the centre: the far
   * corner of the bounding box, and the children's circles */
  ax = fabs(xmin - cx) > fabs(xmax - cx) ? fabs(xmin - cx) : fabs(xmax - cx);
  ay = fabs(ymin - cy) > fabs(ymax - cy) ? fabs(ymin - cy) : fabs(ymax - cy);
  R = sqrt(ax * ax + ay * ay);
  for (k = c0; k < c1; ++k) {
    const struct px_fmm_cell *g = t->cell + k;
    const double dx = g->cx - cx, dy = g->cy - cy, b = sqrt(dx * dx + dy * dy) + g->R;
    Rc = b > Rc ? b : Rc;
  }
  R = (Rc < R ? Rc : R) * (1.0 + 1e-12);
  if (!finite) R = HUGE_VAL;
  cell->cx = cx;
  cell->cy = cy;
  cell->R = R;
  cell->r = R > rmin ? R : rmin;
  box[0] = xmin;
  box[1] = xmax;
  box[2] = ymin;
  box[3] = ymax;
}

/* ------------------------------ expansions ----------------------------- */

/* P2M: multipole of the sources [b, e) about cell c. */
static void PX_SFX(px_fmm_p2m)(const struct px_fmm_run *R, const struct px_fmm_cell *c,
                               px_real *mre, px_real *mim) {
  const int p = R->p;
  const size_t b = c->begin, e = c->end;
  const px_real cx = (px_real)c->cx, cy = (px_real)c->cy, ir = (px_real)(1.0 / c->r);
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

/* M2M: add the multipole of child cc to the parent's (cp):
 * ã'_k += Σ_{m<=k} C(k, m) u^{k−m} (σ^m ã_m), summed m by m over
 * contiguous k (vectorised; R->Bt[m][k] = C(k, m)). */
static void PX_SFX(px_fmm_m2m)(const struct px_fmm_run *R, const struct px_fmm_cell *cp,
                               const struct px_fmm_cell *cc, const px_real *cre, const px_real *cim,
                               px_real *pre, px_real *pim) {
  const int p = R->p;
  px_real ur[PX_FMM_MAX_ORDER], ui[PX_FMM_MAX_ORDER], sr[PX_FMM_MAX_ORDER], si[PX_FMM_MAX_ORDER];
  int k, m;
  PX_SFX(px_fmm_powers)
  ((px_real)((cc->cx - cp->cx) / cp->r), (px_real)((cc->cy - cp->cy) / cp->r), p, ur, ui);
  PX_SFX(px_fmm_powers)((px_real)(cc->r / cp->r), PX_R(0.0), p, sr, si);
  for (m = 0; m < p; ++m) {
    const px_real br = sr[m] * cre[m], bi = sr[m] * cim[m];
    const px_real *Bm = R->Bt + (size_t)m * (size_t)p;
#pragma omp simd
    for (k = m; k < p; ++k) {
      const px_real wr = Bm[k] * ur[k - m], wi = Bm[k] * ui[k - m];
      pre[k] += wr * br - wi * bi;
      pim[k] += wr * bi + wi * br;
    }
  }
}

/* L2L: the local expansion of child cc from its parent's (cp):
 * b̃'_m = σ^m Σ_{l>=m} C(l, m) u^{l−m} b̃_l, summed l by l over contiguous
 * m (vectorised; the powers reversed, v[j] = u^{p−1−j}). */
static void PX_SFX(px_fmm_l2l)(const struct px_fmm_run *R, const struct px_fmm_cell *cp,
                               const struct px_fmm_cell *cc, const px_real *pre, const px_real *pim,
                               px_real *cre, px_real *cim) {
  const int p = R->p;
  px_real ur[PX_FMM_MAX_ORDER], ui[PX_FMM_MAX_ORDER], vr[PX_FMM_MAX_ORDER], vi[PX_FMM_MAX_ORDER],
      sr[PX_FMM_MAX_ORDER], si[PX_FMM_MAX_ORDER];
  int l, m;
  PX_SFX(px_fmm_powers)
  ((px_real)((cc->cx - cp->cx) / cp->r), (px_real)((cc->cy - cp->cy) / cp->r), p, ur, ui);
  PX_SFX(px_fmm_powers)((px_real)(cc->r / cp->r), PX_R(0.0), p, sr, si);
  for (m = 0; m < p; ++m) {
    vr[m] = ur[p - 1 - m];
    vi[m] = ui[p - 1 - m];
    cre[m] = cim[m] = PX_R(0.0);
  }
  for (l = 0; l < p; ++l) {
    const px_real br = pre[l], bi = pim[l];
    const px_real *Bl = R->B + (size_t)l * (size_t)p;
    const px_real *wr0 = vr + (p - 1 - l), *wi0 = vi + (p - 1 - l);
#pragma omp simd
    for (m = 0; m <= l; ++m) {
      const px_real wr = Bl[m] * wr0[m], wi = Bl[m] * wi0[m];
      cre[m] += wr * br - wi * bi;
      cim[m] += wr * bi + wi * br;
    }
  }
  for (m = 0; m < p; ++m) {
    cre[m] *= sr[m];
    cim[m] *= sr[m];
  }
}

/* P2L: add the sources [b, e) to the first q terms of the local expansion
 * of target cell ct. */
static void PX_SFX(px_fmm_p2l)(const struct px_fmm_run *R, size_t b, size_t e,
                               const struct px_fmm_cell *ct, int q, px_real *lre, px_real *lim) {
  const px_real cx = (px_real)ct->cx, cy = (px_real)ct->cy, r = (px_real)ct->r;
  px_real qr[PX_FMM_CHUNK], qi[PX_FMM_CHUNK], wr[PX_FMM_CHUNK], wi[PX_FMM_CHUNK];
  size_t j0;
  int l;
  for (j0 = b; j0 < e; j0 += PX_FMM_CHUNK) {
    const size_t m = e - j0 < PX_FMM_CHUNK ? e - j0 : PX_FMM_CHUNK;
    size_t j;
#pragma omp simd
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
    for (l = 0; l < q; ++l) {
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

/* L2P: set (U, V) of the targets of leaf ct from its local expansion.
 * Horner in w = (z − c)/r, vectorised over a chunk of targets. */
static void PX_SFX(px_fmm_l2p)(const struct px_fmm_run *R, const struct px_fmm_cell *ct,
                               const px_real *lre, const px_real *lim) {
  const int p = R->p;
  const size_t b = ct->begin, e = ct->end;
  const px_real cx = (px_real)ct->cx, cy = (px_real)ct->cy, ir = (px_real)(1.0 / ct->r);
  px_real wr[PX_FMM_CHUNK], wi[PX_FMM_CHUNK], ar[PX_FMM_CHUNK], ai[PX_FMM_CHUNK];
  size_t i0;
  for (i0 = b; i0 < e; i0 += PX_FMM_CHUNK) {
    const size_t m = e - i0 < PX_FMM_CHUNK ? e - i0 : PX_FMM_CHUNK;
    const px_real *tx = R->tx + i0, *ty = R->ty + i0;
    px_real *U = R->U + i0, *V = R->V + i0;
    size_t i;
    int l;
#pragma omp simd
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
#pragma omp simd
    for (i = 0; i < m; ++i) {
      U[i] = ai[i];
      V[i] = ar[i];
    }
  }
}

/* M2P: add the first q terms of the multipole of source cell cs at the
 * targets [b, e). */
static void PX_SFX(px_fmm_m2p)(const struct px_fmm_run *R, size_t b, size_t e,
                               const struct px_fmm_cell *cs, int q, const px_real *mre,
                               const px_real *mim) {
  const px_real cx = (px_real)cs->cx, cy = (px_real)cs->cy, r = (px_real)cs->r;
  const px_real ir = (px_real)(1.0 / cs->r);
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
      ar[i] = mre[q - 1];
      ai[i] = mim[q - 1];
    }
    for (k = q - 2; k >= 0; --k) {
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

/* ---------------------------------- M2L -------------------------------- */

/* The M2Ls of one target cell run in blocks of PX_FMM_VW source cells (the
 * vector lanes), sorted by their order q (largest first, so a block's first
 * column has its order). Per block:
 *   X[k][j] = ã_k(s_j) ρ_s,j^k                (k < q; re in lanes 0..W-1, im in W..2W-1)
 *   Y = T X,  T[l][k] = C(k + l, k)           (q × q block of the p × p matrix)
 *   A[l][j] += ρ_t,j^l / z0_j · Y[l][j]       (complex, per lane)
 * and once per cell b̃_l += (−1)^l Σ_j A[l][j]. */

/* px_real elements of the M2L scratch: X, Y (p × 2W each), A (2 × p × W). */
static size_t PX_SFX(px_fmm_m2l_scratch)(int p) { return (size_t)p * 6 * PX_FMM_VW; }

/* Y = T X for one block: X, Y are q × LD (LD = 2 vectors), T has row stride
 * pt. Register-blocked: 4 rows × 2 vectors of accumulators. fma() is an
 * exact fused operation, so the result does not depend on the compiler
 * (-ffp-contract=off holds everywhere else). */
static void PX_SFX(px_fmm_gemm)(int q, int pt, const px_real *T, const px_real *X, px_real *Y) {
  enum { LD = 2 * PX_FMM_VW };
  int l0 = 0, k, c;
  for (; l0 + 4 <= q; l0 += 4) {
    const px_real *T0 = T + (size_t)l0 * (size_t)pt, *T1 = T0 + pt, *T2 = T1 + pt, *T3 = T2 + pt;
    px_real a0[LD], a1[LD], a2[LD], a3[LD];
    px_real *y = Y + (size_t)l0 * LD;
    for (c = 0; c < LD; ++c) a0[c] = a1[c] = a2[c] = a3[c] = PX_R(0.0);
    for (k = 0; k < q; ++k) {
      const px_real *xk = X + (size_t)k * LD;
      const px_real t0 = T0[k], t1 = T1[k], t2 = T2[k], t3 = T3[k];
#pragma omp simd
      for (c = 0; c < LD; ++c) {
        a0[c] = fma(t0, xk[c], a0[c]);
        a1[c] = fma(t1, xk[c], a1[c]);
        a2[c] = fma(t2, xk[c], a2[c]);
        a3[c] = fma(t3, xk[c], a3[c]);
      }
    }
    for (c = 0; c < LD; ++c) {
      y[c] = a0[c];
      y[LD + c] = a1[c];
      y[2 * LD + c] = a2[c];
      y[3 * LD + c] = a3[c];
    }
  }
  for (; l0 < q; ++l0) {
    const px_real *T0 = T + (size_t)l0 * (size_t)pt;
    px_real a0[LD];
    for (c = 0; c < LD; ++c) a0[c] = PX_R(0.0);
    for (k = 0; k < q; ++k) {
      const px_real *xk = X + (size_t)k * LD;
      const px_real t0 = T0[k];
#pragma omp simd
      for (c = 0; c < LD; ++c) a0[c] = fma(t0, xk[c], a0[c]);
    }
    for (c = 0; c < LD; ++c) Y[(size_t)l0 * LD + (size_t)c] = a0[c];
  }
}

/* One block: m <= W source cells src[] of order q into the lane sums A. */
static void PX_SFX(px_fmm_m2l_block)(const struct px_fmm_run *R, const struct px_fmm_cell *ct,
                                     const uint32_t *src, int m, int q, px_real *X, px_real *Y,
                                     px_real *Ar, px_real *Ai) {
  enum { W = PX_FMM_VW, LD = 2 * PX_FMM_VW };
  px_real sr[W], si[W], tr[W], ti[W], vr[W], vi[W], Pr[W], Pi[W];
  int j, k, l;
  for (j = 0; j < W; ++j) {
    if (j < m) {
      const struct px_fmm_cell *cs = R->S->cell + src[j];
      const px_real *a = R->mp + (size_t)src[j] * R->stride;
      const double zr = ct->cx - cs->cx, zi = ct->cy - cs->cy, iz = 1.0 / (zr * zr + zi * zi);
      const double ivr = zr * iz, ivi = -zi * iz; /* 1 / z0 */
      sr[j] = (px_real)(cs->r * ivr);
      si[j] = (px_real)(cs->r * ivi);
      tr[j] = (px_real)(ct->r * ivr);
      ti[j] = (px_real)(ct->r * ivi);
      vr[j] = (px_real)ivr;
      vi[j] = (px_real)ivi;
      for (k = 0; k < q; ++k) {
        X[k * LD + j] = a[k];
        X[k * LD + W + j] = a[R->half + (size_t)k];
      }
    } else {
      sr[j] = si[j] = tr[j] = ti[j] = vr[j] = vi[j] = PX_R(0.0);
      for (k = 0; k < q; ++k) X[k * LD + j] = X[k * LD + W + j] = PX_R(0.0);
    }
    Pr[j] = PX_R(1.0);
    Pi[j] = PX_R(0.0);
  }
  /* X_k ← ã_k ρ_s^k */
  for (k = 0; k < q; ++k) {
    px_real *xr = X + k * LD, *xi = xr + W;
#pragma omp simd
    for (j = 0; j < W; ++j) {
      const px_real ar = xr[j], ai = xi[j], qr = Pr[j], qi = Pi[j];
      xr[j] = ar * qr - ai * qi;
      xi[j] = ar * qi + ai * qr;
      Pr[j] = qr * sr[j] - qi * si[j];
      Pi[j] = qr * si[j] + qi * sr[j];
    }
  }
  PX_SFX(px_fmm_gemm)(q, R->p, R->Tm, X, Y);
  /* A_l += ρ_t^l / z0 · Y_l */
  for (l = 0; l < q; ++l) {
    const px_real *yr = Y + l * LD, *yi = yr + W;
    px_real *ar = Ar + l * W, *ai = Ai + l * W;
#pragma omp simd
    for (j = 0; j < W; ++j) {
      const px_real qr = vr[j], qi = vi[j];
      ar[j] += qr * yr[j] - qi * yi[j];
      ai[j] += qr * yi[j] + qi * yr[j];
      vr[j] = qr * tr[j] - qi * ti[j];
      vi[j] = qr * ti[j] + qi * tr[j];
    }
  }
}

/* P2P: add the sources g{x,y,g}[0, n) to the targets [b, e) (smoothed kernel). */
static void PX_SFX(px_fmm_p2p)(const struct px_fmm_run *R, size_t b, size_t e, const px_real *gx,
                               const px_real *gy, const px_real *gg, size_t n) {
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

static int PX_SFX(px_fmm_pass_add)(struct px_fmm *fmm, struct px_fmm_thread *th, int pool,
                                   uint32_t c) {
  if (th->pass_len[pool] >= th->pass_cap[pool] / sizeof(uint32_t) &&
      px_fmm_reserve(fmm->ctx, "fmm hand-down lists", (void **)&th->pass[pool], &th->pass_cap[pool],
                     (th->pass_len[pool] + 1) * sizeof(uint32_t)))
    return -1;
  th->pass[pool][th->pass_len[pool]++] = c;
  return 0;
}

/* Order of an interaction with convergence ratio rho: the smallest q in
 * [2, p] with rho^q <= E = ρ_ref^p, i.e. q = ceil(ln E / ln rho). */
static int PX_SFX(px_fmm_order)(const struct px_fmm_run *R, double rho) {
  const double q = rho > 0.0 ? ceil(R->lnE / log(rho) - 1e-9) : 2.0;
  return q >= (double)R->p ? R->p : (q <= 2.0 ? 2 : (int)q);
}

/* The far field of target cell t: M2L (sorted by order, in blocks) and P2L
 * into its local expansion. Returns 1 if the local received anything. */
static int PX_SFX(px_fmm_far)(const struct px_fmm_run *R, struct px_fmm_thread *th,
                              const struct px_fmm_cell *ct, size_t nl, px_real *lre, px_real *lim) {
  const struct px_fmm_tree *S = R->S;
  size_t count[PX_FMM_MAX_ORDER + 2], k, nm = 0;
  int q, l, any = 0;
  memset(count, 0, sizeof count);
  for (k = 0; k < nl; ++k) {
    const uint32_t kind = th->list[2 * k] & 0xffu, s = th->list[2 * k + 1];
    q = (int)(th->list[2 * k] >> 8);
    if (kind == PX_FMM_P2L) {
      PX_SFX(px_fmm_p2l)(R, S->cell[s].begin, S->cell[s].end, ct, q, lre, lim);
      any = 1;
      ++th->p2l;
      th->p2l_sources += (double)(S->cell[s].end - S->cell[s].begin);
    } else if (kind == PX_FMM_M2L) {
      ++count[R->p - q + 1]; /* counting sort, largest order first */
      ++nm;
    }
  }
  if (nm > 0) {
    const int qmax = R->p; /* row bound of the lane sums */
    px_real *X = th->buf, *Y = X + (size_t)qmax * 2 * PX_FMM_VW;
    px_real *Ar = Y + (size_t)qmax * 2 * PX_FMM_VW, *Ai = Ar + (size_t)qmax * PX_FMM_VW;
    uint32_t *sorted = th->sorted;
    int top = 0;
    for (k = 1; k < PX_FMM_MAX_ORDER + 2; ++k) count[k] += count[k - 1];
    for (k = 0; k < nl; ++k)
      if ((th->list[2 * k] & 0xffu) == PX_FMM_M2L) {
        q = (int)(th->list[2 * k] >> 8);
        sorted[2 * count[R->p - q]] = th->list[2 * k + 1];
        sorted[2 * count[R->p - q]++ + 1] = (uint32_t)q;
      }
    top = (int)sorted[1];
    for (k = 0; k < (size_t)top * PX_FMM_VW; ++k) Ar[k] = Ai[k] = PX_R(0.0);
    for (k = 0; k < nm; k += PX_FMM_VW) {
      const int m = nm - k < (size_t)PX_FMM_VW ? (int)(nm - k) : PX_FMM_VW;
      uint32_t src[PX_FMM_VW];
      int j;
      q = (int)sorted[2 * k + 1];
      for (j = 0; j < m; ++j) src[j] = sorted[2 * (k + (size_t)j)];
      PX_SFX(px_fmm_m2l_block)(R, ct, src, m, q, X, Y, Ar, Ai);
      th->m2l_terms += (double)m * (double)q * (double)q;
    }
    for (l = 0; l < top; ++l) {
      px_real sr = PX_R(0.0), si = PX_R(0.0);
      int j;
      for (j = 0; j < PX_FMM_VW; ++j) {
        sr += Ar[l * PX_FMM_VW + j];
        si += Ai[l * PX_FMM_VW + j];
      }
      if (l & 1) {
        lre[l] -= sr;
        lim[l] -= si;
      } else {
        lre[l] += sr;
        lim[l] += si;
      }
    }
    th->m2l += nm;
    any = 1;
  }
  return any;
}

/* One target cell t: its local expansion (L2L + the accepted far field),
 * its hand-down list (appended to the thread's pool `pool`; the parent's
 * list is read from wherever pass_info says), and for a leaf the velocities
 * of its targets. */
static void PX_SFX(px_fmm_target)(const struct px_fmm_run *R, struct px_fmm_thread *th, int tid,
                                  int pool, size_t t) {
  struct px_fmm *fmm = R->fmm;
  const struct px_fmm_tree *S = R->S, *T = R->T;
  const struct px_fmm_cell *ct = T->cell + t;
  const int tleaf = ct->nchild == 0;
  const double nt = (double)(ct->end - ct->begin);
  px_real *lre = R->lc + t * R->stride, *lim = lre + R->half;
  size_t sp = 0, nl = 0, nm = 0, k, pass0 = th->pass_len[pool];
  int has = 0, q;
  /* the source cells to examine */
  if (t == 0) {
    if (PX_SFX(px_fmm_push)(fmm, th, &sp, 0)) goto oom;
  } else {
    const size_t par = ct->parent;
    const uint32_t *info = fmm->pass_info + 3 * par;
    if (info[2] > 0) { /* a parent that handed nothing down may own no list */
      const uint32_t *in = fmm->thr[info[0] / 2].pass[info[0] % 2] + info[1];
      for (k = info[2]; k-- > 0;)
        if (PX_SFX(px_fmm_push)(fmm, th, &sp, in[k])) goto oom;
    }
    if (fmm->has_local[par]) {
      const px_real *pl = R->lc + par * R->stride;
      PX_SFX(px_fmm_l2l)(R, T->cell + par, ct, pl, pl + R->half, lre, lim);
      has = 1;
    }
  }
  if (!has)
    for (q = 0; q < R->p; ++q) lre[q] = lim[q] = PX_R(0.0);
  while (sp > 0) {
    const uint32_t s = th->stack[--sp];
    const struct px_fmm_cell *cs = S->cell + s;
    const double dx = ct->cx - cs->cx, dy = ct->cy - cs->cy, d = sqrt(dx * dx + dy * dy);
    const double rsum = ct->R + cs->R, dt = d - ct->R, ds = d - cs->R;
    const double slack =
        4.0 * DBL_EPSILON * (fabs(ct->cx) + fabs(ct->cy) + fabs(cs->cx) + fabs(cs->cy));
    if (cs->R <= R->rho * dt && ct->R <= R->rho * ds && d - rsum >= R->eps_mac + slack) {
      /* convergence ratios of the multipole (a) and local (b) series */
      const double a = cs->R / dt, b = ct->R / ds;
      const double ns = (double)(cs->end - cs->begin);
      const int qm = PX_SFX(px_fmm_order)(R, a > b ? a : b);
      double best = R->cost_m2l * (double)qm * (double)qm, c;
      uint32_t kind = PX_FMM_M2L;
      q = qm;
      /* P2L and M2P (orders <= qm) only when they can be cheaper */
      if (R->cost_exp * (double)qm * ns < best) {
        const int qb = PX_SFX(px_fmm_order)(R, b);
        c = R->cost_exp * (double)qb * ns;
        if (c < best) best = c, kind = PX_FMM_P2L, q = qb;
      }
      if (tleaf && R->cost_exp * (double)qm * nt < best) {
        const int qa = PX_SFX(px_fmm_order)(R, a);
        c = R->cost_exp * (double)qa * nt;
        if (c < best) best = c, kind = PX_FMM_M2P, q = qa;
      }
      if (tleaf && nt * ns < best) kind = PX_FMM_P2P, q = 0;
      if (PX_SFX(px_fmm_list_add)(fmm, th, &nl, kind | (uint32_t)q << 8, s)) goto oom;
      nm += kind == PX_FMM_M2L;
    } else if (tleaf) {
      if (cs->nchild == 0) {
        if (PX_SFX(px_fmm_list_add)(fmm, th, &nl, PX_FMM_P2P, s)) goto oom;
      } else {
        for (k = cs->nchild; k-- > 0;)
          if (PX_SFX(px_fmm_push)(fmm, th, &sp, (uint32_t)(cs->child + k))) goto oom;
      }
    } else if (cs->nchild == 0 || cs->R <= ct->R) {
      if (PX_SFX(px_fmm_pass_add)(fmm, th, pool, s)) goto oom;
    } else {
      for (k = cs->nchild; k-- > 0;)
        if (PX_SFX(px_fmm_push)(fmm, th, &sp, (uint32_t)(cs->child + k))) goto oom;
    }
  }
  fmm->pass_info[3 * t] = (uint32_t)(2 * tid + pool);
  fmm->pass_info[3 * t + 1] = (uint32_t)pass0;
  fmm->pass_info[3 * t + 2] = (uint32_t)(th->pass_len[pool] - pass0);
  if (px_fmm_reserve(fmm->ctx, "fmm scratch", &th->buf, &th->buf_cap,
                     PX_SFX(px_fmm_m2l_scratch)(R->p) * sizeof(px_real)) ||
      px_fmm_reserve(fmm->ctx, "fmm interaction lists", (void **)&th->sorted, &th->sorted_cap,
                     2 * (nm + 1) * sizeof(uint32_t)))
    goto oom;
  has |= PX_SFX(px_fmm_far)(R, th, ct, nl, lre, lim);
  fmm->has_local[t] = (uint8_t)has;
  if (tleaf) {
    const size_t b = ct->begin, e = ct->end;
    size_t nn = 0, need = 0;
    px_real *gx, *gy, *gg;
    if (has) {
      PX_SFX(px_fmm_l2p)(R, ct, lre, lim);
    } else {
      for (k = b; k < e; ++k) R->U[k] = R->V[k] = PX_R(0.0);
    }
    for (k = 0; k < nl; ++k) {
      const uint32_t kind = th->list[2 * k] & 0xffu, s = th->list[2 * k + 1];
      if (kind == PX_FMM_M2P) {
        const px_real *a = R->mp + (size_t)s * R->stride;
        PX_SFX(px_fmm_m2p)(R, b, e, S->cell + s, (int)(th->list[2 * k] >> 8), a, a + R->half);
        ++th->m2p;
        th->m2p_targets += nt;
      } else if (kind == PX_FMM_P2P) {
        need += S->cell[s].end - S->cell[s].begin;
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
        const uint32_t kind = th->list[2 * k] & 0xffu, s = th->list[2 * k + 1];
        if (kind == PX_FMM_P2P) {
          const size_t sb = S->cell[s].begin, c = S->cell[s].end - sb;
          memcpy(gx + nn, R->sx + sb, c * sizeof(px_real));
          memcpy(gy + nn, R->sy + sb, c * sizeof(px_real));
          memcpy(gg + nn, R->sg + sb, c * sizeof(px_real));
          nn += c;
          ++th->p2p_cells;
        }
      }
      PX_SFX(px_fmm_p2p)(R, b, e, gx, gy, gg, nn);
      th->p2p_pairs += (double)nn * nt;
    }
  }
  return;
oom:
  th->failed = 1;
}

/* Bottom-up work of one cell (its children are done): geometry, and for
 * the source tree the multipole (P2M at a leaf, M2M from the children). */
static void PX_SFX(px_fmm_up_cell)(const struct px_fmm_run *R, const struct px_fmm_tree *t,
                                   const px_real *x, const px_real *y, int multipoles, double rmin,
                                   size_t c) {
  struct px_fmm_cell *cell = t->cell + c;
  px_real *a = R->mp + c * R->stride;
  if (cell->nchild == 0) {
    PX_SFX(px_fmm_geo_leaf)(x, y, rmin, cell, t->box + 4 * c);
    if (multipoles) PX_SFX(px_fmm_p2m)(R, cell, a, a + R->half);
  } else {
    PX_SFX(px_fmm_geo_parent)(t, c, rmin);
    if (multipoles) {
      const size_t c0 = cell->child, c1 = c0 + cell->nchild;
      size_t k;
      int q;
      for (q = 0; q < R->p; ++q) a[q] = a[R->half + (size_t)q] = PX_R(0.0);
      for (k = c0; k < c1; ++k) {
        const px_real *ac = R->mp + k * R->stride;
        PX_SFX(px_fmm_m2m)(R, cell, t->cell + k, ac, ac + R->half, a, a + R->half);
      }
    }
  }
}

/* The subtree of cell c bottom-up (post-order), by one thread. */
static void PX_SFX(px_fmm_up_tree)(const struct px_fmm_run *R, const struct px_fmm_tree *t,
                                   const px_real *x, const px_real *y, int multipoles, double rmin,
                                   size_t c) {
  const size_t c0 = t->cell[c].child, c1 = c0 + t->cell[c].nchild;
  size_t k;
  for (k = c0; k < c1; ++k) PX_SFX(px_fmm_up_tree)(R, t, x, y, multipoles, rmin, k);
  PX_SFX(px_fmm_up_cell)(R, t, x, y, multipoles, rmin, c);
}

/* The target subtree of cell c top-down (pre-order), by one thread; the
 * hand-down lists live on the thread's pool 1 as a stack. */
static void PX_SFX(px_fmm_down_tree)(const struct px_fmm_run *R, struct px_fmm_thread *th, int tid,
                                     size_t c) {
  const size_t mark = th->pass_len[1];
  const size_t c0 = R->T->cell[c].child, c1 = c0 + R->T->cell[c].nchild;
  size_t k;
  PX_SFX(px_fmm_target)(R, th, tid, 1, c);
  for (k = c0; k < c1 && !th->failed; ++k) PX_SFX(px_fmm_down_tree)(R, th, tid, k);
  th->pass_len[1] = mark;
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
  R.half = (size_t)(R.p + PX_FMM_VW - 1) / (size_t)PX_FMM_VW * (size_t)PX_FMM_VW;
  R.stride = 2 * R.half;
  R.rho = exp(log(prm->err) / (double)R.p);
  R.eps_mac = a->eps * (1.0 + 1e-6);
  R.eps2 = (px_real)(a->eps * a->eps);
  R.cost_m2l = prm->cost_m2l;
  R.cost_exp = prm->cost_exp;
  R.lnE = log(prm->err);
  PX_TRY(px_fmm_threads(fmm, threads));

  /* trees */
  PX_TRY(px_fmm_tree_reserve(ctx, S, ns));
  PX_SFX(px_fmm_keys)(threads, ns, a->sx, a->sy, S->keys);
  PX_TRY(px_fmm_tree_build(ctx, S, threads, ns, prm->leaf));
  if (!a->self) {
    PX_TRY(px_fmm_tree_reserve(ctx, T, nt));
    PX_SFX(px_fmm_keys)(threads, nt, a->tx, a->ty, T->keys);
    PX_TRY(px_fmm_tree_build(ctx, T, threads, nt, prm->leaf));
    PX_TRY(px_fmm_tree_tasks(ctx, T, threads));
  }
  PX_TRY(px_fmm_tree_tasks(ctx, S, threads));

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

  /* expansions and tables */
  if (px_fmm_reserve(ctx, "fmm multipoles", &fmm->mpole, &fmm->mpole_cap,
                     S->ncells * R.stride * sizeof(px_real)) ||
      px_fmm_reserve(ctx, "fmm locals", &fmm->local, &fmm->local_cap,
                     T->ncells * R.stride * sizeof(px_real)) ||
      px_fmm_reserve(ctx, "fmm tables", &fmm->tables, &fmm->tables_cap,
                     3 * (size_t)R.p * (size_t)R.p * sizeof(px_real)))
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
    /* Pascal's triangle in double: exact while C(n, k) < 2^53 (n <= 56,
     * i.e. p <= 29), rounded to 1e-16 relative beyond; then cast */
    px_real *Tm = fmm->tables, *Bm = Tm + (size_t)R.p * (size_t)R.p;
    double row[2 * PX_FMM_MAX_ORDER + 1];
    int n;
    row[0] = 1.0;
    for (n = 0; n <= 2 * R.p - 2; ++n) {
      /* row n: C(n, 0..n) */
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
    for (n = 0; n < R.p; ++n)
      for (k = 0; k < R.p; ++k)
        Bm[(size_t)(R.p + n) * (size_t)R.p + (size_t)k] = Bm[(size_t)k * (size_t)R.p + (size_t)n];
    R.Tm = Tm;
    R.B = Bm;
    R.Bt = Bm + (size_t)R.p * (size_t)R.p;
  }
  t1 = px_time_now();
  t2 = t1;

  for (k = 0; k < fmm->nthreads; ++k) {
    struct px_fmm_thread *th = fmm->thr + k;
    th->failed = 0;
    th->m2l = th->p2l = th->m2p = th->p2p_cells = 0;
    th->p2p_pairs = th->m2p_targets = th->p2l_sources = th->m2l_terms = 0.0;
    th->pass_len[0] = th->pass_len[1] = 0;
  }
  /* One parallel region, few barriers (the machine may be shared: a
   * barrier waits for a preempted thread). Subtrees below the top cells
   * are tasks taken dynamically, largest first; the top cells are done by
   * one thread. Who does a cell never changes what is computed. */
  {
    const double rmin = 1e-3 * a->eps;
    const int self = a->self;
    const px_real *sx = a->sx, *sy = a->sy, *sg = a->sg, *tx = a->tx, *ty = a->ty;
    px_real *ox = pts, *oy = pts + nsp, *og = pts + 2 * nsp;
    px_real *otx = pts + 3 * nsp, *oty = pts + 3 * nsp + ntp, *u = a->u, *v = a->v;
    const px_real *U = R.U, *V = R.V;
    const uint32_t *sp = S->perm, *tp = T->perm;
    const int acc = a->accumulate;
#pragma omp parallel num_threads(threads)
    {
      const int tid = omp_get_thread_num();
      struct px_fmm_thread *th = fmm->thr + tid;
      size_t j;
      int bad = 0;
      /* sources and targets into Morton order */
#pragma omp for schedule(static) nowait
      for (size_t q = 0; q < ns; ++q) {
        ox[q] = sx[sp[q]];
        oy[q] = sy[sp[q]];
        og[q] = sg[sp[q]];
      }
      if (!self) {
#pragma omp for schedule(static) nowait
        for (size_t q = 0; q < nt; ++q) {
          otx[q] = tx[tp[q]];
          oty[q] = ty[tp[q]];
        }
      }
#pragma omp barrier
#pragma omp for schedule(dynamic, 1)
      for (size_t q = 0; q < S->nfront + (self ? 0 : T->nfront); ++q) {
        if (q < S->nfront)
          PX_SFX(px_fmm_up_tree)(&R, S, R.sx, R.sy, 1, rmin, S->task[S->ntop + q]);
        else
          PX_SFX(px_fmm_up_tree)(&R, T, R.tx, R.ty, 0, rmin, T->task[T->ntop + q - S->nfront]);
      }
#pragma omp single
      {
        for (j = S->ntop; j-- > 0;) PX_SFX(px_fmm_up_cell)(&R, S, R.sx, R.sy, 1, rmin, S->task[j]);
        if (!self)
          for (j = T->ntop; j-- > 0;)
            PX_SFX(px_fmm_up_cell)(&R, T, R.tx, R.ty, 0, rmin, T->task[j]);
        t2 = px_time_now();
        for (j = 0; j < T->ntop && !th->failed; ++j)
          PX_SFX(px_fmm_target)(&R, th, tid, 0, T->task[j]);
      }
#pragma omp for schedule(dynamic, 1)
      for (size_t q = 0; q < T->nfront; ++q)
        if (!th->failed) PX_SFX(px_fmm_down_tree)(&R, th, tid, T->task[T->ntop + q]);
      /* back to the input order, with the 1/(2π), unless a thread failed */
      for (int w = 0; w < fmm->nthreads; ++w) bad |= fmm->thr[w].failed;
      if (!bad) {
#pragma omp for schedule(static)
        for (size_t q = 0; q < nt; ++q) {
          const size_t o = tp[q];
          u[o] = (acc ? u[o] : PX_R(0.0)) + PX_BIOT_SAVART_SCALE * U[q];
          v[o] = (acc ? v[o] : PX_R(0.0)) + PX_BIOT_SAVART_SCALE * V[q];
        }
      }
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
    fmm->stats.m2l_terms += th->m2l_terms;
  }
  if (failed)
    return px_context_status(ctx) != PX_STATUS_OK ? px_context_status(ctx) : PX_STATUS_NOMEM;

  fmm->stats.src_cells = S->ncells;
  fmm->stats.tgt_cells = T->ncells;
  fmm->stats.src_generations = S->ngen;
  fmm->stats.tgt_generations = T->ngen;
  for (i = 0; i < S->ncells; ++i) fmm->stats.src_leaves += S->cell[i].nchild == 0;
  for (i = 0; i < T->ncells; ++i) fmm->stats.tgt_leaves += T->cell[i].nchild == 0;
  fmm->stats.t_tree = t1 - t0;
  fmm->stats.t_up = t2 - t1;
  fmm->stats.t_total = px_time_now() - t0;
  fmm->stats.t_down = fmm->stats.t_total - fmm->stats.t_up - fmm->stats.t_tree;
  return PX_STATUS_OK;
}
