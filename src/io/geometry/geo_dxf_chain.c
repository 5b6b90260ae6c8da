/* DXF import, second half: the pieces (one per entity) mapped to the
 * caller's units and chained end to end into closed loops, looking ends up
 * in a grid. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/memory.h"
#include "io/geometry/geo_dxf_impl.h"

void px_geo_dxf_transform(struct px_geo_prim *q, double s, double dx, double dy) {
  size_t k;
  switch (q->kind) {
    case PX_GEO_PRIM_LINE:
      q->p[0] = s * q->p[0] + dx, q->p[1] = s * q->p[1] + dy;
      q->p[2] = s * q->p[2] + dx, q->p[3] = s * q->p[3] + dy;
      break;
    case PX_GEO_PRIM_ARC:
      q->p[0] = s * q->p[0] + dx, q->p[1] = s * q->p[1] + dy, q->p[2] *= s;
      break;
    case PX_GEO_PRIM_ELLIPSE:
      q->p[0] = s * q->p[0] + dx, q->p[1] = s * q->p[1] + dy, q->p[2] *= s, q->p[3] *= s;
      break;
    case PX_GEO_PRIM_BEZIER2:
      for (k = 0; k < 3; ++k)
        q->p[2 * k] = s * q->p[2 * k] + dx, q->p[2 * k + 1] = s * q->p[2 * k + 1] + dy;
      break;
    case PX_GEO_PRIM_POINTS:
      for (k = 0; k < q->npts; ++k)
        q->pts[2 * k] = s * q->pts[2 * k] + dx, q->pts[2 * k + 1] = s * q->pts[2 * k + 1] + dy;
      break;
  }
}

static void px_geo_dxf_piece_ends(const struct px_geo_dxf_piece *pc, double *x0, double *y0,
                                  double *x1, double *y1) {
  double a, b;
  px_geo_prim_ends(&pc->path.prims[0], x0, y0, &a, &b);
  px_geo_prim_ends(&pc->path.prims[pc->path.n - 1], &a, &b, x1, y1);
}

static void px_geo_dxf_piece_reverse(struct px_geo_dxf_piece *pc) {
  size_t k;
  for (k = 0; k < pc->path.n / 2; ++k) {
    struct px_geo_prim t = pc->path.prims[k];
    pc->path.prims[k] = pc->path.prims[pc->path.n - 1 - k];
    pc->path.prims[pc->path.n - 1 - k] = t;
  }
  for (k = 0; k < pc->path.n; ++k) px_geo_prim_reverse(&pc->path.prims[k]);
}

/* Move the primitives of piece b to the end of path a (ownership of point
 * arrays moves too). */
static enum px_status px_geo_dxf_append(struct px_context *ctx, struct px_geo_path *a,
                                        struct px_geo_dxf_piece *b) {
  size_t k;
  for (k = 0; k < b->path.n; ++k) {
    struct px_geo_prim q = b->path.prims[k];
    double *pts = q.pts;
    q.pts = NULL;
    q.npts = 0;
    q.kind = q.kind == PX_GEO_PRIM_POINTS ? PX_GEO_PRIM_LINE : q.kind; /* placeholder */
    PX_TRY(px_geo_path_add(ctx, a, &q));
    a->prims[a->n - 1] = b->path.prims[k];
    a->prims[a->n - 1].pts = pts;
    b->path.prims[k].pts = NULL;
  }
  return PX_STATUS_OK;
}

/* The ends of the open pieces, sorted by grid cell (cells of size `cell`
 * >= the tolerance, so every end within the tolerance of a point lies in
 * the 3 x 3 cells around it), with "next unused" links that skip the ends
 * of pieces already chained (path-compressed): each chain step costs about
 * the number of unused ends near its end. */
struct px_geo_dxf_end {
  int64_t ci, cj; /* cell */
  size_t piece;
  int which; /* 0: start, 1: end */
  double x, y;
};

struct px_geo_dxf_ends {
  struct px_geo_dxf_end *v; /* owned, sorted by (ci, cj, piece, which) */
  size_t n;
  size_t *next; /* owned, n + 1: next unused index >= i (n: none) */
  size_t *slot; /* owned, 2 per piece: index of its ends in v (n: none) */
  double x0, y0, cell;
};

