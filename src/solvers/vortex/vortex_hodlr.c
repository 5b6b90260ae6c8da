/* The generation matrix's inverse compressed for the cpu solve (see
 * vortex_panels.h): hierarchically off-diagonal low rank (HODLR).
 *
 * The dense inverse is n^2 doubles that every step's solve reads once: 53 MB
 * at n = 2576, about 1.1 ms of a 27 ms step on two cores, bound by memory
 * bandwidth, and growing as n^2. The inverse of a boundary-integral operator
 * is smooth away from its diagonal: a block coupling two separated stretches
 * of the contour has a low numerical rank. The panels are ordered by a k-d
 * bisection of their midpoints (the longer side of the box halved at the
 * median, down to leaves of at most HX_LEAF), so that each half of a node is
 * a compact piece of the contour. (In contour order, the halves of an airfoil
 * are its upper and lower surfaces, which face each other at the trailing
 * edge: rank 250 at 1e-13. Bisected in space, the largest rank is 37 at
 * n = 2576: 7 MB instead of 53.) Each node's two off-diagonal blocks are
 * stored as U V^T, truncated by a column-pivoted QR where the Frobenius norm
 * of what is left falls below HX_TOL times the largest entry of the inverse;
 * the leaves' blocks and the rows and columns of the bodies' circulation
 * unknowns stay dense, and so does a node of at most HX_DENSE_MAX panels
 * whose blocks need more than a third of its rank (the last few panels of a
 * sharp trailing edge, where the two surfaces touch). At the start the product is checked against
 * the dense one (random vectors, relative error at most HX_CHECK, else the dense product is used)
 * and the compressed copy is kept only where it is at most half the dense size.
 *
 * The product: the n entries of x in tree order, the V^T x of every block
 * (one loop over the blocks), then each row as the sum of its leaf's dense
 * row, its ancestors' U rows and its bodies' columns, in that order on any
 * number of threads: the same bits whatever the threads. Deterministic set
 * up on one thread (no BLAS, no random state but a fixed seed). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "partix/memory.h"
#include "solvers/vortex/vortex_panels.h"

enum { HX_LEAF = 64, HX_DENSE_MAX = 4 * HX_LEAF };
#define HX_TOL 1e-14
#define HX_CHECK 1e-12

/* One off-diagonal block: rows [r0, r0 + nr) by columns [c0, c0 + nc) of the
 * tree order, U (nr x rank, row-major) and V (rank x nc, row-major) at these
 * offsets of data, its V^T x at offset t of the work vector. */
struct hx_block {
  size_t r0, nr, c0, nc, rank, u, v, t;
};

struct px_vortex_hodlr {
  size_t n, ns, nb;    /* panels, unknowns, bodies */
  uint32_t *perm;      /* tree position -> panel */
  struct hx_block *bl; /* blocks */
  size_t nbl, bl_cap;
  size_t nleaf, *la, *lb, *ld; /* leaf ranges and the offsets of their dense blocks */
  size_t *anc, *anc_first;     /* blocks covering each leaf's rows, top down */
  size_t nanc;
  double *data; /* U, V, leaf blocks */
  size_t ndata, data_cap;
  double *bcol; /* the bodies' columns of the inverse, by tree position (n x nb) */
  double *brow; /* the bodies' rows of the inverse (nb x ns, the unknowns' order) */
  double *xp, *t;
  size_t nt;
  double check; /* relative difference to the dense product at the start */
  int over;     /* the copy outgrew half the dense inverse while built */
};

struct hx_key {
  double k;
  uint32_t i;
};

static int hx_key_cmp(const void *a, const void *b) {
  const struct hx_key *p = a, *q = b;
  if (p->k < q->k) return -1;
  if (p->k > q->k) return 1;
  return p->i < q->i ? -1 : (p->i > q->i);
}

