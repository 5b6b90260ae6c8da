/* Particle–boundary contacts of the granular solver (C and OpenCL C).
 *
 * Boundaries are closed contours of straight segments, each contour moving
 * rigidly. Segment data live in the contour's own frame (its coordinates at
 * t = 0); a particle is transformed into that frame, the contact found there
 * and the normal rotated back.
 *
 * One smooth wall across joints: a contact is a local minimum, along the
 * contour, of the distance from the particle centre, closer than the radius:
 *  - an edge contact where the centre projects strictly inside a segment
 *    (0 <= s < length) on the media side;
 *  - a vertex contact at a joint that is convex seen from the media, where the
 *    centre lies in the joint's wedge (beyond the end of the previous segment
 *    and before the start of the next). Each vertex belongs to the segment
 *    that starts there, so it is counted once; the wedge boundaries coincide
 *    with the edge regions, so the normal turns continuously from one
 *    segment's normal to the next as a particle slides over the joint;
 *  - at a concave joint a centre in the overlap wedge of both segments sees two
 *    local minima: kept both at a sharp corner (a box corner pushes on two
 *    walls), merged into the deeper one at a smooth joint (turn angle below
 *    the threshold flag set by the geometry), so a particle sliding along a
 *    polygonised curve feels one wall, not two.
 * Contacts persist while a particle slides from segment to segment: a contact
 * keeps its history slot when its segment moves by at most 2 along the same
 * contour between steps. */
#ifndef PX_GRAN_WALL_KERNEL_H
#define PX_GRAN_WALL_KERNEL_H

#include "solvers/granular/contact_kernel.h"

/* Segment flags. */
#define PX_GRAN_SEG_CONVEX 1 /* the start vertex is convex seen from the media */
#define PX_GRAN_SEG_SMOOTH 2 /* the start vertex is concave with a small turn */

/* History/statistics slots per particle. */
#define PX_GRAN_WSLOTS 4
/* Contacts one particle may have with all walls at once. */
#define PX_GRAN_WMAX 8
/* Events one particle may emit in one step (flush + end per ended slot,
 * impact per new one). */
#define PX_GRAN_WEVENTS (3 * PX_GRAN_WSLOTS)

/* Contour frame record: PX_GRAN_CTR_* reals per contour. */
#define PX_GRAN_CTR_COS 0 /* cos(phi) of the rotation */
#define PX_GRAN_CTR_SIN 1
#define PX_GRAN_CTR_PX 2 /* pivot, local = world at t = 0 [m] */
#define PX_GRAN_CTR_PY 3
#define PX_GRAN_CTR_DX 4 /* displacement of the pivot [m] */
#define PX_GRAN_CTR_DY 5
#define PX_GRAN_CTR_VX 6 /* velocity of the pivot [m/s] */
#define PX_GRAN_CTR_VY 7
#define PX_GRAN_CTR_W 8 /* angular velocity [rad/s] */
#define PX_GRAN_CTR_COUNT 9

/* Event types (events are rare: contact starts and ends). */
#define PX_GRAN_EV_IMPACT                                \
  1 /* a contact starts: r0 = approach speed |vn| [m/s], \
       r1 = |vt| [m/s], r2 = particle mass [kg],         \
       r3 = start time before the step's end [s] */
#define PX_GRAN_EV_FLUSH                               \
  2 /* accumulated on one segment: r0 = normal impulse \
       [N s], r1 = sliding work [J], r2 = integral of  \
       fn |vt| dt [N m], r3 = contact time [s] */
#define PX_GRAN_EV_END                                   \
  3 /* a contact ends: r0 = duration [s] (segment of the \
       impact) */
/* Event record: PX_GRAN_EVI ints (type, segment, particle id, step) and
 * PX_GRAN_EVR reals (r0..r3). */
#define PX_GRAN_EVI 4
#define PX_GRAN_EVR 4

/* The boundary data a particle needs, borrowed. */
struct px_gran_walls {
  PX_GLOBAL const PX_GRAN_STATE *ax, *ay;   /* segment start, contour frame [m] */
  PX_GLOBAL const PX_GRAN_STATE *tx, *ty;   /* unit tangent (media on the left) */
  PX_GLOBAL const PX_GRAN_STATE *len;       /* length [m] */
  PX_GLOBAL const PX_GRAN_STATE *tpx, *tpy; /* tangent of the previous segment */
  PX_GLOBAL const int *flags;               /* PX_GRAN_SEG_* */
  PX_GLOBAL const int *contour;             /* contour of each segment */
  PX_GLOBAL const int *cfirst, *ccount;     /* segments of each contour */
  PX_GLOBAL const PX_GRAN_STATE *frame;     /* PX_GRAN_CTR_COUNT per contour */
};

