/* Panel geometry and the generation linear system (see vortex_panels.h). */
#include "solvers/vortex/vortex_panels.h"

#include <lapacke.h>
#include <string.h>

#include "partix/memory.h"

#define PX_REAL double
#include "kernels/px_kernel.h"
#include "solvers/vortex/vortex_kernel.h"

/* OpenBLAS (Debian's libblas/liblapack alternative on most machines) picks
 * its thread count from the cores the process may use, and its LU and
 * triangular solves round differently with each count: a run's answer would
 * depend on the machine, on taskset, and on mpirun's binding of each rank
 * to a core. The factorization and the solves therefore run on one BLAS
 * thread (the LU of a few thousand panels is factored once, in well under a
 * second; the solves of a step are O(n^2)), restoring the caller's setting
 * after. Weak: another BLAS has no such function and nothing to pin. */
extern void openblas_set_num_threads(int n) __attribute__((weak));
extern int openblas_get_num_threads(void) __attribute__((weak));

int px_vortex_blas_serial(void) {
  int before = openblas_get_num_threads ? openblas_get_num_threads() : 0;
  if (openblas_set_num_threads && before != 1) openblas_set_num_threads(1);
  return before;
}

void px_vortex_blas_restore(int before) {
  if (openblas_set_num_threads && before > 1) openblas_set_num_threads(before);
}

#define VX_PI 3.14159265358979323846

void px_vortex_panels_free(struct px_context *ctx, struct px_vortex_panels *p) {
  if (!p) return;
  px_mem_free(ctx, p->first);
  px_mem_free(ctx, p->body);
  px_mem_free(ctx, p->x0);
  px_vortex_hodlr_free(ctx, p->hodlr);
  p->hodlr = NULL;
  px_mem_free(ctx, p->ainv);
  px_mem_free(ctx, p->xw);
  px_mem_free(ctx, p->lu_f);
  px_mem_free(ctx, p->ipiv_f);
  px_mem_free(ctx, p->bxmin);
  memset(p, 0, sizeof *p);
}

enum px_status px_vortex_panels_build(struct px_context *ctx, const struct px_vortex_contour *c,
                                      size_t nbody, struct px_vortex_panels *out) {
  memset(out, 0, sizeof *out);
  size_t n = 0;
  for (size_t b = 0; b < nbody; ++b) n += c[b].n;
  out->n = n;
  out->nbody = nbody;
  out->nsys = n + nbody;
  out->first = px_mem_alloc(ctx, "vortex.panels", (nbody + 1) * sizeof(size_t));
  out->body = px_mem_alloc(ctx, "vortex.panels", (n ? n : 1) * sizeof(int));
  out->x0 = px_mem_alloc(ctx, "vortex.panels", 9 * (n ? n : 1) * sizeof(double));
  out->bxmin = px_mem_alloc(ctx, "vortex.panels", 4 * (nbody ? nbody : 1) * sizeof(double));
  if (!out->first || !out->body || !out->x0 || !out->bxmin) {
    px_vortex_panels_free(ctx, out);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for %zu panels", n);
  }
  out->y0 = out->x0 + n;
  out->x1 = out->x0 + 2 * n;
  out->y1 = out->x0 + 3 * n;
  out->tx = out->x0 + 4 * n;
  out->ty = out->x0 + 5 * n;
  out->len = out->x0 + 6 * n;
  out->bymin = out->bxmin + nbody;
  out->bxmax = out->bxmin + 2 * nbody;
  out->bymax = out->bxmin + 3 * nbody;
  size_t k = 0;
  out->lmax = 0.0;
  for (size_t b = 0; b < nbody; ++b) {
    out->first[b] = k;
    out->bxmin[b] = out->bymin[b] = INFINITY;
    out->bxmax[b] = out->bymax[b] = -INFINITY;
    for (size_t j = 0; j < c[b].n; ++j, ++k) {
      size_t j1 = (j + 1) % c[b].n;
      out->body[k] = (int)b;
      out->x0[k] = c[b].x[j];
      out->y0[k] = c[b].y[j];
      out->x1[k] = c[b].x[j1];
      out->y1[k] = c[b].y[j1];
      double dx = out->x1[k] - out->x0[k], dy = out->y1[k] - out->y0[k];
      double l = hypot(dx, dy);
      out->len[k] = l;
      out->tx[k] = dx / l;
      out->ty[k] = dy / l;
      if (l > out->lmax) out->lmax = l;
      out->bxmin[b] = fmin(out->bxmin[b], out->x0[k]);
      out->bymin[b] = fmin(out->bymin[b], out->y0[k]);
      out->bxmax[b] = fmax(out->bxmax[b], out->x0[k]);
      out->bymax[b] = fmax(out->bymax[b], out->y0[k]);
    }
  }
  out->first[nbody] = k;
  return PX_STATUS_OK;
}

