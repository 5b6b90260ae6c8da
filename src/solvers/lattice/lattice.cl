/* Lattice kernels for the opencl engine (lattice_opencl.c). The physics is
 * lattice_kernel.h, the same text the cpu loops compile; this file only
 * launches it: one work-item per cell of the padded grid rows
 * (i = pad + global id), state SoA with component stride ns.
 *
 * Stage kernels follow the cpu engine: the element loop treats every cell as
 * free and weights the accumulator by the 0/1 flag fr; the few elements
 * with boundary conditions are then redone by the *_bc kernels with their
 * group row (queued in order, so no extra barrier is needed).
 *
 * Poisson's ratio != 0 (docs/notes/lattice-poisson.md): lt_vol writes the
 * volumetric coefficients P_a of a state into pv before every force pass on
 * that state; the force kernels then take `vol` = 1 and add the P term
 * (lt_gather_v, lt_link_put_v, lt_stress_el_v), as the cpu engine does.
 * vol = 0 runs the nu = 0 code unchanged (pv is then not read). */
#include "kernels/px_kernel.h"
#include "solvers/lattice/lattice_kernel.h"

/* Constants of a launch (scalars in the argument list, assembled here). */
#define LT_PARAMS                                                                              \
  const uint n, const uint pad, const uint ns, const uint s1, const uint s2, const px_real h2, \
      const px_real k, const px_real cl, const px_real kb, const px_real dk, const px_real cr, \
      const px_real inv_m, const px_real inv_i, const px_real alpha

#define LT_LPAR     \
  struct lt_lpar p; \
  p.h2 = h2;        \
  p.k = k;          \
  p.cl = cl;        \
  p.kb = kb;        \
  p.dk = dk;        \
  p.cr = cr

PX_FN void lt_store(__global px_real *y, uint ns, uint j, struct lt_el e) {
  y[j] = e.u.x;
  y[ns + j] = e.u.y;
  y[2 * ns + j] = e.u.z;
  y[3 * ns + j] = e.q.w;
  y[4 * ns + j] = e.q.x;
  y[5 * ns + j] = e.q.y;
  y[6 * ns + j] = e.q.z;
  y[7 * ns + j] = e.v.x;
  y[8 * ns + j] = e.v.y;
  y[9 * ns + j] = e.v.z;
  y[10 * ns + j] = e.W.x;
  y[11 * ns + j] = e.W.y;
  y[12 * ns + j] = e.W.z;
}

/* Component c of an element (for loops over the 13 components). */
PX_FN px_real lt_comp(struct lt_el e, int c) {
  switch (c) {
    case 0: return e.u.x;
    case 1: return e.u.y;
    case 2: return e.u.z;
    case 3: return e.q.w;
    case 4: return e.q.x;
    case 5: return e.q.y;
    case 6: return e.q.z;
    case 7: return e.v.x;
    case 8: return e.v.y;
    case 9: return e.v.z;
    case 10: return e.W.x;
    case 11: return e.W.y;
    default: return e.W.z;
  }
}

/* Forces and moments of element i: its six links gathered (l1 = 0) or the
 * link-once results lk (l1 = 1). Link-once: the link from element i to its
 * + neighbour along each axis, evaluated once (lt_links) into lk, 6 arrays
 * of ns per axis (the F and G of lt_link), scaled by the link's 0/1 flag;
 * padding entries stay 0. Element i then sums its + links (at i) and its -
 * links (at i - s) with lt_sum_axis. */
PX_FN struct lt_ft lt_forces(const struct lt_lpar *p, __global const px_real *y, uint ns, uint i,
                             uint s1, uint s2, uint lp, uint lm, struct lt_el e, int l1,
                             __global const px_real *lk, int vol, __global const px_real *pv) {
  struct lt_ft r;
  /* (link-once: lk already holds the P term, lt_links) */
  if (!l1)
    return vol ? lt_gather_v(p, y, pv, ns, i, s1, s2, lt_lfl_bits(lp, lm), e)
               : lt_gather(p, y, ns, i, s1, s2, lt_lfl_bits(lp, lm), e);
  r.F = lt_v3_make(0, 0, 0);
  r.T = lt_v3_make(0, 0, 0);
  r = lt_sum_axis(p->h2, e.q, 0, lk, lk, ns, i, i - 1u, r);
  r = lt_sum_axis(p->h2, e.q, 1, lk + 6 * ns, lk + 6 * ns, ns, i, i - s1, r);
  return lt_sum_axis(p->h2, e.q, 2, lk + 12 * ns, lk + 12 * ns, ns, i, i - s2, r);
}