/* History and statistics of a particle's wall contacts: PX_GRAN_WSLOTS
 * entries per particle at [i * PX_GRAN_WSLOTS + k], borrowed. */
struct px_gran_wslots {
  PX_GLOBAL int *seg;     /* current segment, -1 = free */
  PX_GLOBAL int *seg0;    /* segment where the contact started */
  PX_GLOBAL int *step0;   /* step in which it started */
  PX_GLOBAL PX_REAL *t0;  /* start time before the end of that step [s] */
  PX_GLOBAL PX_REAL *te;  /* estimated time to separation after the last
                             step in contact, at most dt [s] */
  PX_GLOBAL PX_REAL *xi;  /* tangential spring [m] */
  PX_GLOBAL PX_REAL *th;  /* rolling spring [rad] */
  PX_GLOBAL PX_REAL *dm;  /* largest overlap [m] */
  PX_GLOBAL PX_REAL *dp;  /* overlap at the previous evaluation [m] */
  PX_GLOBAL PX_REAL *imp; /* since the last flush: normal impulse [N s] */
  PX_GLOBAL PX_REAL *slw; /* sliding work [J] */
  PX_GLOBAL PX_REAL *arc; /* integral of fn |vt| dt [N m] */
  PX_GLOBAL PX_REAL *tim; /* contact time [s] */
};

/* A particle's state as the wall routine sees it. */
struct px_gran_wpart {
  PX_GRAN_STATE x, y, vx, vy, w; /* centre [m], velocity [m/s], spin [rad/s] */
  PX_REAL r, m;                  /* radius [m], mass [kg] */
  int id;                        /* persistent particle id */
};

/* Find whether a particle touches segment s: returns 0 (no), 1 (edge) or 2
 * (vertex at the segment's start). (px, py): centre minus segment start, in
 * the contour frame. Out: the distance d to the feature and the unit normal
 * (from the wall to the centre, contour frame). */
PX_FN int px_gran_segment_touch(PX_REAL px, PX_REAL py, PX_REAL tx, PX_REAL ty, PX_REAL len,
                                PX_REAL tpx, PX_REAL tpy, int flags, PX_REAL r, PX_REAL *d,
                                PX_REAL *nx, PX_REAL *ny) {
  const PX_REAL s = px * tx + py * ty;
  if (s >= (PX_REAL)0 && s < len) {
    const PX_REAL dn = py * tx - px * ty; /* along the left normal (-ty, tx) */
    if (dn <= (PX_REAL)0 || dn >= r) return 0;
    *d = dn;
    *nx = -ty;
    *ny = tx;
    return 1;
  }
  if (s < (PX_REAL)0 && (flags & PX_GRAN_SEG_CONVEX) && px * tpx + py * tpy >= (PX_REAL)0) {
    const PX_REAL d2 = px * px + py * py;
    PX_REAL dd;
    if (d2 >= r * r || d2 <= (PX_REAL)0) return 0;
    dd = px_gsqrt(d2);
    *d = dd;
    *nx = px / dd;
    *ny = py / dd;
    return 2;
  }
  return 0;
}

/* Distance along a closed contour of `count` segments between two segment
 * indices of it. */
PX_FN int px_gran_cyclic_gap(int a, int b, int count) {
  int g = a > b ? a - b : b - a;
  return g < count - g ? g : count - g;
}

/* The wall contacts of one particle found (the first step of
 * px_gran_wall_particle): features touched, up to PX_GRAN_WMAX. */
struct px_gran_wfeat {
  int n;
  int cs[PX_GRAN_WMAX];                         /* segment of each contact */
  int ctype[PX_GRAN_WMAX];                      /* 1 edge, 2 vertex */
  PX_REAL cd[PX_GRAN_WMAX];                     /* distance [m] */
  PX_REAL cnx[PX_GRAN_WMAX], cny[PX_GRAN_WMAX]; /* normal, contour frame */
};

/* Features of the candidate segments cand[0..nc-1] (ascending) the particle
 * touches, merging concave smooth joints (a smooth run through a contour's
 * closing joint too). */
