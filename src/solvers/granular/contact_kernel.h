/* Contact laws of the granular solver, written once for C and OpenCL C.
 *
 * Conventions (2D, all forces on particle i of a contact i–j or i–wall):
 *   n      unit normal from the partner (j or the wall) to i
 *   t      = (-n_y, n_x), the unit tangent (n rotated by +90 degrees)
 *   delta  overlap [m] (> 0 in contact)
 *   vn     (v_i - v_j) . n at the contact point [m/s] (< 0 approaching)
 *   vt     (v_i - v_j) . t at the contact point, including rotation:
 *          vt = (v_i - v_j) . t - (a_i w_i + a_j w_j), a = r - delta/2
 *          (a wall's rigid velocity at the contact point replaces v_j + a_j w_j t)
 *   wrel   w_i - w_j [rad/s] (rolling)
 *   fn     normal force on i along n [N] (> 0 repulsive)
 *   ft     tangential force on i along t [N]
 *   mr     rolling-resistance torque on i [N m] (j gets -mr)
 * Torques on i and j from ft: -a_i ft and -a_j ft.
 *
 * The tangential spring is a scalar along t: in 2D this is exactly the
 * Cundall–Strack spring "rotated into the current tangent plane" (Luding 2008,
 * eq. 17), since t turns with n. Symmetry: evaluating the contact from j's
 * side (n -> -n, t -> -t) gives the same vt, xi and ft, so either particle can
 * own the history.
 *
 * References:
 *   Cundall P.A., Strack O.D.L., "A discrete numerical model for granular
 *     assemblies", Geotechnique 29(1):47–65, 1979 (spring–dashpot, tangential
 *     spring with Coulomb limit).
 *   Walton O.R., Braun R.L., "Viscosity, granular-temperature, and stress
 *     calculations for shearing assemblies of inelastic, frictional disks",
 *     J. Rheol. 30(5):949–980, 1986 (linear hysteretic loading k1 /
 *     unloading k2, e = sqrt(k1/k2)).
 *   Luding S., "Cohesive, frictional powders: contact models for tension",
 *     Granular Matter 10:235–246, 2008 (eqs. 5–8: plastic model with
 *     k2(delta_max); eqs. 17–20: tangential spring projection and reset on
 *     sliding).
 *   Ai J., Chen J.-F., Rotter J.M., Ooi J.Y., "Assessment of rolling
 *     resistance models in discrete element simulations", Powder Technol.
 *     206:269–282, 2011 (elastic–plastic spring rolling model, k_r = 2.25 kn
 *     mu_r^2 R*^2).
 *   Schwager T., Pöschel T., "Coefficient of restitution and linear–dashpot
 *     model revisited", Granular Matter 9:465–469, 2007 (with the force
 *     clipped at zero the restitution departs from exp(-zeta pi/...)). */
#ifndef PX_GRAN_CONTACT_KERNEL_H
#define PX_GRAN_CONTACT_KERNEL_H

/* The precisions: PX_REAL for the contact arithmetic (the including unit or
 * the OpenCL build defines it; double for host code that wants the types and
 * constants), PX_GRAN_STATE for the integrated state (positions,
 * velocities, forces, integrator history; `mixed` is a double state with
 * float contacts). */
#ifndef PX_REAL
#define PX_REAL double
#endif
#include "kernels/px_kernel.h"
#ifndef PX_GRAN_STATE
#define PX_GRAN_STATE PX_REAL
#endif

/* Normal models. */
#define PX_GRAN_NORMAL_LINEAR 0
#define PX_GRAN_NORMAL_HYSTERETIC 1
/* Tangential models. */
#define PX_GRAN_TANGENTIAL_NONE 0
#define PX_GRAN_TANGENTIAL_SPRING 1  /* Cundall–Strack spring + Coulomb */
#define PX_GRAN_TANGENTIAL_VISCOUS 2 /* -c_t vt capped by Coulomb, no history */

/* Parameters of one contact law (particle–particle or particle–wall), in
 * the precision of the contact arithmetic. Filled by the backend from the
 * case (double) through px_gran_law_set (C) or from a parameter array
 * (OpenCL, see PX_GRAN_LAW_* indices). */
struct px_gran_law {
  PX_REAL kn;       /* normal stiffness [N/m] (hysteretic: loading k1) */
  PX_REAL k2;       /* hysteretic: maximal unloading stiffness k2 [N/m] */
  PX_REAL phif;     /* hysteretic: Luding's plasticity depth phi_f (0: constant k2) */
  PX_REAL zeta2;    /* 2 zeta, normal damping c_n = 2 zeta sqrt(m* kn) */
  PX_REAL ct_ratio; /* tangential damping c_t = ct_ratio c_n [-] */
  PX_REAL kt;       /* tangential stiffness [N/m] */
  PX_REAL ikt;      /* 1 / kt [m/N] */
  PX_REAL mu;       /* Coulomb friction coefficient [-] */
  PX_REAL mur;      /* rolling friction coefficient [-] (0: off) */
  PX_REAL kr;       /* rolling stiffness factor: k_r = kr kn R*^2 [-] */
  PX_REAL gt;       /* viscous tangential model: c_t = gt [N s/m] */
  int normal;       /* PX_GRAN_NORMAL_* */
  int tangential;   /* PX_GRAN_TANGENTIAL_* */
  PX_REAL clamp;    /* 1: no attractive normal force (fn >= 0); 0: allowed
                       (a real weight, not an int, so that no conversion
                       sits in vectorized loops) */
  PX_REAL cells;    /* 1: velocity Verlet impulse cells (dashpot onset/end
                       correction, see px_gran_contact); 0: off */
  int rolling;      /* 1: rolling resistance on (mur > 0) */
};

