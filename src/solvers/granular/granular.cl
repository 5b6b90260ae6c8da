/* The granular solver on OpenCL devices (granular_opencl.c drives it).
 * Built with -DPX_REAL=float|double (contact arithmetic) and
 * -DPX_GRAN_STATE=float|double (integrated state; mixed = double state,
 * float contacts). The physics is the text the cpu loops compile: the pair
 * force in pair_kernel.h (contact laws in contact_kernel.h), wall contacts
 * in wall_kernel.h, integrator updates in integrate_kernel.h.
 *
 * Layout: particles are not reordered; every particle keeps a full
 * neighbour list of at most PX_GRAN_NMAX partners (both directions, so each
 * work-item sums its own force without atomics) with one history slot per
 * entry. The two copies of a pair's history evolve identically (the scalar
 * tangential spring is symmetric, the rolling angle antisymmetric; see
 * contact_kernel.h). Wall candidates: at most PX_GRAN_WCMAX per particle. */
#if defined(cl_khr_fp64)
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#endif
#include "solvers/granular/integrate_kernel.h"
#include "solvers/granular/pair_kernel.h"
#include "solvers/granular/wall_kernel.h"

#define GS PX_GRAN_STATE
#define GR PX_REAL

#ifndef PX_GRAN_NMAX
#define PX_GRAN_NMAX 16
#endif
#ifndef PX_GRAN_WCMAX
#define PX_GRAN_WCMAX 24
#endif

/* Velocity Verlet drift of the discs own[0..n) (every disc on one rank); the largest displacement
 * since the rebuild goes to *maxdisp as the bits of a non-negative float (integer order = float
 * order). */
__kernel void gran_drift(const uint n, __global const uint *own, const GS h, __global GS *x,
                         __global GS *y, __global GS *vx, __global GS *vy, __global GS *w,
                         __global const GS *ax, __global const GS *ay, __global const GS *aw,
                         __global const GS *xr, __global const GS *yr, __global uint *maxdisp) {
  const uint g = get_global_id(0);
  uint i;
  GS xi, yi, vxi, vyi, wi, dummy = 0, dx, dy;
  float d;
  if (g >= n) return;
  i = own[g];
  xi = x[i], yi = y[i], vxi = vx[i], vyi = vy[i], wi = w[i];
  px_gran_vv_drift(&xi, &vxi, ax[i], h);
  px_gran_vv_drift(&yi, &vyi, ay[i], h);
  px_gran_vv_drift(&dummy, &wi, aw[i], h);
  x[i] = xi, y[i] = yi, vx[i] = vxi, vy[i] = vyi, w[i] = wi;
  dx = xi - xr[i];
  dy = yi - yr[i];
  d = (float)sqrt(dx * dx + dy * dy);
  atomic_max(maxdisp, as_uint(d));
}

/* Pair and wall forces of particle i = own[g] (the discs this rank owns:
 * all of them, in id order, on one rank), then the velocity Verlet kick into
 * vxn, vyn, wn (the host swaps them with vx, vy, w: the neighbours'
 * velocities read here are all of the step's start, as on the cpu).
 * step_no: the step number (not `step`, an OpenCL built-in that some
 * compilers rename, which would hide the name from the argument checks). */