PX_FN void px_gran_wall_features(const struct px_gran_walls *W, const struct px_gran_wpart *P,
                                 PX_GLOBAL const int *cand, int nc, struct px_gran_wfeat *F) {
  int k, q, last_c = -1, prev_seg = -1, run_best = -1;
  PX_GRAN_STATE lx = 0, ly = 0;
  F->n = 0;
  for (k = 0; k < nc; ++k) {
    const int s = cand[k];
    const int c = W->contour[s];
    PX_REAL d = 0, nx = 0, ny = 0;
    int type;
    if (c != last_c) {
      PX_GLOBAL const PX_GRAN_STATE *f = W->frame + c * PX_GRAN_CTR_COUNT;
      const PX_GRAN_STATE ux = P->x - f[PX_GRAN_CTR_PX] - f[PX_GRAN_CTR_DX];
      const PX_GRAN_STATE uy = P->y - f[PX_GRAN_CTR_PY] - f[PX_GRAN_CTR_DY];
      lx = f[PX_GRAN_CTR_PX] + f[PX_GRAN_CTR_COS] * ux + f[PX_GRAN_CTR_SIN] * uy;
      ly = f[PX_GRAN_CTR_PY] - f[PX_GRAN_CTR_SIN] * ux + f[PX_GRAN_CTR_COS] * uy;
      last_c = c;
      prev_seg = -1;
      run_best = -1;
    }
    type =
        px_gran_segment_touch((PX_REAL)(lx - W->ax[s]), (PX_REAL)(ly - W->ay[s]), (PX_REAL)W->tx[s],
                              (PX_REAL)W->ty[s], (PX_REAL)W->len[s], (PX_REAL)W->tpx[s],
                              (PX_REAL)W->tpy[s], W->flags[s], P->r, &d, &nx, &ny);
    if (!type) {
      prev_seg = -1;
      run_best = -1;
      continue;
    }
    if (type == 1 && prev_seg >= 0 && prev_seg == s - 1 && (W->flags[s] & PX_GRAN_SEG_SMOOTH) &&
        run_best >= 0) {
      /* Same smooth concave run: keep the deepest contact. */
      if (d < F->cd[run_best]) {
        F->cs[run_best] = s;
        F->ctype[run_best] = 1;
        F->cd[run_best] = d;
        F->cnx[run_best] = nx;
        F->cny[run_best] = ny;
      }
      prev_seg = s;
      continue;
    }
    if (F->n == PX_GRAN_WMAX) continue; /* cannot happen with sane geometry */
    F->cs[F->n] = s;
    F->ctype[F->n] = type;
    F->cd[F->n] = d;
    F->cnx[F->n] = nx;
    F->cny[F->n] = ny;
    run_best = type == 1 ? F->n : -1;
    prev_seg = type == 1 ? s : -1;
    ++F->n;
  }
  /* A smooth run through the contour's closing joint (last and first
   * segment): merge the two ends. */
  if (F->n >= 2) {
    int a, b;
    for (a = 0; a < F->n; ++a) {
      const int c = W->contour[F->cs[a]];
      const int first = W->cfirst[c], last = first + W->ccount[c] - 1;
      if (F->cs[a] != first || F->ctype[a] != 1 || !(W->flags[first] & PX_GRAN_SEG_SMOOTH))
        continue;
      for (b = F->n - 1; b > a; --b) {
        if (F->cs[b] == last && F->ctype[b] == 1) {
          const int drop = F->cd[a] <= F->cd[b] ? b : a;
          for (q = drop; q + 1 < F->n; ++q) {
            F->cs[q] = F->cs[q + 1];
            F->ctype[q] = F->ctype[q + 1];
            F->cd[q] = F->cd[q + 1];
            F->cnx[q] = F->cnx[q + 1];
            F->cny[q] = F->cny[q + 1];
          }
          --F->n;
          break;
        }
      }
      break;
    }
  }
}

/* Match the contacts to the particle's history slots (same contour,
 * segment within 2): slot_of[k] (-1: a new contact), used[q] the slots
 * matched. */
