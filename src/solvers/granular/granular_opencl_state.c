/* The opencl engine of the granular solver, its state side: the device
 * buffers, the transfers between them and the host mirror (upload,
 * download, wall events), checkpoint sections and the contacts of the
 * device's lists. Only the backend's buffer API (partix/backend.h) is used
 * here, so this file builds with or without OpenCL; the kernels are in
 * granular_opencl.c. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "partix/checkpoint.h"
#include "partix/memory.h"
#include "partix/neighbors.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/granular_opencl_impl.h"
#include "solvers/granular/wall_kernel.h"

static enum px_status px_gran_cl_alloc(struct px_gran_cl *e, int k, const char *label,
                                       size_t bytes) {
  return px_buffer_create(e->be, label, bytes ? bytes : 4, &e->b[k]);
}

/* A host array of doubles into a device buffer of reals of `es` bytes. */
static enum px_status px_gran_cl_put(struct px_gran_cl *e, int k, const double *v, size_t n,
                                     size_t es) {
  void *tmp = px_mem_alloc(e->ctx, "granular opencl staging", (n ? n : 1) * es);
  size_t i;
  enum px_status st;
  if (!tmp) return PX_STATUS_NOMEM;
  for (i = 0; i < n; ++i) {
    if (es == sizeof(double))
      ((double *)tmp)[i] = v[i];
    else
      ((float *)tmp)[i] = (float)v[i];
  }
  st = px_buffer_write(e->b[k], 0, n * es, tmp);
  px_mem_free(e->ctx, tmp);
  return st;
}

void px_gran_cl_free(struct px_gran_cl *e) {
  int k;
  if (!e) return;
  for (k = 0; k < B_COUNT; ++k) px_buffer_free(e->b[k]);
  px_grid_free(e->grid);
  px_mem_free(e->ctx, e->kern);
  px_mem_free(e->ctx, e->ev_i);
  px_mem_free(e->ctx, e->ev_r);
  px_mem_free(e->ctx, e);
}

/* Upload the mirror's particles in id order (device index = id). */
enum px_status px_gran_cl_upload_state(struct px_gran_cl *e) {
  struct px_gran_sys *h = e->h;
  const size_t n = e->n;
  double *v = px_mem_alloc(e->ctx, "granular opencl staging", 14 * (n ? n : 1) * sizeof *v);
  int *ids = px_mem_alloc(e->ctx, "granular opencl staging", (n ? n : 1) * sizeof *ids);
  size_t i, q;
  enum px_status st = PX_STATUS_OK;
  const int ks[14] = {B_X,  B_Y,  B_VX, B_VY, B_W, B_AX, B_AY,
                      B_AW, B_XR, B_YR, B_R,  B_M, B_IM, B_II};
  if (!v || !ids) {
    px_mem_free(e->ctx, v);
    px_mem_free(e->ctx, ids);
    return PX_STATUS_NOMEM;
  }
  for (i = 0; i < n; ++i) {
    double rec[8];
    const size_t hi = (size_t)h->where[i];
    h->ops->get(h, hi, rec);
    v[0 * n + i] = rec[PX_GRAN_P_X], v[1 * n + i] = rec[PX_GRAN_P_Y];
    v[2 * n + i] = rec[PX_GRAN_P_VX], v[3 * n + i] = rec[PX_GRAN_P_VY];
    v[4 * n + i] = rec[PX_GRAN_P_W];
    v[5 * n + i] = px_gran_reals_get(h->fx, hi, h->ssize);
    v[6 * n + i] = px_gran_reals_get(h->fy, hi, h->ssize);
    v[7 * n + i] = px_gran_reals_get(h->tq, hi, h->ssize);
    v[8 * n + i] = rec[PX_GRAN_P_X], v[9 * n + i] = rec[PX_GRAN_P_Y];
    v[10 * n + i] = rec[PX_GRAN_P_R], v[11 * n + i] = rec[PX_GRAN_P_M];
    /* 1/m and 1/I as the system has them (from the case's double values) */
    v[12 * n + i] = px_gran_reals_get(h->im, hi, h->csize);
    v[13 * n + i] = px_gran_reals_get(h->iI, hi, h->csize);
    ids[i] = (int)i;
  }
  for (q = 0; q < 14 && st == PX_STATUS_OK; ++q)
    st = px_gran_cl_put(e, ks[q], v + q * n, n, q < 10 ? e->ss : e->cs);
  if (st == PX_STATUS_OK) st = px_buffer_write(e->b[B_ID], 0, n * sizeof(int), ids);
  /* wall slots, per id */
  if (st == PX_STATUS_OK && h->geom) {
    const size_t W = PX_GRAN_WSLOTS;
    int *iv = px_mem_alloc(e->ctx, "granular opencl staging", 3 * n * W * sizeof *iv);
    double *rv = px_mem_alloc(e->ctx, "granular opencl staging", 11 * n * W * sizeof *rv);
    const union px_gran_reals rs[10] = {h->slots.t0,  h->slots.te, h->slots.xi,  h->slots.th,
                                        h->slots.dm,  h->slots.dp, h->slots.imp, h->slots.slw,
                                        h->slots.arc, h->slots.tim};
    const int rk[10] = {B_ST0, B_STE, B_SXI, B_STH, B_SDM, B_SDP, B_SIMP, B_SSLW, B_SARC, B_STIM};
    if (!iv || !rv) st = PX_STATUS_NOMEM;
    for (i = 0; i < n && st == PX_STATUS_OK; ++i) {
      const size_t hi = (size_t)h->where[i];
      size_t k2;
      for (k2 = 0; k2 < W; ++k2) {
        const size_t a = i * W + k2, b = hi * W + k2;
        iv[a] = h->slots.seg[b];
        iv[n * W + a] = h->slots.seg0[b];
        iv[2 * n * W + a] = h->slots.step0[b];
        for (q = 0; q < 10; ++q) rv[q * n * W + a] = px_gran_reals_get(rs[q], b, h->csize);
      }
    }
    if (st == PX_STATUS_OK) st = px_buffer_write(e->b[B_SSEG], 0, n * W * sizeof(int), iv);
    if (st == PX_STATUS_OK) st = px_buffer_write(e->b[B_SSEG0], 0, n * W * sizeof(int), iv + n * W);
    if (st == PX_STATUS_OK)
      st = px_buffer_write(e->b[B_SSTEP0], 0, n * W * sizeof(int), iv + 2 * n * W);
    for (q = 0; q < 10 && st == PX_STATUS_OK; ++q)
      st = px_gran_cl_put(e, rk[q], rv + q * n * W, n * W, e->cs);
    px_mem_free(e->ctx, iv);
    px_mem_free(e->ctx, rv);
  }
  px_mem_free(e->ctx, v);
  px_mem_free(e->ctx, ids);
  return st;
}