__kernel void gran_forces(
    const uint n, __global const uint *own, const GR dt, const int step_no, const GS gx,
    const GS gy, __constant GR *lawp, __constant GR *laww, __global const GS *x,
    __global const GS *y, __global const GS *vx, __global const GS *vy, __global const GS *w,
    __global GS *ax, __global GS *ay, __global GS *aw, __global const GR *r, __global const GR *m,
    __global const GR *im, __global const GR *iI, __global const int *id,
    __global const int *ncount, __global const int *nbr, __global GR *hxi, __global GR *hth,
    __global GR *hdm, __global GR *hdp,
    /* walls (nseg may be 0) */
    const int has_walls, __global const GS *sax, __global const GS *say, __global const GS *stx,
    __global const GS *sty, __global const GS *slen, __global const GS *stpx,
    __global const GS *stpy, __global const int *sflags, __global const int *scontour,
    __global const int *cfirst, __global const int *ccount, __global const GS *frames,
    __global const int *wcount, __global const int *wcand, __global int *sseg, __global int *sseg0,
    __global int *sstep0, __global GR *st0, __global GR *ste, __global GR *sxi, __global GR *sth,
    __global GR *sdm, __global GR *sdp, __global GR *simp, __global GR *sslw, __global GR *sarc,
    __global GR *stim, __global int *ev_i, __global GR *ev_r, __global uint *ev_n,
    const uint ev_cap, __global GR *wforce, __global GS *vxn, __global GS *vyn, __global GS *wn) {
  const uint g = get_global_id(0);
  struct px_gran_law LP, LW;
  GR fx = 0, fy = 0, tq = 0;
  GS xi, yi, vxi, vyi, wi;
  GR ri, imi;
  int c, nc;
  uint i;
  if (g >= n) return;
  i = own[g];
#define PX_GRAN_LOAD_LAW(L, p)                                                              \
  L.kn = p[PX_GRAN_LAW_KN], L.k2 = p[PX_GRAN_LAW_K2], L.phif = p[PX_GRAN_LAW_PHIF];         \
  L.zeta2 = p[PX_GRAN_LAW_ZETA2], L.ct_ratio = p[PX_GRAN_LAW_CT], L.kt = p[PX_GRAN_LAW_KT]; \
  L.ikt = L.kt > (GR)0 ? (GR)1 / L.kt : (GR)0, L.mu = p[PX_GRAN_LAW_MU];                    \
  L.mur = p[PX_GRAN_LAW_MUR], L.kr = p[PX_GRAN_LAW_KR], L.gt = p[PX_GRAN_LAW_GT];           \
  L.normal = (int)p[PX_GRAN_LAW_NORMAL], L.tangential = (int)p[PX_GRAN_LAW_TANGENTIAL];     \
  L.clamp = p[PX_GRAN_LAW_CLAMP], L.cells = p[PX_GRAN_LAW_CELLS], L.rolling = L.mur > (GR)0
  PX_GRAN_LOAD_LAW(LP, lawp);
  PX_GRAN_LOAD_LAW(LW, laww);
  xi = x[i], yi = y[i], vxi = vx[i], vyi = vy[i], wi = w[i];
  ri = r[i];
  imi = im[i];
  nc = ncount[i];
  for (c = 0; c < nc; ++c) {
    const int k = (int)i * PX_GRAN_NMAX + c;
    const int j = nbr[k];
    const GR dx = (GR)(xi - x[j]), dy = (GR)(yi - y[j]);
    const GR rj = r[j], rs = ri + rj;
    const GR dvx = (GR)(vxi - vx[j]), dvy = (GR)(vyi - vy[j]);
    const GR meff = (GR)1 / (imi + im[j]);
    const GR reff = ri * rj / rs;
    GR xs = hxi[k], th = hth[k], dm = hdm[k], dp = hdp[k], pfx, pfy, pti, ptj;
    px_gran_pair(&LP, dx, dy, dvx, dvy, (GR)wi, (GR)w[j], ri, rj, px_gran_damping(&LP, meff), reff,
                 dt, &xs, &th, &dm, &dp, &pfx, &pfy, &pti, &ptj);
    hxi[k] = xs, hth[k] = th, hdm[k] = dm, hdp[k] = dp;
    fx += pfx;
    fy += pfy;
    tq += pti;
  }
  if (has_walls && wcount[i] > 0) {
    struct px_gran_walls W;
    struct px_gran_wslots S;
    struct px_gran_wpart P;
    int evi[PX_GRAN_WEVENTS * PX_GRAN_EVI];
    GR evr[PX_GRAN_WEVENTS * PX_GRAN_EVR];
    int oc[PX_GRAN_WMAX];
    GR ofx[PX_GRAN_WMAX], ofy[PX_GRAN_WMAX];
    GR wfx = 0, wfy = 0, wtq = 0;
    int nev, noc = 0, e;
    W.ax = sax, W.ay = say, W.tx = stx, W.ty = sty, W.len = slen, W.tpx = stpx, W.tpy = stpy;
    W.flags = sflags, W.contour = scontour, W.cfirst = cfirst, W.ccount = ccount;
    W.frame = frames;
    S.seg = sseg, S.seg0 = sseg0, S.step0 = sstep0, S.t0 = st0, S.te = ste, S.xi = sxi;
    S.th = sth, S.dm = sdm, S.dp = sdp, S.imp = simp, S.slw = sslw, S.arc = sarc, S.tim = stim;
    P.x = xi, P.y = yi, P.vx = vxi, P.vy = vyi, P.w = wi, P.r = ri, P.m = m[i], P.id = id[i];
    nev = px_gran_wall_particle(&LW, &W, &S, (int)i, &P, wcand + i * PX_GRAN_WCMAX, wcount[i], dt,
                                step_no, 1, &wfx, &wfy, &wtq, evi, evr, oc, ofx, ofy, &noc, 0);
    fx += wfx;
    fy += wfy;
    tq += wtq;
    wforce[2 * i] = -wfx;
    wforce[2 * i + 1] = -wfy;
    for (e = 0; e < nev; ++e) {
      const uint at = atomic_inc(ev_n);
      int q;
      if (at >= ev_cap) continue; /* counted by the host as lost */
      for (q = 0; q < PX_GRAN_EVI; ++q) ev_i[at * PX_GRAN_EVI + q] = evi[e * PX_GRAN_EVI + q];
      for (q = 0; q < PX_GRAN_EVR; ++q) ev_r[at * PX_GRAN_EVR + q] = evr[e * PX_GRAN_EVR + q];
    }
  } else if (has_walls) {
    wforce[2 * i] = 0;
    wforce[2 * i + 1] = 0;
  }
  {
    const GS h = (GS)dt;
    const GS anx = (GS)fx * (GS)imi + gx, any = (GS)fy * (GS)imi + gy;
    const GS anw = (GS)tq * (GS)iI[i];
    vxn[i] = px_gran_vv_kick(vxi, ax[i], anx, h);
    vyn[i] = px_gran_vv_kick(vyi, ay[i], any, h);
    wn[i] = px_gran_vv_kick(wi, aw[i], anw, h);
    ax[i] = anx, ay[i] = any, aw[i] = anw;
  }
}