PX_FN void px_gran_wall_match(const struct px_gran_walls *W, const struct px_gran_wslots *S,
                              int base, const struct px_gran_wfeat *F, int *slot_of, int *used) {
  int k, q;
  for (q = 0; q < PX_GRAN_WSLOTS; ++q) used[q] = 0;
  for (k = 0; k < F->n; ++k) {
    const int c = W->contour[F->cs[k]];
    int best = -1, bestgap = 3;
    for (q = 0; q < PX_GRAN_WSLOTS; ++q) {
      const int sq = S->seg[base + q];
      int gap;
      if (sq < 0 || used[q] || W->contour[sq] != c) continue;
      gap = px_gran_cyclic_gap(sq, F->cs[k], W->ccount[c]);
      if (gap < bestgap) {
        bestgap = gap;
        best = q;
      }
    }
    slot_of[k] = best;
    if (best >= 0) used[best] = 1;
  }
}

/* Contacts that ended within this step (slots not matched): the dashpot
 * remainder of px_gran_contact (velocity Verlet cells) from the gap to the
 * slot's segment, added to *fx, *fy (and to oc/ofx/ofy as in
 * px_gran_wall_particle). */
PX_FN void px_gran_wall_ended(const struct px_gran_law *L, const struct px_gran_walls *W,
                              const struct px_gran_wslots *S, int base,
                              const struct px_gran_wpart *P, const int *used, PX_REAL dt,
                              PX_REAL *fx, PX_REAL *fy, int *oc, PX_REAL *ofx, PX_REAL *ofy,
                              int *noc) {
  int q;
  for (q = 0; q < PX_GRAN_WSLOTS; ++q) {
    const int sq = S->seg[base + q];
    if (sq < 0 || used[q]) continue;
    {
      const int c = W->contour[sq];
      PX_GLOBAL const PX_GRAN_STATE *f = W->frame + c * PX_GRAN_CTR_COUNT;
      const PX_GRAN_STATE ux = P->x - f[PX_GRAN_CTR_PX] - f[PX_GRAN_CTR_DX];
      const PX_GRAN_STATE uy = P->y - f[PX_GRAN_CTR_PY] - f[PX_GRAN_CTR_DY];
      const PX_REAL co = (PX_REAL)f[PX_GRAN_CTR_COS], si = (PX_REAL)f[PX_GRAN_CTR_SIN];
      const PX_REAL px = (PX_REAL)(f[PX_GRAN_CTR_PX] + f[PX_GRAN_CTR_COS] * ux +
                                   f[PX_GRAN_CTR_SIN] * uy - W->ax[sq]);
      const PX_REAL py = (PX_REAL)(f[PX_GRAN_CTR_PY] - f[PX_GRAN_CTR_SIN] * ux +
                                   f[PX_GRAN_CTR_COS] * uy - W->ay[sq]);
      const PX_REAL stx = (PX_REAL)W->tx[sq], sty = (PX_REAL)W->ty[sq];
      PX_REAL u = px * stx + py * sty, gx, gy, gd, lnx, lny, nx, ny, ww, rx, ry, vn, dvx, dvy;
      PX_REAL xi = 0, th = 0, dm = 0, dpv = S->dp[base + q], fn, ft, mr;
      u = u < (PX_REAL)0 ? (PX_REAL)0 : (u > (PX_REAL)W->len[sq] ? (PX_REAL)W->len[sq] : u);
      gx = px - u * stx;
      gy = py - u * sty;
      gd = px_gsqrt(gx * gx + gy * gy);
      if (gd <= (PX_REAL)0) continue;
      lnx = gx / gd;
      lny = gy / gd;
      nx = co * lnx - si * lny;
      ny = si * lnx + co * lny;
      ww = (PX_REAL)f[PX_GRAN_CTR_W];
      rx = (PX_REAL)ux - gd * nx;
      ry = (PX_REAL)uy - gd * ny;
      dvx = (PX_REAL)P->vx - ((PX_REAL)f[PX_GRAN_CTR_VX] - ww * ry);
      dvy = (PX_REAL)P->vy - ((PX_REAL)f[PX_GRAN_CTR_VY] + ww * rx);
      vn = dvx * nx + dvy * ny;
      px_gran_contact(L, P->r - gd, vn, (PX_REAL)0, (PX_REAL)0, px_gran_damping(L, P->m), P->r, dt,
                      &xi, &th, &dm, &dpv, &fn, &ft, &mr);
      *fx += fn * nx;
      *fy += fn * ny;
      if (oc) {
        oc[*noc] = c;
        ofx[*noc] = fn * nx;
        ofy[*noc] = fn * ny;
        ++*noc;
      }
    }
  }
}