enum px_status px_gran_cl_write_frames(struct px_gran_cl *e) {
  if (!e->ncontours) return PX_STATUS_OK;
  return px_gran_cl_put(e, B_FRAMES, e->h->frames, e->ncontours * PX_GRAN_CTR_COUNT, e->ss);
}

/* The device buffers of the particles, lists, wall slots and events
 * (lists, counts and reactions zeroed), and the two contact laws. */
enum px_status px_gran_cl_buffers(struct px_gran_cl *e) {
  struct px_gran_sys *h = e->h;
  const size_t n = e->n, W = PX_GRAN_WSLOTS;
  enum px_status st = PX_STATUS_OK;
  {
    const struct {
      int k;
      size_t bytes;
    } sz[] = {{B_X, n * e->ss},
              {B_Y, n * e->ss},
              {B_VX, n * e->ss},
              {B_VY, n * e->ss},
              {B_W, n * e->ss},
              {B_VXN, n * e->ss},
              {B_VYN, n * e->ss},
              {B_WN, n * e->ss},
              {B_AX, n * e->ss},
              {B_AY, n * e->ss},
              {B_AW, n * e->ss},
              {B_XR, n * e->ss},
              {B_YR, n * e->ss},
              {B_R, n * e->cs},
              {B_M, n * e->cs},
              {B_IM, n * e->cs},
              {B_II, n * e->cs},
              {B_ID, n * 4},
              {B_NCOUNT, n * 4},
              {B_NBR, n * PX_GRAN_CL_NMAX * 4},
              {B_HXI, n * PX_GRAN_CL_NMAX * e->cs},
              {B_HTH, n * PX_GRAN_CL_NMAX * e->cs},
              {B_HDM, n * PX_GRAN_CL_NMAX * e->cs},
              {B_HDP, n * PX_GRAN_CL_NMAX * e->cs},
              {B_ONCOUNT, n * 4},
              {B_ONBR, n * PX_GRAN_CL_NMAX * 4},
              {B_OXI, n * PX_GRAN_CL_NMAX * e->cs},
              {B_OTH, n * PX_GRAN_CL_NMAX * e->cs},
              {B_ODM, n * PX_GRAN_CL_NMAX * e->cs},
              {B_ODP, n * PX_GRAN_CL_NMAX * e->cs},
              {B_WCOUNT, n * 4},
              {B_WCAND, n * PX_GRAN_CL_WCMAX * 4},
              {B_SSEG, n * W * 4},
              {B_SSEG0, n * W * 4},
              {B_SSTEP0, n * W * 4},
              {B_ST0, n * W * e->cs},
              {B_STE, n * W * e->cs},
              {B_SXI, n * W * e->cs},
              {B_STH, n * W * e->cs},
              {B_SDM, n * W * e->cs},
              {B_SDP, n * W * e->cs},
              {B_SIMP, n * W * e->cs},
              {B_SSLW, n * W * e->cs},
              {B_SARC, n * W * e->cs},
              {B_STIM, n * W * e->cs},
              {B_EVI, e->ev_cap * PX_GRAN_EVI * 4},
              {B_EVR, e->ev_cap * PX_GRAN_EVR * e->cs},
              {B_EVN, 4},
              {B_WFORCE, 2 * n * e->cs},
              {B_LAWP, PX_GRAN_LAW_COUNT * e->cs},
              {B_LAWW, PX_GRAN_LAW_COUNT * e->cs},
              {B_MAXD, 4},
              {B_OVF, 4},
              {B_ESC, 4},
              {B_OWN, n * 4}};
    size_t k;
    for (k = 0; k < sizeof sz / sizeof sz[0] && st == PX_STATUS_OK; ++k)
      st = px_gran_cl_alloc(e, sz[k].k, "granular opencl", sz[k].bytes);
  }
  if (st == PX_STATUS_OK) st = px_buffer_zero(e->b[B_NCOUNT]);
  if (st == PX_STATUS_OK) st = px_buffer_zero(e->b[B_ONCOUNT]);
  if (st == PX_STATUS_OK) st = px_buffer_zero(e->b[B_WCOUNT]);
  if (st == PX_STATUS_OK) st = px_buffer_zero(e->b[B_EVN]);
  if (st == PX_STATUS_OK) st = px_buffer_zero(e->b[B_WFORCE]);
  if (st == PX_STATUS_OK) {
    /* one rank steps every disc (over ranks the plan writes its own) */
    uint32_t *ids = px_mem_alloc(e->ctx, "granular opencl staging", (n ? n : 1) * sizeof *ids);
    size_t i;
    if (!ids) return PX_STATUS_NOMEM;
    for (i = 0; i < n; ++i) ids[i] = (uint32_t)i;
    st = px_buffer_write(e->b[B_OWN], 0, n * sizeof *ids, ids);
    px_mem_free(e->ctx, ids);
    e->nown = n;
  }
  /* laws */
  if (st == PX_STATUS_OK) {
    double p[PX_GRAN_LAW_COUNT];
    px_gran_law_params(&h->pp, 1, p);
    st = px_gran_cl_put(e, B_LAWP, p, PX_GRAN_LAW_COUNT, e->cs);
    px_gran_law_params(&h->pw, 1, p);
    if (st == PX_STATUS_OK) st = px_gran_cl_put(e, B_LAWW, p, PX_GRAN_LAW_COUNT, e->cs);
  }
  return st;
}

