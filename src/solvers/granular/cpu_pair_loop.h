/* One specialisation of the cpu pair-force loop (included by cpu_loops.h
 * once per contact-model combination, so that the model switches of
 * px_gran_contact are compile-time constants and the loop vectorizes).
 * Defines before inclusion: PX_GRAN_PL_NAME, PX_GRAN_PL_NORMAL,
 * PX_GRAN_PL_TANG, PX_GRAN_PL_ROLL (0/1). The histories h* are updated in
 * place. No include guard. */
static void PX_GRAN_PL_NAME(const struct px_gran_law *law, const GS *restrict x,
                            const GS *restrict y, const GS *restrict vx, const GS *restrict vy,
                            const GS *restrict w, const GR *restrict r, const GR *restrict im,
                            const int32_t *restrict pi, const int32_t *restrict pj,
                            GR *restrict hxi, GR *restrict hth, GR *restrict hdm,
                            GR *restrict hdp, GR *restrict pfx,
                            GR *restrict pfy, GR *restrict pti, GR *restrict ptj, size_t k0,
                            size_t k1, GR dt) {
  struct px_gran_law L = *law;
  size_t k;
  L.normal = PX_GRAN_PL_NORMAL;
  L.tangential = PX_GRAN_PL_TANG;
  L.rolling = PX_GRAN_PL_ROLL;
#pragma omp simd
  for (k = k0; k < k1; ++k) {
    const int32_t i = pi[k], j = pj[k];
    const GR dx = (GR)(x[i] - x[j]), dy = (GR)(y[i] - y[j]);
    const GR ri = r[i], rj = r[j], rs = ri + rj;
    const GR d2 = dx * dx + dy * dy;
    const GR d = px_gran_sqrt(d2);
    const GR inv = (GR)1 / (d > (GR)0 ? d : (GR)1);
    const GR nx = dx * inv, ny = dy * inv;
    const GR delta = rs - d;
    const GR ai = ri - (GR)0.5 * delta, aj = rj - (GR)0.5 * delta;
    const GR dvx = (GR)(vx[i] - vx[j]), dvy = (GR)(vy[i] - vy[j]);
    const GR wi = (GR)w[i], wj = (GR)w[j];
    const GR vn = dvx * nx + dvy * ny;
    const GR vt = dvy * nx - dvx * ny - (ai * wi + aj * wj);
    const GR meff = (GR)1 / (im[i] + im[j]);
    const GR reff = ri * rj / rs;
    GR xi = hxi[k], th = hth[k], dm = hdm[k], dp = hdp[k], fn, ft, mr;
    px_gran_contact(&L, delta, vn, vt, wi - wj, meff, reff, dt, &xi, &th, &dm, &dp, &fn, &ft,
                    &mr);
    pfx[k] = fn * nx - ft * ny;
    pfy[k] = fn * ny + ft * nx;
    pti[k] = -ai * ft + mr;
    ptj[k] = -aj * ft - mr;
    hxi[k] = xi;
    hth[k] = th;
    hdm[k] = dm;
    hdp[k] = dp;
  }
}
#undef PX_GRAN_PL_NAME
#undef PX_GRAN_PL_NORMAL
#undef PX_GRAN_PL_TANG
#undef PX_GRAN_PL_ROLL
