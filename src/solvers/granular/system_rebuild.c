/* Rebuilds of the granular system: cell sort and reordering of the
 * particles, the half neighbour list with its histories carried over, wall
 * candidates, and the fixed work split of the threads. */
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/checkpoint.h"
#include "partix/backend.h"
#include "partix/memory.h"
#include "partix/neighbors.h"
#include "partix/timer.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/system_impl.h"
#include "solvers/granular/wall_kernel.h"

/* ------------------------------------------------------------------ rebuild */

enum px_status px_gran_ensure(struct px_gran_sys *s, void **p, size_t bytes, const char *label) {
  void *q;
  if (*p && px_mem_size(*p) >= bytes) return PX_STATUS_OK;
  q = px_mem_realloc(s->ctx, label, *p, bytes ? bytes : 1);
  if (!q) return PX_STATUS_NOMEM;
  *p = q;
  return PX_STATUS_OK;
}

/* Copy element i of src (blk bytes) to slot j of dst: 4 and 8 bytes (most
 * arrays) as fixed-size copies the compiler turns into one move. */
static inline void px_gran_move(char *dst, size_t j, const char *src, size_t i, size_t blk) {
  if (blk == 8)
    memcpy(dst + j * 8, src + i * 8, 8);
  else if (blk == 4)
    memcpy(dst + j * 4, src + i * 4, 4);
  else
    memcpy(dst + j * blk, src + i * blk, blk);
}

/* Permute the kept per-particle arrays: new slot i takes old order[i]. The
 * arrays are shared out whole among up to 4 threads, each with its own
 * scratch (a pure permutation: the same bits on any thread count; one
 * synchronization, at the end, so that a thread that another process
 * pushes off its core holds the others up once per rebuild, not once per
 * array). */
static enum px_status px_gran_permute(struct px_gran_sys *s) {
  struct px_gran_arr a[PX_GRAN_MAX_ARRAYS];
  const size_t na = px_gran_arrays(s, a), n = s->n, room = n * 8 * PX_GRAN_WSLOTS;
  const uint32_t *order = s->order;
  const int nt = s->active < 1 ? 1 : (s->active < 4 ? s->active : 4);
  long k;
  size_t i;
  PX_TRY(px_gran_ensure(s, &s->scratch, (size_t)nt * room, "granular scratch"));
#pragma omp parallel for num_threads(nt) schedule(dynamic, 1)
  for (k = 0; k < (long)na; ++k) {
    const size_t blk = a[k].esize * a[k].per;
    char *src = *a[k].p, *tmp = (char *)s->scratch + (size_t)omp_get_thread_num() * room;
    size_t j;
    if (!a[k].keep) continue;
    for (j = 0; j < n; ++j) px_gran_move(tmp, j, src, order[j], blk);
    memcpy(src, tmp, n * blk);
  }
  for (i = 0; i < n; ++i) s->where[s->id[i]] = (int32_t)i;
  return PX_STATUS_OK;
}

void px_gran_copy_real(union px_gran_reals dst, size_t di, union px_gran_reals src, size_t si,
                       size_t cs, double sign) {
  if (cs == sizeof(double))
    dst.d[di] = sign * src.d[si];
  else
    dst.f[di] = (float)sign * src.f[si];
}

double px_gran_rd(const void *p, size_t i, size_t es) {
  return es == sizeof(double) ? ((const double *)p)[i] : (double)((const float *)p)[i];
}

/* The wall segments within r + skin of particle i, into buf (room for
 * PX_GRAN_WCAND_MAX): their count, or -1 when they do not fit. */
static int px_gran_wall_cands(const struct px_gran_sys *s, size_t i, int *buf) {
  const struct px_gran_geom *g = s->geom;
  double rec[8];
  size_t c;
  int cnt = 0;
  s->ops->get(s, i, rec);
  for (c = 0; c < g->ncontours; ++c) {
    const struct px_gran_contour *C = &g->contours[c];
    const double range = rec[PX_GRAN_P_R] + s->skin;
    double lx, ly;
    int got;
    px_gran_geom_to_local(s->frames + c * PX_GRAN_CTR_COUNT, rec[PX_GRAN_P_X], rec[PX_GRAN_P_Y],
                          &lx, &ly);
    if (lx < C->xmin - range || lx > C->xmax + range || ly < C->ymin - range ||
        ly > C->ymax + range)
      continue;
    got = px_gran_geom_near(g, c, lx, ly, range, buf + cnt, PX_GRAN_WCAND_MAX - cnt);
    if (got < 0) return -1;
    cnt += got;
  }
  return cnt;
}