/* Parameter-array layout (OpenCL kernels receive the law as reals). */
#define PX_GRAN_LAW_KN 0
#define PX_GRAN_LAW_K2 1
#define PX_GRAN_LAW_PHIF 2
#define PX_GRAN_LAW_ZETA2 3
#define PX_GRAN_LAW_CT 4
#define PX_GRAN_LAW_KT 5
#define PX_GRAN_LAW_MU 6
#define PX_GRAN_LAW_MUR 7
#define PX_GRAN_LAW_KR 8
#define PX_GRAN_LAW_GT 9
#define PX_GRAN_LAW_NORMAL 10
#define PX_GRAN_LAW_TANGENTIAL 11
#define PX_GRAN_LAW_CLAMP 12
#define PX_GRAN_LAW_CELLS 13
#define PX_GRAN_LAW_COUNT 14

/* Damping ratio of the linear spring–dashpot for a restitution coefficient
 * 0 < e <= 1: zeta = -ln e / sqrt(pi^2 + ln^2 e) (e.g. Luding 2008, or any
 * text on the damped oscillator: e = exp(-zeta pi / sqrt(1 - zeta^2))). */
PX_FN PX_REAL px_gran_zeta(PX_REAL e) {
  const PX_REAL pi = (PX_REAL)3.14159265358979323846;
  PX_REAL le = px_glog(e);
  return -le / px_gsqrt(pi * pi + le * le);
}

/* Normal damping coefficient c_n = 2 zeta sqrt(m* kn) [N s/m] of a contact
 * with reduced mass m* (constant per pair: computed when the pair is
 * listed). */
PX_FN PX_REAL px_gran_damping(const struct px_gran_law *L, PX_REAL meff) {
  return L->zeta2 * px_gsqrt(meff * L->kn);
}

/* Evaluate one contact (cn0 = px_gran_damping of the pair).
 * delta <= 0 means "not in contact": the outputs are
 * zero (but for the end-of-contact dashpot remainder below) and the history
 * is reset. The history (xi: tangential spring [m],
 * theta: rolling spring angle [rad], dmax: largest overlap [m], dprev: the
 * overlap at the previous evaluation [m], 0 = unknown) is read and updated in
 * place; a predictor evaluation passes copies and discards them.
 * Written without data-dependent branches on the hot path so that loops over
 * contacts vectorize (the model switches are uniform). */