__kernel void lt_links(LT_PARAMS, __global const px_real *y, __global const uchar *lpv,
                       __global px_real *lk, const int vol, __global const px_real *pv) {
  uint g = (uint)get_global_id(0), i, a;
  struct lt_el e;
  LT_LPAR;
  (void)inv_m;
  (void)inv_i;
  (void)alpha;
  if (g >= n) return;
  i = pad + g;
  e = lt_load(y, ns, i);
  for (a = 0; a < 3; ++a) {
    uint s = a == 0 ? 1u : (a == 1 ? s1 : s2);
    if (vol)
      lt_link_put_v(&p, (int)a, e, lt_load(y, ns, i + s), pv[a * ns + i] + pv[a * ns + i + s],
                    (px_real)((lpv[i] >> a) & 1u), lk + 6 * a * ns, ns, i);
    else
      lt_link_put(&p, (int)a, e, lt_load(y, ns, i + s), (px_real)((lpv[i] >> a) & 1u),
                  lk + 6 * a * ns, ns, i);
  }
}

/* Volumetric coefficients P_a (lt_vol_coef) of every cell of state y into
 * pv[a ns + i]; vfv the elements free for the term (model vfree), lh2 =
 * lambda h^2 [N]. A cell without links (void) gets
 * P = 0. Run before each force pass on y (and before fields and row sums),
 * after fracture: broken links leave theta and c_a of both ends. */
__kernel void lt_vol(LT_PARAMS, __global const px_real *y, __global const uchar *lpv,
                     __global const uchar *lmv, __global const uchar *vfv, const px_real lh2,
                     __global px_real *pv) {
  uint g = (uint)get_global_id(0), i;
  struct lt_lfl f;
  struct lt_v3 P;
  (void)cl;
  (void)kb;
  (void)dk;
  (void)cr;
  (void)inv_m;
  (void)inv_i;
  (void)alpha;
  if (g >= n) return;
  i = pad + g;
  f = lt_lfl_bits(lpv[i], lmv[i]);
  P = lt_vol_coef(h2, lh2, k * h2, (px_real)vfv[i], y, ns, i, s1, s2, f, lt_load(y, ns, i));
  pv[i] = P.x;
  pv[ns + i] = P.y;
  pv[2 * ns + i] = P.z;
}

PX_FN int lt_finite(struct lt_el e) {
  px_real s = (e.u.x + e.u.y + e.u.z + e.q.w + e.q.x + e.q.y + e.q.z + e.v.x + e.v.y + e.v.z +
               e.W.x + e.W.y + e.W.z) *
              PX_R(0.0);
  return s == PX_R(0.0);
}

PX_FN int lt_v3_finite(struct lt_v3 v) { return (v.x + v.y + v.z) * PX_R(0.0) == PX_R(0.0); }

/* A non-finite state of element i at step kstep (1, 2, ... since the host
 * last read the flags): bad[0] keeps the first such step, bad[1] at that
 * step the smallest 4 i + what (what: 0 displacement, 1 velocity, 2 angular
 * velocity, 3 orientation, the order of px_lattice_check_finite_d), so that
 * the host names the step and the element it appeared in though it reads
 * the flags only every few steps. Both start at INT_MAX; kernels of later
 * steps run after (in-order queue) and see bad[0] < kstep. */