/* Contacts that ended (slots not matched): their statistics flushed as
 * events after the nev already in ev_i/ev_r, and the slots freed. Returns
 * the number of events. */
PX_FN int px_gran_wall_flush_ended(const struct px_gran_wslots *S, int base, const int *used,
                                   int id, int step, PX_REAL dt, int *ev_i, PX_REAL *ev_r,
                                   int nev) {
  int q;
  for (q = 0; q < PX_GRAN_WSLOTS; ++q) {
    const int sq = S->seg[base + q];
    if (sq < 0 || used[q]) continue;
    if (nev + 2 <= PX_GRAN_WEVENTS) {
      ev_i[nev * PX_GRAN_EVI + 0] = PX_GRAN_EV_FLUSH;
      ev_i[nev * PX_GRAN_EVI + 1] = sq;
      ev_i[nev * PX_GRAN_EVI + 2] = id;
      ev_i[nev * PX_GRAN_EVI + 3] = step;
      ev_r[nev * PX_GRAN_EVR + 0] = S->imp[base + q];
      ev_r[nev * PX_GRAN_EVR + 1] = S->slw[base + q];
      ev_r[nev * PX_GRAN_EVR + 2] = S->arc[base + q];
      ev_r[nev * PX_GRAN_EVR + 3] = S->tim[base + q];
      ++nev;
      ev_i[nev * PX_GRAN_EVI + 0] = PX_GRAN_EV_END;
      ev_i[nev * PX_GRAN_EVI + 1] = S->seg0[base + q];
      ev_i[nev * PX_GRAN_EVI + 2] = id;
      ev_i[nev * PX_GRAN_EVI + 3] = step;
      /* duration: from the estimated start to the estimated separation
       * after the end of the previous step */
      ev_r[nev * PX_GRAN_EVR + 0] =
          (PX_REAL)(step - S->step0[base + q] - 1) * dt + S->t0[base + q] + S->te[base + q];
      ev_r[nev * PX_GRAN_EVR + 1] = 0;
      ev_r[nev * PX_GRAN_EVR + 2] = 0;
      ev_r[nev * PX_GRAN_EVR + 3] = 0;
      ++nev;
    }
    S->seg[base + q] = -1;
  }
  return nev;
}

/* The history and statistics of contact k of the particle on segment s
 * (slot sl, -1: new) kept in the slots after its force: a new contact
 * takes a free slot and is an IMPACT event, one that slid onto another
 * segment flushes what the old segment received. Returns nev, the events
 * in ev_i/ev_r. */