/* Neighbour list from the grid (particles of the 3x3 cells around i,
 * ascending by index), each with the history it had in the old list (same particle
 * indices: no reordering). *overflow = i + 1 for a particle with more than
 * PX_GRAN_NMAX neighbours. */
__kernel void gran_neighbours(const uint n, const GS cut_extra, __global const GS *x,
                              __global const GS *y, __global const GR *r, __global const uint *cell,
                              __global const uint *perm, __global const uint *start,
                              __global const uint *end, const int nx, const int ny,
                              __global const int *ocount, __global const int *onbr,
                              __global const GR *oxi, __global const GR *oth,
                              __global const GR *odm, __global const GR *odp, __global int *ncount,
                              __global int *nbr, __global GR *hxi, __global GR *hth,
                              __global GR *hdm, __global GR *hdp, __global uint *overflow) {
  const uint i = get_global_id(0);
  const int ci = (int)cell[i] % nx, cj = (int)cell[i] / nx;
  const GS xi = x[i], yi = y[i], ri = (GS)r[i];
  int a, b, cnt = 0;
  if (i >= n) return;
  for (b = cj - 1; b <= cj + 1; ++b) {
    if (b < 0 || b >= ny) continue;
    for (a = ci - 1; a <= ci + 1; ++a) {
      uint q, cc;
      if (a < 0 || a >= nx) continue;
      cc = (uint)(b * nx + a);
      for (q = start[cc]; q < end[cc]; ++q) {
        const uint j = perm[q];
        GS dx, dy, cut;
        int o, k;
        if (j == i) continue;
        dx = xi - x[j];
        dy = yi - y[j];
        cut = ri + (GS)r[j] + cut_extra;
        if (dx * dx + dy * dy >= cut * cut) continue;
        if (cnt == PX_GRAN_NMAX) {
          atomic_max(overflow, i + 1);
          continue;
        }
        /* the row ascending by partner index: the order of the force sum
         * is then the same whatever order the grid listed the cell's
         * particles in (its counting sort places them with atomics), so a
         * run is reproducible */
        k = (int)i * PX_GRAN_NMAX + cnt;
        while (k > (int)i * PX_GRAN_NMAX && nbr[k - 1] > (int)j) {
          nbr[k] = nbr[k - 1];
          hxi[k] = hxi[k - 1], hth[k] = hth[k - 1], hdm[k] = hdm[k - 1], hdp[k] = hdp[k - 1];
          --k;
        }
        nbr[k] = (int)j;
        hxi[k] = 0, hth[k] = 0, hdm[k] = 0, hdp[k] = 0;
        for (o = 0; o < ocount[i]; ++o)
          if (onbr[(int)i * PX_GRAN_NMAX + o] == (int)j) {
            const int ko = (int)i * PX_GRAN_NMAX + o;
            hxi[k] = oxi[ko], hth[k] = oth[ko], hdm[k] = odm[ko], hdp[k] = odp[ko];
            break;
          }
        ++cnt;
      }
    }
  }
  ncount[i] = cnt;
}