PX_FN void lt_flag(__global int *bad, int kstep, uint i, struct lt_el e) {
  int what = !lt_v3_finite(e.u) ? 0 : (!lt_v3_finite(e.v) ? 1 : (!lt_v3_finite(e.W) ? 2 : 3));
  if (atomic_min(&bad[0], kstep) >= kstep) atomic_min(&bad[1], (int)(4u * i) + what);
}

/* RK4 stage update of element i with derivative kk (see lattice_cpu_impl.h):
 * weight w of the accumulator (fr for the element loop, 1 for the BC pass). */
PX_FN void lt_rk4_update(__global px_real *yn, __global px_real *y0, __global px_real *acc, uint ns,
                         uint i, struct lt_el kk, int stage, px_real w, px_real cs, px_real dt6,
                         int bc, __global int *bad, int kstep) {
  int c;
  if (stage < 3) {
    for (c = 0; c < 13; ++c) {
      uint o = (uint)c * ns + i;
      px_real kc = lt_comp(kk, c);
      if (bc)
        acc[o] += (stage == 0 ? PX_R(1.0) : PX_R(2.0)) * kc;
      else
        acc[o] = stage == 0 ? w * kc : acc[o] + w * PX_R(2.0) * kc;
      yn[o] = y0[o] + cs * kc;
    }
  } else {
    struct lt_el yc;
    px_real v[13];
    for (c = 0; c < 13; ++c) {
      uint o = (uint)c * ns + i;
      v[c] = y0[o] + w * dt6 * (acc[o] + lt_comp(kk, c));
    }
    yc.u = lt_v3_make(v[0], v[1], v[2]);
    yc.q.w = v[3];
    yc.q.x = v[4];
    yc.q.y = v[5];
    yc.q.z = v[6];
    yc.v = lt_v3_make(v[7], v[8], v[9]);
    yc.W = lt_v3_make(v[10], v[11], v[12]);
    yc.q = lt_qrenorm(yc.q);
    lt_store(y0, ns, i, yc);
    if (!lt_finite(yc)) lt_flag(bad, kstep, i, yc);
  }
}

__kernel void lt_rk4_stage(LT_PARAMS, __global const px_real *ys, __global px_real *yn,
                           __global px_real *y0, __global px_real *acc, __global const uchar *lpv,
                           __global const uchar *lmv, __global const uchar *frv, const px_real cs,
                           const px_real dt6, const int stage, __global int *bad, const int l1,
                           __global const px_real *lk, const int kstep, const int vol,
                           __global const px_real *pv) {
  uint g = (uint)get_global_id(0), i;
  struct lt_el el;
  struct lt_ft f;
  LT_LPAR;
  if (g >= n) return;
  i = pad + g;
  el = lt_load(ys, ns, i);
  f = lt_forces(&p, ys, ns, i, s1, s2, lpv[i], lmv[i], el, l1, lk, vol, pv);
  lt_rk4_update(yn, y0, acc, ns, i,
                lt_deriv(el, lt_accel_free(inv_m, inv_i, alpha, f.F, f.T, el.v, el.W)), stage,
                (px_real)frv[i], cs, dt6, 0, bad, kstep);
}

/* The elements with boundary conditions: list[0..n-1], group rows in tab. */
__kernel void lt_rk4_bc(LT_PARAMS, __global const px_real *ys, __global px_real *yn,
                        __global px_real *y0, __global px_real *acc, __global const uchar *lpv,
                        __global const uchar *lmv, __global const uint *list,
                        __global const uchar *grp, __global const px_real *tab, const px_real cs,
                        const px_real dt6, const int stage, __global int *bad, const int l1,
                        __global const px_real *lk, const int kstep, const int vol,
                        __global const px_real *pv) {
  uint g = (uint)get_global_id(0), i;
  struct lt_el el;
  struct lt_ft f;
  LT_LPAR;
  (void)pad;
  if (g >= n) return;
  i = list[g];
  el = lt_load(ys, ns, i);
  f = lt_forces(&p, ys, ns, i, s1, s2, lpv[i], lmv[i], el, l1, lk, vol, pv);
  lt_rk4_update(yn, y0, acc, ns, i,
                lt_deriv(el, lt_accel(tab + (uint)grp[i] * LT_GROUP_STRIDE, inv_m, inv_i, alpha,
                                      f.F, f.T, el.v, el.W)),
                stage, PX_R(1.0), cs, dt6, 1, bad, kstep);
}

