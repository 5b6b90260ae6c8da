/* Checkpoints of the lattice solver (px_solver_lattice's save and load;
 * lattice.c sets up the run they belong to). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "partix/memory.h"
#include "solvers/lattice/lattice.h"
#include "solvers/lattice/lattice_ref.h"

/* ---------------------------------------------------------------------------
 * Checkpoints: the state in double (exact for a float engine too), the link
 * flags, the damping in use, the broken-link count and the quasi-static
 * convergence check (static_error, static_since; whether it had converged
 * is decided again at the next check, under the tolerance of the resumed
 * case). */
enum px_status px_lattice_save(void *state, struct px_checkpoint_writer *w) {
  struct px_lattice *L = (struct px_lattice *)state;
  size_t n = L->m.nalloc;
  /* over ranks: the whole state the gather brought to rank 0 */
  const int own = !L->ranks;
  struct lt_el *y =
      own ? (struct lt_el *)px_mem_alloc(L->ctx, "lattice.checkpoint", n * sizeof *y) : L->gy;
  uint8_t *links = own ? (uint8_t *)px_mem_alloc(L->ctx, "lattice.checkpoint", n) : L->gl;
  double extra[2];
  enum px_status st = PX_STATUS_OK;
  int64_t broken = L->vt->broken(L->e);
  if (!y || !links) {
    if (own) {
      px_mem_free(L->ctx, y);
      px_mem_free(L->ctx, links);
    }
    return own ? PX_STATUS_NOMEM
               : px_context_fail(L->ctx, PX_STATUS_INVALID, "lattice: the state was not gathered");
  }
  if (own) st = L->vt->get_state(L->e, y, links);
  extra[0] = L->alpha;
  extra[1] = (double)L->m.grid.count;
  if (st == PX_STATUS_OK)
    st = px_checkpoint_write(w, "lattice.state", PX_DTYPE_F64, (uint64_t)n * 13, y);
  if (st == PX_STATUS_OK) st = px_checkpoint_write(w, "lattice.links", PX_DTYPE_U8, n, links);
  if (st == PX_STATUS_OK) st = px_checkpoint_write(w, "lattice.scalars", PX_DTYPE_F64, 2, extra);
  if (st == PX_STATUS_OK) st = px_checkpoint_write(w, "lattice.broken", PX_DTYPE_I64, 1, &broken);
  if (st == PX_STATUS_OK) {
    double conv[2];
    conv[0] = L->static_error;
    conv[1] = L->static_since;
    st = px_checkpoint_write(w, "lattice.static", PX_DTYPE_F64, 2, conv);
  }
  if (own) {
    px_mem_free(L->ctx, y);
    px_mem_free(L->ctx, links);
  }
  return st;
}

/* ---------------------------------------------------------------------------
 * Checkpoint loading. The file is not trusted (docs/running.md, "What partix
 * trusts"): its CRCs only say it is what was written, not that a partix
 * wrote it. Every section is checked against the case before any of it is
 * used: sizes, link flags (only links the body has, both ends alike), the
 * broken-link count (the links the flags miss), the state (void cells and
 * padding at rest, elements finite within the engine's precision, unit
 * quaternions) and the scalars; a failure is PX_STATUS_FORMAT naming the
 * section. */

/* Grid cell of padded entry i, or (size_t)-1 for padding. */
static size_t px_lattice_cell_of(const struct px_lattice_model *m, size_t i) {
  size_t r, x;
  if (i < m->pad || i >= m->nalloc - m->pad) return (size_t)-1;
  r = (i - m->pad) / m->n0p;
  x = (i - m->pad) % m->n0p;
  return x < (size_t)m->grid.n[0] ? x + (size_t)m->grid.n[0] * r : (size_t)-1;
}

/* "element (i, j, k)" or "padding entry i" into buf. */
static const char *px_lattice_entry_name(const struct px_lattice_model *m, size_t i, char *buf,
                                         size_t size) {
  size_t c = px_lattice_cell_of(m, i), n0 = (size_t)m->grid.n[0], n1 = (size_t)m->grid.n[1];
  if (c == (size_t)-1)
    snprintf(buf, size, "padding entry %zu", i);
  else
    snprintf(buf, size, "%s (%zu, %zu, %zu)", m->grid.occ[c] ? "element" : "void cell", c % n0,
             (c / n0) % n1, c / (n0 * n1));
  return buf;
}

/* The section `name` holds `count` values of `type`: else FORMAT naming
 * it (before anything is allocated or read). */