/* The walls on the device: segments, bins and contour boxes, all fixed in
 * the body frames. */
enum px_status px_gran_cl_walls(struct px_gran_cl *e) {
  struct px_context *ctx = e->ctx;
  struct px_gran_sys *h = e->h;
  const struct px_gran_geom *g = h->geom;
  enum px_status st = PX_STATUS_OK;
  {
    const size_t ns = e->nseg ? e->nseg : 1, nc = e->ncontours ? e->ncontours : 1;
    size_t c, tot = 0, totseg = 0;
    const int segk[7] = {B_SAX, B_SAY, B_STX, B_STY, B_SLEN, B_STPX, B_STPY};
    int q;
    for (q = 0; q < 7 && st == PX_STATUS_OK; ++q)
      st = px_gran_cl_alloc(e, segk[q], "granular opencl", ns * e->ss);
    if (st == PX_STATUS_OK) st = px_gran_cl_alloc(e, B_SFLAGS, "granular opencl", ns * 4);
    if (st == PX_STATUS_OK) st = px_gran_cl_alloc(e, B_SCONTOUR, "granular opencl", ns * 4);
    if (st == PX_STATUS_OK) st = px_gran_cl_alloc(e, B_CFIRST, "granular opencl", nc * 4);
    if (st == PX_STATUS_OK) st = px_gran_cl_alloc(e, B_CCOUNT, "granular opencl", nc * 4);
    if (st == PX_STATUS_OK)
      st = px_gran_cl_alloc(e, B_FRAMES, "granular opencl", nc * PX_GRAN_CTR_COUNT * e->ss);
    if (st == PX_STATUS_OK) st = px_gran_cl_alloc(e, B_CBOX, "granular opencl", nc * 7 * e->ss);
    if (st == PX_STATUS_OK) st = px_gran_cl_alloc(e, B_CBIN, "granular opencl", nc * 3 * 4);
    for (c = 0; c < e->ncontours; ++c) {
      tot += (size_t)g->contours[c].bnx * (size_t)g->contours[c].bny + 1;
      totseg +=
          (size_t)g->contours[c].bin_start[(size_t)g->contours[c].bnx * (size_t)g->contours[c].bny];
    }
    if (st == PX_STATUS_OK) st = px_gran_cl_alloc(e, B_BINSTART, "granular opencl", (tot + 1) * 4);
    if (st == PX_STATUS_OK) st = px_gran_cl_alloc(e, B_BINSEG, "granular opencl", (totseg + 1) * 4);
    if (st == PX_STATUS_OK && g) {
      const double *src[7] = {g->ax, g->ay, g->tx, g->ty, g->len, g->tpx, g->tpy};
      double *box = px_mem_alloc(ctx, "granular opencl staging", nc * 7 * sizeof *box);
      int *bin = px_mem_alloc(ctx, "granular opencl staging", nc * 3 * sizeof *bin);
      int *bs = px_mem_alloc(ctx, "granular opencl staging", (tot + 1) * sizeof *bs);
      int *bg = px_mem_alloc(ctx, "granular opencl staging", (totseg + 1) * sizeof *bg);
      size_t off = 0, soff = 0;
      if (!box || !bin || !bs || !bg) st = PX_STATUS_NOMEM;
      for (q = 0; q < 7 && st == PX_STATUS_OK; ++q)
        st = px_gran_cl_put(e, segk[q], src[q], e->nseg, e->ss);
      if (st == PX_STATUS_OK) st = px_buffer_write(e->b[B_SFLAGS], 0, e->nseg * 4, g->flags);
      if (st == PX_STATUS_OK) st = px_buffer_write(e->b[B_SCONTOUR], 0, e->nseg * 4, g->contour);
      if (st == PX_STATUS_OK)
        st = px_buffer_write(e->b[B_CFIRST], 0, e->ncontours * 4, h->seg_cfirst);
      if (st == PX_STATUS_OK)
        st = px_buffer_write(e->b[B_CCOUNT], 0, e->ncontours * 4, h->seg_ccount);
      for (c = 0; c < e->ncontours && st == PX_STATUS_OK; ++c) {
        const struct px_gran_contour *C = &g->contours[c];
        const size_t cells = (size_t)C->bnx * (size_t)C->bny;
        size_t k;
        box[7 * c + 0] = C->xmin, box[7 * c + 1] = C->ymin, box[7 * c + 2] = C->xmax;
        box[7 * c + 3] = C->ymax, box[7 * c + 4] = C->bx0, box[7 * c + 5] = C->by0;
        box[7 * c + 6] = C->bh;
        bin[3 * c] = C->bnx, bin[3 * c + 1] = C->bny, bin[3 * c + 2] = (int)off;
        for (k = 0; k <= cells; ++k) bs[off + k] = C->bin_start[k] + (int)soff;
        for (k = 0; k < (size_t)C->bin_start[cells]; ++k) bg[soff + k] = C->bin_seg[k];
        off += cells + 1;
        soff += (size_t)C->bin_start[cells];
      }
      if (st == PX_STATUS_OK) st = px_gran_cl_put(e, B_CBOX, box, e->ncontours * 7, e->ss);
      if (st == PX_STATUS_OK) st = px_buffer_write(e->b[B_CBIN], 0, e->ncontours * 3 * 4, bin);
      if (st == PX_STATUS_OK) st = px_buffer_write(e->b[B_BINSTART], 0, (tot + 1) * 4, bs);
      if (st == PX_STATUS_OK) st = px_buffer_write(e->b[B_BINSEG], 0, (totseg + 1) * 4, bg);
      px_mem_free(ctx, box);
      px_mem_free(ctx, bin);
      px_mem_free(ctx, bs);
      px_mem_free(ctx, bg);
    }
  }
  return st;
}