/* Leapfrog: kick with the group row g (0: a free element), drift, store
 * into yb. */
PX_FN void lt_lf_update(const struct lt_lpar *p, __global const px_real *ya, __global px_real *yb,
                        uint ns, uint i, uint s1, uint s2, uint lp, uint lm,
                        __global const px_real *g, px_real inv_m, px_real inv_i, px_real had,
                        px_real dt, __global int *bad, int l1, __global const px_real *lk,
                        int kstep, int vol, __global const px_real *pv) {
  struct lt_el el = lt_load(ya, ns, i);
  struct lt_ft f = lt_forces(p, ya, ns, i, s1, s2, lp, lm, el, l1, lk, vol, pv);
  struct lt_el nn = lt_lf_new(el, f.F, f.T, g, inv_m, inv_i, had, dt);
  lt_store(yb, ns, i, nn);
  if (!lt_finite(nn)) lt_flag(bad, kstep, i, nn);
}

__kernel void lt_leapfrog(LT_PARAMS, __global const px_real *ya, __global px_real *yb,
                          __global const uchar *lpv, __global const uchar *lmv, const px_real had,
                          const px_real dt, __global int *bad, const int l1,
                          __global const px_real *lk, const int kstep, const int vol,
                          __global const px_real *pv) {
  uint g = (uint)get_global_id(0);
  LT_LPAR;
  (void)alpha;
  if (g >= n) return;
  lt_lf_update(&p, ya, yb, ns, pad + g, s1, s2, lpv[pad + g], lmv[pad + g], 0, inv_m, inv_i, had,
               dt, bad, l1, lk, kstep, vol, pv);
}

__kernel void lt_leapfrog_bc(LT_PARAMS, __global const px_real *ya, __global px_real *yb,
                             __global const uchar *lpv, __global const uchar *lmv,
                             __global const uint *list, __global const uchar *grp,
                             __global const px_real *tab, const px_real had, const px_real dt,
                             __global int *bad, const int l1, __global const px_real *lk,
                             const int kstep, const int vol, __global const px_real *pv) {
  uint g = (uint)get_global_id(0), i;
  LT_LPAR;
  (void)alpha;
  (void)pad;
  if (g >= n) return;
  i = list[g];
  lt_lf_update(&p, ya, yb, ns, i, s1, s2, lpv[i], lmv[i], tab + (uint)grp[i] * LT_GROUP_STRIDE,
               inv_m, inv_i, had, dt, bad, l1, lk, kstep, vol, pv);
}

/* Fracture: each element clears its own flags of the links that break
 * (canonical evaluation: both ends decide alike); counts link ends. */
__kernel void lt_fracture(LT_PARAMS, __global const px_real *y, __global uchar *lpv,
                          __global uchar *lmv, const px_real ifn, const px_real ift,
                          const px_real imb, const px_real imt, __global int *ends) {
  uint g = (uint)get_global_id(0), i, lp, lm;
  struct lt_fpar fp;
  int cnt;
  LT_LPAR;
  (void)inv_m;
  (void)inv_i;
  (void)alpha;
  if (g >= n) return;
  i = pad + g;
  lp = lpv[i];
  lm = lmv[i];
  if (!(lp | lm)) return;
  fp.ifn = ifn;
  fp.ift = ift;
  fp.imb = imb;
  fp.imt = imt;
  cnt = lt_fracture_el(&p, &fp, y, ns, i, s1, s2, lt_load(y, ns, i), &lp, &lm);
  if (cnt) {
    lpv[i] = (uchar)lp;
    lmv[i] = (uchar)lm;
    atomic_add(ends, cnt);
  }
}

/* Output fields of every cell: out[c n + g], c = u(3) v(3) sigma(6) vm(1),
 * computed where the state lives; v synchronized for leapfrog (sync != 0)
 * with the group rows in tab. */