static int px_geo_dxf_end_cmp(const void *a, const void *b) {
  const struct px_geo_dxf_end *p = a, *q = b;
  if (p->ci != q->ci) return p->ci < q->ci ? -1 : 1;
  if (p->cj != q->cj) return p->cj < q->cj ? -1 : 1;
  if (p->piece != q->piece) return p->piece < q->piece ? -1 : 1;
  return p->which - q->which;
}

static void px_geo_dxf_ends_free(struct px_context *ctx, struct px_geo_dxf_ends *E) {
  px_mem_free(ctx, E->v);
  px_mem_free(ctx, E->next);
  px_mem_free(ctx, E->slot);
  memset(E, 0, sizeof *E);
}

static enum px_status px_geo_dxf_ends_build(struct px_context *ctx,
                                            const struct px_geo_dxf_pieces *ps, double tol,
                                            struct px_geo_dxf_ends *E) {
  double xmin = DBL_MAX, ymin = DBL_MAX, xmax = -DBL_MAX, ymax = -DBL_MAX;
  size_t k, m = 0;
  memset(E, 0, sizeof *E);
  E->v = px_mem_alloc(ctx, "geometry dxf", (2 * ps->n + 1) * sizeof *E->v);
  E->next = px_mem_alloc(ctx, "geometry dxf", (2 * ps->n + 1) * sizeof *E->next);
  E->slot = px_mem_alloc(ctx, "geometry dxf", (2 * ps->n + 1) * sizeof *E->slot);
  if (!E->v || !E->next || !E->slot) return PX_STATUS_NOMEM;
  for (k = 0; k < ps->n; ++k) {
    double x[2], y[2];
    int w;
    if (ps->v[k].closed) continue;
    px_geo_dxf_piece_ends(&ps->v[k], &x[0], &y[0], &x[1], &y[1]);
    for (w = 0; w < 2; ++w) {
      E->v[m].piece = k;
      E->v[m].which = w;
      E->v[m].x = x[w];
      E->v[m].y = y[w];
      xmin = fmin(xmin, x[w]), xmax = fmax(xmax, x[w]);
      ymin = fmin(ymin, y[w]), ymax = fmax(ymax, y[w]);
      ++m;
    }
  }
  E->n = m;
  /* cells of the tolerance, but at most ~1e9 across the drawing: the cell
   * indices stay far inside int64 (ends are finite: the entities were
   * checked, the scale is finite) */
  E->x0 = m ? xmin : 0;
  E->y0 = m ? ymin : 0;
  E->cell = tol > 0 ? tol : 1;
  if (m && !(fmax(xmax - xmin, ymax - ymin) / E->cell <= 1e9))
    E->cell = fmax(xmax - xmin, ymax - ymin) / 1e9;
  if (!(E->cell > 0) || !isfinite(E->cell)) E->cell = 1;
  for (k = 0; k < m; ++k) {
    E->v[k].ci = (int64_t)floor((E->v[k].x - E->x0) / E->cell);
    E->v[k].cj = (int64_t)floor((E->v[k].y - E->y0) / E->cell);
  }
  qsort(E->v, m, sizeof *E->v, px_geo_dxf_end_cmp);
  for (k = 0; k < 2 * ps->n; ++k) E->slot[k] = m;
  for (k = 0; k <= m; ++k) E->next[k] = k;
  for (k = 0; k < m; ++k) E->slot[2 * E->v[k].piece + (size_t)E->v[k].which] = k;
  return PX_STATUS_OK;
}

/* The first unused end at index >= i (E->n: none), compressing the links. */
static size_t px_geo_dxf_ends_find(struct px_geo_dxf_ends *E, size_t i) {
  size_t r = i, t;
  while (E->next[r] != r) r = E->next[r];
  while (E->next[i] != r) {
    t = E->next[i];
    E->next[i] = r;
    i = t;
  }
  return r;
}

/* Piece `piece` is chained: its ends are no longer candidates. */
static void px_geo_dxf_ends_remove(struct px_geo_dxf_ends *E, size_t piece) {
  int w;
  for (w = 0; w < 2; ++w) {
    const size_t i = E->slot[2 * piece + (size_t)w];
    if (i < E->n) E->next[i] = i + 1;
  }
}

/* The unused piece with an end nearest to (x, y), within tol (ties: the
 * lower piece, its start before its end); *rev = 1 when that is its end
 * (the piece is reversed to continue the chain). ps->n when none. */
