/* The cpu engine's loops for one real type: lattice_cpu_f32.c and
 * lattice_cpu_f64.c define PX_REAL (float, double) and include this once,
 * giving px_lattice_cpu_*_f32 / _f64 (declared in lattice_cpu.h).
 *
 * State buffers are SoA: component k (u.x u.y u.z q.w q.x q.y q.z v.x v.y
 * v.z W.x W.y W.z) of element i is buf[k ns + i]. Loops run over grid rows
 * (fixed y, z): threads take blocks of rows dynamically (LT_ROWS_CHUNK; a
 * row is computed alone: the same bits on any split), and the x loop inside a row
 * is a `#pragma omp simd` loop whose neighbours i +- 1, i +- n0, i +- n0 n1
 * are unit-stride vector loads. */
#ifndef PX_LATTICE_CPU_IMPL_H
#define PX_LATTICE_CPU_IMPL_H

#include <omp.h>
#include <string.h>

#include "solvers/lattice/lattice_cpu.h"
/* (after the model's headers: see below) */
#include "kernels/px_kernel.h"
#include "solvers/lattice/lattice_kernel.h"
/* <complex.h>'s I (through px_kernel.h's <tgmath.h>) would replace the
 * model's rotational inertia m->I. */
#undef I

/* SIMD loops. gcc 12 sizes a loop's vector by the narrowest type in it,
 * whatever simdlen asks: a uint8 link flag made the loops 64 lanes wide in
 * double (8 zmm registers per value, and rows under 64 cells ran scalar) and
 * 16 lanes of xmm registers in float, and the link law's ~100 live values
 * spilled. So the simd loops read reals only (the flags through
 * lt_cpu_row_flags); with -march=native on the AVX-512 EPYC here that gives
 * one zmm register per value in float and one ymm register in double. */
#if PX_REAL_IS_DOUBLE
#define LT_SIMD _Pragma("omp simd simdlen(8)")
#define LT_SIMD_SUM _Pragma("omp simd simdlen(4) reduction(+ : sum)")
#define LT_SIMD_SM _Pragma("omp simd simdlen(8) reduction(+ : sm)")
#else
#define LT_SIMD _Pragma("omp simd simdlen(16)")
#define LT_SIMD_SUM _Pragma("omp simd simdlen(8) reduction(+ : sum)")
#define LT_SIMD_SM _Pragma("omp simd simdlen(16) reduction(+ : sm)")
#endif

#include "solvers/lattice/lattice_cpu_flags_impl.h"

/* The 13 state components, in buffer order, of an element and its
 * derivative (for writing out loops by hand: the vectorizer does not unroll
 * inner loops of a simd loop). */
#define LT_COMPS(X, e, d)                                                                          \
  X(0, e.u.x, d.u.x)                                                                               \
  X(1, e.u.y, d.u.y)                                                                               \
  X(2, e.u.z, d.u.z)                                                                               \
  X(3, e.q.w, d.q.w)                                                                               \
  X(4, e.q.x, d.q.x)                                                                               \
  X(5, e.q.y, d.q.y)                                                                               \
  X(6, e.q.z, d.q.z)                                                                               \
  X(7, e.v.x, d.v.x) X(8, e.v.y, d.v.y) X(9, e.v.z, d.v.z) X(10, e.W.x, d.W.x) X(11, e.W.y, d.W.y) \
      X(12, e.W.z, d.W.z)

/* Derivative of element i's state at stage state ys: (v, dq/dt, dv/dt, dW/dt),
 * with the group row g, or as a free element when g is NULL. */
PX_FN_INLINE struct lt_el lt_cpu_deriv(const struct lt_lpar *p, const px_real *restrict ys,
                                       size_t ns, size_t i, size_t s1, size_t s2, struct lt_lfl fl,
                                       const px_real *g, px_real inv_m, px_real inv_i,
                                       px_real alpha, const px_real *restrict pv) {
  struct lt_el el = lt_load(ys, ns, i);
  /* pv: loop-invariant (NULL at nu = 0) */
  struct lt_ft f =
      pv ? lt_gather_v(p, ys, pv, ns, i, s1, s2, fl, el) : lt_gather(p, ys, ns, i, s1, s2, fl, el);
  return lt_deriv(el, g ? lt_accel(g, inv_m, inv_i, alpha, f.F, f.T, el.v, el.W)
                        : lt_accel_free(inv_m, inv_i, alpha, f.F, f.T, el.v, el.W));
}

/* The simd row loops of one RK4 stage (gather form; px_lattice_cpu_rk4_stage)
 * over row cells [lo, hi) (element base + x), flags fl: inlined once with pv
 * NULL (nu = 0) and once with the coefficients, so that neither loop tests
 * pv (a loop-invariant test inside kept gcc from vectorizing: 5x the
 * instructions). Returns 0 times every value written (a NaN check). */
