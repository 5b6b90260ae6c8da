/* Lattice physics, written once for C and OpenCL C.
 *
 * The body is a regular grid of cubic elements (spacing h). Each element has
 * six degrees of freedom: displacement u (global frame, from its grid
 * position), orientation q (unit quaternion, body -> global), velocity v and
 * angular velocity W, both in the global frame. Face neighbours are joined by a
 * link across their common face (spec: shared/spec/lattice.md, "Model").
 *
 * An ordinary body header on kernels/px_kernel.h (include that first, with
 * PX_REAL float or double): the opencl engine compiles it in lattice.cl,
 * one program per precision; the cpu engine in lattice_cpu_f32.c and
 * lattice_cpu_f64.c; host code (setup, reference engine, checkpoints,
 * tests) in double through lattice_c.h. Functions are PX_FN_INLINE: the cpu
 * simd loops vectorize only with the link law inlined. Buffers are
 * PX_GLOBAL and indexed by px_idx. Nothing here allocates, branches on data
 * (except where a comment says so) or calls trigonometric functions.
 *
 * Conventions of a link ("canonical" form): element 1 is the MINUS end and
 * element 2 the PLUS end along axis a (0 = x, 1 = y, 2 = z), so that
 * X2 = X1 + h e_a. The link is always evaluated with these roles, whichever
 * element asks, so both ends see bit-identical results (Newton's third law
 * holds exactly, and both ends take the same fracture decision).
 *
 * Why quaternions rather than the original's Cardan angles: no singularity
 * (no re-basing), no trigonometry at all (the rotation matrix columns are
 * quadratic in q; the relative rotation of two elements is the vector part of
 * q2 q1^*), and a bending/twist law derived from a potential, so that the
 * undamped model conserves energy and angular momentum exactly in the time
 * continuum (tests/lattice: energy test). */

#ifndef PX_LATTICE_KERNEL_H
#define PX_LATTICE_KERNEL_H

/* ---------------------------------------------------------------------------
 * Small vector algebra */
struct lt_v3 {
  px_real x, y, z;
};
/* Quaternion (w; x, y, z). */
struct lt_q4 {
  px_real w, x, y, z;
};

