/* Time-integration updates of the granular solver (C and OpenCL C), per
 * degree of freedom (x, y, rotation): y is a position or velocity, f its time
 * derivative (velocity or acceleration), h the step [s].
 *
 * Velocity Verlet (Swope, Andersen, Berens, Wilson, J. Chem. Phys. 76:637,
 * 1982), as in DEM codes: half kick, drift, forces, half kick. The contact
 * dashpot needs the velocity at the new time before the second kick; the
 * half-step velocity lags by h/2 and biases the restitution at low e (by 2%
 * at e = 0.2 with 200 steps per contact in LAMMPS), so the forces see the
 * extrapolation v_half + (h/2) a_old instead (second order).
 *
 * Adams–Bashforth–Moulton 4th order predictor–corrector (the original
 * program's integrator; e.g. Hairer, Nørsett, Wanner, Solving ODEs I,
 * sec. III.1): predictor AB4, forces, corrector AM4 (3rd-degree implicit
 * Adams in PECE form), forces again. The first three steps use the two-step
 * pair AB2/AM2 (trapezoidal corrector), the very first one Heun's method,
 * while the derivative history fills. */
#ifndef PX_GRAN_INTEGRATE_KERNEL_H
#define PX_GRAN_INTEGRATE_KERNEL_H

#include "solvers/granular/contact_kernel.h" /* the precisions, PX_FN */

/* AB4 predictor: y + h/24 (55 f0 - 59 f1 + 37 f2 - 9 f3), f0 = f_n. */
PX_FN PX_GRAN_STATE px_gran_ab4(PX_GRAN_STATE y, PX_GRAN_STATE f0, PX_GRAN_STATE f1,
                                PX_GRAN_STATE f2, PX_GRAN_STATE f3, PX_GRAN_STATE h) {
  return y + h / (PX_GRAN_STATE)24 *
                 ((PX_GRAN_STATE)55 * f0 - (PX_GRAN_STATE)59 * f1 + (PX_GRAN_STATE)37 * f2 -
                  (PX_GRAN_STATE)9 * f3);
}

/* AM4 corrector: y + h/24 (9 fp + 19 f0 - 5 f1 + f2), fp = f at the predictor. */
PX_FN PX_GRAN_STATE px_gran_am4(PX_GRAN_STATE y, PX_GRAN_STATE fp, PX_GRAN_STATE f0,
                                PX_GRAN_STATE f1, PX_GRAN_STATE f2, PX_GRAN_STATE h) {
  return y + h / (PX_GRAN_STATE)24 *
                 ((PX_GRAN_STATE)9 * fp + (PX_GRAN_STATE)19 * f0 - (PX_GRAN_STATE)5 * f1 + f2);
}

/* AB2 predictor: y + h/2 (3 f0 - f1). */
PX_FN PX_GRAN_STATE px_gran_ab2(PX_GRAN_STATE y, PX_GRAN_STATE f0, PX_GRAN_STATE f1,
                                PX_GRAN_STATE h) {
  return y + h / (PX_GRAN_STATE)2 * ((PX_GRAN_STATE)3 * f0 - f1);
}

/* AM2 (trapezoidal) corrector: y + h/2 (fp + f0); with f1 = f0 the pair
 * AB2/AM2 is Heun's method. */
PX_FN PX_GRAN_STATE px_gran_am2(PX_GRAN_STATE y, PX_GRAN_STATE fp, PX_GRAN_STATE f0,
                                PX_GRAN_STATE h) {
  return y + h / (PX_GRAN_STATE)2 * (fp + f0);
}

/* Velocity Verlet, first part for one degree of freedom: from (x, v) and the
 * old acceleration a to the new position and the velocity the forces see.
 * *v becomes v_half + h/2 a = v + h a (extrapolated). */
PX_FN void px_gran_vv_drift(PX_GRAN_STATE *x, PX_GRAN_STATE *v, PX_GRAN_STATE a, PX_GRAN_STATE h) {
  const PX_GRAN_STATE p5 = h * (PX_GRAN_STATE)0.5;
  const PX_GRAN_STATE vh = *v + p5 * a;
  *x = *x + h * vh;
  *v = vh + p5 * a;
}

/* Velocity Verlet, second part: the extrapolated velocity corrected by the
 * new acceleration: v_half + h/2 a_new = v_ext + h/2 (a_new - a_old). */
PX_FN PX_GRAN_STATE px_gran_vv_kick(PX_GRAN_STATE v, PX_GRAN_STATE a_old, PX_GRAN_STATE a_new,
                                    PX_GRAN_STATE h) {
  return v + h * (PX_GRAN_STATE)0.5 * (a_new - a_old);
}

#endif
