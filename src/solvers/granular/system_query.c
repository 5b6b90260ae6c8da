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

double px_gran_sys_coordination(const struct px_gran_sys *s, const double *x, const double *y,
                                const double *r, double *z) {
  size_t i, total = 0;
  int32_t k;
  for (i = 0; i < s->n; ++i) z[i] = 0;
  for (i = 0; i < s->n; ++i) {
    for (k = s->pstart[i]; k < s->pstart[i + 1]; ++k) {
      const size_t j = (size_t)s->pj[k];
      const double dx = x[i] - x[j], dy = y[i] - y[j], c = r[i] + r[j];
      const double d2 = dx * dx + dy * dy, c2 = c * c;
      /* hypot(dx, dy) < c, decided by the squares where they are further
       * apart than their rounding can bring them (d2 and c2 are within
       * 4e-16 of exact, hypot within an ulp), by hypot itself in between
       * (and for NaN): the same answer at a tenth of the cost; counted
       * without a branch (adding 0 changes no count) */
      int touch = d2 < c2 * (1.0 - 1e-12);
      if (!touch && !(d2 > c2 * (1.0 + 1e-12))) touch = hypot(dx, dy) < c;
      z[i] += (double)touch;
      z[j] += (double)touch;
      total += 2 * (size_t)touch;
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
  return s->n ? (double)total / (double)s->n : 0;
}