/* The neighbour grid over where particles can be: the contours' reach
 * (plus their motion) or, without contours, the particles' box, widened. */
enum px_status px_gran_cl_grid(struct px_gran_cl *e) {
  struct px_gran_sys *h = e->h;
  const struct px_gran_geom *g = h->geom;
  const size_t n = e->n;
  enum px_status st = PX_STATUS_OK;
  if (st == PX_STATUS_OK) {
    double xmin = 1e300, ymin = 1e300, xmax = -1e300, ymax = -1e300, origin[2], hcell;
    size_t cells[2], i;
    for (i = 0; i < n; ++i) {
      double rec[8];
      h->ops->get(h, i, rec);
      xmin = fmin(xmin, rec[0]), xmax = fmax(xmax, rec[0]);
      ymin = fmin(ymin, rec[1]), ymax = fmax(ymax, rec[1]);
    }
    if (g) {
      size_t c;
      for (c = 0; c < g->ncontours; ++c) {
        const struct px_gran_contour *C = &g->contours[c];
        const double reach = h->c_radius[c] * 0.2 + 0.05 * (C->xmax - C->xmin + C->ymax - C->ymin);
        xmin = fmin(xmin, C->xmin - reach), xmax = fmax(xmax, C->xmax + reach);
        ymin = fmin(ymin, C->ymin - reach), ymax = fmax(ymax, C->ymax + reach);
      }
    } else {
      const double wx = xmax - xmin, wy = ymax - ymin;
      xmin -= wx, xmax += wx, ymin -= wy, ymax += wy;
    }
    hcell = (2 * h->rmax + h->skin) * (1 + 1e-5);
    while (((xmax - xmin) / hcell + 2) * ((ymax - ymin) / hcell + 2) > 4.0 * (double)n + 1e6)
      hcell *= 2;
    origin[0] = xmin - hcell, origin[1] = ymin - hcell;
    cells[0] = (size_t)((xmax - origin[0]) / hcell) + 2;
    cells[1] = (size_t)((ymax - origin[1]) / hcell) + 2;
    e->grid_nx = (int)cells[0];
    e->grid_ny = (int)cells[1];
    st = px_grid_create(e->be, 2, origin, hcell, cells, &e->grid);
  }
  return st;
}

void px_gran_cl_swap(struct px_gran_cl *e, int a, int b) {
  struct px_buffer *t = e->b[a];
  e->b[a] = e->b[b];
  e->b[b] = t;
}

/* One wall event for sorting: its record, the reals as doubles (exact for
 * float ones, so they are written back unchanged). */
struct px_gran_cl_event {
  int key[PX_GRAN_EVI];
  double r[PX_GRAN_EVR];
};

static int px_gran_cl_event_cmp(const void *pa, const void *pb) {
  const struct px_gran_cl_event *a = pa, *b = pb;
  static const int order[PX_GRAN_EVI] = {3, 2, 1, 0}; /* step, id, segment, type */
  int q;
  for (q = 0; q < PX_GRAN_EVI; ++q)
    if (a->key[order[q]] != b->key[order[q]]) return a->key[order[q]] < b->key[order[q]] ? -1 : 1;
  for (q = 0; q < PX_GRAN_EVR; ++q)
    if (a->r[q] != b->r[q]) return a->r[q] < b->r[q] ? -1 : 1;
  return 0;
}

/* The events of the device's buffer (written in the order the work-items
 * reached an atomic counter) into a fixed order, so that the statistics
 * sum them in the same order every run (and over any number of ranks: the
 * order depends on the events only). */
static enum px_status px_gran_cl_sort_events(struct px_gran_cl *e, int *ev_i, void *ev_r,
                                             size_t n) {
  const union px_gran_reals evr = {.p = ev_r};
  struct px_gran_cl_event *ev = px_mem_alloc(e->ctx, "granular opencl events", n * sizeof *ev);
  size_t k, q;
  if (!ev) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory (%zu wall events)", n);
  for (k = 0; k < n; ++k) {
    memcpy(ev[k].key, ev_i + k * PX_GRAN_EVI, sizeof ev[k].key);
    for (q = 0; q < PX_GRAN_EVR; ++q)
      ev[k].r[q] = px_gran_reals_get(evr, k * PX_GRAN_EVR + q, e->cs);
  }
  qsort(ev, n, sizeof *ev, px_gran_cl_event_cmp);
  for (k = 0; k < n; ++k) {
    memcpy(ev_i + k * PX_GRAN_EVI, ev[k].key, sizeof ev[k].key);
    for (q = 0; q < PX_GRAN_EVR; ++q)
      px_gran_reals_set(evr, k * PX_GRAN_EVR + q, e->cs, ev[k].r[q]);
  }
  px_mem_free(e->ctx, ev);
  return PX_STATUS_OK;
}