/* Wall candidates of particle i: segments within r + skin, ascending, from
 * the bins of each contour (in its body frame). Also checks that the centre
 * is not behind the wall closest to it (*escaped = i + 1 otherwise) and
 * copies the reference position for the skin test. */
__kernel void gran_wall_candidates(
    const uint n, const GS skin, __global const GS *x, __global const GS *y, __global const GR *r,
    __global GS *xr, __global GS *yr, const int ncontours, __global const GS *frames,
    __global const GS *cbox, __global const int *cbin, __global const int *bin_start,
    __global const int *bin_seg, __global const GS *sax, __global const GS *say,
    __global const GS *stx, __global const GS *sty, __global const GS *slen,
    __global const GS *stpx, __global const GS *stpy, __global const int *cfirst,
    __global const int *ccount, __global int *wcount, __global int *wcand, __global uint *overflow,
    __global uint *escaped) {
  const uint i = get_global_id(0);
  const GS range = (GS)r[i] + skin;
  int c, cnt = 0;
  GS best = (GS)1e30, side = 1;
  if (i >= n) return;
  xr[i] = x[i];
  yr[i] = y[i];
  for (c = 0; c < ncontours; ++c) {
    __global const GS *f = frames + c * PX_GRAN_CTR_COUNT;
    __global const GS *bx = cbox + c * 7; /* xmin ymin xmax ymax bx0 by0 bh */
    const GS ux = x[i] - f[PX_GRAN_CTR_PX] - f[PX_GRAN_CTR_DX];
    const GS uy = y[i] - f[PX_GRAN_CTR_PY] - f[PX_GRAN_CTR_DY];
    const GS lx = f[PX_GRAN_CTR_PX] + f[PX_GRAN_CTR_COS] * ux + f[PX_GRAN_CTR_SIN] * uy;
    const GS ly = f[PX_GRAN_CTR_PY] - f[PX_GRAN_CTR_SIN] * ux + f[PX_GRAN_CTR_COS] * uy;
    const int bnx = cbin[3 * c], bny = cbin[3 * c + 1], boff = cbin[3 * c + 2];
    int i0, i1, j0, j1, a, b;
    if (lx < bx[0] - range || lx > bx[2] + range || ly < bx[1] - range || ly > bx[3] + range)
      continue;
    i0 = (int)floor((lx - range - bx[4]) / bx[6]);
    i1 = (int)floor((lx + range - bx[4]) / bx[6]);
    j0 = (int)floor((ly - range - bx[5]) / bx[6]);
    j1 = (int)floor((ly + range - bx[5]) / bx[6]);
    i0 = max(i0, 0), j0 = max(j0, 0), i1 = min(i1, bnx - 1), j1 = min(j1, bny - 1);
    for (b = j0; b <= j1; ++b)
      for (a = i0; a <= i1; ++a) {
        const int cc = boff + b * bnx + a;
        int q;
        for (q = bin_start[cc]; q < bin_start[cc + 1]; ++q) {
          const int s = bin_seg[q];
          const GS rx = lx - sax[s], ry = ly - say[s];
          GS u = rx * stx[s] + ry * sty[s], dd, sd;
          int p, dup = 0;
          u = u < (GS)0 ? (GS)0 : (u > slen[s] ? slen[s] : u);
          dd = sqrt((rx - u * stx[s]) * (rx - u * stx[s]) + (ry - u * sty[s]) * (ry - u * sty[s]));
          if (dd >= range) continue;
          /* side of the closest feature (pseudo-normal at vertices) */
          if (u <= (GS)0)
            sd = rx * (-stpy[s] - sty[s]) + ry * (stpx[s] + stx[s]);
          else if (u >= slen[s]) {
            const int nxt = cfirst[c] + (s - cfirst[c] + 1) % ccount[c];
            const GS ex = rx - slen[s] * stx[s], ey = ry - slen[s] * sty[s];
            sd = ex * (-sty[s] - sty[nxt]) + ey * (stx[s] + stx[nxt]);
          } else {
            sd = ry * stx[s] - rx * sty[s];
          }
          if (dd < best) best = dd, side = sd;
          for (p = 0; p < cnt; ++p)
            if (wcand[(int)i * PX_GRAN_WCMAX + p] == s) dup = 1;
          if (dup) continue;
          if (cnt == PX_GRAN_WCMAX) {
            atomic_max(overflow, i + 1);
            continue;
          }
          /* insertion keeps the list ascending */
          p = cnt++;
          while (p > 0 && wcand[(int)i * PX_GRAN_WCMAX + p - 1] > s) {
            wcand[(int)i * PX_GRAN_WCMAX + p] = wcand[(int)i * PX_GRAN_WCMAX + p - 1];
            --p;
          }
          wcand[(int)i * PX_GRAN_WCMAX + p] = s;
        }
      }
  }
  wcount[i] = cnt;
  if (cnt > 0 && side < (GS)0) atomic_max(escaped, i + 1);
}

