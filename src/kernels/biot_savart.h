/* 2D Biot–Savart law for smoothed point vortices: the convective velocity of
 * the vortex method, written once for the cpu loops and the OpenCL programs.
 *
 * Velocity at r induced by a vortex of circulation Γ_j at r_j (d = r − r_j):
 *
 *   u(r) = Γ_j / (2π) · k × d / max(|d|², ε²)
 *        = Γ_j / (2π max(|d|², ε²)) · (−d_y, d_x)                       (1)
 *
 * The cutoff ε (the vortex core radius) turns the singular 1/|d| of a point
 * vortex into solid-body rotation inside |d| < ε (a Rankine core); outside
 * it the field is exactly that of a point vortex (spec vortex.md, step 2;
 * VM2D's boundDenom(r2, eps2) = max(r2, eps2)). A vortex on top of the
 * target (d = 0, e.g. the self term when sources are the targets) adds
 * exactly zero because ε > 0.
 *
 * Written around the geometric factor K(d) = k × d / max(|d|², ε²):
 *   term_ij = Γ_j K(r_i − r_j)   and   u_i = PX_BIOT_SAVART_SCALE · Σ_j term_ij,
 * the 1/(2π) applied once per target. K is odd, K(−d) = −K(d), so a pair
 * evaluated once serves both of its vortices (the cpu self-interaction sum
 * uses that to halve the divisions). */
#ifndef PX_KERNELS_BIOT_SAVART_H
#define PX_KERNELS_BIOT_SAVART_H

#include "kernels/px_kernel.h"

/* 1/(2π) */
#define PX_BIOT_SAVART_SCALE PX_R(0.15915494309189533577)

/* Γ K(d) = Γ k × d / max(|d|², ε²), the un-normalised contribution of a
 * vortex of circulation Γ, with d = (dx, dy) = r − r_j and eps2 = ε² > 0.
 * Computed as w = Γ / max(...) times (−d_y, d_x): one division and two
 * multiplications (scaling K by Γ afterwards costs 10-20% more in the
 * division-bound cpu loop, measured). */
PX_FN px_real2 px_biot_savart_term(px_real dx, px_real dy, px_real gamma, px_real eps2) {
  const px_real w = gamma / px_maxr(dx * dx + dy * dy, eps2);
  return px_v2(-dy * w, dx * w);
}

/* K(d) itself: the term of a unit circulation. */
PX_FN px_real2 px_biot_savart_kernel(px_real dx, px_real dy, px_real eps2) {
  return px_biot_savart_term(dx, dy, PX_R(1.0), eps2);
}

/* Velocity (1) at r induced by one vortex (Γ, r_j); d = r − r_j. */
PX_FN px_real2 px_biot_savart_velocity(px_real dx, px_real dy, px_real gamma, px_real eps2) {
  return px_v2_scale(px_biot_savart_term(dx, dy, gamma, eps2), PX_BIOT_SAVART_SCALE);
}

#endif