PX_FN_INLINE px_real lt_cpu_rk4_rows(const struct lt_lpar *p, const px_real *restrict ys,
                                     px_real *restrict yn, px_real *restrict y0,
                                     px_real *restrict acc, const px_real *restrict fl, size_t ns,
                                     size_t n0, size_t base, long lo, long hi, size_t s1, size_t s2,
                                     px_real inv_m, px_real inv_i, px_real alpha, px_real cs,
                                     px_real dt6, int stage, const px_real *restrict pv) {
  const px_real bs = (px_real)2;
  px_real sum = 0;
  long x;
#define LT_DERIV                                                                                  \
  const size_t i = base + (size_t)x;                                                              \
  const px_real fr = fl[6 * n0 + (size_t)x];                                                      \
  struct lt_el k = lt_cpu_deriv(p, ys, ns, i, s1, s2, lt_lfl_row(fl, n0, (size_t)x), NULL, inv_m, \
                                inv_i, alpha, pv);
  if (stage == 0) {
    LT_SIMD
    for (x = lo; x < hi; ++x) {
      LT_DERIV
#define LT_S0(c, ev, kv)             \
  acc[(size_t)(c)*ns + i] = fr * kv; \
  yn[(size_t)(c)*ns + i] = y0[(size_t)(c)*ns + i] + cs * kv;
      LT_COMPS(LT_S0, k, k)
#undef LT_S0
    }
  } else if (stage < 3) {
    LT_SIMD
    for (x = lo; x < hi; ++x) {
      LT_DERIV
#define LT_S12(c, ev, kv)                  \
  acc[(size_t)(c)*ns + i] += fr * bs * kv; \
  yn[(size_t)(c)*ns + i] = y0[(size_t)(c)*ns + i] + cs * kv;
      LT_COMPS(LT_S12, k, k)
#undef LT_S12
    }
  } else {
    LT_SIMD_SUM
    for (x = lo; x < hi; ++x) {
      LT_DERIV
      struct lt_el yc;
#define LT_S3(c, ev, kv) ev = y0[(size_t)(c)*ns + i] + fr * dt6 * (acc[(size_t)(c)*ns + i] + kv);
      LT_COMPS(LT_S3, yc, k)
#undef LT_S3
      yc.q = lt_qrenorm(yc.q);
#define LT_W3(c, ev, kv)       \
  y0[(size_t)(c)*ns + i] = ev; \
  sum += ev * (px_real)0;
      LT_COMPS(LT_W3, yc, k)
#undef LT_W3
    }
  }
#undef LT_DERIV
  return sum;
}

/* One fused RK4 stage over all elements (gather form): forces from the
 * stage state ys, derivative k, then
 *   stage 0: acc = k;        yn = y0 + dt/2 k
 *   stage 1: acc += 2k;      yn = y0 + dt/2 k
 *   stage 2: acc += 2k;      yn = y0 + dt k
 *   stage 3: y0 += dt/6 (acc + k), q renormalized (yn unused).
 * The simd loop treats every element as free (void cells have no links and
 * stay at rest), weighting acc and the final update by the 0/1 flag `fr`;
 * then the few elements with boundary conditions (e->bc_list) are redone
 * with their group row. The three update forms are separate loops (a branch
 * inside would stop the vectorizer). Returns nonzero if the final stage
 * produced a non-finite value. */
int PX_SFX(px_lattice_cpu_rk4_stage)(struct px_lattice_cpu *e, const px_real *restrict ys,
                                     px_real *restrict yn, px_real *restrict y0,
                                     px_real *restrict acc, int stage, px_real dt, long r0,
                                     long r1) {
  const struct px_lattice_model *m = e->m;
  const size_t ns = e->ns, n0 = m->n0p;
  const size_t s1 = (size_t)m->stride[1], s2 = (size_t)m->stride[2];
  const uint8_t *restrict lpv = e->lp, *restrict lmv = e->lm, *restrict frv = e->free;
  const px_real *tab = (const px_real *)e->table;
  const struct lt_lpar p = *(const struct lt_lpar *)e->lpar;
  const px_real inv_m = (px_real)(1.0 / m->m), inv_i = (px_real)(1.0 / m->I),
                alpha = (px_real)e->alpha;
  const px_real cs = stage == 2 ? dt : (px_real)0.5 * dt, bs = (px_real)2;
  const px_real dt6 = dt / (px_real)6;
  const px_real *restrict pv = (const px_real *)e->pv;
  /* the boundary-condition elements of rows [r0, r1) */
  const long b0 = (long)e->bc_row[r0], b1 = (long)e->bc_row[r1];
  long r;
  int bad = 0;
#pragma omp parallel num_threads(e->active) reduction(| : bad)
  {
    px_real *restrict fl = (px_real *)e->scratch[omp_get_thread_num()] + e->flag_off;
#pragma omp for schedule(dynamic, LT_ROWS_CHUNK)
    for (r = r0; r < r1; ++r) {
      const size_t base = m->pad + (size_t)r * n0;
      const long lo = e->row_lo[r], hi = e->row_hi[r];
      px_real sum;
      lt_cpu_row_flags(lpv, lmv, frv, base, lo, hi, fl, n0, 2 * n0);
      sum = pv ? lt_cpu_rk4_rows(&p, ys, yn, y0, acc, fl, ns, n0, base, lo, hi, s1, s2, inv_m,
                                 inv_i, alpha, cs, dt6, stage, pv)
               : lt_cpu_rk4_rows(&p, ys, yn, y0, acc, fl, ns, n0, base, lo, hi, s1, s2, inv_m,
                                 inv_i, alpha, cs, dt6, stage, NULL);
      if (sum != 0 || sum != sum) bad |= 1;
    }
    /* elements with boundary conditions (implicit barrier above) */
#pragma omp for schedule(dynamic, LT_BC_CHUNK)
    for (r = b0; r < b1; ++r) {
      const size_t i = e->bc_list[r];
      struct lt_el k =
          lt_cpu_deriv(&p, ys, ns, i, s1, s2, lt_lfl_bits(lpv[i], lmv[i]),
                       tab + (size_t)e->bc_group[r] * LT_GROUP_STRIDE, inv_m, inv_i, alpha, pv);
      if (stage < 3) {
#define LT_B012(c, ev, kv)                                        \
  acc[(size_t)(c)*ns + i] += (stage == 0 ? (px_real)1 : bs) * kv; \
  yn[(size_t)(c)*ns + i] = y0[(size_t)(c)*ns + i] + cs * kv;
        LT_COMPS(LT_B012, k, k)
#undef LT_B012
      } else {
        struct lt_el yc;
        px_real chk = 0;
#define LT_B3(c, ev, kv) ev = y0[(size_t)(c)*ns + i] + dt6 * (acc[(size_t)(c)*ns + i] + kv);
        LT_COMPS(LT_B3, yc, k)
#undef LT_B3
        yc.q = lt_qrenorm(yc.q);
#define LT_BW3(c, ev, kv)      \
  y0[(size_t)(c)*ns + i] = ev; \
  chk += ev * (px_real)0;
        LT_COMPS(LT_BW3, yc, k)
#undef LT_BW3
        if (chk != 0 || chk != chk) bad |= 1;
      }
    }
  }
  return bad;
}

