/* The vortex solver's time step on an OpenCL device (vortex_opencl.c drives
 * it): the whole wake stays in device memory. Built with -DPX_REAL=float|double
 * (storage and most arithmetic) and -DVX_NB_REAL=float|double (the precision
 * of the N-body sums, px_nbody_direct's buffers).
 *
 * The physics is the cpu engine's (vortex_cpu.c, vortex_diffusive.c), through
 * the same functions of vortex_kernel.h. Neighbour searches are plain loops over all
 * vortices or panels with the same cut-off radii as the cpu tree queries (on a
 * GPU O(N^2) distance checks are cheap; the original CUDA code did the same),
 * so the sets of pairs are the cpu's; only the summation order differs.
 * Every work-item writes only its own outputs; reductions that need a fixed
 * order run in one work-group per panel or body with a fixed size and
 * reduction tree (the generation's right-hand side, the absorbed
 * circulation, the wall vorticity, the loads: a work-item per panel or body
 * alone scanned the whole wake, latency-bound on a GPU) or in one work-item
 * (the merges, down a list of the candidates that a work-group makes in
 * order). */
#include "solvers/vortex/vortex_kernel.h"

#ifndef VX_NB_REAL
#define VX_NB_REAL float
#endif
#if !defined(VX_OCL_GROUP) || !defined(VX_OCL_MERGE) /* vortex_ocl_state.h passes them */
#error "VX_OCL_GROUP, VX_OCL_MERGE not given"
#endif

/* The sum of v over the VX_OCL_GROUP work-items of the group, in every
 * work-item's return (red: the group's VX_OCL_GROUP entries of local memory;
 * a tree, the same order on every device). */
PX_FN px_real vx_group_sum(__local px_real *red, px_real v) {
  const uint l = get_local_id(0);
  barrier(CLK_LOCAL_MEM_FENCE);
  red[l] = v;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint h = VX_OCL_GROUP / 2; h > 0; h >>= 1) {
    if (l < h) red[l] += red[l + h];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  return red[0];
}

/* Copy the wake into the N-body sums' buffers (positions relative to c). */
__kernel void vx_to_nb(const uint n, __global const px_real *x, __global const px_real *y,
                       __global const px_real *g, const px_real cx, const px_real cy,
                       __global VX_NB_REAL *sx, __global VX_NB_REAL *sy, __global VX_NB_REAL *sg) {
  uint i = get_global_id(0);
  if (i >= n) return;
  sx[i] = (VX_NB_REAL)(x[i] - cx);
  sy[i] = (VX_NB_REAL)(y[i] - cy);
  sg[i] = (VX_NB_REAL)g[i];
}

/* Block 1a: right-hand side of the generation system. Rows i < n: panel i,
 * far part from the 2-point Gauss velocities (gu, gv at 2i, 2i+1), near
 * vortices (within 2 L_i + eps of the middle) by the exact point-vortex mean;
 * rows n + b: the circulation absorbed by body b in the last step. */