static size_t px_geo_dxf_ends_nearest(struct px_geo_dxf_ends *E, const struct px_geo_dxf_pieces *ps,
                                      double x, double y, double tol, int *rev) {
  size_t best = ps->n;
  double bd = DBL_MAX;
  int di, dj;
  const double fi = floor((x - E->x0) / E->cell), fj = floor((y - E->y0) / E->cell);
  *rev = 0;
  /* a point beyond the cells of every end is near none (and its cell is not
   * converted) */
  if (!E->n || !(fi >= -2) || !(fi <= 2e9) || !(fj >= -2) || !(fj <= 2e9)) return best;
  for (dj = -1; dj <= 1; ++dj)
    for (di = -1; di <= 1; ++di) {
      const int64_t ci = (int64_t)fi + di, cj = (int64_t)fj + dj;
      size_t lo = 0, hi = E->n, i;
      /* the first end of the cell (ci, cj) */
      while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        const struct px_geo_dxf_end *p = &E->v[mid];
        if (p->ci < ci || (p->ci == ci && p->cj < cj))
          lo = mid + 1;
        else
          hi = mid;
      }
      for (i = px_geo_dxf_ends_find(E, lo); i < E->n && E->v[i].ci == ci && E->v[i].cj == cj;
           i = px_geo_dxf_ends_find(E, i + 1)) {
        const struct px_geo_dxf_end *p = &E->v[i];
        const double d = hypot(p->x - x, p->y - y);
        if (!(d <= tol)) continue;
        if (d < bd || (d == bd && (p->piece < best || (p->piece == best && p->which < *rev)))) {
          bd = d;
          best = p->piece;
          *rev = p->which;
        }
      }
    }
  return best;
}

/* Chain pieces into closed loops: each open piece's ends are looked up in
 * a grid of cells of at least tol (sorted by cell), so a chain step looks at
 * the ends near its end, not at every piece. out: ps->n paths (owned by the
 * caller, also on failure), *nout of them made. */
enum px_status px_geo_dxf_chain(struct px_context *ctx, const char *name,
                                struct px_geo_dxf_pieces *ps, double tol, struct px_geo_path *out,
                                size_t *nout) {
  unsigned char *used = NULL;
  struct px_geo_dxf_ends ends;
  size_t k;
  enum px_status st;
  memset(&ends, 0, sizeof ends);
  used = px_mem_calloc(ctx, "geometry dxf", ps->n, 1);
  st = used ? px_geo_dxf_ends_build(ctx, ps, tol, &ends) : PX_STATUS_NOMEM;
  if (st != PX_STATUS_OK) goto done;
  for (k = 0; k < ps->n; ++k) {
    struct px_geo_path *P;
    double sx, sy, ex, ey, x0, y0;
    if (used[k]) continue;
    used[k] = 1;
    px_geo_dxf_ends_remove(&ends, k);
    P = &out[(*nout)++];
    px_geo_path_init(P, NULL);
    snprintf(P->where, sizeof P->where, "%s:%zu", name, ps->v[k].line);
    px_geo_dxf_piece_ends(&ps->v[k], &sx, &sy, &ex, &ey);
    st = px_geo_dxf_append(ctx, P, &ps->v[k]);
    if (st != PX_STATUS_OK) goto done;
    if (ps->v[k].closed || hypot(ex - sx, ey - sy) <= tol) continue;
    for (;;) {
      size_t best;
      int rev = 0;
      best = px_geo_dxf_ends_nearest(&ends, ps, ex, ey, tol, &rev);
      if (best == ps->n) {
        st = px_context_fail(ctx, PX_STATUS_CONFIG,
                             "%s: open contour: the chain starting with the %s at line %zu "
                             "(from (%g, %g)) ends at (%g, %g) where no other entity starts or "
                             "ends within %g; close the drawing or raise the tolerance",
                             name, ps->v[k].type, ps->v[k].line, sx, sy, ex, ey, tol);
        goto done;
      }
      used[best] = 1;
      px_geo_dxf_ends_remove(&ends, best);
      if (rev) px_geo_dxf_piece_reverse(&ps->v[best]);
      px_geo_dxf_piece_ends(&ps->v[best], &x0, &y0, &ex, &ey);
      st = px_geo_dxf_append(ctx, P, &ps->v[best]);
      if (st != PX_STATUS_OK) goto done;
      if (hypot(ex - sx, ey - sy) <= tol) break;
    }
  }
done:
  px_mem_free(ctx, used);
  px_geo_dxf_ends_free(ctx, &ends);
  return st;
}