/* One leapfrog step (gather form): forces from ya (u, q at t; v, W at
 * t - dt/2), kick to t + dt/2, drift u, q to t + dt, into yb. Free elements
 * in the simd loop, then the boundary-condition elements again with their
 * group row. */
PX_FN_INLINE px_real lt_cpu_lf_elem(const struct lt_lpar *p, const px_real *restrict ya,
                                    px_real *restrict yb, size_t ns, size_t i, size_t s1, size_t s2,
                                    struct lt_lfl fl, const px_real *g, px_real inv_m,
                                    px_real inv_i, px_real had, px_real dt,
                                    const px_real *restrict pv) {
  struct lt_el el = lt_load(ya, ns, i), n;
  struct lt_ft ft =
      pv ? lt_gather_v(p, ya, pv, ns, i, s1, s2, fl, el) : lt_gather(p, ya, ns, i, s1, s2, fl, el);
  px_real sum = 0;
  n = lt_lf_new(el, ft.F, ft.T, g, inv_m, inv_i, had, dt);
#define LT_LW(c, ev, kv)       \
  yb[(size_t)(c)*ns + i] = ev; \
  sum += ev * (px_real)0;
  LT_COMPS(LT_LW, n, n)
#undef LT_LW
  return sum;
}

int PX_SFX(px_lattice_cpu_leapfrog)(struct px_lattice_cpu *e, const px_real *restrict ya,
                                    px_real *restrict yb, px_real dt, long r0, long r1) {
  const struct px_lattice_model *m = e->m;
  const size_t ns = e->ns, n0 = m->n0p;
  const size_t s1 = (size_t)m->stride[1], s2 = (size_t)m->stride[2];
  const uint8_t *restrict lpv = e->lp, *restrict lmv = e->lm, *restrict frv = e->free;
  const px_real *tab = (const px_real *)e->table;
  const struct lt_lpar p = *(const struct lt_lpar *)e->lpar;
  const px_real inv_m = (px_real)(1.0 / m->m), inv_i = (px_real)(1.0 / m->I);
  const px_real had = (px_real)(0.5 * e->alpha) * dt;
  const px_real *restrict pv = (const px_real *)e->pv;
  const long b0 = (long)e->bc_row[r0], b1 = (long)e->bc_row[r1];
  long r;
  int bad = 0;
#pragma omp parallel num_threads(e->active) reduction(| : bad)
  {
    px_real *restrict fl = (px_real *)e->scratch[omp_get_thread_num()] + e->flag_off;
#pragma omp for schedule(dynamic, LT_ROWS_CHUNK)
    for (r = r0; r < r1; ++r) {
      const size_t base = m->pad + (size_t)r * n0;
      const long lo = e->row_lo[r], hi = e->row_hi[r];
      long x;
      px_real sum = 0;
      lt_cpu_row_flags(lpv, lmv, frv, base, lo, hi, fl, n0, 2 * n0);
      /* pv tested outside the simd loops (see lt_cpu_rk4_rows) */
      if (pv) {
        LT_SIMD_SUM
        for (x = lo; x < hi; ++x) {
          const size_t i = base + (size_t)x;
          sum += lt_cpu_lf_elem(&p, ya, yb, ns, i, s1, s2, lt_lfl_row(fl, n0, (size_t)x), NULL,
                                inv_m, inv_i, had, dt, pv);
        }
      } else {
        LT_SIMD_SUM
        for (x = lo; x < hi; ++x) {
          const size_t i = base + (size_t)x;
          sum += lt_cpu_lf_elem(&p, ya, yb, ns, i, s1, s2, lt_lfl_row(fl, n0, (size_t)x), NULL,
                                inv_m, inv_i, had, dt, NULL);
        }
      }
      if (sum != 0 || sum != sum) bad |= 1;
    }
#pragma omp for schedule(dynamic, LT_BC_CHUNK)
    for (r = b0; r < b1; ++r) {
      const size_t i = e->bc_list[r];
      px_real sum =
          lt_cpu_lf_elem(&p, ya, yb, ns, i, s1, s2, lt_lfl_bits(lpv[i], lmv[i]),
                         tab + (size_t)e->bc_group[r] * LT_GROUP_STRIDE, inv_m, inv_i, had, dt, pv);
      if (sum != 0 || sum != sum) bad |= 1;
    }
  }
  return bad;
}