/* Over MPI ranks (granular_ranks_opencl.c): the ghost rows of a step, the
 * state (x, y, vx, vy, w) of the discs idx[k], k in [first, n) (the launch's
 * global offset), packed as rows of 5 reals at buf + 5 k to be read by the
 * host (gran_pack), or unpacked from it after the host wrote the rows the
 * owners sent (gran_unpack). Plain copies: the ghosts hold the owners' bits. */
__kernel void gran_pack(const uint n, __global const uint *idx, __global const GS *x,
                        __global const GS *y, __global const GS *vx, __global const GS *vy,
                        __global const GS *w, __global GS *buf) {
  const uint k = get_global_id(0);
  uint j;
  if (k >= n) return;
  j = idx[k];
  buf[5 * k] = x[j], buf[5 * k + 1] = y[j], buf[5 * k + 2] = vx[j];
  buf[5 * k + 3] = vy[j], buf[5 * k + 4] = w[j];
}

__kernel void gran_unpack(const uint n, __global const uint *idx, __global const GS *buf,
                          __global GS *x, __global GS *y, __global GS *vx, __global GS *vy,
                          __global GS *w) {
  const uint k = get_global_id(0);
  uint j;
  if (k >= n) return;
  j = idx[k];
  x[j] = buf[5 * k], y[j] = buf[5 * k + 1], vx[j] = buf[5 * k + 2];
  vy[j] = buf[5 * k + 3], w[j] = buf[5 * k + 4];
}