static enum px_status px_lattice_ck_section(struct px_lattice *L, struct px_checkpoint *ck,
                                            const char *name, enum px_dtype type, uint64_t count) {
  enum px_dtype t;
  uint64_t n = 0;
  enum px_status st = px_checkpoint_find(ck, name, &t, &n);
  if (st == PX_STATUS_NOT_FOUND) {
    px_context_clear(L->ctx);
    return px_context_fail(L->ctx, PX_STATUS_FORMAT, "section '%s' is missing", name);
  }
  PX_TRY(st);
  if (t != type || n != count)
    return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                           "section '%s' holds %llu values of type %d; the case needs %llu of "
                           "type %d",
                           name, (unsigned long long)n, (int)t, (unsigned long long)count,
                           (int)type);
  return PX_STATUS_OK;
}

/* Link flags: a subset of the body's (links only break), bits 6-7 clear, both
 * ends of a link alike (fracture decides each link once, canonically). The
 * number of links missing into *missing. */
static enum px_status px_lattice_ck_links(struct px_lattice *L, const uint8_t *links,
                                          uint64_t *missing) {
  const struct px_lattice_model *m = &L->m;
  uint64_t ends = 0;
  size_t i;
  char a_name[96], b_name[96];
  for (i = 0; i < m->nalloc; ++i) {
    int a;
    if (links[i] & ~m->links[i])
      return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                             "section 'lattice.links': %s has link flags 0x%02x, its body only "
                             "0x%02x",
                             px_lattice_entry_name(m, i, a_name, sizeof a_name), links[i],
                             m->links[i]);
    for (a = 0; a < 3; ++a) {
      size_t j = i + (size_t)m->stride[a];
      if (!(m->links[i] & PX_LATTICE_LINK_PLUS(a))) continue;
      /* j < nalloc: a body link's plus end is an element */
      if (!(links[i] & PX_LATTICE_LINK_PLUS(a)) != !(links[j] & PX_LATTICE_LINK_MINUS(a)))
        return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                               "section 'lattice.links': the link between %s and %s is broken "
                               "at one end only",
                               px_lattice_entry_name(m, i, a_name, sizeof a_name),
                               px_lattice_entry_name(m, j, b_name, sizeof b_name));
      if (!(links[i] & PX_LATTICE_LINK_PLUS(a))) ++ends;
    }
  }
  *missing = ends;
  return PX_STATUS_OK;
}

/* The state of the entries [first, first + count), y[0] the first's: void
 * cells and padding exactly at rest (their links are
 * evaluated and multiplied by 0: a NaN there would spread); elements finite
 * and within the engine's precision, orientation a unit quaternion (to
 * 1e-3: the engines renormalize every step, in float to ~1e-7). */
static enum px_status px_lattice_ck_state(struct px_lattice *L, const struct lt_el *y, size_t first,
                                          size_t count) {
  const struct px_lattice_model *m = &L->m;
  double hi = px_lattice_real_max(L);
  size_t i;
  char name[96];
  for (i = first; i < first + count; ++i) {
    const struct lt_el *e = &y[i - first];
    const double c[13] = {e->u.x, e->u.y, e->u.z, e->q.w, e->q.x, e->q.y, e->q.z,
                          e->v.x, e->v.y, e->v.z, e->W.x, e->W.y, e->W.z};
    static const char *const what[13] = {
        "displacement x",    "displacement y", "displacement z",     "orientation w",
        "orientation x",     "orientation y",  "orientation z",      "velocity x",
        "velocity y",        "velocity z",     "angular velocity x", "angular velocity y",
        "angular velocity z"};
    int k;
    if (m->group[i] == 0) {
      for (k = 0; k < 13; ++k)
        if (c[k] != (k == 3 ? 1.0 : 0.0))
          return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                                 "section 'lattice.state': %s is not at rest (%s = %g)",
                                 px_lattice_entry_name(m, i, name, sizeof name), what[k], c[k]);
      continue;
    }
    for (k = 0; k < 13; ++k)
      if (!(fabs(c[k]) <= hi))
        return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                               "section 'lattice.state': %s has %s = %g (not a finite value of "
                               "%s precision)",
                               px_lattice_entry_name(m, i, name, sizeof name), what[k], c[k],
                               L->precision == PX_PRECISION_SINGLE ? "single" : "double");
    {
      /* scaled by the largest component: no overflow for finite ones */
      double big = fmax(fmax(fabs(e->q.w), fabs(e->q.x)), fmax(fabs(e->q.y), fabs(e->q.z)));
      double qn = 0.0;
      if (big > 0.0)
        qn = big * sqrt((e->q.w / big) * (e->q.w / big) + (e->q.x / big) * (e->q.x / big) +
                        (e->q.y / big) * (e->q.y / big) + (e->q.z / big) * (e->q.z / big));
      if (!(fabs(qn - 1.0) <= 1e-3))
        return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                               "section 'lattice.state': %s has an orientation quaternion of "
                               "norm %g (not 1)",
                               px_lattice_entry_name(m, i, name, sizeof name), qn);
    }
  }
  return PX_STATUS_OK;
}