PX_FN int px_gran_wall_commit(const struct px_gran_law *L, const struct px_gran_wslots *S, int base,
                              const struct px_gran_wpart *P, int s, int sl, int *used, int step,
                              PX_REAL dt, PX_REAL delta, PX_REAL vn, PX_REAL vt, PX_REAL fn,
                              PX_REAL ft, PX_REAL xi, PX_REAL th, PX_REAL dm, PX_REAL dpv,
                              int *ev_i, PX_REAL *ev_r, int nev) {
  int q;
  int slot = sl;
  if (slot < 0) {
    for (q = 0; q < PX_GRAN_WSLOTS; ++q)
      if (S->seg[base + q] < 0 && !used[q]) break;
    if (q == PX_GRAN_WSLOTS) return nev; /* all slots busy: no history, no statistics */
    slot = q;
    used[q] = 1;
    S->seg[base + slot] = s;
    S->seg0[base + slot] = s;
    S->step0[base + slot] = step;
    /* the overlap grew from 0 at about -vn: start = end - delta/|vn| */
    S->t0[base + slot] = vn < (PX_REAL)0 ? px_gmin(delta / -vn, dt) : dt;
    S->imp[base + slot] = 0;
    S->slw[base + slot] = 0;
    S->arc[base + slot] = 0;
    S->tim[base + slot] = 0;
    if (nev < PX_GRAN_WEVENTS) {
      ev_i[nev * PX_GRAN_EVI + 0] = PX_GRAN_EV_IMPACT;
      ev_i[nev * PX_GRAN_EVI + 1] = s;
      ev_i[nev * PX_GRAN_EVI + 2] = P->id;
      ev_i[nev * PX_GRAN_EVI + 3] = step;
      ev_r[nev * PX_GRAN_EVR + 0] = vn < (PX_REAL)0 ? -vn : (PX_REAL)0;
      ev_r[nev * PX_GRAN_EVR + 1] = px_gabs(vt);
      ev_r[nev * PX_GRAN_EVR + 2] = P->m;
      ev_r[nev * PX_GRAN_EVR + 3] = S->t0[base + slot];
      ++nev;
    }
  } else if (S->seg[base + slot] != s) {
    /* slid onto another segment: flush what the old one received */
    if (nev < PX_GRAN_WEVENTS) {
      ev_i[nev * PX_GRAN_EVI + 0] = PX_GRAN_EV_FLUSH;
      ev_i[nev * PX_GRAN_EVI + 1] = S->seg[base + slot];
      ev_i[nev * PX_GRAN_EVI + 2] = P->id;
      ev_i[nev * PX_GRAN_EVI + 3] = step;
      ev_r[nev * PX_GRAN_EVR + 0] = S->imp[base + slot];
      ev_r[nev * PX_GRAN_EVR + 1] = S->slw[base + slot];
      ev_r[nev * PX_GRAN_EVR + 2] = S->arc[base + slot];
      ev_r[nev * PX_GRAN_EVR + 3] = S->tim[base + slot];
      ++nev;
    }
    S->seg[base + slot] = s;
    S->imp[base + slot] = 0;
    S->slw[base + slot] = 0;
    S->arc[base + slot] = 0;
    S->tim[base + slot] = 0;
  }
  S->xi[base + slot] = xi;
  S->dp[base + slot] = dpv;
  S->te[base + slot] = vn > (PX_REAL)0 ? px_gmin(delta / vn, dt) : dt;
  S->th[base + slot] = th;
  S->dm[base + slot] = dm;
  {
    const PX_REAL avt = px_gabs(vt);
    const PX_REAL sliding =
        px_gabs(ft) >= L->mu * px_gmax(fn, (PX_REAL)0) && L->tangential != PX_GRAN_TANGENTIAL_NONE
            ? (PX_REAL)1
            : (PX_REAL)0;
    S->imp[base + slot] += fn * dt;
    S->slw[base + slot] += sliding * px_gabs(ft) * avt * dt;
    S->arc[base + slot] += px_gmax(fn, (PX_REAL)0) * avt * dt;
    S->tim[base + slot] += dt;
  }
  return nev;
}

/* All wall contacts of one particle over its candidate segments cand[0..nc-1]
 * (ascending). Adds the force and torque on the particle to *fx, *fy, *tq.
 * commit = 1: update the slots (history, statistics) and emit events into
 * ev_i/ev_r (capacity PX_GRAN_WEVENTS), returning their number;
 * commit = 0 (predictor evaluation): read the slots only, return 0.
 * `step` is the index of the step being taken; dt its size [s].
 * If oc is not NULL, the contour of each contact and the force on the
 * particle from it go to oc/ofx/ofy (capacity PX_GRAN_WMAX), *noc their
 * number (the reactions on the contours are their negatives). If eel is not
 * NULL, the elastic energy kn delta^2 / 2 of the contacts is added to it. */