/* the volumetric coefficients' loops (they use the row helpers above) */
#include "solvers/lattice/lattice_cpu_vol_impl.h"

/* ---------------------------------------------------------------------------
 * Link-once scheme. Threads sweep slabs of z-planes and walk each plane's
 * rows in order; for a row they evaluate the row's x-, y- and z-links once
 * (simple simd loops with few live values) into scratch buffers, then
 * gather each element's six link results and update it. The y-minus links
 * of a row are the previous row's y-plus links and one side's z-links of a
 * plane the previous plane's (rolling buffers); a sweep's first plane
 * evaluates those itself (lt_cpu_l1_plane). Leapfrog and the per-stage RK4
 * passes sweep upward (px_lattice_cpu_pass_l1); RK4 on 1-2 threads runs its four
 * stages in one sweep (px_lattice_cpu_rk4_l1). Scratch layout: 6 components
 * (F.x F.y F.z G.x G.y G.z) with stride os. */

/* The plus links along axis a of row elements x in [lo, hi) into out[c os + x],
 * times their flags fla[x] (flag row a of lt_cpu_row_flags); with the
 * volumetric force when pa is not NULL: pa[x], pb[x] the coefficients P_a of
 * the link's minus and plus ends (lt_cpu_prow). */
PX_FN_INLINE void lt_cpu_link_row(const struct lt_lpar *p, const px_real *restrict y,
                                  const px_real *restrict pa, const px_real *restrict pb, size_t ns,
                                  size_t base, long lo, long hi, size_t s, int a,
                                  const px_real *restrict fla, px_real *restrict out, size_t os) {
  long x;
  if (pa) {
    LT_SIMD
    for (x = lo; x < hi; ++x) {
      const size_t i = base + (size_t)x;
      lt_link_put_v(p, a, lt_load(y, ns, i), lt_load(y, ns, i + s), pa[x] + pb[x], fla[x], out, os,
                    (size_t)x);
    }
    return;
  }
  LT_SIMD
  for (x = lo; x < hi; ++x) {
    const size_t i = base + (size_t)x;
    lt_link_put(p, a, lt_load(y, ns, i), lt_load(y, ns, i + s), fla[x], out, os, (size_t)x);
  }
}

/* Zero the link results of a row outside [lo, hi) (void cells: a
 * neighbouring row may be longer and read them). */
static void lt_cpu_zero_out(px_real *out, size_t os, long lo, long hi, long n) {
  int c;
  for (c = 0; c < 6; ++c) {
    px_real *o = out + (size_t)c * os;
    if (lo > 0) memset(o, 0, (size_t)lo * sizeof(px_real));
    if (hi < n) memset(o + hi, 0, (size_t)(n - hi) * sizeof(px_real));
  }
}

/* Force and moment on element x of a row from its six link results. */
PX_FN_INLINE struct lt_ft lt_cpu_sum_links(px_real h2, struct lt_q4 q, const px_real *restrict lxp,
                                           const px_real *restrict lxm, const px_real *restrict lyp,
                                           const px_real *restrict lym, const px_real *restrict lzp,
                                           const px_real *restrict lzm, size_t osx, size_t osy,
                                           size_t osz, size_t x) {
  struct lt_ft r;
  r.F = lt_v3_make(0, 0, 0);
  r.T = lt_v3_make(0, 0, 0);
  r = lt_sum_axis(h2, q, 0, lxp, lxm, osx, x, x, r);
  r = lt_sum_axis(h2, q, 1, lyp, lym, osy, x, x, r);
  return lt_sum_axis(h2, q, 2, lzp, lzm, osz, x, x, r);
}

/* Gather and RK4-update the elements of one row (stage as in cpu_rk4_stage;
 * a constant after inlining, so the simd loop has no branch). */
PX_FN_INLINE void lt_cpu_row_rk4(const struct lt_lpar *p, const px_real *restrict ys,
                                 px_real *restrict yn, px_real *restrict y0, px_real *restrict acc,
                                 size_t ns, size_t base, long lo, long hi,
                                 const px_real *restrict frow, const px_real *restrict lxp,
                                 const px_real *restrict lxm, const px_real *restrict lyp,
                                 const px_real *restrict lym, const px_real *restrict lzp,
                                 const px_real *restrict lzm, size_t osx, size_t osy, size_t osz,
                                 px_real inv_m, px_real inv_i, px_real alpha, px_real cs,
                                 px_real dt6, const int stage, px_real *sum) {
  long x;
  px_real sm = 0;
  LT_SIMD_SM
  for (x = lo; x < hi; ++x) {
    const size_t i = base + (size_t)x;
    const px_real fr = frow[x];
    struct lt_el el = lt_load(ys, ns, i);
    struct lt_ft f =
        lt_cpu_sum_links(p->h2, el.q, lxp, lxm, lyp, lym, lzp, lzm, osx, osy, osz, (size_t)x);
    struct lt_el k = lt_deriv(el, lt_accel_free(inv_m, inv_i, alpha, f.F, f.T, el.v, el.W));
    if (stage == 0) {
#define LT_S0(c, ev, kv)             \
  acc[(size_t)(c)*ns + i] = fr * kv; \
  yn[(size_t)(c)*ns + i] = y0[(size_t)(c)*ns + i] + cs * kv;
      LT_COMPS(LT_S0, k, k)
#undef LT_S0
    } else if (stage < 3) {
#define LT_S12(c, ev, kv)                          \
  acc[(size_t)(c)*ns + i] += fr * (px_real)2 * kv; \
  yn[(size_t)(c)*ns + i] = y0[(size_t)(c)*ns + i] + cs * kv;
      LT_COMPS(LT_S12, k, k)
#undef LT_S12
    } else {
      struct lt_el yc;
#define LT_S3(c, ev, kv) ev = y0[(size_t)(c)*ns + i] + fr * dt6 * (acc[(size_t)(c)*ns + i] + kv);
      LT_COMPS(LT_S3, yc, k)
#undef LT_S3
      yc.q = lt_qrenorm(yc.q);
#define LT_W3(c, ev, kv)       \
  y0[(size_t)(c)*ns + i] = ev; \
  sm += ev * (px_real)0;
      LT_COMPS(LT_W3, yc, k)
#undef LT_W3
    }
  }
  *sum += sm;
}