/* Wall candidates within r + skin for every particle (CSR), near list: the
 * particles' counts on all threads, then the few near a wall listed again
 * into their places. */
static enum px_status px_gran_build_walls(struct px_gran_sys *s) {
  const long n = (long)s->n;
  long i, bad = n;
  size_t q, total = 0;
  PX_TRY(px_gran_ensure(s, (void **)&s->wstart, ((size_t)n + 1) * sizeof(int32_t),
                        "granular wall lists"));
  PX_TRY(px_gran_ensure(s, (void **)&s->near, (n ? (size_t)n : 1) * sizeof(int32_t),
                        "granular wall lists"));
#pragma omp parallel for num_threads(s->active) schedule(static) reduction(min : bad)
  for (i = 0; i < n; ++i) {
    int buf[PX_GRAN_WCAND_MAX];
    const int cnt = px_gran_wall_cands(s, (size_t)i, buf);
    s->wstart[i] = cnt;
    if (cnt < 0 && i < bad) bad = i;
  }
  if (bad < n) {
    double rec[8];
    s->ops->get(s, (size_t)bad, rec);
    return px_context_fail(s->ctx, PX_STATUS_NUMERIC,
                           "particle %d at (%g, %g) is near more than %d boundary segments: "
                           "the segments are much shorter than the particle (raise "
                           "segment_length)",
                           (int)s->id[bad], rec[PX_GRAN_P_X], rec[PX_GRAN_P_Y], PX_GRAN_WCAND_MAX);
  }
  s->nnear = 0;
  for (i = 0; i < n; ++i) {
    const int32_t cnt = s->wstart[i];
    s->wstart[i] = (int32_t)total;
    if (cnt) s->near[s->nnear++] = (int32_t)i;
    total += (size_t)cnt;
  }
  s->wstart[n] = (int32_t)total;
  s->nwcand = total;
  PX_TRY(px_gran_ensure(s, (void **)&s->wcand, (total ? total : 1) * sizeof(int32_t),
                        "granular wall lists"));
#pragma omp parallel for num_threads(s->active) schedule(static)
  for (q = 0; q < s->nnear; ++q) {
    const int32_t p = s->near[q];
    int buf[PX_GRAN_WCAND_MAX];
    const int cnt = px_gran_wall_cands(s, (size_t)p, buf);
    memcpy(s->wcand + s->wstart[p], buf, (size_t)cnt * sizeof(int32_t));
  }
  return PX_STATUS_OK;
}

/* Is the particle (world x, y) behind the wall it is closest to among its
 * candidates? Returns the contour index or -1. */
static int px_gran_behind_wall(const struct px_gran_sys *s, size_t i, double x, double y) {
  const struct px_gran_geom *g = s->geom;
  int32_t q;
  double best = DBL_MAX, side = 1;
  int bestc = -1;
  for (q = s->wstart[i]; q < s->wstart[i + 1]; ++q) {
    const int sg = s->wcand[q];
    const int c = g->contour[sg];
    const struct px_gran_contour *C = &g->contours[c];
    double lx, ly, rx, ry, u, d, sd;
    px_gran_geom_to_local(s->frames + (size_t)c * PX_GRAN_CTR_COUNT, x, y, &lx, &ly);
    rx = lx - g->ax[sg];
    ry = ly - g->ay[sg];
    u = rx * g->tx[sg] + ry * g->ty[sg];
    if (u <= 0) {
      /* start vertex: pseudo-normal = sum of the two segment normals */
      const double nx = -g->tpy[sg] - g->ty[sg], ny = g->tpx[sg] + g->tx[sg];
      d = hypot(rx, ry);
      sd = rx * nx + ry * ny;
    } else if (u >= g->len[sg]) {
      const size_t k = (size_t)sg - C->first, nxt = C->first + (k + 1) % C->count;
      const double ex = rx - g->len[sg] * g->tx[sg], ey = ry - g->len[sg] * g->ty[sg];
      const double nx = -g->ty[sg] - g->ty[nxt], ny = g->tx[sg] + g->tx[nxt];
      d = hypot(ex, ey);
      sd = ex * nx + ey * ny;
    } else {
      sd = ry * g->tx[sg] - rx * g->ty[sg];
      d = fabs(sd);
    }
    if (d < best) {
      best = d;
      side = sd;
      bestc = c;
    }
  }
  return (bestc >= 0 && side < 0) ? bestc : -1;
}