__kernel __attribute__((reqd_work_group_size(VX_OCL_GROUP, 1, 1))) void vx_rhs(
    const uint n, const uint nbody, __global const uint *first, __global const px_real *x0,
    __global const px_real *y0, __global const px_real *x1, __global const px_real *y1,
    __global const px_real *tx, __global const px_real *ty, __global const px_real *len,
    __global const VX_NB_REAL *gu, __global const VX_NB_REAL *gv, const uint nw,
    __global const px_real *x, __global const px_real *y, __global const px_real *g,
    const px_real eps, const px_real vx, const px_real vy, const px_real gauss,
    __global const px_real *through, __global px_real *rhs) {
  __local px_real red[VX_OCL_GROUP];
  const uint i = get_group_id(0), l = get_local_id(0);
  if (i >= n + nbody) return; /* the whole group */
  if (i >= n) {
    uint b = i - n;
    px_real s = 0;
    for (uint k = first[b] + l; k < first[b + 1]; k += VX_OCL_GROUP) s += through[k];
    s = vx_group_sum(red, s);
    if (l == 0) rhs[i] = s;
    return;
  }
  px_real t_x = tx[i], t_y = ty[i];
  px_real ax = x0[i], ay = y0[i], bx = x1[i], by = y1[i];
  px_real mx = PX_R(0.5) * (ax + bx), my = PX_R(0.5) * (ay + by);
  px_real r = PX_R(2.0) * len[i] + eps, r2 = r * r, eps2 = eps * eps, inv_len = 1 / len[i];
  px_real g0x = ax + gauss * (bx - ax), g0y = ay + gauss * (by - ay);
  px_real g1x = bx - gauss * (bx - ax), g1y = by - gauss * (by - ay);
  px_real corr = 0;
  for (uint j = l; j < nw; j += VX_OCL_GROUP) {
    px_real dx = x[j] - mx, dy = y[j] - my;
    if (dx * dx + dy * dy > r2) continue;
    corr += g[j] *
            vx_near_coef(ax, ay, bx, by, inv_len, t_x, t_y, g0x, g0y, g1x, g1y, eps2, x[j], y[j]);
  }
  corr = vx_group_sum(red, corr);
  if (l == 0) {
    px_real wk = PX_R(0.5) * (((px_real)gu[2 * i] + (px_real)gu[2 * i + 1]) * t_x +
                              ((px_real)gv[2 * i] + (px_real)gv[2 * i + 1]) * t_y);
    rhs[i] = -(vx * t_x + vy * t_y) - (wk + corr);
  }
}

/* Block 1b: sol = A^-1 rhs (the inverse is formed once on the host). */
/* The sheet: sol = ainv rhs, a work-group of VX_OCL_GROUP per row (its
 * work-items read the row together: coalesced) */
__kernel __attribute__((reqd_work_group_size(VX_OCL_GROUP, 1, 1))) void vx_solve(
    const uint ns, __global const px_real *ainv, __global const px_real *rhs,
    __global px_real *sol) {
  __local px_real red[VX_OCL_GROUP];
  const uint i = get_group_id(0), l = get_local_id(0);
  if (i >= ns) return; /* the whole group */
  __global const px_real *row = ainv + (size_t)i * ns;
  px_real s = 0;
  for (uint j = l; j < ns; j += VX_OCL_GROUP) s += row[j] * rhs[j];
  s = vx_group_sum(red, s);
  if (l == 0) sol[i] = s;
}

/* Block 1c: vortices per panel (at least vpp, more when |gamma L| > gamma_max)
 * and flags: bad[0] for runaway or non-finite intensities, bad[1] for a
 * panel whose count VX_NEWBORN_MAX caps (the host warns). */
__kernel void vx_shed_count(const uint n, __global const px_real *sol, __global const px_real *len,
                            const px_real gmax, const uint vpp, const px_real limit,
                            __global uint *count, __global uint *bad) {
  uint k = get_global_id(0);
  if (k >= n) return;
  count[k] = (uint)vx_newborn_count(fabs(sol[k] * len[k]), gmax, (int)vpp);
  if (!(fabs(sol[k]) <= limit)) bad[0] = k + 1; /* any one of them: all are errors */
  if (vx_newborn_capped(fabs(sol[k] * len[k]), gmax)) bad[1] = 1;
}

__kernel void vx_shed(const uint n, const uint base, __global const uint *start,
                      __global const uint *count, __global const px_real *sol,
                      __global const px_real *x0, __global const px_real *y0,
                      __global const px_real *x1, __global const px_real *y1,
                      __global const px_real *tx, __global const px_real *ty,
                      __global const px_real *len, const px_real delta, __global px_real *x,
                      __global px_real *y, __global px_real *g, __global int *born) {
  uint k = get_global_id(0);
  if (k >= n) return;
  uint m = count[k], q = base + start[k];
  px_real gl = sol[k] * len[k];
  px_real nx = ty[k], ny = -tx[k];
  for (uint j = 0; j < m; ++j) {
    px_real f = ((px_real)j + PX_R(0.5)) / (px_real)m;
    x[q + j] = x0[k] + f * (x1[k] - x0[k]) + delta * nx;
    y[q + j] = y0[k] + f * (y1[k] - y0[k]) + delta * ny;
    g[q + j] = gl / (px_real)m;
    born[q + j] = (int)k;
  }
}

