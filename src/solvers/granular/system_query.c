/* Queries of the granular system for outputs and tests: energies,
 * contacts (brute force and through the lists), exports, coordination. */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/checkpoint.h"
#include "partix/memory.h"
#include "partix/timer.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/system_impl.h"
#include "solvers/granular/wall_kernel.h"

/* ------------------------------------------------------------------ queries */

double px_gran_sys_kinetic(const struct px_gran_sys *s) {
  double et, er;
  long bad;
  s->ops->energy(s, &et, &er, &bad);
  return et + er;
}

double px_gran_sys_potential(const struct px_gran_sys *s) {
  double e = 0;
  size_t i;
  for (i = 0; i < s->n; ++i) {
    double rec[8];
    s->ops->get(s, i, rec);
    e -= rec[PX_GRAN_P_M] * (s->gravity[0] * rec[0] + s->gravity[1] * rec[1]);
  }
  return e;
}

static int px_gran_pair_cmp(const void *a, const void *b) {
  const int32_t *p = a, *q = b;
  if (p[0] != q[0]) return p[0] < q[0] ? -1 : 1;
  if (p[1] != q[1]) return p[1] < q[1] ? -1 : 1;
  return 0;
}

static enum px_status px_gran_push_pair(struct px_gran_sys *s, int32_t **v, size_t *n, size_t *cap,
                                        int32_t a, int32_t b) {
  if (*n == *cap) {
    size_t c = *cap ? 2 * *cap : 256;
    int32_t *g = px_mem_realloc(s->ctx, "granular contacts", *v, 2 * c * sizeof *g);
    if (!g) return PX_STATUS_NOMEM;
    *v = g;
    *cap = c;
  }
  (*v)[2 * *n] = a < b ? a : b;
  (*v)[2 * *n + 1] = a < b ? b : a;
  ++*n;
  return PX_STATUS_OK;
}

enum px_status px_gran_sys_contacts_brute(const struct px_gran_sys *s, int32_t **pairs, size_t *n) {
  size_t i, j, cap = 0;
  struct px_gran_sys *m = (struct px_gran_sys *)(size_t)s;
  *pairs = NULL;
  *n = 0;
  for (i = 0; i < s->n; ++i) {
    double a[8];
    s->ops->get(s, i, a);
    for (j = i + 1; j < s->n; ++j) {
      double b[8];
      s->ops->get(s, j, b);
      if (hypot(a[0] - b[0], a[1] - b[1]) < a[PX_GRAN_P_R] + b[PX_GRAN_P_R])
        PX_TRY(px_gran_push_pair(m, pairs, n, &cap, s->id[i], s->id[j]));
    }
  }
  qsort(*pairs, *n, 2 * sizeof(int32_t), px_gran_pair_cmp);
  return PX_STATUS_OK;
}

enum px_status px_gran_sys_contacts_list(const struct px_gran_sys *s, int32_t **pairs, size_t *n) {
  size_t i, cap = 0;
  struct px_gran_sys *m = (struct px_gran_sys *)(size_t)s;
  *pairs = NULL;
  *n = 0;
  for (i = 0; i < s->n; ++i) {
    int32_t k;
    double a[8];
    s->ops->get(s, i, a);
    for (k = s->pstart[i]; k < s->pstart[i + 1]; ++k) {
      double b[8];
      s->ops->get(s, (size_t)s->pj[k], b);
      if (hypot(a[0] - b[0], a[1] - b[1]) < a[PX_GRAN_P_R] + b[PX_GRAN_P_R])
        PX_TRY(px_gran_push_pair(m, pairs, n, &cap, s->id[i], s->id[s->pj[k]]));
    }
  }
  qsort(*pairs, *n, 2 * sizeof(int32_t), px_gran_pair_cmp);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------ exports */

void px_gran_sys_export(const struct px_gran_sys *s, double *x, double *y, double *vx, double *vy,
                        double *w, double *r, double *m, double *id) {
  size_t i;
  for (i = 0; i < s->n; ++i) {
    double rec[8];
    s->ops->get(s, i, rec);
    if (x) x[i] = rec[PX_GRAN_P_X];
    if (y) y[i] = rec[PX_GRAN_P_Y];
    if (vx) vx[i] = rec[PX_GRAN_P_VX];
    if (vy) vy[i] = rec[PX_GRAN_P_VY];
    if (w) w[i] = rec[PX_GRAN_P_W];
    if (r) r[i] = rec[PX_GRAN_P_R];
    if (m) m[i] = rec[PX_GRAN_P_M];
    if (id) id[i] = rec[PX_GRAN_P_ID];
  }
}

double px_gran_sys_coordination(const struct px_gran_sys *s, double *z) {
  size_t i, total = 0;
  int32_t k;
  /* the positions and radii in double once (a record read per pair cost
   * more than the test); without the room, a record read per pair */
  double *xyr = px_mem_alloc(s->ctx, "granular coordination", 3 * (s->n ? s->n : 1) * sizeof *xyr);
  for (i = 0; i < s->n; ++i) {
    double a[8];
    z[i] = 0;
    if (!xyr) continue;
    s->ops->get(s, i, a);
    xyr[3 * i] = a[PX_GRAN_P_X];
    xyr[3 * i + 1] = a[PX_GRAN_P_Y];
    xyr[3 * i + 2] = a[PX_GRAN_P_R];
  }
  for (i = 0; i < s->n; ++i) {
    double a[8];
    if (xyr)
      a[PX_GRAN_P_X] = xyr[3 * i], a[PX_GRAN_P_Y] = xyr[3 * i + 1], a[PX_GRAN_P_R] = xyr[3 * i + 2];
    else
      s->ops->get(s, i, a);
    for (k = s->pstart[i]; k < s->pstart[i + 1]; ++k) {
      const size_t j = (size_t)s->pj[k];
      double b[8];
      if (xyr)
        b[PX_GRAN_P_X] = xyr[3 * j], b[PX_GRAN_P_Y] = xyr[3 * j + 1],
        b[PX_GRAN_P_R] = xyr[3 * j + 2];
      else
        s->ops->get(s, j, b);
      const double dx = a[PX_GRAN_P_X] - b[PX_GRAN_P_X], dy = a[PX_GRAN_P_Y] - b[PX_GRAN_P_Y];
      const double c = a[PX_GRAN_P_R] + b[PX_GRAN_P_R], d2 = dx * dx + dy * dy, c2 = c * c;
      /* hypot(dx, dy) < c, decided by the squares where they are further
       * apart than their rounding can bring them (d2 and c2 are within
       * 4e-16 of exact, hypot within an ulp), by hypot itself in between
       * (and for NaN): the same answer at a tenth of the cost */
      int touch;
      if (d2 < c2 * (1.0 - 1e-12))
        touch = 1;
      else if (d2 > c2 * (1.0 + 1e-12))
        touch = 0;
      else
        touch = hypot(dx, dy) < c;
      if (touch) {
        z[i] += 1;
        z[j] += 1;
        total += 2;
      }
    }
    if (s->geom) {
      int q;
      for (q = 0; q < PX_GRAN_WSLOTS; ++q)
        if (s->slots.seg[i * PX_GRAN_WSLOTS + (size_t)q] >= 0) {
          z[i] += 1;
          total += 1;
        }
    }
  }
  px_mem_free(s->ctx, xyr);
  return s->n ? (double)total / (double)s->n : 0;
}