/* Work split: fixed particle ranges and their cross pairs (j in a later
 * range), from the pair list. */
enum px_status px_gran_sys_split_pairs(struct px_gran_sys *s) {
  const int T = s->nranges;
  const size_t n = s->n;
  int t;
  size_t k;
  int32_t *count;
  PX_TRY(px_gran_ensure(s, (void **)&s->rng_i, (size_t)(T + 1) * sizeof(size_t), "granular pairs"));
  PX_TRY(px_gran_ensure(s, (void **)&s->rng_q, (size_t)(T + 1) * sizeof(size_t), "granular pairs"));
  PX_TRY(px_gran_ensure(s, (void **)&s->rng_hi, (size_t)T * sizeof(int), "granular pairs"));
  PX_TRY(px_gran_ensure(s, (void **)&s->rng_lo, (size_t)T * sizeof(int), "granular pairs"));
  PX_TRY(
      px_gran_ensure(s, (void **)&s->xstart, (size_t)(T + 1) * sizeof(int32_t), "granular pairs"));
  PX_TRY(px_gran_ensure(s, (void **)&s->xpair, (s->npairs ? s->npairs : 1) * sizeof(int32_t),
                        "granular pairs"));
  s->plan_ok = 0; /* the ranks' ghost lists follow the pair list */
  count = px_mem_alloc(s->ctx, "granular pairs", (size_t)(T + 1) * sizeof *count);
  if (!count) return PX_STATUS_NOMEM;
  for (t = 0; t <= T; ++t) s->rng_i[t] = n * (size_t)t / (size_t)T;
  for (t = 0; t < T; ++t) s->rng_hi[t] = s->rng_lo[t] = t;
  memset(s->xstart, 0, (size_t)(T + 1) * sizeof(int32_t));
  for (t = 0; t < T; ++t) {
    const size_t i1 = s->rng_i[t + 1];
    for (k = (size_t)s->pstart[s->rng_i[t]]; k < (size_t)s->pstart[i1]; ++k)
      if ((size_t)s->pj[k] >= i1) {
        int u = t + 1;
        while ((size_t)s->pj[k] >= s->rng_i[u + 1]) ++u;
        ++s->xstart[u + 1];
        if (u > s->rng_hi[t]) s->rng_hi[t] = u;
        if (t < s->rng_lo[u]) s->rng_lo[u] = t;
      }
  }
  for (t = 0; t < T; ++t) s->xstart[t + 1] += s->xstart[t];
  memcpy(count, s->xstart, (size_t)T * sizeof(int32_t));
  for (t = 0; t < T; ++t) {
    const size_t i1 = s->rng_i[t + 1];
    for (k = (size_t)s->pstart[s->rng_i[t]]; k < (size_t)s->pstart[i1]; ++k)
      if ((size_t)s->pj[k] >= i1) {
        int u = t + 1;
        while ((size_t)s->pj[k] >= s->rng_i[u + 1]) ++u;
        s->xpair[count[u]++] = (int32_t)k;
      }
  }
  px_mem_free(s->ctx, count);
  return PX_STATUS_OK;
}

/* Near-wall particles of each range (the near list is ascending). */
void px_gran_sys_split_near(struct px_gran_sys *s) {
  int t;
  size_t q = 0;
  for (t = 0; t <= s->nranges; ++t) {
    while (q < s->nnear && (size_t)s->near[q] < s->rng_i[t]) ++q;
    s->rng_q[t] = q;
  }
  s->rng_q[s->nranges] = s->nnear;
}

/* The neighbour list before a rebuild, in the old particle indices (owned
 * by the rebuild while it carries the histories over). */
struct px_gran_oldlist {
  int32_t *pstart, *pj;
  union px_gran_reals xi, th, dm, dp; /* contact histories (contact precision) */
};