PX_FN_INLINE struct lt_v3 lt_v3_make(px_real x, px_real y, px_real z) {
  struct lt_v3 r;
  r.x = x;
  r.y = y;
  r.z = z;
  return r;
}
PX_FN_INLINE struct lt_v3 lt_v3_add(struct lt_v3 a, struct lt_v3 b) {
  return lt_v3_make(a.x + b.x, a.y + b.y, a.z + b.z);
}
PX_FN_INLINE struct lt_v3 lt_v3_sub(struct lt_v3 a, struct lt_v3 b) {
  return lt_v3_make(a.x - b.x, a.y - b.y, a.z - b.z);
}
PX_FN_INLINE struct lt_v3 lt_v3_scale(px_real s, struct lt_v3 a) {
  return lt_v3_make(s * a.x, s * a.y, s * a.z);
}
PX_FN_INLINE px_real lt_v3_dot(struct lt_v3 a, struct lt_v3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
PX_FN_INLINE struct lt_v3 lt_v3_cross(struct lt_v3 a, struct lt_v3 b) {
  return lt_v3_make(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
/* Unit vector along axis a. */
PX_FN_INLINE struct lt_v3 lt_v3_axis(int a) {
  return lt_v3_make(a == 0 ? (px_real)1 : (px_real)0, a == 1 ? (px_real)1 : (px_real)0,
                    a == 2 ? (px_real)1 : (px_real)0);
}

/* Column a of (A - I), A the rotation matrix of the unit quaternion q. Written
 * out so that the small entries are computed directly, without the
 * cancellation of forming A and subtracting I (matters in single precision).
 * A = I + 2 [ -(y2+z2)  xy-wz     xz+wy
 *             xy+wz     -(x2+z2)  yz-wx
 *             xz-wy     yz+wx     -(x2+y2) ]. */
PX_FN_INLINE struct lt_v3 lt_frame_col(struct lt_q4 q, int a) {
  px_real x2 = q.x + q.x, y2 = q.y + q.y, z2 = q.z + q.z;
  if (a == 0) return lt_v3_make(-(q.y * y2 + q.z * z2), q.x * y2 + q.w * z2, q.x * z2 - q.w * y2);
  if (a == 1) return lt_v3_make(q.x * y2 - q.w * z2, -(q.x * x2 + q.z * z2), q.y * z2 + q.w * x2);
  return lt_v3_make(q.x * z2 + q.w * y2, q.y * z2 - q.w * x2, -(q.x * x2 + q.y * y2));
}

/* ---------------------------------------------------------------------------
 * Link law. Constants (all SI):
 *   h2 = h/2                  [m]      face-centre offset
 *   k  = E h                  [N/m]    normal and shear spring, k_n = k_s
 *   cl = 2 zeta sqrt(k m/2)   [N s/m]  translational dashpot (m/2: two
 *                                      equal masses in series)
 *   kb = E h^3/12             [N m]    bending: E I_face / h, I_face = h^4/12
 *   dk = kt - kb, kt = G J / h with G = E/2, J = 0.1406 h^4 (square section,
 *        Saint-Venant torsion constant 0.1406 a^4; Roark, Table 10.7)
 *   cr = 2 zeta sqrt(kb I/2)  [N m s]  rotational dashpot, I = m h^2/6
 * k_b = E h^3/12 is the Euler-Bernoulli beam bond across a cube face, i.e.
 * the parallel-bond bending stiffness k_n I of Potyondy & Cundall (2004),
 * Int. J. Rock Mech. Min. Sci. 41:1329, eq. 8, with k_n = E/h and I = h^4/12;
 * it makes pure bending of an n-element-thick beam exact for every n
 * (research/lattice.md section 2). The original code's E h^3 is 12x too
 * stiff in bending and is NOT used. */
struct lt_lpar {
  px_real h2, k, cl, kb, dk, cr;
};

/* State of one element as seen by a link. */
struct lt_el {
  struct lt_v3 u; /* displacement [m] */
  struct lt_q4 q; /* orientation (unit quaternion) */
  struct lt_v3 v; /* velocity [m/s] */
  struct lt_v3 W; /* angular velocity, global frame [rad/s] */
};

/* What a link does to its MINUS element (1); the plus element (2) receives
 * -F and, about its own centre, h2 n2 x F - G (see lt_link_torque). */
struct lt_lres {
  struct lt_v3 F;  /* force on element 1 [N], global frame */
  struct lt_v3 G;  /* couple on element 1 [N m], global frame (bending,
                        twist, rotational dashpot; excludes the moment of F) */
  struct lt_v3 d;  /* gap between the face centres, 1 minus 2 [m] */
  struct lt_v3 vg; /* vector part of q2 q1^*: sin(phi/2) * axis of the
                        rotation of 2 relative to 1, global frame */
  px_real s;       /* vg . n1 (twist part) */
};

/* Evaluate the link between element e1 (minus) and e2 (plus) along axis a.
 * b1, b2: column a of (A1 - I) and (A2 - I) (lt_frame_col).
 *
 * Translation: the gap between the two face-centre points
 *   d = (x1 + A1 c1) - (x2 + A2 c2),  c1 = +h2 e_a, c2 = -h2 e_a,
 * which, with x = X + u and X2 - X1 = h e_a, is d = u1 - u2 + h2 (b1 + b2).
 * F = -k d - cl d', the spring pair of the FRUND model with k_n = k_s (an
 * isotropic spring, so the force needs no frame and derives from the
 * potential k|d|^2/2).
 *
 * Rotation: phi~ = 2 vec(q1^* q2) (the small-angle relative rotation, in
 * frame 1) with potential V = (kb |phi~|^2 + dk (phi~ . e_a)^2) / 2. Its
 * exact derivative gives the couple on element 1 in frame 1,
 * (w + [v]x) K phi~ with (w, v) = q1^* q2, K = diag(k_t on a, k_b), and the
 * opposite couple on element 2; rotated to the global frame with
 * vg = A1 v, n1 = A1 e_a this is
 *   G = 2 w (kb vg + dk s n1) + 2 dk s (vg x n1),   s = vg . n1.
 * (Wang 2009 / LAMMPS bpm/rotational use the same split into bending and
 * twist; this form is the gradient of V, so energy is conserved.) */
PX_FN_INLINE struct lt_lres lt_link(const struct lt_lpar *p, int a, struct lt_el e1,
                                    struct lt_el e2, struct lt_v3 b1, struct lt_v3 b2) {
  struct lt_lres r;
  struct lt_v3 ea = lt_v3_axis(a);
  struct lt_v3 n1 = lt_v3_add(ea, b1);
  struct lt_v3 n2 = lt_v3_add(ea, b2);
  struct lt_v3 dd;
  px_real w, two_w, c;
  r.d = lt_v3_add(lt_v3_sub(e1.u, e2.u), lt_v3_scale(p->h2, lt_v3_add(b1, b2)));
  /* rate of the gap: v1 + W1 x (A1 c1) - v2 - W2 x (A2 c2) */
  dd = lt_v3_add(lt_v3_sub(e1.v, e2.v),
                 lt_v3_scale(p->h2, lt_v3_add(lt_v3_cross(e1.W, n1), lt_v3_cross(e2.W, n2))));
  r.F = lt_v3_sub(lt_v3_scale(-p->k, r.d), lt_v3_scale(p->cl, dd));
  /* q2 q1^* = (w1 w2 + v1.v2 ; w1 v2 - w2 v1 + v1 x v2) */
  {
    struct lt_v3 v1 = lt_v3_make(e1.q.x, e1.q.y, e1.q.z);
    struct lt_v3 v2 = lt_v3_make(e2.q.x, e2.q.y, e2.q.z);
    w = e1.q.w * e2.q.w + lt_v3_dot(v1, v2);
    r.vg =
        lt_v3_add(lt_v3_sub(lt_v3_scale(e1.q.w, v2), lt_v3_scale(e2.q.w, v1)), lt_v3_cross(v1, v2));
  }
  r.s = lt_v3_dot(r.vg, n1);
  two_w = w + w;
  c = p->dk * r.s;
  r.G = lt_v3_add(lt_v3_scale(two_w, lt_v3_add(lt_v3_scale(p->kb, r.vg), lt_v3_scale(c, n1))),
                  lt_v3_scale(c + c, lt_v3_cross(r.vg, n1)));
  r.G = lt_v3_add(r.G, lt_v3_scale(p->cr, lt_v3_sub(e2.W, e1.W)));
  return r;
}

/* Moment of the link force about the centre of the element at one end,
 * global frame: h2 n x F for both ends (n = A e_a of that element):
 *   end 1: (A1 c1) x F = h2 n1 x F;  end 2: (A2 c2) x (-F) = h2 n2 x F. */
PX_FN_INLINE struct lt_v3 lt_link_lever(px_real h2, int a, struct lt_v3 b_self, struct lt_v3 F) {
  return lt_v3_scale(h2, lt_v3_cross(lt_v3_add(lt_v3_axis(a), b_self), F));
}

/* Force F and moment T on an element (global frame). */
struct lt_ft {
  struct lt_v3 F, T;
};

/* The two links of an element along axis a added to acc: Fp, Gp of the link
 * to its + neighbour, Fm, Gm of the link from its - neighbour (lres F and G,
 * each already scaled by its 0/1 flag), b_self the element's frame column a.
 * Shared by every engine form (gather, link-once; cpu and OpenCL), so they
 * add in the same order. */
PX_FN_INLINE struct lt_ft lt_axis_acc(px_real h2, int a, struct lt_v3 b_self, struct lt_v3 Fp,
                                      struct lt_v3 Gp, struct lt_v3 Fm, struct lt_v3 Gm,
                                      struct lt_ft acc) {
  acc.F = lt_v3_add(acc.F, lt_v3_sub(Fp, Fm));
  acc.T = lt_v3_add(acc.T, lt_link_lever(h2, a, b_self, lt_v3_add(Fp, Fm)));
  acc.T = lt_v3_add(acc.T, lt_v3_sub(Gp, Gm));
  return acc;
}

/* Elastic energy stored in a link [J]: k |d|^2 / 2 + V_rot. */
PX_FN_INLINE px_real lt_link_energy(const struct lt_lpar *p, struct lt_lres r) {
  return (px_real)0.5 * p->k * lt_v3_dot(r.d, r.d) +
         (px_real)2 * (p->kb * lt_v3_dot(r.vg, r.vg) + p->dk * r.s * r.s);
}

/* Fracture: reciprocal strengths (0 = that mode never breaks the bond). */
struct lt_fpar {
  px_real ifn, ift, imb, imt; /* 1/f_nc [1/N], 1/f_tc, 1/M_bc [1/(N m)], 1/M_tc */
};

/* Combined bond-breaking measure (LAMMPS bond_style bpm/rotational; Clemmer,
 * Monti & Lechman, Soft Matter 20 (2024) 1702, eq. 14):
 *   B = f_n/f_nc + |f_t|/f_tc + |M_b|/M_bc + |M_t|/M_tc,
 * from the elastic forces only (no dashpot). f_n is signed (tension > 0), so
 * compression delays breaking, as in LAMMPS. The bond breaks when B >= 1. */
PX_FN_INLINE px_real lt_link_break(const struct lt_lpar *p, const struct lt_fpar *f, int a,
                                   struct lt_v3 b1, struct lt_lres r) {
  struct lt_v3 n1 = lt_v3_add(lt_v3_axis(a), b1);
  struct lt_v3 fe = lt_v3_scale(-p->k, r.d);
  px_real fn = lt_v3_dot(fe, n1);
  struct lt_v3 ft = lt_v3_sub(fe, lt_v3_scale(fn, n1));
  struct lt_v3 vb = lt_v3_sub(r.vg, lt_v3_scale(r.s, n1));
  px_real mt = (px_real)2 * (p->kb + p->dk) * r.s;
  px_real mb = (px_real)2 * p->kb * sqrt(lt_v3_dot(vb, vb));
  return fn * f->ifn + sqrt(lt_v3_dot(ft, ft)) * f->ift + mb * f->imb +
         (mt < 0 ? -mt : mt) * f->imt;
}

/* ---------------------------------------------------------------------------
 * Volumetric term (Poisson's ratio nu != 0; docs/notes/lattice-poisson.md).
 * Element i estimates its volumetric strain from its intact links,
 *   theta_i = sum_a (1/c_a) sum_{links l of i along a} s_l,
 *   s_l = -(d_l . e_a)/h   (stretch of the link: d_l its face-centre gap),
 * c_a = 0, 1, 2 the intact links along a (1/c_a = 0 at c_a = 0; the
 * one-sided stretch on a face), and stores the energy of its whole cube,
 *   E_i = (lambda/2) h^3 theta_i^2 + fr sum_{a: c_a = 1} (mu/2) h^3 s_a^2,
 * the second term, for a free element (fr = 1: no fixed DOF, force or
 * moment), the half of the normal spring its cube has beyond its one link
 * at a face (the link's spring counts the cube between the centres). The
 * force of this energy acts through the link gaps: link l adds
 * F_vol = (P_a(1) + P_a(2)) e_a to the force F on its minus element,
 * P_a(i) = dE_i/ds_l / h (lt_vol_coef), and the moments follow from F as
 * for the springs (exact gradient: energy is conserved, both ends see the
 * same link force). A rigid motion leaves every gap, hence theta, at zero. */

/* Component a of v. */
PX_FN_INLINE px_real lt_v3_get(struct lt_v3 v, int a) {
  return a == 0 ? v.x : (a == 1 ? v.y : v.z);
}

/* 1/c for c = 0, 1, 2 intact links along an axis (0 for 0), branch-free:
 * c (7/4 - 3c/4). */
PX_FN_INLINE px_real lt_inv_count(px_real c) { return c * ((px_real)1.75 - (px_real)0.75 * c); }

/* Stretch s = -(d . e_a)/h of the link (e1 minus, e2 plus along a; b1, b2
 * their frame columns a) [-]. */
PX_FN_INLINE px_real lt_link_stretch(px_real h2, int a, struct lt_el e1, struct lt_el e2,
                                     struct lt_v3 b1, struct lt_v3 b2) {
  px_real d = lt_v3_get(e1.u, a) - lt_v3_get(e2.u, a) + h2 * (lt_v3_get(b1, a) + lt_v3_get(b2, a));
  return -d / (h2 + h2);
}

/* The link force of lt_link plus the volumetric force (P1 + P2) e_a, p12
 * the sum of the two ends' coefficients P_a [N]. */
PX_FN_INLINE struct lt_v3 lt_vol_add(struct lt_v3 F, int a, px_real p12) {
  return lt_v3_add(F, lt_v3_scale(p12, lt_v3_axis(a)));
}

/* ---------------------------------------------------------------------------
 * Element equations of motion. Inertia of a cube about its centre is
 * isotropic, I = m h^2/6, so the Euler equations reduce to I dW/dt = T in the
 * global frame (no gyroscopic term). */

/* Boundary-condition group (stride LT_GROUP_STRIDE reals): per DOF a 0/1 mask
 * (1 = free), an additive prescribed acceleration and an applied force or
 * moment per element. Layout: mask[6] | acc[6] | load[6] (ux uy uz rx ry rz). */
#define LT_GROUP_STRIDE 18

/* Rates of (v, W) of one element. */
struct lt_dvw {
  struct lt_v3 dv; /* [m/s^2] */
  struct lt_v3 dW; /* [rad/s^2] */
};

/* Derivative of (v, W) for one element: forces F, T (links + loads, global),
 * group g, global mass damping alpha [1/s]. inv_m = 1/m, inv_i = 1/I.
 *   dv/dt = mask (F/m - alpha v) + a_p(t),  dW/dt = mask (T/I - alpha W) + alpha_p(t).
 * A fixed DOF (mask 0) keeps its prescribed motion exactly (zero if none).
 * (Results are returned by value throughout: an address-taken local inside
 * an `omp simd` loop is privatized per lane and stops the vectorizer.) */
PX_FN_INLINE struct lt_dvw lt_accel(PX_GLOBAL const px_real *g, px_real inv_m, px_real inv_i,
                                    px_real alpha, struct lt_v3 F, struct lt_v3 T, struct lt_v3 v,
                                    struct lt_v3 W) {
  struct lt_dvw r;
  r.dv.x = g[0] * ((F.x + g[12]) * inv_m - alpha * v.x) + g[6];
  r.dv.y = g[1] * ((F.y + g[13]) * inv_m - alpha * v.y) + g[7];
  r.dv.z = g[2] * ((F.z + g[14]) * inv_m - alpha * v.z) + g[8];
  r.dW.x = g[3] * ((T.x + g[15]) * inv_i - alpha * W.x) + g[9];
  r.dW.y = g[4] * ((T.y + g[16]) * inv_i - alpha * W.y) + g[10];
  r.dW.z = g[5] * ((T.z + g[17]) * inv_i - alpha * W.z) + g[11];
  return r;
}

/* lt_accel for a free element without loads (the common case; no table
 * lookup, so the simd loops vectorize). */
PX_FN_INLINE struct lt_dvw lt_accel_free(px_real inv_m, px_real inv_i, px_real alpha,
                                         struct lt_v3 F, struct lt_v3 T, struct lt_v3 v,
                                         struct lt_v3 W) {
  struct lt_dvw r;
  r.dv = lt_v3_sub(lt_v3_scale(inv_m, F), lt_v3_scale(alpha, v));
  r.dW = lt_v3_sub(lt_v3_scale(inv_i, T), lt_v3_scale(alpha, W));
  return r;
}

/* Leapfrog kick of one velocity component over dt: central difference with
 * the global damping taken semi-implicitly (unconditionally stable in alpha):
 *   v' (1 + mask alpha dt/2) = v (1 - mask alpha dt/2) + dt (mask (f + load)/m + a_p).
 * mask, acc, load: the component's entries of the group row. */
PX_FN_INLINE px_real lt_kick(px_real mask, px_real acc, px_real load, px_real inv_m,
                             px_real half_adt, px_real dt, px_real f, px_real v) {
  px_real d = mask * half_adt;
  return (v * ((px_real)1 - d) + dt * (mask * (f + load) * inv_m + acc)) / ((px_real)1 + d);
}

/* dq/dt = (0, W) q / 2 for the global angular velocity W. */
PX_FN_INLINE struct lt_q4 lt_qdot(struct lt_q4 q, struct lt_v3 W) {
  struct lt_q4 r;
  r.w = (px_real)-0.5 * (W.x * q.x + W.y * q.y + W.z * q.z);
  r.x = (px_real)0.5 * (q.w * W.x + W.y * q.z - W.z * q.y);
  r.y = (px_real)0.5 * (q.w * W.y + W.z * q.x - W.x * q.z);
  r.z = (px_real)0.5 * (q.w * W.z + W.x * q.y - W.y * q.x);
  return r;
}

PX_FN_INLINE struct lt_q4 lt_qnormalize(struct lt_q4 q) {
  px_real s = (px_real)1 / sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  q.w *= s;
  q.x *= s;
  q.y *= s;
  q.z *= s;
  return q;
}

/* Renormalize a quaternion whose norm is 1 + e with |e| << 1 (after one
 * step): one Newton step for 1/|q|, q (3 - |q|^2)/2, leaves |q|^2 = 1 - 3e^2/4,
 * i.e. unit to rounding, without a square root (so SIMD loops vectorize). */
PX_FN_INLINE struct lt_q4 lt_qrenorm(struct lt_q4 q) {
  px_real s = (px_real)0.5 * ((px_real)3 - (q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z));
  q.w *= s;
  q.x *= s;
  q.y *= s;
  q.z *= s;
  return q;
}

/* exp(th/2) q, normalized: q rotated by the rotation vector th (global frame;
 * leapfrog drift). The half-angle cosine and sinc are Taylor polynomials
 * (error below |th|^6/46080, 2e-11 at |th| = 0.1; a step turns an element by
 * far less), followed by renormalization, so no trigonometry and no square
 * root are needed. */
PX_FN_INLINE struct lt_q4 lt_qrotate(struct lt_q4 q, struct lt_v3 th) {
  px_real a2 = lt_v3_dot(th, th);
  px_real c = (px_real)1 - a2 * ((px_real)0.125 - a2 * ((px_real)1 / (px_real)384));
  px_real s = (px_real)0.5 - a2 * ((px_real)1 / (px_real)48 - a2 * ((px_real)1 / (px_real)3840));
  struct lt_q4 e, r;
  e.w = c;
  e.x = s * th.x;
  e.y = s * th.y;
  e.z = s * th.z;
  r.w = e.w * q.w - e.x * q.x - e.y * q.y - e.z * q.z;
  r.x = e.w * q.x + e.x * q.w + e.y * q.z - e.z * q.y;
  r.y = e.w * q.y - e.x * q.z + e.y * q.w + e.z * q.x;
  r.z = e.w * q.z + e.x * q.y - e.y * q.x + e.z * q.w;
  return lt_qrenorm(r);
}

/* ---------------------------------------------------------------------------
 * Stress. Love-Weber average over the element volume (Love 1927; Weber 1966;
 * e.g. Christoffersen, Mehrabadi & Nemat-Nasser, J. Appl. Mech. 48 (1981)
 * 339, eq. 2.10): sigma = (1/V) sum_s sym(r_s (x) F_s), V = h^3, r_s the
 * lever arm of face s and F_s the force the link exerts on the element there.
 * For either end this is h2 n_self (x) F with F the canonical link force (on
 * the minus element), so a tensile link adds positive normal stress.
 *
 * Faces: an element with one intact link along an axis has lost the other
 * face's half of the average (a plate under 100 MPa read 49.9 MPa on its
 * loaded face). The estimator therefore takes, per axis a, the MEAN
 * traction of the intact links along a: their terms are scaled by
 * 2/c_a (c_a = 1 or 2 intact links; 1 inside the body, where it is the
 * Love-Weber average). Row a of the unsymmetrized sum M = sum r (x) F / V is
 * then the traction on the faces normal to a, exact for a uniform stress at
 * faces, edges and corners; sigma_ab = (M_ab + M_ba)/2, or the one row
 * present when an axis has no link at all (c_b = 0: a one-element-thick
 * wall, whose row b is zero rather than half the shear). */
struct lt_sym {
  px_real xx, yy, zz, xy, yz, zx;
};

/* Unsymmetrized sum M (rows: lever arm components) [N m]. */
struct lt_m3 {
  px_real xx, xy, xz, yx, yy, yz, zx, zy, zz;
};

/* Add r (x) F with r = h2s (e_a + b_self) (h2s: h/2 times the axis scale
 * 2/c_a). */
PX_FN_INLINE struct lt_m3 lt_m3_add(struct lt_m3 M, px_real h2s, int a, struct lt_v3 b_self,
                                    struct lt_v3 F) {
  struct lt_v3 r = lt_v3_scale(h2s, lt_v3_add(lt_v3_axis(a), b_self));
  M.xx += r.x * F.x;
  M.xy += r.x * F.y;
  M.xz += r.x * F.z;
  M.yx += r.y * F.x;
  M.yy += r.y * F.y;
  M.yz += r.y * F.z;
  M.zx += r.z * F.x;
  M.zy += r.z * F.y;
  M.zz += r.z * F.z;
  return M;
}

/* The symmetric stress sum from M and the intact link counts cx, cy, cz
 * (see above): off-diagonal weight 1/2 with both rows present, 1 with one. */
PX_FN_INLINE struct lt_sym lt_stress_fin(struct lt_m3 M, px_real cx, px_real cy, px_real cz) {
  struct lt_sym s;
  px_real px = cx > (px_real)0 ? (px_real)1 : (px_real)0;
  px_real py = cy > (px_real)0 ? (px_real)1 : (px_real)0;
  px_real pz = cz > (px_real)0 ? (px_real)1 : (px_real)0;
  s.xx = M.xx;
  s.yy = M.yy;
  s.zz = M.zz;
  s.xy = (M.xy + M.yx) * ((px_real)1 - (px_real)0.5 * px * py);
  s.yz = (M.yz + M.zy) * ((px_real)1 - (px_real)0.5 * py * pz);
  s.zx = (M.zx + M.xz) * ((px_real)1 - (px_real)0.5 * pz * px);
  return s;
}

/* Von Mises equivalent stress of a symmetric tensor. */
PX_FN_INLINE px_real lt_von_mises(struct lt_sym s) {
  px_real a = s.xx - s.yy, b = s.yy - s.zz, c = s.zz - s.xx;
  return sqrt((px_real)0.5 * (a * a + b * b + c * c) +
              (px_real)3 * (s.xy * s.xy + s.yz * s.yz + s.zx * s.zx));
}

/* ---------------------------------------------------------------------------
 * Per-element assembly on the engines' state buffers, shared by the cpu
 * loops (lattice_cpu_impl.h) and the OpenCL kernels (lattice.cl), so that
 * both load, gather and update an element with the same text.
 *
 * State buffers are SoA: component c (u.x u.y u.z q.w q.x q.y q.z v.x v.y
 * v.z W.x W.y W.z) of element j is y[c ns + j]. Indices are px_idx (size_t in
 * C, uint in OpenCL C; the opencl engine bounds 18 ns below 2^32); buffers
 * are PX_GLOBAL (global memory in OpenCL C). Link results (link-once scheme) are
 * 6 components F.x F.y F.z G.x G.y G.z with stride os. */

/* Element j of a state buffer. */
PX_FN_INLINE struct lt_el lt_load(PX_GLOBAL const px_real *restrict y, px_idx ns, px_idx j) {
  struct lt_el e;
  e.u.x = y[j];
  e.u.y = y[ns + j];
  e.u.z = y[2 * ns + j];
  e.q.w = y[3 * ns + j];
  e.q.x = y[4 * ns + j];
  e.q.y = y[5 * ns + j];
  e.q.z = y[6 * ns + j];
  e.v.x = y[7 * ns + j];
  e.v.y = y[8 * ns + j];
  e.v.z = y[9 * ns + j];
  e.W.x = y[10 * ns + j];
  e.W.y = y[11 * ns + j];
  e.W.z = y[12 * ns + j];
  return e;
}

/* The 0/1 flags of an element's six links (plus x y z, minus x y z) as
 * reals, so that a link is weighted rather than branched on. */
struct lt_lfl {
  px_real xp, yp, zp, xm, ym, zm;
};

/* Flags from the link bytes: plus bits 0-2, minus bits 3-5. */
PX_FN_INLINE struct lt_lfl lt_lfl_bits(unsigned lp, unsigned lm) {
  struct lt_lfl f;
  f.xp = (px_real)(lp & 1u);
  f.yp = (px_real)((lp >> 1) & 1u);
  f.zp = (px_real)((lp >> 2) & 1u);
  f.xm = (px_real)((lm >> 3) & 1u);
  f.ym = (px_real)((lm >> 4) & 1u);
  f.zm = (px_real)((lm >> 5) & 1u);
  return f;
}

/* Stretches along axis a of element i (state e, stride s, flags fp, fm of
 * its + and - links), summed: fp s_+ + fm s_- (the count times the mean). */
PX_FN_INLINE px_real lt_vol_axis(px_real h2, PX_GLOBAL const px_real *restrict y, px_idx ns,
                                 px_idx i, px_idx s, int a, px_real fp, px_real fm,
                                 struct lt_el e) {
  struct lt_v3 bs = lt_frame_col(e.q, a);
  struct lt_el en = lt_load(y, ns, i + s);
  struct lt_el em = lt_load(y, ns, i - s);
  px_real sp = lt_link_stretch(h2, a, e, en, bs, lt_frame_col(en.q, a));
  px_real sm = lt_link_stretch(h2, a, em, e, lt_frame_col(em.q, a), bs);
  return fp * sp + fm * sm;
}

/* The coefficients P_a of element i (state e, flags fl) at state y:
 *   P_a = (1/c_a) (lambda h^2 theta + fr (2 - c_a) mu h^2 S_a),
 * S_a the sum of its stretches along a (lt_vol_axis), theta = sum_a S_a/c_a;
 * the second term, for a free element (fr = 1: no fixed DOF, force or
 * moment) at a face (c_a = 1) only, is the half of the normal spring its
 * cube has beyond its one link, so that a free face carries no normal
 * traction in a uniform strain (docs/notes/lattice-poisson.md, "Faces").
 * P_a = 0 at c_a = 0. lh2 = lambda h^2, mh2 = mu h^2 = k h/2 [N]. */
PX_FN_INLINE struct lt_v3 lt_vol_coef(px_real h2, px_real lh2, px_real mh2, px_real fr,
                                      PX_GLOBAL const px_real *restrict y, px_idx ns, px_idx i,
                                      px_idx s1, px_idx s2, struct lt_lfl fl, struct lt_el e) {
  const px_real two = (px_real)2, m = fr * mh2;
  px_real cx = fl.xp + fl.xm, cy = fl.yp + fl.ym, cz = fl.zp + fl.zm;
  px_real ix = lt_inv_count(cx), iy = lt_inv_count(cy), iz = lt_inv_count(cz);
  px_real sx = lt_vol_axis(h2, y, ns, i, 1, 0, fl.xp, fl.xm, e);
  px_real sy = lt_vol_axis(h2, y, ns, i, s1, 1, fl.yp, fl.ym, e);
  px_real sz = lt_vol_axis(h2, y, ns, i, s2, 2, fl.zp, fl.zm, e);
  px_real t = lh2 * (sx * ix + sy * iy + sz * iz);
  return lt_v3_make(ix * (t + (two - cx) * m * sx), iy * (t + (two - cy) * m * sy),
                    iz * (t + (two - cz) * m * sz));
}

/* Add the two links of element i along axis a (neighbours i +- s; gather
 * form) to acc. Both links are evaluated canonically (minus end first), so
 * the neighbour computes the same bits, and weighted by their 0/1 flags
 * fp, fm. */
PX_FN_INLINE struct lt_ft lt_axis(const struct lt_lpar *p, PX_GLOBAL const px_real *restrict y,
                                  px_idx ns, px_idx i, px_idx s, int a, px_real fp, px_real fm,
                                  struct lt_el e, struct lt_ft acc) {
  struct lt_v3 bs = lt_frame_col(e.q, a);
  struct lt_el en = lt_load(y, ns, i + s);
  struct lt_el em = lt_load(y, ns, i - s);
  struct lt_lres rp = lt_link(p, a, e, en, bs, lt_frame_col(en.q, a));
  struct lt_lres rm = lt_link(p, a, em, e, lt_frame_col(em.q, a), bs);
  return lt_axis_acc(p->h2, a, bs, lt_v3_scale(fp, rp.F), lt_v3_scale(fp, rp.G),
                     lt_v3_scale(fm, rm.F), lt_v3_scale(fm, rm.G), acc);
}

/* Link forces and moments (global frame) of element i, state e, from its
 * six links (gather form); s1, s2 the y and z strides of the padded grid. */
PX_FN_INLINE struct lt_ft lt_gather(const struct lt_lpar *p, PX_GLOBAL const px_real *restrict y,
                                    px_idx ns, px_idx i, px_idx s1, px_idx s2, struct lt_lfl fl,
                                    struct lt_el e) {
  struct lt_ft r;
  r.F = lt_v3_make(0, 0, 0);
  r.T = lt_v3_make(0, 0, 0);
  r = lt_axis(p, y, ns, i, 1, 0, fl.xp, fl.xm, e, r);
  r = lt_axis(p, y, ns, i, s1, 1, fl.yp, fl.ym, e, r);
  return lt_axis(p, y, ns, i, s2, 2, fl.zp, fl.zm, e, r);
}

/* lt_axis with the volumetric force: pv the coefficients P_a of every
 * element (3 components, stride ns; lt_vol_coef). */
PX_FN_INLINE struct lt_ft lt_axis_v(const struct lt_lpar *p, PX_GLOBAL const px_real *restrict y,
                                    PX_GLOBAL const px_real *restrict pv, px_idx ns, px_idx i,
                                    px_idx s, int a, px_real fp, px_real fm, struct lt_el e,
                                    struct lt_ft acc) {
  struct lt_v3 bs = lt_frame_col(e.q, a);
  struct lt_el en = lt_load(y, ns, i + s);
  struct lt_el em = lt_load(y, ns, i - s);
  struct lt_lres rp = lt_link(p, a, e, en, bs, lt_frame_col(en.q, a));
  struct lt_lres rm = lt_link(p, a, em, e, lt_frame_col(em.q, a), bs);
  const px_idx o = (px_idx)a * ns;
  rp.F = lt_vol_add(rp.F, a, pv[o + i] + pv[o + i + s]);
  rm.F = lt_vol_add(rm.F, a, pv[o + i - s] + pv[o + i]);
  return lt_axis_acc(p->h2, a, bs, lt_v3_scale(fp, rp.F), lt_v3_scale(fp, rp.G),
                     lt_v3_scale(fm, rm.F), lt_v3_scale(fm, rm.G), acc);
}

/* lt_gather with the volumetric force (coefficients pv). */
PX_FN_INLINE struct lt_ft lt_gather_v(const struct lt_lpar *p, PX_GLOBAL const px_real *restrict y,
                                      PX_GLOBAL const px_real *restrict pv, px_idx ns, px_idx i,
                                      px_idx s1, px_idx s2, struct lt_lfl fl, struct lt_el e) {
  struct lt_ft r;
  r.F = lt_v3_make(0, 0, 0);
  r.T = lt_v3_make(0, 0, 0);
  r = lt_axis_v(p, y, pv, ns, i, 1, 0, fl.xp, fl.xm, e, r);
  r = lt_axis_v(p, y, pv, ns, i, s1, 1, fl.yp, fl.ym, e, r);
  return lt_axis_v(p, y, pv, ns, i, s2, 2, fl.zp, fl.zm, e, r);
}

/* A link's force and moment weighted by its flag f into out[c os + j]. */
PX_FN_INLINE void lt_link_store(struct lt_lres r, px_real f, PX_GLOBAL px_real *restrict out,
                                px_idx os, px_idx j) {
  out[j] = f * r.F.x;
  out[os + j] = f * r.F.y;
  out[2 * os + j] = f * r.F.z;
  out[3 * os + j] = f * r.G.x;
  out[4 * os + j] = f * r.G.y;
  out[5 * os + j] = f * r.G.z;
}

/* Link-once: the link from element i to its + neighbour along axis a
 * (state e1 of i, e2 of the neighbour), weighted by its flag f, into
 * out[c os + j]. */
PX_FN_INLINE void lt_link_put(const struct lt_lpar *p, int a, struct lt_el e1, struct lt_el e2,
                              px_real f, PX_GLOBAL px_real *restrict out, px_idx os, px_idx j) {
  lt_link_store(lt_link(p, a, e1, e2, lt_frame_col(e1.q, a), lt_frame_col(e2.q, a)), f, out, os, j);
}

/* lt_link_put with the volumetric force: p12 the two ends' P_a summed. */
PX_FN_INLINE void lt_link_put_v(const struct lt_lpar *p, int a, struct lt_el e1, struct lt_el e2,
                                px_real p12, px_real f, PX_GLOBAL px_real *restrict out, px_idx os,
                                px_idx j) {
  struct lt_lres r = lt_link(p, a, e1, e2, lt_frame_col(e1.q, a), lt_frame_col(e2.q, a));
  r.F = lt_vol_add(r.F, a, p12);
  lt_link_store(r, f, out, os, j);
}

/* Link-once: the two link results of an element along axis a (its + link at
 * pl[c os + jp], the link from its - neighbour at mi[c os + jm], both
 * already weighted by their flags) added to acc, q the element's
 * orientation: the arithmetic of lt_axis on the same link results. */
PX_FN_INLINE struct lt_ft lt_sum_axis(px_real h2, struct lt_q4 q, int a,
                                      PX_GLOBAL const px_real *restrict pl,
                                      PX_GLOBAL const px_real *restrict mi, px_idx os, px_idx jp,
                                      px_idx jm, struct lt_ft acc) {
  return lt_axis_acc(h2, a, lt_frame_col(q, a), lt_v3_make(pl[jp], pl[os + jp], pl[2 * os + jp]),
                     lt_v3_make(pl[3 * os + jp], pl[4 * os + jp], pl[5 * os + jp]),
                     lt_v3_make(mi[jm], mi[os + jm], mi[2 * os + jm]),
                     lt_v3_make(mi[3 * os + jm], mi[4 * os + jm], mi[5 * os + jm]), acc);
}

/* Time derivative of an element's state (u, q, v, W) -> (v, dq/dt, dv/dt,
 * dW/dt) from the rates d of lt_accel / lt_accel_free. */
PX_FN_INLINE struct lt_el lt_deriv(struct lt_el el, struct lt_dvw d) {
  struct lt_el k;
  k.v = d.dv;
  k.W = d.dW;
  k.q = lt_qdot(el.q, el.W);
  k.u = el.v;
  return k;
}

/* Leapfrog step of element el under link forces F [N] and moments T [N m]:
 * kick v, W to t + dt/2 (lt_kick) with the group row g, or as a free element
 * without loads when g is NULL (mask 1, no prescribed acceleration, no load;
 * a constant after inlining, so the cpu simd loops do not read the table),
 * then drift u, q to t + dt. had = alpha dt/2. */
PX_FN_INLINE struct lt_el lt_lf_new(struct lt_el el, struct lt_v3 F, struct lt_v3 T,
                                    PX_GLOBAL const px_real *g, px_real inv_m, px_real inv_i,
                                    px_real had, px_real dt) {
  struct lt_el n;
  if (g) {
    n.v.x = lt_kick(g[0], g[6], g[12], inv_m, had, dt, F.x, el.v.x);
    n.v.y = lt_kick(g[1], g[7], g[13], inv_m, had, dt, F.y, el.v.y);
    n.v.z = lt_kick(g[2], g[8], g[14], inv_m, had, dt, F.z, el.v.z);
    n.W.x = lt_kick(g[3], g[9], g[15], inv_i, had, dt, T.x, el.W.x);
    n.W.y = lt_kick(g[4], g[10], g[16], inv_i, had, dt, T.y, el.W.y);
    n.W.z = lt_kick(g[5], g[11], g[17], inv_i, had, dt, T.z, el.W.z);
  } else {
    n.v.x = lt_kick(1, 0, 0, inv_m, had, dt, F.x, el.v.x);
    n.v.y = lt_kick(1, 0, 0, inv_m, had, dt, F.y, el.v.y);
    n.v.z = lt_kick(1, 0, 0, inv_m, had, dt, F.z, el.v.z);
    n.W.x = lt_kick(1, 0, 0, inv_i, had, dt, T.x, el.W.x);
    n.W.y = lt_kick(1, 0, 0, inv_i, had, dt, T.y, el.W.y);
    n.W.z = lt_kick(1, 0, 0, inv_i, had, dt, T.z, el.W.z);
  }
  n.u = lt_v3_add(el.u, lt_v3_scale(dt, n.v));
  n.q = lt_qrotate(el.q, lt_v3_scale(dt, n.W));
  return n;
}

/* Fracture of element i (state el) at state y: its existing links (plus
 * bits 0-2 of *lp, minus bits 3-5 of *lm) evaluated canonically, so both
 * ends decide alike; the flags of the links that break (lt_link_break >= 1)
 * are cleared. Returns the number cleared (link ends). */
PX_FN_INLINE int lt_fracture_el(const struct lt_lpar *p, const struct lt_fpar *fp,
                                PX_GLOBAL const px_real *restrict y, px_idx ns, px_idx i, px_idx s1,
                                px_idx s2, struct lt_el el, unsigned *lp, unsigned *lm) {
  int a, cnt = 0;
  for (a = 0; a < 3; ++a) {
    const px_idx s = a == 0 ? (px_idx)1 : (a == 1 ? s1 : s2);
    struct lt_v3 bs = lt_frame_col(el.q, a);
    if (*lp & (1u << a)) {
      struct lt_el en = lt_load(y, ns, i + s);
      struct lt_lres r = lt_link(p, a, el, en, bs, lt_frame_col(en.q, a));
      if (lt_link_break(p, fp, a, bs, r) >= (px_real)1) {
        *lp &= ~(1u << a);
        ++cnt;
      }
    }
    if (*lm & (8u << a)) {
      struct lt_el em = lt_load(y, ns, i - s);
      struct lt_v3 bm = lt_frame_col(em.q, a);
      struct lt_lres r = lt_link(p, a, em, el, bm, bs);
      if (lt_link_break(p, fp, a, bm, r) >= (px_real)1) {
        *lm &= ~(8u << a);
        ++cnt;
      }
    }
  }
  return cnt;
}

/* Stress sum of element i (state el) over its existing links, with the
 * mean traction per axis (lt_stress_fin; divide by h^3 for the stress
 * [Pa]) [N m]; pv: the volumetric coefficients (lt_axis_v), or 0 at
 * nu = 0. */
PX_FN_INLINE struct lt_sym lt_stress_el_v(const struct lt_lpar *p,
                                          PX_GLOBAL const px_real *restrict y,
                                          PX_GLOBAL const px_real *restrict pv, px_idx ns, px_idx i,
                                          px_idx s1, px_idx s2, unsigned lp, unsigned lm,
                                          struct lt_el el) {
  struct lt_m3 M;
  px_real c[3];
  int a;
  M.xx = M.xy = M.xz = M.yx = M.yy = M.yz = M.zx = M.zy = M.zz = (px_real)0;
  for (a = 0; a < 3; ++a) {
    const px_idx st = a == 0 ? (px_idx)1 : (a == 1 ? s1 : s2);
    const px_idx o = (px_idx)a * ns;
    const unsigned hp = (lp >> a) & 1u, hm = (lm >> (3 + a)) & 1u;
    /* h/2 times 2/c_a */
    const px_real h2s = hp && hm ? p->h2 : p->h2 + p->h2;
    struct lt_v3 bs = lt_frame_col(el.q, a);
    c[a] = (px_real)(hp + hm);
    if (hp) {
      struct lt_el en = lt_load(y, ns, i + st);
      struct lt_v3 F = lt_link(p, a, el, en, bs, lt_frame_col(en.q, a)).F;
      if (pv) F = lt_vol_add(F, a, pv[o + i] + pv[o + i + st]);
      M = lt_m3_add(M, h2s, a, bs, F);
    }
    if (hm) {
      struct lt_el em = lt_load(y, ns, i - st);
      struct lt_v3 F = lt_link(p, a, em, el, lt_frame_col(em.q, a), bs).F;
      if (pv) F = lt_vol_add(F, a, pv[o + i - st] + pv[o + i]);
      M = lt_m3_add(M, h2s, a, bs, F);
    }
  }
  return lt_stress_fin(M, c[0], c[1], c[2]);
}

/* lt_stress_el_v at nu = 0. */
PX_FN_INLINE struct lt_sym lt_stress_el(const struct lt_lpar *p,
                                        PX_GLOBAL const px_real *restrict y, px_idx ns, px_idx i,
                                        px_idx s1, px_idx s2, unsigned lp, unsigned lm,
                                        struct lt_el el) {
  return lt_stress_el_v(p, y, 0, ns, i, s1, s2, lp, lm, el);
}

#endif