/* Move the device's wall events into the mirror's statistics. */
enum px_status px_gran_cl_drain(struct px_gran_cl *e) {
  struct px_gran_sys *h = e->h;
  uint32_t nev = 0;
  const uint32_t zero = 0;
  size_t take;
  if (!e->ncontours) return PX_STATUS_OK;
  PX_TRY(px_buffer_read(e->b[B_EVN], 0, 4, &nev));
  if (nev == 0) return PX_STATUS_OK;
  take = nev < e->ev_cap ? nev : e->ev_cap;
  if (nev > e->ev_cap) h->ev_overflow += nev - e->ev_cap;
  PX_TRY(px_buffer_read(e->b[B_EVI], 0, take * PX_GRAN_EVI * sizeof(int), e->ev_i));
  PX_TRY(px_buffer_read(e->b[B_EVR], 0, take * PX_GRAN_EVR * e->cs, e->ev_r));
  PX_TRY(px_buffer_write(e->b[B_EVN], 0, 4, &zero));
  return px_gran_cl_feed(e, e->ev_i, e->ev_r, take);
}

enum px_status px_gran_cl_feed(struct px_gran_cl *e, int *ev_i, void *ev_r, size_t take) {
  struct px_gran_sys *h = e->h;
  size_t done = 0;
  PX_TRY(px_gran_cl_sort_events(e, ev_i, ev_r, take));
  /* through the mirror's event buffers, in chunks of its capacity */
  while (done < take) {
    const size_t m = take - done < h->ev_cap ? take - done : h->ev_cap;
    int r;
    memcpy(h->ev_i, ev_i + done * PX_GRAN_EVI, m * PX_GRAN_EVI * sizeof(int));
    memcpy(h->ev_r.p, (char *)ev_r + done * PX_GRAN_EVR * e->cs, m * PX_GRAN_EVR * e->cs);
    h->ev_n[0] = m;
    for (r = 1; r < h->nranges; ++r) h->ev_n[r] = 0;
    px_gran_sys_events(h);
    done += m;
  }
  return PX_STATUS_OK;
}

enum px_status px_gran_cl_get(struct px_gran_cl *e, int k, double *v, size_t n, size_t es) {
  void *tmp = px_mem_alloc(e->ctx, "granular opencl staging", (n ? n : 1) * es);
  size_t i;
  enum px_status st;
  if (!tmp) return PX_STATUS_NOMEM;
  st = px_buffer_read(e->b[k], 0, n * es, tmp);
  for (i = 0; st == PX_STATUS_OK && i < n; ++i)
    v[i] = es == sizeof(double) ? ((double *)tmp)[i] : (double)((float *)tmp)[i];
  px_mem_free(e->ctx, tmp);
  return st;
}

enum px_status px_gran_cl_download(struct px_gran_cl *e) {
  struct px_gran_sys *h = e->h;
  const size_t n = e->n, W = PX_GRAN_WSLOTS;
  double *v = px_mem_alloc(e->ctx, "granular opencl staging", 8 * (n ? n : 1) * sizeof *v);
  double *rv = NULL;
  int *iv = NULL;
  size_t i, q;
  enum px_status st = PX_STATUS_OK;
  const int ks[8] = {B_X, B_Y, B_VX, B_VY, B_W, B_AX, B_AY, B_AW};
  if (!v) return PX_STATUS_NOMEM;
  PX_TRY(px_gran_cl_drain(e));
  for (q = 0; q < 8 && st == PX_STATUS_OK; ++q) st = px_gran_cl_get(e, ks[q], v + q * n, n, e->ss);
  for (i = 0; i < n && st == PX_STATUS_OK; ++i) {
    /* the state only: radius, mass and their inverses stay the prepared
     * system's (ops->set would recompute 1/m and 1/I from the rounded
     * radius and mass of a float system, and its checkpoint would no
     * longer match the case) */
    const size_t hi = (size_t)h->where[i];
    px_gran_reals_set(h->x, hi, h->ssize, v[i]);
    px_gran_reals_set(h->y, hi, h->ssize, v[n + i]);
    px_gran_reals_set(h->vx, hi, h->ssize, v[2 * n + i]);
    px_gran_reals_set(h->vy, hi, h->ssize, v[3 * n + i]);
    px_gran_reals_set(h->w, hi, h->ssize, v[4 * n + i]);
    px_gran_reals_set(h->fx, hi, h->ssize, v[5 * n + i]);
    px_gran_reals_set(h->fy, hi, h->ssize, v[6 * n + i]);
    px_gran_reals_set(h->tq, hi, h->ssize, v[7 * n + i]);
  }
  if (st == PX_STATUS_OK && h->geom) {
    const union px_gran_reals rs[10] = {h->slots.t0,  h->slots.te, h->slots.xi,  h->slots.th,
                                        h->slots.dm,  h->slots.dp, h->slots.imp, h->slots.slw,
                                        h->slots.arc, h->slots.tim};
    const int rk[10] = {B_ST0, B_STE, B_SXI, B_STH, B_SDM, B_SDP, B_SIMP, B_SSLW, B_SARC, B_STIM};
    iv = px_mem_alloc(e->ctx, "granular opencl staging", 3 * n * W * sizeof *iv);
    rv = px_mem_alloc(e->ctx, "granular opencl staging", 10 * n * W * sizeof *rv);
    if (!iv || !rv) st = PX_STATUS_NOMEM;
    if (st == PX_STATUS_OK) st = px_buffer_read(e->b[B_SSEG], 0, n * W * 4, iv);
    if (st == PX_STATUS_OK) st = px_buffer_read(e->b[B_SSEG0], 0, n * W * 4, iv + n * W);
    if (st == PX_STATUS_OK) st = px_buffer_read(e->b[B_SSTEP0], 0, n * W * 4, iv + 2 * n * W);
    for (q = 0; q < 10 && st == PX_STATUS_OK; ++q)
      st = px_gran_cl_get(e, rk[q], rv + q * n * W, n * W, e->cs);
    for (i = 0; i < n && st == PX_STATUS_OK; ++i) {
      const size_t hi = (size_t)h->where[i];
      size_t k2;
      for (k2 = 0; k2 < W; ++k2) {
        const size_t a = i * W + k2, b = hi * W + k2;
        h->slots.seg[b] = iv[a];
        h->slots.seg0[b] = iv[n * W + a];
        h->slots.step0[b] = iv[2 * n * W + a];
        for (q = 0; q < 10; ++q) px_gran_reals_set(rs[q], b, h->csize, rv[q * n * W + a]);
      }
    }
  }
  px_mem_free(e->ctx, v);
  px_mem_free(e->ctx, iv);
  px_mem_free(e->ctx, rv);
  PX_TRY(st);
  /* the mirror's own lists for the outputs (coordination, contour loads);
   * its rebuild counter counts the device's rebuilds */
  h->t = e->t;
  h->step = e->step;
  {
    /* the mirror's rebuild must not move what the device's skin test reads:
     * the rebuild count and the contour frames of the device's last rebuild
     * (else an output would change when the device rebuilds next) */
    const long rb = h->rebuilds;
    const size_t nf = h->geom ? h->geom->ncontours * PX_GRAN_CTR_COUNT : 0;
    double *fref = px_mem_alloc(e->ctx, "granular opencl staging", (nf ? nf : 1) * sizeof *fref);
    if (!fref) return px_context_fail(e->ctx, PX_STATUS_NOMEM, "out of memory");
    if (nf) memcpy(fref, h->frames_ref, nf * sizeof *fref);
    st = px_gran_sys_rebuild(h);
    if (nf) memcpy(h->frames_ref, fref, nf * sizeof *fref);
    h->rebuilds = rb;
    px_mem_free(e->ctx, fref);
    PX_TRY(st);
  }
  return px_gran_sys_wall_reactions(h);
}