/* The grid's backend (created at the first rebuild, after prepare has
 * fixed the thread count) and its per-particle buffers sized to n. The
 * system's own cpu backend, whatever engine runs the case: the rebuild is a
 * host loop over host arrays (the OpenCL engine's mirror rebuilds too). */
static enum px_status px_gran_grid_buffers(struct px_gran_sys *s) {
  const size_t n = s->n;
  int a;
  if (!s->gbe) PX_TRY(px_backend_create(s->ctx, "cpu", 0, s->threads, &s->gbe));
  for (a = 0; a < 2; ++a)
    if (!s->gpos[a])
      PX_TRY(px_buffer_create(s->gbe, "granular grid positions", n * sizeof(double), &s->gpos[a]));
    else
      PX_TRY(px_buffer_resize(s->gpos[a], n * sizeof(double)));
  if (!s->gcell)
    PX_TRY(px_buffer_create(s->gbe, "granular grid cells", n * sizeof(uint32_t), &s->gcell));
  else
    PX_TRY(px_buffer_resize(s->gcell, n * sizeof(uint32_t)));
  return PX_STATUS_OK;
}

/* The box [xmin, ymin, xmax, ymax] [m] of the containers (the outermost
 * contours, with the media inside) where they are now (s->frames), grown
 * by the largest radius: a disc whose centre is beyond it touches no wall
 * and has left the container. Each contour's body-frame box is carried by
 * its frame corner by corner (the box of the moved corners holds the moved
 * contour). Returns 0 when the media is not enclosed (no contour, or an
 * outermost contour with the media outside): then nothing bounds the discs. */
static int px_gran_container_box(const struct px_gran_sys *s, double box[4]) {
  const struct px_gran_geom *g = s->geom;
  size_t c;
  int any = 0;
  box[0] = box[1] = DBL_MAX;
  box[2] = box[3] = -DBL_MAX;
  if (!g || !s->frames) return 0;
  for (c = 0; c < g->ncontours; ++c) {
    const struct px_gran_contour *C = &g->contours[c];
    const double *f = s->frames + c * PX_GRAN_CTR_COUNT;
    int k;
    if (C->depth != 0) continue;
    if (!C->media_inside) return 0;
    any = 1;
    for (k = 0; k < 4; ++k) {
      /* world = pivot + d + R(phi) (local - pivot), the inverse of the
       * wall kernel's local frame */
      const double ux = (k & 1 ? C->xmax : C->xmin) - f[PX_GRAN_CTR_PX];
      const double uy = (k & 2 ? C->ymax : C->ymin) - f[PX_GRAN_CTR_PY];
      const double wx =
          f[PX_GRAN_CTR_PX] + f[PX_GRAN_CTR_DX] + f[PX_GRAN_CTR_COS] * ux - f[PX_GRAN_CTR_SIN] * uy;
      const double wy =
          f[PX_GRAN_CTR_PY] + f[PX_GRAN_CTR_DY] + f[PX_GRAN_CTR_SIN] * ux + f[PX_GRAN_CTR_COS] * uy;
      box[0] = fmin(box[0], wx), box[2] = fmax(box[2], wx);
      box[1] = fmin(box[1], wy), box[3] = fmax(box[3], wy);
    }
  }
  box[0] -= s->rmax, box[1] -= s->rmax, box[2] += s->rmax, box[3] += s->rmax;
  return any;
}

/* The particles sorted by cell of a grid over their box (order[] lists
 * them cell by cell, stable), through the platform's neighbour grid;
 * non-finite or scattered particles are a blow-up. The cells have at least
 * one empty cell around the box, so the grid's clamping never acts. */