/* Block 2: convective velocity. Old vortices: pair sum + free stream, and
 * near a panel the exact sheet instead of its newborn row; newborn ones: the
 * mean of the sheet's two limits, gamma tau / 2. */
__kernel void vx_convective(const uint nw, const uint nold, __global const VX_NB_REAL *nu,
                            __global const VX_NB_REAL *nv, __global const px_real *x,
                            __global const px_real *y, __global const px_real *g,
                            __global const int *born, const px_real vx, const px_real vy,
                            const uint n, __global const px_real *x0, __global const px_real *y0,
                            __global const px_real *x1, __global const px_real *y1,
                            __global const px_real *tx, __global const px_real *ty,
                            __global const px_real *len, __global const px_real *sol,
                            __global const uint *start, __global const uint *count,
                            const px_real eps, const int exact, __global px_real *u,
                            __global px_real *v) {
  uint i = get_global_id(0);
  if (i >= nw) return;
  if (i >= nold) {
    int k = born[i];
    u[i] = PX_R(0.5) * sol[k] * tx[k];
    v[i] = PX_R(0.5) * sol[k] * ty[k];
    return;
  }
  px_real ui = (px_real)nu[i] + vx, vi = (px_real)nv[i] + vy;
  if (exact) {
    px_real xi = x[i], yi = y[i], eps2 = eps * eps;
    for (uint k = 0; k < n; ++k) {
      px_real mx = PX_R(0.5) * (x0[k] + x1[k]) - xi, my = PX_R(0.5) * (y0[k] + y1[k]) - yi;
      px_real lim = PX_R(2.0) * len[k] + eps;
      if (mx * mx + my * my > lim * lim) continue;
      px_real2 s = vx_sheet_velocity(x0[k], y0[k], x1[k], y1[k], xi, yi);
      px_real du = 0, dv = 0;
      uint j0 = nold + start[k];
      for (uint j = j0; j < j0 + count[k]; ++j) {
        px_real2 bk = px_biot_savart_term(xi - x[j], yi - y[j], g[j], eps2);
        du += bk.x;
        dv += bk.y;
      }
      ui += sol[k] * s.x - du * PX_BIOT_SAVART_SCALE;
      vi += sol[k] * s.y - dv * PX_BIOT_SAVART_SCALE;
    }
  }
  u[i] = ui;
  v[i] = vi;
}

/* Block 3a: eps* = sqrt(mean of the squared distances to the 3 nearest). */
__kernel void vx_eps(const uint nw, __global const px_real *x, __global const px_real *y,
                     const px_real emin, __global px_real *e) {
  uint i = get_global_id(0);
  if (i >= nw) return;
  px_real xi = x[i], yi = y[i];
  px_real d0 = INFINITY, d1 = INFINITY, d2 = INFINITY;
  for (uint j = 0; j < nw; ++j) {
    if (j == i) continue;
    px_real dx = x[j] - xi, dy = y[j] - yi, q = dx * dx + dy * dy;
    if (q < d2) {
      if (q < d1) {
        d2 = d1;
        if (q < d0) {
          d1 = d0;
          d0 = q;
        } else {
          d1 = q;
        }
      } else {
        d2 = q;
      }
    }
  }
  e[i] = vx_eps_star(d0, d1, d2, emin);
}

/* Block 3b: VVD diffusive velocity W = nu (I2/(e I1) + I3/I0), |W| <= vcap
 * (vx_vvd_particle, vx_vvd_wall). */
