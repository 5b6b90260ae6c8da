/* Lattice physics, written once for C and OpenCL C.
 *
 * The body is a regular grid of cubic elements (spacing h). Each element has
 * six degrees of freedom: displacement u (global frame, from its grid
 * position), orientation q (unit quaternion, body -> global), velocity v and
 * angular velocity W, both in the global frame. Face neighbours are joined by a
 * link across their common face (spec: shared/spec/lattice.md, "Model").
 *
 * This file is a TEMPLATE, included once per real type. The includer defines
 *   LT_R       the real type (float or double)
 *   LT_(name)  the name of an item in this instantiation (e.g. name##_f)
 *   LT_SQRT    square root of an LT_R
 *   LT_FN      function qualifier (static inline in C, inline in OpenCL C)
 *   LT_G       address-space qualifier of the group table (empty in C,
 *              __global in OpenCL C)
 * and the file defines structs and functions named through LT_(...). There is
 * deliberately no include guard. Nothing here allocates, branches on data
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

/* ---------------------------------------------------------------------------
 * Small vector algebra */
struct LT_(v3) {
  LT_R x, y, z;
};
/* Quaternion (w; x, y, z). */
struct LT_(q4) {
  LT_R w, x, y, z;
};

LT_FN struct LT_(v3) LT_(v3_make)(LT_R x, LT_R y, LT_R z) {
  struct LT_(v3) r;
  r.x = x;
  r.y = y;
  r.z = z;
  return r;
}
LT_FN struct LT_(v3) LT_(v3_add)(struct LT_(v3) a, struct LT_(v3) b) {
  return LT_(v3_make)(a.x + b.x, a.y + b.y, a.z + b.z);
}
LT_FN struct LT_(v3) LT_(v3_sub)(struct LT_(v3) a, struct LT_(v3) b) {
  return LT_(v3_make)(a.x - b.x, a.y - b.y, a.z - b.z);
}
LT_FN struct LT_(v3) LT_(v3_scale)(LT_R s, struct LT_(v3) a) {
  return LT_(v3_make)(s * a.x, s * a.y, s * a.z);
}
LT_FN LT_R LT_(v3_dot)(struct LT_(v3) a, struct LT_(v3) b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
LT_FN struct LT_(v3) LT_(v3_cross)(struct LT_(v3) a, struct LT_(v3) b) {
  return LT_(v3_make)(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
/* Unit vector along axis a. */
LT_FN struct LT_(v3) LT_(v3_axis)(int a) {
  return LT_(v3_make)(a == 0 ? (LT_R)1 : (LT_R)0, a == 1 ? (LT_R)1 : (LT_R)0,
                      a == 2 ? (LT_R)1 : (LT_R)0);
}

/* Column a of (A - I), A the rotation matrix of the unit quaternion q. Written
 * out so that the small entries are computed directly, without the
 * cancellation of forming A and subtracting I (matters in single precision).
 * A = I + 2 [ -(y2+z2)  xy-wz     xz+wy
 *             xy+wz     -(x2+z2)  yz-wx
 *             xz-wy     yz+wx     -(x2+y2) ]. */
LT_FN struct LT_(v3) LT_(frame_col)(struct LT_(q4) q, int a) {
  LT_R x2 = q.x + q.x, y2 = q.y + q.y, z2 = q.z + q.z;
  if (a == 0) return LT_(v3_make)(-(q.y * y2 + q.z * z2), q.x * y2 + q.w * z2, q.x * z2 - q.w * y2);
  if (a == 1) return LT_(v3_make)(q.x * y2 - q.w * z2, -(q.x * x2 + q.z * z2), q.y * z2 + q.w * x2);
  return LT_(v3_make)(q.x * z2 + q.w * y2, q.y * z2 - q.w * x2, -(q.x * x2 + q.y * y2));
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
struct LT_(lpar) {
  LT_R h2, k, cl, kb, dk, cr;
};

/* State of one element as seen by a link. */
struct LT_(el) {
  struct LT_(v3) u; /* displacement [m] */
  struct LT_(q4) q; /* orientation (unit quaternion) */
  struct LT_(v3) v; /* velocity [m/s] */
  struct LT_(v3) W; /* angular velocity, global frame [rad/s] */
};

/* What a link does to its MINUS element (1); the plus element (2) receives
 * -F and, about its own centre, h2 n2 x F - G (see lt_link_torque). */
struct LT_(lres) {
  struct LT_(v3) F; /* force on element 1 [N], global frame */
  struct LT_(v3) G; /* couple on element 1 [N m], global frame (bending,
                       twist, rotational dashpot; excludes the moment of F) */
  struct LT_(v3) d; /* gap between the face centres, 1 minus 2 [m] */
  struct LT_(v3) vg;/* vector part of q2 q1^*: sin(phi/2) * axis of the
                       rotation of 2 relative to 1, global frame */
  LT_R s;           /* vg . n1 (twist part) */
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
LT_FN struct LT_(lres) LT_(link)(const struct LT_(lpar) *p, int a, struct LT_(el) e1,
                                 struct LT_(el) e2, struct LT_(v3) b1, struct LT_(v3) b2) {
  struct LT_(lres) r;
  struct LT_(v3) ea = LT_(v3_axis)(a);
  struct LT_(v3) n1 = LT_(v3_add)(ea, b1);
  struct LT_(v3) n2 = LT_(v3_add)(ea, b2);
  struct LT_(v3) dd;
  LT_R w, two_w, c;
  r.d = LT_(v3_add)(LT_(v3_sub)(e1.u, e2.u), LT_(v3_scale)(p->h2, LT_(v3_add)(b1, b2)));
  /* rate of the gap: v1 + W1 x (A1 c1) - v2 - W2 x (A2 c2) */
  dd = LT_(v3_add)(LT_(v3_sub)(e1.v, e2.v),
                   LT_(v3_scale)(p->h2, LT_(v3_add)(LT_(v3_cross)(e1.W, n1),
                                                    LT_(v3_cross)(e2.W, n2))));
  r.F = LT_(v3_sub)(LT_(v3_scale)(-p->k, r.d), LT_(v3_scale)(p->cl, dd));
  /* q2 q1^* = (w1 w2 + v1.v2 ; w1 v2 - w2 v1 + v1 x v2) */
  {
    struct LT_(v3) v1 = LT_(v3_make)(e1.q.x, e1.q.y, e1.q.z);
    struct LT_(v3) v2 = LT_(v3_make)(e2.q.x, e2.q.y, e2.q.z);
    w = e1.q.w * e2.q.w + LT_(v3_dot)(v1, v2);
    r.vg = LT_(v3_add)(LT_(v3_sub)(LT_(v3_scale)(e1.q.w, v2), LT_(v3_scale)(e2.q.w, v1)),
                       LT_(v3_cross)(v1, v2));
  }
  r.s = LT_(v3_dot)(r.vg, n1);
  two_w = w + w;
  c = p->dk * r.s;
  r.G = LT_(v3_add)(
      LT_(v3_scale)(two_w, LT_(v3_add)(LT_(v3_scale)(p->kb, r.vg), LT_(v3_scale)(c, n1))),
      LT_(v3_scale)(c + c, LT_(v3_cross)(r.vg, n1)));
  r.G = LT_(v3_add)(r.G, LT_(v3_scale)(p->cr, LT_(v3_sub)(e2.W, e1.W)));
  return r;
}

/* Moment of the link force about the centre of the element at one end,
 * global frame: h2 n x F for both ends (n = A e_a of that element):
 *   end 1: (A1 c1) x F = h2 n1 x F;  end 2: (A2 c2) x (-F) = h2 n2 x F. */
LT_FN struct LT_(v3) LT_(link_lever)(LT_R h2, int a, struct LT_(v3) b_self, struct LT_(v3) F) {
  return LT_(v3_scale)(h2, LT_(v3_cross)(LT_(v3_add)(LT_(v3_axis)(a), b_self), F));
}

/* Force F and moment T on an element (global frame). */
struct LT_(ft) {
  struct LT_(v3) F, T;
};

/* The two links of an element along axis a added to acc: Fp, Gp of the link
 * to its + neighbour, Fm, Gm of the link from its - neighbour (lres F and G,
 * each already scaled by its 0/1 flag), b_self the element's frame column a.
 * Shared by every engine form (gather, link-once; cpu and OpenCL), so they
 * add in the same order. */
LT_FN struct LT_(ft) LT_(axis_acc)(LT_R h2, int a, struct LT_(v3) b_self, struct LT_(v3) Fp,
                                   struct LT_(v3) Gp, struct LT_(v3) Fm, struct LT_(v3) Gm,
                                   struct LT_(ft) acc) {
  acc.F = LT_(v3_add)(acc.F, LT_(v3_sub)(Fp, Fm));
  acc.T = LT_(v3_add)(acc.T, LT_(link_lever)(h2, a, b_self, LT_(v3_add)(Fp, Fm)));
  acc.T = LT_(v3_add)(acc.T, LT_(v3_sub)(Gp, Gm));
  return acc;
}

/* Elastic energy stored in a link [J]: k |d|^2 / 2 + V_rot. */
LT_FN LT_R LT_(link_energy)(const struct LT_(lpar) *p, struct LT_(lres) r) {
  return (LT_R)0.5 * p->k * LT_(v3_dot)(r.d, r.d) +
         (LT_R)2 * (p->kb * LT_(v3_dot)(r.vg, r.vg) + p->dk * r.s * r.s);
}

/* Fracture: reciprocal strengths (0 = that mode never breaks the bond). */
struct LT_(fpar) {
  LT_R ifn, ift, imb, imt; /* 1/f_nc [1/N], 1/f_tc, 1/M_bc [1/(N m)], 1/M_tc */
};

/* Combined bond-breaking measure (LAMMPS bond_style bpm/rotational; Clemmer,
 * Monti & Lechman, Soft Matter 20 (2024) 1702, eq. 14):
 *   B = f_n/f_nc + |f_t|/f_tc + |M_b|/M_bc + |M_t|/M_tc,
 * from the elastic forces only (no dashpot). f_n is signed (tension > 0), so
 * compression delays breaking, as in LAMMPS. The bond breaks when B >= 1. */
LT_FN LT_R LT_(link_break)(const struct LT_(lpar) *p, const struct LT_(fpar) *f, int a,
                           struct LT_(v3) b1, struct LT_(lres) r) {
  struct LT_(v3) n1 = LT_(v3_add)(LT_(v3_axis)(a), b1);
  struct LT_(v3) fe = LT_(v3_scale)(-p->k, r.d);
  LT_R fn = LT_(v3_dot)(fe, n1);
  struct LT_(v3) ft = LT_(v3_sub)(fe, LT_(v3_scale)(fn, n1));
  struct LT_(v3) vb = LT_(v3_sub)(r.vg, LT_(v3_scale)(r.s, n1));
  LT_R mt = (LT_R)2 * (p->kb + p->dk) * r.s;
  LT_R mb = (LT_R)2 * p->kb * LT_SQRT(LT_(v3_dot)(vb, vb));
  return fn * f->ifn + LT_SQRT(LT_(v3_dot)(ft, ft)) * f->ift + mb * f->imb +
         (mt < 0 ? -mt : mt) * f->imt;
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
struct LT_(dvw) {
  struct LT_(v3) dv; /* [m/s^2] */
  struct LT_(v3) dW; /* [rad/s^2] */
};

/* Derivative of (v, W) for one element: forces F, T (links + loads, global),
 * group g, global mass damping alpha [1/s]. inv_m = 1/m, inv_i = 1/I.
 *   dv/dt = mask (F/m - alpha v) + a_p(t),  dW/dt = mask (T/I - alpha W) + alpha_p(t).
 * A fixed DOF (mask 0) keeps its prescribed motion exactly (zero if none).
 * (Results are returned by value throughout: an address-taken local inside
 * an `omp simd` loop is privatized per lane and stops the vectorizer.) */
LT_FN struct LT_(dvw) LT_(accel)(LT_G const LT_R *g, LT_R inv_m, LT_R inv_i, LT_R alpha,
                                 struct LT_(v3) F, struct LT_(v3) T, struct LT_(v3) v,
                                 struct LT_(v3) W) {
  struct LT_(dvw) r;
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
LT_FN struct LT_(dvw) LT_(accel_free)(LT_R inv_m, LT_R inv_i, LT_R alpha, struct LT_(v3) F,
                                      struct LT_(v3) T, struct LT_(v3) v, struct LT_(v3) W) {
  struct LT_(dvw) r;
  r.dv = LT_(v3_sub)(LT_(v3_scale)(inv_m, F), LT_(v3_scale)(alpha, v));
  r.dW = LT_(v3_sub)(LT_(v3_scale)(inv_i, T), LT_(v3_scale)(alpha, W));
  return r;
}

/* Leapfrog kick of one velocity component over dt: central difference with
 * the global damping taken semi-implicitly (unconditionally stable in alpha):
 *   v' (1 + mask alpha dt/2) = v (1 - mask alpha dt/2) + dt (mask (f + load)/m + a_p).
 * mask, acc, load: the component's entries of the group row. */
LT_FN LT_R LT_(kick)(LT_R mask, LT_R acc, LT_R load, LT_R inv_m, LT_R half_adt, LT_R dt, LT_R f,
                     LT_R v) {
  LT_R d = mask * half_adt;
  return (v * ((LT_R)1 - d) + dt * (mask * (f + load) * inv_m + acc)) / ((LT_R)1 + d);
}

/* dq/dt = (0, W) q / 2 for the global angular velocity W. */
LT_FN struct LT_(q4) LT_(qdot)(struct LT_(q4) q, struct LT_(v3) W) {
  struct LT_(q4) r;
  r.w = (LT_R)-0.5 * (W.x * q.x + W.y * q.y + W.z * q.z);
  r.x = (LT_R)0.5 * (q.w * W.x + W.y * q.z - W.z * q.y);
  r.y = (LT_R)0.5 * (q.w * W.y + W.z * q.x - W.x * q.z);
  r.z = (LT_R)0.5 * (q.w * W.z + W.x * q.y - W.y * q.x);
  return r;
}

LT_FN struct LT_(q4) LT_(qnormalize)(struct LT_(q4) q) {
  LT_R s = (LT_R)1 / LT_SQRT(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  q.w *= s;
  q.x *= s;
  q.y *= s;
  q.z *= s;
  return q;
}

/* Renormalize a quaternion whose norm is 1 + e with |e| << 1 (after one
 * step): one Newton step for 1/|q|, q (3 - |q|^2)/2, leaves |q|^2 = 1 - 3e^2/4,
 * i.e. unit to rounding, without a square root (so SIMD loops vectorize). */
LT_FN struct LT_(q4) LT_(qrenorm)(struct LT_(q4) q) {
  LT_R s = (LT_R)0.5 * ((LT_R)3 - (q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z));
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
LT_FN struct LT_(q4) LT_(qrotate)(struct LT_(q4) q, struct LT_(v3) th) {
  LT_R a2 = LT_(v3_dot)(th, th);
  LT_R c = (LT_R)1 - a2 * ((LT_R)0.125 - a2 * ((LT_R)1 / (LT_R)384));
  LT_R s = (LT_R)0.5 - a2 * ((LT_R)1 / (LT_R)48 - a2 * ((LT_R)1 / (LT_R)3840));
  struct LT_(q4) e, r;
  e.w = c;
  e.x = s * th.x;
  e.y = s * th.y;
  e.z = s * th.z;
  r.w = e.w * q.w - e.x * q.x - e.y * q.y - e.z * q.z;
  r.x = e.w * q.x + e.x * q.w + e.y * q.z - e.z * q.y;
  r.y = e.w * q.y - e.x * q.z + e.y * q.w + e.z * q.x;
  r.z = e.w * q.z + e.x * q.y - e.y * q.x + e.z * q.w;
  return LT_(qrenorm)(r);
}

/* ---------------------------------------------------------------------------
 * Stress. Love-Weber average over the element volume (Love 1927; Weber 1966;
 * e.g. Christoffersen, Mehrabadi & Nemat-Nasser, J. Appl. Mech. 48 (1981)
 * 339, eq. 2.10): sigma = (1/V) sum_s sym(r_s (x) F_s), V = h^3, r_s the
 * lever arm of face s and F_s the force the link exerts on the element there.
 * For either end this is h2 n_self (x) F with F the canonical link force (on
 * the minus element), so a tensile link adds positive normal stress. */
struct LT_(sym) {
  LT_R xx, yy, zz, xy, yz, zx;
};

LT_FN void LT_(stress_add)(struct LT_(sym) *s, LT_R h2, int a, struct LT_(v3) b_self,
                           struct LT_(v3) F) {
  struct LT_(v3) r = LT_(v3_scale)(h2, LT_(v3_add)(LT_(v3_axis)(a), b_self));
  s->xx += r.x * F.x;
  s->yy += r.y * F.y;
  s->zz += r.z * F.z;
  s->xy += (LT_R)0.5 * (r.x * F.y + r.y * F.x);
  s->yz += (LT_R)0.5 * (r.y * F.z + r.z * F.y);
  s->zx += (LT_R)0.5 * (r.z * F.x + r.x * F.z);
}

/* Von Mises equivalent stress of a symmetric tensor. */
LT_FN LT_R LT_(von_mises)(struct LT_(sym) s) {
  LT_R a = s.xx - s.yy, b = s.yy - s.zz, c = s.zz - s.xx;
  return LT_SQRT((LT_R)0.5 * (a * a + b * b + c * c) +
                 (LT_R)3 * (s.xy * s.xy + s.yz * s.yz + s.zx * s.zx));
}
