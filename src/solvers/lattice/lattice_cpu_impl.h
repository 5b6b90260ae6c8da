/* The cpu engine's loops for one real type (included by lattice_cpu.c once
 * per type with LT_R, LT_, LT_SQRT defined; no include guard).
 *
 * State buffers are SoA: component k (u.x u.y u.z q.w q.x q.y q.z v.x v.y
 * v.z W.x W.y W.z) of element i is buf[k ns + i]. Loops run over grid rows
 * (fixed y, z): OpenMP threads take contiguous blocks of rows (static
 * schedule, so results do not depend on timing), and the x loop inside a row
 * is a `#pragma omp simd` loop whose neighbours i +- 1, i +- n0, i +- n0 n1
 * are unit-stride vector loads. */

/* Load element j of a state buffer. */
LT_FN struct LT_(el) LT_(cpu_load)(const LT_R *restrict y, size_t ns, size_t j) {
  struct LT_(el) e;
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
 * reals. The simd loops read them from a per-row real array (lt_cpu_row_flags)
 * rather than from the uint8 link bytes: gcc sizes a loop's vector by its
 * narrowest type, so one uint8 load makes it 64 lanes wide (8 zmm registers
 * per double, no vector iteration at all for rows under 64 cells) or 16
 * lanes of 128-bit vectors (4 xmm registers per float), whatever simdlen
 * says; with reals only it is one register per value. */
struct LT_(lfl) {
  LT_R xp, yp, zp, xm, ym, zm;
};

/* Flags from the link bytes (scalar code). */
LT_FN struct LT_(lfl) LT_(lfl_bits)(unsigned lp, unsigned lm) {
  struct LT_(lfl) f;
  f.xp = (LT_R)(lp & 1u);
  f.yp = (LT_R)((lp >> 1) & 1u);
  f.zp = (LT_R)((lp >> 2) & 1u);
  f.xm = (LT_R)((lm >> 3) & 1u);
  f.ym = (LT_R)((lm >> 4) & 1u);
  f.zm = (LT_R)((lm >> 5) & 1u);
  return f;
}

/* Number of reals per row cell of the flag rows: the six link flags, then
 * the free flag (lt_cpu_row_flags). */
#define LT_ROW_FLAGS 7

/* Flags of row cells x in [lo, hi) (element base + x) into fl[c os + x]:
 * c = 0..5 the link flags in lt_lfl order, c = 6 the free flag. */
static void LT_(cpu_row_flags)(const uint8_t *restrict lpv, const uint8_t *restrict lmv,
                               const uint8_t *restrict frv, size_t base, long lo, long hi,
                               LT_R *restrict fl, size_t os) {
  long x;
  for (x = lo; x < hi; ++x) {
    const size_t i = base + (size_t)x, xs = (size_t)x;
    const unsigned lp = lpv[i], lm = lmv[i];
    fl[xs] = (LT_R)(lp & 1u);
    fl[os + xs] = (LT_R)((lp >> 1) & 1u);
    fl[2 * os + xs] = (LT_R)((lp >> 2) & 1u);
    fl[3 * os + xs] = (LT_R)((lm >> 3) & 1u);
    fl[4 * os + xs] = (LT_R)((lm >> 4) & 1u);
    fl[5 * os + xs] = (LT_R)((lm >> 5) & 1u);
    fl[6 * os + xs] = (LT_R)frv[i];
  }
}

/* Flags of row cell x from the flag rows. */
LT_FN struct LT_(lfl) LT_(lfl_row)(const LT_R *restrict fl, size_t os, size_t x) {
  struct LT_(lfl) f;
  f.xp = fl[x];
  f.yp = fl[os + x];
  f.zp = fl[2 * os + x];
  f.xm = fl[3 * os + x];
  f.ym = fl[4 * os + x];
  f.zm = fl[5 * os + x];
  return f;
}

/* Add the two links of element i along axis a (gather form) to acc. Both
 * links are evaluated canonically (minus end first) and multiplied by their
 * 0/1 flags fp, fm. */
LT_FN struct LT_(ft) LT_(cpu_axis)(const struct LT_(lpar) *p, const LT_R *restrict y, size_t ns,
                                   size_t i, size_t s, int a, LT_R fp, LT_R fm,
                                   struct LT_(el) e, struct LT_(ft) acc) {
  struct LT_(v3) bs = LT_(frame_col)(e.q, a);
  struct LT_(el) en = LT_(cpu_load)(y, ns, i + s);
  struct LT_(el) em = LT_(cpu_load)(y, ns, i - s);
  struct LT_(lres) rp = LT_(link)(p, a, e, en, bs, LT_(frame_col)(en.q, a));
  struct LT_(lres) rm = LT_(link)(p, a, em, e, LT_(frame_col)(em.q, a), bs);
  return LT_(axis_acc)(p->h2, a, bs, LT_(v3_scale)(fp, rp.F), LT_(v3_scale)(fp, rp.G),
                       LT_(v3_scale)(fm, rm.F), LT_(v3_scale)(fm, rm.G), acc);
}

/* Link forces and moments (global) of element i from its six links. */
LT_FN struct LT_(ft) LT_(cpu_gather)(const struct LT_(lpar) *p, const LT_R *restrict y,
                                     size_t ns, size_t i, size_t s1, size_t s2,
                                     struct LT_(lfl) fl, struct LT_(el) e) {
  struct LT_(ft) r;
  r.F = LT_(v3_make)(0, 0, 0);
  r.T = LT_(v3_make)(0, 0, 0);
  r = LT_(cpu_axis)(p, y, ns, i, 1, 0, fl.xp, fl.xm, e, r);
  r = LT_(cpu_axis)(p, y, ns, i, s1, 1, fl.yp, fl.ym, e, r);
  return LT_(cpu_axis)(p, y, ns, i, s2, 2, fl.zp, fl.zm, e, r);
}

/* The 13 state components, in buffer order, of an element and its
 * derivative (for writing out loops by hand: the vectorizer does not unroll
 * inner loops of a simd loop). */
#define LT_COMPS(X, e, d)                                                       \
  X(0, e.u.x, d.u.x) X(1, e.u.y, d.u.y) X(2, e.u.z, d.u.z) X(3, e.q.w, d.q.w)   \
  X(4, e.q.x, d.q.x) X(5, e.q.y, d.q.y) X(6, e.q.z, d.q.z) X(7, e.v.x, d.v.x)   \
  X(8, e.v.y, d.v.y) X(9, e.v.z, d.v.z) X(10, e.W.x, d.W.x) X(11, e.W.y, d.W.y) \
  X(12, e.W.z, d.W.z)

/* Derivative of element i's state at stage state ys: (v, dq/dt, dv/dt, dW/dt),
 * with the group row g, or as a free element when g is NULL. */
LT_FN struct LT_(el) LT_(cpu_deriv)(const struct LT_(lpar) *p, const LT_R *restrict ys, size_t ns,
                                    size_t i, size_t s1, size_t s2, struct LT_(lfl) fl,
                                    const LT_R *g, LT_R inv_m, LT_R inv_i, LT_R alpha) {
  struct LT_(el) el = LT_(cpu_load)(ys, ns, i), k;
  struct LT_(ft) f = LT_(cpu_gather)(p, ys, ns, i, s1, s2, fl, el);
  struct LT_(dvw) d = g ? LT_(accel)(g, inv_m, inv_i, alpha, f.F, f.T, el.v, el.W)
                        : LT_(accel_free)(inv_m, inv_i, alpha, f.F, f.T, el.v, el.W);
  k.v = d.dv;
  k.W = d.dW;
  k.q = LT_(qdot)(el.q, el.W);
  k.u = el.v;
  return k;
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
static int LT_(cpu_rk4_stage)(struct px_lattice_cpu *e, const LT_R *restrict ys,
                              LT_R *restrict yn, LT_R *restrict y0, LT_R *restrict acc,
                              int stage, LT_R dt) {
  const struct px_lattice_model *m = e->m;
  const size_t ns = e->ns, n0 = m->n0p;
  const size_t s1 = (size_t)m->stride[1], s2 = (size_t)m->stride[2];
  const size_t nrow = (size_t)m->grid.n[1] * (size_t)m->grid.n[2];
  const uint8_t *restrict lpv = e->lp, *restrict lmv = e->lm, *restrict frv = e->free;
  const LT_R *tab = (const LT_R *)e->table;
  const struct LT_(lpar) p = *(const struct LT_(lpar) *)e->lpar;
  const LT_R inv_m = (LT_R)(1.0 / m->m), inv_i = (LT_R)(1.0 / m->I), alpha = (LT_R)e->alpha;
  const LT_R cs = stage == 2 ? dt : (LT_R)0.5 * dt, bs = (LT_R)2;
  const LT_R dt6 = dt / (LT_R)6;
  const long nbc = (long)e->nbc;
  long r;
  int bad = 0;
#pragma omp parallel num_threads(e->threads) reduction(| : bad)
  {
    LT_R *restrict fl = (LT_R *)e->scratch[omp_get_thread_num()] + e->flag_off;
#pragma omp for schedule(static)
    for (r = 0; r < (long)nrow; ++r) {
      const size_t base = m->pad + (size_t)r * n0;
      const long lo = e->row_lo[r], hi = e->row_hi[r];
      long x;
      LT_R sum = 0;
      LT_(cpu_row_flags)(lpv, lmv, frv, base, lo, hi, fl, n0);
#define LT_DERIV                                                                \
  const size_t i = base + (size_t)x;                                            \
  const LT_R fr = fl[6 * n0 + (size_t)x];                                       \
  struct LT_(el) k = LT_(cpu_deriv)(&p, ys, ns, i, s1, s2,                      \
                                    LT_(lfl_row)(fl, n0, (size_t)x), NULL, inv_m, \
                                    inv_i, alpha);
      if (stage == 0) {
LT_SIMD
        for (x = lo; x < hi; ++x) {
          LT_DERIV
#define LT_S0(c, ev, kv)                                                        \
  acc[(size_t)(c) * ns + i] = fr * kv;                                          \
  yn[(size_t)(c) * ns + i] = y0[(size_t)(c) * ns + i] + cs * kv;
          LT_COMPS(LT_S0, k, k)
#undef LT_S0
        }
      } else if (stage < 3) {
LT_SIMD
        for (x = lo; x < hi; ++x) {
          LT_DERIV
#define LT_S12(c, ev, kv)                                                       \
  acc[(size_t)(c) * ns + i] += fr * bs * kv;                                    \
  yn[(size_t)(c) * ns + i] = y0[(size_t)(c) * ns + i] + cs * kv;
          LT_COMPS(LT_S12, k, k)
#undef LT_S12
        }
      } else {
LT_SIMD_SUM
        for (x = lo; x < hi; ++x) {
          LT_DERIV
          struct LT_(el) yc;
#define LT_S3(c, ev, kv)                                                        \
  ev = y0[(size_t)(c) * ns + i] + fr * dt6 * (acc[(size_t)(c) * ns + i] + kv);
          LT_COMPS(LT_S3, yc, k)
#undef LT_S3
          yc.q = LT_(qrenorm)(yc.q);
#define LT_W3(c, ev, kv)                                                        \
  y0[(size_t)(c) * ns + i] = ev;                                                \
  sum += ev * (LT_R)0;
          LT_COMPS(LT_W3, yc, k)
#undef LT_W3
        }
      }
#undef LT_DERIV
      if (sum != 0 || sum != sum) bad |= 1;
    }
    /* elements with boundary conditions (implicit barrier above) */
#pragma omp for schedule(static)
    for (r = 0; r < nbc; ++r) {
      const size_t i = e->bc_list[r];
      struct LT_(el) k = LT_(cpu_deriv)(&p, ys, ns, i, s1, s2, LT_(lfl_bits)(lpv[i], lmv[i]),
                                        tab + (size_t)m->group[i] * LT_GROUP_STRIDE, inv_m,
                                        inv_i, alpha);
      if (stage < 3) {
#define LT_B012(c, ev, kv)                                                      \
  acc[(size_t)(c) * ns + i] += (stage == 0 ? (LT_R)1 : bs) * kv;                \
  yn[(size_t)(c) * ns + i] = y0[(size_t)(c) * ns + i] + cs * kv;
        LT_COMPS(LT_B012, k, k)
#undef LT_B012
      } else {
        struct LT_(el) yc;
        LT_R chk = 0;
#define LT_B3(c, ev, kv)                                                        \
  ev = y0[(size_t)(c) * ns + i] + dt6 * (acc[(size_t)(c) * ns + i] + kv);
        LT_COMPS(LT_B3, yc, k)
#undef LT_B3
        yc.q = LT_(qrenorm)(yc.q);
#define LT_BW3(c, ev, kv)                                                       \
  y0[(size_t)(c) * ns + i] = ev;                                                \
  chk += ev * (LT_R)0;
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
/* The leapfrog update of element el under link forces F, T, with the group
 * row g or as a free element when g is NULL. */
LT_FN struct LT_(el) LT_(cpu_lf_new)(struct LT_(el) el, struct LT_(v3) F, struct LT_(v3) T,
                                     const LT_R *g, LT_R inv_m, LT_R inv_i, LT_R had, LT_R dt) {
  struct LT_(el) n;
  if (g) {
    n.v.x = LT_(kick)(g[0], g[6], g[12], inv_m, had, dt, F.x, el.v.x);
    n.v.y = LT_(kick)(g[1], g[7], g[13], inv_m, had, dt, F.y, el.v.y);
    n.v.z = LT_(kick)(g[2], g[8], g[14], inv_m, had, dt, F.z, el.v.z);
    n.W.x = LT_(kick)(g[3], g[9], g[15], inv_i, had, dt, T.x, el.W.x);
    n.W.y = LT_(kick)(g[4], g[10], g[16], inv_i, had, dt, T.y, el.W.y);
    n.W.z = LT_(kick)(g[5], g[11], g[17], inv_i, had, dt, T.z, el.W.z);
  } else {
    n.v.x = LT_(kick)(1, 0, 0, inv_m, had, dt, F.x, el.v.x);
    n.v.y = LT_(kick)(1, 0, 0, inv_m, had, dt, F.y, el.v.y);
    n.v.z = LT_(kick)(1, 0, 0, inv_m, had, dt, F.z, el.v.z);
    n.W.x = LT_(kick)(1, 0, 0, inv_i, had, dt, T.x, el.W.x);
    n.W.y = LT_(kick)(1, 0, 0, inv_i, had, dt, T.y, el.W.y);
    n.W.z = LT_(kick)(1, 0, 0, inv_i, had, dt, T.z, el.W.z);
  }
  n.u = LT_(v3_add)(el.u, LT_(v3_scale)(dt, n.v));
  n.q = LT_(qrotate)(el.q, LT_(v3_scale)(dt, n.W));
  return n;
}

LT_FN LT_R LT_(cpu_lf_elem)(const struct LT_(lpar) *p, const LT_R *restrict ya, LT_R *restrict yb,
                            size_t ns, size_t i, size_t s1, size_t s2, struct LT_(lfl) fl,
                            const LT_R *g, LT_R inv_m, LT_R inv_i, LT_R had, LT_R dt) {
  struct LT_(el) el = LT_(cpu_load)(ya, ns, i), n;
  struct LT_(ft) ft = LT_(cpu_gather)(p, ya, ns, i, s1, s2, fl, el);
  LT_R sum = 0;
  n = LT_(cpu_lf_new)(el, ft.F, ft.T, g, inv_m, inv_i, had, dt);
#define LT_LW(c, ev, kv)                                                        \
  yb[(size_t)(c) * ns + i] = ev;                                                \
  sum += ev * (LT_R)0;
  LT_COMPS(LT_LW, n, n)
#undef LT_LW
  return sum;
}

static int LT_(cpu_leapfrog)(struct px_lattice_cpu *e, const LT_R *restrict ya,
                             LT_R *restrict yb, LT_R dt) {
  const struct px_lattice_model *m = e->m;
  const size_t ns = e->ns, n0 = m->n0p;
  const size_t s1 = (size_t)m->stride[1], s2 = (size_t)m->stride[2];
  const size_t nrow = (size_t)m->grid.n[1] * (size_t)m->grid.n[2];
  const uint8_t *restrict lpv = e->lp, *restrict lmv = e->lm, *restrict frv = e->free;
  const LT_R *tab = (const LT_R *)e->table;
  const struct LT_(lpar) p = *(const struct LT_(lpar) *)e->lpar;
  const LT_R inv_m = (LT_R)(1.0 / m->m), inv_i = (LT_R)(1.0 / m->I);
  const LT_R had = (LT_R)(0.5 * e->alpha) * dt;
  const long nbc = (long)e->nbc;
  long r;
  int bad = 0;
#pragma omp parallel num_threads(e->threads) reduction(| : bad)
  {
    LT_R *restrict fl = (LT_R *)e->scratch[omp_get_thread_num()] + e->flag_off;
#pragma omp for schedule(static)
    for (r = 0; r < (long)nrow; ++r) {
      const size_t base = m->pad + (size_t)r * n0;
      const long lo = e->row_lo[r], hi = e->row_hi[r];
      long x;
      LT_R sum = 0;
      LT_(cpu_row_flags)(lpv, lmv, frv, base, lo, hi, fl, n0);
LT_SIMD_SUM
      for (x = lo; x < hi; ++x) {
        const size_t i = base + (size_t)x;
        sum += LT_(cpu_lf_elem)(&p, ya, yb, ns, i, s1, s2, LT_(lfl_row)(fl, n0, (size_t)x), NULL,
                                inv_m, inv_i, had, dt);
      }
      if (sum != 0 || sum != sum) bad |= 1;
    }
#pragma omp for schedule(static)
    for (r = 0; r < nbc; ++r) {
      const size_t i = e->bc_list[r];
      LT_R sum = LT_(cpu_lf_elem)(&p, ya, yb, ns, i, s1, s2, LT_(lfl_bits)(lpv[i], lmv[i]),
                                  tab + (size_t)m->group[i] * LT_GROUP_STRIDE, inv_m, inv_i, had,
                                  dt);
      if (sum != 0 || sum != sum) bad |= 1;
    }
  }
  return bad;
}

/* ---------------------------------------------------------------------------
 * Link-once scheme. Threads sweep slabs of z-planes and walk each plane's
 * rows in order; for a row they evaluate the row's x-, y- and z-links once
 * (simple simd loops with few live values) into scratch buffers, then
 * gather each element's six link results and update it. The y-minus links
 * of a row are the previous row's y-plus links and one side's z-links of a
 * plane the previous plane's (rolling buffers); a sweep's first plane
 * evaluates those itself (lt_cpu_l1_plane). Leapfrog and the per-stage RK4
 * passes sweep upward (lt_cpu_pass_l1); RK4 on 1-2 threads runs its four
 * stages in one sweep (lt_cpu_rk4_l1). Scratch layout: 6 components
 * (F.x F.y F.z G.x G.y G.z) with stride os. */

/* The plus links along axis a of row elements x in [lo, hi) into out[c os + x],
 * times their flags fla[x] (flag row a of lt_cpu_row_flags). */
LT_FN void LT_(cpu_link_row)(const struct LT_(lpar) *p, const LT_R *restrict y, size_t ns,
                             size_t base, long lo, long hi, size_t s, int a,
                             const LT_R *restrict fla, LT_R *restrict out, size_t os) {
  long x;
LT_SIMD
  for (x = lo; x < hi; ++x) {
    const size_t i = base + (size_t)x;
    struct LT_(el) e1 = LT_(cpu_load)(y, ns, i), e2 = LT_(cpu_load)(y, ns, i + s);
    struct LT_(lres) r = LT_(link)(p, a, e1, e2, LT_(frame_col)(e1.q, a), LT_(frame_col)(e2.q, a));
    const LT_R f = fla[x];
    const size_t xs = (size_t)x;
    out[xs] = f * r.F.x;
    out[os + xs] = f * r.F.y;
    out[2 * os + xs] = f * r.F.z;
    out[3 * os + xs] = f * r.G.x;
    out[4 * os + xs] = f * r.G.y;
    out[5 * os + xs] = f * r.G.z;
  }
}

/* Zero the link results of a row outside [lo, hi) (void cells: a
 * neighbouring row may be longer and read them). */
static void LT_(cpu_zero_out)(LT_R *out, size_t os, long lo, long hi, long n) {
  int c;
  for (c = 0; c < 6; ++c) {
    LT_R *o = out + (size_t)c * os;
    if (lo > 0) memset(o, 0, (size_t)lo * sizeof(LT_R));
    if (hi < n) memset(o + hi, 0, (size_t)(n - hi) * sizeof(LT_R));
  }
}

/* Add the two link results along axis a (plus array pl, minus array mi,
 * component c at c os + x) to the force and moment acc of an element. */
LT_FN struct LT_(ft) LT_(cpu_sum_axis)(LT_R h2, struct LT_(q4) q, int a, const LT_R *restrict pl,
                                       const LT_R *restrict mi, size_t os, size_t x,
                                       struct LT_(ft) acc) {
  return LT_(axis_acc)(h2, a, LT_(frame_col)(q, a),
                       LT_(v3_make)(pl[x], pl[os + x], pl[2 * os + x]),
                       LT_(v3_make)(pl[3 * os + x], pl[4 * os + x], pl[5 * os + x]),
                       LT_(v3_make)(mi[x], mi[os + x], mi[2 * os + x]),
                       LT_(v3_make)(mi[3 * os + x], mi[4 * os + x], mi[5 * os + x]), acc);
}

/* Force and moment on element x of a row from its six link results. */
LT_FN struct LT_(ft) LT_(cpu_sum_links)(LT_R h2, struct LT_(q4) q, const LT_R *restrict lxp,
                                        const LT_R *restrict lxm, const LT_R *restrict lyp,
                                        const LT_R *restrict lym, const LT_R *restrict lzp,
                                        const LT_R *restrict lzm, size_t osx, size_t osy,
                                        size_t osz, size_t x) {
  struct LT_(ft) r;
  r.F = LT_(v3_make)(0, 0, 0);
  r.T = LT_(v3_make)(0, 0, 0);
  r = LT_(cpu_sum_axis)(h2, q, 0, lxp, lxm, osx, x, r);
  r = LT_(cpu_sum_axis)(h2, q, 1, lyp, lym, osy, x, r);
  return LT_(cpu_sum_axis)(h2, q, 2, lzp, lzm, osz, x, r);
}

/* Gather and RK4-update the elements of one row (stage as in cpu_rk4_stage;
 * a constant after inlining, so the simd loop has no branch). */
LT_FN void LT_(cpu_row_rk4)(const struct LT_(lpar) *p, const LT_R *restrict ys,
                            LT_R *restrict yn, LT_R *restrict y0, LT_R *restrict acc, size_t ns,
                            size_t base, long lo, long hi, const LT_R *restrict frow,
                            const LT_R *restrict lxp, const LT_R *restrict lxm,
                            const LT_R *restrict lyp, const LT_R *restrict lym,
                            const LT_R *restrict lzp, const LT_R *restrict lzm, size_t osx,
                            size_t osy, size_t osz, LT_R inv_m, LT_R inv_i, LT_R alpha, LT_R cs,
                            LT_R dt6, const int stage, LT_R *sum) {
  long x;
  LT_R sm = 0;
LT_SIMD_SM
  for (x = lo; x < hi; ++x) {
    const size_t i = base + (size_t)x;
    const LT_R fr = frow[x];
    struct LT_(el) el = LT_(cpu_load)(ys, ns, i), k;
    struct LT_(ft) f =
        LT_(cpu_sum_links)(p->h2, el.q, lxp, lxm, lyp, lym, lzp, lzm, osx, osy, osz, (size_t)x);
    struct LT_(dvw) d = LT_(accel_free)(inv_m, inv_i, alpha, f.F, f.T, el.v, el.W);
    k.v = d.dv;
    k.W = d.dW;
    k.q = LT_(qdot)(el.q, el.W);
    k.u = el.v;
    if (stage == 0) {
#define LT_S0(c, ev, kv)                                                        \
  acc[(size_t)(c) * ns + i] = fr * kv;                                          \
  yn[(size_t)(c) * ns + i] = y0[(size_t)(c) * ns + i] + cs * kv;
      LT_COMPS(LT_S0, k, k)
#undef LT_S0
    } else if (stage < 3) {
#define LT_S12(c, ev, kv)                                                       \
  acc[(size_t)(c) * ns + i] += fr * (LT_R)2 * kv;                               \
  yn[(size_t)(c) * ns + i] = y0[(size_t)(c) * ns + i] + cs * kv;
      LT_COMPS(LT_S12, k, k)
#undef LT_S12
    } else {
      struct LT_(el) yc;
#define LT_S3(c, ev, kv)                                                        \
  ev = y0[(size_t)(c) * ns + i] + fr * dt6 * (acc[(size_t)(c) * ns + i] + kv);
      LT_COMPS(LT_S3, yc, k)
#undef LT_S3
      yc.q = LT_(qrenorm)(yc.q);
#define LT_W3(c, ev, kv)                                                        \
  y0[(size_t)(c) * ns + i] = ev;                                                \
  sm += ev * (LT_R)0;
      LT_COMPS(LT_W3, yc, k)
#undef LT_W3
    }
  }
  *sum += sm;
}

/* Gather and leapfrog-update the free elements of one row (ya -> yb). */
LT_FN void LT_(cpu_row_lf)(const struct LT_(lpar) *p, const LT_R *restrict ya, LT_R *restrict yb,
                           size_t ns, size_t base, long lo, long hi, const LT_R *restrict lxp,
                           const LT_R *restrict lxm, const LT_R *restrict lyp,
                           const LT_R *restrict lym, const LT_R *restrict lzp,
                           const LT_R *restrict lzm, size_t osx, size_t osy, size_t osz,
                           LT_R inv_m, LT_R inv_i, LT_R had, LT_R dt, LT_R *sum) {
  long x;
  LT_R sm = 0;
LT_SIMD_SM
  for (x = lo; x < hi; ++x) {
    const size_t i = base + (size_t)x;
    struct LT_(el) el = LT_(cpu_load)(ya, ns, i), n;
    struct LT_(ft) ft =
        LT_(cpu_sum_links)(p->h2, el.q, lxp, lxm, lyp, lym, lzp, lzm, osx, osy, osz, (size_t)x);
    struct LT_(v3) F = ft.F, T = ft.T;
    n.v.x = LT_(kick)(1, 0, 0, inv_m, had, dt, F.x, el.v.x);
    n.v.y = LT_(kick)(1, 0, 0, inv_m, had, dt, F.y, el.v.y);
    n.v.z = LT_(kick)(1, 0, 0, inv_m, had, dt, F.z, el.v.z);
    n.W.x = LT_(kick)(1, 0, 0, inv_i, had, dt, T.x, el.W.x);
    n.W.y = LT_(kick)(1, 0, 0, inv_i, had, dt, T.y, el.W.y);
    n.W.z = LT_(kick)(1, 0, 0, inv_i, had, dt, T.z, el.W.z);
    n.u = LT_(v3_add)(el.u, LT_(v3_scale)(dt, n.v));
    n.q = LT_(qrotate)(el.q, LT_(v3_scale)(dt, n.W));
#define LT_LW1(c, ev, kv)                                                       \
  yb[(size_t)(c) * ns + i] = ev;                                                \
  sm += ev * (LT_R)0;
    LT_COMPS(LT_LW1, n, n)
#undef LT_LW1
  }
  *sum += sm;
}

/* Redo the boundary-condition elements of one row, bc_list[b0, b1), with
 * their group rows g in tab (the simd row loop took them as free), from the row's
 * link results: RK4 stage `stage` or, with stage < 0, a leapfrog step, as in
 * lt_cpu_pass_l1. The links are canonical, so the forces are bit-identical
 * to the gather form's. Returns 0 times every value written (a NaN check). */
static LT_R LT_(cpu_row_bc)(const struct px_lattice_cpu *e, const LT_R *tab,
                            const struct LT_(lpar) *p,
                            const LT_R *restrict ys, LT_R *restrict yn, LT_R *restrict y0,
                            LT_R *restrict acc, size_t ns, size_t base, size_t b0, size_t b1,
                            const LT_R *restrict lxp, const LT_R *restrict lxm,
                            const LT_R *restrict lyp, const LT_R *restrict lym,
                            const LT_R *restrict lzp, const LT_R *restrict lzm, size_t osx,
                            size_t osy, size_t osz, LT_R inv_m, LT_R inv_i, LT_R alpha, LT_R had,
                            LT_R cs, LT_R dt6, LT_R dt, int stage) {
  LT_R chk = 0;
  size_t b;
  for (b = b0; b < b1; ++b) {
    const size_t i = e->bc_list[b], x = i - base;
    const LT_R *g = tab + (size_t)e->m->group[i] * LT_GROUP_STRIDE;
    struct LT_(el) el = LT_(cpu_load)(ys, ns, i);
    struct LT_(ft) f = LT_(cpu_sum_links)(p->h2, el.q, lxp, lxm, lyp, lym, lzp, lzm, osx, osy,
                                          osz, x);
    if (stage < 0) {
      struct LT_(el) n = LT_(cpu_lf_new)(el, f.F, f.T, g, inv_m, inv_i, had, dt);
#define LT_BL(c, ev, kv)                                                        \
  yn[(size_t)(c) * ns + i] = ev;                                                \
  chk += ev * (LT_R)0;
      LT_COMPS(LT_BL, n, n)
#undef LT_BL
    } else {
      struct LT_(dvw) d = LT_(accel)(g, inv_m, inv_i, alpha, f.F, f.T, el.v, el.W);
      struct LT_(el) k;
      k.v = d.dv;
      k.W = d.dW;
      k.q = LT_(qdot)(el.q, el.W);
      k.u = el.v;
      if (stage < 3) {
#define LT_C012(c, ev, kv)                                                      \
  acc[(size_t)(c) * ns + i] += (stage == 0 ? (LT_R)1 : (LT_R)2) * kv;           \
  yn[(size_t)(c) * ns + i] = y0[(size_t)(c) * ns + i] + cs * kv;
        LT_COMPS(LT_C012, k, k)
#undef LT_C012
      } else {
        struct LT_(el) yc;
#define LT_C3(c, ev, kv)                                                        \
  ev = y0[(size_t)(c) * ns + i] + dt6 * (acc[(size_t)(c) * ns + i] + kv);
        LT_COMPS(LT_C3, yc, k)
#undef LT_C3
        yc.q = LT_(qrenorm)(yc.q);
#define LT_CW3(c, ev, kv)                                                       \
  y0[(size_t)(c) * ns + i] = ev;                                                \
  chk += ev * (LT_R)0;
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
struct LT_(l1s) {
  LT_R *sx, *sy[2], *sz[2];
};

/* Scratch set k (0..3: one per RK4 stage in the fused sweep) of thread tid. */
static struct LT_(l1s) LT_(cpu_l1_scratch)(const struct px_lattice_cpu *e, int tid, int k) {
  const size_t n0 = e->m->n0p, osx = n0 + 1, osy = n0, osz = n0 * (size_t)e->m->grid.n[1];
  struct LT_(l1s) s;
  s.sx = (LT_R *)e->scratch[tid] + (size_t)k * LT_L1_WORDS(n0, (size_t)e->m->grid.n[1]);
  s.sy[0] = s.sx + 6 * osx;
  s.sy[1] = s.sy[0] + 6 * osy;
  s.sz[0] = s.sy[1] + 6 * osy;
  s.sz[1] = s.sz[0] + 6 * osz;
  return s;
}

/* Plane z, link-once: RK4 stage `stage` (0..3, as in lt_cpu_rk4_stage, group
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
 * from the previous plane. Returns 0 times every value written (a NaN
 * check). */
static LT_R LT_(cpu_l1_plane)(struct px_lattice_cpu *e, const struct LT_(l1s) *sc,
                              LT_R *restrict fl, const LT_R *restrict ys, LT_R *restrict yn,
                              LT_R *restrict y0, LT_R *restrict acc, const LT_R *tab, int stage,
                              long z, int dir, int first, LT_R dt) {
  const struct px_lattice_model *m = e->m;
  const size_t ns = e->ns, n0 = m->n0p, n1 = (size_t)m->grid.n[1];
  const long nz = m->grid.n[2];
  const size_t s1 = (size_t)m->stride[1], s2 = (size_t)m->stride[2];
  const uint8_t *restrict lpv = e->lp, *restrict lmv = e->lm, *restrict frv = e->free;
  const struct LT_(lpar) p = *(const struct LT_(lpar) *)e->lpar;
  const LT_R inv_m = (LT_R)(1.0 / m->m), inv_i = (LT_R)(1.0 / m->I), alpha = (LT_R)e->alpha;
  const LT_R cs = stage == 2 ? dt : (LT_R)0.5 * dt, dt6 = dt / (LT_R)6;
  const LT_R had = (LT_R)(0.5 * e->alpha) * dt;
  const size_t osx = n0 + 1, osy = n0, osz = n0 * n1;
  /* cur: the z-links this plane evaluates; prev: those it takes over */
  LT_R *sx = sc->sx, *cur = sc->sz[z & 1], *prev = sc->sz[(z + 1) & 1];
  const int edge = dir > 0 ? z == 0 : z == nz - 1;
  LT_R sum = 0;
  long yy;
  {
    int c;
    for (c = 0; c < 6; ++c) sx[(size_t)c * osx] = 0;
  }
  if (edge)
    memset(prev, 0, 6 * osz * sizeof(LT_R));
  else if (first && dir > 0)
    /* z-links of the plane below */
    for (yy = 0; yy < (long)n1; ++yy) {
      const long rr = (z - 1) * (long)n1 + yy;
      const size_t base = m->pad + (size_t)rr * n0;
      LT_(cpu_row_flags)(lpv, lmv, frv, base, e->row_lo[rr], e->row_hi[rr], fl, n0);
      LT_(cpu_link_row)(&p, ys, ns, base, e->row_lo[rr], e->row_hi[rr], s2, 2, fl + 2 * n0,
                        prev + (size_t)yy * n0, osz);
      LT_(cpu_zero_out)(prev + (size_t)yy * n0, osz, e->row_lo[rr], e->row_hi[rr], (long)n0);
    }
  for (yy = 0; yy < (long)n1; ++yy) {
    const long rr = z * (long)n1 + yy;
    const size_t base = m->pad + (size_t)rr * n0;
    const long lo = e->row_lo[rr], hi = e->row_hi[rr];
    LT_R *lyp = sc->sy[yy & 1], *lym = sc->sy[(yy + 1) & 1];
    LT_R *rc = cur + (size_t)yy * n0, *rv = prev + (size_t)yy * n0;
    LT_R *rzp = dir > 0 ? rc : rv, *rzm = dir > 0 ? rv : rc;
    if (yy == 0) memset(lym, 0, 6 * osy * sizeof(LT_R));
    /* links with a void plus end are flagged absent: computing them is
     * harmless, and rows of different lengths need the z/y results of
     * their whole range */
    LT_(cpu_row_flags)(lpv, lmv, frv, base, lo, hi, fl, n0);
    LT_(cpu_link_row)(&p, ys, ns, base, lo, hi, 1, 0, fl, sx + 1, osx);
    LT_(cpu_link_row)(&p, ys, ns, base, lo, hi, s1, 1, fl + n0, lyp, osy);
    if (dir > 0) {
      LT_(cpu_link_row)(&p, ys, ns, base, lo, hi, s2, 2, fl + 2 * n0, rc, osz);
    } else {
      /* minus links: the row below is the minus end (its padding at z = 0) */
      LT_(cpu_link_row)(&p, ys, ns, base - s2, lo, hi, s2, 2, fl + 5 * n0, rc, osz);
      if (first && !edge) {
        LT_(cpu_link_row)(&p, ys, ns, base, lo, hi, s2, 2, fl + 2 * n0, rv, osz);
        LT_(cpu_zero_out)(rv, osz, lo, hi, (long)n0);
      }
    }
    LT_(cpu_zero_out)(lyp, osy, lo, hi, (long)n0);
    LT_(cpu_zero_out)(rc, osz, lo, hi, (long)n0);
    if (lo > 0) {
      int c;
      for (c = 0; c < 6; ++c) sx[(size_t)c * osx + (size_t)lo] = 0;
    }
    if (stage < 0)
      LT_(cpu_row_lf)(&p, ys, yn, ns, base, lo, hi, sx + 1, sx, lyp, lym, rzp, rzm, osx, osy, osz,
                      inv_m, inv_i, had, dt, &sum);
    else if (stage == 0)
      LT_(cpu_row_rk4)(&p, ys, yn, y0, acc, ns, base, lo, hi, fl + 6 * n0, sx + 1, sx, lyp, lym,
                       rzp, rzm, osx, osy, osz, inv_m, inv_i, alpha, cs, dt6, 0, &sum);
    else if (stage < 3)
      LT_(cpu_row_rk4)(&p, ys, yn, y0, acc, ns, base, lo, hi, fl + 6 * n0, sx + 1, sx, lyp, lym,
                       rzp, rzm, osx, osy, osz, inv_m, inv_i, alpha, cs, dt6, 1, &sum);
    else
      LT_(cpu_row_rk4)(&p, ys, yn, y0, acc, ns, base, lo, hi, fl + 6 * n0, sx + 1, sx, lyp, lym,
                       rzp, rzm, osx, osy, osz, inv_m, inv_i, alpha, cs, dt6, 3, &sum);
    if (e->bc_row[rr] < e->bc_row[rr + 1])
      sum += LT_(cpu_row_bc)(e, tab, &p, ys, yn, y0, acc, ns, base, e->bc_row[rr],
                             e->bc_row[rr + 1], sx + 1, sx, lyp, lym, rzp, rzm, osx, osy, osz,
                             inv_m, inv_i, alpha, had, cs, dt6, dt, stage);
  }
  return sum;
}

/* One link-once pass over all elements: a leapfrog step (stage < 0; ys = ya,
 * yn = yb) or one RK4 stage. Each thread sweeps a slab of z-planes upward. */
static int LT_(cpu_pass_l1)(struct px_lattice_cpu *e, const LT_R *restrict ys,
                            LT_R *restrict yn, LT_R *restrict y0, LT_R *restrict acc, int stage,
                            LT_R dt) {
  const long nz = e->m->grid.n[2];
  int bad = 0;
#pragma omp parallel num_threads(e->threads) reduction(| : bad)
  {
    const int tid = omp_get_thread_num(), nt = omp_get_num_threads();
    const long z0 = nz * tid / nt, z1 = nz * (tid + 1) / nt;
    const struct LT_(l1s) sc = LT_(cpu_l1_scratch)(e, tid, 0);
    LT_R *fl = (LT_R *)e->scratch[tid] + e->flag_off;
    LT_R sum = 0;
    long z;
    for (z = z0; z < z1; ++z)
      sum += LT_(cpu_l1_plane)(e, &sc, fl, ys, yn, y0, acc, (const LT_R *)e->table, stage, z, 1,
                               z == z0, dt);
    if (sum != 0 || sum != sum) bad |= 1;
  }
  return bad;
}

/* One RK4 step, link-once, all four stages in one sweep over the z-planes
 * (temporal blocking): at sweep step t stage s works on the plane t - s
 * places along the sweep, in stage order, so that a plane's stage states and
 * increments are reused while they are still in cache instead of streaming
 * the four state buffers through memory once per stage. Stage s at plane p
 * needs the stage-s states of planes p - 1 .. p + 1 only: the next plane's
 * was written by stage s - 1 earlier in the same sweep step, the others in
 * earlier steps. Buffers and arithmetic are those of four lt_cpu_pass_l1
 * stages (the same bits): y0 the state, ya, yb the stage states (stage 0
 * writes ya, 1 yb, 2 ya, 3 updates y0 in place), acc the increments; stage 2
 * overwrites ya[p] after the last reader of stage 1's ya[p], stage 3 y0[p]
 * after the last reader of y0[p].
 * One thread sweeps upward over all planes. Two threads split the planes in
 * halves and sweep away from the middle (the lower half downward), so they
 * share data only in their first three sweep steps (each reads the other's
 * first plane for the links across the middle): a barrier after each of
 * those, none later. More threads: not handled here (lt_cpu_run uses the
 * per-stage passes). tabs: group tables at t, t + dt/2, t + dt. */
static int LT_(cpu_rk4_l1)(struct px_lattice_cpu *e, LT_R *restrict y0, LT_R *restrict ya,
                           LT_R *restrict yb, LT_R *restrict acc, const LT_R *const tabs[3],
                           LT_R dt) {
  const long nz = e->m->grid.n[2];
  int bad = 0;
#pragma omp parallel num_threads(e->threads < 2 ? e->threads : 2) reduction(| : bad)
  {
    const int tid = omp_get_thread_num(), nt = omp_get_num_threads();
    const long zh = nt == 2 ? nz / 2 : 0, len = tid == 0 ? (nt == 2 ? zh : nz) : nz - zh;
    const long zs = tid == 0 ? (nt == 2 ? zh - 1 : 0) : zh;
    const int dir = tid == 0 && nt == 2 ? -1 : 1;
    struct LT_(l1s) sc[4];
    LT_R *fl = (LT_R *)e->scratch[tid] + e->flag_off;
    LT_R sum = 0;
    long t;
    int s;
    for (s = 0; s < 4; ++s) sc[s] = LT_(cpu_l1_scratch)(e, tid, s);
    for (t = 0; t < len + 3 || t < 3; ++t) {
      for (s = 0; s < 4; ++s) {
        const long k = t - s, z = zs + dir * k;
        const LT_R *ys = s == 0 ? y0 : (s == 2 ? yb : ya);
        LT_R *yn = s == 1 ? yb : ya;
        const LT_R *tab = tabs[s == 0 ? 0 : (s == 3 ? 2 : 1)];
        if (k < 0 || k >= len) continue;
        sum += LT_(cpu_l1_plane)(e, &sc[s], fl, ys, yn, y0, acc, tab, s, z, dir, k == 0, dt);
      }
      if (t < 3) {
#pragma omp barrier
      }
    }
    if (sum != 0 || sum != sum) bad |= 1;
  }
  return bad;
}

/* Fracture: every element evaluates its six links at state y (canonical form,
 * so both ends decide alike) and clears its own flags of the links that
 * break. Returns the number of link ends cleared (2 per broken link). */
static long LT_(cpu_fracture)(struct px_lattice_cpu *e, const LT_R *restrict y) {
  const struct px_lattice_model *m = e->m;
  const size_t ns = e->ns, n0 = m->n0p;
  const size_t nrow = (size_t)m->grid.n[1] * (size_t)m->grid.n[2];
  const struct LT_(lpar) p = *(const struct LT_(lpar) *)e->lpar;
  const struct LT_(fpar) fp = *(const struct LT_(fpar) *)e->fpar;
  uint8_t *restrict lpv = e->lp, *restrict lmv = e->lm;
  long r, ends = 0;
#pragma omp parallel for num_threads(e->threads) schedule(static) reduction(+ : ends)
  for (r = 0; r < (long)nrow; ++r) {
    const size_t base = m->pad + (size_t)r * n0;
    long x;
    for (x = e->row_lo[r]; x < e->row_hi[r]; ++x) {
      const size_t i = base + (size_t)x;
      struct LT_(el) el;
      unsigned lp = lpv[i], lm = lmv[i];
      int a;
      if (!(lp | lm)) continue;
      el = LT_(cpu_load)(y, ns, i);
      for (a = 0; a < 3; ++a) {
        size_t s = (size_t)m->stride[a];
        struct LT_(v3) bs = LT_(frame_col)(el.q, a);
        if (lp & PX_LATTICE_LINK_PLUS(a)) {
          struct LT_(el) en = LT_(cpu_load)(y, ns, i + s);
          struct LT_(lres) rr = LT_(link)(&p, a, el, en, bs, LT_(frame_col)(en.q, a));
          if (LT_(link_break)(&p, &fp, a, bs, rr) >= (LT_R)1) {
            lp &= ~PX_LATTICE_LINK_PLUS(a);
            ++ends;
          }
        }
        if (lm & PX_LATTICE_LINK_MINUS(a)) {
          struct LT_(el) em = LT_(cpu_load)(y, ns, i - s);
          struct LT_(v3) bm = LT_(frame_col)(em.q, a);
          struct LT_(lres) rr = LT_(link)(&p, a, em, el, bm, bs);
          if (LT_(link_break)(&p, &fp, a, bm, rr) >= (LT_R)1) {
            lm &= ~PX_LATTICE_LINK_MINUS(a);
            ++ends;
          }
        }
      }
      lpv[i] = (uint8_t)lp;
      lmv[i] = (uint8_t)lm;
    }
  }
  return ends;
}

/* Fields at output time from state y: stress (Love-Weber) and von Mises,
 * link forces F, T for the leapfrog velocity synchronization, and the
 * Rayleigh sums with the rate sum rq_rate = q.M dq/dt (m u.v + I theta.W,
 * the stored velocities). Outputs in double on the host (NULL = not
 * wanted). Rows are summed in row order for the sums (deterministic). */
static void LT_(cpu_fields)(struct px_lattice_cpu *e, const LT_R *restrict y, double t_sync_dt,
                            const struct px_lattice_fields *f, double *rq_num, double *rq_den,
                            double *rq_rate) {
  const struct px_lattice_model *m = e->m;
  const size_t ns = e->ns, n0 = m->n0p;
  const size_t s1 = (size_t)m->stride[1], s2 = (size_t)m->stride[2];
  const size_t nrow = (size_t)m->grid.n[1] * (size_t)m->grid.n[2];
  const struct LT_(lpar) p = *(const struct LT_(lpar) *)e->lpar;
  const LT_R *restrict tab = (const LT_R *)e->table;
  const double inv_v = 1.0 / (m->grid.h * m->grid.h * m->grid.h);
  const int sync = e->integ == PX_LATTICE_INTEGRATOR_LEAPFROG;
  double *rown = e->rowsum, *rowd = e->rowsum + nrow, *rowk = e->rowsum + 2 * nrow;
  long r;
#pragma omp parallel for num_threads(e->threads) schedule(static)
  for (r = 0; r < (long)nrow; ++r) {
    const size_t base = m->pad + (size_t)r * n0;
    double sn = 0.0, sd = 0.0, sk = 0.0;
    long x;
    for (x = e->row_lo[r]; x < e->row_hi[r]; ++x) {
      const size_t i = base + (size_t)x;
      struct LT_(el) el = LT_(cpu_load)(y, ns, i);
      struct LT_(ft) ft;
      struct LT_(v3) F, T;
      if (m->group[i] == 0) continue;
      ft = LT_(cpu_gather)(&p, y, ns, i, s1, s2, LT_(lfl_bits)(e->lp[i], e->lm[i]), el);
      F = ft.F;
      T = ft.T;
      if (f && f->u) {
        f->u[3 * i] = (double)el.u.x;
        f->u[3 * i + 1] = (double)el.u.y;
        f->u[3 * i + 2] = (double)el.u.z;
      }
      if (f && f->v) {
        struct LT_(v3) v = el.v;
        if (sync) {
          struct LT_(dvw) d =
              LT_(accel)(tab + (size_t)m->group[i] * LT_GROUP_STRIDE, (LT_R)(1.0 / m->m),
                         (LT_R)(1.0 / m->I), (LT_R)e->alpha, F, T, el.v, el.W);
          v = LT_(v3_add)(v, LT_(v3_scale)((LT_R)(0.5 * t_sync_dt), d.dv));
        }
        f->v[3 * i] = (double)v.x;
        f->v[3 * i + 1] = (double)v.y;
        f->v[3 * i + 2] = (double)v.z;
      }
      if (f && (f->sigma || f->vm)) {
        struct LT_(sym) s = {0, 0, 0, 0, 0, 0};
        int a;
        for (a = 0; a < 3; ++a) {
          size_t st = a == 0 ? 1 : (a == 1 ? s1 : s2);
          struct LT_(v3) bs = LT_(frame_col)(el.q, a);
          if (e->lp[i] & PX_LATTICE_LINK_PLUS(a)) {
            struct LT_(el) en = LT_(cpu_load)(y, ns, i + st);
            struct LT_(lres) rr = LT_(link)(&p, a, el, en, bs, LT_(frame_col)(en.q, a));
            LT_(stress_add)(&s, p.h2, a, bs, rr.F);
          }
          if (e->lm[i] & PX_LATTICE_LINK_MINUS(a)) {
            struct LT_(el) em = LT_(cpu_load)(y, ns, i - st);
            struct LT_(lres) rr = LT_(link)(&p, a, em, el, LT_(frame_col)(em.q, a), bs);
            LT_(stress_add)(&s, p.h2, a, bs, rr.F);
          }
        }
        if (f->sigma) {
          f->sigma[6 * i] = (double)s.xx * inv_v;
          f->sigma[6 * i + 1] = (double)s.yy * inv_v;
          f->sigma[6 * i + 2] = (double)s.zz * inv_v;
          f->sigma[6 * i + 3] = (double)s.xy * inv_v;
          f->sigma[6 * i + 4] = (double)s.yz * inv_v;
          f->sigma[6 * i + 5] = (double)s.zx * inv_v;
        }
        if (f->vm) f->vm[i] = (double)LT_(von_mises)(s) * inv_v;
      }
      if (rq_num) {
        double th[3];
        th[0] = 2.0 * (double)el.q.x;
        th[1] = 2.0 * (double)el.q.y;
        th[2] = 2.0 * (double)el.q.z;
        sn -= (double)el.u.x * (double)F.x + (double)el.u.y * (double)F.y +
              (double)el.u.z * (double)F.z + th[0] * (double)T.x + th[1] * (double)T.y +
              th[2] * (double)T.z;
        sd += m->m * ((double)el.u.x * (double)el.u.x + (double)el.u.y * (double)el.u.y +
                      (double)el.u.z * (double)el.u.z) +
              m->I * (th[0] * th[0] + th[1] * th[1] + th[2] * th[2]);
        sk += m->m * ((double)el.u.x * (double)el.v.x + (double)el.u.y * (double)el.v.y +
                      (double)el.u.z * (double)el.v.z) +
              m->I * (th[0] * (double)el.W.x + th[1] * (double)el.W.y + th[2] * (double)el.W.z);
      }
    }
    rown[r] = sn;
    rowd[r] = sd;
    rowk[r] = sk;
  }
  if (rq_num) {
    double sn = 0.0, sd = 0.0, sk = 0.0;
    for (r = 0; r < (long)nrow; ++r) {
      sn += rown[r];
      sd += rowd[r];
      sk += rowk[r];
    }
    *rq_num = sn;
    *rq_den = sd;
    *rq_rate = sk;
  }
}