__kernel void vx_vvd(const uint nw, __global const px_real *x, __global const px_real *y,
                     __global const px_real *g, __global const px_real *e, const int self,
                     const uint n, __global const px_real *x0, __global const px_real *y0,
                     __global const px_real *tx, __global const px_real *ty,
                     __global const px_real *len, const px_real lmax, const px_real cut,
                     const px_real nu, const px_real vcap, __global const int *born,
                     const uint nold, const px_real w_born, const int moments, __global px_real *wu,
                     __global px_real *wv) {
  uint i = get_global_id(0);
  if (i >= nw) return;
  px_real xi = x[i], yi = y[i], ei = e[i], inv_e = 1 / ei;
  px_real r2max = cut * ei * cut * ei, tiny2 = PX_R(1e-24) * ei * ei;
  px_real i1 = 0, i1abs = 0, i2x = 0, i2y = 0, m0 = 0, m1 = 0;
  /* vvd_moments: covariance, the Gaussian-weighted moments of the same-sign
   * neighbours and the vortex itself (vortex_diffusive.c, vvd_covariance) */
  px_real c0 = g[i], cx = 0, cy = 0, cxx = 0, cxy = 0, cyy = 0;
  for (uint j = 0; j < nw; ++j) {
    px_real dx = xi - x[j], dy = yi - y[j], r2 = dx * dx + dy * dy;
    if (r2 > r2max || j == i) continue;
    px_real r = sqrt(r2), ex = vx_exp_neg(r * inv_e), ge = g[j] * ex;
    px_real rinv = r2 > tiny2 ? 1 / r : 0;
    i1 += ge;
    i1abs += fabs(g[j]) * ex;
    i2x += ge * dx * rinv;
    i2y += ge * dy * rinv;
    m0 += ex;
    m1 += ex * r;
    if (moments == 2 && g[j] * g[i] > 0) {
      px_real wg = g[j] * vx_cov_weight(r2, inv_e);
      c0 += wg;
      cx += wg * dx;
      cy += wg * dy;
      cxx += wg * dx * dx;
      cxy += wg * dx * dy;
      cyy += wg * dy * dy;
    }
  }
  if (self) {
    i1 += g[i];
    i1abs += fabs(g[i]);
    m0 += 1;
  }
  px_real s0 = 0, i3x = 0, i3y = 0;
  uint nwall = 0;
  if (n > 0) {
    px_real rr = cut * ei + PX_R(0.5) * lmax;
    for (uint k = 0; k < n; ++k) {
      px_real t_x = tx[k], t_y = ty[k], L = len[k];
      px_real mx = x0[k] + PX_R(0.5) * L * t_x - xi, my = y0[k] + PX_R(0.5) * L * t_y - yi;
      if (mx * mx + my * my > rr * rr) continue;
      px_real rx = xi - x0[k], ry = yi - y0[k];
      px_real s = rx * t_x + ry * t_y, h = rx * t_y - ry * t_x, S3, S0;
      vx_panel_wall(s, h, L, ei, cut, &S3, &S0);
      s0 += S0;
      i3x += t_y * S3;
      i3y += -t_x * S3;
      ++nwall;
    }
  }
  /* the particle term's length: eps*, or M1 / (2 M0) away from walls
   * (vvd_moments, as vortex_diffusive.c) */
  px_real el = moments == 1 && nwall == 0 ? vx_vvd_length(ei, m0, m1) : ei;
  px_real wx, wy;
  vx_vvd_particle(i1, i1abs, i2x, i2y, el, &wx, &wy);
  if (moments == 2 && nwall == 0) vx_cov_velocity(c0, cx, cy, cxx, cxy, cyy, ei, &wx, &wy);
  if (n > 0) vx_vvd_wall(ei, s0, i3x, i3y, &wx, &wy);
  wx *= nu;
  wy *= nu;
  px_real m = sqrt(wx * wx + wy * wy);
  if (vcap > 0 && m > vcap) {
    wx *= vcap / m;
    wy *= vcap / m;
  }
  if (w_born > 0 && i >= nold) { /* newborn: the Rayleigh drift (vortex_diffusive.c) */
    wx = w_born * ty[born[i]];
    wy = -w_born * tx[born[i]];
  }
  wu[i] = wx;
  wv[i] = wy;
}

/* Block 4a: panel domain radius and mean wall vorticity over each panel: one
 * work-group of VX_OCL_GROUP per panel, each work-item every
 * VX_OCL_GROUP-th vortex. */