/* perm[a, b) ordered by the k-d bisection of the midpoints (mx, my). */
static void hx_order(uint32_t *perm, size_t a, size_t b, const double *mx, const double *my,
                     struct hx_key *tmp) {
  if (b - a <= HX_LEAF) return;
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (size_t q = a; q < b; ++q) {
    double x = mx[perm[q]], y = my[perm[q]];
    x0 = x < x0 ? x : x0;
    x1 = x > x1 ? x : x1;
    y0 = y < y0 ? y : y0;
    y1 = y > y1 ? y : y1;
  }
  const int ax = (y1 - y0) > (x1 - x0);
  for (size_t q = a; q < b; ++q) {
    tmp[q - a].i = perm[q];
    tmp[q - a].k = ax ? my[perm[q]] : mx[perm[q]];
  }
  qsort(tmp, b - a, sizeof *tmp, hx_key_cmp);
  for (size_t q = a; q < b; ++q) perm[q] = tmp[q - a].i;
  const size_t m = a + (b - a) / 2;
  hx_order(perm, a, m, mx, my, tmp);
  hx_order(perm, m, b, mx, my, tmp);
}

/* count more entries of data at *off; NULL when out of memory, or (h->over
 * set) when the copy would outgrow its limit: half the dense inverse. */
static double *hx_take(struct px_context *ctx, struct px_vortex_hodlr *h, size_t count,
                       size_t *off) {
  if (h->ndata + count > h->ns * h->ns / 2) {
    h->over = 1;
    return NULL;
  }
  if (h->ndata + count > h->data_cap) {
    size_t cap = h->data_cap * 2 > h->ndata + count ? h->data_cap * 2 : h->ndata + count;
    double *d = px_mem_realloc(ctx, "vortex.matrix", h->data, cap * sizeof(double));
    if (!d) return NULL;
    h->data = d;
    h->data_cap = cap;
  }
  *off = h->ndata;
  h->ndata += count;
  return h->data + *off;
}

/* Block rows r0.., columns c0.. (tree order) of the inverse as U V^T within
 * tol (Frobenius): a column-pivoted QR with two Gram-Schmidt passes,
 * stopped where the residual's norm falls below tol. W: nr x nc scratch,
 * Q: nr x rmax, nrm: nc. Returns 0 when rmax columns do not suffice. */
static int hx_compress(struct px_context *ctx, struct px_vortex_hodlr *h, const double *ainv,
                       size_t r0, size_t nr, size_t c0, size_t nc, double tol, size_t rmax,
                       double *W, double *Q, double *nrm) {
  const size_t ns = h->ns;
  const uint32_t *perm = h->perm;
  for (size_t j = 0; j < nc; ++j) {
    double s = 0.0;
    for (size_t i = 0; i < nr; ++i) {
      double v = ainv[(size_t)perm[r0 + i] * ns + perm[c0 + j]];
      W[j * nr + i] = v;
      s += v * v;
    }
    nrm[j] = s;
  }
  size_t r = 0;
  for (;;) {
    double tail = 0.0, best = -1.0;
    size_t jb = 0;
    for (size_t j = 0; j < nc; ++j) {
      tail += nrm[j];
      if (nrm[j] > best) {
        best = nrm[j];
        jb = j;
      }
    }
    if (tail <= tol * tol) break;
    if (r == rmax) return 0;
    double *q = Q + r * nr;
    memcpy(q, W + jb * nr, nr * sizeof(double));
    for (int pass = 0; pass < 2; ++pass)
      for (size_t k = 0; k < r; ++k) {
        const double *qk = Q + k * nr;
        double c = 0.0;
#pragma omp simd reduction(+ : c)
        for (size_t i = 0; i < nr; ++i) c += qk[i] * q[i];
#pragma omp simd
        for (size_t i = 0; i < nr; ++i) q[i] -= c * qk[i];
      }
    double qn = 0.0;
#pragma omp simd reduction(+ : qn)
    for (size_t i = 0; i < nr; ++i) qn += q[i] * q[i];
    if (!(qn > 0.0)) return 0;
    qn = 1.0 / sqrt(qn);
    for (size_t i = 0; i < nr; ++i) q[i] *= qn;
    for (size_t j = 0; j < nc; ++j) {
      double *w = W + j * nr, c = 0.0, s = 0.0;
#pragma omp simd reduction(+ : c)
      for (size_t i = 0; i < nr; ++i) c += q[i] * w[i];
#pragma omp simd reduction(+ : s)
      for (size_t i = 0; i < nr; ++i) {
        w[i] -= c * q[i];
        s += w[i] * w[i];
      }
      nrm[j] = s;
    }
    ++r;
  }
  struct hx_block b = {r0, nr, c0, nc, r, 0, 0, h->nt};
  double *u = hx_take(ctx, h, nr * r, &b.u), *v;
  if (!u) return h->over ? 0 : -1;
  v = hx_take(ctx, h, r * nc, &b.v);
  if (!v) return h->over ? 0 : -1;
  u = h->data + b.u;
  for (size_t i = 0; i < nr; ++i)
    for (size_t k = 0; k < r; ++k) u[i * r + k] = Q[k * nr + i];
  /* V = Q^T B from the block itself, a column at a time into W (free now:
   * contiguous reads; each sum in ascending rows, not reassociated) */
  for (size_t j = 0; j < nc; ++j) {
    for (size_t i = 0; i < nr; ++i) W[i] = ainv[(size_t)perm[r0 + i] * ns + perm[c0 + j]];
    for (size_t k = 0; k < r; ++k) {
      const double *qk = Q + k * nr;
      double s = 0.0;
      for (size_t i = 0; i < nr; ++i) s += qk[i] * W[i];
      v[k * nc + j] = s;
    }
  }
  if (h->nbl == h->bl_cap) {
    size_t cap = h->bl_cap ? 2 * h->bl_cap : 64;
    struct hx_block *nb = px_mem_realloc(ctx, "vortex.matrix", h->bl, cap * sizeof *nb);
    if (!nb) return -1;
    h->bl = nb;
    h->bl_cap = cap;
  }
  h->bl[h->nbl++] = b;
  h->nt += r;
  return 1;
}