PX_FN void px_gran_contact(const struct px_gran_law *L, PX_REAL delta, PX_REAL vn, PX_REAL vt,
                           PX_REAL wrel, PX_REAL cn0, PX_REAL reff, PX_REAL dt, PX_REAL *xi,
                           PX_REAL *theta, PX_REAL *dmax, PX_REAL *dprev, PX_REAL *fn_out,
                           PX_REAL *ft_out, PX_REAL *mr_out) {
  /* Written with every value computed unconditionally and chosen by selects
   * (branches only on the model switches, constant in the specialised
   * loops), so that loops over contacts vectorize. Divisions that a select
   * may discard can give inf/NaN in lanes that are not chosen. */
  const PX_REAL zero = (PX_REAL)0, p5 = (PX_REAL)0.5, one = (PX_REAL)1;
  const int in = delta > zero;
  const PX_REAL d = in ? delta : zero;
  const PX_REAL dp = *dprev;
  PX_REAL cn = cn0;
  PX_REAL fel, fn, fc, ft, mr, part;

  /* The dashpot force jumps at the start (c |vn|) and at the end (-c vn) of a
   * contact. Velocity Verlet applies a force sample as the impulse of the
   * time cell [t - dt/2, t + dt/2] around it, so a jump inside a cell
   * misplaces up to c vn dt/2 of impulse: an O(dt) error in the restitution
   * that depends on where the contact starts within a step (up to 2-4% at
   * 50 steps per contact for e = 0.2-0.5). With the fraction of the last
   * step spent in contact (from the previous overlap dp, linear in time; from
   * the approach speed when dp is unknown = 0), the first sample in contact
   * carries 1/2 + that fraction of the dashpot impulse, and the first sample
   * out of contact the remaining fraction - 1/2 (may be negative): the
   * restitution becomes second order (0.1-0.6% at 50 steps). Only for
   * velocity Verlet (L->cells). */
  {
    /* one division: in contact after none, d / (d - dp) (dp < 0) or
     * d / (|vn| dt) (dp unknown); out after contact, dp / (dp - delta) */
    const PX_REAL avn = px_gabs(vn) * dt;
    const PX_REAL num = dp > zero ? dp : d;
    const PX_REAL den = dp > zero ? dp - delta : (dp < zero ? d - dp : avn);
    const PX_REAL q = num / den;
    /* in after none: 1/2 + (q, or 1 when the approach speed says the
     * contact began before the step); out after contact: q - 1/2; q read in
     * one place, so that a vectorizing compiler divides once */
    const int whole = in && !(dp < zero) && !(avn > d);
    const PX_REAL sgn_half = in ? p5 : -p5;
    const PX_REAL edge = sgn_half + (whole ? one : q);
    const PX_REAL pc = dp > zero ? (in ? one : edge) : (in ? edge : zero);
    const PX_REAL cf = L->cells; /* uniform 0/1 as a weight, not a branch */
    part = cf * pc + (one - cf) * (in ? one : zero);
  }
  cn *= part;
  *dprev = delta;

  /* Normal force. */
  if (L->normal == PX_GRAN_NORMAL_HYSTERETIC) {
    /* Luding 2008 eqs. 5–8 without cohesion (k_c = 0): loading on
     * k1 delta, un/reloading on k2 (delta - delta0), k2 growing with the
     * largest overlap up to k2max at delta* = k2max/(k2max - k1) phi_f 2R*;
     * phi_f = 0 keeps k2 constant (Walton & Braun 1986): delta* -> huge. */
    const PX_REAL k1 = L->kn, k2m = L->k2;
    const PX_REAL pf = L->phif > zero ? L->phif : (PX_REAL)1e30;
    const PX_REAL dstar = k2m / (k2m - k1) * pf * (PX_REAL)2 * reff;
    const PX_REAL dm0 = px_gmax(*dmax, d);
    const int virgin = dm0 < dstar;
    const PX_REAL dm = px_gmin(dm0, dstar);
    const PX_REAL k2v = k1 + (k2m - k1) * dm / dstar;
    const PX_REAL k2 = L->phif > zero ? k2v : k2m;
    const PX_REAL d0 = (one - k1 / k2) * dm;
    const PX_REAL f_load = k1 * d, f_unload = k2 * (d - d0);
    fel = (virgin && d >= dm) ? f_load : f_unload;
    fel = px_gmax(fel, zero);
    *dmax = in ? dm : zero;
  } else {
    fel = L->kn * d;
  }
  fn = fel - cn * vn;
  {
    const PX_REAL kf = L->clamp; /* uniform 0/1 weight */
    const PX_REAL f_end = (one - kf) * (-cn * vn);
    fn = fn - kf * px_gmin(fn, zero);
    /* out of contact: only the end-of-contact dashpot remainder (if any) */
    fn = in ? fn : f_end;
  }

  /* Tangential force. */
  fc = L->mu * px_gmax(fn, zero);
  if (L->tangential == PX_GRAN_TANGENTIAL_SPRING) {
    /* Cundall & Strack 1979 spring, Coulomb limit, and on sliding the
     * spring reset to the length that gives the sliding force (Luding 2008
     * eq. 20), so that the force stays continuous when sliding stops. */
    const PX_REAL ct = L->ct_ratio * cn;
    const PX_REAL x_trial = *xi + vt * dt;
    const PX_REAL x = in ? x_trial : zero;
    const PX_REAL f_trial = -L->kt * x - ct * vt;
    const PX_REAL flim = f_trial > zero ? fc : -fc;
    const PX_REAL x_slide = -(flim + ct * vt) * L->ikt;
    const int slide = px_gabs(f_trial) > fc;
    *xi = slide ? x_slide : x;
    ft = slide ? flim : f_trial;
  } else if (L->tangential == PX_GRAN_TANGENTIAL_VISCOUS) {
    const PX_REAL f_trial = -L->gt * vt;
    const PX_REAL flim = f_trial > zero ? fc : -fc;
    ft = px_gabs(f_trial) > fc ? flim : f_trial;
    *xi = zero;
  } else {
    ft = zero;
    *xi = zero;
  }
  ft = in ? ft : zero;

  /* Rolling resistance (elastic–plastic spring, Ai et al. 2011 model C
   * without the dashpot): k_r = kr kn R*^2, torque capped by mu_r R* fn. */
  if (L->rolling) {
    const PX_REAL kr = L->kr * L->kn * reff * reff;
    const PX_REAL mlim = L->mur * reff * px_gmax(fn, zero);
    const PX_REAL th_trial = *theta + wrel * dt;
    const PX_REAL th = in ? th_trial : zero;
    const PX_REAL m_trial = -kr * th;
    const PX_REAL mcap = m_trial > zero ? mlim : -mlim;
    const PX_REAL th_slip = -mcap / kr;
    const int slip = px_gabs(m_trial) > mlim;
    mr = slip ? mcap : m_trial;
    *theta = slip ? th_slip : th;
  } else {
    mr = zero;
    *theta = zero;
  }
  *fn_out = fn;
  *ft_out = ft;
  *mr_out = mr;
}

#endif