__kernel __attribute__((reqd_work_group_size(VX_OCL_GROUP, 1, 1))) void vx_wall(
    const uint n, __global const uint *start, __global const uint *count, const uint nold,
    __global const px_real *e, const px_real emin, __global const px_real *x0,
    __global const px_real *y0, __global const px_real *tx, __global const px_real *ty,
    __global const px_real *len, const uint nw, __global const px_real *x,
    __global const px_real *y, __global const px_real *g, const px_real cut,
    __global px_real *pe, __global px_real *omega) {
  __local px_real red[VX_OCL_GROUP];
  const uint k = get_group_id(0), l = get_local_id(0);
  if (k >= n) return; /* the whole group */
  px_real ek = 0;
  uint j0 = nold + start[k], m = count[k];
  for (uint j = j0; j < j0 + m; ++j) ek += e[j];
  ek = m ? ek / (px_real)m : emin;
  px_real t_x = tx[k], t_y = ty[k], L = len[k];
  px_real mx = x0[k] + PX_R(0.5) * L * t_x, my = y0[k] + PX_R(0.5) * L * t_y;
  px_real rr = cut * ek + PX_R(0.5) * L, acc = 0;
  for (uint j = l; j < nw; j += VX_OCL_GROUP) {
    px_real dx = x[j] - mx, dy = y[j] - my;
    if (dx * dx + dy * dy > rr * rr) continue;
    px_real rx = x[j] - x0[k], ry = y[j] - y0[k];
    px_real s = rx * t_x + ry * t_y, h = rx * t_y - ry * t_x, S3, S0;
    vx_panel_wall(s, h, L, ek, cut, &S3, &S0);
    acc += g[j] * S3;
  }
  acc = vx_group_sum(red, acc);
  if (l == 0) {
    pe[k] = ek;
    omega[k] = acc / (PX_R(3.14159265358979323846) * ek * ek * L);
  }
}

/* Block 4b: forces and moments per body (one work-group of VX_OCL_GROUP per
 * body, each work-item every VX_OCL_GROUP-th vortex and panel): out[10 b ..]
 * = fx, fy, m (vorticity flux part), fx, fy, m (friction from the wall
 * vorticity), circulation absorbed in the last step, fx, fy, m (friction
 * from the diffusive drift). */
__kernel __attribute__((reqd_work_group_size(VX_OCL_GROUP, 1, 1))) void vx_loads(
    const uint nbody, __global const uint *first, __global const px_real *x0,
    __global const px_real *y0, __global const px_real *tx, __global const px_real *ty,
    __global const px_real *len, __global const px_real *sol, __global const px_real *through,
    __global const px_real *omega, __global const px_real *center, const px_real rho,
    const px_real nu, const uint nw, __global const px_real *x, __global const px_real *y,
    __global const px_real *g, __global const px_real *wu, __global const px_real *wv,
    __global px_real *out) {
  __local px_real red[VX_OCL_GROUP];
  const uint b = get_group_id(0), l = get_local_id(0);
  if (b >= nbody) return; /* the whole group */
  /* diffusive drift of the vortices nearest to this body's centre (as the cpu):
   * rho sum Gamma_i (k x W_i) and rho sum Gamma_i (r_i - c) . W_i */
  px_real dfx = 0, dfy = 0, dm = 0;
  for (uint i = l; i < nw; i += VX_OCL_GROUP) {
    uint bb = 0;
    px_real best = 0;
    for (uint q = 0; q < nbody && nbody > 1; ++q) {
      px_real dx = x[i] - center[2 * q], dy = y[i] - center[2 * q + 1];
      px_real d2 = dx * dx + dy * dy;
      if (q == 0 || d2 < best) {
        best = d2;
        bb = q;
      }
    }
    if (bb != b) continue;
    dfx += -g[i] * wv[i];
    dfy += g[i] * wu[i];
    dm += g[i] * ((x[i] - center[2 * b]) * wu[i] + (y[i] - center[2 * b + 1]) * wv[i]);
  }
  px_real cx = center[2 * b], cy = center[2 * b + 1];
  px_real fx = 0, fy = 0, m = 0, ffx = 0, ffy = 0, fm = 0, ab = 0;
  for (uint k = first[b] + l; k < first[b + 1]; k += VX_OCL_GROUP) {
    px_real d = sol[k] * len[k] - through[k];
    ab += through[k];
    px_real rx = x0[k] + PX_R(0.5) * len[k] * tx[k] - cx,
            ry = y0[k] + PX_R(0.5) * len[k] * ty[k] - cy;
    fx += -d * ry;
    fy += d * rx;
    m += PX_R(0.5) * d * (rx * rx + ry * ry);
    px_real tf = rho * nu * omega[k] * len[k];
    ffx += tf * tx[k];
    ffy += tf * ty[k];
    fm += tf * (rx * ty[k] - ry * tx[k]);
  }
  const px_real sums[10] = {fx, fy, m, ffx, ffy, fm, ab, rho * dfx, rho * dfy, rho * dm};
  for (int q = 0; q < 10; ++q) {
    const px_real v = vx_group_sum(red, sums[q]);
    if (l == 0) out[10 * b + q] = v;
  }
}