static enum px_status px_gran_sort_cells(struct px_gran_sys *s) {
  const size_t n = s->n;
  double xmin = DBL_MAX, ymin = DBL_MAX, xmax = -DBL_MAX, ymax = -DBL_MAX, h, origin[2], cb[4];
  size_t i, cells[2];
  double *gx, *gy;
  /* a disc far beyond the walls (one step of a disc much faster than the
   * time step allows carries it past the wall's reach, where the check of
   * px_gran_rebuild_walls does not look) is a failure, not a result */
  const int contained = px_gran_container_box(s, cb);
  PX_TRY(px_gran_grid_buffers(s));
  gx = px_buffer_host(s->gpos[0]);
  gy = px_buffer_host(s->gpos[1]);
  /* finite positions and the bounding box; the positions as double (exact
   * in every precision) are what the grid bins */
  for (i = 0; i < n; ++i) {
    double rec[8];
    s->ops->get(s, i, rec);
    if (!isfinite(rec[PX_GRAN_P_X]) || !isfinite(rec[PX_GRAN_P_Y]) ||
        !isfinite(rec[PX_GRAN_P_VX]) || !isfinite(rec[PX_GRAN_P_VY]) || !isfinite(rec[PX_GRAN_P_W]))
      return px_context_fail(s->ctx, PX_STATUS_NUMERIC,
                             "particle %d has a non-finite position or velocity at step %ld (t = "
                             "%g s) (x = %g, y = %g, vx = %g, vy = %g): the time step is too "
                             "large for the stiffness, or the input is wrong",
                             (int)s->id[i], s->step, s->t, rec[0], rec[1], rec[2], rec[3]);
    if (contained && !(rec[0] >= cb[0] && rec[0] <= cb[2] && rec[1] >= cb[1] && rec[1] <= cb[3])) {
      const double v = hypot(rec[PX_GRAN_P_VX], rec[PX_GRAN_P_VY]);
      s->escaped_id = s->id[i];
      return px_context_fail(s->ctx, PX_STATUS_NUMERIC,
                             "particle %d at (%g, %g) has left the container at step %ld (t = %g "
                             "s): the container spans x %g to %g m, y %g to %g m (with a margin "
                             "of the largest radius); at |v| = %g m/s it moves %g m per step of "
                             "%g s: the time step is too large for the speeds, or a wall jumped "
                             "(a motion without a ramp)",
                             (int)s->id[i], rec[0], rec[1], s->step, s->t, cb[0], cb[2], cb[1],
                             cb[3], v, v * s->dt, s->dt);
    }
    if (rec[0] < xmin) xmin = rec[0];
    if (rec[0] > xmax) xmax = rec[0];
    if (rec[1] < ymin) ymin = rec[1];
    if (rec[1] > ymax) ymax = rec[1];
    gx[i] = rec[PX_GRAN_P_X], gy[i] = rec[PX_GRAN_P_Y];
  }
  if (n == 0) xmin = ymin = xmax = ymax = 0;
  if (!(xmax - xmin <= PX_GRAN_COORD_MAX) || !(ymax - ymin <= PX_GRAN_COORD_MAX))
    return px_context_fail(s->ctx, PX_STATUS_NUMERIC,
                           "the particles spread over %g m x %g m at step %ld (t = %g s), more "
                           "than %g m: some escaped the contours and flew away",
                           xmax - xmin, ymax - ymin, s->step, s->t, PX_GRAN_COORD_MAX);
  h = 2 * s->rmax + s->skin;
  while (((xmax - xmin) / h + 3) * ((ymax - ymin) / h + 3) > 4.0 * (double)n + 1e6) h *= 2;
  s->gh = h;
  s->gx0 = xmin - h;
  s->gy0 = ymin - h;
  s->gnx = (int)((xmax - s->gx0) / h) + 2;
  s->gny = (int)((ymax - s->gy0) / h) + 2;
  origin[0] = s->gx0, origin[1] = s->gy0;
  cells[0] = (size_t)s->gnx, cells[1] = (size_t)s->gny;
  if (!s->grid)
    PX_TRY(px_grid_create(s->gbe, 2, origin, h, cells, &s->grid));
  else
    PX_TRY(px_grid_reshape(s->grid, origin, h, cells));
  PX_TRY(px_grid_build(s->grid, PX_PRECISION_DOUBLE, n, s->gpos[0], s->gpos[1], NULL));
  PX_TRY(px_grid_reorder(s->grid, PX_DTYPE_U32, px_grid_cells(s->grid), s->gcell));
  s->order = px_buffer_host(px_grid_permutation(s->grid));
  s->cell = px_buffer_host(s->gcell);
  s->cstart = px_buffer_host(px_grid_cell_start(s->grid));
  s->cend = px_buffer_host(px_grid_cell_end(s->grid));
  return PX_STATUS_OK;
}

/* The new half neighbour list (CSR by particle) of the sorted particles,
 * with zeroed histories and the per-pair arrays sized to it. */
