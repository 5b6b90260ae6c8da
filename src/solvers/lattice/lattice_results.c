/* The lattice solver's results in memory (partix/results.h): per element
 * (occupied cell, in cell order) what the snapshots hold, at full precision,
 * the element's centre and its rotation. */
#include <math.h>

#include "partix/memory.h"
#include "solvers/lattice/lattice.h"
#include "solvers/lattice/lattice_c.h"

/* The rotation vector (axis times angle [rad], the angle in [0, pi]) of
 * unit quaternion q: what turns the element from its reference
 * orientation. */
static void px_lattice_rotation_vector(struct lt_q4 q, double r[3]) {
  double w = (double)q.w, x = (double)q.x, y = (double)q.y, z = (double)q.z;
  double s, angle;
  if (w < 0.0) w = -w, x = -x, y = -y, z = -z; /* q and -q: the same rotation */
  s = sqrt(x * x + y * y + z * z);
  angle = 2.0 * atan2(s, w);
  /* small angles: angle / s -> 2 / w (no 0 / 0) */
  s = s > 1e-300 ? angle / s : 2.0 / (w > 0.0 ? w : 1.0);
  r[0] = s * x, r[1] = s * y, r[2] = s * z;
}

static int px_lattice_bits(unsigned x) {
  int n = 0;
  for (; x; x &= x - 1) ++n;
  return n;
}

enum px_status px_lattice_results(void *state, const struct px_sim_output *o,
                                  enum px_results_kind kind, struct px_results *out) {
  struct px_lattice *L = (struct px_lattice *)state;
  const struct px_lattice_model *m = &L->m;
  const struct px_lattice_grid *g = &m->grid;
  size_t n = g->count, e = 0, cell;
  int64_t *id;
  double *x, *u, *v, *s, *vm;
  uint8_t *broken;
  struct lt_el *y;
  double *rot;
  enum px_status st;
  if (kind != PX_RESULTS_STATE) return PX_STATUS_UNSUPPORTED;
  PX_TRY(px_lattice_fetch(L, o));
  /* the orientations: from the state (the fields hold none) */
  if (L->ranks) {
    /* the whole state the gather brought to rank 0 */
    y = L->gy;
    st = y ? PX_STATUS_OK
           : px_context_fail(L->ctx, PX_STATUS_INVALID, "lattice: the state was not gathered");
  } else {
    y = (struct lt_el *)px_mem_alloc(L->ctx, "lattice.results", m->nalloc * sizeof *y);
    if (!y) return PX_STATUS_NOMEM;
    st = L->vt->get_state(L->e, y, NULL);
  }
  rot = st == PX_STATUS_OK ? px_results_add(out, "rotation", "rad", PX_VIEW_F64, n, 3, NULL) : NULL;
  if (st == PX_STATUS_OK && !rot) st = PX_STATUS_NOMEM;
  if (st == PX_STATUS_OK) {
    size_t c;
    for (c = 0, e = 0; c < g->ncell && e < n; ++c)
      if (g->occ[c]) px_lattice_rotation_vector(y[px_lattice_index(m, c)].q, rot + 3 * e++);
    e = 0;
  }
  if (!L->ranks) px_mem_free(L->ctx, y);
  if (st != PX_STATUS_OK)
    return st == PX_STATUS_NOMEM
               ? px_context_fail(L->ctx, st, "out of memory (results of %zu elements)", n)
               : st;
  id = px_results_add(out, "cell", "", PX_VIEW_I64, n, 1, NULL);
  x = px_results_add(out, "position", "m", PX_VIEW_F64, n, 3, NULL);
  u = px_results_add(out, "displacement", "m", PX_VIEW_F64, n, 3, NULL);
  v = px_results_add(out, "velocity", "m/s", PX_VIEW_F64, n, 3, NULL);
  s = px_results_add(out, "stress", "Pa", PX_VIEW_F64, n, 6, NULL);
  vm = px_results_add(out, "von_mises", "Pa", PX_VIEW_F64, n, 1, NULL);
  broken = px_results_add(out, "broken_links", "", PX_VIEW_U8, n, 1, NULL);
  if (!id || !x || !u || !v || !s || !vm || !broken)
    return px_context_fail(L->ctx, PX_STATUS_NOMEM, "out of memory (results of %zu elements)", n);
  for (cell = 0; cell < g->ncell && e < n; ++cell) {
    size_t i, c[3];
    int k;
    if (!g->occ[cell]) continue;
    i = px_lattice_index(m, cell);
    c[0] = cell % (size_t)g->n[0];
    c[1] = cell / (size_t)g->n[0] % (size_t)g->n[1];
    c[2] = cell / ((size_t)g->n[0] * (size_t)g->n[1]);
    id[e] = (int64_t)cell;
    for (k = 0; k < 3; ++k) {
      x[3 * e + (size_t)k] = g->origin[k] + g->h * ((double)c[k] + 0.5);
      u[3 * e + (size_t)k] = L->fu[3 * i + (size_t)k];
      v[3 * e + (size_t)k] = L->fv[3 * i + (size_t)k];
    }
    for (k = 0; k < 6; ++k) s[6 * e + (size_t)k] = L->fs[6 * i + (size_t)k];
    vm[e] = L->fvm[i];
    broken[e] = (uint8_t)px_lattice_bits((unsigned)(m->links[i] & ~L->flinks[i]));
    ++e;
  }
  return PX_STATUS_OK;
}