/* First panel crossed by the path p -> q, or -1. */
PX_FN int vx_crossed(px_real px, px_real py, px_real qx, px_real qy, const uint n,
                     __global const px_real *x0, __global const px_real *y0,
                     __global const px_real *x1, __global const px_real *y1, const uint nbody,
                     __global const px_real *bbox) {
  px_real bx0 = fmin(px, qx), bx1 = fmax(px, qx), by0 = fmin(py, qy), by1 = fmax(py, qy);
  int any = 0;
  for (uint b = 0; b < nbody && !any; ++b)
    any = !(bx1 < bbox[4 * b] || bx0 > bbox[4 * b + 2] || by1 < bbox[4 * b + 1] ||
            by0 > bbox[4 * b + 3]);
  if (!any) return -1;
  int best = -1;
  px_real tbest = 2;
  for (uint k = 0; k < n; ++k) {
    px_real t;
    if (vx_seg_cross(px, py, qx, qy, x0[k], y0[k], x1[k], y1[k], &t) && t < tbest) {
      tbest = t;
      best = (int)k;
    }
  }
  return best;
}

/* Block 5 with rk2 (vortex_cpu.c, heun): keep the step's positions and
 * convective velocities, move to the predictor positions; then, with the
 * second stage's velocities in u, v, back to the step's positions with the
 * mean velocity (vx_move then moves by it). */
__kernel void vx_rk2_predict(const uint nw, __global px_real *x, __global px_real *y,
                             __global const px_real *u, __global const px_real *v,
                             __global const px_real *wu, __global const px_real *wv,
                             const px_real dt, __global px_real *x1, __global px_real *y1,
                             __global px_real *u1, __global px_real *v1, const uint n,
                             __global const px_real *px0, __global const px_real *py0,
                             __global const px_real *px1, __global const px_real *py1,
                             const uint nbody, __global const px_real *bbox, __global px_real *wu1,
                             __global px_real *wv1) {
  uint i = get_global_id(0);
  if (i >= nw) return;
  x1[i] = x[i];
  y1[i] = y[i];
  u1[i] = u[i];
  v1[i] = v[i];
  wu1[i] = wu[i];
  wv1[i] = wv[i];
  px_real qx = x1[i] + (u1[i] + wu[i]) * dt, qy = y1[i] + (v1[i] + wv[i]) * dt;
  /* a predicted move across a panel: the vortex waits at its start (heun() in
   * vortex_cpu.c) */
  if (n > 0 && vx_crossed(x1[i], y1[i], qx, qy, n, px0, py0, px1, py1, nbody, bbox) >= 0) {
    qx = x1[i];
    qy = y1[i];
  }
  x[i] = qx;
  y[i] = qy;
}

__kernel void vx_rk2_correct(const uint nw, __global px_real *x, __global px_real *y,
                             __global px_real *u, __global px_real *v, __global const px_real *x1,
                             __global const px_real *y1, __global const px_real *u1,
                             __global const px_real *v1, __global px_real *wu, __global px_real *wv,
                             __global const px_real *wu1, __global const px_real *wv1) {
  uint i = get_global_id(0);
  if (i >= nw) return;
  x[i] = x1[i];
  y[i] = y1[i];
  u[i] = PX_R(0.5) * (u1[i] + u[i]);
  v[i] = PX_R(0.5) * (v1[i] + v[i]);
  wu[i] = PX_R(0.5) * (wu1[i] + wu[i]);
  wv[i] = PX_R(0.5) * (wv1[i] + wv[i]);
}