struct hx_build {
  struct px_context *ctx;
  struct px_vortex_hodlr *h;
  const double *ainv;
  double tol, *W, *Q, *nrm;
  size_t stack[64], depth; /* blocks covering the current range */
  size_t *leaf_anc;        /* per leaf: depth entries, appended */
  size_t nanc, anc_cap;
};

/* Node [a, b): a leaf's dense block, or its two off-diagonal blocks and its
 * children. 1: done, 0: a block would not compress, -1: out of memory. */
static int hx_node(struct hx_build *B, size_t a, size_t b) {
  struct px_vortex_hodlr *h = B->h;
  const size_t ns = h->ns;
  int dense = b - a <= HX_LEAF;
  if (!dense) {
    const size_t m = a + (b - a) / 2;
    const size_t rmax = (b - m) / 3, nbl = h->nbl, ndata = h->ndata, nt = h->nt;
    int r = hx_compress(B->ctx, h, B->ainv, a, m - a, m, b - m, B->tol, rmax, B->W, B->Q, B->nrm);
    if (r == 1)
      r = hx_compress(B->ctx, h, B->ainv, m, b - m, a, m - a, B->tol, rmax, B->W, B->Q, B->nrm);
    if (r == -1) return r;
    if (r == 0 || B->depth == 64) {
      /* a node whose halves interact at full rank (near a sharp trailing
       * edge): a dense leaf where small, else no compressed copy */
      if (b - a > HX_DENSE_MAX || h->over) return 0;
      h->nbl = nbl;
      h->ndata = ndata;
      h->nt = nt;
      dense = 1;
    } else {
      const size_t lower = h->nbl - 1; /* rows [m, b); upper: rows [a, m) */
      B->stack[B->depth++] = lower - 1;
      r = hx_node(B, a, m);
      B->depth--;
      if (r != 1) return r;
      B->stack[B->depth++] = lower;
      r = hx_node(B, m, b);
      B->depth--;
      return r;
    }
  }
  {
    size_t off, k = h->nleaf++;
    double *d = hx_take(B->ctx, h, (b - a) * (b - a), &off);
    if (!d) return h->over ? 0 : -1;
    for (size_t i = a; i < b; ++i)
      for (size_t j = a; j < b; ++j)
        d[(i - a) * (b - a) + (j - a)] = B->ainv[(size_t)h->perm[i] * ns + h->perm[j]];
    h->la[k] = a;
    h->lb[k] = b;
    h->ld[k] = off;
    h->anc_first[k] = B->nanc;
    if (B->nanc + B->depth > B->anc_cap) {
      size_t cap = 2 * (B->nanc + B->depth) + 64;
      size_t *p = px_mem_realloc(B->ctx, "vortex.matrix", B->leaf_anc, cap * sizeof *p);
      if (!p) return -1;
      B->leaf_anc = p;
      B->anc_cap = cap;
    }
    memcpy(B->leaf_anc + B->nanc, B->stack, B->depth * sizeof(size_t));
    B->nanc += B->depth;
    h->anc_first[k + 1] = B->nanc;
    return 1;
  }
}