/* The device lists and histories, wall candidates and the positions of the
 * last rebuild are kept in checkpoints by particle id (a resumed run goes on
 * with them, rebuilding when an uninterrupted run would).
 * The entries of a row beyond its count are stale (whatever an earlier
 * list or the fresh allocation left there): they are written as zeros, so
 * that a checkpoint holds only the state and two runs that agree write the
 * same bytes. */
enum px_status px_gran_cl_save(struct px_gran_cl *e, struct px_checkpoint_writer *w) {
  const size_t n = e->n, NM = PX_GRAN_CL_NMAX, WC = PX_GRAN_CL_WCMAX;
  const struct {
    const char *name;
    int k;
    size_t es;  /* bytes of an entry */
    size_t row; /* entries per particle (0: one, no tail) */
    int walls;  /* the row is counted by wcount (else by ncount) */
  } sec[] = {{"granular.cl.ncount", B_NCOUNT, 4, 0, 0}, {"granular.cl.nbr", B_NBR, 4, NM, 0},
             {"granular.cl.hxi", B_HXI, e->cs, NM, 0},  {"granular.cl.hth", B_HTH, e->cs, NM, 0},
             {"granular.cl.hdm", B_HDM, e->cs, NM, 0},  {"granular.cl.hdp", B_HDP, e->cs, NM, 0},
             {"granular.cl.wcount", B_WCOUNT, 4, 0, 0}, {"granular.cl.wcand", B_WCAND, 4, WC, 1},
             {"granular.cl.xr", B_XR, e->ss, 0, 0},     {"granular.cl.yr", B_YR, e->ss, 0, 0}};
  const size_t maxb = n * (NM > WC ? NM : WC) * (e->cs > 4 ? e->cs : 4);
  int32_t *cnt = px_mem_alloc(e->ctx, "granular opencl staging", 2 * (n ? n : 1) * sizeof *cnt);
  unsigned char *tmp = px_mem_alloc(e->ctx, "granular opencl staging", maxb ? maxb : 1);
  size_t k, i;
  enum px_status st = PX_STATUS_OK;
  if (!tmp || !cnt) st = PX_STATUS_NOMEM;
  if (st == PX_STATUS_OK) st = px_buffer_read(e->b[B_NCOUNT], 0, n * 4, cnt);
  if (st == PX_STATUS_OK) st = px_buffer_read(e->b[B_WCOUNT], 0, n * 4, cnt + n);
  for (k = 0; k < sizeof sec / sizeof sec[0] && st == PX_STATUS_OK; ++k) {
    const size_t row = sec[k].row ? sec[k].row : 1, bytes = n * row * sec[k].es;
    st = px_buffer_read(e->b[sec[k].k], 0, bytes, tmp);
    for (i = 0; sec[k].row && i < n && st == PX_STATUS_OK; ++i) {
      const int32_t c = cnt[(sec[k].walls ? n : 0) + i];
      const size_t used = c < 0 ? 0 : (size_t)c < row ? (size_t)c : row;
      memset(tmp + (i * row + used) * sec[k].es, 0, (row - used) * sec[k].es);
    }
    if (st == PX_STATUS_OK) st = px_checkpoint_write(w, sec[k].name, PX_DTYPE_U8, bytes, tmp);
  }
  px_mem_free(e->ctx, tmp);
  px_mem_free(e->ctx, cnt);
  return st;
}

/* After the lists: the wall candidates and the positions of the device's
 * last rebuild, so that the resumed run rebuilds when an uninterrupted one
 * would (the frames of that rebuild are the mirror's frames_ref). A
 * checkpoint without them (written before they were kept) is resumed with
 * a rebuild at the first step. */