/* Entries of the state read at once over ranks (13 doubles each: 1.6 MiB). */
#define PX_LATTICE_LOAD_CHUNK ((size_t)1 << 14)

/* Over ranks: the section lattice.state read in pieces, each checked
 * (px_lattice_ck_state), this rank's window of it and of the checked flags
 * `links` (whole) kept and, once the whole section is read and its CRC
 * verified, given to the engine: no rank holds the whole state. */
static enum px_status px_lattice_load_window(struct px_lattice *L, struct px_checkpoint *ck,
                                             const uint8_t *links) {
  const struct px_lattice_model *m = &L->m, *w = &L->wm;
  const size_t n = m->nalloc;
  struct lt_el *piece, *ly;
  uint8_t *ll;
  size_t at = 0, i;
  enum px_status st = PX_STATUS_OK;
  piece = (struct lt_el *)px_mem_alloc(L->ctx, "lattice.checkpoint",
                                       PX_LATTICE_LOAD_CHUNK * sizeof *piece);
  ly = (struct lt_el *)px_mem_alloc(L->ctx, "lattice.checkpoint", w->nalloc * sizeof *ly);
  ll = (uint8_t *)px_mem_alloc(L->ctx, "lattice.checkpoint", w->nalloc);
  if (!piece || !ly || !ll) st = PX_STATUS_NOMEM;
  /* the window's padding as the engine holds it (at rest, no links) */
  if (st == PX_STATUS_OK) st = L->vt->get_state(L->e, ly, ll);
  if (st == PX_STATUS_OK)
    st = px_checkpoint_read_begin(ck, "lattice.state", PX_DTYPE_F64, (uint64_t)n * 13);
  while (st == PX_STATUS_OK && at < n) {
    const size_t k = n - at < PX_LATTICE_LOAD_CHUNK ? n - at : PX_LATTICE_LOAD_CHUNK;
    st = px_checkpoint_read_chunk(ck, piece, (uint64_t)k * 13);
    if (st == PX_STATUS_OK) st = px_lattice_ck_state(L, piece, at, k);
    for (i = 0; st == PX_STATUS_OK && i < k; ++i) {
      size_t wj, wk;
      const size_t wi = px_lattice_window_entry(L, at + i, &wj, &wk);
      if (wi == (size_t)-1) continue;
      ly[wi] = piece[i];
      ll[wi] = (uint8_t)(links[at + i] & ~px_lattice_window_out(w, wj, wk));
    }
    at += k;
  }
  if (st == PX_STATUS_OK) st = px_checkpoint_read_end(ck);
  /* all read, its CRC verified, checked: use it */
  if (st == PX_STATUS_OK) st = L->vt->set_state(L->e, ly, ll);
  px_mem_free(L->ctx, piece);
  px_mem_free(L->ctx, ly);
  px_mem_free(L->ctx, ll);
  return st;
}