static enum px_status px_gran_new_pairs(struct px_gran_sys *s) {
  const size_t n = s->n, cs = s->csize;
  int32_t *count;
  size_t i;
  enum px_status st = PX_STATUS_OK;
  count = px_mem_alloc(s->ctx, "granular pairs", (n + 1) * sizeof *count);
  s->pstart = px_mem_alloc(s->ctx, "granular pairs", (n + 1) * sizeof(int32_t));
  if (!count || !s->pstart) {
    st = PX_STATUS_NOMEM;
    goto done;
  }
  if (s->pcache_n < 0 || s->pcache_n > PX_GRAN_PCACHE) s->pcache_n = PX_GRAN_PCACHE;
  st = px_gran_ensure(s, (void **)&s->pcache,
                      (n ? n : 1) * (size_t)(s->pcache_n ? s->pcache_n : 1) * sizeof(int32_t),
                      "granular pairs");
  if (st != PX_STATUS_OK) goto done;
  s->ops->build_pairs(s, s->skin, 0, count);
  {
    /* pair indices are int32: a list beyond them (discs piled on top of each
     * other, a skin far above the radii) is a failure, not a wrap */
    size_t total = 0;
    for (i = 0; i < n; ++i) total += (size_t)count[i];
    if (total > (size_t)INT32_MAX) {
      st = px_context_fail(s->ctx, PX_STATUS_NUMERIC,
                           "%zu neighbour pairs within the cut-off (radii + skin %g m) at step "
                           "%ld (t = %g s): more than the neighbour list holds; the discs are "
                           "piled up or the skin is far too large",
                           total, s->skin, s->step, s->t);
      goto done;
    }
  }
  s->pstart[0] = 0;
  for (i = 0; i < n; ++i) s->pstart[i + 1] = s->pstart[i] + count[i];
  s->npairs = (size_t)s->pstart[n];
  {
    const size_t np = s->npairs ? s->npairs : 1;
    void **pa[] = {(void **)&s->pi, &s->pfx.p, &s->pfy.p, &s->pti.p,  &s->ptj.p, &s->pri.p,
                   &s->prj.p,       &s->pme.p, &s->pre.p, &s->pdxr.p, &s->pdyr.p};
    const size_t es[] = {sizeof(int32_t), cs, cs, cs, cs, cs, cs, cs, cs, cs, cs};
    size_t k;
    for (k = 0; k < sizeof pa / sizeof pa[0]; ++k) {
      st = px_gran_ensure(s, pa[k], np * es[k], "granular pairs");
      if (st != PX_STATUS_OK) goto done;
    }
    st = px_gran_ensure(s, &s->phist_scratch.p, 4 * np * cs, "granular pairs");
    if (st != PX_STATUS_OK) goto done;
    s->pj = px_mem_alloc(s->ctx, "granular pairs", np * sizeof(int32_t));
    s->pxi.p = px_mem_calloc(s->ctx, "granular pairs", np, cs);
    s->pth.p = px_mem_calloc(s->ctx, "granular pairs", np, cs);
    s->pdm.p = px_mem_calloc(s->ctx, "granular pairs", np, cs);
    s->pdp.p = px_mem_calloc(s->ctx, "granular pairs", np, cs);
    if (!s->pj || !s->pxi.p || !s->pth.p || !s->pdm.p || !s->pdp.p) {
      st = PX_STATUS_NOMEM;
      goto done;
    }
  }
  s->ops->build_pairs(s, s->skin, 1, NULL);

done:
  px_mem_free(s->ctx, count);
  return st;
}

/* The history of old pair q into new pair k; th_sign: -1 when the pair's
 * ends swapped (the rolling angle changes sign). */
static void px_gran_copy_history(struct px_gran_sys *s, size_t k, const struct px_gran_oldlist *o,
                                 size_t q, double th_sign) {
  const size_t cs = s->csize;
  px_gran_copy_real(s->pxi, k, o->xi, q, cs, 1);
  px_gran_copy_real(s->pth, k, o->th, q, cs, th_sign);
  px_gran_copy_real(s->pdm, k, o->dm, q, cs, 1);
  px_gran_copy_real(s->pdp, k, o->dp, q, cs, 1);
}

/* The contact histories of the old list o carried to the new one: new
 * pair (i, j) was (order[i], order[j]) in old indices, owned by either end. */