/* Blocks 5 and 6: explicit Euler move and the panel crossed on the way. */
__kernel void vx_move(const uint nw, __global const px_real *x, __global const px_real *y,
                      __global const px_real *u, __global const px_real *v,
                      __global const px_real *wu, __global const px_real *wv, const px_real dt,
                      const uint n, __global const px_real *x0, __global const px_real *y0,
                      __global const px_real *x1, __global const px_real *y1, const uint nbody,
                      __global const px_real *bbox, __global px_real *xn, __global px_real *yn,
                      __global int *hit) {
  uint i = get_global_id(0);
  if (i >= nw) return;
  px_real qx = x[i] + (u[i] + wu[i]) * dt, qy = y[i] + (v[i] + wv[i]) * dt;
  xn[i] = qx;
  yn[i] = qy;
  hit[i] = vx_crossed(x[i], y[i], qx, qy, n, x0, y0, x1, y1, nbody, bbox);
}

/* Circulation absorbed by each panel (vortices in index order). */
__kernel __attribute__((reqd_work_group_size(VX_OCL_GROUP, 1, 1))) void vx_through(
    const uint n, const uint nw, __global const int *hit, __global const px_real *g,
    __global px_real *through) {
  __local px_real red[VX_OCL_GROUP];
  const uint k = get_group_id(0), l = get_local_id(0);
  if (k >= n) return; /* the whole group */
  px_real s = 0;
  for (uint i = l; i < nw; i += VX_OCL_GROUP)
    if (hit[i] == (int)k) s += g[i];
  s = vx_group_sum(red, s);
  if (l == 0) through[k] = s;
}

/* Block 7a: which vortices survive (not absorbed, not empty, not far). */
__kernel void vx_keep(const uint nw, __global const int *hit, __global const px_real *g,
                      __global const px_real *xn, __global const px_real *yn, const px_real cx,
                      const px_real cy, const px_real far2, __global uint *keep) {
  uint i = get_global_id(0);
  if (i >= nw) return;
  px_real dx = xn[i] - cx, dy = yn[i] - cy;
  keep[i] = (hit[i] < 0 && g[i] != 0 && dx * dx + dy * dy <= far2) ? 1u : 0u;
}

/* Move the survivors to their places pos[i] in the second set of arrays. */
__kernel void vx_compact(const uint nw, __global const uint *keep, __global const uint *pos,
                         __global const px_real *xs, __global const px_real *ys,
                         __global const px_real *gs, __global const px_real *us,
                         __global const px_real *vs, __global const px_real *es,
                         __global px_real *xd, __global px_real *yd, __global px_real *gd,
                         __global px_real *ud, __global px_real *vd, __global px_real *ed) {
  uint i = get_global_id(0);
  if (i >= nw || !keep[i]) return;
  uint k = pos[i];
  xd[k] = xs[i];
  yd[k] = ys[i];
  gd[k] = gs[i];
  ud[k] = us[i];
  vd[k] = vs[i];
  ed[k] = es[i];
}

/* Block 7b: each vortex's nearest eligible merge partner (ties to the lower
 * index), the merged position and whether that merge keeps clear of the
 * bodies. Same rules as the cpu: same sign within eps_col f, |G1 + G2| <
 * gamma_max f^2; opposite signs within eps_col_opposite f; f grows
 * downstream. */
