/* Part of the template fmm_cpu.h, included by it once per precision after
 * struct px_fmm_run and the names of its functions: Morton keys, cell
 * geometry, and the operators of one cell or one pair of cells (P2M, M2M,
 * L2L, P2L, L2P, M2P, M2L, P2P; formulas in fmm_cpu.h). */
#ifndef PX_FMM_VW
#error "nbody/fmm_cpu_ops.h is a part of nbody/fmm_cpu.h"
#endif

/* Points from which the key loops run on all threads (a team's fork and join
 * cost ~0.5 us; 16k keys ~30 us on one core). */
#define PX_FMM_KEYS_PARALLEL 16384

static void px_fmm_keys(int threads, size_t n, const px_real *x, const px_real *y, uint64_t *keys) {
  double xmin = HUGE_VAL, xmax = -HUGE_VAL, ymin = HUGE_VAL, ymax = -HUGE_VAL;
  double side, scale;
#pragma omp parallel for num_threads(threads) reduction(min           \
                                                        : xmin, ymin) \
    reduction(max                                                     \
              : xmax, ymax) if (n >= PX_FMM_KEYS_PARALLEL)
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
#pragma omp parallel for num_threads(threads) if (n >= PX_FMM_KEYS_PARALLEL)
  for (size_t i = 0; i < n; ++i) {
    /* NaN fails s >= 0 and lands in cell 0; infinities clamp to an edge */
    const double sx = ((double)x[i] - xmin) * scale, sy = ((double)y[i] - ymin) * scale;
    const uint32_t qx = sx >= 0.0 ? (sx < 2147483647.0 ? (uint32_t)sx : 2147483647u) : 0u;
    const uint32_t qy = sy >= 0.0 ? (sy < 2147483647.0 ? (uint32_t)sy : 2147483647u) : 0u;
    keys[i] = px_morton2(qx, qy);
  }
}

/* ------------------------------ geometry ------------------------------- */

/* x rounded to the working precision, as a double. Through a volatile:
 * gcc 12.2 at -O3 -march=native SLP-vectorises the two centre coordinates
 * and drops the (double)(float) round trip of one of them (a
 * miscompilation, found by test_nbody_fmm_accuracy: float errors 30 times
 * larger); a volatile store and load cannot be elided. */
static double px_fmm_round(double x) {
  volatile px_real r = (px_real)x;
  return (double)r;
}