PX_FN int px_gran_wall_particle(const struct px_gran_law *L, const struct px_gran_walls *W,
                                const struct px_gran_wslots *S, int i,
                                const struct px_gran_wpart *P, PX_GLOBAL const int *cand, int nc,
                                PX_REAL dt, int step, int commit, PX_REAL *fx, PX_REAL *fy,
                                PX_REAL *tq, int *ev_i, PX_REAL *ev_r, int *oc, PX_REAL *ofx,
                                PX_REAL *ofy, int *noc, PX_REAL *eel) {
  struct px_gran_wfeat F;
  int slot_of[PX_GRAN_WMAX];
  int used[PX_GRAN_WSLOTS];
  int k, nev = 0;
  const int base = i * PX_GRAN_WSLOTS;
  px_gran_wall_features(W, P, cand, nc, &F);
  px_gran_wall_match(W, S, base, &F, slot_of, used);
  if (L->cells > (PX_REAL)0)
    px_gran_wall_ended(L, W, S, base, P, used, dt, fx, fy, oc, ofx, ofy, noc);
  if (commit) nev = px_gran_wall_flush_ended(S, base, used, P->id, step, dt, ev_i, ev_r, nev);
  /* the forces, and (commit) the slots and events of each contact */
  for (k = 0; k < F.n; ++k) {
    const int s = F.cs[k];
    const int c = W->contour[s];
    PX_GLOBAL const PX_GRAN_STATE *f = W->frame + c * PX_GRAN_CTR_COUNT;
    const PX_REAL co = (PX_REAL)f[PX_GRAN_CTR_COS], si = (PX_REAL)f[PX_GRAN_CTR_SIN];
    const PX_REAL nx = co * F.cnx[k] - si * F.cny[k];
    const PX_REAL ny = si * F.cnx[k] + co * F.cny[k];
    const PX_REAL tx = -ny, ty = nx;
    const PX_REAL delta = P->r - F.cd[k];
    const PX_REAL a = P->r - (PX_REAL)0.5 * delta;
    /* wall point and its rigid velocity */
    const PX_REAL rx = (PX_REAL)(P->x - f[PX_GRAN_CTR_PX] - f[PX_GRAN_CTR_DX]) - F.cd[k] * nx;
    const PX_REAL ry = (PX_REAL)(P->y - f[PX_GRAN_CTR_PY] - f[PX_GRAN_CTR_DY]) - F.cd[k] * ny;
    const PX_REAL ww = (PX_REAL)f[PX_GRAN_CTR_W];
    const PX_REAL wvx = (PX_REAL)f[PX_GRAN_CTR_VX] - ww * ry;
    const PX_REAL wvy = (PX_REAL)f[PX_GRAN_CTR_VY] + ww * rx;
    const PX_REAL dvx = (PX_REAL)P->vx - wvx, dvy = (PX_REAL)P->vy - wvy;
    const PX_REAL vn = dvx * nx + dvy * ny;
    const PX_REAL vt = dvx * tx + dvy * ty - a * (PX_REAL)P->w;
    const int sl = slot_of[k];
    PX_REAL xi = 0, th = 0, dm = 0, dpv = 0, fn, ft, mr;
    if (sl >= 0) {
      xi = S->xi[base + sl];
      th = S->th[base + sl];
      dm = S->dm[base + sl];
      dpv = S->dp[base + sl];
    }
    px_gran_contact(L, delta, vn, vt, (PX_REAL)P->w - ww, px_gran_damping(L, P->m), P->r, dt, &xi,
                    &th, &dm, &dpv, &fn, &ft, &mr);
    *fx += fn * nx + ft * tx;
    *fy += fn * ny + ft * ty;
    *tq += -a * ft + mr;
    if (eel) *eel += (PX_REAL)0.5 * L->kn * delta * delta;
    if (oc) {
      oc[*noc] = c;
      ofx[*noc] = fn * nx + ft * tx;
      ofy[*noc] = fn * ny + ft * ty;
      ++*noc;
    }
    if (commit)
      nev = px_gran_wall_commit(L, S, base, P, s, sl, used, step, dt, delta, vn, vt, fn, ft, xi, th,
                                dm, dpv, ev_i, ev_r, nev);
  }
  return nev;
}

/* Emit FLUSH events for every busy slot of particle i and zero its
 * accumulators (before statistics are written, so that contacts in progress
 * count). Returns the number of events. */
PX_FN int px_gran_wall_flush(const struct px_gran_wslots *S, int i, int id, int step, int *ev_i,
                             PX_REAL *ev_r) {
  int q, nev = 0;
  const int base = i * PX_GRAN_WSLOTS;
  for (q = 0; q < PX_GRAN_WSLOTS; ++q) {
    if (S->seg[base + q] < 0) continue;
    ev_i[nev * PX_GRAN_EVI + 0] = PX_GRAN_EV_FLUSH;
    ev_i[nev * PX_GRAN_EVI + 1] = S->seg[base + q];
    ev_i[nev * PX_GRAN_EVI + 2] = id;
    ev_i[nev * PX_GRAN_EVI + 3] = step;
    ev_r[nev * PX_GRAN_EVR + 0] = S->imp[base + q];
    ev_r[nev * PX_GRAN_EVR + 1] = S->slw[base + q];
    ev_r[nev * PX_GRAN_EVR + 2] = S->arc[base + q];
    ev_r[nev * PX_GRAN_EVR + 3] = S->tim[base + q];
    S->imp[base + q] = 0;
    S->slw[base + q] = 0;
    S->arc[base + q] = 0;
    S->tim[base + q] = 0;
    ++nev;
  }
  return nev;
}

#endif