__kernel void lt_fields(LT_PARAMS, __global const px_real *y, __global const uchar *lpv,
                        __global const uchar *lmv, __global const uchar *grp,
                        __global const px_real *tab, const int sync, const px_real half_dt,
                        __global px_real *out, const int vol, __global const px_real *pv) {
  uint g = (uint)get_global_id(0);
  LT_LPAR;
  if (g < n) {
    uint i = pad + g, lp = lpv[i], lm = lmv[i];
    struct lt_el el = lt_load(y, ns, i);
    struct lt_sym s;
    struct lt_v3 v = el.v;
    s.xx = s.yy = s.zz = s.xy = s.yz = s.zx = PX_R(0.0);
    if (grp[i] != 0) {
      if (sync) {
        struct lt_ft f = lt_forces(&p, y, ns, i, s1, s2, lp, lm, el, 0, 0, vol, pv);
        struct lt_dvw d = lt_accel(tab + (uint)grp[i] * LT_GROUP_STRIDE, inv_m, inv_i, alpha, f.F,
                                   f.T, el.v, el.W);
        v = lt_v3_add(v, lt_v3_scale(half_dt, d.dv));
      }
      s = vol ? lt_stress_el_v(&p, y, pv, ns, i, s1, s2, lp, lm, el)
              : lt_stress_el(&p, y, ns, i, s1, s2, lp, lm, el);
    } else {
      v = lt_v3_make(0, 0, 0);
      el.u = v;
    }
    out[g] = el.u.x;
    out[n + g] = el.u.y;
    out[2 * n + g] = el.u.z;
    out[3 * n + g] = v.x;
    out[4 * n + g] = v.y;
    out[5 * n + g] = v.z;
    out[6 * n + g] = s.xx;
    out[7 * n + g] = s.yy;
    out[8 * n + g] = s.zz;
    out[9 * n + g] = s.xy;
    out[10 * n + g] = s.yz;
    out[11 * n + g] = s.zx;
    out[12 * n + g] = lt_von_mises(s);
  }
}

/* The Rayleigh sums of the quasi-static damping per grid row (rows
 * [0, n) from entry pad on, each n0p entries): -q.f_int, q.M q and
 * q.M dq/dt (m u.v + I theta.W) of the row's elements, summed along the row
 * into rows[r], rows[n + r], rows[2 n + r]. The host adds the rows in row
 * order, so that a run over ranks (each summing its own rows) gets the same
 * sums as one device. */
__kernel void lt_rows(LT_PARAMS, __global const px_real *y, __global const uchar *lpv,
                      __global const uchar *lmv, __global const uchar *grp, const uint n0p,
                      const px_real mass, const px_real inert, __global px_real *rows,
                      const int vol, __global const px_real *pv) {
  uint r = (uint)get_global_id(0), x;
  px_real sn = PX_R(0.0), sd = PX_R(0.0), sk = PX_R(0.0);
  LT_LPAR;
  (void)inv_m;
  (void)inv_i;
  (void)alpha;
  if (r >= n) return;
  for (x = 0; x < n0p; ++x) {
    uint i = pad + r * n0p + x;
    struct lt_el el;
    struct lt_ft f;
    struct lt_v3 th;
    if (grp[i] == 0) continue;
    el = lt_load(y, ns, i);
    f = lt_forces(&p, y, ns, i, s1, s2, lpv[i], lmv[i], el, 0, 0, vol, pv);
    th = lt_v3_make(PX_R(2.0) * el.q.x, PX_R(2.0) * el.q.y, PX_R(2.0) * el.q.z);
    sn -= lt_v3_dot(el.u, f.F) + lt_v3_dot(th, f.T);
    sd += mass * lt_v3_dot(el.u, el.u) + inert * lt_v3_dot(th, th);
    sk += mass * lt_v3_dot(el.u, el.v) + inert * lt_v3_dot(th, el.W);
  }
  rows[r] = sn;
  rows[n + r] = sd;
  rows[2 * n + r] = sk;
}