static void px_gran_carry_histories(struct px_gran_sys *s, const struct px_gran_oldlist *o) {
  const size_t n = s->n;
#pragma omp parallel for num_threads(s->active) schedule(static)
  for (long ii = 0; ii < (long)n; ++ii) {
    int32_t k;
    for (k = s->pstart[ii]; k < s->pstart[ii + 1]; ++k) {
      const int32_t oi = (int32_t)s->order[ii], oj = (int32_t)s->order[s->pj[k]];
      int32_t q;
      int found = 0;
      for (q = o->pstart[oi]; q < o->pstart[oi + 1]; ++q)
        if (o->pj[q] == oj) {
          px_gran_copy_history(s, (size_t)k, o, (size_t)q, 1);
          found = 1;
          break;
        }
      if (found) continue;
      for (q = o->pstart[oj]; q < o->pstart[oj + 1]; ++q)
        if (o->pj[q] == oi) {
          /* ownership swapped: the scalar tangential spring and the largest
           * overlap are symmetric, the rolling angle changes sign */
          px_gran_copy_history(s, (size_t)k, o, (size_t)q, -1);
          break;
        }
    }
  }
}

/* The wall candidates of the new order, the contours' reference frames,
 * and the check that no centre is behind a wall. */
static enum px_status px_gran_rebuild_walls(struct px_gran_sys *s) {
  const size_t n = s->n;
  size_t i;
  if (s->geom) {
    PX_TRY(px_gran_build_walls(s));
    memcpy(s->frames_ref, s->frames, s->geom->ncontours * PX_GRAN_CTR_COUNT * sizeof(double));
    for (i = 0; i < s->nnear; ++i) {
      const size_t p = (size_t)s->near[i];
      double rec[8];
      int c;
      s->ops->get(s, p, rec);
      c = px_gran_behind_wall(s, p, rec[0], rec[1]);
      if (c >= 0) {
        s->escaped_id = s->id[p];
        return px_context_fail(s->ctx, PX_STATUS_NUMERIC,
                               "particle %d at (%g, %g) has passed through contour '%s' at "
                               "step %ld (t = %g s) (its centre is behind the wall): the wall "
                               "is too soft or the time step too large for the impact speed "
                               "(|v| = %g m/s)",
                               (int)s->id[p], rec[0], rec[1], s->geom->contours[c].name, s->step,
                               s->t, hypot(rec[2], rec[3]));
      }
    }
  } else {
    PX_TRY(
        px_gran_ensure(s, (void **)&s->wstart, (n + 1) * sizeof(int32_t), "granular wall lists"));
    memset(s->wstart, 0, (n + 1) * sizeof(int32_t));
    s->nnear = 0;
  }
  return PX_STATUS_OK;
}

enum px_status px_gran_sys_rebuild(struct px_gran_sys *s) {
  const size_t n = s->n;
  struct px_gran_oldlist o;
  enum px_status st;
  PX_TRY(px_gran_sort_cells(s));
  /* keep the old list (old particle indices) for the history transfer */
  o.pstart = s->pstart;
  o.pj = s->pj;
  o.xi = s->pxi;
  o.th = s->pth;
  o.dm = s->pdm;
  o.dp = s->pdp;
  s->pstart = NULL;
  s->pj = NULL;
  s->pxi.p = s->pth.p = s->pdm.p = s->pdp.p = NULL;
  st = px_gran_permute(s);
  if (st == PX_STATUS_OK) st = px_gran_new_pairs(s);
  if (st == PX_STATUS_OK && o.pstart) px_gran_carry_histories(s, &o);
  if (st == PX_STATUS_OK) st = px_gran_sys_split_pairs(s);
  if (st == PX_STATUS_OK) st = px_gran_rebuild_walls(s);
  if (st == PX_STATUS_OK) {
    px_gran_sys_split_near(s);
    /* reference positions */
    memcpy(s->xr.p, s->x.p, n * s->ssize);
    memcpy(s->yr.p, s->y.p, n * s->ssize);
    ++s->rebuilds;
    s->need_rebuild = 0;
  }
  px_mem_free(s->ctx, o.pstart);
  px_mem_free(s->ctx, o.pj);
  px_mem_free(s->ctx, o.xi.p);
  px_mem_free(s->ctx, o.th.p);
  px_mem_free(s->ctx, o.dm.p);
  px_mem_free(s->ctx, o.dp.p);
  return st;
}