double px_vortex_point_coef(double ax0, double ay0, double ax1, double ay1, double x, double y) {
  double sx = ax0 - x, sy = ay0 - y, px = ax1 - x, py = ay1 - y;
  double dth = atan2(sx * py - sy * px, sx * px + sy * py);
  return dth / (2.0 * VX_PI * hypot(ax1 - ax0, ay1 - ay0));
}

void px_vortex_segment_velocity(double bx0, double by0, double bx1, double by1, double x, double y,
                                double *u, double *v) {
  px_real2 r = vx_sheet_velocity(bx0, by0, bx1, by1, x, y);
  *u = r.x;
  *v = r.y;
}

/* Im[w Log w] with the limit 0 at w = 0. */
static double im_wlogw(double a, double b) {
  double r2 = a * a + b * b;
  if (r2 == 0.0) return 0.0;
  return a * atan2(b, a) + 0.5 * b * log(r2);
}

/* Upper side of the cut on the real axis left of the source (x <= 0): Im > 0,
 * or on the axis at Re <= 0, where the principal arguments are +pi. */
static int upper_side(double a, double b) { return b > 0.0 || (b == 0.0 && a <= 0.0); }

/* Closed form of the panel-averaged tangential velocity. In the source frame
 * (w = conj(e_k)(z - z_k0), source on [0, L]) the unit sheet induces the
 * conjugate velocity c(w) = u' - i v' = Log(w / (w - L)) / (2 pi i), and the
 * tangential component along the target direction d = conj(e_k) e_i is
 * Re(c d), so that
 *
 *   A = (1/L_i) Re int_{w0}^{w1} c(w) dw = Im[H(w1) - H(w0)] / (2 pi L_i),
 *   H(w) = w Log w - (w - L) Log(w - L),  H' = Log(w / (w - L)).
 *
 * H is analytic except on the real axis left of L; crossing the part x <= 0
 * it jumps by -+2 pi i L (Log(w - L) jumps there, and so does Log w for x < 0)
 * while the integrand is continuous, so a crossing adds back +-2 pi L to the
 * imaginary part. The source's own interior (0, L) is never crossed (no
 * self-intersection); adjacent panels meet it only at an end. */
static double coef_closed(double ax0, double ay0, double ax1, double ay1, double bx0, double by0,
                          double bx1, double by1) {
  double L = hypot(bx1 - bx0, by1 - by0), Li = hypot(ax1 - ax0, ay1 - ay0);
  double tx = (bx1 - bx0) / L, ty = (by1 - by0) / L;
  double r0x = ax0 - bx0, r0y = ay0 - by0, r1x = ax1 - bx0, r1y = ay1 - by0;
  double a0 = r0x * tx + r0y * ty, b0 = -r0x * ty + r0y * tx;
  double a1 = r1x * tx + r1y * ty, b1 = -r1x * ty + r1y * tx;
  /* a vertex shared with the source gives an exact zero, possibly -0.0, which
   * would put atan2 on the lower side of the cut: x + 0.0 turns -0.0 into +0.0 */
  b0 += 0.0;
  b1 += 0.0;
  double h1 = im_wlogw(a1, b1) - im_wlogw(a1 - L, b1);
  double h0 = im_wlogw(a0, b0) - im_wlogw(a0 - L, b0);
  double im = h1 - h0;
  int s0 = upper_side(a0, b0), s1 = upper_side(a1, b1);
  if (s0 != s1 && !(b0 == 0.0 && b1 == 0.0)) { /* a path along the axis never crosses it */
    int cross;
    if ((a0 == 0.0 && b0 == 0.0) || (a1 == 0.0 && b1 == 0.0))
      cross = 1; /* ends on the source's start vertex, where Log(w - L) has its cut */
    else
      cross = a0 - b0 * (a1 - a0) / (b1 - b0) < 0.0;
    if (cross) im += s0 ? 2.0 * VX_PI * L : -2.0 * VX_PI * L;
  }
  return im / (2.0 * VX_PI * Li);
}

