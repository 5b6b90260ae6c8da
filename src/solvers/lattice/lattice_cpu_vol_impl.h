/* The cpu engine's volumetric coefficients (nu != 0; lattice_kernel.h) for
 * one real type: included by lattice_cpu_impl.h after its row helpers
 * (LT_SIMD, lt_cpu_row_flags, lt_lfl_row), which these loops use.
 *
 * Where the link loops read P_a (struct lt_pw): the engine's array e->pv (3
 * components, stride ns, the layout of the state), filled for a whole stage
 * state by px_lattice_cpu_vol before a pass; or, in the fused RK4 sweep, a
 * window per stage and thread of 3 planes (plane z in slot z mod 3), each
 * slot n1 + 1 rows per component: the plane's rows, then a copy of row 0 of
 * plane z + 1. A link loop reads the plus end of an x- or y-link at +1 or
 * +n0 from the minus end, and that is row 0 of the next plane for the last
 * row (the padding cell or the next row: flagged absent, but its value
 * still sets the sign of the zero the flag gives): the extra row makes the
 * window hold, at every address a loop reads, the value the array holds
 * (cells outside a row's [lo, hi) and planes outside the grid: 0), so the
 * sweep gives the bits of the passes. */
#ifndef PX_LATTICE_CPU_VOL_IMPL_H
#define PX_LATTICE_CPU_VOL_IMPL_H

struct lt_pw {
  px_real *p; /* e->pv, or the window of one stage (not owned) */
  size_t cs;  /* component stride: ns, or (n1 + 1) n0 */
  int win;    /* 1: a window */
};

/* P_a of the elements of row cells [lo, hi) (element base + x, flags fl of
 * lt_cpu_row_flags, its row 6 made from the model's vfree, not the
 * engine's free flags) at state y into out[c cs + x], c = 0..2; mh2 =
 * mu h^2 [N]. */
PX_FN_INLINE void lt_cpu_vol_row(px_real h2, px_real lh2, px_real mh2, const px_real *restrict y,
                                 size_t ns, size_t base, long lo, long hi, size_t s1, size_t s2,
                                 const px_real *restrict fl, size_t n0, px_real *restrict out,
                                 size_t cs) {
  long x;
  LT_SIMD
  for (x = lo; x < hi; ++x) {
    const size_t i = base + (size_t)x;
    const struct lt_lfl f = lt_lfl_row(fl, n0, (size_t)x);
    const struct lt_v3 P =
        lt_vol_coef(h2, lh2, mh2, fl[6 * n0 + (size_t)x], y, ns, i, s1, s2, f, lt_load(y, ns, i));
    out[(size_t)x] = P.x;
    out[cs + (size_t)x] = P.y;
    out[2 * cs + (size_t)x] = P.z;
  }
}

/* Component a of row yy of plane z (-1 <= z <= nz: the planes beyond the
 * grid are zero) in pw. */
static px_real *lt_cpu_prow(const struct lt_pw *pw, const struct px_lattice_model *m, long z,
                            long yy, int a) {
  const long n1 = m->grid.n[1];
  if (pw->win)
    return pw->p + (size_t)((z % 3 + 3) % 3) * 3 * pw->cs + (size_t)a * pw->cs +
           (size_t)yy * m->n0p;
  return pw->p + (size_t)a * pw->cs + (size_t)((ptrdiff_t)m->pad + (z * n1 + yy) * (long)m->n0p);
}

/* Fill plane z (-1 <= z <= nz) of the window pw from state y: P_a of its
 * rows (0 outside the grid and outside each row's [lo, hi)), then its row 0
 * copied into the extra row of plane z - 1's slot. */
static void lt_cpu_vol_plane(const struct px_lattice_cpu *e, px_real *restrict fl,
                             const px_real *restrict y, const struct lt_pw *pw, long z) {
  const struct px_lattice_model *m = e->m;
  const size_t ns = e->ns, n0 = m->n0p, n1 = (size_t)m->grid.n[1];
  const size_t s1 = (size_t)m->stride[1], s2 = (size_t)m->stride[2];
  const struct lt_lpar *lp = (const struct lt_lpar *)e->lpar;
  const px_real h2 = lp->h2, lh2 = (px_real)e->lh2, mh2 = lp->k * lp->h2;
  px_real *slot = lt_cpu_prow(pw, m, z, 0, 0), *below = lt_cpu_prow(pw, m, z - 1, (long)n1, 0);
  int c;
  if (z < 0 || z >= m->grid.n[2]) {
    for (c = 0; c < 3; ++c) memset(slot + (size_t)c * pw->cs, 0, n1 * n0 * sizeof(px_real));
  } else {
    size_t yy;
    for (yy = 0; yy < n1; ++yy) {
      const size_t r = (size_t)z * n1 + yy, base = m->pad + r * n0;
      const long lo = e->row_lo[r], hi = e->row_hi[r];
      px_real *out = slot + yy * n0;
      lt_cpu_row_flags(e->lp, e->lm, e->m->vfree, base, lo, hi, fl, n0, 2 * n0);
      lt_cpu_vol_row(h2, lh2, mh2, y, ns, base, lo, hi, s1, s2, fl, n0, out, pw->cs);
      for (c = 0; c < 3; ++c) {
        px_real *o = out + (size_t)c * pw->cs;
        if (lo > 0) memset(o, 0, (size_t)lo * sizeof(px_real));
        if ((size_t)hi < n0) memset(o + hi, 0, (n0 - (size_t)hi) * sizeof(px_real));
      }
    }
  }
  for (c = 0; c < 3; ++c)
    memcpy(below + (size_t)c * pw->cs, slot + (size_t)c * pw->cs, n0 * sizeof(px_real));
}

/* Volumetric coefficients P_a (lt_vol_coef) of the elements of rows
 * [r0, r1) at state y into e->pv (3 components, stride ns): what the link
 * forces of a pass at y read when nu != 0. */
void PX_SFX(px_lattice_cpu_vol)(struct px_lattice_cpu *e, const px_real *restrict y, long r0,
                                long r1) {
  const struct px_lattice_model *m = e->m;
  const size_t ns = e->ns, n0 = m->n0p;
  const size_t s1 = (size_t)m->stride[1], s2 = (size_t)m->stride[2];
  const uint8_t *restrict lpv = e->lp, *restrict lmv = e->lm, *restrict frv = m->vfree;
  const struct lt_lpar *lp = (const struct lt_lpar *)e->lpar;
  const px_real h2 = lp->h2, lh2 = (px_real)e->lh2, mh2 = lp->k * lp->h2;
  px_real *restrict pv = (px_real *)e->pv;
  long r;
#pragma omp parallel num_threads(e->active)
  {
    px_real *restrict fl = (px_real *)e->scratch[omp_get_thread_num()] + e->flag_off;
#pragma omp for schedule(dynamic, LT_ROWS_CHUNK)
    for (r = r0; r < r1; ++r) {
      const size_t base = m->pad + (size_t)r * n0;
      lt_cpu_row_flags(lpv, lmv, frv, base, e->row_lo[r], e->row_hi[r], fl, n0, 2 * n0);
      lt_cpu_vol_row(h2, lh2, mh2, y, ns, base, e->row_lo[r], e->row_hi[r], s1, s2, fl, n0,
                     pv + base, ns);
    }
  }
}

#endif
