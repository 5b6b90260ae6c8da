/* Panels of all bodies and the vorticity-generation linear system of the
 * vortex solver.
 *
 * Boundary condition (Kuzmina & Marchevsky's "T-scheme": the tangential
 * boundary integral equation satisfied on average over each panel, constant
 * vortex-sheet intensity gamma_k per panel; Kempka, Glass, Peery et al. 1996;
 * Kuzmina, Marchevsky & Moreva, "Vortex sheet intensity computation in
 * incompressible flow simulation around an airfoil by using vortex methods",
 * Math. Models Comput. Simul. 10 (2018) 276-287): the fluid inside a fixed
 * body is at rest, so the inner limit of the tangential velocity vanishes,
 *
 *   V_tau^pv(r) - gamma(r)/2 = 0  on the contour,                        (1)
 *
 * where V^pv = V_inf + V_wake + principal value of the sheet's own field and
 * -gamma/2 is the half jump of the sheet on its inner (left) side. Averaged
 * over panel i:
 *
 *   sum_{k != i} A_ik gamma_k - gamma_i / 2 + R_b = -<(V_inf + V_wake).tau_i>_i,
 *   A_ik = (1/L_i) int_{K_i} int_{K_k} [k x (r - xi)] . tau_i / (2 pi |r - xi|^2) dxi dr,
 *
 * (the straight self panel adds nothing to its own principal value), closed by
 * one circulation equation per body b,
 *
 *   sum_{k in b} gamma_k L_k = Gamma_absorbed_b,                         (2)
 *
 * (zero net vorticity flux from a fixed body: what its wall absorbed in the
 * last step is returned), with Lifanov's regularizing variable R_b making the
 * square system (n + nbody unknowns) uniquely solvable (Lifanov, Singular
 * integral equations and discrete vortices, VSP 1996; R_b ~ 0 at the solution).
 *
 * A_ik is computed in closed form (see px_vortex_panel_coef); the matrix
 * depends only on the shape and is LU-factored once (LAPACKE dgetrf); each step
 * only back-substitutes (dgetrs). */
#ifndef PX_VORTEX_PANELS_H
#define PX_VORTEX_PANELS_H

#include <stddef.h>

#include "partix/context.h"
#include "solvers/vortex/vortex_profile.h"

struct px_vortex_panels {
  size_t n;        /* panels over all bodies */
  size_t nbody;    /* bodies */
  size_t *first;   /* owned: nbody + 1 entries; body b owns panels [first[b], first[b+1]) */
  int *body;       /* owned: body of each panel */
  double *x0, *y0; /* owned: panel start vertex */
  double *x1, *y1; /* owned: panel end vertex */
  double *tx, *ty; /* owned: unit tangent (outward normal = (ty, -tx)) */
  double *len;     /* owned: panel length */
  double *bxmin, *bymin, *bxmax, *bymax; /* owned: bounding box of each body */
  double lmax;                           /* longest panel */
  /* linear system, n + nbody unknowns (gamma_0..gamma_{n-1}, R_0..R_{nbody-1}) */
  size_t nsys;
  /* owned: the inverse of the nsys x nsys matrix, row-major (LU factors,
   * then dgetri), NULL before factoring; xw: nsys reals of the solve's
   * right-hand side */
  double *ainv, *xw;
  struct px_vortex_hodlr *hodlr; /* owned or NULL: the inverse compressed, for the cpu
                                    solve (px_vortex_panels_compress) */
  float *lu_f;                   /* owned or NULL: single-precision factors (precision single) */
  int *ipiv_f;                   /* owned or NULL */
};

/* Panels of the given contours (all checked, counter-clockwise). */
enum px_status px_vortex_panels_build(struct px_context *ctx, const struct px_vortex_contour *c,
                                      size_t nbody, struct px_vortex_panels *out);
void px_vortex_panels_free(struct px_context *ctx, struct px_vortex_panels *p);

/* Assemble the matrix and invert it (double; also LU-factor it in single
 * precision when `single`). */
enum px_status px_vortex_panels_factor(struct px_context *ctx, struct px_vortex_panels *p,
                                       int single);
/* The inverse compressed (vortex_hodlr.c: hierarchically off-diagonal low
 * rank over a k-d order of the panels, within 1e-14 of its largest entry per
 * block, checked against the dense product within 1e-12) into p->hodlr,
 * which px_vortex_panels_solve then uses; left NULL where it would not pay
 * (few panels, or more than half the dense size). For the cpu engine: call
 * after the inverse is final (broadcast over ranks). */
enum px_status px_vortex_panels_compress(struct px_context *ctx, struct px_vortex_panels *p);
struct px_vortex_hodlr;
enum px_status px_vortex_hodlr_build(struct px_context *ctx, const struct px_vortex_panels *p,
                                     struct px_vortex_hodlr **out);
void px_vortex_hodlr_free(struct px_context *ctx, struct px_vortex_hodlr *h);
/* y = A^-1 x (all nsys entries; x and y distinct), each entry summed in the
 * same order whatever the threads. */
void px_vortex_hodlr_apply(const struct px_vortex_hodlr *h, const double *x, double *y,
                           int threads);
size_t px_vortex_hodlr_bytes(const struct px_vortex_hodlr *h);
/* Its relative difference to the dense product, measured when built. */
double px_vortex_hodlr_check(const struct px_vortex_hodlr *h);
/* Pin the BLAS to one thread around a LAPACK call (the answer must not
 * depend on the cores the process may use; vortex_panels.c says why), and
 * restore the setting px_vortex_blas_serial returned. */
int px_vortex_blas_serial(void);
void px_vortex_blas_restore(int before);
/* y = A^-1 x by the dense inverse (nsys entries; x and y distinct), each
 * row's sum in the same order whatever the threads. */
void px_vortex_panels_dense_product(const struct px_vortex_panels *p, const double *x, double *y,
                                    int threads);
/* Solve in place (rhs has nsys entries on entry, the solution on exit):
 * rhs = A^-1 rhs on `threads` threads, each row's product in the same order
 * whatever the threads (p->xw holds the right-hand side meanwhile); _f: by
 * the float LU. */
enum px_status px_vortex_panels_solve(struct px_context *ctx, const struct px_vortex_panels *p,
                                      double *rhs, int threads);
enum px_status px_vortex_panels_solve_f(struct px_context *ctx, const struct px_vortex_panels *p,
                                        float *rhs);

/* A_ik for i != k (closed form; 3-point Gauss in the source panel with the
 * exact target average for well separated pairs). */
double px_vortex_panel_coef(const struct px_vortex_panels *p, size_t i, size_t k);
/* Same between two arbitrary segments (target [a0,a1], source [b0,b1]) whose
 * interiors do not cross: mean over the target of the tangential velocity
 * induced by a unit-intensity sheet on the source. */
double px_vortex_segment_coef(double ax0, double ay0, double ax1, double ay1, double bx0,
                              double by0, double bx1, double by1);
/* Velocity at (x, y) induced by a unit-intensity vortex sheet on the segment
 * (bx0, by0) -> (bx1, by1) (not on the segment itself). */
void px_vortex_segment_velocity(double bx0, double by0, double bx1, double by1, double x, double y,
                                double *u, double *v);
/* Mean over the segment (ax0, ay0) -> (ax1, ay1) of the tangential velocity
 * induced by a point vortex of unit circulation at (x, y): Dtheta / (2 pi L),
 * Dtheta the signed angle the segment subtends at the vortex. */
double px_vortex_point_coef(double ax0, double ay0, double ax1, double ay1, double x, double y);

#endif