/* Gather and leapfrog-update the free elements of one row (ya -> yb). */
PX_FN_INLINE void lt_cpu_row_lf(const struct lt_lpar *p, const px_real *restrict ya,
                                px_real *restrict yb, size_t ns, size_t base, long lo, long hi,
                                const px_real *restrict lxp, const px_real *restrict lxm,
                                const px_real *restrict lyp, const px_real *restrict lym,
                                const px_real *restrict lzp, const px_real *restrict lzm,
                                size_t osx, size_t osy, size_t osz, px_real inv_m, px_real inv_i,
                                px_real had, px_real dt, px_real *sum) {
  long x;
  px_real sm = 0;
  LT_SIMD_SM
  for (x = lo; x < hi; ++x) {
    const size_t i = base + (size_t)x;
    struct lt_el el = lt_load(ya, ns, i);
    struct lt_ft ft =
        lt_cpu_sum_links(p->h2, el.q, lxp, lxm, lyp, lym, lzp, lzm, osx, osy, osz, (size_t)x);
    struct lt_el n = lt_lf_new(el, ft.F, ft.T, NULL, inv_m, inv_i, had, dt);
#define LT_LW1(c, ev, kv)      \
  yb[(size_t)(c)*ns + i] = ev; \
  sm += ev * (px_real)0;
    LT_COMPS(LT_LW1, n, n)
#undef LT_LW1
  }
  *sum += sm;
}

/* Redo the boundary-condition elements of one row, bc_list[b0, b1), with
 * their group rows g in tab (the simd row loop took them as free), from the row's
 * link results: RK4 stage `stage` or, with stage < 0, a leapfrog step, as in
 * px_lattice_cpu_pass_l1. The links are canonical, so the forces are bit-identical
 * to the gather form's. Returns 0 times every value written (a NaN check). */
static px_real lt_cpu_row_bc(const struct px_lattice_cpu *e, const px_real *tab,
                             const struct lt_lpar *p, const px_real *restrict ys,
                             px_real *restrict yn, px_real *restrict y0, px_real *restrict acc,
                             size_t ns, size_t base, size_t b0, size_t b1,
                             const px_real *restrict lxp, const px_real *restrict lxm,
                             const px_real *restrict lyp, const px_real *restrict lym,
                             const px_real *restrict lzp, const px_real *restrict lzm, size_t osx,
                             size_t osy, size_t osz, px_real inv_m, px_real inv_i, px_real alpha,
                             px_real had, px_real cs, px_real dt6, px_real dt, int stage) {
  px_real chk = 0;
  size_t b;
  for (b = b0; b < b1; ++b) {
    const size_t i = e->bc_list[b], x = i - base;
    const px_real *g = tab + (size_t)e->bc_group[b] * LT_GROUP_STRIDE;
    struct lt_el el = lt_load(ys, ns, i);
    struct lt_ft f = lt_cpu_sum_links(p->h2, el.q, lxp, lxm, lyp, lym, lzp, lzm, osx, osy, osz, x);
    if (stage < 0) {
      struct lt_el n = lt_lf_new(el, f.F, f.T, g, inv_m, inv_i, had, dt);
#define LT_BL(c, ev, kv)       \
  yn[(size_t)(c)*ns + i] = ev; \
  chk += ev * (px_real)0;
      LT_COMPS(LT_BL, n, n)
#undef LT_BL
    } else {
      struct lt_el k = lt_deriv(el, lt_accel(g, inv_m, inv_i, alpha, f.F, f.T, el.v, el.W));
      if (stage < 3) {
#define LT_C012(c, ev, kv)                                                \
  acc[(size_t)(c)*ns + i] += (stage == 0 ? (px_real)1 : (px_real)2) * kv; \
  yn[(size_t)(c)*ns + i] = y0[(size_t)(c)*ns + i] + cs * kv;
        LT_COMPS(LT_C012, k, k)
#undef LT_C012
      } else {
        struct lt_el yc;
#define LT_C3(c, ev, kv) ev = y0[(size_t)(c)*ns + i] + dt6 * (acc[(size_t)(c)*ns + i] + kv);
        LT_COMPS(LT_C3, yc, k)
#undef LT_C3
        yc.q = lt_qrenorm(yc.q);
#define LT_CW3(c, ev, kv)      \
  y0[(size_t)(c)*ns + i] = ev; \
  chk += ev * (px_real)0;
        LT_COMPS(LT_CW3, yc, k)
#undef LT_CW3
      }
    }
  }
  return chk;
}