void px_vortex_hodlr_free(struct px_context *ctx, struct px_vortex_hodlr *h) {
  if (!h) return;
  px_mem_free(ctx, h->perm);
  px_mem_free(ctx, h->bl);
  px_mem_free(ctx, h->la);
  px_mem_free(ctx, h->anc);
  px_mem_free(ctx, h->data);
  px_mem_free(ctx, h->bcol);
  px_mem_free(ctx, h->brow);
  px_mem_free(ctx, h->xp);
  px_mem_free(ctx, h);
}

size_t px_vortex_hodlr_bytes(const struct px_vortex_hodlr *h) {
  if (!h) return 0;
  return (h->ndata + 2 * h->n * h->nb + h->nb * h->nb + h->n + h->nt) * sizeof(double) +
         h->nbl * sizeof(struct hx_block) + 4 * h->nleaf * sizeof(size_t) +
         h->nanc * sizeof(size_t) + h->n * sizeof(uint32_t);
}

void px_vortex_hodlr_apply(const struct px_vortex_hodlr *h, const double *x, double *y,
                           int threads) {
  const size_t n = h->n, nb = h->nb;
  double *restrict xp = h->xp, *restrict t = h->t;
  const double *data = h->data;
#pragma omp parallel num_threads(threads > 0 ? threads : 1)
  {
#pragma omp for schedule(static)
    for (long li = 0; li < (long)n; ++li) xp[li] = x[h->perm[li]];
#pragma omp for schedule(dynamic, 1)
    for (long lb = 0; lb < (long)h->nbl; ++lb) {
      const struct hx_block *b = &h->bl[lb];
      const double *xc = xp + b->c0;
      for (size_t k = 0; k < b->rank; ++k) {
        const double *v = data + b->v + k * b->nc;
        double s = 0.0;
#pragma omp simd reduction(+ : s)
        for (size_t j = 0; j < b->nc; ++j) s += v[j] * xc[j];
        t[b->t + k] = s;
      }
    }
#pragma omp for schedule(dynamic, 1)
    for (long ll = 0; ll < (long)h->nleaf; ++ll) {
      const size_t a = h->la[ll], e = h->lb[ll], w = e - a;
      const double *d = data + h->ld[ll];
      for (size_t i = a; i < e; ++i) {
        const double *row = d + (i - a) * w;
        double s = 0.0;
#pragma omp simd reduction(+ : s)
        for (size_t j = 0; j < w; ++j) s += row[j] * xp[a + j];
        for (size_t q = h->anc_first[ll]; q < h->anc_first[ll + 1]; ++q) {
          const struct hx_block *b = &h->bl[h->anc[q]];
          const double *u = data + b->u + (i - b->r0) * b->rank, *tb = t + b->t;
          double s2 = 0.0;
#pragma omp simd reduction(+ : s2)
          for (size_t k = 0; k < b->rank; ++k) s2 += u[k] * tb[k];
          s += s2;
        }
        for (size_t c = 0; c < nb; ++c) s += h->bcol[i * nb + c] * x[n + c];
        y[h->perm[i]] = s;
      }
    }
#pragma omp for schedule(static)
    for (long lc = 0; lc < (long)nb; ++lc) {
      const double *row = h->brow + (size_t)lc * h->ns;
      double s = 0.0;
#pragma omp simd reduction(+ : s)
      for (size_t j = 0; j < h->ns; ++j) s += row[j] * x[j];
      y[n + (size_t)lc] = s;
    }
  }
}

double px_vortex_hodlr_check(const struct px_vortex_hodlr *h) { return h ? h->check : 0.0; }

