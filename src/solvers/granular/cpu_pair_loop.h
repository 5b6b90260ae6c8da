/* One specialisation of the cpu pair-force loop (included by cpu_loops.h
 * once per contact-model combination, so that the model switches of
 * px_gran_contact are compile-time constants and the loop vectorizes). The
 * force of a pair is px_gran_pair (pair_kernel.h, shared with granular.cl).
 * Defines before inclusion: PX_GRAN_PL_NAME, PX_GRAN_PL_NORMAL,
 * PX_GRAN_PL_TANG, PX_GRAN_PL_ROLL (0/1). The histories h* are updated in
 * place.
 * Positions and velocities come as PX_GRAN_PT arrays: the state itself, or
 * (PX_GRAN_RELPOS, mixed precision) float copies of the velocities and float
 * offsets of the positions from those at the last rebuild, the pair's
 * separation at the rebuild being in dxr/dyr: x_i - x_j = dxr + (ox_i - ox_j)
 * keeps the precision of the double state while the gathers load floats.
 * There x holds the offsets as (ox, oy) pairs and vx the velocities as
 * (vx, vy) pairs, each pair loaded as one 64-bit word (y and vy unused):
 * per 16 pairs, 8 gathers of 8 x 64 bits instead of 8 of 16 x 32 bits (half
 * the elements), 8 % more disc-steps per second on a Zen 5 core.
 * No include guard. */
static void PX_GRAN_PL_NAME(const struct px_gran_law *law, const PX_GRAN_PT *restrict x,
                            const PX_GRAN_PT *restrict y, const PX_GRAN_PT *restrict vx,
                            const PX_GRAN_PT *restrict vy, const PX_GRAN_PT *restrict w,
                            const GR *restrict dxr, const GR *restrict dyr, const GR *restrict pri,
                            const GR *restrict prj, const GR *restrict pcn, const GR *restrict pre,
                            const int32_t *restrict pi, const int32_t *restrict pj,
                            GR *restrict hxi, GR *restrict hth, GR *restrict hdm, GR *restrict hdp,
                            GR *restrict pfx, GR *restrict pfy, GR *restrict pti, GR *restrict ptj,
                            size_t k0, size_t k1, GR dt) {
  struct px_gran_law L = *law;
  size_t k;
#ifndef PX_GRAN_RELPOS
  (void)dxr;
  (void)dyr;
#endif
  L.normal = PX_GRAN_PL_NORMAL;
  L.tangential = PX_GRAN_PL_TANG;
  L.rolling = PX_GRAN_PL_ROLL;
#pragma omp simd simdlen(PX_GRAN_SIMDLEN)
  for (k = k0; k < k1; ++k) {
    const int32_t i = pi[k], j = pj[k];
#ifdef PX_GRAN_RELPOS
    /* (x, y) and (vx, vy) interleaved: one 64-bit gather per pair of them */
    const GR xi = px_gran_lo(x, i), xj = px_gran_lo(x, j), yi = px_gran_hi(x, i),
             yj = px_gran_hi(x, j);
    const GR vxi = px_gran_lo(vx, i), vxj = px_gran_lo(vx, j), vyi = px_gran_hi(vx, i),
             vyj = px_gran_hi(vx, j);
    const GR dx = dxr[k] + (xi - xj), dy = dyr[k] + (yi - yj);
    const GR dvx = vxi - vxj, dvy = vyi - vyj;
    (void)y;
    (void)vy;
#else
    const GR dx = (GR)(x[i] - x[j]), dy = (GR)(y[i] - y[j]);
    const GR dvx = (GR)(vx[i] - vx[j]), dvy = (GR)(vy[i] - vy[j]);
#endif
    GR xs = hxi[k], th = hth[k], dm = hdm[k], dp = hdp[k];
    px_gran_pair(&L, dx, dy, dvx, dvy, (GR)w[i], (GR)w[j], pri[k], prj[k], pcn[k], pre[k], dt, &xs,
                 &th, &dm, &dp, &pfx[k], &pfy[k], &pti[k], &ptj[k]);
    /* only the histories the model uses (the others stay 0) */
    if (PX_GRAN_PL_TANG == PX_GRAN_TANGENTIAL_SPRING) hxi[k] = xs;
    if (PX_GRAN_PL_ROLL) hth[k] = th;
    if (PX_GRAN_PL_NORMAL == PX_GRAN_NORMAL_HYSTERETIC) hdm[k] = dm;
    hdp[k] = dp;
  }
}
#undef PX_GRAN_PL_NAME
#undef PX_GRAN_PL_NORMAL
#undef PX_GRAN_PL_TANG
#undef PX_GRAN_PL_ROLL