/* Per-thread link-once scratch of one pass (lt_cpu_l1_scratch): x-links of a
 * row (offset 1, so that index 0 is the x-minus link of cell 0), y-links of
 * two rows and z-links of two planes (rolling), 6 components each. */
struct lt_l1s {
  px_real *sx, *sy[2], *sz[2];
};

/* Scratch set k (0..3: one per RK4 stage in the fused sweep) of thread tid. */
static struct lt_l1s lt_cpu_l1_scratch(const struct px_lattice_cpu *e, int tid, int k) {
  const size_t n0 = e->m->n0p, osx = n0 + 1, osy = n0, osz = n0 * (size_t)e->m->grid.n[1];
  struct lt_l1s s;
  s.sx = (px_real *)e->scratch[tid] + (size_t)k * LT_L1_WORDS(n0, (size_t)e->m->grid.n[1]);
  s.sy[0] = s.sx + 6 * osx;
  s.sy[1] = s.sy[0] + 6 * osy;
  s.sz[0] = s.sy[1] + 6 * osy;
  s.sz[1] = s.sz[0] + 6 * osz;
  return s;
}

/* Component a of the coefficients of row yy of plane z (lt_cpu_prow), or
 * NULL at nu = 0 (in lt_cpu_l1_plane). */
#define LT_PR(z, yy, a) (pw ? lt_cpu_prow(pw, m, (z), (long)(yy), (a)) : NULL)

/* Plane z, link-once: RK4 stage `stage` (0..3, as in px_lattice_cpu_rk4_stage, group
 * rows from tab) or, with stage < 0, a leapfrog step (ys = ya, yn = yb). For
 * each row it evaluates the row's x-, y- and z-links once (simple simd loops
 * with few live values) into the scratch sc, then sums each element's six
 * link results and updates it; the row's boundary-condition elements are
 * then redone with their group rows from the same link results. The y-minus
 * links of a row are the previous row's y-plus links. Planes are taken in
 * sweep direction dir: upward (+1) a plane evaluates its z-plus links and
 * takes its z-minus links from the previous plane's; downward (-1) it
 * evaluates its z-minus links (the same canonical link, minus end first, so
 * the same bits) and takes its z-plus links from the previous plane. The
 * first plane of a sweep (first) evaluates the links it would have taken
 * from the previous plane. pw: where the links read the volumetric
 * coefficients of ys (NULL at nu = 0). Returns 0 times every value written
 * (a NaN check). */