double px_vortex_segment_coef(double ax0, double ay0, double ax1, double ay1, double bx0,
                              double by0, double bx1, double by1) {
  double Li = hypot(ax1 - ax0, ay1 - ay0), Lk = hypot(bx1 - bx0, by1 - by0);
  double dx = 0.5 * (ax0 + ax1 - bx0 - bx1), dy = 0.5 * (ay0 + ay1 - by0 - by1);
  double d = hypot(dx, dy);
  if (d > 8.0 * (Li + Lk)) {
    /* well separated: 3-point Gauss-Legendre over the source, each node a
     * point vortex of circulation w_q L_k whose target mean is exact */
    static const double xg[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
    static const double wg[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
    double s = 0.0;
    for (int q = 0; q < 3; ++q) {
      double f = 0.5 * (1.0 + xg[q]);
      double x = bx0 + f * (bx1 - bx0), y = by0 + f * (by1 - by0);
      s += wg[q] * px_vortex_point_coef(ax0, ay0, ax1, ay1, x, y);
    }
    return s * Lk;
  }
  return coef_closed(ax0, ay0, ax1, ay1, bx0, by0, bx1, by1);
}

double px_vortex_panel_coef(const struct px_vortex_panels *p, size_t i, size_t k) {
  return px_vortex_segment_coef(p->x0[i], p->y0[i], p->x1[i], p->y1[i], p->x0[k], p->y0[k],
                                p->x1[k], p->y1[k]);
}

enum px_status px_vortex_panels_factor(struct px_context *ctx, struct px_vortex_panels *p,
                                       int single) {
  size_t ns = p->nsys, n = p->n;
  px_vortex_hodlr_free(ctx, p->hodlr); /* of the inverse before */
  p->hodlr = NULL;
  px_mem_free(ctx, p->ainv);
  px_mem_free(ctx, p->xw);
  p->ainv = px_mem_alloc(ctx, "vortex.matrix", ns * ns * sizeof(double));
  p->xw = px_mem_alloc(ctx, "vortex.matrix", ns * sizeof(double));
  int *ipiv = px_mem_alloc(ctx, "vortex.matrix", ns * sizeof(int));
  if (!p->ainv || !p->xw || !ipiv) {
    px_mem_free(ctx, ipiv);
    return px_context_fail(ctx, PX_STATUS_NOMEM,
                           "out of memory for the %zu x %zu panel matrix (%.1f MB)", ns, ns,
                           8.0 * (double)ns * (double)ns / 1e6);
  }
  /* column-major (LAPACK's own layout); column k holds the influence of
   * unknown k on every equation */
  double *A = p->ainv;
#pragma omp parallel for schedule(dynamic, 16)
  for (long lk = 0; lk < (long)n; ++lk) {
    size_t k = (size_t)lk;
    double *col = A + k * ns;
    for (size_t i = 0; i < n; ++i) col[i] = (k == i) ? -0.5 : px_vortex_panel_coef(p, i, k);
    for (size_t b = 0; b < p->nbody; ++b) col[n + b] = ((size_t)p->body[k] == b) ? p->len[k] : 0.0;
  }
  for (size_t b = 0; b < p->nbody; ++b) {
    double *col = A + (n + b) * ns;
    memset(col, 0, ns * sizeof(double));
    for (size_t i = p->first[b]; i < p->first[b + 1]; ++i) col[i] = 1.0;
  }
  if (single) {
    px_mem_free(ctx, p->lu_f);
    px_mem_free(ctx, p->ipiv_f);
    p->lu_f = px_mem_alloc(ctx, "vortex.matrix", ns * ns * sizeof(float));
    p->ipiv_f = px_mem_alloc(ctx, "vortex.matrix", ns * sizeof(int));
    if (!p->lu_f || !p->ipiv_f) {
      px_mem_free(ctx, ipiv);
      return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for the float panel matrix");
    }
    for (size_t q = 0; q < ns * ns; ++q) p->lu_f[q] = (float)A[q];
    int blas = px_vortex_blas_serial();
    lapack_int info = LAPACKE_sgetrf(LAPACK_COL_MAJOR, (lapack_int)ns, (lapack_int)ns, p->lu_f,
                                     (lapack_int)ns, p->ipiv_f);
    px_vortex_blas_restore(blas);
    if (info != 0) {
      px_mem_free(ctx, ipiv);
      return px_context_fail(ctx, PX_STATUS_NUMERIC,
                             "the panel matrix is singular in single precision (sgetrf info %d): "
                             "check the profile for nearly touching panels",
                             (int)info);
    }
  }
  /* The inverse, not the LU factors: a step's solve is then one product
   * that all threads share by rows (two triangular solves read the same
   * n^2 reals on one thread: 2.4 ms of a 38 ms step at n = 2576 on two
   * cores, and the same on 16). Its rounding error is of the order of the
   * solve's (the matrix is well conditioned: panels at least a length apart
   * are off the diagonal's -1/2 by less than 1/(2 pi)); the OpenCL engine
   * multiplies by the same matrix. */
  int blas = px_vortex_blas_serial();
  const char *what = "dgetrf";
  lapack_int info =
      LAPACKE_dgetrf(LAPACK_COL_MAJOR, (lapack_int)ns, (lapack_int)ns, A, (lapack_int)ns, ipiv);
  if (info == 0) {
    what = "dgetri";
    info = LAPACKE_dgetri(LAPACK_COL_MAJOR, (lapack_int)ns, A, (lapack_int)ns, ipiv);
  }
  px_vortex_blas_restore(blas);
  px_mem_free(ctx, ipiv);
  if (info != 0)
    return px_context_fail(ctx, PX_STATUS_NUMERIC,
                           "the panel matrix is singular (%s info %d): check the profile for "
                           "nearly touching panels",
                           what, (int)info);
  /* column-major to row-major: row i is then contiguous for its product */
  for (size_t i = 0; i < ns; ++i)
    for (size_t j = i + 1; j < ns; ++j) {
      double t = A[i * ns + j];
      A[i * ns + j] = A[j * ns + i];
      A[j * ns + i] = t;
    }
  return PX_STATUS_OK;
}

void px_vortex_panels_dense_product(const struct px_vortex_panels *p, const double *x, double *y,
                                    int threads) {
  const size_t ns = p->nsys;
  const double *restrict b = x;
#pragma omp parallel for num_threads(threads > 0 ? threads : 1) schedule(static, 32)
  for (long li = 0; li < (long)ns; ++li) {
    const double *restrict a = p->ainv + (size_t)li * ns;
    double s = 0.0;
#pragma omp simd reduction(+ : s)
    for (size_t j = 0; j < ns; ++j) s += a[j] * b[j];
    y[li] = s;
  }
}

enum px_status px_vortex_panels_solve(struct px_context *ctx, const struct px_vortex_panels *p,
                                      double *rhs, int threads) {
  if (!p->ainv) return px_context_fail(ctx, PX_STATUS_INTERNAL, "panel matrix not factored");
  memcpy(p->xw, rhs, p->nsys * sizeof(double));
  if (p->hodlr)
    px_vortex_hodlr_apply(p->hodlr, p->xw, rhs, threads);
  else
    px_vortex_panels_dense_product(p, p->xw, rhs, threads);
  return PX_STATUS_OK;
}

enum px_status px_vortex_panels_solve_f(struct px_context *ctx, const struct px_vortex_panels *p,
                                        float *rhs) {
  if (!p->lu_f)
    return px_context_fail(ctx, PX_STATUS_INTERNAL, "single-precision panel matrix not factored");
  int blas = px_vortex_blas_serial();
  lapack_int info = LAPACKE_sgetrs_work(LAPACK_COL_MAJOR, 'N', (lapack_int)p->nsys, 1, p->lu_f,
                                        (lapack_int)p->nsys, p->ipiv_f, rhs, (lapack_int)p->nsys);
  px_vortex_blas_restore(blas);
  if (info != 0)
    return px_context_fail(ctx, PX_STATUS_NUMERIC, "sgetrs failed (info %d)", (int)info);
  return PX_STATUS_OK;
}

enum px_status px_vortex_panels_compress(struct px_context *ctx, struct px_vortex_panels *p) {
  px_vortex_hodlr_free(ctx, p->hodlr);
  p->hodlr = NULL;
  return px_vortex_hodlr_build(ctx, p, &p->hodlr);
}