static enum px_status px_gran_cl_load_walls(struct px_gran_cl *e, struct px_checkpoint *ck) {
  const size_t n = e->n, WC = PX_GRAN_CL_WCMAX;
  enum px_dtype t;
  uint64_t cnt = 0;
  int32_t *wc = NULL, *cand = NULL;
  double *xy = NULL;
  size_t i, q;
  enum px_status st = PX_STATUS_OK;
  if (px_checkpoint_find(ck, "granular.cl.xr", &t, &cnt) != PX_STATUS_OK) return PX_STATUS_OK;
  wc = px_mem_alloc(e->ctx, "granular opencl staging", n * 4 + 8);
  cand = px_mem_alloc(e->ctx, "granular opencl staging", n * WC * 4 + 8);
  xy = px_mem_alloc(e->ctx, "granular opencl staging", 2 * n * 8 + 8);
  if (!wc || !cand || !xy) st = PX_STATUS_NOMEM;
  if (st == PX_STATUS_OK) st = px_checkpoint_read(ck, "granular.cl.wcount", PX_DTYPE_U8, n * 4, wc);
  if (st == PX_STATUS_OK)
    st = px_checkpoint_read(ck, "granular.cl.wcand", PX_DTYPE_U8, n * WC * 4, cand);
  for (i = 0; i < n && st == PX_STATUS_OK; ++i) {
    if (wc[i] < 0 || (size_t)wc[i] > WC)
      st = px_context_fail(e->ctx, PX_STATUS_FORMAT,
                           "checkpoint section 'granular.cl.wcount': particle %zu has %d wall "
                           "candidates (at most %zu; a damaged or forged checkpoint)",
                           i, (int)wc[i], WC);
    for (q = 0; q < (size_t)wc[i] && st == PX_STATUS_OK; ++q) {
      const int32_t sg = cand[i * WC + q];
      if (sg < 0 || (size_t)sg >= e->nseg)
        st = px_context_fail(e->ctx, PX_STATUS_FORMAT,
                             "checkpoint section 'granular.cl.wcand': candidate %zu of particle "
                             "%zu is segment %d (%zu segments; a damaged or forged checkpoint)",
                             q, i, (int)sg, e->nseg);
    }
  }
  /* the reference positions: finite and within the coordinate bound */
  for (q = 0; q < 2 && st == PX_STATUS_OK; ++q) {
    const char *name = q ? "granular.cl.yr" : "granular.cl.xr";
    unsigned char *raw = (unsigned char *)(xy + q * n);
    st = px_checkpoint_read(ck, name, PX_DTYPE_U8, n * e->ss, raw);
    for (i = 0; i < n && st == PX_STATUS_OK; ++i) {
      const double v = px_gran_reals_get((union px_gran_reals){.p = raw}, i, e->ss);
      if (!(fabs(v) <= PX_GRAN_COORD_MAX))
        st = px_context_fail(e->ctx, PX_STATUS_FORMAT,
                             "checkpoint section '%s': particle %zu: %g is not a position (a "
                             "damaged or forged checkpoint)",
                             name, i, v);
    }
    if (st == PX_STATUS_OK) st = px_buffer_write(e->b[q ? B_YR : B_XR], 0, n * e->ss, raw);
  }
  if (st == PX_STATUS_OK) st = px_buffer_write(e->b[B_WCAND], 0, n * WC * 4, cand);
  if (st == PX_STATUS_OK) st = px_buffer_write(e->b[B_WCOUNT], 0, n * 4, wc);
  if (st == PX_STATUS_OK) e->need_rebuild = 0;
  px_mem_free(e->ctx, wc);
  px_mem_free(e->ctx, cand);
  px_mem_free(e->ctx, xy);
  return st;
}

enum px_status px_gran_cl_load(struct px_gran_cl *e, struct px_checkpoint *ck) {
  const size_t n = e->n, NM = PX_GRAN_CL_NMAX;
  const struct {
    const char *name;
    int k;
    size_t bytes;
  } sec[] = {
      {"granular.cl.ncount", B_ONCOUNT, n * 4},   {"granular.cl.nbr", B_ONBR, n * NM * 4},
      {"granular.cl.hxi", B_OXI, n * NM * e->cs}, {"granular.cl.hth", B_OTH, n * NM * e->cs},
      {"granular.cl.hdm", B_ODM, n * NM * e->cs}, {"granular.cl.hdp", B_ODP, n * NM * e->cs}};
  size_t k, i;
  /* every section checked before the lists reach the device (the file is
   * untrusted): counts in [0, NMAX] and partners other particles (the
   * kernel reads partners up to each particle's count), histories of the
   * listed partners finite; the histories go up first, the lists that
   * index them last */
  int32_t *cnt, *nbr;
  enum px_dtype type;
  uint64_t count;
  /* a checkpoint of the cpu engine holds its pair records, not these lists:
     the contacts' tangential histories cannot be carried over */
  if (px_checkpoint_find(ck, sec[0].name, &type, &count) == PX_STATUS_NOT_FOUND)
    return px_context_fail(e->ctx, PX_STATUS_CONFIG,
                           "this checkpoint was written on the cpu backend: a granular run keeps "
                           "its contacts' histories in the form of the engine that wrote it, so "
                           "it resumes on that backend (--backend cpu)");
  cnt = px_mem_alloc(e->ctx, "granular opencl staging", n * 4 + 8);
  nbr = px_mem_alloc(e->ctx, "granular opencl staging", n * NM * 4 + 8);
  unsigned char *tmp = px_mem_alloc(e->ctx, "granular opencl staging", n * NM * 8 + 8);
  enum px_status st = PX_STATUS_OK;
  if (!cnt || !nbr || !tmp) st = PX_STATUS_NOMEM;
  if (st == PX_STATUS_OK) st = px_checkpoint_read(ck, sec[0].name, PX_DTYPE_U8, sec[0].bytes, cnt);
  if (st == PX_STATUS_OK) st = px_checkpoint_read(ck, sec[1].name, PX_DTYPE_U8, sec[1].bytes, nbr);
  for (i = 0; i < n && st == PX_STATUS_OK; ++i) {
    size_t q;
    if (cnt[i] < 0 || (size_t)cnt[i] > NM) {
      st = px_context_fail(e->ctx, PX_STATUS_FORMAT,
                           "checkpoint section 'granular.cl.ncount': particle %zu has %d "
                           "neighbours (at most %zu; a damaged or forged checkpoint)",
                           i, (int)cnt[i], NM);
      break;
    }
    for (q = 0; q < (size_t)cnt[i] && st == PX_STATUS_OK; ++q) {
      const int32_t j = nbr[i * NM + q];
      if (j < 0 || (size_t)j >= n || (size_t)j == i)
        st = px_context_fail(e->ctx, PX_STATUS_FORMAT,
                             "checkpoint section 'granular.cl.nbr': neighbour %zu of particle "
                             "%zu is %d (%zu particles; a damaged or forged checkpoint)",
                             q, i, (int)j, n);
    }
  }
  for (k = 2; k < 6 && st == PX_STATUS_OK; ++k) {
    st = px_checkpoint_read(ck, sec[k].name, PX_DTYPE_U8, sec[k].bytes, tmp);
    for (i = 0; i < n && st == PX_STATUS_OK; ++i) {
      size_t q;
      for (q = 0; q < (size_t)cnt[i]; ++q) {
        const double v = px_gran_reals_get((union px_gran_reals){.p = tmp}, i * NM + q, e->cs);
        if (!isfinite(v)) {
          st = px_context_fail(e->ctx, PX_STATUS_FORMAT,
                               "checkpoint section '%s': neighbour %zu of particle %zu: %g is "
                               "not finite (a damaged or forged checkpoint)",
                               sec[k].name, q, i, v);
          break;
        }
      }
    }
    if (st == PX_STATUS_OK)
      st = px_buffer_write(e->b[sec[k].k - (B_ONCOUNT - B_NCOUNT)], 0, sec[k].bytes, tmp);
  }
  /* the saved lists become the "current" ones (the rebuild that follows
   * moves them to "old" and carries the histories over) */
  if (st == PX_STATUS_OK)
    st = px_buffer_write(e->b[sec[1].k - (B_ONCOUNT - B_NCOUNT)], 0, sec[1].bytes, nbr);
  if (st == PX_STATUS_OK)
    st = px_buffer_write(e->b[sec[0].k - (B_ONCOUNT - B_NCOUNT)], 0, sec[0].bytes, cnt);
  px_mem_free(e->ctx, cnt);
  px_mem_free(e->ctx, nbr);
  px_mem_free(e->ctx, tmp);
  PX_TRY(st);
  PX_TRY(px_gran_cl_upload(e));
  return px_gran_cl_load_walls(e, ck);
}