static px_real lt_cpu_l1_plane(struct px_lattice_cpu *e, const struct lt_l1s *sc,
                               px_real *restrict fl, const px_real *restrict ys,
                               px_real *restrict yn, px_real *restrict y0, px_real *restrict acc,
                               const px_real *tab, const struct lt_pw *pw, int stage, long z,
                               int dir, int first, px_real dt) {
  const struct px_lattice_model *m = e->m;
  const size_t ns = e->ns, n0 = m->n0p, n1 = (size_t)m->grid.n[1];
  const long nz = m->grid.n[2];
  const size_t s1 = (size_t)m->stride[1], s2 = (size_t)m->stride[2];
  const uint8_t *restrict lpv = e->lp, *restrict lmv = e->lm, *restrict frv = e->free;
  const struct lt_lpar p = *(const struct lt_lpar *)e->lpar;
  const px_real inv_m = (px_real)(1.0 / m->m), inv_i = (px_real)(1.0 / m->I),
                alpha = (px_real)e->alpha;
  const px_real cs = stage == 2 ? dt : (px_real)0.5 * dt, dt6 = dt / (px_real)6;
  const px_real had = (px_real)(0.5 * e->alpha) * dt;
  const size_t osx = n0 + 1, osy = n0, osz = n0 * n1;
  /* cur: the z-links this plane evaluates; prev: those it takes over */
  px_real *sx = sc->sx, *cur = sc->sz[z & 1], *prev = sc->sz[(z + 1) & 1];
  const int edge = dir > 0 ? z == 0 : z == nz - 1;
  px_real sum = 0;
  long yy;
  {
    int c;
    for (c = 0; c < 6; ++c) sx[(size_t)c * osx] = 0;
  }
  if (edge)
    memset(prev, 0, 6 * osz * sizeof(px_real));
  else if (first && dir > 0)
    /* z-links of the plane below */
    for (yy = 0; yy < (long)n1; ++yy) {
      const long rr = (z - 1) * (long)n1 + yy;
      const size_t base = m->pad + (size_t)rr * n0;
      lt_cpu_row_flags(lpv, lmv, frv, base, e->row_lo[rr], e->row_hi[rr], fl, n0, 2 * n0);
      lt_cpu_link_row(&p, ys, LT_PR(z - 1, yy, 2), LT_PR(z, yy, 2), ns, base, e->row_lo[rr],
                      e->row_hi[rr], s2, 2, fl + 2 * n0, prev + (size_t)yy * n0, osz);
      lt_cpu_zero_out(prev + (size_t)yy * n0, osz, e->row_lo[rr], e->row_hi[rr], (long)n0);
    }
  for (yy = 0; yy < (long)n1; ++yy) {
    const long rr = z * (long)n1 + yy;
    const size_t base = m->pad + (size_t)rr * n0;
    const long lo = e->row_lo[rr], hi = e->row_hi[rr];
    px_real *lyp = sc->sy[yy & 1], *lym = sc->sy[(yy + 1) & 1];
    px_real *rc = cur + (size_t)yy * n0, *rv = prev + (size_t)yy * n0;
    px_real *rzp = dir > 0 ? rc : rv, *rzm = dir > 0 ? rv : rc;
    if (yy == 0) memset(lym, 0, 6 * osy * sizeof(px_real));
    /* links with a void plus end are flagged absent: computing them is
     * harmless, and rows of different lengths need the z/y results of
     * their whole range */
    const px_real *pxr = LT_PR(z, yy, 0), *pyr = LT_PR(z, yy, 1);
    lt_cpu_row_flags(lpv, lmv, frv, base, lo, hi, fl, n0, 2 * n0);
    /* the plus ends of x- and y-links: +1, +n0 (row 0 of the next plane
     * for the last row: see lattice_cpu_vol_impl.h) */
    lt_cpu_link_row(&p, ys, pxr, pxr ? pxr + 1 : NULL, ns, base, lo, hi, 1, 0, fl, sx + 1, osx);
    lt_cpu_link_row(&p, ys, pyr, pyr ? pyr + n0 : NULL, ns, base, lo, hi, s1, 1, fl + n0, lyp, osy);
    if (dir > 0) {
      lt_cpu_link_row(&p, ys, LT_PR(z, yy, 2), LT_PR(z + 1, yy, 2), ns, base, lo, hi, s2, 2,
                      fl + 2 * n0, rc, osz);
    } else {
      /* minus links: the row below is the minus end (its padding at z = 0) */
      lt_cpu_link_row(&p, ys, LT_PR(z - 1, yy, 2), LT_PR(z, yy, 2), ns, base - s2, lo, hi, s2, 2,
                      fl + 5 * n0, rc, osz);
      if (first && !edge) {
        lt_cpu_link_row(&p, ys, LT_PR(z, yy, 2), LT_PR(z + 1, yy, 2), ns, base, lo, hi, s2, 2,
                        fl + 2 * n0, rv, osz);
        lt_cpu_zero_out(rv, osz, lo, hi, (long)n0);
      }
    }
    lt_cpu_zero_out(lyp, osy, lo, hi, (long)n0);
    lt_cpu_zero_out(rc, osz, lo, hi, (long)n0);
    if (lo > 0) {
      int c;
      for (c = 0; c < 6; ++c) sx[(size_t)c * osx + (size_t)lo] = 0;
    }
    if (stage < 0)
      lt_cpu_row_lf(&p, ys, yn, ns, base, lo, hi, sx + 1, sx, lyp, lym, rzp, rzm, osx, osy, osz,
                    inv_m, inv_i, had, dt, &sum);
    else if (stage == 0)
      lt_cpu_row_rk4(&p, ys, yn, y0, acc, ns, base, lo, hi, fl + 6 * n0, sx + 1, sx, lyp, lym, rzp,
                     rzm, osx, osy, osz, inv_m, inv_i, alpha, cs, dt6, 0, &sum);
    else if (stage < 3)
      lt_cpu_row_rk4(&p, ys, yn, y0, acc, ns, base, lo, hi, fl + 6 * n0, sx + 1, sx, lyp, lym, rzp,
                     rzm, osx, osy, osz, inv_m, inv_i, alpha, cs, dt6, 1, &sum);
    else
      lt_cpu_row_rk4(&p, ys, yn, y0, acc, ns, base, lo, hi, fl + 6 * n0, sx + 1, sx, lyp, lym, rzp,
                     rzm, osx, osy, osz, inv_m, inv_i, alpha, cs, dt6, 3, &sum);
    if (e->bc_row[rr] < e->bc_row[rr + 1])
      sum += lt_cpu_row_bc(e, tab, &p, ys, yn, y0, acc, ns, base, e->bc_row[rr], e->bc_row[rr + 1],
                           sx + 1, sx, lyp, lym, rzp, rzm, osx, osy, osz, inv_m, inv_i, alpha, had,
                           cs, dt6, dt, stage);
  }
  return sum;
}

#undef LT_PR

/* One link-once pass over all elements: a leapfrog step (stage < 0; ys = ya,
 * yn = yb) or one RK4 stage. A thread sweeps a slab of z-planes upward. */