enum px_status px_lattice_load(void *state, struct px_checkpoint *ck) {
  struct px_lattice *L = (struct px_lattice *)state;
  const struct px_lattice_model *m = &L->m;
  size_t n = m->nalloc;
  struct lt_el *y = NULL;
  uint8_t *links = NULL;
  double extra[2] = {0, 0}, conv[2] = {NAN, NAN}, omega;
  double alpha_max;
  int64_t broken = 0;
  uint64_t missing = 0;
  int has_static = 0;
  enum px_status st;
  /* sizes first, from the index: nothing read or allocated yet */
  PX_TRY(px_lattice_ck_section(L, ck, "lattice.state", PX_DTYPE_F64, (uint64_t)n * 13));
  PX_TRY(px_lattice_ck_section(L, ck, "lattice.links", PX_DTYPE_U8, n));
  PX_TRY(px_lattice_ck_section(L, ck, "lattice.scalars", PX_DTYPE_F64, 2));
  PX_TRY(px_lattice_ck_section(L, ck, "lattice.broken", PX_DTYPE_I64, 1));
  {
    enum px_dtype t;
    uint64_t cnt;
    /* optional: checkpoints from before quasi-static convergence */
    if (px_checkpoint_find(ck, "lattice.static", &t, &cnt) == PX_STATUS_OK) {
      PX_TRY(px_lattice_ck_section(L, ck, "lattice.static", PX_DTYPE_F64, 2));
      has_static = 1;
    } else {
      px_context_clear(L->ctx);
    }
  }
  /* the scalars */
  PX_TRY(px_checkpoint_read(ck, "lattice.scalars", PX_DTYPE_F64, 2, extra));
  PX_TRY(px_checkpoint_read(ck, "lattice.broken", PX_DTYPE_I64, 1, &broken));
  if (has_static) PX_TRY(px_checkpoint_read(ck, "lattice.static", PX_DTYPE_F64, 2, conv));
  if (!(extra[1] == (double)m->grid.count))
    return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                           "section 'lattice.scalars': the checkpoint holds %g elements but the "
                           "case builds %zu",
                           extra[1], m->grid.count);
  /* the damping in use: the case's, or (quasi-static) 2 omega of a
   * Rayleigh quotient, at most twice the highest frequency 3.74 c/h (x2
   * for round-off), or the case's initial one */
  omega = 3.74 * sqrt(m->par.E / m->par.rho) / m->grid.h * px_lattice_model_stiffen(m);
  alpha_max = fmax(m->par.alpha, 4.0 * omega);
  if (L->quasi_static ? !(extra[0] >= 0.0 && extra[0] <= alpha_max) : !(extra[0] == m->par.alpha))
    return px_context_fail(L->ctx, PX_STATUS_FORMAT, "section 'lattice.scalars': damping %g 1/s %s",
                           extra[0],
                           L->quasi_static ? "outside [0, 4 x the highest frequency]"
                                           : "differs from the case's lattice.damping");
  /* static_error (>= 0) and the time since it stayed below the tolerance
   * (>= 0; it may lie past the checkpoint's time after a resume with a
   * smaller time.dt, which only delays convergence); NaN: none */
  if (!(isnan(conv[0]) || (conv[0] >= 0.0 && conv[0] < INFINITY)) ||
      !(isnan(conv[1]) || (conv[1] >= 0.0 && conv[1] < INFINITY)))
    return px_context_fail(L->ctx, PX_STATUS_FORMAT,
                           "section 'lattice.static': static_error %g and the time since it "
                           "converged %g s must be finite and >= 0 (or NaN: none)",
                           conv[0], conv[1]);
  /* the arrays: the flags whole, the state whole on one rank, over ranks
   * in pieces of which this rank keeps its window (px_lattice_load_window) */
  links = (uint8_t *)px_mem_alloc(L->ctx, "lattice.checkpoint", n);
  if (!L->ranks) y = (struct lt_el *)px_mem_alloc(L->ctx, "lattice.checkpoint", n * sizeof *y);
  if ((!L->ranks && !y) || !links) {
    px_mem_free(L->ctx, y);
    px_mem_free(L->ctx, links);
    return PX_STATUS_NOMEM;
  }
  st = px_checkpoint_read(ck, "lattice.links", PX_DTYPE_U8, n, links);
  if (st == PX_STATUS_OK) st = px_lattice_ck_links(L, links, &missing);
  if (st == PX_STATUS_OK && !(broken >= 0 && (uint64_t)broken == missing))
    st = px_context_fail(L->ctx, PX_STATUS_FORMAT,
                         "section 'lattice.broken': %lld broken links, but the link flags miss "
                         "%llu",
                         (long long)broken, (unsigned long long)missing);
  if (st == PX_STATUS_OK && L->ranks) st = px_lattice_load_window(L, ck, links);
  if (st == PX_STATUS_OK && !L->ranks) {
    st = px_checkpoint_read(ck, "lattice.state", PX_DTYPE_F64, (uint64_t)n * 13, y);
    if (st == PX_STATUS_OK) st = px_lattice_ck_state(L, y, 0, n);
    /* all checked: use it */
    if (st == PX_STATUS_OK) st = L->vt->set_state(L->e, y, links);
  }
  if (st == PX_STATUS_OK) st = L->vt->set_broken(L->e, (long)broken);
  if (st == PX_STATUS_OK) {
    L->alpha = extra[0];
    L->vt->set_alpha(L->e, L->alpha);
    if (has_static) {
      L->static_error = conv[0];
      L->static_since = conv[1];
    }
  }
  px_mem_free(L->ctx, y);
  px_mem_free(L->ctx, links);
  return st;
}
