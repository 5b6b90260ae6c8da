/* The cpu engine's non-simd loops for one real type (fracture, output
 * fields, constants): included after lattice_cpu_impl.h by
 * lattice_cpu_f32.c and lattice_cpu_f64.c (PX_REAL float, double), giving
 * px_lattice_cpu_*_f32 / _f64 (declared in lattice_cpu.h). */
#ifndef PX_LATTICE_CPU_FIELDS_IMPL_H
#define PX_LATTICE_CPU_FIELDS_IMPL_H

#include <omp.h>
#include <string.h>

#include "solvers/lattice/lattice_cpu.h"
/* (after the model's headers: see lattice_cpu_impl.h) */
#include "kernels/px_kernel.h"
#include "solvers/lattice/lattice_kernel.h"
#undef I

/* Fracture: every element evaluates its six links at state y (canonical form,
 * so both ends decide alike) and clears its own flags of the links that
 * break. Returns the number of link ends cleared (2 per broken link). */
long PX_SFX(px_lattice_cpu_fracture)(struct px_lattice_cpu *e, const px_real *restrict y, long r0,
                                     long r1) {
  const struct px_lattice_model *m = e->m;
  const size_t ns = e->ns, n0 = m->n0p;
  const size_t s1 = (size_t)m->stride[1], s2 = (size_t)m->stride[2];
  const struct lt_lpar p = *(const struct lt_lpar *)e->lpar;
  const struct lt_fpar fp = *(const struct lt_fpar *)e->fpar;
  uint8_t *restrict lpv = e->lp, *restrict lmv = e->lm;
  long r, ends = 0;
#pragma omp parallel for num_threads(e->active) schedule(dynamic, LT_ROWS_CHUNK) reduction(+ : ends)
  for (r = r0; r < r1; ++r) {
    const size_t base = m->pad + (size_t)r * n0;
    long x;
    for (x = e->row_lo[r]; x < e->row_hi[r]; ++x) {
      const size_t i = base + (size_t)x;
      unsigned lp = lpv[i], lm = lmv[i];
      if (!(lp | lm)) continue;
      ends += lt_fracture_el(&p, &fp, y, ns, i, s1, s2, lt_load(y, ns, i), &lp, &lm);
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
 * wanted), of the elements of rows [r0, r1); with `sums`, the Rayleigh sums
 * of each of those rows into e->rowsum (3 arrays of n[1] n[2]: the caller
 * adds them in row order, the same order on any number of ranks). */
void PX_SFX(px_lattice_cpu_fields)(struct px_lattice_cpu *e, const px_real *restrict y,
                                   double t_sync_dt, const struct px_lattice_fields *f, int sums,
                                   long r0, long r1) {
  const struct px_lattice_model *m = e->m;
  const size_t ns = e->ns, n0 = m->n0p;
  const size_t s1 = (size_t)m->stride[1], s2 = (size_t)m->stride[2];
  const size_t nrow = (size_t)m->grid.n[1] * (size_t)m->grid.n[2];
  const struct lt_lpar p = *(const struct lt_lpar *)e->lpar;
  const px_real *restrict tab = (const px_real *)e->table;
  const double inv_v = 1.0 / (m->grid.h * m->grid.h * m->grid.h);
  const int sync = e->integ == PX_LATTICE_INTEGRATOR_LEAPFROG;
  double *rown = e->rowsum, *rowd = e->rowsum + nrow, *rowk = e->rowsum + 2 * nrow;
  const px_real *restrict pv = (const px_real *)e->pv; /* current: px_lattice_cpu_vol */
  const int need_ft = sums || (f && f->v && sync);
  long r;
#pragma omp parallel for num_threads(e->active) schedule(dynamic, LT_ROWS_CHUNK)
  for (r = r0; r < r1; ++r) {
    const size_t base = m->pad + (size_t)r * n0;
    double sn = 0.0, sd = 0.0, sk = 0.0;
    long x;
    for (x = e->row_lo[r]; x < e->row_hi[r]; ++x) {
      const size_t i = base + (size_t)x;
      struct lt_el el = lt_load(y, ns, i);
      struct lt_v3 F = lt_v3_make(0, 0, 0), T = F;
      if (m->group[i] == 0) continue;
      /* the links' force and torque: for the sums and a leapfrog velocity
       * only (u and the stresses do not read them) */
      if (need_ft) {
        struct lt_ft ft =
            pv ? lt_gather_v(&p, y, pv, ns, i, s1, s2, lt_lfl_bits(e->lp[i], e->lm[i]), el)
               : lt_gather(&p, y, ns, i, s1, s2, lt_lfl_bits(e->lp[i], e->lm[i]), el);
        F = ft.F;
        T = ft.T;
      }
      if (f && f->u) {
        f->u[3 * i] = (double)el.u.x;
        f->u[3 * i + 1] = (double)el.u.y;
        f->u[3 * i + 2] = (double)el.u.z;
      }
      if (f && f->v) {
        struct lt_v3 v = el.v;
        if (sync) {
          struct lt_dvw d =
              lt_accel(tab + (size_t)m->group[i] * LT_GROUP_STRIDE, (px_real)(1.0 / m->m),
                       (px_real)(1.0 / m->I), (px_real)e->alpha, F, T, el.v, el.W);
          v = lt_v3_add(v, lt_v3_scale((px_real)(0.5 * t_sync_dt), d.dv));
        }
        f->v[3 * i] = (double)v.x;
        f->v[3 * i + 1] = (double)v.y;
        f->v[3 * i + 2] = (double)v.z;
      }
      if (f && (f->sigma || f->vm)) {
        struct lt_sym s = lt_stress_el_v(&p, y, pv, ns, i, s1, s2, e->lp[i], e->lm[i], el);
        if (f->sigma) {
          f->sigma[6 * i] = (double)s.xx * inv_v;
          f->sigma[6 * i + 1] = (double)s.yy * inv_v;
          f->sigma[6 * i + 2] = (double)s.zz * inv_v;
          f->sigma[6 * i + 3] = (double)s.xy * inv_v;
          f->sigma[6 * i + 4] = (double)s.yz * inv_v;
          f->sigma[6 * i + 5] = (double)s.zx * inv_v;
        }
        if (f->vm) f->vm[i] = (double)lt_von_mises(s) * inv_v;
      }
      if (sums) {
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
}

/* The link constants of the model (double, lattice_cpu.h) in this
 * precision, into e->lpar and e->fpar. */
void PX_SFX(px_lattice_cpu_params)(struct px_lattice_cpu *e, const double lpar[6],
                                   const double fpar[4]) {
  struct lt_lpar lp;
  struct lt_fpar fp;
  lp.h2 = (px_real)lpar[0];
  lp.k = (px_real)lpar[1];
  lp.cl = (px_real)lpar[2];
  lp.kb = (px_real)lpar[3];
  lp.dk = (px_real)lpar[4];
  lp.cr = (px_real)lpar[5];
  fp.ifn = (px_real)fpar[0];
  fp.ift = (px_real)fpar[1];
  fp.imb = (px_real)fpar[2];
  fp.imt = (px_real)fpar[3];
  memcpy(e->lpar, &lp, sizeof lp);
  memcpy(e->fpar, &fp, sizeof fp);
}

#endif
