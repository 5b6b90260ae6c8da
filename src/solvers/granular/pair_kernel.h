/* The force between two discs, written once for every engine: compiled as
 * C by the cpu loops (cpu_pair_loop.h, once per precision) and as OpenCL C
 * by granular.cl. Kinematics of the pair (normal, overlap, contact-point
 * lever arms, normal and tangential relative velocity), the contact law
 * (px_gran_contact, contact_kernel.h) and the assembly of the force on disc
 * i and the torques on both discs.
 *
 * The includer defines PX_REAL (the contact arithmetic, float or double;
 * OpenCL: -DPX_REAL=...). The caller gathers the pair's separation and
 * relative velocity in the contact precision from its own state layout
 * (the cpu loops may rebuild the separation from float offsets, see
 * cpu_pair_loop.h) and gives the pair's constants: the normal damping cn0
 * (px_gran_damping of the reduced mass) and the reduced radius reff.
 *
 * Rounding: every operation is spelled out in the order both engines used
 * before they shared this text, so results are bit-identical to theirs (C
 * is compiled with -ffp-contract=off; OpenCL may contract a*b+c within one
 * expression, as it did). */
#ifndef PX_GRAN_PAIR_KERNEL_H
#define PX_GRAN_PAIR_KERNEL_H

#include "kernels/px_kernel.h"
#include "solvers/granular/contact_kernel.h"

/* Pair (i, j) with separation (dx, dy) = x_i - x_j [m], relative velocity
 * (dvx, dvy) = v_i - v_j [m/s], spins wi, wj [rad/s] and radii ri, rj [m].
 * The contact history (xs, th, dm, dp: see px_gran_contact) is read and
 * updated in place. Out: the force on i (fx, fy) [N] (on j: its negative)
 * and the torques about the centres ti on i and tj on j [N m]. Discs apart
 * (overlap <= 0) give the end-of-contact remainder of px_gran_contact, zero
 * otherwise. */
PX_FN void px_gran_pair(const struct px_gran_law *L, px_real dx, px_real dy, px_real dvx,
                        px_real dvy, px_real wi, px_real wj, px_real ri, px_real rj, px_real cn0,
                        px_real reff, px_real dt, px_real *xs, px_real *th, px_real *dm,
                        px_real *dp, px_real *fx, px_real *fy, px_real *ti, px_real *tj) {
  const px_real rs = ri + rj;
  const px_real d2 = dx * dx + dy * dy;
  const px_real d = sqrt(d2);
  /* coincident centres: any unit normal would do; (0, 0) keeps the force
   * finite */
  const px_real inv = PX_R(1) / (d > PX_R(0) ? d : PX_R(1));
  const px_real nx = dx * inv, ny = dy * inv;
  const px_real delta = rs - d; /* overlap [m] */
  /* lever arms: centre to the middle of the overlap [m] */
  const px_real ai = ri - PX_R(0.5) * delta, aj = rj - PX_R(0.5) * delta;
  const px_real vn = dvx * nx + dvy * ny;
  /* tangential velocity of the contact point, t = (-ny, nx) */
  const px_real vt = dvy * nx - dvx * ny - (ai * wi + aj * wj);
  px_real fn, ft, mr;
  px_gran_contact(L, delta, vn, vt, wi - wj, cn0, reff, dt, xs, th, dm, dp, &fn, &ft, &mr);
  *fx = fn * nx - ft * ny;
  *fy = fn * ny + ft * nx;
  *ti = -ai * ft + mr;
  *tj = -aj * ft - mr;
}

#endif