int PX_SFX(px_lattice_cpu_pass_l1)(struct px_lattice_cpu *e, const px_real *restrict ys,
                                   px_real *restrict yn, px_real *restrict y0,
                                   px_real *restrict acc, int stage, px_real dt, long za, long zb) {
  const long nz = zb - za;
  const int nt = e->active;
  /* slabs taken in turn (lattice_cpu.h, LT_SLAB_MIN); a slab's first plane
   * evaluates its links as the rolling buffers do: the same bits */
  long nslab = nt > 1 ? (long)LT_SLABS_PER_THREAD * nt : 1, k;
  /* the coefficients of ys: px_lattice_cpu_vol before the pass */
  const struct lt_pw gw = {(px_real *)e->pv, e->ns, 0};
  int bad = 0;
  if (nslab > nz / LT_SLAB_MIN) nslab = nz / LT_SLAB_MIN;
  if (nslab < nt) nslab = nt;
#pragma omp parallel num_threads(nt) reduction(| : bad)
  {
    const int tid = omp_get_thread_num();
    const struct lt_l1s sc = lt_cpu_l1_scratch(e, tid, 0);
    px_real *fl = (px_real *)e->scratch[tid] + e->flag_off;
    px_real sum = 0;
#pragma omp for schedule(dynamic, 1)
    for (k = 0; k < nslab; ++k) {
      const long z0 = za + nz * k / nslab, z1 = za + nz * (k + 1) / nslab;
      for (long z = z0; z < z1; ++z)
        sum += lt_cpu_l1_plane(e, &sc, fl, ys, yn, y0, acc, (const px_real *)e->table,
                               e->pv ? &gw : NULL, stage, z, 1, z == z0, dt);
    }
    if (sum != 0 || sum != sum) bad |= 1;
  }
  return bad;
}

/* One RK4 step, link-once, all four stages in one sweep over the z-planes
 * (temporal blocking): at sweep step t stage s works on the plane t - L s
 * places along the sweep, in stage order, so that a plane's stage states and
 * increments are reused while they are still in cache instead of streaming
 * the four state buffers through memory once per stage. Stage s at plane p
 * needs the stage-s states of planes p - 1 .. p + 1, written by stage s - 1
 * at the same or an earlier sweep step (L >= 1). With the volumetric term
 * (nu != 0) stage s first computes the coefficients of plane p + 1 into its
 * window (lt_cpu_vol_plane; at its first plane those of p - 1 and p too),
 * which needs the stage-s state of p + 2: L = 2. Buffers and arithmetic are
 * those of four px_lattice_cpu_pass_l1 stages (the same bits): y0 the
 * state, ya, yb the stage states (stage 0 writes ya, 1 yb, 2 ya, 3 updates
 * y0 in place), acc the increments; stage 2 overwrites ya[p] at step p + 2L,
 * not before the last reader of stage 1's ya[p] (stage 1 at plane p + 1,
 * step p + 1 + L, earlier in the step for L = 1), stage 3 y0[p] at step
 * p + 3L, after its last reader (stage 0 at plane p + 1: step p + 1).
 * One thread sweeps upward over all planes. Two threads split the planes in
 * halves and sweep away from the middle (the lower half downward), so they
 * share data only in their first 3L sweep steps (each reads the other's
 * first L planes for the links and coefficients across the middle, each
 * computing those coefficients itself): a barrier after each of those, none
 * later. More threads: not handled here (lt_cpu_run uses the per-stage
 * passes). tabs: group tables at t, t + dt/2, t + dt. */
int PX_SFX(px_lattice_cpu_rk4_l1)(struct px_lattice_cpu *e, px_real *restrict y0,
                                  px_real *restrict ya, px_real *restrict yb, px_real *restrict acc,
                                  const px_real *const tabs[3], px_real dt) {
  const long nz = e->m->grid.n[2];
  const long L = e->pv ? 2 : 1;
  int bad = 0;
#pragma omp parallel num_threads(e->active < 2 ? e->active : 2) reduction(| : bad)
  {
    const int tid = omp_get_thread_num(), nt = omp_get_num_threads();
    const long zh = nt == 2 ? nz / 2 : 0, len = tid == 0 ? (nt == 2 ? zh : nz) : nz - zh;
    const long zs = tid == 0 ? (nt == 2 ? zh - 1 : 0) : zh;
    const int dir = tid == 0 && nt == 2 ? -1 : 1;
    struct lt_l1s sc[4];
    struct lt_pw pw[4];
    px_real *fl = (px_real *)e->scratch[tid] + e->flag_off;
    px_real sum = 0;
    long t;
    int s;
    for (s = 0; s < 4; ++s) {
      sc[s] = lt_cpu_l1_scratch(e, tid, s);
      pw[s].p = (px_real *)e->scratch[tid] + e->pw_off +
                (size_t)s * LT_PW_WORDS(e->m->n0p, (size_t)e->m->grid.n[1]);
      pw[s].cs = ((size_t)e->m->grid.n[1] + 1) * e->m->n0p;
      pw[s].win = 1;
    }
    for (t = 0; t < len + 3 * L || t < 3 * L; ++t) {
      for (s = 0; s < 4; ++s) {
        const long k = t - L * s, z = zs + dir * k;
        const px_real *ys = s == 0 ? y0 : (s == 2 ? yb : ya);
        px_real *yn = s == 1 ? yb : ya;
        const px_real *tab = tabs[s == 0 ? 0 : (s == 3 ? 2 : 1)];
        if (k < 0 || k >= len) continue;
        if (e->pv) {
          if (k == 0) {
            lt_cpu_vol_plane(e, fl, ys, &pw[s], z - dir);
            lt_cpu_vol_plane(e, fl, ys, &pw[s], z);
          }
          lt_cpu_vol_plane(e, fl, ys, &pw[s], z + dir);
        }
        sum += lt_cpu_l1_plane(e, &sc[s], fl, ys, yn, y0, acc, tab, e->pv ? &pw[s] : NULL, s, z,
                               dir, k == 0, dt);
      }
      if (t < 3 * L) {
#pragma omp barrier
      }
    }
    if (sum != 0 || sum != sum) bad |= 1;
  }
  return bad;
}

#endif