static int px_gran_cl_pair_cmp(const void *a, const void *b) {
  const int32_t *p = a, *q = b;
  if (p[0] != q[0]) return p[0] < q[0] ? -1 : 1;
  if (p[1] != q[1]) return p[1] < q[1] ? -1 : 1;
  return 0;
}

enum px_status px_gran_cl_contacts(struct px_gran_cl *e, int32_t **pairs, size_t *np) {
  const size_t n = e->n, NM = PX_GRAN_CL_NMAX;
  double *x = px_mem_alloc(e->ctx, "granular opencl staging", 3 * (n ? n : 1) * sizeof *x);
  int *cnt = px_mem_alloc(e->ctx, "granular opencl staging", (n ? n : 1) * sizeof *cnt);
  int *nbr = px_mem_alloc(e->ctx, "granular opencl staging", (n ? n : 1) * NM * sizeof *nbr);
  int32_t *out = NULL;
  size_t i, m = 0;
  enum px_status st = PX_STATUS_OK;
  *pairs = NULL;
  *np = 0;
  if (!x || !cnt || !nbr) st = PX_STATUS_NOMEM;
  if (st == PX_STATUS_OK) st = px_gran_cl_get(e, B_X, x, n, e->ss);
  if (st == PX_STATUS_OK) st = px_gran_cl_get(e, B_Y, x + n, n, e->ss);
  if (st == PX_STATUS_OK) st = px_gran_cl_get(e, B_R, x + 2 * n, n, e->cs);
  if (st == PX_STATUS_OK) st = px_buffer_read(e->b[B_NCOUNT], 0, n * 4, cnt);
  if (st == PX_STATUS_OK) st = px_buffer_read(e->b[B_NBR], 0, n * NM * 4, nbr);
  if (st == PX_STATUS_OK) {
    out = px_mem_alloc(e->ctx, "granular contacts", (n * NM + 1) * 2 * sizeof *out);
    if (!out) st = PX_STATUS_NOMEM;
  }
  for (i = 0; i < n && st == PX_STATUS_OK; ++i) {
    int c;
    for (c = 0; c < cnt[i]; ++c) {
      const size_t j = (size_t)nbr[i * NM + (size_t)c];
      if (j <= i) continue;
      if (hypot(x[i] - x[j], x[n + i] - x[n + j]) < x[2 * n + i] + x[2 * n + j]) {
        out[2 * m] = (int32_t)i;
        out[2 * m + 1] = (int32_t)j;
        ++m;
      }
    }
  }
  px_mem_free(e->ctx, x);
  px_mem_free(e->ctx, cnt);
  px_mem_free(e->ctx, nbr);
  if (st != PX_STATUS_OK) {
    px_mem_free(e->ctx, out);
    return st;
  }
  qsort(out, m, 2 * sizeof *out, px_gran_cl_pair_cmp);
  *pairs = out;
  *np = m;
  return PX_STATUS_OK;
}

enum px_status px_gran_cl_upload(struct px_gran_cl *e) {
  e->step = e->h->step;
  e->synced_step = e->step;
  e->t = e->h->t;
  PX_TRY(px_gran_cl_upload_state(e));
  px_gran_sys_frames(e->h, e->t);
  PX_TRY(px_gran_cl_write_frames(e));
  e->need_rebuild = 1;
  e->plan_ok = 0; /* over ranks: the strips are recut from the uploaded state */
  return PX_STATUS_OK;
}