enum px_status px_vortex_hodlr_build(struct px_context *ctx, const struct px_vortex_panels *p,
                                     struct px_vortex_hodlr **out) {
  *out = NULL;
  const size_t n = p->n, ns = p->nsys, nb = ns - n;
  if (!p->ainv || n <= 2 * HX_LEAF) return PX_STATUS_OK;
  struct px_vortex_hodlr *h = px_mem_calloc(ctx, "vortex.matrix", 1, sizeof *h);
  if (!h) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (compressed panel matrix)");
  h->n = n;
  h->ns = ns;
  h->nb = nb;
  const size_t maxleaf = 2 * (n / HX_LEAF + 1) + 2;
  h->perm = px_mem_alloc(ctx, "vortex.matrix", n * sizeof(uint32_t));
  h->la = px_mem_alloc(ctx, "vortex.matrix", (4 * maxleaf + 1) * sizeof(size_t));
  h->bcol = px_mem_alloc(ctx, "vortex.matrix", (n * nb + 1) * sizeof(double));
  h->brow = px_mem_alloc(ctx, "vortex.matrix", (nb * ns + 1) * sizeof(double));
  double *mx = px_mem_alloc(ctx, "vortex.work", 2 * n * sizeof(double));
  struct hx_key *tmp = px_mem_alloc(ctx, "vortex.work", n * sizeof *tmp);
  struct hx_build B = {ctx, h, p->ainv, 0.0, NULL, NULL, NULL, {0}, 0, NULL, 0, 0};
  const size_t half = n - n / 2;
  B.W = px_mem_alloc(ctx, "vortex.work", half * half * sizeof(double));
  B.Q = px_mem_alloc(ctx, "vortex.work", half * (half / 3 + 1) * sizeof(double));
  B.nrm = px_mem_alloc(ctx, "vortex.work", half * sizeof(double));
  int r = -1;
  if (h->perm && h->la && h->bcol && h->brow && mx && tmp && B.W && B.Q && B.nrm) {
    h->lb = h->la + maxleaf;
    h->ld = h->lb + maxleaf;
    h->anc_first = h->ld + maxleaf;
    double *my = mx + n;
    for (size_t k = 0; k < n; ++k) {
      h->perm[k] = (uint32_t)k;
      mx[k] = 0.5 * (p->x0[k] + p->x1[k]);
      my[k] = 0.5 * (p->y0[k] + p->y1[k]);
    }
    hx_order(h->perm, 0, n, mx, my, tmp);
    double amax = 0.0;
    for (size_t q = 0; q < ns * ns; ++q) amax = fabs(p->ainv[q]) > amax ? fabs(p->ainv[q]) : amax;
    B.tol = HX_TOL * amax;
    r = hx_node(&B, 0, n);
  }
  px_mem_free(ctx, mx);
  px_mem_free(ctx, tmp);
  px_mem_free(ctx, B.W);
  px_mem_free(ctx, B.Q);
  px_mem_free(ctx, B.nrm);
  h->anc = B.leaf_anc;
  h->nanc = B.nanc;
  if (r == 1) {
    for (size_t i = 0; i < n; ++i)
      for (size_t c = 0; c < nb; ++c)
        h->bcol[i * nb + c] = p->ainv[(size_t)h->perm[i] * ns + n + c];
    memcpy(h->brow, p->ainv + n * ns, nb * ns * sizeof(double));
    h->xp = px_mem_alloc(ctx, "vortex.matrix", (n + h->nt + 1) * sizeof(double));
    if (!h->xp)
      r = -1;
    else
      h->t = h->xp + n;
  }
  if (r == 1 && 2 * px_vortex_hodlr_bytes(h) > ns * ns * sizeof(double)) r = 0;
  if (r == 1) {
    /* against the dense product: three vectors of a fixed generator */
    double *x = px_mem_alloc(ctx, "vortex.work", 3 * ns * sizeof(double));
    if (!x) {
      r = -1;
    } else {
      double *yd = x + ns, *yh = yd + ns, err = 0.0, ymax = 0.0;
      unsigned long long sd = 0x9e3779b97f4a7c15ull;
      for (int v = 0; v < 3; ++v) {
        for (size_t i = 0; i < ns; ++i) {
          sd = sd * 6364136223846793005ull + 1442695040888963407ull;
          x[i] = (double)(sd >> 11) * 0x1.0p-53 - 0.5;
        }
        px_vortex_panels_dense_product(p, x, yd, 1);
        px_vortex_hodlr_apply(h, x, yh, 1);
        for (size_t i = 0; i < ns; ++i) {
          err = fmax(err, fabs(yh[i] - yd[i]));
          ymax = fmax(ymax, fabs(yd[i]));
        }
      }
      px_mem_free(ctx, x);
      h->check = ymax > 0.0 ? err / ymax : 0.0;
      if (!(h->check <= HX_CHECK)) r = 0;
    }
  }
  if (r == -1) {
    px_vortex_hodlr_free(ctx, h);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (compressed panel matrix)");
  }
  if (r == 0) {
    px_vortex_hodlr_free(ctx, h);
    return PX_STATUS_OK;
  }
  *out = h;
  return PX_STATUS_OK;
}