/* Geometry of a leaf from its points [b, e); see struct px_fmm_cell. */
static void px_fmm_geo_leaf(const px_real *x, const px_real *y, double rmin, struct px_fmm_cell *c,
                            double *box) {
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
  cx = px_fmm_round(0.5 * xmin + 0.5 * xmax);
  cy = px_fmm_round(0.5 * ymin + 0.5 * ymax);
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

static void px_fmm_geo_parent(const struct px_fmm_tree *t, size_t c, double rmin) {
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
  cx = px_fmm_round(0.5 * xmin + 0.5 * xmax);
  cy = px_fmm_round(0.5 * ymin + 0.5 * ymax);
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

/* The vectors of P2M and L2P: PX_FMM_LANES of the working precision (GCC
 * and clang vector extensions), PX_FMM_BLOCKS of them at a time. Written
 * as plain loops over arrays, the recurrences below went through memory
 * each term (a store and a reload per point and power), with a scalar
 * remainder per term for the points beyond a multiple of the vector width;
 * in registers, 4 blocks of 8 points give 4 independent chains. With M2M
 * and L2L over whole vectors (below), the upward pass at 55k wake vortices
 * went from 1.55 to 1.15-1.25 ms on one Zen 5 core (bench/vortex_fmm,
 * 2026-11-28). */
#define PX_FMM_LANES 8
#define PX_FMM_BLOCKS 4
#define PX_FMM_GROUP (PX_FMM_LANES * PX_FMM_BLOCKS)
typedef px_real px_fmm_vec __attribute__((vector_size(PX_FMM_LANES * sizeof(px_real))));

/* v = a[0..PX_FMM_LANES) (a macro: a vector returned by value changes the
 * ABI where the build has no vector registers that wide) */
#define PX_FMM_VLOAD(v, a) memcpy(&(v), (a), sizeof(v))

/* out[i] = the sum of the lanes of v[i], i < 8, in a fixed order: lanes l
 * and l + 4, then l and l + 2 of those, then the last pair (a transposing
 * reduction, 7 vector additions for 8 sums). */
static void px_fmm_hsum8(const px_fmm_vec *v, px_real *out) {
  px_fmm_vec a[4], b[2], c;
  int i;
  for (i = 0; i < 4; ++i)
    a[i] = __builtin_shufflevector(v[2 * i], v[2 * i + 1], 0, 1, 2, 3, 8, 9, 10, 11) +
           __builtin_shufflevector(v[2 * i], v[2 * i + 1], 4, 5, 6, 7, 12, 13, 14, 15);
  /* a[i]: lanes 0-3 of v[2i], then 4-7 of v[2i + 1] */
  for (i = 0; i < 2; ++i)
    b[i] = __builtin_shufflevector(a[2 * i], a[2 * i + 1], 0, 1, 8, 9, 4, 5, 12, 13) +
           __builtin_shufflevector(a[2 * i], a[2 * i + 1], 2, 3, 10, 11, 6, 7, 14, 15);
  /* b[i]: pairs of v[4i], v[4i + 2], v[4i + 1], v[4i + 3] */
  c = __builtin_shufflevector(b[0], b[1], 0, 8, 2, 10, 4, 12, 6, 14) +
      __builtin_shufflevector(b[0], b[1], 1, 9, 3, 11, 5, 13, 7, 15);
  /* c: v0, v4, v2, v6, v1, v5, v3, v7 */
  out[0] = c[0];
  out[4] = c[1];
  out[2] = c[2];
  out[6] = c[3];
  out[1] = c[4];
  out[5] = c[5];
  out[3] = c[6];
  out[7] = c[7];
}

/* P2M: multipole of the sources [b, e) about cell c. Each lane sums its
 * points' terms (PX_FMM_GROUP points at a time, the last group padded with
 * zero strengths), then the lanes are added (px_fmm_hsum8). */
static void px_fmm_p2m(const struct px_fmm_run *R, const struct px_fmm_cell *c, px_real *mre,
                       px_real *mim) {
  enum { L = PX_FMM_LANES, NB = PX_FMM_BLOCKS, G = PX_FMM_GROUP };
  const int p = R->p, p8 = (p + L - 1) / L * L;
  const size_t b = c->begin, e = c->end;
  const px_real cx = (px_real)c->cx, cy = (px_real)c->cy, ir = (px_real)(1.0 / c->r);
  px_fmm_vec ar[PX_FMM_MAX_ORDER + PX_FMM_LANES], ai[PX_FMM_MAX_ORDER + PX_FMM_LANES];
  px_real wr[G], wi[G], g[G];
  size_t j0;
  int k;
  for (k = 0; k < p8; ++k) ar[k] = ai[k] = (px_fmm_vec){0};
  for (j0 = b; j0 < e; j0 += G) {
    const size_t m = e - j0 < G ? e - j0 : G;
    px_fmm_vec vwr[NB], vwi[NB], pr[NB], pi[NB];
    size_t j;
    int q;
#pragma omp simd
    for (j = 0; j < m; ++j) {
      wr[j] = (R->sx[j0 + j] - cx) * ir;
      wi[j] = (R->sy[j0 + j] - cy) * ir;
      g[j] = R->sg[j0 + j];
    }
    for (j = m; j < G; ++j) wr[j] = wi[j] = g[j] = PX_R(0.0);
    for (q = 0; q < NB; ++q) {
      PX_FMM_VLOAD(vwr[q], wr + q * L);
      PX_FMM_VLOAD(vwi[q], wi + q * L);
      PX_FMM_VLOAD(pr[q], g + q * L);
      pi[q] = (px_fmm_vec){0};
    }
    for (k = 0; k < p; ++k) {
      /* Γ w^k of each point: its own lane */
      ar[k] += (pr[0] + pr[1]) + (pr[2] + pr[3]);
      ai[k] += (pi[0] + pi[1]) + (pi[2] + pi[3]);
      for (q = 0; q < NB; ++q) {
        const px_fmm_vec t = pr[q] * vwr[q] - pi[q] * vwi[q];
        pi[q] = pr[q] * vwi[q] + pi[q] * vwr[q];
        pr[q] = t;
      }
    }
  }
  for (k = 0; k < p8; k += L) {
    px_real sr[L], si[L];
    px_fmm_hsum8(ar + k, sr);
    px_fmm_hsum8(ai + k, si);
    for (int l = 0; l < L && k + l < p; ++l) {
      mre[k + l] = sr[l];
      mim[k + l] = si[l];
    }
  }
}

/* Powers z^0 .. z^(p-1) of a complex number: z^k = z^(k-4) z^4, four
 * chains of multiplications instead of one (the chain's latency was most of
 * M2M and L2L beside their vector loops). */
static void px_fmm_powers(px_real zr, px_real zi, int p, px_real *re, px_real *im) {
  px_real r4, i4;
  int k;
  re[0] = PX_R(1.0);
  im[0] = PX_R(0.0);
  re[1] = zr;
  im[1] = zi;
  re[2] = zr * zr - zi * zi;
  im[2] = zr * zi + zi * zr;
  re[3] = re[2] * zr - im[2] * zi;
  im[3] = re[2] * zi + im[2] * zr;
  r4 = re[2] * re[2] - im[2] * im[2];
  i4 = re[2] * im[2] + im[2] * re[2];
  for (k = 4; k < p; ++k) {
    re[k] = re[k - 4] * r4 - im[k - 4] * i4;
    im[k] = re[k - 4] * i4 + im[k - 4] * r4;
  }
}

/* Coefficients of an expansion rounded up to whole vectors (PX_FMM_LANES);
 * the binomial tables' rows have this length, zero-padded (fmm_cpu.h). */
static inline int px_fmm_p8(int p) { return (p + PX_FMM_LANES - 1) / PX_FMM_LANES * PX_FMM_LANES; }

/* px_fmm_powers of a real z (the same chains, so the same values): re
 * only. */
static void px_fmm_powers_real(px_real z, int p, px_real *re) {
  px_real z4;
  int k;
  re[0] = PX_R(1.0);
  re[1] = z;
  re[2] = z * z;
  re[3] = re[2] * z;
  z4 = re[2] * re[2];
  for (k = 4; k < p; ++k) re[k] = re[k - 4] * z4;
}

/* Zeros at re[0..off), im[0..off), then the powers z^0 .. z^(n-1): entry
 * off + d holds z^d, 0 for d < 0 (M2M reads u^(k-m) for every k). */
static void px_fmm_powers_padded(px_real zr, px_real zi, int off, int n, px_real *re, px_real *im) {
  int k;
  for (k = 0; k < off; ++k) re[k] = im[k] = PX_R(0.0);
  px_fmm_powers(zr, zi, n, re + off, im + off);
}

/* The core of M2M and L2L, over whole vectors: for k < px_fmm_p8(p),
 *   (ar + i ai)[k] += Σ_{j<p} T[j][k] w[p - 1 - j + k] (cr + i ci)[j],
 * j ascending, T's rows px_fmm_p8(p) long (zero-padded), w (wr + i wi)
 * defined at every index read (zeros where the translation has no term);
 * ar, ai hold NV vectors (all of them read and written). */
static void px_fmm_translate(int p, const px_real *T, const px_real *wr, const px_real *wi,
                             const px_real *cr, const px_real *ci, px_real *ar, px_real *ai) {
  enum { L = PX_FMM_LANES, NV = (PX_FMM_MAX_ORDER + PX_FMM_LANES - 1) / PX_FMM_LANES };
  const int p8 = px_fmm_p8(p), nv = p8 / L;
  px_fmm_vec vr[NV], vi[NV];
  int j, v;
  for (v = 0; v < nv; ++v) {
    PX_FMM_VLOAD(vr[v], ar + v * L);
    PX_FMM_VLOAD(vi[v], ai + v * L);
  }
  for (j = 0; j < p; ++j) {
    const px_real br = cr[j], bi = ci[j];
    const px_real *Tj = T + (size_t)j * (size_t)p8;
    const px_real *wr0 = wr + (p - 1 - j), *wi0 = wi + (p - 1 - j);
    for (v = 0; v < nv; ++v) {
      px_fmm_vec bk, tr, ti;
      PX_FMM_VLOAD(bk, Tj + v * L);
      PX_FMM_VLOAD(tr, wr0 + v * L);
      PX_FMM_VLOAD(ti, wi0 + v * L);
      tr *= bk;
      ti *= bk;
      vr[v] += tr * br - ti * bi;
      vi[v] += tr * bi + ti * br;
    }
  }
  for (v = 0; v < nv; ++v) {
    memcpy(ar + v * L, &vr[v], sizeof vr[v]);
    memcpy(ai + v * L, &vi[v], sizeof vi[v]);
  }
}

/* M2M: add the multipole of child cc to the parent's (cp):
 * ã'_k += Σ_{m<=k} C(k, m) u^{k−m} (σ^m ã_m), summed m by m over all k
 * in whole vectors (R->Bt[m][k] = C(k, m), 0 for k < m, and u^(k−m) read
 * as 0 there: each ã'_k gets the terms m <= k in ascending m, as a loop
 * over k >= m gives them, and exact zeros for m > k). */
static void px_fmm_m2m(const struct px_fmm_run *R, const struct px_fmm_cell *cp,
                       const struct px_fmm_cell *cc, const px_real *cre, const px_real *cim,
                       px_real *pre, px_real *pim) {
  enum { L = PX_FMM_LANES, NV = (PX_FMM_MAX_ORDER + PX_FMM_LANES - 1) / PX_FMM_LANES };
  const int p = R->p, p8 = px_fmm_p8(p);
  /* u^d at index p - 1 + d, d in [-(p - 1), p8) */
  px_real ur[2 * PX_FMM_MAX_ORDER + PX_FMM_LANES], ui[2 * PX_FMM_MAX_ORDER + PX_FMM_LANES];
  px_real sr[PX_FMM_MAX_ORDER], br[PX_FMM_MAX_ORDER], bi[PX_FMM_MAX_ORDER];
  px_real ar[NV * L], ai[NV * L];
  int k;
  px_fmm_powers_padded((px_real)((cc->cx - cp->cx) / cp->r), (px_real)((cc->cy - cp->cy) / cp->r),
                       p - 1, p8, ur, ui);
  px_fmm_powers_real((px_real)(cc->r / cp->r), p, sr);
  for (k = 0; k < p; ++k) {
    br[k] = sr[k] * cre[k];
    bi[k] = sr[k] * cim[k];
  }
  for (k = 0; k < NV * L; ++k) {
    ar[k] = k < p ? pre[k] : PX_R(0.0);
    ai[k] = k < p ? pim[k] : PX_R(0.0);
  }
  px_fmm_translate(p, R->Bt, ur, ui, br, bi, ar, ai);
  for (k = 0; k < p; ++k) {
    pre[k] = ar[k];
    pim[k] = ai[k];
  }
}

/* L2L: the local expansion of child cc from its parent's (cp):
 * b̃'_m = σ^m Σ_{l>=m} C(l, m) u^{l−m} b̃_l, summed l by l over all m in
 * whole vectors (R->B[l][m] = C(l, m), 0 for m > l, and u^(l−m) read as 0
 * there; as in px_fmm_m2m). */
static void px_fmm_l2l(const struct px_fmm_run *R, const struct px_fmm_cell *cp,
                       const struct px_fmm_cell *cc, const px_real *pre, const px_real *pim,
                       px_real *cre, px_real *cim) {
  enum { L = PX_FMM_LANES, NV = (PX_FMM_MAX_ORDER + PX_FMM_LANES - 1) / PX_FMM_LANES };
  const int p = R->p, p8 = px_fmm_p8(p);
  /* u^d at index p - 1 - d (reversed), d in (-p8, p - 1]: zeros after */
  px_real ur[PX_FMM_MAX_ORDER], ui[PX_FMM_MAX_ORDER];
  px_real wr[2 * PX_FMM_MAX_ORDER + PX_FMM_LANES], wi[2 * PX_FMM_MAX_ORDER + PX_FMM_LANES];
  px_real sr[PX_FMM_MAX_ORDER];
  px_real ar[NV * L], ai[NV * L];
  int m;
  px_fmm_powers((px_real)((cc->cx - cp->cx) / cp->r), (px_real)((cc->cy - cp->cy) / cp->r), p, ur,
                ui);
  px_fmm_powers_real((px_real)(cc->r / cp->r), p, sr);
  for (m = 0; m < p; ++m) {
    wr[m] = ur[p - 1 - m];
    wi[m] = ui[p - 1 - m];
  }
  for (m = p; m < p + p8; ++m) wr[m] = wi[m] = PX_R(0.0);
  for (m = 0; m < NV * L; ++m) ar[m] = ai[m] = PX_R(0.0);
  px_fmm_translate(p, R->B, wr, wi, pre, pim, ar, ai);
  for (m = 0; m < p; ++m) {
    cre[m] = ar[m] * sr[m];
    cim[m] = ai[m] * sr[m];
  }
}

/* P2L: add the sources [b, e) to the first q terms of the local expansion
 * of target cell ct. */
static void px_fmm_p2l(const struct px_fmm_run *R, size_t b, size_t e, const struct px_fmm_cell *ct,
                       int q, px_real *lre, px_real *lim) {
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
 * Horner in w = (z − c)/r, PX_FMM_GROUP targets at a time in registers
 * (px_fmm_p2m); each target's operations are those of a scalar loop. */
static void px_fmm_l2p(const struct px_fmm_run *R, const struct px_fmm_cell *ct, const px_real *lre,
                       const px_real *lim) {
  enum { L = PX_FMM_LANES, NB = PX_FMM_BLOCKS, G = PX_FMM_GROUP };
  const int p = R->p;
  const size_t b = ct->begin, e = ct->end;
  const px_real cx = (px_real)ct->cx, cy = (px_real)ct->cy, ir = (px_real)(1.0 / ct->r);
  px_real wr[G], wi[G], ur[G], ui[G];
  size_t i0;
  for (i0 = b; i0 < e; i0 += G) {
    const size_t m = e - i0 < G ? e - i0 : G;
    const px_real *tx = R->tx + i0, *ty = R->ty + i0;
    px_real *U = R->U + i0, *V = R->V + i0;
    px_fmm_vec vwr[NB], vwi[NB], ar[NB], ai[NB];
    size_t i;
    int l, q;
#pragma omp simd
    for (i = 0; i < m; ++i) {
      wr[i] = (tx[i] - cx) * ir;
      wi[i] = (ty[i] - cy) * ir;
    }
    for (i = m; i < G; ++i) wr[i] = wi[i] = PX_R(0.0);
    for (q = 0; q < NB; ++q) {
      PX_FMM_VLOAD(vwr[q], wr + q * L);
      PX_FMM_VLOAD(vwi[q], wi + q * L);
      ar[q] = (px_fmm_vec){0} + lre[p - 1];
      ai[q] = (px_fmm_vec){0} + lim[p - 1];
    }
    for (l = p - 2; l >= 0; --l) {
      const px_real br = lre[l], bi = lim[l];
      for (q = 0; q < NB; ++q) {
        const px_fmm_vec t = ar[q] * vwr[q] - ai[q] * vwi[q] + br;
        ai[q] = ar[q] * vwi[q] + ai[q] * vwr[q] + bi;
        ar[q] = t;
      }
    }
    for (q = 0; q < NB; ++q) {
      memcpy(ur + q * L, &ai[q], sizeof ai[q]);
      memcpy(ui + q * L, &ar[q], sizeof ar[q]);
    }
    for (i = 0; i < m; ++i) {
      U[i] = ur[i];
      V[i] = ui[i];
    }
  }
}

/* M2P: add the first q terms of the multipole of source cell cs at the
 * targets [b, e). */
static void px_fmm_m2p(const struct px_fmm_run *R, size_t b, size_t e, const struct px_fmm_cell *cs,
                       int q, const px_real *mre, const px_real *mim) {
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
static size_t px_fmm_m2l_scratch(int p) { return (size_t)p * 6 * PX_FMM_VW; }

/* Y = T X for one block: X, Y are q × LD (LD = 2 vectors), T has row stride
 * pt. Register-blocked: 4 rows × 2 vectors of accumulators. fma() is an
 * exact fused operation, so the result does not depend on the compiler
 * (-ffp-contract=off holds everywhere else). */
static void px_fmm_gemm(int q, int pt, const px_real *T, const px_real *X, px_real *Y) {
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
static void px_fmm_m2l_block(const struct px_fmm_run *R, const struct px_fmm_cell *ct,
                             const uint32_t *src, int m, int q, px_real *X, px_real *Y, px_real *Ar,
                             px_real *Ai) {
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
  px_fmm_gemm(q, R->p, R->Tm, X, Y);
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
static void px_fmm_p2p(const struct px_fmm_run *R, size_t b, size_t e, const px_real *gx,
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