__kernel void vx_partner(const uint nw, __global const px_real *x, __global const px_real *y,
                         __global const px_real *g, const px_real ec, const px_real eo,
                         const px_real gmax, const px_real sdx, const px_real sdy,
                         const px_real s_right, const px_real span, const uint n,
                         __global const px_real *x0, __global const px_real *y0,
                         __global const px_real *x1, __global const px_real *y1, const uint nbody,
                         __global const px_real *bbox, __global int *partner, __global px_real *mx,
                         __global px_real *my) {
  uint i = get_global_id(0);
  if (i >= nw) return;
  px_real xi = x[i], yi = y[i], gi = g[i];
  px_real f = vx_merge_growth(xi * sdx + yi * sdy, s_right, span);
  px_real rs = ec * f, ro = eo * f, rb = rs > ro ? rs : ro, gcap = gmax * f * f;
  int best = -1;
  px_real dbest = INFINITY;
  for (uint j = 0; j < nw; ++j) {
    if (j == i) continue;
    px_real dx = x[j] - xi, dy = y[j] - yi, d2 = dx * dx + dy * dy;
    if (d2 > rb * rb) continue;
    px_real gj = g[j];
    if (vx_merge_ok(gi, gj, d2, rs, ro, gcap) && d2 < dbest) {
      dbest = d2;
      best = (int)j;
    }
  }
  px_real nx = xi, ny = yi;
  if (best >= 0) {
    px_real xj = x[best], yj = y[best];
    vx_merge_position(gi, g[best], xi, yi, xj, yj, &nx, &ny);
    if (vx_crossed(xi, yi, nx, ny, n, x0, y0, x1, y1, nbody, bbox) >= 0 ||
        vx_crossed(xj, yj, nx, ny, n, x0, y0, x1, y1, nbody, bbox) >= 0)
      best = -1;
  }
  partner[i] = best;
  mx[i] = nx;
  my[i] = ny;
}

/* Block 7c: the greedy merge, in index order, in one work-item (the only
 * sequential part; O(N)). keep[i] = 0 for a vortex merged into another. */
/* The merges of the step, in the order of the vortices (vortex i with its
 * partner j where neither merged before in this order): one work-group of
 * VX_OCL_MERGE. Its work-items flag and list, in order, the vortices with a
 * partner (into cand, nw entries of scratch); one work-item merges down that
 * list (the same decisions as down the whole wake: hundreds of candidates,
 * not nw vortices, for one work-item); all then settle the flags. */
__kernel __attribute__((reqd_work_group_size(VX_OCL_MERGE, 1, 1))) void vx_merge(
    const uint nw, __global const int *partner, __global const px_real *mx,
    __global const px_real *my, __global px_real *x, __global px_real *y, __global px_real *g,
    __global uint *keep, __global uint *merged, __global uint *cand) {
  __local uint cnt[VX_OCL_MERGE];
  const uint l = get_local_id(0), chunk = (nw + VX_OCL_MERGE - 1) / VX_OCL_MERGE;
  const uint i0 = min(nw, l * chunk), i1 = min(nw, i0 + chunk);
  uint c = 0;
  for (uint i = i0; i < i1; ++i) {
    keep[i] = 1u;
    c += partner[i] >= 0;
  }
  cnt[l] = c;
  barrier(CLK_LOCAL_MEM_FENCE);
  uint at = 0, total = 0;
  for (uint q = 0; q < VX_OCL_MERGE; ++q) {
    at += q < l ? cnt[q] : 0u;
    total += cnt[q];
  }
  for (uint i = i0; i < i1; ++i)
    if (partner[i] >= 0) cand[at++] = i;
  barrier(CLK_GLOBAL_MEM_FENCE);
  if (l == 0) {
    uint m = 0;
    for (uint q = 0; q < total; ++q) {
      const uint i = cand[q];
      const int j = partner[i];
      if (keep[i] != 1u || keep[j] != 1u) continue;
      x[i] = mx[i];
      y[i] = my[i];
      g[i] = g[i] + g[j];
      g[j] = 0;
      keep[j] = 0u;
      keep[i] = 2u; /* merged: neither may merge again this step */
      ++m;
    }
    merged[0] = m;
  }
  barrier(CLK_GLOBAL_MEM_FENCE);
  for (uint i = i0; i < i1; ++i)
    if (keep[i] == 2u) keep[i] = g[i] != 0 ? 1u : 0u;
}

/* Wake circulation check: any non-finite value flags the step. */
__kernel void vx_finite(const uint nw, __global const px_real *a, __global const px_real *b,
                        __global uint *bad) {
  uint i = get_global_id(0);
  if (i >= nw) return;
  if (!isfinite(a[i]) || !isfinite(b[i])) bad[0] = i + 1;
}
